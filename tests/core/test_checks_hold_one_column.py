"""The recording's checks read a Parquet file's columns one at a time: the lazy mapping
(:class:`thermocal.readers.table.ColumnsOnDemand`) releases a column before it reads the
next, and the checks must keep no reference that would hold it (``_column_problems`` once
held the last column while the next was read: ``metrics`` with four temperatures 29.6 →
37.6 B/row in ``benchmarks/bench_memory.py``).  Every column read is watched by a weak
reference: when the next is read, none read before may still be alive."""

from __future__ import annotations

import weakref
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.readers import read_recording, table
from thermocal.readers.options import ReadOptions
from thermocal.recording import find_problems

ROWS = 50_000


def test_the_checks_hold_no_column_while_the_next_is_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(4)
    path = tmp_path / "six.parquet"
    df = pd.DataFrame({"time [s]": np.arange(ROWS) * 0.01, "gyro [deg/h]": rng.normal(size=ROWS)})
    for k in range(1, 5):
        df[f"T{k} [degC]"] = 20.0 + rng.normal(size=ROWS)
    df.to_parquet(path, index=False)
    temps = tuple(f"T{k} [degC]" for k in range(1, 5))
    read = ReadOptions(signals=("gyro [deg/h]",), temperatures=temps)
    rec = read_recording(path, read, columns_on_demand=True)
    assert isinstance(rec.columns, table.ColumnsOnDemand)  # the lazy mapping, as commands read

    watched: list[tuple[str, Any]] = []
    alive_at_read: dict[str, list[str]] = {}
    real = table.numeric_column

    def spy(source: Any, name: str, where: Any) -> Any:
        alive_at_read[name] = [n for n, ref in watched if ref() is not None]
        values = real(source, name, where)
        watched.append((name, weakref.ref(values)))
        return values

    monkeypatch.setattr(table, "numeric_column", spy)
    assert find_problems(rec) == []
    assert set(alive_at_read) >= {"gyro [deg/h]", *temps}  # every column was read, lazily
    assert all(not alive for alive in alive_at_read.values()), alive_at_read
