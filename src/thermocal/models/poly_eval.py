"""Evaluation of a fitted :class:`~thermocal.models.poly.PolyModel` (module docstring of
:mod:`thermocal.models.poly`, steps 1–4): one plan for ``predict`` on numpy blocks and for
the stream on Python floats, and several models of one structure evaluated together."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
import numpy.typing as npt

from thermocal.errors import ExtrapolationWarning
from thermocal.models.fitting import warn_rate_range
from thermocal.models.poly_types import EvalPlan, PolyBase
from thermocal.models.rundata import RunData
from thermocal.preprocess import backward_partners, gap_free_slices, step_range, temperature_rates
from thermocal.recording import FloatArray
from thermocal.units import SECONDS_PER_MINUTE

# --- evaluation: one plan for predict (numpy blocks) and the stream (Python floats) ----------

PREDICT_BLOCK_ROWS = 8192
"""Rows per block in :meth:`PolyModel.predict`: the block's temporaries (a few
(k × rows) arrays, ~1.5 MB for four sensors) stay in the L2 cache.  (More than 4096:
numpy's broadcast of a coefficient column is slow on smaller rows.)"""


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
        model: PolyBase,
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

    def _load_temperatures(
        self, a: int, b: int, part: int | npt.NDArray[np.intp] | None, buf: dict[str, FloatArray]
    ) -> tuple[FloatArray, FloatArray | None]:
        """The block's raw temperatures (columns × rows) and, for a backward Ṫ whose
        partners lie ``part`` rows back, the partners' (else None), in the buffers."""
        temps, c = self.temps, b - a
        width = buf["prev"].shape[1]
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
        return cur, prev

    def _rates(
        self,
        a: int,
        b: int,
        part: int | npt.NDArray[np.intp] | None,
        cura: FloatArray,
        preva: FloatArray | None,
        ra: FloatArray,
        seen: _Seen,
        buf: dict[str, FloatArray],
    ) -> None:
        """Step 1 into ``ra``: Ṫ = (T_i − T_lo)/(t_i − t_lo)·60 [°C/min] from the raw
        temperatures (or the forward/centred rates computed beforehand); records the range
        met and clips to the fitted one when asked."""
        t, temps, c = self.t, self.temps, b - a
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
        if self.clip_rates and (bool(np.any(rmin < self.r_lo1)) or bool(np.any(rmax > self.r_hi1))):
            np.clip(ra, self.r_lo, self.r_hi, out=ra)

    def _block(
        self,
        s0: int,
        a: int,
        b: int,
        outs: list[FloatArray],
        seen: _Seen,
        buf: dict[str, FloatArray],
    ) -> None:
        """Steps 1–4 on rows ``a:b`` of the segment starting at ``s0``, into ``outs``."""
        plan, t = self.plan, self.t
        c = b - a
        part: int | npt.NDArray[np.intp] | None = None
        if plan.rate_sensors and self.rates is None:
            part = backward_partners(t, s0, a, b, self.interval_s, increasing=self.increasing)
        cur, prev = self._load_temperatures(a, b, part, buf)
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
            self._rates(a, b, part, cura, preva, ra, seen, buf)
        # step 3: centred variables, stacked kind by kind
        d = _centred(plan, dall, ta, ra, nr)
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


def _centred(
    plan: EvalPlan, dall: FloatArray, ta: FloatArray, ra: FloatArray, nr: int
) -> dict[str, FloatArray]:
    """Step 3 in place in ``dall``: ``d_u = T − c_T``, ``d_v = Ṫ − c_R`` (Ṫ itself when the
    plan folded its centre, already computed there), ``d_w = T·Ṫ − c_W``, kind by kind."""
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
    return d


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
    from the ranges met: ``n`` samples outside, per column seen and fitted range.

    Parameters
    ----------
    seen_min, seen_max : numpy.ndarray
        Range met per column [°C].
    temp_range : numpy.ndarray
        Fitted range (k, 2) [°C].
    names : sequence of str
        Column names.
    n_outside : int
        Samples outside.
    extrapolate : bool
        Wording (extrapolating or clamped).
    """
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


def evaluation_key(model: PolyBase) -> tuple[Any, ...]:
    """What decides how a fitted model's inputs are turned into its centred variables
    (steps 1–3 of the module docstring) and the shape of step 4: models with equal keys
    (channels fitted together by :func:`fit_shared`, unless term selection differs) can
    be evaluated together by :func:`predict_many`.

    Parameters
    ----------
    model : PolyBase
        A fitted polynomial model.

    Returns
    -------
    tuple
    """
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
    models: Sequence[PolyBase], run: RunData, *, extrapolate: bool = False
) -> list[FloatArray]:
    """:meth:`PolyModel.predict` of several models on one run: the clamped temperatures,
    Ṫ and centred variables once, then each model's polynomial (step 4) on a copy of
    them — the same operations as each model alone, so each result equals its own
    :meth:`~PolyModel.predict` bit for bit.  Models whose :func:`evaluation_key` differs
    are evaluated one by one.  Range warnings are issued once (the ranges are shared).

    Parameters
    ----------
    models : sequence of PolyBase
        Fitted models.
    run : RunData
        Times [s] and temperatures [°C].
    extrapolate : bool, optional
        Default False.

    Returns
    -------
    list of numpy.ndarray
        One (n,) array per model [signal unit].
    """
    if not models:
        return []
    head = models[0]
    key = evaluation_key(head)
    if len(models) == 1 or any(evaluation_key(m) != key for m in models[1:]):
        return [m.predict(run, extrapolate=extrapolate) for m in models]
    return evaluate(models, run, extrapolate=extrapolate)


def evaluate(
    models: Sequence[PolyBase], run: RunData, *, extrapolate: bool = False
) -> list[FloatArray]:
    """Steps 1–4 for models of one :func:`evaluation_key` (one model: :meth:`PolyModel.
    predict`): the inputs, Ṫ and centred variables once, each model's polynomial, and the
    range warnings once (the ranges are shared).

    Parameters
    ----------
    models : sequence of PolyBase
        Fitted models of one :func:`evaluation_key`.
    run : RunData
        Times [s] and temperatures [°C].
    extrapolate : bool, optional
        Default False.

    Returns
    -------
    list of numpy.ndarray
        One (n,) array per model [signal unit].
    """
    head = models[0]
    head.check_fitted()
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
