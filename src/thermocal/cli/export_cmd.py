"""``thermocal export-c MODEL.json -o DIR [--float] [--unit U]``: plain C99 header and source.

See :mod:`thermocal.export.c`.  The C works in the unit the model was fitted on as the data
gave it (the model file's ``inputs``), or in ``--unit``; older model files that did not
record it give the model's unit, with a warning.  With ``--float`` the worst-case error of the float
build against the double build is measured (both compiled with the system C
compiler on 10⁵ synthetic samples over the model's range) and printed.
"""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import JsonOpt, ModelArg, emit, handle_errors, stdout
from thermocal.report.text import fmt

if TYPE_CHECKING:
    import thermocal.export.c.files as _export_c_files
else:
    _export_c_files = LazyModule("thermocal.export.c.files")


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
    res = _export_c_files.export_c_file(
        model_file, output, use_float=use_float, name=name,
        sample_interval_s=sample_interval,
        unit=tuple(u.strip() for u in unit.split(",")) if unit and "," in unit else unit,
    )  # fmt: skip
    emit(res.to_dict(), as_json, lambda: _show_c(res))


def _show_c(res: "_export_c_files.ExportCResult") -> None:
    ex = res.export
    for p in res.files:
        stdout.print(f"wrote {p}")
    if res.kind == "calibration":
        stdout.print(
            f"{len(res.channels)} channels: "
            + ", ".join(f"{n} [{u}]" for n, u, _family in res.channels)
        )
    elif res.kind == "model":
        stdout.print(f"signal and results in {ex.unit}, temperatures in {ex.temperature_unit}")
        err = res.float_error
        if err is not None:
            stdout.print(
                f"float build: worst-case error against double {fmt(err.max_abs)} {ex.unit} "
                f"(relative {fmt(err.max_rel)}) over {err.n_samples} samples"
            )


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
    from thermocal.export.params import export_params_file

    res = export_params_file(
        calibration, fmt, output, gyro=split_names(gyro), accel=split_names(accel),
        instance=instance, tref_c=tref, device_id=device_id,
    )  # fmt: skip

    def human() -> None:
        stdout.print(f"wrote {output}: {len(res.params.params)} {fmt} parameters")
        for a in res.params.axes:
            stdout.print(
                f"  {a.kind} {a.axis} <- {a.channel}: offset at TREF {fmt_c(a.coef[0])} "
                f"{res.unit_of(a.kind)}"
            )
        for n in res.params.notes:
            stdout.print(n)

    emit(res.to_dict(), as_json, human)


def fmt_c(v: float) -> str:
    """A coefficient in four significant digits."""
    return f"{v:.4g}"
