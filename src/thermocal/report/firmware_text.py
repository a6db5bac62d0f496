"""Flight-controller calibrations as text: the sensors fitted from a PX4 or ArduPilot log,
as blocks of :mod:`thermocal.report.text` (lines and
:class:`~thermocal.report.text.TextTable`), printed by the command line or read in a notebook.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from thermocal.report.text import Block, TextTable, fmt

if TYPE_CHECKING:
    from thermocal.tempcal.ardupilot import ArdupilotTempcalResult
    from thermocal.tempcal.pipeline import SensorFit
    from thermocal.tempcal.px4 import OffsetFit, Px4TempcalResult


def px4_tempcal_text(res: Px4TempcalResult) -> list[Block]:
    """A PX4 thermal calibration: one row per sensor instance (device id, temperature sweep
    [°C], bins, hold-out rms per axis in the sensor's unit), then the run's notes.

    Parameters
    ----------
    res : thermocal.tempcal.px4.Px4TempcalResult
        The calibration of one log.

    Returns
    -------
    list of str or TextTable

    References
    ----------
    PX4 ``Tools/process_sensor_caldata.py`` and ``TemperatureCompensation.cpp``.
    """
    columns = ("sensor", "device id", "sweep [°C]", "bins", "hold-out rms x/y/z")
    fits: list[SensorFit | OffsetFit] = [*res.fits, *res.offset_fits]
    rows = tuple(
        (f"{f.topic}.{f.instance}", str(f.device_id), f"{f.sweep_c[0]:.1f}…{f.sweep_c[1]:.1f}",
         str(f.n_bins), " / ".join(fmt(v, 3) for v in f.holdout_rms.values()) + f" {f.unit}")
        for f in fits
    )  # fmt: skip
    title = f"PX4 thermal calibration of {res.log}"
    return [TextTable(title, columns, rows, ("left",) * len(columns)), *res.notes]


def ardupilot_tempcal_text(res: ArdupilotTempcalResult) -> list[Block]:
    """An ArduPilot thermal calibration: the INS_TCAL coefficients the log held beside the
    new ones (when the log had a calibration active), one row per IMU sensor (sweep [°C],
    bins, hold-out rms per axis), then the run's notes.

    Parameters
    ----------
    res : thermocal.tempcal.ardupilot.ArdupilotTempcalResult
        The calibration of one log.

    Returns
    -------
    list of str or TextTable

    References
    ----------
    ArduPilot ``AP_InertialSensor_tempcal.cpp``.
    """
    blocks: list[Block] = []
    if res.active_found:
        old_new = tuple(
            (n, fmt(v["old"], 6), fmt(v["new"], 6))
            for h in res.hygiene.values()
            for n, v in h.get("coefficients", {}).items()
            if v["old"] is not None
        )
        title = "INS_TCAL coefficients: in the log → new"
        blocks.append(TextTable(title, ("parameter", "old", "new"), old_new, ("left",) * 3))
    columns = ("IMU", "sensor", "sweep [°C]", "bins", "hold-out rms x/y/z")
    rows = tuple(
        (str(f.instance), f.kind, f"{f.sweep_c[0]:.1f}…{f.sweep_c[1]:.1f}", str(f.n_bins),
         " / ".join(fmt(float(v), 3) for v in f.holdout_rms.values()) + f" {f.unit}")
        for f in res.fits
    )  # fmt: skip
    title = f"ArduPilot thermal calibration of {res.log}"
    return [*blocks, TextTable(title, columns, rows, ("left",) * len(columns)), *res.notes]


__all__ = ["ardupilot_tempcal_text", "px4_tempcal_text"]
