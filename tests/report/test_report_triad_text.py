"""Calibrations of triads as text (:mod:`thermocal.report.triad_text`): each cell is the
result's number with its stated digits; the gyro's misfit line follows the threshold
χ²_ν > 1 + 3·√(2/ν) computed here."""

from __future__ import annotations

import math

from thermocal.report.text import TextTable
from thermocal.report.triad_text import (
    gyro_misfit_line,
    multipos_summary_text,
    pose_detection_lines,
)


def _triad(bias: float) -> dict:
    return {
        "method": "Tedaldi",
        "bias": [bias, 0.0, -bias],
        "bias_sigma": [0.001, 0.001, 0.001],
        "bias_unit": "m/s^2",
        "scale_factor_ppm": [120.0, -80.0, 5.0],
        "scale_factor_ppm_sigma": [3.0, 3.0, 3.0],
        "misalignment_names": ["yz", "zy", "xz", "zx", "xy", "yx"],
        "misalignment_arcsec": [10.0, -4.0, 0.0, 0.0, 0.0, 0.0],
        "misalignment_arcsec_sigma": [2.0, 2.0, 0.0, 0.0, 0.0, 0.0],
    }


def _gyro_run(chi2: float, dof: int) -> dict:
    return {"input": "a.csv", "gyro": {"dof": dof, "reduced_chi2": chi2, "n_motions": 12,
                                       "model": "full"}}  # fmt: skip


def test_gyro_misfit_line_at_the_three_sigma_threshold() -> None:
    dof = 18
    limit = 1 + 3 * math.sqrt(2 / dof)  # 3 standard deviations of χ²_ν above its mean 1
    assert gyro_misfit_line(_gyro_run(limit * 0.99, dof)) is None
    line = gyro_misfit_line(_gyro_run(limit * 1.01, dof))
    assert line is not None and line.startswith("a.csv: the gyro's 12 motions scatter")
    assert f"reduced χ² {limit * 1.01:.3g} on 18 degrees of freedom, full model" in line
    assert gyro_misfit_line({"input": "a.csv"}) is None


def test_multipos_text_tables_and_summary() -> None:
    summary = {
        "accel": _triad(0.0123456),
        "n_poses": 14,
        "gravity_residual_rms_before": 0.0456789,
        "gravity_residual_rms_after": 0.00123456,
        "runs": [{"input": "a.csv", "accel": {"misfit": None}}],
        "unit": "m/s^2",
        "pose_detection": [],
    }
    blocks = multipos_summary_text(summary, "m/s^2", "cal.json")
    table = blocks[0]
    assert isinstance(table, TextTable) and table.title == "accel triad (Tedaldi)"
    assert table.rows[0] == ("bias x", "0.012346", "0.001", "m/s^2")
    assert table.rows[3] == ("scale factor x", "120", "3", "ppm")
    assert table.rows[8] == ("misalignment xz", "0", "held (not fitted)", "″")
    assert blocks[1] == (
        "14 poses; gravity-magnitude residual rms 0.0457 → 0.00123 m/s^2; written cal.json"
    )
    assert len(blocks) == 2


def test_pose_detection_lines_name_the_rejected_stretches() -> None:
    out = {
        "unit": "g",
        "pose_detection": [
            {"input": "a.csv", "n_poses": 9, "window_s": 0.5, "static_s": 2.0,
             "accel": {"still_limit_rms": 0.00321, "limit_set_by": "noise",
                       "noise_sigma": [0.001, 0.002, 0.003], "motion_rms": 0.5},
             "rejected": [{"start": 1.0, "end": 2.5, "reason": "drifts"}]},
        ],
    }  # fmt: skip
    assert pose_detection_lines(out) == [
        "a.csv: 9 poses (window 0.5 s, still for ≥ 2 s below an accelerometer rms of "
        "0.00321 g, set by the noise: noise 0.001, 0.002, 0.003, motions 0.5); 1 rejected",
        "  rejected 1.0…2.5: drifts",
    ]
