"""``thermocal metrics FILE``: bias, bias stability, peak-to-peak, drift angle,
repeatability and temperature sensitivity of one signal (SPEC §1)."""

from __future__ import annotations

from typing import Annotated, Any

import typer
from rich.table import Table

from thermocal.cli.app import app
from thermocal.cli.common import (
    AxisOpt,
    FileArg,
    JsonOpt,
    LatitudeOpt,
    SignalOpt,
    SignalUnitOpt,
    TempConversionOpt,
    TempsOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    emit,
    fmt,
    handle_errors,
    jsonable,
    load_recording,
    split_names,
    stdout,
)
from thermocal.metrics import MetricsResult, compute_metrics


def metrics_json(res: MetricsResult) -> dict[str, Any]:
    """The ``--json`` object of ``thermocal metrics`` (INTERFACE.md keys first)."""
    d: dict[str, Any] = jsonable(res)
    ts = res.temperature_sensitivity
    return {
        "bias": res.bias,
        "bias_stability": res.bias_stability,
        "averaging_s": res.averaging_s,
        "peak_to_peak": res.peak_to_peak,
        "unit": res.unit,
        "temperature_sensitivity": None if ts is None else d["temperature_sensitivity"],
        "bias_repeatability": res.bias_repeatability,
        "drift_angle": res.drift_angle,
        "drift_angle_unit": res.drift_angle_unit,
        "earth_rate_removed": res.earth_rate_removed,
        "n_stages": len(res.stages),
        "stages": d["stages"],
        "n_samples": res.n_samples,
        "n_segments": res.n_segments,
        "n_averages": res.n_averages,
        "duration_s": res.duration_s,
        "signal": res.signal,
    }


@app.command("metrics")
@handle_errors
def metrics_cmd(
    file: FileArg,
    signal: SignalOpt = None,
    average: Annotated[
        float | None,
        typer.Option("--average", help="Averaging time S [s] of bias stability and peak-to-peak."),
    ] = None,
    temps: TempsOpt = None,
    latitude: LatitudeOpt = None,
    axis: AxisOpt = None,
    hold_rate: Annotated[
        float,
        typer.Option("--hold-rate", help="Hold stages: |dT/dt| below this [°C/min]."),
    ] = 0.05,
    min_hold: Annotated[
        float, typer.Option("--min-hold", help="Hold stages: at least this long [s].")
    ] = 600.0,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Figures of merit: bias (earth rate removed with --latitude and --axis), bias
    stability at the averaging time, peak-to-peak, drift angle, and over the
    temperature-hold stages of the first --temps column: bias repeatability and
    temperature sensitivity."""
    rec = load_recording(
        file,
        time=time,
        time_unit=time_unit,
        signal=signal,
        temps=temps,
        signal_unit=signal_unit,
        temp_unit=temp_unit,
        temp_conversion=temp_conversion,
        keep_other=False,  # metrics use the signal and the temperatures only
    )
    res = compute_metrics(
        rec,
        signal,
        average,
        latitude,
        axis,
        split_names(temps),
        rate_threshold_c_per_min=hold_rate,
        min_hold_s=min_hold,
    )

    def human() -> None:
        u = res.unit
        table = Table(title=f"{file} — {res.signal}")
        table.add_column("figure")
        table.add_column("value", justify="right")
        table.add_column("unit")
        table.add_row("bias", fmt(res.bias, 6), u)
        if res.earth_rate_removed:
            table.add_row("  earth rate removed", fmt(res.earth_rate_removed, 6), u)
        table.add_row(f"bias stability ({res.averaging_s:g} s)", fmt(res.bias_stability), u)
        table.add_row(f"peak-to-peak ({res.averaging_s:g} s)", fmt(res.peak_to_peak), u)
        if res.drift_angle is not None:
            table.add_row("drift angle (end)", fmt(res.drift_angle), res.drift_angle_unit or "")
        if res.bias_repeatability is not None:
            table.add_row(
                f"bias repeatability ({len(res.stages)} stages)", fmt(res.bias_repeatability), u
            )
        ts = res.temperature_sensitivity
        if ts is not None:
            table.add_row("temp. sensitivity, mean |ΔB/ΔT|", fmt(ts.mean_abs_adjacent), ts.unit)
            table.add_row("temp. sensitivity, LS slope", fmt(ts.ls_slope), ts.unit)
        table.add_row("samples", str(res.n_samples), "")
        stdout.print(table)

    emit(metrics_json(res), as_json, human)
