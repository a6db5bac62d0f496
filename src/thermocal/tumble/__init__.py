"""The tumble test of an accelerometer (IEEE Std 1293-1998): the output against the angle
of a horizontal axis it is turned about (a dividing head's stations, :mod:`.stations`, or a
continuous tumble), its harmonics and the model coefficients K0, K1, δ_o, K2, K_ip (K3)
with their uncertainties (:mod:`.analysis`), and a simulated tumble with known truth
(:mod:`.simulate`).  Pure functions on arrays; files are read by
:mod:`thermocal.pipeline.tumble`.
"""

from __future__ import annotations

from thermocal.tumble.analysis import (
    HarmonicFit,
    TumbleCoefficients,
    coefficients_from_harmonics,
    expected_output,
    fit_harmonics,
    harmonic_design,
)
from thermocal.tumble.stations import Station, find_stations

__all__ = [
    "HarmonicFit",
    "Station",
    "TumbleCoefficients",
    "coefficients_from_harmonics",
    "expected_output",
    "find_stations",
    "fit_harmonics",
    "harmonic_design",
]
