"""``thermocal inspect`` of a simulated chamber run (:mod:`thermocal.inspection`): the chamber's
set-points are not called clipped."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

from thermocal.cli import main

DATA = Path(__file__).parents[1] / "data"


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


MPU = DATA / "imucalibration_mpu6050"


def test_inspect_does_not_call_a_chamber_setpoint_clipped(tmp_path: Path) -> None:
    """``thermocal simulate mems-imu`` then ``thermocal inspect`` of it: the chamber's
    setpoint holds −20 and +50 °C for hours, which the rail detector took for a clipped
    sensor ("setpoint_c has 14403 samples on its rails … rates and rotations across them
    are wrong").  Temperatures (by role or by unit) do not clip; the simulator's signals do
    not either (its truth), so nothing is on a rail.  A raw-count gyro on the int16 rails is
    still found (the MPU-6050 session, README: gx at rows 3910–3911 and 6662–6671)."""
    rec = tmp_path / "mems.parquet"
    assert _run(["simulate", "mems-imu", "-o", str(rec)])[0] == 0
    code, out, err = _run(["inspect", str(rec), "--json"])
    assert code == 0, err
    assert "rails" not in err and "saturated" not in out, err
    code, out, err = _run(["inspect", str(MPU / "example_data_calibration.csv"), "--rate", "100"])
    assert code == 0, err
    assert "column 'gx' has 12 samples on its rails" in out + err, out + err
