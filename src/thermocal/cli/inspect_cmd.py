"""``thermocal inspect FILE``: what is in a recording and what is wrong with it."""

from typing import TYPE_CHECKING, Annotated

import typer

from thermocal._lazy import LazyModule
from thermocal.cli.application import app
from thermocal.cli.common import (
    DecimalOpt,
    DelimiterOpt,
    FileArg,
    JsonOpt,
    NamesOpt,
    OnBadLinesOpt,
    RateOpt,
    SignalUnitOpt,
    StampOpt,
    TempConversionOpt,
    TempsOpt,
    TempUnitOpt,
    TimeOpt,
    TimeUnitOpt,
    TopicOpt,
    chamber_log_options,
    emit,
    handle_errors,
    one_line,
    read_options,
    show,
    stdout,
)
from thermocal.errors import ThermocalInputError
from thermocal.pipeline.messages import option_name
from thermocal.report import text as _text

if TYPE_CHECKING:
    import rich.markup as _markup

    import thermocal.inspection as _inspection
    import thermocal.readers as _readers
    from thermocal import units
else:
    _markup = LazyModule("rich.markup")
    _inspection = LazyModule("thermocal.inspection")
    _readers = LazyModule("thermocal.readers")
    units = LazyModule("thermocal.units")


@app.command("inspect")
@handle_errors
@chamber_log_options
def inspect_cmd(
    file: FileArg,
    time: TimeOpt = None,
    time_unit: TimeUnitOpt = None,
    signal: Annotated[
        str | None, typer.Option("--signal", help="Comma-separated signal columns.")
    ] = None,
    temps: TempsOpt = None,
    signal_unit: SignalUnitOpt = None,
    temp_unit: TempUnitOpt = None,
    temp_conversion: TempConversionOpt = None,
    strict: Annotated[
        bool,
        typer.Option(
            "--strict",
            help="Exit with status 2 on warnings (gaps, spikes, skipped columns) too, "
            "not only on errors.",
        ),
    ] = False,
    t_names: NamesOpt = None,
    topic: TopicOpt = None,
    stamp: StampOpt = "header",
    t_rate: RateOpt = None,
    t_bad: OnBadLinesOpt = "error",
    t_delim: DelimiterOpt = None,
    t_dec: DecimalOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Sample rate, duration, gaps, column ranges, NaNs and problems of a recording.

    Temperature columns are taken from --temps, else from the file's metadata,
    else guessed from their names (T1, temp_..., ...).  Like a linter, it prints every
    finding, then exits with status 2 when a problem would stop the other commands
    (time not increasing, NaN in a signal or temperature, unknown unit, ...); with
    --strict, warnings count too.
    """
    skipped: list[str] = []
    read = read_options(
        time=time, time_unit=time_unit, signal=signal, temps=temps, signal_unit=signal_unit,
        temp_unit=temp_unit, temp_conversion=temp_conversion, topic=topic, names=t_names,
        rate=t_rate, on_bad_lines=t_bad, delimiter=t_delim, decimal=t_dec, stamp=stamp,
    )  # fmt: skip
    rec = _readers.read_recording(
        file,
        read,
        skipped=skipped,
        guess_temperatures=True,
        columns_on_demand=True,  # inspected one at a time: one column held, not all
    )
    result = _inspection.inspect_recording(rec, skipped)
    emit(result.to_dict(option_name), as_json, lambda: _print_human(result))
    # raised as input errors, so that the common handler prints the warnings first and
    # the one error: line last (exit 2)
    errors = result.fatal
    if errors:
        more = f" ({len(errors) - 1} more errors)" if len(errors) > 1 else ""
        raise ThermocalInputError.naming(
            f"{file}: {one_line(errors[0].message)}{more}", *errors[0].parameters
        )
    warns = [p for p in result.problems if p.severity == "warning"]
    if strict and warns:
        more = f" ({len(warns) - 1} more warnings)" if len(warns) > 1 else ""
        raise ThermocalInputError.naming(
            f"{file}: --strict: {one_line(warns[0].message)}{more}", *warns[0].parameters
        )


def _print_human(r: "_inspection.Inspection") -> None:
    stdout.print(f"[bold]{_markup.escape(str(r.file))}[/bold]", markup=True)
    show(_text.inspection_text(r))
    if not r.problems:
        stdout.print("[green]no problems found[/green]", markup=True)
    for p in r.problems:
        colour = "red" if p.severity == "error" else "yellow"
        text = _markup.escape(p.text(option_name))
        stdout.print(f"[{colour}]{p.severity}[/{colour}]: {text}", markup=True)
