"""The octave fast path of issue 29 item 6: rate data at octave τ take adev, hdev and the
noise identification from a pyramid of pairwise block sums (no phase array).  It must give
what the phase path gives (values, terms, α and how it was found, EDF, intervals) and what
the definitions give, written out here from reshaped block sums in extended precision."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.stability.family import stability

NAMES = ["adev", "hdev", "oadev", "mdev", "ohdev", "totdev"]


def _record(kind: str) -> tuple[np.ndarray, list[slice] | None]:
    """Rate records shaped like gyro output [deg/h]: a bias, white noise, random walk,
    a quantised one, and one with gaps (stretches of odd lengths, one too short to use)."""
    rng = np.random.default_rng(29)
    n = 100_003
    white = rng.standard_normal(n)
    if kind == "white":
        return 12.5 + 0.8 * white, None
    if kind == "random_walk":
        return -40.0 + white + np.cumsum(rng.standard_normal(n)) * 0.02, None
    if (
        kind == "integrated_walk"
    ):  # α down to −4 at long τ: the Hadamard identification differences twice
        return 1.0 + white + np.cumsum(np.cumsum(rng.standard_normal(n))) * 2e-6, None
    if kind == "quantised":
        return np.round(
            (3.0 + white + np.cumsum(rng.standard_normal(n)) * 0.01) / 0.05
        ) * 0.05, None
    # gaps: three stretches of odd lengths and a 1-sample stretch (gives too few points)
    y = 7.0 + white + np.cumsum(rng.standard_normal(n)) * 0.005
    return y, [slice(0, 40_001), slice(40_001, 40_002), slice(40_010, 77_777), slice(77_790, n)]


def _general(y: np.ndarray, seg: list[slice] | None, tau0: float):  # type: ignore[no-untyped-def]
    """The same octave factors plus one that is not a power of two at the end: every factor
    then goes through the phase path (the extra one comes last, so no α carried to the
    octave points changes)."""
    fast = stability(y, tau0, NAMES, "octave", segments=seg)
    extra = int(fast.m[-1]) + 1  # not a power of two
    slow = stability(y, tau0, NAMES, np.append(fast.m, extra) * tau0, segments=seg)
    assert slow.m.size == fast.m.size + 1 and slow.m[-1] == extra
    return fast, slow


@pytest.mark.parametrize("kind", ["white", "random_walk", "integrated_walk", "quantised", "gaps"])
def test_octave_fast_path_equals_phase_path(kind: str) -> None:
    y, seg = _record(kind)
    before = y.copy()
    fast, slow = _general(y, seg, 0.01)
    np.testing.assert_array_equal(y, before)  # the caller's samples are never written over
    assert fast.n_segments == slow.n_segments and fast.n_points == slow.n_points
    for name in NAMES:
        a, b = fast.curves[name], slow.curves[name]
        k = a.m.size
        assert np.array_equal(a.m, b.m[:k])
        ok = np.isfinite(b.dev[:k])
        assert np.array_equal(np.isfinite(a.dev), ok), name
        # the phase path's running sum rounds to 1.4e-12 on the integrated walk (the fast
        # path stays within 1e-13 of the definition: the test below)
        np.testing.assert_allclose(a.dev[ok], b.dev[:k][ok], rtol=3e-12, atol=0, err_msg=name)
        np.testing.assert_array_equal(a.n_terms, b.n_terms[:k], err_msg=name)
        np.testing.assert_array_equal(a.alpha, b.alpha[:k], err_msg=name)
        assert a.alpha_method == b.alpha_method[:k], name
        np.testing.assert_allclose(a.edf, b.edf[:k], rtol=1e-12, err_msg=name)
        fin = np.isfinite(b.low[:k])
        np.testing.assert_allclose(a.low[fin], b.low[:k][fin], rtol=3e-12, err_msg=name)
        np.testing.assert_allclose(a.high[fin], b.high[:k][fin], rtol=3e-12, err_msg=name)


@pytest.mark.parametrize("kind", ["gaps", "integrated_walk"])
def test_octave_adev_hdev_equal_block_sum_definition(kind: str) -> None:
    """SP 1065 eqs. 7 and 17 through the m-sample block sums of the rate, each stretch on
    its own and pooled as Σ squares / Σ terms (long double, written here)."""
    y, seg = _record(kind)
    seg = seg or [slice(0, y.size)]
    tau0 = 0.01
    res = stability(y, tau0, ["adev", "hdev"], "octave", segments=seg)
    stretches = [y[s] for s in seg if y[s].size >= 2]
    for name, d, c in (("adev", 1, 2.0), ("hdev", 2, 6.0)):
        curve = res.curves[name]
        for i, m in enumerate(curve.m.tolist()):
            num = terms = np.longdouble(0.0)
            for s in stretches:
                z = s.astype(np.longdouble)
                z -= z.mean()
                nb = z.size // m
                if nb < d + 1:
                    continue
                blocks = z[: nb * m].reshape(nb, m).sum(axis=1)
                diff = np.diff(blocks, d)
                num += (diff @ diff) / (c * m * m)
                terms += diff.size
            if terms == 0:  # m beyond this deviation's reach in every stretch
                assert np.isnan(curve.dev[i]) and curve.n_terms[i] == 0, (name, m)
                continue
            want = float(np.sqrt(num / terms))
            assert curve.dev[i] == pytest.approx(want, rel=1e-13), (name, m)
            assert curve.n_terms[i] == float(terms), (name, m)
