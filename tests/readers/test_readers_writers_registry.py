"""Writing a recording looks its output's format up in the registry: CSV and Parquet are
written; a format thermocal only reads (a flight-controller log) is refused, never written
as CSV under its name."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from thermocal.errors import FileFormatError
from thermocal.readers import ReadOptions, read_recording
from thermocal.writers import RECORDING_WRITERS, write_recording


def _recording(tmp_path: Path):  # type: ignore[no-untyped-def]
    src = tmp_path / "in.csv"
    src.write_text("time,gx,T\n0,1.5,20\n0.5,2.5,21\n1.0,3.5,22\n", encoding="utf-8")
    read = ReadOptions(signals="gx", temperatures="T", signal_unit="deg/h", temp_unit="degC",
                       time_unit="s")  # fmt: skip
    return read_recording(src, read)


@pytest.mark.parametrize("name", ["out.ulg", "out.bin"])
def test_a_format_only_read_is_refused(tmp_path: Path, name: str) -> None:
    rec = _recording(tmp_path)
    with pytest.raises(FileFormatError, match=r"but writes recordings as CSV or Parquet"):
        write_recording(rec, tmp_path / name)
    assert not (tmp_path / name).exists()


@pytest.mark.parametrize("name", ["out.csv", "out.parquet"])
def test_csv_and_parquet_round_trip(tmp_path: Path, name: str) -> None:
    rec = _recording(tmp_path)
    back = read_recording(write_recording(rec, tmp_path / name))
    np.testing.assert_array_equal(back.time_s, [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(back.column("gx"), [1.5, 2.5, 3.5])
    assert (back.units["gx"], back.signals, back.temperatures) == ("deg/h", ("gx",), ("T",))
    assert sorted(RECORDING_WRITERS) == ["csv", "parquet"]
