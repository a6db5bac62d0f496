"""Noise terms and their warnings as a user meets them: white noise read away from a sinusoid,
a moving record warned, a unit the command does not know asked for."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

DATA = Path(__file__).parents[1] / "data"


FERRARIS = DATA / "imucal_ferraris" / "example_ferraris_session.csv"


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


MPU = DATA / "imucalibration_mpu6050"


def test_white_noise_read_away_from_a_sinusoid(tmp_path: Path) -> None:
    """A static accelerometer record [mg] at 100 Hz, 1 h: white noise of N = 0.05 mg·√s
    (50 µg/√Hz) and a 0.56 Hz sinusoid of 0.5 mg (the issue's real MEMS IMU).  ``allan``
    named the sinusoid but read N on a "−½ stretch" τ = 41 … 655 s where the sinusoid's
    ADEV envelope A/(πf₀τ) still holds a third of the variance: 53.8 µg/√Hz (+7.6 %), and
    called the clean white points τ = 0.01 … 0.04 s, which lie exactly on the truth,
    "below the −½ line (the sensor's own filter)".  Truth: the simulation's N (IEEE 952
    C.1.2: σ(τ) = N/√τ)."""
    rng = np.random.default_rng(38)
    fs, n_white, amp = 100.0, 0.05, 0.5
    t = np.arange(int(3600 * fs)) / fs
    y = n_white * np.sqrt(fs) * rng.standard_normal(t.size) + amp * np.sin(2 * np.pi * 0.56 * t)
    path = tmp_path / "acc.csv"
    np.savetxt(path, np.column_stack([t, y]), delimiter=",", header="time [s],az [mg]",
               comments="", fmt=["%.2f", "%.8g"])  # fmt: skip
    code, out, err = _run(["allan", str(path), "--signal", "az [mg]", "--json"])
    assert code == 0, err
    d = json.loads(out)
    (p,) = d["periodic"]
    assert abs(p["frequency_hz"] - 0.56) <= p["resolution_hz"]
    arw = d["noise_slope"]["angle_random_walk"]
    assert arw["unit"] == "ug/sqrt(Hz)"
    assert arw["value"] == pytest.approx(1e3 * n_white, rel=0.02), arw
    assert d["shaped_below_s"] is None  # no filter in this record


def test_noise_of_a_moving_record_is_warned(tmp_path: Path) -> None:
    """``thermocal noise`` on imucal's calibration session (six faces and three 360° turns)
    wrote a Kalibr file with warnings about bounds only, and called the accelerometer's
    white-noise term the "angle random walk".  The motion is now said (the faces: the
    accelerometer's direction turns by 90° and more, written in the session list), the term
    by its accelerometer name; a static record is not warned (the simulated one above)."""
    base = ["noise", str(FERRARIS), "--rate", "102.4", "--gyro", "gyr_x,gyr_y,gyr_z",
            "--gyro-unit", "deg/s"]  # fmt: skip
    code, _, err = _run([*base, "--accel", "acc_x,acc_y,acc_z", "--accel-unit", "m/s^2",
                         "-o", str(tmp_path / "n.yaml")])  # fmt: skip
    assert code == 0, err
    assert "the sensor moves during the record (the accelerometer's direction turns" in err
    assert "[acc_x]: angle random walk" not in err and "[acc_x]: velocity random walk" in err
    code, _, err = _run([*base, "--format", "json", "-o", str(tmp_path / "n.json")])
    assert code == 0, err
    assert "the sensor moves during the record (the gyro's rate departs" in err, err
    rng = np.random.default_rng(5)
    t = np.arange(60_000) / 100.0
    g = rng.standard_normal((t.size, 3)) * 0.05
    a = rng.standard_normal((t.size, 3)) * 2.0 + [0.0, 0.0, 1000.0]
    path = tmp_path / "still.csv"
    head = "time [s],gx [deg/s],gy [deg/s],gz [deg/s],ax [mg],ay [mg],az [mg]"
    np.savetxt(path, np.column_stack([t, g, a]), delimiter=",", comments="", header=head)
    code, _, err = _run(["noise", str(path), "--gyro", "gx [deg/s],gy [deg/s],gz [deg/s]",
                         "--accel", "ax [mg],ay [mg],az [mg]",
                         "-o", str(tmp_path / "s.yaml")])  # fmt: skip
    assert code == 0, err
    assert "moves" not in err, err


def test_noise_asks_for_the_unit_it_does_not_know(tmp_path: Path) -> None:
    """``noise`` on the MPU-6050 logger's bare ``ax,…,gz`` columns warned "no unit stated
    for the signal column … assuming deg/h (give --signal-unit …)" — an option ``noise``
    does not have, and deg/h for an accelerometer — then failed with "ax: a accelerometer
    column in 'deg/h'".  It now asks for the unit by the option it has, as multipos does."""
    code, _, err = _run(["noise", str(MPU / "imu_90_x_rot.csv"), "--rate", "100",
                         "--gyro", "gx,gy,gz", "--accel", "ax,ay,az",
                         "-o", str(tmp_path / "n.yaml")])  # fmt: skip
    assert code == 2 and "--signal-unit" not in err and "assuming" not in err, err
    (line,) = [ln for ln in err.splitlines() if ln.startswith("error: ")]
    assert "no unit stated for column 'gx'; give --gyro-unit" in line, line
