"""Bounded work on inputs of any size (issue 39 item 10, "What to build" 4), through the CLI.

Every attack here is generated in code under ``tmp_path``, run through
:func:`thermocal.cli.main` with a small budget given by option, every input hashed before
and after, and guarded by an alarm: a regression to a hang fails the test instead of
blocking CI.  The outcome is exit 2 with exactly one ``error:`` line naming the file and
the option that gets the user further, or exit 0 with the right numbers.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from types import FrameType

import numpy as np
import pytest

from fleet_data import CHANNELS, TEMP, config_text, write_run
from thermocal.cli import main

ALARM_S = 20


@pytest.fixture(autouse=True)
def _alarm() -> Iterator[None]:
    """Each test fails after :data:`ALARM_S` seconds instead of hanging."""

    def ring(_sig: int, _frame: FrameType | None) -> None:
        raise TimeoutError(f"the command ran beyond {ALARM_S} s (a hang)")

    old = signal.signal(signal.SIGALRM, ring)
    signal.alarm(ALARM_S)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _digests(folder: Path) -> dict[Path, str]:
    return {p: _digest(p) for p in folder.rglob("*") if p.is_file()}


def _refused(code: int, err: str, *needles: str) -> str:
    """Exit 2, no traceback, exactly one ``error:`` line holding every needle; that line."""
    assert "Traceback" not in err, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2, f"exit {code}; stderr: {err}"
    errors = [ln for ln in lines if ln.startswith("error: ")]
    assert len(errors) == 1, err
    for n in needles:
        assert n in errors[0], (n, errors[0])
    return errors[0]


def _rate_csv(path: Path, n: int, seed: int = 39) -> np.ndarray:
    """``n`` white-noise rate samples at 1 Hz in deg/h; returns them."""
    y = np.random.default_rng(seed).standard_normal(n)
    rows = "\n".join(f"{i},{v!r}" for i, v in enumerate(y.tolist()))
    path.write_text("time_s,gyro_x [deg/h]\n" + rows + "\n")
    return y


# --- the total family and Theo1: estimate first, refuse beyond the budget ------------------


def _mtot_ops(n_phase: int, ms: list[int]) -> float:
    """SP 1065 eq. 27: N − 3m + 1 subsequences, each extended to 9m points; at m ≤ 2 taken
    one by one, about ten arithmetic operations per extended point (detrend, centre,
    reflect, running sum, block second difference, square); above, all subsequences at once
    from running sums, about 400 operations per phase point whatever m."""
    return sum(
        10.0 * 9 * m * (n_phase - 3 * m + 1) if m <= 2 else 400.0 * n_phase
        for m in ms
        if n_phase - 3 * m + 1 > 0
    )


def _mtotdev_direct(x: np.ndarray, m: int) -> float:
    """NIST SP 1065 eq. 27 written out term by term (an independent reference): each
    3m-point subsequence, its half-mean slope removed, extended by even reflection to 9m
    points; the modified second differences of its m-point block averages, averaged over
    the 6m of them; averaged over the subsequences; divided by 2τ² (τ0 = 1)."""
    n = x.size
    outer = []
    for i in range(n - 3 * m + 1):
        seq = x[i : i + 3 * m].copy()
        h = 3 * m // 2
        slope = (seq[3 * m - h :].mean() - seq[:h].mean()) / ((3 * m + 1) // 2)
        seq = seq - slope * np.arange(3 * m)
        seq -= seq.mean()
        ext = np.concatenate([seq[::-1], seq, seq[::-1]])
        inner = []
        for j in range(6 * m):
            a = ext[j : j + m].mean()
            b = ext[j + m : j + 2 * m].mean()
            c = ext[j + 2 * m : j + 3 * m].mean()
            inner.append((a - 2 * b + c) ** 2)
        outer.append(np.mean(inner))
    return math.sqrt(np.mean(outer) / (2.0 * m * m))


def test_mtotdev_all_taus_refused_up_front_with_its_estimate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """4000 samples at every τ took 233 s (issue 39 item 10); every τ costs O(N) since,
    so it is 20000 samples at every τ (6666 factors of 20001 points) that are refused at
    once, the estimate in the message equal to the count of the terms, the options named."""
    f = tmp_path / "w.csv"
    _rate_csv(f, 20_000)
    before = _digests(tmp_path)
    code = main(["allan", str(f), "--signal", "gyro_x [deg/h]", "--deviation", "mtotdev",
                 "--taus", "all", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    line = _refused(code, err, str(f), "--taus", "--max-work", "mtotdev")
    assert out == ""
    expected = _mtot_ops(20_001, list(range(1, 20_001 // 3 + 1)))
    assert f"about {expected:.2g} operations" in line
    assert _digests(tmp_path) == before


def test_the_budget_is_the_option_and_a_raised_budget_gives_sp1065s_numbers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """60 samples, mtotdev at m = 1…20: refused just below its estimate, computed just at
    it, and the values those of SP 1065 eq. 27 written out in the test."""
    f = tmp_path / "w.csv"
    y = _rate_csv(f, 60)
    need = _mtot_ops(61, list(range(1, 21)))
    argv = ["allan", str(f), "--signal", "gyro_x [deg/h]", "--deviation", "mtotdev",
            "--taus", "all", "--json"]  # fmt: skip
    code = main([*argv, "--max-work", repr(need * 0.999)])
    _o, err = capsys.readouterr()
    _refused(code, err, str(f), "--max-work")
    code = main([*argv, "--max-work", repr(need * 1.001)])
    out, err = capsys.readouterr()
    assert code == 0, err
    got = json.loads(out)
    x = np.concatenate([[0.0], np.cumsum(y - y.mean())])
    ref = [_mtotdev_direct(x, m) for m in range(1, 21)]
    np.testing.assert_allclose(got["mtotdev"], ref, rtol=1e-9)


def test_the_total_family_at_1e5_samples_beyond_a_budget(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """1e5 samples at octave τ: the total family (about 1.2e9 operations since each τ
    costs O(N)) refused up front by a budget of 1e9, naming --max-work; no output, the
    input unchanged."""
    f = tmp_path / "big.csv"
    _rate_csv(f, 100_000)
    before = _digests(tmp_path)
    code = main(["allan", str(f), "--signal", "gyro_x [deg/h]", "--deviation",
                 "mtotdev,htotdev", "--max-work", "1e9", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    line = _refused(code, err, str(f), "--max-work", "mtotdev")
    assert out == ""
    octave = [2**k for k in range(17) if 2**k <= 100_001 // 3]
    assert f"mtotdev: {_mtot_ops(100_001, octave):.2g}" in line
    assert _digests(tmp_path) == before


@pytest.mark.parametrize("value", ["0", "-1", "nan"])
def test_a_budget_that_is_not_positive_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], value: str
) -> None:
    f = tmp_path / "w.csv"
    _rate_csv(f, 50)
    code = main(["allan", str(f), "--signal", "gyro_x [deg/h]", "--deviation", "oadev",
                 "--max-work", value])  # fmt: skip
    _o, err = capsys.readouterr()
    _refused(code, err, "--max-work")


def test_theo1_at_every_tau_is_refused_with_eq30s_count(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Theo1 (SP 1065 eq. 30) at every τ of 3000 samples: N − m terms of m/2 lags each for
    every even m < N; about four operations per (term, lag)."""
    f = tmp_path / "w.csv"
    _rate_csv(f, 3000)
    n = 3001
    expected = sum(4.0 * (m / 2) * (n - m) for m in range(2, n, 2))
    code = main(["allan", str(f), "--signal", "gyro_x [deg/h]", "--deviation", "theo1",
                 "--taus", "all", "--max-work", repr(0.99 * expected)])  # fmt: skip
    _o, err = capsys.readouterr()
    line = _refused(code, err, str(f), "--max-work", "--taus all")
    assert f"(theo1: {expected:.2g})" in line


def test_theo1_at_the_records_end_has_an_open_interval_not_an_exit_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Theo1's empirical EDF of random-walk FM (as ``--taus all`` identifies it there) at
    τ ≈ 0.84 of 3000 samples falls to ≈ 0.005 and below: the
    χ² quantile is 0 and the upper bound unbounded (null in JSON), not a divide-by-zero
    turned into ``error: internal`` (exit 1).  The value itself is SP 1065 eq. 30 written
    out in the test."""
    f = tmp_path / "w.csv"
    y = _rate_csv(f, 3000)
    code = main(["allan", str(f), "--signal", "gyro_x [deg/h]", "--deviation", "theo1",
                 "--taus", "1891.5,1893", "--noise-type", "rwfm", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    got = json.loads(out)
    assert got["theo1_tau_s"] == [1891.5, 1893.0]
    x = np.concatenate([[0.0], np.cumsum(y - y.mean())])
    n = x.size
    ref = []
    for m in (2522, 2524):
        h = m // 2
        s = sum(
            ((x[i] - x[i - d + h]) + (x[i + m] - x[i + d + h])) ** 2 / (h - d)
            for i in range(n - m)
            for d in range(h)
        )
        ref.append(math.sqrt(s / (0.75 * m * m * (n - m))))
    np.testing.assert_allclose(got["theo1"], ref, rtol=1e-9)
    assert 0 < got["theo1_edf"][0] < 0.01
    assert got["theo1_high"][0] is None or got["theo1_high"][0] > got["theo1"][0]


# --- special files: refused by stat, never opened ------------------------------------------


def _fifo(path: Path) -> Path:
    os.mkfifo(path)
    return path


def _good_model(tmp: Path, capsys: pytest.CaptureFixture[str]) -> tuple[Path, Path]:
    """A recording (fleet_data's run) and the model ``fit`` writes of it."""
    run = tmp / "run.csv"
    write_run(run, 3)
    model = tmp / "model.json"
    code = main(["fit", str(run), "--model", "poly", "--order", "1", "--signal",
                 next(iter(CHANNELS)), "--temps", TEMP, "-o", str(model)])  # fmt: skip
    _o, err = capsys.readouterr()
    assert code == 0, err
    return run, model


def test_a_fifo_as_a_fleet_modelling_file_is_refused_up_front(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The FIFO hung ``fleet`` (its hash opened it, then the reader): now exit 2 naming the
    FIFO and its unit, nothing written, the other unit's file unchanged."""
    write_run(tmp_path / "U1.csv", 1)
    fifo = _fifo(tmp_path / "U2.csv")
    cfg = tmp_path / "batch.toml"
    cfg.write_text(config_text({"U1": ("U1.csv", None), "U2": ("U2.csv", None)}))
    before = {p: _digest(p) for p in (cfg, tmp_path / "U1.csv")}
    code = main(["fleet", str(cfg), "-o", str(tmp_path / "out"), "--workers", "1"])
    _o, err = capsys.readouterr()
    _refused(code, err, str(fifo), "FIFO", "U2")
    assert not (tmp_path / "out").exists()
    assert {p: _digest(p) for p in before} == before


def test_a_fifo_as_the_fleet_configuration_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fifo = _fifo(tmp_path / "batch.toml")
    code = main(["fleet", str(fifo), "-o", str(tmp_path / "out")])
    _o, err = capsys.readouterr()
    _refused(code, err, str(fifo), "FIFO")


@pytest.mark.parametrize("command", ["inspect", "metrics", "allan", "fit"])
def test_a_fifo_as_a_recording_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    fifo = _fifo(tmp_path / "run.csv")
    extra = {"fit": ["--model", "poly", "-o", str(tmp_path / "m.json")], "allan": ["--signal", "x"]}
    code = main([command, str(fifo), *extra.get(command, [])])
    _o, err = capsys.readouterr()
    _refused(code, err, str(fifo), "FIFO")


def test_a_character_device_as_a_recording_is_refused(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``/dev/zero`` never ends: refused by its mode, not read."""
    code = main(["inspect", "/dev/zero"])
    _o, err = capsys.readouterr()
    _refused(code, err, "/dev/zero", "character device")


@pytest.mark.parametrize("which", ["model", "data"])
def test_compensate_refuses_a_fifo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], which: str
) -> None:
    run, model = _good_model(tmp_path, capsys)
    fifo = _fifo(tmp_path / ("m.json" if which == "model" else "d.csv"))
    args = [str(fifo), str(run)] if which == "model" else [str(model), str(fifo)]
    out = tmp_path / "out.csv"
    code = main(["compensate", *args, "-o", str(out)])
    _o, err = capsys.readouterr()
    _refused(code, err, str(fifo), "FIFO")
    assert not out.exists()


# --- line length: a text reader refuses a line beyond its bound, naming it ------------------


def _log_with_long_line(path: Path, sep: str, long_at: int, long_chars: int) -> None:
    """A text log with a header, data lines and at data line ``long_at`` one line of
    ``long_chars`` characters (fields ``1`` separated by ``sep``)."""
    rows = [sep.join(["time [s]", "gx [deg/s]", "T1 [degC]"])]
    for i in range(1, 8):
        rows.append(sep.join([str(i), "0.5", str(20 + i)]))
    rows.insert(long_at - 1, (("1" + sep) * (long_chars // 2))[:long_chars])
    path.write_text("\n".join(rows) + "\n")


@pytest.mark.parametrize("sep", [",", ";"])
@pytest.mark.parametrize("command", ["compensate", "inspect", "fit"])
def test_a_10mb_line_is_refused_naming_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], sep: str, command: str
) -> None:
    """A 10 MB line of five million fields hung ``compensate`` (the layout detection took
    it field by field): now exit 2 at once naming the file and line 2."""
    f = tmp_path / ("log.csv" if sep == "," else "log.txt")
    _log_with_long_line(f, sep, 2, 10_000_000)
    argv = {
        "inspect": ["inspect", str(f)],
        "fit": ["fit", str(f), "--model", "poly", "-o", str(tmp_path / "m.json")],
    }.get(command)
    if argv is None:  # compensate: a good model first
        (tmp_path / "good").mkdir()
        _run, model = _good_model(tmp_path / "good", capsys)
        argv = ["compensate", str(model), str(f), "-o", str(tmp_path / "o.csv")]
    before = _digests(tmp_path)
    code = main(argv)
    _o, err = capsys.readouterr()
    _refused(code, err, str(f), "line 2 ", "THERMOCAL_MAX_LINE")
    assert len(err) < 1000  # the line itself is not echoed
    assert not (tmp_path / "o.csv").exists() and not (tmp_path / "m.json").exists()
    assert _digests(tmp_path) == before


def test_the_line_bound_is_exact_and_set_by_the_environment(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """THERMOCAL_MAX_LINE = 40: a data line of exactly 40 characters (a zero-padded time)
    is read and its value kept; one of 41 is refused naming line 5."""
    monkeypatch.setenv("THERMOCAL_MAX_LINE", "40")
    f = tmp_path / "log.txt"
    lines = ["time [s];gx [deg/s];T1 [degC]"] + [f"{i};0.5;{20 + i}" for i in range(1, 8)]
    padded = "4".zfill(40 - len(";0.5;24"))
    lines[4] = f"{padded};0.5;24"
    assert len(lines[4]) == 40
    f.write_text("\n".join(lines) + "\n")
    code = main(["inspect", str(f), "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert json.loads(out)["n_samples"] == 7
    lines[4] = "0" + lines[4]
    f.write_text("\n".join(lines) + "\n")
    code = main(["inspect", str(f)])
    _o, err = capsys.readouterr()
    _refused(code, err, str(f), "line 5 ", "40 characters")


def test_a_long_line_past_the_layout_lines_is_refused_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Below the 400 lines the layout is found from: the text reader's own bound (line 450
    named), not a split into two million fields."""
    f = tmp_path / "log.txt"
    rows = ["time [s];gx [deg/s];T1 [degC]"] + [f"{i};0.5;25" for i in range(1, 600)]
    rows[449] = "1;" * 2_000_000
    f.write_text("\n".join(rows) + "\n")
    code = main(["inspect", str(f)])
    _o, err = capsys.readouterr()
    _refused(code, err, str(f), "line 450 ", "THERMOCAL_MAX_LINE")


# --- fleets: the scheduler's address, a worker's memory, a worker that dies ----------------


def _two_units(root: Path) -> Path:
    write_run(root / "U1.csv", 1)
    write_run(root / "U2.csv", 2)
    cfg = root / "batch.toml"
    cfg.write_text(config_text({"U1": ("U1.csv", None), "U2": ("U2.csv", None)}))
    return cfg


@pytest.mark.parametrize(
    "address", ["not a url", "tcp://", "foo://host:8786", "inproc://x", "host:99999", "host"]
)
def test_a_scheduler_that_is_not_an_address_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], address: str
) -> None:
    """``--scheduler 'not a url'`` ended in Dask's ValueError, exit 1, with the output
    folder made: now exit 2 naming --scheduler, nothing written."""
    pytest.importorskip("distributed")
    cfg = _two_units(tmp_path)
    before = _digests(tmp_path)
    code = main(["fleet", str(cfg), "-o", str(tmp_path / "out"), "--scheduler", address])
    _o, err = capsys.readouterr()
    _refused(code, err, "--scheduler", repr(address))
    assert not (tmp_path / "out").exists()
    assert _digests(tmp_path) == before


class _KilledWorker(Exception):
    """Dask's own: raised by a future whose task's worker died too often."""


_KilledWorker.__module__ = "distributed.scheduler"


class _Future:
    def __init__(self, fn: object, task: object, key: str, kill: bool) -> None:
        self.fn, self.task, self.key, self.kill = fn, task, key, kill

    def result(self) -> object:
        if self.kill:
            raise _KilledWorker(f"Attempted to run task {self.key!r} on 4 different workers")
        return self.fn(self.task)  # type: ignore[operator]


def _fake_distributed(kill_unit: str, memory_limit: float | None = None) -> object:
    """A stand-in for the ``distributed`` module: a client that runs each task here (the
    unit ``kill_unit``'s future raises KilledWorker, as when its worker dies), and, with
    ``memory_limit``, a worker of that memory limit and one thread."""
    from types import SimpleNamespace

    class Client:
        def __init__(self, address: str, timeout: float) -> None:
            self.address = address

        def map(self, fn: object, tasks: list[object], pure: bool, key: list[str]) -> list[_Future]:
            return [
                _Future(fn, t, k, kill=t.unit.id == kill_unit)  # type: ignore[attr-defined]
                for t, k in zip(tasks, key, strict=True)
            ]

        def close(self) -> None:
            pass

    def get_worker() -> object:
        if memory_limit is None:
            raise ValueError("No worker found")
        return SimpleNamespace(
            memory_manager=SimpleNamespace(memory_limit=memory_limit), nthreads=1
        )

    return SimpleNamespace(Client=Client, as_completed=iter, get_worker=get_worker)


def test_a_unit_whose_worker_dies_is_failed_and_its_file_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The worker running U2 dies (KilledWorker): U2 is a failed unit whose error names
    its file (a warning line, the summary, exit 4), U1 is calibrated — not a batch stopped
    with U2 lost."""
    import pandas as pd

    monkeypatch.setitem(sys.modules, "distributed", _fake_distributed("U2"))
    cfg = _two_units(tmp_path)
    out = tmp_path / "out"
    code = main(["fleet", str(cfg), "-o", str(out), "--scheduler", "tcp://127.0.0.1:8786"])
    _o, err = capsys.readouterr()
    assert code == 4, err
    assert "Traceback" not in err
    warn = [ln for ln in err.splitlines() if ln.startswith("warning: unit U2:")]
    assert len(warn) == 1 and str(tmp_path / "U2.csv") in warn[0] and "died" in warn[0], err
    rows = pd.read_csv(out / "summary.csv").set_index("id")
    assert rows.loc["U1", "status"] == "ok"
    assert rows.loc["U2", "status"] == "failed"
    assert str(tmp_path / "U2.csv") in rows.loc["U2", "error"]


def test_a_unit_on_a_dask_worker_reads_within_the_workers_memory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A 200 000-row Parquet run needs 200 000 × (5 · 8 + 40) B = 16 MB to read (five
    columns used; readers.common.check_memory); on a worker of 20 MB (a unit may use half)
    it is refused naming the file instead of the nanny killing the worker; the small unit
    beside it is calibrated."""
    import pandas as pd

    monkeypatch.setitem(sys.modules, "distributed", _fake_distributed("", memory_limit=20e6))
    cfg = _two_units(tmp_path)
    big = pd.read_csv(tmp_path / "U2.csv")
    big = big.loc[np.arange(200_000) % len(big)].reset_index(drop=True)
    big["time [s]"] = np.arange(len(big), dtype=float)
    big.to_parquet(tmp_path / "U2.parquet", index=False)
    cfg.write_text(config_text({"U1": ("U1.csv", None), "U2": ("U2.parquet", None)}))
    out = tmp_path / "out"
    code = main(["fleet", str(cfg), "-o", str(out), "--workers", "1"])
    _o, err = capsys.readouterr()
    assert code == 4, err
    rows = pd.read_csv(out / "summary.csv").set_index("id")
    assert rows.loc["U1", "status"] == "ok"
    assert rows.loc["U2", "status"] == "failed"
    assert str(tmp_path / "U2.parquet") in rows.loc["U2", "error"]
    assert "memory" in rows.loc["U2", "error"]


def test_dasks_log_records_do_not_reach_stderr(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A lost connection makes Dask's client log its traceback (``distributed.client``,
    which Dask's configuration gives its own level): none of it is emitted while the batch
    runs; stderr holds the command's own lines only."""
    import logging

    fake = _fake_distributed("U2")
    client_cls = fake.Client  # type: ignore[attr-defined]

    class LoggingClient(client_cls):  # type: ignore[misc,valid-type]
        def map(self, *args: object, **kwargs: object) -> list[_Future]:
            for name in ("distributed.client", "distributed.core", "tornado.application"):
                logging.getLogger(name).error("Traceback (most recent call last): ... lost")
            return super().map(*args, **kwargs)  # type: ignore[no-any-return]

    fake.Client = LoggingClient  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "distributed", fake)
    own = logging.getLogger("distributed.client")
    monkeypatch.setattr(own, "level", logging.WARNING)  # as Dask's configuration sets it
    cfg = _two_units(tmp_path)
    with caplog.at_level(logging.DEBUG):
        code = main(["fleet", str(cfg), "-o", str(tmp_path / "out"), "--scheduler",
                     "tcp://127.0.0.1:8786"])  # fmt: skip
    _o, err = capsys.readouterr()
    assert code == 4, err
    assert [r.name for r in caplog.records if r.name.startswith(("distributed", "tornado"))] == []
    assert all(ln.startswith(("warning: ", "error: ")) for ln in err.splitlines() if ln), err
    assert own.level == logging.WARNING  # restored


def test_a_dynamic_adev_of_tens_of_thousands_of_windows_is_refused_up_front(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--dynamic 8`` on 1e5 samples at 1 Hz: windows of 8 samples, 4 apart, so
    (100 000 − 8) // 4 + 1 = 24 999 windows (≈ 7 minutes): refused at once naming the
    window count, --dynamic and --max-work; a budget raised past the estimate of a
    shorter record lets it run."""
    f = tmp_path / "big.csv"
    _rate_csv(f, 100_000)
    code = main(["allan", str(f), "--signal", "gyro_x [deg/h]", "--dynamic", "8"])
    out, err = capsys.readouterr()
    _refused(code, err, str(f), "--dynamic 8 s", f"{(100_000 - 8) // 4 + 1} windows", "--max-work")
    assert out == ""
    small = tmp_path / "small.csv"
    _rate_csv(small, 400)
    windows = (400 - 8) // 4 + 1
    argv = ["allan", str(small), "--signal", "gyro_x [deg/h]", "--dynamic", "8", "--json"]
    code = main([*argv, "--max-work", repr(windows * 1.5e7)])
    _o, err = capsys.readouterr()
    _refused(code, err, f"{windows} windows")
    code = main([*argv, "--max-work", repr(windows * 1.6e7)])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert len(json.loads(out)["dynamic"]["t_s"]) == windows


# --- memory: the Parquet metadata's row count against half the available memory ------------


def _declared_parquet(path: Path, rows: int) -> None:
    """A small Parquet file (constant columns compress to almost nothing) of ``rows`` rows."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    time = pa.array(np.arange(rows, dtype=np.float64))
    zeros = pa.array(np.zeros(rows))
    table = pa.table({"time [s]": time, "gx [deg/s]": zeros, "T1 [degC]": zeros})
    pq.write_table(table, path, compression="zstd")


@pytest.mark.parametrize("command", ["inspect", "metrics"])
def test_a_parquet_declaring_more_rows_than_half_the_memory_is_refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    command: str,
) -> None:
    """With 40 MB available, a read may take 20 MB: 400 000 rows of three columns need
    400 000 × (3 · 8 + 40) B = 25.6 MB (the metadata's row count, before any column is
    read): refused naming the file and THERMOCAL_MEMORY_LIMIT; raised by it, read."""
    import thermocal.readers.common as rc

    monkeypatch.delenv("THERMOCAL_MEMORY_LIMIT", raising=False)
    monkeypatch.setattr(rc, "mem_available_bytes", lambda: 40_000_000)
    f = tmp_path / "run.parquet"
    _declared_parquet(f, 400_000)
    assert f.stat().st_size < 2_000_000
    before = _digests(tmp_path)
    extra = ["--signal", "gx [deg/s]", "--temps", "T1 [degC]"] if command == "metrics" else []
    code = main([command, str(f), *extra])
    _o, err = capsys.readouterr()
    _refused(code, err, str(f), "THERMOCAL_MEMORY_LIMIT", "400,000 rows")
    assert _digests(tmp_path) == before
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", "200M")
    code = main([command, str(f), *extra, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    if command == "inspect":
        assert json.loads(out)["n_samples"] == 400_000


@pytest.mark.parametrize("value", ["nan", "inf", "-5", "0", "12Q"])
def test_a_memory_limit_that_is_not_a_size_is_refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    value: str,
) -> None:
    """``THERMOCAL_MEMORY_LIMIT=inf`` ended in OverflowError (exit 1), ``-5`` refused every
    read with a negative limit: exit 2 naming the variable."""
    monkeypatch.setenv("THERMOCAL_MEMORY_LIMIT", value)
    f = tmp_path / "run.parquet"
    _declared_parquet(f, 100)
    code = main(["inspect", str(f)])
    _o, err = capsys.readouterr()
    _refused(code, err, "THERMOCAL_MEMORY_LIMIT", repr(value))


@pytest.mark.parametrize(
    ("command", "name"), [("ardupilot-tempcal", "log.bin"), ("px4-tempcal", "log.ulg")]
)
def test_a_fifo_as_a_flight_log_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, name: str
) -> None:
    """``ardupilot-tempcal`` on a FIFO hung in pymavlink's open: refused by its mode."""
    fifo = _fifo(tmp_path / name)
    out = tmp_path / "out.params"
    code = main([command, str(fifo), "-o", str(out)])
    _o, err = capsys.readouterr()
    _refused(code, err, str(fifo), "FIFO")
    assert not out.exists()


def test_a_directory_as_a_fleet_modelling_file_is_refused_up_front(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A plain directory (not a station's recording folder) as U2's file: exit 2 naming it
    and the unit before anything is written; ``inspect`` on it names it too (it printed
    ``[Errno 21] Is a directory``)."""
    write_run(tmp_path / "U1.csv", 1)
    (tmp_path / "U2.csv").mkdir()
    cfg = tmp_path / "batch.toml"
    cfg.write_text(config_text({"U1": ("U1.csv", None), "U2": ("U2.csv", None)}))
    code = main(["fleet", str(cfg), "-o", str(tmp_path / "out"), "--workers", "1"])
    _o, err = capsys.readouterr()
    _refused(code, err, str(tmp_path / "U2.csv"), "U2", "is a directory")
    assert not (tmp_path / "out").exists()
    code = main(["inspect", str(tmp_path / "U2.csv")])
    _o, err = capsys.readouterr()
    _refused(code, err, str(tmp_path / "U2.csv"), "is a directory", "station")


@pytest.mark.parametrize("sep", [",", ";"])
@pytest.mark.parametrize("command", ["compensate", "inspect"])
def test_a_table_of_300_000_columns_is_refused_before_pandas_sees_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], sep: str, command: str
) -> None:
    """300 000 one-letter columns fit in a 600 kB line (under the line bound); pandas
    builds an object per column before it reads a row (minutes: compensate did not finish
    in 60 s): refused naming the file and the count, 300 000 > 10 000."""
    f = tmp_path / ("wide.csv" if sep == "," else "wide.txt")
    k = 300_000
    f.write_text(sep.join(["t"] + ["a"] * (k - 1)) + "\n" + (sep.join(["1"] * k) + "\n") * 2)
    if command == "compensate":
        (tmp_path / "good").mkdir()
        _run, model = _good_model(tmp_path / "good", capsys)
        argv = ["compensate", str(model), str(f), "-o", str(tmp_path / "o.csv")]
    else:
        argv = ["inspect", str(f)]
    code = main(argv)
    _o, err = capsys.readouterr()
    _refused(code, err, str(f), "300,000", "10,000 columns")
    assert not (tmp_path / "o.csv").exists()


# --- survivors of issue 39 in the family: Theo1's noise τ, the Hadamard α range ----------


def test_theo1s_noise_is_identified_at_its_own_tau_not_at_m(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Theo1 at factor m averages over τ = 0.75 m τ0 (SP 1065 eq. 30): its EDF's noise is
    the noise at the factor round(0.75 m).  Phase data of white PM plus a random walk
    (white FM), whose lag-1 identification changes between factors 12 and 16: at every τ
    identified by the lag-1 test the α the command reports is the one
    :func:`thermocal.stability.edf.identify_noise` gives at round(0.75 m) on the phase
    minus its end-point line (written out here), and at m = 16 that differs from m's."""
    from thermocal.stability.edf import identify_noise

    rng = np.random.default_rng(7)
    n = 20_000
    x = rng.standard_normal(n) + 0.4 * np.cumsum(rng.standard_normal(n))
    f = tmp_path / "phase.csv"
    f.write_text(
        "time_s,phase [s]\n" + "\n".join(f"{i},{v!r}" for i, v in enumerate(x.tolist())) + "\n"
    )
    code = main(["allan", str(f), "--signal", "phase [s]", "--data-type", "phase",
                 "--deviation", "theo1", "--taus", "octave", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    got = json.loads(out)
    k = np.arange(n, dtype=np.float64)
    xc = x - (x[0] + (x[-1] - x[0]) * k / (n - 1))

    def alpha_at(m: int) -> int:
        return max(min(identify_noise(xc, m, dmax=2, phase_input=True).alpha, 2), -2)

    ms = [round(t / 0.75) for t in got["theo1_tau_s"]]
    checked = 0
    for m, a, how in zip(ms, got["theo1_alpha"], got["theo1_alpha_method"], strict=True):
        if how == "lag1":
            assert a == alpha_at(max(1, round(0.75 * m))), (m, a)
            checked += 1
    assert checked >= 5
    assert alpha_at(12) != alpha_at(16)  # the record tells the two factors apart


def test_random_run_fm_keeps_its_hadamard_alpha_of_minus_4(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Rate samples integrated twice from white noise are random-run FM, S_y ∝ f⁻⁴ (α = −4,
    SP 1065 Table 1; the simulator's truth): the Hadamard deviations, defined down to
    α = −4, identify it so at every τ the lag-1 test reads, not clipped to −2 as the Allan
    family is."""
    rng = np.random.default_rng(4)
    y = np.cumsum(np.cumsum(rng.standard_normal(4096)))
    f = tmp_path / "rrfm.csv"
    f.write_text(
        "time_s,y [deg/h]\n" + "\n".join(f"{i},{v!r}" for i, v in enumerate(y.tolist())) + "\n"
    )
    code = main(["allan", str(f), "--signal", "y [deg/h]", "--deviation", "hdev,ohdev",
                 "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    got = json.loads(out)
    for name in ("hdev", "ohdev"):
        lag1 = [a for a, how in zip(got[f"{name}_alpha"], got[f"{name}_alpha_method"],
                                    strict=True) if how == "lag1"]  # fmt: skip
        assert len(lag1) >= 6 and set(lag1) == {-4}, (name, got[f"{name}_alpha"])
