"""The firmware's own learning emulated on a log, as text: one line per IMU (or sensor
instance) saying whether it would have completed and why, then a table of what it would
store against thermocal's coefficients, and for ArduPilot its ``TCLR`` points against the
log's.  Blocks of :mod:`thermocal.report.text`, printed by the command line.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from thermocal.report.text import Block, TextTable, fmt

if TYPE_CHECKING:
    from thermocal.tempcal.learning import ArdupilotEmulation, Px4Emulation


def ardupilot_learning_text(emulated: Mapping[str, ArdupilotEmulation]) -> list[Block]:
    """ArduPilot's in-flight learning emulated per IMU: its outcome and reason, the largest
    difference of its correction from thermocal's, its points against the log's ``TCLR``.

    Parameters
    ----------
    emulated : mapping of str to thermocal.tempcal.learning.ArdupilotEmulation
        Per IMU (``IMU.<n>``).

    Returns
    -------
    list of str or TextTable

    References
    ----------
    ArduPilot ``AP_InertialSensor_tempcal.cpp`` (``TCal::Learn``).
    """
    blocks: list[Block] = []
    rows = []
    for key, em in emulated.items():
        blocks.append(f"{key} firmware learning (emulated): {em.learning.reason}")
        if em.note:
            blocks.append(f"{key}: {em.note}")
        for kind, unit in (("gyro", "rad/s"), ("accel", "m/s^2")):
            m = em.tclr.get(kind)
            rows.append((
                key, kind, str(len(getattr(em.learning, f"{kind}_points"))),
                fmt(em.max_difference(kind), 3) + f" {unit}",
                "—" if m is None else f"{m.n_matched} of {m.n_logged}",
                "—" if m is None else fmt(m.max_temp_diff_c, 3),
                "—" if m is None else fmt(m.max_value_diff, 3) + f" {unit}",
            ))  # fmt: skip
    columns = ("IMU", "sensor", "points", "max |emulated − thermocal|", "TCLR paired",
               "max ΔTemp [°C]", "max ΔX/Y/Z")  # fmt: skip
    title = "The firmware's learning emulated against thermocal's fit and the log's TCLR"
    return [*blocks, TextTable(title, columns, tuple(rows), ("left",) * len(columns))]


def px4_learning_text(emulated: Mapping[str, Px4Emulation]) -> list[Block]:
    """PX4's on-board calibration emulated per sensor instance: its outcome and reason, its
    progress, the largest difference of its correction from thermocal's.

    Parameters
    ----------
    emulated : mapping of str to thermocal.tempcal.learning.Px4Emulation
        Per sensor instance (``sensor_gyro.<n>`` …).

    Returns
    -------
    list of str or TextTable

    References
    ----------
    PX4 ``temperature_calibration/task.cpp``, ``gyro.cpp``, ``accel.cpp``.
    """
    blocks: list[Block] = [
        f"{key} on-board calibration (emulated): {em.oncal.reason}" for key, em in emulated.items()
    ]
    rows = tuple(
        (key, em.oncal.outcome, f"{em.oncal.progress} %", str(em.oncal.n_fitted),
         fmt(em.max_difference(), 3) + (" rad/s" if em.oncal.kind == "gyro" else " m/s^2"))
        for key, em in emulated.items()
    )  # fmt: skip
    columns = ("sensor", "outcome", "progress", "samples fitted", "max |emulated − thermocal|")
    title = "PX4's on-board temperature calibration emulated against thermocal's fit"
    return [*blocks, TextTable(title, columns, rows, ("left",) * len(columns))]


__all__ = ["ardupilot_learning_text", "px4_learning_text"]
