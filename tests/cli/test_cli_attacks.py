"""Hostile input through the command line (issue 14): one row per attack, generated here.

Every attack builds its files from a good recording and a good model, runs one command
in-process and checks the contract of INTERFACE.md:

* the exit status is one of those allowed (never 1: anything a user can cause is 2);
* exit 2 ends with one ``error: ...`` line on stderr containing the expected words;
* where a command may go on (exit 0), it must say what was doubtful in a ``warning:`` line
  containing the expected words: no silent number;
* no input file (data, sidecar, model) changed, byte for byte;
* no temporary output is left behind.

The attack classes follow the audit: broken CSV, numeric pathologies, unit confusion,
mismatched or corrupt model files, corrupt Parquet, wrong file types, bad output paths.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.cli import main
from thermocal.outputs import TEMP_SUFFIX

N = 600
"""Rows of the good recording: 600 s at 1 Hz, a temperature ramp 10 → 40 °C."""


def _good_frame(n: int = N) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(12)
    t = np.arange(n, dtype=float)
    temp = 10.0 + 30.0 * t / max(n - 1, 1)
    gyro = 0.5 + 0.02 * (temp - 25.0) + rng.normal(0.0, 0.01, n)
    return {"time": t, "gyro": gyro, "T1": temp}


def _csv(cols: dict[str, np.ndarray]) -> bytes:
    names = list(cols)
    lines = [",".join(names)]
    for row in zip(*(cols[c] for c in names), strict=True):
        lines.append(",".join("" if np.isnan(v) else repr(float(v)) for v in row))
    return ("\n".join(lines) + "\n").encode()


GOOD_CSV = _csv(_good_frame())
UNITS = ["--signal-unit", "deg/h", "--time-unit", "s", "--temp-unit", "degC"]
"""Stated explicitly, so that only the attack under test is doubtful."""


@dataclass(frozen=True)
class Attack:
    """One hostile run: files to write, the command line, what the contract allows."""

    id: str
    files: dict[str, bytes]
    argv: list[str]
    allowed: frozenset[int]
    words: str
    """Expected in the ``error:`` line (exit 2) or in a ``warning:`` line (exit 0)."""
    needs_model: bool = False
    setup: Callable[[Path], None] | None = field(default=None, compare=False)


def _model_bytes(tmp: Path) -> bytes:
    src = tmp / "fit.csv"
    src.write_bytes(GOOD_CSV)
    out = tmp / "m.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(["fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
                     "--temps", "T1", "-o", str(out), *UNITS])  # fmt: skip
    assert code == 0
    return out.read_bytes()


# --- the attack table ---------------------------------------------------------------------

DATA_COMMANDS: dict[str, list[str]] = {
    "inspect": ["inspect", "{data}", "--signal", "gyro", "--temps", "T1", *UNITS],
    "metrics": ["metrics", "{data}", "--signal", "gyro", "--temps", "T1", *UNITS],
    "allan": ["allan", "{data}", "--signal", "gyro", *UNITS[:4]],
    "fit": ["fit", "{data}", "--model", "poly", "--order", "1", "--signal", "gyro", "--temps",
            "T1", "-o", "{out}.json", *UNITS],
    "compensate": ["compensate", "{model}", "{data}", "-o", "{out}.csv", *UNITS],
    "validate": ["validate", "{model}", "{data}", *UNITS],
}  # fmt: skip
"""Commands that read a recording (the model, where needed, is the good one)."""

E2 = frozenset({2})
E0 = frozenset({0})
E0_OR_2 = frozenset({0, 2})


def _broken_csv() -> list[tuple[str, bytes, frozenset[int], str]]:
    """(name, content, allowed exits, words) of broken CSV files."""
    good = GOOD_CSV.decode()
    lines = good.splitlines()
    ragged = "\n".join([*lines[:100], lines[100] + ",7,8", *lines[101:]]) + "\n"
    text_cell = "\n".join([*lines[:50], "49,abc,20", *lines[51:]]) + "\n"
    return [
        ("empty", b"", E2, "empty"),
        ("header-only", b"time,gyro,T1\n", E2, "no data rows"),
        ("ragged-row", ragged.encode(), E2, "line"),
        ("text-cell", text_cell.encode(), E2, "row"),
        ("binary-junk", bytes(range(256)) * 8, E2, ""),
        ("utf16", good.encode("utf-16"), E2, "UTF-16"),
        ("missing-signal-column", good.replace("gyro", "gyr0").encode(), E2, "gyro"),
        ("missing-temp-column", good.replace("T1", "Tx").encode(), E2, "T1"),
        ("missing-time-column", good.replace("time", "tyme").encode(), E2, "time"),
        ("only-whitespace", b"   \n\n  \n", E2, ""),
        # issue 16: other delimiters are read, and said (INTERFACE: detected or given)
        ("semicolons-unannounced", good.replace(",", ";").encode(), E0, "';'-separated"),
    ]


def _numeric() -> list[tuple[str, bytes, frozenset[int], str]]:
    f = _good_frame()
    out: list[tuple[str, bytes, frozenset[int], str]] = []

    def edit(name: str, allowed: frozenset[int], words: str, **cols: np.ndarray) -> None:
        out.append((name, _csv({**f, **cols}), allowed, words))

    g = f["gyro"].copy()
    g[10] = np.nan
    edit("nan-signal", E2, "NaN", gyro=g)
    g = f["gyro"].copy()
    g[10] = np.inf
    edit("inf-signal", E2, "", gyro=g)
    tt = f["T1"].copy()
    tt[10] = np.nan
    edit("nan-temperature", E2, "NaN", T1=tt)
    t = f["time"].copy()
    t[200] = t[199]
    edit("duplicate-time", E2, "duplicate", time=t)
    t = f["time"].copy()
    t[200] = t[198]
    edit("backwards-time", E2, "backwards", time=t)
    t = f["time"].copy()
    t[5] = np.nan
    edit("nan-time", E2, "time", time=t)
    edit("huge-signal", E2, "", gyro=f["gyro"] * 1e300)
    edit("kelvin-temperature", E0_OR_2, "°C", T1=f["T1"] + 273.15)
    edit("temperature-5000", E0_OR_2, "°C", T1=f["T1"] + 5000.0)
    edit("below-absolute-zero", E2, "absolute zero", T1=f["T1"] - 400.0)
    edit("raw-counts-as-celsius", E0_OR_2, "counts", T1=np.round(f["T1"] * 16.0 + 64000.0))
    for n_rows in (1, 2):
        small = {k: v[:n_rows] for k, v in f.items()}
        out.append((f"{n_rows}-rows", _csv(small), E0_OR_2, "sample"))
    const = f["T1"].copy()
    const[:] = 25.0
    edit("constant-temperature", E0_OR_2, "constant", T1=const)
    return out


def _data_attacks() -> list[Attack]:
    attacks = []
    for cls, rows in (("csv", _broken_csv()), ("numeric", _numeric())):
        for name, content, allowed, words in rows:
            for cmd, argv in DATA_COMMANDS.items():
                if cmd == "allan" and ("temp" in name or "celsius" in name or "zero" in name):
                    continue  # allan reads no temperature
                if name == "constant-temperature" and cmd in ("compensate", "validate"):
                    continue  # a unit held at one temperature is a fine thing to compensate
                a = allowed
                attacks.append(
                    Attack(
                        id=f"{cls}/{name}/{cmd}",
                        files={"data.csv": content},
                        argv=argv,
                        allowed=a,
                        words=words,
                        needs_model=cmd in ("compensate", "validate"),
                    )
                )
    return attacks


def _unit_attacks() -> list[Attack]:
    rows: list[tuple[str, list[str], frozenset[int], str]] = [
        ("unknown-signal-unit", ["--signal-unit", "rpm"], E2, "rpm"),
        ("unknown-time-unit", ["--time-unit", "fortnights"], E2, "fortnights"),
        ("unknown-temp-unit", ["--temp-unit", "kelvinish"], E2, "kelvinish"),
        ("accel-unit-on-gyro-model", ["--signal-unit", "mg"], E2, "mg"),
    ]
    out = []
    for name, opts, allowed, words in rows:
        for cmd in ("metrics", "allan", "fit", "compensate", "validate"):
            argv = [a for a in DATA_COMMANDS[cmd]]
            # replace the option's default value with the attack's
            flag, value = opts
            if flag in argv:
                argv[argv.index(flag) + 1] = value
            else:
                argv += opts
            if name == "accel-unit-on-gyro-model" and cmd not in ("compensate", "validate"):
                continue  # mg is a fine unit for a recording on its own
            if name == "unknown-temp-unit" and cmd == "allan":
                continue  # allan reads no temperature
            out.append(
                Attack(
                    id=f"units/{name}/{cmd}",
                    files={"data.csv": GOOD_CSV},
                    argv=argv,
                    allowed=allowed,
                    words=words,
                    needs_model=cmd in ("compensate", "validate"),
                )
            )
    return out


def _corrupt_models(good: dict[str, object]) -> list[tuple[str, bytes, str]]:
    """(name, content, words) of model files that must be refused."""

    def dump(d: object) -> bytes:
        return json.dumps(d).encode()

    def with_checksum(d: dict[str, object]) -> bytes:
        from thermocal.models.format import checksum

        d = dict(d)
        d.pop("checksum", None)
        d["checksum"] = checksum(d)
        return dump(d)

    def state_edit(fn: Callable[[dict[str, Any]], None]) -> dict[str, object]:
        d = json.loads(json.dumps(good))
        fn(d["state"])  # type: ignore[arg-type]
        return d

    out = [
        ("not-json", b"{this is not json", "JSON"),
        ("json-array", b"[1, 2, 3]", "not a thermocal model"),
        ("empty-object", b"{}", "not a thermocal model"),
        ("newer-version", dump({**good, "format_version": 999}), "newer"),
        ("edited-by-hand", dump({**good, "family": "piecewise"}), "checksum"),
        ("no-checksum", dump({k: v for k, v in good.items() if k != "checksum"}), "checksum"),
        ("unknown-family", with_checksum({**good, "family": "magic"}), "magic"),
        ("binary", bytes(range(256)), "model"),
    ]
    # the poly family's state (models/poly.py docstring): the fields the prediction needs
    for key in ("base", "terms", "coef", "constant"):
        out.append(
            (f"state-missing-{key}", with_checksum(state_edit(lambda s, k=key: s.pop(k))), key)
        )
    edits: list[tuple[str, Callable[[dict[str, Any]], None]]] = [
        ("string-coefficients", lambda s: s.__setitem__("coef", ["a"])),
        ("coefficients-truncated", lambda s: s.__setitem__("coef", [])),
        ("coefficients-extra", lambda s: s.__setitem__("coef", [1.0, 2.0, 3.0])),
        ("null-coefficients", lambda s: s.__setitem__("coef", [None])),
        ("zero-scale", lambda s: s["base"][0].__setitem__("t_scale", 0.0)),
        ("string-constant", lambda s: s.__setitem__("constant", "0.4")),
        ("term-of-missing-sensor", lambda s: s["terms"][0].__setitem__("sensor", 3)),
    ]
    words = {
        "zero-scale": "t_scale",
        "string-constant": "constant",
        "term-of-missing-sensor": "sensor",
    }
    for name, fn in edits:
        out.append((name, with_checksum(state_edit(fn)), words.get(name, "coef")))
    reversed_range = {"temperature_c": {"T1": [40.0, 10.0]}, "rate_c_per_min": None}
    out.append(("range-reversed", with_checksum({**good, "range": reversed_range}), "range"))
    signal = dict(good["signal"])  # type: ignore[call-overload]
    signal["unit"] = "furlongs"
    out.append(("unknown-signal-unit", with_checksum({**good, "signal": signal}), "furlongs"))
    out.append(
        (
            "missing-signal",
            with_checksum({k: v for k, v in good.items() if k != "signal"}),
            "signal",
        )
    )
    return out


MODEL_COMMANDS: dict[str, list[str]] = {
    "compensate": ["compensate", "{model}", "{data}", "-o", "{out}.csv", *UNITS],
    "validate": ["validate", "{model}", "{data}", *UNITS],
    "export-c": ["export-c", "{model}", "-o", "{out}"],
}


def _parquet_bytes(table: pa.Table) -> bytes:
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink, write_page_checksum=True)
    return bytes(sink.getvalue().to_pybytes())


def _overwritten_parquet() -> bytes:
    """A good Parquet file (with page checksums) with 2.8 kB overwritten in its data."""
    raw = bytearray(_parquet_bytes(pa.table(_good_frame(20_000))))
    mid = len(raw) // 3
    raw[mid : mid + 2800] = bytes((i * 37) % 256 for i in range(2800))
    return bytes(raw)


def _text_column_parquet() -> bytes:
    f = _good_frame()
    return _parquet_bytes(pa.table({**f, "gyro": [f"{v:.3f} dph" for v in f["gyro"]]}))


def _file_type_attacks() -> list[Attack]:
    rows = [
        ("xlsx-extension", "data.xlsx", b"time,gyro,T1\n0,1,2\n", "not a CSV or Parquet"),
        ("parquet-extension-on-csv", "data.parquet", GOOD_CSV, "Parquet"),
        ("csv-extension-on-parquet", "data.csv", b"PAR1" + b"\x00" * 64 + b"PAR1", ""),
        ("truncated-parquet", "data.parquet", b"PAR1\x15\x04", "Parquet"),
        ("partial-output", f"data.csv{TEMP_SUFFIX}", GOOD_CSV, "unfinished output"),
        ("overwritten-parquet", "data.parquet", _overwritten_parquet(), "checksum"),
        ("text-in-parquet-column", "data.parquet", _text_column_parquet(), "numeric"),
    ]
    out = []
    for name, fname, content, words in rows:
        for cmd, argv in DATA_COMMANDS.items():
            out.append(
                Attack(
                    id=f"filetype/{name}/{cmd}",
                    files={fname: content},
                    argv=[a.replace("{data}", "{" + fname + "}") for a in argv],
                    allowed=E2,
                    words=words,
                    needs_model=cmd in ("compensate", "validate"),
                )
            )
    return out


def _output_attacks() -> list[Attack]:
    rows = [
        ("output-is-input", ["fit", "{data}", "--model", "poly", "--order", "1", "--signal",
                             "gyro", "--temps", "T1", "-o", "{data}", *UNITS], "input"),
        ("output-is-directory", ["fit", "{data}", "--model", "poly", "--order", "1", "--signal",
                                 "gyro", "--temps", "T1", "-o", "{dir}", *UNITS], "directory"),
        ("output-under-a-file", ["fit", "{data}", "--model", "poly", "--order", "1", "--signal",
                                 "gyro", "--temps", "T1", "-o", "{data}/m.json", *UNITS],
         "not a directory"),
        ("compensate-over-input", ["compensate", "{model}", "{data}", "-o", "{data}", *UNITS],
         "input"),
        ("compensate-over-model", ["compensate", "{model}", "{data}", "-o", "{model}", *UNITS],
         ""),
        ("compensate-over-sidecar", ["compensate", "{model}", "{data}", "-o",
                                     "{data}.meta.json", *UNITS], ""),
        ("profile-into-directory", ["profile", "fog-slow", "-o", "{dir}"], "adir"),
        ("allan-plot-over-input", ["allan", "{data}", "--signal", "gyro", "--plot", "{data}",
                                   *UNITS[:4]], ""),
    ]  # fmt: skip
    return [
        Attack(
            id=f"output/{name}",
            files={"data.csv": GOOD_CSV, "data.csv.meta.json": b"{}"}
            if "sidecar" in name
            else {"data.csv": GOOD_CSV},
            argv=argv,
            allowed=E2,
            words=words,
            needs_model=True,
        )
        for name, argv, words in rows
    ]


KNOWN_GAPS: frozenset[str] = frozenset({})
"""Attacks that still end wrongly (exit 0 without a warning, or exit 1): strict xfails, so
that each one fixed turns red here until it is taken off this list (issue 14)."""


def all_attacks(good_model: dict[str, object]) -> list[Attack]:
    attacks = _data_attacks() + _unit_attacks() + _file_type_attacks() + _output_attacks()
    for name, content, words in _corrupt_models(good_model):
        for cmd, argv in MODEL_COMMANDS.items():
            attacks.append(
                Attack(
                    id=f"model/{name}/{cmd}",
                    files={"data.csv": GOOD_CSV, "model.json": content},
                    argv=argv,
                    allowed=E2,
                    words=words,
                )
            )
    return attacks


# --- running them -------------------------------------------------------------------------


@pytest.fixture(scope="session")
def good_model_bytes(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    return _model_bytes(tmp_path_factory.mktemp("attack-model"))


def _template_model() -> dict[str, object]:
    """The good model's dict, built once at collection (the table needs its keys)."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        return dict(json.loads(_model_bytes(Path(d))))


ATTACKS = all_attacks(_template_model())


def test_the_table_covers_the_audit() -> None:
    """At least the 259 attacks of the audit, every class represented."""
    assert len(ATTACKS) >= 259, len(ATTACKS)
    classes = {a.id.split("/")[0] for a in ATTACKS}
    assert classes == {"csv", "numeric", "units", "filetype", "output", "model"}
    assert len({a.id for a in ATTACKS}) == len(ATTACKS)


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "dir"


@pytest.mark.parametrize(
    "attack",
    [
        pytest.param(
            a,
            id=a.id,
            marks=[pytest.mark.xfail(strict=True, reason="known gap, issue 14")]
            if a.id in KNOWN_GAPS
            else [],
        )
        for a in ATTACKS
    ],
)
def test_attack(
    attack: Attack,
    tmp_path: Path,
    good_model_bytes: bytes,
    capsys: pytest.CaptureFixture[str],
) -> None:
    paths: dict[str, str] = {}
    for name, content in attack.files.items():
        (tmp_path / name).write_bytes(content)
        paths[name] = str(tmp_path / name)
    if "model.json" not in attack.files:
        (tmp_path / "model.json").write_bytes(good_model_bytes)
    (tmp_path / "adir").mkdir()
    data_name = next((n for n in attack.files if n.startswith("data")), "data.csv")
    subst = {
        "{data}": str(tmp_path / data_name),
        "{model}": str(tmp_path / "model.json"),
        "{out}": str(tmp_path / "out"),
        "{dir}": str(tmp_path / "adir"),
        **{"{" + n + "}": p for n, p in paths.items()},
    }
    argv = []
    for a in attack.argv:
        for k, v in subst.items():
            a = a.replace(k, v)
        argv.append(a)
    before = {p: _digest(p) for p in tmp_path.iterdir()}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numerical warnings reach stderr as warning: lines
        code = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    assert code in attack.allowed, f"exit {code}; stderr: {err}"
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if code == 2:
        assert lines and lines[-1].startswith("error: "), err
        assert attack.words in lines[-1], lines[-1]
        assert "internal" not in lines[-1]
    elif attack.words:
        warned = any(ln.startswith("warning: ") and attack.words in ln for ln in lines)
        # inspect's findings are its output (stdout), the others warn on stderr
        found = argv[0] == "inspect" and attack.words in out
        assert warned or found, err
    after = {p: _digest(p) for p in before}
    assert after == before, "an input file changed"
    assert not list(tmp_path.glob(f"**/*{TEMP_SUFFIX}")) or attack.id.startswith("filetype/partial")
