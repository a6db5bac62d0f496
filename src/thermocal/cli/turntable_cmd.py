"""``thermocal turntable FILE -o RESULT.json``: gyro-triad calibration (CN104880182);
``thermocal turntable FILE... --temps COL [--accel X,Y,Z] -o CAL.json``: both triads'
error models over temperature from runs at several soaks, written as a
calibration that ``compensate`` applies.

The library does the work (:func:`thermocal.pipeline.turntable.turntable_calibration`); this
module parses the options and prints the result."""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    AllowNarrowOpt,
    DecimalOpt,
    DelimiterOpt,
    JsonOpt,
    NamesOpt,
    OnBadLinesOpt,
    OutOpt,
    RateOpt,
    StampOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    TriadAccelUnitOpt,
    chamber_log_options,
    emit,
    handle_errors,
    read_options,
    show,
    split_names,
)
from thermocal.defaults import overrides_of
from thermocal.errors import ThermocalInputError
from thermocal.pipeline.messages import option_name
from thermocal.report import triad_text as _triad_text

if TYPE_CHECKING:
    import thermocal.pipeline.turntable as _files
    import thermocal.writers as _writers
else:
    _files = LazyModule("thermocal.pipeline.turntable")
    _writers = LazyModule("thermocal.writers")

DEFAULT_GYRO = ",".join(defaults.DEFAULT_GYRO_COLUMNS)
FilesArg = Annotated[
    list[Path],
    typer.Argument(
        help="Turntable recording(s) (CSV, Parquet, text log, ULog, DataFlash); several: one "
        "per soak temperature.",
        show_default=False,
    ),
]
TtLatitudeOpt = Annotated[
    float | None, typer.Option("--latitude", help="Site latitude [°] (default: metadata).")
]
GyroColsOpt = Annotated[
    str, typer.Option("--gyro", help="Gyro x,y,z column names (comma-separated).")
]
GyroUnitOpt = Annotated[
    str | None,
    typer.Option(
        "--gyro-unit",
        help="Gyro unit: deg/s, deg/h, rad/s (default: the file's, else deg/s with a warning).",
    ),
]
AlphaOpt = Annotated[str, typer.Option("--alpha", help="Inner-axis encoder angle column.")]
AlphaOffsetOpt = Annotated[
    float,
    typer.Option(
        "--alpha-offset",
        help="The inner-axis encoder's reading [°] where body x points East (the geometry's "
        "α = 0); subtracted.",
    ),
]
BetaOpt = Annotated[str, typer.Option("--beta", help="Outer-axis encoder angle column.")]
EncoderUnitOpt = Annotated[
    str | None,
    typer.Option(
        "--encoder-unit",
        help="Encoder angle unit: deg or rad (default: the file's metadata or the column "
        "name, else deg with a warning).",
    ),
]
ArwOpt = Annotated[
    float | None,
    typer.Option("--arw", help="Angle random walk [°/√h] (default: from the dwells)."),
]
EncoderNoiseOpt = Annotated[
    float | None,
    typer.Option(
        "--encoder-noise",
        help="Encoder reading noise σ [arcsec] (default: estimated from the dwells).",
    ),
]
MinDwellOpt = Annotated[float, typer.Option("--min-dwell", help="Shortest dwell accepted [s].")]
ChannelsOpt = Annotated[
    int,
    typer.Option(
        "--channels", help="3: Δα, Δβ, Δγ (15 states); 2: the source's Δα, Δβ (14 states)."
    ),
]
SoakTempsOpt = Annotated[
    str | None,
    typer.Option(
        "--temps",
        help="Temperature column [°C]: with several runs, every parameter becomes a "
        "polynomial in temperature and the output a calibration.",
    ),
]
AccelColsOpt = Annotated[
    str | None,
    typer.Option("--accel", help="Accelerometer x,y,z column names (also calibrated)."),
]
GravityOpt = Annotated[
    float | None,
    typer.Option(
        "--gravity", help="Local gravity [m/s²] (default: WGS-84 normal gravity at latitude)."
    ),
]
OrderOpt = Annotated[
    int | None,
    typer.Option(
        "--order", help="Polynomial order in temperature (default: chosen per parameter)."
    ),
]
TrefOpt = Annotated[
    float | None,
    typer.Option("--tref", help="Reference temperature [°C] (default: mid soak range)."),
]


@app.command("turntable")
@handle_errors
@chamber_log_options
def turntable_cmd(
    files: FilesArg,
    output: OutOpt,
    latitude: TtLatitudeOpt = None,
    time: TimeOpt = "time",
    time_unit: TimeUnitOpt = None,
    gyro: GyroColsOpt = DEFAULT_GYRO,
    gyro_unit: GyroUnitOpt = None,
    alpha: AlphaOpt = "alpha_deg",
    alpha_offset: AlphaOffsetOpt = 0.0,
    beta: BetaOpt = "beta_deg",
    encoder_unit: EncoderUnitOpt = None,
    arw: ArwOpt = None,
    encoder_noise: EncoderNoiseOpt = None,
    min_dwell: MinDwellOpt = 60.0,
    channels: ChannelsOpt = 3,
    temps: SoakTempsOpt = None,
    accel: AccelColsOpt = None,
    accel_unit: TriadAccelUnitOpt = None,
    gravity: GravityOpt = None,
    order: OrderOpt = None,
    tref: TrefOpt = None,
    allow_narrow: AllowNarrowOpt = False,
    t_names: NamesOpt = None,
    topic: TopicOpt = None,
    stamp: StampOpt = "header",
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Gyro-triad bias, scale factor and misalignment from a 16-position turntable run; with
    several runs at soak temperatures (--temps), both triads' error models over temperature."""
    if order is not None:
        _files.check_order(order)
    _writers.check_not_input(output, list(files))
    gyro_cols = split_names(gyro) or []
    if len(gyro_cols) != 3:
        raise ThermocalInputError(f"--gyro needs three column names, got {gyro!r}")
    accel_cols = split_names(accel) if accel else None
    if accel_cols is not None and len(accel_cols) != 3:
        raise ThermocalInputError(f"--accel needs three column names, got {accel!r}")
    opts = _files.TurntableOptions(
        (gyro_cols[0], gyro_cols[1], gyro_cols[2]),
        (accel_cols[0], accel_cols[1], accel_cols[2]) if accel_cols else None,
        temps, latitude, time, time_unit, gyro_unit, accel_unit, gravity, alpha, beta,
        encoder_unit, arw, encoder_noise, min_dwell, channels,
        read_options(
            names=t_names, rate=t_rate, on_bad_lines=t_bad, delimiter=t_delim, decimal=t_dec,
            stamp=stamp,
        ),
        topic,
        alpha_offset,
    )  # fmt: skip
    res = _files.turntable_calibration(
        files, output, opts, order=order, tref_c=tref, overrides=overrides_of(allow_narrow, False)
    )
    if isinstance(res, _files.ThermalRunsResult):
        emit(
            res.to_dict(option_name), as_json, lambda: show(_triad_text.turntable_thermal_text(res))
        )
    else:
        emit(res.to_dict(option_name), as_json, lambda: show(_triad_text.turntable_text(res)))


__all__ = ["turntable_cmd"]
