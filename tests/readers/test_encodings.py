"""Text encodings of CSV files (issue 14): UTF-8, UTF-8 with a byte-order mark and Latin-1
are read; UTF-16/32 is refused with the remedy."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from thermocal.cli import main

ROWS = "0,1.5,20\n1,1.75,20.5\n2,2.0,21\n3,2.25,21.5\n"


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize(
    ("raw", "warned"),
    [
        ("time,gyro °/h,Temp °C\n".encode() + ROWS.encode(), False),  # UTF-8
        (b"\xef\xbb\xbf" + "time,gyro °/h,Temp °C\n".encode() + ROWS.encode(), False),  # BOM
        ("time,gyro °/h,Temp °C\n".encode("latin-1") + ROWS.encode(), True),  # Latin-1
    ],
    ids=["utf-8", "utf-8-bom", "latin-1"],
)
def test_utf8_bom_and_latin1_headers_are_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], raw: bytes, warned: bool
) -> None:
    path = tmp_path / "rec.csv"
    path.write_bytes(raw)
    code, out, err = _run(
        capsys, "metrics", str(path), "--signal", "gyro °/h", "--signal-unit", "deg/h",
        "--temps", "Temp °C", "--temp-unit", "degC", "--time-unit", "s", "--json",
    )  # fmt: skip
    assert code == 0, err
    d = json.loads(out)
    assert d["bias"] == pytest.approx(1.875, abs=1e-12)  # mean of 1.5, 1.75, 2.0, 2.25
    assert ("read as Latin-1" in err) is warned


def test_utf16_is_refused_with_the_remedy(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "rec.csv"
    path.write_text("time,gyro,T1\n" + ROWS, encoding="utf-16")
    code, out, err = _run(capsys, "inspect", str(path))
    assert code == 2 and out == ""
    assert err.strip().splitlines() == [
        f"error: {path}: the text is UTF-16 or UTF-32 encoded (NUL bytes); save it as UTF-8 CSV"
    ]
