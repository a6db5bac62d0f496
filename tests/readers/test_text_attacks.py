"""Hostile text and CSV files through the command line (issue 26, item 6).

Three attack classes, each generated here from a good recording (600 s at 1 Hz, a
temperature ramp 10 → 40 °C, a gyro in deg/h):

* **duplicate column names** — a header naming a column twice (comma CSV, ``;`` and tab
  text, names equal once blanks are stripped, Parquet) is refused with exit 2 naming the
  column: which of the two a command would read is a guess;
* **malformed numbers** — ``0_5`` (Python's ``float`` reads it as 5.0), ``1_000.5`` and
  non-ASCII digits are bad lines: ``--on-bad-lines error`` (the default) names the line,
  ``skip`` drops it and says so;
* **one 10 MB line** — a header of one name repeated (pandas' renaming of repeats is
  quadratic: it never finished), a 10 MB data row, banner or ``;`` row: the command ends in
  seconds (run in a subprocess with a timeout).

Every run: exit 0 or 2 (never 1), no traceback, the input file unchanged byte for byte, no
temporary output left behind.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.cli import main
from thermocal.outputs import TEMP_SUFFIX

N = 600
UNITS = ["--signal-unit", "deg/h", "--time-unit", "s", "--temp-unit", "degC"]


def _frame() -> dict[str, np.ndarray]:
    t = np.arange(N, dtype=float)
    temp = 10.0 + 30.0 * t / (N - 1)
    gyro = 0.5 + 0.02 * (temp - 25.0)  # [deg/h]
    return {"time": t, "gyro": gyro, "T1": temp}


def _lines(delim: str = ",") -> list[str]:
    f = _frame()
    return [delim.join(repr(float(v)) for v in row) for row in zip(*f.values(), strict=True)]


def _text(header: str, rows: list[str]) -> bytes:
    return ("\n".join([header, *rows]) + "\n").encode()


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _run(
    argv: list[str], files: list[Path], capsys: pytest.CaptureFixture[str]
) -> tuple[int, str, str]:
    """Run the CLI in-process; check the contract common to every attack."""
    before = {p: _digest(p) for p in files}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    assert code in (0, 2), f"exit {code}: {err}"
    if code == 2:
        assert err.strip().splitlines()[-1].startswith("error: "), err
    assert {p: _digest(p) for p in files} == before, "an input file changed"
    for p in files:
        assert not list(p.parent.glob(f"*{TEMP_SUFFIX}"))
    return code, out, err


COMMANDS = {
    "inspect": ["inspect", "{f}", "--signal", "gyro", "--temps", "T1", *UNITS],
    "metrics": ["metrics", "{f}", "--signal", "gyro", "--temps", "T1", *UNITS],
    "fit": ["fit", "{f}", "--model", "poly", "--order", "1", "--signal", "gyro", "--temps",
            "T1", "-o", "{o}", *UNITS],
}  # fmt: skip


def _argv(cmd: str, f: Path) -> list[str]:
    return [a.format(f=f, o=f.parent / "model.json") for a in COMMANDS[cmd]]


# --- duplicate column names -----------------------------------------------------------------


def _duplicates() -> dict[str, tuple[str, bytes]]:
    """name → (file name, content) of files naming ``gyro`` twice; the second ``gyro`` is
    100 times the first, so reading either silently gives a number."""
    rows = _lines()
    doubled = [r.split(",") for r in rows]
    comma = [",".join([a, b, repr(100 * float(b)), c]) for a, b, c in doubled]
    f = _frame()
    table = pa.Table.from_arrays(
        [pa.array(f["time"]), pa.array(f["gyro"]), pa.array(100 * f["gyro"]), pa.array(f["T1"])],
        names=["time", "gyro", "gyro", "T1"],
    )
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink)
    return {
        "comma": ("data.csv", _text("time,gyro,gyro,T1", comma)),
        "semicolon": ("data.csv", _text("time;gyro;gyro;T1", [r.replace(",", ";") for r in comma])),
        "tab": ("data.tsv", _text("time\tgyro\tgyro\tT1", [r.replace(",", "\t") for r in comma])),
        "blank-padded": ("data.csv", _text("time, gyro,gyro ,T1", comma)),
        "quoted": ("data.csv", _text('time,"gyro","gyro",T1', comma)),
        "parquet": ("data.parquet", bytes(sink.getvalue().to_pybytes())),
    }


@pytest.mark.parametrize("cmd", sorted(COMMANDS))
@pytest.mark.parametrize("case", sorted(_duplicates()))
def test_duplicate_column_names_are_refused(
    case: str, cmd: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    name, content = _duplicates()[case]
    f = tmp_path / name
    f.write_bytes(content)
    code, _out, err = _run(_argv(cmd, f), [f], capsys)
    assert code == 2, err
    last = err.strip().splitlines()[-1]
    assert "'gyro'" in last and "twice" in last, last
    assert not (tmp_path / "model.json").exists()


def test_a_repeated_unused_column_is_refused_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Commands keep the other columns (inspect lists them): two ``aux`` are refused."""
    rows = [r + ",1.0,2.0" for r in _lines()]
    f = tmp_path / "data.csv"
    f.write_bytes(_text("time,gyro,T1,aux,aux", rows))
    code, _out, err = _run(_argv("inspect", f), [f], capsys)
    assert code == 2 and "'aux'" in err, err


# --- malformed numbers ----------------------------------------------------------------------

MALFORMED = {
    "underscore": "0_5",  # float('0_5') == 5.0
    "grouped-thousands": "1_000.5",
    "fullwidth-digits": "\uff11\uff12",  # float('１２') == 12.0
    "arabic-indic-digits": "\u0663",  # float('٣') == 3.0
}
ROW = 10
"""The data row (0-based) whose gyro value is replaced."""


def _malformed(delim: str, value: str) -> bytes:
    rows = _lines(delim)
    fields = rows[ROW].split(delim)
    fields[1] = value
    rows[ROW] = delim.join(fields)
    return _text(delim.join(["time", "gyro", "T1"]), rows)


@pytest.mark.parametrize("delim", [",", ";"], ids=["comma", "semicolon"])
@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_a_malformed_number_is_a_bad_line(
    case: str, delim: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "data.csv"
    f.write_bytes(_malformed(delim, MALFORMED[case]))
    code, _out, err = _run(_argv("metrics", f), [f], capsys)
    assert code == 2, f"the malformed number was read as a value: {err}"
    # the line of the file (header is line 1) or the row is named
    last = err.strip().splitlines()[-1]
    assert f"line {ROW + 2}" in last, last


@pytest.mark.parametrize("delim", [",", ";"], ids=["comma", "semicolon"])
def test_on_bad_lines_skip_drops_the_malformed_line(
    delim: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With ``--on-bad-lines skip`` the line is dropped and counted: 599 rows remain and the
    mean is that of the others (the 5.0 that ``float('0_5')`` gives is not in it)."""
    f = tmp_path / "data.csv"
    f.write_bytes(_malformed(delim, "0_5"))
    argv = ["metrics", str(f), "--signal", "gyro", "--temps", "T1", *UNITS, "--json",
            "--on-bad-lines", "skip"]  # fmt: skip
    code, out, err = _run(argv, [f], capsys)
    assert code == 0, err
    assert any(ln.startswith("warning: ") and "1 mangled line" in ln for ln in err.splitlines())
    g = np.delete(_frame()["gyro"], ROW)
    assert json.loads(out)["bias"] == pytest.approx(float(np.mean(g)), rel=1e-12)


# --- one 10 MB line ---------------------------------------------------------------------------

MB10 = 10_000_000


def _long_lines() -> dict[str, bytes]:
    rows = _lines()
    semi = [r.replace(",", ";") for r in rows]
    return {
        # the audit's case: pandas renames repeats a, a.1, a.2 … in quadratic time
        "header-of-one-name": _text(",".join(["a"] * (MB10 // 2)), ["1,2"]),
        "header-of-two-names": _text(",".join(["gyro", "T1"] * (MB10 // 8)), rows[:3]),
        "one-name-of-10-MB": _text("time,gyro,T1" + "(" * MB10, rows),
        "data-row": _text("time,gyro,T1", [*rows[:300], "300," + "2" * MB10 + ",3", *rows[301:]]),
        "banner": _text("x" * MB10 + "\ntime,gyro,T1", rows),
        "semicolon-row": _text("time;gyro;T1", [*semi[:300], "1;" * (MB10 // 2), *semi[301:]]),
    }


@pytest.mark.parametrize("case", sorted(_long_lines()))
def test_a_10_mb_line_finishes_in_seconds(case: str, tmp_path: Path) -> None:
    f = tmp_path / "data.csv"
    f.write_bytes(_long_lines()[case])
    digest = _digest(f)
    argv = ["metrics", str(f), "--signal", "gyro", "--temps", "T1", *UNITS]
    code = "import sys; from thermocal.cli import main; sys.exit(main(sys.argv[1:]))"
    done = subprocess.run(
        [sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=60
    )
    assert done.returncode in (0, 2), done.stderr[-2000:]
    assert "Traceback" not in done.stderr
    assert len(done.stderr) < 5000, "a message repeats the 10 MB line"
    assert _digest(f) == digest
