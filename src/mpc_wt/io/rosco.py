"""A complete ROSCO ``DISCON.IN`` from an mpc-wt design, with the ``Cp_Ct_Cq.txt`` it reads.

Every parameter of ROSCO 2.10's input file is written (:data:`ROSCO_PARAMETERS`, in ROSCO's
order and sections), so that ROSCO reads the file without a missing or unknown key. Values come
from the design where it has them, and the comment of each line says so ("mpc-wt: ..."):

- pitch: the PI gain schedule the baseline applies (kp, ki over pitch, the DISCON form
  ``kp / (1 + theta / theta_K)``, on a 0.25 deg grid), fine pitch, limits and rates, the rated
  generator speed as reference;
- torque: ``VS_ControlMode`` 1 (K omega^2 in region 2, PI transitions at minimum and rated speed:
  ``VS_KP``, ``VS_KI`` placed at 0.2 rad/s, damping 0.7, on the rigid rotor with our dQ/dOmega
  at rated), constant power (``VS_ConstPower`` 1) or constant torque in region 3 as the design,
  our K, rated values and limits; a derated design exports its derated power and torque;
- the generator-speed low-pass of our baseline (first order, 0.25 Hz); no set-point smoothing,
  no peak shaving, no wind-speed estimator (``WE_Mode`` 0), as our baseline has none;
- a design with a minimum-pitch schedule (the IEA-15's) turns on ROSCO's minimum-pitch table
  (``PS_Mode`` 1) with the trim's region-1.5 pitch over wind, read on the hub wind;
- the wind-speed estimator's data that ROSCO reads in any mode: blade radius, gearbox, the
  drivetrain inertia of our plant, air density, the performance table (written beside) and the
  first-order rotor poles dQ/dOmega / J over wind from our linear models.

Every other parameter is ROSCO's default for its unused feature, written as "ROSCO default".
The parameter list and the defaults are reference data from ROSCO 2.10.6's NREL-5MW example
(NREL/ROSCO, Apache-2.0).
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

import linearize
from mpc_wt._version import __version__

__all__ = ["ROSCO_PARAMETERS", "rosco_values", "write_rosco_discon"]

#: ROSCO 2.10's DISCON.IN: (section, ((parameter, default), ...)), in the file's order. A
#: "<table>" default is computed for the turbine.
ROSCO_PARAMETERS: tuple[tuple[str, tuple[tuple[str, str], ...]], ...] = (
    ('SIMULATION CONTROL', (
        ('LoggingLevel', '1'),
        ('DT_Out', '0'),
        ('Ext_Interface', '1'),
        ('Echo', '0'),
    )),
    ('CONTROLLER FLAGS', (
        ('F_LPFType', '1'),
        ('IPC_ControlMode', '0'),
        ('VS_ControlMode', '2'),
        ('VS_ConstPower', '1'),
        ('VS_FBP', '0'),
        ('PC_ControlMode', '1'),
        ('Y_ControlMode', '0'),
        ('SS_Mode', '1'),
        ('PRC_Mode', '0'),
        ('WE_Mode', '2'),
        ('PS_Mode', '1'),
        ('SU_Mode', '0'),
        ('SD_Mode', '0'),
        ('Fl_Mode', '0'),
        ('TD_Mode', '0'),
        ('TRA_Mode', '0'),
        ('Flp_Mode', '0'),
        ('OL_Mode', '0'),
        ('PA_Mode', '0'),
        ('PF_Mode', '0'),
        ('AWC_Mode', '0'),
        ('Ext_Mode', '0'),
        ('ZMQ_Mode', '0'),
        ('CC_Mode', '0'),
        ('StC_Mode', '0'),
    )),
    ('FILTERS', (
        ('F_LPFCornerFreq', '1.57080'),
        ('F_LPFDamping', '0.00000'),
        ('F_NumNotchFilts', '0'),
        ('F_NotchFreqs', '0.0000'),
        ('F_NotchBetaNum', '0.0000'),
        ('F_NotchBetaDen', '0.0000'),
        ('F_GenSpdNotch_N', '0'),
        ('F_GenSpdNotch_Ind', '0'),
        ('F_TwrTopNotch_N', '0'),
        ('F_TwrTopNotch_Ind', '0'),
        ('F_SSCornerFreq', '0.62830'),
        ('F_WECornerFreq', '0.20944'),
        ('F_YawErr', '0.17952'),
        ('F_FlCornerFreq', '0.0000 1.0000'),
        ('F_FlHighPassFreq', '0.01042'),
        ('F_FlpCornerFreq', '0.0000 1.0000'),
        ('F_VSRefSpdCornerFreq', '0.20944'),
    )),
    ('BLADE PITCH CONTROL', (
        ('PC_GS_n', '30'),
        ('PC_GS_angles', '<table>'),
        ('PC_GS_KP', '<table>'),
        ('PC_GS_KI', '<table>'),
        ('PC_GS_KD', '<table>'),
        ('PC_GS_TF', '<table>'),
        ('PC_MaxPit', '1.570000000000'),
        ('PC_MinPit', '0.000000000000'),
        ('PC_MaxRat', '0.174500000000'),
        ('PC_MinRat', '-0.17450000000'),
        ('PC_RefSpd', '122.9096700000'),
        ('PC_FinePit', '0.000000000000'),
        ('PC_Switch', '0.017450000000'),
    )),
    ('INDIVIDUAL PITCH CONTROL', (
        ('IPC_Vramp', '9.120 11.400'),
        ('IPC_SatMode', '2'),
        ('IPC_IntSat', '0.3'),
        ('IPC_KP', '0.000e+00 0.000e+00'),
        ('IPC_KI', '0.000e+00 0.000e+00'),
        ('IPC_aziOffset', '0.000 0.000'),
        ('IPC_CornerFreqAct', '0.0'),
    )),
    ('VS TORQUE CONTROL', (
        ('VS_GenEff', '94.40000'),
        ('VS_ArSatTq', '4.30935e+04'),
        ('VS_MaxRat', '4.00000e+04'),
        ('VS_MaxTq', '4.74029e+04'),
        ('VS_MinTq', '0.00000e+00'),
        ('VS_MinOMSpd', '34.64286'),
        ('VS_Rgn2K', '2.31055e+00'),
        ('VS_RtPwr', '5.00000e+06'),
        ('VS_RtTq', '4.30935e+04'),
        ('VS_RefSpd', '122.90967'),
        ('VS_n', '1'),
        ('VS_KP', '-6.97771e+02'),
        ('VS_KI', '-1.04507e+02'),
        ('VS_TSRopt', '7.50000'),
    )),
    ('FIXED PITCH REGION 3 TORQUE CONTROL', (
        ('VS_FBP_n', '60'),
        ('VS_FBP_U', '<table>'),
        ('VS_FBP_Omega', '<table>'),
        ('VS_FBP_Tau', '<table>'),
    )),
    ('SETPOINT SMOOTHER', (
        ('SS_VSGain', '1.00000'),
        ('SS_PCGain', '0.05000'),
    )),
    ('POWER REFERENCE TRACKING', (
        ('PRC_Comm', '0'),
        ('PRC_R_Torque', '1.00000'),
        ('PRC_R_Speed', '1.00000'),
        ('PRC_R_Pitch', '1.00000'),
        ('PRC_Table_n', '20'),
        ('PRC_R_Table', '<table>'),
        ('PRC_Pitch_Table', '<table>'),
        ('PRC_n', '2'),
        ('PRC_LPF_Freq', '0.07854'),
        ('PRC_WindSpeeds', '3.0000 25.0000'),
        ('PRC_GenSpeeds', '1.2291e+02 1.2291e+02'),
    )),
    ('WIND SPEED ESTIMATOR', (
        ('WE_BladeRadius', '63.000'),
        ('WE_CP_n', '1'),
        ('WE_CP', '0.0'),
        ('WE_Gamma', '0.0'),
        ('WE_GearboxRatio', '97.0'),
        ('WE_Jtot', '43702538.05700'),
        ('WE_RhoAir', '1.225'),
        ('PerfFileName', '"Cp_Ct_Cq.NREL5MW.txt"'),
        ('PerfTableSize', '36 26'),
        ('WE_FOPoles_N', '60'),
        ('WE_FOPoles_v', '<table>'),
        ('WE_FOPoles', '<table>'),
    )),
    ('YAW CONTROL', (
        ('Y_uSwitch', '0.00000'),
        ('Y_ErrThresh', '4.000 8.000'),
        ('Y_Rate', '0.00870'),
        ('Y_MErrSet', '0.00000'),
        ('Y_IPC_IntSat', '0.00000'),
        ('Y_IPC_KP', '0.00000'),
        ('Y_IPC_KI', '0.00000'),
    )),
    ('TOWER CONTROL', (
        ('TRA_ExclSpeed', '0.00000'),
        ('TRA_ExclBand', '0.00000'),
        ('TRA_RateLimit', '0.00000e+00'),
        ('FA_KI', '0.00000'),
        ('FA_HPFCornerFreq', '0.00000'),
        ('FA_IntSat', '0.00000'),
    )),
    ('MINIMUM PITCH SATURATION', (
        ('PS_BldPitchMin_N', '60'),
        ('PS_WindSpeeds', '<table>'),
        ('PS_BldPitchMin', '<table>'),
    )),
    ('STARTUP', (
        ('SU_StartTime', '120.0000000000'),
        ('SU_FW_MinDuration', '200.0000000000'),
        ('SU_RotorSpeedThresh', '0.520000000000'),
        ('SU_RotorSpeedCornerFreq', '0.418880000000'),
        ('SU_LoadStages_N', '2'),
        ('SU_LoadStages', '0.2000 1.0000'),
        ('SU_LoadRampDuration', '100.0000 100.0000'),
        ('SU_LoadHoldDuration', '200.0000 100.0000'),
    )),
    ('SHUTDOWN', (
        ('SD_TimeActivate', '0'),
        ('SD_EnablePitch', '0'),
        ('SD_EnableYawError', '0'),
        ('SD_EnableGenSpeed', '0'),
        ('SD_EnableTime', '0'),
        ('SD_MaxPit', '0.402050000000'),
        ('SD_PitchCornerFreq', '0.418880000000'),
        ('SD_MaxYawError', '30.00000000000'),
        ('SD_YawErrorCornerFreq', '0.418880000000'),
        ('SD_MaxGenSpd', '147.4916000000'),
        ('SD_GenSpdCornerFreq', '0.418880000000'),
        ('SD_Time', '9999.000000000'),
        ('SD_Method', '1'),
        ('SD_Stage_N', '1'),
        ('SD_StageTime', '1000.0000'),
        ('SD_StagePitch', '1.5708'),
        ('SD_MaxTorqueRate', '2000.0000'),
        ('SD_MaxPitchRate', '0.0218'),
    )),
    ('Floating', (
        ('Fl_n', '1'),
        ('Fl_Kp', '0.0000'),
        ('Fl_U', '0.0000'),
    )),
    ('FLAP ACTUATION', (
        ('Flp_Angle', '0.000000000000'),
        ('Flp_Kp', '0.00000000e+00'),
        ('Flp_Ki', '0.00000000e+00'),
        ('Flp_MaxPit', '0.174500000000'),
    )),
    ('Open Loop Control', (
        ('OL_Filename', '"unused"'),
        ('OL_BP_Mode', '0'),
        ('OL_BP_FiltFreq', '0.000000'),
        ('Ind_Breakpoint', '0'),
        ('Ind_BldPitch', '0 0 0'),
        ('Ind_GenTq', '0'),
        ('Ind_YawRate', '0'),
        ('Ind_Azimuth', '0'),
        ('RP_Gains', '0.0000 0.0000 0.0000 0.0000'),
        ('Ind_CableControl', '0'),
        ('Ind_StructControl', '0'),
        ('Ind_R_Speed', '0'),
        ('Ind_R_Torque', '0'),
        ('Ind_R_Pitch', '0'),
    )),
    ('Pitch Actuator Model', (
        ('PA_CornerFreq', '3.140000000000'),
        ('PA_Damping', '0.707000000000'),
    )),
    ('Pitch Actuator Faults', (
        ('PF_Offsets', '0.0000 0.0000 0.0000'),
        ('PF_TimeStuck', '9999.0000 9999.0000 9999.0000'),
    )),
    ('Active Wake Control', (
        ('AWC_NumModes', '1'),
        ('AWC_n', '1'),
        ('AWC_harmonic', '1'),
        ('AWC_freq', '0.0500'),
        ('AWC_amp', '1.0000'),
        ('AWC_clockangle', '0.0000'),
        ('AWC_phaseoffset', '0.000000000000'),
        ('AWC_CntrGains', '0.0000 0.0000'),
    )),
    ('External Controller Interface', (
        ('DLL_FileName', '"unused"'),
        ('DLL_InFile', '"unused"'),
        ('DLL_ProcName', '"DISCON"'),
    )),
    ('ZeroMQ Interface', (
        ('ZMQ_CommAddress', '"tcp://localhost:5555"'),
        ('ZMQ_UpdatePeriod', '1.000000'),
        ('ZMQ_ID', '0'),
    )),
    ('Cable Control', (
        ('CC_Group_N', '1'),
        ('CC_GroupIndex', '0'),
        ('CC_ActTau', '20.000000'),
    )),
    ('Structural Controllers', (
        ('StC_Group_N', '1'),
        ('StC_GroupIndex', '0'),
    )),
)


_FROM_DESIGN = {
    "F_LPFCornerFreq": "generator-speed low-pass of the baseline",
    "PC_GS_n": "entries of the PI schedule", "PC_GS_angles": "pitch grid of the PI schedule",
    "PC_GS_KP": "baseline kp at each pitch", "PC_GS_KI": "baseline ki at each pitch",
    "PC_MaxPit": "pitch limit", "PC_MinPit": "fine pitch", "PC_MaxRat": "pitch rate limit",
    "PC_MinRat": "pitch rate limit", "PC_RefSpd": "rated generator speed",
    "PC_FinePit": "fine pitch", "VS_GenEff": "generator efficiency (ServoDyn's GenEff)",
    "VS_ArSatTq": "rated torque", "VS_MaxRat": "torque rate limit",
    "VS_MaxTq": "torque limit", "VS_MinTq": "torque limit",
    "VS_MinOMSpd": "minimum generator speed", "VS_Rgn2K": "K of the torque law",
    "VS_RtPwr": "rated power", "VS_RtTq": "rated torque", "VS_RefSpd": "rated generator speed",
    "VS_KP": "torque PI at 0.2 rad/s, damping 0.7", "VS_KI": "torque PI",
    "VS_TSRopt": "C_P-optimal tip-speed ratio", "VS_ControlMode": "K omega^2 + PI transitions",
    "VS_ConstPower": "region-3 torque law of the design",
    "WE_BladeRadius": "tip radius", "WE_GearboxRatio": "gearbox ratio",
    "WE_Jtot": "rotor + generator inertia (low-speed shaft)", "WE_RhoAir": "air density",
    "PerfFileName": "written beside", "PerfTableSize": "its size (pitch, TSR)",
    "WE_FOPoles_N": "wind grid", "WE_FOPoles_v": "wind grid",
    "WE_FOPoles": "dQ/dOmega / J of the linear models", "SD_MaxGenSpd": "1.2 x rated speed",
    "IPC_ControlMode": "design", "SS_Mode": "no set-point smoothing in the baseline",
    "PS_Mode": "the design's minimum-pitch schedule (1), or none (0); no peak shaving",
    "WE_Mode": "hub-height wind, for the minimum-pitch table (no estimator in the baseline)",
    "LoggingLevel": "no debug files", "F_LPFType": "first order, as the baseline",
    "VS_FBP_n": "unused table", "VS_FBP_U": "unused table", "VS_FBP_Omega": "unused table",
    "VS_FBP_Tau": "unused table", "PRC_Table_n": "unused table", "PRC_R_Table": "unused table",
    "PRC_Pitch_Table": "unused table", "PRC_n": "unused table",
    "PRC_WindSpeeds": "unused table", "PRC_GenSpeeds": "rated generator speed",
    "PS_BldPitchMin_N": "minimum-pitch table",
    "PS_WindSpeeds": "minimum-pitch table: region 1.5 of the trim",
    "PS_BldPitchMin": "the trim's pitch in region 1.5 with a minimum-pitch schedule, else fine", "IPC_Vramp": "rated wind", "IPC_KI": "design",
    "IPC_aziOffset": "design", "IPC_IntSat": "design's largest cyclic amplitude",
}


def _torque_pi(turbine: linearize.Turbine, j_tot: float, dq_domega: float,
               omega_n: float = 0.2, zeta: float = 0.7) -> tuple[float, float]:
    """ROSCO's torque PI gains (its sign convention: torque = KP (ref - w_g) + KI int) for the
    rigid rotor J w_r' = Q - N T_g: the closed loop s^2 + 2 zeta w_n s + w_n^2."""
    n = turbine.drivetrain.gearbox_ratio
    a = dq_domega / j_tot            # per rad/s of rotor (= generator) speed deviation
    b = -n * n / j_tot               # generator speed per N m of generator torque
    return (2.0 * zeta * omega_n + a) / b, omega_n**2 / b


def _rotor_poles(turbine: linearize.Turbine) -> tuple[np.ndarray, np.ndarray, float]:
    """Wind grid [m/s], dQ/dOmega [N m s/rad] of the rigid rotor's linear models on it, and
    the drivetrain inertia on the low-speed shaft [kg m^2]."""
    op, dr = turbine.operation, turbine.drivetrain
    j_tot = linearize.plant_params(turbine).rotor_inertia \
        + dr.generator_inertia * dr.gearbox_ratio**2
    winds = np.arange(max(op.cut_in_wind, 3.0), op.cut_out_wind + 1e-9, 1.0)
    fam = linearize.linearize_family(turbine, winds,
                                     config=linearize.PlantConfig(frozenset({"generator"})),
                                     disturbance="rotor")
    dq = np.array([linearize.sensitivities(m)["dQ_domega"] for m in fam.models])
    return winds, dq, float(j_tot)


def rosco_values(turbine: linearize.Turbine, doc: dict[str, Any],
                 perf_file: str = "Cp_Ct_Cq.txt", ipc: dict[str, Any] | None = None
                 ) -> dict[str, Any]:
    """The design's values of ROSCO parameters (the others keep ROSCO's defaults).

    Parameters
    ----------
    turbine : Turbine
    doc : dict
        A baseline (or derated baseline) gain table (:func:`mpc_wt.kinds.baseline.baseline_table`).
    perf_file : str
        ``PerfFileName``, relative to the DISCON.IN.
    ipc : dict, optional
        A Coleman IPC gain table (:func:`mpc_wt.kinds.ipc.coleman_ipc_table`): ``IPC_ControlMode``
        1 with its integral gain (median over its schedule) and azimuth offset.

    Returns
    -------
    dict
        Parameter -> number, list of numbers or string.
    """
    from mpc_wt.controllers.baseline import effective_pi_gains

    st = doc["settings"]
    s = doc["schedule"]
    rows = np.asarray(s["rows"], dtype=float)
    op, dr, pa, gen = turbine.operation, turbine.drivetrain, turbine.pitch_actuator, \
        turbine.generator
    n = dr.gearbox_ratio
    top = float(rows[:, s["columns"].index("pitch")].max())
    ang = np.unique(np.r_[np.arange(st["min_pitch_rad"], top, math.radians(0.25)), top])
    kp, ki = effective_pi_gains(st["kp"], st["ki"], st["theta_k_rad"], ang)
    winds, dq, j_tot = _rotor_poles(turbine)
    v_rated = linearize.rated_wind_speed(turbine)
    vs_kp, vs_ki = _torque_pi(turbine, j_tot, float(np.interp(v_rated, winds, dq)))
    # ROSCO's VS_GenEff is the generator's (mechanical to electrical on the high-speed shaft,
    # ServoDyn's GenEff), without the gearbox's: it holds VS_RtPwr electrical with
    # VS_RtTq = VS_RtPwr / (VS_GenEff omega_g)
    eff = dr.generator_efficiency
    region3 = doc.get("settings", {}).get("region3", "constant_power")
    rated_gen = st["rated_gen_speed_rad_s"]
    fine = st["min_pitch_rad"]
    out: dict[str, Any] = {
        "LoggingLevel": 0, "F_LPFType": 1, "VS_ControlMode": 1,
        "VS_ConstPower": 0 if region3 == "constant_torque" else 1, "SS_Mode": 0,
        "PS_Mode": 0, "WE_Mode": 0, "IPC_ControlMode": 0,
        "F_LPFCornerFreq": 2.0 * math.pi * 0.25,
        "PC_GS_n": ang.size, "PC_GS_angles": ang, "PC_GS_KP": -kp, "PC_GS_KI": -ki,
        "PC_GS_KD": np.zeros(ang.size), "PC_GS_TF": np.zeros(ang.size),
        "PC_MaxPit": pa.max_pitch_rad, "PC_MinPit": fine, "PC_MaxRat": pa.max_rate_rad_s,
        "PC_MinRat": -pa.max_rate_rad_s, "PC_RefSpd": rated_gen, "PC_FinePit": fine,
        "VS_GenEff": 100.0 * eff, "VS_ArSatTq": st["rated_torque"],
        "VS_MaxRat": gen.max_torque_rate, "VS_MaxTq": gen.max_torque,
        "VS_MinTq": gen.min_torque, "VS_MinOMSpd": op.min_rotor_speed_rad_s * n,
        "VS_Rgn2K": st["k_opt"], "VS_RtPwr": st["rated_power"], "VS_RtTq": st["rated_torque"],
        "VS_RefSpd": rated_gen, "VS_KP": vs_kp, "VS_KI": vs_ki,
        "VS_TSRopt": linearize.optimal_tsr(turbine)[0],
        "VS_FBP_n": 2, "VS_FBP_U": [op.cut_in_wind, op.cut_out_wind],
        "VS_FBP_Omega": [rated_gen, rated_gen], "VS_FBP_Tau": [st["rated_torque"]] * 2,
        "PRC_Table_n": 2, "PRC_R_Table": [0.0, 1.0], "PRC_Pitch_Table": [fine, fine],
        "PRC_n": 2, "PRC_WindSpeeds": [op.cut_in_wind, op.cut_out_wind],
        "PRC_GenSpeeds": [rated_gen, rated_gen],
        "WE_BladeRadius": turbine.geometry.tip_radius, "WE_GearboxRatio": n,
        "WE_Jtot": j_tot, "WE_RhoAir": turbine.environment.air_density,
        "PerfFileName": f'"{perf_file}"', "PerfTableSize": [36, 26],
        "WE_FOPoles_N": winds.size, "WE_FOPoles_v": winds, "WE_FOPoles": dq / j_tot,
        "PS_BldPitchMin_N": 2, "PS_WindSpeeds": [op.cut_in_wind, op.cut_out_wind],
        "PS_BldPitchMin": [fine, fine], "SD_MaxGenSpd": 1.2 * rated_gen,
        "IPC_Vramp": [0.8 * v_rated, v_rated],
    }
    table = _min_pitch_table(turbine, st)
    if table is not None:
        out.update({"PS_Mode": 1, "PS_BldPitchMin_N": table[0].size,
                    "PS_WindSpeeds": table[0], "PS_BldPitchMin": table[1]})
    if ipc is not None:
        out.update(_ipc_values(ipc))
    return out


def _ipc_values(ipc: dict[str, Any]) -> dict[str, Any]:
    """ROSCO's IPC parameters from a Coleman IPC gain table: ``IPC_ControlMode`` 1, the median
    integral gain and azimuth offset over its schedule, the largest amplitude as the
    integrators' saturation."""
    cols = ipc["schedule"]["columns"]
    r = np.asarray(ipc["schedule"]["rows"], dtype=float)
    # ours: theta_cs = -K_I R(-phi) int M_cs; ROSCO: theta_cs = K_I R(-phi_R) int M_cs
    # (its offset enters the inverse transform only), so phi_R = phi - pi
    phi = float(np.median(r[:, cols.index("azimuth_offset")]))
    out: dict[str, Any] = {"IPC_ControlMode": 1,
                           "IPC_KI": [float(np.median(r[:, cols.index("ki")])), 0.0],
                           "IPC_aziOffset": [math.remainder(phi - math.pi, 2.0 * math.pi), 0.0]}
    amp = ipc["settings"].get("max_amplitude_rad")
    if amp is not None:           # ROSCO clamps each integrator; ours the amplitude
        out["IPC_IntSat"] = float(amp)
    return out


def _min_pitch_table(turbine: linearize.Turbine, st: dict[str, Any]
                     ) -> tuple[np.ndarray, np.ndarray] | None:
    """ROSCO's minimum-pitch table (``PS_BldPitchMin`` over ``PS_WindSpeeds``) for a design
    with a minimum-pitch schedule: ROSCO holds the minimum rotor speed with its torque PI in
    region 1.5, as the trim does, so the table is the trim's pitch there (the torque-maximizing
    pitch at minimum speed, :func:`linearize.trim`), then fine pitch to cut-out. None for a
    design without a schedule."""
    if not st.get("min_pitch_offsets_rad"):
        return None
    op = turbine.operation
    fine = op.fine_pitch_rad
    winds, pitch = [], []
    for v in np.linspace(op.cut_in_wind, linearize.rated_wind_speed(turbine), 30):
        tp = linearize.trim(turbine, float(v))
        winds.append(float(v))
        pitch.append(max(tp.pitch_rad, fine) if tp.region == "1.5" else fine)
        if tp.region != "1.5":
            break
    return np.r_[winds, op.cut_out_wind], np.r_[pitch, fine]


def _fmt(v: Any) -> str:
    if isinstance(v, str):
        return v
    a = np.atleast_1d(np.asarray(v, dtype=float))
    if a.size == 1 and isinstance(v, (int, np.integer)):
        return str(int(v))
    return "  ".join(f"{x:.10g}" for x in a)


def write_rosco_discon(turbine: linearize.Turbine, doc: dict[str, Any], out_dir: str | Path,
                       *, ipc: dict[str, Any] | None = None,
                       name: str = "DISCON.IN") -> list[Path]:
    """Write ``DISCON.IN`` (every ROSCO 2.10 parameter) and its ``Cp_Ct_Cq.txt``.

    Parameters
    ----------
    turbine : Turbine
    doc : dict
        A baseline gain table (derated or not).
    out_dir : str or Path
    ipc : dict, optional
        A Coleman IPC gain table to add.
    name : str
        The DISCON file's name.

    Returns
    -------
    list of Path
        The DISCON file and the performance table.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    perf_name = f"Cp_Ct_Cq.{turbine.name.split()[0].replace('/', '_')}.txt"
    tsr = np.arange(2.0, 14.5 + 1e-9, 0.5)
    pitch = np.arange(-5.0, 30.0 + 1e-9, 1.0)
    perf = linearize.rotor_performance(turbine, tsr, pitch, shear_exponent=0.0)
    perf_path = linearize.write_rotor_performance(perf, out / perf_name)
    vals = rosco_values(turbine, doc, perf_name, ipc)
    vals["PerfTableSize"] = [pitch.size, tsr.size]
    lines = [f"! ROSCO 2.10 DISCON.IN written by mpc-wt {__version__} for {turbine.name} "
             f"(design: {doc['kind']}, power fraction {doc['settings'].get('power_fraction', 1)})",
             "! Each line says where its value comes from: the mpc-wt design, or ROSCO's "
             "default for a feature this design leaves off.", ""]
    for section, items in ROSCO_PARAMETERS:
        lines.append(f"!------- {section} " + "-" * max(4, 70 - len(section)))
        for key, default in items:
            if key in vals:
                value, note = _fmt(vals[key]), f"mpc-wt: {_FROM_DESIGN.get(key, 'design')}"
            else:
                value, note = default, "ROSCO default"
            lines.append(f"{value:<20s} ! {key:<22s} - {note}")
        lines.append("")
    p = out / name
    p.write_text("\n".join(lines) + "\n")
    return [p, perf_path]
