"""``thermocal inspect`` through the command line (INTERFACE.md)."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest
from numpy.testing import assert_allclose

from thermocal.cli import main
from thermocal.datasets import TVAC_SPIKE_ROWS, example_path, make_tvac_log


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_shipped_example_matches_its_recipe() -> None:
    shipped = pd.read_csv(example_path("tvac"))
    pd.testing.assert_frame_equal(shipped, make_tvac_log(), check_dtype=False)


def test_inspect_thermal_vacuum_bursts(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = _run(capsys, "inspect", str(example_path("tvac")), "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["n_samples"] == 6000
    assert_allclose(d["sample_rate_hz"], 50.0, rtol=1e-9)
    assert len(d["gaps"]) == 23
    assert all(280 < g["length_s"] < 310 for g in d["gaps"])
    assert_allclose(d["gaps"][0]["start_s"], 4.98)
    span = d["temperature_span"]["temp_counts"]
    assert -10 < span[0] < 0 and 24 < span[1] < 26
    kinds = {p["kind"]: p for p in d["problems"]}
    assert kinds["gaps"]["severity"] == "warning"
    assert kinds["spikes"]["column"] == "gyro deg/h"
    assert kinds["spikes"]["row"] == TVAC_SPIKE_ROWS[0]
    assert d["columns"]["gyro deg/h"]["n_spikes"] == len(TVAC_SPIKE_ROWS)
    assert d["columns"]["temp_counts"]["unit"] == "counts"


def test_inspect_human_output(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "inspect", str(example_path("tvac")))
    assert code == 0
    assert "6000 samples" in out and "23 gaps" in out


def test_inspect_reports_data_problems(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bad.csv"
    path.write_text("time,gyro,T1\n0,1,20\n1,,20\n1,3,20\n3,4,20\n")
    code, out, _ = _run(capsys, "inspect", str(path), "--json")
    assert code == 0
    kinds = {p["kind"]: p for p in json.loads(out)["problems"]}
    assert kinds["duplicate_time"]["row"] == 2
    assert kinds["nan"]["column"] == "gyro"
    code, _, _ = _run(capsys, "inspect", str(path), "--strict", "--signal", "gyro")
    assert code == 2


@pytest.mark.parametrize(
    ("content", "name", "args", "message"),
    [
        ("", "e.csv", [], "empty"),
        ("a,b\n1,2\n", "x.xlsx", [], "not a CSV or Parquet"),
        ("time,gyro\n0,1\n1,2\n", "m.csv", ["--signal", "gyroz"], "no column 'gyroz'"),
        ("time,gyro\n0,1\n1,zz\n", "n.csv", ["--signal", "gyro"], "non-numeric value 'zz'"),
        ("time,gyro\n0,1\n1,2\n", "u.csv", ["--signal", "gyro", "--signal-unit", "rpm"], "rpm"),
    ],
)
def test_inspect_bad_input_exit_2_one_line(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    content: str,
    name: str,
    args: list[str],
    message: str,
) -> None:
    path = tmp_path / name
    path.write_text(content)
    code, out, err = _run(capsys, "inspect", str(path), *args)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0]
    assert "Traceback" not in err


def test_usage_error_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(capsys, "inspect")
    assert code == 2
    assert err.strip().startswith("error: ") and len(err.strip().splitlines()) == 1
