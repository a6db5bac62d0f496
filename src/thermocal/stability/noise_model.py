"""The noise model of an IMU for estimators (Kalibr's ``imu.yaml``), from Allan analysis.

Pure maths and text: no file I/O.  The noise terms are those of
:func:`thermocal.stability.allan.noise_terms` (IEEE 952 slope lines, least-squares fit); this module
only chooses, converts and states them.

Continuous-time model of one axis (Kalibr's IMU noise model, J. Rehder et al., *Extending
kalibr*, ICRA 2016; the Kalibr wiki "IMU Noise Model")::

    ω̃(t) = ω(t) + b(t) + n(t),   E[n(t) n(t')] = σ_n² δ(t − t'),   ḃ(t) = σ_b w(t)

* ``σ_n`` noise density [rad/s/√Hz] (gyro) or [m/s²/√Hz] (accelerometer) is the white-noise
  coefficient N of the Allan variance ``σ²(τ) = N²/τ``: the −½ slope line read at τ = 1 s
  (IEEE 952-1997 C.3; N in (rad/s)·√s = rad/s/√Hz), fitted on the −½ stretch found in the
  data (:func:`thermocal.stability.allan.white_stretch`), not at the shortest τ a sensor's
  own filter shapes.
* ``σ_b`` random walk [rad/s²/√Hz] or [m/s³/√Hz] is the rate random walk coefficient K of
  ``σ²(τ) = K² τ / 3``: the +½ slope line read at τ = 3 s (K in (rad/s)/√s = rad/s²/√Hz).

The density is taken from the slope line where the curve has that slope, else from the
weighted least-squares fit (IEEE 952 C.2); the random walk from the fit when the noise model
fits the curve well (the +½ stretch of a real record still holds white noise at its short
end, which biases the line up), else from the slope line; else (only the random walk,
which a short record may not reach) as the upper bound the curve allows,
``K ≤ min_τ σ_high(τ) √(3/τ)`` (every term lies below the curve), flagged ``poor``.
Kalibr wants one number per sensor: the largest over the axes.

Discrete time at sample interval Δt (Kalibr wiki): white noise ``σ_d = σ_c / √Δt``;
random walk ``σ_d = σ_c · √Δt``.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, Final, Literal

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import ParameterError, PlausibilityWarning, ThermocalInputError
from thermocal.identifiers import one_line
from thermocal.stability.allan import (
    AllanResult,
    NoiseTerm,
    NoiseTerms,
    annotate_periodic,
    noise_terms,
    overlapping_adev,
    term_units,
)
from thermocal.stability.periodic import periodic_terms

Sensor = Literal["gyro", "accel"]

SI_UNIT: Final[dict[str, str]] = {"gyro": "rad/s", "accel": "m/s^2"}
"""The SI unit each sensor's data are converted to for Kalibr."""

KALIBR_KEYS: Final = (
    "accelerometer_noise_density",
    "accelerometer_random_walk",
    "gyroscope_noise_density",
    "gyroscope_random_walk",
    "update_rate",
    "rostopic",
)
"""The keys of Kalibr's ``imu.yaml``."""

_DENSITY_UNIT: Final = {"gyro": "rad/s/sqrt(Hz)", "accel": "m/s^2/sqrt(Hz)"}
_WALK_UNIT: Final = {"gyro": "rad/s^2/sqrt(Hz)", "accel": "m/s^3/sqrt(Hz)"}
_TERM_OF: Final = {"density": "angle_random_walk", "walk": "rate_random_walk"}
_TERM_WORDS: Final = {
    ("gyro", "density"): "angle random walk N (white rate noise)",
    ("gyro", "walk"): "rate random walk K",
    ("accel", "density"): "velocity random walk N (white acceleration noise)",
    ("accel", "walk"): "acceleration random walk K",
}


def term_words(sensor: str, kind: str) -> str:
    """The term in words for a ``sensor`` (gyro, accel) and ``kind`` (density, walk): an
    accelerometer's white noise is the velocity random walk, not the angle random walk.

    Parameters
    ----------
    sensor : str
        ``"gyro"`` or ``"accel"``.
    kind : str
        ``"density"`` or ``"walk"``.

    Returns
    -------
    str
        The term in words.
    """
    return _TERM_WORDS[(sensor, kind)]


_READ_AT: Final = {"density": 1.0, "walk": 3.0}
_SLOPE: Final = {"density": "−½", "walk": "+½"}


@dataclass(frozen=True)
class ContinuousTerm:
    """One continuous-time coefficient of one axis in SI units.

    ``value``/``low``/``high`` [``unit``]; ``method`` ``slope`` (the IEEE 952 slope line),
    ``fit`` (weighted least squares) or ``bound`` (upper bound from the curve: the record
    does not show the term); ``tau_s`` where the slope line touches the curve (slope), the
    τ of the bounding point (bound), None (fit); ``read_at_tau_s`` where the line is read
    (1 s for white noise, 3 s for random walk); ``quality`` ``good|rough|poor``.

    Attributes
    ----------
    value, low, high : float or None
        The coefficient and its interval [``unit``].
    unit : str
        Its SI unit.
    term : str
        Which coefficient.
    method : str
        ``slope``, ``fit`` or ``bound``.
    tau_s : float or None
        Where the line touches the curve or the bounding point [s].
    read_at_tau_s : float
        Where the line is read [s].
    quality : str
        ``good``, ``rough`` or ``poor``.
    reason : str or None
        Why rough or poor.
    tau_range_s : (float, float) or None
        The τ range the slope line was fitted on [s].
    """

    value: float
    low: float | None
    high: float | None
    unit: str
    term: str
    method: str
    tau_s: float | None
    read_at_tau_s: float
    quality: str
    reason: str | None
    tau_range_s: tuple[float, float] | None = None
    """The τ range [s] the slope line was fitted on (the −½ stretch found in the data)."""


@dataclass(frozen=True, eq=False)
class AxisNoise:
    """The Allan analysis of one axis and its two Kalibr coefficients.

    ``unit`` the data's own unit (of ``allan`` and ``terms``); ``density`` the white-noise
    density, ``walk`` the random-walk strength, both in SI (:data:`SI_UNIT` per √Hz);
    ``quantization`` the output quantisation found in the samples (None: not quantised;
    a rate quantisation's white noise is part of ``density``).

    Attributes
    ----------
    name : str
        The axis (column).
    sensor : {"gyro", "accel"}
        Gyroscope or accelerometer.
    unit : str
        The data's own unit.
    allan : AllanResult
        Its Allan deviation.
    terms : NoiseTerms
        Its noise terms.
    density : ContinuousTerm
        White-noise density [SI unit/√Hz].
    walk : ContinuousTerm
        Random-walk strength [SI unit·√Hz].
    quantization : OutputQuantization or None
        The output quantisation found (None: not quantised).
    """

    name: str
    sensor: Sensor
    unit: str
    allan: AllanResult
    terms: NoiseTerms
    density: ContinuousTerm
    walk: ContinuousTerm
    quantization: OutputQuantization | None = None


@dataclass(frozen=True, eq=False)
class NoiseModel:
    """The IMU noise model: every axis, and per sensor the largest axis (Kalibr).

    ``update_rate_hz`` 1/τ0; ``inflate`` the factor every Kalibr value is multiplied by
    (1: none); ``chosen`` maps a Kalibr key to the axis it came from.

    Attributes
    ----------
    axes : tuple of AxisNoise
        Every axis.
    update_rate_hz : float
        1/τ0 [Hz].
    inflate : float
        Factor every Kalibr value is multiplied by.
    rostopic : str
        The IMU topic written into the Kalibr file.
    confidence : float
        Confidence level of the intervals.
    chosen : dict of str to AxisNoise
        The axis each Kalibr key came from.
    """

    axes: tuple[AxisNoise, ...]
    update_rate_hz: float
    inflate: float
    rostopic: str
    confidence: float
    chosen: dict[str, AxisNoise]

    def kalibr(self) -> dict[str, float | str]:
        """Kalibr's ``imu.yaml`` values (continuous time, inflated), by key."""
        out: dict[str, float | str] = {}
        for key, ax in self.chosen.items():
            out[key] = _term_for(key, ax).value * self.inflate
        out["update_rate"] = self.update_rate_hz
        out["rostopic"] = self.rostopic
        return {k: out[k] for k in KALIBR_KEYS if k in out}

    def to_dict(self, source: str) -> dict[str, Any]:
        """The noise model as plain Python values: the file the ``noise`` command writes as
        JSON (NaN where it writes null).

        Parameters
        ----------
        source : str
            The recording's name, stated in the file.

        Returns
        -------
        dict
            ``kalibr`` (the values and the axis each came from: ``kalibr_axis``), and per
            axis ``terms`` (every IEEE 952 term in the data's unit: the slope reading where
            it exists, else the fit; ``value``, ``unit``, ``low``, ``high``, ``tau_s``,
            ``method``, ``quality``, ``reason``), ``terms_fit`` (all fitted terms),
            ``noise_density`` and ``random_walk`` (continuous time, SI; ``tau_range_s`` the
            stretch a slope line was fitted on), ``bias_instability_minimum`` (the bias
            instability at the curve's minimum, always, with ``tau_s``, interval and
            ``quality``), ``output_quantization`` (:meth:`OutputQuantization.to_dict`, None
            when the samples lie on no lattice).

        References
        ----------
        IEEE Std 952-1997, annex C (the terms); Kalibr's ``imu.yaml`` (continuous-time
        noise densities and random walks).
        """
        axes: dict[str, Any] = {}
        for ax in self.axes:
            slope, fit = ax.terms.slope.terms(), ax.terms.fit.terms()
            axes[ax.name] = {
                "sensor": ax.sensor,
                "unit": ax.unit,
                "terms": {k: _best(slope[k], fit[k]) for k in slope},
                "terms_fit": {k: _term_json(fit[k], "fit") for k in fit},
                "fit_quality": ax.terms.quality.to_dict() if ax.terms.quality else None,
                "output_quantization": ax.quantization.to_dict() if ax.quantization else None,
                "noise_density": _continuous_json(ax.density),
                "random_walk": _continuous_json(ax.walk),
                "bias_instability_minimum": _minimum_json(ax.terms.bias_minimum),
                "periodic": [p.to_dict() for p in ax.terms.periodic],
            }
        return {
            "source": source,
            "kalibr": self.kalibr(),
            "kalibr_axis": {k: a.name for k, a in self.chosen.items()},
            "kalibr_rule": "per sensor the largest value over its axes",
            "inflate": self.inflate,
            "update_rate_hz": self.update_rate_hz,
            "confidence": self.confidence,
            "discrete_time": "white noise σ_d = σ_c / √Δt; random walk σ_d = σ_c · √Δt",
            "axes": axes,
        }


def _term_for(key: str, ax: AxisNoise) -> ContinuousTerm:
    return ax.density if key.endswith("noise_density") else ax.walk


def _native(term: NoiseTerm, j: int, unit: str) -> tuple[float | None, float | None, float | None]:
    """A reported term back in the data unit's own coefficient (unit·s^k, τ in s)."""
    scale, specs = term_units(unit)
    conv = scale * specs[j][0]

    def back(v: float | None) -> float | None:
        return None if v is None else v / conv

    return back(term.value), back(term.low), back(term.high)


def _choose(
    kind: str, sensor: Sensor, unit: str, res: AllanResult, terms: NoiseTerms
) -> ContinuousTerm:
    """The slope-line term, else the fitted one, else (random walk) the curve's bound."""
    name = _TERM_OF[kind]
    j = ("quantization", "angle_random_walk", "bias_instability", "rate_random_walk").index(name)
    si = float(units.convert(1.0, unit, SI_UNIT[sensor]))
    out_unit = _DENSITY_UNIT[sensor] if kind == "density" else _WALK_UNIT[sensor]
    order = [("slope", terms.slope.terms()[name]), ("fit", terms.fit.terms()[name])]
    if kind == "walk" and terms.quality is not None and terms.quality.quality == "good":
        # the +½ stretch of a real record still holds some white noise at its short end,
        # which biases the line up (+4 % on simulated records); a good fit separates them
        order.reverse()
    for method, term in order:
        if term.value is None:
            continue
        v, lo, hi = _native(term, j, unit)
        assert v is not None
        return ContinuousTerm(
            value=v * si,
            low=None if lo is None else lo * si,
            high=None if hi is None else hi * si,
            unit=out_unit,
            term=name,
            method=method,
            tau_s=term.tau_s,
            read_at_tau_s=_READ_AT[kind],
            quality=term.quality or "good",
            reason=term.reason,
            tau_range_s=term.tau_range_s if method == "slope" else None,
        )
    # not in the data: the largest coefficient the curve allows (every term lies below it)
    ok = np.isfinite(res.adev_high) & (res.adev > 0)
    if not ok.any():
        raise ThermocalInputError(
            f"no Allan deviation point above zero: no {name.replace('_', ' ')} can be read"
        )
    tau, high = res.tau_s[ok], res.adev_high[ok]
    power = 0.5 if kind == "density" else -0.5  # N ≤ σ√τ, K ≤ σ√(3/τ)
    cand = high * tau**power * (1.0 if kind == "density" else math.sqrt(3.0))
    k = int(np.argmin(cand))
    why = (terms.slope.terms()[name].reason or "") + "; " + (terms.fit.terms()[name].reason or "")
    return ContinuousTerm(
        value=float(cand[k]) * si,
        low=0.0,
        high=float(cand[k]) * si,
        unit=out_unit,
        term=name,
        method="bound",
        tau_s=float(tau[k]),
        read_at_tau_s=_READ_AT[kind],
        quality="poor",
        reason=(
            f"the record does not show this term ({why.strip('; ')}); the value is the "
            f"largest the curve allows, the {_SLOPE[kind]} line through the upper bound at "
            f"τ = {tau[k]:.4g} s: a longer record would give the term itself"
        ),
    )


def axis_noise(
    values: npt.ArrayLike,
    tau0_s: float,
    *,
    name: str,
    sensor: Sensor,
    unit: str,
    segments: list[slice] | None = None,
    time_s: npt.ArrayLike | None = None,
    confidence: float = 0.6826894921370859,
    taus: Any = "octave",
) -> AxisNoise:
    """The noise of one IMU axis: its Allan analysis in the data's unit and its
    continuous-time white-noise density and random walk in SI.

    Parameters
    ----------
    values : array_like
        Rate samples of the axis [``unit``] (a gyro's angular rate or an accelerometer's
        specific force).
    tau0_s : float
        Sample interval τ0 [s].
    name : str
        The axis (its column).
    sensor : {"gyro", "accel"}
        What the axis measures.
    unit : str
        Unit of ``values`` (a rate or acceleration unit).
    segments : list of slice, optional
        The gap-free index ranges.
    time_s : array_like, optional
        Sample times [s] (the record is split at gaps).
    confidence : float
        Confidence level of the intervals.
    taus : {"octave", "decade", "log"} or array_like
        The τ set of the Allan deviation.

    Returns
    -------
    AxisNoise
        The Allan deviation and terms (:func:`thermocal.stability.allan.overlapping_adev`,
        :func:`thermocal.stability.allan.noise_terms`), the density [rad/s/√Hz or
        m/s²/√Hz] and random walk [rad/s²/√Hz or m/s³/√Hz], the output quantisation found.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A unit that is not the sensor's.

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C.
    """
    u = units.normalize_signal_unit(unit)
    kind_units = units.RATE_UNITS if sensor == "gyro" else units.ACCEL_UNITS
    if u not in kind_units:
        raise ThermocalInputError(
            f"{name}: {'a gyro' if sensor == 'gyro' else 'an accelerometer'} column in {unit!r}; "
            f"the noise model needs one of {', '.join(kind_units)} "
            f"(--{'gyro' if sensor == 'gyro' else 'accel'}-unit)"
        )
    v = np.asarray(values, dtype=np.float64).ravel()
    res, terms, quant = adev_and_terms(
        v, tau0_s, taus, time_s=time_s, segments=segments, unit=u, confidence=confidence
    )
    return AxisNoise(
        name=name,
        sensor=sensor,
        unit=u,
        allan=res,
        terms=terms,
        quantization=quant,
        density=_choose("density", sensor, u, res, terms),
        walk=_choose("walk", sensor, u, res, terms),
    )


def adev_and_terms(
    values: npt.NDArray[np.float64],
    tau0_s: float,
    taus: Any,
    *,
    time_s: npt.ArrayLike | None,
    segments: list[slice] | None,
    unit: str,
    confidence: float,
    overwrite: bool = False,
) -> tuple[AllanResult, NoiseTerms, OutputQuantization | None]:
    """A rate record's overlapping Allan deviation and its noise terms, with the output's
    quantisation and the periodic terms that shape the curve: what ``allan`` and ``noise``
    compute per channel.  The periodogram of the periodic-term check runs in a thread beside
    the quantisation lattice and the ADEV (numpy's FFT and loops release the GIL), joined
    before the sums when they may overwrite ``values``.

    Parameters
    ----------
    values : numpy.ndarray
        Rate samples, float64 [``unit``] (with ``overwrite``, the phase is accumulated in
        their buffer: give them up).
    tau0_s : float
        Sample interval τ0 [s].
    taus : {"octave", "decade", "log"} or array_like
        The τ set (:func:`thermocal.stability.allan.overlapping_adev`).
    time_s : array_like or None
        Sample times [s] (the record split at gaps).
    segments : list of slice or None
        The gap-free index ranges (the longest one's periodogram).
    unit : str
        Unit of ``values``.
    confidence : float
        Confidence level of the intervals.
    overwrite : bool, optional
        Let the ADEV accumulate the phase in ``values``' buffer.

    Returns
    -------
    tuple
        The Allan deviation, its noise terms (IEEE 952 C.2; annotated with the quantisation
        and the periodic terms) and the output quantisation found (or None).

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C.
    """
    longest = max(segments, key=lambda sl: sl.stop - sl.start) if segments else slice(None)
    with ThreadPoolExecutor(max_workers=1) as pool:
        periodic = pool.submit(periodic_terms, values[longest], tau0_s, unit)
        lattice = lattice_step(values)  # before the ADEV may overwrite the values
        res = overlapping_adev(
            values, tau0_s, taus, time_s=time_s, segments=segments, unit=unit,
            confidence=confidence, overwrite=overwrite,
            before_sums=periodic.result if overwrite else None,  # it has read the samples
        )  # fmt: skip
        found = periodic.result()
    terms = noise_terms(res, periodic=found)
    quant = quantization_from_lattice(lattice, tau0_s, unit, terms)
    terms = annotate_periodic(annotate_quantization(terms, quant), res, found)
    return res, terms, quant


def noise_model(
    axes: list[AxisNoise],
    update_rate_hz: float,
    *,
    inflate: float = 1.0,
    rostopic: str = "/imu0",
    confidence: float = 0.6826894921370859,
    where: str = "",
) -> NoiseModel:
    """The noise model of an IMU for an estimator: per sensor the largest white-noise
    density and the largest random walk over its axes (Kalibr's ``imu.yaml`` convention).

    Parameters
    ----------
    axes : list of AxisNoise
        Each axis's continuous-time terms (:func:`axis_noise`).
    update_rate_hz : float
        The IMU's sample rate [Hz].
    inflate : float
        Factor ≥ 1 every noise value is multiplied by (unmodelled effects; 1: none).
    rostopic : str
        The IMU's ROS topic (a ROS graph resource name, :data:`ROS_NAME`).
    confidence : float
        Confidence level of the intervals reported.
    where : str
        The file the warnings name.

    Returns
    -------
    NoiseModel
        The chosen axis per Kalibr key, and every axis.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        ``inflate`` below 1, ``rostopic`` not a ROS name, an axis named twice.

    Warns
    -----
    PlausibilityWarning
        An update rate or a density outside what an IMU has (:func:`implausible`).

    Notes
    -----
    A white-noise density σ_c [unit/√Hz] is the angle (velocity) random walk N, the −½
    line read at τ = 1 s; a random walk σ_c [unit/s/√Hz] is the rate random walk K, the
    +½ line read at τ = 3 s (IEEE Std 952-1997 Annex C: σ² = N²/τ + K²τ/3).  Their
    discrete-time values at the step Δt are σ_c/√Δt and σ_c √Δt.

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C.

    Examples
    --------
    White gyro noise of 0.01 rad/s per sample at 100 Hz: density 0.01·√0.01 = 0.001 rad/s/√Hz.

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 0.01, 4_000)
    >>> ax = axis_noise(y, 0.01, name="gx", sensor="gyro", unit="rad/s")
    >>> print(f"{ax.density.value:.3g} {ax.density.unit}")
    0.000998 rad/s/sqrt(Hz)
    >>> sorted(noise_model([ax], 100.0).chosen)
    ['gyroscope_noise_density', 'gyroscope_random_walk']
    """
    if not (math.isfinite(inflate) and inflate >= 1.0):
        raise ParameterError("inflate", f"{{name}} {inflate!r}: give a factor ≥ 1 (1: none)")
    _distinct_axes(axes)
    if not ROS_NAME.fullmatch(rostopic):
        raise ParameterError(
            "rostopic",
            f"{{name}} {one_line(repr(rostopic))}: not a ROS topic name (a letter, '/' or "
            "'~', then letters, digits, '_' and '/'; ROS wiki 'Names' 1.1.1), e.g. /imu0",
        )
    chosen: dict[str, AxisNoise] = {}
    for sensor, prefix in (("gyro", "gyroscope"), ("accel", "accelerometer")):
        mine = [a for a in axes if a.sensor == sensor]
        if not mine:
            continue
        chosen[f"{prefix}_noise_density"] = max(mine, key=lambda a: a.density.value)
        chosen[f"{prefix}_random_walk"] = max(mine, key=lambda a: a.walk.value)
    model = NoiseModel(tuple(axes), update_rate_hz, inflate, rostopic, confidence, chosen)
    for why in implausible(model):
        if where and why.template is not None:
            why = PlausibilityWarning.naming(f"{where}: {why.template}", *why.parameters)
        warnings.warn(why, stacklevel=2)
    return model


ROS_NAME: Final = re.compile(r"[A-Za-z~/][A-Za-z0-9_/]*")
"""A ROS graph resource name (ROS wiki "Names" 1.1.1: first character a letter, ``~`` or
``/``; then letters, digits, ``_`` and ``/``): Kalibr looks the IMU's topic up in the bag
by this name, so nothing else can be a topic."""

IMU_RATE_HZ: Final = (10.0, 1.0e5)
"""Update rates [Hz] outside which a noise model for an estimator is doubtful: estimators
fuse IMUs at 100 Hz to a few kHz (Kalibr's examples 200 Hz; the fastest MEMS outputs
32 kHz, TDK ICM-42688-P data sheet).  A time column in ms read as s gives 1/1000 of the
rate, and densities √1000 = 31.6× too large (σ_n = σ √τ0)."""

IMU_DENSITY: Final = {"gyro": (1.0e-9, 1.0e-2), "accel": (1.0e-8, 1.0e-1)}
"""White-noise densities [rad/s/√Hz; m/s²/√Hz] outside which no IMU lies: gyros from 30×
below a strategic-grade ring laser gyro (0.0001 °/√h = 2.9e-8 rad/s/√Hz) to 20× above a
noisy consumer MEMS gyro (L3G4200D data sheet 0.03 °/s/√Hz = 5.2e-4 rad/s/√Hz);
accelerometers from 1 ng/√Hz (seismic sensors) to 10 mg/√Hz (25× an ADXL345's
400 µg/√Hz, its data sheet)."""


def implausible(model: NoiseModel) -> list[PlausibilityWarning]:
    """Why ``model``'s update rate or densities cannot be an IMU's (empty: plausible); the
    bounds are :data:`IMU_RATE_HZ` and :data:`IMU_DENSITY`, each with its source.

    Parameters
    ----------
    model : NoiseModel
        The noise model.

    Returns
    -------
    list of PlausibilityWarning
        The reasons (``str()`` of each), empty when plausible; each names the parameters
        to check (``time_unit``, ``gyro_unit``, ``accel_unit``).
    """
    out = []
    lo, hi = IMU_RATE_HZ
    rate = model.update_rate_hz
    if not lo <= rate <= hi:
        out.append(
            PlausibilityWarning.naming(
                f"update rate {rate:.6g} Hz (one sample every {1.0 / rate:.6g} s) is outside "
                f"the {lo:g} Hz … {hi:g} Hz an estimator fuses an IMU at: if the time column "
                "is in ms or µs, give {time_unit} (a time axis ×1000 makes every noise "
                "density √1000 = 31.6× too large)",
                "time_unit",
            )
        )
    for ax in model.axes:
        dlo, dhi = IMU_DENSITY[ax.sensor]
        v = ax.density.value
        if not dlo <= v <= dhi:
            out.append(
                PlausibilityWarning.naming(
                    f"{one_line(ax.name)}: noise density {v:.4g} {ax.density.unit} lies "
                    f"outside the {dlo:g} … {dhi:g} of any {ax.sensor} (check the column's "
                    f"unit {{{ax.sensor}_unit}} and the time unit {{time_unit}})",
                    f"{ax.sensor}_unit",
                    "time_unit",
                )
            )
    return out


def _distinct_axes(axes: list[AxisNoise]) -> None:
    """Each column once: a gyro triad of one column, or accelerometer columns that are the
    gyro's, would give Kalibr one sensor's noise for another's."""
    first: dict[str, str] = {}
    for ax in axes:
        if ax.name in first:
            raise ThermocalInputError.naming(
                f"{{{ax.sensor}}} {one_line(repr(ax.name))}: column named twice (also in "
                f"{{{first[ax.name]}}}); give three different columns X,Y,Z for each sensor",
                *dict.fromkeys((ax.sensor, first[ax.name])),
            )
        first[ax.name] = ax.sensor


def _yaml_float(x: float) -> str:
    """A float YAML 1.1 (PyYAML) reads as a float: a mantissa with a dot, signed exponent."""
    return f"{x:.6e}"


_INFLATED_LINE: Final = (
    "# Every noise value below is INFLATED ×{:g} (--inflate) over the measured one, for "
    # cli-words: the imu.yaml the noise command writes names its option
    "unmodelled effects (vibration, temperature)."
)
"""The comment of an inflated ``imu.yaml`` (``str.format`` of the factor)."""

_ROSTOPIC_LINE: Final = "# rostopic: the ROS topic of this IMU in your bag (--rostopic)."
# cli-words: the imu.yaml the noise command writes names its option (the line above)


def kalibr_yaml(model: NoiseModel, source: str) -> str:
    """Kalibr's ``imu.yaml`` text with a comment block per key (term, τ, method, discrete
    conversion, the axes compared).

    Parameters
    ----------
    model, source : NoiseModel, str
        The model and the file it was computed from.
    """
    dt = 1.0 / model.update_rate_hz
    lines = [
        f"# IMU noise model for Kalibr, written by thermocal noise from {one_line(source)}",
        "# Continuous-time values (Kalibr's convention). Allan analysis: overlapping Allan",
        "# deviation (NIST SP 1065), noise terms by IEEE 952-1997 C.3 slope lines, else the",
        "# weighted least-squares fit (C.2). Kalibr takes one number per sensor: each value",
        "# below is the LARGEST over that sensor's axes.",
    ]
    if model.inflate != 1.0:
        lines.append(_INFLATED_LINE.format(model.inflate))
    lines.append("")
    values = model.kalibr()
    for key in KALIBR_KEYS:
        if key not in values:
            continue
        if key in model.chosen:
            ax = model.chosen[key]
            t = _term_for(key, ax)
            white = key.endswith("noise_density")
            words = _TERM_WORDS[(ax.sensor, "density" if white else "walk")]
            if t.method == "slope" and t.tau_range_s is not None:
                how = (
                    f"the {_SLOPE['density' if white else 'walk']} slope line of the ADEV "
                    f"(fitted on its {_SLOPE['density' if white else 'walk']} stretch τ = "
                    f"{t.tau_range_s[0]:.4g} … {t.tau_range_s[1]:.4g} s) read at τ = "
                    f"{t.read_at_tau_s:g} s"
                )
            elif t.method == "slope":
                how = (
                    f"the {_SLOPE['density' if white else 'walk']} slope line of the ADEV "
                    f"(touching the curve at τ = {t.tau_s:.4g} s) read at τ = "
                    f"{t.read_at_tau_s:g} s"
                )
            elif t.method == "fit":
                fin = ax.allan.tau_s[np.isfinite(ax.allan.adev) & (ax.allan.adev > 0)]
                how = (
                    "the weighted least-squares fit of the Allan variance over τ = "
                    f"{fin[0]:.4g} … {fin[-1]:.4g} s (its "
                    f"{_SLOPE['density' if white else 'walk']} line at τ = {t.read_at_tau_s:g} s)"
                )
            else:
                how = f"an UPPER BOUND: {t.reason}"
            others = ", ".join(
                f"{one_line(a.name)} {_yaml_float(_term_for(key, a).value)}"
                for a in model.axes
                if a.sensor == ax.sensor
            )
            name = one_line(ax.name)
            lines.append(f"# {key} [{t.unit}]: {words} of axis {name}, from {how}.")
            lines.append(f"#   quality {t.quality}; axes: {others}.")
            oq = ax.quantization
            if white and oq is not None and oq.kind == "rate":
                lines.append(
                    f"#   {name} is quantised at {oq.step:.6g} {oq.unit}: its rounding, "
                    f"white noise of {oq.white_density:.4g} {oq.white_density_unit}, is "
                    "part of this density."
                )
            if t.low is not None and t.high is not None:
                lines.append(
                    f"#   {model.confidence * 100:.1f} % interval of {name}: "
                    f"{_yaml_float(t.low)} … {_yaml_float(t.high)} (not inflated)."
                )
            v = float(values[key])
            if white:
                lines.append(
                    f"#   discrete time at Δt = {dt:.6g} s: σ_d = σ_c / √Δt = "
                    f"{_yaml_float(v / math.sqrt(dt))}"
                )
            else:
                lines.append(
                    f"#   discrete time at Δt = {dt:.6g} s: σ_d = σ_c · √Δt = "
                    f"{_yaml_float(v * math.sqrt(dt))}"
                )
            lines.append(f"{key}: {_yaml_float(v)}")
        elif key == "update_rate":
            lines.append("# update_rate [Hz]: 1 / the recording's sample interval.")
            rate = repr(float(model.update_rate_hz))  # 100.0; but 1e+16 is text to YAML 1.1
            if "." not in rate or "e" in rate:
                rate = f"{float(model.update_rate_hz):.16e}"
            lines.append(f"{key}: {rate}")
        else:
            lines.append(_ROSTOPIC_LINE)
            lines.append(f"{key}: {json.dumps(model.rostopic)}")
        lines.append("")
    text = "\n".join(lines)
    check_kalibr_yaml(text)
    return text


def check_kalibr_yaml(text: str) -> None:
    """Refuse (:class:`ThermocalInputError`) ``imu.yaml`` text a name could have steered:
    a character a YAML reader takes for a line break or refuses (anything
    :func:`~thermocal.identifiers.one_line` escapes, other than newline), a line that is
    neither blank, nor a comment starting in column 1, nor ``key: value`` of a key of
    :data:`KALIBR_KEYS`, a key written twice (PyYAML keeps the LAST: a second
    ``gyroscope_noise_density`` would win), a numeric key whose value is not a float, a
    missing key.  The writer's backstop (YAML 1.2 §6.6 comments, §7.4 flow mappings).

    Parameters
    ----------
    text : str
        The ``imu.yaml`` text.

    Raises
    ------
    ThermocalInputError
        On any of the faults above.
    """
    bad = next((c for c in text if c != "\n" and one_line(c) != c), None)
    if bad is not None:
        raise ThermocalInputError(f"Kalibr imu.yaml: character {bad!r} in the text")
    seen: set[str] = set()
    for ln in text.split("\n"):
        if ln == "" or ln.startswith("#"):
            continue
        m = re.fullmatch(r"([a-z_]+): (\S.*)", ln)
        if m is None or m.group(1) not in KALIBR_KEYS:
            raise ThermocalInputError(f"Kalibr imu.yaml: unexpected line {ln[:80]!r}")
        key, value = m.groups()
        if key in seen:
            raise ThermocalInputError(f"Kalibr imu.yaml: {key} written twice")
        seen.add(key)
        if key == "rostopic":
            if not ROS_NAME.fullmatch(json.loads(value)):
                raise ThermocalInputError(f"Kalibr imu.yaml: rostopic {value[:80]!r}")
        elif not re.fullmatch(r"[0-9]+\.[0-9]*(e[+-][0-9]+)?", value):
            raise ThermocalInputError(f"Kalibr imu.yaml: {key} {value[:80]!r} is not a float")
    missing = [k for k in KALIBR_KEYS if k not in seen]
    if missing:
        raise ThermocalInputError(f"Kalibr imu.yaml: no {', '.join(missing)}")


def _term_json(t: NoiseTerm, method: str) -> dict[str, Any]:
    return {
        "value": t.value,
        "unit": t.unit,
        "low": t.low,
        "high": t.high,
        "tau_s": t.tau_s,
        "method": method,
        "quality": None if t.value is None else (t.quality or "good"),
        "reason": t.reason,
        "label": t.label,
        "tau_range_s": list(t.tau_range_s) if t.tau_range_s is not None else None,
    }


def _best(slope: NoiseTerm, fit: NoiseTerm) -> dict[str, Any]:
    """The slope reading where it exists, else the fitted term."""
    return _term_json(slope, "slope") if slope.value is not None else _term_json(fit, "fit")


def _continuous_json(t: ContinuousTerm) -> dict[str, Any]:
    return {
        "value": t.value,
        "low": t.low,
        "high": t.high,
        "unit": t.unit,
        "term": t.term,
        "method": t.method,
        "tau_s": t.tau_s,
        "read_at_tau_s": t.read_at_tau_s,
        "quality": t.quality,
        "reason": t.reason,
        "tau_range_s": list(t.tau_range_s) if t.tau_range_s is not None else None,
    }


def _minimum_json(t: NoiseTerm | None) -> dict[str, Any] | None:
    """The bias instability at the curve's minimum (always; IEEE 952 C.3)."""
    if t is None:
        return None
    out = _term_json(t, "minimum")
    out["quality"] = t.quality
    return out


# --- output quantisation --------------------------------------------------------------------------

QUANT_MIN_LEVELS: Final = 3
"""Distinct output levels a quantised record must show (two levels give no lattice)."""

QUANT_MIN_REPEAT: Final = 20
"""A quantised record visits each level this many times on average at least: ordinary
floating-point data have about as many distinct values as samples."""

QUANT_RTOL: Final = 1e-3
"""Kept for callers: the former tolerance (every sample within this fraction of a step);
:func:`lattice_step` uses :data:`QUANT_LEVEL_TOL` and :data:`QUANT_MAX_OFF`."""

_QUANT_PROBE: Final = 200_000
"""Samples (evenly strided) the lattice step is found from before the whole record is checked."""

_QUANT_MERGE: Final = 1e-9
"""Distinct values closer than this fraction of the sample range are one level."""

QUANT_MIN_ULPS: Final = 4
"""A lattice step of at most this many units in the last place of the storage's precision
at the record's largest magnitude (float32 when every probed sample is a float32 value,
else float64) is the storage's rounding, not the sensor's output quantisation: a float32
accelerometer at 9.8 m/s² lies on a 9.5e-7 lattice, a float64 record at 1e15 on 0.125."""

_SQRT12: Final = math.sqrt(12.0)


@dataclass(frozen=True)
class OutputQuantization:
    """A sensor output found quantised: every sample lies on ``offset + k·step``.

    ``step`` [``unit``, the data's own unit]; ``levels`` distinct levels used; ``kind``
    ``"rate"`` (the rate output is rounded: the rounding errors are independent from
    sample to sample, i.e. white rate noise) or ``"angle"`` (the integrated output is
    rounded and the remainder carried, as a pulse-output or delta-angle sensor does: the
    angle error stays bounded and the Allan deviation falls as τ⁻¹).

    Relations (a uniform rounding error has variance step²/12):

    * rate quantisation: white rate noise of variance step²/12 per sample, the angle random
      walk ``N_q = step·√(τ0/12)`` [unit·√s] (``σ_q²(τ) = N_q²/τ``, slope −½): it is part
      of the measured N, not a separate τ⁻¹ term;
    * angle quantisation at the angle step ``step·τ0``: IEEE Std 952-1997 Annex C.1,
      ``σ²(τ) = 3Q²/τ²`` (slope −1, read at τ = √3 s) with ``Q = step·τ0/√12`` [unit·s].

    ``white_density``/``angle_q`` are N_q and Q in the units the noise terms use
    (:func:`thermocal.stability.allan.term_units`); ``share`` the fraction of the measured
    term's variance explained by the quantisation (rate: N_q²/N² with N the slope line's,
    else the fit's; angle: Q²/Q_fit²), None when the
    record shows no such term; ``quality`` ``good`` or ``rough`` with ``reason``.

    Attributes
    ----------
    step : float
        The quantum [``unit``].
    unit : str
        The data's own unit.
    offset : float
        The lattice's offset [``unit``].
    levels, n_samples : int
        Distinct levels used and samples read.
    kind : str
        ``"rate"`` or ``"angle"``.
    white_density, angle_q : float
        N_q and Q in the noise terms' units.
    white_density_unit, angle_q_unit : str
        Those units.
    share : float or None
        Fraction of the measured term's variance explained.
    quality : str
        ``good`` or ``rough``.
    reason : str or None
        Why rough.
    source : str
        How the quantisation was found and why its variance is step²/12 (one sentence).
    """

    step: float
    unit: str
    offset: float
    levels: int
    n_samples: int
    kind: str
    white_density: float
    white_density_unit: str
    angle_q: float
    angle_q_unit: str
    share: float | None
    quality: str
    reason: str | None
    source: str

    def to_dict(self) -> dict[str, Any]:
        """The ``output_quantization`` JSON object (a noise term: value, unit, source)."""
        return {
            "value": self.step,
            "unit": self.unit,
            "term": f"{self.kind} quantization step",
            "kind": self.kind,
            "levels": self.levels,
            "n_samples": self.n_samples,
            "white_density": {"value": self.white_density, "unit": self.white_density_unit},
            "angle_q": {"value": self.angle_q, "unit": self.angle_q_unit},
            "share": self.share,
            "quality": self.quality,
            "reason": self.reason,
            "source": self.source,
        }

    def line(self) -> str:
        """One line for the text output."""
        if self.kind == "rate":
            how = (
                f"rate quantisation = white rate noise N_q = {self.white_density:.4g} "
                f"{self.white_density_unit}"
            )
            if self.share is not None:
                how += f" ({100 * self.share:.3g} % of the measured N²)"
        else:
            how = f"angle quantisation Q = {self.angle_q:.4g} {self.angle_q_unit}"
            if self.share is not None:
                how += f" ({100 * self.share:.3g} % of the fitted Q²)"
        return (
            f"output quantised: step {self.step:.6g} {self.unit} ({self.levels} levels): {how}"
            + (f"; rough: {self.reason}" if self.reason else "")
        )


QUANT_LEVEL_TOL: Final = 0.02
"""A level lies on the sensor's lattice when within this fraction of a step of it: a storage
grid up to 25× finer than the step rounds each level by at most half a grid step."""

QUANT_MAX_OFF: Final = 1e-3
"""At most this fraction of the samples may lie off the lattice (glitches, outliers)."""


def lattice_step(
    values: npt.ArrayLike, *, rtol: float = QUANT_LEVEL_TOL
) -> tuple[float, float, int, int] | None:
    """The sensor's lattice ``offset + k·step`` among the finite samples' distinct levels,
    as (step, offset, levels, finite samples), or None when they lie on none
    (:data:`QUANT_MIN_LEVELS`, :data:`QUANT_MIN_REPEAT`).

    The step is the greatest common spacing that explains the levels, robust to a finer
    storage grid and a few outliers (a pulse-quantised gyro with 77 levels 0.00816 °/s
    apart stored on a 1.22e-4 °/s grid has step 0.00816, not 1.22e-4): on at most
    :data:`_QUANT_PROBE` evenly strided samples, the distinct values u with their counts,
    the first guess the median gap between neighbouring levels among the most-visited
    ones (adjacent lattice points where the samples are dense), refined by the
    count-weighted least-squares line ``u = o + step·k`` with k = round((u − o)/step),
    over ±5, ±20 and then all steps of the most-visited level.  Then every sample of the
    record is checked: at least 1 − :data:`QUANT_MAX_OFF` of them lie within ``rtol`` of a
    step of the lattice.  A step of at most :data:`QUANT_MIN_ULPS` storage ulps is the
    storage's rounding, not the sensor's.

    Parameters
    ----------
    values : array_like
        Samples [unit].
    rtol : float, optional
        Tolerance relative to the step (default :data:`QUANT_LEVEL_TOL`).

    Returns
    -------
    tuple of (float, float, int, int) or None
        (step [unit], offset [unit], levels, finite samples).
    """
    v = np.asarray(values, dtype=np.float64).ravel()
    if not math.isfinite(float(v.sum())):  # a copy of the finite samples only when needed
        v = v[np.isfinite(v)]
    n = v.size
    if n < QUANT_MIN_LEVELS * QUANT_MIN_REPEAT:
        return None
    probe = v[:: max(1, n // _QUANT_PROBE)]
    u, c = np.unique(probe, return_counts=True)
    if u.size < QUANT_MIN_LEVELS or u.size * QUANT_MIN_REPEAT > probe.size:
        return None
    guess = _level_lattice(u, c.astype(np.float64), rtol)
    if guess is None:
        return None
    step, origin = guess
    if step <= QUANT_MIN_ULPS * _storage_ulp(probe, max(abs(float(u[0])), abs(float(u[-1])))):
        return None
    # the whole record, in blocks (no array of n quotients)
    off = 0
    lo_k, hi_k = math.inf, -math.inf
    for a in range(0, n, 1 << 20):
        q = (v[a : a + (1 << 20)] - origin) / step
        kk = np.rint(q)
        on = np.abs(q - kk) <= rtol
        off += int(on.size - np.count_nonzero(on))
        if on.any():
            lo_k, hi_k = min(lo_k, float(kk[on].min())), max(hi_k, float(kk[on].max()))
    if off > QUANT_MAX_OFF * n or not math.isfinite(lo_k):
        return None
    span = int(hi_k - lo_k) + 1
    if span > 1 << 24:  # a lattice of more levels than that is no quantisation to report
        return None
    seen = np.zeros(span, dtype=bool)
    for a in range(0, n, 1 << 20):
        q = (v[a : a + (1 << 20)] - origin) / step
        kk = np.rint(q)
        seen[(kk[np.abs(q - kk) <= rtol] - lo_k).astype(np.int64)] = True
    levels = int(np.count_nonzero(seen))
    if levels < QUANT_MIN_LEVELS or levels * QUANT_MIN_REPEAT > n:
        return None
    return step, origin + lo_k * step, levels, n


def _level_lattice(
    u: npt.NDArray[np.float64], c: npt.NDArray[np.float64], rtol: float
) -> tuple[float, float] | None:
    """(step, origin) of the lattice the distinct levels ``u`` (visited ``c`` times) lie on,
    or None (:func:`lattice_step`): the median gap between neighbouring levels among those
    visited at least as often as the median level, refined by weighted least squares."""
    top = u[c >= np.median(c)]
    d = np.diff(top)
    d = d[d > _QUANT_MERGE * float(u[-1] - u[0])]
    if d.size == 0:
        return None
    step = float(np.median(d))
    ref = float(u[int(np.argmax(c))])
    origin = ref
    for reach in (5.0, 20.0, math.inf):
        k = np.rint((u - origin) / step)
        sel = np.abs((u - ref) / step) <= reach + 0.5
        kk, uu, w = k[sel], u[sel], c[sel]
        if np.unique(kk).size < 2:
            return None
        km = float(np.average(kk, weights=w))
        um = float(np.average(uu, weights=w))
        step = float(np.sum(w * (kk - km) * (uu - um)) / np.sum(w * (kk - km) ** 2))
        if not step > 0:
            return None
        origin = um - step * km
    r = (u - origin) / step
    on = np.abs(r - np.rint(r)) <= rtol
    if float(c[on].sum()) < (1.0 - QUANT_MAX_OFF) * float(c.sum()):
        return None
    return step, origin


def _storage_ulp(probe: npt.NDArray[np.float64], top: float) -> float:
    """The spacing of the stored numbers at magnitude ``top``: float32's when every probed
    sample is a float32 value (a ULog field, a float32 Parquet column), else float64's."""
    f32 = bool(np.all(probe.astype(np.float32).astype(np.float64) == probe))
    return float(np.spacing(np.float32(top)) if f32 else np.spacing(top))


def output_quantization(
    values: npt.ArrayLike, tau0_s: float, unit: str, terms: NoiseTerms | None = None
) -> OutputQuantization | None:
    r"""The output quantisation of a rate record in its own unit ``unit`` (sampled every
    ``tau0_s`` [s]) found from the data (:func:`lattice_step`), or None when the samples
    lie on no lattice.  Call it before the Allan deviation overwrites ``values``.

    ``terms`` (the record's noise terms) decide the kind and the share: ``angle`` when the
    least-squares fit finds a significant τ⁻¹ (Q) term — rounding a rate does not make one,
    carrying the rounding remainder of an integrated output does (IEEE 952 C.1) — else
    ``rate`` (see :class:`OutputQuantization` for both relations).

    Parameters
    ----------
    values : array_like
        Rate samples [``unit``].
    tau0_s : float
        Sample interval [s].
    unit : str
        Rate unit.
    terms : NoiseTerms, optional
        The record's noise terms.

    Returns
    -------
    OutputQuantization or None
        Step, kind and share, or None without a lattice.

    Notes
    -----
    .. math:: N_q = \Delta \sqrt{\tau_0 / 12}, \qquad Q = \Delta \tau_0 / \sqrt{12}

    with Δ the step [unit].

    References
    ----------
    - IEEE Std 952-1997, Annex C.1 (quantization noise).
    """
    return quantization_from_lattice(lattice_step(values), tau0_s, unit, terms)


def quantization_from_lattice(
    found: tuple[float, float, int, int] | None,
    tau0_s: float,
    unit: str,
    terms: NoiseTerms | None = None,
) -> OutputQuantization | None:
    """:func:`output_quantization` from the lattice :func:`lattice_step` found (None: none).

    Parameters
    ----------
    found : tuple or None
        Result of :func:`lattice_step`.
    tau0_s : float
        Sample interval [s].
    unit : str
        Rate unit.
    terms : NoiseTerms, optional
        The record's noise terms.

    Returns
    -------
    OutputQuantization or None
        As :func:`output_quantization`.
    """
    if found is None:
        return None
    step, offset, levels, n = found
    scale, specs = term_units(unit)
    n_q = step * math.sqrt(tau0_s / 12.0) * scale * specs[1][0]  # unit·√s → N's unit
    q_q = step * tau0_s / _SQRT12 * scale * specs[0][0]  # unit·s → Q's unit
    kind, share = "rate", None
    if terms is not None:
        q_fit = terms.fit.quantization
        if q_fit.value is not None:
            kind, share = "angle", (q_q / q_fit.value) ** 2
        else:
            arw = terms.slope.angle_random_walk
            if arw.value is None:
                arw = terms.fit.angle_random_walk
            if arw.value is not None and arw.value > 0:
                share = (n_q / arw.value) ** 2
    rough = levels < 5
    return OutputQuantization(
        step=step, unit=unit, offset=offset, levels=levels, n_samples=n, kind=kind,
        white_density=n_q, white_density_unit=specs[1][1], angle_q=q_q,
        angle_q_unit=specs[0][1], share=share, quality="rough" if rough else "good",
        reason=(
            f"only {levels} levels: the noise is not much larger than the step, so the "
            "rounding error is not independent of the signal and step²/12 holds roughly"
            if rough
            else None
        ),
        source=(
            "the samples lie on a lattice of this step (the greatest common spacing of the "
            "distinct sample values, a finer storage grid aside; at least "
            f"{100 * (1 - QUANT_MAX_OFF):g} % of the samples within {QUANT_LEVEL_TOL:g} "
            "step of it); a uniform rounding error has variance step²/12 "
            "(IEEE Std 952-1997 Annex C.1)"
        ),
    )  # fmt: skip


def annotate_quantization(terms: NoiseTerms, quant: OutputQuantization | None) -> NoiseTerms:
    """``terms`` with the quantization term's reason naming a rate quantisation: rounding a
    rate is white rate noise (inside N), so IEEE 952's τ⁻¹ term stays null.

    Parameters
    ----------
    terms : NoiseTerms
        Noise terms.
    quant : OutputQuantization or None
        The quantisation found.

    Returns
    -------
    NoiseTerms
        ``terms`` with the quantization reason reworded.
    """
    if quant is None or quant.kind != "rate":
        return terms

    def note(t: NoiseTerm) -> NoiseTerm:
        if t.value is not None:
            return t
        why = (
            f"the rate output is quantised (step {quant.step:.6g} {quant.unit}): rounding a "
            "rate is white rate noise, inside the angle random walk (N_q = "
            f"{quant.white_density:.4g} {quant.white_density_unit}), not a τ⁻¹ term; "
            f"{t.reason}"
        )
        return dataclasses.replace(t, reason=why)

    return dataclasses.replace(
        terms,
        slope=dataclasses.replace(terms.slope, quantization=note(terms.slope.quantization)),
        fit=dataclasses.replace(terms.fit, quantization=note(terms.fit.quantization)),
    )


__all__ = [
    "IMU_DENSITY",
    "IMU_RATE_HZ",
    "KALIBR_KEYS",
    "QUANT_LEVEL_TOL",
    "QUANT_MAX_OFF",
    "QUANT_MIN_LEVELS",
    "QUANT_MIN_REPEAT",
    "QUANT_RTOL",
    "ROS_NAME",
    "SI_UNIT",
    "AxisNoise",
    "ContinuousTerm",
    "NoiseModel",
    "OutputQuantization",
    "adev_and_terms",
    "annotate_quantization",
    "axis_noise",
    "check_kalibr_yaml",
    "implausible",
    "kalibr_yaml",
    "lattice_step",
    "noise_model",
    "output_quantization",
    "quantization_from_lattice",
    "term_words",
]
