"""Monte-Carlo coverage of the 68.3 % intervals for random-walk FM (α = −2, rate random
walk), issue 29 item 3: 200 simulated records (fixed seeds), the fraction whose interval
holds the true deviation must be 68.3 % within binomial tolerance."""

from __future__ import annotations

import numpy as np

from thermocal.stability.allan import overlapping_adev
from thermocal.stability.family import stability

RECORDS = 200
N_RATE = 2048
FACTORS = np.array([4, 16, 64, 256])
NOMINAL = 0.6826894921370859
# binomial σ of one τ's coverage over 200 records: √(0.683·0.317/200) = 0.033; ±2σ per τ
# (the seeds are fixed: the test is deterministic), and the mean of the four τ (correlated,
# so not /2) within ±0.05
PER_TAU = 0.066
ALPHAS: list[np.ndarray] = []
MEAN_TOL = 0.05


def _true_adev(m: int, q: float) -> float:
    """Rate y_k = Σ_{i≤k} w_i, w_i ~ N(0, q²): the difference of two adjacent m-averages is
    Σ_j c_j w_j with c_j = (#{k in the second block, k ≥ j} − #{k in the first, k ≥ j})/m
    (only the last 2m innovations and earlier ones matter; earlier ones cancel), so
    σ²(m) = q² Σ c_j² / 2."""
    c = np.zeros(2 * m)
    for k in range(m):
        c[: k + 1] -= 1.0 / m
    for k in range(m, 2 * m):
        c[: k + 1] += 1.0 / m
    return float(np.sqrt(q * q * float(c @ c) / 2.0))


def _coverage(kind: str) -> np.ndarray:
    q = 0.3
    truth = np.array([_true_adev(int(m), q) for m in FACTORS])
    hits = np.zeros(FACTORS.size)
    for seed in range(RECORDS):
        rng = np.random.default_rng(20_000 + seed)
        y = np.cumsum(rng.standard_normal(N_RATE)) * q + 5.0
        if kind == "family":
            c = stability(y, 1.0, ["oadev"], FACTORS.astype(float)).curves["oadev"]
            ALPHAS.append(c.alpha)
            lo, hi = c.low, c.high
        else:
            r = overlapping_adev(y, 1.0, FACTORS.astype(float), unit="deg/h")
            lo, hi = r.adev_low, r.adev_high
        hits += (lo <= truth) & (truth <= hi)
    return hits / RECORDS


def test_random_walk_intervals_cover_68_percent_family() -> None:
    """At m = 256 only 8 averages remain: the B1 ratio identifies the noise there and,
    before its α was bounded by the shorter τ's, read flicker or white FM in 43 % of the
    records (coverage 60.5 %)."""
    ALPHAS.clear()
    cov = _coverage("family")
    long_tau = np.array(ALPHAS)[:, -1]
    assert np.mean(long_tau == -2) > 0.95, np.unique(long_tau, return_counts=True)
    assert np.all(np.abs(cov - NOMINAL) < PER_TAU), cov
    assert abs(float(cov.mean()) - NOMINAL) < MEAN_TOL, cov


def test_random_walk_intervals_cover_68_percent_allan() -> None:
    cov = _coverage("allan")
    assert np.all(np.abs(cov - NOMINAL) < PER_TAU), cov
    assert abs(float(cov.mean()) - NOMINAL) < MEAN_TOL, cov


SHORT_RECORDS = 400
N_SHORT = 768  # octave m up to 256 ≈ N/3, the longest τ with 2 + 256 second differences
SHORT_FACTORS = [1, 2, 4, 8, 16, 32, 64, 128, 256]


def _short_coverage(kind: str) -> np.ndarray:
    """Coverage per octave τ of the default path's 68.3 % interval over 200 records of
    768 samples (white FM: σ² = q²/m; random-walk FM: :func:`_true_adev`)."""
    q = 0.3
    rng = np.random.default_rng(29_768 if kind == "white" else 29_769)
    w = rng.standard_normal((SHORT_RECORDS, N_SHORT)) * q
    records = w + 2.0 if kind == "white" else np.cumsum(w, axis=1) + 2.0
    truth = np.array(
        [q / np.sqrt(m) if kind == "white" else _true_adev(m, q) for m in SHORT_FACTORS]
    )
    hits = np.zeros(len(SHORT_FACTORS))
    for y in records:
        r = overlapping_adev(y, 1.0, "octave", unit="deg/h")
        assert r.m.tolist() == SHORT_FACTORS
        hits += (r.adev_low <= truth) & (truth <= r.adev_high)
    return hits / SHORT_RECORDS


def test_short_records_cover_68_percent_up_to_the_last_octave() -> None:
    """White FM and random-walk FM, 768 samples, m = 1 … 256 (≈ N/3), 400 records: within
    ±3 binomial σ (0.070; 18 (kind, τ) checks) for m = 2 … 64; at m = 1, 128 and 256 the
    interval must not under-cover.  Measured (400 records, seed 7, this path = Greenhall's
    EDF): m = 256 covers 0.758 (white) and 0.752 (random walk); with SP 1065's simple EDF
    (the path before) 0.788 and 0.765.  The over-coverage at m ≈ N/3 is not the EDF's:
    Greenhall's EDF there equals the Monte-Carlo 2E²/Var of σ̂² (white 2.67 vs 2.53,
    random walk 1.41 vs 1.44) and the chi-square interval at the Monte-Carlo EDF covers
    0.75 / 0.73 too — σ̂² from 2–3 effective terms is not chi-square distributed.  At m = 1
    Greenhall's white-FM EDF is too large (N = 1001: 782; the exact value and the
    Monte-Carlo one 666), the interval too narrow (coverage ≈ 0.64); Stable32 has the same."""
    tol = 3.0 * np.sqrt(NOMINAL * (1.0 - NOMINAL) / SHORT_RECORDS)
    for kind in ("white", "rw"):
        cov = _short_coverage(kind)
        assert np.all(np.abs(cov[1:7] - NOMINAL) < tol), (kind, cov)
        assert np.all(cov[[0, 7, 8]] > NOMINAL - tol - 0.03 * (kind == "white")), (kind, cov)
