"""``thermocal simulate SCENARIO -o OUT [--seed N] [--profile FILE.csv] [--truth TRUTH.json]``.

Scenarios (:data:`thermocal.simulate.SCENARIOS`): ``rlg-modelling``,
``rlg-validation``, ``fog-slow``, ``mems-warmup`` (one file per start
temperature), ``accel-full-range`` (one file per run), ``turntable-16``.

Output naming:

* one file: ``-o run.csv`` (or ``.parquet``) writes that file (a CSV gets its
  ``.meta.json`` sidecar);
* several files: ``-o DIR`` (no data extension) writes
  ``DIR/<scenario>_<label>.csv`` (``--format parquet`` for Parquet), e.g.
  ``DIR/mems-warmup_T+25.csv``; ``-o out/warm.csv`` is a stem and writes
  ``out/warm_T+25.csv`` …;
* ``--truth TRUTH.json`` writes every parameter, with one entry per file under
  ``files`` (``file`` is the path written).
"""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import AxisOpt, JsonOpt, LatitudeOpt, emit, handle_errors, stdout
from thermocal.errors import FileFormatError, ThermocalInputError
from thermocal.outputs import check_outputs

if TYPE_CHECKING:
    import thermocal.outputs as _outputs
    import thermocal.profiles as _profiles
    import thermocal.readers as _readers
    import thermocal.readers.program as _program
    import thermocal.simulate as _simulate
    import thermocal.writers as _writers
else:
    _outputs = LazyModule("thermocal.outputs")
    _readers = LazyModule("thermocal.readers")
    _writers = LazyModule("thermocal.writers")
    _profiles = LazyModule("thermocal.profiles")
    _program = LazyModule("thermocal.readers.program")
    _simulate = LazyModule("thermocal.simulate")


def output_paths(output: Path, scenario: str, labels: list[str], fmt: str) -> list[Path]:
    """File names for the results of a scenario (see the module docstring)."""
    try:
        _readers.file_kind(output)
        is_file = True
    except FileFormatError:
        is_file = False
    if is_file:
        if len(labels) == 1:
            return [output]
        name = output.name
        suffix = next(
            s for s in (".csv.gz", ".parquet", ".csv", ".txt", ".pq") if name.lower().endswith(s)
        )
        stem = name[: -len(suffix)]
        return [output.with_name(f"{stem}_{lab}{suffix}") for lab in labels]
    ext = {"csv": ".csv", "parquet": ".parquet"}.get(fmt)
    if ext is None:
        raise ThermocalInputError(f"--format must be csv or parquet, got {fmt!r}")
    if output.exists() and not output.is_dir():
        raise ThermocalInputError(f"{output}: exists and is not a directory")
    return [output / (f"{scenario}_{lab}{ext}" if lab else f"{scenario}{ext}") for lab in labels]


def _early_gate(output: Path, truth: Path | None, inputs: list[str | Path]) -> None:
    """Refuse outputs over the inputs or on special files before simulating
    (:func:`thermocal.outputs.check_outputs`; the files named after the results are
    checked again once known)."""
    try:
        _readers.file_kind(output)
        files, dirs = [output], []
    except FileFormatError:
        files, dirs = [], [output]
    check_outputs([*files, *([truth] if truth is not None else [])], inputs, dirs=dirs)


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
        "the --poses object, in the truth).",
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
    fmt: FormatOpt = "csv",
    as_json: JsonOpt = False,
) -> None:
    """A simulated recording (or several) with known truth."""
    if scenario not in defaults.SCENARIO_NAMES:
        raise ThermocalInputError(
            f"unknown scenario {scenario!r}; known scenarios: {', '.join(defaults.SCENARIO_NAMES)}"
        )
    opts = _simulate.SimulateOptions(
        rate_hz, latitude, axis, runs, orientation, record_s, run, turns or None
    )
    inputs: list[str | Path] = [profile] if profile is not None else []
    _early_gate(output, truth, inputs)
    prog = _program.read_program(profile) if profile is not None else None
    sim = _simulate.simulate_scenario(scenario, seed, prog, opts)
    paths = output_paths(output, scenario, list(sim.labels), fmt)
    sidecars = [_outputs.sidecar_path(p) for p in paths if _readers.file_kind(p) == "csv"]
    check_outputs([*paths, *sidecars], inputs, dirs=[p.parent for p in paths])
    if truth is not None:
        _writers.check_not_input(truth, [*inputs, *paths])
    for (rec, _), p in zip(sim.results, paths, strict=True):
        _writers.write_recording(rec, p)
    if truth is not None:
        profile_name = str(profile) if profile is not None else None
        _writers.write_json(truth, sim.truth_document([str(p) for p in paths], profile_name))
    summary = {
        "scenario": scenario,
        "seed": seed,
        "files": [str(p) for p in paths],
        "n_samples": [rec.n_samples for rec, _ in sim.results],
        "truth": str(truth) if truth is not None else None,
    }

    def human() -> None:
        for (rec, _), p in zip(sim.results, paths, strict=True):
            stdout.print(
                f"{p}: {rec.n_samples} samples, {rec.duration_s / 3600:.2f} h at "
                f"{rec.sample_rate_hz:g} Hz"
            )
        if truth is not None:
            stdout.print(f"truth → {truth}")

    emit(summary, as_json, human)
