"""Every ``Examples`` section of the package's docstrings runs, as the user would type it.

The examples are collected from every module of ``src/thermocal`` by :mod:`doctest` (one
test per module that has any), with ``ELLIPSIS`` and ``NORMALIZE_WHITESPACE``; an example
that no longer prints what its docstring says fails here.
"""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import thermocal

FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _modules() -> list[str]:
    names = [thermocal.__name__]
    for info in pkgutil.walk_packages(thermocal.__path__, prefix="thermocal."):
        names.append(info.name)
    return sorted(names)


def _with_examples() -> list[str]:
    finder = doctest.DocTestFinder(exclude_empty=True)
    out = []
    for name in _modules():
        if name.endswith("__main__"):
            continue
        module = importlib.import_module(name)
        if any(t.examples for t in finder.find(module, name)):
            out.append(name)
    return out


MODULES = _with_examples()


def test_the_main_entry_points_have_examples() -> None:
    """The examples are collected at all (a broken finder would pass every test below)."""
    assert "thermocal.errors" in MODULES
    assert "thermocal.readers.options" in MODULES


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name: str) -> None:
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=FLAGS, report=False, verbose=False)
    assert result.attempted > 0
    assert result.failed == 0, f"{result.failed} docstring example(s) of {name} failed"
