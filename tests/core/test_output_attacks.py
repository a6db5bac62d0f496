"""Hostile output paths for every command that writes (issue 26 item 1), generated here and
run through the command line.

Inputs are sacred: ``-o`` (and ``--truth``, ``--plot``) naming an input, a hard or symbolic
link to one, a folder holding an input under a name the command writes, an input's sidecar
or a stale temporary that is an input, and a special file (a FIFO, ``/dev/null``,
``/dev/stdout``, a link to ``/proc/self/fd/1``, a link into ``/dev``) end in exit 2 with one
``error:`` line naming the output (and the input), before anything is written: every input
is hashed before and after, and the test folder's tree is unchanged.  ``/dev/null`` is
refused like every device (:mod:`thermocal.outputs`).

A FIFO is never opened (the gate uses ``stat``): each run is guarded by an alarm, so a
command that opened it would fail the test instead of hanging.  A second guard makes
``os.replace``/``os.rename``/``os.unlink``/``shutil.rmtree`` refuse (RuntimeError, exit 1)
paths under ``/dev``, ``/proc`` and ``/sys`` during the runs: a broken gate can then never
replace ``/dev/stdout`` or ``/dev/null`` of the machine the tests run on (as root it could).
"""

from __future__ import annotations

import builtins
import contextlib
import hashlib
import io
import os
import shutil
import signal
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.outputs import TEMP_SUFFIX

GYROS, ACCELS = ("gx", "gy", "gz"), ("ax", "ay", "az")
SPECIAL = ("/dev", "/proc", "/sys")


# --- the inputs, built once ----------------------------------------------------------------


def _recording_csv() -> str:
    """400 s at 1 Hz, 10 → 40 °C; gyros in deg/s, accelerometers in mg (+z up)."""
    rng = np.random.default_rng(26)
    n = 400
    t = np.arange(n, dtype=float)
    temp = 10.0 + 30.0 * t / (n - 1)
    cols: dict[str, np.ndarray] = {"time": t, "T1": temp}
    for name, c in zip(GYROS, (0.1, 0.2, 0.3), strict=True):
        cols[name] = c + 0.01 * (temp - 25.0) + rng.normal(0.0, 0.001, n)
    for name, c in zip(ACCELS, (5.0, -3.0, 1000.0), strict=True):
        cols[name] = c + 0.3 * (temp - 25.0) + rng.normal(0.0, 0.5, n)
    lines = [",".join(cols)] + [
        ",".join(repr(float(v)) for v in row) for row in zip(*cols.values(), strict=True)
    ]
    return "\n".join(lines) + "\n"


def _quiet(argv: list[str]) -> int:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        return main(argv)


@pytest.fixture(scope="module")
def assets(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Every input a command below reads, valid (so that without the gate the command
    would write): a recording, a six-channel calibration fitted on it, a chamber program,
    a 16-position turntable run, a PX4 ULog, an ArduPilot DataFlash log, a fleet batch."""
    from dataflash_writer import imu_log
    from fleet_data import config_text, write_run
    from thermocal.turntable import simulate_turntable16
    from thermocal.writers import write_recording
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    d = tmp_path_factory.mktemp("output-attacks")
    (d / "rec.csv").write_text(_recording_csv())
    code = _quiet(["fit", str(d / "rec.csv"), "--model", "poly", "--order", "3", "--signal",
                   ",".join(GYROS + ACCELS), "--signal-unit", "deg/s,deg/s,deg/s,mg,mg,mg",
                   "--time-unit", "s", "--temps", "T1", "--temp-unit", "degC",
                   "--gravity-axis", "+z", "--gravity", "9.80665",
                   "-o", str(d / "cal.json")])  # fmt: skip
    assert code == 0
    assert _quiet(["profile", "rlg-modelling", "-o", str(d / "prog.csv")]) == 0
    rec, _truth = simulate_turntable16(3, rate_hz=5.0)
    write_recording(rec, d / "tt.csv")
    n = 3000  # 300 s at 10 Hz, 10 → 50 °C, a still sensor drifting 1e-4 rad/s per °C
    ts = (1e6 + np.arange(n) * 1e5).astype(np.int64)
    temp = np.linspace(10.0, 50.0, n)
    ulog_rows = [
        (int(s), 7, 1e-4 * float(x), 0.0, 0.0, float(x)) for s, x in zip(ts, temp, strict=True)
    ]
    (d / "log.ulg").write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, ulog_rows)]))
    bin_rows = [
        (int(s), 0, 1e-4 * float(x), 0.0, 0.0, 0.0, 0.0, -9.8, 0, 0, float(x))
        for s, x in zip(ts, temp, strict=True)
    ]
    (d / "log.bin").write_bytes(imu_log(bin_rows))
    write_run(d / "U1.csv", 7)
    from thermocal.ratetable.simulate import simulate_ladder

    rt, _ = simulate_ladder(np.random.default_rng(0), rates_dps=(-10.0, 0.0, 10.0), dwell_s=6.0,
                            rate_hz=20.0)  # fmt: skip
    write_recording(rt, d / "rt.csv")
    from thermocal.tumble.simulate import simulate_tumble

    tb, _ = simulate_tumble(np.random.default_rng(0), stations=8, dwell_s=4.0, rate_hz=10.0)
    write_recording(tb, d / "tb.csv")
    (d / "batch.toml").write_text(config_text({"U1": ("U1.csv", None)}), encoding="utf-8")
    return d


# --- the commands that write ---------------------------------------------------------------


@dataclass(frozen=True)
class Command:
    """A command with an output: its arguments for inputs ``i`` (name → path) and output
    ``o``, the inputs it reads (asset names), whether ``o`` is a file or a folder it writes
    into, the output's suffix, the name of a file it writes when ``o`` is a folder, and
    whether a CSV output gets a sidecar ``OUT.csv.meta.json``."""

    name: str
    argv: Callable[[dict[str, Path], str], list[str]]
    inputs: tuple[str, ...]
    kind: str = "file"
    suffix: str = ""
    writes: str = ""
    sidecar: bool = False


def _s(p: Path) -> str:
    return str(p)


CAL6 = ["--signal", ",".join(GYROS + ACCELS)]
COMMANDS = [
    Command("fit", lambda i, o: ["fit", _s(i["rec.csv"]), "--model", "poly", "--order", "1",
            "--signal", "gx", "--signal-unit", "deg/s", "--time-unit", "s", "--temps", "T1",
            "--temp-unit", "degC", "-o", o], ("rec.csv",), suffix=".json"),
    Command("compensate", lambda i, o: ["compensate", _s(i["cal.json"]), _s(i["rec.csv"]),
            "-o", o], ("cal.json", "rec.csv"), suffix=".csv", sidecar=True),
    Command("export-c", lambda i, o: ["export-c", _s(i["cal.json"]), "-o", o], ("cal.json",),
            kind="dir", writes="cal.c"),
    Command("export-params", lambda i, o: ["export-params", _s(i["cal.json"]), "--format",
            "px4", "--gyro", "gx,gy,gz", "--accel", "ax,ay,az", "-o", o], ("cal.json",),
            suffix=".params"),
    Command("report", lambda i, o: ["report", "--model", _s(i["cal.json"]), "--recording",
            _s(i["rec.csv"]), "-o", o], ("cal.json", "rec.csv"), suffix=".html"),
    Command("profile", lambda i, o: ["profile", "fog-slow", "-o", o], (), suffix=".csv"),
    Command("profile-design", lambda i, o: ["profile", "design-validation", _s(i["prog.csv"]),
            "-o", o], ("prog.csv",), suffix=".csv"),
    Command("simulate", lambda i, o: ["simulate", "rlg-modelling", "--profile",
            _s(i["prog.csv"]), "--rate-hz", "0.01", "-o", o], ("prog.csv",), suffix=".csv",
            writes="rlg-modelling.csv", sidecar=True),
    Command("simulate-truth", lambda i, o: ["simulate", "rlg-modelling", "--profile",
            _s(i["prog.csv"]), "--rate-hz", "0.01", "-o", str(i["prog.csv"].parent / "sim.csv"),
            "--truth", o], ("prog.csv",), suffix=".json"),
    Command("turntable", lambda i, o: ["turntable", _s(i["tt.csv"]), "-o", o], ("tt.csv",),
            suffix=".json"),
    Command("ratetable", lambda i, o: ["ratetable", _s(i["rt.csv"]), "--rate-column",
            "table_rate", "-o", o], ("rt.csv",), suffix=".json"),
    Command("ratetable-report", lambda i, o: ["ratetable", _s(i["rt.csv"]), "--rate-column",
            "table_rate", "--report", o], ("rt.csv",), suffix=".html"),
    Command("tumble", lambda i, o: ["tumble", _s(i["tb.csv"]), "--angle-column", "angle",
            "-o", o], ("tb.csv",), suffix=".json"),
    Command("tumble-report", lambda i, o: ["tumble", _s(i["tb.csv"]), "--angle-column",
            "angle", "--report", o], ("tb.csv",), suffix=".html"),
    Command("px4-tempcal", lambda i, o: ["px4-tempcal", _s(i["log.ulg"]), "-o", o],
            ("log.ulg",), kind="dir", writes="calibration.json"),
    Command("ardupilot-tempcal", lambda i, o: ["ardupilot-tempcal", _s(i["log.bin"]), "-o", o],
            ("log.bin",), kind="dir", writes="ardupilot.parm"),
    Command("allan", lambda i, o: ["allan", _s(i["rec.csv"]), "--signal", "gx", "--signal-unit",
            "deg/s", "--time-unit", "s", "--plot", o], ("rec.csv",), suffix=".png"),
    Command("demo", lambda i, o: ["demo", "--quick", "-o", o], (), kind="dir"),
    Command("fleet", lambda i, o: ["fleet", _s(i["batch.toml"]), "-o", o, "--workers", "1"],
            ("batch.toml", "U1.csv"), kind="dir", writes="summary.csv"),
]  # fmt: skip
BY_NAME = {c.name: c for c in COMMANDS}


# --- the attacks ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Attack:
    """The output path to give and the words the error line must hold."""

    output: str
    words: tuple[str, ...]


AttackFn = Callable[[Command, dict[str, Path], Path], Attack | None]


def the_input_itself(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    if not c.inputs:
        return None
    p = i[c.inputs[-1]]
    return Attack(str(p), (p.name,))


def a_hard_link_to_an_input(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    if not c.inputs:
        return None
    p = i[c.inputs[0]]
    link = tmp / f"link{c.suffix}"
    os.link(p, link)
    return Attack(str(link), (link.name, p.name))


def a_symlink_to_an_input(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    if not c.inputs:
        return None
    p = i[c.inputs[0]]
    link = tmp / f"link{c.suffix}"
    link.symlink_to(p)
    return Attack(str(link), (link.name, p.name))


def a_folder_holding_an_input_where_it_writes(
    c: Command, i: dict[str, Path], tmp: Path
) -> Attack | None:
    """A file command given the folder of its input; a folder command given a folder in
    which a file it writes is an input (``export-c cal.c -o .``; the tempcal commands'
    ``calibration.json`` a hard link of the log; fleet's ``summary.csv`` its data)."""
    if not c.inputs:
        return None
    folder = i[c.inputs[0]].parent
    if not c.writes:
        return Attack(str(folder), (str(folder), "directory"))
    target = folder / c.writes
    src = i[c.inputs[-1]]
    if c.name in ("export-c", "simulate"):  # the input itself, named like a file it writes
        src.rename(target)
        i[c.inputs[-1]] = target
    elif c.name == "fleet":  # the unit's data where fleet writes its summary
        src.rename(target)
        i[c.inputs[-1]] = target
        cfg = i["batch.toml"]
        cfg.write_text(cfg.read_text(encoding="utf-8").replace('"U1.csv"', '"summary.csv"'))
    else:
        os.link(src, target)
    return Attack(str(folder), (target.name,))


def a_stale_temporary_that_is_an_input(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    """A later run removes its output's stale temporaries: one is a hard link of an input."""
    if not c.inputs:
        return None
    out = tmp / f"out{c.suffix}"
    stale = tmp / f".{out.name}.4999999.deadbeef{TEMP_SUFFIX}"  # no such process
    os.link(i[c.inputs[0]], stale)
    return Attack(str(out), (stale.name, i[c.inputs[0]].name))


def a_sidecar_linked_to_an_input(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    """A CSV output's sidecar ``OUT.csv.meta.json`` is a symbolic link to an input."""
    if not c.sidecar or not c.inputs:
        return None
    out = tmp / "out.csv"
    (tmp / "out.csv.meta.json").symlink_to(i[c.inputs[0]])
    return Attack(str(out), ("out.csv.meta.json", i[c.inputs[0]].name))


def a_fifo(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    fifo = tmp / f"fifo{c.suffix}"
    os.mkfifo(fifo)
    return Attack(str(fifo), (fifo.name,))


def dev_null(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    return Attack("/dev/null", ("/dev/null",))


def dev_stdout(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    return Attack("/dev/stdout", ("/dev/stdout",))


def a_symlink_to_proc_self_fd_1(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    link = tmp / f"stdout{c.suffix}"
    link.symlink_to("/proc/self/fd/1")
    return Attack(str(link), (link.name, "/proc"))


def a_symlinked_folder_into_dev(c: Command, i: dict[str, Path], tmp: Path) -> Attack | None:
    link = tmp / "shm"
    link.symlink_to("/dev/shm", target_is_directory=True)
    out = link if c.kind == "dir" else link / f"out{c.suffix}"
    return Attack(str(out), ("shm", "/dev"))


ATTACKS: list[AttackFn] = [
    the_input_itself,
    a_hard_link_to_an_input,
    a_symlink_to_an_input,
    a_folder_holding_an_input_where_it_writes,
    a_stale_temporary_that_is_an_input,
    a_sidecar_linked_to_an_input,
    a_fifo,
    dev_null,
    dev_stdout,
    a_symlink_to_proc_self_fd_1,
    a_symlinked_folder_into_dev,
]


def _applies(c: Command, a: AttackFn) -> bool:
    """Whether the attack means something for the command (inputs, a CSV output…)."""
    if not c.inputs and a not in (a_fifo, dev_null, dev_stdout, a_symlink_to_proc_self_fd_1,
                                  a_symlinked_folder_into_dev):  # fmt: skip
        return False
    if a is a_sidecar_linked_to_an_input:
        return c.sidecar
    if a is a_folder_holding_an_input_where_it_writes and c.kind == "dir":
        return bool(c.writes)
    if a is a_stale_temporary_that_is_an_input:
        return c.kind == "file"
    return True


CASES = [(c.name, a) for c in COMMANDS for a in ATTACKS if _applies(c, a)]


# --- the guards ----------------------------------------------------------------------------


class _Timeout(Exception):
    pass


@contextlib.contextmanager
def _alarm(seconds: int) -> Iterator[None]:
    """Fail, not hang, when a command blocks (opening a FIFO waits for a reader)."""

    def ring(signum: int, frame: FrameType | None) -> None:
        raise _Timeout(f"the command did not return within {seconds} s (a FIFO opened?)")

    old = signal.signal(signal.SIGALRM, ring)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _special(path: Any) -> bool:
    """The directory entry ``path`` names lies under /dev, /proc or /sys (its folder's
    links resolved, not the entry itself: replacing a link in the test folder is harmless)."""
    p = os.path.abspath(os.fspath(path))
    p = os.path.join(os.path.realpath(os.path.dirname(p)), os.path.basename(p))
    return any(p == r or p.startswith(r + "/") for r in SPECIAL)


@pytest.fixture
def machine_guard(monkeypatch: pytest.MonkeyPatch) -> None:
    """Creating a folder, opening a file for writing, replacing or deleting anything under
    /dev, /proc or /sys raises (module docstring)."""
    for mod, name in (
        (os, "replace"), (os, "rename"), (os, "unlink"), (shutil, "rmtree"), (os, "mkdir"),
        (builtins, "open"),
    ):  # fmt: skip
        real = getattr(mod, name)

        def guarded(*args: Any, _real: Any = real, _name: str = name, **kw: Any) -> Any:
            paths = [a for a in args[:2] if isinstance(a, str | os.PathLike)]
            if _name == "unlink":  # a writer's own temporary may go
                paths = [a for a in paths if TEMP_SUFFIX not in os.fspath(a)]
            if _name == "open":  # reading /proc, /sys is fine
                mode = str(args[1] if len(args) > 1 else kw.get("mode", "r"))
                paths = paths[:1] if set(mode) & set("wax+") else []
            if any(_special(a) for a in paths):
                raise RuntimeError(f"test guard: {_name}{args[:2]} touches a special file")
            return _real(*args, **kw)

        monkeypatch.setattr(mod, name, guarded)


# --- the tests -----------------------------------------------------------------------------


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _tree(root: Path) -> dict[str, str]:
    """Every path under ``root`` (links not followed) with its kind and, for a regular
    file, its SHA-256: what was written, replaced or deleted shows as a difference."""
    out: dict[str, str] = {}
    for dirpath, dirs, files in os.walk(root):
        for name in (*dirs, *files):
            p = Path(dirpath) / name
            if p.is_symlink():
                out[str(p)] = f"link {os.readlink(p)}"
            elif p.is_file():
                out[str(p)] = f"file {_sha(p)}"
            else:
                out[str(p)] = f"mode {p.lstat().st_mode:o}"
    return out


def _copy_inputs(c: Command, assets: Path, tmp: Path) -> dict[str, Path]:
    d = tmp / "in"
    d.mkdir()
    return {n: Path(shutil.copy2(assets / n, d / n)) for n in c.inputs}


@pytest.mark.parametrize(("command", "attack"), CASES, ids=[f"{n}-{a.__name__}" for n, a in CASES])
def test_refused_before_anything_is_written(
    command: str,
    attack: AttackFn,
    assets: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    machine_guard: None,
) -> None:
    c = BY_NAME[command]
    inputs = _copy_inputs(c, assets, tmp_path)
    a = attack(c, inputs, tmp_path)
    assert a is not None
    before = {p: _sha(p) for p in inputs.values()}
    tree = _tree(tmp_path)
    capsys.readouterr()
    with _alarm(60):
        code = main(c.argv(inputs, a.output))
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert code == 2, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    for w in a.words:
        assert w in lines[0], (w, lines[0])
    assert {p: _sha(p) for p in inputs.values()} == before  # no input changed
    assert _tree(tmp_path) == tree  # nothing written, replaced or deleted


def test_export_c_into_the_models_folder_under_another_name_runs(
    assets: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The allowed neighbour of ``export-c cal.c -o .``: the folder holds the model, the
    files written are not it: they are written and the model is unchanged."""
    model = Path(shutil.copy2(assets / "cal.json", tmp_path / "cal.json"))
    before = _sha(model)
    assert main(["export-c", str(model), "-o", str(tmp_path)]) == 0, capsys.readouterr().err
    assert (tmp_path / "cal.c").is_file() and (tmp_path / "cal.h").is_file()
    assert _sha(model) == before


def test_px4_tempcal_into_the_logs_folder_runs(
    assets: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A folder command may write into the folder holding its input (it replaces only the
    files of its own set there): the log stays as it was."""
    log = Path(shutil.copy2(assets / "log.ulg", tmp_path / "log.ulg"))
    before = _sha(log)
    code = main(["px4-tempcal", str(log), "-o", str(tmp_path), "--allow-narrow", "--allow-motion"])
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "px4.params").is_file()
    assert _sha(log) == before


def test_a_stale_temporary_of_a_dead_writer_is_still_removed(
    assets: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """INTERFACE common rules: a later run to the same output removes its own stale
    temporaries (those that are no input)."""
    rec = Path(shutil.copy2(assets / "rec.csv", tmp_path / "rec.csv"))
    out = tmp_path / "m.json"
    stale = tmp_path / f".m.json.4999999.deadbeef{TEMP_SUFFIX}"
    stale.write_text("half a model")
    code = main(["fit", str(rec), "--model", "poly", "--order", "1", "--signal", "gx",
                 "--signal-unit", "deg/s", "--time-unit", "s", "--temps", "T1",
                 "--temp-unit", "degC", "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    assert out.is_file() and not stale.exists()
