"""``thermocal multipos`` on sessions shaped like the public ones (issue 30), through the CLI:

* **imu_tk's shape** (Tedaldi, Pretto, Menegatti, "A robust and easy to implement method
  for IMU calibration without external equipments", ICRA 2014,
  https://www.dis.uniroma1.it/~pretto/papers/tpm_icra2014.pdf; its data format, as
  ZhangPeike/IMU_Calibration's README states it, ``timestamp(us) ax ay az gx gy gz``): a
  consumer MEMS IMU read in int16 register counts (±4 g at 8192 LSB/g, ±2000 °/s at
  16.4 LSB/(°/s)), a 40 s initial static, then 38 hand-placed static poses of 1.75–3.25 s
  separated by hand motions;
* **a Ferraris session** (imucal's form, https://pypi.org/project/imucal/: the six faces
  ``{x,y,z}_{p,a}`` and the three turns ``{x,y,z}_rot``, here given as the POSES file).

The file is written by the test as a logger writes it (header ``timestamp,ax,ay,az,gx,gy,gz``,
integer µs and int16 counts); :mod:`thermocal.multipos.simulate` only gives the truth (the
attitudes, the sensor's errors).

**The factor.** No figure of the gravity-magnitude residual before/after was found for
Tedaldi et al. or imucal (searched: the project's reference pages, docs and code corpora;
the paper's own tables were not among them), so the expected factor is derived from the
simulated truth, as the issue allows: the uncalibrated residual (rms over the poses of
``|(I + E) f + b| − g``, noise-free, from the true attitudes) divided by the noise floor
(rms over the test's own pose windows of the standard error of the mean magnitude).  A
calibration that reaches the noise floor falls by that factor; the test asks for at least
two thirds of it (the fit's 9 parameters take a share of the noise, and the counts'
quantisation adds to it).

**The independent solution.** The imu_tk session's 9 accelerometer parameters (bias 3,
scale 3, misalignment xy, xz, yz of the lower-triangular ``E``: the SPEC's error model
``m = (I + E) f + b``) are solved in the test by ``scipy.optimize.least_squares`` on the
test's own pose windows (the truth's still windows, 0.3 s trimmed at each end) and must agree
with thermocal's within its stated σ; the Ferraris faces' bias and scale in Ferraris's
closed form (``b = Σ_faces m / 6``, since the six specific forces sum to zero, and
``1 + s_i = (m_i(i_p) − m_i(i_a))/2g``, the diagonal of ``I + E``) likewise.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.optimize import least_squares

from thermocal.cli import main
from thermocal.multipos.simulate import simulate_ferraris, simulate_session

ACC_LSB_PER_G = 8192.0
GYR_LSB_PER_DPS = 16.4
MG_PER_COUNT = 1000.0 / ACC_LSB_PER_G
DPS_PER_COUNT = 1.0 / GYR_LSB_PER_DPS
MG_M_S2 = 9.80665e-3
ACC_NOISE_MG = 3.0  # a consumer MEMS accelerometer at 100 Hz
GYR_NOISE_DPS = 0.05
INITIAL_STATIC_S = 40.0
TRIM = 30  # samples (0.3 s) off each end of a still window
ARCSEC = np.pi / 648000.0


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def _truth() -> tuple[np.ndarray, np.ndarray]:
    ta, tg = np.zeros(12), np.zeros(12)
    ta[0:3] = [35.0, -50.0, 20.0]  # mg
    ta[3:6] = [7000.0, -5000.0, 4000.0]  # ppm
    ta[[8, 10, 11]] = [1500.0, -1000.0, 800.0]  # xy, xz, yz [″]
    tg[0:3] = [1800.0, -1200.0, 900.0]  # °/h
    tg[3:6] = [5000.0, -4000.0, 3000.0]
    tg[6:12] = [1000.0, -800.0, 600.0, -500.0, 700.0, -900.0]
    return ta, tg


def _write_logger_csv(path: Path, t_s: np.ndarray, acc_mg: np.ndarray, gyr_dps: np.ndarray) -> Any:
    """The session as a logger writes it: µs timestamps, int16 counts; the counts back."""
    acc = np.clip(np.round(acc_mg / MG_PER_COUNT), -32768, 32767).astype(np.int16)
    gyr = np.clip(np.round(gyr_dps / DPS_PER_COUNT), -32768, 32767).astype(np.int16)
    t_us = np.round(t_s * 1e6).astype(np.int64) + 1_700_000_000_000_000
    rows = np.column_stack([t_us, acc.astype(np.int64), gyr.astype(np.int64)])
    with path.open("w", encoding="ascii") as f:
        f.write("timestamp,ax,ay,az,gx,gy,gz\n")
        np.savetxt(f, rows, fmt="%d", delimiter=",")
    return acc


def _cli(path: Path, out: Path, extra: list[str]) -> dict[str, Any]:
    code, o, err = _run(["multipos", str(path), "--time", "timestamp", "--time-unit", "us",
                         "--accel", "ax,ay,az", "--gyro", "gx,gy,gz", "--accel-unit", "counts",
                         "--gyro-unit", "counts", "--accel-scale", f"{MG_PER_COUNT!r},mg",
                         "--gyro-scale", f"{DPS_PER_COUNT!r},deg/s", "--latitude", "45",
                         "-o", str(out), "--json", *extra])  # fmt: skip
    assert code == 0, err
    doc: dict[str, Any] = json.loads(o)
    return doc


def _expected_factor(
    ta: np.ndarray, att: np.ndarray, windows: list[tuple[int, int]], acc_mg: np.ndarray, g: float
) -> tuple[float, float]:
    """(uncalibrated residual from the truth, noise floor) [mg] over the poses."""
    e = np.zeros((3, 3))
    e[np.diag_indices(3)] = ta[3:6] * 1e-6
    e[1, 0], e[2, 0], e[2, 1] = ta[8] * ARCSEC, ta[10] * ARCSEC, ta[11] * ARCSEC
    before, var = [], []
    for s0, e0 in windows:
        f = att[(s0 + e0) // 2].T @ np.array([0.0, 0.0, g])
        before.append(np.linalg.norm((np.eye(3) + e) @ f + ta[0:3]) - g)
        mag = np.linalg.norm(acc_mg[s0:e0], axis=1)
        var.append(mag.var(ddof=1) / mag.size)
    return float(np.sqrt(np.mean(np.square(before)))), float(np.sqrt(np.mean(var)))


def _lsq9(means: np.ndarray, g: float) -> tuple[np.ndarray, np.ndarray]:
    """The 9-parameter accelerometer model by least squares on the pose means [mg]:
    ``f = (I + E)⁻¹ (m − b)``, residual ``|f| − g``; (b [mg], scale [ppm]), misalignment
    xy, xz, yz [″]."""

    def resid(p: np.ndarray) -> np.ndarray:
        e = np.diag(p[3:6] * 1e-3)
        e[1, 0], e[2, 0], e[2, 1] = p[6:9] * 1e-3
        f = np.linalg.solve(np.eye(3) + e, (means - p[0:3]).T).T
        out: np.ndarray = np.linalg.norm(f, axis=1) - g
        return out

    sol = least_squares(resid, np.zeros(9), x_scale=1.0, xtol=1e-14, ftol=1e-14, gtol=1e-14)
    p = sol.x
    return np.concatenate([p[0:3], p[3:6] * 1e3]), p[6:9] * 1e-3 / ARCSEC


@pytest.fixture(scope="module")
def imu_tk(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("imu_tk")
    ta, tg = _truth()
    rng = np.random.default_rng(2014)
    s = simulate_session(rng, ta, tg, n_poses=38, dwell_s=2.5, move_s=1.5,
                         accel_noise_mg=ACC_NOISE_MG, gyro_noise_deg_s=GYR_NOISE_DPS)  # fmt: skip
    # the initial static (imu_tk: 30–50 s still before the first placement): the first
    # pose's reading held, with the sensor's own noise
    p0s, p0e = s["poses"][0]
    n0 = int(INITIAL_STATIC_S * 100)
    a0 = s["accel_mg"][p0s:p0e].mean(axis=0) + rng.normal(0, ACC_NOISE_MG, (n0, 3))
    w0 = s["gyro_deg_s"][p0s:p0e].mean(axis=0) + rng.normal(0, GYR_NOISE_DPS, (n0, 3))
    acc_mg = np.vstack([a0, s["accel_mg"]])
    gyr = np.vstack([w0, s["gyro_deg_s"]])
    t = np.arange(acc_mg.shape[0]) / 100.0
    counts = _write_logger_csv(d / "imu_tk.csv", t, acc_mg, gyr)
    windows = [(n0 + a + TRIM, n0 + b - TRIM) for a, b in s["poses"]]
    att = np.concatenate([np.repeat(s["attitude"][:1], n0, axis=0), s["attitude"]])
    res = _cli(d / "imu_tk.csv", d / "cal.json", [])
    return {"res": res, "counts": counts, "windows": windows, "att": att, "ta": ta,
            "g": s["g_m_s2"] / MG_M_S2}  # fmt: skip


def test_imu_tk_session_residual_falls_by_the_truths_factor(imu_tk: dict[str, Any]) -> None:
    res, g = imu_tk["res"], imu_tk["g"]
    acc_mg = imu_tk["counts"] * MG_PER_COUNT
    before, floor = _expected_factor(imu_tk["ta"], imu_tk["att"], imu_tk["windows"], acc_mg, g)
    assert res["unit"] == "mg" and res["n_poses"] >= 36
    factor = res["gravity_residual_rms_before"] / res["gravity_residual_rms_after"]
    assert before / floor > 50  # a factor worth checking
    assert factor >= (2 / 3) * before / floor, (factor, before, floor)
    assert res["gravity_residual_rms_after"] <= 1.5 * floor
    np.testing.assert_allclose(res["gravity_residual_rms_before"], before, rtol=0.1)


def test_imu_tk_session_agrees_with_an_independent_least_squares(imu_tk: dict[str, Any]) -> None:
    res, g = imu_tk["res"], imu_tk["g"]
    acc_mg = imu_tk["counts"] * MG_PER_COUNT
    means = np.array([acc_mg[a:b].mean(axis=0) for a, b in imu_tk["windows"]])
    bs, mis = _lsq9(means, g)
    a = res["accel"]
    names = a["misalignment_names"]
    idx = [names.index(n) for n in ("xy", "xz", "yz")]
    tc = np.concatenate([a["bias"], a["scale_factor_ppm"],
                         np.array(a["misalignment_arcsec"])[idx]])  # fmt: skip
    sig = np.concatenate([a["bias_sigma"], a["scale_factor_ppm_sigma"],
                          np.array(a["misalignment_arcsec_sigma"])[idx]])  # fmt: skip
    mine = np.concatenate([bs, mis])
    z = (mine - tc) / sig
    assert np.all(np.abs(z) < 1.0), z
    # and both near the truth (the independent solution is not trivially thermocal's)
    ta = imu_tk["ta"]
    truth = np.concatenate([ta[0:6], ta[[8, 10, 11]]])
    assert np.all(np.abs((mine - truth) / sig) < 4.0), (mine - truth) / sig


@pytest.fixture(scope="module")
def ferraris(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("ferraris")
    ta, tg = _truth()
    s = simulate_ferraris(np.random.default_rng(1995), ta, tg, dwell_s=4.0,
                          accel_noise_mg=ACC_NOISE_MG, gyro_noise_deg_s=GYR_NOISE_DPS)  # fmt: skip
    counts = _write_logger_csv(d / "ferraris.csv", s["time_s"], s["accel_mg"], s["gyro_deg_s"])
    (d / "sections.json").write_text(json.dumps(s["sections"]), encoding="utf-8")
    res = _cli(d / "ferraris.csv", d / "cal.json", ["--poses", str(d / "sections.json")])
    faces = {k: (v["start"] + TRIM, v["end"] - TRIM) for k, v in s["sections"].items()
             if not k.endswith("_rot")}  # fmt: skip
    return {"res": res, "counts": counts, "faces": faces, "att": s["attitude"], "ta": ta,
            "g": s["g_m_s2"] / MG_M_S2}  # fmt: skip


def test_ferraris_session_residual_and_closed_form(ferraris: dict[str, Any]) -> None:
    res, g, faces = ferraris["res"], ferraris["g"], ferraris["faces"]
    acc_mg = ferraris["counts"] * MG_PER_COUNT
    windows = list(faces.values())
    before, floor = _expected_factor(ferraris["ta"], ferraris["att"], windows, acc_mg, g)
    assert res["n_poses"] == 6 and res["runs"][0]["gyro"]["n_turns"] == 3
    factor = res["gravity_residual_rms_before"] / max(res["gravity_residual_rms_after"], 1e-12)
    assert before / floor > 50
    assert factor >= (2 / 3) * before / floor, (factor, before, floor)
    assert res["gravity_residual_rms_after"] <= 1.5 * floor
    # the faces in closed form (module docstring), written here
    m = {k: acc_mg[a:b].mean(axis=0) for k, (a, b) in faces.items()}
    a = res["accel"]
    bias = sum(m.values()) / 6.0
    for i, ax in enumerate("xyz"):
        s_i = ((m[f"{ax}_p"][i] - m[f"{ax}_a"][i]) / (2 * g) - 1) * 1e6
        assert abs(bias[i] - a["bias"][i]) < a["bias_sigma"][i], (ax, bias[i], a["bias"][i])
        assert abs(s_i - a["scale_factor_ppm"][i]) < a["scale_factor_ppm_sigma"][i], (ax, s_i)
