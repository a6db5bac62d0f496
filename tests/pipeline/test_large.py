"""Records too long for memory (thermocal.pipeline.large): the decision from the Parquet
metadata and ``allan`` read a row group at a time, against the in-memory analysis of the
same file."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.errors import GapWarning, MissingValueError, TimestampError
from thermocal.pipeline import large
from thermocal.readers import ReadOptions, read_recording
from thermocal.stability import streaming as st
from thermocal.stability.analysis import allan_analysis

READ = ReadOptions(signals=("gyro",), signal_unit="deg/s", time_unit="ms", temperatures=())


def _write(path: Path, t_ms: np.ndarray, y: np.ndarray, group: int) -> Path:
    pq.write_table(pa.table({"t_ms": t_ms, "gyro": y}), path, row_group_size=group)
    return path


def _record(n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(11)
    t = np.arange(n) * 10.0  # 100 Hz, in ms
    t[n // 3 :] += 2_000.0  # a 2 s gap
    t[2 * n // 3 :] += 15.0  # and a short one: a step of 2.5 nominal steps
    y = 0.01 + rng.normal(0.0, 0.002, n) + np.cumsum(rng.normal(0.0, 2e-5, n))  # [°/s]
    return t, y


def _in_memory(path: Path) -> dict[str, object]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GapWarning)
        rec = read_recording(path, ReadOptions(**{**READ.__dict__, "time": "t_ms"}))
        return allan_analysis(rec, ["gyro"], where=str(path)).channels["gyro"].to_dict()


def _close(a: object, b: object) -> None:
    """Equal JSON-like objects, floats to 1e-12 relative."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys()
        for k in a:
            _close(a[k], b[k])
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _close(x, y)
    elif isinstance(a, float) and isinstance(b, float):
        assert b == pytest.approx(a, rel=1e-12, abs=0.0, nan_ok=True)
    else:
        assert a == b


def test_streamed_allan_equals_in_memory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # odd row groups, odd chunks, windows that fit no kernel's blocks, two gaps, a time
    # column in ms and a signal in °/s (every figure in °/s, as in memory)
    monkeypatch.setattr(large, "CHUNK_ROWS", 9_999)
    monkeypatch.setattr(st, "WINDOW", 5_000)
    t, y = _record(120_001)
    path = _write(tmp_path / "run.parquet", t, y, 7_001)
    read = ReadOptions(**{**READ.__dict__, "time": "t_ms"})
    with pytest.warns(GapWarning, match="2 gaps in time") as seen:
        got = large.allan_streamed(path, read, scratch_dir=tmp_path)
    assert "(2.035 s in all), first after row 39999 at 399.99 s" in str(seen[0].message)
    ch = got.channels["gyro"]
    assert ch.adev.unit == "deg/s" and ch.adev.n_segments == 3
    _close(_in_memory(path), ch.to_dict())
    assert [p.name for p in tmp_path.iterdir()] == ["run.parquet"]  # no temporary left


def test_needs_streaming_from_metadata(tmp_path: Path) -> None:
    t, y = _record(10_000)
    path = _write(tmp_path / "run.parquet", t, y, 4_096)
    need = 10_000 * (8 * 2 + 40)  # check_memory's estimate, written here
    assert large.needs_streaming(path, memory_budget=need - 1)
    assert not large.needs_streaming(path, memory_budget=need)
    (tmp_path / "run.csv").write_text("t,gyro\n0,1\n")
    assert not large.needs_streaming(tmp_path / "run.csv", memory_budget=1)


def test_interrupted_analysis_leaves_no_temporary(tmp_path: Path) -> None:
    t, y = _record(50_000)
    path = _write(tmp_path / "run.parquet", t, y, 10_000)
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    calls = []

    def stop(fraction: float) -> None:
        calls.append(fraction)
        if len(calls) == 8:  # inside the analysis, its temporary files written
            assert any(scratch.rglob("*.f64"))
            raise KeyboardInterrupt

    read = ReadOptions(**{**READ.__dict__, "time": "t_ms"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GapWarning)
        with pytest.raises(KeyboardInterrupt):
            large.allan_streamed(path, read, scratch_dir=scratch, progress=stop)
    assert list(scratch.iterdir()) == []


def test_progress_adds_up_to_one(tmp_path: Path) -> None:
    t, y = _record(30_000)
    path = _write(tmp_path / "run.parquet", t, y, 10_000)
    seen: list[float] = []
    read = ReadOptions(**{**READ.__dict__, "time": "t_ms"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GapWarning)
        large.allan_streamed(path, read, progress=seen.append)
    assert sum(seen) == pytest.approx(1.0, abs=0.02)


def test_bad_rows_are_named(tmp_path: Path) -> None:
    t, y = _record(20_000)
    y[12_345] = np.nan
    bad = _write(tmp_path / "nan.parquet", t, y, 5_000)
    read = ReadOptions(**{**READ.__dict__, "time": "t_ms"})
    with pytest.raises(MissingValueError, match="row 12345"):
        large.allan_streamed(bad, read)
    t2, y2 = _record(20_000)
    t2[15_000] = t2[14_999]
    back = _write(tmp_path / "back.parquet", t2, y2, 5_000)
    with pytest.raises(TimestampError, match="does not increase at row 15000"):
        large.allan_streamed(back, read)
