"""The bank's curve maths ([Seed-Accel]): the continuous piecewise-linear function and its
hat basis, the characteristic curves of the runs on a common temperature grid, their
distance and complete-linkage clustering, the range every run covers, the characteristic
lines a model is checked against and the least-squares fit of one group of runs.

Pure functions on arrays; :class:`thermocal.models.bank.BankModel` strings them together.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal._lazy import LazyModule
from thermocal.errors import DesignError
from thermocal.models.numerics import lstsq_svd
from thermocal.models.rundata import RunData
from thermocal.preprocess import segment_holds
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from scipy.cluster import hierarchy as _hierarchy
    from scipy.spatial import distance as _distance
else:
    _hierarchy = LazyModule("scipy.cluster.hierarchy")
    _distance = LazyModule("scipy.spatial.distance")


# --- pure functions --------------------------------------------------------------------------


def pwl_evaluate(breakpoints_c: FloatArray, values: FloatArray, temp_c: FloatArray) -> FloatArray:
    """Continuous piecewise-linear function through ``(x_j, v_j)`` at ``T``::

        f(T) = v_j + (v_{j+1} − v_j)/(x_{j+1} − x_j) · (T − x_j),   x_j ≤ T < x_{j+1}

    with the end segments extended linearly outside ``[x_0, x_K]`` (callers clamp
    first when they do not want to extrapolate).

    Parameters
    ----------
    breakpoints_c : numpy.ndarray
        Ascending breakpoints x_0 … x_K [°C].
    values : numpy.ndarray
        Value at each breakpoint [signal unit].
    temp_c : numpy.ndarray
        Temperatures T [°C].

    Returns
    -------
    numpy.ndarray
        f(T) [signal unit], the shape of ``temp_c``.

    References
    ----------
    - *Design and engineering implementation of a fibre-optic-gyro line-of-sight
      stabilisation system*, master's thesis, chapter 3 "Fibre-optic gyroscope".
    - *Adaptive accelerometer temperature compensation method for inertial navigation*,
      Chinese invention patent, filed 2019-10-29, published 2020-02-21.

    Examples
    --------
    >>> import numpy as np
    >>> pwl_evaluate(np.array([0.0, 10.0, 20.0]), np.array([0.0, 1.0, 3.0]),
    ...              np.array([5.0, 15.0, 25.0])).tolist()
    [0.5, 2.0, 4.0]
    """
    x = breakpoints_c
    j = np.clip(np.searchsorted(x, temp_c, side="right") - 1, 0, x.size - 2)
    slope = (values[j + 1] - values[j]) / (x[j + 1] - x[j])
    out: FloatArray = values[j] + slope * (temp_c - x[j])
    return out


def hat_basis(breakpoints_c: FloatArray, temp_c: FloatArray) -> FloatArray:
    """Design matrix (n, K+1) of the continuous piecewise-linear hat functions:
    column j is 1 at x_j, 0 at the other breakpoints, linear between (so the
    least-squares coefficients are the values at the breakpoints).

    Parameters
    ----------
    breakpoints_c : numpy.ndarray
        Ascending breakpoints, shape (K+1,) [°C].
    temp_c : numpy.ndarray
        Temperatures, shape (n,) [°C] (clamped to the breakpoints' range).

    Returns
    -------
    numpy.ndarray
        Shape (n, K+1); each row sums to 1.

    Examples
    --------
    >>> import numpy as np
    >>> hat_basis(np.array([0.0, 10.0, 20.0]), np.array([5.0])).tolist()
    [[0.5, 0.5, 0.0]]
    """
    x = breakpoints_c
    t = np.clip(temp_c, x[0], x[-1])
    j = np.clip(np.searchsorted(x, t, side="right") - 1, 0, x.size - 2)
    w = (t - x[j]) / (x[j + 1] - x[j])
    basis = np.zeros((t.size, x.size))
    rows = np.arange(t.size)
    basis[rows, j] = 1.0 - w
    basis[rows, j + 1] += w
    return basis


def binned_curve(
    temp_c: FloatArray, y: FloatArray, edges_c: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Bin means of ``y`` and ``T`` on temperature bins ``edges_c``: returns
    ``(mean_y, mean_T, count)`` per bin (NaN for an empty bin).

    Parameters
    ----------
    temp_c : numpy.ndarray
        Temperatures, shape (n,) [°C].
    y : numpy.ndarray
        Output, shape (n,) [signal unit].
    edges_c : numpy.ndarray
        Bin edges [°C], ascending.

    Returns
    -------
    mean_y : numpy.ndarray
        Bin means of y [signal unit].
    mean_T : numpy.ndarray
        Bin means of T [°C].
    count : numpy.ndarray
        Samples per bin.
    """
    nb = edges_c.size - 1
    idx = np.clip(np.searchsorted(edges_c, temp_c, side="right") - 1, 0, nb - 1)
    cnt = np.bincount(idx, minlength=nb).astype(np.float64)
    sy = np.bincount(idx, weights=y, minlength=nb)
    st = np.bincount(idx, weights=temp_c, minlength=nb)
    with np.errstate(invalid="ignore", divide="ignore"):
        return sy / cnt, st / cnt, cnt


def curve_distance(curves: FloatArray) -> FloatArray:
    """Pairwise max-deviation ``d_ij = max_b |c_i(b) − c_j(b)|`` over the bins where
    both runs have data (inf when they share none).

    Parameters
    ----------
    curves : numpy.ndarray
        Binned curves, shape (runs, bins) [signal unit], NaN where empty.

    Returns
    -------
    numpy.ndarray
        Distance matrix (runs, runs) [signal unit].

    Notes
    -----
    .. math:: d_{ij} = \\max_b |c_i(b) - c_j(b)|
    """
    diff = np.abs(curves[:, None, :] - curves[None, :, :])
    both = np.isfinite(diff)
    d = np.where(both, diff, -np.inf).max(axis=2)
    d[~both.any(axis=2)] = np.inf
    np.fill_diagonal(d, 0.0)
    return np.asarray(d, dtype=np.float64)


def cluster_runs(distance: FloatArray, threshold: float) -> list[list[int]]:
    """Complete-linkage agglomerative clustering: every pair inside a group is
    within ``threshold``.  Groups are ordered by their first run.

    Parameters
    ----------
    distance : numpy.ndarray
        Distance matrix (:func:`curve_distance`) [signal unit].
    threshold : float
        Largest distance inside a group [signal unit] (1 mg in the source document).

    Returns
    -------
    list of list of int
        Run indices per group.

    References
    ----------
    - *Adaptive accelerometer temperature compensation method for inertial navigation*,
      Chinese invention patent, filed 2019-10-29, published 2020-02-21.

    Examples
    --------
    >>> import numpy as np
    >>> d = np.array([[0.0, 0.1, 3.0], [0.1, 0.0, 3.1], [3.0, 3.1, 0.0]])
    >>> cluster_runs(d, 1.0)
    [[0, 1], [2]]
    """
    n = distance.shape[0]
    if n == 1:
        return [[0]]
    finite = np.where(np.isfinite(distance), distance, 1e300)
    z = _hierarchy.linkage(_distance.squareform(finite, checks=False), method="complete")
    labels = _hierarchy.fcluster(z, t=threshold, criterion="distance")
    groups: dict[int, list[int]] = {}
    for i, lab in enumerate(labels):
        groups.setdefault(int(lab), []).append(i)
    return sorted(groups.values(), key=lambda g: g[0])


def common_range(
    temps: list[FloatArray], labels: list[str], grid_step_c: float
) -> tuple[float, float]:
    """The temperature range every run covers, to within two grid steps [°C].

    Parameters
    ----------
    temps : list of numpy.ndarray
        Temperatures of each run [°C].
    labels : list of str
        The runs' names (for the message).
    grid_step_c : float
        Bin width of the characteristic curves [°C].

    Returns
    -------
    tuple of float
        ``(lo, hi)`` [°C].

    Raises
    ------
    thermocal.errors.DesignError
        Runs over different ranges, or a span of one grid step or less.
    """
    lo = np.array([t.min() for t in temps])
    hi = np.array([t.max() for t in temps])
    t_lo, t_hi = float(lo.min()), float(hi.max())
    slack = 2.0 * float(grid_step_c)
    short = [i for i in range(len(temps)) if lo[i] > t_lo + slack or hi[i] < t_hi - slack]
    if short:
        ranges = "; ".join(f"{labels[i]} {lo[i]:.1f}…{hi[i]:.1f} °C" for i in range(len(temps)))
        raise DesignError(
            f"bank: the runs cover different temperature ranges ({ranges}); every run "
            f"must cover {t_lo:.1f}…{t_hi:.1f} °C to within {slack:g} °C, because the "
            "characteristic curves are compared at the same temperatures"
        )
    if not t_hi - t_lo > grid_step_c:
        raise DesignError(
            f"bank: the runs span only {t_hi - t_lo:.2f} °C; at least more than one "
            f"grid step ({grid_step_c:g} °C) is needed"
        )
    return t_lo, t_hi


def characteristic_points(
    runs: Sequence[RunData],
    temps: Sequence[FloatArray],
    ys: Sequence[FloatArray],
    curves: FloatArray,
    curve_t: FloatArray,
    hold_min_s: float,
    grid_step_c: float,
) -> tuple[FloatArray, FloatArray, str]:
    """Characteristic lines of a group of runs: the means of its constant-temperature holds
    when they cover at least three temperatures, else the group's mean binned curve.

    Parameters
    ----------
    runs : sequence of RunData
        The group's runs.
    temps, ys : sequence of numpy.ndarray
        Temperature [°C] and target [signal unit] of each run.
    curves, curve_t : numpy.ndarray
        The group's binned curves [signal unit] and their bin temperatures [°C].
    hold_min_s : float
        Shortest hold used [s] (:func:`thermocal.preprocess.segment_holds`).
    grid_step_c : float
        Holds closer than this are one temperature [°C].

    Returns
    -------
    tuple
        Temperatures [°C], values [signal unit] and ``"holds"`` or ``"curve"``.
    """
    pts: list[tuple[float, float]] = []
    for r, t, y in zip(runs, temps, ys, strict=True):
        for seg in segment_holds(r.time_s, t, min_duration_s=hold_min_s):
            if seg.kind == "hold":
                pts.append((float(np.mean(t[seg.slice])), float(np.mean(y[seg.slice]))))
    if pts:
        arr = np.array(sorted(pts))
        # merge holds at the same temperature (within a grid step)
        split = np.flatnonzero(np.diff(arr[:, 0]) > grid_step_c) + 1
        groups = np.split(arr, split)
        if len(groups) >= 3:
            mt = np.array([g[:, 0].mean() for g in groups])
            my = np.array([g[:, 1].mean() for g in groups])
            return mt, my, "holds"
    ok = np.isfinite(curves).all(axis=0)
    return curve_t[:, ok].mean(axis=0), curves[:, ok].mean(axis=0), "curve"


def fit_group(
    g: list[int],
    one: list[RunData],
    temps: list[FloatArray],
    ys: list[FloatArray],
    labels: list[str],
    knots: FloatArray,
    curves: FloatArray,
    curve_t: FloatArray,
    *,
    error_metric: str,
    tolerance: float,
    hold_min_s: float,
    grid_step_c: float,
) -> tuple[dict[str, Any], FloatArray, FloatArray | None, float, tuple[float, int] | None]:
    """Steps 3–4 of the bank's fit for one group of runs: the piecewise-linear values at the
    knots (least squares on the group's samples, hat basis) and their fit error against the
    group's characteristic lines (:func:`characteristic_points`).

    Parameters
    ----------
    g : list of int
        Indices of the group's runs.
    one, temps, ys, labels : list
        Every run (one temperature channel), its temperatures [°C], targets [signal unit]
        and names.
    knots : numpy.ndarray
        Breakpoints [°C].
    curves, curve_t : numpy.ndarray
        Every run's binned curve [signal unit] and bin temperatures [°C].
    error_metric : {"max", "rms"}
        Fit error of model − characteristic line.
    tolerance : float
        A model is kept when its fit error is below this [signal unit].
    hold_min_s, grid_step_c : float
        As :func:`characteristic_points`.

    Returns
    -------
    tuple
        The group's entry (runs, fit error, check, points), the values at the knots
        [signal unit], their standard errors (None without residual degrees of freedom),
        the condition number and ``(RSS, n)`` of the samples when the fit error is below
        ``tolerance``, else None.

    Raises
    ------
    thermocal.errors.DesignError
        A knot without data.
    """
    nk = knots.size
    tg = np.concatenate([temps[i] for i in g])
    yg = np.concatenate([ys[i] for i in g])
    x = hat_basis(knots, tg)
    res = lstsq_svd(x, yg)
    if res.rank < nk:
        empty = [c for c in res.null_columns]
        where = ", ".join(f"{knots[c]:.1f} °C" for c in empty)
        raise DesignError(
            f"bank: group of {', '.join(labels[i] for i in g)}: no data to determine "
            f"the piecewise-linear value(s) at {where}; increase knot_spacing_c"
        )
    values = res.coef
    se = (
        np.sqrt(np.maximum(np.diag(res.cov_unit) * float(res.sigma2), 0.0)) if res.dof > 0 else None
    )
    # 4: check against the characteristic lines
    pts_t, pts_y, check = characteristic_points(
        [one[i] for i in g],
        [temps[i] for i in g],
        [ys[i] for i in g],
        curves[g],
        curve_t[g],
        hold_min_s,
        grid_step_c,
    )
    err = pts_y - pwl_evaluate(knots, values, pts_t)
    fit_error = (
        float(np.max(np.abs(err))) if error_metric == "max" else float(np.sqrt(np.mean(err**2)))
    )
    entry = {
        "runs": [labels[i] for i in g],
        "fit_error": fit_error,
        "check": check,
        "n_check_points": int(pts_t.size),
    }
    kept = None
    if fit_error < tolerance:
        r = yg - x @ values
        kept = (float(np.sum(r**2)), int(r.size))
    return entry, values, se, float(res.condition_number), kept
