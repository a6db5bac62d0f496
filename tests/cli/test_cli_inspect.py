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
    code, out, err = _run(capsys, "inspect", str(path), "--json")
    # like a linter: every finding printed, then exit 2 because the time is unusable
    assert code == 2
    assert [ln for ln in err.strip().splitlines() if not ln.startswith("warning: ")] == [
        f"error: {path}: duplicate timestamp 1.0 at row 2 (1 duplicates in all; host "
        "timestamps? give --rate HZ to take the samples at the sensor's nominal rate)"
    ]
    d = json.loads(out)
    kinds = {p["kind"]: p for p in d["problems"]}
    assert kinds["duplicate_time"]["row"] == 2
    assert kinds["nan"]["column"] == "gyro"
    assert d["usable"] is False and d["time_ok"] is False
    assert d["duration_s"] is None and d["n_segments"] is None


def test_inspect_backwards_time_exits_2_with_true_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "back.csv"
    path.write_text("time,gyro,T1\n0,1,20\n1,2,20\n0.5,1,20\n2,1,20\n")
    code, out, err = _run(capsys, "inspect", str(path))
    assert code == 2
    assert "time goes backwards at row 2" in out  # the findings are printed first
    assert "0 contiguous segments" not in out and "over 0 s" not in out
    assert "duration, sample rate, gaps and segments are not computed" in out
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("warning: ")]
    assert len(lines) == 1 and lines[0].startswith(f"error: {path}: time goes backwards")
    code, out, _ = _run(capsys, "inspect", str(path), "--json")
    assert code == 2
    d = json.loads(out)
    assert d["sample_rate_hz"] is None and d["duration_s"] is None


def test_inspect_warnings_exit_0_unless_strict(capsys: pytest.CaptureFixture[str]) -> None:
    """Gaps and spikes are warnings: exit 0; --strict makes them fatal (exit 2)."""
    code, _, err = _run(capsys, "inspect", str(example_path("tvac")), "--json")
    assert code == 0, err
    code, out, err = _run(capsys, "inspect", str(example_path("tvac")), "--strict", "--json")
    assert code == 2
    assert json.loads(out)["n_samples"] == 6000  # findings still printed
    assert err.startswith("error: ") and "--strict" in err and "gaps" in err


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
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("warning: ")]
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0]
    assert "Traceback" not in err


def test_usage_error_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(capsys, "inspect")
    assert code == 2
    assert err.strip().startswith("error: ") and len(err.strip().splitlines()) == 1


def test_temp_conversion_option_for_raw_counts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Raw ADC temperatures without metadata: --temp-conversion GAIN,OFFSET converts them,
    and fit + compensate on counts give exactly what the same data in °C give."""
    import numpy as np

    df = make_tvac_log()
    raw = tmp_path / "raw.csv"
    df.to_csv(raw, index=False)  # no sidecar: nothing says how to convert the counts
    common = ["--time", "time_ms", "--time-unit", "ms", "--temps", "temp_counts"]
    code, out, _ = _run(
        capsys, "inspect", str(raw), *common, "--temp-unit", "counts",
        "--temp-conversion", "0.0625,-50", "--json",
    )  # fmt: skip
    assert code == 0
    span = json.loads(out)["temperature_span"]["temp_counts"]
    counts = df["temp_counts"].to_numpy()
    assert_allclose(span, [counts.min() * 0.0625 - 50, counts.max() * 0.0625 - 50])

    # the same data with the temperature already in °C
    deg = tmp_path / "deg.csv"
    df_c = df.assign(temp_counts=counts * 0.0625 - 50.0)
    df_c.to_csv(deg, index=False)
    sig = ["--signal", "gyro deg/h"]
    for path, extra, model in [
        (raw, ["--temp-unit", "counts", "--temp-conversion", "0.0625,-50"], "m_raw.json"),
        (deg, ["--temp-unit", "degC"], "m_deg.json"),  # the option beats the column name
    ]:
        code, _, err = _run(
            capsys, "fit", str(path), "--model", "poly", "--order", "1", *common, *sig,
            *extra, "-o", str(tmp_path / model),
        )  # fmt: skip
        assert code == 0, err
    outs = {}
    for path, extra, model in [
        (raw, ["--temp-unit", "counts", "--temp-conversion", "0.0625,-50"], "m_raw.json"),
        (deg, ["--temp-unit", "degC"], "m_deg.json"),
    ]:
        dst = tmp_path / f"comp_{model}.csv"
        code, _, err = _run(
            capsys, "compensate", str(tmp_path / model), str(path), "--time", "time_ms",
            "--time-unit", "ms", *extra, "-o", str(dst),
        )  # fmt: skip
        assert code == 0, err
        outs[model] = pd.read_csv(dst)["gyro deg/h_comp"].to_numpy()
    assert_allclose(outs["m_raw.json"], outs["m_deg.json"], rtol=0, atol=1e-9)
    # 0.01 °/h/°C recovered from the counts
    coef = json.loads((tmp_path / "m_raw.json").read_text())["coefficients"]
    slope = next(c["value"] for c in coef if c["name"] != "const")
    assert slope == pytest.approx(0.01, abs=1e-3)
    assert np.isfinite(outs["m_raw.json"]).all()


def test_temp_conversion_option_refuses_garbage(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "x.csv"
    path.write_text("time,g,tc\n0,1,800\n1,2,801\n2,3,802\n")
    code, _, err = _run(
        capsys, "inspect", str(path), "--temps", "tc", "--temp-conversion", "0.0625"
    )
    assert code == 2
    assert err.strip().splitlines()[-1].startswith("error: --temp-conversion takes 'GAIN,OFFSET'")


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    from thermocal import __version__

    code, out, _ = _run(capsys, "--version")
    assert code == 0
    assert out.strip() == f"thermocal {__version__}"
