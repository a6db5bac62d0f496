"""A long record's thermometer judged on a bounded subsample (``DESCRIBE_MAX_SAMPLES``): the
judgement sorts its samples (58 B each), which made ``inspect`` of a 1e7-row file 2.5x its
memory; every k-th sample keeps the levels and the update period of a held reading."""

from __future__ import annotations

import numpy as np

from thermocal.thermometer import DESCRIBE_MAX_SAMPLES, describe_thermometer


def test_a_bmi088_like_thermometer_over_three_million_samples() -> None:
    t = np.arange(3_000_000) * 0.005  # 200 Hz for 4 h 10 min
    true = 20.0 + 30.0 * t / t[-1]
    held = np.interp(np.floor(t / 1.28) * 1.28, t, true)  # updated every 1.28 s
    th = describe_thermometer(t, 0.125 * np.round(held / 0.125))
    assert t.size > DESCRIBE_MAX_SAMPLES
    assert th.n_samples == t.size and th.quantised and th.slow
    assert th.step_c is not None and abs(th.step_c - 0.125) < 1e-9
    assert th.update_period_s is not None and abs(th.update_period_s - 1.28) < 0.02
    assert abs(th.sample_period_s - 0.005) < 1e-12
    assert th.n_levels == 241  # 20 … 50 °C in 0.125 °C steps


def test_a_fine_thermometer_over_three_million_samples_is_neither() -> None:
    t = np.arange(3_000_000) * 0.01
    v = 25.0 + 1e-6 * np.arange(t.size) + np.random.default_rng(0).normal(0, 0.01, t.size)
    th = describe_thermometer(t, v)
    assert not th.quantised and not th.slow and th.n_samples == t.size
