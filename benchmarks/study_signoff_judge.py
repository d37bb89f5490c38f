"""The sign-off's bounds, per controller kind, from a finished campaign's report (run
``mpcwt campaign report DIR`` or ``campaign run --report`` first): failed cases; overspeed stops
against the baseline's; the largest rotor speed in DLC 1.x against the baseline's + 2 % of
rated; the largest electrical power in DLC 1.x at most ``mpc_wt.run.POWER_BOUND`` x rated (a grid's
bound; cases of a campaign that predates their power extremes show nan); the largest generator
torque in every DLC at most the turbine's generator limit over its rated torque (the deck's;
1.1 for the NREL 5-MW and the IEA-15, to the swap array's float32); AEP within 0.5 % of the
baseline's; DLC 1.2 pitch travel at most 3x the baseline's; the
lifetime DELs of blade flap, shaft bending and tower fore-aft (below the baseline's is the aim
for the MPC with preview) and the largest lifetime-DEL and governing-design-load change over
every channel (at most +5 % unless the trade is shown; with the standard error the seeds'
scatter leaves on it, +- s, where the report gives one). Prints a Markdown table; a bound not
met is marked with its measured value.

With ``--without DLC ...`` the governing loads are taken over the other DLCs only (from the
report's ``ultimate.csv``, as the report takes them: the largest seed-mean design load in
magnitude), and ``--governing FILE`` writes them per channel.

Run:  python benchmarks/study_signoff_judge.py CAMPAIGN_DIR [--out table.md]
      [--without 2.1 2.2 --governing governing_no_faults.md]
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

from mpc_wt.run import POWER_BOUND

#: the largest torque may lie above the generator's limit by the swap array's float32 rounding
TORQUE_ROUNDING = 1e-6


def _torque_bound(campaign: Path) -> float:
    """The campaign's turbine's generator torque limit over its rated torque."""
    import linearize
    from mpc_wt.campaign import CampaignStore

    with CampaignStore(campaign) as st:          # the spec with its paths resolved
        t = linearize.load_turbine(st.meta()["spec_raw"].get("turbine", "nrel5mw"))
    return t.generator.max_torque / t.rated_generator_torque


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as f:
        return list(csv.DictReader(f))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("campaign", help="a finished sign-off campaign's directory")
    ap.add_argument("--out", help="also write the table here")
    ap.add_argument("--reference", default="baseline")
    ap.add_argument("--without", nargs="+", default=[], metavar="DLC",
                    help="leave these DLCs out of the governing loads")
    ap.add_argument("--governing", help="write the governing loads per channel here")
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
    gse: dict[str, dict[str, float]] = {}       # the change's standard error from the seeds
    if args.without:
        gov, where = _governing(_rows(rep / "ultimate.csv"), set(args.without), args.reference)
    else:
        where = {}
        for r in _rows(rep / "governing.csv"):
            gov.setdefault(r["controller"], {})[r["channel"]] = float(r["change_pct"])
            where.setdefault(r["controller"], {})[r["channel"]] = r["dlc"]
            if r.get("change_se_pct"):
                gse.setdefault(r["controller"], {})[r["channel"]] = float(r["change_se_pct"])
    ctls = list(dict.fromkeys(r["controller"] for r in so))
    agg = {}
    for c in ctls:
        mine = [r for r in so if r["controller"] == c]
        w1 = [float(r["rotor_speed_max_rel"]) for r in mine
              if r["dlc"].startswith("1.") and r["rotor_speed_max_rel"]]
        p1 = [float(r["power_max_rel"]) for r in mine
              if r["dlc"].startswith("1.") and r.get("power_max_rel")]
        q = [float(r["torque_max_rel"]) for r in mine if r.get("torque_max_rel")]
        agg[c] = {"failed": sum(int(r["failed"]) for r in mine),
                  "stops": sum(int(r["overspeed_stops"]) for r in mine),
                  "w1": max(w1) if w1 else float("nan"),
                  "p1": max(p1) if p1 else float("nan"),
                  "q": max(q) if q else float("nan")}
    ref = agg[args.reference]
    qb = _torque_bound(Path(args.campaign))
    head = ("| controller | failed | overspeed stops (baseline) | max rotor speed DLC 1.x / "
            f"rated (bound) | max power DLC 1.x / rated (bound {POWER_BOUND:.2f}) | max torque "
            f"/ rated (bound {qb:.3f}) | AEP change | pitch travel DLC 1.2 | flap / shaft / "
            "tower FA lifetime DEL | largest lifetime DEL change | largest governing load "
            "change |")
    lines = [head, "|" + "---|" * 11]

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
            mark(not a["p1"] > POWER_BOUND, f"{a['p1']:.3f}"),
            mark(not a["q"] > qb * (1 + TORQUE_ROUNDING), f"{a['q']:.3f}"),
            mark(abs(e) <= 0.5, f"{e:+.2f} %"), mark(pt <= 3.0, f"{pt:.2f}x"), three,
            mark(big_l[1] <= 5.0, f"{big_l[1]:+.1f} % ({big_l[0]})"),
            mark(big_g[1] <= 5.0, f"{big_g[1]:+.1f} %{_se(gse, c, big_g[0])} ({big_g[0]})")])
            + " |")
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    if args.governing:
        chans = list(dict.fromkeys(ch for g in gov.values() for ch in g))
        rows = ["| controller | " + " | ".join(chans) + " |", "|" + "---|" * (len(chans) + 1)]
        for c in ctls:
            rows.append(f"| {c} | " + " | ".join(
                f"{gov[c][ch]:+.1f} % ({where[c][ch]})" if ch in gov.get(c, {}) else "-"
                for ch in chans) + " |")
        Path(args.governing).write_text("\n".join(rows) + "\n")
    return 0


def _se(gse: dict[str, dict[str, float]], c: str, ch: str) -> str:
    """' +- s' with the standard error of a governing load's change, where the report has it."""
    se = gse.get(c, {}).get(ch)
    return "" if se is None else f" +- {se:.1f}"


def _governing(ult: list[dict[str, str]], without: set[str], reference: str
               ) -> tuple[dict[str, dict[str, float]], dict[str, dict[str, str]]]:
    """Governing-load change [%] against the reference and its DLC, per controller and
    channel, over the DLCs not in ``without``."""
    best: dict[tuple[str, str], tuple[float, str]] = {}
    for u in ult:
        if u["dlc"] in without:
            continue
        for side in ("max", "min"):
            if not u[f"design_{side}"]:
                continue
            v = abs(float(u[f"design_{side}"]))
            key = (u["controller"], u["channel"])
            if key not in best or v > best[key][0]:
                best[key] = (v, u["dlc"])
    gov: dict[str, dict[str, float]] = {}
    where: dict[str, dict[str, str]] = {}
    for (c, ch), (v, dlc) in best.items():
        ref = best.get((reference, ch))
        if ref is None or ref[0] == 0:
            continue
        gov.setdefault(c, {})[ch] = 100.0 * (v / ref[0] - 1.0)
        where.setdefault(c, {})[ch] = dlc
    return gov, where


if __name__ == "__main__":
    sys.exit(main())
