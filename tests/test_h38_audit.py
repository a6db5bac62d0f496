"""Issue 38, tried as a new user would (the audit): each test reproduces one problem found by
running the CLI on the shipped public sessions (``tests/data/``) or on simulated records, in
the order a user meets it, and holds its fix."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

from thermocal.cli import main

DATA = Path(__file__).parent / "data"
FERRARIS = DATA / "imucal_ferraris" / "example_ferraris_session.csv"


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def test_multipos_one_unit_given_asks_for_the_other(tmp_path: Path) -> None:
    """imucal's columns state no unit.  A user who gives ``--gyro-unit deg/s`` alone was told
    ``no unit stated for column 'acc_x'; give --accel-unit`` — right — but one who gives
    ``--accel-unit m/s^2`` alone was told the same about 'acc_x' (the option was dropped
    unless both were given): the message must name the gyro's column and option."""
    base = ["multipos", str(FERRARIS), "-o", str(tmp_path / "c.json"), "--rate", "102.4",
            "--accel", "acc_x,acc_y,acc_z", "--gyro", "gyr_x,gyr_y,gyr_z",
            "--gravity", "9.81"]  # fmt: skip
    code, _, err = _run([*base, "--accel-unit", "m/s^2"])
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("error: "), err
    assert "'gyr_x'" in err and "--gyro-unit" in err, err
    code, _, err = _run([*base, "--gyro-unit", "deg/s"])
    assert code == 2
    assert "'acc_x'" in err and "--accel-unit" in err, err
