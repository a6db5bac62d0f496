"""``thermocal tumble FILE (--angle-column COL | --turn-rate DPS)``: an accelerometer's
bias, scale factor, misalignment, second-order coefficient K2 and cross-coupling K_ip from a
tumble test (IEEE Std 1293-1998): the output's harmonics against the angle of the
horizontal axis it is turned about.

The library does the work (:func:`thermocal.pipeline.tumble.tumble_file`); this module parses
the options and prints the result."""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    JsonOpt,
    ResultOpt,
    TimeOpt,
    TimeUnitOpt,
    chamber_log_options,
    check_result_outputs,
    emit,
    file_read_options,
    handle_errors,
    show,
    write_result_outputs,
)

if TYPE_CHECKING:
    import thermocal.pipeline.tumble as _files
    import thermocal.report.tumble as _report
    import thermocal.report.tumble_text as _text
    from thermocal.readers.options import ReadOptions
else:
    _files = LazyModule("thermocal.pipeline.tumble")
    _report = LazyModule("thermocal.report.tumble")
    _text = LazyModule("thermocal.report.tumble_text")

FileArg = Annotated[
    Path,
    typer.Argument(help="The tumble recording (CSV, Parquet, text log).", show_default=False),
]
AccelOpt = Annotated[str, typer.Option("--accel", help="The accelerometer's output column.")]
AccelUnitOpt = Annotated[
    str | None,
    typer.Option(
        "--accel-unit",
        help="Its unit: mg, g, m/s^2, counts or V (coefficients per g); default: the file's.",
    ),
]
AngleColumnOpt = Annotated[
    str | None,
    typer.Option(
        "--angle-column",
        help="The dividing head's angle column (0: input axis up, 90: pendulous axis up): "
        "stations where it holds still, or a continuous tumble.",
    ),
]
AngleUnitOpt = Annotated[
    str | None, typer.Option("--angle-unit", help="Its unit (deg, rad); default: the file's.")
]
TurnRateOpt = Annotated[
    float | None,
    typer.Option(
        "--turn-rate",
        help="A continuous tumble at this constant rate [°/s], without an angle column.",
    ),
]
StartAngleOpt = Annotated[
    float,
    typer.Option("--start-angle", help="With --turn-rate: the angle at the first sample [°]."),
]
HarmonicsOpt = Annotated[
    int,
    typer.Option("--harmonics", help="Harmonics fitted: 2 (K0, K1, δo, K2, Kip) to 4 (3 adds K3)."),
]
SettleOpt = Annotated[
    float, typer.Option("--settle", help="Settling left out at each station's start [s].")
]
MinStationOpt = Annotated[float, typer.Option("--min-station", help="Shortest station [s].")]
AngleToleranceOpt = Annotated[
    float,
    typer.Option(
        "--angle-tolerance",
        help="Largest change of the angle between two samples of one station [°].",
    ),
]
TempsOpt = Annotated[
    str | None,
    typer.Option(
        "--temps",
        help="The temperature column the test ran at (chamber: the --chamber-log's, the "
        "default with a chamber log): its mean and span, and each station's.",
    ),
]
ReportOpt = Annotated[
    Path | None,
    typer.Option("--report", help="Also write the result as a self-contained HTML page."),
]


@app.command("tumble")
@handle_errors
@chamber_log_options
@file_read_options
def tumble_cmd(
    file: FileArg,
    accel: AccelOpt = "accel",
    signal_unit: AccelUnitOpt = None,  # so that the reader's {signal_unit} reads --accel-unit
    angle_column: AngleColumnOpt = None,
    angle_unit: AngleUnitOpt = None,
    turn_rate_dps: TurnRateOpt = None,
    start_angle_deg: StartAngleOpt = 0.0,
    harmonics: HarmonicsOpt = 2,
    settle_s: SettleOpt = 1.0,
    min_station_s: MinStationOpt = 2.0,
    angle_tolerance_deg: AngleToleranceOpt = 0.01,
    temps: TempsOpt = None,
    output: ResultOpt = None,
    report: ReportOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    as_json: JsonOpt = False,
    *,
    read: "ReadOptions",
) -> None:
    """Accelerometer bias, scale factor, misalignment, second-order K2 and cross-coupling Kip
    from a tumble test (IEEE Std 1293-1998): the output's harmonics against the angle."""
    check_result_outputs(output, report, [file])
    opts = _files.TumbleOptions(
        accel,
        signal_unit,
        angle_column,
        angle_unit,
        turn_rate_dps,
        start_angle_deg,
        harmonics,
        settle_s,
        min_station_s,
        angle_tolerance_deg,
        time,
        time_unit,
        read,
        temps,
    )
    res = _files.tumble_file(file, opts)
    write_result_outputs(res.to_dict(), output, report, lambda: _report.tumble_html(res))
    emit(res.to_dict(), as_json, lambda: show(_text.tumble_text(res)))


__all__ = ["tumble_cmd"]
