"""A fit's temperatures read from their Parquet file block by block
(:mod:`thermocal.pipeline.fit_columns`): the values a whole read gives, in the layout its
slices have, and a four-temperature fit's model file equal to the one the whole read
gives (the way ``fit`` read files before)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import thermocal.readers.dispatch as dispatch
from thermocal.pipeline import fit_columns
from thermocal.pipeline.fit import fit_files
from thermocal.pipeline.fit_columns import TemperatureBlocks
from thermocal.pipeline.options import FitOptions

N_TEMPS = 4


def _write(path: Path, n: int, group: int, seed: int = 3, gyros: int = 1) -> Path:
    """A recording of ``n`` rows in row groups of ``group``: time [s] at 10 Hz, ``gyros``
    gyros [°/h] and four temperatures [°C] sweeping 20→50 °C, each its own lag."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.1
    span = t[-1]
    temps = [
        20.0 + 30.0 * t / span + 0.4 * k * np.sin(2 * np.pi * (k + 1) * t / span)
        for k in range(N_TEMPS)
    ]
    cols: dict[str, Any] = {"time": t}
    for g in range(gyros):
        cols[f"g{g}"] = (
            0.5 + 0.02 * (temps[0] - 25.0) - 1e-4 * (temps[1] - 30.0) ** 2
            + rng.normal(0.0, 0.05, n)
        )  # fmt: skip
    names = [f"T{k + 1}" for k in range(N_TEMPS)]
    cols.update(zip(names, temps, strict=True))
    meta = {
        "format": "thermocal-recording",
        "version": 1,
        "time": "time",
        "time_unit": "s",
        "signals": {f"g{g}": "deg/h" for g in range(gyros)},
        "temperatures": dict.fromkeys(names, "degC"),
    }
    table = pa.table(cols).replace_schema_metadata({"thermocal": json.dumps(meta)})
    pq.write_table(table, path, row_group_size=group)
    return path


@pytest.fixture
def small_groups(tmp_path: Path) -> tuple[Path, FloatArray2]:
    path = _write(tmp_path / "r.parquet", 10_007, 1000)
    whole = np.column_stack(
        [pq.read_table(path, columns=[f"T{k + 1}"]).column(0).to_numpy() for k in range(4)]
    )
    return path, np.asfortranarray(whole)


FloatArray2 = Any


def test_blocks_hold_the_values_of_a_whole_read(small_groups: tuple[Path, Any]) -> None:
    path, whole = small_groups
    b = TemperatureBlocks(pq.ParquetFile(path), [f"T{k + 1}" for k in range(4)])
    assert b.shape == whole.shape == (10_007, 4)
    for a, z in [(0, 10_007), (999, 1001), (1000, 2000), (5, 5), (3500, 9999), (9000, 10_007)]:
        got = b[a:z]
        np.testing.assert_array_equal(got, whole[a:z])
        assert z == a or got.strides[0] == whole[a:z].strides[0] == 8  # columns contiguous
    for j in range(4):
        np.testing.assert_array_equal(b[:, j], whole[:, j])
    for idx in [np.arange(0, 10_007, 37), np.array([0, 999, 1000, 10_006]), np.arange(0)]:
        got, want = b[idx], whole[idx]
        np.testing.assert_array_equal(got, want)
        assert got.flags["C_CONTIGUOUS"] == want.flags["C_CONTIGUOUS"]
    np.testing.assert_array_equal(b[::7], whole[::7])
    np.testing.assert_array_equal(np.asarray(b), whole)


def test_blocks_read_nulls_as_nan_and_integers_as_floats(tmp_path: Path) -> None:
    f = tmp_path / "n.parquet"
    pq.write_table(
        pa.table({"T1": pa.array([1, 2, None, 4], pa.int32()), "T2": [0.5, None, 2.5, 3.5]}),
        f,
        row_group_size=3,
    )
    b = TemperatureBlocks(pq.ParquetFile(f), ["T1", "T2"])
    np.testing.assert_array_equal(b[0:4], [[1.0, 0.5], [2.0, np.nan], [np.nan, 2.5], [4.0, 3.5]])


def _fit(
    paths: list[Path], out: Path, signals: tuple[str, ...], **params: Any
) -> tuple[Any, list[str]]:
    temps = tuple(f"T{k + 1}" for k in range(4))
    o = FitOptions("poly", params, signals=signals, temperatures=temps, allow_narrow=True)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = fit_files(paths, o, out)
    return res, sorted(str(w.message) for w in caught)


def _model(path: Path) -> Any:
    """The model file without its creation times and checksums (of those times)."""

    def strip(x: Any) -> Any:
        if isinstance(x, dict):
            return {k: strip(v) for k, v in x.items() if k not in ("created_utc", "checksum")}
        return [strip(v) for v in x] if isinstance(x, list) else x

    return strip(json.loads(path.read_text()))


CASES = [
    ("order 2", ("g0",), {"order": 2}),
    ("rate terms, hold-out selection", ("g0",), {"terms": "T1,T1^2,dT1,T2,T3,T1*dT1,T4",
                                                 "select": "holdout"}),
    ("two channels", ("g0", "g1"), {"order": 2}),
]  # fmt: skip


@pytest.mark.parametrize(("what", "signals", "params"), CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("n_runs", [1, 2])
def test_four_temperature_fit_equals_the_whole_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, what: str, signals: tuple[str, ...],
    params: dict[str, Any], n_runs: int,
) -> None:  # fmt: skip
    """The model file of a fit read block by block equals, number for number, the one of
    the same fit on the columns read whole (``fit`` before: every column held)."""
    paths = [
        _write(tmp_path / f"run{i}.parquet", 70_001 + 999 * i, 4096, seed=i, gyros=2)
        for i in range(n_runs)
    ]
    made: list[Any] = []
    real = fit_columns.temperature_blocks

    def spy(*a: Any, **k: Any) -> Any:
        made.append(real(*a, **k))
        return made[-1]

    monkeypatch.setattr(fit_columns, "temperature_blocks", spy)
    monkeypatch.setattr(fit_columns, "MIN_ROWS_BY_BLOCKS", 70_001)  # these files by blocks

    def whole_array(*a: Any, **k: Any) -> Any:
        raise AssertionError("the temperatures were read whole")

    monkeypatch.setattr(TemperatureBlocks, "__array__", whole_array)  # never all at once
    got, got_w = _fit(paths, tmp_path / "blocks.json", signals, **params)
    assert made and all(isinstance(b, TemperatureBlocks) for b in made)  # read by blocks
    monkeypatch.undo()
    assert not fit_columns.read_by_blocks(paths[0])  # 70 001 rows: read whole by default
    assert not fit_columns.read_by_blocks(tmp_path / "absent.parquet")
    assert not fit_columns.read_by_blocks(tmp_path)  # a folder (a station's recording)
    (tmp_path / "notes.xyz").write_text("x")
    assert not fit_columns.read_by_blocks(tmp_path / "notes.xyz")
    whole_read = dispatch.read_recording

    def whole(*a: Any, **k: Any) -> Any:
        k["columns_on_demand"] = False
        return whole_read(*a, **k)

    monkeypatch.setattr(dispatch, "read_recording", whole)
    want, want_w = _fit(paths, tmp_path / "whole.json", signals, **params)
    assert _model(tmp_path / "blocks.json") == _model(tmp_path / "whole.json")
    assert got_w == want_w
    for a, b in zip(got.channels, want.channels, strict=True):
        assert json.dumps(a.figures, sort_keys=True, default=str).replace("blocks", "whole") == (
            json.dumps(b.figures, sort_keys=True, default=str)
        )


def test_a_reconstructed_or_converted_column_is_held_whole(tmp_path: Path) -> None:
    """Blocks only for the file's own °C columns: a column given to the recording (the
    thermometer's reconstruction) or in counts is held as before."""
    from thermocal.readers.dispatch import read_recording

    path = _write(tmp_path / "r.parquet", 5000, 1000)
    rec = read_recording(path, columns_on_demand=True)
    names = [f"T{k + 1}" for k in range(4)]
    assert isinstance(fit_columns.temperature_blocks(rec, names), TemperatureBlocks)
    given = rec.with_columns({"T2": rec.column("T2") + 0.0}, {"T2": "degC"})
    assert fit_columns.temperature_blocks(given, names) is None
    whole = read_recording(path)
    assert fit_columns.temperature_blocks(whole, names) is None


def test_blocks_are_the_same_columns_only_of_the_same_file(tmp_path: Path) -> None:
    """Two channels of one run share its temperatures without reading them to compare;
    the same names of another file (equal shape) are other columns."""
    a = _write(tmp_path / "a.parquet", 3000, 1000, seed=1)
    b = _write(tmp_path / "b.parquet", 3000, 1000, seed=1)
    names = [f"T{k + 1}" for k in range(4)]
    one = TemperatureBlocks(pq.ParquetFile(a), names, a)
    assert one.same_columns(TemperatureBlocks(pq.ParquetFile(a), names, a))
    assert not one.same_columns(TemperatureBlocks(pq.ParquetFile(b), names, b))
    assert not one.same_columns(TemperatureBlocks(pq.ParquetFile(a), names[::-1], a))
    assert not TemperatureBlocks(pq.ParquetFile(a), names).same_columns(one)
    assert not one.same_columns(np.asarray(one))
