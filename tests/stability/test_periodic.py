"""The periodogram behind the periodic-term check (:mod:`thermocal.stability.periodic`):
Welch's PSD with each segment's line removed in the frequency domain equals
``scipy.signal.welch`` (the straightforward time-domain detrend) to 1e-9, and the terms
found with it equal those found with scipy's periodogram on records with sines, an offset
far above the noise and a drift; the running floor equals the median written here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from thermocal.stability import periodic

FS = 200.0


def _record(seed: int, n: int, offset: float, drift: float) -> np.ndarray:
    """White noise of σ = 1, two sines (3.1 Hz, 0.4; 47.3 Hz, 0.15), ``offset`` and a
    ``drift`` [per s] (a quadratic part too, so each segment's line differs)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    return np.asarray(
        offset
        + drift * t
        + 1e-3 * drift * t**2
        + rng.standard_normal(n)
        + 0.4 * np.sin(2.0 * math.pi * 3.1 * t + 0.3)
        + 0.15 * np.sin(2.0 * math.pi * 47.3 * t + 1.1)
    )


def _scipy_welch(x: np.ndarray, fs: float, seg: int) -> tuple[np.ndarray, np.ndarray, int]:
    """The same periodogram from scipy (Hann, half overlap, each segment's line removed in
    the time domain; segments ``seg // 2`` apart), with the segment count written out."""
    f, s = signal.welch(x, fs, "hann", seg, seg - seg // 2, detrend="linear")
    return f, s, (x.size - seg) // (seg // 2) + 1


@pytest.mark.parametrize(
    ("n", "seg", "offset", "drift"),
    [(60_000, 4096, 0.0, 0.0), (60_000, 4096, 1e4, 0.5), (40_001, 1001, 300.0, -2.0),
     (3 * 512, 1024, 5.0, 1.0)],
)  # fmt: skip
def test_welch_equals_scipys_time_domain_detrend(
    n: int, seg: int, offset: float, drift: float
) -> None:
    x = _record(1, n, offset, drift)
    f, s, k = periodic.welch(x, FS, seg)
    f2, s2, k2 = _scipy_welch(x, FS, seg)
    assert k == k2
    np.testing.assert_allclose(f, f2, rtol=1e-15)
    np.testing.assert_allclose(s, s2, rtol=1e-9)


@pytest.mark.parametrize(("offset", "drift"), [(0.0, 0.0), (1e4, 0.0), (250.0, 0.3)])
def test_terms_equal_those_of_scipys_periodogram(
    offset: float, drift: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    x = _record(2, 300_000, offset, drift)
    ours = periodic.periodic_terms(x, 1.0 / FS, "deg/h")
    monkeypatch.setattr(periodic, "welch", _scipy_welch)
    theirs = periodic.periodic_terms(x, 1.0 / FS, "deg/h")
    assert len(ours) == len(theirs) == 2
    assert abs(ours[0].frequency_hz - 3.1) <= ours[0].resolution_hz
    for p, q in zip(ours, theirs, strict=True):
        for key in ("frequency_hz", "amplitude", "ratio", "tau_peak_s", "adev_peak"):
            assert getattr(p, key) == pytest.approx(getattr(q, key), rel=1e-9, abs=0.0), key
        assert p.resolution_hz == q.resolution_hz


def test_noise_alone_finds_nothing_either_way(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(3)
    x = 50.0 + rng.standard_normal(300_000) + np.cumsum(rng.standard_normal(300_000)) * 1e-3
    assert periodic.periodic_terms(x, 1.0 / FS, "mg") == ()
    monkeypatch.setattr(periodic, "welch", _scipy_welch)
    assert periodic.periodic_terms(x, 1.0 / FS, "mg") == ()


def test_running_median_is_the_windows_median() -> None:
    x = np.random.default_rng(4).chisquare(20, 9000)
    half = 32
    pad = np.concatenate([x[half:0:-1], x, x[-2 : -half - 2 : -1]])  # reflected ends
    want = np.array([np.median(pad[i : i + 2 * half + 1]) for i in range(x.size)])
    np.testing.assert_array_equal(periodic._running_median(x, half), want)


def test_gaps_read_as_one_stretch_of_the_finite_samples() -> None:
    x = _record(5, 100_000, 2.0, 0.0)
    holed = x.copy()
    holed[::997] = np.nan
    assert periodic.periodic_terms(holed, 1.0 / FS, "mg") == periodic.periodic_terms(
        x[np.isfinite(holed)], 1.0 / FS, "mg"
    )
