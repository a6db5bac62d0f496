"""saturated_mask computed block by block equals the whole-array rule written out here with
numpy (the column's finite values, its median, the median of its nonzero steps, the runs of
its extremes), on columns long enough for the bracketing median and runs across blocks."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.inspection import RAIL_RUN, RAIL_STEP, RAIL_VALUES, saturated_mask
from thermocal.recording import DIFF_BLOCK, median_in_blocks, median_of_parts


def _reference(a: np.ndarray) -> np.ndarray:
    """The rule on whole arrays (every temporary as long as the column)."""
    out = np.zeros(a.shape, dtype=bool)
    fin = a[np.isfinite(a)]
    if fin.size < 2:
        return out
    hi, lo = float(fin.max()), float(fin.min())
    is_int = bool(np.all(fin == np.round(fin)))
    med = float(np.median(fin))
    d = np.abs(np.diff(fin))
    step = float(np.median(d[d > 0])) if np.any(d > 0) else 0.0
    for v in {hi, lo}:
        at = a == v
        e = np.flatnonzero(np.diff(np.concatenate([[0], at.astype(np.int8), [0]])))
        runs = list(zip(e[0::2].tolist(), e[1::2].tolist(), strict=True))
        longest = max((y - x for x, y in runs), default=0)
        if is_int and v in RAIL_VALUES and longest >= 2:
            out |= at
            continue
        if abs(v - med) <= 0.4 * (hi - lo):
            continue
        for s0, e0 in runs:
            jumps = [abs(v - a[s0 - 1])] if s0 > 0 else []
            jumps += [abs(v - a[e0])] if e0 < a.size else []
            if e0 - s0 >= RAIL_RUN and max(jumps, default=0.0) > RAIL_STEP * step:
                out[s0:e0] = True
    return out


def _clipped_counts(n: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    x = np.round(rng.normal(0.0, 3000.0, n) + 31000.0 * np.sin(6.0 * np.pi * np.arange(n) / n))
    return np.clip(x, -32768.0, 32767.0)


def _float_rail(n: int) -> np.ndarray:
    rng = np.random.default_rng(1)
    x = rng.normal(0.0, 1.0, n)
    edge = DIFF_BLOCK - 2  # a stretch on the rail across the first block's edge
    for s in (1000, edge, 3 * DIFF_BLOCK + 17):
        x[s : s + 6] = 40.0 if s < n - 10 else x[s : s + 6]
    x[[i for i in (5, 777, 2 * DIFF_BLOCK + 1) if i < n]] = np.nan
    x[-3:] = -40.0  # the minimum's stretch at the end of the column
    return x


@pytest.mark.parametrize("make", [_clipped_counts, _float_rail])
@pytest.mark.parametrize("n", [50_000, 1_500_001])
def test_saturated_mask_equals_the_whole_array_rule(make, n):
    a = make(n)
    got = saturated_mask(a)
    want = _reference(a)
    assert int(want.sum()) > 0  # the case has samples on a rail
    np.testing.assert_array_equal(got, want)


def test_rail_of_counts_across_block_edges():
    a = np.zeros(3 * DIFF_BLOCK)
    a[::7] = 1.0
    a[DIFF_BLOCK - 1 : DIFF_BLOCK + 1] = 32767.0  # two samples, one either side of the edge
    got = saturated_mask(a)
    assert np.flatnonzero(got).tolist() == [DIFF_BLOCK - 1, DIFF_BLOCK]
    np.testing.assert_array_equal(got, _reference(a))


@pytest.mark.parametrize("n", [7, 1_200_000, 1_200_001])
def test_median_of_parts_is_numpys_median(n):
    rng = np.random.default_rng(2)
    x = rng.standard_t(3, n)
    x[: n // 3] = 1.5  # ties across the middle
    sizes = rng.integers(1, 300_000, 20).cumsum()
    cuts = sizes[sizes < n].tolist()

    def parts():
        return iter(np.split(x, cuts))

    assert median_of_parts(parts, n) == float(np.median(x))
    assert median_in_blocks(lambda a, b: x[a:b], n) == float(np.median(x))
    x_before = x.copy()
    median_in_blocks(lambda a, b: x[a:b], n)
    np.testing.assert_array_equal(x, x_before)  # the values handed over are not reordered
