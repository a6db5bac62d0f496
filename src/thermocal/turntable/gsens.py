r"""The gyro's sensitivity to specific force (g-sensitivity) on the dual-axis turntable.

At each dwell k the table holds the triad still at encoder angles (α_k, β_k): its true rate
is the earth rate in body axes :math:`\omega_k = C_n^b \omega_{ie}^n` and its specific
force :math:`f_k = C_n^b (0, 0, g)/g_0` [g] (a levelled, north-aligned base, the
constraints of :mod:`.calibration`; :func:`.kinematics.mat_nb`).  With the triad's error
matrix E from the rotations, the dwell's mean rate less :math:`(I + E)\,\omega_k` is

.. math::

    r_k = \bar g_k - (I + E)\,\omega_k = b + A f_k + e_k,
    \qquad \operatorname{var}(e_{ki}) = N_i^2 / T_k                              (1)

with ``A`` the 3×3 g-sensitivity (IEEE Std 1431-2004 and IEEE Std 952-1997 annex B: the
acceleration-sensitive drift of the rate model, row the gyro axis, column the specific
force's axis), ``N_i`` the angle random walk and ``T_k`` the time held.  Each gyro axis is
one weighted least-squares problem in ``(b_i, A_i)``
(:func:`thermocal.multipos.gsens.fit_g_sensitivity_known_rate`); the sixteen positions turn
each body axis up and down and separate all nine elements.  A schedule whose gravity
directions do not span the three axes (the outer axis held at 0° and 180° only: gravity
never along the inner axis) leaves a column of ``A`` unseen: it is not estimated, and the
reason says which direction is missing.

The moves between dwells turn gravity in the body: the gyro reads :math:`A f(t)` on top of
the rotation, which the filter of :mod:`.calibration` would otherwise take for scale factor
and misalignment.  When an element of ``A`` is significant, :func:`subtract_from_model`
takes :math:`p_c \cdot A f(t)\,\tau` off every interval's channels (``f`` at the interval's
mid angles) and the calibration is estimated again, unless ``A`` is ``c I`` alone
(:func:`thermocal.multipos.gsens.isotropic_part`, shared with ``multipos``: what a latitude
of the wrong sign gives).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.turntable import kinematics, model
from thermocal.turntable.accel import dwell_means, gravity_in_body

if TYPE_CHECKING:
    from thermocal.multipos.gsens import GSensitivity

FloatArray = npt.NDArray[np.float64]

REMEDY = (
    "hold positions that turn each body axis up and down (the sixteen positions of the "
    "schedule: the outer axis at 0°, 90°, 180° and 270°)"
)
"""What gets a turntable run's g-sensitivity separable."""


def specific_force_g(
    alpha_deg: npt.ArrayLike, beta_deg: npt.ArrayLike, gravity_m_s2: float
) -> FloatArray:
    r"""The specific force of the triad at rest on the table, body axes [g].

    Parameters
    ----------
    alpha_deg, beta_deg : array_like
        Inner- and outer-axis encoder angles [°].
    gravity_m_s2 : float
        Local gravity [m/s²].

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        :math:`f = C_n^b (0, 0, g) / g_0` [g], :math:`g_0` = 9.80665 m/s².

    Notes
    -----
    .. math:: f = C_n^b\,(0, 0, g)^\mathsf{T} / g_0

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (1).

    Examples
    --------
    >>> (specific_force_g(0.0, 90.0, 9.80665).round(6) + 0.0).tolist()  # inner axis (z) up
    [0.0, 0.0, 1.0]
    >>> (specific_force_g(90.0, 0.0, 9.80665).round(6) + 0.0).tolist()  # body x down
    [-1.0, 0.0, 0.0]
    """
    out: FloatArray = (
        gravity_in_body(alpha_deg, beta_deg, gravity_m_s2) / units.STANDARD_GRAVITY_M_S2
    )
    return out


def dwell_g_sensitivity(
    gyro_rad_s: FloatArray,
    dt_s: FloatArray,
    alpha_deg: FloatArray,
    beta_deg: FloatArray,
    dwells: Sequence[Any],
    theta: FloatArray,
    arw_rad_sqrt_s: FloatArray,
    latitude_deg: float,
    gravity_m_s2: float,
) -> GSensitivity:
    r"""``A`` and its σ from the dwells of a turntable run, eq. (1) of the module docstring.

    Parameters
    ----------
    gyro_rad_s : numpy.ndarray, shape (n, 3)
        Gyro mean rates over the interval ending at each sample [rad/s].
    dt_s : numpy.ndarray, shape (n - 1,)
        The sample intervals [s] (the dwells index them).
    alpha_deg, beta_deg : numpy.ndarray, shape (n,)
        Encoder angles at the samples [°].
    dwells : sequence of Dwell
        The dwells (:class:`.schedule.Dwell`).
    theta : numpy.ndarray, shape (12,)
        The triad's coefficients (:mod:`.model`): E is taken from them.
    arw_rad_sqrt_s : numpy.ndarray, shape (3,)
        Angle random walk of each gyro [rad/√s].
    latitude_deg : float
        Latitude [°] (the earth rate).
    gravity_m_s2 : float
        Local gravity [m/s²].

    Returns
    -------
    thermocal.multipos.gsens.GSensitivity
        ``A`` [°/h/g], its σ, the bias at zero specific force [°/h].

    Raises
    ------
    thermocal.errors.DesignError
        Fewer than four dwells, or dwells whose gravity directions do not span the axes.

    Notes
    -----
    .. math:: r_k = \bar g_k - (I + E)\, C_n^b \omega_{ie}^n = b + A f_k + e_k, \qquad
              \operatorname{var}(e_{ki}) = N_i^2 / T_k

    References
    ----------
    - IEEE Std 1431-2004, *IEEE Standard Specification Format Guide and Test Procedure for
      Coriolis Vibratory Gyros* (acceleration-sensitive drift).
    - IEEE Std 952-1997, annex B (acceleration-sensitive drift).
    """
    from thermocal.multipos.gsens import fit_g_sensitivity_known_rate

    w_mean, _n = dwell_means(gyro_rad_s, dwells)
    ang, _ = dwell_means(np.column_stack([alpha_deg, beta_deg]), dwells)
    earth = kinematics.earth_rate_b(np.radians(ang[:, 0]), np.radians(ang[:, 1]), latitude_deg)
    e_mat = model.error_matrix_from_coeffs(theta)[0]
    resid = w_mean - earth @ (np.eye(3) + e_mat).T
    held_s = np.asarray([float(np.sum(dt_s[d.start : d.stop])) for d in dwells])
    var = np.asarray(arw_rad_sqrt_s, dtype=np.float64)[None, :] ** 2 / held_s[:, None]
    f = specific_force_g(ang[:, 0], ang[:, 1], gravity_m_s2)
    return fit_g_sensitivity_known_rate(resid, var, f, what="dwells", remedy=REMEDY)


def subtract_from_model(
    m: model.IntervalModel,
    matrix_deg_h_g: FloatArray,
    alpha_deg: FloatArray,
    beta_deg: FloatArray,
    gravity_m_s2: float,
) -> model.IntervalModel:
    r"""The interval model with the g-sensitivity's angle taken off every channel.

    Parameters
    ----------
    m : IntervalModel
        The run's measurement model (:func:`.model.interval_model`).
    matrix_deg_h_g : numpy.ndarray, shape (3, 3)
        ``A`` [°/h per g].
    alpha_deg, beta_deg : numpy.ndarray, shape (n,)
        Encoder angles at the samples [°] (the intervals' mid angles give ``f``).
    gravity_m_s2 : float
        Local gravity [m/s²].

    Returns
    -------
    IntervalModel
        ``y`` less :math:`p_c \cdot A f_i \tau_i` [arcsec]; the regressors unchanged.

    Notes
    -----
    .. math:: y'_{c,i} = y_{c,i} - p_{c,i} \cdot A f_i\, \tau_i

    References
    ----------
    - IEEE Std 1431-2004 (the acceleration-sensitive drift of the rate model).
    """
    a_mid = 0.5 * (alpha_deg[1:] + alpha_deg[:-1])
    b_mid = 0.5 * (beta_deg[1:] + beta_deg[:-1])
    drift = specific_force_g(a_mid, b_mid, gravity_m_s2) @ np.asarray(matrix_deg_h_g).T
    angle = drift * (units.DH_TO_RS * units.RAD_TO_ARCSEC) * m.dt_s[:, None]  # [arcsec]
    y = m.y_arcsec - np.einsum("mcj,mj->mc", m.proj, angle)
    return replace(m, y_arcsec=y)


def pooled_g_sensitivity(
    estimates: Sequence[GSensitivity | None],
) -> tuple[FloatArray, FloatArray] | None:
    r"""One ``A`` for several runs (soaks): each element's inverse-variance weighted mean
    over the runs that estimated it, and its σ (widened by the runs' scatter when it is
    beyond their σ: a sensitivity that moves with temperature).

    Parameters
    ----------
    estimates : sequence of GSensitivity or None
        Each run's estimate (None: not estimated, left out).

    Returns
    -------
    tuple of numpy.ndarray or None
        ``A`` and its σ [°/h per g], 3×3; None when no run estimated it.

    Notes
    -----
    .. math:: \hat A_{ij} = \frac{\sum_r w_r A_{ij,r}}{\sum_r w_r}, \quad
              w_r = \sigma_{ij,r}^{-2}, \quad
              \sigma_{ij} = \sqrt{\max(1, \chi^2_\nu) / \textstyle\sum_r w_r}

    with :math:`\chi^2_\nu = \sum_r w_r (A_{ij,r} - \hat A_{ij})^2 / (R - 1)` over the R
    runs.

    References
    ----------
    - S. M. Kay, *Fundamentals of Statistical Signal Processing, Vol. I: Estimation
      Theory*, Prentice Hall, 1993, ch. 6 (the best linear unbiased estimator of a common
      mean: the inverse-variance weighted mean).
    """
    from thermocal.multipos.gsens import combine_g_sensitivity

    used = [e for e in estimates if e is not None]
    if not used:
        return None
    return combine_g_sensitivity(used)


__all__ = [
    "REMEDY",
    "dwell_g_sensitivity",
    "pooled_g_sensitivity",
    "specific_force_g",
    "subtract_from_model",
]
