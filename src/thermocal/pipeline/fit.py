"""Fitting a compensation model on recordings: :func:`fit_files` (``thermocal fit``).

Fits one model (one channel) or a calibration of several channels on one or several runs
(several files = several runs, each with its own turn-on offset unless
``per_run_offset=False``) and writes the self-describing model file
(:func:`thermocal.pipeline.model_file.save_model`; several channels:
:func:`thermocal.pipeline.model_file.save_calibration`) with the data files' names and SHA-256
checksums.  The family is looked up in the registry
(:func:`thermocal.models.registry.get_model_class`)
and built from its declared options (``FitOptions.params``) by its one option parser
(:meth:`TemperatureModel.from_options`).  Every file is read once, through
:func:`thermocal.readers.read_recording` with one ``ReadOptions`` (``FitOptions.read_options``).

The data are judged before the fit (:func:`thermocal.adequacy.judge`: refused when they cannot
support the model, unless overridden); the earth rate seen by a gyro's axis (``latitude``,
``axis``), the gravity an accelerometer reads (``gravity_axis``) and ``known_input`` are
removed as known inputs.  Warnings are issued (:mod:`warnings`) and listed in each channel's
figures (``warnings``).
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from thermocal import units
from thermocal.defaults import overrides_of
from thermocal.errors import (
    ConditioningWarning,
    ParameterError,
    PlausibilityWarning,
    ThermocalInputError,
)
from thermocal.families import MAX_ORDER, MAX_TERMS
from thermocal.pipeline.fit_columns import TemperatureBlocks, read_by_blocks, run_in_blocks
from thermocal.pipeline.messages import warning_text
from thermocal.pipeline.options import FitOptions
from thermocal.pipeline.reading import check_recording
from thermocal.readers.station import station_sensor_paths
from thermocal.recording import FloatArray, all_finite, median_in_blocks

if TYPE_CHECKING:
    import thermocal.adequacy as _adequacy
    import thermocal.gravity as _gravity
    import thermocal.models.base as _base
    import thermocal.models.calibration as _calibration
    import thermocal.models.poly as _poly
    import thermocal.models.poly_fit as _poly_fit
    import thermocal.models.registry as _registry
    import thermocal.models.results as _results
    import thermocal.models.rundata as _rundata
    import thermocal.pipeline.model_file as _files
    import thermocal.recording as _recording
    import thermocal.writers as _writers
else:
    from thermocal._lazy import LazyModule

    _adequacy = LazyModule("thermocal.adequacy")
    _writers = LazyModule("thermocal.writers")
    _base = LazyModule("thermocal.models.base")
    _results = LazyModule("thermocal.models.results")
    _rundata = LazyModule("thermocal.models.rundata")
    _registry = LazyModule("thermocal.models.registry")
    _calibration = LazyModule("thermocal.models.calibration")
    _files = LazyModule("thermocal.pipeline.model_file")
    _poly = LazyModule("thermocal.models.poly")
    _poly_fit = LazyModule("thermocal.models.poly_fit")
    _gravity = LazyModule("thermocal.gravity")
    _recording = LazyModule("thermocal.recording")


def run_temp_names(rec: _recording.Recording, temps: Sequence[str] | None) -> list[str]:
    """The temperature columns a fit uses: those named, or the file's.

    Parameters
    ----------
    rec : Recording
        The run as read.
    temps : sequence of str or None
        Temperature columns named by the user; ``None`` or empty: every one of the file's.

    Returns
    -------
    list of str
        The temperature column names.
    """
    return list(temps or ()) or list(rec.temperatures)


def check_terms(terms: str | None) -> None:
    """Refuse (:class:`~thermocal.errors.ParameterError`, exit 2) a poly term list beyond the
    hard ceilings: more than :data:`~thermocal.families.MAX_TERMS` terms or a power above
    :data:`~thermocal.families.MAX_ORDER`, before any data is read (the value is checked,
    not only its type: an integer literal of any length parses).

    Parameters
    ----------
    terms : str or None
        The poly family's term list as given (e.g. ``"T^0,T^1,T^2"``); ``None``: the
        default terms.

    Returns
    -------
    None

    Raises
    ------
    ParameterError
        ``terms``: more than ``MAX_TERMS`` terms, or a power above ``MAX_ORDER``.
    """
    if terms is None:
        return
    n = terms.count(",") + 1
    if n > MAX_TERMS:
        raise ParameterError("terms", f"{{name}} lists {n} terms; at most {MAX_TERMS} are accepted")
    for power in _POWER.findall(terms):
        if len(power) > 3 or int(power) > MAX_ORDER:
            raise ParameterError(
                "terms", f"{{name}}: power {power[:20]} is above the ceiling {MAX_ORDER}"
            )


_POWER = re.compile(r"\^\s*(\d+)")


def build_model(family: str, options: Mapping[str, Any]) -> _base.TemperatureModel:
    """Instantiate a registered family from its fit options ``{parameter: value}`` by its
    one option parser (:meth:`TemperatureModel.from_options`: an option the family does
    not take is refused, for every family; each value checked against its declaration).

    Parameters
    ----------
    family : str
        Registered family name (e.g. ``"poly"``).
    options : mapping of str to Any
        The family's fit options by parameter name.

    Returns
    -------
    TemperatureModel
        The unfitted model.

    Raises
    ------
    ParameterError
        When an option is not the family's or its value is outside its declared bounds.
    ThermocalInputError
        When the family is not registered.
    """
    return _registry.get_model_class(family).from_options(options)


def earth_rate_known_input(
    latitude: float | None, axis: str | None, unit: str, where: object
) -> float:
    r"""Earth rate seen by the sensitive axis [°/h], as a known input of a gyro run.

    ``Ω_axis = Ω u·(0, cos φ, sin φ)`` for the unit axis ``u`` in East-North-Up
    (IEEE Std 952-1997, :func:`thermocal.units.earth_rate_on_axis_deg_h`); 0 without
    ``latitude``/``axis``.  Both are needed together and
    the signal (canonical unit ``unit``) must be a rate: otherwise an input error naming
    ``where`` (the file).

    Parameters
    ----------
    latitude : float or None
        Geodetic latitude of the site [°].
    axis : str or None
        The sensitive axis in East-North-Up, e.g. ``"up"``, ``"north"`` or ``"0,0.7,0.7"``.
    unit : str
        Canonical unit of the signal (``"deg/h"`` for a gyro).
    where : object
        The file, named in the error message.

    Returns
    -------
    float
        The earth rate along the axis [°/h]; 0.0 when neither is given.

    Raises
    ------
    ThermocalInputError
        When only one of ``latitude``/``axis`` is given, or the signal is not a rate.

    Notes
    -----
    .. math:: \Omega_\mathrm{axis} = \Omega\,\mathbf u \cdot (0, \cos\varphi, \sin\varphi)

    with :math:`\Omega = 7.292115\times10^{-5}` rad/s (WGS 84) and :math:`\varphi` the
    latitude.

    References
    ----------
    - IEEE Std 952-1997, IEEE Standard Specification Format Guide and Test Procedure for
      Single-Axis Interferometric Fiber Optic Gyros.
    - NIMA TR8350.2, Department of Defense World Geodetic System 1984 (WGS 84).
    """
    if latitude is None and axis is None:
        return 0.0
    if latitude is None or axis is None:
        raise ThermocalInputError.naming(
            "earth-rate removal needs both {latitude} and {axis}", "latitude", "axis"
        )
    if units.canonical_unit(unit) != "deg/h":
        raise ThermocalInputError.naming(
            f"{where}: {{latitude}}/{{axis}} remove the earth rate from a gyro signal; "
            f"this signal is in {unit}",
            "latitude",
            "axis",
        )
    return units.earth_rate_on_axis_deg_h(latitude, units.parse_axis(axis))


def known_input_what(
    latitude: float | None, axis: str | None, other: float | None, gravity: str | None = None
) -> str:
    """What a fit's known input is, for the model file (``inputs.known_input.what``).

    Parameters
    ----------
    latitude : float or None
        Site latitude [°] (earth rate removed with ``axis``).
    axis : str or None
        Sensitive axis in East-North-Up.
    other : float or None
        A further constant known input [signal unit].
    gravity : str or None, optional
        Description of the gravity removed, if any (default ``None``).

    Returns
    -------
    str
        The parts joined by ``" + "``, or ``"none"``.
    """
    parts = []
    if latitude is not None and axis is not None:
        parts.append(f"earth rate at latitude {latitude:g}° on axis {axis}")
    if gravity:
        parts.append(gravity)
    if other:
        parts.append(f"--known-input {other:g}")  # cli-words: the provenance a model records
    return " + ".join(parts) or "none"


@dataclass(frozen=True)
class _FitSpec:
    """What every channel's fit shares: the family and its options, the temperature
    columns, the known input (earth rate or given) and the target."""

    family: str
    options: dict[str, Any]
    temps: tuple[str, ...] | None
    latitude: float | None
    axis: str | None
    known_input: float | None
    target: str
    gravity_axis: str | None = None
    gravity_m_s2: float | None = None
    tref_c: float | None = None
    gravity_triad: _gravity.TriadGravity | None = None
    overrides: tuple[str, ...] = ()


def _local_gravity(
    gravity_axis: str | None, gravity: float | None, latitude: float | None
) -> float | None:
    """The local gravity [m/s²] for ``gravity_axis``
    (:func:`thermocal.gravity.local_gravity_m_s2`)."""
    return _gravity.local_gravity_m_s2(gravity_axis, gravity, latitude)


def _gravity_known_input(
    spec: _FitSpec, run: int, path: Path, name: str, unit: str, values_mg: _recording.FloatArray
) -> _gravity.GravityInput:
    """The gravity an accelerometer channel reads in run ``run`` [mg], with the words and
    record of the model's known input: along the triad's measured direction when the
    triad is fitted together, else along the nominal up axis with a warning that the
    direction is unknown (:func:`thermocal.gravity.channel_gravity`)."""
    return _gravity.channel_gravity(
        spec.gravity_triad, run, path, name, unit, values_mg, spec.gravity_axis, spec.gravity_m_s2
    )


@dataclass
class _Prepared:
    """One channel ready to fit: its model, runs and provenance, and the warnings so far."""

    est: _base.TemperatureModel
    runs: list[_rundata.RunData]
    first_inputs: dict[str, Any]
    provenance: list[dict[str, Any]]
    unit: str
    sig_name: str
    caught: list[Any]


def _fit_channel(
    spec: _FitSpec, loaded: list[tuple[Path, _recording.Recording]], signal: str | None
) -> tuple[_base.TemperatureModel, dict[str, Any], int]:
    """Fit one channel on the loaded runs; returns the model, its JSON result and
    the number of runs. Warnings are printed (by handle_errors) and listed in the result."""
    ((_n, est, result, n_runs),) = _fit_channels(spec, loaded, [signal])
    return est, result, n_runs


def _fit_channels(
    spec: _FitSpec, loaded: list[tuple[Path, _recording.Recording]], signals: Sequence[str | None]
) -> list[tuple[str, _base.TemperatureModel, dict[str, Any], int]]:
    """Fit every channel on the loaded runs (each file read once, by the caller).  Channels
    of the ``poly`` family with the same temperature inputs share one design
    (:func:`thermocal.models.poly_fit.fit_shared`: Ṫ, features and the design's reduction once;
    every model equal, bit for bit, to its own fit)."""
    preps = [_prepare_channel(spec, loaded, sig) for sig in signals]
    if spec.family == "poly" and len(preps) > 1:
        _share_inputs(preps)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            _poly_fit.fit_shared(
                [cast(_poly.PolyModel, p.est) for p in preps], [p.runs for p in preps]
            )
        for p in preps:
            p.caught.extend(caught)
    else:
        for p in preps:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                p.est.fit(p.runs)
                _judge_fitted(spec, p)
            p.caught.extend(caught)
    return [(p.sig_name, *_finish_channel(spec, p)) for p in preps]


def _share_inputs(preps: list[_Prepared]) -> None:
    """Give every channel's runs the first channel's time and temperature arrays when they
    are equal (one copy in memory, and :func:`fit_shared` sees one design); temperatures
    read by blocks are the same when they are the same file's columns (never read whole
    to compare them)."""
    first = preps[0].runs
    for p in preps[1:]:
        for i, r in enumerate(p.runs):
            f, mine = first[i], r.temps_c
            if mine is f.temps_c:
                continue
            if (
                mine.same_columns(f.temps_c)
                if isinstance(mine, TemperatureBlocks)
                else np.array_equal(mine, f.temps_c)
            ):
                p.runs[i] = dataclasses.replace(r, temps_c=f.temps_c)


def _prepare_channel(
    spec: _FitSpec, loaded: list[tuple[Path, _recording.Recording]], signal: str | None
) -> _Prepared:
    """One channel's runs with their known inputs, its model object and provenance."""
    est = build_model(spec.family, spec.options)
    temps, latitude, axis, known_input = spec.temps, spec.latitude, spec.axis, spec.known_input
    runs: list[_rundata.RunData] = []
    first_inputs: dict[str, Any] = {}
    provenance: list[dict[str, Any]] = []
    sensor_ids: list[str | None] = []
    unit = ""
    sig_name = signal or "signal"
    temp_names: tuple[str, ...] | None = None
    from thermocal.stability.analysis import check_not_stuck

    for path, rec in loaded:
        _values, run_unit = rec.signal(signal)
        sig_name = signal or rec.signals[0]
        check_not_stuck(
            rec.column(sig_name), sig_name, str(path), "signals",
            "has no thermal behaviour to model (a flat model of a dead channel)",
        )  # fmt: skip
        if unit and run_unit != unit:
            raise ThermocalInputError(f"{path}: signal unit {run_unit} differs from {unit}")
        unit = run_unit
        # --latitude serves gravity alone when no --axis names a gyro's sensitive axis
        earth_lat = None if (spec.gravity_axis and axis is None) else latitude
        ki = earth_rate_known_input(earth_lat, axis, unit, path)
        g_in = _gravity_known_input(spec, len(runs), path, sig_name, unit, _values)
        ki += g_in.value_mg
        if known_input is not None:
            ki += known_input
        if not runs:  # the model learns how its inputs were written (model file "inputs")
            first_inputs = _rundata.model_inputs(
                rec, sig_name, run_temp_names(rec, temps), known_input=ki,
                known_input_what=known_input_what(earth_lat, axis, known_input, g_in.what),
            )  # fmt: skip
            if g_in.record is not None:  # export-params reads whether it was measured
                first_inputs["known_input"]["gravity"] = g_in.record
        if spec.family == "poly":  # its passes go by blocks: temperatures read as they go
            run = run_in_blocks(rec, signal, list(temps) if temps else None, ki, validated=True)
        else:
            run = _rundata.RunData.from_recording(
                rec, signal, list(temps) if temps else None, known_input=ki,
                temperature_unit="auto",
            )  # fmt: skip
        run = dataclasses.replace(run, name=path.name)
        if temp_names is None:
            temp_names = run.temp_names
        elif run.temp_names != temp_names:
            raise ThermocalInputError(
                f"{path}: temperature columns {list(run.temp_names)} differ from the first "
                f"file's {list(temp_names)}"
            )
        runs.append(run)
        sensor_ids.append(rec.meta.sensor_id)
        provenance.append(
            {
                "file": path.name,
                "path": str(path),
                "sha256": _files.file_sha256(path),
                "n_samples": run.n_samples,
                "known_input": ki,
            }
        )

    names = list(runs[0].temp_names) if runs else []
    rate_names = [n for n in est.data_needs(names, len(runs)).rate if n in names] if runs else []
    for doubt in rate_time_doubts(
        runs, rate_names, float(spec.options.get("rate_interval_s") or 60.0)
    ):  # before the judgement: its refusal would drop a warning caught with it
        warnings.warn(doubt, stacklevel=1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        est.adequacy_ = _judge_channel(spec, est, runs, sig_name, first_inputs, unit)
        known_ids = sorted({str(i) for i in sensor_ids if i})
        if len(known_ids) > 1:
            first_inputs.pop("sensor_id", None)
            warnings.warn(
                f"the runs come from different sensors ({', '.join(known_ids)}): one "
                "compensation model for several sensors averages them; fit each sensor "
                "on its own runs",
                ConditioningWarning,
                stacklevel=1,
            )
        elif known_ids and "sensor_id" not in first_inputs:
            first_inputs["sensor_id"] = known_ids[0]
    return _Prepared(est, runs, first_inputs, provenance, unit, sig_name, list(caught))


MAX_CHAMBER_RATE_C_PER_MIN = 20.0
"""|Ṫ| [°C/min] beyond which no thermal test moves a sensor's temperature (climatic chambers
ramp at 1–15 °C/min; thermal-shock transfers are not ramps a Ṫ term describes)."""

MIN_RAMP_C_PER_MIN = 0.1
"""Below this largest |Ṫ| [°C/min] a test fitted with Ṫ terms has no ramp (the same bound as
:data:`thermocal.adequacy.MIN_RATE_SPAN_C_PER_MIN`)."""

TIME_SCALES = ((1000.0, "ms read as s"), (1.0 / 60.0, "minutes read as s"), (1e-3, "s read as ms"))
"""Time-unit mistakes the Ṫ check names: the factor Ṫ would change by, and the mistake."""


def _steps(t: FloatArray, a: int, b: int) -> FloatArray:
    """The steps ``t[a + 1 : b + 1] − t[a : b]``."""
    return np.diff(t[a : b + 1])


def rate_time_doubts(
    runs: Sequence[_rundata.RunData], temp_names: Sequence[str], interval_s: float
) -> list[PlausibilityWarning]:
    r"""Why the time axis of runs fitted with Ṫ terms (``temp_names``) looks wrong, one warning
    per (run, column): the largest |Ṫ| (the 99th percentile of Ṫ over ``interval_s``,
    :func:`thermocal.adequacy.temperature_rate_c_per_min`) above
    :data:`MAX_CHAMBER_RATE_C_PER_MIN` or below :data:`MIN_RAMP_C_PER_MIN` where a time unit
    1000 or 60 times off (:data:`TIME_SCALES`) would make it a chamber's ramp, or a run
    shorter than the interval.  A wrong time unit scales the Ṫ coefficients by the same
    factor (time ×1000 under rate terms).

    Parameters
    ----------
    runs : sequence of RunData
        The runs to fit.
    temp_names : sequence of str
        The temperature columns that carry Ṫ terms.
    interval_s : float
        Interval over which Ṫ is taken [s].

    Returns
    -------
    list of PlausibilityWarning
        One per doubtful (run, column), naming the parameter ``time_unit``; empty when every
        time axis looks right.

    Notes
    -----
    .. math:: \dot T_k = \frac{T(t_k) - T(t_k - \Delta t)}{\Delta t}

    judged by the 99th percentile of :math:`|\dot T|` [°C/min].
    """
    out: list[PlausibilityWarning] = []
    for run in runs:
        if run.temperature_unit != "degC" or run.time_s.size < 2:
            continue
        span_s = float(run.time_s[-1] - run.time_s[0])
        # Ṫ over the interval, or over 1 % of a record too short for it (a time axis read
        # 1000× short spans ramps in one interval), never below 3 samples' steps
        # np.median of the steps, selected block by block (no array of them)
        step = median_in_blocks(partial(_steps, run.time_s), run.time_s.size - 1)
        delta = max(3.0 * step, min(interval_s, span_s / 100.0))
        for name in temp_names:
            j = list(run.temp_names).index(name)
            where = f"{run.name}: {name}"
            rates = _adequacy.temperature_rate_c_per_min(run.time_s, run.temps_c[:, j], delta)
            if not all_finite(rates):
                rates = rates[np.isfinite(rates)]
            if rates.size == 0:
                out.append(
                    PlausibilityWarning.naming(
                        f"{where}: the record spans {span_s:.4g} s, too short for Ṫ: is its "
                        "time unit right? (check {time_unit})",
                        "time_unit",
                    )
                )
                continue
            # |Ṫ| in place and partitioned by the percentile: the rates are this loop's own
            peak = float(np.percentile(np.abs(rates, out=rates), 99.0, overwrite_input=True))
            fits = sorted(
                (
                    (k, what)
                    for k, what in TIME_SCALES
                    if MIN_RAMP_C_PER_MIN <= peak * k <= MAX_CHAMBER_RATE_C_PER_MIN
                ),
                key=lambda kw: abs(math.log(peak * kw[0])),  # nearest a 1 °C/min ramp
            )
            if peak > MAX_CHAMBER_RATE_C_PER_MIN or (peak < MIN_RAMP_C_PER_MIN and fits):
                hint = f" ({fits[0][1]}: {peak * fits[0][0]:.3g} °C/min)" if fits else ""
                out.append(
                    PlausibilityWarning.naming(
                        f"{where}: Ṫ reaches {peak:.3g} °C/min over a record of {span_s:.4g} "
                        f"s; a chamber ramps at {MIN_RAMP_C_PER_MIN:g}–"
                        f"{MAX_CHAMBER_RATE_C_PER_MIN:g} °C/min: is the time unit right{hint}? "
                        "The Ṫ coefficients scale with it (check {time_unit})",
                        "time_unit",
                    )
                )
    return out


def _data_unit(first_inputs: dict[str, Any], sig_name: str, unit: str) -> tuple[str, float]:
    """The data's own unit of a channel (as given in the file, option or column name) and
    the factor from the model's canonical unit to it (raw counts scaled to a physical unit
    stay in the canonical unit)."""
    shown = units.shown_unit(unit, str((first_inputs.get("units") or {}).get(sig_name, unit)))
    return shown.unit, shown.to_shown


def _judge_channel(
    spec: _FitSpec,
    est: _base.TemperatureModel,
    runs: list[_rundata.RunData],
    sig_name: str,
    first_inputs: dict[str, Any],
    unit: str,
) -> dict[str, Any]:
    """Judge the data before the fit (:func:`thermocal.adequacy.judge`): refuse what they
    cannot support (exit 2), warn where overridden; the record goes into the model file."""
    names = list(runs[0].temp_names)
    needs = est.data_needs(names, len(runs))
    kind = {"rate": "gyro", "accel": "accel"}.get(units.signal_kind(unit))
    given, factor = _data_unit(first_inputs, sig_name, unit)
    judged = _adequacy.judge(
        needs,
        [r.time_s for r in runs],
        [r.temps_c for r in runs],
        names,
        signals=[r.signal for r in runs if r.signal is not None],  # no copy: a shift is no motion
        kind=kind,
        name=sig_name,
        temperature_unit="°C" if runs[0].temperature_unit == "degC" else "counts",
        unit_factor=factor,
        unit=given,
        overrides=spec.overrides,
        rate_interval_s=float(spec.options.get("rate_interval_s") or 60.0),
    )
    return judged.enforce().to_dict()


def _judge_fitted(spec: _FitSpec, p: _Prepared) -> None:
    """What only the fit knows, judged by the same rules (a piecewise model's segments,
    ``segment_tests_``): refused unless overridden, added to the adequacy record."""
    tests = tuple(getattr(p.est, "segment_tests_", ()))
    if not tests:
        return
    try:
        judged = _adequacy.Adequacy(tests, tuple(spec.overrides), p.sig_name).enforce()
    except ThermocalInputError as exc:  # name the files, as a reader's error does
        files = ", ".join(str(r.name) for r in p.runs)
        raise ThermocalInputError.around(exc, f"{files}: ") from None
    rec = p.est.adequacy_
    if rec is None:  # judged before the fit: always a record here
        return
    rec["tests"] = [*rec["tests"], *(t.to_dict() for t in tests)]
    if judged.failed and rec["verdict"] == "pass":
        rec["verdict"] = "overridden"


def _finish_channel(
    spec: _FitSpec, prep: _Prepared
) -> tuple[_base.TemperatureModel, dict[str, Any], int]:
    """After the fit: the fit-quality warnings, the model's metadata, the JSON result."""
    est, runs, first_inputs, provenance = prep.est, prep.runs, prep.first_inputs, prep.provenance
    unit, sig_name, target = prep.unit, prep.sig_name, spec.target
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        dof = getattr(est.stats_, "dof", None)
        if dof is not None and dof <= 0:
            warnings.warn(
                f"{est.stats_.n_samples} samples for {len(est.coefficients())} coefficients: "
                "no residual degrees of freedom, the fit passes through the data; standard "
                "errors and the rms residual say nothing about its accuracy — record more data",
                ConditioningWarning,
                stacklevel=1,
            )
        note = (getattr(est.stats_, "extra", None) or {}).get("residual_correlation", {})
        if note and note.get("note"):
            warnings.warn(f"{est.family}: {note['note']}", ConditioningWarning, stacklevel=1)
    all_caught = [*prep.caught, *caught]
    # the --json result speaks to the command line: options where the library names parameters
    messages = [warning_text(w.message) for w in all_caught]
    for w in all_caught:  # hand them on to handle_errors, which prints them on stderr
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)

    est.signal_name = sig_name
    est.signal_unit = unit
    est.target = target
    est.inputs_ = first_inputs
    est.data_ = provenance

    st = est.stats_
    kappa = st.condition_number
    trange = {
        n: [float(a), float(b)] for n, (a, b) in zip(est.temp_names_, est.temp_range_, strict=True)
    }
    rrange = (
        {
            n: [float(a), float(b)]
            for n, (a, b) in zip(est.temp_names_, est.rate_range_, strict=True)
        }
        if est.rate_range_ is not None
        else None
    )
    kept = st.extra.get("selected_terms")
    given, to_given = _data_unit(first_inputs, sig_name, unit)
    result: dict[str, Any] = {
        "model": est.family,
        "n_coefficients": st.n_coefficients,
        "rms_residual": st.rms_residual * to_given,  # in the data's own unit (``unit``)
        "rms_residual_model_unit": st.rms_residual,
        "condition_number": st.condition_number,
        "condition": _results.condition_wording(kappa),
        "temperature_range": trange,
        "rate_range": rrange,
        "n_samples": st.n_samples,
        "n_runs": len(runs),
        "unit": given,
        "model_unit": unit,
        "temperature_unit": est.temperature_unit,
        "inputs": first_inputs,
        "target": target,
        "files": [{k: p[k] for k in ("file", "sha256", "n_samples")} for p in provenance],
        "terms_kept": kept,
        "fit": st.to_dict(),
        "coefficients": [c.to_dict() for c in est.coefficients()],
        "warnings": messages,
        "known_input": {
            "value": first_inputs.get("known_input", {}).get("value", 0.0),
            "what": first_inputs.get("known_input", {}).get("what"),
        },
        "unit_as_given": (first_inputs.get("units") or {}).get(sig_name, unit),
        "adequacy": est.adequacy_,
    }
    if spec.tref_c is not None:
        result["tref"] = {
            "tref_c": spec.tref_c,
            "coefficients": [c.to_dict() for c in est.coefficients_about(spec.tref_c)],  # type: ignore[attr-defined]
        }
    return est, result, len(runs)


# --- the one entry ----------------------------------------------------------------------------


@dataclass(frozen=True)
class FittedChannel:
    """One channel fitted by :func:`fit_files`: its model, its figures (the keys of the
    ``fit`` command's JSON; ``rms_residual`` in the data's own unit) and the number of runs.

    Attributes
    ----------
    name : str
        The channel.
    model : TemperatureModel
        Its fitted model.
    figures : dict
        The keys of the ``fit`` command's JSON.
    n_runs : int
        Runs fitted.
    """

    name: str
    model: _base.TemperatureModel
    figures: dict[str, Any]
    n_runs: int


@dataclass(frozen=True)
class FitResult:
    """What :func:`fit_files` fitted and wrote: the file ``output``, a model file for one
    channel or a calibration file (``calibration``) for several, and each channel.

    Attributes
    ----------
    output : Path
        The model or calibration file written.
    channels : tuple of FittedChannel
        Each channel.
    calibration : bool
        ``output`` is a calibration file of several channels.
    """

    output: Path
    channels: tuple[FittedChannel, ...]
    calibration: bool

    @property
    def warnings(self) -> list[str]:
        """Every channel's warnings (one line each)."""
        return [w for ch in self.channels for w in ch.figures["warnings"]]

    def to_dict(self) -> dict[str, Any]:
        """The ``fit`` command's JSON: one channel's figures with ``output``, or ``{"output",
        "format": "thermocal-calibration", "channels": {name: figures}}``."""
        if not self.calibration:
            return self.channels[0].figures
        return {
            "output": str(self.output),
            "format": "thermocal-calibration",
            "channels": {
                ch.name: {**ch.figures, "output": str(self.output)} for ch in self.channels
            },
        }


def _distinct_runs(paths: Sequence[Path]) -> None:
    """Refuse a run given twice, by name or as a byte-for-byte copy (the same SHA-256): it
    would count twice, its samples weighing double and the standard errors shrunk by √2
    (``fit a.csv a.csv`` counted two runs)."""
    seen: dict[str, Path] = {}
    for path in paths:
        digest = _files.file_sha256(path)
        if digest in seen:
            raise ThermocalInputError(
                f"{path}: the same bytes as {seen[digest]} (a file given twice, or a copy): "
                "each run counts once in a fit; give every run's file once"
            )
        seen[digest] = path


def _check_numbers(o: FitOptions) -> None:
    """Refuse the numeric options no fit can use, naming the option: a latitude outside
    ±90° (the earth rate Ω·sin φ of a latitude of 200° is that of −20°) and a NaN or
    infinite ``known_input``.  The family's own options are checked by their declarations
    (:meth:`thermocal.families.FamilyOption.check`)."""
    if o.latitude is not None and not -90.0 <= o.latitude <= 90.0:
        raise ParameterError("latitude", f"{{name}} must be within ±90°, got {o.latitude}")
    if o.known_input is not None and not np.isfinite(o.known_input):
        raise ParameterError(
            "known_input", f"{{name}} must be a finite number, got {o.known_input}"
        )


def _check_options(paths: Sequence[Path], o: FitOptions, output: Path) -> dict[str, Any]:
    """Everything refused before a file is read: ceilings, output name, family options;
    returns the family options (``o.params``)."""
    options = dict(o.params)
    check_terms(options.get("terms"))
    if not paths:
        raise ThermocalInputError("give at least one data file")
    _writers.check_not_input(output, list(paths))
    if output.suffix.lower() not in (".json", ""):
        raise ThermocalInputError(f"{output}: the model file is JSON; use a .json name")
    _check_numbers(o)
    build_model(o.model, options)  # refuse options that do not apply before reading
    if len(o.signals or ()) > 1 and o.axis is not None:
        raise ParameterError(
            "axis",
            "earth-rate removal ({name}) takes one signal at a time: each gyro's sensitive "
            "axis points elsewhere; fit the gyros one by one with their {name}, or leave the "
            "earth rate in the bias",
        )
    return options


def _thermometers(
    loaded: list[tuple[Path, _recording.Recording]], o: FitOptions
) -> tuple[list[tuple[Path, _recording.Recording]], list[dict[str, Any]]]:
    """Each run's temperature columns with a quantised or slow thermometer reconstructed
    (``o.temperature``; :func:`thermocal.thermometer.reconstruct_columns`), each one
    reconstructed said in a warning; what every column's thermometer is."""
    from thermocal.thermometer import ThermometerWarning, reconstruct_columns

    out, said = [], []
    for path, rec in loaded:
        names = run_temp_names(rec, o.temperatures)
        rec, rows = reconstruct_columns(rec, names, mode=o.temperature)
        for r in rows:
            if r["temperature"] == "reconstructed":
                warnings.warn(
                    ThermometerWarning.naming(
                        f"{path}: {r['column']!r}: {r['note']}; give {{temperature}} raw to "
                        "fit it as logged",
                        "temperature",
                    ),
                    stacklevel=3,
                )
        out.append((path, rec))
        said.extend(rows)
    return out, said


def _recorded(thermo: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """What the model file keeps of each run's thermometers (not the file's path)."""
    return [{k: v for k, v in r.items() if k != "file"} for r in thermo]


def fit_files(paths: Sequence[Path], options: FitOptions, output: Path) -> FitResult:
    """Fit ``options.model`` on the recordings ``paths`` (one run each) and save it to
    ``output`` (module docstring).  Options are checked before any file is read
    (:class:`ThermocalInputError`); each file is read once with every channel's column.

    Parameters
    ----------
    paths : sequence of Path
        The recordings, one run each (or station folders).
    options : FitOptions
        Family, its options, columns, known inputs and read options.
    output : Path
        The model file to write (JSON).

    Returns
    -------
    FitResult
        The fitted model(s), the adequacy record and the path written.

    Raises
    ------
    ThermocalInputError
        When an option does not fit the data, a file cannot be read, a run is repeated,
        or the runs cannot support the model asked (adequacy tests not overridden).
    ParameterError
        When a family option is out of its bounds.
    """
    o = options
    family_options = _check_options(paths, o, output)
    names = list(o.signals or ())
    g_local = _local_gravity(o.gravity_axis, o.gravity, o.latitude)
    loaded = [(path, _read_run(path, o)) for path in station_sensor_paths(paths, o.topic)]
    if o.tref is not None and o.model != "poly":
        raise ParameterError(
            "tref",
            f"{{name}} applies to the poly family (coefficients about TREF), not {o.model!r}",
        )
    _distinct_runs([path for path, _rec in loaded])
    # the thermometer first: the heater's hold is judged (and thinned) on the temperature
    # the fit uses, and the reconstruction needs every sample (its update period)
    loaded, thermo = _thermometers(loaded, o)
    loaded, holds, said = _heater_holds(loaded, o)
    loaded = _legs_of(loaded, o)
    spec = _FitSpec(o.model, family_options, o.temperatures, o.latitude, o.axis, o.known_input,
                    o.target, o.gravity_axis, g_local, o.tref,
                    _gravity.triad_gravity(loaded, names, o.gravity_axis, g_local),
                    overrides_of(o.allow_narrow, o.allow_motion))  # fmt: skip
    if len(names) <= 1:
        est, result, n_runs = _fit_channel(spec, loaded, names[0] if names else None)
        est.inputs_ = {**(est.inputs_ or {}), "thermometers": _recorded(thermo)}
        _files.save_model(est, output)
        result["output"], result["heater"] = str(output), holds
        result["thermometers"] = thermo
        result["warnings"] = [*said, *result["warnings"]]
        return FitResult(output, (FittedChannel(est.signal_name, est, result, n_runs),), False)
    fitted = _fit_channels(spec, loaded, names)
    for _name, est, _res, _n in fitted:
        est.inputs_ = {**(est.inputs_ or {}), "thermometers": _recorded(thermo)}
    cal = _calibration.Calibration(
        [
            _calibration.Channel(
                name,
                name,
                str(res["unit_as_given"]),
                est,
                _calibration.guess_role(name, res["model_unit"]),
            )
            for name, est, res, _n in fitted
        ]
    )
    _files.save_calibration(cal, output)
    extra = {"heater": holds, "thermometers": thermo}
    channels = tuple(
        FittedChannel(name, est, {**res, **extra, "warnings": [*said, *res["warnings"]]}, n)
        for name, est, res, n in fitted
    )
    return FitResult(output, channels, True)


def _read_run(path: Path, o: FitOptions) -> _recording.Recording:
    """One run read and checked (:func:`check_recording`); a long Parquet file fitted with
    ``poly`` read with its columns on demand, its temperatures read as the checks and the
    fit's passes need them (:mod:`thermocal.pipeline.fit_columns`)."""
    from thermocal.readers.dispatch import read_recording

    read = o.read_options
    blocks = o.model == "poly" and read_by_blocks(path)
    return check_recording(read_recording(path, read, columns_on_demand=blocks), read)


def _heater_holds(
    loaded: list[tuple[Path, _recording.Recording]], o: FitOptions
) -> tuple[list[tuple[Path, _recording.Recording]], dict[str, Any], list[str]]:
    """Each run's heater hold (:func:`thermocal.heater.thin_recording`) thinned to its
    sweep's density; the holds found by file name (JSON) and their warnings, also said."""
    from thermocal.heater import HeaterOptions, HeaterWarning, thin_recording

    heater = HeaterOptions(o.heater, o.heater_setpoint, o.heater_band, o.heater_min_hold)  # type: ignore[arg-type]
    if o.model == "warmup" and o.heater_setpoint is None:  # its plateau is what it models
        return loaded, {}, []
    temp = (o.temperatures or (None,))[0]
    out, holds, said = [], {}, []
    for path, rec in loaded:
        thinned, judged = thin_recording(rec, heater, where=str(path), temperature=temp)
        for text in judged.warnings:
            warnings.warn(HeaterWarning(text), stacklevel=3)
            said.append(text)
        if judged.hold is not None:
            holds[path.name] = judged.hold.to_dict()
        out.append((path, thinned))
    return out, holds, said


def _legs_of(
    loaded: list[tuple[Path, _recording.Recording]], o: FitOptions
) -> list[tuple[Path, _recording.Recording]]:
    """``o.legs`` heating or cooling: each run cut into its legs of that direction
    (:func:`thermocal.legs.find_legs` on the first fitted temperature), each leg a run;
    refused, naming ``legs``, when no file has such a leg."""
    if o.legs == "all":
        return loaded
    from thermocal.legs import find_legs

    out = []
    for path, rec in loaded:
        name = run_temp_names(rec, o.temperatures)[0]
        legs = find_legs(rec.time_s, rec.temperature_c(name))
        out += [(path, rec.select(slice(g.start, g.stop))) for g in legs.of(o.legs)]
    if not out:
        where = ", ".join(str(p) for p, _ in loaded).replace("{", "{{").replace("}", "}}")
        raise ThermocalInputError.naming(
            f"no {o.legs} leg in {where} (the temperature "
            f"never {'rises' if o.legs == 'heating' else 'falls'} beyond its noise); give "
            "{legs} all or the other direction",
            "legs",
        )
    return out


__all__ = [
    "FitResult",
    "FittedChannel",
    "build_model",
    "check_terms",
    "fit_files",
]
