"""Gyro-triad error model of the turntable calibration and its linear measurement model.

Error model (the dual-axis turntable source document, CN104880182)::

    ω_meas = (I + E) ω_true + b + n,      Δω = ω_meas − ω_true = b + E ω_true + n

with ``b`` the biases δD0 [°/h], ``diag(E)`` the scale-factor errors δK [ppm] and
the off-diagonal of ``E`` the six misalignments δE [arcsec].  The source's names
``δE_ab`` follow its filter rows (CN104880182, claim 4): ``δE_ab`` is the
sensitivity of gyro *b* to a rate about axis *a*, i.e. ``E[b, a]``:

=======  =============  =================================
name     error_matrix   meaning
=======  =============  =================================
``yx``   ``E[0, 1]``    x gyro sensing the y rate
``zx``   ``E[0, 2]``    x gyro sensing the z rate
``xy``   ``E[1, 0]``    y gyro sensing the x rate
``zy``   ``E[1, 2]``    y gyro sensing the z rate
``xz``   ``E[2, 0]``    z gyro sensing the x rate
``yz``   ``E[2, 1]``    z gyro sensing the y rate
=======  =============  =================================

The coefficient vector θ (12) is, in this order and in these units::

    [b_x, b_y, b_z [°/h], k_x, k_y, k_z [ppm], yx, zx, xy, zy, xz, yz [arcsec]]

Measurement model (CN104880182): over a sample interval i of length τ_i the
gyro-integrated gimbal angles minus the encoder angle changes are, eq. (4)::

    y_α,i = e_z · (g_i τ_i − C_n^b ω_ie^n τ_i) − Δα_enc,i       = h_α,i θ + w_α,i
    y_β,i = e_E^b(α) · (g_i τ_i − C_n^b ω_ie^n τ_i) − Δβ_enc,i  = h_β,i θ + w_β,i
    y_γ,i = e_⊥^b(α) · (g_i τ_i − C_n^b ω_ie^n τ_i)             = h_γ,i θ + w_γ,i

with ``g_i`` the gyro mean rate over the interval and, for a projection ``p``
(``e_z`` or ``e_E^b``) and the true angle increment ``φ_i = ω_true τ_i`` (from the
encoders, kinematics eq. (2)), ``h θ = Σ_j p_j (b_j τ + k_j φ_j + Σ_{m≠j} E_jm φ_m)``.
The noise is white: ``cov(w_c, w_d) = Σ_j p_cj p_dj N_j² τ`` (N_j the angle random
walk of gyro j).  Sums of ``y`` and ``h`` over a block of intervals are the block's
angle increments; the filter's Δα, Δβ, Δγ are their running sums.

The third channel (our reading): ``e_⊥^b = e_z × e_E^b = (sin α, cos α, 0)`` is the
body direction perpendicular to both gimbal axes; the mechanism cannot turn about it,
so the gyro-integrated rotation about it, Δγ, has true value zero.  The source's
filter measures Δα, Δβ only; then, because every outer-axis move of the 16-position
sequence happens at α ∈ {0°, 90°, 180°, 270°} (where ``e_E^bᵀ E e_E^b`` has no xy
term), the two xy misalignments are seen only through the earth rate (σ ≈ 100″).
Δγ sees them during every outer-axis move (``e_⊥ᵀ E e_E^b`` = ``yx`` at α = 0,
``−xy`` at α = 90°).  ``channels=3`` (default) uses Δα, Δβ, Δγ; ``channels=2`` is
the source's 14-state form.

Unobservable combinations and the constraints taken
---------------------------------------------------
* A rotation ε of the triad about the inner axis changes E by ``−ε [e_z×]``
  (``yx += ε``, ``xy −= ε``) and is exactly equivalent, in every channel and in the
  earth-rate terms, to a zero offset of the inner-axis encoder.  **Constraint**: the
  inner encoder's zero is taken as exact — it defines the body x azimuth — so a
  rotation of the triad about the inner axis is reported in the misalignments, and
  their antisymmetric part ``(yx − xy)/2`` is also given as
  ``inner_axis_azimuth_arcsec``.
* A zero offset of the outer-axis encoder, or a base not levelled and aligned,
  rotates the earth-rate input only; it is not estimated (**constraint**: zero, as
  the source prescribes a levelled, aligned base).  Its effect is of the order of
  Ω × offset on the static readings.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.turntable import kinematics

SCALE_FACTOR_REFUSED: Final = 0.5
"""A fitted scale factor beyond ±50 % is refused, not written, by the turntable and the
multi-position calibrations alike: the columns are not in the unit they are declared in (a
°/s gyro declared °/h gave −999722 ppm, declared rad/s +5.6e7 ppm; ``accel_unit="mg"`` on
m/s² data −99 %), or a count scale is wrong by more than a factor 1.5."""


def scale_factors_beyond(theta: npt.ArrayLike) -> list[str]:
    """``"x +5630 %"`` for each scale factor of a triad's parameters beyond
    ±:data:`SCALE_FACTOR_REFUSED` (empty: all within).

    Parameters
    ----------
    theta : array_like
        The triad's parameter vector in this module's layout: ``theta[3:6]`` are the x, y,
        z scale factors [ppm].

    Returns
    -------
    list of str
        One ``"axis ±percent %"`` entry per scale factor beyond the limit (empty: none).

    Examples
    --------
    >>> scale_factors_beyond([0, 0, 0, 1e3, 6e5, -2e3] + [0] * 6)
    ['y +60 %']
    """
    sf = np.asarray(theta, dtype=np.float64)[3:6] * units.PPM
    return [f"{ax} {100 * v:+.4g} %" for ax, v in zip("xyz", sf, strict=True)
            if not abs(v) <= SCALE_FACTOR_REFUSED]  # fmt: skip


FloatArray = npt.NDArray[np.float64]

COEFF_NAMES: Final = (
    "bias_x",
    "bias_y",
    "bias_z",
    "sf_x",
    "sf_y",
    "sf_z",
    "yx",
    "zx",
    "xy",
    "zy",
    "xz",
    "yz",
)
"""Names of θ, in order."""


def coefficient_rows(
    theta: npt.ArrayLike, sigma: npt.ArrayLike, bias_unit: str, triad: str
) -> list[dict[str, Any]]:
    """The twelve coefficients of a triad as table rows.

    Parameters
    ----------
    theta, sigma : array_like, shape (12,)
        The coefficients in :data:`COEFF_NAMES` order and their standard deviations: bias
        [``bias_unit``], scale-factor errors [ppm], misalignments [″].
    bias_unit : str
        The unit of the three biases (``"mg"``, ``"deg/h"``).
    triad : str
        The triad's name, repeated in each row (``"accel"``, ``"gyro"``).

    Returns
    -------
    list of dict
        One row per coefficient: ``triad``, ``parameter`` (:data:`COEFF_NAMES`), ``value``,
        ``sigma`` and ``unit``; ``pandas.DataFrame(rows)`` makes it a table.

    Examples
    --------
    >>> rows = coefficient_rows(np.arange(12.0), np.ones(12), "mg", "accel")
    >>> rows[4]
    {'triad': 'accel', 'parameter': 'sf_y', 'value': 4.0, 'sigma': 1.0, 'unit': 'ppm'}
    """
    th = np.asarray(theta, dtype=np.float64).reshape(N_COEFFS)
    sg = np.asarray(sigma, dtype=np.float64).reshape(N_COEFFS)
    unit = (bias_unit,) * 3 + ("ppm",) * 3 + ("arcsec",) * 6
    return [
        {"triad": triad, "parameter": n, "value": float(v), "sigma": float(e), "unit": u}
        for n, v, e, u in zip(COEFF_NAMES, th, sg, unit, strict=True)
    ]


MISALIGNMENT_NAMES: Final = ("yx", "zx", "xy", "zy", "xz", "yz")
MISALIGNMENT_INDEX: Final[dict[str, tuple[int, int]]] = {
    "yx": (0, 1),
    "zx": (0, 2),
    "xy": (1, 0),
    "zy": (1, 2),
    "xz": (2, 0),
    "yz": (2, 1),
}
"""Misalignment name → (row, column) of the error matrix E."""

N_COEFFS: Final = 12
I_YX: Final = 6
I_XY: Final = 8


def coeffs_from_error_matrix(error_matrix: npt.ArrayLike, bias_deg_h: npt.ArrayLike) -> FloatArray:
    """The coefficient vector θ from the error matrix and the biases.

    Parameters
    ----------
    error_matrix : array_like, shape (3, 3)
        E (dimensionless): scale-factor errors on the diagonal, misalignments off it [rad].
    bias_deg_h : array_like, shape (3,)
        The biases b [°/h].

    Returns
    -------
    numpy.ndarray, shape (12,)
        θ: biases [°/h], scale factors [ppm], misalignments [arcsec] (:data:`COEFF_NAMES`).

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, claim 4.

    Examples
    --------
    >>> e = np.diag([1e-6, 2e-6, 0.0])
    >>> coeffs_from_error_matrix(e, [1.0, 2.0, 3.0])[:6].round(3).tolist()
    [1.0, 2.0, 3.0, 1.0, 2.0, 0.0]
    """
    e = np.asarray(error_matrix, dtype=np.float64).reshape(3, 3)
    b = np.asarray(bias_deg_h, dtype=np.float64).reshape(3)
    mis = [e[MISALIGNMENT_INDEX[n]] * units.RAD_TO_ARCSEC for n in MISALIGNMENT_NAMES]
    return np.concatenate([b, np.diag(e) / units.PPM, np.array(mis)])


def error_matrices(theta: npt.ArrayLike) -> FloatArray:
    """E (…, 3, 3) from θ (…, 12), stacked or not: ``E_ii = θ_{3+i}`` [ppm] · 10⁻⁶ and the
    misalignments θ_6… [″] in radians at :data:`MISALIGNMENT_INDEX` (the biases θ_0…2 are
    not part of E; any bias unit, gyro or accelerometer).

    Parameters
    ----------
    theta : array_like, shape (..., 12)
        θ: biases, scale factors [ppm], misalignments [arcsec].

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        E (dimensionless).

    Notes
    -----
    .. math:: E_{ii} = 10^{-6}\\,\\theta_{3+i}, \\quad
              E_{rc} = \\theta_{6+k}\\,\\pi / (180 \\cdot 3600)

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    """
    th = np.asarray(theta, dtype=np.float64)
    e = np.zeros((*th.shape[:-1], 3, 3))
    for i in range(3):
        e[..., i, i] = th[..., 3 + i] * units.PPM
    for k, n in enumerate(MISALIGNMENT_NAMES):
        r, c = MISALIGNMENT_INDEX[n]
        e[..., r, c] = th[..., 6 + k] * units.ARCSEC_TO_RAD
    return e


def error_matrix_from_coeffs(theta: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """The error matrix and biases from θ (inverse of :func:`coeffs_from_error_matrix`).

    Parameters
    ----------
    theta : array_like, shape (12,)
        θ: biases [°/h], scale factors [ppm], misalignments [arcsec].

    Returns
    -------
    E : numpy.ndarray, shape (3, 3)
        Error matrix (dimensionless).
    b : numpy.ndarray, shape (3,)
        Biases [°/h].
    """
    th = np.asarray(theta, dtype=np.float64).reshape(N_COEFFS)
    return error_matrices(th), th[0:3].copy()


def inner_axis_azimuth(
    theta: npt.ArrayLike, cov: npt.ArrayLike | None = None
) -> tuple[float, float]:
    """Antisymmetric xy part ``a = (yx − xy)/2`` [arcsec] — the triad's rotation about
    the inner axis relative to the encoder zero — and its σ (NaN without ``cov``).

    Parameters
    ----------
    theta : array_like, shape (12,)
        θ (misalignments [arcsec] at indices 6…11).
    cov : array_like, shape (12, 12), optional
        θ's covariance [units²].

    Returns
    -------
    a : float
        The antisymmetric part [arcsec].
    sigma : float
        Its standard deviation [arcsec]; NaN without ``cov``.

    Notes
    -----
    .. math:: a = (\\theta_\\mathrm{yx} - \\theta_\\mathrm{xy})/2, \\quad
              \\sigma_a^2 = w^\\mathsf{T} C w, \\ w = \\tfrac12(e_\\mathrm{yx} - e_\\mathrm{xy})

    Examples
    --------
    >>> th = np.zeros(12)
    >>> th[6], th[8] = 10.0, -10.0
    >>> inner_axis_azimuth(th, np.eye(12))[0], round(inner_axis_azimuth(th, np.eye(12))[1], 3)
    (10.0, 0.707)
    """
    th = np.asarray(theta, dtype=np.float64)
    w = np.zeros(N_COEFFS)
    w[I_YX], w[I_XY] = 0.5, -0.5
    val = float(w @ th)
    if cov is None:
        return val, float("nan")
    c = np.asarray(cov, dtype=np.float64)
    return val, float(np.sqrt(max(float(w @ c @ w), 0.0)))


CHANNEL_NAMES: Final = ("alpha", "beta", "gamma")


@dataclass(frozen=True)
class IntervalModel:
    """Per-sample-interval measurement model of the dual-axis turntable, eq. (4).

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (4).

    Attributes
    ----------
    dt_s : interval lengths τ_i [s], shape (m,).
    y_arcsec : gyro-integrated minus encoder increments, (m, k) for the channels
        (α, β[, γ]) [arcsec].
    h : regressors, (m, k, 12) [arcsec per unit of θ].
    proj : projections p of the channels, (m, k, 3) (e_z, e_E^b, e_⊥^b).
    valid : intervals not spanning a gap in time, (m,).
    moving : intervals where an encoder angle changes, (m,).
    """

    dt_s: FloatArray
    y_arcsec: FloatArray
    h: FloatArray
    proj: FloatArray
    valid: npt.NDArray[np.bool_]
    moving: npt.NDArray[np.bool_]

    @property
    def n_channels(self) -> int:
        """Number of channels k (2: Δα, Δβ; 3: with Δγ)."""
        return int(self.y_arcsec.shape[1])

    def select_channels(self, n_channels: int) -> IntervalModel:
        """The first ``n_channels`` channels (2: the source's Δα, Δβ; 3: with Δγ).

        Parameters
        ----------
        n_channels : {2, 3}
            Number of channels kept.

        Returns
        -------
        IntervalModel

        Raises
        ------
        ValueError
            ``n_channels`` not 2 or 3.
        """
        if n_channels not in (2, 3):
            raise ValueError("n_channels must be 2 or 3")
        return IntervalModel(
            dt_s=self.dt_s,
            y_arcsec=self.y_arcsec[:, :n_channels],
            h=self.h[:, :n_channels],
            proj=self.proj[:, :n_channels],
            valid=self.valid,
            moving=self.moving,
        )

    def channel_cov(self, arw_rad_sqrt_s: npt.ArrayLike) -> FloatArray:
        """White-noise covariance of each interval's channels [arcsec²], (m, k, k):
        ``cov(w_c, w_d) = Σ_j p_cj p_dj N_j² τ``.

        Parameters
        ----------
        arw_rad_sqrt_s : array_like, shape (3,) or scalar
            Angle random walk N_j of each gyro [rad/√s].

        Returns
        -------
        numpy.ndarray, shape (m, k, k)
            Covariance [arcsec²].

        Notes
        -----
        .. math:: \\operatorname{cov}(w_c, w_d) = \\sum_j p_{cj}\\, p_{dj}\\, N_j^2\\, \\tau

        References
        ----------
        - IEEE Std 952-1997, Annex C (angle random walk N).
        """
        n2 = (np.asarray(arw_rad_sqrt_s, dtype=np.float64) * units.RAD_TO_ARCSEC) ** 2
        n2 = n2 * np.ones(3)
        out: FloatArray = np.einsum("mcj,mdj,j->mcd", self.proj, self.proj, n2)
        out *= self.dt_s[:, None, None]
        return out


def interval_model(
    time_s: npt.ArrayLike,
    gyro_rad_s: npt.ArrayLike,
    alpha_rad: npt.ArrayLike,
    beta_rad: npt.ArrayLike,
    latitude_deg: float,
    *,
    gap_factor: float = 1.5,
    move_threshold_rad_s: float = 1e-3,
) -> IntervalModel:
    """Build the measurement model eq. (4) for every sample interval (3 channels).

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Sample times [s].
    gyro_rad_s : array_like, shape (n, 3)
        Gyro mean rates over the interval ending at each sample [rad/s]; the first row
        (an interval before the first encoder reading) is not used.
    alpha_rad, beta_rad : array_like, shape (n,)
        Unwrapped encoder angles at the sample times [rad].
    latitude_deg : float
        Latitude L [°].
    gap_factor : float, default 1.5
        An interval longer than this × the median is a gap (invalid).
    move_threshold_rad_s : float, default 1e-3
        An interval is "moving" if an encoder rate exceeds this [rad/s].

    Returns
    -------
    IntervalModel
        m = n − 1 intervals, three channels.

    Notes
    -----
    The earth rate and e_E^b, e_⊥^b are evaluated at the interval's mid angles; the
    true increments φ = ω_true τ come from the encoders (kinematics eq. (2)):

    .. math:: y_{c,i} = p_c \\cdot (g_i \\tau_i - C_n^b \\omega_{ie}^n \\tau_i)
              - \\Delta\\mathrm{enc}_{c,i} = h_{c,i}\\,\\theta + w_{c,i}

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (4).
    """
    t = np.asarray(time_s, dtype=np.float64)
    g = np.asarray(gyro_rad_s, dtype=np.float64)
    a = np.asarray(alpha_rad, dtype=np.float64)
    b = np.asarray(beta_rad, dtype=np.float64)
    dt = np.diff(t)
    da = np.diff(a)
    db = np.diff(b)
    a_mid = 0.5 * (a[1:] + a[:-1])
    b_mid = 0.5 * (b[1:] + b[:-1])
    earth = kinematics.earth_rate_b(a_mid, b_mid, latitude_deg)  # (m, 3)
    e_e = kinematics.outer_axis_b(a_mid)
    e_z = np.zeros_like(e_e)
    e_z[:, 2] = 1.0
    e_p = np.cross(e_z, e_e)
    proj = np.stack([e_z, e_e, e_p], axis=1)  # (m, 3, 3)
    phi = earth * dt[:, None] + da[:, None] * e_z + db[:, None] * e_e  # true increments [rad]
    inc = g[1:] * dt[:, None] - earth * dt[:, None]
    y = np.einsum("mcj,mj->mc", proj, inc)
    y[:, 0] -= da
    y[:, 1] -= db
    y *= units.RAD_TO_ARCSEC
    # regressors: outer product p_j φ_m
    outer = proj[:, :, :, None] * phi[:, None, None, :]  # (m, 3, 3, 3)
    h = np.empty((dt.size, 3, N_COEFFS))
    h[:, :, 0:3] = proj * dt[:, None, None]  # 1 °/h over τ s = τ arcsec
    h[:, :, 3:6] = np.diagonal(outer, axis1=2, axis2=3) * (units.PPM * units.RAD_TO_ARCSEC)
    for k, n in enumerate(MISALIGNMENT_NAMES):
        r, c = MISALIGNMENT_INDEX[n]
        h[:, :, 6 + k] = outer[:, :, r, c]  # arcsec → rad → arcsec
    med = float(np.median(dt)) if dt.size else 0.0
    valid = (dt > 0) & (dt <= gap_factor * med)
    moving = (np.abs(da) > move_threshold_rad_s * dt) | (np.abs(db) > move_threshold_rad_s * dt)
    return IntervalModel(dt_s=dt, y_arcsec=y, h=h, proj=proj, valid=valid, moving=moving)


def whitened_regressors(model: IntervalModel, arw_rad_sqrt_s: npt.ArrayLike) -> FloatArray:
    """``L_i⁻¹ h_i`` for every interval, (m, k, 12), with ``L_i`` the Cholesky factor of
    the interval's channel covariance (invalid intervals are zero).

    Parameters
    ----------
    model : IntervalModel
        The measurement model.
    arw_rad_sqrt_s : array_like, shape (3,) or scalar
        Angle random walk of each gyro [rad/√s].

    Returns
    -------
    numpy.ndarray, shape (m, k, 12)
        Whitened regressors [1/unit of θ].

    References
    ----------
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013 (Cholesky
      factorisation, generalised least squares).
    """
    cov = model.channel_cov(arw_rad_sqrt_s)
    cov[~model.valid] = np.eye(model.n_channels)
    low = np.linalg.cholesky(cov)
    hw: FloatArray = np.linalg.solve(low, model.h)
    hw[~model.valid] = 0.0
    return hw


def fisher_information(
    model: IntervalModel,
    arw_rad_sqrt_s: npt.ArrayLike,
    mask: npt.NDArray[np.bool_] | None = None,
    *,
    whitened: FloatArray | None = None,
) -> FloatArray:
    """Fisher information of θ from the valid intervals (and ``mask``), all channels
    [1/unit²]: ``J = Σ_i h_iᵀ C_i⁻¹ h_i`` (white Gaussian noise, perfect encoders),
    computed with the Cholesky factor of each interval's channel covariance C_i
    (``whitened`` may pass :func:`whitened_regressors` computed before).

    Its inverse is the Cramér–Rao bound of the design (Kay, *Fundamentals of
    Statistical Signal Processing I*, 1993, §3.7, linear Gaussian model).  With the
    three channels it is the bound for the whole gyro record.

    Parameters
    ----------
    model : IntervalModel
        The measurement model.
    arw_rad_sqrt_s : array_like, shape (3,) or scalar
        Angle random walk of each gyro [rad/√s].
    mask : numpy.ndarray of bool, shape (m,), optional
        Intervals to include (with the valid ones).
    whitened : numpy.ndarray, optional
        :func:`whitened_regressors` computed before.

    Returns
    -------
    numpy.ndarray, shape (12, 12)
        J [1/unit²].

    Notes
    -----
    .. math:: J = \\sum_i h_i^\\mathsf{T} C_i^{-1} h_i

    References
    ----------
    - S. M. Kay, *Fundamentals of Statistical Signal Processing, Vol. I: Estimation
      Theory*, Prentice Hall, 1993, §3.7.
    """
    hw = whitened if whitened is not None else whitened_regressors(model, arw_rad_sqrt_s)
    sel = model.valid if mask is None else model.valid & mask
    hv2 = hw[sel].reshape(-1, N_COEFFS)
    out: FloatArray = hv2.T @ hv2
    return out
