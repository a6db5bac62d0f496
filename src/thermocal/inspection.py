"""What is in a recording and what is wrong with it (``thermocal inspect``).

:func:`inspect_recording` summarises a :class:`~thermocal.recording.Recording`:
sample count, duration, sample rate (from the median interval), gaps, per-column
range and NaN count, temperature span, spikes (Hampel test) and the problems of
:func:`thermocal.recording.find_problems`.  Pure computation; the CLI prints it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
from numpy.lib.stride_tricks import sliding_window_view

from thermocal.errors import ThermocalInputError
from thermocal.recording import (
    DIFF_BLOCK,
    GAP_FACTOR,
    FloatArray,
    Problem,
    Recording,
    TimeJitter,
    all_finite,
    contiguous_slices,
    find_gaps,
    find_problems,
    finite_extrema,
    median_in_blocks,
    median_interval,
    median_of_parts,
)

SPIKE_THRESHOLD = 8.0
"""Hampel test: a sample further than this many robust σ from its window median is a spike."""
SPIKE_HALF_WINDOW = 3
RAIL_VALUES = (-32768.0, 32767.0, 65535.0)
"""The rails of 16-bit raw counts (int16 and the top of uint16): an integer column's extreme
on one of them is saturated."""
RAIL_RUN = 3
"""Any other column: its extreme held this many samples in a row, far from the bulk."""


RAIL_STEP = 10.0
"""…entered or left by a step this many times the column's median step (a smooth peak
of a motion flattens out instead)."""


def _runs_at(a: FloatArray, v: float, block: int = DIFF_BLOCK) -> list[tuple[int, int]]:
    """The stretches ``[start, end)`` where ``a == v``, found block by block (no mask or
    index array as long as the column)."""
    out: list[tuple[int, int]] = []
    for b0 in range(0, a.size, block):
        idx = np.flatnonzero(a[b0 : b0 + block] == v)
        if idx.size == 0:
            continue
        cut = np.flatnonzero(np.diff(idx) != 1)
        starts = [int(idx[0]), *(int(i) for i in idx[cut + 1])]
        ends = [*(int(i) + 1 for i in idx[cut]), int(idx[-1]) + 1]
        for s0, e0 in zip(starts, ends, strict=True):
            if out and out[-1][1] == b0 + s0:  # continues across the block's edge
                out[-1] = (out[-1][0], b0 + e0)
            else:
                out.append((b0 + s0, b0 + e0))
    return out


def _all_integer(a: FloatArray, block: int = DIFF_BLOCK) -> bool:
    """Whether every finite value of ``a`` is an integer, in blocks."""
    for b0 in range(0, a.size, block):
        part = a[b0 : b0 + block]
        fin = part[np.isfinite(part)]
        if not bool(np.all(fin == np.round(fin))):
            return False
    return True


def _finite_parts(a: FloatArray, block: int = DIFF_BLOCK) -> Iterator[FloatArray]:
    """The finite values of ``a`` in order, a block at a time."""
    for b0 in range(0, a.size, block):
        part = a[b0 : b0 + block]
        yield part if all_finite(part) else part[np.isfinite(part)]


def _nonzero_steps(a: FloatArray, block: int = DIFF_BLOCK) -> Iterator[FloatArray]:
    """``|Δ|`` between consecutive finite values of ``a`` where nonzero, a block at a time."""
    last: FloatArray = np.empty(0)
    for fin in _finite_parts(a, block):
        if fin.size == 0:
            continue
        d = np.abs(np.diff(np.concatenate([last, fin])))
        last = fin[-1:].copy()
        yield d[d > 0]


def saturated_mask(x: npt.ArrayLike) -> npt.NDArray[np.bool_]:
    """The samples of one column on the sensor's rails (clipped): its maximum or minimum
    when that is a 16-bit rail of integer counts (:data:`RAIL_VALUES`) held at least twice
    in a row (a wrapping counter passes it once); else the stretches where the column sits
    on its maximum or minimum for :data:`RAIL_RUN` samples or more, entered or left by a
    step :data:`RAIL_STEP` times its median step, more than 0.4 of the range from the
    median.

    Parameters
    ----------
    x : array_like
        One column's samples.

    Returns
    -------
    numpy.ndarray of bool
        True where a sample sits on a rail.
    """
    a = np.asarray(x, dtype=np.float64)
    out = np.zeros(a.shape, dtype=bool)
    ext = finite_extrema(a)  # in blocks: no copy of the column's finite values
    if ext is None or ext.count < 2:
        return out
    hi, lo = ext.hi, ext.lo
    is_int = _all_integer(a)
    med = median_of_parts(lambda: _finite_parts(a), ext.count)
    n_steps = sum(d.size for d in _nonzero_steps(a))
    step = median_of_parts(lambda: _nonzero_steps(a), n_steps) if n_steps else 0.0
    for v in {hi, lo}:
        runs = _runs_at(a, v)
        longest = max((e0 - s0 for s0, e0 in runs), default=0)
        if is_int and v in RAIL_VALUES and longest >= 2:  # a counter passes once
            for s0, e0 in runs:
                out[s0:e0] = True
            continue
        if abs(v - med) <= 0.4 * (hi - lo):
            continue
        for s0, e0 in runs:
            jumps = [abs(v - a[s0 - 1])] if s0 > 0 else []
            jumps += [abs(v - a[e0])] if e0 < a.size else []
            if e0 - s0 >= RAIL_RUN and max(jumps, default=0.0) > RAIL_STEP * step:
                out[s0:e0] = True
    return out


@dataclass(frozen=True)
class ColumnSummary:
    """Range and NaN count of one column (in its own unit).

    Attributes
    ----------
    name : str
        The column.
    role : str
        ``"signal"``, ``"temperature"`` or ``"other"``.
    unit : str
        Its unit.
    min, max, mean : float or None
        Its smallest, largest and mean finite values [``unit``] (None: none finite).
    n_nan : int
        Number of NaN cells.
    first_nan_row : int or None
        The first of them (0-based data row).
    n_spikes : int
        Samples found as spikes.
    """

    name: str
    role: str
    unit: str
    min: float | None
    max: float | None
    mean: float | None
    n_nan: int
    first_nan_row: int | None
    n_spikes: int

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


@dataclass(frozen=True)
class Inspection:
    """Summary of a recording (the keys of the ``inspect`` command's JSON output).

    Attributes
    ----------
    file : str
        The recording.
    n_samples : int
        Number of samples.
    duration_s : float or None
        Last minus first time [s].
    sample_rate_hz : float or None
        Sample rate [Hz].
    median_interval_s : float or None
        Median time step [s].
    gaps : list of dict
        The gaps in time.
    n_segments : int or None
        Gap-free stretches.
    columns : dict of str to ColumnSummary
        Each column's summary.
    temperature_span : dict
        [min, max] [°C] per temperature column.
    problems : list of Problem
        What is wrong with the recording.
    time_ok : bool
        Time is finite and strictly increasing.
    timestamp_jitter : TimeJitter or None
        The scatter of the time steps.
    thermometers : dict
        Per temperature column, what its thermometer is
        (:meth:`thermocal.thermometer.Thermometer.to_dict`: lattice step, update period,
        quantised, slow), None when it cannot be told (raw counts without a conversion, no
        finite value, time not increasing).
    legs : dict
        Per temperature column, its heating and cooling legs
        (:meth:`thermocal.legs.Legs.to_dict` with a ``summary``), None when they cannot be
        told (as ``thermometers``).
    """

    file: str
    n_samples: int
    duration_s: float | None
    """Last minus first time [s]; None when time is not finite and strictly increasing."""
    sample_rate_hz: float | None
    median_interval_s: float | None
    gaps: list[dict[str, float]]
    n_segments: int | None
    """Gap-free stretches; None when time is not finite and strictly increasing."""
    columns: dict[str, ColumnSummary]
    temperature_span: dict[str, list[float] | None]
    """[min, max] [°C] per temperature column (None if raw counts with no conversion)."""
    problems: list[Problem] = field(default_factory=list)
    time_ok: bool = True
    """Time is finite and strictly increasing, so duration, rate, gaps and segments mean
    something."""
    timestamp_jitter: TimeJitter | None = None
    """The scatter of the time steps (:func:`thermocal.recording.time_jitter`)."""
    thermometers: dict[str, dict[str, Any] | None] = field(default_factory=dict)
    """Per temperature column, its thermometer (:mod:`thermocal.thermometer`)."""
    legs: dict[str, dict[str, Any] | None] = field(default_factory=dict)
    """Per temperature column, its heating and cooling legs (:mod:`thermocal.legs`)."""

    @property
    def fatal(self) -> list[Problem]:
        """Problems that stop the other commands (severity ``error``)."""
        return [p for p in self.problems if p.severity == "error"]

    def to_dict(self, spell: Callable[[str], str] | None = None) -> dict[str, Any]:
        """JSON-ready dict; each problem's message names parameters as ``spell`` shows them
        (:meth:`thermocal.recording.Problem.text`: their own names without it).

        Parameters
        ----------
        spell : callable, optional
            What to show for a parameter (the command line: its option).

        Returns
        -------
        dict
        """
        return {
            "file": self.file,
            "n_samples": self.n_samples,
            "duration_s": self.duration_s,
            "sample_rate_hz": self.sample_rate_hz,
            "median_interval_s": self.median_interval_s,
            "gaps": self.gaps,
            "n_gaps": len(self.gaps),
            "n_segments": self.n_segments,
            "columns": {k: v.to_dict() for k, v in self.columns.items()},
            "temperature_span": self.temperature_span,
            "problems": [p.to_dict(spell) for p in self.problems],
            "time_ok": self.time_ok,
            "usable": not self.fatal,
            "timestamp_jitter": (
                self.timestamp_jitter.to_dict() if self.timestamp_jitter is not None else None
            ),
            "thermometers": self.thermometers,
            "legs": self.legs,
        }


SPIKE_CHUNK = 1 << 18
"""Window centres per chunk of the Hampel test's running median (the medians
of one chunk at a time, ≈ 2 MB each, instead of two arrays as long as the column)."""

SPIKE_BLOCK = 1 << 15
"""Window centres per block of the Hampel test (its working memory is ≈ 2·w·8 bytes each)."""


def count_spikes(
    time_s: FloatArray,
    x: FloatArray,
    *,
    threshold: float = SPIKE_THRESHOLD,
    half_window: int = SPIKE_HALF_WINDOW,
) -> tuple[int, int | None]:
    """Count spikes with a Hampel test per contiguous segment.

    Parameters
    ----------
    time_s, x : ndarray, shape (n,)
        Sample times [s] (the test runs on each gap-free segment) and the column.
    threshold : float, optional
        The threshold ``t`` in robust standard deviations.
    half_window : int, optional
        Half the window [samples].

    Returns
    -------
    count : int
        The spike samples.
    first : int or None
        The first spike's row.

    Notes
    -----
    A spike: :math:`|x_i - \\mathrm{med}_i| > t \\cdot 1.4826 \\cdot \\mathrm{MAD}_i` over the
    window ``i ± half_window`` (F. R. Hampel, JASA 69(346), 1974; R. K. Pearson, IEEE Trans.
    Control Systems Technology 10(1), 2002).  A window whose MAD is zero uses the segment's
    MAD of first differences as a floor.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.random.default_rng(0).normal(0.0, 1.0, 300)
    >>> x[[50, 200]] += 40.0
    >>> count_spikes(np.arange(300.0), x)
    (2, 50)
    """
    n_total = 0
    first: int | None = None
    w = 2 * half_window + 1
    for sl in contiguous_slices(time_s):
        xs = x[sl]
        if xs.size < w or not np.all(np.isfinite(xs)):
            continue

        # global MAD of the first differences, their medians selected block by block
        # (exactly np.median's, without an array of steps as long as the column)
        def steps(a: int, b: int, xs: FloatArray = xs) -> FloatArray:
            return np.diff(xs[a : b + 1])

        med_d = median_in_blocks(steps, xs.size - 1)

        def abs_dev(a: int, b: int, med_d: float = med_d) -> FloatArray:
            d = steps(a, b)
            d -= med_d
            return np.abs(d, out=d)

        floor = 1.4826 * median_in_blocks(abs_dev, xs.size - 1) / np.sqrt(2.0)
        # the window medians of every centre (scipy.ndimage's running selection, exact for
        # an odd window: 20× the speed of np.median over sliding windows), then the MAD only
        # where a spike is possible: sigma ≥ floor, so |x − med| ≤ threshold·floor is no spike
        from scipy import ndimage

        hits: list[int] = []
        n_centres = xs.size - 2 * half_window
        windows = sliding_window_view(xs, w)
        for c0 in range(0, n_centres, SPIKE_CHUNK):  # chunks of centres: bounded memory
            c1 = min(n_centres, c0 + SPIKE_CHUNK)
            # centre c (row c + half_window) has window xs[c : c + w]; the chunk's windows
            # lie in xs[c0 : c1 + 2·half_window], whose filter is exact away from its ends
            sub = xs[c0 : c1 + 2 * half_window]
            med = ndimage.median_filter(sub, size=w, mode="nearest")[half_window:-half_window]
            dev_c = np.abs(xs[c0 + half_window : c1 + half_window] - med)
            cand = (
                np.flatnonzero(dev_c > threshold * floor)
                if floor > 0
                else np.flatnonzero(dev_c > 0)
            )
            for a in range(0, cand.size, SPIKE_BLOCK):
                idx = cand[a : a + SPIKE_BLOCK]
                win = windows[c0 + idx]
                mad = np.median(np.abs(win - med[idx, None]), axis=1)
                sigma = np.maximum(1.4826 * mad, floor)
                hit = (dev_c[idx] > threshold * sigma) & (sigma > 0)
                hits.extend(int(c0 + i) for i in idx[hit][:1])
                n_total += int(np.count_nonzero(hit))
            del med, dev_c
        if hits:
            row = int(sl.start) + half_window + min(hits)
            first = row if first is None else min(first, row)
    return n_total, first


def _saturation_problems(name: str, arr: FloatArray) -> list[Problem]:
    """A warning for a signal column with samples on its rails: count, value, first row
    and the number of stretches."""
    sat = saturated_mask(arr)
    n = int(np.count_nonzero(sat))
    if not n:
        return []
    first = int(np.argmax(sat))
    runs = int(np.count_nonzero(np.diff(sat.view(np.int8), prepend=np.int8(0)) == 1))
    vals = ", ".join(f"{v:g}" for v in sorted({float(v) for v in arr[sat]}))
    return [
        Problem(
            "saturated",
            f"column {name!r} has {n} samples on its rails ({vals}: the sensor clipped) in "
            f"{runs} stretches, first at row {first}: rates and rotations across them are wrong",
            severity="warning",
            column=name,
            row=first,
        )
    ]


def inspect_recording(rec: Recording, skipped: Sequence[str] = ()) -> Inspection:
    """What is in a recording and what is wrong with it.

    Parameters
    ----------
    rec : Recording
        The recording, as read.
    skipped : sequence of str
        Columns the reader skipped because they hold non-numeric values (the ``skipped``
        list of :func:`thermocal.readers.read_recording`): each one a ``non_numeric``
        warning, after the other problems.

    Returns
    -------
    Inspection
        Samples, duration [s], sample rate [Hz], gaps, per-column summaries (spikes,
        rails, non-finite values), each temperature's span [°C], the timestamps' jitter and
        every problem found with its severity; never raises on bad data.

    Notes
    -----
    Spikes by the Hampel test (:func:`count_spikes`), clipped samples by
    :func:`saturated_mask`, gaps where a step exceeds :data:`GAP_FACTOR` times the
    median interval.

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.recording import Recording
    >>> x = np.random.default_rng(0).normal(0.0, 1.0, 500)
    >>> x[100] = 50.0
    >>> rec = Recording.from_arrays(np.arange(500) * 0.01, {"gz": x}, signal_unit="deg/h")
    >>> ins = inspect_recording(rec)
    >>> ins.n_samples, round(ins.sample_rate_hz), ins.columns["gz"].n_spikes
    (500, 100, 1)
    """
    t = rec.time_s
    problems = find_problems(rec)
    time_ok = not any(
        p.kind in ("nonfinite_time", "duplicate_time", "backwards_time", "empty") for p in problems
    )
    med = median_interval(t) if t.size > 1 else float("nan")
    gaps = find_gaps(t) if time_ok else []
    names = list(rec.columns)
    # the last signal first: the checks above read it last, and a recording read on demand
    # keeps it (every other column is read once more, not twice); results in column order
    held = [n for n in rec.signals if n in names][-1:]
    done = {n: _column_summary(rec, n, time_ok) for n in held + [n for n in names if n not in held]}
    problems += [p for n in names for p in done[n][1]]
    columns = {n: done[n][0] for n in names}
    span = {n: done[n][2] for n in names if done[n][0].role == "temperature"}
    thermometers = {n: done[n][3] for n in span if time_ok and span[n] is not None}
    legs = {n: done[n][4] for n in thermometers}
    return Inspection(
        file=rec.name,
        n_samples=rec.n_samples,
        duration_s=float(t[-1] - t[0]) if t.size > 1 and time_ok else None,
        sample_rate_hz=(1.0 / med) if time_ok and np.isfinite(med) and med > 0 else None,
        median_interval_s=med if time_ok and np.isfinite(med) else None,
        gaps=[{"start_s": g.start_s, "length_s": g.length_s, "after_row": g.index} for g in gaps],
        n_segments=(len(gaps) + 1 if t.size else 0) if time_ok else None,
        columns=columns,
        temperature_span=span,
        problems=problems + _skipped_problems(skipped),
        time_ok=time_ok,
        timestamp_jitter=rec.time_jitter(),
        thermometers=thermometers,
        legs=legs,
    )


def _column_summary(
    rec: Recording, name: str, time_ok: bool
) -> tuple[ColumnSummary, list[Problem], list[float] | None, dict[str, Any] | None, Any]:
    """One column's summary, its spike and rail problems, and for a temperature its span
    [°C], its thermometer and its legs (None when the span is None or the time is not
    usable), all from one read of the column (and one of it in °C)."""
    t, arr = rec.time_s, rec.columns[name]
    role = (
        "signal" if name in rec.signals else "temperature" if name in rec.temperatures else "other"
    )
    problems: list[Problem] = []
    nan = np.isnan(arr)
    n_nan = int(np.count_nonzero(nan))
    # no copy of the column when it is all finite (the common case)
    finite = arr if n_nan == 0 and bool(np.isfinite(arr).all()) else arr[np.isfinite(arr)]
    n_spikes, first_spike = count_spikes(t, arr) if time_ok and role != "other" else (0, None)
    if n_spikes:
        problems.append(
            Problem(
                "spikes",
                f"column {name!r} has {n_spikes} spike samples (Hampel test, "
                f"{SPIKE_THRESHOLD:g} robust σ), first at row {first_spike}",
                severity="warning",
                column=name,
                row=first_spike,
            )
        )
    if role != "temperature" and rec.units.get(name) != "degC":  # a setpoint's holds
        problems.extend(_saturation_problems(name, arr))
    summary = ColumnSummary(
        name=name,
        role=role,
        unit=rec.units.get(name, ""),
        min=float(finite.min()) if finite.size else None,
        max=float(finite.max()) if finite.size else None,
        mean=float(finite.mean()) if finite.size else None,
        n_nan=n_nan,
        first_nan_row=int(np.argmax(nan)) if n_nan else None,
        n_spikes=n_spikes,
    )
    del nan, finite
    span, thermometer, legs = (
        _temperature_facts(rec, name, time_ok) if role == "temperature" else (None, None, None)
    )
    return summary, problems, span, thermometer, legs


def _temperature_facts(
    rec: Recording, name: str, time_ok: bool
) -> tuple[list[float] | None, dict[str, Any] | None, dict[str, Any] | None]:
    """A temperature column's span [°C] (None: raw counts without a conversion, or no finite
    value), its thermometer and its heating and cooling legs (None without a span or a
    usable time), from one read of it in °C."""
    try:
        temp = rec.temperature_c(name)
    except ThermocalInputError:
        return None, None, None
    ext = finite_extrema(temp)  # in blocks: no copy of the column
    if ext is None:
        return None, None, None
    if not time_ok:
        return [ext.lo, ext.hi], None, None
    return [ext.lo, ext.hi], _thermometer(rec.time_s, temp), _legs(rec.time_s, temp)


def _legs(t: FloatArray, temp_c: FloatArray) -> dict[str, Any] | None:
    """The heating and cooling legs of a temperature [°C] with a summary line (None: no
    finite value)."""
    from thermocal.errors import ParameterError
    from thermocal.legs import find_legs

    try:
        legs = find_legs(t, temp_c)
    except ParameterError:
        return None
    return {"summary": legs.summary(), **legs.to_dict()}


def _thermometer(t: FloatArray, temp_c: FloatArray) -> dict[str, Any] | None:
    """What the thermometer of a temperature [°C] is (None: no finite value)."""
    from thermocal.errors import ParameterError
    from thermocal.thermometer import describe_thermometer

    try:
        return describe_thermometer(t, temp_c).to_dict()
    except ParameterError:
        return None


def _skipped_problems(skipped: Sequence[str]) -> list[Problem]:
    """A ``non_numeric`` warning per column the reader skipped."""
    return [
        Problem(
            "non_numeric",
            f"column {c!r} holds non-numeric values and was skipped",
            severity="warning",
            column=c,
        )
        for c in skipped
    ]


__all__ = [
    "GAP_FACTOR",
    "RAIL_RUN",
    "RAIL_STEP",
    "RAIL_VALUES",
    "ColumnSummary",
    "Inspection",
    "count_spikes",
    "inspect_recording",
    "saturated_mask",
]
