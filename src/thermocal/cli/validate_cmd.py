"""``thermocal validate MODEL.json FILE [--modeling FILE] [--ambient COL]``.

Judges a model on an independent, weakly correlated test (*A modelling and validation
method for the temperature compensation model of a ring-laser gyroscope*, 2017;
:func:`thermocal.validation.validate`).  ``r`` compares the ``--ambient`` column
of the modelling and validation runs (default: the model's first temperature
column).  Without ``--modeling`` the model file's recorded data file is used if
it still exists; otherwise ``r`` is null, with a warning.  The text-log options
(``--names``, ``--rate``, ``--on-bad-lines``, ``--delimiter``, ``--decimal``) apply to
FILE and to the ``--modeling`` file alike.

The command parses its options into :class:`thermocal.pipeline.options.ValidateOptions`,
calls :func:`thermocal.pipeline.validate.validate_files` and prints the report.
"""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    DecimalOpt,
    DelimiterOpt,
    ExtrapolateOpt,
    FileArg,
    JsonOpt,
    ModelArg,
    ModelSignalOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalUnitOpt,
    StampOpt,
    TempConversionOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    TurntableLatitudeOpt,
    chamber_log_options,
    current_chamber_log,
    emit,
    handle_errors,
    stdout,
)
from thermocal.pipeline.options import ValidateOptions, options_of
from thermocal.report.text import fmt

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.pipeline.validate as _validate
    import thermocal.validation as _validation
else:
    _rich_table = LazyModule("rich.table")
    _validation = LazyModule("thermocal.validation")
    _validate = LazyModule("thermocal.pipeline.validate")

ModelingOpt = Annotated[
    Path | None,
    typer.Option(
        "--modeling",
        help="The modelling test's recording (default: the model file's data file); read "
        "with the same options as FILE.",
    ),
]
AmbientOpt = Annotated[
    str | None,
    typer.Option(
        "--ambient",
        help="Temperature column compared by r and used to find the hold stages "
        "(default: the model's first temperature column).",
    ),
]
AveragingOpt = Annotated[
    float, typer.Option("--average", "--averaging", help="Averaging time [s].")
]
StageRateOpt = Annotated[
    float,
    typer.Option("--stage-rate", help="Hold detection: |dT/dt| below this [°C/min]."),
]
MinStageOpt = Annotated[
    float, typer.Option("--min-stage", help="Hold detection: shortest stage [s].")
]
StaticSOpt = Annotated[
    float,
    typer.Option(
        "--static-s",
        help="A multi-position calibration's held-out session: shortest still pose [s].",
    ),
]
LegsReportOpt = Annotated[
    bool,
    typer.Option(
        "--legs",
        help="Print each heating and cooling leg of the ambient temperature with the "
        "compensated output's rms, largest error and mean on it, and whether heating and "
        "cooling disagree at equal temperature beyond the noise (thermal hysteresis), for "
        "every channel of a calibration (each line led by the channel's name); the JSON "
        "output holds them in any case.",
    ),
]
SettleOpt = Annotated[
    float, typer.Option("--settle", help="Seconds cut from the start of each stage.")
]


def _human_channels(report: "_validate.ValidationReport", legs: bool = False) -> None:
    """Several channels: one row and one verdict per channel; with ``legs`` each channel's
    heating and cooling legs after the table, channel by channel."""
    per = report.channels
    table = _rich_table.Table(title=f"validation on {report.file}, {len(per)} channels")
    for col in ("channel", "r", "bias stability before → after", "rms before → after",
                "mean before → after", "rms about zero before → after", "unit",
                "verdict"):  # fmt: skip
        table.add_column(col)
    for ch in per:
        name, res, out = ch.name, ch.result, ch.figures
        table.add_row(
            name,
            fmt(res.r, 3),
            f"{fmt(res.bias_stability_before)} → {fmt(res.bias_stability_after)}",
            f"{fmt(res.rms_before)} → {fmt(res.rms_after)}",
            f"{fmt(out['mean_before'])} → {fmt(out['mean_after'])}",
            f"{fmt(out['rms_about_zero_before'])} → {fmt(out['rms_about_zero_after'])}",
            res.unit,
            res.verdict_line,
        )
    stdout.print(table)
    if legs:
        for ch in per:
            _human_legs(ch.result, ch.name)


def _human_single(report: "_validate.ValidationReport", legs: bool = False) -> None:
    """One channel: the figures before and after, the zero reference and the verdict."""
    ch = report.channels[0]
    res, out, model, file = ch.result, ch.figures, ch.model, report.file
    u = res.unit
    if res.r is None:
        head = "r not computed (no modelling data)"
    else:
        weak = "weakly correlated" if res.weakly_correlated else "NOT weakly correlated"
        head = f"r = {fmt(res.r, 3)} ({weak})"

    table = _rich_table.Table(title=f"validation of {model.family} model on {file}: {head}")
    table.add_column("figure")
    table.add_column(f"before [{u}]", justify="right")
    table.add_column(f"after [{u}]", justify="right")
    table.add_column("improvement", justify="right")
    imp = res.improvement_pct
    for key, label in (
        ("bias_stability", f"bias stability ({res.averaging_s:g} s, rms over stages)"),
        ("bias_repeatability", "bias repeatability"),
        ("rms", "rms"),
        ("peak_to_peak", "peak-to-peak"),
    ):
        pct = imp[key]
        table.add_row(
            label,
            fmt(getattr(res, f"{key}_before")),
            fmt(getattr(res, f"{key}_after")),
            "—" if pct is None else f"{pct:.1f} %",
        )
    for key, label in (
        ("mean", "mean (about zero)"),
        ("rms_about_zero", "rms about zero"),
        ("max_abs", "max |error|"),
    ):
        b, a = out[f"{key}_before"], out[f"{key}_after"]
        pct = _validation.improvement_about_zero_pct(b, a)
        table.add_row(
            label, fmt(b), fmt(a), "—" if pct is None else f"{pct:.1f} %"
        )  # fmt: skip
    stdout.print(table)
    stdout.print(
        f"zero = {fmt(res.zero_reference)} {u}: {res.zero_reference_what}; the figures "
        "about the mean ignore a constant offset, those about zero do not"
    )
    if legs:
        _human_legs(res)
    stdout.print(f"verdict: {res.verdict_line}")


def _human_legs(res: "_validation.ValidationResult", channel: str | None = None) -> None:
    """The heating and cooling legs: each leg's figures after compensation, and whether
    heating and cooling disagree beyond the noise, before and after; ``channel``: the
    channel's name before each line (a calibration of several)."""
    if res.legs is None or res.legs_after is None:
        return
    who = "" if channel is None else f"{channel}: "
    stdout.print(f"{who}legs: {res.legs.summary()}")
    if res.legs_after.per_leg:
        table = _rich_table.Table(
            title=f"{who}legs after compensation [{res.unit}], about the mean"
        )
        for col in ("leg", "time [s]", "T [°C]", "rate [°C/min]", "rms", "max |e|", "mean"):
            table.add_column(col)
        for f in res.legs_after.per_leg:
            g = f.leg
            table.add_row(
                g.direction,
                f"{g.start_s:.6g}…{g.stop_s:.6g}",
                f"{g.temp_start_c:.4g}→{g.temp_stop_c:.4g}",
                fmt(g.rate_c_per_min, 3),
                fmt(f.rms),
                fmt(f.max_abs),
                fmt(f.mean),
            )
        stdout.print(table)
    if res.legs_before is not None and res.legs_before.mean_difference is not None:
        stdout.print(f"{who}before: {res.legs_before.line()}")
    stdout.print(f"{who}after: {res.legs_after.line()}")


def _human_triads(report: "_validate.ValidationReport") -> None:
    """Triads: each figure of each triad before → after, per axis."""
    model_file, file, results = report.model_file, report.file, report.triads
    table = _rich_table.Table(title=f"{model_file} on {file}")
    for col in ("triad", "figure", "x before → after", "y before → after", "z before → after"):
        table.add_column(col, overflow="fold")  # wrapped, never cut
    for r in results:
        for label, before, after in r.rows():
            cells = [f"{fmt(b)} → {fmt(a)}" for b, a in zip(before, after, strict=True)]
            table.add_row(r.triad, label, *cells)
    stdout.print(table)
    for r in results:
        scale = getattr(r, "count_scale", None)
        if scale is not None:
            stdout.print(
                f"{r.triad}: read from raw counts, one count = {scale:.10g} {r.physical_unit} (the "
                "calibration's count scale, as compensate applies it)"
            )
    for note in dict.fromkeys(r.not_judged for r in results if getattr(r, "not_judged", "")):
        stdout.print(f"not judged: {note}")


@app.command("validate")
@handle_errors
@chamber_log_options
def validate_cmd(
    model_file: ModelArg,
    file: FileArg,
    modeling: ModelingOpt = None,
    ambient: AmbientOpt = None,
    averaging: AveragingOpt = defaults.DEFAULT_AVERAGING_S,
    signal: ModelSignalOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    stage_rate: StageRateOpt = 0.05,
    min_stage: MinStageOpt = 600.0,
    settle: SettleOpt = 0.0,
    extrapolate: ExtrapolateOpt = False,
    names: NamesOpt = None,
    rate: RateOpt = None,
    on_bad_lines: OnBadLinesOpt = "error",
    delimiter: DelimiterOpt = None,
    decimal: DecimalOpt = None,
    topic: TopicOpt = None,
    stamp: StampOpt = "header",
    latitude: TurntableLatitudeOpt = None,
    static_s: StaticSOpt = 1.0,
    legs: LegsReportOpt = False,
    as_json: JsonOpt = False,
) -> None:
    """Validate MODEL on FILE: correlation r, bias stability and repeatability over the
    hold stages, rms and peak-to-peak, before and after compensation; a calibration of
    triads (thermocal turntable over temperature) on a turntable run: dwell-mean and
    move-angle errors before and after; with --legs each heating and cooling leg."""
    given = {**locals(), "chamber_log": current_chamber_log()}
    report = _validate.validate_files(model_file, file, options_of(ValidateOptions, given))
    if report.triads:
        emit(report.to_dict(), as_json, lambda: _human_triads(report))
    elif report.several:
        emit(report.to_dict(), as_json, lambda: _human_channels(report, legs))
    else:
        emit(report.to_dict(), as_json, lambda: _human_single(report, legs))
