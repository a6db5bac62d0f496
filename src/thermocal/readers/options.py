"""How a file is read: one frozen object for every reading path of the library.

:class:`ReadOptions` carries what a user states about a recording — its columns, their units,
the raw-count temperature conversion, the log topic and how a text log is laid out.  Every
call that reads a file takes one (``read=ReadOptions(...)``); the command line builds it from
its own options.  What is not stated is
read from the file (sidecar, Parquet metadata, column names), as :mod:`thermocal.units`
resolves it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Literal

from thermocal.errors import ParameterError
from thermocal.units import TemperatureConversion, temperature_conversion

RATE_HZ_RANGE: tuple[float, float] = (1e-6, 1e7)
"""Sample rates [Hz] a sensor log can have: from one sample in 11.6 days to 10 MHz (beyond
any inertial sensor's output rate); outside, time = n / rate overflows or collapses."""


def _names(value: str | Iterable[str] | None, parameter: str) -> tuple[str, ...] | None:
    """``"a, b"`` or ``["a", "b"]`` → ``("a", "b")``; None stays None."""
    if value is None:
        return None
    items = value.split(",") if isinstance(value, str) else list(value)
    out: list[str] = []
    for item in items:
        if not isinstance(item, str):
            raise ParameterError(parameter, f"{{name}} holds column names, got {item!r}")
        if item.strip():
            out.append(item.strip())
    return tuple(out)


def _units(value: Iterable[str]) -> tuple[str, ...]:
    """One unit per signal, as a tuple of strings."""
    out = tuple(value)
    if not all(isinstance(u, str) for u in out):
        raise ParameterError(
            "signal_unit", f"{{name}} holds one unit, or one per signal; got {out!r}"
        )
    return out


CHAMBER_COLUMN = "chamber"
"""The temperature column a chamber log adds to a recording (name it among the
temperatures or as the ambient column)."""


@dataclass(frozen=True)
class ChamberLogSpec:
    """A chamber's or data logger's own log to join to a recording by time.

    Parameters
    ----------
    path : str
        The log file.
    channel : str, optional
        Its channel (``TC3``, ``Chamber PV``; default: the one process value).
    unit : str, optional
        The channels' unit (``degF``, ``degC``, ``K``; default: from the header).
    date : str, optional
        The first row's date (``YYYY-MM-DD``) of a log without dates.
    date_order : {"dmy", "mdy"}, optional
        How ``03/04/2026`` reads.
    offset_s : float, optional
        Where the recording's first sample falls on the log's clock [s], counted from the
        log's first row (default: from absolute times, else by correlation).
    drift_ppm : float, optional
        The log clock's gain on the recording's [ppm] (with ``offset_s``; default 0).
    tz : str, optional
        The log's time zone (``+02:00``) when the recording's time is absolute (UTC).
    """

    path: str
    channel: str | None = None
    unit: str | None = None
    date: str | None = None
    date_order: Literal["dmy", "mdy"] | None = None
    offset_s: float | None = None
    drift_ppm: float | None = None
    tz: str | None = None

    def __post_init__(self) -> None:
        if self.date_order not in (None, "dmy", "mdy"):
            raise ParameterError(
                "chamber_date_order", f"{{name}} must be dmy or mdy, got {self.date_order!r}"
            )
        for name in ("offset_s", "drift_ppm"):
            v = getattr(self, name)
            if v is not None and not math.isfinite(v):
                raise ParameterError("chamber_" + name.split("_")[0], "{name} must be finite")

    @classmethod
    def parse(cls, text: str, **given: Any) -> ChamberLogSpec:
        """``FILE`` or ``FILE:CHANNEL`` (a colon in an existing file's name stays in it).

        Parameters
        ----------
        text : str
            The option's text.
        **given
            The other fields.

        Returns
        -------
        ChamberLogSpec

        Examples
        --------
        >>> ChamberLogSpec.parse("log.csv:TC3").channel
        'TC3'
        """
        import os

        path, colon, channel = text.rpartition(":")
        if not colon or os.path.exists(text) or not path or "/" in channel or "\\" in channel:
            return cls(text, **given)
        return cls(path, channel=channel.strip() or None, **given)


@dataclass(frozen=True)
class ReadOptions:
    """How to read a recording; every field left ``None`` is taken from the file.

    Parameters
    ----------
    time : str, optional
        Name of the time column.  Default: the file's, or a column named like time.
    time_unit : str, optional
        Unit of the time column (``"s"``, ``"ms"``, ``"us"``, ``"ns"``, ``"min"``, ``"h"``).
    signals : tuple of str, optional
        Signal columns, in order; the first is the primary signal.  A comma-separated
        string (``"gx,gy,gz"``) or a list is accepted and stored as a tuple.
    temperatures : tuple of str, optional
        Temperature columns, as ``signals``.
    signal_unit : str or tuple of str, optional
        Unit of the signal columns (``"deg/h"``, ``"deg/s"``, ``"rad/s"``, ``"mg"``,
        ``"m/s^2"``, ``"g"``, ``"counts"``, …): one for every signal, or a tuple of one
        per signal in the order of ``signals`` (an empty string states none for its
        signal; a list is stored as a tuple).
    temp_unit : str, optional
        Unit of the temperature columns (``"degC"``, ``"K"``, ``"degF"``, ``"counts"``).
    temp_conversion : TemperatureConversion, optional
        Raw ADC counts → °C, :math:`T = g\\,v + o` (gain :math:`g` [°C/count], offset
        :math:`o` [°C]); the text ``"GAIN,OFFSET[,int16]"`` or a tuple is accepted.
    topic : str, optional
        Flight-controller log topic or message (``"sensor_gyro"``, ``"sensor_gyro:1"``,
        ``"IMU[0]"``).
    names : tuple of str, optional
        Column names of a text log without a header row.
    rate_hz : float, optional
        Sample rate [Hz] of a log without a time column: :math:`t_k = k / f`.
    on_bad_lines : {"error", "skip"}
        A mangled line of a text log is an error naming it (default) or is dropped and
        counted.
    delimiter : str, optional
        Field separator of a text log (detected when None: ``,`` ``;`` tab or blanks).
    decimal : {".", ","}, optional
        Decimal mark of a text log (detected when None).
    stamp : {"header", "receive"}
        Time of a ROS bag's messages: their header stamp (default) or the bag's receive
        time.
    chamber_log : ChamberLogSpec, optional
        A chamber's own log joined by time: its channel becomes the temperature column
        :data:`CHAMBER_COLUMN` (``temperatures`` may name it).

    Raises
    ------
    thermocal.errors.ParameterError
        A value no file can have, naming the field (``rate_hz``, ``on_bad_lines``, …).

    Examples
    --------
    >>> from thermocal.readers.options import ReadOptions
    >>> ReadOptions(signals="gx, gy", rate_hz=100.0).signals
    ('gx', 'gy')
    >>> ReadOptions(rate_hz=-1.0)
    Traceback (most recent call last):
    ...
    thermocal.errors.ParameterError: rate_hz must be a positive rate [Hz], got -1.0
    """

    time: str | None = None
    time_unit: str | None = None
    signals: tuple[str, ...] | None = None
    temperatures: tuple[str, ...] | None = None
    signal_unit: str | tuple[str, ...] | None = None
    temp_unit: str | None = None
    temp_conversion: TemperatureConversion | None = None
    topic: str | None = None
    names: tuple[str, ...] | None = None
    rate_hz: float | None = None
    on_bad_lines: Literal["error", "skip"] = "error"
    delimiter: str | None = None
    decimal: Literal[".", ","] | None = None
    stamp: Literal["header", "receive"] = "header"
    chamber_log: ChamberLogSpec | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__  # frozen: normalise in place once
        for field in ("signals", "temperatures", "names"):
            set_(self, field, _names(getattr(self, field), field))
        if self.signal_unit is not None and not isinstance(self.signal_unit, str):
            set_(self, "signal_unit", _units(self.signal_unit))
        if self.temp_conversion is not None:
            set_(
                self,
                "temp_conversion",
                temperature_conversion(
                    self.temp_conversion, "{temp_conversion}", ("temp_conversion",)
                ),
            )
        if self.on_bad_lines not in ("error", "skip"):
            raise ParameterError(
                "on_bad_lines", f"{{name}} must be error or skip, got {self.on_bad_lines!r}"
            )
        if self.rate_hz is not None:
            rate = self.rate_hz
            if not (isinstance(rate, int | float) and math.isfinite(rate) and rate > 0):
                raise ParameterError(
                    "rate_hz", f"{{name}} must be a positive rate [Hz], got {rate}"
                )
            lo, hi = RATE_HZ_RANGE
            if not lo <= rate <= hi:
                raise ParameterError(
                    "rate_hz",
                    f"{{name}} {rate:g} Hz: no sensor samples at that rate; give the sample "
                    f"rate from {lo:g} to {hi:g} Hz (one sample a minute: {{name}} 0.0166667)",
                )
        if self.decimal not in (None, ".", ","):
            raise ParameterError("decimal", f"{{name}} must be . or , — got {self.decimal!r}")
        if self.stamp not in ("header", "receive"):
            raise ParameterError("stamp", f"{{name}} must be header or receive, got {self.stamp!r}")
        if self.names is not None and len(set(self.names)) != len(self.names):
            raise ParameterError("names", f"{{name}} repeats a name: {list(self.names)}")

    def replace(self, **changes: Any) -> ReadOptions:
        """A copy with ``changes`` (field = value), checked as a new object is.

        Parameters
        ----------
        **changes
            Field names and their new values.

        Returns
        -------
        ReadOptions
            The new options.

        Raises
        ------
        thermocal.errors.ParameterError
            A new value out of its bounds (as in the constructor).
        """
        return dataclasses.replace(self, **changes)

    @property
    def text_layout_given(self) -> bool:
        """Whether any text-log field (``names``, ``rate_hz``, ``on_bad_lines``,
        ``delimiter``, ``decimal``) differs from its default."""
        return (
            self.names is not None
            or self.rate_hz is not None
            or self.on_bad_lines != "error"
            or bool(self.delimiter)
            or self.decimal is not None
        )


__all__ = ["CHAMBER_COLUMN", "RATE_HZ_RANGE", "ChamberLogSpec", "ReadOptions"]
