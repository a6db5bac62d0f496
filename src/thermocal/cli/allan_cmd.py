"""``thermocal allan FILE``: overlapping Allan deviation, confidence intervals and
IEEE 952 noise terms by slope lines and by least squares."""

import contextlib
import math
import warnings
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule, prefetch
from thermocal.cli.application import app
from thermocal.cli.common import (
    ConfidenceOpt,
    DecimalOpt,
    DelimiterOpt,
    FileArg,
    JsonOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalOpt,
    SignalUnitOpt,
    StampOpt,
    TempConversionOpt,
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
from thermocal.errors import ThermocalInputError, UnitWarning
from thermocal.report import text as _text

if TYPE_CHECKING:
    import thermocal.pipeline.large as _large
    import thermocal.readers as _readers
    import thermocal.stability.analysis as _analysis
    import thermocal.stability.api as _api
    import thermocal.stability.family as _family
    import thermocal.stability.registry as _registry
    import thermocal.writers as _writers
    from thermocal.recording import Recording
else:
    _large = LazyModule("thermocal.pipeline.large")
    _writers = LazyModule("thermocal.writers")
    _readers = LazyModule("thermocal.readers")
    _analysis = LazyModule("thermocal.stability.analysis")
    _family = LazyModule("thermocal.stability.family")
    _registry = LazyModule("thermocal.stability.registry")
    _api = LazyModule("thermocal.stability.api")


def parse_taus(text: str) -> str | list[float]:
    """``--taus``: a named set (:data:`thermocal.stability.api.TAU_SETS`) as given, else a
    list of τ [s]."""
    if text in _api.TAU_SETS:
        return text
    try:
        taus = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ThermocalInputError(
            f"--taus {text!r}: use octave, decade, log or a comma-separated list of τ [s]"
        ) from None
    bad = [t for t in taus if not (math.isfinite(t) and t > 0)]
    if bad or not taus:
        raise ThermocalInputError(
            f"--taus {text!r}: every τ must be a positive, finite time [s]"
            + (f" (got {bad[0]:g})" if bad else " (none given)")
            + "; or use octave, decade, log"
        )
    return taus


def parse_deviations(spec: str) -> list[str]:
    """``--deviation "oadev,mdev"`` → names, checked against the deviation registry."""
    known = _registry.names()
    names = [s.strip().lower() for s in spec.split(",") if s.strip()]
    bad = [n for n in names if n not in known]
    if bad or not names:
        raise ThermocalInputError(
            f"--deviation {spec!r}: unknown {', '.join(bad) or 'empty list'}; use "
            + ", ".join(known)
        )
    return list(dict.fromkeys(names))


def parse_noise_type(spec: str | None, names: list[str]) -> int | None:
    """``--noise-type``: ``auto`` (None: identified per τ), a name of
    :data:`thermocal.stability.family.NOISE_TYPES` or α itself (−4…2).  α < −2 only for the
    Hadamard family (hdev, ohdev, htotdev)."""
    if spec is None or spec.strip().lower() in ("", "auto"):
        return None
    key = spec.strip().lower()
    try:
        alpha = _family.NOISE_TYPES[key] if key in _family.NOISE_TYPES else int(key)
    except ValueError:
        alpha = 99
    if not -4 <= alpha <= 2:
        raise ThermocalInputError(
            f"--noise-type {spec!r}: use auto, {', '.join(_family.NOISE_TYPES)} or α from -4 to 2"
        )
    not_h = [n for n in names if not _registry.get(n).hadamard and _registry.get(n).edf is not None]
    if alpha < -2 and not_h:
        raise ThermocalInputError(
            f"--noise-type {spec!r} (α = {alpha}) is defined for the Hadamard deviations "
            f"(hdev, ohdev, htotdev) only, not {', '.join(not_h)}"
        )
    return alpha


def _noise_type(spec: str | None, devs: list[str] | None, data_type: str) -> int | None:
    """α of ``--noise-type`` for the deviation family (``--deviation`` or phase data); for the
    default overlapping ADEV any α given (0) so that the library refuses the option there."""
    if devs is not None or data_type == "phase":
        return parse_noise_type(spec, devs or ["oadev"])
    return None if spec is None or spec.strip().lower() in ("", "auto") else 0


TausOpt = Annotated[
    str, typer.Option("--taus", help="Tau set: octave, decade, log, or a list '1,10,100' [s].")
]
PlotOpt = Annotated[Path | None, typer.Option("--plot", help="Write a log-log PNG plot here.")]
HiddenTempsOpt = Annotated[
    str | None,
    typer.Option("--temps", help="Temperature column: with --temp-bins, the terms per bin."),
]
AllanTempBinsOpt = Annotated[
    str | None,
    typer.Option(
        "--temp-bins",
        help="With --temps: the noise terms (N, K, B with intervals) per temperature bin and "
        "their trend against temperature; a bin width in °C (5) or the edges (10,25,40).",
    ),
]
DeviationOpt = Annotated[
    str | None,
    typer.Option(
        "--deviation",
        help="Deviations (NIST SP 1065), comma-separated: oadev (default), adev, mdev, "
        "tdev, hdev, ohdev, totdev, mtotdev, ttotdev, htotdev, theo1, mtie, tierms.",
    ),
]
DataTypeOpt = Annotated[
    str,
    typer.Option(
        "--data-type",
        help="rate (default: the column is a rate) or phase (an integrated quantity: "
        "angle, velocity, seconds of a clock).",
    ),
]
BiasCorrectOpt = Annotated[
    bool,
    typer.Option(
        "--bias-correct",
        help="Remove the bias of totdev (flicker and random-walk FM) and htotdev (FM noises, "
        "m ≥ 2) as Stable32 does; the factor per τ is NAME_bias_factor in --json.",
    ),
]
NoiseTypeOpt = Annotated[
    str | None,
    typer.Option(
        "--noise-type",
        help="The power-law noise the intervals (and --bias-correct) assume at every τ, as "
        "Stable32's noise-type setting: auto (default: identified per τ), wpm, fpm, wfm, "
        "ffm, rwfm (fwfm, rrfm: Hadamard deviations only) or α from -4 to 2.",
    ),
]
NoiseIdOpt = Annotated[
    str | None,
    typer.Option(
        "--noise-id",
        help="The noise identification's rules: thermocal (default: B1 judged at its number "
        "of averages and bounded by the shorter τ's noise) or stable32 (Stable32's α column "
        "exactly: B1 judged at the deviation's number of terms, the total family down to 6 "
        "averages, ADEV and HDEV from 10).",
    ),
]
DynamicOpt = Annotated[
    float | None,
    typer.Option(
        "--dynamic",
        help="Dynamic ADEV: the overlapping ADEV in sliding windows of this many seconds "
        "(half-window steps), a heat map beside --plot, a warning when the record is not "
        "stationary.",
    ),
]


MaxWorkOpt = Annotated[
    float | None,
    typer.Option(
        "--max-work",
        help="With --deviation or --dynamic: the arithmetic operations the deviations or "
        "the dynamic ADEV's windows may take (default 3e10, about half a minute); a request "
        "estimated beyond it is refused before it starts (theo1 grows as N·m per τ, the "
        "total family as N).",
    ),
]


StreamOpt = Annotated[
    bool,
    typer.Option(
        "--stream",
        help="Read the Parquet file a row group at a time and analyse it window by window "
        "from temporary files (bounded memory, any length; the default analysis only). "
        "Chosen by itself when the file would not fit in memory (THERMOCAL_MEMORY_LIMIT).",
    ),
]


def _streamed(file: Path, forced: bool, signal: str | None, others: Mapping[str, object]) -> bool:
    """Whether this run is analysed window by window (``--stream``, or a Parquet file too
    large for memory), refusing the options only the in-memory analysis has."""
    if not (forced or _large.needs_streaming(file)):
        return False
    given = [k for k, v in others.items() if v not in (None, False, "rate", "octave", "error")]
    names = split_names(signal) or []
    if len(names) > 1:
        given.append("--signal with several columns")
    if file.suffix.lower() not in (".parquet", ".pq"):
        raise ThermocalInputError(f"{file}: --stream reads Parquet files; convert it to Parquet")
    if given:
        why = "--stream given" if forced else "the file is larger than the memory available"
        raise ThermocalInputError(
            f"{file}: analysed window by window ({why}), which takes the default analysis "
            f"of one channel at octave τ only; drop {', '.join(given)}, or cut the record"
        )
    return True


def _check_plot(plot: Path | None, file: Path) -> None:
    """``--plot``: a PNG, SVG or PDF file name that is not the input."""
    if plot is None:
        return
    _writers.check_not_input(plot, [file])
    if plot.is_dir():
        raise ThermocalInputError(f"{plot}: is a directory, expected a file name")
    if plot.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise ThermocalInputError(f"{plot}: --plot writes PNG, SVG or PDF; name it *.png")


def _write_plots(file: Path, plot: Path, res: "_analysis.AllanAnalysis") -> None:
    """The ADEV plot of every channel (``PLOT_CHANNEL.png`` with several) and, with
    ``--dynamic``, its heat map beside it (``…_dynamic.png``)."""
    from thermocal.report.allan_plots import plot_allan, plot_dynamic

    many = len(res.names) > 1
    for name, ch in res.channels.items():
        target = plot.with_name(f"{plot.stem}_{name}{plot.suffix}") if many else plot
        plot_allan(ch.adev, ch.noise, target, title=f"{file.name} — {name}")
        if ch.dynamic is not None:
            plot_dynamic(
                ch.dynamic, target.with_name(f"{target.stem}_dynamic{target.suffix}"),
                title=f"{file.name} — {name}: dynamic ADEV",
            )  # fmt: skip


@app.command("allan")
@handle_errors
@chamber_log_options
def allan_cmd(
    file: FileArg,
    signal: SignalOpt = None,
    taus: TausOpt = "octave",
    plot: PlotOpt = None,
    confidence: ConfidenceOpt = 0.6826894921370859,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    temps: HiddenTempsOpt = None,
    edges_c: AllanTempBinsOpt = None,
    t_names: NamesOpt = None,
    topic: TopicOpt = None,
    stamp: StampOpt = "header",
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    deviation: DeviationOpt = None,
    data_type: DataTypeOpt = "rate",
    dynamic: DynamicOpt = None,
    bias_correct: BiasCorrectOpt = False,
    noise_type: NoiseTypeOpt = None,
    noise_id: NoiseIdOpt = None,
    max_work: MaxWorkOpt = None,
    stream: StreamOpt = False,
    as_json: JsonOpt = False,
) -> None:
    """Overlapping Allan deviation with chi-square confidence intervals and the noise
    terms (quantization, angle random walk, bias instability, rate random walk, rate
    ramp) by least squares and by IEEE 952 slope lines.  Gaps are never
    differenced across: each contiguous stretch is processed alone and pooled."""
    # imported while the file is read (the intervals' quantiles need no scipy)
    prefetch("rich.table")
    one = split_names(t_names) if t_names is not None else None
    if signal is None and one is not None and len(one) == 1:
        signal = one[0]  # a one-column text log (Stable32's data files): its column
    with warnings.catch_warnings():
        if data_type == "phase":  # the column's own unit is used (angle, s): no rate unit
            warnings.filterwarnings(
                "ignore", ".*no unit stated for the signal column", category=UnitWarning
            )
        read = read_options(
            time=time, time_unit=time_unit, signal=signal,
            temps=temps if temps is not None else "",  # no temperature column is read
            signal_unit=signal_unit, temp_unit=temp_unit, temp_conversion=temp_conversion,
            topic=topic, names=t_names, rate=t_rate, on_bad_lines=t_bad, delimiter=t_delim,
            decimal=t_dec, stamp=stamp,
        )  # fmt: skip
        others = {
            "--deviation": deviation, "--data-type": data_type, "--dynamic": dynamic,
            "--bias-correct": bias_correct, "--noise-type": noise_type,
            "--noise-id": noise_id, "--max-work": max_work, "--rate": t_rate,
            "--temp-bins": edges_c,
        }  # fmt: skip
        if _streamed(file, stream, signal, others):
            _check_plot(plot, file)
            tau_spec = parse_taus(taus)
            one_name = (split_names(signal) or [""])[0] or None
            with progress("allan (window by window)", total=1.0) as advance:
                res = _large.allan_streamed(
                    file, read, one_name, taus=tau_spec,
                    confidence=confidence, where=str(file), progress=advance,
                )  # fmt: skip
            if plot is not None:
                _write_plots(file, plot, res)
            _emit_allan(file, res, as_json, plot)
            return
        # the Allan deviation uses the time and the signal only
        rec = check_recording(_readers.read_recording(file, read, keep_other=False), read)
    _check_plot(plot, file)
    if edges_c is not None:
        others = {"--deviation": deviation, "--dynamic": dynamic, "--noise-type": noise_type,
                  "--data-type": None if data_type == "rate" else data_type}  # fmt: skip
        _by_temperature(file, rec, signal, temps, (edges_c, plot, others), confidence, as_json)
        return
    tau_spec = parse_taus(taus)
    devs = parse_deviations(deviation) if deviation is not None else None
    with _total_bar(devs) as on_total:
        res = _analysis.allan_analysis(
            rec, split_names(signal) or [rec.signals[0]], taus=tau_spec, confidence=confidence,
            deviations=devs, data_type=data_type, dynamic_s=dynamic, where=str(file),
            bias_correct=bias_correct, noise_type=_noise_type(noise_type, devs, data_type),
            noise_id=noise_id,
            max_work=max_work,
            overwrite=True,  # the recording read here is not used after the analysis
            progress=on_total,
        )  # fmt: skip
    if res.is_family:
        _emit_family(file, res, as_json)
        return
    if plot is not None:
        _write_plots(file, plot, res)
    _emit_allan(file, res, as_json, plot)


def _by_temperature(
    file: Path, rec: "Recording", signal: str | None, temps: str | None,
    bins_plot: tuple[str, Path | None, Mapping[str, object]], confidence: float, as_json: bool,
) -> None:  # fmt: skip
    """``--temps COL --temp-bins …``: the noise terms per temperature bin (of the default
    analysis: the options of the others refused)."""
    from thermocal.cli.noise_temps import parse_bins
    from thermocal.report.noise_text import noise_by_temperature_text
    from thermocal.stability.noise_temperature import signals_by_temperature

    if not temps:
        raise ThermocalInputError("--temp-bins applies with --temps COLUMN (the thermometer)")
    given = [k for k, v in bins_plot[2].items() if v is not None]
    if given:
        raise ThermocalInputError(
            f"--temp-bins gives the noise terms per bin of the default analysis: drop "
            f"{', '.join(given)}"
        )
    edges, width = parse_bins(bins_plot[0])
    res = signals_by_temperature(
        rec, split_names(signal) or [rec.signals[0]], (split_names(temps) or [""])[0], edges,
        width_c=width, confidence=confidence, where=str(file),
    )  # fmt: skip
    if bins_plot[1] is not None:
        from thermocal.report.noise_plots import plot_noise_by_temperature

        plot_noise_by_temperature(res, bins_plot[1], title=f"{file.name}: noise per temperature")
    emit(res.to_dict(), as_json, lambda: show(noise_by_temperature_text(str(file), res, None)))


@contextlib.contextmanager
def _total_bar(devs: list[str] | None) -> Iterator[Callable[[float], None] | None]:
    """A determinate progress bar (terminal only) while the total family is computed: yields
    the library's callback (the fraction done), or None when no total deviation is asked."""
    if not devs or not {"mtotdev", "ttotdev", "htotdev"} & set(devs):
        yield None
        return
    with progress("total deviations", total=1.0) as advance:
        shown = [0.0]

        def to(frac: float) -> None:  # the bar advances by the new fraction's increment
            advance(frac - shown[0])
            shown[0] = frac

        yield to


def _emit_family(file: Path, res: "_analysis.AllanAnalysis", as_json: bool) -> None:
    """``--deviation`` or phase data: one channel's object, or ``{"channels": …}``."""
    if len(res.names) == 1:
        one = res.family[res.names[0]]
        emit(one.to_dict(), as_json, lambda: show(_text.family_text(str(file), one)))
        return
    every = {n: r.to_dict() for n, r in res.family.items()}
    emit({"channels": every}, as_json, lambda: show(_family_blocks(file, res)))


def _family_blocks(file: Path, res: "_analysis.AllanAnalysis") -> "list[_text.Block]":
    """Every channel's deviation tables, one after the other."""
    return [b for r in res.family.values() for b in _text.family_text(str(file), r)]


def _emit_allan(
    file: Path, analysis: "_analysis.AllanAnalysis", as_json: bool, plot: Path | None
) -> None:
    """The ADEV table and the noise terms of one channel, or the noise terms of several
    side by side (the ADEV points of several are in the JSON and the plots)."""
    if len(analysis.names) > 1:
        tail = []
        if plot is not None:
            tail = [f"plots written to {plot.stem}_<channel>{plot.suffix} in {plot.parent}"]
        obj = {"channels": {n: c.to_dict() for n, c in analysis.channels.items()}}
        emit(obj, as_json, lambda: show([*_text.allan_channels_text(str(file), analysis), *tail]))
        return
    ch = analysis.channels[analysis.names[0]]
    end = [f"plot written to {plot}"] if plot is not None else []
    emit(ch.to_dict(), as_json, lambda: show([*_text.allan_text(str(file), ch), *end]))
