"""Issue 39's leftovers (slice ``h39-left``), through the CLI, every input hashed before
and after: ``--confidence`` out of range, a FIFO given to ``station check``, a local fleet
worker that dies, a compensate error listing 10 000 columns, names that a spreadsheet runs
as formulas (OWASP "CSV Injection") and values declared as counts that are not counts.
"""

from __future__ import annotations

import hashlib
import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fleet_data import config_text, write_run
from thermocal.cli import main
from thermocal.fleet.batch import UnitOutcome, UnitTask
from thermocal.fleet.batch import run_unit as _real_run_unit


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


def _white_csv(path: Path, n: int = 4000, sigma: float = 0.01, rate: float = 100.0) -> None:
    rng = np.random.default_rng(39)
    cols = {"time_s": np.arange(n) / rate}
    for c in ("gx_dps", "gy_dps", "gz_dps"):
        cols[c] = rng.normal(0.0, sigma, n)
    pd.DataFrame({**cols, "temp_c": 25.0}).to_csv(path, index=False)


# --- 1. --confidence ------------------------------------------------------------------


@pytest.mark.parametrize("value", ["1e-300", "0", "0.3", "1", "1.5", "nan", "0.9999999999999"])
def test_allan_confidence_outside_its_range_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], value: str
) -> None:
    """``--confidence 1e-300`` gave an interval of zero width, (0.0006486 … 0.0006486),
    beside the estimate 0.0006258, exit 0; 0, 1, 1.5 and NaN were refused without the
    option's name.  Accepted: 0.5 ≤ c ≤ 1 − 1e-9."""
    _white_csv(tmp_path / "a.csv")
    before = _digests(tmp_path)
    code = main(["allan", str(tmp_path / "a.csv"), "--signal", "gx_dps", "--confidence", value])
    _o, err = capsys.readouterr()
    _refused(code, err, "--confidence", "0.5")
    assert _digests(tmp_path) == before


def test_noise_confidence_outside_its_range_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _white_csv(tmp_path / "a.csv")
    before = _digests(tmp_path)
    out = tmp_path / "n.json"
    code = main(["noise", str(tmp_path / "a.csv"), "--gyro", "gx_dps,gy_dps,gz_dps",
                 "--format", "json", "-o", str(out), "--confidence", "1e-300"])  # fmt: skip
    _o, err = capsys.readouterr()
    _refused(code, err, "--confidence", "1e-300")
    assert not out.exists()
    assert _digests(tmp_path) == before


def test_allan_confidence_95_matches_the_chi_square_interval(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A valid 0.95 still works, and its interval at the first τ is the chi-square one
    computed here with scipy (NIST SP 1065 eq. 45) from the edf the command reports."""
    import json

    from scipy import stats

    _white_csv(tmp_path / "a.csv")
    code = main(["allan", str(tmp_path / "a.csv"), "--signal", "gx_dps", "--confidence",
                 "0.95", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    d = d.get("gx_dps", d) if isinstance(d, dict) else d
    adev, edf = d["adev"][0], d["edf"][0]
    lo = adev * math.sqrt(edf / stats.chi2.ppf(0.975, edf))
    hi = adev * math.sqrt(edf / stats.chi2.ppf(0.025, edf))
    assert d["adev_low"][0] == pytest.approx(lo, rel=1e-9)
    assert d["adev_high"][0] == pytest.approx(hi, rel=1e-9)


# --- 2. station check on a FIFO -------------------------------------------------------


def test_station_file_that_is_a_fifo_is_named_as_a_fifo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``station check FIFO`` said "no such file"."""
    fifo = tmp_path / "station.toml"
    os.mkfifo(fifo)
    code = main(["station", "check", str(fifo)])
    _o, err = capsys.readouterr()
    _refused(code, err, str(fifo), "FIFO")
    assert "no such file" not in err


def test_station_port_that_is_a_fifo_is_named_as_a_fifo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A sensor's ``device`` that is a FIFO: pyserial's "Inappropriate ioctl for device";
    now the sensor, the path and what it is."""
    pytest.importorskip("serial")
    fifo = tmp_path / "port"
    os.mkfifo(fifo)
    toml = tmp_path / "station.toml"
    toml.write_text(
        '[chamber]\ndriver = "none"\n\n[[sensor]]\nid = "imu1"\n'
        f'device = "{fifo}"\nbaud = 115200\nnames = ["gx", "temp"]\n'
        'units = ["deg/s", "degC"]\nrate_hz = 10\n'
    )
    before = _digest(toml)
    code = main(["station", "check", str(toml)])
    _o, err = capsys.readouterr()
    line = _refused(code, err, "imu1", str(fifo), "FIFO")
    assert "ioctl" not in line
    assert _digest(toml) == before


# --- 3. a local fleet worker that dies ------------------------------------------------


def _dies_on_u2(task: UnitTask) -> UnitOutcome:
    """What a worker runs: unit U2 kills its process (as the OOM killer would)."""
    if task.unit.id == "U2":
        os._exit(9)
    return _real_run_unit(task)


def test_a_local_worker_that_dies_names_its_unit_and_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Local worker processes: the pool broke and the batch stopped ("rerun to resume"),
    the unit unnamed.  Now U2 is a failed unit naming U2.csv; U1 and U3 are calibrated."""
    import thermocal.fleet.batch as batch

    monkeypatch.setattr(batch, "run_unit", _dies_on_u2)
    for k in (1, 2, 3):
        write_run(tmp_path / f"U{k}.csv", k)
    cfg = tmp_path / "batch.toml"
    cfg.write_text(config_text({f"U{k}": (f"U{k}.csv", None) for k in (1, 2, 3)}))
    before = _digests(tmp_path)
    out = tmp_path / "out"
    code = main(["fleet", str(cfg), "-o", str(out), "--workers", "2"])
    _o, err = capsys.readouterr()
    assert code == 4, err
    assert "Traceback" not in err and "rerun to resume" not in err, err
    warn = [ln for ln in err.splitlines() if ln.startswith("warning: unit U2:")]
    assert len(warn) == 1 and str(tmp_path / "U2.csv") in warn[0] and "died" in warn[0], err
    rows = pd.read_csv(out / "summary.csv").set_index("id")
    assert list(rows.loc[["U1", "U2", "U3"], "status"]) == ["ok", "failed", "ok"]
    assert {p: h for p, h in _digests(tmp_path).items() if p in before} == before


# --- 6. compensate's list of columns --------------------------------------------------


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


# --- 1. names that a spreadsheet runs as formulas (OWASP "CSV Injection") -------------

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


def test_compensate_csv_keeps_a_formula_name_and_warns(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """compensate's CSV is data for a program: the column name round-trips exactly, and one
    ``warning:`` names the output, the column and the risk; the compensated values are the
    residual of a straight line fitted here with numpy."""
    temp, sig = _injected_run(tmp_path / "d.csv")
    model = tmp_path / "m.json"
    code = main(["fit", str(tmp_path / "d.csv"), "--model", "poly", "--order", "1",
                 "--signal", INJECTED, "--signal-unit", "deg/s", "--time-unit", "s",
                 "--temps", "T", "--temp-unit", "degC", "-o", str(model)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    capsys.readouterr()
    before = _digests(tmp_path)
    out = tmp_path / "out.csv"
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


@pytest.mark.parametrize("first", ["=", "+", "-", "@"])  # a TAB is stripped by the reader
def test_fleet_summary_csv_neutralises_formula_names(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], first: str
) -> None:
    """fleet's summary.csv is a table for spreadsheets: a channel name beginning with a
    formula trigger is written with a ``'`` in front (OWASP's mitigation); numbers stay
    numbers; summary.parquet keeps the name exactly."""
    import csv

    name = first + "SUM(A1)"
    for k in (1, 2):
        _injected_run(tmp_path / f"U{k}.csv", name)
    cfg = tmp_path / "batch.toml"
    cfg.write_text(
        '[fit]\nmodel = "poly"\norder = 1\nsignal = ["'
        + name.replace("\t", "\\t")
        + '"]\ntemps = "T"\nsignal_unit = "deg/s"\n\n'
        + "".join(f'[[unit]]\nid = "U{k}"\nmodeling = ["U{k}.csv"]\n\n' for k in (1, 2))
    )
    before = _digests(tmp_path)
    out = tmp_path / "out"
    code = main(["fleet", str(cfg), "-o", str(out), "--workers", "1"])
    _o, err = capsys.readouterr()
    assert code == 0, err
    assert {p: h for p, h in _digests(tmp_path).items() if p in before} == before
    with open(out / "summary.csv", newline="", encoding="utf-8") as fh:
        cells = [c for row in csv.reader(fh) for c in row]
    assert "'" + name + ".unit" in cells
    for c in cells:  # a cell a spreadsheet would run is a number, never a text
        if c[:1] in ("=", "+", "-", "@", "\t", "\r"):
            float(c)
    pq_cols = pd.read_parquet(out / "summary.parquet").columns
    assert name + ".unit" in pq_cols


# --- 5. values declared as counts that are not counts ---------------------------------


def _adev_tau0(y: np.ndarray) -> float:
    """The overlapping Allan deviation at τ = τ0 written here: √(½ ⟨(ȳ₂ − ȳ₁)²⟩)."""
    return float(np.sqrt(0.5 * np.mean(np.diff(y) ** 2)))


@pytest.mark.parametrize("integers", [False, True])
def test_allan_counts_that_are_not_integers_warn(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], integers: bool
) -> None:
    """``--signal-unit counts`` on a column of fractions (0.01 σ white noise, physical
    values) gave an ADEV in "counts" without a word; now one warning names the column,
    --signal-unit and the metadata's scale_factor.  Integer counts: no warning.  Both:
    the ADEV at τ0 is the one computed here."""
    import json

    rng = np.random.default_rng(5)
    n = 2000
    y = rng.normal(0.0, 30.0, n).round() if integers else rng.normal(0.0, 0.01, n)
    pd.DataFrame({"time": np.arange(n) / 100.0, "g": y}).to_csv(tmp_path / "c.csv", index=False)
    before = _digests(tmp_path)
    code = main(["allan", str(tmp_path / "c.csv"), "--signal", "g", "--signal-unit", "counts",
                 "--time-unit", "s", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    warn = [ln for ln in err.splitlines() if ln.startswith("warning:")]
    if integers:
        assert not warn, err
    else:
        assert len(warn) == 1, err
        for needle in ("'g'", "counts", "not integers", "--signal-unit", "scale_factor"):
            assert needle in warn[0], (needle, warn[0])
    assert _digests(tmp_path) == before
    d = json.loads(out)
    d = d.get("g", d)
    assert d["tau_s"][0] == pytest.approx(0.01) and d["unit"] == "counts"
    assert d["adev"][0] == pytest.approx(_adev_tau0(y), rel=1e-9)


def test_allan_without_signal_lists_20_columns_and_how_many_more(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The same list in every command's "name the signal column with --signal" error."""
    wide = tmp_path / "wide.csv"
    names = ["time"] + [f"col{k:05d}" for k in range(9999)]
    rows = "\n".join(",".join([str(r)] + ["1"] * 9999) for r in range(3))
    wide.write_text(",".join(names) + "\n" + rows + "\n")
    before = _digests(tmp_path)
    code = main(["allan", str(wide), "--time-unit", "s"])
    _o, err = capsys.readouterr()
    line = _refused(code, err, "--signal", "'col00019'", "(9,979 more)")
    assert "'col00020'" not in line and len(line) < 2000
    assert _digests(tmp_path) == before
