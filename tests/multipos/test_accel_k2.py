"""The accelerometer's K2 per axis from the gravity magnitude (:mod:`thermocal.multipos.
accel_k2`): pose means simulated here with a known K2 recovered within 3σ over many seeds,
the fixed point inverting the forward model written here, and the poses that cannot
separate K2 from the bias (the six faces, poses only along or across the axes) refused;
through ``thermocal multipos --accel-k2`` on a simulated session given a K2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.errors import DesignError
from thermocal.multipos.accel_k2 import fit_k2

G = 1000.0
K2 = np.array([0.5, -0.3, 0.2])
B = np.array([20.0, -10.0, 5.0])


def _e() -> np.ndarray:
    e = np.diag([3e-3, -2e-3, 1e-3])
    e[1, 0], e[2, 0], e[2, 1] = 1e-3, -2e-3, 0.5e-3
    return e


def _forward(a: np.ndarray) -> np.ndarray:
    """The model written here: f = (I + E) a + b + K2 (a/g)²."""
    return a @ (np.eye(3) + _e()).T + B + K2 * (a / G) ** 2


def _poses(rng: np.random.Generator, n: int = 30) -> np.ndarray:
    u = rng.normal(size=(n, 3))
    return G * u / np.linalg.norm(u, axis=1)[:, None]


def test_k2_recovered_within_3_sigma_over_seeds() -> None:
    z, zb = [], []
    for seed in range(20):
        rng = np.random.default_rng(seed)
        a = _poses(rng)
        f = _forward(a) + rng.normal(0, 0.02, a.shape)
        fit = fit_k2(f, np.full(len(a), 0.02), G)
        z += ((fit.k2_mg_per_g2 - K2) / fit.k2_sigma).tolist()
        zb += ((fit.linear.theta[:3] - B) / fit.linear.sigma[:3]).tolist()
    assert (np.abs(z) < 3).mean() >= 0.97 and (np.abs(zb) < 3).mean() >= 0.97
    assert 0.7 < float(np.sqrt(np.mean(np.square(z)))) < 1.3
    assert fit.k2_sigma.max() < 0.1  # K2 of 0.2 to 0.5 mg/g² seen beyond 3σ


def test_the_fixed_point_inverts_the_model() -> None:
    a = _poses(np.random.default_rng(1), 12)
    f = _forward(a)
    fit = fit_k2(f + np.random.default_rng(2).normal(0, 1e-9, f.shape), np.full(12, 1e-3), G)
    np.testing.assert_allclose(fit.k2_mg_per_g2, K2, atol=1e-5)
    np.testing.assert_allclose(fit.correct(f), a, atol=1e-6)


def test_six_faces_cannot_separate_k2() -> None:
    faces = np.vstack([np.eye(3), -np.eye(3)]) * G
    f = _forward(np.vstack([faces, faces]))
    with pytest.raises(DesignError, match="six faces cannot separate K2 from the bias"):
        fit_k2(f, np.full(12, 0.02), G)


def test_poses_only_along_or_across_an_axis_are_refused() -> None:
    """Gravity in the x-y plane at 45° and along ±z: z never seen at a slant."""
    ang = np.deg2rad(np.arange(0.0, 360.0, 30.0))
    a = G * np.column_stack([np.cos(ang), np.sin(ang), 0 * ang])
    a = np.vstack([a, [[0, 0, G], [0, 0, -G]]])
    with pytest.raises(DesignError, match=r"the axes z \(0\)"):
        fit_k2(_forward(a), np.full(len(a), 0.02), G)


def _session_with_k2(tmp: Path, k2_m_s2: np.ndarray) -> tuple[Path, dict]:
    assert main(["simulate", "multipos", "-o", str(tmp / "mp"), "--truth",
                 str(tmp / "t.json"), "--seed", "4"]) == 0  # fmt: skip
    truth = json.loads((tmp / "t.json").read_text())["files"][0]
    p = Path(truth["file"])
    df = pd.read_csv(p)
    f = df[["accel_x", "accel_y", "accel_z"]].to_numpy()
    df[["accel_x", "accel_y", "accel_z"]] = f + k2_m_s2 * (f / truth["gravity_m_s2"]) ** 2
    df.to_csv(p, index=False)
    return p, truth


def test_k2_through_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    k2 = np.array([0.05, -0.04, 0.03])  # m/s² per g²
    p, truth = _session_with_k2(tmp_path, k2)
    capsys.readouterr()
    args = ["multipos", str(p), "-o", str(tmp_path / "cal.json"), "--accel",
            "accel_x,accel_y,accel_z", "--accel-k2"]  # fmt: skip
    assert main([*args, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    run = doc["runs"][0]
    got = run["accel_k2"]
    # stored per standard g² (the session's per local g² times (g_n/g_L)²)
    g_l = truth["gravity_m_s2"]
    stored = doc["accel"]["k2"]
    assert stored["unit"] == "m/s^2/g^2" and doc["accel"]["method"] == "gravity-magnitude with K2"
    np.testing.assert_allclose(stored["k2"], np.array(got["k2"]) * (9.80665 / g_l) ** 2,
                               rtol=1e-12)  # fmt: skip
    assert got["unit"] == "m/s^2/g^2" and all(got["significant"])
    for v, e, t in zip(got["k2"], got["k2_sigma"], k2, strict=True):
        assert abs(v - t) < 3 * e
    # applied in the residuals: without K2 the poses scatter far beyond their noise
    assert run["accel"]["reduced_chi2"] > 20 and got["reduced_chi2"] < 4
    assert got["residual_rms_after"] < 0.2 * run["accel"]["misfit"]
    assert main(args) == 0
    assert "accelerometer K2 x" in capsys.readouterr().out
