"""Allan deviation checks against formulas written out here (IEEE Std 952-1997 Annex C,
NIST SP 1065 §5.2), for the parts a mutation check found unguarded (issue 12 §5)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.stability import allan


def _exact_curve(n_arw: float, k_rrw: float) -> allan.AllanResult:
    """An exact ARW + RRW Allan deviation, σ²(τ) = N²/τ + K²τ/3 (IEEE 952 C.1, C.4),
    on octave τ from 1 s to 2²⁴ s, with tight confidence intervals."""
    m = 2 ** np.arange(0, 25)
    tau = m.astype(float)
    adev = np.sqrt(n_arw**2 / tau + k_rrw**2 * tau / 3.0)
    return allan.AllanResult(
        tau_s=tau,
        m=m,
        adev=adev,
        adev_low=adev * 0.99,
        adev_high=adev * 1.01,
        n_terms=np.full(m.size, 10**7),
        edf=np.full(m.size, 1e5),
        alpha=np.zeros(m.size, dtype=np.int64),
        unit="deg/h",
        confidence=0.683,
        tau0_s=1.0,
        n_samples=10**8,
        n_segments=1,
    )


def test_slope_lines_read_arw_at_1s_and_rrw_at_3s() -> None:
    """N = 0.5 °/h·√s (ARW = N/60 = 0.008333 °/√h), K = 2e-3 °/h/√s (RRW = 60 K =
    0.12 °/h/√h).  The +1/2 line σ = K √(τ/3) read at τ = 3 s gives K; read at 1 s
    it would give K/√3 (IEEE 952 C.4)."""
    nt = allan.noise_terms(_exact_curve(0.5, 2e-3))
    s = nt.slope
    assert s.angle_random_walk.value == pytest.approx(0.5 / 60.0, rel=0.02)
    assert s.rate_random_walk.value == pytest.approx(2e-3 * 60.0, rel=0.02)
    assert s.rate_random_walk.unit == "deg/h/sqrt(h)"
    # the least-squares fit of the same exact curve recovers both too
    assert nt.fit.angle_random_walk.value == pytest.approx(0.5 / 60.0, rel=1e-3)
    assert nt.fit.rate_random_walk.value == pytest.approx(2e-3 * 60.0, rel=1e-3)


def test_gapped_data_pool_the_edf_of_every_segment() -> None:
    """Two gap-separated segments: the pooled equivalent degrees of freedom at each τ are
    the sum of each segment's own (SP 1065 §5.2: independent estimates add their EDF)."""
    rng = np.random.default_rng(5)
    a, b = rng.standard_normal(4000), rng.standard_normal(2500)
    t = np.concatenate([np.arange(4000.0), 10_000.0 + np.arange(2500.0)])
    pooled = allan.overlapping_adev(np.concatenate([a, b]), 1.0, "octave", time_s=t, alpha=0)
    ra = allan.overlapping_adev(a, 1.0, "octave", alpha=0)
    rb = allan.overlapping_adev(b, 1.0, "octave", alpha=0)
    for i, m in enumerate(pooled.m.tolist()):
        expect = 0.0
        for r in (ra, rb):
            hit = np.flatnonzero(r.m == m)
            if hit.size:
                expect += float(r.edf[hit[0]])
        assert pooled.edf[i] == pytest.approx(expect, rel=1e-12), m


def test_white_noise_edf_formula_sp1065() -> None:
    """SP 1065 Table 5 (white FM, α = 0), overlapping Allan variance: for m = 1 the EDF
    is ((3(N−1)/2) − 2(N−2)/N) · 4m²/(4m² + 5) with N phase points."""
    n_phase, m = 1001, 1
    expect = (
        ((3.0 * (n_phase - 1) / 2.0) - 2.0 * (n_phase - 2) / n_phase) * 4 * m**2 / (4 * m**2 + 5)
    )
    got = float(allan.edf_simple(n_phase, np.array([m]), np.array([0]))[0])
    assert got == pytest.approx(expect, rel=1e-12)
    assert math.isfinite(got)
