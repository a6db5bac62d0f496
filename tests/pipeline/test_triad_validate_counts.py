"""``thermocal validate`` of a multipos calibration made on raw counts (issue 38): the
held-out session, in the same int16 counts, is read through the count scale the calibration
stores, exactly as ``compensate`` reads it (one code path, ``Triad.input_in``), so a good
calibration validates as good, with its figures in the calibration's units (mg, °).

Before the fix the counts were read as mg and °/s: a good calibration read
"gravity-magnitude error 7234 → 7222 mg", "rotation-angle error 42.9 → 43.7°" on this
session (issue 38's "380 → 804°" on the real MPU-6050's).

The sessions are written the way a consumer-IMU logger writes them (``timestamp, ax, ay,
az, gx, gy, gz``, int16 register counts of an MPU-6050 at ±4 g, 8192 LSB/g, and ±2000 °/s,
16.4 LSB/(°/s), no unit in the header); :mod:`thermocal.multipos.simulate` only gives the
truth.  The references are computed here, with numpy and scipy, on the truth's still
windows (0.3 s trimmed at each end):

* accelerometer "before": rms over the poses of ``|mean(count_scale · N)| − g`` [mg];
  "after" below 3× the noise floor (rms over the poses of σ/√n, σ = 1.5 mg the simulated
  white noise);
* gyro "before": per motion between consecutive poses, the raw rate (counts × scale)
  integrated by scipy's ``Rotation`` from the middle of one pose to the middle of the
  next carries the first up direction to the second; the angle between it and the second
  up direction, rms over the motions [°]; "after": the same with the rate corrected by the
  TRUE parameters, ``(I + E)⁻¹ (ω − b)``, which a good calibration approaches.
"""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from thermocal.cli import main
from thermocal.multipos.simulate import simulate_attitudes, simulate_session

ACC_MG_PER_COUNT = 1000.0 / 8192.0
GYR_DPS_PER_COUNT = 1.0 / 16.4
MG_M_S2 = 9.80665e-3
ACC_NOISE_MG = 1.5
TRIM = 30  # samples (0.3 s at 100 Hz) off each end of a still window
GYR_NOISE_DPS = 0.03  # the simulator's default
EARTH_RATE_RAD_S = 7.2921150e-5  # WGS-84
LATITUDE_DEG = 45.0
DH_TO_RS = math.pi / 180.0 / 3600.0
ARCSEC = math.pi / 648000.0


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def _truth() -> tuple[np.ndarray, np.ndarray]:
    ta, tg = np.zeros(12), np.zeros(12)
    ta[0:3], ta[3:6], ta[[8, 10, 11]] = [30.0, -45.0, 25.0], [6000.0, -4000.0, 3000.0], [
        300.0, -250.0, 200.0]  # fmt: skip
    tg[0:3], tg[3:6] = [3000.0, -2000.0, 1500.0], [4000.0, -3000.0, 2500.0]
    return ta, tg


def _write_session(path: Path, seed: int, static_s: float | None = None) -> dict[str, Any]:
    """A simulated session written as a logger writes it (``static_s``: one still pose of
    that length, at a random attitude); the truth and the counts."""
    ta, tg = _truth()
    rng = np.random.default_rng(seed)
    if static_s is None:
        s = simulate_session(rng, ta, tg, n_poses=16, accel_noise_mg=ACC_NOISE_MG)
    else:
        att = Rotation.random(random_state=seed).as_matrix()
        s = simulate_attitudes(rng, [att], ta, tg, dwell_s=static_s, accel_noise_mg=ACC_NOISE_MG)
    acc = np.clip(np.round(s["accel_mg"] / ACC_MG_PER_COUNT), -32768, 32767).astype(np.int16)
    gyr = np.clip(np.round(s["gyro_deg_s"] / GYR_DPS_PER_COUNT), -32768, 32767).astype(np.int16)
    t = np.round(s["time_s"], 3)
    lines = ["timestamp,ax,ay,az,gx,gy,gz"]
    lines += [f"{t[i]:.3f},{acc[i, 0]},{acc[i, 1]},{acc[i, 2]},{gyr[i, 0]},{gyr[i, 1]},"
              f"{gyr[i, 2]}" for i in range(t.size)]  # fmt: skip
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return {"sim": s, "acc": acc.astype(np.float64), "gyr": gyr.astype(np.float64), "t": t}


CAL_ARGS = ["--time", "timestamp", "--time-unit", "s", "--accel", "ax,ay,az", "--gyro",
            "gx,gy,gz", "--accel-unit", "counts", "--gyro-unit", "counts", "--accel-scale",
            f"{ACC_MG_PER_COUNT!r},mg", "--gyro-scale", f"{GYR_DPS_PER_COUNT!r},deg/s",
            "--latitude", "45"]  # fmt: skip


@pytest.fixture(scope="module")
def sessions(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("triadval")
    _write_session(d / "cal.csv", 11)
    held = _write_session(d / "held.csv", 12)
    code, out, err = _run(["multipos", str(d / "cal.csv"), *CAL_ARGS, "-o", str(d / "cal.json"),
                           "--json"])  # fmt: skip
    assert code == 0, err
    return {"dir": d, "cal": json.loads(out), **held}


def _windows(sim: dict[str, Any]) -> list[tuple[int, int]]:
    return [(p0 + TRIM, p1 - TRIM) for p0, p1 in sim["poses"]]


def _accel_reference(h: dict[str, Any]) -> tuple[float, float]:
    """(rms over poses of |mean f| − g before [mg], the noise floor [mg])."""
    f = h["acc"] * ACC_MG_PER_COUNT
    g_mg = h["sim"]["g_m_s2"] / MG_M_S2
    w = _windows(h["sim"])
    e = [np.linalg.norm(f[a:b].mean(axis=0)) - g_mg for a, b in w]
    floor = [ACC_NOISE_MG / math.sqrt(b - a) for a, b in w]
    return float(np.sqrt(np.mean(np.square(e)))), float(np.sqrt(np.mean(np.square(floor))))


def _angle_errors(h: dict[str, Any], rate_rad_s: np.ndarray) -> float:
    """rms over motions of the angle between the integrated first up direction and the
    second [°] (module docstring)."""
    f = h["acc"] * ACC_MG_PER_COUNT
    dt = np.diff(h["t"])
    errs = []
    w = _windows(h["sim"])
    for (a0, b0), (a1, b1) in itertools.pairwise(w):
        i0, i1 = (a0 + b0) // 2, (a1 + b1) // 2
        steps = Rotation.from_rotvec(rate_rad_s[i0:i1] * dt[i0:i1, None])
        rot = Rotation.identity()
        for k in range(len(steps)):
            rot = rot * steps[k]
        u0, u1 = f[a0:b0].mean(axis=0), f[a1:b1].mean(axis=0)
        u0, u1 = u0 / np.linalg.norm(u0), u1 / np.linalg.norm(u1)
        errs.append(math.degrees(math.asin(np.linalg.norm(np.cross(u1, rot.inv().apply(u0))))))
    return float(np.sqrt(np.mean(np.square(errs))))


def _gyro_reference(h: dict[str, Any]) -> tuple[float, float]:
    """(rms angle error with the raw rate, with the rate corrected by the truth) [°]."""
    _ta, tg = _truth()
    w = np.radians(h["gyr"] * GYR_DPS_PER_COUNT)
    i_e = np.eye(3) + np.diag(tg[3:6] * 1e-6)  # no misalignment in the truth
    w_true = np.linalg.solve(i_e, (w - tg[0:3] * DH_TO_RS).T).T
    return _angle_errors(h, w), _angle_errors(h, w_true)


def test_validate_reads_the_counts_through_the_count_scale(sessions: dict[str, Any]) -> None:
    d = sessions["dir"]
    code, out, err = _run(["validate", str(d / "cal.json"), str(d / "held.csv"), "--time",
                           "timestamp", "--time-unit", "s", "--json"])  # fmt: skip
    assert code == 0, err
    tri = json.loads(out)["triads"]
    acc, gyr = tri["accel"], tri["gyro"]
    assert acc["unit"] == "mg" and gyr["unit"] == "deg"
    # what was read and how, as compensate says it
    assert (acc["input_unit"], acc["count_scale"], acc["physical_unit"]) == (
        "counts", ACC_MG_PER_COUNT, "mg")  # fmt: skip
    assert (gyr["input_unit"], gyr["count_scale"], gyr["physical_unit"]) == (
        "counts", GYR_DPS_PER_COUNT, "deg/s")  # fmt: skip
    before, floor = _accel_reference(sessions)
    assert acc["rms_before"] == pytest.approx(before, rel=2e-3)
    assert acc["rms_after"] < 3.0 * floor, (acc["rms_after"], floor)
    g_before, g_after = _gyro_reference(sessions)
    assert gyr["rms_before"] == pytest.approx(g_before, rel=0.02)
    assert gyr["rms_after"] < 2.0 * g_after + 0.01, (gyr["rms_after"], g_after)


def test_validate_and_compensate_share_the_count_scale(sessions: dict[str, Any]) -> None:
    """The Python API: the same figures as the CLI, and each pose's compensated gravity
    magnitude equals the one of ``compensate``'s ``_comp`` columns over the same samples."""
    import pandas as pd

    from thermocal.pipeline.options import ValidateOptions
    from thermocal.pipeline.validate import validate_files

    d = sessions["dir"]
    rep = validate_files(d / "cal.json", d / "held.csv",
                         ValidateOptions(time="timestamp", time_unit="s"))  # fmt: skip
    acc = next(r for r in rep.triads if r.triad == "accel")
    assert acc.unit == "mg" and len(acc.per_pose) == len(sessions["sim"]["poses"])
    code, _o, err = _run(["compensate", str(d / "cal.json"), str(d / "held.csv"), "-o",
                          str(d / "comp.csv"), "--time", "timestamp", "--time-unit",
                          "s"])  # fmt: skip
    assert code == 0, err
    comp = pd.read_csv(d / "comp.csv")[["ax_comp", "ay_comp", "az_comp"]].to_numpy()
    g_mg = sessions["sim"]["g_m_s2"] / MG_M_S2
    for p in acc.per_pose:
        a, b = int(p[0]), int(p[1])
        assert p[6] == pytest.approx(np.linalg.norm(comp[a:b].mean(axis=0)) - g_mg, abs=1e-6)


def test_raw_counts_without_a_count_scale_refused(sessions: dict[str, Any]) -> None:
    """A calibration made on mg (the session converted here) and a raw-count file: one error
    line, as compensate says it."""
    d = sessions["dir"]
    phys = d / "cal_mg.csv"
    lines = (d / "cal.csv").read_text().splitlines()
    out = ["timestamp,ax,ay,az,gx,gy,gz"]
    for ln in lines[1:]:
        v = [float(x) for x in ln.split(",")]
        out.append(",".join([f"{v[0]:.3f}", *(f"{x * ACC_MG_PER_COUNT:.6f}" for x in v[1:4]),
                             *(f"{x * GYR_DPS_PER_COUNT:.6f}" for x in v[4:7])]))  # fmt: skip
    phys.write_text("\n".join(out) + "\n")
    code, _o, err = _run(["multipos", str(phys), "--time", "timestamp", "--time-unit", "s",
                          "--accel", "ax,ay,az", "--gyro", "gx,gy,gz", "--accel-unit", "mg",
                          "--gyro-unit", "deg/s", "--latitude", "45", "-o",
                          str(d / "cal_mg.json")])  # fmt: skip
    assert code == 0, err
    code, _o, err = _run(["validate", str(d / "cal_mg.json"), str(d / "held.csv"), "--time",
                          "timestamp", "--time-unit", "s", "--signal-unit", "counts"])  # fmt: skip
    assert code == 2, err
    assert err.count("error:") == 1 and "held.csv" in err and "no count scale" in err, err
    assert "--accel-scale" in err, err


def test_one_static_pose(sessions: dict[str, Any]) -> None:
    """One still pose of 20 s: validated, not refused.  The gravity magnitude there before
    and after (the test's |mean f| − g, and the noise), the gyro's mean rate at rest in the
    calibration's unit (°/s): before, the raw mean; after, the earth rate in body axes
    (the truth's attitude, ``Cᵀ Ω``, Ω = Ω_E (0, cos φ, sin φ) in ENU) within 4σ of the
    calibration's bias σ and the mean's noise; and what one pose cannot judge, said."""
    d = sessions["dir"]
    h = _write_session(d / "static.csv", 21, static_s=20.0)
    code, out, err = _run(["validate", str(d / "cal.json"), str(d / "static.csv"), "--time",
                           "timestamp", "--time-unit", "s", "--json"])  # fmt: skip
    assert code == 0, err
    tri = json.loads(out)["triads"]
    acc, gyr = tri["accel"], tri["gyro"]
    ((a, b),) = _windows(h["sim"])
    f = h["acc"][a:b] * ACC_MG_PER_COUNT
    g_mg = h["sim"]["g_m_s2"] / MG_M_S2
    assert acc["n"] == 1 and acc["unit"] == "mg"
    assert acc["rms_before"] == pytest.approx(abs(np.linalg.norm(f.mean(axis=0)) - g_mg), rel=0.01)
    assert acc["rms_after"] < 4.0 * ACC_NOISE_MG / math.sqrt(b - a) + 0.1  # + the cal's σ
    assert gyr["unit"] == "deg/s" and gyr["what"] == "mean rate at rest"
    raw = h["gyr"][a:b].mean(axis=0) * GYR_DPS_PER_COUNT
    sigma_mean = GYR_NOISE_DPS / math.sqrt(b - a)
    np.testing.assert_allclose(gyr["per_axis_before"], raw, atol=4 * sigma_mean)
    lat = math.radians(LATITUDE_DEG)
    om_n = EARTH_RATE_RAD_S * np.array([0.0, math.cos(lat), math.sin(lat)])
    earth_body = np.degrees(h["sim"]["attitude"][(a + b) // 2].T @ om_n)
    sig = np.hypot(np.array(sessions["cal"]["gyro"]["bias_sigma"]), sigma_mean)
    assert np.all(np.abs(np.array(gyr["per_axis_after"]) - earth_body) < 4 * sig), (
        gyr["per_axis_after"], earth_body, sig)  # fmt: skip
    assert "needs motions between poses" in acc["not_judged"]
    assert "earth rate" in gyr["not_judged"]
    code, out, err = _run(["validate", str(d / "cal.json"), str(d / "static.csv"), "--time",
                           "timestamp", "--time-unit", "s"])  # fmt: skip
    assert code == 0 and "not judged: one still pose" in out, err


def test_static_s_refused_when_not_a_positive_number(sessions: dict[str, Any]) -> None:
    d = sessions["dir"]
    for bad in ("inf", "0", "nan"):
        code, _o, err = _run(["validate", str(d / "cal.json"), str(d / "held.csv"), "--time",
                              "timestamp", "--time-unit", "s", "--static-s", bad])  # fmt: skip
        assert code == 2 and err.count("error:") == 1 and "--static-s" in err, err
        assert "held.csv" in err, err


def test_one_static_pose_of_an_accelerometer_alone(sessions: dict[str, Any]) -> None:
    """An accelerometer triad alone on one still pose: its figures, and a note that names
    only what it cannot judge (no gyro it does not have)."""
    d = sessions["dir"]
    code, _o, err = _run(["multipos", str(d / "cal.csv"), "--time", "timestamp", "--time-unit",
                          "s", "--accel", "ax,ay,az", "--accel-unit", "counts", "--accel-scale",
                          f"{ACC_MG_PER_COUNT!r},mg", "--latitude", "45", "-o",
                          str(d / "cal_acc.json")])  # fmt: skip
    assert code == 0, err
    h = _write_session(d / "static_acc.csv", 22, static_s=20.0)
    code, out, err = _run(["validate", str(d / "cal_acc.json"), str(d / "static_acc.csv"),
                           "--time", "timestamp", "--time-unit", "s", "--json"])  # fmt: skip
    assert code == 0, err
    tri = json.loads(out)["triads"]
    assert list(tri) == ["accel"] and tri["accel"]["n"] == 1
    ((a, b),) = _windows(h["sim"])
    f = h["acc"][a:b] * ACC_MG_PER_COUNT
    g_mg = h["sim"]["g_m_s2"] / MG_M_S2
    assert tri["accel"]["rms_before"] == pytest.approx(
        abs(np.linalg.norm(f.mean(axis=0)) - g_mg), rel=0.01
    )
    note = tri["accel"]["not_judged"]
    assert "accelerometer's scale factors" in note and "gyro" not in note


def test_the_same_session_in_physical_units_validates_alike(sessions: dict[str, Any]) -> None:
    """The held-out session converted here to mg and °/s (``--signal-unit``, one unit per
    column in the triads' order, as compensate takes it) gives the figures of its counts."""
    d = sessions["dir"]
    lines = (d / "held.csv").read_text().splitlines()
    out = [lines[0]]
    for ln in lines[1:]:
        v = [float(x) for x in ln.split(",")]
        out.append(",".join([f"{v[0]:.3f}", *(repr(x * ACC_MG_PER_COUNT) for x in v[1:4]),
                             *(repr(x * GYR_DPS_PER_COUNT) for x in v[4:7])]))  # fmt: skip
    (d / "held_phys.csv").write_text("\n".join(out) + "\n")
    res = {}
    per_column = ["--signal-unit", "mg,mg,mg,deg/s,deg/s,deg/s"]
    for name, extra in (("held.csv", []), ("held_phys.csv", per_column)):
        code, o, err = _run(["validate", str(d / "cal.json"), str(d / name), "--time",
                             "timestamp", "--time-unit", "s", "--json", *extra])  # fmt: skip
        assert code == 0, err
        res[name] = json.loads(o)["triads"]
    for tri in ("accel", "gyro"):
        a, b = res["held.csv"][tri], res["held_phys.csv"][tri]
        assert b["input_unit"] != "counts" and b["count_scale"] is None
        for k in ("rms_before", "rms_after", "per_axis_before", "per_axis_after"):
            np.testing.assert_allclose(b[k], a[k], rtol=1e-9, atol=1e-12)
