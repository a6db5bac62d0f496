"""K2 stored by ``thermocal multipos --accel-k2`` and applied by ``compensate``: a simulated
session given a known K2 per axis (the simulator's truth, K2 added as ``K2 ⊙ (f/g)²``),
calibrated, then the held-out session (same K2) compensated: the poses' compensated |f|
equal the simulator's gravity as closely as a session without K2 calibrated without it (the
noise floor, measured first), and not with the same calibration's K2 left out (residuals
computed here from the truth's pose sections)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np

from k2_session import K2, add_k2, calibrate, held_out, pose_residuals, simulate
from thermocal.models.calibration import Calibration
from thermocal.pipeline.compensate import compensate_calibration_file
from thermocal.pipeline.model_file import load_calibration, save_calibration


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x**2)))


def test_k2_stored_and_applied(tmp_path: Path) -> None:
    files = simulate(tmp_path)
    held = held_out(files)
    calibrate(files, tmp_path / "c0.json")
    compensate_calibration_file(tmp_path / "c0.json", held["file"], tmp_path / "floor.csv")
    floor = _rms(pose_residuals(tmp_path / "floor.csv", held))
    add_k2(files)
    cal_path = tmp_path / "cal.json"
    calibrate(files, cal_path, "--accel-k2")
    d = json.loads(cal_path.read_text())
    acc = d["triads"][0]
    assert d["format_version"] == 4 and acc["k2_unit"] == "m/s^2/g^2"
    for v, e, t in zip(acc["k2"], acc["k2_sigma"], K2, strict=True):
        assert abs(v - t) < 3 * e
    compensate_calibration_file(cal_path, held["file"], tmp_path / "with.csv")
    rms_with = _rms(pose_residuals(tmp_path / "with.csv", held))
    cal = load_calibration(cal_path)
    plain = Calibration(cal.channels, [dataclasses.replace(cal.triads[0], k2=None, k2_sigma=None)])
    save_calibration(plain, tmp_path / "plain.json")
    compensate_calibration_file(tmp_path / "plain.json", held["file"], tmp_path / "without.csv")
    rms_without = _rms(pose_residuals(tmp_path / "without.csv", held))
    # measured: floor 1.45e-3, with K2 2.29e-3 (twelve parameters from 16 poses), without
    # 2.21e-2 m/s²
    assert floor < 2e-3
    assert rms_with < 2 * floor
    assert rms_without > 10 * floor
