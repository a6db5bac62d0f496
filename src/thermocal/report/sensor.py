"""The HTML report of one sensor of a flight-controller calibration, chosen by its request.

:func:`write_sensor_report` is the reporter that :func:`thermocal.tempcal.px4.px4_tempcal`
and :func:`thermocal.tempcal.ardupilot.ardupilot_tempcal` take: a gyro's or accelerometer's
calibration report (:func:`thermocal.report.calibration.write_calibration_report`, with the
coefficients active in the log compared), a barometer's or magnetometer's
(:func:`thermocal.report.tempcal.write_offset_report`) or ArduPilot's ``TCAL_BARO_EXP``
(:func:`thermocal.report.tempcal.write_ardupilot_baro_report`).  The module imports the
report machinery only when a report is written, so that the report worker, not the
process reading the log, pays for it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from thermocal.tempcal.pipeline import AnyReportRequest


def write_sensor_report(path: Path, req: AnyReportRequest) -> None:
    """Write one sensor's HTML report.

    Parameters
    ----------
    path : pathlib.Path
        The HTML file to write (atomically).
    req : thermocal.tempcal.pipeline.AnyReportRequest
        What the calibration pipeline asks to be reported: a
        :class:`~thermocal.tempcal.offset_report.OffsetReportRequest` (barometer,
        magnetometer), an :class:`~thermocal.tempcal.ardupilot_baro.ArdupilotBaroReportRequest`
        or a sensor's calibration request (gyro, accelerometer).
    """
    from thermocal.report.calibration import CalibrationReportInputs, write_calibration_report
    from thermocal.report.tempcal import comparison_html, write_offset_report
    from thermocal.tempcal.ardupilot_baro import ArdupilotBaroReportRequest
    from thermocal.tempcal.offset_report import OffsetReportRequest

    if isinstance(req, OffsetReportRequest):
        write_offset_report(path, req)
        return
    if isinstance(req, ArdupilotBaroReportRequest):  # TCAL_BARO_EXP
        from thermocal.report.tempcal import write_ardupilot_baro_report

        write_ardupilot_baro_report(path, req)
        return

    write_calibration_report(
        path,
        CalibrationReportInputs(
            calibration=req.calibration, recording=req.recording,
            recording_path=req.recording_path, title=req.title, sensor=req.sensor,
            generated_by=req.generated_by, extra=req.extra, notes=req.notes,
            appendix=tuple(
                comparison_html(c)
                for c in (req.previous, req.firmware_learning, req.emulated_learning)
                if c is not None
            ),
            allan=req.allan,
        ),
    )  # fmt: skip


def _warm_reports() -> None:
    """What the first report costs beyond its own work (the report modules imported, a
    bias grid drawn: fonts and tick labels; the template compiled), paid by the report
    worker while the log is read (:func:`thermocal.tempcal.pipeline.report_worker`)."""
    import numpy as np

    from thermocal.report import calibration as _calibration  # noqa: F401
    from thermocal.report import figures as F
    from thermocal.report.build import _env

    _env().get_template("calibration.html.j2")  # compiled once, here

    t = np.linspace(0.0, 1.0, 50)
    F.bias_vs_temperature_grid([F.ChannelBias("x", "unit", "T", t, t, t)] * 3)


write_sensor_report.warm = _warm_reports  # type: ignore[attr-defined]

__all__ = ["write_sensor_report"]
