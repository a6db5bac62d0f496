"""The notebook tutorial (``docs/tutorials/notebook-allan.md``) runs as written (the runner of
``test_tutorials.py``) and its numbers are right: the printed overlapping Allan deviation
equals NIST SP 1065 eq. 11 computed here with numpy on the page's own simulation, the truth's
Allan deviation (IEEE Std 952-1997 Annex C: N²/τ + K²τ/3) lies inside every printed interval,
and the recovered angle and rate random walks hold the simulated N and K in their intervals.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tutorial_pages import _numbers, _run_in_scratch

N_TRUE = 0.005 * 60.0  # the page's N [deg/√s] in deg/√h
K_TRUE = 0.0005 * 60.0  # the page's K [deg/s/√s] in deg/s/√h

Page = tuple[list[tuple[str, str]], Path]


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Page:
    tmp = tmp_path_factory.mktemp("notebook_allan")
    return _run_in_scratch(tmp, "notebook-allan.md"), tmp


def _simulation() -> np.ndarray:
    """The page's draw, repeated here: white rate noise of N plus a random walk of K."""
    rate_hz, n = 100.0, 400_000
    rng = np.random.default_rng(0)
    white = rng.normal(0.0, 0.005 * math.sqrt(rate_hz), n)
    return white + np.cumsum(rng.normal(0.0, 0.0005 / math.sqrt(rate_hz), n))


def _oadev_numpy(y: np.ndarray, tau0: float, m: int) -> float:
    """NIST SP 1065 eq. 11: every second difference of the phase x_k = τ0 Σ_{i<k} y_i."""
    x = np.concatenate([[0.0], np.cumsum(y)]) * tau0
    d = x[2 * m :] - 2.0 * x[m:-m] + x[: -2 * m]
    return float(np.sqrt(np.mean(d**2) / (2.0 * (m * tau0) ** 2)))


def test_the_page_prints_what_it_shows(page: Page) -> None:
    pairs, tmp = page
    assert len(pairs) == 4
    for printed, shown in pairs:
        assert _numbers(printed) == _numbers(shown)
    assert (tmp / "oadev.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_printed_oadev_is_the_numpy_formula_and_holds_the_truth(page: Page) -> None:
    printed = page[0][1][0]
    rows = np.array([_numbers(ln) for ln in printed.splitlines()[1:]])
    tau, dev, low, high = rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3]
    assert tau.tolist() == pytest.approx([0.01 * 4**k for k in range(9)], rel=1e-3)
    y = _simulation()
    want = [_oadev_numpy(y, 0.01, 4**k) for k in range(9)]
    assert dev == pytest.approx(want, rel=1e-3)  # four printed digits
    truth = np.sqrt(0.005**2 / tau + 0.0005**2 * tau / 3.0)
    assert np.all((low <= truth) & (truth <= high))


def test_the_recovered_noise_terms_hold_the_simulated_truth(page: Page) -> None:
    printed = page[0][2][0].splitlines()
    arw = _numbers(printed[0].split(":", 1)[1])
    rrw = _numbers(printed[1].split(":", 1)[1])
    assert arw[1] < N_TRUE < arw[2] and rrw[1] < K_TRUE < rrw[2]
    assert arw[0] == pytest.approx(N_TRUE, rel=0.01)
    assert rrw[0] == pytest.approx(K_TRUE, rel=0.05)
