"""HTML report of a calibration: several channels in one document.

:func:`build_calibration_report` applies every channel's model to the validation run
(:func:`thermocal.report.build.apply_model`, each channel in its data column's unit) and
shows, for 1 to ~18 channels:

1. a per-channel summary table — role, unit, family, coefficients, fitted temperature
   range, fit residual, condition number; temperature sensitivity (least-squares slope
   over the hold stages) and bias stability before → after, computed here from
   the recording with :func:`thermocal.metrics.compute_metrics`; the validation figures
   (r, rms before → after) and one verdict per channel when the ``validate`` command's JSON
   output is given (no verdict without it);
2. bias against temperature before and after, one panel per channel
   (:func:`thermocal.report.figures.bias_vs_temperature_grid`);
3. overlapping Allan deviation before and after, one panel per channel, with the IEEE 952
   bias instability and random walk read from it (:func:`thermocal.report.build.allan_of`);
4. per channel, in collapsible sections: coefficients with standard errors, ranges of
   validity, the validation's stages, warnings;

with a table of contents and the files' SHA-256 (provenance).  Gyro channels of a
calibration are reported without earth-rate removal (each axis sees a different share of
it; the report says so when the file's metadata names a latitude).
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from thermocal.compensate.kernels import unit_factor
from thermocal.defaults import DEFAULT_AVERAGING_S
from thermocal.errors import ThermocalInputError
from thermocal.models.calibration import Calibration
from thermocal.models.format import model_file_dict
from thermocal.pipeline.messages import warning_text
from thermocal.readers.common import sha256_of
from thermocal.recording import Recording
from thermocal.report.analysis import (
    allan_of,
    apply_model,
    averaging_for,
    coverage_of,
    shown_figures,
)
from thermocal.report.build import (
    ILL_CONDITIONED,
    _b64,
    _coefficient_rows,
    _env,
    _range_rows,
    adequacy_rows,
    change_html,
    improvement_pct,
    unit_label,
)
from thermocal.writers import write_html


@dataclass(frozen=True)
class CalibrationReportInputs:
    """Everything :func:`build_calibration_report` needs.

    ``recording`` holds every channel's signal column and temperature inputs (the
    validation run, or any run to show the calibration on); ``validation`` is the JSON
    object the ``validate`` command prints for a calibration (``{"channels": {NAME: {…}}}``), or a
    mapping channel → one validation object; ``extra`` adds named per-channel columns to
    the summary table (``{column title: {channel: value}}``, e.g. the demo's share of the
    simulator's true bias removed).

    Attributes
    ----------
    calibration : Calibration
        The calibration reported.
    recording : Recording
        The run it is shown on.
    recording_path, modeling_path, calibration_path, validation_path : str or None
        The files, as the report names them.
    validation : mapping or None
        The validation object(s) described above.
    title : str
        The report's title.
    sensor : str or None
        The sensor's name.
    generated_by : str
        The command or program named as the report's maker.
    averaging_s : float or None
        Averaging time of the figures [s] (None: the default).
    channels : sequence of str or None
        The channels shown (None: all).
    extra : mapping
        The extra summary columns described above.
    notes : tuple of str
        Notes shown in the report.
    appendix : tuple of str
        HTML sections made by thermocal's report code.
    allan : bool
        Draw the Allan deviation section (default True); False leaves it out, and its
        cost (an overlapping Allan deviation, noise identification and confidence
        intervals per channel, before and after compensation).
    """

    calibration: Calibration
    recording: Recording
    recording_path: str | None = None
    modeling_path: str | None = None
    calibration_path: str | None = None
    validation: Mapping[str, Any] | None = None
    validation_path: str | None = None
    title: str = "IMU calibration report"
    sensor: str | None = None
    generated_by: str = "thermocal report"
    averaging_s: float | None = None
    channels: Sequence[str] | None = None
    extra: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    appendix: tuple[str, ...] = ()
    """Sections of HTML made by thermocal's report code (e.g.
    :func:`thermocal.report.tempcal.comparison_html`), shown before the warnings."""
    allan: bool = True
    """The Allan deviation section drawn (False: left out, not computed)."""


def _validation_of(v: Mapping[str, Any] | None, name: str, single: bool) -> dict[str, Any] | None:
    if not v:
        return None
    per = v.get("channels")
    if isinstance(per, Mapping):
        got = per.get(name)
        return dict(got) if isinstance(got, Mapping) else None
    if "bias_stability_before" in v and single:  # one channel's validate --json
        return dict(v)
    got = v.get(name)
    return dict(got) if isinstance(got, Mapping) else None


def _verdict(v: dict[str, Any] | None) -> tuple[str, str]:
    """(css class, text): pass/fail from a validation object; n/a without one."""
    if v is None:
        return "na", "no validation"
    text = v.get("verdict")
    if not isinstance(text, str):  # a one-channel validate --json: the same rule
        imp = (v.get("improvement_pct") or {}).get("rms")
        if v.get("r") is not None and v.get("weakly_correlated") is False:
            text = "NOT weakly correlated"
        elif not isinstance(imp, int | float):
            text = "—"
        else:
            text = "improved" if imp > 0 else "NOT improved"
    if text == "—":
        return "na", "no figures to compare"
    return ("pass" if text == "improved" else "fail"), text


def _figures_in(stab: float | None, slope: float | None, k: float) -> dict[str, float | None]:
    """Bias stability and temperature sensitivity (canonical unit,
    :func:`thermocal.report.analysis.shown_figures`) in the data's unit
    (``value[data] = value[canonical] / k``)."""

    def div(v: float | None) -> float | None:
        return None if v is None else float(v) / k

    return {"bias_stability": div(stab), "sensitivity_slope": div(slope)}


def _channel_merits(
    rec: Any, applied: Any, k: float, unit: str, averaging_s: float, tau0: float | None
) -> tuple[list[dict[str, float | None]], list[Any], list[str]]:
    """One channel's figures of merit (in the data's unit) and Allan deviations before and
    after compensation (none when ``tau0`` is None: not asked for), and the warnings raised
    while computing them (one line each)."""
    before, after = applied.before / k, applied.after / k
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        shown = shown_figures(
            rec.time_s,
            (applied.before, applied.after),
            applied.unit,
            averaging_s=averaging_s,
            meta=rec.meta,
            temp_name=applied.temp_names[0],
            temp_c=applied.temps_c[:, 0],
        )
        fom = [_figures_in(stab, slope, k) for stab, slope in shown]
        allan = (
            [] if tau0 is None else [allan_of(rec.time_s, x, tau0, unit) for x in (before, after)]
        )
    return fom, allan, [warning_text(w.message) for w in caught]


def _channel_notes(
    cond: Any, v: dict[str, Any] | None, unit: str, adequacy: dict[str, Any] | None
) -> list[str]:
    """A channel's warnings from its files: an ill-conditioned fit, the validation
    result's warnings and unit, a failed (or overridden) adequacy test."""
    msgs: list[str] = []
    if isinstance(cond, int | float) and cond > ILL_CONDITIONED:
        msgs.append(f"the fit's design is ill conditioned (condition number {cond:.3g})")
    if v is not None:
        msgs += [str(w) for w in v.get("warnings") or []]
        if v.get("unit") not in (None, unit):
            msgs.append(f"the validation figures are in {v.get('unit')}, the data in {unit}")
    if adequacy is not None and adequacy["verdict"] in ("fail", "overridden"):
        failed = ", ".join(t["name"] for t in adequacy["tests"] if t["verdict"] == "fail")
        msgs.append(
            f"the data this channel was fitted on failed the adequacy test(s) {failed or '—'}"
            + (" (overridden at fit time)" if adequacy["verdict"] == "overridden" else "")
        )
    return msgs


def _absolute_change(v: dict[str, Any] | None, key: str) -> Any:
    """The change of the error against the reference (rms about zero, beside the
    scatter about the mean) as :func:`change_html` shows it, or None
    without both figures."""
    b, a = (v or {}).get("rms_about_zero_before"), (v or {}).get("rms_about_zero_after")
    if b is None or a is None:
        return None
    imp = improvement_pct(abs(b), abs(a))
    return change_html(b, a, imp, f"{key}.validation.rms_about_zero_improvement_pct")


def _channel_section(
    inputs: CalibrationReportInputs, name: str, averaging_s: float, tau0: float
) -> dict[str, Any]:
    """Everything shown for one channel (figures computed on the full data)."""
    from thermocal.report import figures as F

    ch = inputs.calibration.channel(name)
    md = model_file_dict(ch.model)
    rec = inputs.recording
    if ch.signal not in rec.columns:
        raise ThermocalInputError(
            f"{inputs.recording_path or rec.source}: no column {ch.signal!r} for channel "
            f"{name!r}; available: " + ", ".join(repr(c) for c in rec.columns)
        )
    applied = apply_model(md, rec, ch.signal)  # canonical unit ([°/h] or [mg])
    # back to the data column's own unit: value[canonical] = k · value[data]
    unit = rec.units.get(ch.signal) or applied.unit
    k = unit_factor(unit, applied.unit, meta=rec.meta, where=f"channel {name}")
    before, after = applied.before / k, applied.after / k
    t_name = applied.temp_names[0]
    t_c = applied.temps_c[:, 0]
    fom, allan, caught = _channel_merits(
        rec, applied, k, unit, averaging_s, tau0 if inputs.allan else None
    )
    stats = md.get("fit") or {}
    cond = stats.get("condition_number")
    rms_fit = stats.get("rms_residual")
    if isinstance(rms_fit, int | float):  # model unit → data unit
        rms_fit = float(rms_fit) / unit_factor(unit, ch.model.signal_unit, meta=rec.meta)
    v = _validation_of(inputs.validation, name, len(inputs.calibration.channels) == 1)
    adequacy = adequacy_rows(md.get("adequacy"), f"channels.{name}.adequacy", name)
    msgs = [*applied.warnings, *caught, *_channel_notes(cond, v, unit, adequacy)]
    vclass, vtext = _verdict(v)
    role = ch.role or {}
    key = f"channels.{name}"
    return {
        "name": name,
        "anchor": "ch-" + "".join(c if c.isalnum() else "-" for c in name),
        "signal": ch.signal,
        "unit": unit,
        "unit_label": unit_label(unit),
        "role": " ".join(str(role[k]) for k in ("kind", "axis", "instance") if role.get(k)),
        "family": md.get("family", ""),
        "n_coefficients": stats.get("n_coefficients"),
        "rms_residual": rms_fit,
        "condition_number": cond,
        "temperatures": list(applied.temp_names),
        "temp_range": _range_rows(md, key),
        "coefficients": _coefficient_rows(md, key, unit),
        "before": fom[0],
        "after": fom[1],
        "sensitivity_unit": unit_label(f"{unit}/degC"),
        "sensitivity_improvement": improvement_pct(
            *(
                abs(f["sensitivity_slope"]) if f["sensitivity_slope"] is not None else None
                for f in fom
            )
        ),
        "stability_improvement": improvement_pct(
            fom[0]["bias_stability"], fom[1]["bias_stability"]
        ),
        **_noise_terms(name, unit, allan),
        "validation": v,
        "absolute_change": _absolute_change(v, key),
        "adequacy": adequacy,
        "verdict_class": vclass,
        "verdict": vtext,
        "warnings": list(dict.fromkeys(msgs)),
        "extra": {k: vals.get(name) for k, vals in inputs.extra.items()},
        "_bias": F.ChannelBias(name, unit_label(unit), t_name, t_c, before, after),
    }


def _noise_terms(name: str, unit: str, allan: list[Any]) -> dict[str, Any]:
    """The Allan section's entries of a channel (none without its Allan deviations)."""
    from thermocal.report import figures as F

    if not allan:
        return {}
    terms = [a.terms.fit for a in allan]
    curves = [
        F.AllanCurve(lab, a.result.tau_s, a.result.adev, a.result.adev_low, a.result.adev_high)
        for lab, a in zip(("before", "after"), allan, strict=True)
    ]
    return {
        # IEEE Std 952-1997 Annex C: B at the curve's minimum, always; N on the −½ stretch
        "bi_before": allan[0].terms.bias_minimum or terms[0].bias_instability,
        "bi_after": allan[1].terms.bias_minimum or terms[1].bias_instability,
        "rw_after": (
            allan[1].terms.slope.angle_random_walk
            if allan[1].terms.slope.angle_random_walk.value is not None
            else terms[1].angle_random_walk
        ),
        "_allan": (name, unit_label(unit), curves),
    }


def build_calibration_report(inputs: CalibrationReportInputs) -> str:
    """The calibration report as one self-contained HTML document (module docstring).

    Parameters
    ----------
    inputs : CalibrationReportInputs
        The calibration, the validation run and the optional ``validate`` JSON.

    Returns
    -------
    str
        The HTML document.
    """
    from thermocal import __version__
    from thermocal.report import figures as F

    cal = inputs.calibration
    names = list(inputs.channels or cal.names)
    unknown = [n for n in names if n not in cal.names]
    if unknown:
        raise ThermocalInputError(
            f"no channel {', '.join(map(repr, unknown))} in the calibration; it has "
            + ", ".join(cal.names)
        )
    rec = inputs.recording
    if inputs.validation and isinstance(inputs.validation.get("channels"), Mapping):
        first: Mapping[str, Any] = next(iter(inputs.validation["channels"].values()), {}) or {}
        default_avg = first.get("averaging_s")
    else:
        default_avg = (inputs.validation or {}).get("averaging_s")
    averaging_s = float(inputs.averaging_s or default_avg or DEFAULT_AVERAGING_S)
    averaging_s, avg_note = averaging_for(
        rec.time_s, averaging_s, given=inputs.averaging_s is not None,
        where=inputs.recording_path or rec.source or rec.name, parameter="averaging_s",
    )  # fmt: skip
    # several axes: the earth rate differs per axis, so none is removed (stated below)
    notes = list(inputs.notes) + ([avg_note] if avg_note else [])
    if rec.meta.latitude_deg is not None and len(names) > 1:
        notes.append(
            "The earth rate is not removed from gyro channels in this report (each axis "
            "sees a different share of it); biases are the sensor's output."
        )
        rec = dataclasses.replace(
            rec, meta=dataclasses.replace(rec.meta, latitude_deg=None, axis=None)
        )
        inputs = dataclasses.replace(inputs, recording=rec)
    tau0 = rec.sample_interval_s
    sections = [_channel_section(inputs, n, averaging_s, tau0) for n in names]
    grid = F.bias_vs_temperature_grid([s.pop("_bias") for s in sections])
    allan = F.allan_grid([s.pop("_allan") for s in sections]) if inputs.allan else None
    files = [
        (label, path, sha256_of(path))
        for label, path in (
            ("calibration", inputs.calibration_path),
            (
                "validation run" if inputs.validation else "recording (test run)",
                inputs.recording_path,
            ),
            ("modelling run", inputs.modeling_path),
            ("validation result", inputs.validation_path),
        )
        if path
    ]
    warned: dict[str, list[str]] = {}  # each warning once, with the channels it concerns
    for sec in sections:
        for w in sec["warnings"]:
            warned.setdefault(w, []).append(sec["name"])
    html: str = (
        _env()
        .get_template("calibration.html.j2")
        .render(
            title=inputs.title,
            sensor=inputs.sensor,
            version=__version__,
            generated_utc=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
            generated_by=inputs.generated_by,
            channels=sections,
            extra_titles=list(inputs.extra),
            has_validation=any(s["validation"] is not None for s in sections),
            averaging_s=averaging_s,
            n_samples=rec.time_s.size,
            duration_h=float(rec.time_s[-1] - rec.time_s[0]) / 3600.0,
            coverage=coverage_of(rec.time_s, tau0),
            tau0=tau0,
            warning_list=[(w, chans) for w, chans in warned.items()],
            grid=_b64(grid),
            allan=_b64(allan) if allan is not None else None,
            files=files,
            notes=notes,
            appendix=list(inputs.appendix),
            any_warnings=any(s["warnings"] for s in sections),
        )
    )
    return html


def write_calibration_report(path: str | Path, inputs: CalibrationReportInputs) -> Path:
    """Build the calibration report and write it atomically to ``path``; returns the path.

    Parameters
    ----------
    path : str or pathlib.Path
        The HTML file.
    inputs : CalibrationReportInputs
        As :func:`build_calibration_report`.

    Returns
    -------
    pathlib.Path
    """
    return write_html(path, build_calibration_report(inputs))


__all__ = [
    "CalibrationReportInputs",
    "build_calibration_report",
    "write_calibration_report",
]
