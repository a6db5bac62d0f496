r"""The total family's sums (MTOT, TTOT, HTOT) in O(N log m) per averaging factor.

NIST SP 1065 eq. 27 (Riley 2008, the modified total variance): for each of the
N − 3m + 1 subsequences ``w_i = z_{n+i}`` (i < 3m) of a series ``z`` (phase for MTOT and
TTOT, the rate for HTOT, eq. 29), the linear trend fitted by its half means is removed, the
result is extended by even reflection at both ends to 9m points ``ξ_p`` and the 6m modified
second differences of m-point averages are squared and averaged:

.. math::

    T(m) = \sum_{n=0}^{N-3m} \frac{1}{6m} \sum_{j=0}^{6m-1} v_j(n)^2, \qquad
    v_j = \frac{1}{m} \sum_{t=0}^{3m-1} g_t\, \xi_{j+t},

with ``g_t`` = 1, −2, 1 on ``t`` in [0, m), [m, 2m), [2m, 3m).  A direct evaluation costs
O(m) per subsequence, O(N·m) per factor; :func:`tot_sum` costs O(N log m) per factor, as
the notes below derive.

Notes
-----
*Trend.*  The half-mean slope ``s(n)`` of a line is the line's slope, so ``v`` is unchanged
by a line added to ``w``, and

.. math::

    m v_j = a_j - s(n)\, b_j, \qquad
    \sum_j (m v_j)^2 = \sum_j a_j^2 - 2 s(n) \sum_i c_i w_i + s(n)^2 \sum_j b_j^2

where ``a_j`` is the modified second difference of the reflected ``w`` (not detrended),
``b_j`` that of the reflected ramp ``w_i = i`` (fixed for a given m) and ``c`` the adjoint of
the reflect-and-difference map applied to ``b`` (fold of the correlation of ``b`` with ``g``),
so ``Σ_i c_i z_{n+i}`` is one correlation over the series (FFT, O(N log m)).

*Squares.*  With ``P(k) = Σ_{i<k} z_i`` every sum of ``w`` over an interval is a difference
of two ``P``; the reflected window's intervals have end points ``n + κ + σ j`` with
σ ∈ {−1, 0, 1}, and for ``j`` in one of the six ranges [km, (k+1)m) the list of
(coefficient, κ, σ) is fixed.  Grouping the terms by σ,

.. math::

    a_j(n) = A(n + j) + B(n - j) + C(n),

and :math:`\sum_n \sum_j (A + B + C)^2` needs only per-index weights of ``A²``, ``B²``,
``C²``, running sums of ``A`` and ``B`` (for the ``AC``, ``BC`` products) and running sums of
``B`` with stride 2 (``Σ_j A(r) B(r − 2j)`` over the ``j`` with ``n = r − j`` in range):
O(N) per range.

*Digits.*  ``P`` of a random-walk phase grows as N^{3/2} and the six products cancel to the
small ``Σ a²``: the subsequences are taken in rows of a few 3m spans, and each row's ``z``
and ``P`` have their own line removed first (``a`` changes, ``v`` does not, and a line added to
``P`` cancels in ``a`` because the terms' coefficients and their first moments sum to zero),
so the cancellation is bounded by the row's length over m, not by N.

References
----------
NIST SP 1065, W. J. Riley, *Handbook of Frequency Stability Analysis* (2008), eqs. 27–29.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Final

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

_SPANS: Final = 3
"""Subsequences per row, in units of the subsequence length 3m (rows of 4 spans of data)."""

_ELEMENTS: Final = 1 << 21
"""Data elements per chunk of rows (bounds the temporaries)."""

_Terms = list[tuple[float, int, int]]

DIRECT_UP_TO: Final = 2
"""Largest averaging factor whose sum is taken subsequence by subsequence (:func:`_tot_direct`,
O(N·m), faster than the rows' set-up at these m and the same numbers as ever)."""

_BLOCK: Final = 1 << 22
"""Elements per block of :func:`_tot_direct`."""

_WORKERS: Final = 2
"""Factors computed at once (threads: numpy releases the interpreter on the rows' arrays)."""

_EXECUTOR: list[ThreadPoolExecutor] = []
_CACHE: OrderedDict[tuple[bytes, int], tuple[float, int]] = OrderedDict()
_CACHE_SIZE: Final = 256
_LOCK = threading.Lock()
_REPORT: ContextVar[Callable[[float], None] | None] = ContextVar("total_report", default=None)


class _Stopped(Exception):
    """A factor abandoned because another one raised (an interrupt)."""


@contextmanager
def reporting(advance: Callable[[float], None]) -> Iterator[None]:
    """Report the total family's progress to ``advance`` while the block runs.

    Parameters
    ----------
    advance : callable
        Called with the estimated operations done since the last call (the unit of
        :func:`thermocal.stability.deviations.work`), from any thread.

    Returns
    -------
    contextmanager
        Active for the ``with`` block.
    """
    token = _REPORT.set(advance)
    try:
        yield
    finally:
        _REPORT.reset(token)


def cost(n: int, m: int) -> float:
    """Relative cost of one factor: ``N − 3m + 1`` subsequences, of 9m points each when taken
    directly (m ≤ :data:`DIRECT_UP_TO`), else about N points in rows.

    Parameters
    ----------
    n : int
        Points of the series N.
    m : int
        Averaging factor [samples].

    Returns
    -------
    float
        Estimated operations [1].
    """
    subs = max(n - 3 * m + 1, 0)
    if subs == 0:
        return 0.0
    return 90.0 * m * subs if m <= DIRECT_UP_TO else PER_POINT * float(n)


PER_POINT: Final = 400.0
"""Operations per point and factor of :func:`tot_sum` (rows with a third more points, six
ranges of j, each a dozen passes; one FFT correlation)."""


def _tot_direct(z: FloatArray, m: int) -> tuple[float, int]:
    """Σ_n (1/6m) Σ_{j<6m} ((S1 − 2S2 + S3)/m)² over the N − 3m + 1 subsequences of 3m
    points of ``z``, each with its half-mean linear trend removed and extended by even
    reflection to 9m points (S1, S2, S3 the sums of consecutive m-point blocks from j)."""
    n_sub = z.size - 3 * m + 1
    if n_sub < 1:
        return 0.0, 0
    w = np.lib.stride_tricks.sliding_window_view(z, 3 * m)
    h1, h2 = (3 * m) // 2, (3 * m + 1) // 2
    idx = np.arange(3 * m, dtype=np.float64)
    rows = max(1, _BLOCK // (9 * m))
    total = 0.0
    for a in range(0, n_sub, rows):
        blk = w[a : a + rows]
        slope = (blk[:, h2:].mean(axis=1) - blk[:, :h1].mean(axis=1)) / h2
        x0 = blk - slope[:, None] * idx[None, :]
        x0 = x0 - x0.mean(axis=1, keepdims=True)
        flip = x0[:, ::-1]
        xs = np.concatenate([flip, x0, flip], axis=1)
        cs = np.zeros((xs.shape[0], xs.shape[1] + 1))
        np.cumsum(xs, axis=1, out=cs[:, 1:])
        s = cs[:, m:] - cs[:, :-m]  # block sums starting at j, j = 0 … 8m
        v = (s[:, : 6 * m] - 2.0 * s[:, m : 7 * m] + s[:, 2 * m : 8 * m]) / m
        total += float(np.einsum("ij,ij->", v, v)) / (6.0 * m)
    return total, n_sub


def _two_at_a_time(
    one: Callable[[int], tuple[float, int]], count: int, stop: threading.Event
) -> list[tuple[float, int]]:
    """``[one(i) for i in range(count)]`` on :data:`_WORKERS` threads, each taking the next
    index until none is left or ``stop`` is set (an interrupt or an error in the other)."""
    out: list[tuple[float, int]] = [(0.0, 0)] * count
    order = iter(range(count))

    def worker() -> None:
        try:
            while not stop.is_set():
                with _LOCK:
                    i = next(order, None)
                if i is None:
                    return
                out[i] = one(i)
        except BaseException:
            stop.set()  # the other worker stops at its next chunk
            raise

    if not _EXECUTOR:
        _EXECUTOR.append(ThreadPoolExecutor(_WORKERS, thread_name_prefix="thermocal-total"))
    futures = [_EXECUTOR[0].submit(worker) for _ in range(_WORKERS)]
    try:
        for f in futures:
            f.result()
    except BaseException:
        stop.set()  # an interrupt: the workers stop at their next chunk
        raise
    return out


def tot_sums(
    z: FloatArray, ms: list[int], progress: Callable[[float], None] | None = None
) -> list[tuple[float, int]]:
    r"""The total family's sums :math:`T(m)` of one series at several factors, two at a time.

    Factors up to :data:`DIRECT_UP_TO` are taken subsequence by subsequence, the others by
    :func:`tot_sum`.  A result already computed for the same series and factor (MTOT and TTOT
    share their sums) is reused.

    Parameters
    ----------
    z : numpy.ndarray
        Series of one gap-free stretch (phase for MTOT/TTOT, rate for HTOT) [unit].
    ms : list of int
        Averaging factors [samples].
    progress : callable, optional
        Called with the fraction done (0 to 1); else the callback of :func:`reporting`
        (if any) with the operations done.

    Returns
    -------
    list of tuple of (float, int)
        :math:`T(m)` [unit²] and the subsequence count per factor (see :func:`tot_sum`).

    References
    ----------
    NIST SP 1065 (Riley 2008), eqs. 27–29.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.cumsum(np.random.default_rng(0).standard_normal(300))
    >>> [(k, round(s / k, 3)) for s, k in tot_sums(x, [1, 4, 16])]
    [(298, 1.011), (289, 3.615), (253, 14.473)]
    """
    z = np.ascontiguousarray(z, dtype=np.float64)
    key = hashlib.sha1(z.tobytes()).digest() if ms else b""
    costs = [cost(z.size, mm) for mm in ms]
    whole = max(sum(costs), 1.0)
    report = _REPORT.get()
    stop = threading.Event()
    done = [0.0]

    def advance(ops: float) -> None:
        if stop.is_set():
            raise _Stopped
        with _LOCK:
            done[0] += ops
            frac = min(done[0] / whole, 1.0)
        if progress is not None:
            progress(frac)
        elif report is not None:
            report(ops)

    def one(i: int) -> tuple[float, int]:
        mm = ms[i]
        with _LOCK:
            hit = _CACHE.get((key, mm))
        whole_step = hit is not None or mm <= DIRECT_UP_TO or costs[i] == 0.0
        if hit is None:
            if mm <= DIRECT_UP_TO:
                hit = _tot_direct(z, mm)
            else:
                last = [0.0]

                def part(f: float) -> None:
                    advance((f - last[0]) * costs[i])
                    last[0] = f

                hit = _tot_sum(z, mm, part)
            with _LOCK:
                _CACHE[(key, mm)] = hit
                while len(_CACHE) > _CACHE_SIZE:
                    _CACHE.popitem(last=False)
        if whole_step:  # else the rows reported it as they went
            advance(costs[i])
        return hit

    if len(ms) <= 1:
        return [one(i) for i in range(len(ms))]
    return _two_at_a_time(one, len(ms), stop)


def _regime_terms(m: int, k: int) -> _Terms:
    """(coefficient, κ, σ) with ``m a_j = Σ coef · P(n + κ + σ j)`` for ``j`` in [km, (k+1)m)."""
    jf = k * m + 0.5
    acc: dict[tuple[int, int], float] = {}
    segs = ((0, 3 * m), (3 * m, 6 * m), (6 * m, 9 * m))
    for ta, tb, g in ((0, m, 1.0), (m, 2 * m, -2.0), (2 * m, 3 * m, 1.0)):
        for seg, (sa, sb) in enumerate(segs):
            lo = (ta, 1) if jf + ta >= sa else (sa, 0)
            hi = (tb, 1) if jf + tb <= sb else (sb, 0)
            if lo[0] + lo[1] * jf >= hi[0] + hi[1] * jf:
                continue
            if seg == 1:
                start, end = (lo[0] - 3 * m, lo[1]), (hi[0] - 3 * m, hi[1])
            else:
                top = 3 * m if seg == 0 else 9 * m
                start, end = (top - hi[0], -hi[1]), (top - lo[0], -lo[1])
            acc[end] = acc.get(end, 0.0) + g
            acc[start] = acc.get(start, 0.0) - g
    return [(c, kap, sig) for (kap, sig), c in acc.items() if c != 0.0]


def _ramp_terms(m: int) -> tuple[FloatArray, float]:
    """``c`` (3m weights) and ``Σ_j b_j²`` of the reflected ramp (see the module notes)."""
    x0 = np.arange(3 * m, dtype=np.float64)
    x0 -= x0.mean()
    xs = np.concatenate([x0[::-1], x0, x0[::-1]])
    cs = np.concatenate([[0.0], np.cumsum(xs)])
    s = cs[m:] - cs[:-m]
    b = s[: 6 * m] - 2.0 * s[m : 7 * m] + s[2 * m : 8 * m]
    # adjoint: y_p = Σ_j b_j g_{p−j}, then fold the 9m points onto the 3m
    cb = np.concatenate([[0.0], np.cumsum(b), np.full(3 * m, float(b.sum()))])
    p = np.arange(9 * m)

    def blk(lo: npt.NDArray[np.int64], hi: npt.NDArray[np.int64]) -> FloatArray:
        """Σ b_j over j in [lo, hi] clipped to [0, 6m)."""
        lo = np.clip(lo, 0, 6 * m)
        hi = np.clip(hi + 1, 0, 6 * m)
        return np.asarray(cb[hi] - cb[lo], dtype=np.float64)

    y = blk(p - m + 1, p) - 2.0 * blk(p - 2 * m + 1, p - m) + blk(p - 3 * m + 1, p - 2 * m)
    c = y[3 * m : 6 * m] + y[3 * m - 1 :: -1] + y[: 6 * m - 1 : -1]
    return c, float(b @ b)


def _row_line(v: FloatArray) -> FloatArray:
    """Each row of ``v`` less its half-mean line (for the digits only; see the notes)."""
    n = v.shape[1]
    h = n // 2
    idx = np.arange(n, dtype=np.float64) - (n - 1) / 2.0
    slope = (v[:, n - h :].mean(axis=1) - v[:, :h].mean(axis=1)) / (n - h)
    out: FloatArray = v - slope[:, None] * idx[None, :]
    out -= out.mean(axis=1, keepdims=True)
    return out


def _combine(pp: FloatArray, terms: list[tuple[float, int]], width: int) -> FloatArray:
    """Σ coef · pp[:, start : start + width] over the (coef, start) ``terms``."""
    out = np.zeros((pp.shape[0], width))
    for coef, start in terms:
        part = pp[:, start : start + width]
        if coef == 1.0:
            out += part
        elif coef == -1.0:
            out -= part
        else:
            out += coef * part
    return out


def _regime_sum(pp: FloatArray, terms: _Terms, j0: int, j1: int, ln: int, lb: int) -> float:
    """Σ_rows Σ_{n<ln} Σ_{j0≤j≤j1} (A(n+j) + B(n−j) + C(n))² from the rows' P (``pp``)."""
    rows = pp.shape[0]
    nj = j1 - j0 + 1
    ra = np.arange(j0, lb + j1)  # r = n + j
    sa = np.arange(-j1, lb - j0)  # s = n − j
    a = _combine(pp, [(cf, j0 + kp) for cf, kp, sg in terms if sg > 0], ra.size)
    b = _combine(pp, [(cf, kp - j1) for cf, kp, sg in terms if sg < 0], sa.size)
    c = _combine(pp, [(cf, kp) for cf, kp, sg in terms if sg == 0], ln)
    # weights of A(r)²: #j in [max(j0, r − ln + 1), min(j1, r)]; of B(s)²: with n = s + j < ln
    ja = np.maximum(j0, ra - ln + 1)
    jb = np.minimum(j1, ra)
    wa = np.maximum(jb - ja + 1, 0).astype(np.float64)
    wb = np.maximum(np.minimum(j1, ln - 1 - sa) - np.maximum(j0, -sa) + 1, 0).astype(np.float64)
    total = float(np.einsum("ij,ij->j", a, a) @ wa) + float(np.einsum("ij,ij->j", b, b) @ wb)
    total += nj * float(np.einsum("ij,ij->", c, c))
    # Σ_j A(n + j) and Σ_j B(n − j) for each n < ln
    qa = np.zeros((rows, ra.size + 1))
    np.cumsum(a, axis=1, out=qa[:, 1:])
    qb = np.zeros((rows, sa.size + 1))
    np.cumsum(b, axis=1, out=qb[:, 1:])
    sums = qa[:, nj : nj + ln] - qa[:, :ln]
    sums += qb[:, nj : nj + ln]
    sums -= qb[:, :ln]
    total += 2.0 * float(np.einsum("ij,ij->", c, sums))
    # Σ_r A(r) Σ_{j in [ja, jb]} B(r − 2j): B's running sums with stride 2,
    # Q2(s) = B(s) + B(s − 2) + …, the sum is Q2(r − 2 ja) − Q2(r − 2 jb − 2)
    width = sa.size + (sa.size % 2)
    bp = np.zeros((rows, width + 2))
    bp[:, 2 : 2 + sa.size] = b
    q2 = np.cumsum(bp.reshape(rows, -1, 2), axis=1).reshape(rows, -1)
    ok = np.flatnonzero(wa > 0)
    hi_i = ra[ok] - 2 * ja[ok] - sa[0] + 2
    lo_i = ra[ok] - 2 * jb[ok] - sa[0]
    cross = q2[:, hi_i]
    cross -= q2[:, lo_i]
    total += 2.0 * float(np.einsum("ij,ij->", a if ok.size == ra.size else a[:, ok], cross))
    return total


def _correlate(rows: FloatArray, c: FloatArray, ln: int) -> FloatArray:
    """Σ_i c_i rows[:, n + i] for n < ``ln`` (one FFT per row; no wrap: the FFT's length
    covers the row)."""
    size = 1 << int(rows.shape[1] - 1).bit_length()
    spec = np.fft.rfft(rows, size, axis=1)
    spec *= np.conj(np.fft.rfft(c, size))[None, :]
    out: FloatArray = np.fft.irfft(spec, size, axis=1)[:, :ln]
    return out


def _rows_sum(
    z: FloatArray,
    m: int,
    starts: npt.NDArray[np.int64],
    ln: int,
    lb: int,
    ramp: tuple[FloatArray, float],
    regimes: list[_Terms],
) -> float:
    """Σ over the rows' subsequences of Σ_j (m v_j)² (the module notes)."""
    span = lb + 3 * m - 1
    idx = starts[:, None] + np.arange(span)[None, :]
    zr = _row_line(z[np.minimum(idx, z.size - 1)])
    pp = np.zeros((zr.shape[0], span + 1))
    np.cumsum(zr, axis=1, out=pp[:, 1:])
    pp = _row_line(pp)
    total = 0.0
    for k, terms in enumerate(regimes):
        total += _regime_sum(pp, terms, k * m, (k + 1) * m - 1, ln, lb)
    h1, h2 = (3 * m) // 2, (3 * m + 1) // 2
    q = pp  # P less a line: differences of P over equal spans carry the line's constant
    nn = np.arange(ln)
    slope = ((q[:, nn + 3 * m] - q[:, nn + h2]) - (q[:, nn + h1] - q[:, nn])) / (h1 * h2)
    c, bb = ramp
    xc = _correlate(zr, c, ln)
    total += -2.0 * float(np.einsum("ij,ij->", slope, xc)) + bb * float(
        np.einsum("ij,ij->", slope, slope)
    )
    return total


def tot_sum(
    z: FloatArray, m: int, progress: Callable[[float], None] | None = None
) -> tuple[float, int]:
    r"""The total family's sum at one averaging factor, in O(N log m).

    Parameters
    ----------
    z : numpy.ndarray
        Series of one gap-free stretch (phase for MTOT/TTOT, rate for HTOT) [unit].
    m : int
        Averaging factor [samples].
    progress : callable, optional
        Called with the fraction done (0 to 1) after each chunk of rows.

    Returns
    -------
    tuple of (float, int)
        :math:`T(m) = \sum_n \frac{1}{6m}\sum_j v_j(n)^2` [unit²] and the number of
        subsequences N − 3m + 1 (0 when there are none).

    Notes
    -----
    See the module notes for the algebra.

    References
    ----------
    NIST SP 1065 (Riley 2008), eqs. 27–29.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.cumsum(np.random.default_rng(0).standard_normal(200))
    >>> s, k = tot_sum(x, 4)
    >>> k, f"{s / k:.4g}"
    (189, '3.5')
    """
    return _tot_sum(np.ascontiguousarray(z, dtype=np.float64), m, progress)


def _tot_sum(z: FloatArray, m: int, progress: Callable[[float], None] | None) -> tuple[float, int]:
    """:func:`tot_sum` on a contiguous float64 series."""
    n_sub = z.size - 3 * m + 1
    if m < 1 or n_sub < 1:
        return 0.0, 0
    lb = min(n_sub, _SPANS * 3 * m)
    rows = -(-n_sub // lb)
    starts = np.arange(rows, dtype=np.int64) * lb
    ramp = _ramp_terms(m)
    regimes = [_regime_terms(m, k) for k in range(6)]
    per = max(1, _ELEMENTS // (lb + 6 * m))
    full = n_sub // lb
    total = 0.0
    a = 0
    while a < rows:  # the full rows in chunks, then the last, shorter one
        b = min(a + per, full) if a < full else rows
        ln = lb if a < full else n_sub - a * lb
        total += _rows_sum(z, m, starts[a:b], ln, lb, ramp, regimes)
        a = b
        if progress is not None:
            progress(b / rows)
    return total / (6.0 * m**3), n_sub
