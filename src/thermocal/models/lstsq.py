"""Least squares in chunks (the polynomial model's numerics): a design reduced to its
triangular factor (:mod:`thermocal.models.reduction`, Gram/Cholesky or Householder QR) is
solved here by the SVD of the column-equilibrated factor, with condition numbers and
standard errors, and terms are selected forward (BIC or hold-out).

Used by the polynomial and piecewise families (:mod:`thermocal.models.poly_fit`,
:mod:`thermocal.models.piecewise_lines`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule
from thermocal.errors import DesignError, ThermocalInputError
from thermocal.models.reduction import (
    Reduced,
    column_scales,
    scaled_condition,
    triangularise,
)
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from scipy import linalg as sla
    from scipy.linalg import blas, lapack
else:
    sla = LazyModule("scipy.linalg")
    blas = LazyModule("scipy.linalg.blas")
    lapack = LazyModule("scipy.linalg.lapack")

SINGULAR_RCOND = 1.0e-11
"""``s_min/s_max`` below this: the design is singular → :class:`DesignError`."""


# --- solving the reduced design ----------------------------------------------------------


@dataclass(frozen=True)
class LstsqSolution:
    """Solution of a column-scaled least-squares problem from its R factor.

    Attributes
    ----------
    coef : numpy.ndarray
        Coefficients (q,) in the original column units.
    cov : numpy.ndarray
        Their covariance (q, q).
    rss : float
        Residual sum of squares (ridge and truncation included) [target unit²].
    n : int
        Rows.
    dof : int
        n − rank.
    condition_number : float
        κ₂ of the equilibrated design.
    rank : int
        Singular values kept.
    n_truncated : int
        Singular values dropped.
    singular_values : numpy.ndarray
        Of the equilibrated R, descending.
    extra : dict
        Solver details.

    Examples
    --------
    A line fitted from the R factor agrees with :func:`numpy.linalg.lstsq`:

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> x = rng.random(200)
    >>> a = np.column_stack([x, np.ones_like(x)])
    >>> y = 2.0 * x + 0.5 + 0.01 * rng.standard_normal(200)
    >>> sol = solve_r(np.linalg.qr(np.column_stack([a, y]), mode="r"), 200, ["x", "const"])
    >>> np.round(sol.coef, 3).tolist(), sol.dof
    ([1.997, 0.5], 198)
    >>> np.round(np.linalg.lstsq(a, y, rcond=None)[0], 3).tolist()
    [1.997, 0.5]
    """

    coef: FloatArray
    cov: FloatArray
    rss: float
    n: int
    dof: int
    condition_number: float
    rank: int
    n_truncated: int
    singular_values: FloatArray
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def sigma2(self) -> float:
        """Residual variance :math:`\\hat\\sigma^2 = \\mathrm{RSS}/\\mathrm{dof}` (NaN at dof 0)."""
        return self.rss / self.dof if self.dof > 0 else math.nan


def singular_error(
    r: FloatArray, names: Sequence[str], *, rcond: float = SINGULAR_RCOND
) -> DesignError | None:
    """A :class:`DesignError` naming the columns of a (near-)singular design, or None.

    Parameters
    ----------
    r : numpy.ndarray
        Upper-triangular R of the design, shape (q, q).
    names : sequence of str
        Column names.
    rcond : float, optional
        Singular when :math:`s_\\min < \\mathrm{rcond}\\, s_\\max`.  Default
        :data:`SINGULAR_RCOND`.

    Returns
    -------
    thermocal.errors.DesignError or None
    """
    q = r.shape[1]
    if q == 0:
        return None
    rs = r / column_scales(r)[None, :]
    _u, sv, vt = np.linalg.svd(rs)
    if sv.size < q:
        sv = np.r_[sv, np.zeros(q - sv.size)]
    if sv[-1] > rcond * sv[0]:
        return None
    null = vt[-1]
    big = np.flatnonzero(np.abs(null) > 0.1 * np.max(np.abs(null)))
    involved = [names[int(i)] for i in big]
    zero_cols = [names[i] for i in range(q) if not np.any(r[:, i])]
    if zero_cols:
        return DesignError(
            "singular design: column(s) " + ", ".join(zero_cols) + " are zero over the fitted data"
        )
    return DesignError(
        "singular design (condition number "
        + (f"{sv[0] / sv[-1]:.3g}" if sv[-1] > 0 else "∞")
        + "): these terms are linearly dependent in the data: "
        + ", ".join(involved)
        + "; drop one of them or add data that separates them"
    )


def _filtered_svd(
    R22: FloatArray,
    z2: FloatArray,
    n: int,
    ridge: float,
    rcond: float | None,
    noise_threshold: float | None,
    sigma_full: float,
) -> tuple[FloatArray, npt.NDArray[np.bool_], FloatArray]:
    """The penalised part of :func:`solve_r`: ``R22 = U S Vᵀ``, the components kept
    (``s_i > rcond · s_max``, or ``|c_i| > k σ̂`` with ``c = Uᵀ z2``) and the map
    ``H = V diag(s_i/(s_i² + nα)) Uᵀ`` with ``γ_P = H z2``; returns (H, kept, s)."""
    np_ = R22.shape[0]
    H = np.zeros((np_, np_))
    keep = np.zeros(np_, dtype=bool)
    sv = np.zeros(0)
    if np_:
        U, S, Vt = np.linalg.svd(R22)
        sv = S
        c = U.T @ z2
        keep = np.greater(S, (rcond or 0.0) * S[0])
        if noise_threshold is not None and math.isfinite(sigma_full):
            # a small-s_i component stays when the data along it stand out of the noise
            strong = np.abs(c) > noise_threshold * sigma_full
            keep |= strong & np.greater(S, SINGULAR_RCOND * S[0])
        f = np.zeros_like(S)
        f[keep] = S[keep] / (S[keep] ** 2 + n * ridge)
        H = (Vt.T * f) @ U.T  # γ_P = H z2
    return H, keep, sv


def _free_part(
    R11: FloatArray, R12: FloatArray, z1: FloatArray, H: FloatArray, gamma_p: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The free part of :func:`solve_r`: ``γ_U = R11⁻¹ (z1 − R12 γ_P)`` and the linear map
    ``L`` from ``[z1; z2]`` to ``γ`` (for the covariance); returns (γ_U, L)."""
    nu = R11.shape[0]
    if not nu:
        return np.zeros(0), H
    qq = nu + H.shape[0]
    Linv_u = sla.solve_triangular(R11, np.eye(nu), lower=False)
    gamma_u = Linv_u @ (z1 - R12 @ gamma_p)
    Lmap = np.zeros((qq, qq))
    Lmap[:nu, :nu] = Linv_u
    Lmap[:nu, nu:] = -Linv_u @ R12 @ H
    Lmap[nu:, nu:] = H
    return gamma_u, Lmap


def solve_r(
    r_aug: FloatArray,
    n: int,
    names: Sequence[str],
    *,
    penalised: npt.NDArray[np.bool_] | None = None,
    ridge: float = 0.0,
    rcond: float | None = None,
    noise_threshold: float | None = None,
    columns: Sequence[int] | None = None,
) -> LstsqSolution:
    """Least squares from the augmented R factor of ``[A | y]``, columns equilibrated.

    The columns are scaled to unit RMS (``A_s = A D``) and split into the free
    ones (U: constant, per-run offsets) and the regularised ones (P: the
    ``penalised`` terms).  A QR of ``[A_s,U  A_s,P | y]`` (from R, never from
    the data again) gives ``R11, R12, R22, z1, z2``; the P part is solved by SVD,
    ``R22 = U S Vᵀ``, ``c = Uᵀ z2``::

        γ_P = Σ_{kept i} v_i c_i s_i/(s_i² + nα),     γ_U = R11⁻¹ (z1 − R12 γ_P)

    (ridge α ≥ 0 shrinks only the P coefficients; Golub & Van Loan §6.1.4).  Component i
    is kept when ``s_i > rcond · s_max`` (truncated SVD) or, with ``noise_threshold`` k,
    when ``|c_i| > k σ̂`` — its share of the data stands out of the noise (σ̂² = RSS/(n − q)
    of the full fit; a discrete Picard rule, Hansen, *Rank-Deficient and Discrete
    Ill-Posed Problems*, SIAM 1998, §3.2).  ``β = D γ``; ``cov(β) = σ² D L Lᵀ D`` with L
    the linear map from ``[z1; z2]`` to γ (triangular solves, no inverse of AᵀA).
    Residuals are assumed white; with coloured noise the standard errors are optimistic.

    Parameters
    ----------
    r_aug, n, names : numpy.ndarray, int, sequence of str
        R factor of ``[A | y]`` (q+1, q+1), rows of A, column names (for messages).
    penalised, ridge, rcond, noise_threshold, columns : optional
        P-column mask, α ≥ 0, truncation ratio, k, column subset (in that order).

    Returns
    -------
    LstsqSolution

    Raises
    ------
    thermocal.errors.DesignError
        ``s_min < 1e-11 s_max``, naming the dependent columns.
    """
    q = r_aug.shape[1] - 1
    cols = list(range(q)) if columns is None else list(columns)
    pen_all = np.zeros(q, dtype=bool) if penalised is None else np.asarray(penalised, dtype=bool)
    if ridge < 0:
        raise ThermocalInputError(f"ridge α must be ≥ 0, got {ridge}")
    err = singular_error(r_aug[:, cols], [names[i] for i in cols])
    if err is not None:
        raise err
    free = [c for c in cols if not pen_all[c]]
    reg = [c for c in cols if pen_all[c]]
    order = free + reg
    R = r_aug[:, order]
    scale = column_scales(R) / math.sqrt(max(n, 1))  # RMS of each column
    Rs = R / scale[None, :]
    cond = scaled_condition(R)
    qq = len(order)
    nu = len(free)
    A2 = triangularise(np.column_stack([Rs, r_aug[:, q]]))
    R11 = A2[:nu, :nu]
    R12 = A2[:nu, nu:qq]
    R22 = A2[nu:qq, nu:qq]
    z1 = A2[:nu, qq]
    z2 = A2[nu:qq, qq]
    rss0 = float(A2[qq, qq] ** 2) if A2.shape[0] > qq else 0.0
    dof_full = n - qq
    sigma_full = math.sqrt(rss0 / dof_full) if dof_full > 0 else math.nan
    H, keep, sv = _filtered_svd(R22, z2, n, ridge, rcond, noise_threshold, sigma_full)
    gamma_p = H @ z2
    gamma_u, Lmap = _free_part(R11, R12, z1, H, gamma_p)
    gamma = np.r_[gamma_u, gamma_p]
    res2 = z2 - R22 @ gamma_p
    rss = rss0 + float(res2 @ res2)
    rank = nu + int(keep.sum())
    dof = n - rank
    sigma2 = rss / dof if dof > 0 else math.nan
    cov_g = sigma2 * (Lmap @ Lmap.T)
    coef_o = gamma / scale
    cov_o = cov_g / scale[:, None] / scale[None, :]
    # back to the order of ``cols``
    pos = [order.index(c) for c in cols]
    coef = coef_o[pos]
    cov = cov_o[np.ix_(pos, pos)]
    return LstsqSolution(
        coef=coef,
        cov=cov,
        rss=rss,
        n=n,
        dof=dof,
        condition_number=cond,
        rank=rank,
        n_truncated=int((~keep).sum()),
        singular_values=np.asarray(sv, dtype=np.float64),
        extra={"sigma_full": sigma_full},
    )


def subset_rss(r_aug: FloatArray, columns: Sequence[int]) -> tuple[float, FloatArray]:
    """RSS and coefficients of the least-squares fit on a column subset, from R_aug.

    ``‖y − A_S β‖² = ‖r_y − R_S β‖²`` where ``r_y`` is the last column of
    ``R_aug`` (Q orthogonal); solved by lstsq on the small matrix.

    Parameters
    ----------
    r_aug : numpy.ndarray
        R factor of ``[A | y]``, shape (q+1, q+1).
    columns : sequence of int
        The subset S.

    Returns
    -------
    rss : float
        Residual sum of squares [target unit²].
    beta : numpy.ndarray
        Coefficients of the columns of S.
    """
    q = r_aug.shape[1] - 1
    R = r_aug[:, list(columns)]
    z = r_aug[:, q]
    beta, _res, _rank, _sv = np.linalg.lstsq(R, z, rcond=None)
    res = z - R @ beta
    return float(res @ res), np.asarray(beta, dtype=np.float64)


def holdout_rss(r_aug_hold: FloatArray, columns: Sequence[int], beta: FloatArray) -> float:
    """``‖y_h − A_h,S β‖²`` of a held-out fold from its R factor.

    Parameters
    ----------
    r_aug_hold : numpy.ndarray
        R factor of the held-out fold's ``[A | y]``.
    columns : sequence of int
        The subset S.
    beta : numpy.ndarray
        Coefficients fitted on the other fold.

    Returns
    -------
    float
        Held-out residual sum of squares [target unit²].
    """
    q = r_aug_hold.shape[1] - 1
    res = r_aug_hold[:, q] - r_aug_hold[:, list(columns)] @ beta
    return float(res @ res)


@dataclass(frozen=True)
class Selection:
    """Result of forward stepwise selection: kept columns in the order added, and the path.

    Attributes
    ----------
    kept : list of int
        Columns kept, in the order added.
    path : list of dict
        Each step's column and score.
    method : str
        ``"bic"`` or ``"holdout"``.
    """

    kept: list[int]
    path: list[dict[str, Any]]
    method: str


def forward_select(
    red: Reduced,
    candidates: Sequence[int],
    required: Sequence[int],
    names: Sequence[str],
    method: Literal["bic", "holdout"] = "bic",
) -> Selection:
    """Forward stepwise term selection (by information criterion or validation error).

    Starting from the ``required`` columns (constant / per-run offsets), add at
    each step the candidate that lowers the score most; stop when none lowers
    it.  ``"bic"``: ``n ln(RSS/n) + k ln n`` on all data (Schwarz 1978,
    doi:10.1214/aos/1176344136); ``"holdout"``: RSS on fold 1 of a fit on fold 0
    (blocked hold-out; ``red`` must have two folds).

    Parameters
    ----------
    red : Reduced
        The reduced design (two folds for ``"holdout"``).
    candidates : sequence of int
        Columns that may be added.
    required : sequence of int
        Columns always kept.
    names : sequence of str
        Column names.
    method : {"bic", "holdout"}, optional
        Default ``"bic"``.

    Returns
    -------
    Selection

    Notes
    -----
    .. math:: \\mathrm{BIC} = n \\ln(\\mathrm{RSS}/n) + k \\ln n

    References
    ----------
    - Schwarz, G. (1978). Estimating the dimension of a model. *Annals of Statistics*
      6(2), 461–464, doi:10.1214/aos/1176344136.
    """
    kept: list[int] = list(required)
    remaining = [c for c in candidates if c not in kept]
    path: list[dict[str, Any]] = []
    if method == "bic":
        R = red.combined()
        n = red.n_total

        def score(cols: list[int]) -> float:
            rss, _ = subset_rss(R, cols)
            return n * math.log(max(rss, 1e-300) / n) + len(cols) * math.log(n)

    elif method == "holdout":
        if len(red.r_aug) != 2:
            raise ThermocalInputError("hold-out selection needs two folds")
        Rt, Rh = red.r_aug

        def score(cols: list[int]) -> float:
            _rss, beta = subset_rss(Rt, cols)
            return holdout_rss(Rh, cols, beta)

    else:
        raise ThermocalInputError(f"unknown selection method {method!r}; use bic or holdout")
    current = score(kept)
    path.append({"added": None, "score": current})
    while remaining:
        trials = [(score([*kept, c]), c) for c in remaining]
        best, c = min(trials)
        if not best < current:
            break
        kept.append(c)
        remaining.remove(c)
        current = best
        path.append({"added": names[c], "score": best})
    return Selection(kept=kept, path=path, method=method)
