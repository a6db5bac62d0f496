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


def test_noise_of_regular_and_irregular_blocks_is_the_mad_about_each_block() -> None:
    """σ_w of :func:`adequacy._block_stats` is 1.4826 × the median absolute deviation of
    every ``every``-th sample from its own block's median, written here block by block
    (regular blocks, where the block of a sample is found by arithmetic, and irregular
    ones); the record's own values are left as they were."""
    rng = np.random.default_rng(7)
    for trial in range(6):
        n = 8 * int(rng.integers(75_010, 80_000))  # 3 × SIGMA_SAMPLES: every = 3
        t = np.arange(n) * 0.125  # exact: 8 samples a block of 1 s
        if trial % 2:
            t[n // 2 :] += 7.3  # a drop-out: blocks of unequal counts
        v = rng.normal(size=(n, 2)) + 0.001 * np.arange(n)[:, None] * (trial % 3)
        kept = v.copy()
        _start, counts, med, sigma = adequacy._block_stats(t, v, 1.0)
        assert np.array_equal(v, kept)
        assert bool(np.all(counts == 8)) == (trial % 2 == 0)
        idx = ((t - t[0]) / 1.0).astype(np.int64)
        block_of = np.searchsorted(np.unique(idx), idx)
        every = max(1, n // adequacy.SIGMA_SAMPLES)
        assert every == 3
        for j in range(2):
            dev = np.abs(v[::every, j] - med[block_of[::every], j])
            assert sigma[j] == 1.4826 * float(np.median(dev)), (trial, j)
