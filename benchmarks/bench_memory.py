"""Benchmark: peak memory of whole commands against the length of the file (issue 14).

For each size (rows) a Parquet recording is written once (time [s], a gyro [°/h] and one
temperature [°C], units in the file's metadata), a linear model is fitted on a 10⁵-row
slice, then ``compensate``, ``allan``, ``metrics`` and ``inspect`` run as separate
``thermocal`` processes; each one's peak resident memory is read with
``resource.getrusage(RUSAGE_CHILDREN)`` (the largest child so far, so each command runs
in its own ``python -c`` wrapper).  Printed: MB and bytes per row, and the figure the
issue asks for (≈ 8 bytes per column used + 16 bytes a row of working space + a fixed
base for allan, metrics and inspect; constant for compensate).

Run: ``.venv/bin/python benchmarks/bench_memory.py [--rows 1000000 10000000 20000000]``.
Files go to ``benchmarks/_data/`` (git-ignored).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "_data"

WRAPPER = r"""
import resource, subprocess, sys, time
t0 = time.perf_counter()
proc = subprocess.run(sys.argv[1:], capture_output=True, text=True)
dt = time.perf_counter() - t0
peak_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
print(f"{proc.returncode} {peak_kb} {dt:.3f}")
if proc.returncode:
    print(proc.stderr[-2000:], file=sys.stderr)
"""


def _write(rows: int) -> Path:
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = DATA / f"mem_{rows}.parquet"
    if path.exists():
        return path
    DATA.mkdir(exist_ok=True)
    rng = np.random.default_rng(1)
    t = np.arange(rows, dtype=np.float64) * 0.01
    temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / max(t[-1], 1.0))
    gyro = 0.5 + 0.02 * (temp - 25.0) + rng.normal(0.0, 0.05, rows)
    meta = {
        "format": "thermocal-recording",
        "version": 1,
        "time": "time",
        "time_unit": "s",
        "signals": {"gyro": "deg/h"},
        "temperatures": {"T1": "degC"},
    }
    table = pa.table({"time": t, "gyro": gyro, "T1": temp}).replace_schema_metadata(
        {"thermocal": json.dumps(meta)}
    )
    pq.write_table(table, path)
    return path


def _run(args: list[str]) -> tuple[int, float, float]:
    thermocal = [
        sys.executable,
        "-c",
        "import sys; from thermocal.cli import main; sys.exit(main())",
    ]
    out = subprocess.run(
        [sys.executable, "-c", WRAPPER, *thermocal, *args],
        capture_output=True,
        text=True,
        check=False,
    )
    code, peak_kb, seconds = out.stdout.split()
    if int(code) != 0:
        raise SystemExit(f"{args[0]} failed: {out.stderr}")
    return int(code), int(peak_kb) * 1024 / 1e6, float(seconds)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", type=int, nargs="+", default=[1_000_000, 10_000_000])
    args = ap.parse_args()
    print("rows        command     peak MB   bytes/row   seconds")
    for rows in args.rows:
        src = _write(rows)
        small = DATA / "mem_fit.parquet"
        if not small.exists():
            _write(100_000).rename(small)
        model = DATA / "mem_model.json"
        if not model.exists():
            _run(["fit", str(small), "--model", "poly", "--order", "1", "--signal", "gyro",
                  "--temps", "T1", "-o", str(model)])  # fmt: skip
        out = DATA / f"mem_out_{rows}.parquet"
        commands = {
            "compensate": ["compensate", str(model), str(src), "-o", str(out)],
            "allan": ["allan", str(src), "--signal", "gyro", "--json"],
            "metrics": ["metrics", str(src), "--signal", "gyro", "--temps", "T1",
                        "--average", "10", "--json"],
            "inspect": ["inspect", str(src), "--json"],
        }  # fmt: skip
        for name, cmd in commands.items():
            _code, mb, seconds = _run(cmd)
            print(f"{rows:<11d} {name:<11s} {mb:8.0f}   {mb * 1e6 / rows:9.0f}   {seconds:7.1f}")
        out.unlink(missing_ok=True)
        time.sleep(0.5)


if __name__ == "__main__":
    main()
