"""The rate-table tutorial (``docs/tutorials/ratetable.md``) runs as written: every block in
order in an empty folder, what it prints equal to the page's ``text`` block, and its figures
the simulated truth (``thermocal.simulate.scenarios.RATETABLE_ERRORS``: 40 ppm/°C, a 0.015 °/s
dead zone) and a least-squares line computed here (numpy.polyfit)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from tutorial_pages import Page, _numbers, assert_prints_as_shown, run_page

PAGE = "ratetable.md"


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Page:
    return run_page(tmp_path_factory, PAGE)


def test_ratetable_tutorial_prints_what_the_page_shows(
    page: Page,
) -> None:
    assert_prints_as_shown(page[0], 6)


def test_ratetable_tutorial_figures_are_the_simulated_truth(
    page: Page,
) -> None:
    pairs, tmp = page
    truth = json.loads((tmp / "truth.json").read_text())
    tr = next(f for f in truth["files"] if f["label"] == "T+20")
    assert "0.01 < · ≤ 0.02" in pairs[1][0] and 0.01 < tr["dead_zone_dps"] <= 0.02
    w = np.array([p["rate_dps"] for p in tr["plateaus"]])
    y = np.array(tr["outputs"])
    keep = np.arange(w.size) != 30  # the plateau cut short, left out
    k = np.polyfit(w[keep], y[keep], 1)[0]
    m = re.search(r"scale factor\s+│\s+([\d.]+) ± ([\d.e-]+)", pairs[1][0])
    assert m is not None and abs(float(m[1]) - k) < 4 * float(m[2])
    tc = re.search(r"TC = ([\d.]+) ± ([\d.]+) ppm/°C about ([\d.]+)", pairs[2][0])
    assert tc is not None
    want = tr["tc_ppm_per_c"] / (1 + tr["tc_ppm_per_c"] * 1e-6 * (float(tc[3]) - 25.0))
    assert abs(float(tc[1]) - want) < 4 * float(tc[2])
    a, b = _numbers(pairs[3][0])
    assert a == b


def test_ratetable_tutorial_program_start_is_the_truths(
    page: Page,
) -> None:
    pairs, tmp = page
    truth = json.loads((tmp / "program.json").read_text())["files"][0]
    assert "table_rate" not in (tmp / "program.csv").read_text().splitlines()[0]
    found = re.search(r"found: first plateau at ([\d.]+) s, table at ([\d.]+)", pairs[5][0])
    assert found is not None
    assert abs(float(found[1]) - truth["plateaus"][0]["start_s"]) < 0.02
    assert abs(float(found[2]) - truth["accel_dps2"]) < 0.01 * truth["accel_dps2"]
