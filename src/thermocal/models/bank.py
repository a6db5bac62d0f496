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

This module holds the estimator, :class:`BankModel`; the curve maths (piecewise-linear
evaluation, hat basis, binned curves, clustering, one group's fit) are in
:mod:`thermocal.models.bank_curves`, the choice at power-on (:class:`Selection`) and the
streaming twin (:class:`BankStream`) in :mod:`thermocal.models.bank_select`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any, ClassVar, Self

import numpy as np

from thermocal.adequacy import Needs
from thermocal.errors import (
    ConditioningWarning,
    DesignError,
    ModelFileError,
    ThermocalInputError,
)
from thermocal.families import BANK, FamilyDeclaration
from thermocal.models.bank_curves import (
    binned_curve,
    cluster_runs,
    common_range,
    curve_distance,
    fit_group,
    pwl_evaluate,
)
from thermocal.models.bank_select import BankStream, Selection, selection_of
from thermocal.models.base import ChunkContext, ModelStream, TemperatureModel
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
from thermocal.models.numerics import channel_index, single_channel
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData
from thermocal.models.warmup import CONDITION_WARN
from thermocal.recording import FloatArray

ERROR_METRICS = ("max", "rms")


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

        t_lo, t_hi = common_range(temps, labels, float(self.grid_step_c))

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
            entry, values, se, cond_g, rss_g = fit_group(
                g, one, temps, ys, labels, knots, curves, curve_t,
                error_metric=self.error_metric, tolerance=self.tolerance,
                hold_min_s=self.hold_min_s, grid_step_c=self.grid_step_c,
            )  # fmt: skip
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
        self.selection_ = selection_of(dev[-1], m, m < run.n_samples)
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
        self.selection_ = selection_of(dev[-1], m, m < run.n_samples)
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
