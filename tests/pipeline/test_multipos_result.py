"""``MultiposResult.to_dict`` is the one JSON form of a multi-position calibration, built
from the result each time; a rejected pose's reason names the pose detector's parameters
(``motion_fraction``) for a Python user and, spelled by the command line, its options."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from thermocal.multipos.poses import find_poses
from thermocal.multipos.simulate import simulate_session
from thermocal.pipeline.messages import option_name
from thermocal.pipeline.multipos import MultiposOptions, calibrate_files
from thermocal.simulate import SimulateOptions, simulate_scenario
from thermocal.writers import write_recording

MG_M_S2 = 9.80665e-3  # 1 mg [m/s²]
A = ("accel_x", "accel_y", "accel_z")
G = ("gyro_x", "gyro_y", "gyro_z")


def test_to_dict_is_built_from_the_result_each_time(tmp_path: Path) -> None:
    sim = simulate_scenario("multipos", 11, None, SimulateOptions())
    rec, truth = next((r, t) for r, t in sim.results if t["label"] == "T+25")
    f = tmp_path / "s.parquet"
    write_recording(rec, f)
    res = calibrate_files([f], tmp_path / "cal.json", MultiposOptions(A, G, temps="T_imu"))
    first = res.to_dict()
    first["accel"]["bias"][0] = 1e9  # a caller's change to its copy
    first["runs"][0]["poses"].clear()
    again = res.to_dict()
    assert again["accel"]["bias"][0] != 1e9 and len(again["runs"][0]["poses"]) == len(
        truth["poses"]
    )
    # the figures come from the result's runs: the bias within 3.5 σ of the simulator's
    ta = np.array(truth["accel_theta"])[0:3] * MG_M_S2
    z = (np.array(again["accel"]["bias"]) - ta) / np.array(again["accel"]["bias_sigma"])
    assert np.all(np.abs(z) < 3.5), z
    assert again["output"] == str(tmp_path / "cal.json") and again["unit"] == res.accel_unit


def test_tremor_rejections_name_the_parameters() -> None:
    """20 poses held with a 0.2° tremor at 6 Hz (the tremor case of the real-session tests):
    the gyro's tremor stretches are rejected, naming ``motion_fraction`` and
    ``still_threshold``; the command line's spelling names their options."""
    s = simulate_session(np.random.default_rng(7), np.zeros(12), np.zeros(12), n_poses=20,
                         dwell_s=2.0, move_s=1.5, accel_noise_mg=0.3,
                         tremor_deg=0.2)  # fmt: skip
    det = find_poses(s["time_s"], s["accel_mg"], s["gyro_deg_s"])
    tremor = [r for r in det.rejected if r.reason.startswith("tremor: the gyro's variance")]
    assert len(tremor) == 7
    assert all(r.reason.endswith("raise motion_fraction or still_threshold to take it")
               for r in tremor)  # fmt: skip
    spelled = det.to_dict(spell=option_name)["rejected"]
    assert [r["reason"] for r in spelled] == [
        r.reason.replace("motion_fraction", "--motion-fraction").replace(
            "still_threshold", "--still-threshold"
        )
        for r in det.rejected
    ]
