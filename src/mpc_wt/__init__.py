"""mpc-wt: model-based wind-turbine control design.

Controllers and their synthesis, closed-loop simulation, assessment, campaigns, export and the
``mpcwt`` command line. Builds on ``linearize`` (the plant) and ``lidar`` (wind fields and
preview). Controller kinds are registered objects: ``mpc_wt.controllers.kinds()`` lists them,
``mpc_wt.controllers.register`` adds one, :func:`run_controller` runs any of them.
"""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("mpc-wt")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

from . import controllers
from .assess import (DEFAULT_CHANNELS, assess_series, cs_measures, damage_equivalent_load,
                     lifetime_del, reductions)
from .baseline import BaselineController, BaselineGains, tune_baseline, tune_baseline_schedule
from .controllers import Scenario, register, run_controller
from .errors import (OptionsError, ResultFileError, SimulationDivergedError, SpecError,
                     SynthesisError)
from .estimator import KalmanEstimator
from .mpc import MPC, MPCSettings, MPCWeights, ScheduledMPC
from .qp import BACKENDS, default_backend
from .results import ClosedLoopResult, load_series
from .retrofit import (ColemanIPCController, IBCController, apc_reference, tune_coleman_ipc,
                       tune_ibc)
from .simulate import LidarPreview, simulate_closed_loop
from .synthesis import LQRPIOController, design_lqr, design_lqr_family, design_pi_observer
from .ts import (TSController, build_ts_model, design_ts_controller, design_ts_observer)
from .tuning.run import tune

__all__ = ["__version__", "controllers", "DEFAULT_CHANNELS", "assess_series", "cs_measures",
           "damage_equivalent_load", "lifetime_del", "reductions", "BaselineController",
           "BaselineGains", "tune_baseline", "tune_baseline_schedule", "Scenario", "register",
           "run_controller", "OptionsError", "ResultFileError", "SimulationDivergedError",
           "SpecError", "SynthesisError", "KalmanEstimator", "MPC", "MPCSettings", "MPCWeights",
           "ScheduledMPC", "BACKENDS", "default_backend", "ClosedLoopResult", "load_series",
           "ColemanIPCController", "IBCController", "apc_reference", "tune_coleman_ipc",
           "tune_ibc", "LidarPreview", "simulate_closed_loop", "LQRPIOController", "design_lqr",
           "design_lqr_family", "design_pi_observer", "TSController", "build_ts_model",
           "design_ts_controller", "design_ts_observer", "tune"]

