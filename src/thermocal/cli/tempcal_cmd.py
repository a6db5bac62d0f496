"""``thermocal px4-tempcal LOG.ulg -o DIR`` and ``thermocal ardupilot-tempcal LOG.bin -o DIR``:
a flight controller's thermal calibration from one log.

The library does the work (:func:`thermocal.tempcal.px4.px4_tempcal`,
:func:`thermocal.tempcal.ardupilot.ardupilot_tempcal`, one pipeline:
:mod:`thermocal.tempcal.pipeline`); this module parses the options, gives the report writer
(:func:`thermocal.report.sensor.write_sensor_report`) and prints the result.
"""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import typer

from thermocal.cli.application import app
from thermocal.cli.common import (
    AllowMotionOpt,
    AllowNarrowOpt,
    HeaterBandOpt,
    HeaterMinHoldOpt,
    HeaterOpt,
    HeaterSetpointOpt,
    JsonOpt,
    emit,
    handle_errors,
    show,
    stdout,
)
from thermocal.defaults import overrides_of
from thermocal.report import firmware_text as _firmware_text

if TYPE_CHECKING:
    from thermocal.heater import HeaterOptions
    from thermocal.tempcal.ardupilot import ArdupilotTempcalResult
    from thermocal.tempcal.px4 import Px4TempcalResult
    from thermocal.tempcal.thermometers import TempsFrom

OutDirOpt = Annotated[Path, typer.Option("-o", "--output", help="Directory to write.")]
TemperatureOpt = Annotated[
    str,
    typer.Option(
        "--temperature",
        help="reconstructed: a quantised or slow thermometer (a lattice of 0.1 °C or more, "
        "updated every second or slower) is fitted on the temperature reconstructed at each "
        "sample; raw: on its reading as logged.",
    ),
]
TempsFromOpt = Annotated[
    str | None,
    typer.Option(
        "--temps-from",
        help="Calibrate against another thermometer, joined by time: N (IMU instance N's), "
        "baro (the first barometer's); TARGETS=SOURCE for some instances only, e.g. 0=1 or "
        "0,2=baro (default: every instance its own).",
    ),
]
EmulateOpt = Annotated[
    bool,
    typer.Option(
        "--emulate-learning",
        help="Also run the firmware's own temperature learning on the log's samples, as its "
        "source defines it: would it have completed, why not, what it would store against "
        "thermocal's fit (and, for ArduPilot, its TCLR points against the log's).",
    ),
]


def parse_temps_from(text: str | None) -> "TempsFrom | None":
    """``"1"``, ``"baro"``, ``"0=1"``, ``"0,2=baro"`` → :class:`TempsFrom`.

    Parameters
    ----------
    text : str or None
        The option's text.

    Returns
    -------
    TempsFrom or None

    Raises
    ------
    ThermocalInputError
        Not of that form.
    """
    from thermocal.errors import ThermocalInputError
    from thermocal.tempcal.thermometers import TempsFrom

    if text is None:
        return None
    targets_text, _eq, source_text = text.strip().rpartition("=")
    source_text = source_text.strip().lower()
    try:
        source: int | str = "baro" if source_text == "baro" else int(source_text)
        targets = (
            tuple(int(t) for t in targets_text.split(",")) if _eq else None
        )  # fmt: skip
    except ValueError:
        raise ThermocalInputError(
            f"--temps-from {text!r}: give an instance number, baro, or TARGETS=SOURCE "
            "(e.g. 1, baro, 0=1, 0,2=baro)"
        ) from None
    return TempsFrom(source, targets)  # type: ignore[arg-type]


def _temperature_mode(text: str) -> "Literal['reconstructed', 'raw']":
    """``--temperature``'s text checked."""
    from thermocal.errors import ThermocalInputError

    low = text.strip().lower()
    if low not in ("reconstructed", "raw"):
        raise ThermocalInputError(f"--temperature {text!r}: give reconstructed or raw")
    return "raw" if low == "raw" else "reconstructed"


def heater_options(
    heater: str, setpoint: float | None, band: float, min_hold: float
) -> "HeaterOptions":
    """``--heater``, ``--heater-setpoint``, ``--heater-band`` and ``--heater-min-hold`` as
    the library's options."""
    from thermocal.heater import HeaterOptions

    return HeaterOptions(heater, setpoint, band, min_hold)  # type: ignore[arg-type]


M_MMAP_THRESHOLD = -3
"""glibc's ``mallopt`` parameter of the size from which a block is a mapping of its own."""


def _freed_arrays_given_back() -> None:
    """On glibc, every block of 128 KiB or more (a log's arrays and their temporaries) a
    mapping of its own, returned to the system when freed: ``mallopt(M_MMAP_THRESHOLD)``,
    which also stops glibc from raising that threshold to the size of each large block
    freed (then the next temporaries come from the heap, which keeps them: ~20 MB of a
    50 MB log's peak).  Elsewhere nothing."""
    import contextlib
    import ctypes
    import sys

    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(OSError, AttributeError):  # not glibc
        ctypes.CDLL("libc.so.6").mallopt(M_MMAP_THRESHOLD, 128 * 1024)


@app.command("px4-tempcal")
@handle_errors
def px4_tempcal_cmd(
    log: Annotated[Path, typer.Argument(help="PX4 log (.ulg).", show_default=False)],
    output: OutDirOpt,
    tref: Annotated[
        float | None,
        typer.Option("--tref", help="Reference temperature [°C] (default: mid-range)."),
    ] = None,
    allow_narrow: AllowNarrowOpt = False,
    allow_motion: AllowMotionOpt = False,
    as_json: JsonOpt = False,
    allan: Annotated[
        bool,
        typer.Option(
            "--allan",
            help="Draw each axis's Allan deviation before and after compensation in the "
            "gyro and accelerometer reports (slower on a long log).",
        ),
    ] = False,
    heater: HeaterOpt = "cut",
    heater_setpoint: HeaterSetpointOpt = None,
    heater_band: HeaterBandOpt = 0.5,
    heater_min_hold: HeaterMinHoldOpt = 60.0,
    emulate_learning: EmulateOpt = False,
    temperature: TemperatureOpt = "reconstructed",
    temps_from: TempsFromOpt = None,
) -> None:
    """Fit every gyro and accelerometer instance of a PX4 log as PX4 would (a cubic per axis
    about TREF), robust to spikes, with equal weight across the temperature range and
    judged on held-out data; write the TC_* parameters, the calibration and reports."""
    from thermocal.report.sensor import write_sensor_report
    from thermocal.tempcal.px4 import px4_tempcal

    _freed_arrays_given_back()

    res = px4_tempcal(
        log, output, tref_c=tref, overrides=overrides_of(allow_narrow, allow_motion),
        reporter=write_sensor_report, allan=allan, emulate_learning=emulate_learning,
        heater=heater_options(heater, heater_setpoint, heater_band, heater_min_hold),
        temperature=_temperature_mode(temperature), temps_from=parse_temps_from(temps_from),
    )  # fmt: skip
    emit(res.to_dict(), as_json, lambda: _print_px4(res))


def _print_px4(res: "Px4TempcalResult") -> None:
    show(_firmware_text.px4_tempcal_text(res))
    if res.emulated_learning:
        from thermocal.report.learning_text import px4_learning_text

        show(px4_learning_text(res.emulated_learning))
    stdout.print(f"parameters: [bold]{res.params_path}[/bold]", markup=True)


@app.command("ardupilot-tempcal")
@handle_errors
def ardupilot_tempcal_cmd(
    log: Annotated[Path, typer.Argument(help="ArduPilot log (.bin).", show_default=False)],
    output: OutDirOpt,
    allow_narrow: AllowNarrowOpt = False,
    allow_motion: AllowMotionOpt = False,
    as_json: JsonOpt = False,
    allan: Annotated[
        bool,
        typer.Option(
            "--allan",
            help="Draw each axis's Allan deviation before and after compensation in the "
            "gyro and accelerometer reports (slower on a long log).",
        ),
    ] = False,
    heater: HeaterOpt = "cut",
    heater_setpoint: HeaterSetpointOpt = None,
    heater_band: HeaterBandOpt = 0.5,
    heater_min_hold: HeaterMinHoldOpt = 60.0,
    emulate_learning: EmulateOpt = False,
    temperature: TemperatureOpt = "reconstructed",
    temps_from: TempsFromOpt = None,
) -> None:
    """ArduPilot's thermal calibration from one DataFlash log: every IMU instance's gyro
    and accelerometer fitted as in px4-tempcal, written as INS_TCAL* (.parm), a calibration
    and reports (the polynomial about 35 °C without constant, as the firmware takes it)."""
    from thermocal.report.sensor import write_sensor_report
    from thermocal.tempcal.ardupilot import ardupilot_tempcal

    _freed_arrays_given_back()

    res = ardupilot_tempcal(
        log, output, overrides=overrides_of(allow_narrow, allow_motion),
        reporter=write_sensor_report, allan=allan, emulate_learning=emulate_learning,
        heater=heater_options(heater, heater_setpoint, heater_band, heater_min_hold),
        temperature=_temperature_mode(temperature), temps_from=parse_temps_from(temps_from),
    )  # fmt: skip
    emit(res.to_dict(), as_json, lambda: _print_ardupilot(res))


def _print_ardupilot(res: "ArdupilotTempcalResult") -> None:
    show(_firmware_text.ardupilot_tempcal_text(res))
    if res.emulated_learning:
        from thermocal.report.learning_text import ardupilot_learning_text

        show(ardupilot_learning_text(res.emulated_learning))
    stdout.print(f"parameters: [bold]{res.params_path}[/bold]", markup=True)
