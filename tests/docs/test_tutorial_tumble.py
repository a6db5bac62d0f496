"""The tumble tutorial (``docs/tutorials/tumble.md``) runs as written: every block in order
in an empty folder, what it prints equal to the page's ``text`` block, its K2 and Kip within
3σ of the simulated truth (:data:`thermocal.tumble.simulate.TRUTH`) and equal to the
least-squares harmonics computed on the page (numpy.linalg.lstsq)."""

from __future__ import annotations

import re

import pytest

from thermocal.tumble.simulate import TRUTH
from tutorial_pages import Page, assert_prints_as_shown, run_page

PAGE = "tumble.md"


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Page:
    return run_page(tmp_path_factory, PAGE)


def test_tumble_tutorial_prints_what_the_page_shows(
    page: Page,
) -> None:
    assert_prints_as_shown(page[0], 5)


def test_tumble_tutorial_figures_are_the_simulated_truth(
    page: Page,
) -> None:
    pairs, _ = page
    for name in ("k2", "k_ip"):
        m = re.search(rf"^{name}\s+(\S+) ± (\S+)", pairs[2][0], re.MULTILINE)
        assert m is not None and abs(float(m[1]) - TRUTH[name]) < 3 * float(m[2])
    for line in pairs[3][0].splitlines():
        a, b = re.findall(r"-?\d+\.\d+", line)
        assert a == b
    assert "6 angles" in pairs[4][0]
