"""Shared pieces of the command line: reading options, error handling, output.

INTERFACE.md common rules implemented here:

* ``--json`` prints one JSON object on stdout and nothing else there
  (:func:`emit`); NaN and infinities become ``null``.
* Exit status 0 success; 2 bad input or usage with one line ``error: ...`` on
  stderr and no traceback; 1 internal failure (:func:`handle_errors`).
* Progress bars only on a terminal (:func:`progress`).
"""

from __future__ import annotations

import dataclasses
import errno
import functools
import json
import math
import os
import sys
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, ParamSpec, TypeVar

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.interrupt import report_interrupted
from thermocal.errors import GapWarning, ThermocalInputError, ThermocalWarning

if TYPE_CHECKING:
    import numpy as np
    from rich.console import Console

    from thermocal import units
    from thermocal.models.base import TemperatureModel
    from thermocal.readers.text import TextOptions
    from thermocal.recording import Metadata, Recording
else:
    # this module is imported to register commands (``--help``): nothing heavy at import
    np = LazyModule("numpy")
    units = LazyModule("thermocal.units")

P = ParamSpec("P")
R = TypeVar("R")


class _LazyConsole:
    """A :class:`rich.console.Console` built on first use (``rich.console`` costs start-up)."""

    def __init__(self, **options: Any) -> None:
        self._options = options
        self._console: Console | None = None

    def real(self) -> Console:
        """The console itself (built now if not yet)."""
        if self._console is None:
            from rich.console import Console

            self._console = Console(**self._options)
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
# each command keeps the defaults INTERFACE.md documents for it.

FileArg = Annotated[Path, typer.Argument(help="Recording (CSV or Parquet).", show_default=False)]
ModelArg = Annotated[
    Path, typer.Argument(help="Model file (JSON) written by `thermocal fit`.", show_default=False)
]
TimeOpt = Annotated[str | None, typer.Option("--time", help="Name of the time column.")]
TopicOpt = Annotated[
    str | None,
    typer.Option(
        "--topic", help="PX4 ULog (.ulg): the topic instance, NAME[.N] (default sensor_gyro.0)."
    ),
]
NamesOpt = Annotated[
    str | None,
    typer.Option("--names", help="Text logs without a header row: the column names, a,b,c."),
]
RateOpt = Annotated[
    float | None,
    typer.Option("--rate", help="Text logs without a time column: sample rate [Hz]."),
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


def text_options(
    names: str | None,
    rate: float | None,
    on_bad_lines: str,
    delimiter: str | None,
    decimal: str | None,
) -> TextOptions | None:
    """The text-log options of the command line (None when none is given)."""
    from thermocal.readers.text import TextOptions

    if names is None and rate is None and on_bad_lines == "error" and not delimiter and not decimal:
        return None
    return TextOptions(
        names=tuple(split_names(names) or []) if names is not None else None,
        rate_hz=rate,
        on_bad_lines=on_bad_lines,
        delimiter=delimiter,
        decimal=decimal,
    )


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


def split_names(text: str | None) -> list[str] | None:
    """``"T1, T2,T 3"`` → ``["T1", "T2", "T 3"]`` (None stays None)."""
    if text is None:
        return None
    names = [t.strip() for t in text.split(",")]
    return [n for n in names if n]


def split_floats(text: str | None, what: str) -> list[float] | None:
    """``"25, 30"`` → ``[25.0, 30.0]`` (None stays None); an input error naming the option
    ``what`` when an item is not a number."""
    names = split_names(text)
    if names is None:
        return None
    try:
        return [float(v) for v in names]
    except ValueError:
        raise ThermocalInputError(
            f"{what}: expected comma-separated numbers, got {text!r}"
        ) from None


def parse_temp_conversion(text: str) -> units.TemperatureConversion:
    """``"0.0625,-50"`` → gain [°C/count] 0.0625, offset [°C] −50; ``"0.0625,-50,int16"``
    for signed 16-bit counts stored unsigned (:class:`thermocal.units.TemperatureConversion`)."""
    return units.temperature_conversion(text, "--temp-conversion")


def load_recording(
    path: Path,
    *,
    time: str | None = None,
    time_unit: str | None = None,
    signal: str | None = None,
    temps: str | None = None,
    signal_unit: str | None = None,
    temp_unit: str | None = None,
    meta: Metadata | None = None,
    require_signal: bool = True,
    check: bool = True,
    temp_conversion: str | None = None,
    model_inputs: dict[str, Any] | None = None,
    model: TemperatureModel | None = None,
    keep_other: bool = True,
    text: TextOptions | None = None,
    topic: str | None = None,
) -> Recording:
    """Read a recording with the command line's options (options win over the file).

    ``keep_other=False`` reads only the time, signal and temperature columns (8 bytes a
    row less for every other column, for commands that use no other).

    A signal named with ``--signal`` becomes the first signal; without it the
    file's sidecar roles are used.  With ``require_signal`` a recording with no
    signal at all is an input error.  With ``check`` (INTERFACE.md common rules)
    the time column must be finite and strictly increasing and the signal and
    temperature columns free of NaN (:meth:`Recording.validate`, an input error
    naming the file, column and row); gaps are allowed and reported as one
    :class:`GapWarning`.  ``temp_conversion`` (``"GAIN,OFFSET[,int16]"``) sets the raw-count
    conversion ``T[°C] = GAIN·counts + OFFSET`` of every temperature column.
    ``model`` (a fitted model; or ``model_inputs``, a model file's ``inputs``) fills in
    what the options and the file leave unstated: the time unit, column units and
    temperature conversions as fitted (:meth:`TemperatureModel.input_units`).  Every unit
    is resolved once, by :func:`thermocal.units.resolve_inputs`.
    """
    stated: units.StatedUnits | None = None
    if model is not None:
        stated = model.input_units()
    elif model_inputs is not None:
        stated = units.StatedUnits.from_model_inputs(model_inputs)
    from thermocal.readers.dispatch import read_recording

    rec = read_recording(
        path,
        time=time,
        time_unit=time_unit,
        signals=split_names(signal) if signal else None,  # "gx,gy,gz": several channels
        temperatures=split_names(temps),
        signal_unit=signal_unit,
        temp_unit=temp_unit,
        meta=meta,
        temp_conversion=(
            parse_temp_conversion(temp_conversion) if temp_conversion is not None else None
        ),
        model=stated,
        keep_other=keep_other,
        text=text,
        topic=topic,
    )
    if model is not None or model_inputs is not None:
        from thermocal.models.base import check_sensor_id

        fitted = getattr(model, "inputs_", None) if model is not None else model_inputs
        check_sensor_id(fitted, rec.meta.sensor_id, str(path))
    if require_signal and not rec.signals:
        raise ThermocalInputError(
            f"{path}: name the signal column with --signal; available: "
            + ", ".join(repr(c) for c in rec.columns)
        )
    if check:
        rec.validate()
        gaps = rec.gaps()
        if gaps:
            total = sum(g.length_s for g in gaps)
            warnings.warn(
                GapWarning(
                    f"{path}: {len(gaps)} gaps in time ({total:.6g} s in all), first after "
                    f"row {gaps[0].index} at {gaps[0].start_s:.6g} s"
                ),
                stacklevel=2,
            )
    return rec


def earth_rate_known_input(
    latitude: float | None, axis: str | None, unit: str, where: object
) -> float:
    """Earth rate seen by the sensitive axis [°/h], as a known input of a gyro run.

    ``Ω_axis = Ω u·(0, cos φ, sin φ)`` for the unit axis ``u`` in East-North-Up
    (SPEC §1, :func:`thermocal.units.earth_rate_on_axis_deg_h`); 0 without
    ``--latitude``/``--axis``.  Both options are needed together and
    the signal (canonical unit ``unit``) must be a rate: otherwise an input error naming
    ``where`` (the file).
    """
    if latitude is None and axis is None:
        return 0.0
    if latitude is None or axis is None:
        raise ThermocalInputError("earth-rate removal needs both --latitude and --axis")
    if units.canonical_unit(unit) != "deg/h":
        raise ThermocalInputError(
            f"{where}: --latitude/--axis remove the earth rate from a gyro signal; "
            f"this signal is in {unit}"
        )
    return units.earth_rate_on_axis_deg_h(latitude, units.parse_axis(axis))


def known_input_what(
    latitude: float | None, axis: str | None, other: float | None, gravity: str | None = None
) -> str:
    """What a fit's known input is, for the model file (``inputs.known_input.what``)."""
    parts = []
    if latitude is not None and axis is not None:
        parts.append(f"earth rate at latitude {latitude:g}° on axis {axis}")
    if gravity:
        parts.append(gravity)
    if other:
        parts.append(f"--known-input {other:g}")
    return " + ".join(parts) or "none"


# --- errors ----------------------------------------------------------------------------


def one_line(text: str) -> str:
    return " ".join(str(text).split())


USER_OS_ERRORS: frozenset[int] = frozenset(
    {
        errno.EACCES,
        errno.EPERM,
        errno.EROFS,
        errno.ENOSPC,
        errno.EDQUOT,
        errno.ENAMETOOLONG,
        errno.ENOTDIR,
        errno.EISDIR,
        errno.ENOENT,
        errno.EEXIST,
        errno.EMFILE,
    }
)
"""OS errors a user causes (exit 2 with ``error:``), as opposed to bugs (exit 1)."""


def handle_errors(fn: Callable[P, R]) -> Callable[P, R]:
    """Map exceptions to INTERFACE.md exit statuses.

    :class:`ThermocalInputError` (and ``FileNotFoundError``) → ``error: ...``, exit 2.
    Anything else → ``error: internal: ...``, exit 1 (traceback only when the
    environment variable ``THERMOCAL_DEBUG`` is set).  thermocal warnings are
    printed as one ``warning: ...`` line each on stderr.
    """

    @functools.wraps(fn)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ThermocalWarning)
            try:
                result = fn(*args, **kwargs)
            except (typer.Exit, typer.Abort):
                _show_warnings(caught)
                raise
            except KeyboardInterrupt:
                _show_warnings(caught)
                raise typer.Exit(report_interrupted()) from None
            except (ThermocalInputError, FileNotFoundError, IsADirectoryError) as exc:
                _show_warnings(caught)
                print(f"error: {one_line(str(exc))}", file=sys.stderr)
                raise typer.Exit(2) from None
            except Exception as exc:
                _show_warnings(caught)
                if isinstance(exc, OSError) and exc.errno in USER_OS_ERRORS:
                    # the user's environment, not a bug: permissions, a full disk, ...
                    where = exc.filename if exc.filename is not None else "output"
                    print(f"error: {where}: {exc.strerror or one_line(str(exc))}", file=sys.stderr)
                    raise typer.Exit(2) from None
                if os.environ.get("THERMOCAL_DEBUG"):
                    raise
                print(
                    f"error: internal: {type(exc).__name__}: {one_line(str(exc))}",
                    file=sys.stderr,
                )
                raise typer.Exit(1) from None
        _show_warnings(caught)
        return result

    return wrapper


def _show_warnings(caught: list[warnings.WarningMessage]) -> None:
    seen: set[str] = set()
    for w in caught:
        msg = one_line(str(w.message))
        if msg in seen:
            continue
        seen.add(msg)
        if issubclass(w.category, ThermocalWarning):
            print(f"warning: {msg}", file=sys.stderr)
        elif issubclass(w.category, RuntimeWarning):  # numerical trouble: never hidden
            print(f"warning: {w.category.__name__}: {msg}", file=sys.stderr)


# --- output -------------------------------------------------------------------------------


def jsonable(obj: Any) -> Any:
    """Convert results to plain JSON types: dataclasses → dicts, numpy → Python,
    NaN/inf → ``None``."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return jsonable(obj.item())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def emit(obj: Any, as_json: bool, human: Callable[[], None] | None = None) -> None:
    """Print ``obj`` as one JSON object (``--json``) or call ``human`` for rich output."""
    if as_json:
        sys.stdout.write(json.dumps(jsonable(obj), allow_nan=False) + "\n")
        sys.stdout.flush()
    elif human is not None:
        human()
    else:
        stdout.print_json(json.dumps(jsonable(obj), allow_nan=False))


def fmt(x: float | None, digits: int = 4) -> str:
    """Number for a human table: ``—`` for None/NaN."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    return f"{x:.{digits}g}"


@contextmanager
def progress(description: str, total: float | None = None) -> Iterator[Callable[[float], None]]:
    """A progress bar on a terminal (stderr), silent otherwise.

    Yields ``advance(amount)``.
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
