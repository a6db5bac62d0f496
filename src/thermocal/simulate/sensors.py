"""Sensor presets (ring-laser, fibre-optic and MEMS gyros, accelerometers) and one
simulated sensor output.

Part of :mod:`thermocal.simulate`."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import ThermocalInputError
from thermocal.simulate.bias import BiasModel, PiecewiseTerm, WarmupTerm
from thermocal.simulate.noise import NoiseParams, simulate_noise
from thermocal.simulate.thermal import (
    ChamberModel,
    ThermalNetwork,
    ThermalResult,
    _plain_dict,
)

FloatArray = npt.NDArray[np.float64]
ProgramArrays = tuple[FloatArray, FloatArray]
Truth = dict[str, Any]


# --- sensor presets ------------------------------------------------------------------------------


@dataclass(frozen=True)
class SensorPreset:
    """A simulated sensor: thermal network, error model and noise.

    Parameters
    ----------
    name : str
        The preset's name (a key of :data:`PRESETS`).
    kind : {"gyro", "accel"}
        The sensor type.
    description : str
        One line for ``thermocal simulate`` listings.
    unit : str
        Physical unit of truth and noise (``"deg/h"`` or ``"mg"``).
    output : {"pulses", "value"}
        Integrating counts with scale factor K, or values in ``unit``.
    bias_constant : float
        Constant bias B0 [unit].
    turn_on_sigma : float
        Standard deviation of the turn-on offset D [unit] (bias repeatability).
    bias_model : BiasModel
        The temperature-induced bias E.
    noise : NoiseParams
        The noise terms.
    network : ThermalNetwork
        The sensor's thermal network (its nodes are the temperature channels).
    chamber : ChamberModel
        The chamber the sensor sits in.
    scale_factor : float, optional
        K of a pulse output, in ``scale_factor_unit``.
    scale_factor_unit : str, optional
        A unit of :data:`thermocal.units.SCALE_FACTOR_UNITS` (``"pulse/arcsec"``).
    scale_factor_tc_ppm_per_c : float
        Temperature coefficient of the scale factor [ppm/°C].
    rate_hz : float
        Default sample rate [Hz].
    curves : tuple, optional
        Characteristic curves of an accelerometer (*Adaptive accelerometer temperature
        compensation method for inertial navigation*); a run picks one.
    """

    name: str
    kind: Literal["gyro", "accel"]
    description: str
    unit: str
    output: Literal["pulses", "value"]
    bias_constant: float
    turn_on_sigma: float
    bias_model: BiasModel
    noise: NoiseParams
    network: ThermalNetwork
    chamber: ChamberModel = field(default_factory=ChamberModel)
    scale_factor: float | None = None
    scale_factor_unit: str | None = None
    scale_factor_tc_ppm_per_c: float = 0.0
    rate_hz: float = 1.0
    curves: tuple[BiasModel, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The preset as plain JSON data (written in the truth file)."""
        d = _plain_dict(dataclasses.asdict(self))
        d["network"] = self.network.to_dict()
        return d


_ARW = 1.0 / units.ARW_DEG_SQRT_H_PER_DEG_H_SQRT_HZ  # [°/√h] → [°/h·√s]

RLG = SensorPreset(
    name="rlg",
    kind="gyro",
    description="navigation-grade ring-laser gyro, pulse output K = 4 counts/arcsec, "
    "four temperature sensors (T1 block, T2 discharge, T3 mount, T4 case)",
    unit="deg/h",
    output="pulses",
    bias_constant=0.004,
    turn_on_sigma=0.002,
    bias_model=BiasModel(
        t_ref_c=20.0,
        # uncompensated temperature-induced bias ≈ 0.2 °/h peak to peak over −20…+50 °C
        # (≈ 0.003 °/h/°C), well above the 37-term least-squares noise floor
        poly=((3.0e-3, 3.0e-5, -6.0e-7), (-1.0e-3,), (1.5e-3, -1.5e-5), (0.5e-3,)),
        rate=(0.04, -0.01, 0.02, 0.0),
        coupling=(4.0e-4, 0.0, 0.0, 0.0),
        gradient=((0, 2, 1.0e-2),),
    ),
    noise=NoiseParams(white_density=0.002 * _ARW, bias_instability=0.0015),
    network=ThermalNetwork(
        names=("T1", "T2", "T3", "T4"),
        capacitance_j_per_k=(1200.0, 150.0, 1800.0, 900.0),
        to_air_w_per_k=(0.0, 0.0, 0.4, 1.6),
        links=((3, 2, 2.0), (2, 0, 1.5), (0, 1, 0.8), (3, 0, 0.5)),
        power_w=(1.0, 3.0, 0.0, 1.0),
    ),
    chamber=ChamberModel(max_rate_c_per_min=3.0, air_time_constant_s=120.0),
    scale_factor=4.0,
    scale_factor_unit="counts/arcsec",
    scale_factor_tc_ppm_per_c=0.1,
    rate_hz=1.0,
)

FOG = SensorPreset(
    name="fog",
    kind="gyro",
    description="tactical-grade fibre-optic gyro, rate output [°/h], bias piecewise linear "
    "in the coil temperature T1 with corners near 23.6 and 30 °C (fibre-optic-gyro thesis)",
    unit="deg/h",
    output="value",
    bias_constant=0.3,
    turn_on_sigma=0.05,
    bias_model=BiasModel(
        t_ref_c=20.0,
        piecewise=PiecewiseTerm(
            sensor=0, breakpoints_c=(23.6, 30.0), slopes=(0.35, -0.15, 0.45), smoothing_c=0.15
        ),
    ),
    noise=NoiseParams(white_density=0.003 * _ARW, bias_instability=0.005),
    network=ThermalNetwork(
        names=("T1", "T2", "T3", "T4"),
        capacitance_j_per_k=(400.0, 100.0, 1500.0, 600.0),
        to_air_w_per_k=(0.0, 0.0, 0.5, 1.5),
        links=((3, 2, 2.0), (2, 0, 1.2), (0, 1, 0.5), (3, 1, 0.3)),
        power_w=(0.2, 2.0, 0.0, 0.5),
    ),
    scale_factor_tc_ppm_per_c=1.0,
    rate_hz=1.0,
)

MEMS_GYRO = SensorPreset(
    name="mems-gyro",
    kind="gyro",
    description="industrial MEMS gyro, rate output [°/h], strong self-heating warm-up "
    "(T1 die, T2 board, T3 case, T4 fixture); warm-up bias per the MEMS test plan",
    unit="deg/h",
    output="value",
    bias_constant=0.0,
    turn_on_sigma=8.0,
    bias_model=BiasModel(
        t_ref_c=20.0,
        warmup=WarmupTerm(
            sensor=0,
            coefficients=((6.0, 0.04, 0.0008), (-0.25, 0.002, 4.0e-5)),
            start=(30.0, 0.8, -0.004),
        ),
    ),
    noise=NoiseParams(white_density=0.15 * _ARW, bias_instability=3.0),
    network=ThermalNetwork(
        names=("T1", "T2", "T3", "T4"),
        capacitance_j_per_k=(0.5, 15.0, 120.0, 1500.0),
        to_air_w_per_k=(0.0, 0.0, 0.6, 1.5),
        links=((0, 1, 0.04), (1, 2, 0.4), (2, 3, 0.5)),
        power_w=(0.15, 1.2, 0.0, 0.0),
    ),
    chamber=ChamberModel(max_rate_c_per_min=3.0, air_time_constant_s=120.0),
    rate_hz=10.0,
)

_ACCEL_BASE = ((0.025, 1.5e-4),)
ACCEL = SensorPreset(
    name="accel",
    kind="accel",
    description="navigation/tactical accelerometer, output [mg], bias vs T1 in one of "
    "three characteristic curves per run (adaptive accelerometer method)",
    unit="mg",
    output="value",
    bias_constant=0.0,
    turn_on_sigma=0.03,
    bias_model=BiasModel(t_ref_c=20.0, poly=_ACCEL_BASE),
    noise=NoiseParams(white_density=0.02, bias_instability=0.005),
    network=ThermalNetwork(
        names=("T1", "T2", "T3", "T4"),
        capacitance_j_per_k=(300.0, 150.0, 1500.0, 700.0),
        to_air_w_per_k=(0.0, 0.0, 0.5, 1.5),
        links=((3, 2, 2.0), (2, 0, 1.0), (0, 1, 0.6), (3, 1, 0.3)),
        power_w=(0.3, 1.5, 0.0, 0.3),
    ),
    chamber=ChamberModel(max_rate_c_per_min=3.0, air_time_constant_s=120.0),
    scale_factor_tc_ppm_per_c=20.0,
    rate_hz=1.0,
    curves=(
        BiasModel(t_ref_c=20.0, poly=((0.025, 1.5e-4),), offset=0.0),
        BiasModel(t_ref_c=20.0, poly=((0.029, 1.5e-4),), offset=1.6),
        BiasModel(t_ref_c=20.0, poly=((0.022, 1.2e-4),), offset=-1.4),
    ),
)

PRESETS: dict[str, SensorPreset] = {p.name: p for p in (RLG, FOG, MEMS_GYRO, ACCEL)}
"""Registry of sensor presets by name: ``rlg``, ``fog``, ``mems-gyro``, ``accel``."""


def get_preset(name: str) -> SensorPreset:
    """A preset by name; :class:`ThermocalInputError` lists the known ones.

    Parameters
    ----------
    name : str
        ``"rlg"``, ``"fog"``, ``"mems-gyro"`` or ``"accel"``.

    Returns
    -------
    SensorPreset

    Raises
    ------
    ThermocalInputError
        ``name`` is not a preset (the message lists them).

    Examples
    --------
    >>> p = get_preset("fog")
    >>> p.kind, p.unit, p.network.names
    ('gyro', 'deg/h', ('T1', 'T2', 'T3', 'T4'))
    """
    try:
        return PRESETS[name]
    except KeyError:
        raise ThermocalInputError(
            f"unknown sensor preset {name!r}; known: {', '.join(PRESETS)}"
        ) from None


# --- sensor --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SensorOutput:
    """Output of :func:`simulate_sensor`.

    Parameters
    ----------
    signal : numpy.ndarray
        The output column (n,): counts for pulse outputs, else in the preset's unit.
    signal_unit : str
        Its unit (``"counts"``, ``"deg/h"``, ``"mg"``).
    truth_bias : numpy.ndarray
        The noise-free temperature-induced bias ``E`` (n,) [preset unit] (see
        :mod:`thermocal.simulate`).
    truth_rate : numpy.ndarray
        The noise-free output ``(1 + δK)(ω_in + B0 + D + E)`` (n,) [preset unit].
    turn_on_offset : float
        The turn-on offset ``D`` of this run [preset unit].
    start_temperatures_c : numpy.ndarray
        Node temperatures at power-on (k,) [°C].
    """

    signal: FloatArray
    signal_unit: str
    truth_bias: FloatArray
    truth_rate: FloatArray
    turn_on_offset: float
    start_temperatures_c: FloatArray


def _pulse_counts(
    measured: FloatArray, dt: float, preset: SensorPreset, rng: np.random.Generator
) -> FloatArray:
    """Integrating counts of a pulse output (``measured`` is reused in place)."""
    if preset.scale_factor is None or preset.scale_factor_unit is None:
        raise ThermocalInputError(f"preset {preset.name!r}: pulse output needs K and its unit")
    integrating, factor, _ = units.SCALE_FACTOR_UNITS[preset.scale_factor_unit]
    if not integrating:
        raise ThermocalInputError("pulse output needs an integrating scale-factor unit")
    phase = float(rng.uniform())
    acc = measured  # reused in place: accumulated counts K θ/f + φ, then its floor
    acc *= dt * preset.scale_factor / factor
    np.cumsum(acc, out=acc)
    acc += phase
    np.floor(acc, out=acc)
    signal = np.empty(acc.size)
    signal[0] = acc[0] - math.floor(phase)
    np.subtract(acc[1:], acc[:-1], out=signal[1:])
    return signal


def simulate_sensor(
    thermal: ThermalResult,
    preset: SensorPreset,
    rng: np.random.Generator,
    *,
    input_value: float | FloatArray = 0.0,
    bias_model: BiasModel | None = None,
    turn_on_offset: float | None = None,
    power_on_s: float = 0.0,
) -> SensorOutput:
    """Sensor output for a thermal history.

    Parameters
    ----------
    thermal : ThermalResult
        The sensor's temperatures (:func:`thermocal.simulate.simulate_thermal`).
    preset : SensorPreset
        The sensor.
    rng : numpy.random.Generator
        The source of every random number (turn-on offset, noise, counting phase).
    input_value : float or numpy.ndarray
        The input ω_in [preset unit]: a rate, the earth rate, an accelerometer's force.
    bias_model : BiasModel, optional
        Replaces the preset's bias model.
    turn_on_offset : float, optional
        D [preset unit]; drawn from ``N(0, turn_on_sigma²)`` when not given.
    power_on_s : float
        Power-on time [s] (the warm-up term's T0 is the temperature then).

    Returns
    -------
    SensorOutput
        The output with its truth.

    Raises
    ------
    ThermocalInputError
        A pulse output without an integrating scale factor.

    Notes
    -----
    .. math::

        F = (1 + \\delta K(T_1))\\,(\\omega_{in} + B_0 + D + E(T, \\dot T, \\nabla T)) + n(t),
        \\qquad \\delta K = 10^{-6}\\,\\mathrm{tc}\\,(T_1 - T_{ref})

    with the noise ``n`` of :func:`thermocal.simulate.simulate_noise` (IEEE Std 952-1997
    Annex C) and D drawn from N(0, turn_on_sigma²) unless given.  Pulse outputs count
    ``N_i = ⌊K θ_i/f + φ⌋ − ⌊K θ_{i−1}/f + φ⌋`` (θ the integrated rate, φ ~ U(0, 1), ``f``
    the unit factor of :data:`thermocal.units.SCALE_FACTOR_UNITS`).

    References
    ----------
    IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for
    Single-Axis Interferometric Fiber Optic Gyros*, Annex C.

    Examples
    --------
    A fibre-optic gyro in a chamber ramping from 20 to 40 °C: the output less its truth is
    the noise, of std N/√τ0 = 0.18 °/h (N = 0.18 °/h·√s, τ0 = 1 s; flicker 40 times smaller):

    >>> import numpy as np
    >>> from thermocal.simulate import FOG, simulate_thermal
    >>> t = np.arange(0.0, 3600.0, 1.0)
    >>> th = simulate_thermal(t, [0.0, 3600.0], [20.0, 40.0], FOG.network, warmed_up=True)
    >>> out = simulate_sensor(th, FOG, np.random.default_rng(0))
    >>> round(float(np.std(out.signal - out.truth_rate)), 2)
    0.18
    """
    t = thermal.time_s
    n = t.size
    dt = thermal.sample_interval_s
    model = bias_model or preset.bias_model
    on_idx = int(np.searchsorted(t, power_on_s))
    on_idx = min(max(on_idx, 0), n - 1)
    t0 = thermal.temperatures_c[on_idx]
    e = model.evaluate(thermal.temperatures_c, thermal.rates_c_per_min, t0, on_idx)
    d = float(rng.normal(0.0, preset.turn_on_sigma)) if turn_on_offset is None else turn_on_offset
    start = 0.0
    if model.warmup is not None:
        start = model.warmup.start_bias(float(t0[model.warmup.sensor]))
    dk = np.subtract(thermal.temperatures_c[:, 0], model.t_ref_c)
    dk *= preset.scale_factor_tc_ppm_per_c * units.PPM
    dk += 1.0
    truth_rate = e + (np.asarray(input_value) + (preset.bias_constant + start + d))
    truth_rate *= dk
    del dk
    measured = simulate_noise(n, dt, preset.noise, rng, thermal.temperatures_c[:, 0])
    measured += truth_rate
    if preset.output == "pulses":
        signal = _pulse_counts(measured, dt, preset, rng)
        del measured
        signal_unit = "counts"
    else:
        signal = measured
        if preset.noise.resolution > 0:
            signal = np.round(signal / preset.noise.resolution) * preset.noise.resolution
        signal_unit = preset.unit
    return SensorOutput(signal, signal_unit, e, truth_rate, d, np.asarray(t0, dtype=np.float64))
