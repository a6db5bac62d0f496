"""C code of the ``bank`` family (:mod:`thermocal.export.c`): the bank of models
chosen at power-on."""

from __future__ import annotations

import numpy as np

from thermocal.export.c.core import (
    ExportContext,
    FamilyCode,
)


def generate(ctx: ExportContext) -> FamilyCode:
    """Model bank (models/bank_select.py ``BankStream``): every piecewise-linear model
    evaluated at the clamped T; during ``t − t_first < startup_s`` the residual sums
    ``Σ (y − f_m)`` pick ``argmin_m |Σ_m/N|``; then the choice is frozen.

    Parameters
    ----------
    ctx : ExportContext
        The model dict, C prefix, real type and ring-buffer length.

    Returns
    -------
    FamilyCode
        The family's state fields, constant data and the C bodies of init and update.
    """
    st = ctx.model["state"]
    P, r = ctx.P, ctx.r
    m = len(st["models"])
    return FamilyCode(
        state_fields=[
            "int started;",
            "double t_first;",
            f"{r} sums[{P}_N_MODELS];",
            "long count;",
            "int frozen;",
            "int choice; /* index of the selected model */",
        ],
        data=_data(ctx),
        init=_init(ctx),
        update=_update(ctx),
        defines=[f"#define {P}_N_MODELS {m}"],
        notes=[
            "Model bank: one piecewise-linear model per characteristic curve,",
            f"selected during the first {float(st['startup_s']):g} s after power-on by the",
            "smallest |mean(signal - known_input - model)|; pass the raw signal to update.",
        ],
    )


def _data(ctx: ExportContext) -> str:
    """The models' breakpoints and values in two arrays with offsets, and ``<p>_pwl``."""
    st = ctx.model["state"]
    models = st["models"]
    P, r, p = ctx.P, ctx.r, ctx.prefix
    m = len(models)
    bps = [np.asarray(mm["breakpoints_c"], dtype=np.float64) for mm in models]
    vals = [np.asarray(mm["values"], dtype=np.float64) for mm in models]
    offsets = np.cumsum([0] + [b.size for b in bps])
    return "\n".join(
        [
            ctx.clamp_arrays(),
            f"/* {m} piecewise-linear models; model i uses entries OFF[i] .. OFF[i+1]-1 */",
            ctx.array(f"{P}_X", np.concatenate(bps)),
            ctx.array(f"{P}_V", np.concatenate(vals)),
            f"static const int {P}_OFF[{m + 1}] = {{"
            + ", ".join(str(int(o)) for o in offsets)
            + "};",
            f"static const double {P}_STARTUP_S = {float(st['startup_s'])!r};",
            "",
            f"static {r} {p}_pwl(int i, {r} t)",
            "{",
            f"    const {r} *x = {P}_X + {P}_OFF[i];",
            f"    const {r} *v = {P}_V + {P}_OFF[i];",
            f"    int n = {P}_OFF[i + 1] - {P}_OFF[i];",
            "    int j = 0;",
            f"    {r} slope;",
            "    /* largest j with x[j] <= t, clipped to 0 .. n-2 */",
            "    while (j + 1 < n && x[j + 1] <= t) {",
            "        ++j;",
            "    }",
            "    if (j > n - 2) {",
            "        j = n - 2;",
            "    }",
            "    slope = (v[j + 1] - v[j]) / (x[j + 1] - x[j]);",
            "    return v[j] + slope * (t - x[j]);",
            "}",
        ]
    )


def _init(ctx: ExportContext) -> str:
    """Power-on: no model chosen, the residual sums cleared."""
    P = ctx.P
    return f"""
int i;
s->started = 0;
s->t_first = 0.0;
s->count = 0;
s->frozen = 0;
s->choice = 0;
for (i = 0; i < {P}_N_MODELS; ++i) {{
    s->sums[i] = {ctx.lit(0.0)};
}}
"""


def _update(ctx: ExportContext) -> str:
    """Every model at the clamped T; the start-up selection, then the frozen choice."""
    P, r, p = ctx.P, ctx.r, ctx.prefix
    return f"""
{r} temp = {p}_clamp(temps_c[0], {P}_T_LO[0], {P}_T_HI[0]);
{r} f[{P}_N_MODELS];
int i;
for (i = 0; i < {P}_N_MODELS; ++i) {{
    f[i] = {p}_pwl(i, temp);
}}
if (!s->started) {{
    s->started = 1;
    s->t_first = time_s;
}}
if (!s->frozen && time_s - s->t_first < {P}_STARTUP_S) {{
    {r} y = signal - s->known_input;
    {r} best = {ctx.lit(0.0)};
    s->count += 1;
    for (i = 0; i < {P}_N_MODELS; ++i) {{
        {r} dev;
        s->sums[i] = s->sums[i] + (y - f[i]);
        dev = s->sums[i] / ({r})s->count;
        dev = dev < {ctx.lit(0.0)} ? -dev : dev;
        if (i == 0 || dev < best) {{
            best = dev;
            s->choice = i;
        }}
    }}
}} else {{
    s->frozen = 1;
}}
return f[s->choice];
"""
