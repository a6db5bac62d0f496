"""The turntable's text shows the gyro's g-sensitivity ``A`` it found as a 3×3 table with σ
(``*`` beyond 3σ): a single run's from its dwells, and for soaks the pooled ``A`` with
whether the calibration stores it and why.  Three simulated soaks of a gyro with a known
``A`` (the simulator's truth, °/h/g): every element shown within 3σ of the truth, the large
ones starred, the table equal to what the calibration file holds; without ``A`` the text says
it is not stored and why."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.pipeline.turntable import stored_g_sensitivity
from thermocal.turntable.simulate import simulate_turntable_thermal
from thermocal.writers import write_recording

A_TRUE = np.array([[0.30, -0.12, 0.05], [0.08, -0.25, 0.15], [-0.04, 0.10, 0.40]])  # °/h/g
CELL = re.compile(r"│ ([-+0-9.e]+) ± ([0-9.e+-]+)( \*)? +")


@pytest.fixture(autouse=True)
def _wide_output(monkeypatch: pytest.MonkeyPatch) -> None:
    """The tables are read cell by cell: printed whole, as to a file (a test run's
    ``COLUMNS=80`` would wrap the 85-column table and split a cell from its star)."""
    monkeypatch.delenv("COLUMNS", raising=False)


def _soaks(d: Path, a_true: np.ndarray | None) -> tuple[str, Path]:
    files = []
    for rec, truth in simulate_turntable_thermal(seed=3, soaks_c=(-20.0, 20.0, 60.0),
                                                 g_sensitivity_deg_h_g=a_true):  # fmt: skip
        if not truth["held_out"]:
            files.append(d / f"{truth['label']}.parquet")
            write_recording(rec, files[-1])
    out = d / "cal.json"
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        assert main(["turntable", *map(str, files), "--temps", "T_imu", "--order", "1", "-o",
                     str(out)]) == 0  # fmt: skip
    return text.getvalue(), files[0]


def _table(text: str, title: str) -> list[tuple[float, float, bool]]:
    part = text.split(title)[1].split("└")[0]
    return [(float(v), float(s), bool(star)) for v, s, star in CELL.findall(part)]


def test_soaks_show_the_stored_sensitivity(tmp_path: Path) -> None:
    text, first = _soaks(tmp_path, A_TRUE)
    assert "gyro g-sensitivity over the soaks stored: every run took it off before its fit" in text
    cells = _table(text, "gyro g-sensitivity over the soaks, stored")
    gyro = next(t for t in json.loads((tmp_path / "cal.json").read_text())["triads"]
                if t["name"] == "gyro")  # fmt: skip
    assert gyro["g_sensitivity_unit"] == "deg/s/g"
    assert len(cells) == 9
    a, sa = np.ravel(gyro["g_sensitivity"]), np.ravel(gyro["g_sensitivity_sigma"])
    stored = zip(a, sa, strict=True)
    for (v, s, star), t, (f, fs) in zip(cells, (A_TRUE / 3600.0).ravel(), stored, strict=True):
        assert abs(v - t) < 3 * s, (v, s, t)
        assert v == float(f"{f:.3g}") and s == float(f"{fs:.2g}")
        assert star == (abs(f) > 3 * fs)
    assert sum(star for _v, _s, star in cells) >= 6  # |A| ≥ 0.08 °/h/g against σ ≈ 0.01
    # one run alone: its own A from its dwells, in °/h/g as its JSON
    single = io.StringIO()
    with contextlib.redirect_stdout(single):
        assert main(["turntable", str(first), "-o", str(tmp_path / "one.json")]) == 0
    cells = _table(single.getvalue(), "gyro g-sensitivity from the dwells, taken off the moves")
    for (v, s, _star), t in zip(cells, A_TRUE.ravel(), strict=True):
        assert abs(v - t) < 3.5 * s, (v, s, t)


def test_soaks_without_a_sensitivity_say_it_is_not_stored(tmp_path: Path) -> None:
    text, _first = _soaks(tmp_path, None)
    assert "gyro g-sensitivity over the soaks not stored: 3 of 3 runs did not take it off" in text
    assert "compensate leaves it in" in text
    assert "gyro g-sensitivity over the soaks, not stored" in text
    assert "g_sensitivity" not in json.loads((tmp_path / "cal.json").read_text())["triads"][0]
    assert stored_g_sensitivity([], "deg/s")["why"].startswith("not estimated")
