"""``thermocal px4-tempcal LOG.ulg -o DIR``: PX4's thermal calibration from one log.

Every ``sensor_gyro``/``sensor_accel`` instance with a temperature is binned, judged on
held-out bins and fitted as a cubic per axis (:mod:`thermocal.tempcal.px4`); writes
``DIR/calibration.json``, ``DIR/px4.params`` (QGroundControl, TC_*) and one report per
sensor, ``DIR/report_<topic>_<n>.html``.
"""

import functools
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, ParamSpec, TypeVar

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    AllowMotionOpt,
    AllowNarrowOpt,
    JsonOpt,
    emit,
    fmt,
    handle_errors,
    load_recording,
    stdout,
)
from thermocal.defaults import overrides_of
from thermocal.errors import ThermocalInputError
from thermocal.outputs import check_outputs

if TYPE_CHECKING:
    import rich.table as _rich_table
else:
    _rich_table = LazyModule("rich.table")

P = ParamSpec("P")
R = TypeVar("R")


def staged_outputs(fn: Callable[P, R]) -> Callable[P, R]:
    """The output set is built in a staging directory beside DIR and moved into place when
    complete (:func:`thermocal.writers.commit_directory`); on any failure — a later sensor's
    error, Ctrl-C — this removes the staging directory, so that no part of the set is left."""

    @functools.wraps(fn)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return fn(*args, **kwargs)
        except BaseException:
            from thermocal.writers import discard_staging

            discard_staging()
            raise

    return wrapper


@app.command("px4-tempcal")
@handle_errors
@staged_outputs
def px4_tempcal_cmd(
    log: Annotated[Path, typer.Argument(help="PX4 log (.ulg).", show_default=False)],
    output: Annotated[Path, typer.Option("-o", "--output", help="Directory to write.")],
    tref: Annotated[
        float | None,
        typer.Option("--tref", help="Reference temperature [°C] (default: mid-range)."),
    ] = None,
    allow_narrow: AllowNarrowOpt = False,
    allow_motion: AllowMotionOpt = False,
    as_json: JsonOpt = False,
) -> None:
    """Fit every gyro and accelerometer instance of a PX4 log as PX4 would (a cubic per axis
    about TREF), robust to spikes, with equal weight across the temperature range and
    judged on held-out data; write the TC_* parameters, the calibration and reports."""
    import numpy as np

    from thermocal.export.params import ParamSet, export_params, px4_offset_params
    from thermocal.models.calibration import Calibration
    from thermocal.models.files import save_calibration
    from thermocal.readers.dispatch import read_log_table
    from thermocal.report.calibration import CalibrationReportInputs, write_calibration_report
    from thermocal.tempcal.px4 import (
        OFFSET_TOPICS,
        GateWarning,
        calibration_of,
        end_warning,
        fit_offset_sensor,
        fit_sensor,
        log_topics,
        offset_summary,
        stall_warning,
        step_warnings,
        summary,
    )
    from thermocal.writers import atomic_write, commit_directory, staging_directory

    # DIR may hold the log; the files of the set (replaced by name) may not be it
    check_outputs([output / "calibration.json", output / "px4.params"], [log], dirs=[output])
    if output.exists() and not output.is_dir():
        raise ThermocalInputError(f"{output}: exists and is not a directory")
    topics = log_topics(log)
    if not topics:
        raise ThermocalInputError(
            f"{log}: no sensor_gyro or sensor_accel topic with a temperature in the log"
        )
    check_outputs([output / f"report_{n}_{i}.html" for n, i in topics], [log], dirs=[output])
    stage = staging_directory(output)  # the set is moved into place whole, or removed
    fits, reports = [], []
    gates: list[str | None] = []
    series: dict[str, tuple[Any, Any]] = {}
    offset_fits = []
    params = ParamSet("px4")
    for name, inst in topics:
        if name in OFFSET_TOPICS:  # barometers and magnetometers: TC_B / TC_M
            df, _info = read_log_table(log, f"{name}.{inst}")
            fields = OFFSET_TOPICS[name][1]
            _require_fields(df, ["timestamp", "temperature", *fields], log, f"{name}.{inst}")
            ids = df["device_id"].to_numpy() if "device_id" in df.columns else np.zeros(1)
            ofit = fit_offset_sensor(
                df["timestamp"].to_numpy() * 1e-6, df["temperature"].to_numpy(),
                np.column_stack([df[f].to_numpy() for f in fields]), name, inst,
                int(np.median(ids)), tref_c=tref,
                overrides=overrides_of(allow_narrow, allow_motion),
            )  # fmt: skip
            offset_fits.append(ofit)
            params.merge(
                px4_offset_params(ofit.kind, inst, ofit.device_id, *ofit.sweep_c, ofit.tref_c,
                                  ofit.coefficients),
                f"{name}.{inst}",
            )  # fmt: skip
            continue
        kind = "gyro" if name == "sensor_gyro" else "accel"
        rec = load_recording(log, topic=f"{name}.{inst}", signal="x,y,z", temps="temperature")
        fit = fit_sensor(rec, name, kind, inst, overrides=overrides_of(allow_narrow, allow_motion))
        fits.append(fit)
        where = f"{name}.{inst}"
        temp_c = rec.temperature_c("temperature")
        series[where] = (rec.time_s, np.column_stack([rec.signal(a)[0] for a in "xyz"]))
        gates.append(stall_warning(where, rec.time_s, temp_c))
        if tref is not None:
            gates.append(end_warning(where, "TREF", tref, *fit.sweep_c))
        sub = Calibration(fit.channels)
        with warnings.catch_warnings():  # accelerometers: relative offsets, as PX4's script
            warnings.simplefilter("ignore")
            ps = export_params(
                sub, "px4", instance=inst, device_id={kind: fit.device_id}, tref_c=tref
            )
        params.merge(ps, f"{name}.{inst}")
        rp = output / f"report_{name}_{inst}.html"
        write_calibration_report(
            stage / rp.name,
            CalibrationReportInputs(
                calibration=sub, recording=rec, recording_path=str(log),
                title=f"PX4 thermal calibration — {name}.{inst}",
                sensor=f"device id {fit.device_id}", generated_by="thermocal px4-tempcal",
                extra={"hold-out rms": dict(zip(
                    [c.name for c in fit.channels], fit.holdout_rms.values(), strict=True
                ))},
                notes=(
                    "Each axis: a cubic in the temperature fitted to the medians of 0.5 °C "
                    "temperature bins (equal weight across the range, robust to spikes); "
                    "'hold-out rms' is the rms of a cubic fitted to the even bins on the odd "
                    "ones, in the canonical unit (°/h or mg).",
                    *(f"Firmware: {n}" for n in ps.notes),
                ),
            ),
        )  # fmt: skip
        reports.append(rp)
    gates.extend(step_warnings(fits, series))
    for msg in gates:
        if msg:
            warnings.warn(GateWarning(msg), stacklevel=1)
    if not fits:
        raise ThermocalInputError(
            f"{log}: no sensor_gyro or sensor_accel topic with a temperature in the log"
        )
    cal_path = output / "calibration.json"
    save_calibration(calibration_of(fits), stage / cal_path.name)
    params_path = output / "px4.params"
    with atomic_write(stage / params_path.name, "w") as fh:
        fh.write(params.text())
    commit_directory(stage, output)
    if any(f.kind == "accel" for f in fits):
        params.notes.append(
            "accelerometers: offsets relative to mid-range (gravity is in the data), as PX4's "
            "own script does"
        )
    out = {
        "log": str(log),
        "params": str(params_path),
        "calibration": str(cal_path),
        "reports": [str(p) for p in reports],
        "sensors": {**summary(fits), **offset_summary(offset_fits)},
        "notes": params.notes,
    }

    def human() -> None:
        table = _rich_table.Table(title=f"PX4 thermal calibration of {log}")
        for col in ("sensor", "device id", "sweep [°C]", "bins", "hold-out rms x/y/z"):
            table.add_column(col)
        for f in fits:
            table.add_row(
                f"{f.topic}.{f.instance}", str(f.device_id),
                f"{f.sweep_c[0]:.1f}…{f.sweep_c[1]:.1f}", str(f.n_bins),
                " / ".join(fmt(v, 3) for v in f.holdout_rms.values()) + f" {f.unit}",
            )  # fmt: skip
        for o in offset_fits:
            table.add_row(
                f"{o.topic}.{o.instance}", str(o.device_id),
                f"{o.sweep_c[0]:.1f}…{o.sweep_c[1]:.1f}", str(o.n_bins),
                " / ".join(fmt(v, 3) for v in o.holdout_rms.values()) + f" {o.unit}",
            )  # fmt: skip
        stdout.print(table)
        for n in params.notes:
            stdout.print(n)
        stdout.print(f"parameters: [bold]{params_path}[/bold]", markup=True)

    emit(out, as_json, human)


@app.command("ardupilot-tempcal")
@handle_errors
@staged_outputs
def ardupilot_tempcal_cmd(
    log: Annotated[Path, typer.Argument(help="ArduPilot log (.bin).", show_default=False)],
    output: Annotated[Path, typer.Option("-o", "--output", help="Directory to write.")],
    allow_narrow: AllowNarrowOpt = False,
    allow_motion: AllowMotionOpt = False,
    as_json: JsonOpt = False,
) -> None:
    """ArduPilot's thermal calibration from one DataFlash log: every IMU instance's gyro
    and accelerometer fitted as in px4-tempcal, written as INS_TCAL* (.parm), a calibration
    and reports (the polynomial about 35 °C without constant, as the firmware takes it)."""

    import numpy as np

    from thermocal.errors import MissingColumnError
    from thermocal.export.params import ParamSet, export_params
    from thermocal.models.calibration import Calibration
    from thermocal.models.files import save_calibration
    from thermocal.readers.dataflash import dataflash_table, read_dataflash_log
    from thermocal.recording import Recording
    from thermocal.report.calibration import CalibrationReportInputs, write_calibration_report
    from thermocal.tempcal.px4 import (
        AP_ROTATIONS,
        GateWarning,
        ardupilot_raw,
        calibration_of,
        end_warning,
        fit_sensor,
        stall_warning,
        step_warnings,
        summary,
    )
    from thermocal.writers import atomic_write, commit_directory, staging_directory

    # DIR may hold the log; the files of the set (replaced by name) may not be it
    names = ["calibration.json", "ardupilot.parm"]
    names += [f"report_IMU_{i}_{k}.html" for i in range(3) for k in ("gyro", "accel")]
    check_outputs([output / n for n in names], [log], dirs=[output])
    if output.exists() and not output.is_dir():
        raise ThermocalInputError(f"{output}: exists and is not a directory")
    stage = staging_directory(output)  # the set is moved into place whole, or removed
    fits, reports = [], []
    gates: list[str | None] = []
    series: dict[str, tuple[Any, Any]] = {}
    hygiene: dict[str, dict[str, Any]] = {}
    orientation = 0
    params = ParamSet("ardupilot")
    dlog = read_dataflash_log(log, ["IMU", "IMU2", "IMU3"])  # the log is read once
    for inst in range(3):  # ArduPilot logs up to three IMUs
        try:
            df, _info = dataflash_table(dlog, log, "IMU", inst)
        except MissingColumnError:
            if inst == 0:
                raise
            break
        tcol = next((c for c in ("T", "Temp") if c in df.columns), None)
        if tcol is None:  # LogStructure.h: ``T`` (``Temp`` in Copter 3.4–3.6)
            raise ThermocalInputError(
                f"{log}: IMU.{inst} has no temperature field (T or Temp); it has: "
                + ", ".join(map(str, df.columns))
            )
        _require_fields(df, [f"{p}{a}" for p in ("Gyr", "Acc") for a in "XYZ"], log, f"IMU.{inst}")
        time_s = df["TimeUS"].to_numpy() * 1e-6
        temp_c = df[tcol].to_numpy()
        if not np.isfinite(temp_c).any() or np.all(temp_c[np.isfinite(temp_c)] == 0):
            warnings.warn(
                GateWarning(
                    f"{log}: IMU.{inst} left out: its temperature is all 0 or NaN (a sensor "
                    "without a thermometer cannot be calibrated over temperature)"
                ),
                stacklevel=1,
            )
            continue
        gates.append(stall_warning(f"IMU.{inst}", time_s, temp_c))
        per_kind = []
        for kind, prefix, unit in (("gyro", "Gyr", "rad/s"), ("accel", "Acc", "m/s^2")):
            xyz = np.column_stack([df[f"{prefix}{a.upper()}"].to_numpy() for a in "xyz"])
            xyz, active, orientation = ardupilot_raw(dlog.params, inst, kind, temp_c, xyz)
            hyg = hygiene.setdefault(f"IMU.{inst}", {"active_tcal_removed": active is not None})
            if active is not None:
                hyg.update(tmin_c=active.tmin_c, tmax_c=active.tmax_c, caltemp_c=active.caltemp_c)
            sub_rec = Recording.from_arrays(
                time_s, {a: xyz[:, j] for j, a in enumerate("xyz")},
                {"temperature": temp_c}, signal_unit=unit,
            )  # fmt: skip
            sub_rec.source = str(log)
            sub_rec.validate()
            fit = fit_sensor(
                sub_rec, f"IMU.{prefix}", kind, inst,
                overrides=overrides_of(allow_narrow, allow_motion), firmware="ardupilot",
            )  # fmt: skip
            fits.append(fit)
            per_kind.append((fit, sub_rec))
            series[f"{fit.topic}.{inst}"] = (time_s, np.column_stack(
                [sub_rec.signal(a)[0] for a in "xyz"]
            ))  # fmt: skip
        sub = Calibration([ch for f, _r in per_kind for ch in f.channels])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ps = export_params(sub, "ardupilot", instance=inst)
        params.merge(ps, f"IMU.{inst}")
        hyg = hygiene[f"IMU.{inst}"]
        old_coef = {n: dlog.params[n] for n in ps.params if n in dlog.params}
        hyg["coefficients"] = {
            n: {"old": old_coef.get(n), "new": float(v)}
            for n, v in ps.params.items() if "_ACC" in n or "_GYR" in n
        }  # fmt: skip
        for kind in ("accel", "gyro"):
            ref = hyg.get("caltemp_c", {}).get(kind)
            if ref is not None:
                lo_c, hi_c = (
                    ps.params[f"INS_TCAL{inst + 1}_TMIN"],
                    ps.params[f"INS_TCAL{inst + 1}_TMAX"],
                )
                gates.append(end_warning(f"IMU.{inst}", f"{kind} CALTEMP", ref, lo_c, hi_c))
        for fit, sub_rec in per_kind:
            rp = output / f"report_IMU_{inst}_{fit.kind}.html"
            write_calibration_report(
                stage / rp.name,
                CalibrationReportInputs(
                    calibration=Calibration(fit.channels), recording=sub_rec,
                    recording_path=str(log), title=f"ArduPilot thermal calibration — IMU {inst} "
                    f"{fit.kind}", generated_by="thermocal ardupilot-tempcal",
                    notes=tuple(f"Firmware: {n}" for n in ps.notes),
                ),
            )  # fmt: skip
            reports.append(rp)
    if not fits:
        raise ThermocalInputError(f"{log}: no IMU with a usable temperature in the log")
    gates.extend(step_warnings(fits, series))
    for msg in gates:
        if msg:
            warnings.warn(GateWarning(msg), stacklevel=1)
    cal_path = output / "calibration.json"
    save_calibration(calibration_of(fits), stage / cal_path.name)
    parm = output / "ardupilot.parm"
    with atomic_write(stage / parm.name, "w") as fh:
        fh.write(params.text())
    commit_directory(stage, output)
    out = {
        "log": str(log),
        "params": str(parm),
        "calibration": str(cal_path),
        "reports": [str(p) for p in reports],
        "sensors": summary(fits),
        "notes": params.notes,
        "log_hygiene": {
            "AHRS_ORIENTATION": orientation,
            "rotated_back_to_sensor_frame": orientation != 0,
            "imus": hygiene,
        },
    }
    found = [k for k, h in hygiene.items() if h["active_tcal_removed"]]
    if found:
        params.notes.append(
            "active INS_TCAL coefficients found in the log and removed from the data before "
            "fitting (the firmware had subtracted them): " + ", ".join(found)
        )
    if orientation:
        params.notes.append(
            f"AHRS_ORIENTATION {orientation} ({AP_ROTATIONS[orientation]}): the data were "
            "rotated back to the sensor frame before fitting"
        )

    def human() -> None:
        if found:
            old_new = _rich_table.Table(title="INS_TCAL coefficients: in the log → new")
            for col in ("parameter", "old", "new"):
                old_new.add_column(col)
            for h in hygiene.values():
                for n, v in h.get("coefficients", {}).items():
                    if v["old"] is not None:
                        old_new.add_row(n, fmt(v["old"], 6), fmt(v["new"], 6))
            stdout.print(old_new)
        table = _rich_table.Table(title=f"ArduPilot thermal calibration of {log}")
        for col in ("IMU", "sensor", "sweep [°C]", "bins", "hold-out rms x/y/z"):
            table.add_column(col)
        for f in fits:
            table.add_row(
                str(f.instance), f.kind, f"{f.sweep_c[0]:.1f}…{f.sweep_c[1]:.1f}",
                str(f.n_bins),
                " / ".join(fmt(float(v), 3) for v in f.holdout_rms.values()) + f" {f.unit}",
            )  # fmt: skip
        stdout.print(table)
        for n in params.notes:
            stdout.print(n)
        stdout.print(f"parameters: [bold]{parm}[/bold]", markup=True)

    emit(out, as_json, human)


def _require_fields(df: Any, names: list[str], log: Path, where: str) -> None:
    """Refuse (exit 2) a topic or message missing fields the calibration reads (a damaged
    format definition renames them), naming them."""
    missing = [n for n in names if n not in df.columns]
    if missing:
        raise ThermocalInputError(
            f"{log}: {where} lacks the field(s) {', '.join(missing)} (a damaged format "
            "definition?); it has: " + ", ".join(map(str, list(df.columns)[:20]))
        )
