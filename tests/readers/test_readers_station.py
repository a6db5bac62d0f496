"""The station folder's reader lives in :mod:`thermocal.readers.station` (issue 27): it reads
a folder built here by hand (not by the recorder), and it imports nothing of
:mod:`thermocal.station` (the drivers, the recorder).  The maths of the analysis commands
loads no file layer."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.errors import FileFormatError
from thermocal.readers.station import (
    closed_parts,
    is_station_path,
    read_station,
    read_station_json,
    station_files,
)
from thermocal.recording import META_KEY


def _folder(tmp: Path) -> Path:
    d = tmp / "rec"
    d.mkdir()
    doc = {"format": "thermocal-station", "version": 1, "config": {"sensors": [{"id": "imu1"}]}}
    (d / "station.json").write_text(json.dumps(doc), encoding="utf-8")
    for i, start in enumerate((0.0, 3.0)):
        t = pa.table({"time": [start, start + 1.0, start + 2.0], "gx": [i, i + 0.5, i + 1.0]})
        meta = {"time": "time", "units": {"gx": "deg/h"}, "part": i}  # the last part's wins
        t = t.replace_schema_metadata({META_KEY: json.dumps(meta)})
        pq.write_table(t, d / f"imu1-{i:04d}.parquet")
    pq.write_table(pa.table({"time": [9.0]}), d / ".imu1-0002.parquet.tmp")  # being written
    pq.write_table(pa.table({"time": [0.0]}), d / "chamber-0000.parquet")
    return d


def test_reader_concatenates_the_closed_parts_in_order(tmp_path: Path) -> None:
    d = _folder(tmp_path)
    assert [(s, i) for s, i, _p in closed_parts(d)] == [("chamber", 0), ("imu1", 0), ("imu1", 1)]
    assert [p.name for p in station_files(d)] == ["imu1-0000.parquet", "imu1-0001.parquet"]
    table, meta = read_station(d)  # the only sensor
    np.testing.assert_array_equal(table["time"].to_numpy(), [0, 1, 2, 3, 4, 5])
    np.testing.assert_array_equal(table["gx"].to_numpy(), [0, 0.5, 1, 1, 1.5, 2])
    assert meta["units"] == {"gx": "deg/h"} and meta["part"] == 1
    assert read_station(d / "chamber")[0].num_rows == 1


def test_reader_names_what_is_missing(tmp_path: Path) -> None:
    d = _folder(tmp_path)
    assert is_station_path(d) and is_station_path(d / "imu1")
    assert not is_station_path(tmp_path) and not is_station_path(d / "station.json")
    with pytest.raises(FileFormatError, match="no sensor 'imu9'"):
        read_station(d / "imu9")
    (d / "station.json").write_text('{"format": "thermocal-station", "version": 99}')
    with pytest.raises(FileFormatError, match="newer thermocal"):
        read_station_json(d)


def test_the_recorder_uses_the_readers_names() -> None:
    import thermocal.readers.station as reader
    import thermocal.station.recorder as recorder

    assert recorder.read_station is reader.read_station
    assert recorder.closed_parts is reader.closed_parts
    assert recorder.STATION_JSON == reader.STATION_JSON == "station.json"


def _loaded(module: str, watched: list[str]) -> list[str]:
    code = f"import sys, {module}\nprint(','.join(m for m in {watched!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return [m for m in out.stdout.strip().split(",") if m]


def test_the_station_reader_imports_no_station_driver() -> None:
    assert _loaded("thermocal.readers.station", ["thermocal.station", "pyarrow"]) == []


ANALYSIS_MATHS = [
    "thermocal.stability.analysis",
    "thermocal.stability.family",
    "thermocal.stability.noise_model",
    "thermocal.multipos.calibrate",
    "thermocal.multipos.validate",
    "thermocal.multipos.simulate",
    "thermocal.simulate",
    "thermocal.metrics",
]
FILE_LAYER = [
    "pandas",
    "pyarrow",
    "thermocal.readers",
    "thermocal.writers",
    "thermocal.pipeline.model_file",
]


@pytest.mark.parametrize("module", ANALYSIS_MATHS)
def test_analysis_maths_loads_no_file_layer(module: str) -> None:
    assert _loaded(module, FILE_LAYER) == []
