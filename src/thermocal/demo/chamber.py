"""The whole chamber workflow (model, validation, compensation, C) on built-in simulated data
(``thermocal demo``).

:func:`run_demo` plays what a test lab does with a ring-laser gyro that has four
temperature sensors, as *A modelling and validation method for the temperature compensation
model of a ring-laser gyroscope*
(a Chinese invention patent, 2017) describes:

1. **Profiles** — a shortened modelling profile of the patent (a −20…+50 °C cycle
   and ramps at ±2, ±1, ±0.5 °C/min; :func:`thermocal.profiles.rlg_modelling`)
   and a validation hold profile designed to be weakly correlated with it
   (:func:`thermocal.profiles.design_validation_profile`, r < 0.4).
2. **Simulation** — both runs of the ``rlg`` preset at 1 Hz
   (:mod:`thermocal.simulate`, scenarios ``rlg-modelling`` and
   ``rlg-validation``; separate turn-ons and noise), written as Parquet with
   their truth JSON.
3. **Fit** — the patent's 37-term model (per sensor T, T², T³, Ṫ, Ṫ², Ṫ³, TṪ,
   (TṪ)², (TṪ)³ and a constant) and a term-selected model of the same
   family, both saved as model files.
4. **Validation** of both on the validation run (:func:`thermocal.validation.validate`:
   r of the chamber temperatures, hold-stage bias stability and repeatability
   before and after), saved as the JSON the ``validate`` command prints.
5. **Compensation** of the validation file with the reported model
   (:func:`thermocal.pipeline.compensate.compensate_file`).
6. **C export** of both models (:func:`thermocal.export.c.export_c`).
7. **Report** — ``report.html`` (:func:`thermocal.report.write_report`) with the
   figures of merit and Allan deviation before and after compensation.

Everything is seeded: the same seed gives the same numbers.  The default
demo takes well under a minute on two cores (``DemoResult.timings_s``).
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import units
from thermocal.compensate.kernels import zero_reference
from thermocal.errors import ModelFileError, ThermocalWarning
from thermocal.export.c import export_c
from thermocal.models.base import TemperatureModel
from thermocal.models.registry import make_model
from thermocal.models.rundata import RunData
from thermocal.pipeline.compensate import compensate_file
from thermocal.pipeline.messages import warning_text
from thermocal.pipeline.model_file import save_model
from thermocal.profiles import design_validation_profile, rlg_modelling
from thermocal.recording import Recording
from thermocal.report import ModelEntry, ReportInputs, write_report
from thermocal.report.text import Block, TextTable, fmt
from thermocal.simulate import run_scenario
from thermocal.validation import validate
from thermocal.writers import write_json, write_program, write_recording

DEMO_STEPS: tuple[str, ...] = (
    "designing chamber profiles",
    "simulating the modelling and validation runs",
    "fitting the 37-term seed model",
    "fitting the term-selected model",
    "validating both models",
    "compensating the validation run",
    "exporting C code",
    "writing the report",
)
"""The steps of :func:`run_demo`, in order (one progress call after each)."""

TEMPS = ("T1", "T2", "T3", "T4")
SIGNAL = "gyro"
AMBIENT = "T_chamber"


@dataclass(frozen=True)
class DemoConfig:
    """Sizes of the demo data.

    Attributes
    ----------
    rate_hz : sample rate of the simulated gyro [Hz].
    low_c, high_c : temperature range of the modelling profile [°C].
    n_temperature_cycles, hold_s : the modelling profile's −20…+50 °C cycles and
        their holds [s].
    rates_c_per_min, rate_hold_s : the rate cycles of the modelling profile
        [°C/min] and their end holds [s].
    n_holds, validation_hold_s : number and nominal duration [s] of the
        validation holds (evenly spaced over the modelling range, order designed
        for r < 0.4).
    averaging_s : averaging time of the stability figures [s].
    settle_s : seconds cut from the start of each validation hold stage (the
        sensor lags the chamber air).
    rate_interval_s : Δt of the temperature rate Ṫ [s].
    """

    rate_hz: float = 1.0
    low_c: float = -20.0
    high_c: float = 50.0
    n_temperature_cycles: int = 1
    hold_s: float = 7200.0
    rates_c_per_min: tuple[float, ...] = (2.0, 1.0, 0.5)
    rate_hold_s: float = 1800.0
    n_holds: int = 6
    validation_hold_s: float = 3600.0
    averaging_s: float = 100.0
    settle_s: float = 1200.0
    rate_interval_s: float = 60.0


QUICK = DemoConfig(rate_hz=0.2, rates_c_per_min=(2.0, 1.0), n_holds=5, validation_hold_s=3000.0)
"""A smaller demo (5 s samples, fewer ramps) for tests."""


@dataclass(frozen=True)
class ModelSummary:
    """One model of the demo: its files and key validation figures [°/h].

    Attributes
    ----------
    label : str
        The model's name in the report.
    model_path, validation_path : Path
        The model file and its validation (JSON).
    c_files : tuple of Path
        The generated C files.
    n_coefficients : int
        Number of coefficients.
    condition_number : float or None
        Condition number of the scaled design.
    rms_residual : float
        RMS of the fit's residuals [°/h].
    r : float or None
        Correlation of the modelling and validation temperature histories.
    weakly_correlated : bool or None
        Whether ``r`` is below the limit.
    n_stages : int
        Number of hold stages of the validation run.
    bias_stability_before, bias_stability_after : float or None
        Bias stability of the validation run before and after compensation [°/h].
    bias_repeatability_before, bias_repeatability_after : float or None
        Bias repeatability over the stages before and after compensation [°/h].
    improvement_pct : dict of str to float or None
        Improvement of each figure by compensation [%].
    """

    label: str
    model_path: Path
    validation_path: Path
    c_files: tuple[Path, ...]
    n_coefficients: int
    condition_number: float | None
    rms_residual: float
    r: float | None
    weakly_correlated: bool | None
    n_stages: int
    bias_stability_before: float | None
    bias_stability_after: float | None
    bias_repeatability_before: float | None
    bias_repeatability_after: float | None
    improvement_pct: dict[str, float | None]


@dataclass(frozen=True)
class DemoResult:
    """What :func:`run_demo` produced.

    ``report_path`` is the HTML report; ``models`` the two models (the first is
    the one reported in detail and used for compensation); ``files`` every file
    written; ``timings_s`` the duration of each step [s] and ``elapsed_s`` the total.

    Attributes
    ----------
    out_dir : Path
        The demo's folder.
    report_path : Path
        The HTML report.
    models : tuple of ModelSummary
        The two models; the first is reported in detail and used for compensation.
    recordings : dict of str to Path
        The simulated recordings by role (modelling, validation).
    compensated_path : Path
        The compensated validation run.
    files : tuple of Path
        Every file written.
    timings_s : dict of str to float
        Duration of each step [s].
    elapsed_s : float
        Total duration [s].
    seed : int
        Seed of the simulation.
    warnings : tuple of str
        The warnings the steps gave.
    extra : dict
        Further figures of a variant of the demo.
    """

    out_dir: Path
    report_path: Path
    models: tuple[ModelSummary, ...]
    recordings: dict[str, Path]
    compensated_path: Path
    files: tuple[Path, ...]
    timings_s: dict[str, float]
    elapsed_s: float
    seed: int
    warnings: tuple[str, ...] = ()
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The result as JSON types: the files, the timings and each model's figures.

        Returns
        -------
        dict
            ``report``, ``out_dir`` (paths as strings), ``elapsed_s`` and ``timings_s``
            [s], ``seed``, ``models`` (each model's files and validation figures [°/h],
            improvements [%]) and ``files``.
        """
        figures = ("n_coefficients", "condition_number", "rms_residual", "r",
                   "weakly_correlated", "n_stages", "bias_stability_before",
                   "bias_stability_after", "bias_repeatability_before",
                   "bias_repeatability_after", "improvement_pct")  # fmt: skip
        models = [
            {"label": m.label, "model": str(m.model_path), "validation": str(m.validation_path),
             "c_files": [str(p) for p in m.c_files], **{k: getattr(m, k) for k in figures}}
            for m in self.models
        ]  # fmt: skip
        return {
            "report": str(self.report_path),
            "out_dir": str(self.out_dir),
            "elapsed_s": self.elapsed_s,
            "timings_s": self.timings_s,
            "seed": self.seed,
            "models": models,
            "files": [str(p) for p in self.files],
        }

    def text(self) -> list[Block]:
        """The validation figures of both models against the uncompensated run, and where
        the files went.

        Returns
        -------
        list of str or TextTable
            The table (coefficients, r, bias stability and repeatability before and after
            [°/h] with the improvement [%]; the reported model marked ``*``) and two lines.
        """
        ms = self.models
        rows = [("coefficients", "", *(str(m.n_coefficients) for m in ms)),
                ("r (limit 0.4)", "", *(fmt(m.r, 3) for m in ms))]  # fmt: skip
        for key, label in (("bias_stability", "bias stability"),
                           ("bias_repeatability", "bias repeatability")):  # fmt: skip
            after = [f"{fmt(getattr(m, f'{key}_after'))} ({_pct(m.improvement_pct.get(key))})"
                     for m in ms]  # fmt: skip
            rows.append((label, fmt(getattr(ms[0], f"{key}_before")), *after))
        columns = ("figure", "before", *(f"after, {m.label}" + (" *" if m is ms[0] else "")
                                         for m in ms))  # fmt: skip
        title = f"thermocal demo (seed {self.seed}): validation run, °/h"
        return [
            TextTable(title, columns, tuple(rows), ("left", *("right",) * (len(ms) + 1))),
            "* reported model; (…) improvement",
            f"{len(self.files)} files in {self.out_dir} ({self.elapsed_s:.1f} s)",
        ]


def _pct(value: float | None) -> str:
    """An improvement [%] with its sign, ``—`` for none."""
    return "—" if value is None else f"{value:+.1f} %"


def _fit_poly(run: RunData, cfg: DemoConfig, *, select: bool) -> TemperatureModel:
    """The ring-laser-gyro patent's 37-term polynomial, optionally with term selection."""
    params: dict[str, Any] = {"terms": "seed000", "rate_interval_s": cfg.rate_interval_s}
    if select:
        params["select"] = "bic"
    model = make_model("poly", **params)
    model.fit([run])
    model.signal_name = SIGNAL
    model.signal_unit = "deg/h"
    model.target = "bias"
    return model


def _validation_dict(
    model: TemperatureModel,
    model_path: Path,
    val: Recording,
    val_path: Path,
    mod: Recording,
    mod_path: Path,
    cfg: DemoConfig,
) -> dict[str, Any]:
    """``validate`` on the validation run, as the JSON the ``validate`` command prints."""
    run = RunData.from_recording(val, SIGNAL, list(model.temp_names_))
    res = validate(
        model,
        run,
        (mod.time_s, mod.temperature_c(AMBIENT)),
        validation_ambient=val.temperature_c(AMBIENT),
        averaging_s=cfg.averaging_s,
        settle_s=cfg.settle_s,
        zero_reference=zero_reference(model, val.meta),  # as thermocal validate
    )
    out = res.to_dict()
    out["model"] = str(model_path)
    out["family"] = model.family
    out["file"] = str(val_path)
    out["modeling_file"] = str(mod_path)
    out["ambient"] = AMBIENT
    return out


def _earth_rate(rec: Recording) -> float:
    """Earth rate on the sensitive axis [°/h] from the recording's latitude and axis."""
    if rec.meta.latitude_deg is None or rec.meta.axis is None:
        return 0.0
    return float(
        units.earth_rate_on_axis_deg_h(rec.meta.latitude_deg, units.parse_axis(rec.meta.axis))
    )


def _num(v: Any) -> float | None:
    return None if v is None else float(v)


def _fit_models(
    out: Path,
    cfg: DemoConfig,
    mod: Recording,
    caught: list[warnings.WarningMessage],
    written: list[Path],
    done: Callable[[str], None],
) -> tuple[dict[str, TemperatureModel], dict[str, Path], dict[str, dict[str, Any]], list[str]]:
    """Steps 3-4: the seed-37 and the selected polynomial fits of the modelling run, saved
    under ``models/``; the warnings each fit raised (from ``caught``), labelled."""
    # the earth rate on the sensitive axis is a known input, not a temperature effect
    earth = _earth_rate(mod)
    run_m = RunData.from_recording(mod, SIGNAL, list(TEMPS), known_input=earth)
    fitted: dict[str, TemperatureModel] = {}
    model_paths: dict[str, Path] = {}
    model_dicts: dict[str, dict[str, Any]] = {}
    fit_warnings: list[str] = []
    for label, select, step in (
        ("seed37", False, DEMO_STEPS[2]),
        ("selected", True, DEMO_STEPS[3]),
    ):
        n0 = len(caught)
        model = _fit_poly(run_m, cfg, select=select)
        fit_warnings += [f"{label} fit: {warning_text(w.message)}" for w in caught[n0:]]
        path = out / "models" / f"{label}.json"
        model_dicts[label] = save_model(model, path)
        fitted[label] = model
        model_paths[label] = path
        written.append(path)
        done(step)
    return fitted, model_paths, model_dicts, fit_warnings


def _validate_models(
    out: Path,
    cfg: DemoConfig,
    fitted: dict[str, TemperatureModel],
    model_paths: dict[str, Path],
    mod: Recording,
    mod_path: Path,
    val: Recording,
    val_path: Path,
    written: list[Path],
) -> tuple[dict[str, dict[str, Any]], dict[str, Path], list[str]]:
    """Step 5: each model judged on the validation run (``validation/LABEL.json``), and
    the labels best first: the smaller rms of the whole compensated validation run
    (within-stage stability of a navigation-grade RLG is noise-limited)."""
    val_dicts: dict[str, dict[str, Any]] = {}
    val_paths: dict[str, Path] = {}
    for label, model in fitted.items():
        vd = _validation_dict(model, model_paths[label], val, val_path, mod, mod_path, cfg)
        vp = out / "validation" / f"{label}.json"
        write_json(vp, vd)
        val_dicts[label] = vd
        val_paths[label] = vp
        written.append(vp)
    order = sorted(
        fitted,
        key=lambda lab: (float(val_dicts[lab].get("rms_after") or np.inf), lab != "selected"),
    )
    return val_dicts, val_paths, order


def _export_models(
    out: Path,
    cfg: DemoConfig,
    model_paths: dict[str, Path],
    fit_warnings: list[str],
    written: list[Path],
) -> dict[str, tuple[Path, ...]]:
    """Step 7: each model as C under ``c/`` (a family without a C generator: a warning)."""
    c_files: dict[str, tuple[Path, ...]] = {}
    for label in model_paths:
        try:
            _ex, paths = export_c(
                model_paths[label],
                out / "c",
                prefix=f"thermocal_{label}",
                sample_interval_s=1.0 / cfg.rate_hz,
            )
        except ModelFileError as exc:  # a family without a C generator
            fit_warnings.append(f"{label}: C export not available ({exc})")
            paths = []
        c_files[label] = tuple(paths)
        written += paths
    return c_files


def _write_demo_report(
    out: Path,
    cfg: DemoConfig,
    seed: int,
    order: list[str],
    primary: str,
    model_dicts: dict[str, dict[str, Any]],
    val_dicts: dict[str, dict[str, Any]],
    model_paths: dict[str, Path],
    val_paths: dict[str, Path],
    c_files: dict[str, tuple[Path, ...]],
    comp_path: Path,
    mod: Recording,
    mod_path: Path,
    val: Recording,
    val_path: Path,
    fit_warnings: list[str],
) -> Path:
    """Step 8: ``report.html`` of the models, best first."""
    entries = tuple(
        ModelEntry(lab, model_dicts[lab], val_dicts[lab], str(model_paths[lab])) for lab in order
    )
    notes = _demo_notes(cfg, seed, mod, primary)
    files = [("C export", str(p.relative_to(out))) for lab in order for p in c_files[lab]]
    files += [("validation result", str(val_paths[lab].relative_to(out))) for lab in order]
    files.append(("compensated validation run", str(comp_path.relative_to(out))))
    return write_report(
        out / "report.html",
        ReportInputs(
            models=entries,
            recording=val,
            modeling=mod,
            signal=SIGNAL,
            recording_path=str(val_path),
            modeling_path=str(mod_path),
            title="Temperature compensation of a ring-laser gyro (thermocal demo)",
            sensor=mod.meta.sensor_id,
            notes=notes,
            warnings=tuple(dict.fromkeys(fit_warnings)),
            files=tuple(files),
            generated_by="thermocal demo",
        ),
    )


def run_demo(
    out_dir: str | Path = "thermocal-demo",
    *,
    seed: int = 1,
    config: DemoConfig | None = None,
    progress: Callable[[str], None] | None = None,
) -> DemoResult:
    """Run the chamber workflow (module docstring) and write everything into ``out_dir``:
    ``report.html``; ``models/seed37.json``, ``models/selected.json``; ``validation/*.json``;
    ``c/*.h``, ``c/*.c``; ``data/rlg-modelling.parquet``, ``data/rlg-validation.parquet``
    (+ ``*.truth.json``), ``data/rlg-validation-compensated.parquet``; ``profiles/*.csv``.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The folder written.
    seed : int
        The seed; the same seed gives the same output.
    config : DemoConfig, optional
        Sizes and rates of the demonstration.
    progress : callable, optional
        Called with the name of each of :data:`DEMO_STEPS` once done.

    Returns
    -------
    DemoResult
    """
    cfg = config or DemoConfig()
    out = Path(out_dir)
    for sub in ("models", "validation", "c", "data", "profiles"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    timings: dict[str, float] = {}
    written: list[Path] = []
    t_start = time.perf_counter()
    clock = [t_start]

    def done(step: str) -> None:
        now = time.perf_counter()
        timings[step] = now - clock[0]
        clock[0] = now
        if progress is not None:
            progress(step)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ThermocalWarning)

        prof_m, prof_v = _demo_profiles(out, cfg, seed, written)  # 1. profiles
        done(DEMO_STEPS[0])
        mod, val, mod_path, val_path = _demo_runs(out, cfg, seed, prof_m, prof_v, written)
        done(DEMO_STEPS[1])  # 2. simulation

        # 3-4. fits
        fitted, model_paths, model_dicts, fit_warnings = _fit_models(
            out, cfg, mod, caught, written, done
        )

        # 5. validation
        val_dicts, val_paths, order = _validate_models(
            out, cfg, fitted, model_paths, mod, mod_path, val, val_path, written
        )
        primary = order[0]
        done(DEMO_STEPS[4])

        # 6. compensation
        comp_path = out / "data" / "rlg-validation-compensated.parquet"
        compensate_file(fitted[primary], val_path, comp_path, signal=SIGNAL)
        written.append(comp_path)
        done(DEMO_STEPS[5])

        # 7. C export
        c_files = _export_models(out, cfg, model_paths, fit_warnings, written)
        done(DEMO_STEPS[6])

        # 8. report
        report_path = _write_demo_report(
            out, cfg, seed, order, primary, model_dicts, val_dicts, model_paths, val_paths,
            c_files, comp_path, mod, mod_path, val, val_path, fit_warnings,
        )  # fmt: skip
        written.append(report_path)
        done(DEMO_STEPS[7])
    msgs = tuple(dict.fromkeys(warning_text(w.message) for w in caught))

    summaries = [
        _summary_of(lab, model_paths[lab], val_paths[lab], c_files[lab], model_dicts[lab],
                    val_dicts[lab])
        for lab in order
    ]  # fmt: skip
    return DemoResult(
        out_dir=out,
        report_path=report_path,
        models=tuple(summaries),
        recordings={"modelling": mod_path, "validation": val_path},
        compensated_path=comp_path,
        files=tuple(written),
        timings_s=timings,
        elapsed_s=time.perf_counter() - t_start,
        seed=seed,
        warnings=msgs,
    )


def _demo_profiles(out: Path, cfg: DemoConfig, seed: int, written: list[Path]) -> tuple[Any, Any]:
    """The modelling profile (a shortened cycle of the ring-laser-gyro patent) and a validation
    profile designed
    to be weakly correlated with it (r < 0.4), written as chamber programs."""
    prof_m = rlg_modelling(
        low_c=cfg.low_c,
        high_c=cfg.high_c,
        n_temperature_cycles=cfg.n_temperature_cycles,
        hold_s=cfg.hold_s,
        rates_c_per_min=cfg.rates_c_per_min,
        rate_hold_s=cfg.rate_hold_s,
    )
    prog_m = prof_m.program(60.0)
    prof_v = design_validation_profile(
        *prog_m, seed=seed, n_holds=cfg.n_holds, hold_s=cfg.validation_hold_s
    )
    for name, prof in (("rlg-modelling", prof_m), ("rlg-validation", prof_v)):
        p = out / "profiles" / f"{name}.csv"
        write_program(p, *prof.program(60.0))
        written.append(p)
    return prof_m, prof_v


def _demo_runs(
    out: Path, cfg: DemoConfig, seed: int, prof_m: Any, prof_v: Any, written: list[Path]
) -> tuple[Any, Any, Path, Path]:
    """The simulated modelling and validation runs, written with their truth."""
    ((mod, truth_m),) = run_scenario("rlg-modelling", seed, prof_m, rate_hz=cfg.rate_hz)
    ((val, truth_v),) = run_scenario("rlg-validation", seed, prof_v, rate_hz=cfg.rate_hz)
    mod_path = out / "data" / "rlg-modelling.parquet"
    val_path = out / "data" / "rlg-validation.parquet"
    for rec, truth, path in ((mod, truth_m, mod_path), (val, truth_v, val_path)):
        write_recording(rec, path)
        tp = path.with_suffix(".truth.json")
        write_json(tp, truth)
        written += [path, tp]
    mod = dataclasses.replace(mod, source=str(mod_path))
    val = dataclasses.replace(val, source=str(val_path))
    return mod, val, mod_path, val_path


def _demo_notes(cfg: DemoConfig, seed: int, mod: Any, primary: str) -> tuple[str, ...]:
    """The report's notes on the simulated data and the models."""
    return (
        f"Simulated data (thermocal.simulate, preset rlg, seed {seed}): a navigation-grade "
        "ring-laser gyro with four temperature sensors (T1 block, T2 discharge, T3 mount, "
        f"T4 case), sampled at {cfg.rate_hz:g} Hz, sensitive axis up at latitude "
        f"{mod.meta.latitude_deg:g}°. Modelling run: shortened ring-laser-gyro patent profile "
        f"({cfg.low_c:g}…{cfg.high_c:g} °C cycle, ramps at ±"
        + ", ±".join(f"{r:g}" for r in cfg.rates_c_per_min)
        + " °C/min). Validation run: hold profile designed by thermocal to be weakly "
        "correlated with the modelling run (r < 0.4).",
        f"Models: 'seed37' is the ring-laser-gyro patent's 37-term polynomial; 'selected' the same "
        f"family with term selection (BIC). The model with the smaller rms of the "
        f"compensated validation run ('{primary}') is reported in detail and was used for "
        "the compensated file.",
    )


def _summary_of(
    lab: str,
    model_path: Path,
    val_path: Path,
    c_files: tuple[Path, ...],
    md: dict[str, Any],
    vd: dict[str, Any],
) -> ModelSummary:
    """One model's figures for :class:`DemoResult` (from its model and validation files)."""
    fit = md.get("fit") or {}
    return ModelSummary(
        label=lab,
        model_path=model_path,
        validation_path=val_path,
        c_files=c_files,
        n_coefficients=len(md.get("coefficients") or []),
        condition_number=_num(fit.get("condition_number")),
        rms_residual=float(fit.get("rms_residual") or float("nan")),
        r=_num(vd.get("r")),
        weakly_correlated=vd.get("weakly_correlated"),
        n_stages=int(vd.get("n_stages") or 0),
        bias_stability_before=_num(vd.get("bias_stability_before")),
        bias_stability_after=_num(vd.get("bias_stability_after")),
        bias_repeatability_before=_num(vd.get("bias_repeatability_before")),
        bias_repeatability_after=_num(vd.get("bias_repeatability_after")),
        improvement_pct=dict(vd.get("improvement_pct") or {}),
    )


__all__ = ["DEMO_STEPS", "QUICK", "DemoConfig", "DemoResult", "ModelSummary", "run_demo"]
