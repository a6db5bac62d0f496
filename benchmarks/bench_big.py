"""Records of a billion samples: ``thermocal allan`` on a long FOG-like record (1 kHz, time
and rate as float64 Parquet, written row group by row group: never the whole array in
memory), window by window (``--stream``) beside the in-memory path where it fits.

Prints wall time, samples/s and peak resident memory of each run (whole processes,
``_harness.measure``), interleaved (streamed, in memory, streamed, …), best of N, with
the load average at start and end, and whether the two paths print the same JSON.

    python benchmarks/bench_big.py                  # 1e8 rows, streamed and in memory
    python benchmarks/bench_big.py --rows 1e7 --repeat 3
    python benchmarks/bench_big.py --rows 1e9 --repeat 1 --no-memory   # streamed only
    python benchmarks/bench_big.py --quick          # 1e6 rows (a minute)

The record is written once to ``--dir`` (default /work/big, else $TMPDIR) and kept for
a re-run (``--keep``) or removed at the end.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _harness import THERMOCAL, measure

ROW_GROUP = 1 << 22
"""Rows per row group written (4 Mi: 64 MiB of the two columns)."""


def write_record(path: Path, rows: int, seed: int = 0) -> None:
    """A 1 kHz FOG-like rate record: white rate noise (ARW), a bias random walk (RRW) and a
    slow bias wander, written row group by row group (the memory of one group)."""
    schema = pa.schema([("time", pa.float64()), ("rate", pa.float64())])
    rng = np.random.default_rng(seed)
    walk = 0.0
    tmp = path.with_name(path.name + ".part")
    with pq.ParquetWriter(tmp, schema, compression="snappy") as w:
        for a in range(0, rows, ROW_GROUP):
            b = min(a + ROW_GROUP, rows)
            i = np.arange(a, b, dtype=np.float64)
            steps = rng.normal(0.0, 2e-4, b - a)
            rw = walk + np.cumsum(steps)
            walk = float(rw[-1])
            rate = 0.5 + rng.normal(0.0, 0.05, b - a) + rw  # [deg/h]
            w.write_table(pa.table({"time": i * 1e-3, "rate": rate}, schema=schema))
            print(f"\r  written {b:,} of {rows:,} rows", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    tmp.rename(path)


def load() -> str:
    return "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def _args(command: str, path: Path, stream: bool) -> list[str]:
    cmd = [*THERMOCAL, command, str(path), "--signal", "rate", "--signal-unit", "deg/h",
           "--time-unit", "s", "--json"]  # fmt: skip
    if command == "metrics":
        cmd += ["--average", "1"]
    return [*cmd, "--stream"] if stream else cmd


def largest_difference(command: str, path: Path) -> float:
    """The largest relative difference between the numbers of the streamed and the
    in-memory runs' JSON (0.0: the same digits)."""
    outs = [
        json.loads(
            subprocess.run(
                _args(command, path, s), capture_output=True, text=True, check=True
            ).stdout
        )
        for s in (True, False)
    ]
    worst = 0.0

    def walk(a: object, b: object) -> None:
        nonlocal worst
        if isinstance(a, dict) and isinstance(b, dict):
            for k in a:
                walk(a[k], b[k])
        elif isinstance(a, list) and isinstance(b, list):
            for x, y in zip(a, b, strict=True):
                walk(x, y)
        elif isinstance(a, float) and isinstance(b, float) and a != b:
            worst = max(worst, abs(a - b) / max(abs(a), abs(b)))
        elif a != b:
            worst = math.inf

    walk(*outs)
    return worst


def run(command: str, path: Path, rows: int, repeat: int, streamed_only: bool) -> None:
    """One command streamed and in memory, interleaved, best of ``repeat``."""
    print(f"{command}: rows {rows:.0e}; load at start {load()}")
    best: dict[str, tuple[float, float]] = {}
    kinds = ["streamed"] if streamed_only else ["streamed", "in memory"]
    for _ in range(repeat):
        for kind in kinds:  # interleaved
            sec, mb = measure(_args(command, path, kind == "streamed"))
            print(f"  {kind:10s} {sec:8.1f} s  {rows / sec:12.3g} samples/s  peak {mb:8.0f} MB")
            if kind not in best or sec < best[kind][0]:
                best[kind] = (sec, mb)
    print(f"load at end {load()}")
    for kind, (sec, mb) in best.items():
        print(f"best {kind:10s} {sec:8.1f} s  {rows / sec:12.3g} samples/s  peak {mb:8.0f} MB")
    if len(best) == 2:
        (s_sec, s_mb), (m_sec, m_mb) = best["streamed"], best["in memory"]
        print(f"ratio streamed / in memory: time {s_sec / m_sec:.2f}×, memory {s_mb / m_mb:.2f}×")
        worst = largest_difference(command, path)
        print(f"largest relative difference of the JSON numbers: {worst:.3g}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=float, default=1e8)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--dir", default="/work/big" if Path("/work/big").is_dir() else None)
    ap.add_argument("--quick", action="store_true", help="1e6 rows")
    ap.add_argument("--no-memory", action="store_true", help="the streamed path only")
    ap.add_argument("--keep", action="store_true", help="keep the record written")
    ap.add_argument("--commands", default="allan,metrics", help="allan, metrics or both")
    a = ap.parse_args()
    rows = int(1e6 if a.quick else a.rows)
    folder = Path(a.dir or tempfile.gettempdir())
    path = folder / f"fog_{rows:.0e}.parquet".replace("+", "")
    if not path.exists():
        t0 = time.perf_counter()
        write_record(path, rows)
        print(f"wrote {path} ({path.stat().st_size / 2**30:.2f} GiB) in "
              f"{time.perf_counter() - t0:.0f} s")  # fmt: skip
    for command in a.commands.split(","):
        run(command, path, rows, a.repeat, a.no_memory)
    if not a.keep:
        path.unlink()


if __name__ == "__main__":
    main()
