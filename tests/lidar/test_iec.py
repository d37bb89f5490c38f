"""IEC 61400-1 ed. 3 wind conditions: the standard's formulas at sample times,
hand-worked magnitudes, ROSCO's pyIECWind as a peer, bad input."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import lidar
from lidar import IECSite, iec_field

SITE = IECSite("I", "A", hub_height=90.0, diameter=126.0, cut_in=3.0, cut_out=25.0)


def _hub(f: lidar.WindField, comp: str = "u") -> np.ndarray:
    j, k = int(np.argmin(np.abs(f.y))), int(np.argmin(np.abs(f.z - f.hub_height)))
    return np.asarray(getattr(f, comp)[:, j, k], float)


@pytest.mark.parametrize("cls, expected", [("I", 12.936), ("II", 12.936), ("III", 9.45)])
def test_eog_magnitude_per_class(cls: str, expected: float) -> None:
    """Hand-worked (eq 16) at V_hub = 35 m/s, category A, z_hub 90 m, D 126 m: sigma_1 =
    0.16 (0.75 * 35 + 5.6) = 5.096, Lambda_1 = 42 m, 3.3 sigma_1 / 1.3 = 12.936;
    V_e1 = 0.8 * 1.4 V_ref = 56, 47.6, 42 m/s, 1.35 (V_e1 - 35) = 28.35, 17.01, 9.45: class III
    is set by the extreme speed, I and II by the turbulence."""
    site = IECSite(cls, "A", 90.0, 126.0)
    assert site.magnitudes(35.0)["eog_gust"] == pytest.approx(expected, abs=5e-4)


def test_eog_magnitude_at_rated_hand_worked() -> None:
    # NREL 5-MW, class I A, 11.4 m/s: sigma_1 = 0.16 * 14.15 = 2.264, 3.3 * 2.264 / 1.3
    assert SITE.magnitudes(11.4)["eog_gust"] == pytest.approx(5.74708, abs=1e-5)
    assert SITE.lambda_1 == 42.0 and IECSite(hub_height=50.0, diameter=80.0).lambda_1 == 35.0


def test_eog_time_history_follows_eq_17() -> None:
    """V(z, t) = V(z) - 0.37 V_gust sin(3 pi t / T)(1 - cos(2 pi t / T)) at the grid's hub point
    at every sample, steady before and after; the peak is +0.74 V_gust at T / 2 and the dip
    before it -0.37 V_gust times the maximum of sin(3 pi x)(1 - cos 2 pi x) on [0, 1/3]."""
    f = iec_field("eog", 11.4, SITE, t_start=20.0, dt=0.05, n=9)
    vg, T = SITE.magnitudes(11.4)["eog_gust"], 10.5
    tau = f.t - 20.0
    x = np.clip(tau / T, 0.0, 1.0)
    expected = 11.4 - 0.37 * vg * np.sin(3 * np.pi * x) * (1 - np.cos(2 * np.pi * x))
    assert_allclose(_hub(f), expected, rtol=0, atol=2e-5)   # float32 storage
    k = int(np.argmin(np.abs(tau - T / 2)))
    assert _hub(f)[k] == pytest.approx(11.4 + 0.74 * vg, abs=1e-4)
    xx = np.linspace(0, 1 / 3, 100001)
    dip = (np.sin(3 * np.pi * xx) * (1 - np.cos(2 * np.pi * xx))).max()
    assert _hub(f).min() == pytest.approx(11.4 - 0.37 * vg * dip, abs=5e-3)
    assert np.all(f.v == 0) and np.all(f.w == 0)
    # the same gust at every height, on the power-law profile
    top = f.u[:, 4, -1] - f.u[0, 4, -1]
    assert_allclose(top, _hub(f) - 11.4, atol=3e-5)
    assert f.u[0, 4, -1] == pytest.approx(11.4 * (f.z[-1] / 90.0) ** 0.2, rel=1e-6)


def test_ecd_speed_and_direction() -> None:
    """Eqs 22-24: the speed rises by 0.5 V_cg (1 - cos(pi t / T)) to V + 15 m/s while the
    direction turns by theta_cg = 720 / V_hub deg (63.16 deg at 11.4 m/s), both held after T;
    the vector's angle atan2(v, u) is the direction; 180 deg below 4 m/s."""
    f = iec_field("ecd", 11.4, SITE, t_start=5.0, dt=0.1, n=5)
    tau = f.t - 5.0
    ramp = np.where(tau < 0, 0.0, np.where(tau > 10.0, 1.0, 0.5 * (1 - np.cos(np.pi * tau / 10))))
    speed = np.hypot(_hub(f), _hub(f, "v"))
    assert_allclose(speed, 11.4 + 15.0 * ramp, atol=2e-5)
    angle = np.degrees(np.arctan2(_hub(f, "v"), _hub(f)))
    assert_allclose(angle, 720.0 / 11.4 * ramp, atol=1e-4)
    assert SITE.magnitudes(11.4)["ecd_deg"] == pytest.approx(63.158, abs=1e-3)
    assert SITE.magnitudes(3.5)["ecd_deg"] == 180.0
    neg = iec_field("ecd", 11.4, SITE, t_start=5.0, dt=0.1, n=5, sign=-1)
    assert np.degrees(np.arctan2(_hub(neg, "v")[-1], _hub(neg)[-1])) == pytest.approx(-63.158,
                                                                                     abs=1e-3)


def test_ews_linear_shear_and_hand_worked_amplitude() -> None:
    """Eqs 25-26: the speed departs from the power-law profile by A (z - z_hub) / D (1 - cos(2
    pi t / T)) vertically, A (y / D)(...) horizontally; A = 2.5 + 0.2 * 6.4 * sigma_1 (D /
    Lambda_1)^(1/4) = 2.5 + 1.28 * 2.264 * 3^(1/4) = 6.3139 m/s at 11.4 m/s."""
    amp = 2.5 + 1.28 * 2.264 * 3 ** 0.25
    assert SITE.magnitudes(11.4)["ews_amplitude"] == pytest.approx(amp, rel=1e-12)
    assert amp == pytest.approx(6.3139, abs=1e-4)
    for cond, axis in (("ews-v", "z"), ("ews-h", "y")):
        f = iec_field(cond, 11.4, SITE, t_start=2.0, dt=0.1, n=7)
        k = int(np.argmin(np.abs(f.t - 8.0)))                # T / 2 into the event: 1 - cos = 2
        base = 11.4 * (f.z / 90.0) ** 0.2
        dev = f.u[k] - base[None, :]
        lever = (f.z - 90.0) / 126.0 if axis == "z" else f.y / 126.0
        want = 2.0 * amp * (lever[None, :] if axis == "z" else lever[:, None])
        assert_allclose(dev, np.broadcast_to(want, dev.shape), atol=3e-5)
        assert_allclose(f.u[0] - base[None, :], 0.0, atol=2e-6)


def test_edc_and_etm_hand_worked() -> None:
    # EDC (eq 20): 4 atan(2.264 / (11.4 * 1.3)) = 34.743 deg; ETM (eq 19) at 15 m/s, class I
    # A: 2 * 0.16 (0.072 (10 / 2 + 3)(15 / 2 - 4) + 10) = 3.84512 m/s
    assert SITE.magnitudes(11.4)["edc_deg"] == pytest.approx(
        4 * math.degrees(math.atan(2.264 / (11.4 * 1.3))), rel=1e-12)
    assert SITE.magnitudes(11.4)["edc_deg"] == pytest.approx(34.743, abs=1e-3)
    assert SITE.magnitudes(15.0)["sigma_etm"] == pytest.approx(3.84512, abs=1e-5)
    f = iec_field("edc", 11.4, SITE, t_start=1.0, dt=0.1, n=5, sign=-1)
    assert np.degrees(np.arctan2(_hub(f, "v")[-1], _hub(f)[-1])) == pytest.approx(-34.743,
                                                                                 abs=1e-3)


def test_etm_field_carries_the_extreme_sigma() -> None:
    f = iec_field("etm", 15.0, SITE, duration=600.0, dt=0.1, n=6, seed=3, width=120.0)
    assert f.meta["sigma_1"] == pytest.approx(3.84512, abs=1e-5)
    # Kaimal field: hub std within 15 % of sigma_1 over 600 s (one seed)
    assert _hub(f).std() == pytest.approx(3.84512, rel=0.15)


def _peer_wnd(method: str, v_hub: float, tmp: Path, **attrs: object) -> list[np.ndarray]:
    """ROSCO's pyIECWind (the toolbox's IECWind port) writes .wnd hub-height files; their rows
    (time, speed, direction, vertical speed, horizontal linear shear, power-law exponent,
    vertical linear shear, gust speed, upflow)."""
    mod = pytest.importorskip("rosco.toolbox.ofTools.fast_io.pyIECWind")
    gen = mod.pyIECWind_extreme()
    gen.Turbine_Class, gen.Turbulence_Class = "I", "A"
    gen.z_hub, gen.D, gen.TStart, gen.dt, gen.TF = 90.0, 126.0, 10.0, 0.05, 60.0
    gen.outdir, gen.case_name = str(tmp), "peer"
    for k, v in attrs.items():
        setattr(gen, k, v)
    getattr(gen, method)(v_hub)
    return [np.loadtxt(p, comments="!") for p in gen.fname_out]


def test_against_roscos_pyiecwind(tmp_path: Path) -> None:
    """Peer: ROSCO's pyIECWind. ECD: our hub speed and direction equal its speed and direction
    columns at its sample times (both signs); EWS: its linear shear column times V_hub (its
    shears are relative to the hub speed, over the rotor diameter) is our amplitude times
    (1 - cos)."""
    ecd = _peer_wnd("ECD", 11.4, tmp_path, dir_change="both")
    for rows, sign in zip(ecd, (1, -1)):
        f = iec_field("ecd", 11.4, SITE, t_start=10.0, dt=0.05, n=5, sign=sign)
        t = rows[1:-1, 0]
        idx = np.rint(t / 0.05).astype(int)
        speed = np.hypot(_hub(f), _hub(f, "v"))[idx]
        assert_allclose(speed, rows[1:-1, 1], atol=2e-5)
        ang = np.degrees(np.arctan2(_hub(f, "v"), _hub(f)))[idx]
        assert_allclose(ang, rows[1:-1, 2], atol=2e-5)
    ews = _peer_wnd("EWS", 11.4, tmp_path, dir_change="+", shear_orient="v")
    rows = ews[0]
    f = iec_field("ews-v", 11.4, SITE, t_start=10.0, dt=0.05, n=7)
    idx = np.rint(rows[1:-1, 0] / 0.05).astype(int)
    top = f.u[idx, 3, -1] - 11.4 * (f.z[-1] / 90.0) ** 0.2
    assert_allclose(top, rows[1:-1, 6] * 11.4 * (f.z[-1] - 90.0) / 126.0, atol=3e-5)


@pytest.mark.parametrize("kwargs, match", [
    (dict(condition="eog", mean_speed=26.0), r"mean_speed 26 m/s is above the turbine's "
                                             r"cut-out 25 m/s.*V_in <= V_hub <= V_out"),
    (dict(condition="ecd", mean_speed=2.0), r"below the turbine's cut-in 3 m/s"),
    (dict(condition="gust", mean_speed=10.0), r"condition must be one of \[.*'eog'.*\], got "
                                              r"'gust'"),
    (dict(condition="eog", mean_speed=math.nan), r"mean_speed must be finite and > 0, got nan"),
    (dict(condition="eog", mean_speed=-3.0), r"mean_speed must be finite and > 0, got -3.0"),
    (dict(condition="ews-v", mean_speed=10.0, sign=0), r"sign must be 1 or -1, got 0"),
    (dict(condition="eog", mean_speed=10.0, n=1), r"n must be an integer >= 2"),
    (dict(condition="eog", mean_speed=10.0, width=200.0), r"width 200 m reaches the ground"),
])
def test_bad_input_names_the_value(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        iec_field(site=SITE, **kwargs)


@pytest.mark.parametrize("args, match", [
    (("IV", "A"), r"turbine_class must be one of \['I', 'II', 'III'\].*got 'IV'"),
    (("S", "A"), r"turbine_class must be one of .*got 'S'"),
    (("I", "D"), r"turbulence_class must be one of \['A', 'B', 'C'\].*got 'D'"),
])
def test_classes_the_standard_lacks(args: tuple, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        IECSite(*args)


def test_ecd_above_v_ref_and_eog_above_v_e1() -> None:
    site = IECSite("III", "A", 90.0, 126.0)
    with pytest.raises(ValueError, match=r"above V_ref = 37.5 m/s of class III"):
        site.check_speed("ecd", 40.0)
    with pytest.raises(ValueError, match=r"not below V_e1 = 42 m/s of class III"):
        site.check_speed("eog", 43.0)


def test_extreme_wind_model_speeds() -> None:
    # eqs 14-15: class II, 1.4 * 42.5 = 59.5 m/s at the hub, 0.8 of it for one year, and
    # (z / z_hub)^0.11 above: at 2 z_hub 59.5 * 2^0.11 = 64.15 m/s
    site = IECSite("II", "B", 90.0, 126.0)
    assert site.extreme_speed() == pytest.approx(59.5)
    assert site.extreme_speed(years=1) == pytest.approx(47.6)
    assert site.extreme_speed(180.0) == pytest.approx(59.5 * 2 ** 0.11)
    with pytest.raises(ValueError, match="years must be 50 or 1.*got 10"):
        site.extreme_speed(years=10)
