"""thermocal's command line.

Each command lives in its own module under :mod:`thermocal.cli` and registers on
:data:`thermocal.cli.application.app`; :func:`main` is the console entry point.  A run imports only
the module of the command it runs (:data:`COMMANDS`), so ``thermocal --version`` and
``import thermocal.cli`` load neither pandas, pyarrow, scipy nor matplotlib.
``--help`` and an unknown command register every command module; those import only typer,
the option declarations (:mod:`thermocal.cli.common`) and :mod:`thermocal.defaults` at their
top, and the maths through :class:`thermocal._lazy.LazyModule` when a command runs, so the
list of commands loads not even numpy.  Command modules do without ``from __future__ import
annotations`` (annotations naming the maths are quoted): typer would otherwise compile every
option's annotation string when it builds the help, a third of ``--help``'s time.
"""

from __future__ import annotations

import importlib
import os
import sys
from typing import Any, Final

import typer

from thermocal.cli.application import app as _app
from thermocal.cli.coercion import install as install_plain_coercion
from thermocal.cli.interrupt import report_interrupted

COMMANDS: dict[str, str] = {
    "inspect": "inspect_cmd",
    "metrics": "metrics_cmd",
    "allan": "allan_cmd",
    "noise": "noise_cmd",
    "profile": "profile_cmd",
    "simulate": "simulate_cmd",
    "fit": "fit_cmd",
    "compensate": "compensate_cmd",
    "validate": "validate_cmd",
    "export-c": "export_cmd",
    "export-params": "export_cmd",
    "px4-tempcal": "tempcal_cmd",
    "ardupilot-tempcal": "tempcal_cmd",
    "turntable": "turntable_cmd",
    "multipos": "multipos_cmd",
    "ratetable": "ratetable_cmd",
    "tumble": "tumble_cmd",
    "report": "report_cmd",
    "fleet": "fleet_cmd",
    "demo": "demo_cmd",
    "station": "station_cmd",
}
"""The one list of commands: each command's module (a test checks it against what the
modules register).  Everything else that lists commands derives from it."""

COMMAND_MODULES: tuple[str, ...] = tuple(dict.fromkeys(COMMANDS.values()))
"""Command modules, registered in this order (a missing module is skipped): the modules of
:data:`COMMANDS`, in its order."""

_REGISTERED: set[str] = set()


def _register(modules: tuple[str, ...] = COMMAND_MODULES) -> None:
    """Import command modules (they register on the app), each once, in list order."""
    for mod in COMMAND_MODULES:
        if mod not in modules or mod in _REGISTERED:
            continue
        try:
            importlib.import_module(f"thermocal.cli.{mod}")
        except ModuleNotFoundError as exc:
            if exc.name != f"thermocal.cli.{mod}":
                raise
        _REGISTERED.add(mod)


def _modules_for(args: list[str]) -> tuple[str, ...]:
    """The command modules a run needs: the named command's; none without a command
    (``--version``, ``--help`` and no arguments list the commands from their summaries,
    :data:`~thermocal.cli.application.COMMAND_SUMMARIES`); all for an unknown command (the
    error suggests the names close to it)."""
    first = next((a for a in args if not a.startswith("-")), None)
    if first is None:
        return ()
    mod = COMMANDS.get(first)
    return (mod,) if mod is not None else COMMAND_MODULES


def __getattr__(name: str) -> Any:
    """``thermocal.cli.app``: the application with every command registered."""
    if name == "app":
        _register()
        return _app
    raise AttributeError(f"module 'thermocal.cli' has no attribute {name!r}")


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

_CLICK: dict[frozenset[str], Any] = {}


def _click_command() -> Any:
    """The application as typer builds it for click, once per set of registered command
    modules: typer rebuilds every command's parameters from their annotations on each call
    of the application (≈ 6 ms a command), which a process running many commands in a row
    (``thermocal fleet``'s units) would pay every time.  Its parameters convert their
    values without pydantic where typer's result is not in doubt
    (:func:`thermocal.cli.coercion.install`)."""
    key = frozenset(_REGISTERED)
    if key not in _CLICK:
        command = typer.main.get_command(_app)
        install_plain_coercion(command)
        _CLICK[key] = command
    return _CLICK[key]


def command_summaries() -> dict[str, str]:
    """Each command's summary as the registered modules give it (every module imported), in
    the order ``--help`` lists them: what
    :data:`~thermocal.cli.application.COMMAND_SUMMARIES` must hold.

    Returns
    -------
    dict of str to str
        Command name → the part of its help its summary shows
        (:func:`~thermocal.cli.application.summary_of`).
    """
    from thermocal.cli.application import summary_of

    _register()
    group = _click_command()
    return {name: summary_of(cmd.help) for name, cmd in group.commands.items()}


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 2 bad input, 1 internal).

    Usage errors (unknown option, missing argument) print one ``error: ...`` line
    on stderr and return 2, as the common rules of the command line ask.  A group run
    without a command (``thermocal``, ``thermocal station``) prints its help on stdout and
    returns 0, as ``--help`` does, on every click and typer version.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status.
    """
    if argv is None:  # the process's own command line
        _quiet_idle_blas_threads()
    status = _run(list(sys.argv[1:] if argv is None else argv))
    if argv is None:  # the process's own command line: it ends next
        _leave_to_exit()
    return status


BLAS_THREAD_TIMEOUT: Final = "4"
"""``OPENBLAS_THREAD_TIMEOUT`` of a command's process: an idle OpenBLAS thread spins 2⁴ cycles
before it sleeps, where the default 2²⁸ (≈ 0.1 s) spins after numpy's import and after every
threaded call, on a core the command's own threads (pyarrow's reader, the kernels') need."""


def _quiet_idle_blas_threads() -> None:
    """Before numpy is imported by the process's own command: OpenBLAS's idle threads told to
    sleep at once (:data:`BLAS_THREAD_TIMEOUT`; a value the user set is kept).  The threads
    still share a large product's work; what goes is their spinning between calls, measured
    at 0.1 s of CPU and up to 0.06 s of wall time on a 2-core machine for ``thermocal allan``
    on 10⁷ rows (``benchmarks/RESULTS.md``).  Nothing changes once numpy is loaded (a
    notebook, the tests), where OpenBLAS has read its environment already."""
    if "numpy" not in sys.modules:
        os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", BLAS_THREAD_TIMEOUT)


def _leave_to_exit() -> None:
    """Before the interpreter exits after a command: the objects alive now are moved out of
    the cyclic garbage collector's reach (:func:`gc.freeze`), so that the interpreter's
    shutdown does not run full collections over the ~40 000 objects numpy, pyarrow, rich and
    typer leave (10–15 ms of CPU a run).  What exit must do still happens: the standard
    streams are flushed by the interpreter, ``atexit`` handlers and finalizers (temporary
    folders) run, every object no cycle holds is freed by reference counting as its module
    is cleared; the few reference cycles left over (threadpoolctl's controllers after an
    ``allan`` run) go back with the process's memory, their finalizers not run."""
    import gc

    gc.freeze()


def _run(args: list[str]) -> int:
    """:func:`main`'s command line run (``args`` without the program name)."""
    _register(_modules_for(args))
    try:
        result = _click_command().main(args=args, prog_name="thermocal", standalone_mode=False)
    except typer.Exit as exc:
        if isinstance(exc.__cause__, KeyboardInterrupt):  # typer >= 0.27 turns Ctrl-C into Exit
            return report_interrupted()
        return int(exc.exit_code)
    except (typer.Abort, KeyboardInterrupt):  # click turns Ctrl-C into Abort
        return report_interrupted()
    except _USAGE_ERRORS as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":  # a group run alone: its help, as --help
            print(exc.ctx.get_help())  # type: ignore[attr-defined]
            return 0
        code = int(getattr(exc, "exit_code", 2))
        text = str(getattr(exc, "format_message", exc.__str__)())
        message = " ".join(text.split()) or "missing command or argument"
        print(f"error: {message} (see --help)", file=sys.stderr)
        return code if code else 2
    except SystemExit as exc:
        status = exc.code
        return status if isinstance(status, int) else (0 if status is None else 1)
    return result if isinstance(result, int) else 0


__all__ = ["app", "command_summaries", "main"]
