"""A gyro on a rate table with known truth: the ladder the operator runs, the table's finite
angular acceleration and servo overshoot between plateaus, the sensor's own lag, and the
scale-factor errors the analysis recovers.

Output of the gyro (°/s when ``scale_factor`` is 1):

.. math::

    y = K(T)\\,(1 + \\tfrac{a}{2}\\,\\mathrm{sgn}\\,\\Omega)\\,\\Big(
        \\Omega + q\\,\\frac{\\Omega^2}{\\Omega_{FS}} + c\\,\\frac{\\Omega^3}{\\Omega_{FS}^2}\\Big)
        + b + n, \\qquad K(T) = K_0\\,(1 + \\kappa\\,(T - 25\\,°C)),

with ``q``, ``c``, ``a``, ``κ`` in ppm (of full scale, of ``K``, per °C), no output for
``|Ω|`` below the dead zone (the input threshold), and ``n`` white noise.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.signal import lfilter

from thermocal.defaults import MAX_SIMULATED_SAMPLES
from thermocal.errors import ParameterError
from thermocal.recording import Metadata, Recording

FloatArray = npt.NDArray[np.float64]

DEFAULT_LADDER: tuple[float, ...] = (
    -300.0,
    -200.0,
    -100.0,
    -50.0,
    -10.0,
    -1.0,
    -0.1,
    -0.05,
    -0.02,
    -0.01,
    0.0,
    0.01,
    0.02,
    0.05,
    0.1,
    1.0,
    10.0,
    50.0,
    100.0,
    200.0,
    300.0,
)
"""The default ladder [°/s]: full scale ±300 °/s and small rates for the threshold."""
TREF_C = 25.0
"""Temperature of the nominal scale factor [°C]."""


def expected_output(
    rates_dps: npt.ArrayLike,
    *,
    scale_factor: float = 1.0,
    quadratic_ppm: float = 0.0,
    cubic_ppm: float = 0.0,
    asymmetry_ppm: float = 0.0,
    bias_dps: float = 0.0,
    tc_ppm_per_c: float = 0.0,
    dead_zone_dps: float = 0.0,
    temperature_c: float = TREF_C,
    full_scale_dps: float = 300.0,
) -> FloatArray:
    """The noise-free steady output at each rate (module docstring).

    Parameters
    ----------
    rates_dps : array_like
        Input rates [°/s].
    scale_factor : float
        ``K₀`` at 25 °C [output unit per °/s].
    quadratic_ppm, cubic_ppm : float
        ``q`` and ``c`` [ppm of full scale at full scale].
    asymmetry_ppm : float
        ``a``: the positive rates' scale factor exceeds the negative rates' by ``a·K`` [ppm].
    bias_dps : float
        Bias [output unit].
    tc_ppm_per_c : float
        ``κ`` [ppm/°C].
    dead_zone_dps : float
        No output below this input rate [°/s].
    temperature_c : float
        Temperature [°C].
    full_scale_dps : float
        ``Ω_FS`` [°/s].

    Returns
    -------
    numpy.ndarray
        Output [output unit].

    Examples
    --------
    >>> expected_output([-100.0, 100.0], asymmetry_ppm=1000.0).tolist()
    [-99.95, 100.05]
    """
    w = np.asarray(rates_dps, float)
    g = (
        w
        + quadratic_ppm * 1e-6 * w**2 / full_scale_dps
        + cubic_ppm * 1e-6 * w**3 / full_scale_dps**2
    )
    g = np.where(np.abs(w) < dead_zone_dps, 0.0, g)
    k = scale_factor * (1 + tc_ppm_per_c * 1e-6 * (temperature_c - TREF_C))
    return np.asarray(k * (1 + 0.5e-6 * asymmetry_ppm * np.sign(w)) * g + bias_dps, float)


def ladder_order(rates: Sequence[float], *, repeats: int = 1, up_down: bool = False) -> list[float]:
    """The rates in the order the operator runs them: the ladder as given, then (``up_down``)
    back down without repeating its last rate, the whole ``repeats`` times.

    Parameters
    ----------
    rates : sequence of float
        The ladder [°/s].
    repeats : int
        How many times the operator runs it.
    up_down : bool
        Run it back the other way after each pass.

    Returns
    -------
    list of float

    Examples
    --------
    >>> ladder_order([-1, 0, 1], up_down=True)
    [-1, 0, 1, 0, -1]
    """
    one = list(rates) + (list(rates)[-2::-1] if up_down else [])
    return one * repeats


def _lagged(clean: FloatArray, rate_hz: float, lag_s: float) -> FloatArray:
    """The sensor's first-order lag of time constant ``lag_s`` (none at 0)."""
    a = float(np.exp(-1.0 / (rate_hz * lag_s))) if lag_s > 0 else 0.0
    zi = np.array([clean[0] * a])
    return np.asarray(lfilter([1 - a], [1, -a], clean, zi=zi)[0] if a else clean, float)


def _check_args(
    dwell_s: float, accel_dps2: float, rate_hz: float, noise_dps: float, lead_s: float = 0.0
) -> None:
    """Refuse values no table can run."""
    if not (np.isfinite(lead_s) and lead_s >= 0):
        raise ParameterError("lead_s", f"{{name}} must be ≥ 0, got {lead_s!r}")
    for name, v in (("dwell_s", dwell_s), ("accel_dps2", accel_dps2), ("rate_hz", rate_hz)):
        if not (np.isfinite(v) and v > 0):
            raise ParameterError(name, f"{{name}} must be a positive number, got {v!r}")
    if not (np.isfinite(noise_dps) and noise_dps >= 0):
        raise ParameterError("noise_dps", f"{{name}} must be ≥ 0, got {noise_dps!r}")


def simulate_ladder(
    rng: np.random.Generator,
    *,
    rates_dps: Sequence[float] = DEFAULT_LADDER,
    repeats: int = 1,
    up_down: bool = False,
    dwell_s: float = 20.0,
    accel_dps2: float = 100.0,
    rate_hz: float = 100.0,
    noise_dps: float = 0.005,
    lag_s: float = 0.01,
    cut_short: int | None = None,
    cut_fraction: float = 0.2,
    temperature_c: float = TREF_C,
    lead_s: float = 0.0,
    rate_column: bool = True,
    **errors: float,
) -> tuple[Recording, dict[str, Any]]:
    """A rate ladder run on a table: gyro output, the table's rate and the temperature.

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source.
    rates_dps : sequence of float
        The ladder [°/s].
    repeats : int
        Passes of the ladder.
    up_down : bool
        Each pass goes up the ladder and back down.
    dwell_s : float
        Hold at each rate [s].
    accel_dps2 : float
        The table's angular acceleration between rates [°/s²].
    rate_hz : float
        Sample rate [Hz].
    noise_dps : float
        White noise σ per sample [output unit].
    lag_s : float
        The sensor's first-order time constant [s].
    cut_short : int, optional
        Index (in the run's order) of a plateau the operator cut short.
    cut_fraction : float
        The part of ``dwell_s`` that plateau holds.
    temperature_c : float
        The table's chamber temperature [°C] (the thermometer reads to 0.1 °C).
    lead_s : float
        The record starts this long before the program, the table at rest [s] (0: on the
        first plateau).
    rate_column : bool
        Write the table's rate column (False: the gyro and the temperature, as a logger).
    **errors : float
        The error model of :func:`expected_output` (``scale_factor``, ``quadratic_ppm``,
        ``cubic_ppm``, ``asymmetry_ppm``, ``bias_dps``, ``tc_ppm_per_c``, ``dead_zone_dps``).

    Returns
    -------
    Recording
        Columns ``gyro`` [°/s], ``table_rate`` [°/s] and the temperature ``temp``.
    dict
        The truth: the error model, the plateaus (start, end, rate) and each plateau's
        noise-free output.

    Examples
    --------
    >>> rec, truth = simulate_ladder(np.random.default_rng(0), rates_dps=[-10, 0, 10],
    ...                              dwell_s=5.0, cubic_ppm=100.0)
    >>> rec.n_samples, [round(y, 4) for y in truth["outputs"]]
    (1520, [-10.001, 0.0, 10.001])
    """
    _check_args(dwell_s, accel_dps2, rate_hz, noise_dps, lead_s)
    order = ladder_order(rates_dps, repeats=repeats, up_down=up_down)
    errors = {"full_scale_dps": float(np.max(np.abs(rates_dps))), **errors}
    dwells = [dwell_s * (cut_fraction if k == cut_short else 1.0) for k in range(len(order))]
    time, rate, plat = _profile_dwells(order, dwells, accel_dps2, rate_hz, lead_s)
    clean = expected_output(rate, temperature_c=temperature_c, **errors)
    gyro = _lagged(clean, rate_hz, lag_s) + noise_dps * rng.standard_normal(time.size)
    temp = np.round(temperature_c + 0.02 * rng.standard_normal(time.size), 1)
    rec = Recording.from_arrays(
        time,
        {"gyro": gyro},
        {"temp": temp},
        signal_unit="deg/s",
        other={"table_rate": rate} if rate_column else None,
        other_units={"table_rate": "deg/s"} if rate_column else None,
        meta=Metadata(notes="simulated rate-table ladder"),
    )
    truth = {
        **errors,
        "temperature_c": temperature_c,
        "noise_dps": noise_dps,
        "lag_s": lag_s,
        "accel_dps2": accel_dps2,
        "dwell_s": dwell_s,
        "lead_s": lead_s,
        "order_dps": order,
    }
    return rec, {**truth, **_plateau_truth(plat, temperature_c, errors)}


def _plateau_truth(
    plat: Sequence[tuple[float, float, float]], temperature_c: float, errors: dict[str, float]
) -> dict[str, Any]:
    """The truth's plateaus (start, end, rate) and each one's noise-free output."""
    outputs = expected_output([p[2] for p in plat], temperature_c=temperature_c, **errors)
    return {
        "plateaus": [{"start_s": a0, "end_s": b0, "rate_dps": r} for a0, b0, r in plat],
        "outputs": outputs.tolist(),
    }


def _profile_dwells(
    order: Sequence[float],
    dwells: Sequence[float],
    accel_dps2: float,
    rate_hz: float,
    lead_s: float = 0.0,
) -> tuple[FloatArray, FloatArray, list[tuple[float, float, float]]]:
    """The table's rate: a dwell per plateau, ``lead_s`` at rest before the first."""
    knots_t, knots_r, plat = [0.0], [float(order[0])], []
    t = 0.0
    if lead_s > 0:
        t = lead_s + abs(float(order[0])) / accel_dps2
        knots_t, knots_r = [0.0, lead_s, t], [0.0, 0.0, float(order[0])]
    for k, (r, d) in enumerate(zip(order, dwells, strict=True)):
        if k:
            t += abs(r - knots_r[-1]) / accel_dps2
            knots_t.append(t)
            knots_r.append(float(r))
        plat.append((t, t + d, float(r)))
        t += d
        knots_t.append(t)
        knots_r.append(float(r))
    n = round(t * rate_hz)
    if n > MAX_SIMULATED_SAMPLES:
        raise ParameterError("dwell_s", f"{{name}}: {n} samples, above the budget; shorten it")
    time = np.arange(n) / rate_hz
    rate = np.interp(time, knots_t, knots_r)
    for k, (t0, _, r) in enumerate(plat[1:], start=1):
        step = r - plat[k - 1][2]
        after = time >= t0
        dt = time[after] - t0
        rate[after] += 0.02 * step * np.exp(-dt / 0.15) * np.sin(2 * np.pi * 4.0 * dt)
    return time, rate, plat


def simulate_temperatures(
    rng: np.random.Generator, temperatures_c: Sequence[float], **opts: Any
) -> list[tuple[Recording, dict[str, Any]]]:
    """The same ladder at several chamber temperatures: one recording each.

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source.
    temperatures_c : sequence of float
        The temperatures [°C].
    **opts
        Options of :func:`simulate_ladder`.

    Returns
    -------
    list of (Recording, dict)
    """
    return [simulate_ladder(rng, temperature_c=float(t), **opts) for t in temperatures_c]
