"""``thermocal noise FILE``: the IMU noise model for estimators (Kalibr's ``imu.yaml`` or
JSON), from the Allan analysis of every axis (:mod:`thermocal.stability.noise_model`)."""

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule, prefetch
from thermocal.cli import noise_psd as _psd_out
from thermocal.cli import noise_sheet as _sheet
from thermocal.cli import noise_temps as _temps
from thermocal.cli.application import app
from thermocal.cli.common import (
    ConfidenceOpt,
    DecimalOpt,
    DelimiterOpt,
    FileArg,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    StampOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    chamber_log_options,
    check_recording,
    handle_errors,
    jsonable,
    read_options,
    show,
    split_names,
    stdout,
)
from thermocal.errors import ThermocalInputError
from thermocal.identifiers import one_line
from thermocal.report import text as _text

if TYPE_CHECKING:
    import thermocal.readers as _readers
    import thermocal.stability.analysis as _analysis
    import thermocal.stability.noise_model as _nm
    import thermocal.writers as _writers
else:
    _writers = LazyModule("thermocal.writers")
    _readers = LazyModule("thermocal.readers")
    _analysis = LazyModule("thermocal.stability.analysis")
    _nm = LazyModule("thermocal.stability.noise_model")


def _triad(text: str | None, option: str, taken: list[str] | None = None) -> list[str]:
    """``--gyro``/``--accel`` as three different columns, none of them in ``taken`` (the
    other sensor's)."""
    names = (split_names(text) or []) if text else []
    if text is not None and len(names) != 3:
        raise ThermocalInputError(f"{option} {one_line(repr(text))}: give three columns X,Y,Z")
    for i, n in enumerate(names):
        if n in names[:i] or n in (taken or []):
            where = "named twice" if n in names[:i] else "also in --gyro"
            raise ThermocalInputError(
                f"{option} {one_line(repr(text))}: column {one_line(repr(n))} {where}; "
                "give the three different columns X,Y,Z of each sensor"
            )
    return names


GyroColsOpt = Annotated[
    str | None,
    typer.Option("--gyro", help="Gyro columns X,Y,Z (required but with --from-datasheet)."),
]
FromDatasheetOpt = Annotated[
    bool,
    typer.Option(
        "--from-datasheet",
        help="FILE holds data-sheet figures (TOML: update_rate_hz = 200, gyro_noise_density = "
        '"0.014 deg/s/sqrt(Hz)", accel_noise_density = "175 ug/sqrt(Hz)", gyro_random_walk or '
        "gyro_bias_instability, the same for accel): the Kalibr file from them, units converted.",
    ),
]
NoiseOutOpt = Annotated[Path, typer.Option("-o", "--output", help="Output file.")]
AccelColsOpt = Annotated[str | None, typer.Option("--accel", help="Accelerometer columns X,Y,Z.")]
GyroUnitOpt = Annotated[
    str | None,
    typer.Option("--gyro-unit", help="Unit of the gyro columns: deg/h, deg/s, rad/s."),
]
AccelUnitOpt = Annotated[
    str | None,
    typer.Option("--accel-unit", help="Unit of the accelerometer columns: mg, ug, g, m/s^2."),
]
FormatOpt = Annotated[
    str, typer.Option("--format", help="kalibr (imu.yaml) or json (every term of every axis).")
]
InflateOpt = Annotated[
    float,
    typer.Option(
        "--inflate", help="Multiply every Kalibr noise value by this (≥ 1; stated in the file)."
    ),
]
NoiseTempsOpt = Annotated[
    str | None,
    typer.Option(
        "--temps",
        help="Temperature column: the noise terms per temperature bin (--temp-bins), their "
        "trend against temperature, and with --at-temperature the model at one temperature.",
    ),
]
TempBinsOpt = Annotated[
    str | None,
    typer.Option(
        "--temp-bins",
        help="With --temps: a bin width in °C (default 5) or the edges (10,25,40,55).",
    ),
]
AtTemperatureOpt = Annotated[
    float | None,
    typer.Option(
        "--at-temperature",
        help="With --temps: the model at this temperature [°C], each axis interpolated "
        "between the bins around it, with the inflation the record supports.",
    ),
]
NoisePlotOpt = Annotated[
    Path | None,
    typer.Option(
        "--plot",
        help="With --temps: a PNG of N, K and B per bin against temperature, with their "
        "intervals and significant trends.",
    ),
]
PsdOpt = Annotated[
    Path | None,
    typer.Option(
        "--psd",
        help="Also the PSD (Welch, one-sided, data unit/√Hz) of every axis, written to this "
        "CSV; its white level beside the Allan deviation's, and where the two disagree.",
    ),
]
RostopicOpt = Annotated[str, typer.Option("--rostopic", help="Kalibr's rostopic of this IMU.")]


def _unit_list(
    gyro_unit: str | None, accel_unit: str | None, n_g: int, n_a: int
) -> tuple[str, ...] | None:
    """``--gyro-unit``/``--accel-unit`` as the recording's per-column unit list (None: the
    file's own units); both or neither."""
    if gyro_unit is None and accel_unit is None:
        return None
    if (gyro_unit is None) or (n_a and accel_unit is None):
        raise ThermocalInputError(
            "give both --gyro-unit and --accel-unit, or neither (units from the column "
            "names or the file's metadata)"
        )
    return tuple([gyro_unit] * n_g + [accel_unit or ""] * n_a)


def _check_temps_options(
    file: Path,
    output: Path,
    temps: str | None,
    others: tuple[object, object, Path | None, Path | None],
) -> None:
    """``--temp-bins``, ``--at-temperature`` and ``--plot`` need ``--temps``; ``--psd`` is
    of the whole record; the plot is neither an input nor ``-o``."""
    edges_c, temperature_c, plot, psd = others
    if temps is None and (edges_c is not None or temperature_c is not None or plot is not None):
        raise ThermocalInputError(
            "--temp-bins, --at-temperature and --plot apply with --temps COLUMN (the IMU's "
            "thermometer)"
        )
    if temps is not None and psd is not None:
        raise ThermocalInputError(
            "--psd is of the whole record: run it without --temps (the bins' white levels "
            "are in the --temps table)"
        )
    if plot is not None:
        _writers.check_not_input(plot, [file])
        if plot.resolve() == output.resolve() or plot.is_dir():
            raise ThermocalInputError(f"--plot {plot}: give a PNG file name other than -o")


@app.command("noise")
@handle_errors
@chamber_log_options
def noise_cmd(
    file: FileArg,
    output: NoiseOutOpt,
    gyro: GyroColsOpt = None,
    accel: AccelColsOpt = None,
    gyro_unit: GyroUnitOpt = None,
    accel_unit: AccelUnitOpt = None,
    out_format: FormatOpt = "kalibr",
    inflate: InflateOpt = 1.0,
    rostopic: RostopicOpt = "/imu0",
    confidence: ConfidenceOpt = 0.6826894921370859,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    t_names: NamesOpt = None,
    topic: TopicOpt = None,
    stamp: StampOpt = "header",
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    from_datasheet: FromDatasheetOpt = False,
    temps: NoiseTempsOpt = None,
    temp_unit: TempUnitOpt = None,
    edges_c: TempBinsOpt = None,
    temperature_c: AtTemperatureOpt = None,
    psd: PsdOpt = None,
    plot: NoisePlotOpt = None,
) -> None:
    """IMU noise model for estimators: per axis the white-noise density (the −½ line of
    the Allan deviation at τ = 1 s) and the random walk (+½ line at τ = 3 s, or the
    least-squares fit), in continuous time; Kalibr's imu.yaml takes per sensor the largest
    axis."""
    prefetch("rich.table")  # the analysis needs no scipy (its quantiles are its own)
    if out_format not in ("kalibr", "json"):
        raise ThermocalInputError(f"--format {out_format!r}: use kalibr or json")
    if from_datasheet:
        given = {"--gyro": gyro, "--accel": accel, "--temps": temps, "--psd": psd, "--plot": plot}
        _sheet.refuse_recording_options(given)
        _sheet.from_datasheet(file, output, out_format, inflate=inflate, rostopic=rostopic)
        return
    _check_temps_options(file, output, temps, (edges_c, temperature_c, plot, psd))
    if gyro is None:
        raise ThermocalInputError(
            "give the gyro columns with --gyro X,Y,Z (or --from-datasheet with a file of "
            "data-sheet figures)"
        )
    g_names = _triad(gyro, "--gyro")
    a_names = _triad(accel, "--accel", g_names)
    if out_format == "kalibr" and not a_names:
        raise ThermocalInputError(
            "--format kalibr: Kalibr's imu.yaml needs the accelerometer too; give --accel X,Y,Z "
            "(or --format json for the gyro alone)"
        )
    _writers.check_not_input(output, [file])
    if psd is not None:
        _psd_out.check(psd, file, output)
    if output.is_dir():
        raise ThermocalInputError(f"{output}: is a directory, expected a file name")
    read = read_options(
        time=time, time_unit=time_unit, signal=",".join(g_names + a_names),
        signal_unit=_unit_list(gyro_unit, accel_unit, len(g_names), len(a_names)),
        topic=topic, names=t_names, rate=t_rate, on_bad_lines=t_bad, delimiter=t_delim,
            decimal=t_dec, stamp=stamp, temp_unit=temp_unit,
            **({"temps": temps} if temps is not None else {}),
    )  # fmt: skip
    rec = _readers.read_recording(
        file,
        read,
        keep_other=False,
        ask_units={**dict.fromkeys(g_names, "gyro_unit"),
                   **dict.fromkeys(a_names, "accel_unit")},
    )  # fmt: skip
    check_recording(rec, read)
    if temps is not None:
        opts = {"out_format": out_format, "temperature_c": temperature_c, "inflate": inflate,
                "rostopic": rostopic, "confidence": confidence, "plot": plot}  # fmt: skip
        _temps.by_temperature(file, rec, (g_names, a_names), temps, edges_c, opts, output)
        return
    res = _analysis.imu_noise(
        rec, g_names, a_names, inflate=inflate, rostopic=rostopic, confidence=confidence,
        where=str(file),
    )  # fmt: skip
    if out_format == "kalibr":
        text = _nm.kalibr_yaml(res.model, file.name)  # names escaped, keys checked
    else:
        text = json.dumps(jsonable(res.model.to_dict(file.name)), allow_nan=False, indent=1)
    with _writers.atomic_write(output, "w") as fh:
        fh.write(text + ("" if text.endswith("\n") else "\n"))

    show(_text.imu_noise_text(str(file), res))
    if psd is not None:
        _psd_out.write(rec, res.model.axes, psd)
    stdout.print(f"{out_format} noise model written to {output} (per sensor the largest axis)")
