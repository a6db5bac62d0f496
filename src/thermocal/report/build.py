"""Build the self-contained HTML report of a temperature-compensation workflow.

The report gathers, for one sensor, what an engineer sends a customer (SPEC
§1, §4a–§5, §8): test conditions and data provenance, the chamber profile and
temperature channels, the bias against time and temperature before and after
compensation, the validation table on a weakly correlated test (r, stages,
stability, repeatability, improvement), Allan deviation before and after with
its noise terms, the drift angle, the model coefficients with standard errors
and their range of validity, and every warning (extrapolation, correlation
limit not met, ill-conditioning).

Inputs are what the other commands write: model files (:func:`save_model`
JSON), validation JSON (``thermocal validate --json``) and recordings.  Every
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
import hashlib
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from markupsafe import Markup, escape

from thermocal import units
from thermocal.errors import ThermocalInputError
from thermocal.io import atomic_write
from thermocal.recording import FloatArray, Recording

WEAK_CORRELATION_LIMIT = 0.4
"""Seed 000 / SPEC §5: the validation test is weakly correlated when r < 0.4."""

ILL_CONDITIONED = 1.0e8
"""Condition number (of the scaled design) above which the report warns."""

DEFAULT_AVERAGING_S = 100.0
"""Averaging time of the bias-stability figures when the validation JSON gives none [s]."""


# --- inputs ------------------------------------------------------------------------------


@dataclass(frozen=True)
class ModelEntry:
    """One fitted model in the report.

    ``model`` is the content of a model file (as written by
    :func:`thermocal.models.save_model`), ``validation`` the JSON object of
    ``thermocal validate --json`` for that model on the validation run (or
    ``None``), ``label`` a short name shown in tables, ``path`` the model file
    (provenance).
    """

    label: str
    model: dict[str, Any]
    validation: dict[str, Any] | None = None
    path: str | None = None


@dataclass(frozen=True)
class ReportInputs:
    """Everything :func:`build_report` needs.

    Attributes
    ----------
    models : fitted models; the first is the primary model, shown in detail
        (figures, coefficients); every model appears in the comparison table.
    recording : the validation run (the model is applied to it).
    modeling : the modelling run, if available (profile and fit figures).
    signal : signal column of the recordings (default: the model's signal name).
    recording_path, modeling_path : files the runs were read from (provenance,
        SHA-256 shown).
    title, sensor : headline texts.
    warnings : extra warning lines to show (e.g. caught while fitting).
    notes : free text paragraphs under "Test conditions".
    files : other produced files (label, path) listed in the provenance table.
    generated_by : the command that made the report.
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
    extra: dict[str, Any] = field(default_factory=dict)


# --- number formatting -------------------------------------------------------------------


def fmt_num(value: Any, digits: int = 4) -> str:
    """A number as shown in the report: ``digits`` significant digits, ``—`` for none/NaN.

    Integers are shown whole.  Very large or small magnitudes use an exponent
    (``1.234e-05``).
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
    """HTML for a number; with ``key`` tagged ``data-key``/``data-value`` (full precision)."""
    text = fmt_num(value, digits)
    attrs = ""
    if key is not None:
        raw = "" if value is None else repr(float(value)) if _is_number(value) else str(value)
        attrs = f' data-key="{escape(key)}" data-value="{escape(raw)}"'
    u = f'<span class="unit">&thinsp;{escape(unit)}</span>' if unit and text != "—" else ""
    return Markup(f'<span class="num"{attrs}>{escape(text)}</span>{u}')


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool)


def improvement_pct(before: Any, after: Any) -> float | None:
    """Improvement ``100 · (1 − after/before)`` [%] (None when not computable)."""
    if not (_is_number(before) and _is_number(after)):
        return None
    b, a = float(before), float(after)
    if not (math.isfinite(a) and math.isfinite(b)) or b == 0.0:
        return None
    return 100.0 * (1.0 - a / b)


def unit_label(unit: str) -> str:
    """Pretty unit for display (``deg/h`` → ``°/h``)."""
    return {
        "deg/h": "°/h",
        "deg/s": "°/s",
        "degC": "°C",
        "deg/sqrt(h)": "°/√h",
        "deg/h/sqrt(h)": "°/h/√h",
        "deg/h^2": "°/h²",
        "deg/h/s": "°/h/s",
        "deg": "°",
        "C/min": "°C/min",
    }.get(unit, unit)


# --- analysis of the runs --------------------------------------------------------------------


@dataclass(frozen=True)
class RunSignals:
    """The bias of a run before and after compensation by one model [signal unit]."""

    time_s: FloatArray
    before: FloatArray
    model: FloatArray
    after: FloatArray
    temps_c: FloatArray
    temp_names: tuple[str, ...]
    known_input: float
    warnings: tuple[str, ...]


def known_input_of(rec: Recording, unit: str) -> float:
    """Earth rate seen by the sensitive axis [°/h] when the metadata gives latitude and
    axis (SPEC §1: B0 = mean − Ω_axis), else 0 (accelerometers: 0)."""
    if unit != "deg/h" or rec.meta.latitude_deg is None or rec.meta.axis is None:
        return 0.0
    return float(
        units.earth_rate_on_axis_deg_h(rec.meta.latitude_deg, units.parse_axis(rec.meta.axis))
    )


def apply_model(model_dict: dict[str, Any], rec: Recording, signal: str | None) -> RunSignals:
    """Apply a model (file content) to a recording: bias before, model value, bias after.

    ``after = before − model(T, Ṫ)``; the model is evaluated on the fitted range
    (clamped, as in compensation); :class:`~thermocal.errors.ExtrapolationWarning`
    messages are collected, not raised.
    """
    from thermocal.models import RunData, TemperatureModel

    model = TemperatureModel.from_dict(model_dict)
    sig_name = signal or (model_dict.get("signal") or {}).get("name")
    if sig_name not in rec.columns:
        sig_name = None if not rec.signals else rec.signals[0]
    temp_names = tuple(model_dict["temperatures"])
    x, unit = rec.signal(sig_name)
    known = known_input_of(rec, unit)
    run = RunData.from_recording(rec, sig_name, temp_names, known_input=known)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pred = np.asarray(model.predict(run), dtype=np.float64)
    msgs = tuple(dict.fromkeys(" ".join(str(w.message).split()) for w in caught))
    before = x - known
    return RunSignals(
        time_s=rec.time_s,
        before=before,
        model=pred,
        after=before - pred,
        temps_c=run.temps_c,
        temp_names=temp_names,
        known_input=known,
        warnings=msgs,
    )


def drift_angle_deg(time_s: FloatArray, rate: FloatArray, unit: str = "deg/h") -> FloatArray:
    """Drift angle [°]: ``θ(t) = ∫₀ᵗ (ω(s) − ω̄) ds`` of the bias-corrected rate (SPEC §1,
    seed 001), trapezoidal rule; ω in [°/h] and t in [s] give θ = Σ … / 3600.

    The run's mean rate ω̄ (the bias B0) is removed first, so the angle shows the
    drift of the bias, not its constant part.
    """
    if unit != "deg/h":
        raise ThermocalInputError(f"drift angle needs a gyro rate in deg/h, not {unit}")
    t = np.asarray(time_s, dtype=np.float64)
    w = np.asarray(rate, dtype=np.float64) - float(np.mean(rate))
    inc = 0.5 * (w[1:] + w[:-1]) * np.diff(t) / 3600.0
    return np.r_[0.0, np.cumsum(inc)]


def block_means(time_s: FloatArray, x: FloatArray, block_s: float) -> FloatArray:
    """Means of consecutive blocks of ``block_s`` seconds (complete blocks only)."""
    tau = float(np.median(np.diff(time_s))) if time_s.size > 1 else block_s
    m = max(1, round(block_s / tau))
    n = (x.size // m) * m
    if n == 0:
        return np.asarray([np.mean(x)])
    out: FloatArray = x[:n].reshape(-1, m).mean(axis=1)
    return out


@dataclass(frozen=True)
class FiguresOfMerit:
    """SPEC §1 figures of a run [signal unit]: bias B0, bias stability at ``averaging_s``
    (standard deviation of the block means), peak-to-peak of the block means, and
    the final and largest drift angle [°] (gyros)."""

    bias: float
    bias_stability: float
    averaging_s: float
    peak_to_peak: float
    drift_angle_end_deg: float | None
    drift_angle_max_deg: float | None


def figures_of_merit(
    time_s: FloatArray, x: FloatArray, averaging_s: float, unit: str
) -> FiguresOfMerit:
    """Bias, stability (σ of the ``averaging_s`` block means, n − 1), peak-to-peak and drift
    angle of a run (SPEC §1; IEEE Std 952 style).

    Uses :func:`thermocal.metrics.compute_metrics` when that module provides it,
    so the numbers match ``thermocal metrics``.
    """
    bias, stab, p2p = _metrics(time_s, x, averaging_s, unit)
    if unit == "deg/h":
        ang = drift_angle_deg(time_s, x, unit)
        end: float | None = float(ang[-1])
        mx: float | None = float(np.max(np.abs(ang)))
    else:
        end = mx = None
    return FiguresOfMerit(bias, stab, averaging_s, p2p, end, mx)


def _metrics(
    time_s: FloatArray, x: FloatArray, averaging_s: float, unit: str
) -> tuple[float, float, float]:
    blocks = block_means(time_s, x, averaging_s)
    stab = float(np.std(blocks, ddof=1)) if blocks.size > 1 else float("nan")
    return float(np.mean(x)), stab, float(np.ptp(blocks))


NOISE_TERMS = (
    ("quantization", "Quantization noise Q"),
    ("angle_random_walk", "Angle random walk N"),
    ("bias_instability", "Bias instability B"),
    ("rate_random_walk", "Rate random walk K"),
    ("rate_ramp", "Rate ramp R"),
)


@dataclass(frozen=True)
class AllanAnalysis:
    """Allan deviation of one series and its noise terms (both IEEE 952 methods)."""

    result: Any  # thermocal.allan.AllanResult
    terms: Any  # thermocal.allan.NoiseTerms


def allan_of(time_s: FloatArray, x: FloatArray, tau0_s: float, unit: str) -> AllanAnalysis:
    """Overlapping Allan deviation (octave τ, ±1σ confidence intervals, split at gaps) and
    the IEEE Std 952 noise terms, by :func:`thermocal.allan.overlapping_adev` and
    :func:`thermocal.allan.noise_terms` (NIST SP 1065 eq. 11; SPEC §1)."""
    from thermocal.allan import noise_terms, overlapping_adev

    res = overlapping_adev(x, tau0_s, "octave", time_s=time_s, unit=unit)
    return AllanAnalysis(result=res, terms=noise_terms(res))


# --- provenance ------------------------------------------------------------------------------


def sha256_of(path: str | Path) -> str | None:
    """SHA-256 of a file, or None if it cannot be read."""
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            while block := fh.read(1 << 20):
                h.update(block)
    except OSError:
        return None
    return h.hexdigest()


def _run_info(role: str, rec: Recording, path: str | None, signal: str | None) -> dict[str, Any]:
    sig = signal if signal in rec.columns else (rec.signals[0] if rec.signals else None)
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
        "n_gaps": len(rec.gaps()),
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
    channels = {n: rec.temperature_c(n) for n in names if n in rec.columns}
    ch = None
    if chamber is not None:
        ch = (
            rec.temperature_c(chamber) if chamber in rec.temperatures else rec.column(chamber)
        )
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
        imp = improvement_pct(b, a)
        rows.append(
            {
                "label": label,
                "unit": u,
                "before": num(b, f"{key}.{name}_before"),
                "after": num(a, f"{key}.{name}_after"),
                "improvement": num(imp, f"{key}.{name}_improvement_pct", digits=3),
                "flag": _flag(None if imp is None else imp > 0),
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
    for name, label in (
        ("bias_stability", "Bias stability"),
        ("bias_repeatability", "Bias repeatability"),
        ("peak_to_peak", "Peak-to-peak bias"),
    ):
        b, a = v.get(f"{name}_before"), v.get(f"{name}_after")
        if b is None or a is None:
            continue
        imp = improvement_pct(b, a)
        ok = None if imp is None else imp > 0
        items.append(
            {
                "label": label,
                "before": num(b, f"{key}.{name}_before", unit=unit_label(unit)),
                "after": num(a, f"{key}.{name}_after", unit=unit_label(unit)),
                "value": num(imp, f"summary.{name}_improvement_pct", digits=3, unit="%"),
                "note": "improvement",
                "flag": _flag(ok),
                "flag_text": "improved" if ok else "not improved",
            }
        )
    if fom_before.drift_angle_max_deg is not None and fom_after.drift_angle_max_deg is not None:
        imp = improvement_pct(fom_before.drift_angle_max_deg, fom_after.drift_angle_max_deg)
        ok = None if imp is None else imp > 0
        items.append(
            {
                "label": "Largest drift angle",
                "before": num(fom_before.drift_angle_max_deg, "fom.before.drift_angle_max_deg",
                              unit="°"),
                "after": num(fom_after.drift_angle_max_deg, "fom.after.drift_angle_max_deg",
                             unit="°"),
                "value": num(imp, "summary.drift_angle_improvement_pct", digits=3, unit="%"),
                "note": "improvement",
                "flag": _flag(ok),
                "flag_text": "improved" if ok else "not improved",
            }
        )  # fmt: skip
    return items


def _coefficient_rows(model: dict[str, Any]) -> list[dict[str, Any]]:
    rows = []
    for i, c in enumerate(model.get("coefficients") or []):
        val = c.get("value")
        se = c.get("stderr")
        rel = None
        if _is_number(val) and _is_number(se) and float(val) != 0.0:
            rel = 100.0 * abs(float(se) / float(val))
        rows.append(
            {
                "i": i,
                "name": c.get("name", f"a{i}"),
                "value": num(val, f"model.coefficients.{i}.value", digits=6),
                "stderr": num(se, f"model.coefficients.{i}.stderr", digits=3),
                "rel": num(rel, None, digits=3),
                "unit": unit_label(str(c.get("unit", ""))),
            }
        )
    return rows


def _range_rows(model: dict[str, Any]) -> list[dict[str, Any]]:
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
                "t_lo": num(t[0], f"model.range.temperature_c.{name}.0", digits=4),
                "t_hi": num(t[1], f"model.range.temperature_c.{name}.1", digits=4),
                "r_lo": num(r[0], None, digits=3),
                "r_hi": num(r[1], None, digits=3),
            }
        )
    return rows


def _model_summary(entry: ModelEntry) -> dict[str, Any]:
    m = entry.model
    fit = m.get("fit") or {}
    params = m.get("params") or {}
    rate = m.get("rate") or {}
    cond = fit.get("condition_number")
    return {
        "label": entry.label,
        "family": m.get("family"),
        "n_coefficients": num(len(m.get("coefficients") or []), f"models.{entry.label}.n_coef"),
        "rms_residual": num(fit.get("rms_residual"), f"models.{entry.label}.rms_residual"),
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
    }


def _collect_warnings(
    inputs: ReportInputs, applied: dict[str, RunSignals]
) -> list[dict[str, str]]:
    out: list[dict[str, str]] = []
    seen: set[str] = set()

    def add(kind: str, text: str) -> None:
        if text not in seen:
            seen.add(text)
            out.append({"kind": kind, "text": text})

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
                f"{entry.label}: the scaled design is ill-conditioned (condition number "
                f"{fmt_num(cond, 3)} > {fmt_num(ILL_CONDITIONED, 2)}); coefficients are poorly "
                "determined, prefer a term-selected or ridge model.",
            )
        sig = applied.get(entry.label)
        if sig is not None:
            for w in sig.warnings:
                add("extrapolation", f"{entry.label} on the validation run: {w}")
    for w in inputs.warnings:
        add("workflow", w)
    return out


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


def build_report(inputs: ReportInputs) -> str:
    """The report as one self-contained HTML document (str).

    Steps: apply each model to the validation run (bias before, model, after);
    SPEC §1 figures of merit and Allan deviation before and after for the
    primary model; figures (PNG, base64); tables from the model and validation
    JSON; warnings; render ``templates/report.html.j2``.
    """
    from thermocal import __version__
    from thermocal.report import figures as F

    if not inputs.models:
        raise ThermocalInputError("report: at least one model is needed")
    primary = inputs.models[0]
    labels = [m.label for m in inputs.models]
    if len(set(labels)) != len(labels):
        raise ThermocalInputError(f"report: model labels must be unique, got {labels}")
    rec = inputs.recording
    signal = inputs.signal or (primary.model.get("signal") or {}).get("name")
    applied = {e.label: apply_model(e.model, rec, signal) for e in inputs.models}
    main = applied[primary.label]
    _, unit = rec.signal(signal if signal in rec.columns else None)
    temp_names = main.temp_names
    v = primary.validation or {}
    averaging_s = float(v.get("averaging_s") or DEFAULT_AVERAGING_S)
    tau0 = rec.sample_interval_s

    fom_before = figures_of_merit(main.time_s, main.before, averaging_s, unit)
    fom_after = figures_of_merit(main.time_s, main.after, averaging_s, unit)
    allan_before = allan_of(main.before, tau0)
    allan_after = allan_of(main.after, tau0)

    # --- figures
    panels = []
    if inputs.modeling is not None:
        panels.append(_temperature_panel("Modelling run", inputs.modeling, temp_names))
    panels.append(_temperature_panel("Validation run", rec, temp_names))
    stages = _stages_from(primary.validation)
    figs: dict[str, dict[str, str]] = {}

    def add_fig(key: str, png: bytes, title: str, caption: str) -> None:
        figs[key] = {"src": _b64(png), "title": title, "caption": caption, "id": f"fig-{key}"}

    n_fig = 0

    def cap(text: str) -> str:
        nonlocal n_fig
        n_fig += 1
        return f"Figure {n_fig}. {text}"

    add_fig(
        "profile",
        F.temperature_profile(panels),
        "Chamber profile and temperature channels",
        cap(
            "Temperature channels used by the model ("
            + ", ".join(temp_names)
            + ") and the chamber temperature (dashed) against time, for "
            + ("the modelling run (top) and " if inputs.modeling is not None else "")
            + "the validation run."
        ),
    )
    if inputs.modeling is not None:
        mod = apply_model(primary.model, inputs.modeling, signal)
        add_fig(
            "fit",
            F.model_fit(mod.time_s, mod.before, mod.model, unit=unit_label(unit)),
            "Model fit on the modelling run",
            cap(
                f"Modelling run: measured bias and the {primary.label} model (top), "
                "residual (bottom)."
            ),
        )
    add_fig(
        "bias_time",
        F.bias_vs_time(
            main.time_s,
            main.before,
            main.after,
            unit=unit_label(unit),
            stages=stages,
            temperature=main.temps_c[:, 0],
            temperature_label=temp_names[0],
        ),
        "Bias against time, before and after compensation",
        cap(
            f"Validation run: bias before (red) and after (blue) compensation with the "
            f"{primary.label} model; {temp_names[0]} dotted (right axis)"
            + ("; shaded: temperature-hold stages used for stability and repeatability."
               if stages else ".")
        ),
    )  # fmt: skip
    add_fig(
        "bias_temp",
        F.bias_vs_temperature(
            main.temps_c[:, 0],
            main.before,
            main.after,
            unit=unit_label(unit),
            temperature_label=temp_names[0],
        ),
        "Bias against temperature, before and after compensation",
        cap(f"Validation run: bias against {temp_names[0]}, before and after compensation."),
    )
    add_fig(
        "allan",
        F.allan_deviation(
            [
                F.AllanCurve(
                    "before compensation",
                    allan_before.tau_s,
                    allan_before.adev,
                    allan_before.adev_low,
                    allan_before.adev_high,
                ),
                F.AllanCurve(
                    "after compensation",
                    allan_after.tau_s,
                    allan_after.adev,
                    allan_after.adev_low,
                    allan_after.adev_high,
                ),
            ],
            unit=unit_label(unit),
        ),
        "Allan deviation before and after compensation",
        cap(
            "Overlapping Allan deviation of the validation run before and after "
            "compensation; bars: confidence intervals."
        ),
    )
    if fom_before.drift_angle_end_deg is not None:
        add_fig(
            "drift",
            F.drift_angle(
                main.time_s,
                drift_angle_deg(main.time_s, main.before, unit),
                drift_angle_deg(main.time_s, main.after, unit),
            ),
            "Drift angle before and after compensation",
            cap(
                "Drift angle: integral of the rate with its mean (the bias B0) removed, "
                "before and after compensation."
            ),
        )

    # --- tables
    noise_rows = []
    for key, label in NOISE_TERMS:
        b = allan_before.noise.get(key) or {}
        a = allan_after.noise.get(key) or {}
        if b.get("value") is None and a.get("value") is None:
            continue
        noise_rows.append(
            {
                "label": label,
                "unit": unit_label(str(b.get("unit") or a.get("unit") or "")),
                "before": num(b.get("value"), f"allan.before.{key}"),
                "after": num(a.get("value"), f"allan.after.{key}"),
            }
        )
    fom_rows = []
    for name, label, u, digits in (
        ("bias", "Bias B0", unit_label(unit), 5),
        ("bias_stability", f"Bias stability ({fmt_num(averaging_s)} s averages)",
         unit_label(unit), 4),
        ("peak_to_peak", f"Peak-to-peak ({fmt_num(averaging_s)} s averages)",
         unit_label(unit), 4),
        ("drift_angle_end_deg", "Drift angle at end of run", "°", 4),
        ("drift_angle_max_deg", "Largest |drift angle|", "°", 4),
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
                "improvement": num(
                    improvement_pct(abs(b), abs(a)) if name != "bias" else None, None, 3
                ),
            }
        )

    comparison = []
    for e in inputs.models:
        ve = e.validation or {}
        ms = _model_summary(e)
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
                "stab_imp": num(
                    improvement_pct(ve.get("bias_stability_before"), ve.get("bias_stability_after")),
                    None,
                    3,
                ),
            }
        )

    validations = [
        {
            "label": e.label,
            "rows": _validation_rows(e, unit_label(unit)),
            "r": num((e.validation or {}).get("r"), f"validation.{e.label}.r", 3),
            "weak": (e.validation or {}).get("weakly_correlated"),
            "n_stages": num(
                (e.validation or {}).get("n_stages"), f"validation.{e.label}.n_stages"
            ),
            "averaging_s": (e.validation or {}).get("averaging_s"),
        }
        for e in inputs.models
        if e.validation
    ]

    runs = []
    if inputs.modeling is not None:
        runs.append(_run_info("modelling", inputs.modeling, inputs.modeling_path, signal))
    runs.append(_run_info("validation", rec, inputs.recording_path, signal))
    warn_list = _collect_warnings(inputs, applied)
    summary = _summary(primary, fom_before, fom_after, unit)
    flags = [s["flag"] for s in summary]
    overall = "fail" if "fail" in flags else ("pass" if "pass" in flags else "na")

    ctx = {
        "title": inputs.title,
        "sensor": inputs.sensor or rec.meta.sensor_id or "",
        "generated_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "generated_by": inputs.generated_by,
        "version": __version__,
        "unit": unit_label(unit),
        "signal": signal,
        "primary": _model_summary(primary),
        "summary": summary,
        "overall": overall,
        "warnings": warn_list,
        "runs": runs,
        "notes": list(inputs.notes),
        "files": [{"label": a, "path": b} for a, b in inputs.files],
        "figs": figs,
        "validations": validations,
        "comparison": comparison,
        "fom_rows": fom_rows,
        "noise_rows": noise_rows,
        "coefficients": _coefficient_rows(primary.model),
        "ranges": _range_rows(primary.model),
        "has_rates": bool((primary.model.get("range") or {}).get("rate_c_per_min")),
        "known_input": main.known_input,
        "averaging_s": averaging_s,
        "limit_r": WEAK_CORRELATION_LIMIT,
        "n_figures": len(figs),
        "temp_names": ", ".join(temp_names),
    }
    html: str = _env().get_template("report.html.j2").render(**ctx)
    return html


def write_report(path: str | Path, inputs: ReportInputs) -> Path:
    """Build the report and write it atomically to ``path`` (UTF-8); returns the path."""
    html = build_report(inputs)
    with atomic_write(path, "wb") as fh:
        fh.write(html.encode("utf-8"))
    return Path(path)


__all__ = [
    "ModelEntry",
    "ReportInputs",
    "build_report",
    "drift_angle_deg",
    "figures_of_merit",
    "fmt_num",
    "improvement_pct",
    "write_report",
]
