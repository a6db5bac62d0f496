"""ArduPilot's barometer temperature calibration ``TCAL_BARO_EXP``.

ArduPilot's ``AP_TempCalibration`` (libraries/AP_TempCalibration/AP_TempCalibration.cpp,
.h) documents four parameters: ``TCAL_ENABLED`` (0 disabled, 1 use, 2 learn and use),
``TCAL_TEMP_MIN``/``TCAL_TEMP_MAX`` (the learned range [°C], int8, informational: the
correction is not clamped to it) and ``TCAL_BARO_EXP``, the exponent ``e`` of a one-parameter
correction of the **first** barometer only::

    p_correction = max(T − Tzero, 0)^e  [Pa],  Tzero = 25 °C,  0 ≤ e ≤ 2

*added* to its pressure (``AP_Baro``: ``pressure + p_correction``; the logged ``BARO.Press``
is ``get_pressure``, without it, so a log needs no undoing).  The firmware learns ``e``
while still, by minimising the spread of the corrected pressure over 0.25 °C bins relative
to the first bin, in steps of 0.01.

thermocal fits the same ``e`` from the log: the pressure reduced to the medians of
:data:`~thermocal.firmware.binning.BIN_WIDTH_C` temperature bins (robust to spikes, equal
weight across the range), ``e`` the value in [0, 2] (resolution :data:`EXP_STEP`) that
minimises the variance of ``P_bin + max(T_bin − 25, 0)^e`` about its mean; judged on
held-out bins (``e`` fitted to the even bins, the rms of the corrected odd bins about the even
bins' corrected mean).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from thermocal.firmware.binning import even_odd_split, temperature_bins
from thermocal.recording import FloatArray

TZERO_C = 25.0
"""``AP_TempCalibration::Tzero``: the temperature at which the correction starts [°C]."""
EXP_LIMITS = (0.0, 2.0)
"""``exp_limit_min``, ``exp_limit_max``: the exponents the firmware accepts."""
EXP_STEP = 1e-4
"""The resolution of thermocal's search for the exponent (the firmware's is 0.01)."""
MIN_BINS_ABOVE = 4
INT8_RANGE = (-128, 127)
"""``TCAL_TEMP_MIN``/``TCAL_TEMP_MAX`` are ``AP_Int8`` (AP_TempCalibration.h)."""
"""Fewest temperature bins above :data:`TZERO_C` an exponent is fitted to."""


def baro_correction(temp_c: FloatArray, exponent: float) -> FloatArray:
    r"""The firmware's barometer correction, added to the pressure.

    Parameters
    ----------
    temp_c : numpy.ndarray
        Barometer temperatures [°C].
    exponent : float
        ``TCAL_BARO_EXP`` (dimensionless).

    Returns
    -------
    numpy.ndarray
        The correction [Pa], same shape as ``temp_c``.

    Notes
    -----
    .. math:: \Delta p(T) = \max(T - 25, 0)^{e}

    References
    ----------
    - ArduPilot ``libraries/AP_TempCalibration/AP_TempCalibration.cpp``
      (``calculate_correction``).

    Examples
    --------
    >>> import numpy as np
    >>> baro_correction(np.array([20.0, 29.0]), 1.5).tolist()
    [0.0, 8.0]
    """
    out: FloatArray = np.maximum(np.asarray(temp_c, dtype=np.float64) - TZERO_C, 0.0) ** exponent
    return out


def best_exponent(temp_c: FloatArray, press_pa: FloatArray) -> tuple[float, float]:
    r"""The exponent that makes the corrected pressure the flattest.

    Parameters
    ----------
    temp_c : numpy.ndarray
        Temperatures [°C] (bin medians or samples).
    press_pa : numpy.ndarray
        Pressures, same length [Pa].

    Returns
    -------
    tuple of float
        (the exponent in :data:`EXP_LIMITS` on a grid of :data:`EXP_STEP`, the mean corrected
        pressure [Pa]).

    Notes
    -----
    .. math:: \hat e = \arg\min_{e} \operatorname{var}\left(p_i + \max(T_i - 25, 0)^{e}\right)

    References
    ----------
    - ArduPilot ``libraries/AP_TempCalibration/AP_TempCalibration.cpp`` (its learning
      searches the exponent the same way, in steps of 0.01).
    """
    grid = np.arange(EXP_LIMITS[0], EXP_LIMITS[1] + EXP_STEP / 2, EXP_STEP)
    dt = np.maximum(np.asarray(temp_c, dtype=np.float64) - TZERO_C, 0.0)
    corrected = np.asarray(press_pa, dtype=np.float64)[None, :] + dt[None, :] ** grid[:, None]
    k = int(np.argmin(corrected.var(axis=1)))
    return float(grid[k]), float(corrected[k].mean())


@dataclass(frozen=True)
class ArdupilotBaroFit:
    """``TCAL_BARO_EXP`` of barometer ``instance`` (the firmware corrects instance 0 only):
    the sweep [°C], samples and bins, the exponent, the rms of the bin medians about their
    mean before and after the correction [Pa], the hold-out rms [Pa], whether the exponent
    is at a limit of :data:`EXP_LIMITS` (the model does not fit this barometer).

    References
    ----------
    - ArduPilot ``libraries/AP_TempCalibration/AP_TempCalibration.cpp``.

    Attributes
    ----------
    instance : int
        The barometer.
    sweep_c : (float, float)
        Its temperature sweep [°C].
    n_samples, n_bins : int
        Samples and temperature bins.
    exponent : float
        ``TCAL_BARO_EXP``.
    rms_before_pa, rms_after_pa : float
        RMS of the bin medians about their mean before and after the correction [Pa].
    holdout_rms_pa : float
        RMS of the odd bins about the even bins' fit [Pa].
    at_limit : bool
        The exponent lies at a limit of :data:`EXP_LIMITS`.
    """

    instance: int
    sweep_c: tuple[float, float]
    n_samples: int
    n_bins: int
    exponent: float
    rms_before_pa: float
    rms_after_pa: float
    holdout_rms_pa: float
    at_limit: bool

    def params(self) -> dict[str, float]:
        """``TCAL_ENABLED`` = 1 (0 when the exponent is at a limit: the firmware's model does
        not follow this barometer, and its correction would add up to ``max(T − 25, 0)²`` Pa
        — 1225 Pa at 60 °C — or a constant 1 Pa), ``TCAL_TEMP_MIN``/``MAX`` (``AP_Int8`` in
        AP_TempCalibration.h: rounded and clamped to −128…127, :meth:`int8_clamped` says
        when), ``TCAL_BARO_EXP``."""
        lo, hi = (max(INT8_RANGE[0], min(INT8_RANGE[1], round(v))) for v in self.sweep_c)
        return {
            "TCAL_ENABLED": 0 if self.at_limit else 1,
            "TCAL_TEMP_MIN": lo,
            "TCAL_TEMP_MAX": hi,
            "TCAL_BARO_EXP": self.exponent,
        }

    def int8_clamped(self) -> str | None:
        """The sentence of a sweep beyond ``TCAL_TEMP_MIN``/``MAX``'s int8 (None: within)."""
        lo, hi = self.sweep_c
        if INT8_RANGE[0] <= round(lo) and round(hi) <= INT8_RANGE[1]:
            return None
        p = self.params()
        return (
            f"BARO.{self.instance}: the sweep {lo:.1f}…{hi:.1f} °C does not fit TCAL_TEMP_MIN/"
            f"TCAL_TEMP_MAX (int8 in AP_TempCalibration.h, {INT8_RANGE[0]}…{INT8_RANGE[1]}): "
            f"written as {p['TCAL_TEMP_MIN']:g}…{p['TCAL_TEMP_MAX']:g}; the firmware does not "
            "clamp its correction to them (informational), but they do not say the sweep"
        )

    def to_dict(self) -> dict[str, Any]:
        """The ``BARO.<n>`` object of the ``ardupilot-tempcal`` command's JSON."""
        return {**asdict(self), "parameters": self.params(), "unit": "Pa"}


def fit_ardupilot_baro(
    temp_c: FloatArray, press_pa: FloatArray, instance: int = 0
) -> ArdupilotBaroFit | None:
    """The firmware's exponent ``TCAL_BARO_EXP`` fitted to a log's barometer.

    Parameters
    ----------
    temp_c : numpy.ndarray
        Barometer temperatures [°C] (non-finite samples dropped).
    press_pa : numpy.ndarray
        Pressures as logged (uncorrected), same length [Pa].
    instance : int, optional
        Barometer instance (default 0; the firmware corrects instance 0 only).

    Returns
    -------
    ArdupilotBaroFit or None
        The fit, or None when fewer than :data:`MIN_BINS_ABOVE` temperature bins lie above
        25 °C (the correction is zero below).

    References
    ----------
    - ArduPilot ``libraries/AP_TempCalibration/AP_TempCalibration.cpp``.
    """
    temp = np.asarray(temp_c, dtype=np.float64)
    press = np.asarray(press_pa, dtype=np.float64)
    ok = np.isfinite(temp) & np.isfinite(press)
    temp, press = temp[ok], press[ok]
    if temp.size == 0:
        return None
    _c, t_med, p_med = temperature_bins(temp, press.reshape(-1, 1))
    p_med = p_med[:, 0]
    if int(np.sum(t_med > TZERO_C)) < MIN_BINS_ABOVE:
        return None
    exponent, mean = best_exponent(t_med, p_med)
    after = p_med + baro_correction(t_med, exponent)
    even, odd = even_odd_split(t_med.size)
    e_even, mean_even = best_exponent(t_med[even], p_med[even])
    held = p_med[odd] + baro_correction(t_med[odd], e_even) - mean_even
    at_limit = math.isclose(exponent, EXP_LIMITS[0], abs_tol=EXP_STEP) or math.isclose(
        exponent, EXP_LIMITS[1], abs_tol=EXP_STEP
    )
    return ArdupilotBaroFit(
        instance, (float(np.min(temp)), float(np.max(temp))), int(temp.size), int(t_med.size),
        exponent, float(np.std(p_med)), float(np.sqrt(np.mean((after - mean) ** 2))),
        float(np.sqrt(np.mean(held**2))), at_limit,
    )  # fmt: skip


@dataclass(frozen=True)
class ArdupilotBaroReportRequest:
    """The numbers of the report of a ``TCAL_BARO_EXP`` fit (:func:`baro_report_request`):
    the samples' temperature [°C] and pressure residual before/after the firmware's
    correction [Pa] (before: the pressure relative to its median; after: the corrected
    pressure ``P + max(T − 25, 0)^e`` relative to its median), the same per temperature bin
    (the bins' medians, relative to the same medians), the odd bins' temperature
    and residual to the even bins' fit (:func:`fit_ardupilot_baro`'s hold-out), the log's
    own ``TCAL_*`` values (``old``, those present) and the warnings said about this
    barometer.

    Attributes
    ----------
    fit : ArdupilotBaroFit
        The fit.
    log_path, title, generated_by : str
        The log, the report's title and its maker.
    temp_c, before, after : numpy.ndarray
        The samples' temperature [°C] and residuals [Pa].
    bin_temp_c, bin_before, bin_after : numpy.ndarray
        The same per temperature bin.
    odd_temp_c, odd_residual : numpy.ndarray
        The odd bins' temperature [°C] and hold-out residual [Pa].
    holdout_exponent : float
        The even bins' exponent.
    old : dict of str to float
        The log's own ``TCAL_*`` values.
    warnings : tuple of str
        The warnings said about this barometer.
    """

    fit: ArdupilotBaroFit
    log_path: str
    title: str
    generated_by: str
    temp_c: FloatArray
    before: FloatArray
    after: FloatArray
    bin_temp_c: FloatArray
    bin_before: FloatArray
    bin_after: FloatArray
    odd_temp_c: FloatArray
    odd_residual: FloatArray
    holdout_exponent: float
    old: dict[str, float] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()


def baro_report_request(
    fit: ArdupilotBaroFit, temp_c: FloatArray, press_pa: FloatArray, log_path: str,
    generated_by: str, log_params: Mapping[str, float], said: tuple[str, ...] = (),
) -> ArdupilotBaroReportRequest:  # fmt: skip
    """The numbers of the barometer report of ``fit`` on the log's samples.

    Parameters
    ----------
    fit : ArdupilotBaroFit
        The fitted exponent.
    temp_c : numpy.ndarray
        Barometer temperatures [°C].
    press_pa : numpy.ndarray
        Pressures as logged (``BARO.Press`` is uncorrected) [Pa].
    log_path : str
        The log, named in the report.
    generated_by : str
        The command line that made the report.
    log_params : mapping of str to float
        The log's parameters (their ``TCAL_*`` shown beside the new ones).
    said : tuple of str, optional
        Warnings already said, repeated in the report.

    Returns
    -------
    ArdupilotBaroReportRequest
        What the report is built from.
    """
    temp = np.asarray(temp_c, dtype=np.float64)
    press = np.asarray(press_pa, dtype=np.float64)
    ok = np.isfinite(temp) & np.isfinite(press)
    temp, press = temp[ok], press[ok]
    corrected = press + baro_correction(temp, fit.exponent)
    before, after = press - np.median(press), corrected - np.median(corrected)
    _c, t_med, p_med = temperature_bins(temp, press.reshape(-1, 1))
    p_med = p_med[:, 0]
    c_med = p_med + baro_correction(t_med, fit.exponent)
    even, odd = even_odd_split(t_med.size)
    e_even, mean_even = best_exponent(t_med[even], p_med[even])
    held = p_med[odd] + baro_correction(t_med[odd], e_even) - mean_even
    old = {k: float(log_params[k]) for k in fit.params() if k in log_params}
    return ArdupilotBaroReportRequest(
        fit, log_path, f"ArduPilot barometer temperature calibration — BARO.{fit.instance}",
        generated_by, temp, before, after, t_med, p_med - np.median(press),
        c_med - np.median(corrected),
        t_med[odd], held, e_even, old, said,
    )  # fmt: skip


__all__ = [
    "EXP_LIMITS",
    "TZERO_C",
    "ArdupilotBaroFit",
    "ArdupilotBaroReportRequest",
    "baro_correction",
    "baro_report_request",
    "best_exponent",
    "fit_ardupilot_baro",
]
