"""A multi-position result as a pandas table: ``to_frame()`` holds exactly the rows of
``table()`` (the coefficients imucal's numbers are checked on in the notebook tutorial's
test), one row per coefficient of each triad."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from thermocal.multipos import calibrate_session, parse_poses

DATA = Path(__file__).resolve().parents[1] / "data" / "imucal_ferraris"
MG = 9.80665e-3  # 1 mg [m/s²]


def test_to_frame_is_the_table() -> None:
    data = np.genfromtxt(DATA / "example_ferraris_session.csv", delimiter=",", names=True)
    time_s = data["n_samples"] / 102.4
    accel_mg = np.column_stack([data["acc_x"], data["acc_y"], data["acc_z"]]) / MG
    gyro = np.radians(np.column_stack([data["gyr_x"], data["gyr_y"], data["gyr_z"]]))
    raw = json.loads((DATA / "example_ferraris_session_list.json").read_text(encoding="utf-8"))
    sections = parse_poses(raw, time_s.size, "imucal's section list")
    result = calibrate_session(time_s, accel_mg, gyro, g_mg=9.81 / MG, sections=sections)
    rows = result.table()
    frame = result.to_frame()
    assert len(frame) == len(rows) == 24  # 12 coefficients × 2 triads
    assert list(frame["triad"]) == ["accel"] * 12 + ["gyro"] * 12
    np.testing.assert_array_equal(frame["value"].to_numpy(), [r["value"] for r in rows])
    np.testing.assert_array_equal(
        result.accel.to_frame()["value"].to_numpy(), [r["value"] for r in rows[:12]]
    )
    assert list(result.gyro.to_frame()["unit"]) == [r["unit"] for r in rows[12:]]
