"""What every firmware output checks first: the data behind the calibration supported the
fit (:mod:`thermocal.export`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from thermocal.errors import ThermocalInputError

if TYPE_CHECKING:
    from thermocal.models.calibration import Calibration


def check_firmware_adequacy(cal: Calibration, path: str | Path, firmware: str | None) -> None:
    """Firmware output only from data that supported the fit
    (:func:`thermocal.adequacy.check_for_firmware`), for every triad that recorded the
    check and every channel; for ``firmware="ardupilot"`` also ArduPilot's own minimum
    sweep (:data:`thermocal.adequacy.ARDUPILOT_MIN_SPAN_C` [°C] between the channel's
    fitted temperature limits, unless the fit recorded the ``allow_narrow`` override).

    Parameters
    ----------
    cal : Calibration
        The calibration to export.
    path : str or Path
        Its file, named in messages.
    firmware : str or None
        ``"px4"``, ``"ardupilot"`` or ``None`` (C export).

    Returns
    -------
    None

    Raises
    ------
    ThermocalInputError
        When a triad's or channel's data did not support the fit, or the temperature span
        is narrower than ArduPilot's minimum.

    References
    ----------
    - ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
    """
    from thermocal.adequacy import ARDUPILOT_MIN_SPAN_C, check_for_firmware

    for tri in cal.triads:
        if tri.adequacy is not None:  # turntable calibrations since the check existed
            check_for_firmware(tri.adequacy, f"{path}: triad {tri.name}")
    for ch in cal.channels:
        where = f"{path}: channel {ch.name}" if len(cal.channels) > 1 else str(path)
        record = ch.model.adequacy_
        check_for_firmware(record, where)
        if firmware != "ardupilot":
            continue
        rng = ch.model.temp_range_
        span = float(rng[0, 1] - rng[0, 0]) if rng.size else 0.0
        overrides = (record or {}).get("overrides") or []
        allowed = "--allow-narrow" in overrides  # cli-words: a fit records overrides as options
        if span < ARDUPILOT_MIN_SPAN_C and not allowed:
            raise ThermocalInputError(
                f"{where}: the calibration covers {span:.3g} °C; ArduPilot's temperature "
                f"calibration needs ≥ {ARDUPILOT_MIN_SPAN_C:g} °C (refit on a wider sweep)"
            )
