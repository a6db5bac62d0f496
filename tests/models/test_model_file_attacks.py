"""Hostile model and calibration files through every command that reads one (issue 26).

Real files are made here by ``thermocal fit`` (poly, piecewise, warmup, bank, hyst and a
three-channel calibration) and by ``thermocal turntable`` over temperature (a calibration
of triads), then mutated: NaN/Infinity/1e309 literals, 100 000-deep nesting, 5000-digit
integers, empty and 2-D coefficients, a singular (I + E), a NaN or far TREF, wrong types,
missing keys and a file over the size limit.  Mutations that leave valid JSON are re-signed
(the checksum is recomputed here, as SPEC §8 defines it: SHA-256 of the canonical JSON
without the ``checksum`` key, a calibration's after its channels'), so that the attack
reaches the content checks rather than the checksum check.

Every command that takes a model file (compensate, validate, export-c, export-params,
report) must end each attack in exit 2 with one ``error: FILE: ...`` line naming the key
path, never exit 1 or a traceback, write nothing, and leave its inputs byte for byte.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from thermocal.cli import main
from thermocal.families import MODEL_FAMILIES

COMMANDS: dict[str, list[str]] = {
    "compensate": ["compensate", "{m}", "{d}", "-o", "{o}/comp.csv"],
    "validate": ["validate", "{m}", "{d}"],
    "export-c": ["export-c", "{m}", "-o", "{o}/c"],
    "export-params": ["export-params", "{m}", "--format", "px4", "-o", "{o}/tc.params"],
    "report": ["report", "--model", "{m}", "--recording", "{d}", "-o", "{o}/report.html"],
}
KINDS = (*MODEL_FAMILIES, "calibration", "triads")
"""Every registered model family (thermocal.families.MODEL_FAMILIES), and the calibrations."""

UNITS = ["--time-unit", "s", "--temp-unit", "degC"]


def _run(argv: list[str]) -> int:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return main(argv)


def _ramp_csv(path: Path) -> None:
    """1200 s at 1 Hz, T1 from −10 to +50 °C; three gyros [deg/s] with a cubic bias."""
    rng = np.random.default_rng(3)
    t = np.arange(1200, dtype=float)
    temp = -10.0 + 60.0 * t / t[-1]
    lines = ["time_s,gyro_x,gyro_y,gyro_z,T1"]
    cols = [
        k * 0.01 + 2e-4 * (temp - 20) + 1e-6 * (temp - 20) ** 2 + rng.normal(0, 1e-4, t.size)
        for k in (1, -1, 2)
    ]
    for i in range(t.size):
        lines.append(
            ",".join([f"{t[i]:.0f}", *(repr(float(c[i])) for c in cols), repr(float(temp[i]))])
        )
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def originals(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[bytes, Path]]:
    """Each kind's model file (bytes) and a recording the commands can read with it."""
    d = tmp_path_factory.mktemp("model-files")
    out: dict[str, tuple[bytes, Path]] = {}
    ramp = d / "ramp.csv"
    _ramp_csv(ramp)
    fits = {
        "poly": ["--model", "poly", "--order", "3", "--signal", "gyro_x"],
        "piecewise": ["--model", "piecewise", "--segments", "2", "--signal", "gyro_x"],
        "hyst": ["--model", "hyst", "--order", "2", "--signal", "gyro_x"],
        "calibration": ["--model", "poly", "--order", "3", "--signal", "gyro_x,gyro_y,gyro_z"],
    }
    for kind, args in fits.items():
        unit = ["--signal-unit", ",".join(["deg/s"] * (args[-1].count(",") + 1))]
        f = d / f"{kind}.json"
        assert _run(["fit", str(ramp), *args, "--temps", "T1", "-o", str(f), *unit, *UNITS]) == 0
        out[kind] = (f.read_bytes(), ramp)
    assert _run(["simulate", "mems-warmup", "-o", str(d / "warm"), "--record-s", "600"]) == 0
    warm = sorted((d / "warm").glob("*.csv"))
    f = d / "warmup.json"
    assert _run(["fit", *map(str, warm), "--model", "warmup", "--signal", "gyro", "--temps",
                 "T1", "-o", str(f)]) == 0  # fmt: skip
    out["warmup"] = (f.read_bytes(), warm[0])
    assert _run(["simulate", "accel-full-range", "-o", str(d / "acc"), "--runs", "3",
                 "--rate-hz", "0.1"]) == 0  # fmt: skip
    acc = sorted((d / "acc").glob("*.csv"))
    f = d / "bank.json"
    assert _run(["fit", *map(str, acc), "--model", "bank", "--signal", "accel", "--temps",
                 "T1", "-o", str(f)]) == 0  # fmt: skip
    out["bank"] = (f.read_bytes(), acc[0])
    assert _run(["simulate", "turntable-thermal", "-o", str(d / "tt"), "--format", "parquet"]) == 0
    soaks = sorted(str(p) for p in (d / "tt").glob("*.parquet") if "heldout" not in p.name)
    held = next((d / "tt").glob("*heldout*.parquet"))
    f = d / "triads.json"
    assert _run(["turntable", *soaks, "--temps", "T_imu", "--accel", "accel_x,accel_y,accel_z",
                 "-o", str(f)]) == 0  # fmt: skip
    out["triads"] = (f.read_bytes(), held)
    return out


# --- the checksum, as SPEC §8 defines it (written here, not imported) ---------------------


def _sign(d: dict[str, Any]) -> None:
    body = {k: v for k, v in d.items() if k != "checksum"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=True,
                      allow_nan=False)  # fmt: skip
    d["checksum"] = hashlib.sha256(text.encode("ascii")).hexdigest()


def _resign(d: dict[str, Any]) -> None:
    for ch in d.get("channels") or []:
        if isinstance(ch, dict) and isinstance(ch.get("model"), dict):
            _sign(ch["model"])
    _sign(d)


# --- mutations ----------------------------------------------------------------------------

Path_ = tuple[str | int, ...]

MODEL_AT: dict[str, Path_] = {
    "poly": (),
    "piecewise": (),
    "warmup": (),
    "bank": (),
    "hyst": (),
    "calibration": ("channels", 0, "model"),
}
"""Where the (first) single-channel model sits in each kind's file."""

NUMBER_AT: dict[str, Path_] = {
    "poly": ("state", "constant"),
    "piecewise": ("state", "intercepts", 0),
    "warmup": ("state", "b", 0, 0),
    "bank": ("state", "models", 0, "values", 0),
    "hyst": ("state", "coefficients", 0),
    "calibration": ("channels", 0, "model", "state", "coef", 1),
    "triads": ("triads", 0, "model", "tref_c"),
}
"""A number each prediction uses."""

ARRAY_AT: dict[str, Path_] = {
    "poly": ("state", "coef"),
    "piecewise": ("state", "slopes"),
    "warmup": ("state", "b"),
    "bank": ("state", "models", 0, "values"),
    "hyst": ("state", "coefficients"),
    "calibration": ("channels", 1, "model", "state", "coef"),
    "triads": ("triads", 0, "model", "parameters", 0, "coefficients"),
}
"""A coefficient array each prediction uses."""


def _dotted(path: Path_) -> str:
    out = ""
    for k in path:
        out += f"[{k}]" if isinstance(k, int) else (f".{k}" if out else k)
    return out


def _get(d: Any, path: Path_) -> Any:
    for k in path:
        d = d[k]
    return d


def _set(d: Any, path: Path_, value: Any) -> None:
    _get(d, path[:-1])[path[-1]] = value


def _literal(kind: str, text: str) -> Callable[[dict[str, Any]], bytes]:
    """The file with the number at NUMBER_AT replaced by a JSON-invalid literal ``text``
    (NaN, Infinity...): no checksum can cover it, the reader must refuse it first."""

    def make(d: dict[str, Any]) -> bytes:
        _set(d, NUMBER_AT[kind], "@@MARK@@")
        return json.dumps(d).replace('"@@MARK@@"', text).encode()

    return make


def _edit(fn: Callable[[dict[str, Any]], None]) -> Callable[[dict[str, Any]], bytes]:
    """A structural edit of the parsed file, re-signed."""

    def make(d: dict[str, Any]) -> bytes:
        fn(d)
        _resign(d)
        return json.dumps(d, indent=1).encode()

    return make


@dataclass(frozen=True)
class Mutation:
    id: str
    make: Callable[[dict[str, Any]], bytes]
    words: str
    """Expected in the one ``error:`` line (the key path, or what is wrong)."""


LITERALS = {
    "nan": "NaN",
    "infinity": "Infinity",
    "minus-infinity": "-Infinity",
    "overflow": "1e309",
    "minus-overflow": "-1e309",
    "digits-5000": "9" * 5000,
}


def _model_mutations(kind: str) -> list[Mutation]:
    """Structural edits of a single-channel model (alone or a calibration's channel)."""
    at = MODEL_AT[kind]
    arr = ARRAY_AT[kind]
    arr_rel = _dotted(arr[len(at) :])

    def on_model(fn: Callable[[dict[str, Any]], None]) -> Callable[[dict[str, Any]], None]:
        return lambda d: fn(_get(d, at))

    temp = "T1"
    out = [
        Mutation("coefficients-empty", _edit(lambda d: _set(d, arr, [])), arr_rel),
        Mutation(
            "coefficients-2d",
            _edit(lambda d: _set(d, arr, [[v] for v in _get(d, arr)])),
            arr_rel,
        ),
        Mutation(
            "coefficient-string-nan",
            _edit(lambda d: _set(d, NUMBER_AT[kind], "NaN")),
            _dotted(NUMBER_AT[kind][len(at) :]),
        ),
        Mutation(
            "state-missing",
            _edit(on_model(lambda m: m.pop("state"))),
            "state",
        ),
        Mutation("state-a-list", _edit(on_model(lambda m: m.__setitem__("state", []))), "state"),
        Mutation(
            "range-reversed",
            _edit(on_model(lambda m: m["range"]["temperature_c"][temp].reverse())),
            _dotted((*at, "range", "temperature_c", temp)),
        ),
        Mutation(
            "range-strings",
            _edit(on_model(lambda m: m["range"]["temperature_c"].__setitem__(temp, ["a", "b"]))),
            "range.temperature_c",
        ),
        Mutation(
            "fit-string",
            _edit(on_model(lambda m: m["fit"].__setitem__("n_samples", "many"))),
            "fit.n_samples",
        ),
        Mutation(
            "inputs-units-number",
            _edit(on_model(lambda m: m["inputs"].__setitem__("units", 5))),
            "inputs.units",
        ),
        Mutation(
            "temperatures-numbers",
            _edit(on_model(lambda m: m.__setitem__("temperatures", [1]))),
            "temperatures",
        ),
        Mutation(
            "params-wrong-type",
            _edit(on_model(lambda m: m["params"].__setitem__(next(iter(m["params"])), [[]]))),
            "params.",
        ),
        Mutation(
            "signal-target-number",
            _edit(on_model(lambda m: m["signal"].__setitem__("target", 5))),
            "signal.target",
        ),
    ]
    if kind in ("poly", "calibration"):
        term = (*at, "state", "terms", 0)
        out.append(
            Mutation(
                "power-2-to-the-53",  # ran for ever in export-c before the bound
                _edit(lambda d: _set(d, (*term, "t_power"), 2**53)),
                _dotted((*term, "t_power")),
            )
        )
        out.append(
            Mutation(
                "center-far-from-range",
                _edit(on_model(lambda m: m["state"]["base"][0].__setitem__("t_center", 1e6))),
                "t_center",
            )
        )
    if kind == "calibration":
        out.append(
            Mutation(
                "channel-model-missing",
                _edit(lambda d: d["channels"][0].pop("model")),
                "channels[0]",
            )
        )
    return out


def _singular(d: dict[str, Any]) -> None:
    """scale_factor_x(T) crossing −10⁶ ppm (1 + sₓ = 0: I + E singular) 5 °C below the top
    of the calibrated range, tiny at TREF: the file looks ordinary near TREF."""
    m = d["triads"][0]["model"]
    tref = m["tref_c"]
    hi = m["temperature_range_c"][1]
    p = m["parameters"][3]
    assert p["name"] == "scale_factor_x"
    slope = -1e6 / (hi - 5.0 - tref)
    p["coefficients"] = [0.0, slope]
    p["covariance"] = [[1.0, 0.0], [0.0, 1.0]]


def _triad_mutations() -> list[Mutation]:
    tm = ("triads", 0, "model")

    def on(fn: Callable[[dict[str, Any]], None]) -> Callable[[dict[str, Any]], None]:
        return lambda d: fn(_get(d, tm))

    coef = "triads[0].model.parameters[0].coefficients"
    return [
        Mutation("coefficients-empty", _edit(lambda d: _set(d, ARRAY_AT["triads"], [])), coef),
        Mutation(
            "coefficients-2d",
            _edit(
                lambda d: _set(d, ARRAY_AT["triads"], [[v] for v in _get(d, ARRAY_AT["triads"])])
            ),
            coef,
        ),
        Mutation(
            "coefficients-string",
            _edit(lambda d: _set(d, ARRAY_AT["triads"], "1,2,3")),
            coef,
        ),
        Mutation(
            "covariance-wrong-shape",
            _edit(on(lambda m: m["parameters"][0].__setitem__("covariance", [[1.0]]))),
            "triads[0].model.parameters[0].covariance",
        ),
        Mutation("singular-i-plus-e", _edit(_singular), "singular"),
        Mutation(
            "tref-string-nan",
            _edit(on(lambda m: m.__setitem__("tref_c", "NaN"))),
            "triads[0].model.tref_c",
        ),
        Mutation(
            "tref-null",
            _edit(on(lambda m: m.__setitem__("tref_c", None))),
            "triads[0].model.tref_c",
        ),
        Mutation("tref-missing", _edit(on(lambda m: m.pop("tref_c"))), "tref_c"),
        Mutation(
            "tref-far", _edit(on(lambda m: m.__setitem__("tref_c", 1e6))), "triads[0].model.tref_c"
        ),
        Mutation(
            "range-reversed",
            _edit(on(lambda m: m["temperature_range_c"].reverse())),
            "triads[0].model.temperature_range_c",
        ),
        Mutation(
            "range-one-value",
            _edit(on(lambda m: m.__setitem__("temperature_range_c", [10.0]))),
            "triads[0].model.temperature_range_c",
        ),
        Mutation(
            "eleven-parameters",
            _edit(on(lambda m: m["parameters"].pop())),
            "triads[0].model.parameters",
        ),
        Mutation(
            "parameter-a-list",
            _edit(on(lambda m: m["parameters"].__setitem__(2, [1.0]))),
            "triads[0].model.parameters[2]",
        ),
        Mutation(
            "run-theta-short",
            _edit(on(lambda m: m["runs"][0].__setitem__("theta", [1.0, 2.0]))),
            "triads[0].model.runs[0].theta",
        ),
        Mutation(
            "kind-unknown",
            _edit(on(lambda m: m.__setitem__("kind", "magnetometer"))),
            "triads[0].model.kind",
        ),
        Mutation(
            "order-string",
            _edit(on(lambda m: m.__setitem__("order", "3"))),
            "triads[0].model.order",
        ),
        Mutation("model-missing", _edit(lambda d: d["triads"][0].pop("model")), "triads[0]"),
    ]


def mutations(kind: str) -> list[Mutation]:
    out = [Mutation(f"literal-{n}", _literal(kind, text), _dotted(NUMBER_AT[kind]))
           for n, text in LITERALS.items()]  # fmt: skip
    out.append(
        Mutation(
            "nesting-100000",
            _literal(kind, "[" * 100_000 + "]" * 100_000),
            "nested deeper",
        )
    )
    out += _triad_mutations() if kind == "triads" else _model_mutations(kind)
    return out


CASES = [(kind, m) for kind in KINDS for m in mutations(kind)]


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _check(
    argv_t: list[str],
    model: Path,
    data: Path,
    out_dir: Path,
    words: str,
    capsys: pytest.CaptureFixture[str],
) -> str:
    out_dir.mkdir()
    argv = [a.format(m=model, d=data, o=out_dir) for a in argv_t]
    before = (_digest(model), _digest(data))
    code = _run(argv)
    _, err = capsys.readouterr()
    assert "Traceback" not in err, err
    assert code == 2, f"{argv[0]}: exit {code}; stderr: {err[-2000:]}"
    lines = [ln for ln in err.splitlines() if ln.strip()]
    last = lines[-1]
    assert last.startswith(f"error: {model}: "), last
    assert words in last, last
    assert (_digest(model), _digest(data)) == before, "an input changed"
    assert not list(out_dir.iterdir()), "output written for a refused model file"
    return last


@pytest.mark.parametrize("command", sorted(COMMANDS))
@pytest.mark.parametrize(("kind", "mutation"), CASES, ids=[f"{k}/{m.id}" for k, m in CASES])
def test_model_file_attack(
    kind: str,
    mutation: Mutation,
    command: str,
    originals: dict[str, tuple[bytes, Path]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    raw, data = originals[kind]
    model = tmp_path / "model.json"
    model.write_bytes(mutation.make(copy.deepcopy(json.loads(raw))))
    _check(COMMANDS[command], model, data, tmp_path / "out", mutation.words, capsys)


def test_the_originals_are_accepted(
    originals: dict[str, tuple[bytes, Path]], tmp_path: Path
) -> None:
    """Every unmutated file, re-signed by this test's own checksum, still loads: the checks
    refuse what is wrong, not the files thermocal writes (and the test's checksum is the
    program's)."""
    for kind, (raw, data) in originals.items():
        d = json.loads(raw)
        _resign(d)
        assert json.loads(raw) == d, f"{kind}: this test's checksum differs from thermocal's"
        f = tmp_path / f"{kind}.json"
        f.write_bytes(raw)
        assert _run(["validate", str(f), str(data)]) == 0, kind
        assert _run(["export-c", str(f), "-o", str(tmp_path / f"c-{kind}")]) == 0, kind


def test_a_file_over_the_size_limit(
    originals: dict[str, tuple[bytes, Path]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A valid, correctly signed model padded with whitespace past 64 MiB is refused by
    size (not read whole into memory and parsed) by every command."""
    raw, data = originals["poly"]
    model = tmp_path / "big.json"
    with open(model, "wb") as fh:
        fh.write(raw)
        fh.write(b" " * (64 * 1024 * 1024 + 1 - len(raw)))
    assert json.loads(model.read_bytes()) == json.loads(raw)  # still a valid model file
    for i, command in enumerate(sorted(COMMANDS)):
        _check(COMMANDS[command], model, data, tmp_path / f"out{i}", "64 MiB", capsys)


def test_the_singular_triad_would_blow_up_the_output(
    originals: dict[str, tuple[bytes, Path]],
) -> None:
    """The singular mutation is a real danger, computed here: (I + E(T))⁻¹ at the
    temperature 0.01 °C from the zero of 1 + sₓ turns a 0.0004 °/s rate into more than 1 °/s."""
    d = json.loads(originals["triads"][0])
    _singular(d)
    m = d["triads"][0]["model"]
    c0, c1 = m["parameters"][3]["coefficients"]
    t_zero = m["tref_c"] - (1e6 + c0) / c1
    lo, hi = m["temperature_range_c"]
    assert lo < t_zero < hi
    sx = 1e-6 * (c0 + c1 * (t_zero + 0.01 - m["tref_c"]))
    assert abs(0.0004 / (1.0 + sx)) > 1.0
    assert math.isfinite(sx)


# --- property: any one edit of a real file, re-signed ---------------------------------------

HOSTILE: list[Any] = [None, "", "NaN", "1e309", True, 0, -1, 0.5, 1e308, -1e308, 2**53, [],
                      {}, [[1.0]], [1.0] * 13, {"a": 1}, "DELETE"]  # fmt: skip
"""Replacement values (``"DELETE"``: the key or item is removed)."""


def _paths(obj: Any, path: Path_ = ()) -> list[Path_]:
    """Every key path inside a parsed JSON value (containers and leaves)."""
    out: list[Path_] = [path] if path else []
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k != "checksum":
                out += _paths(v, (*path, k))
    elif isinstance(obj, list):
        for i, v in enumerate(obj[:4]):  # the first items: long arrays repeat their kind
            out += _paths(v, (*path, i))
    return out


@pytest.fixture(scope="module")
def all_paths(originals: dict[str, tuple[bytes, Path]]) -> dict[str, list[Path_]]:
    return {kind: _paths(json.loads(raw)) for kind, (raw, _) in originals.items()}


@pytest.mark.parametrize("command", sorted(COMMANDS))
@settings(
    max_examples=12,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(
    kind=st.sampled_from(KINDS),
    pick=st.integers(0, 10**6),
    value=st.sampled_from(range(len(HOSTILE))),
)
def test_any_edit_ends_in_exit_0_or_2(
    command: str,
    kind: str,
    pick: int,
    value: int,
    originals: dict[str, tuple[bytes, Path]],
    all_paths: dict[str, list[Path_]],
    tmp_path_factory: pytest.TempPathFactory,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """One value anywhere in a real model or calibration file replaced by a hostile one (or
    removed), the file re-signed: every command ends in exit 0 or 2, never 1 or a
    traceback, and exit 2 says why in one ``error:`` line."""
    raw, rec = originals[kind]
    d = json.loads(raw)
    path = all_paths[kind][pick % len(all_paths[kind])]
    new = copy.deepcopy(HOSTILE[value])
    parent = _get(d, path[:-1])
    if new == "DELETE":
        del parent[path[-1]]
    else:
        parent[path[-1]] = new
    if isinstance(d, dict):
        _resign(d)
    tmp = tmp_path_factory.mktemp("edit")
    model = tmp / "model.json"
    model.write_text(json.dumps(d))
    (tmp / "out").mkdir()
    argv = [a.format(m=model, d=rec, o=tmp / "out") for a in COMMANDS[command]]
    before = _digest(rec)
    code = _run(argv)
    _, err = capsys.readouterr()
    assert "Traceback" not in err, err
    assert code in (0, 2), f"{_dotted(path)} = {new!r}: exit {code}; {err[-1500:]}"
    if code == 2:
        assert err.strip().splitlines()[-1].startswith("error: "), err
    assert _digest(rec) == before


@pytest.mark.parametrize("content", ["[" * 100_000 + "]" * 100_000, '{"r": ' + "9" * 5000 + "}"])
def test_a_hostile_validation_file_is_exit_2(tmp_path: Path, content: str) -> None:
    """``report --validation`` reads another JSON file than the model: deep nesting or a
    5000-digit integer there ended in exit 1 (RecursionError, ValueError)."""
    from typer.testing import CliRunner

    from thermocal.cli import app

    bad = tmp_path / "validation.json"
    bad.write_text(content)
    rec = tmp_path / "rec.csv"
    rec.write_text("time,gyro,T1\n" + "".join(f"{i},{0.01 * i},{20 + i}\n" for i in range(50)))
    model = tmp_path / "m.json"
    res = CliRunner().invoke(
        app, ["fit", str(rec), "--model", "poly", "--order", "1", "--signal", "gyro",
              "--temps", "T1", "-o", str(model), "--allow-narrow"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(
        app, ["report", "--model", str(model), "--validation", str(bad), "--recording",
              str(rec), "-o", str(tmp_path / "r.html")],
    )  # fmt: skip
    assert res.exit_code == 2, res.output
    assert "validation.json" in res.output and "Traceback" not in res.output
    assert not (tmp_path / "r.html").exists()
