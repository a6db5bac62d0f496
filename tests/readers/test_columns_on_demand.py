"""A Parquet file's columns read on demand (``read_recording(columns_on_demand=True)``):
the same values, names, units and refusals as a whole read, one column held at a time."""

from __future__ import annotations

import json
import weakref
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.errors import MissingValueError
from thermocal.readers import ReadOptions, read_recording
from thermocal.readers.table import ColumnsOnDemand, ParquetColumns


def _file(tmp_path: Path, nan_in: str | None = None) -> Path:
    """Time, a gyro, four temperatures, an int16 counter and a text column, written by
    pyarrow in several row groups."""
    rng = np.random.default_rng(0)
    n = 5000
    t = np.arange(n) * 0.01
    cols: dict[str, object] = {"time": t, "gyro": rng.normal(0.5, 0.05, n)}
    for k in range(4):
        cols[f"T{k + 1}"] = 25.0 + 10.0 * np.sin(t / 20.0 + k) + rng.normal(0, 0.01, n)
    cols["count"] = pa.array((np.arange(n) % 30000).astype(np.int16))
    cols["note"] = pa.array(["x"] * n)
    if nan_in is not None:
        v = np.array(cols[nan_in], dtype=np.float64)
        v[1234] = np.nan
        cols[nan_in] = v
    meta = {"time": "time", "time_unit": "s", "signals": {"gyro": "deg/h"},
            "temperatures": {f"T{k + 1}": "degC" for k in range(4)}}  # fmt: skip
    table = pa.table(cols).replace_schema_metadata({"thermocal": json.dumps(meta)})
    path = tmp_path / "run.parquet"
    pq.write_table(table, path, row_group_size=1500)
    return path


def test_values_names_and_units_equal_pyarrows_and_a_whole_read(tmp_path: Path) -> None:
    path = _file(tmp_path)
    skipped_lazy: list[str] = []
    skipped_whole: list[str] = []
    lazy = read_recording(path, skipped=skipped_lazy, columns_on_demand=True)
    whole = read_recording(path, skipped=skipped_whole)
    assert isinstance(lazy.columns, ColumnsOnDemand)
    assert list(lazy.columns) == list(whole.columns) == [
        "gyro", "T1", "T2", "T3", "T4", "count"
    ]  # fmt: skip
    assert skipped_lazy == skipped_whole == ["note"]
    assert lazy.units == whole.units and lazy.signals == whole.signals
    assert lazy.temperatures == whole.temperatures
    table = pq.read_table(path)  # the reference: pyarrow's own values
    np.testing.assert_array_equal(lazy.time_s, table.column("time").to_numpy())
    for name in lazy.columns:
        expected = table.column(name).to_numpy().astype(np.float64)
        np.testing.assert_array_equal(lazy.columns[name], expected)
        assert lazy.columns[name].dtype == np.float64
    np.testing.assert_array_equal(
        lazy.temperatures_c(), np.column_stack([table.column(f"T{k}") for k in range(1, 5)])
    )


def test_one_column_held_at_a_time(tmp_path: Path) -> None:
    rec = read_recording(_file(tmp_path), columns_on_demand=True)
    first = weakref.ref(rec.columns["T1"])
    assert first() is rec.columns["T1"]  # kept while it is the last read
    second = rec.columns["T2"]
    assert first() is None  # released once another column is read
    assert rec.columns["T2"] is second  # the last one is not read again


def test_a_column_assigned_is_kept_as_given(tmp_path: Path) -> None:
    path = _file(tmp_path)
    cols = ColumnsOnDemand(ParquetColumns(pq.ParquetFile(path)), path)
    cols.add("gyro")
    given = np.arange(3.0)
    cols["extra"] = given
    cols["gyro"]  # another column read in between
    assert cols["extra"] is given and list(cols) == ["gyro", "extra"]
    del cols["extra"]
    assert "extra" not in cols and len(cols) == 1
    with pytest.raises(KeyError):
        cols["T1"]


def test_a_nan_in_a_temperature_refused_as_by_a_whole_read(tmp_path: Path) -> None:
    path = _file(tmp_path, nan_in="T3")
    read = ReadOptions(temperatures=("T1", "T2", "T3", "T4"))
    with pytest.raises(MissingValueError) as whole:
        read_recording(path, read).validate()
    with pytest.raises(MissingValueError) as lazy:
        read_recording(path, read, columns_on_demand=True).validate()
    assert str(lazy.value) == str(whole.value)
    assert "'T3'" in str(lazy.value) and "1234" in str(lazy.value)


def test_time_and_two_columns_are_read_whole(tmp_path: Path) -> None:
    """Reading on demand holds time and two columns at a time: a file of no more is read
    whole (every use would read a column again for no memory saved)."""
    read = ReadOptions(signals=("gyro",), temperatures=("T1",))
    rec = read_recording(_file(tmp_path), read, keep_other=False, columns_on_demand=True)
    assert type(rec.columns) is dict and list(rec.columns) == ["gyro", "T1"]
    read = ReadOptions(signals=("gyro",), temperatures=("T1", "T2"))
    rec = read_recording(_file(tmp_path), read, keep_other=False, columns_on_demand=True)
    assert isinstance(rec.columns, ColumnsOnDemand)
