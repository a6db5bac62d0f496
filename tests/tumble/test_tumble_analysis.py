"""The tumble test's maths (:mod:`thermocal.tumble`): the harmonic fit equals a least-squares
fit written here, the simulator's K2 and K_ip are recovered within 3σ over many seeds, and
angles that cannot separate the second harmonic are refused."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.errors import DesignError
from thermocal.tumble import coefficients_from_harmonics, find_stations, fit_harmonics
from thermocal.tumble.simulate import TRUTH, simulate_tumble


def _by_hand(theta_deg: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Weighted least squares of 1, cos θ, sin θ, cos 2θ, sin 2θ by the normal equations."""
    th = np.deg2rad(theta_deg)
    x = np.stack([th**0, np.cos(th), np.sin(th), np.cos(2 * th), np.sin(2 * th)], axis=1)
    xw = x * w[:, None] ** 2
    return np.linalg.solve(x.T @ xw, xw.T @ y)


def _stations(seed: int, **kw: float) -> tuple[list, dict]:
    rec, truth = simulate_tumble(np.random.default_rng(seed), **kw)
    st, _ = find_stations(rec.time_s, rec.columns["angle"], rec.columns["accel"])
    return st, truth


def test_harmonic_fit_is_the_least_squares_written_here() -> None:
    st, _ = _stations(1)
    th = np.array([s.angle_deg for s in st])
    y = np.array([s.mean for s in st])
    se = np.array([s.se for s in st])
    fit = fit_harmonics(th, y, se)
    np.testing.assert_allclose(fit.coefficients, _by_hand(th, y, 1 / se), rtol=0, atol=1e-9)
    rec, _ = simulate_tumble(np.random.default_rng(2), turn_rate_dps=3.0, rate_hz=10.0)
    th, y = rec.columns["angle"], rec.columns["accel"]
    cont = fit_harmonics(th, y)
    np.testing.assert_allclose(cont.coefficients, _by_hand(th, y, np.ones_like(y)), atol=1e-9)
    assert cont.reduced_chi2 is None and cont.dof == y.size - 5


def test_k2_and_kip_recovered_within_3_sigma_over_seeds() -> None:
    z = []
    for seed in range(24):
        st, truth = _stations(100 + seed)
        fit = fit_harmonics([s.angle_deg for s in st], [s.mean for s in st], [s.se for s in st])
        k = coefficients_from_harmonics(fit)
        assert len(st) == 24
        z.append([(k[n][0] - truth[n]) / k[n][1] for n in ("k0", "k1", "delta_o", "k2", "k_ip")])
    z_ = np.abs(np.array(z))
    assert (z_ < 3).mean() >= 0.97, z_.max(axis=0)
    # the σ is honest: the normalised errors scatter about 1, not 0.1 or 10
    assert 0.6 < float(np.sqrt(np.mean(np.array(z) ** 2))) < 1.4
    # and K2 is far from zero: the test sees it (50 µg/g² against a σ of a few µg/g²)
    assert k["k2"][1] < TRUTH["k2"] / 10


def test_continuous_tumble_and_third_harmonic() -> None:
    rec, truth = simulate_tumble(np.random.default_rng(5), turn_rate_dps=2.0, rate_hz=20.0,
                                 k3=0.05)  # fmt: skip
    fit = fit_harmonics(rec.columns["angle"], rec.columns["accel"], harmonics=3)
    k = coefficients_from_harmonics(fit)
    for n in ("k0", "k1", "delta_o", "k2", "k_ip", "k3"):
        assert abs(k[n][0] - truth[n]) < 4 * k[n][1], n
    # two harmonics alias K3 into K1: a1 = K1 + 3 K3 / 4
    k2h = coefficients_from_harmonics(fit_harmonics(rec.columns["angle"], rec.columns["accel"]))
    assert abs(k2h["k1"][0] - (truth["k1"] + 0.75 * truth["k3"])) < 4 * k2h["k1"][1]
    norm = k.normalised()
    assert norm["k2_g_per_g2"][0] == pytest.approx(k["k2"][0] / k["k1"][0])


@pytest.mark.parametrize(
    ("angles", "match"),
    [
        ([0.0], "1 distinct angle"),
        ([0.0, 90.0, 180.0, 270.0, 360.0, 0.2], "4 distinct angle"),
        (np.arange(0.0, 50.0, 5.0).tolist(), "gap of 315°"),
    ],
)
def test_angles_that_cannot_separate_the_second_harmonic_are_refused(
    angles: list[float], match: str
) -> None:
    th = np.repeat(angles, 3)
    with pytest.raises(DesignError, match=match):
        fit_harmonics(th, np.cos(np.deg2rad(th)))


def test_stations_found_with_settling_left_out() -> None:
    rec, truth = simulate_tumble(np.random.default_rng(0), stations=12, dwell_s=10.0)
    st, dropped = find_stations(rec.time_s, rec.columns["angle"], rec.columns["accel"],
                                settle_s=2.0)  # fmt: skip
    assert [round(s.angle_deg, 6) for s in st] == truth["angles_deg"]
    assert all(s.n in (8 * 50, 8 * 50 + 1) for s in st) and dropped == []


def test_station_means_scattering_beyond_their_noise_widen_the_sigma() -> None:
    """Station means given a σ far below their scatter (the head's angle errors): the Birge
    correction gives the σ the residuals say, as an unweighted fit's."""
    st, _ = _stations(9)
    th = [s.angle_deg for s in st]
    y = np.array([s.mean for s in st]) + 0.01 * np.sin(np.arange(len(st)) * 2.3)
    tiny = fit_harmonics(th, y, np.full(len(st), 1e-6))
    plain = fit_harmonics(th, y)
    assert tiny.reduced_chi2 is not None and tiny.reduced_chi2 > 1e6
    np.testing.assert_allclose(tiny.sigma, plain.sigma, rtol=1e-9)


def test_continuous_tumble_sigma_is_honest_over_seeds() -> None:
    z = []
    for seed in range(40):
        rec, truth = simulate_tumble(np.random.default_rng(500 + seed), turn_rate_dps=4.0,
                                     rate_hz=5.0)  # fmt: skip
        k = coefficients_from_harmonics(fit_harmonics(rec.columns["angle"], rec.columns["accel"]))
        z += [(k[n][0] - truth[n]) / k[n][1] for n in ("k0", "k1", "delta_o", "k2", "k_ip")]
    assert 0.8 < float(np.sqrt(np.mean(np.square(z)))) < 1.2
