"""The file-format registry: one table of every format a recording can be read from.

Each :class:`FileFormat` declares its name, its suffixes (or a sniff function for what a
suffix cannot tell, such as a station's recording folder), its reader (a table and its
metadata), whether it can be read in chunks (the chunked compensation needs it) and which
:class:`~thermocal.readers.options.ReadOptions` fields apply to it.  Every reading path looks
the format up here (:func:`format_of`): :func:`thermocal.readers.read_recording`, what
``thermocal inspect`` reads, the chunked compensation, station folders, flight-controller and
text logs.  A file whose format is not in the table is refused, never read as CSV.

Other packages add formats through the entry-point group ``thermocal.formats``: each entry
point names a :class:`FileFormat` object, loaded once, the first time a lookup needs them: a
file whose name or folder a built-in format recognises is read by it without looking at the
installed packages (their metadata is read only for another name, a format asked for by a
name thermocal does not have, or the list of every format).  A plugin that cannot be loaded
is skipped with one :class:`FormatPluginWarning`; it never stops the command line.
"""

from __future__ import annotations

import dataclasses
import functools
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from thermocal._lazy import LazyModule
from thermocal.errors import FileFormatError, ParameterError, ThermocalWarning
from thermocal.outputs import TEMP_SUFFIX
from thermocal.readers.common import (
    check_memory,
    check_unique_names,
    csv_encoding,
    csv_float_options,
    csv_rows_estimate,
    thermocal_metadata,
)
from thermocal.readers.options import ReadOptions
from thermocal.readers.station import is_station_path, read_station_table, with_sensor
from thermocal.readers.table import ParquetColumns, csv_header_names, open_parquet

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa

    from thermocal.readers import chunks as _chunks
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")

ENTRY_POINT_GROUP = "thermocal.formats"
"""The entry-point group through which an installed package adds a :class:`FileFormat`."""

COLUMN_FIELDS: frozenset[str] = frozenset(
    {"time", "time_unit", "signals", "temperatures", "signal_unit", "temp_unit",
     "temp_conversion", "rate_hz"}
)  # fmt: skip
"""The :class:`ReadOptions` fields every table has: columns, their units, a rate."""

TEXT_FIELDS: frozenset[str] = frozenset({"names", "on_bad_lines", "delimiter", "decimal"})
"""The :class:`ReadOptions` fields of a text log's layout."""

Reader = Callable[[Path, ReadOptions], tuple[Any, dict[str, Any]]]
"""``read(path, read_options) -> (table, metadata)``: a ``pandas.DataFrame`` (or the lazy
Parquet table) and what the file itself says of its columns (``signals``, ``temperatures``,
``units``, ``time``, ``metadata``, as a thermocal sidecar holds them)."""

ChunkMode = Literal["stream", "whole", "none"]


class FormatPluginWarning(ThermocalWarning):
    """A package declared a file format that could not be loaded; it was skipped."""


@dataclass(frozen=True)
class FileFormat:
    """One file format: how it is recognised, read, and whether it can be read in chunks.

    Parameters
    ----------
    name : str
        Short name (``"csv"``, ``"ulog"``); what :func:`format_of` returns and messages show.
    title : str
        What the format is, in words (``"a PX4 log"``), for messages.
    read : callable
        ``read(path, read_options) -> (table, metadata)``; see :data:`Reader`.  Errors a
        user can cause are :class:`~thermocal.errors.ThermocalInputError` naming the file.
    suffixes : tuple of str
        Lower-case file-name endings that choose this format (``(".ulg",)``).
    chunks : {"whole", "stream", "none"}
        How the chunked compensation reads it: ``"whole"`` with ``read`` then slice by slice
        (a log that fits in memory), ``"stream"`` a chunk at a time with ``head`` and
        ``stream`` (constant memory), ``"none"`` refused.
    head : callable, optional
        ``head(path) -> (names, metadata, n_rows or None)`` without reading the rows; with
        ``chunks="stream"``.
    stream : callable, optional
        ``stream(path, chunk_rows)`` yields ``pandas.DataFrame`` or ``pyarrow.RecordBatch``
        chunks; with ``chunks="stream"``.
    options : frozenset of str
        The :class:`ReadOptions` fields that apply (:data:`COLUMN_FIELDS`, plus ``topic``
        for a log of several topics, :data:`TEXT_FIELDS` for a text log).
    sniff : callable, optional
        ``sniff(path) -> bool``: the path is this format whatever its suffix (tried first;
        a plugin's for a path no built-in format recognises by sniff or suffix).
    locate : callable, optional
        ``locate(path, topic) -> path``: what ``head`` and ``stream`` read when ``topic``
        picks a part of ``path`` (a station folder's sensor, ``DIR/SENSOR``).

    Raises
    ------
    thermocal.errors.ParameterError
        A field no format can have, naming it.

    Examples
    --------
    >>> import pandas as pd
    >>> from thermocal.readers.formats import FileFormat
    >>> def read_toy(path, read):
    ...     return pd.DataFrame({"time": [0.0, 1.0], "gx": [1.0, 2.0]}), {}
    >>> fmt = FileFormat("toy", "a toy log", read_toy, suffixes=(".toy",))
    >>> fmt.chunks, sorted(fmt.options)[:2]
    ('whole', ['rate_hz', 'signal_unit'])
    """

    name: str
    title: str
    read: Reader
    suffixes: tuple[str, ...] = ()
    chunks: ChunkMode = "whole"
    head: Callable[[Path], _chunks.Head] | None = None
    stream: Callable[[Path, int], Iterator[Any]] | None = None
    options: frozenset[str] = COLUMN_FIELDS
    sniff: Callable[[Path], bool] | None = None
    locate: Callable[[Path, str | None], Path] | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.name, str) and self.name.isidentifier()):
            raise ParameterError("name", f"{{name}} must be a short identifier, got {self.name!r}")
        suffixes = tuple(self.suffixes)
        bad = [s for s in suffixes if not (isinstance(s, str) and s.startswith(".") and s[1:])]
        if bad:
            raise ParameterError("suffixes", f"{{name}} must begin with a dot, got {bad}")
        object.__setattr__(self, "suffixes", tuple(s.lower() for s in suffixes))
        object.__setattr__(self, "options", frozenset(self.options))
        if self.chunks not in ("stream", "whole", "none"):
            raise ParameterError(
                "chunks", f"{{name}} must be stream, whole or none, got {self.chunks!r}"
            )
        if self.chunks == "stream" and (self.head is None or self.stream is None):
            raise ParameterError("chunks", "{name}='stream' needs head and stream")
        unknown = sorted(self.options - {f.name for f in dataclasses.fields(ReadOptions)})
        if unknown:
            raise ParameterError("options", f"{{name}} names no ReadOptions field: {unknown}")


# --- the built-in formats -----------------------------------------------------------------


def _text_given(read: ReadOptions) -> ReadOptions | None:
    """``read`` when it states anything of a text log's layout, else None."""
    return read if read.text_layout_given else None


def _read_csv(path: Path, read: ReadOptions) -> tuple[Any, dict[str, Any]]:
    """A CSV file, or a text log whose layout (banner, delimiter, no header) it detects."""
    from thermocal.readers.text import (
        TooManyColumnsError,
        check_column_count,
        head_lines,
        read_text,
        sniff_text,
    )

    text = _text_given(read)
    encoding = csv_encoding(path)
    # pandas holds every column of a CSV (and its parser about as much again)
    rows_est, cols_est = csv_rows_estimate(path)
    check_memory(path, rows_est, 2 * cols_est, estimated=True)
    if not path.name.lower().endswith(".gz"):
        head = head_lines(path, encoding, "replace")
        try:
            lay = sniff_text(head, text)
        except TooManyColumnsError as exc:
            raise FileFormatError(f"{path}: {exc}") from None
        except FileFormatError:
            lay = None  # not numeric text: the CSV reader says what is wrong
        needs_text = text is not None and (
            text.names is not None or text.on_bad_lines == "skip" or text.delimiter or text.decimal
        )
        if (lay is not None and not lay.plain) or needs_text:
            return read_text(path, encoding, text)
    header = csv_header_names(path, encoding)
    check_column_count(path, len(header))  # pandas makes an object per column first
    check_unique_names(path, header)  # before pandas renames
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


def _read_parquet(path: Path, read: ReadOptions) -> tuple[Any, dict[str, Any]]:
    """A Parquet file, read lazily column by column (:class:`ParquetColumns`)."""
    try:
        table = ParquetColumns(open_parquet(path))
    except (pa.ArrowInvalid, OSError) as exc:
        raise FileFormatError(f"{path}: not a readable Parquet file ({exc})") from None
    check_unique_names(path, table.column_names)
    return table, thermocal_metadata(table.metadata, path)


def _read_ulog(path: Path, read: ReadOptions) -> tuple[Any, dict[str, Any]]:
    """One topic instance of a PX4 ULog (:func:`thermocal.readers.ulog.read_ulog`)."""
    from thermocal.readers.ulog import read_ulog

    return read_ulog(path, read.topic)


def _read_dataflash(path: Path, read: ReadOptions) -> tuple[Any, dict[str, Any]]:
    """One message of an ArduPilot DataFlash log (:func:`.dataflash.read_dataflash`)."""
    from thermocal.readers.dataflash import read_dataflash

    return read_dataflash(path, read.topic)


def _read_bag(path: Path, read: ReadOptions) -> tuple[Any, dict[str, Any]]:
    """One topic of a ROS 1 or ROS 2 bag or an MCAP file (:func:`.bag.read_bag`)."""
    from thermocal.readers.bag import read_bag

    return read_bag(path, read.topic, read.stamp)


def _is_ros2_bag(path: Path) -> bool:
    """A ROS 2 bag folder (:func:`.bag.is_ros2_bag`; a file is none, and no reason to import
    the bag reader)."""
    try:
        if not path.is_dir():
            return False
    except OSError:  # as is_ros2_bag answers it
        return False
    from thermocal.readers.bag import is_ros2_bag

    return is_ros2_bag(path)


def _read_station(path: Path, read: ReadOptions) -> tuple[Any, dict[str, Any]]:
    """A station's recording folder, ``DIR`` or ``DIR/SENSOR`` (``topic``: the sensor)."""
    return read_station_table(with_sensor(path, read.topic))


def _chunked(name: str) -> Callable[..., Any]:
    """The function ``name`` of :mod:`thermocal.readers.chunks`, imported at its first call
    (the chunk readers are the chunked compensation's: a command that reads a file whole
    never imports them)."""

    def call(*args: Any) -> Any:
        from thermocal.readers import chunks

        return getattr(chunks, name)(*args)

    call.__name__ = call.__qualname__ = name
    call.__doc__ = f":func:`thermocal.readers.chunks.{name}`."
    return call


BUILT_IN: tuple[FileFormat, ...] = (
    FileFormat(
        "station", "a station recording folder", _read_station, chunks="stream",
        head=_chunked("station_head"), stream=_chunked("station_chunks"),
        options=COLUMN_FIELDS | {"topic"}, sniff=is_station_path, locate=with_sensor,
    ),
    FileFormat(
        "parquet", "a Parquet file", _read_parquet, (".parquet", ".pq"), chunks="stream",
        head=_chunked("parquet_head"), stream=_chunked("parquet_chunks"),
    ),
    FileFormat("ulog", "a PX4 log", _read_ulog, (".ulg",), options=COLUMN_FIELDS | {"topic"}),
    FileFormat(
        "dataflash", "an ArduPilot log", _read_dataflash, (".bin",),
        options=COLUMN_FIELDS | {"topic"},
    ),
    FileFormat(
        "rosbag", "a ROS bag or MCAP file", _read_bag, (".bag", ".mcap", ".db3"),
        options=COLUMN_FIELDS | {"topic", "stamp"}, sniff=_is_ros2_bag,
    ),
    FileFormat(
        "csv", "a CSV file or text log", _read_csv,
        (".csv", ".txt", ".csv.gz", ".log", ".tsv", ".dat"), chunks="stream",
        head=_chunked("csv_head"), stream=_chunked("csv_chunks"),
        options=COLUMN_FIELDS | TEXT_FIELDS,
    ),
)  # fmt: skip
"""The formats thermocal reads itself, in the order they are tried."""


# --- the registry -------------------------------------------------------------------------


def _plugin_formats() -> list[FileFormat]:
    """The formats installed packages declare in :data:`ENTRY_POINT_GROUP`; a broken one is
    skipped with a :class:`FormatPluginWarning`."""
    from importlib import metadata  # 10 ms of imports and a scan of every distribution

    out: list[FileFormat] = []
    taken = {f.name for f in BUILT_IN}
    claimed = {s for f in BUILT_IN for s in f.suffixes}
    for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
        why = ""
        try:
            fmt = ep.load()
        except Exception as exc:  # a plugin must never break the command line
            why = f"{type(exc).__name__}: {exc}"
        else:
            if not isinstance(fmt, FileFormat):
                why = f"it is a {type(fmt).__name__}, not a thermocal FileFormat"
            elif fmt.name in taken:
                why = f"the format name {fmt.name!r} is taken"
            elif set(fmt.suffixes) & claimed:
                why = f"suffix {sorted(set(fmt.suffixes) & claimed)[0]} is another format's"
        if why:
            warnings.warn(
                FormatPluginWarning(
                    f"file-format plugin {ep.name!r} ({ep.value}) skipped: {why}; fix or "
                    "uninstall the package that declares it"
                ),
                stacklevel=3,
            )
            continue
        out.append(fmt)
        taken.add(fmt.name)
        claimed.update(fmt.suffixes)
    return out


@functools.cache
def _plugins() -> tuple[FileFormat, ...]:
    """The plugins' formats (:func:`_plugin_formats`), loaded once a process."""
    return tuple(_plugin_formats())


def _installed() -> tuple[FileFormat, ...]:
    """Built-in formats then plugins."""
    return (*BUILT_IN, *_plugins())


def registered_formats() -> tuple[FileFormat, ...]:
    """Every format a recording can be read from: the built-in ones, then the plugins'.

    Returns
    -------
    tuple of FileFormat
        In the order :func:`format_of` tries them.
    """
    return _installed()


def format_named(name: str) -> FileFormat:
    """The registered format called ``name``.

    Parameters
    ----------
    name : str
        The format's registered name (``"csv"``, ``"parquet"``, ``"ulog"``, …).

    Returns
    -------
    FileFormat
        Its registry entry.

    Raises
    ------
    thermocal.errors.ParameterError
        No format has that name (the registered ones are listed).
    """
    for fmt in BUILT_IN:  # a built-in name needs no look at the installed packages
        if fmt.name == name:
            return fmt
    for fmt in _plugins():
        if fmt.name == name:
            return fmt
    names = ", ".join(f.name for f in _installed())
    raise ParameterError("format", f"{{name}} {name!r} is not registered; registered: {names}")


def _unknown_format_message(path: str | Path) -> str:
    """What to say of a file no registered format reads."""
    plugins = [f for f in _plugins() if f.suffixes]
    more = "".join(f", {', '.join(f.suffixes)} for {f.title}" for f in plugins)
    return (
        f"{path}: not a CSV or Parquet file (expected extension .csv, or .txt, .log, .tsv, "
        f".dat for a text log, .parquet, .ulg for a PX4 log, .bin for an ArduPilot log or "
        f".bag, .mcap for a ROS bag{more})"
    )


def format_of(path: str | Path) -> FileFormat:
    """The format of a file: the first registered format whose sniff function recognises the
    path, else the one whose suffix ends its name (the longest that matches).  The built-in
    formats are tried first, sniff then suffix; the installed packages' formats (their
    metadata read once) only for a path no built-in format recognises.

    Parameters
    ----------
    path : str or Path
        The file (or a station's recording folder).

    Returns
    -------
    FileFormat
        The registry entry that reads the file.

    Raises
    ------
    thermocal.errors.FileFormatError
        An unfinished output of an interrupted run, or no registered format has its
        suffix (the accepted ones are listed).

    Examples
    --------
    >>> from thermocal.readers.formats import format_of
    >>> format_of("flight.ulg").title, format_of("run.csv.gz").name
    ('a PX4 log', 'csv')
    """
    p = Path(path)
    for fmt in BUILT_IN:
        if fmt.sniff is not None and fmt.sniff(p):
            return fmt
    name = str(path).lower()
    built_in = None if name.endswith(TEMP_SUFFIX) else _longest_suffix(name, BUILT_IN)
    if built_in is not None:
        return built_in
    for fmt in _plugins():
        if fmt.sniff is not None and fmt.sniff(p):
            return fmt
    return _by_suffix(path)


def _longest_suffix(name: str, formats: tuple[FileFormat, ...]) -> FileFormat | None:
    """The format among ``formats`` whose suffix (the longest that matches) ends ``name``
    (lower-case), or None."""
    best: tuple[int, FileFormat] | None = None
    for fmt in formats:
        for s in fmt.suffixes:
            if name.endswith(s) and (best is None or len(s) > best[0]):
                best = (len(s), fmt)
    return None if best is None else best[1]


def _by_suffix(path: str | Path) -> FileFormat:
    """The registered format whose suffix (the longest that matches) ends ``path``'s name: a
    built-in one, else a plugin's (the installed packages looked at only then)."""
    name = str(path).lower()
    if name.endswith(TEMP_SUFFIX):
        raise FileFormatError(
            f"{path}: an unfinished output of an interrupted thermocal run, not a result; "
            "delete it (the next run to the same output removes it)"
        )
    found = _longest_suffix(name, BUILT_IN) or _longest_suffix(name, _plugins())
    if found is None:
        raise FileFormatError(_unknown_format_message(path))
    return found


def file_kind(path: str | Path) -> str:
    """The name of a file's format by its suffix alone (``"csv"``, ``"parquet"``, ``"ulog"``,
    ``"dataflash"`` or a plugin's).

    Parameters
    ----------
    path : str or pathlib.Path
        The file.

    Returns
    -------
    str
        The registered format's name.

    Raises
    ------
    thermocal.errors.FileFormatError
        No registered format has the file's suffix, or the file is an unfinished output.

    Examples
    --------
    >>> from thermocal.readers.formats import file_kind
    >>> file_kind("out.parquet")
    'parquet'
    """
    return _by_suffix(path).name


def file_suffix(path: str | Path) -> str:
    """The registered suffix that ends a file's name (the longest that matches), lower-case:
    what a file named after it keeps (``out.csv.gz`` → ``out_T+0.csv.gz``).

    Parameters
    ----------
    path : str or pathlib.Path
        The file.

    Returns
    -------
    str
        A suffix of the format :func:`file_kind` names.

    Raises
    ------
    thermocal.errors.FileFormatError
        No registered format has the file's suffix, or the file is an unfinished output.

    Examples
    --------
    >>> from thermocal.readers.formats import file_suffix
    >>> file_suffix("runs/warm.CSV.gz"), file_suffix("out.pq")
    ('.csv.gz', '.pq')
    """
    name = str(path).lower()
    return max((s for s in _by_suffix(path).suffixes if name.endswith(s)), key=len)


__all__ = [
    "BUILT_IN",
    "COLUMN_FIELDS",
    "ENTRY_POINT_GROUP",
    "TEXT_FIELDS",
    "ChunkMode",
    "FileFormat",
    "FormatPluginWarning",
    "Reader",
    "file_kind",
    "file_suffix",
    "format_named",
    "format_of",
    "registered_formats",
]
