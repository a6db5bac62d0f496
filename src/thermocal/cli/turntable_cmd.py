"""``thermocal turntable FILE -o RESULT.json``: gyro-triad calibration (SPEC §7)."""

from typing import TYPE_CHECKING, Annotated

import typer

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    FileArg,
    JsonOpt,
    OutOpt,
    TimeOpt,
    TimeUnitOpt,
    emit,
    fmt,
    handle_errors,
    split_names,
    stdout,
)
from thermocal.errors import ThermocalInputError

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.io as _io
    import thermocal.turntable.calibrate as _calibrate
    import thermocal.turntable.model as _model
    from thermocal import units
else:
    _rich_table = LazyModule("rich.table")
    _io = LazyModule("thermocal.io")
    _calibrate = LazyModule("thermocal.turntable.calibrate")
    _model = LazyModule("thermocal.turntable.model")
    units = LazyModule("thermocal.units")


@app.command("turntable")
@handle_errors
def turntable_cmd(
    file: FileArg,
    output: OutOpt,
    latitude: Annotated[
        float | None, typer.Option("--latitude", help="Site latitude [°] (default: metadata).")
    ] = None,
    time: TimeOpt = "time",
    time_unit: TimeUnitOpt = None,
    gyro: Annotated[
        str, typer.Option("--gyro", help="Gyro x,y,z column names (comma-separated).")
    ] = ",".join(defaults.DEFAULT_GYRO_COLUMNS),
    gyro_unit: Annotated[
        str | None,
        typer.Option(
            "--gyro-unit",
            help="Gyro unit: deg/s, deg/h, rad/s (default: the file's, else deg/s with a warning).",
        ),
    ] = None,
    alpha: Annotated[
        str, typer.Option("--alpha", help="Inner-axis encoder angle column [°].")
    ] = "alpha_deg",
    beta: Annotated[
        str, typer.Option("--beta", help="Outer-axis encoder angle column [°].")
    ] = "beta_deg",
    arw: Annotated[
        float | None,
        typer.Option("--arw", help="Angle random walk [°/√h] (default: from the dwells)."),
    ] = None,
    encoder_noise: Annotated[
        float | None,
        typer.Option(
            "--encoder-noise",
            help="Encoder reading noise σ [arcsec] (default: estimated from the dwells).",
        ),
    ] = None,
    min_dwell: Annotated[
        float, typer.Option("--min-dwell", help="Shortest dwell accepted [s].")
    ] = 60.0,
    channels: Annotated[
        int,
        typer.Option(
            "--channels", help="3: Δα, Δβ, Δγ (15 states); 2: the SPEC's Δα, Δβ (14 states)."
        ),
    ] = 3,
    as_json: JsonOpt = False,
) -> None:
    """Gyro-triad bias, scale factor and misalignment from a 16-position turntable run."""
    _io.check_not_input(output, [file])
    gyro_cols = split_names(gyro) or []
    if len(gyro_cols) != 3:
        raise ThermocalInputError(f"--gyro needs three column names, got {gyro!r}")
    # the gyro columns' unit through the shared resolver: --gyro-unit > file metadata >
    # unit in the column name > °/s (INTERFACE: gyro_z in °/s), the last stated in a warning
    rec = _io.read_recording(
        file,
        time=time,
        time_unit=time_unit,
        signals=gyro_cols,
        signal_unit=gyro_unit,
        model=units.StatedUnits(signal_default="deg/s"),
    )
    result = _calibrate.calibrate(
        rec,
        latitude,
        gyro_columns=gyro_cols,
        alpha_column=alpha,
        beta_column=beta,
        gyro_unit=gyro_unit,
        arw_deg_sqrt_h=arw,
        encoder_noise_arcsec=encoder_noise,
        min_dwell_s=min_dwell,
        channels=channels,
    )
    out = result.to_dict()
    out["input"] = str(file)
    _io.write_json(output, out)

    def human() -> None:
        table = _rich_table.Table(title=f"turntable calibration of {file} ({out['method']})")
        for col in ("coefficient", "value", "σ", "CRB σ", "least squares", "unit"):
            table.add_column(col)
        ls = out["least_squares"]
        groups = (
            ("bias", "bias_deg_h", "°/h", ("x", "y", "z")),
            ("scale factor", "scale_factor_ppm", "ppm", ("x", "y", "z")),
            ("misalignment", "misalignment_arcsec", "″", _model.MISALIGNMENT_NAMES),
        )
        for label, key, unit, names in groups:
            for i, n in enumerate(names):
                table.add_row(
                    f"{label} {n}",
                    fmt(out[key][i], 5),
                    fmt(out[key + "_sigma"][i], 3),
                    fmt(out["crb"][key][i], 3),
                    fmt(ls[key][i], 5),
                    unit,
                )
        stdout.print(table)
        stdout.print(
            f"inner-axis azimuth (yx − xy)/2: {fmt(out['inner_axis_azimuth_arcsec'], 4)} ± "
            f"{fmt(out['inner_axis_azimuth_arcsec_sigma'], 3)} ″; "
            f"filter/LS agreement {fmt(out['agreement_max_sigma'], 2)} σ; written {output}"
        )

    emit(out, as_json, human)


__all__ = ["turntable_cmd"]
