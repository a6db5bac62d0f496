"""A command's own process tells OpenBLAS's idle threads to sleep at once
(``OPENBLAS_THREAD_TIMEOUT``) before numpy is imported, keeping a value the user set; a
process that loaded numpy first (a notebook, these tests) is left as it is.  What it saves
is measured in ``benchmarks/RESULTS.md`` (CPU of whole processes), not timed here."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[2] / "src")

RUN = (
    "import os, sys\n"
    "{before}"
    "sys.argv = ['thermocal', 'inspect', '--help']\n"
    "from thermocal.cli import main\n"
    "import contextlib, io\n"
    "with contextlib.redirect_stdout(io.StringIO()):\n"
    "    main()\n"
    "import numpy\n"
    "print(os.environ.get('OPENBLAS_THREAD_TIMEOUT'))\n"
)


def _timeout_seen(before: str = "", env_value: str | None = None) -> str:
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_THREAD_TIMEOUT"}
    env["PYTHONPATH"] = SRC
    if env_value is not None:
        env["OPENBLAS_THREAD_TIMEOUT"] = env_value
    code = RUN.format(before=before)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip().splitlines()[-1]


@pytest.mark.parametrize(
    ("before", "env_value", "want"),
    [
        ("", None, "4"),  # the command's process: set before numpy loads
        ("", "12", "12"),  # the user's own value kept
        ("import numpy\n", None, "None"),  # numpy already loaded: nothing to change
    ],
)
def test_the_process_quiets_idle_blas_threads(
    before: str, env_value: str | None, want: str
) -> None:
    assert _timeout_seen(before, env_value) == want


def test_a_call_with_arguments_changes_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    """``main([...])`` from a program (argv given) is not the process's own command line."""
    from thermocal.cli import main

    monkeypatch.delenv("OPENBLAS_THREAD_TIMEOUT", raising=False)
    assert main(["--version"]) == 0
    assert "OPENBLAS_THREAD_TIMEOUT" not in os.environ
