"""The stability maths against values written out here (:mod:`thermocal.stability.noise_model`,
:mod:`thermocal.stability.family`, :mod:`thermocal.stability.edf`): the noise model's
bound and discrete conversion, MTIE over gapped stretches, MDEV's last τ, and B1's noise
identification.  Each kills a mutant of ``benchmarks/mutation_check.py``."""

from __future__ import annotations

import numpy as np
import pytest


def test_noise_model_bound_and_discrete_conversion_by_hand() -> None:
    """White rate noise only (1000 s at 100 Hz, 36 °/h): the rate random walk is not in the
    record, so it is the bound K ≤ σ_high(τ)·√(3/τ) minimised over τ (the +½ line read at
    τ = 3 s: mutant noise-model-walk-sqrt3 uses 3 for √3), in rad/s²/√Hz; Kalibr's file
    states the discrete σ_d = σ_c/√Δt of the density (mutant noise-model-discrete-sqrt-dt
    writes σ_c·√Δt)."""
    import math

    from thermocal.stability.noise_model import axis_noise, kalibr_yaml, noise_model

    rng = np.random.default_rng(13)
    v = rng.normal(0.0, 36.0, 100_000)
    ax = axis_noise(v, 0.01, name="gx", sensor="gyro", unit="deg/h")
    assert ax.walk.method == "bound"
    res = ax.allan
    ok = np.isfinite(res.adev_high) & (res.adev > 0)
    bound = np.min(res.adev_high[ok] * np.sqrt(3.0 / res.tau_s[ok]))
    assert ax.walk.value == pytest.approx(bound * math.pi / 180.0 / 3600.0, rel=1e-12)
    # Kalibr's imu.yaml needs both sensors (the writer refuses a file without the
    # accelerometer keys): a quiet accelerometer axis completes the model
    acc = axis_noise(rng.normal(0.0, 0.01, 100_000), 0.01, name="az", sensor="accel", unit="m/s^2")
    text = kalibr_yaml(noise_model([ax, acc], 100.0), "test")
    lines = text.splitlines()
    k = next(i for i, x in enumerate(lines) if x.startswith("gyroscope_noise_density:"))
    sigma_c = float(lines[k].split(":")[1])
    disc = next(x for x in lines[:k][::-1] if "σ_d" in x)
    assert "σ_c / √Δt" in disc
    assert float(disc.rsplit("=", 1)[1]) == pytest.approx(sigma_c / math.sqrt(0.01), rel=1e-5)
    # the density itself: 36 °/h white noise at 100 Hz is 36/√100 °/h/√Hz = 3.6 °/h/√Hz
    assert sigma_c == pytest.approx(3.6 * math.pi / 180.0 / 3600.0, rel=0.05)


def test_mtie_of_gapped_data_is_the_largest_over_the_stretches() -> None:
    """Two gap-free stretches of rate data (τ0 = 1 s), the second wandering more: MTIE(m)
    of the whole is the larger of the two stretches' own MTIE (mutant stability-mtie-sum
    adds them); the phase over a gap is unknown, so no window spans it."""
    from thermocal.stability.family import stability

    rng = np.random.default_rng(17)
    y = np.r_[rng.normal(0.0, 1.0, 300), rng.normal(0.0, 3.0, 300)]
    taus = [1.0, 4.0, 16.0]
    res = stability(y, 1.0, ["mtie"], taus, segments=[slice(0, 300), slice(300, 600)])
    one = stability(y[:300], 1.0, ["mtie"], taus).curves["mtie"].dev
    two = stability(y[300:], 1.0, ["mtie"], taus).curves["mtie"].dev
    np.testing.assert_allclose(res.curves["mtie"].dev, np.maximum(one, two), rtol=1e-12)
    assert np.all(two > one)


def test_mdev_stops_where_its_terms_do() -> None:
    """Modified Allan deviation of N phase points needs N − 3m + 1 ≥ 1 terms: with 31
    points every m up to 10 has a finite value with that many terms, and none beyond
    (mutant stability-mdev-max-factor asks for m = 11)."""
    from thermocal.stability.family import stability

    x = np.random.default_rng(3).normal(0.0, 1.0, 31)
    res = stability(x, 1.0, ["mdev"], "all", data_type="phase")
    c = res.curves["mdev"]
    assert list(c.m) == list(range(1, 11))
    assert np.all(np.isfinite(c.dev))
    np.testing.assert_array_equal(c.n_terms, 31 - 3 * c.m + 1)


def _b1(ym: np.ndarray) -> float:
    """B1 = standard variance (n − 1) of the averages over their Allan variance."""
    return float(np.var(ym, ddof=1) / (np.mean(np.diff(ym) ** 2) / 2.0))


def _averages_with_b1(lo: float, hi: float, walk: bool) -> np.ndarray:
    """Ten averages whose B1 lies in [lo, hi] (the first seed that gives one)."""
    for seed in range(10_000):
        y = np.random.default_rng(seed).normal(0.0, 1.0, 10)
        ym = np.cumsum(np.cumsum(y)) if walk else y
        if lo <= _b1(ym) <= hi:
            return ym
    raise AssertionError("no seed")


def test_b1_noise_identification_by_hand() -> None:
    """Ten averages (too few for the lag-1 method): B1 against the boundaries of Howe,
    Beard, Greenhall & Riley (2000) table 3 for N = 10, worked here: white PM/FM
    √((N²−1)/(1.5N(N−1)) · 1) = 0.856, white/flicker FM √(N ln N/(2(N−1) ln 2)) = 1.358;
    flicker/random-walk FM … √(N/2 · N(N+1)/6) = 9.57 (Hadamard only).  B1 = 0.90 is white
    FM (α = 0; mutant stability-b1-ddof computes B1 with n, 0.81: white PM); B1 = 9.2 on
    the Hadamard ladder is flicker-walk μ = 1 (α = −2; mutant stability-edf-white-fm puts
    the boundary at √(N/2 · N(N−1)/6) = 8.66)."""
    from thermocal.stability.edf import identify_noise

    assert np.sqrt((99.0 / 135.0) * 1.0) == pytest.approx(0.856, abs=1e-3)
    ym = _averages_with_b1(0.88, 0.95, walk=False)
    x = np.r_[0.0, np.cumsum(ym)]  # phase of rate samples = the averages at m = 1
    nid = identify_noise(x, 1, dmax=2, phase_input=False)
    assert (nid.method, nid.alpha) == ("b1", 0)
    ym = _averages_with_b1(8.9, 9.4, walk=True)
    nid = identify_noise(np.r_[0.0, np.cumsum(ym)], 1, dmax=3, phase_input=False)
    assert (nid.method, nid.alpha) == ("b1", -2)
