"""ReadOptions: the one object that says how a file is read; its errors name its fields,
and the command line names its options in their place."""

from __future__ import annotations

import pickle

import pytest

from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.pipeline.messages import error_text, option_name
from thermocal.readers.options import ReadOptions
from thermocal.units import TemperatureConversion


def test_names_and_conversion_are_normalised() -> None:
    opts = ReadOptions(signals="gx, gy ,gz", temperatures=["T1"], temp_conversion="0.0625,-50")
    assert opts.signals == ("gx", "gy", "gz")
    assert opts.temperatures == ("T1",)
    assert opts.temp_conversion == TemperatureConversion(0.0625, -50.0)
    assert not opts.text_layout_given
    assert ReadOptions(rate_hz=100.0).text_layout_given


@pytest.mark.parametrize(
    ("kwargs", "parameter", "option"),
    [
        ({"rate_hz": 0.0}, "rate_hz", "--rate"),
        ({"rate_hz": float("nan")}, "rate_hz", "--rate"),
        ({"rate_hz": 1e9}, "rate_hz", "--rate"),
        ({"on_bad_lines": "ignore"}, "on_bad_lines", "--on-bad-lines"),
        ({"decimal": ";"}, "decimal", "--decimal"),
        ({"names": "a,b,a"}, "names", "--names"),
    ],
)
def test_errors_name_the_parameter_and_the_cli_the_option(
    kwargs: dict[str, object], parameter: str, option: str
) -> None:
    with pytest.raises(ParameterError) as err:
        ReadOptions(**kwargs)  # type: ignore[arg-type]
    assert err.value.parameter == parameter
    assert str(err.value).startswith(parameter + " ")
    assert option_name(parameter) == option
    text, users = error_text(err.value)
    assert users and text.split()[0] == option


def test_parameter_error_is_an_input_error_and_pickles() -> None:
    err = ParameterError("rate_interval", "{name} must be positive, got -3")
    assert isinstance(err, ThermocalInputError)
    back = pickle.loads(pickle.dumps(err))
    assert str(back) == "rate_interval must be positive, got -3"
    assert error_text(back) == ("--rate-interval must be positive, got -3", True)


def test_replace_checks_again() -> None:
    opts = ReadOptions(time="t")
    assert opts.replace(time_unit="ms").time_unit == "ms"
    with pytest.raises(ParameterError):
        opts.replace(rate_hz=-1.0)
