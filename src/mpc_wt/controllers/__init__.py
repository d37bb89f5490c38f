"""Controllers: the designs and their synthesis, and the laws that run in Python.

Each module holds one kind of controller with its design functions (all in
``mpc_wt.controllers``): the tuned baseline PI and torque law (``baseline``, its torque curve
compiled in ``baseline_law``), Madsen's MPC (``mpc`` on the QP backends of ``qp``, the Kalman
estimator of ``estimator``), Do et al.'s LQR with a PI observer (``lqr``), Clemens et al.'s
Takagi-Sugeno controller and wind observer (``takagi_sugeno``), individual blade control and
Coleman IPC (``ipc``), active power control (``apc``), down-regulation (``derating``), LIDAR
collective pitch feedforward (``lidar_feedforward``), the rotor-effective wind from
measurements (``wind_estimator``), the supervisor (``supervisor``) and Bladed-style DISCON
libraries in the loop (``discon``, its compiled call ``discon_kernel``). A controller offers
``reset()`` and ``step(t, measurements)`` (:class:`~mpc_wt.controllers.base.Controller`); the
baseline's family (baseline, IBC, Coleman IPC, LIDAR feedforward) are designs
(:class:`~mpc_wt.controllers.base.DesignBase`) whose law is their kind's C law
(:func:`mpc_wt.run.law_controller`).

The controller kinds, their options and their builds are registered in :mod:`mpc_wt.kinds`;
the plugin API (``register``, ``Options``, ``option``, ``Built``, ``BuildContext``, ``kinds``,
``describe`` ...) is :mod:`mpc_wt.registry`.
"""
from mpc_wt.controllers.apc import apc_reference
from mpc_wt.controllers.base import Controller, ControllerBase
from mpc_wt.controllers.baseline import (
    BaselineController,
    BaselineGains,
    tune_baseline,
    tune_baseline_schedule,
)
from mpc_wt.controllers.discon import DisconController
from mpc_wt.controllers.estimator import KalmanEstimator
from mpc_wt.controllers.ipc import ColemanIPCController, IBCController, tune_coleman_ipc, tune_ibc
from mpc_wt.controllers.lidar_feedforward import LidarFeedforward
from mpc_wt.controllers.lqr import (
    LQRPIOController,
    design_lqr,
    design_lqr_family,
    design_pi_observer,
)
from mpc_wt.controllers.mpc import (MPC, MPCSettings, MPCWeights, ScheduledMPC,
                                    drivetrain_frequency)
from mpc_wt.controllers.qp import BACKENDS, default_backend
from mpc_wt.controllers.scheduling import RegionFloor, WindSchedule, envelope_winds, region3_wind
from mpc_wt.controllers.supervisor import Supervisor, TorqueLawGuard
from mpc_wt.controllers.takagi_sugeno import (
    TSController,
    build_ts_model,
    design_ts_controller,
    design_ts_observer,
)
from mpc_wt.controllers.wind_estimator import WindEstimatorSettings, WindSpeedEstimator

__all__ = ["apc_reference", "Controller", "ControllerBase", "BaselineController",
           "BaselineGains", "tune_baseline", "tune_baseline_schedule", "DisconController",
           "KalmanEstimator", "ColemanIPCController", "IBCController", "tune_coleman_ipc",
           "tune_ibc", "LidarFeedforward", "LQRPIOController", "design_lqr",
           "design_lqr_family", "design_pi_observer", "MPC", "MPCSettings", "MPCWeights",
           "ScheduledMPC", "drivetrain_frequency", "RegionFloor", "WindSchedule",
           "envelope_winds", "region3_wind", "BACKENDS", "default_backend", "Supervisor",
           "TorqueLawGuard",
           "TSController", "build_ts_model", "design_ts_controller", "design_ts_observer",
           "WindEstimatorSettings", "WindSpeedEstimator"]
