"""Judging a model or calibration on an independent recording: :func:`validate_files`
(``thermocal validate``; [Seed-RLG], :func:`thermocal.validation.validate`).

``r`` compares the ``ambient`` column of the modelling and validation runs (default: the
model's first temperature column).  The modelling run is ``options.modeling``, else the model
file's recorded data file if it still exists (:func:`modeling_file`); otherwise ``r`` is null,
with a warning.  Both files are read through :func:`thermocal.readers.read_recording`
with the same ReadOptions (time, units, temperature conversion and the text-log options: a
headerless serial log as the modelling run needs ``names`` as much as the validated one).
A calibration of triads (``thermocal turntable``, ``thermocal multipos``) is judged on a
turntable or multi-position run instead (dwell-mean and move-angle errors, held-out poses).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal.errors import (
    CorrelationWarning,
    FileFormatError,
    ParameterError,
    ThermocalInputError,
    ThermocalWarning,
    UnitWarning,
)
from thermocal.pipeline.options import ValidateOptions
from thermocal.pipeline.reading import check_recording
from thermocal.readers.formats import file_kind, format_named
from thermocal.readers.options import CHAMBER_COLUMN

if TYPE_CHECKING:
    from thermocal.models.base import TemperatureModel
    from thermocal.models.calibration import Calibration
    from thermocal.readers.options import ReadOptions
    from thermocal.recording import FloatArray, Recording
    from thermocal.validation import ValidationResult


@dataclass(frozen=True)
class ChannelValidation:
    """One channel judged: its model, the :class:`~thermocal.validation.ValidationResult`
    (in the data's own unit) and its JSON object (``figures``).

    Attributes
    ----------
    name : str
        The channel.
    model : TemperatureModel
        Its model.
    result : ValidationResult
        The validation, in the data's own unit.
    figures : dict
        Its JSON object.
    """

    name: str
    model: TemperatureModel
    result: ValidationResult
    figures: dict[str, Any]


@dataclass(frozen=True)
class ValidationReport:
    """What :func:`validate_files` found: per channel (``several``: a calibration of several
    channels), or per triad (``triads``: a calibration of triads on a turntable run).

    Attributes
    ----------
    model_file : Path
        The model or calibration file.
    file : Path
        The validation run.
    channels : tuple of ChannelValidation
        Each channel.
    several : bool
        A calibration of several channels.
    triads : tuple
        Each triad's judgement (a calibration of triads).
    """

    model_file: Path
    file: Path
    channels: tuple[ChannelValidation, ...] = ()
    several: bool = False
    triads: tuple[Any, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The ``validate`` command's JSON: one channel's figures; ``{"channels": {name:
        figures}}`` for several; ``{"model", "file", "family": "triads", "triads"}``."""
        if self.triads:
            return {
                "model": str(self.model_file),
                "file": str(self.file),
                "family": "triads",
                "triads": {r.triad: r.to_dict() for r in self.triads},
            }
        if self.several:
            return {
                "channels": {
                    c.name: {**c.figures, "verdict": c.result.verdict} for c in self.channels
                }
            }
        return self.channels[0].figures


def modeling_file(model: TemperatureModel, model_file: Path) -> Path | None:
    """The first data file recorded in the model file that still exists: its name, then
    the path given to fit (relative ones tried from the current directory and from the
    model file's directory).

    Parameters
    ----------
    model : TemperatureModel
        The fitted model (its recorded data files).
    model_file : Path
        The model file, whose directory relative paths are also tried from.

    Returns
    -------
    Path or None
        The data file found, or ``None``.
    """
    for entry in model.data_:
        if not isinstance(entry, dict):
            continue
        for key in ("file", "path"):  # the name, then the path given to fit
            name = entry.get(key)
            if not name:
                continue
            p = Path(str(name))
            for cand in (p, model_file.parent / p) if not p.is_absolute() else (p,):
                if cand.is_file():
                    return cand
    return None


def ambient_c(rec: Recording, name: str) -> FloatArray:
    """The ambient temperature [°C] for r and the hold stages; raw counts with no
    conversion are used as counts, with a warning (the hold threshold is then per count).

    Parameters
    ----------
    rec : Recording
        The validation recording.
    name : str
        The ambient temperature column.

    Returns
    -------
    numpy.ndarray
        The ambient temperature [°C], or raw counts when no conversion is recorded.

    Warns
    -----
    UnitWarning
        When the column is in raw counts with no conversion.
    """
    if rec.units.get(name) == "counts" and name not in rec.meta.temperature_conversion:
        warnings.warn(
            UnitWarning.naming(
                f"{rec.name}: the ambient column {name!r} is in raw counts with no conversion: "
                "hold stages are found with {stage_rate} in counts/min",
                "stage_rate",
            ),
            stacklevel=2,
        )
        return rec.column(name)
    return rec.temperature_c(name)


@dataclass
class _Context:
    """What every channel's validation shares: the files, options, and the modelling runs
    read so far (one read per file and ambient column)."""

    model_file: Path
    file: Path
    o: ValidateOptions
    read: ReadOptions
    modeling: dict[Path, Recording]


def _modeling_ambient(
    ctx: _Context, model: TemperatureModel, amb: str
) -> tuple[Path | None, tuple[FloatArray, FloatArray] | None]:
    """The modelling run's file and ``(time_s, ambient)``, read with the validated file's
    options (None when there is no modelling run)."""
    from thermocal import recording

    o = ctx.o
    mod_path = o.modeling if o.modeling is not None else modeling_file(model, ctx.model_file)
    if mod_path is None:
        return None, None
    mrec = ctx.modeling.get(mod_path)
    if mrec is None or amb not in mrec.columns:
        from thermocal.readers.dispatch import read_recording

        read = ctx.read.replace(
            signals=None, temperatures=(amb,), signal_unit=None,
            topic=o.topic if _is_log(mod_path) else None,
        )  # fmt: skip
        if read.chamber_log is not None and Path(mod_path) != Path(ctx.file):
            if amb == CHAMBER_COLUMN:  # the chamber log is the validated run's, not this one's
                warnings.warn(
                    CorrelationWarning(
                        f"{mod_path}: the modelling run has no chamber log: r of the ambient "
                        "histories not computed"
                    ),
                    stacklevel=2,
                )
                return None, None
            read = read.replace(chamber_log=None)
        mrec = read_recording(mod_path, read, model=model)
        for prob in recording.find_problems(mrec, required=[amb]):
            if prob.severity == "error" and (prob.column in (None, "time", amb)):
                raise ThermocalInputError.naming(f"{mod_path}: {prob.message}", *prob.parameters)
        ctx.modeling[mod_path] = mrec
    return mod_path, (mrec.time_s, ambient_c(mrec, amb))


def _is_log(path: Path) -> bool:
    """A flight-controller log (``.ulg``, ``.bin``), which ``topic`` applies to; a station
    folder, a CSV or Parquet file is not (and a name no reader accepts is said by the reader)."""
    try:
        return "topic" in format_named(file_kind(path)).options
    except FileFormatError:
        return False


def _validate_channel(
    ctx: _Context, model: TemperatureModel, sig: str, rec: Recording | None = None
) -> tuple[ValidationResult, dict[str, Any]]:
    """Validate one model on its signal column; (result, JSON object).  ``rec``: the
    file already read (several channels: once for all of them)."""
    from thermocal import validation
    from thermocal.compensate import kernels as compensate

    o = ctx.o
    temps = list(model.temp_names_)
    amb = o.ambient or temps[0]
    read_temps = temps if amb in temps else [*temps, amb]
    if rec is None:
        from thermocal.readers.dispatch import read_recording

        read = ctx.read.replace(signals=(sig,), temperatures=tuple(read_temps))
        rec = check_recording(read_recording(ctx.file, read, model=model), read)
    # the data in the model's units (kinds checked); figures go back to the data's unit
    prepared = compensate.prepare_run(model, rec, sig, temps)
    counts = prepared.data_unit == "counts"  # raw counts: figures in K's physical unit
    amb_val = ambient_c(rec, amb)
    mod_path, modeling_ambient = _modeling_ambient(ctx, model, amb)
    res = validation.validate(
        model,
        prepared.run,
        modeling_ambient,
        validation_ambient=amb_val,
        averaging_s=o.averaging,
        rate_threshold_c_per_min=o.stage_rate,
        min_stage_s=o.min_stage,
        settle_s=o.settle,
        extrapolate=o.extrapolate,
        zero_reference=compensate.zero_reference(model, rec.meta),
        display_unit=None if counts else (prepared.data_unit, prepared.factor),
    )
    if not counts:
        res = res.in_unit(prepared.data_unit, prepared.factor)
    out = res.to_dict()
    out["model_unit"] = model.signal_unit
    out["model"] = str(ctx.model_file)
    out["family"] = model.family
    out["file"] = str(ctx.file)
    out["modeling_file"] = str(mod_path) if mod_path is not None else None
    out["ambient"] = amb
    return res, out


def _validate_channels(ctx: _Context, cal: Calibration) -> ValidationReport:
    """A calibration of several channels: the file read once with every chosen channel's
    column, each channel judged on it."""
    from thermocal.models.calibration_inputs import merged_inputs, temperatures_of

    o = ctx.o
    chosen = list(o.signals or ()) or cal.names
    missing = [n for n in chosen if n not in cal.names]
    if missing:
        raise ThermocalInputError(
            f"{ctx.model_file}: no channel {', '.join(map(repr, missing))}; it has "
            + ", ".join(cal.names)
        )
    read_temps = temperatures_of(cal, chosen)
    if o.ambient and o.ambient not in read_temps:
        read_temps.append(o.ambient)
    from thermocal.readers.dispatch import read_recording

    read = ctx.read.replace(
        signals=tuple(cal.channel(n).signal for n in chosen), temperatures=tuple(read_temps)
    )
    rec_all = check_recording(
        read_recording(ctx.file, read, model=merged_inputs(cal, chosen)), read
    )
    per = []
    for n in chosen:
        ch = cal.channel(n)
        res, out = _validate_channel(ctx, ch.model, ch.signal, rec_all)
        per.append(ChannelValidation(n, ch.model, res, out))
    return ValidationReport(ctx.model_file, ctx.file, tuple(per), several=True)


def _own_session(cal: Calibration, file: Path) -> None:
    """A warning when ``file`` is a session the triads were calibrated on (its SHA-256
    among their ``data``): its figures are the fit's residuals, not an independent test."""
    from thermocal.pipeline.model_file import file_sha256

    known = {d.get("sha256") for t in cal.triads for d in t.data}
    if known and file_sha256(file) in known:
        warnings.warn(
            ThermocalWarning(
                f"{file}: this is the session the calibration was fitted on: its figures are "
                "the fit's residuals, not an independent test (validate on a held-out session)"
            ),
            stacklevel=2,
        )


def judge_triads(
    triads: Any,
    rec: Recording,
    latitude_deg: float | None,
    *,
    static_s: float = 1.0,
    signal_unit: str | tuple[str, ...] | None = None,
) -> list[Any]:
    """Triads of a calibration judged on a recording: on held-out poses when the calibration
    is a multi-position one, else as a turntable run.

    Parameters
    ----------
    triads : sequence
        The calibration's triads.
    rec : Recording
        The recording, read with the triads' columns.
    latitude_deg : float or None
        Latitude [°] (None: the recording's metadata).
    static_s : float
        Shortest still stretch [s] of a held-out pose.
    signal_unit : str or tuple of str, optional
        The gyro's unit when the file does not state it.

    Returns
    -------
    list
        One result per triad (:func:`thermocal.multipos.validate.validate_held_out_session`
        or :func:`thermocal.turntable.calibration.validate_turntable_run`).
    """
    from thermocal.multipos import validate as _mp_validate
    from thermocal.turntable.calibration import validate_turntable_run

    if _mp_validate.is_multipos(triads):  # held-out poses
        return list(
            _mp_validate.validate_held_out_session(
                triads, rec, latitude_deg, static_s=static_s, signal_unit=signal_unit
            )
        )
    return list(validate_turntable_run(triads, rec, latitude_deg))


def _validate_triads(
    cal: Calibration, model_file: Path, file: Path, o: ValidateOptions
) -> ValidationReport:
    """A calibration of triads judged on a turntable run, or on held-out poses
    of a multi-position calibration; a warning per triad for the share of samples
    outside its calibrated temperature range."""
    from thermocal.pipeline.compensate import read_for_triads

    rec = read_for_triads(file, cal.triads, o.read_options)
    _own_session(cal, file)
    if o.signal_unit is not None and not isinstance(o.signal_unit, str):
        raise ParameterError(
            "signal_unit", f"{{name}} takes one unit for a triad calibration, got {o.signal_unit}"
        )
    results = judge_triads(
        cal.triads, rec, o.latitude, static_s=o.static_s, signal_unit=o.read_options.signal_unit
    )
    for r in results:
        if r.outside_range_fraction > 0:
            warnings.warn(
                UnitWarning(
                    f"{file}: {100 * r.outside_range_fraction:.3g} % of the samples are outside "
                    f"the {r.triad} triad's calibrated temperature range"
                ),
                stacklevel=1,
            )
    return ValidationReport(model_file, file, triads=tuple(results))


def validate_files(
    calibration: str | Path, file: str | Path, options: ValidateOptions | None = None
) -> ValidationReport:
    """Judge the model or calibration file ``calibration`` on the recording ``file`` (module
    docstring): correlation r, bias stability and repeatability over the hold stages, rms and
    peak-to-peak, before and after compensation, in the data's own unit
    (:func:`thermocal.validation.validate`); triads: dwell-mean and move-angle errors.

    Parameters
    ----------
    calibration : str or Path
        A model or calibration file.
    file : str or Path
        The validation recording.
    options : ValidateOptions or None, optional
        Columns, stage detection and read options (default ``None``: the defaults).

    Returns
    -------
    ValidationReport
        The figures before and after compensation.

    Raises
    ------
    ThermocalInputError
        When a file cannot be read or does not match the model's columns.
    ModelFileError
        When the model or calibration file fails verification.

    References
    ----------
    - *A modelling and validation method for the temperature compensation model of a
      ring-laser gyroscope*, Chinese invention patent, published 2017.
    """
    from thermocal.pipeline.model_file import load_calibration

    o = options if options is not None else ValidateOptions()
    calibration, file = Path(calibration), Path(file)
    pre = load_calibration(calibration)
    if pre.triads and not pre.channels:
        return _validate_triads(pre, calibration, file, o)
    ctx = _Context(calibration, file, o, o.read_options, {})
    cal = load_calibration(calibration)  # a model file is a calibration of one channel
    cal.require_channels("validate")
    if len(cal.channels) > 1:
        return _validate_channels(ctx, cal)
    model = cal.channels[0].model
    signal = ",".join(o.signals) if o.signals else model.signal_name  # one column
    res, out = _validate_channel(ctx, model, signal)
    return ValidationReport(
        calibration, file, (ChannelValidation(model.signal_name, model, res, out),)
    )


__all__ = [
    "ChannelValidation",
    "ValidationReport",
    "ambient_c",
    "judge_triads",
    "modeling_file",
    "validate_files",
]
