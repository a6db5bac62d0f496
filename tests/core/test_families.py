"""The families' declarations (:mod:`thermocal.families`) against the classes, the command
line and the bounds they state.  A family option without its ``fit`` option, a ``fit``
option that no family or common field gives, or a bound the library does not check fails
here."""

from __future__ import annotations

import dataclasses
import inspect
import math
import typing
from typing import Any

import pytest
import typer

from thermocal.errors import ParameterError
from thermocal.families import BUILTIN_FAMILIES, MAX_ORDER, MAX_SEGMENTS, fit_option_table
from thermocal.models.registry import MODEL_REGISTRY
from thermocal.pipeline.messages import option_name
from thermocal.pipeline.options import FitOptions


def _fit_params() -> dict[str, Any]:
    """``fit``'s click parameters by their first long option."""
    from thermocal.cli import _register
    from thermocal.cli.application import app

    _register()
    cmd = typer.main.get_command(app).commands["fit"]  # type: ignore[attr-defined]
    options = [p for p in cmd.params if p.param_type_name == "option"]
    return {next(o for o in p.opts if o.startswith("--")): p for p in options}


def _annotations() -> dict[str, Any]:
    """The type of each parameter of ``fit``'s signature (what typer builds options from)."""
    from thermocal.cli.fit_cmd import fit_cmd

    sig = inspect.signature(fit_cmd)
    return {n: typing.get_args(p.annotation)[0] for n, p in sig.parameters.items()}


def test_every_family_option_is_a_fit_option_of_its_type_and_nothing_else_is() -> None:
    params, types = _fit_params(), _annotations()
    common = {option_name(f.name) for f in dataclasses.fields(FitOptions)}
    common = (common - {"--params"}) | {"--output", "--json"}
    # the chamber log's options are one field, chamber_log (a ChamberLogSpec)
    common |= {o for o in params if o.startswith("--chamber-")}
    declared: set[str] = set()
    for decl in BUILTIN_FAMILIES:
        for o in decl.options:
            declared.add(o.cli)
            assert o.cli in params, (decl.name, o.name)
            kind = {"int": int, "float": float, "bool": bool}.get(o.kind, str)
            field = o.switch or o.field  # a switch: the flag, and the option naming the choice
            assert kind in typing.get_args(types[field]) or types[field] is kind, o.name
            if o.switch:
                declared.add("--" + o.switch.replace("_", "-"))
                assert params[o.cli].is_flag and types[o.field] is bool
    assert set(params) - common == declared
    assert declared.isdisjoint(common)


def test_an_option_shared_by_families_is_one_parameter_of_one_kind() -> None:
    for field, decls in fit_option_table().items():
        assert len({(o.name, o.kind, o.switch) for _fam, o in decls}) == 1, field


def test_each_class_carries_its_declaration_and_takes_its_options() -> None:
    for decl in BUILTIN_FAMILIES:
        cls = MODEL_REGISTRY[decl.name]
        assert cls.declaration is decl and cls.family == decl.name
        assert decl.c_generator == cls.C_GENERATOR
        taken = inspect.signature(cls.__init__).parameters
        assert all(o.name in taken for o in decl.options), decl.name


@pytest.mark.parametrize(
    ("family", "name", "bad", "good", "message"),
    [
        ("poly", "order", MAX_ORDER + 1, MAX_ORDER, "order must be between 1 and 10, got 11"),
        ("poly", "order", 0, 1, "order must be between 1 and 10, got 0"),
        ("warmup", "t0_order", -1, 0, "t0_order must be between 0 and 10, got -1"),
        ("piecewise", "segments", MAX_SEGMENTS + 1, MAX_SEGMENTS,
         "segments must be between 1 and 100, got 101"),
        ("poly", "rate_interval_s", 0.0, 1e-9, "rate_interval_s must be > 0, got 0.0"),
        ("poly", "rcond", -1e-12, 0.0, "rcond must be ≥ 0, got -1e-12"),
        ("poly", "ridge", math.inf, -1.0, "ridge must be a finite number, got inf"),
        ("bank", "startup_s", 0.0, 0.5, "startup_s must be > 0, got 0.0"),
        ("poly", "solver", "lu", "qr", "solver must be auto, qr or gram, got 'lu'"),
        ("piecewise", "breakpoints", (), (25.0,), "breakpoints holds no number"),
        ("poly", "order", 2.0, 2, "order must be an integer, got 2.0"),
    ],
)  # fmt: skip
def test_the_library_checks_the_declared_bounds(
    family: str, name: str, bad: object, good: object, message: str
) -> None:
    """The boundary itself passes, one step beyond is refused naming the parameter; the
    command line shows the option in its place."""
    cls = MODEL_REGISTRY[family]
    assert cls.from_options({name: good}).get_params()[name] == good
    with pytest.raises(ParameterError) as info:
        cls.from_options({name: bad})
    assert str(info.value) == message and info.value.parameter == name
    cli = cls.declaration.option(name).cli
    shown = info.value.named(option_name(name))
    assert shown.startswith(cli if name != "select" else "--select-method")
