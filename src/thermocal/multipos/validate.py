"""A calibration of triads judged on a held-out multi-position session.

The poses are found in the held-out session as in calibration (:func:`.poses.detect_poses`
on the raw data).  Accelerometer: per pose, ``|mean f| − g`` before (raw) and after
compensation ``(I + E(T))⁻¹ (f − b(T))`` — rms over the poses in the accelerometer's
unit; per axis, the pose mean against ``g`` along its compensated direction.  Gyro (with
the accelerometer triad, which gives the up directions): per motion between consecutive
poses, the rotation-angle error ``|u_{k+1} × A_{k+1}ᵀ A_k⁻ᵀ u_k|`` [°] (:func:`.calibrate.
rotation_errors`) with raw data before and compensated data after.  ``g`` is the one the
calibration recorded (else normal gravity at the latitude).

The triads' columns enter as ``compensate`` takes them (:func:`triad_columns`): raw counts
of a triad calibrated on counts through its count scale, so the figures are in the
calibration's units.  A session of ONE still pose is judged on what it can show: the
gravity-magnitude error of that pose and the gyro's mean rate at rest before and after
[gyro unit] (per axis the signed mean; its magnitude as the total), which holds the earth
rate in a direction one pose does not give; ``not_judged`` says what needs motions or other
directions.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from thermocal import units
from thermocal.errors import ParameterError, ThermocalInputError, ThermocalWarning
from thermocal.multipos.calibrate import (
    ACCEL_RESIDUAL_REFUSED,
    GYRO_DIRECTION_REFUSED_DEG,
    METHOD,
    MultiposValidation,
    gravity_errors,
    rotation_errors,
)
from thermocal.multipos.poses import detect_poses


def triad_columns(
    rec: Any, tri: Any, unit_options: Mapping[str, str | None] | None = None
) -> tuple[Any, Any]:
    """A triad's three columns of ``rec`` in the physical unit its model takes, and how
    (:class:`~thermocal.models.calibration.TriadInput`).  Each column's unit is resolved as
    the compensation resolves it (:func:`thermocal.units.resolve_unit`: ``unit_options`` >
    the file's metadata or column name > the unit the triad was calibrated on, raw counts for
    a triad with a count scale), and raw counts become ``count_scale · N``
    (:meth:`Triad.input_in <thermocal.models.calibration.Triad.input_in>`).

    Parameters
    ----------
    rec : Recording
        The session.
    tri : Triad
        The calibrated triad whose columns are read.
    unit_options : mapping of str to str or None, optional
        Column → the unit given for it (:func:`thermocal.units.per_signal_unit`).

    Returns
    -------
    values : numpy.ndarray, shape (n, 3)
        The three columns in the model's physical unit.
    how : TriadInput
        The unit resolved and the count scale applied.

    Raises
    ------
    thermocal.errors.UnitError
        A column's unit unknown or not the triad's kind.
    thermocal.errors.ThermocalInputError
        The columns not finite once converted.
    """
    opts = unit_options or {}
    found = [
        units.resolve_unit(
            c, "signal", option=opts.get(c), metadata=rec.units.get(c) or None,
            model=tri.calibrated_unit(), where=rec.name,
        ).unit
        for c in tri.columns
    ]  # fmt: skip
    inp = tri.input_in(found, rec.name)
    x = inp.physical(np.column_stack([rec.column(c) for c in tri.columns]).astype(np.float64))
    if not np.all(np.isfinite(x)):
        raise ThermocalInputError(
            f"{rec.name}: the {tri.name} triad's columns are not finite in {inp.unit} "
            "(a count scale that overflows, or missing values)"
        )
    return x, inp


def validate_held_out_session(
    triads: Sequence[Any],
    rec: Any,
    latitude_deg: float | None = None,
    *,
    static_s: float = 1.0,
    signal_unit: str | tuple[str, ...] | None = None,
) -> list[MultiposValidation]:
    """A multi-position calibration of triads judged on a held-out session: before and
    after compensation, the gravity-magnitude error over the poses and the rotation-angle
    error over the motions between them (module docstring).

    Parameters
    ----------
    triads : sequence of Triad
        The calibration's triads; one an accelerometer (it gives the poses' up directions).
    rec : Recording
        The held-out session.
    latitude_deg : float or None, optional
        Latitude [°] for normal gravity when the calibration recorded none.
    static_s : float, optional
        Shortest still pose [s] (default 1).
    signal_unit : str or tuple of str or None, optional
        One unit for every triad column, or a tuple of one per column.

    Returns
    -------
    list of MultiposValidation
        One per triad: the figures before and after [the triad's unit or °].

    Raises
    ------
    thermocal.errors.ParameterError
        ``static_s`` not positive, a latitude needed and missing, or no still pose found.
    thermocal.errors.ThermocalInputError
        No accelerometer triad, or a column missing.

    References
    ----------
    - Tedaldi, D., Pretto, A., Menegatti, E., "A robust and easy to implement method for IMU
      calibration without external equipments", Proc. IEEE ICRA 2014, pp. 3042-3049.
    """
    by = {t.model.kind: t for t in triads}
    acc, g_m_s2 = _accel_and_gravity(by, triads, rec, latitude_deg, static_s)
    t = rec.time_s
    unit_opts = units.per_signal_unit(signal_unit, [c for tr in triads for c in tr.columns])
    temp_of = functools.partial(_temp_of, rec)

    xa, a_in = triad_columns(rec, acc, unit_opts)
    a_unit = a_in.unit
    ta = temp_of(acc)
    xa_c = acc.correct(xa, ta, a_in.to_data, a_unit)  # K2 inverted when it holds one
    gyr = by.get("gyro")
    xg = xg_c = None
    if gyr is not None:
        xg, g_in = triad_columns(rec, gyr, unit_opts)
        g_unit = g_in.unit
        tg = temp_of(gyr)
        # its g-sensitivity taken off with the accelerometer's output, as compensate does
        af = gyr.g_sensitivity_term(xa_c, a_unit, g_unit)
        xg_c = gyr.correct(xg - af, tg, g_in.to_data, g_unit)
        xg = units.convert(xg, g_unit, "rad/s")
        xg_c = units.convert(xg_c, g_unit, "rad/s")
    sections = detect_poses(t, xa, xg, static_s=static_s)
    if not sections:
        raise ParameterError(
            "static_s",
            f"{rec.name}: no still pose of {static_s:g} s or longer found: nothing to judge "
            "the calibration on (record the sensor still; {name} sets the shortest pose)",
        )
    g = float(units.convert(np.array([g_m_s2]), "m/s^2", a_unit)[0])
    out = [_accel_figures(acc.name, a_unit, xa, xa_c, sections, g, _outside(acc, ta))]
    out = _with_input(out, a_in)
    if gyr is None or xg is None or xg_c is None:
        if len(sections) == 1:
            out[0] = dataclasses.replace(out[0], not_judged=ONE_POSE_ACCEL_NOT_JUDGED)
        return _judged(out, g, rec.name)
    if len(sections) == 1:
        out[0] = dataclasses.replace(out[0], not_judged=ONE_POSE_NOT_JUDGED)
        return _judged([*out, _rate_at_rest(gyr.name, xg, xg_c, sections[0], g_in,
                                            _outside(gyr, temp_of(gyr)))], g, rec.name)  # fmt: skip
    dt = np.diff(t)
    dt = np.concatenate([dt, dt[-1:]])
    vb = rotation_errors(xg, dt, xa, sections) * units.RAD_TO_DEG
    va = rotation_errors(xg_c, dt, xa_c, sections) * units.RAD_TO_DEG
    nb, na = np.linalg.norm(vb, axis=1), np.linalg.norm(va, axis=1)
    out.append(
        MultiposValidation(
            gyr.name, "deg", float(math.sqrt(np.mean(nb**2))), float(math.sqrt(np.mean(na**2))),
            _rms3(vb), _rms3(va), len(nb), "rotation-angle error", _outside(gyr, temp_of(gyr)),
            input_unit=g_in.data_unit, count_scale=g_in.count_scale, physical_unit=g_in.unit,
        )
    )  # fmt: skip
    return _judged(out, g, rec.name)


def _judged(out: list[MultiposValidation], g: float, name: str) -> list[MultiposValidation]:
    """A warning for each figure left, after compensation, beyond what the calibration's
    own fit accepts (:data:`~thermocal.multipos.calibrate.ACCEL_RESIDUAL_REFUSED` × ``g``,
    :data:`~thermocal.multipos.calibrate.GYRO_DIRECTION_REFUSED_DEG`): the held-out
    session is not read as the calibration was made (a unit, the time's unit, another
    sensor); the figures stand as measured.  Returns ``out`` unchanged."""
    bound = {"gravity-magnitude error": (ACCEL_RESIDUAL_REFUSED * g, "the columns' unit"),
             "rotation-angle error": (GYRO_DIRECTION_REFUSED_DEG, "the gyro's unit, the "
                                      "time's ({time_unit}, {rate_hz})")}  # fmt: skip
    for v in out:
        if v.what not in bound:
            continue
        lim, what = bound[v.what]
        if not v.rms_after <= lim:
            warnings.warn(
                ThermocalWarning.naming(
                    f"{name}: the {v.triad} triad's {v.what} rms is {v.rms_after:.4g} {v.unit} "
                    f"after compensation ({v.rms_before:.4g} before), beyond the "
                    f"{lim:.4g} {v.unit} a calibration's own fit accepts: this session is not "
                    f"read as the calibration was made ({what}, the {{signal_unit}} given) "
                    "or is another sensor's",
                    *("time_unit", "rate_hz", "signal_unit"),
                ),
                stacklevel=3,
            )
    return out


ONE_POSE_ACCEL_NOT_JUDGED = (
    "one still pose: not judged are the accelerometer's scale factors and misalignments "
    "beyond this one direction (they need poses in several directions)"
)
ONE_POSE_NOT_JUDGED = (
    "one still pose: not judged are the gyro's scale factors and misalignments (the "
    "rotation-angle error needs motions between poses) and the accelerometer's scale factors "
    "and misalignments beyond this one direction (they need poses in several directions)"
)
"""What a validation on one static pose cannot judge (said beside its figures; the first
for an accelerometer triad alone)."""


def _accel_figures(
    name: str, unit: str, xa: Any, xa_c: Any, sections: Sequence[Any], g: float, out: float
) -> MultiposValidation:
    """The accelerometer's gravity-magnitude errors ``|mean f| − g`` per pose, before and
    after, rms over the poses [``unit``], and each pose's up direction."""
    eb, ea, pb, pa = gravity_errors(xa, xa_c, sections, g)
    means = np.asarray([xa_c[s.start : s.end].mean(axis=0) for s in sections])
    up = means / np.linalg.norm(means, axis=1)[:, None]
    per_pose = tuple(
        (float(s.start), float(s.end), *(float(v) for v in u), float(b), float(a))
        for s, u, b, a in zip(sections, up, eb, ea, strict=True)
    )
    return MultiposValidation(
        name, unit, float(np.sqrt(np.mean(eb**2))), float(np.sqrt(np.mean(ea**2))),
        _rms3(pb), _rms3(pa), len(sections), "gravity-magnitude error", out, per_pose,
    )  # fmt: skip


def _rate_at_rest(
    name: str, xg: Any, xg_c: Any, pose: Any, g_in: Any, out: float
) -> MultiposValidation:
    """The gyro on one still pose: its mean rate before (raw) and after compensation, per
    axis (signed) and in magnitude, in the triad's unit ``g_in.unit`` (``xg``, ``xg_c`` in
    rad/s); the earth rate it holds, named in ``not_judged``."""
    unit = g_in.unit
    mb = units.convert(xg[pose.start : pose.end].mean(axis=0), "rad/s", unit)
    ma = units.convert(xg_c[pose.start : pose.end].mean(axis=0), "rad/s", unit)
    earth = float(units.convert(np.array([units.EARTH_RATE_RAD_S]), "rad/s", unit)[0])
    note = (f"the mean rate at rest holds the earth rate, |Ω| = {earth:.4g} {unit}, in a "
            "direction one pose does not give")  # fmt: skip
    return MultiposValidation(
        name, unit, float(np.linalg.norm(mb)), float(np.linalg.norm(ma)), _vec3(mb), _vec3(ma),
        1, "mean rate at rest", out, not_judged=note, input_unit=g_in.data_unit,
        count_scale=g_in.count_scale, physical_unit=unit,
    )  # fmt: skip


def _with_input(out: list[MultiposValidation], inp: Any) -> list[MultiposValidation]:
    """The accelerometer's figures with the unit its columns were read in and the count
    scale applied (:class:`~thermocal.models.calibration.TriadInput`)."""
    return [
        dataclasses.replace(
            out[0], input_unit=inp.data_unit, count_scale=inp.count_scale, physical_unit=inp.unit
        )
    ]


def _vec3(v: Any) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _rms3(v: Any) -> tuple[float, float, float]:
    r = np.sqrt(np.mean(np.asarray(v) ** 2, axis=0))
    return (float(r[0]), float(r[1]), float(r[2]))


def _accel_and_gravity(
    by: dict[str, Any], triads: Sequence[Any], rec: Any, latitude_deg: float | None,
    static_s: float,
) -> tuple[Any, float]:  # fmt: skip
    """The accelerometer triad and local gravity [m/s²] (:func:`validate_held_out_session`'s
    checks of its inputs)."""
    if not (math.isfinite(static_s) and static_s > 0):
        raise ParameterError(
            "static_s",
            f"{rec.name}: {{name}} must be a positive number of seconds, got {static_s!r}",
        )
    acc = by.get("accel")
    if acc is None:
        raise ThermocalInputError(
            f"{rec.name}: a multi-position calibration is validated through its "
            "accelerometer triad (it gives the poses' up directions); this one has none"
        )
    rec.validate(required=[c for t in triads for c in (*t.columns, t.temperature) if c])
    lat = next((v for v in (latitude_deg, rec.meta.latitude_deg, acc.latitude_deg)
                if v is not None), None)  # fmt: skip
    g_m_s2 = acc.model.gravity_m_s2
    if g_m_s2 is None:
        if lat is None:
            raise ParameterError("latitude_deg", f"{rec.name}: give the latitude ({{name}} DEG)")
        g_m_s2 = units.normal_gravity_m_s2(float(lat))
    return acc, float(g_m_s2)


def _temp_of(rec: Any, tri: Any) -> Any:
    """The triad's temperature column [°C], else its TREF at every sample."""
    if tri.temperature:
        return rec.temperature_c(tri.temperature)
    return np.full(rec.n_samples, tri.model.tref_c)


def _outside(tri: Any, temp: Any) -> float:
    """Fraction of the samples outside the triad's calibrated temperature range."""
    return float(np.mean((temp < tri.model.t_lo_c) | (temp > tri.model.t_hi_c)))


def is_multipos(triads: Sequence[Any]) -> bool:
    """Whether a calibration of triads was made by the multi-position calibration.

    Parameters
    ----------
    triads : sequence of Triad
        The calibration's triads.

    Returns
    -------
    bool
        True when a triad's model records the multi-position method.
    """
    return any(getattr(t.model, "method", "turntable") == METHOD for t in triads)


__all__ = ["is_multipos", "triad_columns", "validate_held_out_session"]
