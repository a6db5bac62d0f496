"""The generated module's skeleton and the helpers every family's generator uses
(:mod:`thermocal.export.c`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import ModelFileError, ThermocalInputError, UnitError
from thermocal.identifiers import (
    MAX_PREFIX_LEN,
    c_comment,
    c_identifier,
    c_string,
    check_generated_c,
)
from thermocal.recording import GAP_FACTOR, FloatArray

REAL_TYPES = ("double", "float")
FLT_MAX = float(np.finfo(np.float32).max)
"""The largest finite IEEE-754 binary32 value, C's ``FLT_MAX`` (3.4028235e38)."""
FLT_MIN = float(np.finfo(np.float32).tiny)
"""The smallest normal IEEE-754 binary32 value, C's ``FLT_MIN`` (1.1754944e-38); a float
literal below it is written as 0."""


# --- the generated module -------------------------------------------------------------------


@dataclass(frozen=True)
class FamilyCode:
    """What a family generator contributes to the common skeleton.

    ``state_fields`` — C declarations inside the state struct (one per line);
    ``data`` — ``static const`` definitions and static helper functions (source file);
    ``init`` — statements of ``<p>_init`` (``s`` and ``sample_interval_s`` in scope);
    ``update`` — statements of ``<p>_update`` ending in ``return``;
    ``defines`` — extra ``#define`` lines of the header; ``notes`` — comment lines.

    Attributes
    ----------
    state_fields : list of str
        C declarations of the state struct.
    data : str
        Definitions and helpers of the source file.
    init, update : str
        Statements of ``<p>_init`` and ``<p>_update``.
    defines : list of str
        Extra ``#define`` lines.
    notes : list of str
        Comment lines.
    """

    state_fields: list[str]
    data: str
    init: str
    update: str
    defines: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class CExport:
    """A generated C module: ``header`` (``<prefix>.h``) and ``source`` (``<prefix>.c``).

    Attributes
    ----------
    prefix : str
        The C identifier prefix of every name.
    real : str
        ``"double"`` or ``"float"``.
    header, source : str
        The text of ``<prefix>.h`` and ``<prefix>.c``.
    family : str
        The model family.
    n_temps : int
        Number of temperature inputs.
    unit : str
        Unit of the functions' signal and results.
    model_unit : str
        The model's own unit.
    temperature_unit : str
        Unit of the temperature inputs.
    """

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

    def __post_init__(self) -> None:
        # the backstop of the identifier gate (thermocal.identifiers): a module that a name
        # from a file or option could have steered is refused, never written
        if c_identifier(self.prefix, max_len=MAX_PREFIX_LEN) != self.prefix:
            raise ThermocalInputError(f"C prefix {self.prefix!r} is not a safe identifier")
        check_generated_c(self.header, f"generated C ({self.header_name})")
        check_generated_c(self.source, f"generated C ({self.source_name})")

    @property
    def header_name(self) -> str:
        """File name of the header, ``<prefix>.h``."""
        return f"{self.prefix}.h"

    @property
    def source_name(self) -> str:
        """File name of the source, ``<prefix>.c``."""
        return f"{self.prefix}.c"

    def write(self, directory: str | Path, inputs: Sequence[str | Path] = ()) -> list[Path]:
        """Write header and source into ``directory`` as a pair.

        Neither may be one of ``inputs`` (the model file: ``export-c model.c -o .``) nor a
        special file (:func:`thermocal.outputs.check_outputs`).  Both are written whole
        to temporaries beside their targets before either is renamed into place
        (:func:`write_together`): a failure writing either leaves neither new file, and
        an older pair as it was.

        Parameters
        ----------
        directory : str or Path
            Output directory; created (with its parents) when missing.
        inputs : sequence of str or Path, optional
            Input files the outputs must not overwrite (default none).

        Returns
        -------
        list of Path
            The paths written: header first, then source.

        Raises
        ------
        ThermocalInputError
            When an output is an input or a special file, ``directory`` exists and is not a
            directory, or it cannot be created.
        """
        from thermocal.errors import ThermocalInputError
        from thermocal.outputs import check_outputs

        d = Path(directory)
        check_outputs([d / self.header_name, d / self.source_name], inputs, dirs=[d])
        if d.exists() and not d.is_dir():
            raise ThermocalInputError(f"{d}: exists and is not a directory (-o names a directory)")
        try:
            d.mkdir(parents=True, exist_ok=True)
        except (FileExistsError, NotADirectoryError):
            raise ThermocalInputError(f"{d}: cannot create the output directory") from None
        files = [(d / self.header_name, self.header), (d / self.source_name, self.source)]
        write_together(files)
        return [p for p, _text in files]


def _write_text(path: Path, text: str) -> None:
    """``text`` into ``path`` (the temporary of one file of :func:`write_together`)."""
    with open(path, "w") as fh:
        fh.write(text)


def write_together(files: Sequence[tuple[Path, str]]) -> None:
    """Write text files that only make sense together (a C header and its source).

    Each goes into its own temporary beside its target
    (:func:`thermocal.writers.atomic_write_path`), nested, so that every temporary is
    complete before the first rename; an exception while writing any of them removes every
    temporary and renames none.

    Parameters
    ----------
    files : sequence of (Path, str)
        The target paths and the whole text of each.

    Returns
    -------
    None
    """
    from thermocal.writers import atomic_write_path

    if not files:
        return
    (path, text), rest = files[0], files[1:]

    def writer(tmp: Path) -> None:
        _write_text(tmp, text)
        write_together(rest)  # the others complete (and renamed) before this one is

    atomic_write_path(path, writer)


@dataclass(frozen=True)
class ExportContext:
    """What a family generator gets: the model dict, the C prefix and helpers.

    Attributes
    ----------
    model : dict
        The model as saved.
    prefix : str
        The C identifier prefix.
    real : str
        ``"double"`` or ``"float"``.
    rate_buffer_len : int
        Length of the ring buffer of the rate terms.
    """

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

    def state(self, family: str) -> dict[str, Any]:
        """The model's ``state``, checked to be in the layout ``thermocal-<family>-1`` that
        the family's generator reads.

        Parameters
        ----------
        family : str
            The family's name (``"poly"``, ``"piecewise"``, ``"hyst"``).

        Returns
        -------
        dict
            The state as saved.

        Raises
        ------
        ModelFileError
            Another layout (a file of a newer or another family's format).
        """
        st: dict[str, Any] = self.model["state"]
        want = f"thermocal-{family}-1"
        if st.get("layout") != want:
            raise ModelFileError(f"{family} state layout {st.get('layout')!r} is not {want}")
        return st

    def lit(self, x: float) -> str:
        """A C literal of the real type (17 significant digits, ``f`` suffix for float).

        Parameters
        ----------
        x : float
            The constant [unit of the coefficient it carries].

        Returns
        -------
        str
            The C literal; a float magnitude below ``FLT_MIN`` is written as zero.

        Raises
        ------
        ModelFileError
            When ``x`` is not finite, or exceeds ``FLT_MAX`` for the ``float`` real type.

        References
        ----------
        - ISO/IEC 9899:2011 (C11), §5.2.4.2.2 (characteristics of floating types).
        """
        if not math.isfinite(x):
            raise ModelFileError(f"non-finite coefficient {x!r} cannot be exported")
        if self.real == "float" and abs(x) > FLT_MAX:
            raise ModelFileError.naming(
                f"the constant {float(x)!r} is beyond a C float's largest value FLT_MAX = "
                f"{FLT_MAX:.8g} (C11 §5.2.4.2.2): export it without {{use_float}} (in double)",
                "use_float",
            )
        if self.real == "float" and abs(x) < FLT_MIN:
            x = 0.0  # below FLT_MIN: what a float holds of it is 0 (no truncation warning)
        s = repr(float(x))
        if "e" not in s and "." not in s and "inf" not in s:
            s += ".0"
        return s + ("f" if self.real == "float" else "")

    def array(self, name: str, values: Sequence[float] | npt.ArrayLike) -> str:
        """A C definition ``static const <real> NAME[n] = {…};`` of a 1-D array.

        Parameters
        ----------
        name : str
            C identifier of the array.
        values : array_like of float
            The values (flattened); an empty array is written as one zero.

        Returns
        -------
        str
            The C definition, four literals per line.
        """
        v = np.asarray(values, dtype=np.float64).ravel()
        body = ",\n    ".join(
            ", ".join(self.lit(x) for x in v[i : i + 4]) for i in range(0, v.size, 4)
        )
        return (
            f"static const {self.r} {name}[{max(v.size, 1)}] = {{\n    {body or self.lit(0.0)}\n}};"
        )

    def array2(self, name: str, values: npt.ArrayLike) -> str:
        """A C definition ``static const <real> NAME[a][b] = {{…}, …};`` of a 2-D array.

        Parameters
        ----------
        name : str
            C identifier of the array.
        values : array_like of float, shape (a, b)
            The rows of the array.

        Returns
        -------
        str
            The C definition, one row per line.
        """
        m = np.asarray(values, dtype=np.float64)
        rows = ",\n    ".join("{" + ", ".join(self.lit(x) for x in row) + "}" for row in m)
        return f"static const {self.r} {name}[{m.shape[0]}][{m.shape[1]}] = {{\n    {rows}\n}};"

    @property
    def tu(self) -> str:
        """The model's temperature unit: ``degC`` or ``counts`` (anything else in the model
        file is a :class:`UnitError`)."""
        return _temperature_unit(self.model)

    def temp_range(self) -> FloatArray:
        """(k, 2) fitted temperature range [°C or counts] in the model's temperature order."""
        tr = self.model["range"]["temperature_c"]
        return np.array([tr[n] for n in self.model["temperatures"]], dtype=np.float64)

    def clamp_arrays(self) -> str:
        """C arrays ``<P>_T_LO`` and ``<P>_T_HI`` of the fitted temperature range [°C or counts]."""
        rng = self.temp_range()
        return "\n".join(
            [
                f"/* fitted temperature range [{self.tu}]: inputs are clamped to it */",
                self.array(f"{self.P}_T_LO", rng[:, 0]),
                self.array(f"{self.P}_T_HI", rng[:, 1]),
            ]
        )


Generator = Callable[[ExportContext], FamilyCode]


def family_generator(family: str) -> Generator:
    """The C generator a model family declares on its class (``C_GENERATOR``: the module
    of :mod:`thermocal.export.c` whose ``generate(ctx)`` writes its code), so a family's
    options, chunk context and C code are declared in one place.

    Parameters
    ----------
    family : str
        Name of the model family as registered (e.g. ``"poly"``).

    Returns
    -------
    callable
        ``generate(ctx: ExportContext) -> FamilyCode``.

    Raises
    ------
    ModelFileError
        When the family is unknown or declares no C generator (the message lists those
        that do).
    """
    import importlib

    from thermocal.models.registry import MODEL_REGISTRY

    cls = MODEL_REGISTRY.get(family)
    module = getattr(cls, "C_GENERATOR", None) if cls is not None else None
    if not module:
        have = sorted(f for f, c in MODEL_REGISTRY.items() if getattr(c, "C_GENERATOR", None))
        raise ModelFileError(
            f"no C generator for model family {family!r}; available: {', '.join(have)}"
        )
    gen: Generator = importlib.import_module(module).generate
    return gen


# --- common skeleton ----------------------------------------------------------------------


def _temperature_unit(d: dict[str, Any]) -> str:
    """The model file's temperature unit, ``degC`` or ``counts`` (else :class:`UnitError`)."""
    return units.normalize_temperature_unit(
        str(d.get("temperature_unit") or units.LEGACY_TEMPERATURE_UNIT)
    )


def _known_input_line(known: dict[str, Any], prefix: str, su: str) -> str:
    """The banner's known input, in the functions' unit ``su`` (the unit
    ``<p>_set_known_input`` takes), the model file's value and unit beside it."""
    value, unit = float(known["value"]), str(known.get("unit"))
    try:
        in_su = float(units.convert([value], unit, su)[0])
    except (ThermocalInputError, ValueError, KeyError):
        in_su = None
    shown = f"{in_su:.10g} {su} ({value:.10g} {unit})" if in_su is not None else f"{value} {unit}"
    return (
        f"known input:       {shown} removed before the fit ({known.get('what')}); the C "
        f"removes what {prefix}_set_known_input gives, in [{su}] (default 0)"
    )


def _identity(d: dict[str, Any], prefix: str, su: str) -> list[str]:
    sig = d.get("signal") or {}
    lines = [
        "Generated by thermocal export-c from a thermocal model file. Do not edit.",
        f"family:            {d.get('family')}",
        f"format:            {d.get('format')} version {d.get('format_version')}",
        f"thermocal version: {d.get('thermocal_version')}",
        f"created (UTC):     {d.get('created_utc')}",
        f"checksum (sha256): {d.get('checksum')}",
        f"signal:            {sig.get('name')} [{sig.get('unit')}], target {sig.get('target')}",
        f"temperatures:      {', '.join(map(str, d.get('temperatures', [])))} "
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
        lines.append(_known_input_line(known, prefix, su))
    rate = d.get("rate")
    if rate:
        lines.append(f"temperature rate:  {rate.get('method')} over {rate.get('interval_s')} s")
    for entry in d.get("data") or []:
        if isinstance(entry, dict) and entry.get("file"):
            lines.append(f"fitted on:         {entry.get('file')}")
    return [c_comment(ln) for ln in lines]


def _comment(lines: Sequence[str]) -> str:
    """A comment block, every line through :func:`c_comment` (one line each)."""
    return "/*\n" + "\n".join(f" * {c_comment(ln)}".rstrip() for ln in lines) + "\n */"


def c_signal_unit(model: dict[str, Any], unit: str | None = None) -> tuple[str, float]:
    """The unit the generated functions take ``signal`` and return values in, and the factor
    ``f`` with ``value[model unit] = f · value[that unit]``.

    ``unit`` else the unit the model was fitted on as given (model file
    ``inputs.units``, e.g. ``deg/s``), else the model's own unit (older files, raw-count
    data).

    Parameters
    ----------
    model : dict
        The model as read from a model file.
    unit : str or None, optional
        Signal unit of the generated functions (e.g. ``"deg/s"``, ``"m/s^2"``); default
        ``None``: the unit the model was fitted on.

    Returns
    -------
    unit : str
        The normalised signal unit of the generated functions.
    factor : float
        ``f`` with ``value[model unit] = f · value[unit]`` [model unit per unit].

    Raises
    ------
    UnitError
        When ``unit`` is of another kind than the model's, or either is raw ``counts``.
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
        raise UnitError.naming(
            f"{{unit}} {u}: raw counts need the scale factor, the model is in {mu}; "
            "give a physical unit of the model's kind",
            "unit",
        )
    return u, float(units.convert(1.0, u, mu))


def _temperature_from_counts(model: dict[str, Any], p: str, P: str) -> tuple[list[str], str]:
    """Header declaration and source of ``<p>_temps_from_counts`` when every model
    temperature has a counts → °C conversion recorded (the firmware reads counts)."""
    conv_raw = (model.get("inputs") or {}).get("temperature_conversion") or {}
    names = list(model["temperatures"])
    if _temperature_unit(model) != "degC" or not all(n in conv_raw for n in names):
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
        label = c_comment(n)
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
    r"""Generate the C99 header and source of a model dict (see the module docstring).

    ``sample_interval_s`` is only used to size the Ṫ ring buffer of rate models
    (``<P>_RATE_BUF_LEN`` = ⌈Δt/τ⌉ + 8, overridable with ``-D``); the interval used at
    run time is the argument of ``<p>_init``.  ``unit`` is the signal unit of the
    functions (:func:`c_signal_unit`: by default the unit the model was fitted on as
    given); the family code runs in the model's unit and ``<p>_update`` converts its
    input and output with ``<P>_TO_MODEL_UNIT``.

    Parameters
    ----------
    model : dict
        The model as read from a model file (:func:`thermocal.pipeline.model_file.load_model_dict`).
    prefix : str, optional
        Prefix of the C identifiers and file names (default ``"thermocal_model"``); made a
        valid C identifier.
    real : {"double", "float"}, optional
        C type of the coefficients and arithmetic (default ``"double"``).
    sample_interval_s : float, optional
        Expected sample interval [s] (default 1.0), sizing the rate models' ring buffer:

        .. math:: N_\mathrm{buf} = \lceil \Delta t / \tau \rceil + 8

        with :math:`\Delta t` the model's rate interval [s] and :math:`\tau` this interval.
    unit : str or None, optional
        Signal unit of the generated functions (default: the unit fitted on;
        :func:`c_signal_unit`).

    Returns
    -------
    CExport
        Header and source text, prefix, real type, family and units.

    Raises
    ------
    ThermocalInputError
        When ``real`` is not a known C type or ``sample_interval_s`` is not positive.
    ModelFileError
        When the family has no C generator or a coefficient cannot be written.
    UnitError
        When ``unit`` does not fit the model's signal.

    References
    ----------
    - ISO/IEC 9899:1999 (C99), the language of the generated code.
    """
    if real not in REAL_TYPES:
        raise ThermocalInputError(f"real type must be one of {REAL_TYPES}, got {real!r}")
    fam = str(model.get("family"))
    gen = family_generator(fam)
    if not sample_interval_s > 0:
        raise ThermocalInputError(f"sample interval must be positive, got {sample_interval_s}")
    p = c_identifier(prefix, max_len=MAX_PREFIX_LEN)
    rate = model.get("rate") or {}
    interval = float(rate.get("interval_s") or 0.0)
    buf = math.ceil(interval / sample_interval_s) + 8 if interval > 0 else 2
    ctx = ExportContext(model=model, prefix=p, real=real, rate_buffer_len=buf)
    code = gen(ctx)
    su, factor = c_signal_unit(model, unit)
    conv_decl, conv_src = _temperature_from_counts(model, p, ctx.P)
    sk = _Skeleton(
        ctx=ctx,
        code=code,
        ident=_identity(model, p, su),
        su=su,
        mu=units.normalize_signal_unit(str(model["signal"]["unit"])),
        factor=factor,
        conv_decl=conv_decl,
        conv_src=conv_src,
    )
    return CExport(
        prefix=p,
        real=real,
        header=_header(sk),
        source=_source(sk),
        family=fam,
        n_temps=len(model["temperatures"]),
        unit=su,
        model_unit=sk.mu,
        temperature_unit=ctx.tu,
    )


@dataclass(frozen=True)
class _Skeleton:
    """What the header and the source of one model's module share (:func:`generate_c`):
    the family's code, the identity comment, the functions' signal unit ``su``, the model's
    unit ``mu`` and ``factor`` [mu per su], the counts-to-temperature helper."""

    ctx: ExportContext
    code: FamilyCode
    ident: list[str]
    su: str
    mu: str
    factor: float
    conv_decl: list[str]
    conv_src: str

    @property
    def convert(self) -> bool:
        """Whether the functions' unit differs from the model's (``<P>_TO_MODEL_UNIT``)."""
        return self.factor != 1.0


def _header(sk: _Skeleton) -> str:
    """The header ``<p>.h`` of :func:`generate_c`."""
    ctx, code, su, mu = sk.ctx, sk.code, sk.su, sk.mu
    p, P, tu, real = ctx.prefix, ctx.P, ctx.tu, ctx.real
    guard = f"{P}_H"
    unit_defines = [
        f"#define {P}_SIGNAL_UNIT {c_string(su)} /* unit of signal, known_input and every "
        "result */",
        f"#define {P}_TEMPERATURE_UNIT {c_string(tu)} /* unit of temps_c[] */",
    ]
    if sk.convert:
        unit_defines.append(
            f"#define {P}_TO_MODEL_UNIT {ctx.lit(sk.factor)} /* [{mu}] per [{su}]: the model "
            f"runs in {mu} */"
        )
    return "\n".join(
        [
            _comment(
                [
                    *sk.ident,
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
            f"#define {P}_N_TEMPS {len(ctx.model['temperatures'])}",
            f"#define {P}_GAP_FACTOR {GAP_FACTOR!r}",
            *unit_defines,
            *code.defines,
            "",
            f"/* temperature order of temps_c[] [{tu}]: "
            + ", ".join(f"{i}={c_comment(n)}" for i, n in enumerate(ctx.model["temperatures"]))
            + " */",
            "",
            "typedef struct {",
            "    double sample_interval_s;",
            f"    {p}_real known_input; /* [{mu}]"
            + (f", set in [{su}] by {p}_set_known_input */" if sk.convert else " */"),
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
            *sk.conv_decl,
            "",
            f"#endif /* {guard} */",
            "",
        ]
    )


def _update_functions(sk: _Skeleton) -> tuple[str, list[str], list[str]]:
    """``(name, head, wrapper)`` of the family's update function: ``<p>_update`` itself, or a
    static ``<p>_update_<mu>`` in the model's unit behind a ``<p>_update`` converting with
    ``<P>_TO_MODEL_UNIT``."""
    ctx, su, mu = sk.ctx, sk.su, sk.mu
    p, P, tu = ctx.prefix, ctx.P, ctx.tu
    if not sk.convert:
        head = [
            f"/* Model value [{su}] of one sample: temps_c [{tu}], signal [{su}]. */",
            f"{p}_real {p}_update({p}_state *s, double time_s, "
            f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal)",
        ]
        return f"{p}_update", head, []
    model_fn = f"{p}_update_{c_identifier(mu)}"
    head = [
        f"/* Model value [{mu}] of one sample, signal [{mu}]: the family's arithmetic. */",
        f"static {p}_real {model_fn}({p}_state *s, double time_s, "
        f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal)",
    ]
    wrapper = [
        "",
        f"/* Model value [{su}] of one sample: temps_c [{tu}], signal [{su}]. */",
        f"{p}_real {p}_update({p}_state *s, double time_s, "
        f"const {p}_real temps_c[{P}_N_TEMPS], {p}_real signal)",
        "{",
        f"    return {model_fn}(s, time_s, temps_c, signal * {P}_TO_MODEL_UNIT) "
        f"/ {P}_TO_MODEL_UNIT;",
        "}",
    ]
    return model_fn, head, wrapper


def _source(sk: _Skeleton) -> str:
    """The source ``<p>.c`` of :func:`generate_c`."""
    ctx, code, su, mu, ident = sk.ctx, sk.code, sk.su, sk.mu, sk.ident
    p, P = ctx.prefix, ctx.P
    _model_fn, model_fn_head, wrapper = _update_functions(sk)
    ki = f"known_input * {P}_TO_MODEL_UNIT" if sk.convert else "known_input"
    return "\n".join(
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
            *([sk.conv_src, ""] if sk.conv_src else []),
        ]
    )


def _indent(text: str, n: int = 4) -> str:
    pad = " " * n
    return "\n".join(pad + ln if ln.strip() else "" for ln in text.strip("\n").splitlines())


def _rate_buffer_code(ctx: ExportContext) -> tuple[list[str], str, str]:
    """State fields, init and update code of the backward-difference Ṫ:
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
        if (++s->buf_head == {P}_RATE_BUF_LEN) s->buf_head = 0;
        s->buf_n -= 1;
    }}
    slot = s->buf_head + s->buf_n; /* no % in the hot path: one wrap at most */
    if (slot >= {P}_RATE_BUF_LEN) slot -= {P}_RATE_BUF_LEN;
    s->buf_t[slot] = time_s;
    for (i = 0; i < {P}_N_TEMPS; ++i) {{
        s->buf_T[slot][i] = temps_c[i];
    }}
    s->buf_n += 1;
}}
while (s->buf_t[s->buf_head] < time_s - {P}_RATE_INTERVAL_S) {{
    if (++s->buf_head == {P}_RATE_BUF_LEN) s->buf_head = 0;
    s->buf_n -= 1;
}}
{{
    double span = time_s - s->buf_t[s->buf_head];
    const {r} inv_span = span > 0.0 ? ({r})({ctx.lit(60.0)} / span) : {ctx.lit(0.0)};
    for (i = 0; i < {P}_N_TEMPS; ++i) {{
        if (span > 0.0) {{
            rate[i] = (temps_c[i] - s->buf_T[s->buf_head][i]) * inv_span;
        }} else {{
            rate[i] = {ctx.lit(0.0)};
        }}
    }}
}}
"""
    return fields, init, update
