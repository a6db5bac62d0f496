"""The NIST SP 1065 family of frequency-stability deviations, gap-aware.

Every deviation is computed from phase points ``x_k`` [unit·s for rate data; the column's
unit for phase data] of one gap-free stretch; rate samples ``y_i`` (each the mean over τ0)
become ``x_k = τ0 Σ_{i<k} y_i``.  With τ = m τ0 and N phase points (SP 1065 equation numbers):

* ``adev``   (eq. 7)  σ² = Σ (x_{k+2m} − 2x_{k+m} + x_k)² / (2τ²(M)), k = 0, m, 2m, …
* ``oadev``  (eq. 11) the same over every k, N − 2m terms
* ``mdev``   (eq. 14) Mod σ² = Σ_j (Σ_{i=j}^{j+m−1} x_{i+2m} − 2x_{i+m} + x_i)² / (2m²τ²(N−3m+1))
* ``tdev``   (eq. 15) σ_x² = τ²/3 · Mod σ²
* ``hdev``   (eq. 17) Hσ² = Σ (x_{k+3m} − 3x_{k+2m} + 3x_{k+m} − x_k)² / (6τ² M), k = 0, m, …
* ``ohdev``  (eq. 18) the same over every k, N − 3m terms
* ``totdev`` (eq. 25) over the series extended by odd reflection at both ends, N − 2 terms
* ``mtotdev`` (eq. 27) each 3m-point subsequence: linear trend removed by its half means,
  extended by even reflection to 9m points, 6m modified second differences; N − 3m + 1 of them
* ``ttotdev`` (eq. 28) τ²/3 · Mtot σ²
* ``htotdev`` (eq. 29) as mtotdev on the rate (third differences of phase); m = 1 is ohdev
  (as Stable32)
* ``theo1``  (eq. 30) m even, τ = 0.75 m τ0:
  Σ_i Σ_{δ=0}^{m/2−1} ((x_i − x_{i−δ+m/2}) + (x_{i+m} − x_{i+δ+m/2}))²/(m/2 − δ)
  divided by 0.75 (m τ0)² (N − m)
* ``mtie``   (eq. 31) max over windows of m + 1 phase points of (max − min)
* ``tierms`` (eq. 33) √(mean (x_{k+m} − x_k)²)

No bias correction is applied (totdev, mtotdev, htotdev, theo1 as defined; Stable32's "no
bias" outputs).  Segments separated by gaps are never differenced across: each stretch gives
sums of squares and term counts per τ, pooled as Σ S / Σ count (MTIE: the largest).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt
from threadpoolctl import threadpool_limits

from thermocal._lazy import LazyModule
from thermocal.stability import edf as ed
from thermocal.stability import total as _total

ndimage = LazyModule("scipy.ndimage")

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


def max_factor(name: str, n_phase: int) -> int:
    """Largest averaging factor m with at least one term for N phase points.

    Parameters
    ----------
    name : str
        Deviation name (``"adev"``, ``"mdev"``, ``"htotdev"`` …).
    n_phase : int
        Number of phase points N.

    Returns
    -------
    int
        Largest averaging factor m [samples].
    """
    if name in ("adev", "oadev", "tierms", "mtie"):
        return (n_phase - 1) // 2 if name in ("adev", "oadev") else n_phase - 1
    if name in ("mdev", "tdev", "mtotdev", "ttotdev"):
        return (n_phase + 1) // 3 if name in ("mdev", "tdev") else n_phase // 3
    if name in ("hdev", "ohdev"):
        return (n_phase - 1) // 3
    if name == "htotdev":
        return (n_phase - 1) // 3
    if name == "totdev":
        return n_phase - 2
    if name == "theo1":
        return n_phase - 1
    raise ValueError(name)


WORK_PER_TERM: Final = {"theo1": 4.0}
"""Arithmetic operations per (term, lag) of the O(N·m) kernel: Theo1 3 subtractions and a
multiply-add per (i, δ) pair.  The total family: :func:`.total.cost` per factor (90 per
(subsequence, point) of 9m points at m ≤ 2, :data:`.total.PER_POINT` per phase point
above); every other deviation: :data:`WORK_PER_POINT` per phase point and factor."""

WORK_PER_POINT: Final = 4.0
"""Operations per phase point and averaging factor of the O(N) deviations (a difference
of two to four taps and its square)."""


def work(name: str, n_phase: int, m: npt.ArrayLike) -> float:
    """Estimated arithmetic operations of :func:`segment_sums` for ``name`` on one stretch of
    ``n_phase`` phase points at the factors ``m`` (those beyond :func:`max_factor` cost
    nothing).

    * mtotdev, ttotdev: Σ_m 90 m (N − 3m + 1) at m ≤ 2 (N − 3m + 1 subsequences of 9m
      points, NIST SP 1065 eq. 27), 400 N above (:func:`.total.tot_sum`, O(N log m) per
      factor), over the m with at least one subsequence;
    * htotdev: the same on the N − 1 rate points (eq. 29; m = 1 is ohdev);
    * theo1: Σ_m 4 (m/2)(N − m) over even m — m/2 lags δ per term (eq. 30);
    * the others: Σ_m 4 N.

    These are the sums the kernels here evaluate, so the estimate is their cost to a
    constant factor (about 1 ns per operation on one 2020s core).

    Parameters
    ----------
    name : str
        Deviation name.
    n_phase : int
        Number of phase points N.
    m : array_like
        Averaging factors [samples].

    Returns
    -------
    float
        Estimated operations [1].
    """
    mm = np.asarray(m, dtype=np.float64).ravel()
    mm = mm[(mm >= 1) & (mm <= max_factor(name, n_phase))]
    n = float(n_phase)
    if name in ("mtotdev", "ttotdev", "htotdev"):
        pts = n - 1.0 if name == "htotdev" else n
        big = mm[mm > 1] if name == "htotdev" else mm
        ones = float(np.sum(mm == 1)) * WORK_PER_POINT * n if name == "htotdev" else 0.0
        return sum(_total.cost(int(pts), int(v)) for v in big.tolist()) + ones
    if name == "theo1":
        even = mm[mm % 2 == 0]
        return float(np.sum(WORK_PER_TERM[name] * (even / 2.0) * (n - even)))
    return WORK_PER_POINT * n * float(mm.size)


_CHUNK: Final = 1 << 17
"""Terms per block of :func:`_difference_sum` (a few cache-sized buffers, reused)."""

_INDEX: Final = np.arange(_CHUNK, dtype=np.float64)

_WORKERS: Final = max(1, min(2, os.cpu_count() or 1))

_EXECUTOR: list[ThreadPoolExecutor] = []


def _pool() -> ThreadPoolExecutor:
    """One pool of :data:`_WORKERS` threads for the module, made on first use (starting
    threads per call costs milliseconds on a loaded machine)."""
    if not _EXECUTOR:
        _EXECUTOR.append(ThreadPoolExecutor(max_workers=_WORKERS))
    return _EXECUTOR[0]


FIRST: Final = ((1, 1.0), (0, -1.0))
"""x_{k+m} − x_k."""
SECOND: Final = ((2, 1.0), (0, 1.0), (1, -2.0))
"""x_{k+2m} + x_k − 2x_{k+m} (offset in m, coefficient; evaluated in this order)."""
THIRD: Final = ((3, 1.0), (0, -1.0), (2, -3.0), (1, 3.0))
"""x_{k+3m} − x_k − 3x_{k+2m} + 3x_{k+m}."""


def _difference_sum(
    x: FloatArray, m: int, n_terms: int, taps: tuple[tuple[int, float], ...], nested: bool = False
) -> float:
    """Σ_{k<n_terms} (Σ_j c_j x_{k + o_j m})² for taps (o_j, c_j), in blocks of
    :data:`_CHUNK` terms with two reused buffers (no array per sample).  The first two taps
    must have c = ±1 (one add or subtract forms them, as :func:`thermocal.stability.allan.
    second_difference_sums` does: x_{k+2m} + x_k − 2 x_{k+m}); the others are added after."""
    if (taps == SECOND or (nested and taps == THIRD)) and step_small(m):
        return _nested_difference_sum(x, m, n_terms, 2 if taps == SECOND else 3)
    size = min(_CHUNK, max(n_terms, 1))
    buf = np.empty(size)
    tmp = np.empty(size)
    total = 0.0
    (o0, c0), (o1, c1), rest = taps[0], taps[1], taps[2:]
    for a in range(0, n_terms, _CHUNK):
        b = min(a + _CHUNK, n_terms)
        t, u = buf[: b - a], tmp[: b - a]
        first, second = x[a + o0 * m : b + o0 * m], x[a + o1 * m : b + o1 * m]
        (np.add if c0 == c1 else np.subtract)(first, second, out=t)
        if c0 < 0:
            np.negative(t, out=t)
        for o, c in rest:
            np.multiply(x[a + o * m : b + o * m], abs(c), out=u)
            if c > 0:
                t += u
            else:
                t -= u
        total += float(t @ t)
    return total


def step_small(m: int) -> bool:
    """Whether x_k … x_{k+2m} of a block of terms lie within two blocks (cache-resident).

    Parameters
    ----------
    m : int
        Averaging factor [samples].

    Returns
    -------
    bool
        True when the terms of a block stay cache-resident.
    """
    return 0 < m < _CHUNK


def _nested_difference_sum(x: FloatArray, m: int, n_terms: int, d: int) -> float:
    """Σ_{k<n_terms} (Δ_m^d x)_k² for d = 2 (x_{k+2m} − 2x_{k+m} + x_k) or 3 (x_{k+3m} −
    3x_{k+2m} + 3x_{k+m} − x_k), as differences of differences formed once per block over
    the block and (d − 1)m beyond it: d subtractions and a dot per term instead of 3 or 5
    operations (for m below a block, where the overlap is short)."""
    size = min(_CHUNK, max(n_terms, 1))
    bufs = [np.empty(size + (d - 1 - j) * m) for j in range(d)]
    total = 0.0
    for a in range(0, n_terms, _CHUNK):
        n_b = min(a + _CHUNK, n_terms) - a
        cur = bufs[0][: n_b + (d - 1) * m]
        np.subtract(x[a + m : a + n_b + d * m], x[a : a + n_b + (d - 1) * m], out=cur)
        for j in range(1, d):  # the next difference, (d − 1 − j) m beyond the block
            nxt = bufs[j][: n_b + (d - 1 - j) * m]
            np.subtract(cur[m : m + nxt.size], cur[: nxt.size], out=nxt)
            cur = nxt
        total += float(cur @ cur)
    return total


_MOD_CHUNK: Final = 1 << 16
"""Terms per block of :func:`modified_sum` (its five buffers stay in the L2 cache)."""

_LANES: Final = 16
"""Running sums per block of :func:`_prefix_squares` are taken over this many contiguous
pieces at once, one vector add per step (a scalar running sum waits on each add)."""


def _prefix_squares(w: FloatArray, lanes: FloatArray) -> tuple[float, float]:
    """(Σ_k p_k², p_last) of the running sum p_k = Σ_{i≤k} w_i: the block cut into
    :data:`_LANES` pieces laid side by side (``lanes``: a buffer of ``w.size``), each
    piece's running sum taken together step by step, then every piece offset by the totals
    of the pieces before it."""
    n = w.size
    if n % _LANES or n < 4 * _LANES:
        p = np.cumsum(w)
        return float(p @ p), float(p[-1])
    cols = n // _LANES
    grid = lanes[:n].reshape(_LANES, cols)  # column c: w[c·L : (c + 1)·L]
    np.copyto(grid, w.reshape(cols, _LANES).T)
    for i in range(1, _LANES):
        np.add(grid[i], grid[i - 1], out=grid[i])
    before = np.cumsum(grid[-1])  # the pieces' totals, summed
    grid[:, 1:] += before[None, :-1]
    flat = lanes[:n]
    return float(flat @ flat), float(grid[-1, -1])


def modified_sum(x: FloatArray, m: int, n_terms: int) -> float:
    r"""Σ_{j<n_terms} v_j² of MDEV's inner sums v_j = Σ_{i=j}^{j+m−1} (x_{i+2m} − 2x_{i+m} +
    x_i) (NIST SP 1065 eq. 14), with no running sum of the phase itself.

    v_0 is summed directly (pairwise); then v_{j+1} = v_j + t_j with t_j = x_{j+3m} −
    3x_{j+2m} + 3x_{j+m} − x_j (the inner sum slides by one: it gains the second difference
    at j + m and loses the one at j), a running sum carried from block to block of
    :data:`_MOD_CHUNK` terms.  Every partial sum is a v_j itself, as small as the deviation:
    rounding grows as ε √N relative, not as ε N² |x| / |v| as a running sum of the phase
    does.  At m = 1, v_j is the second difference itself (no running sum): MDEV
    is OADEV to the last digit; at m = 2, 4, 8, 16 v_j is the second difference of the
    window sums of m phase points, taken by doubling (:func:`_window_modified_sums`).  For
    m a multiple of :data:`_RUN` the same sums come faster from :func:`lane_modified_sum`.

    Parameters
    ----------
    x : numpy.ndarray
        Phase points [unit·s].
    m : int
        Averaging factor [samples].
    n_terms : int
        Number of inner sums v_j.

    Returns
    -------
    float
        Sum of squared inner sums [(unit·s)²].

    Notes
    -----
    .. math:: v_j = \sum_{i=j}^{j+m-1} (x_{i+2m} - 2x_{i+m} + x_i)

    References
    ----------
    - NIST SP 1065 (Riley 2008), eq. 14 (modified Allan variance).
    """
    if n_terms < 1:
        return 0.0
    if m == 1:
        return _nested_difference_sum(x, 1, n_terms, 2)
    if m in (2, 4, 8, 16):
        return _window_modified_sums(x, [m], [n_terms])[0]
    first = x[2 * m : 3 * m] - 2.0 * x[m : 2 * m]
    first += x[:m]
    v = float(np.sum(first))
    return _modified_tail(x, m, n_terms, 0, v)


def _modified_tail(x: FloatArray, m: int, n_terms: int, start: int, v: float) -> float:
    """Σ v_j² for start ≤ j < n_terms given v = v_start (:func:`modified_sum`), in blocks of
    :data:`_MOD_CHUNK` terms: the third differences t_j, their running sum from v in
    :data:`_LANES` lanes (:func:`_prefix_squares`)."""
    size = min(_MOD_CHUNK, n_terms - start)
    nested = 16 * m <= _MOD_CHUNK  # the 2m extra terms a block cost less than a fourth tap
    extra = 2 * m if nested else 0
    buf, lanes = np.empty(size + 1), np.empty(size)
    tmp, tmp2 = np.empty(size + extra), np.empty(size + extra)
    total = 0.0
    for a in range(start, n_terms, _MOD_CHUNK):
        n_b = min(a + _MOD_CHUNK, n_terms) - a
        n_t = min(n_b, n_terms - 1 - a)  # t_j exists for j < n_terms − 1
        buf[0] = v  # then t_a … t_{a+n_t−1}: their running sum is v_a … v_{a+n_t}
        _third(x, m, a, buf[1 : n_t + 1], tmp, tmp2, nested)
        sq, last = _prefix_squares(buf[:n_b], lanes)
        total += sq
        if n_t == n_b:  # the next block's first inner sum
            v = last + float(buf[n_b])
    return total


def _window_modified_sums(x: FloatArray, ms: list[int], n_terms: list[int]) -> list[float]:
    r""":func:`modified_sum` for m in 2, 4, 8, 16 (ascending) in one pass over the phase:
    v_j = S_{j+2m} − 2S_{j+m} + S_j with S_j = Σ_{i<m} x_{j+i} the window sums of m points,
    each width from the one below by doubling (S^{2w}_j = S^w_j + S^w_{j+w}), in blocks of
    :data:`_MOD_CHUNK` terms.  The window sums are no larger than m |x| (no running sum),
    and every width reads the phase once for all of them.  m = 2 as the pair sums of its
    second differences d_i = x_{i+4} − 2x_{i+2} + x_i (to the digits of m = 1)."""
    n, top = x.size, ms[-1]
    widths = [w for w in (2, 4, 8, 16) if w <= top]
    most = max(n_terms)
    size = min(_MOD_CHUNK, most)
    sums = {w: np.empty(size + 3 * top) for w in widths}
    e1, e2 = np.empty(size + 2 * top + 3), np.empty(size + 1)
    totals = [0.0] * len(ms)
    for a in range(0, most, _MOD_CHUNK):
        nb = min(_MOD_CHUNK, most - a)
        below, span = x[a:], n - a  # S^1 = x; the windows of width w that fit: span − w + 1
        for w in widths:
            cur = sums[w][: min(nb + 3 * top - w, span - w + 1)]
            np.add(below[: cur.size], below[w // 2 : w // 2 + cur.size], out=cur)
            below = cur
            if w not in ms:
                continue
            i = ms.index(w)
            nt = min(nb, n_terms[i] - a)
            if nt <= 0:
                continue
            if w == 2:  # v_j = d_j + d_{j+1}
                d1 = e1[: nt + 3]
                np.subtract(x[a + 2 : a + nt + 5], x[a : a + nt + 3], out=d1)
                d = e2[: nt + 1]
                np.subtract(d1[2:], d1[: nt + 1], out=d)
                np.add(d[:nt], d[1:], out=d[:nt])
                totals[i] += float(d[:nt] @ d[:nt])
                continue
            d1 = e1[: nt + w]
            np.subtract(cur[w : 2 * w + nt], cur[: nt + w], out=d1)
            v = e2[:nt]
            np.subtract(d1[w:], d1[:nt], out=v)
            totals[i] += float(v @ v)
    return totals


_RUN: Final = 32
"""Points per run of :func:`lane_prefix`: the offsets of :func:`lane_modified_sum` cost 1/L
of its work (16, 32, 64: 13.6, 11.9, 12.4 ms at m = 64 on 10⁷ points, :func:`lane_prefix`
30, 30, 44 ms)."""

_PREFIX_BLOCK: Final = 1 << 17
"""Points per block of :func:`lane_prefix` (1 MB, cache-resident)."""

_LANE_MIN: Final = 1 << 17
"""Fewest third differences (N − 3m) for which :func:`lane_modified_sum` is used."""


def lane_prefix(x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    r"""The phase cut into runs of :data:`_RUN` points, each run's running sum: ``q[c, i]``
    = Σ_{i'≤i} x_{cL+i'} (x taken as zero past its end), the runs' totals ``q[c, L − 1]``
    (contiguous) and the sums ``r[c]`` = Σ_i q[c, i].

    Every running sum is over at most L = 32 points, so ``q`` is as small as 32 |x| however
    long the record.  A shift of the index by m = kL is a shift of k rows, the same in every
    column: the third difference of ``q`` over k rows is the running sum, along each run, of
    the third differences t_j of x (:func:`lane_modified_sum`).  Taken column by column in
    blocks of :data:`_PREFIX_BLOCK` points (cache-resident).

    Parameters
    ----------
    x : numpy.ndarray
        Phase points [unit·s], shape (N,).

    Returns
    -------
    tuple of numpy.ndarray
        ``q`` of shape (⌈N / L⌉, L), the totals and ``r``, each of shape (⌈N / L⌉,)
        [unit·s].

    Notes
    -----
    .. math:: q_{c,i} = \sum_{i'=0}^{i} x_{cL+i'}, \qquad r_c = \sum_{i=0}^{L-1} q_{c,i}

    Examples
    --------
    >>> q, totals, r = lane_prefix(np.arange(64.0))
    >>> q.shape, float(q[0, 1]), totals.tolist(), float(r[0])
    ((2, 32), 1.0, [496.0, 1520.0], 5456.0)
    """
    runs, full = -(-x.size // _RUN), x.size // _RUN
    q, totals = np.empty((runs, _RUN)), np.empty(runs)
    src = x[: full * _RUN].reshape(full, _RUN)
    if runs > full:  # the last run, zero past the end of x
        q[full] = 0.0
        q[full, : x.size - full * _RUN] = x[full * _RUN :]
    rows = _PREFIX_BLOCK // _RUN
    for a in range(0, runs, rows):
        blk = q[a : a + rows]
        np.copyto(blk[: max(0, min(rows, full - a))], src[a : a + rows])
        for i in range(1, _RUN):
            np.add(blk[:, i], blk[:, i - 1], out=blk[:, i])
        np.copyto(totals[a : a + rows], blk[:, -1])
    return q, totals, q @ np.ones(_RUN)


_RUN_BLOCK: Final = 1 << 15
"""Runs per block of the offsets of :func:`lane_modified_sum` (256 kB buffers)."""

_NESTED_MAX: Final = 1024
"""Largest m for which :func:`lane_modified_sum` takes third differences as differences of
differences (beyond, the 2m extra terms a block cost more than the fourth tap: 12.8 vs
13.7 ms at m = 1024, 14.5 vs 13.9 ms at 2048 on 10⁷ points)."""


def _third(
    a: FloatArray, k: int, s: int, out: FloatArray, e1: FloatArray, e2: FloatArray, nested: bool
) -> None:
    """out[c − s] = a[c + 3k] − 3a[c + 2k] + 3a[c + k] − a[c] for c in [s, s + out.size):
    ``nested``: as differences of differences over the block and 2k beyond (three
    subtractions a term; ``e1``, ``e2`` of out.size + 2k, + k), else from the four taps
    (``e1`` of out.size)."""
    nb = out.size
    if nested:
        d1, d2 = e1[: nb + 2 * k], e2[: nb + k]
        np.subtract(a[s + k : s + nb + 3 * k], a[s : s + nb + 2 * k], out=d1)
        np.subtract(d1[k:], d1[: nb + k], out=d2)
        np.subtract(d2[k:], d2[:nb], out=out)
        return
    work = e1[:nb]
    np.subtract(a[s + 3 * k : s + nb + 3 * k], a[s : s + nb], out=out)
    np.subtract(a[s + k : s + nb + k], a[s + 2 * k : s + nb + 2 * k], out=work)
    work *= 3.0
    out += work


def _third_squares(a: FloatArray, m: int, n_terms: int) -> float:
    """Σ_{j<n_terms} (a_{j+3m} − 3a_{j+2m} + 3a_{j+m} − a_j)², in blocks of :data:`_CHUNK`
    terms (:func:`_third`; up to :data:`_NESTED_MAX` nested: :func:`_nested_difference_sum`)."""
    if m <= _NESTED_MAX:
        return _nested_difference_sum(a, m, n_terms, 3)
    size = min(_CHUNK, n_terms)
    out, work = np.empty(size), np.empty(size)
    total = 0.0
    for s in range(0, n_terms, _CHUNK):
        t = out[: min(_CHUNK, n_terms - s)]
        _third(a, m, s, t, work, work, nested=False)
        total += float(t @ t)
    return total


def _lane_offsets(
    lanes: tuple[FloatArray, FloatArray, FloatArray], k: int, runs: int, v: float
) -> tuple[float, float]:
    """(Σ_c 2 off_c d_c + L off_c², v_0 + Σ_c T_c) over the runs c < ``runs`` of
    :func:`lane_modified_sum`: T_c, d_c the third differences over k runs of the runs'
    totals and sums (:func:`lane_prefix`), off_c = v_0 + Σ_{c'<c} T_{c'} (``v`` = v_0), in
    blocks of :data:`_RUN_BLOCK` runs, the running sum carried from block to block."""
    _, totals, r = lanes
    size = min(_RUN_BLOCK, runs)
    off, d = np.empty(size + 1), np.empty(size)
    e1, e2 = np.empty(size + 2 * k), np.empty(size + k)
    nested = k * _RUN <= _NESTED_MAX
    total = 0.0
    for s in range(0, runs, _RUN_BLOCK):
        nb = min(_RUN_BLOCK, runs - s)
        off[0] = v  # then T_s … T_{s+nb−1}: their running sum is off_s … off_{s+nb}
        _third(totals, k, s, off[1 : nb + 1], e1, e2, nested)
        np.cumsum(off[: nb + 1], out=off[: nb + 1])
        v = float(off[nb])
        _third(r, k, s, d[:nb], e1, e2, nested)
        o = off[:nb]
        total += 2.0 * float(o @ d[:nb]) + _RUN * float(o @ o)
    return total, v


def lane_modified_sum(
    x: FloatArray, lanes: tuple[FloatArray, FloatArray, FloatArray], m: int
) -> float:
    r""":func:`modified_sum` over all N − 3m + 1 inner sums for m a multiple of
    :data:`_RUN`, from :func:`lane_prefix`'s layout of x: the running sum of the third
    differences taken L at a time by the third difference of q (one pass over it, as
    OHDEV's sums), the runs' offsets from its totals (1/L of the work).

    Parameters
    ----------
    x : numpy.ndarray
        Phase points [unit·s].
    lanes : tuple of numpy.ndarray
        ``x`` through :func:`lane_prefix`.
    m : int
        Averaging factor [samples], a multiple of :data:`_RUN`.

    Returns
    -------
    float
        Σ_j v_j² [(unit·s)²].

    Notes
    -----
    With t_j = x_{j+3m} − 3x_{j+2m} + 3x_{j+m} − x_j and m = kL, the third difference of q
    over k runs is the running sum of the t along a run, p_{c,i}; with the runs' offsets
    off_c = v_0 + Σ_{c'<c} p_{c',L−1}, v_{cL+i+1} = off_c + p_{c,i} and

    .. math:: \sum_{c,i} v_{cL+i+1}^2 = \sum_{c,i} p_{c,i}^2
              + 2\sum_c \mathrm{off}_c \sum_i p_{c,i} + L \sum_c \mathrm{off}_c^2

    where Σ_i p_{c,i} is the same third difference of r and p_{c,L−1} of the totals.

    References
    ----------
    - NIST SP 1065 (Riley 2008), eq. 14 (modified Allan variance).

    Examples
    --------
    >>> x = np.cumsum(np.random.default_rng(0).standard_normal(140_000))
    >>> ratio = lane_modified_sum(x, lane_prefix(x), 32) / modified_sum(x, 32, x.size - 95)
    >>> f"{ratio:.12f}"
    '1.000000000000'
    """
    n = x.size
    runs = (n - 3 * m) // _RUN  # whole runs of t_j, j < N − 3m
    k, totals = m // _RUN, lanes[1]
    d1 = totals[k : 3 * k] - totals[: 2 * k]  # v_0 from the runs' totals (k, not m, terms)
    v = float(np.sum(d1[k:] - d1[:k]))
    flat = lanes[0].reshape(-1)
    total = v * v + _third_squares(flat, m, runs * _RUN)
    cross, v = _lane_offsets(lanes, k, runs, v)
    j = runs * _RUN  # v_j known; the last t_j, j < N − 3m, fewer than L
    t = x[j + 3 * m : n] - x[j : n - 3 * m]
    t -= 3.0 * (x[j + 2 * m : n - m] - x[j + m : n - 2 * m])
    rest = v + np.cumsum(t)
    return total + cross + float(rest @ rest)


def difference_sums(
    base: Callable[[int], tuple[FloatArray, int, int]],
    m: IntArray,
    taps: tuple[tuple[int, float], ...],
    nested: bool = False,
) -> FloatArray:
    """:func:`_difference_sum` for each factor m: ``base(m)`` gives (array, offset unit,
    term count) — the phase with m itself, or a decimated phase with 1 — shared between
    :data:`_WORKERS` threads (numpy releases the GIL in its loops; BLAS held to one thread
    meanwhile).

    Parameters
    ----------
    base : callable
        ``base(m)`` → (array, step, term count).
    m : numpy.ndarray
        Averaging factors [samples].
    taps : tuple of (int, float)
        Offsets and weights of the difference.
    nested : bool, optional
        Whether the sum is nested (default False).

    Returns
    -------
    numpy.ndarray
        Sum per factor [(unit·s)²].
    """

    def one(mm: int) -> float:
        arr, step, n_terms = base(mm)
        return _difference_sum(arr, step, n_terms, taps, nested)

    ms = [int(v) for v in m.tolist()]
    with threadpool_limits(limits=1, user_api="blas"):
        if len(ms) <= 1 or _WORKERS <= 1:
            return np.array([one(mm) for mm in ms], dtype=np.float64)
        vals = list(_pool().map(one, ms))
    return np.asarray(vals, dtype=np.float64)


def _tot_kernel(z: FloatArray, m: int) -> tuple[float, int]:
    """Σ_n (1/6m) Σ_{j<6m} v_j² of the total family (NIST SP 1065 eqs. 27, 29) and the number
    of subsequences (:func:`.total.tot_sum`)."""
    return _total.tot_sums(z, [m])[0]


def _theo1_sum(x: FloatArray, m: int) -> float:
    """Σ_{i<N−m} Σ_{δ<m/2} ((x_i − x_{i−δ+m/2}) + (x_{i+m} − x_{i+δ+m/2}))² / (m/2 − δ)."""
    n = x.size - m
    h = m // 2
    total = 0.0
    base = x[:n] + x[m : m + n]
    for dl in range(h):
        v = base - x[h - dl : h - dl + n] - x[h + dl : h + dl + n]
        total += float(v @ v) / (h - dl)
    return total


_FAST: Final = frozenset({"adev", "oadev", "hdev", "ohdev", "mdev", "tdev", "totdev", "tierms"})
"""Deviations whose sums :func:`_fast_sums` takes in blocks, every τ at once."""


_OVERLAPPING: Final = {"oadev": (2, SECOND), "ohdev": (3, THIRD), "tierms": (1, FIRST)}
"""Differences taken and taps of the overlapping deviations of :func:`_fast_sums`."""


def _modified_sums(x: FloatArray, m: IntArray) -> FloatArray:
    """:func:`modified_sum` per m, shared between the pool's threads: the runs of
    :func:`lane_prefix` made first (first in the queue: no factor waiting on them holds a
    thread before they are begun), m = 2, 4, 8, 16 together (:func:`_window_modified_sums`)
    and the other small m next, then the m of :func:`lane_modified_sum`."""
    n = x.size
    laned = (m % _RUN == 0) & (n - 3 * m >= _LANE_MIN)
    window = ~laned & np.isin(m, (2, 4, 8, 16))
    ex = _pool()
    out = np.zeros(m.size)
    with threadpool_limits(limits=1, user_api="blas"):
        lanes = ex.submit(lane_prefix, x) if np.any(laned) else None
        wi = np.flatnonzero(window)
        wi = wi[np.argsort(m[wi], kind="stable")]
        mw = m[wi].tolist()
        chain = ex.submit(_window_modified_sums, x, mw, [n - 3 * w + 1 for w in mw]) if mw else None
        rest = np.flatnonzero(~laned & ~window).tolist()
        jobs = [ex.submit(modified_sum, x, int(m[i]), n - 3 * int(m[i]) + 1) for i in rest]
        idx = np.flatnonzero(laned).tolist()
        if lanes is not None:
            jobs += [ex.submit(lane_modified_sum, x, lanes.result(), int(m[i])) for i in idx]
        out[rest + idx] = [job.result() for job in jobs]
        if chain is not None:
            out[wi] = chain.result()
    return out


def _fast_sums(name: str, x: FloatArray, m: IntArray) -> tuple[FloatArray, FloatArray]:
    """(Σ of squared differences, terms) per valid m of the finite-difference deviations
    (:data:`_FAST`), through :func:`difference_sums`."""
    n = x.size
    if name in ("adev", "hdev"):  # non-overlapping: the phase decimated by m, differenced
        d = 2 if name == "adev" else 3
        cnt = np.array([(n - 1) // int(mm) + 1 - d for mm in m.tolist()], dtype=np.float64)
        taps: tuple[tuple[int, float], ...] = SECOND if d == 2 else THIRD
        sums = difference_sums(lambda mm: (x[::mm], 1, (n - 1) // mm + 1 - d), m, taps)
        return sums, cnt
    if name in ("oadev", "ohdev", "tierms"):
        d, taps = _OVERLAPPING[name]  # ohdev: nested differences (not mdev's running sum)
        sums = difference_sums(lambda mm: (x, mm, n - d * mm), m, taps, nested=True)
        return sums, (n - d * m).astype(np.float64)
    if name in ("mdev", "tdev"):  # inner sums slid along by third differences
        return _modified_sums(x, m), (n - 3 * m + 1).astype(np.float64)
    # totdev: the series extended by odd reflection at both ends, N − 2 terms centred on it
    ms = [int(v) for v in m.tolist()]
    with threadpool_limits(limits=1, user_api="blas"):
        if len(ms) <= 1 or _WORKERS <= 1:
            sums = np.array([_totdev_sum(x, mm) for mm in ms], dtype=np.float64)
        else:
            sums = np.asarray(list(_pool().map(lambda mm: _totdev_sum(x, mm), ms)))
    return sums, np.full(m.size, float(n - 2))


def _reflected(x: FloatArray, lo: int, hi: int, out: FloatArray) -> FloatArray:
    """``ext[lo:hi]`` of x extended by odd reflection at both ends, written into ``out``
    (``ext`` = 2x₀ − x_{N−2} … 2x₀ − x_1, x, 2x_{N−1} − x_{N−2} … 2x_{N−1} − x_1: 3N − 4
    points, never built whole)."""
    n = x.size
    res = out[: hi - lo]
    a, b = max(lo, 0), min(hi, n - 2)  # the left reflection: ext[e] = 2x₀ − x[N − 2 − e]
    if a < b:
        np.subtract(2.0 * x[0], x[n - 1 - b : n - 1 - a][::-1], out=res[a - lo : b - lo])
    a, b = max(lo, n - 2), min(hi, 2 * n - 2)  # x itself
    if a < b:
        res[a - lo : b - lo] = x[a - n + 2 : b - n + 2]
    a, b = max(lo, 2 * n - 2), hi  # the right reflection: ext[e] = 2x_{N−1} − x[3N − 4 − e]
    if a < b:
        np.subtract(2.0 * x[-1], x[3 * n - 3 - b : 3 * n - 3 - a][::-1], out=res[a - lo : b - lo])
    return res


def _totdev_sum(x: FloatArray, m: int) -> float:
    """Σ_k (e_{k+2m} − 2e_{k+m} + e_k)² over the N − 2 terms centred on x of its odd
    reflection e (:func:`_reflected`), block by block of :data:`_CHUNK` terms: the same
    arithmetic, block for block, as :func:`_difference_sum` on the extended series, from
    buffers of a few blocks (the extension held 24 bytes a sample)."""
    n_terms = x.size - 2
    base = x.size - 1 - m  # ext index of the first term's first tap
    size = min(_CHUNK, max(n_terms, 1))
    total = 0.0
    if step_small(m):  # as _nested_difference_sum, d = 2
        seg, cur, nxt = np.empty(size + 2 * m), np.empty(size + m), np.empty(size)
        for a in range(0, n_terms, _CHUNK):
            n_b = min(a + _CHUNK, n_terms) - a
            e = _reflected(x, base + a, base + a + n_b + 2 * m, seg)
            c = cur[: n_b + m]
            np.subtract(e[m:], e[: n_b + m], out=c)
            d = nxt[:n_b]
            np.subtract(c[m : m + n_b], c[:n_b], out=d)
            total += float(d @ d)
        return total
    t, u, far = np.empty(size), np.empty(size), np.empty(size)
    for a in range(0, n_terms, _CHUNK):  # taps SECOND: x_{k+2m} + x_k − 2 x_{k+m}
        b = min(a + _CHUNK, n_terms)
        tt, uu = t[: b - a], u[: b - a]
        first = _reflected(x, base + a + 2 * m, base + b + 2 * m, far)
        np.add(first, _reflected(x, base + a, base + b, uu), out=tt)
        np.multiply(_reflected(x, base + a + m, base + b + m, uu), 2.0, out=uu)
        tt -= uu
        total += float(tt @ tt)
    return total


@dataclass(frozen=True, eq=False)
class OctaveLevel:
    """Level k of the octave pyramid of one gap-free stretch of rate samples y_i: the block
    sums S_j = Σ_{i=jm}^{(j+1)m−1} (y_i − ȳ) for m = 2^k, j < n // m (level 0: ``z`` is the
    samples themselves and ``offset`` = ȳ; above, ``z`` = S and ``offset`` = 0).

    ``d1`` = Σ_j (S_{j+1} − S_j)², ``d2`` = Σ_j (S_{j+2} − 2S_{j+1} + S_j)² (NaN when not
    asked); ``lag`` the :class:`thermocal.stability.edf.LagSums` of S (noise
    identification).  With phase x_k = τ0 Σ_{i<k}(y_i − ȳ), x_{(j+1)m} − x_{jm} = τ0 S_j:
    the Allan second difference at m is τ0 (S_{j+1} − S_j), the Hadamard third difference
    τ0 (S_{j+2} − 2S_{j+1} + S_j) (SP 1065 eqs. 7, 17).

    Attributes
    ----------
    m : int
        Averaging factor 2^k.
    z : numpy.ndarray
        The level's series (samples at level 0, block sums above).
    offset : float
        ȳ at level 0, else 0.
    d1, d2 : float
        Sums of squared first and second differences of S (NaN: not asked).
    lag : LagSums
        Lag sums of S (noise identification).
    """

    m: int
    z: FloatArray
    offset: float
    d1: float
    d2: float
    lag: ed.LagSums


_LEVEL_BLOCK: Final = 1 << 15
"""Elements per block of :func:`_level_pass` (a few buffers that stay in the L2 cache)."""


def _level_range(
    z: FloatArray, offset: float, lo: int, hi: int, d1: bool, d2: bool, nxt: FloatArray | None
) -> tuple[float, ...]:
    """Σ c, Σ c², Σ c_k c_{k+1}, Σ k c_k, Σ (Δc)², Σ (Δ²c)² over the terms starting at k in
    [lo, hi) (c = z − offset; a difference or pair may reach past ``hi``), in cache-sized
    blocks, writing the pairwise sums c_{2i} + c_{2i+1} of the range into ``nxt`` (lo even)."""
    n = z.size
    big = _LEVEL_BLOCK
    buf, t1, t2 = np.empty(big + 2), np.empty(big + 1), np.empty(big)
    s1 = s2 = sl = sk = q1 = q2 = 0.0
    c: FloatArray
    for a in range(lo, hi, big):
        b = min(a + big, hi)
        e = min(b + 2, n)  # two points past the block for the differences
        if offset:
            c = buf[: e - a]
            np.subtract(z[a:e], offset, out=c)
        else:  # the levels above 0 are centred already: read in place
            c = z[a:e]
        own = c[: b - a]
        tot = float(own.sum())
        s1 += tot
        s2 += float(own @ own)
        sk += float(_INDEX[: b - a] @ own) + a * tot
        lp = min(b - a, e - a - 1)  # pairs (k, k + 1) with k in the block, k + 1 < n
        sl += float(c[:lp] @ c[1 : lp + 1])
        if d1 or d2:
            u = t1[: e - a - 1]
            np.subtract(c[1:], c[:-1], out=u)
            if d1:
                q1 += float(u[:lp] @ u[:lp])
            l2 = min(b - a, e - a - 2)
            if d2 and l2 > 0:
                v = t2[:l2]
                np.subtract(u[1 : l2 + 1], u[:l2], out=v)
                q2 += float(v @ v)
        if nxt is not None:
            h = min((b - a) // 2, nxt.size - a // 2)
            np.add(c[0 : 2 * h : 2], c[1 : 2 * h : 2], out=nxt[a // 2 : a // 2 + h])
    return s1, s2, sl, sk, q1, q2


_SPLIT: Final = 1 << 20
"""Levels of at least this many points are passed over by :data:`_WORKERS` threads."""


def _level_pass(
    z: FloatArray, offset: float, *, d1: bool, d2: bool, nxt: FloatArray | None
) -> tuple[float, float, ed.LagSums]:
    """One pass over ``z`` (two threads on halves when long; numpy releases the GIL) in
    cache-sized blocks of c = z − offset: Σ (Δc)², Σ (Δ²c)², the sums of
    :class:`thermocal.stability.edf.LagSums` and (``nxt``) the next level."""
    n = z.size
    if n >= _SPLIT and _WORKERS > 1:
        half = (n // 2) & ~1
        jobs = [
            _pool().submit(_level_range, z, offset, lo, hi, d1, d2, nxt)
            for lo, hi in ((0, half), (half, n))
        ]
        parts = [j.result() for j in jobs]
        s1, s2, sl, sk, q1, q2 = (p + q for p, q in zip(*parts, strict=True))
    else:
        s1, s2, sl, sk, q1, q2 = _level_range(z, offset, 0, n, d1, d2, nxt)
    delta = s1 / n  # c's own mean: the centring made exact (z_c = c − δ)
    first, last = float(z[0]) - offset - delta, float(z[-1]) - offset - delta
    lag = ed.LagSums(
        n,
        s2 - s1 * delta,
        sk - delta * n * (n - 1) / 2.0,
        sl - delta * (2.0 * s1 - (first + delta) - (last + delta)) + (n - 1) * delta * delta,
        first,
        last,
    )
    return (q1 if d1 else math.nan), (q2 if d2 else math.nan), lag


def octave_levels(
    y: FloatArray, mean: float, m_max: int, *, d1: bool = False, d2: bool = False
) -> list[OctaveLevel]:
    """The :class:`OctaveLevel` for m = 1, 2, 4 … ≤ ``m_max`` (while a block remains) of
    rate samples ``y`` with mean ``mean``: each level from the one below in one blocked pass
    (O(n) in all; no phase array).  ``d1``/``d2``: take the Allan/Hadamard sums too.

    Parameters
    ----------
    y : numpy.ndarray
        Rate samples [unit].
    mean : float
        Their mean [unit].
    m_max : int
        Largest averaging factor [samples].
    d1, d2 : bool, optional
        Also take the Allan / Hadamard sums (default False).

    Returns
    -------
    list of OctaveLevel
        One level per octave.
    """
    out: list[OctaveLevel] = []
    z, offset, m = np.asarray(y, dtype=np.float64), float(mean), 1
    while z.size >= 1 and m <= m_max:
        nxt = np.empty(z.size // 2) if 2 * m <= m_max and z.size >= 2 else None
        q1, q2, lag = _level_pass(z, offset, d1=d1, d2=d2, nxt=nxt)
        out.append(OctaveLevel(m, z, offset, q1, q2, lag))
        if nxt is None:
            break
        z, offset, m = nxt, 0.0, 2 * m
    return out


def octave_sums(name: str, levels: list[OctaveLevel], m: IntArray) -> tuple[FloatArray, FloatArray]:
    r"""(numerator, terms) per m of ``adev``/``hdev`` from one stretch's octave levels, as
    :func:`segment_sums` gives them: Σ (τ0 ΔS)² / (2τ²) = Σ (ΔS)² / (2m²) over n//m − 1 terms
    (adev), Σ (Δ²S)² / (6m²) over n//m − 2 (hdev); (0, 0) where too few blocks remain.

    Parameters
    ----------
    name : str
        ``"adev"`` or ``"hdev"``.
    levels : list of OctaveLevel
        Levels of :func:`octave_levels`.
    m : numpy.ndarray
        Averaging factors [samples].

    Returns
    -------
    tuple of numpy.ndarray
        (numerator, terms) per factor.

    Notes
    -----
    .. math:: \sigma_y^2(m\tau_0) = \frac{1}{2m^2 (n/m - 1)} \sum (\Delta S)^2

    References
    ----------
    - NIST SP 1065 (Riley 2008), eq. 10 (Allan variance) and eq. 17 (Hadamard variance).
    """
    d = 2 if name == "adev" else 3
    by_m = {lv.m: lv for lv in levels}
    num, cnt = np.zeros(m.size), np.zeros(m.size)
    for i, mm in enumerate(m.tolist()):
        lv = by_m.get(int(mm))
        if lv is None or lv.z.size < d:
            continue
        q = lv.d1 if d == 2 else lv.d2
        num[i] = q / ((2.0 if d == 2 else 6.0) * float(mm) * float(mm))
        cnt[i] = lv.z.size + 1 - d
    return num, cnt


def segment_sums(
    name: str, x: FloatArray, tau0_s: float, m: IntArray
) -> tuple[FloatArray, FloatArray]:
    """(numerator, terms) per m for one gap-free stretch of phase ``x``: the variance is
    numerator / terms (for mtie the numerator is the MTIE itself and terms its window count).
    A factor beyond :func:`max_factor` (or below 1) gives (0, 0).

    Parameters
    ----------
    name : str
        Deviation name.
    x : numpy.ndarray
        Phase of one gap-free stretch [unit·s].
    tau0_s : float
        Sample interval [s].
    m : numpy.ndarray
        Averaging factors [samples].

    Returns
    -------
    tuple of numpy.ndarray
        (numerator, terms) per factor.
    """
    num = np.zeros(m.size)
    cnt = np.zeros(m.size)
    n = x.size
    ok = np.flatnonzero((m >= 1) & (m <= max_factor(name, n)))
    if name == "htotdev":  # m = 1 is ohdev (as Stable32)
        one = ok[m[ok] == 1]
        num[one], cnt[one] = segment_sums("ohdev", x, tau0_s, m[one])
        ok = ok[m[ok] > 1]
    if name in _FAST and ok.size:
        sums, terms = _fast_sums(name, x, m[ok])
        tau = np.asarray(m[ok] * float(tau0_s), dtype=np.float64)
        scale = {"adev": 2.0, "oadev": 2.0, "totdev": 2.0, "hdev": 6.0, "ohdev": 6.0}
        if name in scale:
            num[ok] = sums / (scale[name] * tau * tau)
        elif name == "mdev":
            num[ok] = sums / (2.0 * m[ok] ** 2 * tau * tau)
        elif name == "tdev":
            num[ok] = sums / (6.0 * m[ok] ** 2)  # τ²/3 · Mod σ²
        else:  # tierms
            num[ok] = sums
        cnt[ok] = terms
        return num, cnt
    if name in ("mtotdev", "ttotdev", "htotdev"):  # every factor at once, two at a time
        z = np.diff(x) / tau0_s if name == "htotdev" else x
        tot = _total.tot_sums(z, [int(v) for v in m[ok]])
    for i in ok.tolist():
        mm = int(m[i])
        tau_s = mm * tau0_s
        if name in ("mtotdev", "ttotdev"):
            s, k = tot.pop(0)
            val = s / (2.0 * tau_s * tau_s)
            num[i], cnt[i] = (val * tau_s * tau_s / 3.0 if name == "ttotdev" else val), k
        elif name == "htotdev":
            s, k = tot.pop(0)
            num[i], cnt[i] = s / 6.0, k
        elif name == "theo1":
            if mm % 2:
                continue
            num[i], cnt[i] = _theo1_sum(x, mm) / (0.75 * tau_s * tau_s), n - mm
        elif name == "mtie":
            w = mm + 1
            # window [k, k + m]: the filters centre their window; shift it to start at k
            hi = ndimage.maximum_filter1d(x, w, origin=-(w // 2))
            lo = ndimage.minimum_filter1d(x, w, origin=-(w // 2))
            k = n - mm
            num[i], cnt[i] = float(np.max(hi[:k] - lo[:k])), k
        else:
            raise ValueError(f"unknown deviation {name!r}")
    return num, cnt


def pool(
    name: str, parts: list[tuple[FloatArray, FloatArray]], size: int
) -> tuple[FloatArray, FloatArray]:
    """Deviation and term count per m from the stretches' (numerator, terms).

    Parameters
    ----------
    name : str
        Deviation name.
    parts : list of tuple
        (numerator, terms) of each stretch.
    size : int
        Number of factors.

    Returns
    -------
    tuple of numpy.ndarray
        Deviation [unit] and term count per factor.
    """
    num = np.zeros(size)
    cnt = np.zeros(size)
    for a, b in parts:
        if name == "mtie":
            num = np.maximum(num, np.where(b > 0, a, 0.0))
        else:
            num += a
        cnt += b
    with np.errstate(invalid="ignore", divide="ignore"):
        if name == "mtie":
            dev = np.where(cnt > 0, num, np.nan)
        else:
            dev = np.where(cnt > 0, np.sqrt(num / np.where(cnt > 0, cnt, 1.0)), np.nan)
    return np.asarray(dev, dtype=np.float64), cnt


def theo1_tau(m: npt.ArrayLike, tau0_s: float) -> FloatArray:
    r"""Theo1's averaging time τ = 0.75 m τ0 [s].

    Parameters
    ----------
    m : array_like
        Even averaging factors [samples].
    tau0_s : float
        Sample interval [s].

    Returns
    -------
    numpy.ndarray
        Averaging times τ [s].

    Notes
    -----
    .. math:: \tau = 0.75\, m \tau_0

    References
    ----------
    - NIST SP 1065 (Riley 2008), eq. 30 (Theo1).
    """
    return np.asarray(0.75 * np.asarray(m, dtype=np.float64) * tau0_s)


def as_phase(values: FloatArray, tau0_s: float, data_type: str, offset: float = 0.0) -> FloatArray:
    r"""Phase points of one stretch: rate y → x_k = τ0 Σ_{i<k} (y_i − offset) (N = n + 1);
    phase as given, copied (``offset`` unused; the copy may be centred in place).

    Parameters
    ----------
    values : numpy.ndarray
        Rate [unit] or phase [unit·s] samples.
    tau0_s : float
        Sample interval [s].
    data_type : str
        ``"rate"`` (frequency) or ``"phase"``.
    offset : float, optional
        Rate subtracted before integrating [unit] (default 0).

    Returns
    -------
    numpy.ndarray
        Phase points [unit·s].

    Notes
    -----
    .. math:: x_k = \tau_0 \sum_{i<k} (y_i - \text{offset})
    """
    if data_type == "phase":
        return np.array(values, dtype=np.float64)
    x = np.empty(values.size + 1)
    x[0] = 0.0
    np.subtract(values, offset, out=x[1:])
    np.cumsum(x[1:], out=x[1:])
    x *= tau0_s
    return x


def centred(x: FloatArray, *, inplace: bool = False) -> FloatArray:
    """x minus the straight line through its end points: every variance here cancels a linear
    phase (a constant rate) exactly; removing it keeps the sums free of rounding growth.
    ``inplace``: in ``x``'s own buffer.  The result's first point is exactly 0.

    Parameters
    ----------
    x : numpy.ndarray
        Phase points [unit·s].
    inplace : bool, optional
        Work in ``x``'s buffer (default False).

    Returns
    -------
    numpy.ndarray
        Phase minus the line through its end points [unit·s].
    """
    if x.size < 2:
        return x
    x0 = float(x[0])
    slope = (float(x[-1]) - x0) / (x.size - 1)
    out = x if inplace else np.empty_like(x)
    line = np.empty(min(_CHUNK, x.size))
    for a in range(0, x.size, _CHUNK):  # in blocks: no array of n indices
        b = min(a + _CHUNK, x.size)
        seg = line[: b - a]
        np.multiply(_INDEX[: b - a] + a, slope, out=seg)
        seg += x0
        np.subtract(x[a:b], seg, out=out[a:b])
    out[0] = 0.0
    return out


__all__ = [
    "as_phase",
    "centred",
    "max_factor",
    "octave_levels",
    "octave_sums",
    "pool",
    "segment_sums",
    "theo1_tau",
    "work",
]
