"""State and wind estimation for controllers that run on measured signals.

A steady-state Kalman filter on the discrete linear model augmented with the blade-effective
winds as random walks (an unknown-input formulation in the spirit of the PI observer of Do et al.
and the wind observer of Clemens et al.):

    [x; d]_{k+1} = [[A, B_d], [0, I]] [x; d]_k + [B_u; 0] u_k + w_k,
    y_k          = [C_y, D_yd] [x; d]_k + D_yu u_k + v_k,

with y the measured signals (rotor and generator speed, the three pitch angles, the three flap
moments, tower-top fore-aft acceleration). The gain comes from the discrete algebraic Riccati
equation (scipy), once per operating point.
"""
from __future__ import annotations

from typing import Any

import numba as nb
import numpy as np
import scipy.linalg

import linearize
from linearize.validate import check_number

__all__ = ["KalmanEstimator", "MEASURED_SIGNALS", "read_signals", "SignalReader"]

#: Model outputs the estimator uses and their default measurement noise std [output units].
MEASURED_SIGNALS: dict[str, float] = {
    "rotor_speed": 1e-3, "gen_speed": 0.1, "pitch_1": 1e-4, "pitch_2": 1e-4, "pitch_3": 1e-4,
    "flap_moment_1": 2e4, "flap_moment_2": 2e4, "flap_moment_3": 2e4,
    "tower_fa_acceleration": 0.02}

#: Default process-noise std per state and per step [state units].
_STATE_NOISE = {"tower_fa_displacement": 1e-3, "tower_fa_velocity": 2e-3, "rotor_speed": 1e-4,
                "gen_speed": 1e-2, "shaft_torsion": 1e-5, "pitch_1": 1e-5, "pitch_2": 1e-5,
                "pitch_3": 1e-5}


def read_signals(meas: dict[str, Any], names: tuple[str, ...] | list[str]) -> np.ndarray:
    """Named signals from a harness measurement dict: a key of ``meas`` itself, a blade signal
    ``<key>_<1|2|3>`` of a per-blade array, or else a plant state from ``meas["state"]``.

    Parameters
    ----------
    meas : dict
        The harness's measurements.
    names : sequence of str
        Signal names.

    Returns
    -------
    (n,) ndarray
        The signals in that order.
    """
    return SignalReader(names)(meas)


class SignalReader:
    """:func:`read_signals` for one list of names, read the same way every step: where each
    signal sits is found at the first call (and again if the measurements change shape), so
    that a step costs a few item lookups.

    Parameters
    ----------
    names : sequence of str
        Signal names.
    """

    #: where the signals sit in the measurements is learnt from the run, not designed
    __design__ = False

    def __init__(self, names: tuple[str, ...] | list[str]) -> None:
        self.names = tuple(names)
        self._plan: list[tuple[str, int]] | None = None
        self._y = np.empty(len(self.names))

    def _resolve(self, meas: dict[str, Any]) -> list[tuple[str, int]]:
        plan = []
        for n in self.names:
            if n in meas:
                plan.append((n, -1))
            elif n[-2:] in ("_1", "_2", "_3") and n[:-2] in meas:
                plan.append((n[:-2], int(n[-1]) - 1))
            elif n in linearize.STATE_NAMES and "state" in meas:
                plan.append(("state", linearize.STATE_NAMES.index(n)))
            else:
                raise KeyError(f"signal {n!r} is neither in the measurements {sorted(meas)} "
                               f"nor a plant state")
        return plan

    def __call__(self, meas: dict[str, Any]) -> np.ndarray:
        """Read the signals: ``y[i]`` is ``names[i]`` of ``meas`` (a new array each call;
        ``meas`` as :func:`read_signals` takes it)."""
        if self._plan is None:
            self._plan = self._resolve(meas)
        try:
            return self._read(meas)
        except (KeyError, IndexError, TypeError):      # the measurements changed shape
            self._plan = self._resolve(meas)
            return self._read(meas)

    def _read(self, meas: dict[str, Any]) -> np.ndarray:
        y = self._y
        for i, (key, j) in enumerate(self._plan):       # type: ignore[arg-type]
            y[i] = meas[key] if j < 0 else meas[key][j]
        return y.copy()


@nb.njit(cache=True, nogil=True)
def _kalman_step(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray, gain: np.ndarray,
                 y0: np.ndarray, xa: np.ndarray, y: np.ndarray, u: np.ndarray, predict: bool,
                 work: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """One step of :meth:`KalmanEstimator.update` in place on ``xa``: predict (when
    ``predict``) xa = a xa + b u, then correct xa += gain (y - y0 - c xa - d u). False, with
    ``xa`` untouched, when a measurement is not finite."""
    n, ny, nu = xa.shape[0], y.shape[0], u.shape[0]
    for j in range(ny):
        if not np.isfinite(y[j]):
            return False
    xp = work[:n]
    for i in range(n):
        acc = 0.0
        if predict:
            for k in range(n):
                acc += a[i, k] * xa[k]
            for k in range(nu):
                acc += b[i, k] * u[k]
        else:
            acc = xa[i]
        xp[i] = acc
    innov = work[n:n + ny]
    for j in range(ny):
        acc = y[j] - y0[j]
        for k in range(n):
            acc -= c[j, k] * xp[k]
        for k in range(nu):
            acc -= d[j, k] * u[k]
        innov[j] = acc
    for i in range(n):
        acc = xp[i]
        for j in range(ny):
            acc += gain[i, j] * innov[j]
        xa[i] = acc
    return True


class KalmanEstimator:
    """Steady-state Kalman filter for the states and the blade-effective winds.

    Parameters
    ----------
    model : LinearModel
        Discrete model (any ``dt``) with the outputs of :data:`MEASURED_SIGNALS` among its
        outputs (the full output set of :func:`linearize.linearize`).
    wind_std_per_step : float
        Random-walk std of each blade-effective wind per step [m/s] (default 0.2 at 10 Hz): larger
        follows gusts faster and passes more measurement noise.
    measurement_std : dict, optional
        Overrides of the noise std per measured signal.
    """

    #: a work buffer, not design data
    __not_design__ = ("_work",)

    def __init__(self, model: linearize.LinearModel, *, wind_std_per_step: float = 0.2,
                 measurement_std: dict[str, float] | None = None) -> None:
        if model.dt is None:
            raise ValueError("model must be discrete: call model.discretize(dt) first")
        check_number("wind_std_per_step", wind_std_per_step, lo=0.0, lo_open=True, unit="m/s")
        std = dict(MEASURED_SIGNALS)
        for k, v in (measurement_std or {}).items():
            if k not in std:
                raise ValueError(f"measurement_std: unknown signal {k!r}; signals are "
                                 f"{sorted(std)}")
            std[k] = check_number(f"measurement_std[{k!r}]", v, lo=0.0, lo_open=True)
        missing = [n for n in std if n not in model.outputs]
        if missing:
            raise ValueError(f"model lacks the measured outputs {missing}")
        unknown = [n for n in model.states if n not in _STATE_NOISE]
        if unknown:
            raise ValueError(f"the Kalman estimator has no process-noise default for the "
                             f"model's states {unknown} (it knows {sorted(_STATE_NOISE)}): "
                             f"reduce the model to those states, or run the MPC on the true "
                             f"states (MPCSettings(estimator='full-state'))")
        self.signals = tuple(std)
        iy = [model.outputs.index(n) for n in self.signals]
        nx, nd = model.A.shape[0], model.B_d.shape[1]
        self.nx, self.nd = nx, nd
        self.a = np.block([[model.A, model.B_d], [np.zeros((nd, nx)), np.eye(nd)]])
        self.b = np.vstack([model.B_u, np.zeros((nd, model.B_u.shape[1]))])
        self.c = np.hstack([model.C_z[iy], model.D_d[iy]])
        self.d = model.D_u[iy]
        self.y0 = model.z0[iy]
        q = np.diag([_STATE_NOISE[n] ** 2 for n in model.states] + [wind_std_per_step ** 2] * nd)
        r = np.diag([std[n] ** 2 for n in self.signals])
        # scale the outputs for the Riccati solve (flap moments ~1e6, pitch ~1e-2)
        sy = np.sqrt(np.diag(r))
        cs, rs = self.c / sy[:, None], r / np.outer(sy, sy)
        p = scipy.linalg.solve_discrete_are(self.a.T, cs.T, q, rs)
        # filter ("current estimator") gain on the scaled innovation, unscaled afterwards
        self.gain = p @ cs.T @ np.linalg.inv(cs @ p @ cs.T + rs) / sy[None, :]
        eig = np.abs(np.linalg.eigvals((np.eye(nx + nd) - self.gain @ self.c) @ self.a))
        if eig.max() >= 1.0:
            raise ValueError(f"the estimator is unstable (spectral radius {eig.max():.4f})")
        self.spectral_radius = float(eig.max())
        self._read = SignalReader(self.signals)
        self._work = np.empty(nx + nd + len(self.signals))
        self.reset()

    def reset(self, x_dev: np.ndarray | None = None, d_dev: np.ndarray | None = None) -> None:
        """Start from deviations (default: the operating point).

        Parameters
        ----------
        x_dev : (n_x,) ndarray, optional
            State deviation to start from.
        d_dev : (n_d,) ndarray, optional
            Wind deviation to start from.
        """
        self.xa = np.concatenate([np.zeros(self.nx) if x_dev is None else x_dev,
                                  np.zeros(self.nd) if d_dev is None else d_dev])
        self._started = False

    @property
    def started(self) -> bool:
        """Whether a measurement has been taken since the last reset."""
        return self._started

    def hand_over(self, other: "KalmanEstimator", offset: np.ndarray) -> None:
        """Continue from another estimator's estimate (gain scheduling).

        Parameters
        ----------
        other : KalmanEstimator
            The estimator being replaced.
        offset : (n_x + n_d,) ndarray
            Its operating point minus ours ([x0; d0] of its model minus ours), so that the
            estimate is carried over in absolute units.
        """
        self.xa = other.xa + offset
        self._started = other.started

    def measurement(self, meas: dict[str, Any]) -> np.ndarray:
        """The measured-signal vector from a harness measurement dict.

        Parameters
        ----------
        meas : dict
            The harness's measurements.

        Returns
        -------
        (n_y,) ndarray
            The measured signals (:attr:`signals` order).
        """
        return self._read(meas)

    def update(self, y: np.ndarray, u_dev: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One step: predict with the input applied over the last step, correct with the
        measurement ``y`` (absolute values, :attr:`signals` order). Returns the state and wind
        deviations from the operating point.

        Parameters
        ----------
        y : (n_y,) ndarray
            Measured signals (absolute).
        u_dev : (n_u,) ndarray
            Input deviation applied over the last step.

        Returns
        -------
        x_dev : (n_x,) ndarray
            State deviation estimate.
        d_dev : (n_d,) ndarray
            Blade-effective wind deviation estimate [m/s].
        """
        y = np.asarray(y, float)
        u = np.asarray(u_dev, float)
        if y.shape != (len(self.signals),) or u.shape != (self.b.shape[1],) or not \
                _kalman_step(self.a, self.b, self.c, self.d, self.gain, self.y0, self.xa, y, u,
                             self._started, self._work):
            raise ValueError(f"y must be {len(self.signals)} finite measurements "
                             f"{self.signals} and u_dev {self.b.shape[1]} inputs, got y = "
                             f"{y!r}, u_dev = {u!r}")
        self._started = True
        return self.xa[:self.nx].copy(), self.xa[self.nx:].copy()
