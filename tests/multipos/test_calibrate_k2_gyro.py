"""The gyro's stage of a multi-position calibration reads the accelerometer with K2 when K2
is fitted (``calibrate_session(accel_k2=True)``, ``multipos --accel-k2``): the up directions
of the rotations' fit, the g-sensitivity's specific force and the force taken off with it.

A simulated session whose accelerometer has K2 = (50, −40, 30) mg/g² (the simulator adds
``K2 ⊙ (a/g)²`` to the true force) and whose gyro has a known ``A`` (:mod:`gsens_session`'s
truth): with K2 the gyro's scale factors and misalignments are within 3.5σ of the truth, the
motions' reduced χ² near 1 and the error ten times smaller than without (the nine-parameter
accelerometer's up directions are off by the K2 it leaves in: χ² in the thousands), and
``A`` closer to the truth (measured on seeds 0-5: E rms error 3000-10000 → 43-116 ppm/″,
A rms error 3.8-7.3 → 1.7-4.3 °/h/g).  Through the command line, the stored accelerometer
bias is the truth's (within 4σ) when the columns carry a zero given by ``--accel-offset``
(it was added twice when K2 was fitted after the zeros were put back)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from gsens_session import (
    A_TRUE,
    ACCEL_THETA,
    GYRO_NOISE_DEG_S,
    GYRO_THETA,
    LATITUDE_DEG,
    MULTIPOS,
    run,
    write_session,
)
from thermocal.multipos.calibrate import calibrate_session
from thermocal.multipos.simulate import simulate_session

K2_MG_G2 = np.array([50.0, -40.0, 30.0])


def _errors(seed: int, accel_k2: bool) -> tuple[np.ndarray, float, float, float]:
    """The gyro's E error z-scores, its rms error [ppm, ″], A's rms error [°/h/g] and the
    motions' reduced χ²."""
    s = simulate_session(np.random.default_rng(seed), ACCEL_THETA, GYRO_THETA, n_poses=16,
                         gyro_noise_deg_s=GYRO_NOISE_DEG_S, latitude_deg=LATITUDE_DEG,
                         g_sensitivity_deg_h_g=A_TRUE, accel_k2_mg_g2=K2_MG_G2)  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the nine-parameter fit's misfit is warned of
        r = calibrate_session(s["time_s"], s["accel_mg"], np.radians(s["gyro_deg_s"]),
                              g_mg=s["g_m_s2"] / 9.80665e-3, latitude_deg=LATITUDE_DEG,
                              accel_k2=accel_k2)  # fmt: skip
    g, gs = r.gyro, r.g_sensitivity
    assert g is not None and gs is not None
    assert (r.accel_k2 is not None) == accel_k2
    err = g.theta[3:] - GYRO_THETA[3:]
    z = np.concatenate(
        [err / g.sigma[3:], ((gs.matrix_deg_h_g - A_TRUE) / gs.sigma_deg_h_g).ravel()]
    )
    a_rms = float(np.sqrt(np.mean((gs.matrix_deg_h_g - A_TRUE) ** 2)))
    return z, float(np.sqrt(np.mean(err**2))), a_rms, float(g.reduced_chi2)


def test_the_gyro_reads_the_accelerometer_with_k2() -> None:
    for seed in range(3):
        z, e_with, a_with, chi_with = _errors(seed, True)
        _z, e_without, a_without, chi_without = _errors(seed, False)
        assert np.all(np.abs(z) < 3.5), (seed, np.abs(z).max())
        assert chi_with < 2.0 < 100.0 < chi_without, (chi_with, chi_without)
        assert e_with < e_without / 10.0, (e_with, e_without)
        assert a_with < a_without, (a_with, a_without)


def test_k2_with_an_offset_through_the_command_line(tmp_path: Path) -> None:
    write_session(tmp_path, seed=2, k2_mg_g2=K2_MG_G2)
    df = pd.read_csv(tmp_path / "s.csv")
    df[["ax", "ay", "az"]] += 500.0  # a zero of 500 mg in the columns, given below
    df.to_csv(tmp_path / "s.csv", index=False)
    code, out, err = run(["multipos", str(tmp_path / "s.csv"), *MULTIPOS, "-o",
                          str(tmp_path / "c.json"), "--accel-k2", "--accel-offset", "500",
                          "--json"])  # fmt: skip
    assert code == 0, err
    d = json.loads(out)
    acc = d["accel"]
    for v, s, t in zip(acc["bias"], acc["bias_sigma"], ACCEL_THETA[0:3] + 500.0, strict=True):
        assert abs(v - t) < 4 * s, (v, s, t)
    gyro = d["runs"][0]["gyro"]
    assert gyro["reduced_chi2"] < 2.0
    e = np.array(gyro["scale_factor_ppm"] + gyro["misalignment_arcsec"]) - GYRO_THETA[3:]
    sig = np.array(gyro["scale_factor_ppm_sigma"] + gyro["misalignment_arcsec_sigma"])
    assert np.all(np.abs(e) < 3.5 * sig), np.abs(e / sig).max()
