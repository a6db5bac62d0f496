"""Hostile columns for ``compensate``: a missing signal among 10 000 columns lists 20 and how
many more; a column name that is a spreadsheet formula round-trips in CSV with a warning,
and in Parquet without one."""

from __future__ import annotations

import gzip
import hashlib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _digests(folder: Path) -> dict[Path, str]:
    return {p: _digest(p) for p in folder.rglob("*") if p.is_file()}


def _refused(code: int, err: str, *needles: str) -> str:
    """Exit 2, no traceback, exactly one ``error:`` line holding every needle; that line."""
    assert "Traceback" not in err, err
    assert code == 2, f"exit {code}; stderr: {err}"
    errors = [ln for ln in err.splitlines() if ln.startswith("error: ")]
    assert len(errors) == 1, err
    for n in needles:
        assert n in errors[0], (n, errors[0])
    return errors[0]


def test_compensate_missing_signal_lists_20_columns_and_how_many_more(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A file of 10 000 columns without the model's signal: the error listed all 10 000
    names on one line (~100 kB); now the first 20 and "(9,980 more)"."""
    n = 400
    t = np.arange(n, dtype=float)
    temp = np.linspace(10.0, 40.0, n)
    fit_csv = tmp_path / "fit.csv"
    pd.DataFrame({"time": t, "gx": 0.01 * temp, "T": temp}).to_csv(fit_csv, index=False)
    model = tmp_path / "m.json"
    code = main(["fit", str(fit_csv), "--model", "poly", "--order", "1", "--signal", "gx",
                 "--signal-unit", "deg/s", "--time-unit", "s", "--temps", "T",
                 "--temp-unit", "degC", "-o", str(model)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    wide = tmp_path / "wide.csv"
    names = ["time", "T"] + [f"col{k:05d}" for k in range(9998)]
    wide.write_text(",".join(names) + "\n" + ",".join(["1"] * len(names)) + "\n")
    capsys.readouterr()
    before = _digests(tmp_path)
    out = tmp_path / "out.csv"
    code = main(["compensate", str(model), str(wide), "-o", str(out)])
    _o, err = capsys.readouterr()
    line = _refused(code, err, "'gx'", "'col00017'", "(9,980 more)")
    assert "'col00018'" not in line and len(line) < 2000
    assert not out.exists()
    assert _digests(tmp_path) == before


INJECTED = "=1+2"  # a formula a spreadsheet would compute (3)


def _injected_run(path: Path, name: str = INJECTED) -> tuple[np.ndarray, np.ndarray]:
    """400 s at 1 Hz, 10 → 40 °C, a gyro column ``name`` in deg/s (0.5 + 0.01·(T − 25) +
    a wobble): returns (temperature, signal) as the file holds them."""
    n = 400
    t = np.arange(n, dtype=float)
    temp = np.linspace(10.0, 40.0, n)
    pd.DataFrame(
        {"time": t, name: 0.5 + 0.01 * (temp - 25.0) + 0.001 * np.sin(t), "T": temp}
    ).to_csv(path, index=False)
    back = pd.read_csv(path)
    return back["T"].to_numpy(), back[name].to_numpy()


@pytest.mark.parametrize("out_name", ["out.csv", "out.csv.gz"])
def test_compensate_csv_keeps_a_formula_name_and_warns(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], out_name: str
) -> None:
    """compensate's CSV is data for a program: the column name round-trips exactly, and one
    ``warning:`` names the output, the column and the risk (a gzip CSV too: unpacked, a
    spreadsheet opens it); the compensated values are the residual of a straight line
    fitted here with numpy."""
    temp, sig = _injected_run(tmp_path / "d.csv")
    model = tmp_path / "m.json"
    code = main(["fit", str(tmp_path / "d.csv"), "--model", "poly", "--order", "1",
                 "--signal", INJECTED, "--signal-unit", "deg/s", "--time-unit", "s",
                 "--temps", "T", "--temp-unit", "degC", "-o", str(model)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    capsys.readouterr()
    before = _digests(tmp_path)
    out = tmp_path / out_name
    code = main(["compensate", str(model), str(tmp_path / "d.csv"), "-o", str(out)])
    _o, err = capsys.readouterr()
    assert code == 0, err
    warn = [ln for ln in err.splitlines() if ln.startswith("warning:")]
    assert len(warn) == 1, err
    assert str(out) in warn[0] and repr(INJECTED) in warn[0] and "CSV Injection" in warn[0]
    assert {p: h for p, h in _digests(tmp_path).items() if p in before} == before
    df = pd.read_csv(out)
    assert list(df.columns) == ["time", INJECTED, "T", INJECTED + "_model", INJECTED + "_comp"]
    ref = sig - np.polyval(np.polyfit(temp, sig, 1), temp)
    np.testing.assert_allclose(df[INJECTED + "_comp"], ref, rtol=0, atol=1e-9)


def test_compensate_parquet_with_a_formula_name_says_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The warning is about spreadsheets opening a CSV: a Parquet output gets none."""
    _injected_run(tmp_path / "d.csv")
    model = tmp_path / "m.json"
    assert main(["fit", str(tmp_path / "d.csv"), "--model", "poly", "--order", "1",
                 "--signal", INJECTED, "--signal-unit", "deg/s", "--time-unit", "s",
                 "--temps", "T", "--temp-unit", "degC", "-o", str(model)]) == 0  # fmt: skip
    capsys.readouterr()
    out = tmp_path / "out.parquet"
    code = main(["compensate", str(model), str(tmp_path / "d.csv"), "-o", str(out)])
    _o, err = capsys.readouterr()
    assert code == 0 and "warning:" not in err, err


def test_compensate_to_csv_gz_writes_gzip_of_the_same_csv(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An output named ``.csv.gz`` is a gzip stream whose content is byte for byte the
    ``.csv`` output (it was written as plain text under the ``.gz`` name); no file name or
    time in its header, so two runs give the same bytes."""
    _injected_run(tmp_path / "d.csv", name="gyro")
    model = tmp_path / "m.json"
    assert main(["fit", str(tmp_path / "d.csv"), "--model", "poly", "--order", "1",
                 "--signal", "gyro", "--signal-unit", "deg/s", "--time-unit", "s",
                 "--temps", "T", "--temp-unit", "degC", "-o", str(model)]) == 0  # fmt: skip
    outs = [tmp_path / n for n in ("o.csv", "o1.csv.gz", "o2.csv.gz")]
    for out in outs:
        assert main(["compensate", str(model), str(tmp_path / "d.csv"), "-o", str(out)]) == 0
    capsys.readouterr()
    plain, gz1, gz2 = (p.read_bytes() for p in outs)
    assert gz1[:2] == b"\x1f\x8b" and gzip.decompress(gz1) == plain
    assert gz1 == gz2
