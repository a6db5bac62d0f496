"""The typer application object every command module registers on."""

from __future__ import annotations

from typing import Annotated

import typer

app = typer.Typer(
    name="thermocal",
    help="Test and calibrate inertial sensors: figures of merit, Allan deviation, "
    "temperature-compensation models, turntable calibration, C export and reports.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help texts carry units in brackets, e.g. [s], [°C]
)


def _show_version(value: bool) -> None:
    if value:
        from thermocal import __version__

        print(f"thermocal {__version__}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version", help="Print the version and exit.", callback=_show_version, is_eager=True
        ),
    ] = False,
) -> None:
    """thermocal: test and calibrate inertial sensors."""
