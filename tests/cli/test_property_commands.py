"""Every command on arbitrary small recordings ends in exit 0 or 2, never 1, never a
traceback (issue 14).  Hypothesis draws recordings of 0–50 rows with NaN, inf, huge and
tiny values, repeated and backwards times and constant columns.
Issue 26: the log readers (inspect --topic, px4-tempcal, ardupilot-tempcal) on a small valid
ULog or DataFlash log with random bytes flipped, a run zeroed or randomised, or cut; ``fleet``
on random small configurations (bad keys, wrong types, missing files, odd ids: exit 0, 2 or 4,
inputs unchanged) and ``export-params`` on random calibrations and options (exit 0 or 2)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from thermocal.cli import main

SPECIAL = [np.nan, np.inf, -np.inf, 1e300, -1e300, 1e-300, 0.0, -0.0, 65535.0, -273.16]


@st.composite
def recordings(draw: st.DrawFn) -> str:
    """A CSV text with columns time, gyro, T1."""
    n = draw(st.integers(0, 50))
    time_kind = draw(st.sampled_from(["regular", "repeated", "backwards", "gappy", "special"]))
    t = np.arange(n, dtype=float)
    if n and time_kind == "repeated":
        t[n // 2 :] = t[n // 2]
    elif n and time_kind == "backwards":
        t = t[::-1].copy()
    elif n and time_kind == "gappy":
        t[n // 2 :] += 1000.0
    elif n and time_kind == "special":
        t[draw(st.integers(0, n - 1))] = draw(st.sampled_from(SPECIAL))
    cols = []
    for _ in range(2):
        kind = draw(st.sampled_from(["normal", "constant", "special", "huge"]))
        x = np.asarray(draw(st.lists(st.floats(-10, 10), min_size=n, max_size=n)), dtype=float)
        if kind == "constant":
            x[:] = 1.0
        elif kind == "special" and n:
            k = draw(st.integers(1, n))
            x[:k] = draw(st.sampled_from(SPECIAL))
        elif kind == "huge":
            x *= 1e200
        cols.append(x)
    lines = ["time,gyro,T1"]
    lines += [
        ",".join(repr(float(v)).replace("nan", "") for v in row)
        for row in zip(t, *cols, strict=True)
    ]
    return "\n".join(lines) + "\n"


COMMANDS: dict[str, list[str]] = {
    "inspect": ["inspect", "{f}", "--signal", "gyro", "--temps", "T1"],
    "metrics": ["metrics", "{f}", "--signal", "gyro", "--temps", "T1", "--average", "2"],
    "allan": ["allan", "{f}", "--signal", "gyro"],
    "fit": ["fit", "{f}", "--model", "poly", "--order", "1", "--signal", "gyro",
            "--temps", "T1", "-o", "{o}.json"],
    "fit-piecewise": ["fit", "{f}", "--model", "piecewise", "--segments", "2", "--signal", "gyro",
                      "--temps", "T1", "-o", "{o}.json"],
    "compensate": ["compensate", "{m}", "{f}", "-o", "{o}.csv"],
    "validate": ["validate", "{m}", "{f}"],
    "ratetable": ["ratetable", "{f}", "--gyro", "gyro", "--gyro-unit", "deg/s", "--time-unit",
                  "s", "--temps", "T1", "--rates=-10,10", "--min-plateau", "1", "--window", "1"],
    "tumble": ["tumble", "{f}", "--accel", "gyro", "--accel-unit", "mg", "--time-unit", "s",
               "--angle-column", "T1", "--angle-unit", "deg", "--min-station", "1"],
}  # fmt: skip
UNITS = ["--signal-unit", "deg/h", "--time-unit", "s"]
TEMP_UNITS = ["--temp-unit", "degC"]


@pytest.fixture(scope="module")
def model(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("prop")
    n = 200
    temp = np.linspace(0.0, 40.0, n)
    rows = [f"{i},{float(0.01 * x + 0.001 * np.sin(i))!r},{float(x)!r}" for i, x in enumerate(temp)]
    src = d / "fit.csv"
    src.write_text("time,gyro,T1\n" + "\n".join(rows) + "\n")
    out = d / "m.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(["fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
                     "--temps", "T1", "-o", str(out), *UNITS, *TEMP_UNITS])  # fmt: skip
    assert code == 0
    return out


@pytest.mark.parametrize("command", sorted(COMMANDS))
@settings(
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(text=recordings())
def test_every_command_exits_0_or_2(
    command: str,
    text: str,
    model: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    f = tmp_path / "rec.csv"
    f.write_text(text)
    args = [a.format(f=f, o=tmp_path / "out", m=model) for a in COMMANDS[command]]
    if command not in ("compensate", "validate", "ratetable", "tumble"):
        args += UNITS + TEMP_UNITS
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numerical warnings are shown as warning: lines
        code = main(args)
    _, err = capsys.readouterr()
    assert code in (0, 2), err
    assert "Traceback" not in err
    if code == 2:
        assert err.strip().splitlines()[-1].startswith("error: "), err


# --- flight-controller logs (issue 26): random damage to a small valid log ------------------


def _small_logs() -> dict[str, bytes]:
    """A valid ULog (sensor_gyro.0, 200 samples at 10 Hz, 10 → 50 °C) and DataFlash log (the
    same as IMU.0), written by the test writers."""
    from dataflash_writer import imu_log
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    n = 200
    ts = (1e6 + np.arange(n) * 1e5).astype(np.int64)
    temp = np.linspace(10.0, 50.0, n)
    ulog_rows = [
        (int(s), 7, 0.001 * float(x), 0.0, 0.0, float(x)) for s, x in zip(ts, temp, strict=True)
    ]
    bin_rows = [
        (int(s), 0, 0.001 * float(x), 0.0, 0.0, 0.0, 0.0, -9.8, 0, 0, float(x))
        for s, x in zip(ts, temp, strict=True)
    ]
    return {
        ".ulg": ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, ulog_rows)]),
        ".bin": imu_log(bin_rows),
    }


SMALL_LOGS = _small_logs()


@st.composite
def damaged(draw: st.DrawFn, raw: bytes) -> bytes:
    """``raw`` with random damage: bytes flipped, a run zeroed or randomised, or cut."""
    out = bytearray(raw)
    kind = draw(st.sampled_from(["flip", "zero-run", "random-run", "truncate", "mixed"]))
    if kind in ("flip", "mixed"):
        for _ in range(draw(st.integers(1, 20))):
            out[draw(st.integers(0, len(out) - 1))] = draw(st.integers(0, 255))
    if kind in ("zero-run", "random-run", "mixed"):
        a = draw(st.integers(0, len(out) - 1))
        b = min(len(out), a + draw(st.integers(1, 4000)))
        fill = (
            bytes(b - a) if kind == "zero-run" else draw(st.binary(min_size=b - a, max_size=b - a))
        )
        out[a:b] = fill
    if kind in ("truncate", "mixed"):
        out = out[: draw(st.integers(0, len(out)))]
    return bytes(out)


LOG_COMMANDS: dict[str, tuple[str, list[str]]] = {
    "inspect-ulg": (".ulg", ["inspect", "{f}", "--topic", "sensor_gyro.0"]),
    "inspect-bin": (".bin", ["inspect", "{f}", "--topic", "IMU.0"]),
    "px4-tempcal": (".ulg", ["px4-tempcal", "{f}", "-o", "{o}"]),
    "ardupilot-tempcal": (".bin", ["ardupilot-tempcal", "{f}", "-o", "{o}"]),
}


@pytest.mark.parametrize("command", sorted(LOG_COMMANDS))
@settings(
    max_examples=20,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_damaged_logs_exit_0_or_2(
    command: str, data: st.DataObject, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    ext, argv = LOG_COMMANDS[command]
    f = tmp_path / f"log{ext}"
    f.write_bytes(data.draw(damaged(SMALL_LOGS[ext])))
    args = [a.format(f=f, o=tmp_path / "out") for a in argv]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(args)
    _, err = capfd.readouterr()
    assert code in (0, 2), err[-2000:]
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert all(ln.startswith(("warning: ", "error: ")) for ln in lines), err[:2000]
    if code == 2:
        assert lines[-1].startswith("error: "), err


# --- fleet (issue 26 item 9): random small configurations -----------------------------------

FLEET_DATA = "time [s],gx [deg/s],T1 [degC]\n" + "".join(
    f"{i},{0.5 + 0.002 * (t - 25.0) + 0.001 * np.sin(i)!r},{t!r}\n"
    for i, t in enumerate(np.linspace(-10.0, 60.0, 300).tolist())
)
"""A still gyro swept −10 → 60 °C (300 s at 1 Hz): enough for ``poly --order 1``."""

_TOML_VALUES = st.one_of(
    st.sampled_from(['"poly"', '"gx [deg/s]"', '"T1 [degC]"', "1", "0", "-3", "2.5", "true",
                     '""', "[]", '["gx [deg/s]"]', "{}", '"nan"', "1e309", '"../x"']),
)  # fmt: skip
_FIT_KEYS = ["model", "order", "signal", "temps", "signal_unit", "time", "no_such_option",
             "ridge", "select", "rate_interval"]  # fmt: skip
_IDS = ["U1", "U2", "u-3", "U1", "U2", "u-3", "", "../up", "a/b", ".hidden", "x" * 300, "Ü"]
_FILES = ["run.csv"] * 4 + ["missing.csv", "../run.csv", "", "run.parquet", "cfg.toml"]


def _toml_str(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


@st.composite
def fleet_configs(draw: st.DrawFn) -> str:
    """A TOML batch: a usable [fit] with random keys replaced, added or dropped (values of
    any type), 0–3 units with odd ids, missing or repeated files, and a stray table."""
    fit = {"model": '"poly"', "order": "1", "signal": '"gx [deg/s]"', "temps": '"T1 [degC]"'}
    for _ in range(draw(st.sampled_from([0, 0, 0, 1, 2]))):  # a usable [fit] half the time
        key = draw(st.sampled_from(_FIT_KEYS))
        if draw(st.booleans()):
            fit[key] = draw(_TOML_VALUES)
        else:
            fit.pop(key, None)
    lines = ["[fit]"] + [f"{_toml_str(k)} = {v}" for k, v in fit.items()]
    if draw(st.integers(0, 3)) == 0:
        key = draw(st.sampled_from(["rms_residual_max", "rms_residual_max", "x", "rms_min"]))
        lines += ["[limits]", f"{key} = {draw(st.sampled_from(['1.0', '1e-9', '-1', 'true']))}"]
    if draw(st.integers(0, 3)) == 0:
        averaging = draw(st.sampled_from(["10", "10", "-1", '"x"']))
        lines += ["[validate]", f"averaging = {averaging}"]
    for _ in range(draw(st.sampled_from([0, 1, 1, 2, 3]))):
        lines.append("[[unit]]")
        if draw(st.integers(0, 5)):
            lines.append(f"id = {_toml_str(draw(st.sampled_from(_IDS)))}")
        kind = draw(st.sampled_from(["list", "list", "list", "string", "number", "none"]))
        files = [draw(st.sampled_from(_FILES)) for _ in range(draw(st.sampled_from([1, 1, 2, 0])))]
        if kind == "list":
            lines.append(f"modeling = [{', '.join(_toml_str(f) for f in files)}]")
        elif kind == "string":
            lines.append(f"modeling = {_toml_str(files[0] if files else 'run.csv')}")
        elif kind == "number":
            lines.append("modeling = 3")
        if draw(st.integers(0, 3)) == 0:
            lines.append(f"validation = {_toml_str(draw(st.sampled_from(_FILES)))}")
        if draw(st.integers(0, 4)) == 0:
            lines.append(f"{_toml_str(draw(st.sampled_from(['colour', 'id'])))} = 1")
    return "\n".join(lines) + "\n"


@settings(
    max_examples=20,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(text=fleet_configs())
def test_fleet_exits_0_2_or_4(
    text: str, tmp_path_factory: pytest.TempPathFactory, capsys: pytest.CaptureFixture[str]
) -> None:
    """``thermocal fleet`` on a random configuration: exit 0 (all calibrated), 4 (some units
    failed, each recorded) or 2 (refused, one ``error:`` line), never 1; no input changes."""
    import hashlib

    d = tmp_path_factory.mktemp("fleet-prop")
    (d / "run.csv").write_text(FLEET_DATA)
    cfg = d / "cfg.toml"
    cfg.write_text(text, encoding="utf-8")
    inputs = [d / "run.csv", cfg]
    before = [hashlib.sha256(p.read_bytes()).hexdigest() for p in inputs]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(["fleet", str(cfg), "-o", str(d / "out"), "--workers", "1"])
    _, err = capsys.readouterr()
    assert code in (0, 2, 4), err[-2000:]
    assert "Traceback" not in err
    if code == 2:
        assert err.strip().splitlines()[-1].startswith("error: "), err
    assert [hashlib.sha256(p.read_bytes()).hexdigest() for p in inputs] == before


# --- export-params (issue 26 item 9): random calibrations and options -----------------------


@pytest.fixture(scope="module")
def params_calibration(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """Gyros gx, gy, gz [deg/s] and accelerometers ax, ay, az [mg] (+z up), cubic in T1,
    10 → 40 °C over 400 s."""
    d = tmp_path_factory.mktemp("params-prop")
    rng = np.random.default_rng(9)
    n = 400
    t = np.arange(n, dtype=float)
    temp = 10.0 + 30.0 * t / (n - 1)
    cols = {"time": t, "T1": temp}
    for k, c in enumerate(("gx", "gy", "gz")):
        cols[c] = 0.1 * k + 0.01 * (temp - 25.0) + rng.normal(0.0, 0.001, n)
    for c, g in zip(("ax", "ay", "az"), (0.0, 0.0, 1000.0), strict=True):
        cols[c] = g + 0.3 * (temp - 25.0) + rng.normal(0.0, 0.5, n)
    lines = [",".join(cols)] + [
        ",".join(repr(float(v)) for v in row) for row in zip(*cols.values(), strict=True)
    ]
    (d / "d.csv").write_text("\n".join(lines) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(["fit", str(d / "d.csv"), "--model", "poly", "--order", "3", "--signal",
                     "gx,gy,gz,ax,ay,az", "--signal-unit", "deg/s,deg/s,deg/s,mg,mg,mg",
                     "--time-unit", "s", "--temps", "T1", "--temp-unit", "degC",
                     "--gravity-axis", "+z", "--gravity", "9.80665",
                     "-o", str(d / "cal.json")])  # fmt: skip
    assert code == 0
    return (d / "cal.json").read_bytes()


_CHANNEL_NAMES = ["gx", "gy", "gz", "ax", "ay", "az", "nope", "", "gx "]


@st.composite
def params_options(draw: st.DrawFn) -> list[str]:
    """Format, axes maps (repeated, missing, unknown, wrong length), instance, TREF and
    device id, each drawn or left out."""
    fmts = ["px4", "ardupilot"] * 4 + ["PX4", "qgc", ""]
    args = ["--format", draw(st.sampled_from(fmts))]
    for opt, good in (("--gyro", "gx,gy,gz"), ("--accel", "ax,ay,az")):
        how = draw(st.sampled_from(["good", "good", "random", "none"]))
        if how == "good":
            args += [opt, good]
        elif how == "random":
            names = draw(st.lists(st.sampled_from(_CHANNEL_NAMES), min_size=0, max_size=4))
            args += [opt, ",".join(names)]
    if draw(st.booleans()):
        args += ["--instance", str(draw(st.sampled_from([0, 1, 2, 3, 4, -1, 99, 2**40])))]
    if draw(st.booleans()):
        args += ["--tref", draw(st.sampled_from(["25", "-300", "nan", "inf", "1e39", "40"]))]
    if draw(st.booleans()):
        args += ["--device-id", str(draw(st.sampled_from([0, 1, -1, 2**31, 2**64])))]
    return args


@st.composite
def edited_calibrations(draw: st.DrawFn, raw: bytes) -> bytes:
    """The calibration as fitted, or with one coefficient or the range edited (checksums
    recomputed, as anyone can), or its channels cut."""
    import json

    from thermocal.models.format import checksum

    cal = json.loads(raw)
    kind = draw(st.sampled_from(["as-fitted", "as-fitted", "coef", "drop-channels", "roles"]))
    chans = cal["channels"]
    if kind == "coef":
        ch = chans[draw(st.integers(0, len(chans) - 1))]
        coef = ch["model"]["state"]["coef"]
        coef[draw(st.integers(0, len(coef) - 1))] = draw(
            st.sampled_from([0.0, 1e30, -1e30, 3.4e38, 1e-300, 1e6])
        )
    elif kind == "drop-channels":
        keep = draw(st.integers(0, len(chans)))
        cal["channels"] = chans[:keep]
    elif kind == "roles":
        for ch in chans:
            ch.pop("role", None)
    for ch in cal["channels"]:
        ch["model"].pop("checksum", None)
        ch["model"]["checksum"] = checksum(ch["model"])
    cal.pop("checksum", None)
    cal["checksum"] = checksum(cal)
    return json.dumps(cal).encode()


@settings(
    max_examples=30,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_export_params_exits_0_or_2(
    data: st.DataObject,
    params_calibration: bytes,
    tmp_path_factory: pytest.TempPathFactory,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``thermocal export-params`` on a random calibration with random options: exit 0 or 2
    (one ``error:`` line, no output file), never 1; the calibration is unchanged."""
    d = tmp_path_factory.mktemp("params-prop-run")
    cal = d / "cal.json"
    raw = data.draw(edited_calibrations(params_calibration))
    cal.write_bytes(raw)
    out = d / "out.params"
    args = ["export-params", str(cal), "-o", str(out), *data.draw(params_options())]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(args)
    _, err = capsys.readouterr()
    assert code in (0, 2), err[-2000:]
    assert "Traceback" not in err
    if code == 2:
        assert err.strip().splitlines()[-1].startswith("error: "), err
        assert not out.exists()
    assert cal.read_bytes() == raw
