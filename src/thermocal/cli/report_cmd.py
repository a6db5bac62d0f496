"""``thermocal report --model M.json --validation V.json --recording VAL.csv -o report.html``.

Builds the self-contained HTML report (:func:`thermocal.report.write_report`)
from the files the other commands write: one or more model files (``thermocal
fit``), their validation results (``thermocal validate --json``, in the same
order as the models) and the validation recording, optionally the modelling
recording.  The first model is reported in detail; the others appear in the
comparison table.
"""

import functools
import json
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    DecimalOpt,
    DelimiterOpt,
    ModelSignalOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalUnitOpt,
    TempConversionOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    TurntableLatitudeOpt,
    handle_errors,
    load_recording,
    progress,
    split_names,
    stderr,
    text_options,
)
from thermocal.errors import FileFormatError, ThermocalInputError, ThermocalWarning

if TYPE_CHECKING:
    import thermocal.models.calibration as _calibration
    import thermocal.models.files as _files
    import thermocal.recording as _recording
    import thermocal.report as _report
    import thermocal.writers as _writers
else:
    _writers = LazyModule("thermocal.writers")
    _calibration = LazyModule("thermocal.models.calibration")
    _files = LazyModule("thermocal.models.files")
    _recording = LazyModule("thermocal.recording")
    _report = LazyModule("thermocal.report")


def read_validation_json(path: Path, *, channels: bool = False) -> dict[str, Any]:
    """A validation result file (``thermocal validate --json`` output) as a dict; with
    ``channels`` also the several-channel form ``{"channels": {NAME: {…}}}``."""
    try:
        obj = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ThermocalInputError(f"{path}: no such validation file") from None
    except (ValueError, UnicodeDecodeError) as exc:  # JSONDecodeError, a 5000-digit integer
        raise FileFormatError(f"{path}: not a JSON validation result ({exc})") from None
    except RecursionError:
        raise FileFormatError(f"{path}: not a validation result (nested too deeply)") from None
    if channels and isinstance(obj, dict) and isinstance(obj.get("channels"), dict):
        return obj
    if not isinstance(obj, dict) or "bias_stability_before" not in obj:
        raise FileFormatError(
            f"{path}: not a validation result (expected the JSON object of "
            "`thermocal validate --json`, with bias_stability_before, ...)"
        )
    return obj


def _read_run(
    path: Path,
    signal: str,
    *,
    time: str | None,
    time_unit: str | None,
    signal_unit: str | None,
    temp_unit: str | None,
    model_inputs: dict[str, Any] | None = None,
    temp_conversion: str | None = None,
    temps: list[str] | None = None,
    text: Any = None,
    topic: str | None = None,
) -> "_recording.Recording":
    return load_recording(
        path,
        time=time,
        time_unit=time_unit,
        signal=signal,
        temps=",".join(temps) if temps else None,
        signal_unit=signal_unit,
        temp_unit=temp_unit,
        model_inputs=model_inputs,
        temp_conversion=temp_conversion,
        text=text,
        topic=topic,
    )


@app.command("report")
@handle_errors
def report_cmd(
    model: Annotated[
        list[Path],
        typer.Option("--model", help="Model file (repeat for several; the first is detailed)."),
    ],
    recording: Annotated[
        Path, typer.Option("--recording", help="The validation run's recording (CSV/Parquet).")
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="The HTML file to write.")],
    validation: Annotated[
        list[Path] | None,
        typer.Option(
            "--validation",
            help="`thermocal validate --json` output, one per --model, in the same order.",
        ),
    ] = None,
    modeling: Annotated[
        Path | None, typer.Option("--modeling", help="The modelling run's recording.")
    ] = None,
    signal: ModelSignalOpt = None,
    label: Annotated[
        list[str] | None,
        typer.Option("--label", help="Short name of each model (default: the file stem)."),
    ] = None,
    title: Annotated[
        str, typer.Option("--title", help="Report title.")
    ] = "Temperature compensation report",
    sensor: Annotated[
        str | None, typer.Option("--sensor", help="Sensor name or serial number.")
    ] = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    averaging: Annotated[
        float | None,
        typer.Option(
            "--average",
            "--averaging",
            help="Averaging time [s] of bias stability and peak-to-peak (default: the "
            "validation result's, else 100 s).",
        ),
    ] = None,
    topic: TopicOpt = None,
    t_names: NamesOpt = None,
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    latitude: TurntableLatitudeOpt = None,
) -> None:
    """Write a self-contained HTML report (figures embedded, no network needed).

    Every model given is shown (fit, range of validity, coefficients); a PASS/ATTENTION
    verdict is stated only from a validation result given with --validation.
    """
    validations = list(validation or [])
    labels = list(label or [])
    if validations and len(validations) != len(model):
        raise ThermocalInputError(
            f"{len(validations)} --validation files for {len(model)} --model files; "
            "give one validation per model, in the same order"
        )
    if labels and len(labels) != len(model):
        raise ThermocalInputError(f"{len(labels)} --label values for {len(model)} --model files")
    inputs_files: list[str | Path] = [*model, *validations, recording]
    if modeling is not None:
        inputs_files.append(modeling)
    _writers.check_not_input(output, inputs_files)
    cal = _files.load_calibration(model[0])
    if cal.triads and not cal.channels:  # a turntable calibration over temperature
        from thermocal.compensate.files import read_for_triads
        from thermocal.multipos import validate as _mp_validate
        from thermocal.report.triads import write_triad_report
        from thermocal.turntable.calibrate import validate_triads

        rec = read_for_triads(recording, cal.triads, time=time, time_unit=time_unit)
        if _mp_validate.is_multipos(cal.triads):  # held-out poses (issue 30)
            results: list[Any] = _mp_validate.validate_triads(cal.triads, rec, latitude)
        else:
            results = validate_triads(cal.triads, rec, latitude)
        path = write_triad_report(output, cal, model[0], results, recording)
        stderr.print(f"report: {path}")
        return
    cal.require_channels("report")
    if len(cal.channels) > 1 or len(split_names(signal) or []) > 1:
        if len(model) > 1:
            raise ThermocalInputError(
                f"{model[0]} is a calibration of {len(cal.channels)} channels: give it as the "
                "only --model (compare calibrations in separate reports)"
            )
        _calibration_report(
            cal, model[0], recording, output,
            validation=validations[0] if validations else None, modeling=modeling,
            signal=signal, title=title, sensor=sensor, time=time, time_unit=time_unit,
            signal_unit=signal_unit, temp_unit=temp_unit, temp_conversion=temp_conversion,
            averaging=averaging, text=text_options(t_names, t_rate, t_bad, t_delim, t_dec),
            topic=topic,
        )  # fmt: skip
        return

    with progress("building report", total=3) as advance:
        entries = []
        for i, mpath in enumerate(model):
            mdict = _files.load_model_dict(mpath)
            vdict = read_validation_json(validations[i]) if validations else None
            lab = labels[i] if labels else mpath.stem
            entries.append(_report.ModelEntry(lab, mdict, vdict, str(mpath)))
        if len({e.label for e in entries}) != len(entries):
            raise ThermocalInputError(
                "two models have the same label (file stem); name them with --label"
            )
        sig = signal or (entries[0].model.get("signal") or {}).get("name") or None
        if not sig:
            raise ThermocalInputError("name the signal column with --signal")
        fitted = dict(entries[0].model.get("inputs") or {})  # how the first model's data were
        # the temperature columns every model uses, in the first model's order
        temp_cols: list[str] = []
        for e in entries:
            for c in e.model.get("temperatures") or []:
                if c not in temp_cols:
                    temp_cols.append(str(c))
        read = functools.partial(
            _read_run, time=time, time_unit=time_unit, signal_unit=signal_unit,
            temp_unit=temp_unit, model_inputs=fitted, temp_conversion=temp_conversion,
            temps=temp_cols,
        )  # fmt: skip
        text = text_options(t_names, t_rate, t_bad, t_delim, t_dec)
        # what thermocal warns while reading the runs goes into the report too (issue 25)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            val_rec = read(recording, sig, text=text, topic=topic)
            mod_rec = read(modeling, sig) if modeling is not None else None
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        read_warnings = tuple(
            " ".join(str(w.message).split())
            for w in caught
            if issubclass(w.category, ThermocalWarning)
        )
        advance(1)
        inputs = _report.ReportInputs(
            models=tuple(entries),
            recording=val_rec,
            modeling=mod_rec,
            signal=sig,
            recording_path=str(recording),
            modeling_path=str(modeling) if modeling is not None else None,
            title=title,
            sensor=sensor,
            generated_by="thermocal report",
            averaging_s=averaging,
            warnings_caught=read_warnings,
        )
        advance(1)
        path = _report.write_report(output, inputs)
        advance(1)
    stderr.print(f"report written to [bold]{path}[/bold]")


def _calibration_report(
    cal: "_calibration.Calibration",
    cal_path: Path,
    recording: Path,
    output: Path,
    *,
    validation: Path | None,
    modeling: Path | None,
    signal: str | None,
    title: str,
    sensor: str | None,
    time: str | None,
    time_unit: str | None,
    signal_unit: str | None,
    temp_unit: str | None,
    temp_conversion: str | None,
    averaging: float | None,
    text: Any = None,
    topic: str | None = None,
) -> None:
    """A calibration's report: the recording read once for every chosen channel
    (:func:`thermocal.report.calibration.build_calibration_report`)."""
    from thermocal.models.calibration import merged_inputs, temperatures_of
    from thermocal.report.calibration import CalibrationReportInputs, write_calibration_report

    names = split_names(signal) or cal.names
    missing = [n for n in names if n not in cal.names]
    if missing:
        raise ThermocalInputError(
            f"{cal_path}: no channel {', '.join(map(repr, missing))}; it has "
            + ", ".join(cal.names)
        )
    with progress("building calibration report", total=2) as advance:
        vdict = read_validation_json(validation, channels=True) if validation else None
        rec = load_recording(
            recording,
            time=time,
            time_unit=time_unit,
            signal=",".join(cal.channel(n).signal for n in names),
            temps=",".join(temperatures_of(cal, names)),
            signal_unit=signal_unit,
            temp_unit=temp_unit,
            temp_conversion=temp_conversion,
            model_inputs=merged_inputs(cal, names),
            text=text,
            topic=topic,
        )
        advance(1)
        default_title = title == "Temperature compensation report"
        path = write_calibration_report(
            output,
            CalibrationReportInputs(
                calibration=cal,
                recording=rec,
                recording_path=str(recording),
                modeling_path=str(modeling) if modeling is not None else None,
                calibration_path=str(cal_path),
                validation=vdict,
                validation_path=str(validation) if validation is not None else None,
                title="Calibration report" if default_title else title,
                sensor=sensor,
                averaging_s=averaging,
                channels=names,
            ),
        )
        advance(1)
    stderr.print(f"report written to [bold]{path}[/bold]")
