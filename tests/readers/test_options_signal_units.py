"""One signal unit for every signal, or one per signal: the library takes a tuple
(``ReadOptions(signal_unit=("rad/s", "deg/s"))``), the command line splits its comma list
``--signal-unit rad/s,deg/s`` into that tuple, and a wrong number of units is refused naming
``signal_unit`` in the library and ``--signal-unit`` on the command line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from thermocal.cli import main
from thermocal.errors import UnitError
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions

GX = np.array([0.01, -0.02, 0.005, 0.0])  # [rad/s]
GY = np.array([1.5, -0.25, 3.0, 0.75])  # [deg/s]


def _two_gyros(tmp_path: Path) -> Path:
    path = tmp_path / "two.csv"
    rows = "".join(f"{0.01 * i},{x},{y},25\n" for i, (x, y) in enumerate(zip(GX, GY, strict=True)))
    path.write_text("t,gx,gy,T\n" + rows)
    return path


def test_a_tuple_states_one_unit_per_signal(tmp_path: Path) -> None:
    read = ReadOptions(
        time="t", time_unit="s", signals=("gx", "gy"), temperatures=("T",),
        signal_unit=["rad/s", "deg/s"], temp_unit="degC",
    )  # fmt: skip
    assert read.signal_unit == ("rad/s", "deg/s")  # a list is kept as a tuple
    rec = read_recording(_two_gyros(tmp_path), read)
    gx, ux = rec.signal("gx")
    gy, uy = rec.signal("gy")
    assert (ux, uy) == ("deg/h", "deg/h")
    # 1 rad/s = 180/π °/s = 180/π · 3600 °/h; 1 °/s = 3600 °/h
    assert_allclose(gx, GX * 180.0 / math.pi * 3600.0, rtol=1e-12)
    assert_allclose(gy, GY * 3600.0, rtol=1e-12)
    # one unit for both: a string, or a tuple of one
    for one in ("deg/s", ("deg/s",)):
        rec = read_recording(_two_gyros(tmp_path), read.replace(signal_unit=one))
        assert_allclose(rec.signal("gx")[0], GX * 3600.0, rtol=1e-12)


def test_a_wrong_number_of_units_names_the_parameter(tmp_path: Path) -> None:
    read = ReadOptions(
        time="t", time_unit="s", signals=("gx", "gy"), temperatures=("T",),
        signal_unit=("rad/s", "deg/s", "deg/s"), temp_unit="degC",
    )  # fmt: skip
    with pytest.raises(UnitError) as err:
        read_recording(_two_gyros(tmp_path), read)
    assert str(err.value) == (
        "signal_unit gives 3 units for 2 signals ('gx', 'gy'); give one unit, or one per signal"
    )
    with pytest.raises(ValueError, match="signal_unit holds one unit, or one per signal"):
        ReadOptions(signal_unit=("deg/s", 3))  # type: ignore[arg-type]


def test_the_command_line_splits_its_comma_list(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _two_gyros(tmp_path)
    common = ["--time", "t", "--time-unit", "s", "--temps", "T", "--temp-unit", "degC"]
    code = main(["inspect", str(path), "--signal", "gx,gy", *common,
                 "--signal-unit", "rad/s,deg/s,deg/s"])  # fmt: skip
    _out, err = capsys.readouterr()
    assert code == 2
    assert err.splitlines() == [
        "error: --signal-unit gives 3 units for 2 signals ('gx', 'gy'); give one unit, or one "
        "per signal"
    ]
    code = main(["inspect", str(path), "--signal", "gx,gy", *common,
                 "--signal-unit", "rad/s, deg/s", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    columns = json.loads(out)["columns"]
    assert (columns["gx"]["unit"], columns["gy"]["unit"]) == ("rad/s", "deg/s")
    assert columns["gx"]["max"] == pytest.approx(GX.max()) and columns["gy"]["max"] == 3.0
