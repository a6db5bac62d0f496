"""The fast ULog reader (:mod:`thermocal.readers.ulog_fast`, issue 28 item 4's time): on
every clean log it gives pyulog's own ``ULog`` bit for bit (every field of every topic asked,
same dtype; parameters, changed parameters with their timestamps, dropouts, logged strings),
and every damaged log is left to pyulog (so its damage notes stay as they were).

The logs: :mod:`ulog_writer`'s (written from the format description), a richer one built
here from the ULog file-format description (docs.px4.io, "ULog File Format": nested formats,
arrays, a trailing ``_padding`` field, two instances interleaved, a topic not asked for,
information, changed parameters, dropouts, logged and tagged strings, sync and remove
messages in the data section), PX4's real sample log in tests/data, and the benchmark's hard
log (benchmarks/bench_px4_algorithm.py, small size)."""

from __future__ import annotations

import struct
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.readers import ulog as ulog_mod
from thermocal.readers import ulog_fast
from ulog_writer import SENSOR_FIELDS, ulog_bytes

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import bench_px4_algorithm as bench

SAMPLE_LOG = Path(__file__).parents[1] / "data" / "pyulog_sample_log_small.ulg"


def _msg(kind: str, payload: bytes) -> bytes:
    """One ULog message: ``uint16 msg_size, uint8 msg_type``, the payload."""
    return struct.pack("<HB", len(payload), ord(kind)) + payload


def _info(kind: str, typed_key: str, value: bytes, prefix: bytes = b"") -> bytes:
    """An ``I``/``P``/``M``/``Q`` message: ``[prefix] uint8 key_len, "<type> <name>", value``."""
    return _msg(kind, prefix + bytes([len(typed_key)]) + typed_key.encode() + value)


def _rich_log(padded: bool = False) -> bytes:
    """A log with what real PX4 logs have: a nested format (``vec3``), arrays of a basic
    and of a nested type, an int8/uint16/double/bool mix, a trailing ``_padding0`` (written
    with the padding when ``padded``, else trimmed as PX4's logger does; pyulog skips padded
    payloads as damaged), two instances of
    ``imu_like`` interleaved with a third topic (``other2``), and rare messages in the data
    section."""
    out = bytearray(b"ULog\x01\x12\x35\x01" + struct.pack("<Q", 1_000))
    out += _msg("B", bytes(16) + struct.pack("<3Q", 0, 0, 0))
    out += _info("I", "char[7] sys_name", b"PX4_sim")
    out += _info("P", "float CAL_GYRO0_XOFF", struct.pack("<f", 0.25))
    out += _info("P", "int32_t SENS_EN_THERMAL", struct.pack("<i", 1))
    out += _msg("F", b"vec3:float x;float y;float z;")
    out += _msg(
        "F",
        b"imu_like:uint64_t timestamp;vec3 rate;vec3[2] pair;float[3] acc;int8_t k;"
        b"uint16_t count;double temp;bool ok;uint8_t[3] _padding0;",
    )
    out += _msg("F", b"other2:uint64_t timestamp;int32_t[2] v;")
    out += _msg("A", struct.pack("<BH", 0, 3) + b"imu_like")
    out += _msg("A", struct.pack("<BH", 0, 9) + b"other2")
    imu = "<Q3f6f3fbHd?" + ("3x" if padded else "")
    rng = np.random.default_rng(28)
    for i in range(300):
        t = 2_000 + 1000 * i
        for inst, msg_id in ((0, 3), (1, 4)):
            if inst == 1 and i == 0:
                continue
            v = rng.normal(0, 1, 12).astype(np.float32).tolist()
            row = struct.pack(imu, t + inst, *v, -3 + inst, i, 20.0 + 0.01 * i, i % 2 == 0)
            out += _msg("D", struct.pack("<H", msg_id) + row)
        out += _msg("D", struct.pack("<H", 9) + struct.pack("<Q2i", t + 5, i, -i))
        if i == 0:
            out += _msg("A", struct.pack("<BH", 1, 4) + b"imu_like")
        if i == 50:
            out += _info("P", "float CAL_GYRO0_XOFF", struct.pack("<f", 0.5))
            out += _msg("L", b"6" + struct.pack("<Q", t) + b"sensors: temperature rising")
        if i == 80:
            out += _msg("O", struct.pack("<H", 120))
            out += _msg("C", b"4" + struct.pack("<HQ", 7, t) + b"tagged")
            out += _msg("S", b"\x2f\x73\x13\x20\x25\x0c\xbb\x12")
        if i == 120:
            out += _info("I", "uint32_t boot_count", struct.pack("<I", 12))
            out += _info("M", "char[3] perf", b"abc", prefix=b"\x00")
            out += _msg("R", struct.pack("<H", 9))
    return bytes(out)


def _sensor_log() -> bytes:
    """:mod:`ulog_writer`'s layout: sensor_gyro 0/1 and sensor_accel 0 with parameters."""
    topics = []
    for name, inst in (("sensor_gyro", 0), ("sensor_gyro", 1), ("sensor_accel", 0)):
        rows = [(1_000_000 + 4000 * i, 2293768 + inst, 0.001 * i, -0.5, 1e-7 * i, 20.0 + 0.001 * i)
                for i in range(500)]  # fmt: skip
        topics.append((name, inst, SENSOR_FIELDS, rows))
    return ulog_bytes(topics, params={"TC_G_ENABLE": 1, "IMU_GYRO_RATEMAX": 400.0})


def _assert_same(fast: Any, slow: Any) -> None:
    """``fast`` is pyulog's ``slow``, bit for bit."""
    assert [(d.name, d.multi_id) for d in fast.data_list] == [
        (d.name, d.multi_id) for d in slow.data_list
    ]
    for f, s in zip(fast.data_list, slow.data_list, strict=True):
        assert list(f.data) == list(s.data)
        for key, want in s.data.items():
            got = f.data[key]
            assert got.dtype == want.dtype, (f.name, key)
            assert got.tobytes() == want.tobytes(), (f.name, key)
        assert [(x.field_name, x.type_str) for x in f.field_data] == [
            (x.field_name, x.type_str) for x in s.field_data
        ]
    assert fast.initial_parameters == slow.initial_parameters
    assert fast.changed_parameters == slow.changed_parameters
    assert [(d.timestamp, d.duration) for d in fast.dropouts] == [
        (d.timestamp, d.duration) for d in slow.dropouts
    ]
    assert [(m.timestamp, m.message) for m in fast.logged_messages] == [
        (m.timestamp, m.message) for m in slow.logged_messages
    ]
    assert fast.msg_info_dict == slow.msg_info_dict
    assert fast.last_timestamp == slow.last_timestamp
    assert not fast.file_corruption
    assert fast == slow  # pyulog's own comparison: every attribute of the object


def _clean_logs(tmp_path: Path) -> dict[str, Path]:
    out = {"sample": SAMPLE_LOG}
    for name, raw in (
        ("rich", _rich_log()),
        ("sensors", _sensor_log()),
        ("bench_small", bench.hard_log(bench.SIZES["small"])[0]),
    ):
        out[name] = tmp_path / f"{name}.ulg"
        out[name].write_bytes(raw)
    return out


NAMES: dict[str, list[list[str] | None]] = {
    "sample": [None, ["sensor_combined", "vehicle_attitude"], ["no_such_topic"]],
    "rich": [None, ["imu_like"], ["other2"]],
    "sensors": [None, ["sensor_gyro"], ["sensor_gyro", "sensor_accel", "sensor_baro"]],
    "bench_small": [["sensor_gyro", "sensor_accel", "sensor_baro", "sensor_mag"]],
}


def test_the_fast_reader_gives_pyulogs_object_bit_for_bit(tmp_path: Path) -> None:
    from pyulog import ULog

    logs = _clean_logs(tmp_path)
    for key, path in logs.items():
        for names in NAMES[key]:
            fast = ulog_fast.fast_ulog(path, names)
            assert fast is not None, (key, names)
            _assert_same(fast, ULog(str(path), message_name_filter_list=names))
    # what the rich log holds, stated here: both instances, nested and array fields named
    # as pyulog names them, the padding gone, rare messages stamped by the data before them
    rich = ulog_fast.fast_ulog(logs["rich"], ["imu_like"])
    assert rich is not None
    (i0, i1) = rich.data_list
    assert (i0.data["timestamp"].size, i1.data["timestamp"].size) == (300, 299)
    assert {"rate.x", "pair[1].z", "acc[2]", "k", "count", "temp", "ok"} <= set(i0.data)
    assert not any(k.startswith("_padding") for k in i0.data)
    assert i0.data["count"].tolist() == list(range(300))
    assert i1.data["k"].tolist() == [-2] * 299
    assert rich.changed_parameters == [(2_000 + 1000 * 50 + 1, "CAL_GYRO0_XOFF", 0.5)]
    assert [(d.timestamp, d.duration) for d in rich.dropouts] == [(2_000 + 1000 * 80 + 1, 120)]


def _damaged(tmp_path: Path) -> dict[str, Path]:
    """Logs the fast reader must leave to pyulog, with why."""
    good = _sensor_log()
    d_at = [off for off, size, typ in _messages(good) if typ == "D"]
    mid = d_at[len(d_at) // 2]
    cases: dict[str, bytes] = {
        "cut": good[:-7],
        "zeroed length": good[:mid] + b"\x00\x00" + good[mid + 2 :],
        "garbage": good[:mid]
        + bytes(np.random.default_rng(7).integers(0, 256, 400, dtype=np.uint8))
        + good[mid + 400 :],
        "unknown type": good[:mid] + good[mid : mid + 2] + b"Z" + good[mid + 3 :],
        "no subscription": good[:mid] + _msg("D", struct.pack("<H", 77) + bytes(36)) + good[mid:],
        "short payload": good[:mid] + _msg("D", struct.pack("<H", 0) + bytes(20)) + good[mid:],
        "trailing byte": good + b"\x01",
        # pyulog takes a payload longer than its format less the trailing padding as damaged
        "padding written": _rich_log(padded=True),
        # no data section at all (definitions only): nothing to gain, pyulog reads it
        "definitions only": good[: next(o for o, _s, t in _messages(good) if t == "A")],
    }
    cases["appended data"] = (
        good[:16]
        + _msg("B", bytes(8) + bytes([1]) + bytes(7) + struct.pack("<3Q", len(good) - 100, 0, 0))
        + good[16 + 3 + 40 :]
    )
    out = {}
    for name, raw in cases.items():
        out[name] = tmp_path / (name.replace(" ", "_") + ".ulg")
        out[name].write_bytes(raw)
    return out


def _messages(raw: bytes) -> list[tuple[int, int, str]]:
    """(offset, payload size, type) of each message after the 16-byte header."""
    pos, out = 16, []
    while pos + 3 <= len(raw):
        size, typ = struct.unpack_from("<HB", raw, pos)
        out.append((pos, size, chr(typ)))
        pos += 3 + size
    return out


def test_damaged_logs_take_pyulogs_path_and_keep_their_notes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    taken: list[Any] = []
    real = ulog_fast.fast_ulog

    def spy(path: Path, names: Any) -> Any:
        taken.append(real(path, names))
        return taken[-1]

    monkeypatch.setattr(ulog_fast, "fast_ulog", spy)
    said = {}
    for why, path in _damaged(tmp_path).items():
        taken.clear()
        try:
            read = ulog_mod._parse_ulog_file(path, ["sensor_gyro", "imu_like"])
        except Exception as exc:  # pyulog refuses the file: that is its say, unchanged
            said[why] = str(exc)
        else:
            said[why] = " ".join(read.notes)
            assert read.damaged == bool(read.notes), why
        assert taken == [None], why  # the fast reader declined: pyulog parsed it
    assert "cut" in said["cut"] and "cut" in said["trailing byte"]
    assert "stopped at byte" in said["zeroed length"]
    for why in ("garbage", "no subscription", "short payload", "padding written"):
        assert "damaged messages" in said[why], why
    # pyulog skips a message of a type it does not know (a newer logger's) without a word,
    # and reads appended data its own way: the fast reader leaves both to it all the same
    assert said["unknown type"] == said["definitions only"] == ""
    # a clean log takes the fast path: the object returned is the fast reader's
    taken.clear()
    clean = tmp_path / "clean.ulg"
    clean.write_bytes(_sensor_log())
    read = ulog_mod._parse_ulog_file(clean, ["sensor_gyro"])
    assert len(taken) == 1 and read.ulog is taken[0] is not None
    assert (read.damaged, read.skipped, read.notes) == (False, False, ())


def _walk(buf: bytes, start: int) -> tuple[list[int], int]:
    """The message chain walked one message at a time (the file format's definition)."""
    out, pos = [], start
    while pos <= len(buf) - 3:
        out.append(pos)
        pos += 3 + struct.unpack_from("<H", buf, pos)[0]
    return out, pos


def test_message_offsets_along_runs_of_one_size() -> None:
    # runs of equal sizes (longer than the streak that starts a run check, longer than a
    # first check, ending one message after a check), mixed sizes, empty payloads, a cut end
    rng = np.random.default_rng(41)
    for trial in range(200):
        parts = []
        while sum(map(len, parts)) < 30_000:
            size = int(rng.choice([0, 1, 5, 28, 40, 300]))
            reps = int(rng.choice([1, 2, 9, 33, 41, 700]))
            payload = bytes(rng.integers(0, 256, size, dtype=np.uint8))
            parts.append(_msg("D", payload) * reps)
        buf = b"".join(parts)
        buf = buf[: len(buf) - int(rng.integers(0, 40))]
        for start in (0, 3):
            want, end = _walk(buf, start)
            got, got_end = ulog_fast.message_offsets(buf, start)
            assert (got.tolist(), got_end) == (want, end), (trial, start)
