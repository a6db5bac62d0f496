"""``python -m thermocal`` is the command line: the version from ``pyproject.toml``, exit
status 2 and one ``error:`` line for a mistyped command."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

PYPROJECT = Path(__file__).resolve().parents[2] / "pyproject.toml"


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "thermocal", *args], capture_output=True, text=True
    )


def test_python_m_thermocal_prints_the_version() -> None:
    version = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["project"]["version"]
    res = _run("--version")
    assert (res.returncode, res.stdout, res.stderr) == (0, f"thermocal {version}\n", "")


def test_python_m_thermocal_refuses_an_unknown_command_in_one_line() -> None:
    res = _run("fti")
    assert res.returncode == 2
    (line,) = res.stderr.splitlines()
    # click ≥ 8.2 (typer ≥ 0.16) suggests the close name; older versions only refuse
    assert line in (
        "error: No such command 'fti'. Did you mean 'fit'? (see --help)",
        "error: No such command 'fti'. (see --help)",
    )
