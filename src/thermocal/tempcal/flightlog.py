"""A PX4 flight log read once: :class:`FlightLog`, what ``px4-tempcal`` passes down.

:func:`open_px4_log` parses the ULog's sensor topics once (pyulog, within
:func:`thermocal.readers.ulog.parsed_once`) and gathers what the calibration needs of the
log: the sensor instances that carry a temperature, the parameters in the log's header and
those changed during the recording.  Each sensor's data are handed out from that one parse
(:meth:`FlightLog.recording`, :meth:`FlightLog.table`), so no part of the pipeline opens
the file again.

References
----------
* PX4 ULog File Format, https://docs.px4.io/main/en/dev_log/ulog_file_format.html
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas as pd

    from thermocal.recording import Recording


@dataclass(frozen=True)
class FlightLog:
    """A PX4 ULog as the thermal calibration reads it.

    Parameters
    ----------
    path : Path
        The log file.
    topics : tuple of str
        The topics parsed (``sensor_gyro``, ``sensor_accel``, ``sensor_baro``, ``sensor_mag``).
    instances : tuple of (str, int)
        The topic instances that carry a usable temperature, sorted (each instance left out
        is said in a warning when the log is opened).
    parameters : Mapping[str, float]
        The parameters of the log's header (the values at the start of the recording).
    parameter_changes : tuple of (float, str, float)
        Parameters set during the recording: (log time [s], name, value), in log order.
    """

    path: Path
    topics: tuple[str, ...]
    instances: tuple[tuple[str, int], ...]
    parameters: Mapping[str, float]
    parameter_changes: tuple[tuple[float, str, float], ...]

    def recording(self, topic: str) -> Recording:
        """One IMU topic instance as a checked recording, served from the log's one parse.

        Parameters
        ----------
        topic : str
            The topic instance, ``NAME.N``.

        Returns
        -------
        thermocal.recording.Recording
            x, y, z and ``temperature`` in the canonical units (°/h or mg; °C), checked (finite,
            increasing time), its gaps said in one warning.

        Raises
        ------
        ThermocalInputError
            When the topic is missing or its data are unusable.
        """
        from thermocal.pipeline.reading import check_recording
        from thermocal.readers.dispatch import read_recording
        from thermocal.readers.options import ReadOptions

        read = ReadOptions(signals=("x", "y", "z"), temperatures=("temperature",), topic=topic)
        return check_recording(read_recording(self.path, read), read)

    def table(self, topic: str) -> tuple[pd.DataFrame, dict[str, Any]]:
        """One topic instance as a table of its fields, served from the log's one parse.

        Parameters
        ----------
        topic : str
            The topic instance, ``NAME.N``.

        Returns
        -------
        tuple
            (the fields as a pandas.DataFrame in PX4's units, the topic's metadata).
        """
        from thermocal.readers.dispatch import read_whole_table
        from thermocal.readers.options import ReadOptions

        return read_whole_table(self.path, ReadOptions(topic=topic))


@contextlib.contextmanager
def open_px4_log(path: Path, topics: tuple[str, ...]) -> Iterator[FlightLog]:
    """The ULog ``path`` read once for ``topics``: within the block, :class:`FlightLog` and
    every read of its topics are served from one parse.

    Parameters
    ----------
    path : Path
        A PX4 ULog (``.ulg``).
    topics : tuple of str
        The sensor topics to parse.

    Yields
    ------
    FlightLog
        Its instances, parameters and parameter changes.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        The file is not a readable ULog (said by the reader, naming the file).
    """
    from thermocal.readers.ulog import parsed_once, ulog_parameter_changes, ulog_sensor_instances
    from thermocal.readers.ulog_params import ulog_parameters

    with parsed_once(path, topics):
        instances = tuple(ulog_sensor_instances(path, topics))
        yield FlightLog(
            Path(path),
            topics,
            instances,
            ulog_parameters(path) if instances else {},
            tuple(ulog_parameter_changes(path, topics)) if instances else (),
        )


__all__ = ["FlightLog", "open_px4_log"]
