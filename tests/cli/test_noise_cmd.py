"""``thermocal noise``: Kalibr's imu.yaml and the JSON noise model of a simulated 6-axis IMU
(issue 29 item 4).

The record is built here: 100 Hz for 1 h, each axis white noise of a known continuous-time
density σ_n (discrete σ = σ_n/√Δt) plus a random walk of known strength σ_b (increments
σ_b·√Δt), gyros stored in [°/s] and accelerometers in [mg] with the units in the column
names, so that the SI values Kalibr wants need both conversions.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from thermocal.cli import main

FS_HZ = 100.0
DT_S = 1.0 / FS_HZ
DURATION_S = 3600.0
G_M_S2 = 9.80665  # standard gravity, written here, not taken from thermocal
GYRO_DENSITY = (1.5e-4, 1.7e-4, 1.6e-4)  # rad/s/√Hz
GYRO_WALK = (1.5e-5, 2.0e-5, 1.8e-5)  # rad/s²/√Hz
ACCEL_DENSITY = (2.0e-3, 1.8e-3, 2.2e-3)  # m/s²/√Hz
ACCEL_WALK = (3.0e-4, 2.5e-4, 2.8e-4)  # m/s³/√Hz
GYRO_COLS = ("gyro x [deg/s]", "gyro y [deg/s]", "gyro z [deg/s]")
ACCEL_COLS = ("acc x [mg]", "acc y [mg]", "acc z [mg]")
KALIBR_KEYS = {
    "gyroscope_noise_density",
    "gyroscope_random_walk",
    "accelerometer_noise_density",
    "accelerometer_random_walk",
    "update_rate",
    "rostopic",
}


def _axis(rng: np.random.Generator, n: int, density: float, walk: float) -> np.ndarray:
    white = rng.normal(0.0, density / math.sqrt(DT_S), n)
    return white + np.cumsum(rng.normal(0.0, walk * math.sqrt(DT_S), n))


@pytest.fixture(scope="module")
def imu_csv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    import pandas as pd

    rng = np.random.default_rng(2029)
    n = int(DURATION_S * FS_HZ)
    cols: dict[str, np.ndarray] = {"time [s]": np.arange(n) * DT_S}
    for c, d, w in zip(GYRO_COLS, GYRO_DENSITY, GYRO_WALK, strict=True):
        cols[c] = np.degrees(0.02 + _axis(rng, n, d, w))  # rad/s → °/s, with a bias
    for c, d, w, g in zip(ACCEL_COLS, ACCEL_DENSITY, ACCEL_WALK, (0.0, 0.0, G_M_S2), strict=True):
        cols[c] = (0.3 + g + _axis(rng, n, d, w)) / G_M_S2 * 1e3  # m/s² → mg, z up
    path = tmp_path_factory.mktemp("noise") / "imu.csv"
    pd.DataFrame(cols).to_csv(path, index=False, float_format="%.9g")
    return path


def _run(path: Path, out: Path, fmt: str, *extra: str) -> int:
    return main(
        ["noise", str(path), "--time", "time [s]", "--gyro", ",".join(GYRO_COLS),
         "--accel", ",".join(ACCEL_COLS), "--format", fmt, "-o", str(out), *extra]
    )  # fmt: skip


def test_kalibr_yaml_gives_the_simulated_densities(imu_csv: Path, tmp_path: Path) -> None:
    out = tmp_path / "imu.yaml"
    assert _run(imu_csv, out, "kalibr", "--rostopic", "/imu0") == 0
    text = out.read_text(encoding="utf-8")
    doc = yaml.safe_load(text)
    assert set(doc) == KALIBR_KEYS
    assert all(isinstance(doc[k], float) for k in KALIBR_KEYS - {"rostopic"})
    assert doc["rostopic"] == "/imu0"
    assert doc["update_rate"] == pytest.approx(FS_HZ, rel=1e-9)
    # Kalibr takes one number per sensor: the largest axis
    assert doc["gyroscope_noise_density"] == pytest.approx(max(GYRO_DENSITY), rel=0.10)
    assert doc["accelerometer_noise_density"] == pytest.approx(max(ACCEL_DENSITY), rel=0.10)
    # random walks: the order of magnitude here, their intervals in the JSON test
    assert doc["gyroscope_random_walk"] == pytest.approx(max(GYRO_WALK), rel=0.3)
    assert doc["accelerometer_random_walk"] == pytest.approx(max(ACCEL_WALK), rel=0.3)
    # a comment per key: which term, which τ, the discrete-time conversion
    for key in KALIBR_KEYS - {"update_rate", "rostopic"}:
        block = text.split(f"\n{key}:")[0].rsplit("\n\n", 1)[-1]
        assert f"# {key} [" in block
        assert "τ =" in block
        assert ("σ_d = σ_c / √Δt" if "density" in key else "σ_d = σ_c · √Δt") in block
    assert "LARGEST" in text
    assert "INFLATED" not in text


def test_json_random_walks_within_their_intervals(imu_csv: Path, tmp_path: Path) -> None:
    out = tmp_path / "noise.json"
    # 99.7 %: the fit's interval treats neighbouring ADEV points as independent, so it is
    # narrower than the scatter over seeds (measured coverage ≈ 55 % at a nominal 68 %)
    assert _run(imu_csv, out, "json", "--confidence", "0.9973") == 0
    doc = json.loads(out.read_text(encoding="utf-8"))
    truth = {
        **{c: (d, w) for c, d, w in zip(GYRO_COLS, GYRO_DENSITY, GYRO_WALK, strict=True)},
        **{c: (d, w) for c, d, w in zip(ACCEL_COLS, ACCEL_DENSITY, ACCEL_WALK, strict=True)},
    }
    assert set(doc["axes"]) == set(truth)
    for name, (density, walk) in truth.items():
        ax = doc["axes"][name]
        assert ax["noise_density"]["value"] == pytest.approx(density, rel=0.10), name
        rw = ax["random_walk"]
        assert rw["low"] <= walk <= rw["high"], (name, rw)
        assert rw["method"] in ("slope", "fit")
        # every term with its interval, unit, τ, method, quality
        for term in ax["terms"].values():
            assert {"value", "unit", "low", "high", "tau_s", "method", "quality"} <= set(term)
        arw = ax["terms"]["angle_random_walk"]
        if name in GYRO_COLS:  # the data's own unit: °/s data → ARW in °/√h (= 60·°/s·√s)
            assert arw["unit"] == "deg/sqrt(h)"
            assert arw["value"] == pytest.approx(math.degrees(density) * 60.0, rel=0.10)
    assert doc["kalibr"]["gyroscope_noise_density"] == max(
        doc["axes"][c]["noise_density"]["value"] for c in GYRO_COLS
    )


def test_inflate_is_stated_and_applied(imu_csv: Path, tmp_path: Path) -> None:
    plain, inflated = tmp_path / "a.yaml", tmp_path / "b.yaml"
    assert _run(imu_csv, plain, "kalibr") == 0
    assert _run(imu_csv, inflated, "kalibr", "--inflate", "3") == 0
    a = yaml.safe_load(plain.read_text(encoding="utf-8"))
    b = yaml.safe_load(inflated.read_text(encoding="utf-8"))
    for key in ("gyroscope_noise_density", "accelerometer_random_walk"):
        assert b[key] == pytest.approx(3.0 * a[key], rel=1e-6)
    assert "INFLATED ×3" in inflated.read_text(encoding="utf-8")


def test_bad_input_is_exit_2(
    imu_csv: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert _run(imu_csv, imu_csv, "kalibr") == 2  # never over the input
    assert "refusing to write over the input" in capsys.readouterr().err
    assert _run(imu_csv, tmp_path / "x.yaml", "xml") == 2
    gyro_only = [
        "noise",
        str(imu_csv),
        "--time",
        "time [s]",
        "--gyro",
        ",".join(GYRO_COLS),
        "-o",
        str(tmp_path / "g"),
    ]
    assert main([*gyro_only, "--format", "kalibr"]) == 2  # Kalibr needs the accelerometer
    assert (
        main(
            [
                "noise",
                str(imu_csv),
                "--time",
                "time [s]",
                "--gyro",
                "a,b",
                "-o",
                str(tmp_path / "g"),
            ]
        )
        == 2
    )
    assert _run(imu_csv, tmp_path / "y.yaml", "kalibr", "--inflate", "0.5") == 2
    # accelerometer columns declared as a rate
    args = ["noise", str(imu_csv), "--time", "time [s]", "--gyro", ",".join(ACCEL_COLS), "--accel",
            ",".join(ACCEL_COLS), "--format", "json", "-o", str(tmp_path / "z.json")]  # fmt: skip
    assert main(args) == 2
    assert not (tmp_path / "x.yaml").exists() and not (tmp_path / "z.json").exists()
