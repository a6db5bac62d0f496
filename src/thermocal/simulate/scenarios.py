"""Scenarios: recordings with a known truth for every workflow (modelling and
validation runs, warm-up, accelerometers, turntable, a six-axis IMU).

Part of :mod:`thermocal.simulate`."""

from __future__ import annotations

import dataclasses
import math
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.defaults import MAX_SIMULATED_SAMPLES
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.profiles import (
    POWER_ON_LABEL,
    Profile,
    Stage,
    builtin_profile,
    check_program,
    find_holds,
)
from thermocal.recording import Metadata, Recording
from thermocal.simulate.sensors import (
    SensorOutput,
    SensorPreset,
    get_preset,
    simulate_sensor,
)
from thermocal.simulate.thermal import (
    ThermalResult,
    _plain,
    _plain_dict,
    chamber_air,
    simulate_nodes,
    simulate_thermal,
)

FloatArray = npt.NDArray[np.float64]
ProgramArrays = tuple[FloatArray, FloatArray]
ProfileInput = Profile | ProgramArrays | None
Truth = dict[str, Any]
ScenarioResult = list[tuple[Recording, Truth]]


TRUTH_FORMAT = "thermocal-truth"
TRUTH_VERSION = 1


# --- scenarios -----------------------------------------------------------------------------------


def scenario_rng(scenario: str, seed: int, n: int) -> list[np.random.Generator]:
    """``n`` independent generators from ``SeedSequence([seed, crc32(scenario)])``.

    Parameters
    ----------
    scenario : str
        The scenario's name.
    seed : int
        The seed; the same seed gives the same output.
    n : int
        Number of generators.

    Returns
    -------
    list of numpy.random.Generator

    Raises
    ------
    ThermocalInputError
        ``seed`` is not a non-negative integer.

    Examples
    --------
    >>> a, = scenario_rng("fog-slow", 0, 1)
    >>> b, = scenario_rng("fog-slow", 0, 1)
    >>> bool(a.normal() == b.normal())
    True
    """
    if int(seed) != seed or seed < 0:
        raise ThermocalInputError(f"seed must be a non-negative integer, got {seed!r}")
    ss = np.random.SeedSequence([int(seed), zlib.crc32(scenario.encode())])
    return [np.random.default_rng(s) for s in ss.spawn(n)]


def _program(profile: ProfileInput, default: str) -> tuple[ProgramArrays, list[Stage]]:
    """Program arrays and hold stages of a profile (the default built-in when None)."""
    if profile is None:
        profile = builtin_profile(default)
    if isinstance(profile, Profile):
        return profile.knots(), profile.stages()
    t, c = (np.asarray(a, dtype=np.float64) for a in profile)
    check_program(t, c, "chamber program")
    t = t - t[0]
    return (t, c), find_holds(t, c)


MAX_SAMPLES = MAX_SIMULATED_SAMPLES
"""See :data:`thermocal.defaults.MAX_SIMULATED_SAMPLES`."""


def check_sample_budget(n: float, what: str) -> None:
    """Refuse ``n`` samples above :data:`MAX_SAMPLES`, saying what to lower.

    Parameters
    ----------
    n : float
        Samples the call would make.
    what : str
        How the message names the call.

    Raises
    ------
    ThermocalInputError
        ``n`` is above :data:`MAX_SAMPLES` (the message names the parameters that lower it:
        ``rate_hz``, ``profile``, ``record_s``, ``runs``).
    """
    if not n <= MAX_SAMPLES:
        raise ThermocalInputError.naming(
            f"{what}: {n:.3g} samples to simulate, above the limit of {MAX_SAMPLES:.3g}: "
            "lower {rate_hz}, or shorten the chamber program ({profile}, {record_s}, {runs})",
            "rate_hz",
            "profile",
            "record_s",
            "runs",
        )


def _time_grid(duration_s: float, rate_hz: float) -> FloatArray:
    if not (math.isfinite(rate_hz) and rate_hz > 0):
        raise ThermocalInputError(f"rate_hz must be > 0, got {rate_hz!r}")
    dt = 1.0 / rate_hz
    check_sample_budget(duration_s * rate_hz + 1, f"{duration_s:g} s at {rate_hz:g} Hz")
    n = math.floor(duration_s / dt + 1e-9) + 1
    if n < 2:
        raise ThermocalInputError("the chamber program is shorter than two samples")
    return np.arange(n, dtype=np.float64) * dt


def _metadata(
    preset: SensorPreset, scenario: str, seed: int, label: str, rate_hz: float, **extra: Any
) -> Metadata:
    run = f"{scenario}-seed{seed}" + (f"-{label}" if label else "")
    return Metadata(
        sample_interval_s=1.0 / rate_hz,
        scale_factor=preset.scale_factor if preset.output == "pulses" else None,
        scale_factor_unit=preset.scale_factor_unit if preset.output == "pulses" else None,
        latitude_deg=extra.pop("latitude_deg", None),
        axis=extra.pop("axis", None),
        sensor_id=f"sim-{preset.name}-001",
        run_id=run,
        notes=f"simulated by thermocal ({scenario}, seed {seed}); truth_bias = "
        "temperature-induced bias, truth_rate = noise-free output",
        extra={"scenario": scenario, "seed": int(seed), "label": label, **extra},
    )


def _recording(
    thermal: ThermalResult, out: SensorOutput, preset: SensorPreset, meta: Metadata
) -> Recording:
    signal_name = "gyro" if preset.kind == "gyro" else "accel"
    temps: dict[str, npt.ArrayLike] = {
        name: thermal.temperatures_c[:, i] for i, name in enumerate(thermal.names)
    }
    return Recording.from_arrays(
        thermal.time_s,
        signals={signal_name: out.signal},
        temperatures=temps,
        signal_unit=out.signal_unit,
        other={
            "T_chamber": thermal.air_c,
            "setpoint_c": thermal.setpoint_c,
            "truth_bias": out.truth_bias,
            "truth_rate": out.truth_rate,
        },
        other_units={
            "T_chamber": "degC",
            "setpoint_c": "degC",
            "truth_bias": preset.unit,
            "truth_rate": preset.unit,
        },
        meta=meta,
    )


def _truth(
    scenario: str,
    seed: int,
    label: str,
    preset: SensorPreset,
    out: SensorOutput,
    thermal: ThermalResult,
    stages: Sequence[Stage],
    **extra: Any,
) -> Truth:
    return _plain_dict(
        {
            "format": TRUTH_FORMAT,
            "version": TRUTH_VERSION,
            "scenario": scenario,
            "seed": int(seed),
            "label": label,
            "preset": preset.to_dict(),
            "unit": preset.unit,
            "signal": "gyro" if preset.kind == "gyro" else "accel",
            "signal_unit": out.signal_unit,
            "sample_rate_hz": 1.0 / thermal.sample_interval_s,
            "n_samples": int(thermal.time_s.size),
            "bias_constant": preset.bias_constant,
            "turn_on_offset": out.turn_on_offset,
            "start_temperatures_c": dict(
                zip(thermal.names, (float(v) for v in out.start_temperatures_c), strict=True)
            ),
            "time_constants_s": [float(v) for v in thermal.time_constants_s],
            "stages": [s.to_dict() for s in stages],
            "truth_bias_definition": "temperature-induced bias E (constant bias, turn-on "
            "offset and input excluded); see thermocal.simulate module docstring",
            **extra,
        }
    )


def _gyro_run(
    scenario: str,
    preset: SensorPreset,
    seed: int,
    rng: np.random.Generator,
    program: ProgramArrays,
    stages: Sequence[Stage],
    *,
    rate_hz: float,
    latitude_deg: float,
    axis: str,
    warmed_up: bool,
    label: str = "",
) -> tuple[Recording, Truth]:
    t = _time_grid(float(program[0][-1]), rate_hz)
    thermal = simulate_thermal(
        t, program[0], program[1], preset.network, chamber=preset.chamber, warmed_up=warmed_up
    )
    omega = units.earth_rate_on_axis_deg_h(latitude_deg, units.parse_axis(axis))
    out = simulate_sensor(thermal, preset, rng, input_value=omega)
    meta = _metadata(preset, scenario, seed, label, rate_hz, latitude_deg=latitude_deg, axis=axis)
    truth = _truth(
        scenario,
        seed,
        label,
        preset,
        out,
        thermal,
        stages,
        input=omega,
        earth_rate_on_axis_deg_h=omega,
        latitude_deg=latitude_deg,
        axis=axis,
        power_on_s=None if warmed_up else 0.0,
        warmed_up=warmed_up,
    )
    return _recording(thermal, out, preset, meta), truth


DEFAULT_LATITUDE_DEG = 45.0


def _single_gyro_scenario(
    name: str,
    seed: int,
    profile: ProfileInput,
    rate_hz: float | None,
    latitude_deg: float,
    axis: str,
    preset: str,
    *,
    warmed_up: bool,
) -> ScenarioResult:
    """One gyro run of scenario ``name`` over its profile (the built-in one by default)."""
    p = get_preset(preset)
    program, stages = _program(profile, name)
    rng = scenario_rng(name, seed, 1)[0]
    return [
        _gyro_run(
            name, p, seed, rng, program, stages,
            rate_hz=rate_hz or p.rate_hz, latitude_deg=latitude_deg, axis=axis,
            warmed_up=warmed_up,
        )
    ]  # fmt: skip


def scenario_rlg_modelling(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    axis: str = "up",
    preset: str = "rlg",
) -> ScenarioResult:
    """Modelling run (*A modelling and validation method for the temperature compensation model
    of a ring-laser gyroscope*) of the ``rlg`` preset over the ``rlg-modelling`` profile
    (≈ 65 h at 1 Hz by default); powered on at t = 0, soaked at the start temperature.

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : str, tuple of numpy.ndarray or None
        The chamber program (a built-in name or ``(time_s, setpoint_c)``); None: the scenario's own.
    rate_hz : float, optional
        Sample rate [Hz] (default: the preset's).
    latitude_deg : float
        Latitude [°] (the earth rate on the sensitive axis).
    axis : str
        Sensitive axis (``"up"``, ``"north"``, …).
    preset : str
        The sensor preset (:data:`thermocal.simulate.PRESETS`).

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A bad option, a program the chamber cannot follow, or more samples than the budget.
    """
    return _single_gyro_scenario(
        "rlg-modelling", seed, profile, rate_hz, latitude_deg, axis, preset, warmed_up=False
    )


def scenario_rlg_validation(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    axis: str = "up",
    preset: str = "rlg",
) -> ScenarioResult:
    """Validation run of the ring-laser-gyro method (holds, weakly correlated with
    ``rlg-modelling``), same
    sensor as :func:`scenario_rlg_modelling`, another turn-on and noise.

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : str, tuple of numpy.ndarray or None
        The chamber program (a built-in name or ``(time_s, setpoint_c)``); None: the scenario's own.
    rate_hz : float, optional
        Sample rate [Hz] (default: the preset's).
    latitude_deg : float
        Latitude [°] (the earth rate on the sensitive axis).
    axis : str
        Sensitive axis (``"up"``, ``"north"``, …).
    preset : str
        The sensor preset (:data:`thermocal.simulate.PRESETS`).

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A bad option, a program the chamber cannot follow, or more samples than the budget.
    """
    return _single_gyro_scenario(
        "rlg-validation", seed, profile, rate_hz, latitude_deg, axis, preset, warmed_up=False
    )


def scenario_fog_slow(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    axis: str = "up",
    preset: str = "fog",
) -> ScenarioResult:
    """Slow drift (*Design and engineering implementation of a fibre-optic-gyro line-of-sight
    stabilisation system*, chapter 3) over 15–42 °C of a warmed-up ``fog`` (piecewise bias).

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : str, tuple of numpy.ndarray or None
        The chamber program (a built-in name or ``(time_s, setpoint_c)``); None: the scenario's own.
    rate_hz : float, optional
        Sample rate [Hz] (default: the preset's).
    latitude_deg : float
        Latitude [°] (the earth rate on the sensitive axis).
    axis : str
        Sensitive axis (``"up"``, ``"north"``, …).
    preset : str
        The sensor preset (:data:`thermocal.simulate.PRESETS`).

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A bad option, a program the chamber cannot follow, or more samples than the budget.
    """
    return _single_gyro_scenario(
        "fog-slow", seed, profile, rate_hz, latitude_deg, axis, preset, warmed_up=True
    )


def _power_on_windows(profile: ProfileInput, record_s: float) -> tuple[ProgramArrays, list[Stage]]:
    """Power-on windows of a warm-up program: labelled holds of a built-in profile, or for
    program arrays the last ``record_s`` of every hold of at least ``record_s``."""
    if profile is None:
        profile = builtin_profile("mems-warmup", record_s=record_s)
    if isinstance(profile, Profile):
        wins = [s for s in profile.stages() if s.label.startswith(POWER_ON_LABEL)]
        program = profile.knots()
    else:
        program, holds = _program(profile, "mems-warmup")
        wins = [
            Stage(h.end_s - record_s, h.end_s, h.setpoint_c, f"{POWER_ON_LABEL} T{h.setpoint_c:+g}")
            for h in holds
            if h.end_s - h.start_s >= record_s
        ]
    if not wins:
        raise ThermocalInputError(
            f"the warm-up program has no power-on hold (a hold of at least {record_s:g} s)"
        )
    return program, wins


def scenario_mems_warmup(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    record_s: float = 900.0,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    axis: str = "up",
    preset: str = "mems-gyro",
) -> ScenarioResult:
    """Power-on warm-ups (*Temperature-characteristic calibration test plan*): one file per
    start temperature (label ``T+25`` …).

    Each file starts at power-on (t = 0) with the unit soaked at the chamber air
    temperature and lasts the power-on hold (``record_s`` ≥ 360 s for program
    files).  Truth: ``start_temperature_c`` (T0 = T1 at power-on), the warm-up
    coefficients ``a_j(T0)`` and ``start_bias``.

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : str, tuple of numpy.ndarray or None
        The chamber program (a built-in name or ``(time_s, setpoint_c)``); None: the scenario's own.
    rate_hz : float, optional
        Sample rate [Hz] (default: the preset's).
    record_s : float
        Record per power-on [s], at least 360.
    latitude_deg : float
        Latitude [°] (the earth rate on the sensitive axis).
    axis : str
        Sensitive axis (``"up"``, ``"north"``, …).
    preset : str
        The sensor preset (:data:`thermocal.simulate.PRESETS`).

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A bad option, a program the chamber cannot follow, or more samples than the budget.
    """
    if record_s < 360:
        raise ThermocalInputError(
            f"record_s must be ≥ 360 s (the warm-up test plan's record), got {record_s}"
        )
    p = get_preset(preset)
    program, wins = _power_on_windows(profile, record_s)
    hz = rate_hz or p.rate_hz
    rngs = scenario_rng("mems-warmup", seed, len(wins))
    full_t = _time_grid(float(program[0][-1]), 1.0)
    _, air_full = chamber_air(full_t, program[0], program[1], p.chamber)
    results: ScenarioResult = []
    omega = units.earth_rate_on_axis_deg_h(latitude_deg, units.parse_axis(axis))
    for win, rng in zip(wins, rngs, strict=True):
        label = win.label.removeprefix(POWER_ON_LABEL).strip()
        t = _time_grid(win.end_s - win.start_s, hz)
        sp, air = chamber_air(t + win.start_s, program[0], program[1], p.chamber)
        air = air - air[0] + float(np.interp(win.start_s, full_t, air_full))
        temps, rates = simulate_nodes(t, air, p.network, power_on_s=0.0)
        thermal = ThermalResult(
            t, sp, air, temps, rates, p.network.names, p.network.time_constants_s()
        )
        out = simulate_sensor(thermal, p, rng, input_value=omega)
        t0 = float(out.start_temperatures_c[0])
        wu = p.bias_model.warmup
        meta = _metadata(p, "mems-warmup", seed, label, hz, latitude_deg=latitude_deg, axis=axis)
        truth = _truth(
            "mems-warmup", seed, label, p, out, thermal, [],
            input=omega, earth_rate_on_axis_deg_h=omega, latitude_deg=latitude_deg, axis=axis,
            power_on_s=0.0, program_start_s=win.start_s, start_temperature_c=t0,
            warmup_coefficients=wu.a(t0) if wu else [],
            start_bias=wu.start_bias(t0) if wu else 0.0,
        )  # fmt: skip
        results.append((_recording(thermal, out, p, meta), truth))
    return results


ORIENTATIONS: dict[str, float] = {"horizontal": 0.0, "up": 1.0, "down": -1.0}
"""Accelerometer sensitive-axis orientations and their gravity input [g]."""


def scenario_accel_full_range(
    seed: int,
    profile: ProfileInput = None,
    *,
    runs: int = 5,
    rate_hz: float | None = None,
    orientation: str = "horizontal",
    preset: str = "accel",
) -> ScenarioResult:
    """Full-range runs (*Adaptive accelerometer temperature compensation method for inertial
    navigation*): one file per run (label ``run1`` …).

    The program (default ``accel-full-range`` with one repetition) is one run,
    repeated ``runs`` times with a power-on at the start of each.  Each run's bias
    follows one characteristic curve (``curve`` in the truth), assigned as a
    shuffled balanced cycle over the preset's curves, plus the turn-on offset.
    The input is gravity on the sensitive axis (``orientation``: horizontal 0 g,
    up +1 g, down −1 g) in [mg].

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : str, tuple of numpy.ndarray or None
        The chamber program (a built-in name or ``(time_s, setpoint_c)``); None: the scenario's own.
    runs : int
        Number of runs (one power-on each).
    rate_hz : float, optional
        Sample rate [Hz] (default: the preset's).
    orientation : str
        ``"horizontal"``, ``"up"`` or ``"down"`` (gravity on the sensitive axis).
    preset : str
        The sensor preset (:data:`thermocal.simulate.PRESETS`).

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A bad option, a program the chamber cannot follow, or more samples than the budget.
    """
    p = get_preset(preset)
    if orientation not in ORIENTATIONS:
        raise ThermocalInputError(
            f"unknown orientation {orientation!r}; known: {', '.join(ORIENTATIONS)}"
        )
    if int(runs) != runs or runs < 1:
        raise ThermocalInputError(f"runs must be an integer ≥ 1, got {runs!r}")
    if profile is None:
        profile = builtin_profile("accel-full-range", repeats=1)
    program, stages = _program(profile, "accel-full-range")
    stages = [dataclasses.replace(s, label=s.label.removeprefix("run1/")) for s in stages]
    hz = rate_hz or p.rate_hz
    n_run = float(program[0][-1]) * float(hz) + 1
    check_sample_budget(float(runs) * n_run, f"{int(runs)} runs of {n_run:.3g} samples")
    rngs = scenario_rng("accel-full-range", seed, int(runs) + 1)
    curves = p.curves or (p.bias_model,)
    assign = rngs[-1].permutation(np.resize(np.arange(len(curves)), int(runs)))
    input_mg = ORIENTATIONS[orientation] * units.G_TO_MG
    t = _time_grid(float(program[0][-1]), hz)
    thermal = simulate_thermal(t, program[0], program[1], p.network, chamber=p.chamber)
    results: ScenarioResult = []
    for i in range(int(runs)):
        label = f"run{i + 1}"
        k = int(assign[i])
        out = simulate_sensor(thermal, p, rngs[i], input_value=input_mg, bias_model=curves[k])
        meta = _metadata(p, "accel-full-range", seed, label, hz, orientation=orientation)
        truth = _truth(
            "accel-full-range", seed, label, p, out, thermal, stages,
            input=input_mg, input_mg=input_mg, orientation=orientation, curve=k,
            n_curves=len(curves), power_on_s=0.0,
        )  # fmt: skip
        results.append((_recording(thermal, out, p, meta), truth))
    return results


def scenario_turntable16(seed: int, profile: ProfileInput = None, **opts: Any) -> ScenarioResult:
    """The 16-position dual-axis turntable run (CN104880182), delegated to
    :func:`thermocal.turntable.simulate.simulate_turntable16` (imported lazily).

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : None
        Must be None (no chamber program).
    **opts
        Options of the delegated simulator.

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A bad option, a program the chamber cannot follow, or more samples than the budget.
    """
    if profile is not None:
        raise ThermocalInputError("the turntable-16 scenario takes no chamber profile")
    from thermocal.turntable.simulate import simulate_turntable16

    try:
        res: Any = simulate_turntable16(seed=seed, **opts)
    except ThermocalInputError:
        raise
    except ValueError as exc:
        raise ThermocalInputError(f"turntable-16: {exc}") from None
    items = res if isinstance(res, list) else [res]
    out: ScenarioResult = []
    for item in items:
        if isinstance(item, tuple):
            rec, truth = item[0], item[1]
        elif hasattr(item, "recording"):
            rec, truth = item.recording, getattr(item, "truth", {})
        else:
            rec, truth = item, {}
        if not isinstance(rec, Recording):
            raise TypeError("simulate_turntable16 did not return a Recording")
        truth_d: Any = truth
        if dataclasses.is_dataclass(truth) and not isinstance(truth, type):
            truth_d = dataclasses.asdict(truth)
        if not isinstance(truth_d, dict):
            truth_d = {"truth": truth_d}
        out.append(
            (rec, _plain({"scenario": "turntable-16", "seed": int(seed), "label": "", **truth_d}))
        )
    return out


def scenario_turntable_thermal(
    seed: int, profile: ProfileInput = None, **opts: Any
) -> ScenarioResult:
    """16-position runs of a gyro and an accelerometer triad at several soak temperatures
    and a held-out run at an unseen one, every parameter a known polynomial in temperature
    (:func:`thermocal.turntable.simulate.simulate_turntable_thermal`).

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : None
        Must be None (no chamber program).
    **opts
        Options of the delegated simulator.

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A bad option, a program the chamber cannot follow, or more samples than the budget.
    """
    if profile is not None:
        raise ThermocalInputError("the turntable-thermal scenario takes no chamber profile")
    from thermocal.turntable.simulate import simulate_turntable_thermal

    try:
        runs = simulate_turntable_thermal(seed=seed, **opts)
    except TypeError as exc:
        raise ThermocalInputError(f"turntable-thermal: {exc}") from None
    return [(rec, _plain(truth)) for rec, truth in runs]


def scenario_multipos(seed: int, profile: ProfileInput = None, **opts: Any) -> ScenarioResult:
    """Hand-placed multi-position sessions of an IMU with known bias, scale factors and
    misalignments and their temperature trends (
    :func:`thermocal.multipos.simulate.simulate_runs`; ``runs`` sessions at temperatures
    over −10…+50 °C, one at 25 °C by default).

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : None
        Must be None (no chamber program).
    **opts
        Options of the delegated simulator.

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A bad option, a program the chamber cannot follow, or more samples than the budget.
    """
    if profile is not None:
        raise ThermocalInputError("the multipos scenario takes no chamber profile")
    from thermocal.multipos.simulate import simulate_runs

    try:
        runs = simulate_runs(scenario_rng("multipos", seed, 2), **opts)
    except (TypeError, ValueError) as exc:
        raise ThermocalInputError.around(exc, "multipos: ") from None
    return [(rec, _plain({"scenario": "multipos", "seed": int(seed), **t})) for rec, t in runs]


RATETABLE_ERRORS: dict[str, float] = {
    "scale_factor": 1.0,
    "quadratic_ppm": 30.0,
    "cubic_ppm": 150.0,
    "asymmetry_ppm": 200.0,
    "bias_dps": 0.02,
    "tc_ppm_per_c": 40.0,
    "dead_zone_dps": 0.015,
}
"""The ratetable scenario's gyro: a tactical MEMS gyro's scale-factor errors (°/s output)."""


def scenario_ratetable(seed: int, profile: ProfileInput = None, **opts: Any) -> ScenarioResult:
    """A gyro on a rate table (:func:`thermocal.ratetable.simulate.simulate_ladder`): the
    default ±300 °/s ladder with small rates, run up and back down, one plateau cut short,
    with the table's finite acceleration and overshoot; ``runs`` ladders at temperatures
    over −20…+60 °C (one at 25 °C by default), one file each.  ``rate_column=False``: what
    a gyro's own logger records of a program run on the table (20 s at each rate): no rate
    column, no plateau cut short, the record started 5–30 s (random, in the truth's
    ``lead_s``) before the program, the table at rest until then.

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : None
        Must be None (no chamber program).
    **opts
        ``runs`` (temperatures), ``rate_hz`` and ``rate_column``.

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        A chamber profile or a bad option.
    """
    if profile is not None:
        raise ThermocalInputError("the ratetable scenario takes no chamber profile")
    column = bool(opts.pop("rate_column", True))
    from thermocal.ratetable.simulate import simulate_ladder

    runs = int(opts.pop("runs", 1))
    if runs < 1:
        raise ParameterError("runs", f"{{name}} must be at least 1, got {runs}")
    temps = [25.0] if runs == 1 else np.linspace(-20.0, 60.0, runs).tolist()
    (rng,) = scenario_rng("ratetable", seed, 1)
    out: ScenarioResult = []
    for t in temps:
        try:
            kw: dict[str, Any] = {**opts, **RATETABLE_ERRORS}
            if not column:
                kw.update(rate_column=False, lead_s=float(rng.uniform(5.0, 30.0)))
            cut = 30 if column else None
            rec, truth = simulate_ladder(rng, up_down=True, cut_short=cut, temperature_c=t, **kw)
        except TypeError as exc:
            raise ThermocalInputError(f"ratetable: {exc}") from None
        label = f"T{t:+.0f}" if runs > 1 else ""
        out.append((rec, _plain({"scenario": "ratetable", "seed": int(seed), "label": label,
                                 **truth})))  # fmt: skip
    return out


def scenario_tumble(seed: int, profile: ProfileInput = None, **opts: Any) -> ScenarioResult:
    """An accelerometer on a dividing head (:func:`thermocal.tumble.simulate.simulate_tumble`):
    24 stations 15° apart, 20 s each at 50 Hz, with the navigation-grade accelerometer of
    :data:`thermocal.tumble.simulate.TRUTH` (K2 = 50 µg/g², K_ip = −30 µg/g²); with
    ``turns``, a continuous tumble at 2 °/s instead.

    Parameters
    ----------
    seed : int
        The seed; the same seed gives the same output.
    profile : None
        Must be None (no chamber program).
    **opts
        ``rate_hz`` and ``turns``.

    Returns
    -------
    list of (Recording, dict)
        The recording with its truth.

    Raises
    ------
    ThermocalInputError
        A chamber profile or a bad option.
    """
    if profile is not None:
        raise ThermocalInputError("the tumble scenario takes no chamber profile")
    from thermocal.tumble.simulate import simulate_tumble

    continuous = bool(opts.pop("turns", False))
    (rng,) = scenario_rng("tumble", seed, 1)
    try:
        rec, truth = simulate_tumble(rng, turn_rate_dps=2.0 if continuous else None, **opts)
    except TypeError as exc:
        raise ThermocalInputError(f"tumble: {exc}") from None
    return [(rec, _plain({"scenario": "tumble", "seed": int(seed), **truth}))]


IMU_CHANNELS: tuple[tuple[str, str], ...] = (
    ("gx", "deg/s"),
    ("gy", "deg/s"),
    ("gz", "deg/s"),
    ("ax", "mg"),
    ("ay", "mg"),
    ("az", "mg"),
)
"""The six channels of the MEMS IMU scenario and their units."""
IMU_BIAS_SPAN: dict[str, tuple[float, float, float, float]] = {
    # unit: (constant, linear, quadratic, cubic) spans of b(x) = Σ c_j x^j, x = (T − 25)/40 °C
    "deg/s": (0.2, 0.06, 0.02, 0.015),
    "mg": (30.0, 15.0, 6.0, 4.0),
}
"""Realistic MEMS magnitudes over −15…+65 °C: a few 0.01 °/s and a few 10 mg (consumer and
industrial MEMS data sheets quote 0.01-0.05 °/s/°C·40 °C and 0.1-0.5 mg/°C·40 °C)."""
IMU_NOISE: dict[str, float] = {"deg/s": 0.005, "mg": 0.5}
"""White noise σ per 1 s sample (°/s, mg)."""


def scenario_mems_imu(
    seed: int,
    profile: ProfileInput = None,
    *,
    run: str = "modelling",
    rate_hz: float = 1.0,
    gravity_axis: str = "az",
    preset: str = "mems-gyro",
) -> ScenarioResult:
    """A six-axis MEMS IMU in a chamber: gyros [°/s], accelerometers [mg], the die
    temperature ``T_die`` (lagging the air) and the air ``T_chamber``.  Each channel's bias
    is a cubic ``Σ_j c_j x^j``, ``x = (T_die − 25)/40``, coefficients drawn within
    :data:`IMU_BIAS_SPAN`; gravity +1000 mg on ``gravity_axis``; white noise
    :data:`IMU_NOISE`.  Truth: ``channels`` and ``truth_<name>`` columns (the bias alone).

    Parameters
    ----------
    seed : int
        The seed: the same seed gives the same unit (the same coefficients).
    profile : str, tuple of numpy.ndarray or None
        The chamber program; None: ``rlg-modelling`` or ``rlg-validation``, as ``run`` says.
    run, gravity_axis, preset : str
        ``"modelling"`` or ``"validation"``; the accelerometer channel that sees +1000 mg;
        the sensor preset whose thermal network is used.
    rate_hz : float
        Sample rate [Hz].

    Returns
    -------
    list of (Recording, dict)

    Raises
    ------
    ThermocalInputError
        A bad option, or more samples than the budget.
    """
    if run not in ("modelling", "validation"):
        raise ThermocalInputError(f"run must be modelling or validation, got {run!r}")
    names = [n for n, _u in IMU_CHANNELS]
    if gravity_axis not in names[3:]:
        raise ThermocalInputError(f"gravity_axis must be one of {names[3:]}, got {gravity_axis!r}")
    p = get_preset(preset)
    program, stages = _program(profile, f"rlg-{run}")
    t = _time_grid(float(program[0][-1]), rate_hz)
    thermal = simulate_thermal(t, program[0], program[1], p.network, chamber=p.chamber)
    die = thermal.temperatures_c[:, 0]
    coef_rng, *noise_rngs = scenario_rng("mems-imu", seed, 1 + len(IMU_CHANNELS))
    if run == "validation":  # a different noise draw, the same unit (same coefficients)
        noise_rngs = scenario_rng("mems-imu-validation", seed, len(IMU_CHANNELS))
    x = (die - 25.0) / 40.0
    signals: dict[str, npt.ArrayLike] = {}
    other: dict[str, npt.ArrayLike] = {"T_chamber": thermal.air_c, "setpoint_c": thermal.setpoint_c}
    other_units = {"T_chamber": "degC", "setpoint_c": "degC"}
    truth_channels: dict[str, Any] = {}
    for (name, unit), rng in zip(IMU_CHANNELS, noise_rngs, strict=True):
        span = IMU_BIAS_SPAN[unit]
        coef = [float(coef_rng.uniform(-a, a)) for a in span]
        bias = coef[0] + x * (coef[1] + x * (coef[2] + x * coef[3]))
        gravity = 1000.0 if name == gravity_axis else 0.0
        signals[name] = gravity + bias + IMU_NOISE[unit] * rng.standard_normal(t.size)
        other[f"truth_{name}"] = bias - coef[0]
        other_units[f"truth_{name}"] = unit
        truth_channels[name] = {
            "unit": unit,
            "coefficients": coef,
            "x": "(T_die - 25)/40",
            "gravity_mg": gravity,
        }
    meta = Metadata(
        sample_interval_s=1.0 / rate_hz,
        sensor_id="sim-mems-imu-001",
        run_id=f"mems-imu-seed{seed}-{run}",
        notes="simulated by thermocal (mems-imu); truth_<channel> = temperature-induced bias "
        "about its value at 25 °C",
        extra={"scenario": "mems-imu", "seed": int(seed), "label": run},
    )
    rec = Recording.from_arrays(
        t,
        signals=signals,
        temperatures={"T_die": die},
        signal_unit=dict(IMU_CHANNELS),
        other=other,
        other_units=other_units,
        meta=meta,
    )
    truth = _plain_dict(
        {
            "format": TRUTH_FORMAT,
            "version": TRUTH_VERSION,
            "scenario": "mems-imu",
            "seed": int(seed),
            "label": run,
            "sample_rate_hz": float(rate_hz),
            "n_samples": int(t.size),
            "channels": truth_channels,
            "stages": [st.to_dict() for st in stages],
        }
    )
    return [(rec, truth)]


ScenarioFn = Callable[..., ScenarioResult]

SCENARIOS: dict[str, ScenarioFn] = {
    "rlg-modelling": scenario_rlg_modelling,
    "rlg-validation": scenario_rlg_validation,
    "fog-slow": scenario_fog_slow,
    "mems-warmup": scenario_mems_warmup,
    "accel-full-range": scenario_accel_full_range,
    "turntable-16": scenario_turntable16,
    "turntable-thermal": scenario_turntable_thermal,
    "mems-imu": scenario_mems_imu,
    "multipos": scenario_multipos,
    "ratetable": scenario_ratetable,
    "tumble": scenario_tumble,
}
"""Registry: scenario name → ``fn(seed, profile=None, **opts) -> [(Recording, truth)]``."""


def run_scenario(
    name: str, seed: int = 0, profile: ProfileInput = None, **opts: Any
) -> ScenarioResult:
    """Run a scenario by name.

    Parameters
    ----------
    name : str
        A key of :data:`SCENARIOS`.
    seed : int
        The seed; the same seed gives the same recordings.
    profile : str, tuple of numpy.ndarray or None
        The chamber program (a built-in name or ``(time_s, setpoint_c)``); None: the
        scenario's own.
    **opts
        The scenario's options (``rate_hz``, ``latitude_deg``, ``runs``, …).

    Returns
    -------
    list of (Recording, dict)
        Each recording with its truth.

    Raises
    ------
    ThermocalInputError
        An unknown scenario or option.
    """
    try:
        fn = SCENARIOS[name]
    except KeyError:
        raise ThermocalInputError(
            f"unknown scenario {name!r}; known scenarios: {', '.join(SCENARIOS)}"
        ) from None
    try:
        return fn(seed, profile, **opts)
    except TypeError as exc:
        if "unexpected keyword" in str(exc):
            raise ThermocalInputError(f"scenario {name!r}: {exc}") from None
        raise


@dataclass(frozen=True)
class SimulateOptions:
    """The options of a scenario (None: the scenario's default).

    Parameters
    ----------
    rate_hz : float, optional
        Sample rate [Hz].
    latitude_deg : float, optional
        Latitude [°], within ±90.
    axis : str, optional
        Sensitive axis of a single gyro (``"up"``, ``"north"``, …).
    runs : int, optional
        Number of runs.
    orientation : str, optional
        Accelerometer orientation (``"horizontal"``, ``"up"``, ``"down"``).
    record_s : float, optional
        Record per power-on [s].
    run : str, optional
        ``"modelling"`` or ``"validation"`` (multi-channel scenarios).
    turns : bool, optional
        Multi-position sessions with the six named faces and 360° turns; a continuous
        tumble instead of the dividing head's stations (tumble).
    rate_column : bool, optional
        ratetable: write the table's rate column (False: a program's record, the gyro alone).

    Raises
    ------
    thermocal.errors.ParameterError
        A rate that is not positive (``rate_hz``) or a latitude beyond ±90°
        (``latitude_deg``).
    """

    rate_hz: float | None = None
    latitude_deg: float | None = None
    axis: str | None = None
    runs: int | None = None
    orientation: str | None = None
    record_s: float | None = None
    run: str | None = None
    turns: bool | None = None
    """multipos: Ferraris sessions (six named faces and 360° turns)."""
    rate_column: bool | None = None
    """ratetable: the table's rate column written (False: the gyro's output alone)."""

    def __post_init__(self) -> None:
        rate, lat = self.rate_hz, self.latitude_deg
        if rate is not None and not (math.isfinite(rate) and rate > 0):
            raise ParameterError("rate_hz", f"{{name}} must be a positive number, got {rate!r}")
        if lat is not None and not (math.isfinite(lat) and abs(lat) <= 90.0):
            raise ParameterError("latitude_deg", f"{{name}} must be within ±90°, got {lat!r}")

    def given(self) -> dict[str, Any]:
        """The options given, as the scenario's keyword arguments."""
        return {k: v for k, v in dataclasses.asdict(self).items() if v is not None}


@dataclass(frozen=True, eq=False)
class Simulation:
    """The result of :func:`simulate_scenario`: each recording with its truth, and a label per
    recording (the truth's ``label``, else 1, 2, … when the labels do not tell them
    apart).

    Attributes
    ----------
    scenario : str
        The scenario's name.
    seed : int
        Its seed.
    results : ScenarioResult
        Each recording with its truth.
    labels : tuple of str
        One label per recording.
    """

    scenario: str
    seed: int
    results: ScenarioResult
    labels: tuple[str, ...]

    def truth_document(self, files: Sequence[str], profile: str | None) -> dict[str, Any]:
        """The truth JSON: format, version, scenario, seed, profile and per recording
        its truth with ``file`` the path it was written to.

        Parameters
        ----------
        files : sequence of str
            The path each recording was written to.
        profile : str, optional
            The profile's name or file.

        Returns
        -------
        dict
        """
        return {
            "format": TRUTH_FORMAT,
            "version": TRUTH_VERSION,
            "scenario": self.scenario,
            "seed": self.seed,
            "profile": profile,
            "files": [{"file": f, **tr} for (_, tr), f in zip(self.results, files, strict=True)],
        }


def simulate_scenario(
    scenario: str, seed: int, profile: ProfileInput, options: SimulateOptions
) -> Simulation:
    """Run a scenario with its options and label its recordings.

    Parameters
    ----------
    scenario : str
        A key of :data:`SCENARIOS`.
    seed : int
        The seed.
    profile : str, tuple of numpy.ndarray or None
        The chamber program, or None for the scenario's own.
    options : SimulateOptions
        The options.

    Returns
    -------
    Simulation

    Raises
    ------
    ThermocalInputError
        An unknown scenario, an option it does not take, or a run over the sample budget.

    Examples
    --------
    Power-on warm-ups of a MEMS gyro at seven start temperatures; each truth records the
    warm-up coefficients the recording was made with:

    >>> sim = simulate_scenario("mems-warmup", 0, None, SimulateOptions())
    >>> sim.labels
    ('T-40', 'T-20', 'T+0', 'T+20', 'T+40', 'T+60', 'T+80')
    """
    results = run_scenario(scenario, seed, profile, **options.given())
    labels = [str(t.get("label", "")) for _, t in results]
    if len(set(labels)) != len(labels):
        labels = [f"{i + 1}" for i in range(len(results))]
    return Simulation(scenario, seed, results, tuple(labels))
