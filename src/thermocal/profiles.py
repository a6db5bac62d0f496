"""Chamber test profiles, their correlation, and the weakly-correlated validation design.

A :class:`Profile` is a start temperature and a list of segments:

* :class:`Hold` — keep the set-point for ``duration_s`` [s];
* :class:`Ramp` — move the set-point to ``target_c`` [°C] at ``rate_c_per_min`` [°C/min];
* :class:`Cycle` — repeat a list of segments ``repeats`` times.

Expanded, a profile is a continuous piecewise-linear set-point ``setpoint_c(t)``
(:meth:`Profile.pieces`, :meth:`Profile.knots`), written as a chamber program of
two columns ``time_s, setpoint_c`` (:meth:`Profile.program`,
:func:`thermocal.writers.write_program`).
Ramps therefore have exactly their rate and holds exactly their duration.

The built-in profiles (:data:`PROFILE_NAMES`, :func:`builtin_profile`) follow the
source documents: ``rlg-modelling`` and ``rlg-validation`` the RLG patent (*A modelling and
validation method for the temperature compensation model of a ring-laser gyroscope*),
``fog-slow`` the FOG thesis (*Design and engineering implementation of a fibre-optic-gyro
line-of-sight stabilisation system*, chapter 3), ``mems-warmup`` the MEMS test plan
(*Temperature-characteristic calibration test plan*), ``accel-full-range`` the accelerometer
patent (*Adaptive accelerometer temperature compensation method for inertial navigation*).

:func:`correlate` is the RLG patent's weak-correlation test ``r = Cov(X, Y)/(σ_X σ_Y)``
on a common elapsed-time base, and :func:`design_validation_profile`
searches (seeded) for a hold profile over the same temperature range with ``|r|``
below the limit.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.defaults import PROGRAM_SETPOINT as PROGRAM_SETPOINT
from thermocal.defaults import PROGRAM_TIME as PROGRAM_TIME
from thermocal.defaults import WEAK_CORRELATION_LIMIT as WEAK_CORRELATION_LIMIT
from thermocal.errors import (
    DesignError,
    ThermocalInputError,
    TimestampError,
)
from thermocal.units import SECONDS_PER_MINUTE

FloatArray = npt.NDArray[np.float64]


DEFAULT_CORRELATION_POINTS = 10_000
"""Number of points of the common elapsed-time base used by :func:`correlate`."""

# --- segments ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Hold:
    """Keep the current set-point for ``duration_s`` [s].

    Attributes
    ----------
    duration_s : float
        Duration [s].
    label : str
        Label of the hold.
    """

    duration_s: float
    label: str = ""

    def __post_init__(self) -> None:
        if not (math.isfinite(self.duration_s) and self.duration_s >= 0):
            raise ThermocalInputError(f"hold duration must be ≥ 0 s, got {self.duration_s!r}")


RAMP_RATE_RANGE = (1e-4, 1e3)
"""|ramp rate| [°C/min] a program may ask (1e-300 would make a program of 1e302 s and
exit 1); the fastest thermal-shock chambers move tens of °C/min."""


@dataclass(frozen=True)
class Ramp:
    """Move the set-point linearly to ``target_c`` [°C] at ``|rate_c_per_min|`` [°C/min].

    The duration is ``|target − current| / |rate| · 60`` [s]; the sign of the
    rate is ignored (the direction follows from the target).

    Attributes
    ----------
    target_c : float
        Set-point reached at the end [°C].
    rate_c_per_min : float
        Ramp rate [°C/min]; its sign is ignored.
    label : str
        Label of the ramp.
    """

    target_c: float
    rate_c_per_min: float
    label: str = ""

    def __post_init__(self) -> None:
        if not math.isfinite(self.target_c):
            raise ThermocalInputError(f"ramp target must be finite, got {self.target_c!r}")
        if not (math.isfinite(self.rate_c_per_min) and self.rate_c_per_min != 0):
            raise ThermocalInputError(
                f"ramp rate must be finite and non-zero, got {self.rate_c_per_min!r} °C/min"
            )
        lo, hi = RAMP_RATE_RANGE
        if not lo <= abs(self.rate_c_per_min) <= hi:
            raise ThermocalInputError.naming(
                f"ramp rate {self.rate_c_per_min:g} °C/min ({{rate_c_per_min}}, "
                f"{{cycle_rate_c_per_min}}, {{rates_c_per_min}}): a chamber ramps at {lo:g} to "
                f"{hi:g} °C/min; give a rate in that range",
                "rate_c_per_min",
                "cycle_rate_c_per_min",
                "rates_c_per_min",
            )


@dataclass(frozen=True)
class Cycle:
    """Repeat ``segments`` ``repeats`` times.

    When ``label`` is set, the pieces of repetition ``i`` (1-based) are labelled
    ``f"{label}{i}/{piece label}"``, so repetitions can be told apart
    (e.g. ``run3/soak-low``).

    Attributes
    ----------
    segments : tuple of Hold, Ramp or Cycle
        The segments of one repetition.
    repeats : int
        Number of repetitions.
    label : str
        Prefix of the labels of each repetition ("" : the pieces keep their labels).
    """

    segments: tuple[Segment, ...]
    repeats: int = 1
    label: str = ""

    def __post_init__(self) -> None:
        if int(self.repeats) != self.repeats or self.repeats < 1:
            raise ThermocalInputError(f"cycle repeats must be an integer ≥ 1, got {self.repeats!r}")


Segment = Hold | Ramp | Cycle


@dataclass(frozen=True)
class Piece:
    """One linear piece of an expanded profile: ``start_c`` at ``start_s`` to ``end_c`` at
    ``end_s`` ([s], [°C]); ``kind`` is ``"hold"`` or ``"ramp"``.

    Attributes
    ----------
    start_s, end_s : float
        Start and end [s] from the profile's start.
    start_c, end_c : float
        Set-point at the start and at the end [°C].
    kind : str
        ``"hold"`` or ``"ramp"``.
    label : str
        The label of the segment it comes from.
    """

    start_s: float
    end_s: float
    start_c: float
    end_c: float
    kind: str
    label: str = ""

    @property
    def duration_s(self) -> float:
        """Duration of the stage [s]."""
        return self.end_s - self.start_s

    @property
    def rate_c_per_min(self) -> float:
        """Slope [°C/min] (0 for a hold)."""
        d = self.duration_s
        return 0.0 if d == 0 else (self.end_c - self.start_c) / d * SECONDS_PER_MINUTE


@dataclass(frozen=True)
class Stage:
    """A constant-temperature stage (hold): ``start_s``..``end_s`` [s] at ``setpoint_c`` [°C].

    Attributes
    ----------
    start_s, end_s : float
        Start and end [s] from the profile's start.
    setpoint_c : float
        Set-point [°C].
    label : str
        Label of the hold.
    """

    start_s: float
    end_s: float
    setpoint_c: float
    label: str = ""

    def to_dict(self) -> dict[str, Any]:
        """The stage as a JSON-ready dict (times [s], set-point [°C])."""
        return {
            "label": self.label,
            "start_s": float(self.start_s),
            "end_s": float(self.end_s),
            "setpoint_c": float(self.setpoint_c),
        }


def _expand(
    segments: Sequence[Segment], t: float, temp: float, prefix: str, out: list[Piece]
) -> tuple[float, float]:
    for seg in segments:
        if isinstance(seg, Hold):
            if seg.duration_s > 0:
                out.append(Piece(t, t + seg.duration_s, temp, temp, "hold", prefix + seg.label))
                t += seg.duration_s
        elif isinstance(seg, Ramp):
            delta = seg.target_c - temp
            if delta != 0:
                dur = abs(delta) / abs(seg.rate_c_per_min) * SECONDS_PER_MINUTE
                out.append(Piece(t, t + dur, temp, seg.target_c, "ramp", prefix + seg.label))
                t += dur
                temp = seg.target_c
        elif isinstance(seg, Cycle):
            for i in range(int(seg.repeats)):
                sub = f"{prefix}{seg.label}{i + 1}/" if seg.label else prefix
                t, temp = _expand(seg.segments, t, temp, sub, out)
        else:  # pragma: no cover - typing guards this
            raise ThermocalInputError(f"unknown profile segment {seg!r}")
    return t, temp


@dataclass(frozen=True)
class Profile:
    """A chamber profile: start set-point ``start_c`` [°C] and a list of segments.

    ``params`` records the parameters a built-in profile was made with.

    Attributes
    ----------
    start_c : float
        Set-point at the start [°C].
    segments : tuple of Hold, Ramp or Cycle
        The program.
    name : str
        The built-in profile's name ("" : a profile of the user's).
    params : dict
        The parameters a built-in profile was made with.
    """

    start_c: float
    segments: tuple[Segment, ...]
    name: str = ""
    params: dict[str, Any] = field(default_factory=dict, compare=False)

    def pieces(self) -> list[Piece]:
        """The expanded linear pieces, in time order, from ``t = 0``."""
        out: list[Piece] = []
        _expand(self.segments, 0.0, float(self.start_c), "", out)
        return out

    @property
    def duration_s(self) -> float:
        """Total duration [s]."""
        p = self.pieces()
        return p[-1].end_s if p else 0.0

    def knots(self) -> tuple[FloatArray, FloatArray]:
        """Corner points ``(time_s, setpoint_c)`` of the piecewise-linear set-point."""
        p = self.pieces()
        if not p:
            return np.zeros(1), np.array([float(self.start_c)])
        t = np.array([p[0].start_s] + [q.end_s for q in p])
        c = np.array([p[0].start_c] + [q.end_c for q in p])
        return t, c

    def program(self, dt_s: float | None = 60.0) -> tuple[FloatArray, FloatArray]:
        """The chamber program ``(time_s, setpoint_c)``.

        With ``dt_s`` the set-point is sampled every ``dt_s`` seconds from 0 (the
        end point is appended when it is not on the grid); with ``None`` only the
        corner points are returned.  Linear interpolation of either reproduces the
        profile exactly at the returned times.

        Parameters
        ----------
        dt_s : float or None, optional
            Sampling interval [s] (default 60); None: corner points only.

        Returns
        -------
        tuple of numpy.ndarray
            Times [s] and set-points [°C].
        """
        tk, ck = self.knots()
        if dt_s is None:
            return tk, ck
        if not (math.isfinite(dt_s) and dt_s > 0):
            raise ThermocalInputError(f"program step must be > 0 s, got {dt_s!r}")
        end = float(tk[-1])
        n = math.floor(end / dt_s + 1e-9) + 1
        t = np.arange(n, dtype=np.float64) * dt_s
        if end - t[-1] > 1e-9 * max(1.0, end):
            t = np.append(t, end)
        return t, np.interp(t, tk, ck)

    def setpoint_at(self, time_s: npt.ArrayLike) -> FloatArray:
        """Set-point [°C] at the given elapsed times [s] (held at the ends).

        Parameters
        ----------
        time_s : array_like
            Elapsed times [s].

        Returns
        -------
        numpy.ndarray
            Set-points [°C].
        """
        tk, ck = self.knots()
        return np.interp(np.asarray(time_s, dtype=np.float64), tk, ck)

    def stages(self) -> list[Stage]:
        """The holds of the profile as :class:`Stage` (with their labels)."""
        return [
            Stage(p.start_s, p.end_s, p.start_c, p.label) for p in self.pieces() if p.kind == "hold"
        ]


# --- built-in profiles (the source documents) -----------------------------------------------------


def rlg_modelling(
    *,
    low_c: float = -20.0,
    high_c: float = 50.0,
    start_c: float = 20.0,
    n_temperature_cycles: int = 2,
    cycle_rate_c_per_min: float = 1.0,
    hold_s: float = 10800.0,
    rates_c_per_min: Sequence[float] = (2.0, 1.0, 0.5, 0.2, 0.1),
    rate_hold_s: float = 1800.0,
) -> Profile:
    """The modelling test of the RLG patent: cycles between ``low_c`` and ``high_c``, then
    cycles with ramps of ±2, ±1, ±0.5, ±0.2 and ±0.1 °C/min.

    Part 1 (label ``temperature-cycle``): ``n_temperature_cycles`` × (ramp to
    ``high_c``, hold ``hold_s``, ramp to ``low_c``, hold ``hold_s``) at
    ``cycle_rate_c_per_min``.  Part 2 (label ``rate ±R``): for each rate R, ramp to
    ``high_c`` and back to ``low_c`` at R with ``rate_hold_s`` holds at the ends.
    Finally a ramp back to ``start_c``.  The default lasts ≈ 65 h; its 3-h soaks at the
    extremes take the sensor further than the 2-h holds of ``rlg-validation``, so a
    model fitted on it covers the validation run without extrapolating.

    Parameters
    ----------
    low_c, high_c : float
        The cycles' ends [°C] (``low_c < high_c``).
    start_c : float
        Set-point at the start and at the end [°C].
    n_temperature_cycles : int
        Number of cycles of part 1.
    cycle_rate_c_per_min : float
        Ramp rate of part 1 [°C/min].
    hold_s : float
        Holds at the ends in part 1 [s].
    rates_c_per_min : sequence of float
        Ramp rates R of part 2 [°C/min].
    rate_hold_s : float
        Holds at the ends in part 2 [s].

    Returns
    -------
    Profile

    Raises
    ------
    ThermocalInputError
        ``low_c`` not below ``high_c``.
    """
    if not low_c < high_c:
        raise ThermocalInputError(f"low_c ({low_c}) must be below high_c ({high_c})")
    segs: list[Segment] = [
        Cycle(
            (
                Ramp(high_c, cycle_rate_c_per_min, "temperature-cycle"),
                Hold(hold_s, "temperature-cycle hold high"),
                Ramp(low_c, cycle_rate_c_per_min, "temperature-cycle"),
                Hold(hold_s, "temperature-cycle hold low"),
            ),
            repeats=int(n_temperature_cycles),
        )
    ]
    for r in rates_c_per_min:
        lab = f"rate ±{abs(r):g}"
        segs += [
            Ramp(high_c, r, lab),
            Hold(rate_hold_s, lab + " hold high"),
            Ramp(low_c, r, lab),
            Hold(rate_hold_s, lab + " hold low"),
        ]
    segs.append(Ramp(start_c, cycle_rate_c_per_min, "return"))
    return Profile(float(start_c), tuple(segs), "rlg-modelling")


DEFAULT_VALIDATION_HOLDS_C: tuple[float, ...] = (5.0, -20.0, 35.0, -5.0, 50.0, 20.0, -10.0, 40.0)
"""Hold temperatures of the default ``rlg-validation`` profile (|r| < 0.4 against the
default ``rlg-modelling`` profile; checked in the tests)."""


def rlg_validation(
    *,
    holds_c: Sequence[float] = DEFAULT_VALIDATION_HOLDS_C,
    hold_s: float | Sequence[float] = 7200.0,
    rate_c_per_min: float = 1.0,
    start_c: float = 20.0,
) -> Profile:
    """The validation test of the RLG patent: holds at several temperatures.

    From ``start_c``, for each temperature: ramp at ``rate_c_per_min``, hold
    ``hold_s`` (one value or one per hold; label ``hold {T:+g}``); then ramp back
    to ``start_c``.

    Parameters
    ----------
    holds_c : sequence of float
        Hold temperatures [°C], in order.
    hold_s : float or sequence of float
        Duration of each hold [s]: one for all or one per hold.
    rate_c_per_min : float
        Ramp rate between holds [°C/min].
    start_c : float
        Set-point at the start and at the end [°C].

    Returns
    -------
    Profile

    Raises
    ------
    ThermocalInputError
        No hold temperature, or a number of durations that is neither 1 nor one per hold.
    """
    holds = [float(h) for h in holds_c]
    if not holds:
        raise ThermocalInputError("rlg-validation needs at least one hold temperature")
    durs = (
        [float(hold_s)] * len(holds)
        if isinstance(hold_s, int | float)
        else [float(h) for h in hold_s]
    )
    if len(durs) != len(holds):
        raise ThermocalInputError(f"{len(durs)} hold durations for {len(holds)} hold temperatures")
    segs: list[Segment] = []
    for temp, dur in zip(holds, durs, strict=True):
        segs += [Ramp(temp, rate_c_per_min, "ramp"), Hold(dur, f"hold {temp:+g}")]
    segs.append(Ramp(start_c, rate_c_per_min, "return"))
    return Profile(float(start_c), tuple(segs), "rlg-validation")


def fog_slow(
    *,
    low_c: float = 15.0,
    high_c: float = 42.0,
    rate_c_per_min: float = 0.1,
    hold_s: float = 3600.0,
    n_cycles: int = 1,
) -> Profile:
    """The FOG thesis's slow drift over 15–42 °C: hold at ``low_c``, then ``n_cycles`` × (ramp
    to ``high_c`` at ``rate_c_per_min``, hold, ramp to ``low_c``, hold); ≈ 12 h by default.

    Parameters
    ----------
    low_c, high_c : float
        The range's ends [°C] (``low_c < high_c``).
    rate_c_per_min : float
        Ramp rate [°C/min].
    hold_s : float
        Hold at each end [s].
    n_cycles : int
        Number of cycles.

    Returns
    -------
    Profile

    Raises
    ------
    ThermocalInputError
        ``low_c`` not below ``high_c``.
    """
    if not low_c < high_c:
        raise ThermocalInputError(f"low_c ({low_c}) must be below high_c ({high_c})")
    segs: tuple[Segment, ...] = (
        Hold(hold_s, "hold low"),
        Cycle(
            (
                Ramp(high_c, rate_c_per_min, "ramp up"),
                Hold(hold_s, "hold high"),
                Ramp(low_c, rate_c_per_min, "ramp down"),
                Hold(hold_s, "hold low"),
            ),
            repeats=int(n_cycles),
        ),
    )
    return Profile(float(low_c), segs, "fog-slow")


POWER_ON_LABEL = "power-on"
"""Label prefix of the holds during which a unit is powered on (``mems-warmup``)."""


def power_on_label(start_c: float) -> str:
    """``'power-on T+25'`` — the label of a power-on hold at ``start_c``.

    Parameters
    ----------
    start_c : float
        Temperature of the power-on hold [°C].

    Returns
    -------
    str
        The label.
    """
    return f"{POWER_ON_LABEL} T{start_c:+g}"


def mems_warmup(
    *,
    start_temps_c: Sequence[float] = (-40.0, -20.0, 0.0, 20.0, 40.0, 60.0, 80.0),
    soak_s: float = 3600.0,
    record_s: float = 900.0,
    transition_rate_c_per_min: float = 2.0,
    start_c: float = 20.0,
) -> Profile:
    """Warm-ups at several start temperatures (the MEMS test plan).

    For each start temperature T0: ramp to T0, soak ``soak_s`` unpowered (label
    ``soak T0``), then hold ``record_s`` ≥ 6 min with the unit powered (label
    ``power-on T{T0:+g}``, see :func:`power_on_label`).

    Parameters
    ----------
    start_temps_c : sequence of float
        The start temperatures T0 [°C].
    soak_s : float
        Unpowered soak at each T0 [s].
    record_s : float
        Powered record after each soak [s] (≥ 360 s).
    transition_rate_c_per_min : float
        Rate of the ramps between start temperatures [°C/min].
    start_c : float
        Set-point at the start [°C].

    Returns
    -------
    Profile

    Raises
    ------
    ThermocalInputError
        ``record_s`` below 6 min.
    """
    if record_s < 360:
        raise ThermocalInputError(
            f"record_s must be ≥ 360 s (6 min, the MEMS test plan), got {record_s}"
        )
    segs: list[Segment] = []
    for t0 in start_temps_c:
        segs += [
            Ramp(float(t0), transition_rate_c_per_min, "transition"),
            Hold(soak_s, f"soak T{float(t0):+g}"),
            Hold(record_s, power_on_label(float(t0))),
        ]
    segs.append(Ramp(start_c, transition_rate_c_per_min, "return"))
    return Profile(float(start_c), tuple(segs), "mems-warmup")


RUN_LABEL = "run"
"""Cycle label of the repetitions of ``accel-full-range`` (pieces ``run1/...``)."""


def accel_full_range(
    *,
    low_c: float = -40.0,
    high_c: float = 60.0,
    soak_s: float = 7200.0,
    rate_c_per_min: float = 2.0,
    step_c: float = 5.0,
    point_hold_s: float = 1800.0,
    repeats: int = 5,
    start_c: float = 20.0,
    startup_s: float = 600.0,
) -> Profile:
    """The full-range test of the accelerometer patent, repeated ``repeats`` times (one run each).

    Each run (labels ``run{i}/...``): ``startup`` hold at ``start_c`` (power-on),
    cool to ``low_c`` and soak ``soak_s`` (``soak-low``), ramp at ``rate_c_per_min``
    to ``high_c`` (``ramp``, type-1 data) and soak (``soak-high``), then constant
    points every ``step_c`` from ``low_c`` to ``high_c`` held ``point_hold_s``
    (``point {T:+g}``, type-2 data), and return to ``start_c``.

    Parameters
    ----------
    low_c, high_c : float
        The range's ends [°C] (``low_c < high_c``).
    soak_s : float
        Soak at each end [s].
    rate_c_per_min : float
        Rate of the ramp from ``low_c`` to ``high_c`` [°C/min].
    step_c : float
        Step between the constant points [°C] (> 0).
    point_hold_s : float
        Hold at each constant point [s].
    repeats : int
        Number of runs.
    start_c : float
        Set-point at power-on and at the end of each run [°C].
    startup_s : float
        Hold at ``start_c`` after power-on [s].

    Returns
    -------
    Profile

    Raises
    ------
    ThermocalInputError
        ``low_c`` not below ``high_c`` or a step that is not positive.
    """
    if not low_c < high_c:
        raise ThermocalInputError(f"low_c ({low_c}) must be below high_c ({high_c})")
    if not step_c > 0:
        raise ThermocalInputError(f"step_c must be > 0, got {step_c}")
    n_pts = math.floor((high_c - low_c) / step_c + 1e-9) + 1
    points = [low_c + i * step_c for i in range(n_pts)]
    run: list[Segment] = [
        Hold(startup_s, "startup"),
        Ramp(low_c, rate_c_per_min, "cool"),
        Hold(soak_s, "soak-low"),
        Ramp(high_c, rate_c_per_min, "ramp"),
        Hold(soak_s, "soak-high"),
    ]
    for p in points:
        run += [Ramp(p, rate_c_per_min, "transition"), Hold(point_hold_s, f"point {p:+g}")]
    run.append(Ramp(start_c, rate_c_per_min, "return"))
    return Profile(
        float(start_c), (Cycle(tuple(run), int(repeats), RUN_LABEL),), "accel-full-range"
    )


PROFILE_BUILDERS: dict[str, Callable[..., Profile]] = {
    "rlg-modelling": rlg_modelling,
    "rlg-validation": rlg_validation,
    "fog-slow": fog_slow,
    "mems-warmup": mems_warmup,
    "accel-full-range": accel_full_range,
}
"""Registry of the built-in profiles (name → keyword-only builder)."""

PROFILE_NAMES: tuple[str, ...] = tuple(PROFILE_BUILDERS)


def builtin_profile(name: str, **params: Any) -> Profile:
    """A built-in profile by name (:data:`PROFILE_NAMES`) with keyword parameters.

    Raises :class:`ThermocalInputError` for an unknown name or parameter.

    Parameters
    ----------
    name : str
        Profile name (:data:`PROFILE_NAMES`).
    **params
        The profile's keyword parameters (temperatures [°C], durations [s], rates [°C/min]).

    Returns
    -------
    Profile
        The profile.

    Raises
    ------
    ThermocalInputError
        An unknown name or parameter.

    Examples
    --------
    >>> from thermocal.profiles import PROFILE_NAMES, builtin_profile
    >>> p = builtin_profile(PROFILE_NAMES[0])
    >>> t, sp = p.program(None)
    >>> bool(t[0] == 0.0 and len(t) == len(sp))
    True
    """
    try:
        builder = PROFILE_BUILDERS[name]
    except KeyError:
        raise ThermocalInputError(
            f"unknown profile {name!r}; known profiles: {', '.join(PROFILE_NAMES)}"
        ) from None
    try:
        prof = builder(**params)
    except TypeError as exc:
        raise ThermocalInputError(f"profile {name!r}: {exc}") from None
    return Profile(prof.start_c, prof.segments, name, dict(params))


# --- program files -------------------------------------------------------------------------------


ABSOLUTE_ZERO_C = -273.15
"""Absolute zero [°C] (0 K; the kelvin's definition, SI Brochure 9th ed. §2.3.1)."""


def check_program(time_s: npt.ArrayLike, setpoint_c: npt.ArrayLike, what: str = "program") -> None:
    """Raise :class:`ThermocalInputError` unless time is finite and strictly increasing and
    the set-points are finite and not below absolute zero, with at least two points.

    Parameters
    ----------
    time_s : array_like
        Times [s].
    setpoint_c : array_like
        Set-points [°C].
    what : str, optional
        What the message names (default ``"program"``).

    Raises
    ------
    ThermocalInputError
        On any of the faults above.
    """
    t = np.asarray(time_s, dtype=np.float64)
    c = np.asarray(setpoint_c, dtype=np.float64)
    if t.ndim != 1 or t.shape != c.shape:
        raise ThermocalInputError(f"{what}: time and set-point must be 1-D of equal length")
    if t.size < 2:
        raise ThermocalInputError(f"{what}: needs at least two points")
    bad = np.flatnonzero(~np.isfinite(t) | ~np.isfinite(c))
    if bad.size:
        raise ThermocalInputError(f"{what}: missing or non-finite value at row {bad[0]}")
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        raise TimestampError(
            f"{what}: time must increase strictly; row {back[0] + 1} ({float(t[back[0] + 1])!r}) "
            f"follows {float(t[back[0]])!r}"
        )
    cold = np.flatnonzero(c < ABSOLUTE_ZERO_C)
    if cold.size:
        raise ThermocalInputError(
            f"{what}: set-point {float(c[cold[0]])!r} °C at row {cold[0]} is below absolute "
            f"zero ({ABSOLUTE_ZERO_C} °C): a set-point is a temperature in °C"
        )


def find_holds(
    time_s: npt.ArrayLike,
    setpoint_c: npt.ArrayLike,
    min_duration_s: float = 600.0,
    tol_c: float = 1e-6,
) -> list[Stage]:
    """Constant-set-point stages of a program lasting at least ``min_duration_s`` [s].

    A stage is a maximal run of consecutive points whose set-point stays within
    ``tol_c`` of its first value; the program is linear between points.

    Parameters
    ----------
    time_s : array_like
        Program times [s].
    setpoint_c : array_like
        Set-points [°C].
    min_duration_s : float, optional
        Shortest hold [s] (default 600).
    tol_c : float, optional
        Set-point tolerance [°C] (default 1e-6).

    Returns
    -------
    list of Stage
        The holds.

    Examples
    --------
    >>> from thermocal.profiles import find_holds
    >>> [(s.start_s, s.end_s) for s in find_holds([0, 600, 1200, 1800], [25, 25, 40, 40])]
    [(0.0, 600.0), (1200.0, 1800.0)]
    """
    t = np.asarray(time_s, dtype=np.float64)
    c = np.asarray(setpoint_c, dtype=np.float64)
    check_program(t, c)
    flat = np.abs(np.diff(c)) <= tol_c
    stages: list[Stage] = []
    i = 0
    n = flat.size
    while i < n:
        if not flat[i]:
            i += 1
            continue
        j = i
        while j < n and flat[j] and abs(c[j + 1] - c[i]) <= tol_c:
            j += 1
        if t[j] - t[i] >= min_duration_s:
            stages.append(Stage(float(t[i]), float(t[j]), float(c[i]), f"hold {c[i]:+g}"))
        i = max(j, i + 1)
    return stages


# --- correlation (the RLG patent) -----------------------------------------------------------------


@dataclass(frozen=True)
class CorrelationResult:
    """Correlation of two temperature histories on a common elapsed-time base.

    r : Pearson coefficient ``Cov(X, Y)/(σ_X σ_Y)``; weakly_correlated : ``r < r_limit``
    (the RLG patent literally; see :func:`correlate`); n : number of common points;
    duration_s : length of the common base [s]; r_limit : the limit used.

    Attributes
    ----------
    r : float
        Pearson coefficient.
    weakly_correlated : bool
        ``r < r_limit``.
    n : int
        Number of common points.
    duration_s : float
        Length of the common base [s].
    r_limit : float
        The limit used.
    """

    r: float
    weakly_correlated: bool
    n: int
    duration_s: float = float("nan")
    r_limit: float = WEAK_CORRELATION_LIMIT

    def to_dict(self) -> dict[str, Any]:
        """The result as plain Python values, as the ``profile correlate`` command's JSON
        prints it (before the columns' names): ``r``, ``weakly_correlated``, ``r_limit``,
        ``n`` and ``duration_s`` [s]."""
        return {
            "r": self.r,
            "weakly_correlated": self.weakly_correlated,
            "r_limit": self.r_limit,
            "n": self.n,
            "duration_s": self.duration_s,
        }


def program_summary(
    profile: Profile, time_s: npt.ArrayLike, setpoint_c: npt.ArrayLike, file: str
) -> dict[str, Any]:
    """What the ``profile`` command's JSON prints of a written chamber program.

    Parameters
    ----------
    profile : Profile
        The profile the program samples.
    time_s : array_like
        The program's times [s] (:meth:`Profile.program`).
    setpoint_c : array_like
        Its set-points [°C].
    file : str
        Where the program was written.

    Returns
    -------
    dict
        ``profile`` (its name), ``file``, ``n_points``, ``duration_s`` [s] (the last
        time), ``min_c``/``max_c`` [°C] (the set-points' range) and ``params`` (the
        profile's parameters).

    Examples
    --------
    >>> prof = builtin_profile("rlg-validation")
    >>> t, c = prof.program(None)
    >>> s = program_summary(prof, t, c, "val.csv")
    >>> s["n_points"] == t.size, s["min_c"] == float(c.min())
    (True, True)
    """
    t = np.asarray(time_s, dtype=np.float64)
    c = np.asarray(setpoint_c, dtype=np.float64)
    return {
        "profile": profile.name,
        "file": file,
        "n_points": int(t.size),
        "duration_s": float(t[-1]),
        "min_c": float(np.min(c)),
        "max_c": float(np.max(c)),
        "params": profile.params,
    }


def _clean_history(t: npt.ArrayLike, y: npt.ArrayLike, what: str) -> tuple[FloatArray, FloatArray]:
    ta = np.asarray(t, dtype=np.float64).ravel()
    ya = np.asarray(y, dtype=np.float64).ravel()
    if ta.shape != ya.shape:
        raise ThermocalInputError(f"{what}: time and temperature differ in length")
    ok = np.isfinite(ta) & np.isfinite(ya)
    ta, ya = ta[ok], ya[ok]
    if ta.size < 2:
        raise ThermocalInputError(f"{what}: fewer than two finite samples")
    if np.any(np.diff(ta) <= 0):
        raise TimestampError(f"{what}: time must increase strictly")
    return ta - ta[0], ya


def common_base(
    time_a: npt.ArrayLike,
    temp_a: npt.ArrayLike,
    time_b: npt.ArrayLike,
    temp_b: npt.ArrayLike,
    n_points: int = DEFAULT_CORRELATION_POINTS,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Resample two histories on a common elapsed-time base (thermocal's reading).

    Both are timed from their own first sample; the base is ``n_points`` uniform
    times over the overlap ``[0, min(duration_a, duration_b)]``; values are linearly
    interpolated (a chamber program is linear between its points).  Returns
    ``(elapsed_s, x, y)``.

    Parameters
    ----------
    time_a, temp_a : array_like
        Times [s] and temperatures [°C] of the first history.
    time_b, temp_b : array_like
        Times [s] and temperatures [°C] of the second history.
    n_points : int, optional
        Points of the common base (default :data:`DEFAULT_CORRELATION_POINTS`).

    Returns
    -------
    tuple of numpy.ndarray
        Elapsed times [s] and the two resampled histories [°C].
    """
    ta, xa = _clean_history(time_a, temp_a, "history A")
    tb, xb = _clean_history(time_b, temp_b, "history B")
    dur = min(float(ta[-1]), float(tb[-1]))
    if not dur > 0:
        raise ThermocalInputError("the two histories do not overlap in elapsed time")
    if n_points < 3:
        raise ThermocalInputError(f"n_points must be ≥ 3, got {n_points}")
    base = np.linspace(0.0, dur, int(n_points))
    return base, np.interp(base, ta, xa), np.interp(base, tb, xb)


def pearson_r(x: FloatArray, y: FloatArray) -> float:
    r"""Pearson's correlation coefficient of two equally long histories (the RLG patent).

    Parameters
    ----------
    x, y : numpy.ndarray
        The two histories [°C], on one time base.

    Returns
    -------
    float
        r in [−1, 1].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Either history is constant (r undefined).

    Notes
    -----
    .. math:: r = \frac{\mathrm{Cov}(X, Y)}{\sigma_X \sigma_Y}
              = \frac{\sum (x_i - \bar x)(y_i - \bar y)}
                     {\sqrt{\sum (x_i - \bar x)^2 \sum (y_i - \bar y)^2}}

    Examples
    --------
    >>> round(pearson_r(np.array([1.0, 2.0, 3.0, 4.0]), np.array([2.0, 1.0, 4.0, 3.0])), 3)
    0.6
    """
    dx = x - x.mean()
    dy = y - y.mean()
    sx = float(np.sqrt(np.dot(dx, dx)))
    sy = float(np.sqrt(np.dot(dy, dy)))
    scale = max(float(np.max(np.abs(x))), float(np.max(np.abs(y))), 1.0)
    if sx <= 1e-12 * scale * math.sqrt(x.size) or sy <= 1e-12 * scale * math.sqrt(y.size):
        raise ThermocalInputError(
            "a temperature history is constant over the common time base; r is undefined"
        )
    return float(np.clip(np.dot(dx, dy) / (sx * sy), -1.0, 1.0))


def correlate(
    time_a: npt.ArrayLike,
    temp_a: npt.ArrayLike,
    time_b: npt.ArrayLike,
    temp_b: npt.ArrayLike,
    *,
    r_limit: float = WEAK_CORRELATION_LIMIT,
    n_points: int = DEFAULT_CORRELATION_POINTS,
) -> CorrelationResult:
    """Correlation of two temperature histories (the RLG patent).

    Parameters
    ----------
    time_a, temp_a : array_like
        Times [s] and temperatures [°C] of the first history (e.g. the modelling test).
    time_b, temp_b : array_like
        Times [s] and temperatures [°C] of the second (e.g. the validation test).
    r_limit : float
        ``weakly_correlated`` is r < r_limit.
    n_points : int
        Points of the common elapsed-time base.

    Returns
    -------
    CorrelationResult
        r, whether the histories are weakly correlated, the common base's size and length.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A history that is constant on the common base (r undefined), or too short.

    Notes
    -----
    :func:`pearson_r` of X, Y, the two histories on the common elapsed-time base of
    :func:`common_base` (non-finite samples dropped).  ``weakly_correlated`` is
    r < r_limit as the RLG patent states it (a strongly *negative* r also passes;
    :func:`design_validation_profile` aims at ``|r|``).

    Examples
    --------
    A sine and a cosine over one whole period are uncorrelated:

    >>> t = np.arange(0.0, 3600.0, 10.0)
    >>> res = correlate(t, np.sin(2 * np.pi * t / 3600), t, np.cos(2 * np.pi * t / 3600))
    >>> round(res.r, 2) == 0.0, res.weakly_correlated
    (True, True)
    """
    base, x, y = common_base(time_a, temp_a, time_b, temp_b, n_points)
    r = pearson_r(x, y)
    return CorrelationResult(r, bool(r < r_limit), int(base.size), float(base[-1]), r_limit)


# --- validation-profile design -------------------------------------------------------------------


def design_validation_profile(
    model_time_s: npt.ArrayLike,
    model_setpoint_c: npt.ArrayLike,
    seed: int,
    r_limit: float = WEAK_CORRELATION_LIMIT,
    *,
    n_holds: int | None = None,
    hold_s: float = 7200.0,
    rate_c_per_min: float = 1.0,
    n_candidates: int = 400,
    n_points: int = 2000,
) -> Profile:
    """Design a hold profile weakly correlated with a modelling test (thermocal's reading).

    The hold temperatures are ``n_holds`` evenly spaced values over the modelling
    range ``[min, max]`` (so the validation covers the same range; default: one
    per 10 °C, at least 4).  ``n_candidates`` random orders and hold durations
    (each in ``[0.5, 1.5]·hold_s``), drawn from ``numpy.random.default_rng(seed)``,
    are scored by ``|r|`` against the modelling history (:func:`correlate` on
    ``n_points``); the candidate with the smallest ``|r|`` is returned, ramps at
    ``rate_c_per_min`` from and back to the modelling start temperature.

    Raises :class:`DesignError` when no candidate reaches ``|r| < r_limit``.

    Parameters
    ----------
    model_time_s, model_setpoint_c : array_like
        The modelling test's times [s] and set-points [°C].
    seed : int
        Seed of the random generator.
    r_limit : float, optional
        Largest accepted ``|r|`` (default :data:`WEAK_CORRELATION_LIMIT`).
    n_holds : int, optional
        Number of holds (default one per 10 °C, at least 4).
    hold_s : float, optional
        Mean hold duration [s] (default 7200).
    rate_c_per_min : float, optional
        Ramp rate [°C/min] (default 1).
    n_candidates, n_points : int, optional
        Random candidates (default 400) and correlation points (default 2000).

    Returns
    -------
    Profile
        The validation profile.

    Raises
    ------
    DesignError
        When no candidate reaches ``|r| < r_limit``.
    """
    tm = np.asarray(model_time_s, dtype=np.float64)
    cm = np.asarray(model_setpoint_c, dtype=np.float64)
    check_program(tm, cm, "modelling history")
    lo, hi = float(np.min(cm)), float(np.max(cm))
    if not hi - lo > 0:
        raise ThermocalInputError("the modelling history is constant; nothing to correlate")
    if n_holds is None:
        n_holds = max(4, round((hi - lo) / 10.0) + 1)
    if n_holds < 2:
        raise ThermocalInputError(f"n_holds must be ≥ 2, got {n_holds}")
    temps = np.linspace(lo, hi, int(n_holds))
    start = float(cm[0])
    rng = np.random.default_rng(seed)
    best: tuple[float, Profile] | None = None
    for _ in range(int(n_candidates)):
        order = rng.permutation(temps)
        durs = hold_s * rng.uniform(0.5, 1.5, size=order.size)
        prof = rlg_validation(
            holds_c=[round(float(v), 6) for v in order],
            hold_s=[round(float(d), 1) for d in durs],
            rate_c_per_min=rate_c_per_min,
            start_c=start,
        )
        tv, cv = prof.knots()
        res = correlate(tm, cm, tv, cv, r_limit=r_limit, n_points=n_points)
        if best is None or abs(res.r) < best[0]:
            best = (abs(res.r), prof)
    assert best is not None
    if not best[0] < r_limit:
        raise DesignError(
            f"no validation profile with |r| < {r_limit} found in {n_candidates} candidates "
            f"(best |r| = {best[0]:.3f}); try more holds or candidates"
        )
    params = {"seed": int(seed), "r_limit": float(r_limit), "abs_r": float(best[0])}
    return Profile(best[1].start_c, best[1].segments, "rlg-validation", params)
