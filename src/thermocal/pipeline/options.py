"""The options of ``thermocal fit`` and ``thermocal validate`` as frozen dataclasses.

One field per long option of the command, named as the option without its dashes
(``--time-unit`` → ``time_unit``), with the command's default; a fit's family options are
one field, ``params`` (constructor parameter → value, as the family declares them in
:mod:`thermocal.families`).  The command line builds them from its parameters, a fleet
configuration from its ``[fit]``/``[validate]`` tables (:func:`options_from_table`), and a
test checks that the fields, the families' declared options and the command's options are
the same set.  What the command takes besides (its files, ``-o``, ``--json``) is not an
option here.
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from thermocal.defaults import DEFAULT_AVERAGING_S
from thermocal.errors import ThermocalInputError
from thermocal.families import FamilyOption, fit_option_table


@dataclass(frozen=True)
class FitOptions:
    """The options of a fit (:func:`thermocal.pipeline.fit.fit_files`, ``thermocal fit``).

    ``model`` names the family and ``params`` holds its options by constructor parameter,
    as the family declares them (:class:`thermocal.families.FamilyOption`:
    ``{"order": 2, "rate_interval_s": 60.0}``, ``{"breakpoints": (25.0, 30.0)}``); each
    is checked against its declared type and bounds before a file is read.  The other
    fields apply to every family, and how the files are read.
    """

    model: str
    params: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    signal: str | None = None
    temps: str | None = None
    time: str | None = None
    time_unit: str | None = None
    signal_unit: str | None = None
    temp_unit: str | None = None
    temp_conversion: str | None = None
    target: str = "bias"
    latitude: float | None = None
    axis: str | None = None
    known_input: float | None = None
    gravity_axis: str | None = None
    gravity: float | None = None
    tref: float | None = None
    allow_narrow: bool = False
    allow_motion: bool = False
    # how the files are read (text logs, ULog)
    names: str | None = None
    topic: str | None = None
    rate: float | None = None
    on_bad_lines: str = "error"
    delimiter: str | None = None
    decimal: str | None = None


@dataclass(frozen=True)
class ValidateOptions:
    """``thermocal validate`` (INTERFACE.md; :func:`thermocal.pipeline.validate.validate_files`).
    The text-log options (``names``, ``rate``, ``on_bad_lines``, ``delimiter``, ``decimal``)
    apply to the validated file and to the ``modeling`` file alike; the log ``topic`` to each
    of them that is a flight-controller log (a CSV modelling run of a logged test)."""

    modeling: Path | None = None
    ambient: str | None = None
    averaging: float = DEFAULT_AVERAGING_S
    signal: str | None = None
    time: str | None = None
    time_unit: str | None = None
    signal_unit: str | None = None
    temp_unit: str | None = None
    temp_conversion: str | None = None
    stage_rate: float = 0.05
    min_stage: float = 600.0
    settle: float = 0.0
    extrapolate: bool = False
    names: str | None = None
    rate: float | None = None
    on_bad_lines: str = "error"
    delimiter: str | None = None
    decimal: str | None = None
    topic: str | None = None
    latitude: float | None = None
    static_s: float = 1.0


ALIASES: dict[str, dict[str, str]] = {
    "fit": {"sensor": "topic"},
    "validate": {"average": "averaging", "sensor": "topic"},
}
"""Second names of an option (``--average`` is ``--averaging``), per command."""

NOT_IN_TABLES = frozenset({"modeling", "params"})
"""Options a fleet sets itself (the unit's own modelling file)."""

OPTIONS: dict[str, type[Any]] = {"fit": FitOptions, "validate": ValidateOptions}
"""The options dataclass of each command."""

O = TypeVar("O", FitOptions, ValidateOptions)


def option_kinds(cls: type[Any]) -> dict[str, str]:
    """``{option name: "flag" | "int" | "float" | "str" | "path"}`` of an options dataclass
    (option names with dashes)."""
    hints = typing.get_type_hints(cls)
    out: dict[str, str] = {}
    for f in dataclasses.fields(cls):
        if f.name == "params":  # the family's options: :func:`family_option_kinds`
            continue
        args = set(typing.get_args(hints[f.name])) - {type(None)} or {hints[f.name]}
        kind = next(iter(args))
        name = f.name.replace("_", "-")
        out[name] = {bool: "flag", int: "int", float: "float", Path: "path"}.get(kind, "str")
    return out


def family_option_kinds() -> dict[str, tuple[str, tuple[FamilyOption, ...]]]:
    """``{option name: (kind, the declared options it gives)}`` of the built-in families'
    fit options (option names with dashes; :func:`thermocal.families.fit_option_table`).
    A choice with a switch is two options: the flag ``select`` and its ``select-method``."""
    out: dict[str, tuple[str, tuple[FamilyOption, ...]]] = {}
    for name, decls in fit_option_table().items():
        opts = tuple(o for _fam, o in decls)
        first = opts[0]
        dashed = name.replace("_", "-")
        if first.switch:
            out[dashed] = ("flag", opts)
            out[first.switch.replace("_", "-")] = ("str", opts)
        else:
            out[dashed] = ({"bool": "tristate"}.get(first.kind, first.kind), opts)
    return out


def family_params(values: Mapping[str, Any]) -> dict[str, Any]:
    """The family options (constructor parameters) of the command-line values ``values``
    (named as the options without dashes, ``rate_interval``, ``select``,
    ``select_method``): ``{parameter: value}`` for the options given (not None; a flag
    given).  An option the chosen family does not take is kept: the family refuses it."""
    params: dict[str, Any] = {}
    for name, decls in fit_option_table().items():
        first = decls[0][1]
        value = values.get(name)
        if first.switch:
            if value:
                params[first.name] = values.get(first.switch) or first.choices[0]
        elif value is not None:
            params[first.name] = value
    return params


def options_of(cls: type[O], values: Mapping[str, Any]) -> O:
    """The options dataclass from a mapping holding at least its fields (a command's
    parameters, named as the fields)."""
    return cls(**{f.name: values[f.name] for f in dataclasses.fields(cls) if f.name in values})


def _table_text(key: str, value: Any, where: str) -> str:
    """A table value as the command line would take it: a list as ``a,b``, a number as
    written."""
    if isinstance(value, list):
        if not value or not all(isinstance(v, str | int | float) for v in value):
            raise ThermocalInputError(f"{where}: {key}: expected a list of names or numbers")
        return ",".join(str(v) for v in value)
    if isinstance(value, str | int | float) and not isinstance(value, bool):
        return str(value)
    raise ThermocalInputError(f"{where}: {key}: expected a string, number or list")


def _parse(kind: str, name: str, text: str, where: str) -> Any:
    """``text`` as the option's type, refused as the command line refuses it."""
    try:
        if kind == "int":
            return int(text)
        if kind == "float":
            return float(text)
        if kind == "floats":
            return tuple(float(v) for v in text.split(","))
    except ValueError:
        what = {"int": "integer", "float": "float"}.get(kind, "list of numbers")
        raise ThermocalInputError(
            f"{where}: Invalid value for '--{name}': {text!r} is not a valid {what}."
        ) from None
    return Path(text) if kind == "path" else text


def _table_kinds(command: str) -> dict[str, str]:
    """``{option name: kind}`` a table of ``command`` takes (the family options of ``fit``
    included)."""
    kinds = option_kinds(OPTIONS[command])
    if command == "fit":
        kinds |= {n: kind for n, (kind, _opts) in family_option_kinds().items()}
    return kinds


def _table_flag(name: str, kind: str, value: Any, where: str) -> tuple[list[str], bool]:
    """A flag's command-line arguments and value (``tristate``: false is ``--no-NAME``)."""
    if not isinstance(value, bool):
        raise ThermocalInputError(f"{where}: {name} is a flag: write true or false")
    if kind == "tristate":
        return [f"--{name}" if value else f"--no-{name}"], value
    return ([f"--{name}"] if value else []), value


def options_from_table(command: str, table: Mapping[str, Any], where: str) -> tuple[Any, list[str]]:
    """A fleet configuration's table of ``command`` options (``{"model": "poly", "order": 2,
    "signal": ["gx", "gy"], "select": true}``) → the options dataclass and the same options
    as command-line arguments (``["--model", "poly", "--order", "2", "--signal", "gx,gy",
    "--select"]``, recorded with each unit).  An unknown option, a value of the wrong shape
    or type, or a missing required option is a :class:`ThermocalInputError` naming it
    (``where``: the file and table).  A flag set to false is left at its default; a yes/no
    family option (``per_run_offset``) set to false is ``--no-per-run-offset``."""
    cls = OPTIONS[command]
    kinds = _table_kinds(command)
    aliases = ALIASES.get(command, {})
    known = {n: n for n in kinds if n.replace("-", "_") not in NOT_IN_TABLES}
    known |= {a: t for a, t in aliases.items()}
    args: list[str] = []
    values: dict[str, Any] = {}
    for key, value in table.items():
        name = str(key).replace("_", "-")
        if name not in known:
            raise ThermocalInputError(
                f"{where}: {key!r} is not an option of thermocal {command}; it takes "
                + ", ".join(sorted(known))
            )
        field = known[name].replace("-", "_")
        kind = kinds[known[name]]
        if kind in ("flag", "tristate"):
            flag_args, values[field] = _table_flag(name, kind, value, where)
            args += flag_args
            continue
        text = _table_text(str(key), value, where)
        args += [f"--{name}", text]
        values[field] = _parse(kind, name, text, where)
    required = [
        f.name
        for f in dataclasses.fields(cls)
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    for f in required:
        if f not in values:
            raise ThermocalInputError(f"{where}: Missing option '--{f.replace('_', '-')}'.")
    if command == "fit":
        own = {f.name for f in dataclasses.fields(cls)}
        values = {k: v for k, v in values.items() if k in own} | {"params": family_params(values)}
    return cls(**values), args


__all__ = [
    "ALIASES",
    "OPTIONS",
    "FitOptions",
    "ValidateOptions",
    "family_option_kinds",
    "family_params",
    "option_kinds",
    "options_from_table",
    "options_of",
]
