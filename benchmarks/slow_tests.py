"""The suite's long studies: the tests marked ``slow``, which the README's test command leaves
out to keep the suite within 10 minutes on 2 cores.

Run:  python benchmarks/slow_tests.py [extra pytest arguments]

Runs ``python -m pytest -m slow`` on both cores and prints each test's outcome and time, the
total, the date and the machine; exits with pytest's status.
"""
from __future__ import annotations

import datetime
import platform
import re
import subprocess
import sys
import time
from pathlib import Path


def main(argv: list[str]) -> int:
    """Run the slow tests; print their times.

    Parameters
    ----------
    argv : list of str
        Extra pytest arguments.

    Returns
    -------
    int
        pytest's exit status.
    """
    root = Path(__file__).resolve().parents[1]
    cmd = [sys.executable, "-m", "pytest", "-m", "slow", "-q", "-rA", "--durations=0",
           "-p", "no:cacheprovider", *argv]
    print("$", " ".join(cmd[1:]), flush=True)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=root, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    out = proc.stdout
    times = re.findall(r"^([0-9.]+)s call\s+(\S+)$", out, re.M)
    status = {t: s for s, t in re.findall(r"^(PASSED|FAILED|ERROR|SKIPPED|XFAIL|XPASS) (\S+)",
                                          out, re.M)}
    print(f"\n{'test':<100} {'outcome':>8} {'time [s]':>9}")
    for sec, name in times:
        print(f"{name:<100} {status.get(name, '?'):>8} {float(sec):9.1f}")
    print(out.strip().splitlines()[-1] if out.strip() else proc.stderr[-2000:])
    print(f"wall {wall:.0f} s; {datetime.date.today()}; {platform.node()} "
          f"({platform.processor() or platform.machine()})")
    return proc.returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
