"""A recording folder written by ``thermocal station run``, read as one recording.

The folder's layout (``station.json``, closed parts ``SENSOR-NNNN.parquet``, the temporary
name of a part being written) is described in :mod:`thermocal.station.recorder`, the writer,
which imports its names from here: the reader needs nothing of the station's drivers.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal.errors import FileFormatError
from thermocal.readers.common import thermocal_metadata

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa

STATION_JSON = "station.json"
STATION_FORMAT = "thermocal-station"
STATION_VERSION = 1
PART_RE = re.compile(r"^(?P<stream>[A-Za-z0-9][A-Za-z0-9_]*)-(?P<index>\d{4,})\.parquet$")
CHAMBER_STREAM = "chamber"
"""The stream of the chamber's polled temperature and set-point (not a sensor id)."""


def closed_parts(out_dir: Path, stream: str | None = None) -> list[tuple[str, int, Path]]:
    """Closed parts in ``out_dir`` as ``(stream, index, path)``, in stream and index order.

    Parameters
    ----------
    out_dir : pathlib.Path
        The station folder.
    stream : str, optional
        Only this stream's parts (a sensor id or ``chamber``); default all.

    Returns
    -------
    list of (str, int, pathlib.Path)
        Stream, part index and path of each closed part.
    """
    out = []
    for p in out_dir.iterdir():
        m = PART_RE.match(p.name)
        if m and (stream is None or m["stream"] == stream):
            out.append((m["stream"], int(m["index"]), p))
    return sorted(out, key=lambda x: (x[0], x[1]))


def read_station_json(out_dir: Path) -> dict[str, Any]:
    """Read and check a folder's ``station.json``.

    Parameters
    ----------
    out_dir : pathlib.Path
        The station folder.

    Returns
    -------
    dict
        The station file's object (format, version, sensors).

    Raises
    ------
    FileFormatError
        No ``station.json``, invalid JSON, not a thermocal station file, a version that is
        not an integer or newer than this thermocal's, or bad sensor ids.
    """
    p = out_dir / STATION_JSON
    if not p.is_file():
        raise FileFormatError(f"{out_dir}: not a station recording (no {STATION_JSON})")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{p}: not valid JSON ({exc})") from None
    except RecursionError:  # thousands of nested brackets: no station file is built so
        raise FileFormatError(f"{p}: nested too deeply to be a thermocal station file") from None
    if not isinstance(doc, dict) or doc.get("format") != STATION_FORMAT:
        raise FileFormatError(f"{p}: not a thermocal station file")
    version = doc.get("version", 0)
    if not isinstance(version, int) or isinstance(version, bool):
        raise FileFormatError(f"{p}: 'version' must be an integer, got {version!r}")
    if version > STATION_VERSION:
        raise FileFormatError(f"{p}: written by a newer thermocal (version {version})")
    _checked_sensor_ids(doc, p)
    return doc


def is_station_path(path: Path) -> bool:
    """``DIR`` or ``DIR/SENSOR`` of a station recording.

    Parameters
    ----------
    path : pathlib.Path
        A path given by the user.

    Returns
    -------
    bool
        Whether it is a station folder, or a sensor inside one.
    """
    if path.is_dir():
        return (path / STATION_JSON).is_file()
    return not path.exists() and (path.parent / STATION_JSON).is_file()


def _checked_sensor_ids(doc: dict[str, Any], where: Path) -> list[str]:
    """The sensor ids of ``config.sensors``, each a stream name as the recorder writes it
    (letters, digits and ``_``, not the chamber's): an id with ``/`` or ``..`` would name a
    path outside the folder.  A malformed list is a :class:`FileFormatError` naming it."""
    config = doc.get("config") or {}
    sensors = config.get("sensors", []) if isinstance(config, dict) else None
    if not isinstance(sensors, list):
        raise FileFormatError(f"{where}: 'config.sensors' must be a list of {{\"id\": ...}}")
    ids = []
    for s in sensors:
        sid = s.get("id") if isinstance(s, dict) else None
        m = PART_RE.match(f"{sid}-0000.parquet") if isinstance(sid, str) else None
        if m is None or m["stream"] != sid or sid == CHAMBER_STREAM:
            raise FileFormatError(
                f"{where}: sensor id {sid!r} in 'config.sensors' is not a stream name "
                f"(letters, digits and _, not {CHAMBER_STREAM!r})"
            )
        ids.append(sid)
    return ids


def sensor_ids(doc: dict[str, Any]) -> list[str]:
    """The sensor ids of a station file read by :func:`read_station_json` (checked there).

    Parameters
    ----------
    doc : dict
        The station file's object.

    Returns
    -------
    list of str
        The sensor ids, in the file's order.
    """
    return _checked_sensor_ids(doc, Path(STATION_JSON))


def _stream_of(path: Path) -> tuple[Path, str]:
    """``(DIR, stream)`` of ``DIR`` (its only sensor) or ``DIR/SENSOR``."""
    if path.is_dir():
        doc = read_station_json(path)
        ids = sensor_ids(doc)
        if len(ids) != 1:
            raise FileFormatError.naming(
                f"{path}: a station recording of {len(ids)} sensors ({', '.join(ids)}); "
                f"name one with {{sensor}} ID or as {path}/ID (or {path}/{CHAMBER_STREAM})",
                "sensor",
            )
        return path, ids[0]
    doc = read_station_json(path.parent)
    ids = sensor_ids(doc)
    if path.name not in (*ids, CHAMBER_STREAM):
        raise FileFormatError(
            f"{path}: no sensor {path.name!r} in this station recording; sensors: "
            f"{', '.join([*ids, CHAMBER_STREAM])}"
        )
    return path.parent, path.name


def with_sensor(path: Path, sensor: str | None) -> Path:
    """``DIR/SENSOR`` for the sensor ``sensor`` (a station recording folder ``DIR`` is read
    as one recording, of the sensor named when there are several).  ``path`` is ``DIR`` or
    ``DIR/ID``; without ``sensor`` it is returned as it is.  A sensor the recording does not
    have, or ``DIR/A`` with ``sensor="B"``, is a :class:`FileFormatError` naming the sensors.

    Parameters
    ----------
    path : pathlib.Path
        ``DIR`` or ``DIR/ID``.
    sensor : str or None
        The sensor id chosen by the user.

    Returns
    -------
    pathlib.Path
        ``DIR/SENSOR`` (or ``path`` unchanged without ``sensor``).

    Raises
    ------
    FileFormatError
        A sensor the recording does not have, or two different sensors named.
    """
    if sensor is None:
        return path
    if not path.is_dir():
        if path.name != sensor:
            raise FileFormatError.naming(
                f"{path}: names sensor {path.name!r} and {{sensor}} names {sensor!r}; give one",
                "sensor",
            )
        return path
    ids = sensor_ids(read_station_json(path))
    if sensor not in (*ids, CHAMBER_STREAM):
        raise FileFormatError(
            f"{path}: no sensor {sensor!r} in this station recording; sensors: "
            f"{', '.join([*ids, CHAMBER_STREAM])}"
        )
    return path / sensor


def station_sensor_paths(paths: Sequence[Path], sensor: str | None) -> list[Path]:
    """``paths`` with every station folder given as ``DIR`` turned into ``DIR/SENSOR``
    (:func:`with_sensor`): what provenance records and hashes.  Other files are unchanged.

    Parameters
    ----------
    paths : sequence of pathlib.Path
        Paths given by the user.
    sensor : str or None
        The sensor id chosen by the user.

    Returns
    -------
    list of pathlib.Path
        The paths with each station folder narrowed to its sensor.

    Raises
    ------
    FileFormatError
        As :func:`with_sensor`.
    """
    return [with_sensor(p, sensor) if is_station_path(p) else p for p in paths]


def station_files(path: Path) -> list[Path]:
    """The closed parts of ``DIR`` or ``DIR/SENSOR``, in order (the recording's content).

    Parameters
    ----------
    path : pathlib.Path
        ``DIR`` or ``DIR/SENSOR``.

    Returns
    -------
    list of pathlib.Path
        The closed Parquet parts, in index order.

    Raises
    ------
    FileFormatError
        No closed part of the stream yet (or not a station folder).
    """
    out_dir, stream = _stream_of(path)
    parts = closed_parts(out_dir, stream)
    if not parts:
        raise FileFormatError(f"{out_dir}: no closed part of {stream!r} yet")
    return [p for _s, _i, p in parts]


def read_station(path: Path) -> tuple[pa.Table, dict[str, Any]]:
    """A station recording as one table: ``DIR`` (its only sensor) or ``DIR/SENSOR`` (one
    of several, or ``DIR/chamber``).  The closed parts are concatenated in order; the
    metadata object is the last part's.  Raises :class:`FileFormatError` naming what is
    missing.

    Parameters
    ----------
    path : pathlib.Path
        ``DIR`` or ``DIR/SENSOR``.

    Returns
    -------
    tuple of (pyarrow.Table, dict)
        The concatenated parts and the last part's thermocal metadata.

    Raises
    ------
    FileFormatError
        Not a station recording, no closed part, a corrupt part, or parts whose columns
        or units differ.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    files = station_files(path)
    tables = []
    for p in files:
        try:
            tables.append(pq.read_table(p))
        except (pa.ArrowInvalid, OSError) as exc:
            raise FileFormatError(f"{p}: not a readable Parquet part ({exc})") from None
    for p, t in zip(files[1:], tables[1:], strict=True):
        if t.schema.names != tables[0].schema.names:
            raise FileFormatError(
                f"{p}: columns {t.schema.names} differ from the first part's "
                f"{tables[0].schema.names}"
            )
    meta = thermocal_metadata(tables[-1].schema.metadata, files[-1])
    for p, t in zip(files[:-1], tables[:-1], strict=True):
        _same_units(p, thermocal_metadata(t.schema.metadata, p), files[-1], meta)
    try:  # a column stored float32 in one part and float64 in another is widened
        table = pa.concat_tables(
            [t.replace_schema_metadata(None) for t in tables], promote_options="permissive"
        )
    except (pa.ArrowInvalid, pa.ArrowTypeError) as exc:
        raise FileFormatError(f"{path}: parts whose column types disagree ({exc})") from None
    return table, meta


def _same_units(p: Path, m: dict[str, Any], last: Path, m_last: dict[str, Any]) -> None:
    """Parts of one recording read in one set of units: a column whose unit (or role) in
    part ``p`` differs from the last part's is refused, naming both."""

    def units_of(md: dict[str, Any]) -> dict[str, str]:
        out = {"time": str(md.get("time_unit"))}
        for role in ("signals", "temperatures", "units"):
            d = md.get(role)
            out |= {str(k): f"{v} ({role})" for k, v in (d.items() if isinstance(d, dict) else ())}
        return out

    mine, theirs = units_of(m), units_of(m_last)
    for col in sorted(set(mine) | set(theirs)):
        if mine.get(col) != theirs.get(col):
            raise FileFormatError(
                f"{p}: column {col!r} is {mine.get(col, 'absent')} here and "
                f"{theirs.get(col, 'absent')} in {last.name}: the parts were recorded in "
                "different units; read them apart (copy the parts of one setting to a folder "
                "of their own)"
            )


def read_station_table(p: Path) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The closed Parquet parts of a station recording as one table (:func:`read_station`).

    Parameters
    ----------
    p : pathlib.Path
        ``DIR`` or ``DIR/SENSOR``.

    Returns
    -------
    tuple of (pandas.DataFrame, dict)
        The data and the last part's thermocal metadata.

    Raises
    ------
    FileFormatError
        As :func:`read_station`.
    """
    table, meta = read_station(p)
    return table.to_pandas(), meta


__all__ = [
    "CHAMBER_STREAM",
    "STATION_FORMAT",
    "STATION_JSON",
    "STATION_VERSION",
    "closed_parts",
    "is_station_path",
    "read_station",
    "read_station_json",
    "read_station_table",
    "sensor_ids",
    "station_files",
    "station_sensor_paths",
    "with_sensor",
]
