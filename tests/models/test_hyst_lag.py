"""The hyst family's lag (thermocal.models.hyst_lag): the blocked scan of irregular time steps
equal to the sample-by-sample recursion written here, on jittered clocks, repeated and
backward time stamps, long gaps, lengths that leave a tail, and records of a few runs of
equal steps; :func:`affine_scan` equal to its loop."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.models.hyst_lag import SCAN_BLOCK, affine_scan, first_order_lag


def _loop(t: np.ndarray, x: np.ndarray, tau: float) -> np.ndarray:
    """z_k = e_k z_{k−1} + (1 − c_k) T_k + (c_k − e_k) T_{k−1}, e_k = exp(−h_k/τ),
    c_k = (τ/h_k)(1 − e_k); e = c = 1 where h_k ≤ 0 (z held) — sample by sample; τ = 0:
    z = T."""
    if tau <= 0:
        return np.array(x, dtype=np.float64)
    z = [float(x[0])]
    for k in range(1, t.size):
        h = float(t[k] - t[k - 1])
        if h > 0:
            e = math.exp(-h / tau)
            c = -math.expm1(-h / tau) / (h / tau)
        else:
            e = c = 1.0
        z.append(e * z[-1] + (1.0 - c) * float(x[k]) + (c - e) * float(x[k - 1]))
    return np.array(z)


def _rel(z: np.ndarray, ref: np.ndarray) -> float:
    """Largest difference relative to the record's largest |z| (a reading crosses 0 °C)."""
    return float(np.max(np.abs(z - ref)) / np.max(np.abs(ref)))


def _record(n: int, seed: int, jitter: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """A 0.5 s clock jittered by ±jitter·0.5 s; a reading that heats, holds and cools."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(0.5 * (1.0 + jitter * rng.uniform(-1.0, 1.0, n)))
    x = 25.0 + 30.0 * np.sin(2.0 * np.pi * t / t[-1]) + 0.01 * rng.standard_normal(n)
    return t, x


@pytest.mark.parametrize("tau", [0.05, 0.5, 7.0, 300.0, 4000.0])
@pytest.mark.parametrize("n", [1, 2, 5, 4 * SCAN_BLOCK - 1, 20_000, 20_000 + 17])
def test_the_scan_equals_the_loop_on_jittered_records(n: int, tau: float) -> None:
    t, x = _record(n, seed=n)
    ref = _loop(t, x, tau)
    z = first_order_lag(t, x, tau)
    assert z.shape == ref.shape and z[0] == x[0]
    assert _rel(z, ref) < 1e-12


def test_repeated_and_backward_stamps_and_gaps_hold_or_forget_as_the_loop() -> None:
    t, x = _record(30_011, seed=7)
    t[1000:1010] = t[1000]  # repeated stamps: z held
    t[5000] = t[4999] - 0.2  # a step backwards: z held
    t[8000:] += 36_000.0  # a ten-hour gap: e = exp(−72 000) underflows to 0
    t[-5] = t[-6]  # a repeat in the tail after the last whole block
    for tau in (0.5, 300.0):
        ref = _loop(t, x, tau)
        z = first_order_lag(t, x, tau)
        assert _rel(z, ref) < 1e-12
        assert z[1005] == z[1000] and z[-5] == z[-6]


def test_a_few_runs_of_equal_steps_and_many_give_the_loop() -> None:
    """Runs of equal steps (lfilter run by run) and a clock with one step in 300 changed
    (the blocked scan): both the loop's figures."""
    n = 12_000
    few = np.concatenate([np.arange(4000) * 1.0, 4000.0 + np.arange(8000) * 0.25])
    many = np.arange(n) * 0.5
    many[::300] += 0.125
    x = 30.0 + 20.0 * np.cos(np.arange(n) / 2000.0)
    for t in (few, many):
        ref = _loop(t, x, 45.0)
        assert _rel(first_order_lag(t, x, 45.0), ref) < 1e-12


@pytest.mark.parametrize("n", [0, 3, 4 * SCAN_BLOCK, 4 * SCAN_BLOCK * SCAN_BLOCK + 9, 50_001])
def test_affine_scan_is_its_recursion(n: int) -> None:
    rng = np.random.default_rng(n)
    a = rng.uniform(0.0, 1.0, n)
    a[::97] = 0.0  # a reset: the block's past forgotten
    v = rng.standard_normal(n)
    ref, acc = [], 0.0
    for ak, vk in zip(a.tolist(), v.tolist(), strict=True):
        acc = ak * acc + vk
        ref.append(acc)
    y = affine_scan(a, v)
    assert y.shape == (n,)
    assert np.allclose(y, ref, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("order", [1, 2, 3])
def test_the_search_objective_is_the_least_squares_rss(order: int) -> None:
    """rss_at (power sums, no design matrix) against the RSS of a least squares on the
    Vandermonde matrix of the test loop's lag, two runs, fitted and misfitted lags."""
    from thermocal.models.hyst_lag import rss_at

    rng = np.random.default_rng(order)
    runs = [_record(3001, seed=11), _record(2000, seed=12)]
    times, temps = [r[0] for r in runs], [r[1] for r in runs]
    z_true = np.concatenate([_loop(t, x, 120.0) for t, x in runs])
    y = 0.3 * (z_true - 25.0) - 0.004 * (z_true - 25.0) ** 2 + 0.05 * rng.standard_normal(5001)
    for tau in (0.0, 40.0, 120.0, 900.0):
        z = np.concatenate([_loop(t, x, tau) for t, x in runs])
        v = np.vander((z - 25.0) / 30.0, order + 1)
        resid = y - v @ np.linalg.lstsq(v, y, rcond=None)[0]
        ref = float(resid @ resid)
        assert rss_at(times, temps, y, tau, order, (25.0, 30.0)) == pytest.approx(ref, rel=1e-10)
