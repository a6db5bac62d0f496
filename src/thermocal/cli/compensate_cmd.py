"""``thermocal compensate MODEL.json FILE -o OUT``: apply a fitted model to a recording.

OUT keeps every input column and adds ``<signal>_model`` and ``<signal>_comp``
(INTERFACE.md).  Files of any size are processed in chunks with constant memory
(:func:`thermocal.compensate.files.compensate_file`).
"""

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
    TempConversionOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    emit,
    fmt,
    handle_errors,
    parse_temp_conversion,
    progress,
    split_names,
    stdout,
    text_options,
)
from thermocal.errors import ThermocalInputError

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.compensate.files as _compensate
    import thermocal.models.files as _files
    import thermocal.outputs as _outputs
    import thermocal.readers as _readers
    import thermocal.writers as _writers
else:
    _rich_table = LazyModule("rich.table")
    _compensate = LazyModule("thermocal.compensate.files")
    _outputs = LazyModule("thermocal.outputs")
    _readers = LazyModule("thermocal.readers")
    _writers = LazyModule("thermocal.writers")
    _files = LazyModule("thermocal.models.files")


@app.command("compensate")
@handle_errors
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
    topic: TopicOpt = None,
    t_names: NamesOpt = None,
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Apply MODEL to FILE; OUT gets every input column plus <signal>_model and <signal>_comp."""
    _writers.check_not_input(output, [file, model_file])
    if _readers.file_kind(output) == "csv":  # the CSV's sidecar must not land on an input either
        _writers.check_not_input(_outputs.sidecar_path(output), [file, model_file])
    cal = _files.load_calibration(model_file)  # a model file is a calibration of one channel
    conv = parse_temp_conversion(temp_conversion) if temp_conversion is not None else None
    if cal.triads:
        if cal.channels:
            raise ThermocalInputError(
                f"{model_file}: a calibration with both triads and single channels is not "
                "applied yet; split it"
            )
        done = _compensate.compensate_triads(
            cal.triads, file, output, time=time, time_unit=time_unit, chunk_rows=chunk_rows
        )
        summary_t = {"model": str(model_file), "output": str(output),
                     "triads": [d.to_dict() for d in done]}  # fmt: skip

        def human_t() -> None:
            for d in done:
                stdout.print(f"{d.triad}: {', '.join(d.comp_columns)} [{d.unit}]")
            stdout.print(f"written: {output}")

        emit(summary_t, as_json, human_t)
        return
    if len(cal.channels) == 1:
        model = cal.channels[0].model
        with progress("compensating") as advance:
            res = _compensate.compensate_file(
                model,
                file,
                output,
                signal=signal,
                time=time,
                time_unit=time_unit,
                signal_unit=signal_unit,
                temp_unit=temp_unit,
                temperature_conversion=conv,
                chunk_rows=chunk_rows,
                extrapolate=extrapolate,
                known_input=known_input,
                on_progress=advance,
                text=text_options(t_names, t_rate, t_bad, t_delim, t_dec),
                topic=topic,
            )
        summary = {"model": str(model_file), "family": model.family, **res.to_dict()}

        def human() -> None:
            table = _rich_table.Table(title=f"{file} → {res.output}", show_header=False)
            table.add_row("model", f"{model.family} ({model_file})")
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

        emit(summary, as_json, human)
        return
    # a calibration: every channel (or those named by --signal) in one chunked pass
    chosen = split_names(signal) or cal.names
    channels = [(cal.channel(n).signal, cal.channel(n).model) for n in chosen]
    with progress("compensating") as advance:
        results = _compensate.compensate_channels(
            channels,
            file,
            output,
            time=time,
            time_unit=time_unit,
            signal_unit=signal_unit,
            temp_unit=temp_unit,
            temperature_conversion=conv,
            chunk_rows=chunk_rows,
            extrapolate=extrapolate,
            known_input=known_input,
            on_progress=advance,
            text=text_options(t_names, t_rate, t_bad, t_delim, t_dec),
            topic=topic,
        )
    out = {
        "model": str(model_file),
        "output": str(output),
        "channels": {
            name: {"family": cal.channel(name).model.family, **r.to_dict()}
            for name, r in zip(chosen, results, strict=True)
        },
    }

    def human_many() -> None:
        table = _rich_table.Table(title=f"{file} → {output} ({len(results)} channels, one pass)")
        for col in ("channel", "model", "added columns", "rms before", "rms after",
                    "mean before → after", "rms about zero before → after", "unit"):  # fmt: skip
            table.add_column(col)
        for name, r in zip(chosen, results, strict=True):
            table.add_row(
                name, cal.channel(name).model.family, f"{r.model_column}, {r.comp_column}",
                fmt(r.rms_before), fmt(r.rms_after),
                f"{fmt(r.mean_before)} → {fmt(r.mean_after)}",
                f"{fmt(r.rms_about_zero_before)} → {fmt(r.rms_about_zero_after)}"
                + (" (WORSE)" if r.absolute_error_worse else ""),
                r.unit,
            )  # fmt: skip
        stdout.print(table)

    emit(out, as_json, human_many)
