"""Plateaus of a rate-table run: the steady stretches at each commanded rate.

Three sources, in the order a user has them:

* the table's own rate column (encoder or commanded rate, °/s): runs of samples whose rate
  changes by less than a tolerance from one sample to the next (:func:`plateaus_from_rate`);
* the gyro's output alone: window means that agree with their neighbours within the
  output's own noise, separated by the accelerations between rates
  (:func:`plateaus_from_output`);
* a schedule (start, end, rate) given by the user (:func:`plateaus_from_schedule`).

Every plateau drops its first ``settle_s`` seconds (the table's and the sensor's settling
after each change of rate), and the result says so.  :func:`match_rates` pairs plateaus found
in the output with the rates the user gives and refuses a ladder that does not fit.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from thermocal.errors import DesignError, ParameterError

FloatArray = npt.NDArray[np.float64]

SETTLE_S = 1.0
"""Settling dropped at the start of every plateau [s]."""
MIN_PLATEAU_S = 5.0
"""Shortest plateau kept [s] (after the settling)."""
WINDOW_S = 0.5
"""Window of the output-based detector [s]."""
STEADY_SIGMAS = 6.0
"""Window means within this many standard errors of each other are one plateau."""
DROPPED_S = 1.0
"""Steady stretches at least this long but too short for a plateau are reported [s]."""
BLOCKS = 10
"""Blocks of a plateau whose means give the standard error without assuming white noise."""
ORDER_SIGMAS = 5.0
"""Two plateaus out of the given rates' order by more than this many standard errors: refused."""


@dataclass(frozen=True)
class Plateau:
    """One steady stretch of a rate-table run.

    Attributes
    ----------
    start_s, end_s : float
        The stretch used, settling excluded [s].
    i0, i1 : int
        Its sample indices (``i0`` inclusive, ``i1`` exclusive).
    rate_dps : float
        The applied rate [°/s] (NaN until matched with a given rate).
    mean : float
        Mean output [output unit].
    sd : float
        Standard deviation of the samples [output unit].
    n : int
        Number of samples.
    temperature_c : float or None
        Mean temperature [°C], None without a temperature.
    se_blocks : float or None
        Standard error of the mean from ``BLOCKS`` block means [output unit] (None with
        fewer than ``BLOCKS`` × 10 samples): larger than :attr:`se` when the noise is
        correlated (flicker, random walk).
    """

    start_s: float
    end_s: float
    i0: int
    i1: int
    rate_dps: float
    mean: float
    sd: float
    n: int
    temperature_c: float | None = None
    se_blocks: float | None = None

    @property
    def se(self) -> float:
        """Standard error of the mean [output unit]: ``sd / √n`` (white noise)."""
        return float(self.sd / np.sqrt(self.n))


@dataclass(frozen=True)
class Detection:
    """The plateaus found and what was left out.

    Attributes
    ----------
    plateaus : tuple of Plateau
        The plateaus, in time order.
    settle_s : float
        Settling dropped at each plateau's start [s].
    source : str
        ``"rate column"``, ``"output"`` or ``"schedule"``.
    dropped : tuple of (float, float)
        Steady stretches shorter than ``min_plateau_s`` left out (start, end) [s].
    """

    plateaus: tuple[Plateau, ...]
    settle_s: float
    source: str
    dropped: tuple[tuple[float, float], ...] = ()


def _check_positive(name: str, value: float) -> None:
    """Refuse a parameter that is not a positive finite number."""
    if not (np.isfinite(value) and value > 0):
        raise ParameterError(name, f"{{name}} must be a positive number, got {value!r}")


def _runs(mask: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Start (inclusive) and end (exclusive) of each run of True."""
    m = np.concatenate(([False], mask, [False])).astype(np.int8)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist(), strict=True))


def _summarise(
    t: FloatArray,
    y: FloatArray,
    spans: Sequence[tuple[int, int]],
    rates: Sequence[float] | None,
    temp: FloatArray | None,
    settle_s: float,
    min_plateau_s: float,
) -> tuple[list[Plateau], list[tuple[float, float]]]:
    """Plateaus of the spans, settling dropped; spans too short after it are returned apart."""
    out: list[Plateau] = []
    dropped: list[tuple[float, float]] = []
    for k, (a, b) in enumerate(spans):
        a2 = int(np.searchsorted(t, t[a] + settle_s, side="left"))
        if b - a2 < 2 or t[b - 1] - t[a2] < min_plateau_s:
            if t[b - 1] - t[a] >= DROPPED_S:
                dropped.append((float(t[a]), float(t[b - 1])))
            continue
        seg = y[a2:b]
        tc = None if temp is None else float(np.mean(temp[a2:b]))
        rate = float("nan") if rates is None else float(rates[k])
        out.append(
            Plateau(
                float(t[a2]),
                float(t[b - 1]),
                a2,
                b,
                rate,
                float(np.mean(seg)),
                float(np.std(seg, ddof=1)),
                int(seg.size),
                tc,
                _se_blocks(seg),
            )
        )
    return out, dropped


def plateaus_from_rate(
    time_s: npt.ArrayLike,
    output: npt.ArrayLike,
    table_rate_dps: npt.ArrayLike,
    *,
    temperature_c: npt.ArrayLike | None = None,
    settle_s: float = SETTLE_S,
    min_plateau_s: float = MIN_PLATEAU_S,
    tolerance_dps: float = 1e-3,
) -> Detection:
    """Plateaus from the table's rate column: runs where the rate holds still.

    Parameters
    ----------
    time_s : array_like
        Sample times [s], increasing.
    output : array_like
        The gyro's output [its unit].
    table_rate_dps : array_like
        The table's rate [°/s] (encoder or commanded).
    temperature_c : array_like, optional
        Temperature [°C].
    settle_s : float
        Settling dropped at each plateau's start [s].
    min_plateau_s : float
        Shortest plateau kept [s].
    tolerance_dps : float
        Largest change of the rate between two samples of one plateau [°/s], plus
        ``1e-5`` of the rate.

    Returns
    -------
    Detection
        Each plateau's rate is the mean of the rate column over it, rounded to the decimal
        of ``tolerance_dps`` (three decimals of °/s by default), so that the repeated visits
        of a rate are one rate.

    Raises
    ------
    DesignError
        No plateau of at least ``min_plateau_s``.

    Examples
    --------
    >>> t = np.arange(0, 40, 0.1)
    >>> r = np.where(t < 20, 10.0, -10.0)
    >>> d = plateaus_from_rate(t, 2 * r, r)
    >>> [(p.rate_dps, round(p.mean, 3)) for p in d.plateaus]
    [(10.0, 20.0), (-10.0, -20.0)]
    """
    t, y = np.asarray(time_s, float), np.asarray(output, float)
    r = np.asarray(table_rate_dps, float)
    for name, v in (("settle_s", settle_s + 1), ("min_plateau_s", min_plateau_s)):
        _check_positive(name, v)
    _check_positive("tolerance_dps", tolerance_dps)
    tol = tolerance_dps + 1e-5 * np.abs(r[1:])
    still = np.abs(np.diff(r)) <= tol
    spans = [(a, b + 1) for a, b in _runs(still)]
    temp = None if temperature_c is None else np.asarray(temperature_c, float)
    pl, dropped = _summarise(t, y, spans, [0.0] * len(spans), temp, settle_s, min_plateau_s)
    decimals = max(0, math.ceil(-math.log10(tolerance_dps)))
    pl = [_with_rate(p, round(float(np.mean(r[p.i0 : p.i1])), decimals)) for p in pl]
    if not pl:
        raise DesignError.naming(
            f"no plateau of at least {min_plateau_s:g} s where the table's rate holds still "
            f"(changes by at most {tolerance_dps:g} °/s a sample); a noisy rate column needs a "
            "larger {tolerance_dps}; or lower {min_plateau_s}, or give the plateaus with "
            "{schedule}",
            "tolerance_dps",
            "min_plateau_s",
            "schedule",
        )
    return Detection(tuple(pl), settle_s, "rate column", tuple(dropped))


def _with_rate(p: Plateau, rate: float) -> Plateau:
    """The plateau with its applied rate set."""
    return dataclasses.replace(p, rate_dps=rate)


def _se_blocks(seg: FloatArray) -> float | None:
    """Standard error of the mean from ``BLOCKS`` consecutive block means (batch means)."""
    m = seg.size // BLOCKS
    if m < 10:
        return None
    means = seg[: m * BLOCKS].reshape(BLOCKS, m).mean(axis=1)
    return float(np.std(means, ddof=1) / np.sqrt(BLOCKS))


def _noise_sigma(y: FloatArray) -> float:
    """Per-sample white noise from the first differences' median absolute deviation."""
    d = np.diff(y)
    mad = float(np.median(np.abs(d - np.median(d))))
    return float(1.4826 * mad / np.sqrt(2.0))


def plateaus_from_output(
    time_s: npt.ArrayLike,
    output: npt.ArrayLike,
    *,
    temperature_c: npt.ArrayLike | None = None,
    settle_s: float = SETTLE_S,
    min_plateau_s: float = MIN_PLATEAU_S,
    window_s: float = WINDOW_S,
) -> Detection:
    """Plateaus from the gyro's output alone: steady stretches between accelerations.

    The output is cut into windows of ``window_s``; the per-sample noise σ is the median
    absolute deviation of the first differences (×1.4826/√2, robust to the few samples of
    the accelerations).  A window belongs to a plateau when its mean is within
    ``STEADY_SIGMAS`` standard errors (``σ/√n_w``, plus 10 ppm of the output for the
    slow wander of a real sensor) of the mean of its predecessor; consecutive steady
    windows whose means agree form one plateau.

    Parameters
    ----------
    time_s : array_like
        Sample times [s], increasing.
    output : array_like
        The gyro's output [its unit].
    temperature_c : array_like, optional
        Temperature [°C].
    settle_s : float
        Settling dropped at each plateau's start [s].
    min_plateau_s : float
        Shortest plateau kept [s].
    window_s : float
        Window of the detector [s].

    Returns
    -------
    Detection
        The plateaus' rates are NaN (give them with :func:`match_rates`).

    Raises
    ------
    DesignError
        No plateau found.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(0, 60, 0.01)
    >>> w = np.interp(t, [0, 29, 31, 60], [100.0, 100.0, -100.0, -100.0])
    >>> d = plateaus_from_output(t, w + 0.1 * rng.standard_normal(t.size))
    >>> [round(p.mean, 1) for p in d.plateaus]
    [100.0, -100.0]
    """
    t, y = np.asarray(time_s, float), np.asarray(output, float)
    for name, v in (("min_plateau_s", min_plateau_s), ("window_s", window_s)):
        _check_positive(name, v)
    _check_positive("settle_s", settle_s + 1)
    rate = (t.size - 1) / max(float(t[-1] - t[0]), 1e-12)
    nw = max(round(window_s * rate), 2)
    nwin = y.size // nw
    if nwin < 3:
        raise DesignError.naming(
            f"{t.size} samples make fewer than 3 windows of {window_s:g} s; lower {{window_s}}",
            "window_s",
        )
    m = y[: nwin * nw].reshape(nwin, nw).mean(axis=1)
    se = _noise_sigma(y) / np.sqrt(nw)
    tol = STEADY_SIGMAS * np.sqrt(2.0) * se + 1e-5 * np.abs(m[1:])
    steady = np.abs(np.diff(m)) <= tol
    spans = [(a * nw, (b + 1) * nw) for a, b in _runs(steady)]
    temp = None if temperature_c is None else np.asarray(temperature_c, float)
    pl, dropped = _summarise(t, y, spans, None, temp, settle_s, min_plateau_s)
    if not pl:
        raise DesignError.naming(
            f"no steady plateau of at least {min_plateau_s:g} s in the output; lower "
            "{min_plateau_s}, or give the table's rate column ({rate_column}) or a {schedule}",
            "min_plateau_s",
            "rate_column",
            "schedule",
        )
    return Detection(tuple(pl), settle_s, "output", tuple(dropped))


def plateaus_from_schedule(
    time_s: npt.ArrayLike,
    output: npt.ArrayLike,
    schedule: Sequence[tuple[float, float, float]],
    *,
    temperature_c: npt.ArrayLike | None = None,
    settle_s: float = 0.0,
) -> Detection:
    """Plateaus given as (start [s], end [s], rate [°/s]) rows of a schedule.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    output : array_like
        The gyro's output [its unit].
    schedule : sequence of (float, float, float)
        Start and end of each plateau [s] and its rate [°/s].
    temperature_c : array_like, optional
        Temperature [°C].
    settle_s : float
        Settling dropped at each plateau's start [s] (default 0: the schedule's times).

    Returns
    -------
    Detection

    Raises
    ------
    DesignError
        A plateau outside the recording or with fewer than 2 samples.
    """
    t, y = np.asarray(time_s, float), np.asarray(output, float)
    spans = []
    for k, (a, b, _) in enumerate(schedule):
        i0, i1 = int(np.searchsorted(t, a, "left")), int(np.searchsorted(t, b, "right"))
        if not b > a or i1 - i0 < 2:
            raise DesignError.naming(
                f"plateau {k + 1} of {{schedule}} ({a:g}-{b:g} s) holds fewer than 2 samples "
                f"of the recording ({t[0]:g}-{t[-1]:g} s)",
                "schedule",
            )
        spans.append((i0, i1))
    temp = None if temperature_c is None else np.asarray(temperature_c, float)
    rates = [float(r) for _, _, r in schedule]
    pl, dropped = _summarise(t, y, spans, rates, temp, settle_s, 1e-9)
    return Detection(tuple(pl), settle_s, "schedule", tuple(dropped))


def match_rates(detection: Detection, rates_dps: Sequence[float]) -> Detection:
    """Pair the plateaus found in the output with the rates given, in order.

    Refused when the counts differ, or when the plateaus' outputs do not follow the given
    rates' order: for every pair with ``Ω_i < Ω_j`` the outputs must go the same way
    (``s (ȳ_j − ȳ_i) > −5 √(SE_i² + SE_j²)``, ``s`` the sign of the scale factor taken from
    the two extreme rates), so a ladder given in the wrong order or with a wrong sign fails.

    Parameters
    ----------
    detection : Detection
        Plateaus found in the output (rates NaN).
    rates_dps : sequence of float
        The applied rates [°/s], one per plateau, in time order.

    Returns
    -------
    Detection
        The same plateaus with their rates.

    Raises
    ------
    DesignError
        Counts or order that do not match.

    Examples
    --------
    >>> t = np.arange(0, 40, 0.1)
    >>> d = plateaus_from_output(t, np.where(t < 20, 5.0, -5.0))
    >>> [p.rate_dps for p in match_rates(d, [5, -5]).plateaus]
    [5.0, -5.0]
    """
    pl = detection.plateaus
    if len(rates_dps) != len(pl):
        found = ", ".join(f"{p.start_s:.0f}-{p.end_s:.0f} s" for p in pl[:12])
        raise DesignError.naming(
            f"{len(pl)} plateaus found in the output ({found}{', …' if len(pl) > 12 else ''}) "
            f"but {len(rates_dps)} rates given in {{rates_dps}}; give one rate per plateau, or "
            "change {min_plateau_s}, or give a {schedule}",
            "rates_dps",
            "min_plateau_s",
            "schedule",
        )
    w = np.asarray(rates_dps, float)
    y = np.array([p.mean for p in pl])
    se = np.array([p.se for p in pl])
    s = float(np.sign(y[np.argmax(w)] - y[np.argmin(w)])) or 1.0
    for i in range(len(pl)):
        for j in range(len(pl)):
            if w[i] < w[j] and s * (y[j] - y[i]) < -ORDER_SIGMAS * np.hypot(se[i], se[j]):
                raise DesignError.naming(
                    f"the plateaus found do not follow the rates given in {{rates_dps}}: "
                    f"{w[i]:g} °/s (plateau {i + 1}, at {pl[i].start_s:.0f} s) reads beyond "
                    f"{w[j]:g} °/s (plateau {j + 1}, at {pl[j].start_s:.0f} s); give the "
                    "rates in the order the table ran them, in °/s",
                    "rates_dps",
                )
    out = tuple(_with_rate(p, float(r)) for p, r in zip(pl, w, strict=True))
    return Detection(out, detection.settle_s, detection.source, detection.dropped)
