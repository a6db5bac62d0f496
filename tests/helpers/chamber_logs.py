"""Chamber logs written the way chambers and data loggers write them, and sensor recordings
beside them, from one known chamber-air history (the truth the tests compare with)."""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable
from pathlib import Path

import numpy as np
import numpy.typing as npt

KNOTS_S = (0.0, 1800.0, 5400.0, 9000.0, 12600.0, 16200.0, 20000.0, 30000.0)
KNOTS_C = (20.0, 20.0, 60.0, 60.0, -10.0, -10.0, 25.0, 25.0)
"""The chamber air [°C] on the chamber's clock [s from its first row]: holds and ramps whose
corners fall on whole minutes."""


def air_c(tau: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The chamber air [°C] at the chamber clock's ``tau`` [s]."""
    return np.interp(np.asarray(tau, dtype=np.float64), KNOTS_S, KNOTS_C)


def from_c(unit: str) -> Callable[[npt.NDArray[np.float64]], npt.NDArray[np.float64]]:
    """°C → the unit (°F = °C·1.8 + 32, K = °C + 273.15), written independently of the
    reader's table."""
    return {
        "degC": lambda c: c,
        "degF": lambda c: c * 1.8 + 32.0,
        "K": lambda c: c + 273.15,
    }[unit]


def clock_text(seconds: float, style: str) -> str:
    """A time of day as a chamber writes it: ``hh:mm``, ``hh:mm:ss`` or 12 h ``h:mm:ss AM``."""
    s = round(seconds) % 86400
    h, m, sec = s // 3600, (s % 3600) // 60, s % 60
    if style == "hh:mm":
        return f"{h:02d}:{m:02d}"
    if style == "hh:mm:ss":
        return f"{h:02d}:{m:02d}:{sec:02d}"
    ampm = "AM" if h < 12 else "PM"
    return f"{(h % 12) or 12}:{m:02d}:{sec:02d} {ampm}"


def write_log(
    path: Path,
    *,
    start: dt.datetime = dt.datetime(2026, 3, 14, 9, 0, 0),
    period_s: float = 60.0,
    span_s: float = 20000.0,
    style: str = "hh:mm",
    unit: str = "degF",
    header: str = "Time,Chamber PV [{u}],Set Point [{u}]",
    date: str | None = None,
    decimals: int = 2,
) -> Path:
    """A chamber log of :func:`air_c` from ``start`` every ``period_s`` for ``span_s``.

    ``date``: None (no date), ``"header"`` (``Date: YYYY-MM-DD`` above the table),
    ``"dmy"`` / ``"mdy"`` / ``"iso"`` (a Date column before the clock).
    """
    sym = {"degF": "°F", "degC": "°C", "K": "K"}[unit]
    conv = from_c(unit)
    lines = []
    if date == "header":
        lines.append(f"Date: {start:%Y-%m-%d}")
    head = header.format(u=sym)
    lines.append(("Date," + head) if date in ("dmy", "mdy", "iso") else head)
    for tau in np.arange(0.0, span_s, period_s):
        when = start + dt.timedelta(seconds=float(tau))
        clock = clock_text(when.hour * 3600 + when.minute * 60 + when.second, style)
        value = float(conv(air_c(tau)))
        row = f"{clock},{value:.{decimals}f},{value:.1f}"
        if date in ("dmy", "mdy", "iso"):
            fmt = {"dmy": "%d/%m/%Y", "mdy": "%m/%d/%Y", "iso": "%Y-%m-%d"}[date]
            row = f"{when.strftime(fmt)},{row}"
        lines.append(row)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def write_recording(
    path: Path,
    *,
    offset_s: float,
    drift_ppm: float = 0.0,
    span_s: float = 14000.0,
    t0: float = 0.0,
    seed: int = 0,
    noise_c: float = 0.05,
) -> tuple[Path, npt.NDArray[np.float64]]:
    """A 1 Hz recording (``time``, ``gx`` [deg/h], ``T`` [°C]) whose first sample falls
    ``offset_s`` after the log's first row, the log's clock gaining ``drift_ppm``; its
    sensor temperature is the air plus noise, its gyro a line in it.  Returns the file and
    the true chamber air at each sample."""
    rng = np.random.default_rng(seed)
    u = np.arange(0.0, span_s, 1.0)
    truth = air_c(offset_s + (1.0 + drift_ppm * 1e-6) * u)
    temp = truth + noise_c * rng.standard_normal(u.size)
    gx = 5.0 + 0.02 * (truth - 20.0) + 0.01 * rng.standard_normal(u.size)
    rows = ["time,gx,T"] + [
        f"{t0 + a:.3f},{b:.6f},{c:.5f}" for a, b, c in zip(u, gx, temp, strict=True)
    ]
    path.write_text("\n".join(rows) + "\n")
    return path, truth
