"""The command-line reference, generated from the typer application when the docs are built.

``.. thermocal-cli::`` walks :data:`thermocal.cli.app` (every command module registered) and
writes one section per command — ``thermocal NAME`` and the subcommands of a group, e.g.
``thermocal station run`` — with the command's help and a table of its arguments and
options: names, type, default and help, as ``thermocal NAME --help`` prints them.  Nothing is
copied by hand, so the reference cannot fall behind the code.

Works with typer 0.12 (built on click) and with typer ≥ 0.28 (its own copy of click's
classes, the parameter's type in ``type_descriptor``).
"""

from __future__ import annotations

import enum
import pathlib
import re
import types
import typing
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

_PUNCT = re.compile(r"([\\`*_|\[\]<>:=#~^\-+.!\"'(){}@$%&,;/?])")


def rst_text(text: str) -> str:
    """Plain text as reST that renders literally: every punctuation character escaped."""
    return _PUNCT.sub(r"\\\1", " ".join(text.split()))


@dataclass(frozen=True)
class Param:
    """One argument or option of a command, as the reference shows it."""

    names: tuple[str, ...]
    kind: str  # "argument" or "option"
    type: str
    default: str
    required: bool
    help: str


@dataclass(frozen=True)
class Command:
    """One command (``path`` = ("station", "run")) with its help and parameters."""

    path: tuple[str, ...]
    help: str
    params: tuple[Param, ...]

    @property
    def title(self) -> str:
        return " ".join(("thermocal", *self.path))


_SIMPLE = {str: "text", int: "integer", float: "float", bool: "boolean", pathlib.Path: "path"}


def _annotation_name(annotation: Any) -> str:
    """The type of a parameter from its annotation (typer ≥ 0.28)."""
    if isinstance(annotation, str):
        return annotation
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _annotation_name(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        return " | ".join(_annotation_name(a) for a in args)
    if origin in (list, tuple):
        return " ".join(_annotation_name(a) for a in typing.get_args(annotation) if a is not ...)
    if isinstance(annotation, type) and issubclass(annotation, enum.Enum):
        return "choice of " + ", ".join(str(m.value) for m in annotation)
    if annotation in _SIMPLE:
        return _SIMPLE[annotation]
    return getattr(annotation, "__name__", str(annotation))


def _type_name(param: Any) -> str:
    """The parameter's type: click's ``ParamType`` (typer < 0.28) or its annotation."""
    if getattr(param, "is_flag", False) or getattr(param, "count", False):
        return "flag" if getattr(param, "is_flag", False) else "count"
    ptype = getattr(param, "type", None)
    if ptype is not None:
        choices = getattr(ptype, "choices", None)
        if choices:
            return "choice of " + ", ".join(str(getattr(c, "value", c)) for c in choices)
        name = str(getattr(ptype, "name", ptype))
        return {"filename": "path", "file": "path"}.get(name, name)
    descriptor = getattr(param, "type_descriptor", None)
    if descriptor is not None:
        return _annotation_name(descriptor.annotation)
    return "text"


def _default(param: Any) -> str:
    """The default as ``--help`` would state it; empty when there is none."""
    default = getattr(param, "default", None)
    if callable(default):
        return "(computed)"
    if default is None or getattr(param, "required", False):
        return ""
    if isinstance(default, enum.Enum):
        default = default.value
    if isinstance(default, bool):
        return "on" if default else "off"
    if isinstance(default, (list, tuple)):
        return ", ".join(str(d) for d in default)
    return str(default)


def _param(param: Any) -> Param:
    kind = "option" if getattr(param, "param_type_name", "") == "option" else "argument"
    if kind == "argument" and hasattr(param, "is_flag"):
        kind = "option"
    names = tuple(param.opts) + tuple(getattr(param, "secondary_opts", ()) or ())
    if kind == "argument":
        names = (str(param.name).upper(),)
    return Param(
        names=names,
        kind=kind,
        type=_type_name(param),
        default=_default(param),
        required=bool(getattr(param, "required", False)),
        help=str(getattr(param, "help", None) or ""),
    )


def _walk(command: Any, path: tuple[str, ...]) -> Iterator[Command]:
    params = tuple(_param(p) for p in command.params if not getattr(p, "hidden", False))
    if path:
        yield Command(path, str(command.help or ""), params)
    subcommands = getattr(command, "commands", None) or {}
    for name in sorted(subcommands):
        sub = subcommands[name]
        if not getattr(sub, "hidden", False):
            yield from _walk(sub, (*path, name))


def commands() -> list[Command]:
    """Every visible command of thermocal's application, groups before their subcommands."""
    import typer

    import thermocal.cli

    return list(_walk(typer.main.get_command(thermocal.cli.app), ()))


def global_options() -> tuple[Param, ...]:
    """The options of ``thermocal`` itself (``--version``, ``--help``)."""
    import typer

    import thermocal.cli

    root = typer.main.get_command(thermocal.cli.app)
    return tuple(_param(p) for p in root.params if not getattr(p, "hidden", False))


def command_id(command: Command) -> str:
    """The HTML anchor of a command's section: ``thermocal-station-run``."""
    return nodes.make_id(command.title)


def _table(params: tuple[Param, ...]) -> list[str]:
    """A list-table of the parameters (reST lines)."""
    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 25 15 12 48", ""]
    lines += ["   * - name", "     - type", "     - default", "     - help"]
    for p in params:
        names = ", ".join(f"``{n}``" for n in p.names)
        if p.required:
            names += " (required)"
        lines += [
            f"   * - {names}",
            f"     - {rst_text(p.type) or '—'}",
            f"     - {rst_text(p.default) or '—'}",
            f"     - {rst_text(p.help) or '—'}",
        ]
    return lines


def _paragraphs(text: str) -> list[str]:
    """A command's help as reST paragraphs (``\\b`` markers of click dropped)."""
    out: list[str] = []
    for block in re.split(r"\n\s*\n", text.replace("\b", "")):
        if block.strip():
            out += [rst_text(block), ""]
    return out


class ThermocalCliDirective(SphinxDirective):
    """``.. thermocal-cli::``: a section per command of the application."""

    has_content = False

    def _parse(self, lines: list[str], parent: nodes.Element) -> None:
        self.state.nested_parse(StringList(lines, source="thermocal-cli"), 0, parent)

    def run(self) -> list[nodes.Node]:
        out: list[nodes.Node] = []
        glob = nodes.section(ids=["thermocal"], names=["thermocal"])
        glob += nodes.title(text="thermocal")
        self._parse(["Options of the program itself:", "", *_table(global_options())], glob)
        out.append(glob)
        for command in commands():
            section = nodes.section(ids=[command_id(command)], names=[command.title])
            section += nodes.title(text=command.title)
            lines = _paragraphs(command.help)
            if command.params:
                lines += _table(command.params)
            else:
                lines += ["A group: its subcommands follow."]
            self._parse(lines, section)
            self.env.note_dependency(__file__)
            out.append(section)
        return out


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("thermocal-cli", ThermocalCliDirective)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
