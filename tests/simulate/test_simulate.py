"""Simulator: thermal network, chamber, noise, sensor truth and scenarios (SPEC §2, §6)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.integrate import solve_ivp

from thermocal import units
from thermocal.errors import ThermocalInputError
from thermocal.profiles import Hold, Profile, Ramp, builtin_profile, correlate
from thermocal.simulate import (
    PRESETS,
    SCENARIOS,
    ChamberModel,
    NoiseParams,
    ThermalNetwork,
    chamber_air,
    flicker_noise,
    play_operator,
    run_scenario,
    simulate_nodes,
    simulate_noise,
    simulate_sensor,
    simulate_thermal,
)


def avar(y: np.ndarray, m: int) -> float:
    """Non-overlapping Allan variance of rate samples y at cluster size m (IEEE 952 C.1)."""
    n = y.size // m
    means = y[: n * m].reshape(n, m).mean(axis=1)
    return float(0.5 * np.mean(np.diff(means) ** 2))


def avar_rel_sigma(n_clusters: int) -> float:
    """Relative standard deviation of a non-overlapping AVAR estimate (≈ 1/√(K−1))."""
    return 1.0 / math.sqrt(n_clusters - 1)


# --- thermal ------------------------------------------------------------------------------


def _conductance(net: ThermalNetwork) -> np.ndarray:
    k = net.n_nodes
    mat = np.zeros((k, k))
    for i in range(k):
        mat[i, i] = net.to_air_w_per_k[i]
    for i, j, g in net.links:
        mat[i, i] += g
        mat[j, j] += g
        mat[i, j] -= g
        mat[j, i] -= g
    return mat


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_time_constants_match_network_matrix(name: str) -> None:
    net = PRESETS[name].network
    a = -_conductance(net) / np.asarray(net.capacitance_j_per_k)[:, None]
    expected = np.sort(-1.0 / np.linalg.eigvals(a).real)[::-1]
    assert_allclose(net.time_constants_s(), expected, rtol=1e-10)
    assert net.n_nodes >= 4
    # different time constants, so lags and gradients exist
    assert np.min(np.diff(np.sort(expected))) > 1.0


def test_single_node_step_response_is_exponential() -> None:
    net = ThermalNetwork(("T1",), (100.0,), (2.0,), (), (0.0,))
    tau = 50.0
    assert net.time_constants_s()[0] == pytest.approx(tau)
    h = 0.5
    t = np.arange(2001) * h
    air = np.full(t.size, 30.0)
    air[0] = 20.0  # the air rises linearly from 20 to 30 °C over the first sample
    temps, rates = simulate_nodes(t, air, net, power_on_s=None)
    # exact solution for that input, t ≥ h
    after = t >= h
    exact = 30.0 - 10.0 * (tau / h) * math.expm1(h / tau) * np.exp(-t[after] / tau)
    assert_allclose(temps[after, 0], exact, atol=1e-9)
    assert_allclose(rates[after, 0], (30.0 - exact) / tau * 60.0, atol=1e-9)


def test_network_ramp_response_matches_ode_solver() -> None:
    net = PRESETS["rlg"].network
    h = 2.0
    t = np.arange(0, 4 * 3600 + h, h)
    air = 20.0 + 30.0 * np.clip(t / 1800.0, 0.0, 1.0)
    temps, _ = simulate_nodes(t, air, net, power_on_s=600.0)
    c = np.asarray(net.capacitance_j_per_k)
    k = _conductance(net)
    g_air = np.asarray(net.to_air_w_per_k)
    p = np.asarray(net.power_w)

    def rhs(tt: float, x: np.ndarray) -> np.ndarray:
        a_t = 20.0 + 30.0 * min(max(tt / 1800.0, 0.0), 1.0)
        return (-k @ x + g_air * a_t + (p if tt >= 600.0 else 0.0)) / c

    x0 = np.full(4, 20.0)
    ref = np.zeros_like(temps)
    bounds = [0.0, 600.0, 1800.0, float(t[-1])]
    for lo, hi in itertools.pairwise(bounds):
        sel = (t >= lo) & (t <= hi)
        sol = solve_ivp(rhs, (lo, hi), x0, t_eval=t[sel], rtol=1e-10, atol=1e-10, method="LSODA")
        ref[sel] = sol.y.T
        x0 = sol.y[:, -1]
    assert_allclose(temps, ref, atol=2e-6)


def test_warm_up_settles_to_steady_self_heating() -> None:
    net = PRESETS["mems-gyro"].network
    t = np.arange(0, 20 * net.time_constants_s()[0], 1.0)
    temps, rates = simulate_nodes(t, np.full(t.size, 25.0), net, power_on_s=0.0)
    rise = np.linalg.solve(_conductance(net), np.asarray(net.power_w))
    assert_allclose(temps[-1] - 25.0, rise, atol=1e-6)
    assert_allclose(net.steady_rise_c(), rise, rtol=1e-12)
    # exact rates agree with the numerical derivative of the temperatures
    num = np.gradient(temps[:, 0], t) * 60.0
    assert_allclose(rates[100:-100, 0], num[100:-100], atol=1e-3 * np.abs(num).max())
    # the die warms by several °C with a time constant of minutes
    assert rise[0] > 5.0
    t63 = t[np.argmax(temps[:, 0] - 25.0 >= 0.632 * rise[0])]
    assert 30.0 < t63 < 900.0


def test_chamber_rate_limit_and_lag() -> None:
    prog_t = np.array([0.0, 600.0, 601.0, 5000.0])
    prog_c = np.array([20.0, 20.0, 50.0, 50.0])
    t = np.arange(0.0, 5000.0, 1.0)
    sp, air = chamber_air(t, prog_t, prog_c, ChamberModel(3.0, 0.0))
    expected = np.clip(20.0 + 3.0 / 60.0 * (t - 600.0), 20.0, 50.0)
    assert_allclose(air, expected, atol=1e-9)
    assert_allclose(sp, np.interp(t, prog_t, prog_c))
    _, lagged = chamber_air(t, prog_t, prog_c, ChamberModel(3.0, 120.0))
    assert np.max(np.diff(lagged)) <= 3.0 / 60.0 + 1e-12
    # after the limited ramp ends (t = 1200 s) the lag decays with τ = 120 s
    i = np.searchsorted(t, [1500.0, 1620.0])
    ratio = (50.0 - lagged[i[1]]) / (50.0 - lagged[i[0]])
    assert ratio == pytest.approx(math.exp(-1.0), rel=1e-3)


def test_thermal_rejects_non_uniform_grid() -> None:
    net = PRESETS["rlg"].network
    with pytest.raises(ThermocalInputError, match="uniform"):
        simulate_nodes(np.array([0.0, 1.0, 3.0]), np.zeros(3), net)


def test_play_operator() -> None:
    x = np.array([0.0, 1.0, 2.0, 1.5, 0.0, -1.0])
    assert_allclose(play_operator(x, 1.0), [0.0, 0.5, 1.5, 1.5, 0.5, -0.5])


# --- noise --------------------------------------------------------------------------------


def test_white_noise_has_configured_arw() -> None:
    rng = np.random.default_rng(11)
    n_dens = 0.002 * 60.0  # 0.002 °/√h → [°/h·√s]
    dt = 0.1
    y = simulate_noise(400_000, dt, NoiseParams(white_density=n_dens), rng)
    for m in (10, 100):
        tau = m * dt
        k = y.size // m
        got = avar(y, m)
        assert got == pytest.approx(n_dens**2 / tau, rel=4 * avar_rel_sigma(k))


def test_flicker_noise_has_configured_bias_instability() -> None:
    rng = np.random.default_rng(5)
    b = 0.0015
    y = flicker_noise(2**20, 1.0, b, rng)
    plateau = 2.0 * math.log(2.0) / math.pi * b**2  # σ² = (2 ln 2/π) B² (IEEE 952)
    for m in (16, 64, 256):
        k = y.size // m
        # flicker AVAR estimates are less efficient than white ones: 5 × the white σ
        assert avar(y, m) == pytest.approx(plateau, rel=5 * avar_rel_sigma(k) + 0.03)


def test_rate_random_walk_and_ramp() -> None:
    rng = np.random.default_rng(3)
    kk = 1e-4
    y = simulate_noise(2**20, 1.0, NoiseParams(rate_random_walk=kk), rng)
    m = 4096
    got = avar(y, m)
    assert got == pytest.approx(kk**2 * m / 3.0, rel=0.35)  # 255 clusters, correlated
    r = 1e-6
    ramp = simulate_noise(1000, 1.0, NoiseParams(rate_ramp=r), rng)
    assert_allclose(np.diff(ramp), r)


# --- sensor and scenarios -------------------------------------------------------------------


def _static_thermal(preset: str, hours: float, rate_hz: float):  # type: ignore[no-untyped-def]
    p = PRESETS[preset]
    t = np.arange(0.0, hours * 3600.0, 1.0 / rate_hz)
    return simulate_thermal(
        t, np.array([0.0, t[-1]]), np.array([25.0, 25.0]), p.network, warmed_up=True
    )


def test_static_fog_run_has_configured_arw() -> None:
    p = PRESETS["fog"]
    th = _static_thermal("fog", 6.0, 1.0)
    assert np.ptp(th.temperatures_c, axis=0).max() < 1e-9
    out = simulate_sensor(th, p, np.random.default_rng(2))
    noise = out.signal - out.truth_rate
    n_dens = p.noise.white_density
    for m in (1, 4):
        expected = n_dens**2 / m + 2 * math.log(2) / math.pi * p.noise.bias_instability**2
        assert avar(noise, m) == pytest.approx(expected, rel=4 * avar_rel_sigma(noise.size // m))


def test_rlg_pulses_convert_to_the_true_rate() -> None:
    rec, truth = run_scenario("rlg-validation", 4, builtin_profile("rlg-validation", hold_s=1800))[
        0
    ]
    assert rec.units["gyro"] == "counts"
    assert np.all(rec.columns["gyro"] == np.round(rec.columns["gyro"]))
    rate, unit = rec.signal("gyro")
    assert unit == "deg/h"
    err = rate - rec.columns["truth_rate"]
    p = PRESETS["rlg"]
    # quantization of 1/K arcsec per sample is differenced, so the mean error is bounded
    # by one count over the run plus the white-noise mean
    bound = (
        1.0 / (p.scale_factor or 1.0) / err.size
        + 5 * p.noise.white_density / math.sqrt(err.size)
        + 3 * p.noise.bias_instability
    )
    assert abs(err.mean()) < bound
    omega = units.EARTH_RATE_DEG_H * math.sin(math.radians(45.0))
    assert truth["earth_rate_on_axis_deg_h"] == pytest.approx(omega)
    expected = omega + truth["bias_constant"] + truth["turn_on_offset"]
    # truth_rate = (1 + δK)(Ω + B0 + D + E) with δK ≤ 1e-5
    assert_allclose(
        rec.columns["truth_rate"], expected + rec.columns["truth_bias"], atol=1e-5 * 15.1
    )


def test_rlg_scenario_roles_metadata_and_truth_magnitudes() -> None:
    rec, truth = run_scenario("rlg-modelling", 1)[0]
    assert rec.signals == ("gyro",)
    assert rec.temperatures == ("T1", "T2", "T3", "T4")
    assert {"T_chamber", "truth_bias", "truth_rate"} <= set(rec.columns)
    assert rec.units["truth_bias"] == "deg/h"
    assert rec.meta.scale_factor == 4.0 and rec.meta.scale_factor_unit == "counts/arcsec"
    assert rec.meta.latitude_deg == 45.0 and rec.meta.axis == "up"
    assert rec.meta.sensor_id == "sim-rlg-001" and rec.meta.run_id == "rlg-modelling-seed1"
    assert rec.sample_rate_hz == pytest.approx(1.0)
    pp = float(np.ptp(rec.columns["truth_bias"]))
    assert 0.1 < pp < 0.5  # uncompensated nav-grade temperature-induced bias, °/h p-p
    temps = rec.temperatures_c()
    assert temps.min() < -10.0 and temps.max() > 50.0
    assert truth["preset"]["noise"]["white_density"] == pytest.approx(0.12)


def test_rlg_truth_is_in_the_span_of_the_seed000_model() -> None:
    rec, _ = run_scenario("rlg-validation", 2)[0]
    y = rec.columns["truth_bias"]
    temps = rec.temperatures_c()
    lag = 60
    rate = (temps[lag:] - temps[:-lag]) / 1.0  # °C/min over 60 s (seed 000)
    temps = temps[:-lag]
    y = y[:-lag]
    cols = [np.ones(y.size)]
    for k in range(4):
        x, d = temps[:, k], rate[:, k]
        cols += [x, x**2, x**3, d, d**2, d**3, x * d, (x * d) ** 2, (x * d) ** 3]
    a = np.column_stack(cols)
    scale = np.where(a.std(axis=0) > 0, a.std(axis=0), 1.0)
    coef, *_ = np.linalg.lstsq((a - a.mean(axis=0) * (scale != 1.0)) / scale, y, rcond=None)
    resid = y - ((a - a.mean(axis=0) * (scale != 1.0)) / scale) @ coef
    assert np.std(resid) < 0.02 * np.ptp(y)


def test_same_seed_same_data_and_different_seeds_differ() -> None:
    prof = builtin_profile("fog-slow", hold_s=600, rate_c_per_min=1.0)
    a = run_scenario("fog-slow", 9, prof)[0][0]
    b = run_scenario("fog-slow", 9, prof)[0][0]
    c = run_scenario("fog-slow", 10, prof)[0][0]
    for name in a.columns:
        assert np.array_equal(a.columns[name], b.columns[name])
    assert not np.array_equal(a.columns["gyro"], c.columns["gyro"])
    assert np.array_equal(a.columns["truth_bias"], c.columns["truth_bias"])


def test_modelling_and_validation_are_weakly_correlated_in_the_chamber() -> None:
    m = run_scenario("rlg-modelling", 0)[0][0]
    v = run_scenario("rlg-validation", 0)[0][0]
    res = correlate(m.time_s, m.columns["T_chamber"], v.time_s, v.columns["T_chamber"])
    assert res.weakly_correlated and abs(res.r) < 0.4


def test_fog_piecewise_fit_reduces_peak_to_peak_by_96_percent() -> None:
    rec, truth = run_scenario("fog-slow", 3)[0]
    assert truth["warmed_up"] is True
    s, unit = rec.signal("gyro")
    assert unit == "deg/h"
    temp = rec.temperature_c("T1")
    assert temp.min() < 18.0 and temp.max() > 42.0
    m = 100
    n = s.size // m
    sb = s[: n * m].reshape(n, m).mean(axis=1)
    tb = temp[: n * m].reshape(n, m).mean(axis=1)
    a = np.column_stack([np.ones(n), tb, np.maximum(tb - 23.6, 0.0), np.maximum(tb - 30.0, 0.0)])
    coef, *_ = np.linalg.lstsq(a, sb, rcond=None)
    resid = sb - a @ coef
    assert np.ptp(resid) <= 0.04 * np.ptp(sb)
    assert coef[1] == pytest.approx(0.35, abs=0.02)  # slope below 23.6 °C, °/h/°C


def test_mems_warmup_files_and_truth() -> None:
    runs = run_scenario("mems-warmup", 1)
    assert [t["label"] for _, t in runs] == ["T-40", "T-20", "T+0", "T+20", "T+40", "T+60", "T+80"]
    p = PRESETS["mems-gyro"]
    wu = p.bias_model.warmup
    assert wu is not None
    for rec, truth in runs:
        assert rec.duration_s >= 360.0
        t0 = truth["start_temperature_c"]
        assert t0 == pytest.approx(float(truth["label"][1:]), abs=0.05)
        d_t = rec.temperature_c("T1") - rec.temperature_c("T1")[0]
        assert d_t[-1] > 5.0  # strong self-heating
        a1 = wu.coefficients[0][0] + wu.coefficients[0][1] * t0 + wu.coefficients[0][2] * t0**2
        a2 = wu.coefficients[1][0] + wu.coefficients[1][1] * t0 + wu.coefficients[1][2] * t0**2
        assert truth["warmup_coefficients"] == pytest.approx([a1, a2])
        assert_allclose(rec.columns["truth_bias"], a1 * d_t + a2 * d_t**2, atol=1e-6)


def test_accel_runs_fall_on_distinct_characteristic_curves() -> None:
    p = PRESETS["accel"]
    temps = np.linspace(-40.0, 60.0, 201)
    x = temps - 20.0
    curves = [m.offset + m.poly[0][0] * x + m.poly[0][1] * x**2 for m in p.curves]
    for i in range(len(curves)):
        for j in range(i + 1, len(curves)):
            assert np.min(np.abs(curves[i] - curves[j])) > 1.0  # mg (seed 004)
    runs = run_scenario("accel-full-range", 2, runs=4)
    assert [t["label"] for _, t in runs] == ["run1", "run2", "run3", "run4"]
    assert len({t["curve"] for _, t in runs}) >= 2
    for rec, truth in runs:
        assert rec.units["accel"] == "mg"
        assert truth["input_mg"] == 0.0
        k = truth["curve"]
        model = p.curves[k]
        xt = rec.temperature_c("T1") - 20.0
        assert_allclose(
            rec.columns["truth_bias"],
            model.offset + model.poly[0][0] * xt + model.poly[0][1] * xt**2,
            atol=1e-9,
        )
        resid = rec.columns["accel"] - rec.columns["truth_bias"] - truth["turn_on_offset"]
        assert abs(resid.mean()) < 0.02
        assert resid.std() < 0.05  # the per-curve model can fit within 0.2 mg


def test_accel_gravity_input_up() -> None:
    prof = Profile(20.0, (Hold(600.0), Ramp(30.0, 2.0), Hold(600.0)))
    rec, truth = run_scenario("accel-full-range", 0, prof, runs=1, orientation="up")[0]
    assert truth["input_mg"] == pytest.approx(1000.0)
    assert rec.columns["accel"].mean() == pytest.approx(1000.0, abs=3.0)


def test_scenario_registry_and_bad_input() -> None:
    assert set(SCENARIOS) == {
        "rlg-modelling",
        "rlg-validation",
        "fog-slow",
        "mems-warmup",
        "accel-full-range",
        "turntable-16",
        "turntable-thermal",
        "mems-imu",
        "multipos",
        "ratetable",
        "tumble",
        "thermal-lag",
    }
    with pytest.raises(ThermocalInputError, match="unknown scenario"):
        run_scenario("nope", 0)
    with pytest.raises(ThermocalInputError, match="unexpected keyword"):
        run_scenario("fog-slow", 0, bogus=1)
    with pytest.raises(ThermocalInputError, match="seed"):
        run_scenario("fog-slow", -1)
    with pytest.raises(ThermocalInputError, match="orientation"):
        run_scenario("accel-full-range", 0, orientation="sideways")


def test_program_arrays_as_profile() -> None:
    t, c = builtin_profile("rlg-validation", hold_s=1200.0).program(60.0)
    rec, truth = run_scenario("rlg-validation", 0, (t + 100.0, c), rate_hz=0.5)[0]
    assert rec.sample_rate_hz == pytest.approx(0.5)
    assert rec.duration_s == pytest.approx(t[-1] - t[0], abs=2.0)
    assert len(truth["stages"]) == 8


def test_flicker_at_high_rate_keeps_its_plateau() -> None:
    b = 0.002
    y = simulate_noise(2**22 + 37, 0.01, NoiseParams(bias_instability=b), np.random.default_rng(8))
    plateau = 2.0 * math.log(2.0) / math.pi * b**2
    for m in (1000, 4000):
        k = y.size // m
        assert avar(y, m) == pytest.approx(plateau, rel=5 * avar_rel_sigma(k) + 0.03)
