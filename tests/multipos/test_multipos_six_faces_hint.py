"""A Ferraris session run without its section list (issue 38: a message with a way forward).

imucal's example session (six faces, then three turns that come back to faces) holds 13
still poses but only six distinct gravity directions, the six faces: fewer than the nine the
gravity-magnitude fit needs.  The refusal names the file and, as the six directions are the
body axes up and down, the ``--poses`` file that gives Ferraris's six-face closed form;
with it the same file calibrates (exit 0).  Six directions that are not the faces get no such
advice (the directions of the test's own poses, written here)."""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.errors import DesignError
from thermocal.multipos.accel import check_poses

DATA = Path(__file__).parents[1] / "data" / "imucal_ferraris"
SESSION = DATA / "example_ferraris_session.csv"
ARGS = ["--rate", "102.4", "--accel", "acc_x,acc_y,acc_z", "--accel-unit", "m/s^2",
        "--gyro", "gyr_x,gyr_y,gyr_z", "--gyro-unit", "deg/s", "--gravity", "9.81"]  # fmt: skip


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def test_six_faces_without_poses_file_names_the_file_and_the_option(tmp_path: Path) -> None:
    code, _out, err = _run(["multipos", str(SESSION), *ARGS, "-o", str(tmp_path / "c.json")])
    assert code == 2
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"error: {SESSION}: 6 distinct poses"), last
    assert "six faces" in last and "--poses" in last, last
    poses = DATA / "example_ferraris_session_list.json"
    code, _out, err = _run(
        ["multipos", str(SESSION), *ARGS, "--poses", str(poses), "-o", str(tmp_path / "c.json")]
    )
    assert code == 0, err


def test_six_directions_that_are_not_the_faces_get_no_face_advice() -> None:
    tilt = math.radians(35.0)
    dirs = [(math.cos(a) * math.sin(tilt), math.sin(a) * math.sin(tilt), math.cos(tilt))
            for a in np.linspace(0.0, 2 * math.pi, 6, endpoint=False)]  # fmt: skip
    with pytest.raises(DesignError) as info:
        check_poses(1000.0 * np.asarray(dirs))
    assert "6 distinct poses" in str(info.value) and "six faces" not in str(info.value)
