"""The command-line reference is generated from the application: no command or option missing.

A small Sphinx project holding only ``.. thermocal-cli::`` (the extension of
``docs/_ext/thermocal_cli.py``) is built with warnings as errors, and every command and
subcommand of the typer application, every visible argument and option with its help text,
is looked for in that command's section of the HTML.  The application is read here through
typer/click directly (and the command names through :data:`thermocal.cli.COMMANDS`), not
through the extension's own walk.
"""

from __future__ import annotations

import html
import math
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import typer

import thermocal.cli

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _text(fragment: str) -> str:
    """An HTML fragment's visible text, whitespace collapsed."""
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", fragment)).split())


@pytest.fixture(scope="module")
def sections(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """Section id → the visible text of that section, from the built page."""
    src = tmp_path_factory.mktemp("cli-src")
    out = tmp_path_factory.mktemp("cli-html")
    (src / "conf.py").write_text(
        f"import sys\nsys.path.insert(0, {str(DOCS / '_ext')!r})\n"
        "extensions = ['thermocal_cli']\nproject = 'cli'\n",
        encoding="utf-8",
    )
    (src / "index.rst").write_text("CLI\n===\n\n.. thermocal-cli::\n", encoding="utf-8")
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html"]
    proc = subprocess.run(
        [*cmd, str(src), str(out)], capture_output=True, text=True, timeout=300, check=False
    )
    assert proc.returncode == 0, proc.stderr
    page = (out / "index.html").read_text(encoding="utf-8")
    parts = re.split(r'<section id="([^"]+)"', page)
    return {parts[i]: _text(parts[i + 1]) for i in range(1, len(parts) - 1, 2)}


def _walk(command: Any, path: tuple[str, ...]) -> list[tuple[tuple[str, ...], Any]]:
    found = [(path, command)] if path else []
    for name, sub in sorted((getattr(command, "commands", None) or {}).items()):
        if not getattr(sub, "hidden", False):
            found += _walk(sub, (*path, name))
    return found


def _app_commands() -> list[tuple[tuple[str, ...], Any]]:
    return _walk(typer.main.get_command(thermocal.cli.app), ())


def test_every_command_of_the_table_has_a_section(sections: dict[str, str]) -> None:
    missing = [n for n in thermocal.cli.COMMANDS if f"thermocal-{n}" not in sections]
    assert not missing
    assert {"thermocal-station-run", "thermocal-station-check", "thermocal-profile-correlate"} <= (
        sections.keys()
    )


def test_every_option_of_every_command_is_in_its_section(sections: dict[str, str]) -> None:
    commands = _app_commands()
    assert len(commands) >= len(thermocal.cli.COMMANDS)
    missing: list[str] = []
    n_params = 0
    for path, command in commands:
        key = "thermocal-" + "-".join(path)
        body = sections.get(key)
        if body is None:
            missing.append(key)
            continue
        for param in command.params:
            if getattr(param, "hidden", False):
                continue
            n_params += 1
            names = [*param.opts, *(getattr(param, "secondary_opts", None) or [])]
            if getattr(param, "param_type_name", "option") == "argument" or not any(
                n.startswith("-") for n in names
            ):
                names = [str(param.name).upper()]
            for name in names:
                if not re.search(rf"(^|[\s,]){re.escape(name)}([\s,]|$)", body):
                    missing.append(f"{' '.join(path)}: {name}")
            help_text = " ".join(str(getattr(param, "help", None) or "").split())
            if help_text and help_text not in body:
                missing.append(f"{' '.join(path)}: help of {names[0]}")
    assert not missing, missing
    assert n_params > 300  # every command's options, not a handful


def test_types_and_defaults_are_shown(sections: dict[str, str]) -> None:
    allan = sections["thermocal-allan"]
    # --taus: a text option whose default is "octave"; --confidence: a float, by default the
    # probability of ±1σ of a normal distribution, erf(1/√2)
    assert "--taus text octave Tau set" in allan
    shown = re.search(r"--confidence float (\S+) Confidence level", allan)
    assert shown is not None
    assert math.isclose(float(shown.group(1)), math.erf(2**-0.5), rel_tol=1e-12)
    assert re.search(r"--json flag off Print one JSON object", allan)
    assert "FILE (required) path" in allan
