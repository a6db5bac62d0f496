"""Pre-processing against values worked out by hand (SPEC §3)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from thermocal import preprocess as pp
from thermocal.datasets import TVAC_COUNTS_GAIN_C, TVAC_COUNTS_OFFSET_C, make_tvac_log
from thermocal.errors import GapWarning, ThermocalInputError


def test_sum_decimation_100hz_to_1hz() -> None:
    counts = np.arange(250, dtype=float)  # 2.5 s at 100 Hz
    out = pp.sum_decimate(counts, 100)
    assert_allclose(out, [sum(range(100)), sum(range(100, 200))])
    assert_allclose(pp.mean_decimate(counts, 100), [49.5, 149.5])


def test_block_average_never_crosses_a_gap() -> None:
    t = np.r_[np.arange(0, 10.0, 1.0), np.arange(100, 110.0, 1.0)]
    x = np.r_[np.ones(10), 3 * np.ones(10)]
    ba = pp.block_average(t, x, 5.0)
    assert_allclose(ba.values, [1, 1, 3, 3])
    assert_allclose(ba.time_s, [2, 7, 102, 107])
    assert list(ba.segment) == [0, 0, 1, 1]


def test_lowpass_step_response_at_time_constant() -> None:
    tau = 0.01
    tf = pp.lowpass_time_constant_s(0.04)
    assert_allclose(tf, 1 / (2 * math.pi * 0.04))
    n = round(tf / tau)
    tf_exact = n * tau  # make T_f a whole number of samples
    x = np.r_[0.0, np.ones(2 * n + 1)]
    y = pp.lowpass_first_order(x, tau, time_constant_s=tf_exact, initial="zero")
    # step applied at sample 1 → n samples later t = T_f
    assert_allclose(y[1 + n], 1 - math.exp(-1), rtol=1e-12)
    assert_allclose(y[1 + 2 * n], 1 - math.exp(-2), rtol=1e-12)


def test_lowpass_starts_at_rest() -> None:
    y = pp.lowpass_first_order(np.full(50, 3.0), 1.0, bandwidth_hz=0.04)
    assert_allclose(y, 3.0, rtol=1e-14)


@pytest.mark.parametrize("rate", [2.0, -2.0])
@pytest.mark.parametrize("method", ["forward", "backward", "centred"])
def test_rate_of_a_ramp_is_exact(rate: float, method: pp.RateMethod) -> None:
    t = np.arange(0.0, 3600.0, 1.0)
    temp = 20.0 + rate * t / 60.0
    rdot = pp.temperature_rate(t, temp, 60.0, method)
    assert_allclose(rdot[1:-1], rate, rtol=1e-12)


def test_forward_rate_is_the_seed_formula() -> None:
    t = np.arange(0.0, 600.0, 1.0)
    temp = (t / 100.0) ** 2
    rdot = pp.temperature_rate(t, temp, 60.0, "forward")
    i = 100
    assert_allclose(rdot[i], (temp[i + 60] - temp[i]) / 60.0 * 60.0)
    rb = pp.temperature_rate(t, temp, 60.0, "backward")
    assert_allclose(rb[i + 60], rdot[i])


def test_no_rate_across_a_gap() -> None:
    t = np.r_[np.arange(0.0, 120.0, 1.0), np.arange(1000.0, 1120.0, 1.0)]
    temp = np.r_[np.full(120, 10.0), np.full(120, 50.0)]  # a 40 °C jump across the gap
    for method in ("forward", "backward", "centred"):
        rdot = pp.temperature_rate(t, temp, 60.0, method)  # type: ignore[arg-type]
        assert_allclose(rdot, 0.0, atol=0)


def test_rate_per_burst_in_tvac_log() -> None:
    df = make_tvac_log()
    t = df["time_ms"].to_numpy() / 1000.0
    temp = df["temp_counts"].to_numpy() * TVAC_COUNTS_GAIN_C + TVAC_COUNTS_OFFSET_C
    rdot = pp.temperature_rate(t, temp, 60.0, "backward")
    # per-burst rates are noisy (5 s spans of 1-count noise) but never span a gap
    starts = np.r_[0, np.flatnonzero(np.diff(t) > 1.0) + 1]
    assert starts.size == 24
    assert_allclose(rdot[starts], 0.0, atol=0)  # no partner sample: nothing across the gap
    # within a 5 s burst the 60 s backward partner is the burst's first sample (the oldest
    # sample with time ≥ t − 60 s in the same segment): Ṫ_i = 60 (T_i − T_s)/(t_i − t_s)
    # [°C/min], written out here; a partner across the gap would give another number
    stops = np.r_[starts[1:], t.size]
    for a, b in zip(starts, stops, strict=True):
        i = np.arange(a + 1, b)
        expect = 60.0 * (temp[i] - temp[a]) / (t[i] - t[a])
        assert_allclose(rdot[i], expect, rtol=1e-12, atol=1e-12)


def test_segment_holds_and_ramps() -> None:
    t = np.arange(0.0, 3 * 3600.0, 1.0)
    temp = np.piecewise(
        t,
        [t < 3600, (t >= 3600) & (t < 3600 + 1800), t >= 5400],
        [20.0, lambda x: 20.0 + (x - 3600) / 60.0, 50.0],
    )
    segs = pp.segment_holds(t, temp, rate_threshold_c_per_min=0.05, min_duration_s=600.0)
    kinds = [s.kind for s in segs]
    assert kinds == ["hold", "ramp", "hold"]
    assert_allclose(segs[0].mean_temp_c, 20.0, atol=0.02)
    assert_allclose(segs[2].mean_temp_c, 50.0, atol=0.02)
    assert_allclose(segs[1].rate_c_per_min, 1.0, rtol=0.05)
    assert abs(segs[1].start_s - 3600) < 60 and abs(segs[2].start_s - 5400) < 60


def test_remove_startup_offset() -> None:
    t = np.arange(100.0)
    x = np.r_[np.full(10, 5.0), np.full(90, 7.0)]
    y, off = pp.remove_startup_offset(t, x, 10.0)
    assert off == 5.0
    assert_allclose(y[:10], 0.0)


def test_spectrum_finds_a_tone_and_warns_on_gaps() -> None:
    fs = 10.0
    t = np.arange(0, 200.0, 1 / fs)
    x = np.sin(2 * np.pi * 1.5 * t)
    sp = pp.spectrum(t, x)
    assert_allclose(sp.frequency_hz[np.argmax(sp.psd)], 1.5, atol=fs / sp.segment_length)
    t2 = np.r_[t, t + 1000]
    with pytest.warns(GapWarning, match="1 gaps"):
        pp.spectrum(t2, np.r_[x, x])


def test_bad_arguments_raise() -> None:
    with pytest.raises(ThermocalInputError):
        pp.sum_decimate(np.ones(5), 0)
    with pytest.raises(ThermocalInputError, match="rate method"):
        pp.temperature_rate(np.arange(3.0), np.ones(3), 60.0, "sideways")  # type: ignore[arg-type]
    with pytest.raises(ThermocalInputError, match="exactly one"):
        pp.lowpass_first_order(np.ones(3), 1.0)


def test_one_missed_sample_is_a_gap_but_jitter_is_not() -> None:
    """A gap is a step longer than 1.5 median intervals (recording.GAP_FACTOR): one missed
    sample at 1 Hz (a 2 s step) is a gap; a 1.4 s step (logger jitter) is not."""
    from thermocal.recording import find_gaps

    t = np.array([0.0, 1.0, 2.0, 4.0, 5.0, 6.4, 7.4, 8.4])
    gaps = find_gaps(t)
    assert [(g.index, g.start_s, g.length_s) for g in gaps] == [(2, 2.0, 2.0)]
