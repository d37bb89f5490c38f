"""The arms of a finished campaign against its reference, one row per controller: lifetime
DEL changes of the spec's channels, rotor-speed std, power std, pitch travel, pitch-rate std and
the blade-1 flap 1P content, each the mean over the seeds' values, as a change against the
reference's mean [%]; the DEL changes from the campaign report's ``lifetime_del.csv`` (run
``mpcwt campaign report`` or ``campaign run --report`` first). Prints a Markdown table (and
writes it with --out).

Run:  python benchmarks/study_arms.py CAMPAIGN_DIR [--out table.md]
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

from mpc_wt.campaign import CampaignStore, load_spec


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("campaign", help="a finished campaign's directory")
    ap.add_argument("--out", help="also write the table here")
    args = ap.parse_args()
    root = Path(args.campaign)
    spec = load_spec(root / "spec.yaml")
    with CampaignStore(root) as st:
        rows = [r for r in st.rows() if r.status == "done"]
    by: dict[str, list] = {}
    for r in rows:
        by.setdefault(r.case_id.split("__")[0], []).append(r.metrics)

    def mean(name: str, key: str) -> float:
        vals = []
        for m in by[name]:
            v = m[key]
            vals.append(v["1P"] if isinstance(v, dict) else v)
        return float(np.mean(vals))
    ref = spec.reference
    with (root / "report" / "lifetime_del.csv").open() as fh:
        dels = {(r["controller"], r["channel"]): float(r["change_pct"])
                for r in csv.DictReader(fh)}
    chans = list(spec.channels)
    cols = [("rotor-speed std", "rotor_speed_std_rad_s"), ("power std", "power_std_W"),
            ("pitch travel", "pitch_travel_deg"), ("pitch-rate std", "pitch_rate_std_degps"),
            ("flap 1P", "flap_1_harmonics")]
    head = ["arm", *[f"{c} DEL" for c in chans], *[c for c, _ in cols]]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for name in by:
        if name == ref:
            continue
        cells = [name]
        for c in chans:
            cells.append(f"{dels[(name, c)]:+.1f} %" if (name, c) in dels else "-")
        for _, key in cols:
            cells.append(f"{100.0 * (mean(name, key) / mean(ref, key) - 1.0):+.1f} %")
        lines.append("| " + " | ".join(cells) + " |")
    text = "\n".join(lines)
    print(f"{spec.name}: {len(rows)} cases, against {ref} (seeds {list(spec.seeds)})")
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
