"""Readers: one module per file format, one entry (:func:`read_recording`) for all of them.

=====================  ==========================================================
module                 format
=====================  ==========================================================
``table``              CSV and Parquet, units from sidecar, metadata or column names
``text``               text and serial-terminal logs (no header, banners, a rate)
``ulog``               PX4 ULog, by topic and instance
``dataflash``          ArduPilot DataFlash ``.bin``, by message
``station``            the folder ``thermocal station run`` writes
``dispatch``           :func:`read_recording`: the format chosen by the file
=====================  ==========================================================

Public entry points: :func:`read_recording` (every format, one set of options) and
:func:`recording_info` (what a file says of its columns, without reading them); for commands
that go through a file in chunks, :func:`read_log_table` (a flight-controller log's topic)
and :func:`read_text_table` (a text log read with its options); the flight-controller logs
themselves: :func:`ulog_sensor_instances`, :func:`read_dataflash_log`,
:func:`dataflash_table`, and :func:`parse_topic` for ``--topic``.
"""

from thermocal.readers.common import (
    DEFAULT_DATAFLASH_TOPIC,
    DEFAULT_ULOG_TOPIC,
    file_kind,
    parse_topic,
)
from thermocal.readers.dataflash import dataflash_table, read_dataflash_log
from thermocal.readers.dispatch import (
    read_log_table,
    read_recording,
    read_text_table,
    recording_info,
)
from thermocal.readers.text import TextOptions
from thermocal.readers.ulog import ulog_sensor_instances

__all__ = [
    "DEFAULT_DATAFLASH_TOPIC",
    "DEFAULT_ULOG_TOPIC",
    "TextOptions",
    "dataflash_table",
    "file_kind",
    "parse_topic",
    "read_dataflash_log",
    "read_log_table",
    "read_recording",
    "read_text_table",
    "recording_info",
    "ulog_sensor_instances",
]
