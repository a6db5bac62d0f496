"""The six-axis MEMS IMU scenario through the whole multi-channel workflow (issue 15).

Check: on the validation run (another chamber program, weakly correlated), every
channel's temperature-induced bias is removed ≥ 97 % (rms against the simulator's truth),
and the compensated columns are raw − model in the data's unit.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.simulate import IMU_CHANNELS, SCENARIOS
from thermocal.writers import write_recording


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict]:
    d = tmp_path_factory.mktemp("imu")
    ((mod, truth),) = SCENARIOS["mems-imu"](3, rate_hz=0.2)
    ((val, _),) = SCENARIOS["mems-imu"](3, run="validation", rate_hz=0.2)
    write_recording(mod, d / "mod.parquet")
    write_recording(val, d / "val.csv")  # the other format too
    return d / "mod.parquet", d / "val.csv", truth


def test_truth_is_the_same_unit_in_both_runs(runs: tuple[Path, Path, dict]) -> None:
    ((_m, t1),) = SCENARIOS["mems-imu"](3, rate_hz=0.2)
    ((_v, t2),) = SCENARIOS["mems-imu"](3, run="validation", rate_hz=0.2)
    assert t1["channels"] == t2["channels"]
    assert t1["channels"]["az"]["gravity_mg"] == 1000.0


def test_six_channels_fit_compensate_removes_97_percent(
    runs: tuple[Path, Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mod, val, _truth = runs
    names = ",".join(n for n, _u in IMU_CHANNELS)
    cal = tmp_path / "cal.json"
    assert main(["fit", str(mod), "--model", "poly", "--order", "3", "--signal", names,
                 "--temps", "T_die", "-o", str(cal), "--json"]) == 0  # fmt: skip
    fit = json.loads(capsys.readouterr().out)
    assert set(fit["channels"]) == {n for n, _u in IMU_CHANNELS}
    out = tmp_path / "comp.parquet"
    assert main(["compensate", str(cal), str(val), "-o", str(out)]) == 0
    capsys.readouterr()
    d = pd.read_parquet(out)
    raw = pd.read_csv(val)
    for name, unit in IMU_CHANNELS:
        model = d[f"{name}_model"]
        np.testing.assert_allclose(d[f"{name}_comp"], raw[name] - model, rtol=0, atol=1e-9)
        truth = d[f"truth_{name}"]
        err = (model - model.mean()) - (truth - truth.mean())
        removed = 100.0 * (1.0 - float(np.sqrt(np.mean(err**2))) / float(truth.std()))
        assert removed >= 97.0, (name, unit, removed)
