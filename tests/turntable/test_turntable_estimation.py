"""Turntable calibration: recovery of simulator truth, CRB, filter vs least squares,
bad input (SPEC §7).

The 20-run Monte Carlo uses 10 Hz samples (instead of 100 Hz) to keep the runtime
modest; with white angle random walk the information, and so the bound, does not
depend on the sample rate."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose

from thermocal.errors import GapWarning, MissingColumnError
from thermocal.recording import Recording
from thermocal.turntable import (
    TurntableScheduleError,
    TurntableTruth,
    TurntableWarning,
    calibrate,
    simulate_turntable16,
)
from thermocal.turntable.simulate import ALPHA_COLUMN, BETA_COLUMN

N_RUNS = 20


def truth_theta(truth: dict[str, list[float]]) -> np.ndarray:
    return np.array(truth["bias_deg_h"] + truth["scale_factor_ppm"] + truth["misalignment_arcsec"])


@pytest.fixture(scope="module")
def monte_carlo() -> dict[str, np.ndarray]:
    errs_kf, errs_ls, sig_kf, sig_ls, crb, agree = [], [], [], [], [], []
    for seed in range(N_RUNS):
        rec, truth = simulate_turntable16(seed, rate_hz=10.0)
        res = calibrate(rec, 40.0)
        th = truth_theta(truth)
        errs_kf.append(res.kalman.theta - th)
        errs_ls.append(res.least_squares.theta - th)
        sig_kf.append(res.kalman.sigma)
        sig_ls.append(res.least_squares.sigma)
        crb.append(res.crb)
        agree.append(res.agreement)
    return {
        "err_kf": np.array(errs_kf),
        "err_ls": np.array(errs_ls),
        "sig_kf": np.array(sig_kf),
        "sig_ls": np.array(sig_ls),
        "crb": np.array(crb),
        "agree": np.array(agree),
    }


def test_rms_error_within_crb(monte_carlo: dict[str, np.ndarray]) -> None:
    crb = monte_carlo["crb"].mean(axis=0)
    for key in ("err_kf", "err_ls"):
        rms = np.sqrt(np.mean(monte_carlo[key] ** 2, axis=0))
        assert np.all(rms <= 1.5 * crb), (key, rms / crb)
    # the bound itself is what a navigation-grade triad should give (issue 8)
    assert np.all((crb[0:3] > 0.003) & (crb[0:3] < 0.01))  # °/h
    assert np.all((crb[3:6] > 0.2) & (crb[3:6] < 2.0))  # ppm
    assert np.all((crb[6:12] > 0.05) & (crb[6:12] < 0.4))  # arcsec


def test_normalised_errors_bounded(monte_carlo: dict[str, np.ndarray]) -> None:
    for e, s in (("err_kf", "sig_kf"), ("err_ls", "sig_ls")):
        z = monte_carlo[e] / monte_carlo[s]
        assert np.max(np.abs(z)) < 3.0
        assert 0.6 < np.sqrt(np.mean(z**2)) < 1.4


def test_filter_and_least_squares_agree(monte_carlo: dict[str, np.ndarray]) -> None:
    assert np.max(monte_carlo["agree"]) < 0.05
    assert_allclose(monte_carlo["sig_kf"], monte_carlo["sig_ls"], rtol=0.02)
    assert_allclose(monte_carlo["sig_ls"], monte_carlo["crb"], rtol=0.02)


def test_result_dict_keys_and_error_matrix() -> None:
    rec, truth = simulate_turntable16(7, rate_hz=5.0)
    d = calibrate(rec).to_dict()  # latitude from the recording's metadata
    for key in ("bias_deg_h", "scale_factor_ppm", "misalignment_arcsec"):
        assert len(d[key]) == len(d[key + "_sigma"])
    e = np.array(d["error_matrix"])
    assert e.shape == (3, 3)
    assert_allclose(e, np.array(truth["error_matrix"]), atol=3e-6)  # ≈ 0.6″, 3 ppm
    assert_allclose(d["inner_axis_azimuth_arcsec"], truth["inner_axis_azimuth_arcsec"], atol=1.0)
    assert d["misalignment_names"] == ["yx", "zx", "xy", "zy", "xz", "yz"]
    assert d["misalignment_error_matrix_index"][0] == [0, 1]
    assert len(d["unobservable"]) >= 2
    assert d["arw_deg_sqrt_h"] == pytest.approx([0.003] * 3, rel=0.05)


def test_spec_two_channel_filter_leaves_xy_weak() -> None:
    """The SPEC's 14-state filter (Δα, Δβ only) sees yx, xy through the earth rate only."""
    rec, truth = simulate_turntable16(2, rate_hz=5.0)
    with pytest.warns(TurntableWarning, match="weakly observable"):
        res = calibrate(rec, 40.0, channels=2)
    assert res.n_states == 14
    sig = res.kalman.sigma
    assert sig[6] > 30.0 and sig[8] > 30.0  # yx, xy: tens to hundreds of arcsec
    assert np.all(sig[[7, 9, 10, 11]] < 0.5)
    z = (res.kalman.theta - truth_theta(truth)) / sig
    assert np.max(np.abs(z)) < 3.5


def test_encoder_noise_and_random_truth() -> None:
    truth = TurntableTruth.random(11)
    rec, td = simulate_turntable16(4, rate_hz=10.0, truth=truth, encoder_noise_arcsec=0.5)
    res = calibrate(rec, 40.0, encoder_noise_arcsec=0.5)
    th = truth_theta(td)
    for est in (res.kalman, res.least_squares):
        assert np.max(np.abs((est.theta - th) / est.sigma)) < 3.5
    assert res.agreement < 0.1
    assert np.all(res.kalman.sigma >= res.crb * 0.999)


def test_gap_is_reported_and_bridged() -> None:
    rec, truth = simulate_turntable16(5, rate_hz=10.0)
    keep = np.ones(rec.n_samples, dtype=bool)
    keep[3000:3050] = False  # 5 s gap inside the fourth dwell
    with pytest.warns(GapWarning, match="gaps in time"):
        res = calibrate(rec.select(keep), 40.0)
    z = (res.kalman.theta - truth_theta(truth)) / res.kalman.sigma
    assert np.max(np.abs(z)) < 3.5


def _drop(rec: Recording, name: str) -> Recording:
    cols = {k: v for k, v in rec.columns.items() if k != name}
    return Recording(rec.time_s, cols, rec.units, rec.signals, rec.temperatures, rec.meta)


def test_missing_encoder_column() -> None:
    rec, _ = simulate_turntable16(0, rate_hz=2.0)
    with pytest.raises(MissingColumnError, match=BETA_COLUMN):
        calibrate(_drop(rec, BETA_COLUMN), 40.0)
    with pytest.raises(MissingColumnError, match="enc_a"):
        calibrate(rec, 40.0, alpha_column="enc_a")


def test_too_few_positions() -> None:
    rec, _ = simulate_turntable16(
        0, rate_hz=2.0, positions_deg=((0, 0), (90, 0), (90, 90), (180, 90), (180, 270))
    )
    with pytest.raises(TurntableScheduleError, match="only 5 distinct positions"):
        calibrate(rec, 40.0)


def test_short_dwell() -> None:
    rec, _ = simulate_turntable16(0, rate_hz=2.0, dwell_s=30.0)
    with pytest.raises(TurntableScheduleError, match="shorter than the 60 s asked"):
        calibrate(rec, 40.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        calibrate(rec, 40.0, min_dwell_s=30.0)  # accepted when asked for less


def test_axis_that_never_moves() -> None:
    pos = tuple((float(a), 0.0) for a in range(0, 360, 20))
    rec, _ = simulate_turntable16(0, rate_hz=2.0, positions_deg=pos)
    with pytest.raises(TurntableScheduleError, match=r"outer axis \('beta_deg'\) never moves"):
        calibrate(rec, 40.0)
    assert ALPHA_COLUMN in rec.columns


def test_latitude_required() -> None:
    rec, _ = simulate_turntable16(0, rate_hz=2.0)
    rec.meta.latitude_deg = None
    with pytest.raises(Exception, match="latitude"):
        calibrate(rec)
