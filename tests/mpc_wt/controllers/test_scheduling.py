"""The wind schedule of the scheduled controllers: which design acts, and when it acts
outside its range."""
from __future__ import annotations

import pytest

from mpc_wt.controllers.scheduling import WindSchedule


@pytest.mark.parametrize("wind, outside", [
    (None, False), (4.0, False), (3.0, False), (2.9, True), (25.9, False), (26.1, True),
    (12.0, False)])
def test_outside_is_more_than_a_metre_per_second_beyond_the_grid(turbine, wind,
                                                                   outside) -> None:
    """Grid 4-25 m/s and the 1 m/s margin, worked by hand: 3.0 and 25.9 m/s are within it,
    2.9 and 26.1 m/s beyond; no wind yet is not outside."""
    s = WindSchedule([4.0, 10.0, 25.0], turbine, 0.1)
    s.wind = wind
    assert s.outside is outside


def test_the_nearest_grid_wind_acts_first_and_hysteresis_holds(turbine) -> None:
    """The first estimate picks the nearest grid wind; a slow wind moving across a midpoint
    switches only once it is more than the hysteresis beyond it."""
    s = WindSchedule([4.0, 10.0, 25.0], turbine, 0.1, time_constant=0.0, hysteresis=0.5)
    s.measured_wind = lambda meas: meas["w"]          # a scheduling wind given directly
    assert s.update({"w": 6.5}) == (0, False)       # nearest to 6.5 is 4 (midpoint 7)
    assert s.update({"w": 7.4}) == (0, False)       # 0.4 beyond the midpoint: held
    assert s.update({"w": 7.6}) == (1, True)
    assert s.switches == 1
