"""Rate-table scale-factor tests of a gyro (IEEE Std 952-1997, IEEE Std 1431-2004, terms of
IEEE Std 528-2001): the plateaus of a rate ladder (:mod:`.plateaus`), the scale factor, its
nonlinearity, asymmetry, repeatability and temperature coefficient, the bias per rate, the
input threshold and the resolution (:mod:`.analysis`), and a simulated ladder with known
truth (:mod:`.simulate`).  Pure functions on arrays; files are read by
:mod:`thermocal.pipeline.ratetable`.
"""

from __future__ import annotations

from thermocal.ratetable.analysis import (
    Figure,
    LadderResult,
    RateRow,
    TemperatureCoefficient,
    analyse_ladder,
    temperature_coefficient,
)
from thermocal.ratetable.plateaus import (
    Detection,
    Plateau,
    match_rates,
    plateaus_from_output,
    plateaus_from_rate,
    plateaus_from_schedule,
)

__all__ = [
    "Detection",
    "Figure",
    "LadderResult",
    "Plateau",
    "RateRow",
    "TemperatureCoefficient",
    "analyse_ladder",
    "match_rates",
    "plateaus_from_output",
    "plateaus_from_rate",
    "plateaus_from_schedule",
    "temperature_coefficient",
]
