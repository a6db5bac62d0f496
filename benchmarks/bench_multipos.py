"""Benchmark: multi-position calibration of a 10-minute, 100 Hz hand-placed session
(issue 30): poses found, accelerometer and gyro triads (target < 2 s).

Run:  .venv/bin/python benchmarks/bench_multipos.py
Prints the session length, the wall time of calibrate_session() (best of 3) and the
largest |error/σ| of the twelve parameters of each triad.
"""

from __future__ import annotations

import math
import time

import numpy as np

from thermocal.multipos.calibrate import calibrate_session
from thermocal.multipos.simulate import random_truth, simulate_session

MG = 9.80665e-3


def main() -> None:
    rng = np.random.default_rng(0)
    t0_, _t1 = random_truth(rng)
    t0 = time.perf_counter()
    s = simulate_session(rng, t0_.accel, t0_.gyro, n_poses=86)  # ≈ 10 min at 5 s + 2 s
    t_sim = time.perf_counter() - t0
    n = s["time_s"].size
    best, res = math.inf, None
    for _ in range(3):
        t0 = time.perf_counter()
        res = calibrate_session(s["time_s"], s["accel_mg"], s["gyro_deg_s"] * math.pi / 180,
                                g_mg=s["g_m_s2"] / MG, latitude_deg=45.0)  # fmt: skip
        best = min(best, time.perf_counter() - t0)
    assert res is not None and res.gyro is not None
    sa = res.accel.sigma
    za = np.abs((res.accel.theta - t0_.accel)[sa > 0] / sa[sa > 0])
    zg = np.abs((res.gyro.theta - t0_.gyro) / res.gyro.sigma)
    print(f"samples: {n}  duration: {s['time_s'][-1] / 60:.1f} min  rate: 100 Hz  "
          f"poses: {len(res.poses)} of {len(s['poses'])}")  # fmt: skip
    print(f"simulate: {t_sim:.2f} s")
    print(f"calibrate (best of 3): {best:.2f} s   target < 2 s: {'OK' if best < 2 else 'FAIL'}")
    print(f"max |error/σ|: accel {za.max():.2f}, gyro {zg.max():.2f}")


if __name__ == "__main__":
    main()
