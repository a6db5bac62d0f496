"""The file edge of the rate-table test (``thermocal ratetable``): read the recordings, find
or take the plateaus (:mod:`thermocal.ratetable.plateaus`), group them by temperature, and
compute the scale-factor figures of each ladder and the temperature coefficient
(:mod:`thermocal.ratetable.analysis`).  The maths read no file; files come in here.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import units
from thermocal.errors import DesignError, ParameterError, ThermocalInputError, ThermocalWarning
from thermocal.ratetable.analysis import (
    SMALL_FRACTION,
    Figure,
    LadderResult,
    RateRow,
    TemperatureCoefficient,
    analyse_ladder,
    temperature_coefficient,
)
from thermocal.ratetable.plateaus import (
    MIN_PLATEAU_S,
    SETTLE_S,
    WINDOW_S,
    Detection,
    Plateau,
    match_rates,
    plateaus_from_output,
    plateaus_from_rate,
    plateaus_from_schedule,
)
from thermocal.ratetable.timing import LadderTiming, plateaus_from_dwell
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions

TEMP_GAP_C = 3.0
"""Plateaus of one file whose temperatures differ by more than this [°C] are two ladders."""
CORRELATED_RATIO = 2.0
"""Median ratio of the block-means to the white-noise standard error above which the
plateaus' noise is said to be correlated (a warning)."""
MAX_DEVIATION_FS = 0.05
"""A plateau further off the least-squares line than this fraction of full scale is a rate
given wrong (no gyro is 5 % nonlinear), not a nonlinearity."""
K_UNIT_RANGE = (0.5, 2.0)
"""An output in a rate unit has a scale factor near 1: outside this range the rates or the
output's unit are wrong."""


@dataclass(frozen=True)
class RateTableOptions:
    """How the recordings of a rate-table test are read and their plateaus found.

    Attributes
    ----------
    gyro : str
        The gyro's output column.
    gyro_unit : str or None
        Its unit (None: the file's; a rate unit gives a dimensionless scale factor, counts
        or volts a scale factor in counts or volts per °/s).
    rate_column : str or None
        The table's rate column [°/s] (plateaus found where it holds still).
    rates_dps : tuple of float or None
        The applied rates [°/s], one per plateau in time order.
    temps : str or None
        Temperature column [°C].
    settle_s, min_plateau_s, window_s : float
        Settling dropped at each plateau's start, shortest plateau, the output detector's
        window [s].
    small_fraction : float
        Small rates of the threshold test, as a fraction of full scale.
    temp_gap_c : float
        Plateaus of one file further apart in temperature are separate ladders [°C].
    time, time_unit : str or None
        The time column and its unit.
    read : ReadOptions or None
        How a text log is read.
    one_direction : bool
        Accept a ladder in one direction only (no asymmetry); refused otherwise.
    tolerance_dps : float
        Largest change of the table's rate column between two samples of one plateau [°/s]
        (:func:`thermocal.ratetable.plateaus.plateaus_from_rate`).
    dwell_s : tuple of float or None
        How long the table held each of ``rates_dps`` [s] (one for all, or one a rate): the
        plateaus placed by the program's timing (:mod:`thermocal.ratetable.timing`).
    start_s : float or None
        With ``dwell_s``: start of the first plateau [s, the record's time] (None: found).
    accel_dps2 : float or None
        With ``dwell_s``: the table's acceleration between rates [°/s²] (None: found).
    """

    gyro: str = "gyro"
    gyro_unit: str | None = None
    rate_column: str | None = None
    rates_dps: tuple[float, ...] | None = None
    temps: str | None = None
    settle_s: float = SETTLE_S
    min_plateau_s: float = MIN_PLATEAU_S
    window_s: float = WINDOW_S
    small_fraction: float = SMALL_FRACTION
    temp_gap_c: float = TEMP_GAP_C
    time: str | None = None
    time_unit: str | None = None
    read: ReadOptions | None = None
    one_direction: bool = False
    """Accept a ladder run in one direction only (no asymmetry)."""
    tolerance_dps: float = 1e-3
    """Largest change of the table's rate column between two samples of a plateau [°/s]."""
    dwell_s: tuple[float, ...] | None = None
    """How long each rate is held [s]: plateaus from the program's timing."""
    start_s: float | None = None
    """Start of the first plateau of a timed ladder [s] (None: found from the output)."""
    accel_dps2: float | None = None
    """The table's acceleration between the rates of a timed ladder [°/s²] (None: found)."""

    def __post_init__(self) -> None:
        for name in ("settle_s", "min_plateau_s", "window_s", "temp_gap_c", "tolerance_dps"):
            v = getattr(self, name)
            ok = math.isfinite(v) and (v >= 0 if name == "settle_s" else v > 0)
            if not ok:
                raise ParameterError(name, f"{{name}} must be a positive number, got {v!r}")
        if self.rates_dps is not None and not all(math.isfinite(r) for r in self.rates_dps):
            raise ParameterError("rates_dps", "{name}: every rate must be a finite number")
        if self.dwell_s is not None and not all(math.isfinite(d) and d > 0 for d in self.dwell_s):
            raise ParameterError("dwell_s", "{name}: every dwell must be a positive number [s]")
        if self.accel_dps2 is not None and not (
            math.isfinite(self.accel_dps2) and self.accel_dps2 > 0
        ):
            raise ParameterError("accel_dps2", "{name} must be a positive number [°/s²]")
        if self.start_s is not None and not math.isfinite(self.start_s):
            raise ParameterError("start_s", "{name} must be a finite time [s]")


@dataclass(frozen=True)
class RateTableResult:
    """A rate-table test: each ladder's figures and the temperature coefficient.

    Attributes
    ----------
    files : tuple of str
        The recordings.
    detections : tuple of Detection
        The plateaus of each file.
    ladders : tuple of LadderResult
        One per temperature (a single one without temperatures).
    temperature_coefficient : TemperatureCoefficient or None
        With ladders at two or more temperatures.
    output_unit : str
        The gyro output's unit (``deg/s`` for any rate unit, converted).
    timings : tuple of (LadderTiming or None)
        Per file, where a timed ladder (rates and dwells) was placed; None otherwise.
    """

    files: tuple[str, ...]
    detections: tuple[Detection, ...]
    ladders: tuple[LadderResult, ...]
    temperature_coefficient: TemperatureCoefficient | None
    output_unit: str
    timings: tuple[LadderTiming | None, ...] = ()

    @property
    def scale_factor_unit(self) -> str:
        """The scale factor's unit: ``1`` (output in °/s) or ``UNIT/(deg/s)``."""
        return "1" if self.output_unit == "deg/s" else f"{self.output_unit}/(deg/s)"

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
        tc = self.temperature_coefficient
        timings = self.timings or (None,) * len(self.files)
        return {
            "files": list(self.files),
            "output_unit": self.output_unit,
            "scale_factor_unit": self.scale_factor_unit,
            "plateaus": [
                {
                    "file": f,
                    "source": d.source,
                    "settle_s": d.settle_s,
                    "dropped": [list(x) for x in d.dropped],
                    "plateaus": [_plateau_dict(p) for p in d.plateaus],
                    "ladder_start_s": tm.start_s if tm is not None else None,
                    "accel_dps2": tm.accel_dps2 if tm is not None else None,
                    "found": list(tm.found) if tm is not None else None,
                }
                for f, d, tm in zip(self.files, self.detections, timings, strict=True)
            ],
            "ladders": [ld.to_dict() for ld in self.ladders],
            "temperature_coefficient": tc.to_dict() if tc is not None else None,
        }


def _plateau_dict(p: Plateau) -> dict[str, Any]:
    """One plateau as JSON."""
    return {
        "start_s": p.start_s,
        "end_s": p.end_s,
        "rate_dps": p.rate_dps,
        "mean": p.mean,
        "sd": p.sd,
        "n": p.n,
        "temperature_c": p.temperature_c,
    }


def read_schedule(path: Path) -> tuple[tuple[float, ...], ...]:
    """A schedule file: CSV rows ``start_s,end_s,rate_dps`` (the plateaus in the record's
    time), or ``rate_dps,dwell_s`` (the table's program: each rate and how long it is held,
    placed by :func:`thermocal.ratetable.timing.plateaus_from_dwell`); a header line allowed.

    Parameters
    ----------
    path : Path
        The file.

    Returns
    -------
    tuple of tuple of float
        The rows, all of three or all of two numbers.

    Raises
    ------
    ThermocalInputError
        A file that cannot be read, a row that is not two or three numbers, or rows of both.
    """
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise ThermocalInputError(f"{path}: cannot read the schedule ({exc})") from None
    rows: list[tuple[float, ...]] = []
    for k, line in enumerate(text.splitlines(), start=1):
        cells = [c.strip() for c in line.split(",")]
        if not line.strip() or (k == 1 and not _numbers(cells)):
            continue
        vals = _numbers(cells)
        width = len(rows[0]) if rows else None
        if vals is None or len(vals) not in (2, 3) or (width and len(vals) != width):
            raise ThermocalInputError(
                f"{path}: line {k}: a schedule row is start_s,end_s,rate_dps (or, every row, "
                f"rate_dps,dwell_s), got {line!r}"
            )
        rows.append(tuple(vals))
    if not rows:
        raise ThermocalInputError(
            f"{path}: the schedule has no row start_s,end_s,rate_dps or rate_dps,dwell_s"
        )
    if len(rows[0]) == 2 and len(rows) < 2:
        raise ThermocalInputError.naming(
            f"{path}: a program of rate_dps,dwell_s rows in {{schedule}} needs at least 2 rates",
            "schedule",
        )
    return tuple(rows)


def _numbers(cells: Sequence[str]) -> list[float] | None:
    """The cells as finite numbers, or None."""
    try:
        vals = [float(c) for c in cells]
    except ValueError:
        return None
    return vals if all(math.isfinite(v) for v in vals) else None


def _read(path: Path, opts: RateTableOptions) -> tuple[Any, np.ndarray, str, np.ndarray | None]:
    """The recording, its output (rate units converted to °/s), that unit, its temperature."""
    read = (opts.read or ReadOptions()).replace(
        time=opts.time,
        time_unit=opts.time_unit,
        signals=(opts.gyro,),
        signal_unit=opts.gyro_unit,
        temperatures=(opts.temps,) if opts.temps else None,
    )
    own_unit = {opts.gyro: "gyro_unit"}  # what reading and the checks ask for its unit by
    rec = read_recording(path, read, ask_units=own_unit)
    rec.validate(required=[opts.gyro, *([opts.temps] if opts.temps else [])],
                 unit_parameters=own_unit)  # fmt: skip
    y = np.asarray(rec.columns[opts.gyro], float)
    unit = units.normalize_signal_unit(rec.units[opts.gyro])  # resolved, or asked for
    kind = units.signal_kind(unit)
    if kind == "accel":
        raise ThermocalInputError.naming(
            f"{path}: the gyro column {opts.gyro!r} is in {unit}, an acceleration; name the "
            "gyro's column with {gyro} or its unit with {gyro_unit}",
            "gyro",
            "gyro_unit",
        )
    if kind == "rate":
        y, unit = units.convert(y, unit, "deg/s", opts.gyro), "deg/s"
    temp = rec.temperature_c(opts.temps) if opts.temps else None
    return rec, y, unit, temp


def _table_rate(rec: Any, path: Path, col: str) -> np.ndarray:
    """The table's rate column in °/s (its stated rate unit converted)."""
    if col not in rec.columns:
        raise ThermocalInputError.naming(
            f"{path}: no column {col!r} for {{rate_column}}; columns: "
            f"{', '.join(sorted(rec.columns))}",
            "rate_column",
        )
    r = np.asarray(rec.columns[col], float)
    u = rec.units.get(col) or ""
    if u and u not in ("deg/s",):
        try:
            if units.signal_kind(u) == "rate":
                return units.convert(r, u, "deg/s", col)
        except ThermocalInputError:
            pass
    return r


def _detect(
    path: Path,
    rec: Any,
    y: np.ndarray,
    temp: np.ndarray | None,
    opts: RateTableOptions,
    schedule: Sequence[tuple[float, ...]] | None,
) -> tuple[Detection, LadderTiming | None]:
    """The plateaus of one file: from a program's timing, the schedule, the rate column, or
    the output."""
    t = rec.time_s
    settle = opts.settle_s
    if schedule is not None and len(schedule[0]) == 2:
        rates, dwells = [r[0] for r in schedule], [r[1] for r in schedule]
    else:
        rates, dwells = list(opts.rates_dps or ()), list(opts.dwell_s or ())
    if dwells:
        try:
            return plateaus_from_dwell(
                t,
                y,
                rates,
                dwells * len(rates) if len(dwells) == 1 else dwells,
                accel_dps2=opts.accel_dps2,
                start_s=opts.start_s,
                temperature_c=temp,
                settle_s=settle,
            )
        except DesignError as exc:
            raise DesignError.around(exc, f"{path}: ") from None
    if schedule is not None:
        rows = [(a, b, r) for a, b, r in schedule]
        return plateaus_from_schedule(t, y, rows, temperature_c=temp, settle_s=settle), None
    if opts.rate_column is not None:
        d = plateaus_from_rate(
            t,
            y,
            _table_rate(rec, path, opts.rate_column),
            min_plateau_s=opts.min_plateau_s,
            temperature_c=temp,
            settle_s=settle,
            tolerance_dps=opts.tolerance_dps,
        )
        if opts.rates_dps is not None:
            _check_given(d, opts.rates_dps, path)
        return d, None
    d = plateaus_from_output(
        t,
        y,
        min_plateau_s=opts.min_plateau_s,
        window_s=opts.window_s,
        temperature_c=temp,
        settle_s=settle,
    )
    if opts.rates_dps is None:
        raise DesignError.naming(
            f"{path}: {len(d.plateaus)} plateaus found in the output, but their rates are not "
            "known; give them with {rates_dps} (°/s, in the order the table ran them), or the "
            "table's rate column with {rate_column}, or a {schedule}",
            "rates_dps",
            "rate_column",
            "schedule",
        )
    try:
        return match_rates(d, opts.rates_dps), None
    except DesignError as exc:
        raise DesignError.around(exc, f"{path}: ") from None


def _check_timed(opts: RateTableOptions, sched: Sequence[tuple[float, ...]] | None) -> None:
    """A dwell goes with the rates and without the rate column; a start or an acceleration
    only with a dwell (or a schedule of ``rate_dps,dwell_s`` rows)."""
    timed = opts.dwell_s is not None or (sched is not None and len(sched[0]) == 2)
    if opts.dwell_s is not None and (opts.rates_dps is None or opts.rate_column is not None):
        raise ThermocalInputError.naming(
            "{dwell_s} places the plateaus of the rates given with {rates_dps}, without "
            "{rate_column} (whose plateaus need no dwell)",
            "dwell_s",
            "rates_dps",
            "rate_column",
        )
    if opts.dwell_s is not None and len(opts.dwell_s) not in (1, len(opts.rates_dps or ())):
        raise ParameterError(
            "dwell_s",
            f"{{name}}: {len(opts.dwell_s)} dwells for {len(opts.rates_dps or ())} rates; give "
            "one for all, or one a rate",
        )
    for name in ("start_s", "accel_dps2"):
        if getattr(opts, name) is not None and not timed:
            raise ThermocalInputError.naming(
                f"{{{name}}} places a timed ladder: give it with {{dwell_s}} (or a {{schedule}} "
                "of rate_dps,dwell_s rows)",
                name,
                "dwell_s",
                "schedule",
            )


def _check_given(d: Detection, rates: Sequence[float], path: Path) -> None:
    """The rates given must be those the table's rate column shows, in order."""
    found = [p.rate_dps for p in d.plateaus]
    same = len(found) == len(rates) and all(
        abs(a - b) <= 1e-3 + 1e-4 * abs(b) for a, b in zip(found, rates, strict=True)
    )
    if not same:
        shown = ", ".join(f"{r:g}" for r in found[:15]) + (", …" if len(found) > 15 else "")
        raise DesignError.naming(
            f"{path}: the table's rate column shows {len(found)} plateaus ({shown} °/s) but "
            f"{{rates_dps}} gives {len(rates)} rates that differ; leave {{rates_dps}} out to "
            "take the column's",
            "rates_dps",
        )


def _check_noise(dets: Sequence[Detection]) -> None:
    """A warning when the plateaus' noise is correlated: the median ratio of the block-means
    standard error to the white-noise one above ``CORRELATED_RATIO``."""
    ratios = [
        p.se_blocks / p.se for d in dets for p in d.plateaus if p.se_blocks is not None and p.se > 0
    ]
    if not ratios or float(np.median(ratios)) <= CORRELATED_RATIO:
        return
    r = float(np.median(ratios))
    warnings.warn(
        ThermocalWarning.naming(
            f"the plateaus' noise is correlated: their means scatter {r:.1f}x more than white "
            "noise of their spread would (block means); the uncertainties assume white noise "
            "and are too small by about that factor",
        ),
        stacklevel=3,
    )


def _groups(dets: Sequence[Detection], gap_c: float, has_t: bool) -> list[list[Plateau]]:
    """Plateaus grouped into ladders: one per file, or by temperature within one file."""
    if len(dets) > 1 or not has_t:
        return [list(d.plateaus) for d in dets]
    pl = sorted(dets[0].plateaus, key=lambda p: p.temperature_c or 0.0)
    groups: list[list[Plateau]] = [[pl[0]]]
    for p in pl[1:]:
        if (p.temperature_c or 0.0) - (groups[-1][-1].temperature_c or 0.0) > gap_c:
            groups.append([])
        groups[-1].append(p)
    return [sorted(g, key=lambda p: p.start_s) for g in groups]


def _check_fit(ladder: LadderResult, unit: str, where: str) -> None:
    """No plateau off the line by more than ``MAX_DEVIATION_FS`` of full scale (a rate given
    with a wrong sign or out of order), and an output in °/s gives a scale factor near ±1."""
    worst = max(ladder.rows, key=lambda r: abs(r.nonlinearity_ppm_fs))
    if abs(worst.nonlinearity_ppm_fs) > MAX_DEVIATION_FS * 1e6:
        raise DesignError.naming(
            f"{where}: the plateaus at {worst.rate_dps:g} °/s read "
            f"{abs(worst.nonlinearity_ppm_fs) / 1e4:.3g} % of full scale off the line through "
            "the others: a rate with a wrong sign or out of order; give the rates as the table "
            "ran them with {rates_dps} (°/s), or the table's {rate_column}",
            "rates_dps",
            "rate_column",
        )
    k = abs(ladder.scale_factor)
    if unit == "deg/s" and ladder.scale_factor < 0:
        warnings.warn(
            ThermocalWarning.naming(
                f"{where}: scale factor {ladder.scale_factor:.6g}: the gyro's input axis points "
                "against the table's positive rate, or the rates are given in reverse order "
                "({rates_dps})",
                "rates_dps",
            ),
            stacklevel=3,
        )
    if unit != "deg/s" or K_UNIT_RANGE[0] <= k <= K_UNIT_RANGE[1]:
        return
    hint = ""
    for name, f in (("rad/s", 180 / math.pi), ("deg/h", 1 / 3600), ("rpm", 6.0)):
        if abs(k / f - 1) < 0.1:
            hint = f" (the rates look given in {name}, the output in °/s)"
    if not hint:
        for name, f in (("rad/s", math.pi / 180), ("deg/h", 3600.0)):
            if abs(k / f - 1) < 0.1:
                hint = f" (the output looks in {name}, not °/s)"
    raise DesignError.naming(
        f"{where}: scale factor {ladder.scale_factor:.4g} between an output in °/s and the "
        f"rates{hint}: give the rates in °/s ({{rates_dps}}, {{rate_column}}) and the output's "
        "unit with {gyro_unit}",
        "rates_dps",
        "rate_column",
        "gyro_unit",
    )


def _check_ladders(ladders: Sequence[LadderResult]) -> None:
    """Ladders at several temperatures must hold the same rates (the scale factor of a
    nonlinear gyro depends on the ladder)."""
    sets = [{r.rate_dps for r in ld.rows} for ld in ladders]
    for ld, s in zip(ladders[1:], sets[1:], strict=True):
        if s != sets[0]:
            diff = sorted(s ^ sets[0])[:6]
            raise DesignError.naming(
                f"the ladders at {ladders[0].temperature_c:.1f} °C and {ld.temperature_c:.1f} °C "
                f"do not hold the same rates (differ at {', '.join(f'{x:g}' for x in diff)} "
                "°/s; the scale factor of a nonlinear gyro depends on the ladder): run the "
                "same ladder at every temperature, or give the files one at a time without "
                "{temps}",
                "temps",
            )


def ratetable_files(
    paths: Sequence[Path],
    opts: RateTableOptions,
    *,
    schedule: Path | None = None,
) -> RateTableResult:
    """The rate-table test of one or several recordings (one per temperature).

    Parameters
    ----------
    paths : sequence of Path
        The recordings.
    opts : RateTableOptions
        How they are read and their plateaus found.
    schedule : Path, optional
        A schedule file (``start_s,end_s,rate_dps`` rows) giving the plateaus of one file.

    Returns
    -------
    RateTableResult

    Raises
    ------
    ThermocalInputError
        Files, columns or units that cannot be read; plateaus that do not match the rates;
        several files without temperatures; ladders that differ between temperatures.
    """
    if len(paths) > 1 and opts.temps is None:
        raise ThermocalInputError.naming(
            "several files: name their temperature column with {temps} (one file per temperature)",
            "temps",
        )
    if schedule is not None and (
        len(paths) > 1 or opts.rate_column or opts.rates_dps or opts.dwell_s
    ):
        raise ParameterError(
            "schedule",
            "{name} gives the plateaus of one file, alone (no rates, dwell or rate column)",
        )
    sched = read_schedule(schedule) if schedule is not None else None
    _check_timed(opts, sched)
    dets, timings, out_units = [], [], set()
    for p in paths:
        rec, y, unit, temp = _read(Path(p), opts)
        det, timing = _detect(Path(p), rec, y, temp, opts, sched)
        dets.append(det)
        timings.append(timing)
        out_units.add(unit)
    if len(out_units) != 1:
        raise ThermocalInputError.naming(
            f"the files' gyro outputs are in {sorted(out_units)}; give {{gyro_unit}}", "gyro_unit"
        )
    unit = out_units.pop()
    _check_noise(dets)
    ladders = []
    for gi, g in enumerate(_groups(dets, opts.temp_gap_c, opts.temps is not None)):
        where = str(paths[gi] if len(paths) > 1 else paths[0])
        ts = [p.temperature_c for p in g if p.temperature_c is not None]
        ld = analyse_ladder(
            [p.rate_dps for p in g],
            [p.mean for p in g],
            [p.se for p in g],
            temperature_c=float(np.mean(ts)) if ts else None,
            small_fraction=opts.small_fraction,
        )
        _check_fit(ld, unit, where)
        if (
            ld.asymmetry.value is None
            and not opts.one_direction
            and "only" in str(ld.asymmetry.reason)
        ):
            raise DesignError.naming(
                f"{where}: {ld.asymmetry.reason}; run the ladder both ways, or give "
                "{one_direction} for the other figures without it",
                "one_direction",
            )
        ladders.append(ld)
    tc = None
    if len(ladders) > 1:
        _check_ladders(ladders)
        tc = temperature_coefficient(
            [ld.temperature_c or 0.0 for ld in ladders],
            [ld.scale_factor for ld in ladders],
            [ld.scale_factor_sigma for ld in ladders],
        )
    return RateTableResult(
        tuple(str(p) for p in paths), tuple(dets), tuple(ladders), tc, unit, tuple(timings)
    )


def _figure_from(d: dict[str, Any]) -> Figure:
    """A figure from its JSON object (``value``, ``sigma``, ``reason``, its detail)."""
    detail = {k: v for k, v in d.items() if k not in ("value", "sigma", "reason")}
    return Figure(d["value"], d["sigma"], d["reason"], detail or None)


def _ladder_from(d: dict[str, Any]) -> LadderResult:
    """A ladder from its JSON object."""
    numbers: dict[str, Any] = {k: float(d[k]) for k in _LADDER_NUMBERS}
    figures: dict[str, Any] = {a: _figure_from(d[k]) for a, k in _LADDER_FIGURES}
    return LadderResult(
        **numbers,
        **figures,
        rows=tuple(RateRow(**r) for r in d["rates"]),
        temperature_c=d["temperature_c"],
        n_plateaus=int(d["n_plateaus"]),
    )


_LADDER_NUMBERS = (
    "scale_factor",
    "scale_factor_sigma",
    "bias",
    "bias_sigma",
    "zero_rate_bias_dps",
    "zero_rate_bias_sigma_dps",
    "full_scale_dps",
)
_LADDER_FIGURES = (
    ("nonlinearity", "nonlinearity_ppm_fs"),
    ("asymmetry", "asymmetry_ppm"),
    ("threshold", "threshold_dps"),
    ("resolution", "resolution_dps"),
    ("repeatability", "repeatability_ppm"),
)


def _detection_from(d: dict[str, Any]) -> tuple[Detection, LadderTiming | None]:
    """A file's plateaus (sample indices not kept: 0) and its timed ladder, from JSON."""
    keys = ("start_s", "end_s", "rate_dps", "mean", "sd", "temperature_c")
    pl = tuple(Plateau(i0=0, i1=0, n=int(p["n"]), **{k: p[k] for k in keys}) for p in d["plateaus"])
    det = Detection(pl, float(d["settle_s"]), str(d["source"]), tuple(map(tuple, d["dropped"])))
    if d.get("ladder_start_s") is None:
        return det, None
    spans = tuple((p.start_s - det.settle_s, p.end_s) for p in pl)
    found = tuple(d.get("found") or ())
    return det, LadderTiming(d["ladder_start_s"], d["accel_dps2"], found, math.nan, spans)


def result_from_dict(d: dict[str, Any]) -> RateTableResult:
    """A rate-table result from its JSON object (:meth:`RateTableResult.to_dict`).

    Parameters
    ----------
    d : dict
        The object :meth:`RateTableResult.to_dict` gives (what the command line prints or writes).

    Returns
    -------
    RateTableResult
        The plateaus keep their times and statistics, not their sample indices; a timed
        ladder its start and acceleration, not its ``R²`` (NaN).

    Raises
    ------
    ThermocalInputError
        An object that is not a rate-table result.
    """
    try:
        pairs = [_detection_from(p) for p in d["plateaus"]]
        tc = d["temperature_coefficient"]
        tc_args: dict[str, Any] = {
            k: tuple(v) if isinstance(v, list) else v for k, v in (tc or {}).items()
        }
        return RateTableResult(
            tuple(str(f) for f in d["files"]),
            tuple(p[0] for p in pairs),
            tuple(_ladder_from(ld) for ld in d["ladders"]),
            TemperatureCoefficient(**tc_args) if tc else None,
            str(d["output_unit"]),
            tuple(p[1] for p in pairs),
        )
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise ThermocalInputError(
            f"not a rate-table result of `thermocal ratetable -o` ({type(exc).__name__}: {exc})"
        ) from None


def read_result(path: Path) -> RateTableResult:
    """A rate-table result file (``thermocal ratetable -o RESULT.json``).

    Parameters
    ----------
    path : Path
        The JSON file.

    Returns
    -------
    RateTableResult

    Raises
    ------
    ThermocalInputError
        A file that cannot be read or is not a rate-table result.
    """
    import json

    try:
        d = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ThermocalInputError(f"{path}: cannot read the rate-table result ({exc})") from None
    if not isinstance(d, dict):
        raise ThermocalInputError(f"{path}: not a rate-table result of `thermocal ratetable -o`")
    try:
        return result_from_dict(d)
    except ThermocalInputError as exc:
        raise ThermocalInputError(f"{path}: {exc}") from None
