"""The stations of a dividing-head tumble: stretches where the head's angle holds still,
their first seconds left out (the head's settling), each reduced to its mean angle, mean
output and the standard error of that mean.

A run of consecutive samples belongs to one station while the angle moves by at most the
tolerance from one sample to the next; the standard error of the mean output is the
samples' standard deviation over ``√n`` (white noise, IEEE Std 1293-1998's station means).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError

FloatArray = npt.NDArray[np.float64]

TOLERANCE_DEG: Final = 0.01
"""Largest change of the angle between two samples of one station [°]."""
MIN_STATION_S: Final = 2.0
"""Shortest station kept, after the settling is left out [s]."""
SETTLE_S: Final = 1.0
"""Left out at each station's start [s]."""
STATION_SHARE: Final = 0.5
"""The record is a dividing-head tumble when its stations hold at least this share of the
samples; otherwise a continuous tumble (every sample a point)."""


@dataclass(frozen=True)
class Station:
    """One station of the head.

    Attributes
    ----------
    start_s, end_s : float
        The samples kept [s].
    angle_deg : float
        Mean angle [°].
    mean : float
        Mean output [unit].
    se : float
        Its standard error [unit].
    n : int
        Samples.
    """

    start_s: float
    end_s: float
    angle_deg: float
    mean: float
    se: float
    n: int


def find_stations(
    t: npt.ArrayLike,
    angle_deg: npt.ArrayLike,
    y: npt.ArrayLike,
    *,
    tolerance_deg: float = TOLERANCE_DEG,
    min_station_s: float = MIN_STATION_S,
    settle_s: float = SETTLE_S,
) -> tuple[list[Station], list[tuple[float, float]]]:
    """The stations of a record: runs where the angle holds within ``tolerance_deg`` from
    sample to sample, ``settle_s`` left out at the start, at least ``min_station_s`` left.

    Parameters
    ----------
    t : array_like
        Sample times [s], increasing.
    angle_deg : array_like
        The head's angle [°].
    y : array_like
        The accelerometer's output [unit].
    tolerance_deg, min_station_s, settle_s : float, optional
        The station criteria.

    Returns
    -------
    stations : list of Station
        In time order.
    dropped : list of (float, float)
        Steady stretches too short (start, end) [s].

    Notes
    -----
    Each station's mean output ``ȳ`` and its standard error ``s/√n`` (sample standard
    deviation ``s``, ``n`` samples).

    Examples
    --------
    >>> t = np.arange(100) * 0.1
    >>> ang = np.where(t < 5, 0.0, 90.0)
    >>> st, _ = find_stations(t, ang, np.cos(np.radians(ang)), settle_s=0.5, min_station_s=1)
    >>> [(s.angle_deg, s.n) for s in st]
    [(0.0, 45), (90.0, 45)]
    """
    for name, v in (("tolerance_deg", tolerance_deg), ("min_station_s", min_station_s)):
        if not (math.isfinite(v) and v > 0):
            raise ParameterError(name, f"{{name}} must be a positive number, got {v!r}")
    if not (math.isfinite(settle_s) and settle_s >= 0):
        raise ParameterError("settle_s", f"{{name}} must be zero or more, got {settle_s!r}")
    tt = np.asarray(t, dtype=np.float64)
    a = np.asarray(angle_deg, dtype=np.float64)
    yy = np.asarray(y, dtype=np.float64)
    moving = np.abs(np.diff(a)) > tolerance_deg
    cuts = np.flatnonzero(moving) + 1
    stations, dropped = [], []
    for lo, hi in zip(np.r_[0, cuts], np.r_[cuts, a.size], strict=True):
        if hi - lo < 2:
            continue
        keep = np.arange(lo, hi)[tt[lo:hi] >= tt[lo] + settle_s]
        if keep.size < 3 or tt[keep[-1]] - tt[keep[0]] < min_station_s:
            dropped.append((float(tt[lo]), float(tt[hi - 1])))
            continue
        seg = yy[keep]
        stations.append(
            Station(
                float(tt[keep[0]]),
                float(tt[keep[-1]]),
                float(np.mean(a[keep])),
                float(np.mean(seg)),
                float(np.std(seg, ddof=1) / math.sqrt(seg.size)),
                int(seg.size),
            )
        )
    return stations, dropped
