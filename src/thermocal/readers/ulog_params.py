"""The parameters a PX4 ULog was recorded with, read from its definitions section only.

ULog file format (docs.px4.io, "ULog File Format"): a 16-byte header (``ULog`` magic,
version, timestamp), then messages of ``uint16 msg_size, uint8 msg_type`` and a payload; the
definitions section (``B`` flags, ``F`` formats, ``I``/``M`` information, ``P`` parameters,
``Q`` defaults) ends at the first ``A`` (add logged message) or ``D`` (data).  A ``P``
message is ``uint8 key_len, char key[key_len] ("<type> <name>"), value`` with ``float`` or
``int32_t`` values.  Reading stops at the end of the definitions, so that a large log is not
read again (its topics are read by :mod:`thermocal.readers.ulog`).
"""

from __future__ import annotations

import struct
from pathlib import Path

from thermocal.outputs import refuse_special_input

ULOG_MAGIC = b"ULog\x01\x12\x35"
HEADER_BYTES = 16
VALUE_CODES = {"float": "<f", "int32_t": "<i"}


def ulog_parameters(path: str | Path) -> dict[str, float]:
    """The initial parameters (``P`` messages of the definitions section) of a ULog, name →
    value; {} for a file that is not a ULog or has none (the topic reader says why).

    Parameters
    ----------
    path : str or pathlib.Path
        The ULog file.

    Returns
    -------
    dict of str to float
        Parameter name → value (``int32_t`` and ``float`` parameters).

    Raises
    ------
    ThermocalInputError
        A special file (FIFO, device) instead of a regular file.

    References
    ----------
    - PX4 Autopilot, *ULog File Format*, PX4 User Guide (docs.px4.io,
      ``dev_log/ulog_file_format``).
    """
    out: dict[str, float] = {}
    refuse_special_input(path, "ULog")
    with open(path, "rb") as fh:
        if fh.read(HEADER_BYTES)[:7] != ULOG_MAGIC:
            return out
        while True:
            head = fh.read(3)
            if len(head) < 3:
                break
            size, kind = struct.unpack("<HB", head)
            if kind in (ord("A"), ord("D")):
                break
            payload = fh.read(size)
            if len(payload) < size:
                break
            if kind != ord("P") or not payload:
                continue
            n = payload[0]
            key = payload[1 : 1 + n].decode("utf-8", "replace")
            typ, _, name = key.partition(" ")
            code = VALUE_CODES.get(typ)
            raw = payload[1 + n :]
            if code is not None and name and len(raw) >= 4:
                out[name] = float(struct.unpack(code, raw[:4])[0])
    return out


__all__ = ["ulog_parameters"]
