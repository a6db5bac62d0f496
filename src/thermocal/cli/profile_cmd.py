"""``thermocal profile ...``: chamber programs, their correlation, validation design.

* ``thermocal profile NAME -o FILE.csv [options]`` for each built-in profile
  (``rlg-modelling``, ``rlg-validation``, ``fog-slow``, ``mems-warmup``,
  ``accel-full-range``) writes the chamber program ``time_s, setpoint_c``.
* ``thermocal profile correlate A B [--column C] [--json]``: r and
  ``weakly_correlated`` of two temperature histories (r < 0.4).
* ``thermocal profile join FILE --chamber-log LOG[:CHANNEL] [-o OUT]``: a chamber's own
  log joined by time to a recording (offset, drift, time zone stated; OUT the recording with
  the column ``chamber``).  ``profile correlate A B --chamber-logs`` correlates two such logs.
* ``thermocal profile design-validation MODEL -o VAL.csv --seed N``, or
  ``thermocal profile rlg-validation --against MODEL --seed N``: a hold profile
  over the modelling range with |r| below the limit.
"""

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    ChamberDateOpt,
    ChamberDateOrderOpt,
    ChamberUnitOpt,
    DecimalOpt,
    DelimiterOpt,
    JsonOpt,
    NamesOpt,
    OnBadLinesOpt,
    OutOpt,
    StampOpt,
    TempsOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    chamber_log_options,
    current_chamber_log,
    emit,
    handle_errors,
    read_options,
    split_floats,
    stdout,
)
from thermocal.cli.common import RateOpt as TextRateOpt
from thermocal.errors import ThermocalInputError
from thermocal.outputs import check_outputs

if TYPE_CHECKING:
    import numpy as np

    import thermocal.profiles as _profiles
    import thermocal.readers as _readers
    import thermocal.readers.program as _program
    import thermocal.recording as _recording
    import thermocal.writers as _writers
else:
    np = LazyModule("numpy")
    _readers = LazyModule("thermocal.readers")
    _writers = LazyModule("thermocal.writers")
    _profiles = LazyModule("thermocal.profiles")
    _program = LazyModule("thermocal.readers.program")
    _recording = LazyModule("thermocal.recording")

if TYPE_CHECKING:
    import pandas as pd

else:
    pd = LazyModule("pandas")

profile_app = typer.Typer(
    help="Chamber test profiles (time_s, setpoint_c programs), their correlation, and the "
    "design of weakly correlated validation profiles.",
    no_args_is_help=True,
)
app.add_typer(profile_app, name="profile")

DtOpt = Annotated[
    float,
    typer.Option("--dt", help="Program step [s]; 0 writes only the corner points of the profile."),
]
LowOpt = Annotated[float | None, typer.Option("--low", help="Low temperature [°C].")]
HighOpt = Annotated[float | None, typer.Option("--high", help="High temperature [°C].")]
StartOpt = Annotated[float | None, typer.Option("--start", help="Start/end [°C].")]
RateOpt = Annotated[float | None, typer.Option("--rate", help="Ramp rate [°C/min].")]
HoldSOpt = Annotated[float | None, typer.Option("--hold-s", help="Hold duration [s].")]
SeedOpt = Annotated[int, typer.Option("--seed", help="Seed of the design search.")]
LimitOpt = Annotated[float, typer.Option("--limit", help="Correlation limit (weak below it).")]
NHoldsOpt = Annotated[
    int | None, typer.Option("--n-holds", help="Number of holds of a designed profile.")
]
ColumnOpt = Annotated[
    str | None,
    typer.Option(
        "--column",
        help="Temperature column of a recording (default: setpoint_c of a program, else the "
        "first temperature column).",
    ),
]


def _write_profile(
    prof: "_profiles.Profile", output: Path, dt: float, as_json: bool, **extra: Any
) -> None:
    check_outputs([output], [])  # no FIFO, device, /proc… (inputs: checked by the caller)
    if not (dt >= 0 and math.isfinite(dt)):
        raise ThermocalInputError(f"--dt must be ≥ 0 s (0: corner points only), got {dt:g}")
    t, c = prof.program(dt if dt > 0 else None)
    _writers.write_program(output, t, c)
    emit(
        {**_profiles.program_summary(prof, t, c, str(output)), **extra},
        as_json,
        lambda: stdout.print(
            f"{prof.name}: {t.size} points, {t[-1] / 3600:.2f} h, "
            f"{np.min(c):g} … {np.max(c):g} °C → {output}"
            + (f" (r = {extra['r']:.3f})" if "r" in extra else "")
        ),
    )


def _clean(params: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in params.items() if v is not None}


@profile_app.command("rlg-modelling")
@handle_errors
def rlg_modelling_cmd(
    output: OutOpt,
    low: LowOpt = None,
    high: HighOpt = None,
    start: StartOpt = None,
    cycles: Annotated[
        int | None, typer.Option("--cycles", help="Number of full temperature cycles.")
    ] = None,
    cycle_rate: Annotated[
        float | None, typer.Option("--cycle-rate", help="Rate of the full cycles [°C/min].")
    ] = None,
    hold_s: Annotated[
        float | None, typer.Option("--hold-s", help="Hold at the ends of full cycles [s].")
    ] = None,
    rates: Annotated[
        str | None, typer.Option("--rates", help="Rate cycles [°C/min], e.g. 2,1,0.5,0.2,0.1.")
    ] = None,
    rate_hold_s: Annotated[
        float | None, typer.Option("--rate-hold-s", help="Hold at the ends of rate cycles [s].")
    ] = None,
    dt: DtOpt = 60.0,
    as_json: JsonOpt = False,
) -> None:
    """Ring-laser-gyro modelling test: cycles between −20 and +50 °C, then ±2…±0.1 °C/min cycles."""
    params = _clean(
        {
            "low_c": low,
            "high_c": high,
            "start_c": start,
            "n_temperature_cycles": cycles,
            "cycle_rate_c_per_min": cycle_rate,
            "hold_s": hold_s,
            "rates_c_per_min": split_floats(rates, "--rates"),
            "rate_hold_s": rate_hold_s,
        }
    )
    _write_profile(_profiles.builtin_profile("rlg-modelling", **params), output, dt, as_json)


@profile_app.command("rlg-validation")
@handle_errors
def rlg_validation_cmd(
    output: OutOpt,
    holds: Annotated[
        str | None, typer.Option("--holds", help="Hold temperatures [°C], comma-separated.")
    ] = None,
    hold_s: HoldSOpt = None,
    rate: RateOpt = None,
    start: StartOpt = None,
    against: Annotated[
        Path | None,
        typer.Option(
            "--against",
            help="Modelling program or recording: design the holds (seeded) so that |r| is "
            "below --limit.",
        ),
    ] = None,
    column: ColumnOpt = None,
    seed: SeedOpt = 0,
    limit: LimitOpt = defaults.WEAK_CORRELATION_LIMIT,
    n_holds: NHoldsOpt = None,
    dt: DtOpt = 60.0,
    as_json: JsonOpt = False,
) -> None:
    """Ring-laser-gyro validation test: temperature holds (or designed with --against)."""
    if against is not None:
        if holds is not None:
            raise ThermocalInputError("give either --holds or --against, not both")
        _writers.check_not_input(output, [against])
        _design(against, output, column, seed, limit, n_holds, hold_s, rate, dt, as_json)
        return
    params = _clean(
        {
            "holds_c": split_floats(holds, "--holds"),
            "hold_s": hold_s,
            "rate_c_per_min": rate,
            "start_c": start,
        }
    )
    _write_profile(_profiles.builtin_profile("rlg-validation", **params), output, dt, as_json)


@profile_app.command("fog-slow")
@handle_errors
def fog_slow_cmd(
    output: OutOpt,
    low: LowOpt = None,
    high: HighOpt = None,
    rate: RateOpt = None,
    hold_s: HoldSOpt = None,
    cycles: Annotated[int | None, typer.Option("--cycles", help="Number of cycles.")] = None,
    dt: DtOpt = 60.0,
    as_json: JsonOpt = False,
) -> None:
    """Fibre-optic-gyro slow drift over 15–42 °C."""
    params = _clean(
        {
            "low_c": low,
            "high_c": high,
            "rate_c_per_min": rate,
            "hold_s": hold_s,
            "n_cycles": cycles,
        }
    )
    _write_profile(_profiles.builtin_profile("fog-slow", **params), output, dt, as_json)


@profile_app.command("mems-warmup")
@handle_errors
def mems_warmup_cmd(
    output: OutOpt,
    starts: Annotated[
        str | None, typer.Option("--starts", help="Start temperatures [°C], comma-separated.")
    ] = None,
    soak_s: Annotated[
        float | None, typer.Option("--soak-s", help="Soak before power-on [s].")
    ] = None,
    record_s: Annotated[
        float | None, typer.Option("--record-s", help="Powered record per start (≥ 360 s).")
    ] = None,
    rate: Annotated[float | None, typer.Option("--rate", help="Transition rate [°C/min].")] = None,
    start: StartOpt = None,
    dt: DtOpt = 60.0,
    as_json: JsonOpt = False,
) -> None:
    """MEMS power-on warm-ups at several start temperatures."""
    params = _clean(
        {
            "start_temps_c": split_floats(starts, "--starts"),
            "soak_s": soak_s,
            "record_s": record_s,
            "transition_rate_c_per_min": rate,
            "start_c": start,
        }
    )
    _write_profile(_profiles.builtin_profile("mems-warmup", **params), output, dt, as_json)


@profile_app.command("accel-full-range")
@handle_errors
def accel_full_range_cmd(
    output: OutOpt,
    low: LowOpt = None,
    high: HighOpt = None,
    soak_s: Annotated[float | None, typer.Option("--soak-s", help="Soak at the ends [s].")] = None,
    rate: RateOpt = None,
    step: Annotated[
        float | None, typer.Option("--step", help="Constant points every STEP [°C].")
    ] = None,
    point_hold_s: Annotated[
        float | None, typer.Option("--point-hold-s", help="Hold at each constant point [s].")
    ] = None,
    repeats: Annotated[int | None, typer.Option("--repeats", help="Number of runs.")] = None,
    start: StartOpt = None,
    dt: DtOpt = 60.0,
    as_json: JsonOpt = False,
) -> None:
    """Accelerometer full range: −40 °C 2 h, 2 °C/min to +60 °C, 2 h; points every 5 °C."""
    params = _clean(
        {
            "low_c": low,
            "high_c": high,
            "soak_s": soak_s,
            "rate_c_per_min": rate,
            "step_c": step,
            "point_hold_s": point_hold_s,
            "repeats": repeats,
            "start_c": start,
        }
    )
    _write_profile(_profiles.builtin_profile("accel-full-range", **params), output, dt, as_json)


@profile_app.command("correlate")
@handle_errors
def correlate_cmd(
    file_a: Annotated[Path, typer.Argument(help="Modelling program or recording.")],
    file_b: Annotated[Path, typer.Argument(help="Validation program or recording.")],
    column: ColumnOpt = None,
    column_b: Annotated[
        str | None, typer.Option("--column-b", help="Column of B (default: --column's rule).")
    ] = None,
    limit: LimitOpt = defaults.WEAK_CORRELATION_LIMIT,
    points: Annotated[
        int, typer.Option("--points", help="Points of the common elapsed-time base.")
    ] = 10_000,
    t_names: NamesOpt = None,
    topic: TopicOpt = None,
    stamp: StampOpt = "header",
    t_rate: TextRateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    chamber_logs: Annotated[
        bool,
        typer.Option(
            "--chamber-logs",
            help="A and B are chamber or logger logs (hh:mm[:ss] clocks), FILE or "
            "FILE:CHANNEL; their clocks' elapsed time is the base.",
        ),
    ] = False,
    chamber_unit: ChamberUnitOpt = None,
    chamber_date: ChamberDateOpt = None,
    chamber_date_order: ChamberDateOrderOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """r = Cov(X, Y)/(σX σY) of two temperature histories on a common elapsed-time base."""
    if chamber_logs:
        if column is not None or column_b is not None:
            raise ThermocalInputError(
                "--chamber-logs: name each log's channel after a colon, FILE:CHANNEL, not "
                "with --column"
            )
        given = {"chamber_unit": chamber_unit, "chamber_date": chamber_date,
                 "chamber_date_order": chamber_date_order}  # fmt: skip
        ta, xa, ca = _chamber_history(file_a, given)
        tb, xb, cb = _chamber_history(file_b, given)
    else:
        if chamber_unit or chamber_date or chamber_date_order:
            raise ThermocalInputError(
                "--chamber-unit, --chamber-date and --chamber-date-order apply with --chamber-logs"
            )
        ta, xa, ca, tb, xb, cb = _histories(
            file_a, file_b, column, column_b, read_options(
                topic=topic, names=t_names, rate=t_rate, on_bad_lines=t_bad,
                delimiter=t_delim, decimal=t_dec, stamp=stamp,
            ),
        )  # fmt: skip
    res = _profiles.correlate(ta, xa, tb, xb, r_limit=limit, n_points=points)
    emit(
        {**res.to_dict(), "column_a": ca, "column_b": cb},
        as_json,
        lambda: stdout.print(
            f"r = {res.r:.4f} over {res.duration_s / 3600:.2f} h ({res.n} points): "
            + ("weakly correlated" if res.weakly_correlated else "NOT weakly correlated")
            + f" (limit {limit:g})"
        ),
    )


def _chamber_history(path: Path, given: dict[str, Any]) -> tuple["np.ndarray", "np.ndarray", str]:
    """A chamber log's channel: its clock [s] from its first row, °C and name."""
    from thermocal.cli.common import chamber_spec
    from thermocal.readers.chamber_log import read_chamber_log

    spec = chamber_spec({"chamber_log": str(path), **given})
    assert spec is not None  # --chamber-log given
    log = read_chamber_log(spec)
    return log.time_s, log.temp_c, log.channel


def _histories(
    file_a: Path, file_b: Path, column: str | None, column_b: str | None, read: Any
) -> tuple[Any, ...]:
    """The two temperature histories of programs or recordings (``--column``, ``--column-b``)."""
    ta, xa, ca = _program.read_history(file_a, column, read)
    tb, xb, cb = _program.read_history(file_b, column_b if column_b is not None else column, read)
    return ta, xa, ca, tb, xb, cb


def _design(
    model: Path,
    output: Path,
    column: str | None,
    seed: int,
    limit: float,
    n_holds: int | None,
    hold_s: float | None,
    rate: float | None,
    dt: float,
    as_json: bool,
) -> None:
    tm, cm, _ = _program.read_history(model, column)
    kwargs: dict[str, Any] = _clean({"n_holds": n_holds, "hold_s": hold_s, "rate_c_per_min": rate})
    prof = _profiles.design_validation_profile(tm, cm, seed, limit, **kwargs)
    tv, cv = prof.knots()
    res = _profiles.correlate(tm, cm, tv, cv, r_limit=limit)
    _write_profile(prof, output, dt, as_json, r=res.r, weakly_correlated=res.weakly_correlated)


@profile_app.command("design-validation")
@handle_errors
def design_validation_cmd(
    model: Annotated[Path, typer.Argument(help="Modelling program or recording.")],
    output: OutOpt,
    seed: SeedOpt = 0,
    column: ColumnOpt = None,
    limit: LimitOpt = defaults.WEAK_CORRELATION_LIMIT,
    n_holds: NHoldsOpt = None,
    hold_s: Annotated[float | None, typer.Option("--hold-s", help="Mean hold [s].")] = None,
    rate: RateOpt = None,
    dt: DtOpt = 60.0,
    as_json: JsonOpt = False,
) -> None:
    """A hold profile over the modelling range, weakly correlated with it (seeded)."""
    _writers.check_not_input(output, [model])
    _design(model, output, column, seed, limit, n_holds, hold_s, rate, dt, as_json)


@profile_app.command("join")
@handle_errors
@chamber_log_options
def join_cmd(
    file: Annotated[Path, typer.Argument(help="The sensor's recording.", show_default=False)],
    temps: TempsOpt = None,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    output: Annotated[
        Path | None,
        typer.Option(
            "-o", "--output", help="The recording with the joined column 'chamber' (CSV, Parquet)."
        ),
    ] = None,
    as_json: JsonOpt = False,
) -> None:
    """A chamber's own log (--chamber-log) joined by time to a recording: the clocks' offset,
    drift and time zone, with their uncertainties; -o writes the joined recording."""
    spec = current_chamber_log()
    if spec is None:
        raise ThermocalInputError("profile join: give the log, --chamber-log FILE[:CHANNEL]")
    inputs: list[str | Path] = [file, spec.path]
    if output is not None:
        _writers.check_not_input(output, inputs)
    read = read_options(time=time, time_unit=time_unit, temps=temps, temp_unit=temp_unit)
    rec = _readers.read_recording(file, read)
    joined = dict(rec.meta.extra["chamber_log"])
    if output is not None:
        _writers.write_recording(rec, output)
    out = {"file": str(file), "column": "chamber", **joined, "output": output}
    emit(out, as_json, lambda: _show_join(out))


def _show_join(out: dict[str, Any]) -> None:
    """The join as lines of text."""
    sig_o, sig_d = out["offset_sigma_s"], out["drift_sigma_ppm"]
    pm_o = f" ± {sig_o:.2g}" if sig_o is not None else " (given)"
    pm_d = f" ± {sig_d:.2g}" if sig_d is not None else " (assumed)"
    stdout.print(f"{out['log']} [{out['channel']}, {out['unit']}] → {out['file']}: {out['method']}")
    stdout.print(f"offset {out['offset_s']:.6g}{pm_o} s, drift {out['drift_ppm']:.4g}{pm_d} ppm")
    if out["timezone"]:
        stdout.print(f"time zone {out['timezone']}")
    if out["correlation"] is not None:
        stdout.print(f"correlation r = {out['correlation']:.4f}")
    if out["output"] is not None:
        stdout.print(f"written: {out['output']}")
