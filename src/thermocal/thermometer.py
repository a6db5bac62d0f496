r"""Coarse, slow and borrowed thermometers: recognised, and the temperature at each sample
reconstructed.

Many inertial sensors report their temperature on a coarse lattice (Bosch BMI055: 0.5 °C,
BMI088: 0.125 °C, whole degrees on others) and update it slower than they sample (BMI088:
every 1.28 s).  Fitted raw, the residual of a bias model in the temperature is a staircase:
within one level the bias keeps drifting while the temperature stands still.  This module

* **recognises** such a thermometer (:func:`describe_thermometer`): the lattice step
  (:func:`lattice_step`, a robust greatest common divisor of the distinct levels, float noise
  and unit conversions allowed) and the update period (:func:`update_period`, the same on the
  intervals between changes of the reading);
* **reconstructs** the temperature at each sample (:func:`reconstruct_temperature`): the
  reading is replaced by a line through *knots* placed where the true temperature is known
  best (see the Notes of :func:`temperature_knots`);
* **borrows** another sensor's thermometer (:func:`borrowed_temperature`): its reconstructed
  temperature interpolated at this sensor's sample times, where the two records overlap.

Pure functions on arrays; no file is read here.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError, ThermocalInputError, ThermocalWarning, UnitError
from thermocal.recording import FloatArray, Recording

MIN_STEP_C = 0.1
"""A lattice step from which a thermometer is called quantised [°C]."""
MAX_STEP_C = 2.0
"""The coarsest lattice step taken for a thermometer's resolution [°C]: the coarsest IMU
thermometers read whole degrees (1 °C; whole °F, 0.56 °C), while a chamber's set temperatures
are 5 °C or more apart.  Readings on a coarser lattice are the record's set temperatures
(soaks) and are not reconstructed between their changes; soaks 2 °C apart or closer would be
taken for a thermometer."""
MIN_PERIOD_S = 1.0
"""An update period from which a thermometer is called slow [s]."""
ON_LATTICE = 0.05
"""A value within this fraction of a step of a lattice point is on it."""
LATTICE_SHARE = 0.99
"""The share of the samples on the lattice for a thermometer to be called quantised."""
PERIOD_SHARE = 0.9
"""The share of the intervals between changes that are multiples of the period."""
NOISE_C = 1e-3
"""Distinct values closer than this are one level (float noise, a unit conversion) [°C]."""
MAX_JOIN_GAP_S = 5.0
"""A borrowed thermometer silent for longer than this (and 10 of its sample intervals) is
not interpolated across [s]."""

TemperatureMode = Literal["reconstructed", "raw"]
"""How a recording's temperature is used: ``"reconstructed"`` (when the thermometer is
quantised or slow) or ``"raw"`` (as logged)."""


class ThermometerWarning(ThermocalWarning):
    """A borrowed thermometer that covers only part of a record."""


@dataclass(frozen=True)
class Thermometer:
    """What a temperature series is: its levels, lattice step and update period.

    Attributes
    ----------
    n_samples : int
        Finite samples.
    n_levels : int
        Distinct values (float noise below :data:`NOISE_C` merged).
    step_c : float or None
        The lattice step [°C] when the values lie on one (any step, even below
        :data:`MIN_STEP_C`); None when they do not.
    update_period_s : float or None
        The period at which the reading is updated [s], when the changes of the reading
        fall on multiples of one; None otherwise.
    sample_period_s : float
        The median interval between samples [s].
    quantised : bool
        :data:`MIN_STEP_C` ≤ ``step_c`` ≤ :data:`MAX_STEP_C`.
    slow : bool
        ``update_period_s`` ≥ :data:`MIN_PERIOD_S` and at least 5 sample intervals.
    """

    n_samples: int
    n_levels: int
    step_c: float | None
    update_period_s: float | None
    sample_period_s: float
    quantised: bool
    slow: bool

    @property
    def coarse(self) -> bool:
        """Quantised or slow: the reconstruction changes the temperature."""
        return self.quantised or self.slow

    def describe(self) -> str:
        """One phrase: ``"quantised (0.125 °C) and slow (updated every 1.28 s)"`` etc."""
        parts = []
        if self.quantised:
            parts.append(f"quantised ({self.step_c:.4g} °C)")
        if self.slow:
            parts.append(f"slow (updated every {self.update_period_s:.3g} s)")
        return " and ".join(parts) if parts else "continuous"

    def to_dict(self) -> dict[str, Any]:
        """The fields as a JSON object, with ``kind`` (:meth:`describe`)."""
        return {**asdict(self), "kind": self.describe()}


def _levels(values: FloatArray) -> tuple[FloatArray, FloatArray] | None:
    """The distinct levels and their sample counts, float noise merged; None when a group of
    merged values is wider than 10 × :data:`NOISE_C` (a fine, continuous reading)."""
    return _levels_counted(values)[0]


def _levels_counted(values: FloatArray) -> tuple[tuple[FloatArray, FloatArray] | None, int]:
    """:func:`_levels`, and the number of distinct values (of the same one sort)."""
    u, counts = np.unique(values, return_counts=True)
    split = np.flatnonzero(np.diff(u) > NOISE_C) + 1
    starts = np.concatenate([[0], split])
    ends = np.concatenate([split, [u.size]])
    if np.any(u[ends - 1] - u[starts] > 10 * NOISE_C):
        return None, int(u.size)
    weight = np.add.reduceat(counts, starts).astype(np.float64)
    centre = np.add.reduceat(u * counts, starts) / weight
    return (centre, weight), int(u.size)


def _robust_gcd(x: FloatArray, tol: float) -> float | None:
    """The largest g with every ``x`` (positive) near a multiple of it: the smallest of the
    clustered values and of their differences above ``tol``, refined by the median of
    ``x / round(x / g)``."""
    xs = np.sort(x[x > tol])
    if xs.size == 0:
        return None
    split = np.flatnonzero(np.diff(xs) > tol) + 1
    centres = np.array([c.mean() for c in np.split(xs, split)])
    cands = np.concatenate([centres, np.diff(centres)])
    g = float(np.min(cands[cands > tol]))
    k = np.maximum(np.round(xs / g), 1.0)
    return float(np.median(xs / k))


def lattice_step(values: FloatArray) -> float | None:
    r"""The step of the lattice the values lie on, or None.

    Parameters
    ----------
    values : numpy.ndarray
        Temperatures [°C] (non-finite values ignored).

    Returns
    -------
    float or None
        The step [°C] when at least :data:`LATTICE_SHARE` of the samples lie within
        :data:`ON_LATTICE` of a step of the lattice through the most frequent level; None
        when they do not, or when there are fewer than two levels.

    Notes
    -----
    The step is a robust greatest common divisor of the differences between the distinct
    levels :math:`L_j` (values closer than :data:`NOISE_C` merged: float noise, a °F→°C
    or raw-count conversion): the smallest cluster of differences :math:`g`, refined as

    .. math:: q = \operatorname{median}_j \frac{\Delta L_j}{\operatorname{round}(\Delta L_j/g)}

    and accepted when :math:`|(T_i - L_0)/q - \operatorname{round}((T_i - L_0)/q)| \le
    0.05` for 99 % of the samples.

    References
    ----------
    - Bosch Sensortec, *BMI088 data sheet* (BST-BMI088-DS001), temperature sensor:
      0.125 °C resolution, updated every 1.28 s.

    Examples
    --------
    >>> import numpy as np
    >>> t = 23.0 + 0.125 * np.round(np.linspace(0, 40, 5000) / 0.125)
    >>> round(lattice_step(t), 4)
    0.125
    >>> lattice_step(np.random.default_rng(0).normal(30, 5, 1000)) is None
    True
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    return _lattice_of(v, _levels(v))


def _lattice_of(v: FloatArray, found: tuple[FloatArray, FloatArray] | None) -> float | None:
    """:func:`lattice_step` of the finite values ``v`` whose levels are ``found``."""
    if found is None or found[0].size < 2:
        return None
    levels, weight = found
    # levels holding a thousandth of the samples: a glitch is no level
    common = levels[weight >= max(2.0, 1e-3 * v.size)]
    if common.size < 2:
        common = levels
    g = _robust_gcd(np.diff(common), NOISE_C)
    if g is None:
        return None
    ref = levels[int(np.argmax(weight))]
    phase = (v - ref) / g
    on = np.abs(phase - np.round(phase)) <= ON_LATTICE
    return g if np.mean(on) >= LATTICE_SHARE else None


def _changes(temp_c: FloatArray, step_c: float | None) -> npt.NDArray[np.intp]:
    """The indices i ≥ 1 where the reading differs from sample i − 1."""
    tol = 0.5 * step_c if step_c is not None else NOISE_C
    return np.flatnonzero(np.abs(np.diff(temp_c)) > tol) + 1


def update_period(
    time_s: FloatArray, temp_c: FloatArray, step_c: float | None = None
) -> float | None:
    r"""The period at which a held reading is updated, or None.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times, ascending [s].
    temp_c : numpy.ndarray
        The reading at each sample [°C] (finite).
    step_c : float, optional
        Its lattice step [°C] (:func:`lattice_step`): changes smaller than half of it are
        noise.

    Returns
    -------
    float or None
        The period [s] when at least :data:`PERIOD_SHARE` of the intervals between
        successive changes of the reading are within 3 sample intervals (or 2 % of the
        period) of a multiple of it; None when they are not, with fewer than 3 changes, or
        when a quantised reading changes one level at a time at one interval only (a
        steady ramp through the lattice: it tells no update period).

    Notes
    -----
    The period is the robust greatest common divisor (as in :func:`lattice_step`) of the
    intervals :math:`\Delta t_j` between changes.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 600, 0.01)
    >>> held = np.floor(t / 1.28) * 1.28            # updated every 1.28 s
    >>> round(update_period(t, 20 + 0.01 * held), 2)
    1.28
    """
    t = np.asarray(time_s, dtype=np.float64)
    v = np.asarray(temp_c, dtype=np.float64)
    idx = _changes(v, step_c)
    if idx.size < 4 or t.size < 2:
        return None
    dt = float(np.median(np.diff(t)))
    gaps = np.diff(t[idx])
    tol = max(3.0 * dt, 1e-9)
    p = _robust_gcd(gaps, tol)
    if p is None:
        return None
    k = np.maximum(np.round(gaps / p), 1.0)
    near = (np.abs(gaps - k * p) <= max(tol, 0.02 * p)) & (gaps > tol)
    if np.mean(near) < PERIOD_SHARE:
        return None
    if step_c is not None and step_c >= MIN_STEP_C and np.all(k[near] == 1.0):
        jumps = np.abs(np.diff(v)[idx - 1])
        if np.all(jumps < 1.5 * step_c):
            return None  # one level at a time at one interval: a ramp, not a period
    return p


DESCRIBE_MAX_SAMPLES = 250_000
"""Samples a thermometer is judged on: a longer record is judged on every k-th sample
(k the smallest that keeps at most this many), which keeps every level a thermometer holds
for k samples or more and its update period (to k sample intervals), at a bounded cost
(the judgement sorts its samples: 58 B per sample judged)."""


def describe_thermometer(time_s: FloatArray, temp_c: FloatArray) -> Thermometer:
    """Recognise a quantised or slow thermometer.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times, ascending [s].
    temp_c : numpy.ndarray
        The thermometer's reading at each sample [°C].

    Returns
    -------
    Thermometer
        Levels, lattice step [°C], update period [s], and whether it is quantised (a step of
        at least :data:`MIN_STEP_C`, at most :data:`MAX_STEP_C`) or slow (updated every
        :data:`MIN_PERIOD_S` or more, and at least every 5 samples).

    Raises
    ------
    ParameterError
        ``temp_c`` has no finite value, or ``time_s`` and ``temp_c`` differ in length.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 1200, 0.005)                       # 200 Hz for 20 min
    >>> true = 20 + 30 * t / t[-1]
    >>> held = np.interp(np.floor(t / 1.28) * 1.28, t, true)
    >>> th = describe_thermometer(t, 0.125 * np.round(held / 0.125))
    >>> th.describe()
    'quantised (0.125 °C) and slow (updated every 1.28 s)'
    """
    t = np.asarray(time_s, dtype=np.float64)
    v = np.asarray(temp_c, dtype=np.float64)
    if t.shape != v.shape:
        raise ParameterError("temp_c", f"{{name}} has {v.size} samples, the times {t.size}")
    n_finite = int(np.count_nonzero(np.isfinite(v) & np.isfinite(t)))
    if n_finite == 0:
        raise ParameterError("temp_c", "{name} has no finite value")
    stride = -(-t.size // DESCRIBE_MAX_SAMPLES)  # a long record: every stride-th sample
    t, v = t[::stride], v[::stride]
    ok = np.isfinite(v) & np.isfinite(t)
    t, v = t[ok], v[ok]
    found, n_distinct = _levels_counted(v)  # one sort: the levels and the distinct values
    n_levels = int(found[0].size) if found is not None else n_distinct
    step = _lattice_of(v, found)  # v finite: its levels are found once
    period = update_period(t, v, step)
    dt = float(np.median(np.diff(t))) / stride if t.size > 1 else 0.0
    return Thermometer(
        n_samples=n_finite,
        n_levels=n_levels,
        step_c=step,
        update_period_s=period,
        sample_period_s=dt,
        quantised=step is not None and MIN_STEP_C <= step <= MAX_STEP_C,
        slow=period is not None and period >= MIN_PERIOD_S and period >= 5 * dt,
    )


def temperature_knots(
    time_s: FloatArray, temp_c: FloatArray, thermometer: Thermometer
) -> tuple[FloatArray, FloatArray]:
    r"""The points (time, temperature) the reconstruction passes through.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times, ascending [s].
    temp_c : numpy.ndarray
        The reading at each sample [°C] (finite).
    thermometer : Thermometer
        What the reading is (:func:`describe_thermometer`).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Knot times [s], ascending, and temperatures [°C].

    Notes
    -----
    At each change of the reading, from level :math:`a` (last shown at sample
    :math:`i-1`) to :math:`b` (first shown at sample :math:`i`, time :math:`t_i`):

    * a quantised reading moving one level (:math:`|b-a| < 1.5\,q`): the true temperature
      crossed the boundary between the two levels somewhere in the last update interval
      :math:`P` (the update period when slow, else :math:`t_i - t_{i-1}`); the knot is its
      middle, :math:`(t_i - P/2,\ (a+b)/2)`.  The boundary is the midpoint whether the
      sensor rounds or truncates, so the reconstruction keeps the sensor's own convention
      (a truncating sensor reads :math:`q/2` low on average, raw or reconstructed, which is
      what the firmware will read in flight too); the crossing time is off by at most
      :math:`P/2` (uniform: no bias, rms :math:`P/\sqrt{12}`).  Between two such knots
      one level apart (a passage through level :math:`L`), the line passes :math:`L`
      midway; when the stay is twice the median of the 9 passages about it (a pause),
      it reaches :math:`L` half that median after the first knot, holds it, and leaves it
      as long before the second;
    * otherwise (a slow continuous reading, or several levels at once): the new reading is
      the temperature sampled at the update, the knot :math:`(t_i, b)`; a sensor that
      averages over its update period reads :math:`\dot T\,P/2` late (0.01 °C at
      1 °C/min for :math:`P` = 1.28 s).

    Before the first knot and after the last (the other boundary of the end levels is not
    seen), the line goes from the end knot to the end level's own value :math:`L` in half
    the nearest knot interval (where a steady ramp reaches it) and holds it.

    References
    ----------
    - Bosch Sensortec, *BMI088 data sheet* (BST-BMI088-DS001), temperature sensor.
    """
    t = np.asarray(time_s, dtype=np.float64)
    v = np.asarray(temp_c, dtype=np.float64)
    q = thermometer.step_c if thermometer.quantised else None
    idx = _changes(v, q)
    if idx.size == 0:
        return t[[0, -1]], v[[0, -1]]
    a, b, ti = v[idx - 1], v[idx], t[idx]
    gap = ti - t[idx - 1]
    if thermometer.slow and thermometer.update_period_s is not None:
        gap = np.full(idx.size, thermometer.update_period_s)
    if q is not None:
        one = np.abs(b - a) < 1.5 * q
        kt = np.where(one, ti - gap / 2, ti)
        kv = np.where(one, (a + b) / 2, b)
        order = np.argsort(kt, kind="stable")
        return _plateaus(kt[order], kv[order], one[order], q)
    else:
        kt = np.concatenate([[t[0]], ti])
        kv = np.concatenate([[v[0]], b])
    order = np.argsort(kt, kind="stable")
    return kt[order], kv[order]


PASSAGES = 9
"""Passages through one level whose median duration is the local steady-ramp time."""
PAUSE = 2.0
"""A stay in a level this many times the local steady passage time is a pause."""


def _plateaus(kt: FloatArray, kv: FloatArray, one: np.ndarray, q: float) -> tuple[
    FloatArray, FloatArray
]:  # fmt: skip
    """Between two boundary knots one level apart (a passage through level L), the points
    (t_a + h, L) and (t_b − h, L), h half the stay, or, when the stay is a pause
    (:data:`PAUSE` times the median of the :data:`PASSAGES` passages about it), half that
    median: a pause within a level is held at the level, a ramp passes through it."""
    dv = np.diff(kv)
    passage = one[:-1] & one[1:] & (np.abs(np.abs(dv) - q) < 0.25 * q)
    j = np.flatnonzero(passage)
    if j.size == 0:
        return kt, kv
    dur = kt[j + 1] - kt[j]
    half = PASSAGES // 2
    pad = np.pad(dur, half, mode="edge")
    win = np.lib.stride_tricks.sliding_window_view(pad, PASSAGES)
    typical = np.median(win, axis=1)
    h = 0.5 * np.where(dur > PAUSE * typical, typical, dur)
    lvl = (kv[j] + kv[j + 1]) / 2
    t_all = np.concatenate([kt, kt[j] + h, kt[j + 1] - h])
    v_all = np.concatenate([kv, lvl, lvl])
    order = np.argsort(t_all, kind="stable")
    return t_all[order], v_all[order]


def _evaluate(
    where: FloatArray, kt: FloatArray, kv: FloatArray, v: FloatArray, q: float | None
) -> FloatArray:
    """The line through the knots at ``where``; beyond an end knot, a line to the end
    level's value half a passage on (the time to the next boundary), then that level held
    (q None: the knots held)."""
    out = np.interp(where, kt, kv)
    if q is None or kt.size < 2:
        return out
    for end, lvl, side, sign in ((0, v[0], where < kt[0], -1.0), (-1, v[-1], where > kt[-1], 1.0)):
        other = np.flatnonzero(np.abs(kv - kv[end]) >= 0.75 * q)  # the next boundary
        nxt = (other[0] if end == 0 else other[-1]) if other.size else (-1 - end)
        half = 0.5 * abs(kt[nxt] - kt[end])
        x = [kt[end], kt[end] + sign * max(half, 1e-9)]
        y = [kv[end], lvl]
        out[side] = np.interp(where[side], x[::-1] if sign < 0 else x, y[::-1] if sign < 0 else y)
    return out


@dataclass(frozen=True)
class Reconstruction:
    """A temperature reconstructed at each sample, with what was recognised.

    Attributes
    ----------
    temp_c : numpy.ndarray
        The temperature at each sample [°C] (the reading itself when ``used`` is ``"raw"``).
    thermometer : Thermometer
        What the reading is.
    used : str
        ``"reconstructed"`` or ``"raw"``.
    note : str or None
        A sentence saying what was done, for a summary; None when the reading is continuous.
    """

    temp_c: FloatArray
    thermometer: Thermometer
    used: str
    note: str | None

    def to_dict(self) -> dict[str, Any]:
        """The thermometer's fields plus ``temperature`` (``used``) and ``note``."""
        return {**self.thermometer.to_dict(), "temperature": self.used, "note": self.note}


def reconstruct_temperature(
    time_s: FloatArray,
    temp_c: FloatArray,
    *,
    mode: TemperatureMode = "reconstructed",
    at_s: FloatArray | None = None,
) -> Reconstruction:
    """The temperature at each sample of a quantised or slow thermometer.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times of the reading, ascending [s].
    temp_c : numpy.ndarray
        The reading [°C].
    mode : {"reconstructed", "raw"}, optional
        ``"reconstructed"`` (default): a quantised or slow reading is replaced by the line
        through its knots (:func:`temperature_knots`); ``"raw"``: the reading as it is (what
        was recognised still stated).
    at_s : numpy.ndarray, optional
        Times at which the temperature is wanted [s] (default ``time_s``).

    Returns
    -------
    Reconstruction
        The temperature at ``at_s`` [°C], the thermometer, what was used and a note.

    Raises
    ------
    ParameterError
        ``mode`` unknown; ``temp_c`` without finite values; a constant reading (one level:
        no temperature sweep to fit on).

    Notes
    -----
    Linear interpolation between the knots :math:`(t_k, T_k)`:

    .. math:: \\hat T(t) = T_k + (T_{k+1}-T_k)\\,\\frac{t - t_k}{t_{k+1}-t_k},
              \\quad t_k \\le t < t_{k+1}.

    A continuous thermometer is returned as it is (interpolated at ``at_s`` when given).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 600, 0.01)
    >>> true = 20 + 10 * t / 600
    >>> rec = reconstruct_temperature(t, np.round(true))        # whole degrees
    >>> round(float(np.sqrt(np.mean((rec.temp_c - true) ** 2))), 3)
    0.0
    >>> round(float(np.sqrt(np.mean((np.round(true) - true) ** 2))), 2)
    0.29
    """
    if mode not in ("reconstructed", "raw"):
        raise ParameterError("temperature", f"{{name}} must be reconstructed or raw, got {mode!r}")
    t = np.asarray(time_s, dtype=np.float64)
    v = np.asarray(temp_c, dtype=np.float64)
    th = describe_thermometer(t, v)
    if th.n_levels < 2:
        raise ParameterError(
            "temp_c", f"{{name}} holds one value ({np.nanmedian(v):.4g} °C): no sweep to fit on"
        )
    ok = np.isfinite(v) & np.isfinite(t)
    where = t if at_s is None else np.asarray(at_s, dtype=np.float64)
    if mode == "raw" or not th.coarse:
        out = v if at_s is None else np.interp(where, t[ok], v[ok])
        note = (
            None
            if not th.coarse
            else f"the thermometer is {th.describe()}; its reading used as logged"
        )
        return Reconstruction(out, th, "raw", note)
    kt, kv = temperature_knots(t[ok], v[ok], th)
    out = _evaluate(where, kt, kv, v[ok], th.step_c if th.quantised else None)
    note = (
        f"the thermometer is {th.describe()}; the temperature at each sample is "
        f"reconstructed between the changes of its reading ({kt.size} knots)"
    )
    return Reconstruction(out, th, "reconstructed", note)


def borrowed_temperature(
    time_s: FloatArray,
    source_time_s: FloatArray,
    source_temp_c: FloatArray,
    *,
    source: str,
    mode: TemperatureMode = "reconstructed",
) -> tuple[Reconstruction, np.ndarray]:
    """Another sensor's thermometer at this sensor's sample times.

    Parameters
    ----------
    time_s : numpy.ndarray
        This sensor's sample times [s].
    source_time_s : numpy.ndarray
        The other sensor's sample times [s] (same clock).
    source_temp_c : numpy.ndarray
        The other sensor's reading [°C].
    source : str
        The other sensor's name, for messages.
    mode : {"reconstructed", "raw"}, optional
        How the other reading is used (:func:`reconstruct_temperature`).

    Returns
    -------
    (Reconstruction, numpy.ndarray of bool)
        The borrowed temperature at the samples kept [°C], and which samples of ``time_s``
        are kept: those inside the other's record (or one of its sample intervals beyond
        an end) and not in a silence of it longer than
        :data:`MAX_JOIN_GAP_S` (and 10 of its sample intervals).

    Raises
    ------
    ThermocalInputError
        The two records do not overlap (no sample kept).

    Warns
    -----
    ThermometerWarning
        Part of this sensor's record lies outside the other's: those samples are left out.

    Examples
    --------
    >>> import numpy as np
    >>> t_imu = np.arange(0, 100, 0.005)
    >>> t_baro = np.arange(0, 100, 0.1)
    >>> rec, keep = borrowed_temperature(t_imu, t_baro, 20 + 0.1 * t_baro, source="baro")
    >>> round(float(rec.temp_c[keep.sum() // 2]), 2), bool(keep.all())
    (25.0, True)
    """
    t = np.asarray(time_s, dtype=np.float64)
    st = np.asarray(source_time_s, dtype=np.float64)
    sv = np.asarray(source_temp_c, dtype=np.float64)
    ok = np.isfinite(st) & np.isfinite(sv)
    st, sv = st[ok], sv[ok]
    order = np.argsort(st, kind="stable")
    st, sv = st[order], sv[order]
    if st.size < 2 or t.size == 0 or st[-1] < t[0] or st[0] > t[-1]:
        raise ThermocalInputError(
            f"{source}'s thermometer and this sensor's record do not overlap in time"
        )
    dt = float(np.median(np.diff(st)))
    j = np.searchsorted(st, t)
    inside = (t >= st[0] - dt) & (t <= st[-1] + dt)  # one of its intervals beyond
    jj = np.clip(j, 1, st.size - 1)
    silent = (st[jj] - st[jj - 1]) > max(MAX_JOIN_GAP_S, 10 * dt)
    keep = inside & ~silent
    if not keep.any():
        raise ThermocalInputError(
            f"{source}'s thermometer and this sensor's record do not overlap in time"
        )
    if not keep.all():
        warnings.warn(
            ThermometerWarning(
                f"{source}'s thermometer covers {100 * keep.mean():.1f} % of the samples; "
                "the others are left out"
            ),
            stacklevel=2,
        )
    rec = reconstruct_temperature(st, sv, mode=mode, at_s=t[keep])
    return rec, keep


def reconstruct_columns(
    rec: Recording, names: Sequence[str], *, mode: TemperatureMode = "reconstructed"
) -> tuple[Recording, list[dict[str, Any]]]:
    """A recording's temperature columns with a quantised or slow thermometer reconstructed.

    Each column is judged in °C (:meth:`thermocal.recording.Recording.temperature_c`) and
    reconstructed (:func:`reconstruct_temperature`); the result goes back into the column's
    own unit (°F, K, raw counts) through the affine map between the two, so the model file
    keeps the unit the data were given in.

    Parameters
    ----------
    rec : thermocal.recording.Recording
        A recording.
    names : sequence of str
        Its temperature columns to look at.
    mode : {"reconstructed", "raw"}, optional
        ``"raw"``: the columns are left as they are (what they are is still returned).

    Returns
    -------
    (Recording, list of dict)
        The recording (a copy when a column changed), and per column
        :meth:`Reconstruction.to_dict` with ``column`` and ``file``.

    Raises
    ------
    ParameterError
        ``mode`` unknown.
    """
    if mode not in ("reconstructed", "raw"):
        raise ParameterError("temperature", f"{{name}} must be reconstructed or raw, got {mode!r}")
    new: dict[str, FloatArray] = {}
    said = []
    for name in names:
        own = np.asarray(rec.column(name), dtype=np.float64)
        try:
            in_c = np.asarray(rec.temperature_c(name), dtype=np.float64)
        except UnitError:  # raw counts without a conversion: a model in counts, left as given
            continue
        ok = np.isfinite(in_c) & np.isfinite(own)
        if not ok.any() or not float(np.min(in_c, where=ok, initial=np.inf)) < float(
            np.max(in_c, where=ok, initial=-np.inf)
        ):
            continue  # constant or empty: the data's judgement refuses it
        made = reconstruct_temperature(rec.time_s, in_c, mode=mode)
        said.append({"file": rec.name, "column": name, **made.to_dict()})
        if made.used != "reconstructed":
            continue
        slope, icpt = np.polyfit(own[ok], in_c[ok], 1)
        if not np.allclose(icpt + slope * own[ok], in_c[ok], rtol=0, atol=1e-6):
            said[-1].update(temperature="raw", note=f"{made.note}; not affine in its unit: kept")
            continue  # int16 wrap-around: not one affine map
        new[name] = (made.temp_c - icpt) / slope
    if not new:
        return rec, said
    return rec.with_columns(new, {n: rec.units[n] for n in new}), said  # each one's own unit


__all__ = [
    "MAX_STEP_C",
    "MIN_PERIOD_S",
    "MIN_STEP_C",
    "Reconstruction",
    "TemperatureMode",
    "Thermometer",
    "ThermometerWarning",
    "borrowed_temperature",
    "describe_thermometer",
    "lattice_step",
    "reconstruct_columns",
    "reconstruct_temperature",
    "temperature_knots",
    "update_period",
]
