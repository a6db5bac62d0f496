"""Pre-processing of recordings: pure numpy functions on arrays.

* :func:`sum_decimate`, :func:`mean_decimate` — sum raw counts to a lower rate
  (the FOG thesis: 100 Hz summed to 1 Hz) or average.
* :func:`block_average` — averages over blocks of a stated time, never across a gap.
* :func:`lowpass_first_order` — the "inertia link" ``H(s) = 1/(T_f s + 1)``,
  discretised exactly (zero-order hold) at the sample period.
* :func:`temperature_rate` — ``Ṫ = (T(t+Δt) − T(t))/Δt`` [°C/min], forward,
  backward (causal) or centred, never across a gap.
* :func:`segment_holds` — split a run into temperature holds and ramps.
* :func:`remove_startup_offset` — subtract the turn-on bias (the FOG thesis).
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
from typing import TYPE_CHECKING, Literal

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule
from thermocal.errors import GapWarning, ThermocalInputError
from thermocal.recording import GAP_FACTOR, FloatArray, contiguous_slices
from thermocal.units import SECONDS_PER_MINUTE

if TYPE_CHECKING:
    from scipy import signal as sps
else:
    sps = LazyModule("scipy.signal")

RateMethod = Literal["forward", "backward", "centred"]
RATE_METHODS: tuple[str, ...] = ("forward", "backward", "centred")


def _as_f64(x: npt.ArrayLike, name: str) -> FloatArray:
    arr = np.asarray(x, dtype=np.float64)
    if arr.ndim != 1:
        raise ThermocalInputError(f"{name} must be one-dimensional, got shape {arr.shape}")
    return arr


# --- decimation and block averages -----------------------------------------------------


def sum_decimate(x: npt.ArrayLike, factor: int) -> FloatArray:
    r"""Sum consecutive blocks of ``factor`` samples.

    Used for pulse counts (100 Hz counts summed to 1 Hz, as in the fibre-optic-gyro
    thesis).  A trailing partial block is dropped.  No gap check: use
    :func:`block_average` on recordings with gaps.

    Parameters
    ----------
    x : array_like
        Samples, one-dimensional [any unit, e.g. counts].
    factor : int
        Samples per block m (≥ 1).

    Returns
    -------
    numpy.ndarray
        Block sums, ``len(x) // factor`` of them [unit of ``x``].

    Raises
    ------
    ThermocalInputError
        ``factor`` below 1, or ``x`` not one-dimensional.

    Notes
    -----
    .. math:: y_j = \sum_{i=jm}^{jm+m-1} x_i

    References
    ----------
    - *Design and engineering implementation of a fibre-optic-gyro line-of-sight
      stabilisation system*, master's thesis, chapter 3 "Fibre-optic gyroscope".

    Examples
    --------
    >>> sum_decimate([1, 2, 3, 4, 5], 2)
    array([3., 7.])
    """
    arr = _as_f64(x, "x")
    if factor < 1:
        raise ThermocalInputError(f"decimation factor must be ≥ 1, got {factor}")
    n = arr.size // factor
    out: FloatArray = arr[: n * factor].reshape(n, factor).sum(axis=1)
    return out


def mean_decimate(x: npt.ArrayLike, factor: int) -> FloatArray:
    r"""Mean of consecutive blocks of ``factor`` samples (trailing partial block dropped).

    Parameters
    ----------
    x : array_like
        Samples, one-dimensional [any unit].
    factor : int
        Samples per block m (≥ 1).

    Returns
    -------
    numpy.ndarray
        Block means :math:`\frac{1}{m}\sum_{i=jm}^{jm+m-1} x_i` [unit of ``x``].

    Raises
    ------
    ThermocalInputError
        ``factor`` below 1, or ``x`` not one-dimensional.

    Examples
    --------
    >>> mean_decimate([1, 2, 3, 4, 5], 2)
    array([1.5, 3.5])
    """
    return sum_decimate(x, factor) / factor


@dataclass(frozen=True)
class BlockAverage:
    """Result of :func:`block_average`.

    ``time_s`` is the mean time of each block's samples, ``values`` the
    block means (rows = blocks, columns = input channels), ``counts`` the
    samples per block and ``segment`` the contiguous segment each block lies in.

    Attributes
    ----------
    time_s : numpy.ndarray
        Mean time of each block's samples [s].
    values : numpy.ndarray
        Block means, rows = blocks, columns = the input channels [their units].
    counts : numpy.ndarray of int64
        Samples in each block.
    segment : numpy.ndarray of int64
        The contiguous segment (between gaps) each block lies in.
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

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    values : array_like
        Samples [any unit], 1-D or (n_samples, n_channels).
    block_s : float
        Block length [s].
    min_fill : float
        Fraction of the nominal sample count a block must hold to be kept.
    gap_factor : float
        A step longer than this many median steps is a gap.

    Returns
    -------
    BlockAverage
        The block times and means.

    Notes
    -----
    Blocks start at each contiguous segment's first sample; a block holds the samples
    with ``t0 + k·block_s ≤ t < t0 + (k+1)·block_s``; the short block at a segment's end
    is dropped.
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
    r"""The time constant of a first-order low-pass of a given bandwidth.

    Parameters
    ----------
    bandwidth_hz : float
        The −3 dB bandwidth f_c [Hz].

    Returns
    -------
    float
        T_f [s].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A bandwidth that is not positive.

    Notes
    -----
    .. math:: T_f = \frac{1}{2\pi f_c}

    Examples
    --------
    >>> round(lowpass_time_constant_s(0.04), 2)
    3.98
    """
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
    r"""First-order low-pass ``H(s) = 1/(T_f s + 1)`` (the FOG thesis's "inertia link").

    Parameters
    ----------
    x : array_like
        The samples [any unit].
    period_s : float
        Sample period τ [s].
    bandwidth_hz : float, optional
        Bandwidth f_c [Hz] (T_f = 1/(2π f_c)); give it or ``time_constant_s``.
    time_constant_s : float, optional
        Time constant T_f [s].
    initial : {"first", "zero"}
        Start at rest at ``x[0]`` (``y[0] = x[0]``) or from 0.

    Returns
    -------
    numpy.ndarray
        The filtered samples y [the unit of ``x``].

    Notes
    -----
    Exact zero-order-hold discretisation at the sample period τ:

    .. math:: a = e^{-\tau/T_f}, \qquad y_k = a\,y_{k-1} + (1-a)\,x_{k-1},

    so that a unit step applied at k = 0 gives :math:`y_k = 1 - e^{-k\tau/T_f}` exactly
    (1 − e⁻¹ at t = T_f).

    Examples
    --------
    >>> y = lowpass_first_order([1.0] * 3, 1.0, time_constant_s=1.0, initial="zero")
    >>> [round(v, 4) for v in y.tolist()]
    [0.0, 0.6321, 0.8647]
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


RATE_BLOCK_ROWS = 32768
"""Rows per block when computing Ṫ of a whole run (:func:`temperature_rates`)."""


def step_range(time_s: FloatArray) -> tuple[float, float]:
    r"""Smallest and largest time step, reduced in cache-sized blocks.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s], NaN-free.

    Returns
    -------
    tuple of float
        :math:`(\min_i (t_{i+1} - t_i), \max_i (t_{i+1} - t_i))` [s];
        ``(inf, -inf)`` for fewer than 2 samples.

    Examples
    --------
    >>> import numpy as np
    >>> step_range(np.array([0.0, 1.0, 3.0]))
    (1.0, 2.0)
    """
    n = int(time_s.size)
    lo, hi = math.inf, -math.inf
    if n < 2:
        return lo, hi
    step = RATE_BLOCK_ROWS * 8
    buf = np.empty(min(step, n - 1))
    for a in range(0, n - 1, step):
        b = min(n - 1, a + step)
        d = np.subtract(time_s[a + 1 : b + 1], time_s[a:b], out=buf[: b - a])
        lo = min(lo, float(d.min()))
        hi = max(hi, float(d.max()))
    return lo, hi


def gap_free_slices(
    time_s: FloatArray,
    gap_factor: float = GAP_FACTOR,
    steps: tuple[float, float] | None = None,
) -> list[slice]:
    """Contiguous index ranges between gaps, with an exact shortcut for gap-free data.

    The same slices as :func:`thermocal.recording.contiguous_slices` (a step longer
    than ``gap_factor`` × the median step is a gap).  When every step is positive and
    ``max(dt) ≤ gap_factor · min(dt)``, no step can exceed ``gap_factor`` × the median
    (``median ≥ min``), so the whole run is one slice without computing the median.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    gap_factor : float, optional
        A step longer than this many median steps is a gap (default ``GAP_FACTOR``, 1.5).
    steps : tuple of float, optional
        :func:`step_range` of ``time_s`` when already known [s].

    Returns
    -------
    list of slice
        The contiguous segments, in order.
    """
    n = int(time_s.size)
    if n < 3:
        return [slice(0, n)] if n else []
    lo, hi = step_range(time_s) if steps is None else steps
    if lo > 0 and hi <= gap_factor * lo:
        return [slice(0, n)]
    return contiguous_slices(time_s, gap_factor)


def backward_partners(
    time_s: FloatArray, s0: int, a: int, b: int, interval_s: float, *, increasing: bool = False
) -> int | npt.NDArray[np.intp]:
    r"""Partner samples of the causal rate for rows ``a … b−1`` of a segment.

    :math:`lo_i` is the first row :math:`j \ge s_0` with :math:`t_j \ge t_i - \Delta t`
    (``searchsorted(..., side="left")``, as :func:`temperature_rate`).

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    s0 : int
        First row of the contiguous segment.
    a, b : int
        The rows ``a … b−1`` whose partners are wanted.
    interval_s : float
        Δt [s].
    increasing : bool, optional
        The times are known to increase strictly (then :math:`t_{i-L} < t_i` needs
        no check); default False.

    Returns
    -------
    int or numpy.ndarray
        An ``int`` L when :math:`lo_i = i - L` for every row (checked exactly:
        :math:`t_{i-L} \ge t_i - \Delta t > t_{i-L-1}`, :math:`i - L - 1 \ge s_0`) — the
        usual case of regular sampling, where the partner values are a slice; else the
        array of absolute indices :math:`lo_i`.
    """
    x0 = float(time_s[a]) - interval_s
    lo_a = s0 + int(np.searchsorted(time_s[s0 : a + 1], x0, side="left"))
    shift = a - lo_a
    x = time_s[a:b] - interval_s
    if lo_a > s0 and shift >= 1:
        prev = time_s[a - shift - 1 : b - shift]
        if (
            bool(np.all(prev[1:] >= x))
            and bool(np.all(prev[:-1] < x))
            and (increasing or bool(np.all(time_s[a:b] > prev[1:])))
        ):
            return shift
    lo: npt.NDArray[np.intp] = lo_a + np.searchsorted(time_s[lo_a:b], x, side="left")
    return lo


def segment_rates(
    ts: FloatArray,
    Ts: FloatArray,
    rows: npt.NDArray[np.intp],
    interval_s: float,
    method: str = "backward",
) -> FloatArray:
    r"""Temperature rate at some rows of one contiguous segment.

    The same arithmetic as :func:`temperature_rate`: partner samples lo/hi inside the
    segment (backward: the first :math:`t_j \ge t_i - \Delta t` and i; forward: i and
    the first :math:`t_j \ge t_i + \Delta t`; centred: ±Δt/2), 0 when the span is 0.
    Works on a block of rows so that long runs need no full-size temporaries.

    Parameters
    ----------
    ts : numpy.ndarray
        The segment's times [s], shape ``(n,)``.
    Ts : numpy.ndarray
        The segment's temperatures [°C], shape ``(n, k)``.
    rows : numpy.ndarray of int
        The rows (within the segment) whose rate is wanted.
    interval_s : float
        Δt [s].
    method : str, optional
        ``"backward"`` (default), ``"forward"`` or ``"centred"``.

    Returns
    -------
    numpy.ndarray
        Ṫ [°C/min], shape ``(len(rows), k)``, Fortran order.

    Raises
    ------
    ThermocalInputError
        An unknown ``method``.

    Notes
    -----
    .. math:: \dot T_i = 60\,\frac{T_{hi} - T_{lo}}{t_{hi} - t_{lo}}
    """
    n = ts.size
    i = np.asarray(rows, dtype=np.intp)
    if i.size == 0:
        return np.zeros((0, Ts.shape[1]), order="F")
    contiguous = int(i[-1]) - int(i[0]) == i.size - 1 and bool(np.all(np.diff(i) == 1))
    ti = ts[i[0] : i[-1] + 1] if contiguous else ts[i]
    if method == "backward" and contiguous:
        a, b = int(i[0]), int(i[-1]) + 1
        out = np.empty((b - a, Ts.shape[1]), order="F")
        part = backward_partners(ts, 0, a, b, interval_s)
        if isinstance(part, int):
            span = ts[a:b] - ts[a - part : b - part]
            np.subtract(Ts[a:b], Ts[a - part : b - part], out=out)
            out /= span[:, None]
            out *= SECONDS_PER_MINUTE
            return out
        lo = part
        hi = i
    elif method == "backward":
        lo = np.searchsorted(ts, ti - interval_s, side="left")
        hi = i
    elif method == "forward":
        lo = i
        hi = np.minimum(np.searchsorted(ts, ti + interval_s, side="left"), n - 1)
    elif method == "centred":
        lo = np.searchsorted(ts, ti - interval_s / 2.0, side="left")
        hi = np.minimum(np.searchsorted(ts, ti + interval_s / 2.0, side="left"), n - 1)
    else:
        raise ThermocalInputError(f"unknown rate method {method!r}")
    span = ts[hi] - ts[lo]
    out = np.zeros((i.size, Ts.shape[1]), order="F")
    ok = span > 0
    if ok.all():
        out[...] = (Ts[hi] - Ts[lo]) / span[:, None] * SECONDS_PER_MINUTE
    elif ok.any():
        out[ok] = (Ts[hi[ok]] - Ts[lo[ok]]) / span[ok, None] * SECONDS_PER_MINUTE
    return out


def temperature_rates(
    time_s: FloatArray,
    temps_c: FloatArray,
    interval_s: float,
    method: str = "backward",
    *,
    gap_factor: float = GAP_FACTOR,
) -> FloatArray:
    """Temperature rate of every column, never across a gap.

    :func:`segment_rates` per contiguous segment, in blocks of :data:`RATE_BLOCK_ROWS`
    rows; equal, bit for bit, to :func:`temperature_rate` applied column by column.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    temps_c : numpy.ndarray
        Temperatures [°C], shape ``(n, k)`` or ``(n,)`` (then a 1-D result).
    interval_s : float
        Δt [s].
    method : str, optional
        ``"backward"`` (default), ``"forward"`` or ``"centred"``.
    gap_factor : float, optional
        A step longer than this many median steps is a gap (default 1.5).

    Returns
    -------
    numpy.ndarray
        Ṫ [°C/min], the shape of ``temps_c``.
    """
    T = np.asarray(temps_c, dtype=np.float64)
    one_d = T.ndim == 1
    T2 = T.reshape(-1, 1) if one_d else T
    out = np.zeros(T2.shape)
    for sl in gap_free_slices(time_s, gap_factor):
        s0, s1 = int(sl.start), int(sl.stop)
        ts, Ts = time_s[s0:s1], T2[s0:s1]
        for a in range(0, s1 - s0, RATE_BLOCK_ROWS):
            b = min(s1 - s0, a + RATE_BLOCK_ROWS)
            out[s0 + a : s0 + b] = segment_rates(ts, Ts, np.arange(a, b), interval_s, method)
    return out[:, 0] if one_d else out


def backward_rates(
    time_s: FloatArray, temps_c: FloatArray, interval_s: float, *, gap_factor: float = GAP_FACTOR
) -> FloatArray:
    r"""Causal temperature rate of every column.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    temps_c : numpy.ndarray
        Temperatures [°C], shape ``(n, k)`` or ``(n,)``.
    interval_s : float
        Δt [s].
    gap_factor : float, optional
        A step longer than this many median steps is a gap (default 1.5).

    Returns
    -------
    numpy.ndarray
        Ṫ [°C/min], the shape of ``temps_c``.

    Notes
    -----
    .. math:: \dot T(t) = 60\,\frac{T(t) - T(t - \Delta t)}{\Delta t}
    """
    return temperature_rates(time_s, temps_c, interval_s, "backward", gap_factor=gap_factor)


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
    r"""Temperature rate Ṫ [°C/min] over an interval Δt [s], never across a gap.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    temp_c : array_like
        Temperatures [°C].
    interval_s : float
        The interval Δt [s].
    method : {"backward", "forward", "centred"}
        Where the difference is assigned (below).
    gap_factor : float
        A step longer than this many median steps is a gap.

    Returns
    -------
    numpy.ndarray
        Ṫ [°C/min] per sample.

    Raises
    ------
    ThermocalInputError
        ``time_s`` and ``temp_c`` differ in length, an unknown ``method``, or
        ``interval_s`` not positive.

    Notes
    -----
    The forward difference of the ring-laser-gyro modelling method:

    .. math:: \dot T(t) = \frac{T(t+\Delta t) - T(t)}{\Delta t}

    Three forms:

    * ``"forward"`` — the patent's formula at time t: partner sample j is the first
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

    References
    ----------
    - *A modelling and validation method for the temperature compensation model of a
      ring-laser gyroscope*, Chinese invention patent, 2017 (the temperature rate).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 600.0, 1.0)
    >>> round(float(temperature_rate(t, 20.0 + t / 120.0)[-1]), 3)
    0.5
    """
    t = _as_f64(time_s, "time_s")
    T = _as_f64(temp_c, "temp_c")
    if t.size != T.size:
        raise ThermocalInputError("time_s and temp_c have different lengths")
    if method not in RATE_METHODS:
        raise ThermocalInputError(f"unknown rate method {method!r}; use one of {RATE_METHODS}")
    if not interval_s > 0:
        raise ThermocalInputError(f"rate interval must be positive, got {interval_s}")
    # one implementation of Ṫ for the whole package: the block form the models
    # use, on one column
    out: FloatArray = temperature_rates(t, T, interval_s, method, gap_factor=gap_factor)
    return out


# --- segmentation --------------------------------------------------------------------


@dataclass(frozen=True)
class Segment:
    """A stretch of a run: a temperature ``"hold"`` or a ``"ramp"``.

    Attributes
    ----------
    kind : {"hold", "ramp"}
        What the stretch is.
    start, stop : int
        Sample indices (``slice(start, stop)``).
    start_s, stop_s : float
        Times of the first and last sample [s].
    mean_temp_c : float
        Mean temperature [°C].
    rate_c_per_min : float
        Mean temperature rate over the segment [°C/min].
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
        """``slice(start, stop)`` of the segment's samples."""
        return slice(self.start, self.stop)

    @property
    def duration_s(self) -> float:
        """Time from the segment's first to its last sample [s]."""
        return self.stop_s - self.start_s


def _label_segments(
    t: FloatArray,
    T: FloatArray,
    is_hold: npt.NDArray[np.bool_],
    settle_s: float,
    min_duration_s: float,
    gap_factor: float,
) -> list[Segment]:
    """The holds and ramps of :func:`segment_holds` from the per-sample hold mask."""
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
    r"""Split a run into temperature holds and ramps from the temperature rate.

    A sample belongs to a hold when the centred rate over ``rate_interval_s``
    satisfies :math:`|\dot T| <` ``rate_threshold_c_per_min``; runs of such samples
    lasting at least ``min_duration_s`` are holds (their first ``settle_s`` seconds
    are given to the preceding ramp), everything else is ramp.  Segments never span
    a gap.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    temp_c : array_like
        Temperatures [°C].
    rate_threshold_c_per_min : float, optional
        Largest |Ṫ| of a hold [°C/min] (default 0.05).
    min_duration_s : float, optional
        Shortest hold [s] (default 600).
    rate_interval_s : float, optional
        Δt of the centred rate [s] (default 60).
    settle_s : float, optional
        Start of each hold given to the ramp before it [s] (default 0).
    gap_factor : float, optional
        A step longer than this many median steps is a gap (default 1.5).

    Returns
    -------
    list of Segment
        Holds and ramps in time order.

    Raises
    ------
    ThermocalInputError
        Lengths differ, or ``rate_interval_s`` not positive.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 3600.0, 1.0)
    >>> T = np.where(t < 1200, 20.0, np.minimum(20.0 + (t - 1200) / 60.0, 30.0))
    >>> [s.kind for s in segment_holds(t, T)]
    ['hold', 'ramp', 'hold']
    """
    t = _as_f64(time_s, "time_s")
    T = _as_f64(temp_c, "temp_c")
    if t.size != T.size:
        raise ThermocalInputError("time_s and temp_c have different lengths")
    if not rate_interval_s > 0:
        raise ThermocalInputError(f"rate interval must be positive, got {rate_interval_s}")
    # |Ṫ| < threshold block by block (the centred Ṫ of temperature_rate, bit for bit):
    # one byte a sample, no full-length Ṫ
    is_hold = np.full(t.size, rate_threshold_c_per_min > 0.0)  # rows of no segment: Ṫ = 0
    T2 = T.reshape(-1, 1)
    for sl in gap_free_slices(t, gap_factor):
        s0, s1 = int(sl.start), int(sl.stop)
        ts, Ts = t[s0:s1], T2[s0:s1]
        for a in range(0, s1 - s0, RATE_BLOCK_ROWS):
            b = min(s1 - s0, a + RATE_BLOCK_ROWS)
            r = segment_rates(ts, Ts, np.arange(a, b), rate_interval_s, "centred")[:, 0]
            np.less(np.abs(r), rate_threshold_c_per_min, out=is_hold[s0 + a : s0 + b])
    return _label_segments(t, T, is_hold, settle_s, min_duration_s, gap_factor)


# --- offsets and spectrum ---------------------------------------------------------------


def remove_startup_offset(
    time_s: npt.ArrayLike, x: npt.ArrayLike, window_s: float
) -> tuple[FloatArray, float]:
    r"""Subtract the turn-on offset: the mean of the first ``window_s`` seconds.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    x : array_like
        The signal [its unit].
    window_s : float
        Length of the start-up window [s] (at least one sample is used).

    Returns
    -------
    tuple of (numpy.ndarray, float)
        ``(x − offset, offset)`` [unit of ``x``].

    Raises
    ------
    ThermocalInputError
        An empty signal.

    Notes
    -----
    .. math:: b_0 = \frac{1}{n}\sum_{t_i < t_0 + w} x_i

    References
    ----------
    - *Design and engineering implementation of a fibre-optic-gyro line-of-sight
      stabilisation system*, master's thesis, chapter 3 "Fibre-optic gyroscope".

    Examples
    --------
    >>> import numpy as np
    >>> y, b0 = remove_startup_offset(np.arange(10.0), np.arange(10.0) + 5.0, 3.0)
    >>> b0
    6.0
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
    """One-sided power spectral density.

    Attributes
    ----------
    frequency_hz : numpy.ndarray
        Frequencies [Hz].
    psd : numpy.ndarray
        Power spectral density [unit²/Hz].
    segment_length : int
        Samples per Welch segment.
    """

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
    """Welch power spectral density of a signal on its longest gap-free segment.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    x : array_like
        Samples [unit].
    segment_length : int, optional
        Samples per Welch segment (default: scipy's).
    gap_factor : float
        A step longer than this many median steps is a gap.

    Returns
    -------
    Spectrum
        Frequencies [Hz] and the one-sided PSD [unit²/Hz].

    Warns
    -----
    GapWarning
        The recording has gaps (only the longest segment is used).

    Notes
    -----
    ``scipy.signal.welch``: Hann window, 50 % overlap, linear detrend (Welch 1967).  The
    temperature drift lives below ~0.04 Hz.

    References
    ----------
    - P. D. Welch, "The use of fast Fourier transform for the estimation of power
      spectra: a method based on time averaging over short, modified periodograms",
      IEEE Transactions on Audio and Electroacoustics 15(2), pp. 70-73, 1967.
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
