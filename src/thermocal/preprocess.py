"""Pre-processing of recordings (SPEC §3): pure numpy functions on arrays.

* :func:`sum_decimate`, :func:`mean_decimate` — sum raw counts to a lower rate
  (seed 001: 100 Hz summed to 1 Hz) or average.
* :func:`block_average` — averages over blocks of a stated time, never across a gap.
* :func:`lowpass_first_order` — the "inertia link" ``H(s) = 1/(T_f s + 1)``,
  discretised exactly (zero-order hold) at the sample period.
* :func:`temperature_rate` — ``Ṫ = (T(t+Δt) − T(t))/Δt`` [°C/min], forward,
  backward (causal) or centred, never across a gap.
* :func:`segment_holds` — split a run into temperature holds and ramps.
* :func:`remove_startup_offset` — subtract the turn-on bias (seed 001).
* :func:`spectrum` — Welch power spectral density of the static output.

Gaps are found by :func:`thermocal.recording.find_gaps` (a step longer than
1.5 × the median step) and every function that looks across samples in time
works per contiguous segment.
"""

from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt
from scipy import signal as sps

from thermocal.errors import GapWarning, ThermocalInputError
from thermocal.recording import GAP_FACTOR, FloatArray, contiguous_slices
from thermocal.units import SECONDS_PER_MINUTE

RateMethod = Literal["forward", "backward", "centred"]
RATE_METHODS: tuple[str, ...] = ("forward", "backward", "centred")


def _as_f64(x: npt.ArrayLike, name: str) -> FloatArray:
    arr = np.asarray(x, dtype=np.float64)
    if arr.ndim != 1:
        raise ThermocalInputError(f"{name} must be one-dimensional, got shape {arr.shape}")
    return arr


# --- decimation and block averages -----------------------------------------------------


def sum_decimate(x: npt.ArrayLike, factor: int) -> FloatArray:
    """Sum consecutive blocks of ``factor`` samples: ``y_j = Σ_{i=jm}^{jm+m-1} x_i``.

    Used for pulse counts (SPEC §3: 100 Hz counts summed to 1 Hz).  A trailing
    partial block is dropped.  No gap check: use :func:`block_average` on
    recordings with gaps.
    """
    arr = _as_f64(x, "x")
    if factor < 1:
        raise ThermocalInputError(f"decimation factor must be ≥ 1, got {factor}")
    n = arr.size // factor
    out: FloatArray = arr[: n * factor].reshape(n, factor).sum(axis=1)
    return out


def mean_decimate(x: npt.ArrayLike, factor: int) -> FloatArray:
    """Mean of consecutive blocks of ``factor`` samples (trailing partial block dropped)."""
    return sum_decimate(x, factor) / factor


@dataclass(frozen=True)
class BlockAverage:
    """Result of :func:`block_average`.

    ``time_s`` is the mean time of each block's samples, ``values`` the
    block means (rows = blocks, columns = input channels), ``counts`` the
    samples per block and ``segment`` the contiguous segment each block lies in.
    """

    time_s: FloatArray
    values: FloatArray
    counts: npt.NDArray[np.int64]
    segment: npt.NDArray[np.int64]


def block_average(
    time_s: npt.ArrayLike,
    values: npt.ArrayLike,
    block_s: float,
    *,
    min_fill: float = 0.9,
    gap_factor: float = GAP_FACTOR,
) -> BlockAverage:
    """Average ``values`` over consecutive blocks of ``block_s`` seconds, never across a gap.

    Blocks start at each contiguous segment's first sample; a block holds the
    samples with ``t0 + k·block_s ≤ t < t0 + (k+1)·block_s``.  Blocks with fewer
    than ``min_fill`` × the nominal sample count (the end of a segment) are dropped.
    ``values`` may be 1-D or (n_samples, n_channels).
    """
    t = _as_f64(time_s, "time_s")
    v = np.asarray(values, dtype=np.float64)
    one_d = v.ndim == 1
    v2 = v.reshape(-1, 1) if one_d else v
    if v2.shape[0] != t.size:
        raise ThermocalInputError("values and time_s have different lengths")
    if not block_s > 0:
        raise ThermocalInputError(f"block length must be positive, got {block_s}")
    if t.size < 2:
        raise ThermocalInputError("block averaging needs at least 2 samples")
    tau = float(np.median(np.diff(t)))
    nominal = block_s / tau
    out_t: list[FloatArray] = []
    out_v: list[FloatArray] = []
    out_n: list[npt.NDArray[np.int64]] = []
    out_s: list[npt.NDArray[np.int64]] = []
    for k, sl in enumerate(contiguous_slices(t, gap_factor)):
        ts = t[sl]
        idx = np.floor((ts - ts[0]) / block_s + 1e-9).astype(np.int64)
        starts = np.flatnonzero(np.r_[True, idx[1:] != idx[:-1]])
        counts = np.diff(np.r_[starts, ts.size]).astype(np.int64)
        sums_t = np.add.reduceat(ts, starts)
        sums_v = np.add.reduceat(v2[sl], starts, axis=0)
        keep = counts >= min_fill * nominal - 1e-9
        out_t.append(sums_t[keep] / counts[keep])
        out_v.append(sums_v[keep] / counts[keep, None])
        out_n.append(counts[keep])
        out_s.append(np.full(int(keep.sum()), k, dtype=np.int64))
    vals = np.concatenate(out_v) if out_v else np.zeros((0, v2.shape[1]))
    return BlockAverage(
        time_s=np.concatenate(out_t),
        values=vals[:, 0] if one_d else vals,
        counts=np.concatenate(out_n),
        segment=np.concatenate(out_s),
    )


# --- low-pass filter -------------------------------------------------------------------


def lowpass_time_constant_s(bandwidth_hz: float) -> float:
    """``T_f = 1/(2π f_c)`` [s] of a first-order low-pass with bandwidth ``f_c`` [Hz]
    (SPEC §3: 0.04 Hz → T_f ≈ 3.98 s)."""
    if not bandwidth_hz > 0:
        raise ThermocalInputError(f"bandwidth must be positive, got {bandwidth_hz}")
    return 1.0 / (2.0 * math.pi * bandwidth_hz)


def lowpass_first_order(
    x: npt.ArrayLike,
    period_s: float,
    *,
    bandwidth_hz: float | None = None,
    time_constant_s: float | None = None,
    initial: Literal["first", "zero"] = "first",
) -> FloatArray:
    """First-order low-pass ``H(s) = 1/(T_f s + 1)`` (SPEC §3, seed 001 "inertia link").

    Exact zero-order-hold discretisation at the sample period τ::

        a = exp(−τ/T_f),   y[k] = a·y[k−1] + (1 − a)·x[k−1]

    so that a unit step applied at k = 0 gives ``y[k] = 1 − exp(−kτ/T_f)`` exactly
    (``1 − e⁻¹`` at t = T_f).  ``initial="first"`` starts at rest at ``x[0]``
    (``y[0] = x[0]``), ``"zero"`` starts from 0.  Give either ``bandwidth_hz``
    (``T_f = 1/(2π f_c)``) or ``time_constant_s``.
    """
    arr = _as_f64(x, "x")
    if (bandwidth_hz is None) == (time_constant_s is None):
        raise ThermocalInputError("give exactly one of bandwidth_hz and time_constant_s")
    tf = time_constant_s if time_constant_s is not None else lowpass_time_constant_s(bandwidth_hz)  # type: ignore[arg-type]
    if not tf > 0 or not period_s > 0:
        raise ThermocalInputError("time constant and sample period must be positive")
    if arr.size == 0:
        return arr.copy()
    a = math.exp(-period_s / tf)
    y0 = arr[0] if initial == "first" else 0.0
    # y[k] - a y[k-1] = (1-a) x[k-1]  →  lfilter with b = [0, 1-a], a = [1, -a]
    zi = np.array([y0])  # transposed direct form: y[0] = zi
    y, _ = sps.lfilter([0.0, 1.0 - a], [1.0, -a], arr, zi=zi)
    return np.asarray(y, dtype=np.float64)


# --- temperature rate ------------------------------------------------------------------


RATE_BLOCK = 1 << 16
"""Rows per block of :func:`temperature_rate` (its working memory is per block)."""


def temperature_rate(
    time_s: npt.ArrayLike,
    temp_c: npt.ArrayLike,
    interval_s: float = 60.0,
    method: RateMethod = "backward",
    *,
    gap_factor: float = GAP_FACTOR,
) -> FloatArray:
    """Temperature rate Ṫ [°C/min] over an interval Δt [s], never across a gap.

    SPEC §3 (seed 000): ``Ṫ(t) = (T(t+Δt) − T(t)) / Δt``.  Three forms:

    * ``"forward"`` — the seed's formula at time t: partner sample j is the first
      with ``t_j ≥ t_i + Δt``;
    * ``"backward"`` — the same difference assigned to the end of the interval,
      ``Ṫ(t) = (T(t) − T(t−Δt))/Δt``: causal, so firmware and the streaming
      compensator compute it sample by sample (the default for models);
    * ``"centred"`` — ``(T(t+Δt/2) − T(t−Δt/2))/Δt``.

    The partner sample is clipped to the contiguous segment that holds sample i,
    so near a segment's edge the difference spans the samples available (a
    shorter interval, divided by its own length); with no partner (a one-sample
    segment) Ṫ = 0.  The difference is always divided by the actual time between
    the two samples, so ``Ṫ`` of a ramp at r °C/min is exactly r.
    """
    t = _as_f64(time_s, "time_s")
    T = _as_f64(temp_c, "temp_c")
    if t.size != T.size:
        raise ThermocalInputError("time_s and temp_c have different lengths")
    if method not in RATE_METHODS:
        raise ThermocalInputError(f"unknown rate method {method!r}; use one of {RATE_METHODS}")
    if not interval_s > 0:
        raise ThermocalInputError(f"rate interval must be positive, got {interval_s}")
    out = np.zeros_like(T)
    for sl in contiguous_slices(t, gap_factor):
        ts, Ts = t[sl], T[sl]
        n = ts.size
        seg_out = out[sl]
        # in blocks of rows: the partner indices and spans of a block only (bounded memory)
        for a in range(0, n, RATE_BLOCK):
            b = min(n, a + RATE_BLOCK)
            tb = ts[a:b]
            i = np.arange(a, b)
            if method == "forward":
                lo = i
                hi = np.minimum(np.searchsorted(ts, tb + interval_s, side="left"), n - 1)
            elif method == "backward":
                lo = np.searchsorted(ts, tb - interval_s, side="left")
                hi = i
            else:
                lo = np.searchsorted(ts, tb - interval_s / 2.0, side="left")
                hi = np.minimum(np.searchsorted(ts, tb + interval_s / 2.0, side="left"), n - 1)
            span = ts[hi] - ts[lo]
            ok = span > 0
            rate = np.zeros(b - a)
            rate[ok] = (Ts[hi[ok]] - Ts[lo[ok]]) / span[ok] * SECONDS_PER_MINUTE
            seg_out[a:b] = rate
    return out


# --- segmentation --------------------------------------------------------------------


@dataclass(frozen=True)
class Segment:
    """A stretch of a run: a temperature ``"hold"`` or a ``"ramp"``.

    ``start``/``stop`` are sample indices (``slice(start, stop)``), ``start_s``/
    ``stop_s`` times [s], ``mean_temp_c`` the mean temperature [°C] and
    ``rate_c_per_min`` the mean temperature rate [°C/min] over the segment.
    """

    kind: Literal["hold", "ramp"]
    start: int
    stop: int
    start_s: float
    stop_s: float
    mean_temp_c: float
    rate_c_per_min: float

    @property
    def slice(self) -> slice:
        return slice(self.start, self.stop)

    @property
    def duration_s(self) -> float:
        return self.stop_s - self.start_s


def segment_holds(
    time_s: npt.ArrayLike,
    temp_c: npt.ArrayLike,
    *,
    rate_threshold_c_per_min: float = 0.05,
    min_duration_s: float = 600.0,
    rate_interval_s: float = 60.0,
    settle_s: float = 0.0,
    gap_factor: float = GAP_FACTOR,
) -> list[Segment]:
    """Split a run into temperature holds and ramps from the temperature rate.

    A sample belongs to a hold when the centred rate over ``rate_interval_s``
    satisfies ``|Ṫ| < rate_threshold_c_per_min``; runs of such samples lasting at
    least ``min_duration_s`` are holds (their first ``settle_s`` seconds are
    given to the preceding ramp), everything else is ramp.  Segments never span
    a gap.
    """
    t = _as_f64(time_s, "time_s")
    T = _as_f64(temp_c, "temp_c")
    rate = temperature_rate(t, T, rate_interval_s, "centred", gap_factor=gap_factor)
    is_hold = np.empty(rate.size, dtype=bool)
    for a in range(0, rate.size, RATE_BLOCK):  # |Ṫ| without a full-size copy
        np.less(
            np.abs(rate[a : a + RATE_BLOCK]),
            rate_threshold_c_per_min,
            out=is_hold[a : a + RATE_BLOCK],
        )
    del rate
    segs: list[Segment] = []
    for sl in contiguous_slices(t, gap_factor):
        base = int(sl.start)
        h = is_hold[sl]
        ts = t[sl]
        change = np.flatnonzero(h[1:] != h[:-1]) + 1
        bounds = np.r_[0, change, h.size]
        labels: list[tuple[bool, int, int]] = []
        for a, b in itertools.pairwise(bounds):
            hold = bool(h[a])
            if hold:
                a2 = int(np.searchsorted(ts, ts[a] + settle_s, side="left"))
                if ts[b - 1] - ts[min(a2, b - 1)] < min_duration_s or a2 >= b:
                    hold = False
                elif a2 > a:
                    labels.append((False, int(a), a2))
                    a = a2
            labels.append((hold, int(a), int(b)))
        # merge neighbours of the same kind
        merged: list[tuple[bool, int, int]] = []
        for hold, a, b in labels:
            if merged and merged[-1][0] == hold:
                merged[-1] = (hold, merged[-1][1], b)
            else:
                merged.append((hold, a, b))
        for hold, a_i, b_i in merged:
            seg_t = ts[a_i:b_i]
            dur = float(seg_t[-1] - seg_t[0])
            mean_rate = (
                float((T[base + b_i - 1] - T[base + a_i]) / dur * SECONDS_PER_MINUTE)
                if dur > 0
                else 0.0
            )
            segs.append(
                Segment(
                    kind="hold" if hold else "ramp",
                    start=base + a_i,
                    stop=base + b_i,
                    start_s=float(seg_t[0]),
                    stop_s=float(seg_t[-1]),
                    mean_temp_c=float(np.mean(T[base + a_i : base + b_i])),
                    rate_c_per_min=mean_rate,
                )
            )
    return segs


# --- offsets and spectrum ---------------------------------------------------------------


def remove_startup_offset(
    time_s: npt.ArrayLike, x: npt.ArrayLike, window_s: float
) -> tuple[FloatArray, float]:
    """Subtract the turn-on offset: the mean of the first ``window_s`` seconds (seed 001).

    Returns ``(x − offset, offset)``.
    """
    t = _as_f64(time_s, "time_s")
    arr = _as_f64(x, "x")
    if t.size == 0:
        raise ThermocalInputError("cannot remove a start-up offset from an empty signal")
    n = max(1, int(np.searchsorted(t, t[0] + window_s, side="left")))
    offset = float(np.mean(arr[:n]))
    return arr - offset, offset


@dataclass(frozen=True)
class Spectrum:
    """One-sided power spectral density: ``frequency_hz`` and ``psd`` [unit²/Hz]."""

    frequency_hz: FloatArray
    psd: FloatArray
    segment_length: int


def spectrum(
    time_s: npt.ArrayLike,
    x: npt.ArrayLike,
    *,
    segment_length: int | None = None,
    gap_factor: float = GAP_FACTOR,
) -> Spectrum:
    """Welch PSD of a signal (scipy.signal.welch, Hann window, 50 % overlap, linear detrend).

    Computed on the longest contiguous segment (a :class:`GapWarning` says so when
    the recording has gaps).  SPEC §3: the temperature drift lives below ~0.04 Hz.
    """
    t = _as_f64(time_s, "time_s")
    arr = _as_f64(x, "x")
    slices = contiguous_slices(t, gap_factor)
    if len(slices) > 1:
        warnings.warn(
            f"recording has {len(slices) - 1} gaps; spectrum uses the longest contiguous segment",
            GapWarning,
            stacklevel=2,
        )
    sl = max(slices, key=lambda s: s.stop - s.start)
    ts, xs = t[sl], arr[sl]
    if ts.size < 8:
        raise ThermocalInputError("spectrum needs at least 8 contiguous samples")
    fs = 1.0 / float(np.median(np.diff(ts)))
    nper = segment_length or min(ts.size, 2 ** int(math.log2(max(8, ts.size // 8))))
    f, p = sps.welch(xs, fs=fs, nperseg=nper, detrend="linear")
    return Spectrum(np.asarray(f, dtype=np.float64), np.asarray(p, dtype=np.float64), int(nper))
