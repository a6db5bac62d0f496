"""``STATION.toml``: the chamber and the sensors of a test station.  Every key is checked here;
an error names the file and the key.

Example::

    part_s = 60                      # Parquet parts closed every 60 s [s]

    [chamber]
    driver = "modbus-tcp"            # or "modbus-rtu" (device, baud) or "none"
    host = "192.168.0.20"
    port = 502
    unit = 1                         # Modbus slave id
    setpoint_register = 300          # holding register written with the set-point
    temperature_register = 100       # register read for the chamber's temperature
    register_kind = "input"          # "holding" | "input" (of the temperature)
    scale = 0.1                      # [°C per count]
    signed = true                    # 16-bit two's complement
    poll_s = 1                       # [s]
    safe_setpoint_c = 25             # written on stop, error or Ctrl-C [°C]
    # or, for a controller whose manual gives the map (thermocal.station.presets):
    # preset = "eurotherm-2000"      # sets the registers, their kind and sign; give scale

    [[sensor]]
    id = "imu1"
    device = "/dev/ttyUSB0"
    baud = 115200
    names = ["gx", "gy", "gz", "temp"]
    units = ["deg/s", "deg/s", "deg/s", "degC"]
    delimiter = ","
    rate_hz = 100                    # the lines carry no time: time = line / rate

Keys beyond the contract (all optional): ``[chamber]`` ``timeout_s`` (a chamber that does
not answer for this long stops the run safely, default 30 s), ``io_timeout_s`` (one
request, default 1 s), ``tolerance_c`` and ``drift_s`` (a chamber further than
``tolerance_c`` from its set-point for ``drift_s`` of program time is reported; defaults
5 °C, 1800 s; a hold in which the chamber never comes within ``tolerance_c`` is reported
when it ends, however short), ``min_c`` and ``max_c`` (the chamber's range [°C], default
−75…180 °C, the span of common climatic test chambers: every program set-point must lie in
it, and a temperature read outside it by more than ``tolerance_c`` — a register reading
0x8000, a broken probe — is a chamber fault, never a reading); ``[[sensor]]`` ``decimal``
(``.`` or ``,``) and ``stale_s`` (a sensor silent this long is reported, default
``max(2 s, 20 / rate_hz)``).

``safe_setpoint_c`` must lie in the chamber's range and in :data:`SAFE_RANGE_C`: it is
written whenever the run stops, unattended.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from thermocal import units
from thermocal.errors import ThermocalInputError
from thermocal.outputs import refuse_special_input, special_mode
from thermocal.readers.station import CHAMBER_STREAM  # the reader owns the stream name

DRIVERS = ("modbus-tcp", "modbus-rtu", "none")
"""Chamber drivers: Modbus TCP, Modbus RTU over a serial line, or a chamber run by hand."""

_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_]*$")
SAFE_RANGE_C = (0.0, 50.0)
"""Where a safe set-point may lie [°C]: near room temperature, where a chamber left alone
neither heats its load nor freezes condensation on it."""

TIME_NAMES = ("time",)
"""A sensor field with this name is the line's own time (its unit one of s, ms, us)."""


@dataclass(frozen=True)
class ChamberConfig:
    """The ``[chamber]`` table.  Temperatures [°C], times [s].

    Attributes
    ----------
    driver : str
        ``"modbus-tcp"``, ``"modbus-rtu"`` or ``"none"`` (no chamber driven).
    preset : str
        A controller preset of :mod:`thermocal.station.presets` ("" : registers given here).
    host : str
        Modbus TCP host.
    port : int
        Modbus TCP port.
    device : str
        Serial device of Modbus RTU.
    baud : int
        Baud rate of Modbus RTU.
    unit : int
        Modbus slave id.
    setpoint_register : int
        Holding register written with the set-point.
    temperature_register : int
        Register read for the chamber's temperature.
    register_kind : str
        ``"holding"`` or ``"input"``: the kind of ``temperature_register``.
    scale : float
        [°C per count] of both registers.
    signed : bool
        The registers hold 16-bit two's complement values.
    poll_s : float
        Polling period [s].
    safe_setpoint_c : float
        Set-point written whenever the run stops [°C].
    timeout_s : float
        A chamber silent this long stops the run safely [s].
    io_timeout_s : float
        Time allowed for one request [s].
    tolerance_c : float
        Distance from the set-point [°C] that, held for ``drift_s``, is reported.
    drift_s : float
        Program time [s] of that drift.
    min_c, max_c : float
        The chamber's range [°C].
    """

    driver: str = "none"
    preset: str = ""
    host: str = "127.0.0.1"
    port: int = 502
    device: str = ""
    baud: int = 9600
    unit: int = 1
    setpoint_register: int = 0
    temperature_register: int = 0
    register_kind: str = "holding"
    scale: float = 0.1
    signed: bool = True
    poll_s: float = 1.0
    safe_setpoint_c: float = 25.0
    timeout_s: float = 30.0
    io_timeout_s: float = 1.0
    tolerance_c: float = 5.0
    drift_s: float = 1800.0
    min_c: float = -75.0
    max_c: float = 180.0

    def out_of_range(self, temperature_c: float, margin_c: float = 0.0) -> str:
        """``""`` when ``temperature_c`` [°C] lies in ``min_c − margin_c … max_c +
        margin_c`` (finite), else why not (for a message).

        Parameters
        ----------
        temperature_c : float
            A temperature [°C].
        margin_c : float
            Margin beyond the range [°C].

        Returns
        -------
        str
        """
        lo, hi = self.min_c - margin_c, self.max_c + margin_c
        if math.isfinite(temperature_c) and lo <= temperature_c <= hi:
            return ""
        return (f"{temperature_c:g} °C is outside the chamber's range {self.min_c:g}…"
                f"{self.max_c:g} °C ([chamber] min_c, max_c)")  # fmt: skip


@dataclass(frozen=True)
class SensorConfig:
    """One ``[[sensor]]``: a serial port sending one sample per text line.

    Attributes
    ----------
    id : str
        The sensor's name (its folder in the recording).
    device : str
        Serial device.
    baud : int
        Baud rate.
    names : tuple of str
        Names of the fields of a line.
    units : tuple of str
        Their units.
    delimiter : str or None
        Field delimiter (None: white space).
    decimal : str
        Decimal mark, ``"."`` or ``","``.
    rate_hz : float or None
        Nominal sample rate [Hz] when the lines carry no time (time = line / rate).
    stale_s : float or None
        A sensor silent this long is reported [s] (None: ``max(2 s, 20 / rate_hz)``).
    """

    id: str
    device: str
    baud: int = 115200
    names: tuple[str, ...] = ()
    units: tuple[str, ...] = ()
    delimiter: str | None = None
    decimal: str = "."
    rate_hz: float | None = None
    stale_s: float | None = None

    @property
    def silence_s(self) -> float:
        """Seconds without a line after which the sensor is reported stopped [s]."""
        if self.stale_s is not None:
            return self.stale_s
        return max(2.0, 20.0 / self.rate_hz) if self.rate_hz else 2.0

    @property
    def time_name(self) -> str | None:
        """The field holding the line's own time, if any."""
        return next((n for n in self.names if n in TIME_NAMES), None)


@dataclass(frozen=True)
class StationConfig:
    """A whole ``STATION.toml``.

    Attributes
    ----------
    chamber : ChamberConfig
        The ``[chamber]`` table.
    sensors : tuple of SensorConfig
        The ``[[sensor]]`` tables.
    part_s : float
        Period [s] at which the recorder closes a Parquet part.
    source : str
        The file the configuration was read from.
    """

    chamber: ChamberConfig
    sensors: tuple[SensorConfig, ...]
    part_s: float = 60.0
    source: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (``station.json``'s ``config``)."""
        out = asdict(self)
        out["sensors"] = [asdict(s) for s in self.sensors]
        return out


def _err(where: str, msg: str) -> ThermocalInputError:
    return ThermocalInputError(f"{where}: {msg}")


def _take(
    table: dict[str, Any], key: str, kind: type | tuple[type, ...], where: str, default: Any
) -> Any:
    if key not in table:
        return default
    v = table[key]
    if kind is float and isinstance(v, int) and not isinstance(v, bool):
        v = float(v)
    if not isinstance(v, kind) or (kind is int and isinstance(v, bool)):
        name = kind.__name__ if isinstance(kind, type) else "/".join(k.__name__ for k in kind)
        raise _err(where, f"{key} must be {name}, got {v!r}")
    if isinstance(v, float) and not math.isfinite(v):
        raise _err(where, f"{key} must be finite, got {v!r}")
    return v


def _positive(v: float, key: str, where: str) -> float:
    if not v > 0:
        raise _err(where, f"{key} must be > 0, got {v!r}")
    return v


def _with_preset(t: dict[str, Any], w: str) -> dict[str, Any]:
    """``[chamber]`` with a controller preset's register map filled in
    (:mod:`thermocal.station.presets`): a map key given beside the preset must agree with
    it, and ``scale`` must be given (the controller's configured resolution)."""
    if "preset" not in t:
        return t
    from thermocal.station.presets import MAP_KEYS, PRESETS

    name = _take(t, "preset", str, w, "")
    preset = PRESETS.get(name)
    if preset is None:
        raise _err(w, f"unknown preset {name!r}; known: {', '.join(sorted(PRESETS))}")
    filled = dict(t)
    for key in MAP_KEYS:
        value = getattr(preset, key)
        if key in t and t[key] != value:
            raise _err(
                w, f"{key} = {t[key]!r} disagrees with preset {name!r} ({key} = {value!r}, "
                f"from {preset.source}); remove one of them"
            )  # fmt: skip
        filled[key] = value
    if "scale" not in t:
        raise _err(
            w, f"preset {name!r} needs scale: the controller sends temperatures at the "
            "resolution configured on its display (0.1 for one decimal place, 1 for none)"
        )  # fmt: skip
    return filled


def _chamber(t: dict[str, Any], where: str) -> ChamberConfig:
    w = f"{where} [chamber]"
    known = set(ChamberConfig.__dataclass_fields__)
    unknown = sorted(set(t) - known)
    if unknown:
        raise _err(w, f"unknown key {unknown[0]!r}; known: {', '.join(sorted(known))}")
    t = _with_preset(t, w)
    d = ChamberConfig()
    driver = _take(t, "driver", str, w, d.driver)
    if driver not in DRIVERS:
        raise _err(w, f"driver must be one of {', '.join(DRIVERS)}, got {driver!r}")
    kind = _take(t, "register_kind", str, w, d.register_kind)
    if kind not in ("holding", "input"):
        raise _err(w, f"register_kind must be holding or input, got {kind!r}")
    c = ChamberConfig(
        driver=driver,
        preset=_take(t, "preset", str, w, d.preset),
        host=_take(t, "host", str, w, d.host),
        port=_take(t, "port", int, w, d.port),
        device=_take(t, "device", str, w, d.device),
        baud=_take(t, "baud", int, w, d.baud),
        unit=_take(t, "unit", int, w, d.unit),
        setpoint_register=_take(t, "setpoint_register", int, w, d.setpoint_register),
        temperature_register=_take(t, "temperature_register", int, w, d.temperature_register),
        register_kind=kind,
        scale=_positive(_take(t, "scale", float, w, d.scale), "scale", w),
        signed=_take(t, "signed", bool, w, d.signed),
        poll_s=_positive(_take(t, "poll_s", float, w, d.poll_s), "poll_s", w),
        safe_setpoint_c=_take(t, "safe_setpoint_c", float, w, d.safe_setpoint_c),
        timeout_s=_positive(_take(t, "timeout_s", float, w, d.timeout_s), "timeout_s", w),
        io_timeout_s=_positive(
            _take(t, "io_timeout_s", float, w, d.io_timeout_s), "io_timeout_s", w
        ),
        tolerance_c=_positive(_take(t, "tolerance_c", float, w, d.tolerance_c), "tolerance_c", w),
        drift_s=_positive(_take(t, "drift_s", float, w, d.drift_s), "drift_s", w),
        min_c=_take(t, "min_c", float, w, d.min_c),
        max_c=_take(t, "max_c", float, w, d.max_c),
    )
    _check_range(c, w)
    if driver != "none":
        for key in ("setpoint_register", "temperature_register"):
            if key not in t:
                raise _err(w, f"driver {driver} needs {key}")
        for key in ("setpoint_register", "temperature_register"):
            if not 0 <= getattr(c, key) <= 0xFFFF:
                raise _err(w, f"{key} must be a register address 0..65535")
        if not 0 <= c.unit <= 247:
            raise _err(w, f"unit (slave id) must be 0..247, got {c.unit}")
        if c.register_kind == "holding" and c.setpoint_register == c.temperature_register:
            raise _err(w, f"setpoint_register and temperature_register are both holding "
                       f"register {c.setpoint_register}: the station would read its own "
                       "set-point back as the chamber's temperature; give the process value's "
                       "register from the controller's manual")  # fmt: skip
    if driver == "modbus-rtu" and not c.device:
        raise _err(w, "driver modbus-rtu needs device (a serial port) and baud")
    return c


def _check_range(c: ChamberConfig, w: str) -> None:
    """``min_c < max_c``, both above absolute zero; ``safe_setpoint_c`` in the range and in
    :data:`SAFE_RANGE_C`."""
    if not -273.15 < c.min_c < c.max_c:
        raise _err(w, f"min_c must be above -273.15 °C and below max_c, got min_c = "
                   f"{c.min_c:g}, max_c = {c.max_c:g}")  # fmt: skip
    why = c.out_of_range(c.safe_setpoint_c)
    lo, hi = SAFE_RANGE_C
    if not why and not lo <= c.safe_setpoint_c <= hi:
        why = f"{c.safe_setpoint_c:g} °C is not a safe temperature ({lo:g}…{hi:g} °C)"
    if why:
        raise _err(w, f"safe_setpoint_c = {why}; it is written whenever the run stops, "
                   "unattended: give one near room temperature")  # fmt: skip


def _unit_ok(u: str) -> bool:
    for norm in (
        units.normalize_signal_unit,
        units.normalize_temperature_unit,
        units.normalize_time_unit,
    ):
        try:
            norm(u)
        except ThermocalInputError:
            continue
        return True
    return False


def _sensor(t: dict[str, Any], where: str, i: int) -> SensorConfig:
    w = f"{where} [[sensor]] #{i + 1}"
    known = set(SensorConfig.__dataclass_fields__)
    unknown = sorted(set(t) - known)
    if unknown:
        raise _err(w, f"unknown key {unknown[0]!r}; known: {', '.join(sorted(known))}")
    sid = _take(t, "id", str, w, "")
    if not _ID.fullmatch(sid) or sid == CHAMBER_STREAM:  # "$" matches before a "\n"
        raise _err(w, f"id must be letters, digits and _ (and not {CHAMBER_STREAM!r}), got {sid!r}")
    w = f"{where} sensor {sid!r}"
    device = _take(t, "device", str, w, "")
    if not device:
        raise _err(w, "device (a serial port) is missing")
    names = tuple(_take(t, "names", list, w, []))
    units_ = tuple(_take(t, "units", list, w, []))
    if not names or not all(isinstance(n, str) and n for n in names):
        raise _err(w, "names must be a non-empty list of column names")
    if len(set(names)) != len(names):
        raise _err(w, f"names repeats a name: {list(names)}")
    if len(units_) != len(names):
        raise _err(w, f"units must give one unit per name ({len(names)}), got {len(units_)}")
    for n, u in zip(names, units_, strict=True):
        if not isinstance(u, str) or not _unit_ok(u):
            raise _err(w, f"unknown unit {u!r} of {n!r}")
    reserved = {"host_time", "program_s", "setpoint_c", "chamber_c"}
    clash = sorted(reserved & set(names))
    if clash:
        raise _err(w, f"name {clash[0]!r} is the station's own column; rename it")
    rate = _take(t, "rate_hz", float, w, None)
    if rate is not None:
        _positive(rate, "rate_hz", w)
    delim = _take(t, "delimiter", str, w, None)
    if delim is not None and len(delim) != 1:
        raise _err(w, f"delimiter must be one character, got {delim!r}")
    decimal = _take(t, "decimal", str, w, ".")
    if decimal not in (".", ","):
        raise _err(w, f"decimal must be . or , got {decimal!r}")
    if decimal == delim:
        raise _err(w, "decimal and delimiter are the same character")
    s = SensorConfig(
        id=sid,
        device=device,
        baud=_take(t, "baud", int, w, 115200),
        names=names,
        units=units_,
        delimiter=delim,
        decimal=decimal,
        rate_hz=rate,
        stale_s=_take(t, "stale_s", float, w, None),
    )
    if s.time_name is not None:
        tu = units_[names.index(s.time_name)]
        try:
            units.normalize_time_unit(tu)
        except ThermocalInputError:
            raise _err(
                w, f"{s.time_name!r} is the line's time; its unit must be s, ms or us"
            ) from None
        if rate is not None:
            raise _err(w, f"rate_hz given but the lines carry a time ({s.time_name!r}); drop one")
    return s


def parse_station(text: str, where: str = "STATION.toml") -> StationConfig:
    """Parse and check the text of a ``STATION.toml``.

    Parameters
    ----------
    text : str
        The file's text.
    where : str
        How messages name the file.

    Returns
    -------
    StationConfig

    Raises
    ------
    ThermocalInputError
        Not TOML, an unknown or missing key, a value out of its range, a preset the map
        contradicts; the message names the file and the key.

    Examples
    --------
    A Eurotherm 2000 series controller by its preset (set-point register 24, process value
    register 1, from the maker's communications handbook) and one serial IMU at 100 Hz:

    >>> cfg = parse_station('''
    ... [chamber]
    ... driver = "modbus-tcp"
    ... host = "192.168.0.10"
    ... preset = "eurotherm-2000"
    ... scale = 0.1
    ... [[sensor]]
    ... id = "imu"
    ... device = "/dev/ttyUSB0"
    ... names = ["gyro_x", "temp"]
    ... units = ["deg/s", "degC"]
    ... rate_hz = 100
    ... ''')
    >>> cfg.chamber.setpoint_register, cfg.chamber.temperature_register, cfg.sensors[0].id
    (24, 1, 'imu')
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise _err(where, f"not valid TOML ({exc})") from None
    except RecursionError:  # thousands of nested brackets
        raise _err(where, "not a station configuration (TOML nested too deeply)") from None
    known = {"part_s", "chamber", "sensor"}
    unknown = sorted(set(doc) - known)
    if unknown:
        raise _err(where, f"unknown key {unknown[0]!r}; known: chamber, sensor, part_s")
    ch = doc.get("chamber")
    if not isinstance(ch, dict):
        raise _err(where, 'no [chamber] table (driver = "none" for a chamber run by hand)')
    raw_sensors = doc.get("sensor", [])
    if not isinstance(raw_sensors, list) or not raw_sensors:
        raise _err(where, "no [[sensor]]: a station records at least one serial sensor")
    sensors = tuple(_sensor(s, where, i) for i, s in enumerate(raw_sensors))
    ids = [s.id for s in sensors]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise _err(where, f"sensor id {dup[0]!r} used twice")
    part_s = _positive(_take(doc, "part_s", float, where, 60.0), "part_s", where)
    return StationConfig(_chamber(ch, where), sensors, part_s, where)


def load_station(path: str | Path) -> StationConfig:
    """Read and check ``STATION.toml`` (:func:`parse_station`).

    Parameters
    ----------
    path : str or pathlib.Path
        The ``STATION.toml``.

    Returns
    -------
    StationConfig

    Raises
    ------
    ThermocalInputError
        The file is missing, special or not UTF-8, or :func:`parse_station` refuses it.
    """
    p = Path(path)
    refuse_special_input(p, "station file (STATION.toml)")  # a FIFO is no "no such file"
    if not p.is_file():
        raise ThermocalInputError(f"{p}: no such file")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ThermocalInputError(f"{p}: not UTF-8 text") from None
    return parse_station(text, str(p))


def check_port(device: str, who: str) -> None:
    """Refuse a serial ``device`` that is a FIFO, a socket or a block device (``stat``
    only, never opened): pyserial would answer "Inappropriate ioctl for device".
    A character device (``/dev/ttyUSB0``, a pty) and a pyserial URL pass.

    Parameters
    ----------
    device : str
        The serial device or pyserial URL.
    who : str
        How the message names its owner (``[chamber]``, ``[[sensor]] imu``).

    Raises
    ------
    ThermocalInputError
        A FIFO, a socket or a block device.
    """
    why = special_mode(Path(device))
    if why is not None and why != "it is a character device":
        raise ThermocalInputError(
            f"{who}: {device}: {why}, not a serial port: give the port's device "
            "(/dev/ttyUSB0, /dev/ttyACM0, a pty) or a pyserial URL"
        )


def require(module: str) -> Any:
    """Import an optional library of the station, or a one-line input error saying what to
    install (exit 2 on the command line).

    Parameters
    ----------
    module : str
        The module's name.

    Returns
    -------
    module

    Raises
    ------
    ThermocalInputError
        Not installed: the message says ``pip install 'thermocal[station]'``.
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        lib = {"pymodbus": "pymodbus", "serial": "pyserial"}.get(module.split(".")[0], module)
        raise ThermocalInputError(
            f"the test station needs {lib}, which is not installed: "
            "pip install 'thermocal[station]'"
        ) from None
