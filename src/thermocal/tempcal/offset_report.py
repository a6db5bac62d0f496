"""What the report of a barometer or magnetometer calibration shows.

PX4's ``TC_B<n>``/``TC_M<n>`` are polynomials of the offset in ``T − TREF`` [Pa, gauss]
(:func:`thermocal.tempcal.px4.fit_offset_sensor`).  :func:`offset_report_request` computes,
from the log's samples and the fit, the numbers the report draws (the presentation layer
only draws them: :func:`thermocal.report.tempcal.write_offset_report`):

* the residual before and after the firmware's correction against the temperature (before:
  the samples relative to their median, as fitted; after: minus ``Σ X_k·(clamp(T, TMIN,
  TMAX) − TREF)^k``, PX4's ``temperature_compensation``), per sample and per bin median;
* the held-out check: the polynomial fitted to the even temperature bins, its residual on
  the odd bins (whose rms is the fit's ``holdout_rms``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from thermocal.firmware.binning import even_odd_split, temperature_bins
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from thermocal.tempcal.compare import CoefficientComparison
    from thermocal.tempcal.px4 import OffsetFit


@dataclass(frozen=True)
class OffsetReportRequest:
    """One barometer's or magnetometer's report: the fit, the samples' temperature [°C] and
    residuals before/after (n, axes) [``fit.unit``], the bins' median temperature [°C] and
    residuals before/after, the odd bins' temperature and residual to the even bins' fit.

    Attributes
    ----------
    fit : OffsetFit
        The fit.
    log_path, title, generated_by : str
        The log, the report's title and its maker.
    axes : tuple of str
        The axes.
    temp_c, before, after : numpy.ndarray
        The samples' temperature [°C] and residuals (n, axes) [``fit.unit``].
    bin_temp_c, bin_before, bin_after : numpy.ndarray
        The same per temperature bin.
    odd_temp_c, odd_residual : numpy.ndarray
        The odd bins' temperature [°C] and hold-out residual.
    previous : CoefficientComparison or None
        The log's ``TC_*`` for this device against the new ones.
    """

    fit: OffsetFit
    log_path: str
    title: str
    generated_by: str
    axes: tuple[str, ...]
    temp_c: FloatArray
    before: FloatArray
    after: FloatArray
    bin_temp_c: FloatArray
    bin_before: FloatArray
    bin_after: FloatArray
    odd_temp_c: FloatArray
    odd_residual: FloatArray
    previous: CoefficientComparison | None = None
    """The log's ``TC_*`` for this device against the new ones."""


def firmware_offset(fit: OffsetFit, temp_c: FloatArray) -> FloatArray:
    r"""PX4's offset of ``fit`` at ``temp_c`` (TMIN/TMAX: the fit's sweep).

    Parameters
    ----------
    fit : thermocal.tempcal.px4.OffsetFit
        A barometer's or magnetometer's fit.
    temp_c : numpy.ndarray
        Temperatures (n,) [°C].

    Returns
    -------
    numpy.ndarray
        Shape (n, axes) [``fit.unit``].

    Notes
    -----
    .. math:: o_i(T) = \sum_{k} X_{k,i} \left(\operatorname{clamp}(T, T_{min}, T_{max})
       - T_{ref}\right)^k

    References
    ----------
    - PX4 ``src/modules/sensors/temperature_compensation/TemperatureCompensation.cpp``.
    """
    x = np.clip(np.asarray(temp_c, dtype=np.float64), *fit.sweep_c) - fit.tref_c
    cols = [np.polynomial.polynomial.polyval(x, np.asarray(c)) for c in fit.coefficients]
    out: FloatArray = np.column_stack(cols)
    return out


def offset_report_request(
    fit: OffsetFit,
    temp_c: FloatArray,
    values: FloatArray,
    log_path: str,
    generated_by: str,
    previous: CoefficientComparison | None = None,
) -> OffsetReportRequest:
    """The numbers of one barometer's or magnetometer's report (module docstring).

    Parameters
    ----------
    fit : thermocal.tempcal.px4.OffsetFit
        The sensor's fit.
    temp_c : numpy.ndarray
        Temperatures (n,) [°C].
    values : numpy.ndarray
        The sensor's values (n, axes) as logged [``fit.unit``].
    log_path : str
        The log, named in the report.
    generated_by : str
        The command line that made the report.
    previous : CoefficientComparison, optional
        The log's ``TC_*`` for this device against the new ones (default none).

    Returns
    -------
    OffsetReportRequest
        What the report is built from.
    """
    temp = np.asarray(temp_c, dtype=np.float64)
    vals = np.asarray(values, dtype=np.float64).reshape(temp.size, -1)
    before = vals - np.median(vals, axis=0)
    after = before - firmware_offset(fit, temp)
    _c, t_med, b_med = temperature_bins(temp, before)
    _c, _t, a_med = temperature_bins(temp, after)
    even, odd = even_odd_split(t_med.size)
    x = t_med - fit.tref_c
    resid = np.column_stack([
        b_med[odd, j] - np.polynomial.polynomial.polyval(
            x[odd], np.polynomial.polynomial.polyfit(x[even], b_med[even, j], fit.order)
        )
        for j in range(vals.shape[1])
    ])  # fmt: skip
    axes = tuple(fit.holdout_rms)
    where = f"{fit.topic}.{fit.instance}"
    return OffsetReportRequest(
        fit, log_path, f"PX4 thermal calibration — {where} ({fit.kind})", generated_by, axes,
        temp, before, after, t_med, b_med, a_med, t_med[odd], resid, previous,
    )  # fmt: skip


__all__ = ["OffsetReportRequest", "firmware_offset", "offset_report_request"]
