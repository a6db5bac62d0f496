r"""Heating and cooling legs of a temperature history, and whether a residual differs
between them (thermal hysteresis).

A **leg** is a stretch where the temperature rises (heating) or falls (cooling)
monotonically beyond its noise, with holds or reversals between legs.  The legs are found
by a hysteresis quantiser of the temperature (:func:`find_legs`): starting from the first
sample, an *event* is recorded each time the temperature has moved by the threshold

.. math:: h = \max(8\,\sigma_T,\; 2.5\,q,\; s_\mathrm{min}/10)

from the last event's value (:math:`\sigma_T` the white noise of the reading from the median
absolute deviation of its first differences, :math:`q` the thermometer's lattice step from
:func:`thermocal.thermometer.lattice_step` — or, when most samples repeat the one before,
the median of the nonzero steps — :math:`s_\mathrm{min}` the smallest leg).  A
reading that toggles between two adjacent lattice levels, or wanders within its noise,
never makes an event.  Consecutive events of one direction form a leg unless the time
between two of them exceeds :data:`HOLD_FACTOR` times the typical interval around them (a
hold); a change of direction always ends a leg.  The leg's ends are refined to the last
sample at the level of the hold before it and the first at the level of the hold after
(each level the median of the readings between the events).  A leg spans at least
``max(min_span_c, 4 h)``.

**Hysteresis test** (:func:`compare_legs`): the residual (or compensated output) at equal
temperature on heating and on cooling.  The temperature range both directions cover is
cut into bins; in each bin ``b`` with enough samples of both, the difference of the means
:math:`d_b = \bar r_{\mathrm{heat},b} - \bar r_{\mathrm{cool},b}`.  Over the :math:`m` bins,

.. math:: \bar d = \frac1m\sum_b d_b, \qquad
          t = \frac{\bar d}{s_d/\sqrt m}, \qquad s_d^2 = \frac{1}{m-1}\sum_b (d_b-\bar d)^2

is Student's t with :math:`m-1` degrees of freedom when the legs agree (the paired
comparison of Niu et al. 2013 between the two branches at equal temperature); the legs
*disagree beyond the noise* when :math:`|t|` exceeds its two-sided 99 % quantile.  The
white noise :math:`\sigma` of the residual (first differences, as above) is stated beside
:math:`\bar d`.  Pure maths (numpy; scipy.stats for the quantile, imported lazily).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Final, Literal

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule
from thermocal.recording import FloatArray
from thermocal.thermometer import lattice_step

if TYPE_CHECKING:
    from scipy import stats as _stats
else:
    _stats = LazyModule("scipy.stats")

Direction = Literal["heating", "cooling"]

MIN_SPAN_C: Final = 1.0
"""The smallest temperature change of a leg [°C] (a chamber's legs span tens of °C)."""
NOISE_FACTOR: Final = 8.0
"""The event threshold in units of the reading's white noise σ_T: the difference of two
noisy readings has σ_T √2, and 8 σ_T ≈ 5.7 of its σ, which a hold of 10⁶ samples does not
reach by chance."""
LATTICE_FACTOR: Final = 2.5
"""The event threshold in lattice steps q: a toggle between two levels (q) or three (2q)
is no movement."""
HOLD_FACTOR: Final = 5.0
"""A pause between two events longer than this times the typical interval around it is a
hold: the leg ends."""
MAX_SAMPLES: Final = 250_000
"""At most this many samples are walked (every k-th beyond): the legs' ends are then
known to k samples."""
N_BINS: Final = 12
"""Temperature bins of the hysteresis test over the range both directions cover."""
MIN_BIN_SAMPLES: Final = 5
"""Samples of each direction a bin needs to enter the test."""
MIN_BINS: Final = 3
"""Bins the test needs (two degrees of freedom)."""
CONFIDENCE: Final = 0.99
"""Two-sided level of the hysteresis test."""


@dataclass(frozen=True)
class Leg:
    """One heating or cooling leg.

    Attributes
    ----------
    direction : {"heating", "cooling"}
        Rising or falling temperature.
    start, stop : int
        First sample and one past the last (indices of the record).
    start_s, stop_s : float
        Times of the first and last sample [s].
    temp_start_c, temp_stop_c : float
        Temperatures there [°C].
    """

    direction: Direction
    start: int
    stop: int
    start_s: float
    stop_s: float
    temp_start_c: float
    temp_stop_c: float

    @property
    def rate_c_per_min(self) -> float:
        """Mean rate over the leg [°C/min]: ``60 (T_stop − T_start)/(t_stop − t_start)``."""
        span = self.stop_s - self.start_s
        return 60.0 * (self.temp_stop_c - self.temp_start_c) / span if span > 0 else math.nan

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (the ``legs`` entries of ``inspect`` and ``validate``)."""
        return {
            "direction": self.direction,
            "start_index": self.start,
            "stop_index": self.stop,
            "start_s": self.start_s,
            "stop_s": self.stop_s,
            "temp_start_c": self.temp_start_c,
            "temp_stop_c": self.temp_stop_c,
            "rate_c_per_min": _num(self.rate_c_per_min),
        }


@dataclass(frozen=True)
class Legs:
    """The legs of a temperature history (:func:`find_legs`).

    Attributes
    ----------
    legs : tuple of Leg
        In time order.
    threshold_c : float
        The event threshold h [°C].
    lattice_step_c : float or None
        The thermometer's lattice step q [°C] (None: a continuous reading).
    noise_c : float
        The reading's white noise σ_T [°C].
    n_samples : int
        Samples of the record.
    """

    legs: tuple[Leg, ...]
    threshold_c: float
    lattice_step_c: float | None
    noise_c: float
    n_samples: int

    def of(self, direction: Direction) -> tuple[Leg, ...]:
        """The legs of one direction.

        Parameters
        ----------
        direction : {"heating", "cooling"}
            Which legs.

        Returns
        -------
        tuple of Leg
        """
        return tuple(g for g in self.legs if g.direction == direction)

    def mask(self, direction: Direction) -> npt.NDArray[np.bool_]:
        """True on the samples of the legs of ``direction``.

        Parameters
        ----------
        direction : {"heating", "cooling"}
            Which legs.

        Returns
        -------
        numpy.ndarray of bool
            Shape (n_samples,).
        """
        out = np.zeros(self.n_samples, dtype=bool)
        for g in self.of(direction):
            out[g.start : g.stop] = True
        return out

    def summary(self) -> str:
        """One line: how many legs of each direction, or that there is none."""
        if not self.legs:
            return (
                f"no heating or cooling leg (no monotonic change of ≥ "
                f"{max(MIN_SPAN_C, 4 * self.threshold_c):.3g} °C beyond the noise)"
            )
        h, c = len(self.of("heating")), len(self.of("cooling"))
        return f"{h} heating and {c} cooling leg{'s' if h + c != 1 else ''}"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (the ``legs`` of the inspect command's JSON)."""
        return {
            "n_heating": len(self.of("heating")),
            "n_cooling": len(self.of("cooling")),
            "threshold_c": self.threshold_c,
            "lattice_step_c": self.lattice_step_c,
            "noise_c": self.noise_c,
            "legs": [g.to_dict() for g in self.legs],
        }


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def white_noise(x: FloatArray) -> float:
    r"""The white noise of a series from its first differences, robustly.

    Parameters
    ----------
    x : numpy.ndarray
        The series (finite values).

    Returns
    -------
    float
        σ [unit of ``x``]; 0 for fewer than three values.

    Notes
    -----
    .. math:: \sigma = \frac{1.4826\,\operatorname{median}|\Delta x - \operatorname{median}
              \Delta x|}{\sqrt 2}

    the median absolute deviation scaled to a normal σ (Hampel 1974), of differences whose
    variance is twice the white noise's.

    References
    ----------
    - F. R. Hampel, "The influence curve and its role in robust estimation", *J. Amer.
      Statist. Assoc.* 69 (1974) 383–393.
    """
    if x.size < 3:
        return 0.0
    d = np.diff(x)
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0))


def _step_of(v: FloatArray, q: float | None) -> float | None:
    """The reading's step: its lattice step ``q`` (:func:`~thermocal.thermometer.lattice_step`),
    else, when most samples repeat the one before (a coarse reading whose holds outnumber
    its ramps' levels, which the lattice test does not see), the median of the nonzero
    steps."""
    if v.size < 2 or q is not None:
        return q
    d = np.abs(np.diff(v))
    moved = d[d > 0]
    if moved.size and moved.size <= 0.5 * d.size:
        return float(np.median(moved))
    return None


def _events(v: list[float], h: float) -> tuple[list[int], list[int]]:
    """The hysteresis quantiser: indices where the reading has moved ≥ h from the last
    event's value, and the direction (+1, −1) of each."""
    idx: list[int] = []
    sgn: list[int] = []
    a = v[0]
    for i, x in enumerate(v):
        if x - a >= h:
            idx.append(i)
            sgn.append(1)
            a = x
        elif a - x >= h:
            idx.append(i)
            sgn.append(-1)
            a = x
    return idx, sgn


def _runs(idx: list[int], sgn: list[int], tv: FloatArray) -> list[tuple[int, int]]:
    """Runs of events (first, last position in ``idx``) of one direction without a hold:
    a pause longer than :data:`HOLD_FACTOR` times the larger median of the three intervals
    on either side ends a run."""
    if not idx:
        return []
    t = tv[np.asarray(idx)]
    gaps = np.diff(t)
    out: list[tuple[int, int]] = []
    first = 0
    for j in range(1, len(idx)):
        if sgn[j] != sgn[j - 1]:
            out.append((first, j - 1))
            first = j
            continue
        left = gaps[max(first, j - 4) : j - 1]
        right = gaps[j : j + 3]
        ref = [float(np.median(a)) for a in (left, right) if a.size]
        if ref and gaps[j - 1] > HOLD_FACTOR * max(ref):
            out.append((first, j - 1))
            first = j
    out.append((first, len(idx) - 1))
    return out


def _leg_ends(v: FloatArray, idx: list[int], run: tuple[int, int], sign: int) -> tuple[int, int]:
    """The first and last sample of a run's leg: the last at the level before it and the
    first at the level after it (each level the median between the neighbouring events)."""
    i1, im = idx[run[0]], idx[run[1]]
    p = idx[run[0] - 1] if run[0] > 0 else 0
    q = idx[run[1] + 1] if run[1] + 1 < len(idx) else v.size
    # the levels from the stretches beyond the run's events; the crossings searched over
    # the whole run (a noisy reading may make its last event late in the hold after)
    start, end = p, im
    if i1 > p:
        a0 = float(np.median(v[p:i1]))
        at = np.flatnonzero(sign * (v[p : im + 1] - a0) <= 0)
        start = p + int(at[-1]) if at.size else p
    if q > im:
        a1 = float(np.median(v[im:q]))
        at = np.flatnonzero(sign * (v[i1:q] - a1) >= 0)
        end = i1 + int(at[0]) if at.size else im
    return start, end


def find_legs(
    time_s: npt.ArrayLike, temp_c: npt.ArrayLike, *, min_span_c: float = MIN_SPAN_C
) -> Legs:
    r"""The heating and cooling legs of a temperature history (see the module docstring).

    Parameters
    ----------
    time_s : array_like
        Sample times [s], increasing.
    temp_c : array_like
        Temperatures [°C] (non-finite samples are skipped).
    min_span_c : float, optional
        The smallest temperature change of a leg [°C] (default :data:`MIN_SPAN_C`).

    Returns
    -------
    Legs
        The legs in time order (none for an isothermal record), with the threshold, the
        lattice step and the noise used.

    Notes
    -----
    Event threshold :math:`h = \max(8\sigma_T, 2.5q, s_\mathrm{min}/10)`; a leg is a run of
    same-direction events without a pause longer than 5 typical intervals, spanning at
    least :math:`\max(s_\mathrm{min}, 4h)`.

    References
    ----------
    - X. Niu, Y. Li, H. Zhang, Q. Wang and Y. Ban, "Fast thermal calibration of low-grade
      inertial sensors and inertial measurement units", *Sensors* 13 (2013) 12192–12217
      (heating and cooling legs of a thermal calibration).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 3000.0)
    >>> T = np.interp(t, [0, 500, 1000, 1500, 2000, 3000], [20, 20, 40, 40, 25, 25])
    >>> [(g.direction, g.start, g.stop) for g in find_legs(t, T).legs]
    [('heating', 500, 1001), ('cooling', 1500, 2001)]
    >>> find_legs(t, np.full(t.size, 25.0)).summary()
    'no heating or cooling leg (no monotonic change of ≥ 1 °C beyond the noise)'
    """
    t_all = np.asarray(time_s, dtype=np.float64)
    x_all = np.asarray(temp_c, dtype=np.float64)
    n = int(x_all.size)
    k = max(1, math.ceil(n / MAX_SAMPLES))  # every k-th sample: no full-size copy
    t_k, x_k = t_all[::k], x_all[::k]
    keep = np.flatnonzero(np.isfinite(x_k) & np.isfinite(t_k)) * k
    v, tv = x_all[keep], t_all[keep]
    q = lattice_step(v) if v.size >= 2 else None
    sigma = white_noise(v)
    h = max(NOISE_FACTOR * sigma, LATTICE_FACTOR * (_step_of(v, q) or 0.0), min_span_c / 10.0)
    if v.size < 2:
        return Legs((), h, q, sigma, n)
    idx, sgn = _events(v.tolist(), h)
    span_min = max(min_span_c, 4.0 * h)
    legs: list[Leg] = []
    for run in _runs(idx, sgn, tv):
        sign = sgn[run[0]]
        a, b = _leg_ends(v, idx, run, sign)
        if run[1] == run[0] or sign * (v[b] - v[a]) < span_min:
            continue
        legs.append(
            Leg(
                "heating" if sign > 0 else "cooling",
                int(keep[a]),
                int(keep[b]) + 1,
                float(tv[a]),
                float(tv[b]),
                float(v[a]),
                float(v[b]),
            )
        )
    return Legs(tuple(legs), h, q, sigma, n)


@dataclass(frozen=True)
class LegFigures:
    """A residual's figures on one leg.

    Attributes
    ----------
    leg : Leg
        The leg.
    rms, max_abs, mean : float
        RMS, largest magnitude and mean of the residual on the leg [its unit].
    """

    leg: Leg
    rms: float
    max_abs: float
    mean: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return self.leg.to_dict() | {
            "rms": _num(self.rms),
            "max_abs": _num(self.max_abs),
            "mean": _num(self.mean),
        }


@dataclass(frozen=True)
class LegComparison:
    """Heating against cooling at equal temperature (:func:`compare_legs`).

    Attributes
    ----------
    per_leg : tuple of LegFigures
        Each leg's figures.
    mean_difference : float or None
        Mean over the bins of heating minus cooling [unit]; None when the legs cannot be
        compared (:attr:`reason`).
    t_statistic : float or None
        Student's t of the mean difference over the bins.
    t_critical : float or None
        Its two-sided :data:`CONFIDENCE` quantile (m − 1 degrees of freedom).
    n_bins : int
        Temperature bins compared.
    overlap_c : tuple of float or None
        The temperature range both directions cover [°C].
    noise : float
        White noise σ of the residual [unit].
    unit : str
        The residual's unit.
    reason : str
        Why the legs are not compared ("" when they are).
    """

    per_leg: tuple[LegFigures, ...]
    mean_difference: float | None
    t_statistic: float | None
    t_critical: float | None
    n_bins: int
    overlap_c: tuple[float, float] | None
    noise: float
    unit: str
    reason: str = ""

    @property
    def disagree(self) -> bool | None:
        """True when |t| exceeds its critical value (None when not compared)."""
        if self.t_statistic is None or self.t_critical is None:
            return None
        return bool(abs(self.t_statistic) > self.t_critical)

    def scaled(self, unit: str, factor: float) -> LegComparison:
        """The same in another unit.

        Parameters
        ----------
        unit : str
            The new unit.
        factor : float
            ``value[self.unit] = factor · value[unit]``.

        Returns
        -------
        LegComparison
            Every figure divided by ``factor``; t and the bins unchanged.
        """
        legs = tuple(
            LegFigures(f.leg, f.rms / factor, f.max_abs / factor, f.mean / factor)
            for f in self.per_leg
        )
        md = None if self.mean_difference is None else self.mean_difference / factor
        return LegComparison(
            legs, md, self.t_statistic, self.t_critical, self.n_bins, self.overlap_c,
            self.noise / factor, unit, self.reason,
        )  # fmt: skip

    def line(self) -> str:
        """One line: whether heating and cooling disagree beyond the noise, with t."""
        if self.mean_difference is None:
            return f"heating vs cooling: not compared ({self.reason})"
        word = "DISAGREE beyond the noise" if self.disagree else "agree within the noise"
        ratio = f" ({self.mean_difference / self.noise:.2g} σ)" if self.noise > 0 else ""
        return (
            f"heating vs cooling: {word}: mean difference {self.mean_difference:.4g} "
            f"{self.unit}{ratio} over {self.n_bins} temperature bins, t = {self.t_statistic:.3g} "
            f"(|t| > {self.t_critical:.3g} disagrees at {100 * CONFIDENCE:g} %), "
            f"noise σ {self.noise:.3g} {self.unit}"
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (the ``legs`` of the validate command's JSON)."""
        return {
            "legs": [f.to_dict() for f in self.per_leg],
            "mean_difference": _opt(self.mean_difference),
            "t_statistic": _opt(self.t_statistic),
            "t_critical": _opt(self.t_critical),
            "confidence": CONFIDENCE,
            "n_bins": self.n_bins,
            "overlap_c": None if self.overlap_c is None else list(self.overlap_c),
            "noise": _num(self.noise),
            "unit": self.unit,
            "disagree": self.disagree,
            "reason": self.reason,
        }


def _opt(x: float | None) -> float | None:
    return None if x is None else _num(x)


def _bin_differences(
    temp_c: FloatArray, resid: FloatArray, heat: npt.NDArray[np.bool_], cool: npt.NDArray[np.bool_]
) -> tuple[FloatArray, tuple[float, float] | None]:
    """``d_b`` = mean heating − mean cooling residual in each of :data:`N_BINS` bins over
    the temperature range both directions cover (bins with fewer than
    :data:`MIN_BIN_SAMPLES` of either left out), and that range."""
    th, tc = temp_c[heat], temp_c[cool]
    lo, hi = max(th.min(), tc.min()), min(th.max(), tc.max())
    if not hi > lo:
        return np.empty(0), None
    edges = np.linspace(lo, hi, N_BINS + 1)
    out = []
    bh = np.clip(np.searchsorted(edges, th, side="right") - 1, 0, N_BINS - 1)
    bc = np.clip(np.searchsorted(edges, tc, side="right") - 1, 0, N_BINS - 1)
    inh, inc = (th >= lo) & (th <= hi), (tc >= lo) & (tc <= hi)
    rh, rc = resid[heat], resid[cool]
    for b in range(N_BINS):
        sh, sc = inh & (bh == b), inc & (bc == b)
        if np.count_nonzero(sh) >= MIN_BIN_SAMPLES and np.count_nonzero(sc) >= MIN_BIN_SAMPLES:
            out.append(float(rh[sh].mean() - rc[sc].mean()))
    return np.asarray(out), (float(lo), float(hi))


def compare_legs(
    legs: Legs, temp_c: npt.ArrayLike, residual: npt.ArrayLike, unit: str
) -> LegComparison:
    r"""Each leg's residual figures, and the test of heating against cooling at equal
    temperature (module docstring).

    Parameters
    ----------
    legs : Legs
        The record's legs (:func:`find_legs`).
    temp_c : array_like
        The temperature the legs were found on [°C], shape (n,).
    residual : array_like
        The residual or compensated output, shape (n,) [``unit``]; its mean over the
        record is removed first (a constant offset is no hysteresis).
    unit : str
        The residual's unit.

    Returns
    -------
    LegComparison
        Per leg RMS, largest magnitude and mean; the mean difference, t and its critical
        value, or the reason the legs are not compared (no leg of one direction, no
        common temperature range, fewer than :data:`MIN_BINS` bins).

    Notes
    -----
    .. math:: t = \frac{\bar d}{s_d/\sqrt m}, \qquad
              d_b = \bar r_{\mathrm{heat},b} - \bar r_{\mathrm{cool},b}

    disagreement when :math:`|t| > t_{1-(1-0.99)/2,\,m-1}` (Student 1908).  The bins are
    treated as independent: slow noise (flicker) shared by neighbouring bins makes the
    test liberal (16 % rejected at 1 % under AR(1) noise of 300 s on a 1 °C/min sweep); an
    effective-sample-size correction from the bins' lag-1 autocorrelation, measured in
    ``benchmarks/bench_legs_test_size.py``, also hides a real, smooth hysteresis and is
    not applied.

    References
    ----------
    - X. Niu et al., "Fast thermal calibration of low-grade inertial sensors and inertial
      measurement units", *Sensors* 13 (2013) 12192–12217.
    - Student, "The probable error of a mean", *Biometrika* 6 (1908) 1–25.
    """
    t = np.asarray(temp_c, dtype=np.float64)
    r = np.asarray(residual, dtype=np.float64)
    ok = np.isfinite(r) & np.isfinite(t)
    r = r - (float(r[ok].mean()) if ok.any() else 0.0)
    figs = []
    for g in legs.legs:
        seg = r[g.start : g.stop]
        seg = seg[np.isfinite(seg)]
        if seg.size:
            figs.append(
                LegFigures(g, float(np.sqrt(np.mean(seg**2))), float(np.abs(seg).max()),
                           float(seg.mean()))
            )  # fmt: skip
    noise = white_noise(r[ok])
    heat, cool = legs.mask("heating") & ok, legs.mask("cooling") & ok

    def unfit(reason: str, overlap: tuple[float, float] | None = None, m: int = 0) -> LegComparison:
        return LegComparison(tuple(figs), None, None, None, m, overlap, noise, unit, reason)

    if not heat.any() or not cool.any():
        return unfit("no heating leg" if not heat.any() else "no cooling leg")
    d, overlap = _bin_differences(t, r, heat, cool)
    if overlap is None:
        return unfit("heating and cooling share no temperature range")
    m = int(d.size)
    if m < MIN_BINS:
        return unfit(
            f"only {m} temperature bins hold both directions (need {MIN_BINS})", overlap, m
        )
    mean = float(d.mean())
    sd = float(d.std(ddof=1))
    tstat = mean / (sd / math.sqrt(m)) if sd > 0 else (math.inf if mean else 0.0)
    crit = float(_stats.t.ppf(0.5 + CONFIDENCE / 2.0, m - 1))
    return LegComparison(tuple(figs), mean, tstat, crit, m, overlap, noise, unit)
