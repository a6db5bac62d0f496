"""Sphinx configuration of thermocal's documentation.

Build (warnings are errors, as CI builds it)::

    .venv/bin/python -m sphinx -W -b html docs docs/_build/html
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent / "src"))

import re  # noqa: E402
from typing import Any  # noqa: E402

from thermocal import __version__  # noqa: E402

project = "thermocal"
author = "thermocal contributors"
copyright = "thermocal contributors, MIT licence"
version = release = __version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "thermocal_cli",
    "thermocal_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "README.md", "Thumbs.db", ".DS_Store"]

# Markdown pages: $$ … $$ and $ … $ maths, ::: fences for directives
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# API reference: the curated modules of docs/api.rst only; members in source order.
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the signatures show the annotations; numpydoc shows the rest
autodoc_mock_imports: list[str] = []
# numpydoc: the existing docstrings are not all numpydoc yet; no validation checks and no
# autosummary tables of members (their targets would be documented twice) for now.
numpydoc_validation_checks: set[str] = set()
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

html_theme = "alabaster"
html_title = f"thermocal {version}"
html_static_path: list[str] = []

# The docstrings write absolute values as |x| (e.g. |Ṫ| < 0.1 °C/min), which reST reads as a
# substitution reference; no docstring uses substitutions, so the bars are escaped outside
# inline literals before numpydoc and docutils see them.
_LITERAL = re.compile(r"(``.+?``)")
_ABS = re.compile(r"(?<![\\|])\|(?=\S)([^|\n]+?)(?<=\S)\|(?![|_])")


def _escape_abs(line: str) -> str:
    parts = _LITERAL.split(line)
    return "".join(p if p.startswith("``") else _ABS.sub(r"\\|\1\\|", p) for p in parts)


# Many docstrings write a parameter as ``name : what it is [unit]`` on one line, where
# numpydoc expects ``name : type`` and the description indented below; such a line is split
# so that the description is not shown as the parameter's type.
_FIELD_SECTIONS = {"Parameters", "Other Parameters", "Attributes", "Returns", "Yields"}
_FIELD = re.compile(r"^(?P<indent>\s*)(?P<name>[\w*][\w*, ]*?) : (?P<rest>.+)$")
_TYPE = re.compile(r"^[\w.\[\], |()-]+$")


def _is_type(text: str) -> bool:
    """Whether ``rest`` of ``name : rest`` reads as a type (``float``, ``str, optional``)."""
    return bool(_TYPE.match(text)) and len(text.split()) <= 4 and not text.endswith(".")


def _split_fields(lines: list[str]) -> list[str]:
    out: list[str] = []
    section, base = "", ""
    for i, line in enumerate(lines):
        if i + 1 < len(lines) and set(lines[i + 1].strip()) == {"-"} and line.strip():
            section, base = line.strip(), line[: len(line) - len(line.lstrip())]
        m = _FIELD.match(line)
        if section in _FIELD_SECTIONS and m and m["indent"] == base and not _is_type(m["rest"]):
            out += [f"{m['indent']}{m['name']}", f"{m['indent']}    {m['rest']}"]
        else:
            out.append(line)
    return out


def _process_docstring(
    app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    lines[:] = _split_fields([_escape_abs(line) for line in lines])


def setup(app: Any) -> None:
    app.connect("autodoc-process-docstring", _process_docstring, priority=100)
