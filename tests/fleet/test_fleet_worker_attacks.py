"""Hostile fleets: a local worker process that dies names its unit and file; channel names
that are spreadsheet formulas are neutralised in ``summary.csv``."""

from __future__ import annotations

import hashlib
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
