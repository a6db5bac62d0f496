"""Sensor and chamber simulator with known truth.

Chain of the simulation (every stage a pure function on arrays):

1. **Chamber** (:func:`chamber_air`): the programmed set-point ``S(t)`` [°C] goes
   through a slew-rate limiter (``max_rate_c_per_min``) and a first-order lag
   ``τ_air dA/dt = S_lim − A`` — the air temperature of a real chamber.
2. **Thermal network** (:func:`simulate_nodes`): a lumped RC network of the
   sensor, ``C dT/dt = −(L + diag(g_air)) T + g_air A(t) + P·H(t − t_on)``, with
   heat capacities ``C`` [J/K], conductances between nodes (Laplacian ``L``) and to
   the air ``g_air`` [W/K], and self-heating power ``P`` [W] switched on at power-on.
   Solved exactly for piecewise-linear air input in its modal form
   (``C^{-1/2} K C^{-1/2} = Q Λ Qᵀ``, time constants ``1/λ_i``), each mode a
   first-order recursion run by :func:`scipy.signal.lfilter`.  The node
   temperatures are the sensor's temperature channels ``T1..T4``; their exact
   derivatives give the temperature rates.
3. **Sensor** (:func:`simulate_sensor`): the error model
   ``F = (1 + δK(T)) · (ω_in + B0 + D + E(T, Ṫ, ∇T)) + noise`` where ``B0`` is the
   constant bias, ``D`` the turn-on offset (random per run: repeatability), ``E``
   the temperature-induced bias (:class:`BiasModel`: polynomial, rate,
   coupling, gradient, piecewise-linear, warm-up and hysteresis terms), ``δK`` the
   scale-factor temperature coefficient; noise (:func:`simulate_noise`): angle
   random walk, bias instability (flicker, PSD ``B²/(2πf)``), rate random walk,
   rate ramp (IEEE Std 952-1997 Annex C) and quantization — pulse counts with
   scale factor K for ring-laser gyros, output resolution otherwise.

Truth columns (all scenarios):

* ``truth_bias`` [°/h or mg]: the noise-free *temperature-induced* bias ``E`` —
  gyros: the temperature, rate, coupling, gradient (and hysteresis) terms, zero
  at ``t_ref_c`` (20 °C) with no temperature rate; it does **not** include the
  constant bias, the turn-on offset or the earth rate, which are in the truth
  JSON (``bias_constant``, ``turn_on_offset``, ``input``).  MEMS warm-up:
  ``Σ_j a_j(T0) ΔT^j`` (zero at power-on; the power-on value is
  ``start_bias``).  Accelerometers: the run's characteristic curve at ``T1``.
* ``truth_rate`` [same unit]: the noise-free output ``(1 + δK)(ω_in + B0 + D + E)``.

Presets (:data:`PRESETS`) and scenarios (:data:`SCENARIOS`, used by
``thermocal simulate``) are registries keyed by name.  Every random number comes
from an explicit :class:`numpy.random.Generator`; scenarios derive it from
``SeedSequence([seed, crc32(scenario)])`` so the same seed gives the same file.
"""

from __future__ import annotations

from thermocal.simulate.bias import (
    BiasModel,
    HysteresisTerm,
    PiecewiseTerm,
    WarmupTerm,
    play_operator,
)
from thermocal.simulate.lag import die_temperature, scenario_thermal_lag
from thermocal.simulate.noise import FLICKER_MAX_RATE_HZ, NoiseParams, flicker_noise, simulate_noise
from thermocal.simulate.scenarios import (
    DEFAULT_LATITUDE_DEG,
    IMU_BIAS_SPAN,
    IMU_CHANNELS,
    IMU_NOISE,
    ORIENTATIONS,
    SCENARIOS,
    TRUTH_FORMAT,
    TRUTH_VERSION,
    ScenarioFn,
    SimulateOptions,
    Simulation,
    run_scenario,
    scenario_accel_full_range,
    scenario_fog_slow,
    scenario_mems_imu,
    scenario_mems_warmup,
    scenario_rlg_modelling,
    scenario_rlg_validation,
    scenario_rng,
    scenario_turntable16,
    simulate_scenario,
)
from thermocal.simulate.sensors import (
    ACCEL,
    FOG,
    MEMS_GYRO,
    PRESETS,
    RLG,
    SensorOutput,
    SensorPreset,
    get_preset,
    simulate_sensor,
)
from thermocal.simulate.thermal import (
    ChamberModel,
    ThermalNetwork,
    ThermalResult,
    chamber_air,
    simulate_nodes,
    simulate_thermal,
    uniform_step,
)

SCENARIOS["thermal-lag"] = scenario_thermal_lag  # its module imports the scenarios' helpers

__all__ = [
    "ACCEL",
    "DEFAULT_LATITUDE_DEG",
    "FLICKER_MAX_RATE_HZ",
    "FOG",
    "IMU_BIAS_SPAN",
    "IMU_CHANNELS",
    "IMU_NOISE",
    "MEMS_GYRO",
    "ORIENTATIONS",
    "PRESETS",
    "RLG",
    "SCENARIOS",
    "TRUTH_FORMAT",
    "TRUTH_VERSION",
    "BiasModel",
    "ChamberModel",
    "HysteresisTerm",
    "NoiseParams",
    "PiecewiseTerm",
    "ScenarioFn",
    "SensorOutput",
    "SensorPreset",
    "SimulateOptions",
    "Simulation",
    "ThermalNetwork",
    "ThermalResult",
    "WarmupTerm",
    "chamber_air",
    "die_temperature",
    "flicker_noise",
    "get_preset",
    "play_operator",
    "run_scenario",
    "scenario_accel_full_range",
    "scenario_fog_slow",
    "scenario_mems_imu",
    "scenario_mems_warmup",
    "scenario_rlg_modelling",
    "scenario_rlg_validation",
    "scenario_rng",
    "scenario_thermal_lag",
    "scenario_turntable16",
    "simulate_nodes",
    "simulate_noise",
    "simulate_scenario",
    "simulate_sensor",
    "simulate_thermal",
    "uniform_step",
]
