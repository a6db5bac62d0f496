"""The command line against INTERFACE.md's common rules (regressions found by a CLI audit).

Bad input exits 2 with exactly one ``error: ...`` line on stderr naming the file,
column or row, nothing on stdout with ``--json``, no traceback; gaps are a
``warning:``; outputs never replace an input (nor an input's sidecar) and a
refused command leaves no output behind.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

N = 600


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _assert_input_error(code: int, out: str, err: str, *needles: str) -> str:
    """Exit 2, one ``error:`` line (warnings allowed), empty stdout, no traceback."""
    assert code == 2, err
    assert out == ""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("error: ")]
    assert len(errors) == 1, err
    assert all(ln.startswith(("error: ", "warning: ")) for ln in lines), err
    assert "Traceback" not in err and "np.float64" not in err
    for n in needles:
        assert n in errors[0], errors[0]
    return errors[0]


def _frame(n: int = N) -> pd.DataFrame:
    t = np.arange(n, dtype=np.float64)
    temp = 20.0 + 15.0 * np.sin(2.0 * np.pi * t / n)
    rng = np.random.default_rng(0)
    gyro = 1.0 + 0.05 * temp + 0.01 * rng.standard_normal(n)
    return pd.DataFrame({"time": t, "gyro": gyro, "T1": temp})


@pytest.fixture
def good(tmp_path: Path) -> Path:
    p = tmp_path / "good.csv"
    _frame().to_csv(p, index=False)
    return p


def _bad_file(tmp_path: Path, kind: str) -> Path:
    df = _frame()
    if kind == "duplicate":
        df.loc[50, "time"] = 49.0
    elif kind == "backwards":
        df.loc[50, "time"] = 10.0
    elif kind == "nan_time":
        df.loc[50, "time"] = np.nan
    elif kind == "nan_signal":
        df.loc[50, "gyro"] = np.nan
    elif kind == "inf_signal":
        df.loc[50, "gyro"] = np.inf
    elif kind == "nan_temp":
        df.loc[50, "T1"] = np.nan
    p = tmp_path / f"{kind}.csv"
    df.to_csv(p, index=False)
    return p


COMMANDS = {
    "metrics": ["metrics", "{f}", "--signal", "gyro", "--temps", "T1", "--json"],
    "allan": ["allan", "{f}", "--signal", "gyro", "--json"],
    "fit": [
        "fit",
        "{f}",
        "--model",
        "poly",
        "--signal",
        "gyro",
        "--temps",
        "T1",
        "--order",
        "2",
        "-o",
        "{o}",
        "--json",
    ],
}
KINDS = {
    "duplicate": ("row 50", "duplicate"),
    "backwards": ("row 50", "backwards"),
    "nan_time": ("row 50", "time"),
    "nan_signal": ("row 50", "'gyro'"),
    "inf_signal": ("row 50", "'gyro'"),
    "nan_temp": ("row 50", "'T1'"),
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
@pytest.mark.parametrize("kind", sorted(KINDS))
def test_bad_time_or_values_exit_2_naming_file_and_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, kind: str
) -> None:
    if command == "allan" and kind == "nan_temp":
        return  # allan reads no temperature
    f = _bad_file(tmp_path, kind)
    out_path = tmp_path / "model.json"
    args = [a.format(f=f, o=out_path) for a in COMMANDS[command]]
    code, out, err = _run(capsys, *args)
    _assert_input_error(code, out, err, f.name, *KINDS[kind])
    assert not out_path.exists()


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_gaps_are_a_warning_not_an_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    df = _frame()
    df.loc[300:, "time"] += 100.0
    f = tmp_path / "gap.csv"
    df.to_csv(f, index=False)
    args = [a.format(f=f, o=tmp_path / "m.json") for a in COMMANDS[command]]
    code, out, err = _run(capsys, *args)
    assert code == 0, err
    assert isinstance(json.loads(out), dict)
    warn = [ln for ln in err.splitlines() if ln.startswith("warning: ") and "gaps in time" in ln]
    assert len(warn) == 1 and "gap.csv" in warn[0] and "row 299" in warn[0], err


def test_output_over_an_inputs_sidecar_is_refused(
    good: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    side = good.with_name(good.name + ".meta.json")
    code, out, err = _run(
        capsys, "fit", str(good), "--model", "poly", "--signal", "gyro", "--temps", "T1",
        "-o", str(side), "--json",
    )  # fmt: skip
    _assert_input_error(code, out, err, "sidecar", "good.csv")
    assert not side.exists()


def test_allan_plot_into_a_directory_is_an_input_error(
    good: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    d = tmp_path / "adir"
    d.mkdir()
    code, out, err = _run(
        capsys, "allan", str(good), "--signal", "gyro", "--plot", str(d), "--json"
    )
    _assert_input_error(code, out, err, "adir", "is a directory")
    assert list(d.iterdir()) == [] and not list(tmp_path.glob(".*.tmp"))


def test_piecewise_segments_chosen_with_samples_in_every_segment(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Clean linear data (flat RSS surface) used to yield two adjacent breakpoints
    (27.0632, 27.0663 °C) with no sample between them, and a DesignError.  Now the
    data are recognised as a line: one segment is fitted and a warning says so."""
    f = tmp_path / "line.csv"
    _frame(3000).to_csv(f, index=False)
    model = tmp_path / "pw.json"
    code, out, err = _run(
        capsys, "fit", str(f), "--model", "piecewise", "--signal", "gyro", "--temps", "T1",
        "--segments", "3", "-o", str(model), "--json",
    )  # fmt: skip
    assert code == 0, err
    d = json.loads(out)
    assert d["model"] == "piecewise"
    # the data are a line 1 + 0.05 T with 0.01 noise: the fit's rms is the noise
    assert d["rms_residual"] == pytest.approx(0.01, rel=0.1)
    assert "warning: piecewise: 3 segments asked for, 1 fitted: the data are a line" in err
    saved = json.loads(model.read_text())
    assert saved["state"]["breakpoints"] == []
    assert saved["fit"]["segment_selection"]["segments_kept"] == 1


def test_piecewise_more_segments_than_data_support(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t = np.arange(30, dtype=np.float64)
    f = tmp_path / "short.csv"
    pd.DataFrame({"time": t, "gyro": 1.0 + 0.01 * t, "T1": 20.0 + 0.5 * t}).to_csv(f, index=False)
    model = tmp_path / "pw.json"
    code, _out, err = _run(
        capsys, "fit", str(f), "--model", "piecewise", "--signal", "gyro", "--temps", "T1",
        "--segments", "20", "-o", str(model), "--json",
    )  # fmt: skip
    # 30 samples cannot hold 20 segments of ≥ 5 samples: fewer are fitted, and said so
    assert code == 0, err
    assert "warning: piecewise: 20 segments asked for, 1 fitted: the data are a line" in err
    assert "allow at most 6" in err
    assert json.loads(model.read_text())["state"]["breakpoints"] == []


@pytest.fixture
def model(good: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    m = tmp_path / "m.json"
    code, _, err = _run(
        capsys, "fit", str(good), "--model", "poly", "--signal", "gyro", "--temps", "T1",
        "--order", "2", "-o", str(m), "--json",
    )  # fmt: skip
    assert code == 0, err
    return m


def test_export_c_onto_an_existing_file_is_an_input_error(
    model: Path, good: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = good.read_bytes()
    code, out, err = _run(capsys, "export-c", str(model), "-o", str(good), "--json")
    _assert_input_error(code, out, err, "good.csv", "not a directory")
    assert good.read_bytes() == before


def test_validate_modeling_file_with_nan_ambient(
    model: Path, good: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = _bad_file(tmp_path, "nan_temp")
    code, out, err = _run(
        capsys, "validate", str(model), str(good), "--modeling", str(bad), "--json"
    )
    _assert_input_error(code, out, err, "nan_temp.csv", "'T1'", "row 50")


@pytest.mark.parametrize(
    ("option", "value", "needle"),
    [("--rate-hz", "0", "--rate-hz"), ("--latitude", "100", "--latitude")],
)
def test_simulate_rejects_impossible_options(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, value: str, needle: str
) -> None:
    out_path = tmp_path / "sim.parquet"
    code, out, err = _run(
        capsys, "simulate", "rlg-validation", "-o", str(out_path), option, value, "--json"
    )
    _assert_input_error(code, out, err, needle)
    assert not out_path.exists()


def test_inspect_strict_prints_one_error_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = _bad_file(tmp_path, "backwards")
    code, out, err = _run(capsys, "inspect", str(f), "--strict", "--json")
    assert code == 2
    assert isinstance(json.loads(out), dict)  # the inspection itself is the output
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("warning: ")]
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "backwards.csv" in lines[0] and "row 50" in lines[0]
    assert "np.float64" not in lines[0]


def test_profile_backwards_time_message_is_plain(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    prog = tmp_path / "prog.csv"
    prog.write_text("time_s,setpoint_c\n0,20\n10,25\n10,30\n20,30\n")
    out_path = tmp_path / "sim.parquet"
    code, out, err = _run(
        capsys, "simulate", "rlg-validation", "-o", str(out_path), "--profile", str(prog), "--json"
    )
    _assert_input_error(code, out, err, "prog.csv", "row 2", "(10.0)")
    assert not out_path.exists()


def test_compensate_refuses_a_sidecar_over_the_model_file(
    model: Path, good: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o OUT.csv`` writes ``OUT.csv.meta.json``; if that is the model file, refuse."""
    trap = tmp_path / "out.csv.meta.json"
    trap.write_bytes(model.read_bytes())
    before = trap.read_bytes()
    code, out, err = _run(
        capsys, "compensate", str(trap), str(good), "-o", str(tmp_path / "out.csv")
    )
    _assert_input_error(code, out, err, "refusing to write over the input")
    assert trap.read_bytes() == before
    assert not (tmp_path / "out.csv").exists()


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["profile", "fog-slow", "-o", "{d}/prog.xlsx"], "name it *.csv"),
        (["allan", "{good}", "--signal", "gyro", "--plot", "{d}/plot.txt"], "name it *.png"),
        (["profile", "fog-slow", "-o", "{d}/prog.csv", "--dt", "-1"], "--dt must be ≥ 0 s"),
    ],
)
def test_output_extension_matches_what_is_written(
    good: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    args: list[str],
    needle: str,
) -> None:
    filled = [a.format(d=tmp_path, good=good) for a in args]
    code, out, err = _run(capsys, *filled)
    _assert_input_error(code, out, err, needle)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good.csv"]
