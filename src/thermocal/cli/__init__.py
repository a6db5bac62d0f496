"""thermocal's command line (INTERFACE.md).

Each command lives in its own module under :mod:`thermocal.cli` and registers on
:data:`thermocal.cli.app.app`; :func:`main` is the console entry point.
"""

from __future__ import annotations

import importlib
import sys

import typer

from thermocal.cli.app import app
from thermocal.cli.interrupt import report_interrupted

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
    "tempcal_cmd",
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


def _usage_error_types() -> tuple[type[Exception], ...]:
    """The exception class a usage error raises: ``typer.TyperException`` from typer 0.28 on
    (typer no longer depends on click), ``click.ClickException`` before it."""
    new = getattr(typer, "TyperException", None)
    if isinstance(new, type) and issubclass(new, Exception):
        return (new,)
    click = importlib.import_module("click")  # typer < 0.27 depends on click
    old: type[Exception] = click.ClickException
    return (old,)


_USAGE_ERRORS = _usage_error_types()


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 2 bad input, 1 internal).

    Usage errors (unknown option, missing argument) print one ``error: ...`` line
    on stderr and return 2, as INTERFACE.md asks.
    """
    try:
        result = app(args=argv, prog_name="thermocal", standalone_mode=False)
    except typer.Exit as exc:
        if isinstance(exc.__cause__, KeyboardInterrupt):  # typer >= 0.27 turns Ctrl-C into Exit
            return report_interrupted()
        return int(exc.exit_code)
    except (typer.Abort, KeyboardInterrupt):  # click turns Ctrl-C into Abort
        return report_interrupted()
    except _USAGE_ERRORS as exc:
        code = int(getattr(exc, "exit_code", 2))
        text = str(getattr(exc, "format_message", exc.__str__)())
        message = " ".join(text.split()) or "missing command or argument"
        print(f"error: {message} (see --help)", file=sys.stderr)
        return code if code else 2
    except SystemExit as exc:
        status = exc.code
        return status if isinstance(status, int) else (0 if status is None else 1)
    return result if isinstance(result, int) else 0


__all__ = ["app", "main"]
