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


@pytest.mark.parametrize("m", [1, 3, 8])
def test_phase_lag1_in_cache_blocks_equals_the_centred_copy(m: int) -> None:
    """The phase's lag-1 r1 and its differences' r1, taken block by block from a strided
    view (no centred copy), equal Riley & Greenhall's formula written here on a centred
    copy with numpy, and the noise identified is the same: white PM, white FM, random-walk
    FM phase, with a large offset, longer than the whole-array threshold."""
    rng = np.random.default_rng(7)
    n = 3 * ed._WHOLE_PHASE * m + 12_345
    records = {
        "wpm": rng.standard_normal(n) * 1e-9 + 5.0,
        "wfm": np.cumsum(rng.standard_normal(n)) + 1e6,
        "rwfm": np.cumsum(np.cumsum(rng.standard_normal(n))),
    }

    def r1_direct(v: np.ndarray) -> float:
        c = v - v.mean()
        return float(c[:-1] @ c[1:] / (c @ c))

    for name, x in records.items():
        z = x[::m]
        assert z.size > ed._WHOLE_PHASE
        mu = float(z.mean())
        zc = z - mu
        assert ed._lag1_centred(z, mu) == pytest.approx(r1_direct(zc), rel=1e-13, abs=1e-15)
        for d in (1, 2):
            got = ed._lag1_of_difference(z, d, mu)
            assert got == pytest.approx(r1_direct(np.diff(zc, d)), rel=1e-13, abs=1e-15), name
        for dmax in (2, 3):
            nid = ed.identify_noise(x, m, dmax=dmax, phase_input=True)
            # Riley & Greenhall's rule by hand on the centred copy
            d, r1 = 0, r1_direct(zc)
            while r1 / (1 + r1) >= 0.25 and d < dmax:
                d += 1
                r1 = r1_direct(np.diff(zc, d))
            assert (nid.alpha, nid.d) == (-round(2 * r1 / (1 + r1)) - 2 * d + 2, d), name
