"""What every reader shares: encodings, memory checks, numeric columns,
the time column's names, and the capture of log libraries' noise."""

from __future__ import annotations

import contextlib
import contextvars
import functools
import hashlib
import io
import math
import os
import re
import sys
import tempfile
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal import units
from thermocal._lazy import LazyModule
from thermocal.errors import (
    FileFormatError,
    TextEncodingWarning,
    ThermocalInputError,
    ThermocalWarning,
)
from thermocal.outputs import refuse_special_input, special_mode
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")


@functools.cache
def csv_float_options() -> dict[str, Any]:
    """``pandas.read_csv`` options that parse every decimal to the nearest float64 (pandas < 3's
    default parser can be one ulp off; pandas 3 is exact by default and deprecates the option).
    A function so that importing this module does not import pandas.

    Returns
    -------
    dict
        ``{"float_precision": "round_trip"}`` under pandas < 3, else ``{}``.
    """
    major = int(pd.__version__.split(".")[0])
    return {"float_precision": "round_trip"} if major < 3 else {}


def _head_bytes(p: Path, probe_bytes: int) -> bytes:
    """The first bytes of the text: decompressed for a name ending ``.gz`` (a file that is
    not gzip refused in one line)."""
    if not p.name.lower().endswith(".gz"):
        with open(p, "rb") as fh:
            return fh.read(probe_bytes)
    import gzip

    try:
        with gzip.open(p, "rb") as fh:
            return fh.read(probe_bytes)
    except (gzip.BadGzipFile, EOFError) as exc:
        raise FileFormatError(f"{p}: named .gz but not a readable gzip file ({exc})") from None


def csv_encoding(path: str | Path, probe_bytes: int = 1 << 16) -> str:
    """The text encoding of a CSV file: ``utf-8-sig`` (UTF-8, with or without a byte-order
    mark) when its start decodes as UTF-8, else ``latin-1`` (Western lab PCs and
    instrument software write it; a ``°`` in a header is the usual case, stated in a
    warning).  UTF-16/32 (NUL bytes) are refused with the remedy.

    Parameters
    ----------
    path : str or pathlib.Path
        The CSV file.
    probe_bytes : int, optional
        How many bytes of the start are decoded [bytes]; default 65 536.

    Returns
    -------
    str
        ``"utf-8-sig"`` or ``"latin-1"``.

    Raises
    ------
    FileFormatError
        UTF-16/32 text (NUL bytes).
    ThermocalInputError
        A special file (FIFO, device) instead of a regular file.

    Warns
    -----
    TextEncodingWarning
        The start is not UTF-8: read as Latin-1.

    References
    ----------
    - RFC 4180, *Common Format and MIME Type for Comma-Separated Values (CSV) Files*, 2005.
    """
    refuse_special_input(path)
    p = Path(path)
    head = _head_bytes(p, probe_bytes)
    if head.startswith((b"\xff\xfe", b"\xfe\xff")) or b"\x00" in head:
        raise FileFormatError(
            f"{p}: the text is UTF-16 or UTF-32 encoded (NUL bytes); save it as UTF-8 CSV"
        )
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(head) - 4:  # not just a character cut at the probe's end
            warnings.warn(
                TextEncodingWarning(
                    f"{p}: not UTF-8 (byte {head[exc.start]:#04x} at offset {exc.start}); "
                    "read as Latin-1"
                ),
                stacklevel=3,
            )
            return "latin-1"
    return "utf-8-sig"


BYTES_PER_VALUE = 8
"""A value read is one float64."""
WORKING_BYTES_PER_ROW = 40
"""Working memory of the commands beyond the columns, per row (measured: 30-35 B/row at
10⁷ rows, benchmarks/RESULTS.md), rounded up."""


_BUDGET: contextvars.ContextVar[int | None] = contextvars.ContextVar(
    "thermocal_memory_budget", default=None
)


@contextlib.contextmanager
def memory_budget(limit_bytes: int | None) -> Iterator[None]:
    """Within the block, :func:`memory_limit_bytes` is at most ``limit_bytes`` (None: no
    change) in this thread's context: a fleet unit on a Dask worker reads within the
    worker's own memory limit, not the machine's (a 4 MB Parquet of 3e8
    rows passes the machine's check and the worker's nanny kills it).

    Parameters
    ----------
    limit_bytes : int or None
        The memory limit within the block [bytes]; ``None`` leaves the limit unchanged.

    Yields
    ------
    None
    """
    token = _BUDGET.set(limit_bytes)
    try:
        yield
    finally:
        _BUDGET.reset(token)


def memory_limit_bytes() -> int | None:
    """Memory a read may use [bytes]: ``THERMOCAL_MEMORY_LIMIT`` (``2G``, ``512M``, bytes)
    when set, else half the kernel's ``MemAvailable`` (:data:`MEMORY_SHARE`); None where
    neither is known; at most the budget of an enclosing :func:`memory_budget`.

    Returns
    -------
    int or None
        The limit [bytes], or ``None`` when unknown.

    Raises
    ------
    ThermocalInputError
        ``THERMOCAL_MEMORY_LIMIT`` set to something that is not a size.
    """
    base = _machine_limit_bytes()
    budget = _BUDGET.get()
    if budget is None:
        return base
    return budget if base is None else min(base, budget)


MEMORY_SHARE = 0.5
"""Share of the kernel's ``MemAvailable`` one read may take when ``THERMOCAL_MEMORY_LIMIT``
is not set: half, so that a file whose metadata declare more rows than it can hold (a 4 MB
Parquet of 3e8 constant rows wanted 19 GB) is refused before the machine swaps or other
processes are killed (it was 90 %)."""


def _machine_limit_bytes() -> int | None:
    """``THERMOCAL_MEMORY_LIMIT`` or :data:`MEMORY_SHARE` of ``MemAvailable``
    (:func:`memory_limit_bytes`)."""
    env = os.environ.get("THERMOCAL_MEMORY_LIMIT", "").strip()
    if env:
        scale = {"K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}
        try:
            if env[-1].upper() in scale:
                value = int(float(env[:-1]) * scale[env[-1].upper()])
            else:
                value = int(float(env))
        except (ValueError, OverflowError):  # nan, inf
            value = 0
        if value <= 0:
            raise ThermocalInputError(
                f"THERMOCAL_MEMORY_LIMIT={env!r}: give a positive number of bytes, or one "
                "with K, M, G or T"
            )
        return value
    available = mem_available_bytes()
    return None if available is None else int(MEMORY_SHARE * available)


def mem_available_bytes() -> int | None:
    """The kernel's ``MemAvailable`` [bytes] (``/proc/meminfo``), None where unknown.

    Returns
    -------
    int or None
        Available memory [bytes], or ``None`` off Linux or when unreadable.
    """
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def check_memory(path: Path, n_rows: int, n_columns: int, *, estimated: bool = False) -> None:
    r"""Refuse up front a read that would not fit in memory.

    Needed ≈ ``n_rows · (8 · n_columns + 40)`` bytes (the float64 columns plus the
    commands' working memory); compared with :func:`memory_limit_bytes`. The error gives
    both figures and the ways out (cut the file; ``compensate`` streams it).

    Parameters
    ----------
    path : pathlib.Path
        The file named in the error.
    n_rows : int
        Rows to read.
    n_columns : int
        Numeric columns to read.
    estimated : bool, optional
        Whether ``n_rows`` is an estimate (the message says "about"); default ``False``.

    Raises
    ------
    ThermocalInputError
        The read needs more memory than :func:`memory_limit_bytes`.

    Notes
    -----
    .. math:: \mathrm{need} = n_{\mathrm{rows}}\,(8\,n_{\mathrm{columns}} + 40)\ \mathrm{bytes}
    """
    limit = memory_limit_bytes()
    need = n_rows * (BYTES_PER_VALUE * n_columns + WORKING_BYTES_PER_ROW)
    if limit is None or need <= limit:
        return
    about = "about " if estimated else ""
    raise ThermocalInputError(
        f"{path}: reading {about}{n_rows:,} rows of {n_columns} column(s) needs about "
        f"{need / 2**30:.3g} GiB of memory, more than the {limit / 2**30:.3g} GiB available "
        "(THERMOCAL_MEMORY_LIMIT or the machine's free memory); cut the file by time, or "
        "compensate it (compensate streams any length)"
    )


def csv_rows_estimate(path: Path, probe_bytes: int = 1 << 16) -> tuple[int, int]:
    """(rows, columns) of a CSV estimated from its size and its first lines.

    Parameters
    ----------
    path : pathlib.Path
        The CSV file.
    probe_bytes : int, optional
        How many bytes of the start are looked at [bytes]; default 65 536.

    Returns
    -------
    tuple of (int, int)
        Estimated rows (file size / mean line length of the probe) and columns (the
        header's separators + 1).
    """
    size = path.stat().st_size
    with open(path, "rb") as fh:
        head = fh.read(probe_bytes)
    lines = head.splitlines()
    if len(lines) < 2:
        return 1, max(1, head.count(b",") + 1)
    body = lines[1:-1] if len(lines) > 2 else lines[1:]
    mean_len = max(1.0, sum(len(x) + 1 for x in body) / len(body))
    cols = max(lines[0].count(b","), lines[0].count(b";"), lines[0].count(b"\t")) + 1
    return int(size / mean_len), cols


def short_name(name: str, limit: int = 60) -> str:
    """``repr`` of a column name for a message, cut to ``limit`` characters (a header of
    megabytes must not become a message of megabytes).

    Parameters
    ----------
    name : str
        A column name.
    limit : int, optional
        Characters kept; default 60.

    Returns
    -------
    str
        The ``repr``, cut with its full length stated.
    """
    return repr(name) if len(name) <= limit else repr(name[:limit]) + f"… ({len(name):,} chars)"


def names_list(names: Sequence[str], limit: int = 20) -> str:
    """Column names for a message: the first ``limit``, each cut (:func:`short_name`).

    Parameters
    ----------
    names : sequence of str
        Column names.
    limit : int, optional
        Names shown; default 20.

    Returns
    -------
    str
        Comma-separated names, with how many more there are.
    """
    shown = ", ".join(short_name(c) for c in names[:limit])
    return shown + (f", … ({len(names) - limit:,} more)" if len(names) > limit else "")


def check_unique_names(path: str | Path, names: Sequence[str]) -> None:
    """Refuse a header that names a column twice (compared after stripping blanks): which
    of the two a command would read is a guess (:class:`FileFormatError` naming it).

    Parameters
    ----------
    path : str or pathlib.Path
        The file named in the error.
    names : sequence of str
        The header's column names.

    Raises
    ------
    FileFormatError
        A name that appears twice (blank names excepted).
    """
    seen: dict[str, int] = {}
    for k, raw in enumerate(names):
        name = str(raw).strip()
        if not name:
            continue  # unnamed columns are told apart by position
        if name in seen:
            raise FileFormatError(
                f"{path}: the column name {short_name(name)} appears twice (columns "
                f"{seen[name] + 1} and {k + 1}); rename one"
            )
        seen[name] = k


class LogDamageWarning(ThermocalWarning):
    """A flight-controller log is cut or damaged: what was lost is said."""


class LibraryNoise:
    """A text sink counting the lines a log library prints, by kind (numbers and hex
    replaced by ``#``), so that 143 652 ``bad header`` lines become one sentence."""

    MAX_KINDS = 50

    def __init__(self) -> None:
        self.lines = 0
        self.kinds: dict[str, int] = {}
        self._part = ""

    def write(self, text: str) -> int:
        """Count the lines of ``text`` (the file-like protocol of :data:`sys.stdout`).

        Parameters
        ----------
        text : str
            Text a library printed.

        Returns
        -------
        int
            ``len(text)``, as :meth:`io.TextIOBase.write` returns.
        """
        self._part += text
        if "\n" in self._part:
            *done, self._part = self._part.split("\n")
            for line in done:
                self._count(line)
        return len(text)

    def flush(self) -> None:
        """Nothing to flush (the file-like protocol)."""

    def _count(self, line: str) -> None:
        line = line.strip()
        if not line:
            return
        self.lines += 1
        kind = re.sub(r"0x[0-9a-fA-F]+|\d+", "#", line[:200])[:80]
        if kind not in self.kinds and len(self.kinds) >= self.MAX_KINDS:
            kind = "other messages"
        self.kinds[kind] = self.kinds.get(kind, 0) + 1

    def close(self) -> None:
        """Count the last, unfinished line."""
        if self._part:
            self._count(self._part)
            self._part = ""

    def summary(self, library: str) -> str:
        """``pymavlink printed 143 652 line(s): 143 650 × 'bad header # at #', …`` or ``""``.

        Parameters
        ----------
        library : str
            The library's name (``pymavlink``, ``pyulog``).

        Returns
        -------
        str
            One line naming the three most frequent kinds of line, or ``""`` when nothing
            was printed.
        """
        if not self.lines:
            return ""
        top = sorted(self.kinds.items(), key=lambda kv: -kv[1])[:3]
        shown = ", ".join(f"{n:,} × {k!r}" for k, n in top)
        more = ", …" if len(self.kinds) > 3 else ""
        return f"{library} printed {self.lines:,} line(s), not shown: {shown}{more}"


@contextlib.contextmanager
def library_output_captured() -> Iterator[LibraryNoise]:
    """Capture what a log library prints while reading: Python's ``sys.stdout``/``stderr``
    and the file descriptors 1 and 2 underneath (compiled parts print there), counted in a
    :class:`LibraryNoise` instead of flooding the terminal."""
    noise = LibraryNoise()
    saved: list[tuple[int, int]] = []
    spool = tempfile.TemporaryFile()  # noqa: SIM115 (closed in the finally below)
    for stream in (sys.stdout, sys.stderr, sys.__stdout__, sys.__stderr__):
        with contextlib.suppress(Exception):
            if stream is not None:
                stream.flush()
    for fd in (1, 2):
        try:
            saved.append((fd, os.dup(fd)))
            os.dup2(spool.fileno(), fd)
        except OSError:
            continue
    try:
        with contextlib.redirect_stdout(noise), contextlib.redirect_stderr(noise):
            yield noise
    finally:
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)
        spool.seek(0)
        for raw in spool:
            noise.write(raw.decode("utf-8", "replace"))
        spool.close()
        noise.close()


class TrackedReader(io.BufferedReader):
    """A log file as a library reads it, noting where the library stopped (the position at
    ``close``) and whether its last read came back short (the file ends inside a message;
    a clean end is a read of nothing)."""

    def __init__(self, path: Path) -> None:
        super().__init__(io.FileIO(path, "rb"), buffer_size=1 << 20)
        self.stopped_at: int | None = None
        self._short_at: int | None = None

    @property
    def short_read(self) -> bool:
        """The last read came back short (some bytes, fewer than asked): a short read can
        only be the last read with data (the file ends there), so it is the last read when
        nothing was read after it (the position is still where it left off).

        Returns
        -------
        bool
            Whether the file ended inside the last read (a cut file).
        """
        end = self.stopped_at if self.closed else self.tell()
        return self._short_at is not None and self._short_at == end and not self._empty_after

    def read(self, size: int | None = -1) -> bytes:
        """Read like :meth:`io.BufferedReader.read`, noting a short read (a cut file).

        Parameters
        ----------
        size : int or None, optional
            Bytes to read; ``-1`` or ``None``: to the end.

        Returns
        -------
        bytes
            The bytes read (fewer than ``size`` only at the end of the file).
        """
        data = _BUFFERED_READ(self, size)
        if size is None or len(data) != size:  # rare: only at the end of the file
            if data and size is not None and size > 0:
                self._short_at, self._empty_after = self.tell(), False
            elif not data and size:
                self._empty_after = True  # a read of nothing after it: a clean end
        return data

    _empty_after = False

    def close(self) -> None:
        """Close the file, noting where reading stopped (:attr:`stopped_at`)."""
        if self.stopped_at is None and not self.closed:
            self.stopped_at = self.tell()
        super().close()


_BUFFERED_READ = io.BufferedReader.read


def warn_damage(path: Path, notes: Sequence[str]) -> None:
    """Warn once that a log is damaged, listing what was found.

    Parameters
    ----------
    path : pathlib.Path
        The log named in the warning.
    notes : sequence of str
        What is damaged; no warning when empty.

    Warns
    -----
    LogDamageWarning
        When ``notes`` is not empty.
    """
    if notes:
        warnings.warn(
            LogDamageWarning(f"{path}: the log is damaged: " + "; ".join(notes)), stacklevel=3
        )


def arrow_chunk_f64(chunk: pa.Array) -> FloatArray:
    """A numeric Arrow array as float64, nulls as NaN, without pandas: ``to_numpy`` with
    copies allowed goes through pyarrow's pandas shim and imports pandas (0.3 s).

    Parameters
    ----------
    chunk : pyarrow.Array
        A numeric Arrow array (any integer or float type).

    Returns
    -------
    numpy.ndarray
        float64 values, NaN where the array is null.
    """
    if not pa.types.is_float64(chunk.type):
        chunk = chunk.cast(pa.float64())
    if chunk.null_count:
        chunk = chunk.fill_null(math.nan)
    data = chunk.buffers()[1]  # the values; ``to_numpy`` itself imports pandas
    if data is None:  # an empty array
        return np.empty(0, dtype=np.float64)
    return np.frombuffer(data, dtype=np.float64, count=len(chunk), offset=8 * chunk.offset)


TIME_COLUMN_NAMES = ("time", "t", "timestamp", "elapsed", "elapsed time")
"""Names a time column goes by, compared without case and without a unit written in the
name (``time``, ``Time (ms)``, ``time_s``, ``timestamp_us``)."""


TEMPERATURE_NAME = re.compile(r"^(t\d+|t_|temp|tmp)|temperature|°c|degc", re.IGNORECASE)
"""Names a temperature column goes by (``T1``, ``t_die``, ``temp``, ``IMU temperature``,
``chip (°C)``): guessed as temperatures by ``inspect``, never taken for time."""


def named_like_temperature(name: str) -> bool:
    """A column named like a temperature (:data:`TEMPERATURE_NAME`, or a capital ``T``
    alone: ``t`` is time, ``T`` temperature).

    Parameters
    ----------
    name : str
        A column name.

    Returns
    -------
    bool
        Whether the name reads as a temperature.

    Examples
    --------
    >>> from thermocal.readers.common import named_like_temperature
    >>> [named_like_temperature(c) for c in ("T", "temp_gyro", "t")]
    [True, True, False]
    """
    return name.strip() == "T" or TEMPERATURE_NAME.search(name) is not None


def default_time_column(names: Sequence[str], stated: str | None = None) -> str:
    """The time column when ``time`` is not given: ``stated`` (the sidecar's), else
    ``time`` if present, else the one column whose name, with any unit stripped
    (:func:`thermocal.units.unit_in_column_name`), is one of :data:`TIME_COLUMN_NAMES`.
    Several candidates, or none, give ``"time"`` (and so a missing-column error that
    lists what is there) rather than a guess.  A column named like a temperature
    (:func:`named_like_temperature`: ``T``) is never taken for time.

    Parameters
    ----------
    names : sequence of str
        The file's column names.
    stated : str, optional
        The time column a sidecar states; default ``None``.

    Returns
    -------
    str
        The time column's name (``"time"`` when none or several candidates).

    Examples
    --------
    >>> from thermocal.readers.common import default_time_column
    >>> default_time_column(["T1", "Time (ms)", "gyro"])
    'Time (ms)'
    >>> default_time_column(["T", "gyro"])
    'time'
    """
    if stated:
        return stated
    if "time" in names:
        return "time"
    found = []
    for c in names:
        if named_like_temperature(c):
            continue  # ``T``, ``T1``, ``temp``: a temperature, never time
        base = c.strip()
        unit = units.unit_in_column_name(c, "time")
        if unit is not None:
            base = units.strip_unit_from_name(c)
        if base.lower() in TIME_COLUMN_NAMES:
            found.append(c)
    return found[0] if len(found) == 1 else "time"


# --- flight-controller logs: topics ---------------------------------------------------------

DEFAULT_ULOG_TOPIC = "sensor_gyro.0"
"""The PX4 ULog topic read when ``topic`` is not given (:mod:`thermocal.readers.ulog`)."""

DEFAULT_DATAFLASH_TOPIC = "IMU.0"
"""The ArduPilot DataFlash message read when ``topic`` is not given
(:mod:`thermocal.readers.dataflash`)."""


def parse_topic(topic: str | None, default: str = DEFAULT_ULOG_TOPIC) -> tuple[str, int]:
    """The name and instance of a flight-controller log's topic.

    Parameters
    ----------
    topic : str, optional
        ``NAME[.N]``: a ULog topic or a DataFlash message and its instance.
    default : str
        The topic when ``topic`` is None.

    Returns
    -------
    tuple
        ``(name, instance)``, the instance 0 when none is given.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Not ``NAME`` or ``NAME.N``.

    Examples
    --------
    >>> from thermocal.readers.common import parse_topic
    >>> parse_topic("sensor_accel.1"), parse_topic(None, "IMU")
    (('sensor_accel', 1), ('IMU', 0))
    """
    text = (topic or default).strip()
    name, _, inst = text.partition(".")
    if not name or (inst and not inst.isdigit()):
        raise ThermocalInputError.naming(
            f"{{topic}} must be NAME or NAME.N (e.g. sensor_gyro.0), got {text!r}", "topic"
        )
    return name, int(inst or 0)


def thermocal_metadata(kv: Any, where: str | Path) -> dict[str, Any]:
    """The thermocal metadata object (JSON under :data:`thermocal.recording.META_KEY`) of a
    Parquet file's key-value map ``kv`` (None or without the key: ``{}``); anything that is
    not a JSON object is a :class:`FileFormatError` naming ``where``.

    Parameters
    ----------
    kv : mapping of bytes to bytes or None
        A Parquet file's key-value metadata.
    where : str or pathlib.Path
        The file named in the error.

    Returns
    -------
    dict
        The metadata object; ``{}`` when there is none.

    Raises
    ------
    FileFormatError
        The metadata is not a JSON object.
    """
    import json

    from thermocal.recording import META_KEY

    raw = (kv or {}).get(META_KEY.encode())
    if not raw:
        return {}
    try:
        meta = json.loads(raw.decode("utf-8"))
    except (ValueError, UnicodeDecodeError, RecursionError):  # nested too deeply too
        raise FileFormatError(f"{where}: corrupt thermocal metadata") from None
    if not isinstance(meta, dict):
        raise FileFormatError(f"{where}: corrupt thermocal metadata (not an object)")
    return meta


def sha256_of(path: str | Path) -> str | None:
    """SHA-256 of a file's content, read in 1 MiB blocks; None when it cannot be read (a
    report states it unknown; the fleet redoes a unit whose input is missing).  A model
    file's provenance uses :func:`thermocal.pipeline.model_file.file_sha256`, which also reads a
    station folder and lets a read error through.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.

    Returns
    -------
    str or None
        The hexadecimal SHA-256 digest, or ``None`` when unreadable or special.

    References
    ----------
    - NIST FIPS 180-4, *Secure Hash Standard (SHS)*, 2015.
    """
    if special_mode(Path(path)) is not None:  # a FIFO would block: never opened
        return None
    try:
        with open(path, "rb") as fh:
            st = os.fstat(fh.fileno())
            key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
            if key in _SHA256_SEEN:  # the same file unchanged: hashed once per process
                return _SHA256_SEEN[key]
            h = hashlib.sha256()
            while block := fh.read(1 << 20):
                h.update(block)
    except OSError:
        return None
    if len(_SHA256_SEEN) >= 64:
        _SHA256_SEEN.clear()
    _SHA256_SEEN[key] = h.hexdigest()
    return _SHA256_SEEN[key]


_SHA256_SEEN: dict[tuple[int, int, int, int], str] = {}
""":func:`sha256_of`'s digests by (device, inode, size, modification time [ns]): the reports
of one log's sensors name its digest each, and a 50 MB log takes ~0.1 s to hash."""
