"""The tumble test of an accelerometer: its output against the angle of a horizontal axis it
is turned about, expanded in harmonics of the angle, and the model coefficients from them.

**The model** (IEEE Std 1293-1998, the model equation of clause 4 and the tumble test of
its test procedures, written here in our own words).  The accelerometer's input axis (IA)
and pendulous axis (PA) lie in the vertical plane; the output axis (OA) is the horizontal
axis of the dividing head.  At the head's angle ``θ`` (θ = 0: IA up, θ = 90°: PA up) gravity
gives, in units of local gravity ``g``, ``a_i = cos θ``, ``a_p = sin θ``, ``a_o = 0``.  The
output [the data's unit] is, to second order::

    y(θ) = K0 + K1 (a_i + δ_o a_p) + K2 a_i² + K_ip a_i a_p + K3 a_i³ + n

with ``K0`` the bias [unit], ``K1`` the scale factor [unit/g], ``δ_o`` the input axis's
misalignment towards the pendulous axis [rad], ``K2`` the second-order coefficient
[unit/g²], ``K_ip`` the cross-coupling of the input and pendulous accelerations [unit/g²]
and ``K3`` the cubic coefficient [unit/g³].  The standard normalises them by ``K1``
(``K2/K1`` in g/g², shown in µg/g²); both are given.

**The harmonics.**  With ``cos²θ = (1 + cos 2θ)/2``, ``sin θ cos θ = sin 2θ / 2`` and
``cos³θ = (3 cos θ + cos 3θ)/4``::

    y(θ) = a0 + a1 cos θ + b1 sin θ + a2 cos 2θ + b2 sin 2θ [+ a3 cos 3θ + b3 sin 3θ]

    a0 = K0 + K2/2,  a1 = K1 + 3 K3/4,  b1 = K1 δ_o,  a2 = K2/2,  b2 = K_ip/2,  a3 = K3/4

so ``K0 = a0 − a2``, ``K1 = a1 − 3 a3``, ``K2 = 2 a2``, ``K_ip = 2 b2``, ``δ_o = b1/K1``,
``K3 = 4 a3`` (``a3 = 0`` with two harmonics: ``K3`` then sits in ``K1``).  A pendulous-axis
square term ``K_pp a_p²`` gives ``(K_pp/2)(1 − cos 2θ)``: one tumble about OA measures
``K2 − K_pp`` and ``K0 + K_pp``; the standard takes ``K_pp`` from a tumble about the
pendulous axis or as negligible (here: negligible, said in the result).

**The fit.**  Least squares of the harmonics on the points ``(θ_k, y_k)`` — the stations'
means weighted by their standard errors, or, turning continuously, every sample with the
noise estimated from the residuals.  Covariance ``(AᵀWA)⁻¹``; with stations, multiplied by
the reduced χ² when it exceeds 1 (the stations scatter beyond their noise: the head's
angle errors, a drift), the Birge ratio's correction.  The coefficients' covariance is
``J Cov J ᵀ`` with ``J`` the linear map above (δ_o to first order).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal.errors import DesignError, ParameterError

FloatArray = npt.NDArray[np.float64]

HARMONICS: Final = 2
"""Harmonics fitted by default (the first and the second: K0, K1, δ_o, K2, K_ip)."""
DISTINCT_DEG: Final = 0.5
"""Two angles closer than this [°] (on the circle) are one angle of the head."""
MAX_COND: Final = 1e3
"""Largest condition number of the column-scaled harmonic design: beyond it, the angles
do not separate the harmonics (all on a short arc)."""


def harmonic_design(theta_deg: npt.ArrayLike, harmonics: int) -> FloatArray:
    """The columns ``1, cos θ, sin θ, …, cos Hθ, sin Hθ`` at the angles ``θ`` [°].

    Parameters
    ----------
    theta_deg : array_like, shape (n,)
        The head's angles [°].
    harmonics : int
        ``H``, the highest harmonic.

    Returns
    -------
    numpy.ndarray, shape (n, 2H + 1)
        The design matrix.

    Examples
    --------
    >>> harmonic_design([0.0, 90.0], 1).round(12).tolist()
    [[1.0, 1.0, 0.0], [1.0, 0.0, 1.0]]
    """
    th = np.radians(np.asarray(theta_deg, dtype=np.float64))
    cols = [np.ones_like(th)]
    for h in range(1, harmonics + 1):
        cols += [np.cos(h * th), np.sin(h * th)]
    return np.column_stack(cols)


def harmonic_names(harmonics: int) -> tuple[str, ...]:
    """``a0, a1, b1, …, aH, bH``: the names of the harmonic coefficients.

    Parameters
    ----------
    harmonics : int
        ``H``.

    Returns
    -------
    tuple of str

    Examples
    --------
    >>> harmonic_names(2)
    ('a0', 'a1', 'b1', 'a2', 'b2')
    """
    return ("a0", *(f"{c}{h}" for h in range(1, harmonics + 1) for c in "ab"))


def distinct_angles(theta_deg: npt.ArrayLike) -> FloatArray:
    """The distinct angles of the head in [0, 360) [°], sorted: angles within
    :data:`DISTINCT_DEG` of one kept (on the circle) are the same.

    Parameters
    ----------
    theta_deg : array_like
        The angles [°].

    Returns
    -------
    numpy.ndarray
        The distinct angles [°].

    Examples
    --------
    >>> distinct_angles([0.0, 359.9, 90.0, 450.2]).tolist()
    [0.0, 90.0]
    """
    th = np.sort(np.mod(np.asarray(theta_deg, dtype=np.float64), 360.0))
    kept: list[float] = []
    for v in th:
        if not kept or v - kept[-1] > DISTINCT_DEG:
            kept.append(float(v))
    if len(kept) > 1 and kept[0] + 360.0 - kept[-1] <= DISTINCT_DEG:
        kept.pop()
    return np.asarray(kept)


def check_angles(theta_deg: npt.ArrayLike, harmonics: int) -> None:
    """Refuse angles that cannot separate ``H`` harmonics: fewer than ``2H + 2`` distinct
    angles (one more than the coefficients, for the noise), or angles on too short an arc
    (the column-scaled design's condition number above :data:`MAX_COND`).

    Parameters
    ----------
    theta_deg : array_like
        The points' angles [°].
    harmonics : int
        ``H``.

    Raises
    ------
    thermocal.errors.DesignError
        Naming what is missing and the option that gets further.
    """
    d = distinct_angles(theta_deg)
    need = 2 * harmonics + 2
    second = "K2 and K_ip (the second harmonic)" if harmonics >= 2 else "the first harmonic"
    if d.size < need:
        raise DesignError.naming(
            f"{d.size} distinct angle(s) of the head: {second} need at least {need} angles "
            f"over the full turn to be separated from the bias and the scale factor with "
            "their uncertainties; tumble through more angles (e.g. 24 stations 15° apart), or "
            "fit fewer {harmonics}",
            "harmonics",
        )
    a = harmonic_design(d, harmonics)
    s = np.linalg.svd(a / np.linalg.norm(a, axis=0), compute_uv=False)
    if not s[-1] > s[0] / MAX_COND:
        gaps = np.diff(np.append(d, d[0] + 360.0))
        raise DesignError.naming(
            f"the {d.size} angles of the head leave a gap of {gaps.max():.0f}° of the turn: "
            f"they cannot separate {second} from the bias and the scale factor; spread the "
            "angles over the full turn, or fit fewer {harmonics}",
            "harmonics",
        )


@dataclass(frozen=True)
class HarmonicFit:
    """The harmonic coefficients of the output against the angle, with their covariance.

    Attributes
    ----------
    harmonics : int
        ``H``.
    coefficients : numpy.ndarray, shape (2H + 1,)
        ``a0, a1, b1, …`` [the output's unit].
    cov : numpy.ndarray, shape (2H + 1, 2H + 1)
        Their covariance.
    residuals : numpy.ndarray
        Each point's output minus the fit [unit].
    reduced_chi2 : float or None
        ``Σ (r/σ)² / dof`` with the points' own σ (None: σ estimated from the residuals).
    dof : int
        Points minus coefficients.
    n_points : int
        Points fitted.
    """

    harmonics: int
    coefficients: FloatArray
    cov: FloatArray
    residuals: FloatArray
    reduced_chi2: float | None
    dof: int
    n_points: int

    @property
    def sigma(self) -> FloatArray:
        """The coefficients' standard uncertainties [unit]."""
        out: FloatArray = np.sqrt(np.maximum(np.diag(self.cov), 0.0))
        return out

    @property
    def residual_rms(self) -> float:
        """RMS of the residuals [unit]."""
        return float(np.sqrt(np.mean(self.residuals**2)))


def fit_harmonics(
    theta_deg: npt.ArrayLike,
    y: npt.ArrayLike,
    sigma: npt.ArrayLike | None = None,
    harmonics: int = HARMONICS,
) -> HarmonicFit:
    """Least-squares harmonics of the output ``y`` against the head's angle ``θ``.

    Parameters
    ----------
    theta_deg : array_like, shape (n,)
        The points' angles [°].
    y : array_like, shape (n,)
        The output at each [unit].
    sigma : array_like, shape (n,), optional
        Each point's standard error [unit] (station means); None: equal weights, the noise
        estimated from the residuals (every sample of a continuous tumble).
    harmonics : int, optional
        ``H`` (1 to 4; default 2).

    Returns
    -------
    HarmonicFit

    Raises
    ------
    thermocal.errors.DesignError
        Angles that cannot separate the harmonics (:func:`check_angles`).
    thermocal.errors.ParameterError
        ``harmonics`` out of range, arrays of different lengths or non-finite, σ ≤ 0.

    Notes
    -----
    Weighted least squares, ``W = diag(1/σ²)``:

    .. math::

        \\hat c = (A^T W A)^{-1} A^T W y, \\qquad
        \\operatorname{Cov} \\hat c = (A^T W A)^{-1} \\max(1, \\chi^2_\\nu)

    with ``A`` the columns of :func:`harmonic_design` (the Fourier series of the tumble
    test's output, IEEE Std 1293-1998 [1]_); without σ, ``σ² = Σ r² / (n − 2H − 1)``.

    References
    ----------
    .. [1] IEEE Std 1293-1998, *IEEE Standard Specification Format Guide and Test
       Procedure for Linear, Single-Axis, Nongyroscopic Accelerometers*, IEEE, 1999.

    Examples
    --------
    >>> th = np.arange(0.0, 360.0, 30.0)
    >>> y = 1.0 + 1000.0 * np.cos(np.radians(th)) + 0.5 * np.cos(np.radians(2 * th))
    >>> c = fit_harmonics(th, y + 1e-3 * np.cos(np.radians(5 * th))).coefficients
    >>> [round(float(v), 6) + 0.0 for v in c]
    [1.0, 1000.0, 0.0, 0.5, 0.0]
    """
    if not 1 <= int(harmonics) <= 4:
        raise ParameterError("harmonics", f"{{name}} must be 1 to 4, got {harmonics!r}")
    th = np.asarray(theta_deg, dtype=np.float64).ravel()
    yy = np.asarray(y, dtype=np.float64).ravel()
    if th.shape != yy.shape or not (np.isfinite(th).all() and np.isfinite(yy).all()):
        raise ParameterError("theta_deg", "{name} and y must be finite and of one length")
    check_angles(th, harmonics)
    a = harmonic_design(th, harmonics)
    p = a.shape[1]
    if sigma is None:
        w = np.ones_like(yy)
    else:
        sg = np.asarray(sigma, dtype=np.float64).ravel()
        if sg.shape != yy.shape or not (np.isfinite(sg).all() and (sg > 0).all()):
            raise ParameterError("sigma", "{name} must be positive, one per point")
        w = 1.0 / sg
    coef, *_ = np.linalg.lstsq(a * w[:, None], yy * w, rcond=None)
    r = yy - a @ coef
    dof = yy.size - p
    inv = np.linalg.inv((a * (w**2)[:, None]).T @ a)
    if sigma is None:
        chi2 = None
        cov = inv * (float(r @ r) / dof)
    else:
        chi2 = float(np.sum((r * w) ** 2)) / dof
        cov = inv * max(1.0, chi2)
    return HarmonicFit(
        int(harmonics), np.asarray(coef, np.float64), cov, r, chi2, dof, int(yy.size)
    )


COEFFICIENTS: Final = ("k0", "k1", "delta_o", "k2", "k_ip", "k3")
"""The model coefficients the tumble test gives (``k3`` with three harmonics or more)."""


@dataclass(frozen=True)
class TumbleCoefficients:
    """The tumble test's model coefficients with their standard uncertainties.

    Attributes
    ----------
    names : tuple of str
        ``k0`` [unit], ``k1`` [unit/g], ``delta_o`` [rad], ``k2``, ``k_ip`` [unit/g²] and,
        with three harmonics or more, ``k3`` [unit/g³].
    values, sigmas : numpy.ndarray
        The values and their standard uncertainties.
    cov : numpy.ndarray
        Their covariance.
    """

    names: tuple[str, ...]
    values: FloatArray
    sigmas: FloatArray
    cov: FloatArray

    def __getitem__(self, name: str) -> tuple[float, float]:
        """``(value, sigma)`` of a coefficient by name."""
        k = self.names.index(name)
        return float(self.values[k]), float(self.sigmas[k])

    def normalised(self) -> dict[str, tuple[float, float]]:
        """``K0/K1`` [g], ``K2/K1`` [g/g²], ``K_ip/K1`` [g/g²] (``K3/K1`` [g/g³]) with their
        standard uncertainties, to first order (IEEE Std 1293's form of the model).

        Returns
        -------
        dict of str to (float, float)
            ``k0_g``, ``k2_g_per_g2``, ``k_ip_g_per_g2`` (``k3_g_per_g3``) → (value, σ).
        """
        i1 = self.names.index("k1")
        k1 = float(self.values[i1])
        out = {}
        for name, key in (("k0", "k0_g"), ("k2", "k2_g_per_g2"), ("k_ip", "k_ip_g_per_g2"),
                          ("k3", "k3_g_per_g3")):  # fmt: skip
            if name not in self.names:
                continue
            i = self.names.index(name)
            v = float(self.values[i])
            grad = np.zeros(len(self.names))
            grad[i], grad[i1] = 1.0 / k1, -v / k1**2
            out[key] = (v / k1, math.sqrt(max(float(grad @ self.cov @ grad), 0.0)))
        return out


def coefficients_from_harmonics(fit: HarmonicFit) -> TumbleCoefficients:
    """``K0, K1, δ_o, K2, K_ip`` (``K3``) from the harmonic coefficients (module docstring).

    Parameters
    ----------
    fit : HarmonicFit
        At least two harmonics.

    Returns
    -------
    TumbleCoefficients

    Raises
    ------
    thermocal.errors.ParameterError
        Fewer than two harmonics (no second-order term).

    Notes
    -----
    .. math::

        K_0 = a_0 - a_2,\\quad K_1 = a_1 - 3 a_3,\\quad \\delta_o = b_1 / K_1,\\quad
        K_2 = 2 a_2,\\quad K_{ip} = 2 b_2,\\quad K_3 = 4 a_3

    from the expansion of the IEEE Std 1293-1998 [1]_ model equation over a tumble about
    the output axis (``K_pp`` taken as negligible).

    References
    ----------
    .. [1] IEEE Std 1293-1998, *IEEE Standard Specification Format Guide and Test
       Procedure for Linear, Single-Axis, Nongyroscopic Accelerometers*, IEEE, 1999.

    Examples
    --------
    >>> th = np.arange(0.0, 360.0, 15.0)
    >>> c, s = np.cos(np.radians(th)), np.sin(np.radians(th))
    >>> y = 2.0 + 1000.0 * c + 0.3 * c**2 + 0.1 * c * s
    >>> k = coefficients_from_harmonics(fit_harmonics(th, y + 1e-4 * np.cos(np.radians(9 * th))))
    >>> [round(k[n][0], 6) for n in ("k0", "k1", "k2", "k_ip")]
    [2.0, 1000.0, 0.3, 0.1]
    """
    if fit.harmonics < 2:
        raise ParameterError("harmonics", "{name}: the second-order terms need 2 harmonics")
    c = fit.coefficients
    a0, a1, b1, a2, b2 = c[0:5]
    a3 = c[5] if fit.harmonics >= 3 else 0.0
    k1 = a1 - 3.0 * a3
    names = COEFFICIENTS if fit.harmonics >= 3 else COEFFICIENTS[:5]
    j = np.zeros((len(names), c.size))
    j[0, 0], j[0, 3] = 1.0, -1.0  # K0 = a0 − a2
    j[1, 1] = 1.0  # K1 = a1 − 3 a3
    j[2, 2], j[2, 1] = 1.0 / k1, -b1 / k1**2  # δ_o = b1 / K1
    j[3, 3] = 2.0  # K2 = 2 a2
    j[4, 4] = 2.0  # K_ip = 2 b2
    values = [a0 - a2, k1, b1 / k1, 2.0 * a2, 2.0 * b2]
    if fit.harmonics >= 3:
        j[1, 5] = -3.0
        j[2, 5] = 3.0 * b1 / k1**2
        j[5, 5] = 4.0
        values.append(4.0 * a3)
    cov = j @ fit.cov @ j.T
    return TumbleCoefficients(
        tuple(names), np.asarray(values), np.sqrt(np.maximum(np.diag(cov), 0.0)), cov
    )


def expected_output(theta_deg: npt.ArrayLike, coefficients: dict[str, float]) -> FloatArray:
    """The model output ``y(θ)`` [unit] of the tumble test (module docstring) at the
    head's angles.

    Parameters
    ----------
    theta_deg : array_like
        The angles [°].
    coefficients : dict of str to float
        ``k0``, ``k1``, ``delta_o``, ``k2``, ``k_ip``, ``k3`` (missing: 0).

    Returns
    -------
    numpy.ndarray
        The output [unit].

    Notes
    -----
    .. math::

        y = K_0 + K_1 (\\cos\\theta + \\delta_o \\sin\\theta) + K_2 \\cos^2\\theta
            + K_{ip} \\sin\\theta\\cos\\theta + K_3 \\cos^3\\theta

    (IEEE Std 1293-1998's model equation with ``a_i = cos θ``, ``a_p = sin θ``).

    Examples
    --------
    >>> expected_output([0.0, 90.0], {"k0": 1.0, "k1": 1000.0, "k2": 0.5}).round(9).tolist()
    [1001.5, 1.0]
    """
    th = np.radians(np.asarray(theta_deg, dtype=np.float64))
    c, s = np.cos(th), np.sin(th)
    k = {n: float(coefficients.get(n, 0.0)) for n in COEFFICIENTS}
    out: FloatArray = (
        k["k0"]
        + k["k1"] * (c + k["delta_o"] * s)
        + k["k2"] * c**2
        + k["k_ip"] * s * c
        + k["k3"] * c**3
    )
    return out


def significant(values: Sequence[float], sigmas: Sequence[float], k: float = 3.0) -> list[bool]:
    """Whether each value lies beyond ``k`` of its standard uncertainties from zero.

    Parameters
    ----------
    values, sigmas : sequence of float
        Values and their standard uncertainties.
    k : float, optional
        Coverage factor (3).

    Returns
    -------
    list of bool

    Examples
    --------
    >>> significant([1.0, 0.1], [0.1, 0.1])
    [True, False]
    """
    return [abs(v) > k * s for v, s in zip(values, sigmas, strict=True)]


def to_dict(fit: HarmonicFit, coefs: TumbleCoefficients) -> dict[str, Any]:
    """The harmonic fit and the coefficients as JSON types.

    Parameters
    ----------
    fit : HarmonicFit
        The harmonics.
    coefs : TumbleCoefficients
        The coefficients.

    Returns
    -------
    dict
    """
    return {
        "harmonics": fit.harmonics,
        "harmonic_names": list(harmonic_names(fit.harmonics)),
        "harmonic_coefficients": fit.coefficients.tolist(),
        "harmonic_sigmas": fit.sigma.tolist(),
        "coefficients": {n: float(v) for n, v in zip(coefs.names, coefs.values, strict=True)},
        "sigmas": {n: float(v) for n, v in zip(coefs.names, coefs.sigmas, strict=True)},
        "normalised": {k: {"value": v, "sigma": s} for k, (v, s) in coefs.normalised().items()},
        "residual_rms": fit.residual_rms,
        "reduced_chi2": fit.reduced_chi2,
        "dof": fit.dof,
        "n_points": fit.n_points,
    }
