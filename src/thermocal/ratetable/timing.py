"""Plateaus of a rate ladder run to a timed program, without the table's rate column: the
rates in the order run and how long each is held (the dwell), the table accelerating at a
constant rate between them, the record started at a moment nobody wrote down.

The table's rate is then a known piecewise-linear profile up to two numbers, the start of
the first plateau ``s₀`` and the acceleration ``a``:

.. math::

    s_k = s_{k-1} + d_{k-1} + \\frac{|\\Omega_k - \\Omega_{k-1}|}{a}, \\qquad
    \\text{plateau } k = [s_k,\\ s_k + d_k],

and the gyro's output is a line of it, ``y ≈ b + K Ω(t; s₀, a)``.  ``s₀`` and ``a`` (each
unless given) maximise the fraction of the output's variance that line explains over the
ladder (its squared correlation ``R²``): first on block means of ``COARSE_S`` (every start by
one FFT cross-correlation, ``a`` on a logarithmic grid), then on the samples themselves
(Nelder–Mead on ``s₀`` and ``log a``).  Each plateau's output must then hold still: a program
that does not fit the output (a wrong dwell, rate list or start) is refused, never fitted.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.optimize import minimize
from scipy.signal import correlate

from thermocal.errors import DesignError, ParameterError
from thermocal.ratetable.plateaus import (
    SETTLE_S,
    STEADY_SIGMAS,
    Detection,
    _noise_sigma,
    _summarise,
)

FloatArray = npt.NDArray[np.float64]

COARSE_S = 0.1
"""Block length of the coarse search [s]."""
ACCEL_GRID_DPS2 = tuple(float(x) for x in np.geomspace(1.0, 1e4, 33))
"""Accelerations tried by the coarse search [°/s²] (1 … 10 000, 12 % apart)."""
MAX_REFINE_SAMPLES = 500_000
"""The fine search uses at most this many samples (every k-th beyond)."""
STEP_FRACTION = 0.1
"""A plateau whose halves differ by more than this fraction of the step to its nearer
neighbour (and by more than the noise) holds a transition: the program does not fit."""


@dataclass(frozen=True)
class LadderTiming:
    """Where a timed ladder lies in the record.

    Attributes
    ----------
    start_s : float
        Start of the first plateau [s, the record's time].
    accel_dps2 : float
        The table's acceleration between rates [°/s²].
    found : tuple of str
        What was found from the output: ``"start"``, ``"accel"`` (the rest was given).
    r2 : float
        Fraction of the output's variance over the ladder explained by a line of the
        profile.
    spans : tuple of (float, float)
        Each plateau (start, end) [s], settling included.
    """

    start_s: float
    accel_dps2: float
    found: tuple[str, ...]
    r2: float
    spans: tuple[tuple[float, float], ...]


def ladder_profile(
    rates_dps: Sequence[float], dwells_s: Sequence[float], accel_dps2: float, start_s: float
) -> tuple[FloatArray, FloatArray, list[tuple[float, float]]]:
    """The table's rate of a timed ladder as knots of a piecewise-linear profile.

    ``s_k = s_{k-1} + d_{k-1} + |Ω_k − Ω_{k-1}|/a`` (module docstring).

    Parameters
    ----------
    rates_dps : sequence of float
        The rates in the order run [°/s].
    dwells_s : sequence of float
        How long each is held [s].
    accel_dps2 : float
        The table's acceleration between rates [°/s²].
    start_s : float
        Start of the first plateau [s].

    Returns
    -------
    knot_t, knot_r : numpy.ndarray
        Knot times [s] and rates [°/s] (``numpy.interp`` between them).
    list of (float, float)
        Each plateau (start, end) [s].

    Examples
    --------
    >>> t, r, spans = ladder_profile([0, 10, -10], [5, 5, 5], 10.0, 2.0)
    >>> spans
    [(2.0, 7.0), (8.0, 13.0), (15.0, 20.0)]
    """
    kt, kr, spans = [], [], []
    t = float(start_s)
    for k, (r, d) in enumerate(zip(rates_dps, dwells_s, strict=True)):
        if k:
            t += abs(float(r) - float(rates_dps[k - 1])) / accel_dps2
        kt += [t, t + float(d)]
        kr += [float(r), float(r)]
        spans.append((t, t + float(d)))
        t += float(d)
    return np.asarray(kt), np.asarray(kr), spans


def _r2(y: FloatArray, x: FloatArray) -> float:
    """Squared correlation of ``y`` and ``x`` (0 when either is constant)."""
    yc, xc = y - y.mean(), x - x.mean()
    den = float(np.dot(yc, yc) * np.dot(xc, xc))
    return float(np.dot(yc, xc) ** 2 / den) if den > 0 else 0.0


def _blocks(t: FloatArray, y: FloatArray, nb: int) -> tuple[FloatArray, FloatArray]:
    """Block means of ``nb`` samples: their first times and the means."""
    n = y.size // nb
    return t[: n * nb : nb], y[: n * nb].reshape(n, nb).mean(axis=1)


def _best_start(
    td: FloatArray, yd: FloatArray, h: float, kt: FloatArray, kr: FloatArray
) -> tuple[float, float]:
    """The best start on the block grid for a profile starting at 0: (R², start [s])."""
    m = int(kt[-1] // h) + 1
    if m > yd.size or m < 3:
        return -1.0, 0.0
    tmpl = np.interp(np.arange(m) * h, kt, kr)
    tc = tmpl - tmpl.mean()
    vr = float(np.dot(tc, tc))
    if vr <= 0:
        return -1.0, 0.0
    y = yd - yd.mean()
    cov = correlate(y, tc, mode="valid", method="fft")
    c1 = np.concatenate(([0.0], np.cumsum(y)))
    c2 = np.concatenate(([0.0], np.cumsum(y * y)))
    s1, s2 = c1[m:] - c1[:-m], c2[m:] - c2[:-m]
    vy = np.maximum(s2 - s1 * s1 / m, 1e-300)
    r2 = cov * cov / (vy * vr)
    j = int(np.argmax(r2))
    return float(r2[j]), float(td[j])


def _coarse(
    t: FloatArray,
    y: FloatArray,
    rates: Sequence[float],
    dwells: Sequence[float],
    accel: float | None,
    start: float | None,
) -> tuple[float, float]:
    """The coarse start and acceleration: block means, FFT correlation, an ``a`` grid."""
    dt = float(np.median(np.diff(t)))
    nb = max(1, round(COARSE_S / dt))
    td, yd = _blocks(t, y, nb)
    h = nb * dt
    best = (-1.0, 0.0, 0.0)
    for a in ACCEL_GRID_DPS2 if accel is None else (accel,):
        kt, kr, _ = ladder_profile(rates, dwells, a, 0.0)
        if start is None:
            r2, s0 = _best_start(td, yd, h, kt, kr)
        else:
            inside = (td >= start) & (td <= start + kt[-1])
            r2, s0 = _r2(yd[inside], np.interp(td[inside], kt + start, kr)), start
        if r2 > best[0]:
            best = (r2, s0, a)
    if best[0] <= 0:
        raise DesignError.naming(
            "the output does not vary like the ladder given: check {rates_dps} (°/s, in the "
            "order run) and {dwell_s}",
            "rates_dps",
            "dwell_s",
        )
    return best[1], best[2]


def _refine(
    t: FloatArray,
    y: FloatArray,
    rates: Sequence[float],
    dwells: Sequence[float],
    guess: tuple[float, float],
    free: tuple[bool, bool],
) -> tuple[float, float, float]:
    """Start and acceleration refined on the samples: (start, accel, R²)."""
    s0, a0 = guess
    kt, _, _ = ladder_profile(rates, dwells, a0, s0)
    margin = 3 * COARSE_S
    inside = (t >= s0 + margin) & (t <= kt[-1] - margin)
    k = max(1, int(np.count_nonzero(inside)) // MAX_REFINE_SAMPLES)
    tw, yw = t[inside][::k], y[inside][::k]

    def params(p: FloatArray) -> tuple[float, float]:
        it = iter(p.tolist())
        return (next(it) if free[0] else s0), (math.exp(next(it)) if free[1] else a0)

    def cost(p: FloatArray) -> float:
        s, a = params(p)
        kt2, kr2, _ = ladder_profile(rates, dwells, a, s)
        return math.log(max(1.0 - _r2(yw, np.interp(tw, kt2, kr2)), 1e-300))

    x0 = [v for v, f in zip((s0, math.log(a0)), free, strict=True) if f]
    if x0:
        steps = [s for s, f in zip((COARSE_S, 0.1), free, strict=True) if f]
        simplex = np.array(
            [x0] + [np.add(x0, np.eye(len(x0))[i] * steps[i]) for i in range(len(x0))]
        )
        res = minimize(
            cost,
            np.asarray(x0),
            method="Nelder-Mead",
            options={"initial_simplex": simplex, "xatol": 1e-5, "fatol": 1e-7, "maxiter": 400},
        )
        s0, a0 = params(np.asarray(res.x, float))
    kt2, kr2, _ = ladder_profile(rates, dwells, a0, s0)
    return s0, a0, _r2(yw, np.interp(tw, kt2, kr2))


def _check_program(
    t: FloatArray,
    rates: Sequence[float],
    dwells: Sequence[float],
    accel: float | None,
    start: float | None,
    *,
    fitted: str = "",
    given_start: bool = True,
) -> None:
    """Refuse a program that no record could hold: bad numbers, or longer than the record
    (``fitted``: the message's opening when the start or acceleration were found)."""
    if len(rates) < 2:
        raise ParameterError("rates_dps", "{name}: a ladder needs at least 2 rates")
    if len(dwells) != len(rates):
        raise ParameterError(
            "dwell_s",
            f"{{name}}: {len(dwells)} dwells for {len(rates)} rates; give one, or one a rate",
        )
    for name, vals in (("dwell_s", dwells), ("accel_dps2", [] if accel is None else [accel])):
        if not all(math.isfinite(v) and v > 0 for v in vals):
            raise ParameterError(name, "{name} must be a positive number of seconds or °/s²")
    if start is not None and not math.isfinite(start):
        raise ParameterError("start_s", "{name} must be a finite time [s]")
    kt, _, _ = ladder_profile(rates, dwells, accel or math.inf, start or 0.0)
    length = float(kt[-1] - kt[0])
    span = float(t[-1] - t[0])
    first, last = (start, start + length) if start is not None else (t[0], t[0] + length)
    slack = COARSE_S + span / max(t.size - 1, 1)
    if length > span + slack or first < t[0] - slack or last > t[-1] + slack:
        moves = f" and transitions at {accel:g} °/s²" if accel else " (transitions apart)"
        where = f" from {start:g} s" if start is not None else ""
        raise DesignError.naming(
            f"{fitted}the ladder of {len(rates)} rates held {_dwell_text(dwells)}{moves} lasts "
            f"{length:.1f} s{where}, beyond the record ({t[0]:.1f}-{t[-1]:.1f} s): check "
            "{dwell_s} and {rates_dps}" + (" and {start_s}" if given_start else ""),
            "dwell_s",
            "rates_dps",
            "start_s",
        )


def _dwell_text(dwells: Sequence[float]) -> str:
    """``20 s each`` or ``5-60 s``."""
    lo, hi = min(dwells), max(dwells)
    return f"{lo:g} s each" if lo == hi else f"{lo:g}-{hi:g} s"


def fit_timing(
    time_s: npt.ArrayLike,
    output: npt.ArrayLike,
    rates_dps: Sequence[float],
    dwell_s: float | Sequence[float],
    *,
    accel_dps2: float | None = None,
    start_s: float | None = None,
) -> LadderTiming:
    """Where a timed ladder lies in the record: its start and the table's acceleration.

    Maximises ``R²`` of the least-squares line ``y = b + K Ω(t; s₀, a)`` over the ladder
    (module docstring); what is given is held.

    Parameters
    ----------
    time_s : array_like
        Sample times [s], increasing.
    output : array_like
        The gyro's output [its unit].
    rates_dps : sequence of float
        The rates in the order run [°/s].
    dwell_s : float or sequence of float
        How long each rate is held [s] (one for all, or one a rate).
    accel_dps2 : float, optional
        The table's acceleration between rates [°/s²]; found when None.
    start_s : float, optional
        Start of the first plateau [s, the record's time]; found when None.

    Returns
    -------
    LadderTiming

    Raises
    ------
    ParameterError
        Fewer than 2 rates, dwells that do not match them, non-positive values.
    DesignError
        A ladder longer than the record (or outside it from ``start_s``).

    Examples
    --------
    >>> t = np.arange(0, 60, 0.01)
    >>> kt, kr, _ = ladder_profile([0, 50, -50], [15, 15, 15], 25.0, 7.3)
    >>> tm = fit_timing(t, 2 * np.interp(t, kt, kr), [0, 50, -50], 15)
    >>> round(tm.start_s, 2), round(tm.accel_dps2, 1), tm.found
    (7.3, 25.0, ('start', 'accel'))
    """
    t, y = np.asarray(time_s, float), np.asarray(output, float)
    rates = [float(r) for r in rates_dps]
    dwells = (
        [float(dwell_s)] * len(rates)
        if isinstance(dwell_s, int | float)
        else [float(d) for d in dwell_s]
    )
    _check_program(t, rates, dwells, accel_dps2, start_s, given_start=start_s is not None)
    guess = _coarse(t, y, rates, dwells, accel_dps2, start_s)
    free = (start_s is None, accel_dps2 is None)
    s0, a, r2 = _refine(t, y, rates, dwells, guess, free)
    _check_program(
        t,
        rates,
        dwells,
        a,
        s0,
        fitted="no placement fits the record: the best found, ",
        given_start=start_s is not None,
    )
    _, _, spans = ladder_profile(rates, dwells, a, s0)
    found = tuple(n for n, f in zip(("start", "accel"), free, strict=True) if f)
    return LadderTiming(s0, a, found, r2, tuple(spans))


def _check_steady(
    detection: Detection, y: FloatArray, timing: LadderTiming, rates: Sequence[float]
) -> None:
    """Each plateau's halves agree within the noise or ``STEP_FRACTION`` of its nearer step:
    a plateau holding a transition means the program does not fit the output."""
    sigma = _noise_sigma(y)
    pl = detection.plateaus
    means = np.array([p.mean for p in pl])
    w = np.asarray(rates, float)
    k = np.polyfit(w, means, 1)[0] if np.ptp(w) > 0 else 1.0
    for i, p in enumerate(pl):
        seg = y[p.i0 : p.i1]
        h = seg.size // 2
        d = abs(float(seg[:h].mean() - seg[h:].mean()))
        steps = [abs(w[i] - w[j]) for j in (i - 1, i + 1) if 0 <= j < w.size and w[j] != w[i]]
        step = min(steps) if steps else 0.0
        tol = STEADY_SIGMAS * math.sqrt(2.0) * sigma / math.sqrt(max(h, 1)) + 1e-5 * abs(p.mean)
        if d > tol and d > STEP_FRACTION * abs(k) * step:
            how = ", ".join(f"{n} found" for n in timing.found) or "as given"
            raise DesignError.naming(
                f"plateau {i + 1} ({w[i]:g} °/s, {p.start_s:.1f}-{p.end_s:.1f} s) does not hold "
                f"still in the output (its halves differ by {d:.3g}): the ladder starting at "
                f"{timing.start_s:.2f} s, accelerating at {timing.accel_dps2:.3g} °/s² "
                f"({how}) does not fit the record; check {{dwell_s}}, {{rates_dps}} (in the "
                "order run) and {start_s}",
                "dwell_s",
                "rates_dps",
                "start_s",
            )


def plateaus_from_dwell(
    time_s: npt.ArrayLike,
    output: npt.ArrayLike,
    rates_dps: Sequence[float],
    dwell_s: float | Sequence[float],
    *,
    accel_dps2: float | None = None,
    start_s: float | None = None,
    temperature_c: npt.ArrayLike | None = None,
    settle_s: float = SETTLE_S,
) -> tuple[Detection, LadderTiming]:
    """Plateaus of a ladder given by its rates and dwells (no rate column): the program's
    timing fitted to the output (:func:`fit_timing`), the first ``settle_s`` of each plateau
    left out, every plateau checked to hold still.

    Parameters
    ----------
    time_s : array_like
        Sample times [s], increasing.
    output : array_like
        The gyro's output [its unit].
    rates_dps : sequence of float
        The rates in the order run [°/s].
    dwell_s : float or sequence of float
        How long each is held [s].
    accel_dps2 : float, optional
        The table's acceleration [°/s²]; found when None.
    start_s : float, optional
        Start of the first plateau [s]; found when None.
    temperature_c : array_like, optional
        Temperature [°C].
    settle_s : float
        Settling dropped at each plateau's start [s].

    Returns
    -------
    Detection
        Source ``"dwell"``, the rates set.
    LadderTiming
        The start and acceleration used.

    Raises
    ------
    ParameterError
        A dwell not longer than the settling, or the errors of :func:`fit_timing`.
    DesignError
        A program that does not fit the record.
    """
    t, y = np.asarray(time_s, float), np.asarray(output, float)
    if not (math.isfinite(settle_s) and settle_s >= 0):
        raise ParameterError("settle_s", f"{{name}} must be ≥ 0, got {settle_s!r}")
    timing = fit_timing(t, y, rates_dps, dwell_s, accel_dps2=accel_dps2, start_s=start_s)
    spans = []
    for a, b in timing.spans:
        i0, i1 = int(np.searchsorted(t, a, "left")), int(np.searchsorted(t, b, "right"))
        if i1 - i0 < 2 or b - a <= settle_s:
            raise ParameterError(
                "dwell_s", f"{{name}}: {b - a:g} s, not longer than the settling ({settle_s:g} s)"
            )
        spans.append((i0, i1))
    temp = None if temperature_c is None else np.asarray(temperature_c, float)
    rates = [float(r) for r in rates_dps]
    pl, _ = _summarise(t, y, spans, rates, temp, settle_s, 1e-9)
    det = Detection(tuple(pl), settle_s, "dwell")
    _check_steady(det, y, timing, rates)
    return det, timing
