"""``thermocal export-c MODEL.json -o DIR [--float] [--unit U]``: plain C99 header and source.

See :mod:`thermocal.export.c`.  The C works in the unit the model was fitted on as the data
gave it (the model file's ``inputs``), or in ``--unit``; older model files that did not
record it give the model's unit, with a warning.  With ``--float`` the worst-case error of the float
build against the double build is measured (both compiled with the system C
compiler on 10⁵ synthetic samples over the model's range) and printed.
"""

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import JsonOpt, ModelArg, emit, fmt, handle_errors, stdout
from thermocal.errors import ThermocalInputError, ThermocalWarning, UnitWarning
from thermocal.outputs import check_outputs

if TYPE_CHECKING:
    import thermocal.export.c as _export_c
    import thermocal.models.base as _base
    import thermocal.models.calibration as _calibration
    import thermocal.models.files as _files
    from thermocal import units
else:
    units = LazyModule("thermocal.units")
    _export_c = LazyModule("thermocal.export.c")
    _base = LazyModule("thermocal.models.base")
    _calibration = LazyModule("thermocal.models.calibration")
    _files = LazyModule("thermocal.models.files")


def _read_json(path: Path) -> object:
    """The file's JSON, or None when it is not JSON within the model files' bounds (the
    model loader then says why)."""
    from thermocal.errors import ModelFileError
    from thermocal.models.filecheck import read_json

    try:
        return read_json(path)
    except ModelFileError:
        return None


def _check_adequacy(cal: "_calibration.Calibration", path: Path, firmware: str | None) -> None:
    """Firmware output only from data that supported the fit
    (:func:`thermocal.adequacy.check_for_firmware`); ArduPilot's own minimum sweep too."""
    from thermocal.adequacy import ARDUPILOT_MIN_SPAN_C, check_for_firmware

    for tri in cal.triads:
        if tri.adequacy is not None:  # turntable calibrations since the check existed
            check_for_firmware(tri.adequacy, f"{path}: triad {tri.name}")
    for ch in cal.channels:
        where = f"{path}: channel {ch.name}" if len(cal.channels) > 1 else str(path)
        record = ch.model.adequacy_
        check_for_firmware(record, where)
        if firmware != "ardupilot":
            continue
        rng = ch.model.temp_range_
        span = float(rng[0, 1] - rng[0, 0]) if rng.size else 0.0
        allowed = "--allow-narrow" in ((record or {}).get("overrides") or [])
        if span < ARDUPILOT_MIN_SPAN_C and not allowed:
            raise ThermocalInputError(
                f"{where}: the calibration covers {span:.3g} °C; ArduPilot's temperature "
                f"calibration needs ≥ {ARDUPILOT_MIN_SPAN_C:g} °C (refit on a wider sweep)"
            )


def _export_calibration(
    path: Path,
    output: Path,
    name: str | None,
    real: str,
    sample_interval: float | None,
    unit: str | None,
    as_json: bool,
) -> None:
    """A calibration's C: one header and one source for every channel, each channel in
    its data's unit (``--unit`` applies one unit to every channel, or one per channel)."""
    cal = _files.load_calibration(path)
    _check_adequacy(cal, path, None)
    if cal.triads and not cal.channels:  # a turntable calibration over temperature
        from thermocal.export.c.triad import generate_c_triads

        ex = generate_c_triads(
            cal.triads, prefix=name or _export_c.c_identifier(path.stem), real=real
        )
        paths = ex.write(output, inputs=[path])
        out_t = {
            "family": "triads",
            "prefix": ex.prefix,
            "real": ex.real,
            "triads": {t.name: {"unit": t.unit, "columns": list(t.columns)} for t in cal.triads},
            "files": [str(p) for p in paths],
        }

        def human_t() -> None:
            for p in paths:
                stdout.print(f"wrote {p}")

        emit(out_t, as_json, human_t)
        return
    cal.require_channels("export-c")
    unit_of = units.per_signal_option(unit, cal.names)
    channels = [
        (c.name, _base.model_file_dict(c.model), unit_of[c.name] or c.unit) for c in cal.channels
    ]
    ex = _export_c.generate_c_calibration(
        channels,
        prefix=name or _export_c.c_identifier(path.stem),
        real=real,
        sample_interval_s=sample_interval,
    )
    paths = ex.write(output, inputs=[path])
    out = {
        "family": "calibration",
        "prefix": ex.prefix,
        "real": ex.real,
        "channels": {
            c.name: {"unit": u, "family": c.model.family}
            for c, u in zip(cal.channels, ex.unit.split(","), strict=True)
        },
        "temperature_unit": ex.temperature_unit,
        "files": [str(p) for p in paths],
    }

    def human() -> None:
        for p in paths:
            stdout.print(f"wrote {p}")
        stdout.print(
            f"{len(cal.channels)} channels: "
            + ", ".join(f"{n} [{v['unit']}]" for n, v in out["channels"].items())  # type: ignore[attr-defined]
        )

    emit(out, as_json, human)


@app.command("export-c")
@handle_errors
def export_c_cmd(
    model_file: ModelArg,
    output: Annotated[Path, typer.Option("-o", "--output", help="Output directory.")],
    use_float: Annotated[
        bool, typer.Option("--float", help="float instead of double (error measured).")
    ] = False,
    name: Annotated[
        str | None,
        typer.Option("--name", help="C prefix of the files and symbols (default: file stem)."),
    ] = None,
    sample_interval: Annotated[
        float | None,
        typer.Option(
            "--sample-interval",
            help="Nominal sample interval [s] of the firmware's samples; sizes the rate "
            "buffer of rate models (default: the interval of the data the model was fitted "
            "on, recorded in the model file).",
        ),
    ] = None,
    unit: Annotated[
        str | None,
        typer.Option(
            "--unit",
            help="Signal unit of the C functions (default: the unit the model was fitted on, "
            "as the data gave it), e.g. deg/s; same kind as the model's.",
        ),
    ] = None,
    as_json: JsonOpt = False,
) -> None:
    """Write MODEL as a C99 header and source (no dynamic allocation) into DIR."""
    real = "float" if use_float else "double"
    check_outputs([], [model_file], dirs=[output])  # the files themselves: when named
    raw = _read_json(model_file)
    if _calibration.is_calibration(raw):
        _export_calibration(model_file, output, name, real, sample_interval, unit, as_json)
        return
    d = _files.load_model_dict(model_file)
    from thermocal.adequacy import check_for_firmware

    check_for_firmware(d.get("adequacy"), str(model_file))
    if sample_interval is None:
        sample_interval = _export_c.fitted_sample_interval(d)
        if sample_interval is None:
            sample_interval = 1.0
            if d.get("rate"):
                warnings.warn(
                    UnitWarning(
                        f"{model_file}: the model file does not record its data's sample "
                        "interval (an older file); the C rate buffer is sized for 1 s samples "
                        "— give --sample-interval, or sampling faster shortens the rate "
                        "interval in the firmware"
                    ),
                    stacklevel=1,
                )
    if unit is None:
        sig = d.get("signal") or {}
        given = ((d.get("inputs") or {}).get("units") or {}).get(sig.get("name"))
        if not given:
            warnings.warn(
                UnitWarning(
                    f"{model_file}: the model file does not record the unit its data were "
                    f"in (an older file); the C works in the model's unit {sig.get('unit')} "
                    "(give --unit for another)"
                ),
                stacklevel=1,
            )
        elif given == "counts" and sig.get("unit") != "counts":
            warnings.warn(
                UnitWarning(
                    f"{model_file}: the model was fitted on raw counts converted with a scale "
                    f"factor; the C works in {sig.get('unit')} (convert the counts first, or "
                    "give --unit)"
                ),
                stacklevel=1,
            )
    ex, paths = _export_c.export_c(
        model_file, output, prefix=name, real=real, sample_interval_s=sample_interval, unit=unit
    )
    out: dict[str, object] = {
        "family": ex.family,
        "prefix": ex.prefix,
        "real": ex.real,
        "unit": ex.unit,
        "model_unit": ex.model_unit,
        "temperature_unit": ex.temperature_unit,
        "files": [str(p) for p in paths],
        "float_max_abs_error": None,
        "float_max_rel_error": None,
    }
    if use_float:
        if _export_c.find_compiler() is None:
            warnings.warn(
                "no C compiler found: the float build's error was not measured",
                ThermocalWarning,
                stacklevel=1,
            )
        else:
            err = _export_c.measure_float_error(
                d, prefix=ex.prefix, sample_interval_s=sample_interval, unit=unit
            )
            out["float_max_abs_error"] = err.max_abs
            out["float_max_rel_error"] = err.max_rel
            out["float_error_samples"] = err.n_samples

    def human() -> None:
        for p in paths:
            stdout.print(f"wrote {p}")
        stdout.print(f"signal and results in {ex.unit}, temperatures in {ex.temperature_unit}")
        if out["float_max_abs_error"] is not None:
            stdout.print(
                f"float build: worst-case error against double {fmt(err.max_abs)} {ex.unit} "
                f"(relative {fmt(err.max_rel)}) over {err.n_samples} samples"
            )

    emit(out, as_json, human)


@app.command("export-params")
@handle_errors
def export_params_cmd(
    calibration: Annotated[
        Path, typer.Argument(help="Calibration or model file (JSON).", show_default=False)
    ],
    fmt: Annotated[str, typer.Option("--format", help="Firmware: px4 or ardupilot.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Parameter file to write.")],
    gyro: Annotated[
        str | None,
        typer.Option("--gyro", help="Gyro channels x,y,z (default: the channels' roles)."),
    ] = None,
    accel: Annotated[
        str | None,
        typer.Option("--accel", help="Accelerometer channels x,y,z (default: the roles)."),
    ] = None,
    instance: Annotated[
        int,
        typer.Option(
            "--instance",
            help="Sensor instance, 0-based: PX4 0-3 (TC_G0…TC_G3), ArduPilot 0-2 "
            "(INS_TCAL1…INS_TCAL3).",
        ),
    ] = 0,
    tref: Annotated[
        float | None,
        typer.Option("--tref", help="PX4 reference temperature [°C] (default: mid-range)."),
    ] = None,
    device_id: Annotated[
        int | None,
        typer.Option("--device-id", help="PX4 device id (default: the recorded sensor id)."),
    ] = None,
    as_json: JsonOpt = False,
) -> None:
    """Write firmware thermal-calibration parameters: PX4 TC_* (QGroundControl file) or
    ArduPilot INS_TCAL* (.parm), from a calibration of cubic polynomials in one
    temperature (see ``thermocal.export.params``)."""
    from thermocal.cli.common import split_names
    from thermocal.export.params import export_params
    from thermocal.writers import atomic_write, check_not_input

    check_not_input(output, [calibration])
    cal = _files.load_calibration(calibration)
    cal.require_channels("export-params")
    _check_adequacy(cal, calibration, fmt)
    ids = {"gyro": device_id, "accel": device_id} if device_id is not None else None
    ps = export_params(
        cal, fmt, gyro=split_names(gyro), accel=split_names(accel), instance=instance,
        device_id=ids, tref_c=tref,
    )  # fmt: skip
    with atomic_write(output, "w") as fh:
        fh.write(ps.text())
    out = {
        "output": str(output),
        "format": fmt,
        "params": ps.params,
        "axes": [
            {"channel": a.channel, "kind": a.kind, "axis": a.axis, "tref_c": a.tref_c,
             "coefficients": list(a.coef), "tmin_c": a.tmin_c, "tmax_c": a.tmax_c,
             "relative": a.relative}
            for a in ps.axes
        ],
        "notes": ps.notes,
    }  # fmt: skip

    def human() -> None:
        stdout.print(f"wrote {output}: {len(ps.params)} {fmt} parameters")
        for a in ps.axes:
            unit = "rad/s" if a.kind == "gyro" else "m/s^2"
            stdout.print(
                f"  {a.kind} {a.axis} <- {a.channel}: offset at TREF {fmt_c(a.coef[0])} {unit}"
            )
        for n in ps.notes:
            stdout.print(n)

    emit(out, as_json, human)


def fmt_c(v: float) -> str:
    return f"{v:.4g}"
