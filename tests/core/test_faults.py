"""Faults during writes (issue 14): SIGKILL and Ctrl-C mid-write, stale temporaries, two
writers of one output.  Each test runs the real command line in a subprocess."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.errors import FileFormatError
from thermocal.outputs import TEMP_SUFFIX
from thermocal.readers.dispatch import read_recording
from thermocal.writers import remove_stale_temporaries

N_BIG = 400_000
"""Rows of the file compensated while it is killed: several seconds of writing."""


def _cli(*args: str) -> list[str]:
    return [
        sys.executable,
        "-c",
        "import sys; from thermocal.cli import main; sys.exit(main())",
        *args,
    ]


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A fitted linear model and a large CSV to compensate with it."""
    d = tmp_path_factory.mktemp("faults")
    rng = np.random.default_rng(7)
    n = 2000
    temp = np.linspace(-10.0, 50.0, n)
    small = pd.DataFrame(
        {
            "time": np.arange(n, dtype=float),
            "gyro": 0.02 * temp + rng.normal(0, 0.01, n),
            "T1": temp,
        }
    )
    small.to_csv(d / "fit.csv", index=False)
    model = d / "model.json"
    subprocess.run(
        _cli("fit", str(d / "fit.csv"), "--model", "poly", "--order", "1", "--signal", "gyro",
             "--signal-unit", "deg/h", "--temps", "T1", "--temp-unit", "degC",
             "--time-unit", "s", "-o", str(model)),
        check=True, capture_output=True,
    )  # fmt: skip
    t = np.arange(N_BIG, dtype=float) * 0.01
    big = pd.DataFrame(
        {"time": t, "gyro": rng.normal(0, 0.01, N_BIG), "T1": 20.0 + 10.0 * np.sin(t / 3000.0)}
    )
    big.to_csv(d / "big.csv", index=False)
    return model, d / "big.csv"


def _start_compensate(model: Path, src: Path, out: Path) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        # small chunks: the temporary grows chunk by chunk, so the test sees it part-written
        # whatever the speed of the machine and the Parquet writer's buffering (the floor's
        # pyarrow wrote the first 50 kB at the end of a 500 000-row chunk: a flaky test)
        _cli("compensate", str(model), str(src), "-o", str(out), "--signal-unit", "deg/h",
             "--temp-unit", "degC", "--time-unit", "s", "--chunk-rows", "20000"),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip


def _wait_for_partial(out: Path, proc: subprocess.Popen[bytes], timeout_s: float = 60.0) -> Path:
    """Wait until the writer has a temporary with data in it, then return it."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        parts = list(out.parent.glob(f".{out.name}.*{TEMP_SUFFIX}"))
        if parts and parts[0].stat().st_size > 50_000:
            return parts[0]
        if proc.poll() is not None:
            _, err = proc.communicate()  # closes the pipes (no ResourceWarning later)
            pytest.fail(f"the writer ended before it was killed: {err!r}")
        time.sleep(0.02)
    proc.kill()
    pytest.fail("no temporary appeared")


def test_sigkill_mid_write_leaves_nothing_a_reader_accepts(
    setup: tuple[Path, Path], tmp_path: Path
) -> None:
    model, src = setup
    out = tmp_path / "out.csv"
    proc = _start_compensate(model, src, out)
    partial = _wait_for_partial(out, proc)
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    assert not out.exists()
    assert partial.exists()  # SIGKILL cannot clean up: the temporary stays...
    with pytest.raises(FileFormatError, match="unfinished output"):
        read_recording(partial)  # ...but no reader takes it for a result
    # a rerun to the same output removes the stale temporary and leaves only the result
    proc = _start_compensate(model, src, out)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "out.csv.meta.json"]
    df = pd.read_csv(out, usecols=["gyro_comp"])
    assert len(df) == N_BIG


def test_ctrl_c_mid_write_exits_130_and_says_what_was_kept(
    setup: tuple[Path, Path], tmp_path: Path
) -> None:
    model, src = setup
    out = tmp_path / "out.parquet"
    proc = _start_compensate(model, src, out)
    _wait_for_partial(out, proc)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.decode().strip().splitlines()[-1] == "interrupted: nothing written"
    assert "Traceback" not in err.decode()
    assert list(tmp_path.iterdir()) == []


def test_stale_temporaries_of_dead_writers_only_are_removed(tmp_path: Path) -> None:
    out = tmp_path / "x.csv"
    # a pid that no longer exists: a child that has exited and been reaped
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    dead = tmp_path / f".x.csv.{child.pid}.abcd{TEMP_SUFFIX}"
    live = tmp_path / f".x.csv.{os.getpid()}.ef01{TEMP_SUFFIX}"
    other = tmp_path / f".y.csv.{child.pid}.abcd{TEMP_SUFFIX}"
    for p in (dead, live, other):
        p.write_text("time\n1\n")
    removed = remove_stale_temporaries(out)
    assert removed == [dead]
    assert live.exists() and other.exists() and not dead.exists()


def test_two_writers_of_one_output_are_serialised(setup: tuple[Path, Path], tmp_path: Path) -> None:
    model, src = setup
    small = tmp_path / "src.csv"
    pd.read_csv(src, nrows=200_000).to_csv(small, index=False)
    out = tmp_path / "out.csv"
    procs = [_start_compensate(model, small, out) for _ in range(2)]
    for p in procs:
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "out.csv.meta.json", "src.csv"]
    df = pd.read_csv(out)
    assert len(df) == 200_000 and list(df.columns)[-2:] == ["gyro_model", "gyro_comp"]


def test_corrupt_parquet_written_by_thermocal_is_refused(tmp_path: Path) -> None:
    """Parquet files written by thermocal carry page checksums, verified on read: bytes
    overwritten mid-file are an error naming the file, not a silently different number."""
    from thermocal.recording import Recording
    from thermocal.writers import write_recording

    rng = np.random.default_rng(3)
    n = 200_000
    rec = Recording(
        time_s=np.arange(n) * 0.01,
        columns={"gyro": rng.normal(0.0, 1.0, n), "T1": np.full(n, 25.0)},
        units={"gyro": "deg/h", "T1": "degC"},
        signals=("gyro",),
        temperatures=("T1",),
    )
    good = tmp_path / "good.parquet"
    write_recording(rec, good)
    np.testing.assert_array_equal(read_recording(good).columns["gyro"], rec.columns["gyro"])
    bad = tmp_path / "bad.parquet"
    data = bytearray(good.read_bytes())
    mid = len(data) // 4  # inside the first column's data pages
    data[mid : mid + 2800] = rng.integers(0, 256, 2800, dtype=np.uint8).tobytes()
    bad.write_bytes(bytes(data))
    with pytest.raises(FileFormatError, match=r"bad\.parquet.*checksum"):
        read_recording(bad)
    proc = subprocess.run(
        _cli("metrics", str(bad), "--signal", "gyro", "--json"), capture_output=True, text=True
    )
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.startswith(f"error: {bad}") and "checksum" in proc.stderr


@pytest.mark.parametrize(
    ("err", "text"),
    [(errno.ENOSPC, "No space left on device"), (errno.EACCES, "Permission denied")],
)
def test_full_disk_or_no_permission_is_exit_2_naming_the_output(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    err: int,
    text: str,
) -> None:
    """An OS error while writing (a full disk, a read-only folder) is the user's environment,
    not a bug: exit 2 naming the output, and no temporary left behind."""
    import thermocal.writers as tio
    from thermocal.cli import main

    def failing_replace(src: str | Path, dst: str | Path) -> None:
        raise OSError(err, text, str(src))

    monkeypatch.setattr(tio.os, "replace", failing_replace)
    out = tmp_path / "prog.csv"
    code = main(["profile", "fog-slow", "-o", str(out)])
    _, stderr = capsys.readouterr()
    assert code == 2
    assert stderr.strip().splitlines() == [
        f"error: {out}: cannot write the output ({text}); nothing was written"
    ]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
def test_reads_that_would_not_fit_in_memory_are_refused_up_front(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], suffix: str
) -> None:
    """Issue 14: a read needing more than the memory available is refused with the
    estimate (100 000 rows × 3 columns ≈ (24 + 40) B/row ≈ 6.1 MiB against a 1 MiB limit),
    and passes under a limit that holds it."""
    import pandas as pd

    from thermocal.cli import main

    n = 100_000
    df = pd.DataFrame({"time": np.arange(n) * 0.01, "gyro": np.zeros(n), "T1": np.full(n, 25.0)})
    path = tmp_path / f"big{suffix}"
    if suffix == ".csv":
        df.to_csv(path, index=False)
    else:
        df.to_parquet(path)
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", "1M")
    code = main(["inspect", str(path), "--signal", "gyro", "--signal-unit", "deg/h",
                 "--time-unit", "s"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2
    assert ("100,000 rows" in err) == (suffix == ".parquet")  # a CSV's rows are estimated
    assert "rows of" in err and "GiB of memory" in err and "compensate" in err
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", "64M")
    code = main(["inspect", str(path), "--signal", "gyro", "--signal-unit", "deg/h",
                 "--time-unit", "s"])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", "lots")
    assert main(["inspect", str(path)]) == 2
    assert "THERMOCAL_MEMORY_LIMIT" in capsys.readouterr().err
