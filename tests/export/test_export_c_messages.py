"""``thermocal export-c`` as a user meets it: a session without a temperature column invents
none, and the known input of a count signal is stated in its physical unit."""

from __future__ import annotations

import contextlib
import io
import json
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


def test_export_c_of_a_session_without_temperature_invents_none(
    mpu_cal: Path, tmp_path: Path
) -> None:
    """The MPU-6050 session has no temperature column; the report says "calibrated without
    a temperature column: the parameters apply unchanged at every temperature", but the C
    header said "calibrated at 25 degC" (the model's placeholder reference, measured by
    nobody).  It compiles with -Wall -Werror -pedantic either way
    (tests/export/test_export_c_readable.py)."""
    code, _, err = _run(["export-c", str(mpu_cal), "-o", str(tmp_path / "c")])
    assert code == 0, err
    header = (tmp_path / "c" / "mpu.h").read_text(encoding="utf-8")
    assert "degC" not in header and "calibrated at" not in header, header
    assert header.count("no temperature column (none measured)") == 2, header


def test_known_input_of_a_count_signal_is_in_its_physical_unit(tmp_path: Path) -> None:
    """``simulate rlg-modelling`` writes RLG counts with a scale factor (4 counts/″);
    ``fit --latitude 45 --axis up`` takes Ω_up = 15.041067 °/h · sin 45° = 10.6356 °/h off,
    but the model file recorded it as "10.6356 counts" and the C header said "10.6356
    counts removed before the fit" (a count is 0.25″, not 1 °/h)."""
    mod = tmp_path / "m.parquet"
    assert _run(["simulate", "rlg-modelling", "-o", str(mod)])[0] == 0
    cal = tmp_path / "m.json"
    assert _run(["fit", str(mod), "-o", str(cal), "--model", "poly",
                 "--latitude", "45", "--axis", "up"])[0] == 0  # fmt: skip
    ki = json.loads(cal.read_text(encoding="utf-8"))["inputs"]["known_input"]
    omega_up = 15.041067 * np.sin(np.radians(45.0))
    assert ki["unit"] == "deg/h" and ki["value"] == pytest.approx(omega_up, rel=1e-5), ki
    code, _, err = _run(["export-c", str(cal), "-o", str(tmp_path / "c")])
    assert code == 0, err
    header = (tmp_path / "c" / "m.h").read_text(encoding="utf-8")
    assert "counts removed before the fit" not in header
    assert f"{omega_up:.6g}" in header and "deg/h) removed before the fit" in header, header
