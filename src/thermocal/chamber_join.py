"""A chamber's (or data logger's) own clock joined to a sensor's recording.

The log's clock and the recording's time are related by an offset and a rate (the
clock drift, in ppm):

.. math::

    \\tau(t) = o + (1 + \\delta)\\,(t - t_0)

where :math:`t` is the recording's time [s], :math:`t_0` its first sample, :math:`\\tau` the
log's clock [s] counted from the log's first row, :math:`o` the offset [s] (where the
recording's first sample falls on the log's clock) and :math:`\\delta` the drift (the log's
clock gains :math:`\\delta \\times 10^6` ppm on the recording's).  The log's temperature is then
interpolated (linearly) at :math:`\\tau(t)`.

The offset comes from one of three places (:attr:`ClockJoin.method`):

* ``given``: stated by the user (the drift too, 0 unless stated);
* ``absolute``: both clocks are absolute (the recording's in UTC, the log's local with a
  date) and the log's time zone is given: :math:`o = t_0 + z - \\tau_{\\text{first}}`;
* ``correlation``: found from the recording's own temperature.  A grid search on the
  correlation coefficient picks the offset, then the least-squares fit of
  :math:`y(t) = a + b\\,L(\\tau(t))` (:math:`y` the recording's temperature, :math:`L` the log's)
  by Gauss-Newton gives :math:`o` and :math:`\\delta` with their standard uncertainties
  :math:`\\sigma^2 = s^2 (J^\\top J)^{-1}` (Seber & Wild 1989, §2.1), :math:`s^2` inflated by
  :math:`(1 + \\rho)/(1 - \\rho)` for the residuals' lag-one autocorrelation :math:`\\rho`
  (the effective number of samples, Bretherton et al. 1999), plus the log's own rounding
  (:func:`log_resolution`: a uniform error of variance :math:`q^2/12` per reading, Widrow &
  Kollár 2008, carried through the interpolation).  The offset found includes the
  sensor's thermal lag behind the chamber air: the recording's temperature follows the
  air late, so the log seems late by that lag.

Pure functions on arrays (numpy only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import ThermocalInputError

FloatArray = npt.NDArray[np.float64]

MIN_CORRELATION = 0.8
"""Below this correlation coefficient of the recording's temperature with the log's at the
best offset, the log is not taken to follow the recording (another run, another day): the
join is refused, asking for the offset."""

MAX_GRID = 4000
"""Most offsets tried by the correlation's grid search (the step widens beyond)."""

MAX_FIT_POINTS = 20_000
"""Most recording samples the Gauss-Newton fit uses (evenly thinned beyond)."""

MAX_ITERATIONS = 30
"""Gauss-Newton iterations at most."""

SECONDS_PER_DAY = 86_400.0


@dataclass(frozen=True)
class ClockJoin:
    """How a log's clock maps onto a recording's time.

    Attributes
    ----------
    method : {"correlation", "given", "absolute"}
        Where the offset comes from.
    offset_s : float
        :math:`o`: the log's clock [s] (from its first row) at the recording's first sample.
    offset_sigma_s : float or None
        Its standard uncertainty [s]; None when given.
    drift_ppm : float
        :math:`\\delta` [ppm]: the log's clock gains this on the recording's.
    drift_sigma_ppm : float or None
        Its standard uncertainty [ppm]; None when given (or assumed 0).
    timezone : str or None
        The log's time zone (``"UTC+02:00"``) when both clocks are absolute.
    correlation : float or None
        The correlation coefficient of the two temperatures once joined.
    log_span_s : tuple of float
        The log's first and last clock times [s] (from its first row: 0 and its length).
    covered_s : tuple of float
        The log clock's times [s] the recording spans once mapped.
    """

    method: str
    offset_s: float
    offset_sigma_s: float | None
    drift_ppm: float
    drift_sigma_ppm: float | None
    timezone: str | None
    correlation: float | None
    log_span_s: tuple[float, float]
    covered_s: tuple[float, float]

    def clock(self, t: npt.ArrayLike, t0: float) -> FloatArray:
        """The log's clock :math:`\\tau = o + (1 + \\delta)(t - t_0)` [s] at recording times.

        Parameters
        ----------
        t : array_like
            Recording times [s].
        t0 : float
            The recording's first time [s].

        Returns
        -------
        numpy.ndarray
            The log's clock [s], from its first row.
        """
        u = np.asarray(t, dtype=np.float64) - t0
        return self.offset_s + (1.0 + self.drift_ppm * 1e-6) * u

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (keys as the attributes)."""
        return {
            "method": self.method,
            "offset_s": self.offset_s,
            "offset_sigma_s": self.offset_sigma_s,
            "drift_ppm": self.drift_ppm,
            "drift_sigma_ppm": self.drift_sigma_ppm,
            "timezone": self.timezone,
            "correlation": self.correlation,
            "log_span_s": list(self.log_span_s),
            "covered_s": list(self.covered_s),
        }


def timezone_seconds(text: str) -> float:
    """``"+02:00"``, ``"-0530"``, ``"UTC+1"`` or ``"Z"`` → the offset from UTC [s].

    Parameters
    ----------
    text : str
        The zone: ``Z``/``UTC`` or a sign, hours and optional minutes.

    Returns
    -------
    float
        Local time minus UTC [s].

    Raises
    ------
    ThermocalInputError
        Not a zone offset of at most ±14 h (naming ``chamber_tz``).

    Examples
    --------
    >>> timezone_seconds("+02:00"), timezone_seconds("UTC-5"), timezone_seconds("Z")
    (7200.0, -18000.0, 0.0)
    """
    s = text.strip().upper().removeprefix("UTC").removeprefix("GMT")
    if s in ("", "Z"):
        return 0.0
    sign = {"+": 1.0, "-": -1.0}.get(s[:1])
    body = s[1:].replace(":", "")
    if sign is None or not body.isdigit() or len(body) not in (1, 2, 3, 4):
        raise ThermocalInputError.naming(
            f"{{chamber_tz}} {text!r}: give the log's offset from UTC, +HH:MM or -HH:MM",
            "chamber_tz",
        )
    hours, minutes = (int(body), 0) if len(body) <= 2 else (int(body[:-2]), int(body[-2:]))
    if hours > 14 or minutes >= 60:
        raise ThermocalInputError.naming(
            f"{{chamber_tz}} {text!r}: no time zone is that far from UTC", "chamber_tz"
        )
    return sign * (hours * 3600.0 + minutes * 60.0)


def timezone_text(seconds: float) -> str:
    """The offset from UTC [s] as ``"UTC+02:00"``.

    Parameters
    ----------
    seconds : float
        Local time minus UTC [s].

    Returns
    -------
    str
        ``UTC±HH:MM``.
    """
    sign = "-" if seconds < 0 else "+"
    m = round(abs(seconds) / 60.0)
    return f"UTC{sign}{m // 60:02d}:{m % 60:02d}"


def _interp_slope(tau: FloatArray, lt: FloatArray, lv: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The log's linear interpolation at ``tau`` and its slope [°C/s] there."""
    values = np.interp(tau, lt, lv)
    slopes = np.diff(lv) / np.diff(lt)
    k = np.clip(np.searchsorted(lt, tau, side="right") - 1, 0, slopes.size - 1)
    return values, slopes[k]


def _thinned(t: FloatArray, y: FloatArray, n_max: int) -> tuple[FloatArray, FloatArray]:
    """At most ``n_max`` evenly spaced samples of ``(t, y)``."""
    if t.size <= n_max:
        return t, y
    idx = np.linspace(0, t.size - 1, n_max).round().astype(np.intp)
    return t[idx], y[idx]


def _grid_offset(
    u: FloatArray, y: FloatArray, lt: FloatArray, lv: FloatArray
) -> tuple[float, float]:
    """The offset [s] of greatest correlation over every placement of the recording inside
    the log (a grid of at most :data:`MAX_GRID` offsets, a quarter log period apart or
    wider), and that correlation."""
    span_log, span_rec = float(lt[-1] - lt[0]), float(u[-1])
    room = span_log - span_rec
    period = float(np.median(np.diff(lt)))
    step = max(period / 4.0, room / MAX_GRID)
    offsets = lt[0] + np.arange(0.0, room + step / 2, step) if room > 0 else np.array([lt[0]])
    uy, yy = _thinned(u, y, 2000)
    yc = yy - yy.mean()
    best_o, best_r = float(offsets[0]), -math.inf
    for o in offsets:
        x = np.interp(o + uy, lt, lv)
        xc = x - x.mean()
        den = math.sqrt(float(xc @ xc) * float(yc @ yc))
        r = float(xc @ yc) / den if den > 0 else -math.inf
        if r > best_r:
            best_o, best_r = float(o), r
    return best_o, best_r


def _gauss_newton(
    u: FloatArray, y: FloatArray, lt: FloatArray, lv: FloatArray, offset0: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Least squares of :math:`y = a + b L(o + (1 + \\delta) u)` from ``offset0``: the
    parameters ``(a, b, o, δ)``, their covariance (inflated for the residuals'
    autocorrelation) and the residuals."""
    x0 = np.interp(offset0 + u, lt, lv)
    b0, a0 = np.polyfit(x0, y, 1)
    p = np.array([a0, b0, offset0, 0.0])
    jac = np.empty((u.size, 4))
    for _ in range(MAX_ITERATIONS):
        tau = p[2] + (1.0 + p[3]) * u
        val, slope = _interp_slope(tau, lt, lv)
        res = y - (p[0] + p[1] * val)
        jac[:, 0], jac[:, 1] = 1.0, val
        jac[:, 2] = p[1] * slope
        jac[:, 3] = p[1] * slope * u
        step, *_ = np.linalg.lstsq(jac, res, rcond=None)
        p = p + step
        if abs(step[2]) < 1e-6 and abs(step[3]) < 1e-12:
            break
    tau = p[2] + (1.0 + p[3]) * u
    val, slope = _interp_slope(tau, lt, lv)
    res = y - (p[0] + p[1] * val)
    jac[:, 0], jac[:, 1], jac[:, 2], jac[:, 3] = 1.0, val, p[1] * slope, p[1] * slope * u
    s2 = float(res @ res) / max(u.size - 4, 1)
    rho = float(np.clip(np.corrcoef(res[:-1], res[1:])[0, 1], 0.0, 0.99)) if res.size > 3 else 0.0
    if not math.isfinite(rho):
        rho = 0.0
    cov = np.asarray(s2 * (1.0 + rho) / (1.0 - rho) * np.linalg.pinv(jac.T @ jac), dtype=np.float64)
    return np.asarray(p, dtype=np.float64), cov, np.asarray(res, dtype=np.float64)


def log_resolution(values: npt.ArrayLike) -> float:
    """The step of a log's readings: the smallest difference between two distinct values
    (a log written to 0.1 °F reads in steps of 0.0556 °C).

    Parameters
    ----------
    values : array_like
        The log's temperatures [°C].

    Returns
    -------
    float
        The step [°C]; 0 with fewer than two distinct values.
    """
    v = np.unique(np.asarray(values, dtype=np.float64))
    d = np.diff(v)
    d = d[d > 1e-9 * max(1.0, float(np.max(np.abs(v))) if v.size else 1.0)]
    return float(d.min()) if d.size else 0.0


def _log_resolution_cov(u: FloatArray, lt: FloatArray, lv: FloatArray, p: FloatArray) -> FloatArray:
    """The parameters' covariance from the log's own rounding: each log reading off by a
    uniform error of variance :math:`q^2/12` (Widrow & Kollár 2008, ch. 4), spread over the
    recording's samples by the interpolation weights :math:`W`:
    :math:`b^2 \\frac{q^2}{12} M^{-1} (W^\\top J)^\\top (W^\\top J) M^{-1}`,
    :math:`M = J^\\top J` (the sandwich form of a regressor's error)."""
    q = log_resolution(lv)
    tau = p[2] + (1.0 + p[3]) * u
    val, slope = _interp_slope(tau, lt, lv)
    jac = np.column_stack([np.ones_like(u), val, p[1] * slope, p[1] * slope * u])
    k = np.clip(np.searchsorted(lt, tau, side="right") - 1, 0, lt.size - 2)
    w = np.clip((tau - lt[k]) / (lt[k + 1] - lt[k]), 0.0, 1.0)
    spread = np.zeros((lt.size, 4))
    np.add.at(spread, k, (1.0 - w)[:, None] * jac)
    np.add.at(spread, k + 1, w[:, None] * jac)
    curve = np.zeros(lt.size)  # a corner between two readings: cut by up to |Δ²L|/8
    curve[1:-1] = np.diff(lv, 2) / 8.0
    var = q**2 / 12.0 + curve**2
    m_inv = np.linalg.pinv(jac.T @ jac)
    out = p[1] ** 2 * (m_inv @ (spread.T @ (var[:, None] * spread)) @ m_inv)
    return np.asarray(out, dtype=np.float64)


def _correlated(
    t: FloatArray, y: FloatArray, lt: FloatArray, lv: FloatArray
) -> tuple[float, float, float, float, float]:
    """``(offset, σ, drift_ppm, σ, r)`` from the recording's temperature ``y``."""
    u = t - t[0]
    if float(np.ptp(y)) == 0.0 or float(np.ptp(lv)) == 0.0:
        raise ThermocalInputError.naming(
            "the recording's or the log's temperature does not change: the clocks cannot be "
            "joined from it; give {chamber_offset}",
            "chamber_offset",
        )
    o0, r0 = _grid_offset(u, y, lt, lv)
    if r0 < MIN_CORRELATION:
        raise ThermocalInputError.naming(
            f"the log's temperature does not follow the recording's at any offset (best r = "
            f"{r0:.2f} < {MIN_CORRELATION}): it may not overlap the recording; give "
            "{chamber_offset}",
            "chamber_offset",
        )
    uf, yf = _thinned(u, y, MAX_FIT_POINTS)
    p, cov, _res = _gauss_newton(uf, yf, lt, lv, o0)
    cov = cov + _log_resolution_cov(uf, lt, lv, p)
    x = np.interp(p[2] + (1.0 + p[3]) * uf, lt, lv)
    r = float(np.corrcoef(x, yf)[0, 1])
    return (
        float(p[2]),
        math.sqrt(max(float(cov[2, 2]), 0.0)),
        float(p[3]) * 1e6,
        math.sqrt(max(float(cov[3, 3]), 0.0)) * 1e6,
        r,
    )


def join_clock(
    rec_time_s: npt.ArrayLike,
    log_time_s: npt.ArrayLike,
    log_temp_c: npt.ArrayLike,
    *,
    rec_temp_c: npt.ArrayLike | None = None,
    offset_s: float | None = None,
    drift_ppm: float | None = None,
    absolute_offset_s: float | None = None,
    timezone: str | None = None,
) -> ClockJoin:
    """The mapping of a recording's time onto a log's clock, checked to overlap.

    :math:`\\tau(t) = o + (1 + \\delta)(t - t_0)` with the offset :math:`o` given, from
    absolute times, or found by correlation with the recording's own temperature (then
    :math:`o` and :math:`\\delta` by Gauss-Newton least squares, their standard uncertainties
    :math:`s^2 (J^\\top J)^{-1}` inflated by :math:`(1 + \\rho)/(1 - \\rho)`: Seber & Wild 1989,
    §2.1; Bretherton et al. 1999).

    Parameters
    ----------
    rec_time_s : array_like
        The recording's times [s], increasing.
    log_time_s : array_like
        The log's clock [s] from its first row (0 first), increasing.
    log_temp_c : array_like
        The log's temperature [°C] (the channel joined).
    rec_temp_c : array_like, optional
        The recording's own temperature [°C] (correlation only).
    offset_s : float, optional
        Given offset [s]: where the recording's first sample falls on the log's clock.
    drift_ppm : float, optional
        Given drift [ppm] (default 0 with a given or absolute offset; estimated with the
        correlation).
    absolute_offset_s : float, optional
        The offset [s] from absolute clocks (the recording's first time in UTC plus the
        log's zone, minus the log's first row).
    timezone : str, optional
        The log's zone, stated with ``absolute_offset_s``.

    Returns
    -------
    ClockJoin

    Raises
    ------
    ThermocalInputError
        The log does not cover the recording (no overlap, or only part); a correlation
        without the recording's temperature, on flat temperatures or too weak.

    References
    ----------
    Seber, G. A. F. & Wild, C. J. (1989). *Nonlinear Regression*, Wiley, §2.1.
    Bretherton, C. S. et al. (1999). The effective number of spatial degrees of freedom of
    a time-varying field. *J. Climate* 12, 1990–2009.

    Examples
    --------
    >>> import numpy as np
    >>> j = join_clock(np.arange(0.0, 600.0), np.arange(0.0, 1200.0, 60.0),
    ...                np.linspace(20, 40, 20), offset_s=300.0)
    >>> j.method, j.offset_s, j.covered_s
    ('given', 300.0, (300.0, 899.0))
    """
    t = np.asarray(rec_time_s, dtype=np.float64)
    lt = np.asarray(log_time_s, dtype=np.float64)
    lv = np.asarray(log_temp_c, dtype=np.float64)
    if t.size < 2 or lt.size < 2:
        raise ThermocalInputError("a clock join needs two samples of each record at least")
    method, tz = "given", None
    o_sig: float | None = None
    d_sig: float | None = None
    r: float | None = None
    if offset_s is not None:
        o = float(offset_s)
    elif absolute_offset_s is not None:
        method, o, tz = "absolute", float(absolute_offset_s), timezone
    else:
        if rec_temp_c is None:
            raise ThermocalInputError.naming(
                "the clocks are joined by correlating the recording's own temperature with "
                "the log's, and the recording has none: name it in {temperatures}, or give "
                "{chamber_offset}",
                "temperatures",
                "chamber_offset",
            )
        _check_length(t, lt)
        y = np.asarray(rec_temp_c, dtype=np.float64)
        o, o_sig, d, d_sig, r = _correlated(t, y, lt, lv)
        method, drift_ppm = "correlation", d
    d_ppm = 0.0 if drift_ppm is None else float(drift_ppm)
    covered = _check_cover(t, lt, o, d_ppm)
    return ClockJoin(method, o, o_sig, d_ppm, d_sig, tz, r, (float(lt[0]), float(lt[-1])), covered)


def _check_length(t: FloatArray, lt: FloatArray) -> None:
    """A log shorter than the recording (one log period of slack) cannot cover it."""
    slack = float(np.median(np.diff(lt)))
    if float(lt[-1] - lt[0]) + slack < float(t[-1] - t[0]):
        raise ThermocalInputError(
            f"the chamber log spans {lt[-1] - lt[0]:.6g} s, the recording {t[-1] - t[0]:.6g} s: "
            "the log cannot cover the recording"
        )


def _check_cover(t: FloatArray, lt: FloatArray, o: float, d_ppm: float) -> tuple[float, float]:
    """The log clock's span of the recording once mapped; refused unless the log covers it
    (one log period of slack at each end)."""
    a = o
    b = o + (1.0 + d_ppm * 1e-6) * float(t[-1] - t[0])
    slack = float(np.median(np.diff(lt)))
    lo, hi = float(lt[0]) - slack, float(lt[-1]) + slack
    if b < lo or a > hi:
        raise ThermocalInputError.naming(
            f"the chamber log does not overlap the recording: its clock spans "
            f"{lt[0]:.6g}…{lt[-1]:.6g} s, the recording falls at {a:.6g}…{b:.6g} s on it; "
            "check {chamber_offset} or {chamber_tz}, or the file",
            "chamber_offset",
            "chamber_tz",
        )
    if a < lo or b > hi:
        share = (min(b, hi) - max(a, lo)) / (b - a) if b > a else 0.0
        raise ThermocalInputError.naming(
            f"the chamber log covers only {100.0 * share:.1f} % of the recording (its clock "
            f"spans {lt[0]:.6g}…{lt[-1]:.6g} s, the recording falls at {a:.6g}…{b:.6g} s on "
            "it): cut the recording to the log, or check {chamber_offset}",
            "chamber_offset",
        )
    return (a, b)


def joined_values(
    join: ClockJoin, rec_time_s: npt.ArrayLike, log_time_s: npt.ArrayLike, log_temp_c: npt.ArrayLike
) -> FloatArray:
    """The log's temperature at the recording's samples: :math:`L(\\tau(t))`, linear
    interpolation (the ends held within the one period of slack).

    Parameters
    ----------
    join : ClockJoin
        The clocks' mapping.
    rec_time_s : array_like
        The recording's times [s].
    log_time_s, log_temp_c : array_like
        The log's clock [s] and temperature [°C].

    Returns
    -------
    numpy.ndarray
        Temperature [°C] at each recording sample.
    """
    t = np.asarray(rec_time_s, dtype=np.float64)
    tau = join.clock(t, float(t[0]))
    return np.interp(
        tau, np.asarray(log_time_s, dtype=np.float64), np.asarray(log_temp_c, dtype=np.float64)
    )


__all__ = [
    "MIN_CORRELATION",
    "ClockJoin",
    "join_clock",
    "joined_values",
    "timezone_seconds",
    "timezone_text",
]
