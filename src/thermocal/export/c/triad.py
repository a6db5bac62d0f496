"""Plain C99 for a calibration of triads: per triad one function

    void <p>_<triad>_correct(double temp_c, const <real> x[3], <real> out[3]);

computing ``out = (I + E(T))⁻¹ (x − b(T))`` in the data's unit: ``T`` clamped to the
calibrated range, every parameter a polynomial in ``T − TREF`` (Horner), ``E`` with
``E_ii = θ_ppm·10⁻⁶`` and ``E_ij = θ_″·π/648000``, the 3×3 solve by the adjugate over the
determinant (no allocation, no library call; ``I + E`` is within 10⁻³ of the identity, so
the determinant is near 1).  Matches :func:`thermocal.turntable.thermal.correct`.

A gyro triad with a g-sensitivity ``A`` (``Triad.g_sensitivity``) takes a third input,

    void <p>_<triad>_correct(double temp_c, const <real> x[3], const <real> f[3], <real> out[3]);

``f`` the accelerometer triad's corrected output in its unit (the specific force; in g when
the calibration holds no accelerometer triad), and computes ``out = (I + E(T))⁻¹ (x − b(T) −
A f)`` with ``f`` converted to g, as :func:`thermocal.pipeline.compensate.compensate_triads`:
call the accelerometer's function first.

An accelerometer triad with second-order coefficients ``K2`` (``Triad.k2``) inverts
``x = (I + E(T)) a + b(T) + K2 ⊙ (a/g)²`` for ``a`` by the Newton steps of
:func:`thermocal.multipos.accel_k2.invert_k2` (as many, from the same linear start), in a
helper ``<p>_<triad>_solve3``; the signature is unchanged.

A triad calibrated on raw counts (``accel_scale``/``gyro_scale`` of the multi-position
calibration) takes ``x`` in its physical unit all the same; the header defines the count scale
``<P>_<TRIAD>_COUNT_SCALE`` (one count in that unit) and states the conversion
``x = <P>_<TRIAD>_COUNT_SCALE · counts`` that the caller applies to the raw registers first,
as :func:`thermocal.pipeline.compensate.compensate_triads` does.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from thermocal import __version__, units
from thermocal.errors import ThermocalInputError
from thermocal.export.c.core import CExport
from thermocal.identifiers import c_comment, c_identifier, c_names
from thermocal.turntable import model as tt_model


def _lit(x: float) -> str:
    return repr(float(x))


def _force(p: str, tri: Any, force_unit: str | None, real: str) -> tuple[list[str], str, str]:
    """A gyro triad's g-sensitivity in C: its constants (``A`` in the triad's unit per g and
    the factor from the force's unit to g), the extra parameter and the comment; nothing
    for a triad without one."""
    if tri.g_sensitivity is None:
        return [], "", ""
    to_g = float(units.convert([1.0], force_unit, "g")[0]) if force_unit else 1.0
    what = (
        f"the accelerometer triad's corrected output [{c_comment(force_unit)}]"
        if force_unit
        else "the specific force [g]"
    )
    rows = [
        "    {" + ", ".join(_lit(v) for v in row) + "},"
        for row in tri.g_sensitivity  # row: gyro axis; column: the force's axis
    ]
    consts = [
        f"/* g-sensitivity A [{c_comment(tri.unit)} per g]: row the gyro axis, column the "
        "specific force's */",
        f"static const double {p}_GSENS[3][3] = {{",
        *rows,
        "};",
        f"/* f: {what}; to g (9.80665 m/s^2) */",
        f"static const double {p}_FORCE_TO_G = {_lit(to_g)};",
    ]
    return consts, f", const {real} f[3]", f"; A f taken off first, f {what}"


def _gsens_term(p: str, i: int) -> str:
    """``- (A f)_i`` of row ``i`` (``f`` converted to g)."""
    return (
        f" - {p}_FORCE_TO_G * ({p}_GSENS[{i}][0] * (double)f[0] + {p}_GSENS[{i}][1] * "
        f"(double)f[1] + {p}_GSENS[{i}][2] * (double)f[2])"
    )


def _k2_consts(p: str, tri: Any) -> list[str]:
    """An accelerometer triad's K2 in C (in its unit per g²) and one g in its unit; nothing
    without one."""
    if getattr(tri, "k2", None) is None:
        return []
    g = float(units.convert([1.0], "g", tri.unit)[0])
    return [
        f"/* K2 [{c_comment(tri.unit)} per g^2] of x, y, z; one g (9.80665 m/s^2) in "
        f"{c_comment(tri.unit)} */",
        f"static const double {p}_K2[3] = {{{', '.join(_lit(v) for v in tri.k2)}}};",
        f"static const double {p}_G = {_lit(g)};",
    ]


def _solve3_code(name: str) -> list[str]:
    """A static ``out = m⁻¹ r`` (3×3, adjugate over the determinant) for the K2 inversion."""
    return [
        f"static void {name}_solve3(const double m[3][3], const double r[3], double out[3])",
        "{",
        "    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])",
        "        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])",
        "        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);",
        "    out[0] = ((m[1][1] * m[2][2] - m[1][2] * m[2][1]) * r[0]",
        "        - (m[0][1] * m[2][2] - m[0][2] * m[2][1]) * r[1]",
        "        + (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * r[2]) / det;",
        "    out[1] = (-(m[1][0] * m[2][2] - m[1][2] * m[2][0]) * r[0]",
        "        + (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * r[1]",
        "        - (m[0][0] * m[1][2] - m[0][2] * m[1][0]) * r[2]) / det;",
        "    out[2] = ((m[1][0] * m[2][1] - m[1][1] * m[2][0]) * r[0]",
        "        - (m[0][0] * m[2][1] - m[0][1] * m[2][0]) * r[1]",
        "        + (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * r[2]) / det;",
        "}",
        "",
    ]


def _k2_solve(name: str, p: str, real: str) -> list[str]:
    """The tail of a K2 triad's function: ``a`` from ``m a + K2 ⊙ (a/g)² = r`` by Newton
    (:func:`thermocal.multipos.accel_k2.invert_k2`), written to ``out``."""
    from thermocal.multipos.accel_k2 import NEWTON_STEPS

    return [
        f"    {name}_solve3((const double (*)[3])m, r, a);",
        f"    for (k = 0; k < {NEWTON_STEPS}; ++k) {{",
        "        double jac[3][3], res[3], d[3];",
        "        for (j = 0; j < 3; ++j) {",
        f"            double u = a[j] / {p}_G;",
        "            int i;",
        f"            res[j] = m[j][0] * a[0] + m[j][1] * a[1] + m[j][2] * a[2] + {p}_K2[j] * u * u"
        " - r[j];",
        "            for (i = 0; i < 3; ++i) jac[j][i] = m[j][i];",
        f"            jac[j][j] += 2.0 * {p}_K2[j] * u / {p}_G;",
        "        }",
        f"        {name}_solve3((const double (*)[3])jac, res, d);",
        "        for (j = 0; j < 3; ++j) a[j] -= d[j];",
        "    }",
        f"    out[0] = ({real})a[0];",
        f"    out[1] = ({real})a[1];",
        f"    out[2] = ({real})a[2];",
        "}",
    ]


def _triad_code(
    p: str, tri: Any, bias_to_data: float, real: str, ident: str, force_unit: str | None = None
) -> tuple[str, str]:
    """(declaration, definition) of one triad's correction function (``ident``: the triad's
    name through :func:`thermocal.identifiers.c_identifier`; ``force_unit`` the
    accelerometer triad's unit a gyro's g-sensitivity takes its force in, None: in g)."""
    m = tri.model
    name = f"{p}_{ident}"  # two identifiers of the gate joined by '_': an identifier
    label = c_comment(tri.name)
    bias_unit = "deg/h" if m.kind == "gyro" else "mg"
    P = name.upper()
    order = max(len(f.coef) for f in m.fits)
    consts, f_arg, f_about = _force(P, tri, force_unit, real)
    k2 = _k2_consts(P, tri)
    gs = [_gsens_term(P, i) if f_arg else "" for i in range(3)]
    rows = []
    for f in m.fits:
        c = [float(v) for v in f.coef] + [0.0] * (order - len(f.coef))
        rows.append(
            "    {"
            + ", ".join(_lit(v) for v in c)
            + "}, /* "
            + c_comment(f"{f.name} [{f.unit}]")
            + " */"
        )
    lines = [
        f"/* {label} triad: parameters as polynomials in (T - TREF), ascending powers */",
        f"static const double {P}_COEF[12][{order}] = {{",
        *rows,
        "};",
        f"static const double {P}_TREF = {_lit(m.tref_c)};",
        f"static const double {P}_T_LO = {_lit(m.t_lo_c)};",
        f"static const double {P}_T_HI = {_lit(m.t_hi_c)};",
        f"/* bias unit ({bias_unit}) to the data's unit ({c_comment(tri.unit)}) */",
        f"static const double {P}_BIAS_TO_DATA = {_lit(bias_to_data)};",
        *consts,
        *k2,
        "",
        *(_solve3_code(name) if k2 else []),
        f"void {name}_correct(double temp_c, const {real} x[3]{f_arg}, {real} out[3])",
        "{",
        f"    double t = temp_c < {P}_T_LO ? {P}_T_LO : (temp_c > {P}_T_HI ? {P}_T_HI : temp_c);",
        f"    double dt = t - {P}_TREF;",
        "    double th[12], m[3][3], r[3]" + (", a[3];" if k2 else ", det;"),
        "    int k, j;",
        "    for (k = 0; k < 12; ++k) {",
        f"        double acc = {P}_COEF[k][{order - 1}];",
        f"        for (j = {order - 2}; j >= 0; --j) acc = acc * dt"  # cli-words: C's --j
        f" + {P}_COEF[k][j];",
        "        th[k] = acc;",
        "    }",
        "    m[0][0] = 1.0 + th[3] * 1e-6;",
        "    m[1][1] = 1.0 + th[4] * 1e-6;",
        "    m[2][2] = 1.0 + th[5] * 1e-6;",
    ]
    for k, mis in enumerate(tt_model.MISALIGNMENT_NAMES):
        i, j = tt_model.MISALIGNMENT_INDEX[mis]
        lines.append(f"    m[{i}][{j}] = th[{6 + k}] * {_lit(units.ARCSEC_TO_RAD)}; /* {mis} */")
    lines += [
        f"    r[0] = (double)x[0] - th[0] * {P}_BIAS_TO_DATA{gs[0]};",
        f"    r[1] = (double)x[1] - th[1] * {P}_BIAS_TO_DATA{gs[1]};",
        f"    r[2] = (double)x[2] - th[2] * {P}_BIAS_TO_DATA{gs[2]};",
    ]
    if k2:
        lines += _k2_solve(name, P, real)
    else:
        lines += _linear_solve(real)
    formula = (
        "out = the a of x = (I + E(T)) a + b(T) + K2 (a/g)^2 (Newton steps)"
        if k2
        else f"out = (I + E(T))^-1 (x - b(T){' - A f' if f_arg else ''})"
    )
    about = c_comment(
        f"{tri.name}: {formula} in {tri.unit}{f_about}; columns "
        f"{', '.join(map(str, tri.columns))}; {_temperature_about(tri)}"
    )
    decl = f"/* {about} */\n"
    if tri.count_scale is not None:
        unit = c_comment(tri.unit)
        decl += (
            f"/* calibrated on raw counts: one count = {P}_COUNT_SCALE {unit}; convert the raw\n"
            f" * registers first, x[i] = {P}_COUNT_SCALE * counts[i] [{unit}] */\n"
            f"#define {P}_COUNT_SCALE {_lit(tri.count_scale)}\n"
        )
    decl += f"void {name}_correct(double temp_c, const {real} x[3]{f_arg}, {real} out[3]);"
    return decl, "\n".join(lines)


def _temperature_about(tri: Any) -> str:
    """The comment's words on the temperature the triad's function takes."""
    m = tri.model
    if tri.temperature:
        return f"T [degC] of {tri.temperature}, clamped to [{m.t_lo_c:g}, {m.t_hi_c:g}]"
    if m.order == 0:
        return (
            "no temperature column (none measured): the parameters apply unchanged at "
            "every temperature, temp_c has no effect"
        )
    return f"T [degC] (no column named), clamped to [{m.t_lo_c:g}, {m.t_hi_c:g}]"


def _linear_solve(real: str) -> list[str]:
    """The tail of a linear triad's function: ``out = m⁻¹ r`` inline."""
    return [
        "    det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])",
        "        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])",
        "        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);",
        f"    out[0] = ({real})(((m[1][1] * m[2][2] - m[1][2] * m[2][1]) * r[0]",
        "        - (m[0][1] * m[2][2] - m[0][2] * m[2][1]) * r[1]",
        "        + (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * r[2]) / det);",
        f"    out[1] = ({real})((-(m[1][0] * m[2][2] - m[1][2] * m[2][0]) * r[0]",
        "        + (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * r[1]",
        "        - (m[0][0] * m[1][2] - m[0][2] * m[1][0]) * r[2]) / det);",
        f"    out[2] = ({real})(((m[1][0] * m[2][1] - m[1][1] * m[2][0]) * r[0]",
        "        - (m[0][0] * m[2][1] - m[0][1] * m[2][0]) * r[1]",
        "        + (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * r[2]) / det);",
        "}",
    ]


def generate_c_triads(triads: Sequence[Any], *, prefix: str, real: str = "double") -> CExport:
    r"""The C module of a calibration's triads (module docstring).

    Parameters
    ----------
    triads : sequence of Triad
        The calibration's triads (name, unit, temperature model).
    prefix : str
        Prefix of the C identifiers and files.
    real : {"double", "float"}, optional
        C real type of ``x`` and ``out`` (default ``"double"``).

    Returns
    -------
    CExport
        Header and source with one ``<p>_<triad>_correct`` per triad.

    Raises
    ------
    ValueError
        When ``real`` is neither ``"double"`` nor ``"float"``.
    ThermocalInputError
        When two triads give one C name.

    Notes
    -----
    .. math:: \mathbf{out} = (I + E(T))^{-1}\,(\mathbf x - \mathbf b(T) - A \mathbf f)

    ``A f`` only for a gyro triad with a g-sensitivity (module docstring).

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    """
    if real not in ("double", "float"):
        raise ValueError("real must be double or float")
    p = c_identifier(prefix)
    used: dict[str, str] = {}
    decls, defs = [], []
    seen = {f"{p.upper()}_H": "the guard of the file"}
    accel = next((t for t in triads if t.model.kind == "accel"), None)
    for tri in triads:
        bias_unit = "deg/h" if tri.model.kind == "gyro" else "mg"
        factor = float(units.convert([1.0], bias_unit, tri.unit)[0])
        ident = c_identifier(tri.name, used, what="triad")
        d, f = _triad_code(p, tri, factor, real, ident, None if accel is None else accel.unit)
        for n in c_names(d + "\n" + f, f"{p}_{ident}"):
            if seen.setdefault(n, f"triad {tri.name!r}") != f"triad {tri.name!r}":
                raise ThermocalInputError(
                    f"triad {tri.name!r} and {seen[n]} both give the C name {n}; rename one"
                )
        decls.append(d)
        defs.append(f)
    guard = f"{p.upper()}_H"
    banner = (
        f"/*\n * Generated by thermocal {__version__} export-c from a calibration of triads. "
        "Do not edit.\n */\n"
    )
    header = (
        banner
        + f"#ifndef {guard}\n#define {guard}\n\n"
        + "\n\n".join(decls)
        + f"\n\n#endif /* {guard} */\n"
    )
    source = banner + f'#include "{p}.h"\n\n' + "\n\n".join(defs) + "\n"
    units_of = ",".join(t.unit for t in triads)
    return CExport(p, real, header, source, "triads", 1, unit=units_of, model_unit=units_of)


__all__ = ["generate_c_triads"]
