"""Benchmark: both triads over temperature (issue 19).

* six 16-position soak runs of 10⁵ samples each (``simulate turntable-thermal`` at 84 Hz):
  ``thermocal turntable … --temps T_imu --accel … -o CAL.json`` wall time (one process);
* 10⁷ samples compensated: the held-out run tiled to 10⁷ rows (time continued), then
  ``thermocal compensate CAL.json FILE -o OUT``: wall time and peak resident memory.

Run: ``.venv/bin/python benchmarks/bench_turntable_thermal.py``.  Files go to
``benchmarks/_data/tt_thermal/`` (git-ignored).
"""

from __future__ import annotations

import os
from pathlib import Path

from _harness import THERMOCAL, measure

DATA = Path(__file__).resolve().parent / "_data" / "tt_thermal"


def run(cmd: list[str]) -> tuple[float, float]:
    return measure(cmd)


def main() -> int:
    import pyarrow as pa
    import pyarrow.parquet as pq

    from thermocal.turntable.simulate import simulate_turntable_thermal
    from thermocal.writers import write_recording

    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores")
    DATA.mkdir(parents=True, exist_ok=True)
    runs = simulate_turntable_thermal(seed=1, rate_hz=84.2)
    soaks, held = [], None
    for rec, truth in runs:
        f = DATA / f"{truth['label']}.parquet"
        write_recording(rec, f)
        if truth["held_out"]:
            held = f
        else:
            soaks.append(str(f))
    n = runs[0][0].n_samples
    cal = DATA / "cal.json"
    t_cal, mb_cal = run([*THERMOCAL, "turntable", *soaks, "--temps", "T_imu",
                         "--accel", "accel_x,accel_y,accel_z", "-o", str(cal)])  # fmt: skip
    print(f"calibrate six soaks x {n} samples (gyro + accel triads, thermal fit): "
          f"{t_cal:.2f} s, peak {mb_cal:.0f} MB")  # fmt: skip
    assert held is not None
    big = DATA / "held_1e7.parquet"
    if not big.exists():
        table = pq.read_table(held)
        reps = -(-10_000_000 // table.num_rows)
        t = table.column("time").to_numpy()
        span = float(t[-1] - t[0]) + float(t[1] - t[0])
        with pq.ParquetWriter(big, table.schema) as writer:
            for k in range(reps):
                cols = {c: table.column(c) for c in table.column_names}
                cols["time"] = pa.array(t + k * span)
                writer.write_table(pa.table(cols, schema=table.schema))
    rows = pq.ParquetFile(big).metadata.num_rows
    out = DATA / "comp_1e7.parquet"
    t_comp, mb_comp = run([*THERMOCAL, "compensate", str(cal), str(big), "-o", str(out)])
    out.unlink(missing_ok=True)
    print(f"compensate {rows} samples (both triads): {t_comp:.1f} s, "
          f"{rows / t_comp / 1e6:.2f} M samples/s, peak {mb_comp:.0f} MB")  # fmt: skip

    return 0


if __name__ == "__main__":
    raise SystemExit(main())
