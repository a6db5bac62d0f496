"""Fitting :class:`~thermocal.models.poly.PolyModel` ([Seed-RLG]), one channel or several
sharing one design: :func:`fit_shared` and its steps."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from threadpoolctl import threadpool_limits

from thermocal.errors import ConditioningWarning, ThermocalInputError
from thermocal.models.fitting import (
    SHORT_RATE_WARN_SHARE,
    Block,
    OffsetDecision,
    check_runs,
    decide_run_offsets,
    record_ranges,
    run_blocks,
    short_rate_share,
)
from thermocal.models.lstsq import LstsqSolution, forward_select, solve_r
from thermocal.models.poly_types import PolyBase
from thermocal.models.reduction import Chunk, Reduced, accumulate_targets
from thermocal.models.residuals import MAX_SAMPLES_PER_SERIES, residual_correlation
from thermocal.models.results import FitStats
from thermocal.models.rundata import RunData
from thermocal.models.term_scaling import BaseScaling, fit_base_scaling
from thermocal.models.terms import Term, parse_terms, term_features
from thermocal.preprocess import segment_rates
from thermocal.recording import FloatArray

COND_WARN = 1.0e8
"""Condition number above which a :class:`ConditioningWarning` is raised."""

SCALING_SAMPLES = 200_000
"""Centres and scales of the base variables come from at most this many evenly spaced samples."""


def _same_inputs(a: RunData, b: RunData) -> bool:
    """The two runs have the same times and temperatures (the same arrays, or equal)."""

    def same(x: FloatArray, y: FloatArray) -> bool:
        return x is y or (x.shape == y.shape and bool(np.array_equal(x, y)))

    return same(a.time_s, b.time_s) and same(a.temps_c, b.temps_c)


def fit_shared(models: Sequence[PolyBase], runs_by_model: Sequence[Sequence[RunData]]) -> None:
    """Fit several channels that share one design: the same parameters and the
    same runs' times and temperatures, each with its own signal and known input.

    The work that depends on the temperatures alone — Ṫ, the base-variable scaling, the
    features, the offset decision, the ranges — is done once and the design's Gram matrix
    is accumulated once; only the targets' products are per channel
    (:func:`~thermocal.models.reduction.accumulate_targets`), so each channel's reduction is
    computed by the operations a single channel gets, bit for bit.  Term selection, the
    solution, the residuals' autocorrelation and the covariance are per channel, so every
    model equals the one :meth:`PolyModel.fit` gives on its own runs.

    Steps: check the channels share their inputs (:func:`_shared_runs`); the design
    (:func:`_shared_design`); one pass reducing it (:class:`_DesignPass`,
    :func:`~thermocal.models.reduction.accumulate_targets`); per channel the selection and
    solution (:func:`_solve_channel`); a second pass for the residuals; per channel the
    covariance and statistics (:func:`_finish_channel`).

    Parameters
    ----------
    models : sequence of PolyBase
        Unfitted models with equal parameters (fitted in place).
    runs_by_model : sequence of sequence of RunData
        Each model's runs (same times and temperatures, own signal).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        The channels' runs do not share their times, temperatures or parameters.
    """
    head, rls = _shared_runs(models, runs_by_model)
    # BLAS on one thread: the blocks are small (≤ 32 768 × ~40), where threads oversubscribe
    # and triple the wall time on a loaded machine; the same numbers either way
    with threadpool_limits(limits=1, user_api="blas"):
        design = _shared_design(head, rls[0])
        dp = _DesignPass(design, rls)
        reds = accumulate_targets(
            dp.chunks, design.p, design.m, len(models), n_folds=design.n_folds,
            solver=cast(Any, head.solver),
        )  # fmt: skip
        solved = [_solve_channel(m, red, design) for m, red in zip(models, reds, strict=True)]
        residuals = dp.residuals(solved)
        for j, mdl in enumerate(models):
            _finish_channel(mdl, design, dp, j, solved[j], residuals[j], reds[j].solver, rls[j])


def _shared_runs(
    models: Sequence[PolyBase], runs_by_model: Sequence[Sequence[RunData]]
) -> tuple[PolyBase, list[list[RunData]]]:
    """The first model and every channel's checked runs; refuses models with other
    parameters and runs with other times or temperatures."""
    if not models or len(models) != len(runs_by_model):
        raise ThermocalInputError("fit_shared: one list of runs per model")
    head = models[0]
    for mdl in models:
        mdl._check_params()
        if mdl._params_key() != head._params_key():
            raise ThermocalInputError("fit_shared: the models' parameters differ")
    rls = [check_runs(r, head.family) for r in runs_by_model]
    for other in rls[1:]:
        if len(other) != len(rls[0]) or not all(
            _same_inputs(a, b) for a, b in zip(rls[0], other, strict=True)
        ):
            raise ThermocalInputError(
                "fit_shared: the channels' runs differ in time or temperatures; fit them apart"
            )
    return head, rls


@dataclass
class _Design:
    """The design every channel shares: terms, the per-run offset decision, blocks, the
    base-variable scaling (centres and scales from ≤ SCALING_SAMPLES samples)."""

    head: PolyBase
    runs: list[RunData]
    terms: list[Term]
    uses_rate: bool
    n_total: int
    decision: OffsetDecision
    m: int
    n_folds: int
    plans: list[list[Block]]
    scaling: BaseScaling

    @property
    def p(self) -> int:
        return len(self.terms)

    @property
    def names(self) -> list[str]:
        """Column names: the terms, then the offsets (or the constant)."""
        if self.decision.used:
            return [t.name for t in self.terms] + [
                f"offset[{r.name or i + 1}]" for i, r in enumerate(self.runs)
            ]
        return [t.name for t in self.terms] + ["const"]


def _shared_design(head: PolyBase, rl: list[RunData]) -> _Design:
    """Terms, offsets, blocks and scaling from the runs' temperatures (and the warning for
    a rate taken mostly over short segments)."""
    k = rl[0].temps_c.shape[1]
    terms = parse_terms(head.terms, k, head.order)
    uses_rate = any(t.uses_rate for t in terms)
    n_total = sum(r.n_samples for r in rl)
    decision = decide_run_offsets(head.per_run_offset, rl, head.family)
    m = len(rl) if decision.used else 1
    n_folds = 2 if head.select == "holdout" else 1
    if n_total <= len(terms) + m:
        raise ThermocalInputError(
            f"poly: {n_total} samples for {len(terms) + m} coefficients; need more samples "
            "than terms"
        )
    plans = [run_blocks(r.time_s, n_folds) for r in rl]
    if uses_rate:
        _warn_short_rates(head, rl, n_total)
    step = max(1, math.ceil(n_total / SCALING_SAMPLES))
    t_sub: list[FloatArray] = []
    r_sub: list[FloatArray] = []
    for r, plan in zip(rl, plans, strict=True):
        idx = np.arange(0, r.n_samples, step)
        t_sub.append(r.temps_c[idx])
        if uses_rate:
            r_sub.append(head._rates_at(r, plan, idx))
    scaling = fit_base_scaling(t_sub, r_sub if uses_rate else None, terms)
    return _Design(head, rl, terms, uses_rate, n_total, decision, m, n_folds, plans, scaling)


def _warn_short_rates(head: PolyBase, rl: list[RunData], n_total: int) -> None:
    shares = [short_rate_share(r.time_s, float(head.rate_interval_s), head.rate_method) for r in rl]
    n_short = sum(c for c, _ in shares)
    if n_short > SHORT_RATE_WARN_SHARE * n_total:
        warnings.warn(
            ConditioningWarning.naming(
                f"poly: {n_short / n_total:.0%} of the samples have a temperature rate taken "
                f"over less than half the rate interval ({head.rate_interval_s:g} s): the "
                f"record breaks into {sum(g for _, g in shares)} contiguous segment(s) at "
                "its gaps (bursts or dropouts), and a rate over a fraction of a second is "
                "temperature noise; the rate terms and the fitted rate range rest on it. "
                "Fit a plain polynomial ({order} N), average the record to one block per "
                "burst, or choose {rate_interval_s} shorter than the segments",
                "order",
                "rate_interval_s",
            ),
            stacklevel=4,
        )


class _DesignPass:
    """Passes over the design in blocks: ``[F | 1 | Y]`` per block (features once, every
    channel's target), with the temperature and rate ranges and each target's sums
    (n, Σ(y − y0), Σ(y − y0)²) gathered on the way."""

    def __init__(self, design: _Design, rls: list[list[RunData]]) -> None:
        self.d = design
        self.rls = rls
        rl, k = design.runs, design.runs[0].temps_c.shape[1]
        self.temp_lo = np.full((len(rl), k), np.inf)
        self.temp_hi = np.full((len(rl), k), -np.inf)
        self.rate_lo = np.full((len(rl), k), np.inf)
        self.rate_hi = np.full((len(rl), k), -np.inf)
        self.sums = np.zeros((len(rls), 3))
        self.y0 = np.array(
            [float(cast(FloatArray, rs[0].signal)[0]) - rs[0].known_input for rs in rls]
        )
        self.current_run = 0

    def chunks(self, wanted: Callable[[int], bool] | None = None) -> Iterator[Chunk]:
        """The blocks of every run.  Without ``wanted`` (the reducing pass) the ranges and
        sums are gathered on the way; with it (a later pass) they are left as they are and
        the rest of run ``i`` is skipped as soon as ``wanted(i)`` is false."""
        d, nt, p = self.d, len(self.rls), self.d.p
        bufs: dict[int, FloatArray] = {}
        gather = wanted is None
        if gather:
            self.sums[:] = 0.0
        for i, (r, plan) in enumerate(zip(d.runs, d.plans, strict=True)):
            self.current_run = i
            g = i if d.decision.used else 0
            sigs = [cast(FloatArray, rs[i].signal) for rs in self.rls]
            known = [rs[i].known_input for rs in self.rls]
            for s0, s1, a, b, fold in plan:
                if wanted is not None and not wanted(i):
                    break
                rates: FloatArray | None = None
                if d.uses_rate:
                    rates = segment_rates(
                        r.time_s[s0:s1],
                        r.temps_c[s0:s1],
                        np.arange(a - s0, b - s0),
                        float(d.head.rate_interval_s),
                        d.head.rate_method,
                    )
                    if gather:
                        np.minimum(self.rate_lo[i], rates.min(axis=0), out=self.rate_lo[i])
                        np.maximum(self.rate_hi[i], rates.max(axis=0), out=self.rate_hi[i])
                c = b - a
                if c not in bufs:
                    bufs[c] = np.empty((c, p + 1 + nt), order="F")
                    bufs[c][:, p] = 1.0
                A = bufs[c]
                Tf = np.asfortranarray(r.temps_c[a:b])  # contiguous columns
                if gather:
                    np.minimum(self.temp_lo[i], Tf.min(axis=0), out=self.temp_lo[i])
                    np.maximum(self.temp_hi[i], Tf.max(axis=0), out=self.temp_hi[i])
                term_features(d.terms, d.scaling, Tf, rates, out=A[:, :p])
                for j in range(nt):
                    y = np.subtract(sigs[j][a:b], known[j], out=A[:, p + 1 + j])
                    if gather:
                        dev = y - self.y0[j]
                        self.sums[j, 0] += c
                        self.sums[j, 1] += float(np.sum(dev))
                        self.sums[j, 2] += float(dev @ dev)
                yield A, g, fold

    def residuals(self, solved: Sequence[_Solved]) -> list[list[FloatArray]]:
        """Each channel's residuals per run (at most MAX_SAMPLES_PER_SERIES a run), a
        second pass over the same blocks that leaves a run once every channel has its
        residuals of it (the features of the rest would be computed for nothing: 10⁷
        samples a run need 2²¹)."""
        p = self.d.p
        per_run: list[list[list[FloatArray]]] = [[[] for _ in self.d.runs] for _ in solved]

        def wanted(i: int) -> bool:
            return any(sum(x.size for x in runs[i]) < MAX_SAMPLES_PER_SERIES for runs in per_run)

        for A, g, _fold in self.chunks(wanted):
            i = self.current_run
            for j, (kept, _sel, sol) in enumerate(solved):
                if sum(x.size for x in per_run[j][i]) >= MAX_SAMPLES_PER_SERIES:
                    continue
                pk = len(kept)
                e = A[:, p + 1 + j] - A[:, kept] @ sol.coef[:pk] - sol.coef[pk:][g]
                per_run[j][i].append(e)
        return [[np.concatenate(x) if x else np.zeros(0) for x in runs] for runs in per_run]


_Solved = tuple[list[int], dict[str, Any] | None, LstsqSolution]
"""(kept term columns, selection record or None, the least-squares solution)."""


def _solve_channel(mdl: PolyBase, red: Reduced, design: _Design) -> _Solved:
    """Term selection (if asked) and the least-squares solution of one channel."""
    p, m, names = design.p, design.m, design.names
    required = list(range(p, p + m))
    penalised = np.zeros(p + m, dtype=bool)
    penalised[:p] = True
    selection: dict[str, Any] | None = None
    kept = list(range(p))
    if mdl.select is not None:
        sel = forward_select(red, list(range(p)), required, names, cast(Any, mdl.select))
        kept = sorted(c for c in sel.kept if c < p)
        selection = {
            "method": sel.method,
            "kept": [names[c] for c in kept],
            "order_added": [names[c] for c in sel.kept if c < p],
            "path": sel.path,
        }
    sol = solve_r(
        red.combined(),
        red.n_total,
        names,
        penalised=penalised,
        ridge=float(mdl.ridge),
        rcond=mdl.rcond,
        noise_threshold=mdl.noise_threshold,
        columns=kept + required,
    )
    return kept, selection, sol


def _finish_channel(
    mdl: PolyBase,
    design: _Design,
    dp: _DesignPass,
    j: int,
    solved: _Solved,
    residuals: list[FloatArray],
    solver: str,
    runs: list[RunData],
) -> None:
    """One channel's fitted values: coefficients, offsets, the covariance scaled by the
    residuals' autocorrelation time τ (models.residuals), statistics and ranges."""
    kept, selection, sol = solved
    m, pk = design.m, len(kept)
    coef = sol.coef[:pk]
    offsets = sol.coef[pk:]
    n_s, s1_, s2_ = dp.sums[j]
    corr = residual_correlation(residuals, data_rms=math.sqrt(max(s2_, 0.0) / max(n_s, 1.0)))
    # [constant, coef] = L @ [coef, offsets]; constant = mean of the offsets
    L = np.zeros((pk + 1, pk + m))
    L[0, pk:] = 1.0 / m
    L[1:, :pk] = np.eye(pk)
    cov = corr.tau * (L @ sol.cov @ L.T)
    if sol.condition_number > COND_WARN:
        warnings.warn(
            ConditioningWarning.naming(
                f"poly: ill-conditioned design (condition number {sol.condition_number:.3g}); "
                f"{sol.n_truncated} singular value(s) truncated at rcond={mdl.rcond}; "
                "consider fewer terms, stepwise term selection or {ridge}",
                "ridge",
            ),
            stacklevel=4,
        )
    tss = s2_ - s1_ * s1_ / n_s
    mdl.terms_ = [design.terms[c] for c in kept]
    mdl.scaling_ = design.scaling
    mdl.coef_ = np.asarray(coef, dtype=np.float64)
    mdl.offsets_ = np.asarray(offsets, dtype=np.float64)
    mdl.constant_ = float(np.mean(offsets))
    mdl.cov_ = cov
    mdl.selection_ = selection
    stats = FitStats(
        n_samples=design.n_total,
        n_coefficients=pk + 1,
        rms_residual=math.sqrt(sol.rss / design.n_total),
        condition_number=sol.condition_number,
        r_squared=float(1.0 - sol.rss / tss) if tss > 0 else None,
        dof=sol.dof,
        extra={
            "rank": sol.rank,
            "n_truncated": sol.n_truncated,
            "rcond": mdl.rcond,
            "ridge": float(mdl.ridge),
            "solver": solver,
            "n_runs": len(runs),
            "per_run_offsets": [float(o) for o in offsets] if design.decision.used else None,
            "offset_decision": design.decision.to_dict(),
            "residual_correlation": corr.to_dict(),
            "terms": [t.name for t in mdl.terms_],
            "selected_terms": selection["kept"] if selection else None,
        },
    )
    rate_bounds = (dp.rate_lo, dp.rate_hi) if design.uses_rate else None
    record_ranges(mdl, runs, stats, rate_bounds, (dp.temp_lo, dp.temp_hi))
