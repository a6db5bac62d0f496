"""Compensation with a fitted model, in memory and live ([Seed-RLG]): the maths of
:mod:`thermocal.pipeline.compensate` without files (the maths imports no I/O).

A model gives the temperature-induced part of the signal, ``ŷ = model(T, Ṫ, …)``; the
compensated output is ``F' = F − ŷ`` ([Seed-Plan]: "output F' = F − ΔF").

* :func:`compensate_run` — in memory, ``model.predict(run)`` on a whole run.
* :class:`ChunkPredictor` — a long run chunk by chunk with the *context* the model needs
  (the samples since power-on that fix its start-up state and the last Δt seconds that
  feed the Ṫ buffer, declared by each family:
  :meth:`~thermocal.models.base.TemperatureModel.chunk_context`);
  because ``predict`` is causal the values of a chunk's own rows equal those of a
  whole-run ``predict``.  Families without a finite context are streamed sample by sample.
* :class:`StreamingCompensator` — live data, one sample at a time, through the family's
  :class:`~thermocal.models.base.ModelStream`; :class:`CalibrationStream` — every channel
  of a calibration at once.

Units: the model predicts in its signal unit (``model.signal_unit``); data in another unit
of the same kind are converted with :mod:`thermocal.units` (:func:`unit_factor`).  A model
and data of different kinds (°/h against mg) is a :class:`~thermocal.errors.UnitError`
naming both.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Final, cast

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import (
    ExtrapolationWarning,
    ThermocalInputError,
    TimestampError,
    UnitError,
    UnitWarning,
)
from thermocal.models.base import ChunkContext, ModelStream, TemperatureModel
from thermocal.models.ranges import RangeExcess, RangeTally, outside_range_message
from thermocal.models.rundata import RunData
from thermocal.recording import GAP_FACTOR, FloatArray, Metadata, Recording, median_interval

# --- unit handling ------------------------------------------------------------------------


def unit_factor(
    data_unit: str,
    model_unit: str,
    *,
    meta: Metadata | None = None,
    sample_interval_s: float | None = None,
    where: str = "",
) -> float:
    r"""Factor ``f`` with ``value[model unit] = f · value[data unit]`` (all units are linear).

    Raw ``counts`` data are turned into a physical unit with the metadata's scale
    factor K (IEEE Std 952-1997: ``ω = N/(τK)`` or ``N/K``,
    :func:`thermocal.units.counts_to_physical`).

    Parameters
    ----------
    data_unit : str
        Unit of the data's signal column (e.g. ``"deg/h"``, ``"mg"``, ``"counts"``).
    model_unit : str
        The model's signal unit (``model.signal_unit``).
    meta : Metadata, optional
        The recording's metadata; its scale factor K converts raw ``counts``
        (default ``None``: no conversion of counts possible).
    sample_interval_s : float, optional
        Sample interval τ [s] for a scale factor per pulse; default the metadata's
        ``sample_interval_s``, else 1 s.
    where : str, optional
        Name put in front of an error message (the file); default ``""``.

    Returns
    -------
    float
        The factor f [model unit / data unit]; 1.0 for equal units.

    Raises
    ------
    UnitError
        The two units measure different kinds of quantity (the message names both),
        or counts cannot be converted because no scale factor is given.

    Notes
    -----
    .. math:: y_{\mathrm{model}} = f\,y_{\mathrm{data}},
              \qquad \omega = \frac{N}{\tau K}

    References
    ----------
    - IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure
      for Single-Axis Interferometric Fiber Optic Gyros* (scale factor K).

    Examples
    --------
    >>> from thermocal.compensate.kernels import unit_factor
    >>> round(unit_factor("deg/s", "deg/h"), 3)
    3600.0
    >>> unit_factor("mg", "mg")
    1.0
    """
    du = units.normalize_signal_unit(data_unit)
    mu = units.normalize_signal_unit(model_unit)
    prefix = f"{where}: " if where else ""
    if du == mu:
        return 1.0
    if du == "counts":
        if meta is None or meta.scale_factor is None:
            raise UnitError(
                f"{prefix}the data signal is in raw counts but the model is in {mu!r} and "
                "no scale factor K is given to convert them"
            )
        tau = sample_interval_s if sample_interval_s is not None else meta.sample_interval_s
        phys_per_count, phys_unit = units.counts_to_physical(
            1.0,
            meta.scale_factor,
            units.scale_factor_unit_or_default(meta.scale_factor_unit, where),
            float(tau or 1.0),
        )
        return float(phys_per_count) * unit_factor(phys_unit, mu, where=where)
    if units.signal_kind(du) != units.signal_kind(mu):
        raise UnitError(
            f"{prefix}the model's signal unit {mu!r} ({units.signal_kind(mu)}) does not match the "
            f"data's unit {du!r} ({units.signal_kind(du)})"
        )
    return float(units.convert(1.0, du, mu))


def check_signal_kind(data_unit: str, model_unit: str, where: str = "") -> None:
    """Refuse data whose signal is of another kind than the model's.

    A rate against an acceleration is refused, naming both, before anything is computed
    or written.  Raw ``counts`` data pass here (their scale factor decides,
    :func:`unit_factor`).

    Parameters
    ----------
    data_unit : str
        Unit of the data's signal column.
    model_unit : str
        The model's signal unit.
    where : str, optional
        Name put in front of the error message (the file); default ``""``.

    Raises
    ------
    UnitError
        The data's unit is of another kind than the model's (and not raw counts).
    """
    du = units.normalize_signal_unit(data_unit)
    mu = units.normalize_signal_unit(model_unit)
    kd, km = units.signal_kind(du), units.signal_kind(mu)
    if kd != km and kd != "raw":
        raise UnitError(
            f"{where + ': ' if where else ''}the model's signal unit {mu!r} ({km}) does not "
            f"match the data's unit {du!r} ({kd}): a model applies to its own kind of "
            "quantity only"
        )


def model_scale_factor(model: TemperatureModel, meta: Metadata) -> Metadata:
    """``meta`` with the scale factor K taken from the model when the data give none.

    The scale factor of a raw-count signal comes from the model file's ``inputs`` when
    the data's metadata gives none (the resolution order: file > model).

    Parameters
    ----------
    model : TemperatureModel
        A fitted model (its ``inputs_`` record of the fit's scale factor).
    meta : Metadata
        The data's metadata; updated in place when it has no scale factor.

    Returns
    -------
    Metadata
        ``meta`` itself, with ``scale_factor`` [counts per unit] and its unit set when
        the model recorded one and the data did not.
    """
    sf = (getattr(model, "inputs_", {}) or {}).get("scale_factor")
    if meta.scale_factor is None and isinstance(sf, dict) and sf.get("value") is not None:
        meta.scale_factor = float(sf["value"])
        meta.scale_factor_unit = sf.get("unit") or meta.scale_factor_unit
    return meta


def temperature_inputs(
    model: TemperatureModel, resolved: units.ResolvedInputs, where: str = ""
) -> dict[str, units.TemperatureConversion | None]:
    """How each of the model's temperature columns becomes its temperature input: a
    counts → °C conversion, or ``None`` (the values as they are: °C for a °C model, raw
    counts for a model fitted in counts).

    Parameters
    ----------
    model : TemperatureModel
        A fitted model (``temperature_unit`` is ``"°C"`` or ``"counts"``).
    resolved : thermocal.units.ResolvedInputs
        The data's temperature columns with their units and conversions.
    where : str, optional
        Name put in front of a message (the file); default ``""``.

    Returns
    -------
    dict of str to TemperatureConversion or None
        Per temperature column, the counts → °C conversion to apply, or ``None``.

    Raises
    ------
    UnitError
        Raw counts without any conversion (option, file or model) under a °C model, or
        °C data under a counts model.

    Warns
    -----
    UnitWarning
        A conversion given as an option for a model fitted in raw counts (not used).
    """
    prefix = f"{where}: " if where else ""
    out: dict[str, units.TemperatureConversion | None] = {}
    for c, r in resolved.temperatures.items():
        conv = resolved.conversions[c]
        if model.temperature_unit == "counts":
            if r.unit != "counts":
                raise UnitError.naming(
                    f"{prefix}the model's temperatures are raw counts (it was fitted without a "
                    f"conversion), but column {c!r} is in {r.unit}; give raw-count data "
                    "({temp_unit} counts) or refit the model with {temp_conversion}",
                    "temp_unit",
                    "temp_conversion",
                )
            if conv.source == "option":
                warnings.warn(
                    UnitWarning.naming(
                        f"{prefix}the model's temperatures are raw counts; {{temp_conversion}} "
                        f"is not used for column {c!r}",
                        "temp_conversion",
                    ),
                    stacklevel=3,
                )
            out[c] = None
        elif r.unit == "counts":
            if conv.conversion is None:
                raise UnitError.naming(
                    f"{prefix}temperature column {c!r} is in raw counts and no conversion to "
                    "°C is given ({temp_conversion} GAIN,OFFSET[,int16], the file's metadata, "
                    "or a model fitted with one)",
                    "temp_conversion",
                )
            out[c] = conv.conversion
        else:
            out[c] = None
    return out


@dataclass(frozen=True)
class ModelRun:
    """A recording prepared for a model (:func:`prepare_run`).

    ``run`` is in the model's units (signal in ``model.signal_unit``, temperatures in
    ``model.temperature_unit``); ``data_unit`` is the data column's own unit and
    ``factor`` takes values from it to the model's unit: ``value[model] = factor ·
    value[data]``; :meth:`to_data_unit` brings model values (ŷ, residuals, figures) back.

    Attributes
    ----------
    run : RunData
        The run in the model's units.
    data_unit : str
        The data column's own signal unit.
    factor : float
        ``value[model unit] = factor · value[data unit]``.
    """

    run: RunData
    data_unit: str
    factor: float

    def to_data_unit(self, values: npt.ArrayLike) -> FloatArray:
        """Model-unit values → the data's unit.

        Parameters
        ----------
        values : array_like
            Values in the model's signal unit (ŷ, residuals, figures).

        Returns
        -------
        numpy.ndarray
            ``values / factor`` [data unit], float64.
        """
        return np.asarray(values, dtype=np.float64) / self.factor


def prepare_run(
    model: TemperatureModel,
    rec: Recording,
    signal: str | None = None,
    temps: Sequence[str] | None = None,
    *,
    known_input: float = 0.0,
) -> ModelRun:
    """The recording's signal and temperatures as the model takes them (validate, report).

    ``rec`` should be read with the model's recorded units as fallbacks
    (``read_recording(..., model=model)``).  A signal of another kind than the model's is
    refused (:func:`check_signal_kind`); raw-count temperatures are converted, or kept as
    counts for a model fitted in counts (a mismatch is refused).

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.
    rec : Recording
        The recording to prepare.
    signal : str, optional
        Signal column; default the model's ``signal_name``.
    temps : sequence of str, optional
        Temperature columns; default the model's ``temp_names_``.
    known_input : float, optional
        The true input during the run (earth rate, gravity component) [data unit];
        default 0.

    Returns
    -------
    ModelRun
        The run in the model's units with the data unit and the factor between them.

    Raises
    ------
    UnitError
        The signal is of another kind than the model's, or counts cannot be converted.
    ThermocalInputError
        A signal or temperature column is missing from the recording.
    """
    sig = signal or model.signal_name
    names = tuple(temps) if temps else tuple(model.temp_names_)
    data_unit = rec.units.get(sig) or ""
    check_signal_kind(data_unit, model.signal_unit, rec.name)
    if model.temperature_unit == "counts":
        run = RunData.from_recording(rec, sig, names, temperature_unit="counts")
    else:
        run = RunData.from_recording(rec, sig, names)
    values = rec.column(sig)
    factor = unit_factor(data_unit, model.signal_unit, meta=rec.meta, where=rec.name)
    run = dataclasses.replace(
        run,
        signal=values * factor,
        known_input=known_input * factor,
        signal_unit=model.signal_unit,
    )
    return ModelRun(run, units.normalize_signal_unit(data_unit), factor)


# --- batch -------------------------------------------------------------------------------


@dataclass(frozen=True)
class Compensation:
    """Result of :func:`compensate_run`.

    ``model_value`` ŷ and ``corrected`` ``F' = F − ŷ`` [model signal unit], shape (n,).

    Attributes
    ----------
    model_value : numpy.ndarray
        ŷ, the temperature-induced part [model signal unit].
    corrected : numpy.ndarray
        ``F − ŷ`` [model signal unit].
    """

    model_value: FloatArray
    corrected: FloatArray


def compensate_run(
    model: TemperatureModel, run: RunData, *, extrapolate: bool = False
) -> Compensation:
    r"""Apply a model to a whole run in memory: ``F' = F − ŷ(T, Ṫ, …)``.

    ``run.signal`` must be in the model's unit.  ``known_input`` is not removed:
    the compensated output still contains the true input (earth rate, gravity).

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.
    run : RunData
        Time [s], temperatures [°C or counts, as the model] and signal [model unit].
    extrapolate : bool, optional
        Allow prediction outside the calibrated ranges (see the family's
        ``predict``); default ``False``.

    Returns
    -------
    Compensation
        ŷ and ``F − ŷ`` [model signal unit], shape (n,).

    Raises
    ------
    ThermocalInputError
        The run has no signal.

    Notes
    -----
    .. math:: F'_i = F_i - \hat y(T_i, \dot T_i, \ldots)

    References
    ----------
    - *Temperature-characteristic calibration test plan* (output ``F' = F − ΔF``).
    - *A modelling and validation method for the temperature compensation model of a
      ring-laser gyroscope*, Chinese invention patent, 2017.

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.poly import PolyModel
    >>> from thermocal.compensate.kernels import compensate_run
    >>> t = np.arange(0.0, 3600.0, 10.0)
    >>> temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / 3600.0)
    >>> run = RunData(t, temp[:, None], 0.5 + 0.02 * temp, ("T1",))
    >>> out = compensate_run(PolyModel(order=1).fit([run]), run)
    >>> round(float(np.max(np.abs(out.corrected))), 6)
    0.0
    """
    if run.signal is None:
        raise ThermocalInputError(f"{run.name or 'run'}: no signal to compensate")
    y = np.asarray(model.predict(run, extrapolate=extrapolate), dtype=np.float64)
    return Compensation(model_value=y, corrected=run.signal - y)


# --- what the sensor's user sees ----------------------------------------------------------

ABSOLUTE_WORSE_TOLERANCE = 0.01
"""A compensated output is *absolutely worse* when its rms about zero or its largest
|error| exceeds the raw output's by more than this fraction (1 %: beyond the change a
model that removes nothing of the noise makes by itself)."""


@dataclass(frozen=True)
class AbsoluteFigures:
    """The output as the sensor's user sees it, per sample, against the level an ideal
    sensor would give (the reference K: 0, or the known input — earth rate, gravity):
    ``mean = mean(x − K)``, ``rms_about_zero = sqrt(mean((x − K)²)) = sqrt(σ² + mean²)``
    (σ the rms about the mean) and ``max_abs = max |x − K|`` [unit of x].  Unlike the
    figures about the mean, these see a constant offset the model adds or leaves.

    Attributes
    ----------
    mean : float
        ``mean(x − K)`` [unit of x].
    rms_about_zero : float
        ``sqrt(mean((x − K)²))`` [unit of x].
    max_abs : float
        ``max |x − K|`` [unit of x].
    """

    mean: float
    rms_about_zero: float
    max_abs: float


def absolute_figures(x: npt.ArrayLike, reference: float = 0.0) -> AbsoluteFigures:
    r""":class:`AbsoluteFigures` of the samples ``x`` about ``reference`` (same unit).

    Parameters
    ----------
    x : array_like
        The output samples [any unit].
    reference : float, optional
        The level K an ideal sensor would output [unit of x]; default 0.

    Returns
    -------
    AbsoluteFigures
        Mean, rms about K and largest |x − K| [unit of x]; NaN for no sample.

    Notes
    -----
    .. math:: \mathrm{rms}_0 = \sqrt{\frac{1}{n}\sum_i (x_i - K)^2}
              = \sqrt{\sigma^2 + \bar e^{\,2}}

    Examples
    --------
    >>> from thermocal.compensate.kernels import absolute_figures
    >>> f = absolute_figures([1.0, -1.0, 3.0], reference=1.0)
    >>> round(f.mean, 3), round(f.rms_about_zero, 3), f.max_abs
    (0.0, 1.633, 2.0)
    """
    e = np.asarray(x, dtype=np.float64) - float(reference)
    if e.size == 0:
        return AbsoluteFigures(float("nan"), float("nan"), float("nan"))
    return AbsoluteFigures(
        float(np.mean(e)), float(np.sqrt(np.mean(e * e))), float(np.max(np.abs(e)))
    )


def absolute_error_worse(
    before: AbsoluteFigures, after: AbsoluteFigures, tolerance: float = ABSOLUTE_WORSE_TOLERANCE
) -> list[str]:
    r"""The absolute figures the compensation made worse: ``"rms about zero"`` when
    ``after > (1 + tolerance) · before``; ``"max |error|"`` likewise, counted only when the
    rms about zero did not improve as well (a larger single extreme while the rms about
    zero falls is a noise sample, not a worse output); empty when none.

    Parameters
    ----------
    before, after : AbsoluteFigures
        Figures of the raw and of the compensated output [same unit].
    tolerance : float, optional
        Allowed relative increase [fraction]; default
        :data:`ABSOLUTE_WORSE_TOLERANCE` (0.01).

    Returns
    -------
    list of str
        ``"rms about zero"`` and/or ``"max |error|"``; empty when neither is worse.

    Notes
    -----
    .. math:: \mathrm{rms}_0^{\mathrm{after}} > (1 + \mathrm{tol})\,
              \mathrm{rms}_0^{\mathrm{before}}
    """
    out = []
    b, a = before.rms_about_zero, after.rms_about_zero
    finite = math.isfinite(a) and math.isfinite(b)
    if finite and a > (1.0 + tolerance) * b:
        out.append("rms about zero")
    bm, am = before.max_abs, after.max_abs
    if (
        finite
        and a >= b
        and math.isfinite(am)
        and math.isfinite(bm)
        and am > (1.0 + tolerance) * bm
    ):
        out.append("max |error|")
    return out


def absolute_worse_message(
    where: str,
    unit: str,
    before: AbsoluteFigures,
    after: AbsoluteFigures,
    worse: Sequence[str],
    cause: str = "",
) -> str:
    """The ``warning:`` text for a compensation that makes the absolute error worse.

    Parameters
    ----------
    where : str
        The file or channel named first.
    unit : str
        Unit of the figures.
    before, after : AbsoluteFigures
        Figures of the raw and of the compensated output [unit].
    worse : sequence of str
        What got worse (:func:`absolute_error_worse`).
    cause : str, optional
        The known reason; default: a model that does not describe this sensor here.

    Returns
    -------
    str
        One line: the figures before → after and the cause.
    """
    pct = (
        100.0 * (after.rms_about_zero - before.rms_about_zero) / before.rms_about_zero
        if before.rms_about_zero > 0
        else float("nan")
    )
    return (
        f"{where}: the compensation makes the absolute error worse ({', '.join(worse)}): "
        f"mean {before.mean:.4g} → {after.mean:.4g} {unit}, rms about zero "
        f"{before.rms_about_zero:.4g} → {after.rms_about_zero:.4g} {unit} ({pct:+.3g} %), "
        f"max |error| {before.max_abs:.4g} → {after.max_abs:.4g} {unit}; "
        + (cause or "the model does not describe this sensor at these conditions (another "
           "power-on, temperature or sensor?)")
    )  # fmt: skip


KEPT_IN_BIAS: Final = "the model was fitted without removing the earth rate"
"""Words of :func:`zero_reference` that :func:`absolute_worse_message` gives as the cause."""


def _kept_in_bias(model: TemperatureModel, latitude_deg: float, axis: str) -> str:
    """The words for a model fitted without removing a known input (its file records
    ``known_input.what == "none"``) compared with the earth rate: it holds that rate in its
    bias, and the fit option that removes it."""
    rec = ((getattr(model, "inputs_", {}) or {}).get("known_input")) or {}
    if not (isinstance(rec, dict) and rec.get("what") == "none"):
        return ""
    return (
        f"; {KEPT_IN_BIAS} (thermocal fit --latitude {latitude_deg:g} --axis {axis}), so its "
        "compensation takes that rate off as bias"
    )  # cli-words: the command that refits the model


def zero_reference(
    model: TemperatureModel, meta: Metadata | None, known_input: float = 0.0
) -> tuple[float, str]:
    r"""The level an ideal sensor would output on this run [model unit] and what it is: the
    "zero" of the absolute figures (:class:`AbsoluteFigures`).

    In order: ``known_input`` when given (non-zero); for a gyro, the earth rate on the
    sensitive axis when the data's metadata give latitude and axis (IEEE Std 952-1997,
    :func:`thermocal.units.earth_rate_on_axis_deg_h`); the known input the model file
    recorded of its fit (``inputs.known_input``, assumed the same on this run); else 0.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model (its signal unit and the known input of its fit).
    meta : Metadata or None
        The data's metadata (latitude [°] and sensitive axis).
    known_input : float, optional
        The known input given by the user [model unit]; default 0 (none).

    Returns
    -------
    tuple of (float, str)
        The reference level [model unit] and the words saying where it comes from.

    Notes
    -----
    The earth rate on an axis at latitude φ, with Ω = 15.041 °/h:

    .. math:: \Omega_{\mathrm{axis}} = \Omega\,\mathbf{u}\cdot(0, \cos\varphi, \sin\varphi)

    with **u** the unit sensitive axis in local East-North-Up.

    References
    ----------
    - IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure
      for Single-Axis Interferometric Fiber Optic Gyros* (earth-rate input).
    """
    if known_input:
        given = "the known input given (--known-input)"
        return float(known_input), given  # cli-words: the words validate's reports record
    mu = units.normalize_signal_unit(model.signal_unit)
    if (
        meta is not None
        and meta.latitude_deg is not None
        and meta.axis is not None
        and units.signal_kind(mu) == units.signal_kind("deg/h")
    ):
        w = units.earth_rate_on_axis_deg_h(meta.latitude_deg, units.parse_axis(meta.axis))
        return float(units.convert(w, "deg/h", mu)), (
            f"the earth rate on axis {meta.axis} at latitude {meta.latitude_deg:g}° (file metadata)"
            + _kept_in_bias(model, meta.latitude_deg, meta.axis)
        )
    rec = ((getattr(model, "inputs_", {}) or {}).get("known_input")) or {}
    val = rec.get("value") if isinstance(rec, dict) else None
    if isinstance(val, int | float) and val and rec.get("unit") in (None, mu):
        return float(val), (
            f"the known input the model was fitted with ({rec.get('what') or 'given'}), "
            "assumed the same on this run"
        )
    return 0.0, "no known input given, in the file's metadata or in the model file: zero is 0"


# --- streaming -----------------------------------------------------------------------------


class StreamingCompensator:
    """Compensate live data sample by sample: ``F'_i = F_i − ŷ_i``.

    Wraps ``model.stream(sample_interval_s)`` (the family's
    :class:`~thermocal.models.base.ModelStream`): the rate buffer of length Δt,
    T0/F0 captured at power-on and any start-up selection live there; a step
    longer than ``GAP_FACTOR`` × ``sample_interval_s`` resets the rate estimate.
    Time must increase strictly (a :class:`~thermocal.errors.TimestampError`
    otherwise).  Signals and results are in the model's signal unit.  ``known_input``
    (earth rate [°/h], gravity component [mg]) is removed from the signal the model
    sees (as :meth:`RunData.target` does; it matters to the bank's start-up
    selection) but not from the corrected output.

    The outputs equal :func:`compensate_run` to 1e-12 (relative) on the same data,
    start-up included, when ``sample_interval_s`` is the run's median interval.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.
    sample_interval_s : float
        Nominal sample interval [s] (positive, finite).
    extrapolate : bool, optional
        Passed to the family's stream; default ``False``.
    known_input : float, optional
        The true input (earth rate [°/h], gravity component [mg]) [model unit];
        default 0.

    Raises
    ------
    ThermocalInputError
        ``sample_interval_s`` not positive and finite; mixing :meth:`update` and
        :meth:`update_block` between resets.
    TimestampError
        Time that does not increase strictly.

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.poly import PolyModel
    >>> from thermocal.compensate.kernels import StreamingCompensator
    >>> t = np.arange(0.0, 3600.0, 10.0)
    >>> temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / 3600.0)
    >>> model = PolyModel(order=1).fit([RunData(t, temp[:, None], 0.5 + 0.02 * temp, ("T1",))])
    >>> comp = StreamingCompensator(model, 10.0)
    >>> round(comp.update(0.0, [30.0], 1.2), 6)
    0.1

    Two ways to feed it (not to be mixed between two resets):

    * :meth:`update` / :meth:`process` — one sample at a time through the family's
      ``ModelStream`` (the firmware twin; speed set by the family's stream);
    * :meth:`update_block` — a block of samples at once (live data often arrives in
      packets): the block is predicted in one vectorised call together with the
      context the model needs (:class:`ChunkPredictor`), which gives the same values
      because ``predict`` is causal; much faster for blocks of tens of samples or more.
    """

    def __init__(
        self,
        model: TemperatureModel,
        sample_interval_s: float,
        *,
        extrapolate: bool = False,
        known_input: float = 0.0,
    ) -> None:
        if not (math.isfinite(sample_interval_s) and sample_interval_s > 0):
            raise ThermocalInputError(
                f"sample interval must be positive and finite, got {sample_interval_s!r}"
            )
        model.check_fitted()
        self.model = model
        self.sample_interval_s = float(sample_interval_s)
        self.extrapolate = extrapolate
        self.known_input = float(known_input)
        self._stream: ModelStream = model.stream(self.sample_interval_s, extrapolate=extrapolate)
        self._last_t: float | None = None
        self._mode: str | None = None
        self._chunks: ChunkPredictor | None = None
        self._warned = False
        self.last_model_value: float = float("nan")
        """ŷ of the last sample [model signal unit]."""
        self.n_samples = 0

    def _set_mode(self, mode: str) -> None:
        if self._mode is not None and self._mode != mode:
            raise ThermocalInputError(
                "StreamingCompensator: do not mix update() and update_block() between resets"
            )
        self._mode = mode

    def update(self, time_s: float, temps_c: npt.ArrayLike, signal: float) -> float:
        """Corrected output ``F − ŷ`` of one sample.

        Parameters
        ----------
        time_s : float
            Time [s], strictly after the previous sample's.
        temps_c : array_like
            Temperatures (k,) [°C, or counts for a counts model].
        signal : float
            Raw signal F [model unit].

        Returns
        -------
        float
            ``F − ŷ`` [model unit].

        Raises
        ------
        TimestampError
            Time not after the previous sample's.
        """
        t = float(time_s)
        if self._last_t is not None and not t > self._last_t:
            raise TimestampError(
                f"sample {self.n_samples}: time {t!r} does not increase (previous {self._last_t!r})"
            )
        if self._mode != "sample":
            self._set_mode("sample")
        temps = np.asarray(temps_c, dtype=np.float64).reshape(-1)
        y = float(self._stream.update(t, temps, float(signal) - self.known_input))
        self._last_t = t
        self.last_model_value = y
        self.n_samples += 1
        return float(signal) - y

    def reset(self) -> None:
        """A new power-on: forget every state."""
        self._stream.reset()
        self._last_t = None
        self._mode = None
        self._chunks = None
        self._warned = False
        self.last_model_value = float("nan")
        self.n_samples = 0

    @property
    def outside_range(self) -> tuple[RangeExcess, ...]:
        """How far the blocks fed since the last reset (:meth:`update_block`) leave the
        model's calibrated ranges: share of samples and distance per input (empty before
        any block; :meth:`update` relies on the family stream's own one warning)."""
        return self._chunks.outside_range if self._chunks is not None else ()

    def update_block(
        self, time_s: npt.ArrayLike, temps_c: npt.ArrayLike, signal: npt.ArrayLike
    ) -> Compensation:
        """Compensate a block of consecutive samples at once (vectorised); state carried
        on to the next block.  Same values as :meth:`process` (see the class docstring);
        one :class:`ExtrapolationWarning` per stream, at the first block with samples outside
        a calibrated range (temperature, Ṫ, time since power-on; :attr:`outside_range`
        gives the share and distance over every block fed since).

        Parameters
        ----------
        time_s : array_like
            Times (n,) [s], strictly increasing and after the previous block's.
        temps_c : array_like
            Temperatures (n,) or (n, k) [°C].
        signal : array_like
            Raw signal (n,) [model unit].

        Returns
        -------
        Compensation
            ŷ and ``F − ŷ`` (n,) [model unit].

        Raises
        ------
        ThermocalInputError
            Arrays of different lengths; mixing with :meth:`update` before a reset.
        TimestampError
            Time that does not increase.
        """
        t = np.asarray(time_s, dtype=np.float64).reshape(-1)
        T = np.asarray(temps_c, dtype=np.float64)
        if T.ndim == 1:
            T = T.reshape(-1, 1)
        f = np.asarray(signal, dtype=np.float64).reshape(-1)
        if T.shape[0] != t.size or f.size != t.size:
            raise ThermocalInputError("time, temperatures and signal differ in length")
        if t.size == 0:
            return Compensation(np.zeros(0), np.zeros(0))
        bad = np.flatnonzero(np.diff(t) <= 0)
        if (self._last_t is not None and not t[0] > self._last_t) or bad.size:
            i = 0 if bad.size == 0 else int(bad[0]) + 1
            raise TimestampError(f"sample {self.n_samples + i}: time does not increase")
        self._set_mode("block")
        if self._chunks is None:
            self._chunks = ChunkPredictor(
                self.model,
                extrapolate=self.extrapolate,
                known_input=self.known_input,
                sample_interval_s=self.sample_interval_s,
            )
        y = self._chunks.predict(t, T, f)
        if not self._warned and any(e.n_outside for e in self._chunks.outside_range):
            self._warned = True  # once per stream: outside_range gives the figures later
            self._chunks.warn_outside()
        self._last_t = float(t[-1])
        self.last_model_value = float(y[-1])
        self.n_samples += int(t.size)
        return Compensation(model_value=y, corrected=f - y)

    def process(
        self, time_s: npt.ArrayLike, temps_c: npt.ArrayLike, signal: npt.ArrayLike
    ) -> Compensation:
        """Feed arrays sample by sample (state carried on from earlier calls).

        Parameters
        ----------
        time_s : array_like
            Times (n,) [s], strictly increasing.
        temps_c : array_like
            Temperatures (n,) or (n, k) [°C].
        signal : array_like
            Raw signal (n,) [model unit].

        Returns
        -------
        Compensation
            ŷ and ``F − ŷ`` (n,) [model unit].
        """
        t = np.asarray(time_s, dtype=np.float64)
        T = np.asarray(temps_c, dtype=np.float64)
        if T.ndim == 1:
            T = T.reshape(-1, 1)
        f = np.asarray(signal, dtype=np.float64)
        y = np.empty_like(t)
        c = np.empty_like(t)
        for i in range(t.size):
            c[i] = self.update(float(t[i]), T[i], float(f[i]))
            y[i] = self.last_model_value
        return Compensation(model_value=y, corrected=c)


class CalibrationStream:
    """Compensate every channel of a calibration sample by sample (live data).

    One :class:`StreamingCompensator` per channel (each keeps its own rate buffer and
    power-on state), fed from one sample of the whole IMU: the time [s], the
    temperatures of :attr:`temperature_names` (the union of every channel's inputs, in
    first-seen order, °C) and the raw outputs of :attr:`names`, each in its channel's
    data unit (:attr:`units`, the unit the calibration recorded; converted to the model's
    unit and back, ``value[model] = factor · value[data]``).  Returns the corrected
    outputs ``F − ŷ`` in the same units.  Equal to :func:`compensate_channels` on the
    same samples (tested to 1e-9 relative).

    Parameters
    ----------
    channels : Calibration or iterable of (str, TemperatureModel, str)
        A :class:`~thermocal.models.calibration.Calibration` or ``(name, model, data
        unit)`` triples.
    sample_interval_s : float
        Nominal sample interval [s].
    extrapolate : bool, optional
        Passed to every channel's stream; default ``False``.

    Raises
    ------
    ThermocalInputError
        No channel.
    UnitError
        A channel's data unit of another kind than its model's.
    """

    def __init__(
        self,
        channels: Any,
        sample_interval_s: float,
        *,
        extrapolate: bool = False,
    ) -> None:
        from thermocal.models.calibration import Calibration

        triples = (
            [(c.name, c.model, c.unit) for c in channels.channels]
            if isinstance(channels, Calibration)
            else [(str(n), m, str(u)) for n, m, u in channels]
        )
        if not triples:
            raise ThermocalInputError("CalibrationStream: no channel")
        self.names = tuple(n for n, _m, _u in triples)
        self.units = tuple(u for _n, _m, u in triples)
        temps: list[str] = []
        for _n, m, _u in triples:
            temps.extend(str(t) for t in m.temp_names_ if str(t) not in temps)
        self.temperature_names = tuple(temps)
        self._cols = [
            np.array([temps.index(str(t)) for t in m.temp_names_], dtype=np.intp)
            for _n, m, _u in triples
        ]
        self._factors = np.array(
            [unit_factor(u, m.signal_unit, where=f"channel {n}") for n, m, u in triples]
        )
        self._comps = [
            StreamingCompensator(m, sample_interval_s, extrapolate=extrapolate)
            for _n, m, _u in triples
        ]

    def _temps(self, temps_c: Any) -> FloatArray:
        if isinstance(temps_c, Mapping):
            missing = [t for t in self.temperature_names if t not in temps_c]
            if missing:
                raise ThermocalInputError(f"no value for temperature input(s) {missing}")
            return np.array([float(temps_c[t]) for t in self.temperature_names])
        arr = np.asarray(temps_c, dtype=np.float64)
        if arr.shape[-1] != len(self.temperature_names):
            raise ThermocalInputError(
                f"expected {len(self.temperature_names)} temperatures "
                f"({', '.join(self.temperature_names)}), got {arr.shape[-1]}"
            )
        return arr

    def _raw(self, raw: npt.ArrayLike) -> FloatArray:
        arr = np.asarray(raw, dtype=np.float64)
        if arr.shape[-1] != len(self.names):
            raise ThermocalInputError(
                f"expected {len(self.names)} raw values ({', '.join(self.names)}), "
                f"got {arr.shape[-1]}"
            )
        return arr

    def update(self, time_s: float, temps_c: Any, raw: npt.ArrayLike) -> FloatArray:
        """Corrected outputs (N,) of one sample [each channel's data unit].

        Parameters
        ----------
        time_s : float
            Time [s], strictly increasing.
        temps_c : array_like or mapping of str to float
            (k,) temperatures [°C] in :attr:`temperature_names` order, or a mapping
            name → °C.
        raw : array_like
            (N,) raw outputs in :attr:`names` order [each channel's data unit].

        Returns
        -------
        numpy.ndarray
            (N,) corrected outputs ``F − ŷ`` [each channel's data unit].

        Raises
        ------
        ThermocalInputError
            A temperature missing or the wrong number of values.
        """
        T = self._temps(temps_c)
        f = self._raw(raw)
        out = np.empty(len(self.names))
        for i, comp in enumerate(self._comps):
            k = self._factors[i]
            out[i] = comp.update(time_s, T[self._cols[i]], float(f[i]) * k) / k
        return out

    def update_block(
        self, time_s: npt.ArrayLike, temps_c: npt.ArrayLike, raw: npt.ArrayLike
    ) -> tuple[FloatArray, FloatArray]:
        """Compensate a block of samples of every channel.

        Parameters
        ----------
        time_s : array_like
            Times (n,) [s], strictly increasing.
        temps_c : array_like
            (n, k) temperatures [°C] in :attr:`temperature_names` order.
        raw : array_like
            (n, N) raw outputs [each channel's data unit].

        Returns
        -------
        tuple of numpy.ndarray
            (model values ŷ, corrected outputs ``F − ŷ``), both (n, N) in each
            channel's data unit.
        """
        t = np.asarray(time_s, dtype=np.float64).reshape(-1)
        T = self._temps(np.asarray(temps_c, dtype=np.float64).reshape(t.size, -1))
        f = self._raw(np.asarray(raw, dtype=np.float64).reshape(t.size, -1))
        model = np.empty((t.size, len(self.names)))
        for i, comp in enumerate(self._comps):
            k = self._factors[i]
            res = comp.update_block(t, T[:, self._cols[i]], f[:, i] * k)
            model[:, i] = res.model_value / k
        return model, f - model

    def reset(self) -> None:
        """A new power-on of the IMU: every channel forgets its state."""
        for comp in self._comps:
            comp.reset()


# --- chunk context rules ---------------------------------------------------------------------


def chunk_context(model: TemperatureModel) -> ChunkContext:
    """The :class:`ChunkContext` the model's family declares.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model (:meth:`TemperatureModel.chunk_context`).

    Returns
    -------
    ChunkContext
        Head and tail spans [s]; ``None`` fields (an infinite head included): stream
        sample by sample instead.
    """
    ctx = model.chunk_context()
    if ctx.head_s is not None and not math.isfinite(ctx.head_s):
        return ChunkContext(head_s=None, tail_s=ctx.tail_s)
    return ctx


class ChunkPredictor:
    """Predict a long run chunk by chunk with the context carried across chunks.

    For chunk ``c`` the model sees ``head ∪ tail ∪ c``: ``head`` = the samples in the
    first ``head_s`` seconds of the run, ``tail`` = the samples of the previous
    chunks within ``tail_s`` (plus a margin of a few sample intervals) before the
    chunk.  When head and tail meet they are one contiguous stretch; otherwise
    the jump in time between them is a gap, which the model treats like any gap.
    Families without a finite context are streamed sample by sample.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.
    extrapolate : bool, optional
        Passed to ``predict``; default ``False``.
    name : str, optional
        Name of the data in the warning; default ``""`` (``"data"``).
    known_input : float, optional
        The true input [model unit]; default 0.
    sample_interval_s : float, optional
        Sample interval [s]; default the first chunk's median interval.
    """

    MARGIN_SAMPLES = 4

    def __init__(
        self,
        model: TemperatureModel,
        *,
        extrapolate: bool = False,
        name: str = "",
        known_input: float = 0.0,
        sample_interval_s: float | None = None,
    ) -> None:
        self.model = model
        self.known_input = float(known_input)
        self.extrapolate = extrapolate
        self.name = name
        self.context = chunk_context(model)
        self._rows_seen = 0
        self._head_t: FloatArray = np.zeros(0)
        self._head_T: FloatArray = np.zeros((0, 0))
        self._head_f: FloatArray = np.zeros(0)
        self._head_done = False
        self._tail_t: FloatArray = np.zeros(0)
        self._tail_T: FloatArray = np.zeros((0, 0))
        self._tail_f: FloatArray = np.zeros(0)
        self._stream: StreamingCompensator | None = None
        self._tau: float | None = sample_interval_s
        self.n_outside = 0
        """Samples outside the model's fitted temperature range."""
        self.tally = RangeTally(model)
        """How far the rows seen leave the calibrated ranges (one summary warning)."""

    @property
    def streams(self) -> bool:
        """Whether the model is streamed sample by sample (no finite context)."""
        return self.context.head_s is None or self.context.tail_s is None

    def predict(self, time_s: FloatArray, temps_c: FloatArray, signal: FloatArray) -> FloatArray:
        """ŷ for the next chunk of rows (in order).

        Parameters
        ----------
        time_s : numpy.ndarray
            Times (n,) [s], after the previous chunk's.
        temps_c : numpy.ndarray
            Temperatures (n, k) [°C].
        signal : numpy.ndarray
            Raw signal (n,) [model unit].

        Returns
        -------
        numpy.ndarray
            ŷ (n,) [model unit], equal to a whole-run ``predict`` on these rows.
        """
        n = time_s.size
        if n == 0:
            return np.zeros(0)
        if self._tau is None:
            tau = median_interval(time_s) if n > 1 else float("nan")
            self._tau = tau if math.isfinite(tau) and tau > 0 else 1.0
        return self.predict_with(time_s, temps_c, signal, [])[0]

    def predict_with(
        self,
        time_s: FloatArray,
        temps_c: FloatArray,
        signal: FloatArray,
        followers: Sequence[ChunkPredictor],
    ) -> list[FloatArray]:
        """ŷ of this predictor's model and of each follower's (several channels whose
        ``poly`` models share one evaluation, :func:`thermocal.models.poly_eval.predict_many`):
        the context is carried once, here; the followers' counts follow.

        Parameters
        ----------
        time_s : numpy.ndarray
            Times (n,) [s].
        temps_c : numpy.ndarray
            Temperatures (n, k) [°C].
        signal : numpy.ndarray
            Raw signal (n,) [model unit].
        followers : sequence of ChunkPredictor
            Predictors whose models are evaluated together with this one.

        Returns
        -------
        list of numpy.ndarray
            ŷ (n,) of this model then of each follower [each model's unit].
        """
        n = time_s.size
        if n == 0:
            return [np.zeros(0) for _ in range(1 + len(followers))]
        if self._tau is None:
            tau = median_interval(time_s) if n > 1 else float("nan")
            self._tau = tau if math.isfinite(tau) and tau > 0 else 1.0
        lo, hi = self.model.temp_range_[:, 0], self.model.temp_range_[:, 1]
        outside = int(np.count_nonzero(((temps_c < lo) | (temps_c > hi)).any(axis=1)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ExtrapolationWarning)
            if self.streams:
                ys = [self._predict_stream(time_s, temps_c, signal)]
            else:
                ys = self._predict_context(
                    time_s, temps_c, signal, [self.model, *(f.model for f in followers)]
                )
        self.tally.add(time_s, temps_c)
        for p in (self, *followers):
            p.n_outside += outside
            p._rows_seen += n
            p.tally = self.tally  # one evaluation key: the same ranges, counted once
        return ys

    def _predict_stream(
        self, time_s: FloatArray, temps_c: FloatArray, signal: FloatArray
    ) -> FloatArray:
        if self._stream is None:
            assert self._tau is not None
            self._stream = StreamingCompensator(
                self.model, self._tau, extrapolate=self.extrapolate, known_input=self.known_input
            )
        return self._stream.process(time_s, temps_c, signal).model_value

    def _predict_context(
        self,
        time_s: FloatArray,
        temps_c: FloatArray,
        signal: FloatArray,
        models: Sequence[TemperatureModel],
    ) -> list[FloatArray]:
        assert self.context.head_s is not None
        assert self.context.tail_s is not None
        assert self._tau is not None
        k = temps_c.shape[1]
        if self._head_T.shape[1] != k:
            self._head_T = np.zeros((0, k))
            self._tail_T = np.zeros((0, k))
        # context rows: head (only those not also in the tail) then tail
        t0 = self._head_t[0] if self._head_t.size else time_s[0]
        if self._tail_t.size and self._head_t.size:
            keep_head = self._head_t < self._tail_t[0]
        else:
            keep_head = np.ones(self._head_t.size, dtype=bool)
        ct = np.concatenate([self._head_t[keep_head], self._tail_t, time_s])
        cT = np.concatenate([self._head_T[keep_head], self._tail_T, temps_c])
        cf = np.concatenate([self._head_f[keep_head], self._tail_f, signal])
        m = ct.size - time_s.size
        run = RunData(
            time_s=ct,
            temps_c=cT,
            signal=cf,
            temp_names=tuple(self.model.temp_names_),
            name=self.name,
            known_input=self.known_input,
        )
        if len(models) == 1:
            y_alls = [np.asarray(self.model.predict(run, extrapolate=self.extrapolate))]
        else:
            from thermocal.models.poly import PolyModel
            from thermocal.models.poly_eval import predict_many

            y_alls = predict_many(
                [cast(PolyModel, mdl) for mdl in models], run, extrapolate=self.extrapolate
            )
        ys = [np.asarray(y_all[m:], dtype=np.float64).copy() for y_all in y_alls]
        # carry the context on
        if not self._head_done:
            head_s = self.context.head_s + self.MARGIN_SAMPLES * GAP_FACTOR * self._tau
            in_head = time_s - t0 <= head_s
            self._head_t = np.concatenate([self._head_t, time_s[in_head]])
            self._head_T = np.concatenate([self._head_T, temps_c[in_head]])
            self._head_f = np.concatenate([self._head_f, signal[in_head]])
            self._head_done = not bool(in_head.all())
        span = self.context.tail_s + self.MARGIN_SAMPLES * GAP_FACTOR * self._tau
        start = int(np.searchsorted(ct, ct[-1] - span, side="left"))
        start = max(0, min(start, ct.size - self.MARGIN_SAMPLES))
        self._tail_t = ct[start:].copy()
        self._tail_T = cT[start:].copy()
        self._tail_f = cf[start:].copy()
        return ys

    def finish(self) -> None:
        """Issue one :class:`ExtrapolationWarning` for the whole file when samples left the
        calibrated ranges (temperature, Ṫ, time since power-on), saying for what share of
        the samples and how far (:func:`~thermocal.models.ranges.outside_range_message`)."""
        self.warn_outside()

    @property
    def outside_range(self) -> tuple[RangeExcess, ...]:
        """How far the rows predicted so far leave the calibrated ranges."""
        return self.tally.result()

    def warn_outside(self) -> None:
        """One :class:`ExtrapolationWarning` for the rows so far, if any left a range."""
        msg = outside_range_message(
            self.tally.result(), self.name or "data", extrapolate=self.extrapolate
        )
        if msg:
            warnings.warn(msg, ExtrapolationWarning, stacklevel=3)


__all__ = [
    "ABSOLUTE_WORSE_TOLERANCE",
    "KEPT_IN_BIAS",
    "AbsoluteFigures",
    "CalibrationStream",
    "ChunkContext",
    "ChunkPredictor",
    "Compensation",
    "ModelRun",
    "StreamingCompensator",
    "absolute_error_worse",
    "absolute_figures",
    "absolute_worse_message",
    "check_signal_kind",
    "chunk_context",
    "compensate_run",
    "model_scale_factor",
    "prepare_run",
    "temperature_inputs",
    "unit_factor",
    "zero_reference",
]
