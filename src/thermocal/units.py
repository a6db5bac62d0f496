"""Physical constants, unit strings and named conversions: the one glossary of thermocal.

Every quantity in thermocal carries its unit in its name (``rate_c_per_min``,
``bias_deg_h``), in its docstring (``[°/h]``) or in a unit field.  Conversions
are the named constants below; code never writes a bare ``3600`` or ``9.80665``.

Signal unit strings accepted on the command line and in files (INTERFACE.md):

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

Temperature unit strings: ``degC`` (also ``C``, ``°C``) and ``counts`` (raw ADC).

Sources: earth rate from WGS-84 (NIMA TR8350.2, 3rd ed., 2000);
standard gravity from CGPM 1901 (BIPM SI Brochure).
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final, Literal

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
ARCSEC_TO_RAD: Final = DEG_TO_RAD / 3600.0
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


def normalize_signal_unit(unit: str) -> str:
    """Return the canonical spelling of a signal unit, or raise :class:`UnitError`."""
    u = unit.strip()
    if u in SIGNAL_UNITS:
        return u
    alias = _SIGNAL_ALIASES.get(u.lower())
    if alias is not None:
        return alias
    raise UnitError(f"unknown signal unit {unit!r}; known units: {', '.join(SIGNAL_UNITS)}")


def normalize_temperature_unit(unit: str) -> str:
    """Return ``'degC'`` or ``'counts'``, or raise :class:`UnitError`."""
    alias = _TEMP_ALIASES.get(unit.strip().lower())
    if alias is None:
        raise UnitError(
            f"unknown temperature unit {unit!r}; known units: {', '.join(TEMPERATURE_UNITS)}"
        )
    return alias


def normalize_time_unit(unit: str) -> str:
    """Return ``'s'``, ``'ms'`` or ``'us'``, or raise :class:`UnitError`."""
    u = unit.strip().lower().replace("µ", "u")
    if u in TIME_UNITS:
        return u
    raise UnitError(f"unknown time unit {unit!r}; known units: {', '.join(TIME_UNITS)}")


# --- the one resolver: option > file metadata > column name > model file > stated default ---

UnitRole = Literal["time", "signal", "temperature"]
UnitSource = Literal["option", "metadata", "column name", "model", "default"]

DEFAULT_UNITS: Final[dict[str, str]] = {"time": "s", "signal": "deg/h", "temperature": "degC"}
"""What a column is taken to be in when nothing states its unit — always said in a
``warning:`` line (INTERFACE.md common rules), never assumed silently."""

_UNIT_OPTION: Final[dict[str, str]] = {
    "time": "--time-unit",
    "signal": "--signal-unit",
    "temperature": "--temp-unit",
}
_TIME_ALIASES: Final = {"sec": "s", "secs": "s", "msec": "ms", "usec": "us", "µs": "us"}
_NAME_BRACKET = re.compile(r"[\[(]\s*([^\])]+?)\s*[\])]\s*$")
_NAME_SEPARATORS = re.compile(r"[\s_]+")


def _normalize_time_alias(unit: str) -> str:
    alias: str = _TIME_ALIASES.get(unit.strip().lower()) or unit
    return normalize_time_unit(alias)


def _normalizer(role: UnitRole) -> Callable[[str], str]:
    table: dict[str, Callable[[str], str]] = {
        "time": _normalize_time_alias,
        "signal": normalize_signal_unit,
        "temperature": normalize_temperature_unit,
    }
    return table[role]


def unit_in_column_name(name: str, role: UnitRole) -> str | None:
    """The unit written in a column's name, or None.

    Recognised: a trailing bracket (``time (ms)``, ``gx [deg/s]``, ``temp [°C]``) and a
    last word after a space or underscore (``gyrox rad/s``, ``time_ms``,
    ``temp_counts``), when that word is a unit of the column's role (time, signal or
    temperature).  A name that is only a unit (``g``) or has no unit (``T1``) gives None.
    """
    norm = _normalizer(role)
    text = name.strip()
    m = _NAME_BRACKET.search(text)
    candidates = [m.group(1)] if m and text[: m.start()].strip() else []
    words = [w for w in _NAME_SEPARATORS.split(text) if w]
    if len(words) >= 2:
        candidates.append(words[-1])
    for c in candidates:
        try:
            return norm(c)
        except UnitError:
            continue
    return None


@dataclass(frozen=True)
class ResolvedUnit:
    """A column's unit and where it came from (``option`` … ``default``)."""

    unit: str
    source: UnitSource


def resolve_unit(
    column: str,
    role: UnitRole,
    *,
    option: str | None = None,
    metadata: str | None = None,
    model: str | None = None,
    where: str = "",
) -> ResolvedUnit:
    """The unit of ``column``, resolved once, in INTERFACE.md's order: command-line option
    > the file's own metadata > units in the column name > the units recorded in the model
    file > :data:`DEFAULT_UNITS`, the last stated in a :class:`UnitWarning`.  An option
    that contradicts the file's metadata wins, with a warning naming both.  This is the
    only place in thermocal that chooses a unit nobody stated.
    """
    norm = _normalizer(role)
    prefix = f"{where}: " if where else ""
    meta = norm(metadata) if metadata else None
    if option:
        opt = norm(option)
        if meta is not None and meta != opt:
            warnings.warn(
                UnitWarning(
                    f"{prefix}{_UNIT_OPTION[role]} {opt} contradicts the file's metadata, "
                    f"which says column {column!r} is in {meta}; using {opt}"
                ),
                stacklevel=2,
            )
        return ResolvedUnit(opt, "option")
    if meta is not None:
        return ResolvedUnit(meta, "metadata")
    named = unit_in_column_name(column, role)
    if named is not None:
        return ResolvedUnit(named, "column name")
    if model:
        return ResolvedUnit(norm(model), "model")
    default = DEFAULT_UNITS[role]
    warnings.warn(
        UnitWarning(
            f"{prefix}no unit stated for the {role} column {column!r}; assuming {default} "
            f"(give {_UNIT_OPTION[role]}, or the unit in the file's metadata or column name)"
        ),
        stacklevel=2,
    )
    return ResolvedUnit(default, "default")


def signal_kind(unit: str) -> SignalKind:
    """Kind of a signal unit: ``'rate'`` (gyro), ``'accel'`` or ``'raw'``."""
    u = normalize_signal_unit(unit)
    if u in RATE_UNITS:
        return "rate"
    if u in ACCEL_UNITS:
        return "accel"
    return "raw"


def canonical_unit(unit: str) -> str:
    """The unit figures of merit are reported in: [°/h] for rates, [mg] for accelerations.

    Raw counts stay ``'counts'`` unless a scale factor converts them (see
    :func:`to_canonical`).
    """
    kind = signal_kind(unit)
    return {"rate": "deg/h", "accel": "mg", "raw": "counts"}[kind]


def to_canonical(values: npt.ArrayLike, unit: str) -> tuple[npt.NDArray[np.float64], str]:
    """Convert a signal to its canonical unit ([°/h] for rates, [mg] for accelerations).

    Returns the converted float64 array and the canonical unit string.
    """
    u = normalize_signal_unit(unit)
    arr = np.asarray(values, dtype=np.float64)
    if u in RATE_UNITS:
        return arr * RATE_UNITS[u], "deg/h"
    if u in ACCEL_UNITS:
        return arr * ACCEL_UNITS[u], "mg"
    return arr, "counts"


def convert(values: npt.ArrayLike, from_unit: str, to_unit: str) -> npt.NDArray[np.float64]:
    """Convert between two signal units of the same kind (rate↔rate, accel↔accel)."""
    f = normalize_signal_unit(from_unit)
    t = normalize_signal_unit(to_unit)
    arr = np.asarray(values, dtype=np.float64)
    if f == t:
        return arr.copy()
    if f in RATE_UNITS and t in RATE_UNITS:
        return arr * (RATE_UNITS[f] / RATE_UNITS[t])
    if f in ACCEL_UNITS and t in ACCEL_UNITS:
        return arr * (ACCEL_UNITS[f] / ACCEL_UNITS[t])
    raise UnitError(f"cannot convert {from_unit!r} to {to_unit!r}: different kinds of quantity")


def earth_rate_on_axis_deg_h(latitude_deg: float, axis_enu: npt.ArrayLike) -> float:
    """Earth rate seen by a sensitive axis [°/h].

    The earth-rate vector in local East-North-Up is ``Ω (0, cos φ, sin φ)``
    (SPEC §1, §7); the axis reads its projection ``Ω_axis = Ω u·(0, cos φ, sin φ)``
    for a unit vector ``u`` (normalised here).  For a vertical axis this is ``Ω sin φ``.
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
    """Axis name (``up``, ``north``, …) or ``"e,n,u"`` triple → unit vector in ENU."""
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


# --- raw counts ----------------------------------------------------------------------

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

Integrating outputs (ring-laser and fibre-optic gyro pulse counts, SPEC §1):
``rate = N / (τ K)`` with τ the sample interval [s], e.g. K in pulses per arcsec
gives [arcsec/s] = [°/h].  Non-integrating outputs (MEMS LSB): ``value = N / K``.
"""


def counts_to_physical(
    counts: npt.ArrayLike, scale_factor: float, scale_factor_unit: str, interval_s: float
) -> tuple[npt.NDArray[np.float64], str]:
    """Convert raw counts to the canonical unit ([°/h] or [mg]) with scale factor K.

    SPEC §1: ``ω = N / (τ K)`` for pulse (integrating) outputs, ``N / K`` otherwise.
    Returns the converted array and the canonical unit string.
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
        return arr * (factor / (interval_s * scale_factor)), unit
    return arr * (factor / scale_factor), unit
