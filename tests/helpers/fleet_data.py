"""Production-batch files for the fleet tests, written the way a lab's logger writes them: one
CSV per run, units only in the column names (a gyro in °/s, one in rad/s, an accelerometer
in mg), a still sensor in a chamber swept over 70 °C (modelling) or cycled 5–45 °C
(validation).  The truth (bias and slope per channel, noise) is returned with the files."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

TEMP = "T1 [degC]"
CHANNELS = {
    # column: (bias, slope per °C, noise σ), in the column's own unit
    "gx [deg/s]": (0.5, 0.002, 0.01),
    "gy [rad/s]": (0.004, 3.0e-5, 2.0e-4),
    "az [mg]": (20.0, 0.15, 0.8),
}
N_MODEL = 3000
"""Modelling run: 3000 s at 1 Hz, −10 → 60 °C (1.4 °C/min, a still sensor)."""
N_VAL = 2000
"""Validation run: 2000 s at 1 Hz, 25 ± 20 °C."""


@dataclass(frozen=True)
class Run:
    """One written run: its path and the values written (as read back from the CSV)."""

    path: Path
    frame: pd.DataFrame


def write_run(path: Path, seed: int, *, noise_scale: float = 1.0, validation: bool = False) -> Run:
    """One run of every channel of :data:`CHANNELS` (noise × ``noise_scale``)."""
    rng = np.random.default_rng(seed)
    n = N_VAL if validation else N_MODEL
    t = np.arange(n, dtype=np.float64)
    temp = 25.0 + 20.0 * np.sin(2 * np.pi * t / n) if validation else np.linspace(-10, 60, n)
    cols: dict[str, np.ndarray] = {"time [s]": t}
    for name, (bias, slope, sigma) in CHANNELS.items():
        cols[name] = bias + slope * (temp - 25.0) + rng.normal(0.0, sigma * noise_scale, n)
    cols[TEMP] = temp
    pd.DataFrame(cols).to_csv(path, index=False, float_format="%.12g")
    return Run(path, pd.read_csv(path))  # the values as the file holds them


def config_text(
    units: Mapping[str, tuple[str, str | None]], limits: str = "", extra: str = ""
) -> str:
    """A fleet configuration: poly order 1 on every channel of :data:`CHANNELS`,
    ``units``: id → (modelling file, validation file or None), relative to the config."""
    signal = ", ".join(f'"{c}"' for c in CHANNELS)
    text = (
        f'[fit]\nmodel = "poly"\norder = 1\nsignal = [{signal}]\ntemps = "{TEMP}"\n\n'
        "[validate]\naveraging = 10\n\n"
    )
    if extra:
        text += extra + "\n\n"
    if limits:
        text += limits + "\n\n"
    for uid, (mod, val) in units.items():
        text += f'[[unit]]\nid = "{uid}"\nmodeling = ["{mod}"]\n'
        if val is not None:
            text += f'validation = "{val}"\n'
        text += "\n"
    return text
