"""The overlapping Allan deviation of records too long for memory, computed a window at a
time: the default ``thermocal allan`` analysis (octave τ, Greenhall's EDF, the noise
identification, the noise terms) on samples held in block stores instead of one array.

The samples, the phase of each gap-free stretch and the octave block sums of the longest
stretch live in stores the caller provides (:class:`BlockStore`: the file layer writes them
to temporary files); every pass here reads them in windows of :data:`WINDOW` values, so the
memory used is a few windows whatever the record's length.  The arithmetic is that of the
in-memory kernels (:func:`thermocal.stability.allan.overlapping_adev`): the phase is the
running sum with its carry across windows (the same additions in the same order), the sums
of squared second differences are taken over the same blocks of
:data:`thermocal.stability.allan._CHUNK` terms, and the octave levels' sums come from the
same blocked kernel on windows of a level; only the order in which per-window partial sums
are added differs (relative differences of order 1e-16 per sum).

References
----------
- NIST SP 1065 (Riley 2008), eq. 11 (overlapping Allan variance from phase).
- Greenhall & Riley 2003 (EDF); Riley & Greenhall 2004 (noise identification).
"""

from __future__ import annotations

import functools
import math
import threading
import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Final, Protocol

import numpy as np
import numpy.typing as npt
from threadpoolctl import threadpool_limits

from thermocal.errors import ConditioningWarning, ThermocalInputError
from thermocal.stability import allan, family
from thermocal.stability import deviations as dv
from thermocal.stability import edf as ed

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
Progress = Callable[[float], None]

WINDOW: Final = 1 << 22
"""Values per window read from a store (32 MiB of float64), a multiple of every block size
of the in-memory kernels so that their blocks fall on the same indices."""

IN_MEMORY_LEVEL: Final = 1 << 24
"""An octave level of at most this many block sums is read whole for the noise
identification (128 MiB); a longer one is identified from its lag sums and windows."""


class BlockSource(Protocol):
    """A read-only sequence of float64 values read by index range."""

    size: int

    def read(self, start: int, stop: int) -> FloatArray:
        """Values ``start`` … ``stop − 1`` as a new float64 array.

        Parameters
        ----------
        start, stop : int
            First index and one past the last [samples].

        Returns
        -------
        numpy.ndarray
        """
        ...


class BlockWriter(Protocol):
    """A store being filled in order, one window after the other."""

    def write(self, values: FloatArray) -> None:
        """Append ``values``.

        Parameters
        ----------
        values : numpy.ndarray
            The next window, in order.
        """
        ...

    def finish(self) -> BlockSource:
        """Close the store and return it for reading."""
        ...


class BlockStore(Protocol):
    """Where the intermediate series are kept (temporary files, or memory in tests)."""

    def create(self, name: str) -> BlockWriter:
        """A new empty store named ``name`` (unique within the analysis).

        Parameters
        ----------
        name : str
            The store's name.

        Returns
        -------
        BlockWriter
        """
        ...

    def remove(self, source: BlockSource) -> None:
        """Release a store no longer needed.

        Parameters
        ----------
        source : BlockSource
            The finished store.
        """
        ...


class ArrayStore:
    """A :class:`BlockStore` in memory (tests and small records): each store a list of
    windows, concatenated when finished."""

    def create(self, name: str) -> BlockWriter:
        """A new store.

        Parameters
        ----------
        name : str
            Unused (the store lives in memory).

        Returns
        -------
        BlockWriter
        """
        return _ArrayWriter()

    def remove(self, source: BlockSource) -> None:
        """Nothing to release.

        Parameters
        ----------
        source : BlockSource
            The finished store.
        """


@dataclass
class _ArrayWriter:
    parts: list[FloatArray] = field(default_factory=list)

    def write(self, values: FloatArray) -> None:
        self.parts.append(np.array(values, dtype=np.float64))

    def finish(self) -> BlockSource:
        return ArraySource(np.concatenate(self.parts) if self.parts else np.zeros(0))


class ArraySource:
    """A :class:`BlockSource` over an array already in memory.

    Parameters
    ----------
    values : numpy.ndarray
        The values (float64, one-dimensional).
    """

    def __init__(self, values: FloatArray) -> None:
        self.values = np.asarray(values, dtype=np.float64)
        self.size = int(self.values.size)

    def read(self, start: int, stop: int) -> FloatArray:
        """A copy of ``values[start:stop]``.

        Parameters
        ----------
        start, stop : int
            First index and one past the last [samples].

        Returns
        -------
        numpy.ndarray
        """
        return np.array(self.values[start:stop], dtype=np.float64)


class _Stopped(Exception):
    """A worker thread stopped by an interruption of the caller."""


class _Work:
    """Progress in fractions of the whole analysis, from passes weighted by their length."""

    def __init__(self, progress: Progress | None, total: float) -> None:
        self.progress, self.total, self.done = progress, max(total, 1.0), 0.0
        self.stop = threading.Event()
        """Set when the caller is interrupted: the worker threads end at their next window."""

    def check(self) -> None:
        """Raise in a worker thread once the analysis is stopped."""
        if self.stop.is_set():
            raise _Stopped

    def pooled(self, calls: list[Callable[[], Any]]) -> list[Any]:
        """Run ``calls`` on two threads; an interruption (Ctrl-C) stops them both."""
        with ThreadPoolExecutor(max_workers=2) as pool:
            jobs = [pool.submit(c) for c in calls]
            try:
                return [j.result() for j in jobs]
            except BaseException:
                self.stop.set()
                raise

    def advance(self, amount: float) -> None:
        if self.progress is not None and amount > 0:
            self.progress(amount / self.total)
        self.done += amount

    def finish(self) -> None:
        """The rest of the estimate, at the end (the passes' lengths were estimated)."""
        if self.done < self.total:
            self.advance(self.total - self.done)


@dataclass(frozen=True)
class StreamedRecord:
    """A record of rate samples in a store, with its sample interval and stretches.

    Attributes
    ----------
    rate : BlockSource
        Rate samples in the data's own unit [unit].
    tau0_s : float
        Sample interval τ0 [s].
    segments : tuple of slice
        Gap-free index ranges (each processed alone and pooled, as in memory).
    """

    rate: BlockSource
    tau0_s: float
    segments: tuple[slice, ...]


def exact_sum(
    src: BlockSource,
    start: int,
    stop: int,
    transform: Callable[[FloatArray], FloatArray] | None = None,
) -> float:
    """Σ values[start:stop] (of ``transform(values)`` when given) with numpy's own rounding:
    its pairwise summation splits n into halves rounded down to a multiple of 8 until a part
    fits a window, and each part is summed by numpy (the same tree, so the same bits as
    ``values[start:stop].sum()`` on the whole array).

    Parameters
    ----------
    src : BlockSource
        The values.
    start, stop : int
        The index range.
    transform : callable, optional
        Applied to each part before it is summed (elementwise).

    Returns
    -------
    float
        The sum.
    """
    n = stop - start
    if n <= WINDOW:
        part = src.read(start, stop)
        return float(np.add.reduce(transform(part) if transform is not None else part))
    half = n // 2
    half -= half % 8
    return exact_sum(src, start, start + half, transform) + exact_sum(
        src, start + half, stop, transform
    )


def _phase_store(
    src: BlockSource, sl: slice, mean: float, store: BlockStore, work: _Work
) -> BlockSource:
    """x_1 … x_n = cumsum(y − ȳ) of one stretch (:func:`thermocal.stability.allan._phase`),
    window by window with the running sum carried: the same additions in the same order."""
    out = store.create(f"phase-{sl.start}")
    carry = 0.0
    for a in range(sl.start, sl.stop, WINDOW):
        x = src.read(a, min(a + WINDOW, sl.stop))
        np.subtract(x, mean, out=x)
        if a > sl.start:
            x[0] = carry + x[0]
        np.cumsum(x, out=x)
        carry = float(x[-1])
        out.write(x)
        work.advance(x.size)
    return out.finish()


def _second_difference_sum(x1: BlockSource, mm: int, work: _Work) -> float:
    """S(m) = Σ_k (x_{k+2m} − 2x_{k+m} + x_k)² over a phase store (x_0 = 0 not stored),
    in the blocks and with the arithmetic of
    :func:`thermocal.stability.allan.second_difference_sums`: for m up to
    :data:`thermocal.stability.allan._SHORT_M` the difference of first differences
    (:func:`thermocal.stability.allan._block_sums`), else three taps; the block sums added
    in block order (the same bits as in memory)."""
    if mm > allan._SHORT_M:
        return _long_sum(x1, mm, work)
    chunk = allan._CHUNK
    n_terms = x1.size + 1 - 2 * mm
    size = min(chunk, max(n_terms, 1))
    diff = np.empty(size + mm, dtype=np.float64)
    out = np.empty(size, dtype=np.float64)
    total = 0.0
    for wa in range(0, n_terms, WINDOW):
        work.check()
        wb = min(wa + WINDOW, n_terms)
        lo_w = max(wa, 1) - 1  # x1 index of the first x_k read (k ≥ 1)
        span = x1.read(lo_w, wb - 1 + 2 * mm)
        for a in range(wa, wb, chunk):
            b = min(a + chunk, wb)
            d, t = diff[: b - a + mm], out[: b - a]
            lo = max(a, 1)
            i0, i1 = lo - 1 - lo_w, b + mm - 1 - lo_w
            np.subtract(span[i0 + mm : i1 + mm], span[i0:i1], out=d[lo - a :])
            if a == 0:  # d_0 = x_m − x_0, x_0 = 0
                d[0] = float(span[mm - 1]) - 0.0
            np.subtract(d[mm:], d[: b - a], out=t)
            total += float(np.dot(t, t))
        work.advance(3 * (wb - wa))
    return total


def _long_sum(x1: BlockSource, mm: int, work: _Work) -> float:
    """:func:`_second_difference_sum` for m beyond :data:`thermocal.stability.allan.
    _SHORT_M`: ``x_{k+2m} + x_k − 2·x_{k+m}`` (:func:`thermocal.stability.allan._long_block`)."""
    chunk = allan._CHUNK
    n_terms = x1.size + 1 - 2 * mm
    size = min(chunk, max(n_terms, 1))
    buf = np.empty(size, dtype=np.float64)
    buf2 = np.empty(size, dtype=np.float64)
    total = 0.0
    for wa in range(0, n_terms, WINDOW):
        work.check()
        wb = min(wa + WINDOW, n_terms)
        lo_w = max(wa, 1) - 1  # x1 index of the first x_k read (k ≥ 1)
        if 2 * mm <= WINDOW:  # one span holds the three taps
            span = x1.read(lo_w, wb - 1 + 2 * mm)
            xs = [span[s * mm :] for s in (0, 1, 2)]
        else:
            xs = [x1.read(lo_w + s * mm, wb - 1 + s * mm) for s in (0, 1, 2)]
        for a in range(wa, wb, chunk):
            b = min(a + chunk, wb)
            t, t2 = buf[: b - a], buf2[: b - a]
            lo = max(a, 1)
            r = slice(lo - a, b - a)
            i0, i1 = lo - 1 - lo_w, b - 1 - lo_w
            np.add(xs[2][i0:i1], xs[0][i0:i1], out=t[r])
            np.multiply(xs[1][i0:i1], 2.0, out=t2[r])
            if a == 0:  # k = 0: x_{2m} + x_0 − 2 x_m, x_0 = 0
                t[0] = float(x1.read(2 * mm - 1, 2 * mm)[0]) + 0.0
                t2[0] = float(x1.read(mm - 1, mm)[0]) * 2.0
            np.subtract(t, t2, out=t)
            total += float(np.dot(t, t))
        work.advance(3 * (wb - wa))
    return total


@dataclass(frozen=True)
class _Level:
    """One octave level of the longest stretch: its series in a store and its lag sums."""

    m: int
    z: BlockSource
    lag: ed.LagSums


def _level_sums(
    z: BlockSource,
    offset: float,
    lo: int,
    hi: int,
    nxt: BlockWriter | None,
    work: _Work | None = None,
) -> tuple[float, float, float, float]:
    """Σ c, Σ c², Σ c_k c_{k+1}, Σ k c_k over the terms starting in [lo, hi) (c = z −
    offset) by :func:`thermocal.stability.deviations._level_range` on windows, writing the
    next level's pairwise sums."""
    s1 = s2 = sl = sk = 0.0
    n = z.size
    for wa in range(lo, hi, WINDOW):
        if work is not None:
            work.check()
        wb = min(wa + WINDOW, hi)
        zw = z.read(wa, min(wb + 2, n))
        half = np.empty((wb - wa) // 2) if nxt is not None else None
        if half is not None and wa // 2 + half.size > n // 2:
            half = half[: n // 2 - wa // 2]
        p1, p2, pl, pk, _q1, _q2 = dv._level_range(zw, offset, 0, wb - wa, False, False, half)
        s1, s2, sl = s1 + p1, s2 + p2, sl + pl
        sk += pk + wa * p1  # Σ (k + wa) c_k
        if nxt is not None and half is not None:
            nxt.write(half)
    return s1, s2, sl, sk


def _level(
    z: BlockSource, offset: float, m: int, store: BlockStore | None, work: _Work
) -> tuple[_Level, BlockSource | None]:
    """Level m's lag sums (:func:`thermocal.stability.deviations._level_pass`: the halves of
    a long level on two threads, as there) and the next level (in ``store``; None: not
    asked)."""
    n = z.size
    nxt: BlockSource | None = None
    if n >= dv._SPLIT and dv._WORKERS > 1:
        half = (n // 2) & ~1
        outs = [store.create(f"level-{2 * m}-{i}") if store else None for i in (0, 1)]
        parts = work.pooled(
            [
                functools.partial(_level_sums, z, offset, lo, hi, out, work)
                for (lo, hi), out in zip(((0, half), (half, n)), outs, strict=True)
            ]
        )
        s1, s2, sl, sk = (p + q for p, q in zip(*parts, strict=True))
        if store is not None:
            nxt = _Concat([o.finish() for o in outs if o is not None])
    else:
        out = store.create(f"level-{2 * m}") if store else None
        s1, s2, sl, sk = _level_sums(z, offset, 0, n, out)
        nxt = out.finish() if out is not None else None
    work.advance(n)
    delta = s1 / n
    first = float(z.read(0, 1)[0]) - offset - delta
    last = float(z.read(n - 1, n)[0]) - offset - delta
    lag = ed.LagSums(
        n,
        s2 - s1 * delta,
        sk - delta * n * (n - 1) / 2.0,
        sl - delta * (2.0 * s1 - (first + delta) - (last + delta)) + (n - 1) * delta * delta,
        first,
        last,
    )
    return _Level(m, z, lag), nxt


class _Concat:
    """Sources one after the other, read as one."""

    def __init__(self, parts: list[BlockSource]) -> None:
        self.parts = parts
        self.starts = [0]
        for p in parts:
            self.starts.append(self.starts[-1] + p.size)
        self.size = self.starts[-1]

    def read(self, start: int, stop: int) -> FloatArray:
        stop = min(stop, self.size)
        got = []
        for p, a in zip(self.parts, self.starts, strict=False):
            lo, hi = max(start - a, 0), min(stop - a, p.size)
            if hi > lo:
                got.append(p.read(lo, hi))
        if len(got) == 1:
            return got[0]
        return np.concatenate(got) if got else np.zeros(0)


def _release(store: BlockStore, src: BlockSource) -> None:
    """Release a store, or each part of a :class:`_Concat`."""
    for part in src.parts if isinstance(src, _Concat) else [src]:
        store.remove(part)


def _levels(
    y: BlockSource, sl: slice, mean: float, m_max: int, store: BlockStore, work: _Work
) -> list[_Level]:
    """The octave levels m = 1, 2, 4 … ≤ ``m_max`` of stretch ``sl``
    (:func:`thermocal.stability.deviations.octave_levels`), each above 0 in a store."""
    z: BlockSource = _Slice(y, sl.start, sl.stop)
    out: list[_Level] = []
    offset, m = float(mean), 1
    while z.size >= 1 and m <= m_max:
        more = 2 * m <= m_max and z.size >= 2
        lv, nxt = _level(z, offset, m, store if more else None, work)
        out.append(lv)
        if nxt is None:
            break
        z, offset, m = nxt, 0.0, 2 * m
    return out


class _Slice:
    """A window of another source."""

    def __init__(self, src: BlockSource, start: int, stop: int) -> None:
        self.src, self.start, self.size = src, start, stop - start

    def read(self, start: int, stop: int) -> FloatArray:
        return self.src.read(self.start + start, self.start + stop)


def _lag1_of_difference(z: BlockSource, d: int) -> float:
    """:func:`thermocal.stability.edf._lag1_of_difference` on a store (the same blocks)."""
    n = z.size - d
    blk = ed._DIFF_BLOCK
    if n <= blk:
        return float(ed.lag1_autocorrelation(np.diff(z.read(0, z.size), d)))
    total = 0.0
    for a in range(0, n, blk):
        total += float(np.diff(z.read(a, min(a + blk, n) + d), d).sum())
    mean = total / n
    den = num = 0.0
    prev: float | None = None
    for a in range(0, n, blk):
        c = np.diff(z.read(a, min(a + blk, n) + d), d)
        c -= mean
        den += float(c @ c)
        num += float(c[:-1] @ c[1:])
        if prev is not None:
            num += prev * float(c[0])
        prev = float(c[-1])
    return num / den if den > 0 else 0.0


def _identify_level(lv: _Level, dmax: int) -> ed.NoiseId:
    """:func:`thermocal.stability.edf.identify_rate_averages` with thermocal's rules on a
    level: read whole when short, else from its lag sums and windowed differences."""
    if lv.z.size <= IN_MEMORY_LEVEL:
        return ed.identify_rate_averages(lv.z.read(0, lv.z.size), dmax=dmax, sums=lv.lag)
    r1 = ed._lag1_from_sums(lv.lag)
    if r1 is None:  # the line carries nearly all: no digits left in the sums
        raise ThermocalInputError(
            f"the record's {lv.m}-sample averages are almost a straight line "
            f"({lv.z.size} of them): too long to identify their noise window by window; "
            "remove the drift or cut the record"
        )
    d, dm = 0, dmax - 1
    while True:  # :func:`thermocal.stability.edf._lag1_differenced` with thermocal's rules
        rho = r1 / (1.0 + r1) if r1 > -1.0 else 0.0
        if rho < 0.25 or d >= dm:
            a = -round(2.0 * rho) - 2 * d
            return ed.NoiseId(int(a), -2.0 * (rho + d), "lag1", d)
        d += 1
        r1 = _lag1_of_difference(lv.z, d)


class _StreamedIdentity:
    """What :func:`thermocal.stability.family._noise_exponents` asks of a record (its
    stretches' sizes, the longest, :meth:`identify`) for octave factors of rate data."""

    def __init__(self, sizes: list[int], longest: int, levels: list[_Level]) -> None:
        self.sizes, self.longest = sizes, longest
        self.by_m = {lv.m: lv for lv in levels}

    def identify(self, m: int, dmax: int, rules: Any = ed.THERMOCAL_RULES) -> ed.NoiseId:
        if m in self.by_m:
            nid = _identify_level(self.by_m[m], dmax)
            if nid.method == "b1" and nid.alpha == 2:
                raise ThermocalInputError(
                    f"at τ = {m} samples the record reads as phase noise, which a streamed "
                    "analysis cannot tell apart (white or flicker PM); cut the record so "
                    "that it fits in memory"
                )
            return nid
        return ed.identify_rate_averages(np.zeros(0), dmax=dmax)


def _check_octave(m: IntArray) -> None:
    """The streamed analysis serves octave factors only (the octave levels)."""
    if not (m.size and np.all(m & (m - 1) == 0)):
        raise ThermocalInputError.naming(
            "a record analysed window by window takes the octave τ set only; give {taus} "
            "octave, or cut the record so that it fits in memory",
            "taus",
        )


def streamed_adev(
    record: StreamedRecord,
    taus: Any = "octave",
    *,
    unit: str = "deg/h",
    confidence: float = ed.ONE_SIGMA_CONFIDENCE,
    store: BlockStore | None = None,
    progress: Progress | None = None,
) -> allan.AllanResult:
    r"""Overlapping Allan deviation of a record held in a store, with the intervals of
    :func:`thermocal.stability.allan.overlapping_adev` (Greenhall's EDF per stretch, α
    identified per τ on the longest stretch's octave averages).

    Parameters
    ----------
    record : StreamedRecord
        Rate samples [unit] in a store, τ0 [s] and the gap-free stretches.
    taus : str or sequence of float, optional
        ``"octave"`` (default) or octave τ [s] (powers of two of τ0).
    unit : str, optional
        Unit of the rate (reported).
    confidence : float, optional
        Confidence level of the intervals (default ±1σ).
    store : BlockStore, optional
        Where the phase and the octave levels are kept (default :class:`ArrayStore`).
    progress : callable, optional
        Called with each fraction of the work done (they add up to 1).

    Returns
    -------
    AllanResult
        τ, the deviation, its interval, EDF and noise exponent per τ.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A τ set other than octave, too few samples, or a stretch whose noise cannot be
        identified window by window.

    Notes
    -----
    NIST SP 1065 eq. 11 on the phase :math:`x_k = \sum_{i<k} (y_i - \bar y)` of each
    stretch, pooled: :math:`\sigma^2(\tau) = \sum_s S_s / (2 m^2 \sum_s L_s)` with

    .. math:: S = \sum_{k=0}^{N-2m-1} (x_{k+2m} - 2x_{k+m} + x_k)^2

    References
    ----------
    - NIST SP 1065 (Riley 2008), eq. 11.
    - Greenhall & Riley 2003; Riley & Greenhall 2004.

    Examples
    --------
    >>> y = np.random.default_rng(0).normal(0.0, 3.0, 20_000)
    >>> rec = StreamedRecord(ArraySource(y), 0.1, (slice(0, y.size),))
    >>> r = streamed_adev(rec, [0.1, 0.8])
    >>> [round(float(v), 2) for v in r.adev]
    [2.99, 1.05]
    """
    ed.check_confidence(confidence)
    store = store if store is not None else ArrayStore()
    slices = [sl for sl in record.segments if sl.stop > sl.start]
    longest_n = max(sl.stop - sl.start for sl in slices)
    m = allan.averaging_factors(taus, record.tau0_s, longest_n)
    _check_octave(m)
    kept = [sl for sl in slices if sl.stop - sl.start >= 2]  # ≥ 3 phase points
    if not kept:
        raise ThermocalInputError("stability analysis needs at least 3 contiguous points")
    n_all = sum(sl.stop - sl.start for sl in slices)
    work = _Work(progress, n_all * (2.0 + 3.0 * m.size) + 2.0 * longest_n)
    means = [_segment_mean(record.rate, sl, work) for sl in slices]
    sizes = [sl.stop - sl.start + 1 for sl in kept]
    longest = sizes.index(max(sizes))
    i_long = slices.index(kept[longest])
    levels = _levels(record.rate, kept[longest], means[i_long], int(m.max()), store, work)
    try:
        ident = _StreamedIdentity(sizes, longest, levels)
        alphas, methods = family._noise_exponents("oadev", m, ident, None, {})  # type: ignore[arg-type]
    finally:
        for lv in levels[1:]:
            _release(store, lv.z)
    edf = family._pooled_edf("oadev", m, alphas, sizes)
    sums, n_terms, used, segs = _pooled_sums(record.rate, slices, means, m, store, work)
    work.finish()
    avar = sums / (2.0 * m.astype(np.float64) ** 2 * n_terms)
    adev = np.sqrt(avar)
    tau = np.asarray(m * float(record.tau0_s), dtype=np.float64)
    lo, hi = ed.confidence_interval(adev, edf, confidence)
    return allan.AllanResult(
        tau, m, adev, np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64),
        n_terms, edf, alphas, unit, float(confidence), float(record.tau0_s), used, segs,
        methods,
    )  # fmt: skip


def _segment_mean(src: BlockSource, sl: slice, work: _Work) -> float:
    """A stretch's mean sample."""
    n = sl.stop - sl.start
    total = exact_sum(src, sl.start, sl.stop)
    work.advance(n)
    return float(total / n)


def _pooled_sums(
    src: BlockSource,
    slices: Sequence[slice],
    means: Sequence[float],
    m: IntArray,
    store: BlockStore,
    work: _Work,
) -> tuple[FloatArray, IntArray, int, int]:
    """:func:`thermocal.stability.allan._pooled_sums` with each stretch's phase in a store."""
    sums = np.zeros(m.size)
    n_terms = np.zeros(m.size, dtype=np.int64)
    used = segs = 0
    for sl, mean in zip(slices, means, strict=True):
        n_phase = sl.stop - sl.start + 1
        ok = (n_phase - 2 * m) >= 2
        if not np.any(ok):
            continue
        x1 = _phase_store(src, sl, mean, store, work)
        ms = [int(mm) for mm in m[ok].tolist()]
        try:  # the factors shared by two threads, as in memory (numpy releases the GIL)
            with threadpool_limits(limits=1, user_api="blas"):
                if allan._WORKERS > 1 and len(ms) > 1:
                    vals = work.pooled(
                        [functools.partial(_second_difference_sum, x1, mm, work) for mm in ms]
                    )
                else:
                    vals = [_second_difference_sum(x1, mm, work) for mm in ms]
        finally:
            store.remove(x1)
        sums[ok] += np.asarray(vals)
        n_terms[ok] += n_phase - 2 * m[ok]
        used += sl.stop - sl.start
        segs += 1
    return sums, n_terms, used, segs


@dataclass
class ValueSummary:
    """What the checks of a channel need of its samples, gathered window by window: the
    count, the extremes, the first :data:`thermocal.stability.analysis._LEVEL_PROBE` samples'
    distinct values, the distinct values of the whole (while few), and the evenly strided
    probe of :func:`thermocal.stability.noise_model.lattice_step`.

    Parameters
    ----------
    n_total : int
        Samples the record will hold (the probe's stride is set from it).
    """

    n_total: int
    n: int = 0
    lo: float = math.inf
    hi: float = -math.inf
    head: list[FloatArray] = field(default_factory=list)
    levels: set[float] | None = field(default_factory=set)
    probe: list[FloatArray] = field(default_factory=list)

    def add(self, v: FloatArray) -> None:
        """Take the next window of (finite) samples.

        Parameters
        ----------
        v : numpy.ndarray
            The window [the data's unit].
        """
        from thermocal.stability.analysis import _LEVEL_PROBE, FEW_LEVELS
        from thermocal.stability.noise_model import _QUANT_PROBE

        if not v.size:
            return
        self.lo, self.hi = min(self.lo, float(v.min())), max(self.hi, float(v.max()))
        taken = sum(h.size for h in self.head)
        if taken < _LEVEL_PROBE:
            self.head.append(v[: _LEVEL_PROBE - taken].copy())
            if np.unique(np.concatenate(self.head)).size > FEW_LEVELS:
                self.levels = None  # many levels already: the whole's are not counted
        if self.levels is not None:
            self.levels.update(np.unique(v).tolist())
            if len(self.levels) > FEW_LEVELS:
                self.levels = None
        stride = max(1, self.n_total // _QUANT_PROBE)
        first = (-self.n) % stride
        self.probe.append(v[first::stride].copy())
        self.n += int(v.size)

    def check_not_stuck(self, name: str, where: str) -> None:
        """:func:`thermocal.stability.analysis.check_not_stuck` on the whole record.

        Parameters
        ----------
        name : str
            The signal's name.
        where : str
            The file, for the message.
        """
        from thermocal.stability import analysis as an

        if self.n < an.STUCK_MIN_SAMPLES:
            return
        if self.lo == self.hi:
            raise ThermocalInputError.naming(
                f"{where}: the column {name!r} is constant ({self.lo:.6g} in all {self.n} "
                f"samples): a stuck or flat-lined sensor {an.STUCK_ALLAN}; name another "
                "column with {signal}, or check the sensor",
                "signal",
            )
        probe = np.unique(np.concatenate(self.head))
        if probe.size > an.FEW_LEVELS or self.levels is None:
            return
        levels = sorted(self.levels)
        warnings.warn(
            f"{where}: the column {name!r} takes only {len(levels)} distinct values in "
            f"{self.n} samples ({', '.join(f'{x:.6g}' for x in levels)}): a stuck or "
            "flat-lined sensor, or an output step far coarser than its noise: the deviations "
            "describe those steps, not the sensor's noise",
            ConditioningWarning,
            stacklevel=2,
        )


def lattice_step(src: BlockSource, summary: ValueSummary) -> tuple[float, float, int, int] | None:
    """:func:`thermocal.stability.noise_model.lattice_step` of the samples in ``src``
    (finite, as the streamed record holds them) from the strided probe gathered in
    ``summary`` and two passes over the store.

    Parameters
    ----------
    src : BlockSource
        The samples [unit].
    summary : ValueSummary
        Their summary (the probe).

    Returns
    -------
    tuple of (float, float, int, int) or None
        (step [unit], offset [unit], levels, samples), or None where they lie on no lattice.
    """
    from thermocal.stability import noise_model as nm

    rtol = nm.QUANT_LEVEL_TOL
    n = src.size
    if n < nm.QUANT_MIN_LEVELS * nm.QUANT_MIN_REPEAT:
        return None
    probe = np.concatenate(summary.probe)
    u, c = np.unique(probe, return_counts=True)
    if u.size < nm.QUANT_MIN_LEVELS or u.size * nm.QUANT_MIN_REPEAT > probe.size:
        return None
    guess = nm._level_lattice(u, c.astype(np.float64), rtol)
    if guess is None:
        return None
    step, origin = guess
    top = max(abs(float(u[0])), abs(float(u[-1])))
    if step <= nm.QUANT_MIN_ULPS * nm._storage_ulp(probe, top):
        return None
    off, lo_k, hi_k = 0, math.inf, -math.inf
    for a in range(0, n, WINDOW):
        q = (src.read(a, a + WINDOW) - origin) / step
        kk = np.rint(q)
        on = np.abs(q - kk) <= rtol
        off += int(on.size - np.count_nonzero(on))
        if on.any():
            lo_k, hi_k = min(lo_k, float(kk[on].min())), max(hi_k, float(kk[on].max()))
    if off > nm.QUANT_MAX_OFF * n or not math.isfinite(lo_k):
        return None
    span = int(hi_k - lo_k) + 1
    if span > 1 << 24:
        return None
    seen = np.zeros(span, dtype=bool)
    for a in range(0, n, WINDOW):
        q = (src.read(a, a + WINDOW) - origin) / step
        kk = np.rint(q)
        seen[(kk[np.abs(q - kk) <= rtol] - lo_k).astype(np.int64)] = True
    levels = int(np.count_nonzero(seen))
    if levels < nm.QUANT_MIN_LEVELS or levels * nm.QUANT_MIN_REPEAT > n:
        return None
    return step, origin + lo_k * step, levels, n


def streamed_channel(
    record: StreamedRecord,
    summary: ValueSummary,
    name: str,
    unit: str,
    *,
    taus: Any = "octave",
    confidence: float = ed.ONE_SIGMA_CONFIDENCE,
    where: str = "",
    store: BlockStore | None = None,
    progress: Progress | None = None,
) -> Any:
    """One channel's analysis as ``thermocal allan`` gives it in memory
    (:func:`thermocal.stability.analysis.allan_analysis` without a dynamic ADEV): the
    overlapping ADEV (:func:`streamed_adev`), the noise terms, the output quantization and
    the periodic terms of the longest stretch's first samples.

    Parameters
    ----------
    record : StreamedRecord
        Rate samples [unit] in a store, τ0 [s] and the stretches.
    summary : ValueSummary
        The samples' summary (gathered while they were stored).
    name, unit : str
        The channel and its unit.
    taus, confidence : str or sequence of float, float, optional
        As :func:`streamed_adev`.
    where : str, optional
        The file, named in messages.
    store : BlockStore, optional
        Where the intermediate series are kept.
    progress : callable, optional
        Called with each fraction of the work done.

    Returns
    -------
    thermocal.stability.analysis.AllanChannel
        The ADEV, the noise terms and the quantization.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A constant column, or what :func:`streamed_adev` refuses.
    """
    from thermocal.stability import noise_model as nm
    from thermocal.stability.analysis import AllanChannel
    from thermocal.stability.periodic import _MAX_SAMPLES, periodic_terms

    summary.check_not_stuck(name, where)
    lattice = lattice_step(record.rate, summary)
    longest = max(record.segments, key=lambda sl: sl.stop - sl.start)
    head = record.rate.read(longest.start, min(longest.stop, longest.start + _MAX_SAMPLES))
    found = periodic_terms(head, record.tau0_s, unit)
    del head
    res = streamed_adev(
        record, taus, unit=unit, confidence=confidence, store=store, progress=progress
    )
    noise = allan.noise_terms(res, periodic=found)
    quant = nm.quantization_from_lattice(lattice, record.tau0_s, unit, noise)
    noise = nm.annotate_quantization(noise, quant)
    noise = allan.annotate_periodic(noise, res, found)
    if noise.quality is not None and noise.quality.quality == "poor":
        warnings.warn(f"{where}: {noise.quality.reason}", ConditioningWarning, stacklevel=1)
    return AllanChannel(res, noise, quantization=quant)


__all__ = [
    "IN_MEMORY_LEVEL",
    "WINDOW",
    "ArraySource",
    "ArrayStore",
    "BlockSource",
    "BlockStore",
    "BlockWriter",
    "StreamedRecord",
    "ValueSummary",
    "exact_sum",
    "lattice_step",
    "streamed_adev",
    "streamed_channel",
]
