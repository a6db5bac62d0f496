"""Readers: one module per file format, one registry of formats, one reading call.

=====================  ==========================================================
module                 format
=====================  ==========================================================
``table``              CSV and Parquet, units from sidecar, metadata or column names
``text``               text and serial-terminal logs (no header, banners, a rate)
``ulog``               PX4 ULog, by topic and instance
``dataflash``          ArduPilot DataFlash ``.bin``, by message
``station``            the folder ``thermocal station run`` writes
``bag``                ROS 1 bags, ROS 2 bag folders and MCAP files (``rosbags``)
``chunks``             the formats read a chunk at a time (CSV, Parquet, station)
``formats``            the file-format registry (:class:`FileFormat`, entry points)
``options``            :class:`ReadOptions`, how a file is read
``dispatch``           :func:`read_recording`: the format looked up in the registry
=====================  ==========================================================

Public entry points: :func:`read_recording` (every format, one :class:`ReadOptions`),
:func:`recording_info` (the metadata object written beside a recording),
:func:`read_whole_table` (a file read whole as one table, for commands that then go through
it in chunks), :func:`format_of` and :class:`FileFormat` (the registry); the
flight-controller logs themselves: :func:`ulog_sensor_instances`,
:func:`read_dataflash_log`, :func:`dataflash_table`, and :func:`parse_topic` for a topic.
"""

from typing import TYPE_CHECKING, Any

from thermocal.readers.common import (
    DEFAULT_DATAFLASH_TOPIC,
    DEFAULT_ULOG_TOPIC,
    parse_topic,
)
from thermocal.readers.dispatch import read_recording, read_whole_table, recording_info
from thermocal.readers.formats import (
    FileFormat,
    file_kind,
    format_of,
    registered_formats,
)
from thermocal.readers.options import ReadOptions

if TYPE_CHECKING:
    from thermocal.readers.dataflash import dataflash_table, read_dataflash_log
    from thermocal.readers.ulog import ulog_sensor_instances

_LATER = {
    "dataflash_table": "thermocal.readers.dataflash",
    "read_dataflash_log": "thermocal.readers.dataflash",
    "ulog_sensor_instances": "thermocal.readers.ulog",
}
"""The flight-controller logs' entry points, imported at their first use (a command reading
a table never imports the log readers)."""


def __getattr__(name: str) -> Any:
    if name in _LATER:
        import importlib

        return getattr(importlib.import_module(_LATER[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "DEFAULT_DATAFLASH_TOPIC",
    "DEFAULT_ULOG_TOPIC",
    "FileFormat",
    "ReadOptions",
    "dataflash_table",
    "file_kind",
    "format_of",
    "parse_topic",
    "read_dataflash_log",
    "read_recording",
    "read_whole_table",
    "recording_info",
    "registered_formats",
    "ulog_sensor_instances",
]
