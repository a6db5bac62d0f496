"""Gyro and accelerometer figures of merit (IEEE Std 952-1997 and IEEE Std 1293-1998 style).

The pure functions take rates in any one unit (their results are in the same unit;
the drift angle's time base is stated by ``time_unit_s``), times in [s], temperatures
in [°C].  :func:`compute_metrics` runs them on a :class:`~thermocal.recording.Recording`
for the command line and the reports and gives every figure in the data's own unit
(the signal column's unit as given: °/s data give °/s, rad/s data rad/s, g data g;
raw counts converted by a scale factor K give the canonical [°/h] or [mg]).

Averages over a stated time ("bias stability at 100 s") are non-overlapping
block means of ``m = round(averaging_s / τ0)`` consecutive samples, formed
inside each contiguous (gap-free) stretch only; an incomplete block at the end
of a stretch is dropped.
"""

from __future__ import annotations

import bisect
import dataclasses
import hashlib
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Final, TypeVar

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal._lazy import LazyModule
from thermocal.data_units import data_unit_of
from thermocal.errors import (
    MissingValueError,
    ParameterError,
    PlausibilityWarning,
    ThermocalInputError,
)
from thermocal.recording import Recording, contiguous_slices, is_increasing

_Run = TypeVar("_Run")
"""A run as the caller names it (a path): ``read`` turns it into a recording."""
FloatArray = npt.NDArray[np.float64]

special = LazyModule("scipy.special")  # chi-square quantiles, when an interval is asked for

ONE_SIGMA: float = math.erf(1.0 / math.sqrt(2.0))
"""0.6827, the confidence of a ±1σ interval."""


# --- results -------------------------------------------------------------------------


@dataclass(frozen=True)
class TemperatureSensitivity:
    """Bias temperature sensitivity (thermocal's reading: both figures, named).

    Attributes
    ----------
    mean_abs_adjacent : mean of |ΔB/ΔT| between adjacent temperature points [unit/°C].
    ls_slope : least-squares slope of B against T [unit/°C].
    unit : e.g. ``"deg/h/degC"``.
    n_points : number of temperature points.
    temps_c, biases : the points, sorted by temperature.
    """

    mean_abs_adjacent: float
    ls_slope: float
    unit: str
    n_points: int
    temps_c: tuple[float, ...]
    biases: tuple[float, ...]


@dataclass(frozen=True)
class Stage:
    """A temperature-hold stage: its mean temperature [°C] and bias [unit].

    Attributes
    ----------
    start_s, stop_s : float
        The stage's span [s].
    mean_temp_c : float
        Its mean temperature [°C].
    bias : float
        Its mean bias [unit].
    n_samples : int
        Samples in it.
    """

    start_s: float
    stop_s: float
    mean_temp_c: float
    bias: float
    n_samples: int


@dataclass(frozen=True)
class DriftReference:
    """The constant bias b0 removed before the drift angle is integrated.

    Attributes
    ----------
    kind : ``"window"`` — b0 is the mean of ω − Ω_axis over the reference window
        [``start_s``, ``end_s``] (seconds since the first sample); ``"bias"`` — b0 was
        given (``drift_bias``); ``"model"`` — a compensation model removed the bias
        (b0 = 0 on the compensated output).
    start_s, end_s : the window [s since the first sample] (None unless ``"window"``).
    bias : b0 [``unit``], earth rate already removed (comparable with ``bias``).
    unit : the rate unit of ``bias``.
    n_samples : samples in the window (None unless ``"window"``).
    """

    kind: str
    start_s: float | None
    end_s: float | None
    bias: float
    unit: str
    n_samples: int | None = None


@dataclass(frozen=True)
class DriftExtreme:
    """The drift angle's end value and its largest magnitude (the FOG thesis).

    ``end`` θ(t_end), ``max_abs`` max_t |θ(t)|, reached at ``max_time_s`` [s since the
    first sample]; all angles in [``unit``].

    Attributes
    ----------
    end : float
        θ(t_end) [``unit``].
    max_abs : float
        max_t |θ(t)| [``unit``].
    max_time_s : float
        When it is reached [s since the first sample].
    unit : str
        Unit of the angles.
    """

    end: float
    max_abs: float
    max_time_s: float
    unit: str


DEFAULT_DRIFT_REFERENCE_FRACTION = 0.1
"""Default drift-angle reference window: the first 10 % of the run's duration."""

RATE_ANGLE_UNITS: dict[str, tuple[str, float]] = {
    "deg/h": ("deg", units.SECONDS_PER_HOUR),
    "deg/s": ("deg", 1.0),
    "rad/s": ("rad", 1.0),
}
"""Rate unit → (the angle unit of its integral, seconds per the rate's time unit)."""


@dataclass(frozen=True)
class MetricsResult:
    """Figures of merit of one signal (JSON keys of ``thermocal metrics``), every rate
    figure in ``unit`` — the data's own unit (module docstring).

    ``bias`` has the earth-rate component ``earth_rate_removed`` [unit] taken off;
    ``bias_stability`` and ``peak_to_peak`` are over ``averaging_s`` averages;
    ``drift_angle`` is the final value and ``drift_angle_max`` the largest magnitude
    (reached at ``drift_angle_max_time_s`` [s since the first sample]) of
    ``θ(t) = ∫ (ω − Ω_axis − b0) dt`` [``drift_angle_unit``: deg, or rad for rad/s data],
    b0 the constant stated by ``drift_reference`` (trapezoid rule, gaps not integrated;
    gyros only).

    Attributes
    ----------
    bias : float
        Mean of the signal less the earth-rate component [unit].
    bias_stability : float
        Standard deviation of the ``averaging_s`` averages [unit].
    averaging_s : float
        Averaging time [s].
    peak_to_peak : float
        Peak-to-peak of the averages [unit].
    unit : str
        The data's own unit.
    temperature_sensitivity : TemperatureSensitivity or None
        Bias against temperature over the hold stages (None: fewer than two stages).
    bias_repeatability : float or None
        Standard deviation of the stages' biases [unit].
    stages : tuple of Stage
        The hold stages.
    drift_angle : float or None
        θ at the end [``drift_angle_unit``] (gyros).
    drift_angle_unit : str or None
        ``deg``, or ``rad`` for rad/s data.
    earth_rate_removed : float
        Earth-rate component taken off the bias [unit].
    n_samples, n_segments, n_averages : int
        Samples, gap-free segments and averages.
    duration_s : float
        Span of the record [s].
    signal : str
        The signal column.
    drift_angle_max : float or None
        Largest |θ| [``drift_angle_unit``].
    drift_angle_max_time_s : float or None
        When it is reached [s since the first sample].
    drift_reference : DriftReference or None
        How b0 was taken.
    """

    bias: float
    bias_stability: float
    averaging_s: float
    peak_to_peak: float
    unit: str
    temperature_sensitivity: TemperatureSensitivity | None
    bias_repeatability: float | None
    stages: tuple[Stage, ...]
    drift_angle: float | None
    drift_angle_unit: str | None
    earth_rate_removed: float
    n_samples: int
    n_segments: int
    n_averages: int
    duration_s: float
    signal: str
    drift_angle_max: float | None = None
    drift_angle_max_time_s: float | None = None
    drift_reference: DriftReference | None = None

    def to_dict(self) -> dict[str, Any]:
        """The figures as plain Python values: the object the ``metrics`` command prints
        as JSON for one channel (NaN where it prints null).

        Returns
        -------
        dict
            ``bias``, ``bias_stability``, ``averaging_s`` [s], ``peak_to_peak``, ``unit``
            (every rate figure in it), ``temperature_sensitivity`` (its fields, or None),
            ``bias_repeatability``, ``drift_angle_max``, ``drift_angle_max_time_s`` [s],
            ``drift_angle``, ``drift_angle_unit``, ``drift_reference`` (its fields, or
            None), ``earth_rate_removed``, ``n_stages``, ``stages`` (each hold stage's
            fields), ``n_samples``, ``n_segments``, ``n_averages``, ``duration_s`` [s] and
            ``signal``.

        References
        ----------
        IEEE Std 952-1997, IEEE Std 1431-2004 (the figures' definitions).
        """
        ts = self.temperature_sensitivity
        return {
            "bias": self.bias,
            "bias_stability": self.bias_stability,
            "averaging_s": self.averaging_s,
            "peak_to_peak": self.peak_to_peak,
            "unit": self.unit,
            "temperature_sensitivity": None if ts is None else _plain(ts),
            "bias_repeatability": self.bias_repeatability,
            "drift_angle_max": self.drift_angle_max,
            "drift_angle_max_time_s": self.drift_angle_max_time_s,
            "drift_angle": self.drift_angle,
            "drift_angle_unit": self.drift_angle_unit,
            "drift_reference": _plain(self.drift_reference),
            "earth_rate_removed": self.earth_rate_removed,
            "n_stages": len(self.stages),
            "stages": _plain(self.stages),
            "n_samples": self.n_samples,
            "n_segments": self.n_segments,
            "n_averages": self.n_averages,
            "duration_s": self.duration_s,
            "signal": self.signal,
        }


def _plain(obj: Any) -> Any:
    """A result's value as plain Python: dataclasses as dicts, tuples as lists."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: _plain(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, list | tuple):
        return [_plain(v) for v in obj]
    return obj


# --- helpers ---------------------------------------------------------------------------


def _as_1d(values: npt.ArrayLike, name: str) -> FloatArray:
    arr = np.asarray(values, dtype=np.float64).ravel()
    if arr.size == 0:
        raise ThermocalInputError(f"{name} is empty")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise MissingValueError(
            f"{name} has {bad.size} NaN/infinite values (first at row {bad[0]})"
        )
    return arr


def _samples_per_average(tau0_s: float, averaging_s: float | None) -> int:
    if not (math.isfinite(tau0_s) and tau0_s > 0):
        raise ThermocalInputError(f"sample interval τ0 must be positive, got {tau0_s!r}")
    if averaging_s is None:
        return 1
    if not (math.isfinite(averaging_s) and averaging_s > 0):
        raise ThermocalInputError(f"averaging time must be positive, got {averaging_s!r}")
    return max(round(averaging_s / tau0_s), 1)


def block_means(
    values: npt.ArrayLike,
    tau0_s: float,
    averaging_s: float | None,
    *,
    time_s: npt.ArrayLike | None = None,
) -> FloatArray:
    r"""Non-overlapping means of ``m = round(averaging_s/τ0)`` samples, never across a gap.

    Parameters
    ----------
    values : array_like
        Samples [unit].
    tau0_s : float
        Sample interval τ0 [s].
    averaging_s : float or None
        Averaging time [s]; None: the samples themselves.
    time_s : array_like, optional
        Sample times [s]: the record is cut at gaps and each stretch averaged alone.

    Returns
    -------
    numpy.ndarray
        The block means [unit]; an incomplete block at a stretch's end is dropped.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        ``time_s`` and ``values`` of different lengths, a bad averaging time.

    Notes
    -----
    .. math:: \bar\omega_k = \frac{1}{m}\sum_{i=km}^{km+m-1} \omega_i

    Examples
    --------
    >>> block_means([1.0, 3.0, 5.0, 7.0, 9.0], 1.0, 2.0).tolist()
    [2.0, 6.0]
    """
    y = _as_1d(values, "signal")
    m = _samples_per_average(tau0_s, averaging_s)
    if time_s is None:
        slices = [slice(0, y.size)]
    else:
        t = np.asarray(time_s, dtype=np.float64).ravel()
        if t.shape != y.shape:
            raise ThermocalInputError(f"time has {t.size} samples but the signal has {y.size}")
        slices = contiguous_slices(t)
    parts = []
    for sl in slices:
        seg = y[sl]
        k = seg.size // m
        if k:
            parts.append(seg[: k * m].reshape(k, m).mean(axis=1))
    return np.concatenate(parts) if parts else np.zeros(0)


# --- figures of merit ------------------------------------------------------------------


def bias(rate: npt.ArrayLike, *, earth_rate_deg_h: float = 0.0) -> float:
    r"""Bias: the mean rate less the earth rate the sensitive axis sees.

    Parameters
    ----------
    rate : array_like
        Rate samples ω_i [°/h] (any unit, with ``earth_rate_deg_h`` in the same).
    earth_rate_deg_h : float
        The earth rate on the sensitive axis Ω_axis [°/h]
        (:func:`thermocal.units.earth_rate_on_axis_deg_h`); 0 for accelerometers.

    Returns
    -------
    float
        B0 [°/h].

    Notes
    -----
    .. math:: B_0 = \frac{1}{n}\sum_i \omega_i - \Omega_{axis}

    (IEEE Std 952-1997 and IEEE Std 1431-2004 define the bias as the average output over
    a specified time that has no correlation with the input rotation.)

    References
    ----------
    .. [1] IEEE Std 952-1997; IEEE Std 1431-2004.

    Examples
    --------
    >>> bias([10.0, 12.0, 14.0], earth_rate_deg_h=2.0)
    10.0
    """
    return float(np.mean(_as_1d(rate, "rate"))) - float(earth_rate_deg_h)


def bias_from_counts(
    counts: npt.ArrayLike,
    scale_factor: float,
    tau_s: float,
    *,
    scale_factor_unit: str = "counts/arcsec",
    earth_rate_deg_h: float = 0.0,
) -> float:
    r"""Bias from raw pulse counts: ``B0 = (1/(τK)) · mean(N_i) − Ω_axis`` [°/h].

    ``scale_factor`` K in ``scale_factor_unit`` (see
    :data:`thermocal.units.SCALE_FACTOR_UNITS`; the default pulses per arcsec
    gives [arcsec/s] = [°/h]), ``tau_s`` the sample interval τ [s].

    Parameters
    ----------
    counts : array_like
        Pulse counts N_i per sample interval [counts].
    scale_factor : float
        Scale factor K [``scale_factor_unit``].
    tau_s : float
        Sample interval τ [s].
    scale_factor_unit : str, optional
        Unit of K (default ``"counts/arcsec"``).
    earth_rate_deg_h : float, optional
        Earth-rate component Ω_axis along the sensitive axis [°/h] (default 0).

    Returns
    -------
    float
        Bias B0 [°/h].

    Notes
    -----
    .. math:: B_0 = \frac{1}{\tau K} \overline{N_i} - \Omega_{axis}

    References
    ----------
    - IEEE Std 952-1997; IEEE Std 1431-2004 (bias as the average output).
    """
    rate, _unit = units.counts_to_physical(
        _as_1d(counts, "counts"), scale_factor, scale_factor_unit, tau_s
    )
    return bias(rate, earth_rate_deg_h=earth_rate_deg_h)


def bias_stability(
    rate: npt.ArrayLike,
    tau0_s: float,
    averaging_s: float | None,
    *,
    time_s: npt.ArrayLike | None = None,
    where: str | None = None,
) -> float:
    r"""Bias stability: the standard deviation of the averages over ``averaging_s``.

    Parameters
    ----------
    rate : array_like
        Rate samples [unit].
    tau0_s : float
        Sample interval τ0 [s].
    averaging_s : float or None
        Averaging time [s] (report it with the figure); None: the samples.
    time_s : array_like, optional
        Sample times [s]; no average spans a gap (:func:`block_means`).
    where : str, optional
        The file a refusal names.

    Returns
    -------
    float
        Bs [unit].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Fewer than two averages (the message names ``averaging_s`` with the longest
        averaging time that gives two).

    Notes
    -----
    With the p block means :math:`\bar\omega_k` (:func:`block_means`):

    .. math:: B_s = \sqrt{\frac{1}{p-1}\sum_{k=1}^{p}(\bar\omega_k - \bar\omega)^2}

    Examples
    --------
    >>> round(bias_stability([1.0, 3.0, 5.0, 7.0, 9.0, 11.0], 1.0, 2.0), 3)
    4.0
    """
    means = block_means(rate, tau0_s, averaging_s, time_s=time_s)
    if means.size < 2:
        raise _too_few_averages_error(
            where, float(averaging_s or tau0_s), means.size,
            _longest_stretch_s(time_s, tau0_s, np.size(rate)),
        )  # fmt: skip
    return float(np.std(means, ddof=1))


def _too_few_averages_error(
    where: str | None, averaging_s: float, n_means: int, longest_s: float
) -> ThermocalInputError:
    """The refusal of :func:`too_few_averages` naming the parameter ``averaging_s``."""
    text = too_few_averages(where, averaging_s, n_means, longest_s, "{averaging_s}")
    return ThermocalInputError.naming(text, "averaging_s")


def _longest_stretch_s(time_s: npt.ArrayLike | None, tau0_s: float, n: int) -> float:
    """The duration [s] of the longest stretch without a gap (``n·τ0`` without times)."""
    if time_s is None:
        return n * tau0_s
    t = np.asarray(time_s, dtype=np.float64).ravel()
    return float(max((sl.stop - sl.start) * tau0_s for sl in contiguous_slices(t)))


def too_few_averages(
    where: str | None, averaging_s: float, n_means: int, longest_s: float, name: str | None
) -> str:
    """The message of a record that gives fewer than two ``averaging_s`` averages: the file
    ``where``, and the name ``name`` of what sets the averaging time (a parameter,
    ``averaging_s``) with the longest averaging time that gives two averages (half the
    longest stretch without a gap ``longest_s`` [s]); without a name, the record's length is
    what falls short.

    Parameters
    ----------
    where : str or None
        File named in the message.
    averaging_s : float
        Averaging time asked [s].
    n_means : int
        Number of averages it gives.
    longest_s : float
        Longest gap-free stretch [s].
    name : str or None
        What sets the averaging time, as the message names it (None: nothing does).

    Returns
    -------
    str
        The message.

    Examples
    --------
    >>> too_few_averages("a.csv", 600.0, 1, 900.0, "averaging_s").split("; ")[-1]
    'give averaging_s 450 or less'
    """
    head = f"{where}: " if where else ""
    fix = (
        f"; give {name} {longest_s / 2.0:.3g} or less"
        if name and longest_s / 2.0 > 0
        else f"; its longest stretch without a gap is {longest_s:.3g} s: record at least "
        f"{2.0 * averaging_s:.3g} s"
    )
    return (
        f"{head}bias stability needs at least two {averaging_s:g} s averages; the record "
        f"gives {n_means}{fix}"
    )


def bias_repeatability(biases: npt.ArrayLike) -> float:
    r"""Bias repeatability: the standard deviation of the biases of p runs or hold stages.

    Parameters
    ----------
    biases : array_like
        The p biases B0_i [unit].

    Returns
    -------
    float
        Br [unit].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Fewer than two biases.

    Notes
    -----
    .. math:: B_r = \sqrt{\frac{1}{p-1}\sum_{i=1}^{p}(B_{0,i} - \bar B_0)^2}

    Examples
    --------
    >>> bias_repeatability([1.0, 2.0, 3.0])
    1.0
    """
    b = _as_1d(biases, "biases")
    if b.size < 2:
        raise ThermocalInputError(f"bias repeatability needs at least two biases, got {b.size}")
    return float(np.std(b, ddof=1))


@dataclass(frozen=True)
class RunRepeatability:
    """Turn-on to turn-on repeatability over separate power-ons, in ``unit``.

    ``runs`` each run's figures (its bias and in-run bias stability); ``bias_repeatability``
    the sample standard deviation of the run biases, ``low``/``high`` its chi-square
    interval at ``confidence`` (:func:`std_interval`); ``bias_mean`` the mean run bias.

    Attributes
    ----------
    runs : tuple of MetricsResult
        Each run's figures.
    files : tuple of str
        The runs' files.
    bias_mean : float
        Mean of the run biases [unit].
    bias_repeatability : float
        Sample standard deviation of the run biases [unit].
    bias_repeatability_low, bias_repeatability_high : float
        Its chi-square interval at ``confidence`` [unit].
    confidence : float
        Confidence level of the interval.
    unit : str
        The data's unit.
    """

    runs: tuple[MetricsResult, ...]
    files: tuple[str, ...]
    bias_mean: float
    bias_repeatability: float
    bias_repeatability_low: float
    bias_repeatability_high: float
    confidence: float
    unit: str

    def to_dict(self) -> dict[str, Any]:
        """The repeatability as plain Python values: the object the ``metrics`` command
        prints as JSON for one channel of several files (NaN where it prints null).

        Returns
        -------
        dict
            ``runs`` (each run's :meth:`MetricsResult.to_dict` with ``file`` first),
            ``n_runs``, ``bias`` (the mean run bias), ``bias_stability`` (the largest
            in-run one), ``averaging_s`` [s], ``bias_repeatability`` (the sample standard
            deviation of the run biases) with ``bias_repeatability_low``/``_high`` (its
            chi-square interval), ``bias_repeatability_kind``, ``confidence`` and ``unit``.

        References
        ----------
        IEEE Std 952-1997 (turn-on to turn-on bias repeatability).
        """
        return {
            "runs": [
                {"file": f, **r.to_dict()} for f, r in zip(self.files, self.runs, strict=True)
            ],
            "n_runs": len(self.runs),
            "bias": self.bias_mean,
            "bias_stability": max(r.bias_stability for r in self.runs),
            "averaging_s": self.runs[0].averaging_s,
            "bias_repeatability": self.bias_repeatability,
            "bias_repeatability_low": self.bias_repeatability_low,
            "bias_repeatability_high": self.bias_repeatability_high,
            "bias_repeatability_kind": "turn-on to turn-on (sample standard deviation "
            "of the run biases)",
            "confidence": self.confidence,
            "unit": self.unit,
        }


def std_interval(s: float, n: int, confidence: float = ONE_SIGMA) -> tuple[float, float]:
    r"""Chi-square interval of a standard deviation ``s`` of ``n`` normal samples.

    Parameters
    ----------
    s : float
        The sample standard deviation [unit].
    n : int
        The number of samples.
    confidence : float
        Confidence level c, in (0, 1) (default ±1σ).

    Returns
    -------
    low, high : float
        The bounds [unit].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        ``n`` < 2 or ``confidence`` outside (0, 1).

    Notes
    -----
    With ν = n − 1 (NIST SP 1065 eq. 45, as for a deviation with ν degrees of freedom):

    .. math:: \sigma \in \left[ s\sqrt{\nu/\chi^2_{(1+c)/2}(\nu)},\;
              s\sqrt{\nu/\chi^2_{(1-c)/2}(\nu)} \right]

    References
    ----------
    .. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.

    Examples
    --------
    Ten samples at 95 %: the chi-square quantiles of 9 degrees of freedom are 19.02 and
    2.70.

    >>> [round(v, 3) for v in std_interval(1.0, 10, 0.95)]
    [0.688, 1.826]
    """
    if n < 2:
        raise ThermocalInputError(f"a standard deviation needs at least two values, got {n}")
    if not 0.0 < confidence < 1.0:
        raise ThermocalInputError(f"confidence must be in (0, 1), got {confidence!r}")
    nu = float(n - 1)
    p = (1.0 - confidence) / 2.0
    chi_upper = float(special.chdtri(nu, p))  # upper quantile (inverse survival function)
    chi_lower = float(special.chdtri(nu, 1.0 - p))
    return s * math.sqrt(nu / chi_upper), s * math.sqrt(nu / chi_lower)


def run_repeatability(
    runs: list[MetricsResult], files: list[str], confidence: float = ONE_SIGMA
) -> RunRepeatability:
    r"""Turn-on to turn-on bias repeatability of several runs of one signal (separate
    power-ons): ``Br = sqrt(Σ (B_i − B̄)² / (p − 1))`` over the p run biases
    (:func:`bias_repeatability`) with its chi-square interval (:func:`std_interval`).
    Every run must be in one unit.

    Parameters
    ----------
    runs : list of MetricsResult
        Figures of each run, in one unit.
    files : list of str
        Files of the runs.
    confidence : float, optional
        Confidence level of the interval (default one sigma, 0.683).

    Returns
    -------
    RunRepeatability
        Repeatability Br [unit] and its interval.

    Raises
    ------
    ThermocalInputError
        Fewer than two runs, or runs in different units.

    Notes
    -----
    .. math:: B_r = \sqrt{\textstyle\sum_i (B_i - \bar B)^2 / (p - 1)}

    References
    ----------
    - IEEE Std 952-1997 (turn-on to turn-on bias repeatability).
    """
    if len(runs) < 2:
        raise ThermocalInputError(f"turn-on repeatability needs at least two runs, got {len(runs)}")
    unit = runs[0].unit
    for r, f in zip(runs, files, strict=True):
        if r.unit != unit:
            raise ThermocalInputError.naming(
                f"{f}: {r.signal} is in {r.unit}, the first run in {unit}; give the runs in "
                "one unit ({signal_unit})",
                "signal_unit",
            )
    biases = [r.bias for r in runs]
    br = bias_repeatability(biases)
    lo, hi = std_interval(br, len(runs), confidence)
    return RunRepeatability(
        runs=tuple(runs), files=tuple(files), bias_mean=float(np.mean(biases)),
        bias_repeatability=br, bias_repeatability_low=lo, bias_repeatability_high=hi,
        confidence=confidence, unit=unit,
    )  # fmt: skip


def temperature_sensitivity(
    temps_c: npt.ArrayLike, biases: npt.ArrayLike, *, unit: str = "deg/h"
) -> TemperatureSensitivity:
    r"""Bias temperature sensitivity [unit/°C], two ways.

    Parameters
    ----------
    temps_c : array_like
        Temperatures T_i [°C] of the points (two or more, distinct).
    biases : array_like
        The biases B_i [unit] at those temperatures.
    unit : str
        Unit of ``biases``.

    Returns
    -------
    TemperatureSensitivity
        ``mean_abs_adjacent`` and ``ls_slope`` [unit/°C], the sorted points.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Fewer than two points, two at the same temperature, lengths that differ.

    Notes
    -----
    With the points sorted by temperature (thermocal's reading: both figures, named),

    .. math:: S_{adj} = \frac{1}{n-1}\sum_{i=1}^{n-1}
              \left|\frac{B_{i+1}-B_i}{T_{i+1}-T_i}\right|

    and ``ls_slope`` the slope b of the least-squares line B = a + b T.

    Examples
    --------
    >>> s = temperature_sensitivity([20.0, 30.0, 40.0], [1.0, 2.0, 2.5])
    >>> round(s.mean_abs_adjacent, 3), round(s.ls_slope, 3)
    (0.075, 0.075)
    """
    T = _as_1d(temps_c, "temperatures")
    B = _as_1d(biases, "biases")
    if T.shape != B.shape:
        raise ThermocalInputError(f"{T.size} temperatures but {B.size} biases")
    if T.size < 2:
        raise ThermocalInputError("temperature sensitivity needs at least two temperature points")
    order = np.argsort(T, kind="stable")
    T, B = T[order], B[order]
    dT = np.diff(T)
    if np.any(dT == 0):
        raise ThermocalInputError(
            "two temperature points have the same temperature; merge them first"
        )
    mean_abs = float(np.mean(np.abs(np.diff(B) / dT)))
    design = np.column_stack([np.ones_like(T), T - T.mean()])
    sol, *_ = np.linalg.lstsq(design, B, rcond=None)
    return TemperatureSensitivity(
        mean_abs_adjacent=mean_abs,
        ls_slope=float(sol[1]),
        unit=f"{unit}/degC",
        n_points=int(T.size),
        temps_c=tuple(float(v) for v in T),
        biases=tuple(float(v) for v in B),
    )


def peak_to_peak(
    rate: npt.ArrayLike,
    tau0_s: float,
    averaging_s: float | None,
    *,
    time_s: npt.ArrayLike | None = None,
) -> float:
    r"""Peak-to-peak variation ``max(ω̄_k) − min(ω̄_k)`` of the averages over
    ``averaging_s`` [unit] (blocks as in :func:`block_means`).

    Parameters
    ----------
    rate : array_like
        Rate samples [unit].
    tau0_s : float
        Sample interval [s].
    averaging_s : float or None
        Averaging time [s]; None: the samples themselves.
    time_s : array_like, optional
        Sample times [s] (gaps split the blocks).

    Returns
    -------
    float
        Peak-to-peak variation [unit].

    Notes
    -----
    .. math:: \max_k \bar\omega_k - \min_k \bar\omega_k
    """
    means = block_means(rate, tau0_s, averaging_s, time_s=time_s)
    if means.size == 0:
        raise ThermocalInputError(f"the record is shorter than one {averaging_s} s average")
    return float(np.max(means) - np.min(means))


def drift_angle(
    time_s: npt.ArrayLike,
    rate: npt.ArrayLike,
    bias: float,
    *,
    time_unit_s: float = units.SECONDS_PER_HOUR,
) -> FloatArray:
    r"""Drift angle: the integral of the rate less its bias (the FOG thesis).

    Parameters
    ----------
    time_s : array_like
        Sample times t_k [s].
    rate : array_like
        Rate samples ω_k [angle unit per time unit].
    bias : float
        The bias b0 removed [the rate's unit].
    time_unit_s : float
        Seconds in the rate's time unit (3600 for [°/h] → θ in [°]; 1 for [°/s]).

    Returns
    -------
    numpy.ndarray
        θ_k [angle unit], θ_0 = 0; held across a gap
        (:func:`thermocal.recording.find_gaps`).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Lengths that differ.

    Notes
    -----
    Cumulative trapezoid rule with :math:`e_k = \omega_k - b_0`:

    .. math:: \theta_k = \theta_{k-1} + \tfrac12 (e_k + e_{k-1})
              \frac{t_k - t_{k-1}}{\text{time\_unit\_s}}

    Examples
    --------
    >>> drift_angle([0.0, 3600.0, 7200.0], [2.0, 2.0, 4.0], 1.0).tolist()
    [0.0, 1.0, 3.0]
    """
    t = _as_1d(time_s, "time")
    e = _as_1d(rate, "rate") - float(bias)
    if t.shape != e.shape:
        raise ThermocalInputError(f"time has {t.size} samples but the rate has {e.size}")
    inc = 0.5 * (e[1:] + e[:-1]) * np.diff(t) / float(time_unit_s)
    for sl in contiguous_slices(t)[:-1]:
        inc[sl.stop - 1] = 0.0
    out = np.zeros(t.size)
    np.cumsum(inc, out=out[1:])
    return out


def drift_angle_extreme(
    time_s: npt.ArrayLike,
    rate: npt.ArrayLike,
    bias: float,
    *,
    time_unit_s: float = units.SECONDS_PER_HOUR,
    unit: str = "deg",
    block: int = 1 << 18,
) -> DriftExtreme:
    """End value and largest magnitude of :func:`drift_angle` (the same trapezoids,
    nothing integrated across a gap), block by block without the full-length curve.

    ``max_abs = max_k |θ_k|`` at ``max_time_s = t_k − t_0`` (the first such sample).

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    rate : array_like
        Rate samples [unit/time unit].
    bias : float
        Constant b0 removed [unit/time unit].
    time_unit_s : float, optional
        Seconds per time unit of the rate (default 3600: a rate per hour).
    unit : str, optional
        Angle unit (default ``"deg"``).
    block : int, optional
        Samples per block (default 2**18).

    Returns
    -------
    DriftExtreme
        End value and largest magnitude of the drift angle [unit] and its time [s].
    """
    t = _as_1d(time_s, "time")
    r = _as_1d(rate, "rate")
    if t.shape != r.shape:
        raise ThermocalInputError(f"time has {t.size} samples but the rate has {r.size}")
    b0 = float(bias)
    theta = 0.0
    best, best_i = 0.0, 0
    for sl in contiguous_slices(t):
        for a in range(sl.start, sl.stop - 1, block):
            b = min(sl.stop - 1, a + block)  # trapezoids a…b−1 join samples a…b
            e = r[a : b + 1] - b0
            cum = theta + np.cumsum(0.5 * (e[1:] + e[:-1]) * np.diff(t[a : b + 1])) / float(
                time_unit_s
            )
            k = int(np.argmax(np.abs(cum)))
            if abs(float(cum[k])) > best:
                best, best_i = abs(float(cum[k])), a + 1 + k
            theta = float(cum[-1])
    return DriftExtreme(end=theta, max_abs=best, max_time_s=float(t[best_i] - t[0]), unit=unit)


def drift_angle_total(
    time_s: npt.ArrayLike, rate_deg_h: npt.ArrayLike, bias_deg_h: float, block: int = 1 << 18
) -> float:
    r"""The end value θ(t_end) of :func:`drift_angle` [°] for a rate in [°/h], summed block
    by block (the same trapezoids, nothing integrated across a gap) without the curve.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    rate_deg_h : array_like
        Rate [°/h].
    bias_deg_h : float
        Constant b0 removed [°/h].
    block : int, optional
        Samples per block (default 2**18).

    Returns
    -------
    float
        Drift angle at the end θ(t_end) [°].

    Notes
    -----
    .. math:: \theta(t) = \int_{t_0}^{t} (\omega - b_0)\, dt
    """
    return drift_angle_extreme(time_s, rate_deg_h, bias_deg_h, block=block).end


def reference_bias(
    time_s: npt.ArrayLike,
    rate: npt.ArrayLike,
    *,
    window_s: tuple[float, float] | None = None,
    earth_rate: float = 0.0,
    unit: str = "deg/h",
) -> DriftReference:
    """The drift angle's constant b0: the mean of ``ω − Ω_axis`` over a reference window.

    ``window_s`` = (start, end) [s since the first sample]; default the first
    :data:`DEFAULT_DRIFT_REFERENCE_FRACTION` of the run's duration.  ``earth_rate`` Ω_axis
    and ``rate`` in ``unit``.  A window holding no sample is a
    :class:`~thermocal.errors.ThermocalInputError`.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    rate : array_like
        Rate samples [``unit``].
    window_s : tuple of float, optional
        Reference window (start, end) [s since the first sample].
    earth_rate : float, optional
        Earth-rate component Ω_axis [``unit``] (default 0).
    unit : str, optional
        Rate unit (default ``"deg/h"``).

    Returns
    -------
    DriftReference
        The constant b0 [``unit``] and its window.

    Raises
    ------
    ThermocalInputError
        When the window is not 0 ≤ start < end or holds no sample (the message names the
        window as :func:`compute_metrics` does, ``drift_reference_s``).
    """
    t = _as_1d(time_s, "time")
    r = _as_1d(rate, "rate")
    t0 = t[0]
    duration = float(t[-1] - t0)
    start, end = drift_reference_window(window_s, duration)
    if is_increasing(t):  # the window is one stretch: found by bisection, no copy
        # t_i − t_0 is non-decreasing in i (rounding is monotone): the rows with
        # start ≤ t_i − t_0 ≤ end are i0 … i1 − 1
        i0 = bisect.bisect_left(range(t.size), True, key=lambda i: bool(t[i] - t0 >= start))
        i1 = bisect.bisect_left(range(t.size), True, key=lambda i: bool(t[i] - t0 > end))
        n = max(i1 - i0, 0)
        selected = r[i0:i1]
    else:
        rel = t - t0
        sel = (rel >= start) & (rel <= end)
        n = int(np.count_nonzero(sel))
        selected = r[sel]
    if n == 0:
        raise empty_reference_window(start, end, duration)
    b0 = float(np.mean(selected)) - float(earth_rate)
    return DriftReference("window", start, end, b0, unit, n)


def drift_reference_window(
    window_s: tuple[float, float] | None, duration_s: float
) -> tuple[float, float]:
    """The drift angle's reference window, checked: the one given, else the first
    :data:`DEFAULT_DRIFT_REFERENCE_FRACTION` of the run (shared by the in-memory and the
    window-by-window metrics).

    Parameters
    ----------
    window_s : tuple of float or None
        The window (start, end) given [s since the first sample], or None.
    duration_s : float
        The run's last minus first time [s].

    Returns
    -------
    tuple of float
        (start, end) [s since the first sample].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A window that is not finite with 0 ≤ start < end (naming ``drift_reference_s``).

    Examples
    --------
    >>> drift_reference_window(None, 3600.0)
    (0.0, 360.0)
    """
    if window_s is None:
        return 0.0, DEFAULT_DRIFT_REFERENCE_FRACTION * duration_s
    start, end = float(window_s[0]), float(window_s[1])
    if not (math.isfinite(start) and math.isfinite(end) and end > start >= 0.0):
        raise ThermocalInputError.naming(
            f"{{drift_reference_s}} {start:g},{end:g}: give START,END in seconds since "
            "the first sample, with 0 ≤ START < END",
            "drift_reference_s",
        )
    return start, end


def empty_reference_window(start: float, end: float, duration_s: float) -> ThermocalInputError:
    """The error for a drift reference window that holds no sample.

    Parameters
    ----------
    start, end : float
        The window [s since the first sample].
    duration_s : float
        The run's last minus first time [s].

    Returns
    -------
    thermocal.errors.ThermocalInputError
        The error to raise (naming ``drift_reference_s``).
    """
    return ThermocalInputError.naming(
        f"drift reference window {start:g}…{end:g} s holds no sample (the run lasts "
        f"{duration_s:g} s from its first sample); choose another {{drift_reference_s}}",
        "drift_reference_s",
    )


def drift_options(
    name: str,
    unit: str,
    drift_reference_s: tuple[float, float] | None,
    drift_bias: float | None,
) -> tuple[str, float, DriftReference | None] | None:
    r"""What the drift angle of one channel takes, its options checked (shared by the
    in-memory and the window-by-window metrics): None for a signal that is not a gyro
    rate (where the drift options are an error), else the angle's unit, the rate unit's
    time [s] and the given bias b0 (None: b0 is the mean over the reference window).

    Parameters
    ----------
    name : str
        The channel, named in errors.
    unit : str
        Its data unit.
    drift_reference_s : tuple of float or None
        The reference window given [s since the first sample].
    drift_bias : float or None
        b0 given [``unit``, earth rate removed].

    Returns
    -------
    tuple or None
        ``(angle_unit, per_s, reference)``: θ in ``angle_unit`` is
        :math:`\int (\omega - \Omega - b_0)\,dt / \mathrm{per\_s}`; ``reference`` the
        :class:`DriftReference` of a given b0, else None.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Drift options for a signal that is not a rate, both options given, or a bias that
        is not a number.

    Examples
    --------
    >>> drift_options("gz", "deg/h", None, 0.5)[2].bias
    0.5
    """
    if unit not in RATE_ANGLE_UNITS:
        if drift_bias is not None or drift_reference_s is not None:
            raise ThermocalInputError.naming(
                f"the drift angle applies to gyro rates, but {name!r} is in {unit}: "
                "{drift_reference_s}/{drift_bias} do not apply",
                "drift_reference_s",
                "drift_bias",
            )
        return None
    angle_unit, per = RATE_ANGLE_UNITS[unit]
    if drift_bias is None:
        return angle_unit, per, None
    if drift_reference_s is not None:
        raise ThermocalInputError.naming(
            "give either {drift_reference_s} or {drift_bias}, not both",
            "drift_reference_s",
            "drift_bias",
        )
    if not math.isfinite(drift_bias):
        raise ParameterError("drift_bias", f"{{name}} must be a number, got {drift_bias!r}")
    return angle_unit, per, DriftReference("bias", None, None, float(drift_bias), unit)


# --- recording pipeline ------------------------------------------------------------------


def hold_stages(
    time_s: FloatArray,
    temp_c: FloatArray,
    values: FloatArray,
    *,
    rate_threshold_c_per_min: float = 0.05,
    min_duration_s: float = 600.0,
) -> tuple[Stage, ...]:
    """Temperature-hold stages (:func:`thermocal.preprocess.segment_holds`) with the
    mean temperature and mean signal of each.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    temp_c : numpy.ndarray
        Temperatures [°C].
    values : numpy.ndarray
        Signal samples [unit].
    rate_threshold_c_per_min : float, optional
        Largest temperature rate of a hold [°C/min] (default 0.05).
    min_duration_s : float, optional
        Shortest hold [s] (default 600).

    Returns
    -------
    tuple of Stage
        One stage per hold.
    """
    from thermocal.preprocess import segment_holds

    segs = segment_holds(
        time_s,
        temp_c,
        rate_threshold_c_per_min=rate_threshold_c_per_min,
        min_duration_s=min_duration_s,
    )
    return tuple(
        Stage(
            start_s=float(s.start_s),
            stop_s=float(s.stop_s),
            mean_temp_c=float(np.mean(temp_c[s.start : s.stop])),
            bias=float(np.mean(values[s.start : s.stop])),
            n_samples=int(s.stop - s.start),
        )
        for s in segs
        if s.kind == "hold" and s.stop > s.start
    )


def earth_rate_to_remove(
    rec: Recording,
    name: str,
    canon: str,
    unit: str,
    k: float,
    latitude_deg: float | None,
    axis: str | None,
) -> float:
    r"""The earth rate on the sensitive axis [data unit] to remove: 0 unless a latitude or
    an axis is given (options, else the recording's metadata); both are then needed, and
    the signal must be a gyro rate.

    Parameters
    ----------
    rec : Recording
        The recording (its metadata's latitude and axis when none is given).
    name : str
        The signal, named in errors.
    canon : str
        Its canonical unit (``deg/h`` for a gyro rate).
    unit : str
        Its data unit.
    k : float
        Canonical per data unit (:func:`data_unit_of`).
    latitude_deg : float or None
        Site latitude [°].
    axis : str or None
        Sensitive axis (``up``, ``north``, … or ``'e,n,u'``).

    Returns
    -------
    float
        Ω_axis [``unit``].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Only one of latitude and axis, a signal that is not a rate, or a latitude beyond ±90°.

    Notes
    -----
    .. math:: \Omega_\mathrm{axis} = \Omega\,\mathbf u \cdot (0, \cos\varphi, \sin\varphi) / k

    (:func:`thermocal.units.earth_rate_on_axis_deg_h`, east-north-up axes).

    References
    ----------
    - IEEE Std 952-1997, earth rate as an input of a stationary gyro.
    """
    lat = latitude_deg if latitude_deg is not None else rec.meta.latitude_deg
    ax = axis if axis is not None else rec.meta.axis
    if lat is None and axis is None:
        return 0.0
    if lat is None or ax is None:
        raise ThermocalInputError.naming(
            "earth-rate removal needs both {latitude_deg} and {axis}", "latitude_deg", "axis"
        )
    if canon != "deg/h":
        raise ThermocalInputError(
            f"earth-rate removal applies to gyro rates, but {name!r} is in {unit}"
        )
    if not -90.0 <= lat <= 90.0:
        raise ThermocalInputError(f"latitude must be within ±90°, got {lat}")
    return units.earth_rate_on_axis_deg_h(lat, units.parse_axis(ax)) / k  # [unit]


def _drift(
    t: FloatArray,
    values: FloatArray,
    name: str,
    unit: str,
    earth: float,
    drift_reference_s: tuple[float, float] | None,
    drift_bias: float | None,
) -> tuple[DriftReference, DriftExtreme] | None:
    """The drift angle's reference bias b0 and ``θ(t) = ∫ (ω − Ω_axis − b0) dt`` at the
    end and at its largest (gyro rates only; None otherwise, where the drift options are
    an error)."""
    plan = drift_options(name, unit, drift_reference_s, drift_bias)
    if plan is None:
        return None
    angle_unit, per, ref = plan
    if ref is None:
        ref = reference_bias(t, values, window_s=drift_reference_s, earth_rate=earth, unit=unit)
    ext = drift_angle_extreme(t, values, ref.bias + earth, time_unit_s=per, unit=angle_unit)
    return ref, ext


def _stage_figures(
    t: FloatArray,
    temp: FloatArray | None,
    values: FloatArray,
    unit: str,
    earth: float,
    rate_threshold_c_per_min: float,
    min_hold_s: float,
) -> tuple[tuple[Stage, ...], float | None, TemperatureSensitivity | None]:
    """The hold stages of the temperature ``temp`` [°C] (none without one), the bias
    repeatability over them (two or more) and the temperature sensitivity over the
    stages pooled by set-point (within 0.5 °C; two or more set-points)."""
    if temp is None:
        return (), None, None
    stages = hold_stages(
        t,
        temp,
        values,
        rate_threshold_c_per_min=rate_threshold_c_per_min,
        min_duration_s=min_hold_s,
    )
    if earth:  # mean(ω − Ω) = mean(ω) − Ω, without a full-length copy
        stages = tuple(dataclasses.replace(s, bias=s.bias - earth) for s in stages)
    if len(stages) < 2:
        return stages, None, None
    rep = bias_repeatability([s.bias for s in stages])
    st_temps = np.array([s.mean_temp_c for s in stages])
    st_bias = np.array([s.bias for s in stages])
    # hold stages at the same set-point (within 0.5 °C) are pooled
    key = np.round(st_temps * 2.0) / 2.0
    uniq = np.unique(key)
    if uniq.size < 2:
        return stages, rep, None
    pt = np.array([st_temps[key == k].mean() for k in uniq])
    pb = np.array([st_bias[key == k].mean() for k in uniq])
    return stages, rep, temperature_sensitivity(pt, pb, unit=unit)


def compute_metrics(
    rec: Recording,
    signal: str | None = None,
    averaging_s: float | None = None,
    latitude_deg: float | None = None,
    axis: str | None = None,
    temps: list[str] | tuple[str, ...] | None = None,
    *,
    rate_threshold_c_per_min: float = 0.05,
    min_hold_s: float = 600.0,
    drift_reference_s: tuple[float, float] | None = None,
    drift_bias: float | None = None,
) -> MetricsResult:
    """All figures of merit of one signal of a recording, in the data's own unit
    (:func:`data_unit_of`).

    Parameters
    ----------
    rec : the recording.
    signal : column name (default: the first signal).
    averaging_s : averaging time of bias stability and peak-to-peak [s]
        (default: the sample interval, i.e. no averaging).
    latitude_deg, axis : remove the earth-rate component on the sensitive axis
        (gyros only); default from the recording's metadata.
    temps : temperature columns; the first one defines hold stages
        (|Ṫ| < ``rate_threshold_c_per_min`` for at least ``min_hold_s``) for
        bias repeatability and temperature sensitivity over the stages.
    drift_reference_s : the drift angle's reference window (start, end) [s since the
        first sample]; b0 is the mean of ω − Ω_axis over it (:func:`reference_bias`;
        default the first 10 % of the run).
    drift_bias : b0 given instead [data unit, earth rate already removed].

    The drift angle ``θ(t) = ∫ (ω − Ω_axis − b0) dt`` (gyros only) is never taken about
    the same run's mean (that makes θ(t_end) ≈ 0 by construction): b0 is the stated
    constant of ``drift_reference``.
    """
    name = signal or (rec.signals[0] if rec.signals else "")
    canon_values, canon = rec.signal(signal)
    shown, k = data_unit_of(rec, name, canon)
    canon_values = _as_1d(canon_values, f"column {name!r}")
    values = canon_values if k == 1.0 else canon_values / k  # [shown unit]
    unit = shown
    t = rec.time_s
    tau0 = rec.sample_interval_s
    avg = float(averaging_s) if averaging_s is not None else tau0
    earth = earth_rate_to_remove(rec, name, canon, unit, k, latitude_deg, axis)
    b0 = bias(values, earth_rate_deg_h=earth)
    means = block_means(values, tau0, avg, time_s=t)
    if means.size < 2:
        raise _too_few_averages_error(
            rec.source or rec.name, avg, means.size, _longest_stretch_s(t, tau0, values.size)
        )
    stab = float(np.std(means, ddof=1))
    p2p = float(np.max(means) - np.min(means))
    drift = _drift(t, values, name, unit, earth, drift_reference_s, drift_bias)
    ref, ext = drift if drift is not None else (None, None)
    temp_names = list(temps) if temps else list(rec.temperatures)
    stages, rep, sens = _stage_figures(
        t,
        rec.temperature_c(temp_names[0]) if temp_names else None,
        values,
        unit,
        earth,
        rate_threshold_c_per_min,
        min_hold_s,
    )
    return MetricsResult(
        bias=b0,
        bias_stability=stab,
        averaging_s=float(_samples_per_average(tau0, avg) * tau0),
        peak_to_peak=p2p,
        unit=unit,
        temperature_sensitivity=sens,
        bias_repeatability=rep,
        stages=stages,
        drift_angle=ext.end if ext is not None else None,
        drift_angle_unit=RATE_ANGLE_UNITS[unit][0] if ext is not None else None,
        drift_angle_max=ext.max_abs if ext is not None else None,
        drift_angle_max_time_s=ext.max_time_s if ext is not None else None,
        drift_reference=ref,
        earth_rate_removed=earth,
        n_samples=int(values.size),
        n_segments=len(contiguous_slices(t)),
        n_averages=int(means.size),
        duration_s=rec.duration_s,
        signal=name,
    )


@dataclass(frozen=True)
class MetricsOptions:
    """The options of :func:`compute_metrics` shared by every channel and run (``metrics``'
    command line): averaging time [s], earth-rate removal (latitude [°], axis), temperature
    columns, hold-stage detection (|Ṫ| [°C/min], shortest hold [s]) and the drift angle's
    reference window [s] or bias [data unit].

    Attributes
    ----------
    averaging_s : float or None
        Averaging time [s] (None: the default for the record).
    latitude_deg : float or None
        Site latitude [°] (earth-rate removal, with ``axis``).
    axis : str or None
        Sensitive axis (``up``, ``north``, … or ``'e,n,u'``).
    temps : tuple of str or None
        Temperature columns (None: those of the file).
    rate_threshold_c_per_min : float
        |Ṫ| below which a hold stage is found [°C/min].
    min_hold_s : float
        Shortest hold stage [s].
    drift_reference_s : (float, float) or None
        Window [s since the first sample] whose mean is the drift angle's bias b0.
    drift_bias : float or None
        The drift angle's bias b0 given directly [data unit].
    """

    averaging_s: float | None = None
    latitude_deg: float | None = None
    axis: str | None = None
    temps: tuple[str, ...] | None = None
    rate_threshold_c_per_min: float = 0.05
    min_hold_s: float = 600.0
    drift_reference_s: tuple[float, float] | None = None
    drift_bias: float | None = None

    @property
    def removes_earth_rate(self) -> bool:
        """A latitude or an axis is given (earth-rate removal, one signal at a time)."""
        return self.latitude_deg is not None or self.axis is not None

    def of(self, rec: Recording, name: str) -> MetricsResult:
        """:func:`compute_metrics` of the signal ``name`` of ``rec`` with these options.

        Parameters
        ----------
        rec : Recording
            The recording.
        name : str
            Signal name.

        Returns
        -------
        MetricsResult
            The signal's figures of merit.
        """
        return compute_metrics(
            rec,
            name,
            self.averaging_s,
            self.latitude_deg,
            self.axis,
            list(self.temps) if self.temps else None,
            rate_threshold_c_per_min=self.rate_threshold_c_per_min,
            min_hold_s=self.min_hold_s,
            drift_reference_s=self.drift_reference_s,
            drift_bias=self.drift_bias,
        )


def keep_stage_temperature(rec: Recording, temps: Sequence[str] | None) -> None:
    """Keep the temperature that defines the hold stages (the first of ``temps``, else of
    the recording's) in the recording's columns once read.

    A recording read on demand (``metrics``: each column read when used, the last one
    kept) would otherwise read it twice: once for its checks and once more for the
    figures, which need it beside the signal read after it.  Kept, it is read once, and
    every column of the recording once; the memory is that of the figures, which hold it
    with the signal anyway.  A recording held in memory is unchanged.

    Parameters
    ----------
    rec : Recording
        The recording (its ``columns`` are reassigned the column's own values).
    temps : sequence of str or None
        The temperature columns asked for (the first defines the stages).
    """
    names = list(temps) if temps else list(rec.temperatures)
    if names and names[0] in rec.columns:
        rec.columns[names[0]] = rec.columns[names[0]]


def channel_metrics(
    rec: Recording, names: list[str], options: MetricsOptions
) -> dict[str, MetricsResult]:
    """The figures of every channel ``names`` of one recording (one read of the file,
    several channels).  Earth-rate removal takes one channel: each channel's
    sensitive axis points elsewhere.

    Parameters
    ----------
    rec : Recording
        The recording.
    names : list of str
        Signal names.
    options : MetricsOptions
        How the figures are computed.

    Returns
    -------
    dict of str to MetricsResult
        Figures per channel.
    """
    if len(names) > 1 and options.removes_earth_rate:
        raise ThermocalInputError.naming(
            "earth-rate removal ({latitude_deg}/{axis}) takes one signal at a time: each "
            "channel's sensitive axis points elsewhere; run metrics per gyro axis with its "
            "{axis}",
            "latitude_deg",
            "axis",
        )
    return {name: options.of(rec, name) for name in names}


@dataclass(frozen=True, eq=False)
class PowerOnMetrics:
    """The result of :func:`power_on_metrics`: the channels, each run's figures per channel
    (in the order of the runs) and the turn-on to turn-on repeatability per channel.

    Attributes
    ----------
    names : tuple of str
        The channels.
    runs : tuple of dict of str to MetricsResult
        Each run's figures per channel, in the order of the runs.
    repeatability : dict of str to RunRepeatability
        Turn-on to turn-on repeatability per channel.
    """

    names: tuple[str, ...]
    runs: tuple[dict[str, MetricsResult], ...]
    repeatability: dict[str, RunRepeatability]


SENSOR_ID_KEYS: Final = ("sensor_id", "serial", "serial_number", "device_id")
"""Metadata keys that name one physical sensor (:class:`~thermocal.recording.Metadata`'s
``sensor_id``, or the same in its ``extra`` pairs): runs that state different values are
different sensors."""


def _distinct_runs(labels: list[str]) -> None:
    """A run named twice would count twice (its bias twice in the repeatability)."""
    for i, lab in enumerate(labels):
        if lab in labels[:i]:
            raise ThermocalInputError(
                f"{lab}: given twice; each power-on counts once in the turn-on to turn-on "
                "repeatability (give every run's file once)"
            )


def sensor_identity(rec: Recording) -> tuple[str, str] | None:
    """The first of :data:`SENSOR_ID_KEYS` a recording's metadata state, with its value as
    text (None when none is stated).

    Parameters
    ----------
    rec : Recording
        The recording.

    Returns
    -------
    tuple of (str, str) or None
        The metadata key and its value.
    """
    if rec.meta.sensor_id not in (None, ""):
        return "sensor_id", str(rec.meta.sensor_id)
    for key in SENSOR_ID_KEYS:
        v = rec.meta.extra.get(key)
        if v not in (None, ""):
            return key, str(v)
    return None


def _same_sensor(rec: Recording, label: str, sensors: dict[str, str]) -> None:
    """Refuse runs whose metadata name different sensors (``sensors``: value → first run;
    a run that names none is kept under ``""``)."""
    ident = sensor_identity(rec)
    if ident is None:
        sensors.setdefault("", label)
        return
    key, value = ident
    named = {v: f for v, f in sensors.items() if v}
    if named and value not in named:
        first_value, first = next(iter(named.items()))
        raise ThermocalInputError(
            f"{label}: {key} {value!r} is not the sensor of {first} ({first_value!r}): a "
            "turn-on to turn-on repeatability pools power-ons of ONE sensor; give each "
            "sensor's runs in their own metrics command"
        )
    sensors.setdefault(value, label)


def _not_a_copy(
    rec: Recording, names: list[str], label: str, seen: dict[str, tuple[str, str]]
) -> None:
    """Refuse a run whose samples of a channel equal another run's, bit for bit: two
    power-ons of a noisy sensor never give the same record, a copied file does (its bias
    repeats exactly and the repeatability is rounding error, e.g. 6.8e-17 °/h)."""
    for n in names:
        values = np.ascontiguousarray(rec.columns[n], dtype=np.float64)
        digest = hashlib.sha256(values.tobytes()).hexdigest()
        key = f"{n}:{digest}"
        if key in seen:
            raise ThermocalInputError(
                f"{label}: its {values.size} samples of {n} are those of {seen[key][0]}, bit "
                "for bit (a copy of one run, not another power-on); give each power-on's "
                "own file once"
            )
        seen[key] = (label, n)


def power_on_metrics(
    runs: Sequence[_Run],
    read: Callable[[_Run], Recording],
    signals: list[str] | None,
    options: MetricsOptions,
) -> PowerOnMetrics:
    """Several power-ons of one sensor: ``read(run)`` gives each run's recording (read in
    turn, so the first bad file stops the analysis), the figures of the channels
    ``signals`` (default each file's first signal; every run the same channels), and per
    channel :func:`run_repeatability` over the runs, labelled ``str(run)``.

    Refused (:class:`ThermocalInputError`, naming the files): a run named twice, a run
    whose samples of a channel equal another run's bit for bit (a copy), runs whose
    metadata name different sensors (:data:`SENSOR_ID_KEYS`): each would give a
    repeatability of one sensor that the data cannot support.

    Parameters
    ----------
    runs : sequence
        The runs (files).
    read : callable
        ``read(run)`` → Recording.
    signals : list of str or None
        Channels (default each file's first signal).
    options : MetricsOptions
        How the figures are computed.

    Returns
    -------
    PowerOnMetrics
        Figures per run and repeatability per channel.

    Raises
    ------
    ThermocalInputError
        A run named twice, a copied run, or runs of different sensors.
    """
    per_run: list[dict[str, MetricsResult]] = []
    names: list[str] | None = None
    _distinct_runs([str(r) for r in runs])
    seen: dict[str, tuple[str, str]] = {}
    sensors: dict[str, str] = {}
    for run in runs:
        rec = read(run)
        these = signals or [rec.signals[0]]
        if names is None:
            names = these
        elif these != names:
            raise ThermocalInputError(f"{run}: signals {these} differ from the first run's {names}")
        if len(these) > 1 and options.removes_earth_rate:
            raise ThermocalInputError.naming(
                "earth-rate removal ({latitude_deg}/{axis}) takes one signal at a time",
                "latitude_deg",
                "axis",
            )
        _same_sensor(rec, str(run), sensors)
        _not_a_copy(rec, these, str(run), seen)
        per_run.append({n: options.of(rec, n) for n in these})
    if names is None:
        raise ThermocalInputError("no run to analyse")
    if "" in sensors and len(sensors) > 1:
        value, first = next((v, f) for v, f in sensors.items() if v)
        warnings.warn(
            f"{sensors['']}: its metadata names no sensor; taken for the sensor of {first} "
            f"({value!r}) in the repeatability (give only one sensor's power-ons)",
            PlausibilityWarning,
            stacklevel=2,
        )
    labels = [str(r) for r in runs]
    reps = {n: run_repeatability([r[n] for r in per_run], labels) for n in names}
    return PowerOnMetrics(tuple(names), tuple(per_run), reps)


__all__ = [
    "SENSOR_ID_KEYS",
    "DriftExtreme",
    "DriftReference",
    "MetricsOptions",
    "MetricsResult",
    "PowerOnMetrics",
    "RunRepeatability",
    "Stage",
    "TemperatureSensitivity",
    "bias",
    "bias_from_counts",
    "bias_repeatability",
    "bias_stability",
    "block_means",
    "channel_metrics",
    "compute_metrics",
    "data_unit_of",
    "drift_angle",
    "drift_angle_extreme",
    "drift_options",
    "drift_reference_window",
    "earth_rate_to_remove",
    "empty_reference_window",
    "hold_stages",
    "keep_stage_temperature",
    "peak_to_peak",
    "power_on_metrics",
    "reference_bias",
    "run_repeatability",
    "sensor_identity",
    "std_interval",
    "temperature_sensitivity",
    "too_few_averages",
]
