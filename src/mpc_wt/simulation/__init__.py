"""Closed-loop simulation: scenarios and their wind, the loop, its compiled form, results.

A :class:`Scenario` says what the simulator meets (mean wind, turbulence, seed, duration, an
IEC condition); :func:`make_wind` makes its field. :func:`simulate_closed_loop` runs the plant
of :mod:`linearize` with any controller, a LIDAR in the loop (:class:`LidarPreview`) if asked,
and returns a :class:`ClosedLoopResult` that keeps every signal.
"""
from mpc_wt.simulation.loop import simulate_closed_loop
from mpc_wt.simulation.preview import LidarPreview
from mpc_wt.simulation.results import ClosedLoopResult, load_series
from mpc_wt.simulation.scenario import Scenario, field_grid, field_spec, iec_site, make_wind

__all__ = ["simulate_closed_loop", "LidarPreview", "ClosedLoopResult", "load_series",
           "Scenario", "field_grid", "field_spec", "iec_site", "make_wind"]
