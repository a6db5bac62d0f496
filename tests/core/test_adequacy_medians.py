"""The stillness test's medians (adequacy._block_stats, adequacy._ragged_medians) computed
at once by sorting padded rows are numpy's own medians, computed here block by block and
window by window (irregular blocks: a drop-out, jittered times; windows with NaN, ties,
empty ones)."""

from __future__ import annotations

import warnings

import numpy as np

from thermocal import adequacy


def test_block_medians_of_irregular_blocks_are_numpys() -> None:
    rng = np.random.default_rng(41)
    for trial in range(40):
        n = int(rng.integers(200, 5000))
        t = np.cumsum(rng.exponential(0.01, n))
        t[n // 2 :] += 30.0  # a drop-out: blocks of unequal counts
        v = rng.normal(size=(n, 3))
        if trial % 2:
            v = np.round(v, 1)  # ties
        start, counts, med, _sigma = adequacy._block_stats(t, v, 1.0)
        assert np.sum(counts) == n  # short record: no decimation
        idx = ((t - t[0]) / 1.0).astype(np.int64)
        for b, k in enumerate(np.unique(idx)):
            want = np.median(v[idx == k], axis=0)
            assert np.array_equal(med[b], want), (trial, b)
            assert start[b] == t[0] + k


def test_ragged_window_medians_are_nanmedian() -> None:
    rng = np.random.default_rng(42)
    for trial in range(40):
        n, m = int(rng.integers(5, 300)), int(rng.integers(1, 4))
        x = rng.normal(size=(n, m))
        if trial % 2:
            x = np.round(x, 1)
        x[rng.random(x.shape) < 0.1] = np.nan
        lo = rng.integers(0, n, 50)
        hi = np.minimum(lo + rng.integers(0, 20, 50), n)
        got = adequacy._ragged_medians(x, lo, hi)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # an empty or all-NaN window
            want = np.array([np.nanmedian(x[a:b], axis=0) if b > a else np.full(m, np.nan)
                             for a, b in zip(lo, hi, strict=True)])  # fmt: skip
        assert np.array_equal(got, want, equal_nan=True), trial
