"""A flight controller's log read once, the object the thermal calibration passes down.

* PX4: :func:`open_px4_log` parses the ULog's sensor topics once (pyulog, within
  :func:`thermocal.readers.ulog.parsed_once`) into a :class:`FlightLog`: the sensor
  instances that carry a temperature, the parameters in the log's header and those changed
  during the recording.  Each sensor's data are handed out from that one parse
  (:meth:`FlightLog.recording`, :meth:`FlightLog.table`).
* ArduPilot: :func:`read_ardupilot_log` reads the DataFlash log in one pass
  (:func:`thermocal.readers.dataflash.read_dataflash_log`) into a
  :class:`DataflashFlightLog`: the messages kept, the parameters the recording started with
  and every later change.  Each message instance is handed out from that pass
  (:meth:`DataflashFlightLog.table`, :meth:`DataflashFlightLog.rows`).

So no part of either pipeline opens the file again.

References
----------
* PX4 ULog File Format, https://docs.px4.io/main/en/dev_log/ulog_file_format.html
* ArduPilot, *Onboard Message Log Messages* and ``libraries/AP_Logger/LogStructure.h``,
  https://ardupilot.org/copter/docs/logmessages.html
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas as pd

    from thermocal.readers.dataflash import DataflashLog, ParamChange
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


@dataclass(frozen=True)
class DataflashFlightLog:
    """An ArduPilot DataFlash log as the thermal calibration reads it: one pass over the file.

    Parameters
    ----------
    path : Path
        The log file.
    messages : tuple of str
        The message types kept (``IMU``, ``IMU2``, ``IMU3``, ``TCLR``, ``BARO``).
    passed : thermocal.readers.dataflash.DataflashLog
        What the one pass kept: the messages' rows, the types seen, the parameters.
    """

    path: Path
    messages: tuple[str, ...]
    passed: DataflashLog

    @property
    def parameters(self) -> Mapping[str, float]:
        """The parameters the recording started with (the first ``PARM`` of each name)."""
        return self.passed.params

    @property
    def parameter_changes(self) -> tuple[ParamChange, ...]:
        """Every later ``PARM`` that changed a value, in log order (time [s], old, new)."""
        return self.passed.param_changes

    def parameters_at_end(self) -> dict[str, float]:
        """The parameters in force at the end of the log.

        Returns
        -------
        dict of str to float
            Parameter name → the last value set.
        """
        return self.passed.params_at_end()

    def rows(self, message: str) -> list[dict[str, float]]:
        """Every message of type ``message`` (all instances), numeric fields, in log order.

        Parameters
        ----------
        message : str
            A message type among :attr:`messages` (``TCLR``).

        Returns
        -------
        list of dict
            Field name → value; empty when the log has none.
        """
        return self.passed.message_rows(message)

    def release(self, message: str) -> None:
        """Forget the columns of ``message`` kept by the pass (their memory given back);
        a later :meth:`table` of it finds none.

        Parameters
        ----------
        message : str
            A message type among :attr:`messages` (``IMU``).
        """
        self.passed.columns.pop(message, None)
        self.passed.rows.pop(message, None)

    def table(
        self, message: str, instance: int, fields: Sequence[str] | None = None
    ) -> tuple[pd.DataFrame, dict[str, Any]]:
        """Instance ``instance`` of ``message`` as a table in the firmware's units, served
        from the log's one pass (:func:`thermocal.readers.dataflash.dataflash_table`).

        Parameters
        ----------
        message : str
            The message type (``IMU``, ``BARO``).
        instance : int
            The instance, 0-based (``IMU2`` of older logs is ``IMU`` instance 1).
        fields : sequence of str, optional
            Only these fields (those the message has, ``TimeUS`` always); None: all.

        Returns
        -------
        tuple
            (the fields as a pandas.DataFrame, what the reader found: time column, units).

        Raises
        ------
        thermocal.errors.MissingColumnError
            No such message instance in the log.
        """
        from thermocal.readers.dataflash import dataflash_table

        return dataflash_table(self.passed, self.path, message, instance, fields)


def read_ardupilot_log(path: Path, messages: tuple[str, ...]) -> DataflashFlightLog:
    """The DataFlash log ``path`` read in one pass, keeping ``messages`` and every ``PARM``.

    Parameters
    ----------
    path : Path
        An ArduPilot DataFlash log (``.bin``).
    messages : tuple of str
        The message types the calibration takes.

    Returns
    -------
    DataflashFlightLog

    Raises
    ------
    thermocal.errors.ThermocalInputError
        The file is not a readable DataFlash log (said by the reader, naming the file), or
        pymavlink is not installed.
    """
    from thermocal.readers.dataflash import read_dataflash_log

    return DataflashFlightLog(Path(path), tuple(messages), read_dataflash_log(path, messages))


__all__ = ["DataflashFlightLog", "FlightLog", "open_px4_log", "read_ardupilot_log"]
