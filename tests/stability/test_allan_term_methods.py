"""Every noise term of ``thermocal allan --json`` says how it was read (INTERFACE.md,
"Stability analysis": each term gives ``method``), in the same words as ``thermocal noise
--format json`` for the same record (issue 29).

The record is built here: a 3-axis gyro at 100 Hz for 10 min, [°/s] in the column names,
white noise plus a rate random walk plus a bias, written as a logger would (%.9g)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

FS_HZ = 100.0
COLS = ("gyro x [deg/s]", "gyro y [deg/s]", "gyro z [deg/s]")


@pytest.fixture(scope="module")
def gyro_csv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rng = np.random.default_rng(2929)
    n = int(600 * FS_HZ)
    dt = 1.0 / FS_HZ
    lines = ["time [s]," + ",".join(COLS)]
    cols = [
        0.01
        + rng.normal(0.0, 1e-4 / math.sqrt(dt), n)
        + np.cumsum(rng.normal(0.0, 2e-5 * math.sqrt(dt), n))
        for _ in COLS
    ]
    t = np.arange(n) * dt
    lines += [f"{t[i]:.2f}," + ",".join(f"{c[i]:.9g}" for c in cols) for i in range(n)]
    path = tmp_path_factory.mktemp("methods") / "gyro.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_every_allan_term_has_the_method_noise_gives(
    gyro_csv: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["allan", str(gyro_csv), "--time", "time [s]", "--signal", COLS[0], "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    allan = json.loads(cap.out)
    out = tmp_path / "noise.json"
    code = main(["noise", str(gyro_csv), "--time", "time [s]", "--gyro", ",".join(COLS),
                 "--format", "json", "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    axis = json.loads(out.read_text(encoding="utf-8"))["axes"][COLS[0]]
    names = ("quantization", "angle_random_walk", "bias_instability", "rate_random_walk",
             "rate_ramp")  # fmt: skip
    for key, word in (("noise", "fit"), ("noise_slope", "slope")):
        assert set(allan[key]) == set(names)
        for name in names:
            assert allan[key][name]["method"] == word, (key, name)
    for name in names:
        # the fitted terms: the same method word and the same value in both commands
        fit_a, fit_n = allan["noise"][name], axis["terms_fit"][name]
        assert fit_a["method"] == fit_n["method"]
        assert (fit_a["value"] is None) == (fit_n["value"] is None)
        if fit_a["value"] is not None:
            assert fit_a["value"] == pytest.approx(fit_n["value"], rel=1e-9)
        # noise's best term is the slope reading where one exists (then allan's
        # noise_slope term, the same method and value), else the fit
        best = axis["terms"][name]
        slope_a = allan["noise_slope"][name]
        if slope_a["value"] is not None:
            assert best["method"] == slope_a["method"] == "slope"
            assert best["value"] == pytest.approx(slope_a["value"], rel=1e-9)
        else:
            assert best["method"] == fit_a["method"] == "fit"
    # the record shows its white noise on the slope line (so the check above saw "slope")
    assert allan["noise_slope"]["angle_random_walk"]["value"] is not None
