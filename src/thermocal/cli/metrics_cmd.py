"""``thermocal metrics FILE``: bias, bias stability, peak-to-peak, drift angle,
repeatability and temperature sensitivity of one signal."""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
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
    StampOpt,
    TempConversionOpt,
    TempsOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    chamber_log_options,
    check_recording,
    emit,
    handle_errors,
    progress,
    read_options,
    show,
    split_names,
)
from thermocal.errors import ThermocalInputError
from thermocal.report import text as _text
from thermocal.report.text import fmt

if TYPE_CHECKING:
    import thermocal.metrics as _metrics
    import thermocal.pipeline.large as _large
    import thermocal.readers as _readers
    from thermocal.metrics import MetricsResult
    from thermocal.recording import Recording
else:
    _metrics = LazyModule("thermocal.metrics")
    _large = LazyModule("thermocal.pipeline.large")
    _readers = LazyModule("thermocal.readers")


MetricsFilesArg = Annotated[
    list[Path],
    typer.Argument(
        help="Recording(s) (CSV or Parquet); several files are separate power-ons of one "
        "sensor: each run's figures and the turn-on to turn-on bias repeatability.",
        show_default=False,
    ),
]
AverageOpt = Annotated[
    float | None,
    typer.Option("--average", help="Averaging time S [s] of bias stability and peak-to-peak."),
]
HoldRateOpt = Annotated[
    float, typer.Option("--hold-rate", help="Hold stages: |dT/dt| below this [°C/min].")
]
MinHoldOpt = Annotated[
    float, typer.Option("--min-hold", help="Hold stages: at least this long [s].")
]
DriftReferenceOpt = Annotated[
    str | None,
    typer.Option(
        "--drift-reference",
        help="Drift angle: remove the mean rate over START,END [s since the first "
        "sample] (default: the first 10 % of the run).",
    ),
]
DriftBiasOpt = Annotated[
    float | None,
    typer.Option(
        "--drift-bias",
        help="Drift angle: remove this bias [the data's unit, earth rate already "
        "removed] instead of a reference window.",
    ),
]

StreamOpt = Annotated[
    bool,
    typer.Option(
        "--stream",
        help="Read the Parquet file a row group at a time and compute the figures from "
        "temporary files (bounded memory, any length; one signal, no --temps). Chosen by "
        "itself when the file would not fit in memory (THERMOCAL_MEMORY_LIMIT).",
    ),
]


@app.command("metrics")
@handle_errors
@chamber_log_options
def metrics_cmd(
    files: MetricsFilesArg,
    signal: SignalOpt = None,
    average: AverageOpt = None,
    temps: TempsOpt = None,
    latitude: LatitudeOpt = None,
    axis: AxisOpt = None,
    hold_rate: HoldRateOpt = 0.05,
    min_hold: MinHoldOpt = 600.0,
    drift_reference: DriftReferenceOpt = None,
    drift_bias: DriftBiasOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    t_names: NamesOpt = None,
    topic: TopicOpt = None,
    stamp: StampOpt = "header",
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    stream: StreamOpt = False,
    as_json: JsonOpt = False,
) -> None:
    """Figures of merit: bias (earth rate removed with --latitude and --axis), bias
    stability at the averaging time, peak-to-peak, drift angle, and over the
    temperature-hold stages of the first --temps column: bias repeatability and
    temperature sensitivity.  Several files (separate power-ons): each run's bias and in-run
    bias stability, and the turn-on to turn-on repeatability (sample standard deviation of
    the run biases with its 68.3 % chi-square interval)."""

    def read(file: Path) -> "Recording":
        r = read_options(
            time=time, time_unit=time_unit, signal=signal, temps=temps,
            signal_unit=signal_unit, temp_unit=temp_unit, temp_conversion=temp_conversion,
            topic=topic, names=t_names, rate=t_rate, on_bad_lines=t_bad, delimiter=t_delim,
            decimal=t_dec, stamp=stamp,
        )  # fmt: skip
        # metrics use the signal and the temperatures only
        # (each column read when used: the signal and one temperature held, not all)
        rec = _readers.read_recording(file, r, keep_other=False, columns_on_demand=True)
        _metrics.keep_stage_temperature(rec, split_names(temps))  # every column read once
        return check_recording(rec, r)

    def options() -> "_metrics.MetricsOptions":
        t_names_ = split_names(temps)
        return _metrics.MetricsOptions(
            average, latitude, axis, tuple(t_names_) if t_names_ else None, hold_rate,
            min_hold, _parse_window(drift_reference), drift_bias,
        )  # fmt: skip

    if len(files) > 1:
        opts = options()  # the window is checked before any file is read
        res = _metrics.power_on_metrics(files, read, split_names(signal), opts)
        _emit_runs(res, as_json)
        return
    file = files[0]
    # temperature hold stages are computed in memory only: a record too large for memory
    # with --temps gets the reader's refusal (naming the memory limit), not the stream's
    if stream or (not temps and _large.needs_streaming(file)):
        _streamed(file, options(), split_names(signal) or [], t_rate, stream, as_json, read_options(
            time=time, time_unit=time_unit, signal=signal, temps=temps,
            signal_unit=signal_unit, temp_unit=temp_unit, temp_conversion=temp_conversion,
            topic=topic, names=t_names, rate=t_rate,
        ))  # fmt: skip
        return
    rec = read(file)
    opts = options()
    results = _metrics.channel_metrics(rec, split_names(signal) or [rec.signals[0]], opts)
    _emit_metrics(file, results, as_json)


def _streamed(
    file: Path,
    opts: "_metrics.MetricsOptions",
    names: list[str],
    rate: float | None,
    forced: bool,
    as_json: bool,
    read: "_readers.ReadOptions",
) -> None:
    """One file too large for memory (or ``--stream``): its figures from temporary files."""
    why = "--stream given" if forced else "the file is larger than the memory available"
    if file.suffix.lower() not in (".parquet", ".pq"):
        raise ThermocalInputError(f"{file}: --stream reads Parquet files; convert it to Parquet")
    if len(names) > 1 or rate is not None:
        raise ThermocalInputError(
            f"{file}: computed window by window ({why}), which takes one signal and the "
            f"file's time column; drop {'--rate' if rate is not None else 'all but one --signal'}"
        )
    with progress("metrics (window by window)", total=1.0) as advance:
        res = _large.metrics_streamed(file, read, names[0] if names else None, opts,
                                      progress=advance)  # fmt: skip
    _emit_metrics(file, res, as_json)


def _emit_metrics(file: Path, results: "dict[str, MetricsResult]", as_json: bool) -> None:
    """One file: the table of every channel's figures (:func:`thermocal.report.text.
    metrics_text`) and how the drift angle's b0 was chosen, or their JSON."""
    first = next(iter(results.values()))
    ref = first.drift_reference
    tail = [f"drift angle: {_reference_words(ref)}"] if ref is not None else []
    human = lambda: show([*_text.metrics_text(str(file), results), *tail])  # noqa: E731
    if len(results) == 1:
        emit(first.to_dict(), as_json, human)
    else:
        emit({"channels": {n: r.to_dict() for n, r in results.items()}}, as_json, human)


def _parse_window(text: str | None) -> tuple[float, float] | None:
    """``--drift-reference START,END`` [s] as a pair (None when not given)."""
    if text is None:
        return None
    parts = [p.strip() for p in text.split(",")]
    try:
        if len(parts) != 2:
            raise ValueError
        return float(parts[0]), float(parts[1])
    except ValueError:
        raise ThermocalInputError(
            f"--drift-reference {text!r}: give START,END in seconds since the first sample, "
            "e.g. 0,600"
        ) from None


def _reference_words(ref: "_metrics.DriftReference") -> str:
    """How b0 was chosen, in words."""
    if ref.kind == "window":
        return (
            f"θ(t) = ∫ (ω − Ω − b0) dt with b0 = {fmt(ref.bias, 6)} {ref.unit}, the mean "
            f"over {ref.start_s:g}…{ref.end_s:g} s from the first sample "
            "(--drift-reference; default the first 10 % of the run)"
        )
    return f"θ(t) = ∫ (ω − Ω − b0) dt with the given b0 = {fmt(ref.bias, 6)} {ref.unit}"


def _emit_runs(res: "_metrics.PowerOnMetrics", as_json: bool) -> None:
    """``metrics FILE FILE...``: every file one power-on; per channel ``runs`` (each run's
    figures, as one file's JSON plus ``file``), ``bias`` the mean run bias,
    ``bias_stability`` the largest in-run bias stability, ``bias_repeatability`` (turn-on
    to turn-on: sample standard deviation of the run biases) with
    ``bias_repeatability_low``/``_high`` (68.3 % chi-square interval), all in ``unit``."""
    names, reps = list(res.names), res.repeatability
    human = lambda: show(_text.power_on_text(res))  # noqa: E731

    if len(names) == 1:
        emit(reps[names[0]].to_dict(), as_json, human)
    else:
        emit({"channels": {n: r.to_dict() for n, r in reps.items()}}, as_json, human)
