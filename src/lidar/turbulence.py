"""IEC 61400-1 turbulent wind fields: Kaimal spectra, exponential coherence, Veers' method.

Model (IEC 61400-1 ed. 3, sec. 6.3.1.3 and Annex B, the model TurbSim calls IECKAI):

* normal turbulence model: sigma_1 = I_ref (0.75 V_hub + 5.6 m/s), I_ref = 0.16 / 0.14 / 0.12
  for classes A / B / C; sigma_2 = 0.8 sigma_1, sigma_3 = 0.5 sigma_1;
* Kaimal spectra S_k(f) = 4 sigma_k^2 (L_k / V_hub) / (1 + 6 f L_k / V_hub)^(5/3), with
  L_1 = 8.1 Lambda_1, L_2 = 2.7 Lambda_1, L_3 = 0.66 Lambda_1, Lambda_1 = 0.7 z_hub below 60 m
  and 42 m above;
* coherence Coh(r, f) = exp(-12 sqrt((f r / V_hub)^2 + (0.12 r / L_c)^2)), L_c = 8.1 Lambda_1,
  applied to every component (the standard specifies it for u; TurbSim applies it to all);
* power-law mean shear U(z) = V_hub (z / z_hub)^alpha.

Veers' method draws, for every frequency, complex Fourier coefficients with the coherence as
their correlation matrix. The coherence at fixed f is exp(-c(f) r): a function of distance only,
so on a regular grid its correlation matrix is block-Toeplitz and is embedded in a circulant one
on a grid twice as large, whose square root is applied by 2-D FFTs (Dietrich and Newsam 1997).
This is exact in distribution when the embedding's eigenvalues are non-negative; at the few
lowest frequencies where they are not, the exact Cholesky factor is used instead.
``method="cholesky"`` draws every frequency through the Cholesky factor and is the test
reference.

The Kaimal variance below the lowest resolved frequency 1/T (about 11 % at 18 m/s for a 600 s
record) is, by default, added to the first frequency bin (``low_frequency="lump"``) so that the
record has the IEC standard deviation without changing the spectrum above 1/T; ``"scale"``
instead rescales every component to its target standard deviation (as TurbSim's ScaleIEC does),
``"none"`` leaves it out.

References
----------
IEC 61400-1 ed. 3 (2005), sec. 6.3 and Annex B. Veers (1988), Three-dimensional wind simulation,
SAND88-0152. Dietrich and Newsam (1997), Fast and exact simulation of stationary Gaussian
processes through circulant embedding, SIAM J. Sci. Comput. 18(4). Jonkman (2009), TurbSim
user's guide, NREL/TP-500-46198.
"""
from __future__ import annotations

import dataclasses
import hashlib
import logging
import math
from dataclasses import dataclass
from typing import Any, Iterator

import numpy as np

from lidar._typing import FloatArray
from lidar.field import WindField

__all__ = ["TurbulenceSpec", "iec_sigma", "kaimal_spectrum", "iec_coherence", "generate_field",
           "evolve_field", "generate_evolved_field", "evolution_coherence",
           "simley_pao_evolution", "SamplerCache"]

log = logging.getLogger(__name__)

_I_REF = {"A": 0.16, "B": 0.14, "C": 0.12}


@dataclass(frozen=True)
class TurbulenceSpec:
    """What to generate.

    Parameters
    ----------
    mean_speed : float
        Hub-height mean wind speed V_hub [m/s], > 0.
    turbulence : str or float
        IEC class "A", "B", "C", or a turbulence intensity sigma_1 / V_hub [-].
    hub_height : float
        [m].
    width, height : float
        Grid extent in y and z, centred on the hub [m].
    n_y, n_z : int
        Grid points (>= 2).
    duration : float
        [s].
    dt : float
        Time step [s].
    shear_exponent : float
        Power-law exponent alpha [-] (default 0.2).
    """

    mean_speed: float
    turbulence: str | float = "A"
    hub_height: float = 90.0
    width: float = 150.0
    height: float = 150.0
    n_y: int = 32
    n_z: int = 32
    duration: float = 600.0
    dt: float = 0.05
    shear_exponent: float = 0.2

    def __post_init__(self) -> None:
        for name in ("mean_speed", "hub_height", "width", "height", "duration", "dt"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                    or v <= 0:
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        for name in ("n_y", "n_z"):
            v = getattr(self, name)
            if not isinstance(v, (int, np.integer)) or v < 2:
                raise ValueError(f"{name} must be an integer >= 2, got {v!r}")
        if isinstance(self.turbulence, str):
            if self.turbulence.upper() not in _I_REF:
                raise ValueError(f"turbulence must be 'A', 'B', 'C' or an intensity in (0, 1), "
                                 f"got {self.turbulence!r}")
        elif not (isinstance(self.turbulence, (int, float)) and 0 < self.turbulence < 1):
            raise ValueError(f"turbulence must be 'A', 'B', 'C' or an intensity in (0, 1), got "
                             f"{self.turbulence!r}")
        if not -1.0 <= self.shear_exponent <= 1.0:
            raise ValueError(f"shear_exponent must be in [-1, 1], got {self.shear_exponent!r}")
        if self.hub_height - self.height / 2 <= 0:
            raise ValueError(f"the grid reaches below ground: hub_height {self.hub_height} m, "
                             f"height {self.height} m")

    @property
    def sigma(self) -> FloatArray:
        """Standard deviations (sigma_1, sigma_2, sigma_3) [m/s]."""
        return iec_sigma(self.mean_speed, self.turbulence)

    @property
    def length_scales(self) -> FloatArray:
        """Kaimal integral scales (L_1, L_2, L_3) [m] and, last, the coherence scale L_c."""
        lam = 0.7 * self.hub_height if self.hub_height <= 60.0 else 42.0
        return np.array([8.1 * lam, 2.7 * lam, 0.66 * lam, 8.1 * lam])

    def grid(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Time, y and z axes.

        Returns
        -------
        t : (n_t,) ndarray
            Times [s].
        y, z : (n_y,), (n_z,) ndarray
            Lateral and vertical grid positions [m].
        """
        n_t = int(round(self.duration / self.dt))
        t = np.arange(n_t) * self.dt
        y = np.linspace(-self.width / 2, self.width / 2, self.n_y)
        z = self.hub_height + np.linspace(-self.height / 2, self.height / 2, self.n_z)
        return t, y, z


def iec_sigma(mean_speed: float, turbulence: str | float) -> FloatArray:
    """IEC 61400-1 ed. 3 normal turbulence model: (sigma_1, 0.8 sigma_1, 0.5 sigma_1) [m/s].

    Parameters
    ----------
    mean_speed : float
        Hub-height mean wind speed [m/s].
    turbulence : str or float
        IEC class "A", "B" or "C", or a turbulence intensity [-].

    Returns
    -------
    (3,) ndarray
        Standard deviations of u, v, w [m/s].
    """
    if isinstance(turbulence, str):
        s1 = _I_REF[turbulence.upper()] * (0.75 * mean_speed + 5.6)
    else:
        s1 = float(turbulence) * mean_speed
    return np.array([s1, 0.8 * s1, 0.5 * s1])


def kaimal_spectrum(f: FloatArray, sigma: float, length: float, mean_speed: float) -> FloatArray:
    """One-sided Kaimal spectrum S(f) = 4 sigma^2 (L/V) / (1 + 6 f L / V)^(5/3) [m^2/s].

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz].
    sigma : float
        Standard deviation [m/s].
    length : float
        Integral length scale [m].
    mean_speed : float
        Mean wind speed [m/s].

    Returns
    -------
    ndarray
        S(f) [m^2/s].
    """
    f = np.asarray(f, dtype=float)
    lv = length / mean_speed
    return 4.0 * sigma**2 * lv / (1.0 + 6.0 * f * lv) ** (5.0 / 3.0)


def iec_coherence(r: FloatArray, f: FloatArray, mean_speed: float, lc: float) -> FloatArray:
    """IEC exponential coherence exp(-12 sqrt((f r / V)^2 + (0.12 r / L_c)^2)) [-].

    Parameters
    ----------
    r : ndarray
        Separations [m].
    f : ndarray
        Frequencies [Hz], broadcast with ``r``.
    mean_speed : float
        Hub-height mean wind speed [m/s].
    lc : float
        Coherence scale parameter L_c [m].

    Returns
    -------
    ndarray
        The coherence [-].
    """
    r = np.asarray(r, dtype=float)
    f = np.asarray(f, dtype=float)
    return np.exp(-12.0 * np.sqrt((f * r / mean_speed) ** 2 + (0.12 * r / lc) ** 2))


def _decay(f: FloatArray, mean_speed: float, lc: float) -> FloatArray:
    """c(f) such that Coh = exp(-c r)."""
    return 12.0 * np.sqrt((f / mean_speed) ** 2 + (0.12 / lc) ** 2)


def _circulant_eigs(c: FloatArray, spec: TurbulenceSpec, pad: int) -> FloatArray:
    """Eigenvalues of the circulant embedding of exp(-c r) on a (pad n_y) x (pad n_z) torus,
    for each decay in ``c``: (n_f, pad n_y, pad n_z) real."""
    my, mz = pad * spec.n_y, pad * spec.n_z
    dy = spec.width / (spec.n_y - 1)
    dz = spec.height / (spec.n_z - 1)
    iy = np.minimum(np.arange(my), my - np.arange(my)) * dy
    iz = np.minimum(np.arange(mz), mz - np.arange(mz)) * dz
    r = np.sqrt(iy[:, None] ** 2 + iz[None, :] ** 2)
    kern = np.exp(-c[:, None, None] * r[None])
    return np.fft.fft2(kern).real


class _CirculantSampler:
    """Square roots of the circulant-embedding eigenvalues of exp(-c_k r) for every frequency,
    computed once per field and shared by the three components.

    The kernel is even in both lags, so its eigenvalues are too: one quadrant,
    (n_y + 1) x (n_z + 1) of the (2 n_y) x (2 n_z), is stored (a quarter of the memory, 13 MB
    for a 600 s field on 32 x 32 points) and mirrored a chunk at a time when drawing.

    Frequencies whose minimal (2 n_y x 2 n_z) embedding is not non-negative definite (the
    lowest few, where the coherence length exceeds the grid) are drawn through the exact
    Cholesky factor of the coherence matrix instead, so every frequency is exact in
    distribution. The factors (4 MB each on 32 x 32 points, some 80 MB for a 600 s field) are
    kept only by a sampler built with ``keep_factors`` (one shared between fields, see
    :class:`SamplerCache`); otherwise each is formed when drawn (38 ms on 32 x 32 points) and
    only the last is held, which is what two streams drawn side by side need.
    """

    def __init__(self, c: FloatArray, spec: TurbulenceSpec, chunk: int = 64,
                 keep_factors: bool = True) -> None:
        self.spec = spec
        self.my, self.mz = 2 * spec.n_y, 2 * spec.n_z
        # above this frequency index the coherence of the nearest grid neighbours,
        # exp(-c d_min), is below 1.1e-7 (float32 resolution): points are independent there
        dmin = min(spec.width / (spec.n_y - 1), spec.height / (spec.n_z - 1))
        self.n_corr = int(np.searchsorted(c * dmin, 16.0))
        self.n_f = c.size
        self.c = c[:self.n_corr].copy()
        # lag index -> quadrant index (the eigenvalues are even in both wavenumbers)
        self._iy = np.minimum(np.arange(self.my), self.my - np.arange(self.my))
        self._iz = np.minimum(np.arange(self.mz), self.mz - np.arange(self.mz))
        self.root = np.empty((self.n_corr, spec.n_y + 1, spec.n_z + 1), dtype=np.float32)
        exact = []
        for s in range(0, self.n_corr, chunk):
            lam = _circulant_eigs(self.c[s:s + chunk], spec, 2)
            bad = lam.min(axis=(1, 2)) < -1e-9 * lam.max(axis=(1, 2))
            exact += [s + int(i) for i in np.flatnonzero(bad)]
            # the 1/sqrt(2) of a unit complex normal is folded in here
            self.root[s:s + chunk] = np.sqrt(np.clip(lam[:, :spec.n_y + 1, :spec.n_z + 1], 0.0,
                                                     None) / (2 * self.my * self.mz))
        self.exact = tuple(exact)
        self.keep_factors = keep_factors
        self.chol: dict[int, FloatArray] = {}
        self._last: tuple[int, FloatArray] | None = None
        self._r: FloatArray | None = None
        if exact:
            log.debug("circulant embedding indefinite at %d frequencies: exact Cholesky used",
                      len(exact))
            if keep_factors:
                for k in exact:
                    self.factor(k)
                self._r = None

    def full_root(self, start: int, stop: int | None = None) -> FloatArray:
        """The square roots of the eigenvalues of frequencies ``start:stop`` on the whole
        (2 n_y) x (2 n_z) torus, float32 (stop default: start + 1)."""
        stop = start + 1 if stop is None else stop
        return self.root[start:stop][:, self._iy][:, :, self._iz]

    def factor(self, k: int) -> FloatArray:
        """The float32 lower Cholesky factor of the coherence matrix at frequency ``k`` (one of
        ``exact``), kept or formed as the sampler was built to."""
        low = self.chol.get(k)
        if low is None:
            if self._last is not None and self._last[0] == k:
                return self._last[1]
            if self._r is None:
                self._r = _distances(self.spec)
            low = _cholesky_factor(float(self.c[k]), self._r).astype(np.float32)
            if self.keep_factors:
                self.chol[k] = low
            else:
                self._last = (k, low)
        return low

    def chunks(self, rng: np.random.Generator, chunk: int = 32
               ) -> Iterator[tuple[int, int, np.ndarray]]:
        """The complex Gaussian coefficients of one component, covariance exp(-c_k r) at each
        frequency k, as (start, stop, (stop - start, n_y, n_z) array) in the stream's order: the
        independent frequencies a block at a time, the correlated ones a chunk at a time, then
        the exactly drawn ones, which replace what their chunk gave."""
        spec = self.spec
        nf = self.n_corr
        for s in range(nf, self.n_f, 4 * chunk):
            e = min(s + 4 * chunk, self.n_f)
            xi = rng.standard_normal((e - s, spec.n_y, spec.n_z, 2), dtype=np.float32)
            xi *= np.float32(1.0 / math.sqrt(2.0))
            yield s, e, xi.view(np.complex64)[..., 0]
        for s in range(0, nf, chunk):
            root = self.full_root(s, min(s + chunk, nf))
            # complex normals as pairs of float32 normals viewed as complex64 (no copy)
            xi = rng.standard_normal(root.shape + (2,), dtype=np.float32).view(np.complex64)
            xi = xi[..., 0] * root
            # 2-D FFT of which only the first n_y x n_z block is needed: z first, keep n_z
            # columns, then y on those
            part = np.fft.fft(xi, axis=2)[:, :, :spec.n_z]
            yield s, min(s + chunk, nf), np.fft.fft(part, axis=1)[:, :spec.n_y, :]
        n = spec.n_y * spec.n_z
        for k in self.exact:
            xi = (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / math.sqrt(2)
            yield k, k + 1, (self.factor(k) @ xi).reshape(1, spec.n_y, spec.n_z)

    def draw(self, rng: np.random.Generator, chunk: int = 32,
             out: np.ndarray | None = None) -> np.ndarray:
        """Complex Gaussian coefficients (n_f, n_y, n_z), covariance exp(-c_k r) per k
        (written into ``out``, complex64, when given)."""
        if out is None:
            out = np.empty((self.n_f, self.spec.n_y, self.spec.n_z), dtype=np.complex64)
        for s, e, x in self.chunks(rng, chunk):
            out[s:e] = x
        self.release()
        return out

    def release(self) -> None:
        """Drop what drawing formed and did not keep (the last factor, the distances)."""
        self._last = None
        if not self.keep_factors:
            self._r = None


class SamplerCache:
    """Keeps the last field's circulant sampler for the next field of the same wind and grid.

    The seeds of one wind (a campaign worker's consecutive cases, the controllers of one
    comparison that meet the same field, a LIDAR's evolved copy of the field) share the
    sampler: a 680 s, 32 x 32 field then costs 2.1 s instead of 3.6 s, at the price of holding
    it between fields (for a 620 s field on 32 x 32 points, 13 MB of eigenvalues and 84 MB of
    the Cholesky factors of its 20 exactly drawn frequencies). It holds one sampler at a time
    and draws no random numbers, so the fields are the same with or without it (bit for bit).
    Without one, a field's sampler forms those factors when drawn (38 ms each) and is released
    with the field's making.

    Pass it to :func:`generate_field`, :func:`generate_evolved_field` and
    :func:`evolve_field` as ``samplers=``; as a context manager it releases what it holds on
    exit::

        with SamplerCache() as samplers:
            fields = [generate_field(spec, seed, samplers=samplers) for seed in range(6)]
    """

    def __init__(self) -> None:
        self._key: tuple[Any, ...] | None = None
        self._sampler: _CirculantSampler | None = None

    def __enter__(self) -> "SamplerCache":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.clear()

    @property
    def holds(self) -> bool:
        """Whether a sampler is kept."""
        return self._sampler is not None

    def clear(self) -> None:
        """Release the kept sampler."""
        self._key = self._sampler = None

    def _get(self, c: FloatArray, spec: TurbulenceSpec) -> _CirculantSampler:
        key = (spec.n_y, spec.n_z, spec.width, spec.height,
               hashlib.sha1(np.ascontiguousarray(c, dtype=np.float64).tobytes()).hexdigest())
        kept = self._sampler
        if kept is None or key != self._key:
            self.clear()                     # one at a time: release the last before building
            kept = self._sampler = _CirculantSampler(c, spec, keep_factors=True)
            self._key = key
        return kept


def _shared_sampler(c: FloatArray, spec: TurbulenceSpec,
                    samplers: SamplerCache | None) -> _CirculantSampler:
    """The circulant sampler for decay rates ``c`` on the spec's grid: the one ``samplers``
    keeps (built with its Cholesky factors: about 1.7 s and 97 MB for 620 s on 32 x 32 points),
    or a new one whose factors are formed when drawn."""
    if samplers is None:
        return _CirculantSampler(c, spec, keep_factors=False)
    return samplers._get(c, spec)


def _distances(spec: TurbulenceSpec) -> FloatArray:
    """Distances between all grid points, (n_y n_z, n_y n_z) [m] (y-major order)."""
    _, y, z = spec.grid()
    yy, zz = (a.ravel() for a in np.meshgrid(y, z, indexing="ij"))
    d = yy[:, None] - yy[None, :]
    d *= d
    dz = zz[:, None] - zz[None, :]
    dz *= dz
    d += dz
    del dz
    return np.sqrt(d, out=d)


def _cholesky_factor(ck: float, r: FloatArray) -> FloatArray:
    """Exact reference: lower Cholesky factor of the coherence matrix exp(-c r) (+ 1e-12 on
    the diagonal), formed in place (a 32 x 32 grid's matrix is 8 MB)."""
    m = np.multiply(r, -ck)
    np.exp(m, out=m)
    m[np.diag_indices(r.shape[0])] += 1e-12
    return np.linalg.cholesky(m)


def _coefficients_cholesky(c: FloatArray, spec: TurbulenceSpec,
                           rng: np.random.Generator) -> FloatArray:
    """Exact reference sampler: the Cholesky factor at every frequency."""
    r = _distances(spec)
    n = r.shape[0]
    out = np.empty((c.size, spec.n_y, spec.n_z), dtype=np.complex128)
    for k, ck in enumerate(c):
        xi = (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / math.sqrt(2)
        out[k] = (_cholesky_factor(ck, r) @ xi).reshape(spec.n_y, spec.n_z)
    return out


def generate_field(spec: TurbulenceSpec, seed: int | np.random.Generator | None = None, *,
                   method: str = "circulant", low_frequency: str = "lump",
                   components: str = "uvw", samplers: SamplerCache | None = None) -> WindField:
    """Generate a turbulent wind field (IEC 61400-1 Kaimal model, Veers' method).

    Parameters
    ----------
    spec : TurbulenceSpec
    seed : int or Generator
        Reproducible from the seed.
    method : {"circulant", "cholesky"}
        Circulant embedding with FFTs (fast), or per-frequency Cholesky (exact reference, small
        grids only).
    low_frequency : {"lump", "scale", "none"}
        What to do with the Kaimal variance below 1/T (module docstring).
    components : str
        Which components carry turbulence ("uvw" default; "u" leaves v = w = 0).
    samplers : SamplerCache, optional
        Keeps the circulant sampler for the next field of the same wind and grid.

    Returns
    -------
    WindField
        With the mean shear profile in u.

    Raises
    ------
    ValueError
        On an unknown method or option, or a Cholesky request on a grid of more than 400 points.
    """
    if method not in ("circulant", "cholesky"):
        raise ValueError(f"method must be 'circulant' or 'cholesky', got {method!r}")
    if low_frequency not in ("lump", "scale", "none"):
        raise ValueError(f"low_frequency must be 'lump', 'scale' or 'none', got "
                         f"{low_frequency!r}")
    if not isinstance(components, str) or set(components) - set("uvw"):
        raise ValueError(f"components must be letters of 'uvw' (the turbulent ones), got "
                         f"{components!r}")
    if method == "cholesky" and spec.n_y * spec.n_z > 400:
        raise ValueError(f"method='cholesky' is the small-grid reference: n_y * n_z = "
                         f"{spec.n_y * spec.n_z} > 400")
    rng = np.random.default_rng(seed)            # a Generator is returned as it is
    t, y, z = spec.grid()
    fields = dict(_components(spec, rng, method, low_frequency, components, samplers))
    meta = _field_meta(spec, seed, method, low_frequency, components)
    return WindField(t=t, y=y, z=z, u=fields["u"], v=fields["v"], w=fields["w"],
                     mean_speed=spec.mean_speed, hub_height=spec.hub_height, meta=meta)


def _field_meta(spec: TurbulenceSpec, seed: Any, method: str, low_frequency: str,
                components: str) -> dict[str, Any]:
    """A generated field's ``meta``: how it was made."""
    return {"model": "IEC 61400-1 Kaimal (IECKAI)", "method": method,
            "turbulence": spec.turbulence, "sigma": spec.sigma.tolist(),
            "shear_exponent": spec.shear_exponent, "low_frequency": low_frequency,
            "components": components,
            "seed": seed if isinstance(seed, (int, type(None))) else "generator"}


def _shear_profile(spec: TurbulenceSpec) -> np.ndarray:
    """The mean power-law profile of u over the grid's heights, (n_z,) float32 [m/s]."""
    z = spec.grid()[2]
    return (spec.mean_speed * (z / spec.hub_height) ** spec.shear_exponent).astype(np.float32)


def _frequencies(spec: TurbulenceSpec) -> tuple[int, int, FloatArray, FloatArray]:
    """n_t, nf (bins 1..nf-1 carry turbulence; the Nyquist bin nf is left at zero), the
    frequencies of bins 1..nf-1 [Hz] and their coherence decay rates (eq. of :func:`_decay`)."""
    n_t = spec.grid()[0].size
    if n_t < 4:
        raise ValueError(f"duration / dt gives {n_t} samples; need at least 4")
    nf = n_t // 2
    f = np.arange(1, nf) / (n_t * spec.dt)
    return n_t, nf, f, _decay(f, spec.mean_speed, spec.length_scales[3])


def _bin_variance(spec: TurbulenceSpec, k: int, f: FloatArray, low_frequency: str = "lump"
                  ) -> FloatArray:
    """The Kaimal variance of component k in each frequency bin [m^2/s^2], with the variance
    below the first bin added to it when ``low_frequency`` is "lump"."""
    v, sig, ls = spec.mean_speed, spec.sigma, spec.length_scales
    df = f[0]
    var = kaimal_spectrum(f, sig[k], ls[k], v) * df
    if low_frequency == "lump":
        lv = ls[k] / v
        # integral of S from 0 to the lower edge of the first bin (f_1 / 2)
        var[0] += sig[k] ** 2 * (1.0 - (1.0 + 6.0 * f[0] / 2 * lv) ** (-2.0 / 3.0))
    return var


def _components(spec: TurbulenceSpec, rng: np.random.Generator, method: str = "circulant",
                low_frequency: str = "lump", components: str = "uvw",
                samplers: SamplerCache | None = None) -> Iterator[tuple[str, FloatArray]]:
    """The field's components u, v, w in turn, each (n_t, n_y, n_z) float32 and read-only,
    drawn from ``rng`` in that order (one at a time: a caller that needs one component at a
    time never holds the three)."""
    n_t, nf, f, c = _frequencies(spec)
    sampler = _shared_sampler(c, spec, samplers) if method == "circulant" else None
    shear = _shear_profile(spec)
    for k, comp in enumerate("uvw"):
        if comp not in components:
            # no turbulence: one row (the shear profile or zeros) broadcast over the grid and
            # time, a read-only view that holds no memory
            series = np.broadcast_to(shear if comp == "u" else np.float32(0.0),
                                     (n_t, spec.n_y, spec.n_z))
            yield comp, series
            del series
            continue
        var = _bin_variance(spec, k, f, low_frequency)
        spec_arr = np.zeros((nf + 1, spec.n_y, spec.n_z), dtype=np.complex64)
        if sampler is not None:
            sampler.draw(rng, out=spec_arr[1:nf])
        else:
            spec_arr[1:nf] = _coefficients_cholesky(c, spec, rng)
        spec_arr[1:nf] *= (np.sqrt(2.0 * var) * (n_t / 2.0)).astype(np.float32)[:, None, None]
        # complex64 in, float32 out (numpy >= 2 transforms in single precision), a few grid
        # columns at a time: the field is stored as float32 (WindField), and the transform's
        # own buffers stay small
        series = np.empty((n_t, spec.n_y, spec.n_z), dtype=np.float32)
        for j in range(0, spec.n_y, 4):
            series[:, j:j + 4] = np.fft.irfft(spec_arr[:, j:j + 4], n=n_t, axis=0)
        del spec_arr
        if low_frequency == "scale":
            series *= np.float32(spec.sigma[k] / max(float(series.std(dtype=np.float64)), 1e-300))
        if comp == "u":
            series += shear
        series.flags.writeable = False
        yield comp, series
        del series                      # the caller may drop it before asking for the next


def simley_pao_evolution(mean_speed: float, sigma: Any, length_scale: float
                         ) -> tuple[float, float]:
    """Parameters (a [-], b [1/m]) of Simley and Pao's wind-evolution coherence.

    The magnitude-squared longitudinal coherence of the wind at two points ``d`` apart along
    the mean wind (the exponential model of Simley and Pao 2015)

        gamma^2(f, d) = exp(-a sqrt((f d / V)^2 + (b d)^2))

    with the parameters fitted to large-eddy simulations

        a = 8.4 sigma / V + 0.05,    b = 0.25 L^(-1.24),

    sigma the total turbulence standard deviation sqrt(sigma_u^2 + sigma_v^2 + sigma_w^2) and L
    the integral length scale of u (IEC Kaimal: 8.1 Lambda_1). The same parameterization is
    the ``Exp-Simley`` model of Chen et al.'s evoTurb 4-D wind-field generator.

    Parameters
    ----------
    mean_speed : float
        V [m/s], > 0.
    sigma : float or array of 3
        Total standard deviation, or (sigma_u, sigma_v, sigma_w) [m/s].
    length_scale : float
        L [m], > 0.

    Returns
    -------
    a, b : float

    Raises
    ------
    ValueError
        If a value is not finite or not positive.

    References
    ----------
    Simley and Pao (2015), A longitudinal spatial coherence model for wind evolution based on
    large-eddy simulation, American Control Conference, 3708-3714. Chen, Schlipf and Cheng
    (2021), Parameterization of wind evolution using lidar, Wind Energ. Sci. 6, 61-91.
    """
    sig = np.atleast_1d(np.asarray(sigma, dtype=float))
    total = float(np.sqrt(np.sum(sig**2)))
    for name, val in (("mean_speed", mean_speed), ("sigma", total),
                      ("length_scale", length_scale)):
        if not (math.isfinite(val) and val > 0):
            raise ValueError(f"{name} must be finite and > 0, got {val!r}")
    return 8.4 * total / mean_speed + 0.05, 0.25 * length_scale ** -1.24


def evolution_coherence(f: FloatArray, distance: float, mean_speed: float, a: float,
                        b: float) -> FloatArray:
    """Magnitude-squared coherence gamma^2 = exp(-a sqrt((f d / V)^2 + (b d)^2)) [-]
    (Simley and Pao 2015; see :func:`simley_pao_evolution`).

    Parameters
    ----------
    f : (n_f,) ndarray
        Frequencies [Hz].
    distance : float
        Separation along the mean wind [m].
    mean_speed : float
        Mean wind speed [m/s].
    a, b : float
        The model's parameters [-] and [1/m].

    Returns
    -------
    (n_f,) ndarray
        gamma^2 [-].
    """
    f = np.asarray(f, dtype=float)
    return np.exp(-a * np.sqrt((f * distance / mean_speed) ** 2 + (b * distance) ** 2))


def _spec_like(field: WindField) -> TurbulenceSpec:
    """A spec on the field's grid with its turbulence (the class in its meta, else the
    intensity of u measured at the grid centre)."""
    turb = field.meta.get("turbulence")
    if not (isinstance(turb, str) and turb.upper() in _I_REF
            or isinstance(turb, (int, float)) and 0 < turb < 1):
        u = field.u[:, field.y.size // 2, field.z.size // 2]
        turb = float(min(max(u.std(dtype=np.float64) / field.mean_speed, 1e-3), 0.99))
    width = float(field.y[-1] - field.y[0])
    height = float(field.z[-1] - field.z[0])
    return TurbulenceSpec(field.mean_speed, turb, hub_height=float(field.z[0]) + height / 2,
                          width=width, height=height, n_y=field.y.size, n_z=field.z.size,
                          duration=field.t.size * field.dt, dt=field.dt)


def evolve_field(field: WindField, distance: float, spec: TurbulenceSpec | None = None,
                 seed: int | np.random.Generator | None = None, *, a: float | None = None,
                 b: float | None = None, samplers: SamplerCache | None = None) -> WindField:
    """The field as it is upstream, ``distance`` ahead of the rotor, with wind evolution.

    Frozen turbulence would make the upstream wind equal to the field (shifted by
    distance / V). With evolution the upstream turbulence decorrelates from what arrives: each
    Fourier coefficient becomes gamma u + sqrt(1 - gamma^2) u', with u' an independent field of
    the same statistics, so that the two fields have the magnitude-squared coherence gamma^2 of
    :func:`evolution_coherence` at every grid point (and keep their spectra and lateral
    coherence). The mean of every point is kept.

    Parameters
    ----------
    field : WindField
        The field at the rotor.
    distance : float
        Upstream distance d [m], >= 0 (0: the field itself).
    spec : TurbulenceSpec, optional
        The statistics of u' (default: the field's grid with the turbulence class in its meta,
        else the intensity of u measured at the grid centre).
    seed : int or Generator, optional
        Of u'.
    a, b : float, optional
        The coherence parameters (default: :func:`simley_pao_evolution` of the spec's sigma and
        the field's hub height).
    samplers : SamplerCache, optional
        Keeps the circulant sampler for the next field of the same wind and grid.

    Returns
    -------
    WindField
        With ``meta["evolution"]`` = {distance, a, b, model}.

    Raises
    ------
    ValueError
        If the distance or parameters are negative or not finite, or the spec's grid is not the
        field's.
    """
    spec = _spec_like(field) if spec is None else spec
    a, b, model = _evolution_parameters(spec, field.hub_height, distance, a, b)
    t, y, z = spec.grid()
    if (t.size, y.size, z.size) != field.u.shape:
        raise ValueError(f"spec grid {(t.size, y.size, z.size)} does not match the field "
                         f"{field.u.shape}")
    meta = {**field.meta, "evolution": {"distance": distance, "a": a, "b": b, "model": model}}
    if distance == 0.0:
        return WindField(t=field.t, y=field.y, z=field.z, u=field.u, v=field.v, w=field.w,
                         mean_speed=field.mean_speed, hub_height=field.hub_height, meta=meta)
    # u' one component at a time (the same draws as generate_field(spec, seed)), its Fourier
    # coefficients straight from the sampler into a point-major buffer; the field's own
    # coefficients are added a few grid points at a time and each point's series is written
    # back over its coefficients (_series_in_place): per component the peak holds one buffer
    rng = np.random.default_rng(seed)            # a Generator is returned as it is
    n_t, nf, f, c = _frequencies(spec)
    sampler = _shared_sampler(c, spec, samplers)
    keep, fresh = _evolution_gains(n_t, spec.dt, distance, field.mean_speed, a, b)
    n_p = spec.n_y * spec.n_z
    out = {}
    for k, comp in enumerate("uvw"):
        gain = fresh[1:nf] * _bin_scale(spec, k, f, n_t)
        buf = np.zeros((n_p, nf + 1), dtype=np.complex64)
        for s, e, xo in sampler.chunks(rng):
            buf[:, 1 + s:1 + e] = (xo * gain[s:e, None, None]).reshape(e - s, n_p).T
        sampler.release()
        x = getattr(field, comp).reshape(n_t, n_p)
        mean = x.mean(axis=0, dtype=np.float64)

        def add_field(r: int, part: np.ndarray, x: np.ndarray = x) -> None:
            fx = np.fft.rfft(x[:, r:r + part.shape[0]], axis=0)
            fx[0] = 0.0                      # the mean leaves as the zero-frequency bin
            part += (fx * keep[:, None]).T

        series = _series_in_place(buf, n_t, spec, add_field)
        # the mean of every point put back, to the float32 storage's resolution: the residual
        # mean of the single-precision transform is taken out with it
        series += (mean.reshape(spec.n_y, spec.n_z)
                   - series.mean(axis=0, dtype=np.float64)).astype(np.float32)
        series.flags.writeable = False
        out[comp] = series
    return WindField(t=field.t, y=field.y, z=field.z, u=out["u"], v=out["v"], w=out["w"],
                     mean_speed=field.mean_speed, hub_height=field.hub_height, meta=meta)


def generate_evolved_field(spec: TurbulenceSpec, seed: int | np.random.Generator | None,
                           distance: float,
                           evolution_seed: int | np.random.Generator | None = None, *,
                           a: float | None = None, b: float | None = None,
                           samplers: SamplerCache | None = None) -> WindField:
    """The field ``distance`` upstream of ``generate_field(spec, seed)``, with wind evolution,
    without that field: ``evolve_field(generate_field(spec, seed), distance, spec,
    evolution_seed)`` to single-precision rounding.

    A LIDAR in the loop needs the upstream field's three components but the rotor (whose field
    this does not make) only u. Each Fourier coefficient of the upstream field is
    gamma X + sqrt(1 - gamma^2) X' (:func:`evolve_field`), with X drawn from ``seed``'s stream
    as :func:`generate_field` draws it and X' from ``evolution_seed``'s; here both are drawn
    side by side a frequency chunk at a time and combined at once, so neither the rotor's
    field nor the independent one ever exists, and each point's series is written over its
    own coefficients. A 620 s field on 32 x 32 points (152 MB) peaks 44 MB above its own size
    (the sampler's eigenvalues, one Cholesky factor, the chunks); generating a field and
    evolving it held both fields, the independent component and its spectrum.

    Parameters
    ----------
    spec : TurbulenceSpec
        The rotor's field (and of the independent part).
    seed : int or Generator
        The rotor's field's seed, as given to :func:`generate_field`.
    distance : float
        Upstream distance d [m], >= 0 (0: ``generate_field(spec, seed)`` itself).
    evolution_seed : int or Generator, optional
        Of the independent part, as given to :func:`evolve_field`.
    a, b : float, optional
        Coherence parameters (default: :func:`simley_pao_evolution` of the spec).
    samplers : SamplerCache, optional
        Keeps the circulant sampler for the next field of the same wind and grid.

    Returns
    -------
    WindField
        With ``meta["evolution"]`` = {distance, a, b, model}; its components are stored
        point-major (strided (n_t, n_y, n_z) views).

    Raises
    ------
    ValueError
        If the distance or parameters are negative or not finite.
    """
    a, b, model = _evolution_parameters(spec, spec.hub_height, distance, a, b)
    evo = {"distance": distance, "a": a, "b": b, "model": model}
    if distance == 0.0:
        f0 = generate_field(spec, seed, samplers=samplers)
        return dataclasses.replace(f0, meta={**f0.meta, "evolution": evo})
    # default_rng returns a Generator given as it is
    rng, rng_o = np.random.default_rng(seed), np.random.default_rng(evolution_seed)
    n_t, nf, f, c = _frequencies(spec)
    t, y, z = spec.grid()
    sampler = _shared_sampler(c, spec, samplers)
    keep, fresh = _evolution_gains(n_t, spec.dt, distance, spec.mean_speed, a, b)
    n_p = spec.n_y * spec.n_z
    out = {}
    for k, comp in enumerate("uvw"):
        scale = _bin_scale(spec, k, f, n_t)
        gx = (keep[1:nf] * scale)[:, None, None]
        go = (fresh[1:nf] * scale)[:, None, None]
        buf = np.zeros((n_p, nf + 1), dtype=np.complex64)
        for (s, e, x), (_, _, xo) in zip(sampler.chunks(rng), sampler.chunks(rng_o)):
            buf[:, 1 + s:1 + e] = (x * gx[s:e] + xo * go[s:e]).reshape(e - s, n_p).T
        sampler.release()
        series = _series_in_place(buf, n_t, spec)
        if comp == "u":
            series += _shear_profile(spec)
        series.flags.writeable = False
        out[comp] = series
    meta = {**_field_meta(spec, seed, "circulant", "lump", "uvw"), "evolution": evo}
    return WindField(t=t, y=y, z=z, u=out["u"], v=out["v"], w=out["w"],
                     mean_speed=spec.mean_speed, hub_height=spec.hub_height, meta=meta)


def _evolution_parameters(spec: TurbulenceSpec, hub_height: float, distance: float,
                          a: float | None, b: float | None) -> tuple[float, float, str]:
    """(a, b, model) of the evolution coherence: the given ones, else Simley and Pao's of the
    spec's sigma and the hub height's length scale; checked finite and >= 0 with the
    distance."""
    model = "given"
    if a is None or b is None:
        lam = 0.7 * hub_height if hub_height <= 60.0 else 42.0
        sa, sb = simley_pao_evolution(spec.mean_speed, spec.sigma, 8.1 * lam)
        a = sa if a is None else a
        b = sb if b is None else b
        model = "Simley and Pao (2015)"
    for name, val in (("distance", distance), ("a", a), ("b", b)):
        if not (math.isfinite(val) and val >= 0):
            raise ValueError(f"{name} must be finite and >= 0, got {val!r}")
    return float(a), float(b), model


def _evolution_gains(n_t: int, dt: float, distance: float, mean_speed: float, a: float,
                     b: float) -> tuple[FloatArray, FloatArray]:
    """gamma and sqrt(1 - gamma^2) of every rfft bin (0..n_t // 2), float32."""
    g = np.sqrt(evolution_coherence(np.fft.rfftfreq(n_t, dt), distance, mean_speed, a, b))
    return g.astype(np.float32), np.sqrt(1.0 - g**2).astype(np.float32)


def _bin_scale(spec: TurbulenceSpec, k: int, f: FloatArray, n_t: int) -> FloatArray:
    """Unit complex normals times this give component k's rfft coefficients in bins
    1..nf-1 (the IEC default "lump" of the low-frequency variance), float32."""
    return (np.sqrt(2.0 * _bin_variance(spec, k, f)) * (n_t / 2.0)).astype(np.float32)


def _series_in_place(buf: np.ndarray, n_t: int, spec: TurbulenceSpec,
                     before: Any = None, rows: int = 32) -> np.ndarray:
    """The real series of point-major rfft coefficients ``buf`` (n_y n_z, nf + 1) complex64,
    written over them: a point's n_t float32 samples take no more bytes than its nf + 1
    coefficients, so each block of points is transformed and written back into its own rows
    (``before(r, block)`` may change a block's coefficients first). Returns the
    (n_t, n_y, n_z) strided view of ``buf``'s memory."""
    flat = buf.view(np.float32)
    for r in range(0, buf.shape[0], rows):
        block = buf[r:r + rows]
        if before is not None:
            before(r, block)
        flat[r:r + rows, :n_t] = np.fft.irfft(block, n=n_t, axis=1)
    return flat[:, :n_t].reshape(spec.n_y, spec.n_z, n_t).transpose(2, 0, 1)
