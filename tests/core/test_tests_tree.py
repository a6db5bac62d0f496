"""The tests tree mirrors the package (CONTRIBUTING.md, "Where a test goes"): every test file
sits in a folder named after a subpackage of :mod:`thermocal` or in ``core`` (the top-level
modules), ``cli`` (the command-line contract) or ``docs`` (the documentation); no test file
lies at the top of ``tests/``; helpers are in ``tests/helpers/`` and hold no tests; and no two
test files share a basename (pytest imports each by its basename, so a second one would fail
to import, and ``benchmarks/mutation_check.py`` finds test files by it).  The folders allowed
are read from ``src/thermocal`` itself."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import thermocal

TESTS = Path(__file__).resolve().parents[1]
SRC = Path(thermocal.__file__).parent
SUBPACKAGES = {p.parent.name for p in SRC.glob("*/__init__.py")}
OTHER_FOLDERS = {"core", "cli", "docs"}


def _test_files() -> list[Path]:
    return sorted(p for p in TESTS.rglob("test_*.py") if "data" not in p.relative_to(TESTS).parts)


def test_every_test_file_is_in_a_folder_named_after_the_package() -> None:
    misplaced = [
        p.relative_to(TESTS).as_posix()
        for p in _test_files()
        if len(p.relative_to(TESTS).parts) != 2
        or p.relative_to(TESTS).parts[0] not in SUBPACKAGES | OTHER_FOLDERS
    ]
    assert misplaced == [], f"test files outside tests/<subpackage>/: {misplaced}"


def test_test_basenames_are_unique() -> None:
    counts = Counter(p.name for p in _test_files())
    assert [name for name, n in counts.items() if n > 1] == []


def test_helpers_hold_no_tests() -> None:
    helpers = sorted((TESTS / "helpers").glob("*.py"))
    assert helpers, "tests/helpers/ is empty"
    assert [p.name for p in helpers if p.name.startswith("test_")] == []


def test_the_expected_folders_exist() -> None:
    """The folders are read from the package, so an empty list would pass everything: the
    package's subpackages as this tree knows them are all there."""
    assert {"stability", "models", "readers", "station", "tempcal"} <= SUBPACKAGES
