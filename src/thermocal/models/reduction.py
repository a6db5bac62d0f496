"""Designs reduced to triangular factors in chunks (the polynomial and piecewise models'
numerics): each block of rows ``[F | 1 | Y]`` is folded into the factor ``R`` of the whole
design by a chunked Householder QR (R factors stacked and re-triangularised, LAPACK
``dgeqrf``) or by accumulating the Gram matrix ``AᵀA`` and taking its Cholesky factor (the
same R up to signs), kept only when the column-equilibrated design is well conditioned;
with the column scales and the scaled condition number of a factor.

References: Golub & Van Loan, *Matrix Computations*, 4th ed., §5.3; Fukaya et al. (2014)
for CholeskyQR.  The factors are solved in :mod:`thermocal.models.lstsq`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from thermocal._lazy import LazyModule
from thermocal.errors import DesignError, ThermocalInputError
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from scipy import linalg as sla
    from scipy.linalg import blas, lapack
else:
    sla = LazyModule("scipy.linalg")
    blas = LazyModule("scipy.linalg.blas")
    lapack = LazyModule("scipy.linalg.lapack")

GRAM_MAX_COND = 1.0e5
"""Largest condition number (column-equilibrated design) for which the Gram path is kept."""


Chunk = tuple[FloatArray, int, int]
"""``(A, group, fold)`` of one block of c rows: ``A`` (c, p + 1 + t), Fortran order, holds
``[F | 1 | Y]`` (the p features, a column of ones, the t ≥ 1 targets: several channels
sharing one design)."""


@dataclass(frozen=True)
class Reduced:
    """A design reduced to triangular form, per fold.

    Attributes
    ----------
    r_aug : list of numpy.ndarray
        Per fold f, the (q+t)×(q+t) upper-triangular factor of ``[F | Z | Y]`` (q = p
        features + m groups, t targets, usually 1).
    n : list of int
        Row count per fold.
    solver : str
        ``"qr"`` or ``"gram"``.
    """

    r_aug: list[FloatArray]
    n: list[int]
    solver: str

    def combined(self) -> FloatArray:
        """R factor of all folds together."""
        if len(self.r_aug) == 1:
            return self.r_aug[0]
        return triangularise(np.vstack(self.r_aug))

    @property
    def n_total(self) -> int:
        """Rows over all folds."""
        return int(sum(self.n))


def triangularise(a: FloatArray) -> FloatArray:
    """The upper-triangular factor R (q × q) of ``a`` (``AᵀA = RᵀR``), zero-padded when ``a``
    has fewer rows than columns.

    Parameters
    ----------
    a : numpy.ndarray
        A design or stacked R factors, shape (n, q).

    Returns
    -------
    numpy.ndarray
        R, shape (q, q).

    References
    ----------
    - Golub, G. H. & Van Loan, C. F. (2013). *Matrix Computations*, 4th ed., §5.2
      (Householder QR).
    """
    q = a.shape[1]
    if a.shape[0] == 0:
        return np.zeros((q, q))
    r = sla.qr(a, mode="r", check_finite=False)[0]
    out = np.zeros((q, q))
    m = min(r.shape[0], q)
    out[:m] = np.triu(r[:m])
    return out


def _accumulate_qr(
    chunks: Iterable[Chunk], p: int, m: int, n_folds: int, n_targets: int = 1
) -> tuple[list[list[FloatArray]], list[int]]:
    """R factors of ``[F | Z | y_j]`` per target and fold by a chunked Householder QR
    (TSQR-like): each chunk is stacked under the running R and re-triangularised (LAPACK
    ``dgeqrf``); one update per target, so each equals a one-target run."""
    q1 = p + m + 1
    r_acc = [[np.zeros((q1, q1), order="F") for _ in range(n_folds)] for _ in range(n_targets)]
    counts = [0] * n_folds
    buf: FloatArray | None = None
    for A, g, f in chunks:
        c = A.shape[0]
        if c == 0:
            continue
        rows = q1 + c
        if buf is None or buf.shape[0] != rows:
            buf = np.zeros((rows, q1), order="F")
        for j in range(n_targets):
            a = buf
            a[:q1] = r_acc[j][f]
            a[q1:, :p] = A[:, :p]
            a[q1:, p : p + m] = 0.0
            a[q1:, p + g] = 1.0
            a[q1:, p + m] = A[:, p + 1 + j]
            qr, _tau, _work, info = lapack.dgeqrf(a, lwork=max(1, q1 * 64), overwrite_a=1)
            if info != 0:
                raise DesignError(f"QR factorisation failed (LAPACK info {info})")
            r_acc[j][f] = np.asfortranarray(np.triu(qr[:q1]))
        counts[f] += c
    return [[np.ascontiguousarray(r) for r in rj] for rj in r_acc], counts


def _accumulate_gram(
    chunks: Iterable[Chunk], p: int, m: int, n_folds: int, n_targets: int = 1
) -> tuple[list[list[FloatArray]], list[int]]:
    """Gram matrices of ``[F | Z | y_j]`` per fold and target: ``[F | 1]ᵀ[F | 1]`` per
    (fold, group) once (BLAS ``dsyrk``, upper triangle), ``[F | 1]ᵀ y_j`` and ``y_jᵀ y_j``
    per target; returns ``grams[f][j]``."""
    t = n_targets
    q1 = p + m + 1
    xx = [[np.zeros((p + 1, p + 1)) for _ in range(m)] for _ in range(n_folds)]
    xy = [[np.zeros((p + 1, t)) for _ in range(m)] for _ in range(n_folds)]
    yy = [[np.zeros(t) for _ in range(m)] for _ in range(n_folds)]
    counts = [0] * n_folds
    for A, g, f in chunks:
        c = A.shape[0]
        if c == 0:
            continue
        X = np.asfortranarray(A[:, : p + 1])
        xx[f][g] += blas.dsyrk(1.0, X, trans=1, lower=0)
        for j in range(t):
            y = A[:, p + 1 + j]
            xy[f][g][:, j] += X.T @ y
            yy[f][g][j] += float(y @ y)
        counts[f] += c
    grams: list[list[FloatArray]] = []
    for f in range(n_folds):
        per_target = []
        for j in range(t):
            G = np.zeros((q1, q1))
            for g in range(m):
                P = np.triu(xx[f][g])
                P = P + np.triu(P, 1).T
                G[:p, :p] += P[:p, :p]
                G[:p, p + g] = P[:p, p]
                G[p + g, :p] = P[p, :p]
                G[p + g, p + g] = P[p, p]
                G[:p, q1 - 1] += xy[f][g][:p, j]
                G[q1 - 1, :p] += xy[f][g][:p, j]
                G[p + g, q1 - 1] = xy[f][g][p, j]
                G[q1 - 1, p + g] = xy[f][g][p, j]
                G[q1 - 1, q1 - 1] += yy[f][g][j]
            per_target.append(G)
        grams.append(per_target)
    return grams, counts


def _chol_r(G: FloatArray) -> FloatArray | None:
    """Upper Cholesky factor of an augmented Gram matrix, equilibrated; None if not PD."""
    d = np.sqrt(np.diag(G))
    if not np.all(d > 0):
        return None
    Gs = G / d[:, None] / d[None, :]
    try:
        Rs = sla.cholesky(Gs, lower=False, check_finite=False)
    except np.linalg.LinAlgError:
        return None
    R: FloatArray = Rs * d[None, :]
    return R


def accumulate_r(
    make_chunks: Callable[[], Iterator[Chunk]],
    p: int,
    m: int,
    *,
    n_folds: int = 1,
    solver: Literal["auto", "qr", "gram"] = "auto",
) -> Reduced:
    """Reduce the design ``[F | Z | y]`` to triangular factors, per fold, in chunks.

    ``make_chunks()`` yields :data:`Chunk` tuples (it is called a second time
    when the Gram path is abandoned for the QR path).  ``"auto"``: Gram path,
    kept when every fold's Cholesky succeeds and the column-equilibrated design
    has κ ≤ :data:`GRAM_MAX_COND`, else the chunked Householder QR.

    Parameters
    ----------
    make_chunks : callable
        Returns an iterator of :data:`Chunk` ``(A, group, fold)``.
    p : int
        Number of feature columns.
    m : int
        Number of groups (per-run offsets).
    n_folds : int, optional
        Folds (2 for a hold-out selection).  Default 1.
    solver : {"auto", "qr", "gram"}, optional
        Default ``"auto"``.

    Returns
    -------
    Reduced

    Notes
    -----
    Gram path: :math:`A^\\top A = R^\\top R` (Cholesky); QR path: :math:`A = QR`
    (Householder), both giving the same R up to rounding.

    References
    ----------
    - Golub, G. H. & Van Loan, C. F. (2013). *Matrix Computations*, 4th ed., Johns Hopkins
      University Press, §5.3 (the full-rank least-squares problem).
    """
    return accumulate_targets(make_chunks, p, m, 1, n_folds=n_folds, solver=solver)[0]


def accumulate_targets(
    make_chunks: Callable[[], Iterator[Chunk]],
    p: int,
    m: int,
    n_targets: int,
    *,
    n_folds: int = 1,
    solver: Literal["auto", "qr", "gram"] = "auto",
) -> list[Reduced]:
    """:func:`accumulate_r` for ``n_targets`` targets sharing one design (several channels):
    one :class:`Reduced` per target, each computed by the very operations a
    single target gets, so each equals its own one-target reduction bit for bit.

    Shared: the features of every chunk (built once by ``make_chunks``), the Gram matrix
    of ``[F | 1]`` (BLAS ``dsyrk``) and the Gram/QR decision; per target: ``[F | 1]ᵀ y`` and
    ``yᵀy`` (Gram path) or the Householder update (QR path, used for ill-conditioned
    designs).

    Parameters
    ----------
    make_chunks : callable
        Returns an iterator of :data:`Chunk` with ``n_targets`` target columns.
    p, m : int
        Feature columns and groups.
    n_targets : int
        Targets t sharing the design.
    n_folds : int, optional
        Default 1.
    solver : {"auto", "qr", "gram"}, optional
        Default ``"auto"``.

    Returns
    -------
    list of Reduced
        One per target.
    """
    if solver not in ("auto", "qr", "gram"):
        raise ThermocalInputError(f"unknown solver {solver!r}; use auto, qr or gram")
    if solver in ("auto", "gram"):
        grams, counts = _accumulate_gram(make_chunks(), p, m, n_folds, n_targets)
        reds: list[Reduced] = []
        for j in range(n_targets):
            rs = [_chol_r(G[j]) for G in grams]
            if not all(r is not None for r in rs):
                break
            reds.append(Reduced([r for r in rs if r is not None], counts, "gram"))
        if len(reds) == n_targets:
            cond = scaled_condition(reds[0].combined()[: p + m, : p + m])
            if solver == "gram" or cond <= GRAM_MAX_COND:
                return reds
        elif solver == "gram":
            raise DesignError(
                "the Gram matrix is not positive definite (singular design); use solver='qr' "
                "to find the terms at fault"
            )
    r_lists, counts = _accumulate_qr(make_chunks(), p, m, n_folds, n_targets)
    return [Reduced(r_list, counts, "qr") for r_list in r_lists]


def column_scales(r: FloatArray) -> FloatArray:
    """Column 2-norms of the design from its R factor (‖A e_j‖ = ‖R e_j‖).

    Parameters
    ----------
    r : numpy.ndarray
        Upper-triangular R of the design A, shape (q, q).

    Returns
    -------
    numpy.ndarray
        :math:`\\lVert A e_j \\rVert_2` per column, shape (q,); 1 for a zero column.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.random.default_rng(0).random((20, 2))
    >>> r = np.linalg.qr(a, mode="r")
    >>> bool(np.allclose(column_scales(r), np.linalg.norm(a, axis=0)))
    True
    """
    s = np.sqrt(np.sum(r * r, axis=0))
    out: FloatArray = np.where(s > 0, s, 1.0)
    return out


def scaled_condition(r: FloatArray) -> float:
    """2-norm condition number of the column-equilibrated design (from its R factor).

    Parameters
    ----------
    r : numpy.ndarray
        Upper-triangular R of the design, shape (q, q).

    Returns
    -------
    float
        :math:`\\kappa_2(A D) = s_\\max / s_\\min`, D the column scaling to unit norm.

    References
    ----------
    - Golub, G. H. & Van Loan, C. F. (2013). *Matrix Computations*, 4th ed., §2.6.2, §5.3.8.
    """
    rs = r / column_scales(r)[None, :]
    sv = np.linalg.svd(rs, compute_uv=False)
    if sv.size == 0 or sv[-1] <= 0:
        return math.inf
    return float(sv[0] / sv[-1])
