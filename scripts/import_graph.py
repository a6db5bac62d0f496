#!/usr/bin/env python3
"""Draw thermocal's import structure from the code (ARCHITECTURE.md).

    python scripts/import_graph.py              # packages and the arrows between them, by layer
    python scripts/import_graph.py --modules    # module by module
    python scripts/import_graph.py --dot > imports.dot && dot -Tsvg imports.dot > imports.svg

Reads every module of ``src/thermocal`` with :mod:`ast` (nothing is imported or run), counts
module-level and function-level imports (``if TYPE_CHECKING:`` blocks are left out: they are
for the type checker only), prints each room's layer (ARCHITECTURE.md), its arrows, every
arrow that climbs to a higher layer and every import circle.  Exit status 1 when there is a
circle or an upward arrow, so it can gate a change.
"""

from __future__ import annotations

import argparse
import ast
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src" / "thermocal"

LAYERS: dict[str, int] = {
    # 1 core: the glossary, the types, the gates
    "_lazy": 1, "_version": 1, "errors": 1, "defaults": 1, "units": 1, "identifiers": 1, "outputs": 1,
    "recording": 1, "families": 1, "data_units": 1,
    # 2 maths: pure functions on arrays
    "preprocess": 2, "thermometer": 2, "legs": 2, "metrics": 2, "profiles": 2, "inspection": 2, "adequacy": 2, "gravity": 2,
    "heater": 2,
    "stability": 2, "models": 2, "compensate.kernels": 2, "simulate": 2, "turntable": 2,
    "multipos": 2, "datasets": 2, "compensate": 2, "firmware": 2, "metrics_streaming": 2,
    "ratetable": 2, "chamber_join": 2, "tumble": 2,
    # 3 files: reading, writing, model files, the drivers that stream files
    "readers": 3, "writers": 3,
    "validation": 3, "export": 3, "tempcal": 3,
    "station": 3, "pipeline": 3,
    # 4 presentation and batch drivers
    "report": 4, "fleet": 4, "demo": 4,
    # 5 the command line
    "cli": 5, "__main__": 5, "thermocal": 5,
}  # fmt: skip


def module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(["thermocal", *parts])


def _type_checking(node: ast.AST) -> bool:
    test = getattr(node, "test", None)
    return isinstance(test, ast.Name | ast.Attribute) and ast.unparse(test).endswith(
        "TYPE_CHECKING"
    )


def imports_of(path: Path, modules: set[str]) -> set[str]:
    """Modules of the package that ``path`` imports (absolute imports; the package uses no
    relative ones), each resolved to the longest existing module name."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found: set[str] = set()

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking(child):
                for sub in child.orelse:
                    visit(sub)
                continue
            if isinstance(child, ast.Import):
                found.update(a.name for a in child.names)
            elif isinstance(child, ast.ImportFrom) and child.module and child.level == 0:
                subs = {f"{child.module}.{a.name}" for a in child.names}
                found.update(subs & modules)  # ``from pkg import submodule``
                if not subs <= modules:  # names defined in the module (or package) itself
                    found.add(child.module)
            elif (
                isinstance(child, ast.Call)
                and ast.unparse(child.func).endswith("LazyModule")
                and child.args
                and isinstance(child.args[0], ast.Constant)
            ):
                found.add(str(child.args[0].value))
            visit(child)

    visit(tree)
    out = set()
    for name in found:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        if name and name != "thermocal":
            out.add(name)
    return out


def graph() -> dict[str, set[str]]:
    files = {module_name(p): p for p in ROOT.rglob("*.py")}
    mods = set(files)
    return {m: imports_of(p, mods) - {m} for m, p in sorted(files.items())}


def room(module: str) -> str:
    """The layer key a module belongs to (longest match in :data:`LAYERS`)."""
    rest = module.removeprefix("thermocal.").split(".")
    for n in range(len(rest), 0, -1):
        key = ".".join(rest[:n])
        if key in LAYERS:
            return key
    return rest[0]


def cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    sys.setrecursionlimit(10000)

    def strong(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in g:
        if v not in index:
            strong(v)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--modules", action="store_true", help="module by module")
    ap.add_argument("--dot", action="store_true", help="Graphviz DOT on stdout")
    args = ap.parse_args(argv)
    g = graph()
    circles = cycles(g)
    up = [
        (a, b)
        for a, deps in g.items()
        for b in deps
        if LAYERS.get(room(b), 0) > LAYERS.get(room(a), 0)
    ]
    name = (lambda m: m) if args.modules else room
    arrows: dict[str, set[str]] = defaultdict(set)
    for a, deps in g.items():
        for b in deps:
            if name(a) != name(b):
                arrows[name(a)].add(name(b))
    if args.dot:
        print("digraph thermocal {\n  rankdir=BT; node [shape=box];")
        for a in sorted({name(m) for m in g}):
            print(f'  "{a}" [label="{a}\\nlayer {LAYERS.get(room(a), "?")}"];')
        for a, bs in sorted(arrows.items()):
            for b in sorted(bs):
                print(f'  "{a}" -> "{b}";')
        print("}")
    else:
        for layer in sorted({*LAYERS.values(), 0}, reverse=True):
            rooms = sorted({name(m) for m in g if LAYERS.get(room(m), 0) == layer})
            if not rooms:
                continue
            print(f"layer {layer}" + ("" if layer else " (not in ARCHITECTURE.md: add it)"))
            for r in rooms:
                print(f"  {r} -> {', '.join(sorted(arrows.get(r, ()))) or '(nothing)'}")
        print(f"{len(g)} modules, {sum(len(v) for v in arrows.values())} arrows")
        for a, b in sorted(up):
            print(
                f"UPWARD: {a} (layer {LAYERS.get(room(a))}) imports {b} (layer "
                f"{LAYERS.get(room(b))})"
            )
        for c in circles:
            print("CIRCLE: " + " <-> ".join(c))
        unplaced = sorted({room(m) for m in g if room(m) not in LAYERS})
        for r in unplaced:
            print(f"UNPLACED: {r}")
    return 1 if circles or up or any(room(m) not in LAYERS for m in g) else 0


if __name__ == "__main__":
    raise SystemExit(main())
