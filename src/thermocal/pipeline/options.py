"""The options of ``thermocal fit`` and ``thermocal validate`` as frozen dataclasses.

One field per long option of the command, named as the option without its dashes and
with underscores (the option of ``time_unit`` is written with a dash), with the command's
default; a fit's family options are
one field, ``params`` (constructor parameter → value, as the family declares them in
:mod:`thermocal.families`).  The command line builds them from its parameters, a fleet
configuration from its ``[fit]``/``[validate]`` tables (:func:`options_from_table`), and a
test checks that the fields, the families' declared options and the command's options are
the same set.  What the command takes besides (its files, its output, its JSON switch) is
not an option here.
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, TypeVar

from thermocal.defaults import DEFAULT_AVERAGING_S
from thermocal.errors import ParameterError, ThermocalInputError, UnitError
from thermocal.families import FamilyOption, fit_option_table
from thermocal.pipeline.messages import option_name

if TYPE_CHECKING:  # numpy and the readers: imported when used (``fit --help`` loads neither)
    from thermocal.readers.options import ChamberLogSpec, ReadOptions
    from thermocal.units import TemperatureConversion

TARGETS = ("bias", "scale_factor")
"""What a fit's model describes."""


def _names(value: str | Iterable[str] | None, parameter: str) -> tuple[str, ...] | None:
    """``"a, b"`` or ``["a", "b"]`` → ``("a", "b")``; None or no name → None."""
    if value is None:
        return None
    items = value.split(",") if isinstance(value, str) else list(value)
    if not all(isinstance(v, str) for v in items):
        raise ParameterError(parameter, f"{{name}} holds column names, got {value!r}")
    return tuple(v.strip() for v in items if v.strip()) or None


@dataclass(frozen=True)
class FitOptions:
    """The options of a fit (:func:`thermocal.pipeline.fit.fit_files`, ``thermocal fit``).

    Parameters
    ----------
    model : str
        The family (``"poly"``, ``"piecewise"``, ``"warmup"``, ``"bank"`` or a plugin's).
    params : mapping of str to object
        The family's options by constructor parameter, as the family declares them
        (:class:`thermocal.families.FamilyOption`: ``{"order": 2, "rate_interval_s": 60.0}``,
        ``{"breakpoints": (25.0, 30.0)}``); each is checked against its declared type and
        bounds before a file is read.
    signals : tuple of str, optional
        The signal columns; several make a calibration of one model per channel.  A
        comma-separated text is accepted and stored as a tuple.
    temperatures : tuple of str, optional
        The temperature columns (default: the file's), as ``signals``.
    time, time_unit, signal_unit, temp_unit : str, optional
        The time column and the units of the columns (default: the file's).
    temp_conversion : TemperatureConversion, optional
        Raw counts → °C, :math:`T = g\\,v + o` (the text ``"GAIN,OFFSET[,int16]"`` is
        accepted).
    target : {"bias", "scale_factor"}
        What the model describes.
    latitude : float, optional
        Test-site latitude [°]; with ``axis``, the earth rate seen by a gyro's axis is a
        known input.
    axis : str, optional
        A gyro's sensitive axis (``"up"``, ``"north"``, … or ``"e,n,u"``).
    known_input : float, optional
        Any other known input, in the canonical signal unit ([°/h] or [mg]).
    gravity_axis : str, optional
        Accelerometers: the body axis pointing up (``"+z"``); its gravity is a known input.
    gravity : float, optional
        Local gravity [m/s²] (default: WGS-84 normal gravity at ``latitude``).
    tref : float, optional
        poly: also give the coefficients about this reference temperature [°C].
    allow_narrow, allow_motion : bool
        Fit even where the data fail the adequacy tests (with a warning recorded).
    names : tuple of str, optional
        Column names of a text log without a header row.
    topic : str, optional
        Flight-controller log topic, or a station recording's sensor.
    rate_hz : float, optional
        Sample rate [Hz] of a log without a time column.
    on_bad_lines : {"error", "skip"}
        A mangled line of a text log: an error naming it, or dropped and counted.
    delimiter : str, optional
        Field separator of a text log (detected when None).
    decimal : {".", ","}, optional
        Decimal mark of a text log (detected when None).
    stamp : {"header", "receive"}
        Time of a ROS bag's messages: their header stamp (default) or the bag's receive
        time.
    chamber_log : ChamberLogSpec, optional
        A chamber's own log joined by time to each file (its column ``chamber``).
    heater : {"cut", "refuse", "ignore"}
        A heated sensor's hold at its set-point (:class:`thermocal.heater.HeaterPolicy`):
        thinned to the sweep's density with the cut range said (default), refused, or
        not looked for.
    heater_setpoint : float, optional
        The heater's set-point [°C]; default inferred from the one plateau at the top of
        the first temperature column after a 10 °C sweep (never for the warmup family,
        whose plateau is what it models).
    heater_band, heater_min_hold : float
        The hold's half-width [°C] (default 0.5) and shortest duration [s] (default 60).
    temperature : {"reconstructed", "raw"}
        A quantised or slow thermometer (:mod:`thermocal.thermometer`: a lattice of 0.1 °C or
        more, or updated every second or slower) fitted on the temperature reconstructed at
        each sample (default), or on its reading as logged.
    legs : {"all", "heating", "cooling"}
        Every sample, or only the heating (cooling) legs of the first temperature column
        (:func:`thermocal.legs.find_legs`), each leg a run.

    Raises
    ------
    thermocal.errors.ParameterError
        A target, column list, temperature conversion, heater policy or temperature mode no
        fit can use,
        naming the field.

    Examples
    --------
    >>> from thermocal.pipeline.options import FitOptions
    >>> o = FitOptions("poly", {"order": 2}, signals="gx, gy", temperatures=["T1"])
    >>> o.signals, o.temperatures
    (('gx', 'gy'), ('T1',))
    >>> o.read_options.signals
    ('gx', 'gy')
    """

    model: str
    params: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    signals: tuple[str, ...] | None = None
    temperatures: tuple[str, ...] | None = None
    time: str | None = None
    time_unit: str | None = None
    signal_unit: str | None = None
    temp_unit: str | None = None
    temp_conversion: TemperatureConversion | None = None
    target: Literal["bias", "scale_factor"] = "bias"
    latitude: float | None = None
    axis: str | None = None
    known_input: float | None = None
    gravity_axis: str | None = None
    gravity: float | None = None
    tref: float | None = None
    allow_narrow: bool = False
    allow_motion: bool = False
    # how the files are read (text logs, ULog)
    names: tuple[str, ...] | None = None
    topic: str | None = None
    rate_hz: float | None = None
    on_bad_lines: Literal["error", "skip"] = "error"
    delimiter: str | None = None
    decimal: Literal[".", ","] | None = None
    stamp: Literal["header", "receive"] = "header"
    chamber_log: ChamberLogSpec | None = None
    heater: Literal["cut", "refuse", "ignore"] = "cut"
    heater_setpoint: float | None = None
    heater_band: float = 0.5
    heater_min_hold: float = 60.0
    temperature: Literal["reconstructed", "raw"] = "reconstructed"
    legs: Literal["all", "heating", "cooling"] = "all"

    def __post_init__(self) -> None:
        set_ = object.__setattr__  # frozen: normalise in place once
        if self.legs not in ("all", "heating", "cooling"):
            raise ParameterError(
                "legs", f"{{name}} must be all, heating or cooling, got {self.legs!r}"
            )
        if self.temperature not in ("reconstructed", "raw"):
            raise ParameterError(
                "temperature", f"{{name}} must be reconstructed or raw, got {self.temperature!r}"
            )
        if self.heater not in ("cut", "refuse", "ignore"):
            raise ParameterError(
                "heater", f"{{name}} must be cut, refuse or ignore, got {self.heater!r}"
            )
        sp = self.heater_setpoint
        if sp is not None and not -273.15 < sp < float("inf"):
            raise ParameterError(
                "heater_setpoint",
                f"{{name}} must be a finite temperature above −273.15 °C, got {sp}",
            )
        for name in ("heater_band", "heater_min_hold"):
            if not 0.0 < getattr(self, name) < float("inf"):
                raise ParameterError(name, f"{{name}} must be positive, got {getattr(self, name)}")
        for field in ("signals", "temperatures", "names"):
            set_(self, field, _names(getattr(self, field), field))
        if self.temp_conversion is not None:
            set_(self, "temp_conversion", _conversion(self.temp_conversion))
        if self.target not in TARGETS:
            raise ParameterError(
                "target", f"{{name}} must be bias or scale_factor, got {self.target!r}"
            )

    @property
    def read_options(self) -> ReadOptions:
        """How the files are read (:class:`thermocal.readers.options.ReadOptions`)."""
        return _read_options(self, self.temperatures)


@dataclass(frozen=True)
class ValidateOptions:
    """The options of a validation (:func:`thermocal.pipeline.validate.validate_files`,
    ``thermocal validate``).

    The text-log fields (``names``, ``rate_hz``, ``on_bad_lines``, ``delimiter``,
    ``decimal``) apply to the validated file and to the ``modeling`` file alike; the log
    ``topic`` to each of them that is a flight-controller log (a CSV modelling run of a
    logged test).

    Parameters
    ----------
    modeling : Path, optional
        The modelling test's recording (default: the model file's data file).
    ambient : str, optional
        The temperature column compared by r and used to find the hold stages (default:
        the model's first temperature column).
    averaging : float
        Averaging time of the stability figures [s].
    signals : tuple of str, optional
        The channels judged (default: the model's); a comma-separated text is accepted and
        stored as a tuple.
    time, time_unit : str, optional
        The time column and its unit (default: the file's).
    signal_unit : str or tuple of str, optional
        The signal's unit, or one per signal (default: the file's); a single unit in a
        tuple is stored as the unit.
    temp_unit : str, optional
        The temperature columns' unit (default: the file's).
    temp_conversion : TemperatureConversion, optional
        Raw counts → °C, :math:`T = g\\,v + o` (the text ``"GAIN,OFFSET[,int16]"`` is
        accepted).
    stage_rate : float
        Hold detection: the largest temperature rate of a hold [°C/min].
    min_stage : float
        Hold detection: shortest stage [s].
    settle : float
        Time cut from the start of each stage [s].
    extrapolate : bool
        Evaluate the model outside its fitted temperature range (with a warning).
    names : tuple of str, optional
        Column names of a text log without a header row (a comma-separated text is
        accepted).
    rate_hz : float, optional
        Sample rate [Hz] of a log without a time column.
    on_bad_lines : {"error", "skip"}
        A mangled line of a text log: an error naming it, or dropped and counted.
    delimiter : str, optional
        Field separator of a text log (detected when None).
    decimal : {".", ","}, optional
        Decimal mark of a text log (detected when None).
    topic : str, optional
        Flight-controller log topic, or a station recording's sensor.
    stamp : {"header", "receive"}
        Time of a ROS bag's messages: their header stamp (default) or the bag's receive
        time.
    chamber_log : ChamberLogSpec, optional
        A chamber's own log joined by time to each file (its column ``chamber``).
    latitude : float, optional
        Test-site latitude [°] of a turntable run judging a triad calibration.
    static_s : float
        A multi-position calibration's held-out session: shortest still pose [s].
    legs : bool
        The command's text shows each heating and cooling leg (the result holds them in
        any case: :attr:`thermocal.validation.ValidationResult.legs_after`).

    Raises
    ------
    thermocal.errors.ParameterError
        A column list, unit list or temperature conversion no validation can use, naming
        the field.

    Examples
    --------
    >>> from thermocal.pipeline.options import ValidateOptions
    >>> v = ValidateOptions(signals="gz", rate_hz=50.0, on_bad_lines="skip")
    >>> v.signals, v.read_options.rate_hz
    (('gz',), 50.0)
    """

    modeling: Path | None = None
    ambient: str | None = None
    averaging: float = DEFAULT_AVERAGING_S
    signals: tuple[str, ...] | None = None
    time: str | None = None
    time_unit: str | None = None
    signal_unit: str | tuple[str, ...] | None = None
    temp_unit: str | None = None
    temp_conversion: TemperatureConversion | None = None
    stage_rate: float = 0.05
    min_stage: float = 600.0
    settle: float = 0.0
    extrapolate: bool = False
    names: tuple[str, ...] | None = None
    rate_hz: float | None = None
    on_bad_lines: Literal["error", "skip"] = "error"
    delimiter: str | None = None
    decimal: Literal[".", ","] | None = None
    topic: str | None = None
    stamp: Literal["header", "receive"] = "header"
    chamber_log: ChamberLogSpec | None = None
    latitude: float | None = None
    static_s: float = 1.0
    legs: bool = False

    def __post_init__(self) -> None:
        set_ = object.__setattr__  # frozen: normalise in place once
        for field in ("signals", "names"):
            set_(self, field, _names(getattr(self, field), field))
        if self.signal_unit is not None and not isinstance(self.signal_unit, str):
            units = tuple(self.signal_unit)
            set_(self, "signal_unit", units[0] if len(units) == 1 else units)
        if self.temp_conversion is not None:
            set_(self, "temp_conversion", _conversion(self.temp_conversion))

    @property
    def read_options(self) -> ReadOptions:
        """How the files are read (:class:`thermocal.readers.options.ReadOptions`; the
        signal columns named, the temperatures the file's)."""
        return _read_options(self, None)


def _conversion(value: object) -> TemperatureConversion:
    """A temperature conversion from its text or tuple, refused naming ``temp_conversion``."""
    from thermocal.units import temperature_conversion

    try:
        return temperature_conversion(value, "{name}")
    except UnitError as exc:
        raise ParameterError("temp_conversion", str(exc)) from None


def _read_options(
    o: FitOptions | ValidateOptions, temperatures: tuple[str, ...] | None
) -> ReadOptions:
    """The :class:`ReadOptions` of a fit's or a validation's reading fields."""
    from thermocal.pipeline.reading import split_units
    from thermocal.readers.options import ReadOptions

    given: dict[str, Any] = dict(
        time=o.time, time_unit=o.time_unit, signals=o.signals, temperatures=temperatures,
        signal_unit=split_units(o.signal_unit), temp_unit=o.temp_unit,
        temp_conversion=o.temp_conversion,
        topic=o.topic, names=o.names, rate_hz=o.rate_hz,
        on_bad_lines=o.on_bad_lines,
        delimiter=o.delimiter, decimal=o.decimal, stamp=o.stamp, chamber_log=o.chamber_log,
    )  # fmt: skip
    return ReadOptions(**given)


ALIASES: dict[str, dict[str, str]] = {
    "fit": {"sensor": "topic"},
    "validate": {"average": "averaging", "sensor": "topic"},
}
"""Second names of an option (``average`` is ``averaging``), per command."""

NOT_IN_TABLES = frozenset({"modeling", "params"})
"""Options a fleet sets itself (the unit's own modelling file)."""

OPTIONS: dict[str, type[Any]] = {"fit": FitOptions, "validate": ValidateOptions}
"""The options dataclass of each command."""

O = TypeVar("O", FitOptions, ValidateOptions)


def option_kinds(cls: type[Any]) -> dict[str, str]:
    """``{option name: "flag" | "int" | "float" | "str" | "path"}`` of an options dataclass
    (option names with dashes)."""
    from thermocal.readers.options import ChamberLogSpec
    from thermocal.units import TemperatureConversion

    local = {"TemperatureConversion": TemperatureConversion, "ChamberLogSpec": ChamberLogSpec}
    hints = typing.get_type_hints(cls, localns=local)
    out: dict[str, str] = {}
    for f in dataclasses.fields(cls):
        if f.name in ("params", "chamber_log"):  # the family's options, a command line's log
            continue
        args = set(typing.get_args(hints[f.name])) - {type(None)} or {hints[f.name]}
        kind = next(iter(args))
        name = option_name(f.name)[2:]
        out[name] = {bool: "flag", int: "int", float: "float", Path: "path"}.get(kind, "str")
    return out


def family_option_kinds() -> dict[str, tuple[str, tuple[FamilyOption, ...]]]:
    """``{option name: (kind, the declared options it gives)}`` of the built-in families'
    fit options (option names with dashes; :func:`thermocal.families.fit_option_table`).
    A choice with a switch is two options: the flag ``select`` and its ``select-method``."""
    out: dict[str, tuple[str, tuple[FamilyOption, ...]]] = {}
    for name, decls in fit_option_table().items():
        opts = tuple(o for _fam, o in decls)
        first = opts[0]
        dashed = name.replace("_", "-")
        if first.switch:
            out[dashed] = ("flag", opts)
            out[first.switch.replace("_", "-")] = ("str", opts)
        else:
            out[dashed] = ({"bool": "tristate"}.get(first.kind, first.kind), opts)
    return out


def family_params(values: Mapping[str, Any]) -> dict[str, Any]:
    """The family options (constructor parameters) of the command-line values ``values``
    (named as the options without dashes, ``rate_interval``, ``select``,
    ``select_method``): ``{parameter: value}`` for the options given (not None; a flag
    given).  An option the chosen family does not take is kept: the family refuses it.

    Parameters
    ----------
    values : mapping of str to Any
        The command's parameters by option name without dashes.

    Returns
    -------
    dict
        ``{family parameter: value}`` for the options given.
    """
    params: dict[str, Any] = {}
    for name, decls in fit_option_table().items():
        first = decls[0][1]
        value = values.get(name)
        if first.switch:
            if value:
                params[first.name] = values.get(first.switch) or first.choices[0]
        elif value is not None:
            params[first.name] = value
    return params


def options_of(cls: type[O], values: Mapping[str, Any]) -> O:
    """The options dataclass from a command's parameters, named as its options without
    dashes (``signal`` gives the field ``signals``, ``rate`` the field ``rate_hz``:
    :func:`thermocal.pipeline.messages.option_name`).

    Parameters
    ----------
    cls : type
        The options dataclass (e.g. ``TurntableOptions``).
    values : mapping of str to Any
        The command's parameters by option name without dashes.

    Returns
    -------
    instance of ``cls``
        With the fields given; the others at their defaults.
    """
    out: dict[str, Any] = {}
    for f in dataclasses.fields(cls):
        key = option_name(f.name)[2:].replace("-", "_")
        if key in values:
            out[f.name] = values[key]
    return cls(**out)


def _table_text(key: str, value: Any, where: str) -> str:
    """A table value as the command line would take it: a list as ``a,b``, a number as
    written."""
    if isinstance(value, list):
        if not value or not all(isinstance(v, str | int | float) for v in value):
            raise ThermocalInputError(f"{where}: {key}: expected a list of names or numbers")
        return ",".join(str(v) for v in value)
    if isinstance(value, str | int | float) and not isinstance(value, bool):
        return str(value)
    raise ThermocalInputError(f"{where}: {key}: expected a string, number or list")


def _parse(kind: str, name: str, text: str, where: str) -> Any:
    """``text`` as the option's type, refused as the command line refuses it."""
    try:
        if kind == "int":
            return int(text)
        if kind == "float":
            return float(text)
        if kind == "floats":
            return tuple(float(v) for v in text.split(","))
    except ValueError:
        what = {"int": "integer", "float": "float"}.get(kind, "list of numbers")
        raise ThermocalInputError(
            f"{where}: Invalid value for '--{name}': {text!r} is not a valid {what}."
        ) from None
    return Path(text) if kind == "path" else text


def _table_kinds(command: str) -> dict[str, str]:
    """``{option name: kind}`` a table of ``command`` takes (the family options of ``fit``
    included)."""
    kinds = option_kinds(OPTIONS[command])
    if command == "fit":
        kinds |= {n: kind for n, (kind, _opts) in family_option_kinds().items()}
    return kinds


def _table_flag(name: str, kind: str, value: Any, where: str) -> tuple[list[str], bool]:
    """A flag's command-line arguments and value (``tristate``: false is the ``no-`` flag)."""
    if not isinstance(value, bool):
        raise ThermocalInputError(f"{where}: {name} is a flag: write true or false")
    if kind == "tristate":
        return [f"--{name}" if value else f"--no-{name}"], value
    return ([f"--{name}"] if value else []), value  # cli-words: a batch records its command line


def options_from_table(command: str, table: Mapping[str, Any], where: str) -> tuple[Any, list[str]]:
    """A fleet configuration's table of ``command`` options (``{"model": "poly", "order": 2,
    "signal": ["gx", "gy"], "select": true}``) → the options dataclass and the same options
    as command-line arguments (each option with two dashes and its value as text, a list
    joined by commas; recorded with each unit).  An unknown option, a value of the wrong shape
    or type, or a missing required option is a :class:`ThermocalInputError` naming it
    (``where``: the file and table).  A flag set to false is left at its default; a yes/no
    family option (``per_run_offset``) set to false is its ``no-`` flag.

    Parameters
    ----------
    command : str
        The command (``"fit"``, ``"validate"`` …).
    table : mapping of str to Any
        The options as parsed from the configuration file.
    where : str
        The file and table, named in errors.

    Returns
    -------
    options : dataclass
        The command's options.
    argv : list of str
        The same options as command-line arguments.

    Raises
    ------
    ThermocalInputError
        An unknown option, a value of the wrong shape or type, or a missing required one.
    """
    cls = OPTIONS[command]
    kinds = _table_kinds(command)
    fields = {option_name(f.name)[2:]: f.name for f in dataclasses.fields(cls)}
    aliases = ALIASES.get(command, {})
    known = {n: n for n in kinds if n.replace("-", "_") not in NOT_IN_TABLES}
    known |= {a: t for a, t in aliases.items()}
    args: list[str] = []
    values: dict[str, Any] = {}
    for key, value in table.items():
        name = str(key).replace("_", "-")
        if name not in known:
            raise ThermocalInputError(
                f"{where}: {key!r} is not an option of thermocal {command}; it takes "
                + ", ".join(sorted(known))
            )
        field = fields.get(known[name], known[name].replace("-", "_"))
        kind = kinds[known[name]]
        if kind in ("flag", "tristate"):
            flag_args, values[field] = _table_flag(name, kind, value, where)
            args += flag_args
            continue
        text = _table_text(str(key), value, where)
        args += [f"--{name}", text]
        values[field] = _parse(kind, name, text, where)
    required = [
        f.name
        for f in dataclasses.fields(cls)
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    for f in required:
        if f not in values:
            raise ThermocalInputError(f"{where}: Missing option '{option_name(f)}'.")
    if command == "fit":
        own = {f.name for f in dataclasses.fields(cls)}
        values = {k: v for k, v in values.items() if k in own} | {"params": family_params(values)}
    return cls(**values), args


__all__ = [
    "ALIASES",
    "OPTIONS",
    "FitOptions",
    "ValidateOptions",
    "family_option_kinds",
    "family_params",
    "option_kinds",
    "options_from_table",
    "options_of",
]
