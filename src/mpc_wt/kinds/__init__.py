"""The controller kinds mpc-wt ships, one module per family, each kind one registration with
the registry (:mod:`mpc_wt.registry`, which imports this package before anything else
registers): its options, build, design and, for a kind that exports, its shipped law.

- :mod:`~mpc_wt.kinds.baseline`: baseline, baseline-ct, derateNN (Jonkman et al.; Pettas and
  Cheng's down-regulation);
- :mod:`~mpc_wt.kinds.ipc`: ibc and coleman-ipc, add-ons on a baseline (Pettas and Cheng);
- :mod:`~mpc_wt.kinds.mpc`: mpc, mpc-collective, mpc-lidar and the torque-law guard (Madsen
  et al.);
- :mod:`~mpc_wt.kinds.lqr`: lqr-pio (Do et al.);
- :mod:`~mpc_wt.kinds.ts`: ts (Clemens et al.);
- :mod:`~mpc_wt.kinds.apc`: apc, active power control on the baseline (Clemens et al.);
- :mod:`~mpc_wt.kinds.libraries`: discon and rosco, Bladed-style libraries in the loop;
- :mod:`~mpc_wt.kinds.lidar_ff`: lidar-ff, the CW LIDAR's collective pitch feedforward;
- :mod:`~mpc_wt.kinds.common`: what they share (the shipped law, the LIDAR's options).
"""
from mpc_wt.kinds.common import LidarOptions
from mpc_wt.kinds.baseline import BaselineOptions, DerateOptions
from mpc_wt.kinds.ipc import ColemanIPCOptions, IBCOptions
from mpc_wt.kinds.mpc import MPCLidarOptions, MPCOptions, MPCWeightOptions, TorqueLawOptions
from mpc_wt.kinds.lqr import LQRPIOOptions
from mpc_wt.kinds.ts import TSOptions
from mpc_wt.kinds.apc import APCOptions
from mpc_wt.kinds.libraries import DisconOptions, RoscoOptions
from mpc_wt.kinds.lidar_ff import LidarFFOptions

__all__ = ["LidarOptions", "BaselineOptions", "DerateOptions", "ColemanIPCOptions", "IBCOptions",
           "MPCLidarOptions", "MPCOptions", "MPCWeightOptions", "TorqueLawOptions",
           "LQRPIOOptions", "TSOptions", "APCOptions", "DisconOptions", "RoscoOptions",
           "LidarFFOptions"]
