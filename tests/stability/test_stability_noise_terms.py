"""Noise terms on a record shaped like a real static MEMS one (issue 29 item 2): 2.8 h at
100 Hz, rate quantised to 0.05 °/s, angle random walk, a flicker (bias-instability) floor and
rate random walk, built here with known truth.  The flicker is shaped in the frequency
domain to the IEEE 952 PSD S(f) = (B²/2π)/f, whose Allan deviation is flat at 0.6643 B."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.stability import allan

FS = 100.0
N_ARW_DEG_SQRT_H = 1.0  # angle random walk [°/√h]
B_DEG_H = 30.0  # bias instability [°/h]
K_DEG_H_SQRT_H = 38.0  # rate random walk [°/h/√h]
Q_RATE_DEG_S = 0.05  # rate quantisation step [°/s]


def _record(seed: int) -> np.ndarray:
    """Rate [°/h] of 2.8 h at 100 Hz."""
    rng = np.random.default_rng(seed)
    n = int(2.8 * 3600 * FS)
    white = rng.standard_normal(n) * (N_ARW_DEG_SQRT_H * 60.0) * math.sqrt(FS)  # σ = N√fs
    # flicker: IEEE 952's S(f) = (B²/2π)/f is two-sided, i.e. one-sided B²/(π f) (its σ² =
    # 2 ln2 h₋₁ = (2 ln2/π) B²); irfft of c_k (g1 + i g2)/√2 with c_k = √(S(f_k) fs n / 2)
    # has the one-sided PSD S
    f = np.fft.rfftfreq(n, 1.0 / FS)
    s = np.zeros_like(f)
    s[1:] = B_DEG_H**2 / (math.pi * f[1:])
    z = (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) / math.sqrt(2.0)
    flicker = np.fft.irfft(z * np.sqrt(s * FS * n / 2.0), n)
    k_native = K_DEG_H_SQRT_H / 60.0  # °/h/√s
    rrw = np.cumsum(rng.standard_normal(n)) * k_native / math.sqrt(FS)
    rate = 20.0 + white + flicker + rrw  # °/h
    q = Q_RATE_DEG_S * 3600.0
    return np.asarray(np.round(rate / q) * q)


@pytest.fixture(scope="module")
def terms() -> tuple[allan.AllanResult, allan.NoiseTerms]:
    res = allan.overlapping_adev(_record(29), 1.0 / FS, "log", unit="deg/h")
    return res, allan.noise_terms(res)


def test_bias_instability_is_found_at_the_minimum(
    terms: tuple[allan.AllanResult, allan.NoiseTerms],
) -> None:
    res, nt = terms
    bi = nt.slope.bias_instability
    assert bi.value is not None, bi.reason
    assert bi.unit == "deg/h" and bi.tau_s is not None and bi.quality in (None, "rough", "poor")
    assert bi.low is not None and bi.high is not None
    # truth inside the reported interval widened by the other terms' share at the minimum
    # (white and random-walk add ≤ 6 % to the flat level there, computed from the truth)
    tau = bi.tau_s
    others = (N_ARW_DEG_SQRT_H * 60.0) ** 2 / tau + (K_DEG_H_SQRT_H / 60.0) ** 2 * tau / 3.0
    flat = allan.BIAS_INSTABILITY_FACTOR * B_DEG_H
    expect = math.sqrt(flat**2 + others) / allan.BIAS_INSTABILITY_FACTOR
    assert bi.low <= expect <= bi.high, (bi.low, expect, bi.high)
    assert bi.value == pytest.approx(B_DEG_H, rel=0.15)
    assert res.adev.size > 20


def test_arw_and_rrw_within_their_intervals(
    terms: tuple[allan.AllanResult, allan.NoiseTerms],
) -> None:
    _res, nt = terms
    # the rate quantisation adds white noise of variance q²/12 per sample: N² += q²/12 · τ0
    q = Q_RATE_DEG_S * 3600.0
    n_true = math.sqrt((N_ARW_DEG_SQRT_H * 60.0) ** 2 + q * q / 12.0 / FS) / 60.0
    arw = nt.slope.angle_random_walk
    assert arw.value is not None and arw.low is not None and arw.high is not None, arw.reason
    assert arw.unit == "deg/sqrt(h)" and arw.tau_s is not None
    assert arw.value == pytest.approx(n_true, rel=0.1)
    assert arw.low <= n_true * 1.02 and arw.high >= n_true * 0.98
