"""The chamber-log tutorial (``docs/tutorials/chamber-log.md``) runs as written: every block
in order in an empty folder, what it prints equal to the page's ``text`` block, and its
figures the truth the page's own generator used (offset 1820 s, no drift, a bias of
3 + 0.02 (T − 25) deg/h); the refused join it shows is what the command prints."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from thermocal.cli import main
from tutorial_pages import TUTORIALS, _numbers, _run_in_scratch

PAGE = "chamber-log.md"


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[tuple[str, str]], Path]:
    tmp = tmp_path_factory.mktemp("chamber-log")
    return _run_in_scratch(tmp, PAGE), tmp


def test_chamber_log_tutorial_prints_what_the_page_shows(
    page: tuple[list[tuple[str, str]], Path],
) -> None:
    pairs, _ = page
    assert len(pairs) == 5
    for printed, shown in pairs:
        printed, shown = _rounding_zero(printed), _rounding_zero(shown)
        assert _numbers(printed) == _numbers(shown)
        lines = [" ".join(ln.split()) for ln in printed.strip().splitlines()]
        assert lines == [" ".join(ln.split()) for ln in shown.strip().splitlines()]


def _rounding_zero(text: str) -> str:
    """A least-squares residual's mean (the page prints -1.593e-15) is rounding, not a
    figure: any |value| below 1e-12 is compared as the word "zero" (its digits, and so the
    cell's padding, follow the numpy and BLAS in use, the floor's among them: lines are
    compared with their runs of spaces as one)."""
    return re.sub(r"-?\d\.\d+e-(1[2-9]|[2-9]\d)\b", "zero", text)


def test_chamber_log_tutorial_figures_are_the_truth(
    page: tuple[list[tuple[str, str]], Path],
) -> None:
    pairs, _ = page
    m = re.search(r"offset ([\d.]+) ± ([\d.]+) s, drift ([-\d.]+) ± ([\d.]+) ppm", pairs[1][0])
    assert m is not None
    assert abs(float(m[1]) - 1820.0) < 3.0 * float(m[2])
    assert abs(float(m[3])) < 3.0 * float(m[4])
    coef = re.search(r"T1\s+│\s+([\d.]+)\s+│\s+([\d.e-]+)", pairs[2][0])
    assert coef is not None and abs(float(coef[1]) - 0.02) < 4.0 * float(coef[2])
    # compensate with the log: the bias's 0.02 deg/h/°C over −15…70 °C taken off, the
    # generator's 0.01 deg/h noise left
    after = re.search(r"rms after \(about the mean\)\s+│\s+([\d.]+) deg/h", pairs[3][0])
    assert after is not None and 0.0095 < float(after[1]) < 0.0105


def test_the_refused_join_is_printed_as_shown(
    page: tuple[list[tuple[str, str]], Path],
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    _, tmp = page
    text = (TUTORIALS / PAGE).read_text(encoding="utf-8")
    m = re.search(r"^\$ thermocal (profile join .*--chamber-offset 9000)\n(error: .*)$", text, re.M)
    assert m is not None
    monkeypatch.chdir(tmp)
    code = main(m[1].split())
    assert code == 2
    assert capsys.readouterr().err.strip() == m[2]
