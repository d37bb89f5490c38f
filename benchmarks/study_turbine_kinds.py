"""Every controller kind on any OpenFAST deck, judged as a new turbine's kinds must be: the
campaign of ``benchmarks/studies/iea22_kinds.yaml`` (9, 12 and 18 m/s, class IA, seeds 1-2,
300 s after 60 s, every kind and ROSCO with the deck's own ``DISCON.IN``) made for the deck
given, run, and judged by ``benchmarks/study_turbine_table.py`` (whose table it prints). The
rosco wheel's example decks are named by their folder (``--rosco-example BAR_10``); the CW
LIDAR focuses 0.32 rotor diameters ahead (the sign-offs' 90 m on the IEA-15-240-RWT) unless
``--lidar-focus`` says otherwise.

Run:  python benchmarks/study_turbine_kinds.py (--deck FILE.fst | --rosco-example NAME)
                                               --out DIR [--winds 9 12 18] [--seeds 2]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import yaml

import linearize
from mpc_wt.campaign.runner import run_campaign
from mpc_wt.campaign.spec import spec_from_dict

HERE = Path(__file__).resolve().parent
#: the LIDAR's focus ahead of the rotor, in rotor diameters
FOCUS_DIAMETERS = 0.32


def _deck(args: argparse.Namespace) -> Path:
    """The deck's main file."""
    if args.deck:
        return Path(args.deck).resolve()
    import rosco

    folder = Path(rosco.__file__).parents[1] / "Examples" / "Test_Cases" / args.rosco_example
    decks = sorted(folder.glob("*.fst"))
    if len(decks) != 1:
        raise SystemExit(f"--rosco-example: {folder} holds {len(decks)} .fst files, expected 1")
    return decks[0]


def _spec(deck: Path, args: argparse.Namespace) -> dict:
    """The IEA-22 table's spec made for ``deck``."""
    raw = yaml.safe_load((HERE / "studies" / "iea22_kinds.yaml").read_text())
    turbine = linearize.load_turbine(deck)
    discon = sorted(deck.parent.glob("*DISCON*.IN"))
    raw["name"] = f"kinds-{deck.stem}"
    raw["description"] = f"Every controller kind on {turbine.name} ({deck.name})"
    raw["turbine"] = str(deck)
    focus = args.lidar_focus or round(FOCUS_DIAMETERS * 2 * turbine.geometry.tip_radius, 1)
    raw["lidar"] = {"focus_distance": focus, "span_fraction": 0.45}
    raw["load_cases"] = [{"dlc": "1.2", "condition": "ntm", "winds": args.winds,
                          "seeds": args.seeds}]
    ctl = []
    for c in raw["controllers"]:
        if c["controller"] == "rosco":
            if len(discon) != 1:
                continue                      # no (or no single) DISCON.IN beside the deck
            c = {**c, "discon_in": str(discon[0])}
        ctl.append(c)
    raw["controllers"] = ctl
    raw["report"] = {"title": f"Every controller kind on {turbine.name}"}
    return raw


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--deck", help="an OpenFAST deck's .fst file")
    src.add_argument("--rosco-example", help="a folder of the rosco wheel's Test_Cases")
    ap.add_argument("--out", required=True, help="the campaign's directory")
    ap.add_argument("--winds", type=float, nargs="+", default=[9.0, 12.0, 18.0])
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--lidar-focus", type=float, help="the CW LIDAR's focus distance [m]")
    ap.add_argument("--workers", type=int)
    args = ap.parse_args()
    deck = _deck(args)
    raw = _spec(deck, args)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out.parent / f"{out.name}.yaml").write_text(yaml.safe_dump(raw, sort_keys=False))
    spec = spec_from_dict(raw, base=deck.parent, source=str(out.parent / f"{out.name}.yaml"))
    summary = run_campaign(spec, out, workers=args.workers)
    print(summary)
    return subprocess.call([sys.executable, str(HERE / "study_turbine_table.py"), str(out),
                            "--out", str(out / "table.md")])


if __name__ == "__main__":
    sys.exit(main())
