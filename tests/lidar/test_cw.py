"""CW LIDAR: analytic projection, range weighting, exact idealized preview, lag, lead angle."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy import integrate

import lidar
from lidar import CWLidar, TurbulenceSpec, WindField, generate_field

OMEGA = 12.1 * math.pi / 30


def _uniform_field(u: float, v: float, w: float, duration: float = 60.0) -> WindField:
    t = np.arange(0.0, duration, 0.5)
    y = np.linspace(-150, 150, 7)
    z = np.linspace(-60, 240, 7)
    shp = (t.size, y.size, z.size)
    return WindField(t=t, y=y, z=z, u=np.full(shp, u), v=np.full(shp, v), w=np.full(shp, w),
                     mean_speed=u, hub_height=90.0)


@pytest.fixture(scope="module")
def turbulent() -> WindField:
    spec = TurbulenceSpec(18.0, "A", duration=420.0, n_y=24, n_z=24)
    return generate_field(spec, 11)


def test_uniform_inclined_flow_gives_projected_los() -> None:
    # analytic: a beam with unit vector e sees -(e . V); here e = (-cos b, -sin b sin a,
    # sin b cos a) for half-cone angle b and beam azimuth a; the range weights sum to 1
    u, v, w = 12.0, 2.0, -1.0
    lid = CWLidar(63.0)
    t = np.array([0.0, 1.0, 2.0])
    psi = np.array([0.0, 1.0, 2.5])
    m = lid.measure(_uniform_field(u, v, w), t, psi, 0.0)
    b = lid.cone_angle_rad
    a = m.beam_azimuth_rad
    expected = u * math.cos(b) + v * math.sin(b) * np.sin(a) - w * math.sin(b) * np.cos(a)
    assert_allclose(m.los, expected, rtol=1e-12, atol=1e-12)


def test_range_weighting_integrates_to_one_and_has_the_half_width() -> None:
    lid = CWLidar(63.0)
    tot, _ = integrate.quad(lid.weighting, 0, np.inf, limit=500)
    assert_allclose(tot, 1.0, rtol=1e-8, atol=0)
    s, wts = lid.range_quadrature(200.0)
    assert_allclose(wts.sum(), 1.0, rtol=1e-14, atol=0)   # the whole weight counts
    # analytic: Lorentzian half-width at half maximum = lambda F^2 / (pi a^2); find the
    # half-maximum point numerically and compare (bound 1 %)
    f = lid.focus_range
    from scipy.optimize import brentq

    half = brentq(lambda x: lid.weighting(f + x) - 0.5 * lid.weighting(f), 1e-6, 100.0)
    assert_allclose(half, 1.565e-6 * f**2 / (math.pi * 0.028**2), rtol=0.01, atol=0)


def test_idealized_preview_equals_later_blade_wind(turbulent: WindField) -> None:
    # Point measurement, no LOS error, aligned, frozen turbulence -> the preview is the
    # wind the blade meets T_p later, up to interpolation (here the same trilinear sampler)
    lid = CWLidar(63.0, range_weighting=False, los_error=False)
    t = np.arange(0.0, 300.0, 0.1)
    psi = OMEGA * t
    m = lid.measure(turbulent, t, psi, OMEGA)
    tp = m.preview_time
    later = lidar.blade_effective_wind(turbulent, t + tp, psi + OMEGA * tp, lid.radius)
    assert_allclose(m.u_hat, later, rtol=0, atol=1e-9)


def test_realistic_lidar_loses_coherence_with_frequency(turbulent: WindField) -> None:
    lid = CWLidar(63.0)
    t = np.arange(0.0, 300.0, 0.1)
    psi = OMEGA * t
    m = lid.measure(turbulent, t, psi, OMEGA)
    later = lidar.blade_effective_wind(turbulent, t + m.preview_time,
                                       psi + OMEGA * m.preview_time, lid.radius)
    f, g = lidar.coherence(m.u_hat[:, 0], later[:, 0], 10.0, nperseg=512)
    ideal = CWLidar(63.0, range_weighting=False, los_error=False).measure(turbulent, t, psi, OMEGA)
    _, g_ideal = lidar.coherence(ideal.u_hat[:, 0], later[:, 0], 10.0, nperseg=512)
    # Idealized, the estimate is the later blade wind (coherence 1); with range
    # weighting and LOS error it falls with frequency and the bandwidth (coherence 0.5) is
    # reported. The Lorentzian's sharp centre keeps part of the point's high-frequency content,
    # so the fall is gradual (about 0.7 below 0.2 Hz, 0.5 above 3 Hz at 18 m/s, class A).
    assert g_ideal[f > 0].min() > 0.999
    low, high = g[(f > 0) & (f < 0.2)].mean(), g[f > 3.0].mean()
    assert low < 0.95 and low - high > 0.1
    bw = lidar.coherence_bandwidth(f, g)
    assert 0.1 < bw < 5.0


def test_lag_of_peak_correlation_is_the_preview_time(turbulent: WindField) -> None:
    lid = CWLidar(63.0)
    t = np.arange(0.0, 300.0, 0.1)
    psi = OMEGA * t
    m = lid.measure(turbulent, t, psi, OMEGA)
    blade = lidar.blade_effective_wind(turbulent, t, psi, lid.radius)
    lag = lidar.peak_lag(m.u_hat[:, 0], blade[:, 0], 0.1, 8.0)
    assert_allclose(lag, 54.0 / 18.0, rtol=0, atol=0.05)


def test_lead_angle_is_omega_tp() -> None:
    # About 218 deg at 18 m/s with D = 54 m and 12.1 rpm
    lid = CWLidar(63.0)
    ang = lid.beam_azimuths(np.array([0.3]), np.array([OMEGA]), 18.0)
    lead = (ang[0] - (0.3 + 2 * math.pi * np.arange(3) / 3))
    assert_allclose(lead, OMEGA * 3.0, rtol=1e-12)
    assert_allclose(math.degrees(OMEGA * 3.0), 217.8, atol=0.05)


def test_preview_shape_and_times(turbulent: WindField) -> None:
    lid = CWLidar(63.0, range_weighting=False, los_error=False)
    t = np.arange(0.0, 60.0, 0.1)
    m = lid.measure(turbulent, t, OMEGA * t, OMEGA)
    p = lidar.preview(m, 30.0, horizon=15, dt=0.1)
    assert p.blade.shape == (15, 3) and p.rotor.shape == (15,)
    assert_allclose(p.t, 30.0 + 0.1 * np.arange(1, 16), rtol=0, atol=1e-12)
    assert p.measured.all()
    later = lidar.blade_effective_wind(turbulent, p.t, OMEGA * p.t, lid.radius)
    assert_allclose(p.blade, later, rtol=0, atol=1e-6)
    series = lidar.preview_series(m, np.array([30.0, 31.0]))
    assert series.shape == (2, 15, 3) and np.allclose(series[0], p.blade)
    with pytest.raises(ValueError, match="horizon must be an integer >= 1"):
        lidar.preview(m, 30.0, horizon=0)


def test_ring_buffer_serves_the_true_later_blade_wind(turbulent: WindField) -> None:
    """The in-loop preview from the fixed-size ring buffer, pushed one step at a
    time, is the wind each blade meets T_p later (idealized LIDAR, frozen field: exact to
    1e-6 m/s once a whole T_p is measured), while the buffer never holds more than
    ceil(T_p / dt) + 3 samples (600 pushes, 33 kept)."""
    lid = CWLidar(63.0, range_weighting=False, los_error=False)
    t = np.arange(0.0, 60.0, 0.1)
    m = lid.measure(turbulent, t, OMEGA * t, OMEGA)
    buf = lidar.PreviewBuffer(m.preview_time, 0.1)
    assert buf.capacity == math.ceil(m.preview_time / 0.1) + 3 < 40
    for k, tk in enumerate(t):
        buf.push(float(tk), m.u_hat[k])
        assert len(buf) <= buf.capacity
        if tk >= m.preview_time and k % 7 == 0:
            p = buf.preview(float(tk), 15)
            assert p.measured.all()
            later = lidar.blade_effective_wind(turbulent, p.t, OMEGA * p.t, lid.radius)
            assert_allclose(p.blade, later, rtol=0, atol=1e-6)
    assert len(buf) == buf.capacity and buf.history()[0][0] == pytest.approx(t[-buf.capacity])


@settings(max_examples=40, deadline=None)
@given(tp=st.floats(0.05, 6.0), dt=st.floats(0.01, 0.5), horizon=st.integers(1, 40),
       n=st.integers(1, 300), seed=st.integers(0, 2**16))
def test_ring_buffer_preview_equals_the_whole_history(tp, dt, horizon, n, seed) -> None:
    """Property: at every step the ring buffer's preview equals :func:`lidar.preview` on the
    whole measurement history (which keeps everything), whatever T_p, dt, horizon and length
    (held values beyond T_p and the start-up clipping included)."""
    rng = np.random.default_rng(seed)
    t = dt * np.arange(n) + 3.0
    u = 10 + rng.standard_normal((n, 3))
    buf = lidar.PreviewBuffer(tp, dt)
    for k in range(n):
        buf.push(float(t[k]), u[k])
        if k % max(1, n // 20) == 0 or k == n - 1:
            hist = lidar.LidarMeasurement(t=t[:k + 1], los=u[:k + 1], u_hat=u[:k + 1],
                                          beam_azimuth_rad=np.zeros((k + 1, 3)),
                                          preview_time=tp, radius=45.0)
            want = lidar.preview(hist, float(t[k]), horizon, dt)
            got = buf.preview(float(t[k]), horizon)
            assert_allclose(got.blade, want.blade, rtol=0, atol=1e-12)
            assert np.array_equal(got.measured, want.measured)
    assert len(buf) <= math.ceil(tp / dt) + 3


def test_ring_buffer_bad_input() -> None:
    """Bad input names the parameter and what is allowed."""
    with pytest.raises(ValueError, match="preview_time must be > 0 s"):
        lidar.PreviewBuffer(0.0, 0.1)
    with pytest.raises(ValueError, match="dt must be > 0 s"):
        lidar.PreviewBuffer(3.0, math.nan)
    buf = lidar.PreviewBuffer(1.0, 0.1)
    with pytest.raises(ValueError, match="outside the kept measurements .none yet"):
        buf.preview(0.0)
    buf.push(1.0, np.ones(3))
    with pytest.raises(ValueError, match="must be later than the last measurement 1 s"):
        buf.push(1.0, np.ones(3))
    with pytest.raises(ValueError, match="horizon must be an integer >= 1"):
        buf.preview(1.0, 0)


def test_focus_outside_field_is_an_error(turbulent: WindField) -> None:
    t = np.arange(0.0, turbulent.t[-1] - 15.0, 0.1)
    # 400 m ahead at 18 m/s is 22 s: beyond the end of the field for the last measurements
    with pytest.raises(ValueError, match=r"focus_distance = 400 m puts the focus .* beyond "
                                         r"the field's duration"):
        CWLidar(63.0, focus_distance=400.0).measure(turbulent, t, OMEGA * t, OMEGA)
    # a 100 m rotor's circle (75 m) and its beams leave a 150 m wide field
    with pytest.raises(ValueError, match=r"beyond the field's lateral/vertical extent"):
        CWLidar(100.0).measure(turbulent, t[:50], OMEGA * t[:50], OMEGA)


def test_field_shorter_than_simulation_plus_preview(turbulent: WindField) -> None:
    t = np.arange(0.0, turbulent.t[-1] - 1.0, 0.1)          # the preview needs 3 s more
    with pytest.raises(ValueError, match=r"beyond the field's duration"):
        CWLidar(63.0).measure(turbulent, t, OMEGA * t, OMEGA)


@pytest.mark.parametrize("kwargs, match", [
    (dict(focus_distance=0.0), "focus_distance must be a finite number > 0"),
    (dict(span_fraction=1.2), "span_fraction must be in"),
    (dict(noise_std=-1.0), "noise_std must be >= 0"),
    (dict(misalignment_rad=2.0), "misalignment_rad must be in"),
])
def test_bad_lidar(kwargs, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        CWLidar(63.0, **kwargs)


def test_rotor_effective_wind(turbulent: WindField) -> None:
    rews = lidar.rotor_effective_wind(turbulent, 63.0)
    assert rews.shape == turbulent.t.shape
    # the disc average has less variance than a point (spatial filtering)
    assert rews.std() < turbulent.u[:, 12, 12].std()
    assert lidar.rotor_effective_wind(turbulent, 63.0, "cube").mean() >= rews.mean()


@pytest.mark.parametrize("radius", [63.0, 89.2, 120.0, 142.0])
def test_the_default_focus_grows_with_the_rotor(radius: float) -> None:
    """Madsen et al. (2012, sec. II-E) focus 54 m ahead of the NREL 5-MW's 63 m rotor; by
    default any rotor's LIDAR keeps their beam half-cone angle at 75 % span, atan(47.25 / 54)
    = 41.19 deg, under the 45 deg their reference recommends, and a preview that grows with
    the rotor."""
    lid = CWLidar(radius)
    assert math.degrees(lid.cone_angle_rad) == pytest.approx(41.186, abs=1e-3)
    assert lid.focus_distance == pytest.approx(54.0 * radius / 63.0, rel=1e-12)
    if radius == 63.0:
        assert lid.focus_distance == 54.0
    assert CWLidar(radius, focus_distance=30.0).focus_distance == 30.0
