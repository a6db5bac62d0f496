"""The layers of ARCHITECTURE (issue 27, STYLE.md): read from the code itself.

1. No import circle between the modules of :mod:`thermocal`.  The graph is built from the
   AST of every module: module-level AND function-level imports (a late import inside a
   function is still an arrow), ``LazyModule("x")`` and ``importlib.import_module("x")``
   with a literal name too; imports under ``if TYPE_CHECKING:`` are left out (they never
   run).
2. The maths imports no file layer (pandas, pyarrow, the readers and writers, the model and
   compensation files, the report, the CLI): in a fresh interpreter (what ``import X``
   loads) AND statically (every module reachable through the graph above, function-level
   imports included, so a file read hidden in a function is seen too).
3. The CLI uses the library only through public names, and nothing outside ``cli/``
   imports :mod:`thermocal.cli`.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import pytest

import thermocal

SRC = Path(thermocal.__file__).parent
"""The package under test (the worktree's source when ``PYTHONPATH`` points at it)."""

MATHS_MODULES = (
    "thermocal.units",
    "thermocal.recording",
    "thermocal.preprocess",
    "thermocal.metrics",
    "thermocal.legs",
    "thermocal.metrics_streaming",
    "thermocal.profiles",
    "thermocal.inspection",
    "thermocal.adequacy",
    "thermocal.gravity",
    "thermocal.compensate.kernels",
    "thermocal.data_units",
)
MATHS_PACKAGES = (
    "thermocal.stability",
    "thermocal.models",
    "thermocal.simulate",
    "thermocal.turntable",
    "thermocal.multipos",
)
"""Every module of these packages is maths, except :data:`MODEL_FILE_MODULES`."""
MODEL_FILE_MODULES = ()
"""The file-layer edges inside maths packages (ARCHITECTURE.md): none — the model file, the
turntable's and multipos' drivers and the chunked compensation live in ``pipeline/``.
(``models.schema`` and ``models.calibration`` check and build dicts, no I/O:
maths.)"""
FACADES: tuple[str, ...] = ()
"""Packages whose ``__init__`` hands out file functions on first use: checked at import only.
None today: ``thermocal.models`` no longer re-exports ``load_model`` (import it from
``thermocal.pipeline.model_file``)."""

FILE_LAYER = (
    "pandas",
    "pyarrow",
    "thermocal.readers",
    "thermocal.writers",
    "thermocal.pipeline.model_file",
    "thermocal.pipeline.model_filecheck",
    "thermocal.pipeline",
    "thermocal.tempcal",
    "thermocal.export",
    "thermocal.station",
    "thermocal.report",
    "thermocal.fleet",
    "thermocal.demo",
    "thermocal.cli",
)
"""A module is file layer when its name is one of these or inside one of them."""

LIGHT_MODULES = ("thermocal.validation", "thermocal.export.c", "thermocal.report.analysis")
"""Not maths, but their import loads no pandas, pyarrow, readers or files either (start-up)."""
LIGHT_FORBIDDEN = (
    "pandas",
    "pyarrow",
    "thermocal.readers",
    "thermocal.writers",
    "thermocal.pipeline.compensate",
    "thermocal.pipeline.model_file",
)

CLI = "thermocal.cli"
CLI_INFRASTRUCTURE = ("thermocal._lazy",)
"""Private modules of the core the CLI may use (lazy imports, ``prefetch``)."""


# --- the import graph -----------------------------------------------------------------------


@dataclass(frozen=True)
class Import:
    """One import statement of a module: the module it loads and the names it takes."""

    line: int
    target: str
    """The thermocal module it resolves to, or the top-level name of another package."""
    names: tuple[str, ...] = ()
    alias: str | None = None


@dataclass
class Module:
    name: str
    path: Path
    is_package: bool
    imports: list[Import] = field(default_factory=list)


def _module_names() -> dict[str, tuple[Path, bool]]:
    out: dict[str, tuple[Path, bool]] = {}
    for p in sorted(SRC.rglob("*.py")):
        parts = list(p.relative_to(SRC.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        out[".".join(parts)] = (p, is_package)
    return out


def _is_type_checking(node: ast.If) -> bool:
    t = node.test
    return (isinstance(t, ast.Name) and t.id == "TYPE_CHECKING") or (
        isinstance(t, ast.Attribute) and t.attr == "TYPE_CHECKING"
    )


def _nodes(node: ast.AST) -> Iterator[ast.AST]:
    """Every node below ``node`` except the bodies of ``if TYPE_CHECKING:``."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.If) and _is_type_checking(child):
            for other in child.orelse:
                yield other
                yield from _nodes(other)
            continue
        yield child
        yield from _nodes(child)


def _literal_import(node: ast.Call) -> str | None:
    """``LazyModule("x")`` / ``importlib.import_module("x")`` with a literal name."""
    f = node.func
    name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
    if name not in ("LazyModule", "import_module") or not node.args:
        return None
    arg = node.args[0]
    return arg.value if isinstance(arg, ast.Constant) and isinstance(arg.value, str) else None


def _resolve(name: str, known: dict[str, tuple[Path, bool]]) -> str:
    """The thermocal module ``name`` loads (its longest known prefix), or its top package."""
    if not name.startswith("thermocal"):
        return name.split(".")[0]
    while name not in known and "." in name:
        name = name.rpartition(".")[0]
    return name


def _to_frame_nodes(tree: ast.AST) -> set[int]:
    """The nodes inside a ``def to_frame`` method: its ``import pandas`` builds the table the
    user asked for from arrays (no file is read); the fresh-interpreter check still holds
    (importing the module loads no pandas)."""
    return {
        id(n)
        for f in ast.walk(tree)
        if isinstance(f, ast.FunctionDef) and f.name == "to_frame"
        for n in ast.walk(f)
    }


@cache
def import_graph() -> dict[str, Module]:
    """Every module of the package with its imports (see the module docstring)."""
    known = _module_names()
    graph: dict[str, Module] = {}
    for name, (path, is_package) in known.items():
        mod = Module(name, path, is_package)
        package = name if is_package else name.rpartition(".")[0]
        tree = ast.parse(path.read_text(encoding="utf-8"))
        frames = _to_frame_nodes(tree)
        for node in _nodes(tree):
            if isinstance(node, ast.Import):
                for a in node.names:
                    if id(node) in frames and a.name == "pandas":
                        continue  # a result's to_frame(): the table the user asked for
                    mod.imports.append(Import(node.lineno, _resolve(a.name, known), (), a.asname))
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = package.split(".")
                    parts = parts[: len(parts) - (node.level - 1)]
                    base = ".".join([*parts, base] if base else parts)
                for a in node.names:
                    sub = f"{base}.{a.name}"
                    if sub in known:  # `from package import submodule`
                        mod.imports.append(Import(node.lineno, sub, (), a.asname or a.name))
                    else:
                        target = _resolve(base, known)
                        mod.imports.append(Import(node.lineno, target, (a.name,)))
            elif isinstance(node, ast.Call) and (lit := _literal_import(node)):
                mod.imports.append(Import(node.lineno, _resolve(lit, known)))
        graph[name] = mod
    return graph


def _edges(graph: dict[str, Module]) -> dict[str, dict[str, int]]:
    """module → {imported thermocal module: first line}."""
    out: dict[str, dict[str, int]] = {}
    for name, mod in graph.items():
        out[name] = {}
        for imp in mod.imports:
            if imp.target in graph and imp.target != name:
                out[name].setdefault(imp.target, imp.line)
    return out


def find_cycle(edges: dict[str, dict[str, int]]) -> list[str] | None:
    """One import circle ``[a, b, …, a]`` (depth-first search), or None."""
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    stack: list[str] = []

    def visit(v: str) -> list[str] | None:
        state[v] = 1
        stack.append(v)
        for w in sorted(edges[v]):
            if state.get(w) == 1:
                return [*stack[stack.index(w) :], w]
            if w not in state and (found := visit(w)):
                return found
        stack.pop()
        state[v] = 2
        return None

    for v in sorted(edges):
        if v not in state and (found := visit(v)):
            return found
    return None


def _in(name: str, prefixes: tuple[str, ...]) -> bool:
    return any(name == p or name.startswith(p + ".") for p in prefixes)


def maths_modules() -> list[str]:
    graph = import_graph()
    out = [m for m in MATHS_MODULES if m in graph]
    out += [
        m
        for m in graph
        if _in(m, MATHS_PACKAGES)
        and not _in(m, MODEL_FILE_MODULES)
        and m not in FACADES
        and m not in out
    ]
    return sorted(out)


def _path_to_file_layer(start: str) -> list[str] | None:
    """The shortest import chain from ``start`` to a file-layer module, or None."""
    graph = import_graph()
    parent: dict[str, str | None] = {start: None}
    queue = [start]
    while queue:
        v = queue.pop(0)
        targets = sorted({imp.target for imp in graph[v].imports} - {v})
        for t in targets:
            if t in parent:
                continue
            parent[t] = v
            if _in(t, FILE_LAYER):
                chain = [t]
                while (p := parent[chain[-1]]) is not None:
                    chain.append(p)
                return chain[::-1]
            if t in graph:
                queue.append(t)
    return None


# --- 1. no circle ---------------------------------------------------------------------------


def test_the_graph_sees_every_kind_of_import() -> None:
    """The graph builder itself: function-level imports and lazy modules are arrows,
    ``TYPE_CHECKING`` imports are not (checked on modules whose imports are known)."""
    edges = _edges(import_graph())
    assert "thermocal.readers.dispatch" in edges["thermocal"]  # inside __getattr__
    assert "thermocal.pipeline.model_file" in edges["thermocal.pipeline.validate"]  # in a function
    graph = import_graph()
    assert "pandas" in {i.target for i in graph["thermocal.readers.common"].imports}  # Lazy
    assert len(edges) == len(list(SRC.rglob("*.py")))


def test_no_import_circle() -> None:
    cycle = find_cycle(_edges(import_graph()))
    assert cycle is None, "import circle: " + " -> ".join(cycle or [])


def test_a_circle_is_found() -> None:
    edges = {"a": {"b": 1}, "b": {"c": 1}, "c": {"a": 1}, "d": {"a": 1}}
    assert find_cycle(edges) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b": 1}, "b": {}}) is None


# --- 2. the maths imports no file layer -----------------------------------------------------


def test_the_maths_list_is_the_layout() -> None:
    mods = maths_modules()
    assert "thermocal.models.poly" in mods and "thermocal.turntable.thermal" in mods
    assert "thermocal.pipeline.model_file" not in mods and len(mods) > 40


@pytest.mark.parametrize("module", maths_modules())
def test_maths_module_reaches_no_file_layer_statically(module: str) -> None:
    chain = _path_to_file_layer(module)
    assert chain is None, f"{module} imports the file layer: {' -> '.join(chain or [])}"


@pytest.mark.parametrize("module", [*maths_modules(), *FACADES, *LIGHT_MODULES])
def test_maths_module_loads_no_file_layer(module: str) -> None:
    forbidden = FILE_LAYER if module in maths_modules() else LIGHT_FORBIDDEN
    code = (
        f"import sys, {module}\n"
        f"bad = {forbidden!r}\n"
        "print(','.join(sorted({b for m in sys.modules for b in bad "
        "if m == b or m.startswith(b + '.')})))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"{module} loads {out.stdout.strip()}"


def test_the_file_functions_are_still_reachable_from_the_package() -> None:
    import thermocal.pipeline.model_file

    assert callable(thermocal.read_recording) and callable(thermocal.write_recording)
    assert thermocal.load_model is thermocal.pipeline.model_file.load_model
    assert thermocal.save_model is thermocal.pipeline.model_file.save_model
    with pytest.raises(AttributeError):
        _ = thermocal.no_such_thing


# --- 3. the CLI on top ----------------------------------------------------------------------


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _cli_private_uses(mod: Module) -> list[str]:
    """Private names of non-CLI thermocal modules that a CLI module uses: imported by name,
    a private module, or an attribute ``alias._name`` of a module imported under ``alias``
    (``import thermocal.x as alias`` / ``alias = LazyModule("thermocal.x")``)."""
    out = []
    aliases: set[str] = set()
    for imp in mod.imports:
        if not imp.target.startswith("thermocal") or _in(imp.target, (CLI,)):
            continue
        if imp.target not in CLI_INFRASTRUCTURE and any(_private(p) for p in imp.target.split(".")):
            out.append(f"{mod.name}:{imp.line} imports the private module {imp.target}")
        out += [f"{mod.name}:{imp.line} imports {imp.target}.{n}" for n in imp.names if _private(n)]
        if imp.alias:
            aliases.add(imp.alias)
    tree = ast.parse(mod.path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):  # alias = LazyModule("thermocal.x")
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
            lit = _literal_import(node.value)
            if lit and lit.startswith("thermocal") and not _in(lit, (CLI,)):
                aliases |= {t.id for t in node.targets if isinstance(t, ast.Name)}
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id in aliases
            and _private(node.attr)
        ):
            out.append(f"{mod.name}:{node.lineno} uses {node.value.id}.{node.attr}")
    return out


def test_the_cli_uses_only_public_names_of_the_library() -> None:
    graph = import_graph()
    bad = [u for m in sorted(graph) if _in(m, (CLI,)) for u in _cli_private_uses(graph[m])]
    assert not bad, "the CLI uses private names of the library:\n" + "\n".join(bad)


def test_nothing_below_the_cli_imports_it() -> None:
    graph = import_graph()
    bad = [
        f"{m}:{imp.line} imports {imp.target}"
        for m in sorted(graph)
        if not _in(m, (CLI, "thermocal.__main__"))  # ``python -m thermocal`` runs the CLI
        for imp in graph[m].imports
        if _in(imp.target, (CLI,))
    ]
    assert not bad, "modules below the CLI import it:\n" + "\n".join(bad)


def test_the_private_name_check_sees_its_three_forms(tmp_path: Path) -> None:
    p = tmp_path / "x.py"
    p.write_text(
        "from thermocal.models.base import _jsonify, checksum\n"
        "import thermocal.models.base as base\n"
        "from thermocal._lazy import LazyModule\n"
        "fit = LazyModule('thermocal.models.poly')\n"
        "base._canonical({})\nfit._plan\nfit.PolyModel\n"
    )
    mod = Module(
        "thermocal.cli.x",
        p,
        False,
        [
            Import(1, "thermocal.models.base", ("_jsonify", "checksum")),
            Import(2, "thermocal.models.base", (), "base"),
            Import(3, "thermocal._lazy", ("LazyModule",)),
            Import(4, "thermocal.models.poly"),
        ],
    )
    uses = _cli_private_uses(mod)
    assert sorted(u.split(" ", 1)[1] for u in uses) == [
        "imports thermocal.models.base._jsonify",
        "uses base._canonical",
        "uses fit._plan",
    ]


# --- 4. small functions ---------------------------------------------------------------------

LONGEST_FUNCTION_LINES = 100
"""Issue 27: no function of 100 lines or more (signature and docstring counted)."""


def long_functions(root: Path, limit: int = LONGEST_FUNCTION_LINES) -> list[str]:
    """``file:function (n lines)`` of every function or method of ``limit`` lines or more."""
    out = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                n = (node.end_lineno or node.lineno) - node.lineno + 1
                if n >= limit:
                    out.append(f"{path.relative_to(root)}:{node.name} ({n} lines)")
    return out


def test_no_function_reaches_100_lines() -> None:
    assert long_functions(SRC) == []


def test_the_length_check_sees_a_long_function(tmp_path: Path) -> None:
    body = "".join(f"    x{i} = {i}\n" for i in range(98))
    (tmp_path / "m.py").write_text(f"def short():\n    pass\n\n\ndef long():\n{body}    return 0\n")
    assert long_functions(tmp_path) == ["m.py:long (100 lines)"]


def test_the_drawn_structure_has_every_room_placed_and_no_arrow_up() -> None:
    """``scripts/import_graph.py`` (ARCHITECTURE.md's drawing command) places every module
    in a layer and finds no circle and no arrow that climbs a layer."""
    script = Path(__file__).resolve().parents[2] / "scripts" / "import_graph.py"
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, check=False)
    problems = [
        ln for ln in out.stdout.splitlines() if ln.startswith(("UPWARD", "CIRCLE", "UNPLACED"))
    ]
    assert (out.returncode, problems) == (0, [])
