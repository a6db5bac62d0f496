"""The notebook's PX4 fit is the command line's: ``thermocal.firmware.px4.px4_coefficients``
on a log's arrays gives the ``TC_G0_*`` that ``thermocal px4-tempcal`` writes for that log
(the same bins, the same cubic about the same TREF), and the ``TC_A0_X1…X3``; the
accelerometer's ``X0`` differs by the documented constant (the command line makes the offset
zero at mid-range, PX4's script and the function take the median).  The log is written here
from the ULog format description with a known cubic bias, and both are checked against it."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from thermocal.cli import main
from thermocal.firmware.px4 import px4_coefficients
from ulog_writer import SENSOR_FIELDS, ulog_bytes

G0 = 9.80665


def _params(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if line and not line.startswith("#"):
            parts = line.split("\t")
            out[parts[2]] = float(parts[3])
    return out


def test_px4_coefficients_equal_what_px4_tempcal_writes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    n = 4000
    t = np.arange(n) * 0.25
    temp = (-5.0 + 55.0 * t / t[-1]).astype(np.float32).astype(np.float64)
    x = (temp - 22.5) / 27.5
    rng = np.random.default_rng(4)
    gyro = np.column_stack([2e-3 * x, 1e-3 * x**2, -1e-3 * x**3]) + rng.normal(0, 1e-4, (n, 3))
    acc = np.column_stack([0.05 * x, -0.02 * x**2, -G0 + 0.03 * x]) + rng.normal(0, 2e-3, (n, 3))
    gyro, acc = gyro.astype(np.float32), acc.astype(np.float32)  # as the log stores them
    topics: list[Any] = []
    for name, v, dev in (("sensor_gyro", gyro, 100), ("sensor_accel", acc, 200)):
        rows = [(int(1e6 + ti * 1e6), dev, *map(float, r), float(tt))
                for ti, r, tt in zip(t, v, temp, strict=True)]  # fmt: skip
        topics.append((name, 0, SENSOR_FIELDS, rows))
    log = tmp_path / "still.ulg"
    log.write_bytes(ulog_bytes(topics))
    assert main(["px4-tempcal", str(log), "-o", str(tmp_path / "out")]) == 0, (
        capsys.readouterr().err
    )
    cli = _params(tmp_path / "out" / "px4.params")
    # TMIN/TMAX: the function takes the recorded extremes as PX4's script does; the command
    # line the extremes of the fitted bin medians (the first and last 0.5 °C bins' median
    # temperatures), so its TREF, their middle, differs by a fraction of a bin
    fit_g = px4_coefficients(temp, gyro.astype(np.float64), kind="gyro")
    assert (fit_g.tmin_c, fit_g.tmax_c) == (temp.min(), temp.max())
    first, last = temp[temp < -4.5], temp[temp >= 50.0 - 1e-9]
    assert cli["TC_G0_TMIN"] == pytest.approx(np.median(first), abs=1e-5)
    assert cli["TC_G0_TMAX"] == pytest.approx(np.median(last), abs=1e-5)
    tref = cli["TC_G0_TREF"]
    assert tref == pytest.approx(0.5 * (cli["TC_G0_TMIN"] + cli["TC_G0_TMAX"]), abs=1e-5)
    g = px4_coefficients(temp, gyro.astype(np.float64), kind="gyro", tref_c=tref).params(0, 100)
    a = px4_coefficients(temp, acc.astype(np.float64), kind="accel", tref_c=tref).params(0, 200)
    for i in range(3):
        for k in range(4):
            assert g[f"TC_G0_X{k}_{i}"] == pytest.approx(
                cli[f"TC_G0_X{k}_{i}"], rel=1e-6, abs=1e-12
            )
            if k:
                name = f"TC_A0_X{k}_{i}"
                assert a[name] == pytest.approx(cli[name], rel=1e-6, abs=1e-12), name
    # and both follow the truth: gyro x slope 2e-3 rad/s per 27.5 °C
    assert cli["TC_G0_X1_0"] == pytest.approx(2e-3 / 27.5, rel=0.02)
    # the accelerometer: the command line's offset is zero at mid-range, the function's is
    # relative to the median of the data; the curves differ by that constant only
    grid = np.linspace(cli["TC_A0_TMIN"], cli["TC_A0_TMAX"], 50) - tref
    for i in range(3):
        ours = np.polyval([a[f"TC_A0_X{k}_{i}"] for k in (3, 2, 1, 0)], grid)
        theirs = np.polyval([cli[f"TC_A0_X{k}_{i}"] for k in (3, 2, 1, 0)], grid)
        assert np.ptp(ours - theirs) < 1e-9
        assert np.polyval([cli[f"TC_A0_X{k}_{i}"] for k in (3, 2, 1, 0)], 0.0) == pytest.approx(
            0.0, abs=1e-9
        )
