"""The station's program loop: set-points, chamber polling, sensor lines into the recorder,
stale sensors, a silent or drifting chamber, and the safe set-point on every way out.

Program time ``p`` [s] runs ``time_scale`` times faster than the host clock:
``p = p0 + K·(t − t_run)``, ``p0`` = 0 for a new run and, for ``--resume``, the largest
``program_s`` the recording holds (the program continues where the recording ends).  The
set-point is the program interpolated linearly at ``p`` (``numpy.interp``: steps where the
program has them, ramps where it ramps), rounded to the register's resolution, and written
whenever that rounded value changes (``driver = "none"``: each step's goal, once).

The recording's ``time`` is the sensor's own clock (``rate_hz``) or the host's, never the
program's: with ``--time-scale K`` a real chamber still heats at its own pace, so rates of
change in the recording are physical; the program time of every row is its ``program_s``
column, and the metadata's ``station.time_scale`` says the run was accelerated.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from thermocal.errors import ThermocalInputError
from thermocal.readers.station import CHAMBER_STREAM, closed_parts
from thermocal.station import clock
from thermocal.station.chamber import Chamber, ChamberError, make_chamber
from thermocal.station.config import ChamberConfig, StationConfig
from thermocal.station.recorder import Recorder
from thermocal.station.sensors import MAX_BACKLOG, Bad, SerialSensor

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

    FloatArray = npt.NDArray[np.float64]

LOOP_S = 0.02
"""Longest sleep of the loop [s]: sensor lines are drained and stop requests seen at least
this often."""


MAX_PROGRAM_POINTS = 20_000
"""Most points a program may hold: ``station.json`` (holding the program) is rewritten and
flushed at every event; a controller's program holds a few hundred segments, a week at one
point a minute 10 080 (10⁶ points made each rewrite 20 MB and stalled the loop)."""

SETPOINT_EVENT_C = 1.0
"""Along a ramp, a ``setpoint`` event (a rewrite of ``station.json``) is recorded when the
set-point has moved this far from the last one recorded [°C] (or at a new program step, or
after :data:`SETPOINT_EVENT_S`): a ramp at the register's 0.01 °C resolution writes a new
set-point at every turn of the loop, 10⁵ a day, and one event each made every rewrite
megabytes long.  The chamber stream's rows hold every set-point polled."""

SETPOINT_EVENT_S = 60.0
"""Longest host time between two recorded ``setpoint`` events while the set-point moves [s]."""

ROWS_PER_TURN = 2000
"""Most lines of one sensor recorded per turn of the loop: a flooding sensor leaves the
rest for the next turns instead of delaying the chamber's polls and the stop requests
(a turn that records every line waiting lasts 0.02 s / (1 − lines per s × cost of a
line), which diverges for a fast enough flood)."""

CLOCK_STEP_S = 1.0
"""A step of the host's wall clock larger than this between two turns is reported [s]."""

CLOCK_CHECK_S = 2.0
"""Host seconds of lines after which a sensor's time is compared with the host clock [s]."""

CLOCK_RATIO = (0.8, 1.25)
"""Accepted ratio of a sensor's time to the host clock over :data:`CLOCK_CHECK_S`: wide
enough for the bursts in which a serial port delivers lines, narrow enough for a rate or a
time unit off by a factor of 2 or more."""


class StationStopped(ThermocalInputError):
    """The run stopped safely because the chamber stopped answering (exit 2)."""


@dataclass
class SensorView:
    """One sensor's line of the live display.

    Attributes
    ----------
    id : str
        The sensor.
    rate_hz : float
        Measured rate [Hz].
    last : tuple of float
        The last sample's values.
    names : tuple of str
        Their names.
    bad : int
        Bad lines so far.
    samples : int
        Samples so far.
    """

    id: str
    rate_hz: float
    last: tuple[float, ...]
    names: tuple[str, ...]
    bad: int
    samples: int
    stopped: bool


@dataclass
class StationState:
    """What the live display shows, refreshed by the loop.

    Attributes
    ----------
    step, n_steps : int
        The program step running and their number.
    program_s, end_s : float
        Program time now and at the end [s].
    setpoint_c, chamber_c : float
        Set-point and chamber temperature [°C] (NaN: not known yet).
    time_scale : float
        Program seconds per wall-clock second.
    sensors : list of SensorView
        Each sensor's line.
    samples, parts : int
        Samples recorded and Parquet parts written.
    chamber_ok : bool
        The chamber answers.
    """

    step: int = 0
    n_steps: int = 0
    program_s: float = 0.0
    end_s: float = 0.0
    setpoint_c: float = math.nan
    chamber_c: float = math.nan
    time_scale: float = 1.0
    sensors: list[SensorView] = field(default_factory=list)
    samples: int = 0
    parts: int = 0
    chamber_ok: bool = True

    @property
    def time_left_s(self) -> float:
        """Host seconds left [s]."""
        return max(0.0, (self.end_s - self.program_s) / self.time_scale)


class Display(Protocol):
    """Where a run shows its state and messages (a live table or log lines)."""

    def update(self, state: StationState) -> None:
        """Show ``state``.

        Parameters
        ----------
        state : StationState
            The station's state.
        """

    def log(self, message: str) -> None:
        """Show one message.

        Parameters
        ----------
        message : str
            The text.
        """


def say(message: str) -> str:
    """Print ``message`` on stderr; never raises.  Returns ``""``, or why stderr is gone
    (a closed pipe, a vanished terminal): then file descriptor 2 is pointed at
    ``os.devnull``, so that no later message (nor Python's flush at exit) raises either.
    Started without a stderr (``2>&-``: ``sys.stderr`` is None) nothing is printed (never
    on stdout, where ``--json`` writes) and ``""`` is returned: nobody was watching.

    Parameters
    ----------
    message : str
        The text.

    Returns
    -------
    str
        ``""``, or why stderr is gone.
    """
    if sys.stderr is None:
        return ""
    try:
        print(message, file=sys.stderr, flush=True)
    except (OSError, ValueError, AttributeError) as exc:
        mute_stderr()
        return f"stderr closed ({type(exc).__name__})"
    return ""


def mute_stderr() -> None:
    """Point file descriptor 2 (and ``sys.stderr``) at ``os.devnull``."""
    import contextlib
    import os

    with contextlib.suppress(OSError, ValueError, AttributeError):
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, 2)
        os.close(fd)
    with contextlib.suppress(Exception):
        sys.stderr = open(os.devnull, "w", encoding="utf-8")  # noqa: SIM115 (for the process)


class LogDisplay:
    """Not a terminal: a line per program step and per event on stderr, nothing else.
    ``broken`` says why stderr is gone (the loop then stops safely: nobody watches)."""

    def __init__(self) -> None:
        self.broken = ""

    def update(self, state: StationState) -> None:
        """Nothing: a log display prints messages only.

        Parameters
        ----------
        state : StationState
            The station's state.
        """
        return None

    def log(self, message: str) -> None:
        """Print ``message`` on stderr.

        Parameters
        ----------
        message : str
            The text.
        """
        if not self.broken:
            self.broken = say(message)


@dataclass(frozen=True)
class RunResult:
    """What a run did: folder, program span covered [s], parts written, samples per stream,
    bad lines per sensor, how it ended (``"end"``, ``"interrupted"``, ``"chamber"``), the
    set-points written as ``(program_s, °C)``, the safe set-point written (or None), the
    events, why it was interrupted (``"SIGHUP"``, ``"stderr closed (…)"``; ``""``) and, for
    ``--resume``, how the previous run ended (:func:`previous_run`).

    Attributes
    ----------
    out_dir : Path
        The recording folder.
    program_start_s, program_end_s : float
        Program span covered [s].
    parts : list of str
        The Parquet parts written.
    samples : dict of str to int
        Samples per stream.
    bad_lines : dict of str to int
        Bad lines per sensor.
    ended : str
        ``"end"``, ``"interrupted"`` or ``"chamber"``.
    setpoints : list of (float, float)
        The set-points written, ``(program time [s], set-point [°C])``.
    safe_setpoint_c : float or None
        The safe set-point written at the end [°C] (None: none written).
    events : list of dict
        The run's events.
    stop_reason : str
        Why it was interrupted (``"SIGHUP"``, ``"stderr closed (…)"``; "" otherwise).
    previous : str
        How the previous run ended, for a resumed run.
    """

    out_dir: Path
    program_start_s: float
    program_end_s: float
    parts: list[str]
    samples: dict[str, int]
    bad_lines: dict[str, int]
    ended: str
    setpoints: list[tuple[float, float]]
    safe_setpoint_c: float | None
    events: list[dict[str, Any]]
    stop_reason: str = ""
    previous: str = ""


def _last_program_s(out_dir: Path) -> float:
    """The largest ``program_s`` in the closed parts (0 when there are none) [s]."""
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    last = 0.0
    for _s, _i, p in closed_parts(out_dir):
        col = pq.read_table(p, columns=["program_s"])["program_s"]
        m = pc.max(col).as_py()
        if m is not None and math.isfinite(m):
            last = max(last, float(m))
    return last


class _Loop:
    """The state of one run while the program plays: the loop's steps as methods (program
    step, chamber set-point and poll, drift, sensor lines, the safe stop)."""

    def __init__(
        self,
        cfg: StationConfig,
        t_prog: FloatArray,
        c_prog: FloatArray,
        p0: float,
        time_scale: float,
        rec: Recorder,
        chamber: Chamber,
        disp: Display,
    ) -> None:
        self.cfg, self.ch_cfg = cfg, cfg.chamber
        self.t_prog, self.c_prog = t_prog, c_prog
        self.end_s = float(t_prog[-1])
        self.p0, self.time_scale = p0, time_scale
        self.rec, self.chamber, self.disp = rec, chamber, disp
        self.sensors = [SerialSensor(s) for s in cfg.sensors]
        self.state = StationState(n_steps=len(t_prog) - 1, end_s=self.end_s, time_scale=time_scale)
        self.setpoints: list[tuple[float, float]] = []
        self.sp_recorded: tuple[float, float, int] | None = None  # °C, host s, step
        self.samples = {s.id: 0 for s in cfg.sensors} | {CHAMBER_STREAM: 0}
        self.bad = {s.id: 0 for s in cfg.sensors}
        self.parts: list[str] = []
        self.stopped = {s.id: False for s in cfg.sensors}
        self.dropped_warned: dict[str, bool] = {}
        self.anchors: dict[str, float] = {}
        self.clock_first: dict[str, tuple[float, float]] = {}
        self.clock_checked: set[str] = set()
        self.bad_kinds: set[tuple[str, str]] = set()
        self.limits: dict[str, list[tuple[int, float, str]]] = {}
        self.last_time: dict[str, float] = {}
        self.ended = "end"
        self.stop_reason = ""
        self.safe: float | None = None
        self.sp = math.nan
        self.chamber_c = math.nan
        self.fail_since: float | None = None
        self.drift_since: float | None = None
        self.drift_reported = False
        self.hold: tuple[int, float, bool] | None = None
        self.hold_polls = 0
        self.step = -1
        self.t_run = clock.now()
        self.next_poll = self.t_run
        self.p = p0
        self.wall_step = clock.wall_step()

    def start(self) -> None:
        """Connect the chamber (its first temperature), open and start the sensors."""
        try:
            self.chamber.connect()
            self.chamber_c = self.chamber.read_temperature()
        except ChamberError as exc:
            raise ThermocalInputError(f"{exc} (check [chamber] in {self.cfg.source})") from None
        for s in self.sensors:
            s.open()
        for s in self.sensors:
            s.start()
        self.rec.event("start", f"chamber {self.chamber.name}, sensors " + ", ".join(
            s.cfg.id for s in self.sensors), program_s=self.p0,
            time_scale=self.time_scale)  # fmt: skip
        self.t_run = clock.now()
        self.next_poll = self.t_run

    def _stop_asked(self, should_stop: Callable[[], bool | str] | None) -> str:
        """Why the run must stop now (``""``: it need not): ``should_stop``'s answer (a
        string is the reason: a signal's name) or a display whose stderr is gone."""
        asked = should_stop() if should_stop is not None else False
        if asked:
            return asked if isinstance(asked, str) else "asked"
        return str(getattr(self.disp, "broken", "") or "")

    def play(self, should_stop: Callable[[], bool | str] | None) -> None:
        """The loop: every ``LOOP_S`` at most, the program's step and set-point, the
        chamber's poll, drift, the sensors' lines, part rotation and the display."""
        while True:
            now = clock.now()
            self._clock_step(p=self.p)
            p = self.p = self.p0 + (now - self.t_run) * self.time_scale
            why = self._stop_asked(should_stop)
            if p >= self.end_s or why:
                self.p = min(p, self.end_s)
                if p < self.end_s:
                    self.ended, self.stop_reason = "interrupted", why
                else:
                    self._judge_hold()  # the last hold ran to its end
                break
            self._program_step(p)
            self._chamber(now, p)
            self.state.chamber_ok = self.fail_since is None
            self._drift(p)
            views = self._sensors(now, p)
            self.parts += self.rec.maybe_rotate(now)
            state = self.state
            state.step, state.program_s, state.setpoint_c = self.step + 1, p, self.sp
            state.chamber_c, state.sensors = self.chamber_c, views
            state.samples, state.parts = sum(self.samples.values()), len(self.parts)
            self.disp.update(state)
            time.sleep(LOOP_S)

    def _clock_step(self, p: float) -> None:
        """A ``warning:`` when the host's wall clock was stepped by more than
        :data:`CLOCK_STEP_S` since the last turn: the run goes on by the station's clock
        (:mod:`thermocal.station.clock`), unmoved."""
        step = clock.wall_step()
        jump, self.wall_step = step - self.wall_step, step
        if abs(jump) <= CLOCK_STEP_S:
            return
        msg = (f"warning: the host's clock was stepped by {jump:+.1f} s at program time "
               f"{p:.1f} s; the station keeps its own clock: the program, the polls and the "
               "recorded times go on unmoved")  # fmt: skip
        self.rec.event("clock", msg, step_s=jump, program_s=p)
        self.disp.log(msg)

    def _program_step(self, p: float) -> None:
        """Log and record a new program step when ``p`` [s] enters one."""
        import numpy as np

        t_prog, c_prog = self.t_prog, self.c_prog
        k = int(np.searchsorted(t_prog, p, side="right")) - 1
        if k != self.step:
            self._judge_hold()
            self.step = k
            held = k + 1 < len(c_prog) and c_prog[k] == c_prog[k + 1]
            self.hold = (k, float(c_prog[k]), False) if held else None
            nxt = float(c_prog[min(k + 1, len(c_prog) - 1)])
            msg = (f"step {k + 1}/{self.state.n_steps}: {float(c_prog[k]):.2f} → {nxt:.2f} °C "
                   f"from program time {float(t_prog[k]):.0f} s")  # fmt: skip
            self.disp.log(msg)
            self.rec.event("step", msg, program_s=p, step=k + 1)

    def _judge_hold(self) -> None:
        """At a hold's end: warn when the chamber, polled during it, never came within
        ``tolerance_c`` of the hold's set-point (a chamber that ignores its set-point is
        noticed in every hold, however much shorter than ``drift_s``)."""
        hold, self.hold = self.hold, None
        if hold is None or hold[2] or not self.hold_polls:
            self.hold_polls = 0
            return
        k, sp, _ = hold
        t0, t1 = float(self.t_prog[k]), float(self.t_prog[k + 1])
        msg = (f"warning: chamber never within tolerance_c = {self.ch_cfg.tolerance_c:g} °C "
               f"of the set-point {sp:.2f} °C in the hold at program time {t0:.0f}–{t1:.0f} s "
               f"(last read {self.chamber_c:.2f} °C): is it following its set-point?")  # fmt: skip
        self.rec.event("hold", msg, program_s=self.p, step=k + 1, setpoint_c=sp)
        self.disp.log(msg)
        self.hold_polls = 0

    def _track_hold(self) -> None:
        """After a poll: note whether the chamber is within ``tolerance_c`` of the hold's
        set-point [°C]."""
        if self.hold is None or not math.isfinite(self.chamber_c):
            return
        self.hold_polls += 1
        k, sp, reached = self.hold
        if not reached and abs(self.chamber_c - sp) <= self.ch_cfg.tolerance_c:
            self.hold = (k, sp, True)

    def _chamber(self, now: float, p: float) -> None:
        """Write the set-point when its register value changes, poll the chamber every
        ``poll_s``; a chamber silent for ``timeout_s`` stops the run (:class:`StationStopped`)."""
        import numpy as np

        ch_cfg, rec = self.ch_cfg, self.rec
        if ch_cfg.driver == "none":  # by hand: each step's goal once, not every value of a ramp
            target = float(self.c_prog[min(self.step + 1, len(self.c_prog) - 1)])
        else:
            target = _quantize(float(np.interp(p, self.t_prog, self.c_prog)), ch_cfg.scale,
                               ch_cfg.signed, ch_cfg.driver)  # fmt: skip
        asked = target != self.sp or now >= self.next_poll
        try:
            if target != self.sp:
                self.chamber.write_setpoint(target)
                self.sp = target
                self.setpoints.append((p, target))
            self._record_setpoint(now, p)
            if now >= self.next_poll:
                self.next_poll = max(self.next_poll + ch_cfg.poll_s, now)
                self.chamber_c = math.nan  # unknown until the chamber answers
                self.chamber_c = self.chamber.read_temperature()
                self._track_hold()
                rec.add(CHAMBER_STREAM, {"time": rec.rel(now), "program_s": p,
                                         "setpoint_c": self.sp,
                                         "chamber_c": self.chamber_c})  # fmt: skip
                self.samples[CHAMBER_STREAM] += 1
            if self.fail_since is not None and asked:  # an answer, not a turn without request
                rec.event("chamber", "the chamber answers again")
                self.disp.log("chamber answers again")
                self.fail_since = None
        except ChamberError as exc:
            if self.fail_since is None:
                self.fail_since = now
                rec.event("chamber", f"no answer: {exc}")
                self.disp.log(f"warning: {exc}")
            elif now - self.fail_since >= ch_cfg.timeout_s:
                self.ended = "chamber"
                raise StationStopped(
                    f"{exc}; no answer for {now - self.fail_since:.0f} s (timeout_s "
                    f"{ch_cfg.timeout_s:g}): run stopped at program time {p:.1f} s; "
                    f"continue with --resume"
                ) from None
            self.next_poll = now + min(ch_cfg.poll_s, 0.5)

    def _record_setpoint(self, now: float, p: float) -> None:
        """A ``setpoint`` event for the set-point in force (written) at a program step's
        first turn, and along a ramp every :data:`SETPOINT_EVENT_C` or
        :data:`SETPOINT_EVENT_S` (not for every write)."""
        last, target = self.sp_recorded, self.sp
        if target != target or (last is not None and last[0] == target):
            return
        if (last is not None and last[2] == self.step and abs(target - last[0]) < SETPOINT_EVENT_C
                and now - last[1] < SETPOINT_EVENT_S):  # fmt: skip
            return
        self.sp_recorded = (target, now, self.step)
        self.rec.event("setpoint", f"{target:.3f} °C", program_s=p, setpoint_c=target)

    def _drift(self, p: float) -> None:
        """Warn once when the chamber stays beyond ``tolerance_c`` of its set-point for
        ``drift_s`` of program time."""
        chamber_c, sp, ch_cfg = self.chamber_c, self.sp, self.ch_cfg
        if math.isfinite(chamber_c) and abs(chamber_c - sp) > ch_cfg.tolerance_c:
            self.drift_since = p if self.drift_since is None else self.drift_since
            if not self.drift_reported and p - self.drift_since >= ch_cfg.drift_s:
                away = abs(chamber_c - sp)
                msg = (f"warning: chamber {chamber_c:.2f} °C is {away:.2f} °C from its "
                       f"set-point {sp:.2f} °C for {p - self.drift_since:.0f} s")  # fmt: skip
                self.rec.event("drift", msg, program_s=p)
                self.disp.log(msg)
                self.drift_reported = True
        else:
            self.drift_since, self.drift_reported = None, False

    def _add_rows(self, s: SerialSensor, got: list[Any]) -> None:
        """The sensor's lines as rows of its stream, with the chamber's state; a line with a
        value beyond any sensor is kept aside instead (:func:`_beyond_any_sensor`)."""
        row: dict[str, float] = {}
        limits = self.limits.setdefault(s.cfg.id, _signal_limits(s.cfg))
        beyond = [(smp, why) for smp in got if (why := _beyond_any_sensor(smp.values, limits))]
        if beyond:
            rows = [(b.host_unix, b.index, why, ",".join(f"{v:g}" for v in b.values))
                    for b, why in beyond]  # fmt: skip
            self.bad[s.cfg.id] += len(rows)
            self.rec.bad_lines(s.cfg.id, rows)
            self._warn_bad(s.cfg.id, [Bad(h, i, t, r) for h, i, r, t in rows], self.p)
            skip = {id(b) for b, _w in beyond}
            got = [smp for smp in got if id(smp) not in skip]
        for smp in got:
            row = _sensor_row(s, smp.host_unix, smp.index, smp.values, self.rec, self.anchors,
                              self.last_time)  # fmt: skip
            program_s = self.p0 + (smp.host_unix - self.t_run) * self.time_scale
            row.update(chamber_c=self.chamber_c, setpoint_c=self.sp, program_s=program_s)
            self.rec.add(s.cfg.id, row)
        if row:  # from the last line of the first read: lines queued before it share its time
            self.clock_first.setdefault(s.cfg.id, (row["time"], row["host_time"]))
            self._check_clock(s, row["time"], row["host_time"])

    def _check_clock(self, s: SerialSensor, t: float, host: float) -> None:
        """Once per run, after :data:`CLOCK_CHECK_S` of host time: the recording's time
        (``rate_hz`` or the line's own time field) must advance as the host clock does,
        ``Δtime / Δhost`` within :data:`CLOCK_RATIO`; else a ``warning:`` (a rate of 1000 Hz
        declared for a 50 line/s sensor makes every duration 20× too short)."""
        sid = s.cfg.id
        t0, h0 = self.clock_first[sid]
        if sid in self.clock_checked or host - h0 < CLOCK_CHECK_S:
            return
        self.clock_checked.add(sid)
        ratio = (t - t0) / (host - h0)
        lo, hi = CLOCK_RATIO
        if lo <= ratio <= hi:
            return
        cfg = s.cfg
        how = (f"rate_hz = {cfg.rate_hz:g}" if cfg.rate_hz is not None else
               f"its time field {cfg.time_name!r} in "
               f"{cfg.units[cfg.names.index(cfg.time_name or '')]}")  # fmt: skip
        msg = (f"warning: sensor {sid}: its time advances {ratio:.3g}× as fast as the host "
               f"clock over {host - h0:.1f} s ({how} in {self.cfg.source}; the lines arrive at "
               f"{s.stats.rate_hz():.1f} per s): the recording's time is wrong; stop, fix "
               "STATION.toml and record again (host_time holds the host's clock)")  # fmt: skip
        self.rec.event("clock", msg, sensor=sid, ratio=ratio, program_s=self.p)
        self.disp.log(msg)

    def _warn_bad(self, sid: str, bads: list[Any], p: float) -> None:
        """A ``warning:`` for the first bad line of each kind (its reason without the
        numbers and text) per sensor; the rest are counted in ``SENSOR.bad.txt``."""
        import re

        for b in bads:
            kind = re.sub(r"\d+", "#", b.reason.split(":")[0])
            if (sid, kind) in self.bad_kinds:
                continue
            self.bad_kinds.add((sid, kind))
            msg = (
                f"warning: sensor {sid}: line {b.index} kept aside in {sid}.bad.txt, not "
                f"recorded ({b.reason}); lines of this kind are only counted from now on"
            )
            self.rec.event("bad", msg, sensor=sid, program_s=p)
            self.disp.log(msg)

    def _sensors(self, now: float, p: float) -> list[SensorView]:
        """Drain every sensor's lines into the recorder; report a sensor that stops or
        sends again; the display's view of each."""
        rec, views = self.rec, []
        for s in self.sensors:
            sid = s.cfg.id
            got, bads = s.drain(ROWS_PER_TURN)
            if s.stats.dropped and not self.dropped_warned.get(sid):
                self.dropped_warned[sid] = True
                msg = (f"warning: sensor {sid}: lines arrive faster than the station can record "
                       f"them ({s.stats.rate_hz():.0f} per s): lines beyond "
                       f"{MAX_BACKLOG} waiting are dropped and counted; check the sensor's "
                       "output rate")  # fmt: skip
                rec.event("sensor", msg, sensor=sid, program_s=p)
                self.disp.log(msg)
            if bads:
                self.bad[sid] += len(bads)
                rec.bad_lines(sid, [(b.host_unix, b.index, b.reason, b.text) for b in bads])
                self._warn_bad(sid, bads, p)
            self._add_rows(s, got)
            self.samples[sid] += len(got)
            silent = (now - (s.stats.last_unix if s.stats.good else self.t_run)
                      > s.cfg.silence_s) or bool(s.stats.error)  # fmt: skip
            if silent and not self.stopped[sid]:
                why = s.stats.error or f"no line for {s.cfg.silence_s:g} s"
                msg = f"warning: sensor {sid} ({s.cfg.device}) stopped: {why}"
                rec.event("sensor", msg, sensor=sid, program_s=p)
                self.disp.log(msg)
            elif not silent and self.stopped[sid]:
                rec.event("sensor", f"sensor {sid} sends again", sensor=sid, program_s=p)
                self.disp.log(f"sensor {sid} sends again")
            self.stopped[sid] = silent
            views.append(SensorView(sid, s.stats.rate_hz(), s.stats.last_values, s.cfg.names,
                                    self.bad[sid], self.samples[sid], silent))  # fmt: skip
        return views

    def abandon(self) -> None:
        """A start that failed (the chamber or a sensor did not open): close what opened and
        leave no recording behind (:meth:`Recorder.discard`)."""
        import contextlib

        for s in self.sensors:
            with contextlib.suppress(Exception):
                s.close()
        with contextlib.suppress(Exception):
            self.chamber.close()
        self.rec.discard()

    def finish(self) -> None:
        """Every way out: the safe set-point, the ports closed, their last lines recorded,
        the open parts closed, the stop event (how the run ended, the chamber's last
        set-point), the chamber closed.  Each step runs even when one before it failed."""
        rec = self.rec
        self.safe = _safe_stop(self.chamber, self.ch_cfg.safe_setpoint_c, rec, self.disp)
        try:
            for s in self.sensors:
                s.close()
            # the last lines that arrived before the ports closed
            for s in self.sensors:
                got, bads = s.drain()
                self.bad[s.cfg.id] += len(bads)
                rec.bad_lines(s.cfg.id, [(b.host_unix, b.index, b.reason, b.text) for b in bads])
                self._add_rows(s, got)
                self.samples[s.cfg.id] += len(got)
        finally:
            self.parts += rec.close_parts()
            left = self.safe if self.safe is not None else self.sp
            rec.event("stop", f"ended: {self.ended}" + (f" ({self.stop_reason})" if
                      self.stop_reason else ""), program_s=self.p, ended=self.ended,
                      reason=self.stop_reason, safe_setpoint_c=self.safe,
                      left_at_c=None if left != left else left,
                      dropped={s.cfg.id: s.stats.dropped for s in self.sensors})  # fmt: skip
            self.chamber.close()


def _open_recorder(
    cfg: StationConfig,
    t_prog: FloatArray,
    c_prog: FloatArray,
    out_dir: Path,
    profile_source: str,
    resume: bool,
    time_scale: float,
    disp: Display,
) -> tuple[Recorder, float, str]:
    """The recorder of ``out_dir``, the program time to start at [s] (0, or where a
    resumed recording ends) and how the previous run ended (``--resume``)."""
    end_s = float(t_prog[-1])
    p0 = _last_program_s(out_dir) if resume and out_dir.is_dir() else 0.0
    if resume and p0 >= end_s:
        raise ThermocalInputError(
            f"{out_dir}: the recording already reaches the program's end ({end_s:g} s)"
        )
    rec = Recorder(
        out_dir, cfg, (list(map(float, t_prog)), list(map(float, c_prog))),
        profile_source=profile_source, time_scale=time_scale, resume=resume,
    )  # fmt: skip
    n_events = len(rec.doc["events"])
    if rec.removed_tmp:
        rec.event("resume", "removed the part open at the interruption: " + ", ".join(
            rec.removed_tmp))  # fmt: skip
    previous = ""
    if resume:
        previous, alarm = previous_run(rec.doc["events"][:n_events])
        rec.event("resume", previous, program_s=p0)
        disp.log(("warning: " if alarm else "") + previous)
        rec.event("resume", f"program continues at {p0:.1f} s", program_s=p0)
        disp.log(f"resuming at program time {p0:.1f} s of {end_s:.1f} s")
    return rec, p0, previous


def previous_run(events: list[dict[str, Any]]) -> tuple[str, bool]:
    """How the last run of a recording ended and where it left the chamber, from its
    ``station.json`` events, and whether that needs the operator's attention.

    A run that ended writes a ``stop`` event (how it ended, the safe set-point written or
    not); a run killed (SIGKILL, a power cut, a crash of the interpreter) leaves none: then
    the chamber still holds the last set-point written: the last ``setpoint`` event [°C]
    (along a ramp, within :data:`SETPOINT_EVENT_C` of it).

    Parameters
    ----------
    events : list of dict
        The events of ``station.json``.

    Returns
    -------
    tuple of (str, bool)
        How it ended, and whether that needs the operator's attention.
    """
    last_sp: float | None = None
    stop: dict[str, Any] | None = None
    started = False
    for ev in events:
        kind = ev.get("kind")
        if kind == "start":
            started, stop = True, None
        elif kind in ("setpoint", "safe") and isinstance(ev.get("setpoint_c"), int | float):
            last_sp = float(ev["setpoint_c"])
        elif kind == "stop":
            stop = ev
    where = "unknown" if last_sp is None else f"{last_sp:.2f} °C"
    if stop is None:
        if not started:
            return "the last run never started", False
        return (f"the last run was killed (no stop record: SIGKILL, a power cut or a crash); "
                f"the chamber was left at {where}, the last set-point recorded"), True  # fmt: skip
    how = str(stop.get("ended", "?")) + (f" by {stop['reason']}" if stop.get("reason") else "")
    if stop.get("safe_setpoint_c") is None:
        return (f"the last run ended: {how}, WITHOUT the safe set-point; the chamber was "
                f"left at {where}, the last set-point recorded"), True  # fmt: skip
    return f"the last run ended: {how}; the chamber was left at {where} (the safe set-point)", False


def run_station(
    cfg: StationConfig,
    program: tuple[list[float], list[float]],
    out_dir: Path,
    *,
    profile_source: str = "",
    resume: bool = False,
    time_scale: float = 1.0,
    display: Display | None = None,
    chamber: Chamber | None = None,
    should_stop: Callable[[], bool | str] | None = None,
) -> RunResult:
    """Run the program on the station and record everything into ``out_dir``.

    Raises :class:`StationStopped` (after the safe set-point and every file are written)
    when the chamber has not answered for ``chamber.timeout_s``; a ``KeyboardInterrupt`` is
    re-raised after the same safe stop.  ``should_stop`` (signal handlers, tests, a GUI) ends
    the run early as an interrupt does, without the exception; a string it returns is the
    reason recorded (``"SIGHUP"``).  A :class:`LogDisplay` whose stderr is gone ends it too.
    With ``resume``, how the previous run ended and where it left the chamber is logged
    (``warning:`` when it was killed or left without its safe set-point).

    Parameters
    ----------
    cfg : StationConfig
        The station (:func:`thermocal.station.config.load_station`).
    program : tuple of (list of float, list of float)
        The chamber program: times [s] and set-points [°C], linear between points.
    out_dir : pathlib.Path
        The recording folder.
    profile_source : str
        How messages name the program (its file).
    resume : bool
        Continue a recording in ``out_dir`` where it stopped.
    time_scale : float
        Program seconds per wall-clock second (rehearsals with a simulated chamber).
    display : Display, optional
        Where the state is shown (default :class:`LogDisplay`).
    chamber : Chamber, optional
        The chamber driver (default from ``cfg``).
    should_stop : callable, optional
        Polled by the loop; true or a reason string ends the run as an interrupt does.

    Returns
    -------
    RunResult

    Raises
    ------
    ThermocalInputError
        A set-point outside the chamber's range or register, too many program points, a bad
        ``time_scale`` (before anything is written).
    """
    import numpy as np

    if not (math.isfinite(time_scale) and time_scale > 0):
        raise ThermocalInputError(f"--time-scale must be > 0, got {time_scale}")
    disp = display or LogDisplay()
    t_prog = np.asarray(program[0], dtype=np.float64)
    c_prog = np.asarray(program[1], dtype=np.float64)
    ch_cfg = cfg.chamber
    if t_prog.size > MAX_PROGRAM_POINTS:
        raise ThermocalInputError(
            f"{profile_source or 'the program'}: {t_prog.size} program points; the station "
            f"takes at most {MAX_PROGRAM_POINTS} (the set-point is interpolated linearly "
            "between points: a ramp needs only its two ends); resample the program"
        )
    chamber = chamber or make_chamber(ch_cfg, disp.log)
    for t, c in zip(t_prog, c_prog, strict=True):  # before anything is written
        why = ch_cfg.out_of_range(float(c))
        if why:
            raise ThermocalInputError(
                f"{profile_source or 'the program'}: set-point at program time {t:g} s: {why} "
                f"in {cfg.source}; fix the program or the chamber's range"
            )
    for c in (*c_prog, ch_cfg.safe_setpoint_c):  # every set-point must fit the register
        _check_setpoint(float(c), ch_cfg)
    rec, p0, previous = _open_recorder(cfg, t_prog, c_prog, out_dir, profile_source, resume,
                                       time_scale, disp)  # fmt: skip
    loop = _Loop(cfg, t_prog, c_prog, p0, time_scale, rec, chamber, disp)
    try:
        loop.start()
    except BaseException:  # nothing was written to the chamber: no safe stop to make
        loop.abandon()
        raise
    try:
        loop.play(should_stop)
    except KeyboardInterrupt:
        loop.ended = "interrupted"
        raise
    finally:
        try:
            loop.finish()
        finally:
            rec.release()
    return RunResult(out_dir, p0, loop.p, loop.parts, loop.samples, loop.bad, loop.ended,
                     loop.setpoints, loop.safe, list(rec.doc["events"]), loop.stop_reason,
                     previous)  # fmt: skip


def _check_setpoint(c: float, ch: ChamberConfig) -> None:
    """Refuse a set-point the register cannot hold: out of its 16-bit range (``encode``), or
    rounded by a coarse ``scale`` to a value further than ``tolerance_c`` from the program's
    (``scale = 100`` would write 60 °C as 100 °C)."""
    q = _quantize(c, ch.scale, ch.signed, ch.driver)
    if abs(q - c) > ch.tolerance_c:
        raise ThermocalInputError(
            f"set-point {c:g} °C would be written as {q:g} °C at scale {ch.scale:g} °C/count "
            f"(more than tolerance_c = {ch.tolerance_c:g} °C away); check [chamber] scale"
        )


def _quantize(c: float, scale: float, signed: bool, driver: str) -> float:
    """The set-point as the register holds it [°C] (unchanged for ``none``)."""
    if driver == "none":
        return c
    from thermocal.station.chamber import RegisterMap

    m = RegisterMap(0, 0, "holding", scale, signed)
    return m.decode(m.encode(c))


def _sensor_row(
    s: SerialSensor,
    host_unix: float,
    index: int,
    values: tuple[float, ...],
    rec: Recorder,
    anchors: dict[str, float],
    last_time: dict[str, float],
) -> dict[str, float]:
    """One line's row: the time rule of :mod:`thermocal.station.recorder`."""
    from thermocal import units

    cfg = s.cfg
    row = dict(zip(cfg.names, values, strict=True))
    host = rec.rel(host_unix)
    if cfg.time_name is not None:
        tu = units.normalize_time_unit(cfg.units[cfg.names.index(cfg.time_name)])
        t = row.pop(cfg.time_name) * units.TIME_UNITS[tu]
    elif cfg.rate_hz is not None:
        anchor = anchors.setdefault(cfg.id, host - index / cfg.rate_hz)
        t = anchor + index / cfg.rate_hz
    else:  # host time; lines of one read share it: 1 µs apart keeps time increasing
        t = max(host, last_time.get(cfg.id, -math.inf) + 1e-6)
        last_time[cfg.id] = t
    row["time"] = t
    row["host_time"] = host
    return row


def _signal_limits(cfg: Any) -> list[tuple[int, float, str]]:
    """``(field index, limit in the field's own unit, unit)`` of each rate or acceleration
    field: :data:`thermocal.recording.PLAUSIBLE_SIGNAL` (the limit every command applies
    to a recording) converted to the field's unit."""
    import numpy as np

    from thermocal import units
    from thermocal.errors import UnitError
    from thermocal.recording import PLAUSIBLE_SIGNAL

    out = []
    for i, u in enumerate(cfg.units):
        try:
            kind = units.signal_kind(u)
        except UnitError:
            continue
        if kind in PLAUSIBLE_SIGNAL:
            one = float(units.to_canonical(np.array([1.0]), u, finite=False)[0][0])
            out.append((i, PLAUSIBLE_SIGNAL[kind] / one, u))
    return out


def _beyond_any_sensor(values: tuple[float, ...], limits: list[tuple[int, float, str]]) -> str:
    """Why a line's values cannot come from a sensor (``""``: they can): a rate or an
    acceleration beyond :data:`thermocal.recording.PLAUSIBLE_SIGNAL` (``1e300 deg/s``)."""
    for i, lim, u in limits:
        if abs(values[i]) > lim:
            return f"beyond any sensor: {values[i]:g} {u} (|value| ≤ {lim:g} {u})"
    return ""


def _safe_stop(chamber: Chamber, safe_c: float, rec: Recorder, disp: Display) -> float | None:
    """Write the safe set-point (twice tried); record and say whether it was written."""
    for _attempt in range(2):
        try:
            chamber.write_setpoint(safe_c)
        except ChamberError as exc:
            err = str(exc)
            continue
        except Exception as exc:  # never let the safe stop hide the original error
            err = f"{type(exc).__name__}: {exc}"
            continue
        rec.event("safe", f"safe set-point {safe_c:g} °C written", setpoint_c=safe_c)
        disp.log(f"safe set-point {safe_c:g} °C written")
        return safe_c
    msg = f"warning: could not write the safe set-point {safe_c:g} °C: {err}; SET IT BY HAND"
    rec.event("safe", msg)
    disp.log(msg)
    return None
