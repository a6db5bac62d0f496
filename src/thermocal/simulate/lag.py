"""The ``thermal-lag`` scenario: a gyro whose bias follows its die temperature, which lags
the thermometer that is recorded by a first-order time constant — thermal hysteresis
between the heating and the cooling leg of a sweep.

Part of :mod:`thermocal.simulate`."""

from __future__ import annotations

from typing import Any

import numpy as np

from thermocal.errors import ThermocalInputError
from thermocal.profiles import Profile, check_program, find_holds
from thermocal.recording import Recording
from thermocal.simulate.scenarios import (
    TRUTH_FORMAT,
    TRUTH_VERSION,
    ProfileInput,
    ScenarioResult,
    _metadata,
    _time_grid,
    scenario_rng,
)
from thermocal.simulate.sensors import get_preset
from thermocal.simulate.thermal import FloatArray, _first_order, _plain_dict, uniform_step

LAG_PROGRAM: tuple[tuple[float, ...], tuple[float, ...]] = (
    (0.0, 1800.0, 4200.0, 6000.0, 8400.0, 10200.0),
    (20.0, 20.0, 60.0, 60.0, 20.0, 20.0),
)
"""The scenario's own program: 30 min at 20 °C, 1 °C/min to 60 °C, 30 min, back at
1 °C/min, 30 min (time [s], set-point [°C])."""

LAG_POLY: tuple[float, float] = (2.0, -0.02)
"""Bias ``c1 (z − 20) + c2 (z − 20)²`` of the die temperature z [°/h/°C, °/h/°C²]."""


def die_temperature(temp_c: FloatArray, tau_s: float, step_s: float) -> FloatArray:
    """The die temperature: ``τ dz/dt = T − z`` from ``z = T[0]``, the reading linear
    between samples (exact first-order hold, :func:`thermocal.simulate.thermal._first_order`
    with λ = 1/τ).

    Parameters
    ----------
    temp_c : numpy.ndarray
        The true temperature on a uniform grid [°C].
    tau_s : float
        The lag τ [s] (0: none).
    step_s : float
        The grid's step [s].

    Returns
    -------
    numpy.ndarray
        z [°C].
    """
    if tau_s <= 0:
        return temp_c.copy()
    return _first_order(temp_c, 1.0 / tau_s, 1.0 / tau_s, step_s, float(temp_c[0]))


def _program_arrays(profile: ProfileInput) -> tuple[FloatArray, FloatArray]:
    if profile is None:
        t, c = (np.asarray(a, dtype=np.float64) for a in LAG_PROGRAM)
        return t, c
    if isinstance(profile, Profile):
        return profile.knots()
    t, c = (np.asarray(a, dtype=np.float64) for a in profile)
    check_program(t, c, "chamber program")
    return t - t[0], c


def scenario_thermal_lag(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    lag_s: float = 300.0,
    quant_c: float = 0.0625,
    noise: float = 0.5,
    temp_noise_c: float = 0.0,
) -> ScenarioResult:
    """A MEMS gyro on a heat–cool sweep whose bias follows a lagging die temperature.

    The recorded temperature ``T1`` is the program (linear between its points), with white
    noise ``temp_noise_c`` and rounded to ``quant_c``; the die temperature ``z`` lags the
    true temperature by ``lag_s`` (:func:`die_temperature`); the bias is
    ``2 (z − 20) − 0.02 (z − 20)²`` [°/h] plus the constant bias, with white noise of σ
    ``noise`` [°/h] per sample.  The truth holds the lag, the polynomial and the legs of
    the program (its ramps).

    Parameters
    ----------
    seed : int
        The seed.
    profile : str, tuple of numpy.ndarray or None
        The program; None: :data:`LAG_PROGRAM`.
    rate_hz : float, optional
        Sample rate [Hz] (default 1).
    lag_s : float
        The die's lag τ [s].
    quant_c : float
        The thermometer's resolution [°C] (default 0.0625; 0: continuous).
    noise : float
        White noise σ of the gyro per sample [°/h].
    temp_noise_c : float
        White noise σ of the thermometer [°C].

    Returns
    -------
    list of (Recording, dict)
        One recording and its truth.

    Raises
    ------
    ThermocalInputError
        A negative lag, resolution or noise.
    """
    if min(lag_s, quant_c, noise, temp_noise_c) < 0:
        raise ThermocalInputError("thermal-lag: lag_s, quant_c and the noises must be ≥ 0")
    preset = get_preset("mems-gyro")
    rate = rate_hz or 1.0
    pt, pc = _program_arrays(profile)
    t = _time_grid(float(pt[-1]), rate)
    true_t = np.interp(t, pt, pc)
    step = uniform_step(t)
    z = die_temperature(true_t, lag_s, step)
    c1, c2 = LAG_POLY
    bias = c1 * (z - 20.0) + c2 * (z - 20.0) ** 2
    rng_g, rng_t = scenario_rng("thermal-lag", seed, 2)
    signal = preset.bias_constant + bias + noise * rng_g.standard_normal(t.size)
    reading = true_t + temp_noise_c * rng_t.standard_normal(t.size)
    if quant_c > 0:
        reading = quant_c * np.round(reading / quant_c)
    meta = _metadata(preset, "thermal-lag", seed, "", rate)
    rec = Recording.from_arrays(
        t,
        signals={"gyro": signal},
        temperatures={"T1": reading},
        signal_unit=preset.unit,
        other={"T_die": z, "truth_bias": bias},
        other_units={"T_die": "degC", "truth_bias": preset.unit},
        meta=meta,
    )
    return [(rec, _truth(seed, preset.unit, preset.bias_constant, rate, t.size, pt, pc, lag_s,
                         quant_c, noise, temp_noise_c))]  # fmt: skip


def _truth(
    seed: int,
    unit: str,
    bias_constant: float,
    rate: float,
    n: int,
    pt: FloatArray,
    pc: FloatArray,
    *params: float,
) -> dict[str, Any]:
    """The scenario's truth: its parameters and the program's ramps (the true legs)."""
    lag_s, quant_c, noise, temp_noise_c = params
    legs = [
        {"direction": "heating" if b > a else "cooling", "start_s": float(ta), "stop_s": float(tb)}
        for ta, tb, a, b in zip(pt[:-1], pt[1:], pc[:-1], pc[1:], strict=True)
        if b != a
    ]
    return _plain_dict(
        {
            "format": TRUTH_FORMAT,
            "version": TRUTH_VERSION,
            "scenario": "thermal-lag",
            "seed": int(seed),
            "label": "",
            "unit": unit,
            "signal": "gyro",
            "signal_unit": unit,
            "sample_rate_hz": rate,
            "n_samples": int(n),
            "bias_constant": bias_constant,
            "lag_s": lag_s,
            "poly": {"t_ref_c": 20.0, "coefficients": list(LAG_POLY)},
            "quant_c": quant_c,
            "noise": noise,
            "temp_noise_c": temp_noise_c,
            "legs": legs,
            "stages": [s.to_dict() for s in find_holds(pt, pc)],
            "truth_bias_definition": "c1 (z − 20) + c2 (z − 20)² of the die temperature z "
            "(column T_die), the constant bias excluded",
        }
    )
