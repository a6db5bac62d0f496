"""The numbers of a report: a model applied to a run (bias before, model,
after, each in the data's unit), figures of merit and Allan deviation with noise terms.

Pure: no files, no plotting (:mod:`thermocal.report.build` renders them)."""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal import units
from thermocal.compensate.kernels import unit_factor
from thermocal.metrics import (
    RATE_ANGLE_UNITS,
    DriftReference,
    compute_metrics,
    drift_angle,
    drift_angle_extreme,
)
from thermocal.models.registry import model_from_dict
from thermocal.models.rundata import RunData
from thermocal.pipeline.messages import warning_text
from thermocal.recording import FloatArray, Metadata, Recording
from thermocal.stability.allan import (
    AllanResult,
    NoiseTerms,
    annotate_periodic,
    noise_terms,
    overlapping_adev,
)
from thermocal.stability.periodic import periodic_terms

ILL_CONDITIONED = 1.0e6
"""Condition number (scaled design) above which the report warns: ill-conditioned in the
words of :func:`thermocal.models.results.condition_wording`."""


# --- analysis of the runs --------------------------------------------------------------------


@dataclass(frozen=True)
class RunSignals:
    """The bias of a run before and after compensation by one model [signal unit].

    Attributes
    ----------
    time_s : numpy.ndarray
        Time [s].
    signal : numpy.ndarray
        The recorded signal [unit].
    unit : str
        Its unit.
    before : numpy.ndarray
        The bias before compensation (signal less the known input) [unit].
    model : numpy.ndarray
        The model's prediction [unit].
    after : numpy.ndarray
        The bias after compensation [unit].
    temps_c : numpy.ndarray
        The model's temperature inputs [°C], one column each.
    temp_names : tuple of str
        Their names.
    known_input : float
        The known input removed (earth rate, gravity) [unit].
    warnings : tuple of str
        Warnings of the compensation.
    model_includes_known_input : bool
        The model's prediction holds the known input (it was fitted with it).
    """

    time_s: FloatArray
    signal: FloatArray
    unit: str
    before: FloatArray
    model: FloatArray
    after: FloatArray
    temps_c: FloatArray
    temp_names: tuple[str, ...]
    known_input: float
    warnings: tuple[str, ...]
    model_includes_known_input: bool = False

    @property
    def model_bias(self) -> FloatArray:
        """The model value on the bias scale (known input taken off if the model holds it)."""
        if self.model_includes_known_input:
            out: FloatArray = self.model - self.known_input
            return out
        return self.model

    @property
    def after_raw(self) -> FloatArray:
        """Compensated output with the known input kept (what the sensor would output)."""
        out: FloatArray = self.after + self.known_input
        return out


def in_data_unit(sig: RunSignals, unit: str, k: float) -> RunSignals:
    """``sig`` (canonical unit) in the data's own ``unit``: every series and the known input
    divided by ``k`` (``value[canonical] = k · value[data]``).

    Parameters
    ----------
    sig : RunSignals
        The model applied to a run.
    unit : str
        The data's unit (``"deg/h"``, ``"mg"``).
    k : float
        Factor from the model's unit to the data's.

    Returns
    -------
    RunSignals
        The same signals times ``k``, labelled ``unit``.
    """
    if k == 1.0 and unit == sig.unit:
        return sig
    return dataclasses.replace(
        sig,
        unit=unit,
        signal=sig.signal / k,
        before=sig.before / k,
        model=sig.model / k,
        after=sig.after / k,
        known_input=sig.known_input / k,
    )


def known_input_of(rec: Recording, unit: str) -> float:
    """Earth rate seen by the sensitive axis [°/h] when the metadata gives latitude and
    axis (B0 = mean − Ω_axis, IEEE Std 952-1997), else 0 (accelerometers: 0).

    Parameters
    ----------
    rec : Recording
        The recording.
    unit : str
        The data's unit (``"deg/h"``, ``"mg"``).

    Returns
    -------
    float
        Ω sin(latitude) for an up axis, Ω cos(latitude) for north, 0 for east [°/h]; 0 when unknown.

    References
    ----------
    IEEE Std 952-1997, Annex C (the earth rate seen by the sensitive axis).
    """
    if unit != "deg/h" or rec.meta.latitude_deg is None or rec.meta.axis is None:
        return 0.0
    return float(
        units.earth_rate_on_axis_deg_h(rec.meta.latitude_deg, units.parse_axis(rec.meta.axis))
    )


def apply_model(model_dict: dict[str, Any], rec: Recording, signal: str | None) -> RunSignals:
    """Apply a model (file content) to a recording: bias before, model value, bias after.

    ``after = before − model(T, Ṫ)``; the model is evaluated on the fitted range
    (clamped, as in compensation); :class:`~thermocal.errors.ExtrapolationWarning`
    messages are collected, not raised.

    Parameters
    ----------
    model_dict : dict
        The content of a model file.
    rec : Recording
        The recording.
    signal : str, optional
        The signal column (default: the model's).

    Returns
    -------
    RunSignals
        Bias before, model, bias after, each in the data's unit.

    Raises
    ------
    ThermocalInputError
        The recording lacks a column the model needs.
    """
    model = model_from_dict(model_dict)
    sig_name = signal or (model_dict.get("signal") or {}).get("name")
    if sig_name not in rec.columns:
        sig_name = None if not rec.signals else rec.signals[0]
    temp_names = tuple(model_dict["temperatures"])
    x, unit = rec.signal(sig_name)
    factor = unit_factor(unit, model.signal_unit, meta=rec.meta, where=rec.name)
    known = known_input_of(rec, unit)
    run = RunData.from_recording(rec, sig_name, temp_names, known_input=known)
    run = dataclasses.replace(run, signal=x * factor, known_input=known * factor)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pred = np.asarray(model.predict(run), dtype=np.float64) / factor
    msgs = tuple(dict.fromkeys(warning_text(w.message) for w in caught))
    before = x - known
    # A model fitted on the raw output (known input not removed) carries the earth
    # rate in its constant.  The fit's provenance says what was removed (``thermocal fit``
    # records ``known_input`` per file); without it, tell by which level the model's mean
    # is nearer (|Ω| ≫ bias changes).
    fitted = [d.get("known_input") for d in model_dict.get("data", []) if isinstance(d, dict)]
    if known == 0.0:
        includes = False
    elif fitted and all(isinstance(k, int | float) for k in fitted):
        includes = all(float(k) == 0.0 for k in fitted)  # type: ignore[arg-type]
    else:
        includes = bool(abs(np.mean(pred) - np.mean(x)) < abs(np.mean(pred) - np.mean(before)))
    after = x - pred if includes else before - pred
    return RunSignals(
        time_s=rec.time_s,
        signal=x,
        unit=unit,
        before=before,
        model=pred,
        after=after,
        temps_c=run.temps_c,
        temp_names=temp_names,
        known_input=known,
        warnings=msgs,
        model_includes_known_input=includes,
    )


@dataclass(frozen=True)
class FiguresOfMerit:
    """The figures of merit of a whole run [signal unit], from
    :func:`thermocal.metrics.compute_metrics` (the numbers of ``thermocal metrics``):
    bias B0 (earth rate removed when latitude and axis are known), bias stability
    and peak-to-peak over ``averaging_s`` averages, temperature sensitivity over
    the hold stages (least-squares slope and mean |ΔB/ΔT|) [unit/°C], and the drift
    angle θ(t) = ∫ (ω − Ω − b0) dt [``drift_angle_unit``] (gyros), b0 the constant of
    ``drift_reference``: its curve, end value, largest magnitude and when it is reached
    [s since the first sample]; and the largest |θ| with no bias removed (b0 = 0).

    Attributes
    ----------
    bias : float
        Bias B0 [unit].
    bias_stability : float
        Standard deviation of the ``averaging_s`` averages [unit].
    averaging_s : float
        Averaging time [s].
    peak_to_peak : float
        Peak-to-peak of the averages [unit].
    sensitivity_slope, sensitivity_mean_abs : float or None
        Temperature sensitivity over the hold stages [unit/°C] (None: fewer than two stages).
    drift_angle : numpy.ndarray or None
        θ(t) [``drift_angle_unit``] (gyros; None otherwise).
    drift_angle_end, drift_angle_max : float or None
        θ at the end, and its largest magnitude [``drift_angle_unit``].
    drift_angle_max_time_s : float or None
        When the largest |θ| is reached [s since the first sample].
    drift_angle_unit : str or None
        Unit of the drift angle.
    drift_reference : DriftReference or None
        How b0 was taken.
    drift_angle_raw_max : float or None
        The largest |θ| with no bias removed [``drift_angle_unit``].
    """

    bias: float
    bias_stability: float
    averaging_s: float
    peak_to_peak: float
    sensitivity_slope: float | None
    sensitivity_mean_abs: float | None
    drift_angle: FloatArray | None
    drift_angle_end: float | None = None
    drift_angle_max: float | None = None
    drift_angle_max_time_s: float | None = None
    drift_angle_unit: str | None = None
    drift_reference: DriftReference | None = None
    drift_angle_raw_max: float | None = None
    """The largest |θ| of ``θ(t) = ∫ (ω − Ω_axis) dt`` [``drift_angle_unit``]: no bias
    removed (gyros), the figure to compare with another series' of the same definition."""

    @property
    def drift_angle_max_deg(self) -> float | None:
        """The largest |drift angle| in degrees [°] (converted from rad for rad/s data)."""
        return _in_degrees(self.drift_angle_max, self.drift_angle_unit)

    @property
    def drift_angle_raw_max_deg(self) -> float | None:
        """:attr:`drift_angle_raw_max` in degrees [°]."""
        return _in_degrees(self.drift_angle_raw_max, self.drift_angle_unit)

    @property
    def drift_angle_end_deg(self) -> float | None:
        """The drift angle at the end of the run [°]."""
        return _in_degrees(self.drift_angle_end, self.drift_angle_unit)


def _in_degrees(value: float | None, unit: str | None) -> float | None:
    if value is None:
        return None
    return value * units.RAD_TO_DEG if unit == "rad" else value


@dataclass(frozen=True)
class Coverage:
    """How much of a run's span its samples cover: ``span_s`` first to last sample [s],
    ``covered_s`` the span less the gaps [s], ``n_gaps`` and ``gap_s`` their number and
    total length beyond one sample interval [s] (:func:`coverage_of`).

    Attributes
    ----------
    span_s : float
        First to last sample [s].
    covered_s : float
        The span less the gaps [s].
    n_gaps : int
        Number of gaps.
    gap_s : float
        Their total length beyond one sample interval [s].
    """

    span_s: float
    covered_s: float
    n_gaps: int
    gap_s: float

    @property
    def gap_pct(self) -> float:
        """The gaps' share of the span [%] (0 for a span of 0)."""
        return 100.0 * self.gap_s / self.span_s if self.span_s > 0 else 0.0


def coverage_of(time_s: FloatArray, tau0_s: float) -> Coverage:
    """The coverage of a run with times ``time_s`` [s] and sample interval ``tau0_s`` [s]:
    each gap (:func:`thermocal.recording.find_gaps`, a step > 1.5 τ0) counts its length
    less one τ0 (a record 98 % gaps is not "1.02 h" of data).

    Parameters
    ----------
    time_s : numpy.ndarray
        Time [s].
    tau0_s : float
        Sample interval τ0 [s].

    Returns
    -------
    Coverage

    Examples
    --------
    Samples every second at 0…9 s and 100…109 s: one step of 91 s, a gap of 91 − 1 = 90 s:

    >>> import numpy as np
    >>> t = np.concatenate([np.arange(0.0, 10.0), np.arange(100.0, 110.0)])
    >>> round(coverage_of(t, 1.0).gap_s, 1)
    90.0
    """
    from thermocal.recording import find_gaps

    t = np.asarray(time_s, dtype=np.float64)
    span = float(t[-1] - t[0]) if t.size else 0.0
    gaps = find_gaps(t)
    gap_s = float(sum(g.length_s - tau0_s for g in gaps))
    return Coverage(span, span - gap_s, len(gaps), gap_s)


NICE_AVERAGES_S = (1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0)
"""Averaging times [s] a report falls back to, largest first, when the default averaging
time does not fit the record (:func:`averaging_for`)."""
MIN_FALLBACK_AVERAGES = 10
"""Averages a fallback averaging time gives at least (a stated bias stability needs a
handful of averages; IEEE Std 952 reads the Allan curve up to a tenth of the record)."""


def _n_means(slices: list[slice], tau0_s: float, averaging_s: float) -> int:
    m = max(round(averaging_s / tau0_s), 1)
    return sum((sl.stop - sl.start) // m for sl in slices)


def averaging_for(
    time_s: FloatArray, wanted_s: float, *, given: bool, where: str | None, parameter: str | None
) -> tuple[float, str | None]:
    """The averaging time [s] of a report's bias stability and peak-to-peak on a record
    with times ``time_s`` [s], and the note that says why it is not ``wanted_s``.

    ``wanted_s`` when the record gives at least two non-overlapping averages of it (never
    across a gap, as :func:`thermocal.metrics.block_means`).  Else, when the user ``given``
    it, an error naming the file ``where`` and the parameter ``parameter``
    (:func:`thermocal.metrics.too_few_averages`); when it is a default, the largest of
    :data:`NICE_AVERAGES_S` giving at least :data:`MIN_FALLBACK_AVERAGES` averages (the
    sample interval if none does), stated in the note.

    Parameters
    ----------
    time_s : numpy.ndarray
        Time [s].
    wanted_s : float
        The averaging time asked for [s].
    given : bool
        Whether the user gave it (else a default).
    where : str, optional
        How a warning names the run.
    parameter : str, optional
        The parameter that sets it (``"averaging_s"``), named in the error (the command
        line shows its option there).

    Returns
    -------
    tuple of (float, str or None)
        The averaging time used [s] and, when it differs from the one asked for, why.
    """
    from thermocal.errors import ThermocalInputError
    from thermocal.metrics import too_few_averages
    from thermocal.recording import contiguous_slices

    t = np.asarray(time_s, dtype=np.float64)
    if t.size < 2:
        return wanted_s, None
    tau0 = float(np.median(np.diff(t)))
    slices = contiguous_slices(t)
    n = _n_means(slices, tau0, wanted_s)
    if n >= 2:
        return wanted_s, None
    longest = max(sl.stop - sl.start for sl in slices) * tau0
    if given:
        named = "{" + parameter + "}" if parameter else None
        text = too_few_averages(where, wanted_s, n, longest, named)
        raise ThermocalInputError.naming(text, *([parameter] if parameter else []))
    fits = [a for a in NICE_AVERAGES_S if _n_means(slices, tau0, a) >= MIN_FALLBACK_AVERAGES]
    chosen = max(fits) if fits else tau0
    note = (
        f"Bias stability and peak-to-peak are over {chosen:g} s averages: the record "
        f"(longest stretch without a gap {longest:.3g} s) gives fewer than two of the "
        f"default {wanted_s:g} s."
    )
    return chosen, note


def figures_of_merit(
    time_s: FloatArray,
    x: FloatArray,
    unit: str,
    *,
    averaging_s: float,
    meta: Metadata,
    temp_name: str,
    temp_c: FloatArray,
    drift_bias: float | None = None,
    drift_reference_s: tuple[float, float] | None = None,
    where: str | None = None,
) -> FiguresOfMerit:
    """Figures of merit of a rate ``x`` [``unit``, known input included].

    Runs :func:`thermocal.metrics.compute_metrics` on a recording of ``x`` with
    ``temp_c`` as the hold-stage temperature.  The drift angle
    ``θ(t) = ∫ (ω − Ω_axis − b0) dt`` (:func:`thermocal.metrics.drift_angle`, held across
    gaps) removes a stated constant b0, never the run's own mean: ``drift_bias`` when
    given (0 on a compensated output: the model is what removes the bias), else the mean
    over ``drift_reference_s`` (default the first 10 % of the run,
    :func:`thermocal.metrics.reference_bias`).  ``where`` (the file) and ``averaging_s``
    are named when the record gives fewer than two averages.

    Parameters
    ----------
    time_s : numpy.ndarray
        Time [s].
    x : numpy.ndarray
        The signal [``unit``].
    unit : str
        The data's unit (``"deg/h"``, ``"mg"``).
    averaging_s : float
        Averaging time of bias stability and peak-to-peak [s].
    meta : Metadata
        The recording's metadata.
    temp_name : str
        The temperature channel's name.
    temp_c : numpy.ndarray
        Its values [°C] (hold stages).
    drift_bias : float, optional
        b0 of the drift angle [``unit``].
    drift_reference_s : tuple of float, optional
        Window whose mean is b0 [s since the first sample].
    where : str, optional
        How warnings name the run.

    Returns
    -------
    FiguresOfMerit

    References
    ----------
    IEEE Std 952-1997 and IEEE Std 1431-2004 (bias, bias stability); *A modelling and
    validation method for the temperature compensation model of a ring-laser gyroscope*
    (bias stability and repeatability over temperature holds).
    """
    rec = Recording.from_arrays(
        time_s,
        {"signal": x},
        {temp_name: temp_c},
        signal_unit=unit,
        meta=dataclasses.replace(meta, scale_factor=None, scale_factor_unit=None),
    )
    rec = dataclasses.replace(rec, source=where) if where else rec
    m = compute_metrics(
        rec,
        "signal",
        averaging_s,
        temps=[temp_name],
        drift_bias=drift_bias,
        drift_reference_s=drift_reference_s,
    )
    sens = m.temperature_sensitivity
    ang: FloatArray | None = None
    raw_max: float | None = None
    if m.drift_reference is not None and m.unit in RATE_ANGLE_UNITS:
        per = RATE_ANGLE_UNITS[m.unit][1]
        ang = drift_angle(time_s, x, m.drift_reference.bias + m.earth_rate_removed, time_unit_s=per)
        raw_max = drift_angle_extreme(time_s, x, m.earth_rate_removed, time_unit_s=per).max_abs
    return FiguresOfMerit(
        bias=m.bias,
        bias_stability=m.bias_stability,
        averaging_s=m.averaging_s,
        peak_to_peak=m.peak_to_peak,
        sensitivity_slope=sens.ls_slope if sens is not None else None,
        sensitivity_mean_abs=sens.mean_abs_adjacent if sens is not None else None,
        drift_angle=ang,
        drift_angle_end=m.drift_angle,
        drift_angle_max=m.drift_angle_max,
        drift_angle_max_time_s=m.drift_angle_max_time_s,
        drift_angle_unit=m.drift_angle_unit,
        drift_reference=m.drift_reference,
        drift_angle_raw_max=raw_max,
    )


def shown_figures(
    time_s: FloatArray,
    series: tuple[FloatArray, ...],
    unit: str,
    *,
    averaging_s: float,
    meta: Metadata,
    temp_name: str,
    temp_c: FloatArray,
) -> list[tuple[float | None, float | None]]:
    """(bias stability, least-squares temperature sensitivity) [``unit``, ``unit``/°C] of
    each of ``series`` — the two figures of :func:`figures_of_merit` a calibration report
    shows, by the same formulas (:func:`thermocal.metrics.compute_metrics`: the standard
    deviation of the ``averaging_s`` block means, never across a gap; the slope of the hold
    stages' mean biases, pooled by set-point within 0.5 °C, against their temperatures),
    with the gaps, the sample interval and the hold stages found once for all the series
    (they depend on the time and temperature only).  With an earth rate to remove (a latitude or
    axis in
    ``meta``), or fewer than two averages (its error), :func:`figures_of_merit` per series.

    Parameters
    ----------
    time_s : numpy.ndarray
        Time [s].
    series : tuple of numpy.ndarray
        Signals of the same run [``unit``].
    unit : str
        The data's unit (``"deg/h"``, ``"mg"``).
    averaging_s : float
        Averaging time [s].
    meta : Metadata
        The recording's metadata.
    temp_name : str
        The temperature channel's name.
    temp_c : numpy.ndarray
        Its values [°C].

    Returns
    -------
    list of (float or None, float or None)
        Per series its bias stability and temperature sensitivity.
    """
    from thermocal.metrics import block_means, data_unit_of, temperature_sensitivity
    from thermocal.preprocess import segment_holds
    from thermocal.recording import contiguous_slices

    def each() -> list[tuple[float | None, float | None]]:
        out: list[tuple[float | None, float | None]] = []
        for x in series:
            f = figures_of_merit(time_s, x, unit, averaging_s=averaging_s, meta=meta,
                                 temp_name=temp_name, temp_c=temp_c)  # fmt: skip
            out.append((f.bias_stability, f.sensitivity_slope))
        return out

    if meta.latitude_deg is not None or meta.axis is not None:
        return each()
    m = dataclasses.replace(meta, scale_factor=None, scale_factor_unit=None)
    rec = Recording.from_arrays(time_s, {"signal": series[0]}, {temp_name: temp_c},
                                signal_unit=unit, meta=m)  # fmt: skip
    t, temp = rec.time_s, rec.temperature_c(temp_name)
    tau0 = rec.sample_interval_s
    slices = contiguous_slices(t, scan=rec.time_scan())
    holds = [
        s for s in segment_holds(t, temp, rate_threshold_c_per_min=0.05, min_duration_s=600.0)
        if s.kind == "hold" and s.stop > s.start
    ]  # compute_metrics' defaults  # fmt: skip
    st_temps = np.array([float(np.mean(temp[s.start : s.stop])) for s in holds])
    key = np.round(st_temps * 2.0) / 2.0  # hold stages at one set-point (0.5 °C) are pooled
    uniq = np.unique(key)
    out: list[tuple[float | None, float | None]] = []
    for x in series:
        one = dataclasses.replace(rec, columns={**rec.columns, "signal": np.asarray(x)})
        canon_values, canon = one.signal("signal")
        shown, k = data_unit_of(one, "signal", canon)
        values = np.asarray(canon_values, dtype=np.float64).ravel()
        values = values if k == 1.0 else values / k
        parts = [block_means(values[sl], tau0, averaging_s) for sl in slices]
        means = np.concatenate(parts) if parts else np.zeros(0)
        if means.size < 2:
            return each()
        slope = None
        if len(holds) >= 2 and uniq.size >= 2:
            st_bias = np.array([float(np.mean(values[s.start : s.stop])) for s in holds])
            pt = np.array([st_temps[key == q].mean() for q in uniq])
            pb = np.array([st_bias[key == q].mean() for q in uniq])
            slope = temperature_sensitivity(pt, pb, unit=shown).ls_slope
        out.append((float(np.std(means, ddof=1)), slope))
    return out


NOISE_TERMS = (
    ("quantization", "Quantization noise Q"),
    ("angle_random_walk", "Angle random walk N"),
    ("bias_instability", "Bias instability B"),
    ("rate_random_walk", "Rate random walk K"),
    ("rate_ramp", "Rate ramp R"),
)


@dataclass(frozen=True)
class AllanAnalysis:
    """Allan deviation of one series and its noise terms (both IEEE 952 methods).

    Attributes
    ----------
    result : AllanResult
        The Allan deviation.
    terms : NoiseTerms
        Its noise terms by both IEEE Std 952 methods.
    """

    result: AllanResult
    terms: NoiseTerms


def allan_of(time_s: FloatArray, x: FloatArray, tau0_s: float, unit: str) -> AllanAnalysis:
    """Overlapping Allan deviation (octave τ, ±1σ confidence intervals, split at gaps) and
    the IEEE Std 952 noise terms, by :func:`thermocal.stability.allan.overlapping_adev` and
    :func:`thermocal.stability.allan.noise_terms` (NIST SP 1065 eq. 11; IEEE Std 952-1997 Annex
    C), with the
    periodic terms of the longest gap-free stretch that shape the curve named
    (:func:`thermocal.stability.allan.annotate_periodic`).

    Parameters
    ----------
    time_s : numpy.ndarray
        Time [s].
    x : numpy.ndarray
        The signal [``unit``].
    tau0_s : float
        Sample interval τ0 [s].
    unit : str
        The data's unit (``"deg/h"``, ``"mg"``).

    Returns
    -------
    AllanAnalysis

    References
    ----------
    IEEE Std 952-1997, Annex C; W. J. Riley, *Handbook of Frequency Stability Analysis*,
    NIST SP 1065, 2008.
    """
    from thermocal.recording import contiguous_slices

    segs = contiguous_slices(np.asarray(time_s, dtype=np.float64))
    longest = max(segs, key=lambda sl: sl.stop - sl.start) if segs else slice(None)
    found = periodic_terms(np.asarray(x, dtype=np.float64)[longest], tau0_s, unit)
    res = overlapping_adev(x, tau0_s, "octave", time_s=time_s, unit=unit)
    terms = noise_terms(res, periodic=found)
    return AllanAnalysis(result=res, terms=annotate_periodic(terms, res, found))
