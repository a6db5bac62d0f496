"""``thermocal ratetable FILE... [--rate-column COL | --rates R1,R2,… [--dwell D] |
--schedule FILE]``:
a gyro's scale factor, nonlinearity, asymmetry, bias per rate, input threshold, resolution
and repeatability from a rate-table ladder; with ``--temps`` at several temperatures, the
scale factor's temperature coefficient.

The library does the work (:func:`thermocal.pipeline.ratetable.ratetable_files`); this
module parses the options and prints the result."""

import math
import re
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
    split_floats,
    write_result_outputs,
)
from thermocal.errors import ThermocalInputError

if TYPE_CHECKING:
    import thermocal.pipeline.ratetable as _files
    import thermocal.report.ratetable as _report
    import thermocal.report.ratetable_text as _text
    from thermocal.readers.options import ReadOptions
else:
    _files = LazyModule("thermocal.pipeline.ratetable")
    _report = LazyModule("thermocal.report.ratetable")
    _text = LazyModule("thermocal.report.ratetable_text")

FilesArg = Annotated[
    list[Path],
    typer.Argument(
        help="Rate-table recording(s) (CSV, Parquet, text log); several: one per temperature "
        "(with --temps).",
        show_default=False,
    ),
]
GyroOpt = Annotated[str, typer.Option("--gyro", help="The gyro's output column.")]
GyroUnitOpt = Annotated[
    str | None,
    typer.Option(
        "--gyro-unit",
        help="Its unit: deg/s, deg/h, rad/s (scale factor dimensionless), counts or V (scale "
        "factor per °/s); default: the file's.",
    ),
]
RateColumnOpt = Annotated[
    str | None,
    typer.Option(
        "--rate-column", help="The table's rate column [°/s]: plateaus where it holds still."
    ),
]
RatesOpt = Annotated[
    str | None,
    typer.Option(
        "--rates",
        help="The applied rates [°/s], one per plateau in the order run, e.g. "
        "-300,-100,0,100,300 (plateaus found in the output).",
    ),
]
ScheduleOpt = Annotated[
    Path | None,
    typer.Option(
        "--schedule",
        help="CSV of the plateaus: start_s,end_s,rate_dps rows; or the table's program, "
        "rate_dps,dwell_s rows (placed like --dwell).",
    ),
]
DwellOpt = Annotated[
    str | None,
    typer.Option(
        "--dwell",
        help="How long the table held each of --rates, e.g. 60s or 1min (one for all, or one "
        "a rate): the plateaus placed by the program's timing, no rate column needed.",
    ),
]
StartOpt = Annotated[
    float | None,
    typer.Option(
        "--start",
        help="With --dwell: start of the first plateau [s of the record's time] (default: "
        "found from the output).",
    ),
]
AccelOpt = Annotated[
    float | None,
    typer.Option(
        "--accel",
        help="With --dwell: the table's acceleration between rates [°/s²] (default: found "
        "from the output).",
    ),
]
TempsOpt = Annotated[
    str | None,
    typer.Option(
        "--temps",
        help="Temperature column [°C]: ladders at several temperatures give the scale "
        "factor's temperature coefficient.",
    ),
]
SettleOpt = Annotated[
    float, typer.Option("--settle", help="Settling left out at each plateau's start [s].")
]
MinPlateauOpt = Annotated[float, typer.Option("--min-plateau", help="Shortest plateau [s].")]
WindowOpt = Annotated[
    float, typer.Option("--window", help="Window of the output's plateau detector [s].")
]
SmallOpt = Annotated[
    float,
    typer.Option(
        "--small-fraction",
        help="Rates up to this fraction of full scale are the input-threshold test's.",
    ),
]
TempGapOpt = Annotated[
    float,
    typer.Option(
        "--temp-gap", help="One file: plateaus further apart than this [°C] are two ladders."
    ),
]
OneDirectionOpt = Annotated[
    bool,
    typer.Option("--one-direction", help="Accept a ladder in one direction only (no asymmetry)."),
]
RateToleranceOpt = Annotated[
    float,
    typer.Option(
        "--rate-tolerance",
        help="Largest change of --rate-column between two samples of a plateau [°/s] (a "
        "noisy encoder rate needs more).",
    ),
]
ReportOpt = Annotated[
    Path | None,
    typer.Option("--report", help="Also write the spec sheet as a self-contained HTML page."),
]


_DURATION = re.compile(r"^\s*([-+0-9.eE]+)\s*(s|min|h)?\s*$")
_SECONDS = {None: 1.0, "s": 1.0, "min": 60.0, "h": 3600.0}


def _dwells(text: str | None) -> tuple[float, ...] | None:
    """``--dwell``: durations with an optional unit (``60``, ``60s``, ``1min``), comma-separated."""
    if text is None:
        return None
    out = []
    for item in text.split(","):
        m = _DURATION.match(item)
        try:
            v = float(m.group(1)) * _SECONDS[m.group(2)] if m else math.nan
        except ValueError:
            v = math.nan
        if not (math.isfinite(v) and v > 0):
            raise ThermocalInputError(
                f"--dwell: {item.strip()!r} is not a positive duration (60, 60s, 1min, 0.5h)"
            )
        out.append(v)
    return tuple(out)


@app.command("ratetable")
@handle_errors
@chamber_log_options
@file_read_options
def ratetable_cmd(
    files: FilesArg,
    gyro: GyroOpt = "gyro",
    signal_unit: GyroUnitOpt = None,  # so that the reader's {signal_unit} reads --gyro-unit
    rate_column: RateColumnOpt = None,
    rates_dps: RatesOpt = None,
    schedule: ScheduleOpt = None,
    temps: TempsOpt = None,
    settle_s: SettleOpt = 1.0,
    min_plateau_s: MinPlateauOpt = 5.0,
    window_s: WindowOpt = 0.5,
    small_fraction: SmallOpt = 0.01,
    temp_gap_c: TempGapOpt = 3.0,
    one_direction: OneDirectionOpt = False,
    tolerance_dps: RateToleranceOpt = 1e-3,
    dwell_s: DwellOpt = None,
    start_s: StartOpt = None,
    accel_dps2: AccelOpt = None,
    output: ResultOpt = None,
    report: ReportOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    as_json: JsonOpt = False,
    *,
    read: "ReadOptions",
) -> None:
    """Gyro scale factor, nonlinearity, asymmetry, bias per rate, input threshold and
    resolution from a rate-table ladder (IEEE Std 952/1431); with --temps at several
    temperatures, the scale factor's temperature coefficient."""
    inputs: list[str | Path] = [*files, *([schedule] if schedule else [])]
    check_result_outputs(output, report, inputs)
    rates = split_floats(rates_dps, "--rates")
    opts = _files.RateTableOptions(
        gyro,
        signal_unit,
        rate_column,
        tuple(rates) if rates is not None else None,
        temps,
        settle_s,
        min_plateau_s,
        window_s,
        small_fraction,
        temp_gap_c,
        time,
        time_unit,
        read,
        one_direction,
        tolerance_dps,
        _dwells(dwell_s),
        start_s,
        accel_dps2,
    )
    res = _files.ratetable_files(files, opts, schedule=schedule)
    write_result_outputs(res.to_dict(), output, report, lambda: _report.ratetable_html(res))
    emit(res.to_dict(), as_json, lambda: show(_text.ratetable_text(res)))


__all__ = ["ratetable_cmd"]
