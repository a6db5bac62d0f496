"""Readers and writers: round-trips, units, metadata, and every documented error."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from thermocal.errors import (
    FileFormatError,
    MissingColumnError,
    NonNumericError,
    TextLayoutWarning,
    ThermocalInputError,
    TimestampError,
    UnitError,
    UnitWarning,
)
from thermocal.outputs import sidecar_path
from thermocal.readers.dispatch import read_recording
from thermocal.readers.options import ReadOptions
from thermocal.recording import Metadata, Recording, find_problems
from thermocal.writers import write_recording

# Files here that state no unit are about other faults; the unit defaults and their
# warnings are tested in test_units_travel.py and in test_sidecar_options_and_cli_override.
pytestmark = pytest.mark.filterwarnings("ignore::thermocal.errors.UnitWarning")


def _recording(n: int = 500) -> Recording:
    rng = np.random.default_rng(3)
    t = np.arange(n) * 0.01
    return Recording.from_arrays(
        t,
        {"gyrox rad/s": rng.normal(0, 1e-5, n)},
        {"T 1": 20 + rng.normal(0, 0.1, n), "T2": 21 + np.zeros(n)},
        signal_unit="rad/s",
        other={"truth_bias": np.linspace(0, 1, n)},
        other_units={"truth_bias": "deg/h"},
        meta=Metadata(
            sample_interval_s=0.01,
            scale_factor=2.5,
            scale_factor_unit="counts/arcsec",
            latitude_deg=40.0,
            axis="up",
            sensor_id="SN 42",
            run_id="r1",
            notes="chamber 3",
        ),
    )


@pytest.mark.parametrize("ext", [".csv", ".parquet"])
def test_round_trip(tmp_path: Path, ext: str) -> None:
    rec = _recording()
    path = write_recording(rec, tmp_path / f"run{ext}")
    back = read_recording(path)
    assert_array_equal(back.time_s, rec.time_s)
    for c in rec.columns:
        assert_array_equal(back.columns[c], rec.columns[c])
    assert back.units == rec.units
    assert back.signals == ("gyrox rad/s",)
    assert back.temperatures == ("T 1", "T2")
    assert back.meta.to_dict() == rec.meta.to_dict()
    sig, unit = back.signal()
    assert unit == "deg/h"
    assert_allclose(sig, rec.columns["gyrox rad/s"] * 180 / np.pi * 3600)


def test_writer_is_atomic_and_leaves_no_temp(tmp_path: Path) -> None:
    rec = _recording(10)
    out = tmp_path / "a.csv"
    out.write_text("precious")
    bad = Recording.from_arrays(rec.time_s, {"time": rec.time_s})  # clashes with time column
    with pytest.raises(ThermocalInputError, match="clashes"):
        write_recording(bad, out)
    assert out.read_text() == "precious"
    assert [p.name for p in tmp_path.iterdir()] == ["a.csv"]


def test_outputs_get_ordinary_permissions(tmp_path: Path) -> None:
    import os
    import stat

    mask = os.umask(0o022)
    try:
        path = write_recording(_recording(10), tmp_path / "p.parquet")
    finally:
        os.umask(mask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o644


def test_time_in_ms_and_counts_temperature(tmp_path: Path) -> None:
    path = tmp_path / "log.csv"
    pd.DataFrame({"t_ms": [0, 20, 40], "g": [1.0, 2, 3], "tc": [800, 801, 802]}).to_csv(
        path, index=False
    )
    meta = Metadata(temperature_conversion={"tc": (0.0625, -50.0)})
    rec = read_recording(
        path,
        ReadOptions(
            time="t_ms",
            time_unit="ms",
            signals=["g"],
            temperatures=["tc"],
            temp_unit="counts",
            signal_unit="deg/h",
        ),
        meta=meta,
    )
    assert_allclose(rec.time_s, [0.0, 0.02, 0.04])
    assert_allclose(rec.temperature_c("tc"), [0.0, 0.0625, 0.125])
    rec2 = read_recording(
        path,
        ReadOptions(
            time="t_ms",
            signals=["g"],
            temperatures=["tc"],
            temp_unit="counts",
            signal_unit="deg/h",
            time_unit="ms",
        ),
    )
    with pytest.raises(UnitError, match="raw counts"):
        rec2.temperature_c("tc")


def test_sidecar_options_and_cli_override(tmp_path: Path) -> None:
    path = tmp_path / "x.csv"
    pd.DataFrame({"ts": [0.0, 1.0], "w": [1.0, 2.0], "T": [20.0, 21.0]}).to_csv(path, index=False)
    sidecar_path(path).write_text(
        json.dumps(
            {
                "time": "ts",
                "signals": {"w": "deg/s"},
                "temperatures": {"T": "degC"},
                "metadata": {"latitude_deg": 45},
            }
        )
    )
    with pytest.warns(UnitWarning, match="no unit stated for the time column 'ts'; assuming s"):
        rec = read_recording(path)
    assert rec.units["w"] == "deg/s"
    assert rec.unit_sources == {"<time>": "default", "w": "metadata", "T": "metadata"}
    assert rec.meta.latitude_deg == 45.0
    # an option that contradicts the file's metadata wins, with a warning naming both
    with pytest.warns(UnitWarning, match="signal_unit deg/h contradicts the file's metadata"):
        rec = read_recording(path, ReadOptions(signal_unit="deg/h", time_unit="s"))
    assert rec.units["w"] == "deg/h"


def test_parquet_keeps_metadata_without_sidecar(tmp_path: Path) -> None:
    rec = _recording(20)
    path = write_recording(rec, tmp_path / "r.parquet")
    assert not sidecar_path(path).exists()
    assert read_recording(path).meta.sensor_id == "SN 42"


def test_missing_column_lists_available(tmp_path: Path) -> None:
    path = tmp_path / "m.csv"
    pd.DataFrame({"time": [0, 1], "gyro": [1, 2]}).to_csv(path, index=False)
    with pytest.raises(MissingColumnError, match=r"'gyroz'.*available: 'time', 'gyro'"):
        read_recording(path, ReadOptions(signals=["gyroz"]))


def test_non_numeric_cell_names_row_and_column(tmp_path: Path) -> None:
    path = tmp_path / "n.csv"
    path.write_text("time,gyro\n0,1.0\n1,2.0\n2,oops\n3,4\n")
    with pytest.raises(NonNumericError, match=r"'oops' in column 'gyro' at row 2 \(line 4"):
        read_recording(path, ReadOptions(signals=["gyro"]))


def test_problems_nan_duplicates_backwards_gaps() -> None:
    t = np.array([0.0, 1, 2, 2, 3, 2.5, 4, 5, 6, 7])
    g = np.ones(10)
    g[[4, 7]] = np.nan
    rec = Recording.from_arrays(t, {"gyro": g})
    kinds = {p.kind: p for p in find_problems(rec)}
    assert kinds["duplicate_time"].row == 3
    assert kinds["backwards_time"].row == 5
    assert kinds["nan"].row == 4 and "2 NaN" in kinds["nan"].message
    with pytest.raises(TimestampError, match="duplicate timestamp"):
        rec.validate()
    t2 = np.r_[np.arange(10.0), np.arange(50.0, 60.0)]
    rec2 = Recording.from_arrays(t2, {"gyro": np.ones(20)})
    gaps = [p for p in find_problems(rec2) if p.kind == "gaps"]
    assert gaps and gaps[0].severity == "warning" and gaps[0].row == 9
    assert rec2.gaps()[0].length_s == 41.0


def test_unknown_unit_and_empty_and_foreign_files(tmp_path: Path) -> None:
    path = tmp_path / "u.csv"
    pd.DataFrame({"time": [0, 1], "gyro": [1, 2]}).to_csv(path, index=False)
    with pytest.raises(UnitError, match="parsecs"):
        read_recording(path, ReadOptions(signals=["gyro"], signal_unit="parsecs"))
    empty = tmp_path / "e.csv"
    empty.write_text("")
    with pytest.raises(FileFormatError, match="empty"):
        read_recording(empty)
    header_only = tmp_path / "h.csv"
    header_only.write_text("time,gyro\n")
    with pytest.raises(FileFormatError, match="no data rows"):
        read_recording(header_only)
    with pytest.raises(FileFormatError, match="not a CSV or Parquet"):
        read_recording(tmp_path / "data.xlsx")
    fake = tmp_path / "fake.parquet"
    fake.write_bytes(b"PAR1 this is not parquet")
    with pytest.raises(FileFormatError, match="not a readable Parquet"):
        read_recording(fake)


def test_parquet_string_column_is_refused_when_named(tmp_path: Path) -> None:
    path = tmp_path / "s.parquet"
    pq.write_table(pa.table({"time": [0.0, 1.0], "gyro": ["a", "b"]}), path)
    with pytest.raises(NonNumericError, match="'gyro' is not numeric"):
        read_recording(path, ReadOptions(signals=["gyro"]))


# --- malformed files generated by hypothesis -----------------------------------------------

_cell = st.one_of(
    st.floats(allow_nan=True, allow_infinity=False, width=32).map(lambda x: f"{x:g}"),
    st.sampled_from(["", "nan", "abc", "1e", "--", " ", "1,5"]),
)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    rows=st.lists(st.tuples(_cell, _cell), min_size=0, max_size=12),
    header=st.sampled_from(["time,gyro", "time;gyro", "tim,gyro", "", "time"]),
)
def test_malformed_csv_never_crashes_or_passes_silently(
    tmp_path: Path, rows: list[tuple[str, str]], header: str
) -> None:
    """Any malformed CSV either reads into a recording whose problems are reported, or
    raises a ThermocalInputError — never another exception."""
    path = tmp_path / "fuzz.csv"
    path.write_text(header + "\n" + "\n".join(f"{a},{b}" for a, b in rows) + "\n")
    try:
        rec = read_recording(path, ReadOptions(signals=["gyro"]))
    except (ThermocalInputError, TextLayoutWarning):  # refused, or its reading said aloud
        return
    problems = find_problems(rec, required=["gyro"])
    t = rec.time_s
    sig = rec.columns["gyro"]
    has_bad = (
        (not np.all(np.isfinite(t)))
        or np.any(np.diff(t) <= 0)
        or np.any(np.isnan(sig))
        or t.size < 2
        # beyond any sensor (recording.PLAUSIBLE_SIGNAL, rates in °/h): refused too
        or bool(np.any(np.abs(sig[np.isfinite(sig)]) > 1e8))
    )
    assert has_bad == any(p.severity == "error" for p in problems)


_arrow_col = st.one_of(
    st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=3, max_size=3).map(
        lambda v: pa.array(v, type=pa.float64())
    ),
    st.lists(st.integers(-(2**40), 2**40), min_size=3, max_size=3).map(pa.array),
    st.lists(st.one_of(st.none(), st.floats(-1e3, 1e3)), min_size=3, max_size=3).map(
        lambda v: pa.array(v, type=pa.float32())
    ),
    st.lists(st.text(max_size=3), min_size=3, max_size=3).map(pa.array),
    st.lists(st.booleans(), min_size=3, max_size=3).map(pa.array),
)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(time_col=_arrow_col, gyro_col=_arrow_col, name=st.sampled_from(["time", "t"]))
def test_malformed_parquet_never_crashes_or_passes_silently(
    tmp_path: Path, time_col: pa.Array, gyro_col: pa.Array, name: str
) -> None:
    """Parquet files with any column types either read (problems reported) or raise a
    ThermocalInputError naming the file — never another exception."""
    path = tmp_path / "fuzz.parquet"
    pq.write_table(pa.table({name: time_col, "gyro": gyro_col}), path)
    message: str | None = None
    try:
        rec = read_recording(path, ReadOptions(signals=["gyro"]))
    except ThermocalInputError as exc:
        message = str(exc)
    if message is not None:
        assert str(path) in message
        return
    t = rec.time_s
    sig = rec.columns["gyro"]
    has_bad = (
        (not np.all(np.isfinite(t)))
        or np.any(np.diff(t) <= 0)
        or np.any(~np.isfinite(sig))
        # beyond any gyro (recording.PLAUSIBLE_SIGNAL, the default unit being °/h)
        or np.any(np.abs(sig[np.isfinite(sig)]) > 1e8)
    )
    assert has_bad == any(p.severity == "error" for p in find_problems(rec, required=["gyro"]))


@pytest.mark.parametrize(
    ("names", "expect"),
    [
        (["time_s", "gyro"], "time_s"),
        (["Time (ms)", "gyro"], "Time (ms)"),
        (["timestamp_us", "gyro"], "timestamp_us"),
        (["t", "gyro"], "t"),
        (["time", "time_s"], "time"),  # the plain name wins
        (["time_s", "timestamp_ms"], "time"),  # two candidates: no guess
        (["elapsed time", "gyro"], "elapsed time"),
        (["temp_s", "gyro"], "time"),  # 's' as a unit, but not a time name
    ],
)
def test_default_time_column(names: list[str], expect: str) -> None:
    from thermocal.readers.common import default_time_column

    assert default_time_column(names) == expect
    assert default_time_column(names, "gyro") == "gyro"  # the sidecar's says so


def test_time_column_with_unit_in_its_name_is_found_and_its_unit_used(tmp_path: Path) -> None:
    path = tmp_path / "r.csv"
    path.write_text("time_ms,gyro\n0,1\n10,2\n20,3\n")
    rec = read_recording(path, ReadOptions(signals=["gyro"], signal_unit="deg/h"))
    np.testing.assert_allclose(rec.time_s, [0.0, 0.01, 0.02])
