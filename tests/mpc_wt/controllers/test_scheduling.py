"""The design side of the wind schedule: the region floor's curve, the grid of the scheduled
designs and the first region-3 design (the schedule itself runs in the shipped C laws)."""
from __future__ import annotations

import pytest



# ---- the region floor ------------------------------------------------------------------------
import math  # noqa: E402

import numpy as np  # noqa: E402
from hypothesis import given, settings, strategies as st  # noqa: E402

import linearize  # noqa: E402
from mpc_wt.controllers.scheduling import RegionFloor, envelope_winds, region3_wind  # noqa: E402

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


@settings(max_examples=200, deadline=None)
@given(p1=st.floats(-0.05, 0.5), p2=st.floats(-0.05, 0.5), speed=st.floats(0.5, 1.5))
def test_the_floor_never_falls_as_the_pitch_rises(p1, p2, speed) -> None:
    """Property: at one rotor speed, a larger pitch never gives a lower floor (the pitch curve
    rises with the wind)."""
    lo, hi = sorted((p1, p2))
    f = _floor()
    assert f.floor(hi, speed) >= f.floor(lo, speed)
