"""The contract every temperature-compensation model follows, and its file format.

Estimator contract (STYLE.md, after scikit-learn): ``__init__`` only stores its
keyword arguments; ``fit(runs)`` validates, learns values whose names end in
``_`` and returns ``self``; ``predict(run)`` returns the temperature-induced
signal (bias, or scale-factor error, SPEC §4e) in the signal's canonical unit;
``get_params()`` returns the constructor arguments.  The families are listed by name in
the one registry, :data:`thermocal.models.registry.MODEL_REGISTRY` (STYLE rule 8), which
sits above them: this module knows no family.

A model file is a self-describing, versioned JSON object (SPEC §8)::

    {
      "format": "thermocal-model", "format_version": 3,
      "family": "poly", "thermocal_version": "0.1.0",
      "created_utc": "...",
      "signal": {"name": "gyro", "unit": "deg/h", "target": "bias"},
      "temperatures": ["T1", "T2", "T3", "T4"], "temperature_unit": "degC",
      "rate": {"method": "backward", "interval_s": 60.0},
      "params": {...constructor arguments...},
      "state": {...learned values, family specific...},
      "coefficients": [{"name": "T1", "value": ..., "stderr": ...}, ...],
      "range": {"temperature_c": {"T1": [lo, hi], ...}, "temperature_unit": "degC",
                "rate_c_per_min": {"T1": [lo, hi], ...}},
      "fit": {"rms_residual": ..., "condition_number": ..., "n_samples": ..., ...},
      "data": [{"file": "run1.csv", "sha256": "..."}],
      "inputs": {"time_unit": "ms", "units": {"gyro": "deg/s", "T1": "counts"},
                 "unit_sources": {"<time>": "metadata", "gyro": "option", ...},
                 "temperature_conversion": {"T1": [0.0625, -50.0, "int16"]},
                 "temperature_unit": "degC", "known_input": {...},
                 "temperature_rate": {...}, "scale_factor": {...}},
      "checksum": "sha256 of the canonical JSON of everything above"
    }

``signal.unit`` is the canonical unit the maths use ([°/h] or [mg]); ``inputs`` (format
version 2, completed in 3) is how the fitted data were written: the time unit, each
column's unit as given (e.g. ``deg/s``), raw-count temperature conversions, the known
input removed and the Ṫ definition.  ``temperature_unit`` is ``counts`` for a model fitted
on raw-count temperatures without a conversion: its ranges (``range.temperature_c``) and
coefficients are then in counts, and applying it needs raw-count data.  compensate,
validate, report and export-c use ``inputs`` where the command line and the data file are
silent (:meth:`TemperatureModel.input_units`).  Older files load; what they did not
record is unknown and falls to the resolver's stated default.

Loading checks the format tag, the version (a newer version is refused with a
clear error), the family (must be registered) and the checksum (a corrupted or
hand-edited file is refused).  The checksum guards against accidents (truncation, a
hand edit, a bit flip), not against tampering: anyone can recompute it.  So the content
is checked too, before anything uses it: the reader's bounds (:mod:`thermocal.models.
filecheck`: 64 MiB, nesting depth 32, finite numbers only, integers within ±2⁵³) and each
section's types and shapes (:func:`thermocal.models.schema.verify_model_dict`; triads:
:func:`thermocal.turntable.thermal.check_triad_dict`), every error naming the key path.
"""

from __future__ import annotations

import copy
import datetime as _dt
import functools
import hashlib
import inspect
import json
import math
import warnings
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal, Self

import numpy as np

from thermocal.adequacy import Needs
from thermocal.errors import (
    DesignError,
    ExtrapolationWarning,
    ModelFileError,
    ThermocalInputError,
    UnitError,
    UnitWarning,
)
from thermocal.families import FamilyDeclaration
from thermocal.recording import FloatArray, Recording
from thermocal.units import (
    DEFAULT_UNITS,
    LEGACY_TEMPERATURE_UNIT,
    StatedUnits,
    canonical_unit,
    normalize_signal_unit,
    normalize_temperature_unit,
)

MODEL_FORMAT = "thermocal-model"
MODEL_FORMAT_VERSION = 3


# --- input data ------------------------------------------------------------------------


@dataclass(frozen=True)
class RunData:
    """One run (one power-on) as a model sees it.

    Attributes
    ----------
    time_s : sample times [s], shape (n,).
    temps_c : temperatures [°C] (raw counts when ``temperature_unit`` is ``counts``),
        shape (n, k), columns in ``temp_names`` order.
    signal : sensor output in its canonical unit ([°/h] or [mg]), shape (n,),
        or ``None`` when only predicting from temperatures.
    temp_names : names of the temperature columns.
    name : where the run came from (file name), for messages and provenance.
    known_input : the known input to remove before fitting (earth rate [°/h],
        gravity component [mg]); subtracted from ``signal`` by :meth:`target`.
    signal_unit : the canonical unit of ``signal`` (``deg/h``, ``mg`` or ``counts``) when
        known (:meth:`from_recording` sets it); a model fitted on the run records it.
    temperature_unit : ``degC``, or ``counts`` for raw-count temperatures used without a
        conversion (a model fitted on them is in counts).
    """

    time_s: FloatArray
    temps_c: FloatArray
    signal: FloatArray | None = None
    temp_names: tuple[str, ...] = ()
    name: str = ""
    known_input: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)
    signal_unit: str | None = None
    temperature_unit: str = "degC"

    def __post_init__(self) -> None:
        n = self.time_s.shape[0]
        if self.temps_c.ndim != 2 or self.temps_c.shape[0] != n:
            raise ThermocalInputError(
                f"{self.name or 'run'}: temperatures must be (n_samples, n_sensors); got "
                f"{self.temps_c.shape} for {n} samples"
            )
        if self.signal is not None and self.signal.shape != (n,):
            raise ThermocalInputError(
                f"{self.name or 'run'}: signal has {self.signal.shape[0]} samples, time has {n}"
            )

    @property
    def n_samples(self) -> int:
        return int(self.time_s.shape[0])

    def target(self) -> FloatArray:
        """The signal minus the known input: what a model is fitted to."""
        if self.signal is None:
            raise ThermocalInputError(f"{self.name or 'run'}: no signal to fit")
        return self.signal - self.known_input

    @classmethod
    def from_recording(
        cls,
        rec: Recording,
        signal: str | None = None,
        temps: Sequence[str] | None = None,
        *,
        known_input: float = 0.0,
        require_signal: bool = True,
        temperature_unit: Literal["degC", "counts", "auto"] = "degC",
    ) -> RunData:
        """Pull the time, temperatures and signal (canonical unit) out of a recording.

        ``temperature_unit``: ``degC`` (raw counts converted, a counts column without a
        conversion is an error); ``counts`` (the raw counts as stored, for a model fitted
        in counts; a °C column is an error); ``auto`` (fit): ``counts`` when every used
        temperature is in raw counts with no conversion stated, else ``degC``.
        NaN in the used columns is an input error (never silently dropped).
        """
        names = tuple(temps) if temps else rec.temperatures
        if not names:
            raise ThermocalInputError(
                f"{rec.name}: no temperature columns named; available: "
                + ", ".join(repr(c) for c in rec.columns)
            )
        t_unit = temperature_unit
        if t_unit == "auto":
            t_unit = _auto_temperature_unit(rec, names)
        if t_unit == "counts":
            temps_c = np.column_stack([rec.temperature_counts(n) for n in names])
        else:
            temps_c = rec.temperatures_c(names)
        sig: FloatArray | None = None
        sig_unit: str | None = None
        if require_signal or signal is not None or rec.signals:
            try:
                sig, sig_unit = rec.signal(signal)
            except ThermocalInputError:
                if require_signal:
                    raise
        for label, arr in [("time", rec.time_s), ("temperatures", temps_c)] + (
            [("signal", sig)] if sig is not None else []
        ):
            bad = ~np.isfinite(arr)
            if bad.any():
                row = int(np.argwhere(bad)[0][0])
                raise ThermocalInputError(
                    f"{rec.name}: {label} has {int(bad.sum())} NaN/non-finite values "
                    f"(first at row {row}); clean or cut the data first"
                )
        return cls(
            time_s=rec.time_s,
            temps_c=temps_c,
            signal=sig,
            temp_names=names,
            name=rec.source or rec.meta.run_id or "",
            known_input=known_input,
            signal_unit=sig_unit,
            temperature_unit=t_unit,
        )


def _auto_temperature_unit(rec: Recording, names: Sequence[str]) -> Literal["degC", "counts"]:
    """``counts`` when every temperature column is in raw counts with no conversion (a
    model in counts), ``degC`` when none is; a mix is an input error naming the columns."""
    raw = [
        n
        for n in names
        if rec.units.get(n) == "counts" and n not in rec.meta.temperature_conversion
    ]
    if not raw:
        return "degC"
    if len(raw) < len(names):
        raise UnitError(
            f"{rec.name}: temperature column(s) {', '.join(map(repr, raw))} are raw counts "
            "without a conversion, the others are in °C; a model takes one temperature "
            "unit: give --temp-conversion GAIN,OFFSET[,int16] for the counts"
        )
    warnings.warn(
        UnitWarning(
            f"{rec.name}: temperature column(s) {', '.join(map(repr, raw))} are raw counts "
            "and no conversion to °C is given: the model is fitted in counts (its ranges and "
            "coefficients are per count) and applies to raw-count data only"
        ),
        stacklevel=3,
    )
    return "counts"


def _run_units(runs: Sequence[RunData]) -> tuple[str | None, str]:
    """(canonical signal unit or None, temperature unit) shared by ``runs``; runs that
    disagree are an input error naming both."""
    sig = {r.signal_unit for r in runs if r.signal_unit}
    if len(sig) > 1:
        raise UnitError(f"the runs' signals are in different units: {', '.join(sorted(sig))}")
    temp = {r.temperature_unit for r in runs}
    if len(temp) > 1:
        raise UnitError(
            "some runs give temperatures in °C and some in raw counts without a conversion; "
            "give --temp-conversion for the counts"
        )
    return (next(iter(sig)) if sig else None), (next(iter(temp)) if temp else "degC")


def model_inputs(
    rec: Recording,
    signal: str,
    temps: Sequence[str],
    *,
    known_input: float = 0.0,
    known_input_what: str | None = None,
) -> dict[str, Any]:
    """What a model file records of how its fitted data were written (``inputs``): the
    time unit, the signal's and temperatures' units as given (e.g. ``deg/s``, ``counts``)
    and where each was stated, the raw-count temperature conversions, the scale factor of
    a raw-count signal, and the known input removed (value in the canonical unit and what
    it is).  ``rec`` is a recording read by :func:`thermocal.readers.dispatch.read_recording`."""
    used = [signal, *temps]
    out: dict[str, Any] = {
        "time_unit": rec.time_unit,
        "units": {c: rec.units[c] for c in used if rec.units.get(c)},
        "unit_sources": {c: s for c, s in rec.unit_sources.items() if c in used or c == "<time>"},
        "temperature_conversion": {
            c: list(rec.meta.temperature_conversion[c].to_json())
            for c in temps
            if c in rec.meta.temperature_conversion and rec.units.get(c) == "counts"
        },
    }
    sig_unit = rec.units.get(signal)
    if sig_unit == "counts" and rec.meta.scale_factor is not None:
        out["scale_factor"] = {
            "value": rec.meta.scale_factor,
            "unit": rec.meta.scale_factor_unit,
        }
    if rec.meta.sensor_id:
        out["sensor_id"] = str(rec.meta.sensor_id)
    if rec.n_samples > 1:  # sizes the Ṫ buffer of the exported C (export-c)
        out["sample_interval_s"] = float(rec.sample_interval_s)
    canon = canonical_unit(sig_unit) if sig_unit else None
    if sig_unit == "counts" and rec.meta.scale_factor is not None:  # the fit's values are
        canon = rec.signal(signal)[1]  # physical (counts / K), and so is the known input
    out["known_input"] = {
        "value": float(known_input),
        "unit": canon,
        "what": known_input_what or ("none" if known_input == 0.0 else "given"),
    }
    return out


def check_sensor_id(
    model_inputs: Mapping[str, Any] | None, data_sensor_id: Any, where: str
) -> None:
    """:class:`ExtrapolationWarning` when the data's sensor id (metadata ``sensor_id``)
    differs from the one the model was fitted on (model file ``inputs.sensor_id``):
    a compensation model belongs to one sensor (issue 14). Silent when either is unknown."""
    fitted = (model_inputs or {}).get("sensor_id")
    if not fitted or not data_sensor_id or str(fitted) == str(data_sensor_id):
        return
    warnings.warn(
        f"{where}: the data come from sensor {str(data_sensor_id)!r} but the model was fitted "
        f"on sensor {str(fitted)!r}; a compensation model belongs to one sensor",
        ExtrapolationWarning,
        stacklevel=2,
    )


# --- fitted coefficients and statistics ----------------------------------------------------


@dataclass(frozen=True)
class Coefficient:
    """A learned coefficient, in physical (unscaled) units, with its standard error."""

    name: str
    value: float
    stderr: float | None = None
    unit: str = ""

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"name": self.name, "value": self.value}
        # a standard error that cannot be estimated (no residual degrees of freedom) is
        # left out — "not estimable" — rather than written as a non-JSON NaN
        if self.stderr is not None and math.isfinite(self.stderr):
            d["stderr"] = self.stderr
        if self.unit:
            d["unit"] = self.unit
        return d


@dataclass(frozen=True)
class FitStats:
    """Fit statistics reported with every model.

    ``rms_residual`` in the signal unit; ``condition_number`` of the scaled
    design (2-norm, from the SVD); ``dof`` residual degrees of freedom.
    """

    n_samples: int
    n_coefficients: int
    rms_residual: float
    condition_number: float | None = None
    r_squared: float | None = None
    dof: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "n_samples": self.n_samples,
            "n_coefficients": self.n_coefficients,
            "rms_residual": self.rms_residual,
            "condition_number": self.condition_number,
            "r_squared": self.r_squared,
            "dof": self.dof,
        }
        d.update(self.extra)
        return d


CONDITION_WORDS: tuple[tuple[float, str], ...] = (
    (1e3, "well conditioned"),
    (1e6, "moderately conditioned"),
    (1e10, "ill-conditioned"),
    (math.inf, "near singular"),
)
"""Upper bounds of the 2-norm condition number κ of the scaled design and their words."""


def condition_wording(kappa: float | None) -> str:
    """Words for a condition number κ that match the number (issue 13 item 9).

    κ ≤ 1e3 well conditioned; ≤ 1e6 moderately (about log₁₀κ of the data's digits are
    lost: the coefficients' standard errors are inflated by collinear terms); ≤ 1e10
    ill-conditioned (individual coefficients are not meaningful, only the prediction);
    beyond, near singular. Least squares loses ≈ log₁₀ κ significant digits (Golub & Van
    Loan, *Matrix Computations*, 4th ed., §5.3.8).
    """
    if kappa is None or not math.isfinite(kappa):
        return "condition unknown"
    words = next(w for bound, w in CONDITION_WORDS if kappa <= bound)
    if kappa <= 1e3:
        return words
    return f"{words}: about {math.log10(kappa):.0f} of the data's digits lost"


# --- helpers for single-temperature streams --------------------------------------------------


def stream_channel(temps_c: FloatArray | float, column: int) -> float:
    """The model's temperature [°C] from one sample's ``temps_c``: the only value, or
    the value at ``column`` when every fitted column is given."""
    if type(temps_c) is np.ndarray and temps_c.dtype == np.float64 and temps_c.ndim == 1:
        arr = temps_c
    else:
        arr = np.atleast_1d(np.asarray(temps_c, dtype=np.float64)).reshape(-1)
    return float(arr.item(0) if arr.size == 1 else arr.item(column))


class ClampOnce:
    """Clamp one temperature to the fitted range ``[lo, hi]`` [°C] sample by sample, with
    one :class:`ExtrapolationWarning` per stream (``extrapolate=True``: warn, keep T)."""

    __slots__ = ("extrapolate", "hi", "lo", "warned")

    def __init__(self, lo: float, hi: float, *, extrapolate: bool) -> None:
        self.lo = float(lo)
        self.hi = float(hi)
        self.extrapolate = extrapolate
        self.warned = False

    def __call__(self, x: float) -> float:
        if x < self.lo or x > self.hi:
            if not self.warned:
                self.warned = True
                action = "extrapolating" if self.extrapolate else "clamped to the fitted range"
                warnings.warn(
                    f"temperature {x:.2f} °C outside the model's fitted range "
                    f"{self.lo:.2f}…{self.hi:.2f}; {action}",
                    ExtrapolationWarning,
                    stacklevel=3,
                )
            if not self.extrapolate:
                x = min(max(x, self.lo), self.hi)
        return x


# --- the contract ----------------------------------------------------------------------------


class ModelStream(ABC):
    """Sample-by-sample evaluation of a fitted model (live data, firmware twin).

    ``update`` takes one sample and returns the model value (the temperature-
    induced signal) for it; the corrected output is ``signal − value``.  It
    carries exactly the state the model needs (Ṫ buffer of length Δt, T0/F0
    captured at power-on, start-up selection) and resets the rate estimate after
    a gap: a time step longer than ``GAP_FACTOR`` × ``sample_interval_s``.

    Contract: for a run with nominal interval τ (the median step), feeding its
    samples in order to ``model.stream(τ)`` gives the same values as
    ``model.predict(run)`` to 1e-12 (relative), start-up included.
    """

    @abstractmethod
    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        """Model value for one sample: time [s], temperatures (k,) [°C], raw signal."""

    @abstractmethod
    def reset(self) -> None:
        """Forget everything (a new power-on)."""


@dataclass(frozen=True)
class ChunkContext:
    """What a chunk of a long run must be predicted together with to reproduce a
    whole-run predict (declared by each family, :meth:`TemperatureModel.chunk_context`).

    ``head_s`` — seconds from the first sample whose samples fix the start-up state
    (the warm-up window of T0/F0, the bank's selection window); ``tail_s`` — seconds of
    history before the chunk (the Ṫ interval Δt).  ``None`` for either means the
    family needs all history (then a file is streamed sample by sample).
    """

    head_s: float | None
    tail_s: float | None


class TemperatureModel(ABC):
    """Base class of every compensation model family.

    Subclasses set ``family`` (registry name), implement ``fit``, ``predict``,
    ``_state`` / ``_set_state`` (the learned values as JSON-ready dicts), and
    ``coefficients()``.  Learned attributes end in ``_`` and exist only after fit.

    Common learned attributes set by :meth:`_record_common` during ``fit``:
    ``temp_names_``, ``temp_range_`` (k×2 [°C]), ``rate_range_`` (k×2 [°C/min] or
    None), ``stats_`` (:class:`FitStats`), ``data_`` (provenance list).
    """

    family: ClassVar[str] = ""
    uses_rate: ClassVar[bool] = False
    """True when the model uses Ṫ (then ``rate_method``/``rate_interval_s`` matter)."""

    temp_names_: tuple[str, ...]
    temp_range_: FloatArray
    rate_range_: FloatArray | None
    stats_: FitStats
    data_: list[dict[str, Any]]
    adequacy_: dict[str, Any] | None = None
    """The adequacy record of the data it was fitted on (:mod:`thermocal.adequacy`), or
    None (files written before the check, or fitted through the library)."""
    inputs_: dict[str, Any]
    """How the fitted data were written (format version ≥ 2, :func:`model_inputs`):
    ``time_unit``, ``units`` (column → unit as given, e.g. ``deg/s``, ``counts``),
    ``unit_sources``, ``temperature_conversion`` (column → [gain, offset(, "int16")]),
    ``known_input``, ``scale_factor``; commands that apply the model use them where the
    command line and the data file are silent (:meth:`input_units`).  Empty for older
    files."""

    # metadata set by the caller (CLI) before saving; not constructor params
    signal_name: str = "signal"
    signal_unit: str = DEFAULT_UNITS["signal"]
    """Canonical unit of the model's values ([°/h] or [mg]): recorded by ``fit`` from the
    runs' ``signal_unit`` (:meth:`RunData.from_recording`); hand-built runs without a
    unit keep RunData's documented [°/h]."""
    target: str = "bias"
    temperature_unit: str = "degC"
    """Unit of the model's temperature inputs: ``degC``, or ``counts`` when fitted on
    raw-count temperatures without a conversion (recorded by ``fit`` from the runs)."""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Every family's ``fit`` records the units of its runs (signal, temperature) —
        the model learns its inputs without each family having to."""
        super().__init_subclass__(**kwargs)
        decl = cls.__dict__.get("declaration")
        if decl is not None:  # the name and the C generator are the declaration's
            cls.family = decl.name
            cls.C_GENERATOR = decl.c_generator
        fit = cls.__dict__.get("fit")
        if fit is None or getattr(fit, "_records_units", False):
            return

        @functools.wraps(fit)
        def fit_recording_units(
            self: TemperatureModel, runs: Sequence[RunData], *args: Any, **kw: Any
        ) -> Any:
            runs = list(runs)
            sig_unit, temp_unit = _run_units(runs)
            out = fit(self, runs, *args, **kw)
            if sig_unit is not None:
                self.signal_unit = sig_unit
            self.temperature_unit = temp_unit
            return out

        fit_recording_units._records_units = True  # type: ignore[attr-defined]
        setattr(cls, "fit", fit_recording_units)  # noqa: B010

    def input_units(self) -> StatedUnits:
        """The units the model file recorded of its inputs, for the resolver
        (:func:`thermocal.units.resolve_inputs`): the time unit, each column's unit as
        given, the temperature conversions; the model's canonical signal unit is the
        stated default for data whose unit nothing states (older files)."""
        inputs = dict(getattr(self, "inputs_", {}) or {})
        return StatedUnits.from_model_inputs(inputs, signal_default=self.signal_unit)

    # -- what the data must offer (thermocal.adequacy) --
    def data_needs(self, temp_names: Sequence[str], n_runs: int) -> Needs:
        """What this model asks of the data before it is fitted (its polynomial order in
        each temperature column, coefficient count, Ṫ columns), for
        :func:`thermocal.adequacy.judge`.  Default: a line in the first column."""
        return Needs({temp_names[0]: 1} if temp_names else {}, 2)

    # -- estimator contract --
    @abstractmethod
    def fit(self, runs: Sequence[RunData]) -> Self:
        """Learn from one or several runs; returns ``self``."""

    @abstractmethod
    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """Temperature-induced signal for each sample of ``run`` [signal unit]."""

    @abstractmethod
    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> ModelStream:
        """A :class:`ModelStream` computing :meth:`predict` sample by sample."""

    @abstractmethod
    def coefficients(self) -> list[Coefficient]:
        """Learned coefficients with standard errors, physical units."""

    @abstractmethod
    def _state(self) -> dict[str, Any]:
        """Learned values as a JSON-ready dict (family specific)."""

    @abstractmethod
    def _set_state(self, state: dict[str, Any]) -> None:
        """Inverse of :meth:`_state`."""

    @classmethod  # noqa: B027 (an optional hook: the default checks nothing)
    def check_state(cls, d: dict[str, Any], root: str = "") -> None:
        """Check the ``state`` section of a model file of this family (the layout
        :meth:`_state` writes) once the common sections passed
        (:func:`thermocal.models.schema.check_model_dict`); raise
        :class:`~thermocal.errors.ModelFileError` naming the key path, prefixed by ``root``.
        The default checks nothing: a family's own module states its layout."""

    @classmethod
    def _param_names(cls) -> list[str]:
        sig = inspect.signature(cls.__init__)
        return [p for p in sig.parameters if p != "self"]

    C_GENERATOR: ClassVar[str | None] = None
    """The module of :mod:`thermocal.export.c` whose ``generate(ctx)`` writes this family's
    C code (imported only by ``export-c``); None: no C export.  Set from
    :attr:`declaration`."""

    declaration: ClassVar[FamilyDeclaration]
    """What the family declares of itself (:class:`~thermocal.families.FamilyDeclaration`):
    its name, fit options with bounds, data needs, C generator and firmware formats."""

    @classmethod
    def from_options(cls, options: Mapping[str, Any]) -> Self:
        """Build from fit options ``{constructor parameter: value}``, each checked against
        the family's declared option (type and bounds).

        ``None`` values are options not given; a given option the family does not declare
        is refused, naming it and the options the family takes (the same rule for every
        family).

        Parameters
        ----------
        options : mapping of str to object
            Constructor parameters as declared (``{"order": 2, "rate_interval_s": 60.0}``).

        Returns
        -------
        TemperatureModel
            The unfitted model.

        Raises
        ------
        thermocal.errors.ThermocalInputError
            An option the family does not take.
        thermocal.errors.ParameterError
            A value of the wrong type or out of its declared bounds, naming the parameter.
        """
        decl = cls.declaration
        keys = [o.name for o in decl.options]
        given = {k: v for k, v in options.items() if v is not None}
        unknown = [k for k in given if k not in keys]
        if unknown:
            verb = "does" if len(unknown) == 1 else "do"
            raise ThermocalInputError(
                f"option{'s' if len(unknown) > 1 else ''} {', '.join(unknown)} {verb} not apply "
                f"to model {cls.family!r} (it takes: {', '.join(keys)})"
            )
        return cls(**{k: decl.option(k).check(v) for k, v in given.items()})

    def chunk_context(self) -> ChunkContext:
        """The context a chunk needs (:class:`ChunkContext`); the default — all history —
        makes file compensation stream the family sample by sample (exact, slower)."""
        return ChunkContext(head_s=None, tail_s=None)

    def get_params(self) -> dict[str, Any]:
        """Constructor arguments (estimator contract)."""
        return {p: copy.deepcopy(getattr(self, p)) for p in self._param_names()}

    def set_params(self, **params: Any) -> Self:
        for k, v in params.items():
            if k not in self._param_names():
                raise ThermocalInputError(f"{self.family}: unknown parameter {k!r}")
            setattr(self, k, v)
        return self

    def clone(self) -> Self:
        """An unfitted copy with the same parameters."""
        return type(self)(**self.get_params())

    @property
    def is_fitted(self) -> bool:
        return hasattr(self, "stats_")

    def check_fitted(self) -> None:
        if not self.is_fitted:
            raise ThermocalInputError(f"{self.family} model is not fitted yet")

    def check_duration(self, elapsed_s: float) -> None:
        """Warn when a record's time since its start leaves what the model was fitted on.

        No limit by default; a warm-up model (fitted on power-ons of a few minutes)
        overrides it with an :class:`ExtrapolationWarning`.
        """
        del elapsed_s

    def residuals(self, run: RunData) -> FloatArray:
        """``target − predict`` of a run (signal unit)."""
        return run.target() - self.predict(run, extrapolate=True)

    # -- helpers for subclasses --
    def _record_common(
        self,
        runs: Sequence[RunData],
        stats: FitStats,
        rates: Sequence[FloatArray] | None = None,
    ) -> None:
        """Record temperature (and rate) ranges, names and provenance after a fit."""
        temps = np.vstack([r.temps_c for r in runs])
        self.temp_names_ = runs[0].temp_names or tuple(f"T{i + 1}" for i in range(temps.shape[1]))
        self.temp_range_ = np.column_stack([temps.min(axis=0), temps.max(axis=0)])
        if rates is not None:
            rr = np.vstack(list(rates))
            self.rate_range_ = np.column_stack([rr.min(axis=0), rr.max(axis=0)])
        else:
            self.rate_range_ = None
        self.stats_ = stats
        self.data_ = [{"file": r.name, "n_samples": r.n_samples} for r in runs]

    def _check_temps(self, run: RunData) -> None:
        if run.temps_c.shape[1] != self.temp_range_.shape[0]:
            raise ThermocalInputError(
                f"{self.family} model uses {self.temp_range_.shape[0]} temperature channels "
                f"({', '.join(self.temp_names_)}); the data has {run.temps_c.shape[1]}"
            )

    def clamp(self, temps_c: FloatArray, *, extrapolate: bool = False) -> FloatArray:
        """Clamp temperatures to the fitted range and warn (PX4/ArduPilot behaviour).

        With ``extrapolate=True`` the temperatures are returned as they are, with an
        :class:`ExtrapolationWarning` if they leave the range.
        """
        lo = self.temp_range_[:, 0]
        hi = self.temp_range_[:, 1]
        below = temps_c < lo
        above = temps_c > hi
        if below.any() or above.any():
            n = int(np.count_nonzero(below.any(axis=1) | above.any(axis=1)))
            tmin = temps_c.min(axis=0)
            tmax = temps_c.max(axis=0)
            tu = "°C" if self.temperature_unit == "degC" else self.temperature_unit
            where = ", ".join(
                f"{name} {tmin[i]:.2f}…{tmax[i]:.2f} {tu} (fitted {lo[i]:.2f}…{hi[i]:.2f})"
                for i, name in enumerate(self.temp_names_)
                if below[:, i].any() or above[:, i].any()
            )
            action = "extrapolating" if extrapolate else "clamped to the fitted range"
            warnings.warn(
                f"{n} samples outside the model's temperature range: {where}; {action}",
                ExtrapolationWarning,
                stacklevel=3,
            )
            if not extrapolate:
                return np.clip(temps_c, lo, hi)
        return temps_c

    # -- files --
    def to_dict(self) -> dict[str, Any]:
        """The model file's content (without checksum)."""
        from thermocal._version import __version__

        self.check_fitted()
        params = _jsonify(self.get_params())
        state = _jsonify(self._state())
        d: dict[str, Any] = {
            "format": MODEL_FORMAT,
            "format_version": MODEL_FORMAT_VERSION,
            "family": self.family,
            "thermocal_version": __version__,
            "created_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "signal": {"name": self.signal_name, "unit": self.signal_unit, "target": self.target},
            "temperatures": list(self.temp_names_),
            "temperature_unit": self.temperature_unit,
            "rate": (
                {
                    "method": params.get("rate_method", "backward"),
                    "interval_s": params.get("rate_interval_s", 60.0),
                }
                if self.uses_rate
                else None
            ),
            "params": params,
            "state": state,
            "coefficients": [c.to_dict() for c in self.coefficients()],
            "range": {
                "temperature_c": {
                    n: [float(a), float(b)]
                    for n, (a, b) in zip(self.temp_names_, self.temp_range_, strict=True)
                },
                "rate_c_per_min": (
                    {
                        n: [float(a), float(b)]
                        for n, (a, b) in zip(self.temp_names_, self.rate_range_, strict=True)
                    }
                    if self.rate_range_ is not None
                    else None
                ),
            },
            "fit": _jsonify(self.stats_.to_dict()),
            "data": _jsonify(self.data_),
            "inputs": _jsonify(self._inputs_record(params, bool(state.get("uses_rate", True)))),
        }
        if self.adequacy_ is not None:
            d["adequacy"] = _jsonify(self.adequacy_)
        d["range"]["temperature_unit"] = self.temperature_unit
        return d

    def _inputs_record(self, params: dict[str, Any], rate_used: bool) -> dict[str, Any]:
        """The model file's ``inputs``: what the caller recorded (:func:`model_inputs`) with
        the temperature unit of the model and the Ṫ definition of rate models."""
        out = dict(getattr(self, "inputs_", {}) or {})
        out["temperature_unit"] = self.temperature_unit
        if self.uses_rate and rate_used:
            tu = self.temperature_unit
            method = params.get("rate_method", "backward")
            interval = params.get("rate_interval_s", 60.0)
            out["temperature_rate"] = {
                "method": method,
                "interval_s": interval,
                "unit": f"{tu}/min",
                "definition": (
                    f"Ṫ = ΔT/Δt × 60 [{tu}/min] of the raw temperatures over {interval} s "
                    f"({method} difference), within a contiguous (gap-free) segment"
                ),
            }
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Self:
        """Rebuild a fitted model of this family from :meth:`to_dict` output (checks the
        format and that the dict is of this family).  A dict of any registered family:
        :func:`thermocal.models.registry.model_from_dict`."""
        check_model_header(d)
        if not cls.family or str(d["family"]) != cls.family:
            raise ModelFileError(
                f"a model of family {d['family']!r} is not a {cls.family or cls.__name__!r} "
                "model (thermocal.models.registry.model_from_dict reads any family)"
            )
        model = cls(**d.get("params", {}))
        model._set_state(d["state"])
        model.temp_names_ = tuple(d["temperatures"])
        tr = d["range"]["temperature_c"]
        model.temp_range_ = np.array([tr[n] for n in model.temp_names_], dtype=np.float64)
        rr = d["range"].get("rate_c_per_min")
        model.rate_range_ = (
            np.array([rr[n] for n in model.temp_names_], dtype=np.float64) if rr else None
        )
        fit = dict(d["fit"])
        known = {
            "n_samples",
            "n_coefficients",
            "rms_residual",
            "condition_number",
            "r_squared",
            "dof",
        }
        model.stats_ = FitStats(
            n_samples=int(fit.get("n_samples", 0)),
            n_coefficients=int(fit.get("n_coefficients", 0)),
            rms_residual=float(fit.get("rms_residual", float("nan"))),
            condition_number=fit.get("condition_number"),
            r_squared=fit.get("r_squared"),
            dof=fit.get("dof"),
            extra={k: v for k, v in fit.items() if k not in known},
        )
        model.data_ = list(d.get("data", []))
        model.inputs_ = dict(d.get("inputs") or {})  # format version 1 files: unknown
        adequacy = d.get("adequacy")
        model.adequacy_ = dict(adequacy) if isinstance(adequacy, dict) else None
        sig = d.get("signal") or {}
        model.signal_name = sig.get("name", "signal")
        model.signal_unit = normalize_signal_unit(str(sig["unit"]))  # required by the schema
        model.target = sig.get("target", "bias")
        tu = d.get("temperature_unit")
        # files before format version 3 were always fitted in °C (and say so)
        model.temperature_unit = normalize_temperature_unit(str(tu or LEGACY_TEMPERATURE_UNIT))
        return model


# --- file I/O ------------------------------------------------------------------------------


def _jsonify(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonify(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonify(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonify(obj.tolist())
    if isinstance(obj, np.generic):
        return _jsonify(obj.item())
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def _canonical(d: dict[str, Any]) -> bytes:
    return json.dumps(
        {k: v for k, v in d.items() if k != "checksum"},
        sort_keys=True,
        separators=(",", ":"),
        ensure_ascii=True,
        allow_nan=False,
    ).encode("ascii")


def checksum(d: dict[str, Any]) -> str:
    """SHA-256 of the canonical JSON of a model dict (``checksum`` key excluded)."""
    return hashlib.sha256(_canonical(d)).hexdigest()


def check_model_header(d: Any) -> None:
    """Refuse foreign, newer or unknown model dicts with a clear :class:`ModelFileError`."""
    if not isinstance(d, dict) or d.get("format") != MODEL_FORMAT:
        raise ModelFileError("not a thermocal model file (missing 'format': 'thermocal-model')")
    ver = d.get("format_version")
    if not isinstance(ver, int):
        raise ModelFileError("model file has no integer format_version")
    if ver > MODEL_FORMAT_VERSION:
        raise ModelFileError(
            f"model file format version {ver} is newer than this thermocal supports "
            f"({MODEL_FORMAT_VERSION}); upgrade thermocal"
        )
    for key in ("family", "params", "state", "temperatures", "range", "fit"):
        if key not in d:
            raise ModelFileError(f"model file is missing the {key!r} section")


def _nonfinite_fields(obj: Any, path: str = "") -> list[str]:
    """Dotted paths of the NaN/inf floats inside a JSON-like structure."""
    if isinstance(obj, dict):
        return [p for k, v in obj.items() for p in _nonfinite_fields(v, f"{path}.{k}")]
    if isinstance(obj, (list, tuple)):
        return [p for i, v in enumerate(obj) for p in _nonfinite_fields(v, f"{path}[{i}]")]
    if isinstance(obj, float) and not math.isfinite(obj):
        return [path.lstrip(".")]
    return []


def model_file_dict(model: TemperatureModel) -> dict[str, Any]:
    """The model file's dict (:meth:`TemperatureModel.to_dict` with its checksum); a
    non-finite number anywhere is refused with :class:`DesignError` naming the field."""
    d = model.to_dict()
    bad = _nonfinite_fields(d)
    if bad:
        raise DesignError(
            f"the fitted model holds non-finite numbers ({', '.join(bad[:5])}): the data do "
            "not determine it (too few samples or a degenerate design); nothing written"
        )
    d["checksum"] = checksum(d)
    return d


# --- applicability: how far a run leaves the calibrated ranges --------------------------------

RANGE_WARNING_PATTERNS: tuple[str, ...] = (
    r".*samples outside the model's temperature range",
    r"temperature rate outside the model's fitted range",
    r"warmup: the record runs",
)
"""The per-call range warnings of the families' ``predict`` (temperature, Ṫ, time since
power-on) that one :func:`outside_range_message` per channel replaces where a whole run
or file is applied (compensate, validate): pass them to ``warnings.filterwarnings``."""

_SUFFIX = {"°C": "c", "°C/min": "c_per_min", "s": "s", "counts": "counts",
           "counts/min": "counts_per_min"}  # fmt: skip


@dataclass(frozen=True)
class RangeExcess:
    """How far one input of a model left the range it was calibrated over.

    ``quantity``: ``temperature`` [°C], ``temperature_rate`` (Ṫ [°C/min], models with rate
    terms) or ``time_since_power_on`` [s] (warm-up models: the time since the record's first
    sample against the longest fitted power-on); ``counts``/``counts/min`` for a model in raw
    counts.  A sample is outside when any checked column is below its calibrated minimum or
    above its maximum; ``beyond[col]`` is the largest distance ``max(lo − x, x − hi, 0)``
    over the samples [unit]; ``seen[col]`` the range met and ``fitted[col]`` the calibrated
    one.
    """

    quantity: str
    unit: str
    n_samples: int
    n_outside: int
    beyond: dict[str, float]
    seen: dict[str, tuple[float, float]]
    fitted: dict[str, tuple[float, float]]

    @property
    def share(self) -> float:
        """Fraction of the samples outside (0…1)."""
        return self.n_outside / self.n_samples if self.n_samples else 0.0

    @property
    def max_beyond(self) -> float:
        """The largest distance outside over every column [unit]."""
        return max(self.beyond.values(), default=0.0)

    def to_dict(self) -> dict[str, Any]:
        """``share`` (0…1), ``share_pct``, ``n_outside``, ``n_samples``, ``max_beyond_<unit>``
        (``_c``, ``_c_per_min``, ``_s``), ``unit``, and per column ``seen``/``range``/``beyond``."""
        return {
            "share": self.share,
            "share_pct": 100.0 * self.share,
            "n_outside": self.n_outside,
            "n_samples": self.n_samples,
            f"max_beyond_{_SUFFIX.get(self.unit, 'value')}": self.max_beyond,
            "unit": self.unit,
            "columns": {
                c: {"seen": list(self.seen[c]), "range": list(self.fitted[c]),
                    "beyond": self.beyond[c]}
                for c in self.fitted
            },
        }  # fmt: skip

    def describe(self) -> str:
        """One phrase: share, how far, and the columns that left their range."""
        what = {"temperature": "temperature", "temperature_rate": "Ṫ",
                "time_since_power_on": "time after power-on"}[self.quantity]  # fmt: skip
        cols = ", ".join(
            f"{c} met {self.seen[c][0]:.4g}…{self.seen[c][1]:.4g} {self.unit}, calibrated "
            f"{self.fitted[c][0]:.4g}…{self.fitted[c][1]:.4g} {self.unit}"
            for c in self.fitted
            if self.beyond[c] > 0
        )
        return (
            f"{what}: {self.n_outside} samples outside ({100.0 * self.share:.3g} % of "
            f"{self.n_samples}), up to {self.max_beyond:.3g} {self.unit} beyond ({cols})"
        )


class RangeTally:
    """Accumulates, chunk by chunk, how far a run leaves a model's calibrated ranges.

    Feed the samples in order with :meth:`add` (time [s], temperatures (n, k) in the
    model's temperature unit, columns in ``temp_names_`` order); :meth:`result` gives one
    :class:`RangeExcess` per checked input.  Ṫ is the model's own (``model.rates``: its
    Δt and difference form, never across a gap) computed with the last ``2Δt`` of the
    previous chunks as history, so chunked and whole-run figures agree for the causal
    backward form; the time since power-on counts from the first sample added.
    """

    def __init__(self, model: TemperatureModel) -> None:
        model.check_fitted()
        self.model = model
        self.names = tuple(model.temp_names_)
        self._lo = np.asarray(model.temp_range_, dtype=np.float64)[:, 0]
        self._hi = np.asarray(model.temp_range_, dtype=np.float64)[:, 1]
        tu = "°C" if model.temperature_unit == "degC" else model.temperature_unit
        self._tu = tu
        self.n = 0
        self._t_out = 0
        self._t_min = np.full(self._lo.size, np.inf)
        self._t_max = np.full(self._lo.size, -np.inf)
        # Ṫ: the sensors whose rate a term uses (poly), with the model's rate definition
        rr = getattr(model, "rate_range_", None)
        self._rate_cols: list[int] = []
        if rr is not None and bool(getattr(model, "model_uses_rate", False)):
            self._rate_cols = [int(j) for j in model._rate_sensors()]  # type: ignore[attr-defined]
            self._r_lo = np.asarray(rr, dtype=np.float64)[:, 0]
            self._r_hi = np.asarray(rr, dtype=np.float64)[:, 1]
            self._r_min = np.full(self._lo.size, np.inf)
            self._r_max = np.full(self._lo.size, -np.inf)
            self._r_out = 0
            self._hist_s = 2.0 * float(getattr(model, "rate_interval_s", 60.0))
            self._tail_t: FloatArray = np.zeros(0)
            self._tail_T: FloatArray = np.zeros((0, self._lo.size))
        # time since power-on: warm-up models record their fitted power-on durations
        dur = getattr(model, "duration_range_s_", None)
        self._dur: tuple[float, float] | None = (
            None if dur is None else (float(dur[0]), float(dur[1]))
        )
        self._t0: float | None = None
        self._e_max = -np.inf
        self._e_out = 0

    def add(self, time_s: FloatArray, temps_c: FloatArray) -> None:
        """The next samples of the run (in time order)."""
        t = np.asarray(time_s, dtype=np.float64).reshape(-1)
        T = np.asarray(temps_c, dtype=np.float64).reshape(t.size, -1)
        if t.size == 0:
            return
        self.n += int(t.size)
        temps = T
        out = (temps < self._lo) | (temps > self._hi)
        self._t_out += int(np.count_nonzero(out.any(axis=1)))
        self._t_min = np.minimum(self._t_min, T.min(axis=0))
        self._t_max = np.maximum(self._t_max, T.max(axis=0))
        if self._rate_cols:
            m = self._tail_t.size
            ct = np.concatenate([self._tail_t, t])
            cT = np.concatenate([self._tail_T, T])
            r = np.asarray(self.model.rates(ct, cT), dtype=np.float64)[m:]  # type: ignore[attr-defined]
            j = self._rate_cols
            rj = r[:, j]
            self._r_out += int(
                np.count_nonzero(((rj < self._r_lo[j]) | (rj > self._r_hi[j])).any(axis=1))
            )
            self._r_min[j] = np.minimum(self._r_min[j], rj.min(axis=0))
            self._r_max[j] = np.maximum(self._r_max[j], rj.max(axis=0))
            keep = ct >= ct[-1] - self._hist_s
            self._tail_t, self._tail_T = ct[keep].copy(), cT[keep].copy()
        if self._dur is not None:
            if self._t0 is None:
                self._t0 = float(t[0])
            e = t - self._t0
            self._e_max = max(self._e_max, float(e[-1]))
            self._e_out += int(np.count_nonzero(e > self._dur[1]))

    def result(self) -> tuple[RangeExcess, ...]:
        """One :class:`RangeExcess` per checked input (temperature always; Ṫ for models
        with rate terms; time since power-on for warm-up models); empty before any sample."""
        if self.n == 0:
            return ()

        def excess(
            quantity: str, unit: str, n_out: int, cols: Sequence[int],
            mn: FloatArray, mx: FloatArray, lo: FloatArray, hi: FloatArray,
        ) -> RangeExcess:  # fmt: skip
            names = [self.names[i] for i in cols]
            return RangeExcess(
                quantity=quantity,
                unit=unit,
                n_samples=self.n,
                n_outside=n_out,
                beyond={
                    n: float(max(lo[i] - mn[i], mx[i] - hi[i], 0.0))
                    for n, i in zip(names, cols, strict=True)
                },
                seen={n: (float(mn[i]), float(mx[i])) for n, i in zip(names, cols, strict=True)},
                fitted={n: (float(lo[i]), float(hi[i])) for n, i in zip(names, cols, strict=True)},
            )

        all_cols = list(range(self._lo.size))
        out = [
            excess("temperature", self._tu, self._t_out, all_cols,
                   self._t_min, self._t_max, self._lo, self._hi)
        ]  # fmt: skip
        if self._rate_cols:
            out.append(
                excess("temperature_rate", f"{self._tu}/min", self._r_out, self._rate_cols,
                       self._r_min, self._r_max, self._r_lo, self._r_hi)
            )  # fmt: skip
        if self._dur is not None:
            lo, hi = self._dur
            out.append(
                RangeExcess(
                    quantity="time_since_power_on",
                    unit="s",
                    n_samples=self.n,
                    n_outside=self._e_out,
                    beyond={"power-on": max(self._e_max - hi, 0.0)},
                    seen={"power-on": (0.0, self._e_max)},
                    fitted={"power-on": (lo, hi)},
                )
            )
        return tuple(out)


def outside_range(model: TemperatureModel, time_s: FloatArray, temps_c: FloatArray) -> tuple[
    RangeExcess, ...
]:  # fmt: skip
    """How far one whole run (time [s], temperatures (n, k)) leaves ``model``'s calibrated
    ranges (:class:`RangeTally` fed once)."""
    tally = RangeTally(model)
    tally.add(time_s, temps_c)
    return tally.result()


def outside_range_message(
    excess: Sequence[RangeExcess], where: str, *, extrapolate: bool
) -> str | None:
    """The one warning for a channel applied outside its calibrated range (None when every
    sample is inside): each input that left, with its share of samples and how far."""
    bad = [e for e in excess if e.n_outside > 0]
    if not bad:
        return None
    action = (
        "the model is extrapolated there"
        if extrapolate
        else "the model's inputs are held at the calibrated range there"
    )
    return (
        f"{where}: the model is applied outside its calibrated range: "
        + "; ".join(e.describe() for e in bad)
        + f"; {action}"
    )


def outside_range_dict(excess: Sequence[RangeExcess]) -> dict[str, Any]:
    """``{quantity: RangeExcess.to_dict()}`` of every checked input (JSON ``outside_range``)."""
    return {e.quantity: e.to_dict() for e in excess}
