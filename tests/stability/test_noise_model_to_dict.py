"""The noise model serialises itself: ``NoiseModel.to_dict(source)`` is the file
``thermocal noise --format json`` writes, key for key, and its noise densities are the
simulated ones (white noise of a known continuous-time density, drawn here)."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.errors import ConditioningWarning
from thermocal.pipeline.messages import jsonable
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions
from thermocal.stability.analysis import imu_noise

DT_S = 0.01  # 100 Hz
DENSITY = (1.5e-4, 2.0e-4, 2.5e-4)  # rad/s/√Hz, continuous time
COLS = ["gyro x [rad/s]", "gyro y [rad/s]", "gyro z [rad/s]"]


def test_noise_model_to_dict_is_the_json_file(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    n = 60_000
    data = {"time [s]": np.arange(n) * DT_S}
    for c, sigma in zip(COLS, DENSITY, strict=True):
        data[c] = rng.normal(0.0, sigma / math.sqrt(DT_S), n)  # discrete σ = σ_c/√Δt
    path = tmp_path / "imu.csv"
    pd.DataFrame(data).to_csv(path, index=False, float_format="%.9g")
    out = tmp_path / "noise.json"
    code = main(["noise", str(path), "--time", "time [s]", "--gyro", ",".join(COLS),
                 "--format", "json", "-o", str(out)])  # fmt: skip
    assert code == 0
    written = json.loads(out.read_text())

    read = ReadOptions(time="time [s]", signals=tuple(COLS))
    rec = read_recording(path, read, keep_other=False)
    with warnings.catch_warnings():  # white noise alone: no random walk in the record
        warnings.simplefilter("ignore", ConditioningWarning)
        d = imu_noise(rec, COLS, [], where=str(path)).model.to_dict(path.name)
    assert json.loads(json.dumps(jsonable(d), allow_nan=False)) == written
    assert list(d) == [
        "source", "kalibr", "kalibr_axis", "kalibr_rule", "inflate", "update_rate_hz",
        "confidence", "discrete_time", "axes",
    ]  # fmt: skip
    assert d["source"] == "imu.csv" and d["update_rate_hz"] == pytest.approx(100.0)
    for c, truth in zip(COLS, DENSITY, strict=True):
        density = d["axes"][c]["noise_density"]
        assert density["unit"] == "rad/s/sqrt(Hz)"
        assert density["value"] == pytest.approx(truth, rel=0.05)
