"""Serial sensors: one text line per sample, read by a thread per port (pyserial).

Every line gets the host's time [s] (:func:`thermocal.station.clock.now`) when its bytes are read;
lines read in one chunk share it.  A line is parsed with the text-log rules of
:mod:`thermocal.readers`: the fields split at the stated delimiter
(or the first of ``,`` ``;`` tab blanks that gives one field per name), numbers as a CSV
reader takes them (:func:`thermocal.readers.text.parse_number`: no digit-group underscores, no
non-ASCII digits), a decimal comma when the TOML says so.  A line that does not give one
number per name — a banner, a mangled or cut line, a value that is not finite (``nan``,
``inf``, ``1e999``: never a measurement) — is a *bad line*: counted, kept aside with its host
time and reason, never merged into the data.  Empty lines are ignored.
"""

from __future__ import annotations

import collections
import contextlib
import math
import threading
from dataclasses import dataclass, field
from typing import Any

from thermocal.station import clock
from thermocal.station.config import SensorConfig, check_port, require

DELIMITERS = (",", ";", "\t", " ")
"""Delimiters tried, in order, when the TOML gives none (those of the text-log reader)."""

READ_TIMEOUT_S = 0.1
"""A read returns after at most this long without bytes, so a stop is seen promptly [s]."""

MAX_LINE = 4096
"""A line longer than this many bytes without an end is cut and kept aside as bad."""

MAX_BACKLOG = 200_000
"""Most good lines waiting for the station's loop; a sensor flooding faster than the loop
records lines drops the newer ones beyond, counted (:attr:`SensorStats.dropped`), so that
neither memory nor the loop's turns grow without bound."""


class BadLine(ValueError):
    """A line that does not give one number per name."""


@dataclass(frozen=True)
class LineParser:
    """Parse one text line into ``len(names)`` floats (see the module docstring).

    Attributes
    ----------
    n_fields : int
        Number of numbers a good line holds.
    delimiter : str or None
        Field delimiter (None: white space).
    decimal : str
        Decimal mark, ``"."`` or ``","``.
    """

    n_fields: int
    delimiter: str | None = None
    decimal: str = "."

    def _numbers(self, fields: list[str]) -> tuple[float, ...]:
        from thermocal.readers.text import parse_number

        out = []
        for f in fields:
            text = f.strip()
            if self.decimal == ",":
                text = text.replace(",", ".")
            if not text:
                raise BadLine("empty field")
            try:
                value = parse_number(text)
            except ValueError:
                raise BadLine(f"not a number: {text[:40]!r}") from None
            if not math.isfinite(value):  # nan, inf, 1e999, a line glued to the next
                raise BadLine(f"not finite: {text[:40]!r}")
            out.append(value)
        return tuple(out)

    def parse(self, line: str) -> tuple[float, ...]:
        """The line's numbers, or :class:`BadLine` saying why not.

        Parameters
        ----------
        line : str
            One line of the sensor, without its end.

        Returns
        -------
        tuple of float

        Raises
        ------
        BadLine
            Why the line is not a sample.
        """
        delims = (self.delimiter,) if self.delimiter else DELIMITERS
        reason = ""
        for d in delims:
            fields = line.split() if d == " " else line.split(d)
            if len(fields) != self.n_fields:
                reason = reason or f"{len(fields)} fields, expected {self.n_fields}"
                continue
            try:
                return self._numbers(fields)
            except BadLine as exc:
                reason = str(exc)
        raise BadLine(reason or "no fields")


@dataclass
class SensorStats:
    """What the display and ``station check`` show of a sensor.

    Attributes
    ----------
    lines, good, bad : int
        Lines read, parsed and refused.
    last_unix : float
        Host time of the last good line [s, Unix] (NaN: none yet).
    last_values : tuple of float
        Its numbers.
    first_line : str
        The first good line read.
    error : str
        The port's last error ("" : none).
    dropped : int
        Good lines dropped because the recorder could not keep up (backlog full).
    recent : collections.deque of float
        Host times of the last 200 good lines [s, Unix] (the measured rate).
    """

    lines: int = 0
    good: int = 0
    bad: int = 0
    last_unix: float = math.nan
    last_values: tuple[float, ...] = ()
    first_line: str = ""
    error: str = ""
    dropped: int = 0
    recent: collections.deque[float] = field(default_factory=lambda: collections.deque(maxlen=200))

    def rate_hz(self) -> float:
        """Lines per second over the last (up to) 200 lines [Hz]; NaN with fewer than 2."""
        if len(self.recent) < 2 or self.recent[-1] <= self.recent[0]:
            return math.nan
        return (len(self.recent) - 1) / (self.recent[-1] - self.recent[0])


@dataclass(frozen=True)
class Sample:
    """A good line: host time [s, Unix], the line's index in this run (good and bad lines
    counted) and its numbers.

    Attributes
    ----------
    host_unix : float
        Host time of the line [s, Unix].
    index : int
        The line's index in this run (good and bad lines counted).
    values : tuple of float
        Its numbers.
    """

    host_unix: float
    index: int
    values: tuple[float, ...]


@dataclass(frozen=True)
class Bad:
    """A bad line kept aside.

    Attributes
    ----------
    host_unix : float
        Host time of the line [s, Unix].
    index : int
        The line's index in this run.
    text : str
        The line as read.
    reason : str
        Why it was refused.
    """

    host_unix: float
    index: int
    text: str
    reason: str


class SerialSensor:
    """Reads one serial port in a thread; :meth:`drain` hands over what arrived."""

    def __init__(self, cfg: SensorConfig) -> None:
        self.cfg = cfg
        self.parser = LineParser(len(cfg.names), cfg.delimiter, cfg.decimal)
        self.stats = SensorStats()
        self._lock = threading.Lock()
        self._samples: list[Sample] = []
        self._bad: list[Bad] = []
        self._stop = threading.Event()
        self._port: Any = None
        self._thread: threading.Thread | None = None

    def open(self) -> None:
        """Open the port (:class:`thermocal.errors.ThermocalInputError` naming it if not)."""
        serial = require("serial")
        check_port(self.cfg.device, f"sensor {self.cfg.id}")
        try:
            self._port = serial.serial_for_url(
                self.cfg.device, baudrate=self.cfg.baud, timeout=READ_TIMEOUT_S
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            from thermocal.errors import ThermocalInputError

            raise ThermocalInputError(
                f"sensor {self.cfg.id}: cannot open {self.cfg.device}: {exc}"
            ) from None

    def start(self) -> None:
        """Open the port and start the reading thread."""
        if self._port is None:
            self.open()
        self._thread = threading.Thread(
            target=self._run, name=f"thermocal-sensor-{self.cfg.id}", daemon=True
        )
        self._thread.start()

    def _line(self, t: float, raw: bytes, overlong: str = "") -> None:
        text = raw.decode("utf-8", errors="replace").strip("\r\n\x00 ")
        if not text.strip():
            return
        st = self.stats
        idx = st.lines
        st.lines += 1
        try:
            if overlong:
                raise BadLine(overlong)
            values = self.parser.parse(text)
        except BadLine as exc:
            st.bad += 1
            self._bad.append(Bad(t, idx, text, str(exc)))
            return
        if len(self._samples) >= MAX_BACKLOG:  # the loop cannot keep up: counted, not kept
            st.dropped += 1
            return
        st.good += 1
        st.last_unix = t
        st.last_values = values
        st.recent.append(t)
        if not st.first_line:
            st.first_line = text
        self._samples.append(Sample(t, idx, values))

    def _run(self) -> None:
        buf = b""
        skipping = False
        port = self._port
        while True:
            last = self._stop.is_set()  # stopping: what the port already holds, once
            try:
                waiting = port.in_waiting
                data = (
                    port.read(waiting if last else max(1, waiting)) if waiting or not last else b""
                )
            except Exception as exc:  # a port that vanished: reported, thread ends
                self.stats.error = f"{type(exc).__name__}: {exc}"
                return
            if not data:
                if last:
                    return
                continue
            t = clock.now()
            if skipping:  # the rest of an overlong line, up to its end
                if b"\n" not in data:
                    continue
                data, skipping = data.split(b"\n", 1)[1], False
            buf += data
            *lines, buf = buf.split(b"\n")
            with self._lock:
                for raw in lines:
                    self._line(t, raw)
                if len(buf) > MAX_LINE:  # kept aside once (cut), the rest skipped
                    self._line(t, buf[:MAX_LINE], f"longer than {MAX_LINE} bytes")
                    buf, skipping = b"", True
            if last:
                return

    def drain(self, most: int | None = None) -> tuple[list[Sample], list[Bad]]:
        """The good lines that arrived since the last call (the ``most`` oldest of them; the
        rest wait for the next call) and the bad ones.

        Parameters
        ----------
        most : int, optional
            Take at most this many good lines.

        Returns
        -------
        tuple of (list of Sample, list of Bad)
        """
        with self._lock:
            if most is None or len(self._samples) <= most:
                s, self._samples = self._samples, []
            else:
                s, self._samples = self._samples[:most], self._samples[most:]
            b, self._bad = self._bad, []
        return s, b

    def close(self) -> None:
        """Stop the reading thread and close the port."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        if self._port is not None:
            with contextlib.suppress(Exception):  # a vanished port: nothing left to do
                self._port.close()
            self._port = None
