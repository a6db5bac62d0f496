"""``thermocal report --model M.json --validation V.json --recording VAL.csv -o report.html``.

Builds the self-contained HTML report (:func:`thermocal.report.write_report`)
from the files the other commands write: one or more model files (``thermocal
fit``), their validation results (``thermocal validate --json``, in the same
order as the models) and the validation recording, optionally the modelling
recording.  The first model is reported in detail; the others appear in the
comparison table.
"""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    DecimalOpt,
    DelimiterOpt,
    LogTopicOpt,
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
    TurntableLatitudeOpt,
    chamber_log_options,
    handle_errors,
    progress,
    read_options,
    stderr,
)

if TYPE_CHECKING:
    import thermocal.report.files as _report_files
else:
    _report_files = LazyModule("thermocal.report.files")


@app.command("report")
@handle_errors
@chamber_log_options
def report_cmd(
    model: Annotated[
        list[Path],
        typer.Option("--model", help="Model file (repeat for several; the first is detailed)."),
    ],
    recording: Annotated[
        Path, typer.Option("--recording", help="The validation run's recording (CSV/Parquet).")
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="The HTML file to write.")],
    validation: Annotated[
        list[Path] | None,
        typer.Option(
            "--validation",
            help="`thermocal validate --json` output, one per --model, in the same order.",
        ),
    ] = None,
    modeling: Annotated[
        Path | None, typer.Option("--modeling", help="The modelling run's recording.")
    ] = None,
    signal: ModelSignalOpt = None,
    label: Annotated[
        list[str] | None,
        typer.Option("--label", help="Short name of each model (default: the file stem)."),
    ] = None,
    title: Annotated[
        str, typer.Option("--title", help="Report title.")
    ] = "Temperature compensation report",
    sensor: Annotated[
        str | None,
        typer.Option(
            "--sensor",
            help="Sensor name or serial number; with a station recording folder of several "
            "sensors, also the sensor read (its ID).",
        ),
    ] = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    averaging: Annotated[
        float | None,
        typer.Option(
            "--average",
            "--averaging",
            help="Averaging time [s] of bias stability and peak-to-peak (default: the "
            "validation result's, else 100 s).",
        ),
    ] = None,
    topic: LogTopicOpt = None,
    stamp: StampOpt = "header",
    t_names: NamesOpt = None,
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    latitude: TurntableLatitudeOpt = None,
    dynamic: Annotated[
        float | None,
        typer.Option(
            "--dynamic",
            help="Dynamic ADEV of the compensated output: the overlapping ADEV in sliding "
            "windows of this many seconds (half-window steps), a heat map in the stability "
            "section and a warning when the output is not stationary (as allan --dynamic).",
        ),
    ] = None,
    ratetable: Annotated[
        Path | None,
        typer.Option(
            "--ratetable",
            help="A rate-table result (thermocal ratetable -o RESULT.json): its spec sheet "
            "as a section of the report.",
        ),
    ] = None,
) -> None:
    """Write a self-contained HTML report (figures embedded, no network needed).

    Every model given is shown (fit, range of validity, coefficients); a PASS/ATTENTION
    verdict is stated only from a validation result given with --validation.
    """
    read = read_options(
        time=time, time_unit=time_unit, signal_unit=signal_unit, temp_unit=temp_unit,
        temp_conversion=temp_conversion, topic=topic, names=t_names, rate=t_rate,
        on_bad_lines=t_bad, delimiter=t_delim, decimal=t_dec, stamp=stamp,
    )  # fmt: skip
    res = _report_files.make_report(
        model, recording, output, validations=list(validation or []), modeling=modeling,
        signal=signal, labels=list(label or []), title=title, sensor=sensor,
        averaging_s=averaging, latitude_deg=latitude, read=read, progress=progress,
        dynamic_s=dynamic, ratetable=ratetable,
    )  # fmt: skip
    if res.kind == "triads":
        stderr.print(f"report: {res.path}")
    else:
        stderr.print(f"report written to [bold]{res.path}[/bold]")
