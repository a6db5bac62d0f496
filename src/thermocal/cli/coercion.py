"""Option values converted without pydantic on typer ≥ 0.28 (start-up glue of the command line).

typer 0.28 and later convert every option's value through a pydantic ``TypeAdapter``
(``typer._coercion.build_runtime_param`` → ``typer._adapters``): the first conversion of a
run imports pydantic and pydantic-core and builds one adapter per option, ≈ 60–70 ms of CPU
in every command (measured with ``python -X importtime`` and ``cProfile`` on ``thermocal
allan``: ``typer._adapters`` 44 ms, ``pydantic.plugin._loader`` 9 ms with its
``importlib.metadata``, the adapters ≈ 18 ms).  Our options are plain ``str``, ``int``,
``float``, ``bool``, ``Path`` and lists of them, for which the conversion is ``str``,
``int(...)``, ``float(...)`` and ``Path(...)``.

:func:`install` gives each parameter of a built command a conversion
(:class:`_PlainRuntimeParam`, a subclass of typer's own ``RuntimeParam``, the object typer
builds lazily for each parameter) that handles exactly the values whose result is not in
doubt — a ``str`` of decimal digits for an ``int``, a plain decimal or exponent literal for a
``float``, a non-empty ``str`` without NUL for a ``Path`` — and hands every other value
(bad input, ``inf``, ``1_000``, a bound, a choice, a file type) to the runtime parameter typer
itself builds, so that every accepted value and every ``error:`` line stays typer's
(``tests/cli/test_cli_coercion.py`` compares both on every option of every command).  On
typer < 0.28 (click converts, no pydantic) or a typer whose internals differ, nothing is
installed and typer's own path runs.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path
from typing import Any

_INT = re.compile(r"(?:0|-?[1-9][0-9]{0,17})")
"""Decimal integers that ``int()`` and pydantic's lax ``int`` read alike (no sign ``+``, no
leading zero, no ``_``, no blank, at most 18 digits)."""

_FLOAT = re.compile(r"-?(?:[0-9]+\.[0-9]*|\.?[0-9]+)(?:[eE][-+]?[0-9]{1,3})?")
"""Decimal literals that ``float()`` and pydantic's lax ``float`` read alike (both round
correctly; no ``inf``/``nan``, ``_``, blank or leading ``+``: those go to typer)."""

_UNDECIDED = object()
"""What a plain conversion returns when the value is for typer's own conversion."""


def _plain_leaf(annotation: Any, value: Any) -> Any:
    """The value converted for a leaf annotation, or :data:`_UNDECIDED`."""
    kind = type(value)
    if annotation is str:
        return value if kind is str else _UNDECIDED
    if annotation is bool:
        return value if kind is bool else _UNDECIDED
    if annotation is int:
        if kind is int:
            return value
        return int(value) if kind is str and _INT.fullmatch(value) else _UNDECIDED
    if annotation is float:
        if kind is float:
            return value
        return float(value) if kind is str and _FLOAT.fullmatch(value) else _UNDECIDED
    if annotation is Path and kind is str and value and "\x00" not in value:
        return Path(value)
    return _UNDECIDED


def _plain_kind(annotation: Any, parameter_info: Any) -> tuple[Any, bool] | None:
    """``(leaf annotation, is a list)`` when the parameter is converted plainly, else None:
    no parser, bound, clamp or choice, a ``Path`` without existence or permission checks
    beyond typer's defaults, and a leaf of ``str``, ``int``, ``float``, ``bool`` or ``Path``."""
    if any(getattr(parameter_info, k, None) is not None for k in ("parser", "min", "max")):
        return None
    origin = getattr(annotation, "__origin__", None)
    leaf, is_list = annotation, False
    if origin is list:
        args: tuple[Any, ...] = tuple(getattr(annotation, "__args__", ()))
        if len(args) != 1:
            return None
        leaf, is_list = args[0], True
    if leaf not in (str, int, float, bool, Path):
        return None
    if leaf is Path:
        flags = ("exists", "resolve_path", "writable", "allow_dash", "path_type")
        if any(getattr(parameter_info, k, None) for k in flags):
            return None
        if not getattr(parameter_info, "file_okay", True):
            return None
        if not getattr(parameter_info, "dir_okay", True):
            return None
    return leaf, is_list


def _runtime_base() -> Any:
    """typer's ``RuntimeParam`` and ``build_runtime_param`` (typer ≥ 0.28), else None."""
    try:
        coercion = importlib.import_module("typer._coercion")
    except ImportError:
        return None
    base = getattr(coercion, "RuntimeParam", None)
    build = getattr(coercion, "build_runtime_param", None)
    if not isinstance(base, type) or build is None:
        return None
    return base, build


def _plain_class(base: type, build: Any, path_check: Any) -> type:
    """The runtime parameter class: plain conversion first, typer's own otherwise."""

    class _PlainRuntimeParam(base):  # type: ignore[misc]
        """A parameter converted without pydantic where the result is not in doubt."""

        def _coerce_value(self, value: Any, param: Any, ctx: Any) -> Any:
            kind = _plain_kind(self.annotation, self.parameter_info)
            done = _UNDECIDED if kind is None else self._plain(value, kind)
            if done is not _UNDECIDED and kind is not None and kind[0] is Path:
                done = self._checked(done, param, ctx)
            if done is not _UNDECIDED:
                return done
            typer_own = build(param.type_descriptor)
            return typer_own._coerce_value(value, param=param, ctx=ctx)

        @staticmethod
        def _plain(value: Any, kind: tuple[Any, bool]) -> Any:
            leaf, is_list = kind
            if not is_list:
                return _plain_leaf(leaf, value)
            if not isinstance(value, (list, tuple)):
                return _UNDECIDED
            items = [_plain_leaf(leaf, item) for item in value]
            return _UNDECIDED if any(i is _UNDECIDED for i in items) else items

        def _checked(self, done: Any, param: Any, ctx: Any) -> Any:
            """typer's readability check of the paths (its message on failure)."""
            paths = done if isinstance(done, list) else [done]
            try:
                for p in paths:
                    path_check(p, self.parameter_info, path_type=Path, param=param, ctx=ctx)
            except Exception:  # typer's own conversion raises its own message
                return _UNDECIDED
            return done

    return _PlainRuntimeParam


_CLASS: list[type] = []


def install(command: Any) -> int:
    """Give every parameter of ``command`` (and of its subcommands) the plain conversion.

    Parameters
    ----------
    command : click or typer command
        A command as ``typer.main.get_command`` returns it.

    Returns
    -------
    int
        The number of parameters given the plain conversion (0 on typer < 0.28, where click
        converts the values and pydantic is not used).
    """
    if not _CLASS:
        found = _runtime_base()
        params_mod = importlib.import_module("typer._param_types") if found else None
        path_check = getattr(params_mod, "coerce_cli_path", None)
        if found is None or path_check is None:
            return 0
        _CLASS.append(_plain_class(found[0], found[1], path_check))
    count = sum(_give(param, _CLASS[0]) for param in getattr(command, "params", ()))
    _hook_help(command, _CLASS[0])
    for sub in getattr(command, "commands", {}).values():
        count += install(sub)
    return count


def _give(param: Any, cls: type) -> bool:
    """Give one typer parameter the plain conversion (not a file type, not one already
    given a conversion); whether it was given."""
    desc = getattr(param, "type_descriptor", None)
    if desc is None or getattr(param, "_runtime_param", _UNDECIDED) is not None:
        return False
    if desc.file_annotation is not None:
        return False
    try:
        plain = cls(parameter_info=desc.parameter_info, annotation=desc.annotation)
    except TypeError:  # a typer whose RuntimeParam asks for more: its own conversion
        return False
    param._runtime_param = plain
    return True


def _hook_help(command: Any, cls: type) -> None:
    """The command's ``--help`` flag, which typer builds per run, converted plainly too."""
    original = getattr(command, "get_help_option", None)
    if original is None or getattr(original, "_plain", False):
        return

    def get_help_option(ctx: Any) -> Any:
        option = original(ctx)
        if option is not None:
            _give(option, cls)
        return option

    get_help_option._plain = True  # type: ignore[attr-defined]
    command.get_help_option = get_help_option


__all__ = ["install"]
