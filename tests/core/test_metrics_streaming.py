"""The figures of merit of a record held in block stores (thermocal.metrics_streaming)
against thermocal.metrics in memory and formulas written here."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal import metrics as mt
from thermocal import metrics_streaming as ms
from thermocal.errors import ThermocalInputError
from thermocal.recording import contiguous_slices
from thermocal.stability.streaming import ArraySource, ArrayStore


def _record() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(31)
    n = 90_001
    t = np.arange(n) * 0.01
    t[30_000:] += 7.0  # a gap
    y = 3.0 + rng.normal(0.0, 0.5, n) + np.cumsum(rng.normal(0.0, 0.002, n))  # [deg/h]
    return t, y


@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"averaging_s": 1.0},
        {"averaging_s": 0.37, "drift_reference_s": (50.0, 120.0)},
        {"averaging_s": 10.0, "drift_bias": 2.5},
    ],
)
def test_streamed_metrics_equal_in_memory(kw: dict, monkeypatch: pytest.MonkeyPatch) -> None:
    # windows of 7 777 values: no block of the trapezoids or of the means falls on them
    monkeypatch.setattr(ms, "WINDOW", 7_777)
    t, y = _record()
    segs = contiguous_slices(t)
    ref = mt.block_means(y, 0.01, kw.get("averaging_s"), time_s=t)
    got = ms.streamed_metrics(
        ArraySource(t), ArraySource(y), segs, 0.01, name="gyro", unit="deg/h",
        store=ArrayStore(), **kw,
    )  # fmt: skip
    assert got.bias == pytest.approx(float(np.mean(y)), rel=1e-13)
    assert got.bias_stability == pytest.approx(float(np.std(ref, ddof=1)), rel=1e-12)
    assert got.peak_to_peak == pytest.approx(float(ref.max() - ref.min()), rel=1e-12)
    assert got.n_averages == ref.size and got.n_segments == 2
    b0 = kw.get("drift_bias")
    if b0 is None:  # the mean over the reference window, chosen here by the times
        lo, hi = kw.get("drift_reference_s", (0.0, 0.1 * (t[-1] - t[0])))
        sel = (t - t[0] >= lo) & (t - t[0] <= hi)
        b0 = float(y[sel].mean())
        assert got.drift_reference is not None and got.drift_reference.n_samples == sel.sum()
    e = y - b0
    inc = 0.5 * (e[1:] + e[:-1]) * np.diff(t) / 3600.0
    inc[29_999] = 0.0  # nothing integrated across the gap
    theta = np.concatenate(([0.0], np.cumsum(inc)))
    assert got.drift_angle == pytest.approx(theta[-1], rel=1e-9)
    assert got.drift_angle_max == pytest.approx(np.abs(theta).max(), rel=1e-9)
    assert got.drift_angle_max_time_s == pytest.approx(t[np.argmax(np.abs(theta))] - t[0])


def test_streamed_metrics_refuse_what_the_in_memory_ones_refuse() -> None:
    t, y = _record()
    src = (ArraySource(t), ArraySource(y), contiguous_slices(t), 0.01)
    with pytest.raises(ThermocalInputError, match="averaging_s"):
        ms.streamed_metrics(*src, name="gyro", unit="deg/h", averaging_s=1e6)
    with pytest.raises(ThermocalInputError, match="not both"):
        ms.streamed_metrics(
            *src, name="gyro", unit="deg/h", drift_bias=1.0, drift_reference_s=(0.0, 1.0)
        )
    with pytest.raises(ThermocalInputError, match="holds no sample"):
        ms.streamed_metrics(*src, name="gyro", unit="deg/h", drift_reference_s=(1e6, 2e6))
    with pytest.raises(ThermocalInputError, match="gyro rates"):
        ms.streamed_metrics(*src, name="acc", unit="mg", drift_bias=1.0)
