"""``thermocal multipos FILE... --accel X,Y,Z [--gyro X,Y,Z] -o CAL.json``: accelerometer
and gyro triads calibrated without a turntable, from hand-placed static poses and the
rotations between them (issue 30; INTERFACE.md "Calibration without a turntable").  With
several files at several temperatures and ``--temps``, every parameter becomes a
polynomial in T − TREF (:func:`thermocal.turntable.thermal.fit_triad`, the turntable's own
thermal fit).  Writes a calibration of triads, the file type of ``thermocal turntable``."""

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    JsonOpt,
    OutOpt,
    TimeOpt,
    TimeUnitOpt,
    emit,
    fmt,
    handle_errors,
    split_names,
    stdout,
)
from thermocal.errors import ThermocalInputError

if TYPE_CHECKING:
    import numpy as np
    import rich.table as _rich_table

    import thermocal.models.calibration as _calibration
    import thermocal.models.files as _files
    import thermocal.multipos.calibrate as _mp
    import thermocal.multipos.poses as _poses
    import thermocal.readers as _readers
    import thermocal.turntable.thermal as _thermal
    import thermocal.writers as _writers
    from thermocal import units
else:
    np = LazyModule("numpy")
    _rich_table = LazyModule("rich.table")
    _readers = LazyModule("thermocal.readers")
    _writers = LazyModule("thermocal.writers")
    _calibration = LazyModule("thermocal.models.calibration")
    _files = LazyModule("thermocal.models.files")
    _mp = LazyModule("thermocal.multipos.calibrate")
    _poses = LazyModule("thermocal.multipos.poses")
    _thermal = LazyModule("thermocal.turntable.thermal")
    units = LazyModule("thermocal.units")

NO_TEMPERATURE_TREF_C = 25.0
"""TREF recorded for a calibration made without a temperature column (it applies
unchanged at every temperature)."""


def _three(text: str | None, option: str) -> list[str] | None:
    if text is None:
        return None
    cols = split_names(text) or []
    if len(cols) != 3:
        raise ThermocalInputError(f"{option} needs three column names (x,y,z), got {text!r}")
    return cols


def _unit_of(rec: Any, cols: list[str], option: str | None, kind: str, path: Path) -> str:
    """The columns' unit: the option, else the file's (metadata, column name)."""
    stated = [c for c in cols if rec.unit_sources.get(c, "default") != "default"]
    found = {option} if option else {rec.units.get(c) or "" for c in stated}
    if not option and len(stated) < 3:
        found = set()
    if len(found) != 1 or not next(iter(found)):
        raise ThermocalInputError(
            f"{path}: the {kind} columns {cols} state no single unit; give --{kind}-unit"
        )
    unit = str(units.normalize_signal_unit(found.pop()))
    want = "accel" if kind == "accel" else "rate"
    if units.signal_kind(unit) != want:
        what = "an acceleration" if kind == "accel" else "a rate"
        raise ThermocalInputError(
            f"{path}: the {kind} columns' unit {unit!r} is not {what} unit (raw counts are "
            "not supported by multipos yet: convert them first)"
        )
    return unit


@app.command("multipos")
@handle_errors
def multipos_cmd(
    files: Annotated[
        list[Path],
        typer.Argument(
            help="Session recording(s) (CSV or Parquet); several: one per temperature.",
            show_default=False,
        ),
    ],
    output: OutOpt,
    accel: Annotated[str, typer.Option("--accel", help="Accelerometer x,y,z column names.")],
    gyro: Annotated[
        str | None, typer.Option("--gyro", help="Gyro x,y,z column names (also calibrated).")
    ] = None,
    accel_unit: Annotated[
        str | None,
        typer.Option("--accel-unit", help="Accelerometer unit: m/s^2, mg, g (default: file's)."),
    ] = None,
    gyro_unit: Annotated[
        str | None,
        typer.Option("--gyro-unit", help="Gyro unit: deg/s, deg/h, rad/s (default: file's)."),
    ] = None,
    temps: Annotated[
        str | None,
        typer.Option(
            "--temps",
            help="Temperature column [°C]; with several files every parameter becomes a "
            "polynomial in temperature.",
        ),
    ] = None,
    poses: Annotated[
        Path | None,
        typer.Option(
            "--poses",
            help='Named sections {"name": {"start": i, "end": j}} by sample index (x_p…z_a '
            "faces, x_rot… 360° turns) instead of the poses found in the data (one file).",
        ),
    ] = None,
    gravity: Annotated[
        float | None, typer.Option("--gravity", help="Local gravity [m/s²].")
    ] = None,
    latitude: Annotated[
        float | None,
        typer.Option(
            "--latitude", help="Latitude [°]: normal gravity and the vertical earth rate."
        ),
    ] = None,
    order: Annotated[
        int | None,
        typer.Option("--order", help="Polynomial order in temperature (default: by LOTO)."),
    ] = None,
    tref: Annotated[
        float | None, typer.Option("--tref", help="Reference temperature [°C].")
    ] = None,
    static_s: Annotated[float, typer.Option("--static-s", help="Shortest still pose [s].")] = 1.0,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Accelerometer (and gyro) triad bias, scale factors and misalignments from hand-placed
    poses, without a turntable (Tedaldi et al. 2014; Ferraris et al. 1995)."""
    _writers.check_not_input(output, [*files, *([poses] if poses else [])])
    if output.suffix.lower() != ".json":
        raise ThermocalInputError(f"{output}: the calibration is JSON; use a .json name")
    acc_cols = _three(accel, "--accel") or []
    gyr_cols = _three(gyro, "--gyro")
    if len(files) > 1 and temps is None:
        raise ThermocalInputError(
            "several files: name their temperature column with --temps (one file per temperature)"
        )
    if (order is not None or tref is not None) and len(files) < 2:
        raise ThermocalInputError("--order and --tref need several files and --temps")
    if gravity is not None and latitude is not None:
        raise ThermocalInputError("give --gravity or --latitude, not both")
    if static_s is not None and not (math.isfinite(static_s) and static_s > 0):
        raise ThermocalInputError(f"--static-s must be a positive number, got {static_s!r}")
    if poses is not None and len(files) > 1:
        raise ThermocalInputError("--poses names the sections of one file; give one file")
    sections_d = None
    if poses is not None:
        try:
            sections_d = json.loads(poses.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise ThermocalInputError(f"{poses}: not a readable JSON file ({exc})") from None
    runs = []
    a_units: set[str] = set()
    g_units: set[str] = set()
    lat_used = latitude
    g_used = gravity
    for f in files:
        given = [accel_unit] * 3 + ([gyro_unit] * 3 if gyr_cols else [])
        rec = _readers.read_recording(
            f, time=time, time_unit=time_unit, signals=[*acc_cols, *(gyr_cols or [])],
            signal_unit=",".join(given) if all(given) else None,  # type: ignore[arg-type]
            temperatures=[temps] if temps else None,
        )  # fmt: skip
        rec.validate(required=[*acc_cols, *(gyr_cols or []), *([temps] if temps else [])])
        au = _unit_of(rec, acc_cols, accel_unit, "accel", f)
        a_units.add(au)
        lat = latitude if latitude is not None else rec.meta.latitude_deg
        if lat_used is None:
            lat_used = lat
        if g_used is None:
            if lat is None:
                raise ThermocalInputError(
                    f"{f}: give the local gravity (--gravity M/S2) or the latitude "
                    "(--latitude DEG, WGS-84 normal gravity)"
                )
            g_used = units.normal_gravity_m_s2(float(lat))
        acc = units.convert(np.column_stack([rec.column(c) for c in acc_cols]), au, "mg")
        w = None
        if gyr_cols:
            gu = _unit_of(rec, gyr_cols, gyro_unit, "gyro", f)
            g_units.add(gu)
            w = units.convert(np.column_stack([rec.column(c) for c in gyr_cols]), gu, "rad/s")
        sections = None
        if sections_d is not None:
            sections = _poses.parse_poses(sections_d, rec.n_samples, str(poses))
        temp = rec.temperature_c(temps) if temps else None
        res = _mp.calibrate_session(
            rec.time_s, acc, w, g_mg=float(g_used) / 9.80665e-3, latitude_deg=lat_used,
            sections=sections, static_s=static_s, temperature_c=temp, where=str(f),
        )  # fmt: skip
        t_range = (float(np.min(temp)), float(np.max(temp))) if temp is not None else None
        runs.append((f, res, t_range))
    for what, found in (("accelerometer", a_units), ("gyro", g_units)):
        if len(found) > 1:
            raise ThermocalInputError(f"the files' {what} columns differ in unit: {sorted(found)}")
    a_unit = a_units.pop()
    g_unit = g_units.pop() if g_units else None
    triads = []
    models: dict[str, Any] = {}
    for kind, cols, unit in (("accel", acc_cols, a_unit), ("gyro", gyr_cols, g_unit)):
        if cols is None or unit is None:
            continue
        fits = [r.accel if kind == "accel" else r.gyro for _f, r, _t in runs]
        if len(runs) > 1:
            m = _thermal.fit_triad(
                kind, [float(r.temperature_c) for _f, r, _t in runs],  # type: ignore[arg-type]
                [ft.theta for ft in fits], [ft.sigma for ft in fits],  # type: ignore[union-attr]
                tref_c=tref if kind == "accel" or "accel" not in models
                else models["accel"].tref_c,
                order=order, method="multipos", gravity_m_s2=g_used,
            )  # fmt: skip
        else:
            _f, r, t_range = runs[0]
            ft = fits[0]
            assert ft is not None
            m = _thermal.constant_triad(
                kind, r.temperature_c if r.temperature_c is not None else NO_TEMPERATURE_TREF_C,
                ft.theta, ft.cov, t_range_c=t_range, method="multipos", gravity_m_s2=g_used,
            )  # fmt: skip
        models[kind] = m
        triads.append(
            _calibration.Triad(
                kind, (cols[0], cols[1], cols[2]), unit, temps or "", m, latitude_deg=lat_used
            )
        )
    cal = _calibration.Calibration([], triads)
    _files.save_calibration(cal, output)
    out = _summary(runs, models, a_unit, g_unit, float(g_used))  # type: ignore[arg-type]
    out["output"] = str(output)

    def human() -> None:
        for kind in ("accel", "gyro"):
            if kind not in out:
                continue
            d = out[kind]
            table = _rich_table.Table(title=f"{kind} triad ({d['method']})")
            for col in ("parameter", "value", "σ", "unit"):
                table.add_column(col)
            for i, ax in enumerate("xyz"):
                table.add_row(f"bias {ax}", fmt(d["bias"][i], 5), fmt(d["bias_sigma"][i], 3),
                              d["bias_unit"])  # fmt: skip
            for i, ax in enumerate("xyz"):
                table.add_row(f"scale factor {ax}", fmt(d["scale_factor_ppm"][i], 5),
                              fmt(d["scale_factor_ppm_sigma"][i], 3), "ppm")  # fmt: skip
            for i, n in enumerate(d["misalignment_names"]):
                table.add_row(f"misalignment {n}", fmt(d["misalignment_arcsec"][i], 5),
                              fmt(d["misalignment_arcsec_sigma"][i], 3), "″")  # fmt: skip
            stdout.print(table)
        stdout.print(
            f"{out['n_poses']} poses; gravity-magnitude residual rms "
            f"{fmt(out['gravity_residual_rms_before'], 3)} → "
            f"{fmt(out['gravity_residual_rms_after'], 3)} {a_unit}; written {output}"
        )

    emit(out, as_json, human)


def _triad_dict(theta: Any, sigma: Any, bias_factor: float, bias_unit: str) -> dict[str, Any]:
    return {
        "bias": (np.asarray(theta[0:3]) * bias_factor).tolist(),
        "bias_sigma": (np.asarray(sigma[0:3]) * bias_factor).tolist(),
        "bias_unit": bias_unit,
        "scale_factor_ppm": list(theta[3:6]),
        "scale_factor_ppm_sigma": list(sigma[3:6]),
        "misalignment_arcsec": list(theta[6:12]),
        "misalignment_arcsec_sigma": list(sigma[6:12]),
        "misalignment_names": ["yx", "zx", "xy", "zy", "xz", "yz"],
    }


def _summary(
    runs: list[Any], models: dict[str, Any], a_unit: str, g_unit: str | None, g_m_s2: float
) -> dict[str, Any]:
    """The ``--json`` object (INTERFACE.md): each triad at TREF in the data's units, the
    poses, the gravity residuals in the accelerometer's unit, and each run's figures."""
    to_a = float(units.convert(np.array([1.0]), "mg", a_unit)[0])
    to_g = float(units.convert(np.array([1.0]), "deg/h", g_unit)[0]) if g_unit else 1.0
    out: dict[str, Any] = {"format": "thermocal-calibration", "gravity_m_s2": g_m_s2}
    run_dicts = []
    all_before, all_after = [], []
    for f, r, _t in runs:
        rd: dict[str, Any] = {
            "input": str(f),
            "temperature_c": r.temperature_c,
            "n_poses": len(r.poses),
            "accel": {**_triad_dict(r.accel.theta, r.accel.sigma, to_a, a_unit),
                      "method": r.accel.method, "reduced_chi2": r.accel.reduced_chi2},
            "poses": [
                {**p, "mean_specific_force": (np.asarray(p["mean_specific_force_mg"])
                                              * to_a).tolist(),
                 "gravity_residual": p["gravity_residual_mg"] * to_a}
                for p in r.poses_dict()
            ],
            "not_still": list(r.not_still),
        }  # fmt: skip
        for p in rd["poses"]:
            del p["mean_specific_force_mg"], p["gravity_residual_mg"]
        if r.gyro is not None:
            rd["gyro"] = {**_triad_dict(r.gyro.theta, r.gyro.sigma, to_g, str(g_unit)),
                          "method": "rotations between poses"
                          + (" and 360° turns" if r.gyro.n_turns else ""),
                          "n_motions": r.gyro.n_motions, "n_turns": r.gyro.n_turns,
                          "reduced_chi2": r.gyro.reduced_chi2,
                          "direction_rms_before_deg": math.degrees(
                              r.gyro.direction_rms_before_rad),
                          "direction_rms_after_deg": math.degrees(
                              r.gyro.direction_rms_after_rad)}  # fmt: skip
        all_before.append(r.accel.residual_rms_before_mg**2 * len(r.poses))
        all_after.append(r.accel.residual_rms_after_mg**2 * len(r.poses))
        run_dicts.append(rd)
    n_poses = sum(len(r.poses) for _f, r, _t in runs)
    out["n_poses"] = n_poses
    out["gravity_residual_rms_before"] = math.sqrt(sum(all_before) / n_poses) * to_a
    out["gravity_residual_rms_after"] = math.sqrt(sum(all_after) / n_poses) * to_a
    out["unit"] = a_unit
    out["poses"] = [dict(p, file=rd["input"]) for rd in run_dicts for p in rd["poses"]]
    for kind, m in models.items():
        theta = np.array([f.coef[0] for f in m.fits])
        sigma = np.array([f.sigma[0] for f in m.fits])
        if kind == "accel":
            d = _triad_dict(theta, sigma, to_a, a_unit)
            d["method"] = runs[0][1].accel.method
        else:
            d = _triad_dict(theta, sigma, to_g, str(g_unit))
            d["method"] = run_dicts[0]["gyro"]["method"]
        d["tref_c"] = m.tref_c
        if len(runs) > 1:
            d["order"] = m.order
            d["temperature_range_c"] = [m.t_lo_c, m.t_hi_c]
            d["parameters"] = {
                f.name: {"unit": f.unit, "coefficients": f.coef.tolist(),
                         "coefficients_sigma": f.sigma.tolist(),
                         "loto_rms": f.loto_rms if math.isfinite(f.loto_rms) else None}
                for f in m.fits
            }  # fmt: skip
        out[kind] = d
    out["runs"] = run_dicts
    return out


__all__ = ["multipos_cmd"]
