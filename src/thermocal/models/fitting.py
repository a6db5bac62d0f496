"""Run checks, per-run offsets, blocks and ranges shared by the model families' fits
(:mod:`thermocal.models.poly`, :mod:`thermocal.models.piecewise`)."""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal.errors import ConditioningWarning, ExtrapolationWarning, ThermocalInputError
from thermocal.models.base import TemperatureModel
from thermocal.models.results import FitStats
from thermocal.models.rundata import RunData
from thermocal.models.terms import CHUNK_ROWS
from thermocal.recording import FloatArray, contiguous_slices

HOLDOUT_BLOCKS = 10
"""Hold-out selection splits each run into this many equal blocks; odd blocks are held out."""


def check_runs(runs: Sequence[RunData], family: str) -> list[RunData]:
    """Common input checks: at least one run, a signal, the same temperature columns.

    Parameters
    ----------
    runs : sequence of RunData
        The runs to fit.
    family : str
        The family's name, for messages.

    Returns
    -------
    list of RunData

    Raises
    ------
    thermocal.errors.ThermocalInputError
        No run, a run without signal, or runs with different temperature columns.
    """
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


def _central_range(temps_c: FloatArray, column: int) -> tuple[float, float]:
    """The 2nd and 98th percentiles of one temperature column; a column that is not a view
    (read from its file when asked for: ``temps_c`` not an array) is partitioned in place."""
    col = temps_c[:, column]
    lo, hi = np.percentile(col, [2, 98], overwrite_input=not isinstance(temps_c, np.ndarray))
    return float(lo), float(hi)


OFFSET_OVERLAP_FRACTION = 0.5
"""Two runs *overlap* when their central temperature ranges (2nd…98th percentile of the
first temperature column) share at least this fraction of the narrower range."""


@dataclass(frozen=True)
class OffsetDecision:
    """Whether per-run turn-on offsets are estimated, and why.

    A per-run offset is a free constant per run. Offsets and the temperature function are
    only separable where runs cover common temperatures: two runs at separate temperatures
    let the offsets absorb the whole difference between runs, and the slope then comes
    from the within-run variation alone (a real BMI270 pair gave 449 instead of 69
    °/h/°C). The runs form a graph (edge = overlap ≥ :data:`OFFSET_OVERLAP_FRACTION` of
    the narrower central range); offsets are separable when the graph is connected.

    Attributes
    ----------
    used : bool
        Offsets estimated.
    requested : bool or None
        The setting (None = automatic).
    connected : bool
        The overlap graph is connected.
    groups : list of list of str
        Run names per connected group.
    ranges_c : list of tuple of float
        Central range per run [°C].
    reason : str
        One line for the user.
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

    Parameters
    ----------
    ranges_c : sequence of tuple of float
        (lo, hi) per run [°C].
    fraction : float, optional
        Overlap share of the narrower range.  Default :data:`OFFSET_OVERLAP_FRACTION`.

    Returns
    -------
    list of list of int
        Run indices per connected group.

    Examples
    --------
    >>> run_overlap_groups([(20.0, 40.0), (30.0, 50.0), (60.0, 80.0)])
    [[0, 1], [2]]
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

    Parameters
    ----------
    requested : bool or None
        The setting (None: automatic).
    runs : sequence of RunData
        The runs.
    family : str
        The family's name, for messages.
    column : int, optional
        Temperature column compared.  Default 0.

    Returns
    -------
    OffsetDecision
    """
    names = [r.name or f"run {i + 1}" for i, r in enumerate(runs)]
    ranges = [_central_range(r.temps_c, column) for r in runs]
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
            ConditioningWarning.naming(
                why + "; per-run offsets kept as asked ({per_run_offset}): distrust "
                "the slope and its standard error, or record runs that share temperatures",
                "per_run_offset",
            ),
            stacklevel=3,
        )
        return OffsetDecision(True, True, False, named, ranges, why)
    warnings.warn(
        ConditioningWarning.naming(
            why + "; fitting one common offset instead (pooled). Pass "
            "{per_run_offset} to force offsets, or record runs that share temperatures",
            "per_run_offset",
        ),
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
    """:class:`ExtrapolationWarning` when Ṫ of a used sensor left the fitted rate range.

    Parameters
    ----------
    seen_lo, seen_hi : numpy.ndarray
        Ṫ range met per sensor [°C/min].
    rate_range : numpy.ndarray
        Fitted Ṫ range (k, 2) [°C/min].
    names : sequence of str
        Sensor names.
    used : sequence of int
        Sensors whose terms use Ṫ.
    extrapolate : bool
        Wording of the warning (extrapolating or clamped).
    """
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

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    n_folds : int, optional
        1 or 2.  Default 1.
    chunk : int, optional
        Most rows per block.  Default :data:`CHUNK_ROWS`.

    Returns
    -------
    list of Block
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
    fraction of a second.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    interval_s : float
        Ṫ interval Δt [s].
    method : str
        ``backward``, ``forward`` or ``centred``.

    Returns
    -------
    count : int
        Samples whose Ṫ spans less than Δt/2.
    n_segments : int
        Contiguous segments.
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

    Parameters
    ----------
    model : TemperatureModel
        The model being fitted.
    runs : sequence of RunData
        Its runs.
    stats : FitStats
        The fit statistics.
    rate_bounds : tuple of numpy.ndarray or None
        Per-run Ṫ minima and maxima [°C/min].
    temp_bounds : tuple of numpy.ndarray, optional
        Per-run T minima and maxima [°C].
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
