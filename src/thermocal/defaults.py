"""Defaults and names the command line shows in its help, kept free of numpy.

The command line's help registers every command without importing the maths: the
values a command's help or defaults show live here, and the modules that use them import them
from here (one definition each)."""

from __future__ import annotations

from typing import Final

DEFAULT_CHUNK_ROWS: Final = 500_000
"""Rows per chunk of :func:`thermocal.pipeline.compensate.compensate_file` (≈ 100 MB of working
memory for a 37-term polynomial)."""

WEAK_CORRELATION_LIMIT: Final = 0.4
"""A validation test is weakly correlated with the modelling test when the correlation
coefficient of their temperature histories is r < 0.4 (*A modelling and validation method for
the temperature compensation model of a ring-laser gyroscope*, a Chinese invention patent
published 2017)."""

DEFAULT_AVERAGING_S: Final = 100.0
"""Averaging time of the stability figures [s] (10 s or 100 s averages, as the ring-laser-gyro
and fibre-optic-gyro test methods state bias stability)."""

POSE_WINDOW_S: Final = 0.5
POSE_STILL_THRESHOLD: Final = 5.0
POSE_MOTION_FRACTION: Final = 0.01
POSE_DRIFT_DEG: Final = 2.0
"""``thermocal multipos``'s pose detector (:func:`thermocal.multipos.poses.find_poses`):
variance window [s], still limit in noise variances and in the motions' variance, the
largest turn across a pose [°] (parameters ``window_s``, ``still_threshold``,
``motion_fraction``, ``drift_deg``)."""

DEFAULT_GYRO_COLUMNS: Final = ("gyro_x", "gyro_y", "gyro_z")
"""Gyro columns of a turntable recording (``gyro_columns`` of the turntable calibration)."""

SCENARIO_NAMES: Final = (
    "rlg-modelling",
    "rlg-validation",
    "fog-slow",
    "mems-warmup",
    "accel-full-range",
    "turntable-16",
    "turntable-thermal",
    "mems-imu",
    "multipos",
    "ratetable",
    "tumble",
    "thermal-lag",
)
"""The simulator's scenarios (:data:`thermocal.simulate.SCENARIOS`, a test checks they agree)."""

PROGRAM_TIME: Final = "time_s"
PROGRAM_SETPOINT: Final = "setpoint_c"
"""Columns of a chamber program CSV (:func:`thermocal.readers.program.read_program`)."""


ALLOW_NARROW: Final = "--allow-narrow"  # cli-words: the override as model files record it
"""The override of the adequacy tests of the sweep (span, samples, Ṫ range), as a model file
records it (parameter ``allow_narrow``)."""
ALLOW_MOTION: Final = "--allow-motion"  # cli-words: the override as model files record it
"""The override of the adequacy test of stillness, as a model file records it (parameter
``allow_motion``)."""


def overrides_of(allow_narrow: bool, allow_motion: bool) -> tuple[str, ...]:
    """The adequacy overrides a command was given (:mod:`thermocal.adequacy`).

    Parameters
    ----------
    allow_narrow : bool
        Whether the sweep's adequacy tests were overridden.
    allow_motion : bool
        Whether the stillness test was overridden.

    Returns
    -------
    tuple of str
        The overrides given, in that order, as a model file records them
        (:data:`ALLOW_NARROW`, :data:`ALLOW_MOTION`).

    Examples
    --------
    >>> overrides_of(True, False) == (ALLOW_NARROW,)
    True
    """
    return tuple(o for o, on in ((ALLOW_NARROW, allow_narrow), (ALLOW_MOTION, allow_motion)) if on)


MAX_SIMULATED_SAMPLES: Final = 20_000_000
"""The most samples one call of a simulator makes (duration × rate, summed over the files
it writes): 2e7 samples, about 1.6 GB of float64 over the ~10 arrays a scenario builds
(the built-in programs at their own rates hold ≤ 2.4e5).  More is refused before any
array is allocated: a simulation at ``rate_hz`` = 1e9 asked for 1.66 PiB and ended in a
MemoryError.  Shared by the chamber scenarios, the turntable and the multi-position
simulators."""
