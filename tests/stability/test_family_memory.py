"""Phase data given up by the caller (``overwrite``, as ``thermocal allan`` gives its
recording up) are centred in their own buffer, and the noise identification holds one
centred copy of the phase at a time: the same results as on a copy of the record, with
neither the record's copy nor the identification's copies (8 bytes a sample each)."""

from __future__ import annotations

import json
import tracemalloc

import numpy as np
import pytest

from thermocal.stability import edf as ed
from thermocal.stability import family


@pytest.mark.parametrize("noise_id", ["thermocal", "stable32"])
def test_phase_record_given_up_is_not_copied(noise_id: str) -> None:
    n = 3_000_000
    rng = np.random.default_rng(3)
    # white FM (a random-walk phase) beside white PM: identification differences the phase
    phase = np.cumsum(rng.standard_normal(n)) * 1e-3 + rng.standard_normal(n) * 1e-4
    want = family.stability(phase.copy(), 0.01, ["oadev"], data_type="phase", noise_id=noise_id)
    mine = phase.copy()
    tracemalloc.start()
    try:
        got = family.stability(
            mine, 0.01, ["oadev"], data_type="phase", noise_id=noise_id, overwrite=True
        )
        _cur, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert json.dumps(got.to_dict()) == json.dumps(want.to_dict())
    assert set(want.curves["oadev"].alpha.tolist()) >= {0}  # white FM identified: α = 0
    # a copy of the record, its centred copy for the lag-1 test and the m-averages
    # were 8 B a sample each; one centred copy remains, with the differences' blocks
    assert peak < 8 * n + 3 * 8 * ed._DIFF_BLOCK, peak / n
    assert not np.array_equal(mine, phase)  # the buffer given up was used


def test_phase_record_kept_without_overwrite() -> None:
    rng = np.random.default_rng(4)
    phase = np.cumsum(rng.standard_normal(50_000))
    before = phase.copy()
    family.stability(phase, 1.0, ["oadev", "tierms"], data_type="phase")
    assert np.array_equal(phase, before)


def test_stable32_rate_identification_takes_no_centred_copy() -> None:
    # Stable32's lag-1 test on rate averages (mean removed) reads Σ z_c z_c' / Σ z_c² from
    # the octave pass's sums: no centred copy of the 8 B-a-sample level 0
    n = 6_000_000
    rng = np.random.default_rng(2)
    y = rng.standard_normal(n) + 7.0  # white FM: α = 0 wherever the lag-1 test decides
    tracemalloc.start()
    try:
        got = family.stability(y, 0.01, ["oadev"], noise_id="stable32")
        _cur, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    curve = got.curves["oadev"]
    lag1 = [
        a for a, how in zip(curve.alpha.tolist(), curve.alpha_method, strict=True) if how == "lag1"
    ]
    assert len(lag1) >= 15 and set(lag1[:12]) == {0}  # m ≤ 2048: thousands of averages
    # the phase (8 B a sample) and the octave levels above 0 (8 B in all); the centred
    # copy of level 0 was 8 B more
    assert peak < 21 * n, peak / n
    # random-walk FM: r1 of the rate averages near 1, α = −2 (Riley & Greenhall 2004)
    rw = np.cumsum(rng.standard_normal(200_000))
    walk = family.stability(rw, 0.01, ["oadev"], noise_id="stable32").curves["oadev"]
    assert walk.alpha_method[:8] == ("lag1",) * 8
    assert walk.alpha[:8].tolist() == [-2] * 8


def test_tierms_of_rate_takes_no_centred_copy() -> None:
    # TIE rms reads the raw phase: the centred copy the other deviations read is not made
    n = 3_000_000
    rng = np.random.default_rng(6)
    y = rng.standard_normal(n) + 7.0  # white FM of unit σ, τ0 = 1 s
    tracemalloc.start()
    try:
        got = family.stability(y, 1.0, ["tierms"], [1.0, 4.0])
        _cur, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # TIE rms of the rate integrated about its mean: x_{k+m} − x_k sums m samples of unit
    # variance, rms √m (ITU-T G.810)
    assert got.curves["tierms"].dev.tolist() == pytest.approx([1.0, 2.0], rel=2e-3)
    # the phase (8 B a sample) and the octave levels (8 B); the centred copy was 8 B more
    assert peak < 21 * n, peak / n
