"""``thermocal.models.results.Coefficient``: its ratio to its standard error and whether it
is distinct from zero, by hand and as ``thermocal fit`` flags them."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.models.results import Coefficient


@pytest.mark.parametrize(
    ("value", "stderr", "ratio", "weak"),
    [
        (-0.5, 0.25, 2.0, False),  # exactly two standard errors: distinct
        (0.3, 0.2, 1.5, True),
        (3.0, 0.2, 15.0, False),
        (1.0, None, None, False),  # not estimable: not flagged
        (1.0, 0.0, None, False),
        (1.0, math.nan, math.nan, True),
    ],
)
def test_by_hand(value: float, stderr: float | None, ratio: float | None, weak: bool) -> None:
    c = Coefficient("c", value, stderr)
    if ratio is None or not math.isnan(ratio):
        assert c.t_ratio == (None if ratio is None else pytest.approx(ratio, rel=1e-12))
    else:
        assert c.t_ratio is not None and math.isnan(c.t_ratio)
    assert c.indistinct_from_zero is weak


def test_fit_flags_the_coefficients_within_two_standard_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(0)
    temp = np.linspace(-10.0, 50.0, 2000)
    g = 1.0 + 0.05 * temp + 0.2 * rng.standard_normal(temp.size)  # no curvature
    frame = {"time (s)": np.arange(temp.size, dtype=float), "gx [deg/s]": g, "temp_c": temp}
    pd.DataFrame(frame).to_csv(tmp_path / "run.csv", index=False)
    model = str(tmp_path / "m.json")
    argv = ["fit", str(tmp_path / "run.csv"), "--model", "poly", "--order", "3",
            "--signal", "gx [deg/s]", "--temps", "temp_c", "-o", model]  # fmt: skip
    assert main([*argv, "--json"]) == 0
    coefs = json.loads(capsys.readouterr().out)["coefficients"]
    n_weak = sum(1 for c in coefs if "stderr" in c and abs(c["value"]) / c["stderr"] < 2.0)
    assert n_weak >= 1  # the quadratic and cubic terms of a line: noise
    assert main(argv) == 0
    out = capsys.readouterr().out
    said = re.search(r"\* (\d+) coefficient\(s\) within 2 standard errors of 0", out)
    assert said is not None and int(said.group(1)) == n_weak
