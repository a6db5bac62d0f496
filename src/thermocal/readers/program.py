"""Chamber programs and temperature histories: the ``time_s, setpoint_c`` CSV that
``thermocal profile`` writes, and the temperature history of a program or a recording (for
``profile correlate``, ``simulate`` and ``station run``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from thermocal import defaults
from thermocal._lazy import LazyModule
from thermocal.defaults import PROGRAM_SETPOINT, PROGRAM_TIME
from thermocal.errors import FileFormatError, MissingColumnError, NonNumericError
from thermocal.outputs import refuse_special_input
from thermocal.profiles import check_program
from thermocal.readers.common import csv_float_options
from thermocal.readers.dispatch import read_recording
from thermocal.readers.formats import file_kind
from thermocal.readers.options import ReadOptions
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    import pandas as pd
else:
    pd = LazyModule("pandas")


def read_program(path: str | Path) -> tuple[FloatArray, FloatArray]:
    """Read a chamber program CSV (columns ``time_s`` and ``setpoint_c``).

    Parameters
    ----------
    path : str or Path
        The program, as :func:`thermocal.writers.write_program` writes it.

    Returns
    -------
    tuple of ndarray
        ``(time_s, setpoint_c)``: the times [s] and set-points [°C].

    Raises
    ------
    thermocal.errors.FileFormatError, thermocal.errors.MissingColumnError
        Not a readable CSV, or a column missing (named).
    thermocal.errors.NonNumericError, thermocal.errors.TimestampError
        A cell not a number, or times not increasing (file, row and column named).
    """
    p = Path(path)
    if not p.exists():
        raise FileFormatError(f"{p}: no such file")
    refuse_special_input(p, "program file")
    try:
        df = pd.read_csv(p, skipinitialspace=True, **csv_float_options())
    except (pd.errors.EmptyDataError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{p}: not a readable program CSV ({exc})") from None
    df.columns = [str(c).strip() for c in df.columns]
    for col in (PROGRAM_TIME, PROGRAM_SETPOINT):
        if col not in df.columns:
            raise MissingColumnError(
                f"{p}: no column {col!r}; a chamber program has columns time_s, setpoint_c "
                f"(found: {', '.join(map(repr, df.columns))})"
            )
    out = []
    for col in (PROGRAM_TIME, PROGRAM_SETPOINT):
        vals = pd.to_numeric(df[col], errors="coerce")
        bad = np.flatnonzero(vals.isna().to_numpy())
        if bad.size:
            raise NonNumericError(
                f"{p}: missing or non-numeric value {str(df[col].iloc[bad[0]])[:60]!r} in column "
                f"{col!r} at row {bad[0]} (line {bad[0] + 2})"
            )
        out.append(vals.to_numpy(dtype=np.float64))
    check_program(out[0], out[1], str(p))
    return out[0], out[1]


def read_history(
    path: Path,
    column: str | None = None,
    read: ReadOptions | None = None,
) -> tuple[FloatArray, FloatArray, str]:
    """A temperature history from a chamber program or a recording.

    Parameters
    ----------
    path : Path
        A chamber program CSV (``time_s, setpoint_c``) or a recording in any registered
        format.
    column : str, optional
        The column: a program's set-point unless another of its columns is named; a
        recording's first temperature column, else ``setpoint_c``.
    read : ReadOptions, optional
        How a recording is read (a text log's layout, a log's topic), as every command
        reads one (:func:`thermocal.readers.read_recording`).

    Returns
    -------
    tuple
        ``(time_s, temperature_c, column)``: times [s], temperatures [°C] and the column.

    Raises
    ------
    thermocal.errors.FileFormatError
        No such file, or one no registered format reads.
    thermocal.errors.MissingColumnError
        No temperature column known (the available ones are listed).
    """
    if not path.exists():
        raise FileFormatError(f"{path}: no such file")
    time_col: str | None = None
    if file_kind(path) == "csv":
        try:
            header = [str(c).strip() for c in pd.read_csv(path, nrows=0).columns]
        except (pd.errors.EmptyDataError, pd.errors.ParserError, UnicodeDecodeError) as exc:
            raise FileFormatError(f"{path}: not a readable CSV file ({exc})") from None
        is_program = defaults.PROGRAM_TIME in header and defaults.PROGRAM_SETPOINT in header
        if is_program and (column is None or column not in header):
            t, c = read_program(path)
            return t, c, defaults.PROGRAM_SETPOINT
        if defaults.PROGRAM_TIME in header and "time" not in header:
            time_col = defaults.PROGRAM_TIME
    r = read or ReadOptions()
    rec = read_recording(path, r.replace(time=time_col) if time_col is not None else r)
    if column is None:
        if rec.temperatures:
            column = rec.temperatures[0]
        elif defaults.PROGRAM_SETPOINT in rec.columns:
            column = defaults.PROGRAM_SETPOINT
        else:
            raise MissingColumnError.naming(
                f"{path}: no temperature column known; name one with {{column}} (available: "
                + ", ".join(repr(c) for c in rec.columns)
                + ")",
                "column",
            )
    values = rec.temperature_c(column) if column in rec.temperatures else rec.column(column)
    return rec.time_s, values, column
