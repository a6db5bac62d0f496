"""``thermocal metrics``: the drift angle as SPEC §1 (seed 001) means it (issue 25 item 6),
and every printed figure in the data's own unit (issue 25, last bullet).

The rate carries a bias ramp ``ω(t) = b + c·t`` (c = 1 °/h per hour); with samples every
second the trapezoid rule integrates ``ω − b0`` (linear) exactly, so the drift angle is the
closed form ``θ(t) = c t²/2 + (b − b0) t`` written below, never the same run's mean."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

T_END = 7200.0  # s
C_DEG_S_PER_S = 1.0 / 3600.0 / 3600.0  # 1 °/h per hour, in °/s per second
B_DEG_S = 0.01  # °/s


def _write(tmp_path: Path, column: str, rate: np.ndarray, t: np.ndarray) -> Path:
    path = tmp_path / "soak.csv"
    temp = 20.0 + 10.0 * t / T_END
    pd.DataFrame({"time (s)": t, column: rate, "T_gyro [degC]": temp}).to_csv(path, index=False)
    return path


def _json(args: list[str], capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    code = main(args)
    cap = capsys.readouterr()
    assert code == 0, cap.err
    obj = json.loads(cap.out)
    assert isinstance(obj, dict)
    return obj


def _closed_form_max(b0_minus_b: float, t: np.ndarray) -> tuple[float, float]:
    """max |θ| and where, of θ(t) = c t²/2 − (b0 − b) t on the sample times."""
    theta = C_DEG_S_PER_S * t**2 / 2.0 - b0_minus_b * t
    k = int(np.argmax(np.abs(theta)))
    return float(abs(theta[k])), float(t[k])


def test_drift_angle_max_default_reference_is_the_first_tenth(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    t = np.arange(0.0, T_END + 1.0, 1.0)
    rate = B_DEG_S + C_DEG_S_PER_S * t  # °/s
    path = _write(tmp_path, "gyro z [deg/s]", rate, t)
    obj = _json(["metrics", str(path), "--signal", "gyro z [deg/s]", "--json"], capsys)
    # b0 = mean over 0…720 s (the first 10 %): b + c·360; θ(t) = c t²/2 − 360 c t
    b0 = B_DEG_S + C_DEG_S_PER_S * 360.0
    expect_max = C_DEG_S_PER_S * (T_END**2 / 2.0 - 360.0 * T_END)  # reached at the end
    assert obj["drift_angle_unit"] == "deg"
    assert obj["drift_angle_max"] == pytest.approx(expect_max, rel=1e-9)
    assert expect_max == pytest.approx(1.8, rel=1e-12)  # 0.45 c T² with T = 2 h
    assert obj["drift_angle_max_time_s"] == T_END
    assert obj["drift_angle"] == pytest.approx(expect_max, rel=1e-9)
    ref = obj["drift_reference"]
    assert ref["kind"] == "window" and ref["start_s"] == 0.0 and ref["end_s"] == 720.0
    assert ref["bias"] == pytest.approx(b0, rel=1e-12) and ref["unit"] == "deg/s"
    # the figures are in °/s, the data's unit
    assert obj["unit"] == "deg/s"
    assert obj["bias"] == pytest.approx(float(np.mean(rate)), rel=1e-12)
    # about the same run's mean the end angle would be 0 and the largest c T²/8 at T/2
    assert abs(obj["drift_angle"]) > 1.0
    assert obj["drift_angle_max"] != pytest.approx(C_DEG_S_PER_S * T_END**2 / 8.0, rel=0.05)


def test_drift_angle_max_inside_the_run_with_a_late_reference(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    t = np.arange(0.0, T_END + 1.0, 1.0)
    rate = B_DEG_S + C_DEG_S_PER_S * t
    path = _write(tmp_path, "gyro z [deg/s]", rate, t)
    obj = _json(
        ["metrics", str(path), "--signal", "gyro z [deg/s]", "--drift-reference", "3600,7200",
         "--json"],
        capsys,
    )  # fmt: skip
    # b0 = b + c·5400; θ(t) = c t²/2 − 5400 c t: largest |θ| = c·5400²/2 at t = 5400 s
    mx, at = _closed_form_max(C_DEG_S_PER_S * 5400.0, t)
    assert at == 5400.0 and mx == pytest.approx(C_DEG_S_PER_S * 5400.0**2 / 2.0, rel=1e-12)
    assert obj["drift_angle_max"] == pytest.approx(mx, rel=1e-9)
    assert obj["drift_angle_max_time_s"] == at
    assert obj["drift_reference"]["n_samples"] == 3601


def test_drift_angle_rad_s_given_bias_and_earth_rate(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    lat = 45.0
    omega_up = 7.292115e-5 * math.sin(math.radians(lat))  # rad/s seen by an up axis
    c = C_DEG_S_PER_S * math.pi / 180.0  # rad/s per second
    b = 2.0e-4  # rad/s
    t = np.arange(0.0, T_END + 1.0, 1.0)
    rate = b + omega_up + c * t
    path = _write(tmp_path, "wz rad/s", rate, t)
    obj = _json(
        ["metrics", str(path), "--signal", "wz rad/s", "--latitude", str(lat), "--axis", "up",
         "--drift-bias", repr(b), "--average", "10", "--json"],
        capsys,
    )  # fmt: skip
    # θ = ∫ (ω − Ω − b) dt = c t²/2 [rad], largest at the end
    assert obj["unit"] == "rad/s" and obj["drift_angle_unit"] == "rad"
    assert obj["drift_angle_max"] == pytest.approx(c * T_END**2 / 2.0, rel=1e-9)
    assert obj["drift_angle_max_time_s"] == T_END
    assert obj["drift_reference"] == {
        "kind": "bias", "start_s": None, "end_s": None, "bias": b, "unit": "rad/s",
        "n_samples": None,
    }  # fmt: skip
    # printed figures in rad/s: bias with the earth rate removed, stability of 10 s means
    assert obj["earth_rate_removed"] == pytest.approx(omega_up, rel=1e-9)
    assert obj["bias"] == pytest.approx(float(np.mean(rate)) - omega_up, rel=1e-9)
    blocks = rate[: (t.size // 10) * 10].reshape(-1, 10).mean(axis=1)
    assert obj["bias_stability"] == pytest.approx(float(np.std(blocks, ddof=1)), rel=1e-9)
    assert obj["peak_to_peak"] == pytest.approx(float(np.ptp(blocks)), rel=1e-9)


def test_metrics_human_table_in_the_data_unit(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    t = np.arange(0.0, T_END + 1.0, 1.0)
    rate = B_DEG_S + C_DEG_S_PER_S * t
    path = _write(tmp_path, "gyro z [deg/s]", rate, t)
    assert main(["metrics", str(path), "--signal", "gyro z [deg/s]"]) == 0
    out = capsys.readouterr().out
    bias_line = next(line for line in out.splitlines() if "│ bias " in line)
    assert "deg/s" in bias_line and "deg/h" not in out
    value = float(bias_line.split("│")[2])
    assert value == pytest.approx(float(np.mean(rate)), rel=1e-5)
    assert "largest |θ|" in out and "first 10 %" in out


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--drift-reference", "9000,9999"], "holds no sample"),
        (["--drift-reference", "10"], "START,END"),
        (["--drift-reference", "0,600", "--drift-bias", "0.01"], "not both"),
    ],
)
def test_drift_reference_errors_exit_2(tmp_path, capsys, extra, words) -> None:  # type: ignore[no-untyped-def]
    t = np.arange(0.0, T_END + 1.0, 1.0)
    path = _write(tmp_path, "gyro z [deg/s]", B_DEG_S + C_DEG_S_PER_S * t, t)
    assert main(["metrics", str(path), "--signal", "gyro z [deg/s]", *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("error: ") and words in err[-1]
