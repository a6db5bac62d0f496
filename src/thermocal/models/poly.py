"""Multi-sensor polynomial model with rate and coupling terms (SPEC §4a, seed 000).

The temperature-induced signal (bias [°/h] or [mg], or scale-factor error,
SPEC §4e) is

.. math::

    y = a_0 + \\sum_j a_j \\, u_{k_j}^{a} v_{k_j}^{b} w_{k_j}^{c}            (1)

with the centred and scaled base variables of every sensor k
(:mod:`thermocal.models.terms`, eq. 1): ``u = (T − c_T)/s_T`` [T in °C],
``v = (Ṫ − c_R)/s_R`` [Ṫ in °C/min], ``w = (T·Ṫ − c_W)/s_W``.  The default term
set ``seed000`` (37 coefficients for four sensors) spans exactly the seed's raw
cubic polynomial in T, Ṫ and TṪ, but the regressors are orthogonal-ish, so the
least-squares problem is solved accurately (column-equilibrated QR/SVD, the
condition number is reported).  Robust default: singular values of the
equilibrated term design (constant and offsets projected out) below ``rcond``
(1e-3) × the largest are truncated (a truncated-SVD solution; the count is
reported as ``n_truncated``, ``rank``) unless the data along them exceed
``noise_threshold`` (10) × the white-noise σ̂ — truncation relative to the
noise; a design
that is singular to 1e-11 raises :class:`~thermocal.errors.DesignError` naming
the dependent terms; ``ridge`` adds ``n·α‖γ‖²`` on the equilibrated term
coefficients.  Options: explicit term lists, ``order`` (plain polynomial in the
temperatures), stepwise selection (``select="bic"`` or ``"holdout"``), per-run
turn-on offsets as nuisance parameters (``per_run_offset``; the model's constant
is then the mean of the offsets).

Ṫ is the causal backward difference over ``rate_interval_s`` (default 60 s):
``Ṫ(t) = (T(t) − T(t_j))/(t − t_j)·60`` with ``t_j`` the first sample of the
current contiguous segment with ``t_j ≥ t − Δt`` (0 at a segment's first
sample; a step longer than 1.5 × the nominal interval starts a new segment);
see :func:`thermocal.preprocess.temperature_rate`.  ``"forward"`` and
``"centred"`` forms may be chosen for batch use (not for streaming).

Evaluation, in order, for every sample (this is what :meth:`PolyModel.predict`,
:class:`PolyStream` and the generated C code compute):

1. Ṫ_k from the *raw* temperatures (rule above) [°C/min];
2. clamp T_k to the fitted range ``range.temperature_c`` and Ṫ_k to
   ``range.rate_c_per_min`` (unless extrapolating; an
   :class:`~thermocal.errors.ExtrapolationWarning` is raised either way);
3. ``u_k, v_k, w_k`` by eq. (1) of :mod:`~thermocal.models.terms`, with
   ``w_k`` built from the clamped T_k·Ṫ_k;
4. ``y = constant + Σ_j coef[j] · u^t_power · v^rate_power · w^coupling_power``.

Model-file ``state`` layout (``"layout": "thermocal-poly-1"``), for the C export::

    {
      "layout": "thermocal-poly-1",
      "n_sensors": k,                      # temperature columns, order of "temperatures"
      "base": [                            # one entry per sensor, in column order
        {"name": "T1", "t_center": °C, "t_scale": °C,
         "rate_center": °C/min, "rate_scale": °C/min,
         "coupling_center": °C²/min, "coupling_scale": °C²/min}, ...],
      "terms": [                           # the kept terms, in coefficient order
        {"name": "T1^2", "sensor": 0,      # 0-based index into "base"/"temperatures"
         "t_power": 2, "rate_power": 0, "coupling_power": 0}, ...],
      "coef": [...],                       # coefficient of each term [signal unit]
      "constant": a0,                      # [signal unit] (mean of the per-run offsets)
      "offsets": [...],                    # per-run offsets (nuisance), run order of "data"
      "cov": [[...]],                      # covariance of [constant, coef...]
      "uses_rate": true,
      "rate": {"method": "backward", "interval_s": 60.0, "gap_factor": 1.5,
               "unit": "degC/min", "clamp": true},
      "selection": null | {"method": "bic"|"holdout", "kept": [...], "path": [...]}
    }

The ranges for step 2 are the file's ``range`` section (``temperature_c`` and
``rate_c_per_min``, keyed by temperature name, ``[lo, hi]``).  The file's
``coefficients`` list gives the same model expanded into raw monomials
``T_k^P Ṫ_k^Q`` (the seed's a0…a36 for ``seed000``), with standard errors;
those are for reading, the scaled basis above is for evaluation.
"""

from __future__ import annotations

import itertools
import math
import warnings
from collections import deque
from collections.abc import Iterator, Sequence
from typing import Any, ClassVar, Self, cast

import numpy as np
import numpy.typing as npt

from thermocal.errors import ConditioningWarning, ExtrapolationWarning, ThermocalInputError
from thermocal.models.base import (
    Coefficient,
    FitStats,
    ModelStream,
    RunData,
    TemperatureModel,
    register,
)
from thermocal.models.terms import (
    CHUNK_ROWS,
    BaseScaling,
    Chunk,
    Term,
    accumulate_r,
    fit_base_scaling,
    forward_select,
    monomial_name,
    parse_terms,
    raw_expansion,
    segment_rates,
    solve_r,
    temperature_rates,
    term_features,
)
from thermocal.preprocess import RATE_METHODS
from thermocal.recording import GAP_FACTOR, FloatArray, contiguous_slices
from thermocal.units import SECONDS_PER_MINUTE

DEFAULT_RCOND = 1.0e-3
"""Singular values of the equilibrated term design below this × the largest are truncated.

Chosen on the simulator (``rlg`` preset, ``rlg-modelling`` → ``rlg-validation``): the
seed000 design there has κ ≈ 3e6; without truncation the directions with tiny
singular values carry noise amplified up to κ× and the model fails on the
validation profile; with 1e-3 about 8 of 36 directions are dropped and the
validation removal of the temperature-induced bias rises (noise-free: 97.5 → 99.7 %)."""

DEFAULT_NOISE_THRESHOLD = 10.0
"""A truncated component is kept after all when the data along it exceed 10 σ̂ (white-noise σ̂)."""

COND_WARN = 1.0e8
"""Condition number above which a :class:`ConditioningWarning` is raised."""

SCALING_SAMPLES = 200_000
"""Centres and scales of the base variables come from at most this many evenly spaced samples."""

HOLDOUT_BLOCKS = 10
"""Hold-out selection splits each run into this many equal blocks; odd blocks are held out."""

STATE_LAYOUT = "thermocal-poly-1"


def check_runs(runs: Sequence[RunData], family: str) -> list[RunData]:
    """Common input checks: at least one run, a signal, the same temperature columns."""
    rl = list(runs)
    if not rl:
        raise ThermocalInputError(f"{family}: no runs to fit")
    k = rl[0].temps_c.shape[1]
    for r in rl:
        if r.signal is None:
            raise ThermocalInputError(f"{r.name or 'run'}: no signal to fit")
        if r.temps_c.shape[1] != k:
            raise ThermocalInputError(
                f"{r.name or 'run'}: has {r.temps_c.shape[1]} temperature columns, "
                f"the first run {k}"
            )
        if r.temp_names and rl[0].temp_names and r.temp_names != rl[0].temp_names:
            raise ThermocalInputError(
                f"{r.name or 'run'}: temperature columns {list(r.temp_names)} differ from the "
                f"first run's {list(rl[0].temp_names)}"
            )
        if r.n_samples < 2:
            raise ThermocalInputError(f"{r.name or 'run'}: needs at least 2 samples")
    return rl


def warn_rate_range(
    seen_lo: FloatArray,
    seen_hi: FloatArray,
    rate_range: FloatArray,
    names: Sequence[str],
    used: Sequence[int],
    *,
    extrapolate: bool,
) -> None:
    """:class:`ExtrapolationWarning` when Ṫ of a used sensor left the fitted rate range."""
    lo, hi = rate_range[:, 0], rate_range[:, 1]
    bad = [j for j in used if seen_lo[j] < lo[j] or seen_hi[j] > hi[j]]
    if bad:
        where = ", ".join(
            f"d{names[j]} {seen_lo[j]:.3g}…{seen_hi[j]:.3g} °C/min (fitted {lo[j]:.3g}…{hi[j]:.3g})"
            for j in bad
        )
        action = "extrapolating" if extrapolate else "clamped to the fitted range"
        warnings.warn(
            f"temperature rate outside the model's fitted range: {where}; {action}",
            ExtrapolationWarning,
            stacklevel=3,
        )


Block = tuple[int, int, int, int, int]
"""(segment start, segment stop, block start, block stop, fold) row indices of one block."""


def run_blocks(time_s: FloatArray, n_folds: int = 1, chunk: int = CHUNK_ROWS) -> list[Block]:
    """Blocks of ≤ ``chunk`` rows that never cross a gap (nor, with 2 folds, a hold-out edge).

    With ``n_folds == 2`` the run is cut into :data:`HOLDOUT_BLOCKS` equal parts
    by sample index and the odd parts form fold 1 (blocked hold-out).
    """
    n = int(time_s.size)
    if n_folds == 1:
        edges = [0, n]
    else:
        edges = sorted({round(n * j / HOLDOUT_BLOCKS) for j in range(HOLDOUT_BLOCKS + 1)})
    out: list[Block] = []
    for sl in contiguous_slices(time_s):
        s0, s1 = int(sl.start), int(sl.stop)
        cuts = sorted({s0, s1, *[e for e in edges if s0 < e < s1]})
        for a0, b0 in itertools.pairwise(cuts):
            part = int(np.searchsorted(edges, a0, side="right")) - 1
            fold = part % 2 if n_folds == 2 else 0
            for a in range(a0, b0, chunk):
                out.append((s0, s1, a, min(b0, a + chunk), fold))
    return out


def record_ranges(
    model: TemperatureModel,
    runs: Sequence[RunData],
    stats: FitStats,
    rate_bounds: tuple[FloatArray, FloatArray] | None,
    temp_bounds: tuple[FloatArray, FloatArray] | None = None,
) -> None:
    """``model._record_common`` fed with per-run minima and maxima (no full-size copies).

    ``rate_bounds`` / ``temp_bounds`` = (per-run minima, per-run maxima) of Ṫ / T,
    shape (n_runs, k); the temperature bounds are computed here when not given.
    """
    if temp_bounds is None:
        lo_t = np.array([[r.temps_c[:, j].min() for j in range(r.temps_c.shape[1])] for r in runs])
        hi_t = np.array([[r.temps_c[:, j].max() for j in range(r.temps_c.shape[1])] for r in runs])
        temp_bounds = (lo_t, hi_t)
    summary = [
        RunData(
            time_s=np.array([0.0, 1.0]),
            temps_c=np.vstack([temp_bounds[0][i], temp_bounds[1][i]]),
            temp_names=r.temp_names,
            name=r.name,
        )
        for i, r in enumerate(runs)
    ]
    rates = (
        [np.vstack([lo, hi]) for lo, hi in zip(rate_bounds[0], rate_bounds[1], strict=True)]
        if rate_bounds is not None
        else None
    )
    model._record_common(summary, stats, rates=rates)
    model.data_ = [{"file": r.name, "n_samples": r.n_samples} for r in runs]


@register
class PolyModel(TemperatureModel):
    """Polynomial in T, Ṫ and TṪ of several sensors (SPEC §4a); see the module docstring.

    Parameters
    ----------
    terms : ``"seed000"`` (default), a comma-separated term text or a list of
        term texts (:func:`thermocal.models.terms.parse_terms`).
    order : plain polynomial T, …, T^order per sensor (instead of ``terms``).
    rate_interval_s : Δt of Ṫ [s] (default 60).
    rate_method : ``"backward"`` (causal, default), ``"forward"`` or ``"centred"``.
    select : None, ``"bic"`` or ``"holdout"`` (forward stepwise term selection).
    ridge : ridge α on the unit-RMS term columns (0 = none).
    rcond : truncation threshold of the SVD solution (relative to s_max).
    per_run_offset : one turn-on offset per run, estimated as nuisance parameters.
    solver : ``"auto"`` (Gram when well conditioned, else chunked QR), ``"qr"``, ``"gram"``.
    noise_threshold : a component below ``rcond`` is kept when ``|uᵢᵀz| > k σ̂`` (None: never).
    """

    family: ClassVar[str] = "poly"
    uses_rate: ClassVar[bool] = True

    terms_: list[Term]
    scaling_: BaseScaling
    coef_: FloatArray
    constant_: float
    offsets_: FloatArray
    cov_: FloatArray
    selection_: dict[str, Any] | None

    def __init__(
        self,
        terms: str | list[str] | None = "seed000",
        order: int | None = None,
        rate_interval_s: float = 60.0,
        rate_method: str = "backward",
        select: str | None = None,
        ridge: float = 0.0,
        rcond: float | None = DEFAULT_RCOND,
        per_run_offset: bool = True,
        solver: str = "auto",
        noise_threshold: float | None = DEFAULT_NOISE_THRESHOLD,
    ) -> None:
        self.terms = terms
        self.order = order
        self.rate_interval_s = rate_interval_s
        self.rate_method = rate_method
        self.select = select
        self.ridge = ridge
        self.rcond = rcond
        self.per_run_offset = per_run_offset
        self.solver = solver
        self.noise_threshold = noise_threshold

    # -- construction from the command line --
    CLI_KEYS: ClassVar[dict[str, str]] = {
        "terms": "terms",
        "order": "order",
        "rate_interval_s": "rate_interval_s",
        "rate_method": "rate_method",
        "select": "select",
        "ridge": "ridge",
        "rcond": "rcond",
        "per_run_offset": "per_run_offset",
        "solver": "solver",
        "noise_threshold": "noise_threshold",
    }

    @classmethod
    def from_cli_options(cls, options: dict[str, Any]) -> PolyModel:
        """Build from the ``thermocal fit`` option dict (keys in :mod:`thermocal.cli.fit_cmd`)."""
        params: dict[str, Any] = {}
        for key, value in options.items():
            if value is None:
                continue
            if key not in cls.CLI_KEYS:
                raise ThermocalInputError(f"option {key!r} does not apply to model 'poly'")
            params[cls.CLI_KEYS[key]] = value
        return cls(**params)

    # -- helpers --
    def _check_params(self) -> None:
        if self.rate_method not in RATE_METHODS:
            raise ThermocalInputError(
                f"unknown rate method {self.rate_method!r}; use one of {', '.join(RATE_METHODS)}"
            )
        if not (isinstance(self.rate_interval_s, int | float) and self.rate_interval_s > 0):
            raise ThermocalInputError(
                f"rate interval must be a positive number of seconds, got {self.rate_interval_s!r}"
            )
        if self.select not in (None, "bic", "holdout"):
            raise ThermocalInputError(f"unknown selection {self.select!r}; use bic or holdout")
        if self.ridge < 0:
            raise ThermocalInputError(f"ridge α must be ≥ 0, got {self.ridge}")
        if self.solver not in ("auto", "qr", "gram"):
            raise ThermocalInputError(f"unknown solver {self.solver!r}; use auto, qr or gram")

    # -- estimator contract --
    def fit(self, runs: Sequence[RunData]) -> Self:
        """Least-squares fit of eq. (1) on one or several runs; returns ``self``.

        Works through each run in blocks of :data:`~thermocal.models.terms.CHUNK_ROWS`
        samples (Ṫ, features and the reduction per block), so memory stays at the
        input arrays plus a few MB.
        """
        self._check_params()
        rl = check_runs(runs, self.family)
        k = rl[0].temps_c.shape[1]
        terms = parse_terms(self.terms, k, self.order)
        uses_rate = any(t.uses_rate for t in terms)
        n_total = sum(r.n_samples for r in rl)
        p = len(terms)
        m = len(rl) if self.per_run_offset else 1
        n_folds = 2 if self.select == "holdout" else 1
        if n_total <= p + m:
            raise ThermocalInputError(
                f"poly: {n_total} samples for {p + m} coefficients; need more samples than terms"
            )
        plans = [run_blocks(r.time_s, n_folds) for r in rl]
        # centres and scales of the base variables from ≤ SCALING_SAMPLES evenly spaced samples
        step = max(1, math.ceil(n_total / SCALING_SAMPLES))
        t_sub: list[FloatArray] = []
        r_sub: list[FloatArray] = []
        for r, plan in zip(rl, plans, strict=True):
            idx = np.arange(0, r.n_samples, step)
            t_sub.append(r.temps_c[idx])
            if uses_rate:
                r_sub.append(self._rates_at(r, plan, idx))
        scaling = fit_base_scaling(t_sub, r_sub if uses_rate else None, terms)
        del t_sub, r_sub
        temp_lo = np.full((len(rl), k), np.inf)
        temp_hi = np.full((len(rl), k), -np.inf)
        rate_lo = np.full((len(rl), k), np.inf)
        rate_hi = np.full((len(rl), k), -np.inf)
        sums = np.zeros(3)  # n, Σ(y − y0), Σ(y − y0)²

        def make_chunks() -> Iterator[Chunk]:
            bufs: dict[int, FloatArray] = {}
            sums[:] = 0.0
            y0 = float(cast(FloatArray, rl[0].signal)[0]) - rl[0].known_input
            for i, (r, plan) in enumerate(zip(rl, plans, strict=True)):
                g = i if self.per_run_offset else 0
                sig = cast(FloatArray, r.signal)
                for s0, s1, a, b, fold in plan:
                    rates: FloatArray | None = None
                    if uses_rate:
                        rates = segment_rates(
                            r.time_s[s0:s1],
                            r.temps_c[s0:s1],
                            np.arange(a - s0, b - s0),
                            float(self.rate_interval_s),
                            self.rate_method,
                        )
                        np.minimum(rate_lo[i], rates.min(axis=0), out=rate_lo[i])
                        np.maximum(rate_hi[i], rates.max(axis=0), out=rate_hi[i])
                    c = b - a
                    if c not in bufs:
                        bufs[c] = np.empty((c, p + 2), order="F")
                        bufs[c][:, p] = 1.0
                    A = bufs[c]
                    Tf = np.asfortranarray(r.temps_c[a:b])  # contiguous columns
                    np.minimum(temp_lo[i], Tf.min(axis=0), out=temp_lo[i])
                    np.maximum(temp_hi[i], Tf.max(axis=0), out=temp_hi[i])
                    term_features(terms, scaling, Tf, rates, out=A[:, :p])
                    y = np.subtract(sig[a:b], r.known_input, out=A[:, p + 1])
                    d = y - y0
                    sums[0] += c
                    sums[1] += float(np.sum(d))
                    sums[2] += float(d @ d)
                    yield A, g, fold

        red = accumulate_r(make_chunks, p, m, n_folds=n_folds, solver=cast(Any, self.solver))
        names = [t.name for t in terms] + (
            [f"offset[{r.name or i + 1}]" for i, r in enumerate(rl)]
            if self.per_run_offset
            else ["const"]
        )
        required = list(range(p, p + m))
        selection: dict[str, Any] | None = None
        kept = list(range(p))
        if self.select is not None:
            sel = forward_select(red, list(range(p)), required, names, cast(Any, self.select))
            kept = sorted(c for c in sel.kept if c < p)
            selection = {
                "method": sel.method,
                "kept": [names[c] for c in kept],
                "order_added": [names[c] for c in sel.kept if c < p],
                "path": sel.path,
            }
        penalised = np.zeros(p + m, dtype=bool)
        penalised[:p] = True
        sol = solve_r(
            red.combined(),
            red.n_total,
            names,
            penalised=penalised,
            ridge=float(self.ridge),
            rcond=self.rcond,
            noise_threshold=self.noise_threshold,
            columns=kept + required,
        )
        pk = len(kept)
        coef = sol.coef[:pk]
        offsets = sol.coef[pk:]
        # [constant, coef] = L @ [coef, offsets]; constant = mean of the offsets
        L = np.zeros((pk + 1, pk + m))
        L[0, pk:] = 1.0 / m
        L[1:, :pk] = np.eye(pk)
        cov = L @ sol.cov @ L.T
        if sol.condition_number > COND_WARN:
            warnings.warn(
                f"poly: ill-conditioned design (condition number {sol.condition_number:.3g}); "
                f"{sol.n_truncated} singular value(s) truncated at rcond={self.rcond}; "
                "consider fewer terms, --select or --ridge",
                ConditioningWarning,
                stacklevel=2,
            )
        n_s, s1_, s2_ = sums
        tss = s2_ - s1_ * s1_ / n_s
        self.terms_ = [terms[c] for c in kept]
        self.scaling_ = scaling
        self.coef_ = np.asarray(coef, dtype=np.float64)
        self.offsets_ = np.asarray(offsets, dtype=np.float64)
        self.constant_ = float(np.mean(offsets))
        self.cov_ = cov
        self.selection_ = selection
        stats = FitStats(
            n_samples=n_total,
            n_coefficients=pk + 1,
            rms_residual=math.sqrt(sol.rss / n_total),
            condition_number=sol.condition_number,
            r_squared=float(1.0 - sol.rss / tss) if tss > 0 else None,
            dof=sol.dof,
            extra={
                "rank": sol.rank,
                "n_truncated": sol.n_truncated,
                "rcond": self.rcond,
                "ridge": float(self.ridge),
                "solver": red.solver,
                "n_runs": len(rl),
                "per_run_offsets": [float(o) for o in offsets] if self.per_run_offset else None,
                "terms": [t.name for t in self.terms_],
                "selected_terms": selection["kept"] if selection else None,
            },
        )
        record_ranges(
            self, rl, stats, (rate_lo, rate_hi) if uses_rate else None, (temp_lo, temp_hi)
        )
        return self

    def _rates_at(self, run: RunData, plan: list[Block], idx: npt.NDArray[np.intp]) -> FloatArray:
        out = np.zeros((idx.size, run.temps_c.shape[1]))
        for s0, s1 in sorted({(b[0], b[1]) for b in plan}):
            sel = (idx >= s0) & (idx < s1)
            if sel.any():
                out[sel] = segment_rates(
                    run.time_s[s0:s1],
                    run.temps_c[s0:s1],
                    idx[sel] - s0,
                    float(self.rate_interval_s),
                    self.rate_method,
                )
        return out

    def rates(self, time_s: FloatArray, temps_c: FloatArray) -> FloatArray:
        """Ṫ of every temperature column [°C/min] with the model's rate form and Δt."""
        return temperature_rates(time_s, temps_c, float(self.rate_interval_s), self.rate_method)

    @property
    def model_uses_rate(self) -> bool:
        """True when a fitted term uses Ṫ."""
        return any(t.uses_rate for t in self.terms_)

    def _evaluate(self, temps_c: FloatArray, rates: FloatArray | None) -> FloatArray:
        """``constant + Σ coef_j · term_j`` for a block (temperatures and rates already clamped)."""
        F = term_features(self.terms_, self.scaling_, temps_c, rates)
        out: FloatArray = F @ self.coef_ + self.constant_
        return out

    def _rate_sensors(self) -> list[int]:
        return sorted({t.sensor for t in self.terms_ if t.uses_rate})

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """Temperature-induced signal of every sample [signal unit] (module docstring steps 1–4)."""
        self.check_fitted()
        self._check_temps(run)
        temps = self.clamp(run.temps_c, extrapolate=extrapolate)
        uses_rate = self.model_uses_rate
        js = self._rate_sensors()
        rr = self.rate_range_
        n = run.n_samples
        out = np.empty(n)
        seen_lo = np.full(run.temps_c.shape[1], np.inf)
        seen_hi = np.full(run.temps_c.shape[1], -np.inf)
        bufs: dict[int, FloatArray] = {}
        for s0, s1, a, b, _f in run_blocks(run.time_s, 1):
            rates: FloatArray | None = None
            if uses_rate:
                rates = segment_rates(
                    run.time_s[s0:s1],
                    run.temps_c[s0:s1],
                    np.arange(a - s0, b - s0),
                    float(self.rate_interval_s),
                    self.rate_method,
                )
                np.minimum(seen_lo, rates.min(axis=0), out=seen_lo)
                np.maximum(seen_hi, rates.max(axis=0), out=seen_hi)
                if rr is not None and not extrapolate:
                    for j in js:
                        np.clip(rates[:, j], rr[j, 0], rr[j, 1], out=rates[:, j])
            c = b - a
            if c not in bufs:
                bufs[c] = np.empty((c, len(self.terms_)), order="F")
            Tf = np.asfortranarray(temps[a:b])
            F = term_features(self.terms_, self.scaling_, Tf, rates, out=bufs[c])
            out[a:b] = F @ self.coef_ + self.constant_
        if uses_rate and rr is not None:
            warn_rate_range(seen_lo, seen_hi, rr, self.temp_names_, js, extrapolate=extrapolate)
        return out

    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> PolyStream:
        """Sample-by-sample twin of :meth:`predict` (needs the backward rate form)."""
        self.check_fitted()
        if self.model_uses_rate and self.rate_method != "backward":
            raise ThermocalInputError(
                "streaming needs the causal 'backward' rate form; this model uses "
                f"{self.rate_method!r}"
            )
        return PolyStream(self, sample_interval_s, extrapolate=extrapolate)

    def coefficients(self) -> list[Coefficient]:
        """Raw-monomial coefficients ``a`` of ``T_k^P Ṫ_k^Q`` with standard errors (seed form)."""
        self.check_fitted()
        keys, M = raw_expansion(self.terms_, self.scaling_)
        beta = np.r_[self.constant_, self.coef_]
        raw = M @ beta
        cov = M @ self.cov_ @ M.T
        se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        out: list[Coefficient] = []
        for key, v, s in zip(keys, raw, se, strict=True):
            _k, P, Q = key
            unit = self.signal_unit
            if P:
                unit += "/degC" + (f"^{P}" if P > 1 else "")
            if Q:
                unit += "/(degC/min)" + (f"^{Q}" if Q > 1 else "")
            out.append(
                Coefficient(
                    name=monomial_name(key),
                    value=float(v),
                    stderr=float(s) if math.isfinite(s) else None,
                    unit=unit,
                )
            )
        return out

    def scaled_coefficients(self) -> list[Coefficient]:
        """Coefficients in the scaled basis actually evaluated (constant first)."""
        self.check_fitted()
        se = np.sqrt(np.clip(np.diag(self.cov_), 0.0, None))
        names = ["const"] + [t.name for t in self.terms_]
        vals = np.r_[self.constant_, self.coef_]
        return [
            Coefficient(n, float(v), float(s) if math.isfinite(s) else None, self.signal_unit)
            for n, v, s in zip(names, vals, se, strict=True)
        ]

    # -- state --
    def _state(self) -> dict[str, Any]:
        return {
            "layout": STATE_LAYOUT,
            "n_sensors": int(self.scaling_.t_center.size),
            "base": self.scaling_.to_list(self.temp_names_ if hasattr(self, "temp_names_") else ()),
            "terms": [t.to_dict() for t in self.terms_],
            "coef": [float(c) for c in self.coef_],
            "constant": float(self.constant_),
            "offsets": [float(o) for o in self.offsets_],
            "cov": self.cov_.tolist(),
            "uses_rate": self.model_uses_rate,
            "rate": {
                "method": self.rate_method,
                "interval_s": float(self.rate_interval_s),
                "gap_factor": GAP_FACTOR,
                "unit": "degC/min",
                "clamp": True,
            },
            "selection": self.selection_,
        }

    def _set_state(self, state: dict[str, Any]) -> None:
        if state.get("layout") != STATE_LAYOUT:
            raise ThermocalInputError(
                f"poly model state layout {state.get('layout')!r} is not {STATE_LAYOUT!r}"
            )
        self.scaling_ = BaseScaling.from_list(state["base"])
        self.terms_ = [Term.from_dict(t) for t in state["terms"]]
        self.coef_ = np.asarray(state["coef"], dtype=np.float64)
        self.constant_ = float(state["constant"])
        self.offsets_ = np.asarray(state.get("offsets", []), dtype=np.float64)
        self.cov_ = np.asarray(state["cov"], dtype=np.float64)
        self.selection_ = state.get("selection")
        if self.coef_.size != len(self.terms_):
            raise ThermocalInputError("poly model state: coefficient and term counts differ")

    def to_dict(self) -> dict[str, Any]:
        d = super().to_dict()
        if not self.model_uses_rate:
            d["rate"] = None
        return d


class PolyStream(ModelStream):
    """Sample-by-sample :class:`PolyModel` (module docstring steps 1–4).

    Keeps the samples of the last Δt of the current contiguous segment for the
    backward rate; a step longer than ``GAP_FACTOR × sample_interval_s`` starts
    a new segment (rate restarts from 0).  Warns once per stream when a sample
    leaves the fitted range.
    """

    def __init__(self, model: PolyModel, sample_interval_s: float, *, extrapolate: bool) -> None:
        if not sample_interval_s > 0:
            raise ThermocalInputError(f"sample interval must be positive, got {sample_interval_s}")
        self.model = model
        self.extrapolate = extrapolate
        self.gap_s = GAP_FACTOR * float(sample_interval_s)
        self.interval_s = float(model.rate_interval_s)
        self.uses_rate = model.model_uses_rate
        self.t_lo = model.temp_range_[:, 0]
        self.t_hi = model.temp_range_[:, 1]
        rr = model.rate_range_
        self.r_lo = rr[:, 0] if rr is not None else None
        self.r_hi = rr[:, 1] if rr is not None else None
        self.rate_sensors = model._rate_sensors()
        self.reset()

    def reset(self) -> None:
        self._buf: deque[tuple[float, FloatArray]] = deque()
        self._last_t: float | None = None
        self._warned: set[str] = set()

    def _warn(self, what: str, msg: str) -> None:
        if what not in self._warned:
            self._warned.add(what)
            warnings.warn(msg, ExtrapolationWarning, stacklevel=3)

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        t = float(time_s)
        T = np.asarray(temps_c, dtype=np.float64).reshape(1, -1)
        rates: FloatArray | None = None
        if self.uses_rate:
            if self._last_t is not None and t - self._last_t > self.gap_s:
                self._buf.clear()
            self._last_t = t
            self._buf.append((t, T[0].copy()))
            while self._buf[0][0] < t - self.interval_s:
                self._buf.popleft()
            t_lo, T_lo = self._buf[0]
            span = t - t_lo
            if span > 0:
                rates = ((T[0] - T_lo) / span * SECONDS_PER_MINUTE).reshape(1, -1)
            else:
                rates = np.zeros_like(T)
        action = "extrapolating" if self.extrapolate else "clamped to the fitted range"
        if np.any(np.less(T, self.t_lo)) or np.any(np.greater(T, self.t_hi)):
            self._warn("T", f"temperature outside the model's fitted range; {action}")
            if not self.extrapolate:
                T = np.clip(T, self.t_lo, self.t_hi)
        if rates is not None and self.r_lo is not None and self.r_hi is not None:
            js = self.rate_sensors
            if (rates[0, js] < self.r_lo[js]).any() or (rates[0, js] > self.r_hi[js]).any():
                self._warn("R", f"temperature rate outside the model's fitted range; {action}")
                if not self.extrapolate:
                    rates = rates.copy()
                    rates[0, js] = np.clip(rates[0, js], self.r_lo[js], self.r_hi[js])
        return float(self.model._evaluate(T, rates)[0])
