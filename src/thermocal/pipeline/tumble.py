"""The file edge of the tumble test (``thermocal tumble``): read the recording, take the
head's angle from its encoder column (or from time at a constant turn rate), reduce a
dividing head's stations to their means (:mod:`thermocal.tumble.stations`) and fit the
harmonics and the model coefficients (:mod:`thermocal.tumble.analysis`).  The maths read no
file; files come in here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import units
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.readers import read_recording
from thermocal.readers.options import CHAMBER_COLUMN, ReadOptions
from thermocal.tumble.analysis import (
    HARMONICS,
    HarmonicFit,
    TumbleCoefficients,
    coefficients_from_harmonics,
    fit_harmonics,
    significant,
    to_dict,
)
from thermocal.tumble.stations import (
    MIN_STATION_S,
    SETTLE_S,
    STATION_SHARE,
    TOLERANCE_DEG,
    Station,
    find_stations,
)

K_PP_NOTE = (
    "K_pp (pendulous-axis square term) taken as negligible: one tumble about the output "
    "axis gives K2 - K_pp and K0 + K_pp"
)
"""Said with every result: what a tumble about the output axis cannot separate."""


@dataclass(frozen=True)
class TumbleOptions:
    """How a tumble recording is read and its angles found.

    Attributes
    ----------
    accel : str
        The accelerometer's output column.
    accel_unit : str or None
        Its unit (None: the file's; asked for when the file does not say).
    angle_column : str or None
        The head's encoder column (a dividing head's stations, or a continuous tumble).
    angle_unit : str or None
        Its unit (None: the file's, else ° with a warning).
    turn_rate_dps : float or None
        A continuous tumble at this constant rate [°/s], the angle from time.
    start_angle_deg : float
        With ``turn_rate_dps``: the angle at the first sample [°].
    harmonics : int
        Harmonics fitted (2: K0, K1, δ_o, K2, K_ip; 3 adds K3).
    settle_s, min_station_s, angle_tolerance_deg : float
        The station criteria (:func:`thermocal.tumble.stations.find_stations`).
    time, time_unit : str or None
        The time column and its unit.
    read : ReadOptions or None
        How the file is read: a text log's layout, a flight log's or bag's topic and stamps,
        a chamber's own log joined by time (``chamber_log``).
    temps : str or None
        The temperature column the test ran at (the recording's own, or ``"chamber"``: the
        joined chamber log's); None: the chamber log's when ``read`` joins one, else none.
    """

    accel: str = "accel"
    accel_unit: str | None = None
    angle_column: str | None = None
    angle_unit: str | None = None
    turn_rate_dps: float | None = None
    start_angle_deg: float = 0.0
    harmonics: int = HARMONICS
    settle_s: float = SETTLE_S
    min_station_s: float = MIN_STATION_S
    angle_tolerance_deg: float = TOLERANCE_DEG
    time: str | None = None
    time_unit: str | None = None
    read: ReadOptions | None = None
    temps: str | None = None

    def __post_init__(self) -> None:
        if (self.angle_column is None) == (self.turn_rate_dps is None):
            raise ThermocalInputError.naming(
                "the tumble's angles: give the head's encoder column with {angle_column}, or "
                "the constant rate of a continuous tumble with {turn_rate_dps} (one of them)",
                "angle_column",
                "turn_rate_dps",
            )
        r = self.turn_rate_dps
        if r is not None and not (math.isfinite(r) and r != 0):
            raise ParameterError("turn_rate_dps", f"{{name}} must be a non-zero number, got {r!r}")
        if not math.isfinite(self.start_angle_deg):
            raise ParameterError("start_angle_deg", "{name} must be a finite number")
        if not 2 <= self.harmonics <= 4:
            raise ParameterError(
                "harmonics", f"{{name}} must be 2 to 4 (K2 is a second harmonic), got "
                f"{self.harmonics}"
            )  # fmt: skip


@dataclass(frozen=True)
class TumbleResult:
    """A tumble test: the points fitted, the harmonics and the model coefficients.

    Attributes
    ----------
    file : str
        The recording.
    mode : str
        ``stations`` (a dividing head's station means) or ``continuous`` (every sample).
    stations : tuple of Station
        The stations (empty for a continuous tumble).
    dropped : tuple of (float, float)
        Steady stretches too short to be stations [s].
    fit : HarmonicFit
        The harmonics.
    coefficients : TumbleCoefficients
        K0, K1, δ_o, K2, K_ip (K3).
    output_unit : str
        The accelerometer output's unit.
    settle_s : float
        Left out at each station's start [s].
    temperature : TumbleTemperature or None
        The temperature the test ran at (None: no temperature column).
    """

    file: str
    mode: str
    stations: tuple[Station, ...]
    dropped: tuple[tuple[float, float], ...]
    fit: HarmonicFit
    coefficients: TumbleCoefficients
    output_unit: str
    settle_s: float
    temperature: TumbleTemperature | None = None

    def coefficient_units(self) -> dict[str, str]:
        """Each coefficient's unit: the output's unit per g to its order (δ_o in rad)."""
        u = self.output_unit
        out = {"k0": u, "k1": f"{u}/g", "delta_o": "rad", "k2": f"{u}/g^2", "k_ip": f"{u}/g^2"}
        if "k3" in self.coefficients.names:
            out["k3"] = f"{u}/g^3"
        return out

    def to_dict(self, spell: Callable[[str], str] | None = None) -> dict[str, Any]:
        """The result as a JSON object (keys in the JSON reference).

        Parameters
        ----------
        spell : callable, optional
            How parameters are named in messages (unused: kept for the commands' contract).

        Returns
        -------
        dict
        """
        c = self.coefficients
        sig = significant(c.values.tolist(), c.sigmas.tolist())
        return {
            "file": self.file,
            "mode": self.mode,
            "output_unit": self.output_unit,
            "units": self.coefficient_units(),
            **to_dict(self.fit, c),
            "significant": dict(zip(c.names, sig, strict=True)),
            "settle_s": self.settle_s,
            "temperature": None if self.temperature is None else self.temperature.to_dict(),
            "stations": [
                _station_dict(s, self.temperature, k) for k, s in enumerate(self.stations)
            ],
            "dropped": [list(d) for d in self.dropped],
            "note": K_PP_NOTE,
        }


def _station_dict(s: Station, temp: TumbleTemperature | None, k: int) -> dict[str, Any]:
    """One station as JSON (its mean temperature with a temperature column)."""
    return {"start_s": s.start_s, "end_s": s.end_s, "angle_deg": s.angle_deg, "mean": s.mean,
            "se": s.se, "n": s.n,
            "temp_c": None if temp is None else temp.stations_c[k]}  # fmt: skip


@dataclass(frozen=True)
class TumbleTemperature:
    """The temperature a tumble test ran at.

    Attributes
    ----------
    column : str
        The temperature column (``chamber``: a chamber's own log joined by time).
    mean_c, min_c, max_c : float
        Its mean, least and greatest value over the record [°C].
    stations_c : tuple of float
        Each station's mean over its kept samples [°C] (empty for a continuous tumble).
    """

    column: str
    mean_c: float
    min_c: float
    max_c: float
    stations_c: tuple[float, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The JSON object ``temperature`` (the stations' means go with each station)."""
        return {"column": self.column, "mean_c": self.mean_c, "min_c": self.min_c,
                "max_c": self.max_c}  # fmt: skip


def _temp_column(o: TumbleOptions) -> str | None:
    """The temperature column asked for: ``temps``, else a joined chamber log's."""
    if o.temps is not None:
        return o.temps
    return CHAMBER_COLUMN if o.read is not None and o.read.chamber_log is not None else None


def _temperature(rec: Any, col: str | None, stations: list[Station]) -> TumbleTemperature | None:
    """The record's temperature (mean, least, greatest [°C]) and each station's mean over
    the samples its mean took (``start_s`` ≤ t ≤ ``end_s``)."""
    if col is None:
        return None
    t = np.asarray(rec.time_s, float)
    temp = np.asarray(rec.temperature_c(col), float)
    per = tuple(float(np.mean(temp[(t >= s.start_s) & (t <= s.end_s)])) for s in stations)
    return TumbleTemperature(col, float(np.mean(temp)), float(np.min(temp)),
                             float(np.max(temp)), per)  # fmt: skip


def _read(path: Path, o: TumbleOptions) -> tuple[Any, np.ndarray, str]:
    """The recording, its accelerometer output and that output's unit."""
    temp = _temp_column(o)
    read = (o.read or ReadOptions()).replace(
        time=o.time, time_unit=o.time_unit, signals=(o.accel,), signal_unit=o.accel_unit,
        **({"temperatures": (temp,)} if temp is not None else {}),
    )  # fmt: skip
    own_unit = {o.accel: "accel_unit"}  # what reading and the checks ask for its unit by
    rec = read_recording(path, read, ask_units=own_unit)
    rec.validate(required=[o.accel, *([temp] if temp is not None else [])],
                 unit_parameters=own_unit)  # fmt: skip
    unit = units.normalize_signal_unit(rec.units[o.accel])
    if units.signal_kind(unit) == "rate":
        raise ThermocalInputError.naming(
            f"{path}: the accelerometer column {o.accel!r} is in {unit}, a rate; name the "
            "accelerometer's column with {accel} or its unit with {accel_unit}",
            "accel",
            "accel_unit",
        )
    if rec.time_s.size < 3:
        raise ThermocalInputError(f"{path}: too few samples ({rec.time_s.size})")
    return rec, np.asarray(rec.columns[o.accel], float), unit


def _angles(rec: Any, path: Path, o: TumbleOptions) -> np.ndarray:
    """The head's angle at each sample [°]: the encoder column (its unit resolved) or the
    constant turn rate from the first sample."""
    t = np.asarray(rec.time_s, float)
    if o.turn_rate_dps is not None:
        return np.asarray(o.start_angle_deg + o.turn_rate_dps * (t - t[0]))
    col = str(o.angle_column)
    if col not in rec.columns:
        raise ThermocalInputError.naming(
            f"{path}: no column {col!r} for {{angle_column}}; columns: "
            f"{', '.join(sorted(rec.columns))}",
            "angle_column",
        )
    resolved = units.resolve_unit(
        col, "angle", option=o.angle_unit, metadata=rec.units.get(col) or None, where=str(path)
    )
    a = units.angle_to_deg(np.asarray(rec.columns[col], float), resolved.unit)
    bad = ~np.isfinite(a)
    if bad.any():
        k = int(np.argmax(bad))
        raise ThermocalInputError.naming(
            f"{path}: {int(bad.sum())} of the {a.size} values of the angle column {col!r} are "
            f"not numbers (the first at t = {t[k]:.6g} s); mend or cut the record, or give "
            "the continuous tumble's {turn_rate_dps} instead",
            "turn_rate_dps",
        )
    return a


def tumble_file(path: Path, opts: TumbleOptions) -> TumbleResult:
    """The tumble test of one recording.

    Parameters
    ----------
    path : Path
        The recording (any registered format).
    opts : TumbleOptions
        How it is read and its angles found.

    Returns
    -------
    TumbleResult

    Raises
    ------
    ThermocalInputError
        A file, column or unit that cannot be read; NaN angles; angles that cannot
        separate the second harmonic (a :class:`~thermocal.errors.DesignError`).
    """
    path = Path(path)
    rec, y, unit = _read(path, opts)
    theta = _angles(rec, path, opts)
    stations: list[Station] = []
    dropped: list[tuple[float, float]] = []
    mode = "continuous"
    if opts.turn_rate_dps is None:
        stations, dropped = find_stations(
            rec.time_s,
            theta,
            y,
            tolerance_deg=opts.angle_tolerance_deg,
            min_station_s=opts.min_station_s,
            settle_s=opts.settle_s,
        )
        if sum(s.n for s in stations) >= STATION_SHARE * y.size:
            mode = "stations"
        else:
            stations = []
    if mode == "stations":
        se = np.array([s.se for s in stations])
        fit = fit_harmonics(
            [s.angle_deg for s in stations],
            [s.mean for s in stations],
            se if (se > 0).all() else None,
            opts.harmonics,
        )
    else:
        fit = fit_harmonics(theta, y, None, opts.harmonics)
    return TumbleResult(
        str(path),
        mode,
        tuple(stations),
        tuple(dropped),
        fit,
        coefficients_from_harmonics(fit),
        unit,
        opts.settle_s,
        _temperature(rec, _temp_column(opts), stations),
    )
