"""The coherence a hub-mounted CW LIDAR can achieve with the rotor-effective wind, from the
turbulence model alone (Schlipf 2015, ch. 4-5; Simley, Pao, Frehlich, Jonkman and Kelley
2014).

The LIDAR's rotor-effective estimate is the mean of the three beams' reconstructed speeds,
u_L(t) = (1/3) sum_i sum_k w_k u_hat(p_ik, t + x_k / V), each beam's line-of-sight speed weighted
along the beam by the CW range weighting (points p_ik at range s_k: upstream x_k = s_k cos b,
radius s_k sin b, azimuth phi_i; :meth:`lidar.CWLidar.range_quadrature`) and divided by cos b,
so that v and w enter through the line-of-sight error (tan b times their projections). The
rotor-effective wind u_R(t) is the disc average of u. With the IEC Kaimal spectra S_j(f) and
the exponential coherence C(r, f) = exp(-c(f) r) of the field (:func:`lidar.iec_coherence`,
the same for every component, as the field generator draws them), and the wind evolution over
the focus distance D of Simley and Pao (amplitude gamma_e(f) = sqrt of
:func:`lidar.evolution_coherence`), the spectra of the estimate moved by the preview time
T_p = D / V are

    S_RR(f) = S_u sum_ab b_a b_b C(r_ab),
    S_LL(f) = sum_j S_j sum_kl a_jk a_jl C(r_kl) exp(2 pi i f (x_k - x_l) / V) + S_noise,
    S_LR(f) = gamma_e(f) S_u sum_ka a_k b_a C(r_ka) exp(2 pi i f (x_k - D) / V),

with the disc's quadrature weights b and the LIDAR's weights a_j of component j, and the
magnitude-squared coherence is gamma^2 = |S_LR|^2 / (S_LL S_RR). The beams turn with the rotor
(1P is 0.1-0.2 Hz): of the three beams' mean, only the azimuthal modes that are multiples of 3
survive, and those other than the mean (m = 0) are moved to 3P and above. So below 3P the
estimate is the average over the measurement ring at each range of u + tan b (v sin phi -
w cos phi): the ring's mean of u and its first azimuthal moments of v and w, which the
line-of-sight error adds (with the cone half-angle b of a 75 %-span ring at 54 m, tan b = 0.87:
not small). The sums over points become sums over rings with the coherence averaged over the
azimuth between them (for the moments, times cos(dphi) / 2). The feedforward filter's corner is where gamma^2 falls to 0.5.

References
----------
Schlipf (2015), Lidar-assisted control concepts for wind turbines, dissertation, University of
Stuttgart, ch. 4 (the model-based coherence) and 5.2 (the filter). Simley, Pao, Frehlich,
Jonkman and Kelley (2014), Analysis of light detection and ranging wind speed measurements for
wind turbine control, Wind Energy 17, 413-433. Simley and Pao (2015), A longitudinal spatial
coherence model for wind evolution based on large-eddy simulation, ACC.
"""
from __future__ import annotations

import math

import numpy as np

from lidar._typing import FloatArray
from lidar.cw import CWLidar
from lidar.turbulence import (
    TurbulenceSpec,
    evolution_coherence,
    kaimal_spectrum,
    simley_pao_evolution,
)

__all__ = ["rotor_coherence_model", "coherence_corner_model"]


def _ring_kernel(r1: FloatArray, r2: FloatArray, c: float, n_az: int = 48,
                 harmonic: int = 0) -> FloatArray:
    """The coherence exp(-c r) between a point on a ring of radius r1 and the ring of radius
    r2, averaged over the azimuth between them (times cos(harmonic dphi) / 2 for the first
    harmonic: the mean of sin phi_1 sin phi_2 C over the rings): (n1, n2)."""
    dphi = 2 * math.pi * np.arange(n_az) / n_az
    d = np.sqrt(np.maximum(r1[:, None, None] ** 2 + r2[None, :, None] ** 2
                           - 2 * r1[:, None, None] * r2[None, :, None] * np.cos(dphi), 0.0))
    if harmonic == 0:
        return np.exp(-c * d).mean(axis=2)
    return 0.5 * (np.exp(-c * d) * np.cos(harmonic * dphi)).mean(axis=2)


def rotor_coherence_model(lidar_model: CWLidar, spec: TurbulenceSpec, rotor_radius: float,
                          f: FloatArray, *, evolution: bool = True,
                          evolution_parameters: tuple[float, float] | None = None,
                          n_rings: int = 16) -> FloatArray:
    """Magnitude-squared coherence of the LIDAR's rotor-effective estimate (moved by T_p) with
    the rotor-effective wind, from the turbulence model (module docstring).

    Parameters
    ----------
    lidar_model : CWLidar
        The instrument (focus, cone, range weighting, line-of-sight error, noise).
    spec : TurbulenceSpec
        The turbulence: mean wind, class or intensity, hub height (its grid is not used).
    rotor_radius : float
        [m], > 0.
    f : (n_f,) ndarray
        Frequencies [Hz], >= 0, below the beams' 3P (where the model holds).
    evolution : bool
        Wind evolution over the focus distance (Simley and Pao); False: frozen turbulence.
    evolution_parameters : (a, b), optional
        The evolution model's parameters (default :func:`lidar.simley_pao_evolution` of the
        spec, as :func:`lidar.evolve_field` uses).
    n_rings : int
        Rings of the disc's quadrature (default 16).

    Returns
    -------
    (n_f,) ndarray
        gamma^2 [-] in [0, 1].

    Raises
    ------
    ValueError
        If the radius is not positive or a frequency is negative or not finite.
    """
    if not (math.isfinite(rotor_radius) and rotor_radius > 0):
        raise ValueError(f"rotor_radius must be a finite number > 0 m, got {rotor_radius!r}")
    f = np.atleast_1d(np.asarray(f, dtype=float))
    if f.ndim != 1 or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ValueError("f must be a 1-D array of finite frequencies >= 0 Hz")
    v = spec.mean_speed
    sig, ls = spec.sigma, spec.length_scales
    c_all = 12.0 * np.sqrt((f / v) ** 2 + (0.12 / ls[3]) ** 2)          # C = exp(-c r)
    # the beams turn with the rotor: below 3P the three beams' mean is the average over the
    # ring at each range; v and w (odd in azimuth) leave it
    cos_b, sin_b = math.cos(lidar_model.cone_angle_rad), math.sin(lidar_model.cone_angle_rad)
    tan_b2 = (sin_b / cos_b) ** 2
    s, w = lidar_model.range_quadrature()
    x, rho = s * cos_b, s * sin_b
    edges = np.linspace(0.0, rotor_radius, n_rings + 1)
    rd = 0.5 * (edges[1:] + edges[:-1])
    wd = np.diff(edges**2) / rotor_radius**2                             # ring areas
    d = lidar_model.focus_distance
    if evolution:
        a, b = (simley_pao_evolution(v, sig, ls[0]) if evolution_parameters is None
                else evolution_parameters)
        g_e2 = evolution_coherence(f, d, v, a, b)
    else:
        g_e2 = np.ones(f.size)
    s_u = kaimal_spectrum(f, sig[0], ls[0], v)
    noise = lidar_model.noise_std**2 / cos_b**2 / 3.0 * 2.0 / lidar_model.sample_rate
    out = np.empty(f.size)
    for i, (fi, ci) in enumerate(zip(f, c_all)):
        ph = w * np.exp(2j * math.pi * fi * x / v)
        ll = float(np.real(np.conj(ph) @ _ring_kernel(rho, rho, ci) @ ph)) + noise / s_u[i]
        if lidar_model.los_error:
            # tan b (v sin phi - w cos phi): the rings' first azimuthal moments of v and w
            s_vw = (kaimal_spectrum(fi, sig[1], ls[1], v) + kaimal_spectrum(fi, sig[2], ls[2], v))
            ll += tan_b2 * s_vw / s_u[i] * float(np.real(
                np.conj(ph) @ _ring_kernel(rho, rho, ci, harmonic=1) @ ph))
        lr = ph @ _ring_kernel(rho, rd, ci) @ wd
        rr = wd @ _ring_kernel(rd, rd, ci) @ wd
        out[i] = min(1.0, g_e2[i] * abs(lr) ** 2 / (ll * rr))
    return out


def coherence_corner_model(lidar_model: CWLidar, spec: TurbulenceSpec, rotor_radius: float, *,
                           evolution: bool = True, level: float = 0.5,
                           evolution_parameters: tuple[float, float] | None = None) -> float:
    """The frequency where the model coherence (:func:`rotor_coherence_model`) first falls to
    ``level``: the LIDAR feedforward filter's corner (Schlipf 2015, sec. 5.2) [Hz].

    Parameters
    ----------
    lidar_model : CWLidar
        The instrument.
    spec : TurbulenceSpec
        The turbulence model at the wind of interest.
    rotor_radius : float
        [m].
    evolution : bool
        With wind evolution over the focus distance.
    level : float
        The coherence that marks the corner, in (0, 1) (default 0.5).
    evolution_parameters : (a, b), optional
        See :func:`rotor_coherence_model`.

    Returns
    -------
    float
        f_c [Hz] (the highest frequency searched, 2 Hz, if the coherence stays above).

    Raises
    ------
    ValueError
        If ``level`` is not in (0, 1).
    """
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must be in (0, 1), got {level!r}")
    f = np.geomspace(1e-3, 2.0, 40)
    kw = {"evolution": evolution, "evolution_parameters": evolution_parameters}
    g = rotor_coherence_model(lidar_model, spec, rotor_radius, f, **kw)
    below = np.flatnonzero(g < level)
    if below.size == 0:
        return float(f[-1])
    k = int(below[0])
    if k == 0:
        return float(f[0])
    lo, hi = math.log(f[k - 1]), math.log(f[k])       # bisection in log frequency
    for _ in range(12):
        mid = 0.5 * (lo + hi)
        if rotor_coherence_model(lidar_model, spec, rotor_radius, np.array([math.exp(mid)]),
                                 **kw)[0] < level:
            hi = mid
        else:
            lo = mid
    return float(math.exp(0.5 * (lo + hi)))
