"""Rotation helpers of the multi-position calibration: Rodrigues' formula, skew matrices and
the attitude along a rate record by a parallel prefix product (pure numpy)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


def skew(v: npt.ArrayLike) -> FloatArray:
    """``[v×]`` (…, 3, 3) of vectors (…, 3): ``[v×] w = v × w``.

    Parameters
    ----------
    v : array_like, shape (..., 3)
        Vectors [any unit].

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Skew-symmetric matrices [same unit].

    Examples
    --------
    >>> (skew([1.0, 2.0, 3.0]) @ [4.0, 5.0, 6.0]).tolist()  # = (1, 2, 3) × (4, 5, 6)
    [-3.0, 6.0, -3.0]
    """
    a = np.asarray(v, dtype=np.float64)
    out = np.zeros((*a.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -a[..., 2], a[..., 1]
    out[..., 1, 0], out[..., 1, 2] = a[..., 2], -a[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -a[..., 1], a[..., 0]
    return out


def rotvec_to_matrix(phi: npt.ArrayLike) -> FloatArray:
    """``exp([φ×])`` (…, 3, 3) by Rodrigues' formula
    ``I + sin θ/θ [φ×] + (1 − cos θ)/θ² [φ×]²``, θ = |φ| [rad] (series below 1e-4 rad).

    Parameters
    ----------
    phi : array_like, shape (..., 3)
        Rotation vectors [rad].

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Rotation matrices.

    Notes
    -----
    .. math:: R = I + \\frac{\\sin\\theta}{\\theta} [\\varphi\\times]
              + \\frac{1 - \\cos\\theta}{\\theta^2} [\\varphi\\times]^2

    Examples
    --------
    >>> (rotvec_to_matrix([0.0, 0.0, np.pi / 2]) @ [1.0, 0.0, 0.0]).round(3).tolist()
    [0.0, 1.0, 0.0]
    """
    p = np.asarray(phi, dtype=np.float64)
    th2 = np.sum(p * p, axis=-1)
    th = np.sqrt(th2)
    small = th < 1e-4
    safe = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(safe)) / np.where(small, 1.0, th2))
    k = skew(p)
    out: FloatArray = np.eye(3) + a[..., None, None] * k + b[..., None, None] * (k @ k)
    return out


def matrix_to_rotvec(r: npt.ArrayLike) -> FloatArray:
    """Rotation vector (…, 3) [rad] of rotation matrices (angle < π − 1e-6).

    Parameters
    ----------
    r : array_like, shape (..., 3, 3)
        Rotation matrices.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Rotation vectors [rad] (inverse of :func:`rotvec_to_matrix`).

    Examples
    --------
    >>> matrix_to_rotvec(rotvec_to_matrix([0.1, -0.2, 0.3])).round(6).tolist()
    [0.1, -0.2, 0.3]
    """
    m = np.asarray(r, dtype=np.float64)
    c = np.clip((np.trace(m, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    th = np.arccos(c)
    w = np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                  m[..., 1, 0] - m[..., 0, 1]], axis=-1)  # fmt: skip
    s = np.sin(th)
    f = np.where(th < 1e-8, 0.5, th / (2.0 * np.where(th < 1e-8, 1.0, s)))
    out: FloatArray = w * f[..., None]
    return out


def attitude_along(rate_rad_s: npt.ArrayLike, dt_s: npt.ArrayLike) -> FloatArray:
    """``D_i = Π_{s<i} exp([ω_s τ_s ×])`` (n, 3, 3): the body attitude at sample i relative
    to the body at sample 0 (``D_0 = I``), the rate sample ω_s [rad/s] held over the interval
    τ_s [s] to the next sample (``dC/dt = C [ω×]``).  The products are formed by doubling
    (Hillis–Steele scan: log₂ n vectorised steps instead of n matrix products).

    Parameters
    ----------
    rate_rad_s : array_like, shape (n, 3)
        Body rates [rad/s].
    dt_s : array_like, shape (n,) or (n − 1,)
        Intervals to the next sample [s].

    Returns
    -------
    numpy.ndarray, shape (n, 3, 3)
        D_i, body at sample i → body at sample 0.

    Examples
    --------
    >>> w = np.tile([0.0, 0.0, np.pi / 2], (11, 1))  # 90 °/s about z for 1 s
    >>> d = attitude_along(w, np.full(11, 0.1))
    >>> [round(float(v), 3) + 0.0 for v in d[-1] @ [1.0, 0.0, 0.0]]
    [0.0, 1.0, 0.0]
    """
    w = np.asarray(rate_rad_s, dtype=np.float64)
    dt = np.asarray(dt_s, dtype=np.float64)
    n = w.shape[0]
    out = np.empty((n, 3, 3))
    out[0] = np.eye(3)
    if n == 1:
        return out
    p = rotvec_to_matrix(w[:-1] * dt[: n - 1, None])
    s = 1
    while s < p.shape[0]:
        p[s:] = p[:-s] @ p[s:]
        s *= 2
    out[1:] = p
    return out


__all__ = ["attitude_along", "matrix_to_rotvec", "rotvec_to_matrix", "skew"]
