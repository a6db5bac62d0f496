"""Overlapping Allan deviation and noise terms (thermocal.stability.allan).

References: NIST SP 1065 (Riley, Handbook of Frequency Stability Analysis,
2008) §12 1000-point "ran" data set and the NBS14 10-point set with their
published overlapping Allan deviations (Stable32); allantools 2024.06 as an
independent implementation; noise generated here with known coefficients.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import allantools
import numpy as np
import pytest
from allantools import ci as at_ci
from numpy.testing import assert_allclose

from thermocal.errors import MissingValueError, ThermocalInputError
from thermocal.stability import allan

# --- reference data -----------------------------------------------------------------------


def nbs14_1000() -> np.ndarray:
    """SP 1065 §12: n_{k+1} = 16807 n_k mod 2147483647, n_0 = 1234567890, value n/2147483647."""
    n = [1234567890]
    for _ in range(999):
        n.append((16807 * n[-1]) % 2147483647)
    assert n[1:4] == [395529916, 1209410747, 633705974]  # first values printed in SP 1065
    return np.array(n, dtype=np.float64) / 2147483647.0


NBS14_10 = np.array([892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0])


def loop_oadev(y: np.ndarray, m: int) -> float:
    """Straightforward O(n·m) overlapping ADEV from cluster averages (IEEE 952 C.1)."""
    n = y.size
    means = np.array([y[i : i + m].mean() for i in range(n - m + 1)])
    d = means[m:] - means[:-m]
    return math.sqrt(0.5 * np.mean(d**2))


# --- published values -----------------------------------------------------------------------


def test_nist_sp1065_1000_point_overlapping_adev() -> None:
    # SP 1065 Table (p. 108): overlapping ADEV at τ = 1, 10, 100.
    ref = np.array([2.922319e-01, 9.159953e-02, 3.241343e-02])
    res = allan.overlapping_adev(nbs14_1000(), 1.0, [1.0, 10.0, 100.0], unit="")
    assert_allclose(res.adev, ref, rtol=1e-4)
    assert res.n_terms.tolist() == [999, 981, 801]


def test_nbs14_10_point_overlapping_adev() -> None:
    # SP 1065 §12 / Riley: NBS14 10-point frequency data, OADEV τ = 1, 2.
    res = allan.overlapping_adev(NBS14_10, 1.0, [1.0, 2.0], unit="")
    assert_allclose(res.adev, [91.22945, 85.95287], rtol=1e-4)


def test_against_loop_implementation() -> None:
    y = nbs14_1000()
    res = allan.overlapping_adev(y, 1.0, "octave", unit="")
    ref = [loop_oadev(y, int(m)) for m in res.m]
    assert_allclose(res.adev, ref, rtol=1e-10)


@pytest.mark.parametrize("taus", ["octave", "decade", [0.2, 0.7, 3.1, 50.0]])
def test_against_allantools(taus: str | list[float]) -> None:
    rng = np.random.default_rng(7)
    tau0 = 0.1
    y = 12.0 + rng.standard_normal(20_001) + np.cumsum(rng.standard_normal(20_001)) * 1e-2
    res = allan.overlapping_adev(y, tau0, taus)
    t_ref, d_ref, _e, n_ref = allantools.oadev(y, rate=1 / tau0, data_type="freq", taus=taus)
    assert_allclose(res.tau_s, t_ref, rtol=1e-12)
    assert_allclose(res.adev, d_ref, rtol=1e-9)
    assert res.n_terms.tolist() == n_ref.astype(int).tolist()


def test_tau_sets() -> None:
    m = allan.averaging_factors("decade", 1.0, 1000)
    assert m.tolist() == [1, 2, 4, 10, 20, 40, 100, 200, 400]
    m = allan.averaging_factors("octave", 1.0, 1000)
    assert m.tolist() == [1, 2, 4, 8, 16, 32, 64, 128, 256]
    m = allan.averaging_factors("log", 1.0, 1000)
    assert m[:5].tolist() == [1, 2, 3, 4, 5] and m[-1] == 398  # 10^(26/10) → 398
    assert np.all(np.diff(m) > 0)


# --- confidence intervals ---------------------------------------------------------------------


@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
def test_edf_matches_sp1065_table5(alpha: int) -> None:
    for n_phase, m in [(1001, 1), (1001, 2), (1001, 37), (1001, 250), (101, 10)]:
        ref = at_ci.edf_simple(n_phase, m, alpha)
        assert_allclose(allan.edf_simple(n_phase, m, alpha), ref, rtol=1e-12)


def test_confidence_interval_chi_square() -> None:
    """The default path's EDF is Greenhall & Riley's (allantools' edf_greenhall as the
    independent reference), the interval SP 1065 eq. 45 (issue 29 item 1: the same
    intervals as ``--deviation oadev`` and Stable32)."""
    y = nbs14_1000()
    res = allan.overlapping_adev(y, 1.0, [1.0, 10.0, 100.0], alpha=0, confidence=0.95, unit="")
    for i, m in enumerate(res.m):
        edf = at_ci.edf_greenhall(alpha=0, d=2, m=int(m), N=1001, overlapping=True, modified=False)
        lo, hi = at_ci.confidence_interval(res.adev[i], edf, ci=0.95)
        assert res.edf[i] == pytest.approx(edf, rel=1e-12)
        assert res.adev_low[i] == pytest.approx(lo, rel=1e-10)
        assert res.adev_high[i] == pytest.approx(hi, rel=1e-10)
    # white FM at τ = 1 s, n = 1000: Greenhall's edf = 782.0 (SP 1065 Table 5's simple
    # formula: 665.8), so the 95 % interval is about ±1.96/√(2·782) = ±5.0 % of σ
    assert res.edf[0] == pytest.approx(782.03, abs=0.01)
    assert 0.945 < res.adev_low[0] / res.adev[0] < 0.955
    assert 1.045 < res.adev_high[0] / res.adev[0] < 1.055


def test_noise_type_identification() -> None:
    rng = np.random.default_rng(3)
    white = rng.standard_normal(2**15)
    assert np.all(allan.overlapping_adev(white, 1.0).alpha[:8] == 0)
    q = rng.standard_normal(2**15 + 1)
    assert np.all(allan.overlapping_adev(np.diff(q), 1.0).alpha[:6] == 2)


# --- gaps --------------------------------------------------------------------------------------


def test_gaps_pooled_per_segment() -> None:
    rng = np.random.default_rng(11)
    a = rng.standard_normal(3000)
    b = rng.standard_normal(2000) + 1000.0  # level jump across the gap
    y = np.concatenate([a, b])
    t = np.concatenate([np.arange(3000.0), 5000.0 + np.arange(2000.0)])
    res = allan.overlapping_adev(y, 1.0, "octave", time_s=t)
    assert res.n_segments == 2
    for i, m in enumerate(res.m.tolist()):
        ss, nn = 0.0, 0
        for seg in (a, b):
            if seg.size + 1 - 2 * m >= 2:
                v = loop_oadev(seg, m) ** 2
                n = seg.size + 1 - 2 * m
                ss += v * n
                nn += n
        assert res.n_terms[i] == nn
        assert res.adev[i] == pytest.approx(math.sqrt(ss / nn), rel=1e-10)
    # differencing across the gap would see the 1000 °/h jump
    assert allan.overlapping_adev(y, 1.0, "octave").adev[5] > 10 * res.adev[5]


# --- noise terms ---------------------------------------------------------------------------------

C0 = 2.0 * math.log(2.0) / math.pi


def flicker(rng: np.random.Generator, n: int, tau0: float, b: float) -> np.ndarray:
    """Flicker rate noise with one-sided PSD S(f) = h/f, h = B²/π, so that
    σ_flat = sqrt(2 ln2 · h) = 0.6643 B (IEEE 952 C.3 / SP 1065 Table 1)."""
    f = np.fft.rfftfreq(n, tau0)
    gain = np.zeros_like(f)
    gain[1:] = np.sqrt(b**2 / math.pi / tau0 / (2.0 * f[1:]))
    return np.fft.irfft(np.fft.rfft(rng.standard_normal(n)) * gain, n)


def test_recovers_arw_bias_instability_rrw() -> None:
    # Truth: N = 1 °/h·√s = 1/60 °/√h; B chosen so ARW and BI cross at τ = 100 s
    # (B = 0.1505 °/h); K so BI and RRW cross at 3·10⁴ s (K = 1e-3 °/h/√s = 0.06 °/h/√h).
    n, tau0 = 2**21, 1.0
    arw, b_true = 1.0, math.sqrt(1.0 / 100.0 / C0)
    k_native = math.sqrt(3.0 * C0 * b_true**2 / 3.0e4)
    rng = np.random.default_rng(0)
    y = (
        rng.standard_normal(n) * arw / math.sqrt(tau0)
        + flicker(rng, n, tau0, b_true)
        + np.cumsum(rng.standard_normal(n)) * k_native * math.sqrt(tau0)
    )
    res = allan.overlapping_adev(y, tau0, "octave", unit="deg/h", confidence=0.95)
    nt = allan.noise_terms(res)
    truth = {
        "angle_random_walk": arw / 60.0,
        "bias_instability": b_true,
        "rate_random_walk": k_native * 60.0,
    }
    for name, value in truth.items():
        term = nt.fit.terms()[name]
        assert term.value is not None, term.reason
        assert term.low is not None and term.high is not None
        assert term.low <= value <= term.high, (name, term)
    assert nt.fit.angle_random_walk.unit == "deg/sqrt(h)"
    assert nt.fit.bias_instability.unit == "deg/h"
    assert nt.fit.rate_random_walk.unit == "deg/h/sqrt(h)"
    # The slope-line reading is biased high where regions overlap (IEEE 952 C.3: the
    # flat minimum holds ARW and RRW too: +2√(100/3e4) ≈ +12 % in variance here).
    s = nt.slope
    assert s.angle_random_walk.value == pytest.approx(arw / 60.0, rel=0.04)
    assert s.bias_instability.value == pytest.approx(b_true, rel=0.10)
    assert s.bias_instability.value > b_true
    assert nt.fit.quantization.value is None and nt.fit.rate_ramp.value is None


def test_white_noise_has_no_bias_instability_or_rrw() -> None:
    rng = np.random.default_rng(5)
    y = rng.standard_normal(2**20) * 0.3  # N = 0.3 °/h·√s at τ0 = 1 s
    nt = allan.noise_terms(allan.overlapping_adev(y, 1.0, "octave", confidence=0.95))
    for method in (nt.fit, nt.slope):
        for name in ("bias_instability", "rate_random_walk", "rate_ramp", "quantization"):
            term = method.terms()[name]
            assert term.value is None
            assert term.reason
        arw = method.angle_random_walk
        assert arw.value is not None and arw.low is not None and arw.high is not None
        assert arw.low <= 0.3 / 60.0 <= arw.high
    assert "no region of slope +0" in (nt.slope.bias_instability.reason or "")


def test_quantization_and_rate_ramp() -> None:
    rng = np.random.default_rng(9)
    n, tau0, q = 2**18, 0.01, 2.0  # angle quantization noise σ_q = 2 arcsec
    y = np.diff(rng.standard_normal(n + 1) * q) / tau0  # σ(τ) = √3 q / τ
    nt = allan.noise_terms(allan.overlapping_adev(y, tau0, "octave", confidence=0.95))
    for method in (nt.fit, nt.slope):
        assert method.quantization.unit == "arcsec"
        assert method.quantization.value == pytest.approx(q, rel=0.02)
        assert method.angle_random_walk.value is None
    r = 0.5  # °/h per s
    t = np.arange(2**16) * 1.0
    y = r * t + rng.standard_normal(t.size) * 0.01
    nt = allan.noise_terms(allan.overlapping_adev(y, 1.0, "octave"))
    assert nt.fit.rate_ramp.unit == "deg/h/h"
    assert nt.fit.rate_ramp.value == pytest.approx(r * 3600.0, rel=0.02)
    assert nt.slope.rate_ramp.value == pytest.approx(r * 3600.0, rel=0.02)


def test_accelerometer_units() -> None:
    rng = np.random.default_rng(2)
    y = rng.standard_normal(2**16) * 0.05  # 0.05 mg·√s = 50 µg/√Hz at τ0 = 1 s
    nt = allan.noise_terms(allan.overlapping_adev(y, 1.0, unit="mg", confidence=0.95))
    vrw = nt.fit.angle_random_walk
    assert vrw.unit == "ug/sqrt(Hz)" and vrw.label == "velocity random walk"
    assert vrw.low is not None and vrw.high is not None and vrw.low <= 50.0 <= vrw.high
    assert nt.fit.bias_instability.unit == "ug"
    # the same data in g scale by 1000 before the µg conversion
    nt_g = allan.noise_terms(allan.overlapping_adev(y * 1e-3, 1.0, unit="g"))
    assert nt_g.fit.angle_random_walk.value == pytest.approx(vrw.value, rel=1e-9)


# --- bad input ----------------------------------------------------------------------------------


def test_bad_input() -> None:
    with pytest.raises(MissingValueError, match="row 3"):
        allan.overlapping_adev([1.0, 2.0, 3.0, np.nan, 5.0], 1.0)
    with pytest.raises(ThermocalInputError, match="at least 3"):
        allan.overlapping_adev([1.0, 2.0], 1.0)
    with pytest.raises(ThermocalInputError, match="unknown tau set"):
        allan.overlapping_adev(np.ones(100), 1.0, "weekly")
    with pytest.raises(ThermocalInputError, match="τ0"):
        allan.overlapping_adev(np.ones(100), 0.0)
    with pytest.raises(ThermocalInputError, match="no averaging time"):
        allan.overlapping_adev(np.ones(100), 1.0, [1000.0])


# --- edges ----------------------------------------------------------------------------------------


def test_allan_maths_does_not_import_matplotlib() -> None:
    code = "import sys, thermocal.stability.allan; sys.exit('matplotlib' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


def test_plot_writes_png(tmp_path: Path) -> None:
    from thermocal.report.allan_plots import plot_allan

    rng = np.random.default_rng(1)
    res = allan.overlapping_adev(rng.standard_normal(4096), 1.0)
    out = plot_allan(res, allan.noise_terms(res), tmp_path / "adev.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_slope_line_is_not_read_off_the_wrong_region() -> None:
    """A high-passed (compensated-like) white noise falls with slope ≈ −1 at long τ.

    Read naively, that region gives a 'quantization' whose line lies two orders of
    magnitude above the measured curve at τ = 1 s; the slope method must refuse it
    (null with a reason) while the ARW is still read correctly.
    """
    from thermocal import preprocess

    rng = np.random.default_rng(5)
    w = rng.normal(0.0, 1.0, 2**18)  # white rate noise, 1 °/h per 1-s sample → N = 1 °/h·√s
    y = w - preprocess.lowpass_first_order(w, 1.0, time_constant_s=3000.0)
    res = allan.overlapping_adev(y, 1.0)
    slopes = np.diff(np.log(res.adev)) / np.diff(np.log(res.tau_s))
    assert slopes[-3:].max() < -0.75  # the steep fall exists
    terms = allan.noise_terms(res)
    q = terms.slope.quantization
    assert q.value is None
    assert q.reason is not None and "not this noise term" in q.reason
    arw = terms.slope.angle_random_walk
    assert arw.value is not None
    assert arw.value == pytest.approx(1.0 / 60.0, rel=0.05)  # 1 °/h·√s = 1/60 °/√h


def test_nnls_small_is_scipys_nnls() -> None:
    """The noise-term fit's exact NNLS (support enumeration) against scipy.optimize.nnls
    (Lawson–Hanson active set) on random 23×5 problems, half with a sparse positive truth."""
    from scipy.optimize import nnls

    rng = np.random.default_rng(1)
    for i in range(300):
        a = rng.standard_normal((23, 5)) * rng.uniform(0.01, 100.0, 5)
        if i % 2:
            x = np.abs(rng.standard_normal(5)) * (rng.random(5) > 0.5)
            b = a @ x + 0.01 * rng.standard_normal(23)
        else:
            b = rng.standard_normal(23)
        ref, _ = nnls(a, b)
        assert_allclose(allan.nnls_small(a, b), ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())


def test_fit_p_value_is_the_chi_square_survival_function() -> None:
    from scipy.stats import chi2

    r = np.linspace(-2.0, 3.0, 9)
    q = allan.fit_quality(np.arange(1.0, 10.0), r, 3)
    assert q.p_value == pytest.approx(chi2.sf(float(r @ r), 6), rel=1e-12)


def test_nnls_small_with_fewer_points_than_terms() -> None:
    """Three points, five terms: the support has at most three independent columns (what
    scipy's active set keeps), never a minimum-norm solution over all five."""
    from scipy.optimize import nnls

    # the minimum-norm solution over all five columns is positive here
    a = np.array([[2.1, 1.2, 0.6, 0.5, 2.5], [2.8, 2.0, 2.3, 1.9, 2.8], [2.5, 0.5, 2.6, 0.6, 2.3]])
    b = np.array([6.4, 11.1, 7.7])
    assert np.all(np.linalg.lstsq(a, b, rcond=None)[0] > 0)
    x = allan.nnls_small(a, b)
    assert np.count_nonzero(x) <= 3
    assert np.linalg.norm(a @ x - b) == pytest.approx(
        np.linalg.norm(a @ nnls(a, b)[0] - b), abs=1e-12
    )


def test_segments_given_without_time_are_used() -> None:
    """Two records joined end to end with a step between them: with the segments given
    (and no time column) the ADEV is the pooled one of the two halves, NIST SP 1065's
    σ² = Σ_s S_s / (2 m² τ0² Σ_s L_s) written out here, not the one across the step."""
    from thermocal.stability.allan import overlapping_adev

    rng = np.random.default_rng(4)
    a, b = rng.normal(0.0, 1.0, 4000), rng.normal(50.0, 1.0, 3000)
    y = np.concatenate([a, b])
    segs = [slice(0, 4000), slice(4000, 7000)]
    got = overlapping_adev(y, 1.0, [1.0, 8.0, 64.0], segments=segs, unit="deg/h")
    for m, dev in zip((1, 8, 64), got.adev, strict=True):
        s, n = 0.0, 0
        for part in (a, b):
            x = np.concatenate([[0.0], np.cumsum(part)])
            d = x[2 * m :] - 2 * x[m:-m] + x[: -2 * m]
            s, n = s + float(np.sum(d**2)), n + d.size
        assert dev == pytest.approx(np.sqrt(s / (2 * m**2 * n)), rel=1e-9)
    with_time = overlapping_adev(
        y, 1.0, [1.0, 8.0, 64.0], time_s=np.arange(7000.0), segments=segs, unit="deg/h"
    )
    np.testing.assert_allclose(with_time.adev, got.adev, rtol=1e-12)
    for bad in ([slice(0, 4000), slice(3000, 7000)], [slice(0, 8000)], [slice(0, 10, 2)], []):
        with pytest.raises(ThermocalInputError, match="segments"):
            overlapping_adev(y, 1.0, [1.0], segments=bad, unit="deg/h")
