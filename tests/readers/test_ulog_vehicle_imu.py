"""A ULog ``vehicle_imu``'s integrals read as rates (:mod:`thermocal.readers.ulog`), against
the integrals over their intervals written here (kills a mutant of
``benchmarks/mutation_check.py``)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np


def test_ulog_vehicle_imu_integrals_become_rates(tmp_path: Path) -> None:
    """PX4's ``vehicle_imu`` logs Δθ [rad] and Δv [m/s] over Δt [µs]: the reader's rates
    are Δθ/Δt [rad/s] and Δv/Δt [m/s²] with Δt in seconds (mutant ulog-delta-dt-us reads
    Δt in ms: rates 1000× too small).  Written with the test's own ULog writer."""
    from thermocal.readers.dispatch import read_whole_table
    from thermocal.readers.options import ReadOptions
    from ulog_writer import ulog_bytes

    fields = [("uint64_t", "timestamp"), ("float[3]", "delta_angle"),
              ("float[3]", "delta_velocity"), ("uint32_t", "delta_angle_dt"),
              ("uint32_t", "delta_velocity_dt")]  # fmt: skip
    w, a, dt_us = (0.1, -0.2, 0.3), (0.5, 0.0, -9.8), 4000
    rows = [
        (1_000_000 + k * dt_us, *(x * dt_us * 1e-6 for x in w), *(x * dt_us * 1e-6 for x in a),
         dt_us, dt_us)
        for k in range(200)
    ]  # fmt: skip
    log = tmp_path / "imu.ulg"
    log.write_bytes(ulog_bytes([("vehicle_imu", 0, fields, rows)]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        df, info = read_whole_table(log, ReadOptions(topic="vehicle_imu"))
    for i in range(3):
        np.testing.assert_allclose(df[f"gyro_rad_s[{i}]"], w[i], rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(df[f"accel_m_s2[{i}]"], a[i], rtol=1e-6, atol=1e-9)
    assert info["time_unit"] == "us"
