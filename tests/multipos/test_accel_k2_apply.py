"""K2 stored by ``thermocal multipos --accel-k2`` and applied by ``compensate``: a simulated
session given a known K2 per axis (the simulator's truth, K2 added here as
``K2 ⊙ (f/g)²``), calibrated, then the held-out session (same K2) compensated: the poses'
compensated |f| equal the simulator's gravity as closely as a session without K2 calibrated
without it (the noise floor, measured first), and not with the same calibration's K2 left
out (residuals computed here from the truth's pose sections)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pandas as pd

from thermocal.cli import main
from thermocal.models.calibration import Calibration
from thermocal.pipeline.compensate import compensate_calibration_file
from thermocal.pipeline.model_file import load_calibration, save_calibration

COLS = ["accel_x", "accel_y", "accel_z"]
K2 = np.array([0.05, -0.04, 0.03])  # m/s² per g², the simulated truth


def _sessions(tmp: Path) -> tuple[list[dict], float]:
    """The simulated sessions with K2 added, and the held-out session's pose residual rms
    [m/s²] without any K2 (simulated, calibrated and compensated without it)."""
    assert main(["simulate", "multipos", "-o", str(tmp / "mp"), "--truth",
                 str(tmp / "t.json"), "--seed", "4"]) == 0  # fmt: skip
    files = json.loads((tmp / "t.json").read_text())["files"]
    held = next(f for f in files if f["held_out"])
    assert main(["multipos", files[0]["file"], "-o", str(tmp / "c0.json"), "--accel",
                 ",".join(COLS)]) == 0  # fmt: skip
    compensate_calibration_file(tmp / "c0.json", held["file"], tmp / "floor.csv")
    floor = _pose_residuals(tmp / "floor.csv", held)
    for truth in files:
        p = Path(truth["file"])
        df = pd.read_csv(p)
        f = df[COLS].to_numpy()
        df[COLS] = f + K2 * (f / truth["gravity_m_s2"]) ** 2
        df.to_csv(p, index=False)
    return files, float(np.sqrt(np.mean(floor**2)))


def _pose_residuals(out: Path, truth: dict) -> np.ndarray:
    """Each pose's mean compensated |f| less the simulator's gravity [m/s²]."""
    df = pd.read_csv(out)
    f = df[[f"{c}_comp" for c in COLS]].to_numpy()
    poses = json.loads(truth["poses"]) if isinstance(truth["poses"], str) else truth["poses"]
    means = np.array([np.linalg.norm(f[a:b].mean(axis=0)) for a, b in poses])
    return means - truth["gravity_m_s2"]


def test_k2_stored_and_applied(tmp_path: Path) -> None:
    files, floor = _sessions(tmp_path)
    cal_path = tmp_path / "cal.json"
    assert main(["multipos", files[0]["file"], "-o", str(cal_path), "--accel",
                 ",".join(COLS), "--accel-k2"]) == 0  # fmt: skip
    d = json.loads(cal_path.read_text())
    acc = d["triads"][0]
    assert d["format_version"] == 4 and acc["k2_unit"] == "m/s^2/g^2"
    for v, e, t in zip(acc["k2"], acc["k2_sigma"], K2, strict=True):
        assert abs(v - t) < 3 * e
    held = next(f for f in files if f["held_out"])
    compensate_calibration_file(cal_path, held["file"], tmp_path / "with.csv")
    with_k2 = _pose_residuals(tmp_path / "with.csv", held)
    cal = load_calibration(cal_path)
    plain = Calibration(cal.channels, [dataclasses.replace(cal.triads[0], k2=None, k2_sigma=None)])
    save_calibration(plain, tmp_path / "plain.json")
    compensate_calibration_file(tmp_path / "plain.json", held["file"], tmp_path / "without.csv")
    without = _pose_residuals(tmp_path / "without.csv", held)
    rms_with, rms_without = np.sqrt(np.mean(with_k2**2)), np.sqrt(np.mean(without**2))
    # measured: floor 1.45e-3, with K2 2.29e-3 (twelve parameters from 16 poses), without
    # 2.21e-2 m/s²
    assert floor < 2e-3
    assert rms_with < 2 * floor
    assert rms_without > 10 * floor
