"""Every command on arbitrary small recordings ends in exit 0 or 2, never 1, never a
traceback (issue 14).  Hypothesis draws recordings of 0–50 rows with NaN, inf, huge and
tiny values, repeated and backwards times and constant columns.
Issue 26: the log readers (inspect --topic, px4-tempcal, ardupilot-tempcal) on a small valid
ULog or DataFlash log with random bytes flipped, a run zeroed or randomised, or cut."""

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
    if command not in ("compensate", "validate"):
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
