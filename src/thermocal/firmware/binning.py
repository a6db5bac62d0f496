"""The temperature binning of ``px4-tempcal`` and ``ardupilot-tempcal``: the samples of a
sweep reduced to the median of each :data:`BIN_WIDTH_C` temperature bin, so that every part
of the range weighs the same whatever the sweep's speed there (PX4's
``Tools/process_sensor_caldata.py`` bins the temperature for the same reason) and a spike
does not move a bin (the median, not the mean)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from thermocal.recording import FloatArray

BIN_WIDTH_C = 0.5
"""Width of the temperature bins whose medians are fitted [°C]."""
MIN_BINS = 8
"""Fewest occupied bins a cubic is fitted to (and judged on)."""


def temperature_bins(
    temp_c: FloatArray, values: FloatArray, width_c: float = BIN_WIDTH_C
) -> tuple[FloatArray, FloatArray, FloatArray]:
    r"""The medians of the occupied temperature bins of width ``width_c``.

    Parameters
    ----------
    temp_c : numpy.ndarray
        Temperatures (n,) [°C].
    values : numpy.ndarray
        Values (n,) or (n, m), any unit.
    width_c : float, optional
        Bin width [°C]; default :data:`BIN_WIDTH_C` (0.5).

    Returns
    -------
    tuple of numpy.ndarray
        (bin centres [°C], median temperature of each bin [°C], median of each column of
        ``values`` per bin [unit of ``values``]), occupied bins only, ascending.

    Notes
    -----
    Bin :math:`k` holds the samples with

    .. math:: T_{lo} + k w \le T < T_{lo} + (k + 1) w, \qquad
       T_{lo} = \lfloor \min T / w \rfloor\, w

    and its centre is :math:`T_{lo} + (k + \tfrac12) w`.

    References
    ----------
    - PX4 ``Tools/process_sensor_caldata.py`` (temperature binning before the fit).

    Examples
    --------
    >>> import numpy as np
    >>> c, t, v = temperature_bins(np.array([20.1, 20.2, 20.4, 21.3]),
    ...                            np.array([1.0, 9.0, 2.0, 5.0]))
    >>> c.tolist(), t.round(2).tolist(), v.tolist()
    ([20.25, 21.25], [20.2, 21.3], [2.0, 5.0])
    """
    lo = math.floor(float(np.min(temp_c)) / width_c) * width_c
    idx = np.floor((temp_c - lo) / width_c).astype(np.int64)
    order = np.argsort(idx, kind="stable")
    idx_s = idx[order]
    starts = np.flatnonzero(np.r_[True, np.diff(idx_s) != 0])
    stops = np.r_[starts[1:], idx_s.size]
    centres = lo + (idx_s[starts] + 0.5) * width_c
    t_med = np.array([np.median(temp_c[order[a:b]]) for a, b in zip(starts, stops, strict=True)])
    v_med = np.array(
        [np.median(values[order[a:b]], axis=0) for a, b in zip(starts, stops, strict=True)]
    )
    f64 = np.float64
    return centres.astype(f64), t_med.astype(f64), v_med.astype(f64)


def even_odd_split(n_bins: int) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """The indices of the even and of the odd bins, for the hold-out check.

    Parameters
    ----------
    n_bins : int
        Number of bins.

    Returns
    -------
    tuple of numpy.ndarray
        (indices 0, 2, 4, …; indices 1, 3, 5, …): fitted to the even bins, judged on the odd.

    Examples
    --------
    >>> [a.tolist() for a in even_odd_split(5)]
    [[0, 2, 4], [1, 3]]
    """
    return np.arange(0, n_bins, 2, dtype=np.int64), np.arange(1, n_bins, 2, dtype=np.int64)
