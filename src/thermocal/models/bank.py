"""Adaptive model bank chosen at power-on ([Seed-Accel], accelerometers).

Run-to-run repeatability is poor, so one model does not fit every turn-on.  The
bank holds one continuous piecewise-linear model of the output against one
temperature channel per *characteristic curve*, and picks one at power-on.

Fit (``fit(runs)``; all thresholds are parameters, in the signal unit — mg for
accelerometers):

1. Every run is binned on a common temperature grid (``grid_step_c``, over the
   union of the runs' ranges; every run must cover that range to within
   2 × ``grid_step_c`` at each end, else :class:`~thermocal.errors.DesignError`):
   its characteristic curve is the bin means of the output (known input removed).
2. Runs are grouped by agglomerative clustering with complete (max-deviation)
   linkage on the distance ``d_ij = max_bins |c_i − c_j|``: runs whose curves
   differ by more than ``deviation`` at the same temperature are in distinct
   groups (our reading of "differ by more than 1 mg at the same temperature").
3. Per group, a continuous piecewise-linear least-squares fit to all the group's
   samples, breakpoints every ``knot_spacing_c`` over the common range (hat-function
   basis: the coefficients are the values at the breakpoints).
4. Check against the group's characteristic lines: the means of its constant-
   temperature holds (:func:`thermocal.preprocess.segment_holds`, ≥ ``hold_min_s``)
   when they cover ≥ 3 temperatures, else the group's binned curve.  Models whose
   fit error (``error_metric``: max or RMS of model − line) is below ``tolerance``
   form the bank; the others are reported as rejected.  No model within tolerance
   → :class:`~thermocal.errors.DesignError`.

Selection at power-on (``select``, ``predict``, ``stream``): with ``r_i = y_i −
f_m(T_i)`` the residual of model m on sample i (y = output, known input removed),
the deviation of model m after N start-up samples is::

    D_m(N) = | (1/N) Σ_{i<N} (y_i − f_m(T_i)) |

and the chosen model is ``argmin_m D_m``.  (Our reading) the seed smooths the
first n s of output with 1 s averages and compares with each model at the current
temperature; averaging the residual over every start-up sample so far is the same
comparison with stronger smoothing, and evaluates each model at each sample's own
temperature.  The clarity of the choice is the ``margin`` = runner-up − best
deviation.  Causality: while ``t − t_first < startup_s`` each sample uses the
selection from the samples so far (running); from the first sample with
``t − t_first ≥ startup_s`` the selection is frozen.  Gaps do not restart it
(only ``ModelStream.reset()``, a new power-on, does).  ``predict`` keeps the last
:class:`Selection` in ``selection_`` for reporting.

Out of range: the temperature is clamped to the fitted range with an
:class:`~thermocal.errors.ExtrapolationWarning`; with ``extrapolate=True`` the
end segments are extended linearly.

Learned state (``_state()``, the layout the C export reads)::

    {
      "sensor_name": "T1",                 # the temperature channel used
      "models": [                          # the bank, in selection-index order
        {"breakpoints_c": [x_0 … x_K],     # ascending [°C]
         "values": [v_0 … v_K],            # model value at each breakpoint [signal unit]
         "stderr": [...], "runs": [names], "fit_error": e, "check": "holds"|"curve",
         "n_check_points": p},
        ...
      ],
      "rejected": [{"runs": [...], "fit_error": e}, ...],
      "groups": [[run index, ...], ...],   # every characteristic curve found
      "startup_s": n, "deviation": d, "tolerance": tol
    }

Evaluation of model m (firmware twin): ``j`` = the segment holding T (clamped
to ``[x_0, x_K]``; the last segment for T = x_K), ``f = v_j + (v_{j+1} − v_j)/(x_{j+1} − x_j)
· (T − x_j)``.  Selection: keep ``Σ_i (y_i − f_m(T_i))`` and the count N per model
during the start-up window, choose ``argmin_m |Σ/N|`` (first index on ties).
"""

from __future__ import annotations

import bisect
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Self

import numpy as np

from thermocal._lazy import LazyModule
from thermocal.adequacy import Needs
from thermocal.errors import (
    ConditioningWarning,
    DesignError,
    ModelFileError,
    ThermocalInputError,
)
from thermocal.families import BANK, FamilyDeclaration
from thermocal.models.base import (
    ChunkContext,
    ClampOnce,
    ModelStream,
    TemperatureModel,
    stream_channel,
)
from thermocal.models.checks import (
    ascending,
    fields,
    key_path,
    list_of,
    number,
    same_length,
    sensor_param,
    string,
)
from thermocal.models.numerics import channel_index, lstsq_svd, single_channel
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData
from thermocal.models.warmup import CONDITION_WARN
from thermocal.preprocess import segment_holds
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from scipy.cluster import hierarchy as _hierarchy
    from scipy.spatial import distance as _distance
else:
    _hierarchy = LazyModule("scipy.cluster.hierarchy")
    _distance = LazyModule("scipy.spatial.distance")

ERROR_METRICS = ("max", "rms")


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


@dataclass(frozen=True)
class Selection:
    """The model chosen at power-on.

    Attributes
    ----------
    index : int
        Index of the chosen model in the bank.
    deviations : tuple of float
        D_m of every model [signal unit].
    margin : float
        Runner-up − best deviation [signal unit] (inf with one model).
    n_samples : int
        Start-up samples used.
    complete : bool
        True once the start-up window (``startup_s``) was full.
    """

    index: int
    deviations: tuple[float, ...]
    margin: float
    n_samples: int
    complete: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON form of the selection."""
        return {
            "index": self.index,
            "deviations": list(self.deviations),
            "margin": self.margin if math.isfinite(self.margin) else None,
            "n_samples": self.n_samples,
            "complete": self.complete,
        }


def _selection(dev: FloatArray, n: int, complete: bool) -> Selection:
    order = np.argsort(dev, kind="stable")
    best = int(np.argmin(dev))
    margin = float(dev[order[1]] - dev[best]) if dev.size > 1 else math.inf
    return Selection(best, tuple(float(v) for v in dev), margin, n, complete)


# --- the model ------------------------------------------------------------------------------


class BankModel(TemperatureModel):
    """Bank of piecewise-linear models, one per characteristic curve, chosen at
    power-on ([Seed-Accel]).

    Parameters
    ----------
    deviation : curves differing by more than this at the same temperature are
        distinct [signal unit] (seed: 1 mg).
    tolerance : keep a model whose fit error to its characteristic lines is below
        this [signal unit] (seed: 0.2 mg).
    startup_s : start-up window used to select the model [s] (seed: 20 s).
    sensor : index of the temperature channel (0 = first named channel).
    knot_spacing_c : breakpoint spacing of the piecewise-linear models [°C].
    grid_step_c : bin width of the curves compared in the clustering [°C].
    hold_min_s : shortest constant-temperature hold used as a characteristic point [s].
    error_metric : ``"max"`` or ``"rms"`` of model − characteristic line.

    Notes
    -----
    Each model :math:`f_m` of the bank is a continuous piecewise-linear function of one
    temperature; at power-on the model whose mean residual over the start-up samples is
    smallest is chosen,

    .. math::

        D_m(N) = \\Bigl| \\frac{1}{N} \\sum_{i<N} \\bigl(y_i - f_m(T_i)\\bigr) \\Bigr| ,
        \\qquad \\hat m = \\arg\\min_m D_m ,

    and the compensated output is :math:`F' = F - f_{\\hat m}(T)`.

    References
    ----------
    .. [1] *Adaptive accelerometer temperature compensation method for inertial
       navigation*, Chinese invention patent, published 2020 (docs/methods.md,
       Seed-Accel).

    Examples
    --------
    Four runs over −20…60 °C on two characteristic curves 3 mg apart; a power-on that
    reads 3.5 mg at 25 °C picks the second curve (3.025 + 0.02 · 25 mg):

    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.bank import BankModel
    >>> t = np.arange(0.0, 6000.0, 10.0)
    >>> temp = np.clip(-20.0 + t / 60.0, -20.0, 60.0)
    >>> runs = [RunData(t, temp[:, None], c + 0.02 * temp, ("T1",))
    ...         for c in (0.0, 0.05, 3.0, 3.05)]
    >>> model = BankModel(deviation=1.0, tolerance=0.2).fit(runs)
    >>> len(model.values_)
    2
    >>> on = RunData(np.arange(60.0), np.full((60, 1), 25.0), np.full(60, 3.5), ("T1",))
    >>> round(float(model.predict(on)[-1]), 3)
    3.525
    """

    declaration: ClassVar[FamilyDeclaration] = BANK
    uses_rate: ClassVar[bool] = False

    breakpoints_: list[FloatArray]
    values_: list[FloatArray]
    stderr_: list[FloatArray | None]
    model_info_: list[dict[str, Any]]
    rejected_: list[dict[str, Any]]
    groups_: list[list[int]]
    sensor_name_: str
    selection_: Selection

    def __init__(
        self,
        deviation: float = 1.0,
        tolerance: float = 0.2,
        startup_s: float = 20.0,
        sensor: int = 0,
        knot_spacing_c: float = 5.0,
        grid_step_c: float = 1.0,
        hold_min_s: float = 600.0,
        error_metric: str = "max",
    ) -> None:
        self.deviation = deviation
        self.tolerance = tolerance
        self.startup_s = startup_s
        self.sensor = sensor
        self.knot_spacing_c = knot_spacing_c
        self.grid_step_c = grid_step_c
        self.hold_min_s = hold_min_s
        self.error_metric = error_metric

    def data_needs(self, temp_names: Sequence[str], n_runs: int) -> Needs:
        """Each curve of the bank is judged as a line in its column.

        Parameters
        ----------
        temp_names : sequence of str
            The temperature columns.
        n_runs : int
            Number of runs.

        Returns
        -------
        thermocal.adequacy.Needs
        """
        j = self.sensor if 0 <= self.sensor < len(temp_names) else 0
        return Needs({temp_names[j]: 1} if temp_names else {}, 2)

    def chunk_context(self) -> ChunkContext:
        """The model is chosen from the first ``startup_s`` seconds after power-on."""
        w = float(self.startup_s)
        return ChunkContext(head_s=w if math.isfinite(w) else None, tail_s=0.0)

    def _check_params(self) -> None:
        for name in ("deviation", "tolerance", "startup_s", "knot_spacing_c", "grid_step_c"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and v > 0 and math.isfinite(v)):
                raise ThermocalInputError(f"bank: {name} must be a positive number, got {v!r}")
        if self.error_metric not in ERROR_METRICS:
            raise ThermocalInputError(
                f"bank: unknown error_metric {self.error_metric!r}; use one of "
                + ", ".join(ERROR_METRICS)
            )

    @property
    def n_models(self) -> int:
        """Number of models in the bank."""
        self.check_fitted()
        return len(self.values_)

    # -- fit --
    def fit(self, runs: Sequence[RunData]) -> Self:
        """Group the runs into characteristic curves, fit a piecewise-linear model
        per group and keep those within ``tolerance`` ([Seed-Accel], steps 1–3).

        Parameters
        ----------
        runs : sequence of RunData
            Power-ons with signal [signal unit, mg for accelerometers] over a common range.

        Returns
        -------
        BankModel
            ``self``, fitted.

        Raises
        ------
        thermocal.errors.DesignError
            Runs over different temperature ranges, or no curve within ``tolerance``.
        """
        self._check_params()
        if not runs:
            raise ThermocalInputError("bank: no runs to fit")
        one = [single_channel(r, channel_index(self.family, r, self.sensor)) for r in runs]
        names = {r.temp_names[0] for r in one}
        if len(names) > 1:
            raise ThermocalInputError(
                f"bank: the runs name the temperature channel differently: {sorted(names)}"
            )
        temps = [r.temps_c[:, 0] for r in one]
        ys = [r.target() for r in one]
        labels = [r.name or f"run {i}" for i, r in enumerate(one)]

        t_lo, t_hi = self._common_range(temps, labels)

        # 1-2: binned curves and clustering
        nb = max(1, math.ceil((t_hi - t_lo) / self.grid_step_c))
        edges = np.linspace(t_lo, t_hi, nb + 1)
        curves = np.empty((len(one), nb))
        curve_t = np.empty((len(one), nb))
        for i, (t, y) in enumerate(zip(temps, ys, strict=True)):
            curves[i], curve_t[i], _ = binned_curve(t, y, edges)
        dist = curve_distance(curves)
        groups = cluster_runs(dist, float(self.deviation))

        # 3: piecewise-linear model per group
        nk = max(2, round((t_hi - t_lo) / self.knot_spacing_c) + 1)
        knots = np.linspace(t_lo, t_hi, nk)
        kept_b: list[FloatArray] = []
        kept_v: list[FloatArray] = []
        kept_se: list[FloatArray | None] = []
        info: list[dict[str, Any]] = []
        rejected: list[dict[str, Any]] = []
        cond = 0.0
        resid_sq = 0.0
        n_res = 0
        for g in groups:
            entry, values, se, cond_g, rss_g = self._fit_group(
                g, one, temps, ys, labels, knots, curves, curve_t
            )
            cond = max(cond, cond_g)
            if rss_g is not None:
                kept_b.append(knots.copy())
                kept_v.append(values)
                kept_se.append(se)
                info.append(entry)
                resid_sq += rss_g[0]
                n_res += rss_g[1]
            else:
                rejected.append(entry)
        if not kept_v:
            best = min(e["fit_error"] for e in rejected)
            raise DesignError(
                f"bank: no characteristic curve could be modelled within the tolerance "
                f"{self.tolerance:g} (best fit error {best:.3g}); use a smaller knot_spacing_c "
                "or a larger tolerance"
            )
        if cond > CONDITION_WARN:
            warnings.warn(
                f"bank: badly conditioned piecewise design (condition number {cond:.3g})",
                ConditioningWarning,
                stacklevel=2,
            )
        self._store(
            one,
            groups,
            labels,
            dist,
            (kept_b, kept_v, kept_se),
            info,
            rejected,
            (cond, resid_sq, n_res),
        )
        return self

    def _store(
        self,
        one: list[RunData],
        groups: list[list[int]],
        labels: list[str],
        dist: FloatArray,
        kept: tuple[list[FloatArray], list[FloatArray], list[FloatArray | None]],
        info: list[dict[str, Any]],
        rejected: list[dict[str, Any]],
        fit: tuple[float, float, int],
    ) -> None:
        """Set the learned values and the fit statistics of :meth:`fit`."""
        kept_b, kept_v, kept_se = kept
        cond, resid_sq, n_res = fit
        self.breakpoints_ = kept_b
        self.values_ = kept_v
        self.stderr_ = kept_se
        self.model_info_ = info
        self.rejected_ = rejected
        self.groups_ = groups
        self.sensor_name_ = one[0].temp_names[0]
        n_coef = sum(v.size for v in kept_v)
        self._record_common(
            one,
            FitStats(
                n_samples=int(sum(r.n_samples for r in one)),
                n_coefficients=int(n_coef),
                rms_residual=math.sqrt(resid_sq / n_res),
                condition_number=float(cond),
                dof=int(n_res - n_coef),
                extra={
                    "n_groups": len(groups),
                    "n_models": len(kept_v),
                    "groups": [[labels[i] for i in g] for g in groups],
                    "fit_errors": [e["fit_error"] for e in info],
                    "rejected": rejected,
                    "max_within_group_deviation": float(
                        max((dist[np.ix_(g, g)].max() for g in groups), default=0.0)
                    ),
                },
            ),
        )

    def _common_range(self, temps: list[FloatArray], labels: list[str]) -> tuple[float, float]:
        """The temperature range every run covers (to within two grid steps) [°C]; runs
        over different ranges, or a span of one grid step or less, are a design error."""
        lo = np.array([t.min() for t in temps])
        hi = np.array([t.max() for t in temps])
        t_lo, t_hi = float(lo.min()), float(hi.max())
        slack = 2.0 * float(self.grid_step_c)
        short = [i for i in range(len(temps)) if lo[i] > t_lo + slack or hi[i] < t_hi - slack]
        if short:
            ranges = "; ".join(f"{labels[i]} {lo[i]:.1f}…{hi[i]:.1f} °C" for i in range(len(temps)))
            raise DesignError(
                f"bank: the runs cover different temperature ranges ({ranges}); every run "
                f"must cover {t_lo:.1f}…{t_hi:.1f} °C to within {slack:g} °C, because the "
                "characteristic curves are compared at the same temperatures"
            )
        if not t_hi - t_lo > self.grid_step_c:
            raise DesignError(
                f"bank: the runs span only {t_hi - t_lo:.2f} °C; at least more than one "
                f"grid step ({self.grid_step_c:g} °C) is needed"
            )
        return t_lo, t_hi

    def _fit_group(
        self,
        g: list[int],
        one: list[RunData],
        temps: list[FloatArray],
        ys: list[FloatArray],
        labels: list[str],
        knots: FloatArray,
        curves: FloatArray,
        curve_t: FloatArray,
    ) -> tuple[dict[str, Any], FloatArray, FloatArray | None, float, tuple[float, int] | None]:
        """Step 3–4 for one group: the piecewise-linear values at the knots (least squares
        on the group's samples) and their fit error against the characteristic lines;
        returns (entry, values, standard errors, condition number, (RSS, n) of the samples
        when the fit error is below the tolerance, else None)."""
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
            np.sqrt(np.maximum(np.diag(res.cov_unit) * float(res.sigma2), 0.0))
            if res.dof > 0
            else None
        )
        # 4: check against the characteristic lines
        pts_t, pts_y, check = self._characteristic_points(
            [one[i] for i in g],
            [temps[i] for i in g],
            [ys[i] for i in g],
            curves[g],
            curve_t[g],
        )
        err = pts_y - pwl_evaluate(knots, values, pts_t)
        fit_error = (
            float(np.max(np.abs(err)))
            if self.error_metric == "max"
            else float(np.sqrt(np.mean(err**2)))
        )
        entry = {
            "runs": [labels[i] for i in g],
            "fit_error": fit_error,
            "check": check,
            "n_check_points": int(pts_t.size),
        }
        kept = None
        if fit_error < self.tolerance:
            r = yg - x @ values
            kept = (float(np.sum(r**2)), int(r.size))
        return entry, values, se, float(res.condition_number), kept

    def _characteristic_points(
        self,
        runs: Sequence[RunData],
        temps: Sequence[FloatArray],
        ys: Sequence[FloatArray],
        curves: FloatArray,
        curve_t: FloatArray,
    ) -> tuple[FloatArray, FloatArray, str]:
        """Characteristic lines of a group: hold means (≥ 3 distinct temperatures)
        or the group's mean binned curve."""
        pts: list[tuple[float, float]] = []
        for r, t, y in zip(runs, temps, ys, strict=True):
            for seg in segment_holds(r.time_s, t, min_duration_s=self.hold_min_s):
                if seg.kind == "hold":
                    pts.append((float(np.mean(t[seg.slice])), float(np.mean(y[seg.slice]))))
        if pts:
            arr = np.array(sorted(pts))
            # merge holds at the same temperature (within a grid step)
            split = np.flatnonzero(np.diff(arr[:, 0]) > self.grid_step_c) + 1
            groups = np.split(arr, split)
            if len(groups) >= 3:
                mt = np.array([g[:, 0].mean() for g in groups])
                my = np.array([g[:, 1].mean() for g in groups])
                return mt, my, "holds"
        ok = np.isfinite(curves).all(axis=0)
        return curve_t[:, ok].mean(axis=0), curves[:, ok].mean(axis=0), "curve"

    # -- use --
    def _model_matrix(self, temp_c: FloatArray) -> FloatArray:
        """(n, M): every model evaluated at every temperature."""
        return np.column_stack(
            [
                pwl_evaluate(b, v, temp_c)
                for b, v in zip(self.breakpoints_, self.values_, strict=True)
            ]
        )

    def _prepare(self, run: RunData, extrapolate: bool) -> FloatArray:
        self.check_fitted()
        col = channel_index(self.family, run, self.sensor, self.sensor_name_)
        temp = np.asarray(run.temps_c[:, col], dtype=np.float64)
        return self.clamp(temp[:, None], extrapolate=extrapolate)[:, 0]

    def _startup_count(self, run: RunData) -> int:
        """Samples in the start-up window, ``t − t_first < startup_s`` (≥ 1)."""
        return max(1, int(np.count_nonzero(run.time_s - run.time_s[0] < self.startup_s)))

    def _run_selection(self, run: RunData, f: FloatArray) -> tuple[FloatArray, FloatArray, int]:
        """Running deviations (m, M) over the start-up window and per-sample choice."""
        if run.signal is None:
            raise ThermocalInputError(
                f"bank: {run.name or 'run'}: selecting a model at power-on needs the "
                "measured signal"
            )
        m = self._startup_count(run)
        y = run.target()[:m]
        dev = np.abs(np.cumsum(y[:, None] - f[:m], axis=0) / np.arange(1, m + 1)[:, None])
        choice = np.argmin(dev, axis=1)
        return dev, choice, m

    def select(self, run: RunData, *, extrapolate: bool = False) -> Selection:
        """The model chosen for a power-on from its start-up window ([Seed-Accel], step 4);
        also stored in ``selection_``.

        Parameters
        ----------
        run : RunData
            The power-on, with its signal.
        extrapolate : bool, optional
            Default False (clamp temperatures to the fitted range).

        Returns
        -------
        Selection

        Notes
        -----
        .. math:: D_m(N) = \\Big|\\frac{1}{N}\\sum_{i<N} (y_i - f_m(T_i))\\Big|,
                  \\qquad m^* = \\arg\\min_m D_m
        """
        temp = self._prepare(run, extrapolate)
        f = self._model_matrix(temp[: self._startup_count(run)])
        dev, _choice, m = self._run_selection(run, f)
        self.selection_ = _selection(dev[-1], m, m < run.n_samples)
        return self.selection_

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """Output of the selected model at every sample [signal unit]: running
        selection during the start-up window, frozen after it.

        Parameters
        ----------
        run : RunData
            The power-on, with its signal (the selection needs it).
        extrapolate : bool, optional
            Default False.

        Returns
        -------
        numpy.ndarray
            Shape (n,) [signal unit].

        Raises
        ------
        thermocal.errors.ThermocalInputError
            The run has no signal.
        """
        temp = self._prepare(run, extrapolate)
        f = self._model_matrix(temp[: self._startup_count(run)])  # every model, start-up only
        dev, choice, m = self._run_selection(run, f)
        self.selection_ = _selection(dev[-1], m, m < run.n_samples)
        out = np.empty(run.n_samples)
        out[:m] = f[np.arange(m), choice]
        c = int(choice[-1])
        out[m:] = pwl_evaluate(self.breakpoints_[c], self.values_[c], temp[m:])
        return out

    def stream(
        self, sample_interval_s: float, *, extrapolate: bool = False, known_input: float = 0.0
    ) -> ModelStream:
        """Sample-by-sample twin of :meth:`predict`; ``known_input`` (e.g. the gravity
        component [mg]) is subtracted from the raw signal before the selection, like
        :meth:`RunData.target`.

        Parameters
        ----------
        sample_interval_s : float
            Nominal sample interval [s].
        extrapolate : bool, optional
            Default False.
        known_input : float, optional
            Known input [signal unit].  Default 0.

        Returns
        -------
        BankStream
        """
        self.check_fitted()
        return BankStream(self, extrapolate=extrapolate, known_input=known_input)

    def coefficients(self) -> list[Coefficient]:
        """Each model's value at each breakpoint [signal unit], with standard errors."""
        self.check_fitted()
        out = []
        for m, (b, v, se) in enumerate(
            zip(self.breakpoints_, self.values_, self.stderr_, strict=True)
        ):
            for k in range(v.size):
                out.append(
                    Coefficient(
                        name=f"m{m}_v{k} (T={b[k]:.6g} degC)",
                        value=float(v[k]),
                        stderr=None if se is None else float(se[k]),
                        unit=self.signal_unit,
                    )
                )
        return out

    @classmethod
    def check_state(cls, d: dict[str, Any], root: str = "") -> None:
        """The ``state`` section of a bank model file: one or more models of at least two
        ascending breakpoints with a value each; ``params.sensor`` one of the inputs.

        Parameters
        ----------
        d : dict
            The model file's content.
        root : str, optional
            Key path prefix.  Default ``""``.

        Raises
        ------
        thermocal.errors.ModelFileError
            A bad state, naming the key path.
        """
        sensor_param(d, root)
        state, path = d["state"], key_path(root, "state")
        fields(
            {
                "sensor_name": string,
                "models": list_of(
                    fields({"breakpoints_c": ascending, "values": list_of(number)}), min_len=1
                ),
            },
            optional={"startup_s": number, "deviation": number, "tolerance": number},
        )(state, path)
        for i, m in enumerate(state["models"]):
            if len(m["breakpoints_c"]) < 2:
                raise ModelFileError(f"{path}.models[{i}].breakpoints_c: needs at least 2 points")
            same_length(
                m, f"{path}.models[{i}]", "values", len(m["breakpoints_c"]), "one per point"
            )

    def _state(self) -> dict[str, Any]:
        return {
            "sensor_name": self.sensor_name_,
            "models": [
                {
                    "breakpoints_c": b.tolist(),
                    "values": v.tolist(),
                    "stderr": None if se is None else se.tolist(),
                    **info,
                }
                for b, v, se, info in zip(
                    self.breakpoints_, self.values_, self.stderr_, self.model_info_, strict=True
                )
            ],
            "rejected": self.rejected_,
            "groups": self.groups_,
            "startup_s": float(self.startup_s),
            "deviation": float(self.deviation),
            "tolerance": float(self.tolerance),
        }

    def _set_state(self, state: dict[str, Any]) -> None:
        self.sensor_name_ = str(state["sensor_name"])
        models = state["models"]
        self.breakpoints_ = [np.array(m["breakpoints_c"], dtype=np.float64) for m in models]
        self.values_ = [np.array(m["values"], dtype=np.float64) for m in models]
        self.stderr_ = [
            None if m.get("stderr") is None else np.array(m["stderr"], dtype=np.float64)
            for m in models
        ]
        skip = {"breakpoints_c", "values", "stderr"}
        self.model_info_ = [{k: v for k, v in m.items() if k not in skip} for m in models]
        self.rejected_ = list(state.get("rejected", []))
        self.groups_ = [list(g) for g in state.get("groups", [])]


class BankStream(ModelStream):
    """Streaming twin of :meth:`BankModel.predict`, in plain Python floats: running
    residual sums per model during the start-up window, then the frozen choice (only
    the chosen model is evaluated after it).  The same operations as ``predict``
    (:func:`pwl_evaluate`, the cumulative sums of ``_run_selection``), so the same numbers.

    ``temps_c`` holds either one value (the model's channel) or the fitted run's
    channels (``sensor`` picks).  ``signal`` (raw; ``known_input`` is subtracted) is
    required during the start-up window.  ``selection`` is the current :class:`Selection`.
    Warns once per stream when a temperature leaves the fitted range.

    Parameters
    ----------
    model : BankModel
        The fitted bank.
    extrapolate : bool, optional
        Default False.
    known_input : float, optional
        Known input subtracted from the signal [signal unit].  Default 0.
    """

    def __init__(
        self, model: BankModel, *, extrapolate: bool = False, known_input: float = 0.0
    ) -> None:
        self.model = model
        self.extrapolate = extrapolate
        self.known_input = float(known_input)
        self._col = int(model.sensor)
        lo, hi = (float(v) for v in model.temp_range_[0])
        self._clamp = ClampOnce(lo, hi, extrapolate=extrapolate)
        self._startup = float(model.startup_s)
        self._xs = [[float(x) for x in b] for b in model.breakpoints_]
        self._vs = [[float(v) for v in vals] for vals in model.values_]
        self.reset()

    def reset(self) -> None:
        """Forget everything (a new power-on): the start-up selection starts again."""
        n = len(self._vs)
        self._t_first: float | None = None
        self._sums = [0.0] * n
        self._count = 0
        self._frozen = False
        self._choice = 0
        self._dev = [math.nan] * n
        self._clamp.warned = False

    @property
    def selection(self) -> Selection:
        """The current :class:`Selection`."""
        return _selection(np.array(self._dev, dtype=np.float64), self._count, self._frozen)

    def _value(self, m: int, temp: float) -> float:
        """Model m at T: :func:`pwl_evaluate` on one float (same operations)."""
        x, v = self._xs[m], self._vs[m]
        j = min(max(bisect.bisect_right(x, temp) - 1, 0), len(x) - 2)
        slope = (v[j + 1] - v[j]) / (x[j + 1] - x[j])
        return v[j] + slope * (temp - x[j])

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        """Model value for one sample (see :meth:`ModelStream.update`).

        Parameters
        ----------
        time_s : float
            Sample time [s].
        temps_c : numpy.ndarray
            Temperatures [°C].
        signal : float, optional
            Raw signal [signal unit]; required during the start-up window.

        Returns
        -------
        float
            The selected model's value [signal unit].

        Raises
        ------
        thermocal.errors.ThermocalInputError
            No signal during the start-up window.
        """
        temp = self._clamp(stream_channel(temps_c, self._col))
        t = float(time_s)
        if self._t_first is None:
            self._t_first = t
        if not self._frozen and t - self._t_first < self._startup:
            if signal is None:
                raise ThermocalInputError(
                    "bank: selecting a model at power-on needs the measured signal"
                )
            y = float(signal) - self.known_input
            f = [self._value(m, temp) for m in range(len(self._vs))]
            self._count += 1
            sums = self._sums
            best = 0
            for m, fm in enumerate(f):
                sums[m] = sums[m] + (y - fm)
                dev = abs(sums[m] / self._count)
                self._dev[m] = dev
                if dev < self._dev[best]:
                    best = m
            self._choice = best
            return f[best]
        self._frozen = True
        return self._value(self._choice, temp)
