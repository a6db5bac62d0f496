"""Gravity as a known input of static accelerometers.

A static accelerometer triad reads the specific force of gravity plus its bias:
``f = g·u + b(T)`` [mg], ``u`` the unit vector of "up" in the body frame, ``g`` the local
gravity (WGS-84 normal gravity, :func:`thermocal.units.normal_gravity_m_s2`, or given).
A fit given ``gravity_axis`` removes ``g·u_i`` from each axis as a known input, so that the fitted
model is the bias alone and compensation keeps gravity.

**The direction is measured, not assumed.**  A bench is never exactly level: a board tilted
by 6° puts ``g·sin 6° ≈ 105 mg`` on a "horizontal" axis.  When the three axes of a triad
are fitted together, ``u`` is measured from the triad's mean specific force,
``u = f̄ / |f̄|`` (one estimate per placement, below), and axis ``i`` gets the known input
``g·u_i``.  What one placement cannot tell is a bias across gravity from a tilt: the
tangential part of the mean bias, ``b̄ − u (u·b̄)``, is taken as tilt, so the model's
constant holds the bias *along* gravity (``|f̄| − g``, known because ``g`` is) but the
horizontal biases only relative to the placement's mean.  The temperature dependence
(the slopes) is unaffected: the known input is constant within a placement.  This is why
:mod:`thermocal.export.params` writes accelerometer offsets relative to mid-range (PX4's
convention; ArduPilot's polynomial has no constant) and leaves the absolute offset to the
firmware's accelerometer calibration.

**Placements.**  Each run's mean direction ``d_r = f̄_r / |f̄_r|`` is measured; runs whose
directions lie within :data:`PLACEMENT_TOLERANCE_DEG` of a placement's direction are that
placement (a cold and a hot soak of one board on one bench), the others start another.
A placement's direction is that of the mean of its runs' mean specific forces.  Measuring
it per run instead would take the change of the horizontal biases between a cold and a
hot run for a change of tilt, and lose the horizontal axes' slopes; grouping keeps them.
A board re-seated within the tolerance is taken for the same placement (a tilt change
below 5°, ≤ 87 mg, then reads as a bias change): record such runs as one file or keep the
board in place.

**A lone channel** (or two axes of a triad) gives no direction: its known input is the
nominal ``±g`` on the up axis and 0 on the others, a ``warning:`` says the direction is
unknown, and the model records ``direction_measured: false``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal import units
from thermocal.errors import ParameterError, ThermocalInputError, ThermocalWarning

if TYPE_CHECKING:
    from thermocal.recording import FloatArray, Recording

GRAVITY_TOLERANCE_MG = 100.0
"""How far the up accelerometer's mean may be from the local gravity, a horizontal one's
from 0 (lone channels) or the triad's magnitude from g, before the orientation is doubted
[mg] (0.1 g: a 6° tilt)."""
PLACEMENT_TOLERANCE_DEG = 5.0
"""Runs whose mean gravity directions agree within this angle [°] are one placement."""
NO_GRAVITY_MG = 500.0
"""Without ``gravity_axis``, an accelerometer whose mean exceeds this [mg] has gravity in
its data (said in a warning)."""
AXES = ("x", "y", "z")


@dataclass(frozen=True)
class GravityInput:
    r"""The gravity one accelerometer channel reads in one run, as a known input.

    Attributes
    ----------
    value_mg : float
        :math:`g\,u_i` [mg]; 0 for a gyro or without an up axis.
    what : str or None
        The words of the model's known-input record; None when there is no gravity.
    record : dict or None
        The model's ``inputs.known_input.gravity`` (up axis, g [m/s²], the direction
        when measured and ``direction_measured``); None without gravity.
    """

    value_mg: float
    what: str | None = None
    record: dict[str, Any] | None = None


@dataclass(frozen=True)
class TriadGravity:
    """Gravity of one accelerometer triad over the runs of a fit.

    Attributes
    ----------
    channels : dict of str to str
        Axis letter → channel name.
    run_direction : tuple of tuple of float
        Per run, the unit vector ``u`` of its placement (x, y, z) [-].
    placement : tuple of int
        Per run, its placement's index.
    g_mg : float
        Local gravity [mg].
    g_m_s2 : float
        Local gravity [m/s²].
    gravity_axis : str
        The nominal up axis (``"+z"``, ``"-x"`` …).
    """

    channels: dict[str, str]
    run_direction: tuple[tuple[float, float, float], ...]
    placement: tuple[int, ...]
    g_mg: float
    g_m_s2: float
    gravity_axis: str

    def known_input(self, run: int, name: str) -> GravityInput:
        r"""Channel ``name``'s known input in run ``run``.

        Parameters
        ----------
        run : int
            Index of the run in the fit.
        name : str
            Channel name, one of :attr:`channels`.

        Returns
        -------
        GravityInput
            :math:`g\,u_i` [mg], with its words and record.
        """
        axis = next(a for a, n in self.channels.items() if n == name)
        u = self.run_direction[run]
        i = AXES.index(axis)
        tilt = tilt_deg(u, self.gravity_axis)
        n_place = max(self.placement) + 1
        where = (
            f"; {n_place} placements over {len(self.placement)} runs, each its own direction"
            if n_place > 1
            else ""
        )
        what = (
            f"gravity along the measured direction ({u[0]:+.5f}, {u[1]:+.5f}, {u[2]:+.5f}) "
            f"of {','.join(self.channels[a] for a in AXES)} ({self.gravity_axis} up, tilted "
            f"{tilt:.2f}°) of g = {self.g_m_s2:.7g} m/s²: {self.g_mg * u[i]:+.6g} mg on "
            f"{name}{where}"
        )
        record = {
            "up_axis": self.gravity_axis,
            "g_m_s2": self.g_m_s2,
            "direction_measured": True,
            "direction": [float(v) for v in u],
            "triad": [self.channels[a] for a in AXES],
            "tilt_deg": tilt,
            "placements": n_place,
        }
        return GravityInput(self.g_mg * u[i], what, record)


def local_gravity_m_s2(
    gravity_axis: str | None, gravity: float | None, latitude: float | None
) -> float | None:
    """The local gravity [m/s²] used with an up axis.

    Parameters
    ----------
    gravity_axis : str or None
        The sensor axis pointing up (``"+z"``, ``"-x"`` …); None: no gravity input.
    gravity : float or None
        Local gravity [m/s²], within 9.7-9.9.
    latitude : float or None
        Site latitude [°], for WGS-84 normal gravity when ``gravity`` is not given.

    Returns
    -------
    float or None
        ``gravity``, else normal gravity at ``latitude``, else standard gravity
        9.80665 m/s² (with a warning); None without ``gravity_axis``.

    Raises
    ------
    thermocal.errors.ParameterError
        ``gravity`` without ``gravity_axis``, or off the earth's 9.78-9.83 m/s².

    Notes
    -----
    WGS-84 normal gravity (Somigliana's formula, NIMA TR8350.2 eq. 4-1 [1]_):

    .. math::

        \\gamma(\\varphi) = \\gamma_e \\frac{1 + k \\sin^2\\varphi}
        {\\sqrt{1 - e^2 \\sin^2\\varphi}}

    References
    ----------
    .. [1] NIMA TR8350.2, "Department of Defense World Geodetic System 1984, its
       definition and relationships with local geodetic systems", 3rd ed., 2000.

    Examples
    --------
    >>> round(local_gravity_m_s2("+z", None, 45.0), 5)
    9.8062
    >>> local_gravity_m_s2(None, None, 45.0) is None
    True
    """
    if gravity_axis is None:
        if gravity is not None:
            raise ParameterError(
                "gravity", "{name} applies with {gravity_axis} only", ("gravity_axis",)
            )
        return None
    units.parse_gravity_axis(gravity_axis)  # refuse a bad axis before reading
    if gravity is not None:
        if not 9.7 <= gravity <= 9.9:
            raise ParameterError(
                "gravity",
                f"{{name}} {gravity:g}: local gravity on the earth's surface is 9.78-9.83 m/s²",
            )
        return float(gravity)
    if latitude is not None:
        return units.normal_gravity_m_s2(latitude)
    warnings.warn(
        ThermocalWarning.naming(
            f"{{gravity_axis}} without {{gravity}} or {{latitude}}: assuming standard gravity "
            f"{units.STANDARD_GRAVITY_M_S2} m/s² (local gravity differs by up to 0.3 %)",
            "gravity_axis",
            "gravity",
            "latitude",
        ),
        stacklevel=3,
    )
    return units.STANDARD_GRAVITY_M_S2


def nominal_up(gravity_axis: str) -> tuple[float, float, float]:
    """The unit vector of the nominal up axis.

    Parameters
    ----------
    gravity_axis : str
        The sensor axis pointing up: a sign and a letter (``"+z"``, ``"-x"`` …).

    Returns
    -------
    tuple of float
        ``(x, y, z)`` unit vector [-].

    Raises
    ------
    ParameterError
        ``gravity_axis`` is not a sign and one of x, y, z.

    Examples
    --------
    >>> nominal_up("-x")
    (-1.0, 0.0, 0.0)
    """
    letter, sign = units.parse_gravity_axis(gravity_axis)
    return tuple(sign if a == letter else 0.0 for a in AXES)  # type: ignore[return-value]


def tilt_deg(u: Sequence[float], gravity_axis: str) -> float:
    r"""Angle between a direction and the nominal up axis.

    Parameters
    ----------
    u : sequence of float
        Unit vector ``(x, y, z)`` of the measured gravity direction [-].
    gravity_axis : str
        The nominal up axis (``"+z"`` …).

    Returns
    -------
    float
        Tilt [°].

    Notes
    -----
    .. math:: \theta = \arccos(\mathbf u \cdot \mathbf e_{up})

    Examples
    --------
    >>> round(tilt_deg((0.0, 0.1045, 0.9945), "+z"), 1)
    6.0
    """
    e = nominal_up(gravity_axis)
    c = float(np.dot(np.asarray(u, dtype=np.float64), e))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def group_placements(
    means_mg: Sequence[Sequence[float]], tolerance_deg: float = PLACEMENT_TOLERANCE_DEG
) -> tuple[tuple[tuple[float, float, float], ...], tuple[int, ...]]:
    r"""Per run, the unit gravity direction of its placement and the placement's index.

    Runs are taken in order; a run joins the first placement whose direction (that
    of the mean of its runs' mean vectors) is within ``tolerance_deg`` of the run's
    own direction, else it starts a new one.  The directions returned are those of
    the final placements.

    Parameters
    ----------
    means_mg : sequence of sequence of float
        Each run's mean specific force ``(x, y, z)`` [mg].
    tolerance_deg : float, optional
        Largest angle between a run and its placement [°] (default
        :data:`PLACEMENT_TOLERANCE_DEG`, 5°).

    Returns
    -------
    directions : tuple of tuple of float
        Per run, the unit vector of its placement [-].
    placement : tuple of int
        Per run, the index of its placement.

    Notes
    -----
    .. math:: \mathbf d_r = \bar{\mathbf f}_r / |\bar{\mathbf f}_r|, \quad
        \mathbf d_r \cdot \mathbf u_P \ge \cos(\mathrm{tolerance})

    Examples
    --------
    >>> dirs, place = group_placements([(0, 0, 1000), (0, 0, 1001), (1000, 0, 0)])
    >>> place
    (0, 0, 1)
    """
    vecs = [np.asarray(m, dtype=np.float64) for m in means_mg]
    members: list[list[int]] = []
    cos_tol = math.cos(math.radians(tolerance_deg))
    for r, m in enumerate(vecs):
        d = m / np.linalg.norm(m)
        for group in members:
            s = np.mean([vecs[k] for k in group], axis=0)
            if float(np.dot(d, s / np.linalg.norm(s))) >= cos_tol:
                group.append(r)
                break
        else:
            members.append([r])
    place = [0] * len(vecs)
    dirs: list[tuple[float, float, float]] = [(0.0, 0.0, 0.0)] * len(vecs)
    for j, group in enumerate(members):
        s = np.mean([vecs[k] for k in group], axis=0)
        u = s / np.linalg.norm(s)
        for k in group:
            place[k] = j
            dirs[k] = (float(u[0]), float(u[1]), float(u[2]))
    return tuple(dirs), tuple(place)


def accel_triad(names: Sequence[str | None], unit_of: Mapping[str, str]) -> dict[str, str] | None:
    """Axis → channel of the accelerometer triad among the fitted channels.

    Parameters
    ----------
    names : sequence of str or None
        The fitted channels (None entries are skipped).
    unit_of : mapping of str to str
        Channel name → its unit; the kind is read from the unit and the axis from the
        trailing letter (:func:`thermocal.models.calibration.guess_role`).

    Returns
    -------
    dict of str to str or None
        ``{"x": name, "y": name, "z": name}``; None unless exactly one accelerometer
        channel per axis.
    """
    from thermocal.models.calibration import guess_role

    found: dict[str, list[str]] = {a: [] for a in AXES}
    for n in names:
        if n is None or n not in unit_of:
            continue
        role = guess_role(n, unit_of[n]) or {}
        if role.get("kind") == "accel" and role.get("axis") in AXES:
            found[str(role["axis"])].append(n)
    if all(len(v) == 1 for v in found.values()):
        return {a: v[0] for a, v in found.items()}
    return None


def _finite_mean(values: FloatArray, path: Path | str, name: str) -> float:
    finite = np.isfinite(values)
    if not finite.any():
        raise ThermocalInputError(f"{path}: {name} has no finite value")
    return float(np.mean(values[finite]))


def triad_gravity(
    loaded: Sequence[tuple[Path, Recording]],
    names: Sequence[str | None],
    gravity_axis: str | None,
    g_m_s2: float | None,
) -> TriadGravity | None:
    r"""The measured gravity of the accelerometer triad over the runs of a fit.

    Each run is checked: the up axis within :data:`GRAVITY_TOLERANCE_MG` of ±g (else
    an error: the wrong axis or unit), the magnitude within it of g (else a warning:
    a bias of that size along gravity is doubtful).

    Parameters
    ----------
    loaded : sequence of (Path, Recording)
        The runs of the fit, with their paths.
    names : sequence of str or None
        The fitted channels.
    gravity_axis : str or None
        The sensor axis pointing up (``"+z"`` …); None: no gravity.
    g_m_s2 : float or None
        Local gravity [m/s²] (:func:`local_gravity_m_s2`).

    Returns
    -------
    TriadGravity or None
        None without ``gravity_axis`` or without a full triad.

    Raises
    ------
    ParameterError
        (``gravity_axis``) the up axis's mean is more than 100 mg from ±g.
    ThermocalInputError
        A triad channel has no finite value.

    Notes
    -----
    .. math:: \mathbf u = \bar{\mathbf f} / |\bar{\mathbf f}|, \quad g_{mg} = 1000\,g / g_0

    with :math:`g_0` = 9.80665 m/s² and one :math:`\mathbf u` per placement
    (:func:`group_placements`).
    """
    if gravity_axis is None or g_m_s2 is None or not loaded:
        return None
    first = loaded[0][1]
    unit_of = {n: first.signal(n)[1] for n in names if n is not None}
    chans = accel_triad(names, unit_of)
    if chans is None:
        return None
    g_mg = 1000.0 * g_m_s2 / units.STANDARD_GRAVITY_M_S2
    letter, sign = units.parse_gravity_axis(gravity_axis)
    means: list[list[float]] = []
    for path, rec in loaded:
        m = [_finite_mean(rec.signal(chans[a])[0], path, chans[a]) for a in AXES]
        up = m[AXES.index(letter)]
        if abs(up - sign * g_mg) > GRAVITY_TOLERANCE_MG:
            raise ParameterError(
                "gravity_axis",
                f"{path}: {{name}} {gravity_axis}: {chans[letter]} should read about "
                f"{sign * g_mg:+.1f} mg but reads {up:.1f} mg on average; is {gravity_axis} "
                "the axis pointing up, and the unit right?",
            )
        mag = math.sqrt(sum(v * v for v in m))
        if abs(mag - g_mg) > GRAVITY_TOLERANCE_MG:
            warnings.warn(
                f"{path}: the accelerometer triad reads {mag:.1f} mg of specific force on "
                f"average, {mag - g_mg:+.1f} mg from the local gravity {g_mg:.1f} mg: a bias "
                "that large along gravity is doubtful (is every axis's unit right?)",
                ThermocalWarning,
                stacklevel=2,
            )
        means.append(m)
    dirs, place = group_placements(means)
    if max(place) > 0:
        groups = [
            ", ".join(loaded[k][0].name for k in range(len(place)) if place[k] == j)
            for j in range(max(place) + 1)
        ]
        warnings.warn(
            f"the runs were recorded in {len(groups)} placements (gravity directions more "
            f"than {PLACEMENT_TOLERANCE_DEG:g}° apart: {'; '.join(groups)}): each has its own "
            "measured direction, and a horizontal bias that differs between placements is "
            "taken for their tilt",
            ThermocalWarning,
            stacklevel=2,
        )
    return TriadGravity(dict(chans), dirs, place, g_mg, g_m_s2, gravity_axis)


def _warn_lone_channel(
    path: Path | str, name: str, mean: float, g_mg: float, gravity_axis: str, run: int
) -> None:
    """Warnings of a channel fitted without its triad: tilt of a horizontal axis, no direction."""
    off = mean - g_mg
    if g_mg == 0.0 and abs(off) > GRAVITY_TOLERANCE_MG:
        tilt = math.degrees(math.asin(min(1.0, abs(mean) / 1000.0)))
        warnings.warn(
            f"{path}: {name} is horizontal with {gravity_axis} up but reads {mean:.1f} "
            f"mg (a tilt of about {tilt:.0f}°): its share of gravity stays in the model's "
            "constant",
            ThermocalWarning,
            stacklevel=3,
        )
    if run == 0:
        warnings.warn(
            ThermocalWarning.naming(
                f"{{gravity_axis}} {gravity_axis}: {name} is fitted without the other axes of "
                "its accelerometer triad, so the gravity direction is unknown: its known input "
                f"assumes {gravity_axis} exactly up ({g_mg:+.1f} mg) and a tilt's share of "
                "gravity stays in the model's constant; export-params writes no absolute "
                "accelerometer offset from it (fit x, y and z together to measure the "
                "direction)",
                "gravity_axis",
            ),
            stacklevel=3,
        )


def channel_gravity(
    triad: TriadGravity | None,
    run: int,
    path: Path | str,
    name: str,
    unit: str,
    values_mg: FloatArray,
    gravity_axis: str | None,
    g_m_s2: float | None,
) -> GravityInput:
    r"""The gravity a channel reads in one run [mg], as a known input.

    Not an accelerometer: 0.  Without an up axis: 0 (with a warning when its mean
    exceeds :data:`NO_GRAVITY_MG`).  A channel of the measured ``triad``:
    :math:`g\,u_i`.  Otherwise ±g on the nominal up axis and 0 on the others, with a
    warning that the direction is not measured.

    Parameters
    ----------
    triad : TriadGravity or None
        The measured triad (:func:`triad_gravity`).
    run : int
        Index of the run.
    path : Path or str
        The run's file, named in messages.
    name, unit : str
        Channel name and its canonical unit.
    values_mg : numpy.ndarray
        The channel's samples [mg].
    gravity_axis : str or None
        The sensor axis pointing up; None: no gravity.
    g_m_s2 : float or None
        Local gravity [m/s²].

    Returns
    -------
    GravityInput

    Raises
    ------
    ParameterError
        (``gravity_axis``) a channel naming no axis, or an up axis more than 100 mg
        from ±g.
    """
    if units.signal_kind(unit) != "accel":
        return GravityInput(0.0)
    if gravity_axis is None or g_m_s2 is None:
        mean = _finite_mean(values_mg, path, name)
        if abs(mean) > NO_GRAVITY_MG:
            warnings.warn(
                ThermocalWarning.naming(
                    f"{path}: {name} reads {mean:.1f} mg on average: gravity is in the data; "
                    "without {gravity_axis} the model's constant holds it and compensation "
                    f"takes it out ({name}_comp ≈ 0); give {{gravity_axis}} (the axis pointing "
                    "up)",
                    "gravity_axis",
                ),
                stacklevel=2,
            )
        return GravityInput(0.0)
    if triad is not None and name in triad.channels.values():
        return triad.known_input(run, name)
    from thermocal.models.calibration import guess_role

    letter = (guess_role(name, unit) or {}).get("axis")
    if letter is None:
        raise ParameterError(
            "gravity_axis",
            f"{{name}} {gravity_axis}: channel {name!r} names no axis (x, y or z "
            "as its last letter); fit it with {known_input} instead",
            ("known_input",),
        )
    mean = _finite_mean(values_mg, path, name)
    g_mg = units.gravity_on_axis_mg(letter, gravity_axis, g_m_s2)
    off = mean - g_mg
    if g_mg != 0.0 and abs(off) > GRAVITY_TOLERANCE_MG:
        raise ParameterError(
            "gravity_axis",
            f"{path}: {{name}} {gravity_axis}: {name} should read about "
            f"{g_mg:+.1f} mg but reads {mean:.1f} mg on average; is {gravity_axis} the "
            "axis pointing up, and the unit right?",
        )
    _warn_lone_channel(path, name, mean, g_mg, gravity_axis, run)
    what = (
        f"gravity {g_mg:+.6g} mg ({gravity_axis} up, g = {g_m_s2:.7g} m/s²; direction not "
        "measured: a tilt's share of gravity is in the constant)"
    )
    record = {
        "up_axis": gravity_axis,
        "g_m_s2": g_m_s2,
        "direction_measured": False,
        "direction": None,
    }
    return GravityInput(g_mg, what, record)


__all__ = [
    "GRAVITY_TOLERANCE_MG",
    "PLACEMENT_TOLERANCE_DEG",
    "GravityInput",
    "TriadGravity",
    "accel_triad",
    "channel_gravity",
    "group_placements",
    "local_gravity_m_s2",
    "nominal_up",
    "tilt_deg",
    "triad_gravity",
]
