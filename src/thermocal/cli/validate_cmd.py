"""``thermocal validate MODEL.json FILE [--modeling FILE] [--ambient COL]``.

Judges a model on an independent, weakly correlated test (SPEC §5,
:func:`thermocal.validation.validate`).  ``r`` compares the ``--ambient`` column
of the modelling and validation runs (default: the model's first temperature
column).  Without ``--modeling`` the model file's recorded data file is used if
it still exists; otherwise ``r`` is null, with a warning.
"""

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    DecimalOpt,
    DelimiterOpt,
    ExtrapolateOpt,
    FileArg,
    JsonOpt,
    ModelArg,
    ModelSignalOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalUnitOpt,
    TempConversionOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TurntableLatitudeOpt,
    emit,
    fmt,
    handle_errors,
    load_recording,
    split_names,
    stdout,
    text_options,
)
from thermocal.errors import ThermocalInputError, UnitWarning

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.compensate.files as _compensate
    import thermocal.models.base as _base
    import thermocal.models.calibration as _calibration
    import thermocal.models.files as _files
    import thermocal.recording as _recording
    import thermocal.validation as _validation
else:
    _rich_table = LazyModule("rich.table")
    _compensate = LazyModule("thermocal.compensate.files")
    _base = LazyModule("thermocal.models.base")
    _calibration = LazyModule("thermocal.models.calibration")
    _files = LazyModule("thermocal.models.files")
    _recording = LazyModule("thermocal.recording")
    _validation = LazyModule("thermocal.validation")


def _modeling_file(model: "_base.TemperatureModel", model_file: Path) -> Path | None:
    """The first data file recorded in the model file that still exists: its name, then
    the path given to fit (relative ones tried from the current directory and from the
    model file's directory)."""
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


def _ambient(rec: "_recording.Recording", name: str) -> "_recording.FloatArray":
    """The ambient temperature [°C] for r and the hold stages; raw counts with no
    conversion are used as counts, with a warning (the hold threshold is then per count)."""
    if rec.units.get(name) == "counts" and name not in rec.meta.temperature_conversion:
        warnings.warn(
            UnitWarning(
                f"{rec.name}: the ambient column {name!r} is in raw counts with no conversion: "
                "hold stages are found with --stage-rate in counts/min"
            ),
            stacklevel=2,
        )
        return rec.column(name)
    return rec.temperature_c(name)


def _emit_channels(file: Path, per: dict[str, tuple[Any, dict[str, Any]]], as_json: bool) -> None:
    """Several channels: ``{"channels": {NAME: {…}}}`` and one verdict per channel."""

    def human() -> None:
        table = _rich_table.Table(title=f"validation on {file}, {len(per)} channels")
        for col in ("channel", "r", "bias stability before → after", "rms before → after",
                    "mean before → after", "rms about zero before → after", "unit",
                    "verdict"):  # fmt: skip
            table.add_column(col)
        for name, (res, out) in per.items():
            table.add_row(
                name,
                fmt(res.r, 3),
                f"{fmt(res.bias_stability_before)} → {fmt(res.bias_stability_after)}",
                f"{fmt(res.rms_before)} → {fmt(res.rms_after)}",
                f"{fmt(out['mean_before'])} → {fmt(out['mean_after'])}",
                f"{fmt(out['rms_about_zero_before'])} → {fmt(out['rms_about_zero_after'])}",
                res.unit,
                res.verdict_line,
            )
        stdout.print(table)

    emit(
        {"channels": {n: {**out, "verdict": res.verdict} for n, (res, out) in per.items()}},
        as_json,
        human,
    )


@app.command("validate")
@handle_errors
def validate_cmd(
    model_file: ModelArg,
    file: FileArg,
    modeling: Annotated[
        Path | None,
        typer.Option(
            "--modeling",
            help="The modelling test's recording (default: the model file's data file).",
        ),
    ] = None,
    ambient: Annotated[
        str | None,
        typer.Option(
            "--ambient",
            help="Temperature column compared by r and used to find the hold stages "
            "(default: the model's first temperature column).",
        ),
    ] = None,
    averaging: Annotated[
        float, typer.Option("--average", "--averaging", help="Averaging time [s].")
    ] = defaults.DEFAULT_AVERAGING_S,
    signal: ModelSignalOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    stage_rate: Annotated[
        float,
        typer.Option("--stage-rate", help="Hold detection: |dT/dt| below this [°C/min]."),
    ] = 0.05,
    min_stage: Annotated[
        float, typer.Option("--min-stage", help="Hold detection: shortest stage [s].")
    ] = 600.0,
    settle: Annotated[
        float, typer.Option("--settle", help="Seconds cut from the start of each stage.")
    ] = 0.0,
    extrapolate: ExtrapolateOpt = False,
    t_names: NamesOpt = None,
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    latitude: TurntableLatitudeOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Validate MODEL on FILE: correlation r, bias stability and repeatability over the
    hold stages, rms and peak-to-peak, before and after compensation; a calibration of
    triads (thermocal turntable over temperature) on a turntable run: dwell-mean and
    move-angle errors before and after."""
    pre = _files.load_calibration(model_file)
    if pre.triads and not pre.channels:
        _validate_triads(pre, model_file, file, time, time_unit, latitude, as_json)
        return

    modeling_cache: dict[Path, _recording.Recording] = {}

    def run_one(
        model: "_base.TemperatureModel", sig: str, rec: "_recording.Recording | None" = None
    ) -> tuple[Any, dict[str, Any]]:
        """Validate one model on its signal column; (result, --json object).  ``rec``: the
        file already read (several channels: once for all of them)."""
        temps = list(model.temp_names_)
        amb = ambient or temps[0]
        read_temps = temps if amb in temps else [*temps, amb]
        if rec is None:
            rec = load_recording(
                file,
                time=time,
                time_unit=time_unit,
                signal=sig,
                temps=",".join(read_temps),
                signal_unit=signal_unit,
                temp_unit=temp_unit,
                temp_conversion=temp_conversion,
                model=model,
                text=text_options(t_names, t_rate, t_bad, t_delim, t_dec),
            )
        # the data in the model's units (kinds checked); figures go back to the data's unit
        prepared = _compensate.prepare_run(model, rec, sig, temps)
        run = prepared.run
        counts = prepared.data_unit == "counts"  # raw counts: figures in K's physical unit
        amb_val = _ambient(rec, amb)

        mod_path = modeling if modeling is not None else _modeling_file(model, model_file)
        modeling_ambient = None
        if mod_path is not None:
            mrec = modeling_cache.get(mod_path)
            if mrec is None or amb not in mrec.columns:
                mrec = load_recording(
                    mod_path,
                    time=time,
                    time_unit=time_unit,
                    temps=amb,
                    temp_unit=temp_unit,
                    temp_conversion=temp_conversion,
                    model=model,
                    require_signal=False,
                    check=False,
                )
                for prob in _recording.find_problems(mrec, required=[amb]):
                    if prob.severity == "error" and (prob.column in (None, "time", amb)):
                        raise ThermocalInputError(f"{mod_path}: {prob.message}")
                modeling_cache[mod_path] = mrec
            modeling_ambient = (mrec.time_s, _ambient(mrec, amb))
        res = _validation.validate(
            model,
            run,
            modeling_ambient,
            validation_ambient=amb_val,
            averaging_s=averaging,
            rate_threshold_c_per_min=stage_rate,
            min_stage_s=min_stage,
            settle_s=settle,
            extrapolate=extrapolate,
            zero_reference=_compensate.zero_reference(model, rec.meta),
            display_unit=None if counts else (prepared.data_unit, prepared.factor),
        )
        if not counts:
            res = res.in_unit(prepared.data_unit, prepared.factor)
        out = res.to_dict()
        out["model_unit"] = model.signal_unit
        out["model"] = str(model_file)
        out["family"] = model.family
        out["file"] = str(file)
        out["modeling_file"] = str(mod_path) if mod_path is not None else None
        out["ambient"] = amb
        return res, out

    cal = _files.load_calibration(model_file)  # a model file is a calibration of one channel
    cal.require_channels("validate")
    if len(cal.channels) > 1:
        from thermocal.models.calibration import merged_inputs, temperatures_of

        chosen = split_names(signal) or cal.names
        missing = [n for n in chosen if n not in cal.names]
        if missing:
            raise ThermocalInputError(
                f"{model_file}: no channel {', '.join(map(repr, missing))}; it has "
                + ", ".join(cal.names)
            )
        read_temps = temperatures_of(cal, chosen)
        if ambient and ambient not in read_temps:
            read_temps.append(ambient)
        # the file read once, every chosen channel's column (issue 15)
        rec_all = load_recording(
            file,
            time=time,
            time_unit=time_unit,
            signal=",".join(cal.channel(n).signal for n in chosen),
            temps=",".join(read_temps),
            signal_unit=signal_unit,
            temp_unit=temp_unit,
            temp_conversion=temp_conversion,
            model_inputs=merged_inputs(cal, chosen),
            text=text_options(t_names, t_rate, t_bad, t_delim, t_dec),
        )
        per = {n: run_one(cal.channel(n).model, cal.channel(n).signal, rec_all) for n in chosen}
        _emit_channels(file, per, as_json)
        return
    model = cal.channels[0].model
    res, out = run_one(model, signal or model.signal_name)

    def human() -> None:
        u = res.unit
        if res.r is None:
            head = "r not computed (no modelling data)"
        else:
            weak = "weakly correlated" if res.weakly_correlated else "NOT weakly correlated"
            head = f"r = {fmt(res.r, 3)} ({weak})"

        table = _rich_table.Table(title=f"validation of {model.family} model on {file}: {head}")
        table.add_column("figure")
        table.add_column(f"before [{u}]", justify="right")
        table.add_column(f"after [{u}]", justify="right")
        table.add_column("improvement", justify="right")
        imp = res.improvement_pct
        for key, label in (
            ("bias_stability", f"bias stability ({res.averaging_s:g} s, rms over stages)"),
            ("bias_repeatability", "bias repeatability"),
            ("rms", "rms"),
            ("peak_to_peak", "peak-to-peak"),
        ):
            pct = imp[key]
            table.add_row(
                label,
                fmt(getattr(res, f"{key}_before")),
                fmt(getattr(res, f"{key}_after")),
                "—" if pct is None else f"{pct:.1f} %",
            )
        for key, label in (
            ("mean", "mean (about zero)"),
            ("rms_about_zero", "rms about zero"),
            ("max_abs", "max |error|"),
        ):
            b, a = out[f"{key}_before"], out[f"{key}_after"]
            pct = 100.0 * (abs(b) - abs(a)) / abs(b) if b and a is not None else None
            table.add_row(
                label, fmt(b), fmt(a), "—" if pct is None else f"{pct:.1f} %"
            )  # fmt: skip
        stdout.print(table)
        stdout.print(
            f"zero = {fmt(res.zero_reference)} {u}: {res.zero_reference_what}; the figures "
            "about the mean ignore a constant offset, those about zero do not"
        )
        stdout.print(f"verdict: {res.verdict_line}")

    emit(out, as_json, human)


def _validate_triads(
    cal: "_calibration.Calibration",
    model_file: Path,
    file: Path,
    time: str | None,
    time_unit: str | None,
    latitude: float | None,
    as_json: bool,
) -> None:
    """A calibration of triads judged on a turntable run (issue 19)."""
    from thermocal.compensate.files import read_for_triads
    from thermocal.multipos import validate as _mp_validate
    from thermocal.turntable.calibrate import validate_triads

    rec = read_for_triads(file, cal.triads, time=time, time_unit=time_unit)
    if _mp_validate.is_multipos(cal.triads):  # held-out poses (issue 30)
        results: list[Any] = _mp_validate.validate_triads(cal.triads, rec, latitude)
    else:
        results = validate_triads(cal.triads, rec, latitude)
    for r in results:
        if r.outside_range_fraction > 0:
            warnings.warn(
                UnitWarning(
                    f"{file}: {100 * r.outside_range_fraction:.3g} % of the samples are outside "
                    f"the {r.triad} triad's calibrated temperature range"
                ),
                stacklevel=1,
            )
    out = {
        "model": str(model_file),
        "file": str(file),
        "family": "triads",
        "triads": {r.triad: r.to_dict() for r in results},
    }

    def human() -> None:
        table = _rich_table.Table(title=f"{model_file} on {file}")
        for col in ("triad", "figure", "x before → after", "y before → after", "z before → after"):
            table.add_column(col)
        for r in results:
            for label, before, after in r.rows():
                cells = [f"{fmt(b)} → {fmt(a)}" for b, a in zip(before, after, strict=True)]
                table.add_row(r.triad, label, *cells)
        stdout.print(table)

    emit(out, as_json, human)
