"""``thermocal demo [-o DIR]``: the whole chamber workflow on built-in simulated data.

Runs :func:`thermocal.demo.chamber.run_demo` (profiles → simulation → 37-term and
term-selected fits → validation → compensation → C export → HTML report) with a
progress bar on a terminal, then prints a short summary table and the report's path.
"""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import JsonOpt, emit, handle_errors, progress, show, stdout
from thermocal.outputs import check_outputs

if TYPE_CHECKING:
    import rich.markup as _markup

    import thermocal.demo.chamber as _demo
else:
    _markup = LazyModule("rich.markup")
    _demo = LazyModule("thermocal.demo.chamber")


OutputOpt = Annotated[
    Path, typer.Option("-o", "--output", help="Directory for the report, models and C files.")
]
SeedOpt = Annotated[int, typer.Option("--seed", help="Seed of the simulated data.")]
QuickOpt = Annotated[bool, typer.Option("--quick", help="Smaller data (5 s samples, fewer ramps).")]
ImuOpt = Annotated[
    bool,
    typer.Option(
        "--imu",
        help="The six-channel MEMS IMU workflow (gx..az, one die temperature) "
        "into one calibration, one C module and one report.",
    ),
]
StationOpt = Annotated[
    bool,
    typer.Option(
        "--station",
        help="The test station: a simulated chamber (Modbus TCP server) and serial IMU "
        "(pseudo-terminal) driven by the station, then fit, validate and export-c "
        "(needs thermocal[station]).",
    ),
]
TimeScaleOpt = Annotated[
    float, typer.Option("--time-scale", help="--station: run the programs K times faster.")
]


@app.command("demo")
@handle_errors
def demo_cmd(
    output: OutputOpt = Path("thermocal-demo"),
    seed: SeedOpt = 1,
    quick: QuickOpt = False,
    imu: ImuOpt = False,
    station: StationOpt = False,
    time_scale: TimeScaleOpt = 200.0,
    as_json: JsonOpt = False,
) -> None:
    """Simulate, fit, validate, compensate and export a ring-laser gyro model; write a report.

    With ``--imu``: the same for a six-channel MEMS IMU, into one calibration file.  With
    ``--station``: record a simulated chamber and serial IMU through the test station first.
    """
    from thermocal.errors import ThermocalInputError

    if imu and station:
        raise ThermocalInputError("--imu and --station are two demos: give one")
    if seed < 0:  # numpy's SeedSequence takes none (was exit 1 with a half-made folder)
        raise ThermocalInputError(f"--seed must be a non-negative integer, got {seed}")
    if imu and output == Path("thermocal-demo"):
        output = Path("thermocal-imu-demo")
    if station and output == Path("thermocal-demo"):
        output = Path("thermocal-station-demo")
    check_outputs([], [], dirs=[output])  # no FIFO, device, /proc… (the demo reads no file)
    if output.exists() and not output.is_dir():
        raise ThermocalInputError(f"{output}: exists and is not a directory")
    if imu:
        _imu_demo(output, seed, quick, as_json)
        return
    if station:
        _station_demo(output, time_scale, as_json)
        return
    _chamber_demo(output, seed, quick, as_json)


def _chamber_demo(output: Path, seed: int, quick: bool, as_json: bool) -> None:
    """:func:`thermocal.demo.chamber.run_demo` with a progress bar, then its summary."""
    with progress("thermocal demo", total=len(_demo.DEMO_STEPS)) as advance:
        res = _demo.run_demo(output, seed=seed, config=_demo.QUICK if quick else None,
                       progress=lambda _step: advance(1))  # fmt: skip

    def human() -> None:
        show(res.text())
        stdout.print(f"report: [bold]{_markup.escape(str(res.report_path))}[/bold]", markup=True)

    emit(res.to_dict(), as_json, human)


def _imu_demo(output: Path, seed: int, quick: bool, as_json: bool) -> None:
    from thermocal.demo.imu import IMU_STEPS, run_imu_demo

    with progress("thermocal demo --imu", total=len(IMU_STEPS)) as advance:
        res = run_imu_demo(output, seed=seed, rate_hz=0.2 if quick else 1.0,
                           progress=lambda _step: advance(1))  # fmt: skip

    def human() -> None:
        show(res.text())
        stdout.print(f"calibration: {_markup.escape(str(res.calibration_path))}")
        stdout.print(f"report: [bold]{_markup.escape(str(res.report_path))}[/bold]", markup=True)

    emit(res.to_dict(), as_json, human)


def _station_demo(output: Path, time_scale: float, as_json: bool) -> None:
    """:func:`thermocal.demo.station.run_demo`: the fitted thermal slope against the
    simulated sensor's."""
    from thermocal.demo.station import run_demo

    res = run_demo(output, time_scale)

    def human() -> None:
        stdout.print(
            f"fitted thermal slope {res['slope_deg_s_per_c']:.6f} deg/s/°C, simulated "
            f"{res['truth_deg_s_per_c']:.6f} deg/s/°C; everything in "
            f"{_markup.escape(str(res['out_dir']))}"
        )

    emit(dict(res), as_json, human)
