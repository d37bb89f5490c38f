"""Time series of every controller kind beside the baseline in the sign-off's transients: the
ramp through the region-2/3 transition (8 -> 14 -> 8 m/s in 120 s), the extreme operating gust
at rated wind, the extreme coherent gust with direction change at rated wind, a grid loss at a
gust's peak and a pitch runaway on one blade. Reads the finished campaign's result files; writes
one PNG per event (rotor speed, electrical power, blade-1 pitch and blade-1 flap moment over
time) into ``DIR/report/series`` and prints each kind's extremes in it as a Markdown table.

Run:  python benchmarks/study_signoff_series.py CAMPAIGN_DIR
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from mpc_wt.campaign import CampaignStore
from mpc_wt.simulation.results import ClosedLoopResult

#: (title, file stem, DLC, mean wind [m/s] or None for a file case, sign, time window [s])
EVENTS = [
    ("Ramp 8 -> 14 -> 8 m/s in 120 s (uniform, sheared)", "ramp", "ramp", None, None,
     (60.0, 210.0)),
    ("Extreme operating gust at rated wind (11.4 m/s)", "eog_rated", "1.6-eog", 11.4, "pos",
     (60.0, 100.0)),
    ("Extreme coherent gust with direction change at rated wind (11.4 m/s)", "ecd_rated", "1.4",
     11.4, "pos", (60.0, 120.0)),
    ("Grid loss at the peak of an EOG at rated wind (11.4 m/s)", "grid_loss_rated", "2.3", 11.4,
     "pos", (60.0, 100.0)),
    ("Pitch runaway on blade 1 at 17 m/s (protection 1 s later)", "runaway_17", "2.1", 17.0,
     None, (70.0, 100.0)),
]


def _find(rows: list, dlc: str, wind: float | None, sign: str | None) -> dict[str, object]:
    """The result file of each controller's case of this DLC (and wind, sign)."""
    out: dict[str, object] = {}
    for r in rows:
        parts = r.case_id.split("__")
        if r.status != "done" or len(parts) < 2 or parts[1] != f"dlc{dlc}":
            continue
        if wind is not None and abs(r.wind_mps - wind) > 1e-6:
            continue
        if sign is not None and parts[-1] != sign:
            continue
        out.setdefault(r.controller, r.file)
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("campaign", help="a finished sign-off campaign's directory")
    args = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mpc_wt.plotting import save_figure

    root = Path(args.campaign)
    with CampaignStore(root) as st:
        rows = st.rows()
    outdir = root / "report" / "series"
    outdir.mkdir(parents=True, exist_ok=True)
    for title, stem, dlc, wind, sign, (t0, t1) in EVENTS:
        files = _find(rows, dlc, wind, sign)
        if "baseline" not in files:
            print(f"{stem}: no baseline case in {root}; skipped")
            continue
        order = ["baseline"] + sorted(k for k in files if k != "baseline")
        fig, axes = plt.subplots(4, 1, figsize=(10, 11), sharex=True)
        cmap = plt.get_cmap("tab10")
        table = []
        for i, name in enumerate(order):
            res = ClosedLoopResult.load(root / str(files[name]))
            t = res.t
            sel = (t >= t0) & (t <= t1)
            style = dict(color="k", lw=2.2, zorder=5) if name == "baseline" else \
                dict(color=cmap(i % 10), lw=1.0)
            w = res.channel("rotor_speed") * 30.0 / math.pi
            p = res.channel("gen_power") / 1e6
            th = np.degrees(res.channel("pitch_1"))
            fl = res.channel("flap_moment_1") / 1e6
            for ax, y in zip(axes, (w, p, th, fl)):
                ax.plot(t[sel], y[sel], label=name, **style)
            table.append((name, w[sel].max(), p[sel].max(), th[sel].max(), fl[sel].max()))
        axes[0].set_ylabel("rotor speed [rpm]")
        axes[1].set_ylabel("electrical power [MW]")
        axes[2].set_ylabel("blade 1 pitch [deg]")
        axes[3].set_ylabel("blade 1 flap moment [MN m]")
        axes[3].set_xlabel("time [s]")
        axes[0].set_title(title)
        axes[0].legend(ncol=3, fontsize=8, loc="best")
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.tight_layout()
        path = save_figure(fig, outdir / f"{stem}.png")
        plt.close(fig)
        print(f"\n{title}: {path}\n")
        print("| controller | max rotor speed [rpm] | max power [MW] | max pitch [deg] | "
              "max flap [MN m] |")
        print("|---|---|---|---|---|")
        for name, *vals in table:
            print(f"| {name} | " + " | ".join(f"{v:.2f}" for v in vals) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
