"""The polynomial model's types that its fitting and its evaluation share ([Seed-RLG]).

:mod:`thermocal.models.poly_fit` and :mod:`thermocal.models.poly_eval` work on
:class:`PolyBase` (parameters, fitted values, Ṫ, the evaluation plan); the model itself,
:class:`thermocal.models.poly.PolyModel`, adds the estimator contract on top of both.  So
the three modules import downwards only: this module ← fit, eval ← poly.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
import numpy.typing as npt

from thermocal.errors import ThermocalInputError
from thermocal.models.base import TemperatureModel
from thermocal.models.fitting import Block
from thermocal.models.rundata import RunData
from thermocal.models.term_scaling import BaseScaling
from thermocal.models.terms import Term
from thermocal.preprocess import RATE_METHODS, segment_rates, temperature_rates
from thermocal.recording import FloatArray

DEFAULT_RCOND = 1.0e-3
"""Singular values of the equilibrated term design below this × the largest are truncated.

Chosen on the simulator (``rlg`` preset, ``rlg-modelling`` → ``rlg-validation``): the
seed000 design there has κ ≈ 3e6; without truncation the directions with tiny
singular values carry noise amplified up to κ× and the model fails on the
validation profile; with 1e-3 about 8 of 36 directions are dropped and the
validation removal of the temperature-induced bias rises (noise-free: 97.5 → 99.7 %)."""

DEFAULT_NOISE_THRESHOLD = 10.0
"""A truncated component is kept after all when the data along it exceed 10 σ̂ (white-noise σ̂)."""

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

    Attributes
    ----------
    constant : float
        The constant [signal unit].
    sensors, kinds, horner, centres, centred, mixed, rate_sensors, py_rows
        As described above.
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
    constant), which saves a pass and loses no accuracy.

    Parameters
    ----------
    terms, scaling, coef, constant : list of Term, BaseScaling, numpy.ndarray, float
        The fitted terms, their scaling, coefficients and constant [signal unit].
    """
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


class PolyBase(TemperatureModel):
    """The parameters and fitted values of :class:`~thermocal.models.poly.PolyModel` (its
    docstring lists them) and what fitting and evaluation ask of them: the parameter
    check, Ṫ and the evaluation plan.

    Parameters
    ----------
    terms : str or list of str or None
        Term list (``"seed000"`` default) or None with ``order``.
    order : int, optional
        Plain polynomial order in T.
    rate_interval_s : float
        Ṫ interval Δt [s] (default 60).
    rate_method : str
        ``backward`` (default), ``forward`` or ``centred``.
    select : str, optional
        Term selection: ``bic`` or ``holdout``.
    ridge : float
        Ridge α ≥ 0 (default 0).
    rcond : float, optional
        Truncation ratio of singular values.
    per_run_offset : bool, optional
        Per-run offsets (None: decided from the runs' overlap).
    solver : str
        ``auto`` (default), ``qr`` or ``gram``.
    noise_threshold : float, optional
        k of the discrete Picard rule.
    """

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
        """Ṫ of every temperature column [°C/min] with the model's rate form and Δt.

        Parameters
        ----------
        time_s : numpy.ndarray
            Sample times (n,) [s].
        temps_c : numpy.ndarray
            Temperatures (n, k) [°C].

        Returns
        -------
        numpy.ndarray
            Ṫ (n, k) [°C/min].

        Notes
        -----
        .. math:: \\dot T_i = 60\\, \\frac{T_i - T_j}{t_i - t_j}, \\qquad
                  t_j = \\min\\{t : t \\ge t_i - \\Delta t\\} \\text{ (backward)}
        """
        return temperature_rates(time_s, temps_c, float(self.rate_interval_s), self.rate_method)

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
