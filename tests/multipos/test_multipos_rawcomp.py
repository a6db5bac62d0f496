"""``thermocal compensate`` of a raw-count recording with a multipos calibration made on
raw counts (issue 30): the count scale given to ``multipos --accel-scale/--gyro-scale`` is
stored on each triad (``count_scale``, calibration format version 2) and applied first,
``x = count_scale · N``, so the ``_comp`` columns come out in the physical unit the
calibration states (and the output says so).

The session is written the way a consumer-IMU logger writes it: a CSV ``timestamp, ax, ay,
az, gx, gy, gz`` of int16 register counts (±4 g at 8192 LSB/g, ±2000 °/s at
16.4 LSB/(°/s)), no unit in the header.  Checked here, against figures computed in the
test: every static pose's compensated gravity magnitude is local g within 4 σ of its own
noise (about 30 mg off uncalibrated); the compensated gyro equals the truth's correction
``(x − b)/(1 + s)`` of the same samples; an old calibration file (format version 1, no
``count_scale``) compensates a physical-unit file exactly as before and refuses raw counts,
naming the missing count scale.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.models.format import checksum
from thermocal.multipos.simulate import simulate_session

ACC_LSB_PER_G = 8192.0  # ±4 g range
GYR_LSB_PER_DPS = 16.4  # ±2000 °/s range
ACC_MG_PER_COUNT = 1000.0 / ACC_LSB_PER_G
GYR_DPS_PER_COUNT = 1.0 / GYR_LSB_PER_DPS
G_M_S2 = 9.80620  # normal gravity at 45° latitude, as the simulation uses
MG_M_S2 = 9.80665e-3
A_B = np.array([30.0, -45.0, 25.0])  # mg
A_S = np.array([6000.0, -4000.0, 3000.0])  # ppm
A_M = np.array([300.0, -250.0, 200.0])  # ″, xy, xz, yz (lower triangular: the accelerometer
# frame is the body frame, so the gyro's misalignment against it is its truth, zero)
G_B = np.array([3000.0, -2000.0, 1500.0])  # °/h
G_S = np.array([4000.0, -3000.0, 2500.0])  # ppm


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def _int16(x: np.ndarray) -> np.ndarray:
    return np.clip(np.round(x), -32768, 32767).astype(np.int16)


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("rawcomp")
    ta, tg = np.zeros(12), np.zeros(12)
    ta[0:3], ta[3:6], ta[[8, 10, 11]] = A_B, A_S, A_M
    tg[0:3], tg[3:6] = G_B, G_S
    s = simulate_session(np.random.default_rng(11), ta, tg, n_poses=16, accel_noise_mg=1.5)
    acc = _int16(s["accel_mg"] / ACC_MG_PER_COUNT)
    gyr = _int16(s["gyro_deg_s"] / GYR_DPS_PER_COUNT)
    t = np.round(s["time_s"], 3)
    lines = ["timestamp,ax,ay,az,gx,gy,gz"]
    lines += [
        f"{t[i]:.3f},{acc[i, 0]},{acc[i, 1]},{acc[i, 2]},{gyr[i, 0]},{gyr[i, 1]},{gyr[i, 2]}"
        for i in range(t.size)
    ]
    (d / "imu_raw.csv").write_text("\n".join(lines) + "\n", encoding="ascii")
    phys = {"timestamp": t}
    for k, a in enumerate("xyz"):
        phys[f"a{a}"] = acc[:, k] * ACC_MG_PER_COUNT
    for k, a in enumerate("xyz"):
        phys[f"g{a}"] = gyr[:, k] * GYR_DPS_PER_COUNT
    pd.DataFrame(phys).to_csv(d / "imu_mg.csv", index=False)
    args = ["multipos", str(d / "imu_raw.csv"), "--time", "timestamp", "--time-unit", "s",
            "--accel", "ax,ay,az", "--gyro", "gx,gy,gz", "--accel-unit", "counts",
            "--gyro-unit", "counts", "--accel-scale", f"{ACC_MG_PER_COUNT!r},mg",
            "--gyro-scale", f"{GYR_DPS_PER_COUNT!r},deg/s", "--latitude", "45",
            "-o", str(d / "cal.json")]  # fmt: skip
    code, _o, err = _run(args)
    assert code == 0, err
    return {"dir": d, "sim": s, "acc": acc, "gyr": gyr}


def _compensate(cal: Path, data: Path, out: Path) -> tuple[int, dict[str, Any], str]:
    code, o, err = _run(["compensate", str(cal), str(data), "-o", str(out), "--json",
                         "--time", "timestamp", "--time-unit", "s"])  # fmt: skip
    return code, (json.loads(o) if code == 0 else {}), err


def test_the_count_scale_is_stored_on_each_triad(session: dict[str, Any]) -> None:
    doc = json.loads((session["dir"] / "cal.json").read_text())
    assert doc["format_version"] == 2
    scales = {t["name"]: t["count_scale"] for t in doc["triads"]}
    assert scales == {
        "accel": {"value": ACC_MG_PER_COUNT, "unit": "mg"},
        "gyro": {"value": GYR_DPS_PER_COUNT, "unit": "deg/s"},
    }


def test_compensate_a_raw_count_file(session: dict[str, Any]) -> None:
    d, s = session["dir"], session["sim"]
    code, res, err = _compensate(d / "cal.json", d / "imu_raw.csv", d / "comp.csv")
    assert code == 0, err
    tri = {t["triad"]: t for t in res["triads"]}
    assert tri["accel"]["unit"] == "mg" and tri["accel"]["input_unit"] == "counts"
    assert tri["accel"]["count_scale"] == ACC_MG_PER_COUNT
    assert tri["gyro"]["unit"] == "deg/s" and tri["gyro"]["count_scale"] == GYR_DPS_PER_COUNT
    code, table, err = _run(["compensate", str(d / "cal.json"), str(d / "imu_raw.csv"),
                             "-o", str(d / "comp2.csv"), "--time-unit", "s"])  # fmt: skip
    assert code == 0 and "[mg] (from raw counts: one count = 0.1220703125 mg)" in table, table
    meta = json.loads((d / "comp.csv.meta.json").read_text())
    assert meta["units"]["ax_comp"] == "mg" and meta["units"]["gx_comp"] == "deg/s"
    out = pd.read_csv(d / "comp.csv")
    a_c = out[["ax_comp", "ay_comp", "az_comp"]].to_numpy()
    g_mg = G_M_S2 / MG_M_S2
    a_raw_mg = session["acc"] * ACC_MG_PER_COUNT
    for s0, e0 in s["poses"]:
        w = slice(s0 + 20, e0 - 20)  # the pose without the hand's last and first moves
        mag = np.linalg.norm(a_c[w], axis=1)
        sigma = mag.std(ddof=1) / np.sqrt(mag.size)
        assert abs(mag.mean() - g_mg) < 4 * sigma + 0.02, (s0, mag.mean() - g_mg, sigma)
        # uncalibrated, the same pose is tens of mg off: the check can fail
        assert abs(np.linalg.norm(a_raw_mg[w], axis=1).mean() - g_mg) > 10 * sigma
    # the gyro: the truth's own correction (x − b)/(1 + s) of the same samples [°/s]
    x = session["gyr"] * GYR_DPS_PER_COUNT
    truth = (x - G_B / 3600.0) / (1.0 + G_S * 1e-6)
    g_c = out[["gx_comp", "gy_comp", "gz_comp"]].to_numpy()
    err_c = np.abs(g_c - truth)
    # the estimate's own error: ~2 °/h of bias, ~150 ppm of scale and misalignment
    bound = 0.004 + 2e-3 * np.linalg.norm(truth, axis=1)[:, None]
    assert np.all(err_c <= bound), (err_c - bound).max()
    assert np.sqrt(np.mean((x - truth) ** 2)) > 0.5  # the raw counts are not the truth


def _old_file(new: Path, old: Path) -> None:
    """The calibration as a thermocal before the count scale wrote it: format version 1,
    no ``count_scale`` (the parameters, in mg and °/s, unchanged)."""
    doc = json.loads(new.read_text())
    doc["format_version"] = 1
    for t in doc["triads"]:
        del t["count_scale"]
    del doc["checksum"]
    doc["checksum"] = checksum(doc)
    old.write_text(json.dumps(doc), encoding="utf-8")


def test_an_old_calibration_file_compensates_physical_units_as_before(
    session: dict[str, Any],
) -> None:
    d = session["dir"]
    _old_file(d / "cal.json", d / "old.json")
    code, res, err = _compensate(d / "old.json", d / "imu_mg.csv", d / "old_comp.csv")
    assert code == 0, err
    tri = {t["triad"]: t for t in res["triads"]}
    assert tri["accel"]["count_scale"] is None and tri["accel"]["unit"] == "mg"
    assert tri["accel"]["input_unit"] == "mg"
    code, _r, err = _compensate(d / "cal.json", d / "imu_raw.csv", d / "new_comp.csv")
    assert code == 0, err
    old = pd.read_csv(d / "old_comp.csv")
    new = pd.read_csv(d / "new_comp.csv")
    for c in ("ax", "ay", "az", "gx", "gy", "gz"):
        np.testing.assert_allclose(old[f"{c}_comp"], new[f"{c}_comp"], rtol=1e-12, atol=1e-9)
    # the new file, with its count scale, takes physical units too (stated: a column that
    # states no unit is taken in the unit the triad was calibrated on, raw counts)
    code, _o, err = _run(["compensate", str(d / "cal.json"), str(d / "imu_mg.csv"), "-o",
                          str(d / "new_mg.csv"), "--time-unit", "s", "--signal-unit",
                          "mg,mg,mg,deg/s,deg/s,deg/s"])  # fmt: skip
    assert code == 0, err
    np.testing.assert_allclose(pd.read_csv(d / "new_mg.csv")["ax_comp"], old["ax_comp"],
                               rtol=1e-12)  # fmt: skip
    # raw counts with no count scale: refused, naming it
    code, _o, err = _run(["compensate", str(d / "old.json"), str(d / "imu_raw.csv"), "-o",
                          str(d / "x.csv"), "--signal-unit", "counts"])  # fmt: skip
    assert code == 2 and "no count scale" in err, err
    assert not (d / "x.csv").exists()


def test_exports_state_the_count_scale(session: dict[str, Any]) -> None:
    d = session["dir"]
    code, _o, err = _run(["export-c", str(d / "cal.json"), "-o", str(d / "c")])
    assert code == 0, err
    header = (d / "c" / "cal.h").read_text()
    assert f"#define CAL_ACCEL_COUNT_SCALE {ACC_MG_PER_COUNT!r}" in header
    assert f"#define CAL_GYRO_COUNT_SCALE {GYR_DPS_PER_COUNT!r}" in header
    assert "x[i] = CAL_ACCEL_COUNT_SCALE * counts[i] [mg]" in header
    code, _o, err = _run(["export-params", str(d / "cal.json"), "--format", "ardupilot",
                          "-o", str(d / "ap.parm")])  # fmt: skip
    assert code == 0, err
    assert "warning: accel: calibrated on raw counts (one count = 0.1220703125 mg)" in err, err
    assert "not counts" in (d / "ap.parm").read_text()
