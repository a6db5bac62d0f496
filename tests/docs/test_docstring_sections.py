"""Every public function, method and class of the library carries its numpydoc sections.

A public function or method that takes arguments documents them under ``Parameters``; a public
class with fields (a dataclass, a result) documents them under ``Attributes`` (or
``Parameters``).  Exceptions, warnings, enums and protocols are exempt (their one line says what
they are); ``thermocal.cli`` is the command line, documented by its generated reference.  The
reading below is checked against a small module written in the test, so it cannot pass by
seeing nothing.
"""

from __future__ import annotations

import ast
from pathlib import Path

import thermocal

SRC = Path(thermocal.__file__).parent
EXEMPT_BASES = {
    "Enum",
    "IntEnum",
    "NamedTuple",
    "Protocol",
    "StrEnum",
    "TypedDict",
}


def _takes_arguments(fn: ast.FunctionDef) -> bool:
    args = fn.args.posonlyargs + fn.args.args + fn.args.kwonlyargs
    named = [a.arg for a in args if a.arg not in ("self", "cls")]
    return bool(named or fn.args.vararg or fn.args.kwarg)


def _exempt(cls: ast.ClassDef) -> bool:
    bases = {getattr(b, "id", getattr(b, "attr", "")) for b in cls.bases}
    return bool(bases & EXEMPT_BASES) or any(b.endswith(("Error", "Warning")) for b in bases)


def _has_fields(cls: ast.ClassDef) -> bool:
    return any(
        isinstance(n, ast.AnnAssign)
        and isinstance(n.target, ast.Name)
        and not n.target.id.startswith("_")
        for n in cls.body
    )


def _skipped(fn: ast.FunctionDef) -> bool:
    names = {getattr(d, "id", getattr(d, "attr", "")) for d in fn.decorator_list}
    return fn.name.startswith("_") or bool(names & {"property", "overload"})


def _undocumented(tree: ast.Module, rel: str) -> list[str]:
    out: list[str] = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and not _skipped(node):
            if _takes_arguments(node) and "Parameters\n" not in (ast.get_docstring(node) or ""):
                out.append(f"{rel}::{node.name}")
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            doc = ast.get_docstring(node) or ""
            if (
                not _exempt(node)
                and _has_fields(node)
                and "Attributes\n" not in doc
                and "Parameters\n" not in doc
            ):
                out.append(f"{rel}::{node.name}")
            for m in node.body:
                if (
                    isinstance(m, ast.FunctionDef)
                    and not _skipped(m)
                    and _takes_arguments(m)
                    and "Parameters\n" not in (ast.get_docstring(m) or "")
                ):
                    out.append(f"{rel}::{node.name}.{m.name}")
    return out


def undocumented() -> set[str]:
    """Public functions, methods and classes outside ``cli/`` that lack their section."""
    found: set[str] = set()
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if not rel.startswith("cli/"):
            found.update(_undocumented(ast.parse(path.read_text(encoding="utf-8")), rel))
    return found


def test_every_public_name_documents_its_parameters_or_attributes() -> None:
    assert sorted(undocumented()) == []


def test_the_reading_sees_a_missing_section() -> None:
    tree = ast.parse(
        'def f(x):\n    """Doc."""\n'
        'class C:\n    """Doc."""\n    a: int\n'
        'def g(x):\n    """Doc.\n\n    Parameters\n    ----------\n    x : int\n    """\n'
    )
    assert _undocumented(tree, "m.py") == ["m.py::f", "m.py::C"]
