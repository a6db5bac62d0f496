"""The noise per temperature bin (:mod:`thermocal.stability.noise_temperature`) against a
simulated chamber run whose gyro white noise grows 2 %/°C (``tests/helpers/chamber_noise``):
steps 10/25/40/55 °C with heater overshoot and ramps between, read by a 0.5 °C thermometer.
The truth of a bin is computed here from the simulator's true temperature of the samples the
reading puts in the bin, √mean(N(T)²) (white noise pools by variance)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chamber_noise import DN_PER_C, DT_S, N25, chamber, gyro_density, white
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.stability.noise_temperature import (
    AxisSamples,
    bin_edges,
    noise_at_temperature,
    noise_by_temperature,
)

EDGES = (5.0, 17.5, 32.5, 47.5, 62.5)


@pytest.fixture(scope="module")
def run() -> tuple[np.ndarray, np.ndarray, object]:
    rng = np.random.default_rng(7)
    true, reading = chamber(rng)
    gx = white(rng, gyro_density(true), true.size)  # N grows with temperature
    gy = white(rng, 1.2e-4, true.size)  # N constant
    axes = [AxisSamples("gx", "gyro", "rad/s", gx), AxisSamples("gy", "gyro", "rad/s", gy)]
    res = noise_by_temperature(axes, reading, DT_S, EDGES, confidence=0.95)
    return true, reading, res


def test_each_bin_recovers_the_simulated_density(run) -> None:  # type: ignore[no-untyped-def]
    true, reading, res = run
    assert len(res.used) == 4
    for b in res.used:
        last = b.high_c == EDGES[-1]
        inside = (reading >= b.low_c) & ((reading <= b.high_c) if last else (reading < b.high_c))
        truth = math.sqrt(float(np.mean(gyro_density(true[inside]) ** 2)))
        d = b.axis("gx").density
        assert d.low is not None and d.high is not None
        assert d.low <= truth <= d.high
        assert d.value == pytest.approx(truth, rel=0.02)
        assert b.axis("gy").density.value == pytest.approx(1.2e-4, rel=0.02)


def test_trend_is_the_simulated_slope(run) -> None:  # type: ignore[no-untyped-def]
    _, _, res = run
    gx = next(t for t in res.trends if t.axis == "gx" and t.term == "noise_density")
    gy = next(t for t in res.trends if t.axis == "gy" and t.term == "noise_density")
    assert gx.significant and "significant" in gx.words
    assert abs(gx.slope_per_c - N25 * DN_PER_C) <= 3.0 * gx.slope_sigma
    assert gx.slope_sigma < 0.1 * N25 * DN_PER_C
    assert not gy.significant and "not significant" in gy.words
    rw = next(t for t in res.trends if t.axis == "gx" and t.term == "random_walk")
    assert rw.slope_per_c is None and "bound" in rw.words  # 10 min holds show no K


def test_model_at_a_temperature_is_interpolated(run) -> None:  # type: ignore[no-untyped-def]
    _, _, res = run
    b1, b2 = res.used[2], res.used[3]  # around 45 °C
    at = noise_at_temperature(res, 45.0, inflate=2.0)
    w = (45.0 - b1.mean_c) / (b2.mean_c - b1.mean_c)
    expect = (1 - w) * b1.axis("gx").density.value + w * b2.axis("gx").density.value
    assert at.axis_of["gyroscope_noise_density"] == "gx"
    assert at.values["gyroscope_noise_density"] == pytest.approx(2.0 * expect, rel=1e-12)
    assert at.values["gyroscope_noise_density"] / 2.0 == pytest.approx(
        float(gyro_density(45.0)), rel=0.03
    )
    temp = next(i for i in at.advice if i.reason == "temperature" and "density" in i.key)
    worst = max(b.axis("gx").density.value for b in res.used)
    assert temp.factor == pytest.approx(worst / expect, rel=1e-12)
    with pytest.raises(ParameterError, match="outside the bins"):
        noise_at_temperature(res, 70.0)


def test_short_bins_refused_with_the_reason() -> None:
    rng = np.random.default_rng(1)
    t = np.concatenate([np.full(20_000, 20.0), np.full(5_000, 30.0), np.full(20_000, 40.0)])
    y = white(rng, 1e-4, t.size)
    res = noise_by_temperature(
        [AxisSamples("g", "gyro", "rad/s", y)], t, DT_S, (15.0, 25.0, 35.0, 45.0)
    )
    assert [b.refused is None for b in res.bins] == [True, False, True]
    assert "50 s in runs" in (res.bins[1].refused or "") and "120 s" in (res.bins[1].refused or "")


def test_bad_temperatures_and_edges() -> None:
    y = np.zeros(20_000)
    ax = [AxisSamples("g", "gyro", "rad/s", y)]
    with pytest.raises(ThermocalInputError, match="no finite temperature"):
        noise_by_temperature(ax, np.full(y.size, np.nan), DT_S, (0.0, 10.0))
    with pytest.raises(ParameterError, match="increasing"):
        noise_by_temperature(ax, np.full(y.size, 5.0), DT_S, (10.0, 0.0))
    assert bin_edges([21.3, 24.9, 38.2], 5.0) == (20.0, 25.0, 30.0, 35.0, 40.0)
    with pytest.raises(ParameterError, match="bins"):
        bin_edges([0.0, 100.0], 0.01)


def test_simulator_temperature_dependent_arw_recovered() -> None:
    """thermocal's own simulator (``NoiseParams.white_density_per_c``): the MEMS gyro preset
    (N = 9 °/h·√s at 25 °C, flicker B = 3 °/h, self-heating die) with N growing 2 %/°C, a
    chamber held at 0, 25 and 50 °C for 50 min each; the die thermometer read to 0.5 °C.
    Each bin's 95 % interval holds N at the bin's mean die temperature and the slope is the
    simulated N·0.02 per °C within 3σ."""
    import dataclasses

    from thermocal.simulate import MEMS_GYRO, simulate_thermal
    from thermocal.simulate.sensors import simulate_sensor

    noise = dataclasses.replace(MEMS_GYRO.noise, white_density_per_c=0.02)
    preset = dataclasses.replace(MEMS_GYRO, noise=noise)
    fs = 10.0
    t = np.arange(0.0, 3 * 3600.0, 1 / fs)
    prog_t = np.array([0.0, 600, 3600, 4200, 7200, 7800, 10800])
    prog_c = np.array([0.0, 0, 0, 25, 25, 50, 50])
    th = simulate_thermal(t, prog_t, prog_c, preset.network, warmed_up=True)
    out = simulate_sensor(th, preset, np.random.default_rng(3))
    die = th.temperatures_c[:, 0]
    axes = [AxisSamples("g", "gyro", "deg/h", out.signal - out.truth_rate)]
    res = noise_by_temperature(axes, np.round(die * 2) / 2, 1 / fs, (-10.0, 12.5, 37.5, 62.5),
                               confidence=0.95)  # fmt: skip
    to_si = math.pi / 180 / 3600  # °/h·√s → rad/s/√Hz
    assert len(res.used) == 3
    for b in res.used:
        truth = 9.0 * (1 + 0.02 * (b.mean_c - 25.0)) * to_si
        d = b.axis("g").density
        assert d.low is not None and d.high is not None
        assert d.low <= truth <= d.high and d.value == pytest.approx(truth, rel=0.03)
    tr = next(x for x in res.trends if x.term == "noise_density")
    assert tr.significant and tr.slope_per_c is not None and tr.slope_sigma is not None
    assert abs(tr.slope_per_c - 9.0 * 0.02 * to_si) <= 3.0 * tr.slope_sigma
