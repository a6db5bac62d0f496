"""Static poses of a multi-position session: found from the data or named in a POSES file.

Detection (:func:`find_poses`), judged against the sensor's own noise and the motion around
the poses.  The moving-window variance ``v_j`` of each accelerometer axis (and of each gyro
axis when given) over a centred window of ``w = max(5, round(window_s · rate))`` samples,
from running sums.  Each axis's **noise floor** ``σ_j²`` is the 10th percentile of ``v_j``
over the record divided by the 10 % point of ``χ²_{w−1}/(w−1)`` (Wilson–Hilferty), so that it
is the white-noise variance itself when at least a tenth of the session is still.  The
**motion** is the 90th percentile of ``Σ_j v_j``.  A sample is still where, for each sensor,

    Σ_j v_j  <  max( threshold · Σ_j σ_j² ,  motion_fraction · motion )

(``still_threshold``, default 5; ``motion_fraction``, default 0.01): below a few times
the noise, or — for a hand-held board, whose tremor is many times a quiet sensor's noise
but far below the moves between poses — below a hundredth of the motions' variance
(a tenth of their rms), so that a low-noise and a noisier sensor on the same board find
the same poses.  A pose is a run of still samples at least ``static_s`` long (a sample
is still only when its whole centred window is, so a run already keeps ``w/2`` samples
away from the motions on either side); shorter pauses are *rejected, too short*, and a
run whose gravity direction turns more than ``drift_deg`` (default 2°) between its first
and last thirds is *rejected, moving* (a slow turn, which the window variance hardly
sees); a stretch of at least ``static_s`` below ten times the limit that holds no pose is
*rejected, tremor* (the sensor and how far above the limit it sat are named).  Each pose
carries its mean window variance over the accelerometer's noise floor (≈ 1 when still;
more: tremor).

POSES file (imucal's session list): ``{"name": {"start": i, "end": j}, …}`` by sample
index, ``end`` exclusive (imucal's example file), or the same list as pandas writes it
(``section_list.to_json()``: ``{"start": {"name": i, …}, "end": {"name": j, …}}``);
``x_p``, ``x_a``, ``y_p``, ``y_a``, ``z_p``, ``z_a`` are the six faces (that axis up /
down), ``x_rot``, ``y_rot``, ``z_rot`` full 360° turns about that sensor axis (the
Ferraris method), whatever pose comes before them (users turn after the six faces);
any other name is a static pose.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal import defaults
from thermocal.errors import ParameterError, ThermocalInputError, spell_parameters

FloatArray = npt.NDArray[np.float64]

FACES: Final = ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a")
"""Names of the six faces: axis ``x`` up (``_p``) or down (``_a``), …"""
TURNS: Final = ("x_rot", "y_rot", "z_rot")
"""Names of the 360° turns about each axis (Ferraris et al. 1995)."""
WINDOW_S: Final = defaults.POSE_WINDOW_S
"""Default variance window [s] (``window_s``)."""
STILL_THRESHOLD: Final = defaults.POSE_STILL_THRESHOLD
"""Default still limit in multiples of the noise floor (``still_threshold``)."""
MOTION_FRACTION: Final = defaults.POSE_MOTION_FRACTION
"""Default still limit as a fraction of the motions' variance (``motion_fraction``)."""
DRIFT_DEG: Final = defaults.POSE_DRIFT_DEG
"""Default largest turn of the gravity direction across a pose [°] (``drift_deg``)."""
PERCENTILE: Final = 10.0
"""The noise floor is read at this percentile of the window variance, the motion at
``100 −`` it."""


@dataclass(frozen=True)
class Section:
    """Samples ``start … end − 1`` of a session, named (``pose_3``, ``x_p``, ``z_rot``).

    Attributes
    ----------
    name : str
        The section's name.
    start, end : int
        Sample indices, ``end`` exclusive.
    still_ratio : float
        Mean window variance over the noise floor [-].
    """

    name: str
    start: int
    end: int
    still_ratio: float = 1.0
    """The section's mean window variance over the record's noise floor (≈ 1 when still)."""

    @property
    def n(self) -> int:
        return self.end - self.start

    @property
    def is_turn(self) -> bool:
        return self.name in TURNS


@dataclass(frozen=True)
class Rejected:
    """Samples ``start … end − 1`` that looked still but are not a pose, and why.

    Attributes
    ----------
    start, end : int
        The samples rejected, ``end`` exclusive.
    template : str
        Why, with ``{parameter}`` where a parameter of :func:`find_poses` that changes it
        is named.
    parameters : tuple of str
        The parameters ``template`` names.
    """

    start: int
    end: int
    template: str
    parameters: tuple[str, ...] = ()

    @property
    def reason(self) -> str:
        """Why, naming the parameters of :func:`find_poses` (``static_s``)."""
        return self.spelled()

    def spelled(self, spell: Callable[[str], str] | None = None) -> str:
        """Why, with ``spell(parameter)`` for each parameter named.

        Parameters
        ----------
        spell : callable, optional
            What to show for a parameter (the command line: its option); default the
            parameter's own name.

        Returns
        -------
        str
        """
        return spell_parameters(self.template, self.parameters, spell)


def _running_variance(x: FloatArray, w: int) -> FloatArray:
    """Variance over a centred window of ``w`` samples, summed over columns (edges: the
    nearest full window)."""
    n = x.shape[0]
    xc = x - x.mean(axis=0)
    c1 = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(xc, axis=0)])
    c2 = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(xc * xc, axis=0)])
    s1 = c1[w:] - c1[:-w]
    s2 = c2[w:] - c2[:-w]
    v = np.maximum(s2 / w - (s1 / w) ** 2, 0.0).sum(axis=1)  # windows starting at 0 … n − w
    out = np.empty(n)
    h = w // 2
    out[h : h + v.size] = v
    out[:h] = v[0]
    out[h + v.size :] = v[-1]
    return out


def _axis_variances(x: FloatArray, w: int) -> FloatArray:
    """(n, k) variance of each column over a centred window of ``w`` samples."""
    return np.column_stack([_running_variance(x[:, [j]], w) for j in range(x.shape[1])])


def _chi2_low_quantile(dof: int, z: float = -1.2815515655446004) -> float:
    """``χ²_dof`` quantile over ``dof`` at the normal quantile ``z`` (default the 10 %
    point), by the Wilson–Hilferty cube (Johnson, Kotz & Balakrishnan 1994, eq. 18.24):
    the 10th percentile of the window variance of white noise is this fraction of it."""
    c = 2.0 / (9.0 * dof)
    return float(max(1.0 - c + z * math.sqrt(c), 0.05) ** 3)


@dataclass(frozen=True)
class _Limit:
    """One sensor's stillness limit: its noise floor per axis [unit²], the limit on the
    window variance summed over axes [unit²] and what set it (``noise`` or ``motion``)."""

    floor: FloatArray
    limit: float
    motion: float
    source: str


@dataclass(frozen=True)
class PoseDetection:
    """What :func:`find_poses` found: the poses, the stretches rejected (too short, moving),
    the window [samples] and sample interval [s], each sensor's noise floor and still limit
    [its unit²] and the options that set them.

    Attributes
    ----------
    poses : tuple of Section
        The poses found.
    rejected : tuple of Rejected
        The stretches rejected and why.
    window : int
        The variance window [samples].
    dt_s : float
        Sample interval [s].
    accel, gyro : _Limit
        Each sensor's noise floor and still limit [its unit²] (gyro None without it).
    threshold, motion_fraction : float
        The still limit's parameters [-].
    static_s : float
        The shortest pose [s].
    """

    poses: tuple[Section, ...]
    rejected: tuple[Rejected, ...]
    window: int
    dt_s: float
    accel: _Limit
    gyro: _Limit | None
    threshold: float
    motion_fraction: float
    static_s: float

    def to_dict(
        self,
        accel_factor: float = 1.0,
        gyro_factor: float = 1.0,
        spell: Callable[[str], str] | None = None,
    ) -> dict[str, Any]:
        """The detection as JSON types; ``*_factor`` multiply a standard deviation into the
        data's unit (variances by its square); ``spell`` writes the parameters a rejection
        names (:meth:`Rejected.spelled`).

        Parameters
        ----------
        accel_factor, gyro_factor : float
            Factors from the stored standard deviations into the data's units.
        spell : callable, optional
            What to show for a parameter a rejection names (default its own name).

        Returns
        -------
        dict
        """
        out: dict[str, Any] = {
            "window_s": self.window * self.dt_s,
            "still_threshold": self.threshold,
            "motion_fraction": self.motion_fraction,
            "static_s": self.static_s,
            "n_poses": len(self.poses),
            "rejected": [
                {"start": r.start, "end": r.end, "duration_s": (r.end - r.start) * self.dt_s,
                 "reason": r.spelled(spell)}
                for r in self.rejected
            ],
        }  # fmt: skip
        for kind, lim, f in (("accel", self.accel, accel_factor), ("gyro", self.gyro, gyro_factor)):
            if lim is None:
                continue
            out[kind] = {
                "noise_sigma": (np.sqrt(lim.floor) * f).tolist(),
                "motion_rms": math.sqrt(lim.motion) * f,
                "still_limit_rms": math.sqrt(lim.limit) * f,
                "limit_set_by": lim.source,
            }
        return out


def _limit(v: FloatArray, w: int, threshold: float, motion_fraction: float) -> _Limit:
    """Noise floor of each axis: the 10th percentile of its window variance over the record
    corrected by the χ² 10 % point (at least a tenth of the session is still); the motion:
    the 90th percentile of the summed variance.  Limit: ``max(threshold·Σ floor,
    motion_fraction·motion)``."""
    q = _chi2_low_quantile(max(w - 1, 1))
    floor = np.percentile(v, PERCENTILE, axis=0) / q
    tiny = float(np.max(v)) * 1e-12 + 1e-300
    floor = np.maximum(floor, tiny)
    motion = float(np.percentile(v.sum(axis=1), 100 - PERCENTILE))
    by_noise = threshold * float(floor.sum())
    by_motion = motion_fraction * motion
    if by_motion > by_noise:
        return _Limit(floor, by_motion, motion, "motion")
    return _Limit(floor, by_noise, motion, "noise")


def _drift_deg(a: FloatArray) -> float:
    """Angle [°] between the mean direction of the first and of the last third of ``a``."""
    k = max(1, a.shape[0] // 3)
    u0, u1 = a[:k].mean(axis=0), a[-k:].mean(axis=0)
    n0, n1 = float(np.linalg.norm(u0)), float(np.linalg.norm(u1))
    if not (n0 > 0 and n1 > 0):
        return 0.0
    c = float(np.clip(u0 @ u1 / (n0 * n1), -1.0, 1.0))
    return math.degrees(math.acos(c))


TREMOR_FACTOR: Final = 10.0
"""A stretch of at least ``static_s`` whose variance stays below this many times the still
limit, and that holds no pose, is reported as rejected for tremor."""


def _runs(
    a: FloatArray,
    still: npt.NDArray[np.bool_],
    score: FloatArray,
    w: int,
    min_n: int,
    dt: float,
    static_s: float,
    drift_deg: float,
) -> tuple[list[Section], list[Rejected]]:
    """The runs of still samples: poses, or rejected as too short or moving."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    poses: list[Section] = []
    rejected: list[Rejected] = []
    for s0, e0 in zip(edges[0::2], edges[1::2], strict=True):
        s, e = int(s0), int(e0)
        if e - s < min_n:
            if e - s >= w:  # a real pause, not a crossing of the limit
                rejected.append(Rejected(s, e, (
                    f"too short: {(e - s) * dt:.3g} s still < {{static_s}} {static_s:g} s"
                ), ("static_s",)))  # fmt: skip
            continue
        turn = _drift_deg(a[s:e])
        if turn > drift_deg:
            rejected.append(Rejected(s, e, (
                f"moving: the gravity direction turns {turn:.3g}° across it "
                f"(> {{drift_deg}} {drift_deg:g})"
            ), ("drift_deg",)))  # fmt: skip
            continue
        poses.append(Section(f"pose_{len(poses) + 1}", s, e, float(np.mean(score[s:e]))))
    return poses, rejected


def _tremor(
    ratio: dict[str, FloatArray], poses: list[Section], rejected: list[Rejected], min_n: int
) -> list[Rejected]:
    """Stretches of at least ``min_n`` samples below :data:`TREMOR_FACTOR` times the still
    limit (``ratio``: each sensor's window variance over its limit) that overlap no pose
    and no stretch already rejected: rejected for tremor, with the sensor and factor."""
    worst = np.max(np.vstack(list(ratio.values())), axis=0)
    calm = worst < TREMOR_FACTOR
    edges = np.flatnonzero(np.diff(np.concatenate([[0], calm.astype(np.int8), [0]])))
    taken = [(p.start, p.end) for p in poses] + [(r.start, r.end) for r in rejected]
    out = []
    for s0, e0 in zip(edges[0::2], edges[1::2], strict=True):
        s, e = int(s0), int(e0)
        if e - s < min_n or any(a < e and s < b for a, b in taken):
            continue
        name, frac, p90 = max(
            ((k, float(np.mean(v[s:e] >= 1.0)), float(np.percentile(v[s:e], 90)))
             for k, v in ratio.items()),
            key=lambda kv: kv[1],
        )  # fmt: skip
        out.append(Rejected(s, e, (
            f"tremor: the {name}'s variance above the still limit in {frac:.0%} of it (90th "
            f"percentile {p90:.3g}× the limit); raise {{motion_fraction}} or "
            "{still_threshold} to take it"
        ), ("motion_fraction", "still_threshold")))  # fmt: skip
    return out


def find_poses(
    time_s: npt.ArrayLike,
    accel: npt.ArrayLike,
    gyro: npt.ArrayLike | None = None,
    *,
    static_s: float = 1.0,
    window_s: float = WINDOW_S,
    still_threshold: float = STILL_THRESHOLD,
    motion_fraction: float = MOTION_FRACTION,
    drift_deg: float = DRIFT_DEG,
) -> PoseDetection:
    """Static poses found from the data, with the stretches rejected and why.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Sample times [s], at least 10 samples.
    accel, gyro : array_like, shape (n, 3)
        Accelerometer samples in any unit (directions are judged on them); gyro samples in
        any unit or None (when given, a still sample is still for both sensors).
    static_s, window_s : float, optional
        The shortest pose and the moving-variance window [s].
    still_threshold : float, optional
        The still limit in multiples of the noise floor.
    motion_fraction : float, optional
        The still limit as a fraction of the motions' variance, in [0, 1).
    drift_deg : float, optional
        The largest turn of the gravity direction across a pose [°].

    Returns
    -------
    PoseDetection
        The poses (:class:`Section`), the stretches rejected (too short, moving, tremor) and
        each sensor's noise floor and still limit.

    Raises
    ------
    thermocal.errors.ParameterError
        A parameter out of its range (named as in this signature).

    Notes
    -----
    A sample is still where, for each sensor, :math:`\\sum_j v_j < \\max(t \\sum_j
    \\sigma_j^2,\\ f m)`: ``v_j`` the moving variance of axis ``j``, ``σ_j²`` its noise
    floor, ``m`` the motions' variance, ``t`` = ``still_threshold``, ``f`` =
    ``motion_fraction`` (module docstring; the static detector of Tedaldi et al. 2014).

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(800) / 100.0
    >>> a = np.tile([0.0, 0.0, 1000.0], (800, 1)) + rng.normal(0.0, 1.0, (800, 3))
    >>> a[300:500] += 300.0 * np.sin(np.linspace(0, np.pi, 200))[:, None]
    >>> len(find_poses(t, a).poses)
    2
    """
    t = np.asarray(time_s, dtype=np.float64)
    a = np.asarray(accel, dtype=np.float64)
    n = t.size
    if n < 10:
        raise ThermocalInputError(f"{n} samples: too short for a multi-position session")
    threshold = still_threshold
    for name, val in (("static_s", static_s), ("window_s", window_s),
                      ("still_threshold", threshold), ("drift_deg", drift_deg)):  # fmt: skip
        if not (math.isfinite(val) and val > 0):
            raise ParameterError(name, f"{{name}} must be a positive number, got {val!r}")
    if not (math.isfinite(motion_fraction) and 0 <= motion_fraction < 1):
        raise ParameterError(
            "motion_fraction", f"{{name}} must be in [0, 1), got {motion_fraction!r}"
        )
    dt = float(np.median(np.diff(t)))
    w = min(max(5, round(window_s / dt)), max(2, n // 4))
    va = _axis_variances(a, w)
    lim_a = _limit(va, w, threshold, motion_fraction)
    still = va.sum(axis=1) < lim_a.limit
    lim_g = None
    vg = va
    if gyro is not None:
        vg = _axis_variances(np.asarray(gyro, dtype=np.float64), w)
        lim_g = _limit(vg, w, threshold, motion_fraction)
        still &= vg.sum(axis=1) < lim_g.limit
    score = (va / lim_a.floor).mean(axis=1)
    min_n = max(2, round(static_s / dt))
    poses, rejected = _runs(a, still, score, w, min_n, dt, static_s, drift_deg)
    ratio = {"accelerometer": va.sum(axis=1) / lim_a.limit}
    if lim_g is not None:
        ratio["gyro"] = vg.sum(axis=1) / lim_g.limit
    rejected += _tremor(ratio, poses, rejected, min_n)
    rejected.sort(key=lambda r: r.start)
    return PoseDetection(tuple(poses), tuple(rejected), w, dt, lim_a, lim_g, threshold,
                         motion_fraction, static_s)  # fmt: skip


def detect_poses(
    time_s: npt.ArrayLike,
    accel: npt.ArrayLike,
    gyro: npt.ArrayLike | None = None,
    *,
    static_s: float = 1.0,
    window_s: float = WINDOW_S,
    still_threshold: float = STILL_THRESHOLD,
) -> list[Section]:
    """The poses of :func:`find_poses` alone (its defaults for the parameters not named here).

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Sample times [s].
    accel, gyro : array_like, shape (n, 3)
        Accelerometer samples in any unit; gyro samples in any unit or None.
    static_s, window_s : float, optional
        The shortest pose and the moving-variance window [s].
    still_threshold : float, optional
        The still limit in multiples of the noise floor [-].

    Returns
    -------
    list of Section
        The poses found, in time order (sample indices, ``end`` exclusive).

    Raises
    ------
    thermocal.errors.ParameterError
        A parameter out of its range.

    References
    ----------
    - Tedaldi, D., Pretto, A., Menegatti, E., "A robust and easy to implement method for IMU
      calibration without external equipments", Proc. IEEE ICRA 2014, pp. 3042-3049
      (static-interval detection).
    """
    det = find_poses(time_s, accel, gyro, static_s=static_s, window_s=window_s,
                     still_threshold=still_threshold)  # fmt: skip
    return list(det.poses)


def _by_section(d: Any, where: str) -> Any:
    """``{"start": {name: i}, "end": {name: j}}`` (pandas' column orientation of imucal's
    section list) turned into ``{name: {"start": i, "end": j}}``; anything else as is."""
    if not (isinstance(d, dict) and set(d) == {"start", "end"}
            and all(isinstance(v, dict) for v in d.values())):  # fmt: skip
        return d
    if set(d["start"]) != set(d["end"]):
        odd = sorted(set(d["start"]) ^ set(d["end"]))
        raise ThermocalInputError(f"{where}: sections {odd} have a start or an end only")
    return {n: {"start": d["start"][n], "end": d["end"][n]} for n in d["start"]}


def parse_poses(d: Any, n_samples: int, where: str = "poses") -> list[Section]:
    """The sections of a POSES object (module docstring), in order of ``start``.

    Parameters
    ----------
    d : dict
        ``{name: {"start": i, "end": j}}`` by sample index, ``end`` exclusive, or pandas'
        column orientation ``{"start": {name: i}, "end": {name: j}}`` (imucal's section
        list, Ferraris et al. 1995's faces and turns by name).
    n_samples : int
        Samples of the recording the indices refer to.
    where : str
        The file named in messages.

    Returns
    -------
    list of Section
        Sorted by ``start``; a section named ``x_rot``, ``y_rot`` or ``z_rot`` is a turn.
    """
    d = _by_section(d, where)
    if not isinstance(d, dict) or not d:
        raise ThermocalInputError(f"{where}: expected an object of named sections")
    out = []
    for name, v in d.items():
        if not (isinstance(v, dict) and isinstance(v.get("start"), int)
                and isinstance(v.get("end"), int)):  # fmt: skip
            raise ThermocalInputError(
                f"{where}: section {name!r} needs integer 'start' and 'end' sample indices"
            )
        s, e = int(v["start"]), int(v["end"])
        if not 0 <= s < e <= n_samples:
            raise ThermocalInputError(
                f"{where}: section {name!r} ({s}…{e}) is outside the recording's "
                f"{n_samples} samples or empty (a POSES file of another session? its "
                "sections are sample indices of the session file given)"
            )
        out.append(Section(str(name), s, e))
    out.sort(key=lambda sec: sec.start)
    for a, b in itertools.pairwise(out):
        if b.start < a.end:
            raise ThermocalInputError(f"{where}: sections {a.name!r} and {b.name!r} overlap")
    return out


__all__ = [
    "FACES",
    "TURNS",
    "PoseDetection",
    "Rejected",
    "Section",
    "detect_poses",
    "find_poses",
    "parse_poses",
]
