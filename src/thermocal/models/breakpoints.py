"""Breakpoints of a piecewise-linear model: chosen from the data (:func:`choose_breakpoints`,
a search over binned temperatures with the smallest segment a model may have), the segment
of each temperature (:func:`segment_index`), the lines' values (:func:`evaluate_lines`) and
each segment judged by the adequacy rules (:func:`segment_tests`).  The model itself is
:class:`thermocal.models.piecewise.PiecewiseModel` ([Seed-FOG]).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule
from thermocal.adequacy import AdequacyTest, samples_test, temperature_tests
from thermocal.errors import (
    DesignError,
    ThermocalInputError,
)
from thermocal.models.lstsq import LstsqSolution
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from scipy import optimize
else:
    optimize = LazyModule("scipy.optimize")

N_BINS = 400
"""Temperature bins (per run) for the breakpoint search."""

MIN_SEGMENT_SAMPLES = 5
"""Fewest samples a chosen segment may hold."""
MIN_SEGMENT_WIDTH_FRACTION = 0.05
"""A chosen segment spans at least this fraction of the data's temperature range (5 %)."""
MIN_SEGMENT_BINS = 3
"""A chosen segment holds at least this many distinct temperatures (occupied 1/N_BINS
bins of the range), so that its line is determined by more than one temperature."""


@dataclass(frozen=True)
class BreakpointChoice:
    """Outcome of :func:`choose_breakpoints`.

    ``bic[k-1]`` is the Bayesian information criterion of the best continuous fit with
    k segments (on the temperature-binned data; lower is better); ``supported`` the
    largest k whose segments can all meet the minimum width, sample and distinct-
    temperature rules; ``chosen`` the k kept.

    Attributes
    ----------
    breakpoints_c : list of float
        The chosen breakpoints [°C].
    requested : int
        Segments asked for.
    supported : int
        Most segments the rules allow.
    chosen : int
        Segments kept.
    bic : list of float
        BIC per segment count.
    """

    breakpoints_c: list[float]
    requested: int
    supported: int
    chosen: int
    bic: list[float]

    @property
    def reduced(self) -> bool:
        """True when fewer segments were kept than asked for."""
        return self.chosen < self.requested

    def to_dict(self) -> dict[str, Any]:
        """JSON form of the choice."""
        return {
            "method": "BIC of the continuous fit on temperature-binned means",
            "segments_requested": self.requested,
            "segments_supported": self.supported,
            "segments_kept": self.chosen,
            "bic": [float(v) for v in self.bic],
            "min_width_fraction": MIN_SEGMENT_WIDTH_FRACTION,
            "min_samples": MIN_SEGMENT_SAMPLES,
            "min_distinct_temperatures": MIN_SEGMENT_BINS,
        }


def segment_index(breakpoints: FloatArray, temp_c: FloatArray) -> npt.NDArray[np.intp]:
    """Segment of each temperature: the number of breakpoints ``≤ T`` (eq. 1).

    Parameters
    ----------
    breakpoints : numpy.ndarray
        Ascending breakpoints [°C].
    temp_c : numpy.ndarray
        Temperatures [°C].

    Returns
    -------
    numpy.ndarray of int
    """
    idx: npt.NDArray[np.intp] = np.searchsorted(breakpoints, temp_c, side="right")
    return idx


def evaluate_lines(
    breakpoints: FloatArray, intercepts: FloatArray, slopes: FloatArray, temp_c: FloatArray
) -> FloatArray:
    """``y = a_j + s_j T`` with j from :func:`segment_index` (eq. 1).

    Parameters
    ----------
    breakpoints : numpy.ndarray
        Ascending breakpoints (K,) [°C].
    intercepts : numpy.ndarray
        a_j per segment (K+1,) [signal unit].
    slopes : numpy.ndarray
        s_j per segment (K+1,) [signal unit/°C].
    temp_c : numpy.ndarray
        Temperatures [°C].

    Returns
    -------
    numpy.ndarray
        y [signal unit].

    References
    ----------
    - *Design and engineering implementation of a fibre-optic-gyro line-of-sight
      stabilisation system*, master's thesis, chapter 3 "Fibre-optic gyroscope".

    Examples
    --------
    >>> import numpy as np
    >>> t = np.array([20.0, 30.0, 40.0])
    >>> evaluate_lines(np.array([30.0]), np.array([1.0, -2.0]), np.array([0.1, 0.2]), t).tolist()
    [3.0, 4.0, 6.0]
    """
    j = np.searchsorted(breakpoints, temp_c, side="right")
    out: FloatArray = intercepts[j] + slopes[j] * temp_c
    return out


def _bin_runs(
    temps: Sequence[FloatArray], ys: Sequence[FloatArray], lo: float, hi: float, per_run: bool
) -> tuple[FloatArray, FloatArray, FloatArray, npt.NDArray[np.int64], FloatArray]:
    """Per-run temperature bins: mean T, mean y, count, run index, bin index."""
    edges = np.linspace(lo, hi, N_BINS + 1)
    bx, by, bw, bg, bk = [], [], [], [], []
    for r, (x, y) in enumerate(zip(temps, ys, strict=True)):
        k = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, N_BINS - 1)
        cnt = np.bincount(k, minlength=N_BINS).astype(np.float64)
        sx = np.bincount(k, weights=x, minlength=N_BINS)
        sy = np.bincount(k, weights=y, minlength=N_BINS)
        ok = cnt > 0
        bx.append(sx[ok] / cnt[ok])
        by.append(sy[ok] / cnt[ok])
        bw.append(cnt[ok])
        bg.append(np.full(int(ok.sum()), r if per_run else 0, dtype=np.int64))
        bk.append(np.flatnonzero(ok).astype(np.float64))
    return (
        np.concatenate(bx),
        np.concatenate(by),
        np.concatenate(bw),
        np.concatenate(bg),
        np.concatenate(bk),
    )


class _BreakpointSearch:
    """The search of :func:`choose_breakpoints` on the binned data, breakpoints
    normalised to the temperature range (0 = ``lo``, 1 = ``hi``)."""

    def __init__(
        self,
        allx: FloatArray,
        lo: float,
        hi: float,
        X: FloatArray,
        Y: FloatArray,
        W: FloatArray,
        G: npt.NDArray[np.int64],
        K: FloatArray,
        groups: int,
    ) -> None:
        self.allx, self.lo, self.hi, self.Y, self.W = allx, lo, hi, Y, W
        self.Z = np.zeros((X.size, groups))
        self.Z[np.arange(X.size), G] = 1.0
        self.xc = (X - lo) / (hi - lo)
        self.sorted_x = np.sort(allx)
        self.sorted_bins = np.unique(K) / N_BINS  # left edges of occupied bins, normalised
        self.cand = np.unique((np.quantile(allx, np.linspace(0.01, 0.99, 99)) - lo) / (hi - lo))

    def supported(self, bps_c: Sequence[float]) -> bool:
        """Every segment wide enough, with enough samples over enough temperatures."""
        lo, hi, sorted_x = self.lo, self.hi, self.sorted_x
        b = np.asarray(bps_c, dtype=np.float64)
        bounds = np.concatenate([[0.0], b, [1.0]])
        if np.any(np.diff(bounds) < MIN_SEGMENT_WIDTH_FRACTION - 1e-9):
            return False
        below = np.searchsorted(sorted_x, lo + b * (hi - lo), side="left")
        counts = np.diff(np.concatenate([[0], below, [sorted_x.size]]))
        if np.any(counts < MIN_SEGMENT_SAMPLES):
            return False
        # distinct temperatures: occupied bins whose left edge lies in the segment
        nb_in = np.diff(np.searchsorted(self.sorted_bins, bounds, side="left"))
        return bool(np.all(nb_in >= MIN_SEGMENT_BINS))

    def rss(self, bps_c: Sequence[float]) -> float:
        """Weighted RSS of the continuous hinge fit with these breakpoints."""
        xc, W, Y = self.xc, self.W, self.Y
        cols = [self.Z, xc[:, None]] + [np.maximum(0.0, xc - b)[:, None] for b in bps_c]
        A = np.hstack(cols) * W[:, None]
        beta, _res, _rank, _sv = np.linalg.lstsq(A, Y * W, rcond=None)
        res = Y * W - A @ beta
        return float(res @ res)

    def start(self, k: int) -> list[float] | None:
        """A feasible placement of k − 1 breakpoints (quantiles, else equal widths)."""
        if k == 1:
            return []
        lo, hi = self.lo, self.hi
        for guess in (
            (np.quantile(self.allx, np.linspace(0, 1, k + 1)[1:-1]) - lo) / (hi - lo),
            np.linspace(0, 1, k + 1)[1:-1],
        ):
            cur = [float(v) for v in guess]
            if self.supported(cur):
                return cur
        return None

    def search(self, cur: list[float]) -> tuple[list[float], float]:
        """Coordinate search over the candidate quantiles, then Nelder–Mead; returns the
        breakpoints and their RSS."""
        nb = len(cur)
        best = self.rss(cur)
        if nb == 0:
            return cur, best
        for _sweep in range(10):
            changed = False
            for j in range(nb):
                left = cur[j - 1] if j > 0 else 0.0
                right = cur[j + 1] if j < nb - 1 else 1.0
                for c in self.cand:
                    if not left < c < right:
                        continue
                    trial = [*cur[:j], float(c), *cur[j + 1 :]]
                    if not self.supported(trial):
                        continue
                    v = self.rss(trial)
                    if v < best - 1e-12 * abs(best):
                        best, cur, changed = v, trial, True
            if not changed:
                break
        worst = best * 10.0 + 1.0

        def penalised(v: FloatArray) -> float:
            s = sorted(float(b) for b in v)
            return self.rss(s) if self.supported(s) else worst

        res = optimize.minimize(
            penalised, np.array(cur), method="Nelder-Mead", options={"xatol": 1e-5, "fatol": 0.0}
        )
        if res.fun < best:
            cur, best = sorted(float(b) for b in res.x), float(res.fun)
        return cur, best


def choose_breakpoints(
    temps: Sequence[FloatArray],
    ys: Sequence[FloatArray],
    n_segments: int,
    *,
    per_run_offset: bool = True,
) -> BreakpointChoice:
    """Breakpoints of at most ``n_segments`` segments chosen from the data ([Seed-FOG],
    our reading: "a continuous piecewise-linear fit with breakpoints chosen by the data").

    The data are reduced to per-run temperature bins (mean T, mean y, count; N_BINS bins
    over the range).  For each k = 1 … K the k − 1 breakpoints minimise the weighted
    residual sum of squares RSS_k of the continuous hinge fit
    ``y = c_r + s_0 T + Σ_j d_j max(0, T − b_j)`` (coordinate search over the 1–99 %
    quantiles of T, then Nelder–Mead), subject to every segment spanning at least
    :data:`MIN_SEGMENT_WIDTH_FRACTION` of the range and holding at least
    :data:`MIN_SEGMENT_SAMPLES` samples over :data:`MIN_SEGMENT_BINS` distinct
    temperatures, so that no segment can collapse onto a few samples.  K is
    ``n_segments`` or the largest number of segments those rules allow.  The number kept
    minimises the Bayesian information criterion (Schwarz 1978,
    doi:10.1214/aos/1176344136) on the binned means,
    ``BIC_k = n_b ln(RSS_k / n_b) + p_k ln n_b``, ``p_k = m + 1 + 2(k − 1)`` (m run
    levels, the slope, and a slope change and a location per breakpoint): a breakpoint
    is kept only when the data warrant it.  Binning averages the within-bin noise, so
    coloured chamber noise inflates the criterion less than it would per sample.

    Parameters
    ----------
    temps, ys : sequence of numpy.ndarray
        Temperatures [°C] and targets [signal unit] per run.
    n_segments : int
        Most segments.
    per_run_offset : bool, optional
        One level per run (default True).

    Returns
    -------
    BreakpointChoice
    """
    if n_segments < 1:
        raise ThermocalInputError(f"number of segments must be ≥ 1, got {n_segments}")
    allx = np.concatenate([np.asarray(t) for t in temps])
    lo, hi = float(allx.min()), float(allx.max())
    if not hi > lo:
        raise DesignError("the temperature does not vary; cannot choose breakpoints")
    X, Y, cnt, G, K = _bin_runs(temps, ys, lo, hi, per_run_offset)
    W = np.sqrt(cnt)
    groups = int(G.max()) + 1
    n_b = X.size
    searcher = _BreakpointSearch(allx, lo, hi, X, Y, W, G, K, groups)
    fits: list[tuple[list[float], float]] = []
    for k in range(1, n_segments + 1):
        first = searcher.start(k)
        if first is None:
            break
        fits.append(searcher.search(first))
    # residuals below float64 resolution of the data are all the same "exact fit": floor
    # RSS there, so that noise-free data keep the fewest segments, not rounding noise
    # (all-zero data: the floor is the smallest positive float, never 0 — log(0) fails)
    floor = max(n_b * (1e-9 * float(np.max(np.abs(Y * W)))) ** 2, np.finfo(np.float64).tiny)
    bic = [
        n_b * math.log(max(r, floor) / n_b) + (groups + 1 + 2 * (k - 1)) * math.log(n_b)
        for k, (_b, r) in enumerate(fits, start=1)
    ]
    chosen = int(np.argmin(bic)) + 1
    bps = fits[chosen - 1][0]
    return BreakpointChoice(
        breakpoints_c=[float(lo + b * (hi - lo)) for b in bps],
        requested=n_segments,
        supported=len(fits),
        chosen=chosen,
        bic=bic,
    )


def segment_tests(
    breakpoints_c: FloatArray,
    xs: Sequence[FloatArray],
    name: str,
    lo: float,
    hi: float,
    *,
    given: bool,
    unit: str = "°C",
) -> tuple[AdequacyTest, ...]:
    """Every segment of a fitted piecewise model judged as the line it is, by the common
    rules of :mod:`thermocal.adequacy` (a 0.28 °C segment holding one burst was
    fitted and exported): its temperature span (≥ ``MIN_SPAN_PER_ORDER_C`` °C for order 1),
    its distinct temperatures (≥ 2) and its samples per coefficient (≥
    ``MIN_SAMPLES_PER_COEFFICIENT`` for 2), over the samples of every run in
    ``[b_j, b_{j+1})`` of the final ``breakpoints_c`` [°C] (``lo``/``hi`` the range's ends).
    Raw-count temperatures (``unit`` not °C): the span is not judged (as
    :func:`thermocal.adequacy.temperature_tests`).  Each message names the segment and the
    parameter that helps: move or drop a breakpoint (``breakpoints``, when ``given``) or
    fewer ``segments``; a failed span or sample count can be fitted anyway with the
    ``allow_narrow`` override (recorded in the adequacy record).

    Parameters
    ----------
    breakpoints_c : numpy.ndarray
        Final breakpoints [°C].
    xs : sequence of numpy.ndarray
        Temperatures per run [°C].
    name : str
        The temperature column.
    lo, hi : float
        The range's ends [°C].
    given : bool
        Breakpoints given by the user.
    unit : str, optional
        Temperature unit.  Default ``"°C"``.

    Returns
    -------
    tuple of thermocal.adequacy.AdequacyTest
    """
    edges = [lo, *(float(b) for b in breakpoints_c), hi]
    n_seg = len(edges) - 1
    parts: list[list[FloatArray]] = [[] for _ in range(n_seg)]
    for x in xs:
        idx = segment_index(np.asarray(breakpoints_c, dtype=np.float64), x)
        for k in range(n_seg):
            parts[k].append(x[idx == k])
    fix, named = (
        ("move or drop a breakpoint ({breakpoints})", ("breakpoints",))
        if given
        else (f"ask fewer {{segments}} ({{segments}} {n_seg - 1})", ("segments",))
        if n_seg > 1
        else ("record a wider sweep", ())
    )
    out: list[AdequacyTest] = []
    for k in range(n_seg):
        seg = np.concatenate(parts[k]) if parts[k] else np.zeros(0)
        label = f"{name} segment {k + 1} of {n_seg} ({edges[k]:.4g}…{edges[k + 1]:.4g} °C)"
        judged = [
            samples_test(int(seg.size), 2, label),
            *(t for t in temperature_tests(seg, label, 1, unit=unit) if t.name != "range_ends"),
        ]
        out += [
            dataclasses.replace(
                t,
                name=f"segment_{k + 1}_{t.name}",
                message=t.message.removesuffix(": record a wider sweep") + f": {fix}",
                parameters=named,
            )
            if t.verdict != "pass"
            else dataclasses.replace(t, name=f"segment_{k + 1}_{t.name}")
            for t in judged
        ]
    return tuple(out)


@dataclass(frozen=True)
class _Lines:
    """The least-squares lines of the segments: intercepts a_s and slopes k_s [signal unit,
    per °C], their covariance (2S × 2S), the per-run offsets and their mean, the solution
    and the sample count."""

    intercepts: FloatArray
    slopes: FloatArray
    line_cov: FloatArray
    offsets: FloatArray
    const: float
    sol: LstsqSolution
    n_total: int
    m: int
