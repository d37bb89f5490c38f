"""The Python controller of an exportable kind measured as OpenFAST's ServoDyn measures its
library: at the first call no generator torque or electrical power yet (records 23 and 15 are
the previous step's: BladedInterface.f90, Fill_avrSWAP). The tests that hold a kind's Python
step and its library to each other run the Python step through this."""
from __future__ import annotations

from typing import Any

import linearize
from mpc_wt.run import build_controller
from mpc_wt.simulation.loop import simulate_closed_loop
from mpc_wt.simulation.scenario import Scenario


class AsServoDyn:
    """A controller whose first step sees ``gen_torque`` and ``gen_power`` 0."""

    def __init__(self, ctl: Any) -> None:
        self._ctl, self._first = ctl, True

    def __getattr__(self, name: str) -> Any:
        return getattr(self._ctl, name)

    def reset(self) -> None:
        self._first = True
        self._ctl.reset()

    def step(self, t: float, meas: dict[str, Any]) -> Any:
        if self._first:
            meas = {**meas, "gen_torque": 0.0, "gen_power": 0.0}
            self._first = False
        return self._ctl.step(t, meas)


def run_python(turbine: linearize.Turbine, kind: str, wind: float,
               options: dict[str, Any] | None = None, *, duration: float, turbulence: Any,
               seed: int, fields: Any = None) -> Any:
    """A kind's Python controller (its design's objects) in a turbulent case, measured at its
    first step as the library is (the Python loop: :class:`AsServoDyn` hides compiled laws)."""
    sc = Scenario(wind, turbulence=turbulence, seed=seed, duration=duration)
    params = linearize.plant_params(turbine)
    built, op, field = build_controller(turbine, kind, sc, options, fields=fields,
                                        params=params, shipped=False)
    return simulate_closed_loop(params, AsServoDyn(built.controller), field, sc.duration,
                                x0=op.x, u0=op.u, controller_dt=built.controller_dt,
                                preview=built.preview)
