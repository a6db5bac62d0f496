"""The fixed-format DataFlash parser reads a sound log to pymavlink's values (every field
type, the scaled ones divided as pymavlink divides them, parameters and their floors), and
leaves a damaged log to pymavlink, which skips the damage and says so."""

from __future__ import annotations

import struct
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("pymavlink")

from dataflash_writer import FMT_TYPE, HEAD, PARM_FORMAT, dataflash_log, parm
from thermocal.errors import PlausibilityWarning
from thermocal.readers import dataflash
from thermocal.readers.common import LogDamageWarning

ALL_FMT = "QBbhHiIfdcCeELMg"
"""Every numeric DataFlash format character (LogStructure.h) but ``q`` (in ``TXT``: an FMT
holds 16 characters)."""
ALL_LABELS = ("TimeUS", "I", "b", "h", "H", "i", "I4", "f", "d", "c", "C", "e", "E", "L", "M", "g")
ALL_STRUCT = "<QBbhHiIfdhHiIibe"
TXT_STRUCT = "<Qq16s"


def _fmt(msg_type: int, name: str, fmt: str, labels: tuple[str, ...], length: int) -> bytes:
    """An FMT message (``<BB4s16s64s>``) stating ``length`` (header included)."""
    body = struct.pack("<BB4s16s64s", msg_type, length, name.encode(), fmt.encode(),
                       ",".join(labels).encode())  # fmt: skip
    return HEAD + bytes([FMT_TYPE]) + body


def _all_message(rng: np.random.Generator, t_us: int, inst: int) -> bytes:
    vals = (t_us, inst, int(rng.integers(-128, 128)), int(rng.integers(-32768, 32768)),
            int(rng.integers(0, 65536)), int(rng.integers(-2**31, 2**31)),
            int(rng.integers(0, 2**32)), float(rng.normal()), float(rng.normal()) * 1e3,
            int(rng.integers(-32768, 32768)), int(rng.integers(0, 65536)),
            int(rng.integers(-2**31, 2**31)), int(rng.integers(0, 2**32)),
            int(rng.integers(-1_800_000_000, 1_800_000_000)), int(rng.integers(-128, 128)),
            float(rng.normal()))  # fmt: skip
    txt = struct.pack(TXT_STRUCT, t_us, int(rng.integers(-(2**62), 2**62)), b"abc")
    return HEAD + bytes([100]) + struct.pack(ALL_STRUCT, *vals) + HEAD + bytes([101]) + txt


def _log(tmp: Path, n: int = 300) -> tuple[Path, list[bytes]]:
    rng = np.random.default_rng(7)
    body = dataflash_log([PARM_FORMAT], [parm("INS_TCAL1_ENABLE", 1, 1000),
                                         parm("LOG_BITMASK", 5, 1000)])  # fmt: skip
    body += _fmt(100, "ALL", ALL_FMT, ALL_LABELS, 3 + struct.calcsize(ALL_STRUCT))
    body += _fmt(101, "TXT", "QqN", ("TimeUS", "q", "Name"), 3 + struct.calcsize(TXT_STRUCT))
    raw = [_all_message(rng, 1_000_000 + 10_000 * k, k % 3) for k in range(n)]
    head = HEAD + bytes([129])
    later = head + struct.pack("<Q16sf", 1_500_000, b"INS_TCAL1_ENABLE", 0.0)  # stamped back
    path = tmp / "all.bin"
    path.write_bytes(body + b"".join(raw[: n // 2]) + later + b"".join(raw[n // 2 :]))
    return path, raw


def _no_pymavlink(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    from pymavlink import DFReader

    opened: list[str] = []
    real = DFReader.DFReader_binary

    def counting(filename: str, *args: Any, **kwargs: Any) -> Any:
        opened.append(filename)
        return real(filename, *args, **kwargs)

    monkeypatch.setattr(DFReader, "DFReader_binary", counting)
    return opened


def test_every_field_type_reads_to_pymavlinks_values(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path, raw = _log(tmp_path)
    opened = _no_pymavlink(monkeypatch)
    with pytest.warns(PlausibilityWarning, match="clock went backwards"):
        fast = dataflash.read_dataflash_log(path, ["ALL", "TXT"])
    assert opened == []  # a sound log: pymavlink not asked
    with pytest.warns(PlausibilityWarning, match="clock went backwards"):
        ref = dataflash._pymavlink_pass(path, ["ALL", "TXT"])
    assert opened == [str(path)]
    for name in ("ALL", "TXT"):
        got, want = fast.message_rows(name), ref.rows[name]
        assert len(got) == len(want) == len(raw)
        for g, w in zip(got, want, strict=True):
            assert list(g) == list(w) and g == w  # the same fields, bit for bit
    assert "Name" not in got[0] and got[0]["q"] == float(struct.unpack(TXT_STRUCT, raw[0][-32:])[1])
    got = fast.message_rows("ALL")
    # the scaled fields, from the bytes written: c/C/e/E ÷ 100, L ÷ 1e7 (as pymavlink divides)
    first = struct.unpack(ALL_STRUCT, raw[0][3 : 3 + struct.calcsize(ALL_STRUCT)])
    assert got[0]["c"] == first[9] / 100.0 and got[0]["E"] == first[12] / 100.0
    assert got[0]["L"] == first[13] / (1 / 1.0e-7) and got[0]["f"] == first[7]
    assert fast.params == ref.params == {"INS_TCAL1_ENABLE": 1.0, "LOG_BITMASK": 5.0}
    assert fast.param_changes == ref.param_changes
    (change,) = fast.param_changes  # floored at the last sample logged before it
    assert change.time_s == pytest.approx((1_000_000 + 10_000 * 149) * 1e-6, abs=1e-12)
    assert fast.names_seen == ref.names_seen == {"FMT", "PARM", "ALL", "TXT"}
    df, info = dataflash.dataflash_table(fast, path, "ALL", 2)
    df_ref, info_ref = dataflash.dataflash_table(ref, path, "ALL", 2)
    assert info == info_ref and len(df) == 100
    np.testing.assert_array_equal(df.to_numpy(), df_ref.to_numpy())
    assert list(df.columns) == list(df_ref.columns)


def test_padding_at_the_end_is_no_damage(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path, _raw = _log(tmp_path, 40)
    path.write_bytes(path.read_bytes() + b"\xff" * 300)
    opened = _no_pymavlink(monkeypatch)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        warnings.simplefilter("error", LogDamageWarning)
        log = dataflash.read_dataflash_log(path, ["ALL"])
    assert opened == [] and log.notes == () and len(log.message_rows("ALL")) == 40


def test_a_damaged_log_is_left_to_pymavlink(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path, raw = _log(tmp_path, 200)
    data = bytearray(path.read_bytes())
    at = len(data) - 60 * len(raw[0])
    data[at : at + 10 * len(raw[0])] = bytes(10 * len(raw[0]))  # ten messages zeroed
    path.write_bytes(bytes(data))
    opened = _no_pymavlink(monkeypatch)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        log = dataflash.read_dataflash_log(path, ["ALL"])
    damage = [w for w in seen if issubclass(w.category, LogDamageWarning)]
    assert len(damage) == 1 and "not whole messages" in str(damage[0].message)
    assert opened == [str(path)]
    assert len(log.message_rows("ALL")) == 190


def test_a_format_of_the_wrong_length_is_left_to_pymavlink(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "bad.bin"  # ALL says 20 bytes; its fields take 12
    fmts = _fmt(FMT_TYPE, "FMT", "BBnNZ", ("Type", "Length", "Name", "Format", "Columns"), 89)
    path.write_bytes(
        fmts + _fmt(100, "ALL", "QB", ("TimeUS", "I"), 20) + (HEAD + b"d" + bytes(17)) * 5
    )
    opened = _no_pymavlink(monkeypatch)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dataflash.read_dataflash_log(path, ["ALL"])
    assert opened == [str(path)]


def test_a_message_start_inside_a_payload_is_not_a_message(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Payload bytes that read ``A3 95 <type>`` (a message start, an FMT start) are passed
    over by the walk at once, as by pymavlink's reader."""
    path, raw = _log(tmp_path, 60)
    data = bytearray(path.read_bytes())
    size = struct.calcsize(ALL_STRUCT)
    for k, fake in ((5, b"\xa3\x95\x64\x00"), (17, b"\xa3\x95\x80\x64"), (30, b"\xa3\x95\x81\x00")):
        at = data.index(raw[k]) + 3 + struct.calcsize("<QBbhHi")  # the I4 field
        data[at : at + 4] = fake
        raw[k] = bytes(data[at - 3 - struct.calcsize("<QBbhHi") : at + size])
    path.write_bytes(bytes(data))
    u8 = np.frombuffer(bytes(data), np.uint8)
    at_once = dataflash._walk_at_once(bytes(data), u8)
    walked = dataflash._walk(bytes(data))
    assert at_once is not None and walked is not None
    assert at_once[0].tolist() == walked[0] and at_once[2] == walked[2] == len(data)
    opened = _no_pymavlink(monkeypatch)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        fast = dataflash.read_dataflash_log(path, ["ALL"])
        ref = dataflash._pymavlink_pass(path, ["ALL"])
    assert opened == [str(path)]  # the second read only
    assert fast.message_rows("ALL") == ref.rows["ALL"] and len(ref.rows["ALL"]) == 60
    assert fast.message_rows("ALL")[5]["I4"] == float(0x0064_95A3)
