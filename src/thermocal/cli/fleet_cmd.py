"""``thermocal fleet CONFIG.toml -o DIR [--workers N] [--scheduler ADDRESS] [--force]``:
one calibration per unit of a production batch (:mod:`thermocal.fleet.batch`).

Exit status 0 when every unit was calibrated, 4 when some failed (each recorded with its
error; the others went on), 2 for a bad configuration.
"""

import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import JsonOpt, emit, handle_errors, progress, stdout

if TYPE_CHECKING:
    from thermocal.fleet import batch as _fleet
else:
    _fleet = LazyModule("thermocal.fleet.batch")


@app.command("fleet")
@handle_errors
def fleet_cmd(
    config: Annotated[Path, typer.Argument(help="Fleet configuration (TOML).", show_default=False)],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output directory.")],
    workers: Annotated[
        int | None,
        typer.Option(
            "--workers",
            help="Local worker processes (default: the number of CPUs; 1 runs in this process).",
        ),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            help="Dask distributed scheduler, tcp://HOST:PORT (needs thermocal[fleet]).",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Redo units already calibrated in DIR.")
    ] = False,
    as_json: JsonOpt = False,
) -> None:
    """Calibrate every unit of a production batch: the [fit] options once, one [[unit]] per
    device (modelling files, optional validation file), pass/fail [limits]; per unit
    DIR/units/<id>/, then DIR/summary.csv, DIR/summary.parquet and DIR/fleet.html.  A rerun
    resumes where a stopped batch left off, redoing the units whose inputs, options or
    thermocal version changed or whose folder does not verify (JSON ``redone``: id → why).
    Every figure is in its channel's data unit.  Refused (exit 2, nothing written) when an
    output path is, or holds, one of the inputs, or is a special file."""
    cfg = _fleet.load_config(config)
    _fleet.check_workers(workers, scheduler)
    # inputs are sacred: run_fleet refuses an output that is or holds one before writing
    n_workers = workers if workers is not None else max(1, min(os.cpu_count() or 1, len(cfg.units)))
    with progress("units", total=len(cfg.units)) as advance:

        def on_unit(outcome: "_fleet.UnitOutcome") -> None:
            advance(1)
            if outcome.status != "ok" and not as_json:
                print(f"warning: unit {outcome.id}: {outcome.error}", file=sys.stderr)

        res = _fleet.run_fleet(
            cfg, output, workers=n_workers, scheduler=scheduler, force=force, on_unit=on_unit
        )
    out = res.summary(output)

    def human() -> None:
        lines, n = res.text(), len(res.redone)
        stdout.print(lines[0])
        for line in lines[1 : 1 + n]:  # ids and reasons as they are
            stdout.print(line, markup=False, highlight=False)
        for line in lines[1 + n :]:
            stdout.print(line)

    emit(out, as_json, human)
    if res.interrupted:
        print(f"error: {res.interrupted}", file=sys.stderr)
    if out["failed"] or res.interrupted or out["pending"]:
        raise typer.Exit(_fleet.EXIT_SOME_FAILED)
