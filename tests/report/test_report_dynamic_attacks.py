"""Hostile ``report --dynamic`` windows and records: a window that is no length, a record with
a gap."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pandas as pd
import pytest

from thermocal.cli import main


def _run(argv: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(argv)
    return code, o.getvalue(), e.getvalue()


def _refused(argv: list[str], *words: str) -> str:
    """Exit 2, exactly one ``error:`` line holding every word, no traceback."""
    code, _o, err = _run(argv)
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2, (code, err)
    assert len(errors) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in errors[0], (w, errors[0])
    return errors[0]


@pytest.fixture(scope="module")
def dyn_work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """test_report_dynamic's records: 20 000 s at 1 Hz, a linear model fitted on one."""
    from test_report_dynamic import work

    made: Path = work.__wrapped__(tmp_path_factory)  # type: ignore[attr-defined]
    return made


DYN = ["--signal", "gyro [deg/h]", "--time", "time [s]"]


@pytest.mark.parametrize(
    ("window", "words"),
    [
        ("nan", ("--dynamic", "> 0")),
        ("inf", ("--dynamic", "> 0")),
        ("-5", ("--dynamic", "> 0")),
        ("0", ("--dynamic", "> 0")),
        ("1e300", ("fewer than two windows",)),
        ("10001", ("fewer than two windows",)),
        ("0.5", ("holds 0 samples",)),
        ("2000s", ("--dynamic",)),
        ("", ("--dynamic",)),
    ],
)
def test_report_dynamic_window_that_is_no_length(
    dyn_work: Path, window: str, words: tuple[str, ...]
) -> None:
    out = dyn_work / "r.html"
    argv = [
        "report",
        "--model",
        str(dyn_work / "lin.json"),
        "--recording",
        str(dyn_work / "steady.csv"),
    ]
    _refused([*argv, *DYN, "-o", str(out), "--dynamic", window], *words)
    assert not out.exists()


def test_report_dynamic_on_a_record_with_a_gap(dyn_work: Path) -> None:
    """4000 s cut out of the steady record: the report is written, the gap said; the map's
    window is the one asked for, and a stationary output draws no warning."""
    df = pd.read_csv(dyn_work / "steady.csv").drop(index=range(5000, 9000))
    df.to_csv(dyn_work / "gap.csv", index=False)
    out = dyn_work / "rg.html"
    argv = [
        "report",
        "--model",
        str(dyn_work / "lin.json"),
        "--recording",
        str(dyn_work / "gap.csv"),
    ]
    code, _o, err = _run([*argv, *DYN, "-o", str(out), "--dynamic", "2000"])
    assert code == 0, err
    assert "gaps in time" in err and "not stationary" not in err, err
    html = out.read_text()
    assert 'data-key="dynamic.window_s" data-value="2000.0"' in html
