"""Bounds through the command line (issue 26, item 8).

Two attack classes, generated here from a good recording (600 s at 1 Hz, a temperature ramp
10 → 40 °C, a gyro):

* **orders and term counts beyond a hard ceiling** — ``fit --order 99999999999999999999``
  (typer parses it as a Python int; the plain polynomial became a list of 10²⁰ terms and
  grew fleet workers to 10 GB), ``--t0-order``, ``--segments``, ``--terms`` with 201 terms or
  a power of 10⁸, ``turntable --order``: exit 2 naming the option and the ceiling, before
  any data file is read (the reader is replaced by one that fails the test);
* **values that overflow on conversion** — a raw-count gyro of 1e300 counts with a scale
  factor, counts whose scale factor makes every value infinite, a deg/s column of 1e306
  (× 3600 → inf), a temperature in counts whose conversion overflows: exit 2 naming the
  column and the first row, and no ``RuntimeWarning`` (overflow) on the way.

Every run: exit 2 (never 1), no traceback, the input files unchanged byte for byte.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import thermocal.pipeline.fit as fit_cmd
import thermocal.readers.dispatch as io_mod
from thermocal.cli import main

N = 600
ROW = 300
"""The row that carries the hostile value."""


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _write(path: Path, gyro: np.ndarray, temp: np.ndarray, meta: dict[str, Any]) -> Path:
    t = np.arange(N, dtype=float)
    info = {"format": "thermocal-recording", "version": 1, "time": "time", "time_unit": "s",
            **meta}  # fmt: skip
    table = pa.table({"time": t, "gyro": gyro, "T1": temp})
    pq.write_table(table.replace_schema_metadata({"thermocal": json.dumps(info)}), path)
    return path


def _ramp() -> np.ndarray:
    return 10.0 + 30.0 * np.arange(N, dtype=float) / (N - 1)  # [°C]


def _good(path: Path) -> Path:
    temp = _ramp()
    gyro = 0.5 + 0.02 * (temp - 25.0)  # [deg/h]
    meta = {"signals": {"gyro": "deg/h"}, "temperatures": {"T1": "degC"}}
    return _write(path, gyro, temp, meta)


def _run(argv: list[str], files: list[Path], capsys: pytest.CaptureFixture[str]) -> str:
    """Run the CLI in-process; check exit 2, one ``error:`` line, no traceback, no
    RuntimeWarning, inputs unchanged; return stderr's last line."""
    before = {p: _digest(p) for p in files}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        code = main(argv)
    _out, err = capsys.readouterr()
    assert "Traceback" not in err, err
    assert code == 2, f"exit {code}: {err}"
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)], [
        str(w.message) for w in caught
    ]
    assert "RuntimeWarning" not in err, err
    last = err.strip().splitlines()[-1]
    assert last.startswith("error: "), err
    assert {p: _digest(p) for p in files} == before, "an input file changed"
    return last


# --- orders and term counts -------------------------------------------------------------------

HUGE = "99999999999999999999"

FIT_CEILINGS = {
    "poly-order-huge": (["--model", "poly", "--order", HUGE], "--order", "10"),
    "poly-order-11": (["--model", "poly", "--order", "11"], "--order", "10"),
    "poly-order-negative-huge": (["--model", "poly", "--order", "-" + HUGE], "--order", "10"),
    "warmup-order-huge": (["--model", "warmup", "--order", HUGE], "--order", "10"),
    "warmup-t0-order-huge": (["--model", "warmup", "--t0-order", HUGE], "--t0-order", "10"),
    "piecewise-segments-huge": (["--model", "piecewise", "--segments", HUGE], "--segments", "100"),
    "poly-201-terms": (
        ["--model", "poly", "--terms", ",".join(["T1"] * 201)], "--terms", "200"
    ),
    "poly-power-huge": (["--model", "poly", "--terms", "T1,T1^100000000"], "--terms", "10"),
}  # fmt: skip


@pytest.fixture
def no_reading(monkeypatch: pytest.MonkeyPatch) -> None:
    """Any read of a data file by fit or turntable fails the test: the ceiling is checked
    first."""

    def refuse(*_a: object, **_k: object) -> None:
        raise AssertionError("a data file was read before the option was checked")

    monkeypatch.setattr(fit_cmd, "check_recording", refuse)
    monkeypatch.setattr(io_mod, "read_recording", refuse)


@pytest.mark.parametrize("case", sorted(FIT_CEILINGS))
def test_fit_refuses_an_order_or_term_count_beyond_the_ceiling_before_reading(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str], no_reading: None
) -> None:
    args, option, ceiling = FIT_CEILINGS[case]
    f = _good(tmp_path / "run.parquet")
    out = tmp_path / "model.json"
    argv = ["fit", str(f), *args, "--signal", "gyro", "--temps", "T1", "-o", str(out)]
    last = _run(argv, [f], capsys)
    assert option in last and ceiling in last, last
    assert not out.exists()


def test_fit_accepts_the_ceiling_itself(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Order 10 passes the ceiling (the data then decide): the check does not refuse the
    limit it names."""
    fit_cmd.check_terms(",".join(["T1"] * 200))
    fit_cmd.check_terms("T1^10")
    limits = (("poly", "order", 10), ("warmup", "order", 10), ("warmup", "t0_order", 10),
              ("warmup", "t0_order", 0), ("piecewise", "segments", 100),
              ("piecewise", "segments", 1))  # fmt: skip
    for family, name, value in limits:
        assert fit_cmd.build_model(family, {name: value}).get_params()[name] == value


def test_turntable_refuses_an_order_beyond_the_ceiling_before_reading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], no_reading: None
) -> None:
    files = [_good(tmp_path / f"soak{k}.parquet") for k in range(3)]
    out = tmp_path / "cal.json"
    argv = ["turntable", *map(str, files), "--gyro", "gx,gy,gz", "--temps", "T1",
            "--order", HUGE, "-o", str(out)]  # fmt: skip
    last = _run(argv, files, capsys)
    assert "--order" in last and "3" in last, last
    assert not out.exists()


# --- overflow on conversion -------------------------------------------------------------------


def _overflowing(kind: str, path: Path) -> Path:
    temp = _ramp()
    counts = np.round(1000.0 + 20.0 * (temp - 25.0))
    if kind == "counts-1e300":  # 1e300 counts, K = 1000 counts/(deg/h): 1e297 deg/h
        counts[ROW] = 1e300
        meta = {"signals": {"gyro": "counts"}, "temperatures": {"T1": "degC"},
                "metadata": {"scale_factor": 1000.0,
                             "scale_factor_unit": "counts/(deg/h)"}}  # fmt: skip
        return _write(path, counts, temp, meta)
    if kind == "counts-tiny-k":  # K = 1e-306: 1000 counts → 1e309 deg/h = inf
        meta = {"signals": {"gyro": "counts"}, "temperatures": {"T1": "degC"},
                "metadata": {"scale_factor": 1e-306,
                             "scale_factor_unit": "counts/(deg/h)"}}  # fmt: skip
        return _write(path, counts, temp, meta)
    if kind == "deg-s-1e306":  # 1e306 deg/s × 3600 = inf deg/h
        gyro = 0.5 + 0.0001 * (temp - 25.0)
        gyro[ROW] = 1e306
        meta = {"signals": {"gyro": "deg/s"}, "temperatures": {"T1": "degC"}}
        return _write(path, gyro, temp, meta)
    assert kind == "temperature-counts"  # T = 1e10 °C/count · v: v = 1e300 → inf
    v = temp * 1e-10
    v[ROW] = 1e300
    gyro = 0.5 + 0.02 * (temp - 25.0)
    meta = {"signals": {"gyro": "deg/h"}, "temperatures": {"T1": "counts"},
            "metadata": {"temperature_conversion": {"T1": [1e10, 0.0]}}}  # fmt: skip
    return _write(path, gyro, v, meta)


OVERFLOWS = ["counts-1e300", "counts-tiny-k", "deg-s-1e306", "temperature-counts"]
COMMANDS = {
    "inspect": ["inspect", "{f}"],
    "metrics": ["metrics", "{f}", "--signal", "gyro", "--temps", "T1"],
    "allan": ["allan", "{f}", "--signal", "gyro"],
    "fit": ["fit", "{f}", "--model", "poly", "--order", "1", "--signal", "gyro", "--temps",
            "T1", "-o", "{o}"],
    "compensate": ["compensate", "{m}", "{f}", "-o", "{o}"],
}  # fmt: skip


@pytest.mark.parametrize("cmd", sorted(COMMANDS))
@pytest.mark.parametrize("kind", OVERFLOWS)
def test_a_value_that_overflows_on_conversion_is_refused(
    kind: str, cmd: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    if kind == "temperature-counts" and cmd == "allan":
        pytest.skip("allan reads no temperature")
    f = _overflowing(kind, tmp_path / "data.parquet")
    model = tmp_path / "model.json"
    if cmd == "compensate":  # a model of the same signal kind, fitted on good data
        good = _overflowing(kind, tmp_path / "good.parquet")
        tab = pq.read_table(good)
        i = tab.column_names.index("gyro" if kind != "temperature-counts" else "T1")
        col = tab.column(i).to_numpy().copy()
        col[ROW] = col[ROW - 1] if kind != "counts-tiny-k" else col[ROW]
        pq.write_table(tab.set_column(i, tab.field(i), pa.array(col)), good)
        if kind == "counts-tiny-k":  # the same columns with a sane K
            info = json.loads(tab.schema.metadata[b"thermocal"])
            info["metadata"]["scale_factor"] = 1000.0
            pq.write_table(tab.replace_schema_metadata({"thermocal": json.dumps(info)}), good)
        capsys.readouterr()
        assert main(["fit", str(good), "--model", "poly", "--order", "1", "--signal", "gyro",
                     "--temps", "T1", "-o", str(model)]) == 0  # fmt: skip
        capsys.readouterr()
    out = tmp_path / ("out.parquet" if cmd == "compensate" else "model-out.json")
    argv = [a.format(f=f, o=out, m=model) for a in COMMANDS[cmd]]
    last = _run(argv, [f], capsys)
    column = "'T1'" if kind == "temperature-counts" else "'gyro'"
    row = 0 if kind == "counts-tiny-k" else ROW
    assert column in last and f"row {row}" in last, last
    assert not out.exists()
