"""Turntable calibration of a gyro triad: the pipeline (CN104880182).

:func:`calibrate` reads the gyro and encoder columns of a recording, checks the
design (16 positions, dwells, both axes moving), estimates the angle random walk
from the dwells, runs the Kalman filter (:mod:`.kalman`, the reported estimate)
and the batch least squares (:mod:`.estimate_ls`, the cross-check), and computes
the Cramér–Rao bound of the design (:func:`.model.fisher_information`).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.defaults import DEFAULT_GYRO_COLUMNS as DEFAULT_GYRO_COLUMNS
from thermocal.errors import (
    DesignError,
    MissingValueError,
    ParameterError,
    ThermocalInputError,
    UnitError,
    spell_parameters,
)
from thermocal.recording import Recording
from thermocal.turntable import accel as accel_mod
from thermocal.turntable import estimate_ls, kalman, model, schedule
from thermocal.turntable import gsens as gsens_mod
from thermocal.turntable.model import SCALE_FACTOR_REFUSED
from thermocal.turntable.schedule import TurntableWarning

if TYPE_CHECKING:
    from thermocal.multipos.gsens import GSensitivity

FloatArray = npt.NDArray[np.float64]

RESULT_FORMAT = "thermocal-turntable-result"
RESULT_VERSION = 1
DEFAULT_PRIOR_SIGMA = (1.0, 1000.0, 3600.0)
"""Initial σ of the filter's coefficients: bias [°/h], scale factor [ppm], misalignment [″]."""

CONSTRAINTS = (
    {
        "combination": "rotation of the triad about the inner axis (yx - xy)/2 vs the "
        "inner-axis encoder zero offset",
        "status": "indistinguishable",
        "handling": "constraint: the inner encoder zero is exact and defines the body x "
        "azimuth; the rotation is reported in yx, xy and as inner_axis_azimuth_arcsec",
    },
    {
        "combination": "outer-axis encoder zero offset / base levelling and north alignment",
        "status": "seen only through the earth rate; not estimated",
        "handling": "constraint: zero (a levelled, north-aligned base)",
    },
)


@dataclass(frozen=True)
class Estimate:
    """One estimator's coefficients θ (12, units of :mod:`.model`) and covariance.

    Attributes
    ----------
    theta : numpy.ndarray, shape (12,)
        Bias [°/h], scale factors [ppm], misalignments [″].
    cov : numpy.ndarray, shape (12, 12)
        Its covariance.
    """

    theta: FloatArray
    cov: FloatArray

    @property
    def sigma(self) -> FloatArray:
        out: FloatArray = np.sqrt(np.maximum(np.diag(self.cov), 0.0))
        return out

    def to_dict(self) -> dict[str, Any]:
        return _coeff_dict(self.theta, self.sigma, self.cov)


def _coeff_dict(theta: FloatArray, sigma: FloatArray, cov: FloatArray | None) -> dict[str, Any]:
    e, _ = model.error_matrix_from_coeffs(theta)
    az, az_sigma = model.inner_axis_azimuth(theta, cov)
    return {
        "bias_deg_h": theta[0:3].tolist(),
        "bias_deg_h_sigma": sigma[0:3].tolist(),
        "scale_factor_ppm": theta[3:6].tolist(),
        "scale_factor_ppm_sigma": sigma[3:6].tolist(),
        "misalignment_arcsec": theta[6:12].tolist(),
        "misalignment_arcsec_sigma": sigma[6:12].tolist(),
        "error_matrix": e.tolist(),
        "inner_axis_azimuth_arcsec": az,
        "inner_axis_azimuth_arcsec_sigma": az_sigma,
    }


@dataclass(frozen=True)
class TurntableResult:
    """Result of :func:`calibrate`.

    ``kalman`` is the reported estimate (the source's filter), ``least_squares`` the
    cross-check,
    ``crb`` the Cramér–Rao bound σ of each coefficient for this design and noise (12,
    units of :mod:`.model`), ``agreement`` the largest |θ_KF − θ_LS| / σ_LS,
    ``weak_combinations`` the poorly determined directions found in the design,
    ``arw_deg_sqrt_h`` the angle random walk of each gyro [°/√h].

    Attributes
    ----------
    kalman, least_squares : Estimate
        The reported estimate (the source's filter) and the cross-check.
    crb : numpy.ndarray, shape (12,)
        Cramér–Rao bound σ of each coefficient.
    agreement : float
        Largest ``|θ_KF − θ_LS| / σ_LS`` [-].
    latitude_deg : float
        Latitude used [°].
    arw_deg_sqrt_h : numpy.ndarray
        Angle random walk of each axis [°/√h].
    n_channels, n_states, n_positions, n_dwells : int
        Channels, filter states, distinct positions and dwells.
    min_dwell_s, duration_s : float
        Shortest dwell and run duration [s].
    chi2_per_dof, normalised_innovation_rms : float
        Least-squares χ²/dof and the filter's normalised innovation rms [-].
    weak_combinations : tuple of dict
        Poorly determined directions of the design.
    warnings : tuple of str
        What the run was warned of (parameters named as the library names them).
    warning_templates : tuple of str
        The same texts with ``{alpha_offset_deg}`` where the parameter goes, for a reader
        that names it its own way (:meth:`to_dict`'s ``spell``).
    encoder_noise_arcsec, encoder_jitter_arcsec : float
        Encoder noise used and jitter found at rest [″].
    encoder_noise_source : str
        ``"option"`` or ``"dwells"``.
    encoder_quantum_deg : float
        Reading resolution found [°].
    accel : AccelEstimate or None
        The accelerometer triad.
    gravity_m_s2 : float or None
        Local gravity used [m/s²].
    temperature_c, temperature_span_c : float or None
        Mean temperature and its range over the run [°C].
    g_sensitivity : GSensitivity or None
        The gyro's sensitivity to specific force from the dwells (:mod:`.gsens`); None when
        the dwells' gravity directions cannot separate it, with the reason in
        ``g_sensitivity_note``.
    g_sensitivity_subtracted : bool
        Whether a significant one was taken off the moves and the run estimated again.
    """

    kalman: Estimate
    least_squares: Estimate
    crb: FloatArray
    agreement: float
    latitude_deg: float
    arw_deg_sqrt_h: FloatArray
    n_channels: int
    n_states: int
    n_positions: int
    n_dwells: int
    min_dwell_s: float
    duration_s: float
    chi2_per_dof: float
    normalised_innovation_rms: float
    weak_combinations: tuple[dict[str, Any], ...] = ()
    warnings: tuple[str, ...] = field(default=())
    warning_templates: tuple[str, ...] = field(default=(), repr=False, compare=False)
    encoder_noise_arcsec: float = 0.0
    """σ of one encoder reading used by the filter and least squares [″]."""
    encoder_noise_source: str = "option"
    """``"option"`` (given) or ``"dwells"`` (estimated from the readings at rest)."""
    encoder_jitter_arcsec: float = 0.0
    """White jitter of the readings at rest, estimated from the dwells [″]."""
    encoder_quantum_deg: float = 0.0
    """Reading resolution found in the data [°] (0: not quantised)."""
    accel: accel_mod.AccelEstimate | None = None
    """The accelerometer triad (``accel_columns`` given), from the dwells' gravity."""
    gravity_m_s2: float | None = None
    """Local gravity used for the accelerometers [m/s²]."""
    temperature_c: float | None = None
    """Mean of the run's temperature column [°C] (``temperature_column`` given)."""
    temperature_span_c: float | None = None
    """Its range over the run (max − min) [°C]: a soak that drifts during the run."""
    g_sensitivity: GSensitivity | None = None
    """The gyro's g-sensitivity from the dwells [°/h/g] (:mod:`.gsens`)."""
    g_sensitivity_note: str | None = None
    """Why it was not estimated, or not subtracted although significant (else None)."""
    g_sensitivity_subtracted: bool = False
    """A significant g-sensitivity taken off the moves before the estimate reported."""

    def to_dict(self, spell: Callable[[str], str] | None = None) -> dict[str, Any]:
        """JSON-ready dict of the result file's keys (from the Kalman filter).

        Parameters
        ----------
        spell : callable, optional
            How the warnings name a parameter (the command line: its option); without it,
            as :attr:`warnings` (the parameter's own name).

        Returns
        -------
        dict
        """
        out: dict[str, Any] = {"format": RESULT_FORMAT, "version": RESULT_VERSION}
        out.update(self.kalman.to_dict())
        out["misalignment_names"] = list(model.MISALIGNMENT_NAMES)
        out["misalignment_error_matrix_index"] = [
            list(model.MISALIGNMENT_INDEX[n]) for n in model.MISALIGNMENT_NAMES
        ]
        out["crb"] = {
            "bias_deg_h": self.crb[0:3].tolist(),
            "scale_factor_ppm": self.crb[3:6].tolist(),
            "misalignment_arcsec": self.crb[6:12].tolist(),
        }
        out["method"] = f"kalman ({self.n_states} states)"
        out["least_squares"] = self.least_squares.to_dict()
        out["agreement_max_sigma"] = self.agreement
        out["latitude_deg"] = self.latitude_deg
        out["arw_deg_sqrt_h"] = self.arw_deg_sqrt_h.tolist()
        out["channels"] = list(model.CHANNEL_NAMES[: self.n_channels])
        out["n_positions"] = self.n_positions
        out["n_dwells"] = self.n_dwells
        out["encoder_noise_arcsec"] = self.encoder_noise_arcsec
        out["encoder_noise_source"] = self.encoder_noise_source
        out["encoder_jitter_arcsec"] = self.encoder_jitter_arcsec
        out["encoder_quantum_deg"] = self.encoder_quantum_deg
        out["min_dwell_s"] = self.min_dwell_s
        out["duration_s"] = self.duration_s
        out["chi2_per_dof"] = self.chi2_per_dof
        out["normalised_innovation_rms"] = self.normalised_innovation_rms
        out["unobservable"] = [dict(c) for c in CONSTRAINTS] + [
            dict(c) for c in self.weak_combinations
        ]
        out["warnings"] = (
            [spell_parameters(m, ("alpha_offset_deg",), spell) for m in self.warning_templates]
            if spell is not None and self.warning_templates
            else list(self.warnings)
        )
        if self.accel is not None:  # keys added only when asked: single-run JSON unchanged
            out["accel"] = self.accel.to_dict()
            out["gravity_m_s2"] = self.gravity_m_s2
        if self.temperature_c is not None:
            out["temperature_c"] = self.temperature_c
            out["temperature_span_c"] = self.temperature_span_c
        gs = self.g_sensitivity
        out["g_sensitivity"] = None if gs is None else gs.to_dict()
        out["g_sensitivity_note"] = self.g_sensitivity_note
        out["g_sensitivity_subtracted"] = self.g_sensitivity_subtracted
        return out


def _gyro_rad_s(rec: Recording, cols: Sequence[str], unit: str | None) -> FloatArray:
    """The gyro columns in rad/s; a column whose unit nothing states is refused (no
    silent default: the command line resolves it, with a warning, before this)."""
    out = []
    for c in cols:
        v = rec.column(c)
        u = unit or rec.units.get(c)
        if not u:
            raise UnitError.naming(
                f"{rec.name}: no unit is known for the gyro column {c!r}; give {{gyro_unit}} "
                "(deg/s, deg/h, rad/s) or state it in the file's metadata",
                "gyro_unit",
            )
        out.append(units.convert(v, u, "rad/s"))
    return np.column_stack(out)


def _check_finite(rec: Recording, cols: Sequence[str]) -> None:
    for c in cols:
        bad = np.flatnonzero(~np.isfinite(rec.column(c)))
        if bad.size:
            raise MissingValueError(
                f"{rec.name}: column {c!r} has {bad.size} missing/non-finite values, "
                f"first at row {bad[0]}"
            )


def estimate_arw(
    gyro_rad_s: FloatArray, dt_s: FloatArray, dwells: Sequence[schedule.Dwell]
) -> FloatArray:
    """Angle random walk of each gyro [rad/√s] from the scatter at rest:
    ``N² = τ · Σ_d Σ_i (g_i − ḡ_d)² / Σ_d (n_d − 1)`` over the dwells (white rate noise
    of the mean rate over τ has variance N²/τ; IEEE Std 952 annex C).

    Parameters
    ----------
    gyro_rad_s : numpy.ndarray, shape (n, 3)
        Gyro mean rates per interval [rad/s] (row 0 unused).
    dt_s : numpy.ndarray, shape (n − 1,)
        Interval lengths τ [s].
    dwells : sequence of Dwell
        The dwells (:func:`.schedule.segment`).

    Returns
    -------
    numpy.ndarray, shape (3,)
        N of each gyro [rad/√s].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        No dwell of two samples or more.

    Notes
    -----
    .. math:: N^2 = \\tau \\, \\frac{\\sum_d \\sum_i (g_i - \\bar g_d)^2}{\\sum_d (n_d - 1)}

    References
    ----------
    - IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for
      Single-Axis Interferometric Fiber Optic Gyros*, Annex C.

    Examples
    --------
    >>> from thermocal.turntable.schedule import Dwell
    >>> rng = np.random.default_rng(0)
    >>> g = rng.normal(0.0, 1e-3 / np.sqrt(0.01), (100001, 3))  # N = 1e-3 rad/√s at 100 Hz
    >>> d = Dwell(0, 100000, 0.0, 1000.0, 0.0, 0.0)
    >>> [round(float(v) * 1e3, 2) for v in estimate_arw(g, np.full(100000, 0.01), [d])]
    [1.0, 1.0, 1.0]
    """
    ss = np.zeros(3)
    dof = 0
    tau = []
    for d in dwells:
        g = gyro_rad_s[1:][d.start : d.stop]
        if g.shape[0] < 2:
            continue
        ss += np.sum((g - g.mean(axis=0)) ** 2, axis=0)
        dof += g.shape[0] - 1
        tau.append(dt_s[d.start : d.stop])
    if dof == 0:
        raise ThermocalInputError("no dwell long enough to estimate the gyro noise")
    tau_med = float(np.median(np.concatenate(tau)))
    out: FloatArray = np.sqrt(ss / dof * tau_med)
    return out


def weak_combinations(
    info: FloatArray, info_static: FloatArray, static_fraction: float, *, ratio: float = 10.0
) -> tuple[dict[str, Any], ...]:
    """Scale factors and misalignments seen only through the earth rate.

    The earth rate gives about ``info_static / static_fraction`` over the whole run
    (``static_fraction`` the share of time at rest); a coefficient whose total
    information (diagonal) is less than ``ratio`` times that owes nothing to the
    rotations.  Static data alone separate such terms only to hundreds of ppm or ″.

    Parameters
    ----------
    info : numpy.ndarray, shape (12, 12)
        Fisher information of θ from the whole run [1/unit²].
    info_static : numpy.ndarray, shape (12, 12)
        The same from the dwells only.
    static_fraction : float
        Share of the run's time at rest (0…1).
    ratio : float, default 10.0
        Least gain of the whole run over the earth rate alone.

    Returns
    -------
    tuple of dict
        One entry per weak coefficient: ``combination``, ``status``,
        ``information_over_earth_rate_only``.
    """
    out = []
    earth = np.diag(info_static) / max(static_fraction, 1e-12)
    d_all = np.diag(info)
    for i in range(3, model.N_COEFFS):
        gain = float(d_all[i] / earth[i]) if earth[i] > 0 else float("inf")
        if gain < ratio:
            out.append(
                {
                    "combination": model.COEFF_NAMES[i],
                    "status": "weakly observable: seen only through the earth rate",
                    "information_over_earth_rate_only": gain,
                }
            )
    return tuple(out)


AZIMUTH_WARNED_DEG = 1.0
"""A rotation of the body about the inner axis, relative to the declared geometry (body x
East at α = 0, :mod:`.kinematics`), beyond this [°] is warned of: the fit
takes it for the antisymmetric pair of misalignments ``yx = −sin ψ``, ``xy = +sin ψ`` and
biases both x and y scale factors by ``cos ψ − 1`` (−152 ppm at 1°)."""
AZIMUTH_REFUSED_DEG = 5.0
"""Beyond this [°] (scale factors biased by −3800 ppm, misalignments of 18000″) the run is
refused: the α encoder's zero is not the geometry's (a table whose inner axis reads 90° at
the body's α = 0 gave scale factors of −1e6 ppm and misalignments of ±206265″, i.e. the
rotation itself); ``alpha_offset_deg`` declares it."""


def inner_axis_azimuth_deg(theta: npt.ArrayLike) -> float:
    """The rotation ψ [°] of the body about the inner axis (body z) that a calibration's
    error matrix holds: ``I + E ≈ R_z(ψ)(I + E')`` with ``E'`` small, so
    ``ψ = atan2(E₁₀ − E₀₁, 2 + E₀₀ + E₁₁)`` (exact for a pure rotation ``E = R_z(ψ) − I``:
    ``E₀₀ = E₁₁ = cos ψ − 1``, ``E₁₀ = −E₀₁ = sin ψ``).  Positive: the α encoder reads ψ
    more than the geometry's α (the body turned by +ψ about z).

    Parameters
    ----------
    theta : array_like, shape (12,)
        θ (scale factors [ppm], misalignments [arcsec]).

    Returns
    -------
    float
        ψ [°].

    Notes
    -----
    .. math:: \\psi = \\operatorname{atan2}(E_{10} - E_{01},\\ 2 + E_{00} + E_{11})

    Examples
    --------
    >>> from thermocal.turntable.model import coeffs_from_error_matrix
    >>> c, s_ = np.cos(np.radians(2.0)), np.sin(np.radians(2.0))
    >>> e = np.array([[c - 1, -s_, 0], [s_, c - 1, 0], [0, 0, 0]])
    >>> round(inner_axis_azimuth_deg(coeffs_from_error_matrix(e, np.zeros(3))), 6)
    2.0
    """
    e = model.error_matrices(np.asarray(theta, dtype=np.float64))
    return float(np.degrees(np.arctan2(e[1, 0] - e[0, 1], 2.0 + e[0, 0] + e[1, 1])))


def _check_azimuth(
    theta: FloatArray, name: str, alpha_column: str, offset_deg: float = 0.0
) -> str | None:
    """Refuse a run whose fit holds a rotation about the inner axis beyond
    :data:`AZIMUTH_REFUSED_DEG` (:func:`inner_axis_azimuth_deg`), naming ``alpha_offset_deg``;
    the warning's text (``{alpha_offset_deg}`` where the parameter goes) beyond
    :data:`AZIMUTH_WARNED_DEG`, else None.  Judged first, when the x-y block of ``I + E``
    is ``k·R_z(ψ)`` with ``k`` within :data:`SCALE_FACTOR_REFUSED` of 1 (a quarter turn
    reads as −100 % scale factors); otherwise a unit is wrong and :func:`_check_fit` says
    so."""
    e = model.error_matrices(np.asarray(theta, dtype=np.float64))
    k = 0.5 * math.hypot(e[1, 0] - e[0, 1], 2.0 + e[0, 0] + e[1, 1])
    if not abs(k - 1.0) <= SCALE_FACTOR_REFUSED:  # the xy block is k·R_z(ψ): a unit's scale
        return None  # first (:func:`_check_fit`), ψ is not defined by it
    psi = inner_axis_azimuth_deg(theta)
    total = (offset_deg + psi + 180.0) % 360.0 - 180.0  # the alpha_offset_deg that removes it
    what = (
        f"the fit holds a rotation of {psi:+.4g}° of the body about the inner axis (z) "
        f"relative to the geometry (body x East at {alpha_column} = 0): the {alpha_column} "
        "encoder's zero, or the sensor's mounting, is off by that much"
    )
    if abs(psi) > AZIMUTH_REFUSED_DEG:
        raise ParameterError(
            "alpha_offset_deg",
            f"{name}: {what}; its x and y scale factors "
            f"({(math.cos(math.radians(psi)) - 1) * 1e6:+.3g} ppm) and misalignments yx, xy "
            "would be that rotation, not the sensor's; declare it with "
            f"{{name}} {total:.4g} (the reading at the geometry's α = 0), or re-zero the "
            "encoder; nothing written",
        )
    if abs(psi) > AZIMUTH_WARNED_DEG:
        return (
            f"{what}; the x and y scale factors are biased by "
            f"{(math.cos(math.radians(psi)) - 1) * 1e6:+.3g} ppm and yx, xy hold it; declare "
            f"it with {{alpha_offset_deg}} {total:.4g}"
        )
    return None


RESIDUAL_REFUSED = 20.0
"""Least-squares residuals beyond this many times the white-noise level (χ²/dof beyond
400) are refused: the encoder angles and the earth rate do not describe the run as the
geometry says (a latitude of the wrong sign gave 138×, the outer axis's zero a quarter turn
off 152×; the simulated run 1.03×); between ``1 + 5√(2/dof)`` and this, a warning."""


def _check_fit(est: _Estimates, acc: accel_mod.AccelEstimate | None, name: str) -> None:
    """Refuse a run whose fit fails its own checks, before anything is written: a gyro or
    accelerometer scale factor beyond :data:`SCALE_FACTOR_REFUSED`, least-squares residuals
    beyond :data:`RESIDUAL_REFUSED` × the white-noise level."""
    for kind, theta, opt in (("gyro", est.kf.theta, "gyro_unit"),
                             ("accelerometer", None if acc is None else acc.theta,
                              "accel_unit")):  # fmt: skip
        if theta is None:
            continue
        bad = model.scale_factors_beyond(theta)
        if bad:
            raise ThermocalInputError.naming(
                f"{name}: the {kind}'s scale factors come out {', '.join(bad)} (beyond "
                f"±{SCALE_FACTOR_REFUSED:.0%}: no sensor's): its columns are not in the unit "
                f"declared; give the right {{{opt}}}; nothing written",
                opt,
            )
    ratio = math.sqrt(est.chi2_per_dof) if est.dof > 0 and est.chi2_per_dof > 0 else 0.0
    if not ratio <= RESIDUAL_REFUSED:
        raise ThermocalInputError.naming(
            f"{name}: the fit failed: least-squares residuals {ratio:.3g}× the white-noise "
            f"level (at most {RESIDUAL_REFUSED:g}×): the encoder angles and the earth rate do "
            "not describe the run as the geometry says; check {latitude_deg}, the encoder "
            "columns ({alpha_column}, {beta_column}, {encoder_unit}) and their zeros "
            "({alpha_offset_deg}); nothing written",
            *("latitude_deg", "alpha_column", "beta_column", "encoder_unit", "alpha_offset_deg"),
        )


def _encoders(
    rec: Recording, columns: tuple[str, str], unit: str | None, alpha_offset_deg: float
) -> tuple[FloatArray, FloatArray]:
    """The encoder angles α (less ``alpha_offset_deg``) and β [°], unwrapped."""
    if not abs(alpha_offset_deg) <= 360.0:
        raise ParameterError(
            "alpha_offset_deg", f"{{name}} must be an angle within ±360°, got {alpha_offset_deg:g}"
        )
    a_deg = np.unwrap(encoder_deg(rec, columns[0], unit), period=360.0) - float(alpha_offset_deg)
    return a_deg, np.unwrap(encoder_deg(rec, columns[1], unit), period=360.0)


def _judge(
    est: _Estimates, acc: accel_mod.AccelEstimate | None, name: str, alpha: tuple[str, float]
) -> list[str]:
    """The fit judged before anything is written: the rotation about the inner axis first
    (:func:`_check_azimuth`), then the scale factors and residuals (:func:`_check_fit`);
    the warning to add, if any."""
    azimuth = _check_azimuth(est.kf.theta, name, alpha[0], alpha[1])
    _check_fit(est, acc, name)
    return [azimuth] if azimuth else []


def calibrate(
    rec: Recording,
    latitude_deg: float | None = None,
    *,
    gyro_columns: Sequence[str] = DEFAULT_GYRO_COLUMNS,
    alpha_column: str = "alpha_deg",
    beta_column: str = "beta_deg",
    gyro_unit: str | None = None,
    encoder_unit: str | None = None,
    arw_deg_sqrt_h: float | Sequence[float] | None = None,
    encoder_noise_arcsec: float | None = None,
    channels: int = 3,
    min_positions: int = 16,
    min_dwell_s: float = 60.0,
    move_block_s: float = 1.0,
    kf_interval_s: float = 1.0,
    prior_sigma: tuple[float, float, float] = DEFAULT_PRIOR_SIGMA,
    accel_columns: Sequence[str] | None = None,
    accel_unit: str | None = None,
    gravity_m_s2: float | None = None,
    temperature_column: str | None = None,
    alpha_offset_deg: float = 0.0,
) -> TurntableResult:
    """Calibrate a gyro triad from a 16-position dual-axis turntable run (CN104880182).

    Parameters
    ----------
    rec : Recording
        Time [s], gyro mean rates over the interval ending at each sample, encoder angles
        α, β at the sample times [° or rad], wrapped or not.
    latitude_deg : float, optional
        Site latitude [°] (default: the recording's metadata).
    gyro_columns, alpha_column, beta_column, accel_columns, temperature_column : str
        Column names (``accel_columns``: an accelerometer triad from the dwells' gravity,
        :mod:`.accel`; ``temperature_column``: its mean and span over the run [°C]).
    gyro_unit, encoder_unit, accel_unit : str, optional
        Units (default: the recording's; an encoder without one is taken in ° with a warning).
    arw_deg_sqrt_h, encoder_noise_arcsec : float, optional
        Angle random walk [°/√h] and encoder noise σ [″]; estimated from the dwells if None.
    channels : {3, 2}
        3: Δα, Δβ, Δγ (15-state filter); 2: the source's Δα, Δβ (14 states).
    min_positions, min_dwell_s, move_block_s, kf_interval_s : int or float
        Design checks (positions, the shortest dwell [s]), the least-squares block and the
        filter's measurement interval [s].
    prior_sigma : tuple of float
        The filter's initial σ of bias [°/h], scale factor [ppm], misalignment [″].
    gravity_m_s2, alpha_offset_deg : float, optional
        Local gravity [m/s²] (default: WGS-84 normal); the α encoder's reading at α = 0 [°].

    Returns
    -------
    TurntableResult
        The Kalman estimate, the least-squares cross-check and the Cramér–Rao bound.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Missing columns, a schedule not held, a fit that fails its own checks.
    """
    lat = _check_inputs(rec, latitude_deg, channels, gyro_columns, alpha_column, beta_column,
                        accel_columns, temperature_column)  # fmt: skip
    g = _gyro_rad_s(rec, gyro_columns, gyro_unit)
    a_deg, b_deg = _encoders(rec, (alpha_column, beta_column), encoder_unit, alpha_offset_deg)
    full, motion, seg = _segment(rec, g, a_deg, b_deg, lat, alpha_column, beta_column,
                                 min_positions, min_dwell_s)  # fmt: skip
    noise_source = "dwells" if encoder_noise_arcsec is None else "option"
    encoder_noise_arcsec = motion.reading_sigma_arcsec if encoder_noise_arcsec is None else (
        encoder_noise_arcsec)  # fmt: skip
    arw = _arw_rad_sqrt_s(arw_deg_sqrt_h, g, full.dt_s, seg.dwells)
    again = functools.partial(_estimate_channels, channels, arw, motion,
                              float(encoder_noise_arcsec), kf_interval_s, move_block_s,
                              prior_sigma)  # fmt: skip
    g_lat = float(gravity_m_s2) if gravity_m_s2 is not None else units.normal_gravity_m_s2(lat)
    est, gsens = _g_sensitivity(again, full, g, (a_deg, b_deg), seg.dwells, arw, lat, g_lat)
    msgs = list(_diagnostics(est, seg.n_positions))
    acc_est, g_local = None, (g_lat if accel_columns is not None else None)
    if accel_columns is not None:
        acc_est = _accel_triad(rec, accel_columns, accel_unit, a_deg, b_deg, seg.dwells, g_lat)
        msgs.extend(_accel_diagnostics(acc_est))
    msgs.extend(_judge(est, acc_est, str(rec.name), (alpha_column, alpha_offset_deg)))
    t_mean, t_span = _soak_temperature(rec, temperature_column)
    templates = tuple(msgs)
    msgs = _warned(msgs, str(rec.name))
    return TurntableResult(
        kalman=estimate_from(est.kf.theta, est.kf.cov),
        least_squares=estimate_from(est.ls.theta, est.ls.cov), crb=est.crb,
        agreement=est.agreement, latitude_deg=float(lat),
        arw_deg_sqrt_h=arw * units.RAD_TO_DEG * np.sqrt(units.SECONDS_PER_HOUR),
        n_channels=channels, n_states=est.kf.n_states, n_positions=seg.n_positions,
        n_dwells=len(seg.dwells), min_dwell_s=float(min(d.duration_s for d in seg.dwells)),
        duration_s=rec.duration_s, chi2_per_dof=est.chi2_per_dof,
        normalised_innovation_rms=est.kf.normalised_innovation_rms,
        weak_combinations=est.weak, warnings=tuple(msgs), warning_templates=templates,
        encoder_noise_arcsec=float(encoder_noise_arcsec), encoder_noise_source=noise_source,
        encoder_jitter_arcsec=motion.noise_arcsec, encoder_quantum_deg=motion.quantum_deg,
        accel=acc_est, gravity_m_s2=g_local, temperature_c=t_mean, temperature_span_c=t_span,
        g_sensitivity=gsens[0], g_sensitivity_note=gsens[1], g_sensitivity_subtracted=gsens[2],
    )  # fmt: skip


def _estimate_channels(
    channels: int,
    arw: FloatArray,
    motion: schedule.Motion,
    encoder_noise_arcsec: float,
    kf_interval_s: float,
    move_block_s: float,
    prior_sigma: tuple[float, float, float],
    m: model.IntervalModel,
) -> _Estimates:
    """:func:`_estimate` on the model's first ``channels`` channels."""
    return _estimate(m.select_channels(channels), arw, motion, encoder_noise_arcsec,
                     kf_interval_s, move_block_s, prior_sigma)  # fmt: skip


def _g_sensitivity(
    again: Callable[[model.IntervalModel], _Estimates],
    full: model.IntervalModel,
    g: FloatArray,
    angles_deg: tuple[FloatArray, FloatArray],
    dwells: Sequence[schedule.Dwell],
    arw: FloatArray,
    lat: float,
    g_m_s2: float,
) -> tuple[_Estimates, tuple[GSensitivity | None, str | None, bool]]:
    """The run estimated (``again(full)``), then the gyro's g-sensitivity from the dwells
    (:mod:`.gsens`) with its E; when an element is significant, taken off the moves, the run
    estimated again and ``A`` found again with the new E.  The estimates, and (A or None,
    why not, subtracted)."""
    est = again(full)

    def fit(e: _Estimates) -> GSensitivity:
        return gsens_mod.dwell_g_sensitivity(g, full.dt_s, *angles_deg, dwells, e.kf.theta,
                                             arw, lat, g_m_s2)  # fmt: skip

    try:
        gs = fit(est)
    except DesignError as exc:
        return est, (None, str(exc), False)
    from thermocal.multipos.gsens import ISOTROPIC_NOTE, isotropic_part

    iso = isotropic_part(gs.matrix_deg_h_g, gs.sigma_deg_h_g)
    if iso is not None:
        return est, (gs, ISOTROPIC_NOTE.format(c=iso[0], s=iso[1]), False)
    if not bool(np.any(gs.significant)):
        return est, (gs, None, False)
    est = again(gsens_mod.subtract_from_model(full, gs.matrix_deg_h_g, *angles_deg, g_m_s2))
    return est, (fit(est), None, True)


def _warned(msgs: list[str], name: str) -> list[str]:
    """Each message warned (the caller's caller named); the messages with the parameter
    ``alpha_offset_deg`` written as it is named."""
    for msg in msgs:
        warnings.warn(TurntableWarning.naming(f"{name}: {msg}", "alpha_offset_deg"), stacklevel=3)
    return [spell_parameters(m, ("alpha_offset_deg",)) for m in msgs]


def calibrate_arrays(
    time_s: npt.ArrayLike,
    gyro: npt.ArrayLike,
    alpha: npt.ArrayLike,
    beta: npt.ArrayLike,
    latitude_deg: float,
    *,
    gyro_unit: str = "deg/s",
    encoder_unit: str = "deg",
    accel: npt.ArrayLike | None = None,
    accel_unit: str = "m/s^2",
    temperature_c: npt.ArrayLike | None = None,
    **options: Any,
) -> TurntableResult:
    """Calibrate a gyro triad from arrays of a 16-position dual-axis turntable run.

    The arrays are put in a :class:`~thermocal.recording.Recording` and handed to
    :func:`calibrate`, which does the work; use it for what a file holds.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Sample times [s].
    gyro : array_like, shape (n, 3)
        The x, y, z gyro outputs, each the mean rate over the interval ending at its
        sample [``gyro_unit``].
    alpha, beta : array_like, shape (n,)
        Inner- and outer-axis encoder angles at the sample times [``encoder_unit``],
        wrapped or not.
    latitude_deg : float
        Site latitude [°]: the earth rate's input.
    gyro_unit : str, optional
        Unit of ``gyro`` (``"deg/s"``, ``"deg/h"``, ``"rad/s"``).
    encoder_unit : str, optional
        Unit of the encoder angles (``"deg"`` or ``"rad"``).
    accel : array_like, shape (n, 3), optional
        An accelerometer triad on the same table [``accel_unit``], calibrated from the
        dwells' gravity.
    accel_unit : str, optional
        Unit of ``accel`` (``"m/s^2"``, ``"mg"``, ``"g"``).
    temperature_c : array_like, shape (n,), optional
        A temperature [°C] whose mean and span over the run are reported.
    **options
        Any keyword of :func:`calibrate` (``min_dwell_s``, ``channels``, ``gravity_m_s2``,
        ``alpha_offset_deg`` …).

    Returns
    -------
    TurntableResult
        The Kalman-filter estimate, the least-squares cross-check and the design's
        Cramér–Rao bound (:meth:`TurntableResult.to_dict`).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Arrays of different lengths, a run that is not a 16-position schedule, a fit that
        fails its own checks.

    Examples
    --------
    >>> from thermocal.turntable import calibrate_arrays, simulate_turntable16
    >>> rec, truth = simulate_turntable16(0, rate_hz=10.0, dwell_s=20.0)
    >>> gyro = np.column_stack([rec.column(c) for c in ("gyro_x", "gyro_y", "gyro_z")])
    >>> res = calibrate_arrays(rec.time_s, gyro, rec.column("alpha_deg"),
    ...                        rec.column("beta_deg"), 40.0, min_dwell_s=10.0)
    >>> truth["scale_factor_ppm"]
    [45.0, -80.0, 25.0]
    >>> err = res.kalman.theta[3:6] - truth["scale_factor_ppm"]
    >>> bool(np.all(abs(err) < 3 * res.kalman.sigma[3:6]))
    True
    """
    g = np.asarray(gyro, dtype=np.float64)
    if g.ndim != 2 or g.shape[1] != 3:
        raise ParameterError("gyro", f"{{name}} must be an (n, 3) array, got shape {g.shape}")
    signals: dict[str, npt.ArrayLike] = {f"gyro_{ax}": g[:, i] for i, ax in enumerate("xyz")}
    unit_of = dict.fromkeys(signals, gyro_unit)
    if accel is not None:
        a = np.asarray(accel, dtype=np.float64)
        if a.shape != g.shape:
            raise ParameterError("accel", f"{{name}} must have the shape of gyro {g.shape}")
        signals.update({f"accel_{ax}": a[:, i] for i, ax in enumerate("xyz")})
        unit_of.update(dict.fromkeys(("accel_x", "accel_y", "accel_z"), accel_unit))
    temps = None if temperature_c is None else {"temperature_c": temperature_c}
    rec = Recording.from_arrays(
        time_s, signals, temps, signal_unit=unit_of,
        other={"alpha": alpha, "beta": beta},
        other_units={"alpha": encoder_unit, "beta": encoder_unit},
    )  # fmt: skip
    return calibrate(
        rec, latitude_deg, gyro_columns=("gyro_x", "gyro_y", "gyro_z"),
        alpha_column="alpha", beta_column="beta", gyro_unit=gyro_unit,
        encoder_unit=encoder_unit,
        accel_columns=None if accel is None else ("accel_x", "accel_y", "accel_z"),
        accel_unit=None if accel is None else accel_unit,
        temperature_column=None if temperature_c is None else "temperature_c",
        **options,
    )  # fmt: skip


def _segment(
    rec: Recording,
    g: FloatArray,
    a_deg: FloatArray,
    b_deg: FloatArray,
    lat: float,
    alpha_column: str,
    beta_column: str,
    min_positions: int,
    min_dwell_s: float,
) -> tuple[model.IntervalModel, schedule.Motion, schedule.Segmentation]:
    """The run's interval model (:func:`.model.interval_model`), its moves and rests from the
    encoder readings themselves (:func:`.schedule.detect_motion`: robust to jitter and
    quantisation, which a per-sample rate threshold is not), the dwells, positions and the
    design checks (:func:`.schedule.check_design`)."""
    t = rec.time_s
    full = model.interval_model(t, g, a_deg * units.DEG_TO_RAD, b_deg * units.DEG_TO_RAD, lat)
    motion = schedule.detect_motion(t, a_deg, b_deg)
    full = dataclasses.replace(full, moving=motion.moving)
    schedule.warn_gaps(rec.name, t, full.valid)
    seg = schedule.segment(t, a_deg, b_deg, full.moving, full.valid)
    dt_med = float(np.median(full.dt_s))
    schedule.check_design(
        seg,
        name=rec.name,
        alpha_col=alpha_column,
        beta_col=beta_column,
        min_positions=min_positions,
        min_dwell_s=min_dwell_s,
        dwell_tolerance_s=max(2.0 * dt_med, 0.005 * min_dwell_s),
    )
    return full, motion, seg


def _arw_rad_sqrt_s(
    arw_deg_sqrt_h: float | Sequence[float] | None,
    g: FloatArray,
    dt_s: FloatArray,
    dwells: Sequence[schedule.Dwell],
) -> FloatArray:
    """The angle random walk per gyro [rad/√s]: given [°/√h] (``N[rad/√s] = N[°/√h] ·
    (π/180) / √3600``), else estimated from the dwells (:func:`estimate_arw`)."""
    if arw_deg_sqrt_h is None:
        return estimate_arw(g, dt_s, dwells)
    arw = np.asarray(arw_deg_sqrt_h, dtype=np.float64) * np.ones(3)
    out: FloatArray = arw * units.DEG_TO_RAD / np.sqrt(units.SECONDS_PER_HOUR)
    return out


def _accel_diagnostics(acc: accel_mod.AccelEstimate) -> tuple[str, ...]:
    """The doubt about the accelerometer triad: dwell means more than 1 mg rms off the
    model."""
    if acc.residual_rms_mg > 1.0:
        return (
            f"accelerometer dwell means depart from the triad model by "
            f"{acc.residual_rms_mg:.3g} mg rms: check the unit, the axes or the gravity",
        )
    return ()


def _soak_temperature(rec: Recording, column: str | None) -> tuple[float | None, float | None]:
    """(mean, max − min) of the run's temperature column [°C]; (None, None) without one."""
    if column is None:
        return None, None
    temp = rec.temperature_c(column)
    return float(np.mean(temp)), float(np.max(temp) - np.min(temp))


def _check_inputs(
    rec: Recording,
    latitude_deg: float | None,
    channels: int,
    gyro_columns: Sequence[str],
    alpha_column: str,
    beta_column: str,
    accel_columns: Sequence[str] | None,
    temperature_column: str | None,
) -> float:
    """The latitude [°] (the argument, else the recording's metadata) after refusing what
    cannot be calibrated: channels not 2 or 3, no or an impossible latitude, not three gyro
    (or accelerometer) columns, absent or incomplete columns, fewer than three samples."""
    if channels not in (2, 3):
        raise ThermocalInputError(f"channels must be 2 or 3, got {channels}")
    lat = latitude_deg if latitude_deg is not None else rec.meta.latitude_deg
    if lat is None:
        raise ParameterError("latitude_deg", f"{rec.name}: give the latitude ({{name}} DEG)")
    if not -90.0 <= lat <= 90.0:
        raise ThermocalInputError(f"latitude {lat} is outside [-90, 90]°")
    cols = [*gyro_columns, alpha_column, beta_column]
    if len(gyro_columns) != 3:
        raise ThermocalInputError("name exactly three gyro columns (x, y, z)")
    if accel_columns is not None:
        if len(accel_columns) != 3:
            raise ThermocalInputError("name exactly three accelerometer columns (x, y, z)")
        cols += list(accel_columns)
    if temperature_column is not None:
        cols.append(temperature_column)
    rec.validate(required=cols)
    _check_finite(rec, cols)
    if rec.time_s.size < 3:
        raise ThermocalInputError(f"{rec.name}: too few samples")
    return float(lat)


def encoder_deg(rec: Recording, column: str, unit: str | None = None) -> FloatArray:
    """An encoder angle column in [°]: its unit resolved like every column's
    (:func:`thermocal.units.resolve_unit`, role ``angle``: ``unit`` (``encoder_unit``) >
    the file's metadata > the unit in the column's name > ° with a warning), then
    ``θ[°] = θ[unit] · ANGLE_UNITS[unit]``.

    Parameters
    ----------
    rec : Recording
        The turntable run.
    column : str
        The encoder column's name.
    unit : str, optional
        Its unit (``deg``, ``rad``, ``arcsec``…), overriding the file's.

    Returns
    -------
    numpy.ndarray, shape (n,)
        The angle [°].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        An unknown unit.
    """
    resolved = units.resolve_unit(
        column, "angle", option=unit, metadata=rec.units.get(column) or None, where=rec.name
    )
    return units.angle_to_deg(rec.column(column), resolved.unit)


@dataclass(frozen=True)
class _Estimates:
    """The two estimators of one run and what judges them."""

    kf: Any
    ls: Any
    crb: FloatArray
    agreement: float
    chi2_per_dof: float
    dof: int
    weak: tuple[dict[str, Any], ...]


def _estimate(
    m: model.IntervalModel,
    arw: FloatArray,
    motion: schedule.Motion,
    encoder_noise_arcsec: float,
    kf_interval_s: float,
    move_block_s: float,
    prior_sigma: tuple[float, float, float],
) -> _Estimates:
    """The Cramér–Rao bound of the design, the least squares (cross-check) and the Kalman
    filter (reported), the quantised inner encoder's azimuth uncertainty added to both, and
    the weakly observable combinations."""
    hw = model.whitened_regressors(m, arw)
    info = model.fisher_information(m, arw, whitened=hw)
    crb_cov = np.linalg.pinv(info, hermitian=True)
    crb = np.sqrt(np.maximum(np.diag(crb_cov), 0.0))

    # with perfect encoders a dwell's increments are a sufficient statistic; with encoder
    # noise each reading at rest adds information, so the dwells are cut like the filter's
    # A quantised encoder without jitter reads the same value all through a dwell: its
    # reading error is one constant per dwell, not white, so a dwell is one measurement.
    constant_at_rest = motion.quantum_deg > 0 and motion.noise_arcsec == 0
    static_block = kf_interval_s if encoder_noise_arcsec > 0 and not constant_at_rest else None
    ls_blocks = estimate_ls.make_blocks(
        m,
        arw,
        max_static_block_s=static_block,
        max_move_block_s=move_block_s,
    )
    ls = estimate_ls.solve_ls(ls_blocks, encoder_noise_arcsec=encoder_noise_arcsec)
    kf_blocks = estimate_ls.make_blocks(
        m,
        arw,
        max_static_block_s=None if constant_at_rest else kf_interval_s,
        max_move_block_s=kf_interval_s,
    )
    prior = np.repeat(np.asarray(prior_sigma, dtype=np.float64), [3, 3, 6])
    kf = kalman.run_filter(kf_blocks, prior, encoder_noise_arcsec=encoder_noise_arcsec)

    if motion.quantum_deg > 0:
        # The inner encoder's reading defines body x (the stated constraint); a quantised
        # reading leaves that definition uncertain by q/√12, which moves yx and xy
        # together in opposite directions (azimuth ψ: yx = +ψ, xy = −ψ) and is not averaged
        # over a dwell.  Add it to both covariances.
        v = np.zeros(model.N_COEFFS)
        v[6 + model.MISALIGNMENT_NAMES.index("yx")] = 1.0
        v[6 + model.MISALIGNMENT_NAMES.index("xy")] = -1.0
        az_var = (motion.quantum_deg * units.DEG_TO_RAD * units.RAD_TO_ARCSEC) ** 2 / 12.0
        kf = dataclasses.replace(kf, cov=kf.cov + az_var * np.outer(v, v))
        ls = dataclasses.replace(ls, cov=ls.cov + az_var * np.outer(v, v))
    agreement = float(np.max(np.abs(kf.theta - ls.theta) / np.maximum(ls.sigma, 1e-300)))
    info_static = model.fisher_information(m, arw, ~m.moving, whitened=hw)
    static_fraction = float(np.sum(m.dt_s[m.valid & ~m.moving]) / np.sum(m.dt_s[m.valid]))
    weak = weak_combinations(info, info_static, static_fraction)
    chi2 = ls.chi2 / max(ls.dof, 1)
    return _Estimates(kf, ls, crb, agreement, chi2, int(ls.dof), weak)


def _diagnostics(est: _Estimates, n_positions: int) -> tuple[str, ...]:
    """The doubts about one run's estimate, each one sentence: the filter and least squares
    apart by more than 1 σ, residuals above the white-noise level (χ²/dof beyond
    1 + 5·√(2/dof)), weakly observable combinations, fewer than the sixteen positions."""
    msgs: list[str] = []
    if est.agreement > 1.0:
        msgs.append(
            f"Kalman filter and least squares differ by up to {est.agreement:.2g} σ "
            "(prior too tight, or model mismatch)"
        )
    chi2 = est.chi2_per_dof
    if est.dof > 0 and chi2 > 1.0 + 5.0 * np.sqrt(2.0 / est.dof):
        msgs.append(
            f"least-squares residuals are {np.sqrt(chi2):.3g}× the white-noise level: "
            "noise other than angle random walk, or an error not in the model; "
            "the σ are optimistic"
        )
    for w in est.weak:
        msgs.append(f"weakly observable combination: {w['combination']}")
    if n_positions < len(schedule.POSITIONS_16):
        msgs.append(
            f"{n_positions} positions held, not the {len(schedule.POSITIONS_16)} of the schedule: "
            "estimated with what is there (the σ say how well)"
        )
    return tuple(msgs)


def _accel_triad(
    rec: Recording,
    columns: Sequence[str],
    unit: str | None,
    alpha_deg: FloatArray,
    beta_deg: FloatArray,
    dwells: Sequence[schedule.Dwell],
    g_m_s2: float,
) -> accel_mod.AccelEstimate:
    """The accelerometer triad from the dwells: mean specific force [m/s²] and mean encoder
    angles of each dwell (:func:`.accel.estimate_accel_triad`)."""
    out = []
    for c in columns:
        u = unit or rec.units.get(c)
        if not u:
            raise UnitError.naming(
                f"{rec.name}: no unit is known for the accelerometer column {c!r}; give "
                "{accel_unit} (m/s^2, mg, g) or state it in the file's metadata",
                "accel_unit",
            )
        out.append(units.convert(rec.column(c), u, "m/s^2"))
    f = np.column_stack(out)
    f_mean, n = accel_mod.dwell_means(f, dwells)
    ang, _ = accel_mod.dwell_means(np.column_stack([alpha_deg, beta_deg]), dwells)
    f_true = accel_mod.gravity_in_body(ang[:, 0], ang[:, 1], g_m_s2)
    return accel_mod.estimate_accel_triad(f_mean, f_true, n)


def estimate_from(theta: FloatArray, cov: FloatArray) -> Estimate:
    """Wrap θ and its covariance.

    Parameters
    ----------
    theta : numpy.ndarray, shape (12,)
        θ (biases, ppm, arcsec).
    cov : numpy.ndarray, shape (12, 12)
        Its covariance [units²].

    Returns
    -------
    Estimate
    """
    return Estimate(theta=np.asarray(theta, dtype=np.float64), cov=np.asarray(cov))


def validate_turntable_run(
    triads: Sequence[Any],
    rec: Recording,
    latitude_deg: float | None = None,
    *,
    gravity_m_s2: float | None = None,
    alpha_column: str | None = None,
    beta_column: str | None = None,
) -> list[Any]:
    """A turntable calibration of triads judged on an independent 16-position run.

    A gyro triad holding a g-sensitivity :math:`A` has :math:`A f` taken off its samples
    before they are compensated (:math:`f` the specific force the encoders' gravity
    direction gives, as ``compensate`` takes it off with the accelerometer's); an
    accelerometer triad holding K2 is inverted with it, as ``compensate`` does. The
    reference of every sample comes from the encoder angles (the true body rate
    ``ω_ib^b = C_nᵇ ω_ie^n + ω_nb^b(α, β, α̇, β̇)`` over each interval,
    :func:`.kinematics.omega_ib_b`; the specific force ``C_nᵇ (0, 0, g)`` at rest); per triad
    the dwell-mean and move-angle errors before and after compensation
    (:func:`thermocal.turntable.thermal.validate_triad`).

    Parameters
    ----------
    triads : sequence of Triad
        The calibration's triads (:class:`thermocal.models.calibration.Triad`).
    rec : Recording
        The independent run: time, the triads' columns and temperatures, the encoders.
    latitude_deg, gravity_m_s2 : float, optional
        Site latitude [°] (default: the recording's, then the calibration's) and local
        gravity [m/s²] (default: WGS-84 normal gravity there).
    alpha_column, beta_column : str, optional
        The encoder columns (default: the calibration runs').

    Returns
    -------
    list of TriadValidation
        One per triad (:class:`thermocal.turntable.thermal.TriadValidation`).
    """
    from thermocal.turntable import kinematics, thermal

    alpha_column = alpha_column or triads[0].encoders[0]
    beta_column = beta_column or triads[0].encoders[1]
    lat = next(
        (v for v in (latitude_deg, rec.meta.latitude_deg, triads[0].latitude_deg) if v is not None),
        None,
    )
    if lat is None:
        raise ParameterError("latitude_deg", f"{rec.name}: give the latitude ({{name}} DEG)")
    cols = [alpha_column, beta_column]
    for tri in triads:
        cols += [*tri.columns, tri.temperature]
    rec.validate(required=cols)
    _check_finite(rec, cols)
    t = rec.time_s
    a_deg = np.unwrap(encoder_deg(rec, alpha_column), period=360.0)
    b_deg = np.unwrap(encoder_deg(rec, beta_column), period=360.0)
    motion = schedule.detect_motion(t, a_deg, b_deg)
    valid = np.ones(t.size - 1, dtype=bool)
    seg = schedule.segment(t, a_deg, b_deg, motion.moving, valid)
    if len(seg.dwells) < 2:
        raise ThermocalInputError(f"{rec.name}: fewer than two dwells: not a turntable run")
    a, b = a_deg * units.DEG_TO_RAD, b_deg * units.DEG_TO_RAD
    dt = np.diff(t, prepend=t[0] - float(np.median(np.diff(t))))
    a_prev, b_prev = np.concatenate([[a[0]], a[:-1]]), np.concatenate([[b[0]], b[:-1]])
    with np.errstate(divide="ignore", invalid="ignore"):
        omega = kinematics.omega_ib_b(
            0.5 * (a + a_prev), 0.5 * (b + b_prev), (a - a_prev) / dt, (b - b_prev) / dt, lat
        )
    g = float(gravity_m_s2) if gravity_m_s2 is not None else units.normal_gravity_m_s2(lat)
    f_true = np.einsum("nji,j->ni", kinematics.mat_nb(a, b), np.array([0.0, 0.0, g]))
    dt_med = float(np.median(np.diff(t)))
    out = []
    for tri in triads:
        unit = tri.unit
        x = np.column_stack([rec.column(c) for c in tri.columns])
        ref, factor, bias_to_data, fig_unit = _triad_reference(tri, omega, f_true)
        out.append(
            thermal.validate_triad(
                tri.model,
                unit,
                x,
                rec.temperature_c(tri.temperature),
                np.asarray(ref),
                list(seg.dwells),
                bias_to_data,
                dt_med,
                name=tri.name,
                figure_unit_factor=factor,
                figure_unit=fig_unit,
                g_term=_g_sensitivity_term(tri, f_true),
                compensate=functools.partial(_compensate, tri, bias_to_data, unit),
            )
        )
    return out


def _compensate(tri: Any, to_data: float, unit: str, x: Any, temp_c: Any) -> Any:
    """The triad's own correction of ``x`` [``unit``] (:meth:`Triad.correct
    <thermocal.models.calibration.Triad.correct>`: with an accelerometer's K2 when stored),
    as ``compensate`` applies it."""
    return tri.correct(x, temp_c, to_data, unit)


def _g_sensitivity_term(tri: Any, f_true: npt.NDArray[np.float64]) -> Any:
    """A gyro triad's g-sensitivity term :math:`A f` in its unit
    (:meth:`~thermocal.models.calibration.Triad.g_sensitivity_term`, ``f_true`` the specific
    force [m/s²] the encoders' gravity direction gives: the gyro model
    :math:`\\omega_{raw} = (I + E)\\omega + b + A f`, IEEE Std 952-1997 annex B); None for
    an accelerometer triad or a gyro without one."""
    if tri.model.kind != "gyro" or tri.g_sensitivity is None:
        return None
    return tri.g_sensitivity_term(f_true, "m/s^2", tri.unit)


def _triad_reference(
    tri: Any, omega: npt.NDArray[np.float64], f_true: npt.NDArray[np.float64]
) -> tuple[Any, float, float, str]:
    """The triad's reference in its unit (body rate for a gyro, specific force for an
    accelerometer), its unit → figure unit factor, figure unit → its unit, and the figure
    unit (°/h or mg)."""
    unit = tri.unit
    if tri.model.kind == "gyro":
        ref = units.convert(omega, "rad/s", unit)
        factor = float(units.convert(np.array([1.0]), unit, "deg/h")[0])
        return ref, factor, float(units.convert(np.array([1.0]), "deg/h", unit)[0]), "deg/h"
    ref = units.convert(f_true, "m/s^2", unit)
    factor = float(units.convert(np.array([1.0]), unit, "mg")[0])
    return ref, factor, float(units.convert(np.array([1.0]), "mg", unit)[0]), "mg"
