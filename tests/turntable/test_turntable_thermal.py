"""Triad parameters over temperature (issue 19): polynomial fits across soaks with LOTO
order choice, standard errors against the scatter over seeds, clamping, and the per-sample
correction ``(I + E(T))⁻¹ (x − b(T))`` against a direct construction."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.errors import DesignError
from thermocal.turntable import thermal

SOAKS = np.array([-40.0, -20.0, 0.0, 20.0, 40.0, 60.0])
SIGMA = np.array([0.002] * 3 + [2.0] * 3 + [0.5] * 6)


def truth(t: np.ndarray) -> np.ndarray:
    """Cubic biases [°/h], quadratic scale factors [ppm], linear misalignments [″]."""
    d = np.asarray(t) - 10.0
    cols = []
    for i in range(3):
        cols.append(0.01 * (i + 1) + 2e-4 * d - 3e-6 * d**2 + 1e-7 * (i + 1) * d**3)
    for i in range(3):
        cols.append(50.0 * (i - 1) + 1.5 * d + 0.02 * d**2)
    for k in range(6):
        cols.append(10.0 * (k - 2.5) + 0.3 * (k - 2) * d)
    return np.stack(cols, axis=-1)


def _runs(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return truth(SOAKS) + rng.normal(0.0, 1.0, (SOAKS.size, 12)) * SIGMA


def test_orders_chosen_and_parameters_recovered() -> None:
    tri = thermal.fit_triad("gyro", SOAKS, _runs(0), np.tile(SIGMA, (SOAKS.size, 1)), tref_c=10.0)
    assert tri.order == 3  # the biases are cubic
    t = np.linspace(-40.0, 60.0, 11)
    err = np.abs(tri.theta_at(t) - truth(t))
    assert np.all(err < 4 * SIGMA), err.max(axis=0) / SIGMA
    assert all(np.isfinite(f.loto_rms) for f in tri.fits)


def test_sigmas_match_the_scatter_over_seeds() -> None:
    sg = np.tile(SIGMA, (SOAKS.size, 1))
    fits = [
        thermal.fit_triad("gyro", SOAKS, _runs(s), sg, tref_c=10.0, order=3) for s in range(200)
    ]
    c0 = np.array([[f.coef[0] for f in tri.fits] for tri in fits])
    s0 = np.mean([[f.sigma[0] for f in tri.fits] for tri in fits], axis=0)
    ratio = c0.std(axis=0, ddof=1) / s0
    # σ from the runs' own σ (χ² ≈ 1, inflated only above 1): within 25 % of the scatter
    assert np.all((ratio > 0.75) & (ratio < 1.25)), ratio


def test_too_few_soaks_for_the_order() -> None:
    sg = np.tile(SIGMA, (2, 1))
    with pytest.raises(DesignError, match="order 3 needs at least 4"):
        thermal.fit_triad("gyro", [0.0, 40.0], truth(np.array([0.0, 40.0])), sg, order=3)
    with pytest.raises(DesignError, match="different temperatures"):
        thermal.fit_triad("gyro", [25.0, 25.1], truth(np.array([25.0, 25.1])), sg)


def test_clamped_outside_the_calibrated_range() -> None:
    tri = thermal.fit_triad("gyro", SOAKS, truth(SOAKS), np.tile(SIGMA, (6, 1)), order=3)
    np.testing.assert_allclose(tri.theta_at([-80.0, 100.0]), tri.theta_at([-40.0, 60.0]))


def test_correction_inverts_the_error_model() -> None:
    tri = thermal.fit_triad("accel", SOAKS, truth(SOAKS), np.tile(SIGMA, (6, 1)), order=3)
    rng = np.random.default_rng(2)
    temp = rng.uniform(-40.0, 60.0, 500)
    true = rng.normal(0.0, 9.8, (500, 3))
    b, e = thermal.error_terms(tri, temp)
    to_data = 9.80665e-3  # mg → m/s²
    meas = np.einsum("nij,nj->ni", np.eye(3) + e, true) + b * to_data
    np.testing.assert_allclose(thermal.correct(tri, meas, temp, to_data), true, atol=1e-12)


def test_round_trip_through_the_file_form() -> None:
    tri = thermal.fit_triad("gyro", SOAKS, _runs(3), np.tile(SIGMA, (6, 1)))
    back = thermal.TriadThermal.from_dict(tri.to_dict())
    np.testing.assert_array_equal(back.theta_at(SOAKS), tri.theta_at(SOAKS))


def test_pipeline_standard_errors_match_the_scatter_over_seeds() -> None:
    """The whole chain on simulated soaks (per-run Kalman/least-squares gyro estimates and
    dwell accelerometer estimates, then the polynomials, order 3): over six seeds, the
    errors of the 24 parameters at TREF against the simulator's truth, each divided by its
    reported σ, have an rms near 1 (0.6–1.5 for 144 values: σ neither optimistic nor
    pessimistic by half)."""
    import warnings

    from thermocal.turntable.calibration import calibrate
    from thermocal.turntable.simulate import (
        ACCEL_THERMAL_TRUTH,
        GYRO_THERMAL_TRUTH,
        simulate_turntable_thermal,
        thermal_theta,
    )

    z = []
    for seed in range(6):
        runs = [
            r
            for r in simulate_turntable_thermal(seed=seed, rate_hz=10.0, drift_c=0.0)
            if not r[1]["held_out"]
        ]
        res = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for rec, _truth in runs:
                res.append(calibrate(rec, accel_columns=["accel_x", "accel_y", "accel_z"],
                                     temperature_column="T_imu"))  # fmt: skip
        temps = [r.temperature_c for r in res]
        gyro = thermal.fit_triad("gyro", temps, [r.kalman.theta for r in res],
                                 [r.kalman.sigma for r in res], tref_c=10.0, order=3)  # fmt: skip
        acc = thermal.fit_triad("accel", temps, [r.accel.theta for r in res],
                                [r.accel.sigma for r in res], tref_c=10.0, order=3)  # fmt: skip
        for tri, spec in ((gyro, GYRO_THERMAL_TRUTH), (acc, ACCEL_THERMAL_TRUTH)):
            est = tri.theta_at(10.0)
            sig = tri.sigma_at(10.0)
            true = thermal_theta(spec, 10.0)
            z.extend(((est - true) / sig).tolist())
    rms = float(np.sqrt(np.mean(np.square(z))))
    assert 0.6 < rms < 1.5, rms
