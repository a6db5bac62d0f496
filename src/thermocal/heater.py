"""Heated IMUs: the heater's hold found in a temperature record, judged and thinned.

Most flight controllers hold their IMU at a set-point (ArduPilot ``BRD_HEAT_TARG``, older
firmware ``BRD_IMU_TARGTEMP``; PX4 ``SENS_IMU_TEMP`` with the heater started by
``SENS_EN_THERMAL``).  A thermal calibration recorded on such a board sweeps from the cold
start up to the set-point and then sits there: the sweep stops at the set-point, and the
hold's thousands of samples at one temperature would outweigh the sweep in a least-squares
fit.  This module finds the hold (:func:`find_heater_hold`), says what it does to the
calibration (:func:`judge_heater`: the range cut at the set-point, a log with nothing but
the hold refused) and thins the hold to the sweep's density (:func:`thin_hold`).

Pure functions on arrays; no file is read here.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError, ThermocalInputError, ThermocalWarning
from thermocal.recording import Recording

FloatArray = npt.NDArray[np.float64]

HOLD_BAND_C = 0.5
"""Default half-width of the band a hold stays in [°C] (± about the set-point)."""
MIN_HOLD_S = 60.0
"""Default shortest hold [s]."""
GAP_S = 1.0
"""Excursions out of the band shorter than this [s] (a spike, a coarse thermometer's
flicker) do not end a hold."""
MIN_SWEEP_C = 2.0
"""Below this span [°C] of the temperatures outside the hold there is no sweep to fit."""
MIN_HOLD_KEEP = 20
"""A thinned hold keeps at least this many samples."""
WARMUP_S = 600.0
"""Time below the set-point [s] up to which the stretch before a hold is the heater's
warm-up from power-on, not a sweep: a record with no more below the set-point (and none
after reaching it) is missing the cold end of its range."""
MIN_INFERRED_SWEEP_C = 10.0
"""An inferred hold needs this sweep outside it [°C] (ArduPilot's minimum learning range):
a self-heating warm-up of a few degrees, a turntable's or a chamber's hold at one
temperature have plateaus too, and no heater."""

HEATER_PARAMS: dict[str, tuple[tuple[str, ...], str | None, str]] = {
    "px4": (("SENS_IMU_TEMP",), "SENS_EN_THERMAL", "SENS_EN_THERMAL=0"),
    "ardupilot": (("BRD_HEAT_TARG", "BRD_IMU_TARGTEMP"), None, "BRD_HEAT_TARG=-1"),
}
"""Per firmware: the set-point parameters (newest name first), the parameter that starts
the heater (None: the set-point itself, −1 meaning off) and how the heater is turned off.
PX4 ``src/drivers/heater/heater_params.c`` (``SENS_IMU_TEMP`` [°C], default 55) and
``src/modules/sensors/sensor_params.c`` (``SENS_EN_THERMAL``: −1 unavailable, 0 off,
1 on); ArduPilot ``libraries/AP_BoardConfig/AP_BoardConfig.cpp`` (``BRD_HEAT_TARG``
[°C], −1 disables the heater; ``BRD_IMU_TARGTEMP`` before it was renamed)."""


class HeaterPolicy(enum.StrEnum):
    """What a calibration does with a heater's hold.

    ``cut`` (default): fit the sweep up to the set-point with the hold thinned to the
    sweep's density, and say that the range is cut; ``refuse``: a range cut by the heater
    is an error; ``ignore``: no hold is looked for, every sample is fitted as it is.
    """

    CUT = "cut"
    REFUSE = "refuse"
    IGNORE = "ignore"


class HeaterWarning(ThermocalWarning):
    """A heater's hold found, or its set-point never reached."""


@dataclass(frozen=True)
class HeaterOptions:
    """How a calibration looks for a heater's hold.

    Parameters
    ----------
    policy : HeaterPolicy
        ``cut`` (default), ``refuse`` or ``ignore`` (:class:`HeaterPolicy`).
    setpoint_c : float, optional
        The set-point [°C]; default the log's heater parameter, else inferred.
    band_c : float
        Half-width of the hold's band [°C] (default ±0.5 °C).
    min_hold_s : float
        Shortest hold [s] (default 60 s).

    Raises
    ------
    thermocal.errors.ParameterError
        A band or duration not positive, a policy not one of the three, a set-point not a
        finite temperature.
    """

    policy: HeaterPolicy = HeaterPolicy.CUT
    setpoint_c: float | None = None
    band_c: float = HOLD_BAND_C
    min_hold_s: float = MIN_HOLD_S

    def __post_init__(self) -> None:
        try:
            object.__setattr__(self, "policy", HeaterPolicy(self.policy))
        except ValueError:
            raise ParameterError(
                "heater", f"{{name}} must be cut, refuse or ignore, got {self.policy!r}"
            ) from None
        if self.setpoint_c is not None and not -273.15 < self.setpoint_c < math.inf:
            raise ParameterError(
                "heater_setpoint",
                f"{{name}} must be a finite temperature above −273.15 °C, got {self.setpoint_c}",
            )
        if not 0 < self.band_c < math.inf:
            raise ParameterError("heater_band", f"{{name}} must be positive, got {self.band_c:g}")
        if not 0 < self.min_hold_s < math.inf:
            raise ParameterError(
                "heater_min_hold", f"{{name}} must be positive, got {self.min_hold_s:g}"
            )


@dataclass(frozen=True)
class HeaterHold:
    """A heater's hold in a temperature record.

    Attributes
    ----------
    setpoint_c : float
        The set-point [°C].
    setpoint_source : str
        ``"parameter NAME"`` (the log's heater parameter), ``"given"`` or ``"inferred"``
        (the level of the record's one long plateau).
    band_c : float
        Half-width of the band asked for [°C].
    reached_s : float
        When the temperature first reached the set-point [s] (linear interpolation between
        the samples either side; the first sample when the record starts there).
    hold_start_s, hold_end_s : float
        The hold: the longest stretch within ``± band_c`` of the set-point [s].
    held_c : (float, float)
        The band actually held: lowest and highest temperature minus the set-point [°C].
    overshoot_c : float
        Peak above the set-point between reaching it and the hold's start [°C] (0: none).
    overshoot_at_s : float
        When that peak was [s].
    settling_s : float
        ``hold_start_s − reached_s`` (0 when the hold begins before the set-point is
        crossed) [s].
    heater_off_s : float or None
        When the temperature left the band for good before the end of the record (the
        heater turned off) [s]; None: held to the end.
    n_hold, n_sweep : int
        Samples in the hold and outside it.
    sweep_c : (float, float)
        Lowest and highest temperature outside the hold [°C].
    range_cut : bool
        The hold is the top of the record (no sample above the set-point beyond its band
        and overshoot): the calibrated range ends at the set-point.
    cold_cut : bool
        The hold is the bottom of the record: after reaching the set-point the temperature
        never went below its band, and before it spent at most :data:`WARMUP_S` below it
        (a warm-up from power-on), while the sweep goes on above it: the calibrated range
        starts at the set-point (a chamber sweep recorded with the heater on).
    """

    setpoint_c: float
    setpoint_source: str
    band_c: float
    reached_s: float
    hold_start_s: float
    hold_end_s: float
    held_c: tuple[float, float]
    overshoot_c: float
    overshoot_at_s: float
    settling_s: float
    heater_off_s: float | None
    n_hold: int
    n_sweep: int
    sweep_c: tuple[float, float]
    range_cut: bool
    cold_cut: bool = False

    @property
    def hold_s(self) -> float:
        """Duration of the hold [s]."""
        return self.hold_end_s - self.hold_start_s

    def to_dict(self) -> dict[str, Any]:
        """The hold as a JSON object (the ``heater`` key of the commands' JSON output)."""
        return {
            "setpoint_c": self.setpoint_c,
            "setpoint_source": self.setpoint_source,
            "band_c": self.band_c,
            "reached_s": self.reached_s,
            "hold_start_s": self.hold_start_s,
            "hold_end_s": self.hold_end_s,
            "hold_s": self.hold_s,
            "held_c": list(self.held_c),
            "overshoot_c": self.overshoot_c,
            "overshoot_at_s": self.overshoot_at_s,
            "settling_s": self.settling_s,
            "heater_off_s": self.heater_off_s,
            "n_hold": self.n_hold,
            "n_sweep": self.n_sweep,
            "sweep_c": list(self.sweep_c),
            "range_cut": self.range_cut,
            "cold_cut": self.cold_cut,
        }


def heater_setpoint(params: Mapping[str, float], firmware: str) -> tuple[float | None, str | None]:
    """The heater's set-point from a flight-controller log's parameters.

    Parameters
    ----------
    params : mapping of str to float
        The log's parameters (name → value).
    firmware : {"px4", "ardupilot"}
        Whose parameters they are (:data:`HEATER_PARAMS`).

    Returns
    -------
    setpoint_c : float or None
        The set-point [°C]; None when no heater parameter is in the log or the heater is
        off.
    source : str or None
        The parameter it came from (``"SENS_IMU_TEMP"``), or why there is none
        (``"SENS_EN_THERMAL=0"``: heater off); None when the log has no heater parameter.

    References
    ----------
    - PX4 ``src/drivers/heater/heater_params.c``, ``src/modules/sensors/sensor_params.c``.
    - ArduPilot ``libraries/AP_BoardConfig/AP_BoardConfig.cpp``.

    Examples
    --------
    >>> heater_setpoint({"SENS_EN_THERMAL": 1, "SENS_IMU_TEMP": 55.0}, "px4")
    (55.0, 'SENS_IMU_TEMP')
    >>> heater_setpoint({"BRD_HEAT_TARG": -1.0}, "ardupilot")
    (None, 'BRD_HEAT_TARG=-1')
    """
    names, enable, _off = HEATER_PARAMS[firmware]
    if enable is not None and enable in params and params[enable] < 1:
        return None, f"{enable}={params[enable]:g}"
    for name in names:
        if name in params:
            value = float(params[name])
            if value < 0:
                return None, f"{name}={value:g}"
            return value, name
    return None, None


def _runs(mask: npt.NDArray[np.bool_], time_s: FloatArray, gap_s: float) -> list[tuple[int, int]]:
    """Index ranges [a, b] of ``mask``'s true stretches, joined across gaps shorter than
    ``gap_s`` [s]."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate(([idx[0]], idx[breaks + 1]))
    ends = np.concatenate((idx[breaks], [idx[-1]]))
    out: list[tuple[int, int]] = [(int(starts[0]), int(ends[0]))]
    for a, b in zip(starts[1:], ends[1:], strict=True):
        if time_s[a] - time_s[out[-1][1]] <= gap_s:
            out[-1] = (out[-1][0], int(b))
        else:
            out.append((int(a), int(b)))
    return out


def _longest_run(
    time_s: FloatArray, temp_c: FloatArray, level_c: float, band_c: float
) -> tuple[int, int] | None:
    """The longest stretch (by duration) within ``level_c ± band_c``."""
    runs = _runs(np.abs(temp_c - level_c) <= band_c, time_s, GAP_S)
    if not runs:
        return None
    return max(runs, key=lambda r: time_s[r[1]] - time_s[r[0]])


HOLD_MAX_SAMPLES = 250_000
"""Samples a hold is looked for in: a longer record is searched on every k-th sample (k the
smallest that keeps at most this many; the hold's times then to k sample intervals), at a
bounded cost (the search holds about 26 B per sample searched)."""

MAX_WINDOWS = 100_000
"""Most band-wide temperature windows searched for a plateau (10 000 °C at 0.1 °C): a
temperature spanning more is a damaged record, and no set-point is inferred from it."""


WINDOW_BLOCK = 8192
"""Samples binned at a time by :func:`_window_time`: its scratch arrays (64 kB each) are
reused block after block instead of a record-long array each (fresh pages are what the
binning of a long record costs most)."""


def _window_time(temp_c: FloatArray, weights: FloatArray, edges: FloatArray) -> FloatArray:
    r"""The time spent in each temperature window: ``np.histogram(temp_c, bins=edges,
    weights=weights)[0]`` without its sort, for equally spaced ``edges`` [s].

    A sample's window is first estimated on the lattice, :math:`i = \lfloor (T - e_0)/h
    \rfloor` (at most :math:`m - 1`) with :math:`h = (e_m - e_0)/m`, then corrected by one
    step against the edges themselves (:math:`e_i \le T < e_{i+1}`, the last window
    closed), so that every sample falls in the window ``np.histogram`` gives it; the
    weights are summed per window by ``np.bincount``, :data:`WINDOW_BLOCK` samples at a
    time (no sort: ``np.histogram`` with explicit edges sorts the samples and differences
    a cumulative sum; the same sums to rounding).  Samples outside ``[e_0, e_m]`` are left
    out, as ``np.histogram`` leaves them.
    """
    m = edges.size - 1
    inside = (temp_c >= edges[0]) & (temp_c <= edges[-1])
    if not inside.all():
        temp_c, weights = temp_c[inside], weights[inside]
    scale = m / (edges[-1] - edges[0])
    out = np.zeros(m)
    k = min(WINDOW_BLOCK, temp_c.size)
    pos, idx, step = np.empty(k), np.empty(k, dtype=np.intp), np.empty(k, dtype=bool)
    for a in range(0, temp_c.size, WINDOW_BLOCK):
        x = temp_c[a : a + WINDOW_BLOCK]
        p, i, s = pos[: x.size], idx[: x.size], step[: x.size]
        np.subtract(x, edges[0], out=p)
        p *= scale
        i[...] = p  # truncation is the floor here: p >= 0
        np.minimum(i, m - 1, out=i)
        np.less(x, np.take(edges, i, out=p), out=s)  # the lattice's rounding: edges decide
        i -= s
        np.greater_equal(x, np.take(edges[1:], i, out=p), out=s)
        s &= i < m - 1
        i += s
        out += np.bincount(i, weights=weights[a : a + WINDOW_BLOCK], minlength=m)
    return out


def _infer_setpoint(
    time_s: FloatArray, temp_c: FloatArray, band_c: float, min_hold_s: float
) -> float | None:
    """The level of the record's one plateau at its top, or None.

    The candidate is the median of the samples in the band-wide temperature window where
    the record spends the most time; it is a heater's hold when it lasts ``min_hold_s``,
    nothing outside it stays ``max(min_hold_s, hold / 4)`` in any other window of the same
    width away from the hold (a chamber's step program has several plateaus, a cold soak
    among them; a heater one), the temperatures outside it span
    :data:`MIN_INFERRED_SWEEP_C`, and no sample outside it
    is more than ``2 band_c`` above it except an overshoot before the hold.
    """
    dt = np.diff(time_s, append=time_s[-1])
    lo, hi = float(np.min(temp_c)), float(np.max(temp_c))
    if (hi - lo) / band_c > MAX_WINDOWS:  # no thermometer of a board spans this: no plateau
        return None
    edges = np.arange(lo, hi + 2 * band_c, band_c)
    if edges.size < 3:
        return None
    spent = _window_time(temp_c, dt, edges)
    pair = spent[:-1] + spent[1:]
    k = int(np.argmax(pair))
    inside = (temp_c >= edges[k]) & (temp_c <= edges[k + 2])
    level = float(np.median(temp_c[inside]))
    run = _longest_run(time_s, temp_c, level, band_c)
    if run is None or time_s[run[1]] - time_s[run[0]] < min_hold_s:
        return None
    level = float(np.median(temp_c[run[0] : run[1] + 1]))  # the hold's own level
    run = _longest_run(time_s, temp_c, level, band_c)
    if run is None or time_s[run[1]] - time_s[run[0]] < min_hold_s:
        return None
    out = np.ones(temp_c.size, dtype=bool)
    out[run[0] : run[1] + 1] = False
    if np.any(temp_c[run[1] + 1 :] > level + 2 * band_c):
        return None  # hotter after the plateau: a step of a program, not a heater's hold
    if not out.any() or float(np.ptp(temp_c[out])) < MIN_INFERRED_SWEEP_C:
        return None  # a plateau with no sweep to speak of: a warm-up, a hold, no heater
    far = out & (np.abs(temp_c - level) > 2 * band_c)
    rest = _window_time(temp_c[far], dt[far], edges)
    held_s = float(time_s[run[1]] - time_s[run[0]])
    if rest.size > 1 and float(np.max(rest[:-1] + rest[1:])) >= max(min_hold_s, held_s / 4):
        return None
    return level


def find_heater_hold(
    time_s: FloatArray,
    temp_c: FloatArray,
    *,
    setpoint_c: float | None = None,
    setpoint_source: str = "given",
    band_c: float = HOLD_BAND_C,
    min_hold_s: float = MIN_HOLD_S,
) -> HeaterHold | None:
    r"""Find a heater's hold: the temperature held within a band about a set-point.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times, ascending [s].
    temp_c : numpy.ndarray
        The IMU's temperature [°C], same length.
    setpoint_c : float, optional
        The heater's set-point [°C] (from the log's parameters,
        :func:`heater_setpoint`); None: inferred from the record's one plateau at its top
        (none found: None returned).
    setpoint_source : str, optional
        Where ``setpoint_c`` came from, recorded in the result (``"parameter NAME"``).
    band_c : float, optional
        Half-width of the band [°C] (default :data:`HOLD_BAND_C`, ±0.5 °C).
    min_hold_s : float, optional
        Shortest hold [s] (default :data:`MIN_HOLD_S`, 60 s).

    Returns
    -------
    HeaterHold or None
        The hold (set-point, when it was reached, the band held, overshoot, settling time,
        sweep outside it), or None when the temperature never stays ``min_hold_s`` within
        the band.

    Raises
    ------
    thermocal.errors.ParameterError
        ``band_c`` or ``min_hold_s`` not positive, arrays of different lengths.

    Notes
    -----
    The hold is the longest stretch of samples with :math:`|T - T_{sp}| \le b`
    (excursions shorter than :data:`GAP_S` joined); it must last ``min_hold_s``.  The
    set-point is reached at the first upward crossing, interpolated linearly between the
    samples :math:`i-1, i` either side:

    .. math:: t_r = t_{i-1} + (t_i - t_{i-1})\,\frac{T_{sp} - T_{i-1}}{T_i - T_{i-1}}

    overshoot is :math:`\max(T) - T_{sp}` between :math:`t_r` and the hold's start, and
    the settling time the hold's start minus :math:`t_r` — the settling time of a step
    response (IEEE Std 1554-2005 gives the same for an inertial sensor's warm-up).

    References
    ----------
    - IEEE Std 1554-2005, *IEEE Recommended Practice for Inertial Sensor Test Equipment,
      Instrumentation, Data Acquisition, and Analysis* (warm-up and settling).
    - PX4 ``src/drivers/heater/heater_params.c``; ArduPilot
      ``libraries/AP_BoardConfig/AP_BoardConfig.cpp`` (the set-point parameters).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 600.0, 0.1)
    >>> T = np.minimum(20.0 + 0.2 * t, 55.0)  # 0.2 °C/s up to 55 °C, then held
    >>> hold = find_heater_hold(t, T, setpoint_c=55.0)
    >>> round(hold.reached_s, 1), round(hold.hold_s, 1), hold.range_cut
    (175.0, 427.4, True)
    """
    time_s = np.asarray(time_s, dtype=np.float64)
    temp_c = np.asarray(temp_c, dtype=np.float64)
    if time_s.shape != temp_c.shape:
        raise ParameterError("temp_c", "{name} must have the length of the times")
    if not band_c > 0:
        raise ParameterError("band_c", f"{{name}} must be positive, got {band_c:g}")
    if not min_hold_s > 0:
        raise ParameterError("min_hold_s", f"{{name}} must be positive, got {min_hold_s:g}")
    ok = np.isfinite(time_s) & np.isfinite(temp_c)  # a reading lost: the others still tell
    if not ok.all():
        time_s, temp_c = time_s[ok], temp_c[ok]
    stride = -(-temp_c.size // HOLD_MAX_SAMPLES)  # a long record: every stride-th sample
    time_s, temp_c = time_s[::stride], temp_c[::stride]
    if temp_c.size < 2:
        return None
    if setpoint_c is None:
        setpoint_c = _infer_setpoint(time_s, temp_c, band_c, min_hold_s)
        setpoint_source = "inferred"
        if setpoint_c is None:
            return None
    run = _longest_run(time_s, temp_c, setpoint_c, band_c)
    if run is None or time_s[run[1]] - time_s[run[0]] < min_hold_s:
        return None
    return _describe(time_s, temp_c, float(setpoint_c), setpoint_source, band_c, run)


def _reached(time_s: FloatArray, temp_c: FloatArray, sp: float, band_c: float, stop: int) -> float:
    """The first upward crossing of ``sp`` before index ``stop`` [s]: the line fitted to the
    ramp's last ``2 band_c`` below it, solved for ``sp`` (a noisy thermometer's first
    crossing is early by its noise over the ramp rate); too few samples or a ramp not rising:
    linear interpolation between the samples either side."""
    above = np.flatnonzero(temp_c[: stop + 1] >= sp)
    i = int(above[0]) if above.size else stop
    if i == 0:
        return float(time_s[0])
    near = np.flatnonzero(temp_c[:i] < sp - 2 * band_c)
    j = int(near[-1]) + 1 if near.size else 0
    if i - j >= 5:
        slope, icept = np.polyfit(time_s[j:i] - time_s[i], temp_c[j:i], 1)
        if slope > 0:
            at = float(time_s[i] + (sp - icept) / slope)
            if time_s[j] <= at <= time_s[min(stop, temp_c.size - 1)]:
                return at
    t0, t1, y0, y1 = time_s[i - 1], time_s[i], temp_c[i - 1], temp_c[i]
    if y1 <= y0:
        return float(t1)
    return float(t0 + (t1 - t0) * (sp - y0) / (y1 - y0))


def _describe(
    time_s: FloatArray, temp_c: FloatArray, sp: float, source: str, band_c: float,
    run: tuple[int, int],
) -> HeaterHold:  # fmt: skip
    """The :class:`HeaterHold` of the stretch ``run``."""
    a, b = run
    reached = _reached(time_s, temp_c, sp, band_c, b)
    i_r = int(np.searchsorted(time_s, reached))
    seg = temp_c[i_r : a + 1]
    if seg.size and float(np.max(seg)) > sp:
        k = int(np.argmax(seg))
        overshoot, over_at = float(seg[k] - sp), float(time_s[i_r + k])
    else:
        overshoot, over_at = 0.0, reached
    held = temp_c[max(a, min(i_r, b)) : b + 1] - sp  # the band held once the set-point is reached
    outside = np.ones(temp_c.size, dtype=bool)
    outside[a : b + 1] = False
    rest = temp_c[outside]
    sweep = (float(np.min(rest)), float(np.max(rest))) if rest.size else (sp, sp)
    return HeaterHold(
        setpoint_c=sp,
        setpoint_source=source,
        band_c=band_c,
        reached_s=reached,
        hold_start_s=float(time_s[a]),
        hold_end_s=float(time_s[b]),
        held_c=(float(np.min(held)), float(np.max(held))),
        overshoot_c=overshoot,
        overshoot_at_s=over_at,
        settling_s=max(0.0, float(time_s[a]) - reached),
        heater_off_s=float(time_s[b]) if b < temp_c.size - 1 else None,
        n_hold=int(b - a + 1),
        n_sweep=int(rest.size),
        sweep_c=sweep,
        range_cut=bool(float(np.max(temp_c)) <= sp + band_c + overshoot),
        cold_cut=_cold_cut(time_s, temp_c, sp, band_c, i_r, overshoot),
    )


def _cold_cut(
    time_s: FloatArray, temp_c: FloatArray, sp: float, band_c: float, i_r: int, overshoot: float
) -> bool:
    """The hold is the bottom of the record: nothing below the band once the set-point is
    reached (index ``i_r``), at most :data:`WARMUP_S` below it before, a sweep above it."""
    below = temp_c < sp - band_c
    if below[i_r:].any() or float(np.max(temp_c)) <= sp + band_c + overshoot:
        return False
    dt = float(np.median(np.diff(time_s))) if time_s.size > 1 else 0.0
    return bool(np.count_nonzero(below[:i_r]) * dt <= WARMUP_S)


def hold_mask(time_s: FloatArray, hold: HeaterHold) -> npt.NDArray[np.bool_]:
    """The samples of the hold (``hold_start_s ≤ t ≤ hold_end_s``).

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    hold : HeaterHold
        The hold found in them.

    Returns
    -------
    numpy.ndarray of bool
        True for the hold's samples.
    """
    t = np.asarray(time_s, dtype=np.float64)
    return (t >= hold.hold_start_s) & (t <= hold.hold_end_s)


def thin_hold(time_s: FloatArray, temp_c: FloatArray, hold: HeaterHold) -> npt.NDArray[np.bool_]:
    r"""The samples a fit keeps: every sample of the sweep, the hold thinned to its density.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    temp_c : numpy.ndarray
        Temperatures [°C].
    hold : HeaterHold
        The hold (:func:`find_heater_hold`).

    Returns
    -------
    numpy.ndarray of bool
        True for the samples kept.

    Notes
    -----
    The sweep outside the hold has :math:`\rho = n_{sweep} / (T_{max} - T_{min})` samples
    per °C; the hold spans :math:`w = \max(P_{95} - P_5, 0.1)` °C (the central 90 % of its
    temperatures: its overshoot's tail and the thermometer's extremes left out) and keeps
    :math:`n = \max(20, \lceil \rho w \rceil)` of its samples, evenly spaced in time — the
    same density per °C as the sweep, so that it weighs no more in a least-squares fit
    than any other stretch of the range of its width.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 600.0, 0.1)
    >>> T = np.minimum(20.0 + 0.2 * t, 55.0)
    >>> keep = thin_hold(t, T, find_heater_hold(t, T, setpoint_c=55.0))
    >>> int(keep.sum()) < t.size
    True
    """
    t = np.asarray(time_s, dtype=np.float64)
    inside = hold_mask(t, hold)
    keep = ~inside
    span = hold.sweep_c[1] - hold.sweep_c[0]
    p5, p95 = np.percentile(np.asarray(temp_c, dtype=np.float64)[inside], [5.0, 95.0])
    width = max(float(p95 - p5), 0.1)
    n_in = int(np.count_nonzero(inside))
    want = n_in if span <= 0 else max(MIN_HOLD_KEEP, math.ceil(hold.n_sweep / span * width))
    idx = np.flatnonzero(inside)
    if want < n_in:
        idx = idx[np.unique(np.linspace(0, n_in - 1, want).round().astype(np.intp))]
    keep[idx] = True
    return keep


HEATER_OFF = {"px4": "SENS_EN_THERMAL=0", "ardupilot": "BRD_HEAT_TARG=-1"}
"""How to calibrate with the heater off, per firmware (None: any other recording)."""


@dataclass(frozen=True)
class HeaterJudgement:
    """What a heater's hold does to a calibration (:func:`judge_heater`).

    Attributes
    ----------
    hold : HeaterHold or None
        The hold found (None: none).
    keep : numpy.ndarray of bool or None
        The samples to fit (the hold thinned, :func:`thin_hold`); None: every sample.
    notes : tuple of str
        Sentences for the calibration's notes (the hold, what the range covers).
    warnings : tuple of str
        Doubts said to the user as warnings (the range cut, a set-point never held).
    """

    hold: HeaterHold | None
    keep: npt.NDArray[np.bool_] | None
    notes: tuple[str, ...]
    warnings: tuple[str, ...]

    def to_dict(self) -> dict[str, Any] | None:
        """The hold as JSON (None: none found)."""
        return None if self.hold is None else self.hold.to_dict()


def hold_sentence(hold: HeaterHold) -> str:
    """One sentence: the set-point, the hold, the band held, overshoot and settling.

    Parameters
    ----------
    hold : HeaterHold
        The hold.

    Returns
    -------
    str
        The sentence (times in the record's seconds).
    """
    lo, hi = hold.held_c
    return (
        f"heater hold at {hold.setpoint_c:.2f} °C ({hold.setpoint_source}) reached at "
        f"{hold.reached_s:.1f} s, held {hold.hold_start_s:.1f}…{hold.hold_end_s:.1f} s "
        f"within {lo:+.2f}…{hi:+.2f} °C, overshoot {hold.overshoot_c:.2f} °C at "
        f"{hold.overshoot_at_s:.1f} s, settled {hold.settling_s:.1f} s after reaching it"
        + (f", heater off at {hold.heater_off_s:.1f} s" if hold.heater_off_s is not None else "")
    )


def _never_held(
    where: str, temp_c: FloatArray, setpoint_c: float | None, source: str
) -> HeaterJudgement:
    """No hold: a set-point known but never held is said (a warning and a note)."""
    if setpoint_c is None:
        return HeaterJudgement(None, None, (), ())
    said = (
        f"{where}: the heater's set-point {setpoint_c:.1f} °C ({source}) is never held (the "
        f"temperature peaks at {float(np.max(temp_c)):.1f} °C): no hold found, the sweep is "
        "fitted as it is",
    )
    return HeaterJudgement(None, None, said, said)


def judge_heater(
    time_s: FloatArray,
    temp_c: FloatArray,
    *,
    where: str,
    policy: HeaterPolicy = HeaterPolicy.CUT,
    setpoint_c: float | None = None,
    setpoint_source: str = "given",
    firmware: str | None = None,
    band_c: float = HOLD_BAND_C,
    min_hold_s: float = MIN_HOLD_S,
) -> HeaterJudgement:
    """Find a heater's hold and judge what it does to the calibration.

    Parameters
    ----------
    time_s, temp_c : numpy.ndarray
        Sample times [s] and the IMU's temperature [°C].
    where : str
        The record's name in messages (file, topic).
    policy : HeaterPolicy, optional
        ``cut`` (default): the hold thinned, the cut range said as a warning; ``refuse``:
        a range cut at the set-point is an error; ``ignore``: nothing looked for.
    setpoint_c : float, optional
        The set-point [°C] (the log's parameter, :func:`heater_setpoint`, or the user's);
        when it is never held, a plateau at the top of the record is looked for instead.
    setpoint_source : str, optional
        Where ``setpoint_c`` came from (a parameter's name, ``"given"``).
    firmware : {"px4", "ardupilot"}, optional
        Whose parameters turn the heater off, named in the messages (:data:`HEATER_OFF`).
    band_c, min_hold_s : float, optional
        The hold's band [°C] and shortest duration [s] (:func:`find_heater_hold`).

    Returns
    -------
    HeaterJudgement
        The hold, the samples to fit, notes and warnings.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        The record is the hold and nothing else (no sweep of :data:`MIN_SWEEP_C` outside
        it), or ``policy`` is ``refuse`` and the range is cut at the set-point.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 600.0, 0.1)
    >>> T = np.minimum(20.0 + 0.2 * t, 55.0)
    >>> j = judge_heater(t, T, where="log", setpoint_c=55.0, setpoint_source="SENS_IMU_TEMP")
    >>> j.hold.range_cut, int(j.keep.sum()) < t.size
    (True, True)
    """
    if policy is HeaterPolicy.IGNORE:
        return HeaterJudgement(None, None, (), ())
    hold = None
    if setpoint_c is not None:
        hold = find_heater_hold(
            time_s, temp_c, setpoint_c=setpoint_c, setpoint_source=f"parameter {setpoint_source}"
            if setpoint_source != "given" else "given", band_c=band_c, min_hold_s=min_hold_s,
        )  # fmt: skip
    if hold is None:
        hold = find_heater_hold(time_s, temp_c, band_c=band_c, min_hold_s=min_hold_s)
    off = f" ({HEATER_OFF[firmware]})" if firmware in HEATER_OFF else ""
    beyond = (
        "above TMAX the firmware clamps the temperature: no correction beyond"
        if firmware in HEATER_OFF
        else "beyond it the model extrapolates"
    )
    if hold is None:
        return _never_held(where, temp_c, setpoint_c, setpoint_source)
    if hold.sweep_c[1] - hold.sweep_c[0] < MIN_SWEEP_C:  # a set-point given or logged
        raise ThermocalInputError(
            f"{where}: the temperature sits at the heater's set-point {hold.setpoint_c:.1f} °C "
            f"({hold.setpoint_source}) for the whole log: no sweep to calibrate; record again "
            f"from a cold start with the heater off{off}"
        )
    sentence = hold_sentence(hold)
    tail = _cut_sentence(hold, temp_c, off, beyond)
    if tail is None:
        return HeaterJudgement(hold, thin_hold(time_s, temp_c, hold), (sentence,), ())
    cut = f"{where}: {sentence}: {tail}"
    if policy is HeaterPolicy.REFUSE:
        raise ThermocalInputError.naming(
            cut + ", or give {heater} cut to calibrate the range the heater left", "heater"
        )
    return HeaterJudgement(hold, thin_hold(time_s, temp_c, hold), (sentence, tail), (cut,))


def _cut_sentence(hold: HeaterHold, temp_c: FloatArray, off: str, beyond: str) -> str | None:
    """What the hold cuts off the calibrated range (its top or its cold end), or None."""
    if hold.range_cut:
        return (
            "the calibrated range ends at the set-point (the log's highest temperature "
            f"{float(np.max(temp_c)):.1f} °C; {beyond}); to calibrate above it record with "
            f"the heater off{off} or its set-point raised"
        )
    if hold.cold_cut:
        return (
            "the cold end of the range is missing: once the heater reached its set-point the "
            "temperature never went below it (the sweep runs from the set-point up to "
            f"{float(np.max(temp_c)):.1f} °C; below it only the warm-up from power-on); to "
            f"calibrate below it record the sweep with the heater off{off}"
        )
    return None


def thin_recording(
    rec: Recording,
    options: HeaterOptions,
    *,
    where: str,
    temperature: str | None = None,
) -> tuple[Recording, HeaterJudgement]:
    """A recording with its heater's hold thinned to the sweep's density (:func:`thin_hold`).

    Parameters
    ----------
    rec : thermocal.recording.Recording
        The recording (any: a CSV of a heated sensor, a flight-controller log).
    options : HeaterOptions
        The policy, a set-point (default inferred), band and shortest hold.
    where : str
        The recording's name in messages.
    temperature : str, optional
        The temperature column the hold is looked for in (default the first).

    Returns
    -------
    recording : thermocal.recording.Recording
        ``rec`` itself when no hold is found (or its temperature is in raw counts without a
        conversion to °C and no set-point is given: nothing to judge), else its samples kept.
    judgement : HeaterJudgement
        The hold, notes and warnings.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        As :func:`judge_heater`: nothing but the hold, or a cut range refused.
    """
    from thermocal.errors import UnitError

    try:
        temp_c = rec.temperature_c(temperature)
    except UnitError:  # raw counts without a conversion: a model in counts, no °C to judge
        if options.setpoint_c is not None:
            raise
        return rec, HeaterJudgement(None, None, (), ())
    judged = judge_heater(
        rec.time_s, temp_c, where=where, policy=options.policy,
        setpoint_c=options.setpoint_c, band_c=options.band_c, min_hold_s=options.min_hold_s,
    )  # fmt: skip
    if judged.keep is None:
        return rec, judged
    return rec.select(judged.keep), judged
