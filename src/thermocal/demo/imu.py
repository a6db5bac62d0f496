"""The ``imu`` demo: the multi-channel workflow on a simulated six-axis MEMS IMU.

Steps: simulate the ``mems-imu`` scenario's modelling run and its weakly
correlated validation run (the same unit, :func:`thermocal.simulate.scenario_mems_imu`);
fit one cubic per channel on the die temperature into a calibration; validate every
channel on the validation run (r against the modelling run's chamber air, figures before
and after); compensate the validation file in one chunked pass; export one C header and
source for the six channels; write ``report.html`` — a per-channel summary table (range,
model, residual, validation figures before/after, share of the true temperature-induced
bias removed) and a grid of bias against die temperature before and after, one panel per
channel, with the channel's warnings.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal import units
from thermocal.compensate.kernels import prepare_run, zero_reference
from thermocal.errors import ThermocalWarning
from thermocal.export.c import generate_c_calibration
from thermocal.models.calibration import Calibration, Channel, guess_role
from thermocal.models.format import model_file_dict
from thermocal.models.poly import PolyModel
from thermocal.models.rundata import RunData, model_inputs
from thermocal.pipeline.compensate import compensate_channels
from thermocal.pipeline.messages import warning_text
from thermocal.pipeline.model_file import save_calibration
from thermocal.report.calibration import CalibrationReportInputs, write_calibration_report
from thermocal.report.text import Block, TextTable, fmt
from thermocal.simulate import IMU_CHANNELS, SCENARIOS
from thermocal.validation import validate
from thermocal.writers import write_json, write_recording

if TYPE_CHECKING:
    from thermocal.recording import Recording
    from thermocal.validation import ValidationResult

IMU_STEPS = ("simulate", "fit", "validate", "compensate", "export-c", "report")
"""Progress steps of :func:`run_imu_demo`."""

TEMP = "T_die"
GRAVITY_AXIS = "+z"
"""The simulated unit sits with +z up (the scenario's gravity on az)."""
TRUE_REMOVED = "true bias removed [%]"
AMBIENT = "T_chamber"


@dataclass(frozen=True)
class ChannelSummary:
    """One channel's figures: ``removed_pct`` share of the true temperature-induced bias
    removed on the validation run (``100 (1 − rms(e)/sd(E))``, e the model's error against
    the truth E, both centred); validation figures in the channel's data unit.

    Attributes
    ----------
    name, unit : str
        The channel and its data unit.
    n_coefficients : int
        Number of coefficients of its model.
    rms_residual : float
        RMS of the fit's residuals [unit].
    condition_number : float or None
        Condition number of the scaled design.
    temp_range_c : (float, float)
        Temperature range of the fit [°C].
    r : float or None
        Correlation of the modelling and validation temperature histories.
    bias_stability_before, bias_stability_after : float or None
        Bias stability of the validation run before and after compensation [unit].
    rms_before, rms_after : float or None
        RMS of the validation run's bias about its mean before and after [unit].
    removed_pct : float
        Share of the true temperature-induced bias removed [%].
    warnings : list of str
        The channel's warnings.
    """

    name: str
    unit: str
    n_coefficients: int
    rms_residual: float
    condition_number: float | None
    temp_range_c: tuple[float, float]
    r: float | None
    bias_stability_before: float | None
    bias_stability_after: float | None
    rms_before: float | None
    rms_after: float | None
    removed_pct: float
    warnings: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class ImuDemoResult:
    """Where everything went and the per-channel figures.

    Attributes
    ----------
    out_dir : Path
        The demo's folder.
    report_path, calibration_path : Path
        The HTML report and the calibration file.
    channels : list of ChannelSummary
        Each channel's figures.
    files : list of Path
        Every file written.
    elapsed_s : float
        Total duration [s].
    """

    out_dir: Path
    report_path: Path
    calibration_path: Path
    channels: list[ChannelSummary]
    files: list[Path]
    elapsed_s: float
    seed: int = 1

    def to_dict(self) -> dict[str, Any]:
        """The result as JSON types: the files, the seed and each channel's figures.

        Returns
        -------
        dict
            ``report``, ``calibration``, ``out_dir`` (paths as strings), ``elapsed_s`` [s],
            ``seed``, ``channels`` ``{name: {unit, n_coefficients, rms_residual, …,
            removed_pct [%], warnings}}`` and ``files``.
        """
        keys = ("unit", "n_coefficients", "rms_residual", "condition_number", "temp_range_c",
                "r", "bias_stability_before", "bias_stability_after", "rms_before",
                "rms_after", "removed_pct", "warnings")  # fmt: skip
        return {
            "report": str(self.report_path),
            "calibration": str(self.calibration_path),
            "out_dir": str(self.out_dir),
            "elapsed_s": self.elapsed_s,
            "seed": self.seed,
            "channels": {
                c.name: {**{k: getattr(c, k) for k in keys}, "temp_range_c": list(c.temp_range_c)}
                for c in self.channels
            },
            "files": [str(p) for p in self.files],
        }

    def text(self) -> list[Block]:
        """Each channel's validation figures as a table, and where the files went.

        Returns
        -------
        list of str or TextTable
            The table (r, rms before and after [the channel's unit], the share of the true
            temperature-induced bias removed [%]) and two lines.
        """
        title = f"thermocal demo --imu (seed {self.seed}): validation run"  # cli-words: its name
        columns = ("channel", "unit", "r", "rms before", "rms after", "bias removed")
        rows = tuple((c.name, c.unit, fmt(c.r, 3), fmt(c.rms_before), fmt(c.rms_after),
                      f"{c.removed_pct:.1f} %") for c in self.channels)  # fmt: skip
        return [
            TextTable(title, columns, rows, ("left", "left", *("right",) * 4)),
            "bias removed: share of the simulator's true temperature-induced bias",
            f"{len(self.files)} files in {self.out_dir} ({self.elapsed_s:.1f} s)",
        ]


def _fit_channels(mod: Recording) -> tuple[Calibration, dict[str, list[str]]]:
    """Step 2: one cubic per channel in the die temperature, gravity on the up axis a
    known input of the accelerometers; the warnings of each channel's fit."""
    channels: list[Channel] = []
    fit_warnings: dict[str, list[str]] = {}
    for name, unit in IMU_CHANNELS:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ThermocalWarning)
            # gravity on the up axis (+z) is a known input: compensation keeps it
            g_mg = units.gravity_on_axis_mg(name[-1], GRAVITY_AXIS, units.STANDARD_GRAVITY_M_S2)
            g_mg = g_mg if units.signal_kind(unit) == "accel" else 0.0
            run = RunData.from_recording(mod, name, [TEMP], known_input=g_mg)
            model = PolyModel(order=3, per_run_offset=False).fit([run])
        model.signal_name, model.signal_unit = name, run.signal_unit or unit
        what = f"gravity {g_mg:+g} mg ({GRAVITY_AXIS} up)" if g_mg else "none"
        model.inputs_ = model_inputs(mod, name, [TEMP], known_input=g_mg, known_input_what=what)
        channels.append(Channel(name, name, unit, model, guess_role(name, unit)))
        fit_warnings[name] = [warning_text(w.message) for w in caught]
    return Calibration(channels), fit_warnings


def _validate_channels(
    cal: Calibration, mod: Recording, val: Recording, fit_warnings: dict[str, list[str]]
) -> dict[str, ValidationResult]:
    """Step 3: every channel judged on the validation run against the modelling run's
    chamber air, in the data's own unit; its warnings added to ``fit_warnings``."""
    mod_air = (mod.time_s, mod.column(AMBIENT))
    results = {}
    for ch in cal.channels:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ThermocalWarning)
            mrun = prepare_run(ch.model, val, ch.signal, [TEMP])
            res = validate(
                ch.model, mrun.run, mod_air, validation_ambient=val.column(AMBIENT),
                zero_reference=zero_reference(ch.model, val.meta),  # as thermocal validate
            )  # fmt: skip
        results[ch.name] = res.in_unit(mrun.data_unit, mrun.factor)
        fit_warnings[ch.name] += [warning_text(w.message) for w in caught]
    return results


def _summary(
    ch: Channel, val: Recording, res: ValidationResult, warns: list[str]
) -> ChannelSummary:
    """A channel's line of the summary; ``removed_pct = 100·(1 − rms(e)/sd(E))``, e the
    model's error against the simulator's temperature-induced bias E, both centred."""
    model_v = _model_in_data_unit(ch, val)
    true_e = val.column(f"truth_{ch.name}")
    err = (model_v - model_v.mean()) - (true_e - true_e.mean())
    removed = 100.0 * (1.0 - float(np.sqrt(np.mean(err**2))) / float(np.std(true_e)))
    st = ch.model.stats_
    return ChannelSummary(
        name=ch.name,
        unit=ch.unit,
        n_coefficients=st.n_coefficients,
        rms_residual=float(st.rms_residual),
        condition_number=st.condition_number,
        temp_range_c=(float(ch.model.temp_range_[0, 0]), float(ch.model.temp_range_[0, 1])),
        r=res.r,
        bias_stability_before=res.bias_stability_before,
        bias_stability_after=res.bias_stability_after,
        rms_before=res.rms_before,
        rms_after=res.rms_after,
        removed_pct=removed,
        warnings=warns,
    )


def _simulate(out: Path, seed: int, rate_hz: float, files: list[Path]) -> tuple[Any, Any]:
    """The modelling and validation runs of the ``mems-imu`` scenario, written with the truth."""
    ((mod, truth),) = SCENARIOS["mems-imu"](seed, rate_hz=rate_hz)
    ((val, _),) = SCENARIOS["mems-imu"](seed, run="validation", rate_hz=rate_hz)
    for name, rec in (("imu-modelling", mod), ("imu-validation", val)):
        p = out / "data" / f"{name}.parquet"
        write_recording(rec, p)
        files.append(p)
    truth_path = out / "data" / "imu.truth.json"
    write_json(truth_path, truth)
    files.append(truth_path)
    return mod, val


def run_imu_demo(
    out_dir: str | Path = "thermocal-imu-demo",
    *,
    seed: int = 1,
    rate_hz: float = 1.0,
    progress: Callable[[str], None] | None = None,
) -> ImuDemoResult:
    """Run the six-channel workflow (module docstring) into ``out_dir``.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The folder written.
    seed : int
        The seed; the same seed gives the same output.
    rate_hz : float
        Sample rate [Hz].
    progress : callable, optional
        Called with each step's name.

    Returns
    -------
    ImuDemoResult
    """
    out = Path(out_dir)
    for sub in ("data", "models", "c"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    files: list[Path] = []

    def step(name: str) -> None:
        if progress is not None:
            progress(name)

    mod, val = _simulate(out, seed, rate_hz, files)  # 1. simulate
    step(IMU_STEPS[0])

    # 2. fit: one cubic per channel on the die temperature
    cal, fit_warnings = _fit_channels(mod)
    cal_path = out / "models" / "imu.json"
    save_calibration(cal, cal_path)
    files.append(cal_path)
    step(IMU_STEPS[1])

    # 3. validate every channel against the modelling run's chamber air
    results = _validate_channels(cal, mod, val, fit_warnings)
    step(IMU_STEPS[2])

    # 4. compensate the validation file, every channel in one pass
    comp_path = out / "data" / "imu-validation-compensated.parquet"
    compensate_channels(
        [(ch.signal, ch.model) for ch in cal.channels], out / "data" / "imu-validation.parquet",
        comp_path,
    )  # fmt: skip
    files.append(comp_path)
    step(IMU_STEPS[3])

    # 5. one C module for the six channels
    ex = generate_c_calibration(
        [(ch.name, model_file_dict(ch.model), ch.unit) for ch in cal.channels], prefix="imu"
    )
    files.extend(ex.write(out / "c"))
    step(IMU_STEPS[4])

    # 6. summary and report
    summaries = [_summary(ch, val, results[ch.name], fit_warnings[ch.name]) for ch in cal.channels]
    report = out / "report.html"
    validation = {
        "channels": {n: {**r.to_dict(), "verdict": r.verdict} for n, r in results.items()}
    }
    val_json = out / "validation.json"
    write_json(val_json, validation)
    files.append(val_json)
    write_calibration_report(
        report,
        CalibrationReportInputs(
            calibration=cal,
            recording=val,
            recording_path=str(out / "data" / "imu-validation.parquet"),
            modeling_path=str(out / "data" / "imu-modelling.parquet"),
            calibration_path=str(cal_path),
            validation=validation,
            validation_path=str(val_json),
            title="Six-axis MEMS IMU calibration (simulated)",
            sensor=f"mems-imu scenario, seed {seed}",
            generated_by="thermocal demo --imu",  # cli-words: the command the report records
            extra={TRUE_REMOVED: {c.name: c.removed_pct for c in summaries}},
            notes=(
                "Simulated unit: one cubic per channel in the die temperature, fitted on the "
                "modelling run, judged on a weakly correlated validation run. "
                f"'{TRUE_REMOVED}' = 100·(1 − rms(e)/sd(E)), e the model's error against the "
                "simulator's temperature-induced bias E, both centred; the acceptance line is "
                "97 %.",
            ),
        ),
    )
    files.append(report)
    step(IMU_STEPS[5])
    return ImuDemoResult(out, report, cal_path, summaries, files, time.perf_counter() - t0, seed)


def _model_in_data_unit(ch: Channel, rec: Any) -> np.ndarray:
    """The channel's model on ``rec`` in the data column's own unit."""
    mrun = prepare_run(ch.model, rec, ch.signal, [TEMP])
    return mrun.to_data_unit(ch.model.predict(mrun.run))


__all__ = ["IMU_STEPS", "ChannelSummary", "ImuDemoResult", "run_imu_demo"]
