"""Static poses of a multi-position session: found from the data or named in a POSES file.

Detection (:func:`detect_poses`): the moving-window variance of each accelerometer axis
(and of each gyro axis when given), summed over the axes, over a centred window of
``w = max(5, round(window_s · rate))`` samples, from running sums.  The sensor's own noise
is the 10th percentile of that variance over the record (at least a tenth of a session is
still); a sample is still where the variance stays below ``threshold ×`` it, and a pose is
a run of still samples at least ``static_s`` long, shortened by ``w/2`` at each end (the
window straddles the motion there).  A pose whose mean variance is more than twice the
record's quietest is listed as *not still* (a warning: tremor, a hand on the board).

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
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal.errors import ThermocalInputError

FloatArray = npt.NDArray[np.float64]

FACES: Final = ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a")
"""Names of the six faces: axis ``x`` up (``_p``) or down (``_a``), …"""
TURNS: Final = ("x_rot", "y_rot", "z_rot")
"""Names of the 360° turns about each axis (Ferraris et al. 1995)."""


@dataclass(frozen=True)
class Section:
    """Samples ``start … end − 1`` of a session, named (``pose_3``, ``x_p``, ``z_rot``)."""

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


def detect_poses(
    time_s: npt.ArrayLike,
    accel: npt.ArrayLike,
    gyro: npt.ArrayLike | None = None,
    *,
    static_s: float = 1.0,
    window_s: float = 0.25,
    threshold: float = 3.0,
) -> list[Section]:
    """Static poses found from the data (module docstring).  ``accel`` (n, 3) in any unit,
    ``gyro`` (n, 3) or None; each sensor's variance is normalised by its own floor before
    they are summed, so units do not matter."""
    t = np.asarray(time_s, dtype=np.float64)
    a = np.asarray(accel, dtype=np.float64)
    n = t.size
    if n < 10:
        raise ThermocalInputError(f"{n} samples: too short for a multi-position session")
    dt = float(np.median(np.diff(t)))
    if not static_s > 0:
        raise ThermocalInputError(f"--static-s must be positive, got {static_s!r}")
    w = max(5, round(window_s / dt))
    w = min(w, max(2, n // 4))
    score = np.zeros(n)
    floors = []
    for x in (a, None if gyro is None else np.asarray(gyro, dtype=np.float64)):
        if x is None:
            continue
        v = _running_variance(x, w)
        floor = float(np.percentile(v, 10))
        if not floor > 0:
            floor = float(np.max(v)) * 1e-12 + 1e-300
        floors.append(floor)
        score += v / floor
    score /= len(floors)
    still = score < threshold
    # runs of still samples
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    starts, ends = edges[0::2], edges[1::2]
    h = w // 2
    min_n = max(2, round(static_s / dt))
    out: list[Section] = []
    for s0, e0 in zip(starts, ends, strict=True):
        s, e = int(s0) + h, int(e0) - h
        if e - s < min_n:
            continue
        ratio = float(np.mean(score[s:e]))
        out.append(Section(f"pose_{len(out) + 1}", s, e, ratio))
    return out


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


def parse_poses(d: Any, n_samples: int, where: str = "--poses") -> list[Section]:
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
                f"{n_samples} samples or empty"
            )
        out.append(Section(str(name), s, e))
    out.sort(key=lambda sec: sec.start)
    for a, b in itertools.pairwise(out):
        if b.start < a.end:
            raise ThermocalInputError(f"{where}: sections {a.name!r} and {b.name!r} overlap")
    return out


__all__ = ["FACES", "TURNS", "Section", "detect_poses", "parse_poses"]
