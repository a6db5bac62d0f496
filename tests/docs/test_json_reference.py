"""The ``--json`` reference (``docs/json.md``) names every key the commands print, and no other.

Every command that takes ``--json`` is run here, in a temporary folder, on built-in simulated
data, the flight-controller logs of the tutorials (``docs/tutorials/data``), imucal's public
Ferraris session (``tests/data/imucal_ferraris``) and a simulated Modbus chamber with a
serial gyro on 127.0.0.1 (the test station).  The keys each run prints — every top-level key,
and the keys of each nested object or list of objects whose keys the page lists — are
compared with the page's tables, both ways: a printed key missing from the page fails, and
so does a key on the page that no run printed.  A segment ``<name>`` of a documented key
stands for keys that depend on the data (a column, a channel, a noise term, a sensor);
``[]`` for the items of a list of objects.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from chamber_logs import write_log, write_recording
from thermocal.cli import main

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "json.md"
LOGS = ROOT / "docs" / "tutorials" / "data"
FERRARIS = ROOT / "tests" / "data" / "imucal_ferraris"
ROW = re.compile(r"^\|\s*`([^`]+)`\s*\|([^|]*)\|([^|]*)\|(.*)\|\s*$")
SECTION = re.compile(r"^## `thermocal ([^`]+)`", re.MULTILINE)

Path_ = tuple[str, ...]


def documented() -> dict[str, dict[Path_, tuple[str, str, str]]]:
    """Section (``fit``, ``profile NAME``) → key path → (type, unit, meaning), from the page."""
    text = PAGE.read_text(encoding="utf-8")
    parts = SECTION.split(text)
    out: dict[str, dict[Path_, tuple[str, str, str]]] = {}
    for name, body in zip(parts[1::2], parts[2::2], strict=True):
        rows = [ROW.match(line) for line in body.splitlines()]
        out[name] = {
            _split(m[1]): (m[2].strip(), m[3].strip(), m[4].strip()) for m in rows if m is not None
        }
    return out


def _split(key: str) -> Path_:
    """``stages[].bias`` → ("stages", "[]", "bias")."""
    return tuple(s for part in key.split(".") for s in re.split(r"(\[\])", part) if s)


DEVIATIONS = "adev|oadev|mdev|tdev|hdev|ohdev|totdev|mtotdev|ttotdev|htotdev|theo1|mtie|tierms"
"""``allan --deviation``'s names (its help lists them): ``<deviation>`` stands for these only."""


def _segment(pattern: str) -> re.Pattern[str]:
    """A documented segment as a regex: ``<deviation>`` one of :data:`DEVIATIONS`, any other
    ``<name>`` any key; ``<deviation>_tau_s`` a prefix with a fixed rest."""
    parts = re.split(r"(<[^>]+>)", pattern)
    return re.compile(
        "".join(
            (f"(?:{DEVIATIONS})" if p == "<deviation>" else r".+")
            if p.startswith("<")
            else re.escape(p)
            for p in parts
        )
    )


def _matches(pattern: Path_, path: Path_) -> bool:
    return len(pattern) == len(path) and all(
        s != "[]" and _segment(p).fullmatch(s) is not None if p != "[]" else s == "[]"
        for p, s in zip(pattern, path, strict=True)
    )


def _opens(patterns: list[Path_], path: Path_) -> bool:
    """Whether the page lists keys below ``path`` (then they are checked)."""
    return any(len(p) > len(path) and _matches(p[: len(path)], path) for p in patterns)


def printed_keys(value: Any, patterns: list[Path_], path: Path_ = ()) -> Iterator[Path_]:
    """Every key path of ``value``: the top level, and below where the page lists keys."""
    if path and not _opens(patterns, path):
        return
    if isinstance(value, dict):
        for key, sub in value.items():
            yield (*path, key)
            yield from printed_keys(sub, patterns, (*path, key))
    elif isinstance(value, list):
        for item in value:
            if isinstance(item, dict):
                yield from printed_keys(item, patterns, (*path, "[]"))


def _run(args: list[str]) -> Any:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([*args, "--json"])
    assert code == 0, (args, err.getvalue())
    return json.loads(out.getvalue())


STATION_TOML = """part_s = 0.5
[chamber]
driver = "modbus-tcp"
host = "127.0.0.1"
port = {port}
setpoint_register = 300
temperature_register = 100
scale = 0.01
poll_s = 0.1

[[sensor]]
id = "imu"
device = "{device}"
names = ["gx", "temp"]
units = ["deg/s", "degC"]
delimiter = ","
rate_hz = 50
"""


def _station_runs(tmp: Path) -> list[tuple[str, Any]]:
    """``station check`` and ``station run`` on a simulated chamber and serial gyro."""
    pytest.importorskip("pymodbus")
    pytest.importorskip("serial")
    from thermocal.station.sim import ChamberModel, SimulatedChamber, SimulatedSerialSensor

    k = 1000.0
    model = ChamberModel(time_scale=k, tau_s=60.0)
    sim = SimulatedChamber(model=model, scale=0.01).start()
    sensor = SimulatedSerialSensor(model, rate_hz=50, time_scale=k).start()
    try:
        toml = tmp / "station.toml"
        toml.write_text(STATION_TOML.format(port=sim.port, device=sensor.device))
        (tmp / "prog.csv").write_text("time_s,setpoint_c\n0,25\n1000,40\n2000,40\n")
        return [
            ("station check", _run(["station", "check", str(toml), "--listen", "0.5"])),
            ("station run", _run(["station", "run", str(toml), "--profile", str(tmp / "prog.csv"),
                                  "-o", str(tmp / "rec"), "--time-scale", str(k)])),
        ]  # fmt: skip
    finally:
        sensor.stop()
        sim.stop()


FLEET_TOML = """[fit]
model = "poly"
order = 3
signal = "gyro"
temps = "T1"

[limits]
rms_residual_max = 0.45

[[unit]]
id = "SN1"
modeling = ["SN1.csv"]
validation = "SN2.csv"

[[unit]]
id = "SN2"
modeling = ["SN2.csv"]
"""


def _chamber_runs(t: Path) -> list[tuple[str, Any]]:
    """The chamber workflow on a simulated ring-laser gyro, and the chamber programs."""
    runs = [("simulate", _run(["simulate", "rlg-modelling", "-o", str(t / "mod.csv"),
                               "--rate-hz", "0.1", "--truth", str(t / "truth.json")]))]  # fmt: skip
    _run(["simulate", "rlg-validation", "-o", str(t / "val.csv"), "--rate-hz", "0.1"])
    mod, val, model = str(t / "mod.csv"), str(t / "val.csv"), str(t / "poly.json")
    site = ["--latitude", "45", "--axis", "up"]
    runs += [
        ("inspect", _run(["inspect", mod])),
        ("metrics", _run(["metrics", val, "--signal", "gyro", "--average", "100", *site])),
        ("allan", _run(["allan", val, "--signal", "gyro"])),
        ("fit", _run(["fit", mod, "--model", "poly", "--signal", "gyro",
                      "--temps", "T1,T2,T3,T4", *site, "-o", model])),
        ("validate", _run(["validate", model, val, "--modeling", mod, "--ambient", "T_chamber"])),
        ("compensate", _run(["compensate", model, val, "-o", str(t / "comp.csv")])),
        ("export-c", _run(["export-c", model, "-o", str(t / "c"), "--unit", "deg/h"])),
        ("profile correlate", _run(["profile", "correlate", mod, val])),
        ("profile join", _run(["profile", "join", str(write_recording(t / "imu.csv",
          offset_s=20.0, span_s=3000.0)[0]), "--temps", "T", "--time-unit", "s",
          "--temp-unit", "degC", "--chamber-log", str(write_log(t / "chamber.csv",
          span_s=6000.0)), "-o", str(t / "joined.csv")])),
        ("profile design-validation",
         _run(["profile", "design-validation", mod, "-o", str(t / "design.csv")])),
    ]  # fmt: skip
    runs += _imu_runs(t)
    for name in ("rlg-modelling", "rlg-validation", "fog-slow", "mems-warmup", "accel-full-range"):
        runs.append(("profile NAME", _run(["profile", name, "-o", str(t / f"{name}.csv")])))
    return runs


def _imu_runs(t: Path) -> list[tuple[str, Any]]:
    """Several signals at once (a six-channel calibration), the deviation family, the dynamic
    ADEV and several power-ons of one sensor."""
    mod, val, cal = str(t / "imu-mod.parquet"), str(t / "imu-val.parquet"), str(t / "imu.json")
    _run(["simulate", "mems-imu", "-o", mod, "--seed", "1"])
    _run(["simulate", "mems-imu", "--run", "validation", "-o", val, "--seed", "1"])
    runs = []  # three power-ons of a MEMS gyro at +20 °C
    for seed in (1, 2, 3):
        _run(["simulate", "mems-warmup", "-o", str(t / f"w{seed}.csv"), "--seed", str(seed),
              "--record-s", "360"])  # fmt: skip
        runs.append(str(t / f"w{seed}_T+20.csv"))
    return [
        ("fit", _run(["fit", mod, "--model", "poly", "--order", "3",
                      "--signal", "gx,gy,gz,ax,ay,az", "--temps", "T_die",
                      "--gravity-axis", "+z", "--latitude", "45", "-o", cal])),
        ("validate", _run(["validate", cal, val, "--modeling", mod, "--ambient", "T_chamber"])),
        ("compensate", _run(["compensate", cal, val, "-o", str(t / "imu-comp.parquet")])),
        ("export-c", _run(["export-c", cal, "-o", str(t / "imu-c")])),
        ("metrics", _run(["metrics", val, "--signal", "gx,gy,gz"])),
        ("allan", _run(["allan", val, "--signal", "gx,gy"])),
        ("allan", _run(["allan", val, "--signal", "gx", "--deviation", "mdev,hdev"])),
        ("allan", _run(["allan", val, "--signal", "gx", "--dynamic", "20000"])),
        ("allan", _run(["allan", val, "--signal", "gx", "--temps", "T_die", "--temp-bins", "20"])),
        ("metrics", _run(["metrics", *runs, "--signal", "gyro"])),
    ]  # fmt: skip


def _timed_ferraris(t: Path) -> str:
    """imucal's session with a time column (its sample counter over 102.4 Hz): a file a
    calibration of triads is applied to."""
    lines = (FERRARIS / "example_ferraris_session.csv").read_text().splitlines()
    rows = [f"time_s,{lines[0]}"] + [f"{int(ln.split(',')[0]) / 102.4!r},{ln}" for ln in lines[1:]]
    (t / "ferraris-timed.csv").write_text("\n".join(rows) + "\n")
    return str(t / "ferraris-timed.csv")


def _other_runs(t: Path) -> list[tuple[str, Any]]:
    """Flight-controller logs, the turntable, multipos, a batch and the demonstrations."""
    _run(["simulate", "turntable-16", "-o", str(t / "tt.csv")])
    _run(["simulate", "ratetable", "--runs", "2", "-o", str(t / "rt")])
    _run(["simulate", "tumble", "-o", str(t / "tb.csv")])
    rt = sorted(str(p) for p in (t / "rt").glob("*.csv"))
    for seed in (1, 2):
        _run(["simulate", "fog-slow", "-o", str(t / f"SN{seed}.csv"), "--seed", str(seed),
              "--rate-hz", "0.1"])  # fmt: skip
    (t / "batch.toml").write_text(FLEET_TOML)
    px4 = t / "px4"
    return [
        ("px4-tempcal", _run(["px4-tempcal", str(LOGS / "sweep.ulg"), "-o", str(px4),
                              "--emulate-learning"])),
        ("ardupilot-tempcal", _run(["ardupilot-tempcal", str(LOGS / "sweep.bin"),
                                    "-o", str(t / "ap"), "--emulate-learning"])),
        ("export-params", _run(["export-params", str(px4 / "calibration.json"),
                                "--format", "px4", "-o", str(t / "x.params")])),
        ("turntable", _run(["turntable", str(t / "tt.csv"), "-o", str(t / "tt.json"),
                            "--latitude", "40"])),
        ("multipos", _run(["multipos", str(FERRARIS / "example_ferraris_session.csv"),
                           "--poses", str(FERRARIS / "example_ferraris_session_list.json"),
                           "--rate", "102.4", "--accel", "acc_x,acc_y,acc_z",
                           "--accel-unit", "m/s^2", "--gyro", "gyr_x,gyr_y,gyr_z",
                           "--gyro-unit", "deg/s", "--gravity", "9.81",
                           "-o", str(t / "mp.json")])),
        ("compensate", _run(["compensate", str(t / "mp.json"), _timed_ferraris(t),
                             "--time", "time_s", "-o", str(t / "mp-comp.csv")])),
        ("ratetable", _run(["ratetable", *rt, "--rate-column", "table_rate", "--temps", "temp"])),
        ("tumble", _run(["tumble", str(t / "tb.csv"), "--angle-column", "angle"])),
        ("fleet", _run(["fleet", str(t / "batch.toml"), "-o", str(t / "bo"), "--workers", "1"])),
        ("demo", _run(["demo", "--quick", "-o", str(t / "d1")])),
        ("demo", _run(["demo", "--quick", "--imu", "-o", str(t / "d2")])),
        ("demo", _run(["demo", "--station", "--time-scale", "1000", "-o", str(t / "d3")])),
    ]  # fmt: skip


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> list[tuple[str, Any]]:
    """(section, printed JSON) of every run."""
    t = tmp_path_factory.mktemp("json-runs")
    return _chamber_runs(t) + _other_runs(t) + _station_runs(t)


def test_every_json_command_is_run_and_has_a_section(runs: list[tuple[str, Any]]) -> None:
    import typer

    import thermocal.cli

    thermocal.cli._register()
    with_json: set[str] = set()

    def walk(command: Any, path: tuple[str, ...]) -> None:
        if path and any("--json" in p.opts for p in command.params):
            with_json.add(" ".join(path))
        for name, sub in (getattr(command, "commands", None) or {}).items():
            walk(sub, (*path, name))

    walk(typer.main.get_command(thermocal.cli.app), ())
    presets = {"rlg-modelling", "rlg-validation", "fog-slow", "mems-warmup", "accel-full-range"}
    expected = {("profile NAME" if c.split()[-1] in presets else c) for c in with_json}
    assert {name for name, _ in runs} == expected
    assert set(documented()) == expected


def test_every_printed_key_is_in_the_reference(runs: list[tuple[str, Any]]) -> None:
    doc = documented()
    missing = []
    for name, value in runs:
        patterns = list(doc.get(name, {}))
        for path in printed_keys(value, patterns):
            if not any(_matches(p, path) for p in patterns):
                missing.append(f"{name}: {'.'.join(path).replace('.[]', '[]')}")
    assert not sorted(set(missing)), sorted(set(missing))


def test_every_documented_key_is_printed_by_a_run(runs: list[tuple[str, Any]]) -> None:
    seen: dict[str, list[Path_]] = {}
    doc = documented()
    for name, value in runs:
        seen.setdefault(name, []).extend(printed_keys(value, list(doc.get(name, {}))))
    never = [
        f"{name}: {'.'.join(p)}"
        for name, rows in doc.items()
        for p in rows
        if not any(_matches(p, path) for path in seen.get(name, []))
    ]
    assert not never, never


def test_every_row_says_its_type_and_meaning() -> None:
    types = {"string", "integer", "number", "boolean", "null", "array", "object"}
    bad = [
        f"{name}: {'.'.join(p)}"
        for name, rows in documented().items()
        for p, (kind, _unit, meaning) in rows.items()
        if not set(re.findall(r"[a-z]+", kind)) <= types | {"or", "of"} or len(meaning) < 8
    ]
    assert not bad, bad
    assert sum(len(rows) for rows in documented().values()) > 250
