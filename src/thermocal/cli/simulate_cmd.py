"""``thermocal simulate SCENARIO -o OUT [--seed N] [--profile FILE.csv] [--truth TRUTH.json]``.

Scenarios (:data:`thermocal.simulate.SCENARIOS`): ``rlg-modelling``,
``rlg-validation``, ``fog-slow``, ``mems-warmup`` (one file per start
temperature), ``accel-full-range`` (one file per run), ``turntable-16``.

The library does the work (:func:`thermocal.pipeline.simulate.simulate_files`, which
also names the files: one recording ``-o run.csv``, several ``-o DIR`` or a stem
``-o out/warm.csv``); this module parses the options and prints what was written.
"""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import AxisOpt, JsonOpt, LatitudeOpt, emit, handle_errors, stdout

if TYPE_CHECKING:
    import thermocal.pipeline.simulate as _files
    import thermocal.simulate as _simulate
else:
    _files = LazyModule("thermocal.pipeline.simulate")
    _simulate = LazyModule("thermocal.simulate")


ScenarioArg = Annotated[
    str,
    typer.Argument(
        help="Scenario: " + ", ".join(defaults.SCENARIO_NAMES) + ".", show_default=False
    ),
]
SimOutOpt = Annotated[
    Path,
    typer.Option(
        "-o", "--output", help="Output file (one result), directory or file stem (several)."
    ),
]
SeedOpt = Annotated[int, typer.Option("--seed", help="Random seed (same seed, same file).")]
ProfileOpt = Annotated[
    Path | None,
    typer.Option("--profile", help="Chamber program CSV (time_s, setpoint_c) to run instead."),
]
TruthOpt = Annotated[
    Path | None, typer.Option("--truth", help="Write every true parameter to this JSON.")
]
RateHzOpt = Annotated[float | None, typer.Option("--rate-hz", help="Output sample rate [Hz].")]
RunsOpt = Annotated[int | None, typer.Option("--runs", help="Number of runs (accel-full-range).")]
OrientationOpt = Annotated[
    str | None,
    typer.Option("--orientation", help="horizontal, up or down (accel-full-range)."),
]
RecordOpt = Annotated[
    float | None, typer.Option("--record-s", help="Record per power-on [s] (mems-warmup).")
]
RunOpt = Annotated[
    str | None,
    typer.Option("--run", help="modelling or validation (mems-imu: the same unit)."),
]
TurnsOpt = Annotated[
    bool,
    typer.Option(
        "--turns",
        help="multipos: Ferraris sessions, the six faces and 360° turns (their sections, "
        "the --poses object, in the truth); tumble: a continuous tumble at 2 °/s instead of "
        "the dividing head's stations.",
    ),
]
NoRateColumnOpt = Annotated[
    bool,
    typer.Option(
        "--no-rate-column",
        help="ratetable: no table rate column, the record started before the program "
        "(analyse with ratetable --rates … --dwell 20s).",
    ),
]
FormatOpt = Annotated[str, typer.Option("--format", help="File format inside an output directory.")]


@app.command("simulate")
@handle_errors
def simulate_cmd(
    scenario: ScenarioArg,
    output: SimOutOpt,
    seed: SeedOpt = 0,
    profile: ProfileOpt = None,
    truth: TruthOpt = None,
    rate_hz: RateHzOpt = None,
    latitude: LatitudeOpt = None,
    axis: AxisOpt = None,
    runs: RunsOpt = None,
    orientation: OrientationOpt = None,
    record_s: RecordOpt = None,
    run: RunOpt = None,
    turns: TurnsOpt = False,
    no_rate_column: NoRateColumnOpt = False,
    fmt: FormatOpt = "csv",
    as_json: JsonOpt = False,
) -> None:
    """A simulated recording (or several) with known truth."""
    _files.check_scenario(scenario)
    opts = _simulate.SimulateOptions(
        rate_hz,
        latitude,
        axis,
        runs,
        orientation,
        record_s,
        run,
        turns or None,
        rate_column=False if no_rate_column else None,
    )
    res = _files.simulate_files(
        scenario, output, seed=seed, profile=profile, truth=truth, options=opts, file_format=fmt
    )

    def human() -> None:
        for (rec, _), p in zip(res.simulation.results, res.paths, strict=True):
            stdout.print(
                f"{p}: {rec.n_samples} samples, {rec.duration_s / 3600:.2f} h at "
                f"{rec.sample_rate_hz:g} Hz"
            )
        if truth is not None:
            stdout.print(f"truth → {truth}")

    emit(res.to_dict(), as_json, human)
