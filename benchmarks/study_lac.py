"""Our LIDAR collective feedforward against published LIDAR-assisted control results, under
the closest conditions our tool supports (the campaigns ``benchmarks/studies/lac_nrel5mw.yaml``
and ``lac_iea15mw.yaml``, held-out seeds 21-26), and where the pitch travel goes.

For each feedforward arm: the rotor-speed std change against the baseline (mean of the seeds'
stds, as the published examples compute it), the pitch travel change, and the pitch-rate
variance split in frequency bands (below 0.05 Hz, where the LIDAR's wind is coherent with the
rotor's; 0.05-0.15 Hz; above 0.15 Hz, up to and past 1P), so that the sign of the pitch-travel
change can be read off where it comes from. Published figures (their conditions in PUBLISHED)
are printed beside.

Run:  python benchmarks/study_lac.py NREL_CAMPAIGN_DIR IEA15_CAMPAIGN_DIR [--out table.md]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy import signal

from mpc_wt.simulation.results import ClosedLoopResult

#: Published rotor-speed std changes of a LIDAR collective pitch feedforward on ROSCO, with
#: their conditions: (label, turbine, source and conditions, change [%]).
PUBLISHED = [
    ("nrel5mw", "NREL 5-MW",
     "IEA Wind Task 32/52 LAC example NREL5MW_02 (Guo and Schlipf; the code of Guo, Schlipf "
     "and Cheng 2023, WES 8, 149): OpenFAST, ROSCO + feedforward, nacelle pulsed LIDAR (Molas "
     "NL), IEC Kaimal class A, 18 m/s, 6 x 600 s, frozen turbulence", -19.9),
    ("iea15mw", "IEA-15 monopile",
     "IEA Wind Task 52 LAC example IEA15MW_03, circular-scanning CW LIDAR at 200 m (cone "
     "15 deg), OpenFAST, ROSCO 2.6 + feedforward, IEC Kaimal class B, 18 m/s, 6 x 600 s, "
     "frozen turbulence", -63.9),
    ("iea15mw", "IEA-15 monopile",
     "the same example with a 4-beam pulsed LIDAR at 160 m", -49.5),
]
BANDS = ((0.0, 0.05), (0.05, 0.15), (0.15, 5.0))
TRANSIENT = 60.0


def _runs(root: Path) -> dict[str, list[ClosedLoopResult]]:
    out: dict[str, list[ClosedLoopResult]] = {}
    for f in sorted((root / "cases").glob("*.nc")):
        if f.name.endswith(".partial.nc"):
            continue
        out.setdefault(f.name.split("__")[0], []).append(ClosedLoopResult.load(f))
    return out


def _figures(runs: list[ClosedLoopResult]) -> dict[str, object]:
    stds, travel, bands = [], [], np.zeros(len(BANDS))
    for r in runs:
        k = r.t >= TRANSIENT
        stds.append(float(r.channel("rotor_speed")[k].std()))
        p = np.degrees(r.channel("pitch_1")[k])
        travel.append(float(np.abs(np.diff(p)).sum()))
        fs = 1.0 / float(np.median(np.diff(r.t)))
        f, s = signal.welch(np.gradient(p, 1.0 / fs), fs=fs, nperseg=int(204.8 * fs))
        bands += [np.trapezoid(s[(f >= lo) & (f < hi)], f[(f >= lo) & (f < hi)])
                  for lo, hi in BANDS]
    return {"speed_std": float(np.mean(stds)), "travel": float(np.mean(travel)),
            "bands": bands / len(runs), "n": len(runs)}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("nrel5mw", help="the finished lac_nrel5mw campaign's directory")
    ap.add_argument("iea15mw", help="the finished lac_iea15mw campaign's directory")
    ap.add_argument("--out", help="also write the tables here")
    args = ap.parse_args()
    lines = ["| turbine | arm | seeds | rotor-speed std | pitch travel | pitch-rate variance "
             "< 0.05 / 0.05-0.15 / > 0.15 Hz |", "|---|---|---|---|---|---|"]
    for key, turbine in (("nrel5mw", "NREL 5-MW"), ("iea15mw", "IEA-15")):
        runs = _runs(Path(getattr(args, key)))
        base = _figures(runs.pop("baseline"))
        for arm, rs in runs.items():
            fig = _figures(rs)
            ch = [100.0 * (fig[q] / base[q] - 1.0) for q in ("speed_std", "travel")]
            bd = " / ".join(f"{100.0 * (a / b - 1.0):+.0f} %"
                            for a, b in zip(fig["bands"], base["bands"]))
            lines.append(f"| {turbine} | {arm} | {fig['n']} | {ch[0]:+.1f} % | {ch[1]:+.1f} % "
                         f"| {bd} |")
        share = base["bands"] / base["bands"].sum()
        lines.append(f"| {turbine} | baseline's pitch-rate variance by band | | | | "
                     + " / ".join(f"{100 * x:.0f} %" for x in share) + " |")
    lines += ["", "| source and conditions | turbine | rotor-speed std |", "|---|---|---|"]
    lines += [f"| {src} | {tb} | {val:+.1f} % |" for _, tb, src, val in PUBLISHED]
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
