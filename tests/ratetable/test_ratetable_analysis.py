"""Scale-factor figures of a rate ladder (thermocal.ratetable.analysis) against the
simulator's truth and least-squares computations written here (numpy.polyfit)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from thermocal.errors import DesignError, ParameterError
from thermocal.ratetable import analyse_ladder, plateaus_from_rate, temperature_coefficient
from thermocal.ratetable.simulate import simulate_ladder

LADDER = (-300.0, -100.0, -30.0, -10.0, 0.0, 10.0, 30.0, 100.0, 300.0)
ERRORS = {"quadratic_ppm": 80.0, "cubic_ppm": 250.0, "asymmetry_ppm": 150.0, "bias_dps": 0.05}
N_SEEDS = 50


def _run(seed: int, **kw: object) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    opts = {"rates_dps": LADDER, "dwell_s": 8.0, "rate_hz": 50.0, "noise_dps": 0.01, **ERRORS}
    opts.update(kw)
    rec, truth = simulate_ladder(np.random.default_rng(seed), **opts)  # type: ignore[arg-type]
    d = plateaus_from_rate(rec.time_s, rec.columns["gyro"], rec.columns["table_rate"])
    w = np.array([p.rate_dps for p in d.plateaus])
    y = np.array([p.mean for p in d.plateaus])
    se = np.array([p.se for p in d.plateaus])
    return w, y, se, truth


def _band(n: int, p: float = 0.95) -> tuple[int, int]:
    """The 99.9 % binomial band of the number of intervals that cover the truth."""
    lo, hi = stats.binom.ppf([0.0005, 0.9995], n, p)
    return int(lo), int(hi)


def _asym_by_hand(w: np.ndarray, y: np.ndarray) -> float:
    k = np.polyfit(w, y, 1)[0]
    kp = np.polyfit(w[w >= 0], y[w >= 0], 1)[0]
    kn = np.polyfit(w[w <= 0], y[w <= 0], 1)[0]
    return float((kp - kn) / k * 1e6)


def test_nonlinearity_equals_polyfit_on_the_plateau_means() -> None:
    w, y, se, _ = _run(0)
    res = analyse_ladder(w, y, se)
    k, b = np.polyfit(w, y, 1)
    r = y - (k * w + b)
    fs = np.max(np.abs(w))
    assert res.scale_factor == pytest.approx(k, rel=1e-12)
    assert res.bias == pytest.approx(b, abs=1e-12)
    assert res.nonlinearity.value == pytest.approx(
        np.max(np.abs(r)) / (abs(k) * fs) * 1e6, abs=1e-9
    )
    for row in res.rows:
        want = r[w == row.rate_dps].mean() / (abs(k) * fs) * 1e6
        assert row.nonlinearity_ppm_fs == pytest.approx(want, abs=1e-9)
        assert row.bias_dps == pytest.approx((y[w == row.rate_dps].mean() - k * row.rate_dps) / k)
    assert res.asymmetry.value == pytest.approx(_asym_by_hand(w, y), abs=1e-6)


def test_recovered_within_the_stated_uncertainty_over_50_seeds() -> None:
    cover = {"k": 0, "asym": 0, "nl": 0}
    for seed in range(N_SEEDS):
        w, y, se, truth = _run(seed)
        res = analyse_ladder(w, y, se)
        wt = np.array([p["rate_dps"] for p in truth["plateaus"]])
        yt = np.array(truth["outputs"])
        kt, bt = np.polyfit(wt, yt, 1)
        cover["k"] += abs(res.scale_factor - kt) <= 1.96 * res.scale_factor_sigma
        cover["asym"] += (
            abs(res.asymmetry.value - _asym_by_hand(wt, yt)) <= 1.96 * res.asymmetry.sigma
        )
        row = next(r for r in res.rows if r.rate_dps == 300.0)
        nl_t = (yt[wt == 300.0].mean() - kt * 300.0 - bt) / (abs(kt) * 300.0) * 1e6
        cover["nl"] += abs(row.nonlinearity_ppm_fs - nl_t) <= 1.96 * row.nonlinearity_sigma_ppm_fs
    lo, hi = _band(N_SEEDS)
    for name, n in cover.items():
        assert lo <= n <= hi, (name, n, (lo, hi))


def test_pure_asymmetry_is_recovered_with_its_sign() -> None:
    for a in (400.0, -400.0):
        w, y, se, _ = _run(1, quadratic_ppm=0.0, cubic_ppm=0.0, asymmetry_ppm=a)
        res = analyse_ladder(w, y, se)
        assert np.sign(res.asymmetry.value) == np.sign(a)
        # a symmetric ladder: K± = K(1 ± a/2), so (K₊ − K₋)/K = a exactly
        assert abs(res.asymmetry.value - a) < 4 * res.asymmetry.sigma
        d = res.asymmetry.detail
        assert d is not None and np.sign(d["k_positive"] - d["k_negative"]) == np.sign(a)


def test_threshold_and_resolution_from_the_small_rates() -> None:
    small = (-0.1, -0.05, -0.03, -0.02, -0.01, 0.0, 0.01, 0.02, 0.03, 0.05, 0.1)
    w, y, se, _ = _run(
        2, rates_dps=(-300.0, *small, 300.0), dead_zone_dps=0.025, noise_dps=0.002, dwell_s=20.0
    )
    res = analyse_ladder(w, y, se)
    thr = res.threshold
    assert thr.value == pytest.approx(0.03) and thr.detail is not None
    assert thr.detail["above_dps"] == pytest.approx(0.02)  # the dead zone is between them
    assert res.resolution.value == pytest.approx(0.02)  # the 0.03 → 0.05 step responds


def test_threshold_refused_with_its_reason() -> None:
    w, y, se, _ = _run(3)
    res = analyse_ladder(w, y, se)
    assert res.threshold.value is None and "no small rates" in (res.threshold.reason or "")
    assert res.resolution.value is None
    w2, y2, se2 = w[w != 0], y[w != 0], se[w != 0]
    assert "zero-rate" in (analyse_ladder(w2, y2, se2).threshold.reason or "")


def test_asymmetry_refused_with_one_direction() -> None:
    w, y, se, _ = _run(4, rates_dps=(0.0, 10.0, 100.0, 300.0))
    res = analyse_ladder(w, y, se)
    assert res.asymmetry.value is None
    assert "only positive rates" in (res.asymmetry.reason or "")


def test_repeatability_of_a_ladder_run_up_and_down() -> None:
    w, y, se, _ = _run(5, up_down=True, repeats=2)
    res = analyse_ladder(w, y, se)
    rep = res.repeatability
    assert rep.detail is not None and rep.detail["passes"] == 4
    ks = []
    for i in range(4):
        idx = [np.flatnonzero(w == r)[i] for r in LADDER if np.sum(w == r) == 4]
        ks.append(np.polyfit(w[idx], y[idx], 1)[0])
    assert rep.value == pytest.approx(np.std(ks, ddof=1) / abs(res.scale_factor) * 1e6)
    assert "visited once" in (analyse_ladder(*_run(6)[:3]).repeatability.reason or "")


def test_temperature_coefficient_within_its_uncertainty() -> None:
    hits, n = 0, 20
    for seed in range(n):
        temps = (-20.0, 25.0, 70.0)
        ks, sig = [], []
        for t in temps:
            w, y, se, _ = _run(100 + seed, temperature_c=t, tc_ppm_per_c=35.0)
            res = analyse_ladder(w, y, se, temperature_c=t)
            ks.append(res.scale_factor)
            sig.append(res.scale_factor_sigma)
        tc = temperature_coefficient(temps, ks, sig)
        kt = 1.0 + 35e-6 * (tc.tref_c - 25.0)  # K(T) of the simulator at the reference
        hits += abs(tc.ppm_per_c - 35.0 / kt) <= 1.96 * tc.sigma_ppm_per_c
    lo, hi = _band(n)
    assert lo <= hits <= hi


def test_bad_input_refused() -> None:
    with pytest.raises(DesignError, match="two distinct rates"):
        analyse_ladder([10.0, 10.0], [1.0, 1.0], [0.1, 0.1])
    with pytest.raises(ParameterError, match="means"):
        analyse_ladder([1.0, 2.0], [1.0], [0.1])
    with pytest.raises(DesignError, match="temperature coefficient"):
        temperature_coefficient([25.0, 25.2], [1.0, 1.0], [1e-6, 1e-6])
