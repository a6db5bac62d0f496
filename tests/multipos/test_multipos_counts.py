"""``thermocal multipos`` on raw counts (issue 30): a consumer IMU's session as its
registers give it (int16 counts, ±2 g at 16384 LSB/g, ±250 °/s at 131 LSB/(°/s)) with the
datasheet's sensitivity given as ``--accel-scale``/``--gyro-scale``.

The calibration equals the one of the same session converted to mg and °/s here (the
conversion written in the test), its bias is the truth within 3.5σ in the scale's unit,
and counts without a scale (or a scale for columns that are not counts) are refused."""

from __future__ import annotations

import contextlib
import io
import json
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.multipos.simulate import simulate_session

ACC_LSB_PER_G = 16384.0
GYR_LSB_PER_DPS = 131.0
A_B = np.array([20.0, -35.0, 15.0])  # mg
A_S = np.array([5000.0, -3000.0, 2000.0])  # ppm


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("counts")
    ta = np.zeros(12)
    ta[0:3], ta[3:6] = A_B, A_S
    tg = np.zeros(12)
    tg[0:3] = [400.0, -600.0, 250.0]
    s = simulate_session(np.random.default_rng(3), ta, tg, n_poses=14)
    acc_counts = np.round(s["accel_mg"] * 1e-3 * ACC_LSB_PER_G).astype(np.int64)
    gyr_counts = np.round(s["gyro_deg_s"] * GYR_LSB_PER_DPS).astype(np.int64)
    raw = {"time": s["time_s"]}
    phys = {"time": s["time_s"]}
    for k, a in enumerate("xyz"):
        raw[f"acc_{a} [LSB]"] = acc_counts[:, k]
        phys[f"acc_{a} [mg]"] = acc_counts[:, k] * (1000.0 / ACC_LSB_PER_G)
    for k, a in enumerate("xyz"):
        raw[f"gyr_{a} [LSB]"] = gyr_counts[:, k]
        phys[f"gyr_{a} [deg/s]"] = gyr_counts[:, k] / GYR_LSB_PER_DPS
    pd.DataFrame(raw).to_csv(d / "raw.csv", index=False)
    pd.DataFrame(phys).to_csv(d / "phys.csv", index=False)
    return {"dir": d}


def _cols(name: str, unit: str) -> str:
    return ",".join(f"{name}_{a} [{unit}]" for a in "xyz")


def test_raw_counts_with_the_datasheet_scale(files: dict[str, Any]) -> None:
    d = files["dir"]
    code, out, err = _run(["multipos", str(d / "raw.csv"), "--accel", _cols("acc", "LSB"),
                           "--gyro", _cols("gyr", "LSB"), "--accel-scale",
                           f"{1000.0 / ACC_LSB_PER_G!r},mg", "--gyro-scale",
                           f"{1.0 / GYR_LSB_PER_DPS!r},deg/s", "--latitude", "45", "-o",
                           str(d / "raw.json"), "--json"])  # fmt: skip
    assert code == 0, err
    r = json.loads(out)
    code, out, err = _run(["multipos", str(d / "phys.csv"), "--accel", _cols("acc", "mg"),
                           "--gyro", _cols("gyr", "deg/s"), "--latitude", "45", "-o",
                           str(d / "phys.json"), "--json"])  # fmt: skip
    assert code == 0, err
    p = json.loads(out)
    assert r["accel"]["bias_unit"] == "mg" and r["gyro"]["bias_unit"] == "deg/s"
    assert r["accel"]["count_scale"] == {"value": 1000.0 / ACC_LSB_PER_G, "unit": "mg"}
    for kind in ("accel", "gyro"):
        for k in ("bias", "scale_factor_ppm", "misalignment_arcsec"):
            np.testing.assert_allclose(r[kind][k], p[kind][k], rtol=1e-6, atol=1e-9)
    z = (np.array(r["accel"]["bias"]) - A_B) / np.array(r["accel"]["bias_sigma"])
    assert np.all(np.abs(z) < 3.5), z
    z = (np.array(r["accel"]["scale_factor_ppm"]) - A_S) / np.array(
        r["accel"]["scale_factor_ppm_sigma"]
    )
    assert np.all(np.abs(z) < 3.5), z
    assert r["gravity_residual_rms_after"] < 0.05 * r["gravity_residual_rms_before"]


def test_counts_without_a_scale_refused(files: dict[str, Any]) -> None:
    d = files["dir"]
    code, _o, err = _run(["multipos", str(d / "raw.csv"), "--accel", _cols("acc", "LSB"),
                          "--latitude", "45", "-o", str(d / "x.json")])  # fmt: skip
    assert code == 2 and "raw counts" in err and "--accel-scale" in err, err
    code, _o, err = _run(["multipos", str(d / "phys.csv"), "--accel", _cols("acc", "mg"),
                          "--accel-scale", "0.061,mg", "--latitude", "45", "-o",
                          str(d / "x.json")])  # fmt: skip
    assert code == 2 and "is for raw counts" in err, err
    code, _o, err = _run(["multipos", str(d / "raw.csv"), "--accel", _cols("acc", "LSB"),
                          "--accel-scale", "0.061,deg/s", "--latitude", "45", "-o",
                          str(d / "x.json")])  # fmt: skip
    assert code == 2 and "--accel-scale takes VALUE,UNIT" in err, err
    assert not (d / "x.json").exists()


def test_a_count_scale_implies_counts_for_bare_columns(files: dict[str, Any]) -> None:
    """A logger's raw columns name no unit (``ax``, as the MPU-6050 sketches write them):
    ``--accel-scale``/``--gyro-scale`` say they are counts, so the run needs no
    ``--accel-unit`` (it asked for one, issue 38) and equals the one of the same counts
    with ``[LSB]`` in their names, without a word about an assumed unit."""
    d = files["dir"]
    raw = pd.read_csv(d / "raw.csv")
    raw.columns = [c.split(" [")[0] for c in raw.columns]
    raw.to_csv(d / "bare.csv", index=False)
    scales = ["--accel-scale", f"{1000.0 / ACC_LSB_PER_G!r},mg",
              "--gyro-scale", f"{1.0 / GYR_LSB_PER_DPS!r},deg/s", "--latitude", "45"]  # fmt: skip
    code, out, err = _run(["multipos", str(d / "bare.csv"), "--accel", "acc_x,acc_y,acc_z",
                           "--gyro", "gyr_x,gyr_y,gyr_z", *scales, "-o", str(d / "bare.json"),
                           "--json"])  # fmt: skip
    assert code == 0, err
    assert "signal column" not in err and "assuming deg/h" not in err, err
    b = json.loads(out)
    code, out, err = _run(["multipos", str(d / "raw.csv"), "--accel", _cols("acc", "LSB"),
                           "--gyro", _cols("gyr", "LSB"), *scales, "-o", str(d / "r.json"),
                           "--json"])  # fmt: skip
    assert code == 0, err
    r = json.loads(out)
    for kind in ("accel", "gyro"):
        for k in ("bias", "scale_factor_ppm", "misalignment_arcsec"):
            np.testing.assert_allclose(b[kind][k], r[kind][k], rtol=1e-9, atol=1e-9)
    code, _o, err = _run(["multipos", str(d / "bare.csv"), "--accel", "acc_x,acc_y,acc_z",
                          "--latitude", "45", "-o", str(d / "x.json")])  # fmt: skip
    assert code == 2 and "give --accel-unit" in err.splitlines()[-1], err
