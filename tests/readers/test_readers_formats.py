"""The file-format registry: every built-in format found by its suffix (the longest that
matches) or its sniff function, a declaration no format can have refused naming its field."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from thermocal.errors import FileFormatError, ParameterError
from thermocal.outputs import TEMP_SUFFIX
from thermocal.readers.formats import (
    BUILT_IN,
    FileFormat,
    file_kind,
    format_named,
    format_of,
    registered_formats,
)
from thermocal.readers.options import ReadOptions


@pytest.mark.parametrize(
    ("name", "kind"),
    [
        ("a.csv", "csv"), ("A.CSV", "csv"), ("a.csv.gz", "csv"), ("a.txt", "csv"),
        ("a.log", "csv"), ("a.tsv", "csv"), ("a.dat", "csv"), ("a.parquet", "parquet"),
        ("a.pq", "parquet"), ("a.ulg", "ulog"), ("a.bin", "dataflash"),
    ],
)  # fmt: skip
def test_built_in_suffixes(name: str, kind: str) -> None:
    assert file_kind(name) == kind
    assert format_of(name).name == kind


def test_an_unknown_suffix_is_refused_naming_the_file() -> None:
    with pytest.raises(FileFormatError, match=r"^data\.xlsx: not a CSV or Parquet file"):
        format_of("data.xlsx")
    with pytest.raises(FileFormatError, match="unfinished output"):
        format_of("out.csv" + TEMP_SUFFIX)


def test_a_station_folder_is_sniffed_before_suffixes(tmp_path: Path) -> None:
    d = tmp_path / "run.csv"  # a folder with a suffix: station.json decides
    d.mkdir()
    (d / "station.json").write_text('{"format": "thermocal-station", "version": 1}')
    assert format_of(d).name == "station"


def test_which_formats_stream_and_take_a_topic() -> None:
    by = {f.name: f for f in registered_formats()}
    assert {n for n, f in by.items() if f.chunks == "stream"} == {"csv", "parquet", "station"}
    topics = {"ulog", "dataflash", "station", "rosbag"}
    assert {n for n, f in by.items() if "topic" in f.options} == topics
    assert "names" in by["csv"].options and "names" not in by["parquet"].options
    assert format_named("ulog").title == "a PX4 log"
    with pytest.raises(ParameterError, match="format 'xls' is not registered"):
        format_named("xls")
    assert registered_formats()[: len(BUILT_IN)] == BUILT_IN


def _read(path: Path, read: ReadOptions) -> tuple[pd.DataFrame, dict[str, object]]:
    return pd.DataFrame({"time": [0.0]}), {}


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"name": "my format"}, "name"),
        ({"suffixes": ("toy",)}, "suffixes"),
        ({"chunks": "sometimes"}, "chunks"),
        ({"chunks": "stream"}, "chunks"),  # stream needs head and stream
        ({"options": frozenset({"rate"})}, "options"),
    ],
)
def test_a_declaration_no_format_can_have_names_its_field(
    kwargs: dict[str, object], field: str
) -> None:
    args: dict[str, object] = {"name": "toy", "title": "a toy", "read": _read, **kwargs}
    with pytest.raises(ParameterError) as err:
        FileFormat(**args)  # type: ignore[arg-type]
    assert err.value.parameter == field


def test_suffixes_are_lower_case() -> None:
    fmt = FileFormat("toy", "a toy", _read, suffixes=(".TOY",))
    assert fmt.suffixes == (".toy",)
