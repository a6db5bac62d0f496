"""Tests of the maths modules written to kill mutants of the mutation check (issue 27
item 6: ``benchmarks/mutation_check.py``, the mutants named ``adequacy-*``,
``stability-*``, ``multipos-*``, ``metrics-*`` …).  Expected values are written out here
from the stated definitions, with their numbers."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal import adequacy


def test_ten_samples_per_coefficient_is_enough() -> None:
    """n / p ≥ 10 passes, the boundary included (mutant adequacy-samples-strict)."""
    assert adequacy.samples_test(40, 4).verdict == "pass"
    assert adequacy.samples_test(39, 4).verdict == "fail"
    assert adequacy.samples_test(4, 4).verdict == "fail"


def test_a_sweep_exactly_at_the_firmware_minimum_passes() -> None:
    """ArduPilot needs 10 °C: exactly 10 passes, 9.99 fails (mutant adequacy-firmware-strict)."""
    assert adequacy.firmware_test(10.0, "ardupilot", 10.0).verdict == "pass"
    assert adequacy.firmware_test(9.99, "ardupilot", 10.0).verdict == "fail"


def test_the_temperature_rate_is_in_degrees_per_minute() -> None:
    """A ramp of 1.5 °C/min sampled each second: Ṫ over Δ = 60 s is 1.5 [°C/min] from
    t = 60 s on (mutant adequacy-rate-per-second gives 0.025)."""
    t = np.arange(0.0, 600.0, 1.0)
    rate = adequacy.temperature_rate_c_per_min(t, 20.0 + 1.5 * t / 60.0)
    assert rate.size == t.size - 60
    np.testing.assert_allclose(rate, 1.5, rtol=1e-12)


def test_small_records_span_their_whole_range() -> None:
    """Under 1000 samples the span is max − min (no percentile cut): 999 samples from 20
    to 30 °C and one at 40 °C span 20 °C (mutant adequacy-robust-range-small cuts the
    0.1/99.9 percentiles)."""
    t = np.r_[np.linspace(20.0, 30.0, 998), 40.0]
    span = next(x for x in adequacy.temperature_tests(t, "T", 1) if x.name == "temperature_span")
    assert span.figure == pytest.approx(20.0, abs=1e-12)


def test_the_range_ends_figure_is_the_emptier_end() -> None:
    """989 samples at 20 °C and a ramp of 10 samples to 40 °C: the lowest tenth (≤ 22 °C)
    holds 990 of 999 samples, the highest tenth (≥ 38 °C) one: 0.1 %, a warning (mutant
    adequacy-ends-share judges the fuller end)."""
    t = np.r_[np.full(989, 20.0), np.linspace(20.0, 40.0, 10)]
    ends = next(x for x in adequacy.temperature_tests(t, "T", 1) if x.name == "range_ends")
    assert ends.figure == pytest.approx(100.0 / 999.0, rel=1e-12)
    assert ends.verdict == "warn"


def test_a_gyro_moving_a_tenth_of_the_time_is_refused() -> None:
    """2000 s at 10 Hz, still (10 °/h noise) but for twenty 10 s turns at 3000 °/h (above
    the 0.3 °/s = 1080 °/h floor, below the 20 °/s of a rotating gyro): moving ≈ 10 % of
    the record, more than the 2 % allowed: a failure (mutant adequacy-moving-share-strict
    allows 20 %)."""
    rng = np.random.default_rng(6)
    t = np.arange(0.0, 2000.0, 0.1)
    v = rng.normal(0.0, 10.0, t.size)
    for k in range(20):
        v[(t >= 50.0 + 100.0 * k) & (t < 60.0 + 100.0 * k)] += 3000.0
    res = adequacy.stillness_test(t, v, "gyro", "g")
    assert res.verdict == "fail"
    assert 5.0 < res.figure < 20.0  # [%]


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


def test_absolute_figures_and_the_worse_rule_by_hand() -> None:
    """Errors 3 and 4 about zero: mean 3.5, rms √12.5, max 4 (mutant
    compensate-abs-rms-about-mean gives the σ 0.5); an rms about zero 1.0 → 1.2 is worse
    beyond the tolerance, 1.0 → 1.0 + tolerance/2 is not (mutant compensate-worse-strict
    needs 10× the tolerance)."""
    from thermocal.compensate.kernels import (
        ABSOLUTE_WORSE_TOLERANCE,
        AbsoluteFigures,
        absolute_error_worse,
        absolute_figures,
    )

    f = absolute_figures([3.0, 4.0])
    assert (f.mean, f.max_abs) == (3.5, 4.0)
    assert f.rms_about_zero == pytest.approx(np.sqrt(12.5), rel=1e-15)
    tol = ABSOLUTE_WORSE_TOLERANCE
    assert 0.0 < tol < 0.1
    before = AbsoluteFigures(0.0, 1.0, 2.0)
    assert absolute_error_worse(before, AbsoluteFigures(0.0, 1.0 + 2.0 * tol, 2.0)) == [
        "rms about zero"
    ]
    assert absolute_error_worse(before, AbsoluteFigures(0.0, 1.0 + 0.5 * tol, 2.0)) == []


def test_centred_rate_of_a_parabola_is_its_derivative() -> None:
    """T = 20 + 0.001 t² sampled each second: the centred Ṫ over Δ = 60 s, (T(t+30) −
    T(t−30))/60 × 60, is exactly 0.002 t × 60 [°C/min] away from the ends (mutant
    preprocess-centred-half reaches back 60 s: 0.002 t × 60 − 1.8)."""
    from thermocal.preprocess import temperature_rate

    t = np.arange(0.0, 600.0, 1.0)
    rate = temperature_rate(t, 20.0 + 0.001 * t**2, 60.0, "centred")
    inner = (t >= 30.0) & (t <= 569.0)
    np.testing.assert_allclose(rate[inner], 0.002 * t[inner] * 60.0, rtol=0, atol=1e-9)


def test_runs_in_different_directions_are_different_placements() -> None:
    """Means along +z, +z (0.5° off) and +x [mg]: the first two are one placement within
    the tolerance, the third another (mutant gravity-placement-tolerance joins all)."""
    from thermocal.gravity import group_placements

    s = np.sin(np.radians(0.5))
    dirs, place = group_placements(
        [(0.0, 0.0, 1000.0), (1000.0 * s, 0.0, 1000.0), (1000.0, 0.0, 0.0)]
    )
    assert place == (0, 0, 1)
    assert dirs[2] == pytest.approx((1.0, 0.0, 0.0))


def test_c_identifiers_and_strings_by_hand() -> None:
    """A 100-character name becomes an identifier of at most 63 characters (C99's
    significant initial characters; mutant identifiers-length-hash lets 64…71 through), and DEL
    (0x7F) is written as the octal escape \\177 (mutant identifiers-printable-range writes
    it raw)."""
    from thermocal.identifiers import c_identifier, c_string

    for n in (64, 68, 100):
        ident = c_identifier("x" * n)
        assert len(ident) <= 63 and ident.startswith("x"), n
    assert c_identifier("y" * 63) == "y" * 63
    assert c_string("a\x7fb~") == '"a\\177b~"'


def test_counts_to_a_model_in_degrees_per_second() -> None:
    """Pulse counts with K = 2 pulses/″ at τ = 0.5 s: one count is 1/(0.5·2) = 1 ″/s =
    1 °/h = 1/3600 °/s; the factor to a model in °/s is 1/3600 (mutant
    compensate-counts-tau-default gives 3600)."""
    from thermocal.compensate.kernels import unit_factor
    from thermocal.recording import Metadata

    meta = Metadata(scale_factor=2.0, scale_factor_unit="counts/arcsec")
    f = unit_factor("counts", "deg/s", meta=meta, sample_interval_s=0.5)
    assert f == pytest.approx(1.0 / 3600.0, rel=1e-12)


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
