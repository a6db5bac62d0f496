"""Benchmark: a production batch (issue 18).

* 200 units × 10⁵ samples (Parquet: time, a gyro [°/h], a temperature [°C]; a linear model):
  ``thermocal fleet`` with its default workers (one process per CPU) and with one, against the
  one-process library loop that does the same per unit (read the file, fit
  ``make_model("poly", order=1)``, save the model) — the anchor, measured in the same run;
  the ratio fleet/loop (target ≤ 1.5, the default run; the fleet also writes the summary and
  the report, ≈ 1.4 s the loop does not) and the scaling from one worker to the default;
* 20 units × 10⁷ samples with two workers: wall time and the peak resident memory of the
  driver and of its worker processes (``RUSAGE_CHILDREN``: the largest worker).

Run: ``.venv/bin/python benchmarks/bench_fleet.py [--units 200] [--rows 100000] [--skip-big]``.
Files go to ``benchmarks/_data/fleet_*`` (git-ignored).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from _harness import THERMOCAL, measure

DATA = Path(__file__).resolve().parent / "_data"


def write_batch(units: int, rows: int) -> Path:
    """``units`` Parquet files and a configuration; returns the configuration's path."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    folder = DATA / f"fleet_{units}x{rows}"
    cfg = folder / "batch.toml"
    if cfg.exists():
        return cfg
    folder.mkdir(parents=True, exist_ok=True)
    meta = {"format": "thermocal-recording", "version": 1, "time": "time", "time_unit": "s",
            "signals": {"gyro": "deg/h"}, "temperatures": {"T1": "degC"}}  # fmt: skip
    lines = ['[fit]\nmodel = "poly"\norder = 1\nsignal = "gyro"\ntemps = "T1"\n']
    rng = np.random.default_rng(3)
    t = np.arange(rows, dtype=np.float64)
    temp = 25.0 + 30.0 * np.sin(2 * np.pi * t / rows)
    for i in range(units):
        slope = 0.02 + 0.001 * rng.standard_normal()
        gyro = 1.0 + slope * (temp - 25.0) + rng.normal(0.0, 0.01, rows)
        table = pa.table({"time": t, "gyro": gyro, "T1": temp}).replace_schema_metadata(
            {"thermocal": json.dumps(meta)}
        )
        pq.write_table(table, folder / f"u{i:04d}.parquet")
        lines.append(f'[[unit]]\nid = "u{i:04d}"\nmodeling = ["u{i:04d}.parquet"]\n')
    cfg.write_text("\n".join(lines), encoding="utf-8")
    return cfg


def library_loop(cfg: Path, out: Path) -> float:
    """The anchor: one process, per unit read + fit + save, no fleet machinery."""
    code = f"""
import time, tomllib
from pathlib import Path
from threadpoolctl import threadpool_limits
from thermocal.readers.dispatch import read_recording
from thermocal.models.base import RunData
from thermocal.models.registry import make_model
from thermocal.pipeline.model_file import save_model
cfg = Path({str(cfg)!r}); out = Path({str(out)!r}); out.mkdir(parents=True, exist_ok=True)
doc = tomllib.loads(cfg.read_text())
t0 = time.perf_counter()
with threadpool_limits(limits=1):
    for u in doc["unit"]:
        rec = read_recording(cfg.parent / u["modeling"][0])
        model = make_model("poly", order=1).fit([RunData.from_recording(rec, "gyro", ["T1"])])
        save_model(model, out / (u["id"] + ".json"))
print(time.perf_counter() - t0)
"""
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return float(res.stdout.split()[-1])


def fleet(cfg: Path, out: Path, workers: int | None) -> tuple[float, float]:
    """(wall seconds, peak MB of the largest process) of ``thermocal fleet`` (``workers``
    None: the default, one worker process per CPU)."""
    shutil.rmtree(out, ignore_errors=True)
    cmd = [*THERMOCAL, "fleet", str(cfg), "-o", str(out)]
    if workers is not None:
        cmd += ["--workers", str(workers)]
    return measure(cmd)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--units", type=int, default=200)
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--skip-big", action="store_true", help="skip 20 units × 10⁷ samples")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores")
    cfg = write_batch(args.units, args.rows)
    t_loop = library_loop(cfg, DATA / "fleet_loop_out")
    t1, mb1 = fleet(cfg, DATA / "fleet_out_1", 1)
    t2, mb2 = fleet(cfg, DATA / "fleet_out_2", None)
    print(f"{args.units} units x {args.rows} samples:")
    print(f"  library loop, one process           {t_loop:7.2f} s")
    print(f"  thermocal fleet --workers 1         {t1:7.2f} s  ({t1 / t_loop:.2f}x the loop; "
          f"peak {mb1:.0f} MB)")  # fmt: skip
    print(f"  thermocal fleet (default: {os.cpu_count()} workers) {t2:7.2f} s  "
          f"({t2 / t_loop:.2f}x the loop; {t1 / t2:.2f}x faster than 1 worker; "
          f"peak {mb2:.0f} MB)")  # fmt: skip
    ok = t2 / t_loop <= 1.5
    print(f"  target (fleet, default workers, within 1.5x the library loop): "
          f"{'met' if ok else 'NOT met'}")  # fmt: skip
    if not args.skip_big:
        big = write_batch(20, 10_000_000)
        t_big, mb_big = fleet(big, DATA / "fleet_out_big", 2)
        gb = 20 * 10_000_000 * 3 * 8 / 1e9
        print(f"20 units x 1e7 samples, 2 workers: {t_big:.1f} s, peak {mb_big:.0f} MB per "
              f"process ({gb:.1f} GB of data in all)")  # fmt: skip
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
