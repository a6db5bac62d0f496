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

How steps 3–4 are computed (:class:`EvalPlan`; the same operations in
:meth:`PolyModel.predict` on numpy blocks and in :class:`PolyStream` on Python
floats, so the two agree to the last bit): the scales are folded into the
coefficients and the pure powers of each variable summed by Horner's rule in the
centred variable, e.g. ``((a₃/s³·d + a₂/s²)·d + a₁/s)·d`` with ``d = T − c_T``;
the centres of Ṫ and T·Ṫ (near 0) are folded into the coefficients and the
constant when every ``|c| ≤ s``.  Mathematically the same model as eq. (1);
numerically it differs from the literal sum of the scaled terms by rounding only
(~1e-16 relative).  ``predict`` works in cache-sized blocks of
:data:`PREDICT_BLOCK_ROWS` samples, with Ṫ's partner samples found per block by
:func:`~thermocal.models.terms.backward_partners` (a slice on regular sampling).

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
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Self, cast

import numpy as np
import numpy.typing as npt

from thermocal.errors import ConditioningWarning, ExtrapolationWarning, ThermocalInputError
from thermocal.models.base import (
    ChunkContext,
    Coefficient,
    FitStats,
    ModelStream,
    RunData,
    TemperatureModel,
    register,
)
from thermocal.models.residuals import MAX_SAMPLES_PER_SERIES, residual_correlation
from thermocal.models.terms import (
    CHUNK_ROWS,
    BaseScaling,
    Chunk,
    LstsqSolution,
    Reduced,
    Term,
    accumulate_targets,
    backward_partners,
    fit_base_scaling,
    forward_select,
    gap_free_slices,
    monomial_name,
    parse_terms,
    raw_expansion,
    segment_rates,
    solve_r,
    step_range,
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


OFFSET_OVERLAP_FRACTION = 0.5
"""Two runs *overlap* when their central temperature ranges (2nd…98th percentile of the
first temperature column) share at least this fraction of the narrower range."""


@dataclass(frozen=True)
class OffsetDecision:
    """Whether per-run turn-on offsets are estimated, and why (issue 13, honest statistics).

    A per-run offset is a free constant per run. Offsets and the temperature function are
    only separable where runs cover common temperatures: two runs at separate temperatures
    let the offsets absorb the whole difference between runs, and the slope then comes
    from the within-run variation alone (a real BMI270 pair gave 449 instead of 69
    °/h/°C). The runs form a graph (edge = overlap ≥ :data:`OFFSET_OVERLAP_FRACTION` of
    the narrower central range); offsets are separable when the graph is connected.

    ``used`` offsets estimated; ``requested`` the setting (None = automatic);
    ``connected`` the overlap graph is connected; ``groups`` run names per connected
    group; ``ranges_c`` central range per run [°C]; ``reason`` one line for the user.
    """

    used: bool
    requested: bool | None
    connected: bool
    groups: list[list[str]]
    ranges_c: list[tuple[float, float]]
    reason: str

    def to_dict(self) -> dict[str, Any]:
        """JSON form (model file ``fit.extra.offset_decision``)."""
        return {
            "used": self.used,
            "requested": self.requested,
            "connected": self.connected,
            "groups": self.groups,
            "ranges_c": [list(r) for r in self.ranges_c],
            "reason": self.reason,
        }


def run_overlap_groups(
    ranges_c: Sequence[tuple[float, float]], fraction: float = OFFSET_OVERLAP_FRACTION
) -> list[list[int]]:
    """Connected groups of runs whose temperature ranges overlap.

    Runs i and j are linked when ``overlap(i, j) ≥ fraction × min(width_i, width_j)`` with
    ``overlap = min(hi) − max(lo)`` (> 0); a run of (near) zero width — a hold — is linked
    to a run whose range contains its temperature. Groups by union–find.
    """
    n = len(ranges_c)
    parent = list(range(n))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(n):
        for j in range(i + 1, n):
            (lo_i, hi_i), (lo_j, hi_j) = ranges_c[i], ranges_c[j]
            overlap = min(hi_i, hi_j) - max(lo_i, lo_j)
            narrow = min(hi_i - lo_i, hi_j - lo_j)
            tol = 1e-6 * max(1.0, abs(lo_i), abs(lo_j))
            if overlap >= max(fraction * narrow, 0.0) - tol and overlap >= -tol:
                parent[find(i)] = find(j)
    groups: dict[int, list[int]] = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(i)
    return sorted(groups.values())


def decide_run_offsets(
    requested: bool | None, runs: Sequence[RunData], family: str, column: int = 0
) -> OffsetDecision:
    """Per-run offsets or one pooled constant, from the runs' temperature overlap.

    ``requested`` None (automatic, the default): offsets when the runs' overlap graph is
    connected (:func:`run_overlap_groups`), otherwise the pooled fit and a
    :class:`ConditioningWarning` naming the separate groups. True: offsets, with that
    warning when the graph is not connected (the slope then rests on within-run
    variation only). False: pooled. One run: nothing to decide.
    ``column`` the temperature column whose ranges are compared.
    """
    names = [r.name or f"run {i + 1}" for i, r in enumerate(runs)]
    ranges = [
        (
            float(np.percentile(r.temps_c[:, column], 2)),
            float(np.percentile(r.temps_c[:, column], 98)),
        )
        for r in runs
    ]
    if len(runs) < 2:
        return OffsetDecision(False, requested, True, [names], ranges, "one run: one constant")
    groups = run_overlap_groups(ranges)
    named = [[names[i] for i in g] for g in groups]
    connected = len(groups) == 1
    if requested is False:
        return OffsetDecision(False, False, connected, named, ranges, "pooled, as asked")
    if connected:
        return OffsetDecision(
            True,
            requested,
            True,
            named,
            ranges,
            "per-run offsets: the runs overlap in temperature",
        )
    desc = "; ".join(
        "[" + ", ".join(f"{names[i]} {ranges[i][0]:.1f}…{ranges[i][1]:.1f} °C" for i in g) + "]"
        for g in groups
    )
    why = (
        f"{family}: the runs fall into {len(groups)} groups that do not overlap in temperature "
        f"({desc}); per-run offsets would absorb the difference between them and the "
        "temperature dependence would come from within-run variation only"
    )
    if requested is True:
        warnings.warn(
            why + "; per-run offsets kept as asked (--per-run-offset): distrust the slope and "
            "its standard error, or record runs that share temperatures",
            ConditioningWarning,
            stacklevel=3,
        )
        return OffsetDecision(True, True, False, named, ranges, why)
    warnings.warn(
        why + "; fitting one common offset instead (pooled). Pass --per-run-offset to force "
        "offsets, or record runs that share temperatures",
        ConditioningWarning,
        stacklevel=3,
    )
    return OffsetDecision(False, None, False, named, ranges, why + "; pooled")


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


SHORT_RATE_SPAN_FRACTION = 0.5
"""Ṫ taken over less than this fraction of the rate interval Δt is a *short-span* rate."""

SHORT_RATE_WARN_SHARE = 0.1
"""Warn when more than this share of the samples have a short-span Ṫ."""


def short_rate_share(time_s: FloatArray, interval_s: float, method: str) -> tuple[int, int]:
    """Samples whose Ṫ spans less than half of Δt, and the contiguous segments.

    Ṫ is taken inside contiguous segments (a gap > :data:`GAP_FACTOR` × the median step
    ends one), so near a segment's start (backward), end (forward) or either (centred)
    the difference covers less than Δt; a segment shorter than Δt — a 5 s burst logged
    every 5 min — has *only* such samples, and its Ṫ is temperature noise divided by a
    fraction of a second (issue 13 item 8). Returns (count, number of segments).
    """
    half = SHORT_RATE_SPAN_FRACTION * interval_s
    count = 0
    n_seg = 0
    for sl in contiguous_slices(time_s):
        n_seg += 1
        ts = time_s[sl]
        from_start = ts - ts[0]
        to_end = ts[-1] - ts
        if method == "backward":
            short = from_start < half
        elif method == "forward":
            short = to_end < half
        else:
            short = (
                np.minimum(from_start, interval_s / 2.0) + np.minimum(to_end, interval_s / 2.0)
            ) < half
        count += int(np.count_nonzero(short))
    return count, n_seg


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


# --- evaluation: one plan for predict (numpy blocks) and the stream (Python floats) ----------

PREDICT_BLOCK_ROWS = 8192
"""Rows per block in :meth:`PolyModel.predict`: the block's temporaries (a few
(k × rows) arrays, ~1.5 MB for four sensors) stay in the L2 cache.  (More than 4096:
numpy's broadcast of a coefficient column is slow on smaller rows.)"""

KINDS = ("u", "v", "w")
"""Base variables of eq. (1) of :mod:`thermocal.models.terms`: T, Ṫ and T·Ṫ."""

PyRow = tuple[
    int, float, float, float, tuple[tuple[int, float, tuple[float, ...]], ...], tuple[Any, ...]
]
"""Stream form of one sensor: (column, c_T, c_R, c_W, ((kind, c_P, (c_{P−1}, …, c_1)), …),
((coefficient, factor kinds), …)); kinds 0/1/2 = u/v/w."""


@dataclass(frozen=True)
class EvalPlan:
    """A fitted polynomial arranged for fast evaluation (module docstring, steps 3–4).

    With the centred variables ``d_u = T − c_T``, ``d_v = Ṫ − c_R``, ``d_w = T·Ṫ − c_W``
    of each used sensor (T, Ṫ clamped) and the scale factors folded into the
    coefficients (``coef / s^p``), the pure powers of one variable are summed by
    Horner's rule,

        p(d) = ((c_P·d + c_{P−1})·d + … + c_1)·d,

    per sensor ``s_k = (p_u(d_u) + p_v(d_v)) + p_w(d_w)`` (the variables the terms use,
    in this order), then ``s_k + c·Π factors`` for each mixed term ``u^a v^b w^c``
    (two or more variables; factors multiplied left to right: u…, v…, w…), and
    ``y = ((constant + s_1) + s_2) + …`` over the sensors in column order.  The same
    operations in the same order run on numpy blocks in :meth:`PolyModel.predict` and
    on Python floats in :class:`PolyStream`, so both give the same numbers (a
    zero-padded Horner row only adds and multiplies exact zeros).

    ``sensors``: the used columns (rows of the block arrays); ``kinds``: the variables
    formed (``"u"``, ``"v"``, ``"w"``), stacked kind by kind in the block arrays;
    ``horner``: (len(kinds)·len(sensors), 1) coefficient columns ``c_1 … c_P``
    (zero-padded to the highest power; empty without pure-power terms);
    ``centres[kind]``: (len(sensors), 1) — 0 for Ṫ and T·Ṫ when :func:`build_plan`
    folded them into the coefficients (``centred[kind]`` False: no subtraction);
    ``mixed``: (row, coefficient, factor kinds); ``rate_sensors``: the columns whose Ṫ
    a term uses; ``py_rows``: the stream form.
    """

    constant: float
    sensors: tuple[int, ...]
    kinds: tuple[str, ...]
    horner: list[FloatArray]
    centres: dict[str, FloatArray]
    centred: dict[str, bool]
    mixed: tuple[tuple[int, float, tuple[str, ...]], ...]
    rate_sensors: tuple[int, ...]
    py_rows: tuple[PyRow, ...]


def build_plan(
    terms: Sequence[Term], scaling: BaseScaling, coef: FloatArray, constant: float
) -> EvalPlan:
    """Arrange fitted terms for evaluation (:class:`EvalPlan`): the coefficient of a pure
    power ``u^p`` becomes ``coef / s_T^p`` (Horner in ``d_u``), likewise for v and w; a
    mixed term ``u^a v^b w^c`` gets ``coef / (s_T^a s_R^b s_W^c)``.  When no mixed term
    uses it and every sensor's ``|c| ≤ s``, the centre of Ṫ (of T·Ṫ) is folded in by the
    binomial re-expansion ``Σ_p a_p (x − c)^p = Σ_j b_j x^j`` (the ``b_0`` join the
    constant), which saves a pass and loses no accuracy."""
    sensors = tuple(sorted({t.sensor for t in terms}))
    row_of = {s: i for i, s in enumerate(sensors)}
    centre_of = {
        "u": scaling.t_center,
        "v": scaling.rate_center,
        "w": scaling.coupling_center,
    }
    scale_of = {"u": scaling.t_scale, "v": scaling.rate_scale, "w": scaling.coupling_scale}
    pure: dict[tuple[str, int, int], float] = {}  # (kind, row, power) -> coefficient
    mixed: list[tuple[int, float, tuple[str, ...]]] = []
    for term, c in zip(terms, coef, strict=True):
        powers = {"u": term.t_power, "v": term.rate_power, "w": term.coupling_power}
        used = [k for k in KINDS if powers[k]]
        j = term.sensor
        if len(used) == 1:
            kind = used[0]
            p = powers[kind]
            key = (kind, row_of[j], p)
            pure[key] = pure.get(key, 0.0) + float(c) / float(scale_of[kind][j]) ** p
        else:
            div = 1.0
            for kind in used:
                div *= float(scale_of[kind][j]) ** powers[kind]
            factors = tuple(k for k in KINDS for _ in range(powers[k]))
            mixed.append((row_of[j], float(c) / div, factors))
    kinds = tuple(
        k for k in KINDS if any(key[0] == k for key in pure) or any(k in m[2] for m in mixed)
    )
    nr = len(sensors)
    # Ṫ and T·Ṫ: re-expand about 0 when every centre is within one scale of 0 (no loss
    # of accuracy; saves two passes):  Σ_p a_p (x − c)^p = Σ_j b_j x^j,
    # b_j = Σ_{p ≥ max(j,1)} a_p C(p, j) (−c)^(p−j);  the b_0 go into the constant.
    constant = float(constant)
    centre = {k: [float(centre_of[k][s]) for s in sensors] for k in KINDS}
    for kind in ("v", "w"):
        if kind not in kinds or any(kind in m[2] for m in mixed):
            continue
        if not all(abs(centre[kind][r]) <= float(scale_of[kind][s]) for r, s in enumerate(sensors)):
            continue
        for r in range(nr):
            a = {p: v for (k2, r2, p), v in pure.items() if k2 == kind and r2 == r}
            c0 = centre[kind][r]
            if a and c0 != 0.0:
                top_p = max(a)
                for j in range(top_p + 1):
                    b = 0.0
                    for p in range(max(j, 1), top_p + 1):
                        b += a.get(p, 0.0) * math.comb(p, j) * (-c0) ** (p - j)
                    if j == 0:
                        constant += b
                    else:
                        pure[(kind, r, j)] = b
            centre[kind][r] = 0.0
    top = max((key[2] for key, v in pure.items() if v != 0.0), default=0)
    mat = np.zeros((len(kinds) * nr, top))
    for (kind, r, p), v in pure.items():
        if p <= top:
            mat[kinds.index(kind) * nr + r, p - 1] += v
    horner = [np.ascontiguousarray(mat[:, p : p + 1]) for p in range(top)]
    centres = {k: np.array(centre[k], dtype=np.float64).reshape(nr, 1) for k in KINDS}
    py_rows: list[PyRow] = []
    for r, s in enumerate(sensors):
        polys: list[tuple[int, float, tuple[float, ...]]] = []
        for ki, kind in enumerate(kinds):
            col = [float(v) for v in mat[ki * nr + r]]
            while col and col[-1] == 0.0:
                col.pop()
            if col:
                polys.append((KINDS.index(kind), col[-1], tuple(reversed(col[:-1]))))
        mix = tuple(
            (cf, tuple(KINDS.index(f) for f in factors)) for row, cf, factors in mixed if row == r
        )
        py_rows.append((s, centre["u"][r], centre["v"][r], centre["w"][r], tuple(polys), mix))
    return EvalPlan(
        constant=constant,
        sensors=sensors,
        kinds=kinds,
        horner=horner,
        centres=centres,
        centred={k: bool(np.any(centres[k] != 0.0)) for k in KINDS},
        mixed=tuple(mixed),
        rate_sensors=tuple(sorted({t.sensor for t in terms if t.uses_rate})),
        py_rows=tuple(py_rows),
    )


@dataclass
class _Seen:
    """Ranges met while evaluating, for the warnings: per block the minima and maxima of
    the raw T (every column) and Ṫ (rows of the used sensors), and the number of samples
    with a temperature outside the fitted range."""

    t_mins: list[FloatArray] = field(default_factory=list)
    t_maxs: list[FloatArray] = field(default_factory=list)
    r_mins: list[FloatArray] = field(default_factory=list)
    r_maxs: list[FloatArray] = field(default_factory=list)
    n_outside: int = 0

    @staticmethod
    def _reduce(parts: list[FloatArray], n: int, fn: Any, fill: float) -> FloatArray:
        out: FloatArray = fn(np.vstack(parts), axis=0) if parts else np.full(n, fill)
        return out

    def temperature(self, k: int) -> tuple[FloatArray, FloatArray]:
        """(minima, maxima) of every column [°C]."""
        return (
            self._reduce(self.t_mins, k, np.min, np.inf),
            self._reduce(self.t_maxs, k, np.max, -np.inf),
        )

    def rate(self, nr: int) -> tuple[FloatArray, FloatArray]:
        """(minima, maxima) of Ṫ of every used sensor [°C/min] (rows of the plan)."""
        return (
            self._reduce(self.r_mins, nr, np.min, np.inf),
            self._reduce(self.r_maxs, nr, np.max, -np.inf),
        )


class _BlockEvaluator:
    """Evaluates an :class:`EvalPlan` on blocks of a run (numpy, cache-sized, buffers reused)."""

    def __init__(
        self,
        model: PolyModel,
        plan: EvalPlan,
        run: RunData,
        *,
        extrapolate: bool,
        rates: FloatArray | None = None,
        plans: Sequence[EvalPlan] | None = None,
    ) -> None:
        self.plan = plan
        self.plans = list(plans) if plans else [plan]
        """The plans evaluated: one, or several of one structure (:func:`predict_many`)."""
        self.rates = rates
        self.t = run.time_s
        self.temps = run.temps_c
        self.k = int(run.temps_c.shape[1])
        self.extrapolate = extrapolate
        self.interval_s = float(model.rate_interval_s)
        self.t_lo = np.ascontiguousarray(model.temp_range_[:, :1])
        self.t_hi = np.ascontiguousarray(model.temp_range_[:, 1:2])
        self.t_lo1 = self.t_lo[:, 0].copy()
        self.t_hi1 = self.t_hi[:, 0].copy()
        self.increasing = False
        rows = np.array(plan.sensors, dtype=np.intp)
        self.rows = rows
        self.all_rows = plan.sensors == tuple(range(self.k))
        rr = model.rate_range_
        self.clip_rates = rr is not None and not extrapolate and bool(plan.rate_sensors)
        self.r_lo = np.ascontiguousarray(rr[rows, :1]) if rr is not None else None
        self.r_hi = np.ascontiguousarray(rr[rows, 1:2]) if rr is not None else None
        self.r_lo1 = self.r_lo[:, 0].copy() if self.r_lo is not None else None
        self.r_hi1 = self.r_hi[:, 0].copy() if self.r_hi is not None else None

    def blocks(self, rows: int | None = None) -> list[tuple[int, int, int]]:
        """(segment start, block start, block stop): blocks of ≤ ``rows`` (default
        :data:`PREDICT_BLOCK_ROWS`) inside gap-free segments; the start of a segment
        (Ṫ over less than Δt) is a block of its own."""
        rows = PREDICT_BLOCK_ROWS if rows is None else int(rows)
        out: list[tuple[int, int, int]] = []
        t = self.t
        steps = step_range(t)
        self.increasing = steps[0] > 0
        for sl in gap_free_slices(t, steps=steps):
            s0, s1 = int(sl.start), int(sl.stop)
            a = s0
            if self.plan.rate_sensors and self.rates is None:
                head = s0 + int(
                    np.searchsorted(t[s0:s1], float(t[s0]) + self.interval_s, side="right")
                )
                head = min(s1, head + 1)
                while a < head:
                    out.append((s0, a, min(head, a + rows)))
                    a = min(head, a + rows)
            for b0 in range(a, s1, rows):
                out.append((s0, b0, min(s1, b0 + rows)))
        return out

    def run_blocks(
        self, blocks: Sequence[tuple[int, int, int]], out: FloatArray | Sequence[FloatArray]
    ) -> _Seen:
        """Evaluate ``blocks`` into ``out`` (one array per plan); returns the ranges seen."""
        outs = [out] if isinstance(out, np.ndarray) else list(out)
        seen = _Seen()
        if not blocks:
            return seen
        width = max(b - a for _s0, a, b in blocks)
        nr = len(self.plan.sensors)
        nd = len(self.plan.kinds) * nr
        buf = {
            "raw": np.empty((self.k, 2 * width)),
            "prev": np.empty((self.k, width)),
            "clip": np.empty((self.k, width)),
            "rate": np.empty((nr, width)),
            "d": np.empty((nd, width)),
            "acc": np.empty((max(nd, nr), width)),
            "tmp": np.empty(width),
            "span": np.empty(width),
        }
        if len(self.plans) > 1:
            buf["dwork"] = np.empty((nd, width))
        for s0, a, b in blocks:
            self._block(s0, a, b, [o[a:b] for o in outs], seen, buf)
        return seen

    def _block(
        self,
        s0: int,
        a: int,
        b: int,
        outs: list[FloatArray],
        seen: _Seen,
        buf: dict[str, FloatArray],
    ) -> None:
        plan, t, temps = self.plan, self.t, self.temps
        c = b - a
        width = buf["prev"].shape[1]
        part: int | npt.NDArray[np.intp] | None = None
        if plan.rate_sensors and self.rates is None:
            part = backward_partners(t, s0, a, b, self.interval_s, increasing=self.increasing)
        prev: FloatArray | None = None
        if isinstance(part, int) and part <= width:
            raw = buf["raw"][:, : part + c]
            np.copyto(raw, temps[a - part : b].T)
            cur = raw[:, part:]
            prev = raw[:, :c]
        else:
            cur = buf["raw"][:, :c]
            np.copyto(cur, temps[a:b].T)
            if isinstance(part, int):
                prev = buf["prev"][:, :c]
                np.copyto(prev, temps[a - part : b - part].T)
        # step 2: the temperature range (every column, raw values)
        mins = cur.min(axis=1)
        maxs = cur.max(axis=1)
        seen.t_mins.append(mins)
        seen.t_maxs.append(maxs)
        tc = cur
        if bool(np.any(mins < self.t_lo1)) or bool(np.any(maxs > self.t_hi1)):
            outside = np.any((cur < self.t_lo) | (cur > self.t_hi), axis=0)
            seen.n_outside += int(np.count_nonzero(outside))
            if not self.extrapolate:
                tc = buf["clip"][:, :c]
                np.clip(cur, self.t_lo, self.t_hi, out=tc)
        nr = len(plan.sensors)
        if nr == 0:
            for o, pl in zip(outs, self.plans, strict=True):
                o.fill(pl.constant)
            return
        if self.all_rows:
            ta, cura, preva = tc, cur, prev
        else:
            ta, cura = tc[self.rows], cur[self.rows]
            preva = prev[self.rows] if prev is not None else None
        # step 1: Ṫ from the raw temperatures, (T_i − T_lo)/(t_i − t_lo)·60
        dall = buf["d"][:, :c]
        if "v" in plan.kinds and not plan.centred["v"]:  # d_v = Ṫ: computed in place
            vi = plan.kinds.index("v")
            ra = dall[vi * nr : (vi + 1) * nr]
        else:
            ra = buf["rate"][:, :c]
        if plan.rate_sensors:
            if self.rates is not None:  # forward / centred forms, computed beforehand
                np.copyto(ra, self.rates[a:b, self.rows].T)
            elif preva is not None:
                assert isinstance(part, int)
                span = np.subtract(t[a:b], t[a - part : b - part], out=buf["span"][:c])
                np.subtract(cura, preva, out=ra)
                np.divide(ra, span, out=ra)
                np.multiply(ra, SECONDS_PER_MINUTE, out=ra)
            else:
                lo = cast(npt.NDArray[np.intp], part)
                span = t[a:b] - t[lo]
                ok = span > 0
                ra.fill(0.0)
                if ok.any():
                    partner = temps[lo[ok]][:, self.rows].T
                    ra[:, ok] = (cura[:, ok] - partner) / span[ok] * SECONDS_PER_MINUTE
            rmin = ra.min(axis=1)
            rmax = ra.max(axis=1)
            seen.r_mins.append(rmin)
            seen.r_maxs.append(rmax)
            if self.clip_rates and (
                bool(np.any(rmin < self.r_lo1)) or bool(np.any(rmax > self.r_hi1))
            ):
                np.clip(ra, self.r_lo, self.r_hi, out=ra)
        # step 3: centred variables, stacked kind by kind
        d: dict[str, FloatArray] = {}
        for i, kind in enumerate(plan.kinds):
            dk = dall[i * nr : (i + 1) * nr]
            if kind == "u":
                np.subtract(ta, plan.centres["u"], out=dk)
            elif kind == "v":
                if plan.centred["v"]:
                    np.subtract(ra, plan.centres["v"], out=dk)
            else:
                np.multiply(ta, ra, out=dk)
                if plan.centred["w"]:
                    np.subtract(dk, plan.centres["w"], out=dk)
            d[kind] = dk
        # step 4, per plan: on the centred variables themselves (one plan), or on a copy
        # of them for each plan (several plans of one structure: the same operations)
        if len(self.plans) == 1:
            self._horner(plan, dall, d, nr, c, buf, outs[0])
            return
        work = buf["dwork"][:, :c]
        for o, pl in zip(outs, self.plans, strict=True):
            np.copyto(work, dall)
            dw = {kind: work[i * nr : (i + 1) * nr] for i, kind in enumerate(plan.kinds)}
            self._horner(pl, work, dw, nr, c, buf, o)

    @staticmethod
    def _horner(
        plan: EvalPlan,
        dall: FloatArray,
        d: dict[str, FloatArray],
        nr: int,
        c: int,
        buf: dict[str, FloatArray],
        o: FloatArray,
    ) -> None:
        """Step 4 of one plan: Horner on all variables at once (``dall`` is overwritten),
        sums per sensor, then over the sensors, into ``o``."""
        if plan.horner and not plan.mixed:
            acc = buf["acc"][:nr, :c]
            for i in range(len(plan.kinds)):
                dk = dall[i * nr : (i + 1) * nr]
                hk = [h[i * nr : (i + 1) * nr] for h in plan.horner]
                if len(hk) == 1:
                    np.multiply(dk, hk[0], out=dk)
                    continue
                np.multiply(dk, hk[-1], out=acc)
                for cp in hk[-2:0:-1]:
                    np.add(acc, cp, out=acc)
                    np.multiply(acc, dk, out=acc)
                np.add(acc, hk[0], out=acc)
                np.multiply(acc, dk, out=dk)  # p(d) replaces d (no mixed terms need it)
            s = dall[:nr]
            for i in range(1, len(plan.kinds)):
                np.add(s, dall[i * nr : (i + 1) * nr], out=s)
        elif plan.horner:
            acc = buf["acc"][:, :c]
            s = acc[:nr]
            np.multiply(dall, plan.horner[-1], out=acc)
            for cp in plan.horner[-2::-1]:
                np.add(acc, cp, out=acc)
                np.multiply(acc, dall, out=acc)
            for i in range(1, len(plan.kinds)):
                np.add(s, acc[i * nr : (i + 1) * nr], out=s)
        else:
            s = buf["acc"][:nr, :c]
            s.fill(0.0)
        if plan.mixed:
            tmp = buf["tmp"][:c]
            for row, cf, factors in plan.mixed:
                np.multiply(d[factors[0]][row], cf, out=tmp)
                for f in factors[1:]:
                    np.multiply(tmp, d[f][row], out=tmp)
                np.add(s[row], tmp, out=s[row])
        np.add(s[0], plan.constant, out=o)
        for r in range(1, nr):
            np.add(o, s[r], out=o)


def warn_temperature_range(
    seen_min: FloatArray,
    seen_max: FloatArray,
    temp_range: FloatArray,
    names: Sequence[str],
    n_outside: int,
    *,
    extrapolate: bool,
) -> None:
    """The :class:`ExtrapolationWarning` of :meth:`TemperatureModel.clamp` (same text)
    from the ranges met: ``n`` samples outside, per column seen and fitted range."""
    lo, hi = temp_range[:, 0], temp_range[:, 1]
    bad = [i for i in range(lo.size) if seen_min[i] < lo[i] or seen_max[i] > hi[i]]
    if not bad:
        return
    where = ", ".join(
        f"{names[i]} {seen_min[i]:.2f}…{seen_max[i]:.2f} °C (fitted {lo[i]:.2f}…{hi[i]:.2f})"
        for i in bad
    )
    action = "extrapolating" if extrapolate else "clamped to the fitted range"
    warnings.warn(
        f"{n_outside} samples outside the model's temperature range: {where}; {action}",
        ExtrapolationWarning,
        stacklevel=3,
    )


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
    per_run_offset : one turn-on offset per run, estimated as nuisance parameters; None
        (default) when the runs overlap in temperature (:func:`decide_run_offsets`).
    solver : ``"auto"`` (Gram when well conditioned, else chunked QR), ``"qr"``, ``"gram"``.
    noise_threshold : a component below ``rcond`` is kept when ``|uᵢᵀz| > k σ̂`` (None: never).
    """

    family: ClassVar[str] = "poly"
    C_GENERATOR: ClassVar[str | None] = "thermocal.export_c.poly"
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
        per_run_offset: bool | None = None,
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
    CLI_KEYS: ClassVar[Mapping[str, str] | None] = {
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

    def chunk_context(self) -> ChunkContext:
        """Eq. (1) needs the last Δt seconds (the Ṫ interval) and nothing of the start."""
        return ChunkContext(head_s=0.0, tail_s=float(self.rate_interval_s))

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
        input arrays plus a few MB.  :func:`fit_shared` fits several channels at once.
        """
        fit_shared([self], [runs])
        return self

    def _params_key(self) -> tuple[Any, ...]:
        t = self.terms if not isinstance(self.terms, list) else tuple(self.terms)
        return (t, self.order, float(self.rate_interval_s), self.rate_method, self.select,
                float(self.ridge), self.rcond, self.per_run_offset, self.solver,
                self.noise_threshold)  # fmt: skip

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

    def _rate_sensors(self) -> list[int]:
        return sorted({t.sensor for t in self.terms_ if t.uses_rate})

    def _plan(self) -> EvalPlan:
        """The :class:`EvalPlan` of the fitted values (cached; rebuilt when they change)."""
        sc = self.scaling_
        key = (
            tuple(self.terms_),
            self.coef_.tobytes(),
            float(self.constant_),
            b"".join(
                np.asarray(x, dtype=np.float64).tobytes()
                for x in (
                    sc.t_center,
                    sc.t_scale,
                    sc.rate_center,
                    sc.rate_scale,
                    sc.coupling_center,
                    sc.coupling_scale,
                )
            ),
        )
        cached = self.__dict__.get("_plan_cache")
        if cached is not None and cached[0] == key:
            return cast(EvalPlan, cached[1])
        plan = build_plan(self.terms_, sc, self.coef_, self.constant_)
        self.__dict__["_plan_cache"] = (key, plan)
        return plan

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """Temperature-induced signal of every sample [signal unit] (module docstring steps 1–4).

        Evaluated in blocks of :data:`PREDICT_BLOCK_ROWS` rows (Ṫ partners found per
        block by :func:`~thermocal.models.terms.backward_partners`; Horner's rule per
        sensor, :class:`EvalPlan`); the same numbers as :class:`PolyStream`.
        """
        self.check_fitted()
        self._check_temps(run)
        plan = self._plan()
        k = int(run.temps_c.shape[1])
        rates: FloatArray | None = None
        if plan.rate_sensors and self.rate_method != "backward":
            rates = temperature_rates(
                run.time_s, run.temps_c, float(self.rate_interval_s), self.rate_method
            )
        ev = _BlockEvaluator(self, plan, run, extrapolate=extrapolate, rates=rates)
        out = np.empty(run.n_samples)
        seen = ev.run_blocks(ev.blocks(), out)
        t_min, t_max = seen.temperature(k)
        warn_temperature_range(
            t_min,
            t_max,
            self.temp_range_,
            self.temp_names_,
            seen.n_outside,
            extrapolate=extrapolate,
        )
        if plan.rate_sensors and self.rate_range_ is not None:
            r_min = np.full(k, np.inf)
            r_max = np.full(k, -np.inf)
            rows = list(plan.sensors)
            r_min[rows], r_max[rows] = seen.rate(len(rows))
            warn_rate_range(
                r_min,
                r_max,
                self.rate_range_,
                self.temp_names_,
                list(plan.rate_sensors),
                extrapolate=extrapolate,
            )
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

    def coefficients_about(self, tref_c: float) -> list[Coefficient]:
        """Raw-monomial coefficients about a reference temperature: the same model written
        in ``dT_k = T_k − TREF`` (the convention of PX4's and ArduPilot's thermal
        calibrations, INTERFACE.md "export-params"), with standard errors.

        Each monomial ``T_k^P Ṫ_k^Q = ((T_k − TREF) + TREF)^P Ṫ_k^Q`` expands binomially
        into ``Σ_j C(P, j) TREF^(P−j) dT_k^j Ṫ_k^Q``; with ``S`` that linear map,
        ``b = S a`` and ``cov b = S cov a Sᵀ``.  Names use ``dT1`` for ``T1 − TREF``…
        (rates keep ``Ṫ``, written ``rate1``).  Only the constant and the
        polynomial terms change; the model's values do not.
        """
        self.check_fitted()
        if not math.isfinite(tref_c):
            raise ThermocalInputError(f"TREF must be a finite temperature, got {tref_c}")
        keys, M = raw_expansion(self.terms_, self.scaling_)
        beta = np.r_[self.constant_, self.coef_]
        raw = M @ beta
        cov_raw = M @ self.cov_ @ M.T
        out_keys: list[tuple[int, int, int]] = [(-1, 0, 0)]
        index = {(-1, 0, 0): 0}
        entries: list[tuple[int, int, float]] = []  # (row in b, column in a, weight)
        for col, (k, P, Q) in enumerate(keys):
            if k < 0:
                entries.append((0, col, 1.0))
                continue
            for j in range(P + 1):
                new = (k, j, Q) if (j or Q) else (-1, 0, 0)
                if new not in index:
                    index[new] = len(out_keys)
                    out_keys.append(new)
                entries.append((index[new], col, math.comb(P, j) * tref_c ** (P - j)))
        S = np.zeros((len(out_keys), len(keys)))
        for row, col, w in entries:
            S[row, col] += w
        b = S @ raw
        se = np.sqrt(np.clip(np.diag(S @ cov_raw @ S.T), 0.0, None))
        out: list[Coefficient] = []
        for key, v, e in zip(out_keys, b, se, strict=True):
            k, P, Q = key
            unit = self.signal_unit
            if P:
                unit += "/degC" + (f"^{P}" if P > 1 else "")
            if Q:
                unit += "/(degC/min)" + (f"^{Q}" if Q > 1 else "")
            name = "const"
            if k >= 0:
                parts = []
                if P:
                    parts.append(f"(T{k + 1}-TREF)" + (f"^{P}" if P > 1 else ""))
                if Q:
                    parts.append(f"rate{k + 1}" + (f"^{Q}" if Q > 1 else ""))
                name = "*".join(parts)
            out.append(Coefficient(name, float(v), float(e) if math.isfinite(e) else None, unit))
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


def evaluation_key(model: PolyModel) -> tuple[Any, ...]:
    """What decides how a fitted model's inputs are turned into its centred variables
    (steps 1–3 of the module docstring) and the shape of step 4: models with equal keys
    (channels fitted together by :func:`fit_shared`, unless term selection differs) can
    be evaluated together by :func:`predict_many`."""
    model.check_fitted()
    plan = model._plan()
    rr = model.rate_range_
    return (
        tuple(model.temp_names_),
        float(model.rate_interval_s),
        model.rate_method,
        np.asarray(model.temp_range_).tobytes(),
        None if rr is None else np.asarray(rr).tobytes(),
        plan.sensors,
        plan.kinds,
        plan.rate_sensors,
        tuple(sorted(plan.centred.items())),
        tuple((k, np.asarray(v).tobytes()) for k, v in sorted(plan.centres.items())),
        tuple((row, factors) for row, _c, factors in plan.mixed),
        len(plan.horner),
    )


def predict_many(
    models: Sequence[PolyModel], run: RunData, *, extrapolate: bool = False
) -> list[FloatArray]:
    """:meth:`PolyModel.predict` of several models on one run: the clamped temperatures,
    Ṫ and centred variables once, then each model's polynomial (step 4) on a copy of
    them — the same operations as each model alone, so each result equals its own
    :meth:`~PolyModel.predict` bit for bit.  Models whose :func:`evaluation_key` differs
    are evaluated one by one.  Range warnings are issued once (the ranges are shared)."""
    if not models:
        return []
    head = models[0]
    key = evaluation_key(head)
    if len(models) == 1 or any(evaluation_key(m) != key for m in models[1:]):
        return [m.predict(run, extrapolate=extrapolate) for m in models]
    head._check_temps(run)
    plan = head._plan()
    rates: FloatArray | None = None
    if plan.rate_sensors and head.rate_method != "backward":
        rates = temperature_rates(
            run.time_s, run.temps_c, float(head.rate_interval_s), head.rate_method
        )
    ev = _BlockEvaluator(
        head, plan, run, extrapolate=extrapolate, rates=rates, plans=[m._plan() for m in models]
    )
    outs = [np.empty(run.n_samples) for _ in models]
    seen = ev.run_blocks(ev.blocks(), outs)
    k = int(run.temps_c.shape[1])
    t_min, t_max = seen.temperature(k)
    warn_temperature_range(
        t_min, t_max, head.temp_range_, head.temp_names_, seen.n_outside, extrapolate=extrapolate
    )
    if plan.rate_sensors and head.rate_range_ is not None:
        r_min = np.full(k, np.inf)
        r_max = np.full(k, -np.inf)
        rows = list(plan.sensors)
        r_min[rows], r_max[rows] = seen.rate(len(rows))
        warn_rate_range(
            r_min, r_max, head.rate_range_, head.temp_names_, list(plan.rate_sensors),
            extrapolate=extrapolate,
        )  # fmt: skip
    return outs


def _same_inputs(a: RunData, b: RunData) -> bool:
    """The two runs have the same times and temperatures (the same arrays, or equal)."""

    def same(x: FloatArray, y: FloatArray) -> bool:
        return x is y or (x.shape == y.shape and bool(np.array_equal(x, y)))

    return same(a.time_s, b.time_s) and same(a.temps_c, b.temps_c)


def fit_shared(models: Sequence[PolyModel], runs_by_model: Sequence[Sequence[RunData]]) -> None:
    """Fit several channels that share one design (issue 15): the same parameters and the
    same runs' times and temperatures, each with its own signal and known input.

    The work that depends on the temperatures alone — Ṫ, the base-variable scaling, the
    features, the offset decision, the ranges — is done once and the design's Gram matrix
    is accumulated once; only the targets' products are per channel
    (:func:`~thermocal.models.terms.accumulate_targets`), so each channel's reduction is
    computed by the operations a single channel gets, bit for bit.  Term selection, the
    solution, the residuals' autocorrelation and the covariance are per channel, so every
    model equals the one :meth:`PolyModel.fit` gives on its own runs.

    Steps: check the channels share their inputs (:func:`_shared_runs`); the design
    (:func:`_shared_design`); one pass reducing it (:class:`_DesignPass`,
    :func:`~thermocal.models.terms.accumulate_targets`); per channel the selection and
    solution (:func:`_solve_channel`); a second pass for the residuals; per channel the
    covariance and statistics (:func:`_finish_channel`).
    """
    head, rls = _shared_runs(models, runs_by_model)
    design = _shared_design(head, rls[0])
    dp = _DesignPass(design, rls)
    reds = accumulate_targets(
        dp.chunks, design.p, design.m, len(models), n_folds=design.n_folds,
        solver=cast(Any, head.solver),
    )  # fmt: skip
    solved = [_solve_channel(mdl, red, design) for mdl, red in zip(models, reds, strict=True)]
    residuals = dp.residuals(solved)
    for j, mdl in enumerate(models):
        _finish_channel(mdl, design, dp, j, solved[j], residuals[j], reds[j].solver, rls[j])


def _shared_runs(
    models: Sequence[PolyModel], runs_by_model: Sequence[Sequence[RunData]]
) -> tuple[PolyModel, list[list[RunData]]]:
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

    head: PolyModel
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


def _shared_design(head: PolyModel, rl: list[RunData]) -> _Design:
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


def _warn_short_rates(head: PolyModel, rl: list[RunData], n_total: int) -> None:
    shares = [short_rate_share(r.time_s, float(head.rate_interval_s), head.rate_method) for r in rl]
    n_short = sum(c for c, _ in shares)
    if n_short > SHORT_RATE_WARN_SHARE * n_total:
        warnings.warn(
            f"poly: {n_short / n_total:.0%} of the samples have a temperature rate taken "
            f"over less than half the rate interval ({head.rate_interval_s:g} s): the "
            f"record breaks into {sum(g for _, g in shares)} contiguous segment(s) at "
            "its gaps (bursts or dropouts), and a rate over a fraction of a second is "
            "temperature noise; the rate terms and the fitted rate range rest on it. "
            "Fit a plain polynomial (--order N), average the record to one block per "
            "burst, or choose --rate-interval shorter than the segments",
            ConditioningWarning,
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

    def chunks(self) -> Iterator[Chunk]:
        d, nt, p = self.d, len(self.rls), self.d.p
        bufs: dict[int, FloatArray] = {}
        self.sums[:] = 0.0
        for i, (r, plan) in enumerate(zip(d.runs, d.plans, strict=True)):
            self.current_run = i
            g = i if d.decision.used else 0
            sigs = [cast(FloatArray, rs[i].signal) for rs in self.rls]
            known = [rs[i].known_input for rs in self.rls]
            for s0, s1, a, b, fold in plan:
                rates: FloatArray | None = None
                if d.uses_rate:
                    rates = segment_rates(
                        r.time_s[s0:s1],
                        r.temps_c[s0:s1],
                        np.arange(a - s0, b - s0),
                        float(d.head.rate_interval_s),
                        d.head.rate_method,
                    )
                    np.minimum(self.rate_lo[i], rates.min(axis=0), out=self.rate_lo[i])
                    np.maximum(self.rate_hi[i], rates.max(axis=0), out=self.rate_hi[i])
                c = b - a
                if c not in bufs:
                    bufs[c] = np.empty((c, p + 1 + nt), order="F")
                    bufs[c][:, p] = 1.0
                A = bufs[c]
                Tf = np.asfortranarray(r.temps_c[a:b])  # contiguous columns
                np.minimum(self.temp_lo[i], Tf.min(axis=0), out=self.temp_lo[i])
                np.maximum(self.temp_hi[i], Tf.max(axis=0), out=self.temp_hi[i])
                term_features(d.terms, d.scaling, Tf, rates, out=A[:, :p])
                for j in range(nt):
                    y = np.subtract(sigs[j][a:b], known[j], out=A[:, p + 1 + j])
                    dev = y - self.y0[j]
                    self.sums[j, 0] += c
                    self.sums[j, 1] += float(np.sum(dev))
                    self.sums[j, 2] += float(dev @ dev)
                yield A, g, fold

    def residuals(self, solved: Sequence[_Solved]) -> list[list[FloatArray]]:
        """Each channel's residuals per run (at most MAX_SAMPLES_PER_SERIES a run), a
        second pass over the same blocks."""
        p = self.d.p
        per_run: list[list[list[FloatArray]]] = [[[] for _ in self.d.runs] for _ in solved]
        for A, g, _fold in self.chunks():
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


def _solve_channel(mdl: PolyModel, red: Reduced, design: _Design) -> _Solved:
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
    mdl: PolyModel,
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
            f"poly: ill-conditioned design (condition number {sol.condition_number:.3g}); "
            f"{sol.n_truncated} singular value(s) truncated at rcond={mdl.rcond}; "
            "consider fewer terms, --select or --ridge",
            ConditioningWarning,
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


class PolyStream(ModelStream):
    """Sample-by-sample :class:`PolyModel` (module docstring steps 1–4), in plain Python
    floats: the same operations as :meth:`PolyModel.predict` (:class:`EvalPlan`).

    Keeps the samples of the last Δt of the current contiguous segment for the
    backward rate (a ring buffer; the partner is the oldest sample with
    ``t_j ≥ t − Δt``, as ``searchsorted`` in the batch); a step longer than
    ``GAP_FACTOR × sample_interval_s`` starts a new segment (rate restarts from 0).
    Warns once per stream (per kind: temperature, rate) when a sample leaves the
    fitted range.
    """

    def __init__(self, model: PolyModel, sample_interval_s: float, *, extrapolate: bool) -> None:
        if not sample_interval_s > 0:
            raise ThermocalInputError(f"sample interval must be positive, got {sample_interval_s}")
        plan = model._plan()
        self.model = model
        self.extrapolate = extrapolate
        self.gap_s = GAP_FACTOR * float(sample_interval_s)
        self.interval_s = float(model.rate_interval_s)
        self.uses_rate = bool(plan.rate_sensors)
        self._k = int(model.temp_range_.shape[0])
        self._t_lo: list[float] = [float(v) for v in model.temp_range_[:, 0]]
        self._t_hi: list[float] = [float(v) for v in model.temp_range_[:, 1]]
        self._t_bounds = list(zip(range(self._k), self._t_lo, self._t_hi, strict=True))
        rr = model.rate_range_
        # (column, lo, hi) of every Ṫ the terms use; ±inf without a fitted rate range
        self._rate_spec: list[tuple[int, float, float]] = [
            (j, float(rr[j, 0]), float(rr[j, 1])) if rr is not None else (j, -math.inf, math.inf)
            for j in plan.rate_sensors
        ]
        self._const = plan.constant
        self._rows = plan.py_rows
        self.reset()

    def reset(self) -> None:
        self._times: deque[float] = deque()
        self._hist: deque[list[float]] = deque()
        self._last_t: float | None = None
        self._warned_t = False
        self._warned_r = False

    def _warn(self, what: str) -> None:
        action = "extrapolating" if self.extrapolate else "clamped to the fitted range"
        warnings.warn(
            f"{what} outside the model's fitted range; {action}", ExtrapolationWarning, stacklevel=3
        )

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        t = float(time_s)
        if type(temps_c) is np.ndarray and temps_c.dtype == np.float64 and temps_c.ndim == 1:
            row: list[float] = temps_c.tolist()
        else:
            row = np.asarray(temps_c, dtype=np.float64).reshape(-1).tolist()
        if len(row) != self._k:
            raise ThermocalInputError(
                f"poly model uses {self._k} temperature channels; the sample has {len(row)}"
            )
        rates = row  # placeholder, replaced when the model uses Ṫ
        if self.uses_rate:
            times, hist = self._times, self._hist
            if self._last_t is not None and t - self._last_t > self.gap_s:
                times.clear()
                hist.clear()
            self._last_t = t
            times.append(t)
            hist.append(row)
            x = t - self.interval_s
            while times[0] < x:
                times.popleft()
                hist.popleft()
            span = t - times[0]
            rates = [0.0] * self._k
            old = hist[0]
            for j, lo, hi in self._rate_spec:
                r = (row[j] - old[j]) / span * SECONDS_PER_MINUTE if span > 0 else 0.0
                if r < lo or r > hi:
                    if not self._warned_r:
                        self._warned_r = True
                        self._warn("temperature rate")
                    if not self.extrapolate:
                        r = lo if r < lo else hi
                rates[j] = r
        temps = row
        for j, lo, hi in self._t_bounds:
            v = row[j]
            if v < lo or v > hi:
                if not self._warned_t:
                    self._warned_t = True
                    self._warn("temperature")
                if not self.extrapolate:
                    if temps is row:
                        temps = list(row)
                    temps[j] = lo if v < lo else hi
        y = self._const
        for col, tc, rc, wc, polys, mixed in self._rows:
            temp = temps[col]
            s: float | None = None
            for kind, top, rest in polys:
                if kind == 0:
                    d = temp - tc
                elif kind == 1:
                    d = rates[col] - rc
                else:
                    d = temp * rates[col] - wc
                acc = d * top
                for cp in rest:
                    acc = (acc + cp) * d
                s = acc if s is None else s + acc
            if s is None:
                s = 0.0
            for cf, factors in mixed:
                ds = [temp - tc, rates[col] - rc, temp * rates[col] - wc]
                m = ds[factors[0]] * cf
                for f in factors[1:]:
                    m = m * ds[f]
                s = s + m
            y = y + s
        return y
