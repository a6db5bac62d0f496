"""The Hampel spike count of ``thermocal inspect`` against a direct, per-sample computation
written here (median and MAD of each window with plain Python sorting), on noise with
spikes, a quantised signal (MAD zero in places: the global floor applies), and a recording
with a gap (windows never span it)."""

from __future__ import annotations

import itertools
import statistics

import numpy as np
import pytest

from thermocal.inspection import SPIKE_HALF_WINDOW, SPIKE_THRESHOLD, count_spikes
from thermocal.recording import contiguous_slices


def _reference(t: np.ndarray, x: np.ndarray) -> tuple[int, int | None]:
    h, k = SPIKE_HALF_WINDOW, SPIKE_THRESHOLD
    total, first = 0, None
    for sl in contiguous_slices(t):
        xs = [float(v) for v in x[sl]]
        if len(xs) < 2 * h + 1:
            continue
        d = [b - a for a, b in itertools.pairwise(xs)]
        md = statistics.median(d)
        floor = 1.4826 * statistics.median([abs(v - md) for v in d]) / np.sqrt(2.0)
        for i in range(h, len(xs) - h):
            win = xs[i - h : i + h + 1]
            med = statistics.median(win)
            mad = statistics.median([abs(v - med) for v in win])
            sigma = max(1.4826 * mad, floor)
            if sigma > 0 and abs(xs[i] - med) > k * sigma:
                total += 1
                row = sl.start + i
                first = row if first is None else min(first, row)
    return total, first


@pytest.mark.parametrize("case", ["noise", "quantised", "gap"])
def test_count_spikes_is_the_hampel_test(case: str) -> None:
    rng = np.random.default_rng({"noise": 1, "quantised": 2, "gap": 3}[case])
    n = 4000
    t = np.arange(n, dtype=np.float64)
    x = rng.normal(0.0, 1.0, n)
    if case == "quantised":
        x = np.round(x * 0.6)  # many windows with MAD 0
    if case == "gap":
        t[2000:] += 50.0
    spikes = rng.choice(np.arange(20, n - 20), 12, replace=False)
    x[spikes] += rng.choice([-1.0, 1.0], 12) * rng.uniform(15.0, 40.0, 12)
    got = count_spikes(t, x)
    assert got == _reference(t, x)
    assert got[0] >= 10  # the spikes are found (a few may sit in the same window)
