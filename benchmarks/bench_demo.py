"""Time ``thermocal demo`` (issue 7: must stay under 60 s on the 2-core machine).

Prints the duration of each step of :func:`thermocal.demo.chamber.run_demo` (default,
full-size data: 1 Hz, ~17.5 h modelling + ~11 h validation run), the total, and
the wall-clock time of the ``thermocal demo`` command (process start-up and
imports included), best of ``--repeat`` runs.

    .venv/bin/python benchmarks/bench_demo.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from thermocal.demo.chamber import run_demo


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    best: dict[str, float] = {}
    totals = []
    for i in range(args.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            res = run_demo(Path(tmp) / "demo")
            totals.append(res.elapsed_s)
            for k, v in res.timings_s.items():
                best[k] = min(best.get(k, float("inf")), v)
            if i == 0:
                size = sum(p.stat().st_size for p in res.files) / 1e6
                n_files = len(res.files)
    print("run_demo (library), best of", args.repeat)
    for k, v in best.items():
        print(f"  {k:<48s} {v:7.2f} s")
    print(f"  {'total (best / worst)':<48s} {min(totals):7.2f} s / {max(totals):.2f} s")
    print(f"  files written: {n_files}, {size:.1f} MB")
    walls = []
    exe = Path(sys.executable).with_name("thermocal")
    for _ in range(args.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            subprocess.run([str(exe), "demo", "-o", str(Path(tmp) / "d")], check=True,
                           capture_output=True)  # fmt: skip
            walls.append(time.perf_counter() - t0)
    print(f"thermocal demo (command, wall clock): best {min(walls):.2f} s, "
          f"worst {max(walls):.2f} s; budget 60 s")  # fmt: skip


if __name__ == "__main__":
    main()
