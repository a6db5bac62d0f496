"""A model applied to data it was not fitted on says so (issue 14): another sensor."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main


def _csv(path: Path, sensor: str | None, seed: int) -> None:
    rng = np.random.default_rng(seed)
    t = np.arange(3000.0)
    temp = 25.0 + 10.0 * np.sin(2 * np.pi * t / 3000.0)
    gyro = 0.2 * temp + rng.standard_normal(t.size)
    pd.DataFrame({"time": t, "gyro": gyro, "T1": temp}).to_csv(path, index=False)
    meta: dict = {"time_unit": "s", "signals": {"gyro": "deg/h"}, "temperatures": {"T1": "degC"}}
    if sensor:
        meta["metadata"] = {"sensor_id": sensor}
    Path(str(path) + ".meta.json").write_text(json.dumps(meta))


def _fit(tmp_path: Path, *files: str) -> tuple[int, str]:
    code = main(
        ["fit", *[str(tmp_path / f) for f in files], "--model", "poly", "--order", "1",
         "--signal", "gyro", "--temps", "T1", "-o", str(tmp_path / "m.json")]
    )  # fmt: skip
    return code, str(tmp_path / "m.json")


def test_other_sensor_is_named_by_compensate_and_validate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _csv(tmp_path / "a.csv", "SN-001", 1)
    _csv(tmp_path / "b.csv", "SN-002", 2)
    code, model = _fit(tmp_path, "a.csv")
    assert code == 0
    assert json.loads(Path(model).read_text())["inputs"]["sensor_id"] == "SN-001"
    capsys.readouterr()
    code = main(["compensate", model, str(tmp_path / "b.csv"), "-o", str(tmp_path / "o.csv")])
    err = capsys.readouterr().err
    assert code == 0
    assert "sensor 'SN-002' but the model was fitted on sensor 'SN-001'" in err
    code = main(["validate", model, str(tmp_path / "b.csv")])
    err = capsys.readouterr().err
    assert "fitted on sensor 'SN-001'" in err
    # the same sensor, or data that do not say, are quiet
    code = main(["compensate", model, str(tmp_path / "a.csv"), "-o", str(tmp_path / "p.csv")])
    assert "fitted on sensor" not in capsys.readouterr().err
    _csv(tmp_path / "c.csv", None, 3)
    code = main(["compensate", model, str(tmp_path / "c.csv"), "-o", str(tmp_path / "q.csv")])
    assert "fitted on sensor" not in capsys.readouterr().err


def test_fit_over_several_sensors_warns(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _csv(tmp_path / "a.csv", "SN-001", 1)
    _csv(tmp_path / "b.csv", "SN-002", 2)
    code, model = _fit(tmp_path, "a.csv", "b.csv")
    assert code == 0
    assert "different sensors (SN-001, SN-002)" in capsys.readouterr().err
    assert "sensor_id" not in json.loads(Path(model).read_text())["inputs"]
