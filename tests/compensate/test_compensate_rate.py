"""Files without a time column (the MPU-6050 logger's, ``tests/data/``): ``compensate`` of a
triad calibration takes ``--rate``, and every command that needs time points to it."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

DATA = Path(__file__).parents[1] / "data"


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


MPU = DATA / "imucalibration_mpu6050"


MPU_ARGS = ["--accel", "ax,ay,az", "--gyro", "gx,gy,gz", "--rate", "100", "--gravity", "9.81",
            "--accel-scale", "0.00006103515625,g", "--gyro-scale", "0.00763,deg/s",
            "--gyro-model", "scale"]  # fmt: skip


@pytest.fixture(scope="module")
def mpu_cal(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The MPU-6050 session calibrated as its README says (±2 g, ±250 °/s, 100 Hz)."""
    cal = tmp_path_factory.mktemp("mpu") / "mpu.json"
    code, _, err = _run(["multipos", str(MPU / "example_data_calibration.csv"),
                         "-o", str(cal), *MPU_ARGS])  # fmt: skip
    assert code == 0, err
    return cal


def test_compensate_takes_rate_for_a_triad_calibration(mpu_cal: Path, tmp_path: Path) -> None:
    """The held-out MPU file has no time column; ``validate … --rate 100`` reads it, but
    ``compensate … --rate 100`` of the same calibration said ``no time column 'time'``
    (the text options were dropped on the triads' path).  The compensated x rate,
    integrated, is the authors' +90° turn (their README), within 1°."""
    out = tmp_path / "comp.csv"
    code, _, err = _run(["compensate", str(mpu_cal), str(MPU / "imu_90_x_rot.csv"),
                         "-o", str(out), "--rate", "100"])  # fmt: skip
    assert code == 0, err
    raw = np.loadtxt(MPU / "imu_90_x_rot.csv", delimiter=",", skiprows=5)
    got = np.genfromtxt(out, delimiter=",", names=True)
    assert got.size == raw.shape[0]
    assert np.array_equal(got["gx"], raw[:, 3])
    assert np.diff(got["time"]) == pytest.approx(0.01)
    assert float(np.sum(got["gx_comp"]) * 0.01) == pytest.approx(90.0, abs=1.0)


def test_a_missing_time_column_points_to_rate(mpu_cal: Path, tmp_path: Path) -> None:
    """The MPU-6050 logger's files have no time column and a banner ``Fs,100``.  ``inspect``
    and ``validate`` said "give --rate HZ" without the rate the file states; ``compensate``
    said only "no time column 'time'; available: …" (no way forward)."""
    held_out = MPU / "imu_90_x_rot.csv"
    for args in (["inspect", str(held_out)], ["validate", str(mpu_cal), str(held_out)]):
        code, _, err = _run(args)
        assert code == 2, err
        assert "(the file's banner says 'Fs,100': give --rate 100)" in err, err
    code, _, err = _run(["compensate", str(mpu_cal), str(held_out), "-o", str(tmp_path / "c.csv")])
    assert code == 2 and "no time column 'time'" in err and "--rate HZ" in err, err
