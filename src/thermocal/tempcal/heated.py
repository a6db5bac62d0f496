"""The heater's hold of a flight controller's IMU, judged for ``px4-tempcal`` and
``ardupilot-tempcal``: the set-point from the log's parameters (:func:`thermocal.heater.
heater_setpoint`), the hold found and judged (:func:`thermocal.heater.judge_heater`).

The pipeline fits the medians of 0.5 °C temperature bins
(:func:`thermocal.firmware.binning.temperature_bins`), so the hold's samples at one
temperature fill one or two bins and weigh no more than any other stretch of the sweep: no
thinning is needed, and the notes say so.
"""

from __future__ import annotations

from collections.abc import Mapping

from thermocal.heater import HeaterJudgement, HeaterOptions, heater_setpoint, judge_heater
from thermocal.recording import FloatArray

BINNED_HOLD = (
    "the hold's samples reduce to the medians of its 0.5 °C bins (equal weight per bin), "
    "so it weighs no more than any other stretch of the sweep"
)
"""The note of a hold in a binned fit."""


def judge_instance(
    where: str,
    time_s: FloatArray,
    temp_c: FloatArray,
    params: Mapping[str, float],
    firmware: str,
    options: HeaterOptions,
    *,
    own_minus_c: float | None = None,
) -> HeaterJudgement:
    """One IMU instance's heater hold: the set-point given, else the log's parameter, else
    inferred; none looked for when the log's parameters say the heater is off.

    The firmware holds its own thermometer at the parameter's set-point: fitted on another
    thermometer (``temps_from``) that reads ``own_minus_c`` below the IMU's own, the hold
    is looked for at ``T_sp − own_minus_c`` on it, and its source says so.

    Parameters
    ----------
    where : str
        The instance in messages (``LOG: sensor_gyro.0``).
    time_s, temp_c : numpy.ndarray
        Its sample times [s] and temperature [°C].
    params : mapping of str to float
        The log's parameters at the start of the recording.
    firmware : {"px4", "ardupilot"}
        Whose parameters (:data:`thermocal.heater.HEATER_PARAMS`).
    options : HeaterOptions
        The policy, a set-point given, the band and the shortest hold.
    own_minus_c : float, optional
        The IMU's own thermometer less the one ``temp_c`` comes from (median) [°C]: the
        parameter's set-point converted by it (a set-point given is taken as given, in the
        temperature fitted on).

    Returns
    -------
    HeaterJudgement
        The hold (or None), notes and warnings (``keep`` is not used: the fit is binned).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Nothing but the hold in the log, or a range cut by the heater under ``refuse``.
    """
    setpoint, source = options.setpoint_c, "given"
    if setpoint is None:
        setpoint, found = heater_setpoint(params, firmware)
        if setpoint is None and found is not None:  # the heater off in the parameters
            return HeaterJudgement(None, None, (), ())
        source = found or "given"
        if setpoint is not None and own_minus_c:  # the firmware's own thermometer's scale
            source = (
                f"{found} {setpoint:g} °C on the IMU's own thermometer, which reads "
                f"{own_minus_c:+.2f} °C from the one fitted on"
            )
            setpoint -= own_minus_c
    judged = judge_heater(
        time_s, temp_c, where=where, policy=options.policy, setpoint_c=setpoint,
        setpoint_source=source, firmware=firmware, band_c=options.band_c,
        min_hold_s=options.min_hold_s,
    )  # fmt: skip
    if judged.hold is None:
        return judged
    return HeaterJudgement(judged.hold, None, (*judged.notes, BINNED_HOLD), judged.warnings)
