"""totdev's sums from blocks of the reflected series: the same sums as the whole extension
written out here (NIST SP 1065 eq. 25: the phase extended by odd reflection at both ends,
N − 2 second differences centred on it), without holding the extension (3N points)."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from thermocal.stability import deviations as dv


def _by_hand(x: np.ndarray, m: int, tau0_s: float) -> float:
    """Σ (x*_{i−m} − 2x*_i + x*_{i+m})² / (2τ²) over i = 1 … N − 2, x* the odd reflection."""
    n = x.size
    ext = np.concatenate([2.0 * x[0] - x[n - 2 : 0 : -1], x, 2.0 * x[-1] - x[-2:0:-1]])
    i = np.arange(1, n - 1) + (n - 2)  # x_i's index in ext
    d = ext[i - m] - 2.0 * ext[i] + ext[i + m]
    return float(d @ d) / (2.0 * (m * tau0_s) ** 2)


def test_totdev_sums_without_the_extension() -> None:
    n = 3_000_001
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.standard_normal(n)) * 0.01 + np.cumsum(np.cumsum(rng.standard_normal(n)))
    m = np.array([1, 3, 64, dv._CHUNK - 1, dv._CHUNK, 1 << 20, n - 2], dtype=np.int64)
    want = [_by_hand(x, int(mm), 0.5) for mm in m]
    tracemalloc.start()
    try:
        num, cnt = dv.segment_sums("totdev", x, 0.5, m)
        _cur, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert cnt.tolist() == [n - 2] * m.size
    assert num == pytest.approx(want, rel=1e-11)
    # the extension alone is 3N points (72 MB here); blocks hold a few block-long buffers
    # per thread
    assert peak < 16 * 8 * dv._CHUNK, peak / n
