"""``thermocal.pipeline.multipos``: ``MultiposResult.to_dict()`` is what ``thermocal multipos
--json`` prints; the checks of the output name; the gyro's scatter threshold
(:func:`thermocal.multipos.gyro.scatter_beyond_noise`) against the χ² law."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from thermocal.cli import main
from thermocal.errors import ThermocalInputError
from thermocal.multipos.gyro import scatter_beyond_noise
from thermocal.pipeline.multipos import MultiposOptions, calibrate_files
from thermocal.simulate import SimulateOptions, simulate_scenario
from thermocal.writers import write_recording

MG_M_S2 = 9.80665e-3  # 1 mg [m/s²]
A = ("accel_x", "accel_y", "accel_z")
G = ("gyro_x", "gyro_y", "gyro_z")


def test_to_dict_is_what_the_cli_prints(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sim = simulate_scenario("multipos", 11, None, SimulateOptions())
    rec, truth = next((r, t) for r, t in sim.results if t["label"] == "T+25")
    f, out = tmp_path / "s.parquet", tmp_path / "cal.json"
    write_recording(rec, f)
    code = main(["multipos", str(f), "--accel", ",".join(A), "--gyro", ",".join(G),
                 "--temps", "T_imu", "-o", str(out), "--json"])  # fmt: skip
    assert code == 0
    printed = json.loads(capsys.readouterr().out)
    res = calibrate_files([f], out, MultiposOptions(A, G, temps="T_imu"))
    assert json.loads(json.dumps(res.to_dict())) == printed
    # against the simulator's truth: the poses and the accelerometer bias within 3.5 σ
    assert printed["n_poses"] == len(truth["poses"])
    ta = np.array(truth["accel_theta"])[0:3] * MG_M_S2
    z = (np.array(printed["accel"]["bias"]) - ta) / np.array(printed["accel"]["bias_sigma"])
    assert np.all(np.abs(z) < 3.5), z


def test_the_calibration_is_written_as_json_only(tmp_path: Path) -> None:
    with pytest.raises(ThermocalInputError, match=r"the calibration is JSON; use a \.json name"):
        calibrate_files([tmp_path / "s.csv"], tmp_path / "cal.csv", MultiposOptions(A))
    assert not (tmp_path / "cal.csv").exists()


@pytest.mark.parametrize("dof", [3, 12, 50, 400])
def test_scatter_threshold_is_three_sigma_of_the_reduced_chi2(dof: int) -> None:
    # the reduced χ² of ν normal residuals: mean 1, sd std(χ²_ν)/ν (scipy's χ² law)
    law = stats.chi2(dof)
    limit = law.mean() / dof + 3.0 * law.std() / dof
    assert not scatter_beyond_noise(limit * (1 - 1e-9), dof)
    assert scatter_beyond_noise(limit * (1 + 1e-9), dof)
