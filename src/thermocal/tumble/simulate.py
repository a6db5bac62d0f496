"""An accelerometer on a dividing head with known truth: stations at equal steps of the
turn (the head moving between them at a finite rate), or a continuous slow tumble; the
output is :func:`thermocal.tumble.analysis.expected_output` plus white noise.
"""

from __future__ import annotations

import math
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal.defaults import MAX_SIMULATED_SAMPLES
from thermocal.errors import ParameterError
from thermocal.recording import Metadata, Recording
from thermocal.tumble.analysis import expected_output

FloatArray = npt.NDArray[np.float64]

TRUTH: Final[dict[str, float]] = {
    "k0": 2.0,
    "k1": 1000.3,
    "delta_o": 2e-4,
    "k2": 0.05,
    "k_ip": -0.03,
    "k3": 0.0,
}
"""The simulated accelerometer [mg, mg/g, rad, mg/g², mg/g², mg/g³]: a navigation-grade
pendulous accelerometer (2 mg bias, 300 ppm scale-factor error, 200 µrad misalignment,
K2 = 50 µg/g², K_ip = −30 µg/g²)."""


def _check(**v: float) -> None:
    for name, x in v.items():
        if not (math.isfinite(x) and x > 0):
            raise ParameterError(name, f"{{name}} must be a positive number, got {x!r}")


def _head(
    stations: int,
    dwell_s: float,
    step_rate_dps: float,
    turn_rate_dps: float | None,
    turns: float,
    start_deg: float,
) -> tuple[list[float], list[float], list[float]]:
    """The head's angle knots (times [s], angles [°]) and the stations' angles [°]."""
    if turn_rate_dps is not None:
        duration = 360.0 * turns / turn_rate_dps
        return [0.0, duration], [start_deg, start_deg + 360.0 * turns], []
    step = 360.0 / stations
    angles = [start_deg + k * step for k in range(stations)]
    knots_t: list[float] = []
    knots_a: list[float] = []
    t0 = 0.0
    for a in angles:
        knots_t += [t0, t0 + dwell_s]
        knots_a += [a, a]
        t0 += dwell_s + step / step_rate_dps
    return knots_t, knots_a, angles


def simulate_tumble(
    rng: np.random.Generator,
    *,
    stations: int = 24,
    dwell_s: float = 20.0,
    step_rate_dps: float = 30.0,
    turn_rate_dps: float | None = None,
    turns: float = 1.0,
    rate_hz: float = 50.0,
    noise_mg: float = 0.05,
    start_deg: float = 0.0,
    **coefficients: float,
) -> tuple[Recording, dict[str, Any]]:
    """A tumble test: ``stations`` angles ``360°/stations`` apart, each held ``dwell_s``,
    the head turning at ``step_rate_dps`` between them; or, with ``turn_rate_dps``, a
    continuous tumble of ``turns`` turns.

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source.
    stations : int, optional
        Stations of the head (24: 15° apart).
    dwell_s : float, optional
        Time at each station [s].
    step_rate_dps : float, optional
        The head's rate between stations [°/s].
    turn_rate_dps : float, optional
        A continuous tumble at this rate [°/s] instead of stations.
    turns : float, optional
        Turns of the continuous tumble.
    rate_hz : float, optional
        Sample rate [Hz].
    noise_mg : float, optional
        White noise of the output [mg].
    start_deg : float, optional
        The first angle [°].
    **coefficients : float
        ``k0`` [mg], ``k1`` [mg/g], ``delta_o`` [rad], ``k2``, ``k_ip`` [mg/g²], ``k3``
        [mg/g³]; the others from :data:`TRUTH`.

    Returns
    -------
    Recording
        Columns ``accel`` [mg] and ``angle`` [°] (the head's encoder, in [0, 360)).
    dict
        The truth: the coefficients, the noise, the stations' angles.

    Raises
    ------
    thermocal.errors.ParameterError
        A non-positive option, an unknown coefficient, a record over the sample budget.

    Examples
    --------
    >>> rec, truth = simulate_tumble(np.random.default_rng(0), stations=8, dwell_s=2.0)
    >>> rec.n_samples, truth["angles_deg"][:3]
    (1325, [0.0, 45.0, 90.0])
    """
    unknown = sorted(set(coefficients) - set(TRUTH))
    if unknown:
        raise ParameterError("coefficients", f"{{name}}: unknown coefficient(s) {unknown}")
    _check(dwell_s=dwell_s, step_rate_dps=step_rate_dps, rate_hz=rate_hz, noise_mg=noise_mg,
           turns=turns)  # fmt: skip
    if stations < 1:
        raise ParameterError("stations", f"{{name}} must be at least 1, got {stations}")
    coefs = {**TRUTH, **{k: float(v) for k, v in coefficients.items()}}
    if turn_rate_dps is not None:
        _check(turn_rate_dps=turn_rate_dps)
    knots_t, knots_a, angles = _head(stations, dwell_s, step_rate_dps, turn_rate_dps, turns,
                                     start_deg)  # fmt: skip
    n = round(knots_t[-1] * rate_hz)
    if n > MAX_SIMULATED_SAMPLES:
        raise ParameterError("rate_hz", f"{{name}}: {n} samples, above the budget")
    time = np.arange(n) / rate_hz
    head = np.interp(time, knots_t, knots_a)
    y = expected_output(head, coefs) + noise_mg * rng.standard_normal(n)
    rec = Recording.from_arrays(
        time,
        {"accel": y},
        signal_unit="mg",
        other={"angle": np.round(np.mod(head, 360.0), 6)},
        other_units={"angle": "deg"},
        meta=Metadata(notes="simulated tumble test"),
    )
    truth = {
        **coefs,
        "unit": "mg",
        "noise_mg": noise_mg,
        "rate_hz": rate_hz,
        "turn_rate_dps": turn_rate_dps,
        "angles_deg": [float(np.mod(a, 360.0)) for a in angles],
    }
    return rec, truth
