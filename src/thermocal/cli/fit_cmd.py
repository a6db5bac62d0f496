"""``thermocal fit FILE... --model NAME --signal COL --temps COLS -o MODEL.json``.

The command parses its options into :class:`thermocal.pipeline.options.FitOptions` (one field
per option), calls :func:`thermocal.pipeline.fit.fit_files` and prints the result.

Fits a compensation model (SPEC §4) on one or several runs (several FILEs =
several runs, each with its own turn-on offset unless ``--no-per-run-offset``)
and writes the self-describing model file (:func:`thermocal.models.files.save_model`)
with the data files' names and SHA-256 checksums.

The family is looked up in the registry (:func:`thermocal.models.registry.get_model_class`).
The command collects the model options the user gave into one dict and calls
``cls.from_cli_options(options)``, the one option parser of every family
restricted to its constructor parameters.  Only options given on the command
line are in the dict (no ``None`` values).  Keys:

==================  =======================  ==================================================
key                 option                   meaning (families)
==================  =======================  ==================================================
``terms``           ``--terms``              ``seed000`` or ``"T1,T1^2,dT1,T1*dT1,..."`` (poly)
``order``           ``--order N``            plain polynomial order (poly); order in ΔT (warmup)
``rate_interval_s`` ``--rate-interval S``    Δt of Ṫ [s] (poly)
``rate_method``     ``--rate-method``        backward | forward | centred (poly)
``select``          ``--select [--select-method bic|holdout]``  term selection (poly)
``ridge``           ``--ridge ALPHA``        ridge α on unit-RMS terms (poly)
``rcond``           ``--rcond R``            SVD truncation threshold (poly)
``solver``          ``--solver``             auto | qr | gram (poly)
``noise_threshold`` ``--noise-threshold K``  keep truncated components above K σ̂ (poly)
``breakpoints``     ``--breakpoints 25,30``  list of float [°C] (piecewise)
``segments``        ``--segments N``         segments, breakpoints from data (piecewise)
``method``          ``--method``             intersect | continuous (piecewise); warmup's own
``start_window_s``  ``--start-window S``     F0/T0 averaging window [s] (warmup)
``t0_order``        ``--t0-order M``         coefficient order in T0 (warmup)
``deviation``       ``--deviation``          distinct-curve threshold, signal unit (bank)
``tolerance``       ``--tolerance``          model acceptance, signal unit (bank)
``startup_s``       ``--startup-s``          start-up smoothing window [s] (bank)
``per_run_offset``  ``--[no-]per-run-offset``  per-run turn-on offsets (all that support it)
==================  =======================  ==================================================

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
    JsonOpt,
    LatitudeOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalOpt,
    SignalUnitOpt,
    TempConversionOpt,
    TempsOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    emit,
    fmt,
    handle_errors,
    stdout,
)
from thermocal.defaults import MODEL_FAMILIES
from thermocal.pipeline.options import FitOptions, options_of

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.models.base as _base
    import thermocal.pipeline.fit as _fit
else:
    _rich_table = LazyModule("rich.table")
    _base = LazyModule("thermocal.models.base")
    _fit = LazyModule("thermocal.pipeline.fit")

FilesArg = Annotated[
    list[Path],
    typer.Argument(help="Recordings (CSV or Parquet); one run each.", show_default=False),
]

FamilyOpt = Annotated[
    str, typer.Option("--model", help=f"Model family: {', '.join(MODEL_FAMILIES)}.")
]

OutputOpt = Annotated[Path, typer.Option("-o", "--output", help="Model file to write (JSON).")]

TermsOpt = Annotated[
    str | None, typer.Option("--terms", help='poly: "seed000" or "T1,T1^2,dT1,T1*dT1,...".')
]

OrderOpt = Annotated[
    int | None,
    typer.Option("--order", help="poly: plain polynomial order; warmup: order in ΔT."),
]

RateIntervalOpt = Annotated[
    float | None, typer.Option("--rate-interval", help="poly: Δt of Ṫ [s] (default 60).")
]

RateMethodOpt = Annotated[
    str | None, typer.Option("--rate-method", help="poly: backward | forward | centred.")
]

SelectOpt = Annotated[bool, typer.Option("--select", help="poly: stepwise term selection.")]

SelectMethodOpt = Annotated[
    str, typer.Option("--select-method", help="poly: selection criterion bic | holdout.")
]

RidgeOpt = Annotated[float | None, typer.Option("--ridge", help="poly: ridge α.")]

RcondOpt = Annotated[
    float | None, typer.Option("--rcond", help="poly: SVD truncation (default 1e-3).")
]

SolverOpt = Annotated[str | None, typer.Option("--solver", help="poly: auto | qr | gram.")]

NoiseThresholdOpt = Annotated[
    float | None,
    typer.Option(
        "--noise-threshold", help="poly: keep truncated SVD components above K σ (default 10)."
    ),
]

BreakpointsOpt = Annotated[
    str | None, typer.Option("--breakpoints", help="piecewise: breakpoints [°C], e.g. 25,30.")
]

SegmentsOpt = Annotated[
    int | None, typer.Option("--segments", help="piecewise: N segments chosen from the data.")
]

MethodOpt = Annotated[
    str | None, typer.Option("--method", help="piecewise: intersect | continuous.")
]

StartWindowOpt = Annotated[
    float | None, typer.Option("--start-window", help="warmup: F0/T0 window [s].")
]

T0OrderOpt = Annotated[
    int | None, typer.Option("--t0-order", help="warmup: coefficient order in T0.")
]

DeviationOpt = Annotated[
    float | None, typer.Option("--deviation", help="bank: distinct-curve threshold.")
]

ToleranceOpt = Annotated[
    float | None, typer.Option("--tolerance", help="bank: model acceptance tolerance.")
]

StartupSOpt = Annotated[
    float | None, typer.Option("--startup-s", help="bank: start-up window [s].")
]

PerRunOffsetOpt = Annotated[
    bool | None,
    typer.Option(
        "--per-run-offset/--no-per-run-offset",
        help="Estimate one turn-on offset per run (nuisance parameters).",
    ),
]

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


@app.command("fit")
@handle_errors
def fit_cmd(
    files: FilesArg,
    model: FamilyOpt,
    output: OutputOpt,
    signal: SignalOpt = None,
    temps: TempsOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    terms: TermsOpt = None,
    order: OrderOpt = None,
    rate_interval: RateIntervalOpt = None,
    rate_method: RateMethodOpt = None,
    select: SelectOpt = False,
    select_method: SelectMethodOpt = "bic",
    ridge: RidgeOpt = None,
    rcond: RcondOpt = None,
    solver: SolverOpt = None,
    noise_threshold: NoiseThresholdOpt = None,
    breakpoints: BreakpointsOpt = None,
    segments: SegmentsOpt = None,
    method: MethodOpt = None,
    start_window: StartWindowOpt = None,
    t0_order: T0OrderOpt = None,
    deviation: DeviationOpt = None,
    tolerance: ToleranceOpt = None,
    startup_s: StartupSOpt = None,
    per_run_offset: PerRunOffsetOpt = None,
    target: TargetOpt = "bias",
    latitude: LatitudeOpt = None,
    axis: AxisOpt = None,
    known_input: KnownInputOpt = None,
    gravity_axis: GravityAxisOpt = None,
    gravity: GravityOpt = None,
    tref: TrefOpt = None,
    allow_narrow: AllowNarrowOpt = False,
    allow_motion: AllowMotionOpt = False,
    names: NamesOpt = None,
    topic: TopicOpt = None,
    rate: RateOpt = None,
    on_bad_lines: OnBadLinesOpt = "error",
    delimiter: DelimiterOpt = None,
    decimal: DecimalOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Fit a temperature-compensation model on one or several runs and save it."""
    result = _fit.fit_files(files, options_of(FitOptions, locals()), output)
    if result.calibration:
        emit(result.to_dict(), as_json, lambda: _human_channels(result.channels, output))
        return
    ch = result.channels[0]
    emit(result.to_dict(), as_json, lambda: _human_single(ch.model, ch.figures, ch.n_runs, output))


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
    wording = _base.condition_wording(kappa)
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
        ratio = abs(c.value) / c.stderr if c.stderr else None
        flag = "" if ratio is None or ratio >= 2.0 else " *"
        weak += bool(flag)
        ctab.add_row(c.name, fmt(c.value, 6), fmt(c.stderr, 3), f"{fmt(ratio, 2)}{flag}", c.unit)
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
            f"* {weak} coefficient(s) within 2 standard errors of 0: not distinct from "
            "zero on these data (consider --select or fewer terms)"
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
