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
    """(bin centres [°C], median temperature [°C], median of each column of ``values``) of
    the occupied temperature bins of ``width_c`` [°C].  Bin ``k`` holds the samples with
    ``lo + k·w ≤ T < lo + (k + 1)·w``, ``lo = ⌊min T / w⌋·w``; its centre is
    ``lo + (k + ½)·w``."""
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
    """(indices of the even bins, of the odd bins): the hold-out check fits to the even
    bins and judges on the odd ones, which it was not fitted to."""
    return np.arange(0, n_bins, 2, dtype=np.int64), np.arange(1, n_bins, 2, dtype=np.int64)
