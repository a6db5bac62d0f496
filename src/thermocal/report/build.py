"""Build the self-contained HTML report of a temperature-compensation workflow.

The report gathers, for one sensor, what an engineer sends a customer (the
ring-laser-gyro method's figures, model and validation): test conditions and data provenance,
the chamber profile and
temperature channels, the bias against time and temperature before and after
compensation, the validation table on a weakly correlated test (r, stages,
stability, repeatability, improvement), Allan deviation before and after with
its noise terms, the drift angle, the model coefficients with standard errors
and their range of validity, and every warning (extrapolation, correlation
limit not met, ill-conditioning).

Inputs are what the other commands write: model files (:func:`save_model`
JSON), validation JSON (what the ``validate`` command prints) and recordings.  Every
number that also appears in one of those JSON files is shown from the JSON
itself (never recomputed), tagged ``data-key``/``data-value`` in the HTML so
a test can check it.  The report is one HTML file: figures are embedded as
base64 PNG, the CSS is inline, there is no script from the network (a
Content-Security-Policy forbids every external load).

Public API: :class:`ModelEntry`, :class:`ReportInputs`, :func:`build_report`
(→ HTML text) and :func:`write_report` (atomic write).
"""

from __future__ import annotations

import base64
import datetime as _dt
import functools
import math
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeGuard

import numpy as np
from markupsafe import Markup, escape

from thermocal import units
from thermocal.defaults import DEFAULT_AVERAGING_S, WEAK_CORRELATION_LIMIT
from thermocal.errors import ThermocalInputError, ThermocalWarning
from thermocal.metrics import data_unit_of
from thermocal.models.results import condition_wording
from thermocal.pipeline.messages import warning_text
from thermocal.readers.common import sha256_of
from thermocal.recording import Recording
from thermocal.report.analysis import (
    NOISE_TERMS as NOISE_TERMS,
)
from thermocal.report.analysis import (
    AllanAnalysis as AllanAnalysis,
)
from thermocal.report.analysis import (
    FiguresOfMerit as FiguresOfMerit,
)
from thermocal.report.analysis import (
    RunSignals as RunSignals,
)
from thermocal.report.analysis import (  # the numbers, re-exported
    allan_of as allan_of,
)
from thermocal.report.analysis import (
    apply_model as apply_model,
)
from thermocal.report.analysis import (
    figures_of_merit as figures_of_merit,
)
from thermocal.report.analysis import (
    in_data_unit as in_data_unit,
)
from thermocal.report.analysis import (
    known_input_of as known_input_of,
)
from thermocal.stability.allan import DynamicAllan
from thermocal.stability.noise_model import (
    OutputQuantization,
    annotate_quantization,
    output_quantization,
)
from thermocal.writers import write_html

ILL_CONDITIONED = 1.0e6
"""Condition number (scaled design) above which the report warns: ill-conditioned in the
words of :func:`thermocal.models.results.condition_wording`."""


# --- inputs ------------------------------------------------------------------------------


@dataclass(frozen=True)
class ModelEntry:
    """One fitted model in the report.

    Parameters
    ----------
    label : str
        A short name shown in tables.
    model : dict
        The content of a model file (as :func:`thermocal.save_model` writes it).
    validation : dict, optional
        The JSON object of the ``validate`` command for that model on the validation
        run.
    path : str, optional
        The model file (provenance).
    """

    label: str
    model: dict[str, Any]
    validation: dict[str, Any] | None = None
    path: str | None = None


@dataclass(frozen=True)
class ReportInputs:
    """Everything :func:`build_report` needs.

    Parameters
    ----------
    models : tuple of ModelEntry
        Fitted models; the first is the primary model, shown in detail (figures,
        coefficients); every model appears in the comparison table.
    recording : Recording
        The validation run (the models are applied to it).
    modeling : Recording, optional
        The modelling run (profile and fit figures).
    signal : str, optional
        Signal column of the recordings (default: the model's signal name).
    recording_path, modeling_path : str, optional
        Files the runs were read from (provenance, SHA-256 shown).
    title, sensor : str
        Headline texts.
    warnings : tuple of str
        Extra warning lines to show (e.g. caught while fitting).
    notes : tuple of str
        Free text paragraphs under "Test conditions".
    files : tuple of (str, str)
        Other produced files (label, path) listed in the provenance table.
    generated_by : str
        The command that made the report.
    averaging_s : float, optional
        Averaging time of the computed figures [s].
    drift_reference_s : tuple of float, optional
        Window [s since the first sample] whose mean is the drift angle's b0 before
        compensation.
    drift_bias : float, optional
        That b0 [the data's unit] instead of a window.
    dynamic_s : float, optional
        Window [s] of the dynamic Allan deviation of the compensated output.
    ratetable : RateTableResult, optional
        A rate-table test of the sensor (``thermocal ratetable``): its spec sheet as a section.
    """

    models: tuple[ModelEntry, ...]
    recording: Recording
    modeling: Recording | None = None
    signal: str | None = None
    recording_path: str | None = None
    modeling_path: str | None = None
    title: str = "Temperature compensation report"
    sensor: str | None = None
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    files: tuple[tuple[str, str], ...] = ()
    generated_by: str = "thermocal report"
    averaging_s: float | None = None
    """Averaging time of bias stability and peak-to-peak [s] (default: the validation
    result's, else :data:`DEFAULT_AVERAGING_S`)."""
    extra: dict[str, Any] = field(default_factory=dict)
    drift_reference_s: tuple[float, float] | None = None
    """Drift angle before compensation: b0 is the mean over this window [s since the first
    sample] (default the first 10 % of the run)."""
    drift_bias: float | None = None
    """Drift angle before compensation: this b0 [the data's unit] instead of a window."""
    warnings_caught: tuple[str, ...] = ()
    """``warning:`` lines thermocal printed while reading the runs (shown in the report)."""
    dynamic_s: float | None = None
    """Window [s] of the dynamic Allan deviation of the compensated output
    (:func:`thermocal.stability.allan.dynamic_adev`, half-window steps); None: none."""
    ratetable: Any = None
    """A :class:`thermocal.pipeline.ratetable.RateTableResult`: its spec sheet as a section."""


# --- number formatting -------------------------------------------------------------------


def fmt_num(value: Any, digits: int = 4) -> str:
    """A number as shown in the report: ``digits`` significant digits, ``—`` for none/NaN.

    Integers are shown whole.  Very large or small magnitudes use an exponent
    (``1.234e-05``).

    Parameters
    ----------
    value : object
        A number, a bool, None or NaN.
    digits : int
        Significant digits.

    Returns
    -------
    str

    Examples
    --------
    >>> fmt_num(0.123456), fmt_num(1.5e-5), fmt_num(7), fmt_num(float("nan"))
    ('0.1235', '1.500e-05', '7', '—')
    """
    if value is None or isinstance(value, bool):
        return "—" if value is None else ("yes" if value else "no")
    if isinstance(value, int | np.integer):
        return str(int(value))
    x = float(value)
    if not math.isfinite(x):
        return "—"
    if x == 0.0:
        return "0"
    mag = abs(x)
    if mag >= 1e6 or mag < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def num(value: Any, key: str | None = None, digits: int = 4, unit: str = "") -> Markup:
    """HTML for a number; with ``key`` tagged ``data-key``/``data-value`` (full precision).

    Parameters
    ----------
    value : object
        The number.
    key : str, optional
        The key tagged on the element (tests and scrapers read it).
    digits : int
        Significant digits shown.
    unit : str
        Unit shown after it.

    Returns
    -------
    markupsafe.Markup
    """
    text = fmt_num(value, digits)
    attrs = ""
    if key is not None:
        raw = "" if value is None else repr(float(value)) if _is_number(value) else str(value)
        attrs = f' data-key="{escape(key)}" data-value="{escape(raw)}"'
    u = f'<span class="unit">&thinsp;{escape(unit)}</span>' if unit and text != "—" else ""
    return Markup(f'<span class="num"{attrs}>{escape(text)}</span>{u}')


def _is_number(v: Any) -> TypeGuard[float | int]:
    return isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool)


def improvement_pct(before: Any, after: Any) -> float | None:
    """Improvement ``100 · (1 − after/before)`` [%] (None when not computable).

    Parameters
    ----------
    before, after : float
        A figure before and after compensation (same unit).

    Returns
    -------
    float or None
        The improvement [%]; None when either is missing or not finite, or ``before`` is 0.

    Examples
    --------
    >>> improvement_pct(2.0, 0.5), improvement_pct(0.0, 1.0)
    (75.0, None)
    """
    if not (_is_number(before) and _is_number(after)):
        return None
    b, a = float(before), float(after)
    if not (math.isfinite(a) and math.isfinite(b)) or b == 0.0:
        return None
    return 100.0 * (1.0 - a / b)


NO_CHANGE_REL = 1e-9
"""Before and after equal within this fraction of the larger: "no change", not a
percentage of rounding (not "Peak-to-peak −1.06e-13 %")."""


def no_change(before: Any, after: Any) -> bool:
    """Whether two figures are equal within :data:`NO_CHANGE_REL` of the larger
    (``|a − b| ≤ 1e-9 · max(|a|, |b|)``; both zero included).

    Parameters
    ----------
    before : float
        The figure before.
    after : float
        The figure after.

    Returns
    -------
    bool

    Examples
    --------
    >>> no_change(1.0, 1.0 + 1e-12), no_change(1.0, 0.99)
    (True, False)
    """
    if not (_is_number(before) and _is_number(after)):
        return False
    b, a = float(before), float(after)
    return (
        math.isfinite(a) and math.isfinite(b) and abs(a - b) <= NO_CHANGE_REL * max(abs(a), abs(b))
    )


def change_html(before: Any, after: Any, imp: float | None, key: str | None) -> Markup:
    """The improvement cell of ``before`` → ``after``: ``no change`` when they are equal
    (:func:`no_change`; tagged 0), else ``imp`` [%] (:func:`improvement_pct`).

    Parameters
    ----------
    before : float
        The figure before.
    after : float
        The figure after.
    imp : float or None
        The improvement [%] (:func:`improvement_pct`).
    key : str or None
        The key tagged on the element.

    Returns
    -------
    markupsafe.Markup
    """
    if no_change(before, after):
        attrs = f' data-key="{escape(key)}" data-value="0.0"' if key else ""
        return Markup(f'<span class="num"{attrs}>no change</span>')
    return num(imp, key, digits=3, unit="%")


def unit_label(unit: str) -> str:
    """Pretty unit for display (``deg/h`` → ``°/h``).

    Parameters
    ----------
    unit : str
        The data's unit (``"deg/h"``, ``"mg"``).

    Returns
    -------
    str
        The unit as printed (``°/h``, ``mg``, ``°C``).

    Examples
    --------
    >>> unit_label("deg/h")
    '°/h'
    """
    return {
        "deg/h": "°/h",
        "deg/s": "°/s",
        "degC": "°C",
        "deg/sqrt(h)": "°/√h",
        "deg/h/sqrt(h)": "°/h/√h",
        "deg/h/h": "°/h/h",
        "deg/h^2": "°/h²",
        "deg/h/s": "°/h/s",
        "ug/sqrt(Hz)": "µg/√Hz",
        "ug/sqrt(h)": "µg/√h",
        "ug/h": "µg/h",
        "ug": "µg",
        "deg": "°",
        "C/min": "°C/min",
    }.get(unit) or (
        unit.replace("degC", "°C")
        .replace("deg", "°")
        .replace("sqrt(h)", "√h")
        .replace("sqrt(Hz)", "√Hz")
        .replace("ug", "µg")
    )


# --- provenance ------------------------------------------------------------------------------


GAP_SHARE_WARN = 0.10
"""Share of a run's time span in gaps above which the report warns."""


def gap_share(rec: Recording) -> tuple[int, float, float]:
    """(number of gaps, their total length [s], their share of the time span).

    Parameters
    ----------
    rec : Recording
        The recording.

    Returns
    -------
    tuple of (int, float, float)
        Number of gaps, their total [s] and share of the span [%].
    """
    gaps = rec.gaps()
    total = float(sum(g.length_s for g in gaps))
    span = rec.duration_s
    return len(gaps), total, (total / span if span > 0 else 0.0)


def conversions_of(rec: Recording, signal: str | None, shown_unit: str) -> list[str]:
    """Every conversion applied to a run, in words: the time column's unit, the signal's
    unit as given (and where it came from) and the unit the report shows, a scale factor K
    of raw counts, each raw-count temperature's ``T = gain·counts + offset``.

    Parameters
    ----------
    rec : Recording
        The recording.
    signal : str, optional
        The signal column (default: the model's).
    shown_unit : str
        The unit the report shows.

    Returns
    -------
    list of str
        One line per conversion applied when the run was read.
    """
    src = rec.unit_sources
    out = [
        f"time: column in {rec.time_unit}"
        + (f" ({src['<time>']})" if src.get("<time>") else "")
        + ("" if rec.time_unit == "s" else ", converted to s")
    ]
    if signal:
        given = rec.units.get(signal, "") or "?"
        line = f"signal {signal}: {given}" + (f" ({src[signal]})" if src.get(signal) else "")
        if given == "counts" and rec.meta.scale_factor is not None:
            line += (
                f", converted with the scale factor K = {rec.meta.scale_factor:.10g} "
                f"{rec.meta.scale_factor_unit or ''}".rstrip()
            )
        line += f"; figures shown in {unit_label(shown_unit)}"
        out.append(line)
    for name in rec.temperatures:
        u = rec.units.get(name, "")
        conv = rec.meta.temperature_conversion.get(name)
        where = f" ({src[name]})" if src.get(name) else ""
        if conv is not None and u == "counts":
            out.append(f"temperature {name}: raw counts{where}, {conv.describe()}")
        else:
            shown = unit_label(u) if u else "unit not stated"
            out.append(f"temperature {name}: {shown}{where}")
    return out


def _run_info(
    role: str, rec: Recording, path: str | None, signal: str | None, shown_unit: str = ""
) -> dict[str, Any]:
    sig = signal if signal in rec.columns else (rec.signals[0] if rec.signals else None)
    n_gaps, gap_s, share = gap_share(rec)
    temps = [c for c in rec.temperatures if c in rec.columns]
    t_lo = t_hi = None
    if temps:
        tc = rec.temperatures_c(temps)
        t_lo, t_hi = float(np.min(tc)), float(np.max(tc))
    return {
        "role": role,
        "file": Path(path).name if path else (rec.source or rec.meta.run_id or "(in memory)"),
        "sha256": sha256_of(path) if path else None,
        "n_samples": rec.n_samples,
        "duration_h": rec.duration_s / 3600.0,
        "interval_s": rec.sample_interval_s,
        "n_gaps": n_gaps,
        "gap_s": gap_s,
        "gap_share_pct": 100.0 * share,
        "conversions": conversions_of(rec, sig, shown_unit or rec.units.get(sig or "", "")),
        "signal": sig,
        "signal_unit": unit_label(rec.units.get(sig, "")) if sig else "",
        "temperatures": ", ".join(temps),
        "temp_lo": t_lo,
        "temp_hi": t_hi,
        "sensor_id": rec.meta.sensor_id,
        "run_id": rec.meta.run_id,
        "latitude_deg": rec.meta.latitude_deg,
        "axis": rec.meta.axis,
        "notes": rec.meta.notes,
    }


# --- figures ----------------------------------------------------------------------------------


def _b64(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _chamber_column(rec: Recording, model_temps: Sequence[str]) -> str | None:
    for name in ("T_chamber", "chamber", "ambient", "T_ambient", "setpoint_c"):
        if name in rec.columns:
            return name
    others = [t for t in rec.temperatures if t not in model_temps and t in rec.columns]
    return others[0] if others else None


def _temperature_panel(title: str, rec: Recording, names: Sequence[str]) -> Any:
    from thermocal.report.figures import TemperaturePanel

    chamber = _chamber_column(rec, names)
    ordered = [*names, *(t for t in rec.temperatures if t not in names and t != chamber)]
    channels = {n: rec.temperature_c(n) for n in ordered if n in rec.columns}
    ch = None
    if chamber is not None:
        ch = rec.temperature_c(chamber) if chamber in rec.temperatures else rec.column(chamber)
    return TemperaturePanel(
        title=title, time_s=rec.time_s, channels=channels, chamber=ch, chamber_label=chamber or ""
    )


def _stages_from(validation: dict[str, Any] | None) -> list[tuple[float, float]]:
    if not validation:
        return []
    out: list[tuple[float, float]] = []
    for st in validation.get("stages") or []:
        if isinstance(st, dict):
            a = st.get("start_s")
            b = st.get("stop_s", st.get("end_s"))
            if _is_number(a) and _is_number(b):
                out.append((float(a), float(b)))
    return out


# --- the report -------------------------------------------------------------------------------


def _flag(ok: bool | None) -> str:
    return "na" if ok is None else ("pass" if ok else "fail")


def _json_improvement(v: dict[str, Any], name: str) -> float | None:
    """The validation file's ``improvement_pct[name]`` if it has one, else computed."""
    imp = v.get("improvement_pct")
    if isinstance(imp, dict) and name in imp:
        val = imp[name]
        return float(val) if _is_number(val) else None
    return improvement_pct(v.get(f"{name}_before"), v.get(f"{name}_after"))


def _validation_rows(entry: ModelEntry, unit: str) -> list[dict[str, Any]]:
    v = entry.validation or {}
    key = f"validation.{entry.label}"
    rows = []
    for name, label, u in (
        ("bias_stability", "Bias stability (within stages)", unit),
        ("bias_repeatability", "Bias repeatability (across stages)", unit),
        ("rms", "RMS of the bias", unit),
        ("peak_to_peak", "Peak-to-peak bias", unit),
    ):
        b = v.get(f"{name}_before")
        a = v.get(f"{name}_after")
        if b is None and a is None:
            continue
        imp = _json_improvement(v, name)
        rows.append(
            {
                "label": label,
                "unit": u,
                "before": num(b, f"{key}.{name}_before"),
                "after": num(a, f"{key}.{name}_after"),
                "improvement": change_html(b, a, imp, f"{key}.{name}_improvement_pct"),
                "flag": _flag(None if imp is None else imp > 0),
            }
        )
    return rows


def _stage_rows(entry: ModelEntry) -> list[dict[str, Any]]:
    """Per-stage rows of a validation result (``stages`` list of the JSON)."""
    rows = []
    key = f"validation.{entry.label}.stages"
    for i, st in enumerate((entry.validation or {}).get("stages") or []):
        if not isinstance(st, dict):
            continue
        a, b = st.get("start_s"), st.get("stop_s")
        rows.append(
            {
                "index": i + 1,
                "start_h": fmt_num(float(a) / 3600.0, 3) if _is_number(a) else "—",
                "duration_h": (
                    fmt_num((float(b) - float(a)) / 3600.0, 3)
                    if _is_number(a) and _is_number(b)
                    else "—"
                ),
                "temp": num(st.get("mean_temp_c"), None, 4),
                "bias_before": num(st.get("bias_before"), f"{key}.{i}.bias_before", 5),
                "bias_after": num(st.get("bias_after"), f"{key}.{i}.bias_after", 5),
                "stab_before": num(
                    st.get("bias_stability_before"), f"{key}.{i}.bias_stability_before"
                ),
                "stab_after": num(
                    st.get("bias_stability_after"), f"{key}.{i}.bias_stability_after"
                ),
            }
        )
    return rows


def _summary(
    primary: ModelEntry,
    fom_before: FiguresOfMerit,
    fom_after: FiguresOfMerit,
    unit: str,
) -> list[dict[str, Any]]:
    """Key figures for the summary block: label, before, after, improvement, flag."""
    v = primary.validation or {}
    key = f"validation.{primary.label}"
    items: list[dict[str, Any]] = []
    ok: bool | None
    r = v.get("r")
    if r is not None:
        weak = v.get("weakly_correlated")
        ok = bool(weak) if weak is not None else float(r) < WEAK_CORRELATION_LIMIT
        items.append(
            {
                "label": "Correlation r of the validation test",
                "value": num(r, f"{key}.r", digits=3),
                "note": f"limit r < {WEAK_CORRELATION_LIMIT}",
                "flag": _flag(ok),
                "flag_text": "weakly correlated" if ok else "too correlated",
            }
        )
    avg = fmt_num(v.get("averaging_s"))
    for name, label, definition in (
        ("bias_stability", "Bias stability",
         f"std of the {avg} s averages within each hold stage, rms over the stages"),
        ("bias_repeatability", "Bias repeatability", "std of the hold stages' mean biases"),
        ("peak_to_peak", "Peak-to-peak bias", f"max − min of the run's {avg} s averages"),
    ):  # fmt: skip
        b, a = v.get(f"{name}_before"), v.get(f"{name}_after")
        if b is None or a is None:
            continue
        imp = _json_improvement(v, name)
        same = no_change(b, a)
        ok = None if imp is None else imp > 0 and not same
        items.append(
            {
                "label": label,
                "before": num(b, f"{key}.{name}_before", unit=unit_label(unit)),
                "after": num(a, f"{key}.{name}_after", unit=unit_label(unit)),
                "value": change_html(b, a, imp, f"{key}.{name}_improvement_pct"),
                "note": f"improvement; {definition}, before and after (validate)",
                "flag": _flag(ok),
                "flag_text": "no change" if same else "improved" if ok else "not improved",
            }
        )
    b, a = v.get("rms_about_zero_before"), v.get("rms_about_zero_after")
    if b is not None and a is not None:  # what the user sees: worse fails
        worse = bool(v.get("absolute_error_worse"))
        imp = improvement_pct(float(b), float(a))
        items.append(
            {
                "label": "Error about zero (rms per sample)",
                "before": num(b, f"{key}.rms_about_zero_before", unit=unit_label(unit)),
                "after": num(a, f"{key}.rms_about_zero_after", unit=unit_label(unit)),
                "value": change_html(b, a, imp, f"{key}.rms_about_zero_improvement_pct"),
                "note": "improvement; rms of (output − reference) per sample, reference "
                + str((v.get("zero_reference") or {}).get("what") or "0")
                + ", before and after (validate)",
                "flag": _flag(not worse),
                "flag_text": "absolute error worse" if worse else "not worse",
            }
        )
    items += _drift_cards(fom_before, fom_after)
    return items


def _drift_cards(fom_before: FiguresOfMerit, fom_after: FiguresOfMerit) -> list[dict[str, Any]]:
    """The drift-angle cards of the summary, each comparing one definition before and
    after: the start bias removed (each series' b0 over the same window, or a
    given b0 before), and no bias removed.  Improvement ``100·(1 − after/before)``."""
    items: list[dict[str, Any]] = []
    ref = drift_reference_words(fom_before.drift_reference)
    for label, attr, key, note in (
        ("Largest drift angle, start bias removed", "drift_angle_max_deg", "drift_angle",
         f"θ = ∫ (ω − Ω − b0) dt, before: {ref}; after: the same for the compensated rate"),
        ("Largest drift angle, no bias removed", "drift_angle_raw_max_deg", "drift_angle_raw",
         "θ = ∫ (ω − Ω) dt, before and after"),
    ):  # fmt: skip
        b, a = getattr(fom_before, attr), getattr(fom_after, attr)
        if b is None or a is None:
            continue
        imp = improvement_pct(b, a)
        same = no_change(b, a)
        ok = None if imp is None else imp > 0 and not same
        items.append(
            {
                "label": label,
                "before": num(b, f"fom.before.{attr}", unit="°"),
                "after": num(a, f"fom.after.{attr}", unit="°"),
                "value": change_html(b, a, imp, f"summary.{key}_improvement_pct"),
                "note": f"improvement; {note}",
                "flag": _flag(ok),
                "flag_text": "no change" if same else "improved" if ok else "not improved",
            }
        )
    return items


def model_factor(model: dict[str, Any], unit: str | None) -> tuple[str, float]:
    """(the model's signal unit, k) with ``value[model unit] = k · value[unit]``; k = 1 when
    ``unit`` is not given, equal, or of another kind (counts).

    Parameters
    ----------
    model : dict
        The content of a model file.
    unit : str or None
        The data's unit.

    Returns
    -------
    tuple of (str, float)
        The shown unit and the factor from the model's unit.
    """
    mu = str((model.get("signal") or {}).get("unit") or "")
    if not mu:
        return mu, 1.0
    return mu, units.shown_unit(mu, unit).to_model


def _coefficient_rows(
    model: dict[str, Any], key: str = "model", unit: str | None = None
) -> list[dict[str, Any]]:
    """The coefficients with their standard errors; with ``unit`` (the data's) every
    coefficient whose unit starts with the model's signal unit is converted to it
    (``deg/h/degC`` → ``deg/s/degC`` for °/s data: value / k)."""
    mu, k = model_factor(model, unit)
    rows = []
    for i, entry in enumerate(model.get("coefficients") or []):
        c = entry if isinstance(entry, dict) else {}  # the list is informative: shown as is
        val = c.get("value")
        se = c.get("stderr")
        cunit = str(c.get("unit", ""))
        if k != 1.0 and unit and cunit.startswith(mu):
            val = float(val) / k if _is_number(val) else val
            se = float(se) / k if _is_number(se) else se
            cunit = unit + cunit[len(mu) :]
        rel = None
        if _is_number(val) and _is_number(se) and float(val) != 0.0:
            rel = 100.0 * abs(float(se) / float(val))
        rows.append(
            {
                "i": i,
                "name": c.get("name", f"a{i}"),
                "value": num(val, f"{key}.coefficients.{i}.value", digits=6),
                "stderr": num(se, f"{key}.coefficients.{i}.stderr", digits=3),
                "rel": num(rel, None, digits=3),
                "unit": unit_label(cunit),
            }
        )
    return rows


def _range_rows(model: dict[str, Any], key: str = "model") -> list[dict[str, Any]]:
    rng = model.get("range") or {}
    tr = rng.get("temperature_c") or {}
    rr = rng.get("rate_c_per_min") or {}
    rows = []
    for name in model.get("temperatures", []):
        t = tr.get(name) or [None, None]
        r = rr.get(name) or [None, None]
        rows.append(
            {
                "name": name,
                "t_lo": num(t[0], f"{key}.range.temperature_c.{name}.0", digits=4),
                "t_hi": num(t[1], f"{key}.range.temperature_c.{name}.1", digits=4),
                "r_lo": num(r[0], None, digits=3),
                "r_hi": num(r[1], None, digits=3),
            }
        )
    return rows


def _model_summary(entry: ModelEntry, unit: str | None = None) -> dict[str, Any]:
    """One model's summary; with ``unit`` (the data's) its fit residual is converted to it."""
    m = entry.model
    fit = m.get("fit") or {}
    _mu, k_fit = model_factor(m, unit)
    rms_fit = fit.get("rms_residual")
    if _is_number(rms_fit):
        rms_fit = float(rms_fit) / k_fit
    params = m.get("params") or {}
    rate = m.get("rate") or {}
    cond = fit.get("condition_number")
    return {
        "label": entry.label,
        "family": m.get("family"),
        "n_coefficients": num(len(m.get("coefficients") or []), f"models.{entry.label}.n_coef"),
        "rms_residual": num(rms_fit, f"models.{entry.label}.rms_residual"),
        "condition_number": num(cond, f"models.{entry.label}.condition_number", digits=3),
        "r_squared": num(fit.get("r_squared"), None, digits=5),
        "n_samples": num(fit.get("n_samples"), None),
        "rate": (
            f"{rate.get('method', '')}, Δt = {fmt_num(rate.get('interval_s'))} s" if rate else "—"
        ),
        "params": ", ".join(
            f"{k}={v}" for k, v in params.items() if v is not None and not isinstance(v, list)
        ),
        "terms": params.get("terms") if isinstance(params.get("terms"), str) else None,
        "path": Path(entry.path).name if entry.path else "",
        "sha256": sha256_of(entry.path) if entry.path else None,
        "checksum": m.get("checksum"),
        "created": m.get("created_utc"),
        "version": m.get("thermocal_version"),
        "ill_conditioned": _is_number(cond) and float(cond) > ILL_CONDITIONED,
        "condition_words": condition_wording(float(cond) if _is_number(cond) else None),
        "offset_note": (fit.get("offset_decision") or {}).get("reason"),
        "effective_samples": num(
            (fit.get("residual_correlation") or {}).get("n_effective"), None, digits=3
        ),
    }


def _model_details(inputs: ReportInputs, unit: str | None = None) -> list[dict[str, Any]]:
    """Section 8 for every model given: its fit, range of validity and coefficients."""
    out = []
    for i, e in enumerate(inputs.models):
        key = "model" if i == 0 else f"models.{e.label}"
        out.append(
            {
                "summary": _model_summary(e, unit),
                "ranges": _range_rows(e.model, key),
                "coefficients": _coefficient_rows(e.model, key, unit),
                "has_rates": bool((e.model.get("range") or {}).get("rate_c_per_min")),
                "suffix": "" if i == 0 else f"-{i + 1}",
                "primary": i == 0,
            }
        )
    return out


TRUTH_COLUMN = "truth_bias"
"""Column of the simulator's true temperature-induced bias (thermocal.simulate)."""


def _truth_rows(
    inputs: ReportInputs, applied: dict[str, RunSignals], unit: str
) -> list[dict[str, Any]]:
    """Model error against the simulator's truth (simulated data only).

    ``e = (ŷ − mean ŷ) − (E − mean E)`` with ŷ the model on the bias scale and E
    the ``truth_bias`` column; reported: rms(e) and the share of the
    temperature-induced bias removed, ``100 (1 − rms(e)/std(E))`` [%].
    """
    rec = inputs.recording
    if TRUTH_COLUMN not in rec.columns:
        return []
    truth = rec.column(TRUTH_COLUMN)
    sd = float(np.std(truth))
    rows = []
    for e in inputs.models:
        sig = applied[e.label]
        err = (sig.model_bias - np.mean(sig.model_bias)) - (truth - np.mean(truth))
        rms = float(np.sqrt(np.mean(err**2)))
        removed = 100.0 * (1.0 - rms / sd) if sd > 0 else None
        rows.append(
            {
                "label": e.label,
                "rms": num(rms, f"truth.{e.label}.rms_error", unit=unit_label(unit)),
                "removed": num(removed, f"truth.{e.label}.removed_pct", 3),
            }
        )
    return rows


def _core(text: str, labels: Sequence[str]) -> str:
    """A warning's text without the prefixes the report and the commands put before it
    (``warning:``, ``label:``, ``label on the … run:``, ``FILE:``), normalised, so that one
    finding said by several sources is shown once."""
    t = " ".join(text.split())
    alts = "|".join(re.escape(lab) for lab in sorted(labels, key=len, reverse=True))
    pattern = re.compile(
        r"^(?:warning: |(?:" + (alts or "(?!)") + r")(?: on the [a-z]+ run)?: "
        r"|[^:\s]+\.(?:csv|parquet|ulg|bin|txt|log|json)(?: \[[^\]]*\])?: )",
        re.IGNORECASE,
    )
    while True:
        new = pattern.sub("", t, count=1)
        if new == t:
            break
        t = new
    return t.rstrip(". ").lower()


def _adequacy_of(entry: ModelEntry) -> dict[str, Any] | None:
    """The model file's ``adequacy`` record (see the adequacy check) as table rows, or None
    for files without one."""
    return adequacy_rows(entry.model.get("adequacy"), f"adequacy.{entry.label}", entry.label)


def adequacy_rows(ad: Any, key: str, label: str) -> dict[str, Any] | None:
    """``{"label", "verdict", "overrides", "tests": [{name, figure, threshold, unit,
    verdict, override, message}]}`` from an ``adequacy`` record; None when there is none.

    Parameters
    ----------
    ad : dict
        The model file's adequacy record.
    key : str
        The row's key.
    label : str
        The row's label.

    Returns
    -------
    dict or None
    """
    if not isinstance(ad, dict):
        return None
    tests = []
    for i, t in enumerate(ad.get("tests") or []):
        if not isinstance(t, dict):
            continue
        u = str(t.get("unit") or "")
        tests.append(
            {
                "name": str(t.get("name", f"test {i + 1}")),
                "figure": num(t.get("figure") if _is_number(t.get("figure")) else None,
                              f"{key}.{t.get('name', i)}.figure", 4, unit_label(u)),
                "threshold": num(t.get("threshold") if _is_number(t.get("threshold")) else None,
                                 f"{key}.{t.get('name', i)}.threshold", 4, unit_label(u)),
                "verdict": str(t.get("verdict") or "n/a"),
                "override": t.get("override") or "",
                "message": str(t.get("message") or ""),
            }
        )  # fmt: skip
    verdict = str(ad.get("verdict") or "n/a")
    return {
        "label": label,
        "verdict": verdict,
        "overrides": [str(o) for o in ad.get("overrides") or []],
        "tests": tests,
        "css": {"pass": "pass", "fail": "fail", "overridden": "warn"}.get(verdict, "na"),
    }


def _collect_warnings(
    inputs: ReportInputs,
    applied: dict[str, RunSignals],
    an: _Analysis | None = None,
    runs: Sequence[dict[str, Any]] = (),
    run_warnings: Sequence[str] = (),
) -> list[dict[str, str]]:
    """Every warning once (:func:`_core` compares them): the validation results', the
    models' (conditioning, adequacy), extrapolation, what thermocal printed while reading
    and analysing the runs, gaps, and a recording that is the modelling data itself."""
    out: list[dict[str, str]] = []
    seen: set[str] = set()
    labels = [e.label for e in inputs.models]

    def add(kind: str, text: str) -> None:
        key = _core(text, labels)
        if key not in seen and not any(key in k or k in key for k in seen if len(k) > 20):
            seen.add(key)
            out.append({"kind": kind, "text": text})

    if an is not None and an.role == "modelling":
        add(
            "data",
            "the recording is the data the model was fitted on (the modelling run): the "
            "figures below show how well the model fits, not how it performs on an "
            "independent run.",
        )
    for run in runs:
        if run.get("gap_share_pct", 0.0) > 100.0 * GAP_SHARE_WARN:
            add(
                "data",
                f"{run['file']} ({run['role']} run): {run['n_gaps']} gap(s) cover "
                f"{fmt_num(run['gap_share_pct'], 3)} % of its {fmt_num(run['duration_h'], 3)} h; "
                "the figures use only the samples recorded.",
            )
    for w in inputs.warnings_caught:
        add("input", w)
    for w in run_warnings:
        add("analysis", w)
    for entry in inputs.models:
        ad = _adequacy_of(entry)
        if ad is not None and ad["verdict"] in ("fail", "overridden"):
            failed = ", ".join(t["name"] for t in ad["tests"] if t["verdict"] == "fail")
            add(
                "adequacy",
                f"{entry.label}: the data it was fitted on "
                + ("failed" if ad["verdict"] == "fail" else "failed (overridden at fit time by "
                   + (", ".join(ad["overrides"]) or "an override") + ")")
                + f" the adequacy test(s) {failed or '—'}; see the adequacy table.",
            )  # fmt: skip

    for entry in inputs.models:
        v = entry.validation or {}
        r = v.get("r")
        weak = v.get("weakly_correlated")
        if r is not None and (weak is False or (weak is None and r >= WEAK_CORRELATION_LIMIT)):
            add(
                "correlation",
                f"{entry.label}: the validation test is not weakly correlated with the "
                f"modelling test (r = {fmt_num(r, 3)}, limit r < {WEAK_CORRELATION_LIMIT}); "
                "the validation result may be optimistic.",
            )
        for w in v.get("warnings") or []:
            add("validation", f"{entry.label}: {w}")
        cond = (entry.model.get("fit") or {}).get("condition_number")
        if _is_number(cond) and float(cond) > ILL_CONDITIONED:
            add(
                "conditioning",
                f"{entry.label}: the scaled design is {condition_wording(float(cond))} "
                f"(condition number {fmt_num(cond, 3)}); individual coefficients are poorly "
                "determined, prefer a term-selected or ridge model.",
            )
        sig = applied.get(entry.label)
        if sig is not None:
            for w in sig.warnings:
                where = an.run_name if an is not None else "validation run"
                add("extrapolation", f"{entry.label} on the {where}: {w}")
    if inputs.models and not inputs.models[0].validation:
        add(
            "validation",
            "no validation result was given (thermocal validate --json, then --validation): "
            # cli-words: the commands the report tells its reader to run
            "the report shows figures computed on the recording and states no acceptance "
            "verdict.",
        )
    for w in inputs.warnings:
        add("workflow", w)
    return out


@functools.cache  # one environment: each template compiled once per process, not per report
def _env() -> Any:
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("thermocal.report", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        trim_blocks=True,
        lstrip_blocks=True,
        undefined=jinja2.StrictUndefined,
    )
    env.filters["num"] = num
    env.filters["fmt"] = fmt_num
    env.filters["unit"] = unit_label
    return env


@dataclass(frozen=True)
class _Analysis:
    """The numbers behind the report: each model applied to the validation run, and the
    primary model's figures of merit and Allan deviation before and after."""

    primary: ModelEntry
    signal: str | None
    unit: str
    applied: dict[str, RunSignals]
    main: RunSignals
    temp_names: tuple[str, ...]
    averaging_s: float
    tau0: float
    stage_temp: str
    fom_before: FiguresOfMerit
    fom_after: FiguresOfMerit
    allan_before: AllanAnalysis
    allan_after: AllanAnalysis
    k: float = 1.0
    """``value[canonical] = k · value[unit]``: the model's unit over the data's."""
    role: str = "validation"
    """The recording's role: ``modelling`` (a model was fitted on it), ``validation`` (a
    validation result was given) or ``test`` (:func:`recording_role`)."""
    recording_sha256: str | None = None
    dynamic: DynamicAllan | None = None
    """The dynamic ADEV of the compensated output (a
    :class:`~thermocal.stability.allan.DynamicAllan`, ``dynamic_s``) or None."""
    dynamic_warning: str | None = None
    """The non-stationarity warning of :attr:`dynamic` (None: stationary, or no map)."""
    quantization: OutputQuantization | None = None
    """The output quantisation of the uncompensated run in the data's unit
    (:func:`thermocal.stability.noise_model.output_quantization`; None: not quantised)."""

    @property
    def run_name(self) -> str:
        """The recording named by its role, e.g. ``"modelling run"``."""
        return f"{self.role} run"


def recording_role(inputs: ReportInputs, sha256: str | None) -> str:
    """What the recording is to the models: ``"modelling"`` when one of them was fitted on
    it (its SHA-256, else its file name, among the model files' ``data``), else
    ``"validation"`` when a validation result was given, else ``"test"``.

    Parameters
    ----------
    inputs : ReportInputs
        The report's inputs.
    sha256 : str or None
        The recording's checksum.

    Returns
    -------
    str
        ``"validation"`` or ``"modelling"`` (a model applied to its own modelling run).
    """
    name = Path(inputs.recording_path).name if inputs.recording_path else None
    for e in inputs.models:
        for d in e.model.get("data") or []:
            if not isinstance(d, dict):
                continue
            if sha256 is not None and d.get("sha256") == sha256:
                return "modelling"
            if sha256 is None and name is not None and d.get("file") == name:
                return "modelling"
    if any(e.validation for e in inputs.models):
        return "validation"
    return "test"


def _analyse(inputs: ReportInputs) -> _Analysis:
    """Apply every model to the validation run; the primary's figures before and after."""
    if not inputs.models:
        raise ThermocalInputError("report: at least one model is needed")
    primary = inputs.models[0]
    labels = [m.label for m in inputs.models]
    if len(set(labels)) != len(labels):
        raise ThermocalInputError(f"report: model labels must be unique, got {labels}")
    rec = inputs.recording
    signal = inputs.signal or (primary.model.get("signal") or {}).get("name")
    rec_sha = sha256_of(inputs.recording_path) if inputs.recording_path else None
    role = recording_role(inputs, rec_sha)
    sig_col = signal if signal in rec.columns else (rec.signals[0] if rec.signals else None)
    _, canon = rec.signal(sig_col)
    # every figure in the data's own unit (the column's unit as given)
    unit, k = data_unit_of(rec, sig_col or "", canon)
    applied = {
        e.label: in_data_unit(apply_model(e.model, rec, signal), unit, k) for e in inputs.models
    }
    main = applied[primary.label]
    temp_names = main.temp_names
    v = primary.validation or {}
    averaging_s = float(inputs.averaging_s or v.get("averaging_s") or DEFAULT_AVERAGING_S)
    tau0 = rec.sample_interval_s
    ambient = v.get("ambient")
    stage_temp = ambient if isinstance(ambient, str) and ambient in rec.columns else temp_names[0]
    stage_temp_c = (
        rec.temperature_c(stage_temp) if stage_temp not in temp_names
        else main.temps_c[:, temp_names.index(stage_temp)]
    )  # fmt: skip
    # drift angle, like with like: before and after each about its own mean over
    # the same reference window at the start (a given b0 is the raw sensor's: before only);
    # and both with no bias removed (FiguresOfMerit.drift_angle_raw_max)
    fom_before, fom_after = (
        figures_of_merit(
            main.time_s,
            x,
            unit,
            averaging_s=averaging_s,
            meta=rec.meta,
            temp_name=stage_temp,
            temp_c=stage_temp_c,
            drift_bias=drift_bias,
            drift_reference_s=None if drift_bias is not None else inputs.drift_reference_s,
            where=inputs.recording_path or rec.source,
        )
        for x, drift_bias in ((main.signal, inputs.drift_bias), (main.after_raw, None))
    )
    allan_before = allan_of(main.time_s, main.before, tau0, unit)
    allan_after = allan_of(main.time_s, main.after, tau0, unit)
    dyn, dyn_warning = _dynamic_of(inputs, main, allan_after, tau0, role)
    # the sensor's own output: a quantised rate lies on a lattice (the known input taken
    # off is a constant, which moves the lattice, not its step); the model's output does not
    quant = output_quantization(main.before, tau0, unit, allan_before.terms)
    # the Q row's reason then names the rate quantisation, as thermocal allan's does
    terms = annotate_quantization(allan_before.terms, quant)
    allan_before = AllanAnalysis(allan_before.result, terms)
    return _Analysis(
        primary, signal, unit, applied, main, temp_names, averaging_s, tau0, stage_temp,
        fom_before, fom_after, allan_before, allan_after,
        k, role, rec_sha, dyn, dyn_warning, quant,
    )  # fmt: skip


def _dynamic_of(
    inputs: ReportInputs, main: RunSignals, allan_after: AllanAnalysis, tau0: float, role: str
) -> tuple[DynamicAllan | None, str | None]:
    """The dynamic ADEV of the compensated output in windows of
    ``inputs.dynamic_s`` [s] (:func:`thermocal.stability.allan.dynamic_adev`, at the whole
    run's τ and confidence; input errors as the ``allan`` command's dynamic ADEV), and, when it is
    not stationary, the warning (:func:`thermocal.stability.analysis.nonstationary_message`)
    issued as a :class:`~thermocal.errors.ConditioningWarning` (stderr and the report)."""
    if inputs.dynamic_s is None:
        return None, None
    from thermocal.errors import ConditioningWarning
    from thermocal.stability.allan import dynamic_adev
    from thermocal.stability.analysis import nonstationary_message

    dyn = dynamic_adev(
        main.after, tau0, inputs.dynamic_s, allan_after.result, time_s=main.time_s,
        parameter="dynamic_s",
    )  # fmt: skip
    if dyn.stationary:
        return dyn, None
    where = Path(inputs.recording_path).name if inputs.recording_path else "recording"
    text = nonstationary_message(dyn, where, f"the compensated output of the {role} run")
    warnings.warn(text, ConditioningWarning, stacklevel=1)
    return dyn, text


@dataclass
class _FigureSet:
    """Figures (PNG, base64) keyed by name, numbered in the order they are added."""

    figs: dict[str, dict[str, str]] = field(default_factory=dict)
    n: int = 0

    def add(self, key: str, png: bytes, title: str, caption: str) -> None:
        """Add figure ``key`` with its title and caption ``Figure N. <caption>``."""
        self.n += 1
        self.figs[key] = {
            "src": _b64(png),
            "title": title,
            "caption": f"Figure {self.n}. {caption}",
            "id": f"fig-{key}",
        }


def _report_figures(inputs: ReportInputs, an: _Analysis) -> dict[str, dict[str, str]]:
    """Every figure (PNG, base64) with its title and numbered caption."""
    # bias series drawn as averages over the stability averaging time
    block = max(1, round(an.averaging_s / an.tau0))
    avg_text = f" ({fmt_num(block * an.tau0)} s averages)" if block > 1 else ""
    fs = _FigureSet()
    _profile_figure(fs, inputs, an)
    if inputs.modeling is not None:
        _fit_figure(fs, inputs.modeling, an, block, avg_text)
    _bias_figures(fs, an, block, avg_text)
    _allan_figure(fs, an)
    _dynamic_figure(fs, an)
    _drift_figure(fs, an)
    return fs.figs


def _profile_figure(fs: _FigureSet, inputs: ReportInputs, an: _Analysis) -> None:
    """The temperature channels of the modelling run (when given) and of the run judged."""
    from thermocal.report import figures as F

    temp_names = an.temp_names
    panels = []
    if inputs.modeling is not None:
        panels.append(_temperature_panel("Modelling run", inputs.modeling, temp_names))
    panels.append(_temperature_panel(an.run_name.capitalize(), inputs.recording, temp_names))
    fs.add(
        "profile",
        F.temperature_profile(panels),
        "Chamber profile and temperature channels",
        "Temperature channels of the sensor (the model uses "
        + ", ".join(temp_names)
        + ") and the chamber air temperature (dashed) against time, for "
        + ("the modelling run (top) and " if inputs.modeling is not None else "")
        + f"the {an.run_name}.",
    )


def _fit_figure(
    fs: _FigureSet, modeling: Recording, an: _Analysis, block: int, avg_text: str
) -> None:
    """The primary model against the modelling run's bias, and the residual."""
    from thermocal.report import figures as F

    primary, unit = an.primary, an.unit
    mod = in_data_unit(apply_model(primary.model, modeling, an.signal), unit, an.k)
    fs.add(
        "fit",
        F.model_fit(mod.time_s, mod.before, mod.model_bias, unit=unit_label(unit), block=block),
        "Model fit on the modelling run",
        f"Modelling run: measured bias{avg_text} and the {primary.label} model (top), "
        "residual (bottom).",
    )


def _bias_figures(fs: _FigureSet, an: _Analysis, block: int, avg_text: str) -> None:
    """The bias against time and against temperature, before and after compensation."""
    from thermocal.report import figures as F

    primary, main, unit, temp_names = an.primary, an.main, an.unit, an.temp_names
    stages = _stages_from(primary.validation)
    fs.add(
        "bias_time",
        F.bias_vs_time(
            main.time_s,
            main.before,
            main.after,
            unit=unit_label(unit),
            stages=stages,
            temperature=main.temps_c[:, 0],
            temperature_label=temp_names[0],
            block=block,
        ),
        "Bias against time, before and after compensation",
        f"{an.run_name.capitalize()}: bias{avg_text} before (red) and after (blue) "
        "compensation with the "
        f"{primary.label} model; {temp_names[0]} dotted (right axis)"
        + ("; shaded: temperature-hold stages used for stability and repeatability."
           if stages else "."),
    )  # fmt: skip
    fs.add(
        "bias_temp",
        F.bias_vs_temperature(
            main.temps_c[:, 0],
            main.before,
            main.after,
            unit=unit_label(unit),
            temperature_label=temp_names[0],
            block=block,
        ),
        "Bias against temperature, before and after compensation",
        f"{an.run_name.capitalize()}: bias against {temp_names[0]}, before and after "
        "compensation; "
        f"dots: {avg_text.strip(' ()') or 'samples'}, lines: means in temperature bins "
        "with their standard errors.",
    )


def _allan_figure(fs: _FigureSet, an: _Analysis) -> None:
    """The overlapping Allan deviation before and after compensation."""
    from thermocal.report import figures as F

    fs.add(
        "allan",
        F.allan_deviation(
            [
                F.AllanCurve(
                    lab,
                    al.result.tau_s,
                    al.result.adev,
                    al.result.adev_low,
                    al.result.adev_high,
                )
                for lab, al in (
                    ("before compensation", an.allan_before),
                    ("after compensation", an.allan_after),
                )
            ],
            unit=unit_label(an.unit),
        ),
        "Allan deviation before and after compensation",
        f"Overlapping Allan deviation of the {an.run_name} before and after "
        "compensation; bars: confidence intervals.",
    )


def _dynamic_figure(fs: _FigureSet, an: _Analysis) -> None:
    """The heat map of the compensated output's dynamic Allan deviation
    (:func:`thermocal.report.allan_plots.plot_dynamic`)."""
    import tempfile

    from thermocal.report.allan_plots import plot_dynamic

    dyn = an.dynamic
    if dyn is None:
        return
    with tempfile.TemporaryDirectory(prefix="thermocal-dyn-") as tmp:
        png = plot_dynamic(
            dyn, Path(tmp) / "dynamic.png", title="dynamic Allan deviation, after compensation"
        ).read_bytes()
    fs.add(
        "dynamic",
        png,
        "Dynamic Allan deviation after compensation",
        f"Dynamic Allan deviation of the {an.run_name} after compensation: the overlapping "
        f"ADEV in sliding windows of {fmt_num(dyn.window_s)} s stepped by "
        f"{fmt_num(dyn.step_s)} s ({dyn.t_s.size} windows; half a window), at the τ that fit "
        f"a window; colour log10 ADEV [{unit_label(an.unit)}]; crosses: (window, τ) where the "
        "window's ADEV and the whole run's differ beyond both their confidence intervals "
        f"(test at {100 * dyn.test_confidence:.4g} %, Bonferroni over every cell).",
    )


def _dynamic_context(an: _Analysis) -> dict[str, Any] | None:
    """The template's ``dynamic``: window, step and windows (tagged), changes, warning."""
    dyn = an.dynamic
    if dyn is None:
        return None
    return {
        "window_s": num(dyn.window_s, "dynamic.window_s"),
        "step_s": num(dyn.step_s, "dynamic.step_s"),
        "n_windows": num(dyn.t_s.size, "dynamic.n_windows"),
        "n_changes": num(len(dyn.changes), "dynamic.n_changes"),
        "stationary": dyn.stationary,
        "warning": an.dynamic_warning,
    }


def _quantization_context(an: _Analysis) -> dict[str, Any] | None:
    """The template's ``quantization`` (the ``output_quantization`` of ``thermocal allan``):
    step [the data's unit] and levels, kind (rate: white rate noise N_q = q·√(τ0/12); angle:
    Q = q·τ0/√12), that noise in the noise terms' unit and its share of the measured term's
    variance [%], all tagged ``allan.before.output_quantization.*``."""
    q = an.quantization
    if q is None:
        return None
    key = "allan.before.output_quantization"
    if q.kind == "rate":
        label, name, value, vunit = (
            "white rate noise N_q = q·√(τ0/12)", "white_density", q.white_density,
            q.white_density_unit,
        )  # fmt: skip
    else:
        label, name, value, vunit = (
            "angle quantization Q = q·τ0/√12",
            "angle_q",
            q.angle_q,
            q.angle_q_unit,
        )
    return {
        "step": num(q.step, f"{key}.step", 6, unit_label(q.unit)),
        "levels": num(q.levels, f"{key}.levels"),
        "kind": q.kind,
        "noise_label": label,
        "noise": num(value, f"{key}.{name}", 4, unit_label(vunit)),
        "share": num(None if q.share is None else 100.0 * q.share, f"{key}.share_pct", 3),
        "of": "the measured N²" if q.kind == "rate" else "the fitted Q²",
        "reason": q.reason,
    }


def _drift_figure(fs: _FigureSet, an: _Analysis) -> None:
    """The drift angle before and after compensation (gyros: when both are known)."""
    from thermocal.report import figures as F

    fom_before, fom_after = an.fom_before, an.fom_after
    if fom_before.drift_angle is None or fom_after.drift_angle is None:
        return
    fs.add(
        "drift",
        F.drift_angle(
            an.main.time_s,
            fom_before.drift_angle,
            fom_after.drift_angle,
            unit=unit_label(fom_before.drift_angle_unit or ""),
        ),
        "Drift angle before and after compensation",
        "Angle error over time, θ(t) = ∫ (ω − Ω − b0) dt: before compensation (red) "
        f"with {drift_reference_words(fom_before.drift_reference)}; after (blue) the "
        "compensated rate with its own b0 over the same window (like with like; the "
        "figures with no bias removed are in the table of figures of merit).",
    )


def drift_reference_words(ref: Any) -> str:
    """How the constant b0 of the drift angle was chosen, in words (a
    :class:`~thermocal.metrics.DriftReference` or None).

    Parameters
    ----------
    ref : object
        The drift angle's reference (a window or a b0).

    Returns
    -------
    str
    """
    if ref is None:
        return "no bias removed"
    b0 = f"{fmt_num(ref.bias, 5)} {unit_label(ref.unit)}"
    if ref.kind == "window":
        return (
            f"b0 = {b0}, the mean of the uncompensated rate over {fmt_num(ref.start_s)}…"
            f"{fmt_num(ref.end_s)} s from the start of the run (a reference window)"
        )
    if ref.kind == "bias":
        return f"the given b0 = {b0}"
    return f"b0 = {b0}"


def _noise_rows(an: _Analysis) -> list[dict[str, Any]]:
    """IEEE 952 noise terms before and after, by both methods."""
    allan_before, allan_after = an.allan_before, an.allan_after
    noise_rows = []
    for key, label in NOISE_TERMS:
        cells = []
        term_unit = ""
        for when, al in (("before", allan_before), ("after", allan_after)):
            for method in ("slope", "fit"):
                term = getattr(getattr(al.terms, method), key)
                term_unit = term.unit or term_unit
                cells.append(
                    {
                        "html": num(term.value, f"allan.{when}.{method}.{key}", 3),
                        "reason": term.reason or "",
                    }
                )
        noise_rows.append({"label": label, "unit": unit_label(term_unit), "cells": cells})
        if key == "bias_instability":  # IEEE Std 952-1997 Annex C: always at the minimum
            mins = [al.terms.bias_minimum for al in (allan_before, allan_after)]
            cells = []
            for when, m in zip(("before", "after"), mins, strict=True):
                v = None if m is None else m.value
                cells.append({"html": num(v, f"allan.{when}.minimum.{key}", 3),
                              "reason": "" if m is None else m.reason or ""})  # fmt: skip
                cells.append({"html": num(None), "reason": ""})
            noise_rows.append(
                {"label": "  at the curve's minimum", "unit": unit_label(term_unit),
                 "cells": cells}
            )  # fmt: skip
    return noise_rows


def _fom_rows(an: _Analysis) -> list[dict[str, Any]]:
    """The figures of merit before and after, with the improvement."""
    unit, averaging_s, stage_temp = an.unit, an.averaging_s, an.stage_temp
    fom_before, fom_after = an.fom_before, an.fom_after
    fom_rows = []
    for name, label, u, digits in (
        ("bias", "Bias B0", unit_label(unit), 5),
        ("bias_stability", f"Bias stability ({fmt_num(averaging_s)} s averages)",
         unit_label(unit), 4),
        ("peak_to_peak", f"Peak-to-peak ({fmt_num(averaging_s)} s averages)",
         unit_label(unit), 4),
        ("sensitivity_slope", f"Temperature sensitivity, LS slope of stage bias on {stage_temp}",
         f"{unit_label(unit)}/°C", 4),
        ("sensitivity_mean_abs", "Temperature sensitivity, mean |ΔB/ΔT| of adjacent stages",
         f"{unit_label(unit)}/°C", 4),
        ("drift_angle_max", "Largest |drift angle|, start bias removed (b0)",
         unit_label(fom_before.drift_angle_unit or ""), 4),
        ("drift_angle_raw_max", "Largest |drift angle|, no bias removed",
         unit_label(fom_before.drift_angle_unit or ""), 4),
    ):  # fmt: skip
        b = getattr(fom_before, name)
        a = getattr(fom_after, name)
        if b is None and a is None:
            continue
        fom_rows.append(
            {
                "label": label,
                "unit": u,
                "before": num(b, f"fom.before.{name}", digits),
                "after": num(a, f"fom.after.{name}", digits),
                "improvement": change_html(
                    abs(b) if b is not None else None,
                    abs(a) if a is not None else None,
                    improvement_pct(abs(b), abs(a)) if b is not None and a is not None else None,
                    None,
                )
                if name != "bias"
                else num(None),
            }
        )

    tb, ta = fom_before.drift_angle_max_time_s, fom_after.drift_angle_max_time_s
    if tb is not None and ta is not None:
        fom_rows.append(
            {
                "label": "Largest |drift angle| reached at",
                "unit": "h",
                "before": num(tb / 3600.0, "fom.before.drift_angle_max_time_h", 4),
                "after": num(ta / 3600.0, "fom.after.drift_angle_max_time_h", 4),
                "improvement": num(None),
            }
        )
    return fom_rows


def _comparison_rows(inputs: ReportInputs, unit: str | None = None) -> list[dict[str, Any]]:
    """One row per model: its summary and its validation figures."""
    comparison = []
    for e in inputs.models:
        ve = e.validation or {}
        ms = _model_summary(e, unit)
        comparison.append(
            {
                **ms,
                "r": num(ve.get("r"), f"validation.{e.label}.r", 3),
                "n_stages": num(ve.get("n_stages"), f"validation.{e.label}.n_stages"),
                "stab_after": num(
                    ve.get("bias_stability_after"), f"validation.{e.label}.bias_stability_after"
                ),
                "rep_after": num(
                    ve.get("bias_repeatability_after"),
                    f"validation.{e.label}.bias_repeatability_after",
                ),
                "rms_after": num(ve.get("rms_after"), f"validation.{e.label}.rms_after"),
                "stab_imp": num(_json_improvement(ve, "bias_stability"), None, 3),
            }
        )

    return comparison


def _validation_tables(inputs: ReportInputs, unit: str) -> list[dict[str, Any]]:
    """The validation figures and stages of every model given with a validation result."""
    primary = inputs.models[0]
    return [
        {
            "label": e.label,
            "rows": _validation_rows(e, unit_label(unit)),
            "r": num((e.validation or {}).get("r"), f"validation.{e.label}.r", 3),
            "weak": (e.validation or {}).get("weakly_correlated"),
            "n_stages": num((e.validation or {}).get("n_stages"), f"validation.{e.label}.n_stages"),
            "averaging_s": (e.validation or {}).get("averaging_s"),
            "stages": _stage_rows(e) if e is primary else [],
        }
        for e in inputs.models
        if e.validation
    ]


def _overall(primary: ModelEntry, summary: list[dict[str, Any]]) -> str:
    """The verdict: only from a validation result that was given, and PASS only when its
    correlation check is among the passed ones."""
    flags = [s["flag"] for s in summary]
    if not primary.validation:
        return "na"
    if "fail" in flags:
        return "fail"
    if (primary.validation or {}).get("r") is not None and "pass" in flags:
        return "pass"
    return "na"


def build_report(inputs: ReportInputs) -> str:
    """The report as one self-contained HTML document (str).

    Steps: apply each model to the validation run and compute the primary model's
    figures of merit and Allan deviation before and after (:func:`_analyse`); figures
    (:func:`_report_figures`); tables from the figures and the model and validation JSON
    (:func:`_noise_rows`, :func:`_fom_rows`, :func:`_comparison_rows`,
    :func:`_validation_tables`); warnings; the verdict (:func:`_overall`); render
    ``templates/report.html.j2``.

    Parameters
    ----------
    inputs : ReportInputs
        The models, their validation results and the runs.

    Returns
    -------
    str
        The HTML document; every figure in the data's own unit.

    Warns
    -----
    ThermocalWarning
        What the analysis warns (gaps, extrapolation, …), also shown in the report.
    """
    from thermocal import __version__

    # every warning thermocal gives while the numbers and figures are made is shown in the
    # report too (and still reaches the caller: re-issued below)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        an = _analyse(inputs)
        figs = _report_figures(inputs, an)
    for w in caught:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    primary, rec, unit, signal = an.primary, inputs.recording, an.unit, an.signal
    truth_rows = _truth_rows(inputs, an.applied, unit)
    runs = []
    if inputs.modeling is not None:
        runs.append(_run_info("modelling", inputs.modeling, inputs.modeling_path, signal, unit))
    runs.append(_run_info(an.role, rec, inputs.recording_path, signal, unit))
    summary = _summary(primary, an.fom_before, an.fom_after, unit)
    run_warnings = [
        warning_text(w.message) for w in caught if issubclass(w.category, ThermocalWarning)
    ]
    ratetable = _ratetable_section(inputs.ratetable)
    ctx = {
        "title": inputs.title,
        "sensor": inputs.sensor or rec.meta.sensor_id or "",
        "generated_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "generated_by": inputs.generated_by,
        "version": __version__,
        "unit": unit_label(unit),
        "signal": signal,
        "primary": _model_summary(primary, unit),
        "summary": summary,
        "overall": _overall(primary, summary),
        "warnings": _collect_warnings(inputs, an.applied, an, runs, run_warnings),
        "run_name": an.run_name,
        "role": an.role,
        "adequacy": [a for a in (_adequacy_of(e) for e in inputs.models) if a is not None],
        "runs": runs,
        "notes": list(inputs.notes),
        "files": [{"label": a, "path": b} for a, b in inputs.files],
        "figs": figs,
        "validations": _validation_tables(inputs, unit),
        "comparison": _comparison_rows(inputs, unit),
        "fom_rows": _fom_rows(an),
        "truth_rows": truth_rows,
        "truth_std": (
            num(float(np.std(rec.column(TRUTH_COLUMN))), "truth.std", unit=unit_label(unit))
            if truth_rows
            else None
        ),
        "noise_rows": _noise_rows(an),
        "dynamic": _dynamic_context(an),
        "quantization": _quantization_context(an),
        "model_details": _model_details(inputs, unit),
        "coefficients": _coefficient_rows(primary.model, "model", unit),
        "ranges": _range_rows(primary.model),
        "has_rates": bool((primary.model.get("range") or {}).get("rate_c_per_min")),
        "known_input": an.main.known_input,
        "averaging_s": an.averaging_s,
        "limit_r": WEAK_CORRELATION_LIMIT,
        "n_figures": len(figs) + (ratetable.count("<img ") if ratetable else 0),
        "temp_names": ", ".join(an.temp_names),
        "ratetable": Markup(ratetable) if ratetable else None,
    }
    html: str = _env().get_template("report.html.j2").render(**ctx)
    return html


def _ratetable_section(res: Any) -> str | None:
    """The rate-table spec sheet's HTML (:func:`thermocal.report.ratetable.ratetable_section`)."""
    if res is None:
        return None
    from thermocal.report.ratetable import ratetable_section

    return ratetable_section(res)


def write_report(path: str | Path, inputs: ReportInputs) -> Path:
    """Build the report and write it atomically to ``path`` (UTF-8); returns the path.

    Parameters
    ----------
    path : str or pathlib.Path
        The HTML file.
    inputs : ReportInputs
        As :func:`build_report`.

    Returns
    -------
    pathlib.Path
    """
    return write_html(path, build_report(inputs))


__all__ = [
    "ModelEntry",
    "ReportInputs",
    "build_report",
    "figures_of_merit",
    "fmt_num",
    "improvement_pct",
    "write_report",
]
