"""C code of the ``piecewise`` family (:mod:`thermocal.export.c`): piecewise-linear
segments."""

from __future__ import annotations

import numpy as np

from thermocal.errors import ModelFileError
from thermocal.export.c.core import (
    ExportContext,
    FamilyCode,
)
from thermocal.identifiers import c_comment


def generate(ctx: ExportContext) -> FamilyCode:
    """Piecewise-linear model (models/piecewise.py eq. 1 and ``PiecewiseStream``):

    ``T = clamp(T_in)`` to the fitted range; ``j`` = number of breakpoints ``≤ T``;
    ``y = intercepts[j] + slopes[j]·T``.  Both methods (``intersect``, ``continuous``)
    store their lines in this form, so one generator serves both; a discontinuous
    ``intersect`` model (lines that do not meet) jumps at the kept breakpoint exactly
    as in Python.  Memoryless: the state struct only holds the common fields.

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
    st = ctx.state("piecewise")
    P, r, p = ctx.P, ctx.r, ctx.prefix
    bps = np.asarray(st["breakpoints"], dtype=np.float64).ravel()
    icp = np.asarray(st["intercepts"], dtype=np.float64).ravel()
    slp = np.asarray(st["slopes"], dtype=np.float64).ravel()
    if icp.size != bps.size + 1 or slp.size != bps.size + 1:
        raise ModelFileError(
            f"piecewise state: {bps.size} breakpoints need {bps.size + 1} intercepts and "
            f"slopes, got {icp.size} and {slp.size}"
        )
    if bps.size > 1 and not bool(np.all(np.diff(bps) > 0)):
        raise ModelFileError("piecewise state: breakpoints are not strictly ascending")
    names = [str(n) for n in d["temperatures"]]
    used = str(st.get("temperature") or names[0])
    if used not in names:
        raise ModelFileError(
            f"piecewise state: temperature {used!r} is not among the file's temperatures "
            f"{', '.join(map(repr, names))}"
        )
    k = names.index(used)
    unit = c_comment((d.get("signal") or {}).get("unit") or "signal unit")
    method = c_comment(st.get("method"))
    n_b = int(bps.size)
    data = [
        ctx.clamp_arrays(),
        f"/* line j: y = A[j] + S[j] * T for BP[j-1] <= T < BP[j] ({method} method);",
        f"   A [{unit}], S [{unit}/{ctx.tu}] */",
        ctx.array(f"{P}_A", icp),
        ctx.array(f"{P}_S", slp),
    ]
    if n_b:
        data += [
            f"/* breakpoints [{ctx.tu}], ascending */",
            ctx.array(f"{P}_BP", bps),
        ]
    upd = [
        f"const {r} temp = {p}_clamp(temps_c[{k}], {P}_T_LO[{k}], {P}_T_HI[{k}]);",
        "int j = 0;",
        "(void)s; /* memoryless */",
        "(void)time_s;",
        "(void)signal;",
    ]
    if n_b:
        upd += [
            "/* j = number of breakpoints <= T */",
            f"while (j < {P}_N_BREAKPOINTS && {P}_BP[j] <= temp) {{",
            "    ++j;",
            "}",
        ]
    upd.append(f"return {P}_A[j] + {P}_S[j] * temp;")
    return FamilyCode(
        state_fields=["int unused; /* memoryless model: no state */"],
        data="\n".join(data),
        init="s->unused = 0;",
        update="\n".join(upd),
        defines=[
            f"#define {P}_N_BREAKPOINTS {n_b}",
            f"#define {P}_TEMP_INDEX {k} /* temps_c[] entry the model uses ({c_comment(used)}) */",
        ],
        notes=[
            f"Piecewise-linear model ({method} method) in {used} [{ctx.tu}]:",
            "y = A[j] + S[j] T, j = number of breakpoints <= T; T clamped to the fitted range.",
            "Memoryless; call init once before use.",
        ],
    )
