"""``thermocal metrics`` on a record too long for memory: computed window by window by
itself (THERMOCAL_MEMORY_LIMIT) or with ``--stream``, the same figures as in memory."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.cli import main

ARGS = ["--signal", "gyro", "--signal-unit", "deg/s", "--time-unit", "s", "--json"]


def _write(path: Path, n: int, temp: bool = False) -> Path:
    rng = np.random.default_rng(41)
    t = np.arange(n) * 0.01
    t[n // 3 :] += 3.0
    cols = {"time": t, "gyro": 0.002 + rng.normal(0.0, 1e-4, n)}
    if temp:
        cols["T1"] = np.full(n, 25.0)
    pq.write_table(pa.table(cols), path, row_group_size=33_333)
    return path


def test_too_large_for_memory_gives_the_in_memory_figures(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _write(tmp_path / "fog.parquet", 150_001)
    args = ["metrics", str(path), *ARGS, "--average", "2", "--latitude", "48", "--axis", "up"]
    assert main(args) == 0
    ref = json.loads(capsys.readouterr().out)
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", "1M")
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    assert main(args) == 0
    got = json.loads(capsys.readouterr().out)
    assert got.keys() == ref.keys()
    for key, value in ref.items():
        if isinstance(value, float):
            assert got[key] == pytest.approx(value, rel=1e-12), key
        else:
            assert got[key] == value, key
    assert ref["unit"] == "deg/s" and ref["n_segments"] == 2
    assert [p.name for p in tmp_path.iterdir()] == ["fog.parquet"]


def test_stream_refuses_temperatures_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _write(tmp_path / "fog.parquet", 10_000, temp=True)
    assert main(["metrics", str(path), *ARGS, "--temps", "T1", "--stream"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("error:")]
    assert len(err) == 1 and "no temperature hold stages" in err[0] and "--temps" in err[0]
