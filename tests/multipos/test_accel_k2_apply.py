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
import pytest

from k2_session import COLS, K2, add_k2, calibrate, held_out, pose_residuals, simulate
from thermocal.cli import main
from thermocal.models.calibration import Calibration
from thermocal.models.format import checksum
from thermocal.multipos.accel_k2 import invert_k2
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


def test_validate_judges_with_k2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``validate`` inverts K2 as ``compensate`` does: the held-out poses' gravity error
    after compensation equals the residual of the compensated file computed here."""
    files = simulate(tmp_path)
    add_k2(files)
    calibrate(files, tmp_path / "cal.json", "--accel-k2")
    held = held_out(files)
    compensate_calibration_file(tmp_path / "cal.json", held["file"], tmp_path / "with.csv")
    want = _rms(pose_residuals(tmp_path / "with.csv", held))
    capsys.readouterr()
    assert main(["validate", str(tmp_path / "cal.json"), held["file"], "--json"]) == 0
    got = json.loads(capsys.readouterr().out)["triads"]["accel"]["rms_after"]
    assert got == pytest.approx(want, rel=0.05)  # its own pose detection: 2.29e-3 both


def test_invert_k2_to_1e12() -> None:
    """Newton's three steps against the forward model written here: |K2| = 0.01 g/g² on
    forces up to 4 g, a misalignment of 3e-3; recovered to 1e-12 relative."""
    rng = np.random.default_rng(3)
    a = rng.normal(size=(5000, 3))
    a *= rng.uniform(0.0, 4.0, (5000, 1)) / np.linalg.norm(a, axis=1)[:, None]
    m = np.eye(3) + rng.normal(0.0, 3e-3, (3, 3))
    k2 = np.array([0.01, -0.01, 0.007])  # g per g²
    y = a @ m.T + k2 * a**2
    got = invert_k2(y, m, k2, 1.0)
    assert np.max(np.abs(got - a)) < 4e-12
    # in mg: the same a scaled
    np.testing.assert_allclose(invert_k2(y * 1e3, m, k2 * 1e3, 1e3), a * 1e3, rtol=0, atol=4e-9)


def test_k2_on_a_gyro_triad_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A hand-made calibration with K2 on the gyro triad: ``compensate`` exits 2 with one
    ``error:`` line naming it, and writes nothing."""
    files = simulate(tmp_path)
    cal = tmp_path / "cal.json"
    assert main(["multipos", files[0]["file"], "-o", str(cal), "--accel", ",".join(COLS),
                 "--gyro", "gyro_x,gyro_y,gyro_z"]) == 0  # fmt: skip
    d = json.loads(cal.read_text())
    gyro = next(t for t in d["triads"] if t["name"] == "gyro")
    gyro.update(k2=[1.0, 0.0, 0.0], k2_sigma=[0.1] * 3, k2_unit=f"{gyro['unit']}/g^2")
    d.update(format_version=4)
    d.pop("checksum")
    d["checksum"] = checksum(d)
    cal.write_text(json.dumps(d))
    capsys.readouterr()
    out = tmp_path / "out.csv"
    assert main(["compensate", str(cal), files[0]["file"], "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:"), err
    assert "k2 belongs to an accelerometer triad, not a gyro" in err[0]
    assert not out.exists()
