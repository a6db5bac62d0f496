"""The report, fleet and station messages name the library's parameters, the command line
its options: ``str()`` of the error is what a Python user sees, :func:`error_text` what the
command line prints (the texts its tests assert, unchanged)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from thermocal.errors import ThermocalInputError
from thermocal.fleet.batch import check_scheduler
from thermocal.pipeline.messages import error_text
from thermocal.report.analysis import averaging_for
from thermocal.report.files import _check_counts


def test_report_counts_name_the_parameters() -> None:
    with pytest.raises(ThermocalInputError) as info:
        _check_counts([Path("a.json"), Path("b.json")], [Path("v.json")], [])
    assert str(info.value) == (
        "1 validations files for 2 models files; give one validation per model, in the same order"
    )
    assert error_text(info.value)[0] == (
        "1 --validation files for 2 --model files; give one validation per model, in the same order"
    )
    with pytest.raises(ThermocalInputError) as info:
        _check_counts([Path("a.json")], [], ["x", "y"])
    assert str(info.value) == "2 labels values for 1 models files"
    assert error_text(info.value) == ("2 --label values for 1 --model files", True)


def test_too_few_averages_names_averaging_s() -> None:
    """100 s at 1 Hz: two 50 s averages at most, so 60 s asked is refused naming 50 s."""
    t = np.arange(100.0)  # longest stretch without a gap: 100 samples × 1 s
    with pytest.raises(ThermocalInputError) as info:
        averaging_for(t, 60.0, given=True, where="run.csv", parameter="averaging_s")
    assert "give averaging_s 50 or less" in str(info.value)
    text, users = error_text(info.value)
    assert users and text.startswith("run.csv: ") and "give --average 50 or less" in text
    assert averaging_for(t, 50.0, given=True, where="run.csv", parameter="averaging_s") == (
        50.0,
        None,
    )


def test_scheduler_address_names_the_parameter() -> None:
    with pytest.raises(ThermocalInputError) as info:
        check_scheduler("not a url")
    assert str(info.value).startswith("scheduler 'not a url': not a scheduler address")
    assert error_text(info.value)[0].startswith("--scheduler 'not a url': not a scheduler")


def test_station_listen_time_names_the_parameter() -> None:
    from thermocal.station.check import check_station

    with pytest.raises(ThermocalInputError) as info:
        check_station(None, 0.0)  # type: ignore[arg-type]  # refused before the config is used
    assert str(info.value) == "listen_s must be > 0 s, got 0.0"
    assert error_text(info.value) == ("--listen must be > 0 s, got 0.0", True)
