"""The thermal-hysteresis tutorial (``docs/tutorials/hysteresis.md``) runs as written: every
block in order in an empty folder, what it prints equal to the page's ``text`` block (lines
stripped on both sides), and its figures the simulator's truth: the legs are the program's
ramps, the lag fitted on the heating leg is the truth's within 3σ, and the cooling leg's
RMS after the lag model is the truth's noise within 10 %."""

from __future__ import annotations

import json
import re

import pytest

from tutorial_pages import Page, assert_prints_as_shown, run_page

PAGE = "hysteresis.md"


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Page:
    return run_page(tmp_path_factory, PAGE)


def test_hysteresis_tutorial_prints_what_the_page_shows(
    page: Page,
) -> None:
    assert_prints_as_shown(page[0], 6)


def test_hysteresis_tutorial_figures_are_the_simulated_truth(
    page: Page,
) -> None:
    pairs, tmp = page
    truth = json.loads((tmp / "truth.json").read_text())["files"][0]
    legs = re.findall(r"(heating|cooling) (\d+)…(\d+) s", pairs[1][0])
    assert [d for d, _, _ in legs] == [g["direction"] for g in truth["legs"]]
    for (_, a, b), g in zip(legs, truth["legs"], strict=True):  # within 3 lattice steps
        assert abs(float(a) - g["start_s"]) <= 3 * 0.0625 * 60 and abs(float(b) - g["stop_s"]) <= 12
    tau = re.search(r"│ tau\s+│ ([\d.]+)\s+│ ([\d.]+)", pairs[3][0])
    assert tau is not None and abs(float(tau[1]) - truth["lag_s"]) < 3 * float(tau[2])
    cooling = re.findall(r"│ cooling │[^│]+│[^│]+│[^│]+│ ([\d.]+)", pairs[5][0])
    assert float(cooling[0]) == pytest.approx(truth["noise"], rel=0.1)
    poly_cool = re.findall(r"│ cooling │[^│]+│[^│]+│[^│]+│ ([\d.]+)", pairs[4][0])
    assert float(poly_cool[0]) > 10 * truth["noise"]
