"""One g-sensitivity from several sessions (``multipos.gsens.combine_g_sensitivity``): the
inverse-variance mean and its σ computed here element by element, widened by the sessions'
scatter only when it is beyond their σ; over seeds, sessions drawn about a known ``A``
give a mean within its σ as often as a normal law says."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.multipos.gsens import GSensitivity, combine_g_sensitivity


def _est(a: np.ndarray, s: np.ndarray) -> GSensitivity:
    return GSensitivity(a, s, np.zeros(3), np.ones(3), 2, 6, 1.0)


def test_the_weighted_mean_written_here() -> None:
    rng = np.random.default_rng(4)
    a = [rng.normal(0.0, 50.0, (3, 3)) for _ in range(3)]
    s = [rng.uniform(1.0, 20.0, (3, 3)) for _ in range(3)]
    mean, sigma = combine_g_sensitivity([_est(x, y) for x, y in zip(a, s, strict=True)])
    for i in range(3):
        for j in range(3):
            w = [1.0 / s[r][i, j] ** 2 for r in range(3)]
            m = sum(w[r] * a[r][i, j] for r in range(3)) / sum(w)
            chi = sum(w[r] * (a[r][i, j] - m) ** 2 for r in range(3)) / 2.0
            assert mean[i, j] == pytest.approx(m, rel=1e-12)
            assert sigma[i, j] == pytest.approx(math.sqrt(max(1.0, chi) / sum(w)), rel=1e-12)


def test_one_session_is_itself_and_none_is_refused() -> None:
    a, s = np.arange(9.0).reshape(3, 3), np.full((3, 3), 2.0)
    mean, sigma = combine_g_sensitivity([_est(a, s)])
    np.testing.assert_array_equal(mean, a)
    np.testing.assert_array_equal(sigma, s)
    with pytest.raises(ValueError, match="no estimate"):
        combine_g_sensitivity([])


def test_agreeing_sessions_keep_their_sigma_and_cover_the_truth() -> None:
    """Four sessions about A with σ 3, 4, 6, 12: the mean's σ is (Σ 1/σ²)^-1/2 or more, and
    over 400 draws of nine elements about 68 % of the means lie within 1σ of A."""
    rng = np.random.default_rng(7)
    truth = rng.normal(0.0, 100.0, (3, 3))
    sig = [3.0, 4.0, 6.0, 12.0]
    floor = 1.0 / math.sqrt(sum(1.0 / x**2 for x in sig))
    inside = []
    for _ in range(400):
        ests = [_est(truth + rng.normal(0.0, x, (3, 3)), np.full((3, 3), x)) for x in sig]
        mean, sigma = combine_g_sensitivity(ests)
        assert np.all(sigma >= floor * (1 - 1e-12))
        inside.append(np.abs(mean - truth) < sigma)
    share = float(np.mean(inside))
    assert 0.66 <= share <= 0.80, share  # ≥ 68 %: σ widened only by a scatter beyond it
