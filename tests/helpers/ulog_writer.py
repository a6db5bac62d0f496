"""A minimal PX4 ULog writer for tests, written from the ULog file-format description
(docs.px4.io, "ULog File Format"): the 16-byte header, a flag-bits message, one format
message per topic, one add-logged message per instance and the data messages — so the
reader is tested on a file not made by the library it uses."""

from __future__ import annotations

import struct
from collections.abc import Mapping, Sequence

TYPE_CODES = {"uint64_t": "Q", "uint32_t": "I", "int32_t": "i", "float": "f", "uint8_t": "B"}
SENSOR_FIELDS = [
    ("uint64_t", "timestamp"), ("uint32_t", "device_id"), ("float", "x"), ("float", "y"),
    ("float", "z"), ("float", "temperature"),
]  # fmt: skip


def _code(type_name: str) -> str:
    """``float`` → ``f``; an array ``float[3]`` → ``3f`` (its elements given one by one in a
    row, as the format stores them)."""
    base, _, count = type_name.partition("[")
    return (count.rstrip("]") if count else "") + TYPE_CODES[base]


def ulog_bytes(
    topics: Sequence[tuple[str, int, Sequence[tuple[str, str]], Sequence[Sequence[float]]]],
    params: Mapping[str, float | int] | None = None,
    changed: Sequence[tuple[str, float | int]] = (),
) -> bytes:
    """``topics``: (name, instance, fields [(type, name)], rows) → the ULog file's bytes;
    ``params``: initial parameters (``P`` messages: ``uint8 key_len``, ``"<type> <name>"``,
    the value; an ``int`` as ``int32_t``, a ``float`` as ``float``); ``changed``: parameters
    set during the recording (the same ``P`` messages in the data section, after the data)."""
    out = bytearray(b"ULog\x01\x12\x35" + bytes([1]) + struct.pack("<Q", 0))

    def msg(kind: str, payload: bytes) -> None:
        out.extend(struct.pack("<HB", len(payload), ord(kind)))
        out.extend(payload)

    msg("B", bytes(16) + struct.pack("<3Q", 0, 0, 0))

    def param(pname: str, value: float | int) -> None:
        typed = ("int32_t " if isinstance(value, int) else "float ") + pname
        code = "<i" if isinstance(value, int) else "<f"
        msg("P", bytes([len(typed)]) + typed.encode() + struct.pack(code, value))

    for pname, value in (params or {}).items():
        param(pname, value)
    seen: set[str] = set()
    for name, _inst, fields, _rows in topics:
        if name not in seen:
            seen.add(name)
            msg("F", (name + ":" + "".join(f"{t} {n};" for t, n in fields)).encode())
    for msg_id, (name, inst, _fields, _rows) in enumerate(topics):
        msg("A", struct.pack("<BH", inst, msg_id) + name.encode())
    for msg_id, (_name, _inst, fields, rows) in enumerate(topics):
        code = "<" + "".join(_code(t) for t, _n in fields)
        for row in rows:
            msg("D", struct.pack("<H", msg_id) + struct.pack(code, *row))
    for pname, value in changed:
        param(pname, value)
    return bytes(out)
