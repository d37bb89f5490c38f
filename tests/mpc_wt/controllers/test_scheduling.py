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


# ---- the region floor ------------------------------------------------------------------------
import math  # noqa: E402

import numpy as np  # noqa: E402
from hypothesis import given, settings, strategies as st  # noqa: E402

import linearize  # noqa: E402
from mpc_wt.controllers.scheduling import RegionFloor, envelope_winds, region3_wind  # noqa: E402
from mpc_wt.controllers.wind_estimator import WindSpeedEstimator  # noqa: E402

_D = math.radians


def _floor() -> RegionFloor:
    """A pitch curve worked by hand: 2 deg at 12 m/s, 6 deg at 14 m/s; fine pitch 0 with a
    0.3 deg margin; rated speed 1 rad/s; the first region-3 design at 12 m/s."""
    return RegionFloor([12.0, 14.0], [_D(2.0), _D(6.0)], _D(0.3), 1.0, 1.01)


@pytest.mark.parametrize("pitch_deg, speed, expected", [
    (0.1, 1.0, -math.inf),   # at fine pitch and rated speed: no floor
    (0.1, 1.02, 12.0),       # above 1.01 x rated speed: the first region-3 design
    (1.0, 1.0, 12.0),        # above the threshold, below the curve's first pitch: its wind
    (4.0, 1.0, 13.0),        # halfway up the curve: halfway between 12 and 14 m/s
    (10.0, 1.0, 14.0),       # beyond the curve: its last wind
    (4.0, 1.02, 13.0),       # both: the larger
    (4.0, 0.94, -math.inf),  # pitched, the rotor below 0.95 x rated: a lull, no floor
])
def test_the_floor_reads_the_pitch_curve_backwards(pitch_deg, speed, expected) -> None:
    assert _floor().floor(_D(pitch_deg), speed) == pytest.approx(expected)


@pytest.mark.parametrize("kw, name", [
    ({"winds": [12.0, 14.0], "pitches": [0.1, 0.05]}, "pitches"),
    ({"winds": [14.0, 12.0], "pitches": [0.05, 0.1]}, "winds"),
    ({"winds": [12.0, float("nan")], "pitches": [0.05, 0.1]}, "winds"),
])
def test_a_floor_refuses_a_curve_that_does_not_rise(kw, name) -> None:
    with pytest.raises(ValueError, match=name):
        RegionFloor(kw["winds"], kw["pitches"], 0.005, 1.0)


def test_a_floor_refuses_a_speed_margin_below_one() -> None:
    with pytest.raises(ValueError, match="speed_margin"):
        RegionFloor([12.0], [0.05], 0.005, 1.0, speed_margin=0.9)


_ESTIMATORS: dict[int, WindSpeedEstimator] = {}


def _estimator(turbine: linearize.Turbine) -> WindSpeedEstimator:
    """One wind estimator per turbine object, made once: its C_P table takes seconds."""
    if id(turbine) not in _ESTIMATORS:
        _ESTIMATORS[id(turbine)] = WindSpeedEstimator(turbine, 0.1)
    return _ESTIMATORS[id(turbine)]


@settings(max_examples=200, deadline=None)
@given(w=st.floats(2.0, 30.0), pitch=st.floats(-0.05, 0.5), speed=st.floats(0.5, 1.5))
def test_the_floored_wind_is_never_below_the_measured_one(turbine, w, pitch, speed) -> None:
    """Property: the schedule's floored wind is the larger of its wind and the floor, and its
    measured wind stays the wind itself."""
    s = WindSchedule([4.0, 12.0, 14.0, 25.0], turbine, 0.1, time_constant=0.0, floor=_floor(),
                     estimator=_estimator(turbine))
    s.measured_wind = lambda meas: w
    s.update({"pitch": [pitch] * 3, "rotor_speed": speed})
    assert s.measured == w
    assert s.floored == max(w, _floor().floor((pitch + pitch + pitch) / 3.0, speed))


def test_a_pitched_rotor_selects_a_region_3_design_whatever_the_wind_says(turbine) -> None:
    """A wind estimate of 9 m/s (below rated) with the blades at 4 deg: the floor (13 m/s)
    picks the 14 m/s design of the grid 4, 9, 14, 25 m/s; without the floor the 9 m/s one."""
    meas = {"pitch": [_D(4.0)] * 3, "rotor_speed": 1.0}
    for floor, k in ((_floor(), 2), (None, 1)):
        s = WindSchedule([4.0, 9.0, 14.0, 25.0], turbine, 0.1, time_constant=0.0, floor=floor)
        s.measured_wind = lambda meas: 9.0
        assert s.update(meas)[0] == k


def test_the_first_region_3_design_is_where_the_trim_has_left_fine_pitch(turbine) -> None:
    """With region3_pitch = 2 deg the rated point is replaced by the wind whose trim is 2 deg
    above fine pitch (within the bisection's 1 mm/s, the rounding's 5 mm/s and the trim's
    tolerance: 0.05 deg), and no design lies between rated wind and it; without it, the rated
    wind is in the grid as before."""
    conf = linearize.PlantConfig.madsen()
    v3 = region3_wind(turbine, _D(2.0), config=conf)
    pitch = linearize.trim(turbine, v3, config=conf).pitch_rad
    assert math.degrees(pitch - turbine.operation.fine_pitch_rad) == pytest.approx(2.0, abs=0.05)
    rated = linearize.rated_wind_speed(turbine)
    g = envelope_winds(turbine, 1.0, region3_pitch=_D(2.0), config=conf)
    assert v3 in g and not np.any((g > rated - 0.05) & (g < v3))
    assert np.min(np.abs(envelope_winds(turbine, 1.0) - rated)) < 0.01


def test_region3_wind_refuses_a_pitch_the_trim_never_reaches(turbine) -> None:
    with pytest.raises(ValueError, match="pitch_rad"):
        region3_wind(turbine, _D(60.0))
    with pytest.raises(ValueError, match="pitch_rad"):
        region3_wind(turbine, 0.0)


def test_the_floor_of_a_family_below_rated_only_is_refused(turbine) -> None:
    fam = linearize.linearize_family(turbine, [6.0, 8.0], config=linearize.PlantConfig.madsen())
    with pytest.raises(ValueError, match="above rated"):
        RegionFloor.from_family(fam, turbine)
