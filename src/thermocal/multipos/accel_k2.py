"""The accelerometer's second-order coefficients K2 (one per axis) from the gravity magnitude
of a multi-position session, beside the bias, scale factors and misalignments of
:func:`thermocal.multipos.accel.fit_gravity_magnitude`.

**The model.**  Each axis reads, besides the linear model of :mod:`.accel`, a term in the
square of the specific force along it (IEEE Std 1293-1998's model equation, ``K2 a_i²``,
written for the triad in our own words)::

    f = (I + E) a + b + K2 ⊙ (a / g)²        (f, a, b in mg; K2 in mg/g², one per axis)

with ``a`` the true specific force in the accelerometer frame and ``g`` local gravity.  At
rest ``|a| = g`` whatever the pose; ``a`` is recovered from ``f`` by the fixed point
``a ← (I + E)⁻¹ (f − b − K2 ⊙ (a/g)²)`` (K2 ≪ g: three steps reach the double's
precision), and the twelve parameters minimise ``Σ_k ((|a_k| − g)/σ_k)²`` as the nine do
(the misfit τ of :mod:`.accel` added when the poses scatter beyond their noise).

**What the poses must hold.**  The gravity-magnitude residual sees the bias of axis ``j``
through ``u_j``, its scale factor through ``u_j²`` and its K2 through ``u_j³`` (``u`` the
unit gravity direction of a pose).  On the six faces ``u_j`` is −1, 0 or +1, so
``u_j³ = u_j``: K2 and the bias are one and the same column.  Only poses that put gravity
at a slant to an axis (``|u_j|`` between :data:`SLANT` bounds: 45° gives 0.71) tell them
apart; each axis needs :data:`MIN_SLANTED` of them.

**What the gravity magnitude cannot give: the cross-axis terms.**  A term ``K_ji a_j a_i``
in axis ``j``'s output reaches the residual as ``u_j² u_i``; on the sphere
``u_i³ + u_j² u_i + u_k² u_i = u_i``, so the bias of ``i``, its K2 and the cross terms
into it are one column.  (An 18-parameter fit on 40 random poses gave every second-order
term a σ of 13–20 mg/g², against 0.03 mg/g² for K2 alone.)  They need known attitudes: the
tumble test (:mod:`thermocal.tumble`) gives one axis's K_ip.  A real cross-axis term left
out leaks into the same axis's K2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal.errors import DesignError
from thermocal.multipos import accel as _accel

FloatArray = npt.NDArray[np.float64]

SLANT: Final = (0.2, 0.95)
"""A pose sees an axis at a slant when ``|u_j|`` lies in this range (12° to 78° off it)."""
MIN_SLANTED: Final = 3
"""Poses at a slant each axis needs for its K2 to be told from its bias."""
MIN_POSES_K2: Final = 12
"""Twelve parameters: at least twelve distinct poses."""
FIXED_POINT_STEPS: Final = 3
"""Steps of the fixed point that recovers the true specific force."""
NEWTON_STEPS: Final = 3
"""Newton steps of :func:`invert_k2` (compensation and the generated C): from the linear
solution, three reach 1e-15 relative for ``|K2| ≤ 0.01 g/g²`` and ``|a| ≤ 4 g`` (1e-11 at
16 g; measured on 20 000 random forces)."""


@dataclass(frozen=True)
class AccelK2Fit:
    """The accelerometer's twelve parameters with K2.

    Attributes
    ----------
    linear : AccelFit
        Bias [mg], scale factors [ppm], misalignments [″] of the fit with K2 (the nine free,
        as :func:`thermocal.multipos.accel.fit_gravity_magnitude` gives them), their
        covariance and residuals.
    k2_mg_per_g2 : numpy.ndarray, shape (3,)
        K2 of x, y, z [mg/g²].
    k2_sigma : numpy.ndarray, shape (3,)
        Their standard uncertainties [mg/g²].
    g_mg : float
        Local gravity [mg].
    """

    linear: _accel.AccelFit
    k2_mg_per_g2: FloatArray
    k2_sigma: FloatArray
    g_mg: float

    def correct(self, f_mg: npt.ArrayLike) -> FloatArray:
        """The true specific force ``a`` [mg] of raw readings ``f`` (…, 3) [mg] (module
        docstring's fixed point).

        Parameters
        ----------
        f_mg : array_like, shape (..., 3)
            Raw specific force [mg].

        Returns
        -------
        numpy.ndarray, shape (..., 3)
        """
        f = np.asarray(f_mg, dtype=np.float64)
        return _invert(f, self.linear.theta[0:3], self.linear.error_matrix,
                       self.k2_mg_per_g2, self.g_mg)  # fmt: skip

    def to_dict(self, to_unit: float = 1.0, unit: str = "mg") -> dict[str, Any]:
        """K2 per axis in the accelerometer's unit per g² and the fit's residuals.

        Parameters
        ----------
        to_unit : float, optional
            The accelerometer's unit per mg.
        unit : str, optional
            That unit's name.

        Returns
        -------
        dict
            ``k2``, ``k2_sigma`` [unit/g²], ``unit``, ``significant`` (beyond 3σ),
            ``residual_rms_after`` [unit], ``reduced_chi2``, ``misfit`` (the τ added to each
            pose's σ, 0 without) [unit], ``n_poses``, and the linear
            parameters fitted with it (``bias``, ``scale_factor_ppm``,
            ``misalignment_arcsec`` with their σ).
        """
        lin = self.linear
        s = lin.sigma
        return {
            "k2": (self.k2_mg_per_g2 * to_unit).tolist(),
            "k2_sigma": (self.k2_sigma * to_unit).tolist(),
            "unit": f"{unit}/g^2",
            "significant": [bool(abs(v) > 3 * e) for v, e in
                            zip(self.k2_mg_per_g2, self.k2_sigma, strict=True)],
            "residual_rms_after": lin.residual_rms_after_mg * to_unit,
            "reduced_chi2": lin.reduced_chi2,
            "misfit": lin.misfit_mg * to_unit,
            "n_poses": lin.n_poses,
            "bias": (lin.theta[0:3] * to_unit).tolist(),
            "bias_sigma": (s[0:3] * to_unit).tolist(),
            "scale_factor_ppm": lin.theta[3:6].tolist(),
            "scale_factor_ppm_sigma": s[3:6].tolist(),
            "misalignment_arcsec": lin.theta[6:12].tolist(),
            "misalignment_arcsec_sigma": s[6:12].tolist(),
        }  # fmt: skip


def _invert(f: FloatArray, b: FloatArray, e: FloatArray, k2: FloatArray, g: float) -> FloatArray:
    """``a`` with ``f = (I + E) a + b + K2 ⊙ (a/g)²`` by the fixed point."""
    m = np.eye(3) + e
    a = np.linalg.solve(m, (f - b).T).T
    for _ in range(FIXED_POINT_STEPS):
        a = np.linalg.solve(m, (f - b - k2 * (a / g) ** 2).T).T
    return np.asarray(a, dtype=np.float64)


def invert_k2(y: npt.ArrayLike, m: npt.ArrayLike, k2: npt.ArrayLike, g: float) -> FloatArray:
    """The true specific force ``a`` of each sample from ``y = M a + K2 ⊙ (a/g)²`` by
    Newton's method (:data:`NEWTON_STEPS` steps from the linear solution ``M⁻¹ y``).

    Parameters
    ----------
    y : array_like, shape (n, 3)
        The reading less the bias, ``x − b(T)`` [any unit U].
    m : array_like, shape (n, 3, 3) or (3, 3)
        ``I + E(T)`` per sample, or one for all [1].
    k2 : array_like, shape (3,)
        Each axis's second-order coefficient [U per g²].
    g : float
        One g in U (9.80665 m/s², 1000 mg, 1 g).

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        ``a`` [U].

    Notes
    -----
    Newton's iteration on ``F(a) = M a + K2 ⊙ (a/g)² − y``:

    .. math::

        a_{k+1} = a_k - \\left(M + 2\\,\\mathrm{diag}(K_2 \\odot a_k) / g^2\\right)^{-1}
        \\left(M a_k + K_2 \\odot (a_k / g)^2 - y\\right)

    The error squares each step: with ``|K2| ≤ 0.01 g/g²`` the linear start is 1e-2
    relative off, one step 1e-6, two 1e-12 (model of IEEE Std 1293-1998 [1]_).

    References
    ----------
    .. [1] IEEE Std 1293-1998, *IEEE Standard Specification Format Guide and Test
       Procedure for Linear, Single-Axis, Nongyroscopic Accelerometers*, IEEE, 1999.

    Examples
    --------
    >>> invert_k2([[1.01, 0.0, 0.0]], np.eye(3), [0.01, 0.0, 0.0], 1.0).round(12).tolist()
    [[1.0, 0.0, 0.0]]
    """
    yy = np.asarray(y, dtype=np.float64)
    mm = np.broadcast_to(np.asarray(m, dtype=np.float64), (yy.shape[0], 3, 3))
    kk = np.asarray(k2, dtype=np.float64)
    a = np.linalg.solve(mm, yy[..., None])[..., 0]
    for _ in range(NEWTON_STEPS):
        resid = (mm @ a[..., None])[..., 0] + kk * (a / g) ** 2 - yy
        jac = mm.copy()
        idx = np.arange(3)
        jac[:, idx, idx] += 2.0 * kk * a / g**2
        a = a - np.linalg.solve(jac, resid[..., None])[..., 0]
    return np.asarray(a, dtype=np.float64)


def check_k2_poses(f_mg: npt.ArrayLike) -> None:
    """Refuse poses that cannot tell each axis's K2 from its bias: fewer than
    :data:`MIN_POSES_K2` distinct poses, or an axis seen at a slant by fewer than
    :data:`MIN_SLANTED` of them (module docstring: on the six faces ``u³ = u``).

    Parameters
    ----------
    f_mg : array_like, shape (m, 3)
        The poses' mean specific force [mg].

    Raises
    ------
    thermocal.errors.DesignError
        Naming the axes and what to add.

    Examples
    --------
    >>> faces = np.vstack([np.eye(3), -np.eye(3)]) * 1000.0
    >>> check_k2_poses(np.vstack([faces, faces]))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    thermocal.errors.DesignError: 6 distinct poses: ...
    """
    f = np.asarray(f_mg, dtype=np.float64)
    u = np.asarray(_accel.distinct_directions(f))
    if len(u) < MIN_POSES_K2:
        raise DesignError.naming(
            f"{len(u)} distinct poses: the accelerometer's K2 with its bias, scale factors and "
            f"misalignments needs at least {MIN_POSES_K2}, among them poses at a slant to every "
            "axis (the six faces cannot separate K2 from the bias: ±1 g gives the same g²); "
            "add poses at 45° (each axis half-way between up and level), or leave out "
            "{accel_k2}",
            "accel_k2",
        )
    au = np.abs(u)
    slanted = ((au > SLANT[0]) & (au < SLANT[1])).sum(axis=0)
    short = [f"{'xyz'[j]} ({int(slanted[j])})" for j in range(3) if slanted[j] < MIN_SLANTED]
    if short:
        raise DesignError.naming(
            f"the poses see the axes {', '.join(short)} at a slant fewer than {MIN_SLANTED} "
            "times (gravity only along or across them, as on the six faces): their K2 cannot "
            "be told from the bias; add poses at 45° to those axes, or leave out {accel_k2}",
            "accel_k2",
        )


def _solve(f: FloatArray, sg: FloatArray, g: float, p0: FloatArray) -> Any:
    """Least squares of the weighted gravity-magnitude residuals with K2 (p[9:12], mg/g²)."""
    from scipy.optimize import least_squares

    def resid(p: FloatArray) -> FloatArray:
        b, e = _accel._unpack(p[:9])
        a = _invert(f, b, e, p[9:12], g)
        out: FloatArray = (np.linalg.norm(a, axis=1) - g) / sg
        return out

    return least_squares(resid, p0, method="trf", x_scale="jac", xtol=1e-12, ftol=1e-12,
                         gtol=1e-12)  # fmt: skip


def fit_k2(f_mg: npt.ArrayLike, sigma_mg: npt.ArrayLike, g_mg: float) -> AccelK2Fit:
    """The accelerometer's bias, scale factors, misalignments and K2 per axis from the
    gravity magnitude of still poses.

    Parameters
    ----------
    f_mg : array_like, shape (m, 3)
        The mean specific force of each still pose [mg].
    sigma_mg : array_like, shape (m,)
        The noise of each pose mean along gravity [mg].
    g_mg : float
        Local gravity [mg].

    Returns
    -------
    AccelK2Fit

    Raises
    ------
    thermocal.errors.DesignError
        Poses that cannot separate K2 (:func:`check_k2_poses`), or a singular design.

    Notes
    -----
    Weighted least squares (Tedaldi et al. 2014 [1]_, eqs. 9-10, with the second-order
    term of IEEE Std 1293-1998 [2]_):

    .. math::

        r_k = \\frac{\\lVert a_k \\rVert - g}{\\sqrt{\\sigma_k^2 + \\tau^2}}, \\qquad
        \\bar f_k = (I + E)\\, a_k + b + K_2 \\odot (a_k / g)^2

    Covariance ``(JᵀJ)⁻¹`` of the weighted residuals at the solution.

    References
    ----------
    .. [1] D. Tedaldi, A. Pretto and E. Menegatti, "A robust and easy to implement method
       for IMU calibration without external equipments", Proc. IEEE ICRA 2014,
       pp. 3042-3049, doi:10.1109/ICRA.2014.6907297.
    .. [2] IEEE Std 1293-1998, *IEEE Standard Specification Format Guide and Test
       Procedure for Linear, Single-Axis, Nongyroscopic Accelerometers*, IEEE, 1999.
    """
    f = np.asarray(f_mg, dtype=np.float64)
    sg0 = np.asarray(sigma_mg, dtype=np.float64)
    check_k2_poses(f)
    _accel.check_poses(f)
    m = f.shape[0]
    dof = m - 12
    sol = _solve(f, sg0, g_mg, np.zeros(12))
    r0 = np.asarray(sol.fun)
    chi2 = float(r0 @ r0) / dof if dof > 0 else float("nan")
    sg, tau = sg0, 0.0
    if dof > 0 and chi2 > 1.0 + 3.0 * math.sqrt(2.0 / dof):
        for _ in range(_accel.MISFIT_ITERATIONS):
            new = _accel.misfit_tau(np.asarray(sol.fun) * sg, sg0, dof)
            sg = np.sqrt(sg0**2 + new**2)
            sol = _solve(f, sg, g_mg, sol.x)
            done = abs(new - tau) <= 1e-6 * new
            tau = new
            if done:
                break
    _u, s_, vt = np.linalg.svd(np.asarray(sol.jac), full_matrices=False)
    if not s_[-1] > 1e-10 * s_[0]:
        raise DesignError.naming(
            "the poses cannot separate the accelerometer's K2 from its bias and scale "
            "factors (singular design): add poses at 45° to every axis, or leave out "
            "{accel_k2}",
            "accel_k2",
        )
    cov_p = (vt.T / s_**2) @ vt
    idx = np.array(_accel.FREE_INDEX)
    factor = _accel._FREE_FACTOR
    theta, cov = np.zeros(12), np.zeros((12, 12))
    theta[idx] = sol.x[:9] * factor
    cov[np.ix_(idx, idx)] = cov_p[:9, :9] * np.outer(factor, factor)
    after = np.asarray(sol.fun) * sg
    before = np.linalg.norm(f, axis=1) - g_mg
    lin = _accel.AccelFit(
        theta, cov, float(np.sqrt(np.mean(before**2))), float(np.sqrt(np.mean(after**2))),
        chi2, "gravity-magnitude with K2", m, tuple(float(v) for v in after), tau,
    )  # fmt: skip
    return AccelK2Fit(
        lin, np.asarray(sol.x[9:12], dtype=np.float64), np.sqrt(np.diag(cov_p)[9:12]), g_mg
    )


__all__ = [
    "MIN_POSES_K2",
    "MIN_SLANTED",
    "NEWTON_STEPS",
    "AccelK2Fit",
    "check_k2_poses",
    "fit_k2",
    "invert_k2",
]
