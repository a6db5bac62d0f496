"""Demonstrations on built-in, simulated data (``thermocal demo``).

chamber   one gyro in a chamber: simulate, fit, validate, compensate, export, report
imu       a whole IMU (three gyros, three accelerometers)
station   a simulated chamber and serial IMU driven by ``thermocal station run``
"""
