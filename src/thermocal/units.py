"""Physical constants, unit strings and named conversions: the one glossary of thermocal.

Every quantity in thermocal carries its unit in its name (``rate_c_per_min``,
``bias_deg_h``), in its docstring (``[°/h]``) or in a unit field.  Conversions
are the named constants below; code never writes a bare ``3600`` or ``9.80665``.

Signal unit strings accepted on the command line and in files:

========  ==========================  =========
string    meaning                     kind
========  ==========================  =========
deg/h     degrees per hour [°/h]      rate
deg/s     degrees per second [°/s]    rate
rad/s     radians per second          rate
mg        milli-g                     accel
ug        micro-g                     accel
g         standard gravity            accel
m/s^2     metres per second squared   accel
counts    raw output (pulses, LSB)    raw
========  ==========================  =========

Temperature unit strings: ``degC`` (also ``C``, ``°C``) and ``counts`` (raw ADC), converted
by a :class:`TemperatureConversion` ``T = gain·v + offset`` (``int16``: signed 16-bit counts
stored unsigned).

The one resolver (:func:`resolve_inputs`, per column :func:`resolve_unit` and
:func:`resolve_temperature_conversion`) chooses every unit and conversion of a recording,
once, in this order: command-line option > the file's own metadata > a unit in
the column name > what the model file recorded > a default stated in a
:class:`~thermocal.errors.UnitWarning`.  Nothing else in thermocal chooses a unit.

Sources: earth rate from WGS-84 (NIMA TR8350.2, 3rd ed., 2000);
standard gravity from CGPM 1901 (BIPM SI Brochure).
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Final, Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from thermocal.errors import UnitError, UnitWarning

# --- constants -----------------------------------------------------------------

EARTH_RATE_RAD_S: Final = 7.292115e-5
"""Earth rotation rate Ω [rad/s] (WGS-84)."""

STANDARD_GRAVITY_M_S2: Final = 9.80665
"""Standard gravity g0 [m/s²] (CGPM 1901)."""

SECONDS_PER_HOUR: Final = 3600.0
SECONDS_PER_MINUTE: Final = 60.0

# --- angle and rate conversions ----------------------------------------------------

DEG_TO_RAD: Final = math.pi / 180.0
RAD_TO_DEG: Final = 180.0 / math.pi
ARCSEC_PER_DEG: Final = 3600.0
"""Seconds of arc in one degree [″/°]."""
DEG_TO_ARCSEC: Final = ARCSEC_PER_DEG
ARCSEC_TO_DEG: Final = 1.0 / ARCSEC_PER_DEG
ARCSEC_TO_RAD: Final = DEG_TO_RAD / ARCSEC_PER_DEG
RAD_TO_ARCSEC: Final = 1.0 / ARCSEC_TO_RAD
PPM: Final = 1e-6
"""One part per million (dimensionless)."""

DH_TO_RS: Final = DEG_TO_RAD / SECONDS_PER_HOUR
"""[°/h] → [rad/s]."""
RS_TO_DH: Final = 1.0 / DH_TO_RS
"""[rad/s] → [°/h]."""
DS_TO_DH: Final = SECONDS_PER_HOUR
"""[°/s] → [°/h]."""
DH_TO_DS: Final = 1.0 / SECONDS_PER_HOUR
"""[°/h] → [°/s]."""

EARTH_RATE_DEG_H: Final = EARTH_RATE_RAD_S * RS_TO_DH
"""Earth rotation rate Ω [°/h] (≈ 15.041 °/h)."""

# Angle random walk: a rate density [°/h/√Hz] equals [°/√h] × 60 (since √h = 60 √s).
ARW_DEG_SQRT_H_PER_DEG_H_SQRT_HZ: Final = 1.0 / 60.0
"""Multiply an ARW coefficient N in [°/h·√s] = [°/h/√Hz] by this to get [°/√h]."""

# --- acceleration conversions ------------------------------------------------------

MG_TO_MS2: Final = STANDARD_GRAVITY_M_S2 * 1e-3
MS2_TO_MG: Final = 1.0 / MG_TO_MS2
G_TO_MG: Final = 1e3
UG_TO_MG: Final = 1e-3

# --- unit strings ------------------------------------------------------------------

SignalKind = Literal["rate", "accel", "raw"]

RATE_UNITS: Final[dict[str, float]] = {
    "deg/h": 1.0,
    "deg/s": DS_TO_DH,
    "rad/s": RS_TO_DH,
}
"""Factor taking a value in the key's unit to [°/h]."""

ACCEL_UNITS: Final[dict[str, float]] = {
    "mg": 1.0,
    "ug": UG_TO_MG,
    "g": G_TO_MG,
    "m/s^2": MS2_TO_MG,
}
"""Factor taking a value in the key's unit to [mg]."""

RAW_UNITS: Final = ("counts",)

SIGNAL_UNITS: Final = (*RATE_UNITS, *ACCEL_UNITS, *RAW_UNITS)
TEMPERATURE_UNITS: Final = ("degC", "counts")

_TEMP_ALIASES: Final = {
    "degc": "degC",
    "c": "degC",
    "°c": "degC",
    "celsius": "degC",
    "counts": "counts",
}
_SIGNAL_ALIASES: Final = {
    "deg/hr": "deg/h",
    "°/h": "deg/h",
    "dph": "deg/h",
    "°/s": "deg/s",
    "dps": "deg/s",
    "m/s2": "m/s^2",
    "m/s²": "m/s^2",
    "µg": "ug",
    "count": "counts",
    "lsb": "counts",
    "pulses": "counts",
}

TIME_UNITS: Final[dict[str, float]] = {"s": 1.0, "ms": 1e-3, "us": 1e-6}
"""Factor taking a time in the key's unit to [s]."""

ANGLE_UNITS: Final[dict[str, float]] = {"deg": 1.0, "rad": RAD_TO_DEG}
"""Factor taking an angle (a turntable's encoder reading) in the key's unit to [°]."""
_ANGLE_ALIASES: Final = {
    "°": "deg",
    "degree": "deg",
    "degrees": "deg",
    "radian": "rad",
    "radians": "rad",
}


def normalize_signal_unit(unit: str) -> str:
    """The canonical spelling of a signal unit.

    Parameters
    ----------
    unit : str
        A rate, acceleration or raw unit, or an alias (``"°/s"``, ``"dps"`` …).

    Returns
    -------
    str
        A key of :data:`SIGNAL_UNITS` (``"deg/s"``, ``"mg"``, ``"counts"`` …).

    Raises
    ------
    UnitError
        An unknown unit (the message lists the known ones).

    Examples
    --------
    >>> normalize_signal_unit("deg/s")
    'deg/s'
    """
    u = unit.strip()
    if u in SIGNAL_UNITS:
        return u
    alias = _SIGNAL_ALIASES.get(u.lower())
    if alias is not None:
        return alias
    raise UnitError(f"unknown signal unit {unit!r}; known units: {', '.join(SIGNAL_UNITS)}")


def normalize_angle_unit(unit: str) -> str:
    """The canonical spelling of an encoder angle's unit.

    Parameters
    ----------
    unit : str
        ``"deg"``, ``"rad"`` or an alias (``"°"``, ``"degrees"``, ``"radians"``).

    Returns
    -------
    str
        ``"deg"`` or ``"rad"``.

    Raises
    ------
    UnitError
        An unknown unit.
    """
    u = unit.strip().lower()
    alias = u if u in ANGLE_UNITS else _ANGLE_ALIASES.get(u)
    if alias is None:
        raise UnitError(f"unknown angle unit {unit!r}; known units: {', '.join(ANGLE_UNITS)}")
    return alias


def angle_to_deg(values: npt.ArrayLike, unit: str) -> npt.NDArray[np.float64]:
    r"""An angle in degrees.

    Parameters
    ----------
    values : array_like
        Angles [``unit``].
    unit : str
        A unit of :data:`ANGLE_UNITS` or an alias.

    Returns
    -------
    numpy.ndarray
        :math:`\theta[°] = \theta[\mathrm{unit}] \cdot \mathrm{factor}` [°].

    Raises
    ------
    UnitError
        An unknown unit.

    Examples
    --------
    >>> round(float(angle_to_deg(3.141592653589793, "rad")[()]), 6)
    180.0
    """
    out: npt.NDArray[np.float64] = (
        np.asarray(values, dtype=np.float64) * ANGLE_UNITS[normalize_angle_unit(unit)]
    )
    return out


def normalize_temperature_unit(unit: str) -> str:
    """The canonical spelling of a temperature unit.

    Parameters
    ----------
    unit : str
        ``"degC"``, ``"counts"`` or an alias (``"°C"``, ``"C"`` …).

    Returns
    -------
    str
        ``"degC"`` or ``"counts"``.

    Raises
    ------
    UnitError
        An unknown unit.
    """
    alias = _TEMP_ALIASES.get(unit.strip().lower())
    if alias is None:
        raise UnitError(
            f"unknown temperature unit {unit!r}; known units: {', '.join(TEMPERATURE_UNITS)}"
        )
    return alias


def normalize_time_unit(unit: str) -> str:
    """The canonical spelling of a time unit.

    Parameters
    ----------
    unit : str
        ``"s"``, ``"ms"``, ``"us"`` (``"µs"`` accepted).

    Returns
    -------
    str
        A key of :data:`TIME_UNITS`.

    Raises
    ------
    UnitError
        An unknown unit.
    """
    u = unit.strip().lower().replace("µ", "u")
    if u in TIME_UNITS:
        return u
    raise UnitError(f"unknown time unit {unit!r}; known units: {', '.join(TIME_UNITS)}")


# --- raw-count temperatures ------------------------------------------------------------

INT16_SIGN_BIT: Final = 32768.0
"""Unsigned 16-bit values at or above this are negative in two's complement."""
UINT16_MODULUS: Final = 65536.0
"""2¹⁶: an unsigned 16-bit value ``c ≥ 32768`` is the signed value ``c − 65536``."""

TEMPERATURE_ENCODINGS: Final = ("plain", "int16")
"""How raw temperature counts are stored: ``plain`` numbers, or ``int16`` (signed 16-bit
two's complement written as unsigned 0…65535, as many loggers do)."""


class TemperatureConversion(NamedTuple):
    """Raw ADC counts → °C: ``T = gain · v + offset`` (gain [°C/count], offset [°C]).

    ``v`` is the count as stored, except with ``encoding="int16"``: signed 16-bit two's
    complement stored unsigned, ``v = c − 65536`` for ``c ≥ 32768`` (else ``v = c``).
    Written in files as ``[gain, offset]`` or ``[gain, offset, "int16"]``.
    """

    gain: float
    offset: float
    encoding: str = "plain"

    def to_celsius(self, counts: npt.ArrayLike, where: str = "") -> npt.NDArray[np.float64]:
        r"""Temperatures of raw counts.

        Parameters
        ----------
        counts : array_like
            Raw counts as stored [counts].
        where : str, optional
            The column, named in messages.

        Returns
        -------
        numpy.ndarray
            :math:`T = \mathrm{gain}\cdot v + \mathrm{offset}` [°C].

        Raises
        ------
        UnitError
            An ``int16`` count outside −32768…65535, or a value that overflows.

        Examples
        --------
        >>> TemperatureConversion(0.0625, -50.0).to_celsius([800.0]).tolist()
        [0.0]
        >>> TemperatureConversion(0.01, 0.0, "int16").to_celsius([65436.0]).tolist()
        [-1.0]
        """
        v = np.asarray(counts, dtype=np.float64)
        if self.encoding == "int16":
            bad = np.isfinite(v) & ((v < -INT16_SIGN_BIT) | (v >= UINT16_MODULUS))
            if bad.any():
                row = int(np.argmax(bad))
                raise UnitError(
                    f"{where + ': ' if where else ''}count {float(v[row]):.10g} at row {row} is "
                    "not a 16-bit value (the conversion says int16: −32768…65535)"
                )
            v = np.where(v >= INT16_SIGN_BIT, v - UINT16_MODULUS, v)
        with np.errstate(over="ignore", invalid="ignore"):
            out = v * self.gain + self.offset
        refuse_overflow(out, v, f"counts → °C, {self.describe()}", where)
        return out

    def to_json(self) -> list[float | str]:
        """The file form ``[gain, offset]`` or ``[gain, offset, "int16"]``."""
        out: list[float | str] = [float(self.gain), float(self.offset)]
        if self.encoding != "plain":
            out.append(self.encoding)
        return out

    def describe(self) -> str:
        """``T[°C] = 0.0625·counts − 50`` (with the encoding when not plain)."""
        sign = "+" if self.offset >= 0 else "−"
        enc = " (counts signed 16-bit, stored unsigned)" if self.encoding == "int16" else ""
        return f"T[°C] = {self.gain:.10g}·counts {sign} {abs(self.offset):.10g}{enc}"


def temperature_conversion(
    value: object, what: str = "temperature conversion", parameters: tuple[str, ...] = ()
) -> TemperatureConversion:
    """A :class:`TemperatureConversion` from its file form or its text.

    Parameters
    ----------
    value : object
        ``(gain, offset[, encoding])`` as a tuple or list (the file form), a
        :class:`TemperatureConversion`, or the text ``"GAIN,OFFSET[,int16]"``;
        gain [°C/count], offset [°C].
    what : str, optional
        What is being read, named in messages; ``{parameter}`` where it names one of
        ``parameters`` (``"{temp_conversion}"``).
    parameters : tuple of str, optional
        The library's parameters ``what`` names (:meth:`UnitError.naming`).

    Returns
    -------
    TemperatureConversion

    Raises
    ------
    UnitError
        Neither form, an unknown encoding, or a gain that is zero or not finite.

    Examples
    --------
    >>> temperature_conversion("0.0625,-50,int16")
    TemperatureConversion(gain=0.0625, offset=-50.0, encoding='int16')
    """
    if isinstance(value, TemperatureConversion):
        return value
    parts: list[Any]
    if isinstance(value, str):
        parts = [p.strip() for p in value.split(",")]
    elif isinstance(value, list | tuple):
        parts = list(value)
    else:
        parts = []
    encoding = "plain"
    if len(parts) == 3 and isinstance(parts[2], str):
        encoding = parts[2].strip().lower()
        parts = parts[:2]
    usage = (
        f"{what} takes 'GAIN,OFFSET' or 'GAIN,OFFSET,int16' (T[°C] = GAIN·counts + OFFSET), "
        f"got {value!r}"
    )
    if len(parts) != 2 or encoding not in TEMPERATURE_ENCODINGS:
        raise UnitError.naming(usage, *parameters)
    try:
        gain, offset = (float(p) for p in parts)
    except (TypeError, ValueError):
        raise UnitError.naming(usage, *parameters) from None
    if not (math.isfinite(gain) and math.isfinite(offset)) or gain == 0.0:
        raise UnitError.naming(
            f"{what} gain must be finite and non-zero, offset finite; got {value!r}", *parameters
        )
    return TemperatureConversion(gain, offset, encoding)


# --- the one resolver: option > file metadata > column name > model file > stated default ---

UnitRole = Literal["time", "signal", "temperature", "angle"]
UnitSource = Literal["option", "metadata", "column name", "model", "default"]
ConversionSource = Literal["option", "metadata", "model", "none"]

LEGACY_TEMPERATURE_UNIT: Final = "degC"
"""Temperature unit of a model file that names none: not a guess — every model file before
format version 3 was fitted in °C (raw counts were always converted)."""

DEFAULT_UNITS: Final[dict[str, str]] = {
    "time": "s",
    "signal": "deg/h",
    "temperature": "degC",
    "angle": "deg",
}
"""What a column is taken to be in when nothing states its unit — always said in a
``warning:`` line, never assumed silently."""

_UNIT_PARAMETER: Final[dict[str, str]] = {
    "time": "time_unit",
    "signal": "signal_unit",
    "temperature": "temp_unit",
    "angle": "encoder_unit",
}
"""The parameter that states the unit of a column of each role, named in messages."""
_TIME_ALIASES: Final = {"sec": "s", "secs": "s", "msec": "ms", "usec": "us", "µs": "us"}
_NAME_BRACKET = re.compile(r"[\[(]\s*([^\])]+?)\s*[\])]\s*$")
"""A unit in brackets at the end of a name; the reference of :func:`_bracket_unit`, which
finds the same in linear time (this search is quadratic on a name of many ``(``)."""


def _bracket_unit(text: str) -> tuple[int, str] | None:
    """``(start, unit)`` of a unit written in brackets at the end of ``text`` (``time (ms)``
    → ``(5, "ms")``), as ``_NAME_BRACKET.search`` finds it, in one pass: the closing bracket
    is the last character but blanks, the opening one the first ``[`` or ``(`` after the
    last other closing bracket, the unit what lies between them, blanks stripped."""
    t = text.rstrip()
    if len(t) < 3 or t[-1] not in "])":
        return None
    body = t[:-1]
    k = max(body.rfind("]"), body.rfind(")"))
    opens = [i for i in (body.find("[", k + 1), body.find("(", k + 1)) if i >= 0]
    if not opens or min(opens) == len(body) - 1:
        return None
    start = min(opens)
    inner = body[start + 1 :]
    return start, inner.strip() or inner[-1]


_NAME_SEPARATORS = re.compile(r"[\s_]+")
_PLACEHOLDER = re.compile(r"\{([a-z_][a-z0-9_]*)\}")
"""A parameter's place in a message template (``{temp_conversion}``)."""


def _normalize_time_alias(unit: str) -> str:
    alias: str = _TIME_ALIASES.get(unit.strip().lower()) or unit
    return normalize_time_unit(alias)


def _normalizer(role: UnitRole) -> Callable[[str], str]:
    table: dict[str, Callable[[str], str]] = {
        "time": _normalize_time_alias,
        "signal": normalize_signal_unit,
        "temperature": normalize_temperature_unit,
        "angle": normalize_angle_unit,
    }
    return table[role]


def unit_in_column_name(name: str, role: UnitRole) -> str | None:
    """The unit written in a column's name, or None.

    Recognised: a trailing bracket (``time (ms)``, ``gx [deg/s]``, ``temp [°C]``) and a
    last word after a space or underscore (``gyrox rad/s``, ``time_ms``,
    ``temp_counts``), when that word is a unit of the column's role.  A name that is
    only a unit (``g``) or has no unit (``T1``) gives None.

    Parameters
    ----------
    name : str
        The column name.
    role : {"time", "signal", "temperature", "angle"}
        The column's role; only that role's units are recognised.

    Returns
    -------
    str or None
        The canonical unit.

    Examples
    --------
    >>> unit_in_column_name("gx [deg/s]", "signal"), unit_in_column_name("T1", "temperature")
    ('deg/s', None)
    """
    norm = _normalizer(role)
    text = name.strip()
    m = _bracket_unit(text)
    candidates = [m[1]] if m and text[: m[0]].strip() else []
    words = [w for w in _NAME_SEPARATORS.split(text) if w]
    if len(words) >= 2:
        candidates.append(words[-1])
    for c in candidates:
        try:
            return norm(c)
        except UnitError:
            continue
    return None


def other_column_unit(column: str, metadata: str | None) -> str:
    """The unit of a column outside the signal and temperature roles.

    An accelerometer triad read beside the gyros, an auxiliary channel: the file's
    metadata, else a signal unit written in the column's name, else ``""`` — nothing is
    assumed for such a column.

    Parameters
    ----------
    column : str
        The column name.
    metadata : str or None
        The unit the file's metadata states.

    Returns
    -------
    str
        The unit, or ``""`` when none is stated.
    """
    if metadata:
        return metadata
    return unit_in_column_name(column, "signal") or ""


def strip_unit_from_name(name: str) -> str:
    """The column name without a trailing unit.

    Parameters
    ----------
    name : str
        The column name (``time (ms)``, ``time_s``).

    Returns
    -------
    str
        The name without a unit written in brackets or as its last word; unchanged
        when there is none.

    Examples
    --------
    >>> strip_unit_from_name("time (ms)"), strip_unit_from_name("time_s")
    ('time', 'time')
    """
    text = name.strip()
    m = _bracket_unit(text)
    if m and text[: m[0]].strip():
        return text[: m[0]].strip()
    words = [w for w in _NAME_SEPARATORS.split(text) if w]
    if len(words) >= 2:
        return " ".join(words[:-1])
    return text


@dataclass(frozen=True)
class ResolvedUnit:
    """A column's unit and where it came from.

    Attributes
    ----------
    unit : str
        The canonical unit.
    source : {"option", "metadata", "column name", "model", "default"}
        Where it came from.
    """

    unit: str
    source: UnitSource


def resolve_unit(
    column: str,
    role: UnitRole,
    *,
    option: str | None = None,
    metadata: str | None = None,
    model: str | None = None,
    default: str | None = None,
    where: str = "",
    option_name: str | None = None,
    ask: str | None = None,
    implied: str | None = None,
) -> ResolvedUnit:
    """The unit of a column, resolved once; the only place that chooses an unstated unit.

    Order: option > the file's own metadata > the unit in the column name > the unit
    recorded in the model file > ``default`` (else :data:`DEFAULT_UNITS`), the last
    stated in a :class:`UnitWarning`.  An option that contradicts the metadata or the
    column name wins, with a warning naming both.

    Parameters
    ----------
    column : str
        The column name.
    role : {"time", "signal", "temperature", "angle"}
        The column's role.
    option, metadata, model, default : str, optional
        The unit the command line, the file's metadata, the model file and the caller
        state (None: not stated).
    where : str, optional
        The file, named in messages.
    option_name : str, optional
        What stated ``option``, for messages, with ``{parameter}`` where it names a
        parameter (``"{temp_conversion} (raw counts)"``); default: the role's unit
        parameter (``signal_unit``) and the unit.
    ask : str, optional
        The parameter that states this column's unit (``"accel_unit"``; the command line
        shows its option): a unit nobody stated is refused, asking for it, and an option
        contradicting the file is said under this name.
    implied : str, optional
        A unit another option implies (raw ``counts`` with a count scale), taken
        without a warning when nobody states one.

    Returns
    -------
    ResolvedUnit

    Raises
    ------
    UnitError
        An unknown unit, or no unit stated with ``ask``.
    """
    norm = _normalizer(role)
    prefix = f"{where}: " if where else ""
    meta = norm(metadata) if metadata else None
    param = _UNIT_PARAMETER[role]
    if option:
        opt = norm(option)
        stated_by = ask if ask and not ask.startswith("-") else param
        _warn_contradicted(column, stated_by, opt, meta, prefix, option_name, role)
        return ResolvedUnit(opt, "option")
    if meta is not None:
        return ResolvedUnit(meta, "metadata")
    named = unit_in_column_name(column, role)
    if named is not None:
        return ResolvedUnit(named, "column name")
    if model:
        return ResolvedUnit(norm(model), "model")
    if implied:
        return ResolvedUnit(norm(implied), "option")
    if ask:  # a parameter (the command line shows its option), or an option as it is
        named = ask if ask.startswith("-") else "{" + ask + "}"
        raise UnitError.naming(
            f"{prefix}no unit stated for column {column!r}; give {named} (or the unit in the "
            "file's metadata or column name)",
            ask,
        )
    chosen = norm(default) if default else DEFAULT_UNITS[role]
    whose = " (the model's unit)" if default else ""
    warnings.warn(
        UnitWarning.naming(
            f"{prefix}no unit stated for the {role} column {column!r}; assuming {chosen}{whose} "
            f"(give {{{param}}}, or the unit in the file's metadata or column name)",
            param,
        ),
        stacklevel=2,
    )
    return ResolvedUnit(chosen, "default")


def _warn_contradicted(
    column: str,
    param: str,
    opt: str,
    meta: str | None,
    prefix: str,
    option_name: str | None,
    role: UnitRole,
) -> None:
    """A warning when the stated unit ``opt`` contradicts the file's metadata or the unit
    in the column's name (the stated one is used); ``param`` is the parameter that stated
    it."""
    said = option_name or f"{{{param}}} {opt}"
    named_params = (param, *_PLACEHOLDER.findall(option_name or ""))
    if meta is not None and meta != opt:
        warnings.warn(
            UnitWarning.naming(
                f"{prefix}{said} contradicts the file's metadata, which says column "
                f"{column!r} is in {meta}; using {opt}",
                *named_params,
            ),
            stacklevel=3,
        )
    named = unit_in_column_name(column, role) if meta is None else None
    if named is not None and named != opt:
        warnings.warn(
            UnitWarning.naming(
                f"{prefix}{said} contradicts the column name {column!r}, which says "
                f"{named}; using {opt} (drop {{{param}}} if the name is right)",
                *named_params,
            ),
            stacklevel=3,
        )


@dataclass(frozen=True)
class ResolvedConversion:
    """The raw-count conversion of a temperature column and where it came from.

    Attributes
    ----------
    conversion : TemperatureConversion or None
        The conversion; None when none is stated anywhere.
    source : {"option", "metadata", "model", "none"}
        Where it came from.
    """

    conversion: TemperatureConversion | None
    source: ConversionSource


def resolve_temperature_conversion(
    column: str,
    *,
    option: TemperatureConversion | None = None,
    metadata: TemperatureConversion | None = None,
    model: TemperatureConversion | None = None,
    where: str = "",
) -> ResolvedConversion:
    """The counts → °C conversion of a raw-count temperature column.

    Order: option > the file's metadata > the conversion recorded in the model file >
    none.  An option that contradicts the file's metadata wins, with a
    :class:`UnitWarning` naming both.

    Parameters
    ----------
    column : str
        The temperature column.
    option, metadata, model : TemperatureConversion, optional
        The conversion the command line, the file's metadata and the model file state.
    where : str, optional
        The file, named in messages.

    Returns
    -------
    ResolvedConversion
    """
    if option is not None:
        if metadata is not None and tuple(metadata) != tuple(option):
            warnings.warn(
                UnitWarning.naming(
                    f"{where + ': ' if where else ''}{{temp_conversion}} ({option.describe()}) "
                    f"contradicts the file's metadata for column {column!r} "
                    f"({metadata.describe()}); using the option",
                    "temp_conversion",
                ),
                stacklevel=2,
            )
        return ResolvedConversion(option, "option")
    if metadata is not None:
        return ResolvedConversion(metadata, "metadata")
    if model is not None:
        return ResolvedConversion(model, "model")
    return ResolvedConversion(None, "none")


@dataclass(frozen=True)
class UnitOptions:
    """What the caller states about units (``None``: not stated).

    Attributes
    ----------
    time_unit, temp_unit : str or None
        Unit of the time column and of every temperature column.
    signal_unit : str or tuple of str or None
        One unit for every signal, or one per signal (:func:`per_signal_unit`).
    temp_conversion : TemperatureConversion or None
        Applies to every temperature column and implies raw counts.
    ask : mapping of str to str
        Signal column → the parameter to ask for (``"accel_unit"``) when nothing states
        its unit.
    implied : mapping of str to str
        Signal column → the unit another option implies when nothing states one.
    """

    time_unit: str | None = None
    signal_unit: str | tuple[str, ...] | None = None
    temp_unit: str | None = None
    temp_conversion: TemperatureConversion | None = None
    ask: Mapping[str, str] = field(default_factory=dict)
    """Signal column → the parameter to ask for when nothing states its unit (no default is
    assumed: a multi-position calibration asks for its accelerometer's unit rather than
    assume a rate)."""
    implied: Mapping[str, str] = field(default_factory=dict)
    """Signal column → the unit another option implies when nothing states one (``counts``
    for the columns of a triad given a count scale)."""


@dataclass(frozen=True)
class StatedUnits:
    """Units a source states about columns.

    A data file's own metadata (sidecar or Parquet key-value, :meth:`from_file_info`)
    or a model file's record of its inputs (:meth:`from_model_inputs`).

    Attributes
    ----------
    time_unit : str or None
        Unit of the time column.
    columns : mapping of str to str
        Column → unit.
    conversions : mapping of str to TemperatureConversion
        Temperature column → raw-count conversion.
    signal_default : str or None
        Models only: the model's canonical signal unit, the stated default for data
        whose signal unit nothing states (older model files).
    """

    time_unit: str | None = None
    columns: Mapping[str, str] = field(default_factory=dict)
    conversions: Mapping[str, TemperatureConversion] = field(default_factory=dict)
    signal_default: str | None = None

    @classmethod
    def from_file_info(cls, info: Mapping[str, Any], where: str = "") -> StatedUnits:
        """The units a recording's metadata object states.

        Parameters
        ----------
        info : mapping
            ``time_unit``, ``signals``, ``temperatures``, ``units`` and
            ``metadata.temperature_conversion`` (see :mod:`thermocal.readers`).
        where : str, optional
            The file, named in messages.

        Returns
        -------
        StatedUnits

        Raises
        ------
        UnitError
            A malformed temperature conversion.
        """
        cols: dict[str, str] = {}
        for key in ("units", "temperatures", "signals"):  # later keys win
            part = info.get(key) or {}
            if isinstance(part, Mapping):
                cols.update({str(k): str(v) for k, v in part.items() if v})
        md = info.get("metadata") or {}
        raw = md.get("temperature_conversion") if isinstance(md, Mapping) else None
        conv = {
            str(k): temperature_conversion(v, f"{where}: temperature_conversion of {k!r}")
            for k, v in (raw or {}).items()
        }
        t_unit = info.get("time_unit")
        return cls(str(t_unit) if t_unit else None, cols, conv)

    @classmethod
    def from_model_inputs(
        cls, inputs: Mapping[str, Any], *, signal_default: str | None = None
    ) -> StatedUnits:
        """The units a model file's ``inputs`` record states.

        Parameters
        ----------
        inputs : mapping
            The model's ``inputs`` (format version ≥ 2; empty for older files, whose units
            then fall to the stated default).
        signal_default : str, optional
            The model's canonical signal unit.

        Returns
        -------
        StatedUnits
        """
        units_ = inputs.get("units") or {}
        conv = {
            str(k): temperature_conversion(v, f"model inputs: temperature_conversion of {k!r}")
            for k, v in (inputs.get("temperature_conversion") or {}).items()
        }
        t_unit = inputs.get("time_unit")
        return cls(
            str(t_unit) if t_unit else None,
            {str(k): str(v) for k, v in units_.items() if v},
            conv,
            signal_default,
        )


@dataclass(frozen=True)
class ResolvedInputs:
    """Every unit of a recording's used columns, each with its source.

    Attributes
    ----------
    time : ResolvedUnit
        The time column's unit.
    signals, temperatures : mapping of str to ResolvedUnit
        Each signal's and temperature's unit.
    conversions : mapping of str to ResolvedConversion
        Each temperature column's raw-count conversion.
    """

    time: ResolvedUnit
    signals: Mapping[str, ResolvedUnit]
    temperatures: Mapping[str, ResolvedUnit]
    conversions: Mapping[str, ResolvedConversion]

    def units(self) -> dict[str, str]:
        """Column → unit of the signals and temperatures."""
        return {c: r.unit for c, r in {**self.signals, **self.temperatures}.items()}

    def sources(self) -> dict[str, str]:
        """Column → source (``"<time>"`` for the time column), for messages and files."""
        out: dict[str, str] = {"<time>": self.time.source}
        out.update({c: r.source for c, r in {**self.signals, **self.temperatures}.items()})
        return out

    def unconverted_counts(self) -> list[str]:
        """Temperature columns in raw counts with no conversion stated anywhere."""
        return [
            c
            for c, r in self.temperatures.items()
            if r.unit == "counts" and self.conversions[c].conversion is None
        ]


def per_signal_unit(
    signal_unit: str | Sequence[str] | None,
    signals: Sequence[str],
    parameter: str = "signal_unit",
) -> dict[str, str | None]:
    """The stated unit of each signal: one unit for every signal, or one per signal.

    Parameters
    ----------
    signal_unit : str or sequence of str or None
        One unit for every signal (``"deg/s"``), or one per signal, in the order of
        ``signals`` (``("rad/s", "deg/s")``; an empty string states none for its signal);
        None states none.  A sequence of one unit is one unit for every signal.
    signals : sequence of str
        The signal columns.
    parameter : str, optional
        The caller's parameter that gave ``signal_unit``, named in the error.

    Returns
    -------
    dict of str to str or None
        Signal → its stated unit (None when none is stated).

    Raises
    ------
    UnitError
        A number of units that is neither 1 nor the number of signals (naming
        ``parameter``).

    Examples
    --------
    >>> per_signal_unit(("rad/s", "deg/s"), ["gx", "gy"])
    {'gx': 'rad/s', 'gy': 'deg/s'}
    >>> per_signal_unit("deg/s", ["gx", "gy"])
    {'gx': 'deg/s', 'gy': 'deg/s'}
    """
    if not signal_unit:
        return dict.fromkeys(signals)
    given = [signal_unit] if isinstance(signal_unit, str) else signal_unit
    parts = [str(u).strip() for u in given]
    if len(parts) == 1:
        return dict.fromkeys(signals, parts[0] or None)
    if len(parts) != len(signals):
        raise UnitError.naming(
            f"{{{parameter}}} gives {len(parts)} units for {len(signals)} signals "
            f"({', '.join(map(repr, signals))}); give one unit, or one per signal",
            parameter,
        )
    return {c: u or None for c, u in zip(signals, parts, strict=True)}


def resolve_inputs(
    time_column: str,
    signals: Sequence[str],
    temperatures: Sequence[str],
    *,
    options: UnitOptions | None = None,
    file: StatedUnits | None = None,
    model: StatedUnits | None = None,
    where: str = "",
) -> ResolvedInputs:
    """Resolve, once, every unit and raw-count conversion of a recording's used columns.

    Order: option > the file's own metadata > units written in the column name > the
    units recorded in the model file > a default stated in a :class:`UnitWarning`
    (:func:`resolve_unit`).  A temperature conversion says the temperatures are raw
    counts.  Pure: no file is read here.

    Parameters
    ----------
    time_column : str
        The time column.
    signals, temperatures : sequence of str
        The signal and temperature columns.
    options : UnitOptions, optional
        What the command line says.
    file, model : StatedUnits, optional
        What the data file's metadata and the model file state.
    where : str, optional
        The file, named in messages.

    Returns
    -------
    ResolvedInputs

    Raises
    ------
    UnitError
        An unknown unit, or a conversion given with temperatures stated in °C.
    """
    opt = options or UnitOptions()
    fil = file or StatedUnits()
    mod = model or StatedUnits()
    t_res = resolve_unit(
        time_column,
        "time",
        option=opt.time_unit,
        metadata=fil.time_unit,
        model=mod.time_unit,
        where=where,
    )
    sig_opts = per_signal_unit(opt.signal_unit, signals)
    sig_res = {
        c: resolve_unit(
            c,
            "signal",
            option=sig_opts[c],
            metadata=fil.columns.get(c),
            model=mod.columns.get(c),
            default=mod.signal_default,
            where=where,
            ask=opt.ask.get(c),
            implied=opt.implied.get(c),
        )
        for c in signals
    }
    t_opt = opt.temp_unit
    opt_name: str | None = None
    if opt.temp_conversion is not None:
        if t_opt and normalize_temperature_unit(t_opt) != "counts":
            raise UnitError.naming(
                f"{{temp_conversion}} converts raw counts, but {{temp_unit}} {t_opt} says the "
                "temperatures are °C already; give one or the other",
                "temp_conversion",
                "temp_unit",
            )
        t_opt, opt_name = "counts", "{temp_conversion} (raw counts)"
    tmp_res: dict[str, ResolvedUnit] = {}
    conv_res: dict[str, ResolvedConversion] = {}
    for c in temperatures:
        tmp_res[c] = resolve_unit(
            c,
            "temperature",
            option=t_opt,
            metadata=fil.columns.get(c),
            model=mod.columns.get(c),
            where=where,
            option_name=opt_name,
        )
        if tmp_res[c].unit == "counts":
            conv_res[c] = resolve_temperature_conversion(
                c,
                option=opt.temp_conversion,
                metadata=fil.conversions.get(c),
                model=mod.conversions.get(c),
                where=where,
            )
        else:
            conv_res[c] = ResolvedConversion(None, "none")
    return ResolvedInputs(t_res, sig_res, tmp_res, conv_res)


def signal_kind(unit: str) -> SignalKind:
    """Kind of a signal unit.

    Parameters
    ----------
    unit : str
        A signal unit or alias.

    Returns
    -------
    str
        ``"rate"`` (gyro), ``"accel"`` or ``"raw"``.

    Raises
    ------
    UnitError
        An unknown unit.

    Examples
    --------
    >>> signal_kind("deg/s"), signal_kind("g"), signal_kind("counts")
    ('rate', 'accel', 'raw')
    """
    u = normalize_signal_unit(unit)
    if u in RATE_UNITS:
        return "rate"
    if u in ACCEL_UNITS:
        return "accel"
    return "raw"


class ConversionOverflowError(UnitError):
    """A finite value became non-finite (±inf, NaN) on a unit conversion (exit 2)."""


OVERFLOW_SCAN_BLOCK: Final = 1 << 16
"""Rows per block of :func:`refuse_overflow`'s search for the first overflowing value
(a few bytes of working memory per row of a block, none per row of the column)."""


def refuse_overflow(
    out: npt.NDArray[np.float64],
    values: npt.NDArray[np.float64],
    what: str,
    where: str = "",
    first_row: int = 0,
) -> None:
    """Refuse a conversion that made a finite value non-finite.

    Cheap on the usual path: the sum of ``out`` is finite exactly when every element
    is; no copy is made.  Only when it is not are ``out`` and ``values`` scanned, in
    blocks of :data:`OVERFLOW_SCAN_BLOCK`, for a non-finite output whose input was
    finite (a NaN or infinity already in the data is left to the callers).

    Parameters
    ----------
    out : numpy.ndarray
        The converted values.
    values : numpy.ndarray
        The values before conversion (broadcast to ``out``'s shape).
    what : str
        The conversion, for the message (``"deg/s → deg/h"``).
    where : str, optional
        The column, named in the message.
    first_row : int, optional
        Row number of ``out``'s first row (rows of a 2-D array by its first axis).

    Raises
    ------
    ConversionOverflowError
        A float64 overflow (|x| > 1.8e308): names the row and the value before and after.
    """
    flat = out.reshape(-1)
    if flat.size == 0:
        return
    with np.errstate(over="ignore", invalid="ignore"):
        total = float(np.add.reduce(flat))
    if math.isfinite(total):
        return
    vin = np.broadcast_to(values, out.shape).reshape(-1)
    per_row = flat.size // out.shape[0] if out.ndim > 1 and out.shape[0] else 1
    for a in range(0, flat.size, OVERFLOW_SCAN_BLOCK):
        o = flat[a : a + OVERFLOW_SCAN_BLOCK]
        v = vin[a : a + OVERFLOW_SCAN_BLOCK]
        bad = ~np.isfinite(o) & np.isfinite(v)
        if bad.any():
            i = a + int(np.argmax(bad))
            raise ConversionOverflowError(
                f"{where + ': ' if where else ''}{float(vin[i]):.6g} at row "
                f"{first_row + i // per_row} becomes {float(flat[i])} on conversion "
                f"({what}), beyond any float64: a wrong unit or scale factor, or corrupt data"
            )


def canonical_unit(unit: str) -> str:
    """The unit figures of merit are reported in.

    Parameters
    ----------
    unit : str
        A signal unit.

    Returns
    -------
    str
        ``"deg/h"`` for rates, ``"mg"`` for accelerations, ``"counts"`` for raw counts
        (unless a scale factor converts them, :func:`counts_to_physical`).

    Examples
    --------
    >>> canonical_unit("rad/s"), canonical_unit("m/s^2")
    ('deg/h', 'mg')
    """
    kind = signal_kind(unit)
    return {"rate": "deg/h", "accel": "mg", "raw": "counts"}[kind]


def to_canonical(
    values: npt.ArrayLike,
    unit: str,
    where: str = "",
    first_row: int = 0,
    *,
    finite: bool = True,
) -> tuple[npt.NDArray[np.float64], str]:
    """Convert a signal to its canonical unit ([°/h] for rates, [mg] for accelerations).

    Data already in the canonical unit come back as they are (no copy): treat the
    result as read-only.

    Parameters
    ----------
    values : array_like
        The signal [``unit``].
    unit : str
        Its unit.
    where : str, optional
        The column, named in messages.
    first_row : int, optional
        Row number of the first value, for messages.
    finite : bool, optional
        Refuse a finite value that overflows (default True; False for callers that
        report such values themselves).

    Returns
    -------
    values : numpy.ndarray
        The converted signal.
    unit : str
        ``"deg/h"``, ``"mg"`` or ``"counts"``.

    Raises
    ------
    UnitError
        An unknown unit, or an overflow (:func:`refuse_overflow`).

    Examples
    --------
    >>> x, u = to_canonical([1.0], "deg/s")
    >>> x.tolist(), u
    ([3600.0], 'deg/h')
    """
    u = normalize_signal_unit(unit)
    arr = np.asarray(values, dtype=np.float64)
    factor = RATE_UNITS.get(u, ACCEL_UNITS.get(u))
    kind = "deg/h" if u in RATE_UNITS else "mg" if u in ACCEL_UNITS else "counts"
    if factor is None or factor == 1.0:
        return arr, kind
    with np.errstate(over="ignore"):
        out = arr * factor
    if finite:
        refuse_overflow(out, arr, f"{unit} → {kind}", where, first_row)
    return out, kind


def convert(
    values: npt.ArrayLike, from_unit: str, to_unit: str, where: str = ""
) -> npt.NDArray[np.float64]:
    """Convert between two signal units of the same kind (rate↔rate, accel↔accel).

    Parameters
    ----------
    values : array_like
        The signal [``from_unit``].
    from_unit, to_unit : str
        The units.
    where : str, optional
        The column, named in messages.

    Returns
    -------
    numpy.ndarray
        The signal [``to_unit``] (a copy).

    Raises
    ------
    UnitError
        An unknown unit, units of different kinds, or an overflow.

    Examples
    --------
    >>> convert([1000.0], "mg", "g").tolist()
    [1.0]
    """
    f = normalize_signal_unit(from_unit)
    t = normalize_signal_unit(to_unit)
    arr = np.asarray(values, dtype=np.float64)
    if f == t:
        return arr.copy()
    if f in RATE_UNITS and t in RATE_UNITS:
        factor = RATE_UNITS[f] / RATE_UNITS[t]
    elif f in ACCEL_UNITS and t in ACCEL_UNITS:
        factor = ACCEL_UNITS[f] / ACCEL_UNITS[t]
    else:
        raise UnitError(f"cannot convert {from_unit!r} to {to_unit!r}: different kinds of quantity")
    with np.errstate(over="ignore"):
        out = arr * factor
    refuse_overflow(out, arr, f"{from_unit} → {to_unit}", where)
    return out


def earth_rate_on_axis_deg_h(latitude_deg: float, axis_enu: npt.ArrayLike) -> float:
    r"""Earth rate seen by a sensitive axis.

    Parameters
    ----------
    latitude_deg : float
        Site latitude φ [°].
    axis_enu : array_like
        Direction of the sensitive axis in local East-North-Up (normalised here).

    Returns
    -------
    float
        The earth-rate component along the axis [°/h].

    Raises
    ------
    UnitError
        A zero direction vector.

    Notes
    -----
    .. math:: \Omega_{axis} = \Omega\,\mathbf u \cdot (0, \cos\varphi, \sin\varphi)

    with Ω the earth rate (:data:`EARTH_RATE_DEG_H`); for a vertical axis
    :math:`\Omega \sin\varphi`.

    References
    ----------
    - IEEE Std 952-1997, earth rate as an input of a stationary gyro.

    Examples
    --------
    >>> round(earth_rate_on_axis_deg_h(90.0, (0, 0, 1)), 3)
    15.041
    """
    u = np.asarray(axis_enu, dtype=np.float64).reshape(3)
    norm = float(np.linalg.norm(u))
    if norm == 0.0:
        raise UnitError("sensitive-axis direction must be a non-zero vector")
    phi = latitude_deg * DEG_TO_RAD
    w = np.array([0.0, math.cos(phi), math.sin(phi)]) * EARTH_RATE_DEG_H
    return float(np.dot(u / norm, w))


AXIS_NAMES: Final[dict[str, tuple[float, float, float]]] = {
    "up": (0.0, 0.0, 1.0),
    "down": (0.0, 0.0, -1.0),
    "north": (0.0, 1.0, 0.0),
    "south": (0.0, -1.0, 0.0),
    "east": (1.0, 0.0, 0.0),
    "west": (-1.0, 0.0, 0.0),
}
"""Named sensitive-axis directions in local East-North-Up."""


def parse_axis(axis: str | npt.ArrayLike) -> npt.NDArray[np.float64]:
    """A sensitive-axis direction as a unit vector in East-North-Up.

    Parameters
    ----------
    axis : str or array_like
        A name of :data:`AXIS_NAMES` (``"up"``, ``"north"`` …), the text ``"e,n,u"``,
        or three components.

    Returns
    -------
    numpy.ndarray
        Unit vector ``(e, n, u)`` [-].

    Raises
    ------
    UnitError
        An unknown name, not three components, or a zero vector.

    Examples
    --------
    >>> parse_axis("north").tolist(), parse_axis("3,0,4").tolist()
    ([0.0, 1.0, 0.0], [0.6, 0.0, 0.8])
    """
    if isinstance(axis, str):
        key = axis.strip().lower()
        if key in AXIS_NAMES:
            return np.array(AXIS_NAMES[key])
        try:
            vec = np.array([float(p) for p in key.split(",")])
        except ValueError:
            vec = np.zeros(0)
        if vec.shape != (3,):
            raise UnitError(
                f"unknown axis {axis!r}; use one of {', '.join(AXIS_NAMES)} or 'e,n,u' components"
            )
    else:
        vec = np.asarray(axis, dtype=np.float64).reshape(3)
    n = float(np.linalg.norm(vec))
    if n == 0.0:
        raise UnitError("sensitive-axis direction must be a non-zero vector")
    return vec / n


# --- gravity --------------------------------------------------------------------------

WGS84_EQUATORIAL_GRAVITY_M_S2: Final = 9.7803253359
"""WGS-84 normal gravity at the equator γe [m/s²] (NIMA TR8350.2, 3rd ed., table 3.4)."""
WGS84_SOMIGLIANA_K: Final = 0.00193185265241
"""Somigliana's constant k of WGS-84 [-] (NIMA TR8350.2, eq. 4-1)."""
WGS84_E2: Final = 0.00669437999013
"""First eccentricity squared e² of the WGS-84 ellipsoid [-] (NIMA TR8350.2, table 3.3)."""


def normal_gravity_m_s2(latitude_deg: float) -> float:
    r"""WGS 84 normal gravity on the ellipsoid at geodetic latitude φ.

    Height above the ellipsoid is neglected (−3.1e-6 m/s² per metre).

    Parameters
    ----------
    latitude_deg : float
        Geodetic latitude φ [°], within ±90.

    Returns
    -------
    float
        Normal gravity γ [m/s²]: 9.7803 at the equator, 9.8322 at the poles.

    Raises
    ------
    UnitError
        A latitude outside ±90°.

    Notes
    -----
    Somigliana's closed formula:

    .. math:: \gamma(\varphi) = \gamma_e \frac{1 + k \sin^2\varphi}{\sqrt{1 - e^2 \sin^2\varphi}}

    References
    ----------
    - NIMA TR8350.2, *Department of Defense World Geodetic System 1984: its definition
      and relationships with local geodetic systems*, 3rd ed., 2000, eq. 4-1.

    Examples
    --------
    >>> round(normal_gravity_m_s2(0.0), 4), round(normal_gravity_m_s2(90.0), 4)
    (9.7803, 9.8322)
    """
    if not -90.0 <= latitude_deg <= 90.0:
        raise UnitError(f"latitude must be within ±90°, got {latitude_deg}")
    s2 = math.sin(math.radians(latitude_deg)) ** 2
    return (
        WGS84_EQUATORIAL_GRAVITY_M_S2
        * (1.0 + WGS84_SOMIGLIANA_K * s2)
        / math.sqrt(1.0 - WGS84_E2 * s2)
    )


def parse_gravity_axis(text: str) -> tuple[str, float]:
    """The body axis pointing up in a static run.

    Parameters
    ----------
    text : str
        ``"+z"``, ``"-x"``, ``"z"`` …

    Returns
    -------
    letter : str
        ``"x"``, ``"y"`` or ``"z"``.
    sign : float
        +1.0 or −1.0: the sign of the specific force the axis reads.

    Raises
    ------
    UnitError
        Not a sign and one of x, y, z.

    Examples
    --------
    >>> parse_gravity_axis("-x")
    ('x', -1.0)
    """
    key = text.strip().lower().replace(" ", "")
    sign = -1.0 if key.startswith("-") else 1.0
    letter = key.lstrip("+-")
    if letter not in ("x", "y", "z"):
        raise UnitError.naming(
            f"{{gravity_axis}}: expected the body axis pointing up, +x, -x, +y, -y, +z or -z; "
            f"got {text!r}",
            "gravity_axis",
        )
    return letter, sign


def gravity_on_axis_mg(channel_axis: str, gravity_axis: str, gravity_m_s2: float) -> float:
    r"""Specific force of gravity read by a static accelerometer along one axis.

    Parameters
    ----------
    channel_axis : str
        The accelerometer's axis, ``"x"``, ``"y"`` or ``"z"``.
    gravity_axis : str
        The axis pointing up (``"+z"`` …).
    gravity_m_s2 : float
        Local gravity g [m/s²].

    Returns
    -------
    float
        :math:`\pm 1000\,g/g_0` on the up axis, 0 on the others [mg], with
        :math:`g_0` = 9.80665 m/s² (the unit of ``g`` and ``mg``).

    Examples
    --------
    >>> gravity_on_axis_mg("z", "-z", 9.80665)
    -1000.0
    """
    letter, sign = parse_gravity_axis(gravity_axis)
    if channel_axis != letter:
        return 0.0
    return sign * 1000.0 * gravity_m_s2 / STANDARD_GRAVITY_M_S2


# --- raw counts ----------------------------------------------------------------------

DEFAULT_SCALE_FACTOR_UNIT: Final = "counts/arcsec"
"""Unit of a scale factor K given without one: pulses per arcsec, the seed's ring-laser
gyro, stated in a :class:`UnitWarning` wherever it is used."""


def scale_factor_unit_or_default(unit: str | None, where: str = "") -> str:
    """The scale factor's unit, or the default stated in a warning.

    Parameters
    ----------
    unit : str or None
        The unit the metadata states.
    where : str, optional
        The file, named in the warning.

    Returns
    -------
    str
        ``unit``, else :data:`DEFAULT_SCALE_FACTOR_UNIT` (no silent default).

    Warns
    -----
    UnitWarning
        No unit stated.
    """
    if unit:
        return unit
    prefix = f"{where}: " if where else ""
    warnings.warn(
        UnitWarning(
            f"{prefix}the scale factor K has no unit stated; {DEFAULT_SCALE_FACTOR_UNIT} "
            "assumed (pulses per arcsec of a ring-laser gyro); state scale_factor_unit in "
            "the metadata"
        ),
        stacklevel=2,
    )
    return DEFAULT_SCALE_FACTOR_UNIT


SCALE_FACTOR_UNITS: Final[dict[str, tuple[bool, float, str]]] = {
    # unit of K: (integrating output?, factor to the canonical unit, canonical unit)
    "counts/deg": (True, SECONDS_PER_HOUR, "deg/h"),
    "counts/arcsec": (True, 1.0, "deg/h"),
    "counts/rad": (True, RS_TO_DH, "deg/h"),
    "counts/(deg/h)": (False, 1.0, "deg/h"),
    "counts/(deg/s)": (False, DS_TO_DH, "deg/h"),
    "counts/g": (False, G_TO_MG, "mg"),
    "counts/mg": (False, 1.0, "mg"),
}
"""Units of a scale factor K and how counts become a physical signal.

Integrating outputs (ring-laser and fibre-optic gyro pulse counts):
``rate = N / (τ K)`` with τ the sample interval [s], e.g. K in pulses per arcsec
gives [arcsec/s] = [°/h].  Non-integrating outputs (MEMS LSB): ``value = N / K``.
"""


def counts_to_physical(
    counts: npt.ArrayLike,
    scale_factor: float,
    scale_factor_unit: str,
    interval_s: float,
    where: str = "",
    first_row: int = 0,
    *,
    finite: bool = True,
) -> tuple[npt.NDArray[np.float64], str]:
    r"""Convert raw counts to the canonical unit ([°/h] or [mg]) with scale factor K.

    Parameters
    ----------
    counts : array_like
        Raw counts N per sample [counts].
    scale_factor : float
        Scale factor K [``scale_factor_unit``], finite and non-zero.
    scale_factor_unit : str
        A key of :data:`SCALE_FACTOR_UNITS` (``"counts/arcsec"``, ``"counts/g"`` …).
    interval_s : float
        Sample interval τ [s] (integrating outputs only).
    where : str, optional
        The column, named in messages.
    first_row : int, optional
        Row number of the first count, for messages.
    finite : bool, optional
        Refuse a finite count that overflows (default True).

    Returns
    -------
    values : numpy.ndarray
        The signal in its canonical unit.
    unit : str
        ``"deg/h"`` or ``"mg"``.

    Raises
    ------
    UnitError
        An unknown unit, K zero or not finite, τ not positive for a pulse output,
        or an overflow.

    Notes
    -----
    .. math:: \omega = \frac{N}{\tau K} \;\text{(pulse, integrating outputs)}, \qquad
        \omega = \frac{N}{K} \;\text{(otherwise)}

    References
    ----------
    - IEEE Std 952-1997, scale factor of a fibre-optic gyro's pulse output.

    Examples
    --------
    >>> x, u = counts_to_physical([10.0], 10.0, "counts/arcsec", 1.0)
    >>> x.tolist(), u
    ([1.0], 'deg/h')
    """
    if scale_factor_unit not in SCALE_FACTOR_UNITS:
        raise UnitError(
            f"unknown scale-factor unit {scale_factor_unit!r}; "
            f"known: {', '.join(SCALE_FACTOR_UNITS)}"
        )
    if not np.isfinite(scale_factor) or scale_factor == 0.0:
        raise UnitError(f"scale factor K must be finite and non-zero, got {scale_factor!r}")
    integrating, factor, unit = SCALE_FACTOR_UNITS[scale_factor_unit]
    arr = np.asarray(counts, dtype=np.float64)
    if integrating:
        if not interval_s > 0:
            raise UnitError("an integrating (pulse) output needs a positive sample interval τ")
        with np.errstate(over="ignore"):
            gain = factor / (interval_s * scale_factor)
    else:
        with np.errstate(over="ignore"):
            gain = factor / scale_factor
    if not math.isfinite(gain):
        raise UnitError(
            f"{where + ': ' if where else ''}scale factor K = {scale_factor:g} "
            f"{scale_factor_unit} makes one count an infinite {unit}"
        )
    with np.errstate(over="ignore"):
        out = arr * gain
    if finite:
        refuse_overflow(
            out, arr, f"counts → {unit}, K = {scale_factor:g} {scale_factor_unit}", where, first_row
        )
    return out, unit


@dataclass(frozen=True)
class ShownUnit:
    """The unit a channel's figures are shown in, and the factors to the model's unit.

    Attributes
    ----------
    unit : str
        The unit shown to the user.
    to_shown : float
        ``x[unit] = to_shown · x[model_unit]``.
    to_model : float
        ``x[model_unit] = to_model · x[unit]`` (both from :func:`convert`, each exact
        for its own direction).
    """

    unit: str
    to_shown: float
    to_model: float


def shown_unit(model_unit: str, data_unit: str | None) -> ShownUnit:
    """The data's own unit for figures computed in the model's unit.

    ``data_unit`` is kept as written when it is a physical unit of the model unit's
    kind (°/s data of a model in °/h: factor 1/3600).  Raw counts made physical by a
    scale factor, an unknown or missing unit, or another kind keep the model's unit,
    with factors 1.

    Parameters
    ----------
    model_unit : str
        The unit the model works in.
    data_unit : str or None
        The column's unit as given (option, file metadata or column name).

    Returns
    -------
    ShownUnit

    Examples
    --------
    >>> s = shown_unit("deg/h", "deg/s")
    >>> s.unit, round(s.to_shown * 3600, 9)
    ('deg/s', 1.0)
    """
    same = ShownUnit(model_unit, 1.0, 1.0)
    if not data_unit:
        return same
    try:
        mu, du = normalize_signal_unit(model_unit), normalize_signal_unit(data_unit)
        kind = signal_kind(mu)
        if kind == "raw" or signal_kind(du) != kind:
            return same
        return ShownUnit(
            data_unit,
            float(convert(1.0, model_unit, data_unit)),
            float(convert(1.0, data_unit, model_unit)),
        )
    except UnitError:
        return same
