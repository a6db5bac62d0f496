"""``thermocal.validation.improvement_about_zero_pct``: the improvement of a figure about
zero judged on its magnitude, by hand and as ``thermocal validate`` shows it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.validation import improvement_about_zero_pct


@pytest.mark.parametrize(
    ("before", "after", "expected"),
    [
        (3.0, -1.0, 200.0 / 3.0),  # +3 → −1: two thirds of the magnitude gone
        (-4.0, 2.0, 50.0),
        (0.5, 1.0, -100.0),  # worse: negative
        (0.0, 1.0, None),
        (None, 1.0, None),
        (2.0, None, None),
    ],
)
def test_by_hand(before: float | None, after: float | None, expected: float | None) -> None:
    got = improvement_about_zero_pct(before, after)
    assert got == (None if expected is None else pytest.approx(expected, rel=1e-12))


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_validate_prints_it_per_figure(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rng = np.random.default_rng(0)
    t = np.arange(3600.0)
    for name, temp in (("cold", 5.0 + 16.0 * t / 3599.0), ("hot", 30.0 + 0.0 * t)):
        g = 0.3 + 0.02 * (temp - 13.0) + 0.05 * rng.standard_normal(t.size)
        frame = {"time (s)": t, "gx [deg/s]": g, "temp_c": temp}
        pd.DataFrame(frame).to_csv(tmp_path / f"{name}.csv", index=False)
    model = tmp_path / "m.json"
    assert main(["fit", str(tmp_path / "cold.csv"), "--model", "poly", "--order", "1",
                 "--signal", "gx [deg/s]", "--temps", "temp_c", "-o", str(model)]) == 0  # fmt: skip
    capsys.readouterr()
    argv = ["validate", str(model), str(tmp_path / "hot.csv")]
    assert main([*argv, "--json"]) == 0
    v = json.loads(capsys.readouterr().out)
    assert main(argv) == 0
    out = capsys.readouterr().out
    for key in ("mean", "rms_about_zero", "max_abs"):
        b, a = abs(v[f"{key}_before"]), abs(v[f"{key}_after"])
        assert f"{100.0 * (b - a) / b:.1f} %" in out, key
