"""The multi-position calibration's refusals and uncertainties (:mod:`thermocal.multipos`)
against the simulator's truth, formulas written here and the figures a user reported: a
failed gravity residual, poses near one plane, the six-face σ, the gyro's reduced χ².
Each kills a mutant of ``benchmarks/mutation_check.py`` (``h39mp-…``)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from thermocal.errors import DesignError
from thermocal.multipos import accel as mp_accel
from thermocal.multipos.calibrate import check_accel_fit

MG = 9.80665e-3  # 1 mg [m/s²]


ARCSEC = math.pi / 180.0 / 3600.0


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
    with pytest.raises(DesignError, match=r"accel_unit"):
        check_accel_fit(_fit(30.0, 1.0, sf_ppm=-0.51e6), g, "s.csv")
    check_accel_fit(_fit(30.0, 1.0, sf_ppm=-0.49e6), g, "s.csv")


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
