"""One multi-position session end to end (pure maths on arrays), and the validation of a
calibration on a held-out session.

:func:`calibrate_session`: the static poses (:mod:`.poses`), each pose's mean specific
force and its noise, the accelerometer triad (:mod:`.accel`: gravity magnitude over ≥ 9
poses, or the closed form when only the six faces are given), the calibrated up
direction of each pose, the gyro bias from the statics and its scale factors and
misalignments from the motions between poses and the 360° turns (:mod:`.gyro`), each turn
about the sensor axis it is named for (``x_rot``: x, whatever pose came before it), judged
before the fit (:func:`.gyro.check_turn`); a gyro scale factor or misalignment beyond
:data:`GYRO_E_PLAUSIBLE` is a warning.

:func:`validate_session`: on another session, the poses found the same way and, before
(raw) and after compensation with a calibration of triads, the gravity-magnitude error
of each pose mean and the rotation-angle error of each motion (the angle between the
pose's up direction and the one carried over from the previous pose by the integrated
rate).
"""

from __future__ import annotations

import itertools
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import DesignError, ThermocalInputError, ThermocalWarning
from thermocal.multipos import accel as _accel
from thermocal.multipos import accel_k2 as _accel_k2
from thermocal.multipos import gsens as _gsens
from thermocal.multipos import gyro as _gyro
from thermocal.multipos.geometry import attitude_along
from thermocal.multipos.poses import FACES, Section, detect_poses
from thermocal.turntable import model
from thermocal.turntable.model import SCALE_FACTOR_REFUSED

FloatArray = npt.NDArray[np.float64]

METHOD = "multipos"
"""The ``method`` tag of a triad model made by ``thermocal multipos`` (the turntable's are
``"turntable"``): :func:`thermocal.multipos.validate.is_multipos` reads it back."""


GYRO_E_PLAUSIBLE = 0.10
"""A gyro scale factor beyond ±10 % (1e5 ppm) or a misalignment beyond 0.1 rad (20 626″)
is not a sensor's: a wrong unit, count scale or pose is warned of (the turns' own bound,
:data:`.gyro.TURN_ANGLE_TOLERANCE`)."""


ACCEL_RESIDUAL_REFUSED = 0.05
"""The accelerometer's gravity-magnitude residual rms after calibration, as a fraction of
local gravity, beyond which the fit failed (50 mg: a hand-held MPU-6050 leaves 12 mg,
imucal's example recording 1.1 mg, a simulated one 0.07 mg); refused, as a residual no smaller than
before the calibration."""

GYRO_DIRECTION_REFUSED_DEG = 10.0
"""The rms over motions of the gyro's gravity-direction residual after calibration [°]
beyond which the fit failed (the public sessions leave 0.6–4.1°, a simulated one 0.03°; a
°/s gyro declared rad/s leaves 40°); refused, as a residual no smaller than before."""


def check_accel_fit(acc: _accel.AccelFit, g_mg: float, where: str) -> None:
    """Refuse (:class:`~thermocal.errors.DesignError`, exit 2) an accelerometer fit that
    fails its own checks, before anything is written: a scale factor beyond
    :data:`SCALE_FACTOR_REFUSED`, a gravity-magnitude residual rms after calibration above
    :data:`ACCEL_RESIDUAL_REFUSED` × ``g`` or not below the one before (``g_mg`` [mg]).

    Parameters
    ----------
    acc : AccelFit
        The accelerometer fit.
    g_mg : float
        Local gravity [mg] (1000 mg = 1 g).
    where : str
        The session's name in the message.

    Raises
    ------
    thermocal.errors.DesignError
        A scale factor beyond ±50 %, or a residual too large or not reduced.
    """
    bad = model.scale_factors_beyond(acc.theta)
    if bad:
        raise DesignError.naming(
            f"{where}: the accelerometer's scale factors come out {', '.join(bad)} (beyond "
            f"±{SCALE_FACTOR_REFUSED:.0%}: no sensor's; before calibration the poses read "
            f"gravity's magnitude {acc.residual_rms_before_mg / g_mg:.3g} g rms off 1 g): "
            "the columns are not in the unit declared; give the right {accel_unit} (or "
            "{accel_scale} for raw counts); nothing written",
            *("accel_unit", "accel_scale"),
        )
    before, after = acc.residual_rms_before_mg, acc.residual_rms_after_mg
    if not (after <= ACCEL_RESIDUAL_REFUSED * g_mg and (after < before or after == 0.0)):
        raise DesignError.naming(
            f"{where}: the accelerometer fit failed: gravity-magnitude residual rms "
            f"{before:.4g} mg before, {after:.4g} mg after calibration (at most "
            f"{ACCEL_RESIDUAL_REFUSED * g_mg:.4g} mg, and below the one before); check that "
            "the poses are still and what they are named ({poses}), and the accelerometer's "
            "unit ({accel_unit}, {accel_scale}); nothing written",
            *("poses", "accel_unit", "accel_scale"),
        )


def check_gyro_fit(gfit: _gyro.GyroFit, where: str) -> None:
    """Refuse (:class:`~thermocal.errors.DesignError`, exit 2) a gyro fit that fails its own
    checks, before anything is written: a scale factor beyond :data:`SCALE_FACTOR_REFUSED`,
    or a direction residual rms over the motions after calibration above
    :data:`GYRO_DIRECTION_REFUSED_DEG` or not below the one before.

    Parameters
    ----------
    gfit : GyroFit
        The gyro fit.
    where : str
        The session's name in the message.

    Raises
    ------
    thermocal.errors.DesignError
        A scale factor beyond ±50 %, or a direction residual [°] too large or not reduced.
    """
    bad = model.scale_factors_beyond(gfit.theta)
    if bad:
        raise DesignError.naming(
            f"{where}: the gyro's scale factors come out {', '.join(bad)} (beyond "
            f"±{SCALE_FACTOR_REFUSED:.0%}: no gyro's): the columns are not in the unit "
            "declared, or not in the accelerometer's axes; give the right {gyro_unit} (or "
            "{gyro_scale} for raw counts), or the order and signs of the {gyro} and {accel} "
            "columns (x, y, z of one right-handed frame); nothing written",
            *("gyro_unit", "gyro_scale", "gyro", "accel"),
        )
    if gfit.n_motions == 0:
        return
    before = math.degrees(gfit.direction_rms_before_rad)
    after = math.degrees(gfit.direction_rms_after_rad)
    if not (after <= GYRO_DIRECTION_REFUSED_DEG and after < before):
        raise DesignError.naming(
            f"{where}: the gyro fit failed: the {gfit.n_motions} motions' direction residual "
            f"rms {before:.3g}° before, {after:.3g}° after calibration (at most "
            f"{GYRO_DIRECTION_REFUSED_DEG:g}°, and below the one before); check the gyro's unit "
            "({gyro_unit}, {gyro_scale}), the time's ({time_unit}, {rate_hz}), the order and "
            "signs of the {gyro} and {accel} "
            "columns (x, y, z of one right-handed frame) and that the poses are what they are "
            "named ({poses}); nothing written",
            *("gyro_unit", "gyro_scale", "time_unit", "rate_hz", "gyro", "accel", "poses"),
        )


@dataclass(frozen=True)
class PoseStats:
    """A static pose: its samples, mean specific force [mg], per-sample white noise σ of
    each axis [mg] (``var(Δx)/2``), mean rate [rad/s] and rate noise σ [rad/s] (gyro).

    Attributes
    ----------
    section : Section
        The pose's samples.
    f_mean_mg, f_sigma_mg : numpy.ndarray, shape (3,)
        Mean specific force and per-sample white noise σ [mg].
    w_mean_rad_s, w_sigma_rad_s : numpy.ndarray or None
        Mean rate and its noise σ [rad/s] (None without a gyro).
    """

    section: Section
    f_mean_mg: FloatArray
    f_sigma_mg: FloatArray
    w_mean_rad_s: FloatArray | None
    w_sigma_rad_s: FloatArray | None

    @property
    def mean_sigma_mg(self) -> float:
        """Noise of the pose mean along gravity [mg] (isotropic noise assumed)."""
        return float(math.sqrt(float(np.mean(self.f_sigma_mg**2)) / self.section.n))


def _white_sigma(x: FloatArray) -> FloatArray:
    d = np.diff(x, axis=0)
    out: FloatArray = np.sqrt(np.mean(d * d, axis=0) / 2.0) if d.shape[0] else np.zeros(3)
    return out


def pose_stats(
    accel_mg: FloatArray, gyro_rad_s: FloatArray | None, sections: Sequence[Section]
) -> list[PoseStats]:
    """Mean and white-noise σ of each static pose.

    Parameters
    ----------
    accel_mg : numpy.ndarray, shape (n, 3)
        Specific force [mg].
    gyro_rad_s : numpy.ndarray, shape (n, 3), optional
        Rates [rad/s].
    sections : sequence of Section
        The static poses.

    Returns
    -------
    list of PoseStats

    Notes
    -----
    The per-sample white-noise σ from first differences:

    .. math:: \\sigma^2 = \\tfrac12 \\langle (x_{i+1} - x_i)^2 \\rangle

    Examples
    --------
    >>> from thermocal.multipos.poses import Section
    >>> f = np.random.default_rng(0).normal(0.0, 2.0, (20000, 3)) + [0.0, 0.0, 1000.0]
    >>> st = pose_stats(f, None, [Section("pose_1", 0, 20000)])[0]
    >>> round(float(st.f_mean_mg[2])), [round(float(v), 1) for v in st.f_sigma_mg]
    (1000, [2.0, 2.0, 2.0])
    """
    out = []
    for s in sections:
        f = accel_mg[s.start : s.end]
        w = None if gyro_rad_s is None else gyro_rad_s[s.start : s.end]
        out.append(
            PoseStats(
                s,
                f.mean(axis=0),
                _white_sigma(f),
                None if w is None else w.mean(axis=0),
                None if w is None else _white_sigma(w),
            )
        )
    return out


@dataclass(frozen=True)
class SessionResult:
    """What :func:`calibrate_session` found.

    Attributes
    ----------
    accel : AccelFit
        The accelerometer triad.
    gyro : GyroFit or None
        The gyro triad (None without its columns).
    poses : tuple of PoseStats
        The static poses.
    turns : tuple of Section
        The named 360° turns.
    g_mg : float
        Local gravity [mg].
    temperature_c : float or None
        Mean temperature [°C].
    not_still : tuple of str
        Poses whose variance is more than twice the quietest's.
    g_sensitivity : GSensitivity or None
        The gyro's sensitivity to specific force from the static poses
        (:func:`thermocal.multipos.gsens.fit_g_sensitivity`; None without a gyro or when the
        poses cannot separate it).
    g_sensitivity_note : str or None
        Why it is None with a gyro (the poses it would need), or why a significant one was
        not taken off (``c·I`` alone: :func:`thermocal.multipos.gsens.isotropic_part`).
    g_sensitivity_subtracted : bool
        Whether an element of it was beyond 3σ and ``A f(t)`` was taken off the rates before
        the gyro's bias, scale factors and misalignments were fitted.
    accel_k2 : AccelK2Fit or None
        The accelerometer fitted with K2 per axis (``accel_k2``), whose force the gyro's
        stage read; None without.
    """

    accel: _accel.AccelFit
    gyro: _gyro.GyroFit | None
    poses: tuple[PoseStats, ...]
    turns: tuple[Section, ...]
    g_mg: float
    temperature_c: float | None
    not_still: tuple[str, ...] = field(default=())
    g_sensitivity: _gsens.GSensitivity | None = None
    g_sensitivity_note: str | None = None
    g_sensitivity_subtracted: bool = False
    accel_k2: _accel_k2.AccelK2Fit | None = None

    def to_dict(self) -> dict[str, Any]:
        """The session's calibration as plain JSON types: ``accel`` and ``gyro``
        (:meth:`AccelFit.to_dict <thermocal.multipos.accel.AccelFit.to_dict>`,
        :meth:`GyroFit.to_dict <thermocal.multipos.gyro.GyroFit.to_dict>`, None without a
        gyro), ``g_mg`` [mg], ``temperature_c`` [°C], ``poses`` (:meth:`poses_dict`),
        ``turns`` (name, start, end), ``not_still`` and, with a gyro, ``g_sensitivity``
        (:meth:`GSensitivity.to_dict <thermocal.multipos.gsens.GSensitivity.to_dict>` in
        °/h/g, None when the poses cannot separate it), ``g_sensitivity_note`` (why) and
        ``g_sensitivity_subtracted``."""
        out: dict[str, Any] = {
            "accel": self.accel.to_dict(),
            "gyro": None if self.gyro is None else self.gyro.to_dict(),
            "g_mg": self.g_mg,
            "temperature_c": self.temperature_c,
            "poses": self.poses_dict(),
            "turns": [{"name": s.name, "start": s.start, "end": s.end} for s in self.turns],
            "not_still": list(self.not_still),
        }
        if self.gyro is not None:
            gs = self.g_sensitivity
            out["g_sensitivity"] = None if gs is None else gs.to_dict()
            out["g_sensitivity_note"] = self.g_sensitivity_note
            out["g_sensitivity_subtracted"] = self.g_sensitivity_subtracted
        return out

    def table(self) -> list[dict[str, Any]]:
        """Every coefficient of the session as rows (triad, parameter, value, sigma,
        unit): the accelerometer's (bias in mg) then the gyro's (bias in °/h);
        ``pandas.DataFrame(result.table())`` makes it a table."""
        return self.accel.table() + ([] if self.gyro is None else self.gyro.table())

    def to_frame(self) -> Any:
        """:meth:`table` as a pandas DataFrame (pandas must be installed)."""
        import pandas

        return pandas.DataFrame(self.table())

    def poses_dict(self) -> list[dict[str, Any]]:
        """Each pose: name, start, end, mean specific force [mg], gravity-magnitude residual
        [mg] of the accelerometer fit a calibration stores (with K2 when fitted) and the
        still ratio."""
        fit = self.accel if self.accel_k2 is None else self.accel_k2.linear
        return [
            {
                "name": p.section.name,
                "start": p.section.start,
                "end": p.section.end,
                "mean_specific_force_mg": p.f_mean_mg.tolist(),
                "gravity_residual_mg": r,
                "still_ratio": p.section.still_ratio,
            }
            for p, r in zip(self.poses, fit.residuals_mg, strict=False)
        ]


def _calibrated_force(
    theta: FloatArray, f_mg: FloatArray, k2: FloatArray | None = None, g_mg: float = 1.0
) -> FloatArray:
    """The calibrated specific force [mg] of readings ``f_mg`` (…, 3) with the
    accelerometer parameters ``theta``: ``(I + E)⁻¹ (f − b)``, or with ``k2`` [mg/g², per
    local g ``g_mg``] the ``a`` of ``f = (I + E) a + b + K2 ⊙ (a/g)²`` (:mod:`.accel_k2`)."""
    e = model.error_matrices(theta)
    if k2 is None:
        out: FloatArray = np.asarray(np.linalg.solve(np.eye(3) + e, (f_mg - theta[0:3]).T).T)
        return out
    return _accel_k2._invert(f_mg, theta[0:3], e, k2, g_mg)


@dataclass(frozen=True)
class _AccelModel:
    """The accelerometer the gyro's stage reads the specific force with: its fit, the
    indices of θ that fit frees and, when fitted (``accel_k2``), each axis's K2 [mg/g²,
    per local g], the force then the fixed point of :mod:`.accel_k2`."""

    fit: _accel.AccelFit
    idx: Sequence[int]
    k2: FloatArray | None = None
    g_mg: float = units.G_TO_MG

    def force(self, f_mg: FloatArray) -> FloatArray:
        """The calibrated specific force [mg] of readings ``f_mg`` (…, 3) at the fit's θ
        (:func:`_calibrated_force`)."""
        return _calibrated_force(self.fit.theta, f_mg, self.k2, self.g_mg)


def _up_function(
    theta: FloatArray, idx: Sequence[int], f_mg: FloatArray, held: FloatArray | None = None,
    k2: FloatArray | None = None, g_mg: float = 1.0,
) -> Any:  # fmt: skip
    """``p ↦`` unit up directions of the poses for the accelerometer parameters ``p`` at
    ``idx`` of θ (the others held).  The poses where ``held`` is true keep their direction
    at ``theta`` whatever ``p``: the faces of the six-face closed form, whose calibrated
    direction ``(I + Ê)⁻¹(f_j± − b̂) = ±g e_j + (f_j+ + f_j−)/2 − b̂`` (to first order)
    does not move with the calibration's error (E's column j is made of that very
    pose's mean): their error is only the direction noise of :func:`_direction_sigma`.
    With ``k2`` [mg/g², per local g ``g_mg``] the force is read with it
    (:func:`_calibrated_force`)."""
    base = theta.copy()
    ids = np.asarray(idx)

    def up_at(p: FloatArray) -> FloatArray:
        th = base.copy()
        th[ids] = p
        c = _calibrated_force(th, f_mg, k2, g_mg)
        out: FloatArray = c / np.linalg.norm(c, axis=1)[:, None]
        return out

    if held is None or not np.any(held):
        return up_at
    u0 = up_at(base[ids])

    def up_of(p: FloatArray) -> FloatArray:
        out = up_at(p)
        out[held] = u0[held]
        return out

    return up_of


def _direction_sigma(
    sigma_mg: FloatArray, names: Sequence[str], method: str, g_mg: float
) -> FloatArray:
    """Each pose's direction noise [rad] not already in the accelerometer's calibration
    error (:mod:`.gyro`): ``σ_f/g``, times ``√(1/3)`` for a face of the six-face closed
    form (its calibrated direction keeps ``(f_j+ + f_j−)/2 − b`` only: variance
    ``σ²(1/9 + 1/9 + 4/36) = σ²/3``, uncorrelated with ``b`` and E)."""
    factor = np.array(
        [math.sqrt(1.0 / 3.0) if method == "six-face" and n in FACES else 1.0 for n in names]
    )
    out: FloatArray = np.asarray(sigma_mg) / g_mg * factor
    return out


def _named_turns(
    turns: Sequence[Section],
    rate_rad_s: FloatArray,
    dt_s: FloatArray,
    bias_rad_s: FloatArray,
    accel_mg: FloatArray,
    am: _AccelModel,
    face_sigma_rad: dict[str, float],
    where: str,
    sections_from: str,
    saturated: npt.NDArray[np.bool_] | None = None,
) -> list[_gyro.Turn]:
    """Each named turn about the sensor axis of its name (``x_rot``: x), judged first
    (:func:`.gyro.check_turn`), with the calibrated up direction during it and the
    direction noise of that axis across itself [rad]: a hand turns the board about the
    vertical of the face it lies on (``x_p`` or ``x_a``, by the sign of the up
    direction's x during the turn), whose calibrated direction is ``e_j`` to within its
    direction noise ``face_sigma_rad[face]`` (:func:`_direction_sigma`); without that
    face among the poses, the accelerometer calibration's σ of the two misalignments of
    column j (the frame is the accelerometer's)."""
    var = np.diag(am.fit.cov)
    out = []
    dt_med = float(np.median(dt_s))
    for tr in turns:
        j = "xyz".index(tr.name[0])
        gap = _gyro.turn_gap(dt_s, tr, dt_med)
        if gap is not None:
            raise ThermocalInputError(
                f"{where} {tr.name!r}: a gap in time of {gap[1]:.3g} s after sample {gap[0]} "
                "inside the turn: the rotation across it is unknown; fix its start and end "
                f"in {sections_from}, or record the turn again"
            )
        if saturated is not None and np.any(saturated[tr.start : tr.end]):
            i = tr.start + int(np.argmax(saturated[tr.start : tr.end]))
            raise ThermocalInputError(
                f"{where} {tr.name!r}: the gyro sits on its rails at sample {i} inside the "
                "turn: the rotation is unknown; turn more slowly (or at a wider gyro range) "
                f"and record it again, or leave the turn out of {sections_from}"
            )
        rot = _gyro.turn_rotation(rate_rad_s, dt_s, bias_rad_s, tr)
        _gyro.check_turn(rot, tr.name, j, f"{where} {tr.name!r}", sections_from)
        c = am.force(accel_mg[tr.start : tr.end].mean(axis=0)[None, :])[0]
        col = [6 + k for k, n in enumerate(model.MISALIGNMENT_NAMES)
               if model.MISALIGNMENT_INDEX[n][1] == j]  # fmt: skip
        face = f"{'xyz'[j]}_{'p' if c[j] >= 0 else 'a'}"
        sig = face_sigma_rad.get(face, math.sqrt(float(np.mean(var[col]))) * units.ARCSEC_TO_RAD)
        out.append(_gyro.Turn(tr, j, c / np.linalg.norm(c), float(sig)))
    return out


def _section_warnings(
    statics: Sequence[Section],
    turns: Sequence[Section],
    has_gyro: bool,
    where: str,
    sections_from: str,
) -> tuple[str, ...]:
    """Warnings on the sections before any fit (turns named without a gyro, poses not
    still); the names of the poses not still."""
    if turns and not has_gyro:
        warnings.warn(
            ThermocalWarning.naming(
                f"{where}: {', '.join(s.name for s in turns)} in {sections_from} are 360° "
                "turns for the gyro; without its columns ({gyro} X,Y,Z) they are not used",
                "gyro",
            ),
            stacklevel=3,
        )
    not_still = tuple(s.name for s in statics if s.still_ratio > 2.0)
    if not_still:
        warnings.warn(
            ThermocalWarning(
                f"{where}: {len(not_still)} poses are not still (window variance more than "
                f"twice the quietest): {', '.join(not_still[:8])}"
                f"{' …' if len(not_still) > 8 else ''}; their means carry the motion"
            ),
            stacklevel=3,
        )
    return not_still


def _warn_short(
    t: FloatArray, statics: Sequence[Section], static_s: float, where: str, sections_from: str
) -> None:
    """A warning naming the still poses shorter than ``static_s`` [s] (sections of a POSES
    file: the detector never returns them): a mean of a few samples carries their noise and
    σ, from ``var(Δx)/2`` of so few differences, is itself uncertain."""
    short = [f"{s.name} ({t[s.end - 1] - t[s.start]:.3g} s)" for s in statics
             if s.end - s.start < 2 or t[s.end - 1] - t[s.start] < static_s]  # fmt: skip
    if short:
        warnings.warn(
            ThermocalWarning.naming(
                f"{where}: {len(short)} poses in {sections_from} are shorter than {{static_s}} "
                f"{static_s:g} s: {', '.join(short[:6])}{' …' if len(short) > 6 else ''}; "
                "their means and noise rest on few samples (check their start and end)",
                "static_s",
            ),
            stacklevel=3,
        )


def _warn_implausible(gfit: _gyro.GyroFit, where: str) -> None:
    """A warning when a gyro scale factor or misalignment is beyond
    :data:`GYRO_E_PLAUSIBLE` (no sensor's: a unit, count scale or pose is wrong), and
    when the gyro comes from the three turns alone (nothing checks them)."""
    if gfit.n_motions == 0:
        warnings.warn(
            ThermocalWarning(
                f"{where}: the gyro from the three turns alone (no motion between still "
                "poses without a gap in time): nothing checks them, a lean of their axes "
                "is taken for misalignment and σ counts the noise only; record the faces "
                "and turns in one piece for the motions between them"
            ),
            stacklevel=3,
        )
    th = gfit.theta
    bad = [f"scale factor {ax} {th[3 + i] * units.PPM:+.1%}" for i, ax in enumerate("xyz")
           if abs(th[3 + i] * units.PPM) > GYRO_E_PLAUSIBLE]  # fmt: skip
    bad += [f"misalignment {n} {th[6 + k]:+.4g}″" for k, n in enumerate(model.MISALIGNMENT_NAMES)
            if abs(th[6 + k] * units.ARCSEC_TO_RAD) > GYRO_E_PLAUSIBLE]  # fmt: skip
    if bad:
        warnings.warn(
            ThermocalWarning.naming(
                f"{where}: gyro {', '.join(bad)}: beyond ±{GYRO_E_PLAUSIBLE:.0%} (0.1 rad), "
                "no gyro's; check the gyro's unit ({gyro_unit}, {gyro_scale}) and that the "
                "poses and turns are what they are named ({poses})",
                *("gyro_unit", "gyro_scale", "poses"),
            ),
            stacklevel=3,
        )


def _warn_too_few_motions(gfit: _gyro.GyroFit, where: str) -> None:
    """A warning when the motions cannot carry the model's elements of E
    (:func:`.gyro.too_few_motions`), naming the reduced model."""
    if gfit.model != "full" or not _gyro.too_few_motions(gfit):
        return
    worst = float(np.max(gfit.sigma[3:6])) * units.PPM
    warnings.warn(
        ThermocalWarning.naming(
            f"{where}: {gfit.n_motions} motions between poses for the gyro's 9 scale factors "
            f"and misalignments leave {gfit.dof} degree(s) of freedom, and they misfit their "
            f"noise (reduced χ² {gfit.reduced_chi2:.3g}): the misfit goes into E (scale "
            f"factor σ up to {worst:.1%}); fit the 3 scale factors only with "
            "{gyro_model} scale (misalignments held at 0), or record more motions",
            "gyro_model",
        ),
        stacklevel=3,
    )


def _accel_fit(
    stats: Sequence[PoseStats], g_mg: float, where: str, sections_from: str
) -> tuple[_accel.AccelFit, Sequence[int]]:
    """The accelerometer fit of :func:`calibrate_session` and the indices of θ it frees."""
    f = np.asarray([p.f_mean_mg for p in stats])
    sig = np.asarray([p.mean_sigma_mg for p in stats])
    names = [p.section.name for p in stats]
    if all(n in names for n in FACES) and len(stats) < _accel.MIN_POSES:
        faces = {n: f[names.index(n)] for n in FACES}
        face_sig = {n: float(sig[names.index(n)]) for n in FACES}
        try:
            acc = _accel.fit_six_faces(faces, face_sig, g_mg)
        except DesignError as exc:
            raise DesignError.around(
                exc,
                f"{where}: ",
                f"; fix their sections in {sections_from} (a POSES file of "
                "this session?) or the order and signs of the {accel} columns",
                "accel",
            ) from None
        idx: Sequence[int] = tuple(range(12))
        # residuals of the six faces only: map back in pose order
        order = [FACES.index(n) if n in FACES else -1 for n in names]
        acc = _accel.AccelFit(
            acc.theta, acc.cov, acc.residual_rms_before_mg, acc.residual_rms_after_mg,
            acc.reduced_chi2, acc.method, len(stats),
            tuple(acc.residuals_mg[o] if o >= 0 else float("nan") for o in order),
        )  # fmt: skip
    else:
        acc = _accel.fit_gravity_magnitude(f, sig, g_mg)
        idx = _accel.FREE_INDEX
    check_accel_fit(acc, g_mg, where)
    return acc, idx


def _mean_over(x: npt.ArrayLike, sections: Sequence[Section]) -> float:
    """The mean of ``x`` over the samples of ``sections`` (NaN left out)."""
    v = np.asarray(x, dtype=np.float64)
    return float(np.nanmean(np.concatenate([v[s.start : s.end] for s in sections])))


def _calibrated_up(
    stats: Sequence[PoseStats], am: _AccelModel
) -> tuple[Any, FloatArray, FloatArray]:
    """The up direction of each pose as a function of the accelerometer's free θ, those
    θ and their covariance (K2, when fitted, held at its value)."""
    acc, idx = am.fit, np.asarray(am.idx)
    f = np.asarray([p.f_mean_mg for p in stats])
    names = [p.section.name for p in stats]
    held = np.array([acc.method == "six-face" and n in FACES for n in names])
    up_of = _up_function(acc.theta, am.idx, f, held, am.k2, am.g_mg)
    return up_of, acc.theta[idx], acc.cov[np.ix_(idx, idx)]


def _pose_rates(stats: Sequence[PoseStats]) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Samples per pose, each pose's mean rate [rad/s] and the rate's white-noise σ [rad/s]
    (the poses' σ pooled by their samples)."""
    n = np.asarray([p.section.n for p in stats], dtype=np.float64)
    wm = np.asarray([p.w_mean_rad_s for p in stats])
    ws = np.sqrt(np.average(np.asarray([p.w_sigma_rad_s for p in stats]) ** 2, axis=0,
                            weights=n))  # fmt: skip
    return n, wm, ws


def _g_sensitivity(
    stats: Sequence[PoseStats], am: _AccelModel, g_mg: float, latitude_deg: float | None
) -> tuple[_gsens.GSensitivity | None, str | None]:
    """The gyro's g-sensitivity from the static poses (:mod:`.gsens`), or None and why."""
    up_of, free, _cov = _calibrated_up(stats, am)
    n, wm, ws = _pose_rates(stats)
    try:
        gs = _gsens.fit_g_sensitivity(wm, n, ws, up_of(free) * g_mg / 1000.0, latitude_deg)
    except DesignError as exc:
        return None, str(exc)
    return gs, None


def _without_g_drift(
    a: FloatArray, w: FloatArray, stats: Sequence[PoseStats], am: _AccelModel,
    gs: _gsens.GSensitivity | None, note: str | None,
) -> tuple[FloatArray, list[PoseStats], bool, str | None]:  # fmt: skip
    """The rates the rotations' fit takes: with an element of the g-sensitivity beyond 3σ,
    ``ω − A f(t)`` at every sample (``f`` the calibrated specific force in g,
    ``(I + E_a)⁻¹(f_meas − b_a) / 1000``, with K2 when fitted: the hand's accelerations
    too), the poses' means again, True; else the rates and poses as they are, False.  An
    ``A`` that is ``c·I`` alone (:func:`.gsens.isotropic_part`: a latitude of the wrong
    sign) is not taken off, and ``note`` becomes why.  Returns the rates, the poses, whether
    taken off, and ``note``."""
    if gs is None or not bool(np.any(gs.significant)):
        return w, list(stats), False, note
    iso = _gsens.isotropic_part(gs.matrix_deg_h_g, gs.sigma_deg_h_g)
    if iso is not None:
        return w, list(stats), False, _gsens.ISOTROPIC_NOTE.format(c=iso[0], s=iso[1])
    f_g = am.force(a) / units.G_TO_MG
    w_fit = w - f_g @ (gs.matrix_deg_h_g * units.DH_TO_RS).T
    return w_fit, pose_stats(a, w_fit, [p.section for p in stats]), True, note


def _accel_model(
    stats: Sequence[PoseStats], acc: _accel.AccelFit, idx: Sequence[int], g_mg: float,
    accel_k2: bool, where: str,
) -> tuple[_AccelModel, _accel_k2.AccelK2Fit | None]:  # fmt: skip
    """The accelerometer the gyro's stage reads: the fit of :func:`_accel_fit`, or with
    ``accel_k2`` the twelve parameters with K2 (:func:`.accel_k2.fit_k2`), and that K2 fit."""
    if not accel_k2:
        return _AccelModel(acc, idx, None, g_mg), None
    try:
        k2 = _accel_k2.fit_k2([p.f_mean_mg for p in stats], [p.mean_sigma_mg for p in stats],
                              g_mg)  # fmt: skip
    except DesignError as exc:
        raise DesignError.around(exc, f"{where}: ") from None
    return _AccelModel(k2.linear, _accel.FREE_INDEX, k2.k2_mg_per_g2, g_mg), k2


def _gyro_fit(
    t: FloatArray, a: FloatArray, w: FloatArray, stats: Sequence[PoseStats],
    turns: Sequence[Section], am: _AccelModel, g_mg: float,
    latitude_deg: float | None, sat: npt.NDArray[np.bool_] | None, gyro_model: str,
    where: str, sections_from: str,
) -> _gyro.GyroFit:  # fmt: skip
    """The gyro fit of :func:`calibrate_session`, on the accelerometer's up directions."""
    sig = np.asarray([p.mean_sigma_mg for p in stats])
    names = [p.section.name for p in stats]
    up_of, free, free_cov = _calibrated_up(stats, am)
    up = up_of(free)
    n, wm, ws = _pose_rates(stats)
    bias, bias_cov = _gyro.static_bias(wm, n, ws, up, latitude_deg)
    dt = np.diff(t)
    dt = np.concatenate([dt, dt[-1:]])
    dir_sig = _direction_sigma(sig, names, am.fit.method, g_mg)
    named = _named_turns(turns, w, dt, bias, a, am, dict(zip(names, dir_sig, strict=True)),
                         f"{where}: section", sections_from, sat)  # fmt: skip
    gfit = _gyro.fit_rotations(
        w, dt, [p.section for p in stats], up_of, free, free_cov, bias, bias_cov,
        dir_sig, float(np.sqrt(np.mean(ws**2))), named, latitude_deg=latitude_deg,
        saturated=sat,
        model=gyro_model,
    )  # fmt: skip
    check_gyro_fit(gfit, where)
    _warn_implausible(gfit, where)
    _warn_too_few_motions(gfit, where)
    return gfit


def _gyro_stage(
    t: FloatArray, a: FloatArray, w: FloatArray, stats: Sequence[PoseStats],
    turns: Sequence[Section], am: _AccelModel, g_mg: float, latitude_deg: float | None,
    saturated: npt.ArrayLike | None, gyro_model: str, where: str, sections_from: str,
) -> tuple[_gyro.GyroFit, _gsens.GSensitivity | None, str | None, bool]:  # fmt: skip
    """The gyro's part of :func:`calibrate_session`: its g-sensitivity, the rates with
    ``A f`` taken off when significant (:func:`_without_g_drift`), the rotations' fit; the
    fit, the g-sensitivity, why (not), and whether it was taken off."""
    sat = None if saturated is None else np.asarray(saturated, dtype=bool)
    gsens, gnote = _g_sensitivity(stats, am, g_mg, latitude_deg)
    w_fit, stats_fit, subtracted, gnote = _without_g_drift(a, w, stats, am, gsens, gnote)
    gfit = _gyro_fit(t, a, w_fit, stats_fit, turns, am, g_mg, latitude_deg, sat,
                     gyro_model, where, sections_from)  # fmt: skip
    return gfit, gsens, gnote, subtracted


def calibrate_session(
    time_s: npt.ArrayLike,
    accel_mg: npt.ArrayLike,
    gyro_rad_s: npt.ArrayLike | None,
    *,
    g_mg: float,
    latitude_deg: float | None = None,
    sections: Sequence[Section] | None = None,
    static_s: float = 1.0,
    temperature_c: npt.ArrayLike | None = None,
    where: str = "session",
    sections_from: str = "the POSES file",
    saturated: npt.ArrayLike | None = None,
    gyro_model: str = "full",
    accel_k2: bool = False,
) -> SessionResult:
    """Calibrate the accelerometer (and gyro) triad of one multi-position session.

    Parameters
    ----------
    time_s, accel_mg, gyro_rad_s : array_like, shapes (n,), (n, 3), (n, 3) or None
        Sample times [s], specific force [mg] and rates [rad/s] (None: accelerometer only).
    g_mg, latitude_deg : float
        Local gravity [mg]; site latitude [°], the earth rate taken off the gyro bias (None:
        not taken off, as imucal does).
    sections : sequence of Section, optional
        Poses and turns by sample (:func:`.poses.parse_poses`); None finds the poses.
    static_s : float, optional
        The shortest still pose [s].
    temperature_c, saturated : array_like, shape (n,), optional
        Temperature [°C] (its mean over the poses reported); samples with a gyro on its
        rails (their motions left out, a turn holding one refused).
    where, sections_from : str, optional
        The session and the source of ``sections``, as messages name them.
    gyro_model : {"full", "scale"}, optional
        The elements of the gyro's ``E`` fitted (:data:`.gyro.GYRO_MODELS`).
    accel_k2 : bool, optional
        Also fit each accelerometer axis's K2 (:func:`.accel_k2.fit_k2`), which the gyro's
        stage then reads the accelerometer with (up directions, g-sensitivity, A f).

    Returns
    -------
    SessionResult
        The accelerometer and gyro fits (and the gyro's g-sensitivity), the poses and turns.

    Raises
    ------
    thermocal.errors.DesignError
        Fewer than six poses, faces not what they are named, a fit failing its checks.

    Notes
    -----
    The accelerometer minimises :math:`\\sum_k (\\lVert (I + E_a)^{-1} (\\bar f_k - b_a)
    \\rVert - g)^2 / \\sigma_k^2` over the poses (Tedaldi et al. 2014, eqs. 9-10), or, with
    the six faces named, Ferraris et al. (1995)'s closed form; the gyro's ``E_g`` makes the
    rotation integrated over each motion carry one pose's up direction onto the next's
    (:mod:`thermocal.multipos`: the model and its sources).

    Examples
    --------
    Six faces, accelerometer only, with a +2 % x scale factor and a 30 mg y bias:

    >>> import numpy as np
    >>> from thermocal.multipos import FACES, Section, calibrate_session
    >>> rng = np.random.default_rng(0)
    >>> f = np.repeat(np.vstack([np.eye(3), -np.eye(3)])[[0, 3, 1, 4, 2, 5]] * 1000.0, 200, 0)
    >>> f = f * [1.02, 1.0, 1.0] + [0.0, 30.0, 0.0] + rng.normal(0, 0.5, f.shape)
    >>> secs = [Section(n, 200 * i, 200 * i + 200) for i, n in enumerate(FACES)]
    >>> res = calibrate_session(np.arange(1200) / 100.0, f, None, g_mg=1000.0, sections=secs)
    >>> res.accel.method, round(float(res.accel.theta[3]), -2), round(float(res.accel.theta[1]), 1)
    ('six-face', 20000.0, 30.0)
    """
    t = np.asarray(time_s, dtype=np.float64)
    a = np.asarray(accel_mg, dtype=np.float64)
    w = None if gyro_rad_s is None else np.asarray(gyro_rad_s, dtype=np.float64)
    given = sections is not None
    if sections is None:
        sections = detect_poses(t, a, w, static_s=static_s)
    statics = [s for s in sections if not s.is_turn]
    turns = [s for s in sections if s.is_turn]
    not_still = _section_warnings(statics, turns, w is not None, where, sections_from)
    if given:
        _warn_short(t, statics, static_s, where, sections_from)
    stats = pose_stats(a, w, statics)
    if len(stats) < 6:
        raise DesignError.naming(
            f"{where}: {len(stats)} static poses found (still for at least {static_s:g} s): "
            f"the accelerometer triad needs at least {_accel.MIN_POSES} distinct poses "
            "(6 with the six faces named in {poses})",
            "poses",
        )
    acc, idx = _accel_fit(stats, g_mg, where, sections_from)
    am, k2fit = _accel_model(stats, acc, idx, g_mg, accel_k2, where)
    temp = None if temperature_c is None else _mean_over(temperature_c, statics)
    gfit, gsens, gnote, subtracted = (None, None, None, False) if w is None else _gyro_stage(
        t, a, w, stats, turns, am, g_mg, latitude_deg, saturated, gyro_model, where, sections_from
    )  # fmt: skip
    return SessionResult(acc, gfit, tuple(stats), tuple(turns), g_mg, temp, not_still,
                         gsens, gnote, subtracted, k2fit)  # fmt: skip


@dataclass(frozen=True)
class MultiposValidation:
    """Held-out session figures before (raw) and after compensation: per triad, the rms
    over poses of the gravity-magnitude error [accelerometer unit] or over motions of the
    rotation-angle error [°] (and its per-axis rms, for the report's table).

    Attributes
    ----------
    triad : str
        The triad's name.
    unit : str
        Unit of the figures.
    rms_before, rms_after : float
        Rms error before and after compensation [unit].
    per_axis_before, per_axis_after : tuple of 3 float
        Per-axis rms [unit].
    n : int
        Poses or motions judged.
    what : str
        ``gravity-magnitude error`` or ``rotation-angle error``.
    outside_range_fraction : float
        Fraction of samples outside the calibrated temperature range.
    per_pose, not_judged, input_unit, count_scale, physical_unit
        As documented on each field.
    """

    triad: str
    unit: str
    rms_before: float
    rms_after: float
    per_axis_before: tuple[float, float, float]
    per_axis_after: tuple[float, float, float]
    n: int
    what: str
    outside_range_fraction: float = 0.0
    per_pose: tuple[tuple[float, ...], ...] = ()
    """Accelerometer: per pose (start, end, u_x, u_y, u_z, error before, error after): the
    compensated gravity direction (unit, body axes) and the gravity-magnitude errors
    [``unit``], for the report's poses on the sphere (not in ``to_dict``)."""
    not_judged: str = ""
    """What these figures cannot judge (a validation on one still pose), else empty."""
    input_unit: str = ""
    """The unit the triad's columns were read in (``counts`` for raw counts)."""
    count_scale: float | None = None
    """Raw counts: one count is ``count_scale`` ``physical_unit`` (the calibration's), as
    ``compensate`` applies it; None for columns already in a physical unit."""
    physical_unit: str = ""
    """The triad's own unit, the one its columns are judged in."""

    def to_dict(self) -> dict[str, Any]:
        from dataclasses import asdict

        out = asdict(self)
        del out["per_pose"]
        return out

    def rows(self) -> list[tuple[str, tuple[float, ...], tuple[float, ...]]]:
        return [
            (f"{self.what}{' rms' if self.n > 1 else ''} [{self.unit}] (total "
             f"{self.rms_before:.4g} → {self.rms_after:.4g})", self.per_axis_before,
             self.per_axis_after)
        ]  # fmt: skip


def _rms3(v: FloatArray) -> tuple[float, float, float]:
    r = np.sqrt(np.mean(v**2, axis=0))
    return (float(r[0]), float(r[1]), float(r[2]))


def gravity_errors(
    f_before: FloatArray, f_after: FloatArray, sections: Sequence[Section], g: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Per pose: |mean f| − g before and after, and that error along each axis,
    ``(|m| − g)·m/|m|`` (for the table: the axes' rms over poses add in quadrature to the
    total's, before as after), all in the unit of ``f``.

    Parameters
    ----------
    f_before, f_after : numpy.ndarray, shape (n, 3)
        Specific force before and after calibration [any unit, e.g. mg].
    sections : sequence of Section
        The static poses.
    g : float
        Local gravity in the same unit.

    Returns
    -------
    err_before, err_after : numpy.ndarray, shape (P,)
        :math:`|\\bar f| - g` per pose.
    axes_before, axes_after : numpy.ndarray, shape (P, 3)
        That error along each axis.

    Notes
    -----
    .. math:: e = |m| - g, \\qquad e_\\mathrm{axes} = e \\, m / |m|

    References
    ----------
    - D. Tedaldi, A. Pretto and E. Menegatti, "A robust and easy to implement method for
      IMU calibration without external equipments", Proc. IEEE ICRA 2014, 3042–3049.
    """
    mb = np.asarray([f_before[s.start : s.end].mean(axis=0) for s in sections])
    ma = np.asarray([f_after[s.start : s.end].mean(axis=0) for s in sections])
    nb, na = np.linalg.norm(mb, axis=1), np.linalg.norm(ma, axis=1)
    eb, ea = nb - g, na - g
    return eb, ea, mb * (eb / nb)[:, None], ma * (ea / na)[:, None]


def rotation_errors(
    rate_rad_s: FloatArray, dt_s: FloatArray, f: FloatArray, sections: Sequence[Section]
) -> FloatArray:
    """Per motion between consecutive poses, the direction error vector
    ``u_{k+1} × (A_{k+1}ᵀ A_k⁻ᵀ u_k)`` [rad] (its norm is the rotation-angle error),
    ``f`` the specific force that gives the up directions.

    Parameters
    ----------
    rate_rad_s : numpy.ndarray, shape (n, 3)
        Calibrated body rates [rad/s].
    dt_s : numpy.ndarray, shape (n,)
        Sample intervals [s].
    f : numpy.ndarray, shape (n, 3)
        Specific force [any unit].
    sections : sequence of Section
        The static poses, in time order.

    Returns
    -------
    numpy.ndarray, shape (P − 1, 3)
        Direction error per motion [rad].

    Notes
    -----
    .. math:: \\varepsilon_k = u_{k+1} \\times (A_{k+1}^\\mathsf{T} A_k^{-\\mathsf{T}} u_k)

    References
    ----------
    - D. Tedaldi, A. Pretto and E. Menegatti, "A robust and easy to implement method for
      IMU calibration without external equipments", Proc. IEEE ICRA 2014, 3042–3049.
    """
    out = []
    for p0, p1 in itertools.pairwise(sections):
        sl = slice(p0.start, p1.end)
        d = attitude_along(rate_rad_s[sl], dt_s[sl])
        a0 = d[: p0.end - p0.start].mean(axis=0)
        a1 = d[p1.start - p0.start :].mean(axis=0)
        u0 = f[p0.start : p0.end].mean(axis=0)
        u1 = f[p1.start : p1.end].mean(axis=0)
        u0, u1 = u0 / np.linalg.norm(u0), u1 / np.linalg.norm(u1)
        p = a1.T @ np.linalg.solve(a0.T, u0)
        out.append(np.cross(u1, p))
    return np.asarray(out).reshape(-1, 3)


__all__ = [
    "ACCEL_RESIDUAL_REFUSED",
    "GYRO_DIRECTION_REFUSED_DEG",
    "METHOD",
    "SCALE_FACTOR_REFUSED",
    "MultiposValidation",
    "PoseStats",
    "SessionResult",
    "calibrate_session",
    "check_accel_fit",
    "check_gyro_fit",
    "gravity_errors",
    "pose_stats",
    "rotation_errors",
]
