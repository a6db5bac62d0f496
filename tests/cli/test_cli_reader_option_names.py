"""The readers' messages name the library's parameters (``topic``, ``names``, ``rate_hz``);
the command line shows its own options in their place, read from each command's option
declarations (``--topic``, declared first of ``--topic``/``--sensor``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from thermocal.cli import main
from thermocal.errors import ThermocalInputError
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions


def _csv(tmp_path: Path) -> Path:
    path = tmp_path / "run.csv"
    path.write_text("time,gx,T\n" + "".join(f"{i},{i % 3},25\n" for i in range(12)))
    return path


def _error(capsys: pytest.CaptureFixture[str], *args: str) -> list[str]:
    code = main(list(args))
    err = capsys.readouterr().err
    assert code == 2, err
    return [ln for ln in err.splitlines() if not ln.startswith("warning: ")]


def test_a_topic_for_a_csv_names_the_parameter_and_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _csv(tmp_path)
    text = f"{path}: topic is for flight-controller logs (.ulg, .bin) and station recordings"
    with pytest.raises(ThermocalInputError) as err:
        read_recording(path, ReadOptions(time_unit="s", topic="sensor_gyro"))
    assert str(err.value) == text
    for command in ("inspect", "allan"):  # both declare --topic then --sensor
        lines = _error(capsys, command, str(path), "--time-unit", "s", "--topic", "sensor_gyro")
        assert lines == ["error: " + text.replace("topic is", "--topic is")]


def test_names_for_a_file_with_a_header(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "log.txt"
    path.write_text("a;b;c\n" + "".join(f"{i};{i % 3};25\n" for i in range(12)))
    text = f"{path}: the file has a header row (a, b, c); names is for files without one"
    with pytest.raises(ThermocalInputError) as err:
        read_recording(path, ReadOptions(names=("t", "g", "T")))
    assert str(err.value) == text
    lines = _error(capsys, "inspect", str(path), "--names", "t,g,T")
    assert lines == ["error: " + text.replace("; names is", "; --names is")]
