"""The overlapping ADEV of a record held in block stores, window by window
(thermocal.stability.streaming) against the in-memory analysis and a direct numpy
evaluation of NIST SP 1065 eq. 11."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.errors import ThermocalInputError
from thermocal.stability import allan
from thermocal.stability import noise_model as nm
from thermocal.stability import streaming as st


def _record(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return 2.0 + rng.normal(0.0, 3.0, n) + np.cumsum(rng.normal(0.0, 0.02, n))


def _direct_adev(y: np.ndarray, segs: list[slice], m: int) -> float:
    """NIST SP 1065 eq. 11 on each stretch's phase, pooled (written out here)."""
    num, terms = 0.0, 0
    for sl in segs:
        seg = y[sl]
        x = np.concatenate(([0.0], np.cumsum(seg - seg.mean())))
        d = x[2 * m :] - 2.0 * x[m:-m] + x[: -2 * m]
        num += float(d @ d)
        terms += d.size
    return float(np.sqrt(num / (2.0 * m * m * terms)))


@pytest.mark.parametrize("window", [1 << 22, 1 << 12, 3000])
def test_streamed_adev_equals_in_memory_with_gaps(
    window: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    # odd lengths, three stretches, windows that cut the blocks anywhere (3000: no block
    # size of the kernels divides it) and a level identified window by window
    monkeypatch.setattr(st, "WINDOW", window)
    monkeypatch.setattr(st, "IN_MEMORY_LEVEL", 5000)
    y = _record(150_007, 3)
    segs = [slice(0, 40_001), slice(40_001, 40_050), slice(40_050, 150_007)]
    t = np.arange(y.size) * 0.01
    ref = allan.overlapping_adev(y.copy(), 0.01, "octave", time_s=t, segments=segs)
    rec = st.StreamedRecord(st.ArraySource(y), 0.01, tuple(segs))
    got = st.streamed_adev(rec, "octave")
    np.testing.assert_array_equal(got.m, ref.m)
    np.testing.assert_allclose(got.adev, ref.adev, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(got.alpha, ref.alpha)
    assert got.alpha_method == ref.alpha_method
    np.testing.assert_allclose(got.edf, ref.edf, rtol=1e-12)
    np.testing.assert_array_equal(got.n_terms, ref.n_terms)
    assert (got.n_samples, got.n_segments) == (ref.n_samples, ref.n_segments)
    for k in (0, 3, 7):
        assert got.adev[k] == pytest.approx(_direct_adev(y, segs, int(got.m[k])), rel=1e-9)


def test_windowed_identification_differences_random_walk(monkeypatch: pytest.MonkeyPatch) -> None:
    # random-walk rate: r1 of the averages near 1, the rule differences them (d = 1) on
    # levels read window by window, as the whole array in memory
    monkeypatch.setattr(st, "IN_MEMORY_LEVEL", 1000)
    monkeypatch.setattr(st, "WINDOW", 4096)
    y = np.cumsum(np.random.default_rng(5).normal(0.0, 1.0, 60_001))
    ref = allan.overlapping_adev(y.copy(), 1.0, "octave")
    got = st.streamed_adev(st.StreamedRecord(st.ArraySource(y), 1.0, (slice(0, y.size),)))
    assert set(ref.alpha[:8].tolist()) == {-2}  # random-walk FM
    np.testing.assert_array_equal(got.alpha, ref.alpha)
    np.testing.assert_allclose(got.adev, ref.adev, rtol=1e-12)


def test_streamed_adev_refuses_other_tau_sets() -> None:
    y = _record(10_000, 1)
    rec = st.StreamedRecord(st.ArraySource(y), 0.1, (slice(0, y.size),))
    with pytest.raises(ThermocalInputError, match="octave"):
        st.streamed_adev(rec, "decade")


def test_summary_lattice_and_stuck_as_in_memory() -> None:
    rng = np.random.default_rng(7)
    step = 0.00816
    y = np.round(rng.normal(0.0, 0.05, 250_001) / step) * step + 0.3
    summary = st.ValueSummary(y.size)
    for a in range(0, y.size, 7_777):
        summary.add(y[a : a + 7_777])
    got = st.lattice_step(st.ArraySource(y), summary)
    ref = nm.lattice_step(y)
    assert ref is not None and got is not None
    assert got[0] == pytest.approx(step, rel=1e-6)
    assert got == ref
    flat = st.ValueSummary(1000)
    flat.add(np.full(1000, 4.5))
    with pytest.raises(ThermocalInputError, match="constant"):
        flat.check_not_stuck("gyro", "run.parquet")


def test_octave_level_sums_carry_across_windows(monkeypatch: pytest.MonkeyPatch) -> None:
    # the lag sums of every level (Σ c², Σ k c, Σ c c₊₁, ends) with windows of 3000 values
    # against the in-memory pyramid (deviations.octave_levels) of a drifting record
    from thermocal.stability import deviations as dv

    monkeypatch.setattr(st, "WINDOW", 3000)
    y = _record(70_001, 9) + np.linspace(0.0, 40.0, 70_001)
    mean = float(y.mean())
    ref = dv.octave_levels(y, mean, 1024)
    work = st._Work(None, 1.0)
    got = st._levels(st.ArraySource(y), slice(0, y.size), mean, 1024, st.ArrayStore(), work)
    assert [lv.m for lv in got] == [lv.m for lv in ref]
    for g, r in zip(got, ref, strict=True):
        assert g.lag.n == r.lag.n
        for key in ("szz", "uz", "cross", "first", "last"):
            assert getattr(g.lag, key) == pytest.approx(getattr(r.lag, key), rel=1e-11, abs=1e-9)
