"""Accelerometer triad from the dwells of a dual-axis turntable run (the geometry of
:mod:`.kinematics`).

Model: ``f_meas = (I + E_a) f_true + b_a + noise``, with ``f_true`` the specific force of a
sensor at rest, gravity's reaction pointing up: ``f_true_b = C_nᵇ (0, 0, g)`` in the body
axes, ``C_bⁿ = R_E(β) C_0 R_z(α)`` from the encoder angles (:func:`.kinematics.mat_nb`) and
``g`` the local gravity (WGS-84 normal gravity at the latitude, or given).

Each dwell's mean specific force gives three equations; axis ``i`` alone reads
``f_i − f_true,i = Σ_j E_ij f_true,j + b_i``: four unknowns per axis, linear, solved by
weighted least squares over the dwells (weights: samples per dwell, the mean of ``n``
samples having variance σ²/n), through an SVD of the scaled design (no normal equations).
The per-axis residual variance gives the covariance.  Sixteen positions put
gravity along ± every body axis and between them: every element of ``E_a`` is seen.

Units out (θ, 12, the order of the gyro's :mod:`.model`): bias [mg] (1 mg = 9.80665·10⁻³
m/s²), scale-factor errors ``E_ii`` [ppm], misalignments ``E_ij`` [″] in
:data:`.model.MISALIGNMENT_NAMES` order.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import DesignError, ThermocalInputError
from thermocal.turntable import kinematics, model

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class AccelEstimate:
    """An accelerometer triad's θ (12: bias [mg], scale factor [ppm], misalignment [″]),
    its covariance, the weighted residual rms of the dwell means [mg] and the number of
    dwells and distinct gravity directions used.

    Attributes
    ----------
    theta : numpy.ndarray, shape (12,)
        Bias [mg], scale factors [ppm], misalignments [″].
    cov : numpy.ndarray, shape (12, 12)
        Its covariance.
    residual_rms_mg : float
        Weighted residual rms of the dwell means [mg].
    n_dwells : int
        Dwells used.
    condition_number : float
        Condition number of the scaled design [-].
    """

    theta: FloatArray
    cov: FloatArray
    residual_rms_mg: float
    n_dwells: int
    condition_number: float

    @property
    def sigma(self) -> FloatArray:
        out: FloatArray = np.sqrt(np.maximum(np.diag(self.cov), 0.0))
        return out

    @property
    def error_matrix(self) -> FloatArray:
        """E_a (dimensionless)."""
        return model.error_matrices(self.theta)

    @property
    def bias_m_s2(self) -> FloatArray:
        out: FloatArray = self.theta[0:3] * units.MG_TO_MS2
        return out

    def to_dict(self) -> dict[str, Any]:
        s = self.sigma
        return {
            "bias_mg": self.theta[0:3].tolist(),
            "bias_mg_sigma": s[0:3].tolist(),
            "scale_factor_ppm": self.theta[3:6].tolist(),
            "scale_factor_ppm_sigma": s[3:6].tolist(),
            "misalignment_arcsec": self.theta[6:12].tolist(),
            "misalignment_arcsec_sigma": s[6:12].tolist(),
            "misalignment_names": list(model.MISALIGNMENT_NAMES),
            "error_matrix": self.error_matrix.tolist(),
            "residual_rms_mg": self.residual_rms_mg,
            "n_dwells": self.n_dwells,
            "condition_number": self.condition_number,
        }


def gravity_in_body(alpha_deg: npt.ArrayLike, beta_deg: npt.ArrayLike, g_m_s2: float) -> FloatArray:
    r"""Specific force of a triad at rest in body axes [m/s²] (ENU base, up positive).

    Parameters
    ----------
    alpha_deg, beta_deg : array_like
        Inner- and outer-axis encoder angles [°], of the same shape.
    g_m_s2 : float
        Local gravity [m/s²].

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The specific force in body axes [m/s²].

    Notes
    -----
    .. math:: \mathbf f_b = C_n^b \, (0, 0, g)^\mathsf{T}, \qquad
              C_b^n = R_E(\beta)\, C_0\, R_z(\alpha)

    (:func:`.kinematics.mat_nb`).

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.

    Examples
    --------
    >>> [round(float(v), 3) + 0.0 for v in gravity_in_body(0.0, 0.0, 9.8)]
    [0.0, -9.8, 0.0]
    """
    a = np.deg2rad(np.asarray(alpha_deg, dtype=np.float64))
    b = np.deg2rad(np.asarray(beta_deg, dtype=np.float64))
    c_nb = kinematics.mat_nb(a, b)  # body → base
    up = np.array([0.0, 0.0, g_m_s2])
    out: FloatArray = np.einsum("...ji,j->...i", c_nb, up)  # Cᵀ · up
    return out


def estimate_accel_triad(
    f_mean_m_s2: npt.ArrayLike,
    f_true_m_s2: npt.ArrayLike,
    n_samples: npt.ArrayLike,
) -> AccelEstimate:
    r"""Bias, scale factors and misalignments of an accelerometer triad from dwell means
    (module docstring).  Needs gravity along at least three independent body directions and
    more dwells than the four unknowns of an axis.

    Parameters
    ----------
    f_mean_m_s2 : array_like, shape (m, 3)
        Measured mean specific force of each dwell [m/s²].
    f_true_m_s2 : array_like, shape (m, 3)
        Specific force of each dwell from its attitude [m/s²] (:func:`gravity_in_body`).
    n_samples : array_like, shape (m,)
        Samples averaged in each dwell (the weights).

    Returns
    -------
    AccelEstimate
        θ (12: bias [mg], scale factors [ppm], misalignments [″]), its covariance, the
        residual rms [mg], the number of dwells and the design's condition number.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Arrays of the wrong shapes.
    thermocal.errors.DesignError
        Fewer than 6 dwells, or gravity not along three independent body directions.

    Notes
    -----
    Axis :math:`i` alone, by weighted least squares over the dwells (weights :math:`n_k`):

    .. math:: f_i - f_{\mathrm{true},i} = \sum_j E_{ij}\, f_{\mathrm{true},j} + b_i

    References
    ----------
    - IEEE Std 1293-1998, *IEEE Standard Specification Format Guide and Test Procedure for
      Linear, Single-Axis, Nongyroscopic Accelerometers* (multipoint tumble test).
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    """
    f = np.asarray(f_mean_m_s2, dtype=np.float64)
    ft = np.asarray(f_true_m_s2, dtype=np.float64)
    w = np.asarray(n_samples, dtype=np.float64)
    if f.ndim != 2 or f.shape[1] != 3 or ft.shape != f.shape or w.shape != (f.shape[0],):
        raise ThermocalInputError("dwell means: expected (m, 3) measured and true, (m,) counts")
    m = f.shape[0]
    if m < 6:
        raise DesignError(f"{m} dwells: an accelerometer triad needs at least 6 attitudes")
    g = float(np.median(np.linalg.norm(ft, axis=1)))
    # scaled design: f_true/g in [−1, 1] and the constant column, rows weighted by √n
    design = np.column_stack([ft / g, np.ones(m)])
    sw = np.sqrt(w)
    a = design * sw[:, None]
    u, s, vt = np.linalg.svd(a, full_matrices=False)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else math.inf
    if not s[-1] > 1e-9 * s[0]:
        raise DesignError(
            "the dwells do not put gravity along three independent body directions: the "
            "accelerometer scale factors and misalignments cannot be separated"
        )
    theta = np.zeros(12)
    cov = np.zeros((12, 12))
    ss = 0.0
    v_inv_s = vt.T / s  # columns of V scaled by 1/σ: x = V S⁻¹ Uᵀ y
    for i in range(3):
        y = (f[:, i] - ft[:, i]) * sw
        x = v_inv_s @ (u.T @ y)
        r = a @ x - y
        dof = max(m - 4, 1)
        var = float(r @ r) / dof  # per unit weight (one sample's variance)
        ss += float(r @ r)
        cov_x = var * (v_inv_s @ v_inv_s.T)
        # x = (E_i0 g, E_i1 g, E_i2 g, b_i) in m/s²: back to E and b
        scale = np.array([1.0 / g, 1.0 / g, 1.0 / g, 1.0 / units.MG_TO_MS2])
        xs = x * scale
        cs = cov_x * np.outer(scale, scale)
        idx = [_theta_index(i, j) for j in range(3)] + [i]
        units_of = [_unit_factor(i, j) for j in range(3)] + [1.0]
        for p, (ip, up) in enumerate(zip(idx, units_of, strict=True)):
            theta[ip] = xs[p] * up
            for q, (iq, uq) in enumerate(zip(idx, units_of, strict=True)):
                cov[ip, iq] = cs[p, q] * up * uq
    rms_mg = math.sqrt(ss / max(float(w.sum()), 1.0)) / units.MG_TO_MS2
    return AccelEstimate(theta, cov, rms_mg, m, cond)


def _theta_index(i: int, j: int) -> int:
    """Index in θ of E_ij."""
    if i == j:
        return 3 + i
    for k, name in enumerate(model.MISALIGNMENT_NAMES):
        if model.MISALIGNMENT_INDEX[name] == (i, j):
            return 6 + k
    raise AssertionError((i, j))


def _unit_factor(i: int, j: int) -> float:
    """θ units per unit of E_ij: ppm on the diagonal, arcsec off it."""
    return 1.0 / units.PPM if i == j else units.RAD_TO_ARCSEC


def dwell_means(values: FloatArray, dwells: Sequence[Any]) -> tuple[FloatArray, FloatArray]:
    """Mean of ``values`` over each dwell's samples (intervals ``[start, stop)`` are the
    samples ``start+1 … stop``).

    Parameters
    ----------
    values : numpy.ndarray, shape (n, k)
        Samples, in any unit.
    dwells : sequence of Dwell
        The dwells (:class:`.schedule.Dwell`: ``start``, ``stop`` interval indices).

    Returns
    -------
    means : numpy.ndarray, shape (m, k)
        Each dwell's mean, in the unit of ``values``.
    counts : numpy.ndarray, shape (m,)
        Each dwell's number of samples.
    """
    rows = [values[1:][d.start : d.stop] for d in dwells]
    means = np.asarray([r.mean(axis=0) for r in rows], dtype=np.float64)
    return means, np.asarray([r.shape[0] for r in rows], dtype=np.float64)


__all__ = [
    "AccelEstimate",
    "dwell_means",
    "estimate_accel_triad",
    "gravity_in_body",
]
