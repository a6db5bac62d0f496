"""The gyro's sensitivity to specific force from static poses (``multipos.gsens``): the six
faces' half differences written here, the simulator's truth over seeds, the refusals, and
the command's report on imucal's public Ferraris session."""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.errors import DesignError
from thermocal.multipos import Section, calibrate_session
from thermocal.multipos.gsens import fit_g_sensitivity, fit_g_sensitivity_known_rate
from thermocal.multipos.simulate import random_truth, simulate_ferraris

DH = math.pi / 180.0 / 3600.0  # 1 °/h in rad/s
FERRARIS = Path(__file__).parents[1] / "data" / "imucal_ferraris"
A_TRUE = np.array([[180.0, -90.0, 36.0], [50.0, -250.0, 120.0], [-30.0, 60.0, 300.0]])


def test_six_faces_give_the_half_differences_of_each_pair() -> None:
    """Each face pair ±j seen with equal weight: A_ij = (ω_i(+j) − ω_i(−j))/2, whatever
    the bias and the other pairs (the normal equations decouple); computed here."""
    rng = np.random.default_rng(3)
    up = np.vstack([np.eye(3), -np.eye(3)])
    w = rng.normal(0.0, 50.0, (6, 3)) * DH  # arbitrary pose means [rad/s]
    gs = fit_g_sensitivity(w, np.full(6, 500), np.full(3, 1e-3), up)  # no latitude
    half = (w[0:3] - w[3:6]).T / 2.0 / DH  # [i, j]: axis i, pair j
    np.testing.assert_allclose(gs.matrix_deg_h_g, half, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(gs.bias_deg_h, w.mean(axis=0) / DH, rtol=1e-12)
    assert gs.dof == 2 and gs.n_poses == 6


def test_the_vertical_earth_rate_is_not_taken_for_a_sensitivity() -> None:
    """At latitude L a still gyro reads Ω sin L along up on top of its bias: with the six
    faces and no sensitivity, A must come out 0 (it would be Ω sin L on the diagonal)."""
    lat = 48.0
    up = np.vstack([np.eye(3), -np.eye(3)])
    om = 7.292115e-5 * math.sin(math.radians(lat))
    w = up * om + np.array([5.0, -3.0, 1.0]) * DH
    gs = fit_g_sensitivity(w, np.full(6, 1000), np.full(3, 1e-4), up, latitude_deg=lat)
    np.testing.assert_allclose(gs.matrix_deg_h_g, 0.0, atol=1e-9)


def test_too_few_poses_or_poses_in_one_plane_are_refused() -> None:
    up = np.vstack([np.eye(3), -np.eye(3)])
    with pytest.raises(DesignError, match="at least 4 static poses"):
        fit_g_sensitivity(np.zeros((3, 3)), np.full(3, 100), np.full(3, 1e-3), up[:3])
    flat = up[[0, 1, 3, 4]]  # gravity along ±x and ±y only: A's z column unseen
    with pytest.raises(DesignError, match="do not span the three axes"):
        fit_g_sensitivity(np.zeros((4, 3)), np.full(4, 100), np.full(3, 1e-3), flat)


def test_a_force_component_left_by_rounding_is_not_taken_for_a_seen_axis() -> None:
    """Gravity along ±x and ±y with a z component of 1e-16 g (what rounding a rotation
    leaves): the z column is unseen, whatever the scale of that component; the direction is
    named."""
    rng = np.random.default_rng(1)
    flat = np.vstack([np.eye(3), -np.eye(3)])[[0, 1, 3, 4]]
    flat[:, 2] = rng.normal(0.0, 1e-16, 4)
    with pytest.raises(
        DesignError, match=r"unseen: specific force along \(\+0.00, \+0.00, \+1.00\)"
    ):
        fit_g_sensitivity(np.zeros((4, 3)), np.full(4, 100), np.full(3, 1e-3), flat)
    line = np.array([[0.0, 0.0, 1.0]] * 3 + [[0.0, 0.0, -1.0]] * 3)
    line[:, :2] = rng.normal(0.0, 1e-16, (6, 2))
    with pytest.raises(
        DesignError, match=r"every gravity direction along \(\+0.00, \+0.00, \+1.00\)"
    ):
        fit_g_sensitivity_known_rate(np.zeros((6, 3)), np.full((6, 3), 1e-12), line)


def test_with_the_rate_known_each_pair_gives_its_half_difference_and_its_sigma() -> None:
    """Known-rate residuals of the six faces with per-pose variances: A_ij is the half
    difference of the pair ±j and its σ is √(v₊ + v₋)/2 (computed here)."""
    rng = np.random.default_rng(5)
    up = np.vstack([np.eye(3), -np.eye(3)])
    r = rng.normal(0.0, 20.0, (6, 3)) * DH
    var = np.full((6, 3), (0.5 * DH) ** 2)
    gs = fit_g_sensitivity_known_rate(r, var, up)
    np.testing.assert_allclose(gs.matrix_deg_h_g, (r[0:3] - r[3:6]).T / 2.0 / DH, rtol=1e-11)
    # the scatter is far beyond the variances: σ scaled by each axis's reduced χ²
    chi = gs.reduced_chi2
    want = np.sqrt(2 * 0.25) / 2.0 * np.sqrt(np.maximum(chi, 1.0))[:, None] * np.ones((3, 3))
    np.testing.assert_allclose(gs.sigma_deg_h_g, want, rtol=1e-9)


def _session(seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    truth, _ = random_truth(rng)
    s = simulate_ferraris(rng, truth.accel, truth.gyro, g_sensitivity_deg_h_g=A_TRUE)
    secs = [Section(k, v["start"], v["end"]) for k, v in s["sections"].items()]
    g_mg = s["g_m_s2"] / 9.80665e-3
    res = calibrate_session(s["time_s"], s["accel_mg"], np.radians(s["gyro_deg_s"]),
                            g_mg=g_mg, latitude_deg=45.0, sections=secs)  # fmt: skip
    gs = res.g_sensitivity
    assert gs is not None and res.g_sensitivity_note is None
    return gs.matrix_deg_h_g, gs.sigma_deg_h_g


def test_the_simulators_sensitivity_is_recovered_within_its_sigma() -> None:
    """A Ferraris session as users record it (six faces at random headings, then the three
    turns; hand tremor, earth rate at 45°) with a known A of up to 300 °/h/g: over 12 seeds
    every element within 3.5σ, about 95 % within 1.96σ (binomial band for 108 draws)."""
    z = np.array([((a - A_TRUE) / s).ravel() for a, s in map(_session, range(12))])
    assert np.all(np.abs(z) < 3.5), np.abs(z).max()
    inside = float(np.mean(np.abs(z) < 1.96))
    assert 0.88 <= inside <= 1.0, inside
    assert 0.7 < float(z.std()) < 1.3


def test_multipos_reports_it_on_imucals_session(tmp_path: Path) -> None:
    """imucal's public Ferraris session (six faces, then three turns): the JSON holds the 3×3
    matrix in the gyro's unit per g with σ below 0.01 °/s/g, and the text says none is beyond
    3σ."""
    args = ["multipos", str(FERRARIS / "example_ferraris_session.csv"),
            "--poses", str(FERRARIS / "example_ferraris_session_list.json"), "--rate", "102.4",
            "--accel", "acc_x,acc_y,acc_z", "--accel-unit", "m/s^2",
            "--gyro", "gyr_x,gyr_y,gyr_z", "--gyro-unit", "deg/s", "--gravity", "9.81"]  # fmt: skip
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        assert main([*args, "-o", str(tmp_path / "a.json"), "--json"]) == 0
    gyro = json.loads(out.getvalue())["runs"][0]["gyro"]
    gs = gyro["g_sensitivity"]
    assert gyro["g_sensitivity_subtracted"] is False  # none significant: the fit as before
    assert gs["unit"] == "deg/s/g" and gs["n_poses"] == 6 and gs["dof"] == 2
    m, s = np.array(gs["matrix"]), np.array(gs["matrix_sigma"])
    assert m.shape == (3, 3) and np.all(s > 0) and np.all(s < 0.01)
    assert not np.any(gs["significant"]) and np.all(np.abs(m) < 3 * s)
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        assert main([*args, "-o", str(tmp_path / "b.json")]) == 0
    assert "gyro g-sensitivity from 6 poses [deg/s/g, gyro/force axis]: none beyond 3σ" in (
        " ".join(out.getvalue().split())
    )


A_LARGE = np.array([[360.0, -180.0, 90.0], [120.0, -300.0, 200.0], [-60.0, 150.0, 360.0]])
"""Up to 0.1 °/s/g: an uncompensated MEMS gyro's acceleration-sensitive drift [°/h/g]."""


def _gyro_z(seed: int, a: np.ndarray) -> tuple[np.ndarray, bool]:
    """One simulated Ferraris session (faces, then the turns) with sensitivity ``a``: the
    gyro's θ less the truth in σ, and whether A f(t) was taken off."""
    rng = np.random.default_rng(seed)
    truth, _ = random_truth(rng)
    s = simulate_ferraris(rng, truth.accel, truth.gyro, g_sensitivity_deg_h_g=a)
    secs = [Section(k, v["start"], v["end"]) for k, v in s["sections"].items()]
    res = calibrate_session(s["time_s"], s["accel_mg"], np.radians(s["gyro_deg_s"]),
                            g_mg=s["g_m_s2"] / 9.80665e-3, latitude_deg=45.0,
                            sections=secs)  # fmt: skip
    assert res.gyro is not None
    return (res.gyro.theta - truth.gyro) / res.gyro.sigma, res.g_sensitivity_subtracted


def test_the_rotations_fit_takes_the_sensitivitys_drift_off(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With A up to 0.1 °/s/g the gyro reads A·f(t) along every turn: left in, the scale
    factors come out 3–12σ off (σ already widened by the misfit, reduced χ² 24–117); taken
    off (f from the calibrated accelerometer), bias, scale factors and misalignments are
    within 3.5σ over 8 seeds, as without a sensitivity."""
    zs = []
    for seed in range(8):
        z, subtracted = _gyro_z(seed, A_LARGE)
        assert subtracted
        zs.append(z)
    assert np.all(np.abs(np.array(zs)) < 3.5), np.abs(np.array(zs)).max()
    import thermocal.multipos.calibrate as calibrate_mod

    monkeypatch.setattr(calibrate_mod, "_without_g_drift",
                        lambda a, w, st, am, gs, note: (w, list(st), False, note))  # fmt: skip
    left_in = [np.abs(_gyro_z(seed, A_LARGE)[0][3:6]).max() for seed in range(4)]
    assert min(left_in) > 3.0, left_in


def test_without_a_sensitivity_nothing_is_taken_off() -> None:
    """A = 0: no element beyond 3σ on these seeds, the rates fitted as they are."""
    for seed in range(3):
        z, subtracted = _gyro_z(seed, np.zeros((3, 3)))
        assert not subtracted and np.all(np.abs(z) < 3.5)


def test_the_xsens_session_sensitivity_is_taken_off_its_rotations(tmp_path: Path) -> None:
    """imu_tk's Xsens session (raw counts): its gyro's A reaches 0.11 ± 0.007 °/s/g (y/x);
    taken off, the motions' reduced χ² falls from 110 to 4.8 and their direction residual
    from 1.22° to 0.25° rms; imucal's session (none beyond 3σ) is fitted as before."""
    data = Path(__file__).parents[1] / "data" / "imu_tk_xsens" / "xsens_imu_tk.parquet"
    acc = ",".join(f"acc_{a} [counts]" for a in "xyz")
    gyr = ",".join(f"gyro_{a} [counts]" for a in "xyz")
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        code = main(["multipos", str(data), "--accel", acc, "--gyro", gyr, "--accel-scale",
                     "0.27,mg", "--gyro-scale", "0.0091554,deg/s", "--gravity", "9.81744",
                     "--accel-offset", "32768", "--gyro-offset", "32768", "-o",
                     str(tmp_path / "c.json"), "--json"])  # fmt: skip
    assert code == 0
    g = json.loads(out.getvalue())["runs"][0]["gyro"]
    assert g["g_sensitivity_subtracted"] is True
    assert g["reduced_chi2"] < 6.0 and g["direction_rms_after_deg"] < 0.3
    assert g["g_sensitivity"]["unit"] == "deg/s/g"
    assert abs(g["g_sensitivity"]["matrix"][1][0] + 0.11) < 0.02
