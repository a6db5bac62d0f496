"""The contract every temperature-compensation model follows, and its file format.

Estimator contract (after scikit-learn): ``__init__`` only stores its
keyword arguments; ``fit(runs)`` validates, learns values whose names end in
``_`` and returns ``self``; ``predict(run)`` returns the temperature-induced
signal (bias, or scale-factor error, [Seed-RLG]) in the signal's canonical unit;
``get_params()`` returns the constructor arguments.  The families are listed by name in
the one registry, :data:`thermocal.models.registry.MODEL_REGISTRY`, which
sits above them: this module knows no family.

The model file's layout, its format tag, version and checksum are described in
:mod:`thermocal.models.format`, which writes and reads the dict of a model.
"""

from __future__ import annotations

import copy
import functools
import inspect
import warnings
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Self

import numpy as np

from thermocal.adequacy import Needs
from thermocal.errors import (
    ExtrapolationWarning,
    ThermocalInputError,
)
from thermocal.families import FamilyDeclaration
from thermocal.models.format import model_content, restore_model
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData, _run_units
from thermocal.recording import FloatArray
from thermocal.units import (
    DEFAULT_UNITS,
    StatedUnits,
)

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
        """Model value for one sample.

        Parameters
        ----------
        time_s : float
            Sample time [s].
        temps_c : numpy.ndarray
            The sample's temperatures, shape (k,) [°C].
        signal : float, optional
            The raw signal in the model's unit ([°/h] or [mg]); only the warm-up
            family's start-up state uses it.  Default None.

        Returns
        -------
        float
            The temperature-induced signal for this sample [model's signal unit].
        """

    @abstractmethod
    def reset(self) -> None:
        """Forget everything (a new power-on)."""


@dataclass(frozen=True)
class ChunkContext:
    """What a chunk of a long run must be predicted together with to reproduce a
    whole-run predict (declared by each family, :meth:`TemperatureModel.chunk_context`).

    Attributes
    ----------
    head_s : float or None
        Seconds [s] from the first sample whose samples fix the start-up state (the
        warm-up window of T0/F0, the bank's selection window); None: all history.
    tail_s : float or None
        Seconds [s] of history before the chunk (the Ṫ interval Δt); None: all history
        (then a file is streamed sample by sample).
    """

    head_s: float | None
    tail_s: float | None


class TemperatureModel(ABC):
    """Base class of every compensation model family.

    Subclasses set ``family`` (registry name), implement ``fit``, ``predict``,
    ``_state`` / ``_set_state`` (the learned values as JSON-ready dicts), and
    ``coefficients()``.  Learned attributes end in ``_`` and exist only after fit.

    Attributes
    ----------
    temp_names_ : tuple of str
        Names of the fitted temperature columns (learned).
    temp_range_ : numpy.ndarray
        Fitted temperature range per column, shape (k, 2) [°C] (learned).
    rate_range_ : numpy.ndarray or None
        Fitted Ṫ range per column, shape (k, 2) [°C/min]; None for models without Ṫ.
    stats_ : FitStats
        Fit statistics (learned).
    data_ : list of dict
        Provenance of the fitted runs (file name, sample count).

    References
    ----------
    - Buitinck, L. et al. (2013). API design for machine learning software: experiences
      from the scikit-learn project. ECML PKDD Workshop on Languages for Data Mining and
      Machine Learning, 108–122 (the estimator contract ``fit``/``predict``/``get_params``).
    - IEEE Std 1431-2004, IEEE Standard Specification Format Guide and Test Procedure
      for Coriolis Vibratory Gyros (temperature sensitivity of bias and scale factor).

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.poly import PolyModel
    >>> t = np.arange(0.0, 600.0, 1.0)
    >>> temp = 20.0 + t / 60.0
    >>> run = RunData(t, temp[:, None], 3.0 - 0.1 * temp, ("T1",))
    >>> model = PolyModel(order=1).fit([run])
    >>> model.is_fitted, model.temp_names_, [round(float(v), 3) for v in model.temp_range_[0]]
    (True, ('T1',), [20.0, 29.983])
    >>> round(float(model.residuals(run).std()), 9)
    0.0
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
        :func:`thermocal.adequacy.judge`.  Default: a line in the first column.

        Parameters
        ----------
        temp_names : sequence of str
            The temperature columns the model will be fitted on.
        n_runs : int
            Number of runs it will be fitted on.

        Returns
        -------
        thermocal.adequacy.Needs
            Polynomial order per column and coefficient count.
        """
        return Needs({temp_names[0]: 1} if temp_names else {}, 2)

    # -- estimator contract --
    @abstractmethod
    def fit(self, runs: Sequence[RunData]) -> Self:
        """Learn from one or several runs.

        Parameters
        ----------
        runs : sequence of RunData
            The runs (power-ons) to fit, each with a signal.

        Returns
        -------
        TemperatureModel
            ``self``, fitted.

        Raises
        ------
        thermocal.errors.ThermocalInputError
            Runs without a signal, too few samples, or parameters the data cannot support.
        """

    @abstractmethod
    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """Temperature-induced signal for each sample of ``run``.

        Parameters
        ----------
        run : RunData
            Times [s] and temperatures [°C] (signal not needed).
        extrapolate : bool, optional
            False (default): temperatures outside the fitted range are clamped, with an
            :class:`~thermocal.errors.ExtrapolationWarning`; True: used as they are.

        Returns
        -------
        numpy.ndarray
            Model value per sample, shape (n,) [model's signal unit, °/h or mg].
        """

    @abstractmethod
    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> ModelStream:
        """A :class:`ModelStream` computing :meth:`predict` sample by sample.

        Parameters
        ----------
        sample_interval_s : float
            Nominal sample interval [s] (a step longer than ``GAP_FACTOR`` times it is a
            gap that resets the Ṫ estimate).
        extrapolate : bool, optional
            As in :meth:`predict`.  Default False.

        Returns
        -------
        ModelStream
        """

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
        The default checks nothing: a family's own module states its layout.

        Parameters
        ----------
        d : dict
            The ``state`` section.
        root : str, optional
            Key path prefix for messages.  Default ``""``.

        Raises
        ------
        thermocal.errors.ModelFileError
            A key of the state missing or of the wrong type or shape.
        """

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
        """Set constructor arguments (estimator contract); returns ``self``.

        Parameters
        ----------
        **params
            Constructor arguments by name.

        Returns
        -------
        TemperatureModel
            ``self``.

        Raises
        ------
        thermocal.errors.ThermocalInputError
            A name the family's constructor does not take.
        """
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
        """True once :meth:`fit` (or :meth:`from_dict`) set the learned values."""
        return hasattr(self, "stats_")

    def check_fitted(self) -> None:
        """Raise :class:`~thermocal.errors.ThermocalInputError` when the model is not fitted."""
        if not self.is_fitted:
            raise ThermocalInputError(f"{self.family} model is not fitted yet")

    def check_duration(self, elapsed_s: float) -> None:
        """Warn when a record's time since its start leaves what the model was fitted on.

        No limit by default; a warm-up model (fitted on power-ons of a few minutes)
        overrides it with an :class:`ExtrapolationWarning`.

        Parameters
        ----------
        elapsed_s : float
            Time since the record's first sample [s].
        """
        del elapsed_s

    def residuals(self, run: RunData) -> FloatArray:
        """``target − predict`` of a run.

        Parameters
        ----------
        run : RunData
            A run with a signal.

        Returns
        -------
        numpy.ndarray
            Residual per sample, shape (n,) [model's signal unit]; the model is evaluated
            with ``extrapolate=True``.

        Notes
        -----
        .. math:: e_i = (y_i - y_\\mathrm{known}) - \\hat f(T_i, \\dot T_i)
        """
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

        Parameters
        ----------
        temps_c : numpy.ndarray
            Temperatures, shape (n, k) [°C].
        extrapolate : bool, optional
            Keep out-of-range temperatures (and warn).  Default False.

        Returns
        -------
        numpy.ndarray
            The temperatures clipped to ``temp_range_`` column by column [°C].

        References
        ----------
        - PX4 ``src/modules/temperature_compensation/TemperatureCompensation.cpp``.
        - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
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
        """The model file's content (without checksum).

        Returns
        -------
        dict
            JSON-ready content in the layout of :mod:`thermocal.models.format`.

        Raises
        ------
        thermocal.errors.ThermocalInputError
            The model is not fitted.
        """
        return model_content(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Self:
        """Rebuild a fitted model of this family from :meth:`to_dict` output (checks the
        format and that the dict is of this family).  A dict of any registered family:
        :func:`thermocal.models.registry.model_from_dict`.

        Parameters
        ----------
        d : dict
            A model file's content (:meth:`to_dict`).

        Returns
        -------
        TemperatureModel
            The fitted model.

        Raises
        ------
        thermocal.errors.ModelFileError
            Wrong format tag, a newer format version, or a dict of another family.
        """
        return restore_model(cls, d)
