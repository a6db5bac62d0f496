"""``thermocal turntable`` command line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.turntable import simulate_turntable16
from thermocal.writers import write_recording


@pytest.fixture(scope="module")
def run_csv(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, list[float]]]:
    d = tmp_path_factory.mktemp("tt")
    rec, truth = simulate_turntable16(3, rate_hz=5.0)
    path = d / "run.csv"
    write_recording(rec, path)
    return path, truth


def test_turntable_json_and_file(
    run_csv: tuple[Path, dict[str, list[float]]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, truth = run_csv
    out = tmp_path / "res.json"
    assert main(["turntable", str(path), "-o", str(out), "--latitude", "40", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    saved = json.loads(out.read_text())
    for key in ("bias_deg_h", "scale_factor_ppm", "misalignment_arcsec"):
        assert key in saved and key + "_sigma" in saved
        est = np.array(saved[key])
        sig = np.array(saved[key + "_sigma"])
        assert np.all(np.abs(est - np.array(truth[key])) < 4 * sig)
    assert np.array(saved["error_matrix"]).shape == (3, 3)
    assert printed["bias_deg_h"] == saved["bias_deg_h"]
    assert saved["agreement_max_sigma"] < 0.05


def test_turntable_renamed_columns(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec, _ = simulate_turntable16(1, rate_hz=2.0)
    rec.columns = {
        {"gyro_x": "wx rad/s", "gyro_y": "wy rad/s", "gyro_z": "wz rad/s"}.get(k, k): (
            np.deg2rad(v) if k.startswith("gyro") else v
        )
        for k, v in rec.columns.items()
    }
    rec.columns["outer"] = rec.columns.pop("beta_deg")
    rec.units = {}
    rec.signals = ()
    path = tmp_path / "renamed.csv"
    write_recording(rec, path)
    out = tmp_path / "r.json"
    code = main(
        [
            "turntable",
            str(path),
            "-o",
            str(out),
            "--gyro",
            "wx rad/s,wy rad/s,wz rad/s",
            "--gyro-unit",
            "rad/s",
            "--beta",
            "outer",
            "--latitude",
            "40",
            "--json",
        ]
    )
    assert code == 0
    assert json.loads(capsys.readouterr().out)["n_positions"] == 16


def test_turntable_bad_input_exit_2(
    run_csv: tuple[Path, dict[str, list[float]]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, _ = run_csv
    assert main(["turntable", str(path), "-o", str(tmp_path / "x.json"), "--alpha", "nope"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "'nope'" in err
    assert main(["turntable", str(path), "-o", str(path)]) == 2
    assert "refusing to write over the input" in capsys.readouterr().err
    assert main(["turntable", str(path), "-o", str(tmp_path / "y.json"), "--min-dwell", "120"]) == 2
    assert "shorter than the 120 s asked" in capsys.readouterr().err
    assert not (tmp_path / "y.json").exists()


def test_turntable_gyro_unit_from_column_name_or_a_stated_default(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No silent unit: gyro columns written in °/h with the unit in their names give the
    same calibration as the °/s original; with no unit anywhere, a warning states deg/s."""
    import pandas as pd

    rec, truth = simulate_turntable16(2, rate_hz=2.0)
    df = pd.DataFrame({"time": rec.time_s, **rec.columns})
    for k in ("gyro_x", "gyro_y", "gyro_z"):
        df[f"{k} (deg/h)"] = df.pop(k) * 3600.0
    df.to_csv(tmp_path / "dph.csv", index=False)
    code = main(
        ["turntable", str(tmp_path / "dph.csv"), "-o", str(tmp_path / "a.json"), "--gyro",
         "gyro_x (deg/h),gyro_y (deg/h),gyro_z (deg/h)", "--time-unit", "s", "--latitude",
         "40", "--json"]
    )  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "no unit" not in err
    got = json.loads(out)
    sig = np.array(got["bias_deg_h_sigma"])
    assert np.all(np.abs(np.array(got["bias_deg_h"]) - np.array(truth["bias_deg_h"])) < 4 * sig)

    plain = pd.DataFrame({"time": rec.time_s, **rec.columns})
    plain.to_csv(tmp_path / "plain.csv", index=False)
    code = main(
        ["turntable", str(tmp_path / "plain.csv"), "-o", str(tmp_path / "b.json"),
         "--time-unit", "s", "--latitude", "40", "--json"]
    )  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "warning:" in err and "deg/s" in err
    assert json.loads(out)["bias_deg_h"] == pytest.approx(got["bias_deg_h"], rel=1e-6, abs=1e-9)
