"""A library error names its parameter; the command line prints the running command's own
option in its place (click's parameter table), else the common spelling."""

from __future__ import annotations

from typing import Annotated

import typer
from typer.testing import CliRunner

from thermocal.cli.common import handle_errors
from thermocal.errors import ParameterError


def _app() -> typer.Typer:
    app = typer.Typer()

    @app.command()
    @handle_errors
    def run(
        rate_hz: Annotated[float, typer.Option("--rate-hz")] = 1.0,
        which: Annotated[str, typer.Option("--which")] = "rate_hz",
    ) -> None:
        raise ParameterError(which, f"{{name}} must be positive, got {rate_hz:g}")

    return app


def test_the_commands_own_option_is_named() -> None:
    result = CliRunner().invoke(_app(), ["--rate-hz", "-2"])
    assert result.exit_code == 2
    assert result.output.strip().splitlines() == ["error: --rate-hz must be positive, got -2"]


def test_a_parameter_the_command_does_not_take_gets_the_common_spelling() -> None:
    for which, option in [("rate_interval", "--rate-interval"), ("temperatures", "--temps")]:
        result = CliRunner().invoke(_app(), ["--which", which])
        assert result.exit_code == 2
        assert result.output.strip() == f"error: {option} must be positive, got 1"
