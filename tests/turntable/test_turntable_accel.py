"""The accelerometer triad from turntable dwells (issue 19, first part).

References come from outside the estimator: a joint 12-unknown least squares over all the
stacked dwell equations, written here with ``np.linalg.lstsq`` (the estimator solves the
three axes separately through an SVD of a scaled, weighted design), and the truth the test
applies."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal import units
from thermocal.errors import DesignError
from thermocal.turntable import accel
from thermocal.turntable.model import error_matrices
from thermocal.turntable.schedule import POSITIONS_16

G = 9.80619  # WGS-84 normal gravity near 45°, m/s²
TRUTH = np.array([1.5, -2.0, 0.8, 120.0, -300.0, 80.0, 30.0, -25.0, -10.0, 15.0, 40.0, -35.0])
"""bias [mg], scale factor [ppm], misalignment [″] (yx, zx, xy, zy, xz, yz)."""


def _dwells(noise_mg: float, seed: int, n: int = 6000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pos = np.array(POSITIONS_16, dtype=np.float64)
    f_true = accel.gravity_in_body(pos[:, 0], pos[:, 1], G)
    e = error_matrices(TRUTH)
    b = TRUTH[0:3] * units.MG_TO_MS2
    rng = np.random.default_rng(seed)
    f_meas = f_true @ (np.eye(3) + e).T + b
    f_meas += rng.normal(0.0, noise_mg * units.MG_TO_MS2, f_meas.shape)
    return f_meas, f_true, np.full(len(pos), float(n))


def _joint_lstsq(f_meas: np.ndarray, f_true: np.ndarray) -> np.ndarray:
    """θ from one stacked least squares: unknowns E (9, row-major) and b (3)."""
    rows, rhs = [], []
    for d in range(f_meas.shape[0]):
        for i in range(3):
            row = np.zeros(12)
            row[3 * i : 3 * i + 3] = f_true[d]
            row[9 + i] = 1.0
            rows.append(row)
            rhs.append(f_meas[d, i] - f_true[d, i])
    x = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
    e = x[:9].reshape(3, 3)
    theta = np.zeros(12)
    theta[0:3] = x[9:] / units.MG_TO_MS2
    theta[3:6] = np.diag(e) * 1e6
    names = {"yx": (0, 1), "zx": (0, 2), "xy": (1, 0), "zy": (1, 2), "xz": (2, 0), "yz": (2, 1)}
    for k, nm in enumerate(("yx", "zx", "xy", "zy", "xz", "yz")):
        theta[6 + k] = e[names[nm]] * 180.0 / np.pi * 3600.0
    return theta


def test_noise_free_dwells_give_the_truth() -> None:
    f_meas, f_true, n = _dwells(0.0, 0)
    est = accel.estimate_accel_triad(f_meas, f_true, n)
    np.testing.assert_allclose(est.theta, TRUTH, rtol=1e-9, atol=1e-9)
    assert est.residual_rms_mg < 1e-9


def test_agrees_with_an_independent_joint_least_squares() -> None:
    f_meas, f_true, n = _dwells(0.05, 1)
    est = accel.estimate_accel_triad(f_meas, f_true, n)
    np.testing.assert_allclose(est.theta, _joint_lstsq(f_meas, f_true), rtol=0, atol=1e-8)


def test_standard_errors_match_the_scatter_over_seeds() -> None:
    """σ from one run's residuals against the spread of θ over 300 noisy runs (0.05 mg a
    dwell mean): within 20 % for every parameter, and the truth within 4σ."""
    ests = [accel.estimate_accel_triad(*_dwells(0.05, s)) for s in range(300)]
    theta = np.array([e.theta for e in ests])
    sigma = np.mean([e.sigma for e in ests], axis=0)
    np.testing.assert_allclose(theta.std(axis=0, ddof=1), sigma, rtol=0.2)
    assert np.all(np.abs(theta.mean(axis=0) - TRUTH) < 4 * sigma / np.sqrt(300) + 1e-12)
    # 0.05 mg a dwell, 16 dwells: biases to about 0.02 mg, scale factors to tens of ppm
    assert np.all(sigma[0:3] < 0.05) and np.all(sigma[3:6] < 60)


def test_attitudes_all_in_one_plane_are_refused() -> None:
    pos = np.array([(a, 0.0) for a in range(0, 360, 45)], dtype=np.float64)  # β fixed
    f_true = accel.gravity_in_body(pos[:, 0], pos[:, 1], G)
    with pytest.raises(DesignError, match="three independent"):
        accel.estimate_accel_triad(f_true, f_true, np.full(len(pos), 100.0))
