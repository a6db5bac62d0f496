"""Benchmark: peak memory of ``compensate --chamber-log`` against the length of the file
(issue 44, item 5).

``compensate`` streams its file; with a chamber log it first joins the log once for the
whole recording, then gives each chunk the log's temperature at its own times.  The join
holds the recording's first and last times when the offset is given (``given``: constant
memory) and its time and own temperature when the clocks are found by correlation
(``correlation``: 16 B a row of data).  For each size a Parquet recording (time [s] at
100 Hz, ``gyro`` [°/h], ``T1`` [°C]) and a chamber log (hh:mm:ss every 10 s, °C) are written
once; the model (``--temps T1,chamber``; ``T1`` alone for the run without a log, the
chunked pass's own figure) is fitted on the smallest.  The figure, as
:mod:`bench_memory`'s::

    bytes per row = (peak RSS on the N-row file − peak RSS on the 10 000-row file) / N

Target: ≤ 40 B/row (:data:`bench_memory.TARGET_B_PER_ROW`).

Run: ``.venv/bin/python benchmarks/bench_compensate_chamber.py [--rows 2000000]``.
Files go to ``benchmarks/_data/`` (git-ignored).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from _harness import THERMOCAL, measure

DATA = Path(__file__).parent / "_data"
BASE_ROWS = 10_000
TARGET_B_PER_ROW = 40.0


def air_c(t: np.ndarray, span: float) -> np.ndarray:
    """The chamber air [°C] at recording time ``t`` [s] (one slow cycle over the span)."""
    return 25.0 + 15.0 * np.sin(2 * np.pi * t / span)


def write_files(rows: int) -> tuple[Path, Path]:
    """The recording (in slices: bounded memory) and its chamber log."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rec = DATA / f"chamber_{rows}.parquet"
    log = DATA / f"chamber_{rows}_log.csv"
    span = max((rows - 1) * 0.01, 1.0)
    if not log.exists():
        DATA.mkdir(exist_ok=True)
        lines = ["Time,Air [°C]"]
        for tau in np.arange(0.0, span + 20.0, 10.0):
            s = int(tau)
            lines.append(f"{s // 3600:02d}:{s % 3600 // 60:02d}:{s % 60:02d},"
                         f"{float(air_c(np.array([tau]), span)[0]):.3f}")  # fmt: skip
        log.write_text("\n".join(lines) + "\n", encoding="utf-8")
    if rec.exists():
        return rec, log
    meta = {"format": "thermocal-recording", "version": 1, "time": "time", "time_unit": "s",
            "signals": {"gyro": "deg/h"}, "temperatures": {"T1": "degC"}}  # fmt: skip
    schema = pa.schema([(c, pa.float64()) for c in ("time", "gyro", "T1")]).with_metadata(
        {"thermocal": json.dumps(meta)}
    )
    rng = np.random.default_rng(1)
    tmp = rec.with_suffix(".tmp")
    with pq.ParquetWriter(tmp, schema) as w:
        for a in range(0, rows, 1 << 20):
            t = np.arange(a, min(rows, a + (1 << 20)), dtype=np.float64) * 0.01
            air = air_c(t, span)
            own = air + 0.5 * np.sin(2 * np.pi * 3 * t / span)  # the sensor's own lag
            gyro = 0.5 + 0.02 * (air - 25.0) + rng.normal(0.0, 0.05, t.size)
            w.write_table(pa.table({"time": t, "gyro": gyro, "T1": own}, schema=schema))
    tmp.rename(rec)
    return rec, log


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", type=int, nargs="+", default=[2_000_000])
    args = ap.parse_args()
    base_rec, base_log = write_files(BASE_ROWS)
    model = DATA / "chamber_model.json"
    measure([*THERMOCAL, "fit", str(base_rec), "--model", "poly", "--order", "1", "--signal",
             "gyro", "--temps", "T1,chamber", "--chamber-log", str(base_log),
             "--chamber-offset", "0", "--allow-narrow", "-o", str(model)])  # fmt: skip
    plain = DATA / "chamber_model_plain.json"
    measure([*THERMOCAL, "fit", str(base_rec), "--model", "poly", "--order", "1", "--signal",
             "gyro", "--temps", "T1", "--allow-narrow", "-o", str(plain)])  # fmt: skip
    out = DATA / "chamber_out.parquet"

    def run(rec: Path, log: Path, how: str) -> tuple[float, float]:
        if how == "no log":
            return measure([*THERMOCAL, "compensate", str(plain), str(rec), "-o", str(out),
                            "--extrapolate"])  # fmt: skip
        clock = ["--chamber-offset", "0"] if how == "given" else []
        return measure([*THERMOCAL, "compensate", str(model), str(rec), "-o", str(out),
                        "--chamber-log", str(log), *clock, "--extrapolate"])  # fmt: skip

    hows = ("no log", "given", "correlation")
    base = {how: run(base_rec, base_log, how)[1] for how in hows}
    print(f"{'rows':>10s} {'join':>12s} {'peak MB':>8s} {'base MB':>8s} {'B/row':>7s} "
          f"{'s':>6s}  target ≤ {TARGET_B_PER_ROW:.0f} B/row")  # fmt: skip
    for rows in args.rows:
        rec, log = write_files(rows)
        for how in hows:
            wall, mb = run(rec, log, how)
            per_row = (mb - base[how]) * 1024 * 1024 / rows
            verdict = "met" if per_row <= TARGET_B_PER_ROW else "NOT MET"
            print(f"{rows:10d} {how:>12s} {mb:8.1f} {base[how]:8.1f} {per_row:7.1f} "
                  f"{wall:6.1f}  {verdict}")  # fmt: skip


if __name__ == "__main__":
    main()
