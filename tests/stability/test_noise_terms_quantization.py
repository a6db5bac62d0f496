"""Output quantisation recognised from the samples (issue 29 item 2), through the CLI.

Records shaped like a static MEMS one, built here with known truth: 100 Hz for 1 h, a
gyro column in [°/s] written with two decimals, a bias, white rate noise and a flicker
floor (IEEE 952 PSD S(f) = (B²/2π)/f, shaped in the frequency domain).

* rate quantised to 0.05 °/s: the rounding error is white rate noise of variance q²/12
  per sample, so N² = σ_w² τ0 + q² τ0/12 (slope −½; no τ⁻¹ term);
* angle quantised to q_θ with the remainder carried (a pulse/delta-angle output): the
  rate is Δθ/τ0 on a 0.05 °/s lattice and IEEE 952 C.1 gives σ² = 3Q²/τ², Q = q_θ/√12;
* not quantised (written with nine significant digits): no quantisation reported.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

FS = 100.0
T0 = 1.0 / FS
N_SAMPLES = int(3600 * FS)
Q_RATE = 0.05  # rate quantisation step [°/s]
SIGMA_W = 0.05  # white rate noise per sample [°/s]
B_FLICKER = 0.004  # bias instability [°/s]
Q_ANGLE = Q_RATE * T0  # angle step [°] of the delta-angle record (same rate lattice)
COL = "gyro z [deg/s]"


def _flicker(rng: np.random.Generator, n: int, b: float) -> np.ndarray:
    f = np.fft.rfftfreq(n, T0)
    s = np.zeros_like(f)
    s[1:] = b**2 / (math.pi * f[1:])  # one-sided form of IEEE 952's two-sided (B²/2π)/f
    z = (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) / math.sqrt(2.0)
    return np.asarray(np.fft.irfft(z * np.sqrt(s * FS * n / 2.0), n))


def _write(path: Path, rate: np.ndarray, fmt: str) -> Path:
    t = np.arange(rate.size) * T0
    with path.open("w", encoding="utf-8") as fh:
        fh.write(f"time [s],{COL}\n")
        for ti, ri in zip(t, rate, strict=True):
            fh.write(f"{ti:.2f},{ri:{fmt}}\n")
    return path


@pytest.fixture(scope="module")
def records(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    rng = np.random.default_rng(2929)
    d = tmp_path_factory.mktemp("quant")
    rate = 0.3 + rng.standard_normal(N_SAMPLES) * SIGMA_W + _flicker(rng, N_SAMPLES, B_FLICKER)
    # angle-quantised: small white noise (the τ⁻¹ region spans the short τ), remainder carried
    r2 = 0.3123 + rng.standard_normal(N_SAMPLES) * 0.02 + _flicker(rng, N_SAMPLES, 0.0005)
    theta = np.concatenate([[0.0], np.cumsum(r2) * T0])
    delta = np.diff(np.round(theta / Q_ANGLE)) * Q_ANGLE / T0
    return {
        "rate": _write(d / "rate_q.csv", np.round(rate / Q_RATE) * Q_RATE, ".2f"),
        "plain": _write(d / "plain.csv", rate, ".9g"),
        "angle": _write(d / "angle_q.csv", delta, ".2f"),
    }


def _allan(path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> str:
    capsys.readouterr()
    assert main(["allan", str(path), "--time", "time [s]", "--signal", COL, *extra]) == 0
    return capsys.readouterr().out


def test_rate_quantisation_is_recognised_as_white_noise(
    records: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    doc = json.loads(_allan(records["rate"], capsys, "--json"))
    oq = doc["output_quantization"]
    assert oq is not None
    assert oq["value"] == pytest.approx(Q_RATE, rel=1e-9)
    assert oq["unit"] == "deg/s" and oq["kind"] == "rate" and oq["levels"] >= 5
    assert "lattice" in oq["source"]
    # N_q = q √(τ0/12) [°/s·√s] = 60 × that in °/√h (√h = 60 √s)
    n_q = Q_RATE * math.sqrt(T0 / 12.0) * 60.0
    assert oq["white_density"]["value"] == pytest.approx(n_q, rel=1e-9)
    assert oq["white_density"]["unit"] == "deg/sqrt(h)"
    # the measured N holds the quantisation's white noise: N² = σ_w² τ0 + q² τ0/12
    n_white = SIGMA_W * math.sqrt(T0) * 60.0
    n_true = math.hypot(n_white, n_q)
    arw = doc["noise_slope"]["angle_random_walk"]
    assert arw["low"] * 0.98 <= n_true <= arw["high"] * 1.02, (arw, n_true)
    assert not arw["low"] * 0.98 <= n_white <= arw["high"] * 1.02  # 4 % apart: it matters
    assert oq["share"] == pytest.approx(n_q**2 / n_true**2, abs=0.01)
    # no τ⁻¹ term, and the reason says why
    assert doc["noise"]["quantization"]["value"] is None
    assert "rate output is quantised" in doc["noise"]["quantization"]["reason"]
    text = _allan(records["rate"], capsys)
    assert "output quantised: step 0.05 deg/s" in text


def test_angle_quantisation_is_the_tau_minus_one_term(
    records: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    doc = json.loads(_allan(records["angle"], capsys, "--json"))
    oq = doc["output_quantization"]
    assert oq is not None and oq["kind"] == "angle"
    assert oq["value"] == pytest.approx(Q_RATE, rel=1e-6)
    q_true = Q_ANGLE / math.sqrt(12.0) * 3600.0  # Q = q_θ/√12 [°] in arcsec
    assert oq["angle_q"]["value"] == pytest.approx(q_true, rel=1e-6)
    assert oq["angle_q"]["unit"] == "arcsec"
    fit_q = doc["noise"]["quantization"]
    assert fit_q["value"] is not None
    assert fit_q["low"] * 0.98 <= q_true <= fit_q["high"] * 1.02, (fit_q, q_true)
    assert oq["share"] == pytest.approx(1.0, abs=0.05)


def test_no_false_positive_on_unquantised_data(
    records: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    doc = json.loads(_allan(records["plain"], capsys, "--json"))
    assert doc["output_quantization"] is None
    assert "quantised" not in (doc["noise"]["quantization"]["reason"] or "")
    assert "output quantised" not in _allan(records["plain"], capsys)


def test_noise_command_reports_it_per_axis(tmp_path: Path) -> None:
    rng = np.random.default_rng(29)
    n = N_SAMPLES // 4
    cols = ("gyro x [deg/s]", "gyro y [deg/s]", "gyro z [deg/s]")
    rates = [0.1 * k + rng.standard_normal(n) * SIGMA_W for k in range(3)]
    t = np.arange(n) * T0
    files = {}
    for key in ("rate", "plain"):
        data = [np.round(r / Q_RATE) * Q_RATE if key == "rate" else r for r in rates]
        path = tmp_path / f"{key}.csv"
        digits = "%.2f" if key == "rate" else "%.9g"
        np.savetxt(
            path, np.column_stack([t, *data]), delimiter=",", comments="",
            header="time [s]," + ",".join(cols), fmt=["%.2f"] + [digits] * 3,
        )  # fmt: skip
        files[key] = path
        out = tmp_path / f"{key}.json"
        args = ["noise", str(path), "--time", "time [s]", "--gyro", ",".join(cols)]
        assert main([*args, "--format", "json", "-o", str(out)]) == 0
        for c in cols:
            oq = json.loads(out.read_text(encoding="utf-8"))["axes"][c]["output_quantization"]
            if key == "plain":
                assert oq is None
            else:
                assert oq["value"] == pytest.approx(Q_RATE, rel=1e-9)
                assert oq["unit"] == "deg/s" and oq["kind"] == "rate"
    # Kalibr's file needs the accelerometers: three unquantised [mg] columns beside them
    acc = ("acc x [mg]", "acc y [mg]", "acc z [mg]")
    imu = tmp_path / "imu.csv"
    data = np.column_stack(
        [t, *[np.round(r / Q_RATE) * Q_RATE for r in rates]]
        + [g + rng.standard_normal(n) for g in (0.0, 0.0, 1000.0)]
    )
    np.savetxt(
        imu, data, delimiter=",", comments="", header="time [s]," + ",".join(cols + acc),
        fmt=["%.2f"] * 4 + ["%.9g"] * 3,
    )  # fmt: skip
    yml = tmp_path / "imu.yaml"
    args = ["noise", str(imu), "--time", "time [s]", "--gyro", ",".join(cols)]
    assert main([*args, "--accel", ",".join(acc), "--format", "kalibr", "-o", str(yml)]) == 0
    assert "is quantised at 0.05 deg/s" in yml.read_text(encoding="utf-8")
