"""``report --modeling`` reads its file like ``--recording``: through
:func:`thermocal.readers.read_recording` with the text-log options (issue 27; a headerless
serial log there used to stop the report with an error telling the user to pass
``--names``, which only reached ``--recording``).  The modelling run's row of the report
is checked against the numbers of the log written here."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.errors import TextLayoutWarning
from thermocal.readers.options import ReadOptions
from thermocal.report.files import make_report

BANNER = [
    "=~=~=~=~=~=~=~=~=~=~=~= PuTTY log 2026.11.20 10:15:03 =~=~=~=~=~=~=~=~=~=~=~=",
    "BMI270 temperature test v1.2",
    "IMU init ok, ODR 50 Hz",
]
RATE_HZ = 50.0
NAMES = "gx,gy,gz,T"


def _write_log(path: Path, n: int, t_mid: float, seed: int) -> np.ndarray:
    """A serial capture: a banner, no header row, no time column, blank-separated
    fields gx gy gz T; gx carries 0.8 (°/h)/°C.  Returns the samples as written."""
    rng = np.random.default_rng(seed)
    T = t_mid + 8.0 * np.sin(np.arange(n) / 300.0)
    g = rng.normal(0.0, 2.0, (n, 3)) + 0.8 * (T[:, None] - 25.0)
    data = np.round(np.column_stack([g, T]), 6)
    lines = [*BANNER, *(" ".join(f"{v:.6f}" for v in row) for row in data)]
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode())
    return data


def _modelling_row(html: str) -> list[str]:
    """The cells of the runs table's ``modelling`` row."""
    m = re.search(r"<tr><td>modelling</td>(.*?)</tr>", html, re.S)
    assert m is not None, "no modelling row in the runs table"
    return [
        re.sub(r"<[^>]+>", "", c).strip()
        for c in re.findall(r"<td[^>]*>(.*?)</td>", m.group(1), re.S)
    ]


def _check_row(html: str, data: np.ndarray) -> None:
    cells = _modelling_row(html)
    # File, Samples, Duration [h], Interval [s], Gaps, Signal, Temperatures, Range [°C]
    assert cells[0].startswith("mod.log")
    n = data.shape[0]
    assert int(cells[1]) == n
    assert cells[2] == f"{(n - 1) / RATE_HZ / 3600.0:.3g}"  # shown to 3 digits
    assert float(cells[3]) == pytest.approx(1.0 / RATE_HZ, rel=1e-9)
    lo, hi = (float(v) for v in cells[7].split("…"))
    assert lo == pytest.approx(float(data[:, 3].min()), abs=0.05)
    assert hi == pytest.approx(float(data[:, 3].max()), abs=0.05)


@pytest.fixture
def logs(tmp_path: Path) -> tuple[Path, Path, Path, np.ndarray]:
    mod, val = tmp_path / "mod.log", tmp_path / "val.log"
    data = _write_log(mod, 2400, 30.0, 1)
    _write_log(val, 1800, 20.0, 2)
    model = tmp_path / "m.json"
    fit = ["fit", str(mod), "--signal", "gx", "--temps", "T", "--model", "poly", "--order", "1",
           "--names", NAMES, "--rate", str(RATE_HZ), "--signal-unit", "deg/h",
           "--temp-unit", "degC", "-o", str(model)]  # fmt: skip
    assert main(fit) == 0
    return model, mod, val, data


def test_report_reads_a_headerless_modelling_log(
    logs: tuple[Path, Path, Path, np.ndarray],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    model, mod, val, data = logs
    html = tmp_path / "r.html"
    capsys.readouterr()
    code = main(["report", "--model", str(model), "--recording", str(val), "--modeling",
                 str(mod), "--names", NAMES, "--rate", str(RATE_HZ), "--average", "1",
                 "-o", str(html)])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 0, err
    text = html.read_text(encoding="utf-8")
    _check_row(text, data)
    assert 'id="fig-fit"' in text  # the model drawn on the modelling run


def test_make_report_reads_the_modelling_log_with_the_text_options(
    logs: tuple[Path, Path, Path, np.ndarray], tmp_path: Path
) -> None:
    model, mod, val, data = logs
    read = ReadOptions(names=tuple(NAMES.split(",")), rate_hz=RATE_HZ)
    with warnings.catch_warnings(record=True) as caught:  # how each log was read, said
        warnings.simplefilter("always")
        res = make_report([model], val, tmp_path / "r.html", modeling=mod, averaging_s=1.0,
                          read=read)  # fmt: skip
    said = [str(w.message) for w in caught if issubclass(w.category, TextLayoutWarning)]
    assert any(m.startswith(f"{mod}: 3 banner line(s)") for m in said), said
    assert res.kind == "models" and res.path == tmp_path / "r.html"
    _check_row(res.path.read_text(encoding="utf-8"), data)
