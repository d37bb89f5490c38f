"""An OpenFAST case's run conditions, read from its input files: the turbine, the full-field
wind and where the rotor meets it, the initial state, the degrees of freedom and the
aerodynamic options, and the controller it runs; so that mpc-wt's plant can run the same case
(:func:`mpc_wt.run.run_openfast_case`) and be compared with OpenFAST's output
(:func:`mpc_wt.assessment.compare.compare_series`).

Read from the ``.fst`` (``TMax``, ``EDFile``, ``AeroFile``, ``ServoFile``, ``InflowFile``), from
ElastoDyn (the DOF flags and the initial conditions ``RotSpeed``, ``BlPitch``, ``Azimuth``,
``OoPDefl``, ``IPDefl``, ``TTDspFA``, ``TTDspSS``), from AeroDyn 15 (``UA_Mod``,
``TwrPotent``, ``TwrAero``, ``Skew_Mod``), from InflowWind (``WindType = 3``, a TurbSim
``.bts``) and from ServoDyn (``DLL_InFile``: a ROSCO ``DISCON.IN``, or none for Jonkman's
baseline DLL, whose gains are compiled in).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import lidar
import linearize
from linearize.openfast import ELASTODYN_DOFS, OpenFASTFile
from linearize.openfast_channels import blade_frame_moment
from mpc_wt.errors import ResultFileError

__all__ = ["OpenFASTCase", "read_openfast_case", "case_grid_wind", "describe",
           "aeromap_comparison"]


@dataclass(frozen=True)
class OpenFASTCase:
    """What mpc-wt needs to run an OpenFAST case.

    Parameters
    ----------
    fst : Path
        The case's main file.
    turbine : linearize.Turbine
        The turbine (the deck's, or the one given).
    wind_file : Path or None
        The TurbSim ``.bts`` the case runs in.
    duration : float
        ``TMax`` [s].
    x0 : (n_x,) ndarray
        The plant's initial state from ElastoDyn's initial conditions.
    config : linearize.PlantConfig
        The degrees of freedom ElastoDyn has and the aerodynamic effects AeroDyn models.
    discon_in : Path or None
        ServoDyn's ``DLL_InFile`` when it is a controller input file, else None.
    notes : tuple of str
        What was assumed or left out.
    steady_wind : (float, float) or None
        InflowWind's steady wind (``WindType = 1``): ``HWindSpeed`` [m/s] and ``PLExp`` [-],
        when the case runs in one (then ``wind_file`` is None).
    dll_dt : float or None
        ServoDyn's ``DLL_DT`` [s], the interval ServoDyn calls a library at (``default``:
        the main file's ``DT``); None without a ServoDyn file.
    individual_pitch : bool
        ServoDyn's ``Ptch_Cntrl`` is 1: a library's individual pitch demands (records 42-44)
        apply, else its collective one (record 45).
    lidar : dict or None
        InflowWind's lidar where its ``SensorType`` is not 0: ``sensor_type``, ``points``
        ((n, 3) from the hub [m]: ``FocalDistanceX/Y/Z`` plus ``RotorApexOffsetPos``),
        ``interval`` (``MeasurementInterval`` [s]), ``gates`` and ``radial`` (``NumPulseGate``,
        ``LidRadialVel``).
    """

    fst: Path
    turbine: linearize.Turbine
    wind_file: Path | None
    duration: float
    x0: np.ndarray
    config: linearize.PlantConfig
    discon_in: Path | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    steady_wind: tuple[float, float] | None = None
    dll_dt: float | None = None
    individual_pitch: bool = False
    lidar: dict[str, Any] | None = None


def _flag(f: OpenFASTFile, key: str, default: bool) -> bool:
    return f.flag(key) if f.has(key) else default


def _dofs(ed: OpenFASTFile) -> frozenset[str]:
    """The plant's DOFs from ElastoDyn's flags (first modes; the pitch as commanded)."""
    return frozenset(d for d, key in ELASTODYN_DOFS.items() if _flag(ed, key, True))


def _initial_state(ed: OpenFASTFile, turbine: linearize.Turbine) -> np.ndarray:
    x = np.zeros(len(linearize.STATE_NAMES))
    rpm = math.pi / 30
    w = ed.number("RotSpeed", 0.0, 100.0) * rpm
    x[2], x[3] = w, w * turbine.drivetrain.gearbox_ratio
    for i in range(3):
        key = f"BlPitch({i + 1})" if ed.has(f"BlPitch({i + 1})") else "BlPitch"
        x[5 + i] = math.radians(ed.number(key, -180.0, 180.0)) if ed.has(key) else 0.0
    x[0] = ed.number("TTDspFA") if ed.has("TTDspFA") else 0.0
    x[8] = ed.number("TTDspSS") if ed.has("TTDspSS") else 0.0
    x[10:13] = ed.number("OoPDefl") if ed.has("OoPDefl") else 0.0
    x[17:20] = -ed.number("IPDefl") if ed.has("IPDefl") else 0.0   # ours: toward the leading edge
    x[16] = math.radians(ed.number("Azimuth")) if ed.has("Azimuth") else 0.0
    return x


def read_openfast_case(fst: str | Path, *, wind: str | Path | None = None,
                       turbine: linearize.Turbine | None = None) -> OpenFASTCase:
    """Read an OpenFAST case's run conditions.

    Parameters
    ----------
    fst : str or Path
        The ``.fst`` main file.
    wind : str or Path, optional
        The TurbSim ``.bts`` to use in place of InflowWind's ``FileName_BTS`` (a case shipped
        without its wind file).
    turbine : linearize.Turbine, optional
        The turbine, when the deck alone does not make one (Jonkman's baseline DLL has no
        ``DISCON.IN``, where :func:`linearize.load_openfast` reads the rated point).

    Returns
    -------
    OpenFASTCase

    Raises
    ------
    ResultFileError
        Naming the file and what is missing or not supported: no ElastoDyn, a wind type other
        than a TurbSim full field, no wind file, a deck that needs ``turbine``.
    """
    fst = Path(fst).resolve()
    try:
        main = OpenFASTFile(fst)
        ed_path, ad_path = main.file("EDFile"), main.file("AeroFile")
        if ed_path is None or ad_path is None:
            raise ResultFileError(f"{fst}: EDFile and AeroFile (AeroDyn 15) are required")
        ed, ad = OpenFASTFile(ed_path), OpenFASTFile(ad_path)
        srv_path = main.file("ServoFile")
        srv = OpenFASTFile(srv_path) if srv_path is not None else None
        discon = srv.file("DLL_InFile") if srv is not None else None
        if discon is not None and not discon.is_file():
            discon = None
        notes: list[str] = []
        if turbine is None:
            try:
                turbine = linearize.load_openfast(fst)
            except linearize.TurbineFileError as err:
                raise ResultFileError(f"{fst}: the deck does not make a turbine ({err}); pass "
                                      f"the turbine (mpcwt compare-openfast --turbine NAME)") \
                    from None
        steady = None
        if wind is not None:
            wind_file: Path | None = Path(wind).resolve()
        else:
            wind_file, steady = _inflow(main)
        if steady is None and (wind_file is None or not wind_file.is_file()):
            raise ResultFileError(f"{fst}: wind file {wind_file} not found; pass it "
                                  f"(--wind FILE.bts)")
        ua = (ad.number("UA_Mod") if ad.has("UA_Mod") else
              ad.number("UAMod") if ad.has("UAMod") else 0) > 0
        cfg = linearize.PlantConfig.openfast(
            unsteady_aero=bool(ua), tower_drag=_flag(ad, "TwrAero", False),
            tower_shadow=(ad.number("TwrPotent") > 0) if ad.has("TwrPotent") else False,
            skewed_wake=_skewed_wake(ad), dofs=_dofs(ed))
        notes.append("pitch as the controller commands it (no actuator lag), as ServoDyn "
                     "applies a DLL's pitch")
        for key in ("FlapDOF2", "TwFADOF2", "TwSSDOF2", "YawDOF"):
            if _flag(ed, key, False):
                notes.append(f"ElastoDyn {key} is on; the plant has no such DOF")
        dll_dt, ipc = _bladed_interface(main, srv)
        return OpenFASTCase(fst=fst, turbine=turbine, wind_file=wind_file,
                            duration=main.number("TMax", 0.0, 1e7),
                            x0=_initial_state(ed, turbine), config=cfg, discon_in=discon,
                            notes=tuple(notes), steady_wind=steady, dll_dt=dll_dt,
                            individual_pitch=ipc, lidar=_lidar(main))
    except linearize.TurbineFileError as err:
        raise ResultFileError(str(err)) from None


def check_case_output(case: OpenFASTCase, series: Any, name: str) -> None:
    """Refuse an OpenFAST output that is not the case's: its time step against the main
    file's ``DT_Out`` (``DT`` by default), its end against ``TMax``, and the hub wind it
    records (``Wind1VelX``, where written) against the case's (InflowWind's steady
    ``HWindSpeed`` or the TurbSim file's mean), within 25 %.

    Parameters
    ----------
    case : OpenFASTCase
        The case (:func:`read_openfast_case`).
    series : OpenFASTSeries
        Its output, read (:func:`mpc_wt.io.openfast_output.read_openfast_output`).
    name : str
        The output file, for the message.

    Raises
    ------
    ResultFileError
        Naming the output, the case and the quantity that differs, with both values.
    """
    main = OpenFASTFile(case.fst)
    dt_out = (main.number("DT", 0.0) if not main.has("DT_Out") or main.is_default("DT_Out")
              else main.number("DT_Out", 0.0))
    t = np.asarray(series.t, dtype=float)
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    why = None
    if abs(step - dt_out) > 1e-6 * max(dt_out, 1e-9):
        why = (f"it steps by {step:g} s; the case writes every {dt_out:g} s "
               f"({main.where('DT_Out') if main.has('DT_Out') else main.where('DT')})")
    elif abs(t[-1] - case.duration) > 1.5 * max(step, 1e-9):
        why = f"it ends at {t[-1]:g} s; the case runs to {case.duration:g} s ({main.where('TMax')})"
    elif "Wind1VelX" in series.names:
        hub = float(np.mean(series.data[:, series.names.index("Wind1VelX")]))
        want = (case.steady_wind[0] if case.steady_wind is not None else
                float(lidar.WindField.load(case.wind_file).mean_speed) if case.wind_file
                else None)
        if want is not None and abs(hub - want) > 0.25 * want:
            why = (f"its hub wind Wind1VelX averages {hub:.4g} m/s; the case's wind is "
                   f"{want:.4g} m/s")
    if why is not None:
        raise ResultFileError(f"{name}: not the output of {case.fst.name}: {why}; compare a "
                              f"case with its own output")


def _lidar(main: OpenFASTFile) -> dict[str, Any] | None:
    """InflowWind's lidar (its ``SensorType`` 1-3), or None (none, or no InflowWind file)."""
    inflow = main.file("InflowFile")
    if inflow is None:
        return None
    iw = OpenFASTFile(inflow)
    if not iw.has("SensorType") or iw.integer("SensorType", 0, 3) == 0:
        return None
    kind = iw.integer("SensorType", 0, 3)
    n = iw.integer("NumBeam", 1, 5) if kind == 1 else 1
    focal = np.stack([iw.numbers(f"FocalDistance{c}")[:n] for c in "XYZ"], axis=1)
    if focal.shape != (n, 3):
        raise ResultFileError(f"{inflow}: FocalDistanceX, Y and Z need {n} values each "
                              f"(NumBeam), got {focal.shape[0]}")
    offset = iw.numbers("RotorApexOffsetPos")[:3] if iw.has("RotorApexOffsetPos") else \
        np.zeros(3)
    return {"sensor_type": kind, "points": focal + offset,
            "interval": iw.number("MeasurementInterval", 0.0),
            "gates": iw.integer("NumPulseGate", 0, 5) if kind == 3 else 1,
            "radial": iw.flag("LidRadialVel") if iw.has("LidRadialVel") else False,
            "file": str(inflow)}


def _bladed_interface(main: OpenFASTFile, srv: OpenFASTFile | None) -> tuple[float | None,
                                                                             bool]:
    """ServoDyn's ``DLL_DT`` (``default``: ServoDyn's ``DT``, whose ``default`` is the main
    file's ``DT``) and whether ``Ptch_Cntrl`` is 1; (None, False) without a ServoDyn file."""
    if srv is None or not srv.has("DLL_DT"):
        return None, False
    dt = srv.number("DLL_DT", 0.0) if not srv.is_default("DLL_DT") else \
        srv.number("DT", 0.0) if srv.has("DT") and not srv.is_default("DT") else \
        main.number("DT", 0.0)
    ipc = srv.has("Ptch_Cntrl") and srv.integer("Ptch_Cntrl", 0, 1) == 1
    return dt, ipc


def _skewed_wake(ad: OpenFASTFile) -> bool:
    """AeroDyn's Pitt and Peters skewed-wake correction: ``Skew_Mod = 1`` with
    ``SkewRedistr_Mod`` 1 or "default" (AeroDyn 4.0 on), or ``SkewMod = 2`` (earlier)."""
    if ad.has("Skew_Mod"):
        if ad.number("Skew_Mod") != 1:
            return False
        return (not ad.has("SkewRedistr_Mod") or ad.is_default("SkewRedistr_Mod")
                or ad.number("SkewRedistr_Mod") == 1)
    if ad.has("SkewMod"):
        return ad.number("SkewMod") == 2
    return False


def _inflow(main: OpenFASTFile) -> tuple[Path | None, tuple[float, float] | None]:
    """InflowWind's wind: a TurbSim file (``WindType = 3``) or a steady power-law wind (1)."""
    inflow = main.file("InflowFile")
    if inflow is None:
        return None, None
    iw = OpenFASTFile(inflow)
    kind = int(iw.number("WindType")) if iw.has("WindType") else 0
    if kind == 1:
        return None, (iw.number("HWindSpeed", 0.0, 100.0),
                      iw.number("PLExp", -1.0, 1.0) if iw.has("PLExp") else 0.0)
    if kind != 3:
        raise ResultFileError(f"{inflow}: WindType = {kind}; a steady wind (1) or a TurbSim "
                              f"full field (3) is supported (pass --wind FILE.bts)")
    return iw.file("FileName_BTS"), None


def case_wind_field(case: OpenFASTCase) -> tuple[lidar.WindField, float]:
    """The case's ``.bts`` field as the rotor meets it (u at least 0), for the plant
    (:func:`case_grid_wind`) and a lidar (:func:`case_lidar`).

    InflowWind carries a full field past the turbine at its mean speed U, its grid's upwind
    edge starting at the tower: the wind at a point x downwind of the tower at time t is the
    file's at t + (W/2 - x) / U, W the grid's width. The rotor's apex is OverHang cos(tilt)
    upwind, so the plant (which samples the field in its rotor plane) reads the file at
    t + (W/2 + OverHang cos(tilt)) / U.

    Parameters
    ----------
    case : OpenFASTCase
        A case in a TurbSim field (not a steady wind).

    Returns
    -------
    field : lidar.WindField
        Times from the shift on, as seen at the rotor; the file's mean speed, the turbine's
        hub height.
    shift : float
        [s]

    Raises
    ------
    ResultFileError
        A steady-wind case, or a field shorter than the case.
    """
    if case.steady_wind is not None or case.wind_file is None:
        raise ResultFileError(f"{case.fst}: the case runs in a steady wind, not a TurbSim field")
    f = lidar.WindField.load(case.wind_file)
    g = case.turbine.geometry
    u_ref = float(f.mean_speed)
    shift = (0.5 * (f.y[-1] - f.y[0]) + g.overhang * math.cos(g.shaft_tilt_rad)) / u_ref
    keep = f.t >= f.t[0] + shift - (f.t[1] - f.t[0])
    if f.t[-1] - shift < case.duration:
        raise ResultFileError(f"{case.wind_file}: {f.t[-1] - f.t[0]:.1f} s of wind, less than "
                              f"the case's {case.duration:g} s plus the {shift:.2f} s the "
                              f"field takes to reach the rotor")
    u = np.maximum(f.u[keep], 0.0).astype(np.float32)
    return lidar.WindField(t=f.t[keep] - f.t[0] - shift, y=f.y, z=f.z, u=u, v=f.v[keep],
                           w=f.w[keep], mean_speed=u_ref, hub_height=g.hub_height), shift


def case_grid_wind(case: OpenFASTCase,
                   field: tuple[lidar.WindField, float] | None = None
                   ) -> tuple[linearize.GridWind | linearize.SteadyWind, float]:
    """The plant's wind for the case: the ``.bts`` field (u, v, w) as the rotor meets it
    (:func:`case_wind_field`), or the case's steady power-law wind (no shift).

    Parameters
    ----------
    case : OpenFASTCase
    field : (lidar.WindField, float), optional
        :func:`case_wind_field`'s result, where it was read already.

    Returns
    -------
    wind : linearize.GridWind or linearize.SteadyWind
        Times from the shift on, as seen at the rotor.
    shift : float
        [s]
    """
    if case.steady_wind is not None:
        return linearize.SteadyWind(*case.steady_wind), 0.0
    f, shift = field if field is not None else case_wind_field(case)
    return linearize.GridWind(t=f.t, y=f.y, z=f.z, u=f.u, v=f.v, w=f.w), shift


def case_lidar(case: OpenFASTCase, field: lidar.WindField) -> lidar.PointLidar | None:
    """The case's InflowWind lidar on its wind (:class:`lidar.PointLidar`: single points, or
    the CW beam's x estimate at its focus), or None where the case has none.

    Parameters
    ----------
    case : OpenFASTCase
    field : lidar.WindField
        The case's wind as the rotor meets it (:func:`case_wind_field`).

    Returns
    -------
    lidar.PointLidar or None

    Raises
    ------
    ValueError
        InflowWind's pulsed lidar, or its CW lidar with ``LidRadialVel True``, which mpc-wt's
        plant does not make.
    """
    cfg = case.lidar
    if cfg is None:
        return None
    if cfg["sensor_type"] == 3 or (cfg["sensor_type"] == 2 and cfg["radial"]):
        raise ValueError(f"{cfg['file']}: SensorType = {cfg['sensor_type']}"
                         f"{', LidRadialVel True' if cfg['radial'] else ''}; mpc-wt's plant "
                         f"measures InflowWind's single points (SensorType 1) and its CW lidar "
                         f"with LidRadialVel False (SensorType 2)")
    g = case.turbine.geometry
    hub = (-g.overhang * math.cos(g.shaft_tilt_rad), 0.0, g.hub_height)
    return lidar.PointLidar(cfg["points"], cfg["interval"], hub,
                            sensor_type=cfg["sensor_type"]).bind(field)


def describe(case: OpenFASTCase) -> dict[str, Any]:
    """The case's conditions for a report.

    Parameters
    ----------
    case : OpenFASTCase

    Returns
    -------
    dict
    """
    c = case.config
    return {"fst": str(case.fst), "wind_file": str(case.wind_file),
            "steady_wind": list(case.steady_wind) if case.steady_wind else None,
            "duration_s": case.duration, "dofs": sorted(c.dofs),
            "unsteady_aero": c.unsteady_aero, "tower_shadow": c.tower_shadow,
            "tower_drag": c.tower_drag,
            "rotor_speed_rpm": float(case.x0[2] * 30 / math.pi),
            "pitch_deg": float(math.degrees(case.x0[5])), "notes": list(case.notes)}


def aeromap_comparison(outb: str | Path, turbine: linearize.Turbine,
                       config: linearize.PlantConfig | None = None) -> list[dict[str, float]]:
    """An OpenFAST AeroMap's blade-root moments beside the plant's steady ones at its points.

    OpenFAST's AeroMap solves the static equilibrium of the elastic rotor held at azimuth 0
    (blade 1 up) at given rotor speed, wind (or tip-speed ratio) and pitch, without gravity:
    each blade deflects under its own loads at its azimuth. The plant is put at each point's
    operating point (:func:`linearize.operating_point`), turned to azimuth 0, and its tower,
    flap and edge modes are brought to the same static equilibrium there (Newton's method on
    their accelerations); points the plant cannot hold (the generator torque out of range)
    are left out.

    Parameters
    ----------
    outb : str or Path
        The AeroMap's output (channels ``Pitch``, ``TSR``, ``WindSpeed``, ``RotorSpeed``,
        ``RootMyb1``, ``RootMxb1`` in deg, -, m/s, rpm, kN m).
    turbine : linearize.Turbine
    config : linearize.PlantConfig, optional
        Default: AeroDyn 15's load integration, the blade body forces and twisted modes on,
        gravity off (the AeroMap's).

    Returns
    -------
    list of dict
        Per point: ``pitch_deg``, ``tsr``, ``flapwise_of_kNm``, ``flapwise_kNm``,
        ``edgewise_of_kNm``, ``edgewise_kNm``.

    Raises
    ------
    linearize.TrimError
        If the modes' equilibrium at a point is not found.
    """
    from mpc_wt.io.openfast_output import read_openfast_output

    of = read_openfast_output(outb)
    d = {n: of.data[:, i] for i, n in enumerate(of.names)}
    cfg = config or linearize.PlantConfig(aero=linearize.AeroOptions(gravity=False),
                                          blade_body_forces=True, twisted_modes=True,
                                          integration="trapezoid")
    params = linearize.plant_params(turbine, cfg)
    iz = {n: i for i, n in enumerate(linearize.OUTPUT_NAMES)}
    rows = []
    for k in range(of.t.size):
        pitch, wind, rpm = d["Pitch"][k], d["WindSpeed"][k], d["RotorSpeed"][k]
        try:
            op = linearize.operating_point(turbine, wind, rpm * math.pi / 30,
                                           math.radians(pitch), config=cfg)
        except linearize.TrimError:
            continue
        x = _static_modes_at_azimuth(params, op.x, op.u, wind, 0.0)
        z = linearize.plant_outputs(0.0, x, op.u, np.full(3, wind), params)
        args = (z[iz["pitch_1"]], z[iz["flap_moment_1"]], z[iz["edge_moment_1"]])
        rows.append({"pitch_deg": float(pitch), "tsr": float(d["TSR"][k]),
                     "flapwise_of_kNm": float(d["RootMyb1"][k]),
                     "flapwise_kNm": float(blade_frame_moment("flapwise_moment_1", *args)) / 1e3,
                     "edgewise_of_kNm": float(d["RootMxb1"][k]),
                     "edgewise_kNm": float(blade_frame_moment("edgewise_moment_1", *args)) / 1e3})
    return rows


#: the structural modes of a static equilibrium: (displacement, velocity) state indices of the
#: tower fore-aft and side-side modes and each blade's flap and edge modes
_MODE_STATES = ((0, 1), (8, 9), (10, 13), (11, 14), (12, 15), (17, 20), (18, 21), (19, 22))


def _static_modes_at_azimuth(params: linearize.PlantParams, x0: np.ndarray, u: np.ndarray,
                             wind: float, azimuth: float) -> np.ndarray:
    """The state ``x0`` turned to ``azimuth`` [rad] with the enabled tower, flap and edge modes
    in static equilibrium there (their accelerations zero, rates zero) in a steady uniform
    ``wind`` [m/s]: Newton's method with a finite-difference Jacobian."""
    on = set(params.config.active_states())
    names = linearize.STATE_NAMES
    pairs = [(i, j) for i, j in _MODE_STATES if names[i] in on]
    x = np.asarray(x0, dtype=float).copy()
    x[16] = azimuth
    if not pairs:
        return x
    pos = [i for i, _ in pairs]
    acc = [j for _, j in pairs]
    x[acc] = 0.0
    d = np.full(3, wind)

    def accel(xx: np.ndarray) -> np.ndarray:
        return linearize.plant_rhs(0.0, xx, u, d, params)[acc]

    for _ in range(20):
        f = accel(x)
        jac = np.empty((len(pos), len(pos)))
        for c, i in enumerate(pos):
            h = 1e-6 * max(1.0, abs(x[i]))
            xp = x.copy()
            xp[i] += h
            jac[:, c] = (accel(xp) - f) / h
        step = np.linalg.solve(jac, f)
        x[pos] -= step
        if np.max(np.abs(step)) < 1e-10:
            return x
    raise linearize.TrimError(f"the modes' static equilibrium at azimuth {azimuth:g} rad in "
                              f"{wind:g} m/s did not converge (last step "
                              f"{np.max(np.abs(step)):.2e})")
