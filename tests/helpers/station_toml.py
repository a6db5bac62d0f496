"""The ``[[sensor]]`` table of the station tests' STATION.toml: a gyro line ``gx,temp`` at
50 Hz on a serial port (what :class:`thermocal.station.sim.SimulatedSerialSensor` sends)."""

from __future__ import annotations


def sensor_toml(device: str, sid: str = "imu", stale_s: float | None = 0.5) -> str:
    """One sensor's table; ``stale_s`` None leaves the key out (the default applies)."""
    stale = "" if stale_s is None else f"stale_s = {stale_s}\n"
    return f"""
[[sensor]]
id = "{sid}"
device = "{device}"
baud = 115200
names = ["gx", "temp"]
units = ["deg/s", "degC"]
delimiter = ","
rate_hz = 50
{stale}"""
