"""``thermocal multipos FILE... --accel X,Y,Z [--gyro X,Y,Z] -o CAL.json``: accelerometer
and gyro triads calibrated without a turntable, from hand-placed static poses and the
rotations between them (Tedaldi et al. 2014, Ferraris et al. 1995).  With
several files at several temperatures and ``--temps``, every parameter becomes a
polynomial in T − TREF (:func:`thermocal.turntable.thermal.fit_triad`, the turntable's own
thermal fit).  Writes a calibration of triads, the file type of ``thermocal turntable``."""

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal import defaults as _poses
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    JsonOpt,
    OutOpt,
    TimeOpt,
    TimeUnitOpt,
    TriadAccelUnitOpt,
    chamber_log_options,
    emit,
    file_read_options,
    handle_errors,
    show,
    split_names,
)
from thermocal.errors import ThermocalInputError, UnitError
from thermocal.pipeline.messages import option_name
from thermocal.report import triad_text as _triad_text

if TYPE_CHECKING:
    import thermocal.pipeline.multipos as _mpf
    import thermocal.units as units
    from thermocal.readers.options import ReadOptions
else:
    _mpf = LazyModule("thermocal.pipeline.multipos")
    units = LazyModule("thermocal.units")


def _count_scale(text: str | None, kind: str) -> tuple[float, str] | None:
    """``--accel-scale``/``--gyro-scale VALUE,UNIT``: one raw count is ``VALUE`` ``UNIT``
    (a datasheet's sensitivity, e.g. ``0.061,mg`` or ``0.00763,deg/s``), a positive
    finite number and a unit of the triad's kind."""
    if text is None:
        return None
    parts = [p.strip() for p in text.split(",")]
    want = "accel" if kind == "accel" else "rate"
    try:
        value = float(parts[0])
        unit = str(units.normalize_signal_unit(parts[1])) if len(parts) == 2 else ""
    except (ValueError, UnitError):
        value, unit = math.nan, ""
    if not (math.isfinite(value) and value > 0 and unit and units.signal_kind(unit) == want):
        example = "0.061,mg" if kind == "accel" else "0.00763,deg/s"
        what = "an accelerometer unit: mg, g, m/s^2" if kind == "accel" else "a rate unit: deg/s"
        raise ThermocalInputError(
            f"--{kind}-scale takes VALUE,UNIT (one count in {what}…; e.g. {example}), got {text!r}"
        )
    return value, unit


def _three(text: str | None, option: str) -> list[str] | None:
    if text is None:
        return None
    cols = split_names(text) or []
    if len(cols) != 3:
        raise ThermocalInputError(f"{option} needs three column names (x,y,z), got {text!r}")
    return cols


MultiposFilesArg = Annotated[
    list[Path],
    typer.Argument(
        help="Session recording(s) (CSV or Parquet); several: one per temperature.",
        show_default=False,
    ),
]
AccelColsOpt = Annotated[str, typer.Option("--accel", help="Accelerometer x,y,z column names.")]
GyroColsOpt = Annotated[
    str | None, typer.Option("--gyro", help="Gyro x,y,z column names (also calibrated).")
]
GyroUnitOpt = Annotated[
    str | None,
    typer.Option("--gyro-unit", help="Gyro unit: deg/s, deg/h, rad/s (default: file's)."),
]
MultiposTempsOpt = Annotated[
    str | None,
    typer.Option(
        "--temps",
        help="Temperature column [°C]; with several files every parameter becomes a "
        "polynomial in temperature.",
    ),
]
PosesOpt = Annotated[
    Path | None,
    typer.Option(
        "--poses",
        help='Named sections {"name": {"start": i, "end": j}} by sample index, or '
        "imucal's section list as CSV (x_p…z_a faces, x_rot… 360° turns about that "
        "axis) instead of the poses found in the data (one file).",
    ),
]
GravityOpt = Annotated[float | None, typer.Option("--gravity", help="Local gravity [m/s²].")]
MultiposLatitudeOpt = Annotated[
    float | None,
    typer.Option("--latitude", help="Latitude [°]: normal gravity and the vertical earth rate."),
]
OrderOpt = Annotated[
    int | None,
    typer.Option("--order", help="Polynomial order in temperature (default: by LOTO)."),
]
TrefOpt = Annotated[float | None, typer.Option("--tref", help="Reference temperature [°C].")]
AccelScaleOpt = Annotated[
    str | None,
    typer.Option(
        "--accel-scale",
        help="Raw-count accelerometer: one count as VALUE,UNIT (e.g. 0.061,mg); figures "
        "are then in UNIT.",
    ),
]
GyroScaleOpt = Annotated[
    str | None,
    typer.Option(
        "--gyro-scale", help="Raw-count gyro: one count as VALUE,UNIT (e.g. 0.00763,deg/s)."
    ),
]
StaticOpt = Annotated[float, typer.Option("--static-s", help="Shortest still pose [s].")]
WindowOpt = Annotated[float, typer.Option("--window-s", help="Pose detector: variance window [s].")]
StillThresholdOpt = Annotated[
    float,
    typer.Option(
        "--still-threshold",
        help="Pose detector: still below this many times the sensor's noise variance…",
    ),
]
MotionFractionOpt = Annotated[
    float,
    typer.Option(
        "--motion-fraction",
        help="…or below this fraction of the motions' variance (hand-held tremor).",
    ),
]
DriftOpt = Annotated[
    float,
    typer.Option("--drift-deg", help="Pose detector: a pose turning more than this [°] is moving."),
]
AccelOffsetOpt = Annotated[
    float | None,
    typer.Option(
        "--accel-offset",
        help="Zero of the accelerometer columns in their unit (32768 for unsigned counts).",
    ),
]
GyroOffsetOpt = Annotated[
    float | None,
    typer.Option("--gyro-offset", help="Zero of the gyro columns in their unit."),
]
GyroModelOpt = Annotated[
    str,
    typer.Option(
        "--gyro-model",
        help="Gyro elements fitted: full (3 scale factors, 6 misalignments) or scale (3 "
        "scale factors, misalignments 0: few motions).",
    ),
]

GSensitivityOpt = Annotated[
    str,
    typer.Option(
        "--g-sensitivity",
        help="The gyro's g-sensitivity (3×3, its unit per g) in the calibration, applied by "
        "compensate: auto (when an element is beyond 3σ), apply (whenever the poses "
        "separate it), off (reported only).",
    ),
]

AccelK2Opt = Annotated[
    bool,
    typer.Option(
        "--accel-k2",
        help="Also fit each accelerometer axis's second-order coefficient K2 [unit/g²] "
        "(needs poses at a slant to every axis, e.g. 45°; the six faces cannot separate it "
        "from the bias).",
    ),
]


@app.command("multipos")
@handle_errors
@chamber_log_options
@file_read_options
def multipos_cmd(
    files: MultiposFilesArg,
    output: OutOpt,
    accel: AccelColsOpt,
    gyro: GyroColsOpt = None,
    accel_unit: TriadAccelUnitOpt = None,
    gyro_unit: GyroUnitOpt = None,
    temps: MultiposTempsOpt = None,
    poses: PosesOpt = None,
    gravity: GravityOpt = None,
    latitude: MultiposLatitudeOpt = None,
    order: OrderOpt = None,
    tref: TrefOpt = None,
    static_s: StaticOpt = 1.0,
    window_s: WindowOpt = _poses.POSE_WINDOW_S,
    still_threshold: StillThresholdOpt = _poses.POSE_STILL_THRESHOLD,
    motion_fraction: MotionFractionOpt = _poses.POSE_MOTION_FRACTION,
    drift_deg: DriftOpt = _poses.POSE_DRIFT_DEG,
    accel_offset: AccelOffsetOpt = None,
    gyro_offset: GyroOffsetOpt = None,
    gyro_model: GyroModelOpt = "full",
    g_sensitivity: GSensitivityOpt = "auto",
    accel_k2: AccelK2Opt = False,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    accel_scale: AccelScaleOpt = None,
    gyro_scale: GyroScaleOpt = None,
    as_json: JsonOpt = False,
    *,
    read: "ReadOptions",
) -> None:
    """Accelerometer (and gyro) triad bias, scale factors and misalignments from hand-placed
    poses, without a turntable (Tedaldi et al. 2014; Ferraris et al. 1995)."""
    acc_cols = _three(accel, "--accel") or []
    gyr_cols = _three(gyro, "--gyro")
    opts = _mpf.MultiposOptions(
        (acc_cols[0], acc_cols[1], acc_cols[2]),
        (gyr_cols[0], gyr_cols[1], gyr_cols[2]) if gyr_cols else None,
        accel_unit, gyro_unit, temps, gravity, latitude, order, tref, static_s, time, time_unit,
        _count_scale(accel_scale, "accel"), _count_scale(gyro_scale, "gyro"),
        window_s, still_threshold, motion_fraction, drift_deg, accel_offset, gyro_offset,
        gyro_model,
        g_sensitivity=g_sensitivity,
        read=read,
        accel_k2=accel_k2,
    )  # fmt: skip
    res = _mpf.calibrate_files(files, output, opts, poses)
    emit(res.to_dict(option_name), as_json,
         lambda: show(_triad_text.multipos_text(res, output, option_name)))  # fmt: skip


__all__ = ["multipos_cmd"]
