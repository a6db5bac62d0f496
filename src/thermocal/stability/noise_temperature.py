"""An IMU's noise over temperature: the Allan noise terms per temperature bin, their trend
against temperature, the noise model at a chosen temperature and the inflation it needs.

Pure maths on arrays (and a :class:`~thermocal.recording.Recording`): no file I/O.  The
samples whose temperature falls in a bin form runs (a chamber ramp crosses a bin once per
pass, a step holds in it); the Allan deviation of a bin pools the runs' sums of squares
(NIST SP 1065 eq. 14 per run, as :func:`thermocal.stability.allan.overlapping_adev` pools
gap-free segments), so a bin visited twice (up and down) counts both visits.  The terms of
each bin are those of :func:`thermocal.stability.noise_model.axis_noise` (IEEE Std 952-1997
Annex C) with their intervals.  The trend of a term is the weighted least-squares line of
its values against the bins' mean temperatures, weights from the intervals, its slope's
standard error scaled by the Birge ratio when the points scatter more than their intervals.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.recording import Recording
from thermocal.stability.edf import ONE_SIGMA_CONFIDENCE
from thermocal.stability.noise_model import AxisNoise, ContinuousTerm, Sensor, axis_noise

FloatArray = npt.NDArray[np.float64]

MIN_RUN_S: Final = 10.0
"""Runs in a bin shorter than this [s] are left out: a thermometer dithering across a bin
edge makes many short runs whose Allan sums hold almost no τ."""

MIN_BIN_S: Final = 120.0
"""A bin with fewer seconds than this in its runs is refused: the white noise is read at
τ = 1 s and the random walk at τ = 3 s, and a −½ line fitted on a few τ of a short record
has an interval wider than the change with temperature it is asked to show."""

SIGNIFICANT_T: Final = 2.0
"""A slope is called significant when it is at least this many standard errors from 0
(≈ 95 % two-sided for a normal estimate)."""

AT_MINIMUM: Final = 0.664
"""The Allan deviation's flicker floor is 0.664 B (IEEE Std 952-1997 C.3)."""


@dataclass(frozen=True)
class AxisSamples:
    """One axis's samples for the noise analysis.

    Attributes
    ----------
    name : str
        The axis (its column).
    sensor : {"gyro", "accel"}
        What it measures.
    unit : str
        Unit of ``values`` (a rate or acceleration unit).
    values : numpy.ndarray
        The samples [``unit``].
    """

    name: str
    sensor: Sensor
    unit: str
    values: FloatArray


@dataclass(frozen=True, eq=False)
class BinNoise:
    """The noise of every axis in one temperature bin, or why the bin is refused.

    Attributes
    ----------
    low_c, high_c : float
        The bin's edges [°C] (``low_c ≤ T < high_c``; the last bin holds its upper edge).
    mean_c : float
        Mean temperature of the samples used [°C] (NaN when refused).
    duration_s : float
        Seconds of samples used (runs of at least :data:`MIN_RUN_S`).
    runs : int
        Runs used.
    rate_c_per_min : float
        The runs' temperature ranges summed over their duration [°C/min] (about 0 on a
        hold; the bias's thermal drift at this rate is part of the bin's random walk and
        bias instability).
    axes : tuple of AxisNoise
        Per axis its terms (empty when refused).
    refused : str or None
        Why the bin has no terms (None: it has).
    """

    low_c: float
    high_c: float
    mean_c: float
    duration_s: float
    runs: int
    rate_c_per_min: float
    axes: tuple[AxisNoise, ...]
    refused: str | None = None

    def axis(self, name: str) -> AxisNoise:
        """The named axis's terms.

        Parameters
        ----------
        name : str
            The axis (its column).

        Returns
        -------
        AxisNoise
        """
        return next(a for a in self.axes if a.name == name)


@dataclass(frozen=True)
class Trend:
    """A term's weighted least-squares line against temperature.

    Attributes
    ----------
    axis : str
        The axis.
    term : str
        ``noise_density`` (N, SI), ``random_walk`` (K, SI) or ``bias_instability`` (B at
        the minimum, the data's unit).
    unit : str
        Unit of the term.
    slope_per_c : float or None
        d(term)/dT [``unit``/°C] (None: fewer than two bins with the term).
    slope_sigma : float or None
        Its standard error [``unit``/°C] (Birge-scaled).
    value_at_mean : float or None
        The line at ``mean_c`` [``unit``].
    mean_c : float or None
        The bins' weighted mean temperature [°C].
    relative_per_c : float or None
        ``slope_per_c / value_at_mean`` [1/°C].
    significant : bool
        ``|slope| ≥ 2 σ``.
    bins : int
        Bins used.
    words : str
        The trend in words (its slope in %/°C and whether it is significant, or why there
        is none).
    """

    axis: str
    term: str
    unit: str
    slope_per_c: float | None
    slope_sigma: float | None
    value_at_mean: float | None
    mean_c: float | None
    relative_per_c: float | None
    significant: bool
    bins: int
    words: str


@dataclass(frozen=True, eq=False)
class NoiseOverTemperature:
    """The noise terms per temperature bin and their trends.

    Attributes
    ----------
    bins : tuple of BinNoise
        Every bin, refused ones included.
    trends : tuple of Trend
        Per axis and term.
    tau0_s : float
        Sample interval [s].
    confidence : float
        Confidence level of the intervals.
    temperature : str
        The temperature column.
    """

    bins: tuple[BinNoise, ...]
    trends: tuple[Trend, ...]
    tau0_s: float
    confidence: float
    temperature: str

    @property
    def used(self) -> tuple[BinNoise, ...]:
        """The bins with terms, by temperature."""
        return tuple(b for b in self.bins if b.refused is None)

    def to_dict(self) -> dict[str, Any]:
        """Plain values: ``temperature``, ``confidence``, ``bins`` (edges, mean, duration,
        runs, rate, refused, per axis N, K and B with intervals), ``trends``.

        Returns
        -------
        dict
            The keys above.
        """
        return {
            "temperature": self.temperature,
            "confidence": self.confidence,
            "bins": [_bin_dict(b) for b in self.bins],
            "trends": [dataclasses.asdict(t) for t in self.trends],
        }


def _term_dict(t: ContinuousTerm) -> dict[str, Any]:
    """A continuous term as plain values."""
    return {"value": t.value, "low": t.low, "high": t.high, "unit": t.unit,
            "method": t.method, "quality": t.quality}  # fmt: skip


def _bin_dict(b: BinNoise) -> dict[str, Any]:
    """One bin as plain values."""
    axes = {}
    for a in b.axes:
        bm = a.terms.bias_minimum
        axes[a.name] = {
            "sensor": a.sensor,
            "noise_density": _term_dict(a.density),
            "random_walk": _term_dict(a.walk),
            "bias_instability": None
            if bm is None
            else {"value": bm.value, "low": bm.low, "high": bm.high, "unit": bm.unit},
        }
    return {"low_c": b.low_c, "high_c": b.high_c, "mean_c": b.mean_c,
            "duration_s": b.duration_s, "runs": b.runs, "rate_c_per_min": b.rate_c_per_min,
            "refused": b.refused, "axes": axes}  # fmt: skip


def bin_edges(temperature_c: npt.ArrayLike, width_c: float) -> tuple[float, ...]:
    """Bin edges of ``width_c`` covering the finite temperatures, on multiples of the width.

    Parameters
    ----------
    temperature_c : array_like
        Temperatures [°C].
    width_c : float
        Bin width [°C], > 0.

    Returns
    -------
    tuple of float
        The edges [°C], from ``floor(min/w)·w`` to past the maximum.

    Raises
    ------
    thermocal.errors.ParameterError
        A width not finite and positive.
    thermocal.errors.ThermocalInputError
        No finite temperature.

    Examples
    --------
    >>> bin_edges([21.3, 24.9, 38.2], 5.0)
    (20.0, 25.0, 30.0, 35.0, 40.0)
    """
    if not (math.isfinite(width_c) and width_c > 0.0):
        raise ParameterError("width_c", f"{{name}} {width_c!r}: give a bin width > 0 °C")
    t = np.asarray(temperature_c, dtype=np.float64)
    t = t[np.isfinite(t)]
    if t.size == 0:
        raise ThermocalInputError("no finite temperature: the noise cannot be binned by it")
    lo = math.floor(float(t.min()) / width_c) * width_c
    n = math.floor((float(t.max()) - lo) / width_c) + 1
    if n > 1000:
        raise ParameterError("width_c", f"{{name}} {width_c:g} °C makes {n} bins; give a wider bin")
    return tuple(float(lo + i * width_c) for i in range(n + 1))


def _runs(inside: npt.NDArray[np.bool_], segments: Sequence[slice], min_len: int) -> list[slice]:
    """The runs of ``inside`` within each gap-free segment, at least ``min_len`` long."""
    out: list[slice] = []
    for seg in segments:
        m = inside[seg].astype(np.int8)
        d = np.diff(np.concatenate(([0], m, [0])))
        starts, stops = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
        base = seg.start or 0
        out += [slice(base + a, base + b) for a, b in zip(starts, stops, strict=True)
                if b - a >= min_len]  # fmt: skip
    return out


def noise_by_temperature(
    axes: Sequence[AxisSamples],
    temperature_c: npt.ArrayLike,
    tau0_s: float,
    edges_c: Sequence[float],
    *,
    segments: Sequence[slice] | None = None,
    min_bin_s: float = MIN_BIN_S,
    confidence: float = ONE_SIGMA_CONFIDENCE,
    temperature: str = "temperature",
) -> NoiseOverTemperature:
    """The Allan noise terms of every axis per temperature bin, and their trends.

    Parameters
    ----------
    axes : sequence of AxisSamples
        The axes (each as long as ``temperature_c``).
    temperature_c : array_like
        The temperature at each sample [°C] (NaN: the sample is in no bin).
    tau0_s : float
        Sample interval τ0 [s].
    edges_c : sequence of float
        Increasing bin edges [°C] (at least two).
    segments : sequence of slice, optional
        The record's gap-free index ranges (default: one).
    min_bin_s : float, optional
        Seconds a bin needs (default :data:`MIN_BIN_S`); fewer: refused with the reason.
    confidence : float, optional
        Confidence level of the intervals (default one sigma).
    temperature : str, optional
        The temperature's name, stated in the result.

    Returns
    -------
    NoiseOverTemperature
        Per bin the terms or why the bin is refused; per axis and term the trend.

    Raises
    ------
    thermocal.errors.ParameterError
        Edges not increasing, fewer than two; ``min_bin_s`` not positive.
    thermocal.errors.ThermocalInputError
        No finite temperature; fewer than one bin with terms.

    Notes
    -----
    In each bin the Allan variance pools its runs r (NIST SP 1065 eq. 14),
    :math:`\\sigma^2(\\tau) = \\sum_r S_r / (2 m^2 \\sum_r L_r)`, and the terms follow
    IEEE Std 952-1997 C.3 (N from the −½ line at τ = 1 s, K from the +½ line at τ = 3 s).

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C.
    .. [2] W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065 (2008).

    Examples
    --------
    White gyro noise whose density doubles from 20 °C to 40 °C, held 10 min at each:

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> t = np.repeat([20.0, 40.0], 15_000)
    >>> y = rng.normal(0.0, 1.0, t.size) * np.where(t < 30, 1e-3, 2e-3) / np.sqrt(0.01)
    >>> r = noise_by_temperature([AxisSamples("gx", "gyro", "rad/s", y)], t, 0.01,
    ...                          (15.0, 30.0, 45.0))
    >>> [round(b.axis("gx").density.value * 1e3, 1) for b in r.used]
    [1.0, 2.0]
    """
    edges = _check_edges(edges_c, min_bin_s)
    t = np.asarray(temperature_c, dtype=np.float64)
    if not np.isfinite(t).any():
        raise ThermocalInputError(
            f"{temperature}: no finite temperature; the noise cannot be binned by it"
        )
    segs = list(segments) if segments else [slice(0, t.size)]
    min_len = max(3, math.ceil(MIN_RUN_S / tau0_s))
    bins: list[BinNoise] = []
    for i, (lo, hi) in enumerate(itertools.pairwise(edges)):
        last = i == len(edges) - 2
        inside = (t >= lo) & ((t <= hi) if last else (t < hi))
        bins.append(_one_bin(axes, t, inside, lo, hi, segs, min_len, tau0_s, min_bin_s,
                             confidence))  # fmt: skip
    if not any(b.refused is None for b in bins):
        why = "; ".join(f"{b.low_c:g}…{b.high_c:g} °C: {b.refused}" for b in bins[:4])
        raise ThermocalInputError(f"{temperature}: no temperature bin has noise terms ({why})")
    trends = _trends(bins, axes, confidence)
    return NoiseOverTemperature(tuple(bins), trends, tau0_s, confidence, temperature)


def _check_edges(edges_c: Sequence[float], min_bin_s: float) -> tuple[float, ...]:
    """The edges as floats, refused unless finite, increasing and at least two."""
    edges = tuple(float(e) for e in edges_c)
    if (
        len(edges) < 2
        or not all(math.isfinite(e) for e in edges)
        or any(b <= a for a, b in itertools.pairwise(edges))
    ):
        raise ParameterError(
            "edges_c", f"{{name}} {edges!r}: give at least two increasing finite edges [°C]"
        )
    if not (math.isfinite(min_bin_s) and min_bin_s > 0):
        raise ParameterError("min_bin_s", f"{{name}} {min_bin_s!r}: give seconds > 0")
    return edges


def _one_bin(
    axes: Sequence[AxisSamples],
    t: FloatArray,
    inside: npt.NDArray[np.bool_],
    lo: float,
    hi: float,
    segs: list[slice],
    min_len: int,
    tau0_s: float,
    min_bin_s: float,
    confidence: float,
) -> BinNoise:
    """One bin's terms, or the reason it has none."""
    runs = _runs(inside, segs, min_len)
    n = sum(r.stop - r.start for r in runs)
    dur = n * tau0_s
    if dur < min_bin_s:
        total = int(inside.sum()) * tau0_s
        why = (
            f"{dur:.0f} s in runs of ≥ {MIN_RUN_S:g} s ({total:.0f} s in all), fewer than "
            f"the {min_bin_s:g} s the noise terms need: hold the chamber longer in this "
            "range or give wider bins"
        )
        return BinNoise(lo, hi, math.nan, dur, len(runs), math.nan, (), why)
    tt = np.concatenate([t[r] for r in runs])
    span = sum(float(np.ptp(t[r])) for r in runs)  # each run's temperature range
    rate = span / dur * units.SECONDS_PER_MINUTE
    clock = np.arange(t.size, dtype=np.float64) * tau0_s  # the runs are honoured with a clock
    done = tuple(
        axis_noise(
            a.values,
            tau0_s,
            name=a.name,
            sensor=a.sensor,
            unit=a.unit,
            segments=runs,
            time_s=clock,
            confidence=confidence,
        )
        for a in axes
    )
    return BinNoise(lo, hi, float(tt.mean()), dur, len(runs), rate, done)


def _term_of(ax: AxisNoise, term: str) -> tuple[float, float, float, str] | None:
    """(value, low, high, unit) of a term of one bin's axis; None when not measured."""
    if term == "bias_instability":
        bm = ax.terms.bias_minimum
        if bm is None or bm.value is None or bm.low is None or bm.high is None:
            return None
        return bm.value, bm.low, bm.high, bm.unit
    t = ax.density if term == "noise_density" else ax.walk
    if t.method == "bound" or t.low is None or t.high is None:
        return None
    if term == "noise_density":  # the weight: the χ² interval of the Allan point read
        lo, hi = _white_point_interval(ax)
        return t.value, t.value * lo, t.value * hi, t.unit
    return t.value, t.low, t.high, t.unit


def _white_point_interval(ax: AxisNoise) -> tuple[float, float]:
    """(low, high) relative to the Allan deviation at the τ the white noise is read at
    (1 s, or the end of the −½ stretch when it ends sooner): the χ² interval of that one
    point (NIST SP 1065 §5.3), much narrower than the slope line's over its whole stretch."""
    r = ax.allan
    rng = ax.density.tau_range_s
    want = min(ax.density.read_at_tau_s, rng[1]) if rng else ax.density.read_at_tau_s
    ok = np.flatnonzero(np.isfinite(r.adev) & (r.adev > 0) & np.isfinite(r.adev_high))
    k = int(ok[np.argmin(np.abs(np.log(r.tau_s[ok] / want)))])
    return float(r.adev_low[k] / r.adev[k]), float(r.adev_high[k] / r.adev[k])


TERMS: Final = ("noise_density", "random_walk", "bias_instability")
"""The terms whose trend against temperature is computed."""


def _trends(
    bins: list[BinNoise], axes: Sequence[AxisSamples], confidence: float
) -> tuple[Trend, ...]:
    """Every axis's and term's line against temperature."""
    from scipy.stats import norm

    z = float(norm.ppf(0.5 + confidence / 2.0))
    out = []
    for a in axes:
        for term in TERMS:
            pts = [(b.mean_c, _term_of(b.axis(a.name), term)) for b in bins if b.refused is None]
            out.append(_line(a.name, term, [(t, v) for t, v in pts if v is not None],
                             len(pts), z))  # fmt: skip
    return tuple(out)


def _line(
    axis: str,
    term: str,
    pts: list[tuple[float, tuple[float, float, float, str]]],
    n_bins: int,
    z: float,
) -> Trend:
    """The weighted least-squares line of one term's points (T, (v, lo, hi, unit))."""
    unit = pts[0][1][3] if pts else ""
    if len(pts) < 2:
        why = (
            f"no trend: {len(pts)} of {n_bins} bins measure it (a random walk given only as "
            "a bound is not a measurement)"
        )
        return Trend(axis, term, unit, None, None, None, None, None, False, len(pts), why)
    tc = np.array([p[0] for p in pts])
    v = np.array([p[1][0] for p in pts])
    sig = np.array([max((p[1][2] - p[1][1]) / (2.0 * z), 1e-300) for p in pts])
    w = 1.0 / sig**2
    tm = float(np.sum(w * tc) / np.sum(w))
    sxx = float(np.sum(w * (tc - tm) ** 2))
    if sxx <= 0.0:
        why = "no trend: every bin used has the same mean temperature"
        return Trend(axis, term, unit, None, None, None, None, None, False, len(pts), why)
    slope = float(np.sum(w * (tc - tm) * v) / sxx)
    mean = float(np.sum(w * v) / np.sum(w))
    se = 1.0 / math.sqrt(sxx)
    if len(pts) > 2:  # Birge ratio: scatter beyond the intervals widens the error
        chi2 = float(np.sum(w * (v - mean - slope * (tc - tm)) ** 2)) / (len(pts) - 2)
        se *= math.sqrt(max(chi2, 1.0))
    sig_ok = abs(slope) >= SIGNIFICANT_T * se
    rel = slope / mean if mean != 0 else math.nan
    words = f"{rel * 100:+.2g} %/°C ± {se / abs(mean) * 100:.2g} %/°C over {len(pts)} bins: " + (
        "significant" if sig_ok else f"not significant (below {SIGNIFICANT_T:g} σ)"
    )
    return Trend(axis, term, unit, slope, se, mean, tm, rel, sig_ok, len(pts), words)


def imu_noise_by_temperature(
    rec: Recording,
    gyro: Sequence[str],
    accel: Sequence[str],
    temperature: str,
    edges_c: Sequence[float] | None = None,
    *,
    width_c: float = 5.0,
    min_bin_s: float = MIN_BIN_S,
    confidence: float = ONE_SIGMA_CONFIDENCE,
    where: str = "",
) -> NoiseOverTemperature:
    """The noise terms of a recording's gyro (and accelerometer) columns per bin of one
    temperature column (:func:`noise_by_temperature` on the columns in the data's unit).

    Parameters
    ----------
    rec : Recording
        The recording (the IMU at rest in a chamber: steps or a ramp).
    gyro, accel : sequence of str
        Gyro and accelerometer columns.
    temperature : str
        The temperature column.
    edges_c : sequence of float, optional
        Bin edges [°C] (default: bins of ``width_c`` from :func:`bin_edges`).
    width_c : float, optional
        Bin width [°C] when no edges are given (default 5).
    min_bin_s : float, optional
        Seconds a bin needs (default :data:`MIN_BIN_S`).
    confidence : float, optional
        Confidence level of the intervals (default one sigma).
    where : str, optional
        The file errors name.

    Returns
    -------
    NoiseOverTemperature
        Per bin the terms (or why refused) and the trends.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A temperature column with no finite value, or fewer than two bins with terms (no
        change with temperature can be read).
    """
    from thermocal.stability.analysis import signal_in_data_unit

    tc = rec.temperature_c(temperature)
    if not np.isfinite(tc).any():
        raise ThermocalInputError(
            f"{where}: temperature column {temperature!r} holds no finite value; name the "
            "IMU's thermometer column"
        )
    edges = tuple(edges_c) if edges_c is not None else bin_edges(tc, width_c)
    axes = []
    for name in [*gyro, *accel]:
        values, unit = signal_in_data_unit(rec, name)
        axes.append(AxisSamples(name, "gyro" if name in gyro else "accel", unit, values))
    res = noise_by_temperature(
        axes, tc, rec.sample_interval_s, edges, segments=rec.segments(), min_bin_s=min_bin_s,
        confidence=confidence, temperature=temperature,
    )  # fmt: skip
    if len(res.used) < 2:
        used = res.used[0]
        raise ThermocalInputError.naming(
            f"{where}: only one temperature bin has noise terms ({used.low_c:g}…"
            f"{used.high_c:g} °C, {used.duration_s:.0f} s); no change with temperature can "
            "be read: give narrower {edges_c}, or leave the temperature out for one model",
            "edges_c",
        )
    return res


@dataclass(frozen=True)
class Inflation:
    """One reason to inflate the noise model, and the factor this record supports.

    Attributes
    ----------
    reason : str
        ``discretisation``, ``bias_instability`` or ``temperature``.
    key : str
        The Kalibr key it applies to.
    factor : float
        The factor the record supports (1: none needed).
    words : str
        The reason in words, with its source.
    """

    reason: str
    key: str
    factor: float
    words: str


@dataclass(frozen=True, eq=False)
class NoiseAtTemperature:
    """The noise model at one temperature, interpolated between bins, and the inflation it
    needs.

    Attributes
    ----------
    temperature_c : float
        The temperature asked for [°C].
    values : dict of str to float
        Kalibr's keys (continuous time, SI, multiplied by ``inflate``).
    axis_of : dict of str to str
        The axis each key came from (per sensor the largest at this temperature).
    between : tuple of float
        The mean temperatures of the two bins interpolated between [°C] (equal when held
        from the nearest bin).
    inflate : float
        The factor included in ``values`` (1: none).
    advice : tuple of Inflation
        The inflation the record supports, per reason and key.
    update_rate_hz : float
        1/τ0 [Hz].
    """

    temperature_c: float
    values: dict[str, float]
    axis_of: dict[str, str]
    between: tuple[float, float]
    inflate: float
    advice: tuple[Inflation, ...]
    update_rate_hz: float

    def to_dict(self) -> dict[str, Any]:
        """Plain values of every attribute (``advice`` as a list of dicts).

        Returns
        -------
        dict
        """
        d = dataclasses.asdict(self)
        d["between"] = list(self.between)
        return d


_KEYS: Final = (("gyro", "gyroscope"), ("accel", "accelerometer"))


def _interp(res: NoiseOverTemperature, temperature_c: float) -> tuple[BinNoise, BinNoise, float]:
    """The two bins around ``temperature_c`` and the weight of the second; refuses a
    temperature outside the bins' samples."""
    used = sorted(res.used, key=lambda b: b.mean_c)
    lo = min(b.low_c for b in used)
    hi = max(b.high_c for b in used)
    if not (math.isfinite(temperature_c) and lo <= temperature_c <= hi):
        raise ParameterError(
            "temperature_c",
            f"{{name}} {temperature_c:g} °C is outside the bins with noise terms "
            f"({lo:g} … {hi:g} °C): record the IMU at that temperature",
        )
    if temperature_c <= used[0].mean_c:
        return used[0], used[0], 0.0
    if temperature_c >= used[-1].mean_c:
        return used[-1], used[-1], 0.0
    k = next(i for i, b in enumerate(used) if b.mean_c >= temperature_c)
    a, b = used[k - 1], used[k]
    return a, b, (temperature_c - a.mean_c) / (b.mean_c - a.mean_c)


def noise_at_temperature(
    res: NoiseOverTemperature, temperature_c: float, *, inflate: float = 1.0
) -> NoiseAtTemperature:
    """Kalibr's noise model at ``temperature_c``: each axis's N and K interpolated linearly
    between the two bins whose mean temperatures bracket it (held from the nearest bin
    between its mean and its edge), per sensor the largest axis; with the inflation the
    record supports, per reason.

    Parameters
    ----------
    res : NoiseOverTemperature
        The noise per bin (:func:`noise_by_temperature`).
    temperature_c : float
        The estimator's temperature [°C], inside the bins with terms.
    inflate : float, optional
        Factor ≥ 1 included in the values (default 1: none).

    Returns
    -------
    NoiseAtTemperature
        The values, where they came from, and the inflation advice.

    Raises
    ------
    thermocal.errors.ParameterError
        ``temperature_c`` outside the bins with terms; ``inflate`` below 1.

    Notes
    -----
    Inflation advice: (1) discretisation: the values are continuous-time; Kalibr takes
    :math:`\\sigma_d = \\sigma_c/\\sqrt{\\Delta t}` at its ``update_rate`` (factor 1, valid when
    the output is low-pass filtered before decimation, the Kalibr wiki "IMU Noise Model");
    (2) unmodelled bias instability: Kalibr's model has no flicker term, so K is raised
    until the model's minimum :math:`\\sqrt{2NK/\\sqrt3}` reaches the measured floor
    :math:`\\sigma_{min}` (IEEE Std 952-1997 C.3),
    :math:`f_K = \\sqrt3\\,\\sigma_{min}^2 / (2NK)`; (3) temperature: the largest value over the
    bins divided by the value at ``temperature_c``.

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C.
    .. [2] The Kalibr wiki, "IMU Noise Model" (continuous and discrete time; "Kalibr IMU
       Noise Parameters in Practice": inflate for unmodelled effects).
    """
    if not (math.isfinite(inflate) and inflate >= 1.0):
        raise ParameterError("inflate", f"{{name}} {inflate!r}: give a factor ≥ 1 (1: none)")
    a, b, w = _interp(res, temperature_c)
    values: dict[str, float] = {}
    axis_of: dict[str, str] = {}
    advice: list[Inflation] = []
    rate = 1.0 / res.tau0_s
    for sensor, prefix in _KEYS:
        names = [x.name for x in a.axes if x.sensor == sensor]
        if not names:
            continue
        for kind in ("noise_density", "random_walk"):
            key = f"{prefix}_{kind}"
            at = {n: _mix(a.axis(n), b.axis(n), w, kind) for n in names}
            best = max(at, key=lambda n: at[n])
            values[key], axis_of[key] = at[best] * inflate, best
            advice += _advice(res, key, kind, best, at[best], rate)
        bi = _bias_factor(a if w < 0.5 else b, axis_of, prefix, values, inflate)
        if bi is not None:
            advice.append(bi)
    between = (a.mean_c, b.mean_c)
    return NoiseAtTemperature(
        float(temperature_c), values, axis_of, between, float(inflate), tuple(advice), rate
    )


def _mix(a: AxisNoise, b: AxisNoise, w: float, kind: str) -> float:
    """A term linearly between two bins (weight ``w`` on ``b``)."""
    ta, tb = (a.density, b.density) if kind == "noise_density" else (a.walk, b.walk)
    return (1.0 - w) * ta.value + w * tb.value


def _advice(
    res: NoiseOverTemperature, key: str, kind: str, axis: str, value: float, rate: float
) -> list[Inflation]:
    """The discretisation statement and the spread over temperature of one key."""
    out = []
    if kind == "noise_density":
        out.append(Inflation("discretisation", key, 1.0, (
            f"continuous time; Kalibr uses σ_d = σ_c/√Δt = {value * math.sqrt(rate):.4g} per "
            f"sample at {rate:g} Hz, right only when the output is low-pass filtered before "
            "decimation (a subsampled output needs the density at its own rate)"
        )))  # fmt: skip
    worst = max(_mix(b.axis(axis), b.axis(axis), 0.0, kind) for b in res.used)
    out.append(Inflation("temperature", key, max(worst / value, 1.0), (
        f"×{max(worst / value, 1.0):.3g} covers every bin's {axis} "
        f"({worst:.4g} at its largest)"
    )))  # fmt: skip
    return out


def _bias_factor(
    b: BinNoise, axis_of: dict[str, str], prefix: str, values: dict[str, float], inflate: float
) -> Inflation | None:
    """The factor on K that makes the white + random-walk model reach the measured floor."""
    key = f"{prefix}_random_walk"
    ax = b.axis(axis_of[key])
    bm = ax.terms.bias_minimum
    if bm is None or bm.value is None:
        return None
    sensor_si = "rad/s" if ax.sensor == "gyro" else "m/s^2"
    floor = float(units.convert(bm.value * AT_MINIMUM, bm.unit, sensor_si))
    n = values[f"{prefix}_noise_density"] / inflate
    k = values[key] / inflate
    f = math.sqrt(3.0) * floor**2 / (2.0 * n * k)
    return Inflation("bias_instability", key, max(f, 1.0), (
        f"Kalibr's model has no bias instability: the measured floor {floor:.3g} {sensor_si} "
        f"(0.664 B) needs K ×{max(f, 1.0):.3g} for √(2NK/√3) to reach it; Kalibr users "
        "commonly inflate by up to 10× for such unmodelled effects"
    ))  # fmt: skip


def at_temperature_yaml(
    at: NoiseAtTemperature, res: NoiseOverTemperature, source: str, rostopic: str = "/imu0"
) -> str:
    """Kalibr's ``imu.yaml`` at one temperature: each key with the bins it was
    interpolated between, whether the random walk is only a bound, the inflation it
    includes and the inflation the record supports, per reason.

    Parameters
    ----------
    at : NoiseAtTemperature
        The model at the temperature (:func:`noise_at_temperature`).
    res : NoiseOverTemperature
        The bins it came from.
    source : str
        The recording, named in the header.
    rostopic : str, optional
        The IMU's ROS topic (checked by the writer's backstop).

    Returns
    -------
    str
        The ``imu.yaml`` text (checked by
        :func:`thermocal.stability.noise_model.check_kalibr_yaml`).
    """
    from thermocal.identifiers import one_line
    from thermocal.stability.noise_model import KALIBR_KEYS, check_kalibr_yaml

    a, b = at.between
    where = f"{a:.4g} °C" if a == b else f"between the bins at {a:.4g} and {b:.4g} °C"
    lines = [
        f"# IMU noise model for Kalibr at {at.temperature_c:g} °C, written by thermocal noise "
        f"from {one_line(source)}",
        f"# (temperature column {one_line(res.temperature)}; per axis linear {where}).",
        "# Continuous-time values (Kalibr's convention); per sensor the LARGEST axis.",
        f"# Inflation INCLUDED in the values below: x{at.inflate:g}"
        + (" (none)." if at.inflate == 1.0 else "."),
        "# Inflation this record supports (NOT included unless stated above):",
    ]
    lines += [f"#   {i.key} x{i.factor:.3g} ({i.reason}): {one_line(i.words)}" for i in at.advice]
    lines.append("")
    dt = 1.0 / at.update_rate_hz
    for key in KALIBR_KEYS:
        if key in at.values:
            v = at.values[key]
            bound = any(
                not (x.refused) and key.endswith("random_walk")
                and x.axis(at.axis_of[key]).walk.method == "bound"
                for x in res.used
            )  # fmt: skip
            lines.append(f"# {key}: axis {one_line(at.axis_of[key])}"
                         + (" (an UPPER BOUND in at least one bin: the record is too short to"
                            " show the random walk)" if bound else ""))  # fmt: skip
            disc = v / math.sqrt(dt) if key.endswith("density") else v * math.sqrt(dt)
            lines.append(f"#   discrete time at Δt = {dt:.6g} s: {disc:.6e}")
            lines += [f"{key}: {v:.6e}", ""]
    lines += [
        f"update_rate: {float(at.update_rate_hz)!r}",
        "",
        f"rostopic: {json.dumps(rostopic)}",
        "",
    ]
    text = "\n".join(lines)
    check_kalibr_yaml(text)
    return text


def signals_by_temperature(
    rec: Recording,
    names: Sequence[str],
    temperature: str,
    edges_c: Sequence[float] | None = None,
    *,
    width_c: float = 5.0,
    confidence: float = ONE_SIGMA_CONFIDENCE,
    where: str = "",
) -> NoiseOverTemperature:
    """The noise terms per temperature bin of rate or acceleration signals, each taken as a
    gyro or an accelerometer by its unit (:func:`imu_noise_by_temperature`).

    Parameters
    ----------
    rec : Recording
        The recording.
    names : sequence of str
        The signals (a rate or an acceleration unit each).
    temperature : str
        The temperature column.
    edges_c : sequence of float, optional
        Bin edges [°C] (default: bins of ``width_c``).
    width_c : float, optional
        Bin width [°C] (default 5).
    confidence : float, optional
        Confidence level of the intervals.
    where : str, optional
        The file errors name.

    Returns
    -------
    NoiseOverTemperature

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A signal neither a rate nor an acceleration (raw counts: give its unit).
    """
    from thermocal.stability.analysis import signal_in_data_unit

    gyro, accel = [], []
    for n in names:
        unit = units.normalize_signal_unit(signal_in_data_unit(rec, n)[1])
        if unit in units.RATE_UNITS:
            gyro.append(n)
        elif unit in units.ACCEL_UNITS:
            accel.append(n)
        else:
            raise ThermocalInputError(
                f"{where}: signal {n!r} is in {unit!r}: the noise terms per temperature need "
                "a rate or an acceleration unit: state the unit the file is read with"
            )
    return imu_noise_by_temperature(
        rec, gyro, accel, temperature, edges_c, width_c=width_c, confidence=confidence,
        where=where,
    )  # fmt: skip
