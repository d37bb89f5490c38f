"""OpenFAST I/O speed: deck loading, .outb/.out and .lin reading, each beside
openfast-io (a dependency of the rosco package) doing the same job in the same run.

Run:  python benchmarks/bench_openfast_io.py [--json]

Prints best-of-5 wall times (after one warm-up): ``load_openfast`` of the four decks of the
rosco wheel (floor: under 2 s each) against openfast-io's ``InputReader_OpenFAST`` reading the
same modules (main, ElastoDyn with blade and tower, AeroDyn with blade and polars, ServoDyn,
DISCON); a 600 s, 40-channel, 80 Hz binary output (FileFmtID 2, as OpenFAST writes) and its text
twin against openfast-io's ``FASTOutputFile``; a 106-state OpenFAST .lin file and the MBC3 of its
12-azimuth set against openfast-io's ``FASTLinearizationFile``.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
import timeit
from pathlib import Path

import numpy as np
import rosco

from linearize import load_openfast, read_lin, read_lin_set
from mpc_wt.io.openfast_output import read_openfast_output, write_openfast_output

CASES = Path(rosco.__file__).parents[1] / "Examples" / "Test_Cases"
DECKS = {"NREL-5MW": "NREL-5MW/NREL-5MW.fst",
         "IEA-15-240-RWT": "IEA-15-240-RWT/IEA-15-240-RWT-Monopile/IEA-15-240-RWT-Monopile.fst",
         "BAR_10": "BAR_10/BAR_10.fst", "NREL-2.8-127": "NREL_2p8_127/NREL-2p8-127.fst"}
LIN = CASES / "IEA-15-240-RWT" / "IEA-15-240-RWT-UMaineSemi" / "linearizations"


def _best(fn, repeat: int = 5) -> float:
    """Best of ``repeat`` single calls after a warm-up [s]."""
    fn()
    return min(timeit.repeat(fn, number=1, repeat=repeat))


def _peer_deck(fst: Path) -> None:
    import contextlib
    import io

    from openfast_io.FAST_reader import InputReader_OpenFAST

    with contextlib.redirect_stdout(io.StringIO()):
        r = InputReader_OpenFAST()
        r.FAST_InputFile = fst.name
        r.FAST_directory = str(fst.parent)
        r.read_MainInput()
        ed = os.path.join(r.FAST_directory, r.fst_vt["Fst"]["EDFile"])
        r.read_ElastoDyn(ed)
        r.read_ElastoDynBlade(os.path.join(os.path.dirname(ed), r.fst_vt["ElastoDyn"]["BldFile1"]))
        r.read_ElastoDynTower(os.path.join(os.path.dirname(ed), r.fst_vt["ElastoDyn"]["TwrFile"]))
        r.read_AeroDyn()
        r.read_ServoDyn()
        r.read_DISCON_in()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    from openfast_io.FAST_linearization_reader import FASTLinearizationFile
    from openfast_io.FAST_output_reader import FASTOutputFile

    res: dict = {"date": time.strftime("%Y-%m-%d %H:%M"), "machine": platform.machine(),
                 "python": platform.python_version(), "decks": {}}
    for name, rel in DECKS.items():
        fst = CASES / rel
        ours = _best(lambda: load_openfast(fst))
        try:
            peer = _best(lambda: _peer_deck(fst))
        except Exception as err:                     # the peer's own limits, reported
            peer = f"failed: {type(err).__name__}: {str(err)[:60]}"
        res["decks"][name] = {"mpc_wt_s": ours, "openfast_io_s": peer,
                              "ratio": peer / ours if isinstance(peer, float) else None}
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 600.0, 1 / 80)
    ch = {f"Ch{k:02d}": np.cumsum(rng.standard_normal(t.size)) for k in range(40)}
    with tempfile.TemporaryDirectory() as d:
        outb = write_openfast_output(Path(d) / "run.outb", t, ch, binary_format=2)
        out = write_openfast_output(Path(d) / "run.out", t, ch)
        for key, p in (("outb_600s_40ch", outb), ("out_600s_40ch", out)):
            ours = _best(lambda: read_openfast_output(p), 3)
            peer = _best(lambda: FASTOutputFile(str(p)), 3)
            res[key] = {"mpc_wt_s": ours, "openfast_io_s": peer, "ratio": peer / ours,
                        "bytes": p.stat().st_size}
    one = LIN / "lin_12.7.lin"
    files = sorted(LIN.glob("lin_12.*.lin"))
    ours = _best(lambda: read_lin(one))
    peer = _best(lambda: FASTLinearizationFile(str(one)))
    res["lin_106_states"] = {"mpc_wt_s": ours, "openfast_io_s": peer, "ratio": peer / ours}
    res["lin_set_12_mbc3_s"] = _best(lambda: read_lin_set(files), 3)
    if args.json:
        print(json.dumps(res, indent=1))
        return 0
    print(f"# {res['date']} {res['machine']} Python {res['python']}")
    for name, d in res["decks"].items():
        peer = d["openfast_io_s"]
        ptxt = f"{peer * 1e3:8.1f} ms  ratio {d['ratio']:.1f}" if isinstance(peer, float) else peer
        print(f"deck {name:16s} mpc-wt {d['mpc_wt_s'] * 1e3:8.1f} ms   openfast-io {ptxt}")
    for key in ("outb_600s_40ch", "out_600s_40ch", "lin_106_states"):
        d = res[key]
        print(f"{key:22s} mpc-wt {d['mpc_wt_s'] * 1e3:8.1f} ms   openfast-io "
              f"{d['openfast_io_s'] * 1e3:8.1f} ms  ratio {d['ratio']:.1f}")
    print(f"lin set, 12 azimuths, MBC3 + average: {res['lin_set_12_mbc3_s'] * 1e3:.1f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
