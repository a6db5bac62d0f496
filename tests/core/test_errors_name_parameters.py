"""The library names its parameters, the command line its options.

A message, warning or docstring below ``thermocal.cli`` speaks to a Python user: it names the
parameter (``rate_hz``), not the option of one command (``--rate``).  A message that names a
parameter is built with ``naming`` (:class:`thermocal.errors.NamesParameters`) so that the
command line shows its option in the same place; these tests check the mechanism with its own
rendering and check, by reading every string of the package, that no option is left in the
library except where the text is about a command line (a line marked ``# cli-words:`` with the
reason: a command a report or generated file records, a command the demo tells its user to run).
"""

from __future__ import annotations

import ast
import pickle
import re
import warnings
from pathlib import Path

import pytest

import thermocal
from thermocal.errors import ParameterError, UnitError, UnitWarning
from thermocal.pipeline.messages import error_text, warning_lines

SRC = Path(thermocal.__file__).parent
OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9]*(?:-[a-z0-9]+)*")
MARK = "# cli-words:"

WHOLE_FILES = {
    # the table from the library's parameters to the command line's options
    "pipeline/messages.py",
    # the docstring examples of how the command line spells a parameter
    "errors.py",
}


def _option_strings() -> dict[str, list[tuple[int, str]]]:
    """Every option-like string below ``thermocal`` outside ``cli/``, by file."""
    found: dict[str, list[tuple[int, str]]] = {}
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith("cli/") or rel in WHOLE_FILES:
            continue
        lines = path.read_text(encoding="utf-8").splitlines()
        for node in ast.walk(ast.parse("\n".join(lines))):
            if not (isinstance(node, ast.Constant) and isinstance(node.value, str)):
                continue
            end = node.end_lineno or node.lineno
            if any(MARK in lines[i - 1] for i in range(node.lineno, min(end + 1, len(lines)) + 1)):
                continue
            for option in OPTION.findall(node.value):
                found.setdefault(rel, []).append((node.lineno, option))
    return found


def test_the_library_names_no_option_of_the_command_line() -> None:
    found = _option_strings()
    assert found == {}, "options named in the library (name the parameter; see this module)"


def test_the_scan_sees_an_option() -> None:
    """The scan is not blind: this very pattern finds an option in a string."""
    assert OPTION.findall("give --rate HZ or --time-unit s; not x--y nor ---z") == [
        "--rate",
        "--time-unit",
    ]


def test_an_input_error_names_the_parameter_and_the_command_line_the_option() -> None:
    err = UnitError.naming("time unit not stated: give {time_unit}", "time_unit")
    assert str(err) == "time unit not stated: give time_unit"
    assert error_text(err) == ("time unit not stated: give --time-unit", True)
    assert error_text(err, {"time_unit": "--tu"}) == ("time unit not stated: give --tu", True)
    again = pickle.loads(pickle.dumps(err))  # the fleet's workers send errors back
    assert type(again) is UnitError and error_text(again)[0].endswith("--time-unit")


def test_a_parameter_error_keeps_its_rendering() -> None:
    err = ParameterError("rate_hz", "{name} must be positive with {gravity}", ("gravity",))
    assert str(err) == "rate_hz must be positive with gravity"
    assert error_text(err) == ("--rate must be positive with --gravity", True)


def test_a_warning_names_the_parameter_and_the_command_line_the_option() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.warn(UnitWarning.naming("host clock? give {rate_hz}", "rate_hz"), stacklevel=1)
    assert str(caught[0].message) == "host clock? give rate_hz"
    assert warning_lines(caught) == ["host clock? give --rate"]
    assert warning_lines(caught, {"rate_hz": "--rate-hz"}) == ["host clock? give --rate-hz"]


@pytest.mark.parametrize("text", ["plain message", "braces {kept} as they are"])
def test_a_plain_message_is_shown_as_it_is(text: str) -> None:
    assert error_text(UnitError(text)) == (text, True)
