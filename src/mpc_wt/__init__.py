"""mpc-wt: model-based wind-turbine control design.

Controllers and their synthesis (:mod:`mpc_wt.controllers`), the registry of controller kinds
(:mod:`mpc_wt.registry`), closed-loop simulation (:mod:`mpc_wt.simulation`), assessment
(:mod:`mpc_wt.assessment`), files in and out (:mod:`mpc_wt.io`), load-case campaigns
(:mod:`mpc_wt.campaign`), tuning (:mod:`mpc_wt.tuning`) and the ``mpcwt`` command line
(:mod:`mpc_wt.cli`). Builds on :mod:`linearize` (the plant) and :mod:`lidar` (wind fields and
preview). :func:`run_controller` runs any registered kind on a scenario.
"""
import importlib
from typing import Any

from mpc_wt._version import __version__

#: where each public name lives: imported on first use, so that ``import mpc_wt`` (and
#: ``mpcwt --version``) does not load the whole toolkit
_WHERE = {
    "controllers": "mpc_wt.controllers",
    "registry": "mpc_wt.registry",
    "damage_equivalent_load": "mpc_wt.assessment.fatigue",
    "lifetime_del": "mpc_wt.assessment.fatigue",
    "cs_measures": "mpc_wt.assessment.performance",
    "DEFAULT_CHANNELS": "mpc_wt.assessment.series",
    "assess_series": "mpc_wt.assessment.series",
    "reductions": "mpc_wt.assessment.series",
    "apc_reference": "mpc_wt.controllers.apc",
    "BaselineController": "mpc_wt.controllers.baseline",
    "BaselineGains": "mpc_wt.controllers.baseline",
    "tune_baseline": "mpc_wt.controllers.baseline",
    "tune_baseline_schedule": "mpc_wt.controllers.baseline",
    "KalmanEstimator": "mpc_wt.controllers.estimator",
    "ColemanIPCController": "mpc_wt.controllers.ipc",
    "IBCController": "mpc_wt.controllers.ipc",
    "tune_coleman_ipc": "mpc_wt.controllers.ipc",
    "tune_ibc": "mpc_wt.controllers.ipc",
    "LQRPIOController": "mpc_wt.controllers.lqr",
    "design_lqr": "mpc_wt.controllers.lqr",
    "design_lqr_family": "mpc_wt.controllers.lqr",
    "design_pi_observer": "mpc_wt.controllers.lqr",
    "MPC": "mpc_wt.controllers.mpc",
    "MPCSettings": "mpc_wt.controllers.mpc",
    "MPCWeights": "mpc_wt.controllers.mpc",
    "ScheduledMPC": "mpc_wt.controllers.mpc",
    "BACKENDS": "mpc_wt.controllers.qp",
    "default_backend": "mpc_wt.controllers.qp",
    "TSController": "mpc_wt.controllers.takagi_sugeno",
    "build_ts_model": "mpc_wt.controllers.takagi_sugeno",
    "design_ts_controller": "mpc_wt.controllers.takagi_sugeno",
    "design_ts_observer": "mpc_wt.controllers.takagi_sugeno",
    "WindSpeedEstimator": "mpc_wt.controllers.wind_estimator",
    "OptionsError": "mpc_wt.errors",
    "ResultFileError": "mpc_wt.errors",
    "RunTooLargeError": "mpc_wt.errors",
    "SimulationDivergedError": "mpc_wt.errors",
    "SpecError": "mpc_wt.errors",
    "SynthesisError": "mpc_wt.errors",
    "register": "mpc_wt.registry.registry",
    "build_controller": "mpc_wt.run",
    "export_discon": "mpc_wt.run",
    "law_controller": "mpc_wt.run",
    "estimate_wind": "mpc_wt.run",
    "run_controller": "mpc_wt.run",
    "simulate_closed_loop": "mpc_wt.simulation.loop",
    "LidarPreview": "mpc_wt.simulation.preview",
    "ClosedLoopResult": "mpc_wt.simulation.results",
    "load_series": "mpc_wt.simulation.results",
    "Scenario": "mpc_wt.simulation.scenario",
    "tune": "mpc_wt.tuning.run",
}

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
           "design_ts_observer", "WindSpeedEstimator", "tune", "export_discon",
           "law_controller", "estimate_wind"]


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use."""
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module 'mpc_wt' has no attribute {name!r}")
    module = importlib.import_module(where)
    value = module if where == f"mpc_wt.{name}" else getattr(module, name)
    globals()[name] = value
    return value
