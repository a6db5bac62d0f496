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
"""

from thermocal.readers.common import file_kind
from thermocal.readers.dispatch import read_recording, recording_info
from thermocal.readers.text import TextOptions

__all__ = ["TextOptions", "file_kind", "read_recording", "recording_info"]
