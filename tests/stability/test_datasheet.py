"""Data-sheet figures to Kalibr's continuous-time noise model
(:mod:`thermocal.stability.datasheet`).

The worked example is the ADIS16448 data sheet (Analog Devices, Rev. C) as quoted in
Kalibr issue 63 ("Obtaining IMU parameters from datasheet"): gyro angular random walk
0.66 °/√hr and rate noise density 0.0135 °/s/√Hz at 25 Hz; accelerometer velocity random
walk 0.11 m/s/√hr and noise density 0.23 mg/√Hz.  Every SI value below is computed by hand
in the test from the definitions (√h = 60 √s, π/180, g0 = 9.80665 m/s²), not by thermocal.
"""

from __future__ import annotations

import math

import pytest

from thermocal.errors import ParameterError
from thermocal.stability.datasheet import (
    datasheet_noise,
    datasheet_yaml,
    normalize_unit,
    sheet_figure,
    walk_from_bias,
)

DEG = math.pi / 180.0
G0 = 9.80665


@pytest.mark.parametrize(
    ("sensor", "kind", "value", "unit", "si"),
    [
        ("gyro", "density", 0.66, "°/√hr", 0.66 * DEG / 60.0),  # 1.9199e-4 rad/s/√Hz
        ("gyro", "density", 0.0135, "deg/s/sqrt(Hz)", 0.0135 * DEG),  # 2.3562e-4
        ("gyro", "density", 14.0, "mdps/√Hz", 0.014 * DEG),  # BMI088-style 0.014 °/s/√Hz
        ("gyro", "density", 2.0e-4, "rad/s/√Hz", 2.0e-4),
        ("accel", "density", 0.11, "m/sec/√hr", 0.11 / 60.0),  # 1.8333e-3 m/s²/√Hz
        ("accel", "density", 0.23, "mg/√Hz", 0.23e-3 * G0),  # 2.2555e-3
        ("accel", "density", 175.0, "µg/√Hz", 175e-6 * G0),
        ("accel", "density", 2e-3, "m/s^2/sqrt(Hz)", 2e-3),
        ("gyro", "bias", 14.5, "°/hr", 14.5 * DEG / 3600.0),
        ("accel", "bias", 0.25, "mg", 0.25e-3 * G0),
        ("accel", "bias", 40.0, "ug", 40e-6 * G0),
        ("gyro", "walk", 2.0, "deg/h/sqrt(h)", 2.0 * DEG / 3600.0 / 60.0),
        ("accel", "walk", 3e-4, "m/s^3/sqrt(Hz)", 3e-4),
    ],
)
def test_units_converted_as_by_hand(
    sensor: str, kind: str, value: float, unit: str, si: float
) -> None:
    f = sheet_figure(sensor, kind, value, unit, parameter="x")  # type: ignore[arg-type]
    assert f.si == pytest.approx(si, rel=1e-12)


def test_adis16448_worked_example() -> None:
    """Kalibr issue 63's ADIS16448 figures: each pair of white-noise figures converted and
    the larger used, their disagreement stated; the random walk from the bias stability
    by K = √3 σ_min²/(2N) (the Allan minimum of N²/τ + K²τ/3), computed here."""
    figs = {
        "gyro_noise_density": (0.0135, "deg/s/sqrt(Hz)"),
        "gyro_arw": (0.66, "deg/sqrt(hr)"),
        "accel_noise_density": (0.23, "mg/sqrt(Hz)"),
        "accel_vrw": (0.11, "m/s/sqrt(hr)"),
        "gyro_bias_instability": (14.5, "deg/hr"),
        "accel_random_walk": (2e-4, "m/s^3/sqrt(Hz)"),
    }
    m = datasheet_noise(figs, 200.0, inflate=3.0)
    k = m.kalibr()
    n_g = 0.0135 * DEG  # 2.356e-4 > 0.66 °/√h = 1.920e-4
    assert k["gyroscope_noise_density"] == pytest.approx(3.0 * n_g, rel=1e-12)
    assert k["accelerometer_noise_density"] == pytest.approx(3.0 * 0.23e-3 * G0, rel=1e-12)
    sigma_min = 14.5 * DEG / 3600.0
    k_g = math.sqrt(3.0) * sigma_min**2 / (2.0 * n_g)
    assert k["gyroscope_random_walk"] == pytest.approx(3.0 * k_g, rel=1e-12)
    # the Allan deviation of N and K has its minimum σ_min: checked numerically here
    taus = [10 ** (i / 200) for i in range(-400, 1200)]
    adev_min = min(math.sqrt(n_g**2 / t + k_g**2 * t / 3.0) for t in taus)
    assert adev_min == pytest.approx(sigma_min, rel=1e-4)
    assert k["accelerometer_random_walk"] == pytest.approx(6e-4, rel=1e-12)
    assert k["update_rate"] == 200.0
    gyro_note = next(n for n in m.notes if n.startswith("gyro: the data sheet's two"))
    assert f"{(0.0135 * 60 / 0.66 - 1) * 100:.0f} %" in gyro_note  # 23 %
    text = datasheet_yaml(m, "adis16448.toml")
    assert "INFLATED x3" in text
    assert f"gyroscope_noise_density: {3 * n_g:.6e}" in text


def test_units_spelled_as_data_sheets_write_them() -> None:
    assert normalize_unit("°/√hr") == "deg/sqrt(h)"
    assert normalize_unit("dps/√Hz") == "deg/s/sqrt(hz)"
    assert normalize_unit("m/s²/Hz^0.5") == "m/s^2/sqrt(hz)"
    assert normalize_unit("µg/rtHz") == "ug/sqrt(hz)"


@pytest.mark.parametrize(
    ("figs", "rate", "words"),
    [
        ({"gyro_noise_density": (1e3, "deg/sqrt(h)")}, 200.0, "outside any gyro"),
        ({"gyro_noise_density": (0.01, "furlong/sqrt(Hz)")}, 200.0, "unit 'furlong"),
        ({"gyro_noise_density": (0.01, "mg/sqrt(Hz)")}, 200.0, "not one for a gyro"),
        ({"gyro_noise_density": (-0.01, "deg/s/sqrt(Hz)")}, 200.0, "positive"),
        ({"gyro_noise_density": (0.01, "deg/s/sqrt(Hz)"), "gyro_nois": (1, "x")}, 200.0,
         "unknown figure"),
        ({"accel_noise_density": (100, "ug/sqrt(Hz)")}, 200.0, "no gyro_noise_density"),
        ({"gyro_noise_density": (0.01, "deg/s/sqrt(Hz)")}, 1e6, "output rate"),
    ],
)  # fmt: skip
def test_refused_with_the_parameter_named(
    figs: dict[str, tuple[float, str]], rate: float, words: str
) -> None:
    with pytest.raises(ParameterError, match=words):
        datasheet_noise(figs, rate)


def test_random_walk_needed() -> None:
    figs = {
        "gyro_noise_density": (0.01, "deg/s/sqrt(Hz)"),
        "accel_noise_density": (100.0, "ug/sqrt(Hz)"),
        "accel_random_walk": (1e-4, "m/s^3/sqrt(Hz)"),
    }
    with pytest.raises(ParameterError, match="no gyro_random_walk and no gyro_bias_instability"):
        datasheet_noise(figs, 100.0)
    n = sheet_figure("accel", "density", 1e-3, "m/s^2/sqrt(Hz)", parameter="n")
    b = sheet_figure("accel", "bias", 1e-4, "m/s^2", parameter="b")
    assert walk_from_bias(n, b).si == pytest.approx(math.sqrt(3) * 1e-8 / 2e-3, rel=1e-12)
