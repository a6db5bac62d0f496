"""The in-memory form of a test: :class:`Recording`.

A recording is one row per sample: time [s] as float64, named signal channels
with units, named temperature channels ([°C] or raw ADC ``counts``), other
numeric columns kept as they are (e.g. the simulator's ``truth_bias``), and
:class:`Metadata` (sample interval, scale factor K, latitude, sensitive axis,
sensor and run ids, notes).

Validation lives here too: :func:`find_problems` lists what is wrong with a
recording without raising; :func:`find_gaps` finds gaps in time from the
median sample interval (gaps are reported, never interpolated).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import warnings
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any, Final, Literal

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import (
    MissingColumnError,
    MissingValueError,
    PlausibilityWarning,
    ThermocalInputError,
    TimestampError,
    TimestampWarning,
    UnitError,
    spell_parameters,
)

META_KEY = "thermocal"
META_FORMAT = "thermocal-recording"
META_VERSION = 1
"""Key, format and version of the metadata a recording file carries (Parquet key-value
metadata or sidecar JSON)."""

FloatArray = npt.NDArray[np.float64]

GAP_FACTOR = 1.5
"""A time step larger than ``GAP_FACTOR`` × the median interval is a gap."""


@dataclass
class Metadata:
    """What a test is, beyond its numbers.  Every field is optional.

    Attributes
    ----------
    sample_interval_s : float or None
        Nominal sample interval τ [s]; the median interval of the time column when
        not given.
    scale_factor : float or None
        Scale factor K of a raw-count output [``scale_factor_unit``].
    scale_factor_unit : str or None
        Unit of K, a key of :data:`thermocal.units.SCALE_FACTOR_UNITS`.
    latitude_deg : float or None
        Test-site latitude φ [°], for earth-rate removal.
    axis : str or None
        Sensitive-axis direction in local ENU (``"up"``, ``"north"``, ``"e,n,u"``).
    sensor_id, run_id, notes : str or None
        Free text.
    temperature_conversion : dict of str to TemperatureConversion
        Per temperature column ``(gain, offset[, "int16"])`` with
        ``T[°C] = gain · counts + offset`` for raw ADC temperatures (``int16``: signed
        16-bit counts stored unsigned).
    extra : dict
        Any other key-value pairs (kept through read/write round-trips).
    """

    sample_interval_s: float | None = None
    scale_factor: float | None = None
    scale_factor_unit: str | None = None
    latitude_deg: float | None = None
    axis: str | None = None
    sensor_id: str | None = None
    run_id: str | None = None
    notes: str | None = None
    temperature_conversion: dict[str, units.TemperatureConversion] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (``None`` fields omitted)."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if v is None or (isinstance(v, dict) and not v):
                continue
            if f.name == "temperature_conversion":
                v = {k: units.temperature_conversion(c).to_json() for k, c in v.items()}
            out[f.name] = v
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Metadata:
        """Inverse of :meth:`to_dict`; unknown keys go to ``extra``.

        Parameters
        ----------
        d : dict
            A metadata mapping (a sidecar ``FILE.meta.json`` or a file's key-value store).

        Returns
        -------
        Metadata

        Raises
        ------
        ThermocalInputError
            A malformed ``temperature_conversion`` entry.

        Examples
        --------
        >>> m = Metadata.from_dict({"sample_interval_s": 0.01, "site": "lab 2"})
        >>> m.sample_interval_s, m.extra
        (0.01, {'site': 'lab 2'})
        """
        known = {f.name for f in dataclasses.fields(cls)}
        kwargs: dict[str, Any] = {}
        extra = dict(d.get("extra", {}))
        for k, v in d.items():
            if k == "extra":
                continue
            if k in known:
                kwargs[k] = v
            else:
                extra[k] = v
        conv = kwargs.get("temperature_conversion") or {}
        kwargs["temperature_conversion"] = {
            str(k): units.temperature_conversion(v, f"temperature_conversion of {k!r}")
            for k, v in conv.items()
        }
        for k in ("sample_interval_s", "scale_factor", "latitude_deg"):
            if kwargs.get(k) is not None:
                kwargs[k] = float(kwargs[k])
        return cls(**kwargs, extra=extra)

    def merged(self, other: Metadata) -> Metadata:
        """A copy of ``self`` with every field that ``other`` sets taken from ``other``.

        Parameters
        ----------
        other : Metadata
            Metadata whose set fields win (dicts are merged key by key).

        Returns
        -------
        Metadata
        """
        out = dataclasses.replace(self)
        for f in dataclasses.fields(other):
            v = getattr(other, f.name)
            if v is None or (isinstance(v, dict) and not v):
                continue
            if isinstance(v, dict):
                merged = dict(getattr(self, f.name))
                merged.update(v)
                v = merged
            setattr(out, f.name, v)
        return out


@dataclass(frozen=True)
class Gap:
    """A gap in time: the samples at ``index`` and ``index + 1`` are ``length_s`` apart.

    ``start_s`` is the time of the last sample before the gap (elapsed from the
    first sample when reported by ``inspect``).

    Attributes
    ----------
    index : int
        The sample before the gap.
    start_s : float
        Time of that sample [s].
    length_s : float
        Time between the two samples [s].
    """

    index: int
    start_s: float
    length_s: float


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a recording.

    ``severity`` is ``"error"`` (results would be wrong) or ``"warning"``.
    ``row`` is the 0-based data row (not counting the header), when one is at fault.
    ``message`` writes each of ``parameters`` (the library's parameters it names, such as
    ``rate_hz``) as ``{parameter}``; :meth:`text` shows them.

    Attributes
    ----------
    kind : str
        What kind of problem (a short key).
    message : str
        The message, with ``{parameter}`` for each of ``parameters``.
    severity : {"error", "warning"}
        Whether results would be wrong.
    column : str or None
        The column at fault.
    row : int or None
        The 0-based data row at fault.
    parameters : tuple of str
        The library's parameters the message names.
    """

    kind: str
    message: str
    severity: Literal["error", "warning"] = "error"
    column: str | None = None
    row: int | None = None
    parameters: tuple[str, ...] = ()

    def text(self, spell: Callable[[str], str] | None = None) -> str:
        """The message with each parameter as ``spell(parameter)`` (its own name without).

        Parameters
        ----------
        spell : callable, optional
            What to show for a parameter (the command line: its option).

        Returns
        -------
        str
        """
        return spell_parameters(self.message, self.parameters, spell)

    def to_dict(self, spell: Callable[[str], str] | None = None) -> dict[str, Any]:
        """JSON-ready dict of the set fields, the message as :meth:`text` shows it.

        Parameters
        ----------
        spell : callable, optional
            As :meth:`text`.

        Returns
        -------
        dict
        """
        d = dataclasses.asdict(self)
        d.pop("parameters")
        d["message"] = self.text(spell)
        return {k: v for k, v in d.items() if v is not None}


@dataclass
class Recording:
    """A test recording: time, channels with roles and units, metadata.

    Attributes
    ----------
    time_s : numpy.ndarray
        Sample times [s], float64, strictly increasing once validated.
    columns : dict of str to numpy.ndarray
        Every non-time column as float64 arrays, by name.
    units : dict of str to str
        Unit string of each column (``""`` if unknown).
    signals : tuple of str
        Names of the sensor-output columns (roles).
    temperatures : tuple of str
        Names of the temperature columns (roles).
    meta : Metadata
        What the test is.
    source : str or None
        The file it was read from, if any.
    time_unit : str
        Unit the file's time column was written in (``time_s`` is always in seconds).
    unit_sources : dict of str to str
        Where each column's unit came from (``option``, ``metadata``, ``column name``,
        ``model`` or ``default``; ``"<time>"`` for the time column).
    """

    time_s: FloatArray
    columns: dict[str, FloatArray]
    units: dict[str, str] = field(default_factory=dict)
    signals: tuple[str, ...] = ()
    temperatures: tuple[str, ...] = ()
    meta: Metadata = field(default_factory=Metadata)
    source: str | None = None
    time_unit: str = "s"
    """Unit the file's time column was written in (``time_s`` is always in seconds)."""
    unit_sources: dict[str, str] = field(default_factory=dict)
    """Where each column's unit came from (``option``, ``metadata``, ``column name``,
    ``model`` or ``default``; ``"<time>"`` for the time column), for files read by
    :func:`thermocal.readers.dispatch.read_recording`."""
    _scan: tuple[FloatArray, TimeScan] | None = field(
        default=None, init=False, repr=False, compare=False
    )

    # --- construction ----------------------------------------------------------
    @classmethod
    def from_arrays(
        cls,
        time_s: npt.ArrayLike,
        signals: dict[str, npt.ArrayLike] | None = None,
        temperatures: dict[str, npt.ArrayLike] | None = None,
        *,
        signal_unit: str | dict[str, str] = "deg/h",
        temperature_unit: str = "degC",
        other: dict[str, npt.ArrayLike] | None = None,
        other_units: dict[str, str] | None = None,
        meta: Metadata | None = None,
    ) -> Recording:
        """Build a recording from arrays, all the same length.

        Parameters
        ----------
        time_s : array_like
            Sample times [s].
        signals : dict of str to array_like, optional
            Sensor-output columns by name [``signal_unit``].
        temperatures : dict of str to array_like, optional
            Temperature columns by name [``temperature_unit``].
        signal_unit : str or dict of str to str, optional
            Unit of every signal, or per signal (default ``"deg/h"``).
        temperature_unit : str, optional
            Unit of the temperatures (default ``"degC"``; ``"counts"`` for raw ADC values).
        other : dict of str to array_like, optional
            Further columns without a role.
        other_units : dict of str to str, optional
            Their units (default ``""``, unknown).
        meta : Metadata, optional
            The recording's metadata (default empty).

        Returns
        -------
        Recording

        Raises
        ------
        ThermocalInputError
            A column whose length differs from ``time_s``'s.
        UnitError
            An unknown unit.

        Examples
        --------
        >>> import numpy as np
        >>> t = np.arange(0.0, 10.0, 0.5)
        >>> rec = Recording.from_arrays(t, {"gx": np.zeros(t.size)}, {"T": 25.0 + 0 * t},
        ...                             signal_unit="deg/s")
        >>> rec.n_samples, rec.sample_rate_hz, round(float(rec.signal("gx")[0][0]), 3)
        (20, 2.0, 0.0)
        >>> rec.signal("gx")[1]
        'deg/h'
        """
        t = np.asarray(time_s, dtype=np.float64)
        cols: dict[str, FloatArray] = {}
        unit_map: dict[str, str] = {}
        for name, arr in (signals or {}).items():
            cols[name] = np.asarray(arr, dtype=np.float64)
            u = signal_unit if isinstance(signal_unit, str) else signal_unit[name]
            unit_map[name] = units.normalize_signal_unit(u)
        for name, arr in (temperatures or {}).items():
            cols[name] = np.asarray(arr, dtype=np.float64)
            unit_map[name] = units.normalize_temperature_unit(temperature_unit)
        for name, arr in (other or {}).items():
            cols[name] = np.asarray(arr, dtype=np.float64)
            unit_map[name] = (other_units or {}).get(name, "")
        for name, arr in cols.items():
            if arr.shape != t.shape:
                raise ThermocalInputError(
                    f"column {name!r} has {arr.size} samples but time has {t.size}"
                )
        return cls(
            time_s=t,
            columns=cols,
            units=unit_map,
            signals=tuple((signals or {}).keys()),
            temperatures=tuple((temperatures or {}).keys()),
            meta=meta or Metadata(),
        )

    # --- basic properties --------------------------------------------------------
    def __len__(self) -> int:
        return int(self.time_s.size)

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.time_s.size)

    @property
    def duration_s(self) -> float:
        """Time from the first to the last sample [s] (0 for fewer than 2 samples)."""
        return float(self.time_s[-1] - self.time_s[0]) if self.time_s.size > 1 else 0.0

    @property
    def sample_interval_s(self) -> float:
        """Nominal sample interval τ [s]: metadata if given, else the median time step (the
        mean step on a regular grid, :func:`scan_time`)."""
        if self.meta.sample_interval_s is not None:
            return float(self.meta.sample_interval_s)
        return self.time_scan().interval_s

    @property
    def sample_rate_hz(self) -> float:
        """Nominal sample rate 1/τ [Hz] (NaN when τ is not positive)."""
        tau = self.sample_interval_s
        return 1.0 / tau if tau > 0 else float("nan")

    @property
    def name(self) -> str:
        """The source file, else the run id, else ``"<recording>"``, for messages."""
        return self.source or self.meta.run_id or "<recording>"

    def column(self, name: str) -> FloatArray:
        """A column by name, as stored.

        Parameters
        ----------
        name : str
            The column.

        Returns
        -------
        numpy.ndarray
            Its values [its unit, :attr:`units`].

        Raises
        ------
        MissingColumnError
            No such column (the message lists the available ones).
        """
        try:
            return self.columns[name]
        except KeyError:
            raise MissingColumnError(
                f"{self.name}: no column {name!r}; available: "
                + ", ".join(repr(c) for c in self.columns)
            ) from None

    def signal(self, name: str | None = None) -> tuple[FloatArray, str]:
        """A signal in its canonical unit ([°/h] or [mg]) with that unit.

        Raw ``counts`` are converted with the metadata's scale factor K when one is
        given, otherwise returned as counts.

        Parameters
        ----------
        name : str, optional
            The signal column (default the first signal).

        Returns
        -------
        values : numpy.ndarray
            The signal [``unit``].
        unit : str
            ``"deg/h"``, ``"mg"`` or ``"counts"``.

        Raises
        ------
        MissingColumnError
            No such column, or no signal column at all.
        UnitError
            No unit is known for the column.
        """
        name = self._default(name, self.signals, "signal")
        values = self.column(name)
        unit = self.units.get(name)
        if not unit:
            raise UnitError(f"{self.name}: no unit is known for the signal column {name!r}")
        if units.normalize_signal_unit(unit) == "counts" and self.meta.scale_factor is not None:
            return units.counts_to_physical(
                values,
                self.meta.scale_factor,
                units.scale_factor_unit_or_default(self.meta.scale_factor_unit, self.name),
                self.sample_interval_s,
                f"{self.name}: signal column {name!r}",
            )
        return units.to_canonical(values, unit, f"{self.name}: signal column {name!r}")

    def temperature_c(self, name: str | None = None) -> FloatArray:
        r"""A temperature column in [°C].

        Raw counts are converted with the metadata's ``temperature_conversion``
        (:math:`T = \mathrm{gain}\cdot\mathrm{counts} + \mathrm{offset}`, int16 counts first
        made signed).

        Parameters
        ----------
        name : str, optional
            The temperature column (default the first).

        Returns
        -------
        numpy.ndarray
            Temperatures [°C].

        Raises
        ------
        MissingColumnError
            No such column.
        UnitError
            No unit known, or raw counts without a conversion.
        """
        name = self._default(name, self.temperatures, "temperature")
        values = self.column(name)
        unit = self.units.get(name)
        if not unit:
            raise UnitError(f"{self.name}: no unit is known for the temperature column {name!r}")
        if units.normalize_temperature_unit(unit) == "degC":
            return values
        conv = self.meta.temperature_conversion.get(name)
        if conv is None:
            raise UnitError.naming(
                f"{self.name}: temperature column {name!r} is in raw counts and no "
                "conversion to °C is given ({temp_conversion} GAIN,OFFSET[,int16], or "
                "temperature_conversion in the file's metadata)",
                "temp_conversion",
            )
        return units.temperature_conversion(conv).to_celsius(values, f"{self.name}: {name!r}")

    def temperature_counts(self, name: str) -> FloatArray:
        """A raw-count temperature column as stored, for models fitted in counts.

        Parameters
        ----------
        name : str
            The temperature column.

        Returns
        -------
        numpy.ndarray
            The column [counts], not converted.

        Raises
        ------
        UnitError
            The column is not in counts (e.g. in °C).
        """
        unit = self.units.get(name)
        if not unit or units.normalize_temperature_unit(unit) != "counts":
            raise UnitError.naming(
                f"{self.name}: the model's temperatures are raw counts, but column {name!r} "
                f"is in {unit or 'an unknown unit'}; give the data in counts ({{temp_unit}} "
                "counts) or refit the model with {temp_conversion}",
                "temp_unit",
                "temp_conversion",
            )
        return self.column(name)

    def temperatures_c(self, names: list[str] | tuple[str, ...] | None = None) -> FloatArray:
        """Temperatures as an ``(n_samples, n_sensors)`` array [°C].

        Parameters
        ----------
        names : sequence of str, optional
            The columns, in order (default every temperature column).

        Returns
        -------
        numpy.ndarray
            Temperatures [°C]; a view of the column when there is one.

        Raises
        ------
        MissingColumnError
            No temperature column named.
        UnitError
            A column in counts without a conversion.
        """
        names = tuple(names) if names is not None else self.temperatures
        if not names:
            raise MissingColumnError(f"{self.name}: no temperature columns named")
        if len(names) == 1:  # one column: a view of it (no copy; the (n, 1) array is read)
            return self.temperature_c(names[0]).reshape(-1, 1)
        cols = [self.temperature_c(n) for n in names]
        side = _side_by_side(cols)  # columns of one block as read: a view of them
        return side if side is not None else np.column_stack(cols)

    def _default(self, name: str | None, pool: tuple[str, ...], what: str) -> str:
        if name is not None:
            return name
        if not pool:
            raise MissingColumnError(
                f"{self.name}: no {what} column named; available: "
                + ", ".join(repr(c) for c in self.columns)
            )
        return pool[0]

    def time_scan(self) -> TimeScan:
        """The time checks (:func:`scan_time`), computed once per time array: validation,
        gaps, segments and the sample interval share one pass.  A new ``time_s`` object
        (``dataclasses.replace``, :meth:`select`) is scanned anew; writing into the time
        array in place is not detected."""
        if self._scan is None or self._scan[0] is not self.time_s:
            self._scan = (self.time_s, scan_time(self.time_s))
        return self._scan[1]

    def time_jitter(self) -> TimeJitter | None:
        """The scatter of the time steps (:func:`time_jitter`): host timestamps."""
        return time_jitter(self.time_s)

    def gaps(self, factor: float = GAP_FACTOR) -> list[Gap]:
        """Gaps in time (:func:`find_gaps`).

        Parameters
        ----------
        factor : float, optional
            A step longer than this many nominal steps is a gap (default ``GAP_FACTOR``, 1.5).

        Returns
        -------
        list of Gap
        """
        return find_gaps(self.time_s, factor=factor, scan=self.time_scan())

    def segments(self, factor: float = GAP_FACTOR) -> list[slice]:
        """Contiguous (gap-free) index ranges (:func:`contiguous_slices`).

        Parameters
        ----------
        factor : float, optional
            A step longer than this many nominal steps is a gap (default 1.5).

        Returns
        -------
        list of slice
        """
        return contiguous_slices(self.time_s, factor=factor, scan=self.time_scan())

    def select(self, index: slice | npt.NDArray[np.bool_] | npt.NDArray[np.intp]) -> Recording:
        """A recording of the selected rows (metadata and roles kept).

        Parameters
        ----------
        index : slice or numpy.ndarray of bool or int
            The rows.

        Returns
        -------
        Recording
        """
        return dataclasses.replace(
            self,
            time_s=self.time_s[index],
            columns={k: v[index] for k, v in self.columns.items()},
        )

    def with_columns(self, new: dict[str, FloatArray], new_units: dict[str, str]) -> Recording:
        """A copy with extra (or replaced) columns; roles unchanged.

        Parameters
        ----------
        new : dict of str to numpy.ndarray
            The columns to add or replace.
        new_units : dict of str to str
            Their units.

        Returns
        -------
        Recording
        """
        cols = dict(self.columns)
        cols.update(new)
        u = dict(self.units)
        u.update(new_units)
        return dataclasses.replace(self, columns=cols, units=u)

    def validate(
        self, required: list[str] | None = None, unit_parameters: Mapping[str, str] | None = None
    ) -> None:
        """Raise the first error of :func:`find_problems`, warn for the doubtful.

        Implausible values that are only doubtful are emitted as
        :class:`PlausibilityWarning`, timestamp jitter (:func:`time_jitter`) as a
        :class:`TimestampWarning`; other warnings, such as gaps, are reported by the caller.

        Parameters
        ----------
        required : list of str, optional
            Columns that must be present.
        unit_parameters : mapping of str to str, optional
            Signal column → the parameter its unit was given by, where not ``signal_unit``
            (``{"ax": "accel_unit"}``): a problem of that column names it instead.

        Raises
        ------
        MissingColumnError
            A required column is missing.
        MissingValueError
            NaN or empty values in a signal or temperature column.
        TimestampError
            Duplicate, backward or non-finite times.
        ThermocalInputError
            Any other error of :func:`find_problems`.
        """
        problems = [_unit_named(p, unit_parameters) for p in find_problems(self, required)]
        for p in problems:
            text = f"{self.name}: {p.message}"
            if p.severity == "warning" and p.kind.startswith("implausible"):
                warnings.warn(PlausibilityWarning.naming(text, *p.parameters), stacklevel=2)
            elif p.kind == "timestamp_jitter" and not any(q.severity == "error" for q in problems):
                warnings.warn(TimestampWarning.naming(text, *p.parameters), stacklevel=2)
        for p in problems:
            if p.severity == "error":
                cls = {
                    "missing_column": MissingColumnError,
                    "nan": MissingValueError,
                    "duplicate_time": TimestampError,
                    "backwards_time": TimestampError,
                    "nonfinite_time": TimestampError,
                }.get(p.kind, ThermocalInputError)
                raise cls.naming(f"{self.name}: {p.message}", *p.parameters)


def _unit_named(p: Problem, unit_parameters: Mapping[str, str] | None) -> Problem:
    """``p`` naming its column's own unit parameter (``unit_parameters``) where it names
    ``signal_unit``: a command whose accelerometer unit is ``accel_unit`` says so."""
    own = (unit_parameters or {}).get(p.column or "")
    if not own or "signal_unit" not in p.parameters:
        return p
    message = p.message.replace(COUNT_UNIT_EXAMPLES, _OWN_EXAMPLES.get(own, COUNT_UNIT_EXAMPLES))
    return dataclasses.replace(
        p,
        message=message.replace("{signal_unit}", "{" + own + "}"),
        parameters=tuple(own if q == "signal_unit" else q for q in p.parameters),
    )


COUNT_UNIT_EXAMPLES: Final = "{signal_unit} deg/s, mg, …"
"""The units the raw-count warning offers (:func:`_count_problems`) for any signal."""

_OWN_EXAMPLES: Final = {
    "accel_unit": "{accel_unit} mg, g, m/s^2, …",
    "gyro_unit": "{gyro_unit} deg/s, deg/h, rad/s, …",
}
"""The same offer where the column's unit has its own parameter (:func:`_unit_named`)."""


# --- pure helpers --------------------------------------------------------------------


DIFF_BLOCK = 1 << 18
"""Rows per block when time steps are scanned block by block (bounded working memory)."""


def _side_by_side(cols: list[FloatArray]) -> FloatArray | None:
    """The ``(n, k)`` read-only view of k float64 columns that lie evenly spaced in one
    buffer (the column-major block a reader filled), or None when they do not."""
    c0 = cols[0]
    base = c0.base
    if base is None or c0.ndim != 1 or c0.dtype != np.float64 or c0.size == 0:
        return None
    n = c0.size
    addr = [c.__array_interface__["data"][0] for c in cols]
    gap = addr[1] - addr[0]
    same = all(
        c.base is base and c.ndim == 1 and c.size == n and c.strides == (8,) and c.dtype == c0.dtype
        for c in cols
    )
    if not same or gap < 8 * n or any(b - a != gap for a, b in itertools.pairwise(addr)):
        return None
    view: FloatArray = np.lib.stride_tricks.as_strided(
        c0, shape=(n, len(cols)), strides=(8, gap), writeable=False
    )
    return view


def time_steps(time_s: FloatArray, block: int = DIFF_BLOCK) -> Iterator[tuple[int, FloatArray]]:
    r"""Blocks of the time steps, in constant extra memory.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    block : int, optional
        Largest block length (default :data:`DIFF_BLOCK`).

    Yields
    ------
    offset : int
        Index i of the block's first step.
    steps : numpy.ndarray
        :math:`\Delta t_i = t_{i+1} - t_i` [s] for the block.
    """
    n = int(time_s.size) - 1
    for a in range(0, max(n, 0), block):
        b = min(n, a + block)
        yield a, time_s[a + 1 : b + 1] - time_s[a:b]


REGULAR_GRID_ULPS = 64
"""Steps that differ by at most this many units in the last place of the largest time stamp
differ only by the rounding of the stamps: the grid is regular (:func:`scan_time`)."""


@dataclass(frozen=True)
class TimeScan:
    """What one pass over the time steps ``Δt_i = t[i+1] − t[i]`` finds (:func:`scan_time`).

    ``interval_s`` is the nominal sample interval [s]: on a regular grid (every step within
    :data:`REGULAR_GRID_ULPS` units in the last place of the largest stamp of each other)
    the mean step ``(t[n−1] − t[0]) / (n − 1)``, which the median then equals to that
    rounding; otherwise the median step (one O(n) partition).  NaN for fewer than 2 samples
    or a non-finite time.  ``duplicate_rows``/``backward_rows`` are the ``i`` with
    ``Δt_i = 0`` / ``Δt_i < 0``.

    Attributes
    ----------
    n : int
        Number of samples.
    finite : bool
        Every time is finite.
    min_step_s, max_step_s : float
        Smallest and largest step [s].
    interval_s : float
        Nominal sample interval [s].
    regular : bool
        The stamps lie on a regular grid.
    duplicate_rows, backward_rows : numpy.ndarray of intp
        The ``i`` with ``Δt_i = 0`` and ``Δt_i < 0``.
    """

    n: int
    finite: bool
    min_step_s: float
    max_step_s: float
    interval_s: float
    regular: bool
    duplicate_rows: npt.NDArray[np.intp]
    backward_rows: npt.NDArray[np.intp]


def scan_time(time_s: FloatArray) -> TimeScan:
    """Scan a time column once, block by block, with bounded memory.

    Finds whether it is finite, its smallest and largest step, duplicates, backward
    steps and the nominal interval (:class:`TimeScan`).  The exact median is computed
    only when the grid is not regular (the checks of a 10⁸-row file otherwise take six
    differences and four medians).

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].

    Returns
    -------
    TimeScan

    Examples
    --------
    >>> import numpy as np
    >>> sc = scan_time(np.array([0.0, 0.1, 0.2, 0.2, 0.4]))
    >>> round(sc.interval_s, 3), sc.duplicate_rows.tolist()
    (0.1, [2])
    """
    n = int(time_s.size)
    if n >= 2:
        fast = _scan_finite(time_s)
        if fast is not None:  # the usual case: one pass, no mask as long as the column
            return fast
    return _scan_any(time_s)


def _scan_finite(time_s: FloatArray) -> TimeScan | None:
    """:func:`scan_time` of at least two stamps in one pass over the steps, each block's
    steps written into one reused buffer; None when a step is not finite (NaN or ±inf:
    :func:`_scan_any` then looks at the stamps themselves).  With every step finite and the
    first stamp finite, every stamp is (``t[i+1]`` is finite when ``t[i]`` and
    ``t[i+1] − t[i]`` are): the column's finiteness needs no pass of its own."""
    n = int(time_s.size)
    if time_s.dtype != np.float64 or not math.isfinite(float(time_s[0])):
        return None
    lo, hi = math.inf, -math.inf
    dup_parts: list[npt.NDArray[np.intp]] = []
    back_parts: list[npt.NDArray[np.intp]] = []
    buf = np.empty(min(n - 1, DIFF_BLOCK), dtype=np.float64)
    for a in range(0, n - 1, DIFF_BLOCK):
        dt = buf[: min(n - 1, a + DIFF_BLOCK) - a]
        with np.errstate(over="ignore", invalid="ignore"):  # a step that is not finite: below
            np.subtract(time_s[a + 1 : a + 1 + dt.size], time_s[a : a + dt.size], out=dt)
        b_lo, b_hi = float(dt.min()), float(dt.max())
        if not (math.isfinite(b_lo) and math.isfinite(b_hi)):
            return None
        lo, hi = min(lo, b_lo), max(hi, b_hi)
        if lo <= 0.0:
            dup_parts.append(a + np.flatnonzero(dt == 0))
            back_parts.append(a + np.flatnonzero(dt < 0))
    return _time_scan(time_s, lo, hi, dup_parts, back_parts)


def _time_scan(
    time_s: FloatArray,
    lo: float,
    hi: float,
    dup_parts: list[npt.NDArray[np.intp]],
    back_parts: list[npt.NDArray[np.intp]],
) -> TimeScan:
    """The :class:`TimeScan` of a finite time column of at least two stamps from its
    smallest and largest step and the rows of its zero and negative steps."""
    n = int(time_s.size)
    empty = np.zeros(0, dtype=np.intp)
    dup = np.concatenate(dup_parts) if dup_parts else empty
    back = np.concatenate(back_parts) if back_parts else empty
    stamp_ulp = math.ulp(max(abs(float(time_s[0])), abs(float(time_s[-1]))))  # no overflow
    regular = lo > 0 and hi - lo <= REGULAR_GRID_ULPS * stamp_ulp
    if regular:
        interval = float(time_s[-1] - time_s[0]) / (n - 1)
    else:
        interval = float(np.median(np.diff(time_s), overwrite_input=True))
    return TimeScan(n, True, lo, hi, interval, regular, dup, back)


def _scan_any(time_s: FloatArray) -> TimeScan:
    """:func:`scan_time` of any time column: a mask of the finite stamps first (fewer than
    two samples, or a stamp that is not finite, have no steps to scan)."""
    n = int(time_s.size)
    empty = np.zeros(0, dtype=np.intp)
    nan = float("nan")
    if n < 2 or not bool(np.isfinite(time_s).all()):
        finite = n == 0 or bool(np.isfinite(time_s).all())
        return TimeScan(n, finite, nan, nan, nan, False, empty, empty)
    lo, hi = math.inf, -math.inf
    dup_parts: list[npt.NDArray[np.intp]] = []
    back_parts: list[npt.NDArray[np.intp]] = []
    for a, dt in time_steps(time_s):
        lo = min(lo, float(dt.min()))
        hi = max(hi, float(dt.max()))
        if lo <= 0.0:
            dup_parts.append(a + np.flatnonzero(dt == 0))
            back_parts.append(a + np.flatnonzero(dt < 0))
    return _time_scan(time_s, lo, hi, dup_parts, back_parts)


def median_interval(time_s: FloatArray) -> float:
    """Nominal time step: the median step, or the mean step on a regular grid.

    On a regular grid the two agree to the rounding of the stamps (:func:`scan_time`).

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].

    Returns
    -------
    float
        The nominal step [s]; NaN for fewer than 2 samples.

    Examples
    --------
    >>> import numpy as np
    >>> median_interval(np.array([0.0, 1.0, 2.0, 5.0]))
    1.0
    """
    return scan_time(time_s).interval_s


def find_gaps(
    time_s: FloatArray, factor: float = GAP_FACTOR, scan: TimeScan | None = None
) -> list[Gap]:
    """Gaps: steps longer than ``factor`` × the nominal step.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    factor : float, optional
        Gap threshold in nominal steps (default ``GAP_FACTOR``, 1.5).
    scan : TimeScan, optional
        :func:`scan_time` of ``time_s`` when the caller has it already.

    Returns
    -------
    list of Gap
        One per gap, ``start_s`` measured from the first sample [s].

    Examples
    --------
    >>> import numpy as np
    >>> find_gaps(np.array([0.0, 1.0, 2.0, 5.0, 6.0]))
    [Gap(index=2, start_s=2.0, length_s=3.0)]
    """
    if time_s.size < 3:
        return []
    sc = scan if scan is not None else scan_time(time_s)
    med = sc.interval_s
    if not med > 0 or not sc.max_step_s > factor * med:  # no step long enough: no pass
        return []
    t0 = float(time_s[0])
    out: list[Gap] = []
    for a, dt in time_steps(time_s):
        for i in np.flatnonzero(dt > factor * med):
            j = a + int(i)
            out.append(Gap(j, float(time_s[j] - t0), float(dt[i])))
    return out


def contiguous_slices(
    time_s: FloatArray, factor: float = GAP_FACTOR, scan: TimeScan | None = None
) -> list[slice]:
    """Index ranges between gaps (one slice for a gap-free recording).

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    factor : float, optional
        Gap threshold in nominal steps (default 1.5).
    scan : TimeScan, optional
        :func:`scan_time` of ``time_s`` when known.

    Returns
    -------
    list of slice

    Examples
    --------
    >>> import numpy as np
    >>> contiguous_slices(np.array([0.0, 1.0, 2.0, 5.0, 6.0]))
    [slice(0, 3, None), slice(3, 5, None)]
    """
    gaps = find_gaps(time_s, factor, scan)
    bounds = [0] + [g.index + 1 for g in gaps] + [int(time_s.size)]
    return [slice(a, b) for a, b in itertools.pairwise(bounds) if b > a]


JITTER_RELATIVE = 0.1
"""Time steps scattered by more than this fraction of their median (half the 5–95 %
range) are host-timestamp jitter, reported with ``rate_hz`` as the remedy."""
JITTER_STEPS = 1 << 20
"""Steps of the time column (its first) that the jitter is measured on: bounded memory."""


@dataclass(frozen=True)
class TimeJitter:
    """The scatter of the time steps ``Δt_i = t[i+1] − t[i]`` of a recording's first
    :data:`JITTER_STEPS` steps (:func:`time_jitter`).

    ``interval_s`` is their median [s]; ``relative`` half their 5–95 % percentile range
    over the median (``0.3``: the steps scatter ±30 % around it); ``n_same`` the steps of
    zero length (a burst of samples stamped at the same instant by a host);
    ``n_steps`` how many steps were measured.

    Attributes
    ----------
    interval_s : float
        Median step [s].
    relative : float
        Half the 5–95 % range of the steps over the median.
    n_same : int
        Steps of zero length.
    n_steps : int
        Steps measured.
    """

    interval_s: float
    relative: float
    n_same: int
    n_steps: int

    @property
    def significant(self) -> bool:
        """Scatter beyond :data:`JITTER_RELATIVE`, or samples sharing a timestamp."""
        return self.relative > JITTER_RELATIVE or self.n_same > 0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the fields and :attr:`significant`."""
        return {**dataclasses.asdict(self), "significant": self.significant}

    def message(self) -> str:
        """What a warning says of it, with the remedy (``{rate_hz}`` where it names that
        parameter, as :class:`Problem` writes it)."""
        same = (
            f", {self.n_same} samples stamped at the same instant as the one before"
            if self.n_same
            else ""
        )
        return (
            f"timestamp jitter: the sample intervals scatter ±{100 * self.relative:.3g} % "
            f"(5–95 %) around their median {self.interval_s:.6g} s{same} (host timestamps, "
            "e.g. Bluetooth?); give {rate_hz} HZ to take the samples at the sensor's nominal "
            "rate"
        )


def time_jitter(time_s: FloatArray) -> TimeJitter | None:
    r"""The jitter of a time column's steps, measured on its first :data:`JITTER_STEPS` steps.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].

    Returns
    -------
    TimeJitter or None
        None for fewer than 3 samples, a time that is not finite, or steps that go
        backwards (refused elsewhere).

    Notes
    -----
    .. math::
        \mathrm{relative} = \frac{P_{95}(\Delta t) - P_{5}(\Delta t)}{2\,\mathrm{median}(\Delta t)}

    0 for a regular grid; 0.27 for host timestamps of a link whose latency scatters
    uniformly over ±30 % of the period (the 5–95 % range of a uniform ±30 % is ±27 %).
    """
    t = time_s[: JITTER_STEPS + 1]
    if t.size < 3 or not all_finite(t):
        return None
    dt = np.diff(t)
    if bool((dt < 0).any()):
        return None
    n_same = int(np.count_nonzero(dt == 0))
    med, p5, p95 = _median_p5_p95(dt)
    if not med > 0:
        return TimeJitter(med, math.inf, n_same, int(dt.size))
    return TimeJitter(med, (p95 - p5) / (2.0 * med), n_same, int(dt.size))


def _jitter_bounded(scan: TimeScan) -> bool:
    r"""Whether the smallest and largest of all the time steps (:func:`scan_time`) show
    that the jitter of the first :data:`JITTER_STEPS` (:func:`time_jitter`) cannot be
    significant, without measuring it.

    Parameters
    ----------
    scan : TimeScan
        The scan of the time column.

    Returns
    -------
    bool
        True when every step is positive and the steps spread by at most
        :data:`JITTER_RELATIVE` of the smallest: then no step is of zero length and

        .. math::
            \mathrm{relative} = \frac{P_{95} - P_{5}}{2\,\mathrm{median}}
            \le \frac{\Delta t_{\max} - \Delta t_{\min}}{2\,\Delta t_{\min}}
            \le \frac{\mathrm{JITTER\_RELATIVE}}{2}

        (the percentiles and the median of any steps lie between the smallest and the
        largest), half the threshold: not significant.  False says nothing (measure it).
    """
    lo, hi = scan.min_step_s, scan.max_step_s
    return bool(scan.finite and lo > 0 and hi - lo <= JITTER_RELATIVE * lo)


def _median_p5_p95(steps: FloatArray) -> tuple[float, float, float]:
    """``np.median`` and ``np.percentile(…, [5, 95])`` (linear) of at least two finite
    values, equal to them to the bit, from one partition of ``steps`` (reordered in place)
    instead of one per call: the median's middle value(s) and each percentile's two
    neighbours are placed together, then read as numpy reads them (the mean of the two
    middle values; ``a + (b − a)·γ``, or ``b − (b − a)·(1 − γ)`` for γ ≥ ½, at the virtual
    index (n − 1)·q)."""
    n = steps.size
    virtual = (n - 1) * (np.asarray([5.0, 95.0]) / 100)
    below = np.floor(virtual).astype(np.intp)
    above = np.minimum(below + 1, n - 1)
    half = n // 2
    steps.partition(sorted({half - 1 + n % 2, half, *below.tolist(), *above.tolist()}))
    med = float(steps[half]) if n % 2 else float((steps[half - 1] + steps[half]) / 2)
    a, b, gamma = steps[below], steps[above], virtual - below
    diff = b - a
    q = np.where(gamma >= 0.5, b - diff * (1 - gamma), a + diff * gamma)
    return med, float(q[0]), float(q[1])


LOST_SAMPLE_JUMP = 0.5
"""A rise of the host-latency floor by more than this many nominal periods at one step is
samples lost there (:func:`nominal_time`)."""
LATENCY_WINDOW = 32
"""Samples before a step over which the latency floor before it is taken (:func:`nominal_time`)."""


def nominal_time(time_s: FloatArray, rate_hz: float) -> tuple[FloatArray, int]:
    r"""Host timestamps replaced by the sensor's nominal grid, and the samples found lost.

    A host stamps each sample at its arrival, :math:`t_i = T_0 + (i + k_i)/r + \ell_i`
    with the latency :math:`\ell_i \ge 0` and :math:`k_i` the samples lost before sample
    i (non-decreasing).  In the offsets :math:`o_i = (t_i - t_0) r - i` a burst of late
    samples only rises above the latency floor; a lost sample lifts the floor by one
    period.  At each step i the floor after it, :math:`m_{i+1} = \min_{j>i} o_j`, is
    compared with the floor before it, :math:`q_i = \min(o_{i-W+1} \ldots o_i)`
    (W = :data:`LATENCY_WINDOW`); where :math:`m_{i+1} - q_i`, less the samples already
    counted lost within the window, exceeds :data:`LOST_SAMPLE_JUMP`, its rounding is
    lost there, when sample i + 1 itself lies that many periods up (within half that
    margin).  Within a burst next to a loss a sample may be placed one period off; a
    slow drift of the host's clock adds none.

    Parameters
    ----------
    time_s : numpy.ndarray
        Host timestamps [s], finite, at least 2.
    rate_hz : float
        The sensor's nominal sample rate r [Hz].

    Returns
    -------
    time_s : numpy.ndarray
        :math:`t'_i = t_0 + (m_0 + i + k_i)/r` [s].
    n_lost : int
        Total samples found lost.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.array([0.0, 0.01, 0.02, 0.04, 0.05]) + np.array([0, 3, 0, 2, 0]) * 1e-3
    >>> new, lost = nominal_time(t, 100.0)
    >>> np.round(new, 3).tolist(), lost
    ([0.0, 0.01, 0.02, 0.04, 0.05], 1)
    """
    n = int(time_s.size)
    i = np.arange(n, dtype=np.float64)
    o = (time_s - time_s[0]) * rate_hz - i
    m = np.minimum.accumulate(o[::-1])[::-1]
    w = min(LATENCY_WINDOW, n)
    padded = np.concatenate([np.full(w - 1, np.inf), o])
    q = np.lib.stride_tricks.sliding_window_view(padded, w).min(axis=1)  # q[i]: o[i-w+1..i]
    jump = m[1:] - q[:-1]
    lost = np.zeros(n, dtype=np.float64)  # lost[i + 1]: samples lost between i and i + 1
    for j in np.flatnonzero(jump > LOST_SAMPLE_JUMP):
        earlier = float(lost[max(0, j - w + 2) : j + 1].sum())
        rise = float(jump[j]) - earlier
        n_lost = round(rise)
        # sample j + 1 itself must lie n_lost periods up (not merely late, before the loss)
        if rise > LOST_SAMPLE_JUMP and o[j + 1] - q[j] - earlier > n_lost - LOST_SAMPLE_JUMP / 2:
            lost[j + 1] = n_lost
    k = np.cumsum(lost)
    out: FloatArray = time_s[0] + (m[0] + i + k) / rate_hz
    return out, int(k[-1])


def _nan_problems(rec: Recording, name: str, arr: FloatArray) -> list[Problem]:
    """NaN, empty or infinite values in the column ``name``, with the first row: an error
    in a signal or temperature column, a warning in another."""
    if all_finite(arr):  # the usual case: no mask as long as the column
        return []
    nan = ~np.isfinite(arr)
    n_nan = int(np.count_nonzero(nan))
    if not n_nan:
        return []
    first = int(np.argmax(nan))
    sev: Literal["error", "warning"] = (
        "error" if name in rec.signals or name in rec.temperatures else "warning"
    )
    return [
        Problem(
            "nan",
            f"column {name!r} has {n_nan} NaN/empty/infinite values, first at row {first}",
            severity=sev,
            column=name,
            row=first,
        )
    ]


def _column_problems(rec: Recording) -> tuple[list[Problem], dict[str, list[Problem]]]:
    """Every column's NaN problems (in the columns' order) and each temperature's and
    signal's plausibility problems (by role and name: ``"T:" + name``, ``"S:" + name``),
    each column taken from ``rec.columns`` once: the other columns, then the temperatures,
    then the signals, so that a recording whose columns are read on demand (``metrics``,
    ``inspect``: the last one kept) reads each once, and the last signal is still at hand
    for the checks that follow."""
    names = list(rec.columns)
    roles = set(rec.temperatures) | set(rec.signals)
    order = [n for n in names if n not in roles]
    order += [n for n in dict.fromkeys((*rec.temperatures, *rec.signals)) if n in names]
    nan: dict[str, list[Problem]] = {}
    plausible: dict[str, list[Problem]] = {}
    for name in order:
        arr = rec.columns[name]
        span = _finite_range(arr)  # one pass: finite, and the signal's plausible range
        nan[name] = [] if span is not None else _nan_problems(rec, name, arr)
        del arr  # a lazy file's mapping releases a column before it reads the next: no hold
        if name in rec.temperatures:
            plausible["T:" + name] = _temperature_problems(rec, name)
        if name in rec.signals:
            found = _signal_problems(rec, name, span)
            plausible["S:" + name] = found + _count_problems(rec, name)
    return [p for n in names for p in nan[n]], plausible


RANGE_BLOCK = 1 << 16
"""Values per block of :func:`_finite_range` (half a megabyte: each block's minimum and
maximum are read while it is in the cache)."""


def _finite_range(arr: FloatArray, block: int = RANGE_BLOCK) -> tuple[float, float] | None:
    """The smallest and largest value of a float64 column whose every value is finite, in
    one pass over its memory (block by block, each block's minimum then maximum); None for
    an empty column, another dtype, or a NaN or infinite value anywhere (the minimum or
    maximum of a block holding one is not finite)."""
    if arr.size == 0 or arr.dtype != np.float64:
        return None
    lo, hi = math.inf, -math.inf
    for a in range(0, arr.size, block):
        part = arr[a : a + block]
        b_lo, b_hi = float(part.min()), float(part.max())
        if not (math.isfinite(b_lo) and math.isfinite(b_hi)):
            return None
        lo, hi = min(lo, b_lo), max(hi, b_hi)
    return lo, hi


RATE_HINT = "host timestamps? give {rate_hz} HZ to take the samples at the sensor's nominal rate"
"""What a duplicate timestamp's message says to do (``{rate_hz}``: the parameter)."""


def _jitter_problems(t: FloatArray, found: list[Problem], scan: TimeScan) -> list[Problem]:
    """Timestamp jitter (:func:`time_jitter`) as a warning, unless the time is already
    refused as not finite or going backwards (``found``), or the scan of every step
    (:func:`scan_time`) bounds it below the threshold already (:func:`_jitter_bounded`)."""
    if any(p.kind in ("nonfinite_time", "backwards_time") for p in found):
        return []
    if _jitter_bounded(scan):
        return []
    jit = time_jitter(t)
    if jit is None or not jit.significant:
        return []
    return [
        Problem(
            "timestamp_jitter",
            jit.message(),
            severity="warning",
            column="time",
            parameters=("rate_hz",),
        )
    ]


def find_problems(rec: Recording, required: list[str] | None = None) -> list[Problem]:
    """Everything wrong with a recording, errors first, without raising.

    Checks: required columns present; time finite, strictly increasing (duplicate and
    backwards steps named by row); NaN counts per column with the first row; gaps
    (warning); unknown unit strings; fewer than 2 samples.

    Parameters
    ----------
    rec : Recording
        The recording.
    required : list of str, optional
        Columns that must be present.

    Returns
    -------
    list of Problem
    """
    probs: list[Problem] = []
    for name in required or []:
        if name not in rec.columns:
            probs.append(
                Problem(
                    "missing_column",
                    f"no column {name!r}; available: " + ", ".join(repr(c) for c in rec.columns),
                    column=name,
                )
            )
    t = rec.time_s
    if t.size == 0:
        probs.append(Problem("empty", "the recording has no samples"))
        return probs
    scan = rec.time_scan()
    bad_t = np.flatnonzero(~np.isfinite(t)) if not scan.finite else np.zeros(0, dtype=np.intp)
    if bad_t.size:
        probs.append(
            Problem(
                "nonfinite_time",
                f"time is missing or not finite in {bad_t.size} rows, first at row {bad_t[0]}",
                column="time",
                row=int(bad_t[0]),
            )
        )
    else:
        dup, back = scan.duplicate_rows, scan.backward_rows
        if dup.size:
            probs.append(
                Problem(
                    "duplicate_time",
                    f"duplicate timestamp {float(t[dup[0] + 1])!r} at row {dup[0] + 1} "
                    f"({dup.size} duplicates in all; {RATE_HINT})",
                    column="time",
                    row=int(dup[0] + 1),
                    parameters=("rate_hz",),
                )
            )
        if back.size:
            probs.append(
                Problem(
                    "backwards_time",
                    f"time goes backwards at row {back[0] + 1} ({float(t[back[0]])!r} → "
                    f"{float(t[back[0] + 1])!r}; {back.size} backward steps in all)",
                    column="time",
                    row=int(back[0] + 1),
                )
            )
    nan, plausible = _column_problems(rec)
    probs.extend(nan)
    for name in rec.signals:
        u = rec.units.get(name, "")
        if u:
            try:
                units.normalize_signal_unit(u)
            except UnitError as exc:
                probs.append(Problem("unit", f"column {name!r}: {exc}", column=name))
    if t.size < 2:
        probs.append(Problem("too_short", "the recording has fewer than 2 samples"))
    probs.extend(_jitter_problems(t, probs, scan))
    if not any(p.kind in ("nonfinite_time", "duplicate_time", "backwards_time") for p in probs):
        gaps = rec.gaps()
        if gaps:
            total = sum(g.length_s for g in gaps)
            probs.append(
                Problem(
                    "gaps",
                    f"{len(gaps)} gaps in time (longer than {GAP_FACTOR}× the median "
                    f"interval {scan.interval_s:.6g} s), {total:.6g} s in all; "
                    "first after row "
                    f"{gaps[0].index} at {gaps[0].start_s:.6g} s",
                    severity="warning",
                    column="time",
                    row=gaps[0].index,
                )
            )
    probs.extend(_plausibility(rec, plausible))
    order = {"error": 0, "warning": 1}
    return sorted(probs, key=lambda p: order[p.severity])


ABSOLUTE_ZERO_C = -273.15
"""No temperature is below this [°C]."""
PLAUSIBLE_TEMPERATURE_C = (-100.0, 200.0)
"""Temperatures a test chamber or a sensor reaches [°C]; outside, a unit is likely wrong."""
FEW_SAMPLES = 10
"""Fewer sample rows than this are reported (a warning; commands needing more refuse)."""
PLAUSIBLE_SIGNAL = {"rate": 1e8, "accel": 1e7}
"""Largest |value| any gyro [°/h] (≈ 28 000 °/s) or accelerometer [mg] (10 000 g) outputs."""
PLAUSIBLE_COUNTS = 2.0**64
"""Largest |value| of a raw count column without a scale factor: no ADC or pulse counter
has more than 64 bits (and float64 is exact for integers only up to 2⁵³)."""
NON_INTEGER_COUNTS_SHARE = 0.1
"""A column declared in raw counts of which at least this share of the finite values is
not an integer is reported (a warning: values declared as counts): an ADC or
a pulse counter outputs integers; fractions mean physical values or averaged counts."""


def _physical_of_counts(
    rec: Recording,
) -> Callable[[FloatArray], tuple[FloatArray, str]] | None:
    """The conversion counts → [°/h] or [mg] of ``rec``'s scale factor, for a block of
    rows and without the overflow refusal (the caller reports the row itself); None when
    the recording states no scale factor."""
    k = rec.meta.scale_factor
    if k is None:
        return None
    k_unit = units.scale_factor_unit_or_default(rec.meta.scale_factor_unit, rec.name)
    try:
        tau = rec.sample_interval_s if units.SCALE_FACTOR_UNITS[k_unit][0] else 1.0
    except (KeyError, ThermocalInputError):
        return None  # an unknown unit or no interval: refused where the signal is used

    def conv(part: FloatArray) -> tuple[FloatArray, str]:
        return units.counts_to_physical(part, k, k_unit, tau, finite=False)

    return conv


@dataclass(frozen=True)
class Extrema:
    """Smallest and largest finite value of a column, their first rows, and the number
    of finite values (:func:`finite_extrema`).

    Attributes
    ----------
    lo, hi : float
        Smallest and largest finite value.
    lo_row, hi_row : int
        Their first rows.
    count : int
        Number of finite values.
    """

    lo: float
    lo_row: int
    hi: float
    hi_row: int
    count: int


MEDIAN_BLOCK = 1 << 18
"""Values per block of :func:`median_in_blocks`."""


def median_in_blocks(
    values: Callable[[int, int], FloatArray], n: int, block: int = MEDIAN_BLOCK
) -> float:
    """The exact median of ``n`` values computed block by block, in bounded memory.

    Selection by bracketing: a strided sample of ≈ 65 536 values gives bounds
    ``lo ≤ hi`` around its median; one pass counts the values below ``lo`` and keeps
    those within ``[lo, hi]``; when the middle order statistic(s) ``(n − 1)//2`` and
    ``n//2`` fall among the kept ones they are selected there (``np.partition``), their
    mean is the median as ``np.median`` forms it (the same bits).  Otherwise the bracket
    is widened (three tries), and at last the whole array is built.

    Parameters
    ----------
    values : callable
        ``values(a, b)`` returns rows ``a … b − 1`` (NaN-free; the caller checks).
    n : int
        Number of values.
    block : int, optional
        Rows per block (default :data:`MEDIAN_BLOCK`).

    Returns
    -------
    float
        ``np.median`` of the n values [their unit].

    References
    ----------
    - R. W. Floyd and R. L. Rivest, "Expected time bounds for selection",
      Communications of the ACM 18(3), pp. 165-172, 1975.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.arange(11.0)
    >>> median_in_blocks(lambda a, b: x[a:b], 11, block=2)
    5.0
    """
    return median_of_parts(
        lambda: (values(a, min(n, a + block)) for a in range(0, n, block)), n, block
    )


def median_of_parts(
    parts: Callable[[], Iterator[FloatArray]], n: int, block: int = MEDIAN_BLOCK
) -> float:
    """The exact median of ``n`` values handed over in parts, in bounded memory.

    :func:`median_in_blocks` for values that are not rows of one array (the nonzero steps
    of a column between its finite samples, say): ``parts()`` yields them in order, in
    parts of any length, and is called once per pass (two to five passes).  Up to
    ``4 × block`` values are gathered and handed to ``np.median``.

    Parameters
    ----------
    parts : callable
        Returns an iterator over the parts (NaN-free; the caller checks), together ``n``
        values.
    n : int
        Number of values.
    block : int, optional
        Values at or below ``4 × block`` are gathered whole (default :data:`MEDIAN_BLOCK`).

    Returns
    -------
    float
        ``np.median`` of the n values [their unit].

    Notes
    -----
    Selection by bracketing: a strided sample gives bounds :math:`lo \\le hi` around its
    median; one pass counts the values below ``lo`` and keeps those in ``[lo, hi]``; the
    order statistics :math:`\\lfloor (n-1)/2 \\rfloor` and :math:`\\lfloor n/2 \\rfloor` are
    selected among the kept ones (their mean for an even ``n``, as ``np.median`` forms it).

    References
    ----------
    - R. W. Floyd and R. L. Rivest, "Expected time bounds for selection",
      Communications of the ACM 18(3), pp. 165-172, 1975.

    Examples
    --------
    >>> import numpy as np
    >>> median_of_parts(lambda: iter([np.array([3.0, 1.0]), np.array([2.0, 5.0])]), 4)
    2.5
    """
    if n <= 4 * block:
        return float(np.median(np.concatenate([np.empty(0), *parts()]), overwrite_input=True))
    k_lo, k_hi = (n - 1) // 2, n // 2
    step = max(1, n // 65536)
    samples: list[FloatArray] = []
    a = 0
    for v in parts():  # copies: a strided view would keep its whole part alive
        samples.append(v[(-a) % step :: step].copy())
        a += v.size
    sample = np.sort(np.concatenate(samples))
    m = sample.size
    widen = 0.01
    for _ in range(3):
        lo = sample[max(0, int(m * (0.5 - widen)))]
        hi = sample[min(m - 1, int(m * (0.5 + widen)))]
        below = 0
        kept: list[FloatArray] = []
        for v in parts():
            below += int(np.count_nonzero(v < lo))
            kept.append(v[(v >= lo) & (v <= hi)])
        mid = np.concatenate(kept)
        if below <= k_lo and k_hi < below + mid.size:
            i, j = k_lo - below, k_hi - below
            part = np.partition(mid, [i, j])
            return float(np.mean(part[[i, j]])) if i != j else float(part[i])
        widen *= 4.0
    whole = np.concatenate(list(parts()))
    return float(np.median(whole, overwrite_input=True))


def all_finite(arr: npt.NDArray[np.float64]) -> bool:
    """Every element finite, without a full-size mask on the usual path.

    The sum is finite exactly when every element is (or it overflowed: then the mask).

    Parameters
    ----------
    arr : numpy.ndarray
        Values.

    Returns
    -------
    bool
        True for an empty array.

    Examples
    --------
    >>> import numpy as np
    >>> all_finite(np.array([1.0, np.nan])), all_finite(np.array([1e308, 1e308]))
    (False, True)
    """
    if arr.size == 0:
        return True
    with np.errstate(over="ignore", invalid="ignore"):
        if math.isfinite(float(np.sum(arr))):
            return True
    return bool(np.isfinite(arr).all())


def is_increasing(t: FloatArray, block: int = DIFF_BLOCK) -> bool:
    """Whether ``t`` is strictly increasing, checked in blocks.

    Parameters
    ----------
    t : numpy.ndarray
        Sample times [s].
    block : int, optional
        Rows per block (default :data:`DIFF_BLOCK`).

    Returns
    -------
    bool
    """
    for a in range(0, max(t.size - 1, 0), block):
        if not bool(np.all(np.diff(t[a : a + block + 1]) > 0)):
            return False
    return True


def finite_extrema(arr: FloatArray, block: int = DIFF_BLOCK) -> Extrema | None:
    """:class:`Extrema` of the finite values of an array, scanned in blocks.

    A few bytes of working memory per row of a block, none per row of the column.

    Parameters
    ----------
    arr : numpy.ndarray
        Values [any unit].
    block : int, optional
        Rows per block (default :data:`DIFF_BLOCK`).

    Returns
    -------
    Extrema or None
        None when there is no finite value.
    """
    best: list[Any] = [math.inf, -1, -math.inf, -1, 0]
    for a in range(0, arr.size, block):
        part = arr[a : a + block]
        fin = np.isfinite(part)
        k = int(np.count_nonzero(fin))
        if k == 0:
            continue
        best[4] += k
        lo_part = np.where(fin, part, np.inf)
        i = int(np.argmin(lo_part))
        if part[i] < best[0]:
            best[0], best[1] = float(part[i]), a + i
        np.copyto(lo_part, part)
        lo_part[~fin] = -np.inf
        j = int(np.argmax(lo_part))
        if part[j] > best[2]:
            best[2], best[3] = float(part[j]), a + j
    if best[4] == 0:
        return None
    return Extrema(best[0], best[1], best[2], best[3], best[4])


def _temperature_problems(rec: Recording, name: str) -> list[Problem]:
    """A constant temperature column (warning), one below absolute zero (error) or
    outside the plausible range in °C (warning, with the likely cause)."""
    probs: list[Problem] = []
    arr = rec.columns.get(name)
    if arr is None or not rec.units.get(name):
        return probs
    ext = finite_extrema(arr)
    if ext is not None and ext.count >= 2 and ext.hi == ext.lo:
        probs.append(
            Problem(
                "implausible_constant_temperature",
                f"temperature column {name!r} is constant ({ext.lo:.6g} "
                f"{rec.units[name]}): no temperature dependence can be seen in it",
                severity="warning",
                column=name,
            )
        )
    try:
        temp = rec.temperature_c(name)
    except units.ConversionOverflowError:
        raise  # a finite count beyond float64 once converted: no °C to check
    except ThermocalInputError:
        return probs  # raw counts without a conversion: checked where they are used
    ext = finite_extrema(temp)
    if ext is None:
        return probs
    lo_row, hi_row, lo, hi = ext.lo_row, ext.hi_row, ext.lo, ext.hi
    if lo < ABSOLUTE_ZERO_C:
        probs.append(
            Problem(
                "implausible_temperature",
                f"temperature column {name!r} reads {lo:.6g} °C at row {lo_row}, below "
                "absolute zero (−273.15 °C): a wrong unit, offset or conversion",
                column=name,
                row=lo_row,
            )
        )
        return probs
    a, b = PLAUSIBLE_TEMPERATURE_C
    if lo < a or hi > b:
        bad_row, bad = (hi_row, hi) if hi > b else (lo_row, lo)
        vals = temp[np.isfinite(temp)]  # only on this warning's path
        if lo >= 173.0 and hi <= 473.0:
            hint = "kelvin? give the data in °C"
        elif np.all(vals == np.round(vals)) and hi > 1000.0:
            hint = "raw ADC counts? give {temp_unit} counts and {temp_conversion}"
        else:
            hint = "check the unit and the conversion"
        probs.append(
            Problem(
                "implausible_temperature",
                f"temperature column {name!r} reads {bad:.6g} °C at row {bad_row}, "
                f"outside {a:g}…{b:+g} °C ({hint})",
                severity="warning",
                column=name,
                row=bad_row,
                parameters=("temp_unit", "temp_conversion"),
            )
        )
    return probs


def _signal_problems(
    rec: Recording, name: str, span: tuple[float, float] | None = None
) -> list[Problem]:
    """The first value of a signal column beyond any sensor once in its canonical unit
    (an error naming the row), scanned in blocks of :data:`DIFF_BLOCK` rows.  ``span``: the
    column's smallest and largest value when every value is finite (:func:`_finite_range`):
    a unit's conversion multiplies by one factor, so that when both ends are within the
    limit every value is (a rounded product is monotonic in the value) and no block is
    scanned."""
    probs: list[Problem] = []
    arr = rec.columns.get(name)
    unit = rec.units.get(name)
    if arr is None or not unit:
        return probs
    try:
        kind = units.signal_kind(unit)
    except UnitError:
        return probs
    found: tuple[int, float] | None = None  # (row, value in the canonical unit)
    to_physical = _physical_of_counts(rec) if kind == "raw" else None
    if to_physical is not None:
        canon_unit = to_physical(arr[:1])[1]
        limit = PLAUSIBLE_SIGNAL["rate" if canon_unit == "deg/h" else "accel"]
    elif kind == "raw":
        canon_unit, limit = unit, PLAUSIBLE_COUNTS  # counts stay counts
    else:
        canon_unit, limit = units.canonical_unit(unit), PLAUSIBLE_SIGNAL[kind]
        if span is not None:
            with np.errstate(over="ignore"):
                ends, _ = units.to_canonical(np.array(span), unit, finite=False)
            if bool(np.all(np.abs(ends) <= limit)):
                return probs
    for a0 in range(0, arr.size, DIFF_BLOCK):  # in blocks: bounded working memory
        part = arr[a0 : a0 + DIFF_BLOCK]
        with np.errstate(over="ignore", invalid="ignore"):
            if kind != "raw":
                canon, _ = units.to_canonical(part, unit, finite=False)
            elif to_physical is None:
                canon = part
            else:
                canon = to_physical(part)[0]
        finite_in = np.isfinite(part)
        beyond = finite_in & ~(np.abs(canon) <= limit)  # inf or too big
        if beyond.any():
            i = int(np.argmax(beyond))
            found = (a0 + i, float(canon[i]))
            break
    if found is not None:
        row = found[0]
        canon_row = found[1]
        probs.append(
            Problem(
                "implausible_signal",
                f"signal column {name!r} reads {float(arr[row]):.6g} {unit} at row {row} "
                f"({canon_row:.6g} {canon_unit}), beyond any sensor "
                f"(|value| ≤ {limit:g} {canon_unit}): wrong unit, scale factor or "
                "corrupt data",
                column=name,
                row=row,
            )
        )
    return probs


def _count_problems(rec: Recording, name: str) -> list[Problem]:
    """A warning when the signal ``name`` is declared in raw counts and at least
    :data:`NON_INTEGER_COUNTS_SHARE` of its finite values are not integers (blocks of
    :data:`DIFF_BLOCK` rows)."""
    arr, unit = rec.columns.get(name), rec.units.get(name)
    if arr is None or not unit:
        return []
    try:
        if units.signal_kind(unit) != "raw":
            return []
    except UnitError:
        return []
    finite = fractional = 0
    first: int | None = None
    for a0 in range(0, arr.size, DIFF_BLOCK):
        part = arr[a0 : a0 + DIFF_BLOCK]
        ok = np.isfinite(part)
        frac = ok & (part != np.round(part))
        finite += int(ok.sum())
        fractional += int(frac.sum())
        if first is None and frac.any():
            first = a0 + int(np.argmax(frac))
    if first is None or fractional < NON_INTEGER_COUNTS_SHARE * finite:
        return []
    return [
        Problem(
            "implausible_counts",
            f"signal column {name!r} is declared in counts, but {fractional:,} of its "
            f"{finite:,} values are not integers (row {first}: {float(arr[first]):.6g}): a "
            f"count is an integer; physical values need their unit ({COUNT_UNIT_EXAMPLES}), "
            "averaged counts one count's size (scale_factor and scale_factor_unit in the "
            "file's metadata, FILE.meta.json)",
            severity="warning",
            column=name,
            row=first,
            parameters=("signal_unit",),
        )
    ]


def plausibility_problems(rec: Recording) -> list[Problem]:
    """Values no sensor or chamber produces, named by column, value and row.

    Temperatures (in °C, after a counts conversion where one is given): below
    absolute zero is an error; outside −100…+200 °C a warning (with the likely cause:
    kelvin, raw ADC counts).  Signals, converted to their canonical unit: a magnitude
    beyond :data:`PLAUSIBLE_SIGNAL`, or one that overflows on conversion, is an error.

    Parameters
    ----------
    rec : Recording
        The recording.

    Returns
    -------
    list of Problem
    """
    return _plausibility(rec, {})


def _plausibility(rec: Recording, checked: dict[str, list[Problem]]) -> list[Problem]:
    """:func:`plausibility_problems`, the temperatures' and signals' own problems taken
    from ``checked`` where they are (:func:`_column_problems`'s keys)."""
    probs: list[Problem] = []
    n = rec.n_samples
    if 2 <= n < FEW_SAMPLES:
        probs.append(
            Problem(
                "implausible_few_samples",
                f"only {n} samples: figures from so few are not meaningful (at least "
                f"{FEW_SAMPLES} sample rows are expected of a test recording)",
                severity="warning",
            )
        )
    for name in rec.temperatures:
        found = checked.get("T:" + name)
        probs.extend(_temperature_problems(rec, name) if found is None else found)
    for name in rec.signals:
        found = checked.get("S:" + name)
        if found is None:
            found = _signal_problems(rec, name) + _count_problems(rec, name)
        probs.extend(found)
    probs.extend(_accelerometer_magnitude_problems(rec))
    probs.extend(_sample_interval_problems(rec))
    return probs


STATIC_G_MG = (800.0, 1200.0)
"""A static accelerometer triad reads |a| ≈ 1 g; its median magnitude outside this band
[mg] points to a wrong range setting or unit (a plausibility check)."""
SINGLE_AXIS_MAX_MG = 1500.0
"""A static single-axis accelerometer reads within ±1 g; a median |a| beyond this [mg]."""


def _g_hint(mag_mg: float) -> str:
    """The likely cause of an accelerometer magnitude far from 1 g."""
    ratios = {
        9.80665: "m/s² given as g?",
        1.0 / 9.80665: "g given as m/s²?",
        1000.0: "mg given as g?",
        0.001: "g given as mg?",
        2.0: "a ±2 g range read as ±4 g, or a scale factor off by 2?",
        0.5: "a ±4 g range read as ±2 g, or a scale factor off by 2?",
    }
    g = mag_mg / 1000.0
    for r, hint in ratios.items():
        if abs(g / r - 1.0) < 0.15:
            return hint
    return "check the range setting, scale factor and unit"


def _accelerometer_magnitude_problems(rec: Recording) -> list[Problem]:
    """Accelerometers whose static reading is far from 1 g: a warning naming the value.

    With three or more accelerometer columns the first three are taken as a triad and
    the median of |a| = √(ax² + ay² + az²) [mg] is compared with :data:`STATIC_G_MG`; a
    single axis is compared with :data:`SINGLE_AXIS_MAX_MG`. The median is robust to
    moves between static positions.
    """
    cols: list[tuple[str, FloatArray]] = []
    for name in rec.signals:
        arr, unit = rec.columns.get(name), rec.units.get(name)
        if arr is None or not unit:
            continue
        try:
            if units.signal_kind(unit) != "accel":
                continue
        except UnitError:
            continue
        with np.errstate(over="ignore", invalid="ignore"):
            cols.append((name, units.to_canonical(arr, unit, finite=False)[0]))
    if not cols:
        return []
    if len(cols) >= 3:
        names = [c[0] for c in cols[:3]]
        with np.errstate(over="ignore", invalid="ignore"):
            mag = np.sqrt(sum(c[1] ** 2 for c in cols[:3]))
        mag = mag[np.isfinite(mag)]
        if mag.size == 0:
            return []
        med = float(np.median(mag))
        lo, hi = STATIC_G_MG
        if lo <= med <= hi:
            return []
        return [
            Problem(
                "implausible_acceleration",
                f"accelerometer triad {', '.join(names)} has a median magnitude of "
                f"{med / 1000.0:.4g} g; at rest it reads 1 g ({_g_hint(med)})",
                severity="warning",
                column=names[0],
            )
        ]
    out = []
    for name, arr in cols:
        fin = np.abs(arr[np.isfinite(arr)])
        if fin.size and float(np.median(fin)) > SINGLE_AXIS_MAX_MG:
            med = float(np.median(fin))
            out.append(
                Problem(
                    "implausible_acceleration",
                    f"accelerometer column {name!r} reads a median |a| of {med / 1000.0:.4g} "
                    f"g; a static axis reads within ±1 g ({_g_hint(med)})",
                    severity="warning",
                    column=name,
                )
            )
    return out


SAMPLE_INTERVAL_TOLERANCE = 0.1
"""Relative difference between the stated and the measured sample interval that is
reported."""


def _sample_interval_problems(rec: Recording) -> list[Problem]:
    """A stated sample interval (metadata ``sample_interval_s``) that the time column
    contradicts by more than 10 %: a warning with both values and the likely cause."""
    stated = rec.meta.sample_interval_s
    t = rec.time_s
    if stated is None or t.size < 3 or not np.all(np.isfinite(t)):
        return []
    if not stated > 0:
        return [
            Problem(
                "implausible_sample_interval",
                f"metadata sample_interval_s = {stated:g} s is not positive",
                severity="warning",
                column="time",
            )
        ]
    measured = median_interval(t)
    if not measured > 0:
        return []
    ratio = measured / stated
    if abs(ratio - 1.0) <= SAMPLE_INTERVAL_TOLERANCE:
        return []
    if abs(ratio / 1000.0 - 1.0) < 0.1 or abs(ratio * 1000.0 - 1.0) < 0.1:
        hint = "the time unit is off by 1000: ms read as s or s as ms? state {time_unit}"
    elif abs(ratio / 1e6 - 1.0) < 0.1 or abs(ratio * 1e6 - 1.0) < 0.1:
        hint = "the time unit is off by 10⁶: µs read as s? state {time_unit}"
    else:
        hint = "decimated, averaged or mislabelled data?"
    return [
        Problem(
            "implausible_sample_interval",
            f"the time column's median interval is {measured:.6g} s "
            f"({1.0 / measured:.6g} Hz) but the metadata state {stated:.6g} s "
            f"({1.0 / stated:.6g} Hz) ({hint})",
            severity="warning",
            column="time",
            parameters=("time_unit",),
        )
    ]
