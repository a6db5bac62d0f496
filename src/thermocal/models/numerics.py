"""Numerical helpers of the one-temperature families (warm-up and bank): least squares by
the SVD with its rank and condition (:func:`lstsq_svd`), the temperature channel a model
reads (:func:`channel_index`, :func:`single_channel`), Horner evaluation and the running
start-window mean of a power-on (:func:`running_start_mean`).
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
from numpy.polynomial import polynomial as npoly

from thermocal.errors import (
    ExtrapolationWarning,
    ThermocalInputError,
)
from thermocal.models.rundata import RunData
from thermocal.recording import FloatArray

RANK_RTOL = 1e-12
"""Singular values below ``RANK_RTOL × s_max`` make a design singular (DesignError)."""


# --- shared numerical helpers (also used by the bank family) ------------------------------


@dataclasses.dataclass(frozen=True)
class LstsqResult:
    """Solution of ``min ‖X c − y‖₂`` by SVD.

    ``coef`` (p,) or (p, q); ``cov_unit`` = (XᵀX)⁻¹ = V S⁻² Vᵀ (from the SVD, no
    explicit inverse of XᵀX), multiply by s² for the covariance; ``sigma2`` the
    residual variance s² = ‖r‖²/(n − p) per column (NaN when n = p);
    Attributes
    ----------
    coef : numpy.ndarray
        Coefficients (p,) or (p, q).
    cov_unit : numpy.ndarray
        :math:`(X^\\top X)^{-1} = V S^{-2} V^\\top` (from the SVD, no explicit inverse);
        multiply by s² for the covariance.
    sigma2 : numpy.ndarray
        Residual variance :math:`s^2 = \\lVert r\\rVert^2/(n - p)` per column (NaN when n = p).
    condition_number : float
        :math:`s_\\max / s_\\min`.
    rank : int
        Numerical rank.
    dof : int
        n − p.
    null_columns : tuple of int
        Columns most involved in the null space (empty when full rank).
    """

    coef: FloatArray
    cov_unit: FloatArray
    sigma2: FloatArray
    condition_number: float
    rank: int
    dof: int
    null_columns: tuple[int, ...]


def lstsq_svd(x: FloatArray, y: FloatArray) -> LstsqResult:
    """Least squares ``c = V S⁻¹ Uᵀ y`` through the thin SVD ``X = U S Vᵀ``.

    Covariance of the coefficients ``cov = s² V S⁻² Vᵀ`` with
    ``s² = ‖y − Xc‖²/(n − p)`` (Golub & Van Loan, *Matrix Computations*, §5.5).
    A rank-deficient design is not solved: ``rank < p`` and ``null_columns``
    tell the caller which terms to name in its :class:`DesignError`.

    Parameters
    ----------
    x : numpy.ndarray
        Design X, shape (n, p).
    y : numpy.ndarray
        Targets, shape (n,) or (n, q).

    Returns
    -------
    LstsqResult

    Notes
    -----
    .. math:: c = V S^{-1} U^\\top y, \\qquad \\mathrm{cov}(c) = s^2 V S^{-2} V^\\top

    References
    ----------
    - Golub, G. H. & Van Loan, C. F. (2013). *Matrix Computations*, 4th ed., Johns Hopkins
      University Press, §5.5.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.column_stack([np.ones(5), np.arange(5.0)])
    >>> res = lstsq_svd(x, 1.0 + 2.0 * np.arange(5.0))
    >>> np.round(res.coef, 6).tolist(), res.rank, res.dof
    ([1.0, 2.0], 2, 3)
    """
    n, p = x.shape
    u, s, vt = np.linalg.svd(x, full_matrices=False)
    smax = float(s[0]) if s.size else 0.0
    tol = RANK_RTOL * smax
    rank = int(np.count_nonzero(s > tol)) if smax > 0 else 0
    if rank < p:
        # columns with the largest weight in the weakest right singular vectors
        weak = vt[rank:] if rank < vt.shape[0] else vt[-1:]
        w = np.abs(weak).max(axis=0)
        null = tuple(int(i) for i in np.flatnonzero(w > 0.1 * w.max()))
        nan = np.full((p, *y.shape[1:]), np.nan)
        return LstsqResult(
            nan, np.full((p, p), np.nan), np.full(y.shape[1:], np.nan), math.inf, rank, n - p, null
        )
    uty = u.T @ y
    coef = vt.T @ (uty / s[:, None] if y.ndim == 2 else uty / s)
    resid = y - x @ coef
    dof = n - p
    sigma2 = (
        np.asarray(np.sum(resid**2, axis=0) / dof, dtype=np.float64)
        if dof > 0
        else np.full(y.shape[1:], np.nan)
    )
    vs = vt.T / s
    cov_unit = vs @ vs.T
    return LstsqResult(
        np.asarray(coef, dtype=np.float64),
        np.asarray(cov_unit, dtype=np.float64),
        sigma2,
        smax / float(s[-1]),
        rank,
        dof,
        (),
    )


def channel_index(family: str, run: RunData, sensor: int, fitted_name: str | None = None) -> int:
    """Column of ``run.temps_c`` a single-channel model uses.

    The fitted channel's name when the run has it, else the only column, else
    column ``sensor`` (0 = the first named temperature channel).

    Parameters
    ----------
    family : str
        The family's name, for messages.
    run : RunData
        The run.
    sensor : int
        0-based column index used when the name does not decide.
    fitted_name : str, optional
        The fitted channel's name.

    Returns
    -------
    int

    Raises
    ------
    thermocal.errors.ThermocalInputError
        ``sensor`` beyond the run's temperature columns.
    """
    k = run.temps_c.shape[1]
    if fitted_name is not None:
        if fitted_name in run.temp_names:
            return run.temp_names.index(fitted_name)
        if k == 1:
            return 0
    if not 0 <= sensor < k:
        names = ", ".join(run.temp_names) or f"{k} unnamed"
        raise ThermocalInputError(
            f"{family}: temperature channel index sensor={sensor} does not exist in "
            f"{run.name or 'run'} (channels: {names})"
        )
    return sensor


def single_channel(run: RunData, col: int) -> RunData:
    """A copy of ``run`` holding only temperature column ``col``.

    Parameters
    ----------
    run : RunData
        The run.
    col : int
        The column to keep.

    Returns
    -------
    RunData
    """
    name = run.temp_names[col] if col < len(run.temp_names) else f"T{col + 1}"
    return dataclasses.replace(run, temps_c=run.temps_c[:, [col]], temp_names=(name,))


def horner(coef: FloatArray, x: FloatArray) -> FloatArray:
    """``Σ_k coef[k] x^k`` by Horner's rule (same operations for arrays and scalars).

    Parameters
    ----------
    coef : numpy.ndarray
        Coefficients, lowest power first.
    x : numpy.ndarray or float
        Where to evaluate.

    Returns
    -------
    numpy.ndarray or float

    Notes
    -----
    .. math:: p(x) = c_0 + x (c_1 + x (c_2 + \\dots))

    Examples
    --------
    >>> import numpy as np
    >>> horner(np.array([1.0, 2.0, 3.0]), np.array([0.0, 1.0, 2.0])).tolist()
    [1.0, 6.0, 17.0]
    """
    out = np.full_like(x, coef[-1])
    for c in coef[-2::-1]:
        out = out * x + c
    return out


def _clamp_range(
    values: FloatArray, lo: float, hi: float, what: str, *, extrapolate: bool
) -> FloatArray:
    below = values < lo
    above = values > hi
    if below.any() or above.any():
        n = int(np.count_nonzero(below | above))
        action = "extrapolating" if extrapolate else "clamped to the fitted range"
        warnings.warn(
            f"{n} samples with {what} {float(values.min()):.2f}…{float(values.max()):.2f} °C "
            f"outside the fitted {lo:.2f}…{hi:.2f} °C; {action}",
            ExtrapolationWarning,
            stacklevel=4,
        )
        if not extrapolate:
            return np.clip(values, lo, hi)
    return values


def _window_count(time_s: FloatArray, window_s: float) -> int:
    """Number of samples in the start window ``t − t_first < window_s`` (≥ 1)."""
    return max(1, int(np.count_nonzero(time_s - time_s[0] < window_s)))


def running_start_mean(time_s: FloatArray, x: FloatArray, window_s: float) -> FloatArray:
    """Causal start value of every sample: the running mean over the start window,
    frozen once the window is full ([Seed-Plan]; causal)::

        x0_i = (1/(i+1)) Σ_{k≤i} x_k   for i < m,     x0_i = x0_{m−1}   for i ≥ m

    with m the number of samples with ``t − t_first < window_s``.  The sums are
    sequential (``np.cumsum``), as in the streaming twin.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    x : numpy.ndarray
        Values (temperature [°C] or output [signal unit]).
    window_s : float
        Start window [s].

    Returns
    -------
    numpy.ndarray
        x0 per sample, the unit of ``x``.

    References
    ----------
    - *Temperature-characteristic calibration test plan* (a MEMS sensor's power-on warm-up
      tests and model).

    Examples
    --------
    >>> import numpy as np
    >>> running_start_mean(np.arange(5.0), np.array([1.0, 3.0, 5.0, 7.0, 9.0]), 2.0).tolist()
    [1.0, 2.0, 2.0, 2.0, 2.0]
    """
    m = _window_count(time_s, window_s)
    cs = np.cumsum(x[:m]) / np.arange(1, m + 1, dtype=np.float64)
    out = np.empty_like(x)
    out[:m] = cs
    out[m:] = cs[-1]
    return out


def _poly_shift_matrix(mu: float, sigma: float, n: int) -> FloatArray:
    """M with ``Σ_k c_k ((x − μ)/σ)^k = Σ_k (M c)_k x^k`` (binomial expansion)."""
    m = np.zeros((n, n))
    base = np.array([-mu / sigma, 1.0 / sigma])
    for k in range(n):
        pk = npoly.polypow(base, k) if k else np.array([1.0])
        m[: pk.size, k] = pk
    return m
