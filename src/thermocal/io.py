"""Read and write recordings as CSV or Parquet, with sidecar metadata.

* Format by extension: ``.csv`` (also ``.csv.gz``, ``.txt``) or ``.parquet``/``.pq``.
* Metadata: an optional sidecar ``FILE.meta.json`` beside the data file, or the
  Parquet key-value metadata under the key ``thermocal``; command-line options
  (the ``read_recording`` arguments) win over both.
* Writers never touch an input: they write to a temporary name in the target's
  directory and rename it over the target when complete (:func:`atomic_write`).

The sidecar / Parquet metadata is a JSON object::

    {"format": "thermocal-recording", "version": 1,
     "time": "time", "time_unit": "s",
     "signals": {"gyro": "deg/h"}, "temperatures": {"T1": "degC"},
     "units": {"truth_bias": "deg/h"},
     "metadata": {...Metadata.to_dict()...}}
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import fcntl
import functools
import gc
import glob
import hashlib
import io
import json
import math
import os
import re
import secrets
import shutil
import sys
import tempfile
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal import units
from thermocal._lazy import LazyModule
from thermocal.errors import (
    FileFormatError,
    MissingColumnError,
    NonNumericError,
    TextEncodingWarning,
    TextLayoutWarning,
    ThermocalInputError,
    ThermocalWarning,
    UnitWarning,
)
from thermocal.outputs import check_outputs, refuse_special
from thermocal.recording import FloatArray, Metadata, Recording

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")
    pacsv = LazyModule("pyarrow.csv")
    pq = LazyModule("pyarrow.parquet")

META_KEY = "thermocal"
META_FORMAT = "thermocal-recording"
META_VERSION = 1


@functools.cache
def csv_float_options() -> dict[str, Any]:
    """``pandas.read_csv`` options that parse every decimal to the nearest float64 (pandas < 3's
    default parser can be one ulp off; pandas 3 is exact by default and deprecates the option).
    A function so that importing this module does not import pandas (issue 17)."""
    major = int(pd.__version__.split(".")[0])
    return {"float_precision": "round_trip"} if major < 3 else {}


CSV_SUFFIXES = (".csv", ".txt", ".csv.gz", ".log", ".tsv", ".dat")
PARQUET_SUFFIXES = (".parquet", ".pq")
ULOG_SUFFIXES = (".ulg",)
DATAFLASH_SUFFIXES = (".bin",)


def file_kind(path: str | Path) -> str:
    """``'csv'`` or ``'parquet'`` from the extension, else :class:`FileFormatError`."""
    name = str(path).lower()
    if name.endswith(TEMP_SUFFIX):
        raise FileFormatError(
            f"{path}: an unfinished output of an interrupted thermocal run, not a result; "
            "delete it (the next run to the same output removes it)"
        )
    if name.endswith(PARQUET_SUFFIXES):
        return "parquet"
    if name.endswith(ULOG_SUFFIXES):
        return "ulog"
    if name.endswith(DATAFLASH_SUFFIXES):
        return "dataflash"
    if name.endswith(CSV_SUFFIXES):
        return "csv"
    raise FileFormatError(
        f"{path}: not a CSV or Parquet file (expected extension .csv, or .txt, .log, .tsv, "
        ".dat for a text log, .parquet, .ulg for a PX4 log or .bin for an ArduPilot log)"
    )


def sidecar_path(path: str | Path) -> Path:
    """``FILE.meta.json`` beside ``FILE``."""
    p = Path(path)
    return p.with_name(p.name + ".meta.json")


def _default_mode() -> int:
    """Permissions of a newly created file under the current umask (``0o666 & ~umask``);
    ``mkstemp`` would otherwise leave outputs readable by their owner only."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _writable_target(path: str | Path) -> Path:
    """``path`` as a Path, its directory created; an existing directory there is an
    input error (not an ``IsADirectoryError`` naming the temporary file)."""
    target = Path(path)
    refuse_special(target)  # a FIFO, a device, /proc…: never replaced by a regular file
    if target.is_dir():
        raise ThermocalInputError(f"{path}: is a directory, expected a file name")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise ThermocalInputError(
            f"{path}: cannot create the output, {target.parent} is not a directory"
        ) from None
    return target


TEMP_SUFFIX = ".thermocal-partial"
"""Suffix of an output being written.  No reader accepts it (:func:`file_kind`), so an
interrupted write can never be mistaken for a result; the next run that writes the same
output removes the stale ones (:func:`remove_stale_temporaries`)."""

_WRITE_ERRORS = frozenset(
    {errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT, errno.ENOENT, errno.EFBIG}
)
"""Errors of the user's environment while writing an output (permissions, a full disk)."""

WRITTEN: list[Path] = []
"""Outputs completed by this process, in order (the CLI names them when interrupted)."""


def _temp_path(target: Path) -> Path:
    """``.NAME.<pid>.<random>.thermocal-partial`` beside ``target``."""
    return target.with_name(f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}{TEMP_SUFFIX}")


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_stale_temporaries(target: str | Path) -> list[Path]:
    """Remove the temporaries of ``target`` left by writers that no longer run.

    A temporary is ``.NAME.<pid>.<random>.thermocal-partial`` (:data:`TEMP_SUFFIX`); it is
    stale when no process ``pid`` exists (a writer killed by SIGKILL or a power cut).
    Temporaries of live writers are left alone.  Returns the removed paths.
    """
    t = Path(target)
    removed: list[Path] = []
    pattern = f".{glob.escape(t.name)}.*{TEMP_SUFFIX}"
    for cand in t.parent.glob(pattern):
        middle = cand.name[len(t.name) + 2 : -len(TEMP_SUFFIX)]
        pid_text = middle.split(".", 1)[0]
        if not pid_text.isdigit() or _pid_alive(int(pid_text)):
            continue
        with contextlib.suppress(OSError):
            cand.unlink()
            removed.append(cand)
    return removed


@contextlib.contextmanager
def _output_lock(target: Path) -> Iterator[None]:
    """Serialise writers of one output: an exclusive ``flock`` on a lock file kept in the
    system's temporary directory (so the output's directory holds only the results),
    named by a hash of the output's absolute path.  A second writer waits its turn."""
    key = hashlib.sha256(str(target.resolve()).encode("utf-8")).hexdigest()[:32]
    lock_dir = Path(tempfile.gettempdir()) / f"thermocal-locks-{os.getuid()}"
    try:
        lock_dir.mkdir(mode=0o700, exist_ok=True)
        fd = os.open(lock_dir / f"{key}.lock", os.O_RDWR | os.O_CREAT, 0o600)
    except OSError:  # no usable temporary directory: write unserialised
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


@contextlib.contextmanager
def _temporary_for(path: str | Path) -> Iterator[tuple[Path, Path]]:
    """(target, temporary) under the output lock, stale temporaries removed first; the
    temporary is renamed over the target when the block ends without an exception and
    removed otherwise."""
    target = _writable_target(path)
    with _output_lock(target):
        remove_stale_temporaries(target)
        tmp = _temp_path(target)
        try:
            yield target, tmp
            os.chmod(tmp, _default_mode())
            os.replace(tmp, target)
        except BaseException as exc:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            if isinstance(exc, OSError) and exc.errno in _WRITE_ERRORS:
                # name the output the user asked for, not our temporary
                raise ThermocalInputError(
                    f"{target}: cannot write the output ({exc.strerror}); nothing was written"
                ) from None
            raise
    WRITTEN.append(target)


@contextlib.contextmanager
def atomic_write(path: str | Path, mode: str = "wb") -> Iterator[Any]:
    """Open a temporary file beside ``path``; rename it over ``path`` on success.

    On any exception the temporary file is removed and ``path`` is untouched.  Writers
    of the same output are serialised; temporaries carry :data:`TEMP_SUFFIX`.
    """
    with _temporary_for(path) as (_target, tmp), open(tmp, mode) as fh:
        yield fh


def atomic_write_path(path: str | Path, writer: Callable[[Path], None]) -> None:
    """Call ``writer(tmp_path)`` then rename ``tmp_path`` over ``path`` (for libraries
    that want a path, not a file object)."""
    with _temporary_for(path) as (_target, tmp):
        tmp.touch(mode=0o600)
        writer(tmp)


_STAGED: list[Path] = []
"""Staging directories of this process not yet moved into place (:func:`discard_staging`)."""


def _remove_stale_staging(target: Path) -> None:
    """Remove the staging directories of ``target`` left by runs that no longer exist."""
    for cand in target.parent.glob(f".{glob.escape(target.name)}.*{TEMP_SUFFIX}"):
        middle = cand.name[len(target.name) + 2 : -len(TEMP_SUFFIX)]
        pid_text = middle.split(".", 1)[0]
        dead = pid_text.isdigit() and not _pid_alive(int(pid_text))
        if dead and cand.is_dir() and not cand.is_symlink():
            shutil.rmtree(cand, ignore_errors=True)


def staging_directory(target: str | Path) -> Path:
    """A new empty directory beside ``target``, ``.NAME.<pid>.<random>.thermocal-partial``,
    in which a command builds a set of outputs (calibration, parameters, reports) that must
    appear whole or not at all; :func:`commit_directory` moves it into place,
    :func:`discard_staging` removes it on failure, and the next
    run to the same target removes those of runs that died."""
    t = Path(target)
    refuse_special(t)
    if t.exists() and not t.is_dir():
        raise ThermocalInputError(f"{target}: exists and is not a directory")
    try:
        t.parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise ThermocalInputError(
            f"{target}: cannot create the output, {t.parent} is not a directory"
        ) from None
    _remove_stale_staging(t)
    stage = _temp_path(t)
    stage.mkdir()
    _STAGED.append(stage)
    return stage


def commit_directory(stage: Path, target: str | Path) -> None:
    """Move a complete output set from ``stage`` into ``target``: one rename when ``target``
    does not exist or is an empty directory (atomic); otherwise each file replaces its
    namesake in ``target`` (``os.replace``, atomic per file; other files of ``target`` are
    left alone), then ``stage`` is removed."""
    t = Path(target)
    with _output_lock(t):
        empty = t.is_dir() and not t.is_symlink() and not any(t.iterdir())
        if (not t.exists() and not t.is_symlink()) or empty:
            os.replace(stage, t)
        else:
            t.mkdir(parents=True, exist_ok=True)
            for f in sorted(stage.iterdir()):
                os.replace(f, t / f.name)
            stage.rmdir()
    with contextlib.suppress(ValueError):
        _STAGED.remove(stage)
    for k, w in enumerate(WRITTEN):  # name the outputs where they now are
        if w.parent == stage:
            WRITTEN[k] = t / w.name


def discard_staging() -> None:
    """Remove every staging directory of this process not moved into place."""
    while _STAGED:
        stage = _STAGED.pop()
        shutil.rmtree(stage, ignore_errors=True)
        WRITTEN[:] = [w for w in WRITTEN if w.parent != stage]


def write_json(path: str | Path, obj: Any) -> None:
    """Write JSON atomically (indent 2, UTF-8)."""
    text = json.dumps(obj, indent=2, ensure_ascii=False, allow_nan=False)
    with atomic_write(path, "w") as fh:
        fh.write(text + "\n")


def check_not_input(out: str | Path, inputs: list[str | Path]) -> None:
    """Refuse to write ``out`` over one of the inputs or an input's sidecar
    ``FILE.meta.json``, or onto a special file (the one gate,
    :func:`thermocal.outputs.check_outputs`; INTERFACE.md common rules)."""
    check_outputs([out], inputs)


# --- reading -------------------------------------------------------------------------


def _load_sidecar(path: Path) -> dict[str, Any]:
    side = sidecar_path(path)
    if not side.exists():
        return {}
    try:
        obj = json.loads(side.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{side}: not valid JSON ({exc})") from None
    if not isinstance(obj, dict):
        raise FileFormatError(f"{side}: expected a JSON object")
    return obj


class _ParquetColumns:
    """Columns of a Parquet file read one at a time, so that peak memory stays near
    the size of the float64 arrays handed back (not the Arrow table plus its copy)."""

    def __init__(self, pf: pq.ParquetFile) -> None:
        self._pf = pf
        schema = pf.schema_arrow
        self.column_names: list[str] = list(schema.names)
        self.num_rows: int = int(pf.metadata.num_rows)
        self.metadata: dict[bytes, bytes] = dict(schema.metadata or {})
        self._read: dict[str, FloatArray] = {}

    def read_f64(self, names: Sequence[str]) -> None:
        """Read the integer and floating-point columns among ``names`` together, one row
        group at a time (pyarrow decodes the columns of a row group on several threads);
        :meth:`column_f64` then hands each one over.  Peak memory: the results plus one
        row group of these columns."""
        schema = self._pf.schema_arrow
        todo = [
            n
            for n in dict.fromkeys(names)
            if n in self.column_names
            and n not in self._read
            and (
                pa.types.is_integer(schema.field(n).type)
                or pa.types.is_floating(schema.field(n).type)
            )
        ]
        if len(todo) < 2:
            return
        out = {n: np.empty(self.num_rows, dtype=np.float64) for n in todo}
        pos = 0
        try:
            for i in range(self._pf.num_row_groups):
                k = 0
                for n in todo:  # one column chunk at a time: the decoding buffers of one
                    group = self._pf.read_row_group(i, columns=[n], use_threads=False)
                    k = 0
                    for chunk in group.column(0).chunks:
                        out[n][pos + k : pos + k + len(chunk)] = arrow_chunk_f64(chunk)
                        k += len(chunk)
                    del group
                pos += k
        except (pa.ArrowInvalid, OSError):
            return  # a damaged file: column by column, the error names the column
        if pos == self.num_rows:
            self._read.update(out)

    def column(self, name: str) -> pa.ChunkedArray:
        col: pa.ChunkedArray = self._pf.read(columns=[name], use_threads=True).column(0)
        return col

    def column_f64(self, name: str) -> FloatArray | None:
        """A numeric column as float64, read one row group at a time into the result, so
        that the only memory beyond the result is one row group of one column (None for a
        column that is not integer or floating point: the caller reads it whole)."""
        if name in self._read:  # read with others by :meth:`read_f64`
            return self._read.pop(name)
        field_type = self._pf.schema_arrow.field(name).type
        if not (pa.types.is_integer(field_type) or pa.types.is_floating(field_type)):
            return None
        out = np.empty(self.num_rows, dtype=np.float64)
        pos = 0
        for i in range(self._pf.num_row_groups):
            col = self._pf.read_row_group(i, columns=[name]).column(0)
            for chunk in col.chunks:
                k = len(chunk)
                out[pos : pos + k] = arrow_chunk_f64(chunk)  # nulls → NaN
                pos += k
            del col
        if pos != self.num_rows:
            raise pa.ArrowInvalid(f"column {name!r} has {pos} rows, the file {self.num_rows}")
        return out


def csv_encoding(path: str | Path, probe_bytes: int = 1 << 16) -> str:
    """The text encoding of a CSV file: ``utf-8-sig`` (UTF-8, with or without a byte-order
    mark) when its start decodes as UTF-8, else ``latin-1`` (Western lab PCs and
    instrument software write it; a ``°`` in a header is the usual case, stated in a
    warning).  UTF-16/32 (NUL bytes) are refused with the remedy.
    """
    p = Path(path)
    with open(p, "rb") as fh:
        head = fh.read(probe_bytes)
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


def memory_limit_bytes() -> int | None:
    """Memory a read may use [bytes]: ``THERMOCAL_MEMORY_LIMIT`` (``2G``, ``512M``, bytes)
    when set, else 90 % of the kernel's ``MemAvailable``; None where neither is known."""
    env = os.environ.get("THERMOCAL_MEMORY_LIMIT", "").strip()
    if env:
        scale = {"K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}
        try:
            if env[-1].upper() in scale:
                return int(float(env[:-1]) * scale[env[-1].upper()])
            return int(float(env))
        except ValueError:
            raise ThermocalInputError(
                f"THERMOCAL_MEMORY_LIMIT={env!r}: give bytes or a number with K, M, G or T"
            ) from None
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(0.9 * int(line.split()[1]) * 1024)
    except OSError:
        return None
    return None


def check_memory(path: Path, n_rows: int, n_columns: int, *, estimated: bool = False) -> None:
    """Refuse up front a read that would not fit in memory (issue 14).

    Needed ≈ ``n_rows · (8 · n_columns + 40)`` bytes (the float64 columns plus the
    commands' working memory); compared with :func:`memory_limit_bytes`. The error gives
    both figures and the ways out (cut the file; ``compensate`` streams it).
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


def _csv_rows_estimate(path: Path, probe_bytes: int = 1 << 16) -> tuple[int, int]:
    """(rows, columns) of a CSV estimated from its size and its first lines."""
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


# --- text logs (serial terminals, spreadsheets of other locales) ----------------------------


@dataclass(frozen=True)
class TextOptions:
    """How to read a text log (INTERFACE.md common rules): ``names`` for a file without a
    header row; ``rate_hz`` for a file without a time column (time = row / rate);
    ``on_bad_lines`` ``"error"`` (default: the first mangled line is named) or ``"skip"``
    (mangled lines dropped, how many reported); ``delimiter`` and ``decimal`` (detected when
    None: ``,`` ``;`` tab or blanks; ``.`` or ``,``)."""

    names: tuple[str, ...] | None = None
    rate_hz: float | None = None
    on_bad_lines: str = "error"
    delimiter: str | None = None
    decimal: str | None = None

    def __post_init__(self) -> None:
        if self.on_bad_lines not in ("error", "skip"):
            raise ThermocalInputError(
                f"--on-bad-lines must be error or skip, got {self.on_bad_lines!r}"
            )
        if self.rate_hz is not None and not (math.isfinite(self.rate_hz) and self.rate_hz > 0):
            raise ThermocalInputError(f"--rate must be a positive rate [Hz], got {self.rate_hz}")
        if self.decimal not in (None, ".", ","):
            raise ThermocalInputError(f"--decimal must be . or , — got {self.decimal!r}")
        if self.names is not None and len(set(self.names)) != len(self.names):
            raise ThermocalInputError(f"--names repeats a name: {list(self.names)}")


SNIFF_LINES = 400
"""Lines read to find a text log's layout (banner, delimiter, decimal mark, header)."""

_DELIMS = (",", ";", "\t", " ")


def _split(line: str, delim: str) -> list[str]:
    return line.split() if delim == " " else [f.strip() for f in line.split(delim)]


def parse_number(field: str) -> float:
    """A text field as a float, as a CSV reader takes it: ASCII digits, sign, ``.``,
    exponent, or ``nan``/``inf``.  Python's :func:`float` also accepts digit-group
    underscores (``0_5`` → 5.0) and non-ASCII digits (``١٢``); those are malformed numbers
    here (``ValueError``), so a mangled line is a bad line, not a silent value."""
    if "_" in field or not field.isascii():
        raise ValueError(f"malformed number {field.strip()[:40]!r}")
    return float(field)


def _is_number(field: str, decimal: str, *, empty: bool = False) -> bool:
    """A number written with ``decimal`` (an empty field counts when ``empty``: a missing
    value, NaN downstream, not a sign of a banner)."""
    f = field.strip().replace(decimal, ".") if decimal == "," else field.strip()
    if empty and not f:
        return True
    try:
        parse_number(f)
    except ValueError:
        return False
    return True


def short_name(name: str, limit: int = 60) -> str:
    """``repr`` of a column name for a message, cut to ``limit`` characters (a header of
    megabytes must not become a message of megabytes)."""
    return repr(name) if len(name) <= limit else repr(name[:limit]) + f"… ({len(name):,} chars)"


def names_list(names: Sequence[str], limit: int = 20) -> str:
    """Column names for a message: the first ``limit``, each cut (:func:`short_name`)."""
    shown = ", ".join(short_name(c) for c in names[:limit])
    return shown + (f", … ({len(names) - limit:,} more)" if len(names) > limit else "")


def check_unique_names(path: str | Path, names: Sequence[str]) -> None:
    """Refuse a header that names a column twice (compared after stripping blanks): which
    of the two a command would read is a guess (:class:`FileFormatError` naming it)."""
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


@dataclass(frozen=True)
class TextLayout:
    """A text log's layout found by :func:`sniff_text`: ``skip`` lines before the header
    (or first data row), the banner lines skipped, the delimiter, the decimal mark, whether
    the first kept line is a header, the number of fields."""

    skip: int
    banner: tuple[str, ...]
    delimiter: str
    decimal: str
    header: bool
    n_fields: int

    @property
    def plain(self) -> bool:
        """An ordinary comma CSV with a header and nothing to skip (the fast path)."""
        return self.skip == 0 and self.delimiter == "," and self.decimal == "." and self.header


def sniff_text(lines: Sequence[str], opts: TextOptions | None = None) -> TextLayout:
    """The layout of a text log from its first lines.

    For each candidate delimiter (``, ; tab blanks``, or the one given) the modal number of
    fields m (≥ 2) of the non-empty, non-``#`` lines; the delimiter whose modal count
    covers most lines wins (ties: in that order).  The data start at the first line with m
    fields that is numeric (empty fields allowed: missing values), or that names the
    columns (no field a number) and is followed by a line of m fields (the header); the
    lines before
    are a banner (a terminal's, a logger's) and are skipped.  Lines further down that do
    not fit are mangled lines, for ``--on-bad-lines``.  The decimal mark is ``,`` when the
    delimiter is not a comma and the data parse with ``,`` but not with ``.``.
    """
    o = opts or TextOptions()
    delims = [o.delimiter] if o.delimiter else list(_DELIMS)
    delims = ["\t" if d == "\\t" else d for d in delims]
    body = [x for x in lines if x.strip() and not x.lstrip().startswith("#")]
    best: tuple[int, int, str] | None = None  # (-covered, order, delimiter)
    for order, d in enumerate(delims):
        counts = [len(_split(x, d)) for x in body]
        good = [c for c in counts if c >= 2]
        if not good:
            continue
        m = max(set(good), key=good.count)
        key = (-good.count(m), order, d)
        if best is None or key < best:
            best = key
    if best is None:
        raise FileFormatError(
            "no lines with two or more fields were found (is it a data log? give "
            "--delimiter and --decimal if it uses others than , ; tab blanks)"
        )
    d = best[2]
    m = max(
        set(c for c in (len(_split(x, d)) for x in body) if c >= 2),
        key=[len(_split(x, d)) for x in body].count,
    )
    decimals = [o.decimal] if o.decimal else ([".", ","] if d != "," else ["."])

    def numeric(line: str, dec: str) -> bool:
        f = _split(line, d)
        return len(f) == m and all(_is_number(x, dec, empty=True) for x in f)

    # the decimal mark under which most lines of m fields are numbers (ties: ".")
    dec = max(decimals, key=lambda c: (sum(numeric(x, c) for x in body), c == "."))
    for k, line in enumerate(lines):
        if not line.strip() or line.lstrip().startswith("#") or len(_split(line, d)) != m:
            continue
        if numeric(line, dec):
            return TextLayout(k, _banner(lines[:k]), d, dec, False, m)
        names = _split(line, d)
        nxt = next((x for x in lines[k + 1 :] if x.strip()), None)
        is_names = all(f and not _is_number(f, dec) for f in names)
        if is_names and nxt is not None and len(_split(nxt, d)) == m:
            return TextLayout(k, _banner(lines[:k]), d, dec, True, m)
    raise FileFormatError(
        f"no line of {m} numeric fields separated by {d!r} was found (give --delimiter and "
        "--decimal if the log uses others)"
    )


def _banner(lines: Sequence[str]) -> tuple[str, ...]:
    return tuple(x for x in lines if x.strip())


def _head_lines(path: Path, encoding: str, errors: str) -> list[str]:
    """The first :data:`SNIFF_LINES` lines of a text file, line ends removed."""
    with open(path, encoding=encoding, errors=errors, newline="") as fh:
        return [fh.readline().rstrip("\r\n") for _ in range(SNIFF_LINES)]


def _delimiter_name(delimiter: str) -> str:
    """How a warning names a delimiter: ``tab``, ``blank`` or the quoted character."""
    return {"\t": "tab", " ": "blank"}.get(delimiter, repr(delimiter))


def csv_chunk_options(path: Path, encoding: str) -> dict[str, Any]:
    """``pandas.read_csv`` options for reading a text file in chunks (compensate): the
    detected delimiter, decimal mark and banner lines to skip, stated in a warning when
    not a plain comma CSV; a file without a header row is refused (name the columns)."""
    if path.name.lower().endswith(".gz"):
        return {}
    head = _head_lines(path, encoding, "replace")
    try:
        lay = sniff_text(head)
    except FileFormatError:
        return {}  # the CSV reader says what is wrong
    if lay.plain:
        return {}
    if not lay.header:
        raise ThermocalInputError(
            f"{path}: no header row (line {lay.skip + 1} is data); compensate needs named "
            "columns: add a header line, or read it with --names in another command and "
            "write it out"
        )
    warnings.warn(
        TextLayoutWarning(
            f"{path}: read as {_delimiter_name(lay.delimiter)}-separated text with decimal "
            f"mark {lay.decimal!r}"
            + (f", {len(lay.banner)} banner line(s) skipped" if lay.banner else "")
        ),
        stacklevel=3,
    )
    return {
        "sep": r"\s+" if lay.delimiter == " " else lay.delimiter,
        "decimal": lay.decimal,
        "skiprows": lay.skip,
    }


def _read_text(
    path: Path, encoding: str, opts: TextOptions | None
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """A text log as a DataFrame of floats: banner skipped, delimiter and decimal mark
    detected (or given), header taken from ``--names`` when the file has none, mangled
    lines (another number of fields, a non-number) refused naming the first or, with
    ``on_bad_lines="skip"``, dropped and counted.  Warnings say what was skipped."""
    o = opts or TextOptions()
    head = _head_lines(path, encoding, "strict")
    try:
        lay = sniff_text(head, o)
    except FileFormatError as exc:
        raise FileFormatError(f"{path}: {exc}") from None
    names: list[str] | None = None
    if lay.header:
        names = [c.strip() for c in _split(head[lay.skip], lay.delimiter)]
        check_unique_names(path, names)
        if o.names is not None:
            raise ThermocalInputError(
                f"{path}: the file has a header row ({', '.join(names)}); --names is for "
                "files without one"
            )
    elif o.names is None:
        raise ThermocalInputError(
            f"{path}: no header row (line {lay.skip + 1} is data: "
            f"{head[lay.skip].strip()[:60]!r}); name its {lay.n_fields} columns with "
            "--names a,b,c"
        )
    else:
        names = list(o.names)
        if len(names) != lay.n_fields:
            raise ThermocalInputError(
                f"{path}: --names gives {len(names)} names for {lay.n_fields} columns "
                f"(line {lay.skip + 1}: {head[lay.skip].strip()[:60]!r})"
            )
    first_data = lay.skip + (1 if lay.header else 0)  # 0-based line of the first data row
    bad: list[tuple[int, str]] = []
    rows: list[list[float]] = []
    ordinal: list[int] = []  # each kept row's place among the data lines (dropped ones too)
    n_data = 0
    n = len(names)
    with open(path, encoding=encoding, errors="strict", newline="") as fh:
        for lineno, line in enumerate(fh, start=1):
            if lineno <= first_data:
                continue
            text = line.rstrip("\r\n")
            if not text.strip() or text.lstrip().startswith("#"):
                continue
            fields = _split(text, lay.delimiter)
            n_data += 1
            try:
                if len(fields) != n:
                    raise ValueError(f"{len(fields)} fields, {n} expected")
                rows.append(
                    [parse_number(f.replace(",", ".") if lay.decimal == "," else f) for f in fields]
                )
                ordinal.append(n_data - 1)
            except ValueError as exc:
                if o.on_bad_lines == "error":
                    raise FileFormatError(
                        f"{path}: line {lineno} is not a data row ({exc}): {text.strip()[:80]!r}; "
                        "fix it or pass --on-bad-lines skip to drop such lines"
                    ) from None
                bad.append((lineno, text))
    if not rows:
        raise FileFormatError(f"{path}: the file has a header but no data rows")
    df = pd.DataFrame(np.asarray(rows, dtype=np.float64), columns=names)
    # --rate: time = data-line number / rate, so a dropped line leaves a gap, not a shift
    df.attrs["row_index"] = np.asarray(ordinal, dtype=np.float64)
    report: dict[str, Any] = {
        "text_layout": {
            "banner_lines": len(lay.banner),
            "delimiter": "\t" if lay.delimiter == "\t" else lay.delimiter,
            "decimal": lay.decimal,
            "header": lay.header,
            "bad_lines": [ln for ln, _t in bad],
        }
    }
    if lay.delimiter != "," or lay.decimal != ".":
        warnings.warn(
            TextLayoutWarning(
                f"{path}: read as {_delimiter_name(lay.delimiter)}-separated text with decimal "
                f"mark {lay.decimal!r} (give --delimiter/--decimal if that is wrong)"
            ),
            stacklevel=3,
        )
    if lay.banner:
        warnings.warn(
            TextLayoutWarning(
                f"{path}: {len(lay.banner)} banner line(s) before the data skipped (first: "
                f"{lay.banner[0].strip()[:60]!r})"
            ),
            stacklevel=3,
        )
    if bad:
        shown = ", ".join(str(ln) for ln, _t in bad[:5]) + (" …" if len(bad) > 5 else "")
        warnings.warn(
            TextLayoutWarning(
                f"{path}: {len(bad)} mangled line(s) dropped (--on-bad-lines skip): line(s) {shown}"
            ),
            stacklevel=3,
        )
    return df, report


# --- PX4 ULog ------------------------------------------------------------------------------

_XYZ = ("x", "y", "z")
PX4_UNITS: dict[str, dict[str, str]] = {
    "sensor_gyro": {**dict.fromkeys(_XYZ, "rad/s"), "temperature": "degC"},
    "sensor_accel": {**dict.fromkeys(_XYZ, "m/s^2"), "temperature": "degC"},
    "sensor_baro": {"pressure": "Pa", "temperature": "degC"},
    "sensor_mag": {**dict.fromkeys(_XYZ, "gauss"), "temperature": "degC"},
    "sensor_combined": {
        **{f"gyro_rad[{i}]": "rad/s" for i in range(3)},
        **{f"accelerometer_m_s2[{i}]": "m/s^2" for i in range(3)},
        "gyro_integral_dt": "us", "accelerometer_integral_dt": "us",
    },
    "vehicle_imu": {
        **{f"delta_angle[{i}]": "rad" for i in range(3)},
        **{f"delta_velocity[{i}]": "m/s" for i in range(3)},
        "delta_angle_dt": "us", "delta_velocity_dt": "us",
        **{f"gyro_rad_s[{i}]": "rad/s" for i in range(3)},
        **{f"accel_m_s2[{i}]": "m/s^2" for i in range(3)},
    },
    "vehicle_imu_status": {"temperature_accel": "degC", "temperature_gyro": "degC"},
}  # fmt: skip
"""Units of PX4's sensor topics, from the uORB message definitions (PX4-Autopilot
``msg/SensorGyro.msg`` [rad/s], ``SensorAccel.msg`` [m/s²], ``SensorBaro.msg`` pressure [Pa],
``SensorMag.msg`` [gauss], ``SensorCombined.msg`` ``gyro_rad`` [rad/s] and
``accelerometer_m_s2`` [m/s²], ``VehicleImu.msg`` ``delta_angle`` [rad] and ``delta_velocity``
[m/s] over ``delta_angle_dt``/``delta_velocity_dt`` [µs]; temperatures [°C]).  pyulog names an
array's elements ``name[i]``.  ``vehicle_imu`` is also given as rates:
``gyro_rad_s[i] = delta_angle[i] / delta_angle_dt`` [rad/s] and
``accel_m_s2[i] = delta_velocity[i] / delta_velocity_dt`` [m/s²] (columns added by the
reader).  The time is ``timestamp`` [µs]."""

DEFAULT_ULOG_TOPIC = "sensor_gyro.0"


def parse_topic(topic: str | None, default: str = DEFAULT_ULOG_TOPIC) -> tuple[str, int]:
    """``NAME[.N]`` → (name, instance); default :data:`DEFAULT_ULOG_TOPIC`."""
    text = (topic or default).strip()
    name, _, inst = text.partition(".")
    if not name or (inst and not inst.isdigit()):
        raise ThermocalInputError(
            f"--topic must be NAME or NAME.N (e.g. sensor_gyro.0), got {text!r}"
        )
    return name, int(inst or 0)


class LogDamageWarning(ThermocalWarning):
    """A flight-controller log is cut or damaged: what was lost is said."""


class _LibraryNoise:
    """A text sink counting the lines a log library prints, by kind (numbers and hex
    replaced by ``#``), so that 143 652 ``bad header`` lines become one sentence."""

    MAX_KINDS = 50

    def __init__(self) -> None:
        self.lines = 0
        self.kinds: dict[str, int] = {}
        self._part = ""

    def write(self, text: str) -> int:
        self._part += text
        if "\n" in self._part:
            *done, self._part = self._part.split("\n")
            for line in done:
                self._count(line)
        return len(text)

    def flush(self) -> None:
        pass

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
        if self._part:
            self._count(self._part)
            self._part = ""

    def summary(self, library: str) -> str:
        """``pymavlink printed 143 652 line(s): 143 650 × 'bad header # at #', …`` or ``""``."""
        if not self.lines:
            return ""
        top = sorted(self.kinds.items(), key=lambda kv: -kv[1])[:3]
        shown = ", ".join(f"{n:,} × {k!r}" for k, n in top)
        more = ", …" if len(self.kinds) > 3 else ""
        return f"{library} printed {self.lines:,} line(s), not shown: {shown}{more}"


@contextlib.contextmanager
def _library_output_captured() -> Iterator[_LibraryNoise]:
    """Capture what a log library prints while reading: Python's ``sys.stdout``/``stderr``
    and the file descriptors 1 and 2 underneath (compiled parts print there), counted in a
    :class:`_LibraryNoise` instead of flooding the terminal."""
    noise = _LibraryNoise()
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


class _TrackedReader(io.BufferedReader):
    """A log file as a library reads it, noting where the library stopped (the position at
    ``close``) and whether its last read came back short (the file ends inside a message;
    a clean end is a read of nothing)."""

    def __init__(self, path: Path) -> None:
        super().__init__(io.FileIO(path, "rb"))
        self.stopped_at: int | None = None
        self.short_read = False

    def read(self, size: int | None = -1) -> bytes:
        data = super().read(size)
        self.short_read = size is not None and size > 0 and 0 < len(data) < size
        return data

    def close(self) -> None:
        if self.stopped_at is None and not self.closed:
            self.stopped_at = self.tell()
        super().close()


@dataclass(frozen=True)
class _ULogRead:
    """A parsed ULog and what its reading lost: ``notes`` (sentences for one warning)."""

    ulog: Any
    damaged: bool
    skipped: bool
    """pyulog skipped damaged messages inside the file (``file_corruption``)."""
    notes: tuple[str, ...]


def _parse_ulog(path: Path, names: list[str] | None) -> _ULogRead:
    """Parse a ULog with pyulog (only the topics ``names``, all when None), its printed
    noise captured, and measure what was lost:

    * pyulog stops at a damaged message header (a zeroed length, say) without saying so:
      the bytes after the position it stopped at, as a share of the file;
    * a file cut inside its last message (a short read);
    * pyulog's own ``file_corruption`` flag (damaged messages skipped: the topics' missing
      samples are estimated from their sample interval, :func:`_topic_loss`).
    """
    try:
        from pyulog import ULog
    except ImportError:
        raise ThermocalInputError(
            f"{path}: reading PX4 ULog files needs pyulog: pip install 'thermocal[logs]' "
            "(or pip install pyulog)"
        ) from None
    if not path.exists():
        raise FileFormatError(f"{path}: no such file")
    size = path.stat().st_size
    if size == 0:
        raise FileFormatError(f"{path}: the file is empty")
    fh = _TrackedReader(path)
    try:
        with _library_output_captured() as noise:
            ulog = ULog(fh, message_name_filter_list=names)
    except Exception as exc:  # pyulog raises several kinds on a bad file
        msg = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise FileFormatError(f"{path}: not a readable ULog file ({msg})") from None
    finally:
        fh.close()
    notes: list[str] = []
    stop = fh.stopped_at if fh.stopped_at is not None else size
    if stop < size:
        notes.append(
            f"pyulog stopped at byte {stop:,} of {size:,} (a damaged message header): the "
            f"last {100.0 * (size - stop) / size:.1f} % of the file is not read"
        )
    cut = fh.short_read and stop == size
    if cut:
        notes.append("the file ends inside a message (cut): its last message is lost")
    if ulog.file_corruption:
        notes.append("pyulog found damaged messages and skipped them")
    said = noise.summary("pyulog")
    if said:
        notes.append(said)
    skipped = bool(ulog.file_corruption)
    return _ULogRead(ulog, stop < size or cut or skipped, skipped, tuple(notes))


def _warn_damage(path: Path, notes: Sequence[str]) -> None:
    if notes:
        warnings.warn(
            LogDamageWarning(f"{path}: the log is damaged: " + "; ".join(notes)), stacklevel=3
        )


def _topic_loss(time_us: FloatArray) -> tuple[int, int]:
    """(missing, expected) samples of a topic in a damaged log, judged by its median sample
    interval: expected = span / median interval + 1."""
    n = int(time_us.size)
    if n < 3:
        return 0, n
    dt = np.diff(time_us)
    med = float(np.median(dt))
    if not (math.isfinite(med) and med > 0):
        return 0, n
    span = float(time_us[-1] - time_us[0])
    expected = round(span / med) + 1
    return max(0, expected - n), max(expected, n)


def ulog_sensor_instances(path: str | Path, topics: Sequence[str]) -> list[tuple[str, int]]:
    """The instances of ``topics`` in a ULog that carry a temperature, sorted; every instance
    left out (no ``temperature`` field, or one that is all 0 or NaN: no sensor behind it) is
    named in a warning, and damage to the log is said (:func:`_parse_ulog`)."""
    p = Path(path)
    read = _parse_ulog(p, list(topics))
    _warn_damage(p, read.notes)
    out: list[tuple[str, int]] = []
    left: list[str] = []
    for d in read.ulog.data_list:
        t = d.data.get("temperature")
        where = f"{d.name}.{int(d.multi_id)}"
        if t is None:
            left.append(f"{where} (no temperature field)")
        elif not np.isfinite(t).any():
            left.append(f"{where} (temperature all NaN)")
        elif np.all(t == 0):
            left.append(f"{where} (temperature all 0)")
        else:
            out.append((d.name, int(d.multi_id)))
    if left:
        warnings.warn(
            LogDamageWarning(
                f"{p}: {len(left)} sensor instance(s) left out, without a usable temperature: "
                + ", ".join(left)
            ),
            stacklevel=2,
        )
    return sorted(out)


def _read_ulog(path: Path, topic: str | None) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One topic instance of a PX4 ULog as a table: its fields as columns, ``timestamp``
    [µs] the time, PX4's units for the known topics, the median ``device_id`` as the
    sensor id.  Damage to the log is said in a warning with what was lost
    (:func:`_parse_ulog`).  Needs ``pyulog`` (``pip install 'thermocal[logs]'``)."""
    name, inst = parse_topic(topic)
    read = _parse_ulog(path, [name])
    found = [d for d in read.ulog.data_list if d.name == name and d.multi_id == inst]
    if not found:
        _warn_damage(path, read.notes)
        every = _parse_ulog(path, None).ulog.data_list if not read.damaged else []
        have = sorted(f"{d.name}.{d.multi_id}" for d in every or read.ulog.data_list)
        raise MissingColumnError(
            f"{path}: no topic {name}.{inst} in the log"
            + (" (it may be in the damaged part)" if read.damaged else "")
            + f"; it has: {', '.join(have) or 'none'}"
        )
    data = found[0].data
    cols = {k: np.asarray(v, dtype=np.float64) for k, v in data.items()}
    notes = list(read.notes)
    if read.skipped and "timestamp" in cols:  # messages skipped inside the read part
        missing, expected = _topic_loss(cols["timestamp"])
        if missing:
            notes.append(
                f"{name}.{inst} misses about {missing:,} of {expected:,} samples "
                f"({100.0 * missing / expected:.1f} %) judged by its sample interval"
            )
    _warn_damage(path, notes)
    if name == "vehicle_imu":  # integrals over their intervals → rates (PX4_UNITS)
        for i in range(3):
            for d_col, dt_col, out in (
                (f"delta_angle[{i}]", "delta_angle_dt", f"gyro_rad_s[{i}]"),
                (f"delta_velocity[{i}]", "delta_velocity_dt", f"accel_m_s2[{i}]"),
            ):
                if d_col in cols and dt_col in cols:
                    dt_s = cols[dt_col] * 1e-6
                    with np.errstate(divide="ignore", invalid="ignore"):
                        cols[out] = np.where(dt_s > 0, cols[d_col] / dt_s, np.nan)
    df = pd.DataFrame(cols)
    units_ = {k: u for k, u in PX4_UNITS.get(name, {}).items() if k in df.columns}
    info: dict[str, Any] = {"time": "timestamp", "time_unit": "us", "units": units_}
    info["fc_log"] = True
    if "device_id" in df.columns:
        ids = df["device_id"].to_numpy()
        info["metadata"] = {"sensor_id": str(int(np.median(ids)))}
        if np.unique(ids).size > 1:
            warnings.warn(
                TextLayoutWarning(f"{path}: {name}.{inst} changes device_id during the log"),
                stacklevel=3,
            )
    info["ulog_topic"] = f"{name}.{inst}"
    return df, info


# --- ArduPilot DataFlash --------------------------------------------------------------------

_IMU_UNITS = {
    **dict.fromkeys(("GyrX", "GyrY", "GyrZ"), "rad/s"),
    **dict.fromkeys(("AccX", "AccY", "AccZ"), "m/s^2"),
    "T": "degC", "Temp": "degC", "GHz": "Hz", "AHz": "Hz",
}  # fmt: skip
ARDUPILOT_UNITS: dict[str, dict[str, str]] = {
    "IMU": _IMU_UNITS, "IMU2": _IMU_UNITS, "IMU3": _IMU_UNITS,
    "GYR": dict.fromkeys(("GyrX", "GyrY", "GyrZ"), "rad/s"),
    "ACC": dict.fromkeys(("AccX", "AccY", "AccZ"), "m/s^2"),
    "BARO": {
        "Alt": "m", "AltAMSL": "m", "Press": "Pa", "CPress": "Pa", "Temp": "degC",
        "CRt": "m/s", "Offset": "m", "GndTemp": "degC",
    },
    "MAG": dict.fromkeys(
        ("MagX", "MagY", "MagZ", "OfsX", "OfsY", "OfsZ", "MOX", "MOY", "MOZ"), "mGauss"
    ),
    "TCLR": {"Temp": "degC"},
}  # fmt: skip
"""Units of ArduPilot's log messages, fixed by the firmware's message definitions whether or
not a log carries unit (FMTU/UNIT/MULT) messages — ArduPilot ``libraries/AP_InertialSensor/
LogStructure.h``: ``IMU`` "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz" with
units "s#EEEooo--O--zz" (E rad/s, o m/s², O degC, z Hz), multipliers 1; ``GYR``/``ACC`` the
same; older firmware (Copter 3.4–3.6) logs ``IMU``, ``IMU2``, ``IMU3`` without ``I`` and names
the temperature ``Temp`` (same units); ``libraries/AP_Logger/LogStructure.h``: ``BARO``
"TimeUS,I,Alt,AltAMSL,Press,Temp,…" units "s#mmPO…" (P Pa, O degC; ``Temp`` stored ×100 as
int16 'c', scaled by pymavlink), ``MAG`` "TimeUS,I,MagX,…" units "s#GGG…" with multiplier C
(10⁻³): milligauss; ``AP_InertialSensor_tempcal.cpp`` ``TCLR``
"TimeUS,I,SType,Temp,X,Y,Z,NSamp" (no units declared: Temp the learning's temperature [°C];
X,Y,Z the mean accelerometer [m/s², relative to the first] for SType 0, gyro [rad/s] for
SType 1 — set per read by :func:`_read_dataflash`).  The time is ``TimeUS`` [µs]."""

DEFAULT_DATAFLASH_TOPIC = "IMU.0"


DATAFLASH_PADDING = 528
"""Bytes at the end of a DataFlash log that may be padding rather than messages (block
logging fills its last page; pymavlink ignores up to this many, DFReader.py)."""


@dataclass(frozen=True)
class DataflashLog:
    """What one pass over a DataFlash log kept: the rows of the wanted message types (numeric
    fields), every message type seen, the parameters (``PARM``: the last value of each name)
    and the sentences on what was lost (:func:`_dataflash_loss`)."""

    rows: dict[str, list[dict[str, float]]]
    names_seen: frozenset[str]
    params: dict[str, float]
    notes: tuple[str, ...]


def read_dataflash_log(path: str | Path, messages: Sequence[str]) -> DataflashLog:
    """Read an ArduPilot DataFlash log once, keeping the messages named in ``messages`` and
    every ``PARM``.  pymavlink's printed complaints are captured; bytes of the file that are
    not whole messages (file size − Σ message lengths, trailing padding of one fill byte
    excepted) are lost and said in a warning with their share.  Needs ``pymavlink``
    (``pip install 'thermocal[logs]'``)."""
    try:
        from pymavlink import DFReader
    except ImportError:
        raise ThermocalInputError(
            f"{path}: reading ArduPilot DataFlash logs needs pymavlink: pip install "
            "'thermocal[logs]' (or pip install pymavlink)"
        ) from None
    path = Path(path)
    keep = set(messages)
    rows: dict[str, list[dict[str, float]]] = {m: [] for m in keep}
    params: dict[str, float] = {}
    names_seen: set[str] = set()
    accounted = 0  # bytes in whole messages
    last_end = 0
    size = path.stat().st_size
    with _library_output_captured() as noise:
        failure = None
        try:
            log = DFReader.DFReader_binary(str(path), zero_time_base=False)
        except Exception as exc:  # pymavlink raises several kinds on a bad file
            failure = " ".join(str(exc).split())[:200] or type(exc).__name__
        if failure is not None:
            # pymavlink leaves the file of a log it could not open to the garbage collector:
            # close it now, quietly, rather than warn later in someone else's code
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ResourceWarning)
                gc.collect()
            raise FileFormatError(f"{path}: not a readable DataFlash log ({failure})")
        try:
            while True:
                try:
                    m = log.recv_msg()
                except Exception as exc:
                    msg = " ".join(str(exc).split())[:200] or type(exc).__name__
                    raise FileFormatError(
                        f"{path}: a damaged DataFlash log pymavlink cannot read past byte "
                        f"{getattr(log, 'offset', 0):,} ({msg})"
                    ) from None
                if m is None:
                    break
                accounted += int(m.fmt.len)  # header included (LogStructure.h)
                last_end = int(getattr(log, "offset", 0))
                mtype = m.get_type()
                names_seen.add(mtype)
                if mtype in keep:
                    d = m.to_dict()
                    rows[mtype].append(
                        {k: float(v) for k, v in d.items() if isinstance(v, int | float)}
                    )
                elif mtype == "PARM":
                    with contextlib.suppress(AttributeError, TypeError, ValueError):
                        params[str(m.Name)] = float(m.Value)
        finally:  # pymavlink keeps the file and its memory map open
            for attr in ("data_map", "filehandle"):
                h = getattr(log, attr, None)
                if h is not None:
                    h.close()
    notes = _dataflash_loss(path, size, accounted, last_end)
    said = noise.summary("pymavlink")
    if said and notes:
        notes.append(said)
    _warn_damage(path, notes)
    return DataflashLog(rows, frozenset(names_seen), params, tuple(notes))


def dataflash_table(
    log: DataflashLog, path: Path, name: str, inst: int
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Instance ``inst`` of message ``name`` from a :func:`read_dataflash_log` pass, as a
    table with the firmware's units (:data:`ARDUPILOT_UNITS`).  Both layouts: the instance
    field ``I`` (newer firmware) or, for ``IMU.1``/``IMU.2``, the older messages
    ``IMU2``/``IMU3`` without it; ``T`` or ``Temp`` the temperature."""
    legacy = f"{name}{inst + 1}" if inst > 0 else None  # IMU2 = IMU.1 in older logs
    rows = [r for r in log.rows.get(name, []) if int(r.get("I", 0)) == inst]
    source = name
    if not rows and legacy:
        rows = [r for r in log.rows.get(legacy, []) if "I" not in r]
        source = legacy
    if not rows:
        raise MissingColumnError(
            f"{path}: no {name} messages of instance {inst} in the log"
            + (" (they may be in its damaged part)" if log.notes else "")
            + "; it has: "
            + (", ".join(sorted(log.names_seen - {"FMT", "FMTU", "UNIT", "MULT"})) or "none")
        )
    df = pd.DataFrame(rows).astype(np.float64)
    if "TimeUS" not in df.columns:  # a damaged FMT message renames the fields
        raise FileFormatError(
            f"{path}: the {source} messages have no TimeUS field (their format definition is "
            "damaged); fields: " + names_list([str(c) for c in df.columns])
        )
    known = dict(ARDUPILOT_UNITS.get(source, {}))
    if source == "TCLR" and "SType" in df.columns:  # X, Y, Z: accel (0) or gyro (1) means
        kinds = set(df["SType"].astype(int).tolist())
        if len(kinds) == 1:
            u = {0: "m/s^2", 1: "rad/s"}.get(kinds.pop())
            if u:
                known.update(dict.fromkeys(("X", "Y", "Z"), u))
    units_ = {k: u for k, u in known.items() if k in df.columns}
    info: dict[str, Any] = {"time": "TimeUS", "time_unit": "us", "units": units_}
    info["dataflash_message"] = f"{name}.{inst}"
    info["dataflash_source"] = source
    info["fc_log"] = True
    return df, info


def _read_dataflash(path: Path, topic: str | None) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One message type and instance (field ``I``) of an ArduPilot DataFlash log as a
    table: the message's fields as columns, ``TimeUS`` [µs] the time, the firmware's units
    (:data:`ARDUPILOT_UNITS`, whether or not the log carries unit messages).  Older logs
    name their second and third IMU ``IMU2``/``IMU3`` (no ``I`` field): ``IMU.1`` reads
    ``IMU2`` (:func:`dataflash_table`).  The log is read once (:func:`read_dataflash_log`)."""
    name, inst = parse_topic(topic, DEFAULT_DATAFLASH_TOPIC)
    wanted = [name] + ([f"{name}{inst + 1}"] if inst > 0 else [])
    log = read_dataflash_log(path, wanted)
    return dataflash_table(log, path, name, inst)


def _dataflash_loss(path: Path, size: int, accounted: int, last_end: int) -> list[str]:
    """Sentences on the bytes of a DataFlash log that were not whole messages: skipped as
    damaged inside the log, or left at its end (a cut last message; a tail shorter than
    :data:`DATAFLASH_PADDING` of one repeated fill byte is padding, not loss)."""
    lost_inside = max(0, last_end - accounted)
    tail = max(0, size - last_end)
    notes = []
    if lost_inside:
        notes.append(
            f"{lost_inside:,} bytes ({100.0 * lost_inside / size:.1f} % of the file) are not "
            "whole messages and were skipped, with the messages in them"
        )
    if tail:
        with open(path, "rb") as fh:
            fh.seek(last_end)
            rest = fh.read(DATAFLASH_PADDING + 1)
        padding = len(rest) < DATAFLASH_PADDING and len(set(rest)) == 1
        if not padding:
            notes.append(
                f"its last {tail:,} bytes ({100.0 * tail / size:.1f} % of the file) are not a "
                "whole message (the file is cut or damaged at its end)"
            )
    return notes


def _read_table(
    path: Path, kind: str, text: TextOptions | None = None, topic: str | None = None
) -> tuple[pd.DataFrame | _ParquetColumns, dict[str, Any]]:
    if not path.exists():
        raise FileFormatError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise FileFormatError(f"{path}: the file is empty")
    if kind == "ulog":
        return _read_ulog(path, topic)
    if kind == "dataflash":
        return _read_dataflash(path, topic)
    if kind == "parquet":
        try:
            table = _ParquetColumns(pq.ParquetFile(path, page_checksum_verification=True))
        except (pa.ArrowInvalid, OSError) as exc:
            raise FileFormatError(f"{path}: not a readable Parquet file ({exc})") from None
        check_unique_names(path, table.column_names)
        meta: dict[str, Any] = {}
        raw = table.metadata.get(META_KEY.encode())
        if raw:
            try:
                meta = json.loads(raw.decode("utf-8"))
            except (json.JSONDecodeError, UnicodeDecodeError):
                raise FileFormatError(f"{path}: corrupt thermocal metadata") from None
        return table, meta
    encoding = csv_encoding(path)
    # pandas holds every column of a CSV (and its parser about as much again)
    rows_est, cols_est = _csv_rows_estimate(path)
    check_memory(path, rows_est, 2 * cols_est, estimated=True)
    if not path.name.lower().endswith(".gz"):
        head = _head_lines(path, encoding, "replace")
        try:
            lay = sniff_text(head, text)
        except FileFormatError:
            lay = None  # not numeric text: the CSV reader says what is wrong
        needs_text = text is not None and (
            text.names is not None or text.on_bad_lines == "skip" or text.delimiter or text.decimal
        )
        if (lay is not None and not lay.plain) or needs_text:
            return _read_text(path, encoding, text)
    check_unique_names(path, _csv_header_names(path, encoding))  # before pandas renames
    try:
        df = pd.read_csv(
            path,
            skipinitialspace=True,
            comment=None,
            low_memory=False,
            **csv_float_options(),
            encoding=encoding,
        )
    except pd.errors.EmptyDataError:
        raise FileFormatError(f"{path}: the file is empty (no header)") from None
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FileFormatError(f"{path}: not a readable CSV file ({msg})") from None
    df.columns = [str(c).strip() for c in df.columns]
    check_unique_names(path, list(df.columns))  # ``a`` and ``a `` are one name stripped
    return df, {}


def _csv_header_names(path: Path, encoding: str) -> list[str]:
    """The names of a comma CSV's header line as written (pandas renames a repeated name
    ``a.1``, so repeats are looked for here).  One pass over the line: linear in its
    length.  Empty for a header the ``csv`` module cannot split (the reader then says)."""
    opener: Callable[..., Any] = open
    if path.name.lower().endswith(".gz"):
        import gzip

        opener = gzip.open
    try:
        with opener(path, "rt", encoding=encoding, errors="replace", newline="") as fh:
            line = fh.readline().lstrip("\ufeff")
    except (OSError, EOFError):
        return []
    if '"' not in line:
        return [f.strip() for f in line.rstrip("\r\n").split(",")]
    import csv

    try:
        return [f.strip() for f in next(csv.reader([line], skipinitialspace=True), [])]
    except csv.Error:  # a quoted field beyond the csv module's size limit
        return []


def arrow_chunk_f64(chunk: pa.Array) -> FloatArray:
    """A numeric Arrow array as float64, nulls as NaN, without pandas: ``to_numpy`` with
    copies allowed goes through pyarrow's pandas shim and imports pandas (0.3 s)."""
    if not pa.types.is_float64(chunk.type):
        chunk = chunk.cast(pa.float64())
    if chunk.null_count:
        chunk = chunk.fill_null(math.nan)
    data = chunk.buffers()[1]  # the values; ``to_numpy`` itself imports pandas
    if data is None:  # an empty array
        return np.empty(0, dtype=np.float64)
    return np.frombuffer(data, dtype=np.float64, count=len(chunk), offset=8 * chunk.offset)


def _arrow_to_f64(col: pa.ChunkedArray | pa.Array, name: str, path: Path) -> FloatArray:
    """An Arrow column as float64 (copied chunk by chunk into one array)."""
    if not (pa.types.is_integer(col.type) or pa.types.is_floating(col.type)):
        if pa.types.is_boolean(col.type) or pa.types.is_decimal(col.type):
            return np.asarray(col.to_numpy(zero_copy_only=False), dtype=np.float64)
        raise NonNumericError(f"{path}: column {name!r} is not numeric (type {col.type})")
    chunks = col.chunks if isinstance(col, pa.ChunkedArray) else [col]
    if col.null_count == 0 and pa.types.is_float64(col.type):
        if len(chunks) == 1:
            return arrow_chunk_f64(chunks[0])
        out = np.empty(len(col), dtype=np.float64)
        pos = 0
        for chunk in chunks:
            n = len(chunk)
            out[pos : pos + n] = chunk.to_numpy(zero_copy_only=True)
            pos += n
        return out
    out = np.empty(len(col), dtype=np.float64)
    pos = 0
    for chunk in chunks:
        out[pos : pos + len(chunk)] = arrow_chunk_f64(chunk)
        pos += len(chunk)
    return out


def numeric_column(
    obj: pd.DataFrame | pa.RecordBatch | _ParquetColumns,
    name: str,
    path: str | Path,
    row_offset: int = 0,
) -> FloatArray:
    """A column of a table (or of a chunk of one) as float64.

    Missing cells become NaN.  A cell that is not a number raises
    :class:`NonNumericError` naming the column and the row (``row_offset`` is the
    file row of the chunk's first row, for chunked readers).
    """
    p = Path(path)
    if isinstance(obj, _ParquetColumns):
        try:
            direct = obj.column_f64(name)
            if direct is not None:
                return direct
            col = obj.column(name)
        except (pa.ArrowInvalid, OSError) as exc:
            raise FileFormatError(f"{p}: cannot read column {name!r} ({exc})") from None
        return _arrow_to_f64(col, name, p)
    if isinstance(obj, pa.RecordBatch):
        return _arrow_to_f64(obj.column(name), name, p)
    series = obj[name]
    if pd.api.types.is_numeric_dtype(series.dtype) and not pd.api.types.is_bool_dtype(series.dtype):
        return series.to_numpy(dtype=np.float64, na_value=np.nan)
    conv = pd.to_numeric(series, errors="coerce")
    bad = conv.isna() & series.notna() & (series.astype(str).str.strip() != "")
    if bad.any():
        row = row_offset + int(np.argmax(bad.to_numpy()))
        raise NonNumericError(
            f"{p}: non-numeric value {short_name(str(series.iloc[row - row_offset]))} in column "
            f"{short_name(name)} at row {row} (line {row + 2} of the file)"
        )
    return conv.to_numpy(dtype=np.float64, na_value=np.nan)


TIME_COLUMN_NAMES = ("time", "t", "timestamp", "elapsed", "elapsed time")
"""Names a time column goes by, compared without case and without a unit written in the
name (``time``, ``Time (ms)``, ``time_s``, ``timestamp_us``)."""


def default_time_column(names: Sequence[str], stated: str | None = None) -> str:
    """The time column when ``--time`` is not given: ``stated`` (the sidecar's), else
    ``time`` if present, else the one column whose name, with any unit stripped
    (:func:`thermocal.units.unit_in_column_name`), is one of :data:`TIME_COLUMN_NAMES`.
    Several candidates, or none, give ``"time"`` (and so a missing-column error that
    lists what is there) rather than a guess.
    """
    if stated:
        return stated
    if "time" in names:
        return "time"
    found = []
    for c in names:
        base = c.strip()
        unit = units.unit_in_column_name(c, "time")
        if unit is not None:
            base = units.strip_unit_from_name(c)
        if base.lower() in TIME_COLUMN_NAMES:
            found.append(c)
    return found[0] if len(found) == 1 else "time"


def read_log_table(path: str | Path, topic: str | None) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One topic instance of a flight-controller log (.ulg, .bin) as a table and its
    metadata (for commands that go through it in chunks: compensate)."""
    p = Path(path)
    kind = file_kind(p)
    if kind not in ("ulog", "dataflash"):
        raise ThermocalInputError(f"{p}: --topic is for flight-controller logs (.ulg, .bin)")
    obj, info = _read_table(p, kind, None, topic)
    assert isinstance(obj, pd.DataFrame)
    return obj, info


def read_text_table(
    path: str | Path, text: TextOptions, time: str | None = None
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """A text log read whole with ``text`` (names, rate, bad lines, delimiter, decimal):
    the table (a ``time`` column added for ``--rate``) and its sidecar metadata — for
    commands that then go through it in chunks (compensate).  Text logs are small; the
    memory check still applies."""
    p = Path(path)
    if file_kind(p) != "csv":
        raise ThermocalInputError(
            f"{p}: --names, --rate, --on-bad-lines, --delimiter and --decimal are for text logs"
        )
    obj, file_meta = _read_table(p, "csv", text)
    info: dict[str, Any] = {**file_meta, **_load_sidecar(p)}
    assert isinstance(obj, pd.DataFrame)
    names = list(obj.columns)
    if text.rate_hz is not None:
        obj, names, t_col, t_unit = _rate_time(p, obj, names, info, time, None, text)
        info["time"], info["time_unit"] = t_col, t_unit
    return obj, info


def _rate_time(
    p: Path,
    obj: Any,
    names: list[str],
    info: dict[str, Any],
    time: str | None,
    time_unit: str | None,
    text: TextOptions,
) -> tuple[Any, list[str], str, str]:
    """``--rate``: a file without a time column gets ``time = row / rate`` [s], the row
    counted among the log's data lines (a mangled line dropped leaves a gap); a file that
    has a time column is refused (say which to believe)."""
    assert text.rate_hz is not None
    named = time or info.get("time")
    if named and named in names:
        raise ThermocalInputError(
            f"{p}: --rate {text.rate_hz:g} Hz given but the file has a time column "
            f"{named!r}; drop --rate (or name another column with --time)"
        )
    col = named or "time"
    if col in names:
        raise ThermocalInputError(
            f"{p}: --rate {text.rate_hz:g} Hz given but the file has a time column {col!r}; "
            "drop --rate"
        )
    if isinstance(obj, _ParquetColumns):
        raise ThermocalInputError(f"{p}: --rate is for text logs; a Parquet file has its time")
    if time_unit not in (None, "s"):
        raise ThermocalInputError("--rate gives the time in seconds; drop --time-unit")
    rows = obj.attrs.get("row_index")
    if rows is None or len(rows) != len(obj):
        rows = np.arange(len(obj), dtype=np.float64)
    obj = obj.copy()
    obj.insert(0, col, np.asarray(rows, dtype=np.float64) / float(text.rate_hz))
    return obj, [col, *names], col, "s"


def _fc_log_unknown_units(
    p: Path,
    info: dict[str, Any],
    sig_names: Sequence[str],
    option: str | None,
    model: units.StatedUnits | None,
) -> None:
    """A flight-controller log's field whose unit neither the firmware's message definition
    known here (:data:`PX4_UNITS`, :data:`ARDUPILOT_UNITS`), nor ``--signal-unit``, the column
    name or the model states is read as raw values (``counts``, not converted) with a
    :class:`~thermocal.errors.UnitWarning` — never guessed as °/h (issue 28)."""
    if option:
        return
    known: dict[str, str] = info.setdefault("units", {})
    topic = info.get("ulog_topic") or info.get("dataflash_message") or "?"
    for c in sig_names:
        if c in known or units.unit_in_column_name(c, "signal") is not None:
            continue
        if model is not None and model.columns.get(c):
            continue
        known[c] = "counts"
        warnings.warn(
            UnitWarning(
                f"{p}: the unit of field {c!r} of {topic} is not known from the firmware's "
                "message definition: read as raw values (counts), not converted; give "
                "--signal-unit"
            ),
            stacklevel=3,
        )


def _station_path(p: Path) -> bool:
    """``DIR`` (or ``DIR/SENSOR``) written by ``thermocal station run``."""
    return (p.is_dir() or not p.exists()) and (
        (p / "station.json").is_file() or (p.parent / "station.json").is_file()
    )


def _read_station(p: Path) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The closed Parquet parts of a station recording as one table
    (:func:`thermocal.station.recorder.read_station`)."""
    from thermocal.station.recorder import read_station

    table, meta = read_station(p)
    return table.to_pandas(), meta


def read_recording(
    path: str | Path,
    *,
    time: str | None = None,
    time_unit: str | None = None,
    signals: list[str] | None = None,
    temperatures: list[str] | None = None,
    signal_unit: str | None = None,
    temp_unit: str | None = None,
    meta: Metadata | None = None,
    keep_other: bool = True,
    skipped: list[str] | None = None,
    temp_conversion: units.TemperatureConversion | None = None,
    model: units.StatedUnits | None = None,
    text: TextOptions | None = None,
    topic: str | None = None,
) -> Recording:
    """Read a CSV, text log or Parquet recording, or a station's recording folder.

    Parameters
    ----------
    path : the file; its extension chooses the format.  A folder written by ``thermocal
        station run`` is read as one recording (``DIR``, or ``DIR/SENSOR`` of several).
    time : name of the time column (default: sidecar's, else ``"time"``).
    time_unit : ``s``, ``ms`` or ``us``; converted to [s].
    signals, temperatures : column names with those roles (default: sidecar's).
    signal_unit, temp_unit : units of those columns (override the sidecar); ``signal_unit``
        may be ``U1,…,Un``, one per signal.
    meta : metadata that overrides the file's (its temperature conversions count as
        options).
    keep_other : keep the other numeric columns (non-numeric ones are skipped).
    skipped : if a list is given, the names of skipped non-numeric columns are appended.
    temp_conversion : ``--temp-conversion``, the counts → °C conversion of every
        temperature column (which it says are raw counts).
    model : the units a model file recorded of its inputs
        (:meth:`thermocal.units.StatedUnits.from_model_inputs`): used where the option,
        the file and the column name are silent.
    text : how to read a text log (:class:`TextOptions`: ``--names``, ``--rate``,
        ``--on-bad-lines``, ``--delimiter``, ``--decimal``); banners, other delimiters and
        decimal commas are detected without it.
    topic : a PX4 ULog's topic instance, ``NAME[.N]`` (default ``sensor_gyro.0``).

    Units and temperature conversions are resolved once by
    :func:`thermocal.units.resolve_inputs` (option > file metadata > column name > model
    file > a default stated in a warning); the source of each is in
    ``Recording.unit_sources``.

    Raises
    ------
    FileFormatError : not CSV/Parquet, unreadable or empty.
    MissingColumnError : a named column is absent (the available ones are listed).
    NonNumericError : a non-numeric cell in a named column (row and column named).
    UnitError : an unknown unit string.
    """
    p = Path(path)
    station = _station_path(p)  # a station's recording folder, DIR or DIR/SENSOR
    kind = "station" if station else file_kind(p)
    if topic is not None and kind not in ("ulog", "dataflash"):
        raise ThermocalInputError(f"{p}: --topic is for flight-controller logs (.ulg, .bin)")
    obj, file_meta = _read_station(p) if station else _read_table(p, kind, text, topic)
    side = _load_sidecar(p)
    info: dict[str, Any] = {**file_meta, **side}

    names = list(obj.column_names) if isinstance(obj, _ParquetColumns) else list(obj.columns)
    if text is not None and text.rate_hz is not None:
        obj, names, time, time_unit = _rate_time(p, obj, names, info, time, time_unit, text)
    if not names:
        raise FileFormatError(f"{p}: the file has no columns")
    n_rows = obj.num_rows if isinstance(obj, _ParquetColumns) else len(obj)
    if n_rows == 0:
        raise FileFormatError(f"{p}: the file has a header but no data rows")

    time_col = time or default_time_column(names, info.get("time"))
    where = str(p)
    sig_info: dict[str, str] = dict(info.get("signals") or {})
    tmp_info: dict[str, str] = dict(info.get("temperatures") or {})
    sig_names = list(signals) if signals is not None else list(sig_info)
    tmp_names = list(temperatures) if temperatures is not None else list(tmp_info)
    md = Metadata.from_dict(dict(info.get("metadata") or {}))
    if meta is not None:
        md = md.merged(meta)

    present = set(names)
    for c in [time_col, *sig_names, *tmp_names]:
        if c not in present:
            raise MissingColumnError(
                f"{p}: no column {short_name(c)}; available: {names_list(names)}"
            )

    if info.get("fc_log"):
        _fc_log_unknown_units(p, info, sig_names, signal_unit, model)
    stated = units.StatedUnits.from_file_info(info, where)
    resolved = units.resolve_inputs(
        time_col,
        sig_names,
        tmp_names,
        options=units.UnitOptions(
            time_unit=time_unit,
            signal_unit=signal_unit,
            temp_unit=temp_unit,
            temp_conversion=temp_conversion,
        ),
        file=dataclasses.replace(
            stated,
            conversions={**stated.conversions, **(meta.temperature_conversion if meta else {})},
        ),
        model=model,
        where=where,
    )
    if isinstance(obj, _ParquetColumns):  # read column by column: only what is used
        used = len(names) if keep_other else 1 + len(sig_names) + len(tmp_names)
        check_memory(p, n_rows, used)
        obj.read_f64([time_col, *sig_names, *tmp_names])
    t = numeric_column(obj, time_col, p)
    if resolved.time.unit != "s":
        t = t * units.TIME_UNITS[resolved.time.unit]

    cols: dict[str, FloatArray] = {c: numeric_column(obj, c, p) for c in [*sig_names, *tmp_names]}
    unit_map: dict[str, str] = resolved.units()
    md.temperature_conversion = {  # the resolved ones; others kept for guessed columns
        **{c: v for c, v in md.temperature_conversion.items() if c not in tmp_names},
        **{c: r.conversion for c, r in resolved.conversions.items() if r.conversion is not None},
    }
    extra_units: dict[str, str] = dict(info.get("units") or {})
    if keep_other:
        for c in names:
            if c == time_col or c in cols:
                continue
            try:
                cols[c] = numeric_column(obj, c, p)
            except NonNumericError:
                if skipped is not None:
                    skipped.append(c)
                continue
            unit_map[c] = units.other_column_unit(c, extra_units.get(c))

    return Recording(
        time_s=t,
        columns=cols,
        units=unit_map,
        signals=tuple(sig_names),
        temperatures=tuple(tmp_names),
        meta=md,
        source=str(p),
        time_unit=resolved.time.unit,
        unit_sources=resolved.sources(),
    )


def recording_info(rec: Recording, time: str = "time") -> dict[str, Any]:
    """The metadata object written beside (or into) a recording file."""
    return {
        "format": META_FORMAT,
        "version": META_VERSION,
        "time": time,
        "time_unit": "s",
        "signals": {s: rec.units.get(s, "") for s in rec.signals},
        "temperatures": {s: rec.units.get(s, "") for s in rec.temperatures},
        "units": {
            c: u
            for c, u in rec.units.items()
            if u and c not in rec.signals and c not in rec.temperatures
        },
        "metadata": rec.meta.to_dict(),
    }


def write_recording(
    rec: Recording, path: str | Path, *, time: str = "time", sidecar: bool | None = None
) -> Path:
    """Write a recording as CSV or Parquet (by extension), atomically.

    CSV files get a sidecar ``FILE.meta.json``; Parquet files carry the same JSON in
    their key-value metadata (and a sidecar only if ``sidecar=True``).
    Time is written in [s].  CSV numbers are written by Arrow's writer in their
    shortest exact form, so a CSV round-trip reproduces every float64 bit.
    """
    p = Path(path)
    kind = file_kind(p)
    info = recording_info(rec, time=time)
    data: dict[str, FloatArray] = {time: rec.time_s}
    for c, v in rec.columns.items():
        if c == time:
            raise ThermocalInputError(f"column name {c!r} clashes with the time column")
        data[c] = v
    if kind == "parquet":
        table = pa.table(data)
        table = table.replace_schema_metadata({META_KEY: json.dumps(info)})
        atomic_write_path(p, lambda tmp: pq.write_table(table, tmp, write_page_checksum=True))
        if sidecar:
            write_json(sidecar_path(p), info)
    else:
        table = pa.table(data)
        opts = pacsv.WriteOptions(include_header=True, quoting_style="needed")
        atomic_write_path(p, lambda tmp: pacsv.write_csv(table, tmp, write_options=opts))
        if sidecar is None or sidecar:
            write_json(sidecar_path(p), info)
    return p
