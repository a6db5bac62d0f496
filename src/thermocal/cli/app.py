"""The typer application object every command module registers on."""

from __future__ import annotations

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


@app.callback()
def _root() -> None:
    """thermocal: test and calibrate inertial sensors."""
