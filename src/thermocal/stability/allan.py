"""Overlapping Allan deviation of rate data, confidence intervals and noise terms.

This module is pure numpy/scipy maths (no plotting, no I/O).

Definitions
-----------
Rate samples ``y_i`` (a gyro rate [°/h], an acceleration [mg], ...) with sample
interval ``τ0`` [s] are integrated to the "phase" (angle) ``x_k = τ0 Σ_{i<k} y_i``
(``x_0 = 0``, N = n + 1 phase points).  The overlapping Allan variance at
``τ = m τ0`` is (NIST SP 1065 eq. 11, IEEE Std 952-1997 Annex C)::

    σ²(τ) = 1 / (2 τ² (N − 2m)) · Σ_{k=0}^{N−2m−1} (x_{k+2m} − 2 x_{k+m} + x_k)²

with ``N − 2m`` terms.  The mean rate is removed before the cumulative sum (the
second difference cancels it exactly, and it keeps the cumulative sum small so
rounding does not grow with the bias).

Confidence intervals (SP 1065 §5.3, eq. 45): ``edf · σ̂² / χ²_{p}(edf)`` with
Greenhall & Riley's equivalent degrees of freedom (Greenhall & Riley 2003; SP 1065
§5.3.3) for the power-law noise type α identified at each τ by the lag-1 autocorrelation
of the m-averages (Riley & Greenhall 2004; the B1 ratio where too few averages remain) —
the one implementation of the deviation family's ``oadev``
(:func:`thermocal.stability.family.oadev_edf`), so both give the same intervals, equal to
Stable32's (gyro terms: quantization ↔ α = +2, angle random walk ↔ α = 0, bias
instability ↔ α = −1, rate random walk ↔ α = −2).  SP 1065 Table 5's simple EDF
(:func:`edf_simple`) is kept as a reference formula only: it is too small at the largest m
(the random-walk-FM interval at m ≈ N/3 is too wide).

Noise terms (IEEE Std 952-1997 Annex C): the model ::

    σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π) B² + K² τ/3 + R² τ²/2

is read two ways, both reported by :func:`noise_terms`:

* slope lines: the straight line of slope −1, −½, 0, +½, +1 through the region
  of that slope, read at τ = √3, 1 s, (÷ 0.6643), 3 s, √2 s;
* weighted non-negative least squares of the five coefficients.

A term whose slope region does not exist in the data is ``None`` with a reason.

Units of the terms (native coefficient → reported unit):

===================  ==================  ===========================  =========================
term (JSON key)      rate input [°/h]    acceleration input [mg]      other input [U]
===================  ==================  ===========================  =========================
quantization Q       arcsec              m/s (velocity quantization)  U·s
angle_random_walk N  °/√h                µg/√Hz (velocity r.w.)       U·√s
bias_instability B   °/h                 µg                           U
rate_random_walk K   °/h/√h              µg/√h (accel. random walk)   U/√s
rate_ramp R          °/h/h               µg/h                         U/s
===================  ==================  ===========================  =========================

(``(°/h)·s`` is exactly one arcsec; ``(°/h)·√s = (°/√h)/60``.)  Rates in ``deg/s``
or ``rad/s`` keep the data's own unit (:data:`ANGLE_RATE_TERMS`): Q in arcsec or µrad,
N in °/√h or rad/√h, B in °/s or rad/s, K in (°/s)/√h or (rad/s)/√h, R in (°/s)/h or
(rad/s)/h.  Accelerations in ``g`` and ``ug`` are first scaled to [mg] (their g family);
in ``m/s^2`` they keep the SI family (:data:`SI_ACCEL_TERMS`): Q in m/s, N in m/s/√h,
B in m/s², K in (m/s²)/√h, R in (m/s²)/h.

These are IEEE Std 952's coefficient units (IEEE Std 952-1997 Annex C: Q in angle, ″ or
µrad; N in °/√h; K in (°/h)/√h; B in °/h; R in (°/h)/h = °/h²), expressed in the data's
unit family: every figure in the data's own unit.

References: IEEE Std 952-1997 (R2008) Annex C; W. J. Riley, *Handbook of
Frequency Stability Analysis*, NIST SP 1065 (2008); IEEE Std 1554-2005.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, Final, Literal, cast

import numpy as np
import numpy.typing as npt
from threadpoolctl import threadpool_limits

from thermocal import units
from thermocal.errors import MissingValueError, ParameterError, ThermocalInputError
from thermocal.recording import contiguous_slices
from thermocal.stability import family
from thermocal.stability import quantiles as _quantiles
from thermocal.stability.edf import ONE_SIGMA_CONFIDENCE, confidence_interval
from thermocal.stability.periodic import PeriodicTerm, shaping_terms

# scipy is imported when first needed (a command that reads the help does not pay for it)

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

TauSpec = Literal["octave", "decade", "log"] | npt.ArrayLike

BIAS_INSTABILITY_FACTOR: Final = math.sqrt(2.0 * math.log(2.0) / math.pi)
"""0.6643: flat-region Allan deviation of bias instability is 0.6643 B (IEEE 952 C.3)."""

TERM_NAMES: Final = (
    "quantization",
    "angle_random_walk",
    "bias_instability",
    "rate_random_walk",
    "rate_ramp",
)
"""JSON keys of the noise terms, in order of the power of τ in σ²(τ): −2 … +2."""

TERM_SLOPES: Final = (-1.0, -0.5, 0.0, 0.5, 1.0)
"""Log-log slope of σ(τ) of each term."""

READ_TAU_S: Final = (math.sqrt(3.0), 1.0, float("nan"), 3.0, math.sqrt(2.0))
"""IEEE Std 952 read-off points τ [s] of the slope lines (bias instability: the flat minimum)."""

_FIT_FACTORS: Final = (3.0, 1.0, 2.0 * math.log(2.0) / math.pi, 1.0 / 3.0, 0.5)
"""σ² = Σ_j f_j c_j² τ^(j−2): C_j = f_j · coefficient²."""

_SLOPE_TOLERANCE: Final = 0.25
"""A slope region exists where the local log-log slope is within this of the term's slope."""

_LOCAL_WINDOW: Final = 4.0
"""Local slope fitted over τ*/4 … 4τ* around the tangent point."""

_LINE_TOLERANCE: Final = math.log(1.25)
"""A slope line may exceed the curve's upper confidence bound by at most 25 % before it
is rejected as read off the wrong region (:func:`_read_slope`)."""

_CHUNK: Final = 1 << 16
"""Block length of the second-difference loop (its 512 KiB buffers stay in a core's cache:
on 10⁷ samples 1 << 16 took 0.82× the CPU time of 1 << 18)."""

_SHORT_M: Final = _CHUNK // 4
"""Averaging factors up to this take the second difference as a difference of first
differences (two passes a row instead of three, on a block m rows longer), block by block
for all of them at once (:func:`_block_sums`)."""

_THREADED_FROM: Final = 1 << 20
"""Phase points from which the blocks are shared between threads."""

_RANGES_PER_WORKER: Final = 4
"""Block ranges per thread (the early blocks serve every factor, the late ones the short
factors only: more ranges than threads even the load)."""

_WORKERS: Final = max(1, min(2, os.cpu_count() or 1))
"""Threads sharing the averaging factors of one Allan computation."""


def _worst_above(
    line: FloatArray, ld: FloatArray, hi_ratio: FloatArray, start: int = 0
) -> int | None:
    """The τ index (from ``start``) where a term's log line rises furthest above the log of
    the curve's upper confidence bound ``ld + log(hi_ratio)``, beyond
    :data:`_LINE_TOLERANCE`; None where it never does (every term's line lies below the
    whole curve, σ² being a sum of positive terms)."""
    upper = ld + np.log(np.maximum(hi_ratio, 1.0))
    above = np.flatnonzero(line > upper + _LINE_TOLERANCE)
    above = above[above >= start]
    if not above.size:
        return None
    return int(above[np.argmax(line[above] - upper[above])])


# --- results -------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class AllanResult:
    """Overlapping Allan deviation with confidence intervals.

    Attributes
    ----------
    tau_s : averaging times τ = m τ0 [s].
    m : averaging factors.
    adev : overlapping Allan deviation [unit].
    adev_low, adev_high : confidence interval at ``confidence`` [unit].
    n_terms : number of second differences behind each point (summed over segments).
    edf : Greenhall's equivalent degrees of freedom (summed over segments).
    alpha : power-law noise exponent used for the EDF at each τ.
    alpha_method : how each α was found (``lag1``, ``b1``, ``b1-rn``, ``b1-previous``, ``previous``,
        ``given``; :class:`thermocal.stability.family.DeviationCurve`).
    unit : unit of the rate data and of ``adev``.
    confidence : confidence level of the interval (0.683 = ±1σ).
    tau0_s : sample interval [s].
    n_samples : rate samples used.
    n_segments : contiguous (gap-free) segments combined.
    """

    tau_s: FloatArray
    m: IntArray
    adev: FloatArray
    adev_low: FloatArray
    adev_high: FloatArray
    n_terms: IntArray
    edf: FloatArray
    alpha: IntArray
    unit: str
    confidence: float
    tau0_s: float
    n_samples: int
    n_segments: int
    alpha_method: tuple[str, ...] = ()

    @property
    def avar(self) -> FloatArray:
        """Allan variance σ² [unit²]."""
        return np.asarray(self.adev**2, dtype=np.float64)


@dataclass(frozen=True)
class NoiseTerm:
    """One noise coefficient.

    ``value`` is ``None`` when the term is not in the data, and ``reason`` says why
    (``reason`` is ``None`` when ``value`` is present).  ``low``/``high`` bound the
    value at the result's confidence level; ``tau_s`` is where the slope line
    touches the curve (slope method) or ``None`` (fit).

    Attributes
    ----------
    value : float or None
        The coefficient [``unit``] (None: not in the data).
    unit : str
        Its unit.
    reason : str or None
        Why ``value`` is missing or doubtful.
    low, high : float or None
        Its interval at the result's confidence [``unit``].
    tau_s : float or None
        Where the slope line touches the curve [s] (slope method).
    label : str
        The term's name as shown.
    quality : str or None
        ``"poor"`` when the noise model fits the curve badly.
    tau_range_s : (float, float) or None
        The τ range the value was read from [s].
    """

    value: float | None
    unit: str
    reason: str | None = None
    low: float | None = None
    high: float | None = None
    tau_s: float | None = None
    label: str = ""
    quality: str | None = None
    """``"poor"`` when the noise model fits the curve badly (:class:`FitQuality`); the
    value is kept and ``reason`` says why it is doubtful; None otherwise."""
    tau_range_s: tuple[float, float] | None = None
    """The τ range [s] the value was read from (the −½ stretch of the angle random walk,
    the minimum's neighbours of the bias instability); None when not stated."""


@dataclass(frozen=True)
class FitQuality:
    """How well ``σ² = Σ C_p τ^p`` describes the measured curve.

    ``reduced_chi2`` weighted residual sum of squares per degree of freedom, the weights
    from the points' EDF (χ² with ``dof`` degrees of freedom when the model holds);
    ``p_value`` its upper tail (neighbouring ADEV points are correlated, so this is a
    rough guide); ``misfits`` stretches of at least :data:`MISFIT_RUN` consecutive points
    all on one side of the fit by more than :data:`MISFIT_SIGMA` standard deviations
    (``{"tau_from_s", "tau_to_s", "side", "mean_sigma"}``; side ``"above"`` = the fitted
    curve lies above the points); ``quality`` ``"good"`` or ``"poor"`` (poor: a misfit
    stretch, or a reduced χ² above :data:`POOR_CHI2`); ``reason`` one line.

    Attributes
    ----------
    reduced_chi2 : float
        Weighted residual sum of squares per degree of freedom.
    dof : int
        Degrees of freedom.
    p_value : float
        Upper tail of χ²(dof) at the sum.
    misfits : tuple of dict
        The one-sided stretches described above.
    quality : str
        ``"good"`` or ``"poor"``.
    reason : str or None
        Why poor.
    """

    reduced_chi2: float
    dof: int
    p_value: float
    misfits: tuple[dict[str, Any], ...]
    quality: str
    reason: str | None

    def to_dict(self) -> dict[str, Any]:
        """The fit quality as a JSON-ready dict (misfit runs as dicts)."""
        return {
            "reduced_chi2": self.reduced_chi2,
            "dof": self.dof,
            "p_value": self.p_value,
            "misfits": [dict(m) for m in self.misfits],
            "quality": self.quality,
            "reason": self.reason,
        }


_OTHER_PROCESS: Final = (
    "(another noise process — flicker of a different kind, a periodic term, a drift or a "
    "step — or a wrong time base)"
)
"""The fit quality's words when nothing names what the noise model misses."""

POOR_CHI2 = 4.0
"""Reduced χ² above which the noise model is reported as a poor description."""
MISFIT_RUN = 4
"""Consecutive points on one side of the fit that make a systematic misfit stretch..."""
MISFIT_SIGMA = 1.5
"""... each by more than this many of its standard deviations."""


def fit_quality(tau_s: FloatArray, normalised_residuals: FloatArray, n_active: int) -> FitQuality:
    """:class:`FitQuality` from the fit's residuals ``(σ²_fit − σ̂²)/sd(σ̂²)`` per point.

    Parameters
    ----------
    tau_s : numpy.ndarray
        Averaging times of the fitted points [s].
    normalised_residuals : numpy.ndarray
        Residual of each point over the standard deviation of its Allan variance [1].
    n_active : int
        Number of noise terms with a positive coefficient.

    Returns
    -------
    FitQuality
        Reduced chi-square and the runs of same-sign misfits.
    """
    r = np.asarray(normalised_residuals, dtype=np.float64)
    dof = max(int(r.size) - int(n_active), 1)
    chi2 = float(r @ r)
    red = chi2 / dof
    p_value = _quantiles.chi2_sf(chi2, dof)  # chi-square survival function
    misfits: list[dict[str, Any]] = []
    big = np.abs(r) > MISFIT_SIGMA
    sign = np.sign(r)
    k = 0
    while k < r.size:
        if not big[k]:
            k += 1
            continue
        e = k + 1
        while e < r.size and big[e] and sign[e] == sign[k]:
            e += 1
        if e - k >= MISFIT_RUN:
            misfits.append(
                {
                    "tau_from_s": float(tau_s[k]),
                    "tau_to_s": float(tau_s[e - 1]),
                    "side": "above" if sign[k] > 0 else "below",
                    "mean_sigma": float(np.mean(np.abs(r[k:e]))),
                }
            )
        k = e
    reasons = []
    for m in misfits:
        reasons.append(
            f"the fitted curve lies {m['side']} every point from τ = {m['tau_from_s']:.4g} s "
            f"to {m['tau_to_s']:.4g} s (by {m['mean_sigma']:.2g} standard deviations on average)"
        )
    if red > POOR_CHI2:
        reasons.append(f"reduced χ² = {red:.3g} on {dof} degrees of freedom")
    poor = bool(misfits) or red > POOR_CHI2
    reason = (
        "the noise model σ² = Σ C_p τ^p does not describe this curve: "
        + "; ".join(reasons)
        + f" {_OTHER_PROCESS}; the noise terms are rough"
        if poor
        else None
    )
    return FitQuality(red, dof, p_value, tuple(misfits), "poor" if poor else "good", reason)


@dataclass(frozen=True)
class NoiseTermSet:
    """The five IEEE 952 terms found by one method (``"slope"`` or ``"fit"``).

    Attributes
    ----------
    method : str
        ``"slope"`` or ``"fit"``.
    quantization, angle_random_walk, bias_instability, rate_random_walk, rate_ramp : NoiseTerm
        The five terms of IEEE Std 952-1997 Annex C.
    """

    method: str
    quantization: NoiseTerm
    angle_random_walk: NoiseTerm
    bias_instability: NoiseTerm
    rate_random_walk: NoiseTerm
    rate_ramp: NoiseTerm

    def terms(self) -> dict[str, NoiseTerm]:
        """Terms by JSON key, in order."""
        return {name: getattr(self, name) for name in TERM_NAMES}

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """Each term's object as the ``allan`` command's JSON holds it under ``noise``
        (fit) or ``noise_slope`` (slope lines): ``value``, ``unit``, ``reason``, ``low``,
        ``high``, ``tau_s``, ``label``, ``quality``, ``method`` (this set's, the word the
        noise model's JSON gives) and ``tau_range_s``."""
        return {
            name: {
                "value": t.value,
                "unit": t.unit,
                "reason": t.reason,
                "low": t.low,
                "high": t.high,
                "tau_s": t.tau_s,
                "label": t.label,
                "quality": t.quality,
                "method": self.method,
                "tau_range_s": list(t.tau_range_s) if t.tau_range_s is not None else None,
            }
            for name, t in self.terms().items()
        }


def minimum_dict(t: NoiseTerm | None) -> dict[str, Any] | None:
    """The bias instability at the curve's minimum (:func:`bias_at_minimum`) as
    the ``allan`` command's JSON holds it under ``bias_instability_minimum``.

    Parameters
    ----------
    t : NoiseTerm or None
        :attr:`NoiseTerms.bias_minimum`.

    Returns
    -------
    dict or None
        ``value`` (σ_min/0.6643), ``unit``, ``low``/``high`` (the minimum point's interval
        / 0.6643), ``tau_s`` (the minimum), ``quality`` (good; rough: poorly defined; poor:
        at the record's end, an upper bound), ``reason`` and ``method`` ("minimum"); None
        without a minimum.

    References
    ----------
    IEEE Std 952-1997, annex C.3 (the bias instability read at the flat of the curve).
    """
    if t is None:
        return None
    return {
        "value": t.value,
        "unit": t.unit,
        "low": t.low,
        "high": t.high,
        "tau_s": t.tau_s,
        "quality": t.quality,
        "reason": t.reason,
        "method": "minimum",
    }


@dataclass(frozen=True, eq=False)
class NoiseTerms:
    """Noise terms by both IEEE 952 methods.

    Attributes
    ----------
    slope : slope-line reading.
    fit : weighted non-negative least-squares fit.
    fit_coefficients : C_{−2..2} of ``σ² = Σ C_p τ^p`` [unit² s^p].
    fit_sigma : standard errors of ``fit_coefficients`` (NaN where C = 0).
    reduced_chi2 : weighted residual sum of squares / (points − active terms).
    quality : how well the noise model describes the curve (:class:`FitQuality`).

    Examples
    --------
    White rate noise of 3 °/h per sample at 10 Hz: N = 3·√0.1 / 60 = 0.0158 °/√h.

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 3.0, 20_000)
    >>> terms = noise_terms(overlapping_adev(y, 0.1, unit="deg/h"))
    >>> arw = terms.slope.angle_random_walk
    >>> print(f"{arw.value:.3g} {arw.unit}")
    0.0158 deg/sqrt(h)
    """

    slope: NoiseTermSet
    fit: NoiseTermSet
    fit_coefficients: FloatArray
    fit_sigma: FloatArray
    reduced_chi2: float
    quality: FitQuality | None = None
    bias_minimum: NoiseTerm | None = None
    """The bias instability at the curve's minimum, always (:func:`bias_at_minimum`);
    None without three usable points."""
    shaped_below_s: float | None = None
    """The points at τ below this [s] lie under the −½ stretch's line beyond their
    intervals (the sensor's own filter): left out of the fit and the slope lines."""
    periodic: tuple[PeriodicTerm, ...] = ()
    """Sinusoids found in the record that shape the curve (:func:`annotate_periodic`)."""

    def fit_curve(self, tau_s: npt.ArrayLike) -> FloatArray:
        r"""Fitted Allan deviation sqrt(Σ C_p τ^p) [unit] at ``tau_s``.

        Parameters
        ----------
        tau_s : array_like
            Averaging times [s].

        Returns
        -------
        numpy.ndarray
            Fitted Allan deviation [unit of the rate].

        Notes
        -----
        .. math:: \sigma(\tau) = \sqrt{\textstyle\sum_{p=-2}^{2} C_p \tau^p}

        References
        ----------
        - IEEE Std 952-1997, Annex C (Allan variance noise terms).
        """
        tau = np.asarray(tau_s, dtype=np.float64)
        powers = np.arange(-2, 3)
        design = tau[:, None] ** powers[None, :]
        return np.asarray(np.sqrt(np.maximum(design @ self.fit_coefficients, 0.0)))

    def term_curve(self, name: str, tau_s: npt.ArrayLike) -> FloatArray:
        """Allan deviation [unit] of one fitted term alone at ``tau_s``.

        Parameters
        ----------
        name : str
            Term name, one of ``TERM_NAMES``.
        tau_s : array_like
            Averaging times [s].

        Returns
        -------
        numpy.ndarray
            Allan deviation of that term alone [unit of the rate].
        """
        j = TERM_NAMES.index(name)
        tau = np.asarray(tau_s, dtype=np.float64)
        return np.asarray(np.sqrt(self.fit_coefficients[j] * tau ** float(j - 2)))


# --- tau sets ------------------------------------------------------------------------


def max_averaging_factor(n_samples: int) -> int:
    """Largest m with at least two second differences: ``N − 2m ≥ 2`` with N = n + 1.

    Parameters
    ----------
    n_samples : int
        Number of rate samples n.

    Returns
    -------
    int
        Largest averaging factor m [samples].
    """
    return max((n_samples - 1) // 2, 0)


def averaging_factors(taus: TauSpec, tau0_s: float, n_samples: int) -> IntArray:
    """Averaging factors m for a tau set.

    ``"octave"``: 1, 2, 4, 8, …; ``"decade"``: 1, 2, 4, 10, 20, 40, …;
    ``"log"``: about ten per decade (``round(10^(k/10))``, duplicates removed);
    an array: τ [s] rounded to the nearest multiple of τ0.  Only m with at least
    two terms (``m ≤ (n − 1)/2``) are kept (same set as allantools' ``oadev``).

    Parameters
    ----------
    taus : str or array_like
        ``"octave"``, ``"decade"``, ``"log"`` or averaging times [s].
    tau0_s : float
        Sample interval τ0 [s].
    n_samples : int
        Number of rate samples n.

    Returns
    -------
    numpy.ndarray
        Sorted unique averaging factors m [samples].
    """
    m_max = max_averaging_factor(n_samples)
    if m_max < 1:
        raise ThermocalInputError(
            f"Allan deviation needs at least 3 contiguous samples, got {n_samples}"
        )
    if isinstance(taus, str):
        if taus == "octave":
            m = 2 ** np.arange(math.floor(math.log2(m_max)) + 1)
        elif taus == "decade":
            dec = 10 ** np.arange(math.floor(math.log10(m_max)) + 1)
            m = (dec[:, None] * np.array([1, 2, 4])[None, :]).ravel()
        elif taus == "log":
            k = np.arange(math.floor(10.0 * math.log10(m_max)) + 1)
            m = np.round(10.0 ** (k / 10.0))
        else:
            raise ThermocalInputError(
                f"unknown tau set {taus!r}; use octave, decade, log or a list of τ [s]"
            )
    else:
        tau = np.asarray(taus, dtype=np.float64).ravel()
        if tau.size == 0 or not np.all(np.isfinite(tau)) or np.any(tau <= 0):
            raise ThermocalInputError("averaging times τ must be positive and finite")
        m = np.round(tau / tau0_s)
    m = np.sort(m.astype(np.int64))
    m = m[np.diff(m, prepend=m[:1] - 1) != 0]  # unique (np.unique imports numpy.ma)
    m = np.asarray(m[(m >= 1) & (m <= m_max)], dtype=np.int64)
    if m.size == 0:
        raise ThermocalInputError(
            f"no averaging time τ fits the data: τ0 = {tau0_s:g} s, at most "
            f"{m_max} samples per cluster"
        )
    return m


# --- the estimator -------------------------------------------------------------------


def _phase(rate: FloatArray, overwrite: bool = False) -> FloatArray:
    """x_k = Σ_{i<k} (y_i − ȳ), in units of rate·τ0, *without* its leading x_0 = 0: the
    array returned holds x_1 … x_n (one per rate sample; :func:`second_difference_sums`
    supplies x_0).  With ``overwrite`` (and a writeable ``rate``) it is computed in
    ``rate``'s own buffer: no memory per sample."""
    mean = rate.mean()
    x = rate if overwrite and rate.flags.writeable else np.empty_like(rate)
    np.subtract(rate, mean, out=x)
    np.cumsum(x, out=x)
    return x


def _block_sums(x1: FloatArray, ms: list[int], blocks: range) -> list[list[float]]:
    """Per block ``a`` of ``blocks`` (rows a … a + :data:`_CHUNK` of the second
    difference) and per factor m of ``ms`` (increasing), the block's sum of squared second
    differences: up to :data:`_SHORT_M` as Σ (d_{k+m} − d_k)² with the first differences
    ``d_k = x_{k+m} − x_k`` over its rows and m more (two passes a row), beyond as
    :func:`_long_block`.  The block's phase is read from memory once for every factor, and
    a factor's farthest tap is the next octave's middle one: both stay in the cache between
    the factors.  A block beyond a factor's rows gives 0."""
    n = x1.size
    top = max([mm for mm in ms if mm <= _SHORT_M], default=0)
    diff = np.empty(_CHUNK + top, dtype=np.float64)
    out = np.empty(_CHUNK, dtype=np.float64)
    out2 = np.empty(_CHUNK, dtype=np.float64)
    dots: list[list[float]] = []
    for a in blocks:
        row = []
        for mm in ms:
            b = min(a + _CHUNK, n + 1 - 2 * mm)
            if b <= a:
                row.append(0.0)
                continue
            if mm > _SHORT_M:
                row.append(_long_block(x1, mm, a, b, out[: b - a], out2[: b - a]))
                continue
            d, t = diff[: b - a + mm], out[: b - a]
            lo = max(a, 1)  # rows k ≥ 1 read x_k = x1[k − 1]; k = 0 reads x_0 = 0
            np.subtract(x1[lo + mm - 1 : b + 2 * mm - 1], x1[lo - 1 : b + mm - 1], out=d[lo - a :])
            if a == 0:  # d_0 = x_m − x_0, x_0 = 0
                d[0] = x1[mm - 1] - 0.0
            np.subtract(d[mm:], d[: b - a], out=t)
            row.append(float(np.dot(t, t)))
        dots.append(row)
    return dots


def _long_block(x1: FloatArray, mm: int, a: int, b: int, t: FloatArray, t2: FloatArray) -> float:
    """Σ_{k=a}^{b−1} (x_{k+2m} + x_k − 2·x_{k+m})² for an m beyond :data:`_SHORT_M` (no
    block m rows longer; doubling is exact), in the buffers ``t``, ``t2`` of b − a rows."""
    lo = max(a, 1)  # rows k ≥ 1 read x_k = x1[k − 1]; k = 0 reads x_0 = 0
    r = slice(lo - a, b - a)
    np.add(x1[lo + 2 * mm - 1 : b + 2 * mm - 1], x1[lo - 1 : b - 1], out=t[r])
    np.multiply(x1[lo + mm - 1 : b + mm - 1], 2.0, out=t2[r])
    if a == 0:  # k = 0: x_{2m} + x_0 − 2 x_m, x_0 = 0
        t[0] = x1[2 * mm - 1] + 0.0
        t2[0] = x1[mm - 1] * 2.0
    np.subtract(t, t2, out=t)
    return float(np.dot(t, t))


def _added(parts: list[list[list[float]]], ms: list[int], n: int) -> list[float]:
    """Each factor's block sums (``parts``: :func:`_block_sums` of consecutive block
    ranges) added in block order from 0.0, as one loop over the blocks adds them."""
    totals = [0.0] * len(ms)
    a = 0
    for part in parts:
        for row in part:
            for j, mm in enumerate(ms):
                if a < n + 1 - 2 * mm:
                    totals[j] += row[j]
            a += _CHUNK
    return totals


def second_difference_sums(x1: FloatArray, m: IntArray) -> FloatArray:
    r"""S(m) for each averaging factor m (``x1`` the phase without x_0), block by block,
    each block of the phase read once for all the factors (:func:`_block_sums`): up to
    :data:`_SHORT_M` as a difference of first differences, beyond with three taps.

    The blocks are shared between :data:`_WORKERS` threads (numpy releases the GIL inside
    its loops) in consecutive ranges; each factor's block sums are added in block order, so
    the result does not depend on the threads.  BLAS is held to one thread meanwhile,
    because a multi-threaded ``dot`` inside each worker would oversubscribe the cores.

    Parameters
    ----------
    x1 : numpy.ndarray
        Phase (integrated rate) without x_0 [unit·s].
    m : numpy.ndarray
        Averaging factors [samples].

    Returns
    -------
    numpy.ndarray
        Sum of squared second differences S(m) per factor [(unit·s)²].

    Notes
    -----
    .. math:: S(m) = \sum_{i} (x_{i+2m} - 2x_{i+m} + x_i)^2
              = \sum_{i} (d_{i+m} - d_i)^2, \quad d_i = x_{i+m} - x_i

    References
    ----------
    - NIST SP 1065 (Riley 2008), eq. 11 (overlapping Allan variance from phase).
    """
    ms = sorted({int(v) for v in m.tolist()})
    blocks = range(0, x1.size + 1 - 2 * ms[0], _CHUNK) if ms else range(0)
    workers = _WORKERS if x1.size >= _THREADED_FROM else 1
    step = max(1, -(-len(blocks) // (_RANGES_PER_WORKER * workers)))
    ranges = [blocks[i : i + step] for i in range(0, len(blocks), step)]
    with threadpool_limits(limits=1, user_api="blas"):
        if workers <= 1 or len(ranges) <= 1:
            parts = [_block_sums(x1, ms, r) for r in ranges]
        else:
            with ThreadPoolExecutor(max_workers=workers) as pool:
                parts = list(pool.map(functools.partial(_block_sums, x1, ms), ranges))
    by_m = dict(zip(ms, _added(parts, ms, x1.size), strict=True))
    return np.asarray([by_m[int(v)] for v in m.tolist()], dtype=np.float64)


def edf_simple(n_phase: npt.ArrayLike, m: npt.ArrayLike, alpha: npt.ArrayLike) -> FloatArray:
    """Simple equivalent degrees of freedom of the overlapping Allan variance (a reference
    formula: :func:`overlapping_adev` uses Greenhall's EDF, which this underestimates at
    large m — its 68.3 % interval over-covers near m = N/3).

    NIST SP 1065 Table 5 (Howe, Allan & Barnes simple approximations), with
    N phase points, averaging factor m and noise exponent α:

    * α = +2 (white PM): ``(N+1)(N−2m) / (2(N−m))``
    * α = +1 (flicker PM): ``exp(√(ln((N−1)/2m) · ln((2m+1)(N−1)/4)))``
    * α =  0 (white FM): ``(3(N−1)/2m − 2(N−2)/N) · 4m²/(4m²+5)``
    * α = −1 (flicker FM): ``2(N−2)/(2.3N−4.9)`` for m = 1, ``5N²/(4m(N+3m))`` else
    * α = −2 (random-walk FM): ``(N−2)/(m(N−3)²) · ((N−1)² − 3m(N−1) + 4m²)``

    Parameters
    ----------
    n_phase : array_like
        Number of phase points N.
    m : array_like
        Averaging factors [samples].
    alpha : array_like
        Power-law noise exponent α (+2 … −2).

    Returns
    -------
    numpy.ndarray
        Equivalent degrees of freedom [1].

    References
    ----------
    - NIST SP 1065 (Riley 2008), section 5.3, Table 5.
    """
    N, mm, a = np.broadcast_arrays(
        np.asarray(n_phase, dtype=np.float64),
        np.asarray(m, dtype=np.float64),
        np.asarray(alpha, dtype=np.int64),
    )
    out = np.full(N.shape, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        wpm = (N + 1) * (N - 2 * mm) / (2 * (N - mm))
        fpm = np.exp(
            np.sqrt(
                np.maximum(np.log((N - 1) / (2 * mm)), 0.0) * np.log((2 * mm + 1) * (N - 1) / 4)
            )
        )
        wfm = (3 * (N - 1) / (2 * mm) - 2 * (N - 2) / N) * (4 * mm**2 / (4 * mm**2 + 5))
        ffm = np.where(mm == 1, 2 * (N - 2) / (2.3 * N - 4.9), 5 * N**2 / (4 * mm * (N + 3 * mm)))
        rwfm = (N - 2) / (mm * (N - 3) ** 2) * ((N - 1) ** 2 - 3 * mm * (N - 1) + 4 * mm**2)
    out = np.select([a == 2, a == 1, a == 0, a == -1, a == -2], [wpm, fpm, wfm, ffm, rwfm], out)
    return np.asarray(out, dtype=np.float64)


def _checked_rate(rate: npt.ArrayLike, tau0_s: float, overwrite: bool) -> tuple[FloatArray, bool]:
    """The rate as a 1-D float64 array (the caller's own buffer when it is one, then
    ``overwrite`` may stand) after checking τ0 and that every sample is finite."""
    own = isinstance(rate, np.ndarray) and rate.dtype == np.float64 and rate.ndim == 1
    y = cast(FloatArray, rate) if own else np.asarray(rate, dtype=np.float64)
    if y.ndim != 1:  # a table of axes flattened into one record: a silent wrong number
        raise ParameterError("rate", f"{{name}} must be one-dimensional, got shape {y.shape}")
    if not (math.isfinite(tau0_s) and tau0_s > 0):
        raise ThermocalInputError(f"sample interval τ0 must be positive, got {tau0_s!r}")
    with np.errstate(over="ignore", invalid="ignore"):
        all_finite = math.isfinite(float(np.add.reduce(y))) if y.size else True
    bad = np.zeros(0, dtype=np.intp) if all_finite else np.flatnonzero(~np.isfinite(y))
    if bad.size:
        raise MissingValueError(
            f"rate has {bad.size} NaN/infinite samples (first at row {bad[0]}); "
            "remove them or split the record"
        )
    return y, overwrite and own  # only the caller's own float64 buffer


def _gap_free_slices(
    y: FloatArray, time_s: npt.ArrayLike | None, segments: list[slice] | None
) -> list[slice]:
    """The gap-free index ranges of the record: ``segments`` when given (checked: increasing,
    disjoint, inside the record), else from the time column, else the whole record."""
    if time_s is not None:
        t = np.asarray(time_s, dtype=np.float64).ravel()
        if t.shape != y.shape:
            raise ThermocalInputError(f"time has {t.size} samples but rate has {y.size}")
    if segments is not None:
        return _checked_segments(segments, y.size)
    return [slice(0, y.size)] if time_s is None else contiguous_slices(t)


def _checked_segments(segments: list[slice], n: int) -> list[slice]:
    """The caller's gap-free ranges as ``slice(start, stop)``, refused unless they are
    increasing, disjoint, non-empty, of step 1 and inside the ``n`` samples."""
    out: list[slice] = []
    last = 0
    for sl in segments:
        ok = isinstance(sl, slice) and sl.step in (None, 1)
        a, b, _ = sl.indices(n) if ok else (0, 0, 1)
        given: tuple[Any, ...] = (sl.start, sl.stop) if ok else ()
        if not ok or a < last or b <= a or any(v is not None and not 0 <= v <= n for v in given):
            raise ThermocalInputError(
                f"segments: {sl!r} is not a gap-free range of the {n} samples after the one "
                "before it (slices of step 1, increasing, disjoint, non-empty)"
            )
        out.append(slice(a, b))
        last = b
    if not out:
        raise ThermocalInputError("segments: no range given")
    return out


def _pooled_sums(
    y: FloatArray, slices: list[slice], m: IntArray, overwrite: bool
) -> tuple[FloatArray, IntArray, int, int, list[tuple[int, IntArray]]]:
    """Per averaging factor m, the second-difference sums of squares S and term counts L
    pooled over the segments (``Σ_s S_s``, ``Σ_s L_s`` with ``L_s = N_s + 1 − 2m``), the
    samples and segments used, and per used segment its phase count and the indices of
    the factors it serves (for the EDF)."""
    sums = np.zeros(m.size)
    n_terms = np.zeros(m.size, dtype=np.int64)
    used = 0
    segs = 0
    seg_terms: list[tuple[int, IntArray]] = []
    for sl in slices:
        seg = y[sl]
        n_phase = seg.size + 1
        ok = (n_phase - 2 * m) >= 2
        if not np.any(ok):
            continue
        x1 = _phase(seg, overwrite)
        sums[ok] += second_difference_sums(x1, m[ok])
        del x1
        n_terms[ok] += n_phase - 2 * m[ok]
        used += seg.size
        segs += 1
        seg_terms.append((n_phase, np.flatnonzero(ok)))
    return sums, n_terms, used, segs, seg_terms


def overlapping_adev(
    rate: npt.ArrayLike,
    tau0_s: float,
    taus: TauSpec = "octave",
    *,
    time_s: npt.ArrayLike | None = None,
    segments: list[slice] | None = None,
    unit: str = "deg/h",
    confidence: float = ONE_SIGMA_CONFIDENCE,
    alpha: int | None = None,
    overwrite: bool = False,
    before_sums: Callable[[], object] | None = None,
) -> AllanResult:
    r"""Overlapping Allan deviation of rate data with chi-square intervals.

    Parameters
    ----------
    rate : array_like
        Rate samples y_i [unit], each the mean over its interval τ0.
    tau0_s : float
        Sample interval τ0 [s].
    taus : {"octave", "decade", "log"} or array_like
        A named set or averaging times [s] (:func:`averaging_factors`).
    time_s : array_like, optional
        Sample times [s]: the data are split at gaps, each segment processed alone and
        the per-τ sums of squares pooled, :math:`\sigma^2 = \sum_s S_s / (2 m^2 \sum_s
        L_s)`; the EDFs add.
    segments : list of slice, optional
        The gap-free index ranges, when the caller has them (used with or without
        ``time_s``; increasing, disjoint, inside the record, else refused).
    unit : str
        Unit of ``rate`` (reported, and used by :func:`noise_terms`).
    confidence : float
        Confidence level of ``adev_low``/``adev_high`` (default ±1σ).
    alpha : int, optional
        The noise exponent of the EDF at every τ (default: identified per τ,
        :func:`thermocal.stability.family.oadev_edf`).
    overwrite : bool
        The phase may be accumulated in ``rate``'s own buffer (a writeable float64 array
        the caller no longer needs: its values are destroyed).
    before_sums : callable, optional
        Called once the rate is read for the EDF, before the sums (which may overwrite it)
        start: a caller reading the same buffer in a thread of its own waits there.

    Returns
    -------
    AllanResult
        τ, the deviation, its interval, EDF and noise exponent per τ.

    Raises
    ------
    thermocal.errors.MissingValueError
        NaN or infinite rate samples.
    thermocal.errors.ThermocalInputError
        Too few samples, a bad τ0 or τ list, mismatched time.

    Notes
    -----
    NIST SP 1065 eq. 11 (IEEE Std 952-1997 C.1) on the phase :math:`x_k = \tau_0
    \sum_{i<k} (y_i - \bar y)`:

    .. math:: \sigma^2(\tau) = \frac{1}{2\tau^2(N-2m)}\sum_{k=0}^{N-2m-1}
              (x_{k+2m} - 2x_{k+m} + x_k)^2

    References
    ----------
    .. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.

    Examples
    --------
    >>> y = np.random.default_rng(0).normal(0.0, 3.0, 20_000)
    >>> r = overlapping_adev(y, 0.1, [0.1, 1.0], unit="deg/h")
    >>> [round(float(v), 2) for v in r.adev]
    [2.99, 0.94]
    """
    y, overwrite = _checked_rate(rate, tau0_s, overwrite)
    slices = _gap_free_slices(y, time_s, segments)
    longest = max(sl.stop - sl.start for sl in slices)
    m = averaging_factors(taus, tau0_s, longest)
    if alpha is not None and alpha not in (-2, -1, 0, 1, 2):
        raise ThermocalInputError(f"noise exponent alpha must be −2…2, got {alpha!r}")
    # α and EDF per τ exactly as the family's oadev has them (one implementation),
    # from the segments that give the sums a term, before the phase may overwrite the rate
    with threadpool_limits(limits=1, user_api="blas"):  # the pyramid's dots on our threads
        alphas, methods, edf = family.oadev_edf(
            y, tau0_s, m, segments=[sl for sl in slices if sl.stop - sl.start >= 3], alpha=alpha
        )
    if before_sums is not None:
        before_sums()
    sums, n_terms, used, segs, _seg_terms = _pooled_sums(y, slices, m, overwrite)

    avar = sums / (2.0 * m.astype(np.float64) ** 2 * n_terms)
    adev = np.sqrt(avar)
    tau = np.asarray(m * float(tau0_s), dtype=np.float64)
    lo, hi = confidence_interval(adev, edf, confidence)
    return AllanResult(
        tau, m, adev, np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64),
        n_terms, edf, alphas, unit, float(confidence), float(tau0_s), used, segs, methods,
    )  # fmt: skip


# --- dynamic Allan deviation ---------------------------------------------------------


STATIONARITY_FALSE_ALARM: Final = 0.01
"""Family-wise false-alarm probability of :func:`dynamic_adev`'s stationarity test."""


@dataclass(frozen=True, eq=False)
class DynamicAllan:
    """Overlapping ADEV in sliding windows (dynamic Allan deviation).

    ``t_s`` the windows' centres [s from the first sample]; ``adev`` (windows × τ) [unit],
    NaN where a window is too short for that τ; ``adev_low``/``adev_high`` its interval at
    the whole record's confidence; ``changes`` every (window, τ) where the window's
    deviation and the whole record's differ beyond both their intervals at the test's
    confidence ``test_confidence`` (``{"t_s", "tau_s", "adev", "whole_adev"}``);
    ``stationary`` no such change.

    Attributes
    ----------
    window_s, step_s : float
        Window length and step [s].
    t_s : numpy.ndarray
        Window centres [s from the first sample].
    tau_s : numpy.ndarray
        Averaging times [s].
    adev, adev_low, adev_high : numpy.ndarray
        Deviation and its interval, windows × τ [unit] (NaN: window too short for τ).
    unit : str
        The data's unit.
    test_confidence : float
        Confidence of the change test.
    changes : tuple of dict
        The (window, τ) changes described above.
    """

    window_s: float
    step_s: float
    t_s: FloatArray
    tau_s: FloatArray
    adev: FloatArray
    adev_low: FloatArray
    adev_high: FloatArray
    unit: str
    test_confidence: float
    changes: tuple[dict[str, float], ...]

    @property
    def stationary(self) -> bool:
        """True when no (window, τ) cell differs from the whole record's ADEV."""
        return not self.changes

    def to_dict(self) -> dict[str, Any]:
        """The object the ``allan`` command's JSON holds under ``dynamic``:
        ``window_s``, ``step_s``, ``t_s`` (window centres), ``tau_s``, ``adev`` (windows ×
        τ, NaN where a window is too short), ``adev_low``/``adev_high``, ``unit``,
        ``stationary``, ``changes`` and ``test_confidence``."""
        return {
            "window_s": self.window_s,
            "step_s": self.step_s,
            "t_s": self.t_s.tolist(),
            "tau_s": self.tau_s.tolist(),
            "adev": self.adev.tolist(),
            "adev_low": self.adev_low.tolist(),
            "adev_high": self.adev_high.tolist(),
            "unit": self.unit,
            "stationary": self.stationary,
            "changes": [dict(c) for c in self.changes],
            "test_confidence": self.test_confidence,
        }


DYNAMIC_WINDOW_WORK: Final = 1.5e7
"""Operations one window of :func:`dynamic_adev` costs beyond its sums (its ADEV's noise
identification and intervals: ≈ 15 ms a window measured on one core, at ≈ 1 ns an
operation, the scale of :func:`thermocal.stability.deviations.work`)."""


def check_dynamic_work(
    n_samples: int,
    tau0_s: float,
    window_s: float,
    max_work: float,
    *,
    channels: int = 1,
    where: str = "",
    parameter: str = "window_s",
) -> float:
    """Estimated operations of :func:`dynamic_adev` in windows of ``window_s`` [s] (half a
    window apart) over ``n_samples`` samples every ``tau0_s`` [s], for ``channels``
    channels: windows × (:data:`DYNAMIC_WINDOW_WORK` + 4 n log2 n) with n samples a
    window.  Beyond ``max_work`` a :class:`ThermocalInputError` naming ``where``, the
    window (``parameter``) and ``max_work`` (a window the dynamic ADEV refuses anyway
    costs 0 here: it says why).  An 8 s window on 1e5 samples at 1 Hz is 25 000 windows,
    ≈ 7 minutes.

    Parameters
    ----------
    n_samples : int
        Number of samples.
    tau0_s : float
        Sample interval [s].
    window_s : float
        Window length [s].
    max_work : float
        Largest allowed estimated work [operations].
    channels : int, optional
        Number of channels (default 1).
    where : str, optional
        File or channel named in the error (default none).
    parameter : str, optional
        The caller's parameter that sets the window, as the error names it (default
        ``window_s``; :func:`thermocal.stability.analysis.allan_analysis`: ``dynamic_s``).

    Returns
    -------
    float
        Estimated work [operations].

    Raises
    ------
    ThermocalInputError
        When the estimate exceeds ``max_work``.
    """
    if not max_work > 0:
        raise ParameterError("max_work", f"{{name}} {max_work!r}: give a positive operation count")
    if not (math.isfinite(window_s) and window_s > 0 and tau0_s > 0):
        return 0.0
    n_win = round(window_s / tau0_s)
    if n_win < 8 or n_win > n_samples // 2:
        return 0.0
    step = max(1, round(window_s / 2.0 / tau0_s))
    windows = (n_samples - n_win) // step + 1
    work = channels * windows * (DYNAMIC_WINDOW_WORK + 4.0 * n_win * math.log2(n_win))
    if work > max_work:
        raise ThermocalInputError.naming(
            (f"{where}: " if where else "")
            + f"{{{parameter}}} {window_s:g} s on {n_samples} samples makes {windows} windows"
            + (f" in each of {channels} channels" if channels > 1 else "")
            + f", about {work:.2g} operations, beyond the budget of {max_work:.2g}; give a "
            f"longer window, or raise {{max_work}} to {math.ceil(work / 1e9) * 1e9:.3g} to "
            "run it",
            parameter,
            "max_work",
        )
    return work


def _window_samples(n: int, tau0_s: float, window_s: float, parameter: str) -> int:
    """Samples in a dynamic ADEV window of ``window_s`` [s]: at least 8, at most ``n // 2``."""
    if not (math.isfinite(window_s) and window_s > 0):
        raise ParameterError(parameter, f"{{name}} {window_s!r}: give a window length > 0 [s]")
    n_win = round(window_s / tau0_s)
    if n_win < 8:
        raise ParameterError(
            parameter,
            f"{{name}} {window_s:g} s holds {n_win} samples at τ0 = {tau0_s:g} s; give at "
            "least 8 samples' worth",
        )
    if n_win > n // 2:
        raise ParameterError(
            parameter,
            f"{{name}} {window_s:g} s: the record ({n * tau0_s:g} s) holds fewer than "
            "two windows; give a shorter window",
        )
    return int(n_win)


def dynamic_adev(
    rate: npt.ArrayLike,
    tau0_s: float,
    window_s: float,
    whole: AllanResult,
    *,
    time_s: npt.ArrayLike | None = None,
    step_s: float | None = None,
    parameter: str = "window_s",
) -> DynamicAllan:
    """Dynamic Allan deviation: :func:`overlapping_adev` in windows of ``window_s`` [s]
    stepped by ``step_s`` (default half a window), at the τ of ``whole`` that fit a window
    (Galleani & Tavella, "The dynamic Allan variance", IEEE Trans. UFFC 56(3), 2009).

    Stationarity: a window's ADEV and the whole record's differ when their chi-square
    intervals (NIST SP 1065 eq. 45, each its own EDF) are disjoint, each taken at
    ``1 − 0.01 / comparisons`` (Bonferroni): a stationary record is flagged at ≤ 1 %.

    Parameters
    ----------
    rate : array_like
        Rate samples [unit].
    tau0_s, window_s : float
        Sample interval and window length [s].
    whole : AllanResult
        The whole record's result; ``time_s`` [s], ``step_s`` [s] optional.
    parameter : str, optional
        The caller's parameter that sets the window, as a refusal names it (default
        ``window_s``).

    Returns
    -------
    DynamicAllan
        Per-window deviations and the stationarity verdict.

    Raises
    ------
    ThermocalInputError
        A window that is no length, holds fewer than 8 samples, more than half the record,
        or no τ of ``whole``.
    """
    y = np.asarray(rate, dtype=np.float64).ravel()
    n_win = _window_samples(y.size, tau0_s, window_s, parameter)
    step = max(1, round((step_s if step_s is not None else window_s / 2.0) / tau0_s))
    t = None if time_s is None else np.asarray(time_s, dtype=np.float64).ravel()
    m_all = whole.m[whole.m <= max_averaging_factor(n_win)]
    if m_all.size == 0:
        raise ParameterError(
            parameter, f"{{name}} {window_s:g} s: no τ of the record fits a window"
        )
    starts = list(range(0, y.size - n_win + 1, step))
    results: list[AllanResult | None] = []
    centres = []
    for a in starts:
        sl = slice(a, a + n_win)
        centres.append(
            (a + n_win / 2.0) * tau0_s if t is None else float(np.mean(t[sl][[0, -1]]) - t[0])
        )
        try:
            results.append(
                overlapping_adev(
                    y[sl], tau0_s, m_all * tau0_s, time_s=None if t is None else t[sl],
                    unit=whole.unit, confidence=whole.confidence,
                )
            )  # fmt: skip
        except ThermocalInputError:  # a window cut to pieces by gaps
            results.append(None)
    shape = (len(starts), m_all.size)
    dev, lo, hi, edf = (np.full(shape, np.nan) for _ in range(4))
    for i, r in enumerate(results):
        if r is None:
            continue
        j = np.searchsorted(m_all, r.m)
        dev[i, j], lo[i, j], hi[i, j], edf[i, j] = r.adev, r.adev_low, r.adev_high, r.edf
    cols = np.searchsorted(whole.m, m_all)
    w_dev, w_edf = whole.adev[cols], whole.edf[cols]
    ok = np.isfinite(dev) & (dev > 0) & (edf > 0) & (w_dev > 0)[None, :]
    n_cmp = int(ok.sum())
    test_conf = 1.0 - STATIONARITY_FALSE_ALARM / max(n_cmp, 1)
    changes: list[dict[str, float]] = []
    if n_cmp:
        ii, jj = np.nonzero(ok)
        d_lo, d_hi = confidence_interval(dev[ii, jj], edf[ii, jj], test_conf)
        w_lo, w_hi = confidence_interval(w_dev[jj], w_edf[jj], test_conf)
        apart = (d_lo > w_hi) | (d_hi < w_lo)
        for k in np.flatnonzero(apart):
            changes.append(
                {
                    "t_s": float(centres[ii[k]]),
                    "tau_s": float(m_all[jj[k]] * tau0_s),
                    "adev": float(dev[ii[k], jj[k]]),
                    "whole_adev": float(w_dev[jj[k]]),
                }
            )
    return DynamicAllan(
        window_s=n_win * tau0_s, step_s=step * tau0_s, t_s=np.asarray(centres, dtype=np.float64),
        tau_s=np.asarray(m_all * tau0_s, dtype=np.float64), adev=dev, adev_low=lo,
        adev_high=hi, unit=whole.unit, test_confidence=test_conf, changes=tuple(changes),
    )  # fmt: skip


# --- noise terms -----------------------------------------------------------------------


_SQRT_H_PER_SQRT_S: Final = math.sqrt(units.SECONDS_PER_HOUR)  # √h = 60 √s

ANGLE_RATE_TERMS: Final[dict[str, tuple[tuple[float, str, str], ...]]] = {
    "deg/s": (
        (units.SECONDS_PER_HOUR, "arcsec", "quantization"),  # (°/s)·s = ° = 3600″
        (_SQRT_H_PER_SQRT_S, "deg/sqrt(h)", "angle random walk"),  # °/√s = 60 °/√h
        (1.0, "deg/s", "bias instability"),
        (_SQRT_H_PER_SQRT_S, "deg/s/sqrt(h)", "rate random walk"),
        (units.SECONDS_PER_HOUR, "deg/s/h", "rate ramp"),
    ),
    "rad/s": (
        (1e6, "urad", "quantization"),  # (rad/s)·s = rad = 10⁶ µrad
        (_SQRT_H_PER_SQRT_S, "rad/sqrt(h)", "angle random walk"),
        (1.0, "rad/s", "bias instability"),
        (_SQRT_H_PER_SQRT_S, "rad/s/sqrt(h)", "rate random walk"),
        (units.SECONDS_PER_HOUR, "rad/s/h", "rate ramp"),
    ),
}
"""Noise-term units of rates in [°/s] and [rad/s]: each figure in the data's own unit
(rate terms in the data's rate unit, angle terms in its angle unit) on IEEE 952's time
bases (√h, h); (factor, unit, label) per term as :func:`term_units` gives them."""

SI_ACCEL_TERMS: Final[tuple[tuple[float, str, str], ...]] = (
    (1.0, "m/s", "velocity quantization"),  # (m/s²)·s = m/s
    (_SQRT_H_PER_SQRT_S, "m/s/sqrt(h)", "velocity random walk"),  # m/s/√s = 60 m/s/√h
    (1.0, "m/s^2", "bias instability"),
    (_SQRT_H_PER_SQRT_S, "m/s^2/sqrt(h)", "acceleration random walk"),
    (units.SECONDS_PER_HOUR, "m/s^2/h", "acceleration ramp"),
)
"""Noise-term units of accelerations in [m/s²]: the data's SI family, on IEEE 952's time
bases (√h, h): velocity random walk in m/s/√h."""


def term_units(unit: str) -> tuple[float, tuple[tuple[float, str, str], ...]]:
    """Scale to the base unit and, per term, (factor, unit string, label).

    A native coefficient (in unit·s^k, τ in seconds) times ``scale · factor`` is
    the reported value.  See the module docstring for the table.

    Parameters
    ----------
    unit : str
        Unit of the rate, e.g. ``"deg/s"``.

    Returns
    -------
    tuple
        Scale to the base unit and, per term, (factor, unit string, label).
    """
    try:
        u = units.normalize_signal_unit(unit)
    except ThermocalInputError:
        u = unit
    if u in ANGLE_RATE_TERMS:
        return 1.0, ANGLE_RATE_TERMS[u]
    if u == "m/s^2":
        return 1.0, SI_ACCEL_TERMS
    if u in units.RATE_UNITS:
        return units.RATE_UNITS[u], (
            (1.0, "arcsec", "quantization"),
            (units.ARW_DEG_SQRT_H_PER_DEG_H_SQRT_HZ, "deg/sqrt(h)", "angle random walk"),
            (1.0, "deg/h", "bias instability"),
            (math.sqrt(units.SECONDS_PER_HOUR), "deg/h/sqrt(h)", "rate random walk"),
            (units.SECONDS_PER_HOUR, "deg/h/h", "rate ramp"),
        )
    if u in units.ACCEL_UNITS:
        ug = 1.0 / units.UG_TO_MG
        return units.ACCEL_UNITS[u], (
            (units.MG_TO_MS2, "m/s", "velocity quantization"),
            (ug, "ug/sqrt(Hz)", "velocity random walk"),
            (ug, "ug", "bias instability"),
            (ug * math.sqrt(units.SECONDS_PER_HOUR), "ug/sqrt(h)", "acceleration random walk"),
            (ug * units.SECONDS_PER_HOUR, "ug/h", "acceleration ramp"),
        )
    return 1.0, (
        (1.0, f"{u}*s", "quantization"),
        (1.0, f"{u}*sqrt(s)", "random walk"),
        (1.0, u, "bias instability"),
        (1.0, f"{u}/sqrt(s)", "rate random walk"),
        (1.0, f"{u}/s", "ramp"),
    )


def nnls_small(a: FloatArray, b: FloatArray) -> FloatArray:
    """Non-negative least squares ``min ‖A x − b‖, x ≥ 0`` of a design with few columns
    (the five noise terms), exactly, by enumerating the supports.

    At the optimum x*, the free coefficients S = {j: x*_j > 0} solve the unconstrained
    least squares on the columns S (the Karush–Kuhn–Tucker conditions), so x* is the best
    of the supports whose unconstrained solution is positive (Lawson & Hanson, *Solving
    Least Squares Problems*, 1974, ch. 23, solve the same problem by an active set).  2^k
    small solves for k columns; ``scipy.optimize.nnls`` would cost 0.1–0.3 s of import
    on every ``thermocal allan`` run.

    Parameters
    ----------
    a : numpy.ndarray
        Design matrix, shape (n, k) with small k.
    b : numpy.ndarray
        Right-hand side, shape (n,).

    Returns
    -------
    numpy.ndarray
        Non-negative solution x, shape (k,).

    References
    ----------
    - Lawson, C. L. & Hanson, R. J. (1974). *Solving Least Squares Problems*, ch. 23.
    """
    k = a.shape[1]
    if k > 12:
        raise ValueError(f"nnls_small enumerates 2^k supports; k = {k} is too many")
    best = np.zeros(k)
    best_rss = float(b @ b)
    for mask in range(1, 1 << k):
        cols = [j for j in range(k) if mask >> j & 1]
        sol, _res, rank, _sv = np.linalg.lstsq(a[:, cols], b, rcond=None)
        if rank < len(cols) or np.any(sol <= 0.0):  # supports of independent columns only,
            continue  # as the active set keeps them (fewer points than terms)
        r = a[:, cols] @ sol - b
        rss = float(r @ r)
        if rss < best_rss:
            best_rss = rss
            best = np.zeros(k)
            best[cols] = sol
    return best


_COV_EXACT: Final = 24
"""A stretch of lags between two kinks of the summand shorter than this is summed lag by lag;
a longer one by Gauss–Legendre quadrature with the Euler–Maclaurin end corrections."""

_COV_NODES: Final = 16
"""Gauss–Legendre nodes per longer stretch of lags."""

_COV_REACH: Final = 6
"""Flicker FM's second differences correlate at every lag (∝ 1/l²): summed to this many
times the longer τ beyond the windows' overlap."""


def _gacv_basis(k: FloatArray) -> FloatArray:
    """The three power-law parts of the phase's generalised autocovariance at integer lags
    ``k`` [samples], stacked on a new last axis: ``−|k|/2`` (white FM), ``k² ln|k|``
    (flicker FM), ``|k|³`` (random-walk FM); :func:`_gacv_scale` turns them into
    ``s(t)`` for a record's τ0 and coefficients (white PM C₋₂ left out:
    :func:`avar_covariance` adds its δ exactly).  Second differences cancel the
    ``k² ln τ0`` that a change of unit adds to flicker's part, so lags in samples do."""
    a = np.abs(k)
    flicker = a * a * np.log(np.where(a > 0, a, 1.0))
    return np.stack([-0.5 * a, flicker, a * a * a], axis=-1)


def _gacv_scale(tau0_s: float, coef: FloatArray) -> FloatArray:
    """Weights of :func:`_gacv_basis`'s three parts in ``s(t)`` [unit²·s²]:
    ``C₋₁ τ0``, ``C₀ τ0² / (4 ln 2)``, ``C₁ τ0³ / 4``."""
    return np.array(
        [coef[1] * tau0_s, coef[2] * tau0_s**2 / (4.0 * math.log(2.0)), coef[3] * tau0_s**3 / 4.0]
    )


@functools.cache
def _gauss_legendre() -> tuple[FloatArray, FloatArray]:
    """The :data:`_COV_NODES` Gauss–Legendre nodes and weights on [−1, 1], computed once."""
    x, w = np.polynomial.legendre.leggauss(_COV_NODES)
    return np.asarray(x, dtype=np.float64), np.asarray(w, dtype=np.float64)


_EM_ENDS: Final = np.array([15.0, -4.0, 1.0, -9.0, -4.0, 1.0]) / 24.0
"""Weights of f(a), f(a+1), f(a+2), f(b), f(b−1), f(b−2) in Σ_{l=a}^{b−1} f(l) − ∫_a^b f: the
Euler–Maclaurin terms (f(a) − f(b))/2 + (f′(b) − f′(a))/12, one-sided differences for f′."""

_OFF_A: Final = np.repeat(np.array([0, 1, 2]), 3)
_OFF_B: Final = np.tile(np.array([0, 1, 2]), 3)
_W_AB: Final = np.outer([1.0, -2.0, 1.0], [1.0, -2.0, 1.0]).ravel()
"""The nine phase offsets (a·m, b·m') of two second differences and their weights w_a·w_b."""


def _pair_knots(m1: int, m2: int, n1: float, n2: float, flicker: bool) -> list[int]:
    """The lags where the summand of one pair m1 ≤ m2 has a kink, from the first to the last
    lag summed (the nine offsets, the counts' corners, flicker's tail)."""
    reach = _COV_REACH * m2 if flicker else 0
    lo, hi = -2 * m2 - reach, 2 * m1 + reach
    knots = {a * m1 - b * m2 for a in range(3) for b in range(3)} | {lo, hi}
    knots |= {-int(n1), int(n2)}
    if flicker:
        knots |= {-2 * m2 - f * m2 for f in (1, 2, 4)} | {2 * m1 + f * m2 for f in (1, 2, 4)}
    return sorted(k for k in knots if lo <= k <= hi)


def _lag_points(
    m: IntArray, n_terms: FloatArray, flicker: bool
) -> tuple[IntArray, IntArray, FloatArray, FloatArray]:
    """For every pair (i ≤ j) of points, the lags and weights whose weighted sum of a summand
    smooth between the pair's knots (:func:`_pair_knots`) is its sum over every integer lag:
    lag by lag over stretches of at most :data:`_COV_EXACT`, Gauss–Legendre plus the
    Euler–Maclaurin end terms (:data:`_EM_ENDS`) over longer ones.  Returns the pairs' (i, j),
    each point's pair and the points' lags and weights."""
    ii, jj = np.triu_indices(m.size)
    short: list[tuple[int, int, int]] = []
    long: list[tuple[int, int, int]] = []
    last = np.empty(ii.size)
    for p, (i, j) in enumerate(zip(ii.tolist(), jj.tolist(), strict=True)):
        lo_i, hi_i = (i, j) if m[i] <= m[j] else (j, i)
        knots = _pair_knots(int(m[lo_i]), int(m[hi_i]), n_terms[lo_i], n_terms[hi_i], flicker)
        for a, b in itertools.pairwise(knots):
            (short if b - a <= _COV_EXACT else long).append((a, b, p))
        last[p] = knots[-1]
    sa, sb, sp = np.array(short, dtype=np.int64).reshape(-1, 3).T
    n_s = sb - sa
    start = np.repeat(np.cumsum(n_s) - n_s, n_s)
    lag_s = np.repeat(sa, n_s) + np.arange(int(n_s.sum())) - start
    pair = [np.repeat(sp, n_s), np.arange(ii.size)]
    lags = [lag_s.astype(np.float64), last]
    wts = [np.ones(lag_s.size), np.ones(ii.size)]
    if long:
        la, lb, lp = np.array(long, dtype=np.float64).reshape(-1, 3).T
        x, w = _gauss_legendre()
        half = (lb - la)[:, None] / 2.0
        ends = np.concatenate([la[:, None] + [0.0, 1.0, 2.0], lb[:, None] - [0.0, 1.0, 2.0]], 1)
        pts = np.concatenate([(la + lb)[:, None] / 2.0 + half * x, ends], 1)
        wt = np.concatenate([half * w, np.broadcast_to(_EM_ENDS, (la.size, 6))], 1)
        pair.append(np.repeat(lp.astype(np.int64), x.size + 6))
        lags.append(pts.ravel())
        wts.append(wt.ravel())
    pair_ij = np.column_stack([ii, jj])
    return pair_ij, np.concatenate(pair), np.concatenate(lags), np.concatenate(wts)


def avar_covariance(
    m: npt.ArrayLike, n_terms: npt.ArrayLike, tau0_s: float, coef: npt.ArrayLike
) -> FloatArray:
    r"""Covariance matrix of overlapping Allan variance estimates at several τ, for Gaussian
    noise of Allan variance ``σ²(τ) = Σ_{p=−2..2} C_p τ^p``.

    The points of one record share its data: neighbouring octave points are correlated
    (about 0.5 for white FM, 0.7 flicker FM, 0.9 random-walk FM), which a fit that weights
    them as independent does not see.  Each estimate is a mean of squared second differences
    ``d_k = x_{k+2m} − 2x_{k+m} + x_k`` of the phase; for Gaussian noise (Isserlis)
    ``cov(d_k², d'_j²) = 2c² + 4μμ'c`` with ``c = cov(d_k, d'_j)`` and μ the differences'
    mean (a rate ramp's ``Rτ²``), and c follows from the phase's generalised autocovariance
    ``s(t)``, which second differences see alone (they cancel polynomials of degree one):
    ``c = Σ_{a,b} w_a w_b s(t_a − t_b)``, w = (1, −2, 1), with ``s(t) = (C₋₂/3)·δ(t)``
    (white PM), ``−C₋₁|t|/2`` (white FM), ``C₀ t² ln|t| / (4 ln 2)`` (flicker FM),
    ``C₁|t|³/4`` (random-walk FM), each giving its term of ``σ²(τ)`` exactly.  The lags
    between two kinks of the summand are summed one by one or, over longer stretches, by
    Gauss–Legendre quadrature (:func:`_lag_points`); flicker's infinite reach is cut at
    :data:`_COV_REACH` times the longer τ.  Gaps are ignored (one segment of ``n_terms``
    differences per τ).

    Parameters
    ----------
    m : array_like of int
        Averaging factors of the points [samples].
    n_terms : array_like
        Second differences behind each point (N − 2m) [1].
    tau0_s : float
        Sample interval τ0 [s].
    coef : array_like
        The five coefficients C₋₂ … C₂ of ``σ²(τ)`` [unit²·s^−p], non-negative.

    Returns
    -------
    numpy.ndarray
        Covariance of the Allan variances, shape (len(m), len(m)) [unit⁴].

    Notes
    -----
    .. math::

        \operatorname{cov}(\hat\sigma^2_m, \hat\sigma^2_{m'}) =
        \frac{\sum_l n(l)\,\bigl(2c_{mm'}(l)^2 + 4\mu_m\mu_{m'}c_{mm'}(l)\bigr)}
             {4\tau_m^2\tau_{m'}^2 M M'}

    with n(l) the pairs (k, k + l) of the M and M' differences.

    References
    ----------
    - C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on finite
      differences", PTTI 2003 (the generalised autocovariance of the power-law noises).
    - L. Isserlis, "On a formula for the product-moment coefficient of any order of a normal
      frequency distribution in any number of variables", *Biometrika* 12 (1918) 134–139.
    """
    mm = np.asarray(m, dtype=np.int64)
    c = np.maximum(np.asarray(coef, dtype=np.float64), 0.0)
    geometry = _cov_geometry(mm, np.asarray(n_terms, dtype=np.float64), bool(c[2] > 0))
    return _cov_combine(geometry, tau0_s, c)


_COV_BLOCK: Final = 1 << 15
"""Quadrature points per block of :func:`_cov_geometry` (bounds its temporaries)."""


@dataclass(frozen=True, eq=False)
class _CovGeometry:
    """What :func:`avar_covariance` needs of the points alone (not of the coefficients):
    the pairs (i ≤ j) and their shorter and longer τ's m and n, the sums over lags of the
    products of :func:`_gacv_basis`'s parts (``quad``, (P, 3, 3)) and of the parts
    (``lin``, (P, 3)), each weighted by the quadrature and the pairs counted; and white
    PM's per-offset terms (``pm_same``, ``pm_cross``, ``pm_count``).  One fit computes it
    once and combines it with each model's coefficients (:func:`_cov_combine`)."""

    m: IntArray
    n: FloatArray
    pair_ij: IntArray
    m1: FloatArray
    m2: FloatArray
    quad: FloatArray
    lin: FloatArray
    pm_same: FloatArray
    pm_cross: FloatArray
    pm_count: FloatArray


def _count(lg: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Pairs (k, k + lg) of a stretch of ``a`` and one of ``b`` differences."""
    return np.asarray(np.clip(np.minimum(a, b - lg) - np.maximum(0.0, -lg), 0.0, None))


def _cov_geometry(mm: IntArray, nt: FloatArray, flicker: bool) -> _CovGeometry:
    """The coefficient-free part of :func:`avar_covariance` for averaging factors ``mm``,
    difference counts ``nt``, with flicker FM's reach when ``flicker``."""
    pair_ij, pid, lag, wt = _lag_points(mm, nt, flicker)
    i, j = pair_ij[:, 0], pair_ij[:, 1]
    swap = mm[i] > mm[j]
    first, second = np.where(swap, j, i), np.where(swap, i, j)  # m1 ≤ m2
    m1, m2 = mm[first].astype(np.float64), mm[second].astype(np.float64)
    n1, n2 = nt[first], nt[second]
    n_pairs = i.size
    quad = np.zeros((n_pairs, 3, 3))
    lin = np.zeros((n_pairs, 3))
    for lo in range(0, lag.size, _COV_BLOCK):
        blk = slice(lo, lo + _COV_BLOCK)
        p, lg = pid[blk], lag[blk]
        d = _OFF_A[None, :] * m1[p, None] - _OFF_B[None, :] * m2[p, None]
        g = np.einsum("nkp,k->np", _gacv_basis(d - lg[:, None]), _W_AB)
        w = wt[blk] * _count(lg, n1[p], n2[p])
        for u in range(3):
            lin[:, u] += np.bincount(p, weights=w * g[:, u], minlength=n_pairs)
            for v in range(u, 3):
                quad[:, u, v] += np.bincount(p, weights=w * g[:, u] * g[:, v], minlength=n_pairs)
    quad += np.triu(quad, 1).transpose(0, 2, 1)
    dp = _OFF_A[None, :] * m1[:, None] - _OFF_B[None, :] * m2[:, None]
    same = dp[:, :, None] == dp[:, None, :]
    pm_same = (same * _W_AB).sum(axis=2)  # white PM's δ, times C₋₂/3
    pm_cross = np.einsum("nkjp,j->nkp", _gacv_basis(dp[:, None, :] - dp[:, :, None]), _W_AB)
    pm_count = _count(dp, n1[:, None], n2[:, None]) / same.sum(axis=2)  # each lag once
    return _CovGeometry(mm, nt, pair_ij, m1, m2, quad, lin, pm_same, pm_cross, pm_count)


def _cov_combine(geo: _CovGeometry, tau0_s: float, c: FloatArray) -> FloatArray:
    """:func:`avar_covariance` from its geometry and the (non-negative) coefficients ``c``:
    per pair ``Σ_l n(l)(2c(l)² + 4μμ′c(l))`` with ``c(l)`` linear in the parts."""
    scale = _gacv_scale(tau0_s, c)
    ramp = 8.0 * c[4] * (geo.m1 * tau0_s) ** 2 * (geo.m2 * tau0_s) ** 2  # 4μ₁μ₂, μ = Rτ²
    total = 2.0 * np.einsum("u,nuv,v->n", scale, geo.quad, scale) + ramp * (geo.lin @ scale)
    if c[0] > 0:  # white PM: a δ at the lags where two phase points coincide
        c_pm = geo.pm_same * c[0] / 3.0
        c_o = geo.pm_cross @ scale
        pm = 2.0 * (2.0 * c_o * c_pm + c_pm**2) + ramp[:, None] * c_pm
        total += np.sum(geo.pm_count * pm, axis=1)
    i, j = geo.pair_ij[:, 0], geo.pair_ij[:, 1]
    tau = geo.m.astype(np.float64) * tau0_s
    out = np.zeros((geo.m.size, geo.m.size))
    out[i, j] = total / (4.0 * tau[i] ** 2 * tau[j] ** 2 * geo.n[i] * geo.n[j])
    out[j, i] = out[i, j]
    return out


def _usable(result: AllanResult) -> npt.NDArray[np.bool_]:
    """The ADEV points noise terms can use: finite, above zero, with degrees of freedom."""
    return np.asarray(np.isfinite(result.adev) & (result.adev > 0) & (result.edf > 0))


def _fit_sigma(
    aw: FloatArray,
    w: FloatArray,
    active: npt.NDArray[np.bool_],
    cov_s2: FloatArray,
    red_chi2: float,
) -> FloatArray:
    """Standard errors of the fitted coefficients (NaN where inactive or inseparable).

    The weighted estimate on the active columns is linear in the Allan variances,
    ``Ĉ = B σ̂²`` with ``B = (AᵀWA)⁻¹AᵀW``; its covariance is ``B V Bᵀ`` with V the
    Allan variances' own covariance (:func:`avar_covariance`, neighbouring points
    correlated), not the ``(AᵀWA)⁻¹`` that independent points would give; scaled by the
    reduced χ² when it exceeds 1 (a model that misses something).  ``aw`` the design
    times the weights ``w`` (per point), from a QR factor of its scaled columns."""
    sigma = np.full(5, np.nan)
    if not active.any():
        return sigma
    a_act = aw[:, active]
    col = np.linalg.norm(a_act, axis=0)
    q, r = np.linalg.qr(a_act / col)
    if not np.all(np.abs(np.diag(r)) > 1e-12 * np.abs(r).max()):
        return sigma
    b = np.linalg.solve(r, q.T) * w[None, :] / col[:, None]  # (AᵀWA)⁻¹AᵀW, back substitution
    cov = b @ cov_s2 @ b.T * max(red_chi2, 1.0)
    sigma[active] = np.sqrt(np.maximum(np.diag(cov), 0.0))
    return sigma


def _irls(
    design: FloatArray, s2: FloatArray, edf: FloatArray, cols: npt.NDArray[np.bool_]
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Weighted NNLS of ``s2`` on the columns ``cols`` of ``design``, weights
    ``√(edf/2)/σ²`` iterated three times with the fitted σ² in place of the noisy σ̂²;
    the coefficients (zero outside ``cols``), the weighted design and the weights."""
    model = s2.copy()
    coef = np.zeros(5)
    for _ in range(3):
        w = np.sqrt(edf / 2.0) / model
        aw = design[:, cols] * w[:, None]
        scale = np.linalg.norm(aw, axis=0)
        scale[scale == 0] = 1.0
        coef = np.zeros(5)
        coef[cols] = nnls_small(aw / scale, s2 * w) / scale
        fitted = design @ coef
        model = np.where(fitted > 0, fitted, s2)
    w = np.sqrt(edf / 2.0) / model
    return coef, design * w[:, None], w


def _fit(
    result: AllanResult, significance: float, ok: npt.NDArray[np.bool_] | None = None
) -> tuple[FloatArray, FloatArray, float, list[str | None], FitQuality | None]:
    """Weighted NNLS of σ²(τ) = Σ_{p=−2..2} C_p τ^p (IEEE 952 C.2).

    Weights 1/sd(σ̂²) with sd(σ̂²) = σ² √(2/edf) (chi-square with edf degrees of
    freedom), iterated three times with the fitted σ² in place of the noisy σ̂²
    (:func:`_irls`); standard errors from the Allan variances' covariance across τ
    (:func:`_fit_sigma`, :func:`avar_covariance`), scaled by the reduced χ² when it
    exceeds 1.  While the model fits (reduced χ² ≤ :data:`POOR_CHI2`) and more than one
    term remains, the least significant term below ``significance`` standard errors is
    left out and the fit repeated.  Returns C, sd(C), reduced χ², reasons and the
    fit's quality (:func:`fit_quality`; None without points).  ``ok``: the points
    used (default :func:`_usable`).
    """
    ok = _usable(result) if ok is None else ok
    tau = result.tau_s[ok]
    s2 = result.avar[ok]
    edf = result.edf[ok]
    if tau.size == 0:  # a constant or too short signal: no point to fit
        why = "no Allan deviation point above zero (a constant or too short signal)"
        return np.zeros(5), np.full(5, np.nan), float("nan"), [why] * 5, None
    design = tau[:, None] ** np.arange(-2, 3, dtype=np.float64)[None, :]
    cols = np.ones(5, dtype=bool)
    dropped: dict[int, tuple[float, float]] = {}
    cov_s2: FloatArray | None = None  # of the full model while choosing, the final one after
    geometry: _CovGeometry | None = None  # the points' part of it, computed once
    while True:
        coef, aw, w = _irls(design, s2, edf, cols)
        resid = aw @ coef - s2 * w
        active = coef > 0
        red_chi2 = float(resid @ resid / max(tau.size - int(active.sum()), 1))
        if cov_s2 is None:
            m_ok, n_ok = result.m[ok].astype(np.int64), result.n_terms[ok].astype(np.float64)
            geometry = _cov_geometry(m_ok, n_ok, bool(coef[2] > 0))
            cov_s2 = _cov_combine(geometry, result.tau0_s, np.maximum(coef, 0.0))
        sigma = _fit_sigma(aw, w, active, cov_s2, red_chi2)
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = np.where(active & (coef < significance * sigma), coef / sigma, np.inf)
        if not np.isfinite(ratio).any() or int(active.sum()) <= 1 or red_chi2 > POOR_CHI2:
            break  # all significant, the last term, or a model that does not hold anyway
        j = int(np.argmin(ratio))  # the least significant term leaves the model
        dropped[j] = (float(coef[j]), float(sigma[j]))
        cols[j] = False
    if dropped and geometry is not None:  # the standard errors of the model kept
        cov_s2 = _cov_combine(geometry, result.tau0_s, np.maximum(coef, 0.0))
        sigma = _fit_sigma(aw, w, active, cov_s2, red_chi2)
    reasons: list[str | None] = []
    for j in range(5):
        if j in dropped:
            reasons.append(
                f"not significant: fitted coefficient {dropped[j][0]:.3g} ± "
                f"{dropped[j][1]:.2g} is below {significance:g} standard errors (left out "
                "of the fit)"
            )
        elif coef[j] <= 0:
            reasons.append("the non-negative least-squares fit sets this term to zero")
        elif not np.isfinite(sigma[j]):
            reasons.append("the fit cannot separate this term from the others")
        elif coef[j] < significance * sigma[j]:
            reasons.append(
                f"not significant: fitted coefficient {coef[j]:.3g} ± {sigma[j]:.2g} "
                f"is below {significance:g} standard errors"
            )
        else:
            reasons.append(None)
    quality = fit_quality(tau, resid, int(active.sum()))
    return coef, sigma, red_chi2, reasons, quality


def _local_slope(log_tau: FloatArray, log_dev: FloatArray, edf: FloatArray, k: int) -> float:
    """Weighted LS slope of ln σ vs ln τ over τ*/4 … 4τ*, at least the neighbours of k."""
    near = np.abs(log_tau - log_tau[k]) <= math.log(_LOCAL_WINDOW) + 1e-12
    near[max(k - 1, 0) : k + 2] = True
    if near.sum() < 2:
        return float("nan")
    lt, ld, w = log_tau[near], log_dev[near], np.sqrt(edf[near])
    design = np.column_stack([np.ones_like(lt), lt]) * w[:, None]
    sol, *_ = np.linalg.lstsq(design, ld * w, rcond=None)
    return float(sol[1])


def _read_slope(
    j: int,
    tau: FloatArray,
    lt: FloatArray,
    ld: FloatArray,
    edf: FloatArray,
    local: FloatArray,
    lo_ratio: FloatArray,
    hi_ratio: FloatArray,
) -> tuple[float, float, float, float] | str:
    """Read term j off its slope line; (value, low, high, τ*) in native units, or a reason.

    The region of slope s: the contiguous run of points (at least two) whose local
    slope is within ±0.25 of s and which holds the tangent point τ* (the lowest
    line of slope s touching the curve, argmin ln σ − s ln τ over such points).
    The line's intercept is the EDF-weighted mean of ln σ − s ln τ over the run
    (for bias instability: over τ*/2 … 2τ* within the run, i.e. the flat minimum).
    """
    s = TERM_SLOPES[j]
    inside = np.abs(local - s) <= _SLOPE_TOLERANCE
    if not inside.any():
        return (
            f"no region of slope {s:+g} in the data: local slopes range from "
            f"{np.nanmin(local):+.2f} to {np.nanmax(local):+.2f}"
        )
    g = ld - s * lt
    cand = np.flatnonzero(inside)
    k = int(cand[np.argmin(g[cand])])
    a = k
    while a > 0 and inside[a - 1]:
        a -= 1
    b = k + 1
    while b < inside.size and inside[b]:
        b += 1
    if b - a < 2:
        return (
            f"no region of slope {s:+g} in the data: only the single point τ = {tau[k]:.4g} s "
            f"has a local slope near {s:+g} ({local[k]:+.2f})"
        )
    idx = np.arange(a, b)
    if s == 0.0:
        idx = idx[np.abs(lt[idx] - lt[k]) <= math.log(2.0) + 1e-12]
    intercept = float(np.average(g[idx], weights=edf[idx]))
    best = int(idx[np.argmax(edf[idx])])
    # Every term's line lies below the whole curve (σ² is a sum of positive terms): a
    # line above the curve's upper confidence bound anywhere was read off a region that
    # belongs to something else (e.g. the steep fall of a detrended curve's last points).
    line = intercept + s * lt
    w = _worst_above(line, ld, hi_ratio)
    if w is not None:
        return (
            f"the slope {s:+g} region near τ = {tau[k]:.4g} s is not this noise term: its "
            f"line would lie {math.exp(line[w] - ld[w]):.3g}× above the measured curve at "
            f"τ = {tau[w]:.4g} s"
        )
    if j == 2:
        val = math.exp(intercept) / BIAS_INSTABILITY_FACTOR
    else:
        val = math.exp(intercept + s * math.log(READ_TAU_S[j]))
    return val, val * float(lo_ratio[best]), val * float(hi_ratio[best]), float(tau[k])


_STRETCH_Z: Final = 2.0
"""A point lies on the −½ stretch when the stretch's line passes within this many of its
standard deviations, sd(ln σ̂) = 1/√(2·edf) (σ̂²·edf/σ² is χ² with edf degrees of freedom)..."""

_STRETCH_SLACK: Final = math.log(1.01)
"""... widened by 1 % (neighbouring ADEV points are correlated, the EDF approximate)."""


@dataclass(frozen=True)
class WhiteStretch:
    """The −½ stretch of an ADEV curve (:func:`white_stretch`).

    ``start``/``stop`` the index range of the points used (into the arrays given);
    ``intercept`` c of the line ``ln σ = c − ½ ln τ`` (σ(1 s) = e^c, the white-noise
    coefficient N [unit·√s]); ``shaped_stop`` the leading points ``[0, shaped_stop)`` before
    the stretch that each lie below its line beyond their intervals (the sensor's own low-pass
    filter shapes the short τ: a sum of noise terms never lies below one of them), 0 when
    none.

    Attributes
    ----------
    start, stop : int
        Index range of the points used.
    intercept : float
        c of ``ln σ = c − ½ ln τ``.
    shaped_stop : int
        End of the leading points shaped by the sensor's filter (0: none).
    """

    start: int
    stop: int
    intercept: float
    shaped_stop: int


def white_stretch(
    tau_s: npt.ArrayLike,
    adev: npt.ArrayLike,
    edf: npt.ArrayLike,
    allowed: npt.ArrayLike | None = None,
) -> WhiteStretch | None:
    r"""The −½ stretch of an ADEV curve found in the data, not assumed at the shortest τ.

    A run of consecutive points (``adev`` [unit] at ``tau_s`` [s], each with its ``edf``)
    through which one line of slope −½ passes within each point's interval
    ``ln σ̂ ± (z/√(2·edf) + 1 %)`` (z = :data:`_STRETCH_Z`; the intersection of the
    intervals of ``g = ln σ̂ + ½ ln τ`` is not empty).  Of the maximal runs, the stretch
    is the longest in τ (ln τ_last − ln τ_first) of those of at least three points (else
    two), the one holding more degrees of freedom Σ edf when two are as long; its line's
    intercept is the EDF-weighted mean of g over it (IEEE Std 952-1997 C.3: the
    white-noise coefficient is read on the straight line of slope −½ fitted
    where the curve has that slope; the local slope of a filtered sensor at short τ,
    −0.31, −0.42, is not −½ and its points lie below the line).  None without a run of
    two points.  ``allowed``: the points a run may hold (:func:`noise_terms` passes those
    whose local slope over τ/4 … 4τ is within ±0.25 of −½, so that the wide intervals
    of a few long-τ points do not make a stretch of a curve of another slope).

    Parameters
    ----------
    tau_s : array_like
        Averaging times [s].
    adev : array_like
        Allan deviations [unit].
    edf : array_like
        Equivalent degrees of freedom of each point [1].
    allowed : array_like of bool, optional
        Points a run may hold (default all).

    Returns
    -------
    WhiteStretch or None
        The stretch and its line, or None without a run of two points.

    Notes
    -----
    .. math:: \sigma(\tau) = N / \sqrt{\tau}

    References
    ----------
    - IEEE Std 952-1997, Annex C.3.
    """
    tau = np.asarray(tau_s, dtype=np.float64)
    ok = np.ones(tau.size, dtype=bool) if allowed is None else np.asarray(allowed, dtype=bool)
    ld = np.log(np.asarray(adev, dtype=np.float64))
    w = np.asarray(edf, dtype=np.float64)
    g = ld + 0.5 * np.log(tau)
    half = _STRETCH_Z / np.sqrt(2.0 * w) + _STRETCH_SLACK
    lo, hi = g - half, g + half
    best: tuple[bool, float, float, int, int] | None = None
    lt = np.log(tau)
    b_prev = 0
    for a in range(tau.size):
        if b_prev == tau.size:  # a run reached the last point: later ones are its sub-runs
            break
        if not ok[a]:
            continue
        low, high, b = lo[a], hi[a], a + 1
        while b < tau.size and ok[b] and max(low, lo[b]) <= min(high, hi[b]):
            low, high, b = max(low, lo[b]), min(high, hi[b]), b + 1
        if b <= b_prev or b - a < 2:  # a sub-run of the previous run, or one point
            continue
        b_prev = b
        key = (b - a >= 3, round(float(lt[b - 1] - lt[a]), 9), float(w[a:b].sum()), a, b)
        if best is None or key[:3] > best[:3]:
            best = key
    if best is None:
        return None
    a, b = best[3], best[4]
    c = float(np.average(g[a:b], weights=w[a:b]))
    shaped = 0  # the leading points that lie below the line beyond their intervals
    while shaped < a and hi[shaped] < c:
        shaped += 1
    return WhiteStretch(a, b, c, shaped)


BIAS_MIN_EDF: Final = 5.0
"""The curve's minimum is sought among the points of at least this many degrees of freedom
(their ±1σ interval narrower than a factor 1.9): the last points of a record, of one or two
degrees of freedom, often fall far below the curve by chance."""


def bias_at_minimum(
    tau: FloatArray,
    dev: FloatArray,
    lo_ratio: FloatArray,
    hi_ratio: FloatArray,
    conv: float,
    unit: str,
    label: str,
    edf: FloatArray | None = None,
) -> NoiseTerm:
    r"""The bias instability at the curve's minimum, always (IEEE Std 952-1997 C.3: the flat
    minimum of a bias-instability floor is ``0.6643·B``, so ``B = σ_min / 0.6643``), as
    allan_variance_ros and imu_utils report it.

    ``tau`` [s], ``dev`` [unit] the usable points, ``lo_ratio``/``hi_ratio`` their
    interval over the deviation; ``conv`` the factor to the term's ``unit``.  The value's
    interval is the minimum point's (``σ_low/0.6643 … σ_high/0.6643``), ``tau_s`` the τ of
    the minimum, ``tau_range_s`` its neighbours.  ``quality``: ``good`` when the curve rises
    beyond both intervals after the minimum; ``rough`` when it does not (the minimum is
    poorly defined: a flat floor, a noisy tail); ``poor`` when the minimum is the first
    or the last point (the record's end: σ still falls, B is an upper bound).  ``edf``:
    the points' degrees of freedom; those below :data:`BIAS_MIN_EDF` are left out (when
    others remain).

    Parameters
    ----------
    tau : numpy.ndarray
        Averaging times of the usable points [s].
    dev : numpy.ndarray
        Allan deviations [unit].
    lo_ratio, hi_ratio : numpy.ndarray
        Interval bounds over the deviation [1].
    conv : float
        Factor to the term's unit.
    unit, label : str
        Unit and label of the term.
    edf : numpy.ndarray, optional
        Degrees of freedom of the points (default none).

    Returns
    -------
    NoiseTerm
        Bias instability B with its interval, τ and quality.

    Notes
    -----
    .. math:: B = \sigma_{min} / 0.6643

    References
    ----------
    - IEEE Std 952-1997, Annex C.3.
    """
    if edf is not None and int(np.count_nonzero(edf >= BIAS_MIN_EDF)) >= 3:
        keep = np.asarray(edf >= BIAS_MIN_EDF)
        tau, dev, lo_ratio, hi_ratio = tau[keep], dev[keep], lo_ratio[keep], hi_ratio[keep]
    k = int(np.argmin(dev))
    val = float(dev[k]) / BIAS_INSTABILITY_FACTOR
    lo, hi = val * float(lo_ratio[k]), val * float(hi_ratio[k])
    rng = (float(tau[max(k - 1, 0)]), float(tau[min(k + 1, tau.size - 1)]))
    where = f"read at the curve's minimum τ = {tau[k]:.4g} s (σ_min / 0.6643, IEEE 952 C.3)"
    if k == tau.size - 1:
        quality, why = (
            "poor",
            (
                f"the minimum is the last point (of at least {BIAS_MIN_EDF:g} degrees of "
                "freedom), at the record's end: the curve still falls, so this is an upper "
                "bound; a longer record shows the floor"
            ),
        )
    elif k == 0:
        quality, why = "poor", "the minimum is the shortest τ: the curve rises from its start"
    elif bool(np.any(dev[k + 1 :] * lo_ratio[k + 1 :] > dev[k] * hi_ratio[k])):
        quality, why = "good", ""
    else:
        quality, why = (
            "rough",
            (
                "the minimum is poorly defined: no later point rises beyond both intervals "
                "(a flat floor or a noisy tail)"
            ),
        )
    reason = where + (f"; {quality}: {why}" if why else "")
    return NoiseTerm(
        val * conv, unit, reason, lo * conv, hi * conv, float(tau[k]), label, quality, rng
    )


def _fit_terms(
    specs: tuple[tuple[float, str, str], ...],
    scale: float,
    coef: FloatArray,
    sigma: FloatArray,
    fit_reasons: list[str | None],
    quality: FitQuality | None,
    z: float,
) -> list[NoiseTerm]:
    """The least-squares terms of :func:`noise_terms`: ``√(C_p / f_p)`` in the term's unit,
    the interval ``√((C_p ± z·sd) / f_p)``; ``None`` with the fit's reason where it rejects
    the term; every value marked poor when the fit's quality is."""
    poor = quality is not None and quality.quality == "poor"
    fit_terms: list[NoiseTerm] = []
    for j, (factor, u, label) in enumerate(specs):
        f = _FIT_FACTORS[j] * 1.0
        conv = scale * factor
        if fit_reasons[j] is None:
            val = math.sqrt(coef[j] / f) * conv
            lo = math.sqrt(max(coef[j] - z * sigma[j], 0.0) / f) * conv
            hi = math.sqrt((coef[j] + z * sigma[j]) / f) * conv
            if poor:
                assert quality is not None
                fit_terms.append(
                    NoiseTerm(val, u, quality.reason, lo, hi, None, label, quality="poor")
                )
            else:
                fit_terms.append(NoiseTerm(val, u, None, lo, hi, None, label))
        else:
            fit_terms.append(NoiseTerm(None, u, fit_reasons[j], label=label))

    return fit_terms


def _read_white(
    tau: FloatArray,
    lt: FloatArray,
    ld: FloatArray,
    edf: FloatArray,
    local: FloatArray,
    ratios: tuple[FloatArray, FloatArray],
    allowed: npt.NDArray[np.bool_],
) -> tuple[float, float, float, float, tuple[float, float]] | str:
    """The angle random walk N on the −½ stretch (:func:`white_stretch`): (value, low, high,
    τ of the stretch's best-determined point, the stretch's τ range) in native units, or
    a reason.  The line ``σ = N/√τ`` read at τ = 1 s; the interval spans every point's
    own reading ``σ̂_i √τ_i`` with its interval over the stretch (where along the stretch
    N is read is part of the uncertainty); rejected when the line lies more than 25 % above the
    curve's upper bound at a τ at or beyond the stretch's start (every term lies below the
    curve; only a sensor's own filter pulls the curve below it, at τ shorter than the
    stretch).  ``ratios`` the points' interval bounds over their value; ``allowed`` the
    points the stretch may hold (those no sinusoid shapes)."""
    lo_ratio, hi_ratio = ratios
    st = white_stretch(tau, np.exp(ld), edf, (np.abs(local + 0.5) <= _SLOPE_TOLERANCE) & allowed)
    if st is None:
        slopes = np.diff(ld) / np.diff(lt)
        return (
            "no region of slope -0.5 in the data: no two neighbouring points lie on one line "
            f"of slope −½ within their intervals (slopes between points {np.min(slopes):+.2f} "
            f"… {np.max(slopes):+.2f})"
        )
    idx = np.arange(st.start, st.stop)
    best = int(idx[np.argmax(edf[idx])])
    line = st.intercept - 0.5 * lt
    w = _worst_above(line, ld, hi_ratio, st.start)
    if w is not None:
        return (
            f"the slope -0.5 stretch τ = {tau[st.start]:.4g} … {tau[st.stop - 1]:.4g} s is not "
            f"this noise term: its line would lie {math.exp(line[w] - ld[w]):.3g}× above the "
            f"measured curve at τ = {tau[w]:.4g} s"
        )
    val = math.exp(st.intercept)
    rng = (float(tau[st.start]), float(tau[st.stop - 1]))
    g = ld[idx] + 0.5 * lt[idx]  # each point's own reading of N, with its interval
    lo = math.exp(float(np.min(g + np.log(lo_ratio[idx]))))
    hi = math.exp(float(np.max(g + np.log(hi_ratio[idx]))))
    return val, min(lo, val), max(hi, val), float(tau[best]), rng


def _at(j: int, tau_k: float) -> str:
    return f"the slope {TERM_SLOPES[j]:+g} stretch at τ = {tau_k:.4g} s"


def _slope_terms(
    result: AllanResult,
    specs: tuple[tuple[float, str, str], ...],
    scale: float,
    fit_reasons: list[str | None],
    poor: bool,
    ok: npt.NDArray[np.bool_] | None = None,
    free: npt.NDArray[np.bool_] | None = None,
) -> list[NoiseTerm]:
    """The slope-line terms of :func:`noise_terms` (IEEE 952 C.3, read by
    :func:`_read_slope`, the angle random walk by :func:`_read_white`; bias instability at
    the curve's minimum when the curve turns up); ``ok`` the points used, ``free`` those the
    −½ stretch may hold (:func:`periodic_free`)."""
    ok = _usable(result) if ok is None else ok
    allowed = np.ones(int(ok.sum()), dtype=bool) if free is None else free[ok]
    tau = result.tau_s[ok]
    dev = result.adev[ok]
    lo_ratio = result.adev_low[ok] / dev
    hi_ratio = result.adev_high[ok] / dev
    edf = result.edf[ok]
    slope_terms: list[NoiseTerm] = []
    if tau.size < 3:
        reason = "fewer than three Allan deviation points: no slope can be read"
        return [NoiseTerm(None, u, reason, label=lb) for _f, u, lb in specs]
    lt, ld = np.log(tau), np.log(dev)
    local = np.array([_local_slope(lt, ld, edf, k) for k in range(tau.size)])
    for j, (factor, u, label) in enumerate(specs):
        rng: tuple[float, float] | None = None
        if j == 1:
            white = _read_white(tau, lt, ld, edf, local, (lo_ratio, hi_ratio), allowed)
            term: tuple[float, float, float, float] | str = (
                white if isinstance(white, str) else white[:4]
            )
            rng = None if isinstance(white, str) else white[4]
        else:
            term = _read_slope(j, tau, lt, ld, edf, local, lo_ratio, hi_ratio)
        conv = scale * factor
        k_min = int(np.argmin(dev))
        # a minimum inside the data: the curve rises after it beyond both intervals (a
        # later point's lower bound above the minimum's upper bound), not a noisy tail
        turns_up = 0 < k_min < tau.size - 1 and bool(
            np.any(dev[k_min + 1 :] * lo_ratio[k_min + 1 :] > dev[k_min] * hi_ratio[k_min])
        )
        where = (
            f"the slope {TERM_SLOPES[j]:+g} stretch τ = {rng[0]:.4g} … {rng[1]:.4g} s"
            if rng is not None
            else None
        )
        if j == 2 and (isinstance(term, str) or fit_reasons[j] is not None) and turns_up:
            # IEEE 952 C.3: bias instability is the curve's minimum / 0.664, read wherever
            # the curve turns up again inside the data, whatever the least-squares fit says
            why = term if isinstance(term, str) else fit_reasons[j]
            val = float(dev[k_min]) / BIAS_INSTABILITY_FACTOR
            note = (
                f"read at the curve's minimum τ = {tau[k_min]:.4g} s (minimum / 0.664, "
                f"IEEE 952 C.3); rough: {why}"
            )
            slope_terms.append(
                NoiseTerm(
                    val * conv, u, note, val * float(lo_ratio[k_min]) * conv,
                    val * float(hi_ratio[k_min]) * conv, float(tau[k_min]), label,
                    quality="poor" if poor else "rough",
                )
            )  # fmt: skip
        elif isinstance(term, str):
            slope_terms.append(NoiseTerm(None, u, term, label=label))
        elif fit_reasons[j] is not None:
            # the slope line stands (IEEE 952 C.3), marked rough: the fit does not find it
            val, lo, hi, tau_k = term
            reason = (
                f"read from {where or _at(j, tau_k)}"
                f"; rough: the least-squares fit does not support it ({fit_reasons[j]})"
            )
            slope_terms.append(
                NoiseTerm(
                    val * conv, u, reason, lo * conv, hi * conv, tau_k, label,
                    quality="poor" if poor else "rough", tau_range_s=rng,
                )
            )  # fmt: skip
        else:
            val, lo, hi, tau_k = term
            note = f"read from {where or _at(j, tau_k)}" + (
                " (the flat minimum / 0.664)" if j == 2 else ""
            )
            slope_terms.append(
                NoiseTerm(
                    val * conv, u, note if poor else None, lo * conv, hi * conv, tau_k,
                    label, quality="poor" if poor else None, tau_range_s=rng,
                )
            )  # fmt: skip
    return slope_terms


PERIODIC_CLEAN_SHARE: Final = 0.05
"""A point of the curve is read for the noise terms only where every sinusoid found holds
less than this share of its Allan variance (:meth:`PeriodicTerm.adev_bound`)."""


def periodic_free(result: AllanResult, periodic: tuple[PeriodicTerm, ...]) -> npt.NDArray[np.bool_]:
    """The points of ``result`` whose Allan variance the sinusoids ``periodic`` that shape
    the curve (:func:`~thermocal.stability.periodic.shaping_terms`) hold less than
    :data:`PERIODIC_CLEAN_SHARE` of, as a boolean mask (all True without one).

    Parameters
    ----------
    result : AllanResult
        Allan deviation result.
    periodic : tuple of PeriodicTerm
        Sinusoids that shape the curve.

    Returns
    -------
    numpy.ndarray of bool
        True at the points free of the sinusoids.
    """
    free = np.ones(result.tau_s.size, dtype=bool)
    for p in shaping_terms(periodic, result.tau_s, result.adev):
        with np.errstate(invalid="ignore", divide="ignore"):
            share = p.adev_bound(result.tau_s) ** 2 / result.adev**2
        free &= ~(share >= PERIODIC_CLEAN_SHARE)
    return free


def noise_terms(
    result: AllanResult,
    *,
    significance: float = 3.0,
    confidence: float | None = None,
    periodic: tuple[PeriodicTerm, ...] = (),
) -> NoiseTerms:
    r"""IEEE 952 noise terms by slope-line reading and by weighted least squares.

    Parameters
    ----------
    result : AllanResult
        The overlapping Allan deviation (:func:`overlapping_adev`).
    significance : float
        Standard errors a fitted coefficient must reach to be reported.
    confidence : float, optional
        Confidence level of the terms' intervals (default: the result's).
    periodic : tuple of PeriodicTerm
        Sinusoids found in the record (:func:`thermocal.stability.periodic.periodic_terms`):
        the points where one holds :data:`PERIODIC_CLEAN_SHARE` or more of the Allan
        variance are not read for the −½ stretch (IEEE 952 C.1.7, :func:`periodic_free`).

    Returns
    -------
    NoiseTerms
        The five terms by both methods, the fit and its quality, and the bias instability
        at the curve's minimum (:func:`bias_at_minimum`).

    Notes
    -----
    .. math:: \sigma^2(\tau) = \frac{3Q^2}{\tau^2} + \frac{N^2}{\tau}
              + \frac{2\ln 2}{\pi}B^2 + \frac{K^2\tau}{3} + \frac{R^2\tau^2}{2}

    Fit (IEEE 952 C.2): ``σ²(τ) = Σ_{p=−2..2} C_p τ^p`` by weighted NNLS
    (see :func:`_fit`); ``Q = √(C₋₂/3)``, ``N = √C₋₁``, ``B = √(C₀ π/(2 ln 2))``,
    ``K = √(3C₁)``, ``R = √(2C₂)``.  A coefficient that is zero or below
    ``significance`` standard errors is reported as ``None`` with a reason (and left out
    of the fit, :func:`_fit`).  Interval: ``C ± z·sd(C)`` (z the normal quantile of
    ``confidence``; sd from :func:`avar_covariance`), mapped through the square root.

    Slope lines (IEEE 952 C.3): for slope s ∈ {−1, 0, +½, +1} the region of
    that slope is the run of points whose weighted local slope (ln σ against ln τ
    over τ/4 … 4τ) is within ±0.25 of s and which holds the tangent point τ*
    (the lowest line of slope s touching the curve there).  The line
    ``ln σ = c + s ln τ`` with c the EDF-weighted mean over the run is read at
    τ = √3 s (Q), 3 s (K), √2 s (R); B = σ_flat / 0.6643 with σ_flat
    the weighted mean over τ*/2 … 2τ* (the flat minimum).  The angle random walk N is
    read on the −½ stretch found in the data (:func:`white_stretch`: the points one line
    of slope −½ passes through within their intervals), at τ = 1 s; the points at
    shorter τ that lie below that line (a sensor's own low-pass filter) are left out of
    the fit and the other slope lines (``shaped_below_s``).  A term is reported
    only where its region exists (at least two points) and the least-squares fit
    also finds it significant; otherwise ``None`` with the reason.  The interval
    applies the chi-square interval of the region's best-determined point.

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C.
    """
    conf = result.confidence if confidence is None else confidence
    scale, specs = term_units(result.unit)
    ok = _usable(result)
    free = periodic_free(result, periodic)
    shaped_below: float | None = None
    if int(ok.sum()) >= 3:
        lt, ld, edf = np.log(result.tau_s[ok]), np.log(result.adev[ok]), result.edf[ok]
        local = np.array([_local_slope(lt, ld, edf, k) for k in range(lt.size)])
        st = white_stretch(
            result.tau_s[ok], result.adev[ok], edf,
            (np.abs(local + 0.5) <= _SLOPE_TOLERANCE) & free[ok],
        )  # fmt: skip
        if st is not None and st.shaped_stop:
            used = np.flatnonzero(ok)
            ok = ok.copy()
            ok[used[: st.shaped_stop]] = False
            shaped_below = float(result.tau_s[used[st.shaped_stop]])
    coef, sigma, red_chi2, fit_reasons, quality = _fit(result, significance, ok)
    poor = quality is not None and quality.quality == "poor"
    z = _quantiles.normal_ppf(0.5 + conf / 2.0)  # normal quantile

    fit_terms = _fit_terms(specs, scale, coef, sigma, fit_reasons, quality, z)
    slope_terms = _slope_terms(result, specs, scale, fit_reasons, poor, ok, free)
    minimum = None
    if int(ok.sum()) >= 3:
        dev = result.adev[ok]
        minimum = bias_at_minimum(
            result.tau_s[ok], dev, result.adev_low[ok] / dev, result.adev_high[ok] / dev,
            scale * specs[2][0], specs[2][1], specs[2][2], result.edf[ok],
        )  # fmt: skip
    return NoiseTerms(
        slope=NoiseTermSet("slope", *slope_terms),
        fit=NoiseTermSet("fit", *fit_terms),
        fit_coefficients=coef,
        fit_sigma=sigma,
        reduced_chi2=red_chi2,
        quality=quality,
        bias_minimum=minimum,
        shaped_below_s=shaped_below,
    )


def annotate_periodic(
    terms: NoiseTerms, result: AllanResult, found: tuple[PeriodicTerm, ...]
) -> NoiseTerms:
    r"""``terms`` with the periodic terms ``found`` in the record
    (:func:`thermocal.stability.periodic.periodic_terms`) that shape its curve
    (:func:`~thermocal.stability.periodic.shaping_terms`: ≥ 5 % of the Allan variance at
    τ = 0.371/f₀) in ``periodic``, and every reason that blamed "another noise process"
    naming them with their frequency and amplitude instead (IEEE Std 952-1997 C.1.7: a
    sinusoid's Allan deviation A·sin²(πf₀τ)/(πf₀τ) is not in the noise model).

    Parameters
    ----------
    terms : NoiseTerms
        Noise terms read from the curve.
    result : AllanResult
        Allan deviation result.
    found : tuple of PeriodicTerm
        Periodic terms found in the record.

    Returns
    -------
    NoiseTerms
        ``terms`` with the shaping periodic terms and reworded reasons.

    Notes
    -----
    .. math:: \sigma(\tau) = A \sin^2(\pi f_0 \tau) / (\pi f_0 \tau)

    References
    ----------
    - IEEE Std 952-1997, Annex C.1.7.
    """
    shaping = shaping_terms(found, result.tau_s, result.adev)
    if not shaping:
        return terms
    named = (
        "(" + "; ".join(p.words() for p in shaping) + ": not a term of the noise model; "
        "remove it — a notch at its frequency — or read the terms away from that τ)"
    )

    def fix(t: NoiseTerm) -> NoiseTerm:
        if t.reason is None or _OTHER_PROCESS not in t.reason:
            return t
        return dataclasses.replace(t, reason=t.reason.replace(_OTHER_PROCESS, named))

    def fix_set(ts: NoiseTermSet) -> NoiseTermSet:
        return NoiseTermSet(ts.method, *(fix(t) for t in ts.terms().values()))

    quality = terms.quality
    if quality is not None and quality.reason is not None:
        quality = dataclasses.replace(quality, reason=quality.reason.replace(_OTHER_PROCESS, named))
    return dataclasses.replace(
        terms, slope=fix_set(terms.slope), fit=fix_set(terms.fit), quality=quality,
        periodic=shaping,
    )  # fmt: skip


__all__ = [
    "BIAS_INSTABILITY_FACTOR",
    "ONE_SIGMA_CONFIDENCE",
    "PERIODIC_CLEAN_SHARE",
    "SI_ACCEL_TERMS",
    "TERM_NAMES",
    "AllanResult",
    "DynamicAllan",
    "FitQuality",
    "NoiseTerm",
    "NoiseTermSet",
    "NoiseTerms",
    "WhiteStretch",
    "annotate_periodic",
    "avar_covariance",
    "averaging_factors",
    "bias_at_minimum",
    "confidence_interval",
    "dynamic_adev",
    "edf_simple",
    "fit_quality",
    "noise_terms",
    "overlapping_adev",
    "periodic_free",
    "term_units",
    "white_stretch",
]
