"""Can these data support this answer?  One adequacy check for every calibration command.

A temperature calibration is only as good as the sweep it was fitted on.  Before a fit,
:func:`judge` measures what the recording offers against what the model needs and returns
an :class:`Adequacy` record: each test's figure, threshold and verdict.  The fits of
thermocal (a chamber fit, PX4's and ArduPilot's temperature calibrations, a turntable over
temperature, a production batch) call it; the record is stored in the model file (key
``adequacy``) and in the fit's JSON result; firmware parameters and C export refuse a
calibration whose record failed without an override (:func:`check_for_firmware`).

The tests (figures over every run of a channel together):

``samples_per_coefficient``
    n / p, the samples per fitted coefficient.  n ≤ p cannot be fitted (refused, no
    override); n / p < :data:`MIN_SAMPLES_PER_COEFFICIENT` is refused unless
    ``allow_narrow``.
``temperature_span``
    The span of each temperature column between its 0.1 and 99.9 percentiles [°C] (a
    few spikes do not make a range) against :data:`MIN_SPAN_PER_ORDER_C` × the model's
    polynomial order in T: a cubic over 0.3 °C extrapolates its own noise (the constant
    of such a fit was 5e8 °/h).  ``allow_narrow`` overrides.
``distinct_temperatures``
    Occupied temperature bins (``max(span / 20, 0.1 °C)`` wide, at least
    :data:`MIN_SAMPLES_PER_BIN` samples each) against order + 1: fewer cannot determine
    the polynomial (refused, no override); exactly order + 1 (e.g. a two-point soak for a
    line) determines it but cannot check its shape (a warning).
``range_ends``
    The share of samples in the lowest and the highest tenth of the span [%] (the smaller
    of the two): a range whose ends are held by a handful of samples is warned about.
``rate_range``
    Models with Ṫ terms: the span of Ṫ [°C/min] (1–99 percentiles, Ṫ over
    :data:`RATE_INTERVAL_S`) against :data:`MIN_RATE_SPAN_C_PER_MIN`; a sweep at one rate
    cannot separate Ṫ terms from the constant.  ``allow_narrow`` overrides.
``stillness``
    Motion told from thermal drift (:func:`stillness`): one-second block means against a
    running median over :data:`STILL_WINDOW_S` (slow thermal drift follows the median,
    a bump or a turn does not), judged against the sensor's own noise (the scatter within
    the blocks) and an absolute floor (:data:`MOTION_FLOOR_DEG_S`, :data:`MOTION_FLOOR_MG`).
    Moving more than :data:`MAX_MOVING_SHARE` of the time (a flight log) is refused unless
    ``allow_motion``; shorter episodes are named with their times in a warning.
``firmware_minimum``
    The firmware's own minimum sweep (ArduPilot's learning requires
    :data:`ARDUPILOT_MIN_SPAN_C` °C).

Sources: the temperature-characteristic calibration test plan (the chamber program must
cover the operating range with soaks and ramps; the temperature-rate terms need ramps of
both signs), IEEE Std 952-2020 Annex C
(thermal tests at stabilised and ramped temperatures), ArduPilot's ``TCal`` learning
(``AP_InertialSensor_tempcal.cpp``: a 10 °C minimum span), PX4's
``process_sensor_caldata.py`` (binned cubic per axis).
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import warnings
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.defaults import ALLOW_MOTION, ALLOW_NARROW, overrides_of
from thermocal.errors import ThermocalInputError, ThermocalWarning, spell_parameters
from thermocal.recording import all_finite

FloatArray = npt.NDArray[np.float64]


MIN_SAMPLES_PER_COEFFICIENT = 10.0
"""Fewest samples per fitted coefficient accepted without ``allow_narrow``."""
MIN_SPAN_PER_ORDER_C = 5.0
"""Temperature span needed per polynomial order [°C]: a line 5 °C, a cubic 15 °C."""
N_SPAN_BINS = 20
MIN_BIN_WIDTH_C = 0.1
MIN_SAMPLES_PER_BIN = 3
END_FRACTION = 0.1
MIN_END_SHARE_PCT = 0.5
"""Fewest samples in each end tenth of the span [% of the samples] before a warning."""
RATE_INTERVAL_S = 60.0
MIN_RATE_SPAN_C_PER_MIN = 0.1
"""Narrowest Ṫ span that supports Ṫ terms [°C/min]."""
STILL_BLOCK_S = 1.0
STILL_WINDOW_S = 60.0
STILL_K_SIGMA = 8.0
MOTION_FLOOR_DEG_S = 0.3
"""Smallest departure of a gyro's 1-s mean from its running median taken as motion [°/s]."""
MOTION_FLOOR_MG = 20.0
"""Smallest departure of an accelerometer's 1-s mean from its running median taken as
motion [mg] (about 1.1° of tilt)."""
ROTATING_DEG_S = 20.0
"""A gyro whose median rate exceeds this is turning, not drifting [°/s]."""
MAX_MOVING_SHARE = 0.02
"""Moving more than this share of the time is refused without ``allow_motion``."""
ARDUPILOT_MIN_SPAN_C = 10.0
"""ArduPilot's temperature-calibration learning needs at least this sweep [°C]."""
DEG_H_PER_DEG_S = 3600.0


@dataclass(frozen=True)
class AdequacyTest:
    """One adequacy test: its figure, threshold, verdict and message.

    Attributes
    ----------
    name : str
        The test (``"temperature_span"``, ``"stillness"`` …; module docstring).
    figure : float or None
        What the data offer [``unit``]; None when not judged.
    threshold : float or None
        What the model needs [``unit``].
    unit : str
        Unit of ``figure`` and ``threshold`` (``"°C"``, ``"°C/min"``, ``"%"`` …).
    verdict : str
        ``"pass"``, ``"warn"``, ``"fail"`` or ``"n/a"``.
    override : str or None
        The override that allows a failure (:data:`ALLOW_NARROW`, :data:`ALLOW_MOTION`, as
        a model file records it; the parameter of that name allows it: ``allow_narrow``); None:
        it cannot be overridden.
    message : str
        One line for the user: a template with ``{parameter}`` for each of ``parameters``.
    parameters : tuple of str, optional
        The library parameters ``message`` names (``str()`` of the refusal shows their
        names, the command line its options; :meth:`NamesParameters.naming
        <thermocal.errors.NamesParameters.naming>`).  Default none.
    """

    name: str
    figure: float | None
    threshold: float | None
    unit: str
    verdict: str
    override: str | None
    message: str
    parameters: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite figures → None)."""

        def num(v: float | None) -> float | None:
            return None if v is None or not math.isfinite(v) else float(v)

        return {
            "name": self.name,
            "figure": num(self.figure),
            "threshold": num(self.threshold),
            "unit": self.unit,
            "verdict": self.verdict,
            "override": self.override,
            "message": spell_parameters(self.message, self.parameters),
        }


@dataclass(frozen=True)
class Adequacy:
    """The record of every adequacy test of a fit and the overrides the user gave.

    Attributes
    ----------
    tests : tuple of AdequacyTest
        Every test, in order.
    overrides : tuple of str
        The refusals the user allowed (:data:`ALLOW_NARROW`, :data:`ALLOW_MOTION`).
    subject : str
        What was judged (a channel or a command), for messages.
    """

    tests: tuple[AdequacyTest, ...]
    overrides: tuple[str, ...] = ()
    subject: str = ""

    @property
    def failed(self) -> tuple[AdequacyTest, ...]:
        """The tests whose verdict is ``"fail"``."""
        return tuple(t for t in self.tests if t.verdict == "fail")

    @property
    def refused(self) -> tuple[AdequacyTest, ...]:
        """Failed tests that no given override allows."""
        return tuple(
            t for t in self.failed if t.override is None or t.override not in self.overrides
        )

    @property
    def verdict(self) -> str:
        """``"fail"`` when a failure is not overridden, ``"overridden"`` when every failure
        is, else ``"pass"``."""
        if self.refused:
            return "fail"
        return "overridden" if self.failed else "pass"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: the verdict, the overrides and every test."""
        return {
            "verdict": self.verdict,
            "overrides": list(self.overrides),
            "tests": [t.to_dict() for t in self.tests],
        }

    def merged(self, other: Adequacy) -> Adequacy:
        """The record of both fits' tests (this record's overrides and subject).

        Parameters
        ----------
        other : Adequacy
            Another record whose tests are appended.

        Returns
        -------
        Adequacy
        """
        return Adequacy((*self.tests, *other.tests), self.overrides, self.subject)

    def enforce(self) -> Adequacy:
        """Refuse what is not supported and not overridden; warn for the rest.

        Returns
        -------
        Adequacy
            ``self``.

        Raises
        ------
        ThermocalInputError
            A failed test that no given override allows, naming every missing thing
            and the options that would allow it.

        Warns
        -----
        ThermocalWarning
            For each overridden failure and each ``warn`` verdict.
        """
        refused = self.refused
        if refused:
            hints = sorted({_parameter_of(t.override) for t in refused if t.override})
            hint = (
                " (to fit anyway, knowingly: " + " ".join(f"{{{h}}}" for h in hints) + ")"
                if hints and all(t.override for t in refused)
                else ""
            )
            raise ThermocalInputError.naming(
                "the data cannot support this fit: " + "; ".join(t.message for t in refused) + hint,
                *dict.fromkeys(
                    [*(p for t in refused for p in t.parameters), *(hints if hint else ())]
                ),
            )
        for t in self.failed:
            allow = _parameter_of(t.override or "")
            warnings.warn(
                ThermocalWarning.naming(
                    f"{t.message} — fitted anyway ({{{allow}}}): do not trust this "
                    "calibration beyond what the data cover",
                    *dict.fromkeys((*t.parameters, allow)),
                ),
                stacklevel=2,
            )
        for t in self.tests:
            if t.verdict == "warn":
                warnings.warn(ThermocalWarning.naming(t.message, *t.parameters), stacklevel=2)
        return self


def _parameter_of(override: str) -> str:
    """The parameter that allows an override as a model file records it (``allow_narrow``)."""
    return override.lstrip("-").replace("-", "_")


def from_dict(d: Any) -> dict[str, Any] | None:
    """A stored adequacy record, checked for shape.

    Parameters
    ----------
    d : object
        The ``adequacy`` value of a model file.

    Returns
    -------
    dict or None
        ``d`` when it is a dict with a ``tests`` list; None when absent or malformed.
    """
    if not isinstance(d, dict) or not isinstance(d.get("tests"), list):
        return None
    return d


# --- the tests ---------------------------------------------------------------------------


def _span(temps: FloatArray, *, finite_scratch: bool = False) -> tuple[float, float]:
    """The 0.1 and 99.9 percentiles of the finite temperatures (min and max under 1000).
    ``finite_scratch``: ``temps`` is already finite and may be reordered in place (no
    copy: the percentiles partition it)."""
    t = temps if finite_scratch else temps[np.isfinite(temps)]
    if t.size == 0:
        return math.nan, math.nan
    if t.size < 1000:
        return float(t.min()), float(t.max())
    lo, hi = np.percentile(t, [0.1, 99.9], overwrite_input=True)
    return float(lo), float(hi)


def samples_test(n_samples: int, n_coefficients: int, name: str = "") -> AdequacyTest:
    """Samples per fitted coefficient against :data:`MIN_SAMPLES_PER_COEFFICIENT`.

    Parameters
    ----------
    n_samples : int
        Samples n of the fit (all runs).
    n_coefficients : int
        Coefficients p of the model.
    name : str, optional
        The channel, for the message (default none).

    Returns
    -------
    AdequacyTest
        ``samples_per_coefficient`` with figure n / p; fails (overridable with
        :data:`ALLOW_NARROW`) below the minimum and without override when n ≤ p.

    Examples
    --------
    >>> samples_test(100, 4).verdict, samples_test(4, 4).override is None
    ('pass', True)
    """
    ratio = n_samples / max(n_coefficients, 1)
    if n_samples <= n_coefficients:
        return AdequacyTest(
            "samples_per_coefficient",
            ratio,
            MIN_SAMPLES_PER_COEFFICIENT,
            "samples",
            "fail",
            None,
            f"{name + ': ' if name else ''}{n_samples} samples for {n_coefficients} "
            "coefficients: the fit would pass through the data; record more",
        )
    ok = ratio >= MIN_SAMPLES_PER_COEFFICIENT
    return AdequacyTest(
        "samples_per_coefficient",
        ratio,
        MIN_SAMPLES_PER_COEFFICIENT,
        "samples",
        "pass" if ok else "fail",
        ALLOW_NARROW,
        f"{name + ': ' if name else ''}{n_samples} samples for {n_coefficients} "
        f"coefficients ({ratio:.3g} each; "
        f"{MIN_SAMPLES_PER_COEFFICIENT:g} needed)",
    )


def _distinct_bins(t: FloatArray, lo: float, hi: float, width: float, per_bin: int) -> int:
    """Occupied bins of ``width`` [°C] from ``lo`` to ``hi`` holding ≥ ``per_bin`` samples."""
    span = hi - lo if t.size else 0.0
    if t.size and span > 0:
        counts = np.zeros(0, dtype=np.intp)
        for a in range(0, t.size, 1 << 18):  # in blocks: the bin counts add up
            tb = t[a : a + (1 << 18)]
            idx = np.clip(np.floor((tb - lo) / width).astype(np.int64), 0, None)
            c = np.bincount(idx[(tb >= lo) & (tb <= hi)])
            if c.size > counts.size:
                c[: counts.size] += counts
                counts = c
            else:
                counts[: c.size] += c
        return int(np.count_nonzero(counts >= per_bin))
    return 1 if t.size else 0


def _range_ends_test(t: FloatArray, lo: float, hi: float, name: str) -> AdequacyTest:
    """The share of samples [%] in the lowest and highest tenth of ``lo…hi`` (the smaller)."""
    span = hi - lo
    low = float(np.count_nonzero(t <= lo + END_FRACTION * span)) / t.size * 100.0
    high = float(np.count_nonzero(t >= hi - END_FRACTION * span)) / t.size * 100.0
    share = min(low, high)
    end = "lowest" if low <= high else "highest"
    return AdequacyTest(
        "range_ends",
        share,
        MIN_END_SHARE_PCT,
        "%",
        "pass" if share >= MIN_END_SHARE_PCT else "warn",
        None,
        f"{name}: the {end} tenth of the range holds {share:.2g} % of the samples: "
        "the model's end there rests on few samples (soak longer at the ends)",
    )


def temperature_tests(
    temps: FloatArray, name: str, order: int, *, unit: str = "°C", scratch: bool = False
) -> list[AdequacyTest]:
    """Span, distinct temperatures and coverage of the ends of one temperature column.

    Parameters
    ----------
    temps : numpy.ndarray
        The column's temperatures over all runs together [°C].
    name : str
        The column, for messages.
    order : int
        The model's polynomial order in this column.
    unit : str, optional
        Unit of ``temps``; anything but ``"°C"`` (raw counts) is not judged.
    scratch : bool, optional
        ``temps`` is the caller's own array and may be reordered in place: no copy of it
        when it is finite (the same figures: the tests do not use the order).  Default
        ``False``.

    Returns
    -------
    list of AdequacyTest
        ``temperature_span`` (0.1–99.9 percentile span against
        :data:`MIN_SPAN_PER_ORDER_C` × order), ``distinct_temperatures`` (occupied bins
        against order + 1) and ``range_ends`` (share in the lowest and highest tenth).
    """
    if unit != "°C":
        return [
            AdequacyTest(
                "temperature_span",
                None,
                None,
                unit,
                "n/a",
                None,
                f"{name}: temperatures in raw {unit} without a conversion: span not judged",
            )
        ]
    # a copy (unless the caller's own), reordered by the percentiles (order is not used)
    t = temps if scratch and all_finite(temps) else temps[np.isfinite(temps)]
    lo, hi = _span(t, finite_scratch=True)
    span = hi - lo if t.size else 0.0
    need = MIN_SPAN_PER_ORDER_C * max(order, 1)
    out = [
        AdequacyTest(
            "temperature_span",
            span,
            need,
            "°C",
            "pass" if span >= need else "fail",
            ALLOW_NARROW,
            (
                f"{name} is constant at {lo:.2f} °C"
                if span == 0
                else f"{name} spans {span:.3g} °C ({lo:.2f}…{hi:.2f} °C)"
            )
            + f"; a model of order {order} in temperature needs ≥ {need:g} °C: record a "
            "wider sweep",
        )
    ]
    width = max(span / N_SPAN_BINS, MIN_BIN_WIDTH_C)
    per_bin = max(1, min(MIN_SAMPLES_PER_BIN, t.size // (3 * N_SPAN_BINS)))
    distinct = _distinct_bins(t, lo, hi, width, per_bin)
    if distinct < order + 1:
        verdict, override = "fail", None
        msg = (
            f"{name} holds {distinct} distinct temperature(s) (bins of {width:.2g} °C with "
            f"≥ {per_bin} samples); a polynomial of order {order} needs "
            f"≥ {order + 1}: add soak temperatures or fit a lower order"
        )
    elif distinct == order + 1:
        verdict, override = "warn", None
        msg = (
            f"{name} holds {distinct} distinct temperatures for a polynomial of order "
            f"{order}: the fit passes through them and cannot show whether the shape is "
            "right; add a temperature"
        )
    else:
        verdict, override, msg = "pass", None, f"{name}: {distinct} distinct temperatures"
    out.append(
        AdequacyTest(
            "distinct_temperatures",
            float(distinct),
            float(order + 1),
            "bins",
            verdict,
            override,
            msg,
        )
    )
    if t.size and span > 0:
        out.append(_range_ends_test(t, lo, hi, name))
    return out


def temperature_rate_c_per_min(
    time_s: FloatArray, temps: FloatArray, interval_s: float = RATE_INTERVAL_S
) -> FloatArray:
    r"""Temperature rate by a backward difference over ``interval_s``.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s], increasing.
    temps : numpy.ndarray
        Temperatures [°C].
    interval_s : float, optional
        Δ of the difference [s] (default :data:`RATE_INTERVAL_S`).

    Returns
    -------
    numpy.ndarray
        Ṫ [°C/min] for the samples at least Δ after the start.

    Notes
    -----
    .. math:: \dot T(t) = 60\,\frac{T(t) - T(t - \Delta)}{\Delta}

    with :math:`T(t-\Delta)` interpolated linearly.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 600.0, 1.0)
    >>> round(float(temperature_rate_c_per_min(t, 0.01 * t, 60.0)[0]), 3)
    0.6
    """
    if time_s.size < 2:
        return np.empty(0)
    keep = time_s >= time_s[0] + interval_s
    i0 = int(np.argmax(keep))
    if not keep[i0]:
        return np.empty(0)
    if not keep[i0:].all():  # a time axis out of order: the samples kept picked out
        back = np.interp(time_s[keep] - interval_s, time_s, temps)
        return (temps[keep] - back) / interval_s * 60.0  # type: ignore[no-any-return]
    # increasing time: the samples kept are a tail; T(t − Δ) interpolated a block at a time
    # into the result (np.interp's values, without its slope table as long as the column)
    tc = np.ascontiguousarray(temps)
    out = np.empty(time_s.size - i0)
    for a in range(i0, time_s.size, _RATE_BLOCK):
        b = min(time_s.size, a + _RATE_BLOCK)
        part = out[a - i0 : b - i0]
        part[:] = np.interp(time_s[a:b] - interval_s, time_s, tc)
        np.subtract(tc[a:b], part, out=part)
    out /= interval_s
    out *= 60.0
    return out


_RATE_BLOCK = 1 << 16
"""Samples per block of :func:`temperature_rate_c_per_min`."""


def rate_test(rates_c_per_min: FloatArray, name: str) -> AdequacyTest:
    """The span of the temperature rate against :data:`MIN_RATE_SPAN_C_PER_MIN`.

    Parameters
    ----------
    rates_c_per_min : numpy.ndarray
        Ṫ [°C/min] (:func:`temperature_rate_c_per_min`); non-finite values skipped.
    name : str
        The temperature column, for the message.

    Returns
    -------
    AdequacyTest
        ``rate_range`` with the 1–99 percentile span [°C/min]; fails (overridable
        with :data:`ALLOW_NARROW`) below the minimum.
    """
    r = rates_c_per_min[np.isfinite(rates_c_per_min)]
    if r.size == 0:
        span, lo, hi = 0.0, math.nan, math.nan
    else:
        lo, hi = (float(v) for v in np.percentile(r, [1.0, 99.0]))
        span = hi - lo
    ok = span >= MIN_RATE_SPAN_C_PER_MIN
    return AdequacyTest(
        "rate_range",
        span,
        MIN_RATE_SPAN_C_PER_MIN,
        "°C/min",
        "pass" if ok else "fail",
        ALLOW_NARROW,
        f"{name}: Ṫ spans {span:.3g} °C/min ({lo:.3g}…{hi:.3g}); the model's Ṫ terms need "
        f"≥ {MIN_RATE_SPAN_C_PER_MIN:g} °C/min (ramps up and down) or a model without them",
    )


def firmware_test(span_c: float, firmware: str, minimum_c: float) -> AdequacyTest:
    """The sweep against a firmware's minimum temperature span.

    Parameters
    ----------
    span_c : float
        The sweep's span [°C].
    firmware : str
        The firmware's name, for the message (``"ArduPilot"`` …).
    minimum_c : float
        The smallest span that firmware's calibration accepts [°C]
        (e.g. :data:`ARDUPILOT_MIN_SPAN_C`).

    Returns
    -------
    AdequacyTest
        ``firmware_minimum``; fails (overridable with :data:`ALLOW_NARROW`) below
        ``minimum_c``.

    References
    ----------
    - ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``:
      ``TEMP_RANGE_MIN`` = 10 [°C], and ``INS_TCALn_TMAX`` "must be at least 10
      degrees above TMIN".
    """
    ok = span_c >= minimum_c
    return AdequacyTest(
        "firmware_minimum",
        span_c,
        minimum_c,
        "°C",
        "pass" if ok else "fail",
        ALLOW_NARROW,
        f"the sweep spans {span_c:.3g} °C; {firmware}'s temperature calibration needs "
        f"≥ {minimum_c:g} °C",
    )


@dataclass(frozen=True)
class Motion:
    """What :func:`stillness` found.

    Attributes
    ----------
    share : float
        Share of the time moving [-].
    peak : float
        Largest departure from the running median [the given unit].
    threshold : float
        The threshold used [the given unit].
    episodes : list of (float, float, float)
        The bumps: start [s], end [s], peak [the given unit].
    rotating : float or None
        The median level's norm [the given unit] (a gyro turning), None without one.
    steps : list of (float, float, float or None)
        The steps: time [s], size [the given unit], angle between the levels before
        and after [°] (None without a level to measure it by).
    """

    share: float
    peak: float
    threshold: float
    episodes: list[tuple[float, float, float]] = field(default_factory=list)
    rotating: float | None = None
    steps: list[tuple[float, float, float | None]] = field(default_factory=list)


MAX_PER_BLOCK = 64
"""Samples a block's median is taken over (longer blocks are decimated evenly)."""
SIGMA_SAMPLES = 200_000
"""Samples the sensor's own noise is estimated from (an even subsample of long records)."""


def _block_stats(
    time_s: FloatArray, values: FloatArray, block_s: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Per occupied block: start time [s], samples, median (n_blocks, m), and the sensor's
    own noise σ_w per column (1.4826 × the median absolute deviation from the block
    medians, all blocks together).  Medians, so that isolated spikes are not motion; long
    blocks are decimated evenly to about :data:`MAX_PER_BLOCK` samples first (a median
    needs no more), so the cost is linear in the record and small (time increases, so the
    blocks are runs of consecutive samples: no sort of the record)."""
    n = time_s.size
    span_blocks = int((time_s[-1] - time_s[0]) / block_s) + 1
    step = max(1, math.ceil(n / span_blocks / MAX_PER_BLOCK))
    t_d = time_s[::step]
    v = values[::step]
    idx = ((t_d - time_s[0]) / block_s).astype(np.int64)
    starts = np.r_[0, np.flatnonzero(np.diff(idx)) + 1]
    counts = np.diff(np.r_[starts, idx.size])
    m = v.shape[1]
    med = np.empty((starts.size, m))
    sigma = np.empty(m)
    every = max(1, idx.size // SIGMA_SAMPLES)  # the noise from an even subsample
    equal = bool(np.all(counts == counts[0]))
    picked = np.arange(0, idx.size, every)
    # each picked sample's block: blocks of one length c start at multiples of c
    inv = picked // counts[0] if equal else np.searchsorted(starts, picked, side="right") - 1
    if not equal:  # each block a row, padded with NaN (sorted last, as in the block alone)
        rows = np.repeat(np.arange(starts.size), counts)
        at = (rows, np.arange(idx.size) - starts[rows])
        lo_i, hi_i = (counts - 1) // 2, counts // 2
        block = np.full((starts.size, int(counts.max())), np.nan)
    for j in range(m):
        if equal:  # the common case: a regular record
            med[:, j] = np.median(v[:, j].reshape(starts.size, int(counts[0])), axis=1)
        else:
            block.fill(np.nan)
            block[at] = v[:, j]
            block.sort(axis=1)
            every_block = np.arange(starts.size)
            med[:, j] = 0.5 * (block[every_block, lo_i] + block[every_block, hi_i])
        dev = v[::every, j] - med[inv, j]  # its own: |dev| in place, partitioned in place
        sigma[j] = 1.4826 * float(np.median(np.abs(dev, out=dev), overwrite_input=True))
    return time_s[0] + idx[starts] * block_s, counts.astype(np.float64), med, sigma


def _window_medians(t_block: FloatArray, x: FloatArray, window_s: float) -> FloatArray:
    """Per block, the medians of the block values in [t − w/2, t + w/2] (centre), in
    [t − w/2, t) (before) and in (t, t + w/2] (after): shape (3, n_blocks, m).  Time-based,
    so gaps and bursts are handled; a sliding median filter when the blocks are regular."""
    n = t_block.size
    steps = np.diff(t_block)
    if n > 2 and np.allclose(steps, steps[0]):
        from scipy.ndimage import median_filter

        h = max(1, round(window_s / 2 / steps[0])) | 1
        c = np.column_stack(
            [median_filter(x[:, j], size=2 * h + 1, mode="nearest") for j in range(x.shape[1])]
        )
        side = np.column_stack(
            [median_filter(x[:, j], size=h, mode="nearest") for j in range(x.shape[1])]
        )
        # h odd: the side window centred at b - 1 - h // 2 ends at b - 1 (before the block),
        # centred at b + 1 + h // 2 it starts at b + 1 (after it)
        before_i = np.clip(np.arange(n) - 1 - h // 2, 0, n - 1)
        after_i = np.clip(np.arange(n) + 1 + h // 2, 0, n - 1)
        before, after = side[before_i], side[after_i]
        before[0], after[-1] = x[0], x[-1]
        return np.stack([c, before, after])
    half = window_s / 2
    lo = np.searchsorted(t_block, t_block - half, side="left")
    hi = np.searchsorted(t_block, t_block + half, side="right")
    me = np.arange(n)
    c = _ragged_medians(x, lo, hi)
    before = np.where((me > lo)[:, None], _ragged_medians(x, lo, me), x)
    after = np.where((hi > me + 1)[:, None], _ragged_medians(x, me + 1, hi), x)
    return np.stack([c, before, after])


def _ragged_medians(
    x: FloatArray, lo: npt.NDArray[np.intp], hi: npt.NDArray[np.intp]
) -> FloatArray:
    """Per i, the median of the rows ``x[lo[i]:hi[i]]`` (n, m) (NaN for an empty window),
    at once: the windows side by side, padded with NaN (``np.nanmedian``: the median of
    what is not padding), in pieces of a bounded size."""
    n, m = x.shape
    out = np.full((lo.size, m), np.nan)
    width = int(np.max(hi - lo, initial=0))
    if width == 0:
        return out
    padded = np.vstack([x, np.full((1, m), np.nan)])
    step = max(1, 2_000_000 // (width * m))
    cols = np.arange(width)
    for a in range(0, lo.size, step):
        rows = lo[a : a + step, None] + cols
        rows = np.where(rows < hi[a : a + step, None], rows, n)
        out[a : a + step] = _nan_medians(padded[rows])
    return out


def _nan_medians(w: FloatArray) -> FloatArray:
    """``np.nanmedian(w, axis=1)`` of windows (k, width, m), the same numbers at once: each
    window sorted (NaN last), the middle one or the mean of the middle two of what is not
    NaN; NaN for an all-NaN window."""
    w = np.sort(w, axis=1)
    c = np.sum(~np.isnan(w), axis=1)  # (k, m)
    lo = np.maximum(c - 1, 0) // 2
    hi = c // 2
    a = np.take_along_axis(w, lo[:, None, :], axis=1)[:, 0, :]
    b = np.take_along_axis(w, np.minimum(hi, w.shape[1] - 1)[:, None, :], axis=1)[:, 0, :]
    med: FloatArray = np.where(c > 0, (a + b) / 2.0, np.nan)
    return med


def _runs_of(mask: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


_STILL_MEMO: contextvars.ContextVar[list[tuple[Any, Any, float, float, Motion]] | None] = (
    contextvars.ContextVar("thermocal_stillness_memo", default=None)
)


@contextlib.contextmanager
def stillness_remembered() -> Iterator[None]:
    """Within the block, :func:`stillness` of the same two array objects (identity, not
    equality), floor and k_sigma is computed once and its :class:`Motion` returned again
    (the adequacy judgement and the bump mask of one sensor ask for it twice).  The
    arrays must not be changed in place within the block."""
    token = _STILL_MEMO.set([])
    try:
        yield
    finally:
        _STILL_MEMO.reset(token)


def stillness(
    time_s: npt.ArrayLike, values: npt.ArrayLike, floor: float, *, k_sigma: float = STILL_K_SIGMA
) -> Motion:
    r"""Tell motion from thermal drift in a channel or a triad.

    Blocks of ``max(1 s, 10 samples)``; each block's median :math:`m_b` (a vector
    for a triad) is compared with :math:`M_b`, the median of the block medians within
    ±w/2 (w = :data:`STILL_WINDOW_S`): slow thermal drift follows it, a bump or a turn
    does not.  Remembered within :func:`stillness_remembered`.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    values : array_like
        The signal, shape ``(n,)`` or ``(n, m)`` for a triad [unit of ``floor``,
        e.g. °/h or mg].
    floor : float
        Absolute threshold [unit of ``values``] (:data:`MOTION_FLOOR_DEG_S`,
        :data:`MOTION_FLOOR_MG` in the canonical unit).
    k_sigma : float, optional
        Threshold in units of the sensor's noise (default :data:`STILL_K_SIGMA`).

    Returns
    -------
    Motion

    Notes
    -----
    A block is moving when a bump or a step exceeds the threshold:

    .. math::
        |m_b - M_b| \;\text{or}\; 2\,|M_b - (B_b + A_b)/2|
        > \max\!\left(\mathrm{floor},\; 1.25\,k\,\sigma_w/\sqrt{n_b}\right)

    with :math:`B_b`, :math:`A_b` the medians over w/2 before and after the block,
    :math:`\sigma_w` the sensor's own noise (robust scatter about the block medians)
    and :math:`n_b` the samples per block (the median of n white samples scatters
    1.25 σ/√n).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 600.0, 0.1)
    >>> x = np.random.default_rng(0).normal(0.0, 1.0, t.size)
    >>> stillness(t, x, 5.0).share
    0.0
    """
    memo = _STILL_MEMO.get()
    if memo is None:
        return _stillness(time_s, values, floor, k_sigma=k_sigma)
    for t_seen, v_seen, f_seen, k_seen, got in memo:
        if t_seen is time_s and v_seen is values and f_seen == floor and k_seen == k_sigma:
            return got
    got = _stillness(time_s, values, floor, k_sigma=k_sigma)
    memo.append((time_s, values, floor, k_sigma, got))
    return got


def _stillness(
    time_s: npt.ArrayLike, values: npt.ArrayLike, floor: float, *, k_sigma: float = STILL_K_SIGMA
) -> Motion:
    """Tell motion from thermal drift.

    Blocks of ``max(1 s, 10 samples)``; each block's median ``m_b`` (a vector for a triad;
    a median, so that isolated spikes are not motion).  Slow thermal drift changes little
    within :data:`STILL_WINDOW_S`; motion does not:

    * a **bump** (a turn and back, a knock): ``|m_b − M_b|`` with ``M_b`` the median of the
      block medians within ±w/2;
    * a **step** (the board re-oriented, a bias jump): ``2 |M_b − (B_b + A_b)/2|`` with
      ``B_b``/``A_b`` the medians over w/2 before and after the block — a step moves the
      centre median to one side, a ramp keeps it half-way — counted once per step (the
      middle of its plateau), with its size ``|A_b − B_b|`` and the angle between the
      levels before and after.

    Either beyond ``max(floor, 1.25 k σ_w / √n_b)`` is motion, with σ_w the sensor's own
    noise (robust scatter about the block medians, combined over the axes) and n_b the
    samples per block (the median of n white samples scatters 1.25 σ/√n).  ``values`` (n,)
    or (n, m) in the unit of ``floor``."""
    t = np.asarray(time_s, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    if v.ndim == 1:
        v = v[:, None]
    if not (all_finite(t) and all_finite(v)):  # a copy only when something is dropped
        ok = np.isfinite(t) & np.all(np.isfinite(v), axis=1)
        t, v = t[ok], v[ok]
    if t.size < 20:
        return Motion(0.0, 0.0, floor)
    # the sample interval, from the start (the steps are its own: partitioned in place)
    dt = float(np.median(np.diff(t[:100_001]), overwrite_input=True))
    block_s = max(STILL_BLOCK_S, 10.0 * dt)
    tb, cnt, meds, sigma = _block_stats(t, v, block_s)
    centre, before, after = _window_medians(tb, meds, max(STILL_WINDOW_S, 30.0 * block_s))
    dev = np.sqrt(np.sum((meds - centre) ** 2, axis=1))
    # a step moves the centre median to one side; a ramp (or any smooth drift) keeps it
    # half-way between the medians before and after
    jump = 2.0 * np.sqrt(np.sum((centre - 0.5 * (before + after)) ** 2, axis=1))
    sigma_w = float(np.sqrt(np.sum(sigma**2)))
    n_b = float(np.median(cnt))
    threshold = max(floor, k_sigma * 1.25 * sigma_w / math.sqrt(max(n_b, 1.0)))
    moving = dev > threshold
    episodes = [
        (float(tb[a]), float(tb[b - 1] + block_s), float(dev[a:b].max()))
        for a, b in _runs_of(moving)
    ]
    steps: list[tuple[float, float, float | None]] = []
    for a, b in _runs_of(jump > threshold):
        top = np.flatnonzero(jump[a:b] >= 0.95 * jump[a:b].max())
        i = a + int(top[top.size // 2])  # the middle of the plateau: where the level changed
        moving[i] = True
        u, w = before[i], after[i]
        nu, nw = float(np.linalg.norm(u)), float(np.linalg.norm(w))
        angle = (
            math.degrees(math.acos(max(-1.0, min(1.0, float(u @ w) / (nu * nw)))))
            if min(nu, nw) > 10.0 * threshold and v.shape[1] > 1
            else None
        )
        steps.append((float(tb[i]), float(np.linalg.norm(w - u)), angle))
    share = float(np.sum(cnt[moving]) / np.sum(cnt))
    level = float(np.linalg.norm(np.median(meds, axis=0)))
    peak = float(max(dev.max(), jump.max()))
    return Motion(share, peak, threshold, episodes, level, steps)


def stillness_test(
    time_s: npt.ArrayLike,
    values: npt.ArrayLike,
    kind: str,
    name: str,
    *,
    unit_factor: float = 1.0,
    unit: str | None = None,
) -> AdequacyTest:
    """:func:`stillness` of a gyro or accelerometer channel or triad, as a test.

    Refused (:data:`ALLOW_MOTION`): moving more than :data:`MAX_MOVING_SHARE` of the
    time, a gyro turning at more than :data:`ROTATING_DEG_S`, an accelerometer whose
    level stepped (the board was re-oriented).  Warned: shorter bumps, a gyro's step.

    Parameters
    ----------
    time_s : array_like
        Sample times [s].
    values : array_like
        The signal [°/h for a gyro, mg for an accelerometer].
    kind : str
        ``"gyro"`` or ``"accel"``; anything else is not judged (``n/a``).
    name : str
        The channel, for messages.
    unit_factor : float, optional
        Multiplies a figure in the canonical unit into the data's unit (default 1).
    unit : str, optional
        The data's unit as messages show it (default the canonical one).

    Returns
    -------
    AdequacyTest
        ``stillness`` with the share of moving time [%].
    """
    if kind not in ("gyro", "accel"):
        return AdequacyTest(
            "stillness", None, None, "", "n/a", None,
            f"{name}: not a gyro or accelerometer unit: stillness not judged",
        )  # fmt: skip
    canonical = "deg/h" if kind == "gyro" else "mg"
    floor = MOTION_FLOOR_DEG_S * DEG_H_PER_DEG_S if kind == "gyro" else MOTION_FLOOR_MG
    mot = stillness(time_s, values, floor)
    shown = unit or canonical

    def f(x: float) -> str:
        return f"{x * unit_factor:.3g} {shown}"

    eps = ", ".join(f"{a:.1f}–{b:.1f} s (up to {f(p)})" for a, b, p in mot.episodes[:4])
    more = f" and {len(mot.episodes) - 4} more" if len(mot.episodes) > 4 else ""
    steps = ", ".join(
        f"at {ts:.1f} s by {f(size)}" + (f" ({ang:.1f}°)" if ang is not None else "")
        for ts, size, ang in mot.steps[:4]
    )
    rot = mot.rotating if kind == "gyro" else None
    pct = mot.share * 100.0
    fig, thr = pct, MAX_MOVING_SHARE * 100.0
    if rot is not None and rot > ROTATING_DEG_S * DEG_H_PER_DEG_S:
        return AdequacyTest(
            "stillness", rot * unit_factor, ROTATING_DEG_S * DEG_H_PER_DEG_S * unit_factor,
            shown, "fail", ALLOW_MOTION,
            f"{name} turns at {f(rot)} (median): a thermal calibration needs the sensor still",
        )  # fmt: skip
    if mot.share > MAX_MOVING_SHARE:
        verdict = "fail"
        msg = (
            f"{name}: the sensor moved during {pct:.3g} % of the record (departures from its "
            f"slow drift up to {f(mot.peak)}, threshold {f(mot.threshold)}): "
            f"{eps}{more}; a thermal calibration needs it still"
        )
    elif kind == "accel" and mot.steps:
        verdict = "fail"
        msg = (
            f"{name}: the gravity direction changed (the board was moved) {steps}: the "
            "levels before and after differ by more than any thermal drift; record the sweep "
            "without touching the board"
        )
    elif mot.episodes or mot.steps:
        verdict = "warn"
        what = [f"moved at {eps}{more}"] if mot.episodes else []
        what += [f"stepped {steps} (a bias jump or a re-orientation)"] if mot.steps else []
        msg = f"{name}: the sensor {' and '.join(what)} ({pct:.2g} % of the record)"
    else:
        verdict = "pass"
        msg = (
            f"{name}: still (largest departure from the slow drift {f(mot.peak)}, "
            f"threshold {f(mot.threshold)})"
        )
    return AdequacyTest("stillness", fig, thr, "% moving", verdict, ALLOW_MOTION, msg)


# --- what a model needs ----------------------------------------------------------------


@dataclass(frozen=True)
class Needs:
    """What a model asks of the data.

    Attributes
    ----------
    order : dict of str to int
        Polynomial order in T per temperature column (0: not used in T).
    n_coefficients : int
        Number of fitted coefficients.
    rate : tuple of str
        The temperature columns whose Ṫ terms are fitted.
    """

    order: dict[str, int]
    n_coefficients: int
    rate: tuple[str, ...] = ()


def judge(
    needs: Needs,
    runs_time_s: Sequence[FloatArray],
    runs_temps: Sequence[FloatArray],
    temp_names: Sequence[str],
    *,
    signals: Sequence[FloatArray] | None = None,
    kind: str | None = None,
    name: str = "",
    temperature_unit: str = "°C",
    unit_factor: float = 1.0,
    unit: str | None = None,
    overrides: Iterable[str] = (),
    rate_interval_s: float = RATE_INTERVAL_S,
) -> Adequacy:
    """Can these runs support this model?  Every adequacy test for one channel.

    Parameters
    ----------
    needs : Needs
        The model's order in T per temperature column, its coefficients, its Ṫ columns.
    runs_time_s, runs_temps : sequence of ndarray
        Each run's times [s] and temperatures (n, k) in ``temp_names`` order.
    temp_names : sequence of str
        The temperature columns' names.
    signals : sequence of ndarray, optional
        Each run's signal in the canonical unit of ``kind`` (°/h, mg), for the stillness test.
    kind : {"gyro", "accel"}, optional
        The signal's kind.
    name, temperature_unit, unit : str, optional
        The channel, and the units as messages show them.
    unit_factor : float, optional
        Multiplies a figure in the canonical unit into the data's own unit.
    overrides : iterable of str, optional
        The refusals the user allowed (:data:`ALLOW_NARROW`, :data:`ALLOW_MOTION`).
    rate_interval_s : float, optional
        Δ of the backward difference Ṫ = 60 (T(t) − T(t − Δ)) / Δ [°C/min] [s].

    Returns
    -------
    Adequacy
        Every test (samples, span, distinct temperatures, ends, rate, stillness) with its
        verdict, and the overrides (sources: module docstring).

    Examples
    --------
    A linear model in T on a run from 10 to 40 °C at 0.5 °C/min:

    >>> import numpy as np
    >>> t = np.arange(0.0, 3600.0, 1.0)
    >>> temps = (10.0 + 30.0 * t / 3600.0)[:, None]
    >>> rec = judge(Needs({"T": 1}, 2), [t], [temps], ["T"])
    >>> [(x.name, x.verdict) for x in rec.tests][:2]
    [('samples_per_coefficient', 'pass'), ('temperature_span', 'pass')]
    """
    n = int(sum(t.size for t in runs_time_s))
    tests = [samples_test(n, needs.n_coefficients, name)]
    for j, tn in enumerate(temp_names):
        order = needs.order.get(tn, 0)
        if order <= 0 and tn not in needs.rate:
            continue
        parts = [_column(T, j) for T in runs_temps]
        col = parts[0] if len(parts) == 1 else np.concatenate(parts)  # no copy of one run
        own = len(parts) > 1 or not isinstance(runs_temps[0], np.ndarray)  # a new array
        if order > 0:
            tests.extend(temperature_tests(col, tn, order, unit=temperature_unit, scratch=own))
        del parts, col
        if tn in needs.rate:
            rates = np.concatenate(
                [
                    temperature_rate_c_per_min(
                        np.asarray(ts, dtype=np.float64),
                        _column(T, j),
                        rate_interval_s,
                    )
                    for ts, T in zip(runs_time_s, runs_temps, strict=True)
                ]
            )
            tests.append(rate_test(rates, tn))
    if signals is not None and kind is not None:
        per_run = [
            stillness_test(
                ts,
                s,
                kind,
                f"{name} (run {i + 1})" if len(signals) > 1 else name,
                unit_factor=unit_factor,
                unit=unit,
            )
            for i, (ts, s) in enumerate(zip(runs_time_s, signals, strict=True))
        ]
        tests.append(_worst_stillness(per_run))
    return Adequacy(tuple(tests), tuple(overrides), name)


def _column(temps: Any, j: int) -> FloatArray:
    """Column ``j`` of a run's ``(n, k)`` temperatures: a view of an array, or read from
    an array-like that reads its columns when asked for (``temps[:, j]``,
    :class:`thermocal.pipeline.fit_columns.TemperatureBlocks`) without holding them all."""
    if isinstance(temps, np.ndarray):
        return np.asarray(temps, dtype=np.float64)[:, j]
    return np.asarray(temps[:, j], dtype=np.float64)


def _worst_stillness(tests: list[AdequacyTest]) -> AdequacyTest:
    rank = {"fail": 3, "warn": 2, "pass": 1, "n/a": 0}
    return max(tests, key=lambda t: (rank[t.verdict], t.figure or 0.0))


def check_for_firmware(record: Any, where: str) -> None:
    """Refuse firmware output from a model whose adequacy failed without an override.

    Parameters
    ----------
    record : object
        The model file's ``adequacy`` record (:meth:`Adequacy.to_dict`).
    where : str
        The model file, named in messages.

    Raises
    ------
    ThermocalInputError
        A test failed at fit time without an override (exit 2, naming the test).

    Warns
    -----
    ThermocalWarning
        A failure was overridden, or the model carries no record (written before
        the check existed).
    """
    rec = from_dict(record)
    if rec is None:
        warnings.warn(
            f"{where}: the calibration carries no adequacy record (written before thermocal "
            "judged its data): refit it to have the sweep checked",
            ThermocalWarning,
            stacklevel=2,
        )
        return
    failed = [t for t in rec["tests"] if isinstance(t, dict) and t.get("verdict") == "fail"]
    overrides = set(rec.get("overrides") or [])
    refused = [t for t in failed if t.get("override") not in overrides or not t.get("override")]
    if refused:
        raise ThermocalInputError(
            f"{where}: its data failed the adequacy check ("
            + "; ".join(f"{t.get('name')}: {t.get('message')}" for t in refused)
            + "): no firmware parameters from it"
        )
    if failed:
        warnings.warn(
            f"{where}: fitted with {', '.join(sorted(overrides))} although "
            + "; ".join(f"{t.get('name')} failed" for t in failed)
            + ": these firmware parameters rest on data that do not support them",
            ThermocalWarning,
            stacklevel=2,
        )


__all__ = [
    "ALLOW_MOTION",
    "ALLOW_NARROW",
    "Adequacy",
    "AdequacyTest",
    "Motion",
    "Needs",
    "check_for_firmware",
    "firmware_test",
    "judge",
    "overrides_of",
    "rate_test",
    "samples_test",
    "stillness",
    "stillness_test",
    "temperature_rate_c_per_min",
    "temperature_tests",
]
