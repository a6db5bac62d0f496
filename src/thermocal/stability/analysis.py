"""The stability analysis of a recording's channels, as ``thermocal allan`` and ``thermocal
noise`` run it: the library function each command calls once.

Pure maths on a :class:`~thermocal.recording.Recording` already read (no file layer):

* :func:`allan_analysis`: per channel the overlapping Allan deviation with its noise terms
  (:func:`thermocal.stability.allan.overlapping_adev`,
  :func:`~thermocal.stability.allan.noise_terms`)
  and, with ``dynamic_s``, the dynamic ADEV; or the NIST SP 1065 deviations named in
  ``deviations`` (:func:`thermocal.stability.family.stability`), of rate or phase data.
* :func:`imu_noise`: the estimator noise model of a gyro (and accelerometer) triad
  (:mod:`thermocal.stability.noise_model`).

Every figure is in the data's own unit (:func:`thermocal.data_units.data_unit_of`); doubtful
results are :class:`~thermocal.errors.ConditioningWarning` naming ``where`` (the file).
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Final

from thermocal.data_units import signal_in_data_unit
from thermocal.errors import ConditioningWarning, ParameterError, ThermocalInputError, UnitWarning
from thermocal.stability.allan import ONE_SIGMA_CONFIDENCE
from thermocal.stability.edf import check_confidence

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

    from thermocal.recording import Recording
    from thermocal.stability.allan import AllanResult, DynamicAllan, NoiseTerms
    from thermocal.stability.family import StabilityResult
    from thermocal.stability.noise_model import AxisNoise, NoiseModel, OutputQuantization

    FloatArray = npt.NDArray[np.float64]

DATA_TYPES = ("rate", "phase")
"""``data_type``: rate data (a rate column) or phase data (an integrated quantity)."""


FEW_LEVELS: Final = 3
"""A channel whose samples take at most this many distinct values (more than one) is
flagged: a stuck or flat-lined sensor, or an output step far above its noise; its
deviations describe the steps, not the sensor's noise (a warning)."""

STUCK_MIN_SAMPLES: Final = 10
"""Fewer finite samples than this are too few to call a channel stuck (the estimators' own
minimums refuse so short a record, naming why)."""

_LEVEL_PROBE: Final = 100_000
"""Samples probed first for :data:`FEW_LEVELS` (the whole column only when they are few)."""


STUCK_ALLAN: Final = "has no noise to analyse (every deviation 0, no noise type)"
"""What a constant column means to the deviations (:func:`check_not_stuck`)."""


def check_not_stuck(
    values: FloatArray,
    name: str,
    where: str,
    parameter: str = "signal",
    consequence: str = STUCK_ALLAN,
) -> None:
    """Refuse a constant column, warn on one with at most :data:`FEW_LEVELS` values.

    A constant record has an Allan deviation of 0 at every τ, a zero-width interval and no
    identifiable noise (the B1 ratio and R(n) of NIST SP 1065 §5.6 are 0/0): no sensor at
    rest gives one, a stuck or flat-lined channel does.  ``where`` names the file,
    ``parameter`` the parameter that names the column, ``consequence`` what a constant means
    to the caller.

    Parameters
    ----------
    values : numpy.ndarray
        Samples of the column [unit].
    name : str
        Column name.
    where : str
        File named in the message.
    parameter : str, optional
        The caller's parameter that names the column (default ``"signal"``); the refusal
        names it.
    consequence : str, optional
        What a constant means to the caller.

    Raises
    ------
    ThermocalInputError
        Every finite sample equal (at least :data:`STUCK_MIN_SAMPLES`).
    """
    import numpy as np

    v = np.asarray(values, dtype=np.float64).ravel()
    lo, hi = (float(v.min()), float(v.max())) if v.size else (math.nan, math.nan)
    finite = v  # a NaN makes the minimum NaN, an infinity the minimum or maximum infinite
    if not (math.isfinite(lo) and math.isfinite(hi)):
        finite = v[np.isfinite(v)]
        lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 0.0)
    if finite.size < STUCK_MIN_SAMPLES:
        return
    if lo == hi:
        raise ThermocalInputError.naming(
            f"{where}: the column {name!r} is constant ({lo:.6g} in all {finite.size} "
            f"samples): a stuck or flat-lined sensor {consequence}; name another column "
            "with {" + parameter + "}, or check the sensor",
            parameter,
        )
    probe = _first_levels(finite[:_LEVEL_PROBE], FEW_LEVELS + 1)
    if len(probe) > FEW_LEVELS:
        return
    levels = _first_levels(finite, FEW_LEVELS + 1) if finite.size > _LEVEL_PROBE else probe
    if len(levels) <= FEW_LEVELS:
        warnings.warn(
            f"{where}: the column {name!r} takes only {len(levels)} distinct values in "
            f"{finite.size} samples ({', '.join(f'{x:.6g}' for x in levels)}): a stuck or "
            "flat-lined sensor, or an output step far coarser than its noise: "
            + (
                "the deviations describe those steps, not the sensor's noise"
                if consequence == STUCK_ALLAN
                else "a model of it describes those steps"
            ),
            ConditioningWarning,
            stacklevel=2,
        )


def _first_levels(values: FloatArray, most: int) -> list[float]:
    """The distinct values of ``values`` (no NaN), sorted, up to ``most`` of them: one pass
    per value found, none sorting the column (a record of noise stops after ``most``
    passes; ``np.unique`` would sort it and import ``numpy.ma``)."""
    found: list[float] = []
    rest = values
    while rest.size and len(found) < most:
        first = rest[0]
        found.append(float(first))
        rest = rest[rest != first]
    return sorted(found)


def _tau_range(name: str, tau0_s: float, n_phase: int) -> tuple[float, float, int]:
    """The τ [s] a deviation reaches on ``n_phase`` phase points and its largest m
    (theo1: τ = 0.75 m τ0, m even)."""
    from thermocal.stability import registry

    if name == "adev-rate":  # the overlapping ADEV of rate samples (allan.averaging_factors)
        from thermocal.stability.allan import max_averaging_factor

        m_max = max_averaging_factor(n_phase)
        return tau0_s, m_max * tau0_s, m_max
    m_max = registry.get(name).max_factor(n_phase)
    if name == "theo1":
        m_max -= m_max % 2
        return 1.5 * tau0_s, 0.75 * m_max * tau0_s, m_max
    return tau0_s, m_max * tau0_s, m_max


def check_tau_list(
    taus: Any, tau0_s: float, n_points: int, names: Sequence[str], where: str, spec: str = ""
) -> None:
    """``taus`` as a list of τ [s]: refuse one whose every τ lies outside what the record
    reaches (every array would be empty), warn naming the τ left out of a list partly
    outside.  ``n_points``: the longest gap-free stretch's points as each deviation counts
    them (phase points; ``"adev-rate"``: rate samples); ``names`` the deviations asked.

    Parameters
    ----------
    taus : sequence of float or str
        The τ list [s] (a named set passes).
    tau0_s : float
        Sample interval [s].
    n_points : int
        Points of the longest gap-free stretch.
    names : sequence of str
        Deviations asked.
    where : str
        File named in the message.
    spec : str, optional
        The list as the user wrote it.

    Raises
    ------
    ThermocalInputError
        Every τ outside what the record reaches.
    """
    import numpy as np

    if isinstance(taus, str):
        return
    tau = np.asarray(taus, dtype=np.float64).ravel()
    if tau.size == 0 or not np.all(np.isfinite(tau)) or np.any(tau <= 0):
        return  # the estimators refuse it with their own message
    ranges = {n: _tau_range(n, tau0_s, n_points) for n in names}
    inside = np.zeros(tau.size, dtype=bool)
    for n, (_lo, _hi, m_max) in ranges.items():
        m = 2 * np.round(tau / (1.5 * tau0_s)) if n == "theo1" else np.round(tau / tau0_s)
        inside |= (m >= (2 if n == "theo1" else 1)) & (m <= m_max)
    lo = min(r[0] for r in ranges.values())
    hi = max(r[1] for r in ranges.values())
    given = spec or ",".join(f"{t:g}" for t in tau)
    span = (
        f"the record reaches τ {lo:.6g} … {hi:.6g} s (τ0 = {tau0_s:.6g} s, {n_points} points "
        "in its longest gap-free stretch)"
    )
    if not inside.any():
        raise ThermocalInputError.naming(
            f"{where}: {{taus}} {given}: no τ within the record: {span}; give {{taus}} in "
            "that range, or a named set (octave, decade, log)",
            "taus",
        )
    if not inside.all():
        out = ", ".join(f"{t:g}" for t in tau[~inside])
        warnings.warn(
            ConditioningWarning.naming(f"{where}: {{taus}}: τ {out} s left out: {span}", "taus"),
            stacklevel=2,
        )


def _longest(rec: Recording) -> int:
    """Samples in the longest gap-free stretch of ``rec``."""
    segs = rec.segments()
    return max((sl.stop - sl.start for sl in segs), default=rec.n_samples)


def column_unit(name: str) -> str:
    """A phase column's unit from its name (``phase [s]``, ``angle (deg)``), else ``""``:
    phase units are not signal (rate) units, so the recording's unit resolver cannot give it.

    Parameters
    ----------
    name : str
        Column name.

    Returns
    -------
    str
        The unit, or ``""``.
    """
    hit = re.search(r"[\[(]([^\])]+)[\])]\s*$", name)
    return hit.group(1).strip() if hit else ""


@dataclass(frozen=True, eq=False)
class AllanChannel:
    """One channel's overlapping ADEV, its noise terms, (``dynamic_s``) dynamic ADEV and
    the output quantisation found in the samples
    (:func:`thermocal.stability.noise_model.output_quantization`; None: not quantised).

    Attributes
    ----------
    adev : AllanResult
        The overlapping Allan deviation.
    noise : NoiseTerms
        Its noise terms.
    dynamic : DynamicAllan or None
        The dynamic ADEV (when asked).
    quantization : OutputQuantization or None
        The output quantisation found (None: not quantised).
    """

    adev: AllanResult
    noise: NoiseTerms
    dynamic: DynamicAllan | None = None
    quantization: OutputQuantization | None = None

    def to_dict(self) -> dict[str, Any]:
        """The channel as plain Python values: the object the ``allan`` command prints as
        JSON (NaN where it prints null).

        Returns
        -------
        dict
            The curve (``tau_s``, ``adev``, ``adev_low``/``adev_high``, ``unit``,
            ``n_terms``, ``edf``, ``alpha``, ``alpha_method``, ``interval``: how the
            interval was found), ``noise`` (the least-squares terms,
            :meth:`thermocal.stability.allan.NoiseTermSet.to_dict`), ``noise_slope`` (the
            slope-line terms), ``fit_coefficients``, ``fit_reduced_chi2``, ``fit_quality``,
            ``output_quantization`` (None when the samples lie on no lattice),
            ``bias_instability_minimum``, ``shaped_below_s``, ``periodic`` and, with a
            dynamic ADEV, ``dynamic``.

        References
        ----------
        IEEE Std 952-1997, annex C (C.2: the least-squares fit; C.3: the slope lines).
        """
        from thermocal.stability.allan import minimum_dict
        from thermocal.stability.family import edf_source

        res, noise, quant = self.adev, self.noise, self.quantization
        out: dict[str, Any] = {
            "tau_s": res.tau_s.tolist(),
            "adev": res.adev.tolist(),
            "adev_low": res.adev_low.tolist(),
            "adev_high": res.adev_high.tolist(),
            "unit": res.unit,
            "n_terms": res.n_terms.tolist(),
            "edf": res.edf.tolist(),
            "alpha": res.alpha.tolist(),
            "alpha_method": list(res.alpha_method),
            "interval": f"chi-square, {100 * res.confidence:.1f} %, "
            + edf_source("oadev")
            + ", α identified per τ (as --deviation oadev)",  # cli-words: the allan JSON
            "confidence": res.confidence,
            "tau0_s": res.tau0_s,
            "n_samples": res.n_samples,
            "n_segments": res.n_segments,
            "noise": noise.fit.to_dict(),
            "noise_method": "weighted non-negative least squares (IEEE 952 C.2)",
            "noise_slope": noise.slope.to_dict(),
            "noise_slope_method": "slope lines (IEEE 952 C.3)",
            "fit_coefficients": noise.fit_coefficients.tolist(),
            "fit_reduced_chi2": noise.reduced_chi2,
            "fit_quality": noise.quality.to_dict() if noise.quality is not None else None,
            "output_quantization": quant.to_dict() if quant is not None else None,
            "bias_instability_minimum": minimum_dict(noise.bias_minimum),
            "shaped_below_s": noise.shaped_below_s,
            "periodic": [p.to_dict() for p in noise.periodic],
        }
        if self.dynamic is not None:
            out["dynamic"] = self.dynamic.to_dict()
        return out


@dataclass(frozen=True, eq=False)
class AllanAnalysis:
    """The result of :func:`allan_analysis`: ``channels`` (overlapping ADEV and noise terms,
    the default) or ``family`` (the deviations asked for, or phase data), per channel name
    in the order asked.

    Attributes
    ----------
    names : tuple of str
        The channels, in the order asked.
    channels : dict of str to AllanChannel
        Overlapping ADEV and noise terms per channel (the default).
    family : dict of str to StabilityResult
        The deviations asked for, per channel.
    """

    names: tuple[str, ...]
    channels: dict[str, AllanChannel] = field(default_factory=dict)
    family: dict[str, StabilityResult] = field(default_factory=dict)

    @property
    def is_family(self) -> bool:
        """True when the result holds the deviation family (``deviations``/phase data)."""
        return bool(self.family)


def allan_analysis(
    rec: Recording,
    names: list[str],
    *,
    taus: Any = "octave",
    confidence: float = ONE_SIGMA_CONFIDENCE,
    deviations: Sequence[str] | None = None,
    data_type: str = "rate",
    dynamic_s: float | None = None,
    where: str = "",
    bias_correct: bool = False,
    noise_type: int | None = None,
    noise_id: str | None = None,
    max_work: float | None = None,
    overwrite: bool = False,
    progress: Callable[[float], None] | None = None,
) -> AllanAnalysis:
    """The stability analysis of the channels ``names`` of ``rec`` (module docstring).

    Parameters
    ----------
    rec : Recording
        The recording; ``names`` : list of str, the channels analysed.
    taus : str or sequence of float, optional
        ``octave`` (default), ``decade``, ``log``, ``all`` or a list of τ [s].
    confidence : float, optional
        Confidence level of the intervals (default one sigma, 0.683).
    deviations : sequence of str, optional
        Registered deviation names (:func:`thermocal.stability.registry.names`); then, or
        with ``data_type="phase"``, the family replaces the ADEV and noise terms.
    data_type : str, optional
        ``"rate"`` (default) or ``"phase"``.
    dynamic_s : float, optional
        The dynamic ADEV's window [s] (rate data, ADEV only).
    where, bias_correct : str, bool, optional
        File named in messages; Stable32's bias correction of totdev and htotdev.
    noise_type, noise_id : int, str, optional
        Power-law α (−4…2) assumed at every τ; identification rules ``thermocal``/``stable32``.
    max_work : float, optional
        The family's operation budget (:func:`thermocal.stability.family.check_work`).
    overwrite : bool, optional
        Accumulate the phase in the recording's own signal buffers (no memory per sample):
        ``rec``'s values are changed.  Only for a recording nothing reads afterwards (the
        ``allan`` command's, read from a file); default False leaves ``rec`` as it was.
    progress : callable, optional
        With ``deviations`` or phase data: called with the fraction done (0 to 1, rising)
        of the total family's sums over every channel
        (:func:`thermocal.stability.family.stability`), 1.0 at the end.

    Returns
    -------
    AllanAnalysis
        Per channel the deviations, noise terms and dynamic ADEV.

    Raises
    ------
    ParameterError
        An unknown ``data_type``.
    ThermocalInputError
        A confidence, τ list or option the record cannot serve (a poor noise-model fit
        and a non-stationary record are a :class:`ConditioningWarning`).
    """
    check_confidence(confidence)
    if data_type not in DATA_TYPES:
        raise ParameterError("data_type", f"{{name}} {data_type!r}: use rate or phase")
    if dynamic_s is not None and (deviations is not None or data_type == "phase"):
        raise ThermocalInputError.naming(
            "{dynamic_s} computes the overlapping ADEV of rate data; run it without "
            "{deviations} and {data_type} phase",
            "dynamic_s",
            "deviations",
            "data_type",
        )
    if deviations is not None or data_type == "phase":
        return AllanAnalysis(
            tuple(names),
            family=_family(
                rec, names, taus, confidence, deviations, data_type, bias_correct, noise_type,
                noise_id or "thermocal", max_work, where, overwrite, progress,
            ),
        )  # fmt: skip
    _refuse_family_only(bias_correct, noise_type, noise_id)
    check_tau_list(taus, rec.sample_interval_s, _longest(rec), ["adev-rate"], where)
    if dynamic_s is not None:  # the windows counted before any work
        from thermocal.stability import allan, family

        allan.check_dynamic_work(
            rec.n_samples, rec.sample_interval_s, dynamic_s,
            family.DEFAULT_MAX_WORK if max_work is None else max_work,
            channels=len(names), where=where, parameter="dynamic_s",
        )  # fmt: skip
    channels: dict[str, AllanChannel] = {}
    for name in names:  # one read of the file, every channel
        label = where + (f" [{name}]" if len(names) > 1 else "")
        channels[name] = _allan_channel(
            rec, name, taus, confidence, dynamic_s, overwrite and names.count(name) == 1, label
        )
    return AllanAnalysis(tuple(names), channels=channels)


def _refuse_family_only(bias_correct: bool, noise_type: int | None, noise_id: str | None) -> None:
    """Refuse the deviation family's parameters given without ``deviations``."""
    family_only = [
        (text, parameter)
        for text, parameter, given in (
            ("{bias_correct} (totdev, htotdev)", "bias_correct", bias_correct),
            ("{noise_type}", "noise_type", noise_type is not None),
            ("{noise_id}", "noise_id", noise_id is not None),
        )
        if given
    ]
    if family_only:
        raise ThermocalInputError.naming(
            f"{', '.join(t for t, _ in family_only)}: for the deviation family's intervals; "
            "give the deviations with {deviations} (the overlapping ADEV: {deviations} oadev)",
            *(p for _, p in family_only),
            "deviations",
        )


def _family(
    rec: Recording,
    names: list[str],
    taus: Any,
    confidence: float,
    deviations: Sequence[str] | None,
    data_type: str,
    bias_correct: bool = False,
    noise_type: int | None = None,
    noise_id: str = "thermocal",
    max_work: float | None = None,
    where: str = "",
    overwrite: bool = False,
    progress: Callable[[float], None] | None = None,
) -> dict[str, StabilityResult]:
    """The deviations of every channel (phase data: the column as given, in its own unit;
    ``overwrite``: centred in the recording's own buffer when the channel is named once)."""
    from thermocal.stability import family

    devs = list(dict.fromkeys(deviations or ["oadev"]))
    alpha = family.check_noise_type(noise_type, devs)
    n_phase = _longest(rec) + (1 if data_type == "rate" else 0)
    check_tau_list(taus, rec.sample_interval_s, n_phase, devs, where)
    results = {}
    for k, name in enumerate(names):
        if data_type == "phase":  # the column as given, in its own unit
            values, unit = rec.column(name), column_unit(name)
            if not unit:
                warnings.warn(
                    UnitWarning(
                        f"the phase column {name!r} names no unit (as 'phase [s]' or "
                        "'angle (deg)'): its deviations are given without one"
                    ),
                    stacklevel=1,
                )
        else:
            values, unit = signal_in_data_unit(rec, name)
        check_not_stuck(values, name, where)
        results[name] = family.stability(
            values, rec.sample_interval_s, devs, taus, data_type=data_type,
            segments=rec.segments(), unit=unit, confidence=confidence, bias_correct=bias_correct,
            alpha=alpha, noise_id=noise_id,
            where=where, max_work=family.DEFAULT_MAX_WORK if max_work is None else max_work,
            overwrite=overwrite and names.count(name) == 1,
            progress=None if progress is None else _share(progress, k, len(names)),
        )  # fmt: skip
    _idle_options(results, devs, bias_correct, alpha, where)
    return results


def _share(progress: Callable[[float], None], k: int, count: int) -> Callable[[float], None]:
    """The ``k``-th of ``count`` channels' fractions as fractions of the whole run."""
    return lambda frac: progress((k + frac) / count)


BIAS_CORRECTED: Final = ("totdev", "htotdev")
"""The deviations ``bias_correct`` multiplies by Stable32's factor (the others: 1)."""


def _idle_options(
    results: dict[str, StabilityResult],
    devs: list[str],
    bias_correct: bool,
    alpha: int | None,
    where: str,
) -> None:
    """A warning naming ``bias_correct`` or ``noise_type`` where it changed nothing: no
    totdev/htotdev asked, a factor of 1 at every τ (Stable32 corrects totdev for flicker and
    random-walk FM only, htotdev for FM noise from m = 2: :func:`.family.stable32_bias`), or
    no deviation with an interval (MTIE, TIE rms: :func:`.family.no_interval`)."""
    import numpy as np

    from thermocal.stability.family import no_interval

    if bias_correct:
        corrected = [d for d in devs if d in BIAS_CORRECTED]
        if not corrected:
            why = f"it corrects totdev and htotdev only, not {', '.join(devs)}"
        elif all(
            r.curves[d].bias is None or bool(np.all(r.curves[d].bias == 1.0))
            for r in results.values()
            for d in corrected
        ):
            why = (
                f"the factor is 1 at every τ of {', '.join(corrected)} for the noise "
                "identified (Stable32 corrects totdev for flicker and random-walk FM, "
                "htotdev for FM noise from m = 2)"
            )
        else:
            why = ""
        if why:
            warnings.warn(
                ConditioningWarning.naming(
                    f"{where}: {{bias_correct}} changes nothing: {why}", "bias_correct"
                ),
                stacklevel=2,
            )
    if alpha is not None and all(no_interval(d) is not None for d in devs):
        warnings.warn(
            ConditioningWarning.naming(
                f"{where}: {{noise_type}} changes nothing: no confidence interval or bias "
                f"factor uses it ({', '.join(devs)}: none)",
                "noise_type",
            ),
            stacklevel=2,
        )


def _allan_channel(
    rec: Recording,
    name: str,
    taus: Any,
    confidence: float,
    dynamic_s: float | None,
    overwrite: bool,
    where: str,
) -> AllanChannel:
    """One channel's ADEV, noise terms and dynamic ADEV, with their warnings (BLAS on one
    thread: the kernels' many short dots on threads of their own; OpenBLAS's idle threads
    spin and take the cores from them)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _channel_analysis(rec, name, taus, confidence, dynamic_s, overwrite, where)


def _channel_analysis(
    rec: Recording,
    name: str,
    taus: Any,
    confidence: float,
    dynamic_s: float | None,
    overwrite: bool,
    where: str,
) -> AllanChannel:
    """:func:`_allan_channel`'s work (:func:`thermocal.stability.noise_model.adev_and_terms`:
    the periodogram in a thread beside the lattice and the ADEV), with its warnings."""
    from thermocal.stability import allan
    from thermocal.stability import noise_model as nm

    # every figure in the data's own unit (°/s data: ADEV in °/s)
    values, unit = signal_in_data_unit(rec, name)
    check_not_stuck(values, name, where)
    res, noise, quant = nm.adev_and_terms(
        values,
        rec.sample_interval_s,
        taus,
        time_s=rec.time_s,
        segments=rec.segments(),  # one scan of the time column for every channel
        unit=unit,
        confidence=confidence,
        # the phase is accumulated in the column's own buffer (no memory per sample)
        # only when the caller gives the recording up and the column is not used
        # again: not when the channel is named twice or the dynamic ADEV reads the rate
        # after it (it did, on the floor's numpy/pyarrow, where the buffer is
        # writeable: windows of phase, found by the floor check)
        overwrite=overwrite and dynamic_s is None,
    )
    if noise.quality is not None and noise.quality.quality == "poor":
        warnings.warn(f"{where}: {noise.quality.reason}", ConditioningWarning, stacklevel=1)
    if dynamic_s is None:
        return AllanChannel(res, noise, quantization=quant)
    dyn = allan.dynamic_adev(
        values, rec.sample_interval_s, dynamic_s, res, time_s=rec.time_s, parameter="dynamic_s"
    )
    if not dyn.stationary:
        warnings.warn(nonstationary_message(dyn, where), ConditioningWarning, stacklevel=1)
    return AllanChannel(res, noise, dyn, quant)


def nonstationary_message(dyn: DynamicAllan, where: str, what: str = "the record") -> str:
    """The warning of a non-stationary record (``dyn.changes`` not empty): how many
    (window, τ) cells differ from the whole record's ADEV beyond both intervals and the
    largest such change [``dyn.unit``]; ``where`` names the file, ``what`` the series.

    Parameters
    ----------
    dyn : DynamicAllan
        Dynamic ADEV result.
    where : str
        File named in the message.
    what : str, optional
        The series (default ``"the record"``).

    Returns
    -------
    str
        The warning text.
    """
    worst = max(dyn.changes, key=lambda c: abs(math.log(c["adev"] / c["whole_adev"])))
    return (
        f"{where}: {what} is not stationary: in {len(dyn.changes)} (window, τ) "
        f"cells the {dyn.window_s:g} s windows' ADEV differs from the whole "
        f"record's beyond both intervals (e.g. {worst['adev']:.4g} against "
        f"{worst['whole_adev']:.4g} {dyn.unit} at τ = {worst['tau_s']:.4g} s in "
        f"the window centred at {worst['t_s']:.4g} s); the noise terms of the "
        "whole record average over changing noise"
    )


STILL_TURN_DEG: Final = 5.0
"""A noise record whose accelerometer direction (1 s means) turns more than this [°] moved."""
STILL_RATE_DEG_H: Final = 7200.0
"""…or, without an accelerometer, whose gyro's 1 s means leave their median by more than
this [°/h] (2 °/s: a hand's turn, far above any bias change at rest)."""


def motion_in(rec: Recording, gyro: Sequence[str], accel: Sequence[str]) -> str | None:
    """Words for the motion of a record meant to be static, else None: the largest turn of
    the accelerometer's 1 s mean direction from its median (beyond :data:`STILL_TURN_DEG`;
    when it reads gravity, above 0.5 g), else the largest departure of the gyro's 1 s mean
    rate from its median (beyond :data:`STILL_RATE_DEG_H`).  Columns in raw counts without
    a scale factor are not judged.

    Parameters
    ----------
    rec : Recording
        The recording.
    gyro, accel : sequence of str
        Gyro [rate unit] and accelerometer [acceleration unit] columns.

    Returns
    -------
    str or None
        The motion in words, None when still.
    """
    import numpy as np

    w = max(1, round(1.0 / rec.sample_interval_s))
    k = rec.n_samples // w

    def means(cols: Sequence[str], canon: str) -> FloatArray | None:
        got = [rec.signal(c) for c in cols]
        if k < 3 or not cols or any(u != canon for _v, u in got):
            return None
        x = np.column_stack([v[: k * w] for v, _u in got])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN window
            m = np.nanmean(x.reshape(k, w, len(cols)), axis=1)
        return m if int(np.all(np.isfinite(m), axis=1).sum()) >= 3 else None

    a = means(accel, "mg")
    if a is not None and np.nanmedian(np.linalg.norm(a, axis=1)) > 500.0:
        u = a / np.linalg.norm(a, axis=1)[:, None]
        ref = np.nanmedian(u, axis=0)
        ang = np.degrees(np.arccos(np.clip(u @ (ref / np.linalg.norm(ref)), -1.0, 1.0)))
        j = int(np.nanargmax(ang))
        if ang[j] > STILL_TURN_DEG:
            return f"the accelerometer's direction turns {ang[j]:.3g}° (1 s means, at {j} s)"
        return None
    g = means(gyro, "deg/h")
    if g is None:
        return None
    dev = np.linalg.norm(g - np.nanmedian(g, axis=0), axis=1)
    j = int(np.nanargmax(dev))
    if dev[j] > STILL_RATE_DEG_H:
        return f"the gyro's rate departs {dev[j] / 3600.0:.3g} °/s from its median (at {j} s)"
    return None


@dataclass(frozen=True, eq=False)
class ImuNoise:
    """The result of :func:`imu_noise`: each axis's terms and the estimator noise model.

    Attributes
    ----------
    axes : tuple of AxisNoise
        Each axis's terms.
    model : NoiseModel
        The estimator noise model.
    """

    axes: tuple[AxisNoise, ...]
    model: NoiseModel


def imu_noise(
    rec: Recording,
    gyro: list[str],
    accel: list[str],
    *,
    inflate: float = 1.0,
    rostopic: str = "/imu0",
    confidence: float = ONE_SIGMA_CONFIDENCE,
    where: str = "",
) -> ImuNoise:
    """The IMU noise model of the gyro (and accelerometer) columns of ``rec``
    (:func:`thermocal.stability.noise_model.axis_noise` per axis in the data's own unit,
    :func:`~thermocal.stability.noise_model.noise_model` over them, rate 1/τ0).  A term
    given only as an upper bound is a :class:`ConditioningWarning` naming ``where`` and
    the axis.

    Parameters
    ----------
    rec : Recording
        The recording.
    gyro, accel : list of str
        Gyro and accelerometer columns.
    inflate : float, optional
        Factor on the densities (default 1).
    rostopic : str, optional
        ROS topic of the IMU (default ``"/imu0"``).
    confidence : float, optional
        Confidence level of the intervals (default one sigma, 0.683).
    where : str, optional
        File named in warnings.

    Returns
    -------
    ImuNoise
        The noise model and its terms per axis.

    References
    ----------
    - IEEE Std 952-1997, Annex C (Allan variance noise terms).
    """
    from thermocal.stability import noise_model as nm

    check_confidence(confidence)
    moved = motion_in(rec, gyro, accel)
    if moved is not None:
        warnings.warn(
            f"{where}: the sensor moves during the record ({moved}): the noise terms need it "
            "at rest, the Allan deviation of a moving record holds the motion; cut a static "
            "stretch",
            ConditioningWarning,
            stacklevel=1,
        )
    axes = []
    for name in gyro + accel:
        values, unit = signal_in_data_unit(rec, name)
        check_not_stuck(values, name, where, "gyro" if name in gyro else "accel")
        axes.append(
            nm.axis_noise(
                values, rec.sample_interval_s, name=name,
                sensor="gyro" if name in gyro else "accel", unit=unit,
                segments=rec.segments(), time_s=rec.time_s, confidence=confidence,
            )
        )  # fmt: skip
    model = nm.noise_model(
        axes, 1.0 / rec.sample_interval_s, inflate=inflate, rostopic=rostopic,
        confidence=confidence, where=where,
    )  # fmt: skip
    for ax in axes:
        for kind, t in (("density", ax.density), ("walk", ax.walk)):
            if t.method == "bound":
                warnings.warn(
                    f"{where} [{ax.name}]: {nm.term_words(ax.sensor, kind)}: {t.reason}",
                    ConditioningWarning,
                    stacklevel=1,
                )
    return ImuNoise(tuple(axes), model)


__all__ = [
    "DATA_TYPES",
    "AllanAnalysis",
    "AllanChannel",
    "ImuNoise",
    "allan_analysis",
    "column_unit",
    "imu_noise",
    "nonstationary_message",
    "signal_in_data_unit",
]
