"""The plain option conversion (thermocal.cli.coercion) against typer's own, on every option of
every command: the same value (and type) for every input, or the same error message.

typer ≥ 0.28 converts through pydantic; the plain conversion must be indistinguishable from it,
and must leave pydantic unimported on a command's ordinary run."""

import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

coercion_mod = pytest.importorskip("typer._coercion", reason="typer < 0.28: click converts")

import thermocal.cli as cli  # noqa: E402
from thermocal.cli import coercion  # noqa: E402

TEXT = ["0", "7", "-3", "+5", "007", "1_000", " 5", "5 ", "5.0", "1e3", "-0", "", "abc",
        "99999999999999999999", "999999999999999999", "١٢", "0.95", "-2.5", ".5", "5.", "1e-3",
        "1E+300", "1e400", "1e-400", "inf", "-inf", "nan", "NaN", "1_0.5", "0x10", "-.5",
        "00.5", "1.5e", "e5", "--", "-", "a.csv", "a//b/", "dir/x.parquet", "ü", "x\x00y",
        "true", "no"]  # fmt: skip
"""Inputs a user can type, each tried on every option."""

OTHER: list[Any] = [None, True, False, 0, 1, 2.5, -1.0]
"""Values that reach the conversion from defaults and flags."""


def _params() -> list[tuple[str, Any, Any]]:
    cli._register()
    group = cli._click_command()
    out = []

    def walk(cmd: Any, name: str) -> None:
        for p in cmd.params:
            if getattr(p, "type_descriptor", None) is not None:
                out.append((f"{name} {p.name}", cmd, p))
        for sub_name, sub in getattr(cmd, "commands", {}).items():
            walk(sub, f"{name} {sub_name}".strip())

    walk(group, "")
    return out


def _outcome(runtime: Any, value: Any, param: Any, ctx: Any) -> tuple[str, Any]:
    try:
        got = runtime.coerce(value, param=param, ctx=ctx)
    except Exception as exc:  # typer's BadParameter (or any other error) compared by text
        return "error", (type(exc).__name__, str(exc))
    if isinstance(got, float) and math.isnan(got):
        return "value", ("nan", float)
    if isinstance(got, (list, tuple)):
        return "value", (type(got), [(type(g), g) for g in got])
    return "value", (type(got), got)


def _values(param: Any, tmp_path: Path) -> list[Any]:
    existing = [str(tmp_path / "f.csv"), str(tmp_path), str(tmp_path / "f.csv") + "/"]
    singles: list[Any] = [*TEXT, *existing, *OTHER]
    if param.multiple or param.nargs == -1:
        return [("a", "b"), ("1", "2.5"), (existing[0], "x.csv"), ("a", ""), (), ["5", "inf"]]
    return singles


def test_every_option_converts_as_typer_does(tmp_path: Path) -> None:
    (tmp_path / "f.csv").write_text("t,x\n0,1\n")
    build = coercion_mod.build_runtime_param
    params = _params()
    assert len(params) > 400  # every option of every command
    from typer._click import Context

    checked = plain = 0
    for label, cmd, param in params:
        context = Context(cmd)
        ours = param._runtime_param
        theirs = build(param.type_descriptor)
        for value in _values(param, tmp_path):
            if value is None and param.required:
                continue
            want = _outcome(theirs, value, param, context)
            got = _outcome(ours, value, param, context)
            assert got == want, (label, value)
            checked += 1
        plain += type(ours).__name__ == "_PlainRuntimeParam"
    assert plain == len(params)
    assert checked > 20_000


def test_plain_conversions_known_values() -> None:
    # Python's own conversions, written here: what a user's text means.
    assert coercion._plain_leaf(int, "-12") == -12
    assert coercion._plain_leaf(float, "1e-3") == 0.001
    assert coercion._plain_leaf(float, "5.") == 5.0
    assert coercion._plain_leaf(Path, "a//b/") == Path("a/b")
    assert coercion._plain_leaf(int, "+5") is coercion._UNDECIDED  # typer decides
    assert coercion._plain_leaf(float, "inf") is coercion._UNDECIDED
    assert coercion._plain_leaf(Path, "") is coercion._UNDECIDED


def test_a_run_does_not_import_pydantic(tmp_path: Path) -> None:
    data = tmp_path / "r.csv"
    rows = "\n".join(f"{0.01 * i:.2f},{(i * 7919) % 13 - 6}" for i in range(3000))
    data.write_text("time [s],rate [deg/h]\n" + rows + "\n")
    code = (
        "import sys; from thermocal.cli import main; "
        f"s = main(['allan', {str(data)!r}, '--signal', 'rate [deg/h]', '--json', "
        "'--confidence', '0.9', '--time', 'time [s]']); "
        "print(s, 'pydantic' in sys.modules, file=sys.stderr)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stderr.strip().splitlines()[-1] == "0 False"


def test_bad_number_keeps_typer_message(tmp_path: Path) -> None:
    data = tmp_path / "r.csv"
    data.write_text("time [s],rate [deg/h]\n0,1\n0.01,2\n")
    code = (
        "import sys; from thermocal.cli import main; "
        f"sys.exit(main(['allan', {str(data)!r}, '--signal', 'rate [deg/h]', "
        "'--confidence', 'abc']))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: Invalid value for '--confidence'")
