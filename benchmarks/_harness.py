"""What several benchmarks share: running ``thermocal`` (or a script) as a child process and
reading its wall time and peak resident memory (``RUSAGE_CHILDREN`` of a wrapper process, so
that each measurement is of one child alone)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

THERMOCAL = [sys.executable, "-c", "import sys; from thermocal.cli import main; sys.exit(main())"]
"""``thermocal`` in this interpreter's environment."""

WRAPPER = r"""
import resource, subprocess, sys, time
t0 = time.perf_counter()
proc = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
dt = time.perf_counter() - t0
print(f"{proc.returncode} {resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss} {dt:.4f}")
if proc.returncode:
    print(proc.stderr[-2000:], file=sys.stderr)
"""


def measure(cmd: list[str]) -> tuple[float, float]:
    """(wall seconds, peak resident MB) of one child process; a failure stops the benchmark."""
    res = subprocess.run([sys.executable, "-c", WRAPPER, *cmd], capture_output=True, text=True)
    code, peak_kb, seconds = res.stdout.split()
    if int(code) != 0:
        raise SystemExit(f"{cmd[3:] if cmd[:1] == THERMOCAL[:1] else cmd} failed: {res.stderr}")
    return float(seconds), int(peak_kb) / 1024.0


# --- shared by the flight-controller benchmarks (bench_px4_algorithm, bench_ardupilot_algorithm)

CPU_WRAPPER = r"""
import resource, subprocess, sys, time
t0 = time.perf_counter()
proc = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
dt = time.perf_counter() - t0
ru = resource.getrusage(resource.RUSAGE_CHILDREN)
print(f"{proc.returncode} {ru.ru_maxrss} {dt:.4f} {ru.ru_utime + ru.ru_stime:.4f}")
if proc.returncode:
    print(proc.stderr[-2000:], file=sys.stderr)
"""
"""``WRAPPER`` with the CPU time [s] of the child and its own children added (user + system):
on a loaded machine the wall time is mostly waiting for a core, the CPU time is what the
program costs."""


def measure_cpu(cmd: list[str]) -> tuple[float, float, float]:
    """(wall [s], peak resident memory of the largest process [MB], CPU [s]) of one run."""
    res = subprocess.run([sys.executable, "-c", CPU_WRAPPER, *cmd], capture_output=True,
                         text=True, check=False)  # fmt: skip
    code, peak_kb, wall, cpu = res.stdout.split()
    if int(code) != 0:
        raise SystemExit(f"{cmd} failed: {res.stderr}")
    return float(wall), int(peak_kb) / 1024.0, float(cpu)


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
