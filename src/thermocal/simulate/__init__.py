"""Sensor and chamber simulator with known truth (SPEC §2, §6).

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
3. **Sensor** (:func:`simulate_sensor`): SPEC §2 error model
   ``F = (1 + δK(T)) · (ω_in + B0 + D + E(T, Ṫ, ∇T)) + noise`` where ``B0`` is the
   constant bias, ``D`` the turn-on offset (random per run: repeatability), ``E``
   the temperature-induced bias (:class:`BiasModel`: polynomial, rate,
   coupling, gradient, piecewise-linear, warm-up and hysteresis terms), ``δK`` the
   scale-factor temperature coefficient; noise (:func:`simulate_noise`): angle
   random walk, bias instability (flicker, PSD ``B²/(2πf)``), rate random walk,
   rate ramp (IEEE Std 952-1997 Annex C) and quantization — pulse counts with
   scale factor K for ring-laser gyros (SPEC §1), output resolution otherwise.

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
    BiasModel as BiasModel,
)
from thermocal.simulate.bias import (
    HysteresisTerm as HysteresisTerm,
)
from thermocal.simulate.bias import (
    PiecewiseTerm as PiecewiseTerm,
)
from thermocal.simulate.bias import (
    WarmupTerm as WarmupTerm,
)
from thermocal.simulate.bias import (
    play_operator as play_operator,
)
from thermocal.simulate.noise import (
    FLICKER_MAX_RATE_HZ as FLICKER_MAX_RATE_HZ,
)
from thermocal.simulate.noise import (
    NoiseParams as NoiseParams,
)
from thermocal.simulate.noise import (
    flicker_noise as flicker_noise,
)
from thermocal.simulate.noise import (
    simulate_noise as simulate_noise,
)
from thermocal.simulate.scenarios import (
    DEFAULT_LATITUDE_DEG as DEFAULT_LATITUDE_DEG,
)
from thermocal.simulate.scenarios import (
    IMU_BIAS_SPAN as IMU_BIAS_SPAN,
)
from thermocal.simulate.scenarios import (
    IMU_CHANNELS as IMU_CHANNELS,
)
from thermocal.simulate.scenarios import (
    IMU_NOISE as IMU_NOISE,
)
from thermocal.simulate.scenarios import (
    ORIENTATIONS as ORIENTATIONS,
)
from thermocal.simulate.scenarios import (
    SCENARIOS as SCENARIOS,
)
from thermocal.simulate.scenarios import (
    TRUTH_FORMAT as TRUTH_FORMAT,
)
from thermocal.simulate.scenarios import (
    TRUTH_VERSION as TRUTH_VERSION,
)
from thermocal.simulate.scenarios import (
    ScenarioFn as ScenarioFn,
)
from thermocal.simulate.scenarios import (
    SimulateOptions as SimulateOptions,
)
from thermocal.simulate.scenarios import (
    Simulation as Simulation,
)
from thermocal.simulate.scenarios import (
    run_scenario as run_scenario,
)
from thermocal.simulate.scenarios import (
    scenario_accel_full_range as scenario_accel_full_range,
)
from thermocal.simulate.scenarios import (
    scenario_fog_slow as scenario_fog_slow,
)
from thermocal.simulate.scenarios import (
    scenario_mems_imu as scenario_mems_imu,
)
from thermocal.simulate.scenarios import (
    scenario_mems_warmup as scenario_mems_warmup,
)
from thermocal.simulate.scenarios import (
    scenario_rlg_modelling as scenario_rlg_modelling,
)
from thermocal.simulate.scenarios import (
    scenario_rlg_validation as scenario_rlg_validation,
)
from thermocal.simulate.scenarios import (
    scenario_rng as scenario_rng,
)
from thermocal.simulate.scenarios import (
    scenario_turntable16 as scenario_turntable16,
)
from thermocal.simulate.scenarios import (
    simulate_scenario as simulate_scenario,
)
from thermocal.simulate.sensors import (
    ACCEL as ACCEL,
)
from thermocal.simulate.sensors import (
    FOG as FOG,
)
from thermocal.simulate.sensors import (
    MEMS_GYRO as MEMS_GYRO,
)
from thermocal.simulate.sensors import (
    PRESETS as PRESETS,
)
from thermocal.simulate.sensors import (
    RLG as RLG,
)
from thermocal.simulate.sensors import (
    SensorOutput as SensorOutput,
)
from thermocal.simulate.sensors import (
    SensorPreset as SensorPreset,
)
from thermocal.simulate.sensors import (
    get_preset as get_preset,
)
from thermocal.simulate.sensors import (
    simulate_sensor as simulate_sensor,
)
from thermocal.simulate.thermal import (
    ChamberModel as ChamberModel,
)
from thermocal.simulate.thermal import (
    ThermalNetwork as ThermalNetwork,
)
from thermocal.simulate.thermal import (
    ThermalResult as ThermalResult,
)
from thermocal.simulate.thermal import (
    chamber_air as chamber_air,
)
from thermocal.simulate.thermal import (
    simulate_nodes as simulate_nodes,
)
from thermocal.simulate.thermal import (
    simulate_thermal as simulate_thermal,
)
from thermocal.simulate.thermal import (
    uniform_step as uniform_step,
)
