"""Temperature calibration from flight-controller logs: PX4 (ULog) and ArduPilot (DataFlash).

px4       the PX4 pipeline: read the sensor topics, judge the data, fit, hold-out check, ``TC_*``
"""
