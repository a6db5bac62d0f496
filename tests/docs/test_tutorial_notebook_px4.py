"""The tutorial ``docs/tutorials/notebook-px4.md`` runs as written (its ``python`` blocks in
one namespace, as a notebook runs its cells; each block's print compared, number by number,
with the ``text`` block after it), and its parameters are right by two references outside
thermocal: the simulator's true polynomial (written again here) and ``numpy.polyfit`` of
the page's raw samples — PX4's ``Tools/process_sensor_caldata.py`` with ``--no_resample``
fits exactly that: ``numpy.polyfit(T − TREF, v, 3)``."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

PAGE = Path(__file__).resolve().parents[2] / "docs" / "tutorials" / "notebook-px4.md"
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```$", re.MULTILINE | re.DOTALL)
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")
TRUE = (3.0e-3, 6.0e-5, -1.2e-6, 1.5e-8)  # rad/s per (T − 25 °C)^k: the page's simulator


@pytest.fixture(scope="module")
def page() -> tuple[list[tuple[str, str]], dict[str, Any]]:
    blocks = [(m.group(1), m.group(2)) for m in BLOCK.finditer(PAGE.read_text(encoding="utf-8"))]
    ns: dict[str, Any] = {}
    pairs = []
    for i, (lang, body) in enumerate(blocks):
        if lang == "python":
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                exec(compile(body, str(PAGE), "exec"), ns)
            pairs.append((out.getvalue(), next(b for la, b in blocks[i + 1 :] if la == "text")))
    return pairs, ns


def _printed(pairs: list[tuple[str, str]]) -> dict[str, float]:
    return {
        m.group(1): float(m.group(2))
        for printed, _ in pairs
        for m in re.finditer(r"^(\w+)\s+(\S+)$", printed, re.MULTILINE)
    }


def test_the_page_prints_what_it_shows(page: tuple[list[tuple[str, str]], dict[str, Any]]) -> None:
    pairs, _ = page
    assert len(pairs) == 4
    for printed, shown in pairs:
        got = [float(v) for v in NUMBER.findall(printed)]
        want = [float(v) for v in NUMBER.findall(shown)]
        assert got == pytest.approx(want, rel=1e-4, abs=1e-12), (printed, shown)


def test_px4_parameters_are_the_simulators_cubic_and_numpy_polyfits(
    page: tuple[list[tuple[str, str]], dict[str, Any]],
) -> None:
    pairs, ns = page
    p = _printed(pairs)
    assert tuple(ns["true_coef"]) == TRUE
    temp, gyro = ns["temp"], ns["gyro"]
    assert p["TC_G0_ID"] == 2293768
    assert (p["TC_G0_TMIN"], p["TC_G0_TMAX"]) == pytest.approx((temp.min(), temp.max()), abs=1e-4)
    assert p["TC_G0_TREF"] == pytest.approx(0.5 * (temp.min() + temp.max()), abs=1e-4)
    # the truth re-expanded about the printed TREF (binomial shift, numpy)
    truth = np.polynomial.Polynomial(TRUE)(np.polynomial.Polynomial([p["TC_G0_TREF"] - 25.0, 1]))
    got = [p[f"TC_G0_X{k}_0"] for k in range(4)]
    assert got == pytest.approx(truth.coef, rel=0.02)
    # numpy.polyfit of every raw sample (PX4's script without resampling)
    raw = np.polyfit(temp - p["TC_G0_TREF"], gyro[:, 0], 3)[::-1]
    for k, tol in enumerate((2e-6, 2e-7, 1e-8, 3e-10)):
        assert got[k] == pytest.approx(raw[k], abs=tol), k


def test_ardupilot_parameters_are_the_cubic_about_35_times_1e6(
    page: tuple[list[tuple[str, str]], dict[str, Any]],
) -> None:
    pairs, ns = page
    p = _printed(pairs)
    assert p["INS_TCAL1_ENABLE"] == 1
    about35 = np.polynomial.Polynomial(TRUE)(np.polynomial.Polynomial([10.0, 1])).coef * 1e6
    got = [p[f"INS_TCAL1_GYR{k}_X"] for k in (1, 2, 3)]
    np.testing.assert_allclose(about35[1:], [40.5, -0.75, 0.015], rtol=1e-12)  # the page's text
    assert got == pytest.approx(about35[1:], rel=0.03)
    raw = np.polyfit(ns["temp"] - 35.0, ns["gyro"][:, 0], 3)[::-1][1:] * 1e6
    assert got == pytest.approx(raw, rel=0.02)
