"""Gyro triad from the rotations between static poses (and from known 360° turns).

**Bias**: the sample-weighted mean of the static poses' rates, minus, with the latitude
L, the vertical earth rate ``Ω sin L · u_k`` along each pose's (calibrated) up direction
``u_k``.  The horizontal earth rate's direction in the board is not known (the heading of
a hand-placed pose is not measured): it is left in the bias and counted in its σ, as
independent unknown headings, ``Σ_k w_k² (Ω cos L)² (1 − u_ki²)/2`` per axis (without L,
``Σ_k w_k² Ω²/3``), with the white noise ``σ_i²/N``.

**Scale factors and misalignments** (the nine elements of ``E_g``; the idea of Tedaldi et
al., ICRA 2014, §III-C, with every element of E free).  Gravity is fixed in the local
frame, so between the mean attitudes of consecutive poses k and k+1 the calibrated
gravity directions satisfy ``u_{k+1} = A_{k+1}ᵀ A_k⁻ᵀ u_k``, where
``A = mean_{window} D(t)`` and ``D(t) = Π exp([ω_c τ×])`` is the attitude integrated from
the start of pose k with the calibrated rate ``ω_c = (I + E_g)⁻¹ (ω − b_g)``
(:func:`.geometry.attitude_along`; averaging D over each pose matches the pose's mean
specific force even when the board trembles).  The residual
``r = u_{k+1} − A_{k+1}ᵀ A_k⁻ᵀ u_k`` of every motion is minimised over ``E_g`` by
Gauss–Newton: a perturbation ``δE`` turns the total rotation R by
``ε = −Rᵀ Σ_t D(t) δE ω_c(t) τ``, so ``∂r/∂E_ij = [p×] Rᵀ Σ_t D(t) e_i ω_cj(t) τ`` with
``p = A_{k+1}ᵀ A_k⁻ᵀ u_k``; the attitude is integrated again at each iteration.

**Models** (:data:`GYRO_MODELS`): ``full`` fits the nine elements; ``scale`` the three
scale factors, the misalignments held at 0, when the motions cannot carry nine
(:func:`too_few_motions`: fewer redundant rows than elements and a misfit beyond the
noise; a hand-held MPU-6050 session of tomisuarez2/ImuCalibration, 6 usable motions at
χ² ≈ 700, gives 7.0° on its held-out 90° turn with nine, 0.90° with three).

Each motion's residual lies in the plane normal to ``u_{k+1}`` and has there, per
component, the variance ``c_k σ_u,k² + c_k+1 σ_u,k+1² + σ_ω² τ T_eff + V_Ω``: the
direction noise of the two pose means (``σ_u = σ_f/g``, the pose mean's noise across
gravity; ``c = 1`` for a pose the gravity-magnitude fit does not use across gravity,
``c = 1/3`` for a face of the six-face closed form, whose calibrated direction keeps only
``(f_j+ + f_j−)/2 − b``, of variance ``σ_f²/3`` and uncorrelated with ``b`` and E: the rest
of the pose's noise *is* the accelerometer's calibration error, counted once below), the
angle random walk over ``T_eff = T_motion + (T_k + T_{k+1})/3`` and the earth's turn of
gravity against inertial space over the span ``T = T_motion + (T_k + T_{k+1})/2``, about
the north axis whose heading in the board is unknown: ``V_Ω = (Ω cos L T)²/2`` (without
L, ``(Ω T)²/3``: an earth axis of unknown direction); the vertical earth rate only turns
the board about gravity and leaves ``u`` alone.  The covariance ``(JᵀJ)⁻¹`` of the
whitened problem (scaled by a significant reduced χ², as :mod:`.accel`) is widened by
the propagated uncertainties of the gyro bias and of the accelerometer calibration that
defines ``u`` (``K G C Gᵀ Kᵀ``, ``K = (JᵀJ)⁻¹Jᵀ``).  Rotations all about one axis leave
``E_g``'s other columns unseen: refused.

**360° turns** (Ferraris, Gorini, Grimaldi and Parvis 1994, *Sensors and Actuators A* 42,
doi:10.1016/0924-4247(94)80031-6; Ferraris et al. 1995; imucal's ``x_rot``, ``y_rot``,
``z_rot``): a turn
named about the sensor's axis ``e_j`` (j = x, y, z, whatever pose came before it: users
do the turns after the six faces) adds
``Σ ω_c τ − 2π s e_j − Ω sin L T u = 0``, three linear rows of the same least squares
(``s = ±1`` the sense, the sign of ``Σ ω_c τ · e_j``; ``u`` the calibrated up direction
during the turn, along which the vertical earth rate over its duration T is known from
the latitude).  The axis is the calibrated frame's, as in Ferraris's and imucal's
``W_s = (I + E_g) (±360°) I`` (imucal ``K_g R_g = I + E_g``).  The 3×3 covariance is
``σ_ω² τ T I + (2π σ_a)² (I − e_j e_jᵀ) + (Ω cos L T ρ)²/2 (I − u uᵀ)``: angle random
walk, the direction noise ``σ_a`` of the axis (across it only: a hand turns the board
about the vertical of the face it lies on, ``e_j`` to within that face's direction noise
``σ_u``; without the face, the accelerometer calibration's σ of the misalignments of
column j) and the horizontal earth rate, which turns with the board and integrates to
``Ω cos L T ρ`` in an unknown horizontal direction, with ``ρ = |mean_t exp(i ψ(t))|`` from
the turn's own heading ``ψ(t) = ∫ ω_c·u dt`` (0 for a uniform full turn); without L,
``(Ω T)²/3 I`` for the whole earth rate.  The rows are whitened by ``C^(−1/2)``.
A hand's turn leans off its axis: the lean's variance, found in the data when the
turns disagree with the motions (:func:`_turn_axis_scatter`), is added to the turns'
covariance.  Before any fit a turn is judged by :func:`check_turn`: its rotation vector (raw rate,
bias removed) within :data:`TURN_AXIS_TOLERANCE_DEG` of its named axis and its angle
within :data:`TURN_ANGLE_TOLERANCE` of 360°, else refused.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import DesignError, ThermocalInputError
from thermocal.multipos.geometry import attitude_along, skew
from thermocal.multipos.poses import Section
from thermocal.turntable import model

FloatArray = npt.NDArray[np.float64]


GAP_FACTOR: float = 1.5
"""An interval above this many median intervals is a gap in time: no motion is
integrated across it, no turn may hold one."""
TURN_ANGLE_TOLERANCE: float = 0.10
"""A named turn's angle (raw rate, bias removed) may differ from 360° by this fraction;
more (a quarter turn, two turns, a wrong gyro unit) is refused (:func:`check_turn`).
It bounds the scale factor a turn can give to ±10 %."""
GYRO_MODELS: dict[str, tuple[int, ...]] = {"full": tuple(range(9)), "scale": (0, 4, 8)}
"""The elements of ``E_g`` (row-major) each gyro model fits: ``full`` all nine (three
scale factors, six misalignments), ``scale`` the three scale factors only, the
misalignments held at 0 (the gyro's axes taken as the accelerometer's calibrated axes:
one chip, one die), for sessions whose motions cannot carry nine (:func:`too_few_motions`)."""
TURN_AXIS_TOLERANCE_DEG: float = 15.0
"""A named turn's rotation vector may be this far [°] from its named axis (consumer
gyro misalignments and a hand's wobble are a few degrees); more is refused: a turn named
``x_rot`` that turns about y (:func:`check_turn`)."""


@dataclass(frozen=True)
class Turn:
    """A named 360° turn (module docstring): its ``section``, the sensor axis it is named
    about (``axis`` 0, 1, 2 for ``x_rot``, ``y_rot``, ``z_rot``), the calibrated unit up
    direction during it ``up`` (body axes: the vertical earth rate) and the direction
    noise ``axis_sigma_rad`` [rad] of the axis across itself.

    Attributes
    ----------
    section : Section
        The turn's samples.
    axis : int
        0, 1, 2 for ``x_rot``, ``y_rot``, ``z_rot``.
    up : numpy.ndarray, shape (3,)
        The calibrated unit up direction during it (body axes).
    axis_sigma_rad : float
        Direction noise of the axis across itself [rad].
    """

    section: Section
    axis: int
    up: FloatArray
    axis_sigma_rad: float


def turn_intervals(dt_s: FloatArray, section: Section, dt_med: float) -> FloatArray:
    """τ [s] of a turn's samples: their forward intervals, the last one the median
    interval ``dt_med`` when a gap follows the turn (sections recorded apart, imucal's
    annotated sessions); a gap inside a turn is refused before (:func:`turn_gap`).

    Parameters
    ----------
    dt_s : numpy.ndarray, shape (n,)
        Sample intervals [s].
    section : Section
        The turn's samples.
    dt_med : float
        The median interval [s].

    Returns
    -------
    numpy.ndarray
        τ of each of the turn's samples [s].
    """
    tau: FloatArray = dt_s[section.start : section.end].copy()
    if tau.size and tau[-1] > GAP_FACTOR * dt_med:
        tau[-1] = dt_med
    return tau


def turn_gap(dt_s: FloatArray, section: Section, dt_med: float) -> tuple[int, float] | None:
    """The first gap in time inside a turn (interval above ``GAP_FACTOR × dt_med``): the
    sample before it and its length [s]; None without one.

    Parameters
    ----------
    dt_s : numpy.ndarray, shape (n,)
        Sample intervals [s].
    section : Section
        The turn's samples.
    dt_med : float
        The median interval [s].

    Returns
    -------
    tuple of (int, float) or None
        Index of the sample before the gap and the gap's length [s].
    """
    inside = dt_s[section.start : section.end - 1]
    big = np.flatnonzero(inside > GAP_FACTOR * dt_med)
    return None if big.size == 0 else (section.start + int(big[0]), float(inside[big[0]]))


def turn_rotation(
    rate_rad_s: FloatArray, dt_s: FloatArray, bias_rad_s: FloatArray, section: Section
) -> FloatArray:
    """The rotation vector of a turn: ``Σ (ω − b) τ`` over its samples.

    The raw rate with the bias removed, integrated as Ferraris et al. (1995,
    doi:10.1016/0924-4247(94)00969-1) integrate a turn (imucal's ``W_s``, its eq. 13–14).

    Parameters
    ----------
    rate_rad_s : ndarray, shape (n, 3)
        Gyro rate [rad/s].
    dt_s : ndarray, shape (n,)
        Each sample's forward interval [s] (τ: :func:`turn_intervals`).
    bias_rad_s : ndarray, shape (3,)
        Gyro bias b [rad/s].
    section : Section
        The turn's samples.

    Returns
    -------
    ndarray, shape (3,)
        The rotation vector [rad], in the gyro's own axes.
    """
    sl = slice(section.start, section.end)
    tau = turn_intervals(dt_s, section, float(np.median(dt_s)))
    out: FloatArray = ((rate_rad_s[sl] - bias_rad_s) * tau[:, None]).sum(axis=0)
    return out


def check_turn(
    rotation_rad: FloatArray, name: str, axis: int, where: str, source: str = "the POSES file"
) -> None:
    """Refuse a named turn that is not one full turn about its named axis.

    Ferraris et al. (1995) turn the board once about each sensor axis: the rotation
    vector ``v`` (:func:`turn_rotation`) must lie within :data:`TURN_AXIS_TOLERANCE_DEG`
    of ``±e_axis`` (``acos(|v_axis| / |v|)``) and its angle ``|v|`` within
    :data:`TURN_ANGLE_TOLERANCE` of 2π.

    Parameters
    ----------
    rotation_rad : ndarray, shape (3,)
        The turn's rotation vector [rad].
    name : str
        The section's name (``x_rot`` …).
    axis : int
        The axis it names (0, 1, 2).
    where : str
        The file and section, for the message.
    source : str
        The file that named the section (the remedy).

    Raises
    ------
    ThermocalInputError
        One line with the measured rotation vector and what to fix.
    """
    v = np.asarray(rotation_rad, dtype=np.float64)
    ang = float(np.linalg.norm(v))
    ax = "xyz"[axis]
    deg = np.degrees(v)
    shown = f"rotation vector ({deg[0]:+.1f}°, {deg[1]:+.1f}°, {deg[2]:+.1f}°) bias removed"
    off = math.degrees(math.acos(min(1.0, abs(float(v[axis])) / ang))) if ang > 0 else 90.0
    if off > TURN_AXIS_TOLERANCE_DEG:
        most = "xyz"[int(np.argmax(np.abs(v)))]
        raise ThermocalInputError.naming(
            f"{where}: the gyro turns {math.degrees(ang):.1f}° mostly about {most} "
            f"({shown}), {off:.1f}° from the sensor's {ax} axis that {name!r} names, "
            f"which must hold one full turn about {ax}: fix the section's name or its "
            f"start and end in {source} (or the order of the {{gyro}} columns)",
            "gyro",
        )
    if abs(ang / (2.0 * math.pi) - 1.0) > TURN_ANGLE_TOLERANCE:
        raise ThermocalInputError.naming(
            f"{where}: the gyro turns {math.degrees(ang):.1f}° about {ax} ({shown}), not "
            f"one full turn (360° ± {TURN_ANGLE_TOLERANCE:.0%}): fix the section's start "
            f"and end in {source} to hold exactly one turn, or the gyro's unit "
            "({gyro_unit}, {gyro_scale})",
            *("gyro_unit", "gyro_scale"),
        )


@dataclass(frozen=True)
class GyroFit:
    """θ (12: bias [°/h], scale factors [ppm], misalignments [″]) and its covariance, the
    rms of the motions' gravity-direction residuals before (raw rate, bias removed) and
    after calibration [rad], the reduced χ² and the number of motions and turns used, and
    the turns' axis lean found in the data [rad] (sd per component, 0 when not
    significant: :func:`_turn_axis_scatter`).

    Attributes
    ----------
    theta : numpy.ndarray, shape (12,)
        Bias [°/h], scale factors [ppm], misalignments [″].
    cov : numpy.ndarray, shape (12, 12)
        Its covariance.
    direction_rms_before_rad, direction_rms_after_rad : float
        Rms of the motions' gravity-direction residuals [rad].
    reduced_chi2 : float
        Reduced χ² [-].
    n_motions, n_turns : int
        Motions and turns used.
    turn_axis_lean_rad : float
        The turns' axis lean found in the data [rad].
    model : str
        ``full`` or ``scale``.
    """

    theta: FloatArray
    cov: FloatArray
    direction_rms_before_rad: float
    direction_rms_after_rad: float
    reduced_chi2: float
    n_motions: int
    n_turns: int
    turn_axis_lean_rad: float = 0.0
    model: str = "full"

    @property
    def dof(self) -> int:
        """The fit's degrees of freedom: two per motion (the residual lies across
        gravity), three per turn, less the elements of E the model fits."""
        return 2 * self.n_motions + 3 * self.n_turns - len(GYRO_MODELS[self.model])

    @property
    def sigma(self) -> FloatArray:
        out: FloatArray = np.sqrt(np.maximum(np.diag(self.cov), 0.0))
        return out

    @property
    def error_matrix(self) -> FloatArray:
        """``E`` of ``ω_meas = (I + E) ω + b`` (3×3, dimensionless)."""
        return model.error_matrices(self.theta)

    def to_dict(self) -> dict[str, Any]:
        """The fit as plain JSON types: biases [°/h], scale-factor errors [ppm] and
        misalignments [″] (:data:`thermocal.turntable.model.MISALIGNMENT_NAMES` order) with
        their σ, the error matrix ``E``, the direction residuals [°] and what was used."""
        s = self.sigma
        return {
            "bias_deg_h": self.theta[0:3].tolist(),
            "bias_deg_h_sigma": s[0:3].tolist(),
            "scale_factor_ppm": self.theta[3:6].tolist(),
            "scale_factor_ppm_sigma": s[3:6].tolist(),
            "misalignment_arcsec": self.theta[6:12].tolist(),
            "misalignment_arcsec_sigma": s[6:12].tolist(),
            "misalignment_names": list(model.MISALIGNMENT_NAMES),
            "error_matrix": self.error_matrix.tolist(),
            "direction_rms_before_deg": math.degrees(self.direction_rms_before_rad),
            "direction_rms_after_deg": math.degrees(self.direction_rms_after_rad),
            "reduced_chi2": self.reduced_chi2,
            "n_motions": self.n_motions,
            "n_turns": self.n_turns,
            "turn_axis_lean_deg": math.degrees(self.turn_axis_lean_rad),
            "model": self.model,
        }

    def table(self) -> list[dict[str, Any]]:
        """The twelve coefficients as rows (:func:`thermocal.turntable.model.
        coefficient_rows`, bias in °/h)."""
        return model.coefficient_rows(self.theta, self.sigma, "deg/h", "gyro")

    def to_frame(self) -> Any:
        """:meth:`table` as a pandas DataFrame (pandas must be installed)."""
        import pandas

        return pandas.DataFrame(self.table())


def static_bias(
    rate_means_rad_s: FloatArray,
    n_samples: FloatArray,
    rate_sigma_rad_s: FloatArray,
    up: FloatArray,
    latitude_deg: float | None,
) -> tuple[FloatArray, FloatArray]:
    """Gyro bias [rad/s] and its covariance from the static poses (module docstring):
    ``rate_means`` (m, 3), ``n_samples`` (m,), per-sample white noise σ (3,), ``up`` (m, 3)
    unit up directions in body axes.

    Parameters
    ----------
    rate_means_rad_s : numpy.ndarray, shape (m, 3)
        Mean rate of each static pose [rad/s].
    n_samples : numpy.ndarray, shape (m,)
        Samples per pose.
    rate_sigma_rad_s : numpy.ndarray, shape (3,)
        Per-sample white-noise σ [rad/s].
    up : numpy.ndarray, shape (m, 3)
        Unit up direction of each pose in body axes.
    latitude_deg : float or None
        Latitude [°] for the earth rate's vertical component; None: not removed.

    Returns
    -------
    bias, cov : numpy.ndarray
        Bias (3,) [rad/s] and its covariance (3, 3) [rad²/s²].

    References
    ----------
    - F. Ferraris, U. Grimaldi and M. Parvis, "Procedure for effortless in-field
      calibration of three-axis rate gyros and accelerometers", *Sensors and Materials*
      7(5), 311–330, 1995.
    """
    w = n_samples / n_samples.sum()
    om = units.EARTH_RATE_RAD_S
    b = (w[:, None] * rate_means_rad_s).sum(axis=0)
    if latitude_deg is not None:
        sl = math.sin(math.radians(latitude_deg))
        b = b - om * sl * (w[:, None] * up).sum(axis=0)
    var_e = (w[:, None] ** 2 * unmeasured_earth_rate_var(up, latitude_deg)).sum(axis=0)
    var = rate_sigma_rad_s**2 / n_samples.sum() + var_e
    return b, np.diag(var)


def unmeasured_earth_rate_var(up: FloatArray, latitude_deg: float | None) -> FloatArray:
    r"""The variance the earth rate leaves in each static pose's mean rate, per axis
    [rad²/s²], when the pose's heading is not measured (module docstring).

    Parameters
    ----------
    up : numpy.ndarray, shape (m, 3)
        Unit up direction of each pose in body axes.
    latitude_deg : float or None
        Latitude [°]: the vertical earth rate is known (and taken off by the caller), the
        horizontal one of unknown heading counted; None: the whole earth rate, of unknown
        direction.

    Returns
    -------
    numpy.ndarray, shape (m, 3)

    Notes
    -----
    .. math:: (\Omega \cos L)^2 (1 - u_{ki}^2) / 2 \quad \text{or, without } L, \quad
              \Omega^2 / 3
    """
    om = units.EARTH_RATE_RAD_S
    if latitude_deg is None:
        return np.full(np.shape(up), om**2 / 3.0)
    cl = math.cos(math.radians(latitude_deg))
    out: FloatArray = (om * cl) ** 2 * (1.0 - up**2) / 2.0
    return out


@dataclass(frozen=True)
class _Motion:
    start: int
    k_end: int  # samples of pose k: [start, k_end)
    k1_start: int  # samples of pose k+1: [k1_start, stop)
    stop: int
    var: float  # residual variance per component [rad²]
    pose_k: int
    pose_k1: int


def _direction(u0: FloatArray, a0: FloatArray, a1: FloatArray) -> FloatArray:
    out: FloatArray = a1.T @ np.linalg.solve(a0.T, u0)
    return out


_Held = tuple[list[tuple[FloatArray, FloatArray]], list[tuple[FloatArray, FloatArray, FloatArray]]]
"""The attitudes at each motion's ends and each turn's (integrated rate, expected rotation
vector [rad], whitening matrix)."""


def _motions(
    dt_s: FloatArray,
    poses: Sequence[Section],
    dt_med: float,
    dir_sigma_rad: FloatArray,
    rate_sigma_rad_s: float,
    latitude_deg: float | None,
) -> list[_Motion]:
    """The motions between consecutive poses not split by a gap in time, each with the
    variance of its residual per component across gravity [rad²] (module docstring): the
    two poses' direction noise, the rate noise integrated over ``T_m + (T_k + T_k+1)/3``
    and the earth's turn of gravity over ``T = T_m + (T_k + T_k+1)/2``,
    ``(Ω cos L T)²/2`` (``(Ω T)²/3`` without L)."""
    om = units.EARTH_RATE_RAD_S
    if latitude_deg is None:
        earth_per_s2 = om**2 / 3.0
    else:
        earth_per_s2 = (om * math.cos(math.radians(latitude_deg))) ** 2 / 2.0
    motions: list[_Motion] = []
    for k in range(len(poses) - 1):
        p0, p1 = poses[k], poses[k + 1]
        if np.any(dt_s[p0.start : p1.end - 1] > GAP_FACTOR * dt_med):
            continue  # a gap in time: the rotation across it is unknown
        t_k, t_k1 = p0.n * dt_med, p1.n * dt_med
        t_m = (p1.start - p0.end) * dt_med
        t_eff = t_m + (t_k + t_k1) / 3.0
        t_span = t_m + (t_k + t_k1) / 2.0
        var = (dir_sigma_rad[k] ** 2 + dir_sigma_rad[k + 1] ** 2
               + rate_sigma_rad_s**2 * dt_med * t_eff + earth_per_s2 * t_span**2)  # fmt: skip
        motions.append(_Motion(p0.start, p0.end, p1.start, p1.end, var, k, k + 1))
    return motions


def unsaturated(motions: list[_Motion], saturated: npt.NDArray[np.bool_] | None) -> list[_Motion]:
    """The motions with no sample on the gyro's rails between pose k's start and pose
    k+1's end (``saturated`` per sample, None: none): the rotation across a clipped rate is
    unknown, as across a gap in time.

    Parameters
    ----------
    motions : list of _Motion
        The motions between poses.
    saturated : numpy.ndarray of bool, shape (n,), optional
        Per sample, a rate on the rails.

    Returns
    -------
    list of _Motion
        The motions with no saturated sample.
    """
    if saturated is None:
        return motions
    return [m for m in motions if not np.any(saturated[m.start : m.stop])]


@dataclass(frozen=True, eq=False)
class _Rotations:
    """The whitened residuals of the rotation fit (module docstring) and their Jacobians."""

    rate_rad_s: FloatArray
    dt_s: FloatArray
    dt_med: float
    motions: list[_Motion]
    turns: Sequence[Turn]
    rate_sigma_rad_s: float
    latitude_deg: float | None
    tilt_var: float = 0.0
    """τ²: the variance [rad²] of a turn's axis lean off ``e_j`` per component beyond the
    face's noise (:func:`_turn_axis_scatter`)."""
    free: tuple[int, ...] = tuple(range(9))
    """The elements of E fitted (row-major, :data:`GYRO_MODELS`); the others stay 0."""

    @property
    def n_rows(self) -> int:
        return 3 * len(self.motions) + 3 * len(self.turns)

    def across_rows(self) -> FloatArray:
        """Indices of the turns' across-axis rows (the whitening is diagonal in body axes:
        row ``axis`` of a turn's three is along it, the other two across)."""
        n_m = 3 * len(self.motions)
        out = [n_m + 3 * t_i + k for t_i, tn in enumerate(self.turns) for k in range(3)
               if k != tn.axis]  # fmt: skip
        return np.asarray(out, dtype=np.int64)

    def evaluate(
        self, e: FloatArray, b: FloatArray, u: FloatArray, jac: bool
    ) -> tuple[FloatArray, FloatArray, FloatArray, _Held]:
        """Residuals r, ∂r/∂E (row-major), ∂r/∂b and the attitudes held, for the error
        matrix ``e``, the bias ``b`` [rad/s] and the poses' up directions ``u``."""
        rate_rad_s, dt_s, dt_med = self.rate_rad_s, self.dt_s, self.dt_med
        motions, turns = self.motions, self.turns
        n_rows = self.n_rows
        ie_inv = np.linalg.inv(np.eye(3) + e)
        r = np.empty(n_rows)
        j = np.zeros((n_rows, 9))
        jb = np.zeros((n_rows, 3))
        atts: list[tuple[FloatArray, FloatArray]] = []
        turn_info: list[tuple[FloatArray, FloatArray, FloatArray]] = []
        for m_i, mo in enumerate(motions):
            sl = slice(mo.start, mo.stop)
            wc = (rate_rad_s[sl] - b) @ ie_inv.T
            d = attitude_along(wc, dt_s[sl])
            a0 = d[: mo.k_end - mo.start].mean(axis=0)
            a1 = d[mo.k1_start - mo.start :].mean(axis=0)
            atts.append((a0, a1))
            p = _direction(u[mo.pose_k], a0, a1)
            s = 1.0 / math.sqrt(mo.var)
            r[3 * m_i : 3 * m_i + 3] = (u[mo.pose_k1] - p) * s
            if jac:
                rot = a1 @ np.linalg.inv(a0)
                tau = dt_s[sl][:, None]
                sij = np.einsum("tai,tj->aij", d, wc * tau).reshape(3, 9)
                px = skew(p) @ rot.T
                j[3 * m_i : 3 * m_i + 3] = px @ sij * s
                jb[3 * m_i : 3 * m_i + 3] = px @ d.sum(axis=0) * dt_med * s
        for t_i, tn in enumerate(turns):
            sl = slice(tn.section.start, tn.section.end)
            wc = (rate_rad_s[sl] - b) @ ie_inv.T
            tau = turn_intervals(dt_s, tn.section, dt_med)[:, None]
            tot = (wc * tau).sum(axis=0)
            sense = 1.0 if float(tot[tn.axis]) >= 0 else -1.0
            t_turn = tn.section.n * dt_med
            vert, w_mat = self._turn_whitening(wc, tau, tn, t_turn)
            row = slice(3 * len(motions) + 3 * t_i, 3 * len(motions) + 3 * t_i + 3)
            want = 2.0 * math.pi * sense * np.eye(3)[tn.axis] + vert * tn.up
            r[row] = w_mat @ (tot - want)
            turn_info.append((tot, want, w_mat))
            if jac:
                # ∂/∂E_ij of Σ (I+E)⁻¹ ω' τ ≈ −e_i Σ ω_cj τ ; ∂/∂b ≈ −T I
                colsum = (wc * tau).sum(axis=0)
                jt = np.zeros((3, 9))
                for i in range(3):
                    jt[i, 3 * i : 3 * i + 3] = -colsum
                j[row] = w_mat @ jt
                jb[row] = -w_mat * t_turn
        return r, j, jb, (atts, turn_info)

    def _turn_whitening(
        self, wc: FloatArray, tau: FloatArray, tn: Turn, t_turn: float
    ) -> tuple[float, FloatArray]:
        """The vertical earth rate's angle over a turn [rad] and ``C^(−1/2)`` of the turn's
        residual covariance (module docstring), along and across the named axis (the
        horizontal earth rate, across ``up``, counted across the axis: ``up`` is the axis
        of a turn on a level table)."""
        om = units.EARTH_RATE_RAD_S
        along = self.rate_sigma_rad_s**2 * self.dt_med * t_turn
        lean = (2 * math.pi) ** 2 * self.tilt_var
        across = along + (2 * math.pi * tn.axis_sigma_rad) ** 2 + lean
        along += 2.0 * (2 * math.pi * self.tilt_var) ** 2
        if self.latitude_deg is None:
            vert = 0.0
            along += (om * t_turn) ** 2 / 3.0
            across += (om * t_turn) ** 2 / 3.0
        else:
            lat = math.radians(self.latitude_deg)
            vert = om * math.sin(lat) * t_turn
            psi = np.cumsum((wc @ tn.up) * tau[:, 0])
            rho = abs(complex(np.mean(np.exp(1j * psi))))
            across += (om * math.cos(lat) * t_turn * rho) ** 2 / 2.0
        uu = np.outer(np.eye(3)[tn.axis], np.eye(3)[tn.axis])
        return vert, uu / math.sqrt(along) + (np.eye(3) - uu) / math.sqrt(across)


_SCALE = 1e-3
"""Column scale of the Gauss-Newton steps in E (its elements are ~1e-3)."""


def _solve_error_matrix(
    rot: _Rotations, bias_rad_s: FloatArray, up: FloatArray, max_iter: int
) -> FloatArray:
    """Gauss-Newton on E from E = 0 until the largest step is below 1e-10."""
    e = np.zeros((3, 3))
    free = list(rot.free)
    for _ in range(max_iter):
        r, j, _jb, _atts = rot.evaluate(e, bias_rad_s, up, jac=True)
        step, *_ = np.linalg.lstsq(j[:, free] * _SCALE, -r, rcond=None)
        full = np.zeros(9)
        full[free] = step
        e = e + (full * _SCALE).reshape(3, 3)
        if float(np.max(np.abs(step * _SCALE))) < 1e-10:
            break
    return e


def _turn_axis_scatter(
    rot: _Rotations, e: FloatArray, bias_rad_s: FloatArray, up: FloatArray, max_iter: int
) -> tuple[_Rotations, FloatArray]:
    """The turns' axis lean by Helmert's variance-component estimate (Koch, *Parameter
    Estimation and Hypothesis Testing in Linear Models*, 1999, §3.6): a hand's turn
    wobbles, its axis leans off ``e_j`` by more than the face's noise, and the
    misalignments would take that lean as theirs with the turns' small σ.  The lean, of
    variance τ² per component, adds ``(2π)² τ²`` across the axis and ``2 (2π τ²)²`` along
    it (``2π (1 − cos θ)`` ≈ ``π θ²``: mean and sd ``2π τ²``).  With the redundancy of the
    across rows ``r_a = n_a − tr(H_aa)`` (``H`` the hat matrix of the whitened fit) and
    ``f = e_aᵀe_a / r_a``, ``τ² ← τ² + (f − 1) C_a / (2π)²`` (``C_a`` the rows' mean
    across variance) and E is fitted again, until f settles (at most 8 times), when the
    first f exceeds ``1 + 3√(2/r_a)``; the motions then hold what the turns cannot."""
    rows = rot.across_rows()
    if rows.size == 0 or not rot.motions:
        return rot, e
    for it in range(8):
        r, j, _jb, (_a, turn_info) = rot.evaluate(e, bias_rad_s, up, jac=True)
        u_, s_, _vt = np.linalg.svd(j[:, list(rot.free)], full_matrices=False)
        keep = s_ > 1e-12 * s_[0]
        hat = np.sum(u_[:, keep] ** 2, axis=1)
        red = float(rows.size - hat[rows].sum())
        if red < 0.05:
            break
        f = float(r[rows] @ r[rows]) / red
        if (it == 0 and f <= 1.0 + 3.0 * math.sqrt(2.0 / red)) or abs(f - 1.0) < 0.01:
            break
        across = float(np.mean([1.0 / float(np.min(np.diag(w))) ** 2 for *_x, w in turn_info]))
        tau2 = rot.tilt_var + (f - 1.0) * across / (2 * math.pi) ** 2
        rot = replace(rot, tilt_var=max(0.0, tau2))
        e = _solve_error_matrix(rot, bias_rad_s, up, max_iter)
    return rot, e


def _error_matrix_cov(
    rot: _Rotations,
    r: FloatArray,
    j: FloatArray,
    jb: FloatArray,
    held: _Held,
    up_of: Callable[[FloatArray], FloatArray],
    accel_free: FloatArray,
    accel_free_cov: FloatArray,
    bias_cov: FloatArray,
) -> tuple[FloatArray, float]:
    """Covariance of E's nine elements (row-major) and the reduced χ²::

        C_E = (JᵀJ)⁻¹ [· χ²/ν when significant] + K (J_b C_b J_bᵀ + G C_a Gᵀ) Kᵀ

    with ``K = (JᵀJ)⁻¹Jᵀ`` of the whitened fit (never scaled: it is the map from the
    rows to E), ``J_b`` the rows' derivative by the gyro bias (covariance ``C_b``) and
    ``G`` by the accelerometer's free parameters (``C_a``, numerical derivative, the
    attitudes held).  The reduced χ² is that of the residuals against their whole
    covariance ``I + J_b C_b J_bᵀ + G C_a Gᵀ`` (a bias error known to be there is not
    taken for unmodelled scatter and counted a second time); ``(JᵀJ)⁻¹`` is scaled by it
    only when above ``1 + 3√(2/ν)``."""
    free = list(rot.free)
    _u, s_, vt = np.linalg.svd(j[:, free] * _SCALE, full_matrices=False)
    if not s_[-1] > 1e-6 * s_[0]:
        raise DesignError(
            "the rotations between poses are all about one axis (or too small): the gyro's "
            "scale factors and misalignments of the other axes are unseen; turn the board "
            "about at least two different axes between poses"
        )
    cov0 = np.zeros((9, 9))  # (JᵀJ)⁻¹ of E's fitted elements, 0 for those held at 0
    cov0[np.ix_(free, free)] = (vt.T / s_**2) @ vt * _SCALE**2
    gain = cov0 @ j.T  # K = (JᵀJ)⁻¹ Jᵀ (whitened)
    # the accelerometer's uncertainty through u (numerical derivative of the residuals)
    ga = np.zeros((rot.n_rows, accel_free.size))
    for q in range(accel_free.size):
        h = max(1e-6, 1e-3 * math.sqrt(max(float(accel_free_cov[q, q]), 0.0)))
        pq = accel_free.copy()
        pq[q] += h
        r_q = _residuals_fixed_att(rot.motions, held, up_of(pq), r)
        ga[:, q] = (r_q - r) / h
    c_sys = jb @ bias_cov @ jb.T + ga @ accel_free_cov @ ga.T
    dof = (2 * len(rot.motions) + 3 * len(rot.turns)) - len(free)
    c_rows = np.eye(rot.n_rows) + c_sys
    chi2 = float(r @ np.linalg.solve(c_rows, r)) / dof if dof > 0 else float("nan")
    cov_p = cov0
    if dof > 0 and chi2 > 1.0 + 3.0 * math.sqrt(2.0 / dof):
        cov_p = cov0 * chi2
    return cov_p + gain @ c_sys @ gain.T, chi2


def _coefficients(
    e: FloatArray, bias_rad_s: FloatArray, bias_cov: FloatArray, cov_p: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """θ (bias [°/h], scale factors [ppm], misalignments [″]) of E and the bias, and its
    covariance through the Jacobian of θ[3:12] w.r.t. E's row-major elements."""
    theta = np.zeros(12)
    theta[0:3] = bias_rad_s * units.RS_TO_DH
    theta[3:12] = model.coeffs_from_error_matrix(e, np.zeros(3))[3:12]
    t_mat = np.zeros((9, 9))
    for i in range(3):
        t_mat[i, 4 * i] = 1.0 / units.PPM
    for k, name in enumerate(model.MISALIGNMENT_NAMES):
        rr, cc = model.MISALIGNMENT_INDEX[name]
        t_mat[3 + k, 3 * rr + cc] = units.RAD_TO_ARCSEC
    cov = np.zeros((12, 12))
    cov[0:3, 0:3] = bias_cov * units.RS_TO_DH**2
    cov[3:12, 3:12] = t_mat @ cov_p @ t_mat.T
    return theta, cov


def fit_rotations(
    rate_rad_s: FloatArray,
    dt_s: FloatArray,
    poses: Sequence[Section],
    up_of: Callable[[FloatArray], FloatArray],
    accel_free: FloatArray,
    accel_free_cov: FloatArray,
    bias_rad_s: FloatArray,
    bias_cov: FloatArray,
    dir_sigma_rad: FloatArray,
    rate_sigma_rad_s: float,
    turns: Sequence[Turn] = (),
    *,
    latitude_deg: float | None = None,
    max_iter: int = 8,
    saturated: npt.NDArray[np.bool_] | None = None,
    model: str = "full",
) -> GyroFit:
    r"""``E_g`` from the motions between consecutive ``poses`` (module docstring).

    Parameters
    ----------
    rate_rad_s : numpy.ndarray, shape (n, 3)
        Gyro samples [rad/s].
    dt_s : numpy.ndarray, shape (n,)
        Each sample's interval [s].
    poses : sequence of Section
        The static poses, in time order.
    up_of : callable
        ``up_of(p)``: the poses' calibrated unit up directions (m, 3) for accelerometer
        parameters ``p``.
    accel_free, accel_free_cov : numpy.ndarray
        The accelerometer parameters at the solution and their covariance.
    bias_rad_s, bias_cov : numpy.ndarray
        The gyro bias [rad/s] (3,) and its covariance [(rad/s)²].
    dir_sigma_rad : numpy.ndarray, shape (m,)
        The noise of each pose's up direction [rad].
    rate_sigma_rad_s : float
        The gyro's white noise per sample [rad/s].
    turns : sequence of Turn, optional
        The 360° turns with their named axes (default none).
    latitude_deg : float or None, optional
        Latitude [°]: the vertical earth rate is known, the horizontal one of unknown
        heading (None: the earth rate's direction unknown).
    max_iter : int, optional
        Gauss–Newton iterations at most (default 8).
    saturated : numpy.ndarray of bool or None, optional
        Samples on the gyro's rails (motions across them are left out).
    model : str, optional
        The elements of E fitted (:data:`GYRO_MODELS`: ``full`` nine, ``scale`` three).

    Returns
    -------
    GyroFit
        θ (12) and its covariance, direction rms before and after [rad], χ², the motions.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        An unknown ``model``.
    thermocal.errors.DesignError
        Too few rotations, or all about one axis.

    Notes
    -----
    Each motion between poses :math:`k` and :math:`k+1` gives a residual, minimised over
    :math:`E_g` by Gauss–Newton:

    .. math:: r_k = u_{k+1} - A_{k+1}^\mathsf{T} A_k^{-\mathsf{T}} u_k, \qquad
              \omega_c = (I + E_g)^{-1} (\omega - b_g)

    References
    ----------
    - Tedaldi, D., Pretto, A., Menegatti, E., "A robust and easy to implement method for IMU
      calibration without external equipments", Proc. IEEE ICRA 2014, §III-C.
    - Ferraris, F., Grimaldi, U., Parvis, M., "Procedure for effortless in-field calibration
      of three-axis rate gyros and accelerometers", Sensors and Materials 7(5), 1995.
    """
    if model not in GYRO_MODELS:
        raise ThermocalInputError(f"gyro model {model!r}: one of {', '.join(GYRO_MODELS)}")
    dt_med = float(np.median(dt_s))
    up = up_of(accel_free)
    motions = _motions(dt_s, poses, dt_med, dir_sigma_rad, rate_sigma_rad_s, latitude_deg)
    motions = unsaturated(motions, saturated)
    rot = _Rotations(rate_rad_s, dt_s, dt_med, motions, turns, rate_sigma_rad_s,
                     latitude_deg, free=GYRO_MODELS[model])  # fmt: skip
    _check_rotations(rot, len(motions), turns)
    r0, _j, _jb, _a = rot.evaluate(np.zeros((3, 3)), bias_rad_s, up, jac=False)
    e = _solve_error_matrix(rot, bias_rad_s, up, max_iter)
    rot, e = _turn_axis_scatter(rot, e, bias_rad_s, up, max_iter)
    r, j, jb, held = rot.evaluate(e, bias_rad_s, up, jac=True)
    cov_p, chi2 = _error_matrix_cov(
        rot, r, j, jb, held, up_of, accel_free, accel_free_cov, bias_cov
    )
    theta, cov = _coefficients(e, bias_rad_s, bias_cov, cov_p)
    return GyroFit(
        theta, cov, _direction_rms(r0, motions), _direction_rms(r, motions), chi2,
        len(motions), len(turns), math.sqrt(rot.tilt_var), model,
    )  # fmt: skip


def _direction_rms(r: FloatArray, motions: Sequence[Any]) -> float:
    """Rms over the motions of their unwhitened direction residuals' norms [rad] (NaN for
    no motion)."""
    sw = np.array([math.sqrt(mo.var) for mo in motions])
    v = r[: 3 * len(motions)].reshape(-1, 3) * sw[:, None]
    return float(np.sqrt(np.mean(np.sum(v**2, axis=1)))) if len(motions) else float("nan")


def _check_rotations(rot: Any, n_motions: int, turns: Sequence[Turn]) -> None:
    """Refuse rotations that cannot carry the fitted elements of E (:func:`fit_rotations`)."""
    three_turns = {tn.axis for tn in turns} == {0, 1, 2}
    if rot.n_rows < len(rot.free) + 3 and not three_turns:
        raise DesignError(
            f"{n_motions} motions between static poses (none across a gap in time) and "
            f"{len(turns)} named turns: the gyro's scale factors and misalignments need "
            "rotations about at least two different axes with a still pose before and "
            "after each, or the three turns x_rot, y_rot, z_rot"
        )


def scatter_beyond_noise(reduced_chi2: float, dof: int) -> bool:
    r"""Whether a fit's residuals scatter beyond their noise: a reduced χ² more than three
    of its standard deviations above 1.

    Parameters
    ----------
    reduced_chi2 : float
        The fit's χ² divided by its degrees of freedom [dimensionless].
    dof : int
        The degrees of freedom ν (positive).

    Returns
    -------
    bool
        True when :math:`\chi^2_\nu > 1 + 3\sqrt{2/\nu}`.

    Notes
    -----
    With normal residuals of the stated σ, :math:`\nu\chi^2_\nu` follows a χ² law of ν
    degrees of freedom (mean ν, variance 2ν): :math:`\chi^2_\nu` has mean 1 and standard
    deviation :math:`\sqrt{2/\nu}`.

    .. math::

        \chi^2_\nu > 1 + 3\sqrt{2/\nu}

    References
    ----------
    Tedaldi, D., Pretto, A., Menegatti, E. (2014). A robust and easy to implement method
    for IMU calibration without external equipments. ICRA 2014, 3042-3049.

    Examples
    --------
    >>> scatter_beyond_noise(1.5, 100), scatter_beyond_noise(704.0, 3)
    (True, True)
    >>> scatter_beyond_noise(1.2, 100)
    False
    """
    return reduced_chi2 > 1.0 + 3.0 * math.sqrt(2.0 / dof)


def too_few_motions(fit: GyroFit) -> bool:
    """Whether the motions cannot carry the model's elements of E: a redundancy
    (:attr:`GyroFit.dof`) below the number of elements fitted, with a misfit beyond the
    noise (reduced χ² above ``1 + 3√(2/ν)``, ν the dof).

    A least-squares fit of ``u`` unknowns on ``n`` rows averages an unmodelled error of
    the rows over their redundancy ``n − u`` only (the hat matrix keeps ``u/n`` of each
    row's error in the fit, Koch 1999, §3.2): with fewer redundant rows than unknowns, a
    misfit of the motions (χ² ≫ 1: something the model does not hold) goes mostly into
    E.  A session of a hand-held consumer IMU (six usable motions for nine elements,
    reduced χ² 704: tomisuarez2/ImuCalibration's MPU-6050) is one; fitting only the scale
    factors (``model="scale"``) leaves it nine rows of redundancy.

    Parameters
    ----------
    fit : GyroFit
        The fit to judge.

    Returns
    -------
    bool
        True when the redundancy is below the number of elements fitted and the reduced
        χ² is significant.
    """
    nu = fit.dof
    if nu <= 0:
        return True
    return nu < len(GYRO_MODELS[fit.model]) and scatter_beyond_noise(fit.reduced_chi2, nu)


def _residuals_fixed_att(
    motions: Sequence[_Motion], held: _Held, u: FloatArray, r_ref: FloatArray
) -> FloatArray:
    """The whitened residuals for other up directions ``u`` of the poses, the attitudes
    held (the turns' rows, about the calibrated frame's named axes, do not move with the
    poses' directions)."""
    atts, _turn_info = held
    out = r_ref.copy()
    for m_i, mo in enumerate(motions):
        a0, a1 = atts[m_i]
        s = 1.0 / math.sqrt(mo.var)
        out[3 * m_i : 3 * m_i + 3] = (u[mo.pose_k1] - _direction(u[mo.pose_k], a0, a1)) * s
    return out


__all__ = [
    "GAP_FACTOR",
    "GYRO_MODELS",
    "TURN_ANGLE_TOLERANCE",
    "TURN_AXIS_TOLERANCE_DEG",
    "GyroFit",
    "Turn",
    "check_turn",
    "fit_rotations",
    "scatter_beyond_noise",
    "static_bias",
    "too_few_motions",
    "turn_gap",
    "turn_intervals",
    "turn_rotation",
]
