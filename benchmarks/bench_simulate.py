"""Benchmark: simulate 28 h of a ring-laser gyro at 100 Hz (≈ 10⁷ samples, four temperatures).

Target (issue 3): < 10 s and peak memory < 2 GB.  Prints the wall time of the
simulation (thermal network + sensor + pulse output + Recording), the peak resident
memory of the process, and, separately, the time to write the result as Parquet.

    .venv/bin/python benchmarks/bench_simulate.py [--hours 28] [--rate-hz 100] [--write]
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from thermocal.profiles import builtin_profile
from thermocal.simulate import run_scenario
from thermocal.writers import write_recording


def peak_rss_mb() -> float:
    """Peak resident set size of this process [MB] (Linux ru_maxrss is in kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--hours", type=float, default=28.0)
    ap.add_argument("--rate-hz", type=float, default=100.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--write", action="store_true", help="also time writing Parquet")
    args = ap.parse_args(argv)

    # the modelling profile cut to the requested length
    t, c = builtin_profile("rlg-modelling").program(60.0)
    end = args.hours * 3600.0
    keep = t < end
    t_prog = np.append(t[keep], end)
    c_prog = np.append(c[keep], np.interp(end, t, c))

    base_rss = peak_rss_mb()
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    rec, _truth = run_scenario("rlg-modelling", args.seed, (t_prog, c_prog), rate_hz=args.rate_hz)[
        0
    ]
    elapsed = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    cpu_user = r1.ru_utime - r0.ru_utime
    cpu_sys = r1.ru_stime - r0.ru_stime
    rss = peak_rss_mb()
    load1 = os.getloadavg()[0]
    n = rec.n_samples
    print(f"samples            {n:,d} ({args.hours:g} h at {args.rate_hz:g} Hz)")
    print(f"temperatures       {len(rec.temperatures)}")
    print(f"columns            {len(rec.columns)}")
    print(f"simulate time      {elapsed:.2f} s  (target < 10 s; ratio {elapsed / 10.0:.2f})")
    print(f"cpu time           {cpu_user + cpu_sys:.2f} s (user {cpu_user:.2f}, sys {cpu_sys:.2f})")
    print(f"load average (1 m) {load1:.2f} on {os.cpu_count()} CPUs")
    print(f"throughput         {n / elapsed / 1e6:.2f} M samples/s")
    print(f"peak RSS           {rss:.0f} MB (before: {base_rss:.0f} MB; target < 2048 MB)")
    if args.write:
        with tempfile.TemporaryDirectory() as d:
            t1 = time.perf_counter()
            p = write_recording(rec, Path(d) / "rlg.parquet")
            wt = time.perf_counter() - t1
            print(f"parquet write      {wt:.2f} s, {p.stat().st_size / 1e6:.0f} MB")
            print(f"peak RSS (write)   {peak_rss_mb():.0f} MB")
    ok = elapsed < 10.0 and rss < 2048.0
    print("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
