"""A fast reader of a clean PX4 ULog's data messages, giving the same ``pyulog.ULog`` object
as pyulog's own parse (pyulog's per-message Python loop takes ≈ 2 s of a 50 MB log).

ULog file format (docs.px4.io, "ULog File Format"): a 16-byte header, then messages of
``uint16 msg_size, uint8 msg_type`` and ``msg_size`` bytes of payload.  The definitions
section (``B`` flag bits, ``F`` formats, ``I``/``M`` information, ``P`` parameters, ``Q``
defaults) is parsed by pyulog itself (``parse_header_only=True``).  In the data section:
``A`` add subscription (``uint8 multi_id, uint16 msg_id, char name[]``), ``D`` data
(``uint16 msg_id`` and the payload of the format), ``P`` changed parameter, ``O`` dropout
(``uint16 duration`` [ms]), ``L``/``C`` logged strings, ``S`` sync, ``I``/``M``/``Q``,
``R`` remove subscription.

Here the data section's message chain is walked reading only each message's size (one
``struct.unpack_from`` a message), the rare messages are handled in file order with pyulog's
own message classes, and each subscribed topic's data payloads are gathered at once (a
view of the file whose element ``i`` is the ``itemsize`` bytes at offset ``i``, indexed by
the payloads' offsets), then turned into ``ULog.Data`` by pyulog (its dtype, its field
names: nested formats and arrays flattened as ``a.b[0]``, trailing ``_padding`` dropped).

The result is taken only for a clean log, else :func:`fast_ulog` returns None and the caller
parses with pyulog as before (so its notes and warnings about damage are unchanged): the
definitions parse said nothing and found no corruption, no appended data, the chain ends
exactly at the end of the file, every message type is known, every ``D`` message's msg_id has
an ``A`` before it (or is filtered out by name) with a payload size pyulog accepts, no msg_id
is subscribed twice, every subscribed format has a ``uint64_t timestamp``.
"""

from __future__ import annotations

import contextlib
import mmap
import os
import struct
from array import array
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from thermocal.readers.common import TrackedReader, library_output_captured

_HEADER = struct.Struct("<H")
_KNOWN = {ord(c) for c in "ADPOLCSIMQR"}
_SYNC_BYTES = 8
"""Length of ULog's sync marker: a payload shorter than it cannot hold one (pyulog searches
an unknown message's payload for it)."""


RUN_STREAK, RUN_MIN, RUN_MAX = 8, 32, 1 << 16
"""Runs of equal sizes (:func:`message_offsets`): messages of one size in a row before the
next ones are checked together, how many at the first try, and at most (each full run
doubles it)."""


def message_offsets(buf: bytes | mmap.mmap, start: int) -> tuple[np.ndarray, int]:
    """Offsets (int64) of the messages of ``buf`` from ``start`` (``uint16`` size, ``uint8``
    type, payload) and the position after the last one (``len(buf)`` for a chain that ends
    exactly at the end of the file).

    The chain is walked one message at a time; where two messages in a row have the same
    size (a logger writing one topic's messages back to back), the next ones are taken as
    far as their sizes are that size too, checked together (:func:`_run`): the same
    offsets, without a Python step per message.

    Parameters
    ----------
    buf : bytes or mmap.mmap
        The whole file.
    start : int
        Byte offset of the first message (the end of the definitions section).

    Returns
    -------
    tuple of (numpy.ndarray, int)
        The messages' byte offsets and the byte position after the last message.

    Examples
    --------
    >>> from thermocal.readers.ulog_fast import message_offsets
    >>> buf = bytes([2, 0, ord("D"), 7, 7, 0, 0, ord("S")])
    >>> offsets, end = message_offsets(buf, 0)
    >>> offsets.tolist(), end
    ([0, 5], 8)

    References
    ----------
    - PX4 Autopilot, *ULog File Format*, PX4 User Guide (docs.px4.io,
      ``dev_log/ulog_file_format``).
    """
    unpack = _HEADER.unpack_from
    sizes = np.frombuffer(buf, dtype=np.uint8)
    out = array("q")  # compact and faster to append to than a list
    add = out.append
    pos = start
    last = len(buf) - 3
    prev, streak, k = -1, 0, RUN_MIN
    while pos <= last:
        add(pos)
        size = unpack(buf, pos)[0]
        pos += 3 + size
        if size != prev:
            prev = size
            streak = 0
            continue
        streak += 1
        if streak < RUN_STREAK:
            continue
        run, pos = _run(sizes, pos, size, last, k)
        out.frombytes(run.tobytes())
        # a full run: try a longer one next; a short one (sizes mixed): wait for a streak
        k, streak = (min(2 * k, RUN_MAX), streak) if run.size == k else (RUN_MIN, 0)
    return np.frombuffer(out, dtype=np.int64), pos


def _run(arr: np.ndarray, pos: int, size: int, last: int, k: int) -> tuple[np.ndarray, int]:
    """Up to ``k`` messages from ``pos`` (a message's start) whose size is ``size``: their
    offsets (int64), and the start of the message after them (the first of another size, or
    the end).  Each offset is a message's start because the ones before it have that size."""
    step = 3 + size
    k = min(k, (last - pos) // step + 1) if pos <= last else 0
    at = pos + step * np.arange(k, dtype=np.int64)
    same = (arr[at] | (arr[at + 1].astype(np.int64) << 8)) == size
    m = int(np.argmin(same)) if k and not same.all() else k
    return at[:m], pos + m * step


def _u16(arr: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Little-endian ``uint16`` at the byte offsets ``at`` of the byte array ``arr`` (as
    int64), gathered through a view of ``arr`` whose element ``i`` is the ``uint16`` at byte
    ``i`` (a stride of one byte)."""
    every = np.ndarray((max(arr.size - 1, 0),), "<u2", arr, 0, (1,))
    out: np.ndarray = every[at].astype(np.int64)
    return out


def _rows(buf: mmap.mmap, at: np.ndarray, itemsize: int) -> np.ndarray:
    """The ``itemsize`` bytes at each offset ``at`` of ``buf``, as one contiguous (n,)
    array of ``V<itemsize>``, gathered through a view of ``buf`` whose element ``i`` is the
    ``itemsize`` bytes from byte ``i`` (a stride of one byte)."""
    every = np.ndarray((len(buf) - itemsize + 1,), f"V{itemsize}", buf, 0, (1,))
    out: np.ndarray = every[at]
    return out


def fast_ulog(path: Path, names: Sequence[str] | None) -> Any | None:
    """The ``pyulog.ULog`` of ``path`` with the topics ``names`` (all when None), equal to
    ``ULog(path, message_name_filter_list=names)``, or None when the log is not clean (see
    the module's docstring): the caller then parses it with pyulog.

    Parameters
    ----------
    path : pathlib.Path
        The ULog file.
    names : sequence of str or None
        Topics to keep; ``None``: all.

    Returns
    -------
    pyulog.ULog or None
        The parsed log, or ``None`` when the log is damaged or has no data section.

    References
    ----------
    - PX4 Autopilot, *ULog File Format*, PX4 User Guide (docs.px4.io,
      ``dev_log/ulog_file_format``).
    """
    from pyulog import ULog

    fh = TrackedReader(path)  # pyulog closes it where its definitions parse stopped
    try:
        with library_output_captured() as noise:
            ulog = ULog(fh, message_name_filter_list=names, parse_header_only=True)
    except Exception:  # the caller's pyulog parse says what is wrong
        return None
    finally:
        fh.close()
    if noise.summary("pyulog") or ulog.file_corruption or ulog.has_data_appended:
        return None
    with open(path, "rb") as raw:
        if fh.stopped_at is None or os.fstat(raw.fileno()).st_size <= fh.stopped_at:
            return None  # no data section: pyulog's parse says what there is
        buf = mmap.mmap(raw.fileno(), 0, access=mmap.ACCESS_READ)
    try:
        offsets, end = message_offsets(buf, fh.stopped_at)
        if end != len(buf):
            return None
        return _fill(ulog, buf, offsets, names)
    except Exception:  # anything unexpected: pyulog's own parse, which says what is wrong
        return None
    finally:
        with contextlib.suppress(BufferError):  # no view of the file is left: copies only
            buf.close()


def _fill(ulog: Any, buf: mmap.mmap, offs: np.ndarray, names: Sequence[str] | None) -> Any | None:
    """Give ``ulog`` (definitions parsed) its data section from the messages at ``offs``,
    as pyulog's own data parse does; None when something is not clean."""
    ULog = type(ulog)

    arr = np.frombuffer(buf, dtype=np.uint8)
    types = arr[offs + 2] if offs.size else np.zeros(0, np.uint8)
    if not set(np.flatnonzero(np.bincount(types, minlength=256)).tolist()) <= _KNOWN:
        return None
    rare = offs[types != ord("D")]
    data_at = offs[types == ord("D")]
    subs, filtered, sub_at, steps = _rare_messages(ulog, buf, rare, names)
    if subs is None:
        return None
    ids = _u16(arr, data_at + 3)
    sizes = _u16(arr, data_at) - 2
    if sizes.size and sizes.min() < 0:  # no room for the msg_id: pyulog stops reading
        return None
    first = np.full(1 << 16, -1, dtype=np.int64)
    first[ids[::-1]] = data_at[::-1]  # repeated indices: the last assignment wins
    for msg_id in np.flatnonzero(first >= 0).tolist():
        since = sub_at.get(msg_id, filtered.get(msg_id))
        if since is None or first[msg_id] < since:
            return None  # a data message without a subscription before it
    stamp = np.zeros(data_at.size, dtype=np.uint64)
    for msg_id, sub in subs.items():
        if first[msg_id] < 0:
            continue
        pick = ids == msg_id
        size = sizes[pick]
        item = sub.dtype.itemsize
        if size.min() < item or size.max() > sub.max_data_size:
            return None
        sub.buffer = _rows(buf, data_at[pick] + 5, item).view(np.uint8)
        stamp[pick] = np.frombuffer(sub.buffer, sub.dtype)["timestamp"]
    _timestamps(ulog, data_at, stamp, steps)
    data = [ULog.Data(sub) for sub in subs.values() if len(sub.buffer) > 0]
    ulog._data_list = sorted(data, key=lambda d: (d.name, d.multi_id))
    ulog._filtered_message_ids = set(filtered)
    return ulog


_Step = tuple[int, str, Any]
"""(file offset, kind, object) of a changed parameter (``P``) or dropout (``O``): their
timestamp is the last data timestamp before them, set by :func:`_timestamps`."""


def _rare_messages(
    ulog: Any, buf: mmap.mmap, rare: np.ndarray, names: Sequence[str] | None
) -> tuple[dict[int, Any] | None, dict[int, int], dict[int, int], list[_Step]]:
    """Every message of the data section but ``D``, in file order, handled as pyulog's data
    parse does (with its message classes): the subscriptions (msg_id → ``_MessageAddLogged``
    with the offset of its ``A``), the msg_ids filtered out by name (→ offset), and the
    changed parameters and dropouts to be given their timestamps.  None subscriptions: not
    clean (an ``A`` of an msg_id seen before, a message pyulog would search for a sync
    marker)."""
    ULog = type(ulog)

    subs: dict[int, Any] = {}
    filtered: dict[int, int] = {}
    sub_at: dict[int, int] = {}
    steps: list[_Step] = []
    header = ULog._MessageHeader()
    for pos in rare.tolist():
        header.initialize(buf[pos : pos + 3])
        typ = chr(header.msg_type)
        data = buf[pos + 3 : pos + 3 + header.msg_size]
        if typ == "A":
            sub = ULog._MessageAddLogged(data, header, ulog._message_formats)
            if sub.msg_id in subs or sub.msg_id in filtered:
                return None, filtered, sub_at, steps
            if names is None or sub.message_name in names:
                stamp = [f for f in sub.field_data if f.field_name == "timestamp"]
                if not stamp or stamp[0].type_str != "uint64_t":
                    return None, filtered, sub_at, steps
                subs[sub.msg_id], sub_at[sub.msg_id] = sub, pos
            else:
                filtered[sub.msg_id] = pos
        elif typ in "IMQ":
            _info(ulog, typ, data, header)
        elif typ == "P":
            steps.append((pos, "P", ULog._MessageInfo(data, header)))
        elif typ == "O":
            steps.append((pos, "O", ULog.MessageDropout(data, header, 0)))
        elif typ == "L":
            ulog._logged_messages.append(ULog.MessageLogging(data, header))
        elif typ == "C":
            msg = ULog.MessageLoggingTagged(data, header)
            ulog._logged_messages_tagged.setdefault(msg.tag, []).append(msg)
        elif typ == "S":
            ulog._sync_seq_cnt += 1
        elif header.msg_size >= _SYNC_BYTES:  # R: pyulog skips it unless a sync fits in
            return None, filtered, sub_at, steps
    return subs, filtered, sub_at, steps


def _info(ulog: Any, typ: str, data: bytes, header: Any) -> None:
    """An information (``I``), multiple information (``M``) or default parameter (``Q``)
    message of the data section, stored as pyulog stores it."""
    ULog = type(ulog)

    if typ == "I":
        msg = ULog._MessageInfo(data, header)
        ulog._msg_info_dict[msg.key] = msg.value
        ulog._msg_info_dict_types[msg.key] = msg.type
    elif typ == "M":
        ulog._add_message_info_multiple(ULog._MessageInfo(data, header, is_info_multiple=True))
    else:
        ulog._add_parameter_default(ULog._MessageParameterDefault(data, header))


def _timestamps(ulog: Any, data_at: np.ndarray, stamp: np.ndarray, steps: list[_Step]) -> None:
    """pyulog's ``last_timestamp`` (the largest data timestamp of the subscribed topics, at
    least the header's), and the timestamp of each changed parameter and dropout: the
    largest such timestamp before it in the file (the header's when larger).  ``stamp``:
    the timestamp of each data message at ``data_at`` (0 for topics not subscribed)."""
    first = int(ulog._start_timestamp)
    if steps:
        upto = np.maximum.accumulate(stamp) if stamp.size else stamp
        for pos, kind, obj in steps:
            k = int(np.searchsorted(data_at, pos))
            when = max(first, int(upto[k - 1])) if k else first
            if kind == "P":
                ulog._changed_parameters.append((when, obj.key, obj.value))
            else:
                obj.timestamp = when
                ulog._dropouts.append(obj)
    ulog._last_timestamp = max(first, int(stamp.max())) if stamp.size else first


__all__ = ["fast_ulog", "message_offsets"]
