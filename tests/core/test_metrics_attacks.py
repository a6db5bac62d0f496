"""Hostile ``metrics FILE FILE...`` inputs (issue 39 item 9, first half), through the CLI.

A turn-on to turn-on bias repeatability is the sample standard deviation of the biases of
separate power-ons of ONE sensor.  Three copies of one file gave 6.8e-17 °/h (rounding
error: one run counted three times), one path given twice counted twice, and runs of three
different sensors (different ``sensor_id`` in their metadata) were pooled into one figure.
Each must end in exit 2 with one ``error:`` line naming the files, every input unchanged;
separate power-ons of one sensor still give the repeatability numpy computes.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.recording import Metadata, Recording
from thermocal.writers import write_recording


def _digest(paths: list[Path]) -> dict[str, str]:
    return {str(p): hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


BIASES = (1.0, 1.3, 0.8)
"""The true bias of each power-on [deg/h]."""


def _power_on(path: Path, seed: int, bias: float, sensor_id: str | None = "SN-1") -> Path:
    """One power-on: 600 s at 1 Hz, white noise 0.05 deg/h about ``bias``."""
    rng = np.random.default_rng(seed)
    t = np.arange(600.0)
    rec = Recording.from_arrays(
        t,
        {"gx": bias + rng.normal(0.0, 0.05, t.size)},
        {"T1": 24.5 + t / 600.0},
        signal_unit="deg/h",
        meta=Metadata(sensor_id=sensor_id),
    )
    write_recording(rec, path)
    return path


def _error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err
    return lines[0]


def test_separate_power_ons_give_numpys_repeatability(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The control: three power-ons of one sensor; the repeatability is numpy's sample
    standard deviation of each file's mean (computed here from the written files)."""
    files = [_power_on(tmp_path / f"run{i}.csv", i, b) for i, b in enumerate(BIASES)]
    code, out, err = _run(capsys, "metrics", *map(str, files), "--signal", "gx", "--json")
    assert code == 0, err
    got = json.loads(out)
    means = []
    for f in files:
        data = np.genfromtxt(f, delimiter=",", names=True)
        means.append(float(np.mean(data["gx"])))
    assert got["bias_repeatability"] == pytest.approx(float(np.std(means, ddof=1)), rel=1e-9)
    assert got["bias_repeatability"] == pytest.approx(0.25, abs=0.02)  # std of BIASES


def test_three_copies_of_one_run_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = _power_on(tmp_path / "a.csv", 1, 1.0)
    files = [a]
    for name in ("b.csv", "c.csv"):
        shutil.copy(a, tmp_path / name)
        shutil.copy(tmp_path / "a.csv.meta.json", tmp_path / f"{name}.meta.json")
        files.append(tmp_path / name)
    inputs = files + [tmp_path / f"{f.name}.meta.json" for f in files]
    before = _digest(inputs)
    code, out, err = _run(capsys, "metrics", *map(str, files), "--signal", "gx", "--json")
    assert code == 2, (out, err)
    line = _error_line(err)
    assert "b.csv" in line and "a.csv" in line and "copy" in line, line
    assert out == ""
    assert _digest(inputs) == before


def test_a_copy_with_another_time_axis_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The same samples under another clock (the copy re-stamped an hour later) are still
    one power-on."""
    a = _power_on(tmp_path / "a.csv", 1, 1.0)
    data = np.genfromtxt(a, delimiter=",", names=True)
    lines = ["time,gx,T1"] + [
        f"{float(t) + 3600.0!r},{float(g)!r},{float(T)!r}"
        for t, g, T in zip(data["time"], data["gx"], data["T1"], strict=True)
    ]
    b = tmp_path / "b.csv"
    b.write_text("\n".join(lines) + "\n")
    shutil.copy(tmp_path / "a.csv.meta.json", tmp_path / "b.csv.meta.json")
    code, out, err = _run(capsys, "metrics", str(a), str(b), "--signal", "gx")
    assert code == 2, (out, err)
    line = _error_line(err)
    assert "b.csv" in line and "a.csv" in line, line


def test_one_path_given_twice_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = _power_on(tmp_path / "a.csv", 1, 1.0)
    b = _power_on(tmp_path / "b.csv", 2, 1.3)
    before = _digest([a, b])
    code, out, err = _run(capsys, "metrics", str(a), str(b), str(a), "--signal", "gx")
    assert code == 2, (out, err)
    line = _error_line(err)
    assert str(a) in line and ": given twice;" in line, line
    code, out, err = _run(capsys, "metrics", str(a), str(a), "--signal", "gx")
    assert code == 2, (out, err)
    assert ": given twice;" in _error_line(err)
    assert _digest([a, b]) == before


def test_runs_of_different_sensors_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    files = [
        _power_on(tmp_path / f"unit{i}.csv", i, b, sensor_id=f"SN-{i}")
        for i, b in enumerate(BIASES)
    ]
    code, out, err = _run(capsys, "metrics", *map(str, files), "--signal", "gx")
    assert code == 2, (out, err)
    line = _error_line(err)
    assert "unit1.csv" in line and "unit0.csv" in line, line
    assert "'SN-1'" in line and "'SN-0'" in line, line


def test_a_serial_in_the_metadata_extra_pairs_counts_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A logger that writes ``serial`` (not thermocal's ``sensor_id``) in the sidecar."""
    files = []
    for i, b in enumerate(BIASES):
        f = _power_on(tmp_path / f"unit{i}.csv", i, b, sensor_id=None)
        side = tmp_path / f"unit{i}.csv.meta.json"
        doc = json.loads(side.read_text())
        doc.setdefault("metadata", {})["serial"] = "A77" if i < 2 else "B12"
        side.write_text(json.dumps(doc))
        files.append(f)
    code, out, err = _run(capsys, "metrics", *map(str, files), "--signal", "gx")
    assert code == 2, (out, err)
    line = _error_line(err)
    assert "unit2.csv" in line and "'B12'" in line and "serial" in line, line
    code, out, err = _run(capsys, "metrics", *map(str, files[:2]), "--signal", "gx")
    assert code == 0, err


def test_a_run_naming_no_sensor_beside_a_named_one_is_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One run states SN-1, the other nothing: pooled (they may be one sensor), with a
    warning naming the file without a sensor; the figure is still numpy's."""
    a = _power_on(tmp_path / "a.csv", 1, 1.0, sensor_id="SN-1")
    b = _power_on(tmp_path / "b.csv", 2, 1.3, sensor_id=None)
    code, out, err = _run(capsys, "metrics", str(a), str(b), "--signal", "gx", "--json")
    assert code == 0, err
    warned = [ln for ln in err.splitlines() if "names no sensor" in ln]
    assert len(warned) == 1 and warned[0].startswith(f"warning: {b}: "), err
    assert "'SN-1'" in warned[0] and str(a) in warned[0]
    means = [float(np.mean(np.genfromtxt(f, delimiter=",", names=True)["gx"])) for f in (a, b)]
    got = json.loads(out)["bias_repeatability"]
    assert got == pytest.approx(float(np.std(means, ddof=1)), rel=1e-9)
