"""The exported controller libraries through the sign-off beside the Python controllers they
came from: the kinds exported (``mpc_wt.run.export_discon``, built with the system's C
compiler; default the baseline and the scheduled MPC), then the NREL 5-MW sign-off's load cases
(``benchmarks/studies/signoff.yaml``) run for each kind and its library side by side, and the
sign-off's figures compared pair by pair.

Run:  python benchmarks/study_discon_signoff.py OUT_DIR [--workers 2] [--kinds baseline mpc ...]

Writes OUT_DIR/libs (the exports), OUT_DIR/spec.yaml, the campaign in OUT_DIR/campaign with its
report, and prints per pair: failed cases, overspeed stops, the largest rotor speed in DLC 1.x,
AEP, DLC 1.2 pitch travel, and the largest change of a lifetime DEL and of a governing load of
the library against its Python controller.
"""
from __future__ import annotations

import argparse
import csv
import subprocess
import sys
from pathlib import Path

import yaml

import linearize
from mpc_wt.run import export_discon

HERE = Path(__file__).resolve().parent


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as f:
        return list(csv.DictReader(f))


def _spec(out: Path, kinds: list[str]) -> Path:
    t = linearize.load_turbine("nrel5mw")
    libs = {k: export_discon(t, k, out / "libs" / k) for k in kinds}
    spec = yaml.safe_load((HERE / "studies" / "signoff.yaml").read_text())
    spec["name"] = "signoff-discon"
    spec["description"] = (f"The sign-off's load cases for {', '.join(kinds)} and for the "
                           f"libraries exported from them.")
    if "baseline" not in kinds:            # the report's changes are against the baseline
        spec["controllers"] = [{"name": "baseline", "controller": "baseline"}]
    else:
        spec["controllers"] = []
    spec["controllers"] += [{"name": k, "controller": k} for k in kinds]
    for k, ex in libs.items():
        spec["controllers"].append({"name": f"{k}-library", "controller": "discon",
                                    "discon_library": str(ex.library),
                                    "discon_in": str(ex.input_file), "discon_dt": ex.dt})
    spec["report"] = {"title": "The exported libraries beside their Python controllers",
                      "psd_wind": 17, "cs_wind": 17}
    spec["load_cases"] = [
        {**lc, "wind_files": [{**w, "file": str(HERE / "studies" / w["file"])}
                              for w in lc["wind_files"]]} if "wind_files" in lc else lc
        for lc in spec["load_cases"]]
    path = out / "spec.yaml"
    path.write_text(yaml.safe_dump(spec, sort_keys=False))
    return path


def _compare(rep: Path, kinds: list[str]) -> list[str]:
    so = _rows(rep / "signoff.csv")
    aep = {r["controller"]: float(r["change_pct"]) for r in _rows(rep / "aep.csv")}
    travel = {r["controller"]: float(r["pitch_travel_deg_change_pct"])
              for r in _rows(rep / "pitch.csv")}
    life: dict[str, dict[str, float]] = {}
    for r in _rows(rep / "lifetime_del.csv"):
        life.setdefault(r["controller"], {})[r["channel"]] = float(r["lifetime_del"])
    gov: dict[str, dict[str, float]] = {}
    for r in _rows(rep / "governing.csv"):
        gov.setdefault(r["controller"], {})[r["channel"]] = float(r["design"])
    lines = ["| pair | failed | stops | max speed DLC 1.x [x rated] | AEP vs baseline [%] | "
             "pitch travel vs baseline [%] | largest lifetime-DEL change [%] | largest "
             "governing-load change [%] |", "|---" * 8 + "|"]
    for py, lib in ((k, f"{k}-library") for k in kinds):
        cells = []
        for c in (py, lib):
            mine = [r for r in so if r["controller"] == c]
            failed = sum(int(r["failed"]) for r in mine)
            stops = sum(int(r["overspeed_stops"]) for r in mine)
            w = max(float(r["rotor_speed_max_rel"]) for r in mine
                    if r["dlc"].startswith("1.") and r["rotor_speed_max_rel"])
            cells.append((failed, stops, w, aep.get(c, 0.0), travel.get(c, 0.0)))
        dl = max(abs(life[lib][ch] / life[py][ch] - 1) * 100 for ch in life[py])
        dg = max(abs(gov[lib][ch] / gov[py][ch] - 1) * 100 for ch in gov[py])
        (f0, s0, w0, a0, t0), (f1, s1, w1, a1, t1) = cells
        lines.append(f"| {py} / {lib} | {f0} / {f1} | {s0} / {s1} | {w0:.3f} / {w1:.3f} | "
                     f"{a0:+.2f} / {a1:+.2f} | {t0:+.1f} / {t1:+.1f} | {dl:.3f} | {dg:.3f} |")
    return lines


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", help="output directory")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--kinds", nargs="+", default=["baseline", "mpc"],
                    help="the exportable kinds to compare with their libraries")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    spec = _spec(out, args.kinds)
    camp = out / "campaign"
    subprocess.run([sys.executable, "-m", "mpc_wt.cli", "campaign", "run", str(spec), "--out",
                    str(camp), "--workers", str(args.workers), "--report", "--quiet"],
                   check=True)
    table = _compare(camp / "report", args.kinds)
    (out / "comparison.md").write_text("\n".join(table) + "\n")
    print("\n".join(table))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
