r"""Gyro sensitivity to specific force (g-sensitivity) from the static poses.

A gyro's bias moves with the specific force it feels: IEEE Std 952-1997 (fibre-optic
gyros, annex B, the model's *acceleration-sensitive drift* terms) and IEEE Std 1431-2004
(Coriolis vibratory gyros) write the rate output's bias as ``D_F + Σ_j D_j a_j`` with
``a_j`` the specific force along axis j in g.  For the triad the nine coefficients make the
matrix ``A`` of

.. math::

    \bar\omega_k = b + A\, f_k + \Omega \sin L\, u_k + e_k,                 (1)

with :math:`\bar\omega_k` the mean rate of static pose k, :math:`f_k = (g_k/g_0)\, u_k`
its specific force in g along the calibrated up direction :math:`u_k` (the accelerometer's
calibration gives it), :math:`\Omega \sin L\, u_k` the vertical earth rate at latitude L
and :math:`e_k` the pose's noise: white noise :math:`\sigma_i^2/n_k` and the horizontal
earth rate, whose direction in the board (the pose's heading) is not measured and counts
as noise of variance :math:`(\Omega\cos L)^2 (1 - u_{ki}^2)/2` per axis (without L:
:math:`\Omega^2/3`), as the static bias does (:func:`thermocal.multipos.gyro.static_bias`).

Each gyro axis i is one weighted least-squares problem in :math:`(b_i, A_{i1}, A_{i2},
A_{i3})` over the poses, solved by QR of the whitened design (Golub & Van Loan §5.3): it
needs at least four poses whose gravity directions are not all in one plane through the
board (a design of rank 4); the six faces give it, each coefficient then the half
difference of a face pair.  Its covariance is :math:`(X^\top W X)^{-1}`, scaled by the
reduced χ² when the scatter is beyond the noise model (a bias that also drifts with
time or temperature between the poses).

The matrix is an estimate of the gyro's sensitivity, reported with its σ.  When an element
is beyond :data:`SIGNIFICANT_SIGMA` σ, the session's calibration
(:func:`thermocal.multipos.calibrate_session`) takes ``A f(t)`` off every sample's rate,
``f`` the calibrated accelerometer's reading in g (the hand's accelerations too), before the
gyro's bias and the rotations' fit (:mod:`thermocal.multipos.gyro`): left in, the drift
along each turn is taken for scale factor (a simulated Ferraris session with A up to
0.1 °/s/g: scale factors 3–12σ off; imu_tk's Xsens session: the motions' reduced χ² 110,
4.8 with it taken off).  A's own σ is not carried into the rotations' covariance (on those
sessions the gyro's θ then stays within 3.5σ of the truth, as without a sensitivity).
An ``A`` that is ``c I`` alone (:func:`isotropic_part`) is what a latitude of the wrong sign
gives (a vertical earth rate off along every up direction): reported, never taken off
(``multipos`` and ``turntable`` alike).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import DesignError
from thermocal.recording import FloatArray

MIN_POSES = 4
"""Poses the fit of eq. (1) needs per axis (a bias and three sensitivities)."""

MAX_DESIGN_COND = 1e4
"""Largest condition number of the design ``[1, f_x, f_y, f_z]`` (f in g) accepted:
beyond it the poses' gravity directions lie (nearly) in one plane through the board and one
column of ``A`` is not seen."""

SIGNIFICANT_SIGMA = 3.0
"""An element of ``A`` farther than this many σ from 0 is a g-sensitivity found."""


@dataclass(frozen=True)
class GSensitivity:
    """The gyro's sensitivity to specific force, eq. (1) of the module docstring.

    Attributes
    ----------
    matrix_deg_h_g : numpy.ndarray, shape (3, 3)
        ``A``: row i the gyro axis, column j the specific force's axis [°/h per g].
    sigma_deg_h_g : numpy.ndarray, shape (3, 3)
        Its standard uncertainties [°/h per g].
    bias_deg_h : numpy.ndarray, shape (3,)
        ``b`` of eq. (1), the bias at zero specific force [°/h].
    reduced_chi2 : numpy.ndarray, shape (3,)
        Each axis's reduced χ² (NaN with no degree of freedom).
    dof : int
        Degrees of freedom per axis: poses less four.
    n_poses : int
        Static poses used.
    design_cond : float
        Condition number of the design ``[1, f]`` (f in g).
    """

    matrix_deg_h_g: FloatArray
    sigma_deg_h_g: FloatArray
    bias_deg_h: FloatArray
    reduced_chi2: FloatArray
    dof: int
    n_poses: int
    design_cond: float

    @property
    def significant(self) -> npt.NDArray[np.bool_]:
        """Elements of ``A`` beyond :data:`SIGNIFICANT_SIGMA` σ from 0 (3×3 booleans)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.abs(self.matrix_deg_h_g) / self.sigma_deg_h_g
        out: npt.NDArray[np.bool_] = np.asarray(z > SIGNIFICANT_SIGMA)
        return out

    def to_dict(self, per_deg_h: float = 1.0, unit: str = "deg/h") -> dict[str, Any]:
        """The estimate as JSON types, in the gyro's unit per g.

        Parameters
        ----------
        per_deg_h : float, optional
            The gyro unit's value of 1 °/h (1.0: °/h).
        unit : str, optional
            That unit's name.

        Returns
        -------
        dict
            ``matrix`` and ``matrix_sigma`` (rows: gyro axis x, y, z; columns: specific force
            along x, y, z) in ``unit`` per g, ``unit``, ``bias`` at zero specific force,
            ``significant`` (3×3 booleans), ``reduced_chi2`` per axis (None without a degree
            of freedom), ``dof``, ``n_poses``, ``design_cond``.
        """
        chi = [None if not math.isfinite(float(c)) else float(c) for c in self.reduced_chi2]
        return {
            "matrix": (self.matrix_deg_h_g * per_deg_h).tolist(),
            "matrix_sigma": (self.sigma_deg_h_g * per_deg_h).tolist(),
            "unit": f"{unit}/g",
            "bias": (self.bias_deg_h * per_deg_h).tolist(),
            "significant": self.significant.tolist(),
            "reduced_chi2": chi,
            "dof": self.dof,
            "n_poses": self.n_poses,
            "design_cond": self.design_cond,
        }


def _noise_var(
    n_samples: FloatArray, rate_sigma_rad_s: FloatArray, up: FloatArray, latitude_deg: float | None
) -> FloatArray:
    """Each pose's variance per axis [rad²/s²]: white noise and the horizontal earth rate."""
    from thermocal.multipos.gyro import unmeasured_earth_rate_var

    earth = unmeasured_earth_rate_var(up, latitude_deg)
    out: FloatArray = rate_sigma_rad_s[None, :] ** 2 / n_samples[:, None] + earth
    return out


def fit_g_sensitivity(
    rate_means_rad_s: npt.ArrayLike,
    n_samples: npt.ArrayLike,
    rate_sigma_rad_s: npt.ArrayLike,
    specific_force_g: npt.ArrayLike,
    latitude_deg: float | None = None,
) -> GSensitivity:
    """The gyro's g-sensitivity matrix ``A`` and its σ from static poses, eq. (1).

    Parameters
    ----------
    rate_means_rad_s : array_like, shape (m, 3)
        Mean rate of each static pose [rad/s].
    n_samples : array_like, shape (m,)
        Samples per pose.
    rate_sigma_rad_s : array_like, shape (3,)
        Per-sample white-noise σ of each gyro axis [rad/s].
    specific_force_g : array_like, shape (m, 3)
        Each pose's calibrated specific force in body axes [g] (at rest: the up direction
        times the local gravity over standard gravity).
    latitude_deg : float, optional
        Latitude [°]: the vertical earth rate is taken off and the horizontal one counted as
        noise; None counts the whole earth rate as noise of unknown direction.

    Returns
    -------
    GSensitivity
        ``A`` [°/h/g], its σ, the bias at zero specific force [°/h], each axis's reduced χ².

    Raises
    ------
    thermocal.errors.DesignError
        Fewer than :data:`MIN_POSES` poses, or poses whose gravity directions do not span
        the three axes (condition number beyond :data:`MAX_DESIGN_COND`).

    Notes
    -----
    Per gyro axis i, whitened by each pose's noise σ_ki (module docstring):

    .. math::

        \\min_{b_i, A_i} \\sum_k \\frac{(\\bar\\omega_{ki} - \\Omega \\sin L\\, u_{ki}
        - b_i - A_i f_k)^2}{\\sigma_{ki}^2}, \\qquad
        \\operatorname{cov} = (X^\\top W X)^{-1} \\max(1, \\chi^2_\\nu)

    the χ² factor applied when the scatter is beyond the noise (5 % level).

    References
    ----------
    - IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for
      Single-Axis Interferometric Fiber Optic Gyros*, annex B (acceleration-sensitive drift).
    - IEEE Std 1431-2004, *IEEE Standard Specification Format Guide and Test Procedure for
      Coriolis Vibratory Gyros*.
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., §5.3.

    Examples
    --------
    Six faces; the x gyro reads 360 °/h per g along z (latitude 0; noise-free means):

    >>> import numpy as np
    >>> up = np.vstack([np.eye(3), -np.eye(3)])
    >>> a = np.zeros((3, 3)); a[0, 2] = 360.0
    >>> w = (up @ a.T + [10.0, 0.0, 0.0]) * np.pi / 180 / 3600
    >>> gs = fit_g_sensitivity(w, np.full(6, 1000), np.full(3, 1e-3), up, latitude_deg=0.0)
    >>> round(float(gs.matrix_deg_h_g[0, 2]), 3), round(float(gs.bias_deg_h[0]), 3)
    (360.0, 10.0)
    """
    w = np.asarray(rate_means_rad_s, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(n_samples, dtype=np.float64).ravel()
    sig = np.asarray(rate_sigma_rad_s, dtype=np.float64).ravel()
    f = np.asarray(specific_force_g, dtype=np.float64).reshape(-1, 3)
    cond = _check_design(f, "static poses", POSES_REMEDY)
    norm = np.linalg.norm(f, axis=1, keepdims=True)
    up = f / np.where(norm > 0, norm, 1.0)
    y = w.copy()
    if latitude_deg is not None:
        y = y - units.EARTH_RATE_RAD_S * math.sin(math.radians(latitude_deg)) * up
    return _fit(y, _noise_var(n, sig, up, latitude_deg), f, cond)


POSES_REMEDY = "add poses with gravity along each axis in both senses (the six faces)"
"""What gets a multi-position session's g-sensitivity separable."""


def fit_g_sensitivity_known_rate(
    residual_means_rad_s: npt.ArrayLike,
    variance_rad2_s2: npt.ArrayLike,
    specific_force_g: npt.ArrayLike,
    *,
    what: str = "dwells",
    remedy: str = POSES_REMEDY,
) -> GSensitivity:
    r"""``A`` and its σ from still positions whose whole true rate is known (a turntable's
    encoders and a levelled, aligned base give the earth rate in body axes): eq. (1) with
    the earth rate, scale factors and misalignments already taken off by the caller.

    Parameters
    ----------
    residual_means_rad_s : array_like, shape (m, 3)
        Each position's mean rate less ``(I + E) ω_true`` [rad/s]: ``b + A f_k + e_k``.
    variance_rad2_s2 : array_like, shape (m, 3)
        The variance of each mean per axis [rad²/s²] (white noise: ``N² / T_k``, N the
        angle random walk [rad/√s] and ``T_k`` the time held [s]).
    specific_force_g : array_like, shape (m, 3)
        Each position's specific force in body axes [g].
    what : str, optional
        What the positions are called in a refusal (``"dwells"``).
    remedy : str, optional
        What gets the user further, in a refusal.

    Returns
    -------
    GSensitivity
        ``A`` [°/h/g], its σ, the bias at zero specific force [°/h], each axis's reduced χ².

    Raises
    ------
    thermocal.errors.DesignError
        Fewer than :data:`MIN_POSES` positions, or gravity directions that do not span the
        three axes (the unseen direction named).

    Notes
    -----
    Per gyro axis i, the weighted least squares of :func:`fit_g_sensitivity` with known
    variances :math:`\sigma_{ki}^2`:

    .. math::

        \min_{b_i, A_i} \sum_k \frac{(r_{ki} - b_i - A_i f_k)^2}{\sigma_{ki}^2}

    References
    ----------
    - IEEE Std 1431-2004, *IEEE Standard Specification Format Guide and Test Procedure for
      Coriolis Vibratory Gyros* (the acceleration-sensitive drift of the rate model).
    - IEEE Std 952-1997, annex B (acceleration-sensitive drift).

    Examples
    --------
    >>> import numpy as np
    >>> up = np.vstack([np.eye(3), -np.eye(3)])
    >>> a = np.zeros((3, 3)); a[1, 0] = 3.6
    >>> r = (up @ a.T) * np.pi / 180 / 3600
    >>> gs = fit_g_sensitivity_known_rate(r, np.full((6, 3), 1e-14), up)
    >>> round(float(gs.matrix_deg_h_g[1, 0]), 6)
    3.6
    """
    r = np.asarray(residual_means_rad_s, dtype=np.float64).reshape(-1, 3)
    var = np.asarray(variance_rad2_s2, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(specific_force_g, dtype=np.float64).reshape(-1, 3)
    return _fit(r, var, f, _check_design(f, what, remedy))


def _check_design(f: FloatArray, what: str, remedy: str) -> float:
    """The scaled design's condition number; refuses too few positions or directions that
    do not span the axes (naming the unseen direction, body axes)."""
    m = f.shape[0]
    if m < MIN_POSES:
        raise DesignError(
            f"the gyro's g-sensitivity needs at least {MIN_POSES} {what} (a bias and "
            f"three sensitivities per axis), got {m}"
        )
    # f in g has its own scale (a column scaled by its norm would make a force component
    # that only rounding leaves off zero, 1e-16 g, look as well seen as the others)
    design = np.column_stack([np.ones(m), f])
    _u, s, vt = np.linalg.svd(design, full_matrices=False)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else math.inf
    if not cond <= MAX_DESIGN_COND:
        raise DesignError(
            f"the gyro's g-sensitivity is not separable from these {m} {what}: their gravity "
            f"directions do not span the three axes (design condition number {cond:.3g}; "
            f"{_unseen(s, vt)}); {remedy}"
        )
    return cond


def _unseen(s: FloatArray, vt: FloatArray) -> str:
    """The specific-force directions the design ``[1, f]`` does not see (its singular values
    ``s`` and right vectors ``vt``), in words, body axes."""

    def shown(v: FloatArray) -> str:
        d = v / max(float(np.linalg.norm(v)), 1e-300)
        d = np.round(d * (1.0 if d[int(np.argmax(np.abs(d)))] >= 0 else -1.0), 2) + 0.0
        return f"({d[0]:+.2f}, {d[1]:+.2f}, {d[2]:+.2f})"

    weak = vt[s * MAX_DESIGN_COND < s[0], 1:]
    if weak.shape[0] >= 2:
        return (
            "every gravity direction along "
            f"{shown(np.cross(weak[0], weak[1]))}: the force across it unseen"
        )
    return f"unseen: specific force along {shown(vt[-1, 1:])} in body axes"


def _fit(y: FloatArray, var: FloatArray, f: FloatArray, cond: float) -> GSensitivity:
    """Each axis's fit of eq. (1) on the prepared means ``y`` and variances ``var`` (the
    design's condition number ``cond`` checked before)."""
    m = f.shape[0]
    x = np.column_stack([np.ones(m), f])
    to_dh = 1.0 / units.DH_TO_RS
    fits = [_solve_axis(x, y[:, i], var[:, i]) for i in range(3)]
    coef = np.array([c for c, _, _ in fits]) * to_dh
    sd = np.array([s for _, s, _ in fits]) * to_dh
    chi = np.array([c for _, _, c in fits])
    return GSensitivity(coef[:, 1:], sd[:, 1:], coef[:, 0], chi, m - 4, m, cond)


ISOTROPIC_NOTE = (
    "the g-sensitivity is c·I alone (c = {c:.3g} ± {s:.2g} °/h/g): what a vertical earth "
    "rate off by c gives (a latitude of the wrong sign), so it is not taken off the moves; "
    "check the latitude"
)
"""Why an isotropic ``A`` (:func:`isotropic_part`) is reported but not subtracted, by
``multipos`` and ``turntable`` alike."""


def isotropic_part(matrix: npt.ArrayLike, sigma: npt.ArrayLike) -> tuple[float, float] | None:
    r"""``(c, σ_c)`` when ``A`` is ``c I`` alone: ``c`` (the diagonal's
    inverse-variance mean) beyond 3σ and every other part of ``A`` (the off-diagonal, the
    diagonal less ``c``) within 3σ; else None.

    ``c I f = c (g/g_0)\, u`` is a rate along the up direction ``u``: exactly what an error
    of the vertical earth rate :math:`\Omega \sin L` gives (a latitude of the wrong sign).
    On its own it is not taken for a sensitivity to subtract from the moves, nor stored.

    Parameters
    ----------
    matrix, sigma : array_like, shape (3, 3)
        The estimate ``A`` and its σ (:attr:`GSensitivity.matrix_deg_h_g`, or the sessions'
        combined :func:`combine_g_sensitivity`) [any rate unit per g].

    Returns
    -------
    tuple of float or None
        ``c`` and its σ [the unit of ``matrix``], or None.

    Notes
    -----
    .. math:: c = \frac{\sum_i A_{ii} / \sigma_{ii}^2}{\sum_i 1 / \sigma_{ii}^2}, \qquad
              \sigma_c = \Big(\sum_i \sigma_{ii}^{-2}\Big)^{-1/2}

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (2) (the
      earth rate in body axes).
    """
    a, s = np.asarray(matrix, dtype=np.float64), np.asarray(sigma, dtype=np.float64)
    d, sd = np.diag(a), np.diag(s)
    w = 1.0 / sd**2
    c = float((w * d).sum() / w.sum())
    sc = float(1.0 / np.sqrt(w.sum()))
    off = ~np.eye(3, dtype=bool)
    rest_seen = np.any(np.abs(a[off]) > 3.0 * s[off]) or np.any(np.abs(d - c) > 3.0 * sd)
    return (c, sc) if abs(c) > 3.0 * sc and not rest_seen else None


def combine_g_sensitivity(estimates: Sequence[GSensitivity]) -> tuple[FloatArray, FloatArray]:
    """One ``A`` from the estimates of several sessions (one per temperature): each element
    the inverse-variance weighted mean, its σ that of the mean, scaled by the square root of
    the sessions' reduced χ² about it when they scatter beyond their σ.

    Parameters
    ----------
    estimates : sequence of GSensitivity
        One or more sessions' estimates.

    Returns
    -------
    matrix, sigma : numpy.ndarray, shape (3, 3)
        ``A`` and its standard uncertainty [°/h per g].

    Raises
    ------
    ValueError
        No estimate.

    Notes
    -----
    Per element, with :math:`w_r = 1/\\sigma_r^2` over the k sessions:

    .. math::

        \\bar A = \\frac{\\sum_r w_r A_r}{\\sum_r w_r}, \\qquad
        \\sigma_{\\bar A} = \\Big(\\sum_r w_r\\Big)^{-1/2}
        \\max\\Big(1, \\frac{\\sum_r w_r (A_r - \\bar A)^2}{k - 1}\\Big)^{1/2}

    the weighted mean of a least-squares fit of a constant (Golub & Van Loan §5.3 with a
    one-column design); the sensitivity is taken as constant in temperature.

    References
    ----------
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., §5.3.

    Examples
    --------
    >>> import numpy as np
    >>> one = GSensitivity(np.full((3, 3), 10.0), np.full((3, 3), 2.0), np.zeros(3),
    ...                    np.ones(3), 2, 6, 1.0)
    >>> two = GSensitivity(np.full((3, 3), 13.0), np.full((3, 3), 1.0), np.zeros(3),
    ...                    np.ones(3), 2, 6, 1.0)
    >>> a, s = combine_g_sensitivity([one, two])
    >>> float(a[0, 0]), round(float(s[0, 0]), 4)
    (12.4, 1.2)
    """
    if not estimates:
        raise ValueError("combine_g_sensitivity: no estimate")
    a = np.array([e.matrix_deg_h_g for e in estimates])
    w = 1.0 / np.array([e.sigma_deg_h_g for e in estimates]) ** 2
    mean: FloatArray = (w * a).sum(axis=0) / w.sum(axis=0)
    sigma: FloatArray = 1.0 / np.sqrt(w.sum(axis=0))
    if len(estimates) > 1:
        chi = (w * (a - mean) ** 2).sum(axis=0) / (len(estimates) - 1)
        sigma = sigma * np.sqrt(np.maximum(1.0, chi))
    return mean, sigma


def _solve_axis(
    x: FloatArray, y: FloatArray, var: FloatArray
) -> tuple[FloatArray, FloatArray, float]:
    """One axis's weighted least squares by QR: coefficients, their σ (scaled by a reduced χ²
    beyond the noise at the 5 % level) and the reduced χ² (NaN without a degree of freedom)."""
    wt = 1.0 / np.sqrt(var)
    q, r = np.linalg.qr(x * wt[:, None])
    c = np.linalg.solve(r, q.T @ (y * wt))
    rinv = np.linalg.solve(r, np.eye(x.shape[1]))
    cov = rinv @ rinv.T
    dof = x.shape[0] - x.shape[1]
    chi = math.nan
    if dof > 0:
        res = (y - x @ c) * wt
        chi = float(res @ res) / dof
        from scipy.stats import chi2

        if chi > chi2.ppf(0.95, dof) / dof:
            cov = cov * chi
    return c, np.sqrt(np.diag(cov)), chi


__all__ = [
    "ISOTROPIC_NOTE",
    "MAX_DESIGN_COND",
    "MIN_POSES",
    "POSES_REMEDY",
    "SIGNIFICANT_SIGMA",
    "GSensitivity",
    "combine_g_sensitivity",
    "fit_g_sensitivity",
    "fit_g_sensitivity_known_rate",
    "isotropic_part",
]
