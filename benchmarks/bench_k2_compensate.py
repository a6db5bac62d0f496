"""Cost of K2 in ``compensate``: one accelerometer triad (constant parameters, unit m/s²)
with and without ``k2``, compensated side by side in one run on the same Parquet file of
2·10⁶ samples (chunks of 500 k rows), best of 3 of each, wall and CPU time.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_k2_compensate.py [ROWS]``; prints
one line per variant and the CPU ratio.
"""

from __future__ import annotations

import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from thermocal.models.calibration import Calibration, Triad
from thermocal.pipeline.compensate import compensate_calibration_file
from thermocal.pipeline.model_file import save_calibration
from thermocal.turntable.thermal import constant_triad

COLS = ("ax", "ay", "az")


def main() -> None:
    warnings.simplefilter("ignore")
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2_000_000
    theta = np.array([36.0, -18.0, 7.2, 100.0, -50.0, 20.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    model = constant_triad("accel", 25.0, theta, np.eye(12), method="multipos")
    rng = np.random.default_rng(1)
    x = rng.normal(0.0, 9.80665, (n, 3))
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        pd.DataFrame({"time": np.arange(n) * 0.01, **{c: x[:, i] for i, c in enumerate(COLS)}}
                     ).to_parquet(d / "in.parquet")  # fmt: skip
        cpu = {}
        for label, k2 in (("linear", None), ("K2", np.array([0.05, -0.04, 0.03]))):
            cal = Calibration([], [Triad("accel", COLS, "m/s^2", "", model, k2=k2)])
            save_calibration(cal, d / f"{label}.json")
            best_w, best_c = float("inf"), float("inf")
            for _ in range(3):
                out = d / f"{label}.parquet"
                out.unlink(missing_ok=True)
                w0, c0 = time.perf_counter(), time.process_time()
                compensate_calibration_file(d / f"{label}.json", d / "in.parquet", out,
                                            chunk_rows=500_000)  # fmt: skip
                best_w = min(best_w, time.perf_counter() - w0)
                best_c = min(best_c, time.process_time() - c0)
            cpu[label] = best_c
            print(f"{label:7s} wall {best_w:.2f} s  CPU {best_c:.2f} s  ({n} rows)")
    print(f"CPU ratio K2/linear {cpu['K2'] / cpu['linear']:.2f}")


if __name__ == "__main__":
    main()
