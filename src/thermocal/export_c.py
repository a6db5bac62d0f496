"""Plain C99 code computing a model's correction sample by sample (SPEC §8).

"Coefficients solidified in the IMU software": :func:`generate_c` turns a model
file's dict (:func:`thermocal.models.files.load_model_dict`) into a header and a
source file with

* no dynamic allocation, no library beyond ``<math.h>``-free C99 (``<stddef.h>``);
* the coefficients as ``static const`` arrays, the clamp range of every input;
* a state struct ``<p>_state`` and the functions::

      void    <p>_init(<p>_state *s, double sample_interval_s);
      <p>_real <p>_update(<p>_state *s, double time_s,
                          const <p>_real temps_c[<P>_N_TEMPS], <p>_real signal);
      <p>_real <p>_compensate(<p>_state *s, double time_s,
                              const <p>_real temps_c[<P>_N_TEMPS], <p>_real signal);
      void    <p>_set_known_input(<p>_state *s, <p>_real known_input);

  ``update`` returns the model value ŷ (the temperature-induced signal);
  ``compensate`` returns ``signal − ŷ``.  Signal, known input and results are in the
  data's own unit (the unit the model was fitted on as given, model file ``inputs``;
  ``--unit`` for another of the same kind, :func:`c_signal_unit`), named in every
  function's comment and in ``<P>_SIGNAL_UNIT``; the family arithmetic runs in the
  model's unit behind ``<P>_TO_MODEL_UNIT``.  ``temps_c`` are in the model's temperature
  unit (``<P>_TEMPERATURE_UNIT``: °C, or raw counts for a model fitted in counts); a model
  fitted on converted counts also gets ``<p>_temps_from_counts``.  ``init`` is a power-on (it
  forgets every state); ``sample_interval_s`` is the nominal sample interval τ:
  a time step longer than ``GAP_FACTOR`` (1.5) × τ resets the rate estimate, as
  in :class:`thermocal.compensate.StreamingCompensator`;
* a comment block with the model file's identity (family, format version,
  thermocal version, checksum, signal, temperatures, data files).

The arithmetic follows the family's ``ModelStream`` operation by operation, so
the double build agrees with the Python streaming compensator to rounding
(tests: 1e-9 relative on 10⁵ samples with cc -O2 -std=c99).  Time is ``double``
in both builds; ``--float`` makes every other quantity ``float`` and its
worst-case error against double is measured (:func:`measure_float_error`).
Temperatures are always clamped to the fitted range (the Python default,
``extrapolate=False``).

Families register a generator in :data:`GENERATORS` (STYLE rule 8): ``poly``,
``piecewise`` (both methods), ``warmup``, ``bank``; each reads the ``state`` layout
documented in its module docstring and emits only the constants, state and
parameters the model uses, so the module builds with ``-Wall -Wextra -Werror``
(e.g. a poly model without rate terms has no rate buffer or rate constants).
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import ModelFileError, ThermocalInputError, UnitError
from thermocal.recording import GAP_FACTOR, FloatArray

REAL_TYPES = ("double", "float")


# --- the generated module -------------------------------------------------------------------


@dataclass(frozen=True)
class FamilyCode:
    """What a family generator contributes to the common skeleton.

    ``state_fields`` — C declarations inside the state struct (one per line);
    ``data`` — ``static const`` definitions and static helper functions (source file);
    ``init`` — statements of ``<p>_init`` (``s`` and ``sample_interval_s`` in scope);
    ``update`` — statements of ``<p>_update`` ending in ``return``;
    ``defines`` — extra ``#define`` lines of the header; ``notes`` — comment lines.
    """

    state_fields: list[str]
    data: str
    init: str
    update: str
    defines: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class CExport:
    """A generated C module: ``header`` (``<prefix>.h``) and ``source`` (``<prefix>.c``)."""

    prefix: str
    real: str
    header: str
    source: str
    family: str
    n_temps: int
    unit: str = ""
    """Unit of the functions' signal and results (:func:`c_signal_unit`)."""
    model_unit: str = ""
    """The model's own unit, in which the family arithmetic runs."""
    temperature_unit: str = "degC"

    @property
    def header_name(self) -> str:
        return f"{self.prefix}.h"

    @property
    def source_name(self) -> str:
        return f"{self.prefix}.c"

    def write(self, directory: str | Path) -> list[Path]:
        """Write header and source into ``directory`` (atomically); returns the paths."""
        from thermocal.errors import ThermocalInputError
        from thermocal.io import atomic_write

        d = Path(directory)
        if d.exists() and not d.is_dir():
            raise ThermocalInputError(f"{d}: exists and is not a directory (-o names a directory)")
        try:
            d.mkdir(parents=True, exist_ok=True)
        except (FileExistsError, NotADirectoryError):
            raise ThermocalInputError(f"{d}: cannot create the output directory") from None
        out = []
        for name, text in ((self.header_name, self.header), (self.source_name, self.source)):
            with atomic_write(d / name, "w") as fh:
                fh.write(text)
            out.append(d / name)
        return out


@dataclass(frozen=True)
class ExportContext:
    """What a family generator gets: the model dict, the C prefix and helpers."""

    model: dict[str, Any]
    prefix: str
    real: str
    rate_buffer_len: int

    @property
    def P(self) -> str:
        """The C macro prefix (upper case)."""
        return self.prefix.upper()

    @property
    def r(self) -> str:
        """The C real type name."""
        return f"{self.prefix}_real"

    def lit(self, x: float) -> str:
        """A C literal of the real type (17 significant digits, ``f`` suffix for float)."""
        if not math.isfinite(x):
            raise ModelFileError(f"non-finite coefficient {x!r} cannot be exported")
        s = repr(float(x))
        if "e" not in s and "." not in s and "inf" not in s:
            s += ".0"
        return s + ("f" if self.real == "float" else "")

    def array(self, name: str, values: Sequence[float] | npt.ArrayLike) -> str:
        """``static const <real> NAME[n] = {…};`` (1-D)."""
        v = np.asarray(values, dtype=np.float64).ravel()
        body = ",\n    ".join(
            ", ".join(self.lit(x) for x in v[i : i + 4]) for i in range(0, v.size, 4)
        )
        return (
            f"static const {self.r} {name}[{max(v.size, 1)}] = {{\n    {body or self.lit(0.0)}\n}};"
        )

    def array2(self, name: str, values: npt.ArrayLike) -> str:
        """``static const <real> NAME[a][b] = {{…}, …};``."""
        m = np.asarray(values, dtype=np.float64)
        rows = ",\n    ".join("{" + ", ".join(self.lit(x) for x in row) + "}" for row in m)
        return f"static const {self.r} {name}[{m.shape[0]}][{m.shape[1]}] = {{\n    {rows}\n}};"

    @property
    def tu(self) -> str:
        """The model's temperature unit in comments: ``degC`` or ``counts``."""
        return str(self.model.get("temperature_unit") or units.LEGACY_TEMPERATURE_UNIT)

    def temp_range(self) -> FloatArray:
        """(k, 2) fitted temperature range [°C or counts] in the model's temperature order."""
        tr = self.model["range"]["temperature_c"]
        return np.array([tr[n] for n in self.model["temperatures"]], dtype=np.float64)

    def clamp_arrays(self) -> str:
        rng = self.temp_range()
        return "\n".join(
            [
                f"/* fitted temperature range [{self.tu}]: inputs are clamped to it */",
                self.array(f"{self.P}_T_LO", rng[:, 0]),
                self.array(f"{self.P}_T_HI", rng[:, 1]),
            ]
        )


Generator = Callable[[ExportContext], FamilyCode]

GENERATORS: dict[str, Generator] = {}
"""C generators by model family (STYLE rule 8)."""


def register_generator(family: str) -> Callable[[Generator], Generator]:
    """Decorator: register the C generator of a family."""

    def deco(fn: Generator) -> Generator:
        GENERATORS[family] = fn
        return fn

    return deco


# --- common skeleton ----------------------------------------------------------------------


def c_identifier(text: str) -> str:
    """A valid C identifier from a file stem (``rlg poly-v2`` → ``rlg_poly_v2``)."""
    s = re.sub(r"[^0-9A-Za-z_]", "_", text).strip("_").lower() or "model"
    if s[0].isdigit():
        s = "m_" + s
    return s


def _identity(d: dict[str, Any]) -> list[str]:
    sig = d.get("signal") or {}
    lines = [
        "Generated by thermocal export-c from a thermocal model file. Do not edit.",
        f"family:            {d.get('family')}",
        f"format:            {d.get('format')} version {d.get('format_version')}",
        f"thermocal version: {d.get('thermocal_version')}",
        f"created (UTC):     {d.get('created_utc')}",
        f"checksum (sha256): {d.get('checksum')}",
        f"signal:            {sig.get('name')} [{sig.get('unit')}], target {sig.get('target')}",
        f"temperatures:      {', '.join(d.get('temperatures', []))} "
        f"[{d.get('temperature_unit') or units.LEGACY_TEMPERATURE_UNIT}]",
    ]
    inputs = d.get("inputs") or {}
    if inputs.get("units"):
        given = ", ".join(f"{k} [{v}]" for k, v in inputs["units"].items())
        lines.append(f"fitted data:       {given}")
    for name, conv in (inputs.get("temperature_conversion") or {}).items():
        lines.append(f"conversion {name}: {units.temperature_conversion(conv).describe()}")
    known = inputs.get("known_input")
    if isinstance(known, dict) and known.get("value"):
        lines.append(
            f"known input:       {known.get('value')} {known.get('unit')} removed before the "
            f"fit ({known.get('what')})"
        )
    rate = d.get("rate")
    if rate:
        lines.append(f"temperature rate:  {rate.get('method')} over {rate.get('interval_s')} s")
    for entry in d.get("data") or []:
        if isinstance(entry, dict) and entry.get("file"):
            lines.append(f"fitted on:         {entry.get('file')}")
    return [ln.replace("*/", "* /") for ln in lines]


def _comment(lines: Sequence[str]) -> str:
    return "/*\n" + "\n".join(f" * {ln}".rstrip() for ln in lines) + "\n */"


def c_signal_unit(model: dict[str, Any], unit: str | None = None) -> tuple[str, float]:
    """The unit the generated functions take ``signal`` and return values in, and the factor
    ``f`` with ``value[model unit] = f · value[that unit]``.

    ``unit`` (``--unit``) else the unit the model was fitted on as given (model file
    ``inputs.units``, e.g. ``deg/s``), else the model's own unit (older files, raw-count
    data).  A unit of another kind than the model's, or ``counts``, is a :class:`UnitError`.
    """
    mu = units.normalize_signal_unit(str((model.get("signal") or {}).get("unit")))
    if unit is None:
        given = ((model.get("inputs") or {}).get("units") or {}).get(
            (model.get("signal") or {}).get("name")
        )
        ok = given and units.signal_kind(str(given)) == units.signal_kind(mu)
        unit = str(given) if ok else mu
    u = units.normalize_signal_unit(unit)
    if u != mu and (units.signal_kind(u) == "raw" or units.signal_kind(mu) == "raw"):
        raise UnitError(
            f"export-c --unit {u}: raw counts need the scale factor, the model is in {mu}; "
            "give a physical unit of the model's kind"
        )
    return u, float(units.convert(1.0, u, mu))


def _temperature_from_counts(model: dict[str, Any], p: str, P: str) -> tuple[list[str], str]:
    """Header declaration and source of ``<p>_temps_from_counts`` when every model
    temperature has a counts → °C conversion recorded (the firmware reads counts)."""
    conv_raw = (model.get("inputs") or {}).get("temperature_conversion") or {}
    names = list(model["temperatures"])
    if (model.get("temperature_unit") or units.LEGACY_TEMPERATURE_UNIT) != "degC" or not all(
        n in conv_raw for n in names
    ):
        return [], ""
    convs = [units.temperature_conversion(conv_raw[n]) for n in names]
    decl = [
        "/* Raw ADC temperature counts -> temps_c [degC] as fitted: T = gain*v + offset, v the",
        "   count (int16: signed 16-bit stored unsigned, v >= 32768 -> v - 65536 first). */",
        f"void {p}_temps_from_counts(const double counts[{P}_N_TEMPS], "
        f"{p}_real temps_c[{P}_N_TEMPS]);",
    ]
    body = [
        f"void {p}_temps_from_counts(const double counts[{P}_N_TEMPS], "
        f"{p}_real temps_c[{P}_N_TEMPS])",
        "{",
        "    double v;",
    ]
    for i, (n, c) in enumerate(zip(names, convs, strict=True)):
        enc = ", int16" if c.encoding == "int16" else ""
        label = n.replace("*/", "* /")
        body.append(f"    v = counts[{i}]; /* {label}: T = {c.gain!r} * v + {c.offset!r}{enc} */")
        if c.encoding == "int16":
            body.append(f"    if (v >= {units.INT16_SIGN_BIT!r}) {{")
            body.append(f"        v -= {units.UINT16_MODULUS!r};")
            body.append("    }")
        body.append(f"    temps_c[{i}] = ({p}_real)(v * {float(c.gain)!r} + {float(c.offset)!r});")
    body.append("}")
    return decl, "\n".join(body)


def generate_c(
    model: dict[str, Any],
    *,
    prefix: str = "thermocal_model",
    real: str = "double",
    sample_interval_s: float = 1.0,
    unit: str | None = None,
) -> CExport:
    """Generate the C99 header and source of a model dict (see the module docstring).

    ``sample_interval_s`` is only used to size the Ṫ ring buffer of rate models
    (``<P>_RATE_BUF_LEN`` = ⌈Δt/τ⌉ + 8, overridable with ``-D``); the interval used at
    run time is the argument of ``<p>_init``.  ``unit`` is the signal unit of the
    functions (:func:`c_signal_unit`: by default the unit the model was fitted on as
    given); the family code runs in the model's unit and ``<p>_update`` converts its
    input and output with ``<P>_TO_MODEL_UNIT``.
    """
    if real not in REAL_TYPES:
        raise ThermocalInputError(f"real type must be one of {REAL_TYPES}, got {real!r}")
    fam = str(model.get("family"))
    gen = GENERATORS.get(fam)
    if gen is None:
        raise ModelFileError(
            f"no C generator for model family {fam!r}; available: {', '.join(sorted(GENERATORS))}"
        )
    if not sample_interval_s > 0:
        raise ThermocalInputError(f"sample interval must be positive, got {sample_interval_s}")
    p = c_identifier(prefix)
    rate = model.get("rate") or {}
    interval = float(rate.get("interval_s") or 0.0)
    buf = math.ceil(interval / sample_interval_s) + 8 if interval > 0 else 2
    ctx = ExportContext(model=model, prefix=p, real=real, rate_buffer_len=buf)
    code = gen(ctx)
    P = ctx.P
    k = len(model["temperatures"])
    guard = f"{P}_H"
    ident = _identity(model)
    su, factor = c_signal_unit(model, unit)
    mu = units.normalize_signal_unit(str(model["signal"]["unit"]))
    tu = ctx.tu
    convert = factor != 1.0
    conv_decl, conv_src = _temperature_from_counts(model, p, P)
    unit_defines = [
        f'#define {P}_SIGNAL_UNIT "{su}" /* unit of signal, known_input and every result */',
        f'#define {P}_TEMPERATURE_UNIT "{tu}" /* unit of temps_c[] */',
    ]
    if convert:
        unit_defines.append(
            f"#define {P}_TO_MODEL_UNIT {ctx.lit(factor)} /* [{mu}] per [{su}]: the model "
            f"runs in {mu} */"
        )
    header = "\n".join(
        [
            _comment(
                [
                    *ident,
                    f"C functions: signal and results in [{su}], temps_c in [{tu}]",
                    "",
                    *code.notes,
                ]
            ),
            f"#ifndef {guard}",
            f"#define {guard}",
            "",
            f"typedef {real} {p}_real;",
            "",
            f"#define {P}_N_TEMPS {k}",
            f"#define {P}_GAP_FACTOR {GAP_FACTOR!r}",
            *unit_defines,
            *code.defines,
            "",
            f"/* temperature order of temps_c[] [{tu}]: "
            + ", ".join(f"{i}={n}" for i, n in enumerate(model["temperatures"]))
            + " */",
            "",
            "typedef struct {",
            "    double sample_interval_s;",
            f"    {p}_real known_input; /* [{mu}] */",
            *[f"    {f}" for f in code.state_fields],
            f"}} {p}_state;",
            "",
            "/* Power-on: forget every state. sample_interval_s = nominal interval [s]. */",
            f"void {p}_init({p}_state *s, double sample_interval_s);",
            f"/* Known input [{su}] (earth rate, gravity component) removed from the signal the",
            "   model sees (start-up selection); default 0. */",
            f"void {p}_set_known_input({p}_state *s, {p}_real known_input);",
            f"/* Model value [{su}] (temperature-induced signal) of one sample: time_s [s],",
            f"   temps_c [{tu}], signal [{su}]. */",
            f"{p}_real {p}_update({p}_state *s, double time_s, "
            f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal);",
            f"/* Compensated output [{su}]: signal [{su}] - model value. */",
            f"{p}_real {p}_compensate({p}_state *s, double time_s, "
            f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal);",
            *conv_decl,
            "",
            f"#endif /* {guard} */",
            "",
        ]
    )
    model_fn = f"{p}_update_{c_identifier(mu)}" if convert else f"{p}_update"
    model_fn_head = (
        [
            f"/* Model value [{mu}] of one sample, signal [{mu}]: the family's arithmetic. */",
            f"static {p}_real {model_fn}({p}_state *s, double time_s, "
            f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal)",
        ]
        if convert
        else [
            f"/* Model value [{su}] of one sample: temps_c [{tu}], signal [{su}]. */",
            f"{p}_real {p}_update({p}_state *s, double time_s, "
            f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal)",
        ]
    )
    wrapper = (
        [
            "",
            f"/* Model value [{su}] of one sample: temps_c [{tu}], signal [{su}]. */",
            f"{p}_real {p}_update({p}_state *s, double time_s, "
            f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal)",
            "{",
            f"    return {model_fn}(s, time_s, temps_c, signal * {P}_TO_MODEL_UNIT) "
            f"/ {P}_TO_MODEL_UNIT;",
            "}",
        ]
        if convert
        else []
    )
    ki = f"known_input * {P}_TO_MODEL_UNIT" if convert else "known_input"
    source = "\n".join(
        [
            _comment(ident[:1] + ident[1:3] + ident[5:6]),
            f'#include "{p}.h"',
            "",
            f"static {p}_real {p}_clamp({p}_real x, {p}_real lo, {p}_real hi)",
            "{",
            "    return x < lo ? lo : (x > hi ? hi : x);",
            "}",
            "",
            code.data,
            "",
            f"void {p}_init({p}_state *s, double sample_interval_s)",
            "{",
            "    s->sample_interval_s = sample_interval_s;",
            f"    s->known_input = {ctx.lit(0.0)};",
            _indent(code.init),
            "}",
            "",
            f"/* known_input [{su}], kept in [{mu}] */",
            f"void {p}_set_known_input({p}_state *s, {p}_real known_input)",
            "{",
            f"    s->known_input = {ki};",
            "}",
            "",
            *model_fn_head,
            "{",
            _indent(code.update),
            "}",
            *wrapper,
            "",
            f"/* Compensated output [{su}]: signal [{su}] - model value [{su}]. */",
            f"{p}_real {p}_compensate({p}_state *s, double time_s, "
            f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal)",
            "{",
            f"    return signal - {p}_update(s, time_s, temps_c, signal);",
            "}",
            "",
            *([conv_src, ""] if conv_src else []),
        ]
    )
    return CExport(
        prefix=p,
        real=real,
        header=header,
        source=source,
        family=fam,
        n_temps=k,
        unit=su,
        model_unit=mu,
        temperature_unit=tu,
    )


def _indent(text: str, n: int = 4) -> str:
    pad = " " * n
    return "\n".join(pad + ln if ln.strip() else "" for ln in text.strip("\n").splitlines())


# --- families: poly --------------------------------------------------------------------------


def _rate_buffer_code(ctx: ExportContext) -> tuple[list[str], str, str]:
    """State fields, init and update code of the backward-difference Ṫ (SPEC §3, seed 000):
    a ring buffer of the raw temperatures of the last Δt of the current contiguous
    segment; ``Ṫ = (T − T_lo)/(t − t_lo)·60`` [°C/min] with ``t_lo`` the oldest buffered
    time ≥ t − Δt, 0 at a segment's first sample; a step > GAP_FACTOR·τ clears the buffer.
    Fills ``rate[k]``."""
    P, r = ctx.P, ctx.r
    fields = [
        f"double buf_t[{P}_RATE_BUF_LEN];",
        f"{r} buf_T[{P}_RATE_BUF_LEN][{P}_N_TEMPS];",
        "int buf_head; /* index of the oldest sample */",
        "int buf_n;    /* samples in the buffer */",
        "int have_last;",
        "double last_t;",
    ]
    init = """
s->buf_head = 0;
s->buf_n = 0;
s->have_last = 0;
s->last_t = 0.0;
"""
    update = f"""
/* backward temperature rate [{ctx.tu}/min] from the raw temperatures */
if (s->have_last && time_s - s->last_t > {P}_GAP_FACTOR * s->sample_interval_s) {{
    s->buf_n = 0; /* a gap: new contiguous segment */
}}
s->have_last = 1;
s->last_t = time_s;
{{
    int slot;
    if (s->buf_n == {P}_RATE_BUF_LEN) {{ /* full: sampling faster than sized for */
        s->buf_head = (s->buf_head + 1) % {P}_RATE_BUF_LEN;
        s->buf_n -= 1;
    }}
    slot = (s->buf_head + s->buf_n) % {P}_RATE_BUF_LEN;
    s->buf_t[slot] = time_s;
    for (i = 0; i < {P}_N_TEMPS; ++i) {{
        s->buf_T[slot][i] = temps_c[i];
    }}
    s->buf_n += 1;
}}
while (s->buf_t[s->buf_head] < time_s - {P}_RATE_INTERVAL_S) {{
    s->buf_head = (s->buf_head + 1) % {P}_RATE_BUF_LEN;
    s->buf_n -= 1;
}}
{{
    double span = time_s - s->buf_t[s->buf_head];
    for (i = 0; i < {P}_N_TEMPS; ++i) {{
        if (span > 0.0) {{
            rate[i] = (temps_c[i] - s->buf_T[s->buf_head][i]) / ({r})span * {ctx.lit(60.0)};
        }} else {{
            rate[i] = {ctx.lit(0.0)};
        }}
    }}
}}
"""
    return fields, init, update


@register_generator("poly")
def _gen_poly(ctx: ExportContext) -> FamilyCode:
    """Polynomial model (SPEC §4a, models/poly.py docstring steps 1–4 and ``PolyStream``):
    Ṫ from the raw temperatures, clamp T and Ṫ (rate sensors) to the fitted ranges,
    ``u = (T − c_T)/s_T``, ``v = (Ṫ − c_R)/s_R``, ``w = (T·Ṫ − c_W)/s_W``,
    ``y = Σ_j coef_j u^a v^b w^c + constant`` (powers by repeated multiplication)."""
    d = ctx.model
    st = d["state"]
    if st.get("layout") != "thermocal-poly-1":
        raise ModelFileError(f"poly state layout {st.get('layout')!r} is not thermocal-poly-1")
    P, r, p = ctx.P, ctx.r, ctx.prefix
    base = st["base"]
    terms = st["terms"]
    coef = np.asarray(st["coef"], dtype=np.float64)
    uses_rate = bool(st.get("uses_rate"))
    rate = st.get("rate") or {}
    if uses_rate and rate.get("method", "backward") != "backward":
        raise ModelFileError(
            f"poly model uses the {rate.get('method')!r} rate form; only the causal "
            "'backward' form can run sample by sample"
        )
    rate_sensors = sorted(
        {int(t["sensor"]) for t in terms if t["rate_power"] or t["coupling_power"]}
    )
    t_sensors = sorted({int(t["sensor"]) for t in terms if t["t_power"]})
    w_sensors = sorted({int(t["sensor"]) for t in terms if t["coupling_power"]})
    v_sensors = sorted({int(t["sensor"]) for t in terms if t["rate_power"]})

    def col(key: str) -> list[float]:
        return [float(b[key]) for b in base]

    # only the arrays the terms use: -Wall -Wextra -Werror rejects unused static consts
    needs_t = bool(t_sensors or w_sensors)  # clamped T used by u or w
    if needs_t:
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
        (t_sensors, "T", "t_center", "t_scale", "u"),
        (v_sensors, "R", "rate_center", "rate_scale", "v"),
        (w_sensors, "W", "coupling_center", "coupling_scale", "w"),
    ]
    for sensors, tag, c_key, s_key, var in used:
        if sensors:
            data += [
                f"/* centre and scale of the base variable {var} of every sensor */",
                ctx.array(f"{P}_{tag}_CENTER", col(c_key)),
                ctx.array(f"{P}_{tag}_SCALE", col(s_key)),
            ]
    if terms:
        data += [
            f"/* coefficients of the {len(terms)} terms [signal unit] */",
            ctx.array(f"{P}_COEF", coef),
        ]
    data.append("/* constant [signal unit] */")
    data.append(f"static const {r} {P}_CONSTANT = {ctx.lit(float(st['constant']))};")
    rr: dict[str, list[float]] = (d.get("range") or {}).get("rate_c_per_min") or {}
    clamp_rate = uses_rate and bool(rr) and bool(rate.get("clamp", True))
    if clamp_rate:
        rng = np.array([rr[n] for n in d["temperatures"]], dtype=np.float64)
        data += [
            f"/* fitted temperature-rate range [{ctx.tu}/min]: rates of the rate sensors are "
            "clamped */",
            ctx.array(f"{P}_R_LO", rng[:, 0]),
            ctx.array(f"{P}_R_HI", rng[:, 1]),
        ]
    defines = [f"#define {P}_N_TERMS {len(terms)}"]
    notes = [
        f"Polynomial model (SPEC 4a): {len(terms)} terms + constant in the centred and scaled",
        "base variables u = (T - c_T)/s_T, v = (dT - c_R)/s_R, w = (T dT - c_W)/s_W",
        f"(dT = backward difference over the rate interval, {ctx.tu}/min). Inputs are clamped",
        "to the fitted temperature (and rate) range. Call init at power-on.",
    ]
    if not terms:
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
    upd = [f"{r} T[{P}_N_TEMPS];"] if needs_t else []
    upd += [f"{r} acc = {ctx.lit(0.0)};", "int i;"]
    if uses_rate:
        interval = float(rate.get("interval_s", 60.0))
        defines += [
            f"#define {P}_RATE_INTERVAL_S {interval!r}",
            "/* ring buffer of the rate: >= samples in RATE_INTERVAL_S + 1 */",
            f"#ifndef {P}_RATE_BUF_LEN",
            f"#define {P}_RATE_BUF_LEN {ctx.rate_buffer_len}",
            "#endif",
        ]
        fields, init, rate_update = _rate_buffer_code(ctx)
        upd += [f"{r} rate[{P}_N_TEMPS];", rate_update.strip("\n")]
    if not uses_rate:
        upd += ["(void)s; /* memoryless without rate terms */", "(void)time_s;"]
    upd.append("(void)signal;")
    if needs_t:
        upd += [
            "for (i = 0; i < " + f"{P}_N_TEMPS; ++i) {{",
            f"    T[i] = {p}_clamp(temps_c[i], {P}_T_LO[i], {P}_T_HI[i]);",
            "}",
        ]
    if clamp_rate:
        for j in rate_sensors:
            upd.append(f"rate[{j}] = {p}_clamp(rate[{j}], {P}_R_LO[{j}], {P}_R_HI[{j}]);")
    for j in t_sensors:
        upd.append(f"const {r} u{j} = (T[{j}] - {P}_T_CENTER[{j}]) / {P}_T_SCALE[{j}];")
    for j in v_sensors:
        upd.append(f"const {r} v{j} = (rate[{j}] - {P}_R_CENTER[{j}]) / {P}_R_SCALE[{j}];")
    for j in w_sensors:
        upd.append(f"const {r} w{j} = (T[{j}] * rate[{j}] - {P}_W_CENTER[{j}]) / {P}_W_SCALE[{j}];")

    def power(x: str, n: int) -> str:
        out = x
        for _ in range(n - 1):
            out = f"({out} * {x})"
        return out

    for i, t in enumerate(terms):
        j = int(t["sensor"])
        factors = [
            power(f"{var}{j}", int(t[key]))
            for var, key in (("u", "t_power"), ("v", "rate_power"), ("w", "coupling_power"))
            if int(t[key])
        ]
        val = factors[0]
        for fct in factors[1:]:
            val = f"({val} * {fct})"
        label = str(t.get("name", "")).replace("*/", "* /")
        upd.append(f"acc += {val} * {P}_COEF[{i}]; /* {label} */")
    upd.append(f"return acc + {P}_CONSTANT;")
    return FamilyCode(
        state_fields=fields or ["int unused; /* no state */"],
        data="\n".join(data),
        init=init or "s->unused = 0;",
        update="\n".join(upd),
        defines=defines,
        notes=notes,
    )


# --- families: piecewise ---------------------------------------------------------------------


@register_generator("piecewise")
def _gen_piecewise(ctx: ExportContext) -> FamilyCode:
    """Piecewise-linear model (SPEC §4b, models/piecewise.py eq. 1 and ``PiecewiseStream``):

    ``T = clamp(T_in)`` to the fitted range; ``j`` = number of breakpoints ``≤ T``;
    ``y = intercepts[j] + slopes[j]·T``.  Both methods (``intersect``, ``continuous``)
    store their lines in this form, so one generator serves both; a discontinuous
    ``intersect`` model (lines that do not meet) jumps at the kept breakpoint exactly
    as in Python.  Memoryless: the state struct only holds the common fields.
    """
    d = ctx.model
    st = d["state"]
    if st.get("layout") != "thermocal-piecewise-1":
        raise ModelFileError(
            f"piecewise state layout {st.get('layout')!r} is not thermocal-piecewise-1"
        )
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
    unit = str((d.get("signal") or {}).get("unit") or "signal unit").replace("*/", "* /")
    n_b = int(bps.size)
    data = [
        ctx.clamp_arrays(),
        f"/* line j: y = A[j] + S[j] * T for BP[j-1] <= T < BP[j] ({st.get('method')} method);",
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
            f"#define {P}_TEMP_INDEX {k} /* temps_c[] entry the model uses ({used}) */",
        ],
        notes=[
            f"Piecewise-linear model (SPEC 4b, {st.get('method')} method) in {used} [{ctx.tu}]:",
            "y = A[j] + S[j] T, j = number of breakpoints <= T; T clamped to the fitted range.",
            "Memoryless; call init once before use.",
        ],
    )


# --- families: warmup --------------------------------------------------------------------------


@register_generator("warmup")
def _gen_warmup(ctx: ExportContext) -> FamilyCode:
    """Warm-up model (SPEC §4c, models/warmup.py ``WarmupStream``):

    T = clamp(T_in); during ``t − t_first < W``: T0 = running mean of T; then frozen;
    a_j = Σ_k b_jk clamp(T0)^k (Horner), ΔF = Σ_j a_j (T − T0)^j (Horner).
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
            f"/* b[j][k]: coefficient of dT^j * T0^k [{ctx.model['signal']['unit']}/"
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
"""
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
            "Warm-up model (SPEC 4c): dF = sum_j a_j(T0) dT^j, a_j(T0) = sum_k b_jk T0^k,",
            f"T0 = running mean of the temperature over the first {window:g} s after power-on.",
            "Call init at power-on.",
        ],
    )


# --- families: bank --------------------------------------------------------------------------


@register_generator("bank")
def _gen_bank(ctx: ExportContext) -> FamilyCode:
    """Model bank (SPEC §4d, models/bank.py ``BankStream``): every piecewise-linear model
    evaluated at the clamped T; during ``t − t_first < startup_s`` the residual sums
    ``Σ (y − f_m)`` pick ``argmin_m |Σ_m/N|``; then the choice is frozen."""
    st = ctx.model["state"]
    models = st["models"]
    P, r, p = ctx.P, ctx.r, ctx.prefix
    m = len(models)
    bps = [np.asarray(mm["breakpoints_c"], dtype=np.float64) for mm in models]
    vals = [np.asarray(mm["values"], dtype=np.float64) for mm in models]
    offsets = np.cumsum([0] + [b.size for b in bps])
    data = "\n".join(
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
    init = f"""
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
    update = f"""
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
    return FamilyCode(
        state_fields=[
            "int started;",
            "double t_first;",
            f"{r} sums[{P}_N_MODELS];",
            "long count;",
            "int frozen;",
            "int choice; /* index of the selected model */",
        ],
        data=data,
        init=init,
        update=update,
        defines=[f"#define {P}_N_MODELS {m}"],
        notes=[
            "Model bank (SPEC 4d): one piecewise-linear model per characteristic curve,",
            f"selected during the first {float(st['startup_s']):g} s after power-on by the",
            "smallest |mean(signal - known_input - model)|; pass the raw signal to update.",
        ],
    )


# --- compile and run (tests, float error) -----------------------------------------------------


def c_harness(export: CExport) -> str:
    """A small C main: reads ``n`` then ``n`` records of doubles ``(t, T_1..T_k, F)`` from
    a binary file (argv[1]), calls ``init(τ = argv[3])`` and ``update`` on each sample and
    writes the model values as doubles to argv[2]."""
    p, P, r = export.prefix, export.prefix.upper(), f"{export.prefix}_real"
    return f"""#include <stdio.h>
#include <stdlib.h>
#include "{p}.h"

int main(int argc, char **argv)
{{
    FILE *in, *out;
    long n, i;
    double rec[{P}_N_TEMPS + 2];
    {r} temps[{P}_N_TEMPS];
    {p}_state st;
    int j;
    if (argc < 4) {{
        return 2;
    }}
    in = fopen(argv[1], "rb");
    out = fopen(argv[2], "wb");
    if (in == NULL || out == NULL) {{
        return 2;
    }}
    if (fread(&n, sizeof n, 1, in) != 1) {{
        return 2;
    }}
    {p}_init(&st, atof(argv[3]));
    if (argc > 4) {{
        {p}_set_known_input(&st, ({r})atof(argv[4]));
    }}
    for (i = 0; i < n; ++i) {{
        double y;
        if (fread(rec, sizeof(double), {P}_N_TEMPS + 2, in) != {P}_N_TEMPS + 2) {{
            return 3;
        }}
        for (j = 0; j < {P}_N_TEMPS; ++j) {{
            temps[j] = ({r})rec[1 + j];
        }}
        y = (double){p}_update(&st, rec[0], temps, ({r})rec[{P}_N_TEMPS + 1]);
        fwrite(&y, sizeof y, 1, out);
    }}
    fclose(in);
    fclose(out);
    return 0;
}}
"""


CFLAGS = ("-O2", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")


def find_compiler() -> str | None:
    """The system C compiler (``cc``, ``gcc`` or ``clang``), or None."""
    for name in ("cc", "gcc", "clang"):
        path = shutil.which(name)
        if path:
            return path
    return None


def compile_harness(export: CExport, directory: str | Path, compiler: str | None = None) -> Path:
    """Write the module and :func:`c_harness` into ``directory`` and compile them with
    ``cc -O2 -std=c99 -Wall -Wextra -Werror -pedantic``; returns the executable."""
    cc = compiler or find_compiler()
    if cc is None:
        raise ThermocalInputError("no C compiler (cc, gcc or clang) found")
    d = Path(directory)
    export.write(d)
    main = d / f"{export.prefix}_main.c"
    main.write_text(c_harness(export))
    exe = d / f"{export.prefix}_run"
    cmd = [cc, *CFLAGS, "-o", str(exe), str(d / export.source_name), str(main)]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"C compilation failed: {' '.join(cmd)}\n{proc.stderr}")
    return exe


def run_harness(
    exe: str | Path,
    time_s: npt.ArrayLike,
    temps_c: npt.ArrayLike,
    signal: npt.ArrayLike,
    sample_interval_s: float,
    *,
    known_input: float = 0.0,
) -> FloatArray:
    """Run a compiled harness on samples; returns the model values (n,)."""
    t = np.asarray(time_s, dtype=np.float64)
    T = np.asarray(temps_c, dtype=np.float64).reshape(t.size, -1)
    f = np.asarray(signal, dtype=np.float64)
    rec = np.column_stack([t, T, f])
    with tempfile.TemporaryDirectory() as tmp:
        fin = Path(tmp) / "in.bin"
        fout = Path(tmp) / "out.bin"
        with open(fin, "wb") as fh:
            fh.write(np.int64(t.size).tobytes())
            fh.write(np.ascontiguousarray(rec).tobytes())
        proc = subprocess.run(
            [
                str(exe),
                str(fin),
                str(fout),
                repr(float(sample_interval_s)),
                repr(float(known_input)),
            ],
            capture_output=True,
            check=False,
        )
        if proc.returncode != 0:
            raise RuntimeError(f"C harness failed with status {proc.returncode}")
        return np.fromfile(fout, dtype=np.float64)


def exercise_inputs(
    model: dict[str, Any],
    n: int = 100_000,
    sample_interval_s: float = 1.0,
    seed: int = 0,
    *,
    gap_at: float = 0.6,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Synthetic samples over a model's fitted range, power-on included: every
    temperature channel sweeps its fitted range ±10 % (triangle waves of different
    periods, so rates and clamping occur), a gap of 7 τ after the fraction ``gap_at``
    of the samples, signal = small noise.  Returns ``(time_s, temps_c (n, k), signal)``."""
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=np.float64) * sample_interval_s
    t[int(gap_at * n) :] += 7.0 * sample_interval_s
    tr = model["range"]["temperature_c"]
    names = model["temperatures"]
    cols = []
    for i, name in enumerate(names):
        lo, hi = (float(v) for v in tr[name])
        span = max(hi - lo, 1e-3)
        period = (n * sample_interval_s) / (3.0 + 1.7 * i)
        phase = (t / period + 0.13 * i) % 1.0
        tri = 1.0 - np.abs(2.0 * phase - 1.0)
        cols.append(lo - 0.1 * span + 1.2 * span * tri + 0.001 * span * rng.standard_normal(n))
    sig = 0.01 * rng.standard_normal(n)
    return t, np.column_stack(cols), sig


@dataclass(frozen=True)
class FloatError:
    """Worst-case difference of the float build from the double build on :func:`exercise_inputs`:
    ``max_abs`` [signal unit], ``max_rel`` (relative to max |ŷ|), ``n_samples``."""

    max_abs: float
    max_rel: float
    n_samples: int


def measure_float_error(
    model: dict[str, Any],
    *,
    prefix: str = "thermocal_model",
    n: int = 100_000,
    sample_interval_s: float = 1.0,
    compiler: str | None = None,
    unit: str | None = None,
) -> FloatError:
    """Compile the double and float builds and compare them on the same inputs."""
    t, T, f = exercise_inputs(model, n, sample_interval_s)
    outs = []
    with tempfile.TemporaryDirectory() as tmp:
        for real in REAL_TYPES:
            ex = generate_c(
                model, prefix=prefix, real=real, sample_interval_s=sample_interval_s, unit=unit
            )
            exe = compile_harness(ex, Path(tmp) / real, compiler)
            outs.append(run_harness(exe, t, T, f, sample_interval_s))
    d = np.abs(outs[1] - outs[0])
    scale = float(np.max(np.abs(outs[0]))) or 1.0
    return FloatError(float(d.max()), float(d.max()) / scale, int(t.size))


def generate_c_calibration(
    channels: Sequence[tuple[str, dict[str, Any], str | None]],
    *,
    prefix: str = "thermocal_cal",
    real: str = "double",
    sample_interval_s: float | None = None,
) -> CExport:
    """One C99 header and source for a whole calibration (issue 15).

    ``channels``: ``(name, model dict, unit)`` per channel (unit None: the channel's data
    unit as fitted, :func:`c_signal_unit`). Each channel is the same code as its own
    :func:`generate_c` module under the prefix ``<prefix>_<name>``; on top, one state
    struct holding every channel's, one ``<prefix>_init`` and one
    ``<prefix>_compensate(s, time_s, temps_c[<P>_N_TEMPS], raw[<P>_N_CHANNELS],
    out[<P>_N_CHANNELS])`` taking the union of the channels' temperature inputs (in the
    order of ``<P>_TEMPERATURE_NAMES``) and the N raw values, each in its channel's unit,
    and writing the N compensated values. No allocation; the per-channel functions stay
    callable (``<prefix>_<name>_compensate``). ``sample_interval_s`` sizes the Ṫ buffers
    (None: each channel's fitted interval, :func:`fitted_sample_interval`).
    """
    if not channels:
        raise ThermocalInputError("a calibration with no channel has no C")
    p = c_identifier(prefix)
    P = p.upper()
    mods: list[tuple[str, CExport, list[str]]] = []
    temps: list[str] = []
    for _name, md, _unit in channels:
        for t in md["temperatures"]:
            if t not in temps:
                temps.append(str(t))
    tus = set()
    for name, md, unit in channels:
        ex = generate_c(
            md,
            prefix=f"{p}_{c_identifier(name)}",
            real=real,
            sample_interval_s=(
                sample_interval_s
                if sample_interval_s is not None
                else fitted_sample_interval(md) or 1.0
            ),
            unit=unit,
        )
        mods.append((name, ex, [str(t) for t in md["temperatures"]]))
        tus.add(ex.temperature_unit)
    if len(tus) > 1:
        raise ThermocalInputError(
            "the channels' models take temperatures in different units "
            f"({', '.join(sorted(tus))}); one calibration's C takes one kind"
        )
    n, k = len(mods), len(temps)
    chan_list = ", ".join(f"{i}={name} [{ex.unit}]" for i, (name, ex, _t) in enumerate(mods))
    temp_list = ", ".join(f"{i}={t}" for i, t in enumerate(temps))
    tu = next(iter(tus))
    parts_h = [ex.header for _n, ex, _t in mods]
    header = "\n".join(
        [
            _comment(
                [
                    f"thermocal calibration of {n} channels: {chan_list}",
                    f"temps_c[] order: {temp_list} [{tu}]",
                    "Each channel's own functions are below; the calibration's functions at the "
                    "end take every channel at once.",
                ]
            ),
            f"#ifndef {P}_CAL_H",
            f"#define {P}_CAL_H",
            "",
            *parts_h,
            f"typedef {real} {p}_real;",
            f"#define {P}_N_CHANNELS {n}",
            f"#define {P}_N_TEMPS {k}",
            f"/* channels: {chan_list} */",
            f"/* temperatures: {temp_list} */",
            "",
            "typedef struct {",
            *[f"    {ex.prefix}_state {c_identifier(name)};" for name, ex, _t in mods],
            f"}} {p}_state;",
            "",
            "/* Power-on: forget every channel's state; sample_interval_s: nominal [s]. */",
            f"void {p}_init({p}_state *s, double sample_interval_s);",
            f"/* One sample of every channel: time_s [s], temps_c [{tu}] in the order above,",
            "   raw[i] in channel i's unit; out[i] = raw[i] - model value, same unit. */",
            f"void {p}_compensate({p}_state *s, double time_s, const {p}_real "
            f"temps_c[{P}_N_TEMPS], const {p}_real raw[{P}_N_CHANNELS], "
            f"{p}_real out[{P}_N_CHANNELS]);",
            "",
            f"#endif /* {P}_CAL_H */",
            "",
        ]
    )
    bodies = []
    for _name, ex, _t in mods:
        lines = [ln for ln in ex.source.split("\n") if ln != f'#include "{ex.prefix}.h"']
        bodies.append("\n".join(lines))
    calls = []
    for i, (name, ex, ts) in enumerate(mods):
        ident = c_identifier(name)
        idx = ", ".join(f"temps_c[{temps.index(t)}]" for t in ts)
        calls += [
            "    {",
            f"        const {p}_real t_{ident}[{len(ts)}] = {{{idx}}};",
            f"        out[{i}] = {ex.prefix}_compensate(&s->{ident}, time_s, t_{ident}, raw[{i}]);",
            "    }",
        ]
    source = "\n".join(
        [
            _comment([f"thermocal calibration of {n} channels: {chan_list}"]),
            f'#include "{p}.h"',
            "",
            *bodies,
            f"void {p}_init({p}_state *s, double sample_interval_s)",
            "{",
            *[
                f"    {ex.prefix}_init(&s->{c_identifier(name)}, sample_interval_s);"
                for name, ex, _t in mods
            ],
            "}",
            "",
            f"void {p}_compensate({p}_state *s, double time_s, const {p}_real "
            f"temps_c[{P}_N_TEMPS], const {p}_real raw[{P}_N_CHANNELS], "
            f"{p}_real out[{P}_N_CHANNELS])",
            "{",
            *calls,
            "}",
            "",
        ]
    )
    return CExport(
        prefix=p,
        real=real,
        header=header,
        source=source,
        family="calibration",
        n_temps=k,
        unit=",".join(ex.unit for _n, ex, _t in mods),
        model_unit=",".join(ex.model_unit for _n, ex, _t in mods),
        temperature_unit=tu,
    )


def fitted_sample_interval(model: dict[str, Any]) -> float | None:
    """The sample interval [s] of the data a model was fitted on (model file
    ``inputs.sample_interval_s``), or None for files that do not record it."""
    v = (model.get("inputs") or {}).get("sample_interval_s")
    return float(v) if isinstance(v, int | float) and v > 0 else None


def export_c(
    model_path: str | Path,
    out_dir: str | Path,
    *,
    prefix: str | None = None,
    real: str = "double",
    sample_interval_s: float = 1.0,
    unit: str | None = None,
) -> tuple[CExport, list[Path]]:
    """Read and verify a model file, generate its C module and write it into ``out_dir``
    (``unit``: the functions' signal unit, :func:`c_signal_unit`)."""
    from thermocal.models.files import load_model_dict

    d = load_model_dict(model_path)
    ex = generate_c(
        d,
        prefix=prefix or c_identifier(Path(model_path).stem),
        real=real,
        sample_interval_s=sample_interval_s,
        unit=unit,
    )
    return ex, ex.write(out_dir)


__all__ = [
    "CFLAGS",
    "GENERATORS",
    "CExport",
    "ExportContext",
    "FamilyCode",
    "FloatError",
    "c_harness",
    "c_identifier",
    "c_signal_unit",
    "compile_harness",
    "exercise_inputs",
    "export_c",
    "find_compiler",
    "fitted_sample_interval",
    "generate_c",
    "generate_c_calibration",
    "measure_float_error",
    "register_generator",
    "run_harness",
]
