"""``multipos --accel-k2`` as text shows what the calibration stores: the accelerometer's
table holds K2 (per axis, with σ) beside the bias, scale factors and misalignments fitted
with it, the summary's gravity-magnitude residual is that fit's, and the gyro's
g-sensitivity is a 3×3 table with σ (beyond 3σ starred).

A simulated session with K2 = (50, −40, 30) mg/g² and a known gyro ``A`` (the simulator's
truth): K2 shown within 4σ of the truth; the residual after equals that of the same session
simulated without K2 and fitted without it (the same noise: the floor) to within a factor
1.5, where the nine-parameter fit of the session with K2 leaves ten times more; every
element of ``A`` shown within 4σ of the truth and starred."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

from gsens_session import A_TRUE, MULTIPOS, run, write_session

K2_TRUE = np.array([50.0, -40.0, 30.0])  # mg per g²
NUM = r"([-+0-9.e]+)"


def _multipos(d: Path, name: str, *extra: str) -> tuple[str, dict]:
    code, text, err = run(["multipos", str(d / "s.csv"), *MULTIPOS, "-o", str(d / name), *extra])
    assert code == 0, err
    code, out, err = run(["multipos", str(d / "s.csv"), *MULTIPOS, "-o", str(d / name), *extra,
                          "--json"])  # fmt: skip
    assert code == 0, err
    return text, json.loads(out)


def _after(text: str) -> float:
    m = re.search(rf"gravity-magnitude residual rms {NUM} → {NUM} mg", text)
    assert m is not None, text
    return float(m.group(2))


def test_the_text_shows_what_is_stored(tmp_path: Path) -> None:
    write_session(tmp_path, seed=3, a_deg_h_g=np.zeros((3, 3)))
    floor = _after(_multipos(tmp_path, "floor.json")[0])
    write_session(tmp_path, seed=3, k2_mg_g2=K2_TRUE)
    nine = _after(_multipos(tmp_path, "nine.json")[0])
    text, d = _multipos(tmp_path, "k2.json", "--accel-k2")
    rows = re.findall(rf"│ K2 ([xyz]) +│ {NUM} +│ {NUM} +│ mg/g² +│", text)
    assert [r[0] for r in rows] == ["x", "y", "z"], text
    for (_ax, v, s), t in zip(rows, K2_TRUE, strict=True):
        assert abs(float(v) - t) < 4 * float(s), (v, s, t)
    after = _after(text)
    assert "(the fit with K2, stored)" in text
    assert after < 1.5 * floor and nine > 10 * floor, (after, floor, nine)
    assert after == float(f"{d['gravity_residual_rms_after']:.3g}")
    assert d["gravity_residual_rms_after"] == d["runs"][0]["accel_k2"]["residual_rms_after"]
    per_pose = np.array([p["gravity_residual"] for p in d["poses"]])
    rms = float(np.sqrt(np.mean(per_pose**2)))  # the poses' residuals are that fit's too
    assert abs(rms - d["gravity_residual_rms_after"]) < 1e-9 * rms
    cells = re.findall(
        rf"{NUM} ± {NUM}( \*)?", text.split("gyro g-sensitivity over 1 session(s)")[1]
    )
    assert len(cells) >= 9
    for (v, s, star), t in zip(cells[:9], (A_TRUE / 3600.0).ravel(), strict=True):
        assert abs(float(v) - t) < 4 * float(s) and star, (v, s, t)


def test_the_misfit_line_is_the_stored_fits() -> None:
    """A run fitted with K2: the poses' misfit said is the fit with K2's (none when that fit
    meets the noise, whatever the nine-parameter fit left)."""
    from thermocal.report.triad_text import multipos_summary_text

    k2 = {
        "k2": [1.0, 2.0, 3.0],
        "k2_sigma": [0.1] * 3,
        "unit": "mg/g^2",
        "residual_rms_after": 0.05,
    }

    def text(misfit_k2: float) -> list[str]:
        run_ = {"input": "a.csv", "accel": {"misfit": 0.7, "reduced_chi2": 120.0},
                "accel_k2": {**k2, "misfit": misfit_k2, "reduced_chi2": 3.21}}  # fmt: skip
        out = {"n_poses": 16, "gravity_residual_rms_before": 9.0, "runs": [run_],
               "gravity_residual_rms_after": 0.05, "pose_detection": []}  # fmt: skip
        return [b for b in multipos_summary_text(out, "mg", "c.json") if isinstance(b, str)]

    assert not any("scatter more than their noise" in b for b in text(0.0))
    line = next(b for b in text(0.25) if "scatter more than their noise" in b)
    assert line == (
        "a.csv: the poses scatter more than their noise (the fit with K2) (reduced χ² 3.21): "
        "each pose's σ inflated by a misfit of 0.25 mg, so that each counts as the misfit says"
    )
