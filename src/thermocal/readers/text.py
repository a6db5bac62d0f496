"""Text and serial-terminal logs: layout sniffed (delimiter, decimal mark, banner, header),
mangled lines counted and kept aside, a time column built from a stated rate."""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from thermocal import units
from thermocal._lazy import LazyModule
from thermocal.errors import (
    FileFormatError,
    TextLayoutWarning,
    ThermocalInputError,
)
from thermocal.readers.common import TIME_COLUMN_NAMES, check_unique_names
from thermocal.readers.options import ReadOptions
from thermocal.readers.table import ParquetColumns
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    import pandas as pd
else:
    pd = LazyModule("pandas")


# --- text logs (serial terminals, spreadsheets of other locales) ----------------------------


SNIFF_LINES = 400
"""Lines read to find a text log's layout (banner, delimiter, decimal mark, header)."""

_DELIMS = (",", ";", "\t", " ")


def _split(line: str, delim: str) -> list[str]:
    return line.split() if delim == " " else [f.strip() for f in line.split(delim)]


def parse_number(field: str) -> float:
    """A text field as a float, as a CSV reader takes it: ASCII digits, sign, ``.``,
    exponent, or ``nan``/``inf``.  Python's :func:`float` also accepts digit-group
    underscores (``0_5`` → 5.0) and non-ASCII digits (``١٢``); those are malformed numbers
    here (``ValueError``), so a mangled line is a bad line, not a silent value.

    Parameters
    ----------
    field : str
        One field of a text line.

    Returns
    -------
    float
        The number.

    Raises
    ------
    ValueError
        A malformed number (underscores, non-ASCII digits, any other text).

    Examples
    --------
    >>> from thermocal.readers.text import parse_number
    >>> parse_number(" -1.5e-3 ")
    -0.0015
    """
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


@dataclass(frozen=True)
class TextLayout:
    """A text log's layout found by :func:`sniff_text`: ``skip`` lines before the header
    (or first data row), the banner lines skipped, the delimiter, the decimal mark, whether
    the first kept line is a header, the number of fields.

    Attributes
    ----------
    skip : int
        Lines before the header (or first data row).
    banner : tuple of str
        The banner lines skipped.
    delimiter : str
        Field delimiter.
    decimal : str
        Decimal mark.
    header : bool
        The first kept line is a header.
    n_fields : int
        Number of fields.
    text_columns : tuple of int
        Positions of the fields that hold text.
    """

    skip: int
    banner: tuple[str, ...]
    delimiter: str
    decimal: str
    header: bool
    n_fields: int
    text_columns: tuple[int, ...] = ()
    """Positions of the fields that hold text on (nearly) every data line (a MAC address,
    a device name): kept as text, never parsed as numbers (:data:`TEXT_COLUMN_SHARE`)."""

    @property
    def plain(self) -> bool:
        """An ordinary comma CSV with a header and nothing to skip (the fast path)."""
        return self.skip == 0 and self.delimiter == "," and self.decimal == "." and self.header


def _best_delimiter(body: Sequence[str], delims: Sequence[str]) -> tuple[int, int, str] | None:
    """(-lines covered by the modal field count, order, delimiter) of the best delimiter."""
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
    return best


def sniff_text(lines: Sequence[str], opts: ReadOptions | None = None) -> TextLayout:
    """The layout of a text log from its first lines.

    For each candidate delimiter (``, ; tab blanks``, or the one given) the modal number of
    fields m (≥ 2) of the non-empty, non-``#`` lines; the delimiter whose modal count covers
    most lines wins (ties: in that order). Where no line has two fields and most lines are
    one number, one column (m = 1: Stable32's phase/frequency files). The data start at the
    first line with m fields that is numeric (empty fields: missing values), or that names
    the columns (no field a number) and is followed by a line of m fields (the header); the
    lines before are skipped, those but ``#`` comments as a banner (a terminal's, a
    logger's). Lines further down that do not fit are mangled lines, for ``on_bad_lines``.
    The decimal mark is ``,`` when the delimiter is not a comma and the data parse with
    ``,`` but not with ``.``.

    Parameters
    ----------
    lines : sequence of str
        The file's first lines, line ends removed.
    opts : ReadOptions, optional
        How the file is read (a given delimiter); default :class:`ReadOptions`.

    Returns
    -------
    TextLayout
        Delimiter, decimal mark, lines to skip, header and number of fields.

    Raises
    ------
    FileFormatError
        No layout found; ``TooManyColumnsError`` (a subclass) for too many columns.
    """
    o = opts or ReadOptions()
    delims = [o.delimiter] if o.delimiter else list(_DELIMS)
    delims = ["\t" if d == "\\t" else d for d in delims]
    body = [x for x in lines if x.strip() and not x.lstrip().startswith("#")]
    best = _best_delimiter(body, delims)
    if best is None:
        # one value a line (Stable32's phase and frequency files, a logger's single column):
        # one column when most lines are one number each
        single = [x for x in body if len(x.split()) == 1]
        dec1 = o.decimal or "."
        if (
            single
            and 2 * sum(_is_number(x, dec1) for x in single) > len(body)
            and (o.delimiter in (None, " "))
        ):
            best = (0, 0, " ")
        else:
            raise FileFormatError.naming(
                "no lines with two or more fields were found (is it a data log? give "
                "{delimiter} and {decimal} if it uses others than , ; tab blanks)",
                "delimiter",
                "decimal",
            )
    d = best[2]
    counts_d = [len(_split(x, d)) for x in body]
    m = max(set(c for c in counts_d if c >= 2) or {1}, key=counts_d.count)
    if m > MAX_COLUMNS:  # before any field is parsed: the parse is per field, in Python
        raise TooManyColumnsError(
            f"{m:,} fields a line, more than the {MAX_COLUMNS:,} columns a recording may "
            "have: not a data log (or cut it to the columns you use)"
        )
    decimals = [o.decimal] if o.decimal else ([".", ","] if d != "," else ["."])
    fields_m = [f for f in (_split(x, d) for x in body) if len(f) == m]
    texts = {c: _text_positions(fields_m, c) for c in decimals}

    text_sets = {c: frozenset(v) for c, v in texts.items()}  # membership O(1) per field

    def numeric(line: str, dec: str) -> bool:
        f = _split(line, d)
        tp = text_sets[dec]
        return (
            len(f) == m
            and len(tp) < m
            and all(_is_number(x, dec, empty=True) for j, x in enumerate(f) if j not in tp)
        )

    # the decimal mark under which most lines of m fields are numbers, with the fewest
    # text columns (ties: ".")
    dec = max(decimals, key=lambda c: (sum(numeric(x, c) for x in body), -len(texts[c]), c == "."))
    for k, line in enumerate(lines):
        if not line.strip() or line.lstrip().startswith("#") or len(_split(line, d)) != m:
            continue
        if numeric(line, dec):
            return TextLayout(k, _banner(lines[:k]), d, dec, False, m, texts[dec])
        names = _split(line, d)
        nxt = next((x for x in lines[k + 1 :] if x.strip()), None)
        is_names = all(f and not _is_number(f, dec) for f in names)
        if is_names and nxt is not None and len(_split(nxt, d)) == m:
            return TextLayout(k, _banner(lines[:k]), d, dec, True, m, texts[dec])
    raise FileFormatError.naming(
        f"no line of {m} numeric fields separated by {d!r} was found (give {{delimiter}} and "
        "{decimal} if the log uses others)",
        "delimiter",
        "decimal",
    )


TEXT_COLUMN_SHARE = 0.9
"""A field that is not a number on at least this share of the lines that hold numbers
elsewhere is a text column (:func:`_text_positions`)."""


def _text_positions(rows: Sequence[Sequence[str]], decimal: str) -> tuple[int, ...]:
    """The positions of ``rows`` (lines split into fields) that are text columns: among the
    lines with at least one number, those where the field is not a number on at least
    :data:`TEXT_COLUMN_SHARE` of them (a MAC address beside the samples).  A header (no
    number) does not count; a line with a stray word is a mangled line, not a column."""
    mixed = [f for f in rows if any(_is_number(x, decimal) for x in f)]
    if not mixed:
        return ()
    m = len(mixed[0])
    return tuple(
        j
        for j in range(m)
        if sum(not _is_number(f[j], decimal, empty=True) for f in mixed)
        >= TEXT_COLUMN_SHARE * len(mixed)
    )


def _banner(lines: Sequence[str]) -> tuple[str, ...]:
    """The lines before the data that are neither empty nor ``#`` comments."""
    return tuple(x for x in lines if x.strip() and not x.lstrip().startswith("#"))


MAX_LINE_CHARS = 1 << 20
"""Longest line a text reader takes [characters]: 1 MiB, about 50 000 numeric fields (the
station cuts a sensor's line at 10 MB).  A longer line is refused naming the file and the
line: one 10 MB line split into five million fields hung the layout detection.
``THERMOCAL_MAX_LINE`` (characters) raises it."""


class TooManyColumnsError(FileFormatError):
    """A text log whose lines hold more than :data:`MAX_COLUMNS` fields (:func:`sniff_text`):
    never passed on to pandas, which would take minutes over the columns."""


MAX_COLUMNS = 10_000
"""Most columns a table may have: pandas builds one object per column before it reads a
row (90 000 columns: 40 s; the 500 000 a 1 MiB line can hold: minutes)."""


def check_column_count(path: Path, n_columns: int) -> None:
    """A :class:`FileFormatError` naming ``path`` when it has more than
    :data:`MAX_COLUMNS` columns.

    Parameters
    ----------
    path : pathlib.Path
        The file named in the error.
    n_columns : int
        The file's number of columns.

    Raises
    ------
    FileFormatError
        More than :data:`MAX_COLUMNS` columns.
    """
    if n_columns > MAX_COLUMNS:
        raise FileFormatError(
            f"{path}: {n_columns:,} columns, more than the {MAX_COLUMNS:,} a recording may "
            "have: not a data log (or cut it to the columns you use)"
        )


def max_line_chars() -> int:
    """:data:`MAX_LINE_CHARS`, or ``THERMOCAL_MAX_LINE`` when set (a positive integer).

    Returns
    -------
    int
        The longest line a text reader accepts [characters].

    Raises
    ------
    ThermocalInputError
        ``THERMOCAL_MAX_LINE`` set to something other than a positive integer.
    """
    env = os.environ.get("THERMOCAL_MAX_LINE", "").strip()
    if not env:
        return MAX_LINE_CHARS
    try:
        value = int(env)
    except ValueError:
        value = 0
    if value < 1:
        raise ThermocalInputError(f"THERMOCAL_MAX_LINE={env!r}: give a positive integer")
    return value


def bounded_line(fh: IO[str], path: Path, lineno: int, limit: int) -> str:
    """The next line of ``fh`` (line end kept; ``""`` at the end) read up to ``limit``
    characters; a longer one is a :class:`FileFormatError` naming ``path`` and ``lineno``.

    Parameters
    ----------
    fh : file-like of str
        The open text file.
    path : pathlib.Path
        The file named in the error.
    lineno : int
        The line's number (1-based), named in the error.
    limit : int
        Longest line accepted [characters].

    Returns
    -------
    str
        The line, its end kept; ``""`` at the end of the file.

    Raises
    ------
    FileFormatError
        A line longer than ``limit``.
    """
    line = fh.readline(limit + 1)
    if len(line) > limit and not (len(line) == limit + 1 and line.endswith("\n")):
        raise FileFormatError(
            f"{path}: line {lineno} is longer than {limit:,} characters: not a line of a "
            "data log (cut the file, or set THERMOCAL_MAX_LINE to read longer lines)"
        )
    return line


def head_lines(path: Path, encoding: str, errors: str) -> list[str]:
    """The first :data:`SNIFF_LINES` lines of a text file, line ends removed (each bounded
    by :func:`max_line_chars`).

    Parameters
    ----------
    path : pathlib.Path
        The text file.
    encoding : str
        Its encoding (:func:`~thermocal.readers.common.csv_encoding`).
    errors : str
        How decoding errors are handled (``"strict"``, ``"replace"``).

    Returns
    -------
    list of str
        Up to :data:`SNIFF_LINES` lines.

    Raises
    ------
    FileFormatError
        A line longer than :func:`max_line_chars`.
    """
    limit = max_line_chars()
    with open(path, encoding=encoding, errors=errors, newline="") as fh:
        return [bounded_line(fh, path, k, limit).rstrip("\r\n") for k in range(1, SNIFF_LINES + 1)]


def delimiter_name(delimiter: str) -> str:
    """How a warning names a delimiter: ``tab``, ``blank`` or the quoted character.

    Parameters
    ----------
    delimiter : str
        The delimiter.

    Returns
    -------
    str
        ``"tab"``, ``"blank"`` or the quoted character.
    """
    return {"\t": "tab", " ": "blank"}.get(delimiter, repr(delimiter))


def csv_chunk_options(path: Path, encoding: str) -> dict[str, Any]:
    """``pandas.read_csv`` options for reading a text file in chunks (compensate): the
    detected delimiter, decimal mark and banner lines to skip, stated in a warning when
    not a plain comma CSV; a file without a header row is refused (name the columns).

    Parameters
    ----------
    path : pathlib.Path
        The text file.
    encoding : str
        Its encoding.

    Returns
    -------
    dict
        Keyword options for :func:`pandas.read_csv` (``sep``, ``decimal``, ``skiprows``);
        ``{}`` for a plain comma CSV or a gzip file.

    Raises
    ------
    FileFormatError
        Too many columns.
    ThermocalInputError
        A file without a header row.

    Warns
    -----
    TextLayoutWarning
        A layout other than a plain comma CSV.
    """
    if path.name.lower().endswith(".gz"):
        return {}
    head = head_lines(path, encoding, "replace")
    try:
        lay = sniff_text(head)
    except TooManyColumnsError as exc:
        raise FileFormatError(f"{path}: {exc}") from None
    except FileFormatError:
        return {}  # the CSV reader says what is wrong
    check_column_count(path, lay.n_fields)
    if lay.plain:
        return {}
    if not lay.header:
        raise ThermocalInputError.naming(
            f"{path}: no header row (line {lay.skip + 1} is data); compensate needs named "
            "columns: add a header line, or read it with {names} in another command and "
            "write it out",
            "names",
        )
    warnings.warn(
        TextLayoutWarning(
            f"{path}: read as {delimiter_name(lay.delimiter)}-separated text with decimal "
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


def _column_names(path: Path, head: list[str], lay: TextLayout, o: ReadOptions) -> list[str]:
    """The header row's names, or ``names`` for a file without one (refused with a
    header, or when their number is not the number of fields)."""
    if lay.header:
        names = [c.strip() for c in _split(head[lay.skip], lay.delimiter)]
        check_unique_names(path, names)
        if o.names is not None:
            raise ThermocalInputError.naming(
                f"{path}: the file has a header row ({', '.join(names)}); {{names}} is for "
                "files without one",
                "names",
            )
    elif o.names is None:
        what = (
            "name its column with {names} NAME (and give {rate_hz} HZ: no time column)"
            if lay.n_fields == 1
            else f"name its {lay.n_fields} columns with {{names}} a,b,c"
        )
        raise ThermocalInputError.naming(
            f"{path}: no header row (line {lay.skip + 1} is data: "
            f"{head[lay.skip].strip()[:60]!r}); {what}",
            "names",
            "rate_hz",
        )
    else:
        names = list(o.names)
        if len(names) != lay.n_fields:
            raise ThermocalInputError.naming(
                f"{path}: {{names}} gives {len(names)} names for {lay.n_fields} columns "
                f"(line {lay.skip + 1}: {head[lay.skip].strip()[:60]!r})",
                "names",
            )
    return names


def _data_rows(
    path: Path, encoding: str, lay: TextLayout, n: int, on_bad_lines: str
) -> tuple[list[list[float]], list[int], list[tuple[int, str]], dict[int, list[str]], list[int]]:
    """The data rows as floats, each kept row's place among the data lines, the mangled
    lines dropped (line number, text), the text columns' fields (position → the kept
    rows' texts; NaN stands in their place among the floats) and each kept row's line in
    the file (for messages): another number of fields
    than ``n``, or a non-number outside a text column, is an error naming the line unless
    ``on_bad_lines`` is ``"skip"``."""
    tp = set(lay.text_columns)
    texts: dict[int, list[str]] = {j: [] for j in lay.text_columns}
    linenos: list[int] = []  # each kept row's line in the file (1-based)
    first_data = lay.skip + (1 if lay.header else 0)  # 0-based line of the first data row
    bad: list[tuple[int, str]] = []
    rows: list[list[float]] = []
    ordinal: list[int] = []  # each kept row's place among the data lines (dropped ones too)
    n_data = 0
    limit = max_line_chars()
    with open(path, encoding=encoding, errors="strict", newline="") as fh:
        lineno = 0
        while line := bounded_line(fh, path, lineno + 1, limit):
            lineno += 1
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
                    [
                        math.nan
                        if j in tp
                        else parse_number(f.replace(",", ".") if lay.decimal == "," else f)
                        for j, f in enumerate(fields)
                    ]
                )
                for j in tp:
                    texts[j].append(fields[j])
                ordinal.append(n_data - 1)
                linenos.append(lineno)
            except ValueError as exc:
                if on_bad_lines == "error":
                    raise FileFormatError.naming(
                        f"{path}: line {lineno} is not a data row ({exc}): {text.strip()[:80]!r}; "
                        "fix it or pass {on_bad_lines} skip to drop such lines",
                        "on_bad_lines",
                    ) from None
                bad.append((lineno, text))
    return rows, ordinal, bad, texts, linenos


def read_text(
    path: Path, encoding: str, opts: ReadOptions | None
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """A text log as a DataFrame of floats: banner skipped, delimiter and decimal mark
    detected (or given), header taken from ``names`` when the file has none, mangled
    lines (another number of fields, a non-number) refused naming the first or, with
    ``on_bad_lines="skip"``, dropped and counted.  Warnings say what was skipped.

    Parameters
    ----------
    path : pathlib.Path
        The text file.
    encoding : str
        Its encoding.
    opts : ReadOptions or None
        How the file is read (delimiter, names, bad lines); ``None``: the defaults.

    Returns
    -------
    tuple of (pandas.DataFrame, dict)
        The data as float64 columns, and what was found (layout, lines skipped).

    Raises
    ------
    FileFormatError
        No layout, no data row, a mangled line (unless ``on_bad_lines="skip"``), too many
        columns or too long a line.

    Warns
    -----
    TextLayoutWarning
        Lines skipped or dropped, a layout other than a plain comma CSV.
    """
    o = opts or ReadOptions()
    head = head_lines(path, encoding, "strict")
    try:
        lay = sniff_text(head, o)
    except FileFormatError as exc:
        raise FileFormatError.naming(f"{path}: {exc.template or exc}", *exc.parameters) from None
    names = _column_names(path, head, lay, o)
    check_column_count(path, len(names))
    rows, ordinal, bad, texts, linenos = _data_rows(path, encoding, lay, len(names), o.on_bad_lines)
    if not rows:
        raise FileFormatError(f"{path}: the file has a header but no data rows")
    df = pd.DataFrame(np.asarray(rows, dtype=np.float64), columns=names)
    df.attrs["file_lines"] = np.asarray(linenos, dtype=np.int64)  # for messages
    for j, values in texts.items():  # kept as text: refused only where a command uses it
        df[names[j]] = pd.Series(values, dtype=object)
    # rate_hz: time = data-line number / rate, so a dropped line leaves a gap, not a shift
    df.attrs["row_index"] = np.asarray(ordinal, dtype=np.float64)
    report: dict[str, Any] = {
        "text_layout": {
            "banner_lines": len(lay.banner),
            "banner": [b.strip()[:80] for b in lay.banner[:10]],
            "delimiter": "\t" if lay.delimiter == "\t" else lay.delimiter,
            "decimal": lay.decimal,
            "header": lay.header,
            "bad_lines": [ln for ln, _t in bad],
        }
    }
    if (lay.delimiter != "," and lay.n_fields > 1) or lay.decimal != ".":
        warnings.warn(
            TextLayoutWarning.naming(
                f"{path}: read as {delimiter_name(lay.delimiter)}-separated text with decimal "
                f"mark {lay.decimal!r} (give {{delimiter}}/{{decimal}} if that is wrong)",
                "delimiter",
                "decimal",
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
            TextLayoutWarning.naming(
                f"{path}: {len(bad)} mangled line(s) dropped ({{on_bad_lines}} skip): "
                f"line(s) {shown}",
                "on_bad_lines",
            ),
            stacklevel=3,
        )
    return df, report


COUNTER_COLUMN_NAMES = (
    "n_samples",
    "samples",
    "sample",
    "sample_index",
    "counter",
    "count",
    "index",
    "idx",
    "seq",
    "n",
)
"""Names a sample counter goes by (compared without case): with ``rate_hz`` such a column is
the time, ``counter / rate`` (imucal's sessions: ``n_samples``)."""


def counter_column(names: Sequence[str]) -> str | None:
    """The one column named like a sample counter (:data:`COUNTER_COLUMN_NAMES`), else None.

    Parameters
    ----------
    names : sequence of str
        Column names.

    Returns
    -------
    str or None
        The counter column's name; ``None`` for none or several.
    """
    found = [c for c in names if c.strip().lower() in COUNTER_COLUMN_NAMES]
    return found[0] if len(found) == 1 else None


def rate_time(
    p: Path,
    obj: Any,
    names: list[str],
    info: dict[str, Any],
    time: str | None,
    time_unit: str | None,
    text: ReadOptions,
    *,
    allow_column: bool = True,
) -> tuple[Any, list[str], str, str | None, str]:
    r"""``rate_hz``: the time of each sample at the stated rate, and how it is found (the
    last item): ``"rows"`` — a file without a time column gets ``time = row / rate`` [s],
    the row counted among the log's data lines (a mangled line dropped leaves a gap);
    ``"counter"`` — a sample counter (``time="N"``, or the one column named like one,
    :data:`COUNTER_COLUMN_NAMES`) is the time, ``counter / rate`` (:func:`counter_time`);
    ``"stamps"`` — a time column (host timestamps) is replaced by the nominal grid
    (:func:`thermocal.recording.nominal_time`).  The last two are read by the caller;
    without ``allow_column`` (a command that streams the file) a time column is refused.

    Parameters
    ----------
    p : pathlib.Path
        The file, named in messages.
    obj : pandas.DataFrame or pyarrow.Table
        The data read so far.
    names : list of str
        Its column names.
    info : dict
        What the reader found (a stated time column).
    time : str or None
        The time (or counter) column given by the user.
    time_unit : str or None
        The unit of that column.
    text : ReadOptions
        How the file is read; ``rate_hz`` [Hz] must be set.
    allow_column : bool, optional
        Whether a time column may be replaced by the nominal grid; default ``True``.

    Returns
    -------
    tuple
        ``(obj, names, time column, time unit, how)`` with ``how`` one of ``"rows"``,
        ``"counter"``, ``"stamps"``.

    Raises
    ------
    ThermocalInputError
        A time column where none is allowed, or a named column that is missing.

    Notes
    -----
    .. math:: t_i = \frac{i}{f_s}\ \mathrm{[s]}, \qquad f_s = \texttt{rate\_hz}
    """
    assert text.rate_hz is not None
    named = time or info.get("time")
    if named is None and "time" not in names:
        named = counter_column(names)
    col = named or "time"
    if col in names:
        is_counter = col.strip().lower() in COUNTER_COLUMN_NAMES or (
            time is not None
            and col == time
            and time_unit is None
            and col.strip().lower() not in TIME_COLUMN_NAMES
            and units.unit_in_column_name(col, "time") is None
        )
        if not allow_column:
            raise ThermocalInputError.naming(
                f"{p}: {{rate_hz}} {text.rate_hz:g} Hz given but the file has a time column "
                f"{col!r}; drop {{rate_hz}}"
                if not is_counter
                else f"{p}: this command streams the file and cannot take the sample counter "
                f"{col!r} as time; add a time column (time = {col} / {text.rate_hz:g} Hz) "
                "and drop {rate_hz}",
                "rate_hz",
            )
        if is_counter and time_unit not in (None, "s"):
            raise ThermocalInputError.naming(
                f"{p}: {{rate_hz}} {text.rate_hz:g} Hz counts the samples of {col!r}; "
                "drop {time_unit}",
                "rate_hz",
                "time_unit",
            )
        return obj, names, col, time_unit, "counter" if is_counter else "stamps"
    if isinstance(obj, ParquetColumns):
        raise ThermocalInputError.naming(
            f"{p}: {{rate_hz}} is for text logs; a Parquet file has its time", "rate_hz"
        )
    if time_unit not in (None, "s"):
        raise ThermocalInputError.naming(
            "{rate_hz} gives the time in seconds; drop {time_unit}", "rate_hz", "time_unit"
        )
    rows = obj.attrs.get("row_index")
    if rows is None or len(rows) != len(obj):
        rows = np.arange(len(obj), dtype=np.float64)
    obj = obj.copy()
    obj.insert(0, col, np.asarray(rows, dtype=np.float64) / float(text.rate_hz))
    return obj, [col, *names], col, "s", "rows"


def counter_time(p: Path, col: str, counts: FloatArray, rate_hz: float) -> FloatArray:
    r"""A sample counter's time [s]: ``t = n / rate``.  The counter must hold whole numbers
    that increase (a skipped number is a gap: samples lost); anything else is refused,
    naming the first row that is not.

    Parameters
    ----------
    p : pathlib.Path
        The file, named in the error.
    col : str
        The counter column's name.
    counts : numpy.ndarray
        The counter's values.
    rate_hz : float
        The sample rate [Hz].

    Returns
    -------
    numpy.ndarray
        Time [s], ``counts / rate_hz``.

    Raises
    ------
    ThermocalInputError
        A value that is not a whole number, or a counter that does not increase.

    Notes
    -----
    .. math:: t_i = \frac{n_i}{f_s}

    Examples
    --------
    >>> import numpy as np
    >>> from pathlib import Path
    >>> from thermocal.readers.text import counter_time
    >>> counter_time(Path("log.txt"), "n", np.array([10.0, 11.0, 13.0]), 100.0).tolist()
    [0.1, 0.11, 0.13]
    """
    fin = np.isfinite(counts)
    whole = fin & (counts == np.round(counts))
    if not bool(whole.all()):
        row = int(np.argmin(whole))
        raise ThermocalInputError.naming(
            f"{p}: {{rate_hz}} {rate_hz:g} Hz takes {col!r} for a sample counter, but row {row} "
            f"holds {float(counts[row])!r}, not a whole number; name the time column with "
            "{time}",
            "rate_hz",
            "time",
        )
    steps = np.diff(counts)
    if steps.size and not bool((steps > 0).all()):
        row = int(np.argmin(steps > 0)) + 1
        raise ThermocalInputError(
            f"{p}: the sample counter {col!r} does not increase at row {row} "
            f"({counts[row - 1]:g} → {counts[row]:g}): samples repeated or the counter wrapped"
        )
    out: FloatArray = counts / float(rate_hz)
    return out
