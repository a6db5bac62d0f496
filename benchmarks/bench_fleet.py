"""Benchmark: a production batch (issue 18).

* 200 units × 10⁵ samples (Parquet: time, a gyro [°/h], a temperature [°C]; a linear model):
  ``thermocal fleet`` with its default workers (one process per CPU) and with one, against the
  one-process library loop that does the same per unit (read the file, fit
  ``make_model("poly", order=1)``, save the model) — the anchor, measured in the same run;
  the ratio fleet/loop (target ≤ 1.5, the default run; the fleet also writes the summary and
  the report, ≈ 1.4 s the loop does not) and the scaling from one worker to the default;
  beside it, the loop of what ``thermocal fit`` does per unit (``fit_files``: the same fit
  with the command's checks of the data, the fleet's work per unit), to tell the fleet's own
  cost from the command's; best of 3 interleaved rounds (every job once per round), with
  ``--before SRC`` the fleet of an older tree in the same rounds;
* 20 units × 10⁷ samples with two workers: wall time and the peak resident memory of the
  driver and of its worker processes (``RUSAGE_CHILDREN``: the largest worker).

Every time is given as wall and as CPU time (user + system; the fleet's worker processes
included), the steadier figure on a shared machine.  The trees are byte-compiled first, as an
installed package is (``--no-bytecode``: each process compiles what it imports, as this
environment's ``PYTHONDONTWRITEBYTECODE`` makes it); the library loop is also timed as a whole
process (start-up and imports included), which the fleet's figures are.

Run: ``.venv/bin/python benchmarks/bench_fleet.py [--units 200] [--rows 100000] [--skip-big]
[--quick] [--repeat 3] [--before OLD/src] [--no-bytecode]``.
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
from typing import Any

import numpy as np

from _harness import THERMOCAL, compiled, measure_cpu

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


LOOP_CODE = """
import sys, time, tomllib
from pathlib import Path
from threadpoolctl import threadpool_limits
from thermocal.readers.dispatch import read_recording
from thermocal.models.base import RunData
from thermocal.models.registry import make_model
from thermocal.pipeline.model_file import save_model
from thermocal.fleet.config import load_config
from thermocal.pipeline.fit import fit_files
cfg = Path(sys.argv[1]); out = Path(sys.argv[2]); out.mkdir(parents=True, exist_ok=True)
pipeline = sys.argv[3] == "pipeline"
doc = tomllib.loads(cfg.read_text())
opts = load_config(cfg).fit
t0, c0 = time.perf_counter(), time.process_time()
with threadpool_limits(limits=1):
    for u in doc["unit"]:
        path = cfg.parent / u["modeling"][0]
        if pipeline:
            fit_files([path], opts, out / (u["id"] + ".json"))
            continue
        rec = read_recording(path)
        model = make_model("poly", order=1).fit([RunData.from_recording(rec, "gyro", ["T1"])])
        save_model(model, out / (u["id"] + ".json"))
print(time.perf_counter() - t0, time.process_time() - c0)
"""


def library_loop(cfg: Path, out: Path, pipeline: bool = False) -> tuple[float, float]:
    """The anchor: one process, per unit read + fit + save, no fleet machinery (timed
    after the imports: wall and CPU seconds).  ``pipeline``: per unit what ``thermocal
    fit`` does instead (:func:`thermocal.pipeline.fit.fit_files`: the same fit with the
    command's checks of the data, its warnings and the model file with its provenance),
    the work the fleet asks of each unit."""
    kind = "pipeline" if pipeline else "loop"
    cmd = [sys.executable, "-c", LOOP_CODE, str(cfg), str(out), kind]
    res = subprocess.run(cmd, capture_output=True, text=True, check=True)
    wall, cpu = res.stdout.split()[-2:]
    return float(wall), float(cpu)


def fleet(
    cfg: Path, out: Path, workers: int | None, src: str | None = None
) -> tuple[float, float, float]:
    """(wall seconds, peak MB of the largest process, CPU seconds of the command and its
    worker processes: user + system, imports included) of ``thermocal fleet``
    (``workers`` None: the default, one worker process per CPU; ``src``: the package of
    that folder)."""
    shutil.rmtree(out, ignore_errors=True)
    cmd = [*THERMOCAL, "fleet", str(cfg), "-o", str(out)]
    if workers is not None:
        cmd += ["--workers", str(workers)]
    env = None if src is None else {**os.environ, "PYTHONPATH": src}
    return measure_cpu(cmd, env)


def rounds(cfg: Path, repeat: int, before: str | None) -> dict[str, tuple[float, float, float]]:
    """Best of ``repeat`` interleaved rounds (each: every job once, in turn) of the anchors
    and the fleet, (seconds, peak MB, CPU seconds; each the best of its rounds); with
    ``before``, the fleet of that tree too."""
    jobs: dict[str, Any] = {
        "loop": lambda: _no_peak(library_loop(cfg, DATA / "fleet_loop_out")),
        "pipeline": lambda: _no_peak(library_loop(cfg, DATA / "fleet_loop_out", pipeline=True)),
        "loop process": lambda: measure_cpu(
            [sys.executable, "-c", LOOP_CODE, str(cfg), str(DATA / "fleet_loop_out"), "loop"]
        ),
        "fleet": lambda: fleet(cfg, DATA / "fleet_out_2", None),
        "fleet -w1": lambda: fleet(cfg, DATA / "fleet_out_1", 1),
    }
    if before is not None:
        jobs["fleet (before)"] = lambda: fleet(cfg, DATA / "fleet_out_2", None, before)
        jobs["fleet -w1 (before)"] = lambda: fleet(cfg, DATA / "fleet_out_1", 1, before)
    best: dict[str, tuple[float, float, float]] = {}
    for _ in range(repeat):
        for name, job in jobs.items():
            t, mb, cpu = job()
            old = best.get(name, (t, mb, cpu))
            best[name] = (min(t, old[0]), max(mb, old[1]), min(cpu, old[2]))
    return best


def _no_peak(wall_cpu: tuple[float, float]) -> tuple[float, float, float]:
    return wall_cpu[0], 0.0, wall_cpu[1]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--units", type=int, default=200)
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--quick", action="store_true", help="60 units")
    ap.add_argument("--repeat", type=int, help="interleaved rounds (best of; default 3, quick 2)")
    ap.add_argument("--before", metavar="SRC", help="also the fleet of the package in SRC")
    ap.add_argument("--skip-big", action="store_true", help="skip 20 units × 10⁷ samples")
    ap.add_argument(
        "--no-bytecode", action="store_true", help="each process compiles what it imports"
    )
    args = ap.parse_args()
    units, repeat = (60, 2) if args.quick else (args.units, 3)
    repeat = args.repeat or repeat
    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores")
    if not args.no_bytecode:  # as an installed package is (PYTHONDONTWRITEBYTECODE is set here)
        import thermocal

        compiled([Path(thermocal.__file__).parent, *([Path(args.before)] if args.before else [])])
    cfg = write_batch(units, args.rows)
    best = rounds(cfg, repeat, args.before)
    (t_loop, _, c_loop), (t_pipe, _, c_pipe) = best["loop"], best["pipeline"]
    print(f"{units} units x {args.rows} samples, best of {repeat} interleaved rounds "
          f"(load {os.getloadavg()[0]:.2f} at the end); wall, then CPU (user + system):"
          )  # fmt: skip
    print(f"  library loop (read, fit, save), one process   {t_loop:7.2f} s  cpu {c_loop:6.2f} s "
          "(both after its imports)")  # fmt: skip
    t_proc, _, c_proc = best["loop process"]
    print(f"  the same loop, its whole process               {t_proc:7.2f} s  cpu {c_proc:6.2f} s "
          "(start-up and imports included)")  # fmt: skip
    print(f"  fit pipeline loop (fit_files), one process     {t_pipe:7.2f} s  cpu {c_pipe:6.2f} s "
          f"({t_pipe / t_loop:.2f}x the library loop; cpu {c_pipe / c_loop:.2f}x)")  # fmt: skip
    for name in best:
        if not name.startswith("fleet"):
            continue
        t, mb, cpu = best[name]
        label = f"thermocal {name}".replace("-w1", "--workers 1")
        print(f"  {label:<46s} {t:7.2f} s  cpu {cpu:6.2f} s ({t / t_loop:.2f}x the loop, "
              f"{t / t_pipe:.2f}x the pipeline loop; cpu {cpu / c_loop:.2f}x / "
              f"{cpu / c_pipe:.2f}x; peak {mb:.0f} MB)")  # fmt: skip
    t2 = best["fleet"][0]
    ok = t2 / t_loop <= 1.5
    print(f"  target (fleet, default {os.cpu_count()} workers, within 1.5x the library loop): "
          f"{'met' if ok else 'NOT met'}")  # fmt: skip
    if not args.skip_big:
        big = write_batch(20, 10_000_000)
        t_big, mb_big, _cpu = fleet(big, DATA / "fleet_out_big", 2)
        gb = 20 * 10_000_000 * 3 * 8 / 1e9
        print(f"20 units x 1e7 samples, 2 workers: {t_big:.1f} s, peak {mb_big:.0f} MB per "
              f"process ({gb:.1f} GB of data in all)")  # fmt: skip
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
