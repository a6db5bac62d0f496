"""``thermocal fit FILE... --model NAME --signal COL --temps COLS -o MODEL.json``.

Fits a compensation model (SPEC §4) on one or several runs (several FILEs =
several runs, each with its own turn-on offset unless ``--no-per-run-offset``)
and writes the self-describing model file (:func:`thermocal.models.files.save_model`)
with the data files' names and SHA-256 checksums.

The family is looked up in the registry (:func:`thermocal.models.registry.get_model_class`).
The command collects the model options the user gave into one dict and calls
``cls.from_cli_options(options)``, the one option parser of every family
restricted to its constructor parameters.  Only options given on the command
line are in the dict (no ``None`` values).  Keys:

==================  =======================  ==================================================
key                 option                   meaning (families)
==================  =======================  ==================================================
``terms``           ``--terms``              ``seed000`` or ``"T1,T1^2,dT1,T1*dT1,..."`` (poly)
``order``           ``--order N``            plain polynomial order (poly); order in ΔT (warmup)
``rate_interval_s`` ``--rate-interval S``    Δt of Ṫ [s] (poly)
``rate_method``     ``--rate-method``        backward | forward | centred (poly)
``select``          ``--select [--select-method bic|holdout]``  term selection (poly)
``ridge``           ``--ridge ALPHA``        ridge α on unit-RMS terms (poly)
``rcond``           ``--rcond R``            SVD truncation threshold (poly)
``solver``          ``--solver``             auto | qr | gram (poly)
``noise_threshold`` ``--noise-threshold K``  keep truncated components above K σ̂ (poly)
``breakpoints``     ``--breakpoints 25,30``  list of float [°C] (piecewise)
``segments``        ``--segments N``         segments, breakpoints from data (piecewise)
``method``          ``--method``             intersect | continuous (piecewise); warmup's own
``start_window_s``  ``--start-window S``     F0/T0 averaging window [s] (warmup)
``t0_order``        ``--t0-order M``         coefficient order in T0 (warmup)
``deviation``       ``--deviation``          distinct-curve threshold, signal unit (bank)
``tolerance``       ``--tolerance``          model acceptance, signal unit (bank)
``startup_s``       ``--startup-s``          start-up smoothing window [s] (bank)
``per_run_offset``  ``--[no-]per-run-offset``  per-run turn-on offsets (all that support it)
==================  =======================  ==================================================

``--target bias|scale_factor`` and the signal's name and unit are recorded in
the model file.  ``--latitude DEG --axis up`` removes the earth rate seen by
the axis (:func:`thermocal.units.earth_rate_on_axis_deg_h`) as a known input;
``--known-input X`` gives any other known input in the canonical signal unit.

JSON keys (``--json``): ``model``, ``output``, ``n_coefficients``,
``rms_residual`` (in the data's own unit, ``unit``; ``rms_residual_model_unit`` in the
model's canonical ``model_unit``), ``condition_number``, ``temperature_range`` ({name: [lo, hi]}),
``rate_range``, ``n_samples``, ``n_runs``, ``unit``, ``target``, ``files``
(name, sha256, n_samples), ``terms_kept`` (selection, else null), ``fit`` (all
fit statistics), ``coefficients`` and ``warnings``.
"""

import dataclasses
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, cast

import typer

from thermocal import errors as _errors
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    AllowMotionOpt,
    AllowNarrowOpt,
    AxisOpt,
    DecimalOpt,
    DelimiterOpt,
    JsonOpt,
    LatitudeOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalOpt,
    SignalUnitOpt,
    TempConversionOpt,
    TempsOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    earth_rate_known_input,
    emit,
    fmt,
    handle_errors,
    known_input_what,
    load_recording,
    one_line,
    split_floats,
    split_names,
    stdout,
    text_options,
)
from thermocal.defaults import MODEL_FAMILIES, overrides_of
from thermocal.errors import ConditioningWarning, ThermocalInputError

if TYPE_CHECKING:
    import numpy as np
    import rich.table as _rich_table

    import thermocal.adequacy as _adequacy
    import thermocal.gravity as _gravity
    import thermocal.models.base as _base
    import thermocal.models.calibration as _calibration
    import thermocal.models.files as _files
    import thermocal.models.poly as _poly
    import thermocal.models.registry as _registry
    import thermocal.recording as _recording
    import thermocal.writers as _writers
    from thermocal import units
else:
    np = LazyModule("numpy")
    _rich_table = LazyModule("rich.table")
    units = LazyModule("thermocal.units")
    _adequacy = LazyModule("thermocal.adequacy")
    _writers = LazyModule("thermocal.writers")
    _base = LazyModule("thermocal.models.base")
    _registry = LazyModule("thermocal.models.registry")
    _calibration = LazyModule("thermocal.models.calibration")
    _files = LazyModule("thermocal.models.files")
    _poly = LazyModule("thermocal.models.poly")
    _gravity = LazyModule("thermocal.gravity")
    _recording = LazyModule("thermocal.recording")

TARGETS = ("bias", "scale_factor")


def run_temp_names(rec: "_recording.Recording", temps: str | None) -> list[str]:
    """The temperature columns a fit uses: ``--temps`` or the file's."""
    return split_names(temps) or list(rec.temperatures)


MAX_ORDER = 10
"""Hard ceiling of ``--order`` (poly: powers of each temperature; warmup: order in ΔT) and
``--t0-order`` (warmup).  A temperature polynomial of order 10 over a −40…85 °C range
already has a condition number near 1e9 on scaled variables (each further power loses about
one digit of the fit's 16); calibration practice (IEEE Std 952/1293, the PX4 and ArduPilot
thermal calibrations: order 3) stays well below.  The data limit (more coefficients than
samples or distinct temperatures) is checked once the data are read (``thermocal.adequacy``);
this ceiling is checked before anything is read or allocated, so that an order of 10²⁰ —
which typer parses as a Python int — never becomes a list of 10²⁰ terms."""

MAX_TERMS = 200
"""Hard ceiling of the number of terms in ``--terms`` (poly).  The seed set ``seed000`` has
9 terms per temperature sensor (37 with four sensors and the constant); 200 terms is five times
that, and a design matrix of 200 float64 columns costs 1.6 kB per sample (16 GB at 10⁷
samples), beyond any machine the fit is meant for."""

MAX_SEGMENTS = 100
"""Hard ceiling of ``--segments`` (piecewise): each segment adds two coefficients and
needs its own temperature span; 100 segments over a −40…85 °C range is 1.25 °C each, below
which a segment fits the noise of one soak rather than a temperature effect."""


def check_ceilings(
    order: int | None, t0_order: int | None, segments: int | None, terms: str | None
) -> None:
    """Refuse (:class:`ThermocalInputError`, exit 2) an order or term count beyond the hard
    ceilings :data:`MAX_ORDER`, :data:`MAX_TERMS`, :data:`MAX_SEGMENTS`, before any data is
    read.  The value is checked, not only its type: typer parses any integer literal."""
    for option, value, lo, hi in (
        ("--order", order, 1, MAX_ORDER),
        ("--t0-order", t0_order, 0, MAX_ORDER),
        ("--segments", segments, 1, MAX_SEGMENTS),
    ):
        if value is not None and not lo <= value <= hi:
            shown = (
                str(value)
                if len(str(value)) <= 24
                else f"{str(value)[:20]}… ({len(str(value))} digits)"
            )
            raise ThermocalInputError(f"{option} must be between {lo} and {hi}, got {shown}")
    if terms is not None:
        n = terms.count(",") + 1
        if n > MAX_TERMS:
            raise ThermocalInputError(f"--terms lists {n} terms; at most {MAX_TERMS} are accepted")
        for power in _POWER.findall(terms):
            if len(power) > 3 or int(power) > MAX_ORDER:
                raise ThermocalInputError(
                    f"--terms: power {power[:20]} is above the ceiling {MAX_ORDER}"
                )


_POWER = re.compile(r"\^\s*(\d+)")


def build_model(family: str, options: dict[str, Any]) -> "_base.TemperatureModel":
    """Instantiate a registered family from the CLI option dict by its one option parser
    (:meth:`TemperatureModel.from_cli_options`: an option the family does not take is
    refused, for every family)."""
    return _registry.get_model_class(family).from_cli_options(options)


@app.command("fit")
@handle_errors
def fit_cmd(
    files: Annotated[
        list[Path],
        typer.Argument(help="Recordings (CSV or Parquet); one run each.", show_default=False),
    ],
    model: Annotated[
        str, typer.Option("--model", help=f"Model family: {', '.join(MODEL_FAMILIES)}.")
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="Model file to write (JSON).")],
    signal: SignalOpt = None,
    temps: TempsOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    # poly
    terms: Annotated[
        str | None, typer.Option("--terms", help='poly: "seed000" or "T1,T1^2,dT1,T1*dT1,...".')
    ] = None,
    order: Annotated[
        int | None,
        typer.Option("--order", help="poly: plain polynomial order; warmup: order in ΔT."),
    ] = None,
    rate_interval: Annotated[
        float | None, typer.Option("--rate-interval", help="poly: Δt of Ṫ [s] (default 60).")
    ] = None,
    rate_method: Annotated[
        str | None, typer.Option("--rate-method", help="poly: backward | forward | centred.")
    ] = None,
    select: Annotated[
        bool, typer.Option("--select", help="poly: stepwise term selection.")
    ] = False,
    select_method: Annotated[
        str, typer.Option("--select-method", help="poly: selection criterion bic | holdout.")
    ] = "bic",
    ridge: Annotated[float | None, typer.Option("--ridge", help="poly: ridge α.")] = None,
    rcond: Annotated[
        float | None, typer.Option("--rcond", help="poly: SVD truncation (default 1e-3).")
    ] = None,
    solver: Annotated[str | None, typer.Option("--solver", help="poly: auto | qr | gram.")] = None,
    noise_threshold: Annotated[
        float | None,
        typer.Option(
            "--noise-threshold", help="poly: keep truncated SVD components above K σ (default 10)."
        ),
    ] = None,
    # piecewise
    breakpoints: Annotated[
        str | None, typer.Option("--breakpoints", help="piecewise: breakpoints [°C], e.g. 25,30.")
    ] = None,
    segments: Annotated[
        int | None, typer.Option("--segments", help="piecewise: N segments chosen from the data.")
    ] = None,
    method: Annotated[
        str | None, typer.Option("--method", help="piecewise: intersect | continuous.")
    ] = None,
    # warmup
    start_window: Annotated[
        float | None, typer.Option("--start-window", help="warmup: F0/T0 window [s].")
    ] = None,
    t0_order: Annotated[
        int | None, typer.Option("--t0-order", help="warmup: coefficient order in T0.")
    ] = None,
    # bank
    deviation: Annotated[
        float | None, typer.Option("--deviation", help="bank: distinct-curve threshold.")
    ] = None,
    tolerance: Annotated[
        float | None, typer.Option("--tolerance", help="bank: model acceptance tolerance.")
    ] = None,
    startup_s: Annotated[
        float | None, typer.Option("--startup-s", help="bank: start-up window [s].")
    ] = None,
    # common
    per_run_offset: Annotated[
        bool | None,
        typer.Option(
            "--per-run-offset/--no-per-run-offset",
            help="Estimate one turn-on offset per run (nuisance parameters).",
        ),
    ] = None,
    target: Annotated[
        str, typer.Option("--target", help="What the model describes: bias | scale_factor.")
    ] = "bias",
    latitude: LatitudeOpt = None,
    axis: AxisOpt = None,
    known_input: Annotated[
        float | None,
        typer.Option("--known-input", help="Known input to remove, canonical signal unit."),
    ] = None,
    gravity_axis: Annotated[
        str | None,
        typer.Option(
            "--gravity-axis",
            help="Accelerometers: the body axis pointing up in the static runs (+x, -x, +y, "
            "-y, +z, -z); the gravity it reads is a known input, so compensation keeps it.",
        ),
    ] = None,
    gravity: Annotated[
        float | None,
        typer.Option(
            "--gravity",
            help="Local gravity [m/s²] for --gravity-axis (default: WGS-84 normal gravity "
            "at --latitude, else standard gravity with a warning).",
        ),
    ] = None,
    tref: Annotated[
        float | None,
        typer.Option(
            "--tref",
            help="poly: also give the coefficients about this reference temperature [°C] "
            "(in T − TREF, the PX4/ArduPilot convention).",
        ),
    ] = None,
    allow_narrow: AllowNarrowOpt = False,
    allow_motion: AllowMotionOpt = False,
    t_names: NamesOpt = None,
    topic: TopicOpt = None,
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Fit a temperature-compensation model on one or several runs and save it."""
    if target not in TARGETS:
        raise ThermocalInputError(f"--target must be bias or scale_factor, got {target!r}")
    check_ceilings(order, t0_order, segments, terms)
    if not files:
        raise ThermocalInputError("give at least one data file")
    _writers.check_not_input(output, list(files))
    if output.suffix.lower() not in (".json", ""):
        raise ThermocalInputError(f"{output}: the model file is JSON; use a .json name")
    options: dict[str, Any] = {
        "terms": terms,
        "order": order,
        "rate_interval_s": rate_interval,
        "rate_method": rate_method,
        "select": select_method if select else None,
        "ridge": ridge,
        "rcond": rcond,
        "solver": solver,
        "noise_threshold": noise_threshold,
        "breakpoints": split_floats(breakpoints, "--breakpoints"),
        "segments": segments,
        "method": method,
        "start_window_s": start_window,
        "t0_order": t0_order,
        "deviation": deviation,
        "tolerance": tolerance,
        "startup_s": startup_s,
        "per_run_offset": per_run_offset,
    }
    if select_method not in ("bic", "holdout"):
        raise ThermocalInputError(f"--select-method must be bic or holdout, got {select_method!r}")
    build_model(model, options)  # refuse options that do not apply before reading
    names = split_names(signal) or []
    if len(names) > 1 and axis is not None:
        raise ThermocalInputError(
            "earth-rate removal (--axis) takes one signal at a time: each gyro's sensitive "
            "axis points elsewhere; fit the gyros one by one with their --axis, or leave the "
            "earth rate in the bias"
        )
    g_local = _local_gravity(gravity_axis, gravity, latitude)
    # every file read once, with every channel's column (several channels: issue 15)
    loaded = [
        (
            path,
            load_recording(
                path,
                time=time,
                time_unit=time_unit,
                signal=signal,
                temps=temps,
                signal_unit=signal_unit,
                temp_unit=temp_unit,
                temp_conversion=temp_conversion,
                text=text_options(t_names, t_rate, t_bad, t_delim, t_dec),
                topic=topic,
            ),
        )
        for path in files
    ]
    if tref is not None and model != "poly":
        raise ThermocalInputError(
            f"--tref applies to the poly family (coefficients about TREF), not {model!r}"
        )
    spec = _FitSpec(model, options, temps, latitude, axis, known_input, target,
                    gravity_axis, g_local, tref,
                    _gravity.triad_gravity(loaded, names, gravity_axis, g_local),
                    overrides_of(allow_narrow, allow_motion))  # fmt: skip
    if len(names) <= 1:
        est, result, n_runs = _fit_channel(spec, loaded, signal)
        _files.save_model(est, output)
        result["output"] = str(output)
        emit(result, as_json, lambda: _human_single(est, result, n_runs, output))
        return
    fitted = _fit_channels(spec, loaded, names)
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
    out = {
        "output": str(output),
        "format": "thermocal-calibration",
        "channels": {name: {**res, "output": str(output)} for name, _e, res, _n in fitted},
    }
    emit(out, as_json, lambda: _human_channels(fitted, output))


@dataclass(frozen=True)
class _FitSpec:
    """What every channel's fit shares: the family and its options, the temperature
    columns, the known input (earth rate or given) and the target."""

    family: str
    options: dict[str, Any]
    temps: str | None
    latitude: float | None
    axis: str | None
    known_input: float | None
    target: str
    gravity_axis: str | None = None
    gravity_m_s2: float | None = None
    tref_c: float | None = None
    gravity_triad: "_gravity.TriadGravity | None" = None
    overrides: tuple[str, ...] = ()


def _local_gravity(
    gravity_axis: str | None, gravity: float | None, latitude: float | None
) -> float | None:
    """The local gravity [m/s²] for ``--gravity-axis``
    (:func:`thermocal.gravity.local_gravity_m_s2`)."""
    return _gravity.local_gravity_m_s2(gravity_axis, gravity, latitude)


def _gravity_known_input(
    spec: _FitSpec, run: int, path: Path, name: str, unit: str, values_mg: "_recording.FloatArray"
) -> "_gravity.GravityInput":
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

    est: "_base.TemperatureModel"
    runs: "list[_base.RunData]"
    first_inputs: dict[str, Any]
    provenance: list[dict[str, Any]]
    unit: str
    sig_name: str
    caught: list[Any]


def _fit_channel(
    spec: _FitSpec, loaded: "list[tuple[Path, _recording.Recording]]", signal: str | None
) -> "tuple[_base.TemperatureModel, dict[str, Any], int]":
    """Fit one channel on the loaded runs; returns the model, its ``--json`` result and
    the number of runs. Warnings are printed (by handle_errors) and listed in the result."""
    ((_n, est, result, n_runs),) = _fit_channels(spec, loaded, [signal])
    return est, result, n_runs


def _fit_channels(
    spec: _FitSpec, loaded: "list[tuple[Path, _recording.Recording]]", signals: Sequence[str | None]
) -> "list[tuple[str, _base.TemperatureModel, dict[str, Any], int]]":
    """Fit every channel on the loaded runs (each file read once, by the caller).  Channels
    of the ``poly`` family with the same temperature inputs share one design
    (:func:`thermocal.models.poly.fit_shared`: Ṫ, features and the design's reduction once;
    every model equal, bit for bit, to its own fit)."""
    preps = [_prepare_channel(spec, loaded, sig) for sig in signals]
    if spec.family == "poly" and len(preps) > 1:
        _share_inputs(preps)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            _poly.fit_shared([cast(_poly.PolyModel, p.est) for p in preps], [p.runs for p in preps])
        for p in preps:
            p.caught.extend(caught)
    else:
        for p in preps:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                p.est.fit(p.runs)
            p.caught.extend(caught)
    return [(p.sig_name, *_finish_channel(spec, p)) for p in preps]


def _share_inputs(preps: list[_Prepared]) -> None:
    """Give every channel's runs the first channel's time and temperature arrays when they
    are equal (one copy in memory, and :func:`fit_shared` sees one design)."""
    first = preps[0].runs
    for p in preps[1:]:
        for i, r in enumerate(p.runs):
            f = first[i]
            if r.temps_c is not f.temps_c and np.array_equal(r.temps_c, f.temps_c):
                p.runs[i] = dataclasses.replace(r, temps_c=f.temps_c)


def _prepare_channel(
    spec: _FitSpec, loaded: "list[tuple[Path, _recording.Recording]]", signal: str | None
) -> _Prepared:
    """One channel's runs with their known inputs, its model object and provenance."""
    est = build_model(spec.family, spec.options)
    temps, latitude, axis, known_input = spec.temps, spec.latitude, spec.axis, spec.known_input
    runs: list[_base.RunData] = []
    first_inputs: dict[str, Any] = {}
    provenance: list[dict[str, Any]] = []
    sensor_ids: list[str | None] = []
    unit = ""
    sig_name = signal or "signal"
    temp_names: tuple[str, ...] | None = None
    for path, rec in loaded:
        _values, run_unit = rec.signal(signal)
        sig_name = signal or rec.signals[0]
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
            first_inputs = _base.model_inputs(
                rec, sig_name, run_temp_names(rec, temps), known_input=ki,
                known_input_what=known_input_what(earth_lat, axis, known_input, g_in.what),
            )  # fmt: skip
            if g_in.record is not None:  # export-params reads whether it was measured
                first_inputs["known_input"]["gravity"] = g_in.record
        run = _base.RunData.from_recording(
            rec, signal, split_names(temps), known_input=ki, temperature_unit="auto"
        )
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


def _data_unit(first_inputs: dict[str, Any], sig_name: str, unit: str) -> tuple[str, float]:
    """The data's own unit of a channel (as given in the file, option or column name) and
    the factor from the model's canonical unit to it (raw counts scaled to a physical unit
    stay in the canonical unit)."""
    given = str((first_inputs.get("units") or {}).get(sig_name, unit))
    try:
        return given, float(units.convert(1.0, unit, given))
    except _errors.UnitError:
        return unit, 1.0


def _judge_channel(
    spec: _FitSpec,
    est: "_base.TemperatureModel",
    runs: "list[_base.RunData]",
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


def _finish_channel(
    spec: _FitSpec, prep: _Prepared
) -> "tuple[_base.TemperatureModel, dict[str, Any], int]":
    """After the fit: the fit-quality warnings, the model's metadata, the ``--json`` result."""
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
    messages = [one_line(str(w.message)) for w in all_caught]
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
        "condition": _base.condition_wording(kappa),
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


def _human_single(
    est: "_base.TemperatureModel", result: dict[str, Any], n_runs: int, output: Path
) -> None:
    """The fit summary and coefficient tables of one model."""
    st = est.stats_
    unit = result["unit"]
    kappa = st.condition_number
    corr: dict[str, Any] | None = st.extra.get("residual_correlation")
    trange = result["temperature_range"]
    kept = result["terms_kept"]
    tab = _rich_table.Table(title=f"{est.family} model → {output}")
    tab.add_column("quantity")
    tab.add_column("value")
    tab.add_row("runs / samples", f"{n_runs} / {st.n_samples}")
    tab.add_row("coefficients", str(st.n_coefficients))
    tab.add_row(f"rms residual [{unit}]", fmt(result["rms_residual"]))
    wording = _base.condition_wording(kappa)
    tab.add_row("condition number", f"{fmt(st.condition_number)} ({wording})")
    if corr:
        tab.add_row(
            "effective samples",
            f"{fmt(corr['n_effective'])} (residual correlation time "
            f"{fmt(corr['tau_samples'])} samples; std. errors × {corr['stderr_factor']:.3g})",
        )
    for n, (a, b) in trange.items():
        tu = "°C" if est.temperature_unit == "degC" else est.temperature_unit
        tab.add_row(f"range {n} [{tu}]", f"{a:.2f} … {b:.2f}")
    if kept is not None:
        tab.add_row("terms kept", ", ".join(kept))
    stdout.print(tab)
    ctab = _rich_table.Table(title="coefficients")
    ctab.add_column("name")
    ctab.add_column("value")
    ctab.add_column("std. error")
    ctab.add_column("|value|/s.e.")
    weak = 0
    ctab.add_column("unit")
    for c in est.coefficients():
        ratio = abs(c.value) / c.stderr if c.stderr else None
        flag = "" if ratio is None or ratio >= 2.0 else " *"
        weak += bool(flag)
        ctab.add_row(c.name, fmt(c.value, 6), fmt(c.stderr, 3), f"{fmt(ratio, 2)}{flag}", c.unit)
    stdout.print(ctab)
    if "tref" in result:
        ttab = _rich_table.Table(title=f"coefficients about TREF = {result['tref']['tref_c']:g} °C")
        for col in ("name", "value", "std. error", "unit"):
            ttab.add_column(col)
        for c in result["tref"]["coefficients"]:
            ttab.add_row(c["name"], fmt(c["value"], 6), fmt(c.get("stderr"), 3), c.get("unit", ""))
        stdout.print(ttab)
    if weak:
        stdout.print(
            f"* {weak} coefficient(s) within 2 standard errors of 0: not distinct from "
            "zero on these data (consider --select or fewer terms)"
        )


def _human_channels(
    fitted: "list[tuple[str, _base.TemperatureModel, dict[str, Any], int]]", output: Path
) -> None:
    """One row per channel: model, samples, residual, condition, range."""
    tab = _rich_table.Table(title=f"calibration of {len(fitted)} channels → {output}")
    for col in ("channel", "model", "coefficients", "rms residual", "condition", "range [°C]"):
        tab.add_column(col)
    for name, est, res, _n in fitted:
        rng = "; ".join(f"{k} {a:.1f}…{b:.1f}" for k, (a, b) in res["temperature_range"].items())
        tab.add_row(
            name,
            est.family,
            str(res["n_coefficients"]),
            f"{fmt(res['rms_residual'])} {res['unit']}",
            f"{fmt(res['condition_number'])} ({res['condition']})",
            rng,
        )
    stdout.print(tab)
