"""``thermocal turntable FILE -o RESULT.json``: gyro-triad calibration (SPEC §7);
``thermocal turntable FILE... --temps COL [--accel X,Y,Z] -o CAL.json``: both triads'
error models over temperature from runs at several soaks (issue 19), written as a
calibration that ``compensate`` applies."""

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    AllowNarrowOpt,
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
from thermocal.defaults import overrides_of
from thermocal.errors import ThermocalInputError

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.models.calibration as _calibration
    import thermocal.models.files as _files
    import thermocal.readers as _readers
    import thermocal.recording as _recording
    import thermocal.turntable.calibrate as _calibrate
    import thermocal.turntable.model as _model
    import thermocal.turntable.thermal as _thermal
    import thermocal.writers as _writers
    from thermocal import units
else:
    _calibration = LazyModule("thermocal.models.calibration")
    _files = LazyModule("thermocal.models.files")
    _thermal = LazyModule("thermocal.turntable.thermal")
    _rich_table = LazyModule("rich.table")
    _readers = LazyModule("thermocal.readers")
    _writers = LazyModule("thermocal.writers")
    _calibrate = LazyModule("thermocal.turntable.calibrate")
    _model = LazyModule("thermocal.turntable.model")
    units = LazyModule("thermocal.units")


@app.command("turntable")
@handle_errors
def turntable_cmd(
    files: Annotated[
        list[Path],
        typer.Argument(
            help="Turntable recording(s) (CSV or Parquet); several: one per soak temperature.",
            show_default=False,
        ),
    ],
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
    temps: Annotated[
        str | None,
        typer.Option(
            "--temps",
            help="Temperature column [°C]: with several runs, every parameter becomes a "
            "polynomial in temperature and the output a calibration.",
        ),
    ] = None,
    accel: Annotated[
        str | None,
        typer.Option("--accel", help="Accelerometer x,y,z column names (also calibrated)."),
    ] = None,
    accel_unit: Annotated[
        str | None,
        typer.Option("--accel-unit", help="Accelerometer unit: m/s^2, mg, g (default: file's)."),
    ] = None,
    gravity: Annotated[
        float | None,
        typer.Option(
            "--gravity", help="Local gravity [m/s²] (default: WGS-84 normal gravity at latitude)."
        ),
    ] = None,
    order: Annotated[
        int | None,
        typer.Option(
            "--order", help="Polynomial order in temperature (default: chosen per parameter)."
        ),
    ] = None,
    tref: Annotated[
        float | None,
        typer.Option("--tref", help="Reference temperature [°C] (default: mid soak range)."),
    ] = None,
    allow_narrow: AllowNarrowOpt = False,
    as_json: JsonOpt = False,
) -> None:
    """Gyro-triad bias, scale factor and misalignment from a 16-position turntable run; with
    several runs at soak temperatures (--temps), both triads' error models over temperature."""
    if order is not None:
        check_order(order)
    _writers.check_not_input(output, list(files))
    gyro_cols = split_names(gyro) or []
    if len(gyro_cols) != 3:
        raise ThermocalInputError(f"--gyro needs three column names, got {gyro!r}")
    accel_cols = split_names(accel) if accel else None
    if accel_cols is not None and len(accel_cols) != 3:
        raise ThermocalInputError(f"--accel needs three column names, got {accel!r}")
    opts = _RunOptions(
        gyro_cols, accel_cols, temps, latitude, time, time_unit, gyro_unit, accel_unit, gravity,
        alpha, beta, arw, encoder_noise, min_dwell, channels,
    )  # fmt: skip
    if len(files) > 1 or (temps is not None and (order is not None or tref is not None)):
        if temps is None:
            raise ThermocalInputError(
                "several runs: name their temperature column with --temps (one run per soak)"
            )
        _thermal_calibration(files, output, opts, order, tref, as_json, allow_narrow)
        return
    if order is not None or tref is not None:
        raise ThermocalInputError("--order and --tref need several runs and --temps")
    file = files[0]
    _rec, result = _calibrate_file(file, opts, min_positions=16)
    out = result.to_dict()
    out["input"] = str(file)
    _writers.write_json(output, out)

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


@dataclass(frozen=True)
class _RunOptions:
    """What every run of the command is read and calibrated with."""

    gyro: list[str]
    accel: list[str] | None
    temps: str | None
    latitude: float | None
    time: str | None
    time_unit: str | None
    gyro_unit: str | None
    accel_unit: str | None
    gravity: float | None
    alpha: str
    beta: str
    arw: float | None
    encoder_noise: float | None
    min_dwell: float
    channels: int


def _calibrate_file(
    path: Path, o: _RunOptions, *, min_positions: int
) -> tuple["_recording.Recording", "_calibrate.TurntableResult"]:
    """Read one run and calibrate it.  The gyro columns' unit goes through the shared
    resolver: --gyro-unit > file metadata > unit in the column name > °/s (INTERFACE: gyro_z
    in °/s), the last stated in a warning."""
    rec = _readers.read_recording(
        path,
        time=o.time,
        time_unit=o.time_unit,
        signals=o.gyro,
        signal_unit=o.gyro_unit,
        temperatures=[o.temps] if o.temps else None,
        model=units.StatedUnits(signal_default="deg/s"),
    )
    res = _calibrate.calibrate(
        rec,
        o.latitude,
        gyro_columns=o.gyro,
        alpha_column=o.alpha,
        beta_column=o.beta,
        gyro_unit=o.gyro_unit,
        arw_deg_sqrt_h=o.arw,
        encoder_noise_arcsec=o.encoder_noise,
        min_dwell_s=o.min_dwell,
        channels=o.channels,
        accel_columns=o.accel,
        accel_unit=o.accel_unit,
        gravity_m_s2=o.gravity,
        temperature_column=o.temps,
        min_positions=min_positions,
    )
    return rec, res


MIN_POSITIONS_OF_A_SOAK = 12
"""A soak run missing a few of the sixteen positions is still used (with a warning): twelve
distinct attitudes still separate the twelve parameters of each triad."""


def check_order(order: int) -> None:
    """Refuse (exit 2) a ``--order`` outside 0 … :data:`thermocal.turntable.thermal.MAX_ORDER`
    (3: a cubic in temperature per parameter, the most a few soaks can support; the number of
    soaks limits it further once the runs are read) before any file is read: typer parses an
    order of 10²⁰ as a Python int."""
    from thermocal.turntable.thermal import MAX_ORDER

    if not 0 <= order <= MAX_ORDER:
        shown = (
            str(order)
            if len(str(order)) <= 24
            else f"{str(order)[:20]}… ({len(str(order))} digits)"
        )
        raise ThermocalInputError(f"--order must be between 0 and {MAX_ORDER}, got {shown}")


def _thermal_calibration(
    files: list[Path],
    output: Path,
    opts: "_RunOptions",
    order: int | None,
    tref: float | None,
    as_json: bool,
    allow_narrow: bool = False,
) -> None:
    """Each run calibrated alone, then every parameter of each triad as a polynomial in
    temperature (:mod:`thermocal.turntable.thermal`); writes a calibration of triads.  The
    soak temperatures are judged first (:mod:`thermocal.adequacy`: span and distinct soaks
    for the order asked, a line when the order is chosen per parameter)."""
    if output.suffix.lower() != ".json":
        raise ThermocalInputError(f"{output}: the calibration is JSON; use a .json name")
    runs = []
    gyro_units: set[str] = set()
    accel_units: set[str] = set()
    gyro_cols, accel_cols, temps = opts.gyro, opts.accel, str(opts.temps)
    for f in files:
        rec, res = _calibrate_file(f, opts, min_positions=MIN_POSITIONS_OF_A_SOAK)
        gyro_units |= {rec.units[c] for c in gyro_cols}  # resolved by read_recording
        if accel_cols is not None:
            accel_units |= (
                {opts.accel_unit} if opts.accel_unit else {rec.units[c] for c in accel_cols}
            )
        runs.append((f, res))
    for what, found in (("gyro", gyro_units), ("accelerometer", accel_units)):
        if len(found) > 1:
            raise ThermocalInputError(f"the runs' {what} columns differ in unit: {sorted(found)}")
    temps_c = [float(r.temperature_c) for _f, r in runs]  # type: ignore[arg-type]
    import numpy as np

    from thermocal import adequacy

    soaks = np.asarray(temps_c, dtype=np.float64)
    judged = adequacy.Adequacy(
        tuple(adequacy.temperature_tests(soaks, "the soak temperatures", order or 1)),
        overrides_of(allow_narrow, False),
    )
    record = judged.enforce().to_dict()
    rig = (opts.alpha, opts.beta)
    latitude = runs[0][1].latitude_deg  # as used (the option or the files' metadata)
    gyro_model = _thermal.fit_triad(
        "gyro",
        temps_c,
        [r.kalman.theta for _f, r in runs],
        [r.kalman.sigma for _f, r in runs],
        tref_c=tref,
        order=order,
    )
    triads = [
        _calibration.Triad("gyro", (gyro_cols[0], gyro_cols[1], gyro_cols[2]),
                           gyro_units.pop(), temps, gyro_model, rig, latitude, record)
    ]  # fmt: skip
    accel_model = None
    if accel_cols is not None:
        accel_model = _thermal.fit_triad(
            "accel",
            temps_c,
            [r.accel.theta for _f, r in runs if r.accel is not None],
            [r.accel.sigma for _f, r in runs if r.accel is not None],
            tref_c=gyro_model.tref_c,
            order=order,
        )
        triads.append(
            _calibration.Triad("accel", (accel_cols[0], accel_cols[1], accel_cols[2]),
                               accel_units.pop(), temps, accel_model, rig, latitude, record)
        )  # fmt: skip
    cal = _calibration.Calibration([], triads)
    _files.save_calibration(cal, output)
    out = {
        "output": str(output),
        "format": "thermocal-calibration",
        "runs": [{"input": str(f), **r.to_dict()} for f, r in runs],
        "gyro": _triad_summary(gyro_model),
        "adequacy": record,
    }
    if accel_model is not None:
        out["accel"] = _triad_summary(accel_model)

    def human() -> None:
        for name, tri in (("gyro", gyro_model), ("accel", accel_model)):
            if tri is None:
                continue
            table = _rich_table.Table(
                title=f"{name} triad over temperature (TREF {tri.tref_c:g} °C, soaks "
                f"{', '.join(f'{t:g}' for t in tri.soak_temperatures_c)} °C)"
            )
            for col in ("parameter", "unit", "order", "at TREF", "σ", "LOTO rms"):
                table.add_column(col)
            for fit in tri.fits:
                table.add_row(fit.name, fit.unit, str(len(fit.coef) - 1), fmt(fit.coef[0], 5),
                              fmt(fit.sigma[0], 3), fmt(fit.loto_rms, 3))  # fmt: skip
            stdout.print(table)
        stdout.print(f"calibration written: {output} (compensate applies it per sample)")

    emit(out, as_json, human)


def _triad_summary(tri: "_thermal.TriadThermal") -> dict[str, object]:
    """The JSON of one triad's temperature model (INTERFACE.md: tref_c, order, coefficients
    with _sigma, loto_rms)."""
    return {
        "tref_c": tri.tref_c,
        "order": tri.order,
        "temperature_range_c": [tri.t_lo_c, tri.t_hi_c],
        "parameters": {
            f.name: {
                "unit": f.unit,
                "coefficients": f.coef.tolist(),
                "coefficients_sigma": f.sigma.tolist(),
                "loto_rms": f.loto_rms,
            }
            for f in tri.fits
        },
    }


__all__ = ["turntable_cmd"]
