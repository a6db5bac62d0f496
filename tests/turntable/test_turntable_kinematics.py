"""Turntable kinematics and schedule (SPEC §7, INTERFACE.md "Turntable geometry")."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from thermocal import units
from thermocal.turntable import kinematics, model
from thermocal.turntable.schedule import POSITIONS_16, build_schedule
from thermocal.turntable.simulate import (
    ALPHA_COLUMN,
    BETA_COLUMN,
    GYRO_COLUMNS,
    TurntableTruth,
    simulate_turntable16,
)

LAT = 40.0
OMEGA = units.EARTH_RATE_RAD_S
OM_N = OMEGA * np.cos(np.deg2rad(LAT))
OM_U = OMEGA * np.sin(np.deg2rad(LAT))
PERFECT = TurntableTruth((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0,) * 6)


def reference_earth_rate_b(alpha_deg: float, beta_deg: float) -> np.ndarray:
    """Independent reference: body axes in ENU by scipy rotations, projected on ω_ie^n."""
    c0 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    r = (
        Rotation.from_euler("x", beta_deg, degrees=True).as_matrix()
        @ c0
        @ Rotation.from_euler("z", alpha_deg, degrees=True).as_matrix()
    )
    w_n = np.array([0.0, OM_N, OM_U])
    return np.array([r[:, i] @ w_n for i in range(3)])


# body axes at the named positions, read off the geometry by hand:
# (0,0): x=E, y=D, z=N;  (90,0): x=D, y=W, z=N;  (0,90): x=E, y=N, z=U;  (0,180): x=E, y=U, z=S
HAND = {
    (0.0, 0.0): (0.0, -OM_U, OM_N),
    (90.0, 0.0): (-OM_U, 0.0, OM_N),
    (0.0, 90.0): (0.0, OM_N, OM_U),
    (0.0, 180.0): (0.0, OM_U, -OM_N),
    (180.0, 270.0): (0.0, OM_N, -OM_U),
}


@pytest.mark.parametrize(("pos", "expected"), list(HAND.items()))
def test_earth_rate_by_hand(pos: tuple[float, float], expected: tuple[float, float, float]) -> None:
    a, b = np.deg2rad(pos)
    assert_allclose(kinematics.earth_rate_b(a, b, LAT), expected, atol=1e-18)
    assert_allclose(reference_earth_rate_b(*pos), expected, atol=1e-18)


def test_inner_axis_sees_north_and_up_mix() -> None:
    beta = np.deg2rad(np.linspace(0, 360, 37))
    w = kinematics.earth_rate_b(0.3, beta, LAT)
    assert_allclose(w[:, 2], OM_N * np.cos(beta) + OM_U * np.sin(beta), rtol=0, atol=1e-18)


def test_mat_nb_matches_independent_rotations() -> None:
    rng = np.random.default_rng(1)
    a, b = rng.uniform(-400, 400, (2, 50))
    c = kinematics.mat_nb(np.deg2rad(a), np.deg2rad(b))
    for k in range(a.size):
        assert_allclose(
            c[k] @ np.array([0.0, 0.0, 1.0]),
            [0, np.cos(np.deg2rad(b[k])), np.sin(np.deg2rad(b[k]))],
            atol=1e-15,
        )
        assert_allclose(
            reference_earth_rate_b(a[k], b[k]),
            kinematics.earth_rate_b(np.deg2rad(a[k]), np.deg2rad(b[k]), LAT),
            atol=1e-18,
        )
    assert_allclose(c @ np.swapaxes(c, -1, -2), np.broadcast_to(np.eye(3), c.shape), atol=1e-15)


def test_gimbal_rates_on_the_right_axes() -> None:
    """ω_nb^b from a finite difference of C_b^n equals α̇ e_z + β̇ e_E^b, and
    gimbal_rates() recovers (α̇, β̇) from ω_ib^b."""
    a0, b0, ad, bd, h = 0.7, -1.1, 0.17, -0.23, 1e-6
    c_m = kinematics.mat_nb(a0 - ad * h, b0 - bd * h)
    c_p = kinematics.mat_nb(a0 + ad * h, b0 + bd * h)
    c = kinematics.mat_nb(a0, b0)
    skew = c.T @ (c_p - c_m) / (2 * h)
    w_nb = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    assert_allclose(
        w_nb, ad * np.array([0, 0, 1.0]) + bd * np.array([np.cos(a0), -np.sin(a0), 0]), atol=1e-9
    )
    w = kinematics.omega_ib_b(a0, b0, ad, bd, LAT)
    assert_allclose(w - kinematics.earth_rate_b(a0, b0, LAT), w_nb, atol=1e-9)
    got = kinematics.gimbal_rates(w, a0, b0, LAT)
    assert_allclose(got, (ad, bd), atol=1e-15)


def test_perfect_triad_reads_earth_rate_at_all_16_positions() -> None:
    rec, _ = simulate_turntable16(0, rate_hz=5.0, dwell_s=60.0, arw_deg_sqrt_h=0.0, truth=PERFECT)
    sched = build_schedule(dwell_s=60.0)
    g = np.column_stack([rec.columns[c] for c in GYRO_COLUMNS]) * units.DEG_TO_RAD
    for (t0, t1), (pa, pb) in zip(sched.dwell_windows_s, POSITIONS_16, strict=True):
        sel = (rec.time_s > t0 + 0.5) & (rec.time_s <= t1)
        assert_allclose(g[sel].mean(axis=0), reference_earth_rate_b(pa, pb), atol=1e-17)
        assert_allclose(rec.columns[ALPHA_COLUMN][sel], pa % 360.0, atol=1e-9)
        assert_allclose(rec.columns[BETA_COLUMN][sel], pb % 360.0, atol=1e-9)


def test_perfect_triad_integrates_to_encoder_angles() -> None:
    """Through every move, the gyro-integrated gimbal angles equal the encoder's and the
    third channel stays at zero (model eq. (4) with θ = 0, no noise)."""
    rec, _ = simulate_turntable16(0, rate_hz=20.0, arw_deg_sqrt_h=0.0, truth=PERFECT)
    g = np.column_stack([rec.columns[c] for c in GYRO_COLUMNS]) * units.DEG_TO_RAD
    a = np.unwrap(rec.columns[ALPHA_COLUMN], period=360.0) * units.DEG_TO_RAD
    b = np.unwrap(rec.columns[BETA_COLUMN], period=360.0) * units.DEG_TO_RAD
    m = model.interval_model(rec.time_s, g, a, b, LAT)
    assert m.moving.sum() > 1000
    cum = np.cumsum(m.y_arcsec, axis=0)
    assert np.max(np.abs(cum)) < 1e-6  # arcsec over the whole run
    # and the gimbal-rate integral reproduces the encoder change of a 90° move
    alpha_dot, beta_dot = kinematics.gimbal_rates(
        g[1:], 0.5 * (a[1:] + a[:-1]), 0.5 * (b[1:] + b[:-1]), LAT
    )
    assert_allclose(np.sum(alpha_dot * m.dt_s), a[-1] - a[0], atol=1e-9)
    assert_allclose(np.sum(beta_dot * m.dt_s), b[-1] - b[0], atol=1e-9)


def test_error_model_regressor_matches_simulated_errors() -> None:
    """y = h θ exactly (to second order) for a noise-free triad with errors."""
    truth = TurntableTruth()
    rec, _ = simulate_turntable16(0, rate_hz=10.0, arw_deg_sqrt_h=0.0, truth=truth)
    g = np.column_stack([rec.columns[c] for c in GYRO_COLUMNS]) * units.DEG_TO_RAD
    a = np.unwrap(rec.columns[ALPHA_COLUMN], period=360.0) * units.DEG_TO_RAD
    b = np.unwrap(rec.columns[BETA_COLUMN], period=360.0) * units.DEG_TO_RAD
    m = model.interval_model(rec.time_s, g, a, b, LAT)
    pred = m.h @ truth.theta
    assert_allclose(np.cumsum(m.y_arcsec, axis=0), np.cumsum(pred, axis=0), atol=1e-6)
    # the 90° outer move at α = 0 shows yx on Δγ: 90° × yx = 90·π/180 · 30″
    assert np.max(np.abs(np.cumsum(pred[:, 2]))) > 40.0


def test_schedule_positions_and_single_axis_moves() -> None:
    s = build_schedule(dwell_s=60.0, move_rate_deg_s=10.0)
    assert s.positions_deg.shape == (16, 2)
    keys = {(round(a % 360), round(b % 360)) for a, b in s.positions_deg}
    assert len(keys) == 16
    assert_allclose(np.diff(s.dwell_windows_s, axis=1).ravel(), 60.0)
    da, db, dt = np.diff(s.alpha_deg), np.diff(s.beta_deg), np.diff(s.time_s)
    assert not np.any((da != 0) & (db != 0))  # single-axis moves
    moving = (da != 0) | (db != 0)
    assert_allclose(np.abs(da + db)[moving] / dt[moving], 10.0)
    a_end, b_end = s.angles_at(s.dwell_windows_s[:, 0])
    assert_allclose(np.c_[a_end, b_end] % 360, np.array(POSITIONS_16) % 360, atol=1e-9)


def test_model_round_trip_and_index_map() -> None:
    theta = TurntableTruth().theta
    e, b = model.error_matrix_from_coeffs(theta)
    assert e[0, 1] == pytest.approx(30.0 * units.ARCSEC_TO_RAD)  # yx: x gyro senses y
    assert e[2, 0] == pytest.approx(40.0 * units.ARCSEC_TO_RAD)  # xz: z gyro senses x
    assert e[1, 1] == pytest.approx(-80e-6)
    assert_allclose(model.coeffs_from_error_matrix(e, b), theta, rtol=1e-12)
    assert model.inner_axis_azimuth(theta)[0] == pytest.approx(20.0)
