"""``thermocal report``: the HTML report of a model, calibration or turntable calibration
from the files the other commands write (:mod:`thermocal.report`).

:func:`make_report` reads the model files, the validation results and the recordings
(every recording through :func:`thermocal.readers.read_recording` with the same text-log
options and the log topic), chooses the report (models compared, one calibration of
channels, or a calibration of triads judged on the recording) and writes it atomically.
"""

from __future__ import annotations

import contextlib
import json
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal.errors import FileFormatError, ThermocalInputError, ThermocalWarning
from thermocal.pipeline.messages import warning_text
from thermocal.pipeline.reading import split_names

if TYPE_CHECKING:
    from contextlib import AbstractContextManager

    from thermocal.models.calibration import Calibration
    from thermocal.readers.options import ReadOptions
    from thermocal.recording import Recording

    Progress = Callable[[str, float | None], AbstractContextManager[Callable[[float], None]]]
    """``progress(description, total)`` → a context yielding ``advance(amount)``."""

DEFAULT_TITLE = "Temperature compensation report"


@contextlib.contextmanager
def _no_progress(
    _description: str, _total: float | None = None
) -> Iterator[Callable[[float], None]]:
    yield lambda _amount: None


def read_validation_json(path: Path, *, channels: bool = False) -> dict[str, Any]:
    """A validation result file (the ``validate`` command's JSON) as a dict; with
    ``channels`` also the several-channel form ``{"channels": {NAME: {…}}}``.

    Parameters
    ----------
    path : pathlib.Path
        The ``validate`` command's JSON.
    channels : bool
        Expect a calibration's per-channel result.

    Returns
    -------
    dict

    Raises
    ------
    ThermocalInputError
        Not a validation result.
    """
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
            "`thermocal validate --json`, with bias_stability_before, ...)"  # cli-words: its writer
        )
    return obj


def read_run(
    path: Path, signals: str, temps: Sequence[str], model_inputs: dict[str, Any], opts: ReadOptions
) -> Recording:
    """A recording read as the command line reads one for a fitted model: ``signals`` (one
    name or ``"a,b"``) and the temperature columns ``temps``, units resolved once with the
    model file's ``inputs`` filling in what the options and the file leave unstated
    (:func:`thermocal.units.resolve_inputs`); the sensor id compared with the model's; a
    signal required; time finite and increasing, no NaN (:meth:`Recording.validate`),
    gaps reported in one :class:`GapWarning`.

    Parameters
    ----------
    path : pathlib.Path
        The recording.
    signals : str
        The signal column(s).
    temps : sequence of str
        The temperature columns.
    model_inputs : dict
        The model file's ``inputs``.
    opts : ReadOptions
        How the report's recordings are read.

    Returns
    -------
    Recording

    Raises
    ------
    ThermocalInputError
        A missing column, a unit that cannot be resolved, a sensor id that differs.
    """
    from thermocal.pipeline.reading import check_recording
    from thermocal.readers.dispatch import read_recording

    read = opts.replace(signals=signals or None, temperatures=tuple(temps) if temps else None)
    return check_recording(read_recording(path, read, model=model_inputs), read)


@dataclass(frozen=True)
class ReportResult:
    """What :func:`make_report` wrote: the HTML file and the kind of report, ``"models"``,
    ``"calibration"`` or ``"triads"``.

    Attributes
    ----------
    path : Path
        The HTML file.
    kind : str
        ``"models"``, ``"calibration"`` or ``"triads"``.
    """

    path: Path
    kind: str


def _check_counts(
    models: Sequence[Path], validations: Sequence[Path], labels: Sequence[str]
) -> None:
    """One validation file and one label per model file, when given."""
    if validations and len(validations) != len(models):
        raise ThermocalInputError.naming(
            f"{len(validations)} {{validations}} files for {len(models)} {{models}} files; "
            "give one validation per model, in the same order",
            "validations",
            "models",
        )
    if labels and len(labels) != len(models):
        raise ThermocalInputError.naming(
            f"{len(labels)} {{labels}} values for {len(models)} {{models}} files",
            "labels",
            "models",
        )


def _check_dynamic(dynamic_s: float | None, one_channel: bool) -> None:
    """A dynamic Allan deviation only in the report of one channel."""
    if dynamic_s is not None and not one_channel:
        raise ThermocalInputError.naming(
            "{dynamic_s} maps one channel's compensated output: it applies to the report of a "
            "single-signal model, not of a calibration of triads or several channels (run "
            "thermocal allan --dynamic on each channel)",  # cli-words: the command to run
            "dynamic_s",
        )


def _station_topic(
    read: ReadOptions, sensor: str | None, paths: Sequence[Path | None]
) -> ReadOptions:
    """A station folder's sensor is the report's: ``sensor`` read as the topic when no topic
    is given and a recording is a station folder."""
    if read.topic is not None or sensor is None:
        return read
    from thermocal.readers.station import is_station_path

    if any(p is not None and p.is_dir() and is_station_path(p) for p in paths):
        return replace(read, topic=sensor)
    return read


def make_report(
    models: Sequence[Path],
    recording: Path,
    output: Path,
    *,
    validations: Sequence[Path] = (),
    modeling: Path | None = None,
    signal: str | None = None,
    labels: Sequence[str] = (),
    title: str = DEFAULT_TITLE,
    sensor: str | None = None,
    averaging_s: float | None = None,
    latitude_deg: float | None = None,
    read: ReadOptions | None = None,
    progress: Progress | None = None,
    dynamic_s: float | None = None,
    ratetable: Path | None = None,
) -> ReportResult:
    """``thermocal report``: a self-contained HTML report written atomically to ``output``.

    Parameters
    ----------
    models : sequence of pathlib.Path
        Model files, compared (:func:`thermocal.report.write_report`); or one calibration:
        of triads, judged on ``recording`` (held-out poses, else the turntable's validation;
        :func:`thermocal.report.triads.write_triad_report`), or of several channels
        (:func:`thermocal.report.calibration.write_calibration_report`).
    recording, modeling : pathlib.Path
        The validation run and, optionally, the modelling run.
    output : pathlib.Path
        The HTML file to write.
    validations, labels : sequence
        Results of the ``validate`` command (JSON files) and labels, one per model, in its order.
    signal, title, sensor : str, optional
        The signal column(s) and the headline texts; with a station folder and no
        ``read.topic``, ``sensor`` is also the sensor read.
    averaging_s, latitude_deg, dynamic_s : float, optional
        Averaging time of the stability figures [s]; latitude [°] of a triad's validation
        (default the file's metadata); window of the dynamic Allan deviation [s].
    read, progress : ReadOptions, callable, optional
        How the recordings are read; what draws the steps.
    ratetable : pathlib.Path, optional
        A rate-table result (``thermocal ratetable -o``): its spec sheet as a section of a
        model's report.

    Returns
    -------
    ReportResult

    Raises
    ------
    ThermocalInputError
        Counts that do not match, the output an input, channels given with other models.
    """
    from thermocal.pipeline.model_file import load_calibration
    from thermocal.readers.options import ReadOptions
    from thermocal.writers import check_not_input

    opts = _station_topic(read or ReadOptions(), sensor, (recording, modeling))
    bar = progress or _no_progress
    _check_counts(models, validations, labels)
    inputs_files: list[str | Path] = [*models, *validations, recording]
    inputs_files += [p for p in (modeling, ratetable) if p is not None]
    check_not_input(output, inputs_files)
    cal = load_calibration(models[0])
    one_channel = not (cal.triads and not cal.channels) and not (
        len(cal.channels) > 1 or len(split_names(signal) or []) > 1
    )
    _check_dynamic(dynamic_s, one_channel)
    rt = _read_ratetable(ratetable, one_channel, models[0])
    if cal.triads and not cal.channels:  # a turntable calibration over temperature
        return _triad_report(
            cal,
            models[0],
            recording,
            output,
            opts,
            latitude_deg,
            title=None if title == DEFAULT_TITLE else title,
            sensor=sensor,
        )
    cal.require_channels("report")
    if len(cal.channels) > 1 or len(split_names(signal) or []) > 1:
        if len(models) > 1:
            raise ThermocalInputError.naming(
                f"{models[0]} is a calibration of {len(cal.channels)} channels: give it as the "
                "only {models} (compare calibrations in separate reports)",
                "models",
            )
        return _calibration_report(
            cal, models[0], recording, output, opts, bar,
            validation=validations[0] if validations else None, modeling=modeling,
            signal=signal, title=title, sensor=sensor, averaging_s=averaging_s,
        )  # fmt: skip
    return _models_report(
        models, recording, output, opts, bar, validations=validations, modeling=modeling,
        signal=signal, labels=labels, title=title, sensor=sensor, averaging_s=averaging_s,
        dynamic_s=dynamic_s, ratetable=rt,
    )  # fmt: skip


def _read_ratetable(path: Path | None, one_channel: bool, model: Path) -> Any:
    """The rate-table result read from ``path`` (None without one), refused beside a
    calibration of several channels or triads."""
    if path is None:
        return None
    if not one_channel:
        raise ThermocalInputError.naming(
            f"{model} is a calibration of several channels or triads: the rate-table section "
            "({ratetable}) goes into the report of a one-channel model; open the rate table's "
            "own page with `thermocal ratetable --report`",  # cli-words: the command that draws it
            "ratetable",
        )
    from thermocal.pipeline.ratetable import read_result

    return read_result(path)


def _triad_report(
    cal: Calibration,
    cal_path: Path,
    recording: Path,
    output: Path,
    opts: ReadOptions,
    latitude_deg: float | None,
    *,
    title: str | None = None,
    sensor: str | None = None,
) -> ReportResult:
    """A calibration of triads judged on ``recording`` and reported (``title`` None: the
    triad report's own)."""
    from thermocal.pipeline.compensate import read_for_triads
    from thermocal.pipeline.validate import judge_triads
    from thermocal.report.triads import write_triad_report

    rec = read_for_triads(recording, cal.triads, opts)
    results = judge_triads(cal.triads, rec, latitude_deg, signal_unit=opts.signal_unit)
    path = write_triad_report(output, cal, cal_path, results, recording, title=title, sensor=sensor)
    return ReportResult(Path(path), "triads")


def _models_report(
    models: Sequence[Path],
    recording: Path,
    output: Path,
    opts: ReadOptions,
    bar: Progress,
    *,
    validations: Sequence[Path],
    modeling: Path | None,
    signal: str | None,
    labels: Sequence[str],
    title: str,
    sensor: str | None,
    averaging_s: float | None,
    dynamic_s: float | None = None,
    ratetable: Any = None,
) -> ReportResult:
    """Model files reported and compared: both runs read with the same options (what they
    warn shown in the report too)."""
    from thermocal.pipeline.model_file import load_model_dict
    from thermocal.report.build import ModelEntry, ReportInputs, write_report

    with bar("building report", 3) as advance:
        entries = []
        for i, mpath in enumerate(models):
            mdict = load_model_dict(mpath)
            vdict = read_validation_json(validations[i]) if validations else None
            lab = labels[i] if labels else mpath.stem
            entries.append(ModelEntry(lab, mdict, vdict, str(mpath)))
        if len({e.label for e in entries}) != len(entries):
            raise ThermocalInputError.naming(
                "two models have the same label (file stem); name them with {labels}", "labels"
            )
        sig = signal or (entries[0].model.get("signal") or {}).get("name") or None
        if not sig:
            raise ThermocalInputError.naming("name the signal column with {signal}", "signal")
        fitted = dict(entries[0].model.get("inputs") or {})  # how the first model's data were
        # the temperature columns every model uses, in the first model's order
        temp_cols: list[str] = []
        for e in entries:
            for c in e.model.get("temperatures") or []:
                if c not in temp_cols:
                    temp_cols.append(str(c))
        # what thermocal warns while reading the runs goes into the report too
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            val_rec = read_run(recording, sig, temp_cols, fitted, opts)
            mod_rec = (
                read_run(modeling, sig, temp_cols, fitted, opts) if modeling is not None else None
            )
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        read_warnings = tuple(
            warning_text(w.message) for w in caught if issubclass(w.category, ThermocalWarning)
        )
        advance(1)
        inputs = ReportInputs(
            models=tuple(entries),
            recording=val_rec,
            modeling=mod_rec,
            signal=sig,
            recording_path=str(recording),
            modeling_path=str(modeling) if modeling is not None else None,
            title=title,
            sensor=sensor,
            generated_by="thermocal report",
            averaging_s=averaging_s,
            warnings_caught=read_warnings,
            dynamic_s=dynamic_s,
            ratetable=ratetable,
        )
        advance(1)
        path = write_report(output, inputs)
        advance(1)
    return ReportResult(Path(path), "models")


def _calibration_report(
    cal: Calibration,
    cal_path: Path,
    recording: Path,
    output: Path,
    opts: ReadOptions,
    bar: Progress,
    *,
    validation: Path | None,
    modeling: Path | None,
    signal: str | None,
    title: str,
    sensor: str | None,
    averaging_s: float | None,
) -> ReportResult:
    """A calibration's report: the recording read once for every chosen channel
    (:func:`thermocal.report.calibration.build_calibration_report`)."""
    from thermocal.models.calibration_inputs import merged_inputs, temperatures_of
    from thermocal.report.calibration import CalibrationReportInputs, write_calibration_report

    names = split_names(signal) or cal.names
    missing = [n for n in names if n not in cal.names]
    if missing:
        raise ThermocalInputError(
            f"{cal_path}: no channel {', '.join(map(repr, missing))}; it has "
            + ", ".join(cal.names)
        )
    with bar("building calibration report", 2) as advance:
        vdict = read_validation_json(validation, channels=True) if validation else None
        rec = read_run(
            recording,
            ",".join(cal.channel(n).signal for n in names),
            temperatures_of(cal, names),
            merged_inputs(cal, names),
            opts,
        )
        advance(1)
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
                title="Calibration report" if title == DEFAULT_TITLE else title,
                sensor=sensor,
                averaging_s=averaging_s,
                channels=names,
            ),
        )
        advance(1)
    return ReportResult(Path(path), "calibration")
