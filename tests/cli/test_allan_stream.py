"""``thermocal allan`` on a record too long for memory: analysed window by window by
itself (the Parquet metadata against THERMOCAL_MEMORY_LIMIT) or with ``--stream``; the
same JSON as the in-memory run, one error line for what it cannot do, Ctrl-C cleans up."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.cli import main

ARGS = ["--signal", "gyro", "--signal-unit", "deg/h", "--time-unit", "s", "--json"]


def _write(path: Path, n: int) -> Path:
    rng = np.random.default_rng(21)
    t = np.arange(n) * 0.002
    t[n // 2 :] += 1.0  # a gap
    y = rng.normal(0.0, 1.0, n) + np.cumsum(rng.normal(0.0, 0.001, n))
    pq.write_table(pa.table({"time": t, "gyro": y}), path, row_group_size=65_537)
    return path


def test_too_large_for_memory_is_streamed_with_the_same_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _write(tmp_path / "fog.parquet", 200_003)
    assert main(["allan", str(path), *ARGS]) == 0
    in_memory = capsys.readouterr()
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", "1M")  # 200 003 rows need 11 MB
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    assert main(["allan", str(path), *ARGS]) == 0
    streamed = capsys.readouterr()
    assert json.loads(streamed.out) == json.loads(in_memory.out)
    assert "1 gaps in time" in streamed.err
    assert [p.name for p in tmp_path.iterdir()] == ["fog.parquet"]


def test_stream_refuses_the_in_memory_options_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _write(tmp_path / "fog.parquet", 5_000)
    assert main(["allan", str(path), *ARGS, "--stream", "--deviation", "mdev"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("error:")]
    assert err == [
        f"error: {path}: analysed window by window (--stream given), which takes the default "
        "analysis of one channel at octave τ only; drop --deviation, or cut the record"
    ]
    assert main(["allan", str(path), *ARGS, "--stream", "--taus", "decade"]) == 2
    assert "give --taus octave" in capsys.readouterr().err


def test_ctrl_c_while_streaming_exits_130_and_removes_the_temporaries(tmp_path: Path) -> None:
    path = _write(tmp_path / "fog.parquet", 3_000_000)
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    plot = tmp_path / "adev.png"
    env = {**os.environ, "TMPDIR": str(scratch)}
    code = "import sys; from thermocal.cli import main; sys.exit(main())"
    proc = subprocess.Popen(
        [sys.executable, "-c", code, "allan", str(path), *ARGS, "--stream", "--plot", str(plot)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
    )  # fmt: skip
    end = time.monotonic() + 120
    while not any(f.stat().st_size > 1_000_000 for f in scratch.rglob("*.f64")):
        if proc.poll() is not None or time.monotonic() > end:
            proc.kill()
            _, err = proc.communicate()
            pytest.fail(f"no temporary seen before the end: {err!r}")
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert err.decode().strip().splitlines()[-1] == "interrupted: nothing written"
    assert list(scratch.iterdir()) == []
    assert not plot.exists()
