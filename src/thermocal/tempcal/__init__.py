"""Temperature calibration from flight-controller logs: PX4 (ULog) and ArduPilot (DataFlash).

The workflow layer: it reads the log, judges it, fits and writes the calibration set; the
firmware maths it uses are pure functions in :mod:`thermocal.firmware`.

flightlog  a log read once and passed down: a PX4 ULog
           (:class:`~thermocal.tempcal.flightlog.FlightLog`) or an ArduPilot DataFlash log
           (:class:`~thermocal.tempcal.flightlog.DataflashFlightLog`)
pipeline   the one pipeline both share: judge the data (:mod:`thermocal.adequacy`), bin, hold-out
           check, fit a cubic per axis, the gates, the output set written whole
px4        the PX4 dialect: ``sensor_*`` topics, ``TC_*`` parameters, TREF mid-range;
           :func:`~thermocal.tempcal.px4.px4_tempcal`
ardupilot  the ArduPilot dialect: ``IMU`` messages, ``INS_TCAL*`` parameters about 35 °C, the
           log's hygiene; :func:`~thermocal.tempcal.ardupilot.ardupilot_tempcal`
"""
