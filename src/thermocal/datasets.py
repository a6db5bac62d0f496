"""Small example recordings shipped inside the package.

* ``tvac``: a thermal-vacuum test log as real units write it — 5-second bursts at
  50 Hz once every ~5 minutes for two hours, time in milliseconds, temperature
  in raw ADC counts (``T[°C] = 0.0625·counts − 50``), and a few spike samples.
  ``thermocal inspect`` reports the bursts as gaps; the pre-processing computes
  rates per burst and never across a gap.

:func:`make_tvac_log` regenerates the shipped file exactly (seeded), so tests
can check the file against its recipe.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from thermocal._lazy import LazyModule

if TYPE_CHECKING:
    import pandas as pd
else:
    pd = LazyModule("pandas")

EXAMPLES = {"tvac": "tvac_bursts.csv"}
"""Name of each shipped example → its file in ``thermocal/data``."""
TVAC_COUNTS_GAIN_C = 0.0625
"""Gain of the ``tvac`` temperature counts [°C/count]."""
TVAC_COUNTS_OFFSET_C = -50.0
"""Offset of the ``tvac`` temperature counts [°C]: ``T = 0.0625·counts − 50``."""
TVAC_SPIKE_ROWS = (1_337, 4_020, 5_555)
"""Rows of the ``tvac`` log that hold a +30 °/h spike."""


def example_path(name: str) -> Path:
    """Path of a shipped example recording (``tvac``).

    Parameters
    ----------
    name : str
        The example's name, a key of :data:`EXAMPLES`.

    Returns
    -------
    pathlib.Path
        The file inside the installed package.

    Raises
    ------
    KeyError
        ``name`` is not a shipped example (the message lists them).

    Examples
    --------
    >>> example_path("tvac").name
    'tvac_bursts.csv'
    """
    if name not in EXAMPLES:
        raise KeyError(f"unknown example {name!r}; known: {', '.join(EXAMPLES)}")
    return Path(str(resources.files("thermocal") / "data" / EXAMPLES[name]))


def make_tvac_log(seed: int = 7) -> pd.DataFrame:
    """The ``tvac`` example as a DataFrame (columns ``time_ms``, ``gyro deg/h``, ``temp_counts``).

    24 bursts of 250 samples at 50 Hz, bursts starting every 300 s ± 5 s; the
    sensor temperature falls from +25 °C towards −10 °C with a 40-minute time
    constant; the gyro reads 0.5 °/h + 0.01 °/h/°C·(T − 25) + white noise
    (0.05 °/h rms); three spikes of +30 °/h.

    Parameters
    ----------
    seed : int
        Seed of :func:`numpy.random.default_rng`; 7 gives the shipped file.

    Returns
    -------
    pandas.DataFrame
        6000 rows: ``time_ms`` [ms], ``gyro deg/h`` [°/h], ``temp_counts`` [counts].

    Examples
    --------
    >>> df = make_tvac_log()
    >>> df.shape
    (6000, 3)
    >>> float(df["temp_counts"].iloc[0]) * TVAC_COUNTS_GAIN_C + TVAC_COUNTS_OFFSET_C  # [°C]
    25.0
    """
    rng = np.random.default_rng(seed)
    starts_s = np.arange(24) * 300.0 + rng.uniform(-5.0, 5.0, 24)
    starts_s[0] = 0.0
    t_s = (starts_s[:, None] + np.arange(250)[None, :] * 0.02).ravel()
    temp_c = -10.0 + 35.0 * np.exp(-t_s / 2400.0)
    counts = np.round(
        (temp_c - TVAC_COUNTS_OFFSET_C) / TVAC_COUNTS_GAIN_C + rng.normal(0, 1.0, t_s.size)
    )
    gyro = 0.5 + 0.01 * (temp_c - 25.0) + rng.normal(0.0, 0.05, t_s.size)
    gyro[list(TVAC_SPIKE_ROWS)] += 30.0
    return pd.DataFrame(
        {"time_ms": np.round(t_s * 1000.0), "gyro deg/h": np.round(gyro, 5), "temp_counts": counts}
    )
