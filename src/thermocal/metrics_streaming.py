"""The figures of merit of :func:`thermocal.metrics.compute_metrics` for one rate channel
of a record too long for memory, its time and samples held in block stores
(:class:`thermocal.stability.streaming.BlockSource`) and read window by window: the bias,
the bias stability and peak-to-peak of the block means (never across a gap), the drift
angle at the end and at its largest.  The same arithmetic as in memory; the means and sums
over the whole record are added window by window (relative differences of order 1e-16).

References
----------
- IEEE Std 952-1997; IEEE Std 1431-2004 (bias, bias stability).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Final

import numpy as np
import numpy.typing as npt

from thermocal import metrics as mt
from thermocal.stability.streaming import ArrayStore, BlockSource, BlockStore, exact_sum

FloatArray = npt.NDArray[np.float64]

WINDOW: Final = 1 << 22
"""Values per window read from a store."""

DRIFT_BLOCK: Final = 1 << 18
"""The trapezoids' blocks of :func:`thermocal.metrics.drift_angle_extreme` (its default)."""


def _windows(start: int, stop: int, size: int = WINDOW) -> list[tuple[int, int]]:
    """[start, stop) cut in windows of ``size``."""
    return [(a, min(a + size, stop)) for a in range(start, stop, size)]


def _mean(src: BlockSource, start: int, stop: int) -> float:
    """The mean of values [start, stop), numpy's (its pairwise sum, then / n)."""
    return exact_sum(src, start, stop) / (stop - start)


def _block_means(
    rate: BlockSource, segments: Sequence[slice], m: int, store: BlockStore
) -> BlockSource:
    """:func:`thermocal.metrics.block_means` (m samples, never across a gap; an incomplete
    block at a stretch's end dropped) into a store (the samples themselves for m = 1)."""
    if m == 1 and len(segments) >= 1:
        return rate
    out = store.create("means")
    step = max(WINDOW // m, 1) * m
    for sl in segments:
        k = (sl.stop - sl.start) // m
        for a, b in _windows(sl.start, sl.start + k * m, step):
            out.write(rate.read(a, b).reshape((b - a) // m, m).mean(axis=1))
    return out.finish()


def _std_and_range(means: BlockSource) -> tuple[float, float]:
    """Sample standard deviation (ddof 1, two passes as numpy's) and max − min."""
    n = means.size
    mu = _mean(means, 0, n)
    lo, hi = math.inf, -math.inf
    for a, b in _windows(0, n):
        x = means.read(a, b)
        lo, hi = min(lo, float(x.min())), max(hi, float(x.max()))

    def squares(x: FloatArray) -> FloatArray:
        x -= mu
        return np.multiply(x, x, out=x)

    return math.sqrt(exact_sum(means, 0, n, squares) / (n - 1)), hi - lo


def _reference_window(
    time: BlockSource, rate: BlockSource, window_s: tuple[float, float] | None, earth: float,
    unit: str,
) -> mt.DriftReference:  # fmt: skip
    """:func:`thermocal.metrics.reference_bias` on increasing time in a store."""
    n = time.size
    t0, t_end = float(time.read(0, 1)[0]), float(time.read(n - 1, n)[0])
    duration = t_end - t0
    start, end = mt.drift_reference_window(window_s, duration)
    i0 = i1 = n
    for a, b in _windows(0, n):
        rel = time.read(a, b) - t0
        if i0 == n and rel[-1] >= start:
            i0 = a + int(np.argmax(rel >= start))
        if rel[-1] > end:
            i1 = a + int(np.argmax(rel > end))
            break
    count = max(i1 - i0, 0)
    if count == 0:
        raise mt.empty_reference_window(start, end, duration)
    b0 = _mean(rate, i0, i1) - float(earth)
    return mt.DriftReference("window", start, end, b0, unit, count)


def _drift_extreme(
    time: BlockSource,
    rate: BlockSource,
    segments: Sequence[slice],
    bias: float,
    per: float,
    unit: str,
) -> mt.DriftExtreme:
    """:func:`thermocal.metrics.drift_angle_extreme`: the same trapezoids in the same
    blocks, θ carried across them."""
    theta, best, best_i = 0.0, 0.0, 0
    for sl in segments:
        for wa, wb in _windows(sl.start, sl.stop - 1, max(WINDOW // DRIFT_BLOCK, 1) * DRIFT_BLOCK):
            tw, rw = time.read(wa, wb + 1), rate.read(wa, wb + 1)
            for a in range(wa, wb, DRIFT_BLOCK):
                b = min(wb, a + DRIFT_BLOCK)
                e = rw[a - wa : b + 1 - wa] - bias
                dt = np.diff(tw[a - wa : b + 1 - wa])
                cum = theta + np.cumsum(0.5 * (e[1:] + e[:-1]) * dt) / float(per)
                k = int(np.argmax(np.abs(cum)))
                if abs(float(cum[k])) > best:
                    best, best_i = abs(float(cum[k])), a + 1 + k
                theta = float(cum[-1])
    t0 = float(time.read(0, 1)[0])
    t_best = float(time.read(best_i, best_i + 1)[0])
    return mt.DriftExtreme(end=theta, max_abs=best, max_time_s=t_best - t0, unit=unit)


def streamed_metrics(
    time: BlockSource,
    rate: BlockSource,
    segments: Sequence[slice],
    tau0_s: float,
    *,
    name: str,
    unit: str,
    earth_rate: float = 0.0,
    averaging_s: float | None = None,
    drift_reference_s: tuple[float, float] | None = None,
    drift_bias: float | None = None,
    store: BlockStore | None = None,
    where: str = "",
    progress: Callable[[float], None] | None = None,
) -> mt.MetricsResult:
    r"""The figures of merit of one rate channel held in block stores, as
    :func:`thermocal.metrics.compute_metrics` gives them without temperatures.

    Parameters
    ----------
    time : BlockSource
        Sample times [s], increasing.
    rate : BlockSource
        Samples [``unit``].
    segments : sequence of slice
        The gap-free stretches.
    tau0_s : float
        Sample interval τ0 [s].
    name, unit : str
        The signal and its unit.
    earth_rate : float, optional
        Earth rate on the sensitive axis removed [``unit``] (default 0).
    averaging_s : float, optional
        Averaging time of the bias stability [s] (default τ0).
    drift_reference_s, drift_bias : tuple of float, float, optional
        The drift angle's reference window [s since the first sample] or its constant b0.
    store, where : BlockStore, str, optional
        Where the block means are kept (default memory); the file named in messages.
    progress : callable, optional
        Called with each fraction of the work done.

    Returns
    -------
    thermocal.metrics.MetricsResult
        Bias, bias stability, peak-to-peak and drift angle [``unit``].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Fewer than two averages, or a drift option that does not apply.

    Notes
    -----
    .. math:: B_0 = \frac{1}{n}\sum_i \omega_i - \Omega_{axis},\quad
              \sigma_B = \sqrt{\frac{1}{K-1}\sum_k (\bar\omega_k - \bar{\bar\omega})^2}

    References
    ----------
    - IEEE Std 952-1997; IEEE Std 1431-2004.

    Examples
    --------
    >>> from thermocal.stability.streaming import ArraySource
    >>> y = np.random.default_rng(0).normal(1.0, 0.1, 10_000)
    >>> t = np.arange(y.size) * 0.01
    >>> r = streamed_metrics(ArraySource(t), ArraySource(y), [slice(0, y.size)], 0.01,
    ...                      name="gyro", unit="deg/h", averaging_s=1.0)
    >>> round(r.bias, 3), round(r.bias_stability, 4)
    (1.001, 0.0108)
    """
    store = store if store is not None else ArrayStore()
    report = progress or (lambda _f: None)
    n = rate.size
    avg = float(averaging_s) if averaging_s is not None else tau0_s
    m = mt._samples_per_average(tau0_s, avg)
    b0 = _mean(rate, 0, n) - float(earth_rate)
    report(0.25)
    means = _block_means(rate, segments, m, store)
    if means.size < 2:
        longest = float(max((sl.stop - sl.start) * tau0_s for sl in segments))
        raise mt._too_few_averages_error(where or None, avg, means.size, longest)
    stab, p2p = _std_and_range(means)
    n_means = means.size
    if means is not rate:
        store.remove(means)
    report(0.25)
    ref = ext = None
    drift = _drift(time, rate, segments, name, unit, earth_rate, drift_reference_s, drift_bias)
    if drift is not None:
        ref, ext = drift
    report(0.5)
    t_first, t_last = float(time.read(0, 1)[0]), float(time.read(n - 1, n)[0])
    return _result(
        (b0, stab, float(m * tau0_s), p2p, earth_rate), unit, ref, ext,
        (int(n), len(segments), int(n_means), t_last - t_first if n > 1 else 0.0), name,
    )  # fmt: skip


def _result(
    figures: tuple[float, float, float, float, float],
    unit: str,
    ref: mt.DriftReference | None,
    ext: mt.DriftExtreme | None,
    counts: tuple[int, int, int, float],
    name: str,
) -> mt.MetricsResult:
    """The :class:`thermocal.metrics.MetricsResult` of the figures (bias, stability,
    averaging time, peak-to-peak, earth rate) and counts (samples, stretches, averages,
    duration)."""
    b0, stab, avg_s, p2p, earth = figures
    n, segs, n_means, duration = counts
    return mt.MetricsResult(
        bias=b0, bias_stability=stab, averaging_s=avg_s, peak_to_peak=p2p,
        unit=unit, temperature_sensitivity=None, bias_repeatability=None, stages=(),
        drift_angle=ext.end if ext is not None else None,
        drift_angle_unit=mt.RATE_ANGLE_UNITS[unit][0] if ext is not None else None,
        drift_angle_max=ext.max_abs if ext is not None else None,
        drift_angle_max_time_s=ext.max_time_s if ext is not None else None,
        drift_reference=ref, earth_rate_removed=earth, n_samples=n,
        n_segments=segs, n_averages=n_means, duration_s=duration, signal=name,
    )  # fmt: skip


def _drift(
    time: BlockSource,
    rate: BlockSource,
    segments: Sequence[slice],
    name: str,
    unit: str,
    earth: float,
    drift_reference_s: tuple[float, float] | None,
    drift_bias: float | None,
) -> tuple[mt.DriftReference, mt.DriftExtreme] | None:
    """The drift angle's b0 and extremes on stores, its options checked by
    :func:`thermocal.metrics.drift_options` (None: not a gyro rate)."""
    plan = mt.drift_options(name, unit, drift_reference_s, drift_bias)
    if plan is None:
        return None
    angle_unit, per, ref = plan
    if ref is None:
        ref = _reference_window(time, rate, drift_reference_s, earth, unit)
    ext = _drift_extreme(time, rate, segments, ref.bias + earth, per, angle_unit)
    return ref, ext


__all__ = ["streamed_metrics"]
