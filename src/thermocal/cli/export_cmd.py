"""``thermocal export-c MODEL.json -o DIR [--float] [--unit U]``: plain C99 header and source.

See :mod:`thermocal.export_c`.  The C works in the unit the model was fitted on as the data
gave it (the model file's ``inputs``), or in ``--unit``; older model files that did not
record it give the model's unit, with a warning.  With ``--float`` the worst-case error of the float
build against the double build is measured (both compiled with the system C
compiler on 10⁵ synthetic samples over the model's range) and printed.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer

from thermocal.cli.app import app
from thermocal.cli.common import JsonOpt, ModelArg, emit, fmt, handle_errors, stdout
from thermocal.errors import ThermocalWarning, UnitWarning
from thermocal.export_c import export_c, find_compiler, measure_float_error
from thermocal.models.base import load_model_dict


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
        float,
        typer.Option(
            "--sample-interval",
            help="Nominal sample interval [s], sizes the rate buffer of rate models.",
        ),
    ] = 1.0,
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
    d = load_model_dict(model_file)
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
    ex, paths = export_c(
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
        if find_compiler() is None:
            warnings.warn(
                "no C compiler found: the float build's error was not measured",
                ThermocalWarning,
                stacklevel=1,
            )
        else:
            err = measure_float_error(
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
