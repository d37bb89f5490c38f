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

import numpy as np
import scipy.linalg

import linearize
from linearize.validate import check_number

__all__ = ["KalmanEstimator", "MEASURED_SIGNALS", "STATE_NOISE"]

#: Model outputs the estimator uses and their default measurement noise std [output units]
#: (the NREL 5-MW's: :func:`mpc_wt.controllers.mpc.turbine_noise` carries them to another
#: turbine).
MEASURED_SIGNALS: dict[str, float] = {
    "rotor_speed": 1e-3, "gen_speed": 0.1, "pitch_1": 1e-4, "pitch_2": 1e-4, "pitch_3": 1e-4,
    "flap_moment_1": 2e4, "flap_moment_2": 2e4, "flap_moment_3": 2e4,
    "tower_fa_acceleration": 0.02}

#: Default process-noise std per state and per step [state units] (the NREL 5-MW's).
STATE_NOISE = {"tower_fa_displacement": 1e-3, "tower_fa_velocity": 2e-3, "rotor_speed": 1e-4,
                "gen_speed": 1e-2, "shaft_torsion": 1e-5, "pitch_1": 1e-5, "pitch_2": 1e-5,
                "pitch_3": 1e-5}


class KalmanEstimator:
    """The design of the steady-state Kalman filter for the states and the blade-effective
    winds: its augmented model and gain, which the MPC's shipped law runs (``mpc.c``: predict
    with the input applied over the last step, correct with the measurements).

    Parameters
    ----------
    model : LinearModel
        Discrete model (any ``dt``) with the outputs of :data:`MEASURED_SIGNALS` among its
        outputs (the full output set of :func:`linearize.linearize`).
    wind_std_per_step : float
        Random-walk std of each blade-effective wind per step [m/s] (default 0.2 at 10 Hz): larger
        follows gusts faster and passes more measurement noise.
    measurement_std : dict, optional
        Overrides of the noise std per measured signal [its units].
    state_std : dict, optional
        Overrides of the process-noise std per state and per step [its units].
    """

    def __init__(self, model: linearize.LinearModel, *, wind_std_per_step: float = 0.2,
                 measurement_std: dict[str, float] | None = None,
                 state_std: dict[str, float] | None = None) -> None:
        if model.dt is None:
            raise ValueError("model must be discrete: call model.discretize(dt) first")
        check_number("wind_std_per_step", wind_std_per_step, lo=0.0, lo_open=True, unit="m/s")
        std = dict(MEASURED_SIGNALS)
        for k, v in (measurement_std or {}).items():
            if k not in std:
                raise ValueError(f"measurement_std: unknown signal {k!r}; signals are "
                                 f"{sorted(std)}")
            std[k] = check_number(f"measurement_std[{k!r}]", v, lo=0.0, lo_open=True)
        state = dict(STATE_NOISE)
        for k, v in (state_std or {}).items():
            if k not in state:
                raise ValueError(f"state_std: unknown state {k!r}; states are {sorted(state)}")
            state[k] = check_number(f"state_std[{k!r}]", v, lo=0.0, lo_open=True)
        missing = [n for n in std if n not in model.outputs]
        if missing:
            raise ValueError(f"model lacks the measured outputs {missing}")
        unknown = [n for n in model.states if n not in state]
        if unknown:
            raise ValueError(f"the Kalman estimator has no process-noise default for the "
                             f"model's states {unknown} (it knows {sorted(STATE_NOISE)}): "
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
        q = np.diag([state[n] ** 2 for n in model.states] + [wind_std_per_step ** 2] * nd)
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

