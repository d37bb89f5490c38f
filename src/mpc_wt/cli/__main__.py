"""``python -m mpc_wt.cli``: the ``mpcwt`` command."""
import sys

from .main import main

sys.exit(main())
