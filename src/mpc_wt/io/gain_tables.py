"""Gain tables: one document per designed controller, exported to CSV, JSON, MATLAB and ROSCO.

A gain table is a JSON-able dict (``design.json`` in a design directory):

    {"schema": "mpc-wt gain table", "schema_version": 1,
     "kind": "baseline" | "lqr" | "ts" | "ibc" | "coleman-ipc",
     "turbine": ..., "software": {"mpc_wt": version}, "settings": {...},
     "schedule": {"columns": [...], "units": [...], "rows": [[...], ...]},
     "matrices": {name: {"unit": ..., "rows": [...], "cols": [...], "data": [[[...]]] }}}

``schedule`` has one row per operating point (wind speed for the LQR family, premise vertex
for TS with its membership breakpoints ``wind_grid`` / ``reduction_grid`` in ``settings``,
pitch angle for the PI baseline, the individual blade control and the Coleman IPC);
``matrices`` stacks gain matrices over those points with row/column names and one unit string
per matrix.

Formats (:func:`export`):

* ``json``: the document itself (``gains.json``);
* ``csv``: ``gains_schedule.csv`` (wide: one row per point, headers ``name [unit]``) and
  ``gains_matrices.csv`` (long: matrix, point, row, col, value, unit); a first ``#`` line gives
  schema and kind (``pandas.read_csv(..., comment="#")``);
* ``mat``: ``gains.mat`` (scipy.io.savemat) with the schedule columns as vectors and every
  matrix as an (n_points, n_rows, n_cols) array, names and units as cell strings;
* ``rosco``: a complete ROSCO 2.10 ``DISCON.IN`` (every parameter; the design's PI schedule,
  torque law, limits, filters and IPC, ROSCO's defaults elsewhere) and its ``Cp_Ct_Cq`` table
  (PC_GS_n/angles/KP/KI/KD/TF, PC_RefSpd, PC_MaxPit/MinPit/MaxRat/MinRat, VS_Rgn2K, VS_RtTq,
  VS_RefSpd, VS_RtPwr, VS_MaxTq, VS_MinTq, VS_MaxRat, VS_MinOMSpd); ROSCO's pitch gains act on
  the speed error (reference minus measured), so they carry the opposite sign of ours.
"""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import linearize
from mpc_wt._version import __version__
from mpc_wt.controllers.baseline import effective_pi_gains
from mpc_wt.errors import GainTableError
from mpc_wt.io.json_text import write_json

__all__ = ["SCHEMA_VERSION", "GainTableError", "baseline_table", "lqr_table", "ts_table",
           "ibc_table", "coleman_ipc_table", "mpc_table", "lqr_pio_table", "lidar_ff_table", "design_turbine",
           "save_design", "load_design", "export", "read_rosco", "FORMATS"]

SCHEMA_VERSION = 1
SCHEMA = "mpc-wt gain table"
FORMATS = ("csv", "json", "mat", "rosco", "discon")


def _unit_ratio(num: str, den: str) -> str:
    if den in ("-", ""):
        return num
    if num == den:
        return "-"
    return f"{num}/({den})" if " " in den or "/" in den else f"{num}/{den}"


def _doc(kind: str, turbine: linearize.Turbine, settings: dict[str, Any], columns: list[str],
         units: list[str], rows: list[list[float]],
         matrices: dict[str, dict[str, Any]]) -> dict[str, Any]:
    return {"schema": SCHEMA, "schema_version": SCHEMA_VERSION, "kind": kind,
            "turbine": turbine.name, "software": {"mpc_wt": __version__},
            "settings": settings,
            "schedule": {"columns": columns, "units": units,
                         "rows": [[float(v) for v in r] for r in rows]},
            "matrices": matrices}


def _matrix(stack: np.ndarray, rows: Sequence[str], cols: Sequence[str], unit: str,
            units: Sequence[str] | None = None) -> dict[str, Any]:
    d = {"unit": unit, "rows": list(rows), "cols": list(cols),
         "data": np.asarray(stack, dtype=float).tolist()}
    if units is not None:
        d["units"] = list(units)
    return d


def baseline_table(turbine: linearize.Turbine, gains: Any,
                   winds: Sequence[float] | None = None) -> dict[str, Any]:
    """The PI baseline (:class:`~mpc_wt.controllers.baseline.BaselineGains`) as a gain table: the pitch
    gain schedule -- the gains the controller applies, :func:`~mpc_wt.controllers.baseline.effective_pi_gains`
    (kp, ki / (1 + 2 theta / theta_K) of the DISCON form), not the design's kp GK(theta) --
    at the trim pitch of each wind speed from rated (the first row: the wind at which the design's rated or
    derated power is reached at fine pitch) to cut-out in 1 m/s steps, with the set points.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    gains : BaselineGains
        The design.
    winds : sequence of float, optional
        Wind speeds of the rows [m/s].

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    op = turbine.operation
    p_w = None if gains.power_fraction == 1.0 else gains.rated_power
    if winds is None:
        v0 = _rated_wind(turbine, p_w)
        winds = np.r_[v0, np.arange(math.floor(v0) + 1.0, op.cut_out_wind + 0.5, 1.0)]
    rows = []
    for v in winds:
        p = linearize.trim(turbine, float(v), p_w)
        kp, ki = effective_pi_gains(gains.kp, gains.ki, gains.theta_k_rad, p.pitch_rad)
        rows.append([float(v), p.pitch_rad, float(kp), float(ki), p.gen_torque,
                     p.gen_speed_rad_s, p.power])
    settings = {"kp": gains.kp, "ki": gains.ki, "theta_k_rad": gains.theta_k_rad,
                "k_opt": gains.k_opt, "rated_gen_speed_rad_s": gains.rated_gen_speed_rad_s,
                "rated_torque": gains.rated_torque, "rated_power": gains.rated_power,
                "omega_n_rad_s": gains.omega_n_rad_s, "zeta": gains.zeta,
                "power_fraction": gains.power_fraction, "min_pitch_rad": op.fine_pitch_rad,
                "max_pitch_rad": turbine.pitch_actuator.max_pitch_rad,
                "max_pitch_rate_rad_s": turbine.pitch_actuator.max_rate_rad_s,
                "max_torque": turbine.generator.max_torque,
                "min_torque": turbine.generator.min_torque,
                "max_torque_rate": turbine.generator.max_torque_rate,
                "min_gen_speed_rad_s": op.min_rotor_speed_rad_s
                * turbine.drivetrain.gearbox_ratio,
                "min_pitch_speeds_rad_s": list(gains.min_pitch_speeds),
                "min_pitch_offsets_rad": list(gains.min_pitch_offsets),
                "units": {"kp": "s", "ki": "-", "theta_k_rad": "rad",
                          "k_opt": "N m/(rad/s)^2", "rated_torque": "N m", "rated_power": "W"}}
    return _doc("baseline", turbine, settings,
                ["wind_speed", "pitch", "kp", "ki", "gen_torque", "gen_speed", "power"],
                ["m/s", "rad", "s", "-", "N m", "rad/s", "W"], rows, {})


def _rated_wind(turbine: linearize.Turbine, power_W: float | None) -> float:
    """The lowest wind at which ``power_W`` (default rated) is reached at fine pitch [m/s]."""
    v_rated = linearize.rated_wind_speed(turbine)
    if power_W is None:
        return v_rated
    from scipy.optimize import brentq

    def short(v: float) -> float:
        return linearize.trim(turbine, v).power - power_W

    lo = turbine.operation.cut_in_wind
    return float(brentq(short, lo, v_rated, xtol=1e-6)) if short(lo) < 0 else lo


def lqr_table(turbine: linearize.Turbine, designs: Sequence[Any],
              observers: Sequence[Any] | None = None,
              state_units: Sequence[str] | None = None) -> dict[str, Any]:
    """An LQR family (:func:`~mpc_wt.controllers.lqr.design_lqr_family`) as a gain table: operating
    points per wind speed, the gains K (u - u0 = -K (x - x0)) and, when given, the PI observer
    gains L1, L2 (Do et al. eqs 13-16).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    designs : sequence of LQRDesign
        One per wind.
    observers : sequence of PIObserver, optional
        The PI observers of the same models.
    state_units : sequence of str, optional
        Units of the states (default from the plant's tables).

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    if not designs:
        raise GainTableError("no LQR designs to tabulate")
    d0 = designs[0]
    su = list(state_units or [dict(zip(linearize.STATE_NAMES, linearize.STATE_UNITS)).get(
        n, "-") for n in d0.states])
    iu = dict(zip(linearize.INPUT_NAMES, linearize.INPUT_UNITS))
    cols = ["wind_speed"] + [f"x0_{n}" for n in d0.states] + [f"u0_{n}" for n in d0.inputs]
    units = ["m/s"] + su + [iu.get(n, "-") for n in d0.inputs]
    rows = [[d.wind_mps, *d.x0, *d.u0] for d in designs]
    mats = {"K": _matrix(np.array([d.K for d in designs]), d0.inputs, d0.states,
                         "input unit / state unit",
                         [_unit_ratio(iu.get(i, "-"), s) for i in d0.inputs for s in su])}
    if observers:
        o = observers[0]
        nf = o.L2.shape[0]
        mats["L1"] = _matrix(np.array([ob.L1 for ob in observers]), d0.states, o.measured,
                             "state unit / measurement unit")
        mats["L2"] = _matrix(np.array([ob.L2 for ob in observers]),
                             [f"unknown_input_{k + 1}" for k in range(nf)], o.measured,
                             "unknown-input unit / measurement unit")
    settings = {"dt": d0.dt, "weights": d0.weights,
                "gain_ratio_L2_L1": [ob.gain_ratio for ob in observers] if observers else None,
                "convention": "u = u0 - K (x - x0); observer per Do et al. eqs 13-16"}
    return _doc("lqr", turbine, settings, cols, units, rows, mats)


def lqr_pio_table(turbine: linearize.Turbine, ctl: Any, kind: str = "lqr-pio",
                  options: dict[str, Any] | None = None) -> dict[str, Any]:
    """A scheduled LQR-PIO (:class:`~mpc_wt.controllers.lqr.ScheduledLQRPIO`) as a gain table:
    :func:`lqr_table` of its designs from cut-in to cut-out, with each design's region and the
    options it was built with (from which ``mpcwt export --format discon`` builds it again).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    ctl : ScheduledLQRPIO
        The design.
    kind : str
        Its kind.
    options : dict, optional
        The options it was built with.

    Returns
    -------
    dict
        The gain-table document.
    """
    pts = ctl.controllers
    doc = lqr_table(turbine, [c.lqr for c in pts], [c.obs for c in pts])
    doc["kind"] = kind
    doc["schedule"]["columns"].append("region")
    doc["schedule"]["units"].append("-")
    for row, c in zip(doc["schedule"]["rows"], pts):
        row.append(2.0 if c.region == "II" else 3.0)
    doc["settings"].update({
        "options": dict(options or {}), "dt": ctl.dt,
        "schedule_time_constant": ctl.schedule.tau, "measured": list(pts[0].obs.measured),
        "units": {"dt": "s", "schedule_time_constant": "s"}})
    return doc


def ts_table(turbine: linearize.Turbine, ts: Any, controller: Any,
             observer: Any | None = None) -> dict[str, Any]:
    """A TS design (:mod:`mpc_wt.controllers.takagi_sugeno`) as a gain table: one row per premise vertex (wind,
    power reduction, equilibrium x0, u0), the PDC gains K_i and observer gains L_i, with the
    membership breakpoints and the LMI settings and certificate.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    ts : TSModel
        The model.
    controller : TSControllerDesign
        The PDC gains.
    observer : TSObserverDesign, optional
        The observer gains.

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    su = dict(zip(linearize.STATE_NAMES, linearize.STATE_UNITS))
    st_units = [su.get(n, "-") for n in ts.states]
    in_units = ["rad", "N m"]
    vt = ts.vertices
    cols = ["wind_speed", "power_reduction"] + [f"x0_{n}" for n in ts.states] + \
        [f"u0_{n}" for n in ts.inputs]
    units = ["m/s", "-"] + st_units + in_units
    rows = [[vt[i, 0], vt[i, 1], *ts.x0[i], *ts.u0[i]] for i in range(ts.n_vertices)]
    kcols = list(ts.states) + ([f"integral_{controller.integral_of}"]
                               if controller.integral_of else [])
    kunits = st_units + ([su.get(controller.integral_of, "-") + " s"]
                         if controller.integral_of else [])
    mats = {"K": _matrix(controller.K, ts.inputs, kcols, "input unit / state unit",
                         [_unit_ratio(i, s) for i in in_units for s in kunits])}
    settings = {"wind_grid": ts.wind_grid.tolist(), "reduction_grid": ts.reduction_grid.tolist(),
                "membership": "product of piecewise-linear hats on wind_grid x reduction_grid",
                "rated_power": ts.rated_power, "measured": list(ts.measured),
                "decay_rate": controller.decay_rate, "disk_radius": controller.disk_radius,
                "input_bounds": controller.input_bounds.tolist(), "solver": controller.solver,
                "certificate_ok": controller.certificate.ok,
                "convention": "u = sum_i h_i (u0_i - K_i (x_hat - x0_i)) (Clemens eq 7)"}
    if observer is not None:
        yunits = [su.get(n, "-") for n in ts.measured]
        mats["L"] = _matrix(observer.L, list(ts.states) + ["wind"], list(ts.measured),
                            "xi unit / measurement unit",
                            [_unit_ratio(s, y) for s in st_units + ["m/s"] for y in yunits])
        settings.update({"tau_v": observer.tau_v, "observer_decay_rate": observer.decay_rate,
                         "observer_disk_radius": observer.disk_radius,
                         "observer_certificate_ok": observer.certificate.ok})
    return _doc("ts", turbine, settings, cols, units, rows, mats)


def ibc_table(turbine: linearize.Turbine, gains: Any) -> dict[str, Any]:
    """Individual blade control (:class:`~mpc_wt.controllers.ipc.IBCGains`) as a gain table: the
    proportional gain per mean-pitch breakpoint, with its gain margin and 1P loop gain, and the
    filters (high-pass corner, band-stop frequencies and Q) and power fade-in in ``settings``.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    gains : IBCGains
        The design.

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    rows = [[w, p, k, gm if math.isfinite(gm) else 1e300, lg] for w, p, k, gm, lg in zip(
        gains.wind_mps, gains.pitch_rad, gains.gain, gains.gain_margin, gains.loop_gain_1p)]
    settings = {"dt": gains.dt, "highpass_hz": gains.highpass_hz,
                "notch_hz": [h * gains.one_p_hz for h in gains.notch_harmonics],
                "notch_harmonics": list(gains.notch_harmonics), "notch_q": gains.notch_q,
                "weight_range": list(gains.weight_range), "rated_power": gains.rated_power,
                "power_fraction": gains.power_fraction,
                "rotor_speed_rad_s": gains.rotor_speed_rad_s,
                "max_amplitude_rad": min(gains.max_amplitude_rad, 1e300),
                "convention": "theta_i = theta_collective + w(P) BS(K(theta_mean) HP(M_flap_i)) "
                              "(Pettas and Cheng sec. 3.1); gain margin 1e300: none"}
    return _doc("ibc", turbine, settings,
                ["wind_speed", "pitch", "gain", "gain_margin", "loop_gain_1p"],
                ["m/s", "rad", "rad/(N m)", "-", "-"], rows, {})


def coleman_ipc_table(turbine: linearize.Turbine, gains: Any) -> dict[str, Any]:
    """Coleman-frame IPC (:class:`~mpc_wt.controllers.ipc.ColemanIPCGains`) as a gain table: integral
    gain and azimuth offset per mean-pitch breakpoint.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    gains : ColemanIPCGains
        The design.

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    rows = [[w, p, k, a, gm] for w, p, k, a, gm in zip(
        gains.wind_mps, gains.pitch_rad, gains.ki, gains.azimuth_offset_rad, gains.gain_margin)]
    settings = {"crossover_rad_s": gains.crossover_rad_s,
                "max_amplitude_rad": gains.max_amplitude_rad,
                "weight_range": list(gains.weight_range), "rated_power": gains.rated_power,
                "power_fraction": gains.power_fraction,
                "convention": "theta_cs = -K_I R(-phi) int M_cs dt, M_cs = 2/3 sum M_i "
                              "[cos psi_i, sin psi_i]; theta_i += theta_c cos psi_i + theta_s "
                              "sin psi_i"}
    return _doc("coleman-ipc", turbine, settings,
                ["wind_speed", "pitch", "ki", "azimuth_offset", "gain_margin"],
                ["m/s", "rad", "rad/(N m s)", "rad", "-"], rows, {})


def _check(doc: Any, where: str) -> dict[str, Any]:
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
        raise GainTableError(f"{where} is not an mpc-wt gain table (no schema {SCHEMA!r})")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise GainTableError(f"{where} has schema_version {doc.get('schema_version')!r}; this "
                             f"mpc-wt reads version {SCHEMA_VERSION}")
    missing = [k for k in ("kind", "schedule", "matrices", "settings") if k not in doc]
    if missing:
        raise GainTableError(f"{where} misses the keys {missing}")
    s = doc["schedule"]
    if not all(len(r) == len(s["columns"]) for r in s["rows"]) or \
            len(s["units"]) != len(s["columns"]):
        raise GainTableError(f"{where}: schedule rows, columns and units differ in length")
    return doc


def mpc_table(turbine: linearize.Turbine, ctl: Any, kind: str,
              options: dict[str, Any] | None = None) -> dict[str, Any]:
    """A scheduled MPC's design as a table: one row per grid wind with the trim the cost
    tracks there (pitch, torque, rotor speed, power) and its Kalman filter's spectral radius;
    the settings hold the kind's options (from which the design is built again), the MPC's
    horizon and period, the notch on its torque command (centre, None: none; Q), and its
    region floor (the pitch above which and the rotor speed above which the measurements
    choose a design inside region 3, and that design's wind; None: none).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    ctl : ScheduledMPC
        The design.
    kind : str
        Its kind (``mpc``, ``mpc-collective``, ``mpc-lidar``).
    options : dict, optional
        The options it was built with.

    Returns
    -------
    dict
        The gain-table document.
    """
    rows = []
    for k, v in enumerate(ctl._grid):
        m = ctl.controller(k)
        z0, outs = m.model.z0, list(m.model.outputs)
        rows.append([float(v), float(np.mean(m.model.u0[:3])), float(m.model.u0[3]),
                     float(z0[outs.index("rotor_speed")]), float(z0[outs.index("gen_power")]),
                     float(m.estimator.spectral_radius) if m.estimator is not None else
                     float("nan")])
    st = ctl.settings
    settings = {"options": dict(options or {}), "dt": st.dt, "horizon": st.horizon,
                "control_horizon": st.hu, "schedule_time_constant": ctl.schedule.tau,
                "target_time_constant": ctl.target_tau,
                "torque_notch_hz": ctl.torque_notch_hz, "torque_notch_q": ctl.torque_notch_q,
                "tower_notch_hz": ctl.tower_notch_hz,
                "region_floor": None if ctl.region_floor is None else {
                    "pitch_above": ctl.region_floor.pitch_threshold,
                    "pitch_counts_above_rotor_speed": ctl.region_floor.pitch_min_speed
                    * ctl.region_floor.rated_speed,
                    "rotor_speed_above": ctl.region_floor.speed_margin
                    * ctl.region_floor.rated_speed,
                    "region3_wind": ctl.region_floor.region3_wind},
                "units": {"dt": "s", "schedule_time_constant": "s",
                          "target_time_constant": "s", "torque_notch_hz": "Hz",
                          "tower_notch_hz": "Hz", "region_floor": "rad, rad/s, m/s"}}
    return _doc(kind, turbine, settings,
                ["wind_speed", "pitch", "gen_torque", "rotor_speed", "gen_power",
                 "estimator_spectral_radius"], ["m/s", "rad", "N m", "rad/s", "W", "-"], rows,
                {})


def lidar_ff_table(turbine: linearize.Turbine, ctl: Any, kind: str,
                   options: dict[str, Any] | None = None) -> dict[str, Any]:
    """The LIDAR feedforward's design as a table over mean wind: the filter corner of the
    turbulence model and the static pitch curve the feedforward follows; the settings hold the
    kind's options (from which it is built again), the baseline's PI gains and the filter.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    ctl : LidarFeedforward
        The design.
    kind : str
        Its kind (``baseline+lidar-ff``).
    options : dict, optional
        The options it was built with.

    Returns
    -------
    dict
        The gain-table document.
    """
    winds = np.asarray(ctl.corner_winds, float)
    pitch = np.interp(winds, ctl.curve_v, ctl.curve_pitch)
    rows = [[float(v), float(c), float(p)] for v, c, p in zip(winds, ctl.corners, pitch)]
    g = ctl.base.gains
    settings = {"options": dict(options or {}), "kp": g.kp, "ki": g.ki,
                "filter_order": ctl.order, "sample_dt": ctl.sample_dt,
                "lead_s": ctl.lead_given, "focus_distance": ctl.sensor.focus_distance,
                "units": {"kp": "s", "ki": "-", "sample_dt": "s", "lead_s": "s",
                          "focus_distance": "m"}}
    return _doc(kind, turbine, settings, ["wind_speed", "filter_corner", "static_pitch"],
                ["m/s", "rad/s", "rad"], rows, {})


def save_design(doc: dict[str, Any], out_dir: str | Path) -> Path:
    """Write ``design.json`` into ``out_dir`` (created).

    Parameters
    ----------
    doc : dict
        A gain-table document.
    out_dir : str or Path
        The design directory.

    Returns
    -------
    Path
        The file written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    p = out / "design.json"
    write_json(p, _check(doc, "the design"))
    return p


def load_design(path: str | Path) -> dict[str, Any]:
    """Read a design directory's ``design.json`` (or a gain-table JSON file).


    Parameters
    ----------
    path : str or Path
        A design directory or a JSON file.

    Returns
    -------
    dict
        The checked document.

    Raises
    ------
    GainTableError
        Missing, not JSON, another schema or version, inconsistent lengths.
    """
    p = Path(path)
    if p.is_dir():
        p = p / "design.json"
    if not p.exists():
        raise GainTableError(f"{p} does not exist (run `mpcwt design ... --out DIR` first)")
    try:
        doc = json.loads(p.read_text())
    except json.JSONDecodeError as err:
        raise GainTableError(f"{p} is not valid JSON: {err}") from err
    return _check(doc, str(p))


def _write_csv(doc: dict[str, Any], out: Path) -> list[Path]:
    s = doc["schedule"]
    head = f"# {SCHEMA}, schema_version {SCHEMA_VERSION}, kind {doc['kind']}, " \
           f"turbine {doc['turbine']}"
    p1 = out / "gains_schedule.csv"
    with p1.open("w", newline="") as fh:
        fh.write(head + "\n")
        w = csv.writer(fh)
        w.writerow([f"{c} [{u}]" for c, u in zip(s["columns"], s["units"])])
        w.writerows([[repr(float(v)) for v in r] for r in s["rows"]])
    p2 = out / "gains_matrices.csv"
    with p2.open("w", newline="") as fh:
        fh.write(head + "\n")
        w = csv.writer(fh)
        w.writerow(["matrix", "point", "row", "col", "value", "unit"])
        for name, m in doc["matrices"].items():
            data = np.asarray(m["data"], dtype=float)
            ncol = len(m["cols"])
            for k in range(data.shape[0]):
                for i, rn in enumerate(m["rows"]):
                    for j, cn in enumerate(m["cols"]):
                        unit = m["units"][i * ncol + j] if "units" in m else m["unit"]
                        w.writerow([name, k, rn, cn, repr(float(data[k, i, j])), unit])
    return [p1, p2]


def _write_mat(doc: dict[str, Any], out: Path) -> list[Path]:
    import scipy.io

    s = doc["schedule"]
    rows = np.asarray(s["rows"], dtype=float).reshape(-1, len(s["columns"]))
    d: dict[str, Any] = {"schema_version": SCHEMA_VERSION, "kind": doc["kind"],
                         "turbine": doc["turbine"],
                         "schedule_columns": np.array(s["columns"], dtype=object),
                         "schedule_units": np.array(s["units"], dtype=object),
                         "schedule": rows}
    for c, col in zip(s["columns"], rows.T):
        d[f"s_{c}"[:63]] = col
    for name, m in doc["matrices"].items():
        d[name] = np.asarray(m["data"], dtype=float)
        d[f"{name}_rows"] = np.array(m["rows"], dtype=object)
        d[f"{name}_cols"] = np.array(m["cols"], dtype=object)
        d[f"{name}_unit"] = m["unit"]
    p = out / "gains.mat"
    scipy.io.savemat(p, d, long_field_names=True, do_compression=True)
    return [p]


def design_turbine(doc: dict[str, Any], turbine: linearize.Turbine | None = None
                   ) -> linearize.Turbine:
    """The turbine of a design document: ``turbine`` when given, else the packaged turbine of
    the document's turbine name.

    Parameters
    ----------
    doc : dict
        A gain-table document.
    turbine : Turbine, optional
        The design's turbine, when it is not a packaged one.

    Returns
    -------
    Turbine

    Raises
    ------
    GainTableError
        No packaged turbine has that name and none was given.
    """
    if turbine is not None:
        return turbine
    for name in linearize.available_turbines():
        t = linearize.load_turbine(name)
        if t.name == doc["turbine"]:
            return t
    raise GainTableError(f"the design's turbine {doc['turbine']!r} is not a packaged one "
                         f"{linearize.available_turbines()}: give its turbine (export(..., "
                         f"turbine=...), mpcwt export --turbine PATH) for the rosco and discon "
                         f"formats")


def _write_rosco(doc: dict[str, Any], out: Path,
                 turbine: linearize.Turbine | None = None) -> list[Path]:
    from mpc_wt.controllers.baseline import tune_baseline
    from mpc_wt.io.rosco import write_rosco_discon

    if doc["kind"] not in ("baseline", "coleman-ipc"):
        raise GainTableError(f"the rosco format holds a PI pitch schedule, torque set points and "
                             f"Coleman IPC; a {doc['kind']!r} design has none: export a baseline "
                             f"(`mpcwt design baseline`), derated or not, or a coleman-ipc design "
                             f"for ROSCO, or use csv/json/mat")
    t = design_turbine(doc, turbine)
    if doc["kind"] == "coleman-ipc":
        frac = float(doc["settings"].get("power_fraction", 1.0))
        base = baseline_table(t, tune_baseline(t, power_fraction=frac))
        return write_rosco_discon(t, base, out, ipc=doc)
    return write_rosco_discon(t, doc, out)


def _write_discon(doc: dict[str, Any], out: Path,
                  turbine: linearize.Turbine | None = None) -> list[Path]:
    raise GainTableError(f"a {doc['kind']!r} design exports as a controller library through its "
                         f"kind's export: mpc_wt.run.export_saved_design (mpcwt export "
                         f"--format discon)")


def read_rosco(path: str | Path) -> dict[str, Any]:
    """Parse ``NAME`` values from DISCON.IN-style lines (``values ! NAME - text``): a float,
    or a list of floats when the line holds several. Lines without ``!`` are skipped.

    Parameters
    ----------
    path : str or Path
        A DISCON.IN-style file.

    Returns
    -------
    dict
        Name -> float or list of floats.
    """
    out: dict[str, Any] = {}
    for line in Path(path).read_text().splitlines():
        if "!" not in line or line.lstrip().startswith("!"):
            continue
        vals, comment = line.split("!", 1)
        name = comment.split()[0] if comment.split() else ""
        try:
            nums = [float(v) for v in vals.split()]
        except ValueError:
            continue
        if name and nums:
            out[name] = nums if len(nums) > 1 or name in ("PC_GS_angles", "PC_GS_KP",
                                                          "PC_GS_KI", "PC_GS_KD",
                                                          "PC_GS_TF") else nums[0]
    return out


def export(doc_or_dir: dict[str, Any] | str | Path, fmt: str,
           out_dir: str | Path | None = None,
           turbine: linearize.Turbine | None = None) -> list[Path]:
    """Export a gain table (a document, or a design directory) to ``fmt`` in ``out_dir``
    (default the design directory). Returns the files written.


    Parameters
    ----------
    doc_or_dir : dict or str or Path
        A gain-table document or a design directory.
    fmt : {"csv", "json", "mat", "rosco", "discon"}
        The format (``discon``, a Bladed-style controller library, is written by the design's
        kind: :func:`mpc_wt.run.export_saved_design`; here it raises GainTableError).
    out_dir : str or Path, optional
        Where to write (default the design directory).
    turbine : Turbine, optional
        For ``rosco`` and ``discon``: the design's turbine (default: the packaged turbine of
        that name).

    Returns
    -------
    list of Path
        The files written (``rosco``: a complete ROSCO 2.10 ``DISCON.IN`` and its
        ``Cp_Ct_Cq`` table, :mod:`mpc_wt.io.rosco`).

    Raises
    ------
    ValueError
        An unknown format.
    GainTableError
        A broken table, or ``rosco`` for a design that is not the PI baseline.
    """
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {list(FORMATS)}, got {fmt!r}")
    if isinstance(doc_or_dir, dict):
        doc = _check(doc_or_dir, "the design")
        if out_dir is None:
            raise ValueError("out_dir is needed when exporting a document")
    else:
        doc = load_design(doc_or_dir)
        if out_dir is None:
            p = Path(doc_or_dir)
            out_dir = p if p.is_dir() else p.parent
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if fmt == "json":
        p = out / "gains.json"
        write_json(p, doc)
        return [p]
    if fmt == "csv":
        return _write_csv(doc, out)
    if fmt == "mat":
        return _write_mat(doc, out)
    if fmt == "discon":
        return _write_discon(doc, out, turbine)
    return _write_rosco(doc, out, turbine)
