"""``docs/tutorials/notebook-multipos.md`` runs as written: its ``python`` blocks are executed
in order in ONE namespace (as a notebook runs its cells), in a temporary folder that sees the
repository's ``tests/`` as the root does; what each prints is compared number by number with
the ``text`` block after it, and the calibration it prints with imucal 2.6.0's calibration of
the same session (``tests/data/imucal_ferraris``, MIT; the reference numbers are those of
``tests/multipos/test_multipos_imucal.py``, computed with imucal in a scratch venv; imucal is no
dependency of thermocal).
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import pytest

from test_tutorials import ARCSEC, IMUCAL_KA_RA, IMUCAL_KG_RG, MISALIGNMENT_RC
from tutorial_pages import BLOCK, ROOT, TUTORIALS, _numbers

PAGE = TUTORIALS / "notebook-multipos.md"

# imucal 2.6.0's b_g of the same session [deg/s] (tests/multipos/test_multipos_imucal.py)
IMUCAL_B_G = np.array([-0.5996686296674446, -0.36984313466306884, 0.0587739354671091])


def _run_cells(tmp: Path) -> list[tuple[str, str]]:
    """(printed, shown) for every ``python`` block, run in order in one namespace."""
    (tmp / "tests").symlink_to(ROOT / "tests", target_is_directory=True)
    blocks = [(m.group(1), m.group(2)) for m in BLOCK.finditer(PAGE.read_text(encoding="utf-8"))]
    namespace: dict[str, object] = {}
    pairs = []
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(tmp)
        for i, (lang, body) in enumerate(blocks):
            if lang != "python":
                continue
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                exec(compile(body, str(PAGE), "exec"), namespace)
            shown = next(b for la, b in blocks[i + 1 :] if la == "text")
            pairs.append((out.getvalue(), shown))
    return pairs


@pytest.fixture(scope="module")
def cells(tmp_path_factory: pytest.TempPathFactory) -> list[tuple[str, str]]:
    return _run_cells(tmp_path_factory.mktemp("notebook_multipos"))


def test_the_page_prints_what_it_shows(cells: list[tuple[str, str]]) -> None:
    assert len(cells) == 5
    for printed, shown in cells:
        assert _numbers(printed) == _numbers(shown), printed
    assert len(_numbers(cells[3][0])) >= 37  # 18 parameters, value and σ


def _rows(printed: str) -> dict[tuple[str, str], tuple[float, float]]:
    """(triad, parameter) → (value, σ) of the calibration block's lines; each line's unit
    is checked: ppm for a scale factor, arcsec for a misalignment."""
    out = {}
    for line in printed.splitlines()[1:]:
        triad, name, value, _pm, sigma, unit = line.split()
        assert unit == ("ppm" if name.startswith("sf_") else "arcsec"), line
        out[(triad, name)] = (float(value), float(sigma))
    return out


def test_the_page_calibration_is_imucals(cells: list[tuple[str, str]]) -> None:
    """Accelerometer scale factors [ppm] and misalignments [″] equal imucal's ``K_a R_a − I``
    to the one decimal printed; gyro scale factors within 1σ of imucal's ``K_g R_g − I``;
    the gyro bias [°/h] is imucal's ``b_g`` to the decimal printed."""
    rows = _rows(cells[3][0])
    for i, axis in enumerate("xyz"):
        assert rows[("accel", f"sf_{axis}")][0] == pytest.approx(
            (IMUCAL_KA_RA[i, i] - 1) * 1e6, abs=0.051
        )
        value, sigma = rows[("gyro", f"sf_{axis}")]
        assert abs(value - (IMUCAL_KG_RG[i, i] - 1) * 1e6) < sigma, axis
    for name, (r, c) in MISALIGNMENT_RC.items():
        assert rows[("accel", name)][0] == pytest.approx(IMUCAL_KA_RA[r, c] * ARCSEC, abs=0.051)
    bias = _numbers(cells[4][0])[:3]
    np.testing.assert_allclose(bias, IMUCAL_B_G * 3600.0, atol=0.051)
