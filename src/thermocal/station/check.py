"""``thermocal station check``: does every part of the station answer?"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.station.chamber import ChamberError, make_chamber
from thermocal.station.config import StationConfig
from thermocal.station.sensors import SerialSensor


@dataclass(frozen=True)
class SensorCheck:
    """A sensor's answer: lines and bad lines seen in ``listen_s``, rate [Hz], the first
    parsed line, or the error.

    Attributes
    ----------
    id, device : str
        The sensor and its serial device.
    ok : bool
        Good lines were read.
    rate_hz : float
        Measured line rate [Hz].
    lines, bad_lines : int
        Lines and bad lines seen.
    first_line : str
        The first parsed line.
    error : str
        The port's error ("" : none).
    """

    id: str
    device: str
    ok: bool
    rate_hz: float
    lines: int
    bad_lines: int
    first_line: str
    error: str


@dataclass(frozen=True)
class StationCheck:
    """The chamber's temperature and set-point [°C] (NaN for ``none``) and each sensor.

    Attributes
    ----------
    chamber : str
        The chamber's driver.
    chamber_ok : bool
        The chamber answered.
    chamber_error : str
        Its error ("" : none).
    temperature_c, setpoint_c : float
        The chamber's temperature and set-point [°C] (NaN for ``none``).
    sensors : tuple of SensorCheck
        Each sensor's answer.
    """

    chamber: str
    chamber_ok: bool
    chamber_error: str
    temperature_c: float
    setpoint_c: float
    sensors: tuple[SensorCheck, ...]

    @property
    def failed(self) -> list[str]:
        """What did not answer."""
        out = [] if self.chamber_ok else [f"chamber ({self.chamber_error})"]
        out += [f"sensor {s.id} ({s.error})" for s in self.sensors if not s.ok]
        return out

    def to_dict(self) -> dict[str, Any]:
        """The answers as JSON types (NaN and "" as None).

        Returns
        -------
        dict
            ``chamber`` (driver, ok, temperature_c and setpoint_c [°C], error) and
            ``sensors`` (each one's id, device, ok, rate_hz [Hz], lines, bad_lines,
            first_line, error).
        """
        chamber = {"driver": self.chamber, "ok": self.chamber_ok,
                   "temperature_c": _nan_none(self.temperature_c),
                   "setpoint_c": _nan_none(self.setpoint_c),
                   "error": self.chamber_error or None}  # fmt: skip
        sensors = [
            {"id": s.id, "device": s.device, "ok": s.ok, "rate_hz": _nan_none(s.rate_hz),
             "lines": s.lines, "bad_lines": s.bad_lines, "first_line": s.first_line or None,
             "error": s.error or None}
            for s in self.sensors
        ]  # fmt: skip
        return {"chamber": chamber, "sensors": sensors}

    def text(self) -> list[str]:
        """One line for the chamber and one per sensor: what each answered, or its error.

        Returns
        -------
        list of str
        """
        c = self.to_dict()["chamber"]
        head = (f"temperature {_celsius(c['temperature_c'])}, set-point {_celsius(c['setpoint_c'])}"
                if self.chamber_ok else f"NO ANSWER: {self.chamber_error}")  # fmt: skip
        lines = [f"chamber {self.chamber}: {head}"]
        for s in self.sensors:
            rate = "—" if s.rate_hz != s.rate_hz else f"{s.rate_hz:.1f} Hz"
            said = (f"{rate}, {s.lines} lines ({s.bad_lines} bad), first: {s.first_line}"
                    if s.ok else f"NO ANSWER: {s.error}")  # fmt: skip
            lines.append(f"sensor {s.id} ({s.device}): {said}")
        return lines


def _celsius(v: float | None) -> str:
    """A temperature [°C] as shown, or "not reported" for a chamber that gives none."""
    return "not reported" if v is None else f"{v} °C"


def _nan_none(v: float) -> float | None:
    """None for NaN."""
    return None if v != v else v


def check_station(cfg: StationConfig, listen_s: float = 3.0) -> StationCheck:
    """Connect to the chamber (read its temperature and set-point) and listen to every
    sensor for up to ``listen_s`` seconds [s] (less once each has sent 20 good lines).

    Parameters
    ----------
    cfg : StationConfig
        The station.
    listen_s : float
        The longest time to listen to each sensor [s].

    Returns
    -------
    StationCheck
        The chamber's answer and each sensor's; nothing is recorded.

    Raises
    ------
    ThermocalInputError
        ``listen_s`` is not positive.
    """
    if not listen_s > 0:
        raise ParameterError("listen_s", f"{{name}} must be > 0 s, got {listen_s}")
    chamber = make_chamber(cfg.chamber)
    temp = sp = math.nan
    err = ""
    try:
        chamber.connect()
        temp = chamber.read_temperature()
        sp = chamber.read_setpoint()
    except ChamberError as exc:
        err = str(exc)
    finally:
        chamber.close()
    sensors = [SerialSensor(s) for s in cfg.sensors]
    opened: list[SerialSensor] = []
    errors: dict[str, str] = {}
    for s in sensors:
        try:
            s.start()
            opened.append(s)
        except ThermocalInputError as exc:
            errors[s.cfg.id] = str(exc)
    t_end = time.time() + listen_s
    while time.time() < t_end and not all(s.stats.good >= 20 for s in opened):
        time.sleep(0.05)
    for s in opened:
        s.close()
    out = []
    for s in sensors:
        st = s.stats
        e = errors.get(s.cfg.id) or st.error
        if not e and st.good == 0:
            e = (f"no parsed line in {listen_s:g} s ({st.bad} bad)" if st.bad
                 else f"silent for {listen_s:g} s")  # fmt: skip
        out.append(SensorCheck(s.cfg.id, s.cfg.device, not e, st.rate_hz(), st.lines, st.bad,
                               st.first_line, e))  # fmt: skip
    return StationCheck(chamber.name, not err, err, temp, sp, tuple(out))
