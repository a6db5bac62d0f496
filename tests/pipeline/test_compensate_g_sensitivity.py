"""A gyro's g-sensitivity through ``multipos`` → ``compensate`` (issue 44): on a simulated
16-pose session whose gyro reads ``A f`` more (``A`` up to 300 °/h/g), the compensated
gyro's bias in every static pose falls to the white noise of the pose's mean with ``A``
applied, and stays at ``A f`` without (residuals computed here from the simulator's attitude:
the true earth rate in body axes taken off); the stored bias is the truth's, at zero specific
force; a calibration without a significant ``A`` stores none; a recording without the
accelerometer's columns is refused in one line naming ``--g-sensitivity``; the formula on a
calibration written here, in other units, equals ``(I + E)⁻¹ (ω − b − A f)`` computed here."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from gsens_session import (
    A_TRUE,
    GYRO_NOISE_DEG_S,
    GYRO_THETA,
    LATITUDE_DEG,
    MULTIPOS,
    READ,
    calibrate,
    run,
    write_session,
)
from thermocal import units
from thermocal.models.calibration import Calibration, Triad
from thermocal.pipeline.model_file import save_calibration
from thermocal.turntable import model, thermal

TRIM = 50  # samples left out at each end of a pose (the hand settling)


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("gsens")
    sim = write_session(d)
    return {"dir": d, "sim": sim, "result": calibrate(d)}


def _compensate(d: Path, data: str, out: str, *extra: str) -> tuple[int, str, str]:
    return run(["compensate", str(d / "cal.json"), str(d / data), "-o", str(d / out), *READ,
                "--json", *extra])  # fmt: skip


def _pose_residuals(sim: dict[str, Any], comp: pd.DataFrame) -> tuple[Any, Any, Any]:
    """Per static pose: the compensated gyro's mean less the true earth rate in body axes
    [°/h], the truth's A f [°/h] and the white-noise σ of the mean [°/h]."""
    w = comp[["gx_comp", "gy_comp", "gz_comp"]].to_numpy() * 3600.0
    lat = math.radians(LATITUDE_DEG)
    om = units.EARTH_RATE_RAD_S * np.array([0.0, math.cos(lat), math.sin(lat)])  # ENU
    res, af, sig = [], [], []
    for a0, a1 in sim["poses"]:
        att = sim["attitude"][(a0 + a1) // 2]  # body → ENU
        earth = att.T @ om * 180.0 / math.pi * 3600.0
        f_g = att.T @ np.array([0.0, 0.0, sim["g_m_s2"] / 9.80665])
        res.append(w[a0 + TRIM : a1 - TRIM].mean(axis=0) - earth)
        af.append(A_TRUE @ f_g)
        sig.append(GYRO_NOISE_DEG_S * 3600.0 / math.sqrt(a1 - a0 - 2 * TRIM))
    return np.array(res), np.array(af), np.array(sig)


def test_applied_the_pose_biases_fall_to_the_noise(session: dict[str, Any]) -> None:
    """Seen red with the A f term left out of the compensation: residual rms 155 °/h."""
    d = session["dir"]
    code, out, err = _compensate(d, "s.csv", "with.csv")
    assert code == 0, err
    flags = {t["triad"]: t["g_sensitivity"] for t in json.loads(out)["triads"]}
    assert flags == {"accel": False, "gyro": True}
    res, af, sig = _pose_residuals(session["sim"], pd.read_csv(d / "with.csv"))
    rms_noise = math.sqrt(float(np.mean(sig**2)))
    # what is left is the noise of each pose's mean and of the calibration's own estimates
    assert math.sqrt(float(np.mean(res**2))) < 2.0 * rms_noise, (res, rms_noise)
    assert math.sqrt(float(np.mean(af**2))) > 25.0 * rms_noise  # A f is far beyond it


def test_not_applied_the_pose_biases_keep_a_f(session: dict[str, Any]) -> None:
    d = session["dir"]
    code, out, err = _compensate(d, "s.csv", "without.csv", "--g-sensitivity", "off")
    assert code == 0, err
    assert not any(t["g_sensitivity"] for t in json.loads(out)["triads"])
    res, af, _sig = _pose_residuals(session["sim"], pd.read_csv(d / "without.csv"))
    # the residual is A f about the bias at zero force: it follows A f pose by pose
    np.testing.assert_allclose(res - res.mean(axis=0), af - af.mean(axis=0), atol=30.0)
    assert math.sqrt(float(np.mean(res**2))) > 0.8 * math.sqrt(float(np.mean(af**2)))


def test_the_file_holds_a_and_the_bias_at_zero_force(session: dict[str, Any]) -> None:
    """A within 4σ of the truth in deg/s/g; the gyro bias within 4σ of the truth's (the
    static poses' mean holds A f̄ besides)."""
    doc = json.loads((session["dir"] / "cal.json").read_text())
    assert doc["format_version"] == 3
    gyro = next(t for t in doc["triads"] if t["name"] == "gyro")
    assert gyro["g_sensitivity_unit"] == "deg/s/g"
    a, s = np.array(gyro["g_sensitivity"]), np.array(gyro["g_sensitivity_sigma"])
    assert np.all(np.abs(a - A_TRUE / 3600.0) < 4.0 * s), (a * 3600, s * 3600)
    g = session["result"]["gyro"]
    assert g["g_sensitivity"]["stored"] and g["g_sensitivity"]["n_sessions"] == 1
    b, sb = np.array(g["bias"]), np.array(g["bias_sigma"])
    assert np.all(np.abs(b - GYRO_THETA[0:3] / 3600.0) < 4.0 * sb), (b * 3600, sb * 3600)


def test_a_gyro_only_recording_is_refused_then_taken_with_off(session: dict[str, Any]) -> None:
    d = session["dir"]
    pd.read_csv(d / "s.csv")[["t", "gx", "gy", "gz"]].to_csv(d / "gyro.csv", index=False)
    code, _o, err = _compensate(d, "gyro.csv", "g1.csv")
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2 and len(errors) == 1 and "Traceback" not in err, err
    assert "--g-sensitivity off" in errors[0] and "'ax'" in errors[0], errors[0]
    assert not (d / "g1.csv").exists()
    code, out, err = _compensate(d, "gyro.csv", "g2.csv", "--g-sensitivity", "off")
    assert code == 0, err
    assert "warning:" in err and "accel" in err and "left out" in err
    assert [t["triad"] for t in json.loads(out)["triads"]] == ["gyro"]
    code, _o, err = _compensate(d, "s.csv", "full_off.csv", "--g-sensitivity", "off")
    assert code == 0, err
    cols = ["gx_comp", "gy_comp", "gz_comp"]  # the gyro alone: as with the accelerometer
    # (to 1e-12 deg/s: the floor's numpy/pandas gave 4e-14 apart on values near zero, where
    # a relative tolerance alone fails)
    np.testing.assert_allclose(
        pd.read_csv(d / "g2.csv")[cols],
        pd.read_csv(d / "full_off.csv")[cols],
        rtol=1e-12,
        atol=1e-12,
    )


def test_bad_choices_are_refused_in_one_line(session: dict[str, Any]) -> None:
    d = session["dir"]
    code, _o, err = _compensate(d, "s.csv", "x.csv", "--g-sensitivity", "yes")
    assert code == 2 and "--g-sensitivity" in err and "apply or off" in err, err
    code, _o, err = run(["multipos", str(d / "s.csv"), *READ, "--accel", "ax,ay,az",
                         "--accel-unit", "mg", "--latitude", "45", "-o", str(d / "y.json"),
                         "--g-sensitivity", "apply"])  # fmt: skip
    assert code == 2 and "--gyro" in err and "--g-sensitivity" in err, err


def test_auto_stores_none_that_is_not_significant(tmp_path: Path) -> None:
    """A gyro without g-sensitivity: auto stores nothing (format version 1, the gyro bias the
    static poses' mean); apply stores it anyway; off never, even with one."""
    write_session(tmp_path, seed=8, a_deg_h_g=np.zeros((3, 3)))
    r = calibrate(tmp_path)
    assert not r["gyro"]["g_sensitivity"]["stored"]
    assert "no element beyond 3σ" in r["gyro"]["g_sensitivity"]["why"]
    doc = json.loads((tmp_path / "cal.json").read_text())
    assert doc["format_version"] == 1
    assert not any("g_sensitivity" in t for t in doc["triads"])
    assert r["gyro"]["bias"] == pytest.approx(r["runs"][0]["gyro"]["bias"], rel=1e-9)
    calibrate(tmp_path, "--g-sensitivity", "apply", name="apply.json")
    doc = json.loads((tmp_path / "apply.json").read_text())
    assert doc["format_version"] == 3 and "g_sensitivity" in doc["triads"][1]
    write_session(tmp_path, seed=8)
    r = calibrate(tmp_path, "--g-sensitivity", "off", name="off.json")
    assert any(r["runs"][0]["gyro"]["g_sensitivity"]["significant"][0])
    assert not r["gyro"]["g_sensitivity"]["stored"]
    assert json.loads((tmp_path / "off.json").read_text())["format_version"] == 1


def test_the_formula_in_other_units(tmp_path: Path) -> None:
    """Accelerometer in m/s², gyro in rad/s, A in rad/s per g: ω_c = (I + E)⁻¹ (ω − b − A f),
    f the accelerometer's compensated output over 9.80665 m/s², written here."""
    ta = np.array([20.0, -10.0, 5.0, 3000.0, -2000.0, 1000.0, 0, 0, 100.0, 0, -50.0, 80.0])
    tg = np.array([900.0, -500.0, 300.0, 2000.0, 1000.0, -500.0, 60, -40, 30, 20, -10, 50.0])
    a_rad = np.array([[1e-3, -2e-4, 3e-4], [0.0, 5e-4, -1e-4], [2e-4, 1e-4, -8e-4]])
    cal = Calibration([], [
        Triad("accel", ("ax", "ay", "az"), "m/s^2", "", thermal.constant_triad(
            "accel", 25.0, ta, np.eye(12), method="multipos")),
        Triad("gyro", ("gx", "gy", "gz"), "rad/s", "", thermal.constant_triad(
            "gyro", 25.0, tg, np.eye(12), method="multipos"),
            g_sensitivity=a_rad, g_sensitivity_sigma=np.full((3, 3), 1e-5)),
    ])  # fmt: skip
    save_calibration(cal, tmp_path / "cal.json")
    rng = np.random.default_rng(2)
    acc = rng.normal(0.0, 6.0, (40, 3))
    gyr = rng.normal(0.0, 0.5, (40, 3))
    pd.DataFrame({"t": np.arange(40) * 0.01, **{f"a{c}": acc[:, k] for k, c in enumerate("xyz")},
                  **{f"g{c}": gyr[:, k] for k, c in enumerate("xyz")}}).to_csv(
        tmp_path / "r.csv", index=False)  # fmt: skip
    code, _o, err = run(["compensate", str(tmp_path / "cal.json"), str(tmp_path / "r.csv"),
                         "-o", str(tmp_path / "o.csv"), *READ, "--signal-unit",
                         "m/s^2,m/s^2,m/s^2,rad/s,rad/s,rad/s"])  # fmt: skip
    assert code == 0, err
    out = pd.read_csv(tmp_path / "o.csv")
    mg_ms2 = 9.80665e-3
    dh_rs = math.pi / 180.0 / 3600.0
    ea, eg = model.error_matrices(ta), model.error_matrices(tg)
    f_ms2 = np.linalg.solve(np.eye(3) + ea, (acc - ta[0:3] * mg_ms2).T).T
    want = np.linalg.solve(np.eye(3) + eg, (gyr - tg[0:3] * dh_rs - f_ms2 / 9.80665 @ a_rad.T).T).T
    np.testing.assert_allclose(out[["ax_comp", "ay_comp", "az_comp"]], f_ms2, rtol=1e-12)
    np.testing.assert_allclose(out[["gx_comp", "gy_comp", "gz_comp"]], want, rtol=1e-10, atol=1e-15)


def test_the_text_says_what_was_stored_and_applied(session: dict[str, Any]) -> None:
    d = session["dir"]
    code, out, err = run(["compensate", str(d / "cal.json"), str(d / "s.csv"), "-o",
                          str(d / "text.csv"), *READ])  # fmt: skip
    assert code == 0, err
    text = " ".join(out.split())
    assert "gyro: gx_comp, gy_comp, gz_comp [deg/s] (g-sensitivity A·f taken off)" in text
    assert "accel: ax_comp, ay_comp, az_comp [mg]" in text and text.count("A·f") == 1
    code, out, err = run(["multipos", str(d / "s.csv"), *MULTIPOS, "-o", str(d / "t.json")])
    assert code == 0, err
    largest = float(np.max(np.abs(json.loads((d / "t.json").read_text())["triads"][1][
        "g_sensitivity"])))  # fmt: skip
    assert (
        "gyro g-sensitivity stored: an element is beyond 3σ (largest |A| "
        f"{largest:.3g} deg/s/g, over 1 session(s)): compensate takes A·f off"
    ) in " ".join(out.split())


def test_a_gyro_triad_alone_with_a_is_refused_then_taken_with_off(tmp_path: Path) -> None:
    """A calibration holding the gyro triad only (no accelerometer to give f)."""
    tg = np.zeros(12)
    tg[0:3] = [36.0, -72.0, 18.0]  # °/h
    model = thermal.constant_triad("gyro", 25.0, tg, np.eye(12), method="multipos")
    gyro = Triad("gyro", ("gx", "gy", "gz"), "deg/s", "", model, g_sensitivity=np.eye(3) * 0.01,
                 g_sensitivity_sigma=np.full((3, 3), 1e-4))  # fmt: skip
    save_calibration(Calibration([], [gyro]), tmp_path / "g.json")
    pd.DataFrame({"t": [0.0, 0.01, 0.02], "gx": [0.1, 0.2, 0.3], "gy": [0.0] * 3,
                  "gz": [1.0] * 3}).to_csv(tmp_path / "r.csv", index=False)  # fmt: skip
    args = ["compensate", str(tmp_path / "g.json"), str(tmp_path / "r.csv"), *READ,
            "--signal-unit", "deg/s"]  # fmt: skip
    code, _o, err = run([*args, "-o", str(tmp_path / "a.csv")])
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2 and len(errors) == 1, err
    assert "holds none" in errors[0] and "--g-sensitivity off" in errors[0], errors[0]
    code, _o, err = run([*args, "-o", str(tmp_path / "b.csv"), "--g-sensitivity", "off"])
    assert code == 0, err
    out = pd.read_csv(tmp_path / "b.csv")
    np.testing.assert_allclose(out["gx_comp"], np.array([0.1, 0.2, 0.3]) - 0.01, rtol=1e-12)


def test_two_sessions_give_one_a(tmp_path: Path) -> None:
    """Two sessions of the sensor at 20 and 40 °C (no temperature dependence simulated):
    one A from both (n_sessions 2, within 4σ of the truth), the gyro's bias polynomial fitted
    on the biases at zero force (its value at TREF within 4σ of the truth)."""
    files = []
    for k, (seed, temp) in enumerate(((5, 20.0), (11, 40.0))):
        d = tmp_path / f"s{k}"
        d.mkdir()
        write_session(d, seed=seed)
        data = pd.read_csv(d / "s.csv")
        data["T"] = temp
        data.to_csv(d / "s.csv", index=False)
        files.append(str(d / "s.csv"))
    code, out, err = run(["multipos", *files, *MULTIPOS, "--temps", "T", "--order", "0",
                          "-o", str(tmp_path / "cal.json"), "--json"])  # fmt: skip
    assert code == 0, err
    g = json.loads(out)["gyro"]
    gs = g["g_sensitivity"]
    assert gs["stored"] and gs["n_sessions"] == 2
    a, s = np.array(gs["matrix"]), np.array(gs["matrix_sigma"])
    assert np.all(np.abs(a - A_TRUE / 3600.0) < 4.0 * s), (a * 3600, s * 3600)
    runs = [np.array(r["gyro"]["g_sensitivity"]["matrix_sigma"]) for r in json.loads(out)["runs"]]
    assert np.all(s < np.minimum(runs[0], runs[1]))  # two sessions: tighter than either
    b, sb = np.array(g["bias"]), np.array(g["bias_sigma"])
    assert np.all(np.abs(b - GYRO_THETA[0:3] / 3600.0) < 4.0 * sb), (b * 3600, sb * 3600)
