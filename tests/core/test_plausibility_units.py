"""Plausibility checks that catch a wrong unit or range setting (issue 13): a static
accelerometer far from 1 g, a stated sample rate the time column contradicts. Data are
written here the way other tools write them; the expected magnitudes are worked out here.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

G = 9.80665  # m/s² per g (CGPM 1901)


def _triad(path: Path, scale: float) -> None:
    """10 min at 10 Hz, the triad tilted so that gravity splits 0.6/0.0/0.8 g, times scale."""
    rng = np.random.default_rng(0)
    n = 6000
    a = np.array([0.6, 0.0, 0.8]) * scale
    data = a[None, :] + 1e-4 * scale * rng.standard_normal((n, 3))
    pd.DataFrame(
        {"time": np.arange(n) * 0.1, "ax": data[:, 0], "ay": data[:, 1], "az": data[:, 2]}
    ).to_csv(path, index=False)


def _inspect(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict, str]:
    code = main(["inspect", *args, "--json"])
    out, err = capsys.readouterr()
    return code, json.loads(out), err


@pytest.mark.parametrize(
    ("scale", "stated", "words"),
    [
        (G, "g", "m/s² given as g?"),  # m/s² values stated as g: 9.81 g
        (1.0, "m/s^2", "g given as m/s²?"),  # g values stated as m/s²: 0.102 g
        (1000.0, "g", "mg given as g?"),
        (0.5, "g", "a ±4 g range read as ±2 g"),
    ],
)
def test_triad_far_from_one_g_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], scale: float, stated: str, words: str
) -> None:
    _triad(tmp_path / "acc.csv", scale)
    code, res, _err = _inspect(
        capsys, str(tmp_path / "acc.csv"), "--signal", "ax,ay,az", "--signal-unit", stated,
        "--time-unit", "s",
    )  # fmt: skip
    assert code == 0
    probs = [p for p in res["problems"] if p["kind"] == "implausible_acceleration"]
    assert len(probs) == 1, res["problems"]
    assert words in probs[0]["message"]
    # the magnitude printed is the stated-unit reading in g, worked out here
    expect_g = scale * {"g": 1.0, "m/s^2": 1.0 / G}[stated]
    assert f"{expect_g:.4g} g" in probs[0]["message"]


def test_triad_at_one_g_is_quiet(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _triad(tmp_path / "acc.csv", G)
    code, res, _ = _inspect(
        capsys, str(tmp_path / "acc.csv"), "--signal", "ax,ay,az", "--signal-unit", "m/s^2",
        "--time-unit", "s",
    )  # fmt: skip
    assert code == 0
    assert not [p for p in res["problems"] if p["kind"] == "implausible_acceleration"]


def test_stated_sample_interval_contradicted_by_the_time_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A sidecar says 100 Hz (0.01 s), the time column counts milliseconds but is read as
    seconds: the median interval is 10 s, 1000× the stated one."""
    path = tmp_path / "r.csv"
    n = 500
    pd.DataFrame({"time": np.arange(n) * 10.0, "gyro": np.zeros(n)}).to_csv(path, index=False)
    (tmp_path / "r.csv.meta.json").write_text(
        json.dumps({"metadata": {"sample_interval_s": 0.01}, "signals": {"gyro": "deg/h"}})
    )
    code, res, _err = _inspect(capsys, str(path), "--time-unit", "s")
    assert code == 0
    probs = [p for p in res["problems"] if p["kind"] == "implausible_sample_interval"]
    assert len(probs) == 1, res["problems"]
    assert "off by 1000" in probs[0]["message"]
    assert "10 s" in probs[0]["message"] and "0.01 s" in probs[0]["message"]
    # read in ms, the two agree and nothing is said
    code, res, _ = _inspect(capsys, str(path), "--time-unit", "ms")
    assert not [p for p in res["problems"] if p["kind"] == "implausible_sample_interval"]
