"""``thermocal compensate MODEL.json FILE -o OUT``: apply a fitted model to a recording.

OUT keeps every input column and adds ``<signal>_model`` and ``<signal>_comp``
Files of any size are processed in chunks with constant memory
(:func:`thermocal.pipeline.compensate.compensate_file`).
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
    OutOpt,
    RateOpt,
    SignalUnitOpt,
    StampOpt,
    TempConversionOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    chamber_log_options,
    emit,
    handle_errors,
    progress,
    read_options,
    split_names,
    stdout,
)
from thermocal.report.text import fmt

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.pipeline.compensate as _compensate
else:
    _rich_table = LazyModule("rich.table")
    _compensate = LazyModule("thermocal.pipeline.compensate")


@app.command("compensate")
@handle_errors
@chamber_log_options
def compensate_cmd(
    model_file: ModelArg,
    file: FileArg,
    output: OutOpt,
    signal: ModelSignalOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    extrapolate: ExtrapolateOpt = False,
    known_input: Annotated[
        float,
        typer.Option(
            "--known-input",
            help="Known input in the model's unit (earth rate, gravity component), removed "
            "from what the model sees (bank start-up selection).",
        ),
    ] = 0.0,
    chunk_rows: Annotated[
        int, typer.Option("--chunk-rows", help="Rows read and written at a time.")
    ] = defaults.DEFAULT_CHUNK_ROWS,
    g_sensitivity: Annotated[
        str,
        typer.Option(
            "--g-sensitivity",
            help="apply: a calibration's gyro g-sensitivity is taken off with the "
            "accelerometer triad's specific force (the recording needs its columns); off: "
            "not, and a triad none of whose columns are in FILE is left out.",
        ),
    ] = "apply",
    topic: TopicOpt = None,
    stamp: StampOpt = "header",
    t_names: NamesOpt = None,
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Apply MODEL to FILE; OUT gets every input column plus <signal>_model and <signal>_comp."""
    with progress("compensating") as advance:
        read = read_options(
            time=time, time_unit=time_unit, signal_unit=signal_unit, temp_unit=temp_unit,
            temp_conversion=temp_conversion, topic=topic, names=t_names, rate=t_rate,
            on_bad_lines=t_bad, delimiter=t_delim, decimal=t_dec, stamp=stamp,
        )  # fmt: skip
        run = _compensate.compensate_calibration_file(
            model_file, file, output, read, signals=tuple(split_names(signal) or ()) or None,
            chunk_rows=chunk_rows,
            extrapolate=extrapolate, known_input=known_input, on_progress=advance,
            g_sensitivity=g_sensitivity,
        )  # fmt: skip
    show = {"triads": _show_triads, "single": _show_single, "channels": _show_channels}
    emit(run.to_dict(), as_json, lambda: show[run.kind](run, file))


def _show_triads(run: "_compensate.CalibrationCompensation", _file: Path) -> None:
    for d in run.triads:
        scale = (
            f" (from raw counts: one count = {d.count_scale:.10g} {d.unit})"
            if d.count_scale is not None
            else ""
        )
        gs = " (g-sensitivity A·f taken off)" if d.g_sensitivity else ""
        stdout.print(f"{d.triad}: {', '.join(d.comp_columns)} [{d.unit}]{scale}{gs}")
    stdout.print(f"written: {run.output}")


def _show_single(run: "_compensate.CalibrationCompensation", file: Path) -> None:
    _name, family, res = run.channels[0]
    table = _rich_table.Table(title=f"{file} → {res.output}", show_header=False)
    table.add_row("model", f"{family} ({run.model_file})")
    table.add_row("rows", str(res.n_rows))
    table.add_row("added columns", f"{res.model_column}, {res.comp_column} [{res.unit}]")
    table.add_row("rms before (about the mean)", f"{fmt(res.rms_before)} {res.unit}")
    table.add_row("rms after (about the mean)", f"{fmt(res.rms_after)} {res.unit}")
    for key, label in (
        ("mean", "mean"),
        ("rms_about_zero", "rms about zero"),
        ("max_abs", "max |error|"),
    ):
        b, a = getattr(res, f"{key}_before"), getattr(res, f"{key}_after")
        table.add_row(f"{label} before → after", f"{fmt(b)} → {fmt(a)} {res.unit}")
    z = res.zero_reference
    table.add_row("zero", f"{fmt(z.get('value'))} {res.unit}: {z.get('what')}")
    if res.absolute_error_worse:
        table.add_row("verdict", "the absolute error is WORSE after compensation")
    stdout.print(table)


def _show_channels(run: "_compensate.CalibrationCompensation", file: Path) -> None:
    table = _rich_table.Table(
        title=f"{file} → {run.output} ({len(run.channels)} channels, one pass)"
    )
    for col in ("channel", "model", "added columns", "rms before", "rms after",
                "mean before → after", "rms about zero before → after", "unit"):  # fmt: skip
        table.add_column(col)
    for name, family, r in run.channels:
        table.add_row(
            name, family, f"{r.model_column}, {r.comp_column}",
            fmt(r.rms_before), fmt(r.rms_after),
            f"{fmt(r.mean_before)} → {fmt(r.mean_after)}",
            f"{fmt(r.rms_about_zero_before)} → {fmt(r.rms_about_zero_after)}"
            + (" (WORSE)" if r.absolute_error_worse else ""),
            r.unit,
        )  # fmt: skip
    stdout.print(table)
