"""The turntable calibration from numpy arrays (:func:`thermocal.turntable.calibrate_arrays`),
as a notebook user calls it: checked against the simulator's truth, and independent of the
unit the arrays are given in."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.errors import ParameterError
from thermocal.turntable import calibrate_arrays, simulate_turntable16

GYRO = ("gyro_x", "gyro_y", "gyro_z")


@pytest.fixture(scope="module")
def run() -> tuple[dict[str, np.ndarray], dict[str, object]]:
    rec, truth = simulate_turntable16(3, rate_hz=10.0, dwell_s=20.0)
    arrays = {
        "time_s": rec.time_s,
        "gyro_deg_s": np.column_stack([rec.column(c) for c in GYRO]),
        "alpha_deg": rec.column("alpha_deg"),
        "beta_deg": rec.column("beta_deg"),
    }
    return arrays, truth


def test_every_coefficient_is_the_simulators_within_4_sigma(
    run: tuple[dict[str, np.ndarray], dict[str, object]],
) -> None:
    a, truth = run
    res = calibrate_arrays(a["time_s"], a["gyro_deg_s"], a["alpha_deg"], a["beta_deg"], 40.0,
                           min_dwell_s=10.0)  # fmt: skip
    want = np.concatenate([truth["bias_deg_h"], truth["scale_factor_ppm"],
                           truth["misalignment_arcsec"]])  # type: ignore[list-item]  # fmt: skip
    z = (res.kalman.theta - want) / np.maximum(res.kalman.sigma, 1e-3)
    assert np.all(np.abs(z) < 4.0), z
    assert res.n_positions == 16 and res.latitude_deg == 40.0


def test_radians_in_give_the_same_calibration(
    run: tuple[dict[str, np.ndarray], dict[str, object]],
) -> None:
    """Gyro in rad/s and encoders in rad (converted here with π/180) give the coefficients
    of the degree arrays to 1e-6 of their σ."""
    a, _ = run
    deg = calibrate_arrays(a["time_s"], a["gyro_deg_s"], a["alpha_deg"], a["beta_deg"], 40.0,
                           min_dwell_s=10.0)  # fmt: skip
    k = np.pi / 180.0
    rad = calibrate_arrays(a["time_s"], a["gyro_deg_s"] * k, a["alpha_deg"] * k,
                           a["beta_deg"] * k, 40.0, gyro_unit="rad/s", encoder_unit="rad",
                           min_dwell_s=10.0)  # fmt: skip
    np.testing.assert_allclose(rad.kalman.theta, deg.kalman.theta, rtol=0,
                               atol=1e-6 * float(np.max(deg.kalman.sigma)))  # fmt: skip


def test_a_gyro_of_the_wrong_shape_is_refused_by_its_name(
    run: tuple[dict[str, np.ndarray], dict[str, object]],
) -> None:
    a, _ = run
    with pytest.raises(ParameterError) as err:
        calibrate_arrays(a["time_s"], a["gyro_deg_s"][:, :2], a["alpha_deg"], a["beta_deg"], 40.0)
    assert err.value.parameter == "gyro"
    assert str(err.value).startswith("gyro must be an (n, 3) array")
