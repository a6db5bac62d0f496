"""The fit and validate path names the library's parameters; the command line its options.

A Python user of :func:`thermocal.pipeline.fit.fit_files`, :class:`ValidateOptions` or the
adequacy record reads the parameter (``latitude``, ``allow_narrow``, ``temp_conversion``);
``thermocal fit`` and ``thermocal validate`` print the same messages with their options in
place (``--latitude``, ``--allow-narrow``, ``--temp-conversion``), as before.
"""

from __future__ import annotations

import contextlib
import io
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.adequacy import ALLOW_NARROW, Adequacy, AdequacyTest
from thermocal.cli import main
from thermocal.errors import ParameterError, ThermocalInputError, ThermocalWarning
from thermocal.pipeline.fit import earth_rate_known_input, fit_files
from thermocal.pipeline.messages import error_text, warning_lines
from thermocal.pipeline.options import FitOptions, ValidateOptions
from thermocal.pipeline.validate import validate_files
from thermocal.readers.options import ReadOptions
from thermocal.units import TemperatureConversion


def _run(args: list[str]) -> tuple[int, str]:
    """The exit status and stderr of one command line."""
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(args)
    return code, err.getvalue()


@pytest.fixture
def run_csv(tmp_path: Path) -> Path:
    """A gyro run over a 40 °C sweep: bias 0.02 °/h/°C (a line), seeded noise."""
    rng = np.random.default_rng(0)
    t = np.arange(0.0, 4000.0, 1.0)
    temp = 10.0 + 40.0 * t / t[-1]
    gx = 0.02 * (temp - 25.0) + 1e-3 * rng.standard_normal(t.size)
    path = tmp_path / "run.csv"
    pd.DataFrame({"time_s": t, "gx": gx, "T1": temp}).to_csv(path, index=False)
    return path


def test_earth_rate_names_latitude_and_axis() -> None:
    with pytest.raises(ThermocalInputError) as info:
        earth_rate_known_input(45.0, None, "deg/h", "run.csv")
    assert str(info.value) == "earth-rate removal needs both latitude and axis"
    assert error_text(info.value) == ("earth-rate removal needs both --latitude and --axis", True)
    with pytest.raises(ThermocalInputError) as info:
        earth_rate_known_input(45.0, "up", "mg", "run.csv")
    assert str(info.value).startswith("run.csv: latitude/axis remove the earth rate")


@pytest.mark.parametrize(
    ("options", "python", "cli_args", "cli"),
    [
        ({"latitude": 200.0}, "latitude must be within ±90°, got 200.0",
         ["--latitude", "200"], "error: --latitude must be within ±90°, got 200.0"),
        ({"known_input": float("nan")}, "known_input must be a finite number, got nan",
         ["--known-input", "nan"], "error: --known-input must be a finite number, got nan"),
        ({"tref": 25.0, "model": "piecewise"},
         "tref applies to the poly family (coefficients about TREF), not 'piecewise'",
         ["--tref", "25", "--model", "piecewise"],
         "error: --tref applies to the poly family (coefficients about TREF), not 'piecewise'"),
    ],
)  # fmt: skip
def test_a_bad_fit_option_names_the_parameter_and_the_cli_the_option(
    run_csv: Path, tmp_path: Path, options: dict, python: str, cli_args: list[str], cli: str
) -> None:
    model = options.pop("model", "poly")
    with pytest.raises(ParameterError) as info:
        fit_files(
            [run_csv],
            FitOptions(model, signals=("gx",), signal_unit="deg/h", **options),
            tmp_path / "m.json",
        )
    assert str(info.value) == python
    base = [
        "fit",
        str(run_csv),
        "--signal",
        "gx",
        "--signal-unit",
        "deg/h",
        "-o",
        str(tmp_path / "c.json"),
    ]
    code, err = _run([*base, *([] if "--model" in cli_args else ["--model", "poly"]), *cli_args])
    assert code == 2 and err.strip() == cli, err
    assert not (tmp_path / "m.json").exists() and not (tmp_path / "c.json").exists()


def _narrow() -> AdequacyTest:
    """A temperature span of 0.3 °C against the 15 °C a cubic needs: fails, overridable."""
    return AdequacyTest("temperature_span", 0.3, 15.0, "°C", "fail", ALLOW_NARROW, "span 0.3 °C")


def test_the_adequacy_override_is_named_as_the_parameter() -> None:
    with pytest.raises(ThermocalInputError) as info:
        Adequacy((_narrow(),)).enforce()
    assert str(info.value) == (
        "the data cannot support this fit: span 0.3 °C (to fit anyway, knowingly: allow_narrow)"
    )
    assert error_text(info.value)[0].endswith("(to fit anyway, knowingly: --allow-narrow)")
    with pytest.warns(ThermocalWarning) as caught:
        Adequacy((_narrow(),), (ALLOW_NARROW,)).enforce()
    assert str(caught[0].message).startswith("span 0.3 °C — fitted anyway (allow_narrow):")
    assert warning_lines(caught)[0].startswith("span 0.3 °C — fitted anyway (--allow-narrow):")


def test_validate_options_are_typed() -> None:
    v = ValidateOptions(
        signals="gx, gy", names=["t", "gx", "gy", "T"], temp_conversion="0.0625,-50,int16",
        signal_unit=["deg/s", "deg/s"], rate_hz=100.0, decimal=",",
    )  # fmt: skip
    assert v.signals == ("gx", "gy") and v.names == ("t", "gx", "gy", "T")
    assert v.temp_conversion == TemperatureConversion(0.0625, -50.0, "int16")
    assert v.signal_unit == ("deg/s", "deg/s")
    assert ValidateOptions(signal_unit=["deg/h"]).signal_unit == "deg/h"
    assert v.read_options.signals == ("gx", "gy") and v.read_options.rate_hz == 100.0
    assert ValidateOptions().read_options == ReadOptions()
    with pytest.raises(ParameterError) as info:
        ValidateOptions(temp_conversion="0.0625")
    assert info.value.parameter == "temp_conversion"
    assert str(info.value).startswith("temp_conversion")


def test_a_ramp_rate_no_chamber_has_names_the_profile_parameters() -> None:
    from thermocal.profiles import builtin_profile

    with pytest.raises(ThermocalInputError) as info:
        builtin_profile("fog-slow", rate_c_per_min=1e300)
    assert "°C/min (rate_c_per_min, cycle_rate_c_per_min, rates_c_per_min): a chamber" in str(
        info.value
    )
    assert "°C/min (--rate, --cycle-rate, --rates): a chamber" in error_text(info.value)[0]


def test_validate_files_takes_paths_as_text(run_csv: Path, tmp_path: Path) -> None:
    """A notebook user's strings: the model judged on its own run (the line written into the
    data removed, so what is left is the seeded noise)."""
    model = tmp_path / "m.json"
    options = FitOptions(
        "poly", {"order": 1}, signals="gx", temperatures="T1", signal_unit="deg/h", temp_unit="degC"
    )
    fit_files([run_csv], options, model)
    v = ValidateOptions(signals=("gx",), signal_unit=("deg/h",), temp_unit="degC")
    with warnings.catch_warnings(record=True):  # the same run, no hold stages: said
        warnings.simplefilter("always")
        out = validate_files(str(model), str(run_csv), v).to_dict()
    # the sweep's line: 0.02 °/h/°C over a uniform 40 °C sweep has rms 0.02·40/√12 °/h
    assert out["rms_before"] == pytest.approx(0.02 * 40.0 / np.sqrt(12.0), rel=1e-3)
    # left: the white noise of 1e-3 °/h in 1 s samples, averaged over 100 s: 1e-4 °/h
    # (40 averages: the estimate's own scatter is about 11 %)
    assert out["rms_after"] == pytest.approx(1e-3 / np.sqrt(100.0), rel=0.25)
