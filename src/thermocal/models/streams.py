"""Helpers of the one-temperature models' streaming twins: the model's temperature from one
sample (:func:`stream_channel`) and the clamp to the fitted range that warns once per
stream (:class:`ClampOnce`).  The streaming contract itself is
:class:`thermocal.models.base.ModelStream`.
"""

from __future__ import annotations

import warnings

import numpy as np

from thermocal.errors import ExtrapolationWarning
from thermocal.recording import FloatArray


def stream_channel(temps_c: FloatArray | float, column: int) -> float:
    """The model's temperature [°C] from one sample's ``temps_c``.

    Parameters
    ----------
    temps_c : numpy.ndarray or float
        One sample's temperatures [°C]: a single value, or one per fitted column.
    column : int
        Index of the model's column among the fitted columns.

    Returns
    -------
    float
        The only value, or the value at ``column`` when every fitted column is given [°C].

    Examples
    --------
    >>> import numpy as np
    >>> stream_channel(25.0, 1), stream_channel(np.array([20.0, 30.0]), 1)
    (25.0, 30.0)
    """
    if type(temps_c) is np.ndarray and temps_c.dtype == np.float64 and temps_c.ndim == 1:
        arr = temps_c
    else:
        arr = np.atleast_1d(np.asarray(temps_c, dtype=np.float64)).reshape(-1)
    return float(arr.item(0) if arr.size == 1 else arr.item(column))


class ClampOnce:
    """Clamp one temperature to the fitted range ``[lo, hi]`` [°C] sample by sample, with
    one :class:`ExtrapolationWarning` per stream (``extrapolate=True``: warn, keep T).

    Parameters
    ----------
    lo, hi : float
        The fitted temperature range [°C] (or [counts] for a model in counts).
    extrapolate : bool
        True: keep a temperature outside the range (and warn once); False: clamp it.

    Notes
    -----
    .. math:: T_\\mathrm{used} = \\min(\\max(T, T_\\mathrm{lo}), T_\\mathrm{hi})

    the clamping PX4 (``TemperatureCompensation.cpp``) and ArduPilot
    (``AP_InertialSensor_tempcal.cpp``) apply outside the calibrated range.
    """

    __slots__ = ("extrapolate", "hi", "lo", "warned")

    def __init__(self, lo: float, hi: float, *, extrapolate: bool) -> None:
        self.lo = float(lo)
        self.hi = float(hi)
        self.extrapolate = extrapolate
        self.warned = False

    def __call__(self, x: float) -> float:
        if x < self.lo or x > self.hi:
            if not self.warned:
                self.warned = True
                action = "extrapolating" if self.extrapolate else "clamped to the fitted range"
                warnings.warn(
                    f"temperature {x:.2f} °C outside the model's fitted range "
                    f"{self.lo:.2f}…{self.hi:.2f}; {action}",
                    ExtrapolationWarning,
                    stacklevel=3,
                )
            if not self.extrapolate:
                x = min(max(x, self.lo), self.hi)
        return x
