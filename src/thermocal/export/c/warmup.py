"""C code of the ``warmup`` family (:mod:`thermocal.export.c`): warm-up models indexed
by the start temperature."""

from __future__ import annotations

import numpy as np

from thermocal.export.c.core import (
    ExportContext,
    FamilyCode,
)
from thermocal.identifiers import c_comment


def generate(ctx: ExportContext) -> FamilyCode:
    """Warm-up model (models/warmup_stream.py ``WarmupStream``):

    T = clamp(T_in); during ``t − t_first < W``: T0 = running mean of T; then frozen;
    a_j = Σ_k b_jk clamp(T0)^k (Horner), ΔF = Σ_j a_j (T − T0)^j (Horner).

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
    b = np.asarray(st["b"], dtype=np.float64)
    lo, hi = (float(v) for v in st["t0_range_c"])
    window = float(st["start_window_s"])
    P, r, p = ctx.P, ctx.r, ctx.prefix
    nj, nk = b.shape
    data = "\n".join(
        [
            ctx.clamp_arrays(),
            f"/* b[j][k]: coefficient of dT^j * T0^k [{c_comment(ctx.model['signal']['unit'])}/"
            f"{ctx.tu}^(j+k)] */",
            ctx.array2(f"{P}_B", b),
            f"static const {r} {P}_T0_LO = {ctx.lit(lo)}; /* fitted start temperatures */",
            f"static const {r} {P}_T0_HI = {ctx.lit(hi)};",
            f"static const double {P}_START_WINDOW_S = {window!r};",
        ]
    )
    init = f"""
s->started = 0;
s->t_first = 0.0;
s->sum = {ctx.lit(0.0)};
s->count = 0;
s->frozen = 0;
s->t0 = {ctx.lit(0.0)};
"""
    update = f"""
{r} temp = {p}_clamp(temps_c[0], {P}_T_LO[0], {P}_T_HI[0]);
{r} t0c, dt, acc = {ctx.lit(0.0)};
int j, k;
(void)signal;
if (!s->started) {{
    s->started = 1;
    s->t_first = time_s;
}}
if (!s->frozen && time_s - s->t_first < {P}_START_WINDOW_S) {{
    s->sum = s->sum + temp;
    s->count += 1;
    s->t0 = s->sum / ({r})s->count;
}} else if (!s->frozen) {{
    s->frozen = 1;
}}
t0c = {p}_clamp(s->t0, {P}_T0_LO, {P}_T0_HI);
dt = temp - s->t0;
for (j = {nj - 1}; j >= 0; --j) {{
    {r} a = {P}_B[j][{nk - 1}];
    for (k = {nk - 2}; k >= 0; --k) {{
        a = a * t0c + {P}_B[j][k];
    }}
    acc = (j == {nj - 1}) ? a : acc * dt + a;
}}
return acc;
"""  # cli-words: C's pre-decrement operators (--j, --k) in the generated loop, not options
    return FamilyCode(
        state_fields=[
            "int started;",
            "double t_first;",
            f"{r} sum;",
            "long count;",
            "int frozen;",
            f"{r} t0;",
        ],
        data=data,
        init=init,
        update=update,
        defines=[f"#define {P}_ORDER {nj - 1}", f"#define {P}_T0_ORDER {nk - 1}"],
        notes=[
            "Warm-up model: dF = sum_j a_j(T0) dT^j, a_j(T0) = sum_k b_jk T0^k,",
            f"T0 = running mean of the temperature over the first {window:g} s after power-on.",
            "Call init at power-on.",
        ],
    )
