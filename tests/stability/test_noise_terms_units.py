"""Noise-term units in the data's unit family (issue 29 item 2, IEEE 952 units review):
accelerations given in m/s² keep the SI family (m/s, m/s/√h, m/s², (m/s²)/√h,
(m/s²)/h), through the CLI; the figures computed here from the simulation's truth."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

FS = 50.0
SIGMA = 0.004  # white acceleration noise per sample [m/s²]


def test_m_s2_data_give_si_noise_terms(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rng = np.random.default_rng(1293)
    n = int(1800 * FS)
    t = np.arange(n) / FS
    acc = 9.80665 + 0.02 + SIGMA * rng.standard_normal(n)
    path = tmp_path / "acc.csv"
    np.savetxt(
        path, np.column_stack([t, acc]), delimiter=",", comments="",
        header="time [s],acc z [m/s^2]", fmt=["%.3f", "%.9g"],
    )  # fmt: skip
    capsys.readouterr()
    assert main(["allan", str(path), "--signal", "acc z [m/s^2]", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["unit"] == "m/s^2"
    noise = doc["noise"]
    assert noise["quantization"]["unit"] == "m/s"
    assert noise["angle_random_walk"]["unit"] == "m/s/sqrt(h)"
    assert noise["bias_instability"]["unit"] == "m/s^2"
    assert noise["rate_random_walk"]["unit"] == "m/s^2/sqrt(h)"
    assert noise["rate_ramp"]["unit"] == "m/s^2/h"
    # white noise σ at fs: N = σ/√fs [m/s/√s] = 60 σ/√fs [m/s/√h]
    vrw = doc["noise_slope"]["angle_random_walk"]
    assert vrw["value"] == pytest.approx(60.0 * SIGMA / math.sqrt(FS), rel=0.03)
    assert "ug" not in json.dumps(noise)
