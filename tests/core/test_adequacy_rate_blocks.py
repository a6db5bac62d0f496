"""temperature_rate_c_per_min, interpolated a block at a time, equals the backward
difference written here with numpy on whole arrays (tails longer than a block, a time axis
out of order, NaN in the temperatures)."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.adequacy import temperature_rate_c_per_min


def _whole(t: np.ndarray, temps: np.ndarray, delta: float) -> np.ndarray:
    keep = t >= t[0] + delta
    back = np.interp(t[keep] - delta, t, temps)
    return (temps[keep] - back) / delta * 60.0


@pytest.mark.parametrize("n", [1_000, 200_001])
def test_rate_equals_the_whole_array_difference(n):
    rng = np.random.default_rng(0)
    t = np.cumsum(rng.uniform(0.05, 0.15, n))
    temps = 25.0 + 10.0 * np.sin(t / 900.0) + rng.normal(0.0, 0.01, n)
    temps[n // 2] = np.nan
    strided = np.column_stack([temps, -temps])[:, 0]  # a column of a (n, k) array
    got = temperature_rate_c_per_min(t, strided, 60.0)
    want = _whole(t, temps, 60.0)
    np.testing.assert_array_equal(got, want)
    # a ramp of 1.5 °C/min reads 1.5 °C/min
    ramp = temperature_rate_c_per_min(t, 20.0 + 1.5 * t / 60.0, 60.0)
    np.testing.assert_allclose(ramp, 1.5, rtol=1e-9)


def test_rate_on_a_time_axis_out_of_order():
    t = np.array([0.0, 1.0, 2.0, 0.5, 3.0, 4.0, 5.0])
    temps = np.arange(7.0)
    np.testing.assert_array_equal(temperature_rate_c_per_min(t, temps, 2.0), _whole(t, temps, 2.0))
