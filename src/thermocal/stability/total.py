r"""The total family's sums (MTOT, TTOT, HTOT) in O(N log m) per averaging factor.

NIST SP 1065 eq. 27 (Riley 2008; Howe & Vernotte's modified total variance): for each of the
N − 3m + 1 subsequences ``w_i = z_{n+i}`` (i < 3m) of a series ``z`` (phase for MTOT and
TTOT, the rate for HTOT, eq. 29), the linear trend fitted by its half means is removed, the
result is extended by even reflection at both ends to 9m points ``ξ_p`` and the 6m modified
second differences of m-point averages are squared and averaged:

.. math::

    T(m) = \sum_{n=0}^{N-3m} \frac{1}{6m} \sum_{j=0}^{6m-1} v_j(n)^2, \qquad
    v_j = \frac{1}{m^2} \sum_{t=0}^{3m-1} g_t\, \xi_{j+t},

with ``g_t`` = 1, −2, 1 on ``t`` in [0, m), [m, 2m), [2m, 3m).  A direct evaluation costs
O(m) per subsequence, O(N·m) per factor.  Here (:func:`tot_sum`):

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
D. A. Howe and F. Vernotte, "Generalization of the total variance approach to the modified
Allan variance", Proc. 31st PTTI Meeting (1999).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Final

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule

signal = LazyModule("scipy.signal")

FloatArray = npt.NDArray[np.float64]

_SPANS: Final = 3
"""Subsequences per row, in units of the subsequence length 3m (rows of 4 spans of data)."""

_ELEMENTS: Final = 1 << 21
"""Data elements per chunk of rows (bounds the temporaries)."""

_Terms = list[tuple[float, int, int]]


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


def _regime_sum(pp: FloatArray, terms: _Terms, j0: int, j1: int, ln: int, lb: int) -> float:
    """Σ_rows Σ_{n<ln} Σ_{j0≤j≤j1} (A(n+j) + B(n−j) + C(n))² from the rows' P (``pp``)."""
    rows = pp.shape[0]
    nj = j1 - j0 + 1
    ra = np.arange(j0, lb + j1)  # r = n + j
    sa = np.arange(-j1, lb - j0)  # s = n − j
    a = np.zeros((rows, ra.size))
    b = np.zeros((rows, sa.size))
    c = np.zeros((rows, ln))
    for coef, kap, sig in terms:
        if sig > 0:
            a += coef * pp[:, j0 + kap : j0 + kap + ra.size]
        elif sig < 0:
            b += coef * pp[:, kap - j1 : kap - j1 + sa.size]
        else:
            c += coef * pp[:, kap : kap + ln]
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
    total += 2.0 * float(np.einsum("ij,ij->", a[:, ok], cross))
    return total


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
    xc = signal.fftconvolve(zr[:, : ln + 3 * m - 1], c[None, ::-1], mode="valid", axes=1)
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
    z = np.ascontiguousarray(z, dtype=np.float64)
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
