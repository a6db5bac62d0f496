"""``thermocal export-c MODEL.json -o DIR [--float]``: plain C99 header and source.

See :mod:`thermocal.export_c`.  With ``--float`` the worst-case error of the float
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
from thermocal.errors import ThermocalWarning
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
    as_json: JsonOpt = False,
) -> None:
    """Write MODEL as a C99 header and source (no dynamic allocation) into DIR."""
    real = "float" if use_float else "double"
    ex, paths = export_c(
        model_file, output, prefix=name, real=real, sample_interval_s=sample_interval
    )
    out: dict[str, object] = {
        "family": ex.family,
        "prefix": ex.prefix,
        "real": ex.real,
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
                load_model_dict(model_file), prefix=ex.prefix, sample_interval_s=sample_interval
            )
            out["float_max_abs_error"] = err.max_abs
            out["float_max_rel_error"] = err.max_rel
            out["float_error_samples"] = err.n_samples

    def human() -> None:
        for p in paths:
            stdout.print(f"wrote {p}")
        if out["float_max_abs_error"] is not None:
            stdout.print(
                f"float build: worst-case error against double {fmt(err.max_abs)} "
                f"(relative {fmt(err.max_rel)}) over {err.n_samples} samples"
            )

    emit(out, as_json, human)
