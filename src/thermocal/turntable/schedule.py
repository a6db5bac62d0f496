"""The 16-position schedule of CN104880182 and its recognition in recorded encoder angles.

Positions (α, β) relative to the starting angles (α0, β0), in the source's order
(CN104880182, claim 3)::

    (0,0) (90,0) (180,0) (270,0) (0,180) (90,180) (180,180) (270,180)
    (90,90) (270,90) (0,90) (180,90) (270,270) (90,270) (180,270) (0,270)

Between positions the mechanism makes single-axis moves at a set rate (inner axis
first, then outer, with a short settle between them), the shorter way round
(a half turn goes positive).  A dwell of at least 60 s is held at each position.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import DesignError, GapWarning, ThermocalWarning

FloatArray = npt.NDArray[np.float64]

POSITIONS_16: Final = (
    (0.0, 0.0),
    (90.0, 0.0),
    (180.0, 0.0),
    (270.0, 0.0),
    (0.0, 180.0),
    (90.0, 180.0),
    (180.0, 180.0),
    (270.0, 180.0),
    (90.0, 90.0),
    (270.0, 90.0),
    (0.0, 90.0),
    (180.0, 90.0),
    (270.0, 270.0),
    (90.0, 270.0),
    (180.0, 270.0),
    (0.0, 270.0),
)
"""The sixteen (α − α0, β − β0) positions of the source document [°]."""


class TurntableScheduleError(DesignError):
    """The recording does not contain the turntable design the calibration needs
    (too few positions, dwells shorter than asked, an axis that never moves)."""


class TurntableWarning(ThermocalWarning):
    """Something in a turntable run weakens the calibration but does not stop it."""


@dataclass(frozen=True)
class Schedule:
    """A piecewise-linear gimbal trajectory.

    Attributes
    ----------
    time_s, alpha_deg, beta_deg : knots; angles are linear between them [s], [°].
    dwell_windows_s : (start, end) of the dwell at each position [s], (n_pos, 2).
    positions_deg : commanded (α, β) of each position [°], (n_pos, 2).
    """

    time_s: FloatArray
    alpha_deg: FloatArray
    beta_deg: FloatArray
    dwell_windows_s: FloatArray
    positions_deg: FloatArray

    @property
    def duration_s(self) -> float:
        """Length of the trajectory [s] (time of the last knot)."""
        return float(self.time_s[-1])

    def angles_at(self, t_s: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Unwrapped (α, β) at times ``t_s`` (linear interpolation of the knots).

        Parameters
        ----------
        t_s : array_like
            Times [s].

        Returns
        -------
        alpha_deg, beta_deg : numpy.ndarray
            Inner and outer gimbal angles [°], unwrapped.

        Examples
        --------
        >>> sch = build_schedule(dwell_s=60.0, move_rate_deg_s=10.0)
        >>> [round(float(v), 3) for v in sch.angles_at(30.0)]  # first dwell: (0, 0)
        [0.0, 0.0]
        """
        t = np.asarray(t_s, dtype=np.float64)
        return (
            np.interp(t, self.time_s, self.alpha_deg),
            np.interp(t, self.time_s, self.beta_deg),
        )


def _signed_step(delta_deg: float) -> float:
    """Shortest signed rotation for a change of angle, half turns positive [°]."""
    d = (delta_deg + 180.0) % 360.0 - 180.0
    return 180.0 if d == -180.0 else d


def build_schedule(
    *,
    alpha0_deg: float = 0.0,
    beta0_deg: float = 0.0,
    dwell_s: float = 60.0,
    move_rate_deg_s: float = 10.0,
    settle_s: float = 1.0,
    positions_deg: tuple[tuple[float, float], ...] = POSITIONS_16,
) -> Schedule:
    """The sixteen-position schedule of the dual-axis turntable source document [1]_.

    Parameters
    ----------
    alpha0_deg, beta0_deg : float, optional
        The inner- and outer-axis starting angles [°].
    dwell_s : float, optional
        The dwell at each position [s].
    move_rate_deg_s : float, optional
        The rate of the single-axis moves [°/s] (α first, then β).
    settle_s : float, optional
        The pause between the α and the β move [s].
    positions_deg : tuple of (float, float), optional
        The (α − α0, β − β0) positions [°] (default: :data:`POSITIONS_16`).

    Returns
    -------
    Schedule
        The angle knots against time and the dwell windows.

    Raises
    ------
    thermocal.errors.DesignError
        A dwell or move rate not positive, a negative settle.

    References
    ----------
    .. [1] *A method for separating the combined error coefficients of a ring-laser gyro
       triad based on dual-axis rotation*, Chinese invention patent CN104880182, claim 3.

    Examples
    --------
    >>> s = build_schedule(dwell_s=10.0)
    >>> s.dwell_windows_s.shape
    (16, 2)
    """
    if dwell_s <= 0 or move_rate_deg_s <= 0 or settle_s < 0:
        raise DesignError("dwell, move rate must be positive and settle non-negative")
    t = 0.0
    a = alpha0_deg + positions_deg[0][0]
    b = beta0_deg + positions_deg[0][1]
    knots = [(t, a, b)]
    windows = []
    cmd = []
    for k, (pa, pb) in enumerate(positions_deg):
        if k > 0:
            da = _signed_step(alpha0_deg + pa - a)
            db = _signed_step(beta0_deg + pb - b)
            if da != 0.0:
                t += abs(da) / move_rate_deg_s
                a += da
                knots.append((t, a, b))
                if db != 0.0 and settle_s > 0:
                    t += settle_s
                    knots.append((t, a, b))
            if db != 0.0:
                t += abs(db) / move_rate_deg_s
                b += db
                knots.append((t, a, b))
        windows.append((t, t + dwell_s))
        cmd.append((alpha0_deg + pa, beta0_deg + pb))
        t += dwell_s
        knots.append((t, a, b))
    arr = np.array(knots)
    return Schedule(
        time_s=arr[:, 0],
        alpha_deg=arr[:, 1],
        beta_deg=arr[:, 2],
        dwell_windows_s=np.array(windows),
        positions_deg=np.array(cmd),
    )


@dataclass(frozen=True)
class Dwell:
    """A static run of the recorded encoder angles (possibly split by gaps in time).

    ``start``/``stop`` index the sample intervals (``[start, stop)``), ``alpha_deg``
    and ``beta_deg`` are the angles mod 360 [°], ``duration_s`` the time the
    position was held [s] (gaps inside it included; they are warned about).

    Attributes
    ----------
    start, stop : int
        Sample intervals ``[start, stop)``.
    start_s : float
        Start time [s].
    duration_s : float
        Time the position was held [s].
    alpha_deg, beta_deg : float
        The encoder angles mod 360 [°].
    """

    start: int
    stop: int
    start_s: float
    duration_s: float
    alpha_deg: float
    beta_deg: float


@dataclass(frozen=True)
class Segmentation:
    """What the recording's encoder angles show: dwells, positions and moves.

    ``dwells`` are static runs at least ``pause_s`` long, ``n_positions`` the number
    of distinct (α, β) mod 360 among them, ``alpha_travel_deg``/``beta_travel_deg``
    the total travel of each axis [°].

    Attributes
    ----------
    dwells : tuple of Dwell
        Static runs at least ``pause_s`` long.
    n_positions : int
        Distinct (α, β) mod 360 among them.
    alpha_travel_deg, beta_travel_deg : float
        Total travel of each axis [°].
    """

    dwells: tuple[Dwell, ...]
    n_positions: int
    alpha_travel_deg: float
    beta_travel_deg: float


@dataclass(frozen=True)
class Motion:
    """Moves and rests found in encoder readings (:func:`detect_motion`).

    ``moving`` per sample interval (n − 1,); ``noise_arcsec`` the white jitter σ of the
    readings at rest [″] (robust, per axis, the larger); ``quantum_deg`` the reading
    resolution [°] when the readings lie on a grid (else 0); ``tolerance_deg`` the band
    [°] within which an angle counts as held.

    Attributes
    ----------
    moving : numpy.ndarray of bool, shape (n - 1,)
        Per sample interval.
    noise_arcsec : float
        White jitter σ of the readings at rest [″].
    quantum_deg : float
        Reading resolution [°] (0: not on a grid).
    tolerance_deg : float
        Band within which an angle counts as held [°].
    """

    moving: npt.NDArray[np.bool_]
    noise_arcsec: float
    quantum_deg: float
    tolerance_deg: float

    @property
    def reading_sigma_arcsec(self) -> float:
        """σ of one reading [″]: the jitter, or the quantisation σ q/√12 where the jitter
        is below it (a quantised reading at rest is constant, its error unknown)."""
        return float(max(self.noise_arcsec, self.quantum_deg * units.DEG_TO_ARCSEC / np.sqrt(12.0)))


MOTION_WINDOW_S: Final = 0.05
"""Half-width of the window over which an angle must stay in its band to be at rest [s]."""


QUANTUM_CANDIDATES_DEG: Final = tuple(
    sorted(
        {m * 10.0**-k for k in range(0, 7) for m in (5.0, 2.0, 1.0)}
        | {360.0 / 2.0**n for n in range(8, 29)},
        reverse=True,
    )
)
"""Reading resolutions tried [°]: decimal displays (1, 0.5, 0.2, 0.1, … 1e-6) and binary
encoders (360/2ⁿ, n = 8 … 28)."""


MAX_QUANTUM_DEG: Final = 0.01
"""Coarsest reading resolution taken for an encoder grid [°] (36″)."""


_EPS: Final = float(np.finfo(np.float64).eps)


def _quantum(readings_deg: FloatArray, max_values: int = 100_000) -> float:
    """Reading resolution [°]: the largest of :data:`QUANTUM_CANDIDATES_DEG` on whose grid
    every reading lies, to 1e-6 of a grid step plus the float64 rounding of the reading
    (4 ulp of |x|, i.e. ``4·eps·|x|/q`` steps), else 0 (not quantised).  A tolerance that grew
    with x/q (as it did) let jittered readings far from 0° pass every fine grid."""
    x = np.mod(np.asarray(readings_deg, dtype=np.float64), 360.0)
    if x.size > max_values:
        x = x[:: x.size // max_values + 1]
    x = np.unique(x)
    if x.size < 10:
        return 0.0
    for q in QUANTUM_CANDIDATES_DEG:
        r = x / q
        if np.all(np.abs(r - np.round(r)) < 1e-6 + 4.0 * _EPS * np.abs(x) / q):
            # on a grid coarser than any calibration-table encoder: the angles are exact
            # round numbers (a programmed trajectory), not readings of a coarse encoder
            return float(q) if q <= MAX_QUANTUM_DEG else 0.0
    return 0.0


def detect_motion(time_s: FloatArray, alpha_deg: FloatArray, beta_deg: FloatArray) -> Motion:
    """Classify each sample interval as moving or at rest, robustly to encoder jitter and
    quantisation (a per-sample rate threshold is crossed by a few arcseconds of
    jitter at 100–200 Hz).

    1. Noise: σ from the median absolute deviation of second differences of the unwrapped
       angles, ``σ = 1.4826 · MAD(Δ²θ) / √6`` (a second difference of white noise has
       variance 6σ²; moves are a minority of the samples and constant-rate motion has
       zero second difference), per axis; the reading grid q from the values
       (:func:`_quantum`).
    2. Tolerance band ``tol = 8σ + 2q + 2″``.
    3. A sample is at rest when both angles stay within ``tol`` over ±
       :data:`MOTION_WINDOW_S` (at least ±1 sample): the range over the window ≤ tol.
    4. Hysteresis: each run of such samples is extended sample by sample while both angles
       stay within ``tol`` of the run's median, so a dwell keeps its full length.

    An interval is moving unless both of its samples belong to the same rest run.

    Parameters
    ----------
    time_s : numpy.ndarray, shape (n,)
        Sample times [s].
    alpha_deg, beta_deg : numpy.ndarray, shape (n,)
        Unwrapped encoder angles [°].

    Returns
    -------
    Motion
        ``moving`` per interval (n − 1), the rest jitter [arcsec], the reading grid [°]
        and the tolerance band [°].

    References
    ----------
    - F. R. Hampel, "The influence curve and its role in robust estimation", *J. Amer.
      Statist. Assoc.* 69(346), 383–393, 1974 (the MAD scale 1.4826).
    """
    from scipy.ndimage import maximum_filter1d, minimum_filter1d

    t = np.asarray(time_s, dtype=np.float64)
    n = t.size
    angles = [np.asarray(alpha_deg, dtype=np.float64), np.asarray(beta_deg, dtype=np.float64)]
    if n < 3:
        return Motion(np.zeros(max(n - 1, 0), dtype=bool), 0.0, 0.0, 0.0)
    dt_med = float(np.median(np.diff(t)))
    half = max(1, round(MOTION_WINDOW_S / dt_med)) if dt_med > 0 else 1
    sig = []
    for x in angles:
        d2 = np.diff(x, 2)
        sig.append(1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0))
    sigma_deg = max(sig)
    q = max(
        _quantum(np.asarray(alpha_deg, dtype=np.float64)),
        _quantum(np.asarray(beta_deg, dtype=np.float64)),
    )
    tol = 8.0 * sigma_deg + 2.0 * q + 2.0 * units.ARCSEC_TO_DEG
    rest = np.ones(n, dtype=bool)
    for x in angles:
        rng_ = maximum_filter1d(x, 2 * half + 1, mode="nearest") - minimum_filter1d(
            x, 2 * half + 1, mode="nearest"
        )
        rest &= rng_ <= tol
    label = np.full(n, -1, dtype=np.int64)
    for k, (a, b) in enumerate(runs(rest)):
        med = [float(np.median(x[a:b])) for x in angles]

        def inside(i: int, med: list[float] = med) -> bool:
            return all(abs(x[i] - m) <= tol for x, m in zip(angles, med, strict=True))

        while a > 0 and label[a - 1] < 0 and inside(a - 1):
            a -= 1
        while b < n and inside(b):
            b += 1
        label[a:b] = k
    moving = ~((label[:-1] >= 0) & (label[:-1] == label[1:]))
    # the jitter itself, from the rest samples about their run medians (robust)
    dev = []
    for x in angles:
        resid = []
        for k in np.unique(label[label >= 0]):
            xs = x[label == k]
            resid.append(xs - np.median(xs))
        r = np.concatenate(resid) if resid else np.zeros(1)
        dev.append(1.4826 * float(np.median(np.abs(r))))
    noise_arcsec = float(max(dev)) * units.DEG_TO_ARCSEC
    if q > 0 and noise_arcsec < q * units.DEG_TO_ARCSEC:
        noise_arcsec = 0.0  # steps of one grid unit at rest are quantisation, not jitter
    return Motion(moving, noise_arcsec, q, tol)


def runs(mask: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Maximal runs ``[start, stop)`` where ``mask`` is true.

    Parameters
    ----------
    mask : numpy.ndarray of bool
        The flags.

    Returns
    -------
    list of tuple of int
        ``(start, stop)`` index pairs, in order.

    Examples
    --------
    >>> runs(np.array([True, True, False, True]))
    [(0, 2), (3, 4)]
    """
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(np.int8))
    starts = np.flatnonzero(d == 1)
    stops = np.flatnonzero(d == -1)
    return [(int(a), int(b)) for a, b in zip(starts, stops, strict=True)]


def segment(
    time_s: FloatArray,
    alpha_deg: FloatArray,
    beta_deg: FloatArray,
    moving: npt.NDArray[np.bool_],
    valid: npt.NDArray[np.bool_],
    *,
    pause_s: float = 10.0,
    position_tol_deg: float = 0.5,
) -> Segmentation:
    """Find the dwells (static runs ≥ ``pause_s``) and count distinct positions.

    Parameters
    ----------
    time_s : numpy.ndarray, shape (n,)
        Sample times [s].
    alpha_deg, beta_deg : numpy.ndarray, shape (n,)
        Unwrapped encoder angles [°].
    moving, valid : numpy.ndarray of bool, shape (n − 1,)
        Per sample interval: moving (:func:`detect_motion`) and not spanning a time gap.
    pause_s : float, default 10.0
        Shortest static run counted as a dwell [s].
    position_tol_deg : float, default 0.5
        Two dwells within this angle on both axes are one position [°].

    Returns
    -------
    Segmentation
        The dwells, the number of distinct positions and each axis's travel [°].
    """
    # static runs; runs at one position separated only by gaps in time are one dwell
    merged: list[list[float]] = []  # [start, stop, duration, alpha, beta]
    for a, b in runs(~moving & valid):
        dur = float(time_s[b] - time_s[a])
        pa = float(np.median(alpha_deg[a : b + 1]) % 360.0)
        pb = float(np.median(beta_deg[a : b + 1]) % 360.0)
        if merged:
            prev = merged[-1]
            between = slice(int(prev[1]), a)
            if (
                not np.any(moving[between] & valid[between])
                and _angle_close(pa, prev[3], position_tol_deg)
                and _angle_close(pb, prev[4], position_tol_deg)
            ):
                prev[1] = b
                prev[2] = float(time_s[b] - time_s[int(prev[0])])
                continue
        merged.append([a, b, dur, pa, pb])
    dwells = [
        Dwell(int(a), int(b), float(time_s[int(a)] - time_s[0]), dur, pa, pb)
        for a, b, dur, pa, pb in merged
        if dur >= pause_s
    ]
    keys: list[tuple[float, float]] = []
    for d in dwells:
        if not any(
            _angle_close(d.alpha_deg, ka, position_tol_deg)
            and _angle_close(d.beta_deg, kb, position_tol_deg)
            for ka, kb in keys
        ):
            keys.append((d.alpha_deg, d.beta_deg))
    return Segmentation(
        dwells=tuple(dwells),
        n_positions=len(keys),
        alpha_travel_deg=float(np.sum(np.abs(np.diff(alpha_deg)))),
        beta_travel_deg=float(np.sum(np.abs(np.diff(beta_deg)))),
    )


def _angle_close(a: float, b: float, tol: float) -> bool:
    return abs((a - b + 180.0) % 360.0 - 180.0) <= tol


def check_design(
    seg: Segmentation,
    *,
    name: str,
    alpha_col: str,
    beta_col: str,
    min_positions: int = 16,
    min_dwell_s: float = 60.0,
    dwell_tolerance_s: float = 0.0,
    min_travel_deg: float = 45.0,
) -> None:
    """Raise :class:`TurntableScheduleError` if the run cannot give the calibration.

    Checks: each axis travels at least ``min_travel_deg`` (rotations are what make
    scale factors and misalignments observable); at least ``min_positions``
    distinct positions; every dwell at least ``min_dwell_s − dwell_tolerance_s``.

    Parameters
    ----------
    seg : Segmentation
        The recognised dwells (:func:`segment`).
    name : str
        The recording's name in messages (e.g. the file).
    alpha_col, beta_col : str
        The encoder columns' names, in messages.
    min_positions : int, default 16
        Distinct positions needed.
    min_dwell_s : float, default 60.0
        Shortest dwell asked [s].
    dwell_tolerance_s : float, default 0.0
        Allowance below ``min_dwell_s`` [s].
    min_travel_deg : float, default 45.0
        Least total travel of each axis [°].

    Raises
    ------
    TurntableScheduleError
        An axis that never moves, too few positions, or a dwell too short.

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, claim 3.
    """
    for col, travel, what in (
        (alpha_col, seg.alpha_travel_deg, "inner"),
        (beta_col, seg.beta_travel_deg, "outer"),
    ):
        if travel < min_travel_deg:
            raise TurntableScheduleError(
                f"{name}: the {what} axis ({col!r}) never moves (total travel "
                f"{travel:.3g}°): its scale factor and misalignments are unobservable"
            )
    if seg.n_positions < min_positions:
        raise TurntableScheduleError(
            f"{name}: only {seg.n_positions} distinct positions held (need "
            f"{min_positions}, the sixteen-position sequence)"
        )
    short = [d for d in seg.dwells if d.duration_s < min_dwell_s - dwell_tolerance_s]
    if short:
        d = short[0]
        raise TurntableScheduleError(
            f"{name}: dwell at α={d.alpha_deg:.1f}°, β={d.beta_deg:.1f}° starting at "
            f"{d.start_s:.6g} s lasts {d.duration_s:.3g} s, shorter than the "
            f"{min_dwell_s:.3g} s asked ({len(short)} short dwells in all)"
        )


def warn_gaps(name: str, time_s: FloatArray, valid: npt.NDArray[np.bool_]) -> None:
    """Warn (``GapWarning``) about time gaps: they split the angle integration.

    Parameters
    ----------
    name : str
        The recording's name in the message.
    time_s : numpy.ndarray, shape (n,)
        Sample times [s].
    valid : numpy.ndarray of bool, shape (n − 1,)
        False for an interval that spans a gap.
    """
    bad = np.flatnonzero(~valid)
    if bad.size:
        i = int(bad[0])
        warnings.warn(
            f"{name}: {bad.size} gaps in time; the first after t = "
            f"{time_s[i] - time_s[0]:.6g} s lasts {time_s[i + 1] - time_s[i]:.6g} s; "
            "the gyro angle integration restarts after each gap",
            GapWarning,
            stacklevel=2,
        )
