"""The sign-off's bounds, per controller kind, from a finished campaign's report (run
``mpcwt campaign report DIR`` or ``campaign run --report`` first): failed cases; overspeed stops
against the baseline's; the largest rotor speed in DLC 1.x against the baseline's + 2 % of
rated; AEP within 0.5 % of the baseline's; DLC 1.2 pitch travel at most 3x the baseline's; the
lifetime DELs of blade flap, shaft bending and tower fore-aft (below the baseline's is the aim
for the MPC with preview) and the largest lifetime-DEL and governing-design-load change over
every channel (at most +5 % unless the trade is shown). Prints a Markdown table; a bound not
met is marked with its measured value.

Run:  python benchmarks/study_signoff_judge.py CAMPAIGN_DIR [--out table.md]
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as f:
        return list(csv.DictReader(f))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("campaign", help="a finished sign-off campaign's directory")
    ap.add_argument("--out", help="also write the table here")
    ap.add_argument("--reference", default="baseline")
    args = ap.parse_args()
    rep = Path(args.campaign) / "report"
    so = _rows(rep / "signoff.csv")
    aep = {r["controller"]: float(r["change_pct"]) for r in _rows(rep / "aep.csv")}
    pitch = {r["controller"]: float(r["pitch_travel_deg_change_pct"]) / 100 + 1
             for r in _rows(rep / "pitch.csv")}
    life: dict[str, dict[str, float]] = {}
    for r in _rows(rep / "lifetime_del.csv"):
        life.setdefault(r["controller"], {})[r["channel"]] = float(r["change_pct"])
    gov: dict[str, dict[str, float]] = {}
    for r in _rows(rep / "governing.csv"):
        gov.setdefault(r["controller"], {})[r["channel"]] = float(r["change_pct"])
    ctls = list(dict.fromkeys(r["controller"] for r in so))
    agg = {}
    for c in ctls:
        mine = [r for r in so if r["controller"] == c]
        w1 = [float(r["rotor_speed_max_rel"]) for r in mine
              if r["dlc"].startswith("1.") and r["rotor_speed_max_rel"]]
        agg[c] = {"failed": sum(int(r["failed"]) for r in mine),
                  "stops": sum(int(r["overspeed_stops"]) for r in mine),
                  "w1": max(w1) if w1 else float("nan")}
    ref = agg[args.reference]
    head = ("| controller | failed | overspeed stops (baseline) | max rotor speed DLC 1.x / "
            "rated (bound) | AEP change | pitch travel DLC 1.2 | flap / shaft / tower FA "
            "lifetime DEL | largest lifetime DEL change | largest governing load change |")
    lines = [head, "|" + "---|" * 9]

    def mark(ok: bool, text: str) -> str:
        return text if ok else f"**{text}** (not met)"

    for c in ctls:
        a = agg[c]
        ld, gd = life.get(c, {}), gov.get(c, {})
        big_l = max(ld.items(), key=lambda kv: kv[1]) if ld else ("-", float("nan"))
        big_g = max(gd.items(), key=lambda kv: kv[1]) if gd else ("-", float("nan"))
        three = " / ".join(f"{ld.get(ch, float('nan')):+.1f} %" for ch in
                           ("flap_moment_1", "shaft_bending_blade1", "tower_base_fa_moment"))
        nan = float("nan")
        w1, e, pt = a["w1"], aep.get(c, nan), pitch.get(c, nan)
        lines.append(" | ".join([
            f"| {c}", mark(a["failed"] == 0, str(a["failed"])),
            mark(a["stops"] <= ref["stops"], str(a["stops"])) + f" ({ref['stops']})",
            mark(w1 <= ref["w1"] + 0.02, f"{w1:.3f}") + f" ({ref['w1'] + 0.02:.3f})",
            mark(abs(e) <= 0.5, f"{e:+.2f} %"), mark(pt <= 3.0, f"{pt:.2f}x"), three,
            mark(big_l[1] <= 5.0, f"{big_l[1]:+.1f} % ({big_l[0]})"),
            mark(big_g[1] <= 5.0, f"{big_g[1]:+.1f} % ({big_g[0]})")]) + " |")
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
