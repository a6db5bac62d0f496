"""One driver for every figure of ``benchmarks/RESULTS.md`` (issue 17).

Runs each benchmark script in turn, in this interpreter's environment, one after the other
(never two at once: they time the same two cores), each printing its figures next to the
anchor it is compared with, measured in the same run.  The output of every script is shown
as it comes and kept in ``benchmarks/_data/run-<UTC time>.log``; at the end one table says,
per script, how long it took, whether it exited cleanly, and each ``target`` line it
printed (``met`` / ``NOT met``).  The exit status is 1 when a script failed or a target was
not met, so a scheduled run can flag it.

Run::

    .venv/bin/python benchmarks/run.py              # everything (≈ 40 min, 10 GB of files)
    .venv/bin/python benchmarks/run.py --quick      # the 10⁷-row figures only (≈ 10 min)
    .venv/bin/python benchmarks/run.py allan fit    # the named ones

The mutation check (``benchmarks/mutation_check.py``) is not a benchmark and is run on its
own.
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import re
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
DATA = HERE / "_data"

BENCHMARKS: dict[str, tuple[list[str], list[str]]] = {
    # name: (arguments of a full run, arguments of a --quick run)
    "io": ([], []),
    "allan": ([], ["--skip-1e8"]),
    "fit": (["--no-tracemalloc"], ["--no-tracemalloc"]),
    "channels": ([], ["--skip-file"]),
    "compensate": ([], []),
    "end_to_end": ([], ["--skip-1e8"]),
    "memory": (
        ["--rows", "10000000", "20000000", "--temps", "1", "4"],
        ["--rows", "10000000", "--temps", "1"],
    ),
    "simulate": ([], ["--hours", "2.8"]),
    "turntable": ([], []),
    "models_warmup_bank": ([], []),
    "demo": (["--repeat", "3"], ["--repeat", "1"]),
    "fleet": ([], ["--skip-big"]),
    "turntable_thermal": ([], []),
    "multipos": ([], []),
    "stability": ([], ["--repeat", "1"]),
}
"""Every benchmark script (``bench_<name>.py``) and the RESULTS.md section it feeds."""

TARGET = re.compile(r"target|NOT met|\bmet\b|\bFAIL\b|\bPASS\b", re.IGNORECASE)
MISSED = re.compile(r"NOT met|\bFAIL\b")


def run_one(name: str, args: list[str], log: object) -> tuple[int, float, list[str]]:
    """Run ``bench_<name>.py``; echo and log its output; return (status, seconds, target
    lines)."""
    cmd = [sys.executable, str(HERE / f"bench_{name}.py"), *args]
    header = f"\n=== {name}: {' '.join(cmd[1:])} (load average {os.getloadavg()[0]:.2f})"
    print(header, flush=True)
    print(header, file=log, flush=True)  # type: ignore[call-overload]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    targets: list[str] = []
    assert proc.stdout is not None
    for line in proc.stdout:
        sys.stdout.write(line)
        sys.stdout.flush()
        log.write(line)  # type: ignore[attr-defined]
        if TARGET.search(line):
            targets.append(line.strip())
    status = proc.wait()
    return status, time.perf_counter() - t0, targets


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("names", nargs="*", help=f"benchmarks to run (default all): {list(BENCHMARKS)}")
    ap.add_argument("--quick", action="store_true", help="skip the 10⁸-row and longest runs")
    opts = ap.parse_args()
    unknown = [n for n in opts.names if n not in BENCHMARKS]
    if unknown:
        ap.error(f"unknown benchmark(s) {unknown}; known: {list(BENCHMARKS)}")
    names = opts.names or list(BENCHMARKS)
    DATA.mkdir(exist_ok=True)
    stamp = dt.datetime.now(dt.UTC).strftime("%Y%m%dT%H%M%SZ")
    log_path = DATA / f"run-{stamp}.log"
    summary: list[tuple[str, int, float, list[str]]] = []
    with open(log_path, "w", encoding="utf-8") as log:
        python = sys.version.split()[0]
        print(f"thermocal benchmarks {stamp}: {os.cpu_count()} cores, python {python}", file=log)
        for name in names:
            full, quick = BENCHMARKS[name]
            status, seconds, targets = run_one(name, quick if opts.quick else full, log)
            summary.append((name, status, seconds, targets))
    print(f"\n=== summary (log: {log_path})")
    bad = 0
    for name, status, seconds, targets in summary:
        state = "ok" if status == 0 else f"exit {status}"
        print(f"{name:<20s} {seconds:7.1f} s  {state}")
        for t in targets:
            print(f"    {t}")
        missed = any(MISSED.search(t) for t in targets)
        bad += int(status != 0 or missed)
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
