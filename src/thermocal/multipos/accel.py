"""Accelerometer triad from the gravity magnitude over unknown poses, or in closed form from
the six faces.

**Gravity magnitude** (Tedaldi et al., ICRA 2014, eq. 9–10).  At rest the specific force
has the magnitude of local gravity ``g`` whatever the pose, so with the pose means
``f_k`` (k = 1…m) the nine parameters ``p = (b, s, m)`` — bias ``b`` [mg], scale-factor
errors ``s`` and the three misalignments ``xy = E[1,0]``, ``xz = E[2,0]``, ``yz = E[2,1]``
of a lower-triangular ``E`` (the accelerometer frame, package docstring) — minimise::

    Σ_k  r_k² ,   r_k = ( | (I + E)⁻¹ (f_k − b) | − g ) / σ_k

(scipy.optimize.least_squares, trust-region reflective, from ``p = 0``).  ``σ_k`` is the
noise of the pose mean along gravity: the white-noise variance of the pose's samples
(from first differences, ``var(Δx)/2``, which a slow tremor hardly touches) over its
sample count.

**A misfit sensor.**  When the reduced χ² exceeds its 3-σ range ``1 + 3·√(2/(m − 9))``
(the poses scatter more than their noise says: tremor, coloured noise, a model that does
not fit), the white-noise weights would let the longest poses pull the fit.  Each pose's
σ is then inflated by a misfit ``τ`` common to all poses, ``σ_k² → σ_k² + τ²``, with ``τ``
such that the reduced χ² of the refitted poses is 1 (the additive-variance estimate of a
random-effects fit, e.g. Paule & Mandel, J. Res. NBS 87 (1982) 377), repeated to a fixed
point: when ``τ ≫ σ_k`` every pose counts alike (imu_tk's unweighted cost).
Covariance ``(JᵀJ)⁻¹`` at the solution (J of the weighted residuals); ``reduced_chi2``
is the one with the white-noise weights, ``misfit_mg`` the ``τ`` added.

**Six faces** (closed form): with gravity along ±each body axis,
``f_{j±} = ±g (I + E) e_j + b``, so ``b = Σ_faces f / 6`` and the column ``j`` of ``I + E``
is ``(f_{j+} − f_{j−}) / 2g``: all nine elements of E, relative to the faces of the box;
variances from the pose means' noise.  Each opposite pair ``(f_{j+} + f_{j−}) / 2`` is an
estimate of ``b``; a face set down a degree off adds ``g·sin`` of it to the other axes, so the
bias variance is at least the three pair estimates' sample variance over 3 (on imucal's
session the noise alone gave a σ sixty times below the pairs' disagreement).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import DesignError
from thermocal.turntable import model

FloatArray = npt.NDArray[np.float64]

FREE_MISALIGNMENTS: Final = ("xy", "xz", "yz")
"""The accelerometer misalignments the gravity magnitude determines (E lower triangular)."""
MIN_POSES: Final = 9
"""Nine parameters from the gravity magnitude: at least nine distinct poses."""
DISTINCT_DEG: Final = 10.0
"""Two poses whose gravity directions are closer than this are the same pose."""


@dataclass(frozen=True)
class AccelFit:
    """θ (12: bias [mg], scale factors [ppm], misalignments [″]), its covariance (12×12;
    zero rows for the constrained misalignments), the gravity-magnitude residual rms of the
    poses before and after [mg], the reduced χ², the method and the number of poses.

    Attributes
    ----------
    theta : numpy.ndarray, shape (12,)
        Bias [mg], scale factors [ppm], misalignments [″].
    cov : numpy.ndarray, shape (12, 12)
        Its covariance.
    residual_rms_before_mg, residual_rms_after_mg : float
        Gravity-magnitude residual rms of the poses [mg].
    reduced_chi2 : float
        Reduced χ² [-].
    method : str
        How it was fitted.
    n_poses : int
        Poses used.
    residuals_mg : tuple of float
        Each pose's gravity-magnitude error after calibration [mg].
    misfit_mg : float
        Misfit τ added in quadrature to each pose's σ [mg].
    """

    theta: FloatArray
    cov: FloatArray
    residual_rms_before_mg: float
    residual_rms_after_mg: float
    reduced_chi2: float
    method: str
    n_poses: int
    residuals_mg: tuple[float, ...]
    """Each pose's gravity-magnitude error after calibration [mg]."""
    misfit_mg: float = 0.0
    """The misfit τ added in quadrature to each pose's σ [mg] (0: the white-noise weights)."""

    @property
    def sigma(self) -> FloatArray:
        out: FloatArray = np.sqrt(np.maximum(np.diag(self.cov), 0.0))
        return out

    @property
    def error_matrix(self) -> FloatArray:
        return model.error_matrices(self.theta)

    def correct(self, f_mg: npt.ArrayLike) -> FloatArray:
        """``(I + E)⁻¹ (f − b)`` [mg] of specific forces (…, 3) [mg].

        Parameters
        ----------
        f_mg : array_like, shape (..., 3)
            Raw specific force [mg].

        Returns
        -------
        numpy.ndarray, shape (..., 3)
            Compensated specific force [mg].
        """
        f = np.asarray(f_mg, dtype=np.float64)
        out = np.linalg.solve(np.eye(3) + self.error_matrix, (f - self.theta[0:3]).T).T
        return np.asarray(out, dtype=np.float64)

    def to_dict(self) -> dict[str, Any]:
        """The fit as plain JSON types: biases [mg], scale-factor errors [ppm] and
        misalignments [″] (:data:`thermocal.turntable.model.MISALIGNMENT_NAMES` order) with
        their σ, the error matrix ``E``, the residuals [mg], the method and the poses."""
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
            "residual_rms_before_mg": self.residual_rms_before_mg,
            "residual_rms_after_mg": self.residual_rms_after_mg,
            "reduced_chi2": self.reduced_chi2,
            "method": self.method,
            "n_poses": self.n_poses,
            "residuals_mg": list(self.residuals_mg),
            "misfit_mg": self.misfit_mg,
        }

    def table(self) -> list[dict[str, Any]]:
        """The twelve coefficients as rows (:func:`thermocal.turntable.model.
        coefficient_rows`, bias in mg)."""
        return model.coefficient_rows(self.theta, self.sigma, "mg", "accel")

    def to_frame(self) -> Any:
        """:meth:`table` as a pandas DataFrame (pandas must be installed)."""
        import pandas

        return pandas.DataFrame(self.table())


def _unpack(p: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(b [mg], E) from the nine free parameters (E entries in 10⁻³)."""
    e = np.zeros((3, 3))
    e[0, 0], e[1, 1], e[2, 2] = p[3] * 1e-3, p[4] * 1e-3, p[5] * 1e-3
    e[1, 0], e[2, 0], e[2, 1] = p[6] * 1e-3, p[7] * 1e-3, p[8] * 1e-3
    return p[0:3], e


FREE_INDEX: Final = (0, 1, 2, 3, 4, 5, 8, 10, 11)
"""Indices in θ of the nine free parameters (bias, scale factors, xy, xz, yz)."""
_FREE_FACTOR = np.array([1.0, 1.0, 1.0] + [1e-3 / units.PPM] * 3 + [1e-3 * units.RAD_TO_ARCSEC] * 3)
"""θ units per unit of the free parameters (mg; 10⁻³ → ppm; 10⁻³ rad → ″)."""


def distinct_directions(f_mg: FloatArray) -> list[FloatArray]:
    """The unit gravity directions of the poses ``f_mg`` (n, 3) [mg], each more than
    :data:`DISTINCT_DEG` from those kept before it (in pose order).

    Parameters
    ----------
    f_mg : numpy.ndarray, shape (n, 3)
        The poses' mean specific force [mg].

    Returns
    -------
    list of numpy.ndarray, shape (3,)
        The distinct unit directions.

    Examples
    --------
    >>> f = np.array([[0, 0, 1000.0], [0, 1.0, 1000.0], [1000.0, 0, 0]])
    >>> len(distinct_directions(f))
    2
    """
    u = f_mg / np.linalg.norm(f_mg, axis=1)[:, None]
    distinct: list[FloatArray] = []
    for v in u:
        if all(float(v @ d) < math.cos(math.radians(DISTINCT_DEG)) for d in distinct):
            distinct.append(v)
    return distinct


def _six_faces_hint(u: FloatArray) -> str:
    """Where the distinct directions are the six faces (each within ``DISTINCT_DEG`` of a
    body axis, up and down), the advice that uses them: a POSES file naming them (``{poses}``
    where the parameter goes)."""
    if len(u) != 6:
        return ""
    near = np.abs(u).max(axis=1) > math.cos(math.radians(DISTINCT_DEG))
    faces = {(int(np.argmax(np.abs(v))), bool(v[np.argmax(np.abs(v))] > 0)) for v in u}
    if not near.all() or len(faces) != 6:
        return ""
    return (
        ", or, as they are the six faces (each body axis up and down), name them in a "
        "{poses} file (x_p, x_a, y_p, y_a, z_p, z_a: imucal's section list) for Ferraris's "
        "six-face closed form"
    )


def check_poses(f_mg: FloatArray) -> None:
    """Refuse poses that cannot determine the nine parameters: fewer than nine distinct
    gravity directions, or directions all near one plane (a scale factor or a bias along
    the plane's normal is then unseen).

    Parameters
    ----------
    f_mg : numpy.ndarray, shape (n, 3)
        The poses' mean specific force [mg].

    Raises
    ------
    thermocal.errors.DesignError
        Too few distinct directions, or all near one plane.
    """
    distinct = distinct_directions(f_mg)
    if len(distinct) < MIN_POSES:
        raise DesignError.naming(
            f"{len(distinct)} distinct poses (gravity directions more than {DISTINCT_DEG:g}° "
            f"apart) of {len(f_mg)}: the accelerometer's bias, scale factors and misalignments "
            f"need at least {MIN_POSES}; place the board in more orientations"
            + _six_faces_hint(np.asarray(distinct)),
            "poses",
        )
    w, v = np.linalg.eigh(np.asarray(distinct).T @ np.asarray(distinct) / len(distinct))
    if w[0] < 0.02:
        n = v[:, 0]
        raise DesignError(
            "the poses' gravity directions all lie near one plane (normal "
            f"{n[0]:+.2f}, {n[1]:+.2f}, {n[2]:+.2f} in body axes): tilt the board out of it "
            "so that gravity also has a component along that normal"
        )


MISFIT_ITERATIONS: Final = 20
"""Refits at most, while the misfit τ moves by more than 10⁻⁶ of itself."""


def _solve(f: FloatArray, sg: FloatArray, g_mg: float, p0: FloatArray) -> Any:
    """Least squares of the weighted gravity-magnitude residuals (module docstring)."""
    from scipy.optimize import least_squares

    def resid(p: FloatArray) -> FloatArray:
        b, e = _unpack(p)
        c = np.linalg.solve(np.eye(3) + e, (f - b).T).T
        out: FloatArray = (np.linalg.norm(c, axis=1) - g_mg) / sg
        return out

    return least_squares(resid, p0, method="trf", x_scale="jac", xtol=1e-12, ftol=1e-12,
                         gtol=1e-12)  # fmt: skip


def misfit_tau(r_mg: FloatArray, sigma_mg: FloatArray, dof: int) -> float:
    """``τ ≥ 0`` [mg] with ``Σ r_k²/(σ_k² + τ²) = dof`` (0 when already below): the root of
    a decreasing function, by bisection on ``τ²`` in ``[0, Σ r²/dof]``.

    Parameters
    ----------
    r_mg : numpy.ndarray
        Residuals [mg].
    sigma_mg : numpy.ndarray
        Their σ [mg].
    dof : int
        Degrees of freedom.

    Returns
    -------
    float
        τ [mg].

    Notes
    -----
    .. math:: \\sum_k \\frac{r_k^2}{\\sigma_k^2 + \\tau^2} = \\mathrm{dof}

    Examples
    --------
    >>> round(misfit_tau(np.full(4, 5.0), np.full(4, 3.0), 4), 3)  # √(25 − 9)
    4.0
    """
    r2 = r_mg**2
    s2 = sigma_mg**2

    def h(t2: float) -> float:
        return float(np.sum(r2 / (s2 + t2))) - dof

    if dof <= 0 or h(0.0) <= 0:
        return 0.0
    lo, hi = 0.0, float(r2.sum()) / dof
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if h(mid) > 0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-12 * hi:
            break
    return math.sqrt(0.5 * (lo + hi))


def fit_gravity_magnitude(f_mg: npt.ArrayLike, sigma_mg: npt.ArrayLike, g_mg: float) -> AccelFit:
    """The accelerometer triad's nine free parameters from the gravity magnitude.

    Parameters
    ----------
    f_mg : array_like, shape (m, 3)
        The mean specific force of each still pose [mg], at least nine distinct poses.
    sigma_mg : array_like, shape (m,)
        The noise of each pose mean along gravity [mg].
    g_mg : float
        Local gravity [mg].

    Returns
    -------
    AccelFit
        θ (12: bias [mg], scale factors [ppm], misalignments [″]; ``yx = zx = zy = 0``, the
        body frame being the accelerometer frame), its covariance and the residuals.

    Raises
    ------
    thermocal.errors.DesignError
        Fewer than nine distinct poses (:func:`check_poses`).

    Notes
    -----
    Weighted least squares (Tedaldi et al. 2014 [1]_, eqs. 9-10) on

    .. math::

        r_k = \\frac{\\lVert (I + E)^{-1} (\\bar f_k - b) \\rVert - g}
        {\\sqrt{\\sigma_k^2 + \\tau^2}}

    with ``τ`` a misfit added in quadrature when the reduced χ² is beyond its 3σ band
    (the poses scatter beyond their noise: a hand's placement, a board's flex).

    References
    ----------
    .. [1] D. Tedaldi, A. Pretto and E. Menegatti, "A robust and easy to implement method
       for IMU calibration without external equipments", Proc. IEEE ICRA 2014,
       pp. 3042-3049, doi:10.1109/ICRA.2014.6907297.
    """
    f = np.asarray(f_mg, dtype=np.float64)
    sg0 = np.asarray(sigma_mg, dtype=np.float64)
    m = f.shape[0]
    check_poses(f)
    dof = m - 9
    sol = _solve(f, sg0, g_mg, np.zeros(9))
    r0 = np.asarray(sol.fun)
    chi2 = float(r0 @ r0) / dof if dof > 0 else float("nan")
    tau = 0.0
    sg = sg0
    if dof > 0 and chi2 > 1.0 + 3.0 * math.sqrt(2.0 / dof):
        for _ in range(MISFIT_ITERATIONS):
            new = misfit_tau(np.asarray(sol.fun) * sg, sg0, dof)
            sg = np.sqrt(sg0**2 + new**2)
            sol = _solve(f, sg, g_mg, sol.x)
            done = abs(new - tau) <= 1e-6 * new
            tau = new
            if done:
                break
    jac = np.asarray(sol.jac)
    _u, s_, vt = np.linalg.svd(jac, full_matrices=False)
    if not s_[-1] > 1e-10 * s_[0]:
        raise DesignError(
            "the poses cannot separate the accelerometer's bias, scale factors and "
            "misalignments (singular design): add poses in other orientations"
        )
    cov_p = (vt.T / s_**2) @ vt
    r = np.asarray(sol.fun)
    theta = np.zeros(12)
    cov = np.zeros((12, 12))
    idx = np.array(FREE_INDEX)
    theta[idx] = sol.x * _FREE_FACTOR
    cov[np.ix_(idx, idx)] = cov_p * np.outer(_FREE_FACTOR, _FREE_FACTOR)
    before = np.linalg.norm(f, axis=1) - g_mg
    after = r * sg
    return AccelFit(
        theta,
        cov,
        float(np.sqrt(np.mean(before**2))),
        float(np.sqrt(np.mean(after**2))),
        chi2,
        "gravity-magnitude",
        m,
        tuple(float(v) for v in after),
        tau,
    )


FACE_MAX_DEG: Final = 30.0
"""A face of the six-face form reads gravity within this angle [°] of the axis its name
puts up (a board laid on a face by hand sits within a few degrees of it)."""


def _check_faces(f: dict[str, FloatArray], faces: Sequence[str]) -> None:
    """Refuse faces whose mean specific force ``f`` [mg] is more than :data:`FACE_MAX_DEG`
    from the axis their name puts up (``x_p``: +x, ``x_a``: −x …): the closed form would
    turn any six means into a calibration (a POSES file of another session gave a residual
    of 4090 g)."""
    bad = []
    for n in faces:
        up = np.zeros(3)
        up["xyz".index(n[0])] = 1.0 if n.endswith("_p") else -1.0
        u = f[n] / np.linalg.norm(f[n])
        ang = math.degrees(math.acos(max(-1.0, min(1.0, float(u @ up)))))
        if ang > FACE_MAX_DEG:
            bad.append(f"'{n}' {ang:.0f}° off {'+' if up.sum() > 0 else '−'}{n[0]}")
    if bad:
        raise DesignError(
            f"{len(bad)} of the six faces do not read gravity along the axis their name puts "
            f"up (more than {FACE_MAX_DEG:g}°): {', '.join(bad)}"
        )


def fit_six_faces(
    faces_mg: dict[str, FloatArray], sigma_mg: dict[str, float], g_mg: float
) -> AccelFit:
    """The accelerometer triad in closed form from the six named faces.

    Parameters
    ----------
    faces_mg : dict of str to array_like
        ``x_p`` … ``z_a`` (that axis up, then down) → the face's mean specific force (3,)
        [mg].
    sigma_mg : dict of str to float
        Each face → the per-axis noise of its mean [mg].
    g_mg : float
        Local gravity [mg].

    Returns
    -------
    AccelFit
        θ (12: bias [mg], scale factors [ppm], misalignments [″], all six: ``E`` refers
        to the faces of the box), its covariance and each face's gravity residual.

    Raises
    ------
    thermocal.errors.DesignError
        A face missing, or a face whose gravity is not along the axis its name says.

    Notes
    -----
    Ferraris et al. (1995) [1]_: the bias is the mean of the six faces and column ``j`` of
    ``I + E`` half the difference of the faces ``j+`` and ``j−`` over ``g``:

    .. math::

        b = \\frac{1}{6} \\sum_{\\text{faces}} \\bar f, \\qquad
        (I + E)\\, e_j = \\frac{\\bar f_{j+} - \\bar f_{j-}}{2 g}

    References
    ----------
    .. [1] F. Ferraris, U. Grimaldi and M. Parvis, "Procedure for effortless in-field
       calibration of three-axis rate gyros and accelerometers", Sensors and Materials
       7(5), 1995, pp. 311-330.

    Examples
    --------
    >>> import numpy as np
    >>> k = np.diag([1.01, 0.99, 1.0])  # +1 % x, -1 % y scale factors
    >>> faces = {f"{a}_{s}": k @ (sg * 1000.0 * np.eye(3)[i])
    ...          for i, a in enumerate("xyz") for s, sg in (("p", 1), ("a", -1))}
    >>> fit = fit_six_faces(faces, dict.fromkeys(faces, 0.1), 1000.0)
    >>> [round(float(v)) for v in fit.theta[3:6]]
    [10000, -10000, 0]
    """
    from thermocal.multipos.poses import FACES

    missing = [n for n in FACES if n not in faces_mg]
    if missing:
        raise DesignError(f"the six-face calibration needs every face; missing {missing}")
    f = {k: np.asarray(v, dtype=np.float64) for k, v in faces_mg.items()}
    _check_faces(f, FACES)
    b = sum((f[n] for n in FACES), np.zeros(3)) / 6.0
    pairs = np.array([(f[f"{ax}_p"] + f[f"{ax}_a"]) / 2.0 for ax in "xyz"])
    var_b = np.maximum(  # the noise's, or the three pair estimates' scatter (placement)
        sum(sigma_mg[n] ** 2 for n in FACES) / 36.0, np.var(pairs, axis=0, ddof=1) / 3.0
    )
    ie = np.zeros((3, 3))
    var_e = np.zeros(3)
    for j, ax in enumerate("xyz"):
        ie[:, j] = (f[f"{ax}_p"] - f[f"{ax}_a"]) / (2.0 * g_mg)
        var_e[j] = (sigma_mg[f"{ax}_p"] ** 2 + sigma_mg[f"{ax}_a"] ** 2) / (2.0 * g_mg) ** 2
    e = ie - np.eye(3)
    theta = model.coeffs_from_error_matrix(e, b)
    sig = np.zeros(12)
    sig[0:3] = np.sqrt(var_b)
    sig[3:6] = np.sqrt(var_e) / units.PPM
    for k, n in enumerate(model.MISALIGNMENT_NAMES):
        sig[6 + k] = math.sqrt(var_e[model.MISALIGNMENT_INDEX[n][1]]) * units.RAD_TO_ARCSEC
    fs = np.asarray([f[n] for n in FACES])
    before = np.linalg.norm(fs, axis=1) - g_mg
    after = np.linalg.norm(np.linalg.solve(ie, (fs - b).T).T, axis=1) - g_mg
    return AccelFit(
        theta,
        np.diag(sig**2),
        float(np.sqrt(np.mean(before**2))),
        float(np.sqrt(np.mean(after**2))),
        float("nan"),
        "six-face",
        6,
        tuple(float(v) for v in after),
    )


def to_dict(fit: AccelFit) -> dict[str, Any]:
    """An accelerometer fit as a JSON-ready dict.

    Parameters
    ----------
    fit : AccelFit
        The fit (:func:`fit_accel`, :func:`fit_six_faces`).

    Returns
    -------
    dict
        ``method``, the biases [mg], scale factors [ppm] and misalignments [″], each with
        its σ.
    """
    s = fit.sigma
    return {
        "method": fit.method,
        "bias_mg": fit.theta[0:3].tolist(),
        "scale_factor_ppm": fit.theta[3:6].tolist(),
        "misalignment_arcsec": fit.theta[6:12].tolist(),
        "bias_mg_sigma": s[0:3].tolist(),
        "scale_factor_ppm_sigma": s[3:6].tolist(),
        "misalignment_arcsec_sigma": s[6:12].tolist(),
    }


__all__ = [
    "FREE_INDEX",
    "MISFIT_ITERATIONS",
    "AccelFit",
    "check_poses",
    "distinct_directions",
    "fit_gravity_magnitude",
    "fit_six_faces",
    "misfit_tau",
]
