"""The plant's rotor aerodynamics against AeroDyn 15 itself (OpenFAST v5.0.0's AeroDyn driver on
the NREL 5-MW inputs of OpenFAST's regression case ``5MW_Land_DLL_WTurb``; the runs and their
conditions are in ``tests/data/openfast_v5_nrel5mw_checks.json`` and ``tests/data/README.md``),
and the tower base's share of the blades' flap inertia against the momentum balance."""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

import linearize
from linearize import OUTPUT_NAMES, PlantConfig

_Z = {n: i for i, n in enumerate(OUTPUT_NAMES)}
_CHECKS = json.loads((Path(__file__).resolve().parents[1] / "data"
                      / "openfast_v5_nrel5mw_checks.json").read_text())


@pytest.fixture(scope="module")
def turbine() -> linearize.Turbine:
    return linearize.load_turbine("nrel5mw")


def _rotor_means(turbine: linearize.Turbine, cfg: PlantConfig, wind: float, rpm: float,
                 pitch_deg: float, x_extra: dict[int, float] | None = None,
                 revolutions: int = 2) -> tuple[float, float]:
    """Aerodynamic torque and thrust [kN m, kN] over the last whole revolutions of a run at a held
    rotor speed and pitch in a steady uniform wind, after 5 s in which the unsteady airfoil
    states settle (the tower's flow makes the loads periodic: whole revolutions)."""
    params = linearize.plant_params(turbine, cfg)
    x0 = np.zeros(len(linearize.STATE_NAMES))
    x0[2] = rpm * math.pi / 30
    x0[3] = x0[2] * turbine.drivetrain.gearbox_ratio
    x0[5:8] = math.radians(pitch_deg)
    for k, v in (x_extra or {}).items():
        x0[k] = v
    u = np.array([x0[5], x0[6], x0[7], 0.0])
    period = 2 * math.pi / x0[2]
    duration = 5.0 + revolutions * period
    res = linearize.rk4_simulate(params, x0, u, linearize.SteadyWind(wind, 0.0), duration)
    late = res.t > duration - revolutions * period
    return (float(res.z[late, _Z["aero_torque"]].mean()) / 1e3,
            float(res.z[late, _Z["thrust"]].mean()) / 1e3)


@pytest.mark.parametrize("row", _CHECKS["steady_rigid_rotor"],
                         ids=lambda r: f"{r['wind_mps']:g}mps-{r['pitch_deg']:g}deg")
def test_rigid_rotor_torque_and_thrust_are_aerodyn_15s(turbine, row) -> None:
    """A rigid rotor held at speed and pitch in steady wind, AeroDyn 15's options as the case runs
    them (BEM with tip and hub losses, tangential induction, tower potential flow, skew
    correction; UA_Mod 3 and without it) and AeroDyn 15's integration of its nodes' line loads
    (``PlantConfig.openfast``, AeroDyn's tip node included: its inductions fixed at a = 1,
    a' = 0, as AeroDyn's node outputs show): torque within 1.0 %, thrust within 1.2 %
    (measured on 2026-11-30: torque -0.92 to -0.37 %, thrust -1.01 to -0.38 %, largest at
    18 m/s, 14 deg; without the tip node's load the torque was -0.51 to -0.28 %, its drag
    missing, and the thrust -1.2 to +2.3 %); the unsteady model's steady loss of torque
    (AeroDyn: 3.8-5.9 %) within 0.3 points."""
    base = PlantConfig.openfast(dofs=frozenset())
    out = {}
    for ua in (False, True):
        cfg = dataclasses.replace(base, unsteady_aero=ua)
        q, f = _rotor_means(turbine, cfg, row["wind_mps"], row["rotor_speed_rpm"],
                            row["pitch_deg"])
        tag = "ua3" if ua else "ua0"
        q_ref, f_ref = row[f"torque_kNm_{tag}"], row[f"thrust_kN_{tag}"]
        assert abs(q / q_ref - 1) <= 0.010, (tag, q, q_ref)
        assert abs(f / f_ref - 1) <= 0.012, (tag, f, f_ref)
        out[tag] = q
    loss, loss_ref = (1 - out["ua3"] / out["ua0"],
                      1 - row["torque_kNm_ua3"] / row["torque_kNm_ua0"])
    assert abs(loss - loss_ref) <= 0.003, (loss, loss_ref)


@pytest.mark.parametrize("row", _CHECKS["deflected_blade"],
                         ids=lambda r: f"pitch{r['pitch_deg']:g}")
def test_a_deflected_blade_meets_the_wind_as_in_aerodyn_15(turbine, row) -> None:
    """Every blade deflected 4.04 m at the tip in its first flap mode (the case's mean
    out-of-plane tip deflection), against the straight blade: AeroDyn 15 with the deflection as
    an inextensible prebend (``BlCrvAC``, ``BlCrvAng``, spans shortened), without the pitching
    moment, the aerodynamic-centre offsets, the skew correction and the tower's flow, which
    the comparison leaves out. At pitch 0 (modes in the rotor plane): torque -0.340 %, thrust
    -0.271 %; at 4.1 deg the prebend turns with the pitch, as the plant's modes do along their
    pitched axes (structural twist set to zero): -0.617 % and -0.672 %. The plant's changes
    within 0.1 points (torque) and 0.3 points (thrust); without ``deflected_blades`` the loads do
    not change at all."""
    twisted = row["pitch_deg"] != 0.0
    t = turbine
    if twisted:
        bs = t.blade_structure
        t = dataclasses.replace(t, blade_structure=dataclasses.replace(
            bs, structural_twist_rad=np.zeros_like(bs.structural_twist_rad)))
    cfg = PlantConfig(frozenset({"blade_flap"}), integration="trapezoid",
                      twisted_modes=twisted, deflected_blades=True)
    q_mode = 4.04
    # the flap DOF on but held: its stiffness carries the load, so hold the deflection by
    # sampling one instant (no time for it to move) over a revolution's azimuths
    params = linearize.plant_params(t, cfg)
    off = linearize.plant_params(t, dataclasses.replace(cfg, deflected_blades=False))
    loads = {}
    for name, p, q in (("straight", params, 0.0), ("deflected", params, q_mode),
                       ("ignored", off, q_mode)):
        zs = []
        for psi in np.radians(np.arange(0.0, 120.0, 10.0)):
            x = np.zeros(len(linearize.STATE_NAMES))
            x[2] = row["rotor_speed_rpm"] * math.pi / 30
            x[3] = 97.0 * x[2]
            x[5:8] = math.radians(row["pitch_deg"])
            x[10:13] = q
            x[16] = psi
            d = np.full((3, p.pack.r.size), row["wind_mps"])
            zs.append(linearize.plant_outputs(0.0, x, np.array([*x[5:8], 0.0]), d, p))
        z = np.mean(zs, axis=0)
        loads[name] = (z[_Z["aero_torque"]], z[_Z["thrust"]])
    dq = loads["deflected"][0] / loads["straight"][0] - 1
    df = loads["deflected"][1] / loads["straight"][1] - 1
    dq_ref = row["torque_kNm_deflected"] / row["torque_kNm_straight"] - 1
    df_ref = row["thrust_kN_deflected"] / row["thrust_kN_straight"] - 1
    assert abs(dq - dq_ref) <= 0.001, (dq, dq_ref)
    assert abs(df - df_ref) <= 0.003, (df, df_ref)
    if not twisted:
        # the straight blade's loads do not depend on the switch
        assert loads["ignored"][0] == pytest.approx(loads["straight"][0], rel=1e-12)


def test_the_tower_base_takes_the_blades_flap_inertia(turbine) -> None:
    """A parked rotor in still air, without gravity, its tower rigid and its blades ringing in
    their collective flap mode: nothing else acts, so the hub pushes the blades with the rate of
    their axial momentum, sum int m phi q' dr, and the blades push the hub back (Newton's second
    and third laws): the tower base's moment is minus that rate times the hub height. The
    momentum rate is differenced from the recorded flap rates; the plant's output follows it
    within 1 % of its amplitude."""
    cfg = PlantConfig(frozenset({"blade_flap"}), aero=linearize.AeroOptions(gravity=False))
    params = linearize.plant_params(turbine, cfg)
    x0 = np.zeros(len(linearize.STATE_NAMES))
    x0[10:13] = 0.5
    res = linearize.rk4_simulate(params, x0, np.zeros(4), linearize.SteadyWind(0.0), 4.0)
    rates = res.x[:, [13, 14, 15]].sum(axis=1)
    dt = res.t[1] - res.t[0]
    momentum_rate = np.gradient(rates, dt) * params.pack.g_b
    moment = res.z[:, _Z["tower_base_fa_moment"]]
    expected = -momentum_rate * params.pack.zhub
    fluct = moment - moment.mean() + expected.mean()
    amp = np.abs(expected).max()
    assert amp > 1e5                       # the blades do ring (about 1 MN m at the base)
    inner = slice(2, -2)                   # the one-sided differences at the ends
    assert np.abs(fluct[inner] - expected[inner]).max() <= 0.01 * amp
