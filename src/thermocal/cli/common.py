"""Shared pieces of the command line: reading options, error handling, output.

The common rules of the command line, implemented here:

* ``--json`` prints one JSON object on stdout and nothing else there
  (:func:`emit`); NaN and infinities become ``null``.
* Exit status 0 success; 2 bad input or usage with one line ``error: ...`` on
  stderr and no traceback; 1 internal failure (:func:`handle_errors`).
* Progress bars only on a terminal (:func:`progress`).
"""

from __future__ import annotations

import contextvars
import functools
import inspect
import json
import os
import sys
import typing
import warnings
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, ParamSpec, TypeVar

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.interrupt import report_interrupted
from thermocal.errors import ThermocalInputError, ThermocalWarning
from thermocal.pipeline.messages import error_text, warning_lines
from thermocal.pipeline.messages import jsonable as jsonable
from thermocal.pipeline.messages import one_line as one_line
from thermocal.pipeline.reading import check_recording as check_recording
from thermocal.pipeline.reading import read_options as _read_options
from thermocal.pipeline.reading import split_names as split_names
from thermocal.report.text import Block

if TYPE_CHECKING:
    import numpy as np
    from rich.console import Console

    from thermocal import units, writers
    from thermocal.readers.options import ChamberLogSpec, ReadOptions
else:
    # this module is imported to register commands (``--help``): nothing heavy at import
    np = LazyModule("numpy")
    units = LazyModule("thermocal.units")
    writers = LazyModule("thermocal.writers")

P = ParamSpec("P")
R = TypeVar("R")


def split_floats(text: str | None, option: str) -> list[float] | None:
    """``"25, 30"`` → ``[25.0, 30.0]`` (None stays None); an input error naming ``option``
    when an item is not a number.

    Parameters
    ----------
    text : str or None
        The option's comma-separated numbers.
    option : str
        The option, named in the error (``"--breakpoints"``).

    Returns
    -------
    list of float or None
        The numbers.

    Raises
    ------
    ThermocalInputError
        When an item is not a number.

    Examples
    --------
    >>> split_floats("25, 30.5", "--breakpoints")
    [25.0, 30.5]
    """
    names = split_names(text)
    if names is None:
        return None
    try:
        return [float(v) for v in names]
    except ValueError:
        raise ThermocalInputError(
            f"{option}: expected comma-separated numbers, got {text!r}"
        ) from None


WIDTH_OFF_TERMINAL = 10_000
"""Columns of the console when the output is not a terminal: wide enough for any table
(rich tables take their natural width, text is not wrapped: ``soft_wrap``)."""


class _LazyConsole:
    """A :class:`rich.console.Console` built on first use (``rich.console`` costs start-up)."""

    def __init__(self, **options: Any) -> None:
        self._options = options
        self._console: Console | None = None

    def real(self) -> Console:
        """The console itself (built now if not yet).  Outside a terminal (a pipe, a file)
        and without ``COLUMNS`` set, it is :data:`WIDTH_OFF_TERMINAL` wide, so that a table
        wider than 80 columns is printed whole rather than its names cut."""
        if self._console is None:
            from rich.console import Console

            options = dict(self._options)
            stream = sys.stderr if options.get("stderr") else sys.stdout
            if "width" not in options and not os.environ.get("COLUMNS"):
                try:
                    tty = stream.isatty()
                except (AttributeError, ValueError):  # a closed or odd stream
                    tty = False
                if not tty:
                    options["width"] = WIDTH_OFF_TERMINAL
            self._console = Console(**options)
        return self._console

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("__"):
            raise AttributeError(attr)
        return getattr(self.real(), attr)


stdout: Console = _LazyConsole(soft_wrap=True, markup=False)  # type: ignore[assignment]
"""Results on stdout.  No rich markup: units in brackets (``[deg/h]``) and column names such
as ``gx [deg/s]`` must print as they are; prints that style use ``markup=True`` and
escape what they interpolate."""
stderr: Console = _LazyConsole(stderr=True, soft_wrap=True)  # type: ignore[assignment]

# --- reusable option types ----------------------------------------------------------
# Defaults are given where a command uses an alias (``time_unit: TimeUnitOpt = "s"``);
# each command keeps the defaults its help documents.

FileArg = Annotated[Path, typer.Argument(help="Recording (CSV or Parquet).", show_default=False)]
ModelArg = Annotated[
    Path, typer.Argument(help="Model file (JSON) written by `thermocal fit`.", show_default=False)
]
TimeOpt = Annotated[str | None, typer.Option("--time", help="Name of the time column.")]
TopicOpt = Annotated[
    str | None,
    typer.Option(
        "--topic",
        "--sensor",
        help="Flight-controller log: the message/topic instance, NAME[.N] (default "
        "sensor_gyro.0 for a .ulg); station recording folder: the sensor's ID; ROS bag or "
        "MCAP: the Imu topic, or IMU_TOPIC,TEMPERATURE_TOPIC.",
    ),
]
LogTopicOpt = Annotated[
    str | None,
    typer.Option(
        "--topic",
        help="Flight-controller log: the message/topic instance, NAME[.N]; station "
        "recording folder: the sensor's ID (--sensor also picks it and labels the report).",
    ),
]
"""``--topic`` without ``--sensor`` (``report`` has its own ``--sensor``: the report's label)."""
StampOpt = Annotated[
    str,
    typer.Option(
        "--stamp",
        help="ROS bag or MCAP: the time of each message, header (its header stamp, when the "
        "sensor sampled) or receive (when the recorder wrote it).",
    ),
]
NamesOpt = Annotated[
    str | None,
    typer.Option("--names", help="Text logs without a header row: the column names, a,b,c."),
]
RateOpt = Annotated[
    float | None,
    typer.Option(
        "--rate",
        help="Sample rate [Hz]: the time of a log without a time column, of a sample counter "
        "(n_samples, or --time N), or host timestamps taken at this nominal rate.",
    ),
]
OnBadLinesOpt = Annotated[
    str,
    typer.Option(
        "--on-bad-lines",
        help="Mangled lines in a text log: error (name the first) or skip (drop, count).",
    ),
]
DelimiterOpt = Annotated[
    str | None,
    typer.Option("--delimiter", help="Text logs: the field delimiter (default: detected)."),
]
DecimalOpt = Annotated[
    str | None,
    typer.Option("--decimal", help="Text logs: the decimal mark, . or , (default: detected)."),
]


TimeUnitOpt = Annotated[str | None, typer.Option("--time-unit", help="Time unit: s, ms or us.")]
SignalOpt = Annotated[
    str | None, typer.Option("--signal", help="Name of the sensor-output column.")
]
ModelSignalOpt = Annotated[
    str | None,
    typer.Option("--signal", help="Signal column (default: the model's signal name)."),
]
"""``--signal`` of the commands that read a model file: its default is the model's signal."""
TempsOpt = Annotated[
    str | None,
    typer.Option("--temps", help="Comma-separated temperature column names."),
]
SignalUnitOpt = Annotated[
    str | None,
    typer.Option(
        "--signal-unit",
        help="Signal unit: deg/h, deg/s, rad/s, mg, g, m/s^2, counts (default deg/h).",
    ),
]
TempUnitOpt = Annotated[
    str | None, typer.Option("--temp-unit", help="Temperature unit: degC or counts.")
]
TempConversionOpt = Annotated[
    str | None,
    typer.Option(
        "--temp-conversion",
        help="Raw-count temperatures: 'GAIN,OFFSET' with T[°C] = GAIN·counts + OFFSET, or "
        "'GAIN,OFFSET,int16' for signed 16-bit counts stored unsigned (v >= 32768 -> "
        "v - 65536 first), for every temperature column (overrides the file's metadata).",
    ),
]
LatitudeOpt = Annotated[
    float | None, typer.Option("--latitude", help="Test-site latitude [°] (earth rate).")
]
AxisOpt = Annotated[
    str | None,
    typer.Option(
        "--axis", help="Sensitive axis: up, down, north, south, east, west or 'e,n,u' (ENU)."
    ),
]
ExtrapolateOpt = Annotated[
    bool,
    typer.Option(
        "--extrapolate",
        help="Evaluate the model outside its fitted temperature range instead of clamping.",
    ),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")]
AllowNarrowOpt = Annotated[
    bool,
    typer.Option(
        "--allow-narrow",
        help="Calibrate even where the sweep is too narrow for the model (span, samples, Ṫ "
        "range), with a warning recorded in the calibration.",
    ),
]
AllowMotionOpt = Annotated[
    bool,
    typer.Option(
        "--allow-motion",
        help="Calibrate even where the sensor moved during the record, with a warning.",
    ),
]
TurntableLatitudeOpt = Annotated[
    float | None,
    typer.Option(
        "--latitude",
        help="Site latitude [°] of a turntable run (a calibration of triads; default: "
        "the file's metadata).",
    ),
]
OutOpt = Annotated[Path, typer.Option("-o", "--output", help="Output file.")]
ConfidenceOpt = Annotated[
    float, typer.Option("--confidence", help="Confidence level of the intervals.")
]
"""``--confidence`` of the commands that give deviations with intervals (allan, noise)."""
TriadAccelUnitOpt = Annotated[
    str | None,
    typer.Option("--accel-unit", help="Accelerometer unit: m/s^2, mg, g (default: file's)."),
]
"""``--accel-unit`` of the triad calibrations (multipos, turntable)."""


def parse_temp_conversion(text: str) -> units.TemperatureConversion:
    """``"0.0625,-50"`` → gain [°C/count] 0.0625, offset [°C] −50; ``"0.0625,-50,int16"``
    for signed 16-bit counts stored unsigned (:class:`thermocal.units.TemperatureConversion`).

    Parameters
    ----------
    text : str
        The option's text.

    Returns
    -------
    TemperatureConversion

    Raises
    ------
    ThermocalInputError
        Not ``GAIN,OFFSET[,int16]`` with finite numbers.
    """
    return units.temperature_conversion(text, "--temp-conversion")


# --- errors ----------------------------------------------------------------------------


def handle_errors(fn: Callable[P, R]) -> Callable[P, R]:
    """Map exceptions to the exit statuses of the command line.

    :class:`ThermocalInputError` (and ``FileNotFoundError``) → ``error: ...``, exit 2.
    Anything else → ``error: internal: ...``, exit 1 (traceback only when the
    environment variable ``THERMOCAL_DEBUG`` is set).  thermocal warnings are
    printed as one ``warning: ...`` line each on stderr.

    Parameters
    ----------
    fn : callable
        The command's function.

    Returns
    -------
    callable
        ``fn`` wrapped: exit 2 with one ``error:`` line for the user's errors, 1 for thermocal's
        own.
    """

    @functools.wraps(fn)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ThermocalWarning)
            try:
                result = fn(*args, **kwargs)
            except (typer.Exit, typer.Abort):
                _show_warnings(caught, fn)
                raise
            except KeyboardInterrupt:
                _show_warnings(caught, fn)
                raise typer.Exit(report_interrupted()) from None
            except Exception as exc:  # the mapping the fleet uses too (error_text)
                _show_warnings(caught, fn)
                text, users = error_text(exc, _command_options(fn))
                if not users and os.environ.get("THERMOCAL_DEBUG"):
                    raise
                print(f"error: {text}", file=sys.stderr)
                raise typer.Exit(2 if users else 1) from None
        _show_warnings(caught, fn)
        return result

    return wrapper


def _command_options(fn: Callable[..., Any]) -> dict[str, str]:
    """``{parameter: option}`` of a command function (``rate_hz`` → ``--rate-hz`` for
    ``simulate``), read from its ``Annotated[..., typer.Option("--name")]`` declarations;
    empty when they cannot be read."""
    try:
        hints = typing.get_type_hints(fn, include_extras=True)
    except Exception:  # a courtesy for the message: never fails the error path
        return {}
    out: dict[str, str] = {}
    for name, hint in hints.items():
        for info in getattr(hint, "__metadata__", ()):
            first = getattr(info, "default", None)  # Annotated: the first declaration
            given = (first, *(getattr(info, "param_decls", None) or ()))
            # a flag's "--name/--no-name" is named by its first spelling
            decls = [d.split("/")[0] for d in given if isinstance(d, str) and d.startswith("--")]
            if isinstance(info, typer.models.OptionInfo):
                out[name] = decls[0] if decls else "--" + name.replace("_", "-")
    return out


def _show_warnings(caught: list[warnings.WarningMessage], fn: Callable[..., Any]) -> None:
    """One ``warning: ...`` line on stderr per message (:func:`warning_lines`), with the
    options of the command ``fn`` where a warning names the library's parameters."""
    if not caught:
        return
    for line in warning_lines(caught, _command_options(fn)):
        print(f"warning: {line}", file=sys.stderr)


# --- output -------------------------------------------------------------------------------


def emit(obj: Any, as_json: bool, human: Callable[[], None] | None = None) -> None:
    """Print ``obj`` as one JSON object (``--json``) or call ``human`` for rich output.

    Parameters
    ----------
    obj : object
        What to print.
    as_json : bool
        Print JSON instead of text.
    human : callable, optional
        Prints the human output.
    """
    if as_json:
        sys.stdout.write(json.dumps(jsonable(obj), allow_nan=False) + "\n")
        sys.stdout.flush()
    elif human is not None:
        human()
    else:
        stdout.print_json(json.dumps(jsonable(obj), allow_nan=False))


def show(blocks: Iterable[Block]) -> None:
    """Print a text rendering (:mod:`thermocal.report.text`) on stdout: each line as it is,
    each table drawn by rich with its title, columns, justification and rows.

    Parameters
    ----------
    blocks : iterable of str or TextTable
        What to print, in order.
    """
    from rich.table import Table

    for b in blocks:
        if isinstance(b, str):
            stdout.print(b)
            continue
        t = Table(title=b.title)
        for name, justify in zip(b.columns, b.justify, strict=True):
            t.add_column(name, justify="right" if justify == "right" else "left")
        for row in b.rows:
            t.add_row(*row)
        stdout.print(t)


@contextmanager
def progress(description: str, total: float | None = None) -> Iterator[Callable[[float], None]]:
    """A progress bar on a terminal (stderr), silent otherwise.

    Yields ``advance(amount)``.

    Parameters
    ----------
    description : str
        The bar's label.
    total : float, optional
        The total (None: no percentage).

    Returns
    -------
    contextmanager
        Yields a function that advances the bar.
    """
    if not sys.stderr.isatty():
        yield lambda _amount: None
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.percentage:>3.0f}%"),
        TimeElapsedColumn(),
        console=stderr.real() if isinstance(stderr, _LazyConsole) else stderr,
        transient=True,
    ) as bar:
        task = bar.add_task(description, total=total)
        yield lambda amount: bar.advance(task, amount)


HeaterOpt = Annotated[
    str,
    typer.Option(
        "--heater",
        help="A heated IMU's hold at its set-point (within ±0.5 °C for 60 s): cut (fit the "
        "sweep up to the set-point, the hold weighing no more than the sweep, and say the "
        "range is cut), refuse (a range cut by the heater is an error) or ignore (no hold "
        "looked for).",
    ),
]
HeaterSetpointOpt = Annotated[
    float | None,
    typer.Option(
        "--heater-setpoint",
        help="The heater's set-point [°C] (default: the flight-controller log's "
        "SENS_IMU_TEMP or BRD_HEAT_TARG in px4-tempcal and ardupilot-tempcal, else inferred "
        "from the one plateau at the top of the temperature).",
    ),
]
HeaterBandOpt = Annotated[
    float,
    typer.Option(
        "--heater-band",
        help="Half-width [°C] of the band a heater's hold stays in (default 0.5; 1 for a "
        "thermometer that reads whole degrees).",
    ),
]
HeaterMinHoldOpt = Annotated[
    float,
    typer.Option("--heater-min-hold", help="Shortest heater hold [s] (default 60)."),
]


# --- a chamber's own log, joined by time (every recording command) --------------------------

ChamberLogOpt = Annotated[
    str | None,
    typer.Option(
        "--chamber-log",
        help="The chamber's or data logger's own log (CSV/TSV with an hh:mm[:ss] clock), "
        "FILE or FILE:CHANNEL: its channel joined by time to the recording as the temperature "
        "column 'chamber' (--temps T,chamber; --ambient chamber). The clocks' offset is "
        "--chamber-offset, or from absolute times (--chamber-tz), or found by correlating the "
        "recording's own temperature (offset and drift stated in a warning).",
    ),
]
ChamberUnitOpt = Annotated[
    str | None,
    typer.Option("--chamber-unit", help="The chamber log's unit: degF, degC or K (default: "
                 "its header)."),
]  # fmt: skip
ChamberDateOpt = Annotated[
    str | None,
    typer.Option("--chamber-date", help="The chamber log's first date, YYYY-MM-DD (a log with "
                 "no dates whose clock passes midnight)."),
]  # fmt: skip
ChamberDateOrderOpt = Annotated[
    str | None,
    typer.Option("--chamber-date-order", help="How the chamber log's dates read: dmy "
                 "(03/04 is 3 April) or mdy (4 March)."),
]  # fmt: skip
ChamberOffsetOpt = Annotated[
    float | None,
    typer.Option("--chamber-offset", help="Where the recording's first sample falls on the "
                 "chamber log's clock [s], counted from the log's first row."),
]  # fmt: skip
ChamberDriftOpt = Annotated[
    float | None,
    typer.Option("--chamber-drift", help="The chamber log clock's gain on the recording's "
                 "[ppm], with --chamber-offset (default 0)."),
]  # fmt: skip
ChamberTzOpt = Annotated[
    str | None,
    typer.Option("--chamber-tz", help="The chamber log's time zone, +HH:MM from UTC, when the "
                 "recording's time is absolute (UTC)."),
]  # fmt: skip

_CHAMBER_OPTIONS: tuple[tuple[str, Any], ...] = (
    ("chamber_log", ChamberLogOpt), ("chamber_unit", ChamberUnitOpt),
    ("chamber_date", ChamberDateOpt), ("chamber_date_order", ChamberDateOrderOpt),
    ("chamber_offset", ChamberOffsetOpt), ("chamber_drift", ChamberDriftOpt),
    ("chamber_tz", ChamberTzOpt),
)  # fmt: skip
"""The chamber-log options every recording command takes (:func:`chamber_log_options`)."""

_CHAMBER: contextvars.ContextVar[ChamberLogSpec | None] = contextvars.ContextVar(
    "chamber_log", default=None
)


def chamber_spec(given: dict[str, Any]) -> ChamberLogSpec | None:
    """The :class:`~thermocal.readers.options.ChamberLogSpec` of the chamber-log options
    (None without ``--chamber-log``; the others alone are refused).

    Parameters
    ----------
    given : dict
        ``chamber_log``, ``chamber_unit``, … as typed.

    Returns
    -------
    ChamberLogSpec or None

    Raises
    ------
    ThermocalInputError
        A chamber option without ``--chamber-log``.
    """
    from thermocal.readers.options import ChamberLogSpec

    text = given.get("chamber_log")
    if text is None:
        others = [n for n, v in given.items() if v is not None]
        if others:
            raise ThermocalInputError(
                f"--{others[0].replace('_', '-')} applies with --chamber-log FILE[:CHANNEL]"
            )
        return None
    if given.get("chamber_drift") is not None and given.get("chamber_offset") is None:
        raise ThermocalInputError(
            "--chamber-drift applies with --chamber-offset (found by correlation, the drift "
            "is estimated)"
        )
    return ChamberLogSpec.parse(
        text, unit=given.get("chamber_unit"), date=given.get("chamber_date"),
        date_order=given.get("chamber_date_order"), offset_s=given.get("chamber_offset"),
        drift_ppm=given.get("chamber_drift"), tz=given.get("chamber_tz"),
    )  # fmt: skip


def chamber_log_options(fn: Callable[P, R]) -> Callable[P, R]:
    """Give a command the chamber-log options (``--chamber-log FILE[:CHANNEL]`` and
    ``--chamber-unit``, ``--chamber-date``, ``--chamber-date-order``, ``--chamber-offset``,
    ``--chamber-drift``, ``--chamber-tz``): they are added to its signature, taken off its
    arguments and, while it runs, put into every :func:`read_options` it builds
    (:func:`current_chamber_log` for options objects built otherwise).

    Parameters
    ----------
    fn : callable
        The command's function (below :func:`handle_errors`).

    Returns
    -------
    callable
        The command with the options.
    """
    sig = inspect.signature(fn, eval_str=True)
    extra = [
        inspect.Parameter(n, inspect.Parameter.KEYWORD_ONLY, annotation=a, default=None)
        for n, a in _CHAMBER_OPTIONS
    ]
    kept = [p for p in sig.parameters.values() if p.kind != inspect.Parameter.VAR_KEYWORD]

    @functools.wraps(fn)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        given = {n: kwargs.pop(n, None) for n, _ in _CHAMBER_OPTIONS}
        token = _CHAMBER.set(chamber_spec(given))
        try:
            return fn(*args, **kwargs)
        finally:
            _CHAMBER.reset(token)

    wrapper.__signature__ = sig.replace(parameters=[*kept, *extra])  # type: ignore[attr-defined]
    wrapper.__annotations__ = {
        **{p.name: p.annotation for p in kept},
        **{n: a for n, a in _CHAMBER_OPTIONS},
    }
    return wrapper


def current_chamber_log() -> ChamberLogSpec | None:
    """The chamber log of the command running (:func:`chamber_log_options`), or None.

    Returns
    -------
    ChamberLogSpec or None
    """
    return _CHAMBER.get()


def read_options(**given: Any) -> ReadOptions:
    """:func:`thermocal.pipeline.reading.read_options` with the running command's chamber
    log (:func:`chamber_log_options`).

    Parameters
    ----------
    **given
        As :func:`thermocal.pipeline.reading.read_options` takes them.

    Returns
    -------
    ReadOptions
    """
    r = _read_options(**given)
    spec = _CHAMBER.get()
    return r if spec is None else r.replace(chamber_log=spec)


# --- how a file is read, and a result's files (the commands of one test: tumble, ratetable) ---

ResultOpt = Annotated[
    Path | None, typer.Option("-o", "--output", help="Also write the result as JSON here.")
]
"""``-o`` of a command whose result also goes to a JSON file (beside ``--report``)."""

_FILE_READ_OPTIONS: tuple[tuple[str, Any, Any], ...] = (
    ("names", NamesOpt, None), ("topic", TopicOpt, None), ("stamp", StampOpt, "header"),
    ("rate", RateOpt, None), ("on_bad_lines", OnBadLinesOpt, "error"),
    ("delimiter", DelimiterOpt, None), ("decimal", DecimalOpt, None),
)  # fmt: skip
"""How a file is read beyond its columns: a text log's layout, a flight log's topic, a bag's
topic and stamps (:func:`file_read_options`)."""


def file_read_options(fn: Callable[P, R]) -> Callable[P, R]:
    """Give a command the options of how its files are read (``--names``, ``--topic``,
    ``--stamp``, ``--rate``, ``--on-bad-lines``, ``--delimiter``, ``--decimal``): they are
    added to its signature in place of its parameter ``read``, which receives their
    :func:`read_options` (with the running command's chamber log: put
    :func:`chamber_log_options` above this decorator).

    Parameters
    ----------
    fn : callable
        The command's function, with a keyword parameter ``read``.

    Returns
    -------
    callable
        The command with the options.
    """
    sig = inspect.signature(fn)  # ``read``'s annotation may name a type not imported
    extra = [inspect.Parameter(n, inspect.Parameter.KEYWORD_ONLY, annotation=a, default=d)
             for n, a, d in _FILE_READ_OPTIONS]  # fmt: skip
    kept = [p for p in sig.parameters.values() if p.name != "read"]

    @functools.wraps(fn)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        given = {n: kwargs.pop(n, d) for n, _, d in _FILE_READ_OPTIONS}
        return fn(*args, read=read_options(**given), **kwargs)  # type: ignore[arg-type]

    wrapper.__signature__ = sig.replace(parameters=[*kept, *extra])  # type: ignore[attr-defined]
    wrapper.__annotations__ = {
        **{p.name: p.annotation for p in kept},
        **{n: a for n, a, _ in _FILE_READ_OPTIONS},
    }
    return wrapper


def check_result_outputs(
    output: Path | None, report: Path | None, inputs: list[str | Path]
) -> None:
    """Refuse a result's JSON (``-o``) or HTML page (``--report``) over an input, or both
    in one file.

    Parameters
    ----------
    output, report : Path or None
        The files asked for.
    inputs : list of str or Path
        The command's input files.

    Raises
    ------
    ThermocalInputError
        An output over an input (:func:`thermocal.writers.check_not_input`), or ``-o`` and
        ``--report`` naming one file.
    """
    for out in (output, report):
        if out is not None:
            writers.check_not_input(out, inputs)
    if output is not None and output == report:
        raise ThermocalInputError("-o and --report name the same file; give two files")


def write_result_outputs(
    result: dict[str, Any], output: Path | None, report: Path | None, html: Callable[[], str]
) -> None:
    """Write a result's JSON (``-o``) and HTML page (``--report``, ``html()`` built only
    then), each to a temporary renamed.

    Parameters
    ----------
    result : dict
        The result as JSON.
    output, report : Path or None
        The files asked for.
    html : callable
        Builds the page.
    """
    if output is not None:
        writers.write_json(output, result)
    if report is not None:
        writers.write_html(report, html())
