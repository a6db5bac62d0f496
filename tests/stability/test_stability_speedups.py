"""The faster noise identification and sums of issue 29 item 1 give the numbers of the
direct computations (written out here): the lag-1 autocorrelation of the linearly
detrended m-averages, the m-averages from the decimated phase, the blocked difference
sums, and the caller's phase array is never written over by the in-place centring."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.stability import deviations as dv
from thermocal.stability import edf as ed
from thermocal.stability.family import stability


def _r1_direct(z: np.ndarray) -> float:
    """Least-squares line removed by numpy's lstsq, then Σ c_k c_{k+1} / Σ c_k²."""
    k = np.arange(z.size, dtype=np.float64)
    a = np.vstack([np.ones_like(k), k]).T
    coef, *_ = np.linalg.lstsq(a, z, rcond=None)
    c = z - a @ coef
    c = c - c.mean()
    return float(c[:-1] @ c[1:] / (c @ c))


@pytest.mark.parametrize("kind", ["white", "random_walk", "drift", "integrated_rw"])
def test_lag1_of_detrended_averages_from_sums_equals_direct(kind: str) -> None:
    rng = np.random.default_rng(11)
    n = 70_001  # more than one block of the index sums
    w = rng.standard_normal(n)
    z = {
        "white": w,
        "random_walk": np.cumsum(w),
        "drift": w + 1e-3 * np.arange(n) + 50.0,
        "integrated_rw": np.cumsum(np.cumsum(w)),
    }[kind]
    want = _r1_direct(z)
    got = ed._lag1_linear_detrended(z.copy(), own=True)
    assert got == pytest.approx(want, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("m", [1, 3, 8, 64])
def test_noise_id_on_decimated_phase_equals_block_averages(m: int) -> None:
    """Rate data: α at m from the m-averages of the rate taken directly (reshape-mean of
    the samples) and the lag-1 rule of Riley & Greenhall written here."""
    rng = np.random.default_rng(3)
    n = 40_000
    y = rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * (0.05 if m > 8 else 0.0)
    x = np.concatenate([[0.0], np.cumsum(y)])  # phase, τ0 = 1
    nb = n // m
    z = y[: nb * m].reshape(nb, m).mean(axis=1)
    d = 0
    r1 = _r1_direct(z)
    zz = z
    while True:
        rho = r1 / (1.0 + r1)
        if rho < 0.25 or d >= 1:  # dmax = 2 on phase: one difference of the rate
            want = -round(2.0 * rho) - 2 * d
            want_float = -2.0 * (rho + d)
            break
        zz = np.diff(zz)
        d += 1
        c = zz - zz.mean()
        r1 = float(c[:-1] @ c[1:] / (c @ c))
    nid = ed.identify_noise(x, m, dmax=2, phase_input=False)
    assert nid.method == "lag1"
    assert nid.alpha == want
    assert nid.alpha_float == pytest.approx(want_float, rel=1e-9, abs=1e-12)


def test_blocked_sums_equal_whole_array_sums() -> None:
    """oadev, ohdev, mdev, totdev of a record longer than several blocks: the sums of the
    whole-array expressions (SP 1065 eqs. 11, 18, 14, 25) written here."""
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.standard_normal(400_003)) * 0.01
    x = dv.centred(x)
    n = x.size
    m = np.array([1, 7, 64, 1000])
    num, cnt = dv.segment_sums("oadev", x, 1.0, m)
    for i, mm in enumerate(m.tolist()):
        v = x[2 * mm :] - 2.0 * x[mm:-mm] + x[: -2 * mm]
        assert num[i] == pytest.approx(float(v @ v) / (2.0 * mm * mm), rel=1e-12)
        assert cnt[i] == n - 2 * mm
    num, cnt = dv.segment_sums("ohdev", x, 1.0, m)
    for i, mm in enumerate(m.tolist()):
        v = x[3 * mm :] - 3.0 * x[2 * mm : n - mm] + 3.0 * x[mm : n - 2 * mm] - x[: n - 3 * mm]
        assert num[i] == pytest.approx(float(v @ v) / (6.0 * mm * mm), rel=1e-12)
    num, cnt = dv.segment_sums("mdev", x, 1.0, m)
    for i, mm in enumerate(m.tolist()):
        s = np.convolve(x, np.ones(mm), mode="valid")  # Σ of m consecutive phases
        k = n - 3 * mm + 1
        v = s[2 * mm : 2 * mm + k] - 2.0 * s[mm : mm + k] + s[:k]
        assert num[i] == pytest.approx(float(v @ v) / (2.0 * mm**4), rel=1e-8)
        assert cnt[i] == k
    num, cnt = dv.segment_sums("totdev", x, 1.0, m)
    ext = np.concatenate([2 * x[0] - x[1 : n - 1][::-1], x, 2 * x[-1] - x[1 : n - 1][::-1]])
    for i, mm in enumerate(m.tolist()):
        centre = np.arange(n - 2) + (n - 1)  # x_1 … x_{N−2} in the extended series
        v = ext[centre - mm] - 2.0 * ext[centre] + ext[centre + mm]
        assert num[i] == pytest.approx(float(v @ v) / (2.0 * mm * mm), rel=1e-12)
        assert cnt[i] == n - 2


def test_phase_input_is_not_written_over() -> None:
    rng = np.random.default_rng(2)
    x = np.cumsum(rng.standard_normal(5000)) + 3.0 * np.arange(5000)
    keep = x.copy()
    stability(x, 1.0, ["oadev", "mdev"], "octave", data_type="phase")
    np.testing.assert_array_equal(x, keep)
    y = rng.standard_normal(5000) + 7.0
    keep = y.copy()
    stability(y, 1.0, ["oadev", "totdev"], "octave")
    np.testing.assert_array_equal(y, keep)
