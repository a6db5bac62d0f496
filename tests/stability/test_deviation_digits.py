"""The deviation family keeps its digits on long records with a large mean (issue 42).

Records: rate samples y_i = 1e6 °/h (offset) + random-walk + white content, on a dyadic grid
(every sample an integer multiple of 2⁻¹⁰ °/h, exactly representable in float64).  The
reference evaluates each NIST SP 1065 definition EXACTLY in integer arithmetic: with
y_i = I_i / 2¹⁰ and τ0 factored out, the phase x_k = τ0 Σ_{i<k} y_i is τ0 2⁻¹⁰ times the
integer X_k = Σ_{i<k} I_i, every difference of it (and MDEV's running sums of differences)
is an integer (numpy int64: a wrapped intermediate leaves the final difference exact, since
it fits in 63 bits), and only the last step — squares summed by ``math.fsum`` — rounds
(relative ≈ 1e-16).  Nothing of thermocal's is used for the reference: no mean removal, no
centring, no octave pyramid, no running sum in floating point.  TIE rms is of the phase of
the rate less its mean, as thermocal defines it for rate data (:func:`thermocal.stability.
deviations.as_phase`); its reference subtracts the mean's exact phase step, rounded once.

Before issue 42 MDEV and TDEV were formed from a running sum of the whole phase (magnitude
N² × the offset), and lost digits in proportion: 1e-4 relative at m = 1 on 1e5 samples.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import pytest

from thermocal.stability.family import stability

I64 = npt.NDArray[np.int64]
TAU0 = 0.01
"""Sample interval [s]."""
SCALE = 1024
"""Samples are integer multiples of 1 / SCALE °/h."""
ALL = ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev", "tierms")
REL = 1e-9


def _record(n: int, seed: int) -> I64:
    """Integer samples I_i (y_i = I_i / SCALE °/h): 1e6 °/h + a random walk (steps of
    0.05 °/h rms) + white noise (0.5 °/h rms), rounded to the grid."""
    rng = np.random.default_rng(seed)
    y = 1e6 + np.cumsum(rng.normal(0.0, 0.05, n)) + rng.normal(0.0, 0.5, n)
    return np.round(y * SCALE).astype(np.int64)


def _fsum_sq(v: I64) -> float:
    """Σ v² of integers |v| < 2⁵³, each square rounded once, summed exactly (math.fsum)."""
    f = v.astype(np.float64)
    return math.fsum((f * f).tolist())


def _diff(x: I64, m: int, d: int, step: int = 1) -> I64:
    """d-th difference at lag m of the integer phase (binomial taps), every ``step``-th k."""
    n_terms = x.size - d * m
    out = np.zeros(n_terms, dtype=np.int64)
    for j in range(d + 1):
        out += (-1) ** (d - j) * math.comb(d, j) * x[j * m : j * m + n_terms]
    return out[::step]


def _reference(name: str, ints: I64, m: int) -> float:
    """SP 1065 deviation ``name`` at factor m of y = ints / SCALE [°/h] sampled every TAU0
    (time deviations in °/h·s), from exact integer differences."""
    x = np.zeros(ints.size + 1, dtype=np.int64)
    np.cumsum(ints, out=x[1:])  # X_k: phase / (τ0 / SCALE), exact (wraps harmlessly)
    n = x.size
    tau = m * TAU0
    unit = TAU0 / SCALE  # one integer phase step [°/h·s]
    if name in ("adev", "oadev"):  # eqs. 7, 11
        v = _diff(x, m, 2, m if name == "adev" else 1)
        return math.sqrt(_fsum_sq(v) / (2.0 * v.size)) * unit / tau
    if name in ("hdev", "ohdev"):  # eqs. 17, 18
        v = _diff(x, m, 3, m if name == "hdev" else 1)
        return math.sqrt(_fsum_sq(v) / (6.0 * v.size)) * unit / tau
    if name == "tierms":  # eq. 33 on the phase of the rate less its mean S / n (as_phase)
        total = int(ints.sum())  # exact (Python int)
        step = m * total / ints.size  # the mean's phase step over m, correctly rounded
        w = _diff(x, m, 1).astype(np.float64) - step  # integers < 2⁵³: one rounding
        return math.sqrt(math.fsum((w * w).tolist()) / w.size) * unit
    if name in ("mdev", "tdev"):  # eqs. 14, 15: inner sums of m second differences
        d2 = _diff(x, m, 2)
        c = np.zeros(d2.size + 1, dtype=np.int64)
        np.cumsum(d2, out=c[1:])
        v = c[m:] - c[:-m]  # Σ_{i=j}^{j+m−1} (x_{i+2m} − 2x_{i+m} + x_i), j < N − 3m + 1
        assert v.size == n - 3 * m + 1
        mod = math.sqrt(_fsum_sq(v) / (2.0 * v.size)) * unit / (m * tau)
        return mod * tau / math.sqrt(3.0) if name == "tdev" else mod
    if name == "totdev":  # eq. 25: odd reflection at both ends, N − 2 centred terms
        left = 2 * x[0] - x[n - 2 : 0 : -1]  # x*_{−j} = 2x_0 − x_j, j = N−2 … 1
        right = 2 * x[-1] - x[-2:0:-1]  # x*_{N−1+j} = 2x_{N−1} − x_{N−1−j}, j = 1 … N−2
        ext = np.concatenate([left, x, right])
        c = n - 2  # ext index of x_0
        i = np.arange(1, n - 1) + c  # x_1 … x_{N−2}
        v = ext[i - m] - 2 * ext[i] + ext[i + m]
        return math.sqrt(_fsum_sq(v) / (2.0 * v.size)) * unit / tau
    raise ValueError(name)


def _check(ints: I64, names: tuple[str, ...]) -> float:
    """thermocal's deviations of y = ints / SCALE at every octave τ against the exact
    reference; the largest relative difference."""
    y = ints.astype(np.float64) / SCALE
    res = stability(y, TAU0, list(names), "octave")
    worst = 0.0
    for name in names:
        curve = res.curves[name]
        ok = curve.n_terms > 0  # the common octave τ run to totdev's N − 2
        assert np.count_nonzero(ok) >= 10, name
        assert np.all(np.isfinite(curve.dev[ok])), name
        for m, dev in zip(curve.m[ok].tolist(), curve.dev[ok].tolist(), strict=True):
            ref = _reference(name, ints, int(m))
            rel = abs(dev - ref) / ref
            assert rel <= REL, f"{name} m={m}: {dev!r} vs exact {ref!r} (rel {rel:.2e})"
            worst = max(worst, rel)
    return worst


@pytest.mark.parametrize("seed", [1, 2])
def test_every_deviation_keeps_its_digits_1e5(seed: int) -> None:
    """1e5 samples of 1e6 °/h + random walk: every finite-difference deviation within 1e-9
    of the exact SP 1065 value at every octave τ (m = 1 … 2¹⁴)."""
    _check(_record(100_000, seed), ALL)


def test_mdev_tdev_keep_their_digits_1e6() -> None:
    """1e6 samples (the running sums longest): MDEV, TDEV and OADEV within 1e-9 of exact."""
    _check(_record(1_000_000, 3), ("oadev", "mdev", "tdev"))


def test_mdev_equals_adev_at_m1() -> None:
    """At m = 1 the inner sum has one term: MDEV is OADEV (SP 1065 eq. 14), to the last
    digits, on a record with a 1e6 °/h mean."""
    y = _record(100_000, 4).astype(np.float64) / SCALE
    res = stability(y, TAU0, ["oadev", "mdev"], np.array([TAU0]))
    mdev, oadev = float(res.curves["mdev"].dev[0]), float(res.curves["oadev"].dev[0])
    assert mdev == pytest.approx(oadev, rel=1e-12, abs=0.0)


def test_mdev_any_factor_across_blocks() -> None:
    """MDEV at factors that are no power of 2, either side of the kernel's switch from
    nested differences to taps (m = 4096 | 4097) and with terms spanning several blocks:
    within 1e-9 of exact."""
    ints = _record(300_000, 5)
    m = np.array([3, 7, 4095, 4096, 4097, 40_000, 99_999])
    res = stability(ints.astype(np.float64) / SCALE, TAU0, ["mdev"], m * TAU0)
    curve = res.curves["mdev"]
    assert curve.m.tolist() == m.tolist()
    for mm, dev in zip(curve.m.tolist(), curve.dev.tolist(), strict=True):
        ref = _reference("mdev", ints, int(mm))
        assert abs(dev - ref) / ref <= REL, (mm, dev, ref)


# The total family and Theo1 (issue 42): their kernels are O(N·m) per τ, so the records are
# short (N ≈ 3e3–1e4) but carry the same 1e6 °/h offset.  The reference evaluates NIST SP
# 1065 eqs. 27–30 directly in numpy float64 on the record with its offset removed EXACTLY
# (J_i = I_i − 1e6·SCALE, integers): every one of these deviations cancels a constant rate
# (a phase line) — MTOT/HTOT remove each subsequence's own line, Theo1's taps sum to zero —
# so the offset-free record has the same deviations, and its phase X_k = Σ_{i<k} J_i is an
# exact integer of at most ~1e9, whose float64 sums keep ~1e-15 of their digits.
OFFSET = 1_000_000 * SCALE
"""The 1e6 °/h offset in integer units (exactly representable)."""


def _half_mean_detrended(seg: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Rows of ``seg`` (3m points each) less their line through the means of the first and
    last ⌊3m/2⌋ points (SP 1065 §5.2.8: the half-average slope; for odd 3m the middle point
    is in neither half), the slope per point being the difference of the half means over
    the distance between the halves' centres."""
    p = seg.shape[1]
    h = p // 2
    first, last = seg[:, :h].mean(axis=1), seg[:, p - h :].mean(axis=1)
    slope = (last - first) / (p - h)  # centres (h − 1)/2 and (2p − h − 1)/2 apart: p − h
    return np.asarray(seg - slope[:, None] * np.arange(p)[None, :])


def _tot_reference(z: npt.NDArray[np.float64], m: int) -> float:
    """Σ_n (1/6m) Σ_{i<6m} (Σ_{k=i}^{i+m−1} x#_{k+2m} − 2x#_{k+m} + x#_k)² / m² over the
    N − 3m + 1 subsequences of 3m points of ``z``, each detrended (half means) and extended
    by uninverted even reflection to 9m points x# (SP 1065 eqs. 27 and 29)."""
    seg = _half_mean_detrended(np.lib.stride_tricks.sliding_window_view(z, 3 * m))
    ext = np.concatenate([seg[:, ::-1], seg, seg[:, ::-1]], axis=1)  # 9m points
    d2 = ext[:, 2 * m :] - 2.0 * ext[:, m : 8 * m] + ext[:, : 7 * m]  # 7m second differences
    c = np.zeros((d2.shape[0], d2.shape[1] + 1))
    np.cumsum(d2, axis=1, out=c[:, 1:])  # of detrended differences: small, no cancellation
    inner = (c[:, m : 7 * m] - c[:, : 6 * m]) / m  # i = 0 … 6m − 1
    return float(np.sum(inner * inner)) / (6.0 * m)


def _total_reference(name: str, ints: I64, m: int) -> float:
    """mtotdev, ttotdev, htotdev or theo1 of y = ints / SCALE [°/h] every TAU0 at factor m,
    by SP 1065's definitions on the offset-free record (see OFFSET)."""
    j = ints - OFFSET
    x = np.zeros(j.size + 1, dtype=np.int64)
    np.cumsum(j, out=x[1:])
    xf = x.astype(np.float64)  # phase in units of TAU0 / SCALE, exact
    unit, tau = TAU0 / SCALE, m * TAU0
    n = xf.size
    if name in ("mtotdev", "ttotdev"):  # eq. 27 (ttotdev: eq. 28, τ²/3 of it)
        var = _tot_reference(xf, m) * unit**2 / (2.0 * tau * tau * (n - 3 * m + 1))
        return math.sqrt(var * tau * tau / 3.0) if name == "ttotdev" else math.sqrt(var)
    if name == "htotdev":  # eq. 29 on the rate; m = 1 is ohdev (Stable32's convention)
        yf = j.astype(np.float64)  # rate in units of 1 / SCALE
        if m == 1:
            t = xf[3:] - 3.0 * xf[2:-1] + 3.0 * xf[1:-2] - xf[:-3]
            return math.sqrt(float(t @ t) / (6.0 * t.size)) * unit / tau
        var = _tot_reference(yf, m) / (6.0 * (yf.size - 3 * m + 1))
        return math.sqrt(var) / SCALE
    if name == "theo1":  # eq. 30, m even, τ = 0.75 m τ0
        h, k = m // 2, n - m
        total = 0.0
        for dl in range(h):
            i = np.arange(k)
            v = (xf[i] - xf[i - dl + h]) + (xf[i + m] - xf[i + dl + h])
            total += float(v @ v) / (h - dl)
        return math.sqrt(total / (0.75 * k)) * unit / tau
    raise ValueError(name)


@pytest.mark.parametrize(
    ("names", "n"), [(("mtotdev", "ttotdev"), 3000), (("htotdev",), 3000), (("theo1",), 10_000)]
)
def test_total_family_and_theo1_keep_their_digits(names: tuple[str, ...], n: int) -> None:
    """MTOT, TTOT, HTOT and Theo1 of a record of 1e6 °/h + random walk + white noise within
    1e-9 of SP 1065's definition evaluated on the offset-free record, at every octave τ."""
    ints = _record(n, 6)
    res = stability(ints.astype(np.float64) / SCALE, TAU0, list(names), "octave")
    for name in names:
        curve = res.curves[name]
        ok = curve.n_terms > 0
        assert np.count_nonzero(ok) >= 5, name
        for m, dev in zip(curve.m[ok].tolist(), curve.dev[ok].tolist(), strict=True):
            ref = _total_reference(name, ints, int(m))
            rel = abs(dev - ref) / ref
            assert rel <= REL, f"{name} m={m}: {dev!r} vs {ref!r} (rel {rel:.2e})"
