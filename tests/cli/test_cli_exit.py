"""The end of a ``thermocal`` process: the command line run as the process's own (``main()``
without arguments, as the ``thermocal`` script and ``python -m thermocal`` run it) leaves
its objects out of the collector's shutdown passes (:func:`gc.freeze`), and still ends as a
process must — its output whole on stdout and in its files, nothing temporary left, its
``atexit`` handlers run.  Called with arguments (a library or a test), nothing changes."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
from pathlib import Path

import thermocal
from thermocal.cli import main

SRC = str(Path(thermocal.__file__).resolve().parents[1])


def _process(cwd: Path, *args: str) -> subprocess.CompletedProcess[str]:
    """``thermocal ARGS`` as its script runs it, with an ``atexit`` handler registered first
    (so run last) that says whether the collector was frozen."""
    code = (
        "import atexit, gc, sys\n"
        "atexit.register(lambda: print('frozen', gc.get_freeze_count() > 0, file=sys.stderr))\n"
        "from thermocal.cli import main\n"
        "sys.exit(main())\n"
    )
    return subprocess.run(
        [sys.executable, "-c", code, *args], cwd=cwd, env={**os.environ, "PYTHONPATH": SRC},
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip


def test_a_process_ends_with_its_output_whole_and_nothing_temporary(tmp_path: Path) -> None:
    proc = _process(tmp_path, "simulate", "fog-slow", "-o", "run.csv")
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.splitlines()[-1] == "frozen True"
    proc = _process(tmp_path, "metrics", "run.csv", "--json")
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.splitlines()[-1] == "frozen True"
    out = json.loads(proc.stdout)  # the whole object, flushed at exit
    assert out["n_samples"] > 0
    rows = (tmp_path / "run.csv").read_text(encoding="utf-8").splitlines()
    assert len(rows) == out["n_samples"] + 1  # the header, then every sample
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted(["run.csv", "run.csv.meta.json"]), left


def test_main_with_arguments_leaves_the_collector_alone(capsys: object) -> None:
    assert gc.get_freeze_count() == 0
    assert main(["--version"]) == 0
    assert gc.get_freeze_count() == 0
