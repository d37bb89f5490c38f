"""mpc-wt: model-based wind-turbine control design.

Controllers and their synthesis (:mod:`mpc_wt.controllers`), the registry of controller kinds
(:mod:`mpc_wt.registry`), closed-loop simulation (:mod:`mpc_wt.simulation`), assessment
(:mod:`mpc_wt.assessment`), files in and out (:mod:`mpc_wt.io`), load-case campaigns
(:mod:`mpc_wt.campaign`), tuning (:mod:`mpc_wt.tuning`) and the ``mpcwt`` command line
(:mod:`mpc_wt.cli`). Builds on :mod:`linearize` (the plant) and :mod:`lidar` (wind fields and
preview). :func:`run_controller` runs any registered kind on a scenario.
"""
from mpc_wt import controllers, registry
from mpc_wt._version import __version__
from mpc_wt.assessment.fatigue import damage_equivalent_load, lifetime_del
from mpc_wt.assessment.performance import cs_measures
from mpc_wt.assessment.series import DEFAULT_CHANNELS, assess_series, reductions
from mpc_wt.controllers.apc import apc_reference
from mpc_wt.controllers.baseline import (
                                         BaselineController,
                                         BaselineGains,
                                         tune_baseline,
                                         tune_baseline_schedule,
)
from mpc_wt.controllers.estimator import KalmanEstimator
from mpc_wt.controllers.ipc import ColemanIPCController, IBCController, tune_coleman_ipc, tune_ibc
from mpc_wt.controllers.lqr import (
                                         LQRPIOController,
                                         design_lqr,
                                         design_lqr_family,
                                         design_pi_observer,
)
from mpc_wt.controllers.mpc import MPC, MPCSettings, MPCWeights, ScheduledMPC
from mpc_wt.controllers.qp import BACKENDS, default_backend
from mpc_wt.controllers.takagi_sugeno import (
                                         TSController,
                                         build_ts_model,
                                         design_ts_controller,
                                         design_ts_observer,
)
from mpc_wt.controllers.wind_estimator import WindSpeedEstimator
from mpc_wt.errors import (
                                         OptionsError,
                                         ResultFileError, RunTooLargeError,
                                         SimulationDivergedError,
                                         SpecError,
                                         SynthesisError,
)
from mpc_wt.registry.registry import register
from mpc_wt.run import build_controller, export_discon, run_controller
from mpc_wt.simulation.loop import simulate_closed_loop
from mpc_wt.simulation.preview import LidarPreview
from mpc_wt.simulation.results import ClosedLoopResult, load_series
from mpc_wt.simulation.scenario import Scenario
from mpc_wt.tuning.run import tune

__all__ = ["__version__", "controllers", "registry", "DEFAULT_CHANNELS", "assess_series",
           "cs_measures", "damage_equivalent_load", "lifetime_del", "reductions",
           "BaselineController", "BaselineGains", "tune_baseline", "tune_baseline_schedule",
           "Scenario", "register", "run_controller", "build_controller", "OptionsError",
           "ResultFileError", "RunTooLargeError", "SimulationDivergedError", "SpecError",
           "SynthesisError",
           "KalmanEstimator", "MPC", "MPCSettings", "MPCWeights", "ScheduledMPC", "BACKENDS",
           "default_backend", "ClosedLoopResult", "load_series", "ColemanIPCController",
           "IBCController", "apc_reference", "tune_coleman_ipc", "tune_ibc", "LidarPreview",
           "simulate_closed_loop", "LQRPIOController", "design_lqr", "design_lqr_family",
           "design_pi_observer", "TSController", "build_ts_model", "design_ts_controller",
           "design_ts_observer", "WindSpeedEstimator", "tune", "export_discon"]
