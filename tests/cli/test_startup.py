"""Start-up (issue 17, first item): ``thermocal --version`` and ``import thermocal.cli`` load
neither pandas, pyarrow, scipy nor matplotlib; a run imports only its command's module;
``--help`` (every command registered, every option's help resolved) loads not even numpy:
each command imports what it uses when it runs.  Checked in fresh interpreters; the wall-time
figures belong to the benchmarks."""

from __future__ import annotations

import subprocess
import sys

HEAVY = ("pandas", "pyarrow", "scipy", "matplotlib")


def _loaded(code: str) -> list[str]:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return out.stdout.split()


def test_import_cli_loads_no_heavy_library() -> None:
    code = (
        f"import sys, thermocal, thermocal.cli; print(*[m for m in {HEAVY!r} if m in sys.modules])"
    )
    assert _loaded(code) == []


def test_version_runs_without_commands() -> None:
    code = (
        "import sys, contextlib, io; from thermocal.cli import main\n"
        "buf = io.StringIO()\n"
        "with contextlib.redirect_stdout(buf): rc = main(['--version'])\n"
        "print(rc, buf.getvalue().strip().replace(' ', '_'), "
        f"*[m for m in {HEAVY!r} + ('thermocal.cli.fit_cmd',) if m in sys.modules])"
    )
    assert _loaded(code) == ["0", "thermocal_0.1.0"]


def test_a_command_imports_only_its_module() -> None:
    code = (
        "import sys, contextlib, io; from thermocal.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()): main(['profile', 'list'])\n"
        "mods = [m for m in sys.modules if m.startswith('thermocal.cli.')]\n"
        "print(*sorted(m for m in mods if m.endswith('_cmd')))"
    )
    assert _loaded(code) == ["thermocal.cli.profile_cmd"]


def test_the_command_map_is_what_the_modules_register() -> None:
    import thermocal.cli as cli

    app = cli.app  # every module registered
    names = {c.name: c.callback.__module__.rsplit(".", 1)[1] for c in app.registered_commands}
    names.update(
        {
            g.name: g.typer_instance.registered_commands[0].callback.__module__.rsplit(".", 1)[1]
            for g in app.registered_groups
            if g.typer_instance is not None
        }
    )
    assert names == cli.COMMANDS


HELP_FREE = (*HEAVY, "numpy", "rich.console", "jinja2")


def _profile_commands() -> list[str]:
    """The subcommands of ``thermocal profile``, as the module registers them."""
    import thermocal.cli as cli

    group = next(g for g in cli.app.registered_groups if g.name == "profile")
    assert group.typer_instance is not None
    return [str(c.name) for c in group.typer_instance.registered_commands]


def test_help_resolves_every_command_without_the_maths() -> None:
    """``thermocal --help`` and each command's ``--help`` run on typer alone: the maths,
    numpy and rich's console are imported when a command runs, not when it is listed.
    What typer itself loads to print a help (typer < 0.13 formats it with rich's console) is
    typer's: a one-command typer application prints its help first, in the same process."""
    commands = sorted({*__import__("thermocal.cli").cli.COMMANDS} - {"profile"})
    profile_commands = _profile_commands()
    code = (
        "import sys, contextlib, io, typer\n"
        "mini = typer.Typer(rich_markup_mode=None)\n"
        "@mini.command()\n"
        "def one(x: int = 1) -> None: pass\n"
        "@mini.command()\n"
        "def two() -> None: pass\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    for a in (['--help'], ['one', '--help']):\n"
        "        try: mini(a, standalone_mode=False)\n"
        "        except SystemExit: pass\n"
        f"typers = {{m for m in {HELP_FREE!r} if m in sys.modules}}\n"
        "from thermocal.cli import main\n"
        "buf = io.StringIO()\n"
        "with contextlib.redirect_stdout(buf):\n"
        "    codes = [main(['--help'])]\n"
        f"    codes += [main([c, '--help']) for c in {commands!r}]\n"
        f"    codes += [main(['profile', c, '--help']) for c in {profile_commands!r}]\n"
        "assert 'compensate' in buf.getvalue() and '500000' in buf.getvalue(), buf.getvalue()\n"
        f"print(sum(codes), *[m for m in {HELP_FREE!r} if m in sys.modules and m not in typers])"
    )
    assert _loaded(code) == ["0"]


def test_the_help_names_are_the_libraries_names() -> None:
    """The values the help shows (thermocal.defaults) are the ones the maths uses."""
    from thermocal import defaults, profiles, validation
    from thermocal.pipeline import compensate
    from thermocal.simulate import SCENARIOS
    from thermocal.turntable.calibration import DEFAULT_GYRO_COLUMNS

    assert tuple(SCENARIOS) == defaults.SCENARIO_NAMES
    assert compensate.DEFAULT_CHUNK_ROWS is defaults.DEFAULT_CHUNK_ROWS
    assert validation.DEFAULT_AVERAGING_S is defaults.DEFAULT_AVERAGING_S
    assert profiles.WEAK_CORRELATION_LIMIT is defaults.WEAK_CORRELATION_LIMIT
    assert DEFAULT_GYRO_COLUMNS is defaults.DEFAULT_GYRO_COLUMNS


def test_command_modules_give_typer_evaluated_annotations() -> None:
    """typer compiles string annotations when it builds the help (~30 ms for all commands):
    the command modules keep their option annotations evaluated (cli/__init__ docstring)."""
    from pathlib import Path

    import thermocal.cli as cli

    folder = Path(cli.__file__).parent
    postponed = [
        f.name
        for f in sorted(folder.glob("*_cmd.py"))
        if "from __future__ import annotations" in f.read_text(encoding="utf-8")
    ]
    assert postponed == []
