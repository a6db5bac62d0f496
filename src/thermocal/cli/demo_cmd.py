"""``thermocal demo [-o DIR]``: the whole chamber workflow on built-in simulated data.

Runs :func:`thermocal.demo.run_demo` (profiles → simulation → 37-term and
term-selected fits → validation → compensation → C export → HTML report) with a
progress bar on a terminal, then prints a short summary table and the report's path.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from thermocal.cli.app import app
from thermocal.cli.common import JsonOpt, emit, fmt, handle_errors, progress, stdout
from thermocal.demo import DEMO_STEPS, QUICK, run_demo


@app.command("demo")
@handle_errors
def demo_cmd(
    output: Annotated[
        Path, typer.Option("-o", "--output", help="Directory for the report, models and C files.")
    ] = Path("thermocal-demo"),
    seed: Annotated[int, typer.Option("--seed", help="Seed of the simulated data.")] = 1,
    quick: Annotated[
        bool, typer.Option("--quick", help="Smaller data (5 s samples, fewer ramps).")
    ] = False,
    as_json: JsonOpt = False,
) -> None:
    """Simulate, fit, validate, compensate and export a ring-laser gyro model; write a report."""
    if output.exists() and not output.is_dir():
        from thermocal.errors import ThermocalInputError

        raise ThermocalInputError(f"{output}: exists and is not a directory")
    with progress("thermocal demo", total=len(DEMO_STEPS)) as advance:
        res = run_demo(output, seed=seed, config=QUICK if quick else None,
                       progress=lambda _step: advance(1))  # fmt: skip

    out = {
        "report": str(res.report_path),
        "out_dir": str(res.out_dir),
        "elapsed_s": res.elapsed_s,
        "timings_s": res.timings_s,
        "seed": res.seed,
        "models": [
            {
                "label": m.label,
                "model": str(m.model_path),
                "validation": str(m.validation_path),
                "c_files": [str(p) for p in m.c_files],
                "n_coefficients": m.n_coefficients,
                "condition_number": m.condition_number,
                "rms_residual": m.rms_residual,
                "r": m.r,
                "weakly_correlated": m.weakly_correlated,
                "n_stages": m.n_stages,
                "bias_stability_before": m.bias_stability_before,
                "bias_stability_after": m.bias_stability_after,
                "bias_repeatability_before": m.bias_repeatability_before,
                "bias_repeatability_after": m.bias_repeatability_after,
                "improvement_pct": m.improvement_pct,
            }
            for m in res.models
        ],
        "files": [str(p) for p in res.files],
    }

    def human() -> None:
        table = Table(title=f"thermocal demo (seed {res.seed}) — validation on a weakly "
                      "correlated run, bias in °/h")  # fmt: skip
        table.add_column("model")
        table.add_column("coeffs", justify="right")
        table.add_column("r", justify="right")
        table.add_column("stability before → after", justify="right")
        table.add_column("repeatability before → after", justify="right")
        table.add_column("improvement", justify="right")
        for m in res.models:
            imp = m.improvement_pct.get("bias_stability")
            table.add_row(
                m.label + (" (reported)" if m is res.models[0] else ""),
                str(m.n_coefficients),
                fmt(m.r, 3),
                f"{fmt(m.bias_stability_before)} → {fmt(m.bias_stability_after)}",
                f"{fmt(m.bias_repeatability_before)} → {fmt(m.bias_repeatability_after)}",
                "—" if imp is None else f"{imp:.1f} %",
            )
        stdout.print(table)
        stdout.print(f"files in [bold]{res.out_dir}[/bold] ({len(res.files)} written, "
                     f"{res.elapsed_s:.1f} s)")  # fmt: skip
        stdout.print(f"report: [bold]{res.report_path}[/bold]")

    emit(out, as_json, human)
