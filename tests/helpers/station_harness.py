"""The station attack tests' harness: one scripted Modbus TCP server on 127.0.0.1 written
byte by byte (MBAP header, PDU), a pseudo-terminal sensor sending scripted lines, the
station's TOML and program written here, and a CLI child process with its end and its
stacks when it stalls.  Expected values come from outside the station: what the server
received, what the sensor sent."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import pyarrow.parquet as pq

from station_toml import sensor_toml

SCALE = 0.01
SRC = str(Path(__file__).resolve().parents[2] / "src")
HOT = ((0.0, 10.0, 400.0), (25.0, 65.0, 65.0))
"""A program that goes hot at once and holds: 65 °C is what a dead station leaves."""


def _digest(*paths: Path) -> list[str]:
    return [hashlib.sha256(p.read_bytes()).hexdigest() for p in paths]


def _toml(port: int, device: str, part_s: float = 60.0, **extra: object) -> str:
    ch = "\n".join(f"{k} = {json.dumps(v)}" for k, v in extra.items())
    return f"""part_s = {part_s}
[chamber]
driver = "modbus-tcp"
host = "127.0.0.1"
port = {port}
setpoint_register = 300
temperature_register = 100
register_kind = "input"
scale = {SCALE}
poll_s = 0.1
io_timeout_s = 0.3
safe_setpoint_c = 21.5
{ch}
""" + sensor_toml(device)


def _profile(tmp: Path, program: tuple[tuple[float, ...], tuple[float, ...]] = HOT) -> Path:
    p = tmp / "p.csv"
    p.write_text(
        "time_s,setpoint_c\n" + "".join(f"{t},{c}\n" for t, c in zip(*program, strict=True))
    )
    return p


def _spawn(args: list[str], stdout: int = subprocess.PIPE) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": SRC, "PYTHONFAULTHANDLER": "1"}  # SIGABRT: stacks
    code = "import sys; from thermocal.cli import main; sys.exit(main())"
    return subprocess.Popen([sys.executable, "-c", code, *args], env=env, text=True,
                            stdout=stdout, stderr=subprocess.PIPE)  # fmt: skip


def _end(proc: subprocess.Popen[str]) -> None:
    """Kill the child if it still runs and close its pipes (a pipe left to the garbage
    collector is a ResourceWarning in whatever test runs next)."""
    proc.kill()
    proc.wait()
    for f in (proc.stdout, proc.stderr):
        if f is not None:
            with contextlib.suppress(OSError):
                f.close()


def _where_is(proc: subprocess.Popen[str]) -> str:
    """Where a child that seems stalled is: its state and kernel wait channel, and every
    thread's Python stack (SIGABRT: ``PYTHONFAULTHANDLER`` prints them on its stderr)."""
    import select

    if proc.poll() is not None:
        return f"the child ended with {proc.returncode}"
    state = ""
    with contextlib.suppress(OSError):
        status = Path(f"/proc/{proc.pid}/status").read_text().splitlines()
        state = next((ln for ln in status if ln.startswith("State:")), "")
        state += ", wchan " + Path(f"/proc/{proc.pid}/wchan").read_text()
    proc.send_signal(signal.SIGABRT)
    out, end = b"", time.monotonic() + 10
    fd = proc.stderr.fileno() if proc.stderr is not None else None
    while fd is not None and time.monotonic() < end:
        if select.select([fd], [], [], 0.2)[0]:
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                break
            out += chunk
    return f"the child still ran ({state}); its stacks: {out.decode(errors='replace')[-6000:]}"


def _wait(pred, timeout_s: float, what: str, drain: int | None = None) -> None:  # type: ignore[no-untyped-def]
    """Poll ``pred`` until true; ``drain``: a pipe's descriptor read meanwhile, so that a
    child writing to it never blocks on a full pipe (a loaded machine is slow to start it)."""
    import select

    end = time.monotonic() + timeout_s
    drained: list[bytes] = []
    while time.monotonic() < end:
        if pred():
            return
        if drain is not None and select.select([drain], [], [], 0)[0]:
            drained.append(os.read(drain, 1 << 16))
        time.sleep(0.02)
    tail = b"".join(drained)[-2000:].decode(errors="replace")
    raise AssertionError(
        f"timed out waiting for {what}" + (f"; the child said: {tail}" if tail else "")
    )


def _last_kept(out: Path, sent: list[tuple[float, float]]) -> int:
    """How many lines the sensor had sent when the last recorded one was sent (the
    recording's last ``(gx, temp)`` found in the lines sent)."""
    rows: list[tuple[float, float]] = []
    for p in sorted(out.glob("imu-*.parquet")):
        t = pq.read_table(p, columns=["gx", "temp"])
        rows += list(zip(t["gx"].to_pylist(), t["temp"].to_pylist(), strict=True))
    assert rows, "nothing recorded"
    return max(i + 1 for i, s in enumerate(sent) if s == rows[-1])


def _events(out: Path) -> list[dict]:
    return json.loads((out / "station.json").read_text())["events"]


class _ModbusServer:
    """A Modbus TCP server on 127.0.0.1 written here byte by byte (MBAP header, PDU): every
    request is answered with :meth:`_reply`'s PDU after ``delay_s``."""

    delay_s = 0.0

    def __init__(self) -> None:
        self.srv = socket.socket()
        self.srv.bind(("127.0.0.1", 0))
        self.srv.listen(4)
        self.srv.settimeout(0.2)
        self.port = self.srv.getsockname()[1]
        self.stop = threading.Event()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while not self.stop.is_set():
            try:
                conn, _ = self.srv.accept()
            except OSError:
                continue
            threading.Thread(target=self._serve, args=(conn,), daemon=True).start()

    def _serve(self, conn: socket.socket) -> None:
        with conn:
            while not self.stop.is_set():
                try:
                    head = conn.recv(7)
                    if len(head) < 7:
                        return
                    tid, _pid, length, unit = struct.unpack(">HHHB", head)
                    pdu = conn.recv(length - 1)
                    body = self._reply(pdu[0], pdu)
                    time.sleep(self.delay_s)
                    conn.sendall(struct.pack(">HHHB", tid, 0, len(body) + 1, unit) + body)
                except OSError:
                    return

    def _reply(self, fc: int, pdu: bytes) -> bytes:
        """The reply's PDU to the request ``pdu`` of function code ``fc``."""
        raise NotImplementedError

    def close(self) -> None:
        self.stop.set()
        self.srv.close()


class BrokenModbus(_ModbusServer):
    """Writes (function 6) are echoed; a read (3 or 4) is answered as ``mode`` says:
    ``zero`` a reply with byte count 0, ``cut`` a frame whose byte count (2) exceeds its
    data (1 byte), ``fc`` the reply of another function code (6), ``ok`` one register =
    250."""

    def __init__(self, mode: str) -> None:
        self.mode = mode
        self.writes = 0
        super().__init__()

    def _reply(self, fc: int, pdu: bytes) -> bytes:
        if fc == 6:
            self.writes += 1
            return pdu
        replies = {"zero": bytes([fc, 0]), "cut": bytes([fc, 2, 0x01]),
                   "fc": bytes([6, 0, 100, 0, 1]), "ok": bytes([fc, 2, 0, 250])}  # fmt: skip
        return replies[self.mode]


class ScriptedModbus(_ModbusServer):
    """A write (function 6) is echoed and its value kept in :attr:`writes` [°C at
    :data:`SCALE`]; a read (3 or 4) answers one register = 25 °C.  ``delay_s`` delays every
    reply; ``exception`` (a Modbus exception code) answers every read with it."""

    def __init__(self, *, delay_s: float = 0.0, exception: int = 0) -> None:
        self.delay_s, self.exception = delay_s, exception
        self.writes: list[float] = []
        super().__init__()

    def _reply(self, fc: int, pdu: bytes) -> bytes:
        if fc == 6:
            word = struct.unpack(">H", pdu[3:5])[0]
            self.writes.append((word - 0x10000 if word >= 0x8000 else word) * SCALE)
            return pdu
        if self.exception:
            return bytes([fc | 0x80, self.exception])
        return bytes([fc, 2]) + struct.pack(">H", round(25.0 / SCALE))


class ScriptedSensor:
    """A pseudo-terminal sending ``lines`` in a loop at ``rate_hz``; what was sent kept."""

    def __init__(self, lines: list[str] | Callable[[int], str], rate_hz: float = 100.0) -> None:
        import tty

        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.device = os.ttyname(self.slave)
        os.set_blocking(self.master, False)
        self.lines, self.rate_hz = lines, rate_hz
        self.sent: list[str] = []
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        i = 0
        while not self.stop.wait(1.0 / self.rate_hz):
            line = self.lines(i) if callable(self.lines) else self.lines[i % len(self.lines)]
            try:
                os.write(self.master, (line + "\r\n").encode())
            except BlockingIOError:
                continue
            except OSError:
                return
            self.sent.append(line)
            i += 1

    def close(self) -> None:
        self.stop.set()
        self.thread.join(2)
        for fd in (self.master, self.slave):
            with contextlib.suppress(OSError):
                os.close(fd)
