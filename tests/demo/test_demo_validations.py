"""``thermocal demo`` validates with the zero ``thermocal validate`` takes."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

from thermocal.cli import main


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


@pytest.mark.parametrize("imu", [False, True])
def test_demo_validations_take_the_zero_the_cli_takes(tmp_path: Path, imu: bool) -> None:
    """``thermocal demo`` validated with a zero of 0 where ``thermocal validate`` takes the
    known input: the RLG demo's "rms about zero" read 10.66 → 10.64 °/h (the earth rate on
    the up axis counted as error, +0.2 %), the IMU demo's az "error against the reference"
    997.6 → 1000 mg (gravity counted as error, −0.24 %).  The zero is now the simulator's
    own: the earth rate of its truth file, the 1 g of the IMU's up axis."""
    out = tmp_path / "demo"
    code, _, err = _run(["demo", "--quick", "-o", str(out), *(["--imu"] if imu else [])])
    assert code == 0, err
    if imu:
        truth = json.loads((out / "data" / "imu.truth.json").read_text(encoding="utf-8"))
        az = json.loads((out / "validation.json").read_text(encoding="utf-8"))["channels"]["az"]
        assert az["zero_reference"]["value"] == pytest.approx(truth["channels"]["az"]["gravity_mg"])
        assert az["rms_about_zero_after"] < 1.0 < az["rms_about_zero_before"]
    else:
        truth = json.loads((out / "data" / "rlg-validation.truth.json").read_text("utf-8"))
        val = json.loads((out / "validation" / "selected.json").read_text(encoding="utf-8"))
        omega = truth["earth_rate_on_axis_deg_h"]
        assert val["zero_reference"]["value"] == pytest.approx(omega, rel=1e-9)
        assert val["rms_about_zero_after"] < 0.2 < 1.0 < omega
