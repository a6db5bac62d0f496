"""What several benchmarks share: running ``thermocal`` (or a script) as a child process and
reading its wall time, CPU time and peak resident memory (``RUSAGE_CHILDREN`` of a wrapper
process, so that each measurement is of one child alone), and the Parquet recording the
``allan`` benchmarks read."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

THERMOCAL = [sys.executable, "-c", "import sys; from thermocal.cli import main; sys.exit(main())"]
"""``thermocal`` in this interpreter's environment."""

WRAPPER = r"""
import resource, subprocess, sys, time
t0 = time.perf_counter()
proc = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
dt = time.perf_counter() - t0
use = resource.getrusage(resource.RUSAGE_CHILDREN)
print(f"{proc.returncode} {use.ru_maxrss} {dt:.4f} {use.ru_utime + use.ru_stime:.4f}")
if proc.returncode:
    print(proc.stderr[-2000:], file=sys.stderr)
"""
"""Prints the child's exit status, peak resident memory [kB], wall time [s] and CPU time
(user + system) [s]."""


def measure_cpu(cmd: list[str], env: dict[str, str] | None = None) -> tuple[float, float, float]:
    """(wall seconds, peak resident MB, CPU seconds: user + system) of one child process run
    with ``env`` (default this one's); a failure stops the benchmark."""
    res = subprocess.run(
        [sys.executable, "-c", WRAPPER, *cmd], capture_output=True, text=True, env=env
    )
    code, peak_kb, seconds, cpu = res.stdout.split()
    if int(code) != 0:
        raise SystemExit(f"{cmd[3:] if cmd[:1] == THERMOCAL[:1] else cmd} failed: {res.stderr}")
    return float(seconds), int(peak_kb) / 1024.0, float(cpu)


def measure(cmd: list[str]) -> tuple[float, float]:
    """(wall seconds, peak resident MB) of one child process; a failure stops the benchmark."""
    wall, mb, _cpu = measure_cpu(cmd)
    return wall, mb


# --- shared by the flight-controller benchmarks (bench_px4_algorithm, bench_ardupilot_algorithm)


def compiled(trees: list[Path]) -> None:
    """Each source tree timed byte-compiled first (``compileall``, written even under
    ``PYTHONDONTWRITEBYTECODE``), as an installed package is: else every run compiles
    thermocal's modules again (≈ 1 s of CPU) while the firmware projects' scripts import
    only installed packages."""
    import compileall

    for tree in trees:
        compileall.compile_dir(str(tree), quiet=1)


def race(
    cmds: dict[str, list[str]], repeat: int, runs_of: dict[str, int] | None = None
) -> dict[str, tuple[float, float, float]]:
    """Best wall time [s], peak resident memory [MB] and least CPU time [s] of each command,
    run ``repeat`` times interleaved (one of each in turn, so that a change of the machine's
    load falls on all of them alike), each a fresh process; ``runs_of``: fewer runs of some
    (the first rounds only)."""
    import math
    import os

    best: dict[str, tuple[float, float, float]] = {}
    for r in range(repeat):
        for name, cmd in cmds.items():
            if r >= (runs_of or {}).get(name, repeat):
                continue
            t, mb, cpu = measure_cpu(cmd)
            old = best.get(name, (math.inf, 0.0, math.inf))
            best[name] = (min(old[0], t), max(old[1], mb), min(old[2], cpu))
            print(f"  run {r + 1}/{repeat} {name:<16} {t:7.2f} s {mb:7.0f} MB cpu {cpu:6.2f} s "
                  f"(load {os.getloadavg()[0]:.2f})", flush=True)  # fmt: skip
    return best


def residual_table(rows: list[tuple[str, float, float]], other: str) -> tuple[float, float]:
    """Print the residuals (name, rms thermocal, rms ``other``) per axis with their ratio;
    returns the geometric mean of the ratios over the axes and the worst ratio."""
    import numpy as np

    print(f"{'axis':<10} {'thermocal':>12} {other:>12} {'ratio':>7}")
    for name, ours, theirs in rows:
        unit = "rad/s" if name.startswith("gyro") else "m/s²"
        print(f"{name:<10} {ours:12.3e} {theirs:12.3e} {ours / theirs:7.2f}  {unit}")
    ratios = [o / t for _n, o, t in rows]
    return float(np.exp(np.mean(np.log(ratios)))), max(ratios)


def memory_above(peak_mb: float, log: Path, tiny_peak_mb: float, tiny: Path) -> float:
    """Print the memory of a command on ``log`` above that of the same command on the tiny
    log ``tiny`` (its imports and fixed costs), against the log's size; returns the MB above."""
    log_mb, tiny_mb = log.stat().st_size / 1e6, tiny.stat().st_size / 1e6
    above = peak_mb - tiny_peak_mb
    print(f"memory: peak {peak_mb:.0f} MB on the {log_mb:.1f} MB log, {tiny_peak_mb:.0f} MB on "
          f"a {tiny_mb:.2f} MB log: {above:.0f} MB above, {above / log_mb:.2f}x the log (peak "
          "RSS of the largest process, wrapper's RUSAGE_CHILDREN; target <= 2x: "
          f"{'met' if above <= 2 * log_mb else 'NOT met'})")  # fmt: skip
    return above


ALLAN_COLUMNS = {"rate": "rate [deg/h]", "phase": "angle [deg]"}
"""The signal column of :func:`write_allan_parquet` per data type."""


def write_allan_parquet(path: Path, rows: int, data_type: str = "rate") -> Path:
    """The ``allan`` benchmarks' recording, written once (atomically) to ``path``: 100 Hz
    time [s], the signal — a rate [deg/h] of white noise, a slow random walk and 10 deg/h,
    or for ``data_type="phase"`` its running angle [deg] — two temperature ramps and one
    unused column, uncompressed, seeded (the same file on every machine)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    if path.exists():
        return path
    path.parent.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(0)
    t = np.arange(rows) * 0.01
    y = rng.standard_normal(rows) + np.cumsum(rng.standard_normal(rows)) * 1e-4 + 10.0
    if data_type == "phase":
        y = np.cumsum(y * (0.01 / 3600.0))  # the angle [deg] of a rate [deg/h]
    ramp = 1e-6 * np.arange(rows)
    table = pa.table({"time [s]": t, ALLAN_COLUMNS[data_type]: y, "T1 [degC]": 25.0 + ramp,
                      "T2 [degC]": 24.0 + ramp, "aux": rng.standard_normal(rows)})  # fmt: skip
    del t, y, ramp
    tmp = path.with_suffix(".tmp")
    pq.write_table(table, tmp, compression="none")
    tmp.rename(path)
    return path
