"""Theo1's equivalent degrees of freedom (issue 29, item 4 of the noise-term brief):
:func:`thermocal.stability.edf.edf_theo1` against the scatter of Theo1 itself over many
simulated records of a known power-law noise.

For an estimator distributed as σ² χ²_ν / ν the EDF is ν = 2 E[σ̂²]² / Var[σ̂²]; the
Monte-Carlo value is computed here from Theo1 written out in numpy (NIST SP 1065 eq. for
Theo1), not from thermocal's implementation.  Howe's EDF formulas are empirical fits
(a few to ~15 % here); the test allows 20 %, well beyond the Monte-Carlo error
(√(2/R)-ish, ≈ 4 % at R = 2000), and far below the factor the old "no interval" left."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.stability.edf import edf_theo1

N_PHASE = 201
REPS = 2000


def _theo1_var(x: np.ndarray, m: int) -> float:
    """Theo1 variance at τ = 0.75 m τ0 (τ0 = 1): 1/(0.75 (N − m) (m τ0)²) Σ_i Σ_δ
    [(x_i − x_{i−δ+m/2}) + (x_{i+m} − x_{i+δ+m/2})]² / (m/2 − δ)."""
    n = x.size
    h = m // 2
    total = 0.0
    for i in range(n - m):
        for d in range(h):
            v = (x[i] - x[i - d + h]) + (x[i + m] - x[i + d + h])
            total += v * v / (h - d)
    return total / (0.75 * (n - m) * m * m)


def _theo1_var_fast(x: np.ndarray, m: int) -> float:
    """The same sum vectorised over i (checked against :func:`_theo1_var` below)."""
    n = x.size
    h = m // 2
    i = np.arange(n - m)
    total = 0.0
    for d in range(h):
        v = (x[i] - x[i - d + h]) + (x[i + m] - x[i + d + h])
        total += float(v @ v) / (h - d)
    return total / (0.75 * (n - m) * m * m)


def _record(rng: np.random.Generator, alpha: int) -> np.ndarray:
    w = rng.standard_normal(N_PHASE)
    if alpha == 2:  # white PM: the phase is white
        return w
    if alpha == 0:  # white FM: the phase is a random walk
        return np.cumsum(w)
    return np.cumsum(np.cumsum(w))  # random-walk FM


def test_vectorised_sum_is_the_definition() -> None:
    x = np.random.default_rng(1).standard_normal(40)
    assert _theo1_var_fast(x, 10) == pytest.approx(_theo1_var(x, 10), rel=1e-12)


@pytest.mark.parametrize("alpha", [2, 0, -2])
@pytest.mark.parametrize("m", [4, 20, 60])
def test_edf_matches_the_scatter_of_theo1(alpha: int, m: int) -> None:
    rng = np.random.default_rng(1000 + 10 * m + alpha)
    v = np.array([_theo1_var_fast(_record(rng, alpha), m) for _ in range(REPS)])
    edf_mc = 2.0 * v.mean() ** 2 / v.var(ddof=1)
    assert edf_theo1(N_PHASE, m, alpha) == pytest.approx(edf_mc, rel=0.20)


def test_white_fm_value_written_out() -> None:
    # α = 0, N = 1001, m = 100: t = 75, ((4.1·1001 + 0.8)/75 − (3.1·1001 + 6.5)/1001)
    # · 75^1.5/(75^1.5 + 5.2)
    t = 75.0
    expect = ((4.1 * 1001 + 0.8) / t - (3.1 * 1001 + 6.5) / 1001) * t**1.5 / (t**1.5 + 5.2)
    assert edf_theo1(1001, 100, 0) == pytest.approx(expect, rel=1e-12)
    assert math.isnan(edf_theo1(1001, 1001, 0))  # beyond m = N − 1
    assert math.isnan(edf_theo1(1001, 0, 0))
