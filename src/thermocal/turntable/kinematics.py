"""Kinematics of the dual-axis turntable (CN104880182).

Frames (pyins-style names: ``mat_nb`` takes body vectors to the base frame n):

* n: the base frame, local level East-North-Up, levelled and aligned.
* b: the body (gyro triad) frame.  The inner axis is body z; the outer axis is
  fixed along base East.  At α = β = 0 the body axes point x = East, y = Down,
  z = North.

Attitude, eq. (1)::

    C_b^n = R_E(β) · C_0 · R_z(α),    C_0 = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]

(columns of C_0 are body x, y, z in ENU: East, Down, North).

Angular rate of the body with respect to inertial space, in body axes, eq. (2)::

    ω_ib^b = C_n^b ω_ie^n + α̇ e_z + β̇ C_n^b e_E,      ω_ie^n = Ω (0, cos L, sin L)

with ``C_n^b e_E = (cos α, −sin α, 0)`` (the outer axis seen from the body; it is
always perpendicular to the inner axis e_z).  The inner axis therefore sees
``Ω_N cos β + Ω_U sin β`` (the source's filter row) and the gimbal rates follow from
the gyro outputs as, eq. (3)::

    α̇ = e_z · (ω_ib^b − C_n^b ω_ie^n),      β̇ = e_E^b(α) · (ω_ib^b − C_n^b ω_ie^n)

which is how the gyro-integrated gimbal angles of the 14-state filter are formed.
Source: CN104880182's kinematic equations, rewritten for this geometry.
"""

from __future__ import annotations

from typing import Final

import numpy as np
import numpy.typing as npt

from thermocal import units

FloatArray = npt.NDArray[np.float64]

MAT_C0: Final = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
"""C_0: body → base at α = β = 0 (body x = East, y = Down, z = North)."""


def mat_nb(alpha_rad: npt.ArrayLike, beta_rad: npt.ArrayLike) -> FloatArray:
    """Body-to-base matrices ``C_b^n = R_E(β) C_0 R_z(α)``, eq. (1); shape (..., 3, 3).

    ``R_E(β)`` is the right-handed rotation by β about base East (x of ENU),
    ``R_z(α)`` the right-handed rotation by α about body z.

    Parameters
    ----------
    alpha_rad, beta_rad : array_like
        Inner (α) and outer (β) gimbal angles [rad], broadcast together.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        C_b^n (dimensionless, orthonormal).

    Notes
    -----
    .. math:: C_b^n = R_E(\\beta)\\, C_0\\, R_z(\\alpha)

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (1).

    Examples
    --------
    >>> mat_nb(0.0, 0.0).tolist() == MAT_C0.tolist()
    True
    >>> (mat_nb(np.pi / 2, 0.0) @ [1.0, 0.0, 0.0]).round(3).tolist()  # body x → Down
    [0.0, 0.0, -1.0]
    """
    a = np.asarray(alpha_rad, dtype=np.float64)
    b = np.asarray(beta_rad, dtype=np.float64)
    a, b = np.broadcast_arrays(a, b)
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    zero, one = np.zeros_like(a), np.ones_like(a)
    rz = np.stack(
        [
            np.stack([ca, -sa, zero], -1),
            np.stack([sa, ca, zero], -1),
            np.stack([zero, zero, one], -1),
        ],
        -2,
    )
    rx = np.stack(
        [
            np.stack([one, zero, zero], -1),
            np.stack([zero, cb, -sb], -1),
            np.stack([zero, sb, cb], -1),
        ],
        -2,
    )
    out: FloatArray = rx @ MAT_C0 @ rz
    return out


def earth_rate_b(
    alpha_rad: npt.ArrayLike, beta_rad: npt.ArrayLike, latitude_deg: float
) -> FloatArray:
    """Earth rate in body axes ``C_n^b ω_ie^n`` [rad/s], shape (..., 3).

    Closed form of ``R_z(−α) C_0ᵀ R_E(−β) (0, Ω_N, Ω_U)``::

        u = Ω_N cos β + Ω_U sin β      (along the inner axis, body z)
        v = −(Ω_U cos β − Ω_N sin β)   (along body y at α = 0: Down)
        ω = (v sin α, v cos α, u)

    Parameters
    ----------
    alpha_rad, beta_rad : array_like
        Inner (α) and outer (β) gimbal angles [rad], broadcast together.
    latitude_deg : float
        Latitude L [°].

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Earth rate in body axes [rad/s].

    Notes
    -----
    .. math:: \\omega_{ie}^n = \\Omega\\,(0, \\cos L, \\sin L), \\quad
              \\Omega = 7.292115 \\times 10^{-5}\\ \\mathrm{rad/s}\\ \\text{(WGS 84)}

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (2).
    - NIMA TR8350.2, *Department of Defense World Geodetic System 1984*, 3rd ed., 2000
      (earth rotation rate).

    Examples
    --------
    >>> w = earth_rate_b(0.0, 0.0, 0.0)  # equator: all along North = body z
    >>> round(float(w[2]) * 1e5, 3), round(float(abs(w[0]) + abs(w[1])), 12)
    (7.292, 0.0)
    """
    a = np.asarray(alpha_rad, dtype=np.float64)
    b = np.asarray(beta_rad, dtype=np.float64)
    lat = np.deg2rad(latitude_deg)
    om_n = units.EARTH_RATE_RAD_S * np.cos(lat)
    om_u = units.EARTH_RATE_RAD_S * np.sin(lat)
    u = om_n * np.cos(b) + om_u * np.sin(b)
    v = -(om_u * np.cos(b) - om_n * np.sin(b))
    a, u, v = np.broadcast_arrays(a, u, v)
    out: FloatArray = np.stack([v * np.sin(a), v * np.cos(a), u], axis=-1)
    return out


def outer_axis_b(alpha_rad: npt.ArrayLike) -> FloatArray:
    """Outer (East) axis in body axes ``e_E^b = C_n^b e_E = (cos α, −sin α, 0)``.

    Parameters
    ----------
    alpha_rad : array_like
        Inner gimbal angle α [rad].

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Unit vector (dimensionless).
    """
    a = np.asarray(alpha_rad, dtype=np.float64)
    out: FloatArray = np.stack([np.cos(a), -np.sin(a), np.zeros_like(a)], axis=-1)
    return out


def omega_ib_b(
    alpha_rad: npt.ArrayLike,
    beta_rad: npt.ArrayLike,
    alpha_rate_rad_s: npt.ArrayLike,
    beta_rate_rad_s: npt.ArrayLike,
    latitude_deg: float,
) -> FloatArray:
    """True body rate with respect to inertial space, in body axes, eq. (2).

    Parameters
    ----------
    alpha_rad, beta_rad : array_like
        Inner (α) and outer (β) gimbal angles [rad], broadcast together.
    alpha_rate_rad_s, beta_rate_rad_s : array_like
        Gimbal rates α̇, β̇ [rad/s].
    latitude_deg : float
        Latitude L [°].

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        ω_ib^b [rad/s].

    Notes
    -----
    .. math:: \\omega_{ib}^b = C_n^b \\omega_{ie}^n + \\dot\\alpha\\, e_z + \\dot\\beta\\, e_E^b

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (2).

    Examples
    --------
    >>> w = omega_ib_b(0.3, 0.2, 0.1, -0.05, 45.0)
    >>> [round(float(v), 6) for v in gimbal_rates(w, 0.3, 0.2, 45.0)]
    [0.1, -0.05]
    """
    a = np.asarray(alpha_rad, dtype=np.float64)
    ad = np.asarray(alpha_rate_rad_s, dtype=np.float64)
    bd = np.asarray(beta_rate_rad_s, dtype=np.float64)
    w: FloatArray = (
        earth_rate_b(a, beta_rad, latitude_deg)
        + ad[..., None] * np.array([0.0, 0.0, 1.0])
        + bd[..., None] * outer_axis_b(a)
    )
    return w


def gimbal_rates(
    omega_b_rad_s: npt.ArrayLike,
    alpha_rad: npt.ArrayLike,
    beta_rad: npt.ArrayLike,
    latitude_deg: float,
) -> tuple[FloatArray, FloatArray]:
    """Gimbal rates from body rates, eq. (3): ``(α̇, β̇)`` [rad/s].

    ``α̇ = e_z·(ω − C_n^b ω_ie^n)``, ``β̇ = e_E^b(α)·(ω − C_n^b ω_ie^n)``.

    Parameters
    ----------
    omega_b_rad_s : array_like, shape (..., 3)
        Body rates [rad/s].
    alpha_rad, beta_rad : array_like
        Inner (α) and outer (β) gimbal angles [rad], broadcast together.
    latitude_deg : float
        Latitude L [°].

    Returns
    -------
    alpha_rate, beta_rate : numpy.ndarray
        α̇ and β̇ [rad/s].

    Notes
    -----
    .. math:: \\dot\\alpha = e_z \\cdot (\\omega - C_n^b \\omega_{ie}^n), \\quad
              \\dot\\beta = e_E^b(\\alpha) \\cdot (\\omega - C_n^b \\omega_{ie}^n)

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (3).
    """
    w = np.asarray(omega_b_rad_s, dtype=np.float64) - earth_rate_b(
        alpha_rad, beta_rad, latitude_deg
    )
    e_e = outer_axis_b(alpha_rad)
    return w[..., 2], np.einsum("...i,...i->...", w, e_e)
