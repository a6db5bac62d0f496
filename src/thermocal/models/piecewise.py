"""Piecewise-linear temperature model ([Seed-FOG], fibre-optic gyro).

For a warmed-up sensor and slow temperature change (no rate terms) the
temperature-induced signal is a piecewise-linear function of one temperature T
[°C] (the first temperature column unless ``temperature`` names another):

.. math::

    y(T) = a_j + s_j T, \\qquad b_{j} \\le T < b_{j+1},                  (1)

with breakpoints ``b_1 < … < b_B`` (``b_0 = −∞``, ``b_{B+1} = +∞``).  Two ways
to get the lines:

* ``method="intersect"`` (the seed's): split the data at the given (or chosen)
  breakpoints, fit a least-squares line per segment, then move each breakpoint
  to the intersection of the two adjacent lines,
  ``b_j = (a_j − a_{j−1})/(s_{j−1} − s_j)`` (seed: 25 and 30 °C became 23.6 and
  30 °C), which makes the model continuous.  An intersection that is undefined
  (parallel lines) or falls outside the two segments' span keeps the given
  breakpoint; the model then jumps there (reported in ``fit.discontinuities``
  and with a warning).
* ``method="continuous"`` (our reading): continuous piecewise-linear
  least squares in the hinge basis ``y = c + s_0 T + Σ_j d_j max(0, T − b_j)``.

Breakpoints are given (``breakpoints=[25, 30]``) or chosen from the data
(``segments=N``, :func:`choose_breakpoints`): at most N−1 breakpoints minimise the
residual sum of squares of the continuous fit on temperature-binned data, every
segment at least 5 % of the range wide with enough samples and distinct
temperatures, and a breakpoint is kept only when it lowers the BIC; fewer segments
than asked are fitted with a warning.  Several runs may be
fitted together with per-run offsets (nuisance parameters; the model's level is
their mean).  Outside the fitted temperature range T is clamped (with an
:class:`~thermocal.errors.ExtrapolationWarning`) unless extrapolating.

Model-file ``state`` layout (``"layout": "thermocal-piecewise-1"``), for the C export::

    {
      "layout": "thermocal-piecewise-1",
      "temperature": "T1",        # the one temperature used (= "temperatures"[0])
      "column_index": 0,          # its position among the fitted data's columns
      "method": "intersect" | "continuous",
      "breakpoints": [b1, ...],   # [°C], ascending, B values
      "intercepts": [a0, ...],    # [signal unit], B + 1 values: value of line j at T = 0
      "slopes": [s0, ...],        # [signal unit/°C], B + 1 values
      "offsets": [...],           # per-run offsets (nuisance), run order of "data"
      "initial_breakpoints": [...]
    }

Evaluation of one sample: ``T`` clamped to ``range.temperature_c`` of the
file; ``j`` = number of breakpoints ``≤ T``; ``y = intercepts[j] + slopes[j]·T``.

This module holds the estimator, :class:`PiecewiseModel`, and its streaming twin; the lines'
maths (initial breakpoints, segment checks, the chunked least squares, the intersections)
are in :mod:`thermocal.models.piecewise_lines`, the choice of breakpoints from the data in
:mod:`thermocal.models.breakpoints`.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar, Self

import numpy as np

from thermocal._lazy import LazyModule
from thermocal.adequacy import AdequacyTest, Needs
from thermocal.errors import (
    ModelFileError,
    ThermocalInputError,
)
from thermocal.families import PIECEWISE, FamilyDeclaration
from thermocal.models.base import ChunkContext, ModelStream, TemperatureModel
from thermocal.models.breakpoints import (
    BreakpointChoice,
    _Lines,
    evaluate_lines,
    segment_tests,
)
from thermocal.models.checks import (
    ascending,
    fields,
    integer,
    key_path,
    list_of,
    matrix,
    number,
    same_length,
)
from thermocal.models.fitting import (
    OffsetDecision,
    check_runs,
    decide_run_offsets,
    record_ranges,
)
from thermocal.models.piecewise_lines import (
    check_segments,
    initial_breakpoints,
    intersections,
    solve_lines,
)
from thermocal.models.residuals import MAX_SAMPLES_PER_SERIES, residual_correlation
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData
from thermocal.models.streams import ClampOnce, stream_channel
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from scipy import optimize
else:
    optimize = LazyModule("scipy.optimize")

STATE_LAYOUT = "thermocal-piecewise-1"
METHODS = ("intersect", "continuous")


class PiecewiseModel(TemperatureModel):
    """Piecewise-linear model in one temperature ([Seed-FOG]); see the module docstring.

    Parameters
    ----------
    breakpoints : breakpoints [°C] (initial ones for ``"intersect"``).
    segments : number of segments, breakpoints chosen from the data (default 3
        when no breakpoints are given).
    method : ``"intersect"`` (seed: per-segment lines, breakpoints at the
        intersections) or ``"continuous"`` (hinge-basis least squares).
    temperature : name or 0-based index of the temperature column (default the first).
    per_run_offset : per-run offsets as nuisance parameters; None (default) when the runs
        overlap in temperature (:func:`thermocal.models.fitting.decide_run_offsets`).

    Notes
    -----
    With breakpoints :math:`\\beta_1 < \\dots < \\beta_{S-1}` in one temperature, each
    segment :math:`j` is a line fitted by least squares on its own data,

    .. math::

        \\hat y(T) = a_j + s_j T, \\qquad \\beta_{j-1} \\le T < \\beta_j ,

    and with ``method="intersect"`` each breakpoint moves to the intersection of the two
    adjacent lines, which makes the model continuous.

    References
    ----------
    .. [1] *Design and engineering implementation of a fibre-optic-gyro line-of-sight
       stabilisation system*, master's thesis, chapter 3 (docs/methods.md, Seed-FOG).

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.piecewise import PiecewiseModel
    >>> t = np.arange(0.0, 3600.0, 10.0)
    >>> temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / 3600.0)
    >>> y = np.where(temp < 25.0, 1.0 + 0.01 * (temp - 25.0), 1.0 + 0.03 * (temp - 25.0))
    >>> model = PiecewiseModel(breakpoints=[25.0]).fit([RunData(t, temp[:, None], y, ("T1",))])
    >>> at = RunData(np.arange(3.0), np.array([[15.0], [25.0], [35.0]]), None, ("T1",))
    >>> [round(float(v), 4) for v in model.predict(at)]
    [0.9, 1.0, 1.3]
    """

    declaration: ClassVar[FamilyDeclaration] = PIECEWISE
    uses_rate: ClassVar[bool] = False

    breakpoints_: FloatArray
    intercepts_: FloatArray
    slopes_: FloatArray
    offsets_: FloatArray
    initial_breakpoints_: FloatArray
    column_index_: int
    line_cov_: FloatArray
    segment_tests_: tuple[AdequacyTest, ...]
    """Each segment judged after the fit (:func:`segment_tests`); the fit pipeline adds
    them to the model's adequacy record (refused unless overridden)."""

    def __init__(
        self,
        breakpoints: list[float] | None = None,
        segments: int | None = None,
        method: str = "intersect",
        temperature: str | int | None = None,
        per_run_offset: bool | None = None,
    ) -> None:
        self.breakpoints = breakpoints
        self.segments = segments
        self.method = method
        self.temperature = temperature
        self.per_run_offset = per_run_offset

    def chunk_context(self) -> ChunkContext:
        """Eq. (1) is memoryless: a sample's value depends on its own temperature only."""
        return ChunkContext(head_s=0.0, tail_s=0.0)

    # -- helpers --
    def data_needs(self, temp_names: Sequence[str], n_runs: int) -> Needs:
        """Judged as a line in the model's column (each segment's own data are checked by
        the fit); S + 1 coefficients for S given segments, plus per-run offsets.

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
        j = self._column(temp_names, len(temp_names)) if temp_names else 0
        # breakpoints chosen from the data (segments=N) are fewer where the data are short
        s = len(self.breakpoints) + 1 if self.breakpoints else 1
        offsets = n_runs - 1 if (self.per_run_offset is not False and n_runs > 1) else 0
        return Needs({temp_names[j]: 1} if temp_names else {}, s + 1 + offsets)

    def _column(self, names: Sequence[str], k: int) -> int:
        t = self.temperature
        if t is None:
            return 0
        if isinstance(t, int) and not isinstance(t, bool):
            if not 0 <= t < k:
                raise ThermocalInputError(
                    f"piecewise: temperature index {t} out of range 0…{k - 1}"
                )
            return t
        if str(t) in names:
            return list(names).index(str(t))
        raise ThermocalInputError(
            f"piecewise: temperature column {t!r} not among {', '.join(map(repr, names))}"
        )

    def _pick(self, run: RunData) -> FloatArray:
        """The model's temperature column of a run [°C]."""
        k = run.temps_c.shape[1]
        name = self.temp_names_[0]
        if k == 1:
            return run.temps_c[:, 0]
        if run.temp_names and name in run.temp_names:
            return run.temps_c[:, list(run.temp_names).index(name)]
        if self.column_index_ < k:
            return run.temps_c[:, self.column_index_]
        raise ThermocalInputError(
            f"piecewise model needs temperature {name!r}; the data has {k} columns"
        )

    # -- estimator contract --
    def fit(self, runs: Sequence[RunData]) -> Self:
        """Fit eq. (1) on one or several runs (module docstring); returns ``self``.

        Steps (:mod:`thermocal.models.piecewise_lines`): the initial breakpoints, given
        or chosen by BIC (:func:`~thermocal.models.piecewise_lines.initial_breakpoints`);
        every segment checked to hold a line
        (:func:`~thermocal.models.piecewise_lines.check_segments`); the lines by chunked
        least squares (:func:`~thermocal.models.piecewise_lines.solve_lines`); the
        breakpoints moved to where adjacent lines meet (intersect method,
        :func:`~thermocal.models.piecewise_lines.intersections`); residuals,
        their correlation and the statistics (:meth:`_set_fitted`); every final segment
        judged by the common adequacy rules (:func:`segment_tests`, ``segment_tests_``).

        Parameters
        ----------
        runs : sequence of RunData
            Runs with times [s], temperatures [°C] and signal [°/h or mg].

        Returns
        -------
        PiecewiseModel
            ``self``, fitted.

        Raises
        ------
        thermocal.errors.DesignError
            The data cannot determine the model (rank, ranges, segments).
        """
        if self.method not in METHODS:
            raise ThermocalInputError(
                f"unknown piecewise method {self.method!r}; use {' or '.join(METHODS)}"
            )
        if self.breakpoints is not None and self.segments is not None:
            raise ThermocalInputError("give either breakpoints or a number of segments, not both")
        rl = check_runs(runs, self.family)
        names = rl[0].temp_names or tuple(f"T{i + 1}" for i in range(rl[0].temps_c.shape[1]))
        j = self._column(names, rl[0].temps_c.shape[1])
        xs = [np.ascontiguousarray(r.temps_c[:, j]) for r in rl]
        ys = [r.target() for r in rl]
        decision = decide_run_offsets(self.per_run_offset, rl, self.family, column=j)
        lo = min(float(x.min()) for x in xs)
        hi = max(float(x.max()) for x in xs)
        bps, choice = initial_breakpoints(
            xs, ys, decision.used, lo, hi, breakpoints=self.breakpoints, segments=self.segments
        )
        bp = np.asarray(bps, dtype=np.float64)
        check_segments(bp, xs, lo, hi)
        lines = solve_lines(xs, ys, bp, rl, decision.used, lo, hi, self.method)
        final, discontinuities = intersections(bp, lines, lo, hi, self.method)
        self._set_fitted(rl, names, j, xs, ys, bp, final, discontinuities, lines, decision,
                         choice)  # fmt: skip
        self.segment_tests_ = segment_tests(
            final, xs, names[j], lo, hi, given=self.breakpoints is not None,
            unit="°C" if rl[0].temperature_unit == "degC" else str(rl[0].temperature_unit),
        )  # fmt: skip
        return self

    def _set_fitted(
        self,
        rl: list[RunData],
        names: Sequence[str],
        j: int,
        xs: list[FloatArray],
        ys: list[FloatArray],
        bp: FloatArray,
        final: FloatArray,
        discontinuities: list[float],
        lines: _Lines,
        decision: OffsetDecision,
        choice: BreakpointChoice | None,
    ) -> None:
        """The fitted values; the residuals of the final model (breakpoints moved), their
        correlation time scaling the lines' covariance, the statistics and ranges."""
        intercepts, slopes, line_cov, offsets = (
            lines.intercepts, lines.slopes, lines.line_cov, lines.offsets,
        )  # fmt: skip
        const, sol, use_offsets, S = lines.const, lines.sol, decision.used, bp.size + 1
        self.column_index_ = j
        self.breakpoints_ = final
        self.initial_breakpoints_ = bp
        self.intercepts_ = intercepts
        self.slopes_ = slopes
        self.offsets_ = offsets
        self.line_cov_ = line_cov
        n_total = lines.n_total
        # residual of the final model (breakpoints moved): exact, one pass
        rss = 0.0
        residuals: list[FloatArray] = []
        for i, (x, y) in enumerate(zip(xs, ys, strict=True)):
            off = offsets[i] - const if use_offsets else 0.0
            res = y - evaluate_lines(final, intercepts, slopes, x) - off
            rss += float(res @ res)
            residuals.append(res[:MAX_SAMPLES_PER_SERIES])
        ybar = sum(float(np.sum(y)) for y in ys) / n_total
        tss = sum(float(((y - ybar) ** 2).sum()) for y in ys)
        # coloured residuals: the lines' covariance is scaled by τ (models.residuals)
        corr = residual_correlation(residuals, data_rms=math.sqrt(tss / n_total))
        del residuals
        self.line_cov_ = corr.tau * line_cov
        stats = FitStats(
            n_samples=n_total,
            n_coefficients=2 * S if self.method == "intersect" else S + 1,
            rms_residual=math.sqrt(rss / n_total),
            condition_number=sol.condition_number,
            r_squared=float(1.0 - rss / tss) if tss > 0 else None,
            dof=sol.dof,
            extra={
                "method": self.method,
                "temperature": names[j],
                "breakpoints": [float(b) for b in final],
                "initial_breakpoints": [float(b) for b in bp],
                "discontinuities": discontinuities,
                "n_runs": len(rl),
                "per_run_offsets": [float(o) for o in offsets] if use_offsets else None,
                "offset_decision": decision.to_dict(),
                "residual_correlation": corr.to_dict(),
                "rms_residual_lsq": math.sqrt(sol.rss / n_total),
                "segment_selection": None if choice is None else choice.to_dict(),
            },
        )
        # ranges of the used column only (record_ranges takes per-run min/max)
        summary = [
            RunData(
                time_s=np.array([0.0, 1.0]),
                temps_c=np.array([[x.min()], [x.max()]]),
                temp_names=(names[j],),
                name=r.name,
            )
            for r, x in zip(rl, xs, strict=True)
        ]
        record_ranges(self, summary, stats, None)
        self.data_ = [{"file": r.name, "n_samples": r.n_samples} for r in rl]

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """Eq. (1) for every sample of ``run`` [signal unit]; T clamped to the fitted range.

        Parameters
        ----------
        run : RunData
            Times [s] and temperatures [°C].
        extrapolate : bool, optional
            False (default): temperatures clamped to the fitted range, with a warning.

        Returns
        -------
        numpy.ndarray
            Shape (n,) [signal unit].
        """
        self.check_fitted()
        x = self._pick(run)
        xc = self.clamp(x[:, None], extrapolate=extrapolate)[:, 0]
        return evaluate_lines(self.breakpoints_, self.intercepts_, self.slopes_, xc)

    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> PiecewiseStream:
        """Sample-by-sample twin of :meth:`predict` (memoryless).

        Parameters
        ----------
        sample_interval_s : float
            Nominal sample interval [s].
        extrapolate : bool, optional
            Default False.

        Returns
        -------
        PiecewiseStream
        """
        self.check_fitted()
        return PiecewiseStream(self, extrapolate=extrapolate)

    def coefficients(self) -> list[Coefficient]:
        """Per-segment intercepts and slopes (physical units, with standard errors), breakpoints."""
        self.check_fitted()
        S = self.slopes_.size
        se = np.sqrt(np.clip(np.diag(self.line_cov_), 0.0, None))
        edges = [-math.inf, *self.breakpoints_, math.inf]
        out: list[Coefficient] = []
        for s in range(S):
            lab = f"{edges[s]:.4g}…{edges[s + 1]:.4g}"
            out.append(
                Coefficient(
                    f"intercept[{lab}]", float(self.intercepts_[s]), float(se[s]), self.signal_unit
                )
            )
            out.append(
                Coefficient(
                    f"slope[{lab}]",
                    float(self.slopes_[s]),
                    float(se[S + s]),
                    f"{self.signal_unit}/degC",
                )
            )
        for i, b in enumerate(self.breakpoints_):
            out.append(Coefficient(f"breakpoint[{i + 1}]", float(b), None, "degC"))
        return out

    @classmethod
    def check_state(cls, d: dict[str, Any], root: str = "") -> None:
        """The ``state`` section of a piecewise model file: ascending breakpoints, one
        intercept and slope per segment, its column one of the inputs.

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
        state, path, n_temps = d["state"], key_path(root, "state"), len(d["temperatures"])
        fields(
            {"breakpoints": ascending, "intercepts": list_of(number), "slopes": list_of(number)},
            optional={"column_index": integer, "offsets": list_of(number), "line_cov": matrix},
        )(state, path)
        n_lines = len(state["breakpoints"]) + 1
        same_length(state, path, "intercepts", n_lines, "one per segment")
        same_length(state, path, "slopes", n_lines, "one per segment")
        col = state.get("column_index", 0)
        if not 0 <= col < n_temps:
            raise ModelFileError(f"{path}.column_index: {col} is not one of the {n_temps} inputs")

    def _state(self) -> dict[str, Any]:
        return {
            "layout": STATE_LAYOUT,
            "temperature": self.temp_names_[0] if hasattr(self, "temp_names_") else None,
            "column_index": int(self.column_index_),
            "method": self.method,
            "breakpoints": [float(b) for b in self.breakpoints_],
            "intercepts": [float(a) for a in self.intercepts_],
            "slopes": [float(s) for s in self.slopes_],
            "offsets": [float(o) for o in self.offsets_],
            "initial_breakpoints": [float(b) for b in self.initial_breakpoints_],
            "line_cov": self.line_cov_.tolist(),
        }

    def _set_state(self, state: dict[str, Any]) -> None:
        if state.get("layout") != STATE_LAYOUT:
            raise ThermocalInputError(
                f"piecewise model state layout {state.get('layout')!r} is not {STATE_LAYOUT!r}"
            )
        self.column_index_ = int(state.get("column_index", 0))
        self.breakpoints_ = np.asarray(state["breakpoints"], dtype=np.float64)
        self.intercepts_ = np.asarray(state["intercepts"], dtype=np.float64)
        self.slopes_ = np.asarray(state["slopes"], dtype=np.float64)
        self.offsets_ = np.asarray(state.get("offsets", []), dtype=np.float64)
        self.initial_breakpoints_ = np.asarray(
            state.get("initial_breakpoints", state["breakpoints"]), dtype=np.float64
        )
        S = self.slopes_.size
        self.line_cov_ = np.asarray(
            state.get("line_cov", np.full((2 * S, 2 * S), np.nan)), dtype=np.float64
        )
        if self.intercepts_.size != S or self.breakpoints_.size != S - 1:
            raise ThermocalInputError("piecewise model state: need one more line than breakpoints")


class PiecewiseStream(ModelStream):
    """Sample-by-sample :class:`PiecewiseModel`: eq. (1) on the clamped temperature, in
    plain Python floats (``bisect`` for the segment; the same operations as
    :func:`evaluate_lines`, so the same numbers as ``predict``).

    ``temps_c`` may hold only the model's temperature or every fitted column
    (then the model's ``column_index`` is used).  Warns once per stream when a
    sample leaves the fitted range.

    Parameters
    ----------
    model : PiecewiseModel
        The fitted model.
    extrapolate : bool
        Keep out-of-range temperatures (and warn).
    """

    def __init__(self, model: PiecewiseModel, *, extrapolate: bool) -> None:
        self.model = model
        self.extrapolate = extrapolate
        lo, hi = (float(v) for v in model.temp_range_[0])
        self._clamp = ClampOnce(lo, hi, extrapolate=extrapolate)
        self._col = int(model.column_index_)
        self._bps = [float(b) for b in model.breakpoints_]
        self._inter = [float(a) for a in model.intercepts_]
        self._slopes = [float(v) for v in model.slopes_]
        self.reset()

    def reset(self) -> None:
        """Forget everything (a new power-on)."""
        self._clamp.warned = False

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        """Model value for one sample (see :meth:`ModelStream.update`).

        Parameters
        ----------
        time_s : float
            Sample time [s].
        temps_c : numpy.ndarray
            Temperatures [°C].
        signal : float, optional
            Not used.

        Returns
        -------
        float
            [signal unit].
        """
        x = self._clamp(stream_channel(temps_c, self._col))
        j = bisect.bisect_right(self._bps, x)
        return self._inter[j] + self._slopes[j] * x
