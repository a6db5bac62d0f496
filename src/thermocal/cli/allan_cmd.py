"""``thermocal allan FILE``: overlapping Allan deviation, confidence intervals and
IEEE 952 noise terms by slope lines and by least squares."""

import math
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from thermocal._lazy import LazyModule, prefetch
from thermocal.cli.application import app
from thermocal.cli.common import (
    DecimalOpt,
    DelimiterOpt,
    FileArg,
    JsonOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalOpt,
    SignalUnitOpt,
    TempConversionOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    emit,
    fmt,
    handle_errors,
    jsonable,
    load_recording,
    split_names,
    stdout,
    text_options,
)
from thermocal.errors import ConditioningWarning, ThermocalInputError

if TYPE_CHECKING:
    import rich.table as _rich_table

    import thermocal.metrics as _metrics
    import thermocal.stability.allan as _allan
    import thermocal.stability.family as _family
    import thermocal.writers as _writers
else:
    _rich_table = LazyModule("rich.table")
    _allan = LazyModule("thermocal.stability.allan")
    _writers = LazyModule("thermocal.writers")
    _metrics = LazyModule("thermocal.metrics")
    _family = LazyModule("thermocal.stability.family")


def _column_unit(name: str) -> str:
    """A phase column's unit from its name (``phase [s]``, ``angle (deg)``), else ``""``:
    phase units are not signal (rate) units, so the recording's unit resolver cannot give it."""
    import re

    hit = re.search(r"[\[(]([^\])]+)[\])]\s*$", name)
    return hit.group(1).strip() if hit else ""


def family_json(res: "_family.StabilityResult") -> dict[str, Any]:
    """The ``--json`` object of ``allan --deviation``: ``tau_s`` and per deviation NAME the
    keys NAME, NAME_low, NAME_high, NAME_edf, NAME_alpha, NAME_n, NAME_tau_s, NAME_unit;
    ``alpha`` the noise identified per ``tau_s`` (first Allan-family deviation)."""
    out: dict[str, Any] = {
        "tau_s": res.tau_s,
        "data_type": res.data_type,
        "confidence": res.confidence,
        "tau0_s": res.tau0_s,
        "n_segments": res.n_segments,
        "deviations": list(res.curves),
    }
    alpha_src = next(
        (c for c in res.curves.values() if c.name not in ("theo1", "hdev", "ohdev", "htotdev")),
        next(iter(res.curves.values())),
    )
    out["alpha"] = alpha_src.alpha if alpha_src.name != "theo1" else None
    for name, c in res.curves.items():
        out[name] = c.dev
        out[f"{name}_low"] = c.low
        out[f"{name}_high"] = c.high
        out[f"{name}_edf"] = c.edf
        out[f"{name}_alpha"] = c.alpha
        out[f"{name}_alpha_method"] = list(c.alpha_method)
        out[f"{name}_n"] = c.n_terms
        out[f"{name}_tau_s"] = c.tau_s
        out[f"{name}_unit"] = c.unit
    return dict(jsonable(out))


def _family_human(file: Path, res: "_family.StabilityResult") -> None:
    for name, c in res.curves.items():
        t = _rich_table.Table(title=f"{file} — {name} [{c.unit}] ({res.data_type} data)")
        for col in ("τ [s]", name, "low", "high", "edf", "α", "terms"):
            t.add_column(col, justify="right")
        for i in range(c.tau_s.size):
            if not math.isfinite(float(c.dev[i])):
                continue
            t.add_row(
                fmt(float(c.tau_s[i])), fmt(float(c.dev[i]), 5), fmt(float(c.low[i]), 5),
                fmt(float(c.high[i]), 5), fmt(float(c.edf[i]), 4), str(int(c.alpha[i])),
                str(int(c.n_terms[i])),
            )  # fmt: skip
        stdout.print(t)


def _terms_json(terms: dict[str, Any]) -> dict[str, Any]:
    return {
        name: {
            "value": t.value,
            "unit": t.unit,
            "reason": t.reason,
            "low": t.low,
            "high": t.high,
            "tau_s": t.tau_s,
            "label": t.label,
            "quality": t.quality,
        }
        for name, t in terms.items()
    }


def dynamic_json(dyn: "_allan.DynamicAllan") -> dict[str, Any]:
    """``dynamic``: ``window_s``, ``step_s``, ``t_s`` (window centres), ``tau_s``, ``adev``
    (windows × τ, null where a window is too short), ``adev_low``/``adev_high``,
    ``stationary``, ``changes`` and the test's ``test_confidence``."""
    return {
        "window_s": dyn.window_s,
        "step_s": dyn.step_s,
        "t_s": dyn.t_s,
        "tau_s": dyn.tau_s,
        "adev": dyn.adev,
        "adev_low": dyn.adev_low,
        "adev_high": dyn.adev_high,
        "unit": dyn.unit,
        "stationary": dyn.stationary,
        "changes": list(dyn.changes),
        "test_confidence": dyn.test_confidence,
    }


def allan_json(
    res: "_allan.AllanResult",
    noise: "_allan.NoiseTerms",
    dyn: "_allan.DynamicAllan | None" = None,
) -> dict[str, Any]:
    """The ``--json`` object of ``thermocal allan``: ``noise`` holds the fit-method
    terms, ``noise_slope`` the slope-line terms (each value or null with a reason);
    ``dynamic`` with ``--dynamic``."""
    out: dict[str, Any] = {
        "tau_s": res.tau_s,
        "adev": res.adev,
        "adev_low": res.adev_low,
        "adev_high": res.adev_high,
        "unit": res.unit,
        "n_terms": res.n_terms,
        "edf": res.edf,
        "alpha": res.alpha,
        "confidence": res.confidence,
        "tau0_s": res.tau0_s,
        "n_samples": res.n_samples,
        "n_segments": res.n_segments,
        "noise": _terms_json(noise.fit.terms()),
        "noise_method": "weighted non-negative least squares (IEEE 952 C.2)",
        "noise_slope": _terms_json(noise.slope.terms()),
        "noise_slope_method": "slope lines (IEEE 952 C.3)",
        "fit_coefficients": noise.fit_coefficients,
        "fit_reduced_chi2": noise.reduced_chi2,
        "fit_quality": noise.quality.to_dict() if noise.quality is not None else None,
    }
    if dyn is not None:
        out["dynamic"] = dynamic_json(dyn)
    return dict(jsonable(out))


def _emit_channels(
    file: Path,
    analyses: "dict[str, tuple[_allan.AllanResult, _allan.NoiseTerms]]",
    as_json: bool,
    plot: Path | None,
    dynamics: "dict[str, _allan.DynamicAllan]",
) -> None:
    """Several channels: ``{"channels": {NAME: {…}}}`` or one noise-term table with a
    column per channel (the ADEV points are in the JSON and the plots)."""

    def human() -> None:
        t = _rich_table.Table(title=f"{file} — noise terms (least-squares fit), per channel")
        t.add_column("term")
        for name in analyses:
            t.add_column(name, justify="right")
        first_noise = next(iter(analyses.values()))[1]
        for key, term in first_noise.fit.terms().items():
            cells = []
            for _res, noise in analyses.values():
                tt = noise.fit.terms()[key]
                cells.append(f"{fmt(tt.value)} {tt.unit}" if tt.value is not None else "—")
            t.add_row(term.label, *cells)
        t.add_row(
            "fit quality",
            *[
                f"{n.quality.quality} (χ²/ν {n.quality.reduced_chi2:.3g})" if n.quality else "—"
                for _r, n in analyses.values()
            ],
        )
        stdout.print(t)
        if plot is not None:
            stdout.print(f"plots written to {plot.stem}_<channel>{plot.suffix} in {plot.parent}")

    emit(
        {
            "channels": {
                name: allan_json(r, n, dynamics.get(name)) for name, (r, n) in analyses.items()
            }
        },
        as_json,
        human,
    )


@app.command("allan")
@handle_errors
def allan_cmd(
    file: FileArg,
    signal: SignalOpt = None,
    taus: Annotated[
        str, typer.Option("--taus", help="Tau set: octave, decade, log, or a list '1,10,100' [s].")
    ] = "octave",
    plot: Annotated[
        Path | None, typer.Option("--plot", help="Write a log-log PNG plot here.")
    ] = None,
    confidence: Annotated[
        float, typer.Option("--confidence", help="Confidence level of the intervals.")
    ] = 0.6826894921370859,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    temps: Annotated[str | None, typer.Option("--temps", hidden=True)] = None,
    t_names: NamesOpt = None,
    topic: TopicOpt = None,
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    deviation: Annotated[
        str | None,
        typer.Option(
            "--deviation",
            help="Deviations (NIST SP 1065), comma-separated: oadev (default), adev, mdev, "
            "tdev, hdev, ohdev, totdev, mtotdev, ttotdev, htotdev, theo1, mtie, tierms.",
        ),
    ] = None,
    data_type: Annotated[
        str,
        typer.Option(
            "--data-type",
            help="rate (default: the column is a rate) or phase (an integrated quantity: "
            "angle, velocity, seconds of a clock).",
        ),
    ] = "rate",
    dynamic: Annotated[
        float | None,
        typer.Option(
            "--dynamic",
            help="Dynamic ADEV: the overlapping ADEV in sliding windows of this many seconds "
            "(half-window steps), a heat map beside --plot, a warning when the record is not "
            "stationary.",
        ),
    ] = None,
    as_json: JsonOpt = False,
) -> None:
    """Overlapping Allan deviation with chi-square confidence intervals and the noise
    terms (quantization, angle random walk, bias instability, rate random walk, rate
    ramp) by least squares and by IEEE 952 slope lines.  Gaps are never
    differenced across: each contiguous stretch is processed alone and pooled."""
    prefetch("scipy.special", "scipy.linalg", "rich.table")  # imported while the file is read
    rec = load_recording(
        file,
        text=text_options(t_names, t_rate, t_bad, t_delim, t_dec),
        topic=topic,
        time=time,
        time_unit=time_unit,
        signal=signal,
        temps=temps if temps is not None else "",  # no temperature column is read
        signal_unit=signal_unit,
        temp_unit=temp_unit,
        temp_conversion=temp_conversion,
        keep_other=False,  # the Allan deviation uses the time and the signal only
    )
    if plot is not None:
        _writers.check_not_input(plot, [file])
        if plot.is_dir():
            raise ThermocalInputError(f"{plot}: is a directory, expected a file name")
        if plot.suffix.lower() not in (".png", ".svg", ".pdf"):
            raise ThermocalInputError(f"{plot}: --plot writes PNG, SVG or PDF; name it *.png")
    tau_spec: Any = taus
    if taus not in ("octave", "decade", "log", "all"):
        try:
            tau_spec = [float(v) for v in taus.split(",") if v.strip()]
        except ValueError:
            raise ThermocalInputError(
                f"--taus {taus!r}: use octave, decade, log or a comma-separated list of τ [s]"
            ) from None
    names = split_names(signal) or [rec.signals[0]]
    if data_type not in ("rate", "phase"):
        raise ThermocalInputError(f"--data-type {data_type!r}: use rate or phase")
    if dynamic is not None and (deviation is not None or data_type == "phase"):
        raise ThermocalInputError(
            "--dynamic computes the overlapping ADEV of rate data; run it without --deviation "
            "and --data-type phase"
        )
    if deviation is not None or data_type == "phase":
        devs = _family.parse_deviations(deviation or "oadev")
        fam_spec: Any = "all" if taus == "all" else tau_spec
        results = {}
        for name in names:
            if data_type == "phase":  # the column as given, in its own unit
                values, unit = rec.column(name), _column_unit(name)
            else:
                canonical, canon_unit = rec.signal(name)
                unit, k = _metrics.data_unit_of(rec, name, canon_unit)
                values = canonical if k == 1.0 else canonical / k
            results[name] = _family.stability(
                values, rec.sample_interval_s, devs, fam_spec, data_type=data_type,
                segments=rec.segments(), unit=unit, confidence=confidence,
            )  # fmt: skip
        if len(names) == 1:
            one = results[names[0]]
            emit(family_json(one), as_json, lambda: _family_human(file, one))
        else:

            def human_all() -> None:
                for r in results.values():
                    _family_human(file, r)

            emit({"channels": {n: family_json(r) for n, r in results.items()}}, as_json, human_all)
        return
    analyses: dict[str, tuple[_allan.AllanResult, _allan.NoiseTerms]] = {}
    dynamics: dict[str, _allan.DynamicAllan] = {}
    for name in names:  # one read of the file, every channel (INTERFACE: several channels)
        canonical, canon_unit = rec.signal(name)
        # every figure in the data's own unit (°/s data: ADEV in °/s; INTERFACE common rules)
        unit, k = _metrics.data_unit_of(rec, name, canon_unit)
        values = canonical if k == 1.0 else canonical / k
        res_c = _allan.overlapping_adev(
            values,
            rec.sample_interval_s,
            tau_spec,
            time_s=rec.time_s,
            segments=rec.segments(),  # one scan of the time column for every channel
            unit=unit,
            confidence=confidence,
            # the phase is accumulated in the column's own buffer (no memory per sample):
            # the column is not used again unless the channel is named twice or the
            # dynamic ADEV reads the rate after it (it did, on the floor's numpy/pyarrow,
            # where the buffer is writeable: windows of phase, found by the floor check)
            overwrite=names.count(name) == 1 and dynamic is None,
        )
        noise_c = _allan.noise_terms(res_c)
        where = f"{file}" + (f" [{name}]" if len(names) > 1 else "")
        if noise_c.quality is not None and noise_c.quality.quality == "poor":
            warnings.warn(f"{where}: {noise_c.quality.reason}", ConditioningWarning, stacklevel=1)
        if dynamic is not None:
            dyn = _allan.dynamic_adev(
                values, rec.sample_interval_s, dynamic, res_c, time_s=rec.time_s
            )
            dynamics[name] = dyn
            if not dyn.stationary:
                worst = max(dyn.changes, key=lambda c: abs(math.log(c["adev"] / c["whole_adev"])))
                warnings.warn(
                    f"{where}: the record is not stationary: in {len(dyn.changes)} (window, τ) "
                    f"cells the {dyn.window_s:g} s windows' ADEV differs from the whole "
                    f"record's beyond both intervals (e.g. {worst['adev']:.4g} against "
                    f"{worst['whole_adev']:.4g} {res_c.unit} at τ = {worst['tau_s']:.4g} s in "
                    f"the window centred at {worst['t_s']:.4g} s); the noise terms of the "
                    "whole record average over changing noise",
                    ConditioningWarning,
                    stacklevel=1,
                )
        if plot is not None:
            from thermocal.report.allan_plots import plot_allan, plot_dynamic

            target = plot if len(names) == 1 else plot.with_name(f"{plot.stem}_{name}{plot.suffix}")
            plot_allan(res_c, noise_c, target, title=f"{file.name} — {name}")
            if name in dynamics:
                plot_dynamic(
                    dynamics[name], target.with_name(f"{target.stem}_dynamic{target.suffix}"),
                    title=f"{file.name} — {name}: dynamic ADEV",
                )  # fmt: skip
        analyses[name] = (res_c, noise_c)
    if len(names) > 1:
        _emit_channels(file, analyses, as_json, plot, dynamics)
        return
    res, noise = analyses[names[0]]

    def human() -> None:
        t1 = _rich_table.Table(title=f"{file} — overlapping Allan deviation [{res.unit}]")
        for col in ("τ [s]", "ADEV", "low", "high", "terms", "edf"):
            t1.add_column(col, justify="right")
        for i in range(res.tau_s.size):
            t1.add_row(
                fmt(float(res.tau_s[i])),
                fmt(float(res.adev[i])),
                fmt(float(res.adev_low[i])),
                fmt(float(res.adev_high[i])),
                str(int(res.n_terms[i])),
                fmt(float(res.edf[i]), 3),
            )
        stdout.print(t1)
        t2 = _rich_table.Table(title="noise terms")
        for col in ("term", "fit", "slope lines", "unit", "note"):
            t2.add_column(col)
        fit, slope = noise.fit.terms(), noise.slope.terms()
        poor = noise.quality is not None and noise.quality.quality == "poor"
        for name in fit:
            f, s = fit[name], slope[name]
            note = "poor fit (see the warning)" if poor else (f.reason or s.reason or "")
            mark = " ?" if poor else ""
            t2.add_row(
                f.label,
                fmt(f.value) + (mark if f.value is not None else ""),
                fmt(s.value) + (mark if s.value is not None else ""),
                f.unit,
                note,
            )
        stdout.print(t2)
        if noise.quality is not None:
            stdout.print(
                f"noise-model fit: reduced χ² {noise.quality.reduced_chi2:.3g} on "
                f"{noise.quality.dof} degrees of freedom — {noise.quality.quality}"
            )
        dyn = dynamics.get(names[0])
        if dyn is not None:
            stdout.print(
                f"dynamic ADEV: {dyn.t_s.size} windows of {dyn.window_s:g} s, "
                + ("stationary" if dyn.stationary else f"{len(dyn.changes)} changes (warning)")
            )
        if plot is not None:
            stdout.print(f"plot written to {plot}")

    emit(allan_json(res, noise, dynamics.get(names[0])), as_json, human)
