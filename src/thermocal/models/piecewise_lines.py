"""The piecewise model's lines ([Seed-FOG]): the initial breakpoints (given, or as many
segments as the data support, chosen by BIC), the check that every segment determines a
line, the segments' lines by chunked least squares with their covariance, and the
breakpoints moved to where adjacent lines meet (intersect method).

Pure functions on arrays; :class:`thermocal.models.piecewise.PiecewiseModel` strings them
together.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterator, Sequence

import numpy as np

from thermocal.errors import DesignError, ThermocalInputError, ThermocalWarning
from thermocal.models.breakpoints import (
    MIN_SEGMENT_BINS,
    MIN_SEGMENT_SAMPLES,
    MIN_SEGMENT_WIDTH_FRACTION,
    BreakpointChoice,
    _Lines,
    choose_breakpoints,
    segment_index,
)
from thermocal.models.lstsq import solve_r
from thermocal.models.reduction import Chunk, accumulate_r
from thermocal.models.rundata import RunData
from thermocal.models.terms import CHUNK_ROWS
from thermocal.recording import FloatArray


def initial_breakpoints(
    xs: list[FloatArray],
    ys: list[FloatArray],
    use_offsets: bool,
    lo: float,
    hi: float,
    *,
    breakpoints: Sequence[float] | None,
    segments: int | None,
) -> tuple[list[float], BreakpointChoice | None]:
    """The breakpoints given (checked inside the data's range), or the number of segments
    the data support, chosen by BIC (:func:`~thermocal.models.breakpoints.choose_breakpoints`;
    a warning when fewer than asked).

    Parameters
    ----------
    xs, ys : list of numpy.ndarray
        Temperature [°C] and target [signal unit] of each run.
    use_offsets : bool
        Per-run offsets in the fit.
    lo, hi : float
        The data's temperature range [°C].
    breakpoints : sequence of float or None
        Breakpoints given [°C].
    segments : int or None
        Segments asked for when no breakpoints are given (default 3).

    Returns
    -------
    tuple
        The breakpoints [°C] and the choice (None when given).

    Raises
    ------
    thermocal.errors.DesignError
        A breakpoint outside the data's range.
    thermocal.errors.ThermocalInputError
        Breakpoints that are not distinct.

    Warns
    -----
    thermocal.errors.ThermocalWarning
        Fewer segments fitted than asked for.
    """
    choice: BreakpointChoice | None = None
    if breakpoints is not None:
        bps = sorted(float(b) for b in breakpoints)
        for b in bps:
            if not lo < b < hi:
                raise DesignError(
                    f"breakpoint {b:g} °C is outside the data's temperature range "
                    f"{lo:.2f}…{hi:.2f} °C"
                )
        if len(set(bps)) != len(bps):
            raise ThermocalInputError("breakpoints must be distinct")
    else:
        n_seg = 3 if segments is None else int(segments)
        choice = choose_breakpoints(xs, ys, n_seg, per_run_offset=use_offsets)
        bps = choice.breakpoints_c
        if choice.reduced:
            reasons = []
            if choice.supported < n_seg:
                reasons.append(
                    f"segments of ≥ {MIN_SEGMENT_WIDTH_FRACTION:.0%} of the "
                    f"{lo:.4g}…{hi:.4g} °C range with ≥ {MIN_SEGMENT_SAMPLES} samples over "
                    f"≥ {MIN_SEGMENT_BINS} distinct temperatures allow at most "
                    f"{choice.supported}"
                )
            if choice.chosen < choice.supported:
                reasons.append("more breakpoints do not lower the BIC")
            what = (
                "the data are a line" if choice.chosen == 1 else f"the data support {choice.chosen}"
            )
            warnings.warn(
                f"piecewise: {n_seg} segments asked for, {choice.chosen} fitted: {what} ("
                + "; ".join(reasons)
                + "; BIC by number of segments: "
                + ", ".join(f"{k}: {v:.1f}" for k, v in enumerate(choice.bic, start=1))
                + ")",
                ThermocalWarning,
                stacklevel=2,
            )
    return list(bps), choice


def check_segments(bp: FloatArray, xs: list[FloatArray], lo: float, hi: float) -> None:
    """Every segment holds at least two distinct temperatures (a line is determined).

    Parameters
    ----------
    bp : numpy.ndarray
        Breakpoints [°C].
    xs : list of numpy.ndarray
        Temperatures of each run [°C].
    lo, hi : float
        The data's temperature range [°C].

    Raises
    ------
    thermocal.errors.DesignError
        A segment with fewer than two samples or no temperature span.
    """
    S = bp.size + 1
    seg_edges = [lo, *bp.tolist(), hi]
    labels = [f"{seg_edges[s]:.4g}–{seg_edges[s + 1]:.4g} °C" for s in range(S)]
    counts = np.zeros(S, dtype=np.int64)
    for x in xs:
        counts += np.bincount(segment_index(bp, x), minlength=S)
    spans = np.zeros(S)
    for x in xs:
        seg = segment_index(bp, x)
        for s_ in range(S):
            xs_ = x[seg == s_]
            if xs_.size:
                spans[s_] = max(spans[s_], float(np.ptp(xs_)))
    for s in range(S):
        if counts[s] < 2 or not spans[s] > 1e-9 * max(1.0, abs(hi)):
            raise DesignError(
                f"segment {labels[s]} has {int(counts[s])} sample(s) over "
                f"{spans[s]:.3g} °C; a line needs at least 2 distinct temperatures "
                "(move or drop a breakpoint)"
            )


def solve_lines(
    xs: list[FloatArray],
    ys: list[FloatArray],
    bp: FloatArray,
    rl: list[RunData],
    use_offsets: bool,
    lo: float,
    hi: float,
    method: str,
) -> _Lines:
    """The segments' lines ``y = a_s + k_s T`` by chunked least squares (Householder QR),
    with their covariance.

    Parameters
    ----------
    xs, ys : list of numpy.ndarray
        Temperature [°C] and target [signal unit] of each run.
    bp : numpy.ndarray
        Breakpoints [°C].
    rl : list of RunData
        The runs (names of the offsets).
    use_offsets : bool
        One offset per run (else one constant).
    lo, hi : float
        The data's temperature range [°C].
    method : {"intersect", "continuous"}
        Independent lines per segment, or one continuous line with hinges.

    Returns
    -------
    thermocal.models.breakpoints._Lines
        Intercepts [signal unit], slopes [signal unit/°C], their covariance, the offsets.

    Notes
    -----
    Continuous method, with :math:`c` the range's centre and :math:`\\sigma` its half
    width:

    .. math:: y = a + s_0 \\frac{T - c}{\\sigma}
              + \\sum_i d_i \\frac{\\max(0, T - b_i)}{\\sigma}
    """
    S = bp.size + 1
    bps = bp.tolist()
    seg_edges = [lo, *bps, hi]
    labels = [f"{seg_edges[s]:.4g}–{seg_edges[s + 1]:.4g} °C" for s in range(S)]
    m = len(rl) if use_offsets else 1
    centre = 0.5 * (lo + hi)
    scale = max(0.5 * (hi - lo), 1e-12)
    if method == "intersect":
        # features: slope of each segment, then intercept steps of segments 2..S
        p = S + (S - 1)
        names_f = [f"slope[{lab}]" for lab in labels] + [f"level[{lab}]" for lab in labels[1:]]
    else:
        p = 1 + bp.size
        names_f = ["slope"] + [f"hinge[{b:.4g}]" for b in bps]
    names_all = names_f + (
        [f"offset[{r.name or i + 1}]" for i, r in enumerate(rl)] if use_offsets else ["const"]
    )

    def features(x: FloatArray, out: FloatArray) -> None:
        u = (x - centre) / scale
        if method == "intersect":
            seg = segment_index(bp, x)
            for s in range(S):
                np.multiply(u, seg == s, out=out[:, s])
            for s in range(1, S):
                out[:, S + s - 1] = seg == s
        else:
            out[:, 0] = u
            for i, b in enumerate(bp):
                np.maximum(0.0, (x - b) / scale, out=out[:, 1 + i])

    def make_chunks() -> Iterator[Chunk]:
        bufs: dict[int, FloatArray] = {}
        for i, (x, y) in enumerate(zip(xs, ys, strict=True)):
            g = i if use_offsets else 0
            for a in range(0, x.size, CHUNK_ROWS):
                b = min(x.size, a + CHUNK_ROWS)
                c = b - a
                if c not in bufs:
                    bufs[c] = np.empty((c, p + 2), order="F")
                    bufs[c][:, p] = 1.0
                A = bufs[c]
                features(x[a:b], A[:, :p])
                A[:, p + 1] = y[a:b]
                yield A, g, 0

    red = accumulate_r(make_chunks, p, m, solver="qr")
    sol = solve_r(red.combined(), red.n_total, names_all)
    coef = sol.coef
    offsets = coef[p:]
    const = float(np.mean(offsets))
    A_int, A_slp = _line_maps(bp, p, m, centre, scale, method)
    intercepts = A_int @ coef
    slopes = A_slp @ coef
    Lmat = np.vstack([A_int, A_slp])
    line_cov = Lmat @ sol.cov @ Lmat.T
    return _Lines(intercepts, slopes, line_cov, offsets, const, sol, red.n_total, m)


def _line_maps(
    bp: FloatArray, p: int, m: int, centre: float, scale: float, method: str
) -> tuple[FloatArray, FloatArray]:
    """The lines ``y = a_s + k_s T`` as linear maps of the solution ``[coef, offsets]``:
    (intercepts' map, slopes' map), each (S, p + m)."""
    S = bp.size + 1
    q = p + m
    A_int = np.zeros((S, q))  # intercepts a_s
    A_slp = np.zeros((S, q))  # slopes k_s
    A_int[:, p:] = 1.0 / m
    if method == "intersect":
        for s in range(S):
            A_slp[s, s] = 1.0 / scale
            A_int[s, s] = -centre / scale
            if s > 0:
                A_int[s, S + s - 1] = 1.0
    else:
        # y = const + s0 (T − c)/σ + Σ_i d_i max(0, T − b_i)/σ
        for s in range(S):
            A_slp[s, 0] = 1.0 / scale
            A_int[s, 0] = -centre / scale
            for i in range(s):  # hinges active in segment s
                A_slp[s, 1 + i] = 1.0 / scale
                A_int[s, 1 + i] = -bp[i] / scale
    return A_int, A_slp


def intersections(
    bp: FloatArray, lines: _Lines, lo: float, hi: float, method: str
) -> tuple[FloatArray, list[float]]:
    """Intersect method: each breakpoint moved to where the adjacent lines meet, when that
    lies between its neighbours; the others kept (the model jumps there).

    Parameters
    ----------
    bp : numpy.ndarray
        Breakpoints [°C].
    lines : thermocal.models.breakpoints._Lines
        The segments' lines (:func:`solve_lines`).
    lo, hi : float
        The data's temperature range [°C].
    method : {"intersect", "continuous"}
        Only the intersect method moves breakpoints.

    Returns
    -------
    tuple
        The final breakpoints [°C] and the breakpoints kept where the lines do not meet.

    Notes
    -----
    .. math:: x^* = \\frac{a_{i+1} - a_i}{k_i - k_{i+1}}

    Warns
    -----
    thermocal.errors.ThermocalWarning
        Lines that do not meet between their segments.
    """
    intercepts, slopes = lines.intercepts, lines.slopes
    final = bp.copy()
    discontinuities: list[float] = []
    if method == "intersect":
        for i in range(bp.size):
            ds = slopes[i] - slopes[i + 1]
            x_star = (intercepts[i + 1] - intercepts[i]) / ds if ds != 0 else math.nan
            left = final[i - 1] if i > 0 else lo
            right = bp[i + 1] if i + 1 < bp.size else hi
            if math.isfinite(x_star) and left < x_star < right:
                final[i] = x_star
            else:
                discontinuities.append(float(bp[i]))
        if discontinuities:
            warnings.warn(
                "piecewise: adjacent lines do not intersect between their segments at "
                + ", ".join(f"{b:g} °C" for b in discontinuities)
                + "; the given breakpoint is kept and the model jumps there",
                ThermocalWarning,
                stacklevel=2,
            )
    return final, discontinuities
