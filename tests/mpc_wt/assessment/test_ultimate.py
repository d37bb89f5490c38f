"""Ultimate-load bookkeeping on synthetic series worked by hand."""
from __future__ import annotations

import numpy as np
import pytest

from mpc_wt.assessment.ultimate import SAFETY_FACTORS, case_extremes, ultimate_table


def test_case_extremes_and_their_times() -> None:
    t = np.linspace(0.0, 10.0, 101)
    x = np.sin(2 * np.pi * 0.1 * t)            # max 1 at t = 2.5 s, min -1 at 7.5 s
    ex = case_extremes(t, {"tower": 3.0 * x, "flap": x + 2.0}, ["tower", "flap"])
    assert ex["tower"] == {"max": pytest.approx(3.0), "t_max": 2.5, "min": pytest.approx(-3.0),
                           "t_min": 7.5}
    assert ex["flap"]["max"] == pytest.approx(3.0) and ex["flap"]["min"] == pytest.approx(1.0)


def test_ultimate_table_by_hand() -> None:
    """DLC 1.3 at two winds x two seeds and one EOG case (DLC 1.4, abnormal here for the
    test): the campaign's maximum is 12 (case c4); DLC 1.3's characteristic maximum is the
    larger seed mean, (9 + 11) / 2 = 10 at 18 m/s against (8 + 10) / 2 = 9 at 12 m/s, so its
    design load is 1.35 x 10 = 13.5; the minimum's seed means are -3 and -2, so -3 at 12 m/s
    and -4.05 designed; DLC 1.4 has one case: 12 x 1.1 = 13.2."""
    def row(cid, dlc, wind, seed, hi, lo):
        return {"case_id": cid, "dlc": dlc, "wind_mps": wind, "seed": seed,
                "extremes": {"tower": {"max": hi, "t_max": 0.0, "min": lo, "t_min": 0.0}}}
    rows = [row("c0", "1.3", 12.0, 1, 8.0, -4.0), row("c1", "1.3", 12.0, 2, 10.0, -2.0),
            row("c2", "1.3", 18.0, 1, 9.0, -1.0), row("c3", "1.3", 18.0, 2, 11.0, -3.0),
            row("c4", "1.4", 13.0, 1, 12.0, 0.5)]
    tab = ultimate_table(rows, ["tower"], families={"1.4": "A"})["tower"]
    assert (tab["max"], tab["max_case"], tab["min"], tab["min_case"]) == (12.0, "c4", -4.0, "c0")
    d13 = tab["by_dlc"]["1.3"]
    assert d13["characteristic_max"] == 10.0 and d13["wind_max"] == 18.0
    assert d13["characteristic_min"] == -3.0 and d13["wind_min"] == 12.0
    assert d13["design_max"] == pytest.approx(13.5) and d13["design_min"] == pytest.approx(-4.05)
    assert d13["seeds"] == 2 and d13["family"] == "N"
    d14 = tab["by_dlc"]["1.4"]
    assert d14["design_max"] == pytest.approx(12.0 * 1.1) and d14["safety_factor"] == 1.1
    assert SAFETY_FACTORS == {"N": 1.35, "A": 1.1, "T": 1.5}


def test_bad_input() -> None:
    t = np.arange(4.0)
    with pytest.raises(ValueError, match=r"channel 'edge' is not in the case; it has \['flap'\]"):
        case_extremes(t, {"flap": np.zeros(4)}, ["edge"])
    with pytest.raises(ValueError, match=r"channel 'flap' has non-finite values at t = 2 s"):
        case_extremes(t, {"flap": np.array([0.0, 1.0, np.nan, 2.0])}, ["flap"])
    with pytest.raises(ValueError, match=r"shape \(3,\); expected \(4,\)"):
        case_extremes(t, {"flap": np.zeros(3)}, ["flap"])
    with pytest.raises(ValueError, match="at least one case"):
        ultimate_table([], ["flap"])
    rows = [{"case_id": "c0", "dlc": "2.2", "wind_mps": 10.0, "seed": 1,
             "extremes": {"flap": {"max": 1.0, "t_max": 0.0, "min": 0.0, "t_min": 0.0}}}]
    with pytest.raises(ValueError, match=r"family of DLC '2.2' must be one of \['A', 'N', 'T'\]"
                                         r".*got 'X'"):
        ultimate_table(rows, ["flap"], families={"2.2": "X"})
    with pytest.raises(ValueError, match=r"case 'c0' has no extremes of channel 'edge'"):
        ultimate_table(rows, ["edge"])


def test_campaign_case_metrics_carry_the_extremes() -> None:
    """Every campaign case's metrics hold each channel's extremes after the transient (here a
    sine of 1 MN m amplitude on 5 MN m: 6 and 4 MN m; the start-up spike of 9 MN m before the
    transient is discarded)."""
    from mpc_wt.campaign.task import case_metrics

    t = np.arange(0.0, 60.0, 0.0125)
    tower = 5e6 + 1e6 * np.sin(2 * np.pi * 0.25 * t)
    tower[:10] = 9e6
    m = case_metrics(t, {"tower_base_fa_moment": tower, "gen_power": np.full_like(t, 5e6),
                         "rotor_speed": np.full_like(t, 1.2)}, {"tower_base_fa_moment": 4.0},
                     5.0)
    ex = m["extremes"]["tower_base_fa_moment"]
    assert ex["max"] == pytest.approx(6e6, rel=1e-6) and ex["min"] == pytest.approx(4e6, rel=1e-6)
    assert ex["t_max"] >= 5.0 and m["extremes"]["rotor_speed"]["max"] == pytest.approx(1.2)
