"""Benchmark: read a 10⁷-row Parquet recording (100 Hz × 28 h, one signal, four temperatures).

Target (issue 2): < 3 s and peak memory < 3× the data's size.

Run: ``.venv/bin/python benchmarks/bench_io.py [--rows N]``.  The file is written to
``benchmarks/_data/`` (git-ignored); the read is timed in a fresh child process whose
peak resident memory above its baseline (after imports) is measured with
``resource.getrusage``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

CHILD = r"""
import json, resource, sys, time
import numpy as np
import thermocal.readers as tio
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0 = time.perf_counter()
rec = tio.read_recording(sys.argv[1])
dt = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
data_bytes = rec.time_s.nbytes + sum(v.nbytes for v in rec.columns.values())
print(json.dumps({"seconds": dt, "peak_above_baseline_bytes": (peak - base) * 1024,
                  "data_bytes": data_bytes, "n": rec.n_samples,
                  "check": float(np.mean(rec.columns["T1"]))}))
"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", type=int, default=100 * 3600 * 28)
    args = ap.parse_args()
    out_dir = Path(__file__).parent / "_data"
    path = out_dir / f"read_{args.rows}.parquet"
    if not path.exists():
        from thermocal.recording import Recording
        from thermocal.writers import write_recording

        rng = np.random.default_rng(0)
        n = args.rows
        t = np.arange(n) * 0.01
        temps = {
            f"T{k}": 20 + 30 * np.sin(t / 7200 + k) + rng.normal(0, 0.01, n) for k in range(1, 5)
        }
        rec = Recording.from_arrays(t, {"gyro": rng.normal(0, 0.01, n)}, temps)
        t0 = time.perf_counter()
        write_recording(rec, path)
        print(f"wrote {path} in {time.perf_counter() - t0:.1f} s")
    res = json.loads(
        subprocess.run(
            [sys.executable, "-c", CHILD, str(path)], check=True, capture_output=True, text=True
        ).stdout
    )
    ratio = res["peak_above_baseline_bytes"] / res["data_bytes"]
    print(
        f"read {res['n']:,} rows × 6 columns ({res['data_bytes'] / 1e6:.0f} MB) in "
        f"{res['seconds']:.2f} s (target < 3 s); peak memory above baseline "
        f"{res['peak_above_baseline_bytes'] / 1e6:.0f} MB = {ratio:.2f}× the data (target < 3×)"
    )


if __name__ == "__main__":
    main()
