"""The temperatures of a Parquet file read side by side: Recording.temperatures_c hands the
(n, k) array of the columns as read, without a copy, equal to the columns pyarrow reads and
stacks here; any other choice or order of columns is stacked as before."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.readers.dispatch import read_recording
from thermocal.readers.options import ReadOptions
from thermocal.recording import Recording


@pytest.fixture
def four_temps(tmp_path):
    n = 5000
    rng = np.random.default_rng(0)
    t = np.arange(n) * 0.01
    cols = {"time": t, "gyro": rng.normal(0.0, 1.0, n)}
    cols.update({f"T{k}": 25.0 + k + np.sin(t / (k + 1.0)) for k in range(1, 5)})
    meta = {
        "format": "thermocal-recording",
        "version": 1,
        "time": "time",
        "time_unit": "s",
        "signals": {"gyro": "deg/h"},
        "temperatures": dict.fromkeys(["T1", "T2", "T3", "T4"], "degC"),
    }
    table = pa.table(cols).replace_schema_metadata({"thermocal": json.dumps(meta)})
    path = tmp_path / "four.parquet"
    pq.write_table(table, path, row_group_size=1500)
    return path


def _stacked(path, names):
    table = pq.read_table(path)
    return np.column_stack([table.column(c).to_numpy() for c in names])


def test_temperatures_as_read_are_a_view(four_temps):
    rec = read_recording(four_temps, ReadOptions())
    names = ["T1", "T2", "T3", "T4"]
    got = rec.temperatures_c(names)
    np.testing.assert_array_equal(got, _stacked(four_temps, names))
    assert got.shape == (5000, 4)
    assert all(np.shares_memory(got, rec.columns[c]) for c in names)  # no copy
    assert not got.flags.writeable  # the recording's columns cannot be written through it
    np.testing.assert_array_equal(
        rec.temperatures_c(["T2", "T3"]), _stacked(four_temps, ["T2", "T3"])
    )


def test_other_orders_are_stacked(four_temps):
    rec = read_recording(four_temps, ReadOptions())
    names = ["T3", "T1", "T4"]
    got = rec.temperatures_c(names)
    np.testing.assert_array_equal(got, _stacked(four_temps, names))
    assert got.flags.writeable  # a copy of its own
    t = np.arange(10.0)
    own = Recording.from_arrays(t, {"g": t}, {"A": t + 20.0, "B": t + 30.0})
    np.testing.assert_array_equal(own.temperatures_c(), np.column_stack([t + 20.0, t + 30.0]))
