"""Text logs as lab engineers have them (issue 16): a serial-terminal capture with a PuTTY
banner, no header row, no time column, blank-separated fields and mangled lines; other
locales' CSV (semicolons, decimal commas). Checked through the CLI, against values written
here and allantools on the same samples."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import allantools
import numpy as np
import pytest

from thermocal.cli import main
from thermocal.errors import TextLayoutWarning
from thermocal.readers.dispatch import read_recording
from thermocal.readers.options import ReadOptions
from thermocal.readers.text import sniff_text

BANNER = [
    "=~=~=~=~=~=~=~=~=~=~=~= PuTTY log 2026.11.20 10:15:03 =~=~=~=~=~=~=~=~=~=~=~=",
    "BMI270 temperature test v1.2",
    "IMU init ok, ODR 100 Hz",
]
RATE_HZ = 100.0
N = 3000


def _samples(seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    T = 25.0 + 10.0 * np.sin(np.arange(N) / 400.0)
    g = rng.normal(0.0, 5.0, (N, 3)) + 0.8 * (T[:, None] - 25.0)
    return np.column_stack([g, T])


def _write_log(path: Path, data: np.ndarray, mangle: bool) -> list[str]:
    lines = [*BANNER, *(" ".join(f"{v:.6f}" for v in row) for row in data)]
    if mangle:  # a cut line, two lines run together, line noise
        k = len(BANNER)
        lines[k + 500] = lines[k + 500][:9]
        lines[k + 900] = lines[k + 900] + " " + lines[k + 901]
        lines[k + 1200] = "0.00@1 0.002 0.003 25.1"
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode())
    return lines


def _run(args: list[str]) -> tuple[int, str]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(args)
    return code, buf.getvalue()


TEXT = ["--names", "gx,gy,gz,T", "--rate", "100", "--signal-unit", "deg/h",
        "--temp-unit", "degC"]  # fmt: skip


def test_mangled_lines_are_refused_naming_the_first(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bmi.log"
    _write_log(path, _samples(), mangle=True)
    assert main(["inspect", str(path), "--signal", "gx", "--temps", "T", *TEXT]) == 2
    err = capsys.readouterr().err
    # the cut line is line 3 (banner) + 500 + 1 of the file
    assert "line 504 is not a data row (" in err and "fields, 4 expected" in err
    assert "--on-bad-lines skip" in err


def test_skip_drops_and_reports_mangled_lines_and_keeps_time(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bmi.log"
    data = _samples()
    _write_log(path, data, mangle=True)
    code, out = _run(["inspect", str(path), "--signal", "gx", "--temps", "T", *TEXT,
                      "--on-bad-lines", "skip", "--json"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 0, err
    d = json.loads(out)
    assert d["n_samples"] == N - 3
    assert "3 banner line(s) before the data skipped" in err
    assert "3 mangled line(s) dropped (--on-bad-lines skip): line(s) 504, 904, 1204" in err
    # time = data-line number / rate: the dropped lines leave gaps, the rest keep their time
    with pytest.warns(TextLayoutWarning):
        rec = read_recording(
            path,
            ReadOptions(
                signals=["gx"],
                temperatures=["T"],
                signal_unit="deg/h",
                temp_unit="degC",
                names=("gx", "gy", "gz", "T"),
                rate_hz=RATE_HZ,
                on_bad_lines="skip",
            ),
        )
    keep = np.setdiff1d(np.arange(N), [500, 900, 1200])  # the three mangled lines
    np.testing.assert_array_equal(rec.time_s, keep / RATE_HZ)
    # every value kept is the one written on its line (6 decimals)
    np.testing.assert_allclose(rec.column("gx"), np.round(data[keep, 0], 6), rtol=0, atol=0)
    np.testing.assert_allclose(rec.column("T"), np.round(data[keep, 3], 6), rtol=0, atol=0)


def test_allan_on_a_serial_log_equals_allantools(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A clean capture (banner, no header, no time column): the overlapping ADEV equals
    allantools on the samples as written."""
    path = tmp_path / "bmi.log"
    data = np.round(_samples(3), 6)
    _write_log(path, data, mangle=False)
    code, out = _run(["allan", str(path), "--signal", "gx", "--temps", "T", *TEXT,
                      "--taus", "0.01,0.02,0.04,0.08,0.16,0.32,0.64", "--json"])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    d = json.loads(out)
    tau0 = 1.0 / RATE_HZ
    taus = np.array([1, 2, 4, 8, 16, 32, 64]) * tau0
    t_ref, adev_ref, _e, _n = allantools.oadev(data[:, 0], rate=RATE_HZ, data_type="freq",
                                               taus=taus)  # fmt: skip
    assert d["unit"] == "deg/h"
    np.testing.assert_allclose(d["tau_s"], t_ref, rtol=1e-12)
    np.testing.assert_allclose(d["adev"], adev_ref, rtol=1e-9)


def test_semicolons_and_decimal_commas_are_read_and_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "eu.csv"
    rows = [f"{i * 0.5:.1f};{20 + i * 0.01:.2f};{0.5 + i * 1e-4:.5f}" for i in range(200)]
    path.write_text("Zeit;Temp;gx\n" + "\n".join(r.replace(".", ",") for r in rows) + "\n")
    code, out = _run(["metrics", str(path), "--time", "Zeit", "--time-unit", "s", "--signal",
                      "gx", "--signal-unit", "deg/h", "--temps", "Temp", "--temp-unit", "degC",
                      "--json", "--average", "10"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 0, err
    assert "read as ';'-separated text with decimal mark ','" in err
    d = json.loads(out)
    assert d["bias"] == pytest.approx(np.mean(0.5 + np.arange(200) * 1e-4), rel=1e-12)


@pytest.mark.parametrize(
    ("text", "want"),
    [
        ("time,g\n0,1\n1,2\n", (0, ",", ".", True)),
        ("# a comment\ntime\tg\n0\t1\n1\t2\n", (1, "\t", ".", True)),
        ("log start\n1 2 3\n4 5 6\n7 8 9\n", (1, " ", ".", False)),
        ("t;g\n0,5;1,25\n1,5;2,5\n", (0, ";", ",", True)),
        ("time,g\n0,abc\n0,0\n", (0, ",", ".", True)),  # a mangled row is not a header
    ],
)
def test_sniff_text(text: str, want: tuple[int, str, str, bool]) -> None:
    lay = sniff_text(text.splitlines())
    assert (lay.skip, lay.delimiter, lay.decimal, lay.header) == want


def test_names_and_rate_are_checked(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "a.log"
    _write_log(path, _samples(), mangle=False)
    # no header and no names
    assert main(["inspect", str(path), "--rate", "100"]) == 2
    assert "no header row" in capsys.readouterr().err
    # wrong number of names
    assert main(["inspect", str(path), "--names", "a,b", "--rate", "100"]) == 2
    assert "2 names for 4 columns" in capsys.readouterr().err
    # --rate with a time column
    csv = tmp_path / "t.csv"
    csv.write_text("time,g\n0,1\n1,2\n2,3\n")
    assert main(["inspect", str(csv), "--rate", "10"]) == 2
    assert "has a time column" in capsys.readouterr().err


def test_fit_and_compensate_a_serial_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import pandas as pd

    path = tmp_path / "bmi.log"
    data = _samples(7)
    _write_log(path, data, mangle=True)
    opts = [*TEXT, "--on-bad-lines", "skip"]
    model = tmp_path / "m.json"
    assert main(["fit", str(path), "--signal", "gx", "--temps", "T", "--model", "poly",
                 "--order", "1", *opts, "-o", str(model)]) == 0  # fmt: skip
    out = tmp_path / "comp.csv"
    assert main(["compensate", str(model), str(path), *opts[:4], "--on-bad-lines", "skip",
                 "-o", str(out)]) == 0  # fmt: skip
    capsys.readouterr()
    d = pd.read_csv(out)
    assert len(d) == N - 3
    keep = np.setdiff1d(np.arange(N), [500, 900, 1200])
    np.testing.assert_allclose(d["time"], keep / RATE_HZ, rtol=0, atol=1e-12)
    np.testing.assert_allclose(d["gx_comp"], d["gx"] - d["gx_model"], rtol=0, atol=1e-9)
    # the 0.8 (deg/h)/°C slope written into the data is what the model removed
    assert float(np.std(d["gx_comp"])) == pytest.approx(5.0, rel=0.1)


def test_report_and_compensate_read_logs_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The text options and --topic reach report and compensate (INTERFACE: all commands)."""
    path = tmp_path / "bmi.log"
    _write_log(path, _samples(9), mangle=False)
    model = tmp_path / "m.json"
    assert main(["fit", str(path), "--signal", "gx", "--temps", "T", "--model", "poly",
                 "--order", "1", *TEXT, "-o", str(model)]) == 0  # fmt: skip
    html = tmp_path / "r.html"
    text = ["--names", "gx,gy,gz,T", "--rate", "100"]
    assert main(["report", "--model", str(model), "--recording", str(path), *text,
                 "--average", "1", "-o", str(html)]) == 0  # fmt: skip
    assert html.stat().st_size > 10_000
    capsys.readouterr()
