"""A column declared in raw counts whose values are not whole numbers gets a warning that
names the unit's own parameter: ``--accel-unit`` / ``--gyro-unit`` in multipos and tumble
(which have no ``--signal-unit``), ``accel_unit`` in the library's options, with units of the
sensor's kind; ``--signal-unit`` where that is the option (inspect)."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsens_session import run, write_session

MULTIPOS = ["--time", "t", "--time-unit", "s", "--accel", "ax,ay,az", "--accel-unit", "counts",
            "--accel-scale", "1,mg", "--gyro", "gx,gy,gz", "--gyro-unit", "deg/s",
            "--latitude", "45"]  # fmt: skip


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("counts")
    write_session(d, seed=5, a_deg_h_g=None)  # accelerometer in mg, not whole numbers
    return d / "s.csv"


def _count_warnings(err: str) -> list[str]:
    return [ln for ln in err.splitlines() if "is declared in counts" in ln]


def test_multipos_names_its_accel_unit(session: Path) -> None:
    code, _out, err = run(["multipos", str(session), *MULTIPOS, "-o",
                           str(session.parent / "cal.json")])  # fmt: skip
    assert code == 0, err
    said = _count_warnings(err)
    assert len(said) == 3, err  # ax, ay, az
    for line in said:
        assert "(--accel-unit mg, g, m/s^2, …)" in line, line
        assert "--signal-unit" not in line and "deg/s" not in line


def test_the_library_names_accel_unit(session: Path) -> None:
    from thermocal.errors import PlausibilityWarning
    from thermocal.pipeline.multipos import MultiposOptions, calibrate_files

    opts = MultiposOptions(("ax", "ay", "az"), None, accel_unit="counts", latitude_deg=45.0,
                           time="t", time_unit="s", accel_scale=(1.0, "mg"))  # fmt: skip
    with pytest.warns(PlausibilityWarning, match="is declared in counts") as caught:
        calibrate_files([session], session.parent / "lib.json", opts, None)
    said = [str(w.message) for w in caught if "is declared in counts" in str(w.message)]
    assert said and all("(accel_unit mg, g, m/s^2, …)" in s for s in said), said


def test_inspect_still_names_signal_unit(session: Path) -> None:
    code, out, err = run(["inspect", str(session), "--time", "t", "--time-unit", "s",
                          "--signal", "ax", "--signal-unit", "counts"])  # fmt: skip
    said = _count_warnings(out + err)  # inspect lists what it found on stdout
    assert code == 0 and len(said) == 1, out + err
    assert "(--signal-unit deg/s, mg, …)" in said[0]
