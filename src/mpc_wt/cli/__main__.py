"""``python -m mpc_wt.cli``: the ``mpcwt`` command."""
import sys

from mpc_wt.cli import main

if __name__ == "__main__":
    sys.exit(main())
