"""C code of the ``poly`` family (:mod:`thermocal.export.c`): the polynomial model
with its Ṫ buffer, as models/poly.py streams it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal.errors import ModelFileError
from thermocal.export.c.core import (
    ExportContext,
    FamilyCode,
    _rate_buffer_code,
)
from thermocal.identifiers import c_comment
from thermocal.recording import FloatArray

N_ACCUMULATORS = 4
"""Partial sums of the terms in the generated C (term i goes to sum i mod 4; the sums are
added pairwise at the end): four chains of additions run side by side, where one would
wait on each addition's latency (18.6 → 30+ M samples/s at -O2)."""


@dataclass(frozen=True)
class _PolyPlan:
    """What the poly C needs from the model's ``state`` (:func:`generate`): the terms and
    coefficients, which sensors feed u (T), v (Ṫ) and w (T·Ṫ), whether the clamped T is
    needed and whether the rates are clamped to the fitted rate range."""

    state: dict[str, Any]
    terms: list[dict[str, Any]]
    coef: FloatArray
    uses_rate: bool
    rate: dict[str, Any]
    rate_sensors: list[int]
    t_sensors: list[int]
    v_sensors: list[int]
    w_sensors: list[int]
    rate_range: dict[str, list[float]]
    clamp_rate: bool

    @property
    def needs_t(self) -> bool:
        """The clamped T is used by u or w."""
        return bool(self.t_sensors or self.w_sensors)


def _plan(ctx: ExportContext) -> _PolyPlan:
    """The model's poly state checked (layout, causal rate form) and read."""
    d = ctx.model
    st = ctx.state("poly")
    terms = st["terms"]
    uses_rate = bool(st.get("uses_rate"))
    rate = st.get("rate") or {}
    if uses_rate and rate.get("method", "backward") != "backward":
        raise ModelFileError(
            f"poly model uses the {rate.get('method')!r} rate form; only the causal "
            "'backward' form can run sample by sample"
        )
    rr: dict[str, list[float]] = (d.get("range") or {}).get("rate_c_per_min") or {}
    return _PolyPlan(
        state=st,
        terms=terms,
        coef=np.asarray(st["coef"], dtype=np.float64),
        uses_rate=uses_rate,
        rate=rate,
        rate_sensors=sorted(
            {int(t["sensor"]) for t in terms if t["rate_power"] or t["coupling_power"]}
        ),
        t_sensors=sorted({int(t["sensor"]) for t in terms if t["t_power"]}),
        v_sensors=sorted({int(t["sensor"]) for t in terms if t["rate_power"]}),
        w_sensors=sorted({int(t["sensor"]) for t in terms if t["coupling_power"]}),
        rate_range=rr,
        clamp_rate=uses_rate and bool(rr) and bool(rate.get("clamp", True)),
    )


def _data(ctx: ExportContext, plan: _PolyPlan) -> list[str]:
    """The ``static const`` arrays: only those the terms use (-Wall -Wextra -Werror rejects
    unused static consts)."""
    d = ctx.model
    P, r = ctx.P, ctx.r
    base = plan.state["base"]

    def col(key: str) -> list[float]:
        return [float(b[key]) for b in base]

    if plan.needs_t:
        data = [ctx.clamp_arrays()]
    else:  # constant or rate-only model: the temperature range is documentation only
        rng = ctx.temp_range()
        data = [
            f"/* fitted temperature range [{ctx.tu}]: "
            + ", ".join(
                f"{n} {lo!r}..{hi!r}" for n, (lo, hi) in zip(d["temperatures"], rng, strict=True)
            )
            + " (not used: no T or T*dT term) */"
        ]
    used = [
        (plan.t_sensors, "T", "t_center", "t_scale", "u"),
        (plan.v_sensors, "R", "rate_center", "rate_scale", "v"),
        (plan.w_sensors, "W", "coupling_center", "coupling_scale", "w"),
    ]
    for sensors, tag, c_key, s_key, var in used:
        if sensors:
            data += [
                f"/* centre and reciprocal scale (1/s, no division per sample) of the base "
                f"variable {var} of every sensor */",
                ctx.array(f"{P}_{tag}_CENTER", col(c_key)),
                ctx.array(f"{P}_{tag}_INV_SCALE", 1.0 / np.asarray(col(s_key), dtype=np.float64)),
            ]
    if plan.terms:
        data += [
            f"/* coefficients of the {len(plan.terms)} terms [signal unit] */",
            ctx.array(f"{P}_COEF", plan.coef),
        ]
    data.append("/* constant [signal unit] */")
    data.append(f"static const {r} {P}_CONSTANT = {ctx.lit(float(plan.state['constant']))};")
    if plan.clamp_rate:
        rng = np.array([plan.rate_range[n] for n in d["temperatures"]], dtype=np.float64)
        data += [
            f"/* fitted temperature-rate range [{ctx.tu}/min]: rates of the rate sensors are "
            "clamped */",
            ctx.array(f"{P}_R_LO", rng[:, 0]),
            ctx.array(f"{P}_R_HI", rng[:, 1]),
        ]
    return data


def generate(ctx: ExportContext) -> FamilyCode:
    """Polynomial model (models/poly.py docstring steps 1–4 and ``PolyStream``):
    Ṫ from the raw temperatures, clamp T and Ṫ (rate sensors) to the fitted ranges,
    ``u = (T − c_T)/s_T``, ``v = (Ṫ − c_R)/s_R``, ``w = (T·Ṫ − c_W)/s_W``,
    ``y = Σ_j coef_j u^a v^b w^c + constant`` (powers by repeated multiplication; the sum
    in :data:`N_ACCUMULATORS` partial sums).

    Parameters
    ----------
    ctx : ExportContext
        The model dict, C prefix, real type and ring-buffer length.

    Returns
    -------
    FamilyCode
        The family's state fields, constant data and the C bodies of init and update.
    """
    plan = _plan(ctx)
    P, p = ctx.P, ctx.prefix
    data = _data(ctx, plan)
    defines = [f"#define {P}_N_TERMS {len(plan.terms)}"]
    notes = [
        f"Polynomial model: {len(plan.terms)} terms + constant in the centred and scaled",
        "base variables u = (T - c_T)/s_T, v = (dT - c_R)/s_R, w = (T dT - c_W)/s_W",
        f"(dT = backward difference over the rate interval, {ctx.tu}/min). Inputs are clamped",
        "to the fitted temperature (and rate) range. Call init at power-on.",
    ]
    if not plan.terms:
        return FamilyCode(
            state_fields=["int unused; /* no state */"],
            data="\n".join(data),
            init="s->unused = 0;",
            update="\n".join(
                [
                    "(void)s; /* a constant model */",
                    "(void)time_s;",
                    "(void)temps_c;",
                    "(void)signal;",
                    f"(void){p}_clamp; /* nothing to clamp */",
                    f"return {P}_CONSTANT;",
                ]
            ),
            defines=defines,
            notes=notes,
        )
    fields: list[str] = []
    init = ""
    upd, n_acc = _update_head(ctx, plan)
    if plan.uses_rate:
        interval = float(plan.rate.get("interval_s", 60.0))
        defines += [
            f"#define {P}_RATE_INTERVAL_S {interval!r}",
            "/* ring buffer of the rate: >= samples in RATE_INTERVAL_S + 1 */",
            f"#ifndef {P}_RATE_BUF_LEN",
            f"#define {P}_RATE_BUF_LEN {ctx.rate_buffer_len}",
            "#endif",
        ]
        fields, init, rate_update = _rate_buffer_code(ctx)
        upd += [f"{ctx.r} rate[{P}_N_TEMPS];", rate_update.strip("\n")]
    upd += _base_variables(ctx, plan) + _term_sum(ctx, plan, n_acc)
    return FamilyCode(
        state_fields=fields or ["int unused; /* no state */"],
        data="\n".join(data),
        init=init or "s->unused = 0;",
        update="\n".join(upd),
        defines=defines,
        notes=notes,
    )


def _update_head(ctx: ExportContext, plan: _PolyPlan) -> tuple[list[str], int]:
    """The update's declarations (clamped T, the partial sums) and the number of sums."""
    P, r = ctx.P, ctx.r
    upd = [f"{r} T[{P}_N_TEMPS];"] if plan.needs_t else []
    # independent partial sums: one running sum would chain every term's addition on the
    # last (its latency, not the arithmetic, bounding the speed)
    n_acc = max(1, min(N_ACCUMULATORS, len(plan.terms)))
    upd += [
        f"{r} " + ", ".join(f"acc{k} = {ctx.lit(0.0)}" for k in range(n_acc)) + ";",
        "int i;",
    ]
    return upd, n_acc


def _base_variables(ctx: ExportContext, plan: _PolyPlan) -> list[str]:
    """Update statements after the rate: T and Ṫ clamped, then u, v, w of every sensor."""
    P, r, p = ctx.P, ctx.r, ctx.prefix
    upd = (
        [] if plan.uses_rate else ["(void)s; /* memoryless without rate terms */", "(void)time_s;"]
    )
    upd.append("(void)signal;")
    if plan.needs_t:
        upd += [
            "for (i = 0; i < " + f"{P}_N_TEMPS; ++i) {{",
            f"    T[i] = {p}_clamp(temps_c[i], {P}_T_LO[i], {P}_T_HI[i]);",
            "}",
        ]
    if plan.clamp_rate:
        for j in plan.rate_sensors:
            upd.append(f"rate[{j}] = {p}_clamp(rate[{j}], {P}_R_LO[{j}], {P}_R_HI[{j}]);")
    for j in plan.t_sensors:
        upd.append(f"const {r} u{j} = (T[{j}] - {P}_T_CENTER[{j}]) * {P}_T_INV_SCALE[{j}];")
    for j in plan.v_sensors:
        upd.append(f"const {r} v{j} = (rate[{j}] - {P}_R_CENTER[{j}]) * {P}_R_INV_SCALE[{j}];")
    for j in plan.w_sensors:
        upd.append(
            f"const {r} w{j} = (T[{j}] * rate[{j}] - {P}_W_CENTER[{j}]) * {P}_W_INV_SCALE[{j}];"
        )
    return upd


def _power(x: str, n: int) -> str:
    """``x`` to the ``n``-th power by repeated multiplication, ``((x * x) * x)``."""
    out = x
    for _ in range(n - 1):
        out = f"({out} * {x})"
    return out


def _term_sum(ctx: ExportContext, plan: _PolyPlan, n_acc: int) -> list[str]:
    """Each term added to partial sum ``i mod n_acc``; the return of their balanced sum plus
    the constant."""
    P = ctx.P
    upd = []
    for i, t in enumerate(plan.terms):
        j = int(t["sensor"])
        factors = [
            _power(f"{var}{j}", int(t[key]))
            for var, key in (("u", "t_power"), ("v", "rate_power"), ("w", "coupling_power"))
            if int(t[key])
        ]
        val = factors[0]
        for fct in factors[1:]:
            val = f"({val} * {fct})"
        label = c_comment(t.get("name", ""))
        upd.append(f"acc{i % n_acc} += {val} * {P}_COEF[{i}]; /* {label} */")
    total = [f"acc{k}" for k in range(n_acc)]
    while len(total) > 1:  # a balanced sum of the partial sums
        total = [f"({a} + {b})" for a, b in zip(total[::2], total[1::2], strict=False)] + (
            [total[-1]] if len(total) % 2 else []
        )
    upd.append(f"return {total[0]} + {P}_CONSTANT;")
    return upd
