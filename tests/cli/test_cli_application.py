"""The root group's list of commands without the command modules: ``thermocal --help`` and
``thermocal`` alone list every command from ``COMMAND_SUMMARIES`` and import no command
module; the list is byte for byte what typer writes from the commands' own docstrings when
every module is registered, at any width."""

from __future__ import annotations

import ast
import os
import subprocess
import sys

import pytest

import thermocal.cli as cli
from thermocal.cli.application import COMMAND_SUMMARIES

LAZY_THEN_FULL = r"""
import contextlib, io, sys
from thermocal import cli

def run(args):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main(args)
    return code, out.getvalue(), err.getvalue()

args = sys.argv[1:]
lazy = run(args)
loaded = sorted(m for m in sys.modules if m.startswith("thermocal.cli.") and m.endswith("_cmd"))
cli._register()  # every command module, as before the list of summaries
full = run(args)
print(repr((lazy, loaded, full)))
"""


def _lazy_then_full(args: list[str], columns: str) -> tuple[object, list[str], object]:
    env = {**os.environ, "COLUMNS": columns}
    res = subprocess.run(
        [sys.executable, "-c", LAZY_THEN_FULL, *args],
        capture_output=True,
        text=True,
        check=True,
        env=env,
    )
    lazy, loaded, full = ast.literal_eval(res.stdout)
    return lazy, loaded, full


def test_the_summaries_are_the_commands_docstrings() -> None:
    """The table holds what the registered commands give (their order, which depends on
    which modules this test process imported first, is checked against a fresh process's
    listing by the test below)."""
    real = cli.command_summaries()
    assert dict(COMMAND_SUMMARIES) == real, (
        "regenerate COMMAND_SUMMARIES from thermocal.cli.command_summaries()"
    )


@pytest.mark.parametrize("columns", ["80", "200", "40"])
@pytest.mark.parametrize("args", [["--help"], []], ids=["help", "no-arguments"])
def test_the_list_without_modules_is_the_list_with_them(args: list[str], columns: str) -> None:
    lazy, loaded, full = _lazy_then_full(args, columns)
    assert loaded == []
    assert lazy == full
    text = lazy[1] + lazy[2]  # type: ignore[index]
    assert all(f" {name} " in text for name in cli.COMMANDS)


def test_help_before_a_command_lists_every_command() -> None:
    """``thermocal --help fit`` is the root's help: every command listed (it listed only the
    command named after it, the one module registered)."""
    lazy, loaded, _ = _lazy_then_full(["--help", "fit"], "80")
    assert loaded == ["thermocal.cli.fit_cmd"]
    assert lazy[0] == 0  # type: ignore[index]
    listed = [line.split()[0] for line in lazy[1].split("Commands:")[1].splitlines() if line]  # type: ignore[index]
    assert listed == list(COMMAND_SUMMARIES)


def test_a_commands_help_loads_no_pydantic() -> None:
    """A command's ``--help`` needs no coercion of values: typer ≥ 0.28 builds a pydantic
    adapter for the root's ``--help`` flag left out, unless the root takes it as given."""
    commands = sorted(set(cli.COMMANDS) - {"profile", "station"})  # groups: typer's own
    code = (
        "import contextlib, io, sys\n"
        "from thermocal.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    codes = [main([c, '--help']) for c in {commands!r}]\n"
        "print(sum(codes), 'pydantic' in sys.modules, 'importlib.metadata' in sys.modules)"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert res.stdout.split() == ["0", "False", "False"]


@pytest.mark.parametrize(
    "group", [[], ["station"], ["profile"]], ids=["root", "station", "profile"]
)
def test_a_group_alone_prints_its_help_as_help_does(group: list[str], capsys) -> None:  # type: ignore[no-untyped-def]
    """``thermocal`` (or a group) without a command prints the same help as ``--help``, on
    stdout, with its line breaks, and exits 0 (click ≥ 8.2 and typer ≥ 0.28 raise it as a usage
    error: the help was squashed into one ``error:`` line with exit 2)."""
    assert cli.main([*group, "--help"]) == 0
    expected = capsys.readouterr().out
    assert cli.main(group) == 0
    out, err = capsys.readouterr()
    assert out.rstrip("\n") == expected.rstrip("\n")
    assert out.count("\n") > 5 and err == ""
