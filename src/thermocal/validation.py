"""Validating a compensation model on a weakly correlated test ([Seed-RLG]).

A model is judged on a test it was not fitted to, whose temperature history is
not a copy of the modelling test's:

1. **Correlation** of the ambient temperature histories X (modelling test) and
   Y (validation test) on a common elapsed-time base,
   ``r = Cov(X, Y)/(σ_X σ_Y)`` (:func:`thermocal.profiles.correlate`); the
   validation test is *weakly correlated* when ``r < 0.4``.  A test that is not
   gets a :class:`~thermocal.errors.CorrelationWarning`, not a refusal.
2. **Compensation**: ``F' = F − ŷ(T, Ṫ, …)`` with the model
   (:func:`thermocal.compensate.kernels.compensate_run`).
3. **Hold stages**: the temperature-hold stages of the validation run are cut
   out (:func:`thermocal.preprocess.segment_holds` on the ambient column) and,
   before and after compensation, within each stage s:

   * bias ``B0_s = mean(F)`` over the stage (IEEE Std 952-1997);
   * bias stability ``Bs_s = sqrt(Σ (F̄_j − mean F̄)²/(q − 1))`` of the q averages
     ``F̄_j`` over complete blocks of ``round(averaging_s/τ0)`` samples from the
     stage's first sample (:func:`thermocal.metrics.block_means`; IEEE Std 952-1997);

   and across the p stages:

   * ``bias_stability = sqrt((1/p') Σ_s Bs_s²)`` — the **rms over the stages**
     (our choice: the rms is the stability a user sees over a typical stage and
     is not pulled down by short, quiet stages as a median would be; p' counts
     the stages with ≥ 2 complete blocks);
   * ``bias_repeatability Br = sqrt(Σ (B0_s − mean B0)²/(p − 1))`` (IEEE Std 952-1997).

4. **Whole run**: on the averages over ``averaging_s`` of the whole run (never
   across a gap), after removing their mean, ``rms = sqrt(mean(F̄_j − mean F̄)²)``
   and ``peak_to_peak = max F̄_j − min F̄_j``.
5. ``improvement_pct[x] = 100 (x_before − x_after)/x_before`` for each figure.
6. **What the user sees**: per sample, about the level an ideal sensor would
   give (``K``, :func:`thermocal.compensate.kernels.zero_reference`: the known input — earth rate,
   gravity — or 0), ``mean = mean(F − K)``, ``rms_about_zero = sqrt(mean((F − K)²))`` and
   ``max_abs = max |F − K|``, before and after (:class:`~thermocal.compensate.kernels.
   AbsoluteFigures`).  A compensation that raises the rms about zero or the largest |error|
   by more than 1 % is *absolutely worse*: a warning, ``absolute_error_worse`` and the
   verdict ``NOT improved (absolute error worse)`` — the figures about the mean cannot see a
   constant offset the model adds (a model fitted at 13 °C applied at 47 °C).
7. **Heating and cooling legs** of the ambient temperature (:func:`thermocal.legs.find_legs`):
   each leg's rms, largest magnitude and mean of the output about its mean, before and
   after, and whether heating and cooling disagree at equal temperature beyond the noise
   (Student's t of the binned mean difference, :func:`thermocal.legs.compare_legs`) —
   thermal hysteresis the model leaves.
8. **Applicability**: the share of samples outside the model's calibrated temperature
   range (and Ṫ range, and time since power-on for warm-up models) and how far
   (:class:`~thermocal.models.ranges.RangeExcess`), one warning for the run.

All figures are in the model's signal unit ([°/h] or [mg]); :meth:`ValidationResult.in_unit`
gives them in the data's own unit (``thermocal validate`` does).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import metrics
from thermocal.compensate.kernels import (
    KEPT_IN_BIAS,
    AbsoluteFigures,
    absolute_error_worse,
    absolute_figures,
    absolute_worse_message,
    compensate_run,
)
from thermocal.defaults import DEFAULT_AVERAGING_S as DEFAULT_AVERAGING_S
from thermocal.defaults import WEAK_CORRELATION_LIMIT
from thermocal.errors import (
    CorrelationWarning,
    ExtrapolationWarning,
    ThermocalInputError,
    ThermocalWarning,
    TimestampError,
)
from thermocal.legs import LegComparison, Legs, compare_legs, find_legs
from thermocal.models.base import TemperatureModel
from thermocal.models.ranges import (
    RANGE_WARNING_PATTERNS,
    RangeExcess,
    outside_range,
    outside_range_dict,
    outside_range_message,
)
from thermocal.models.rundata import RunData
from thermocal.preprocess import segment_holds
from thermocal.profiles import correlate
from thermocal.recording import FloatArray, median_interval


@dataclass(frozen=True)
class StageFigures:
    """Figures of one temperature-hold stage, before and after compensation [signal unit].

    Attributes
    ----------
    index : int
        The stage's number, from 0.
    start_s, stop_s : float
        Its span [s].
    mean_temp_c : float
        Its mean temperature [°C].
    n_samples, n_averages : int
        Samples and averages in it.
    bias_before, bias_after : float
        Mean bias before and after compensation [unit].
    bias_stability_before, bias_stability_after : float
        Standard deviation of the averages before and after [unit].
    """

    index: int
    start_s: float
    stop_s: float
    mean_temp_c: float
    n_samples: int
    n_averages: int
    bias_before: float
    bias_after: float
    bias_stability_before: float
    bias_stability_after: float

    @property
    def duration_s(self) -> float:
        """Length of the stage [s]."""
        return self.stop_s - self.start_s

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the stage's figures."""
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        d["duration_s"] = self.duration_s
        return d


@dataclass(frozen=True)
class ValidationResult:
    """Result of :func:`validate`; :meth:`to_dict` gives the ``validate`` command's JSON keys.

    ``r`` and ``weakly_correlated`` are ``None`` when no modelling history was given.

    Attributes
    ----------
    r : float or None
        Correlation of the validation and modelling temperature histories.
    weakly_correlated : bool or None
        ``r < r_limit``.
    r_limit : float
        The limit used.
    n_stages : int
        Number of hold stages.
    stages : tuple of StageFigures
        Each stage's figures.
    bias_stability_before, bias_stability_after : float
        RMS over the stages of their bias stabilities, before and after compensation [unit].
    bias_repeatability_before, bias_repeatability_after : float
        Standard deviation of the stages' mean biases before and after [unit].
    rms_before, rms_after : float
        RMS about their mean of the whole run's averages before and after [unit].
    peak_to_peak_before, peak_to_peak_after : float
        Peak-to-peak of the averages before and after [unit].
    averaging_s : float
        Averaging time [s].
    unit : str
        The signal's unit.
    n_samples : int
        Samples validated.
    warnings : tuple of str
        The validation's warnings.
    extra : dict
        Further figures.
    absolute_before, absolute_after : AbsoluteFigures or None
        Per-sample figures of the raw and compensated output about ``zero_reference`` [unit].
    zero_reference : float
        The level an ideal sensor would output [unit].
    zero_reference_what : str
        What that level is.
    absolute_worse : tuple of str
        The absolute figures the compensation made worse (beyond 1 %).
    outside_range : tuple of RangeExcess
        How far the run leaves the model's calibrated ranges, per input.
    legs : Legs or None
        The heating and cooling legs of the ambient temperature (:func:`thermocal.legs.find_legs`).
    legs_after, legs_before : LegComparison or None
        Each leg's figures of the compensated (raw) output about its mean, and heating
        against cooling at equal temperature (:func:`thermocal.legs.compare_legs`) [unit].
    """

    r: float | None
    weakly_correlated: bool | None
    r_limit: float
    n_stages: int
    stages: tuple[StageFigures, ...]
    bias_stability_before: float
    bias_stability_after: float
    bias_repeatability_before: float
    bias_repeatability_after: float
    rms_before: float
    rms_after: float
    peak_to_peak_before: float
    peak_to_peak_after: float
    averaging_s: float
    unit: str
    n_samples: int
    warnings: tuple[str, ...] = ()
    extra: dict[str, Any] = field(default_factory=dict)
    absolute_before: AbsoluteFigures | None = None
    """Per-sample figures of the raw output about :attr:`zero_reference` [unit]."""
    absolute_after: AbsoluteFigures | None = None
    """The same of the compensated output [unit]."""
    zero_reference: float = 0.0
    """The level an ideal sensor would output, "zero" of the absolute figures [unit]."""
    zero_reference_what: str = "0"
    absolute_worse: tuple[str, ...] = ()
    """The absolute figures the compensation made worse (beyond 1 %)."""
    outside_range: tuple[RangeExcess, ...] = ()
    """How far the run leaves the model's calibrated ranges, per input."""
    legs: Legs | None = None
    """The heating and cooling legs of the ambient temperature."""
    legs_after: LegComparison | None = None
    """Per leg, the compensated output about its mean, and heating vs cooling [unit]."""
    legs_before: LegComparison | None = None
    """The same of the raw output [unit]."""

    @property
    def absolute_error_worse(self) -> bool:
        """True when the compensation makes the absolute error worse (rms about zero or
        max |error| after > before by more than 1 %)."""
        return bool(self.absolute_worse)

    @property
    def outside_calibrated_range(self) -> bool:
        """True when any sample left a calibrated range (temperature, Ṫ, power-on time)."""
        return any(e.n_outside for e in self.outside_range)

    @property
    def improvement_pct(self) -> dict[str, float | None]:
        """``100 (before − after)/before`` for each figure (None when undefined)."""
        out: dict[str, float | None] = {}
        for key in ("bias_stability", "bias_repeatability", "rms", "peak_to_peak"):
            b = float(getattr(self, f"{key}_before"))
            a = float(getattr(self, f"{key}_after"))
            out[key] = 100.0 * (b - a) / b if math.isfinite(a) and math.isfinite(b) and b else None
        return out

    @property
    def verdict(self) -> str:
        """One word on the model for this run: ``"NOT weakly correlated"`` when r says the
        validation run repeats the modelling run (then it proves nothing), else
        ``"NOT improved (absolute error worse)"`` when the compensation makes the error
        about zero worse (:attr:`absolute_error_worse`), else ``"improved"``/``"NOT
        improved"`` by the rms of the bias before and after; ``"—"`` when the rms cannot be
        compared.  A run outside the calibrated range is flagged beside the verdict
        (:attr:`outside_calibrated_range`, :attr:`verdict_line`), not in this word."""
        if self.r is not None and not self.weakly_correlated:
            return "NOT weakly correlated"
        if self.absolute_error_worse:
            return "NOT improved (absolute error worse)"
        imp = self.improvement_pct.get("rms")
        if imp is None:
            return "—"
        return "improved" if imp > 0 else "NOT improved"

    @property
    def verdict_line(self) -> str:
        """The verdict with what qualifies it: the run outside the calibrated range."""
        bad = [e for e in self.outside_range if e.n_outside]
        if not bad:
            return self.verdict
        what = ", ".join(
            f"{e.quantity.replace('_', ' ')} {100.0 * e.share:.3g} % of samples, up to "
            f"{e.max_beyond:.3g} {e.unit} beyond"
            for e in bad
        )
        return f"{self.verdict}; outside the calibrated range ({what})"

    def in_unit(self, unit: str, factor: float) -> ValidationResult:
        """The same result with every signal figure expressed in another unit.

        Parameters
        ----------
        unit : str
            Name of the new unit (e.g. the data's own unit, ``"deg/h"``).
        factor : float
            Conversion factor [unit of ``self`` per ``unit``], so that
            ``value[self.unit] = factor · value[unit]``; ``1.0`` with the same unit
            returns ``self``.

        Returns
        -------
        ValidationResult
            Copy whose bias stability, repeatability, rms, peak-to-peak, stage biases,
            absolute figures and zero reference are divided by ``factor``; improvements,
            correlation ``r`` and the stage layout are unchanged.
        """
        if factor == 1.0 and unit == self.unit:
            return self
        keys = [
            f"{k}_{w}"
            for k in ("bias_stability", "bias_repeatability", "rms", "peak_to_peak")
            for w in ("before", "after")
        ]
        stage_keys = ("bias_before", "bias_after", "bias_stability_before", "bias_stability_after")
        stages = tuple(
            dataclasses.replace(s, **{k: getattr(s, k) / factor for k in stage_keys})
            for s in self.stages
        )

        def absolute(a: AbsoluteFigures | None) -> AbsoluteFigures | None:
            if a is None:
                return None
            return AbsoluteFigures(a.mean / factor, a.rms_about_zero / factor, a.max_abs / factor)

        return dataclasses.replace(
            self,
            unit=unit,
            stages=stages,
            legs_after=None if self.legs_after is None else self.legs_after.scaled(unit, factor),
            legs_before=(
                None if self.legs_before is None else self.legs_before.scaled(unit, factor)
            ),
            absolute_before=absolute(self.absolute_before),
            absolute_after=absolute(self.absolute_after),
            zero_reference=self.zero_reference / factor,
            **{k: getattr(self, k) / factor for k in keys},
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (NaN → None)."""

        def num(x: float | None) -> float | None:
            return None if x is None or not math.isfinite(x) else float(x)

        d: dict[str, Any] = {
            "r": num(self.r),
            "weakly_correlated": self.weakly_correlated,
            "r_limit": self.r_limit,
            "n_stages": self.n_stages,
            "bias_stability_before": num(self.bias_stability_before),
            "bias_stability_after": num(self.bias_stability_after),
            "bias_repeatability_before": num(self.bias_repeatability_before),
            "bias_repeatability_after": num(self.bias_repeatability_after),
            "rms_before": num(self.rms_before),
            "rms_after": num(self.rms_after),
            "peak_to_peak_before": num(self.peak_to_peak_before),
            "peak_to_peak_after": num(self.peak_to_peak_after),
            "improvement_pct": {k: num(v) for k, v in self.improvement_pct.items()},
        }
        # what the sensor's user sees: per sample, about the reference "zero" (unit)
        for when, a in (("before", self.absolute_before), ("after", self.absolute_after)):
            d[f"mean_{when}"] = num(a.mean) if a else None
            d[f"rms_about_zero_{when}"] = num(a.rms_about_zero) if a else None
            d[f"max_abs_{when}"] = num(a.max_abs) if a else None
        d["zero_reference"] = {
            "value": num(self.zero_reference),
            "unit": self.unit,
            "what": self.zero_reference_what,
        }
        d["absolute_error_worse"] = self.absolute_error_worse
        d["absolute_error_worse_figures"] = list(self.absolute_worse)
        d["outside_calibrated_range"] = self.outside_calibrated_range
        d["outside_range"] = outside_range_dict(self.outside_range)
        d["verdict"] = self.verdict
        d["verdict_line"] = self.verdict_line
        d |= {
            "averaging_s": self.averaging_s,
            "unit": self.unit,
            "n_samples": self.n_samples,
            "stages": [
                {k: (num(v) if isinstance(v, float) else v) for k, v in s.to_dict().items()}
                for s in self.stages
            ],
            "warnings": list(self.warnings),
        }
        d["legs"] = self._legs_dict()
        d.update(self.extra)
        return d

    def _legs_dict(self) -> dict[str, Any] | None:
        """``legs`` of :meth:`to_dict`: the legs found, each leg's figures after
        compensation, heating vs cooling after and before."""
        if self.legs is None or self.legs_after is None:
            return None
        found = self.legs.to_dict()
        after = self.legs_after.to_dict()
        before = None if self.legs_before is None else self.legs_before.to_dict()
        return {
            "summary": self.legs.summary(),
            **{k: v for k, v in found.items() if k != "legs"},
            **after,
            "before": None if before is None else {k: v for k, v in before.items() if k != "legs"},
        }


# --- pure figure functions -----------------------------------------------------------------


def block_means(time_s: FloatArray, x: FloatArray, averaging_s: float, tau0_s: float) -> FloatArray:
    """Averages of a signal over complete consecutive blocks, never across a gap.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    x : numpy.ndarray
        Signal [its unit].
    averaging_s : float
        Averaging time τ [s].
    tau0_s : float
        Sample interval τ0 [s]; blocks hold ``m = round(averaging_s / tau0_s)``
        samples counted from the first sample.

    Returns
    -------
    numpy.ndarray
        One average per complete block [unit of ``x``]
        (see :func:`thermocal.metrics.block_means`).

    References
    ----------
    - IEEE Std 952-1997, Annex C (averages over the sample time τ).
    """
    return metrics.block_means(x, tau0_s, averaging_s, time_s=time_s)


def stability_of_means(means: FloatArray) -> float:
    r"""Bias stability: sample standard deviation of the block averages.

    Parameters
    ----------
    means : numpy.ndarray
        Block averages :math:`\bar x_j` [signal unit].

    Returns
    -------
    float
        Bias stability [signal unit]; NaN for fewer than 2 averages.

    Notes
    -----
    .. math:: B_s = \sqrt{\frac{1}{m-1}\sum_{j=1}^{m}(\bar x_j - \langle \bar x\rangle)^2}

    References
    ----------
    - IEEE Std 952-1997, IEEE Standard Specification Format Guide and Test Procedure
      for Single-Axis Interferometric Fiber Optic Gyros, bias instability/stability.
    """
    return float(np.std(means, ddof=1)) if means.size >= 2 else float("nan")


def repeatability(biases: npt.ArrayLike) -> float:
    r"""Bias repeatability: sample standard deviation of the biases of ``p`` runs.

    Parameters
    ----------
    biases : array_like
        Bias :math:`B_{0,i}` of each run or stage [signal unit].

    Returns
    -------
    float
        Bias repeatability [signal unit]; NaN for fewer than 2 biases.

    Notes
    -----
    .. math:: B_r = \sqrt{\frac{1}{p-1}\sum_{i=1}^{p}(B_{0,i} - \langle B_0\rangle)^2}

    References
    ----------
    - IEEE Std 952-1997, bias repeatability.

    Examples
    --------
    >>> round(repeatability([1.0, 2.0, 3.0]), 3)
    1.0
    """
    b = np.asarray(biases, dtype=np.float64)
    return metrics.bias_repeatability(b) if b.size >= 2 else float("nan")


def rms_over_stages(values: npt.ArrayLike) -> float:
    r"""Root mean square over stages of a per-stage figure, ignoring NaN.

    Parameters
    ----------
    values : array_like
        One figure per stage [signal unit]; non-finite values are skipped.

    Returns
    -------
    float
        :math:`\sqrt{\frac{1}{p'}\sum_s v_s^2}` over the ``p'`` finite values
        [signal unit]; NaN when none is finite.

    Examples
    --------
    >>> round(rms_over_stages([3.0, 4.0, float("nan")]), 3)
    3.536
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v * v))) if v.size else float("nan")


def run_rms_and_peak_to_peak(
    time_s: FloatArray, x: FloatArray, averaging_s: float, tau0_s: float
) -> tuple[float, float]:
    r"""Whole-run rms and peak-to-peak of the averages over ``averaging_s``.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    x : numpy.ndarray
        Signal [its unit].
    averaging_s : float
        Averaging time τ [s].
    tau0_s : float
        Sample interval τ0 [s].

    Returns
    -------
    tuple of float
        ``(rms, peak_to_peak)`` [unit of ``x``]: rms of the block averages about
        their mean and ``max − min`` of the averages; ``(nan, nan)`` when the run
        is shorter than one block.

    Notes
    -----
    .. math:: \mathrm{rms} = \sqrt{\frac{1}{m}\sum_j(\bar x_j - \langle\bar x\rangle)^2},
        \quad \mathrm{p2p} = \max_j \bar x_j - \min_j \bar x_j
    """
    m = block_means(time_s, x, averaging_s, tau0_s)
    if m.size == 0:
        return float("nan"), float("nan")
    d = m - m.mean()
    return float(np.sqrt(np.mean(d * d))), float(m.max() - m.min())


# --- validation -----------------------------------------------------------------------------


def improvement_about_zero_pct(before: float | None, after: float | None) -> float | None:
    r"""Improvement of a figure about zero (a mean, an rms about zero, a largest error),
    judged on its magnitude [%].

    Parameters
    ----------
    before, after : float or None
        The figure before and after compensation (same unit; signed for a mean).

    Returns
    -------
    float or None
        :math:`100\,(|b| - |a|)/|b|`; None when ``before`` is 0 or missing or ``after``
        is missing.

    Notes
    -----
    A compensation that moves the mean from +3 to −1 improved it by 67 %: the sign of a
    mean about zero is not an error of its own.

    .. math::

        I = 100\,\frac{|b| - |a|}{|b|}

    References
    ----------
    IEEE Std 1431-2004, IEEE Standard Specification Format Guide and Test Procedure for
    Coriolis Vibratory Gyros (bias and its temperature sensitivity).

    Examples
    --------
    >>> improvement_about_zero_pct(3.0, -1.0), improvement_about_zero_pct(0.0, 1.0)
    (66.66666666666667, None)
    """
    if not before or after is None:
        return None
    return 100.0 * (abs(before) - abs(after)) / abs(before)


def _correlation(
    modeling_ambient: tuple[npt.ArrayLike, npt.ArrayLike] | None,
    t: FloatArray,
    amb: FloatArray,
    r_limit: float,
    note: Callable[[str, type[Warning]], None],
) -> tuple[float | None, bool | None]:
    """Step 1: ``(r, weakly_correlated)`` of the ambient histories (None, None without a
    modelling history or when r is undefined), the warnings given to ``note``."""
    r: float | None = None
    weak: bool | None = None
    if modeling_ambient is None:
        note(
            "no modelling-test temperature history: the correlation r was not computed (null)",
            CorrelationWarning,
        )
        return r, weak
    try:
        cr = correlate(modeling_ambient[0], modeling_ambient[1], t, amb, r_limit=r_limit)
    except TimestampError:
        raise
    except ThermocalInputError as exc:  # e.g. a constant history: r undefined
        note(f"the correlation r could not be computed: {exc}", CorrelationWarning)
    else:
        r, weak = cr.r, cr.weakly_correlated
    if weak is False:
        note(
            f"the validation test is not weakly correlated with the modelling test: "
            f"r = {r:.3f} ≥ {r_limit}",
            CorrelationWarning,
        )
    return r, weak


def _stages(
    t: FloatArray,
    amb: FloatArray,
    before: FloatArray,
    after: FloatArray,
    averaging_s: float,
    tau0: float,
    holds: tuple[float, float, float],
) -> list[StageFigures]:
    """Step 3: the figures of each hold stage of ``amb`` (``holds``: rate threshold
    [°C/min], shortest stage [s], settling cut [s]; :func:`segment_holds`)."""
    rate, min_s, settle = holds
    segs = segment_holds(
        t, amb, rate_threshold_c_per_min=rate, min_duration_s=min_s, settle_s=settle
    )
    stages: list[StageFigures] = []
    for i, s in enumerate(g for g in segs if g.kind == "hold"):
        sl = s.slice
        ts = t[sl]
        mb = block_means(ts, before[sl], averaging_s, tau0)
        ma = block_means(ts, after[sl], averaging_s, tau0)
        stages.append(
            StageFigures(
                index=i,
                start_s=s.start_s,
                stop_s=s.stop_s,
                mean_temp_c=s.mean_temp_c,
                n_samples=int(ts.size),
                n_averages=int(mb.size),
                bias_before=metrics.bias(before[sl]),
                bias_after=metrics.bias(after[sl]),
                bias_stability_before=stability_of_means(mb),
                bias_stability_after=stability_of_means(ma),
            )
        )
    return stages


def _stage_notes(
    stages: list[StageFigures],
    averaging_s: float,
    rate_threshold_c_per_min: float,
    min_stage_s: float,
    note: Callable[[str, type[Warning]], None],
) -> None:
    """The warnings on the hold stages: fewer than two, or stages too short to average."""
    if len(stages) < 2:
        note(
            f"{len(stages)} temperature-hold stage(s) found (|Ṫ| < {rate_threshold_c_per_min} "
            f"°C/min for ≥ {min_stage_s:g} s): bias repeatability needs at least 2",
            ThermocalWarning,
        )
    short = [s.index for s in stages if s.n_averages < 2]
    if short:
        note(
            f"stage(s) {', '.join(map(str, short))} hold fewer than 2 averages of "
            f"{averaging_s:g} s: left out of the bias stability",
            ThermocalWarning,
        )


def _absolute(
    before: FloatArray,
    after: FloatArray,
    ref: float,
    ref_what: str,
    where: str,
    display_unit: tuple[str, float],
    note: Callable[[str, type[Warning]], None],
) -> tuple[AbsoluteFigures, AbsoluteFigures, list[str]]:
    """Step 6: the per-sample figures about ``ref`` before and after, and those made worse
    (a warning in ``display_unit``, ``(unit, factor)``)."""
    abs_b = absolute_figures(before, ref)
    abs_a = absolute_figures(after, ref)
    worse = absolute_error_worse(abs_b, abs_a)
    if worse:
        du, k = display_unit
        shown = [AbsoluteFigures(a.mean / k, a.rms_about_zero / k, a.max_abs / k)
                 for a in (abs_b, abs_a)]  # fmt: skip
        cause = ref_what.split("; ", 1)[1] if KEPT_IN_BIAS in ref_what else ""
        note(absolute_worse_message(where, du, shown[0], shown[1], worse, cause), ThermocalWarning)
    return abs_b, abs_a, list(worse)


def _compensated(
    model: TemperatureModel,
    run: RunData,
    extrapolate: bool,
    where: str,
    note: Callable[[str, type[Warning]], None],
) -> tuple[FloatArray, tuple[RangeExcess, ...]]:
    """Step 2: the compensated signal and how far the run leaves the calibrated ranges
    (step 7: one warning with the figures, in place of the model's own range warnings)."""
    with warnings.catch_warnings():
        for pattern in RANGE_WARNING_PATTERNS:
            warnings.filterwarnings("ignore", pattern, ExtrapolationWarning)
        comp = compensate_run(model, run, extrapolate=extrapolate)
    excess = outside_range(model, run.time_s, run.temps_c)
    msg = outside_range_message(excess, where, extrapolate=extrapolate)
    if msg:
        note(msg, ExtrapolationWarning)
    return comp.corrected, excess


def _inputs(
    run: RunData, validation_ambient: npt.ArrayLike | None, averaging_s: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The run's time [s], ambient temperature [°C] (default its first temperature
    column) and signal, checked: a signal, a positive averaging time, one ambient value
    per sample."""
    if run.signal is None:
        raise ThermocalInputError(f"{run.name or 'validation run'}: no signal")
    if not averaging_s > 0:
        raise ThermocalInputError(f"averaging time must be positive, got {averaging_s}")
    t = run.time_s
    amb = (
        run.temps_c[:, 0]
        if validation_ambient is None
        else np.asarray(validation_ambient, dtype=np.float64)
    )
    if amb.shape != t.shape:
        raise ThermocalInputError("validation ambient temperature and time differ in length")
    return t, amb, run.signal


def _validate(
    model: TemperatureModel,
    run_validation: RunData,
    modeling_ambient: tuple[npt.ArrayLike, npt.ArrayLike] | None,
    validation_ambient: npt.ArrayLike | None,
    averaging_s: float,
    r_limit: float,
    holds: tuple[float, float, float],
    extrapolate: bool,
    zero_reference: tuple[float, str],
    display_unit: tuple[str, float] | None,
) -> ValidationResult:
    """The work of :func:`validate` (``holds`` = rate threshold, minimum stage, settle)."""
    t, amb, before = _inputs(run_validation, validation_ambient, averaging_s)
    notes: list[str] = []

    def note(msg: str, cat: type[Warning]) -> None:
        notes.append(msg)
        warnings.warn(msg, cat, stacklevel=4)

    # 1. correlation of the ambient histories
    r, weak = _correlation(modeling_ambient, t, amb, r_limit, note)

    # 2. compensation; the model's per-call range warnings give way to one with figures
    where = run_validation.name or "validation run"
    after, excess = _compensated(model, run_validation, extrapolate, where, note)
    tau0 = median_interval(t)
    if not (math.isfinite(tau0) and tau0 > 0):
        raise ThermocalInputError("the validation run needs at least two increasing times")

    # 3. hold stages
    stages = _stages(t, amb, before, after, averaging_s, tau0, holds)
    _stage_notes(stages, averaging_s, holds[0], holds[1], note)

    rms_b, ptp_b = run_rms_and_peak_to_peak(t, before, averaging_s, tau0)
    rms_a, ptp_a = run_rms_and_peak_to_peak(t, after, averaging_s, tau0)
    ref, ref_what = zero_reference
    legs = find_legs(t, amb)
    unit = model.signal_unit
    legs_after, legs_before = (
        compare_legs(legs, amb, after, unit),
        compare_legs(legs, amb, before, unit),
    )
    abs_b, abs_a, worse = _absolute(
        before, after, ref, ref_what, where, display_unit or (model.signal_unit, 1.0), note
    )
    return ValidationResult(
        r=r,
        weakly_correlated=weak,
        r_limit=r_limit,
        n_stages=len(stages),
        stages=tuple(stages),
        bias_stability_before=rms_over_stages([s.bias_stability_before for s in stages]),
        bias_stability_after=rms_over_stages([s.bias_stability_after for s in stages]),
        bias_repeatability_before=repeatability([s.bias_before for s in stages]),
        bias_repeatability_after=repeatability([s.bias_after for s in stages]),
        rms_before=rms_b,
        rms_after=rms_a,
        peak_to_peak_before=ptp_b,
        peak_to_peak_after=ptp_a,
        averaging_s=float(averaging_s),
        unit=model.signal_unit,
        n_samples=run_validation.n_samples,
        warnings=tuple(notes),
        absolute_before=abs_b,
        absolute_after=abs_a,
        zero_reference=float(ref),
        zero_reference_what=ref_what,
        absolute_worse=tuple(worse),
        outside_range=excess,
        legs=legs,
        legs_after=legs_after,
        legs_before=legs_before,
    )


def validate(
    model: TemperatureModel,
    run_validation: RunData,
    modeling_ambient: tuple[npt.ArrayLike, npt.ArrayLike] | None = None,
    *,
    validation_ambient: npt.ArrayLike | None = None,
    averaging_s: float = DEFAULT_AVERAGING_S,
    r_limit: float = WEAK_CORRELATION_LIMIT,
    rate_threshold_c_per_min: float = 0.05,
    min_stage_s: float = 600.0,
    settle_s: float = 0.0,
    extrapolate: bool = False,
    zero_reference: tuple[float, str] = (0.0, "0"),
    display_unit: tuple[str, float] | None = None,
) -> ValidationResult:
    r"""Judge a compensation model on an independent, weakly correlated test.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model; every figure is in ``model.signal_unit``.
    run_validation : RunData
        The validation run (signal in the model's unit, times [s], temperatures [°C]).
    modeling_ambient : tuple of array_like, optional
        ``(time_s, temp_c)`` of the modelling test's ambient temperature [s, °C];
        ``None`` (default) leaves ``r`` undefined and a :class:`CorrelationWarning` says so.
    validation_ambient : array_like, optional
        The validation test's ambient temperature [°C], shape ``(n,)``; default the
        run's first temperature column.
    averaging_s : float, optional
        Averaging time τ of the stability, rms and peak-to-peak figures [s]
        (default ``DEFAULT_AVERAGING_S``).
    r_limit : float, optional
        Correlation below which the test is weakly correlated [-] (default 0.4).
    rate_threshold_c_per_min : float, optional
        Hold detection: largest temperature rate of a hold [°C/min] (default 0.05).
    min_stage_s : float, optional
        Hold detection: shortest hold kept [s] (default 600).
    settle_s : float, optional
        Hold detection: time dropped at the start of each hold [s] (default 0);
        see :func:`thermocal.preprocess.segment_holds`.
    extrapolate : bool, optional
        Evaluate the model outside its fitted range instead of clamping (default False).
    zero_reference : tuple of (float, str), optional
        ``(K, what)``: the level an ideal sensor would output on this run [model unit]
        and its description (:func:`thermocal.compensate.kernels.zero_reference`);
        default ``(0.0, "0")``.
    display_unit : tuple of (str, float), optional
        ``(unit, factor)`` with ``value[model unit] = factor · value[unit]``: the unit
        the warning texts state figures in; default the model's.

    Returns
    -------
    ValidationResult
        Per-stage and whole-run figures before/after compensation, and the verdict.

    Raises
    ------
    ThermocalInputError
        ``averaging_s`` ≤ 0, ambient and run lengths differ, < 2 increasing times.

    Warns
    -----
    CorrelationWarning
        Not weakly correlated (``r ≥ r_limit``), or no modelling history given.
    ThermocalWarning
        Fewer than two hold stages; the absolute error made worse.
    ExtrapolationWarning
        Samples outside the model's calibrated ranges (share and distance per input).

    Notes
    -----
    Ambient correlation, compensated signal, per-stage stability of q block averages,

    .. math::
        r = \frac{\mathrm{Cov}(X, Y)}{\sigma_X \sigma_Y}, \quad
        F' = F - \hat y(T, \dot T, \ldots), \quad
        B_{s} = \sqrt{\frac{1}{q-1}\sum_j (\bar F_j - \langle \bar F\rangle)^2}

    then across stages :func:`rms_over_stages` and :func:`repeatability`.

    References
    ----------
    - *A modelling and validation method for the temperature compensation model of a
      ring-laser gyroscope*, Chinese invention patent, 2017 (r < 0.4).
    - IEEE Std 952-1997, bias, bias stability and bias repeatability.
    """
    return _validate(
        model,
        run_validation,
        modeling_ambient,
        validation_ambient,
        averaging_s,
        r_limit,
        (rate_threshold_c_per_min, min_stage_s, settle_s),
        extrapolate,
        zero_reference,
        display_unit,
    )


__all__ = [
    "DEFAULT_AVERAGING_S",
    "StageFigures",
    "ValidationResult",
    "block_means",
    "improvement_about_zero_pct",
    "repeatability",
    "rms_over_stages",
    "run_rms_and_peak_to_peak",
    "stability_of_means",
    "validate",
]
