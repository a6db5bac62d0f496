"""The tutorials run as written: every ``console`` and ``python`` block of a tutorial page is
executed from the repository's root, in order, and what it prints is compared, number by
number, with the ``text`` block that follows it on the page; the numbers are also checked
against the reference the page quotes (Stable32's printed tables, shipped in
``tests/data/stable32_phasedat`` from allantools' test data, LGPL-3.0).
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

ROOT = Path(__file__).resolve().parents[2]
TUTORIALS = ROOT / "docs" / "tutorials"
STABLE32 = ROOT / "tests" / "data" / "stable32_phasedat"
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```$", re.MULTILINE | re.DOTALL)


def _run_block(lang: str, body: str) -> str:
    """What a ``console`` block's ``$ thermocal …`` lines or a ``python`` block print."""
    out = io.StringIO()
    if lang == "python":
        with contextlib.redirect_stdout(out):
            exec(compile(body, "tutorial", "exec"), {})
        return out.getvalue()
    for line in body.splitlines():
        assert line.startswith("$ thermocal "), line
        err = io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(shlex.split(line[len("$ thermocal ") :]))
        assert code == 0, err.getvalue()
    return out.getvalue()


def _run_page(page: Path) -> list[tuple[str, str]]:
    """(printed, shown) for every executable block of the page, in order."""
    blocks = [(m.group(1), m.group(2)) for m in BLOCK.finditer(page.read_text(encoding="utf-8"))]
    pairs = []
    for i, (lang, body) in enumerate(blocks):
        if lang in ("console", "python"):
            shown = next(b for la, b in blocks[i + 1 :] if la == "text")
            pairs.append((_run_block(lang, body), shown))
    return pairs


def _numbers(text: str) -> list[float]:
    return [float(v) for v in NUMBER.findall(text)]


def _stable32(name: str) -> np.ndarray:
    """Stable32's printed rows: AF, τ, terms, α, low, deviation, high."""
    lines = (STABLE32 / name).read_text(encoding="latin-1").splitlines()
    return np.array([[float(v) for v in ln.split()] for ln in lines if ln.strip() and ln[0] != "#"])


@pytest.fixture(scope="module")
def stability_page() -> list[tuple[str, str]]:
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(ROOT)
        return _run_page(TUTORIALS / "stability-stable32.md")


def test_every_tutorial_is_executed_here() -> None:
    assert sorted(p.name for p in TUTORIALS.glob("*.md")) == ["stability-stable32.md"]


def test_stability_tutorial_prints_what_the_page_shows(
    stability_page: list[tuple[str, str]],
) -> None:
    assert len(stability_page) == 2
    for printed, shown in stability_page:
        assert _numbers(printed) == _numbers(shown)
        assert len(_numbers(printed)) >= 30


def test_stability_tutorial_numbers_are_stable32s(stability_page: list[tuple[str, str]]) -> None:
    """Values to Stable32's five printed digits, bounds to 2e-3 (its EDF rounding), terms and
    α exactly: the tolerances of tests/test_stability_reference.py."""
    table = [_numbers(line) for line in stability_page[0][0].splitlines() if line.startswith("│")]
    got = np.array(table)  # τ, oadev, low, high, edf, α, terms
    ref = _stable32("phase_dat_oadev_octave.txt")
    np.testing.assert_array_equal(got[:, 0], ref[:, 1])
    np.testing.assert_allclose(got[:, 1], ref[:, 5], rtol=1e-4)
    np.testing.assert_allclose(got[:, 2], ref[:, 4], rtol=2e-3)
    np.testing.assert_allclose(got[:, 3], ref[:, 6], rtol=2e-3)
    np.testing.assert_array_equal(got[:, 5], ref[:, 3])
    np.testing.assert_array_equal(got[:, 6], ref[:, 2])
    # the Python block: oadev and mdev at τ = 1, 4, 16, 64 s against both of Stable32's tables
    rows = [_numbers(line) for line in stability_page[1][0].splitlines()]
    for k, name in enumerate(("oadev", "mdev")):
        ref = _stable32(f"phase_dat_{name}_octave.txt")
        ref = ref[np.isin(ref[:, 1], [1, 4, 16, 64])]
        mine = np.array(rows[4 * k : 4 * k + 4])  # τ, dev, low, high
        np.testing.assert_allclose(mine[:, 1], ref[:, 5], rtol=1e-4)
        np.testing.assert_allclose(mine[:, 2], ref[:, 4], rtol=2e-3)
        np.testing.assert_allclose(mine[:, 3], ref[:, 6], rtol=2e-3)
