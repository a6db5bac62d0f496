"""Tests of the maths modules written to kill mutants of the mutation check (issue 27
item 6: ``benchmarks/mutation_check.py``, the mutants named ``adequacy-*``,
``stability-*``, ``multipos-*``, ``metrics-*`` …).  Expected values are written out here
from the stated definitions, with their numbers."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal import adequacy


def test_ten_samples_per_coefficient_is_enough() -> None:
    """n / p ≥ 10 passes, the boundary included (mutant adequacy-samples-strict)."""
    assert adequacy.samples_test(40, 4).verdict == "pass"
    assert adequacy.samples_test(39, 4).verdict == "fail"
    assert adequacy.samples_test(4, 4).verdict == "fail"


def test_a_sweep_exactly_at_the_firmware_minimum_passes() -> None:
    """ArduPilot needs 10 °C: exactly 10 passes, 9.99 fails (mutant adequacy-firmware-strict)."""
    assert adequacy.firmware_test(10.0, "ardupilot", 10.0).verdict == "pass"
    assert adequacy.firmware_test(9.99, "ardupilot", 10.0).verdict == "fail"


def test_the_temperature_rate_is_in_degrees_per_minute() -> None:
    """A ramp of 1.5 °C/min sampled each second: Ṫ over Δ = 60 s is 1.5 [°C/min] from
    t = 60 s on (mutant adequacy-rate-per-second gives 0.025)."""
    t = np.arange(0.0, 600.0, 1.0)
    rate = adequacy.temperature_rate_c_per_min(t, 20.0 + 1.5 * t / 60.0)
    assert rate.size == t.size - 60
    np.testing.assert_allclose(rate, 1.5, rtol=1e-12)
