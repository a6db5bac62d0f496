"""Hostile flight-controller logs through the command line (issue 26, item 5).

PX4 ULog files are built by :mod:`ulog_writer` (and the real PX4 sample log in tests/data),
ArduPilot DataFlash files by :mod:`dataflash_writer`; then damaged here.  Attack classes:

* **unreadable** — empty, text, random bytes, a bare header: exit 2 with one ``error:``;
* **truncated** — a log cut inside a message: a ``warning:`` that it is cut;
* **damaged** — one zeroed ULog message length (pyulog silently stops reading there), a
  block of garbage inside a ULog, a zeroed block inside a DataFlash log (pymavlink prints a
  ``bad header`` line per byte): one ``warning:`` saying how much was lost, computed here
  independently, and nothing of the library's own output on the terminal;
* **left-out sensors** — instances whose temperature is all 0 or NaN are named in a
  warning; the second IMU of an older DataFlash log (message ``IMU2``, no ``I`` field) is
  calibrated, not dropped;
* **partial sets** — when a later sensor cannot be fitted, px4-tempcal and
  ardupilot-tempcal write nothing (no reports of the earlier sensors without the
  calibration), and leave other files of an existing DIR alone.

Every run: exit 0 or 2, never 1; no traceback; input files unchanged byte for byte; no
temporary output left; a 60 s alarm against hangs.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import signal
import struct
import warnings
from collections.abc import Iterator
from pathlib import Path
from types import FrameType

import numpy as np
import pytest

from dataflash_writer import FMT_TYPE, IMU_FMT, IMU_LABELS, data_message, fmt_message, imu_log
from thermocal.cli import main
from thermocal.outputs import TEMP_SUFFIX
from ulog_writer import SENSOR_FIELDS, ulog_bytes

SAMPLE_LOG = Path(__file__).parent.parent / "data" / "pyulog_sample_log_small.ulg"
N = 6000
DT_S = 0.1
"""Rows of a sweep log: 600 s at 10 Hz, the temperature 10 → 50 °C."""


def _sweep(
    n: int = N, lo_c: float = 10.0, hi_c: float = 50.0, seed: int = 3
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(time [µs], temperature [°C], gyro [rad/s] (n, 3), accel [m/s²] (n, 3))."""
    rng = np.random.default_rng(seed)
    t_s = np.arange(n) * DT_S
    temp = lo_c + (hi_c - lo_c) * t_s / t_s[-1]
    x = (temp - 30.0) / 20.0
    gyro = np.column_stack([0.002 * x, -0.001 * x, 0.0005 * x**2]) + rng.normal(0, 2e-4, (n, 3))
    accel = np.column_stack([0.05 * x, -0.03 * x, -9.80665 + 0.1 * x]) + rng.normal(0, 0.01, (n, 3))
    return (1e6 + t_s * 1e6).astype(np.int64), temp, gyro, accel


def _ulog_rows(
    ts: np.ndarray, temp: np.ndarray, v: np.ndarray, device: int
) -> list[tuple[float, ...]]:
    return [
        (int(s), device, *map(float, row), float(tt))
        for s, row, tt in zip(ts, v, temp, strict=True)
    ]


def _good_ulog(extra: list[tuple[str, int, np.ndarray]] | None = None) -> bytes:
    """sensor_gyro.0 and sensor_accel.0 over a 40 °C sweep; ``extra``: (topic, instance,
    temperature) of more instances with the same signals."""
    ts, temp, gyro, accel = _sweep()
    topics = [
        ("sensor_gyro", 0, SENSOR_FIELDS, _ulog_rows(ts, temp, gyro, 2293768)),
        ("sensor_accel", 0, SENSOR_FIELDS, _ulog_rows(ts, temp, accel, 2293776)),
    ]
    for name, inst, t_c in extra or []:
        v = gyro if name == "sensor_gyro" else accel
        topics.append((name, inst, SENSOR_FIELDS, _ulog_rows(ts, t_c, v, 2293800 + inst)))
    return ulog_bytes(topics)


def _imu_rows(inst: int, temp: np.ndarray, with_i: bool = True) -> list[tuple[float, ...]]:
    ts, _t, gyro, accel = _sweep(seed=10 + inst)
    return [
        (int(s), *([inst] if with_i else []), *map(float, g), *map(float, a), 0, 0, float(tt))
        for s, g, a, tt in zip(ts, gyro, accel, temp, strict=True)
    ]


def _good_bin(n_imu: int = 1) -> bytes:
    temp = _sweep()[1]
    rows = [r for k in range(n_imu) for r in _imu_rows(k, temp)]
    return imu_log(sorted(rows, key=lambda r: r[0]))


IMU_MSG_LEN = 3 + struct.calcsize("<QBffffffIIf")
"""Bytes of one IMU message of :mod:`dataflash_writer` (header included)."""
HEADER_LEN = 2 * (3 + struct.calcsize("<BB4s16s64s"))
"""Bytes of the two FMT messages that start a :func:`dataflash_writer.imu_log`."""


def _ulog_messages(raw: bytes) -> Iterator[tuple[int, int, str]]:
    """(offset, payload size, type) of each message of a ULog (ULog file format: a 16-byte
    header, then messages of ``<uint16 size><uint8 type><payload>``)."""
    pos = 16
    while pos + 3 <= len(raw):
        size, typ = struct.unpack_from("<HB", raw, pos)
        yield pos, size, chr(typ)
        pos += 3 + size


def _topic_data_offsets(raw: bytes, name: str, inst: int) -> list[int]:
    """Offsets of the data messages of one topic instance."""
    ids = set()
    out = []
    for off, size, typ in _ulog_messages(raw):
        if typ == "A":
            multi, msg_id = struct.unpack_from("<BH", raw, off + 3)
            if raw[off + 6 : off + 3 + size].decode() == name and multi == inst:
                ids.add(msg_id)
        elif typ == "D" and struct.unpack_from("<H", raw, off + 3)[0] in ids:
            out.append(off)
    return out


# --- running ----------------------------------------------------------------------------------


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


@contextlib.contextmanager
def _alarm(seconds: int = 60) -> Iterator[None]:
    def hung(_sig: int, _frame: FrameType | None) -> None:
        raise TimeoutError(f"no result after {seconds} s")

    old = signal.signal(signal.SIGALRM, hung)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _run(
    argv: list[str], inputs: list[Path], capfd: pytest.CaptureFixture[str]
) -> tuple[int, str, str]:
    """Run the CLI in-process (file-descriptor output captured too: what a log library
    prints there counts); check the contract common to every attack."""
    before = {p: _digest(p) for p in inputs}
    with warnings.catch_warnings(), _alarm():
        warnings.simplefilter("ignore")
        code = main(argv)
    out, err = capfd.readouterr()
    assert "Traceback" not in err
    assert code in (0, 2), f"exit {code}: {err[-3000:]}"
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert all(ln.startswith(("warning: ", "error: ")) for ln in lines), err[:3000]
    if code == 2:
        assert lines and lines[-1].startswith("error: "), err
        assert "internal" not in lines[-1]
    assert {p: _digest(p) for p in inputs} == before, "an input file changed"
    for p in inputs:
        assert not list(p.parent.rglob(f"*{TEMP_SUFFIX}")), "a temporary output is left"
    return code, out, err


def _warnings(err: str) -> list[str]:
    return [ln for ln in err.splitlines() if ln.startswith("warning: ")]


# --- unreadable -------------------------------------------------------------------------------

UNREADABLE = {
    "empty": b"",
    "text": b"time,gyro,T1\n0,1,2\n" * 20,
    "random": bytes(np.random.default_rng(1).integers(0, 256, 5000, dtype=np.uint8)),
    "ulog-header-only": b"ULog\x01\x12\x35\x01" + bytes(8),
    "ulog-header-cut": b"ULog\x01\x12",
}


@pytest.mark.parametrize("content", sorted(UNREADABLE))
@pytest.mark.parametrize(
    "command",
    ["px4-tempcal", "inspect-ulg", "ardupilot-tempcal", "inspect-bin"],
)
def test_an_unreadable_log_is_refused(
    command: str, content: str, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    ext = ".bin" if command.endswith(("bin", "ardupilot-tempcal")) else ".ulg"
    log = tmp_path / f"log{ext}"
    log.write_bytes(UNREADABLE[content])
    if command.startswith("inspect"):
        argv = ["inspect", str(log), "--topic", "IMU.0" if ext == ".bin" else "sensor_gyro.0"]
    else:
        argv = [command, str(log), "-o", str(tmp_path / "out")]
    code, _out, err = _run(argv, [log], capfd)
    assert code == 2, err
    assert str(log) in err.splitlines()[-1]
    assert len(err.splitlines()) < 5, "the library's own messages reach the terminal"
    assert not (tmp_path / "out").exists()


# --- truncated --------------------------------------------------------------------------------


def test_a_ulog_cut_inside_a_message_says_so(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    raw = _good_ulog()
    log = tmp_path / "cut.ulg"
    log.write_bytes(raw[:-7])  # the last message loses 7 of its bytes
    code, _out, err = _run(["px4-tempcal", str(log), "-o", str(tmp_path / "out")], [log], capfd)
    assert code == 0, err
    assert any("cut" in w and "last message" in w for w in _warnings(err)), err


def test_a_dataflash_log_cut_inside_a_message_says_so(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    raw = _good_bin()
    log = tmp_path / "cut.bin"
    log.write_bytes(raw[:-7])
    code, _out, err = _run(
        ["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")], [log], capfd
    )
    assert code == 0, err
    # the cut message: its first IMU_MSG_LEN - 7 bytes are at the end, not a whole message
    assert any(f"last {IMU_MSG_LEN - 7:,} bytes" in w for w in _warnings(err)), err


# --- damaged ----------------------------------------------------------------------------------


def test_a_zeroed_message_length_in_the_real_px4_log_says_what_is_lost(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """pyulog reads the zero-length message, fails on its empty payload and stops reading
    the file there, silently: 90 % of the topic are gone.  The warning gives the share of
    the file not read: (size − (offset + 3)) / size, the 3 bytes being the header read."""
    raw = bytearray(SAMPLE_LOG.read_bytes())
    offsets = _topic_data_offsets(bytes(raw), "vehicle_angular_velocity", 0)
    assert len(offsets) == 1812
    off = offsets[len(offsets) // 10]
    raw[off : off + 2] = b"\x00\x00"
    log = tmp_path / "zeroed.ulg"
    log.write_bytes(bytes(raw))
    argv = ["inspect", str(log), "--topic", "vehicle_angular_velocity.0", "--json"]
    code, out, err = _run(argv, [log], capfd)
    assert code == 0, err
    share = 100.0 * (len(raw) - (off + 3)) / len(raw)
    damage = [w for w in _warnings(err) if "the log is damaged" in w]
    assert len(damage) == 1, err
    assert f"{share:.1f} %" in damage[0], (share, damage)
    assert json.loads(out)["n_samples"] == len(offsets) // 10


def test_a_zeroed_message_length_in_a_tempcal_log_is_said(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    raw = bytearray(_good_ulog())
    offsets = _topic_data_offsets(bytes(raw), "sensor_gyro", 0)
    off = offsets[len(offsets) // 2]
    raw[off : off + 2] = b"\x00\x00"
    log = tmp_path / "zeroed.ulg"
    log.write_bytes(bytes(raw))
    code, _out, err = _run(["px4-tempcal", str(log), "-o", str(tmp_path / "out")], [log], capfd)
    share = 100.0 * (len(raw) - (off + 3)) / len(raw)
    assert any(f"{share:.1f} %" in w for w in _warnings(err)), err
    assert code in (0, 2)


def test_garbage_inside_a_ulog_is_said(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    """100 data messages overwritten with random bytes: pyulog flags the file, may resync or
    stop; the warning says so (not that the file is cut: it is whole), and pyulog's own
    messages do not reach the terminal."""
    raw = bytearray(_good_ulog())
    offsets = _topic_data_offsets(bytes(raw), "sensor_gyro", 0)
    a, b = offsets[1000], offsets[1100]
    raw[a:b] = bytes(np.random.default_rng(7).integers(0, 256, b - a, dtype=np.uint8))
    log = tmp_path / "garbage.ulg"
    log.write_bytes(bytes(raw))
    argv = ["inspect", str(log), "--topic", "sensor_gyro.0", "--json"]
    code, out, err = _run(argv, [log], capfd)
    damage = [w for w in _warnings(err) if "the log is damaged" in w]
    assert len(damage) == 1, err
    assert "pyulog found damaged messages" in damage[0]
    assert "cut" not in damage[0]
    assert code == 0, err
    assert json.loads(out)["n_samples"] == 1000  # the messages before the garbage
    assert "not read" in damage[0] or "misses about" in damage[0]


def test_a_zeroed_block_in_a_dataflash_log_is_one_warning(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A third of the IMU messages zeroed: pymavlink prints one ``bad header`` line per
    byte (128 000 lines); the command prints one warning giving the bytes lost, exactly the
    zeroed messages' bytes, and their share of the file."""
    raw = bytearray(_good_bin())
    first, k = N // 3, N // 3
    a = HEADER_LEN + first * IMU_MSG_LEN
    b = a + k * IMU_MSG_LEN
    raw[a:b] = bytes(b - a)
    log = tmp_path / "zeroed.bin"
    log.write_bytes(bytes(raw))
    argv = ["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")]
    code, out, err = _run(argv, [log], capfd)
    assert "bad header" not in out
    assert len(err.splitlines()) < 12, err[:2000]
    damage = [w for w in _warnings(err) if "the log is damaged" in w]
    assert len(damage) == 1, err[:2000]
    assert f"{b - a:,} bytes ({100.0 * (b - a) / len(raw):.1f} % of the file)" in damage[0]
    assert code == 0, err


# --- left-out sensors -------------------------------------------------------------------------


def test_sensors_without_a_temperature_are_named(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    temp = _sweep()[1]
    log = tmp_path / "three.ulg"
    log.write_bytes(
        _good_ulog(
            [
                ("sensor_gyro", 1, np.zeros_like(temp)),
                ("sensor_accel", 1, np.full_like(temp, np.nan)),
            ]
        )
    )
    out_dir = tmp_path / "out"
    code, out, err = _run(["px4-tempcal", str(log), "-o", str(out_dir), "--json"], [log], capfd)
    assert code == 0, err
    left = [w for w in _warnings(err) if "left out" in w]
    assert len(left) == 1, err
    assert "sensor_gyro.1 (temperature all 0)" in left[0]
    assert "sensor_accel.1 (temperature all NaN)" in left[0]
    assert sorted(json.loads(out)["sensors"]) == ["sensor_accel.0", "sensor_gyro.0"]


def _legacy_bin() -> bytes:
    """An older DataFlash layout: IMU (no ``I`` field) and IMU2 for the second IMU."""
    fmt = IMU_FMT.replace("QB", "Q", 1)
    labels = tuple(x for x in IMU_LABELS if x != "I")
    temp = _sweep()[1]
    out = bytearray(fmt_message(FMT_TYPE, "FMT", "BBnNZ", ("Type", "Length", "Name", "Format",
                                                           "Columns")))  # fmt: skip
    out += fmt_message(100, "IMU", fmt, labels)
    out += fmt_message(101, "IMU2", fmt, labels)
    for r0, r1 in zip(_imu_rows(0, temp, False), _imu_rows(1, temp, False), strict=True):
        out += data_message(100, fmt, r0)
        out += data_message(101, fmt, r1)
    return bytes(out)


def test_the_second_imu_of_an_older_dataflash_log_is_calibrated(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "legacy.bin"
    log.write_bytes(_legacy_bin())
    out_dir = tmp_path / "out"
    argv = ["ardupilot-tempcal", str(log), "-o", str(out_dir), "--json"]
    code, out, err = _run(argv, [log], capfd)
    assert code == 0, err
    assert sorted(json.loads(out)["sensors"]) == [
        "IMU.Acc.0", "IMU.Acc.1", "IMU.Gyr.0", "IMU.Gyr.1"
    ]  # fmt: skip
    assert (out_dir / "report_IMU_1_gyro.html").is_file()
    parm = (out_dir / "ardupilot.parm").read_text()
    assert "INS_TCAL2_ENABLE" in parm


# --- partial sets -----------------------------------------------------------------------------


@pytest.mark.parametrize("existing", [False, True], ids=["new-dir", "existing-dir"])
def test_px4_tempcal_writes_nothing_when_a_later_sensor_fails(
    existing: bool, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """sensor_gyro.1 sweeps 2 °C (4 bins of 0.5 °C, a cubic needs 8): exit 2, and neither
    the reports of sensor_accel.0 and sensor_gyro.0 fitted before it nor a staging
    directory are left; a file already in DIR is untouched."""
    temp = _sweep()[1]
    log = tmp_path / "log.ulg"
    log.write_bytes(_good_ulog([("sensor_gyro", 1, 20.0 + 2.0 * (temp - 10.0) / 40.0)]))
    out_dir = tmp_path / "out"
    keep = out_dir / "notes.txt"
    if existing:
        out_dir.mkdir()
        keep.write_text("mine\n")
    code, _out, err = _run(["px4-tempcal", str(log), "-o", str(out_dir)], [log], capfd)
    assert code == 2, err
    assert "sensor_gyro.1" in err.splitlines()[-1]
    if existing:
        assert sorted(p.name for p in out_dir.iterdir()) == ["notes.txt"]
        assert keep.read_text() == "mine\n"
    else:
        assert not out_dir.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["log.ulg", *(["out"] if existing else [])]
    )


def test_ardupilot_tempcal_writes_nothing_when_a_later_imu_fails(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    temp = _sweep()[1]
    narrow = 20.0 + 2.0 * (temp - 10.0) / 40.0
    rows = sorted(_imu_rows(0, temp) + _imu_rows(1, narrow), key=lambda r: r[0])
    log = tmp_path / "log.bin"
    log.write_bytes(imu_log(rows))
    out_dir = tmp_path / "out"
    code, _out, err = _run(["ardupilot-tempcal", str(log), "-o", str(out_dir)], [log], capfd)
    assert code == 2, err
    assert not out_dir.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["log.bin"]


def test_a_complete_set_joins_an_existing_dir(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "log.ulg"
    log.write_bytes(_good_ulog())
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    (out_dir / "notes.txt").write_text("mine\n")
    code, _out, err = _run(["px4-tempcal", str(log), "-o", str(out_dir)], [log], capfd)
    assert code == 0, err
    assert sorted(p.name for p in out_dir.iterdir()) == [
        "calibration.json", "notes.txt", "px4.params", "report_sensor_accel_0.html",
        "report_sensor_gyro_0.html",
    ]  # fmt: skip
    assert (out_dir / "notes.txt").read_text() == "mine\n"
    assert not [w for w in _warnings(err) if "damaged" in w or "left out" in w], err


def test_whole_logs_give_no_damage_warning(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """No false alarm: the real PX4 sample log and a whole DataFlash log read without one."""
    argv = ["inspect", str(SAMPLE_LOG), "--topic", "vehicle_angular_velocity.0"]
    code, _out, err = _run(argv, [SAMPLE_LOG], capfd)
    assert code == 0 and "damaged" not in err, err
    log = tmp_path / "whole.bin"
    log.write_bytes(_good_bin(2))
    code, _out, err = _run(["inspect", str(log), "--topic", "IMU.1"], [log], capfd)
    assert code == 0 and "damaged" not in err, err
