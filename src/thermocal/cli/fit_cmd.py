"""``thermocal fit FILE... --model NAME --signal COL --temps COLS -o MODEL.json``.

The command parses its options into :class:`thermocal.pipeline.options.FitOptions`, calls
:func:`thermocal.pipeline.fit.fit_files` and prints the result.

Fits a compensation model on one or several runs (several FILEs = several runs, each with
its own turn-on offset unless ``--no-per-run-offset``) and writes the self-describing model
file with the data files' names and SHA-256 checksums.

The options of the model families are not written here: one typer option is made for each
option the built-in families declare (:func:`thermocal.families.fit_option_table`; an
option several families share, such as ``--order``, once, its help naming each family's
meaning), and the values given go to ``FitOptions.params`` by constructor parameter
(:func:`thermocal.pipeline.options.family_params`: ``--rate-interval`` →
``rate_interval_s``, ``--select --select-method holdout`` → ``select="holdout"``,
``--breakpoints 25,30`` → ``(25.0, 30.0)``).  The family checks them against its
declaration and refuses an option it does not take.

``--target bias|scale_factor`` and the signal's name and unit are recorded in
the model file.  ``--latitude DEG --axis up`` removes the earth rate seen by
the axis (:func:`thermocal.units.earth_rate_on_axis_deg_h`) as a known input;
``--known-input X`` gives any other known input in the canonical signal unit.

JSON keys (``--json``): ``model``, ``output``, ``n_coefficients``,
``rms_residual`` (in the data's own unit, ``unit``; ``rms_residual_model_unit`` in the
model's canonical ``model_unit``), ``condition_number``, ``temperature_range`` ({name: [lo, hi]}),
``rate_range``, ``n_samples``, ``n_runs``, ``unit``, ``target``, ``files``
(name, sha256, n_samples), ``terms_kept`` (selection, else null), ``fit`` (all
fit statistics), ``coefficients`` and ``warnings``.
"""

import dataclasses
import inspect
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    AllowMotionOpt,
    AllowNarrowOpt,
    AxisOpt,
    DecimalOpt,
    DelimiterOpt,
    HeaterBandOpt,
    HeaterMinHoldOpt,
    HeaterOpt,
    HeaterSetpointOpt,
    JsonOpt,
    LatitudeOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalOpt,
    SignalUnitOpt,
    StampOpt,
    TempConversionOpt,
    TempsOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    chamber_log_options,
    current_chamber_log,
    emit,
    handle_errors,
    split_floats,
    stdout,
)
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.families import MODEL_FAMILIES, FamilyOption, fit_option_table
from thermocal.pipeline.options import FitOptions, family_params, options_of
from thermocal.report.text import fmt

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.models.base as _base
    import thermocal.models.results as _results
    import thermocal.pipeline.fit as _fit
else:
    _rich_table = LazyModule("rich.table")
    _base = LazyModule("thermocal.models.base")
    _results = LazyModule("thermocal.models.results")
    _fit = LazyModule("thermocal.pipeline.fit")

FilesArg = Annotated[
    list[Path],
    typer.Argument(help="Recordings (CSV or Parquet); one run each.", show_default=False),
]

FamilyOpt = Annotated[
    str,
    typer.Option(
        "--model",
        help=f"Model family: {', '.join(MODEL_FAMILIES)}, or one a plugin package installs.",
    ),
]

OutputOpt = Annotated[Path, typer.Option("-o", "--output", help="Model file to write (JSON).")]

TargetOpt = Annotated[
    str, typer.Option("--target", help="What the model describes: bias | scale_factor.")
]

KnownInputOpt = Annotated[
    float | None,
    typer.Option("--known-input", help="Known input to remove, canonical signal unit."),
]

GravityAxisOpt = Annotated[
    str | None,
    typer.Option(
        "--gravity-axis",
        help="Accelerometers: the body axis pointing up in the static runs (+x, -x, +y, "
        "-y, +z, -z); the gravity it reads is a known input, so compensation keeps it.",
    ),
]

GravityOpt = Annotated[
    float | None,
    typer.Option(
        "--gravity",
        help="Local gravity [m/s²] for --gravity-axis (default: WGS-84 normal gravity "
        "at --latitude, else standard gravity with a warning).",
    ),
]

TrefOpt = Annotated[
    float | None,
    typer.Option(
        "--tref",
        help="poly: also give the coefficients about this reference temperature [°C] "
        "(in T − TREF, the PX4/ArduPilot convention).",
    ),
]

ParamOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--param",
        metavar="NAME=VALUE",
        help="Any option the chosen family declares, by its parameter name, e.g. --param "
        "rate_interval_s=30 (repeatable; a plugin family's options too); checked against "
        "the family's declared type and bounds.",
    ),
]


_FAMILY_FIELDS = fit_option_table()
"""The family options of ``fit``, by option name without dashes: built from the families'
declarations (:mod:`thermocal.families`), not written here."""


def _family_help(decls: list[tuple[str, FamilyOption]]) -> str:
    """One help text for an option several families may share: ``poly: …; warmup: ….``
    (families giving the same text named together)."""
    by_text: dict[str, list[str]] = {}
    for fam, o in decls:
        by_text.setdefault(o.help, []).append(fam)
    return "; ".join(f"{', '.join(fams)}: {text}" for text, fams in by_text.items()) + "."


def _negated(cli: str) -> str:
    """The negative of a yes/no option (``--per-run-offset`` → its ``no-`` form)."""
    return "-" * 2 + "no-" + cli[2:]


def _family_parameters() -> list[inspect.Parameter]:
    """One typer option per family option of :data:`_FAMILY_FIELDS` (a switch: its flag
    and its choice; a yes/no: ``--NAME/--no-NAME``; numbers as numbers; a list of numbers
    as text, parsed by :func:`_family_values`)."""
    out: list[inspect.Parameter] = []

    def add(name: str, kind: type[Any] | Any, option: Any, default: Any) -> None:
        out.append(inspect.Parameter(name, KW, annotation=Annotated[kind, option], default=default))

    for field, decls in _FAMILY_FIELDS.items():
        first, cli, text = decls[0][1], decls[0][1].cli, _family_help(decls)
        if first.switch:
            add(field, bool, typer.Option(cli, help=text), False)
            switch = "--" + first.switch.replace("_", "-")
            choice = f"{' | '.join(first.choices)} (with {cli}; default {first.choices[0]})."
            add(first.switch, str | None, typer.Option(switch, help=choice), None)
        elif first.kind == "bool":
            add(field, bool | None, typer.Option(f"{cli}/{_negated(cli)}", help=text), None)
        else:
            kind = {"int": int, "float": float}.get(first.kind, str)
            add(field, kind | None, typer.Option(cli, help=text), None)
    return out


def _check_switches(values: dict[str, Any]) -> None:
    """A switch's choice given without the switch (``--select-method holdout`` without
    ``--select``) would be ignored: one error line naming both."""
    for field, decls in _FAMILY_FIELDS.items():
        first = decls[0][1]
        chosen = values.get(first.switch) if first.switch else None
        if chosen is not None and not values.get(field):
            switch = "--" + str(first.switch).replace("_", "-")
            raise ThermocalInputError(
                f"{switch} {chosen} chooses how {first.cli} works, but {first.cli} is not "
                f"given: add {first.cli} (or leave {switch} out)"
            )


def _family_values(values: dict[str, Any]) -> dict[str, Any]:
    """The family options given on the command line as the families declare them: a list
    of numbers (``--breakpoints 25,30``) parsed into a tuple of floats [°C]."""
    out = dict(values)
    for field, decls in _FAMILY_FIELDS.items():
        text = values.get(field)
        if decls[0][1].kind == "floats" and text is not None:
            numbers = split_floats(text, decls[0][1].cli) or []
            if not numbers:
                raise ThermocalInputError(
                    f"{decls[0][1].cli} {text!r} holds no number: give them as 25,30, or "
                    "--segments N to choose them from the data"
                )
            out[field] = tuple(numbers)
    return out


def _param_text(option: FamilyOption, text: str) -> Any:
    """``--param``'s VALUE as the option's declared type (left as text when it is not one:
    the declaration's check then refuses it, naming the parameter)."""
    parse: dict[str, Any] = {
        "int": int, "float": float, "floats": lambda t: tuple(float(v) for v in t.split(",")),
        "bool": lambda t: {"true": True, "yes": True, "1": True, "false": False, "no": False,
                           "0": False}[t.lower()],
    }  # fmt: skip
    try:
        return parse.get(option.kind, str)(text)
    except (ValueError, KeyError):
        return text


def _param_values(model: str, texts: list[str], given: dict[str, Any]) -> dict[str, Any]:
    """The family options of ``--param NAME=VALUE`` (NAME a constructor parameter the family
    ``model`` declares, a plugin's too), each checked against its declaration; an unknown
    NAME, a missing ``=``, an option given twice or a value out of bounds is one error line
    naming ``--param`` and the family's options."""
    if not texts:
        return {}
    from thermocal.models.registry import get_model_class

    declared = {o.name: o for o in get_model_class(model).declaration.options}
    takes = ", ".join(declared) or "none"
    out: dict[str, Any] = {}
    for text in texts:
        name, eq, value = (part.strip() for part in text.partition("="))
        if not eq or name not in declared:
            raise ThermocalInputError(
                f"--param {text!r}: give NAME=VALUE, NAME an option of model {model!r} "
                f"(it takes: {takes})"
            )
        if name in out or given.get(name) is not None:
            raise ThermocalInputError(f"--param {text!r}: the option {name} is given twice")
        try:
            out[name] = declared[name].check(_param_text(declared[name], value))
        except ParameterError as exc:
            raise ThermocalInputError(
                f"{exc.named('--param ' + name)} (model {model!r} takes: {takes})"
            ) from None
    return out


def fit_cmd(**values: Any) -> None:
    """Fit a temperature-compensation model on one or several runs and save it."""
    files, output, as_json = values.pop("files"), values.pop("output"), values.pop("as_json")
    texts = values.pop("param") or []
    _check_switches(values)
    values = _family_values(values)
    options = options_of(FitOptions, {**values, "chamber_log": current_chamber_log()})
    params = family_params(values)
    params |= _param_values(options.model, texts, params)
    options = dataclasses.replace(options, params=params)
    result = _fit.fit_files(files, options, output)
    if result.calibration:
        emit(result.to_dict(), as_json, lambda: _human_channels(result.channels, output))
        return
    ch = result.channels[0]
    emit(result.to_dict(), as_json, lambda: _human_single(ch.model, ch.figures, ch.n_runs, output))


TemperatureModeOpt = Annotated[
    str,
    typer.Option(
        "--temperature",
        help="reconstructed: a quantised or slow thermometer (a lattice of 0.1 °C or more, "
        "updated every second or slower) is fitted on the temperature reconstructed at each "
        "sample; raw: on its reading as logged.",
    ),
]


LegsOpt = Annotated[
    str,
    typer.Option(
        "--legs",
        help="all: every sample; heating or cooling: only the legs where the first "
        "temperature rises (falls) beyond its noise, each leg a run (thermal hysteresis: fit "
        "on one leg, validate on the other).",
    ),
]


KW = inspect.Parameter.KEYWORD_ONLY
_EMPTY = inspect.Parameter.empty
_COMMON_FIRST = (
    ("files", FilesArg, _EMPTY), ("model", FamilyOpt, _EMPTY), ("output", OutputOpt, _EMPTY),
    ("signal", SignalOpt, None), ("temps", TempsOpt, None), ("time", TimeOpt, None),
    ("time_unit", TimeUnitOpt, None), ("signal_unit", SignalUnitOpt, None),
    ("temp_unit", TempUnitOpt, None), ("temp_conversion", TempConversionOpt, None),
)  # fmt: skip
_COMMON_LAST = (
    ("target", TargetOpt, "bias"), ("latitude", LatitudeOpt, None), ("axis", AxisOpt, None),
    ("known_input", KnownInputOpt, None), ("gravity_axis", GravityAxisOpt, None),
    ("gravity", GravityOpt, None), ("tref", TrefOpt, None),
    ("allow_narrow", AllowNarrowOpt, False), ("allow_motion", AllowMotionOpt, False),
    ("names", NamesOpt, None), ("topic", TopicOpt, None), ("rate", RateOpt, None),
    ("on_bad_lines", OnBadLinesOpt, "error"), ("delimiter", DelimiterOpt, None),
    ("decimal", DecimalOpt, None), ("stamp", StampOpt, "header"),
    ("heater", HeaterOpt, "cut"), ("heater_setpoint", HeaterSetpointOpt, None),
    ("heater_band", HeaterBandOpt, 0.5), ("heater_min_hold", HeaterMinHoldOpt, 60.0),
    ("param", ParamOpt, None),
    ("temperature", TemperatureModeOpt, "reconstructed"), ("legs", LegsOpt, "all"),
    ("as_json", JsonOpt, False),
)  # fmt: skip
"""The options of ``fit`` every family shares, around the families' own."""

fit_cmd.__signature__ = inspect.Signature(  # type: ignore[attr-defined]
    [inspect.Parameter(n, KW, annotation=a, default=d) for n, a, d in _COMMON_FIRST]
    + _family_parameters()
    + [inspect.Parameter(n, KW, annotation=a, default=d) for n, a, d in _COMMON_LAST]
)
app.command("fit")(handle_errors(chamber_log_options(fit_cmd)))


def _human_single(
    est: "_base.TemperatureModel", result: dict[str, Any], n_runs: int, output: Path
) -> None:
    """The fit summary and coefficient tables of one model."""
    st = est.stats_
    unit = result["unit"]
    kappa = st.condition_number
    corr: dict[str, Any] | None = st.extra.get("residual_correlation")
    trange = result["temperature_range"]
    kept = result["terms_kept"]
    tab = _rich_table.Table(title=f"{est.family} model → {output}")
    tab.add_column("quantity")
    tab.add_column("value")
    tab.add_row("runs / samples", f"{n_runs} / {st.n_samples}")
    tab.add_row("coefficients", str(st.n_coefficients))
    tab.add_row(f"rms residual [{unit}]", fmt(result["rms_residual"]))
    wording = _results.condition_wording(kappa)
    tab.add_row("condition number", f"{fmt(st.condition_number)} ({wording})")
    if corr:
        tab.add_row(
            "effective samples",
            f"{fmt(corr['n_effective'])} (residual correlation time "
            f"{fmt(corr['tau_samples'])} samples; std. errors × {corr['stderr_factor']:.3g})",
        )
    for n, (a, b) in trange.items():
        tu = "°C" if est.temperature_unit == "degC" else est.temperature_unit
        tab.add_row(f"range {n} [{tu}]", f"{a:.2f} … {b:.2f}")
    if kept is not None:
        tab.add_row("terms kept", ", ".join(kept))
    stdout.print(tab)
    ctab = _rich_table.Table(title="coefficients")
    ctab.add_column("name")
    ctab.add_column("value")
    ctab.add_column("std. error")
    ctab.add_column("|value|/s.e.")
    weak = 0
    ctab.add_column("unit")
    for c in est.coefficients():
        flag = " *" if c.indistinct_from_zero else ""
        weak += bool(flag)
        ctab.add_row(c.name, fmt(c.value, 6), fmt(c.stderr, 3), f"{fmt(c.t_ratio, 2)}{flag}",
                     c.unit)  # fmt: skip
    stdout.print(ctab)
    if "tref" in result:
        ttab = _rich_table.Table(title=f"coefficients about TREF = {result['tref']['tref_c']:g} °C")
        for col in ("name", "value", "std. error", "unit"):
            ttab.add_column(col)
        for c in result["tref"]["coefficients"]:
            ttab.add_row(c["name"], fmt(c["value"], 6), fmt(c.get("stderr"), 3), c.get("unit", ""))
        stdout.print(ttab)
    if weak:
        stdout.print(
            f"* {weak} coefficient(s) within {_results.DISTINCT_T:g} standard errors of 0: not "
            "distinct from zero on these data (consider --select or fewer terms)"
        )


def _human_channels(fitted: "tuple[_fit.FittedChannel, ...]", output: Path) -> None:
    """One row per channel: model, samples, residual, condition, range."""
    tab = _rich_table.Table(title=f"calibration of {len(fitted)} channels → {output}")
    for col in ("channel", "model", "coefficients", "rms residual", "condition", "range [°C]"):
        tab.add_column(col)
    for ch in fitted:
        name, est, res = ch.name, ch.model, ch.figures
        rng = "; ".join(f"{k} {a:.1f}…{b:.1f}" for k, (a, b) in res["temperature_range"].items())
        tab.add_row(
            name,
            est.family,
            str(res["n_coefficients"]),
            f"{fmt(res['rms_residual'])} {res['unit']}",
            f"{fmt(res['condition_number'])} ({res['condition']})",
            rng,
        )
    stdout.print(tab)
