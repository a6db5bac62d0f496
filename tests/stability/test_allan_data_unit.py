"""``thermocal allan`` prints every figure in the data's own unit (issue 25, last bullet):
ADEV of °/s data in °/s, of rad/s data in rad/s, with ``unit`` naming it; the noise terms
in the data's rate unit (bias instability, rate random walk, ramp) or its angle unit
(quantization, angle random walk).  The expected numbers are computed here with numpy."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

FS_HZ = 10.0


def _oadev(y: np.ndarray, m: int) -> float:
    """Overlapping Allan deviation at τ = m τ0 from the phase x_k = Σ y (NIST SP 1065
    eq. 11), written out for this test."""
    x = np.concatenate([[0.0], np.cumsum(y)]) / FS_HZ
    d = x[2 * m :] - 2.0 * x[m:-m] + x[: -2 * m]
    tau = m / FS_HZ
    return float(math.sqrt(np.mean(d**2) / (2.0 * tau**2)))


@pytest.mark.parametrize(
    ("column", "unit", "sigma", "angle_unit", "q_unit"),
    [
        ("gyro x [deg/s]", "deg/s", 0.02, "deg/sqrt(h)", "arcsec"),
        ("gx rad/s", "rad/s", 3.0e-4, "rad/sqrt(h)", "urad"),
    ],
)
def test_allan_json_and_table_in_the_data_unit(  # type: ignore[no-untyped-def]
    tmp_path: Path, capsys, column, unit, sigma, angle_unit, q_unit
) -> None:
    rng = np.random.default_rng(7)
    n = 20_000
    t = np.arange(n) / FS_HZ
    y = 0.5 * sigma + sigma * rng.standard_normal(n)  # white rate noise [unit]
    path = tmp_path / "imu.csv"
    pd.DataFrame({"time (s)": t, column: y}).to_csv(path, index=False)
    code = main(["allan", str(path), "--signal", column, "--taus", "1,10,100", "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    obj = json.loads(cap.out)
    assert obj["unit"] == unit
    expect = [_oadev(y, round(tau * FS_HZ)) for tau in (1.0, 10.0, 100.0)]
    np.testing.assert_allclose(obj["adev"], expect, rtol=1e-9)
    noise = obj["noise"]
    assert noise["bias_instability"]["unit"] == unit
    assert noise["rate_random_walk"]["unit"] == f"{unit}/sqrt(h)"
    assert noise["rate_ramp"]["unit"] == f"{unit}/h"
    assert noise["quantization"]["unit"] == q_unit
    arw = noise["angle_random_walk"]
    # white noise σ at fs: N = σ·√τ0 [angle/√s] = 60·σ·√τ0 [angle/√h]
    assert arw["unit"] == angle_unit
    assert arw["value"] == pytest.approx(60.0 * sigma / math.sqrt(FS_HZ), rel=0.05)

    assert main(["allan", str(path), "--signal", column, "--taus", "1,10,100"]) == 0
    out = capsys.readouterr().out
    assert f"[{unit}]" in out and "deg/h" not in out
    rows = [line.split("│") for line in out.splitlines() if line.startswith("│")]
    row = next(cells for cells in rows if cells[1].strip() == "10")
    assert float(row[2]) == pytest.approx(expect[1], rel=1e-3)
