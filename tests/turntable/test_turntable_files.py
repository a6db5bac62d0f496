"""``thermocal turntable`` as a library call (:mod:`thermocal.pipeline.turntable`), without the
command line (issue 27)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.errors import ThermocalInputError
from thermocal.pipeline.turntable import (
    SingleRunResult,
    TurntableOptions,
    check_order,
    turntable_calibration,
)
from thermocal.readers.dispatch import read_recording
from thermocal.readers.options import ReadOptions
from thermocal.turntable import calibrate, simulate_turntable16
from thermocal.writers import write_recording

GYRO = ("gyro_x", "gyro_y", "gyro_z")


def test_one_run_is_calibrated_and_written(tmp_path: Path) -> None:
    rec, truth = simulate_turntable16(2, rate_hz=2.0)
    path = tmp_path / "run.csv"
    write_recording(rec, path)
    out = tmp_path / "res.json"
    res = turntable_calibration([path], out, TurntableOptions(GYRO, latitude=40.0))
    assert isinstance(res, SingleRunResult)
    direct = calibrate(read_recording(path, ReadOptions(signals=list(GYRO))), 40.0)
    np.testing.assert_array_equal(res.result.kalman.theta, direct.kalman.theta)
    saved = json.loads(out.read_text())
    assert saved["input"] == str(path) and saved["bias_deg_h"] == res.to_dict()["bias_deg_h"]
    sigma = np.array(saved["bias_deg_h_sigma"])
    assert np.all(np.abs(np.array(saved["bias_deg_h"]) - truth["bias_deg_h"]) < 4 * sigma)


def test_refusals(tmp_path: Path) -> None:
    for bad in (-1, 4, 10**30):
        with pytest.raises(ThermocalInputError, match=r"^order must be between 0 and 3"):
            check_order(bad)
    check_order(0)
    check_order(3)
    files = [tmp_path / "a.csv", tmp_path / "b.csv"]
    with pytest.raises(ThermocalInputError, match="several runs: name their temperature"):
        turntable_calibration(files, tmp_path / "c.json", TurntableOptions(GYRO))
    with pytest.raises(ThermocalInputError, match=r"^order and tref_c need several runs"):
        turntable_calibration(files[:1], tmp_path / "c.json", TurntableOptions(GYRO), order=1)
