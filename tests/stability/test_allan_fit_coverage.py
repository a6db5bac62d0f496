"""The least-squares noise terms' ±1σ are honest: they cover the simulated truth as often as
a standard error should, and the Allan variances' covariance they rest on is exact.

* ``avar_covariance`` against the covariance of two quadratic forms of a Gaussian vector,
  ``cov(xᵀAx, xᵀBx) = 2 tr(AΣBΣ) + 4 μᵀAΣBμ``, written here with dense matrices on the
  phase: Brownian motion (white FM), integrated Brownian motion (random-walk FM, covariance
  s²(3t − s)/6), independent phase points (white PM) and a ramp's mean R t²/2.
* coverage over 40 seeded records of each of three noise mixtures (white + random walk,
  white + flicker + random walk, angle quantisation + white): the share of |Ĉ − C| ≤ 1σ
  and ≤ 2σ over every (record, true term).  A standard error covers 68.3 % and 95.4 %;
  the 280 pairs are not independent (the terms of one record are correlated), so the 1σ
  share is accepted in 0.58 … 0.78 (about ±2.5 binomial standard deviations of 120
  independent pairs) and the 2σ share in 0.88 … 1; each term alone at least 0.40 and 0.80.
  Before the fit used the variances' covariance (independent points, ``(AᵀWA)⁻¹``), the
  shares were about 0.5 and 0.8, random-walk terms 0.4 and 0.7.  The mean of (Ĉ − C)/σ per
  term is within ±0.4 of 0 (unbiased: its standard deviation over 40 records is 0.16).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.simulate.noise import NoiseParams, simulate_noise
from thermocal.stability.allan import avar_covariance, noise_terms, overlapping_adev

LN2 = math.log(2.0)


def _second_difference_form(n_phase: int, m: int, tau0: float) -> np.ndarray:
    """The matrix A of σ̂²(mτ0) = xᵀAx on the phase x (NIST SP 1065 eq. 11)."""
    rows = n_phase - 2 * m
    d = np.zeros((rows, n_phase))
    k = np.arange(rows)
    d[k, k], d[k, k + m], d[k, k + 2 * m] = 1.0, -2.0, 1.0
    return d.T @ d / (2.0 * (m * tau0) ** 2 * rows)


def _dense_covariance(
    n_phase: int, ms: list[int], tau0: float, n2: float, k2: float, q_x2: float, r: float
) -> np.ndarray:
    t = np.arange(n_phase) * tau0
    s, u = np.minimum.outer(t, t), np.maximum.outer(t, t)
    sigma = n2 * s + k2 * s * s * (3.0 * u - s) / 6.0 + q_x2 * np.eye(n_phase)
    mu = r * t * t / 2.0
    forms = [_second_difference_form(n_phase, m, tau0) for m in ms]
    out = np.empty((len(ms), len(ms)))
    for i, a in enumerate(forms):
        for j, b in enumerate(forms):
            out[i, j] = 2.0 * np.trace(a @ sigma @ b @ sigma) + 4.0 * mu @ a @ sigma @ b @ mu
    return out


@pytest.mark.parametrize(
    ("n_phase", "ms"),
    # the second sums long stretches by quadrature, the third nothing but long ones
    [(41, [1, 2, 4, 8]), (400, [1, 8, 64, 96]), (300, [70])],
)
def test_avar_covariance_equals_the_quadratic_forms(n_phase: int, ms: list[int]) -> None:
    tau0 = 0.5
    n2, k2, q_x2, r = 2.0, 0.03, 0.7, 0.01  # white FM N², random walk K², phase var., ramp
    want = _dense_covariance(n_phase, ms, tau0, n2, k2, q_x2, r)
    # σ² = 3σ_x²/τ² + N²/τ + K²τ/3 + R²τ²/2 (IEEE 952 C.1)
    coef = [3.0 * q_x2, n2, 0.0, k2 / 3.0, r * r / 2.0]
    m = np.array(ms)
    got = avar_covariance(m, n_phase - 2 * m, tau0, coef)
    np.testing.assert_allclose(got, want, rtol=1e-6)
    if len(ms) > 1:  # the two longest τ, a factor 2 or 1.5 apart, are correlated: far
        # from the diagonal matrix a fit of independent points assumes
        assert got[-2, -1] / math.sqrt(got[-2, -2] * got[-1, -1]) > 0.3


def _white_rw(seed: int) -> tuple[np.ndarray, float, dict[int, float]]:
    n_dens, k = 1.0, 0.0173  # white and random walk cross at τ = 3N²/K² ≈ 10⁴ s / 1 h
    y = simulate_noise(16384, 1.0, NoiseParams(white_density=n_dens, rate_random_walk=k),
                       np.random.default_rng(seed))  # fmt: skip
    return y, 1.0, {-1: n_dens**2, 1: k * k / 3.0}


def _white_flicker_rw(seed: int) -> tuple[np.ndarray, float, dict[int, float]]:
    n_dens, b, k = 1.0, 0.476, 0.1  # crossings near τ = 10 s and 30 s; record 6554 s
    noise = NoiseParams(white_density=n_dens, bias_instability=b, rate_random_walk=k)
    y = simulate_noise(65536, 0.1, noise, np.random.default_rng(seed))
    return y, 0.1, {-1: n_dens**2, 0: 2.0 * LN2 / math.pi * b * b, 1: k * k / 3.0}


def _angle_quantised(seed: int) -> tuple[np.ndarray, float, dict[int, float]]:
    # the angle rounded to q with the remainder carried: a phase error uniform on ±q/2,
    # variance q²/12, so σ² = 3(q²/12)/τ² (C₋₂ = q²/4); a constant rate of 6.2459 q per
    # sample makes the rounding errors independent; white rate noise of density N
    q, n_dens = 1.0, 0.4
    rng = np.random.default_rng(seed)
    rate = 6.2459 * q + rng.standard_normal(16384) * n_dens
    theta = np.concatenate([[0.0], np.cumsum(rate)])
    return np.diff(np.round(theta / q) * q), 1.0, {-2: q * q / 4.0, -1: n_dens**2}


def _shares(scenario: object) -> dict[int, tuple[int, int, int, float]]:
    """Per true term: (within 1σ, within 2σ, records, mean (Ĉ − C)/σ) over 40 seeds."""
    out: dict[int, list[int]] = {}
    bias: dict[int, list[float]] = {}
    for seed in range(40):
        y, tau0, truth = scenario(seed)  # type: ignore[operator]
        nt = noise_terms(overlapping_adev(y, tau0, unit="deg/h"))
        for p, c_true in truth.items():
            c, s = nt.fit_coefficients[p + 2], nt.fit_sigma[p + 2]
            z = abs(c - c_true) / s if np.isfinite(s) and s > 0 else math.inf
            bias.setdefault(p, []).append((c - c_true) / s if math.isfinite(z) else math.nan)
            tally = out.setdefault(p, [0, 0, 0])
            tally[0] += int(z <= 1.0)
            tally[1] += int(z <= 2.0)
            tally[2] += 1
    return {p: (t[0], t[1], t[2], float(np.mean(bias[p]))) for p, t in out.items()}


def test_fit_intervals_cover_the_truth_as_standard_errors_should() -> None:
    one = two = total = 0
    per_term = []
    for scenario in (_white_rw, _white_flicker_rw, _angle_quantised):
        for p, (c1, c2, n, z_mean) in _shares(scenario).items():
            per_term.append((scenario.__name__, p, c1 / n, c2 / n, z_mean))
            one, two, total = one + c1, two + c2, total + n
    assert total == 280
    assert 0.58 <= one / total <= 0.78, (one / total, per_term)
    assert 0.88 <= two / total <= 1.0, (two / total, per_term)
    assert all(s1 >= 0.40 and s2 >= 0.80 for _, _, s1, s2, _ in per_term), per_term
    # and centred on the truth: the mean of (Ĉ − C)/σ over 40 records is within ±0.16
    # (its own standard deviation) of 0 when unbiased; a spurious term kept in the fit
    # pulls the others down by about one σ
    assert all(abs(zm) <= 0.4 for *_, zm in per_term), per_term
