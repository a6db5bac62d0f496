"""thermocal's command line (INTERFACE.md).

Each command lives in its own module under :mod:`thermocal.cli` and registers on
:data:`thermocal.cli.app.app`; :func:`main` is the console entry point.
"""

from __future__ import annotations

import importlib
import sys

import typer

from thermocal.cli.app import app

COMMAND_MODULES = (
    "inspect_cmd",
    "metrics_cmd",
    "allan_cmd",
    "profile_cmd",
    "simulate_cmd",
    "fit_cmd",
    "compensate_cmd",
    "validate_cmd",
    "export_cmd",
    "turntable_cmd",
    "report_cmd",
    "demo_cmd",
)
"""Command modules, registered in this order (a missing module is skipped)."""


def _register() -> None:
    for mod in COMMAND_MODULES:
        try:
            importlib.import_module(f"thermocal.cli.{mod}")
        except ModuleNotFoundError as exc:
            if exc.name != f"thermocal.cli.{mod}":
                raise


_register()


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 2 bad input, 1 internal).

    Usage errors (unknown option, missing argument) print one ``error: ...`` line
    on stderr and return 2, as INTERFACE.md asks.
    """
    try:
        result = app(args=argv, prog_name="thermocal", standalone_mode=False)
    except typer.Exit as exc:
        return int(exc.exit_code)
    except typer.Abort:
        print("error: aborted", file=sys.stderr)
        return 1
    except typer.TyperException as exc:
        code = int(getattr(exc, "exit_code", 2))
        message = " ".join(exc.format_message().split()) or "missing command or argument"
        print(f"error: {message} (see --help)", file=sys.stderr)
        return code if code else 2
    except SystemExit as exc:
        status = exc.code
        return status if isinstance(status, int) else (0 if status is None else 1)
    return result if isinstance(result, int) else 0


__all__ = ["app", "main"]
