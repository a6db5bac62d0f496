"""``thermocal multipos``'s library function :func:`thermocal.pipeline.multipos.calibrate_files`
without the command line (issue 27): a simulated session with known truth, its options
checked before any file is read, the calibration it saves."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from thermocal.errors import ThermocalInputError
from thermocal.pipeline.model_file import load_calibration
from thermocal.pipeline.multipos import MultiposOptions, calibrate_files
from thermocal.simulate import SimulateOptions, simulate_scenario
from thermocal.writers import write_recording

MG_M_S2 = 9.80665e-3  # 1 mg [m/s²]
A = ("accel_x", "accel_y", "accel_z")
G = ("gyro_x", "gyro_y", "gyro_z")


def test_calibrate_files_recovers_the_true_bias_and_saves(tmp_path: Path) -> None:
    sim = simulate_scenario("multipos", 11, None, SimulateOptions())
    (rec, truth) = next((r, t) for r, t in sim.results if t["label"] == "T+25")
    f = tmp_path / "s.parquet"
    write_recording(rec, f)
    out = tmp_path / "cal.json"
    res = calibrate_files([f], out, MultiposOptions(A, G, temps="T_imu"))
    s = res.to_dict()
    assert s["output"] == str(out) and res.accel_unit == s["unit"] == "m/s^2"
    assert s["n_poses"] == len(truth["poses"])
    # the accelerometer bias [m/s²] and the gyro bias [deg/s] within 3.5σ of the truth
    ta, tg = np.array(truth["accel_theta"]), np.array(truth["gyro_theta"])
    z = (np.array(s["accel"]["bias"]) - ta[0:3] * MG_M_S2) / np.array(s["accel"]["bias_sigma"])
    assert np.all(np.abs(z) < 3.5), z
    z = (np.array(s["gyro"]["bias"]) - tg[0:3] / 3600.0) / np.array(s["gyro"]["bias_sigma"])
    assert np.all(np.abs(z) < 3.5), z
    saved = load_calibration(out)
    assert [t.name for t in saved.triads] == ["accel", "gyro"]
    assert [t.columns for t in saved.triads] == [A, G]
    assert saved.triads[0].model.tref_c == pytest.approx(res.calibration.triads[0].model.tref_c)


@pytest.mark.parametrize(
    ("opts", "n_files", "poses", "message"),
    [
        (MultiposOptions(A), 2, None, "several files: name their temperature column"),
        (MultiposOptions(A, order=2), 1, None, r"^order and tref_c need several files"),
        (MultiposOptions(A, gravity_m_s2=9.8, latitude_deg=45.0), 1, None, "not both"),
        (MultiposOptions(A, static_s=0.0), 1, None, r"^static_s must be a positive"),
        (MultiposOptions(A, temps="T"), 2, Path("p.json"), r"^poses names the sections"),
    ],
)
def test_calibrate_files_checks_the_options_before_reading(
    tmp_path: Path, opts: MultiposOptions, n_files: int, poses: Path | None, message: str
) -> None:
    missing = [tmp_path / f"no{i}.csv" for i in range(n_files)]  # never read
    with pytest.raises(ThermocalInputError, match=message):
        calibrate_files(missing, tmp_path / "cal.json", opts, poses)
    assert not (tmp_path / "cal.json").exists()
