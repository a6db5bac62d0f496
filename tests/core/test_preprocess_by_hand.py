"""The centred temperature rate of :mod:`thermocal.preprocess` against a parabola's
derivative written out here (kills a mutant of ``benchmarks/mutation_check.py``)."""

from __future__ import annotations

import numpy as np


def test_centred_rate_of_a_parabola_is_its_derivative() -> None:
    """T = 20 + 0.001 t² sampled each second: the centred Ṫ over Δ = 60 s, (T(t+30) −
    T(t−30))/60 × 60, is exactly 0.002 t × 60 [°C/min] away from the ends (mutant
    preprocess-centred-half reaches back 60 s: 0.002 t × 60 − 1.8)."""
    from thermocal.preprocess import temperature_rate

    t = np.arange(0.0, 600.0, 1.0)
    rate = temperature_rate(t, 20.0 + 0.001 * t**2, 60.0, "centred")
    inner = (t >= 30.0) & (t <= 569.0)
    np.testing.assert_allclose(rate[inner], 0.002 * t[inner] * 60.0, rtol=0, atol=1e-9)
