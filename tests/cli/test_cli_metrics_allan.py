"""``thermocal metrics`` and ``thermocal allan`` command lines (INTERFACE.md)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import allantools
import numpy as np
import pandas as pd
import pytest

from thermocal import units
from thermocal.cli import main

INTERFACE_NOISE_KEYS = {
    "quantization",
    "angle_random_walk",
    "bias_instability",
    "rate_random_walk",
    "rate_ramp",
}


@pytest.fixture
def gyro_csv(tmp_path: Path) -> tuple[Path, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(4)
    n = 20_000
    t = np.arange(n) * 0.5  # 2 Hz
    temp = np.where(t < 5000.0, 20.0, 40.0)
    temp[(t >= 4000.0) & (t < 5000.0)] = np.linspace(20.0, 40.0, 2000)  # 1.2 °C/min ramp
    rate_dps = (5.0 + 0.01 * temp + rng.standard_normal(n) * 0.2) / 3600.0  # °/s
    path = tmp_path / "gyro run.csv"
    pd.DataFrame({"time": t, "gyro z deg/s": rate_dps, "T1": temp}).to_csv(path, index=False)
    return path, t, rate_dps * 3600.0, temp


def run_json(args: list[str], capsys: pytest.CaptureFixture[str]) -> dict[str, object]:
    code = main(args)
    out = capsys.readouterr().out
    assert code == 0, out
    obj = json.loads(out)
    assert isinstance(obj, dict)
    return obj


def test_metrics_json(gyro_csv, capsys) -> None:  # type: ignore[no-untyped-def]
    path, t, rate, _temp = gyro_csv
    obj = run_json(
        [
            "metrics",
            str(path),
            "--signal",
            "gyro z deg/s",
            "--signal-unit",
            "deg/s",
            "--average",
            "10",
            "--temps",
            "T1",
            "--latitude",
            "52",
            "--axis",
            "up",
            "--min-hold",
            "600",
            "--json",
        ],
        capsys,
    )
    for key in (
        "bias",
        "bias_stability",
        "averaging_s",
        "peak_to_peak",
        "unit",
        "temperature_sensitivity",
    ):
        assert key in obj
    # every figure in the data's own unit (°/s), named in "unit" (INTERFACE common rules)
    omega = units.EARTH_RATE_DEG_H * math.sin(math.radians(52.0)) / 3600.0  # [°/s]
    rate_dps = rate / 3600.0
    assert obj["unit"] == "deg/s" and obj["averaging_s"] == 10.0
    assert obj["earth_rate_removed"] == pytest.approx(omega, rel=1e-12)
    assert obj["bias"] == pytest.approx(rate_dps.mean() - omega, rel=1e-9)
    blocks = rate_dps.reshape(-1, 20).mean(axis=1)
    assert obj["bias_stability"] == pytest.approx(np.std(blocks, ddof=1), rel=1e-9)
    assert obj["peak_to_peak"] == pytest.approx(np.ptp(blocks), rel=1e-9)
    ts = obj["temperature_sensitivity"]
    assert isinstance(ts, dict) and ts["unit"] == "deg/s/degC"
    # two holds (20 and 40 °C): (B40 − B20)/20 with B = 5 + 0.01 T → 0.01 °/h/°C
    assert ts["ls_slope"] == pytest.approx(0.01 / 3600.0, abs=0.002 / 3600.0)
    assert ts["mean_abs_adjacent"] == pytest.approx(ts["ls_slope"], rel=1e-9)
    assert obj["n_stages"] == 2 and obj["n_samples"] == t.size


def test_allan_json_and_plot(gyro_csv, capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    path, _t, rate, _temp = gyro_csv
    png = tmp_path / "adev.png"
    obj = run_json(
        [
            "allan",
            str(path),
            "--signal",
            "gyro z deg/s",
            "--signal-unit",
            "deg/s",
            "--taus",
            "octave",
            "--plot",
            str(png),
            "--json",
        ],
        capsys,
    )
    for key in ("tau_s", "adev", "adev_low", "adev_high", "unit", "noise"):
        assert key in obj
    assert obj["unit"] == "deg/s"  # the data's own unit
    taus, devs, _e, ns = allantools.oadev(rate / 3600.0, rate=2.0, data_type="freq", taus="octave")
    np.testing.assert_allclose(obj["tau_s"], taus, rtol=1e-12)
    np.testing.assert_allclose(obj["adev"], devs, rtol=1e-9)
    assert obj["n_terms"] == ns.astype(int).tolist()
    assert np.all(np.array(obj["adev_low"]) < devs) and np.all(np.array(obj["adev_high"]) > devs)
    noise = obj["noise"]
    slope = obj["noise_slope"]
    assert isinstance(noise, dict) and isinstance(slope, dict)
    assert set(noise) == INTERFACE_NOISE_KEYS == set(slope)
    arw = noise["angle_random_walk"]
    # white rate noise 0.2 °/h at 2 Hz: N = 0.2·√0.5 °/h·√s = 0.2·√0.5/60 °/√h (an angle
    # figure: the data's angle unit, degrees)
    assert arw["unit"] == "deg/sqrt(h)"
    assert arw["value"] == pytest.approx(0.2 * math.sqrt(0.5) / 60.0, rel=0.05)
    assert noise["bias_instability"]["value"] is None and noise["bias_instability"]["reason"]
    # the 20 → 40 °C bias step makes the curve turn up inside the data: the slope method
    # reports its minimum / 0.664 (issue 29: always where the curve has a minimum), rough
    bi = slope["bias_instability"]
    k = int(np.argmin(obj["adev"]))
    assert bi["tau_s"] == obj["tau_s"][k] and bi["quality"] == "rough"
    assert bi["value"] == pytest.approx(obj["adev"][k] / 0.6643, rel=1e-3)
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_allan_decade_and_list(gyro_csv, capsys) -> None:  # type: ignore[no-untyped-def]
    path = gyro_csv[0]
    obj = run_json(
        ["allan", str(path), "--signal", "gyro z deg/s", "--taus", "decade", "--json"], capsys
    )
    assert obj["tau_s"][:4] == [0.5, 1.0, 2.0, 5.0]
    obj = run_json(
        ["allan", str(path), "--signal", "gyro z deg/s", "--taus", "1,10", "--json"], capsys
    )
    assert obj["tau_s"] == [1.0, 10.0]


@pytest.mark.parametrize("command", ["metrics", "allan"])
def test_missing_column_is_exit_2(gyro_csv, capsys, command) -> None:  # type: ignore[no-untyped-def]
    path = gyro_csv[0]
    code = main([command, str(path), "--signal", "nope", "--json"])
    cap = capsys.readouterr()
    assert code == 2
    assert cap.out == ""
    lines = cap.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "'nope'" in lines[0]


def test_bad_taus_and_average(gyro_csv, capsys) -> None:  # type: ignore[no-untyped-def]
    path = gyro_csv[0]
    assert main(["allan", str(path), "--signal", "gyro z deg/s", "--taus", "weekly"]) == 2
    assert "error:" in capsys.readouterr().err
    assert main(["metrics", str(path), "--signal", "gyro z deg/s", "--average", "1e9"]) == 2
    assert "two" in capsys.readouterr().err


def test_human_output(gyro_csv, capsys) -> None:  # type: ignore[no-untyped-def]
    path = gyro_csv[0]
    assert main(["allan", str(path), "--signal", "gyro z deg/s"]) == 0
    out = capsys.readouterr().out
    assert "quantization" in out and "ADEV" in out
    assert main(["metrics", str(path), "--signal", "gyro z deg/s", "--average", "10"]) == 0
    assert "stability" in capsys.readouterr().out
