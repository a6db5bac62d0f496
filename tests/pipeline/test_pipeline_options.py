"""The options of a fit and a validation as typed values (:mod:`thermocal.pipeline.options`):
column lists as tuples, the temperature conversion parsed once, the target checked naming
its field, the reading fields as one :class:`~thermocal.readers.options.ReadOptions`, and a
fleet table's family options as constructor parameters."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from thermocal.cli import main
from thermocal.errors import ParameterError
from thermocal.pipeline.options import FitOptions, ValidateOptions, options_from_table
from thermocal.readers.options import ReadOptions
from thermocal.units import TemperatureConversion


def test_fit_options_hold_typed_values() -> None:
    o = FitOptions(
        "poly", {"order": 2}, signals="gx, gy", temperatures=["T1", "T2"],
        temp_conversion="0.0625,-50,int16", names="t,gx,gy,T1,T2", rate_hz=200.0,
    )  # fmt: skip
    assert o.signals == ("gx", "gy") and o.temperatures == ("T1", "T2")
    assert o.temp_conversion == TemperatureConversion(0.0625, -50.0, "int16")
    assert o.read_options == ReadOptions(
        signals=("gx", "gy"), temperatures=("T1", "T2"),
        temp_conversion=TemperatureConversion(0.0625, -50.0, "int16"),
        names=("t", "gx", "gy", "T1", "T2"), rate_hz=200.0,
    )  # fmt: skip
    assert FitOptions("poly", signals="").signals is None  # no name: the file's signal
    v = ValidateOptions(signals="gz", rate_hz=50.0, on_bad_lines="skip", decimal=",")
    assert v.read_options == ReadOptions(
        signals=("gz",), rate_hz=50.0, on_bad_lines="skip", decimal=","
    )


def test_a_bad_value_names_the_field_and_the_cli_its_option(tmp_path: Path) -> None:
    with pytest.raises(ParameterError) as info:
        FitOptions("poly", target="drift")  # type: ignore[arg-type]
    assert info.value.parameter == "target"
    assert str(info.value) == "target must be bias or scale_factor, got 'drift'"
    with pytest.raises(ParameterError) as info:
        FitOptions("poly", temp_conversion="0,1")  # type: ignore[arg-type]
    assert info.value.parameter == "temp_conversion"
    assert str(info.value).startswith("temp_conversion gain must be finite and non-zero")
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(["fit", str(tmp_path / "a.csv"), "--model", "poly", "--temp-conversion",
                     "x", "-o", str(tmp_path / "m.json")])  # fmt: skip
    assert code == 2
    assert err.getvalue().strip() == (
        "error: --temp-conversion takes 'GAIN,OFFSET' or 'GAIN,OFFSET,int16' "
        "(T[°C] = GAIN·counts + OFFSET), got 'x'"
    )


def test_a_fleet_table_gives_the_family_parameters() -> None:
    table = {"model": "piecewise", "breakpoints": [25, 30], "per_run_offset": False,
             "signal": "gx", "temps": ["T1"], "rate": 100}  # fmt: skip
    opts, args = options_from_table("fit", table, "cfg [fit]")
    assert opts == FitOptions(
        "piecewise", {"breakpoints": (25.0, 30.0), "per_run_offset": False},
        signals=("gx",), temperatures=("T1",), rate_hz=100.0,
    )  # fmt: skip
    assert args == ["--model", "piecewise", "--breakpoints", "25,30", "--no-per-run-offset",
                    "--signal", "gx", "--temps", "T1", "--rate", "100"]  # fmt: skip
