"""The numbers of a report (SPEC §1, §5): a model applied to a run (bias before, model,
after, each in the data's unit), figures of merit and Allan deviation with noise terms.

Pure: no files, no plotting (:mod:`thermocal.report.build` renders them)."""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal import units
from thermocal.allan import AllanResult, NoiseTerms, noise_terms, overlapping_adev
from thermocal.compensation import unit_factor
from thermocal.metrics import compute_metrics, drift_angle
from thermocal.models.base import RunData, TemperatureModel
from thermocal.recording import FloatArray, Metadata, Recording

ILL_CONDITIONED = 1.0e6
"""Condition number (scaled design) above which the report warns: ill-conditioned in the
words of :func:`thermocal.models.base.condition_wording`."""


# --- analysis of the runs --------------------------------------------------------------------


@dataclass(frozen=True)
class RunSignals:
    """The bias of a run before and after compensation by one model [signal unit]."""

    time_s: FloatArray
    signal: FloatArray
    unit: str
    before: FloatArray
    model: FloatArray
    after: FloatArray
    temps_c: FloatArray
    temp_names: tuple[str, ...]
    known_input: float
    warnings: tuple[str, ...]
    model_includes_known_input: bool = False

    @property
    def model_bias(self) -> FloatArray:
        """The model value on the bias scale (known input taken off if the model holds it)."""
        if self.model_includes_known_input:
            out: FloatArray = self.model - self.known_input
            return out
        return self.model

    @property
    def after_raw(self) -> FloatArray:
        """Compensated output with the known input kept (what the sensor would output)."""
        out: FloatArray = self.after + self.known_input
        return out


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
    model = TemperatureModel.from_dict(model_dict)
    sig_name = signal or (model_dict.get("signal") or {}).get("name")
    if sig_name not in rec.columns:
        sig_name = None if not rec.signals else rec.signals[0]
    temp_names = tuple(model_dict["temperatures"])
    x, unit = rec.signal(sig_name)
    factor = unit_factor(unit, model.signal_unit, meta=rec.meta, where=rec.name)
    known = known_input_of(rec, unit)
    run = RunData.from_recording(rec, sig_name, temp_names, known_input=known)
    run = dataclasses.replace(run, signal=x * factor, known_input=known * factor)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pred = np.asarray(model.predict(run), dtype=np.float64) / factor
    msgs = tuple(dict.fromkeys(" ".join(str(w.message).split()) for w in caught))
    before = x - known
    # A model fitted on the raw output (known input not removed) carries the earth
    # rate in its constant.  The fit's provenance says what was removed (``thermocal fit``
    # records ``known_input`` per file); without it, tell by which level the model's mean
    # is nearer (|Ω| ≫ bias changes).
    fitted = [d.get("known_input") for d in model_dict.get("data", []) if isinstance(d, dict)]
    if known == 0.0:
        includes = False
    elif fitted and all(isinstance(k, int | float) for k in fitted):
        includes = all(float(k) == 0.0 for k in fitted)  # type: ignore[arg-type]
    else:
        includes = bool(abs(np.mean(pred) - np.mean(x)) < abs(np.mean(pred) - np.mean(before)))
    after = x - pred if includes else before - pred
    return RunSignals(
        time_s=rec.time_s,
        signal=x,
        unit=unit,
        before=before,
        model=pred,
        after=after,
        temps_c=run.temps_c,
        temp_names=temp_names,
        known_input=known,
        warnings=msgs,
        model_includes_known_input=includes,
    )


@dataclass(frozen=True)
class FiguresOfMerit:
    """SPEC §1 figures of a whole run [signal unit], from
    :func:`thermocal.metrics.compute_metrics` (the numbers of ``thermocal metrics``):
    bias B0 (earth rate removed when latitude and axis are known), bias stability
    and peak-to-peak over ``averaging_s`` averages, temperature sensitivity over
    the hold stages (least-squares slope and mean |ΔB/ΔT|) [unit/°C], and the
    largest and final drift angle [°] (gyros)."""

    bias: float
    bias_stability: float
    averaging_s: float
    peak_to_peak: float
    sensitivity_slope: float | None
    sensitivity_mean_abs: float | None
    drift_angle: FloatArray | None
    drift_angle_end_deg: float | None
    drift_angle_max_deg: float | None


def figures_of_merit(
    time_s: FloatArray,
    x: FloatArray,
    unit: str,
    *,
    averaging_s: float,
    meta: Metadata,
    temp_name: str,
    temp_c: FloatArray,
) -> FiguresOfMerit:
    """Figures of merit of a rate ``x`` [canonical unit, known input included] (SPEC §1).

    Runs :func:`thermocal.metrics.compute_metrics` on a recording of ``x`` with
    ``temp_c`` as the hold-stage temperature; the drift angle
    ``θ(t) = ∫ (ω − B0) dt`` with B0 the run's mean rate is
    :func:`thermocal.metrics.drift_angle` (held across gaps).
    """
    rec = Recording.from_arrays(
        time_s,
        {"signal": x},
        {temp_name: temp_c},
        signal_unit=unit,
        meta=dataclasses.replace(meta, scale_factor=None, scale_factor_unit=None),
    )
    m = compute_metrics(rec, "signal", averaging_s, temps=[temp_name])
    sens = m.temperature_sensitivity
    ang: FloatArray | None = None
    end = mx = None
    if unit == "deg/h":
        ang = drift_angle(time_s, x, float(np.mean(x)))
        end = float(ang[-1])
        mx = float(np.max(np.abs(ang)))
    return FiguresOfMerit(
        bias=m.bias,
        bias_stability=m.bias_stability,
        averaging_s=m.averaging_s,
        peak_to_peak=m.peak_to_peak,
        sensitivity_slope=sens.ls_slope if sens is not None else None,
        sensitivity_mean_abs=sens.mean_abs_adjacent if sens is not None else None,
        drift_angle=ang,
        drift_angle_end_deg=end,
        drift_angle_max_deg=mx,
    )


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

    result: AllanResult
    terms: NoiseTerms


def allan_of(time_s: FloatArray, x: FloatArray, tau0_s: float, unit: str) -> AllanAnalysis:
    """Overlapping Allan deviation (octave τ, ±1σ confidence intervals, split at gaps) and
    the IEEE Std 952 noise terms, by :func:`thermocal.allan.overlapping_adev` and
    :func:`thermocal.allan.noise_terms` (NIST SP 1065 eq. 11; SPEC §1)."""
    res = overlapping_adev(x, tau0_s, "octave", time_s=time_s, unit=unit)
    return AllanAnalysis(result=res, terms=noise_terms(res))
