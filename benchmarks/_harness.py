"""What several benchmarks share: running ``thermocal`` (or a script) as a child process and
reading its wall time and peak resident memory (``RUSAGE_CHILDREN`` of a wrapper process, so
that each measurement is of one child alone)."""

from __future__ import annotations

import subprocess
import sys

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
