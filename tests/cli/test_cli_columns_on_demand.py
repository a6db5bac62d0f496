"""``inspect`` and ``metrics`` read a Parquet file's columns one at a time: on a file with
a gap, a temperature step, a NaN or time that goes backwards they print what they print
when every column is read at once (the reader with ``columns_on_demand=False``, the path
they took before), the findings named where the test put them."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import thermocal.readers
from thermocal.cli import main

N = 6000
GAP_ROW = 2500
"""The row after which 30 s are missing."""


def _file(tmp_path: Path, *, backwards: bool = False, nan_t3: bool = False) -> Path:
    rng = np.random.default_rng(1)
    t = np.arange(N) * 0.1
    t[GAP_ROW + 1 :] += 30.0  # one gap of 30 s
    if backwards:
        t[4000] = t[3998]  # time goes backwards at row 4000
    temps = {f"T{k + 1}": 20.0 + 0.002 * np.arange(N) + 0.3 * k for k in range(4)}
    temps["T2"][3000:] += 5.0  # a step of the second sensor
    if nan_t3:
        temps["T3"][777] = np.nan
    gyro = 0.5 + 0.01 * (temps["T1"] - 25.0) + rng.normal(0.0, 0.05, N)
    gyro[[1000, 4500]] += 30.0  # two spikes
    meta = {"time": "time", "time_unit": "s", "signals": {"gyro": "deg/h"},
            "temperatures": dict.fromkeys(temps, "degC")}  # fmt: skip
    table = pa.table({"time": t, "gyro": gyro, **temps}).replace_schema_metadata(
        {"thermocal": json.dumps(meta)}
    )
    path = tmp_path / "run.parquet"
    pq.write_table(table, path, row_group_size=1000)
    return path


def _both(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, args: list[str]
) -> tuple[tuple[int, str, str], tuple[int, str, str]]:
    """(on demand, whole read): exit status, stdout, stderr."""
    code = main(args)
    lazy = (code, *capsys.readouterr())
    original = thermocal.readers.read_recording

    def whole(*a: Any, **k: Any) -> Any:
        return original(*a, **{**k, "columns_on_demand": False})

    monkeypatch.setattr(thermocal.readers, "read_recording", whole)
    code = main(args)
    return lazy, (code, *capsys.readouterr())


TEMPS = ["--temps", "T1,T2,T3,T4"]


def test_inspect_gap_step_spikes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _file(tmp_path)
    lazy, whole = _both(capsys, monkeypatch, ["inspect", str(path), *TEMPS, "--json"])
    assert lazy == whole
    d = json.loads(lazy[1])
    assert lazy[0] == 0 and d["n_samples"] == N
    assert [g["after_row"] for g in d["gaps"]] == [GAP_ROW]
    assert d["columns"]["gyro"]["n_spikes"] == 2
    assert d["columns"]["T2"]["max"] == pytest.approx(20.0 + 0.002 * (N - 1) + 0.3 + 5.0)
    assert d["temperature_span"]["T4"] == pytest.approx([20.9, 20.9 + 0.002 * (N - 1)])
    lazy, whole = _both(capsys, monkeypatch, ["inspect", str(path), *TEMPS])
    assert lazy == whole


def test_inspect_and_metrics_time_backwards_and_nan(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _file(tmp_path, backwards=True, nan_t3=True)
    lazy, whole = _both(capsys, monkeypatch, ["inspect", str(path), *TEMPS, "--json"])
    assert lazy == whole and lazy[0] == 2
    assert "time goes backwards at row 4000" in lazy[2]
    monkeypatch.undo()
    lazy, whole = _both(
        capsys, monkeypatch, ["metrics", str(path), "--signal", "gyro", *TEMPS, "--json"]
    )
    assert lazy == whole and lazy[0] == 2
    assert lazy[2].strip().splitlines()[-1].startswith("error: ")
    assert "row 4000" in lazy[2]


def test_metrics_nan_in_the_third_temperature(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _file(tmp_path, nan_t3=True)
    lazy, whole = _both(capsys, monkeypatch, ["metrics", str(path), "--signal", "gyro", *TEMPS])
    assert lazy == whole and lazy[0] == 2
    last = lazy[2].strip().splitlines()[-1]
    assert last.startswith("error: ") and "'T3'" in last and "777" in last


def test_metrics_gap_and_step_figures(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _file(tmp_path)
    args = ["metrics", str(path), "--signal", "gyro", *TEMPS, "--average", "10", "--json"]
    lazy, whole = _both(capsys, monkeypatch, args)
    assert lazy == whole and lazy[0] == 0
    assert "1 gaps in time (30.1 s in all), first after row 2500" in lazy[2]
    d = json.loads(lazy[1])
    assert d["n_samples"] == N and d["n_segments"] == 2
    gyro = pq.read_table(path).column("gyro").to_numpy()
    assert d["bias"] == pytest.approx(float(np.mean(gyro)), rel=1e-12)


@pytest.mark.parametrize("command", ["inspect", "metrics"])
def test_a_file_too_large_whole_is_read_on_demand(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    command: str,
) -> None:
    """Six columns of 6000 rows need 6000 × (6 · 8 + 40) B = 528 000 B whole, and
    6000 × (3 · 8 + 40) B = 384 000 B on demand (time and two columns held): with 450 kB
    the file is inspected, its figures those of a whole read; with 350 kB it is refused
    naming the memory limit."""
    path = _file(tmp_path)
    args = [command, str(path), *TEMPS, "--json"]
    args += ["--signal", "gyro"] if command == "metrics" else []
    assert main(args) == 0
    whole = capsys.readouterr()
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", "450000")
    assert main(args) == 0
    assert capsys.readouterr() == whole
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", "350000")
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith(f"error: {path}: reading 6,000 rows of 3 column(s)")
    assert "THERMOCAL_MEMORY_LIMIT" in err[-1]


def _reads(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """How many times each column is read from the file (``numeric_column``)."""
    import thermocal.readers.table as table

    counts: dict[str, int] = {}
    original = table.numeric_column

    def counted(source: Any, name: str, path: Path) -> Any:
        counts[name] = counts.get(name, 0) + 1
        return original(source, name, path)

    monkeypatch.setattr(table, "numeric_column", counted)
    return counts


def test_metrics_reads_each_column_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    src = _file(tmp_path)
    args = ["metrics", str(src), "--signal", "gyro", "--temps", "T1,T2,T3,T4", "--json"]
    reads = _reads(monkeypatch)
    assert main(args) == 0
    assert reads == {"gyro": 1, "T1": 1, "T2": 1, "T3": 1, "T4": 1}
    assert json.loads(capsys.readouterr().out)["n_samples"] == N


def test_inspect_reads_each_column_at_most_twice(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    src = _file(tmp_path)
    reads = _reads(monkeypatch)
    assert main(["inspect", str(src), "--json"]) == 0
    # the checks read every column once, the summaries every column but the signal once more
    assert reads == {"gyro": 1, "T1": 2, "T2": 2, "T3": 2, "T4": 2}
    assert set(json.loads(capsys.readouterr().out)["thermometers"]) == {"T1", "T2", "T3", "T4"}
