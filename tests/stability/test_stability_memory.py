"""The noise identification of a long record holds no differenced copy of it (issue 26's
memory rule, kept by issue 29's per-τ identification): r1 of the differences from blocks
equals the whole-array formula written out here."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from thermocal.stability import edf as ed


@pytest.mark.parametrize("d", [1, 2])
def test_lag1_of_differences_from_blocks(d: int) -> None:
    n = 6 * (1 << 20) + 3  # six blocks and a short seventh
    rng = np.random.default_rng(11)
    z = np.cumsum(rng.standard_normal(n)) * 1e-3 + rng.standard_normal(n)
    w = np.diff(z, d)  # the r1 of Riley & Greenhall 2004 eq. 2, written out
    c = w - w.mean()
    want = float(c[:-1] @ c[1:]) / float(c @ c)
    del w, c
    tracemalloc.start()
    try:
        got = ed._lag1_of_difference(z, d)
        _cur, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert got == pytest.approx(want, rel=1e-12)
    # a differenced copy and its centred copy would be 2 × 8 B per sample (100 MB here);
    # blocks hold at most three block-long arrays at once
    assert peak < 3 * 8 * ed._DIFF_BLOCK + (1 << 20), peak / n
