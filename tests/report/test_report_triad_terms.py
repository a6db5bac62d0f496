"""The triad report's second-order terms: a gyro's g-sensitivity ``A`` (3×3) and an
accelerometer's ``K2`` (per axis), each with its σ and ``|value|/σ`` (beyond 3σ marked), or
why the calibration holds none.  A simulated session with a known ``A`` and ``K2`` (the
simulator's truth) is calibrated by ``multipos --accel-k2`` and reported on a held-out
session: every element shown lies within 4σ of the truth and the large ones are marked; a
calibration fitted without them says why, and a gyro triad without an accelerometer triad
says that nothing multiplies it."""

from __future__ import annotations

import dataclasses
import html as _html
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gsens_session import A_TRUE, MULTIPOS, run, write_session
from thermocal.pipeline.model_file import load_calibration
from thermocal.report.triads import term_section

K2_TRUE = np.array([50.0, -40.0, 30.0])  # mg per g², the simulator's truth
CELL = re.compile(r"<td( class=\"beyond\")?>([-+0-9.e]+) ± ([0-9.e+-]+)</td>")


@pytest.fixture(scope="module")
def sessions(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("terms")
    write_session(d, seed=11, k2_mg_g2=K2_TRUE, n_poses=24)
    write_session(d, seed=12, k2_mg_g2=K2_TRUE, name="held.csv")
    return d


def _report(d: Path, cal: str, *extra: str) -> str:
    code, _o, err = run(["multipos", str(d / "s.csv"), *MULTIPOS, "-o", str(d / cal), *extra])
    assert code == 0, err
    out = d / f"{cal}.html"
    code, _o, err = run(["report", "--model", str(d / cal), "--recording", str(d / "held.csv"),
                         *MULTIPOS[:4], "-o", str(out)])  # fmt: skip
    assert code == 0, err
    return _html.unescape(out.read_text(encoding="utf-8"))


def _table(page: str, name: str) -> list[tuple[bool, float, float]]:
    m = re.search(rf'<table class="compact" id="term-{name}">(.*?)</table>', page, re.S)
    assert m is not None, f"no term table of {name}"
    return [(bool(b), float(v), float(s)) for b, v, s in CELL.findall(m.group(1))]


def test_a_and_k2_shown_against_the_truth(sessions: Path) -> None:
    page = _report(sessions, "with.json", "--accel-k2", "--g-sensitivity", "apply")
    a = _table(page, "gyro")
    assert len(a) == 9
    truth_a = (A_TRUE / 3600.0).ravel()  # deg/h/g → deg/s/g (the gyro's unit)
    for (beyond, v, s), t in zip(a, truth_a, strict=True):
        assert abs(v - t) < 4 * s, (v, s, t)
        assert beyond == (abs(v) > 3 * s)
    assert all(b for b, _v, _s in a)  # the smallest truth, 30 °/h/g, is ~6σ
    k2 = _table(page, "accel")
    assert len(k2) == 3
    for (beyond, v, s), t in zip(k2, K2_TRUE, strict=True):  # mg/g², standard g
        assert abs(v - t) < 4 * s and beyond, (v, s, t)
    assert "[deg/s/g]" in page and "[mg/g²]" in page


def test_absent_terms_say_why(sessions: Path) -> None:
    page = _report(sessions, "without.json", "--g-sensitivity", "off")
    assert 'id="term-gyro"' not in page and 'id="term-accel"' not in page
    assert "A not stored in this calibration" in page
    assert "K2 not estimated: the calibration was fitted without K2" in page


def test_a_gyro_alone_has_nothing_to_multiply(sessions: Path) -> None:
    code, _o, err = run(["multipos", str(sessions / "s.csv"), *MULTIPOS, "-o",
                         str(sessions / "alone.json"), "--g-sensitivity", "off"])  # fmt: skip
    assert code == 0, err
    cal = load_calibration(sessions / "alone.json")
    gyro = next(t for t in cal.triads if t.name == "gyro")
    got: dict[str, Any] | None = term_section(gyro, [gyro])
    assert got is not None and got["absent"].startswith(
        "not estimated: the calibration holds no accelerometer triad"
    )
    with_a = dataclasses.replace(gyro, g_sensitivity=np.eye(3), g_sensitivity_sigma=None)
    cells = term_section(with_a, [with_a])["rows"][0]["cells"]  # type: ignore[index]
    assert [c["z"] for c in cells] == ["—"] * 3 and not any(c["beyond"] for c in cells)


def test_the_reason_follows_the_calibrating_command(sessions: Path) -> None:
    """A gyro beside an accelerometer without A: multipos' rule (3σ, not c·I alone, or
    asked for) or the turntable soaks' (every soak took it off)."""
    code, _o, err = run(["multipos", str(sessions / "s.csv"), *MULTIPOS, "-o",
                         str(sessions / "off.json"), "--g-sensitivity", "off"])  # fmt: skip
    assert code == 0, err
    triads = load_calibration(sessions / "off.json").triads
    gyro = next(t for t in triads if t.name == "gyro")
    assert "not c·I alone" in (term_section(gyro, triads) or {})["absent"]
    tt = dataclasses.replace(gyro, model=dataclasses.replace(gyro.model, method="turntable"))
    assert "every soak's dwells" in (term_section(tt, [tt, *triads]) or {})["absent"]
