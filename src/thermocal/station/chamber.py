"""Chamber drivers: write the set-point and read the chamber's temperature.

``modbus-tcp`` and ``modbus-rtu`` talk to the controller with pymodbus's synchronous
clients through a generic register map (:class:`RegisterMap`: one holding register for the
set-point, one holding or input register for the temperature, a scale in °C per count and
16-bit signed or unsigned counts).  ``none`` is a chamber run by hand: each new set-point is
shown to the operator and the chamber's temperature is unknown (NaN).

Presets (:mod:`thermocal.station.presets`) hold the maps read in makers' manuals; the maps of
other controllers (Watlow F4, ESPEC, Vötsch/Weiss)
depend on the controller's firmware and configured decimal places; a map copied from memory
would write set-points to the wrong register.  Give the map from your controller's manual
in ``STATION.toml``.
"""

from __future__ import annotations

import contextlib
import inspect
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from thermocal.errors import ThermocalError, ThermocalInputError
from thermocal.station.config import ChamberConfig, check_port, require


class ChamberError(ThermocalError):
    """The chamber did not answer, or answered with a Modbus exception."""


@dataclass(frozen=True)
class RegisterMap:
    """How a temperature is held in one 16-bit register.

    ``counts = round(T / scale)``; signed registers hold −32768…32767 as two's complement
    (``u = counts mod 2¹⁶``), unsigned ones 0…65535.

    Parameters
    ----------
    setpoint_register : int
        Address of the holding register the set-point is written to.
    temperature_register : int
        Address of the register the chamber's temperature (process value) is read from.
    register_kind : {"holding", "input"}
        The temperature register's kind.
    scale : float
        Resolution [°C per count] (0.1 for a controller showing one decimal place).
    signed : bool
        Two's-complement counts.

    References
    ----------
    Modbus Organization, *MODBUS Application Protocol Specification V1.1b3*, 2012
    (function codes 0x03 Read Holding Registers, 0x04 Read Input Registers, 0x06 Write
    Single Register).

    Eurotherm, *2000 Series Communications Handbook*, HA026230 (scaled integers at the
    configured resolution).

    Examples
    --------
    >>> m = RegisterMap(setpoint_register=24, temperature_register=1, scale=0.1)
    >>> m.encode(-12.5), m.decode(65411)
    (65411, -12.5)
    """

    setpoint_register: int
    temperature_register: int
    register_kind: str = "holding"
    scale: float = 0.1
    signed: bool = True

    def encode(self, temperature_c: float) -> int:
        """°C → the unsigned 16-bit word written to the register.

        Raises
        ------
        ThermocalInputError
            The temperature does not fit the register at this scale.

        Parameters
        ----------
        temperature_c : float
            The temperature [°C].

        Returns
        -------
        int
            The word, 0…65535.
        """
        ratio = temperature_c / self.scale  # inf for a tiny scale: refused, not rounded
        lo, hi = (-32768, 32767) if self.signed else (0, 65535)
        counts = round(ratio) if math.isfinite(ratio) else None
        if counts is None or not lo <= counts <= hi:
            kind = "signed" if self.signed else "unsigned"
            raise ThermocalInputError(
                f"set-point {temperature_c:g} °C does not fit a {kind} 16-bit register at "
                f"scale {self.scale:g} °C/count ({lo * self.scale:g}…{hi * self.scale:g} °C)"
            )
        return counts & 0xFFFF

    def decode(self, word: int) -> float:
        """The unsigned 16-bit word read from a register → °C.

        Parameters
        ----------
        word : int
            The unsigned 16-bit word read.

        Returns
        -------
        float
            The temperature [°C].
        """
        w = int(word) & 0xFFFF
        if self.signed and w >= 0x8000:
            w -= 0x10000
        return w * self.scale


class Chamber(Protocol):
    """What the station needs of a chamber.  Temperatures [°C]."""

    name: str

    def connect(self) -> None:
        """Open the connection; :class:`ChamberError` when the chamber does not answer."""

    def write_setpoint(self, setpoint_c: float) -> None:
        """Write the set-point [°C].

        Parameters
        ----------
        setpoint_c : float
            The set-point [°C].
        """

    def read_temperature(self) -> float:
        """The chamber's temperature [°C] (NaN when unknown)."""

    def read_setpoint(self) -> float:
        """The set-point the controller holds [°C] (NaN when unknown)."""

    def close(self) -> None:
        """Close the connection (never raises)."""


class ManualChamber:
    """``driver = "none"``: the operator sets the chamber by hand; every new set-point is
    handed to ``show`` (the live display or a log line)."""

    name = "none (by hand)"

    def __init__(self, show: Callable[[str], None] | None = None) -> None:
        self._show = show or (lambda _msg: None)
        self._setpoint = math.nan

    def connect(self) -> None:
        """Nothing to open: the operator runs the chamber."""
        return None

    def write_setpoint(self, setpoint_c: float) -> None:
        """The step's goal, shown once per program step (the loop asks no more often).

        Parameters
        ----------
        setpoint_c : float
            The set-point [°C].
        """
        self._setpoint = setpoint_c
        self._show(f"operator: set the chamber to {setpoint_c:.2f} °C")

    def read_temperature(self) -> float:
        """NaN: a chamber run by hand reports no temperature."""
        return math.nan

    def read_setpoint(self) -> float:
        """The last set-point shown to the operator [°C] (NaN before the first)."""
        return self._setpoint

    def close(self) -> None:
        """Nothing to close."""
        return None


class _LibraryLog(logging.Handler):
    """pymodbus's own log records (``Unable to decode frame …``), kept off stderr: the last
    one is added to the :class:`ChamberError` that follows it."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.last = ""

    def emit(self, record: logging.LogRecord) -> None:
        with contextlib.suppress(Exception):
            self.last = record.getMessage().strip().splitlines()[0][:200]

    def take(self) -> str:
        last, self.last = self.last, ""
        return f" (pymodbus: {last})" if last else ""


LIBRARY_LOG = _LibraryLog()


def quiet_pymodbus() -> None:
    """Route the ``pymodbus`` loggers to :data:`LIBRARY_LOG` only (no line on stderr)."""
    log = logging.getLogger("pymodbus")
    if LIBRARY_LOG not in log.handlers:
        log.addHandler(LIBRARY_LOG)
    log.propagate = False
    log.setLevel(logging.WARNING)


def _unit_keyword(method: Callable[..., Any]) -> str:
    """pymodbus ≥ 3.10 names the slave id ``device_id``; older releases ``slave``."""
    params = inspect.signature(method).parameters
    return "device_id" if "device_id" in params else "slave"


class ModbusChamber:
    """A controller on Modbus TCP or RTU (pymodbus).

    Every request either returns or raises :class:`ChamberError` within ``io_timeout_s`` (no
    retries: the station's own loop retries at its poll interval and stops after
    ``timeout_s``).

    Parameters
    ----------
    cfg : ChamberConfig
        The ``[chamber]`` table (driver, address, register map).

    References
    ----------
    Modbus Organization, *MODBUS Application Protocol Specification V1.1b3*, 2012
    (function codes 0x03 Read Holding Registers, 0x04 Read Input Registers, 0x06 Write
    Single Register).
    """

    def __init__(self, cfg: ChamberConfig) -> None:
        self.cfg = cfg
        self.map = RegisterMap(
            cfg.setpoint_register, cfg.temperature_register, cfg.register_kind, cfg.scale,
            cfg.signed,
        )  # fmt: skip
        if cfg.driver == "modbus-tcp":
            self.name = f"modbus-tcp {cfg.host}:{cfg.port} unit {cfg.unit}"
        else:
            self.name = f"modbus-rtu {cfg.device} {cfg.baud} Bd unit {cfg.unit}"
        self._client: Any = None

    def connect(self) -> None:
        """Open the Modbus connection; :class:`ChamberError` when it cannot be opened."""
        client_mod = require("pymodbus.client")
        quiet_pymodbus()
        if self.cfg.driver == "modbus-tcp":
            self._client = client_mod.ModbusTcpClient(
                self.cfg.host, port=self.cfg.port, timeout=self.cfg.io_timeout_s, retries=0
            )
        else:
            require("serial")
            check_port(self.cfg.device, f"chamber {self.name}")
            self._client = client_mod.ModbusSerialClient(
                self.cfg.device, baudrate=self.cfg.baud, timeout=self.cfg.io_timeout_s,
                retries=0,
            )  # fmt: skip
        self._kw = _unit_keyword(self._client.read_holding_registers)
        if not self._client.connect():
            raise ChamberError(f"chamber {self.name}: cannot connect{LIBRARY_LOG.take()}")

    def _call(self, what: str, fn: Callable[..., Any], code: int, *args: Any) -> Any:
        """One request; any failure is a :class:`ChamberError` naming the chamber and the
        register: no answer, a Modbus exception, a reply pymodbus cannot decode, or a
        reply to another function code than ``code`` (never a value taken from it)."""
        if self._client is None:
            self.connect()
        LIBRARY_LOG.take()
        try:
            rr = fn(*args, **{self._kw: self.cfg.unit})
        except Exception as exc:  # a broken frame may surface as anything inside pymodbus
            raise ChamberError(
                f"chamber {self.name}: {what}: {type(exc).__name__}: {exc}{LIBRARY_LOG.take()}"
            ) from None
        if rr is None or rr.isError():
            raise ChamberError(f"chamber {self.name}: {what}: Modbus error {rr}"
                               f"{LIBRARY_LOG.take()}")  # fmt: skip
        got = getattr(rr, "function_code", None)
        if got != code:
            raise ChamberError(
                f"chamber {self.name}: {what}: the reply is for function code {got}, not "
                f"{code}: not a reply to this request"
            )
        return rr

    def write_setpoint(self, setpoint_c: float) -> None:
        """Write the set-point [°C] to the set-point register (Write Single Register).

        Parameters
        ----------
        setpoint_c : float
            The set-point [°C].
        """
        word = self.map.encode(setpoint_c)
        reg = self.map.setpoint_register
        what = f"write set-point to register {reg}"
        rr = self._call(what, self._client_method("write_register"), 6, reg, word)
        echo = (getattr(rr, "address", reg), list(getattr(rr, "registers", [word]) or [word]))
        if echo != (reg, [word]):
            raise ChamberError(
                f"chamber {self.name}: {what}: the reply echoes register {echo[0]} = "
                f"{echo[1]}, not {reg} = [{word}]"
            )

    def _client_method(self, name: str) -> Callable[..., Any]:
        if self._client is None:
            self.connect()
        fn: Callable[..., Any] = getattr(self._client, name)
        return fn

    def _read(self, register: int, kind: str) -> float:
        """One register in °C; a value outside the chamber's range (more than
        ``tolerance_c`` beyond ``min_c``…``max_c``) is a :class:`ChamberError`: a controller
        reports a broken probe as 0x8000 (−3276.8 °C at 0.1 °C/count), never a reading."""
        method = "read_input_registers" if kind == "input" else "read_holding_registers"
        what = f"read {kind} register {register}"
        rr = self._call(what, self._client_method(method), 4 if kind == "input" else 3, register)
        regs = list(getattr(rr, "registers", None) or [])
        if len(regs) != 1:
            raise ChamberError(
                f"chamber {self.name}: {what}: the reply holds {len(regs)} registers, not 1 "
                "(byte count 0 or a cut frame)"
            )
        word = regs[0]
        value = self.map.decode(word)
        why = self.cfg.out_of_range(value, self.cfg.tolerance_c)
        if why:
            raise ChamberError(
                f"chamber {self.name}: {what}: 0x{int(word) & 0xFFFF:04X} = {why}: a probe "
                "fault, or check the register, scale and signed of [chamber]"
            )
        return value

    def read_temperature(self) -> float:
        """Read the temperature register [°C]."""
        return self._read(self.map.temperature_register, self.map.register_kind)

    def read_setpoint(self) -> float:
        """Read the set-point register back [°C]."""
        return self._read(self.map.setpoint_register, "holding")

    def close(self) -> None:
        """Close the connection (never raises)."""
        if self._client is not None:
            self._client.close()
            self._client = None


def make_chamber(cfg: ChamberConfig, show: Callable[[str], None] | None = None) -> Chamber:
    """The driver named by ``cfg.driver`` (not yet connected).

    Parameters
    ----------
    cfg : ChamberConfig
        The ``[chamber]`` table.
    show : callable, optional
        How a chamber run by hand shows the operator each new set-point.

    Returns
    -------
    Chamber
        :class:`ManualChamber` for ``driver = "none"``, else :class:`ModbusChamber`.
    """
    if cfg.driver == "none":
        return ManualChamber(show)
    return ModbusChamber(cfg)
