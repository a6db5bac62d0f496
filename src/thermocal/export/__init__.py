"""What the sensor's firmware loads.

c         plain C99 for the fitted models, calibrations and banks (with a test harness)
params    PX4 (``TC_*``, ``CAL_*``) and ArduPilot (``INS_TCAL*``) parameter files
"""
