"""Flight-controller logs' truth for the tests: one IMU's thermal biases over a sweep, and
the parameter files the firmware commands write, read back as a dict."""

from __future__ import annotations

from pathlib import Path

import numpy as np

G0 = 9.80665


def imu_truth(n: int, seed: int, scale: float) -> dict[str, np.ndarray]:
    """A −10…50 °C sweep and one IMU's thermal biases (rad/s, m/s²) plus noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.05
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 30.0
    gyro = scale * np.column_stack([0.002 + 0.004 * x - 0.001 * x**2, -0.003 * x, 0.006 * x**2])
    accel = np.column_stack(
        [0.05 + 0.08 * x * scale, -0.06 * x + 0.04 * x**3, -G0 + 0.1 * x * scale]
    )
    return {
        "time_us": (1_000_000 + t * 1e6).astype(np.int64),
        "temp": temp,
        "gyro": gyro,
        "accel": accel,
        "gyro_meas": gyro + rng.normal(0.0, 0.001, (n, 3)),
        "accel_meas": accel + rng.normal(0.0, 0.02, (n, 3)),
    }


def parm_file(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if line and not line.startswith("#"):
            name, value = line.split()
            out[name] = float(value)
    return out


def heated_truth(
    seed: int = 7,
    *,
    rate_hz: float = 20.0,
    ambient_c: float = 15.0,
    setpoint_c: float = 55.0,
    boot_s: float = 20.0,
    ramp_c_per_s: float = 0.06,
    overshoot_amp_c: float = 1.6,
    hold_s: float = 900.0,
    heater_off_s: float | None = None,
    after_s: float = 600.0,
    at_setpoint: bool = False,
) -> dict:
    """A heated IMU as a board with a heater records it, in the order it happens: boot at
    ambient (``boot_s``), the heater on at full power (a ramp of ``ramp_c_per_s``), the
    controller's overshoot past the set-point (a damped oscillation of ``overshoot_amp_c``,
    τ = 25 s, period 80 s), a hold with a ±0.2 °C ripple (period 45 s) plus a 0.03 °C
    thermometer noise (±0.3 °C), and optionally the heater turned off at ``heater_off_s``
    (log time: first-order cooling to ambient, τ = 300 s) or a log that starts already at
    the set-point.  Biases (rad/s, m/s²) are cubics in T plus noise.

    Truth: ``reached_s`` (log time, the ramp's crossing of the set-point), ``overshoot_c``
    and ``overshoot_at_s`` (the noiseless profile's peak)."""
    rng = np.random.default_rng(seed)
    t_ramp = (setpoint_c - ambient_c) / ramp_c_per_s
    t_reach = 0.0 if at_setpoint else boot_s + t_ramp
    end = t_reach + hold_s + (after_s if heater_off_s is not None else 0.0)
    t = np.arange(0.0, end, 1.0 / rate_hz)
    u = t - t_reach
    ramp = ambient_c + ramp_c_per_s * np.clip(t - boot_s, 0.0, None)
    over = overshoot_amp_c * np.exp(-u / 25.0) * np.sin(2 * np.pi * u / 80.0)
    clean = np.where(u < 0, ramp, setpoint_c + over)
    ripple = np.where(u < 0, 0.0, 0.2 * np.sin(2 * np.pi * t / 45.0))
    off_at = None
    if heater_off_s is not None:
        off_at = heater_off_s - 1.0  # log time = t + 1 s
        cool = off_at <= t
        start = float(np.interp(off_at, t, clean))
        clean = np.where(cool, ambient_c + (start - ambient_c) * np.exp(-(t - off_at) / 300.0),
                         clean)  # fmt: skip
        ripple = np.where(cool, 0.0, ripple)
    temp = clean + ripple + rng.normal(0.0, 0.03, t.size)
    k = int(np.argmax(np.where(u >= 0, clean, -np.inf)))
    x = (temp - 35.0) / 20.0
    gyro = np.column_stack(
        [0.002 + 0.004 * x - 0.001 * x**2, -0.003 * x, 0.006 * x**2 - 0.001 * x**3]
    )
    accel = np.column_stack([0.05 + 0.08 * x, -0.06 * x + 0.04 * x**3, -G0 + 0.1 * x])
    return {
        "time_us": (1_000_000 + t * 1e6).astype(np.int64),
        "time_s": t + 1.0,
        "temp": temp,
        "gyro": gyro,
        "accel": accel,
        "gyro_meas": gyro + rng.normal(0.0, 0.001, (t.size, 3)),
        "accel_meas": accel + rng.normal(0.0, 0.02, (t.size, 3)),
        "setpoint_c": setpoint_c,
        "reached_s": t_reach + 1.0,
        "overshoot_c": float(clean[k] - setpoint_c),
        "overshoot_at_s": float(t[k] + 1.0),
        "heater_off_s": heater_off_s,
    }


def heated_ulog(truth: dict, params: dict | None = None) -> bytes:
    """``truth`` (:func:`heated_truth`) as a PX4 ULog: ``sensor_gyro`` and ``sensor_accel``
    instance 0 with their temperature, ``params`` in the header."""
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    topics = []
    for name, dev, key in (
        ("sensor_gyro", 2293768, "gyro_meas"),
        ("sensor_accel", 2293776, "accel_meas"),
    ):
        rows = [
            (int(s), dev, *map(float, v), float(tt))
            for s, v, tt in zip(truth["time_us"], truth[key], truth["temp"], strict=True)
        ]
        topics.append((name, 0, SENSOR_FIELDS, rows))
    return ulog_bytes(topics, params)


def heated_dataflash(truth: dict, params: dict | None = None) -> bytes:
    """``truth`` as an ArduPilot DataFlash log: ``PARM`` messages, then ``IMU`` (instance 0)."""
    from dataflash_writer import IMU_FMT, IMU_LABELS, PARM_FORMAT, dataflash_log, parm

    msgs = [parm(k, float(v)) for k, v in (params or {}).items()]
    msgs += [
        (100, (int(s), 0, *map(float, g), *map(float, a), 0, 0, float(tt)))
        for s, g, a, tt in zip(truth["time_us"], truth["gyro_meas"], truth["accel_meas"],
                               truth["temp"], strict=True)
    ]  # fmt: skip
    return dataflash_log([PARM_FORMAT, (100, "IMU", IMU_FMT, IMU_LABELS)], msgs)
