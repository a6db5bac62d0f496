"""Tutorial pages run as written: every ``console`` and ``python`` block of a page is
executed, in order, in a temporary folder that sees the repository's ``tests/`` as the root
does, and paired with the ``text`` block that follows it on the page (what it printed,
what the page shows)."""

from __future__ import annotations

import contextlib
import io
import re
import shlex
from pathlib import Path

import pytest

from thermocal.cli import main

ROOT = Path(__file__).resolve().parents[2]
TUTORIALS = ROOT / "docs" / "tutorials"
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```$", re.MULTILINE | re.DOTALL)


def _run_block(lang: str, body: str, namespace: dict[str, object] | None = None) -> str:
    """What a ``console`` block's ``$ thermocal …`` lines or a ``python`` block print (the
    page's python blocks share ``namespace``, as a notebook's cells do)."""
    out = io.StringIO()
    if lang == "python":
        with contextlib.redirect_stdout(out):
            exec(compile(body, "tutorial", "exec"), {} if namespace is None else namespace)
        return out.getvalue()
    for line in body.splitlines():
        assert line.startswith("$ thermocal "), line
        err = io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(shlex.split(line[len("$ thermocal ") :]))
        assert code == 0, err.getvalue()
    return out.getvalue()


def _run_page(page: Path) -> list[tuple[str, str]]:
    """(printed, shown) for every executable block of the page, in order."""
    blocks = [(m.group(1), m.group(2)) for m in BLOCK.finditer(page.read_text(encoding="utf-8"))]
    pairs = []
    namespace: dict[str, object] = {}
    for i, (lang, body) in enumerate(blocks):
        if lang in ("console", "python"):
            shown = next(b for la, b in blocks[i + 1 :] if la == "text")
            pairs.append((_run_block(lang, body, namespace), shown))
    return pairs


def _numbers(text: str) -> list[float]:
    return [float(v) for v in NUMBER.findall(text)]


def fresh_cli(mp: pytest.MonkeyPatch) -> None:
    """The page runs as in a new shell: no ``COLUMNS`` left by an earlier test and the
    CLI's consoles built anew (a module fixture runs before the autouse console reset of
    ``tests/conftest.py``, so in a parallel run a console of another test's width printed
    the page's tables cut short)."""
    from thermocal.cli import common

    mp.delenv("COLUMNS", raising=False)
    for console in (common.stdout, common.stderr):
        mp.setattr(console, "_console", None)


def _run_in_scratch(tmp: Path, name: str) -> list[tuple[str, str]]:
    (tmp / "tests").symlink_to(ROOT / "tests", target_is_directory=True)
    with pytest.MonkeyPatch.context() as mp:
        fresh_cli(mp)
        mp.chdir(tmp)
        return _run_page(TUTORIALS / name)


Page = tuple[list[tuple[str, str]], Path]
"""A page run: (printed, shown) for each executable block, and the folder it ran in."""


def run_page(factory: pytest.TempPathFactory, name: str) -> Page:
    """Run the tutorial ``name`` (``"tumble.md"``) in a new empty folder (named after it);
    for a module-scoped fixture."""
    tmp = factory.mktemp(Path(name).stem)
    return _run_in_scratch(tmp, name), tmp


def assert_prints_as_shown(pairs: list[tuple[str, str]], blocks: int) -> None:
    """The page's ``blocks`` executable blocks each printed what the page shows: the same
    numbers, and the same lines stripped on both sides (rich versions pad a table's title
    differently: centred with leading spaces on the floor's rich, flush on the lock's)."""
    assert len(pairs) == blocks
    for printed, shown in pairs:
        assert _numbers(printed) == _numbers(shown)
        lines = [ln.strip() for ln in printed.strip().splitlines()]
        assert lines == [ln.strip() for ln in shown.strip().splitlines()]
