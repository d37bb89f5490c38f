"""Controllers designed in mpc-wt exported as Bladed-style controller libraries (``DISCON``),
to run in OpenFAST's ServoDyn, in Bladed or in any host of that interface.

An export is a folder with the C sources of the controller (the Bladed entry point, the
reader of its input file and the control law), a ``Makefile``, the input file that holds
every number of the design (a user changes a gain there without recompiling), a ServoDyn
input file for the turbine's packaged OpenFAST deck that points at the library, and the
library itself when a C compiler is found (``cc``, or ``$CC``).

The design is the one mpc-wt runs: :func:`mpc_wt.run.export_discon` builds the controller through
the registry (as every run does) and :func:`export_controller` writes its numbers out, so the
library and the Python controller are the same law (checked step by step in the tests).

The library's interface (``DISCON(avrSWAP, aviFAIL, accINFILE, avcOUTNAME, avcMSG)``), the swap
records it reads and writes, and its behaviour on errors are described in the guide
"Run your mpc-wt controller in OpenFAST".
"""
from __future__ import annotations

import dataclasses
import datetime as _dt
import hashlib
import importlib.resources
import logging
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

import linearize
from mpc_wt.errors import ControllerLibraryError

__all__ = ["DisconExport", "EXPORTABLE", "REBUILT", "export_controller", "export_design", "controller_input",
           "check_exportable", "prepare_sources", "shipped_library", "shipped_input",
           "LOG_CHANNELS", "log_channels",
           "build_library",
           "find_compiler", "library_name", "servodyn_input", "SWAP_READ", "SWAP_WRITTEN"]

log = logging.getLogger(__name__)

#: The controller kinds that export, and what each becomes.
EXPORTABLE: dict[str, str] = {
    "baseline": "the tuned PI pitch loop and torque law, constant power in region III",
    "baseline-ct": "the baseline with constant torque in region III",
    "mpc": "Madsen's individual-pitch MPC scheduled from cut-in to cut-out on the estimated "
           "wind, with its Kalman estimator and the QP solved by DAQP",
    "mpc-collective": "the scheduled MPC with collective pitch",
    "mpc-lidar": "the scheduled MPC with the per-blade preview of a hub-mounted CW LIDAR, read "
                 "from OpenFAST's lidar records",
    "baseline+lidar-ff": "the baseline with the collective pitch feedforward of a hub-mounted "
                         "CW LIDAR, read from OpenFAST's lidar records",
    "lqr-pio": "Do et al.'s LQR on PI-observer estimates, scheduled from cut-in to cut-out on "
               "the estimated wind, observing generator speed, tower-top acceleration and the "
               "blade root moments",
    "ts": "Clemens et al.'s Takagi-Sugeno controller and wind observer, observing the tower-top "
          "accelerations and the rotor and generator speeds",
    "ibc": "Pettas and Cheng's individual blade control on the baseline: each blade's root "
           "moment filtered, scaled by the gain scheduled on the mean pitch, faded in with the "
           "power",
}

#: The kinds whose export builds the controller again from the options of their design
#: (``mpcwt design`` keeps those, not the controller's numbers); the baseline exports from its
#: gain table.
REBUILT = frozenset(EXPORTABLE) - {"baseline", "baseline-ct"}

#: Library kinds (the input file's ``kind``) of the exported controller kinds.
_LIBRARY_KIND = {"baseline": "baseline", "baseline-ct": "baseline", "mpc": "mpc",
                 "mpc-collective": "mpc", "mpc-lidar": "mpc", "baseline+lidar-ff": "baseline",
                 "lqr-pio": "lqr", "ts": "ts", "ibc": "baseline"}

#: The logging channels each exported kind's library returns (records 65 and 63 on), in
#: order: the signals a shipped run records beside the host's (the C laws fill them,
#: ``mw_cmd.log``).
_MPC_LOG = ("qp_fallback", "qp_solve_ms", "schedule_wind", "schedule_grid_wind")
LOG_CHANNELS: dict[str, tuple[str, ...]] = {
    "mpc": _MPC_LOG, "mpc-collective": _MPC_LOG, "mpc-lidar": _MPC_LOG,
    "lqr-pio": ("region", "schedule_wind", "schedule_grid_wind"),
    "ts": ("wind_est", "premise_clipped"),
    "baseline+lidar-ff": ("ff_wind", "ff_pitch", "ff_mean_wind", "ff_corner"),
    "ibc": ("ibc_weight", "ibc_gain", "ibc_pitch_1", "ibc_pitch_2", "ibc_pitch_3"),
}


def log_channels(kind: str) -> tuple[str, ...]:
    """The logging channels of a kind's library (:data:`LOG_CHANNELS`).

    Parameters
    ----------
    kind : str
        An exportable kind.

    Returns
    -------
    tuple of str
        Empty for a library that returns none.
    """
    check_exportable(kind)
    return LOG_CHANNELS.get(kind, ())


#: The measured signals of the Kalman filter (MPC) and the observer (LQR-PIO) and their codes
#: in the library.
_SIGNAL_CODES = {"rotor_speed": 0, "gen_speed": 1, "pitch_1": 2, "pitch_2": 3, "pitch_3": 4,
                 "flap_moment_1": 5, "flap_moment_2": 6, "flap_moment_3": 7,
                 "tower_fa_acceleration": 8, "tower_ss_acceleration": 9}

#: The swap records the library reads (1-based, as the interface numbers them).
SWAP_READ: dict[int, str] = {
    1: "status (0 first call, 1 running, -1 last call)", 2: "time of the first call [s]",
    3: "communication interval [s] (checked against the design's)",
    4: "blade 1 pitch [rad]", 33: "blade 2 pitch [rad]", 34: "blade 3 pitch [rad]",
    20: "generator speed [rad/s]", 21: "rotor speed [rad/s] (MPC, LQR-PIO, TS)",
    23: "measured generator torque [N m] (MPC, LQR-PIO)",
    30: "blade 1 root out-of-plane moment [N m] (MPC, LQR-PIO, IBC; 31, 32 blades 2, 3)",
    15: "measured electrical power [W] (IBC)",
    53: "tower-top fore-aft acceleration [m/s^2] (MPC, LQR-PIO, TS)",
    54: "tower-top side-side acceleration [m/s^2] (TS)", 49: "length of avcMSG",
    50: "length of accINFILE", 51: "length of avcOUTNAME",
    129: "swap array length (the lidar block is read when it reaches record 2007)",
    2002: "lidar beams (3; the LIDAR kinds)", 2003: "lidar pulse gates (1)",
    2005: "beam 1 line-of-sight speed [m/s] (2006, 2007 beams 2, 3)"}

#: The swap records the library writes.
SWAP_WRITTEN: dict[int, str] = {
    35: "generator contactor (1)", 36: "shaft brake (0: off)",
    41: "yaw actuator torque demand (0)", 42: "blade 1 pitch demand [rad]",
    43: "blade 2 pitch demand [rad]", 44: "blade 3 pitch demand [rad]",
    45: "collective pitch demand (the blades' mean) [rad]",
    47: "generator torque demand [N m]", 48: "yaw rate demand (0)",
    55: "pitch override (0: off)", 56: "torque override (0: off)", 65: "logging channels (0)"}

_SOURCES = ("mpcwt_discon.h", "input.c", "baseline.c", "ibc.c", "windest.c", "lqr.c", "ts.c",
            "discon.c")
_MPC_SOURCE = "mpc.c"
_DAQP = "daqp"
_CFLAGS = "-O2 -std=c99 -Wall -fPIC -fvisibility=hidden"
_SANITIZE = "-O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined " \
            "-fno-sanitize-recover=all"


@dataclasses.dataclass(frozen=True)
class DisconExport:
    """What an export wrote (:func:`export_controller`, :func:`mpc_wt.run.export_discon`).

    Parameters
    ----------
    kind : str
        The controller kind.
    directory : Path
        The export folder.
    input_file : Path
        The controller's input file (``accINFILE``, ServoDyn's ``DLL_InFile``).
    sources : tuple of Path
        The C sources and header.
    makefile : Path
        ``make`` builds the library with the system's C compiler.
    library : Path or None
        The built library (None when it was not built: see ``note``).
    servodyn : Path or None
        A ServoDyn input file of the turbine's packaged OpenFAST deck pointing at the library
        (None when no deck is packaged for the turbine: see ``note``).
    dt : float
        The communication interval the design runs at [s] (ServoDyn's ``DLL_DT``).
    note : str
        What was not done and why (empty when everything was).
    """

    kind: str
    directory: Path
    input_file: Path
    sources: tuple[Path, ...]
    makefile: Path
    library: Path | None
    servodyn: Path | None
    dt: float
    note: str = ""

    def files(self) -> list[Path]:
        """Every file the export wrote: the input file, the library and the ServoDyn file
        (when made), the Makefile and the sources.

        Returns
        -------
        list of Path
        """
        made = [f for f in (self.library, self.servodyn) if f is not None]
        return [self.input_file, *made, self.makefile, *self.sources]


def library_name(kind: str) -> str:
    """The file name of an exported library on this platform (``libmpcwt_<kind>.so``,
    ``.dylib`` on macOS, ``mpcwt_<kind>.dll`` on Windows).

    Parameters
    ----------
    kind : str
        The controller kind.

    Returns
    -------
    str
    """
    stem = _stem(kind)
    if sys.platform == "win32":
        return stem + ".dll"
    return "lib" + stem + (".dylib" if sys.platform == "darwin" else ".so")


def _stem(kind: str) -> str:
    """The file stem of a kind's export (``mpcwt_baseline_lidar_ff``)."""
    return "mpcwt_" + kind.replace("-", "_").replace("+", "_")


def find_compiler() -> str | None:
    """The C compiler the export builds with: ``$CC`` if set, else the first of ``cc``,
    ``gcc``, ``clang`` on the path.

    Returns
    -------
    str or None
        Its path, or None when there is none.
    """
    env = os.environ.get("CC")
    if env:
        found = shutil.which(env.split()[0])
        return found
    for name in ("cc", "gcc", "clang"):
        found = shutil.which(name)
        if found:
            return found
    return None


def _fmt(v: float) -> str:
    return "0" if v == 0.0 else repr(float(v))


def _baseline_entries(ctl: Any, prefix: str = "") -> list[tuple[str, Any, str]]:
    """The numbers of a :class:`~mpc_wt.controllers.baseline.BaselineController` as input-file
    entries (key, value, unit and meaning)."""
    from mpc_wt.controllers.baseline import BaselineController

    if type(ctl) is not BaselineController:
        raise ValueError(f"the baseline export takes a BaselineController, got "
                         f"{type(ctl).__name__}")
    if ctl.power_reference is not None or ctl._sched_f is not None:
        raise ValueError("a baseline with a power reference or a gain schedule (active power "
                         "control) does not export yet: export the plain design")
    g, tb = ctl.gains, ctl.turbine
    rows = [
        ("dt", ctl.dt, "communication interval [s] (ServoDyn DLL_DT)"),
        ("speed_filter_corner_hz", ctl.wc / (2 * math.pi),
         "generator-speed low-pass corner [Hz]"),
        ("gen_speed_setpoint", g.rated_gen_speed_rad_s, "PI speed set-point [rad/s]"),
        ("kp", g.kp, "proportional gain at fine pitch [s]"),
        ("ki", g.ki, "integral gain at fine pitch [-]"),
        ("theta_k", g.theta_k_rad, "pitch at which the gain has halved [rad]"),
        ("pitch_min", ctl.pitch_min, "minimum pitch command [rad]"),
        ("pitch_max", ctl.pitch_max, "maximum pitch command [rad]"),
        ("pitch_rate_max", ctl.rate, "pitch-rate limit [rad/s]"),
        ("torque_rate_max", ctl.tq_rate, "generator-torque rate limit [N m/s]"),
        ("torque_max", ctl.tq_max, "maximum generator torque [N m]"),
        ("gen_speed_cutin", ctl.w_cutin, "region 1.5 starts [rad/s]"),
        ("gen_speed_region2", ctl.w_rgn2, "region 2 starts [rad/s]"),
        ("gen_speed_transition", ctl.w_trans, "region 2.5 starts [rad/s]"),
        ("gen_speed_rated", ctl.w_rated, "region 3 speed [rad/s]"),
        ("gen_speed_sync", ctl.w_sync, "region 2.5 line's zero-torque speed [rad/s]"),
        ("slope_region15", ctl.slope15, "region 1.5 torque slope [N m s/rad]"),
        ("slope_region25", ctl.slope25, "region 2.5 torque slope [N m s/rad]"),
        ("k_opt", g.k_opt, "region 2 torque gain [N m s^2/rad^2]"),
        ("torque_cap", ctl.tq_cap, "largest torque below rated [N m]"),
        ("rated_power", g.rated_power, "rated electrical power [W]"),
        ("gen_efficiency", tb.drivetrain.generator_efficiency, "generator efficiency [-]"),
        ("rated_torque", g.rated_torque, "region 3 torque (constant torque) [N m]"),
        ("region3_constant_power", float(ctl.region3 == "constant_power"),
         "1: constant power above rated, 0: constant torque"),
    ]
    rows += [
        ("min_pitch_speeds", np.array(ctl.min_pitch_speeds, float),
         "minimum-pitch schedule: filtered generator speeds [rad/s]"),
        ("min_pitch_offsets", np.array(ctl.min_pitch_offsets, float),
         "minimum-pitch schedule: pitch above pitch_min [rad]"),
    ]
    return [(prefix + k, v, doc) for k, v, doc in rows]


def _ibc_entries(ctl: Any) -> list[tuple[str, Any, str]]:
    """An :class:`~mpc_wt.controllers.ipc.IBCController` on the baseline: the baseline's law
    and the IBC's gain schedule, filters (second-order sections and their unit-step states),
    power fade-in and limits."""
    from mpc_wt.controllers.ipc import IBCController

    if type(ctl) is not IBCController:
        raise ValueError(f"the IBC export takes an IBCController, got {type(ctl).__name__}")
    g = ctl.gains
    return _baseline_entries(ctl.collective) + [
        ("feedforward", 0.0, "no LIDAR feedforward"),
        ("ibc", 1.0, "1: individual blade control on the collective command"),
        ("ibc_settings", np.array([g.weight_range[0], g.weight_range[1], g.rated_power,
                                   math.exp(-ctl.dt / ctl.power_tau), ctl.pitch_min,
                                   ctl.pitch_max, ctl.step_max / ctl.dt,
                                   float(ctl.remove_collective),
                                   min(g.max_amplitude_rad, 1e300)], float),
         "the fade-in's power fractions [-], the power it refers to [W], the power filter's "
         "pole, pitch min, max [rad], pitch rate [rad/s], 1: the blades' mean removed, each "
         "blade's largest IBC pitch [rad] (1e300: none)"),
        ("ibc_gain_pitch", np.asarray(g.pitch_rad, float), "mean pitch of the gain schedule "
                                                           "[rad]"),
        ("ibc_gain", np.asarray(g.gain, float), "gain [rad/(N m)]"),
        ("ibc_input_sos", ctl._hp.sos.ravel(), "input (high-pass) sections b0 b1 b2 a0 a1 a2"),
        ("ibc_input_zi", np.asarray(ctl._hp._zi1, float).ravel(),
         "their state at a unit input's steady state"),
        ("ibc_output_sos", ctl._bs.sos.ravel(), "output (band-stop, low-pass) sections"),
        ("ibc_output_zi", np.asarray(ctl._bs._zi1, float).ravel(),
         "their state at a unit input's steady state"),
    ]


def _ff_entries(ctl: Any) -> list[tuple[str, Any, str]]:
    """A :class:`~mpc_wt.controllers.lidar_feedforward.LidarFeedforward` on the baseline: the
    baseline's law and the feedforward's LIDAR processing, filter, lead and pitch curve."""
    from mpc_wt.controllers.lidar_feedforward import LidarFeedforward

    if type(ctl) is not LidarFeedforward:
        raise ValueError(f"the feedforward export takes a LidarFeedforward, got "
                         f"{type(ctl).__name__}")
    inst = ctl.sensor.instrument
    return _baseline_entries(ctl.base) + [
        ("feedforward", 1.0, "1: the LIDAR's collective pitch feedforward"),
        ("ff", np.array([math.cos(inst.cone_angle_rad), inst.focus_distance, ctl.sample_dt,
                         ctl.mean_time_constant, ctl.tau_act,
                         -1.0 if ctl.lead_given is None else ctl.lead_given, ctl.order], float),
         "cos(cone), focus distance [m], LIDAR sample period [s], the mean wind's averaging "
         "time [s], pitch actuator time constant [s], a fixed lead [s] (-1: from the filter), "
         "filter order"),
        ("ff_corner_winds", np.asarray(ctl.corner_winds, float), "mean winds of the filter "
                                                                 "corners [m/s]"),
        ("ff_corners", np.asarray(ctl.corners, float), "filter corners [rad/s]"),
        ("ff_curve_winds", np.asarray(ctl.curve_v, float), "winds of the static pitch curve "
                                                           "[m/s]"),
        ("ff_curve_pitch", np.asarray(ctl.curve_pitch, float), "static pitch [rad]"),
    ]


def _mpc_point(m: Any, k: int, signals: tuple[str, ...]) -> list[tuple[str, Any, str]]:
    """One grid point of a scheduled MPC: its QP's packed step data, matrices and Kalman
    filter."""
    from mpc_wt.controllers.estimator import KalmanEstimator

    if m.formulation != "condensed" or m.backend != "daqp":
        raise ValueError(f"the MPC exports with the condensed formulation solved by DAQP; grid "
                         f"point {k} has {m.formulation!r} with {m.backend!r}")
    est = m.estimator
    if not isinstance(est, KalmanEstimator) or est.signals != signals:
        raise ValueError("the MPC exports with its Kalman estimator (estimator='kalman') on "
                         "the same measured signals at every grid point")
    nx, nd, nu = m._nx, m._nd, m._nu
    ny, nb, nz = m._wt.shape[1], len(m._bconst), len(m._z)
    head = [int(v) for v in m._im[:9]]
    sizes = [nx, nd, nu, ny, nb, m._map_nv, nz, m._nzd, m._nvu, m.hp, m.hu, m._slack0,
             len(m.model.outputs), int(m.collective)]
    if head != [m._nzd, m._slack0, nx, nd, ny, nb, m._map_nv, nu, nz]:
        raise ValueError(f"grid point {k}: the MPC's packed step data is not laid out as the "
                         f"library reads it ({head})")
    z_init = np.zeros(nz)
    z_init[0] = 1.0
    p = f"point.{k}."
    a_gen = np.asarray(m._a_gen_s, float)
    return [
        (p + "sizes", np.array(sizes, float),
         "n_x n_d n_u n_y n_bounds n_v n_z n_z_data n_v_inputs H_p H_u first_slack n_outputs "
         "collective"),
        (p + "im", np.asarray(m._im, float), "packed integers: sizes, state index, bound rows, "
                                             "command columns"),
        (p + "fc", np.asarray(m._fc, float), "packed constants: x0, d0, bound constants and "
                                             "signs, input scales, u0"),
        (p + "wt", np.asarray(m._wt, float).ravel(), "the step's affine map Y, transposed "
                                                     "(n_z x n_y, row-major)"),
        (p + "z_init", z_init, "the step data at a reset"),
        (p + "su", np.asarray(m._su, float), "variable scales"),
        (p + "u0", np.asarray(m.model.u0, float), "operating point inputs [rad, rad, rad, N m]"),
        (p + "z0", np.asarray(m.model.z0, float), "operating point outputs"),
        (p + "x0d0", np.concatenate([m.model.x0, m.model.d0]).astype(float),
         "operating point states and winds"),
        (p + "up0", np.asarray(m._up0, float), "previous command deviation at the start"),
        (p + "h", np.asarray(m._h_s, float).ravel(), "QP Hessian (scaled, row-major)"),
        (p + "n_box", float(m._n_box), "simple bounds (the first QP rows)"),
        (p + "a", a_gen.ravel(), "QP general constraint rows (scaled, row-major)"),
        (p + "limits", np.asarray(m._limits, float), "pitch min, max [rad], torque min, max "
                                                     "[N m]"),
        (p + "kalman.n_ny", np.array([est.a.shape[0], len(est.signals)], float),
         "Kalman filter states and measurements"),
        (p + "kalman.a", est.a.ravel(), "Kalman A"), (p + "kalman.b", est.b.ravel(), "B"),
        (p + "kalman.c", est.c.ravel(), "C"), (p + "kalman.d", est.d.ravel(), "D"),
        (p + "kalman.gain", est.gain.ravel(), "steady-state gain"),
        (p + "kalman.y0", np.asarray(est.y0, float), "operating point measurements"),
    ]


def _windest_entries(est: Any, prefix: str) -> list[tuple[str, Any, str]]:
    tx, ty, c, kx, ky = est._spline
    k = np.concatenate([est._k, [est.settings.speed_std ** 2, 1.0]])
    return [
        (prefix + "spline_degrees", np.array([kx, ky], float), "C_P spline degrees"),
        (prefix + "spline_tx", np.asarray(tx, float), "C_P spline knots in tip-speed ratio"),
        (prefix + "spline_ty", np.asarray(ty, float), "C_P spline knots in pitch [rad]"),
        (prefix + "spline_c", np.asarray(c, float), "C_P spline coefficients"),
        (prefix + "constants", k,
         "radius [m], air density [kg/m^3], gearbox ratio, inertia [kg m^2], dt [s], process "
         "noise of speed and wind, speed noise, wind range [m/s], tip-speed ratio range, "
         "initial variances of speed and wind"),
    ]


def _preview_entries(preview: Any, horizon: int) -> list[tuple[str, Any, str]]:
    """A :class:`~mpc_wt.simulation.preview.LidarPreview`'s processing as input-file
    entries (the instrument's cone and focus, the mean wind's averaging, the preview time)."""
    inst = preview.sensor.instrument
    if getattr(inst, "noise_std", 0.0) > 0:
        log.warning("the LIDAR's measurement noise is the simulator's; the library reads "
                    "whatever the host's LIDAR measures")
    return [("lidar_preview", 1.0, "1: the LIDAR's per-blade preview (records 2001-2016)"),
            ("lidar_horizon", float(preview.horizon), "preview steps"),
            ("lidar", np.array([math.cos(inst.cone_angle_rad), inst.focus_distance,
                                preview.min_wind, preview.mean_time_constant,
                                -1.0 if preview.fixed is None else preview.fixed], float),
             "cos(cone), focus distance [m], lowest mean wind for the preview time [m/s], the "
             "mean wind's averaging time [s], a fixed preview time [s] (-1: D / measured mean)")]


def _mpc_entries(ctl: Any, preview: Any = None) -> list[tuple[str, Any, str]]:
    """The numbers of a :class:`~mpc_wt.controllers.mpc.ScheduledMPC` (and its LIDAR preview)
    as input-file entries."""
    from mpc_wt.controllers.mpc import ScheduledMPC

    if type(ctl) is not ScheduledMPC:
        raise ValueError(f"the MPC export takes a ScheduledMPC, got {type(ctl).__name__}")
    if ctl.wind_source != "estimator" and preview is None:
        raise ValueError("an MPC scheduled on its LIDAR's measurement exports with its LIDAR "
                         "preview (export the kind 'mpc-lidar' through mpc_wt.run."
                         "export_discon)")
    n = len(ctl._grid)
    pts = [ctl.controller(k) for k in range(n)]
    if pts[0].estimator is None:
        raise ValueError("an MPC on the plant's true states (estimator 'full-state') does not "
                         "export: a controller library has its measurements only (the "
                         "default estimator, 'kalman', does)")
    signals = pts[0].estimator.signals
    sched = ctl.schedule
    budget = ctl.settings.time_budget_ms
    rows: list[tuple[str, Any, str]] = [
        ("dt", ctl.dt, "controller period [s] (ServoDyn DLL_DT)"),
        ("n_points", float(n), "designs over the wind"),
        ("n_outputs", float(len(ctl._z_trim[0])), "performance outputs of each design"),
        ("power_output", float(ctl._ip), "the generator power's index among them"),
        ("power_efficiency", ctl._eff, "power / (torque x generator speed) at the trim"),
        ("target_time_constant", -1.0 if ctl.target_tau is None else float(ctl.target_tau),
         "low-pass of the wind whose trim the cost tracks [s] (-1: each design's own)"),
        ("qp_time_budget_ms", 0.0 if budget is None else float(budget),
         "a QP over this time takes the fallback [ms] (0: no budget)"),
        ("torque_law", float(ctl._law is not None), "1: the target torque from the baseline's "
                                                    "schedule"),
        ("kalman_signals", _signal_codes(signals, "Kalman filter"),
         "measured: " + ", ".join(signals)),
        ("schedule.grid", np.asarray(ctl._grid, float), "the designs' winds [m/s]"),
        ("schedule.time_constant_hysteresis", np.array([sched.tau, sched.hyst], float),
         "low-pass of the scheduling wind [s], hysteresis [m/s]"),
        *_windest_entries(sched.estimator, "schedule.windest."),
        *_floor_entries(sched.floor, "schedule."),
        ("trim_z", np.asarray(ctl._z_trim, float).ravel(), "the trim's outputs over the grid"),
        ("trim_u", np.asarray(ctl._u_trim, float).ravel(), "the trim's inputs over the grid"),
    ]
    if ctl._law is not None:
        lt = ctl._law
        rows += _baseline_entries(ctl.torque_law, "law.")
        rows.append(("law_torque", np.array([lt._a, lt._offset, lt._lo, lt._hi], float),
                     "speed filter pole, below-rated pitch offset [rad], torque min, max "
                     "[N m]"))
    notch = ctl._notch
    rows.append(("torque_notch", float(notch is not None),
                 "1: a notch on the torque command (the estimator is given the filtered torque)"))
    if notch is not None:
        rows += [("torque_notch_sos", notch.sos.ravel(),
                  f"its sections b0 b1 b2 a0 a1 a2 (centres "
                  f"{', '.join(f'{f:.6g}' for f in (ctl.torque_notch_hz, ctl.tower_notch_hz) if f is not None)}"
                  f" Hz, Q {ctl.torque_notch_q:g})"),
                 ("torque_notch_zi", np.asarray(notch._zi1, float).ravel(),
                  "their state at a unit input's steady state"),
                 ("torque_notch_rate", float(ctl.turbine.generator.max_torque_rate),
                  "the filtered torque's largest rate [N m/s]")]
    rows += _preview_entries(preview, ctl.settings.horizon) if preview is not None else \
        [("lidar_preview", 0.0, "no LIDAR")]
    for k, m in enumerate(pts):
        rows += _mpc_point(m, k, signals)
    return rows


def _floor_entries(floor: Any, pre: str) -> list[tuple[str, Any, str]]:
    """A schedule's region floor (:class:`~mpc_wt.controllers.scheduling.RegionFloor`)."""
    if floor is None:
        return [(pre + "region_floor", 0.0, "0: the designs chosen by the measured wind alone")]
    return [(pre + "region_floor", 1.0, "1: at least the design the measured pitch and rotor "
                                        "speed tell"),
            (pre + "floor_winds", np.asarray(floor.winds, float),
             "the trim's pitch curve above rated: winds [m/s]"),
            (pre + "floor_pitches", np.asarray(floor.pitches, float),
             "... and their collective pitch [rad]"),
            (pre + "floor_limits", np.array([floor.pitch_threshold,
                                             floor.pitch_min_speed * floor.rated_speed,
                                             floor.speed_margin * floor.rated_speed,
                                             floor.region3_wind], float),
             "a pitch above [rad] with the rotor above [rad/s]; a rotor speed above [rad/s] "
             "and the design wind then [m/s]")]


def _signal_codes(signals: Sequence[str], who: str) -> np.ndarray:
    unknown = [s for s in signals if s not in _SIGNAL_CODES]
    if unknown:
        raise ValueError(f"the {who} measures {unknown}, which the library does not read from "
                         f"the swap array (it reads {sorted(_SIGNAL_CODES)})")
    return np.array([_SIGNAL_CODES[s] for s in signals], float)


def _lqr_point(c: Any, k: int) -> list[tuple[str, Any, str]]:
    """One design of a scheduled LQR-PIO: its discretized observer, gains and operating
    point."""
    law = c._law
    nx, nf = c._nx, c._nf
    p = f"point.{k}."
    return [
        (p + "sizes", np.array([nx, nf, len(c.obs.measured), c._nu_all, len(c._iu),
                                2 if c.region == "II" else 3, float(law is not None)], float),
         "n_x n_f n_y n_u n_gain region has_torque_law"),
        (p + "ad", c._ad.ravel(), "observer A_d (n_x + n_f square, row-major)"),
        (p + "bd", c._bd.ravel(), "observer B_d: [u_dev; y - y0] columns (row-major)"),
        (p + "gain", c._gain.ravel(), "[K K_f] on the estimate (n_gain x (n_x + n_f))"),
        (p + "gain_inputs", np.asarray(c._iu, float), "the inputs the gain rows command"),
        (p + "y0", np.asarray(c.obs.y0, float), "operating point measurements"),
        (p + "u0", np.asarray(c.model.u0, float), "operating point inputs [rad, rad, rad, N m]"),
        (p + "x0d0", np.concatenate([c.model.x0, np.asarray(c.model.d0)[:nf]]).astype(float),
         "operating point states and unknown inputs"),
        (p + "k_opt", 0.0 if c.k_opt is None else float(c.k_opt),
         "region II torque gain without a torque law [N m s^2/rad^2]"),
    ]


def _lqr_entries(ctl: Any) -> list[tuple[str, Any, str]]:
    """The numbers of a :class:`~mpc_wt.controllers.lqr.ScheduledLQRPIO` as input-file
    entries: the wind schedule, the torque law and every design's observer and gains."""
    from mpc_wt.controllers.lqr import ScheduledLQRPIO

    if type(ctl) is not ScheduledLQRPIO:
        raise ValueError(f"the LQR-PIO export takes the scheduled design (ScheduledLQRPIO), got "
                         f"{type(ctl).__name__}: leave design_wind_mps unset")
    pts = ctl.controllers
    signals = pts[0].obs.measured
    if any(c.obs.measured != signals for c in pts):
        raise ValueError("the LQR-PIO exports with the same measured signals at every design")
    codes = _signal_codes(signals, "PI observer")
    sched, c0 = ctl.schedule, pts[0]
    pa, g = c0.turbine.pitch_actuator, c0.turbine.generator
    reach = c0._reach if math.isfinite(c0._reach) else -1.0
    rows: list[tuple[str, Any, str]] = [
        ("dt", ctl.dt, "controller period [s] (ServoDyn DLL_DT)"),
        ("n_points", float(len(pts)), "designs over the wind"),
        ("signals", codes, "measured: " + ", ".join(signals)),
        ("limits", np.array([pa.min_pitch_rad, pa.max_pitch_rad, g.min_torque, g.max_torque,
                             reach], float),
         "pitch min, max [rad], torque min, max [N m], how far a pitch command may lead the "
         "measured pitch [rad] (-1: no bound)"),
        ("schedule.grid", np.asarray(ctl.winds, float), "the designs' winds [m/s]"),
        ("schedule.time_constant_hysteresis", np.array([sched.tau, sched.hyst], float),
         "low-pass of the scheduling wind [s], hysteresis [m/s]"),
        *_windest_entries(sched.estimator, "schedule.windest."),
    ]
    laws = [c._law for c in pts if c._law is not None]
    if laws:
        lt = laws[0]
        first = _baseline_entries(lt.law, "law.")
        ref = np.concatenate([np.atleast_1d(v) for _, v, _ in first] + [[lt._a, lt._offset]])
        for x in laws[1:]:
            other = np.concatenate([np.atleast_1d(v) for _, v, _ in
                                    _baseline_entries(x.law, "law.")] + [[x._a, x._offset]])
            if ref.shape != other.shape or not np.array_equal(ref, other, equal_nan=True):
                raise ValueError("the LQR-PIO exports with one torque law for every design")
        rows += _law_entries(lt)
    for k, c in enumerate(pts):
        rows += _lqr_point(c, k)
    return rows


def _law_entries(law: Any) -> list[tuple[str, Any, str]]:
    """A :class:`~mpc_wt.controllers.baseline.LawTorque` (the baseline's torque schedule in
    another controller) as input-file entries."""
    return _baseline_entries(law.law, "law.") + [
        ("law_torque", np.array([law._a, law._offset, law._lo, law._hi], float),
         "speed filter pole, below-rated pitch offset [rad], torque min, max [N m]")]


def _ts_entries(ctl: Any) -> list[tuple[str, Any, str]]:
    """The numbers of a :class:`~mpc_wt.controllers.takagi_sugeno.TSController`: its grids,
    the observer's blended zero-order-hold maps, the vertex equilibria and gains."""
    from mpc_wt.controllers.takagi_sugeno import TSController

    if type(ctl) is not TSController:
        raise ValueError(f"the TS export takes a TSController, got {type(ctl).__name__}")
    if ctl.power_reduction is not None or ctl._v_given is not None:
        raise ValueError("a TS design with a power reduction over time (apc_frequency) or a "
                         "given initial wind does not export: the library takes its power "
                         "from the torque schedule and starts from the measured pitch")
    ts, gen, pa = ctl.ts, ctl.turbine.generator, ctl.turbine.pitch_actuator
    codes = _signal_codes(ts.measured, "TS observer")
    n, nx = ctl._phi.shape[1], len(ts.states)
    dp0 = float(ts.reduction_grid[0])
    eq = np.array([ts.blend(ts.membership(float(v), dp0))["u0"][0] for v in ts.wind_grid])
    order = np.argsort(eq)
    kk = np.asarray(ctl._K, float)
    rows: list[tuple[str, Any, str]] = [
        ("dt", ctl.dt, "controller period [s] (ServoDyn DLL_DT)"),
        ("sizes", np.array([ts.wind_grid.size, ts.reduction_grid.size, n, len(ts.inputs),
                            len(ts.measured), kk.shape[2], -1 if ctl._ki is None else ctl._ki,
                            float(ctl.torque_law is None)], float),
         "winds, reductions, observer states (x and v), inputs, measurements, gain columns, "
         "integral state (-1: none), 1: the TS law's torque applied"),
        ("signals", codes, "measured: " + ", ".join(ts.measured)),
        ("limits", np.array([pa.min_pitch_rad, pa.max_pitch_rad, gen.min_torque,
                             gen.max_torque,
                             ctl._reach if math.isfinite(ctl._reach) else -1.0], float),
         "pitch min, max [rad], torque min, max [N m], how far a pitch command may lead the "
         "measured pitch [rad] (-1: no bound)"),
        ("rated_power", float(ts.rated_power), "electrical power the torque schedule holds [W]"),
        ("integral_source", float(-1 if ctl._int_src is None else ctl._int_src),
         "the measurement whose deviation is integrated (-1: the estimate)"),
        ("torque_law", float(ctl._law is not None), "1: the generator torque from the "
                                                    "baseline's schedule"),
        ("wind_grid", np.asarray(ts.wind_grid, float), "vertex winds [m/s]"),
        ("reduction_grid", np.asarray(ts.reduction_grid, float), "vertex power reductions [-]"),
        ("start_pitch", eq[order], "the vertex pitch without reduction, increasing [rad]"),
        ("start_wind", np.asarray(ts.wind_grid, float)[order], "its wind [m/s]"),
        ("terms", np.asarray(ctl._terms, float).ravel(),
         "the observer's terms: vertex i and j (weight h_i h_j; j = -1: h_i)"),
        ("phi", ctl._phi.ravel(), "each term's state map over a period (row-major)"),
        ("gamma", ctl._gam.ravel(), "each term's map of [u; y; 1] over a period (row-major)"),
        ("x0", np.asarray(ts.x0, float).ravel(), f"vertex equilibria ({nx} states each)"),
        ("u0", np.asarray(ts.u0, float).ravel(), "vertex inputs [rad, N m]"),
        ("gain", kk.ravel(), "vertex gains K_i (inputs x gain columns, row-major)"),
    ]
    if ctl._law is not None:
        rows += _law_entries(ctl._law)
    return rows


def controller_input(controller: Any, kind: str, turbine: linearize.Turbine,
                     source: str = "", preview: Any = None) -> str:
    """The input file of an exported controller: every number of its design.

    Parameters
    ----------
    controller : object
        The designed controller (from :func:`mpc_wt.run.design_controller`).
    kind : str
        Its kind (one of :data:`EXPORTABLE`).
    turbine : Turbine
        Its turbine (named in the header).
    source : str
        How it was designed (written as a comment).
    preview : LidarPreview, optional
        The design's LIDAR preview (``Built.preview``), for the LIDAR kinds.

    Returns
    -------
    str
        The file's text.

    Raises
    ------
    ValueError
        A kind that does not export, or a controller of another type.
    """
    check_exportable(kind)
    lib_kind = _LIBRARY_KIND[kind]
    if kind == "baseline+lidar-ff":
        entries = _ff_entries(controller)
    elif kind == "ibc":
        entries = _ibc_entries(controller)
    elif lib_kind == "baseline":
        entries = _baseline_entries(controller) + [("feedforward", 0.0, "no LIDAR feedforward"),
                                                   ("ibc", 0.0, "no individual blade control")]
    elif lib_kind == "lqr":
        entries = _lqr_entries(controller)
    elif lib_kind == "ts":
        entries = _ts_entries(controller)
    else:
        entries = _mpc_entries(controller, preview)
    from mpc_wt._version import __version__

    head = [f"# mpc-wt {__version__}: controller '{kind}' for {turbine.name}",
            f"# {EXPORTABLE[kind]}",
            f"# exported {_dt.date.today().isoformat()}{'; ' + source if source else ''}",
            "# One entry per line: key value [value ...]; '#' starts a comment. Every number",
            "# here is read at the first call: change one and restart the simulation.",
            "format_version 1",
            f"kind {lib_kind}"]
    width = max(len(k) for k, v, _ in entries if np.ndim(v) == 0)
    body = []
    for k, v, doc in entries:
        if np.ndim(v) == 0:
            body.append(f"{k:<{width}} {_fmt(v):<24} # {doc}")
        else:
            body.append(f"# {k}: {doc} ({np.size(v)} values)")
            body.append(k + " " + " ".join(map(_fmt, np.asarray(v, float).ravel().tolist())))
    return "\n".join(head + body) + "\n"


def _needs_qp(kind: str) -> bool:
    """Whether a kind's library carries the MPC and its QP solver."""
    return _LIBRARY_KIND[kind] == "mpc"


def _source_names(directory: Path) -> list[str]:
    """An export's source files, relative to its folder: ours (with ``mpc.c`` where the folder
    has it), then the QP solver's (``daqp/``)."""
    names = list(_SOURCES)
    if (directory / _MPC_SOURCE).is_file():
        names.append(_MPC_SOURCE)
        qp = directory / _DAQP
        if qp.is_dir():
            names += sorted(f"{_DAQP}/{p.name}" for p in qp.iterdir()
                            if p.name.endswith((".c", ".h")))
    return names


def prepare_sources(kind: str) -> None:
    """Make sure the sources a kind's library is built from can be had: for an MPC kind,
    DAQP's C sources in the per-user cache (downloaded where they are not yet).

    Parameters
    ----------
    kind : str
        A controller kind (one of :data:`EXPORTABLE`).

    Raises
    ------
    SolverSourceError
        Neither cached nor downloadable; the message gives the command that fixes it.
    """
    if _needs_qp(kind):
        from mpc_wt.io.solver_sources import daqp_sources

        daqp_sources()


def _copy_sources(directory: Path, kind: str) -> tuple[Path, ...]:
    """Write the kind's C sources into its export folder; an MPC kind's come with DAQP's
    sources from its published distribution (:func:`mpc_wt.io.solver_sources.daqp_sources`)."""
    src = importlib.resources.files("mpc_wt.io") / "discon_c"
    names = list(_SOURCES) + ([_MPC_SOURCE] if _needs_qp(kind) else [])
    out = []
    for name in names:
        target = directory / name
        target.write_text((src / name).read_text())
        out.append(target)
    stale = directory / _MPC_SOURCE
    if not _needs_qp(kind) and stale.is_file():
        stale.unlink()                  # an earlier MPC export into the same folder
    if _needs_qp(kind):
        from mpc_wt.io.solver_sources import daqp_sources

        out += daqp_sources().write(directory / _DAQP)
    return tuple(out)


def _c_files(directory: Path) -> list[str]:
    return [n for n in _source_names(directory) if n.endswith(".c")]


def _defines(directory: Path) -> list[str]:
    """The preprocessor's flags beyond ``-I.``: the MPC and its solver's headers, where the
    folder has them."""
    return ["-DMPCWT_WITH_MPC", f"-I{_DAQP}"] if (directory / _MPC_SOURCE).is_file() else []


def _makefile(directory: Path, lib: str) -> Path:
    srcs = " ".join(_c_files(directory))
    cppflags = " ".join(["-I.", *_defines(directory)])
    text = (f"# Builds {lib} with the system's C compiler (make CC=... to choose another).\n"
            f"CC ?= cc\nCFLAGS ?= {_CFLAGS}\nCPPFLAGS += {cppflags}\n"
            f"LDLIBS = -lm -lpthread\n\n"
            f"{lib}: {srcs} mpcwt_discon.h\n"
            f"\t$(CC) $(CPPFLAGS) $(CFLAGS) -shared -o $@ {srcs} $(LDLIBS)\n\n"
            f"clean:\n\trm -f {lib}\n")
    path = directory / "Makefile"
    path.write_text(text)
    return path


def build_library(directory: str | Path, kind: str, *, compiler: str | None = None,
                  sanitize: bool = False, name: str | None = None) -> Path:
    """Compile an export folder's sources into the shared library.

    Parameters
    ----------
    directory : path
        The export folder (its ``*.c`` and header).
    kind : str
        The controller kind (names the library).
    compiler : str, optional
        The C compiler (default :func:`find_compiler`).
    sanitize : bool
        Build with AddressSanitizer and UndefinedBehaviorSanitizer (the library then runs
        only in a process that loads the sanitizer runtime first).
    name : str, optional
        The library's file name (default :func:`library_name`).

    Returns
    -------
    Path
        The library.

    Raises
    ------
    ControllerLibraryError
        No compiler, or the compiler failed (its output in the message).
    """
    directory = Path(directory).resolve()
    cc = compiler or find_compiler()
    if cc is None:
        raise ControllerLibraryError(
            "no C compiler found (looked for $CC, cc, gcc, clang): install one (e.g. "
            "build-essential, Xcode's command line tools, MSYS2) and run 'make' in "
            f"{directory}")
    lib = directory / (name or library_name(kind))
    flags = (_SANITIZE if sanitize else _CFLAGS).split()
    if sanitize:
        flags += ["-fPIC"]
    flags += _defines(directory)            # relative to the folder, the compiler's cwd
    cmd = [cc, f"-I{directory}", *flags, "-shared", "-o", str(lib),
           *[str(directory / n) for n in _c_files(directory)], "-lm"]
    if sys.platform != "win32":
        cmd.append("-lpthread")
    key = _build_key(directory, cc, flags)
    if _reuse_build(key, lib):
        return lib
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=directory)
    if proc.returncode != 0 or not lib.is_file():
        raise ControllerLibraryError(
            f"building {lib.name} failed (exit {proc.returncode}): {' '.join(cmd)}\n"
            f"{proc.stderr.strip() or proc.stdout.strip()}")
    _BUILDS[key] = (lib, _digest(lib.read_bytes()))
    return lib


#: This process's builds: (compiler, flags, the sources' digest) -> (library, its digest)
_BUILDS: dict[tuple[str, ...], tuple[Path, str]] = {}


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _build_key(directory: Path, cc: str, flags: list[str]) -> tuple[str, ...]:
    """What a build depends on: the compiler, its flags and every source file's bytes."""
    src = b"".join(n.encode() + b"\0" + (directory / n).read_bytes() + b"\0"
                   for n in _source_names(directory) if n.endswith((".c", ".h")))
    return (cc, *flags, sys.platform, _digest(src))


def _reuse_build(key: tuple[str, ...], lib: Path) -> bool:
    """Copy an earlier build of the same sources with the same compiler and flags to ``lib``
    (compiling the same sources again gives the same library); False if there is none, or it
    was removed or changed since."""
    hit = _BUILDS.get(key)
    if hit is None or hit[0] == lib:
        return False
    try:
        data = hit[0].read_bytes()
    except OSError:
        data = b""
    if _digest(data) != hit[1]:
        del _BUILDS[key]
        return False
    tmp = lib.with_name(lib.name + ".part")     # a new file: a loaded library is not touched
    tmp.write_bytes(data)
    os.chmod(tmp, 0o755)
    os.replace(tmp, lib)
    log.debug("%s: the same sources were built as %s in this process; copied", lib, hit[0])
    return True


#: ServoDyn inputs of the packaged OpenFAST decks, by turbine name prefix.
#: This process's libraries of the shipped laws: (core or mpc, compiler) -> the library
_SHIPPED: dict[tuple[bool, str], Path] = {}
_INPUTS: dict[str, Path] = {}
_INPUT_DIR: list[Path] = []


def shipped_library(kind: str, *, compiler: str | None = None) -> Path:
    """The library a kind exports as, compiled once per machine and kept in the per-user cache
    (:func:`mpc_wt.io.solver_sources.cache_dir`, ``libraries/``): the law mpc-wt's own runs
    call, the same bytes a user's export builds.

    Parameters
    ----------
    kind : str
        An exportable kind (the MPC kinds share one library, every other kind another).
    compiler : str, optional
        The C compiler (default :func:`find_compiler`).

    Returns
    -------
    Path
        The library; a new build where the sources, compiler or flags changed.

    Raises
    ------
    ControllerLibraryError
        No C compiler, or the build failed.
    SolverSourceError
        An MPC kind whose QP solver's sources cannot be had.
    """
    import tempfile

    from mpc_wt.io.solver_sources import cache_dir

    check_exportable(kind)
    cc = compiler or find_compiler()
    if cc is None:
        raise ControllerLibraryError(
            f"controller kind {kind!r} runs its exported C law, and no C compiler was found "
            f"(looked for $CC, cc, gcc, clang): install one (e.g. build-essential, Xcode's "
            f"command line tools, MSYS2)")
    memo = (_needs_qp(kind), cc)
    if memo in _SHIPPED and _SHIPPED[memo].is_file():
        return _SHIPPED[memo]
    name = library_name("mpc" if _needs_qp(kind) else "core")
    with tempfile.TemporaryDirectory(prefix="mpcwt_shipped_") as tmp:
        folder = Path(tmp)
        _copy_sources(folder, kind)
        flags = _CFLAGS.split() + _defines(folder)
        key = _digest("\0".join(_build_key(folder, cc, flags)).encode())[:24]
        target = cache_dir() / "libraries" / key / name
        if not target.is_file():
            lib = build_library(folder, kind, compiler=cc, name=name)
            target.parent.mkdir(parents=True, exist_ok=True)
            part = target.with_name(f"{name}.{os.getpid()}.part")
            shutil.copy2(lib, part)
            os.replace(part, target)      # whole or not at all, also for a parallel worker
            log.info("the %s law's library built and cached at %s", kind, target)
    _SHIPPED[memo] = target
    return target


def shipped_input(controller: Any, kind: str, turbine: linearize.Turbine,
                  preview: Any = None) -> Path:
    """A designed controller's input file for its library (:func:`controller_input`), written
    once per content into a folder kept for this process.

    Parameters
    ----------
    controller : object
        The design (of the type its kind builds).
    kind : str
        Its kind (one of :data:`EXPORTABLE`).
    turbine : Turbine
        Its turbine.
    preview : LidarPreview, optional
        The design's LIDAR preview (the LIDAR kinds).

    Returns
    -------
    Path
        The input file.
    """
    import atexit
    import tempfile

    text = controller_input(controller, kind, turbine, "the design mpc-wt runs", preview)
    key = _digest(text.encode())
    hit = _INPUTS.get(key)
    if hit is not None and hit.is_file():
        return hit
    if not _INPUT_DIR or not _INPUT_DIR[0].is_dir():
        d = Path(tempfile.mkdtemp(prefix="mpcwt_inputs_"))
        atexit.register(shutil.rmtree, d, ignore_errors=True)
        _INPUT_DIR[:] = [d]
    path = _INPUT_DIR[0] / f"{_stem(kind)}_{key[:16]}.in"
    path.write_text(text)
    _INPUTS[key] = path
    return path


def _deck_servodyn(turbine: linearize.Turbine) -> Path | None:
    name = turbine.name
    if name.startswith("IEA-15-240-RWT"):
        root = importlib.resources.files("linearize") / "data" / "iea15mw"
        p = Path(str(root)) / "IEA-15-240-RWT-Monopile" / "IEA-15-240-RWT-Monopile_ServoDyn.dat"
        return p if p.is_file() else None
    if name.startswith("NREL 5-MW"):
        try:
            from mpc_wt.controllers.discon import rosco_discon
            deck = rosco_discon("NREL-5MW").parent
        except Exception:  # noqa: BLE001 - the rosco package is optional
            return None
        p = deck / "NRELOffshrBsline5MW_Onshore_ServoDyn.dat"
        return p if p.is_file() else None
    return None


def servodyn_input(template: str | Path, out: str | Path, library: str | Path,
                   input_file: str | Path, dt: float, *, individual_pitch: bool = True) -> Path:
    """A ServoDyn input file that runs a Bladed-style library: ``template`` with pitch and
    torque control from the library (``PCMode = 5``, ``VSContrl = 5``), ``DLL_FileName``,
    ``DLL_InFile``, ``DLL_ProcName = "DISCON"``, ``DLL_DT`` and ``Ptch_Cntrl`` set; every other
    line as it was.

    Parameters
    ----------
    template : path
        A ServoDyn input file (OpenFAST v3/v4 layout: ``value  Key  - description``).
    out : path
        Where to write it.
    library, input_file : path
        The library and its input file (written as absolute paths).
    dt : float
        ``DLL_DT`` [s].
    individual_pitch : bool
        ``Ptch_Cntrl`` 1 (records 42-44) or 0 (record 45).

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        If the template lacks one of the keys.
    """
    want = {"PCMode": "5", "VSContrl": "5",
            "DLL_FileName": f'"{Path(library).resolve()}"',
            "DLL_InFile": f'"{Path(input_file).resolve()}"', "DLL_ProcName": '"DISCON"',
            "DLL_DT": repr(float(dt)), "Ptch_Cntrl": "1" if individual_pitch else "0"}
    lines = Path(template).read_text().splitlines()
    seen = set()
    for i, line in enumerate(lines):
        parts = line.split()
        if len(parts) >= 2 and parts[1] in want and parts[1] not in seen:
            key = parts[1]
            rest = line[line.index(key):]
            lines[i] = f"{want[key]:<14} {rest}"
            seen.add(key)
    missing = sorted(set(want) - seen)
    if missing:
        raise ValueError(f"ServoDyn template {template}: no line for {missing}")
    out = Path(out)
    out.write_text("\n".join(lines) + "\n")
    return out


def check_exportable(kind: str) -> None:
    """Raise ``ValueError`` (listing the kinds that export) unless ``kind`` exports.

    Parameters
    ----------
    kind : str
        A controller kind.

    Raises
    ------
    ValueError
        If it is not one of :data:`EXPORTABLE`.
    """
    if kind not in EXPORTABLE:
        raise ValueError(f"controller kind {kind!r} does not export as a DISCON library; "
                         f"the kinds that do: {sorted(EXPORTABLE)}")


def export_controller(controller: Any, kind: str, turbine: linearize.Turbine,
                      out: str | Path, *, build: bool = True, compiler: str | None = None,
                      source: str = "", preview: Any = None) -> DisconExport:
    """Export a designed controller object as a Bladed-style library
    (:func:`mpc_wt.run.export_discon` designs a kind and calls this).

    Parameters
    ----------
    controller : object
        The controller (of the type its kind builds).
    kind : str
        Its kind (one of :data:`EXPORTABLE`).
    turbine : Turbine
        Its turbine.
    out : path
        The export folder (created).
    build : bool
        Compile the library now.
    compiler : str, optional
        The C compiler.
    source : str
        How it was designed (a comment in the input file).
    preview : LidarPreview, optional
        The design's LIDAR preview (the LIDAR kinds).

    Returns
    -------
    DisconExport
    """
    check_exportable(kind)
    dt = float(getattr(controller, "dt"))
    directory = Path(out)
    directory.mkdir(parents=True, exist_ok=True)
    text = controller_input(controller, kind, turbine, source, preview)
    stem = _stem(kind)
    input_file = directory / f"{stem}.in"
    input_file.write_text(text)
    sources = _copy_sources(directory, kind)
    lib_name = library_name(kind)
    makefile = _makefile(directory, lib_name)
    notes = []
    library = None
    if build:
        if find_compiler() is None and compiler is None:
            notes.append("no C compiler found ($CC, cc, gcc, clang): the sources and Makefile "
                         "are written; run 'make' where a compiler is installed")
        else:
            library = build_library(directory, kind, compiler=compiler)
    template = _deck_servodyn(turbine)
    servodyn = None
    if template is None:
        notes.append(f"no OpenFAST deck is packaged for {turbine.name}: set DLL_FileName, "
                     f"DLL_InFile, DLL_ProcName and DLL_DT in your ServoDyn file yourself")
    else:
        servodyn = servodyn_input(template, directory / f"ServoDyn_{stem}.dat",
                                  directory / lib_name, input_file, dt)
    for n in notes:
        log.warning("%s", n)
    return DisconExport(kind=kind, directory=directory, input_file=input_file,
                        sources=sources, makefile=makefile, library=library,
                        servodyn=servodyn, dt=dt, note="; ".join(notes))


def export_design(doc: Mapping[str, Any], turbine: linearize.Turbine, out: str | Path, *,
                  build: bool = True, compiler: str | None = None) -> DisconExport:
    """Export a saved design (a gain-table document of ``mpcwt design``) as a library.

    Parameters
    ----------
    doc : mapping
        The design document (:func:`mpc_wt.io.gain_tables.load_design`).
    turbine : Turbine
        Its turbine.
    out : path
        The export folder.
    build : bool
        Compile the library now.
    compiler : str, optional
        The C compiler.

    Returns
    -------
    DisconExport

    Raises
    ------
    ValueError
        A design of a kind that does not export.
    """
    from mpc_wt.controllers.baseline import BaselineController, BaselineGains

    kind = doc.get("kind")
    if kind != "baseline":
        raise ValueError(f"a {kind!r} design does not export as a DISCON library from its "
                         f"gain table; the kinds that do: {sorted(EXPORTABLE)} (mpcwt design "
                         f"baseline, or export_discon for a registered kind)")
    s = doc["settings"]
    gains = BaselineGains(kp=s["kp"], ki=s["ki"], theta_k_rad=s["theta_k_rad"], k_opt=s["k_opt"],
                          rated_gen_speed_rad_s=s["rated_gen_speed_rad_s"],
                          rated_torque=s["rated_torque"], rated_power=s["rated_power"],
                          dpdtheta_0=math.nan, omega_n_rad_s=s.get("omega_n_rad_s", 0.6),
                          zeta=s.get("zeta", 0.7), power_fraction=s.get("power_fraction", 1.0),
                          min_pitch_speeds=tuple(s.get("min_pitch_speeds_rad_s", ())),
                          min_pitch_offsets=tuple(s.get("min_pitch_offsets_rad", ())))
    ctl = BaselineController(turbine, gains)
    return export_controller(ctl, "baseline", turbine, out, build=build, compiler=compiler,
                             source=f"from the design of omega_n {gains.omega_n_rad_s:g} rad/s, "
                                    f"zeta {gains.zeta:g}, power fraction "
                                    f"{gains.power_fraction:g}")
