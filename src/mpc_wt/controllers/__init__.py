"""Controllers as registered kinds: the registry, typed options, and one run from a name.

``kinds()`` lists every kind (``describe()`` with its options); ``register`` adds one;
``run_controller`` trims, builds, makes the wind and simulates. The kinds mpc-wt ships are
registered by importing :mod:`mpc_wt.controllers.builtin`, which this package does.
"""
from . import builtin
from .builtin import (APCOptions, BaselineOptions, ColemanIPCOptions, DerateOptions, IBCOptions,
                      LidarOptions, LQRPIOOptions, MPCLidarOptions, MPCOptions, TSOptions)
from .context import BuildContext, Built, DesignCache, Scenario, make_wind, turbine_key
from .options import REQUIRED, Options, option
from .registry import (API_NAMING, ControllerKind, Naming, Selection, cli_naming, describe,
                       get_kind, kinds, load_plugins, register, register_kind, resolve)
from .run import build_controller, run_controller

__all__ = ["builtin", "APCOptions", "BaselineOptions", "ColemanIPCOptions", "DerateOptions",
           "IBCOptions", "LidarOptions", "LQRPIOOptions", "MPCLidarOptions", "MPCOptions",
           "TSOptions", "BuildContext", "Built", "DesignCache", "Scenario", "make_wind",
           "turbine_key", "REQUIRED", "Options", "option", "API_NAMING", "ControllerKind",
           "Naming", "Selection", "cli_naming", "describe", "get_kind", "kinds", "load_plugins",
           "register", "register_kind", "resolve", "build_controller", "run_controller"]
