"""C code of the ``hyst`` family (:mod:`thermocal.export.c`): a polynomial in the die
temperature, the die a first-order lag of the measured temperature."""

from __future__ import annotations

import numpy as np

from thermocal.errors import ModelFileError
from thermocal.export.c.core import ExportContext, FamilyCode
from thermocal.identifiers import c_comment


def generate(ctx: ExportContext) -> FamilyCode:
    """The hyst model (models/hyst.py eq. 1 and ``HystStream``):

    ``T = clamp(T_in)`` to the fitted range; at the first sample ``z = T``, then
    ``z = e z + (1 − c) T + (c − e) T_prev`` with ``e = exp(−h/τ)``,
    ``c = −expm1(−h/τ)·τ/h`` for a step ``h > 0`` (``z`` kept otherwise);
    ``y = Σ a_j u^j`` with ``u = (z − μ)/s`` by Horner's rule.  The lag is computed in
    double whatever the real type.

    Parameters
    ----------
    ctx : ExportContext
        The model dict, C prefix, real type and ring-buffer length.

    Returns
    -------
    FamilyCode
        The family's state fields, constant data and the C bodies of init and update.
    """
    d = ctx.model
    st = ctx.state("hyst")
    P, r, p = ctx.P, ctx.r, ctx.prefix
    coef = np.asarray(st["coefficients"], dtype=np.float64).ravel()
    tau = float(st["tau_s"])
    if not (tau >= 0 and np.all(np.isfinite(coef)) and coef.size >= 1):
        raise ModelFileError("hyst state: tau_s must be ≥ 0 and the coefficients finite")
    names = [str(n) for n in d["temperatures"]]
    used = str(st.get("temperature") or names[0])
    if used not in names:
        raise ModelFileError(
            f"hyst state: temperature {used!r} is not among the file's temperatures "
            f"{', '.join(map(repr, names))}"
        )
    k = names.index(used)
    unit = c_comment((d.get("signal") or {}).get("unit") or "signal unit")
    data = [
        ctx.clamp_arrays(),
        f"/* y = sum_j A[j] u^j, u = (z - CENTRE) / SCALE [{ctx.tu}]; A [{unit}] */",
        ctx.array(f"{P}_A", coef),
    ]
    upd = [
        f"const double x = (double){p}_clamp(temps_c[{k}], {P}_T_LO[{k}], {P}_T_HI[{k}]);",
        f"{r} u;",
        f"{r} y = {P}_A[{P}_ORDER];",
        "int j;",
        "(void)signal;",
        f"if (!s->started || !({P}_TAU_S > 0.0)) {{",
        "    s->z = x;",
        "    s->started = 1;",
        "} else {",
        "    const double h = time_s - s->last_t;",
        "    if (h > 0.0) {",
        f"        const double q = h / {P}_TAU_S;",
        "        const double e = exp(-q);",
        "        const double c = -expm1(-q) / q;",
        "        s->z = e * s->z + (1.0 - c) * x + (c - e) * s->last_x;",
        "    }",
        "}",
        "s->last_t = time_s;",
        "s->last_x = x;",
        f"u = ({r})((s->z - {P}_CENTRE) / {P}_SCALE);",
        f"for (j = {P}_ORDER - 1; j >= 0; j -= 1) {{",
        f"    y = y * u + {P}_A[j];",
        "}",
        "return y;",
    ]
    return FamilyCode(
        state_fields=[
            "int started;",
            "double z;      /* die temperature (the lag's state) */",
            "double last_t; /* previous sample's time [s] */",
            "double last_x; /* previous sample's clamped temperature */",
        ],
        data="\n".join(["#include <math.h>", *data]),
        init="s->started = 0;\ns->z = 0.0;\ns->last_t = 0.0;\ns->last_x = 0.0;",
        update="\n".join(upd),
        defines=[
            f"#define {P}_ORDER {coef.size - 1}",
            f"#define {P}_TAU_S {tau!r} /* the lag tau [s] */",
            f"#define {P}_CENTRE {float(st['centre_c'])!r} /* [{ctx.tu}] */",
            f"#define {P}_SCALE {float(st['scale_c'])!r} /* [{ctx.tu}] */",
            f"#define {P}_TEMP_INDEX {k} /* temps_c[] entry the model uses ({c_comment(used)}) */",
        ],
        notes=[
            f"Thermal-hysteresis model in {used} [{ctx.tu}]: the die temperature z is a",
            "first-order lag (tau) of the clamped reading; y = sum_j A[j] ((z - CENTRE)/SCALE)^j.",
            "Call init once at power-on: the lag starts at the first reading.",
        ],
    )
