"""The gyro's g-sensitivity on the dual-axis turntable (``turntable.gsens``): the simulator's
A recovered within its σ over seeds, the rotations' estimate kept unbiased by taking A's
drift off the moves, a schedule whose gravity never leaves one axis stated "not estimated",
and the command's JSON and text line."""

from __future__ import annotations

import contextlib
import io
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.turntable import calibrate, simulate_turntable16
from thermocal.turntable.schedule import TurntableWarning
from thermocal.writers import write_recording

# a tactical gyro's acceleration-sensitive drift [°/h per g]: row gyro axis, column force axis
A_TRUE = np.array([[0.30, -0.12, 0.05], [0.08, -0.25, 0.15], [-0.04, 0.10, 0.40]])
VERTICAL = tuple(
    (a, b)
    for k, a in enumerate((0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0))
    for b in ((90.0, 270.0) if k % 2 == 0 else (270.0, 90.0))
)
"""Sixteen positions with the inner axis (body z) vertical: the outer axis only at 90° and
270°, the inner one at eight headings; gravity is ±z at every dwell."""


def _theta(truth: dict) -> np.ndarray:
    return np.array(
        [*truth["bias_deg_h"], *truth["scale_factor_ppm"], *truth["misalignment_arcsec"]]
    )


def test_the_simulators_sensitivity_is_recovered_within_its_sigma() -> None:
    """Sixteen positions at 20 Hz with a known A up to 0.4 °/h/g (σ ≈ 0.012 °/h/g): over 12
    seeds every element within 3σ and about 95 % within 1.96σ (binomial band for 108
    draws); σ as the white noise of the dwell means says."""
    n_rad = 0.003 * math.pi / 180.0 / 60.0  # the simulator's 0.003 °/√h in rad/√s
    per_dwell = n_rad / math.sqrt(60.0) * 180.0 / math.pi * 3600.0  # a 60 s mean's σ [°/h]
    z = []
    for seed in range(12):
        rec, _truth = simulate_turntable16(seed, rate_hz=20.0, g_sensitivity_deg_h_g=A_TRUE)
        gs = calibrate(rec, 40.0).g_sensitivity
        assert gs is not None and gs.n_poses == 16 and gs.dof == 12
        z.append(((gs.matrix_deg_h_g - A_TRUE) / gs.sigma_deg_h_g).ravel())
        # x up at 2 dwells, down at 2: σ of the half difference is per_dwell / 2 (the ARW
        # found in the dwells: ±5 %), more only when an axis's χ² is significant
        assert np.all(gs.sigma_deg_h_g[:, 0] >= 0.95 * per_dwell / 2.0)
        assert np.all(gs.sigma_deg_h_g <= 1.8 * per_dwell / 2.0)
    za = np.abs(np.array(z))
    assert np.all(za < 3.0), za.max()
    inside = float(np.mean(za < 1.96))
    assert 0.88 <= inside <= 1.0, inside


def test_taking_its_drift_off_the_moves_keeps_the_rotations_unbiased() -> None:
    """With A the gyro drifts by A·f(t) along every move: the bias, scale factors and
    misalignments stay within 3.5σ of the truth and the residuals at the white-noise level
    (χ²/dof < 1.3; ≈ 8 when the drift is left in: misalignment xz 4–6σ off)."""
    for seed in range(3):
        rec, truth = simulate_turntable16(seed, rate_hz=20.0, g_sensitivity_deg_h_g=A_TRUE)
        res = calibrate(rec, 40.0)
        assert res.g_sensitivity_subtracted
        z = (res.kalman.theta - _theta(truth)) / res.kalman.sigma
        assert np.all(np.abs(z) < 3.5), z
        assert res.chi2_per_dof < 1.3


def test_without_a_sensitivity_nothing_is_subtracted_and_nothing_changes() -> None:
    """A = 0: none beyond 3σ (for these seeds), the run estimated once, as before."""
    rec, _truth = simulate_turntable16(0, rate_hz=20.0)
    res = calibrate(rec, 40.0)
    assert res.g_sensitivity is not None and not res.g_sensitivity_subtracted
    assert not np.any(res.g_sensitivity.significant)


def test_gravity_along_one_axis_only_is_stated_not_estimated() -> None:
    """The inner axis vertical at every dwell: gravity is ±z, A's x and y columns unseen;
    the calibration goes on, A is None and the note names the direction and the remedy."""
    rec, _truth = simulate_turntable16(0, rate_hz=20.0, positions_deg=VERTICAL,
                                       g_sensitivity_deg_h_g=A_TRUE)  # fmt: skip
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always", TurntableWarning)  # the drift left in: residuals
        res = calibrate(rec, 40.0)
    assert res.g_sensitivity is None and not res.g_sensitivity_subtracted
    note = res.g_sensitivity_note or ""
    assert "not separable from these 16 dwells" in note
    assert "every gravity direction along (+0.00, +0.00, +1.00)" in note
    assert "outer axis at 0°, 90°, 180° and 270°" in note
    out = res.to_dict()
    assert out["g_sensitivity"] is None and out["g_sensitivity_note"] == note


def test_the_command_prints_and_writes_it(tmp_path: Path) -> None:
    rec, _truth = simulate_turntable16(1, rate_hz=20.0, g_sensitivity_deg_h_g=A_TRUE)
    path = tmp_path / "run.csv"
    write_recording(rec, path)
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["turntable", str(path), "-o", str(tmp_path / "r.json"), "--latitude", "40"])
    assert code == 0
    text = buf.getvalue()
    assert "gyro g-sensitivity from 16 dwells [deg/h/g, gyro/force axis]: x/x " in text
    assert "taken off the rotations before the fit" in text
    saved = json.loads((tmp_path / "r.json").read_text())
    gs = saved["g_sensitivity"]
    assert gs["unit"] == "deg/h/g" and saved["g_sensitivity_subtracted"] is True
    err = (np.array(gs["matrix"]) - A_TRUE) / np.array(gs["matrix_sigma"])
    assert np.all(np.abs(err) < 3.5)


@pytest.mark.parametrize("column", [0, 1, 2])
def test_a_single_column_is_the_half_difference_of_opposite_dwells(column: int) -> None:
    """Noise-free (ARW 1e-9 °/√h) with one column of A set, the others 0: recovered to
    2e-4 °/h/g (the earth rate through the scale factors and misalignments taken off), the
    other columns 0 (no leak between the force's axes)."""
    a = np.zeros((3, 3))
    a[:, column] = (0.5, -0.2, 0.3)
    rec, _truth = simulate_turntable16(0, rate_hz=5.0, dwell_s=20.0, arw_deg_sqrt_h=1e-9,
                                       g_sensitivity_deg_h_g=a)  # fmt: skip
    res = calibrate(rec, 40.0, min_dwell_s=10.0, arw_deg_sqrt_h=0.003)
    gs = res.g_sensitivity
    assert gs is not None
    np.testing.assert_allclose(gs.matrix_deg_h_g, a, atol=2e-4)


def test_soaks_pool_into_one_matrix_weighted_by_their_variances() -> None:
    """Two runs' estimates and one not estimated: each element the inverse-variance mean
    (computed here), σ widened by the scatter when it is beyond the σ."""
    from thermocal.multipos.gsens import GSensitivity
    from thermocal.turntable.gsens import pooled_g_sensitivity

    def est(a: np.ndarray, s: float) -> GSensitivity:
        z3 = np.zeros(3)
        return GSensitivity(a, np.full((3, 3), s), z3, z3, 12, 16, 2.0)

    a1, a2 = A_TRUE, A_TRUE + 0.01
    got = pooled_g_sensitivity([est(a1, 0.01), None, est(a2, 0.02)])
    assert got is not None
    w1, w2 = 1 / 0.01**2, 1 / 0.02**2
    mean = (w1 * a1 + w2 * a2) / (w1 + w2)
    np.testing.assert_allclose(got[0], mean, rtol=1e-12)
    chi = w1 * (a1 - mean) ** 2 + w2 * (a2 - mean) ** 2  # one degree of freedom
    np.testing.assert_allclose(got[1], np.sqrt(np.maximum(chi, 1.0) / (w1 + w2)), rtol=1e-12)
    far = pooled_g_sensitivity([est(a1, 0.01), est(a1 + 0.1, 0.01)])
    assert far is not None and np.all(far[1] > 0.04)  # 10 σ apart: the scatter counts
    assert pooled_g_sensitivity([None]) is None


def test_an_isotropic_sensitivity_is_reported_not_subtracted() -> None:
    """A = c·I reads c·(g/g₀) along up, as a vertical earth rate off by c would (a latitude
    of the wrong sign, refused by the residual check): reported with c within 3σ of the
    truth, not taken off the moves, the note saying why and the text line showing it."""
    from thermocal.report.triad_text import turntable_g_sensitivity_line

    rec, _truth = simulate_turntable16(0, rate_hz=20.0, g_sensitivity_deg_h_g=0.3 * np.eye(3))
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always", TurntableWarning)  # the drift left in: residuals
        res = calibrate(rec, 40.0)
    gs = res.g_sensitivity
    assert gs is not None and not res.g_sensitivity_subtracted
    assert np.all(np.abs(np.diag(gs.matrix_deg_h_g) - 0.3) < 3.0 * np.diag(gs.sigma_deg_h_g))
    note = res.g_sensitivity_note or ""
    assert note.startswith("the g-sensitivity is c·I alone (c = 0.") and "latitude" in note
    line = turntable_g_sensitivity_line(res.to_dict(), "run.csv") or ""
    assert line.endswith(f"not compensated by this calibration; {note})"), line


def test_a_schedule_started_turned_and_tilted_still_separates_it() -> None:
    """The sixteen positions started at α = 30°, β = 45° (a mounting turned about the inner
    axis and tilted on the outer: no dwell has gravity along a body axis): A within 3σ and
    the twelve coefficients within 3.5σ over 4 seeds, the drift taken off."""
    for seed in range(4):
        rec, truth = simulate_turntable16(seed, rate_hz=20.0, alpha0_deg=30.0, beta0_deg=45.0,
                                          g_sensitivity_deg_h_g=A_TRUE)  # fmt: skip
        res = calibrate(rec, 40.0)
        gs = res.g_sensitivity
        assert gs is not None and res.g_sensitivity_subtracted
        assert np.all(np.abs(gs.matrix_deg_h_g - A_TRUE) < 3.0 * gs.sigma_deg_h_g)
        assert np.all(np.abs(res.kalman.theta - _theta(truth)) < 3.5 * res.kalman.sigma)


def test_runs_over_temperature_state_each_runs_sensitivity(tmp_path: Path) -> None:
    """Three soaks of a triad without a g-sensitivity: one text line per run (none beyond
    3σ, each from its 16 dwells) and each run's JSON holding its matrix."""
    from thermocal.turntable.simulate import simulate_turntable_thermal

    files = []
    for rec, truth in simulate_turntable_thermal(seed=2, soaks_c=(-20.0, 20.0, 60.0)):
        if not truth["held_out"]:
            files.append(tmp_path / f"{truth['label']}.parquet")
            write_recording(rec, files[-1])
    args = ["turntable", *map(str, files), "--temps", "T_imu", "--order", "1", "-o"]
    text, js = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(text):
        assert main([*args, str(tmp_path / "a.json")]) == 0
    with contextlib.redirect_stdout(js):
        assert main([*args, str(tmp_path / "b.json"), "--json"]) == 0
    lines = [ln for ln in text.getvalue().splitlines() if "gyro g-sensitivity from" in ln]
    assert len(lines) == 3 and all("from 16 dwells" in ln for ln in lines), lines
    assert all("none beyond 3σ" in ln for ln in lines), lines
    runs = json.loads(js.getvalue())["runs"]
    assert [np.shape(r["g_sensitivity"]["matrix"]) for r in runs] == [(3, 3)] * 3


def _soak_calibration(tmp_path: Path, a_true: np.ndarray | None) -> dict:
    from thermocal.turntable.simulate import simulate_turntable_thermal

    files = []
    for rec, truth in simulate_turntable_thermal(
        seed=3, soaks_c=(-20.0, 20.0, 60.0), g_sensitivity_deg_h_g=a_true
    ):
        if not truth["held_out"]:
            files.append(tmp_path / f"{truth['label']}.parquet")
            write_recording(rec, files[-1])
    out = tmp_path / "cal.json"
    args = ["turntable", *map(str, files), "--temps", "T_imu", "--order", "1", "-o", str(out)]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(args) == 0
    gyro = [t for t in json.loads(out.read_text())["triads"] if t["name"] == "gyro"]
    return gyro[0]


def test_soaks_store_the_pooled_sensitivity_in_the_calibration(tmp_path: Path) -> None:
    """Three soaks of a gyro with a known A (°/h/g, constant in temperature): the
    calibration file's gyro triad holds A in its own unit per g (°/s/g here) within 3σ of
    the truth, so that ``compensate`` takes A f off; without A nothing is stored."""
    got = _soak_calibration(tmp_path, A_TRUE)
    assert got["g_sensitivity_unit"] == "deg/s/g"
    a = np.asarray(got["g_sensitivity"]) * 3600.0  # °/s/g → °/h/g, written here
    sig = np.asarray(got["g_sensitivity_sigma"]) * 3600.0
    assert np.all(sig > 0) and np.all(sig < 0.05), sig
    assert np.all(np.abs(a - A_TRUE) < 3.0 * sig), (a - A_TRUE) / sig
    (tmp_path / "none").mkdir()
    assert "g_sensitivity" not in _soak_calibration(tmp_path / "none", None)


def test_validate_takes_the_calibrations_sensitivity_off(tmp_path: Path) -> None:
    """The held-out soak of a gyro with a known A judged by ``validate_turntable_run``: with
    the calibration's A taken off (f from the encoders' gravity) its dwell-mean errors are
    at the noise, ARW / √T_dwell = 0.01 °/√h / √(60 s) = 0.0775 °/h (written here from the
    simulator's defaults); the same triad without A leaves A f in them (over 2σ)."""
    import dataclasses

    from thermocal.pipeline.model_file import load_calibration
    from thermocal.turntable.calibration import validate_turntable_run
    from thermocal.turntable.simulate import simulate_turntable_thermal

    files, held = [], None
    for rec, truth in simulate_turntable_thermal(
        seed=3, soaks_c=(-20.0, 20.0, 60.0), g_sensitivity_deg_h_g=A_TRUE
    ):
        if truth["held_out"]:
            held = rec
        else:
            files.append(tmp_path / f"{truth['label']}.parquet")
            write_recording(rec, files[-1])
    assert held is not None
    out = tmp_path / "cal.json"
    args = ["turntable", *map(str, files), "--temps", "T_imu", "--order", "1", "-o", str(out)]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(args) == 0
    triads = list(load_calibration(out).triads)
    assert [t.g_sensitivity is not None for t in triads if t.name == "gyro"] == [True]
    bare = [dataclasses.replace(t, g_sensitivity=None) for t in triads]
    sigma = 0.01 / math.sqrt(60.0 / 3600.0)  # °/h
    (with_a,) = [v for v in validate_turntable_run(triads, held) if v.triad == "gyro"]
    (without,) = [v for v in validate_turntable_run(bare, held) if v.triad == "gyro"]
    assert all(e < 1.5 * sigma for e in with_a.dwell_rms_after), with_a.dwell_rms_after
    assert all(e > 2.0 * sigma for e in without.dwell_rms_after), without.dwell_rms_after
    assert with_a.dwell_rms_before == without.dwell_rms_before  # "before": the raw samples
