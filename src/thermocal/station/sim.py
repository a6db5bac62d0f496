"""A station without hardware: a simulated chamber (pymodbus's own server, Modbus TCP or
RTU, with first-order thermal dynamics) and simulated serial sensors on pseudo-terminals.

Chamber: the air temperature follows the set-point as a first-order lag,
``dT/dt = (SP − T) / τ``, integrated exactly between requests,
``T ← SP + (T − SP)·exp(−K·Δt/τ)`` (``Δt`` host seconds, ``K`` the time scale).  Every
set-point written is logged with its host time.

Sensor: a gyro line ``gx,temp`` at ``rate_hz`` whose die temperature lags the chamber's
(``τ_die``) and whose output is ``bias_0 + slope·(T_die − 25 °C) + noise`` [deg/s] — the
known thermal bias a fit must recover.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from thermocal.station.chamber import RegisterMap
from thermocal.station.config import require

SETPOINT_REGISTER = 300
TEMPERATURE_REGISTER = 100
N_REGISTERS = 400


@dataclass
class ChamberModel:
    """First-order chamber: temperature [°C], time constant ``tau_s`` [program s].

    Attributes
    ----------
    temperature_c : float
        Temperature now [°C].
    setpoint_c : float
        Set-point [°C].
    tau_s : float
        Time constant [program s].
    time_scale : float
        Program seconds per wall-clock second.
    last_unix : float
        Wall-clock time of the last update [s, Unix].
    writes : list of (float, float)
        ``(time [s, Unix], set-point [°C])`` of every write.
    lock : threading.Lock
        Guards the state across the server's threads.
    """

    temperature_c: float = 25.0
    setpoint_c: float = 25.0
    tau_s: float = 120.0
    time_scale: float = 1.0
    last_unix: float = field(default_factory=time.time)
    writes: list[tuple[float, float]] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def advance(self, now: float | None = None) -> float:
        """Integrate to ``now`` (host [s]); return the temperature [°C].

        Parameters
        ----------
        now : float, optional
            Host time [s] (default now).

        Returns
        -------
        float
            The temperature [°C].
        """
        with self.lock:
            now = time.time() if now is None else now
            dt = max(0.0, now - self.last_unix) * self.time_scale
            self.last_unix = now
            self.temperature_c = self.setpoint_c + (self.temperature_c - self.setpoint_c) * (
                math.exp(-dt / self.tau_s)
            )
            return self.temperature_c


class SimulatedChamber:
    """A Modbus server (TCP on 127.0.0.1 with an OS-chosen port, or RTU on a serial port)
    in its own thread, holding the set-point in holding register ``setpoint_register``
    and the temperature in register ``temperature_register`` (defaults
    :data:`SETPOINT_REGISTER`, :data:`TEMPERATURE_REGISTER`; holding and input share
    one block), ``scale`` °C per count, signed.  ``answer = False`` makes it stop answering
    without closing (requests time out)."""

    def __init__(
        self,
        *,
        model: ChamberModel | None = None,
        scale: float = 0.01,
        rtu_port: str | None = None,
        unit: int = 1,
        setpoint_register: int = SETPOINT_REGISTER,
        temperature_register: int = TEMPERATURE_REGISTER,
    ) -> None:
        self.model = model or ChamberModel()
        self.map = RegisterMap(setpoint_register, temperature_register, "holding", scale, True)
        self.rtu_port = rtu_port
        self.unit = unit
        self.port = 0
        self.answer = True
        self._loop: asyncio.AbstractEventLoop | None = None
        self._server: Any = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._main, name="sim-chamber", daemon=True)

    @property
    def writes(self) -> list[tuple[float, float]]:
        """Set-points received: ``(host unix time [s], °C)``."""
        with self.model.lock:
            return list(self.model.writes)

    async def _action(
        self,
        function_code: int,
        start_address: int,
        address: int,
        count: int,
        registers: list[int],
        set_values: list[int] | list[bool] | None,
    ) -> Any:
        if not self.answer:
            await asyncio.sleep(3600)  # silent: the client times out
        now = time.time()
        self.model.advance(now)
        sp_reg, t_reg = self.map.setpoint_register, self.map.temperature_register
        sp_off = sp_reg - start_address
        if set_values and address <= sp_reg < address + len(set_values):
            word = int(set_values[sp_reg - address])
            with self.model.lock:
                self.model.setpoint_c = self.map.decode(word)
                self.model.writes.append((now, self.model.setpoint_c))
        registers[t_reg - start_address] = self.map.encode(self.model.temperature_c)
        if not set_values:
            registers[sp_off] = self.map.encode(self.model.setpoint_c)
        return None

    def _main(self) -> None:
        try:
            asyncio.run(self._serve())
        except BaseException as exc:  # reported to the starting thread
            self._error = exc
            self._ready.set()

    async def _serve(self) -> None:
        require("pymodbus")
        from pymodbus.server import ModbusSerialServer, ModbusTcpServer
        from pymodbus.simulator import DataType, SimData, SimDevice

        values = [0] * N_REGISTERS
        values[self.map.setpoint_register] = self.map.encode(self.model.setpoint_c)
        values[self.map.temperature_register] = self.map.encode(self.model.temperature_c)
        device = SimDevice(
            id=self.unit,
            simdata=[SimData(0, values=values, datatype=DataType.REGISTERS)],
            action=self._action,
        )
        self._loop = asyncio.get_running_loop()
        if self.rtu_port is None:
            self._server = ModbusTcpServer(device, address=("127.0.0.1", 0))
        else:
            self._server = ModbusSerialServer(device, port=self.rtu_port, baudrate=115200)
        await self._server.serve_forever(background=True)
        if self.rtu_port is None:
            self.port = int(self._server.transport.sockets[0].getsockname()[1])
        self._ready.set()
        await self._server.serving

    def start(self, timeout_s: float = 10.0) -> SimulatedChamber:
        """Start the Modbus server in a thread; return self once it answers (within
        ``timeout_s``).

        Parameters
        ----------
        timeout_s : float
            Longest wait for the server [s].

        Returns
        -------
        SimulatedChamber

        Raises
        ------
        TimeoutError
            The server did not start in time.
        """
        self._thread.start()
        if not self._ready.wait(timeout_s):
            raise TimeoutError("simulated chamber did not start")
        if self._error is not None:
            raise RuntimeError(f"simulated chamber failed: {self._error!r}")
        return self

    def stop(self, timeout_s: float = 5.0) -> None:
        """Shut the server down (its port closes: the chamber stops answering).

        Parameters
        ----------
        timeout_s : float
            Longest wait for the server to stop [s].
        """
        if self._loop is not None and self._server is not None and self._thread.is_alive():
            fut = asyncio.run_coroutine_threadsafe(self._server.shutdown(), self._loop)
            with contextlib.suppress(Exception):  # already closing
                fut.result(timeout_s)
        self._thread.join(timeout_s)


@dataclass(frozen=True)
class GyroTruth:
    """The simulated sensor's truth: ``gx = bias_deg_s + slope_deg_s_per_c·(T − 25 °C)``
    [deg/s], white noise ``noise_deg_s`` (1σ), die temperature lag ``tau_s`` [program s].

    Attributes
    ----------
    bias_deg_s : float
        Bias at 25 °C [deg/s].
    slope_deg_s_per_c : float
        Temperature slope [deg/s/°C].
    noise_deg_s : float
        White noise, 1σ [deg/s].
    tau_s : float
        Die temperature lag [program s].
    """

    bias_deg_s: float = 0.05
    slope_deg_s_per_c: float = 0.002
    noise_deg_s: float = 0.0005
    tau_s: float = 60.0


class SimulatedSerialSensor:
    """A pseudo-terminal pair: the station opens :attr:`device` (the slave end); a thread
    writes ``gx,temp`` lines at ``rate_hz`` host lines per second to the master end.

    ``banner`` lines are written first; ``bad_every`` > 0 mangles every n-th line (kept in
    :attr:`sent_bad`); :meth:`silence` stops sending (the port stays open).  Every good line
    sent is kept in :attr:`sent` as ``(gx, temp)``.
    """

    def __init__(
        self,
        chamber: ChamberModel | Callable[[], float],
        *,
        rate_hz: float = 50.0,
        truth: GyroTruth | None = None,
        time_scale: float = 1.0,
        seed: int = 1,
        banner: tuple[str, ...] = (),
        bad_every: int = 0,
    ) -> None:
        import random
        import tty

        self.master, slave = os.openpty()
        tty.setraw(slave)
        self.device = os.ttyname(slave)
        os.set_blocking(self.master, False)
        self._slave = slave  # kept open so the master never sees a hang-up
        self.chamber = chamber
        self.rate_hz = rate_hz
        self.truth = truth or GyroTruth()
        self.time_scale = time_scale
        self.rng = random.Random(seed)
        self.banner = banner
        self.bad_every = bad_every
        self.sent: list[tuple[float, float]] = []
        self.sent_bad: list[str] = []
        self.die_c = self._air()
        self._silent = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="sim-sensor", daemon=True)

    def _air(self) -> float:
        if isinstance(self.chamber, ChamberModel):
            return self.chamber.advance()
        return self.chamber()

    def _run(self) -> None:
        for b in self.banner:
            os.write(self.master, (b + "\r\n").encode())
        period = 1.0 / self.rate_hz
        t_next = time.time()
        last = time.time()
        n = 0
        while not self._stop.is_set():
            now = time.time()
            if now < t_next:
                time.sleep(min(period, t_next - now))
                continue
            t_next += period
            if self._silent.is_set():
                continue
            air = self._air()
            dt = (now - last) * self.time_scale
            last = now
            self.die_c = air + (self.die_c - air) * math.exp(-dt / self.truth.tau_s)
            tr = self.truth
            gx = (tr.bias_deg_s + tr.slope_deg_s_per_c * (self.die_c - 25.0)
                  + self.rng.gauss(0.0, tr.noise_deg_s))  # fmt: skip
            n += 1
            bad = bool(self.bad_every and n % self.bad_every == 0)
            line = f"{gx:.6f},{self.die_c:.3f}"
            if bad:
                line = line[:7]  # a cut line
            try:
                os.write(self.master, (line + "\r\n").encode())
            except BlockingIOError:  # nobody reads: the line is not sent
                continue
            except OSError:
                return
            if bad:
                self.sent_bad.append(line)
            else:
                self.sent.append((float(f"{gx:.6f}"), float(f"{self.die_c:.3f}")))

    def start(self) -> SimulatedSerialSensor:
        """Open the pseudo-terminal and start sending lines; return self."""
        self._thread.start()
        return self

    def silence(self) -> None:
        """Stop sending lines, keeping the port open (a sensor gone quiet)."""
        self._silent.set()

    def stop(self) -> None:
        """Stop sending and close the pseudo-terminal."""
        self._stop.set()
        self._thread.join(5.0)
        for fd in (self.master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)
