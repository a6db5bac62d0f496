"""Tests that catch a tired developer's bugs in multipos, the turntable's checks before a
write, validate and the gravity placements (issue 39, slice h39-multipos): each test
kills a mutant of ``benchmarks/mutation_check.py`` (``h39mp-…``) that the module's other
tests let survive, against a reference from outside the code under test (the simulator's
truth, a formula written here, the issue's own figures).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from thermocal.errors import DesignError, ThermocalInputError
from thermocal.multipos import accel as mp_accel
from thermocal.multipos.calibrate import check_accel_fit
from thermocal.turntable import thermal

MG = 9.80665e-3  # 1 mg [m/s²]
ARCSEC = math.pi / 180.0 / 3600.0


# --- the checks before a calibration is written -------------------------------------------


def test_a_tref_the_reader_refuses_is_refused_before_the_fit() -> None:
    """The reader accepts a TREF within the soaks' range or ``max(span, 50 °C)`` of it
    (:func:`thermocal.models.checks.range_margin`); soaks at −10, 20, 50 °C: span 60, so
    −70 … 110 °C.  110 is fitted, 110.5 refused naming --tref (the issue's 1e9 too)."""
    temps = [-10.0, 20.0, 50.0]
    th = np.zeros((3, 12))
    sg = np.ones((3, 12))
    assert thermal.fit_triad("accel", temps, th, sg, tref_c=110.0).tref_c == 110.0
    assert thermal.fit_triad("accel", temps, th, sg, tref_c=-70.0).tref_c == -70.0
    for bad in (110.5, -70.5, 1e9, float("nan")):
        with pytest.raises(ThermocalInputError, match=r"--tref"):
            thermal.fit_triad("accel", temps, th, sg, tref_c=bad)


def test_a_calibration_its_reader_refuses_is_not_written(tmp_path: object) -> None:
    """A triad whose ``I + E`` has condition number 20 (x scale factor −95 %: singular
    values 1 and 0.05, computed here) is refused by the reader (≤ 10); it is refused
    before the write, naming the condition number, and nothing is written."""
    from pathlib import Path

    from thermocal.models.calibration import Calibration, Triad
    from thermocal.turntable.files import check_as_read

    th = np.zeros(12)
    th[3] = -0.95e6  # ppm
    sv = np.linalg.svd(np.diag([0.05, 1.0, 1.0]), compute_uv=False)
    assert sv[0] / sv[-1] == pytest.approx(20.0)
    m = thermal.constant_triad("accel", 25.0, th, np.eye(12), method="multipos")
    cal = Calibration([], [Triad("accel", ("ax", "ay", "az"), "mg", "", m)])
    out = Path(str(tmp_path)) / "cal.json"
    with pytest.raises(DesignError, match=r"condition number 20"):
        check_as_read(cal, out, "the hint")
    assert not out.exists()
    th[3] = -0.85e6  # condition 1/0.15 = 6.7: accepted by the reader, and here
    ok = thermal.constant_triad("accel", 25.0, th, np.eye(12), method="multipos")
    check_as_read(Calibration([], [Triad("accel", ("ax", "ay", "az"), "mg", "", ok)]), out, "")


def test_every_calibration_writer_applies_the_readers_checks(tmp_path: object) -> None:
    """``save_calibration`` (fit, tempcal, multipos, turntable, the demo all write through
    it): the condition-20 triad above is refused, nothing written; a TREF 200 °C beyond a
    25 °C-only range (the reader's margin is 50 °C) too."""
    from pathlib import Path

    from thermocal.models.calibration import Calibration, Triad
    from thermocal.pipeline.model_file import save_calibration

    out = Path(str(tmp_path)) / "cal.json"
    th = np.zeros(12)
    th[3] = -0.95e6
    bad = thermal.constant_triad("accel", 25.0, th, np.eye(12), method="multipos")
    with pytest.raises(DesignError, match=r"condition number 20.*not written"):
        save_calibration(Calibration([], [Triad("accel", ("ax", "ay", "az"), "mg", "", bad)]), out)
    assert not out.exists()
    far = thermal.constant_triad("accel", 200.0, np.zeros(12), np.eye(12), t_range_c=(25.0, 25.0))
    with pytest.raises(DesignError, match=r"TREF 200"):
        save_calibration(Calibration([], [Triad("accel", ("ax", "ay", "az"), "mg", "", far)]), out)
    assert not out.exists()


def _fit(before_mg: float, after_mg: float, sf_ppm: float = 100.0) -> mp_accel.AccelFit:
    th = np.zeros(12)
    th[3:6] = sf_ppm
    return mp_accel.AccelFit(th, np.eye(12), before_mg, after_mg, 1.0, "gravity-magnitude",
                             12, (after_mg,) * 12)  # fmt: skip


def test_an_accelerometer_fit_that_failed_its_residual_is_refused() -> None:
    """The issue's figures: a gravity residual of 0.163 → 6.98e4 m/s² (16.6 mg → 7.1e6 mg)
    refused; 0.163 → 0.2 m/s² (worse than before, below 5 % of g) refused; a residual
    that falls (30 → 1 mg) accepted; 60 mg after (above 5 % of 1000 mg) refused."""
    g = 1000.0
    for before, after in ((0.163 / MG, 6.98e4 / MG), (0.163 / MG, 0.2 / MG), (100.0, 60.0)):
        with pytest.raises(DesignError, match="accelerometer fit failed"):
            check_accel_fit(_fit(before, after), g, "s.csv")
    check_accel_fit(_fit(30.0, 1.0), g, "s.csv")
    with pytest.raises(DesignError, match=r"--accel-unit"):
        check_accel_fit(_fit(30.0, 1.0, sf_ppm=-0.51e6), g, "s.csv")
    check_accel_fit(_fit(30.0, 1.0, sf_ppm=-0.49e6), g, "s.csv")


# --- multipos: the accelerometer's poses and the six faces ---------------------------------


def _directions(elev_deg: float, n: int = 10) -> np.ndarray:
    """``n`` gravity directions at azimuths 36° apart and elevations ±``elev_deg``
    alternately, times 1 g [mg]: their mean outer product's least eigenvalue is
    ``sin² elev`` (the plane z = 0 their normal)."""
    az = np.radians(np.arange(n) * 360.0 / n)
    el = np.radians(elev_deg) * np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    return 1000.0 * np.column_stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])


def test_poses_near_one_plane_are_refused() -> None:
    """Ten poses within ±5° of the plane z = 0 (least eigenvalue sin² 5° = 0.0076,
    computed here) leave z's scale factor and bias unseen: refused; at ±12° (0.043) they
    are accepted.  The threshold 0.02 lies between (±8.1°)."""
    f5, f12 = _directions(5.0), _directions(12.0)
    u5 = f5 / np.linalg.norm(f5, axis=1)[:, None]
    assert np.linalg.eigvalsh(u5.T @ u5 / len(u5))[0] == pytest.approx(
        math.sin(math.radians(5)) ** 2
    )
    with pytest.raises(DesignError, match="near one plane"):
        mp_accel.check_poses(f5)
    mp_accel.check_poses(f12)


def test_six_face_misalignment_sigma_comes_from_its_columns_faces() -> None:
    """Closed form: column j of ``I + E`` is ``(f_j+ − f_j−)/2g``, so each element of
    column j has the variance ``(σ_j+² + σ_j−²)/(2g)²`` [rad²] — written here with the
    faces of x, y, z at σ 1, 2, 4 mg: misalignment ``yx`` (E[0, 1], column y) has σ
    √8/2000 rad, not x's √2/2000."""
    g = 1000.0
    sig_axis = {"x": 1.0, "y": 2.0, "z": 4.0}
    faces = {f"{a}_{s}": (1.0 if s == "p" else -1.0) * g * np.eye(3)["xyz".index(a)]
             + np.array([5.0, -3.0, 2.0]) for a in "xyz" for s in "pa"}  # fmt: skip
    sig = {n: sig_axis[n[0]] for n in faces}
    fit = mp_accel.fit_six_faces(faces, sig, g)
    column = {"yx": "y", "zx": "z", "xy": "x", "zy": "z", "xz": "x", "yz": "y"}  # E[i, j]: j
    names = ("yx", "zx", "xy", "zy", "xz", "yz")
    for k, n in enumerate(names):
        want = math.sqrt(2.0 * sig_axis[column[n]] ** 2) / (2.0 * g) / ARCSEC
        assert fit.sigma[6 + k] == pytest.approx(want, rel=1e-12), n
    for i, a in enumerate("xyz"):  # scale factors: their own axis's faces, in ppm
        want = math.sqrt(2.0) * sig_axis[a] / (2.0 * g) * 1e6
        assert fit.sigma[3 + i] == pytest.approx(want, rel=1e-12), a


# --- gravity: a placement's direction -----------------------------------------------------


def test_a_placements_direction_is_that_of_all_its_runs() -> None:
    """Two runs 2.3° apart (one placement, tolerance 5°): the placement's gravity direction
    is that of the mean of both runs' mean specific forces, (0, −10, 1000)/|…|, for each."""
    from thermocal.gravity import group_placements

    dirs, place = group_placements([[0.0, 10.0, 1000.0], [0.0, -30.0, 1000.0]])
    assert place == (0, 0)
    want = np.array([0.0, -10.0, 1000.0]) / math.hypot(10.0, 1000.0)
    for d in dirs:
        np.testing.assert_allclose(d, want, atol=1e-14)


# --- validate: ambient, verdict, units ----------------------------------------------------


def _validation_inputs() -> tuple[Any, Any, Any]:
    from test_validation import _synthetic_run

    return _synthetic_run()


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_a_run_that_repeats_the_modelling_run_is_not_judged_improved() -> None:
    """SPEC §5: a validation run whose ambient repeats the modelling run's (r = 1 ≥ 0.4)
    proves nothing: its verdict says so, whatever the figures."""
    from thermocal.validation import validate

    run, _noise, model = _validation_inputs()
    res = validate(model, run, (run.time_s, run.temps_c[:, 0]))
    assert res.r == pytest.approx(1.0, abs=1e-12)
    assert res.verdict == "NOT weakly correlated"
    assert res.to_dict()["verdict"] == "NOT weakly correlated"


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_the_ambient_is_the_first_temperature_column() -> None:
    """A run with a second temperature column held at 25 °C: the ambient (stages, r) is the
    first column: four holds (the profile's), and r equals numpy's Pearson r of the first
    column against the modelling history on their common time base, computed here."""
    from test_validation import _profile
    from thermocal.models.rundata import RunData
    from thermocal.profiles import common_base
    from thermocal.validation import validate

    run, _noise, model = _validation_inputs()
    two = RunData(time_s=run.time_s, temps_c=np.column_stack([run.temps_c[:, 0],
                  np.full(run.time_s.size, 25.0)]), signal=run.signal,
                  temp_names=("T1", "T_board"), name="two")  # fmt: skip
    t_mod, temp_mod = _profile((30.0, 0.0, 10.0, 50.0))
    res = validate(model, two, (t_mod, temp_mod), averaging_s=100.0)
    assert res.n_stages == 4
    _b, x, y = common_base(t_mod, temp_mod, run.time_s, run.temps_c[:, 0])
    assert res.r == pytest.approx(float(np.corrcoef(x, y)[0, 1]), abs=1e-12)


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_figures_shown_in_the_datas_unit_are_all_converted() -> None:
    """Shown in °/s (1 °/s = 3600 °/h): each stage's bias stability (the std of its
    100-sample block means, computed here) and the zero reference (15.04 °/h, an earth
    rate) divided by 3600, as the run's own figures are."""
    from thermocal.validation import validate

    run, _noise, model = _validation_inputs()
    t_mod = run.time_s
    res = validate(model, run, (t_mod, run.temps_c[::-1, 0]), averaging_s=100.0,
                   zero_reference=(15.04, "earth rate"))  # fmt: skip
    shown = res.in_unit("deg/s", 3600.0)
    assert shown.zero_reference == pytest.approx(15.04 / 3600.0, rel=1e-12)
    assert shown.to_dict()["zero_reference"]["value"] == pytest.approx(15.04 / 3600.0)
    sig = np.asarray(run.signal)
    for s in shown.stages:
        a = int(np.searchsorted(run.time_s, s.start_s))
        b = int(np.searchsorted(run.time_s, s.stop_s)) + 1
        k = (b - a) // 100
        blocks = sig[a : a + 100 * k].reshape(k, 100).mean(axis=1)
        assert s.bias_stability_before == pytest.approx(np.std(blocks, ddof=1) / 3600.0,
                                                        rel=1e-9)  # fmt: skip
        assert s.bias_before == pytest.approx(sig[a:b].mean() / 3600.0, rel=1e-9)
    assert shown.bias_stability_before == pytest.approx(res.bias_stability_before / 3600.0)


# --- multipos: the gyro's χ² -----------------------------------------------------------------

DEG = math.pi / 180.0


def _gyro_session(seed: int, motion_noise_deg_s: float) -> tuple[Any, np.ndarray]:
    """A simulated 16-pose session (truth from :func:`random_truth`) calibrated; with
    ``motion_noise_deg_s`` more white rate noise during the motions only (a sensor noisier
    moving than still: the statics' noise understates the motions' scatter)."""
    from thermocal.multipos.calibrate import calibrate_session
    from thermocal.multipos.simulate import random_truth, simulate_session

    rng = np.random.default_rng(seed)
    ta, _slope = random_truth(rng)
    s = simulate_session(rng, ta.accel, ta.gyro, n_poses=16)
    gyro = s["gyro_deg_s"].copy()
    if motion_noise_deg_s:
        still = np.zeros(gyro.shape[0], dtype=bool)
        for a, b in s["poses"]:
            still[a:b] = True
        gyro[~still] += rng.normal(0.0, motion_noise_deg_s, size=gyro[~still].shape)
    res = calibrate_session(s["time_s"], s["accel_mg"], gyro * DEG, g_mg=s["g_m_s2"] / MG,
                            latitude_deg=45.0)  # fmt: skip
    return res.gyro, ta.gyro


SEEDS = (11, 12, 13, 14, 15, 16)


@pytest.fixture(scope="module")
def clean_gyros() -> list[tuple[Any, np.ndarray]]:
    return [_gyro_session(s, 0.0) for s in SEEDS]


def test_the_gyro_reduced_chi2_is_one_on_white_noise(clean_gyros: list[Any]) -> None:
    """The simulator's noise is white and its model the fit's: the reduced χ² of each
    session's motions averages 1 (six sessions of 15 motions, 2 degrees of freedom each —
    the direction residual lies across gravity — less 9: ν = 21, so the mean of six has
    σ ≈ √(2/21)/√6 = 0.13).  Counting 3 per motion gives 21/36 of it (0.58)."""
    chi2 = np.array([g.reduced_chi2 for g, _t in clean_gyros])
    dof = np.array([g.dof for g, _t in clean_gyros])
    assert np.all(dof == 2 * np.array([g.n_motions for g, _t in clean_gyros]) - 9)
    assert 0.7 < float(chi2.mean()) < 1.4, chi2


def test_a_misfit_gyro_sigma_is_scaled_by_its_chi2() -> None:
    """Rate noise of 1 °/s during the motions only (33 times the still noise): the
    motions scatter far beyond the σ the statics give, the reduced χ² is large, and the
    σ must be scaled by it so that the scale factors and misalignments stay within their σ
    of the simulator's truth (z rms over six sessions × nine elements below 2; unscaled,
    the z's are ~√χ² times larger)."""
    z = []
    chi2 = []
    for seed in SEEDS:
        g, truth = _gyro_session(seed, 1.0)
        chi2.append(g.reduced_chi2)
        z.extend(((g.theta[3:] - truth[3:]) / g.sigma[3:]).tolist())
    assert min(chi2) > 20.0, chi2  # the misfit is there
    assert float(np.sqrt(np.mean(np.square(z)))) < 2.0, (np.sqrt(np.mean(np.square(z))), chi2)
