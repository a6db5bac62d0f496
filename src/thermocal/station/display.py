"""The live display of a station run on a terminal (rich): program step, set-point,
chamber temperature, each sensor's rate, last temperature and bad-line count, samples
recorded, parts closed and time left.  Not on a terminal: :class:`~thermocal.station.run.
LogDisplay` (a line per step and per event)."""

from __future__ import annotations

import math
from typing import Any

from thermocal.station.run import StationState

REFRESH_HZ = 4.0


def _f(v: float, fmt: str = ".2f") -> str:
    return "—" if not math.isfinite(v) else format(v, fmt)


def _hms(s: float) -> str:
    s = round(s)
    return f"{s // 3600:d}:{s % 3600 // 60:02d}:{s % 60:02d}"


def render(state: StationState) -> Any:
    """The display as a rich renderable.

    Parameters
    ----------
    state : StationState
        The station's state.

    Returns
    -------
    rich renderable
    """
    from rich.console import Group
    from rich.table import Table

    head = Table.grid(padding=(0, 2))
    head.add_row(
        f"step {state.step}/{state.n_steps}",
        f"program {_f(state.program_s, '.0f')} / {_f(state.end_s, '.0f')} s",
        f"set-point {_f(state.setpoint_c)} °C",
        f"chamber {_f(state.chamber_c)} °C" + ("" if state.chamber_ok else " (NO ANSWER)"),
        f"time left {_hms(state.time_left_s)}",
    )
    tab = Table("sensor", "rate [Hz]", "last line", "samples", "bad lines", "state")
    for s in state.sensors:
        last = ", ".join(f"{n}={v:.4g}" for n, v in zip(s.names, s.last, strict=False))
        tab.add_row(s.id, _f(s.rate_hz, ".1f"), last or "—", f"{s.samples:,}", f"{s.bad:,}",
                    "STOPPED" if s.stopped else "ok")  # fmt: skip
    foot = f"samples recorded {state.samples:,} · parts closed {state.parts}"
    return Group(head, tab, foot)


class RichDisplay:
    """A rich ``Live`` on stderr; messages print above it."""

    def __init__(self) -> None:
        from rich.console import Console
        from rich.live import Live

        self.console = Console(stderr=True)
        self.live = Live(console=self.console, refresh_per_second=REFRESH_HZ, transient=False)
        self.live.start()
        self._last = -1.0e9
        self._open = True
        self.broken = ""
        """Why the terminal is gone (a hang-up, a closed pipe); the loop then stops safely."""

    def _gone(self, exc: BaseException) -> None:
        from thermocal.station.run import mute_stderr

        self.broken = f"stderr closed ({type(exc).__name__})"
        mute_stderr()

    def update(self, state: StationState) -> None:
        """Redraw the live display with ``state``.

        Parameters
        ----------
        state : StationState
            The station's state.
        """
        import time

        now = time.monotonic()  # the loop turns at 50 Hz; the display needs 4
        if now - self._last >= 1.0 / REFRESH_HZ and not self.broken:
            self._last = now
            try:
                self.live.update(render(state))
            except (OSError, ValueError) as exc:
                self._gone(exc)

    def log(self, message: str) -> None:
        """Print ``message`` above the live display.

        Parameters
        ----------
        message : str
            The text.
        """
        if self.broken:
            return
        try:
            self.console.print(message, markup=False, highlight=False)
        except (OSError, ValueError) as exc:
            self._gone(exc)

    def close(self) -> None:
        """Stop the live display."""
        if self._open:
            self._open = False
            try:
                self.live.stop()
            except (OSError, ValueError) as exc:
                self._gone(exc)
