"""Start-up (issue 17, first item): ``thermocal --version`` and ``import thermocal.cli`` load
neither pandas, pyarrow, scipy nor matplotlib; a run imports only its command's module.
Checked in fresh interpreters; the wall-time figures belong to the benchmarks."""

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
    names.update({g.name: "profile_cmd" for g in app.registered_groups})
    assert names == cli.COMMANDS
