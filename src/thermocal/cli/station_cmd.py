"""``thermocal station check|run``: the test station.

Thin: parse, call :func:`thermocal.station.check.check_station` or
:func:`thermocal.station.run.run_station`, print.  pymodbus and pyserial are imported when a
command runs (``pip install 'thermocal[station]'``).
"""

import signal
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import JsonOpt, emit, handle_errors, stdout
from thermocal.cli.interrupt import EXIT_INTERRUPTED

if TYPE_CHECKING:
    import thermocal.profiles as _profiles
    import thermocal.readers.program as _program
    import thermocal.station.check as _check
    import thermocal.station.config as _config
    import thermocal.station.display as _display
    import thermocal.station.run as _run
else:
    _profiles = LazyModule("thermocal.profiles")
    _program = LazyModule("thermocal.readers.program")
    _check = LazyModule("thermocal.station.check")
    _config = LazyModule("thermocal.station.config")
    _display = LazyModule("thermocal.station.display")
    _run = LazyModule("thermocal.station.run")

station_app = typer.Typer(
    help="The test station: drive the chamber over Modbus and record serial sensors into a "
    "crash-safe folder that every command reads as one recording.",
    no_args_is_help=True,
)
app.add_typer(station_app, name="station")

StationArg = Annotated[
    Path, typer.Argument(help="STATION.toml: [chamber] and [[sensor]] tables.", show_default=False)
]


@station_app.command("check")
@handle_errors
def check_cmd(
    station: StationArg,
    listen: Annotated[
        float, typer.Option("--listen", help="Seconds to listen to each sensor [s].")
    ] = 3.0,
    as_json: JsonOpt = False,
) -> None:
    """Connect to the chamber and every sensor; print the chamber's temperature and
    set-point and each sensor's rate and first parsed line.  Exit 2 naming what did not
    answer."""
    cfg = _config.load_station(station)
    res = _check.check_station(cfg, listen)
    out = res.to_dict()

    def human() -> None:
        for line in res.text():
            stdout.print(line)

    emit(out, as_json, human)
    if res.failed:
        print("error: did not answer: " + "; ".join(res.failed), file=sys.stderr)
        raise typer.Exit(2)


STOP_SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP")
"""Signals that end a run with the safe stop (a hang-up: the operator's terminal or ssh
session went away)."""


class _StopFlag:
    """Signal handlers that only note the signal: the loop sees it within one turn and
    stops safely; a second signal cannot interrupt the safe stop itself."""

    def __init__(self) -> None:
        self.signum = 0
        self._old: dict[int, Any] = {}

    def __enter__(self) -> "_StopFlag":
        for name in STOP_SIGNALS:
            if hasattr(signal, name):
                num = getattr(signal, name)
                self._old[num] = signal.signal(num, self._note)
        return self

    def __exit__(self, *_exc: object) -> None:
        for num, old in self._old.items():
            signal.signal(num, old)

    def _note(self, signum: int, _frame: Any) -> None:
        self.signum = self.signum or signum

    def __call__(self) -> str:
        return signal.Signals(self.signum).name if self.signum else ""


@station_app.command("run")
@handle_errors
def run_cmd(
    station: StationArg,
    profile: Annotated[
        Path,
        typer.Option(
            "--profile", help="Chamber program CSV (time_s, setpoint_c).", show_default=False
        ),
    ],
    output: Annotated[
        Path, typer.Option("-o", "--output", help="Recording folder.", show_default=False)
    ],
    resume: Annotated[
        bool, typer.Option("--resume", help="Continue the program where DIR's recording ends.")
    ] = False,
    time_scale: Annotated[
        float, typer.Option("--time-scale", help="Run the program K times faster (rehearsals).")
    ] = 1.0,
    as_json: JsonOpt = False,
) -> None:
    """Run the chamber program and record every sensor and the chamber into DIR.

    Ctrl-C, SIGTERM, a hang-up (the terminal or ssh session gone), a closed stderr, an
    error or the end of the program writes the safe set-point and closes every file;
    continue an interrupted run with --resume (it says how the last run ended and where it
    left the chamber).
    """
    cfg = _config.load_station(station)
    prog_t, prog_c = _program.read_program(profile)
    live = sys.stderr is not None and sys.stderr.isatty() and not as_json  # None: 2>&-
    disp = _display.RichDisplay() if live else _run.LogDisplay()
    flag = _StopFlag()
    try:
        with flag:
            res = _run.run_station(
                cfg, (list(prog_t), list(prog_c)), output, profile_source=str(profile),
                resume=resume, time_scale=time_scale, display=disp, should_stop=flag,
            )  # fmt: skip
    except KeyboardInterrupt:
        res = None
    finally:
        if live:
            disp.close()  # type: ignore[union-attr]
    if res is None or res.ended == "interrupted":
        why = "" if res is None or not res.stop_reason else f" ({res.stop_reason})"
        safe = (
            "safe set-point written as logged above"
            if res is None or (res.safe_setpoint_c is not None)
            else "the safe set-point could NOT be written"
        )
        _run.say(
            f"interrupted{why}: {safe}; the closed parts in {output} are kept (the part open "
            "at the interruption was closed too); continue with --resume"
        )  # fmt: skip
        raise typer.Exit(128 + flag.signum if flag.signum else EXIT_INTERRUPTED)
    out = {
        "out_dir": str(res.out_dir),
        "ended": res.ended,
        "program_start_s": res.program_start_s,
        "program_end_s": res.program_end_s,
        "parts": res.parts,
        "samples": res.samples,
        "bad_lines": res.bad_lines,
        "setpoints_written": len(res.setpoints),
        "safe_setpoint_c": res.safe_setpoint_c,
    }

    def human() -> None:
        stdout.print(
            f"recorded {sum(res.samples.values()):,} samples into {res.out_dir} "
            f"({len(res.parts)} parts), program {res.program_start_s:.0f}–"
            f"{res.program_end_s:.0f} s, ended: {res.ended}; bad lines: "
            + ", ".join(f"{k} {v}" for k, v in res.bad_lines.items())
        )

    emit(out, as_json, human)
