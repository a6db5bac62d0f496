"""Turntable calibration of a gyro triad on a dual-axis rotation mechanism (SPEC §7).

Modules: :mod:`.kinematics` (frames, eq. (1)–(3)), :mod:`.schedule` (16 positions,
design checks), :mod:`.model` (error model, measurement model, Cramér–Rao bound),
:mod:`.simulate` (``turntable-16`` scenario), :mod:`.estimate_ls` (batch least
squares), :mod:`.kalman` (14/15-state filter), :mod:`.calibrate` (the pipeline),
:mod:`.thermal` (every parameter over temperature).  The command's file driver (runs read,
calibrated, written) is :mod:`thermocal.pipeline.turntable`.
"""

from __future__ import annotations

from thermocal.turntable.calibrate import TurntableResult, calibrate
from thermocal.turntable.schedule import (
    POSITIONS_16,
    TurntableScheduleError,
    TurntableWarning,
    build_schedule,
)
from thermocal.turntable.simulate import TurntableTruth, simulate_turntable16

__all__ = [
    "POSITIONS_16",
    "TurntableResult",
    "TurntableScheduleError",
    "TurntableTruth",
    "TurntableWarning",
    "build_schedule",
    "calibrate",
    "simulate_turntable16",
]
