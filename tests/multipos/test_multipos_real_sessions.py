"""``thermocal multipos`` on real public sessions (issue 38), through the CLI.

**MPU-6050, hand-held** (``tests/data/imucalibration_mpu6050``, tomisuarez2/ImuCalibration,
MIT): a 36.5 s static on the table, then nine places where the board is held by hand for
2–7 s.  Its authors' tool finds 10 static intervals (their
``optmization result data/static_intervals.csv``, quoted below); thermocal's detector,
judged against the sensor's noise and the motions around the poses, must find the same 10
places (each of the authors' intervals inside exactly one pose, one to one).  The file has
no time column (``Fs,100`` in its banner): the test writes it as a user's export with
``time = row / 100 Hz``.  Its held-out +90° turn is compared with the authors' own
calibration applied as their code does (written here).

**imu_tk's Xsens session** (``tests/data/imu_tk_xsens``, BSD-2): unsigned ADC counts
around 32768; its poses with the offset stated (or found, with a warning), and the
accelerometer calibration against imu_tk's unweighted gravity-magnitude cost solved here
with scipy on the same poses.

**Simulated sessions** (:mod:`thermocal.multipos.simulate` gives the truth): hand-held 2 s
poses read by a quiet and a noisy accelerometer, heavy tremor, a slow turn inside a rest,
a gyro clipping on its int16 rails, unsigned offset counts.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main

DATA = Path(__file__).parents[1] / "data"
MPU = DATA / "imucalibration_mpu6050"
MPU_RATE_HZ = 100.0
MPU_ACC = "0.06103515625,mg"  # ±2 g: 1000/16384 mg per count (the authors' g/16384)
MPU_GYR = "0.00762939453125,deg/s"  # ±250 °/s: 250/32768 °/s per count
AUTHOR_STARTS = (150, 4297, 4934, 5585, 6205, 7018, 7570, 8297, 9094, 9662)
AUTHOR_ENDS = (3613, 4299, 4946, 5690, 6368, 7046, 7765, 8457, 9158, 10095)
"""The authors' 10 static intervals (``static_intervals.csv``, sample indices)."""
COLS = ("ax", "ay", "az", "gx", "gy", "gz")


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def _mpu_csv(name: str, out: Path) -> Path:
    """The authors' file as a CSV with a time column (s) and the counts' unit named."""
    d = np.loadtxt(MPU / name, delimiter=",", skiprows=5)
    t = np.arange(d.shape[0]) / MPU_RATE_HZ
    head = "time [s]," + ",".join(f"{c} [counts]" for c in COLS)
    np.savetxt(out, np.column_stack([t, d]), delimiter=",", header=head, comments="",
               fmt=["%.2f"] + ["%d"] * 6)  # fmt: skip
    return out


def _cols(names: str) -> str:
    return ",".join(f"{c} [counts]" for c in names.split(","))


@pytest.fixture(scope="module")
def mpu(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("mpu")
    cal = _mpu_csv("example_data_calibration.csv", d / "cal.csv")
    args = ["multipos", str(cal), "--accel", _cols("ax,ay,az"), "--gyro", _cols("gx,gy,gz"),
            "--accel-scale", MPU_ACC, "--gyro-scale", MPU_GYR, "--gravity", "9.80665",
            "-o", str(d / "cal.json"), "--json"]  # fmt: skip
    code, out, err = _run(args)
    assert code == 0, err
    assert "poses are not still" in err  # held with a shaking hand
    # the gyro on the int16 rails at rows 3910–3911, 6662–6671 (gx) and 8766–8771 (gz),
    # counted in the shipped file: those three motions are named and left out of the fit
    assert (
        "the gyro is on its rails (clipped) during 3 motion(s): pose_1 → pose_2 (rows "
        "3910…), pose_5 → pose_6 (rows 6662…), pose_8 → pose_9 (rows 8766…)" in err
    ), err
    # 6 motions left for 9 gyro elements (3 degrees of freedom) misfitting their noise
    # (reduced χ² ≈ 700): the default full model is warned of, naming the reduced one
    assert "6 motions between poses for the gyro's 9 scale factors" in err, err
    assert "--gyro-model scale" in err
    return {"dir": d, "summary": json.loads(out), "cal": d / "cal.json", "args": args}


def test_mpu_hand_held_session_gives_the_authors_ten_poses(mpu: dict[str, Any]) -> None:
    s = mpu["summary"]
    assert s["n_poses"] == 10
    poses = [(p["start"], p["end"]) for p in s["poses"]]
    for a0, a1 in zip(AUTHOR_STARTS, AUTHOR_ENDS, strict=True):
        inside = [k for k, (p0, p1) in enumerate(poses) if p0 < a1 and a0 < p1]
        assert len(inside) == 1, (a0, a1, poses)
    det = s["pose_detection"][0]
    assert det["n_poses"] == 10 and det["rejected"] == []
    # the explanation: the limit was set by the motions (hand-held), in the data's unit
    assert det["accel"]["limit_set_by"] == "motion"
    assert det["accel"]["still_limit_rms"] == pytest.approx(0.1 * det["accel"]["motion_rms"])


def test_mpu_explanation_in_the_human_output(mpu: dict[str, Any]) -> None:
    args = [a for a in mpu["args"] if a != "--json"]
    args[args.index("-o") + 1] = str(mpu["dir"] / "cal2.json")
    code, out, err = _run(args)
    assert code == 0, err
    assert "10 poses (window 0.5 s" in out and "set by the motions" in out
    # the gyro's misfit said beside its σ: χ² of the 6 motions' residuals against their
    # noise (≈ 0.05° per motion; the residuals are ≈ 1°)
    assert "the gyro's 6 motions scatter beyond their noise (reduced χ² 704 on 3 degrees" in out


AUTHOR_ACC = (1.043860522409845042e-05, 2.098452816658057195e-06,
              2.005985606930172646e-06, 6.020083400010406817e-04,
              5.968449488725015338e-04, 5.859241382355084718e-04,
              -7.115163422327075295e02, 3.585054836108664063e02,
              1.840128451085784491e03)  # fmt: skip
"""The authors' accelerometer calibration (``optmization result data/params_acc.csv``):
misalignments yz, zy, zx, scales [(m/s²)/count], biases [counts]."""
AUTHOR_GYR = (-9.967394130262499652e-03, 9.183836411500549690e-03, -2.912198601931083493e-03,
              7.234881652289322680e-03, -9.841957371310869340e-03, 5.795923574753897821e-03,
              1.373743743438648286e-04, 1.329249743689399734e-04, 1.339443406342994032e-04,
              -4.274617614746093750e02, 1.479479370117187500e02,
              -8.072266387939453125e01)  # fmt: skip
"""The authors' gyro calibration (``params_gyro.csv``): six misalignments, scales
[(rad/s)/count], biases [counts]."""
TURN_BEFORE, TURN_AFTER = (100, 1450), (2400, 4300)
"""The held-out session's still stretches around its +90° turn about x (rows; the gyro
stays within 0.5 °/s of its rest there, the turn spans rows ≈1475–2225)."""


def _author_acc(raw: np.ndarray) -> np.ndarray:
    """The authors' ``apply_accel_calibration``: ``T K (raw + b)``, written here."""
    m, k, b = np.split(np.asarray(AUTHOR_ACC), [3, 6])
    t = np.array([[1.0, -m[0], m[1]], [0.0, 1.0, -m[2]], [0.0, 0.0, 1.0]])
    out: np.ndarray = (raw + b) @ (t @ np.diag(k)).T
    return out


def _author_gyr(raw: np.ndarray) -> np.ndarray:
    """The authors' ``apply_gyro_calibration``: ``T K (raw − b)`` [rad/s], written here."""
    m, k, b = np.split(np.asarray(AUTHOR_GYR), [6, 9])
    t = np.array([[1.0, -m[0], m[1]], [m[2], 1.0, -m[3]], [-m[4], m[5], 1.0]])
    out: np.ndarray = (raw - b) @ (t @ np.diag(k)).T
    return out


def _turn_error_deg(acc: np.ndarray, rate_rad_s: np.ndarray, dt: float = 0.01) -> float:
    """The angle [°] between gravity measured after the turn and gravity before it carried
    by the integrated rate (body frame, scipy rotations composed sample by sample)."""
    from scipy.spatial.transform import Rotation

    (a0, a1), (b0, b1) = TURN_BEFORE, TURN_AFTER
    u0 = acc[a0:a1].mean(axis=0)
    u1 = acc[b0:b1].mean(axis=0)
    rot = Rotation.identity()
    for w in rate_rad_s[a1:b0]:
        rot = rot * Rotation.from_rotvec(w * dt)
    p = rot.apply(u0 / np.linalg.norm(u0), inverse=True)
    c = float(p @ u1 / np.linalg.norm(u1))
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def _held_out(cal: Path, d: Path) -> tuple[np.ndarray, np.ndarray]:
    """The held-out session compensated by ``thermocal compensate`` with ``cal``: the
    accelerometer [counts' unit] and the rate [rad/s]."""
    import pandas as pd

    held = _mpu_csv("imu_90_x_rot.csv", d / "held.csv")
    comp = d / f"held_comp_{cal.stem}.csv"
    code, _o, err = _run(["compensate", str(cal), str(held), "-o", str(comp)])
    assert code == 0, err
    df = pd.read_csv(comp)
    acc = df[[f"a{a} [counts]_comp" for a in "xyz"]].to_numpy()
    rate = np.radians(df[[f"g{a} [counts]_comp" for a in "xyz"]].to_numpy())
    return acc, rate


def test_mpu_held_out_90_degree_turn(mpu: dict[str, Any]) -> None:
    """The held-out turn compensated by ``thermocal compensate`` with the session's
    calibration, against the authors' own calibration applied as their code does (both
    computed here).  The authors' error is 1.54°.  thermocal's full model, with the three
    clipped motions left out (6 motions for 9 gyro parameters, warned of), is 7.0°,
    within what its stated uncertainty predicts for a turn about x, 7.3° (the σ of the x
    scale factor and of the misalignments of x into y and z, ``xy`` and ``xz``, times the
    90° turned): worse than the datasheet's nominal gyro scale with thermocal's
    accelerometer (2.23°).  ``--gyro-model scale`` (below) reaches the target."""
    acc, rate = _held_out(mpu["cal"], mpu["dir"])
    raw = np.loadtxt(MPU / "imu_90_x_rot.csv", delimiter=",", skiprows=5)
    author = _turn_error_deg(_author_acc(raw[:, :3]), _author_gyr(raw[:, 3:]))
    assert author == pytest.approx(1.54, abs=0.01)
    mine = _turn_error_deg(acc, rate)
    g = mpu["summary"]["gyro"]
    names = g["misalignment_names"]
    arcsec = 1.0 / 206264.80624709636
    sig = np.array([g["scale_factor_ppm_sigma"][0] * 1e-6,  # E[0, 0], E[1, 0], E[2, 0]
                    g["misalignment_arcsec_sigma"][names.index("xy")] * arcsec,
                    g["misalignment_arcsec_sigma"][names.index("xz")] * arcsec])  # fmt: skip
    predicted = 90.0 * float(np.linalg.norm(sig))
    assert mine <= 1.5 * predicted, (mine, predicted)
    nominal = np.radians((raw[:, 3:] - raw[100:1450, 3:].mean(axis=0)) * 250 / 32768)
    assert _turn_error_deg(raw[:, :3], nominal) > 10.0  # nothing calibrated: 10.3°
    # thermocal's accelerometer with the datasheet's gyro scale: 2.23°, within 1.5× the
    # authors': the accelerometer part holds; the gyro fit on 6 hand-held motions does not
    assert _turn_error_deg(acc, nominal) <= 1.5 * author


def test_mpu_held_out_turn_within_1p2_of_the_authors(mpu: dict[str, Any]) -> None:
    """What the default's warning says, done: ``--gyro-model scale`` fits the 3 gyro
    scale factors on the 6 unclipped motions (9 degrees of freedom), the misalignments
    held at 0; the held-out turn, compensated by ``thermocal compensate``, is then 0.90°
    from gravity, within 1.2× the authors' 1.54° (their 9 elements on all 9 motions,
    clipped ones included; computed here as their code does).  Seen red with the scale
    model fitting all nine elements (6.96°)."""
    args = [a for a in mpu["args"]]
    args[args.index("-o") + 1] = str(mpu["dir"] / "cal_scale.json")
    code, out, err = _run([*args, "--gyro-model", "scale"])
    assert code == 0, err
    assert "--gyro-model" not in err  # the reduced model is not warned of
    g = json.loads(out)["runs"][0]["gyro"]
    assert g["model"] == "scale" and g["n_motions"] == 6
    assert g["misalignment_arcsec"] == [0.0] * 6 and g["misalignment_arcsec_sigma"] == [0.0] * 6
    acc, rate = _held_out(mpu["dir"] / "cal_scale.json", mpu["dir"])
    raw = np.loadtxt(MPU / "imu_90_x_rot.csv", delimiter=",", skiprows=5)
    author = _turn_error_deg(_author_acc(raw[:, :3]), _author_gyr(raw[:, 3:]))
    mine = _turn_error_deg(acc, rate)
    assert mine <= 1.2 * author, (mine, author)
    assert mine == pytest.approx(0.90, abs=0.05)
    # what thermocal states for it: the x scale factor's σ (scaled by the misfit, χ² 794
    # on 9 dof) times the 90° turned, 2.2°: the 0.90° is inside, the data do not pin the
    # scale factors below ≈ 2.5 % (leaving one of the 6 motions out moves it to 0.4–4.6°)
    predicted = 90.0 * g["scale_factor_ppm_sigma"][0] * 1e-6
    assert predicted == pytest.approx(2.2, abs=0.1) and mine <= predicted


def test_gyro_model_unknown_is_refused(mpu: dict[str, Any]) -> None:
    args = [a for a in mpu["args"]]
    args[args.index("-o") + 1] = str(mpu["dir"] / "cal_bad.json")
    code, _out, err = _run([*args, "--gyro-model", "diag"])
    assert code == 2
    assert err.strip().count("\n") == 0 and "error: --gyro-model 'diag': full or scale" in err
    no_gyro = args[: args.index("--gyro")] + args[args.index("--gyro") + 2 :]
    code, _out, err = _run([*no_gyro, "--gyro-model", "scale"])
    assert code == 2 and err.strip().count("\n") == 0
    assert "error: --gyro-model scale: no gyro columns to fit; name them with --gyro" in err


# --- imu_tk's Xsens session -------------------------------------------------------------

XSENS = DATA / "imu_tk_xsens" / "xsens_imu_tk.parquet"
X_ACC = "0.27,mg"  # ≈ g/3700: one count, from the initial static's own magnitude
X_GYR = "0.0091554,deg/s"  # imu_tk's test program: 1/6258 (rad/s)/count
X_G_M_S2 = 9.81744  # imu_tk's test program
MID = 32768.0
MG_M_S2 = 9.80665e-3


def _xsens_args(out: Path, *extra: str) -> list[str]:
    acc = ",".join(f"acc_{a} [counts]" for a in "xyz")
    gyr = ",".join(f"gyro_{a} [counts]" for a in "xyz")
    return ["multipos", str(XSENS), "--accel", acc, "--gyro", gyr, "--accel-scale", X_ACC,
            "--gyro-scale", X_GYR, "--gravity", str(X_G_M_S2), "-o", str(out), "--json",
            *extra]  # fmt: skip


@pytest.fixture(scope="module")
def xsens(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("xsens")
    code, out, err = _run(_xsens_args(d / "cal.json", "--accel-offset", "32768",
                                      "--gyro-offset", "32768"))  # fmt: skip
    assert code == 0, err
    import pandas as pd

    df = pd.read_parquet(XSENS)
    counts = df[[f"acc_{a} [counts]" for a in "xyz"]].to_numpy(dtype=np.float64)
    return {"dir": d, "summary": json.loads(out), "err": err, "counts": counts}


def _distinct(u: np.ndarray, deg: float = 10.0) -> int:
    """Directions more than ``deg`` apart (greedy, in order), written here."""
    kept: list[np.ndarray] = []
    for v in u / np.linalg.norm(u, axis=1)[:, None]:
        if all(float(v @ k) < np.cos(np.radians(deg)) for k in kept):
            kept.append(v)
    return len(kept)


def test_xsens_offset_counts_give_its_thirty_odd_poses(xsens: dict[str, Any]) -> None:
    s, counts = xsens["summary"], xsens["counts"]
    assert 30 <= s["n_poses"] <= 45
    means = np.array([counts[p["start"] : p["end"]].mean(axis=0) for p in s["poses"]])
    # every placement is a real move (consecutive poses ≥ 30° apart); the session revisits
    # orientations, 14 of them more than 10° from each other (the fit needs 9)
    u = (means - MID) / np.linalg.norm(means - MID, axis=1)[:, None]
    assert np.all(np.degrees(np.arccos(np.sum(u[1:] * u[:-1], axis=1))) > 30)
    assert _distinct(means - MID) >= 12
    # the pose means reported are the columns' own (offset put back), in the scale's unit
    got = np.array([p["mean_specific_force"] for p in s["poses"]])
    np.testing.assert_allclose(got, means * 0.27, rtol=1e-9)
    assert s["runs"][0]["offset"] == {"accel": pytest.approx(MID * 0.27),
                                      "gyro": pytest.approx(MID * 0.0091554)}  # fmt: skip


def test_xsens_without_the_offset_is_one_direction(tmp_path: Path) -> None:
    """Raw counts judged with their mid-scale in: every pose points to (+, +, +)."""
    code, _out, err = _run(_xsens_args(tmp_path / "c.json", "--accel-offset", "0",
                                       "--gyro-offset", "0"))  # fmt: skip
    assert code == 2 and "1 distinct poses" in err and "--accel-offset" in err, err


def test_xsens_mid_scale_found_with_a_warning(tmp_path: Path, xsens: dict[str, Any]) -> None:
    code, out, err = _run(_xsens_args(tmp_path / "c.json"))
    assert code == 0, err
    assert "warning:" in err and "32768 taken as their zero; give --accel-offset" in err
    assert json.loads(out)["accel"]["bias"] == pytest.approx(xsens["summary"]["accel"]["bias"])


def _tedaldi(means: np.ndarray, g: float, sigma: np.ndarray) -> np.ndarray:
    """Tedaldi et al. 2014's gravity-magnitude fit written here (scipy): ``m = (I + E) f +
    b``, E lower triangular (scale on the diagonal, xy, xz, yz below), residual
    ``(|(I + E)⁻¹ (m − b)| − g)/σ_k``; returns (b, scale ×10⁻³, xy/xz/yz ×10⁻³)."""
    from scipy.optimize import least_squares

    def resid(p: np.ndarray) -> np.ndarray:
        e = np.diag(p[3:6] * 1e-3)
        e[1, 0], e[2, 0], e[2, 1] = p[6:9] * 1e-3
        f = np.linalg.solve(np.eye(3) + e, (means - p[0:3]).T).T
        out: np.ndarray = (np.linalg.norm(f, axis=1) - g) / sigma
        return out

    sol = least_squares(resid, np.zeros(9), xtol=1e-14, ftol=1e-14, gtol=1e-14)
    return np.asarray(sol.x)


def _resid_rms(p: np.ndarray, means: np.ndarray, g: float) -> float:
    e = np.diag(p[3:6] * 1e-3)
    e[1, 0], e[2, 0], e[2, 1] = p[6:9] * 1e-3
    f = np.linalg.solve(np.eye(3) + e, (means - p[0:3]).T).T
    return float(np.sqrt(np.mean((np.linalg.norm(f, axis=1) - g) ** 2)))


def test_xsens_calibration_as_imu_tks_unweighted_cost(xsens: dict[str, Any]) -> None:
    """imu_tk's cost counts every pose alike (``MultiPosAccResidual``: ``g − |calib(a)|``,
    squared loss, no weights).  On this misfit sensor (reduced χ² ≈ 16 with the white-noise
    weights) thermocal inflates each pose's σ by the misfit, so its residual is within 1 %
    of the unweighted solution written here on the same poses (it was 9 % above with the
    white-noise weights, the long initial static pulling the fit) and its parameters within
    their stated σ of it."""
    s, counts = xsens["summary"], xsens["counts"]
    g = X_G_M_S2 / MG_M_S2
    means = np.array([(counts[p["start"] : p["end"]] - MID).mean(axis=0) * 0.27
                      for p in s["poses"]])  # fmt: skip
    ref = _tedaldi(means, g, np.ones(len(means)))
    assert s["gravity_residual_rms_after"] <= 1.01 * _resid_rms(ref, means, g)
    run = s["runs"][0]["accel"]
    assert run["reduced_chi2"] > 10 and run["misfit"] > 0
    a = s["accel"]
    names = a["misalignment_names"]
    idx = [names.index(n) for n in ("xy", "xz", "yz")]
    mine = np.concatenate([np.asarray(a["bias"]) - MID * 0.27, a["scale_factor_ppm"],
                           np.asarray(a["misalignment_arcsec"])[idx]])  # fmt: skip
    theirs = np.concatenate([ref[0:3], ref[3:6] * 1e3, ref[6:9] * 1e-3 * 206264.80624709636])
    sig = np.concatenate([a["bias_sigma"], a["scale_factor_ppm_sigma"],
                          np.asarray(a["misalignment_arcsec_sigma"])[idx]])  # fmt: skip
    z = (mine - theirs) / sig
    assert np.all(np.abs(z) < 1.0), z


# --- simulated hand-held sessions (multipos.simulate gives the truth) -------------------


def _write(path: Path, cols: dict[str, np.ndarray]) -> Path:
    import pandas as pd

    pd.DataFrame(cols).to_csv(path, index=False)
    return path


def _one_to_one(truth: list[tuple[int, int]], poses: list[dict[str, Any]]) -> bool:
    found = [(p["start"], p["end"]) for p in poses]
    return len(found) == len(truth) and all(
        sum(1 for a, b in found if a < t1 and t0 < b) == 1 for t0, t1 in truth
    )


def test_two_second_poses_same_for_a_low_noise_and_a_noisier_accelerometer(
    tmp_path: Path,
) -> None:
    """20 hand-held poses of 1.5–2.5 s (tremor 0.2°), the same motion read by a 0.3 mg and a
    5 mg accelerometer: both give the 20 poses of the truth.  With the still limit from the
    noise alone, the quiet one gave 9 (its tremor is many times its noise) and the noisy
    one 20."""
    from thermocal.multipos.simulate import simulate_session

    out = []
    for noise in (0.3, 5.0):
        s = simulate_session(np.random.default_rng(7), np.zeros(12), np.zeros(12), n_poses=20,
                             dwell_s=2.0, move_s=1.5, accel_noise_mg=noise,
                             tremor_deg=0.2)  # fmt: skip
        cols = {"time [s]": s["time_s"]}
        cols.update({f"acc_{a} [mg]": s["accel_mg"][:, k] for k, a in enumerate("xyz")})
        f = _write(tmp_path / f"n{noise}.csv", cols)
        code, o, err = _run(["multipos", str(f), "--accel", "acc_x [mg],acc_y [mg],acc_z [mg]",
                             "--gravity", "9.80665", "-o", str(tmp_path / f"n{noise}.json"),
                             "--json"])  # fmt: skip
        assert code == 0, err
        out.append(json.loads(o))
        assert _one_to_one(list(s["poses"]), out[-1]["poses"]), (noise, out[-1]["poses"])
    assert out[0]["n_poses"] == out[1]["n_poses"] == 20


@pytest.fixture(scope="module")
def clipped(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """A session read by a ±180 °/s gyro (int16 counts, 32767/180 LSB/(°/s)): its fastest
    moves clip on the rails; the clipped samples and motions are counted here."""
    from thermocal.multipos.simulate import simulate_session

    d = tmp_path_factory.mktemp("clipped")
    ta, tg = np.zeros(12), np.zeros(12)
    ta[3:6] = [3000.0, -2000.0, 1500.0]
    tg[0:3], tg[3:6] = [300.0, -500.0, 200.0], [20000.0, -15000.0, 10000.0]
    s = simulate_session(np.random.default_rng(11), ta, tg, n_poses=20, dwell_s=3.0,
                         move_s=1.0)  # fmt: skip
    lsb = 32767.0 / 180.0
    raw = np.round(s["gyro_deg_s"] * lsb)
    sat = (raw > 32767) | (raw < -32768)
    gc = np.clip(raw, -32768, 32767).astype(np.int64)
    ac = np.round(s["accel_mg"] * 16.384).astype(np.int64)
    cols: dict[str, np.ndarray] = {"time [s]": s["time_s"]}
    cols.update({f"a{a} [counts]": ac[:, k] for k, a in enumerate("xyz")})
    cols.update({f"g{a} [counts]": gc[:, k] for k, a in enumerate("xyz")})
    f = _write(d / "clipped.csv", cols)
    p = s["poses"]
    hit = [k for k in range(len(p) - 1) if sat[p[k][0] : p[k + 1][1]].any()]
    return {"file": f, "sat": sat, "hit": hit, "tg": tg, "poses": p, "dir": d,
            "scale": f"{1.0 / lsb!r},deg/s"}  # fmt: skip


def test_inspect_reports_the_samples_on_the_rails(clipped: dict[str, Any]) -> None:
    code, out, err = _run(["inspect", str(clipped["file"])])
    assert code == 0, err
    sat = clipped["sat"]
    for k, a in enumerate("xyz"):
        n = int(sat[:, k].sum())
        if n:
            first = int(np.argmax(sat[:, k]))
            assert f"column 'g{a} [counts]' has {n} samples on its rails" in out + err
            assert f"first at row {first}" in out + err
    assert int(sat[:, 1].sum()) > 0 and int(sat[:, 2].sum()) > 0


def test_clipped_motions_named_and_kept_out_of_the_gyro_fit(clipped: dict[str, Any]) -> None:
    """4 of the 19 motions clip: they are named in a warning and left out, so the gyro scale
    factors are the truth within 4σ (with them in: −33 400 ± 8 600 ppm for a true −15 000)."""
    assert len(clipped["hit"]) == 4
    code, out, err = _run(["multipos", str(clipped["file"]), "--accel", _cols("ax,ay,az"),
                           "--gyro", _cols("gx,gy,gz"), "--accel-scale", "0.06103515625,mg",
                           "--gyro-scale", clipped["scale"], "--latitude", "45",
                           "-o", str(clipped["dir"] / "cal.json"), "--json"])  # fmt: skip
    assert code == 0, err
    s = json.loads(out)
    assert _one_to_one(list(clipped["poses"]), s["poses"])
    names = [f"pose_{k + 1} → pose_{k + 2}" for k in clipped["hit"]]
    assert f"during {len(names)} motion(s): " in err and all(n in err for n in names), err
    g = s["gyro"]
    z = (np.asarray(g["scale_factor_ppm"]) - clipped["tg"][3:6]) / np.asarray(
        g["scale_factor_ppm_sigma"]
    )
    assert np.all(np.abs(z) < 4.0), z
    assert max(g["scale_factor_ppm_sigma"]) < 500.0


def test_a_slow_turn_is_rejected_as_moving() -> None:
    """Eight 3 s rests between 1 s shaken moves (2 mg noise); the fifth rest turns slowly by
    10° (its window variance stays at the noise): rejected as *moving*, the gravity
    direction turning (10°)·(2/3) ≈ 6.7° between the means of its first and last thirds
    (their centres are 2 s apart; the means average over a third each: 5–7°), and the
    other seven found."""
    from scipy.spatial.transform import Rotation

    from thermocal.multipos.poses import find_poses

    rng = np.random.default_rng(5)
    cur = np.array([0.0, 0.0, 1000.0])
    dirs = [Rotation.from_rotvec(v).apply(cur) for v in rng.normal(0, 1.2, (8, 3))]
    segs, truth, n = [], [], 0
    for k, d in enumerate(dirs):
        s = np.linspace(0, 1, 100)[:, None]
        segs.append(cur + (d - cur) * (0.5 - 0.5 * np.cos(np.pi * s)) + rng.normal(0, 60, (100, 3)))
        n += 100
        if k == 4:
            ax = np.cross(d, [1.0, 0.0, 0.0])
            ax /= np.linalg.norm(ax)
            rest = np.array([Rotation.from_rotvec(ax * a).apply(d)
                             for a in np.linspace(0, np.radians(10.0), 300)])  # fmt: skip
        else:
            rest = np.tile(d, (300, 1))
        cur = rest[-1]
        truth.append((n, n + 300))
        segs.append(rest + rng.normal(0, 2.0, rest.shape))
        n += 300
    acc = np.vstack(segs)
    det = find_poses(np.arange(n) / 100.0, acc)
    assert len(det.poses) == 7
    assert len(det.rejected) == 1
    r = det.rejected[0]
    assert truth[4][0] <= r.start < r.end <= truth[4][1]
    assert r.reason.startswith("moving: the gravity direction turns ")
    turned = float(r.reason.split("turns ")[1].split("°")[0])
    assert 5.0 < turned < 7.0
    kept = [t for k, t in enumerate(truth) if k != 4]
    assert all(sum(1 for p in det.poses if p.start < b and a < p.end) == 1 for a, b in kept)


def test_tremor_rejections_explained_and_motion_fraction_takes_them(tmp_path: Path) -> None:
    """20 poses held with a heavy tremor (0.2° at 6 Hz: ≈ 5 °/s rms on the gyro, beyond a
    hundredth of the motions' variance): 13 are still for both sensors and 7 are reported
    rejected for the gyro's tremor, naming the option; with ``--motion-fraction 0.03`` all
    20 of the truth are poses."""
    from thermocal.multipos.simulate import simulate_session

    s = simulate_session(np.random.default_rng(7), np.zeros(12), np.zeros(12), n_poses=20,
                         dwell_s=2.0, move_s=1.5, accel_noise_mg=0.3,
                         tremor_deg=0.2)  # fmt: skip
    cols = {"time [s]": s["time_s"]}
    cols.update({f"acc_{a} [mg]": s["accel_mg"][:, k] for k, a in enumerate("xyz")})
    cols.update({f"gyr_{a} [deg/s]": s["gyro_deg_s"][:, k] for k, a in enumerate("xyz")})
    f = _write(tmp_path / "tremor.csv", cols)
    base = ["multipos", str(f), "--accel", "acc_x [mg],acc_y [mg],acc_z [mg]", "--gyro",
            "gyr_x [deg/s],gyr_y [deg/s],gyr_z [deg/s]", "--latitude", "45"]  # fmt: skip
    code, out, err = _run([*base, "-o", str(tmp_path / "a.json"), "--json"])
    assert code == 0, err
    det = json.loads(out)["pose_detection"][0]
    assert det["n_poses"] == 13
    tremor = [r for r in det["rejected"] if r["reason"].startswith("tremor: the gyro's variance")]
    assert len(tremor) == 7 and len(det["rejected"]) == 7
    assert all("raise --motion-fraction" in r["reason"] for r in tremor)
    truth = list(s["poses"])
    found = [(p["start"], p["end"]) for p in json.loads(out)["poses"]]
    found += [(r["start"], r["end"]) for r in tremor]
    assert all(sum(1 for a, b in found if a < t1 and t0 < b) == 1 for t0, t1 in truth)
    code, out, err = _run([*base, "-o", str(tmp_path / "b.json"), "--motion-fraction", "0.03"])
    assert code == 0, err
    assert "20 poses (window 0.5 s" in out and "0 rejected" in out


def test_unsigned_offset_counts_give_the_truth_with_the_offset_in_the_bias(
    tmp_path: Path,
) -> None:
    """A simulated session stored as unsigned 16-bit counts around 32768 (±2 g at 16384
    LSB/g, ±250 °/s at 131 LSB/(°/s)): with ``--accel-offset``/``--gyro-offset 32768`` the
    biases are the truth plus the offset (in the scale's unit) within 4σ, the scale factors
    the truth within 4σ, and ``thermocal compensate`` with the calibration gives gravity's
    magnitude at every pose; with a zero of 0, exit 2 naming ``--accel-offset``; without
    one, mid-scale taken with a warning."""
    import pandas as pd

    from thermocal.multipos.simulate import simulate_session

    ta, tg = np.zeros(12), np.zeros(12)
    ta[0:3], ta[3:6] = [25.0, -40.0, 10.0], [4000.0, -2500.0, 1500.0]
    tg[0:3] = [400.0, -600.0, 250.0]
    s = simulate_session(np.random.default_rng(38), ta, tg, n_poses=16)
    ac = np.round(s["accel_mg"] * 16.384) + MID
    gc = np.round(s["gyro_deg_s"] * 131.0) + MID
    assert ac.min() >= 0 and gc.min() >= 0 and max(ac.max(), gc.max()) <= 65535
    cols: dict[str, np.ndarray] = {"time [s]": s["time_s"]}
    cols.update({f"a{a} [counts]": ac[:, k].astype(np.int64) for k, a in enumerate("xyz")})
    cols.update({f"g{a} [counts]": gc[:, k].astype(np.int64) for k, a in enumerate("xyz")})
    f = _write(tmp_path / "u16.csv", cols)
    acc_lsb, gyr_lsb = 1000.0 / 16384.0, 1.0 / 131.0
    base = ["multipos", str(f), "--accel", _cols("ax,ay,az"), "--gyro", _cols("gx,gy,gz"),
            "--accel-scale", f"{acc_lsb!r},mg", "--gyro-scale", f"{gyr_lsb!r},deg/s",
            "--latitude", "45"]  # fmt: skip
    code, _o, err = _run([*base, "--accel-offset", "0", "--gyro-offset", "0",
                          "-o", str(tmp_path / "no.json")])  # fmt: skip
    assert code == 2 and "--accel-offset" in err, err
    code, _o, err = _run([*base, "-o", str(tmp_path / "auto.json")])
    assert code == 0 and "32768 taken as their zero; give --accel-offset" in err, err
    code, out, err = _run([*base, "--accel-offset", "32768", "--gyro-offset", "32768",
                           "-o", str(tmp_path / "cal.json"), "--json"])  # fmt: skip
    assert code == 0, err
    r = json.loads(out)
    a, g = r["accel"], r["gyro"]
    want_b = ta[0:3] + MID * acc_lsb
    assert np.all(np.abs((np.asarray(a["bias"]) - want_b) / np.asarray(a["bias_sigma"])) < 4)
    z = (np.asarray(a["scale_factor_ppm"]) - ta[3:6]) / np.asarray(a["scale_factor_ppm_sigma"])
    assert np.all(np.abs(z) < 4), z
    want_g = tg[0:3] / 3600.0 + MID * gyr_lsb  # °/h → °/s
    assert np.all(np.abs((np.asarray(g["bias"]) - want_g) / np.asarray(g["bias_sigma"])) < 4)
    comp = tmp_path / "comp.csv"
    code, _o, err = _run(["compensate", str(tmp_path / "cal.json"), str(f), "-o", str(comp)])
    assert code == 0, err
    fc = pd.read_csv(comp)[[f"a{a} [counts]_comp" for a in "xyz"]].to_numpy()
    g_mg = s["g_m_s2"] / MG_M_S2
    mags = [np.linalg.norm(fc[p0 + 30 : p1 - 30].mean(axis=0)) for p0, p1 in s["poses"]]
    assert np.max(np.abs(np.asarray(mags) - g_mg)) < 1.0  # mg


def test_too_few_motions_rule() -> None:
    """The rule behind the warning (:func:`thermocal.multipos.gyro.too_few_motions`): a
    redundancy below the elements fitted AND a reduced χ² above ``1 + 3√(2/ν)``."""
    from thermocal.multipos.gyro import GyroFit, too_few_motions

    def fit(n_motions: int, chi2: float, model: str = "full") -> GyroFit:
        z = np.zeros(12)
        return GyroFit(z, np.zeros((12, 12)), 0.0, 0.0, chi2, n_motions, 0, 0.0, model)

    limit3 = 1.0 + 3.0 * np.sqrt(2.0 / 3.0)  # 3.449 for ν = 2·6 − 9 = 3
    assert fit(6, 704.0).dof == 3 and too_few_motions(fit(6, 704.0))
    assert too_few_motions(fit(6, limit3 * 1.01)) and not too_few_motions(fit(6, limit3 * 0.99))
    assert fit(9, 704.0).dof == 9 and not too_few_motions(fit(9, 704.0))  # ν = 9: enough
    assert fit(6, 794.0, "scale").dof == 9 and not too_few_motions(fit(6, 794.0, "scale"))
    assert too_few_motions(fit(4, 1.0))  # ν = −1: nothing left to judge the fit
