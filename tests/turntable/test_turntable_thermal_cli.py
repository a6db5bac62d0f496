"""Both triads over temperature end to end (issue 19): ``thermocal simulate
turntable-thermal`` runs at six soaks (−40…+60 °C, each drifting 1.5 °C during the run),
``thermocal turntable … --temps T_imu --accel …`` → a calibration of triads, ``thermocal
compensate`` on the held-out run at +10 °C.

Judged against what the true parameters give on the same held-out data (the test rebuilds
the true body rate and specific force from the encoder angles, as the simulator does):
dwell-mean gyro errors and move-angle errors within 1.5× of the true parameters', the
accelerometer dwell errors within 0.02 mg; a bias-only temperature model and the
single-temperature calibration of the +20 °C run are shown to do much worse (numbers in
the assertion messages)."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.readers.dispatch import read_recording
from thermocal.turntable.calibration import calibrate
from thermocal.turntable.schedule import detect_motion, segment
from thermocal.turntable.simulate import (
    ACCEL_THERMAL_TRUTH,
    GYRO_THERMAL_TRUTH,
    simulate_turntable_thermal,
    thermal_theta,
)
from thermocal.writers import write_recording

G_COLS = ["gyro_x", "gyro_y", "gyro_z"]
A_COLS = ["accel_x", "accel_y", "accel_z"]
MG = 9.80665e-3
ARCSEC = np.pi / 180 / 3600
EARTH_RATE_RAD_S = 7.292115e-5  # WGS-84 Ω


# --- the reference, from first principles (not the package's kinematics) ---------------------
# Base frame ENU; body axes at α = β = 0: x East, y Down, z North (SPEC §7).  The inner axis
# turns the body about its own z by α, the outer axis turns the inner gimbal about base East
# by β, so body → base is C_b^n = R_E(β) · C_0 · R_z(α), with right-handed rotations.


def _rot_x(t: np.ndarray) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    out = np.zeros((t.size, 3, 3))
    out[:, 0, 0] = 1.0
    out[:, 1, 1], out[:, 1, 2], out[:, 2, 1], out[:, 2, 2] = c, -s, s, c
    return out


def _rot_z(t: np.ndarray) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    out = np.zeros((t.size, 3, 3))
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
    out[:, 2, 2] = 1.0
    return out


C_0 = np.column_stack([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
"""Columns: body x, y, z in ENU at α = β = 0 (East, Down, North)."""


def _c_nb(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Base → body, C_n^b = (R_E(β) C_0 R_z(α))ᵀ, per sample."""
    return np.transpose(_rot_x(b) @ C_0 @ _rot_z(a), (0, 2, 1))


def _reference(a: np.ndarray, b: np.ndarray, lat_deg: float, g: float, tau: float) -> tuple:
    """(ω_ib^b [rad/s] over each interval, specific force at rest f^b [m/s²]): the earth rate
    Ω (0, cos L, sin L) in ENU and the outer rate β̇ about East seen in the body, plus the
    inner rate α̇ about body z (at the interval's mid angles); gravity's reaction (0, 0, g)
    up in ENU seen in the body."""
    a_prev, b_prev = np.concatenate([[a[0]], a[:-1]]), np.concatenate([[b[0]], b[:-1]])
    lat = np.deg2rad(lat_deg)
    w_ie = EARTH_RATE_RAD_S * np.array([0.0, np.cos(lat), np.sin(lat)])
    c_mid = _c_nb(0.5 * (a + a_prev), 0.5 * (b + b_prev))
    a_dot, b_dot = (a - a_prev) / tau, (b - b_prev) / tau
    in_base = w_ie[None, :] + b_dot[:, None] * np.array([1.0, 0.0, 0.0])
    omega = np.einsum("nij,nj->ni", c_mid, in_base) + a_dot[:, None] * np.array([0.0, 0.0, 1.0])
    f_true = np.einsum("nij,j->ni", _c_nb(a, b), np.array([0.0, 0.0, g]))
    return omega, f_true


def _write_runs(runs: list, folder: Path) -> tuple[list[str], Path]:
    """The simulated runs as Parquet files: (the soaks' paths, the held-out run's path)."""
    soaks, held = [], None
    for rec, truth in runs:
        f = folder / f"{truth['label']}.parquet"
        write_recording(rec, f)
        if truth["held_out"]:
            held = f
        else:
            soaks.append(str(f))
    assert held is not None
    return soaks, held


@pytest.fixture(scope="module")
def workflow(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    d = tmp_path_factory.mktemp("thermal")
    runs = simulate_turntable_thermal(seed=5)
    soaks, held = _write_runs(runs, d)
    cal = d / "cal.json"
    code = main(["turntable", *soaks, "--temps", "T_imu", "--accel", ",".join(A_COLS),
                 "-o", str(cal), "--json"])  # fmt: skip
    assert code == 0
    comp = d / "comp.parquet"
    assert main(["compensate", str(cal), str(held), "-o", str(comp)]) == 0
    # the +20 °C run calibrated alone: the single-temperature calibration
    one = calibrate(
        read_recording(d / "T+20.parquet"), accel_columns=A_COLS, temperature_column="T_imu"
    )
    return {"cal": cal, "held": held, "comp": comp, "one": one, "dir": d}


def _truth_frame(held: Path) -> tuple[pd.DataFrame, np.ndarray, np.ndarray, list, float]:
    rec = read_recording(held)
    t = rec.time_s
    a = np.deg2rad(np.unwrap(rec.column("alpha_deg"), period=360.0))
    b = np.deg2rad(np.unwrap(rec.column("beta_deg"), period=360.0))
    tau = float(np.median(np.diff(t)))
    lat = float(rec.meta.latitude_deg or 40.0)
    from thermocal import units

    g = units.normal_gravity_m_s2(lat)
    omega, f_true = _reference(a, b, lat, g, tau)
    a_deg, b_deg = np.rad2deg(a), np.rad2deg(b)
    motion = detect_motion(t, a_deg, b_deg)
    seg = segment(t, a_deg, b_deg, motion.moving, np.ones(t.size - 1, dtype=bool))
    return rec, omega, f_true, list(seg.dwells), tau


def _true_params_correction(
    rec: object, spec: dict, cols: list[str], bias_to_data: float
) -> np.ndarray:
    """(I + E_true(T))⁻¹ (x − b_true(T)) with the simulator's own polynomials."""
    temp = rec.temperature_c("T_imu")  # type: ignore[attr-defined]
    th = thermal_theta(spec, temp)
    b = th[:, 0:3]
    e = np.zeros((th.shape[0], 3, 3))
    for i in range(3):
        e[:, i, i] = th[:, 3 + i] * 1e-6
    for k, (r, c) in enumerate([(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)]):
        e[:, r, c] = th[:, 6 + k] * ARCSEC
    x = np.column_stack([rec.column(c) for c in cols])  # type: ignore[attr-defined]
    out = np.linalg.solve(np.eye(3) + e, (x - b * bias_to_data)[..., None])[..., 0]
    return np.asarray(out)


def _dwell_rms(x: np.ndarray, ref: np.ndarray, dwells: list) -> float:
    errs = [x[1:][d.start : d.stop].mean(axis=0) - ref[1:][d.start : d.stop].mean(axis=0)
            for d in dwells]  # fmt: skip
    return float(np.sqrt(np.mean(np.square(errs))))


def _move_rms(x: np.ndarray, ref: np.ndarray, dwells: list, tau: float) -> float:
    """Angle error accumulated over each move between dwells [rad]."""
    errs = []
    for d0, d1 in itertools.pairwise(dwells):
        sl = slice(d0.stop, d1.start)
        errs.append(((x[1:][sl] - ref[1:][sl]) * tau).sum(axis=0))
    return float(np.sqrt(np.mean(np.square(errs))))


def test_the_calibration_and_its_json(workflow: dict) -> None:
    cal = json.loads(Path(workflow["cal"]).read_text())  # type: ignore[arg-type]
    assert [t["name"] for t in cal["triads"]] == ["gyro", "accel"]
    assert cal["channels"] == []


def test_held_out_run_compensated_as_well_as_the_true_parameters(workflow: dict) -> None:
    from thermocal import units

    rec, omega, f_true, dwells, tau = _truth_frame(workflow["held"])  # type: ignore[arg-type]
    comp = pd.read_parquet(workflow["comp"])
    deg_s = units.RAD_TO_DEG
    ours_g = comp[[f"{c}_comp" for c in G_COLS]].to_numpy() / deg_s  # rad/s
    true_g = _true_params_correction(rec, GYRO_THERMAL_TRUTH, G_COLS, 1 / 3600.0) / deg_s
    raw_g = np.column_stack([rec.column(c) for c in G_COLS]) / deg_s
    dwell_ours = _dwell_rms(ours_g, omega, dwells)
    dwell_true = _dwell_rms(true_g, omega, dwells)
    move_ours = _move_rms(ours_g, omega, dwells, tau)
    move_true = _move_rms(true_g, omega, dwells, tau)
    to_dh = float(np.rad2deg(1.0)) * 3600.0
    move_raw = _move_rms(raw_g, omega, dwells, tau)
    msg = (
        f"gyro dwell rms ours {dwell_ours * to_dh:.3g} °/h vs true params "
        f"{dwell_true * to_dh:.3g}; move rms ours {move_ours / ARCSEC:.3g}″ vs "
        f"{move_true / ARCSEC:.3g}″, raw {move_raw / ARCSEC:.3g}″"
    )
    assert dwell_ours <= 1.5 * dwell_true, msg
    assert move_ours <= 1.5 * move_true, msg
    ours_a = comp[[f"{c}_comp" for c in A_COLS]].to_numpy()
    acc_err_mg = _dwell_rms(ours_a, f_true, dwells) / MG
    assert acc_err_mg < 0.02, f"accelerometer dwell rms {acc_err_mg:.4g} mg"


def test_bias_only_and_single_temperature_do_much_worse(workflow: dict) -> None:
    rec, _omega, f_true, dwells, _tau = _truth_frame(workflow["held"])  # type: ignore[arg-type]
    comp = pd.read_parquet(workflow["comp"])
    temp = rec.temperature_c("T_imu")
    raw_a = np.column_stack([rec.column(c) for c in A_COLS])
    ours = _dwell_rms(comp[[f"{c}_comp" for c in A_COLS]].to_numpy(), f_true, dwells) / MG
    # bias-only: the calibrated bias polynomials, no scale factor or misalignment
    from thermocal.pipeline.model_file import load_calibration

    tri = load_calibration(workflow["cal"]).triads[1].model  # type: ignore[arg-type]
    bias_only = raw_a - tri.theta_at(temp)[:, 0:3] * MG
    bias_only_mg = _dwell_rms(bias_only, f_true, dwells) / MG
    # single temperature: the +20 °C run's constant parameters at every sample
    one = workflow["one"]
    e = np.eye(3) + one.accel.error_matrix  # type: ignore[attr-defined]
    single = np.linalg.solve(e, (raw_a - one.accel.bias_m_s2).T).T  # type: ignore[attr-defined]
    single_mg = _dwell_rms(single, f_true, dwells) / MG
    msg = (
        f"accelerometer dwell rms: ours {ours:.3g} mg, bias-only {bias_only_mg:.3g} mg, "
        f"single temperature {single_mg:.3g} mg"
    )
    assert bias_only_mg > 10 * ours, msg
    assert single_mg > 10 * ours, msg


def test_a_soak_that_missed_a_position(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The 0 °C run holds 15 of the 16 positions: it is used, the warning says so, and the
    held-out run is still compensated to the accelerometer target."""
    runs = simulate_turntable_thermal(seed=6, drop_position=("T+0", 5))
    soaks, held = _write_runs(runs, tmp_path)
    cal = tmp_path / "cal.json"
    code = main(["turntable", *soaks, "--temps", "T_imu", "--accel", ",".join(A_COLS),
                 "-o", str(cal)])  # fmt: skip
    assert code == 0
    err = capsys.readouterr().err
    assert "T+0" in err and "15 positions held" in err
    comp = tmp_path / "comp.parquet"
    assert main(["compensate", str(cal), str(held), "-o", str(comp)]) == 0
    _rec, _omega, f_true, dwells, _tau = _truth_frame(held)
    ours = pd.read_parquet(comp)[[f"{c}_comp" for c in A_COLS]].to_numpy()
    assert _dwell_rms(ours, f_true, dwells) / MG < 0.02


def test_validate_judges_the_held_out_run(
    workflow: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["validate", str(workflow["cal"]), str(workflow["held"]), "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    acc, gyro = out["triads"]["accel"], out["triads"]["gyro"]
    assert acc["unit"] == "mg" and max(acc["dwell_rms_after"]) < 0.02
    assert min(acc["dwell_rms_before"]) > 20 * max(acc["dwell_rms_after"])
    assert max(gyro["move_angle_rms_after_arcsec"]) < min(gyro["move_angle_rms_before_arcsec"]) / 5
    # the same figures the test computes itself on the compensated file
    _rec, _omega, f_true, dwells, _tau = _truth_frame(workflow["held"])  # type: ignore[arg-type]
    comp = pd.read_parquet(workflow["comp"])
    mine = [
        _dwell_rms(comp[[f"{c}_comp" for c in A_COLS]].to_numpy()[:, [k]], f_true[:, [k]], dwells)
        / MG
        for k in range(3)
    ]
    np.testing.assert_allclose(acc["dwell_rms_after"], mine, rtol=1e-6)


def test_the_report_shows_every_parameter_and_the_held_out_run(workflow: dict) -> None:
    out = Path(workflow["dir"]) / "report.html"  # type: ignore[arg-type]
    code = main(["report", "--model", str(workflow["cal"]), "--recording", str(workflow["held"]),
                 "-o", str(out)])  # fmt: skip
    assert code == 0
    html = out.read_text(encoding="utf-8")
    assert html.count('class="figure"') == 2  # one figure per triad
    for name in ("bias_x", "scale_factor_z", "misalignment_yz", "move-angle error rms"):
        assert name in html
    assert 'id="triad-gyro"' in html and 'id="triad-accel"' in html


def test_encoder_jitter_in_every_run(tmp_path: Path) -> None:
    """Encoders read with 3″ of white jitter in every run (soaks and held-out): the
    calibration still compensates the held-out accelerometers to the target."""
    runs = simulate_turntable_thermal(seed=8, encoder_noise_arcsec=3.0)
    soaks, held = _write_runs(runs, tmp_path)
    cal = tmp_path / "cal.json"
    assert main(["turntable", *soaks, "--temps", "T_imu", "--accel", ",".join(A_COLS),
                 "-o", str(cal)]) == 0  # fmt: skip
    comp = tmp_path / "comp.parquet"
    assert main(["compensate", str(cal), str(held), "-o", str(comp)]) == 0
    rec = read_recording(held)
    a = np.deg2rad(np.unwrap(rec.column("alpha_deg"), period=360.0))
    b = np.deg2rad(np.unwrap(rec.column("beta_deg"), period=360.0))
    _r, _o, _f, dwells, _t = _truth_frame(held)
    from thermocal import units

    g = units.normal_gravity_m_s2(40.0)
    _omega, f_true = _reference(a, b, 40.0, g, _t)
    ours = pd.read_parquet(comp)[[f"{c}_comp" for c in A_COLS]].to_numpy()
    assert _dwell_rms(ours, f_true, dwells) / MG < 0.02


def test_a_logger_csv_chain_without_repeating_options(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Runs written the way a lab logger writes them: CSV with a banner line, time in ms,
    units only in the column names (gyro in °/h, accelerometers in mg), other column names,
    a gap in the held-out run.  turntable names the columns once; compensate, validate and
    report then need only the calibration (encoders, latitude, units travel with it)."""
    mg = 9.80665e-3
    names = {}
    for rec, truth in simulate_turntable_thermal(seed=3):
        df = pd.DataFrame(
            {
                "t [ms]": rec.time_s * 1000.0,
                **{f"g{a} [deg/h]": rec.column(f"gyro_{a}") * 3600.0 for a in "xyz"},
                **{f"a{a} [mg]": rec.column(f"accel_{a}") / mg for a in "xyz"},
                "enc_in [deg]": rec.column("alpha_deg"),
                "enc_out [deg]": rec.column("beta_deg"),
                "T_imu [degC]": rec.column("T_imu"),
            }
        )
        if truth["held_out"]:
            df = df.drop(index=range(3000, 3040))  # a gap
        f = tmp_path / f"{truth['label']}.csv"
        with open(f, "w", encoding="utf-8") as fh:
            fh.write("# IMU logger v2.3, unit 0042\n")
            df.to_csv(fh, index=False, float_format="%.12g")
        names[truth["label"]] = f
    soaks = [str(f) for lab, f in names.items() if not lab.startswith("heldout")]
    cal = tmp_path / "cal.json"
    code = main(["turntable", *soaks, "--time", "t [ms]",
                 "--gyro", "gx [deg/h],gy [deg/h],gz [deg/h]",
                 "--accel", "ax [mg],ay [mg],az [mg]", "--alpha", "enc_in [deg]",
                 "--beta", "enc_out [deg]", "--temps", "T_imu [degC]", "--latitude", "40",
                 "-o", str(cal), "--json"])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    out = json.loads(capsys.readouterr().out)
    # the −40 °C run's accelerometer biases against the simulator's truth there [mg]
    true_acc = thermal_theta(ACCEL_THERMAL_TRUTH, out["runs"][0]["temperature_c"])
    np.testing.assert_allclose(out["runs"][0]["accel"]["bias_mg"], true_acc[0:3], atol=0.03)
    held = str(names["heldout_T+10"])
    comp = tmp_path / "comp.csv"
    assert main(["compensate", str(cal), held, "-o", str(comp)]) == 0
    capsys.readouterr()
    assert main(["validate", str(cal), held, "--json"]) == 0
    val = json.loads(capsys.readouterr().out)["triads"]
    assert val["accel"]["unit"] == "mg" and max(val["accel"]["dwell_rms_after"]) < 0.02
    assert max(val["gyro"]["move_angle_rms_after_arcsec"]) < 5.0
    # the compensated columns in the data's units: az at +1 g where the raw read ≈ 1 g + bias
    df = pd.read_csv(comp)
    assert df["az [mg]_comp"].abs().max() == pytest.approx(1000.0 * 9.80169 / 9.80665, rel=1e-3)
