"""A Parquet file opened in pyarrow's own reader (:func:`thermocal.readers.table.open_parquet`)
reads what :class:`pyarrow.parquet.ParquetFile` reads — schema, metadata, row groups and
columns chosen by name, nested ones included — without importing ``pyarrow.parquet``."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import thermocal
from thermocal.readers.table import ReaderFile, open_parquet


@pytest.fixture(scope="module")
def path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Flat and nested columns, a name with a dot, text and JSON, three row groups."""
    n = 700
    rng = np.random.default_rng(1)
    cols: dict[str, pa.Array] = {
        "time": pa.array(np.arange(n) * 0.1),
        "gyro": pa.array(rng.normal(size=n)),
        "imu": pa.StructArray.from_arrays(
            [pa.array(rng.normal(size=n)), pa.array(np.arange(n, dtype=np.int32))], ["x", "n"]
        ),
        "imu.x": pa.array(rng.normal(size=n)),  # a flat name that reads like a nested one
        "note": pa.array(["a"] * n),
    }
    if hasattr(pa, "json_"):  # an extension type (pyarrow 19+): read as ParquetFile reads it
        cols["js"] = pa.array(['{"a": 1}'] * n, type=pa.json_())
    out = tmp_path_factory.mktemp("rf") / "r.parquet"
    table = pa.table(cols).replace_schema_metadata({"k": "v"})
    pq.write_table(table, out, row_group_size=300, write_page_checksum=True)
    return out


@pytest.mark.parametrize("arrow_schema", [True, False])
def test_schema_metadata_and_row_groups_as_parquetfile(
    path: Path, tmp_path: Path, arrow_schema: bool
) -> None:
    """With and without the Arrow schema stored in the file (without it, the Parquet
    logical types alone say what a column is: JSON text an extension type, as
    ``ParquetFile`` reads it)."""
    if not arrow_schema:
        path_2 = tmp_path / "plain.parquet"
        pq.write_table(pq.read_table(path), path_2, store_schema=False, row_group_size=300)
        path = path_2
    mine, theirs = open_parquet(path), pq.ParquetFile(path, page_checksum_verification=True)
    assert isinstance(mine, ReaderFile)
    assert mine.schema_arrow.equals(theirs.schema_arrow, check_metadata=True)
    assert mine.metadata.num_rows == theirs.metadata.num_rows == 700
    assert mine.num_row_groups == theirs.num_row_groups == 3


@pytest.mark.parametrize(
    "names", [["gyro"], ["imu"], ["imu.x"], ["imu", "time"], ["note", "gyro"], ["nothing"]]
)
def test_columns_by_name_as_parquetfile(path: Path, names: list[str]) -> None:
    mine, theirs = open_parquet(path), pq.ParquetFile(path)
    for i in range(theirs.num_row_groups):
        got = mine.read_row_group(i, columns=names, use_threads=False)
        assert got.equals(theirs.read_row_group(i, columns=names, use_threads=False))
    assert mine.read(columns=names, use_threads=True).equals(theirs.read(columns=names))


def test_not_parquet_is_an_arrow_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.parquet"
    bad.write_bytes(b"PAR1 not really")
    with pytest.raises(pa.ArrowInvalid):
        open_parquet(bad)


def test_a_parquet_recording_is_read_without_pyarrow_parquet(path: Path) -> None:
    """A fresh interpreter reads a Parquet recording's columns without importing
    ``pyarrow.parquet`` (and ``pyarrow.fs``, ``ssl``…)."""
    code = (
        "import sys; from thermocal.readers import ReadOptions, read_recording; "
        f"rec = read_recording({str(path)!r}, ReadOptions(signals=['gyro']), keep_other=False); "
        "print(rec.n_samples, float(rec.columns['gyro'].sum()).hex(), "
        "'pyarrow.parquet' in sys.modules, 'pyarrow.fs' in sys.modules)"
    )
    src = Path(thermocal.__file__).resolve().parents[1]
    proc = subprocess.run(
        [sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(src)},
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    gyro = pq.read_table(path, columns=["gyro"]).column(0).to_numpy()
    assert proc.stdout.split() == ["700", float(gyro.sum()).hex(), "False", "False"]


def test_a_flat_column_named_like_a_nested_one_is_read_as_itself(path: Path) -> None:
    """``imu.x`` beside a struct ``imu`` with a field ``x``: a name selects both (as
    ``ParquetFile`` selects them), the flat column is the one read (an internal error
    before: the struct was taken for it)."""
    from thermocal.errors import UnitWarning
    from thermocal.readers import ReadOptions, read_recording

    with pytest.warns(UnitWarning, match="no unit stated"):  # the file states none
        rec = read_recording(path, ReadOptions(signals=["gyro"]))
    flat = pq.read_table(path, columns=["imu.x"]).column("imu.x").to_numpy()
    assert np.array_equal(rec.columns["imu.x"], flat)
    assert "imu" not in rec.columns  # a struct is no numeric column
