"""A simulated IMU at rest in a chamber whose white noise depends on temperature: what a
lab records for noise over temperature (steps with a heater overshoot, ramps between them,
a coarse thermometer), with the truth to test against."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

FS_HZ = 100.0
DT_S = 1.0 / FS_HZ
N25 = 1.0e-4  # gyro white-noise density at 25 °C [rad/s/√Hz]
DN_PER_C = 0.02  # its relative change per °C (the truth of the trend: 2e-6 rad/s/√Hz/°C)


def gyro_density(temp_c: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The true gyro density N(T) = N25·(1 + 0.02·(T − 25)) [rad/s/√Hz]."""
    return N25 * (1.0 + DN_PER_C * (np.asarray(temp_c, dtype=np.float64) - 25.0))


def chamber(
    rng: np.random.Generator,
    setpoints: tuple[float, ...] = (10.0, 25.0, 40.0, 55.0),
    hold_s: float = 600.0,
    ramp_c_per_min: float = 2.0,
    step_c: float = 0.5,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The true chamber temperature and the thermometer's reading at FS_HZ: holds of
    ``hold_s`` at each set-point after the first entered with a 1.5 °C overshoot decaying
    with τ = 60 s, ramps of ``ramp_c_per_min`` between; the reading noisy (0.05 °C) and
    rounded to ``step_c``."""
    parts = []
    for i, sp in enumerate(setpoints):
        if i:
            prev = setpoints[i - 1]
            n = int(abs(sp - prev) / ramp_c_per_min * 60.0 * FS_HZ)
            parts.append(np.linspace(prev, sp, n, endpoint=False))
        k = np.arange(int(hold_s * FS_HZ)) * DT_S
        parts.append(sp + (1.5 * np.exp(-k / 60.0) if i else 0.0 * k))
    true = np.concatenate(parts)
    reading = np.round((true + rng.normal(0.0, 0.05, true.size)) / step_c) * step_c
    return true, reading


def white(rng: np.random.Generator, density: npt.ArrayLike, n: int) -> npt.NDArray[np.float64]:
    """White noise of continuous-time density ``density`` (per sample σ = N/√Δt)."""
    return rng.standard_normal(n) * np.asarray(density, dtype=np.float64) / np.sqrt(DT_S)
