"""Every controller kind on one turbine against the bounds a new turbine's kinds must meet,
from a finished campaign of a few mean winds (``benchmarks/studies/iea22_kinds.yaml`` and its
siblings for other decks): failed cases and supervisor stops (the overspeed stop at the spec's
``supervisor.overspeed``); the mean electrical power at the winds at least
``--region3-margin`` m/s above the turbine's rated wind within 1 % of rated (seed mean); the
largest rotor speed at each wind within the baseline's largest at that wind + 2 % of rated; the
largest electrical power at most ``mpc_wt.run.POWER_BOUND`` x rated; the pitch travel over all
cases at most 3x the baseline's; and, at the winds below rated, the region-2 pitch on the
turbine's minimum-pitch schedule (``linearize.region2_pitch``): the median over region-2
samples of the blades' mean pitch minus the schedule's pitch at the rotor-effective wind of the
case's field, low-passed over 30 s (the simulator's wind, which no controller reads; region-2
samples are those where that wind lies 1 m/s or more below rated and the power below 95 % of
rated), within ``REGION2_PITCH_TOL`` deg. Prints a Markdown table; a bound not met is marked with
its measured value.

Run:  python benchmarks/study_turbine_table.py CAMPAIGN_DIR [--out table.md]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

import lidar
import linearize
from mpc_wt.campaign import CampaignStore
from mpc_wt.campaign.spec import spec_from_dict
from mpc_wt.run import POWER_BOUND
from mpc_wt.simulation.results import ClosedLoopResult
from mpc_wt.simulation.scenario import Scenario, make_wind

#: region-3 mean electrical power within this fraction of rated
POWER_TOL = 0.01
#: the largest rotor speed within the baseline's + this fraction of rated speed
SPEED_MARGIN = 0.02
#: pitch travel at most this multiple of the baseline's
TRAVEL_BOUND = 3.0
#: the region-2 pitch's median deviation from the minimum-pitch schedule [deg]: a quarter of
#: the IEA-22 schedule's span over region 2 (-1.3 to +0.6 deg), and 3x the trim's own spread of
#: the schedule's pitch over 1 m/s there
REGION2_PITCH_TOL = 0.5
#: the low-pass of the rotor-effective wind that sets the schedule's pitch [s]
WIND_AVERAGE_S = 30.0


#: the low-passed rotor-effective wind of each scenario's field: every controller of a case
#: meets the same field, made once here
_WIND: dict[Scenario, tuple[np.ndarray, np.ndarray]] = {}


def _filtered_wind(turbine: linearize.Turbine, scenario: Scenario
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Times [s] and the rotor-effective wind of the case's field low-passed over
    :data:`WIND_AVERAGE_S` [m/s]."""
    if scenario not in _WIND:
        _, field = make_wind(turbine, scenario, "u")
        v = lidar.rotor_effective_wind(field, turbine.geometry.tip_radius, method="cube")
        n = max(1, int(round(WIND_AVERAGE_S / float(np.median(np.diff(field.t))))))
        _WIND[scenario] = (field.t, np.convolve(v, np.ones(n) / n, mode="same"))
    return _WIND[scenario]


def _region2_deviation(turbine: linearize.Turbine, res: ClosedLoopResult, scenario: Scenario,
                       rated_wind: float, transient: float) -> float:
    """The median region-2 deviation of the mean pitch from the schedule [deg] (module
    docstring), NaN where the case holds no region-2 sample."""
    tf, vf = _filtered_wind(turbine, scenario)
    t = res.t
    keep = t >= t[0] + transient
    vw = np.interp(t[keep], tf, vf)
    pitch = np.mean([res.channel(f"pitch_{i}")[keep] for i in (1, 2, 3)], axis=0)
    power = res.channel("gen_power")[keep]
    sel = (vw <= rated_wind - 1.0) & (power < 0.95 * turbine.operation.rated_power)
    if not np.any(sel):
        return math.nan
    table = np.array([linearize.region2_pitch(turbine, float(w)) for w in vw[sel]])
    return float(np.degrees(np.median(pitch[sel] - table)))


def _collect(root: Path) -> tuple[dict[str, Any], linearize.Turbine, float]:
    """Per controller its done cases (wind, seed, metrics, file, the spec's case) and
    failures."""
    out: dict[str, Any] = {}
    with CampaignStore(root) as st:
        raw = st.meta()["spec_raw"]          # the spec with its paths resolved
        spec = spec_from_dict(raw, import_plugins=False)
        cases = {c.case_id: c for c in spec.cases()}
        turbine = linearize.load_turbine(spec.turbine)
        rated_wind = linearize.rated_wind_speed(turbine)
        for r in st.rows():
            d = out.setdefault(r.controller, {"cases": [], "failed": []})
            if r.status == "done" and r.metrics:
                d["cases"].append((r.wind_mps, r.seed, r.metrics, root / str(r.file),
                                   cases.get(r.case_id)))
            elif r.status == "failed":
                d["failed"].append(f"{r.wind_mps:g} m/s seed {r.seed}: {r.error}")
    return out, turbine, rated_wind


def _judge(name: str, d: dict[str, Any], base: dict[str, Any], turbine: linearize.Turbine,
           rated_wind: float, margin: float) -> dict[str, Any]:
    """One controller's row: each measure and whether it meets its bound."""
    rated_p = turbine.operation.rated_power
    rated_w = turbine.operation.rated_rotor_speed_rad_s
    cases = d["cases"]
    winds = sorted({c[0] for c in cases})
    row: dict[str, Any] = {"controller": name, "failed": len(d["failed"]),
                           "stops": sum(1 for c in cases if c[2].get("supervisor_state"))}
    if not cases:                              # every case failed: nothing to measure
        return {**row, **dict.fromkeys(("power_r3", "speed_over", "power_max", "travel",
                                        "region2_pitch"), math.nan)}
    p3 = [np.mean([c[2]["power_mean_W"] for c in cases if c[0] == w]) / rated_p
          for w in winds if w >= rated_wind + margin]
    row["power_r3"] = max(p3, key=lambda p: abs(p - 1.0)) if p3 else math.nan
    over = []
    for w in winds:
        ours = max(c[2]["rotor_speed_max_rad_s"] for c in cases if c[0] == w)
        ref = [c[2]["rotor_speed_max_rad_s"] for c in base["cases"] if c[0] == w]
        if ref:
            over.append((ours - max(ref)) / rated_w)
    row["speed_over"] = max(over) if over else math.nan
    row["power_max"] = max(c[2]["extremes"]["gen_power"]["max"] for c in cases) / rated_p
    travel = sum(c[2]["pitch_travel_deg"] for c in cases)
    row["travel"] = travel / sum(c[2]["pitch_travel_deg"] for c in base["cases"])
    dev = [_region2_deviation(turbine, ClosedLoopResult.load(c[3]), c[4].scenario, rated_wind,
                              c[4].transient)
           for c in cases if c[0] < rated_wind and c[4] is not None]
    dev = [x for x in dev if math.isfinite(x)]
    row["region2_pitch"] = max(dev, key=abs) if dev else math.nan
    return row


def _cell(v: float, ok: bool, fmt: str) -> str:
    if not math.isfinite(v):
        return "-"
    return format(v, fmt) if ok else f"**{format(v, fmt)} (bound not met)**"


def _cells(r: dict[str, Any]) -> tuple[list[str], bool]:
    """A row's cells and whether every bound is met (a measure that does not apply, NaN,
    meets it)."""
    checks = [("failed", r["failed"] == 0, "d"), ("stops", r["stops"] == 0, "d"),
              ("power_r3", abs(r["power_r3"] - 1.0) <= POWER_TOL, ".4f"),
              ("speed_over", r["speed_over"] <= SPEED_MARGIN, "+.2%"),
              ("power_max", r["power_max"] <= POWER_BOUND, ".3f"),
              ("travel", r["travel"] <= TRAVEL_BOUND, ".2f"),
              ("region2_pitch", abs(r["region2_pitch"]) <= REGION2_PITCH_TOL, "+.2f")]
    ok = [good or not math.isfinite(r[k]) for k, good, _ in checks]
    return [_cell(r[k], o, f) for (k, _, f), o in zip(checks, ok)], all(ok)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("campaign", help="a finished campaign's directory")
    ap.add_argument("--out", help="also write the table here")
    ap.add_argument("--reference", default="baseline")
    ap.add_argument("--region3-margin", type=float, default=4.0,
                    help="region-3 winds lie this far above rated [m/s] (default 4)")
    args = ap.parse_args()
    root = Path(args.campaign)
    data, turbine, rated_wind = _collect(root)
    if args.reference not in data:
        print(f"no controller {args.reference!r} in {root}", file=sys.stderr)
        return 2
    lines = [f"{turbine.name}: rated wind {rated_wind:.2f} m/s, rated power "
             f"{turbine.operation.rated_power / 1e6:.3g} MW", "",
             "| controller | failed | supervisor stops | region-3 power / rated | largest "
             "speed - baseline's (of rated) | largest power / rated | pitch travel / "
             "baseline's | region-2 pitch - schedule [deg] |", "|---" * 8 + "|"]
    met = True
    for name in [args.reference] + sorted(k for k in data if k != args.reference):
        r = _judge(name, data[name], data[args.reference], turbine, rated_wind,
                   args.region3_margin)
        cells, ok = _cells(r)
        met &= ok
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
        for f in data[name]["failed"]:
            lines.append(f"<!-- {name} failed: {f[:300]} -->")
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    return 0 if met else 1


if __name__ == "__main__":
    sys.exit(main())
