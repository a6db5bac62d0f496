"""The file edge of the multi-position calibration (``thermocal multipos``): read the
session recordings (and a POSES file), calibrate each session
(:func:`thermocal.multipos.calibrate.calibrate_session`), fit every parameter in
temperature over several sessions (:func:`thermocal.turntable.thermal.fit_triad`, the
turntable's own thermal fit) and save the calibration of triads.

The maths of :mod:`thermocal.multipos` reads no file; this module is where files come in
and go out (file layer, as :mod:`thermocal.pipeline.compensate` for the compensation kernels).
"""

from __future__ import annotations

import itertools
import json
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import units
from thermocal.errors import DesignError, ParameterError, ThermocalInputError, ThermocalWarning
from thermocal.inspection import saturated_mask
from thermocal.models.calibration import Calibration, Triad
from thermocal.multipos.accel_k2 import AccelK2Fit
from thermocal.multipos.calibrate import METHOD, SessionResult, calibrate_session
from thermocal.multipos.gsens import (
    ISOTROPIC_NOTE,
    SIGNIFICANT_SIGMA,
    combine_g_sensitivity,
    isotropic_part,
)
from thermocal.multipos.poses import (
    DRIFT_DEG,
    MOTION_FRACTION,
    STILL_THRESHOLD,
    WINDOW_S,
    PoseDetection,
    Section,
    find_poses,
    parse_poses,
)
from thermocal.pipeline.model_file import file_sha256, save_calibration
from thermocal.pipeline.turntable import check_as_read
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions
from thermocal.recording import Recording
from thermocal.turntable import thermal
from thermocal.writers import check_not_input

G_SENSITIVITY_CHOICES = ("auto", "apply", "off")
"""What ``multipos`` does with the gyro's g-sensitivity (:class:`MultiposOptions`)."""

NO_TEMPERATURE_TREF_C = 25.0
"""TREF recorded for a calibration made without a temperature column (it applies
unchanged at every temperature)."""


@dataclass(frozen=True)
class MultiposOptions:
    """How the session files of a multi-position calibration are read and calibrated.

    Attributes
    ----------
    accel, gyro : tuple of str
        The accelerometer's (and gyro's, or None) x, y, z columns.
    accel_unit, gyro_unit : str or None
        Their units (None: the file's).
    temps : str or None
        The temperature column [°C].
    gravity_m_s2, latitude_deg : float or None
        Local gravity [m/s²] or the latitude [°] (WGS-84 normal gravity), not both.
    order : int or None
        Polynomial order in temperature (None: chosen per parameter).
    tref_c : float or None
        Reference temperature [°C].
    static_s : float
        Shortest still pose [s].
    time, time_unit : str or None
        The time column and its unit.
    accel_scale, gyro_scale : tuple of (float, str) or None
        Raw-count columns: one count is ``value`` ``unit``.
    window_s, still_threshold, motion_fraction, drift_deg : float
        The pose detector's parameters (:func:`thermocal.multipos.poses.find_poses`).
    accel_offset, gyro_offset : float or None
        Zero of the columns in their own unit.
    gyro_model : str
        The gyro's elements of E fitted: ``full`` or ``scale``.
    read : ReadOptions or None
        How a text log and its time are read.
    """

    accel: tuple[str, str, str]
    gyro: tuple[str, str, str] | None = None
    accel_unit: str | None = None
    gyro_unit: str | None = None
    temps: str | None = None
    gravity_m_s2: float | None = None
    latitude_deg: float | None = None
    order: int | None = None
    tref_c: float | None = None
    static_s: float = 1.0
    time: str | None = None
    time_unit: str | None = None
    accel_scale: tuple[float, str] | None = None
    gyro_scale: tuple[float, str] | None = None
    """Raw-count columns: one count is ``value`` ``unit`` (``accel_scale=(0.061, "mg")``)."""
    window_s: float = WINDOW_S
    still_threshold: float = STILL_THRESHOLD
    motion_fraction: float = MOTION_FRACTION
    drift_deg: float = DRIFT_DEG
    """The pose detector's options (:func:`thermocal.multipos.poses.find_poses`)."""
    accel_offset: float | None = None
    gyro_offset: float | None = None
    """Zero of the columns in their own unit (counts: ``accel_offset=32768`` for unsigned
    ADC counts); None: none, or mid-scale found in unsigned counts (a warning)."""
    gyro_model: str = "full"
    """The gyro's elements of E fitted (:data:`thermocal.multipos.gyro.GYRO_MODELS`)."""
    g_sensitivity: str = "auto"
    """The gyro's g-sensitivity in the calibration (:data:`G_SENSITIVITY_CHOICES`): ``auto``
    stores it (and ``compensate`` applies it) when an element is beyond
    :data:`thermocal.multipos.gsens.SIGNIFICANT_SIGMA` σ, ``apply`` whenever the poses
    separate it (refused where they do not), ``off`` never (it is still reported)."""
    read: ReadOptions | None = None
    """How to read a text log and its time (``rate_hz``: a sample counter, or samples at
    the nominal rate; ``names`` …), as every command reads it; its columns and units are
    those named above."""
    accel_k2: bool = False
    """Also fit each accelerometer axis's second-order coefficient K2 (poses at a slant to
    every axis needed: :func:`thermocal.multipos.accel_k2.fit_k2`)."""

    def check(self, n_files: int, poses: Path | None) -> None:
        """The options' own consistency (before any file is read).

        Parameters
        ----------
        n_files : int
            Number of session files given.
        poses : Path or None
            The poses file naming sections of a single file, if given.

        Returns
        -------
        None

        Raises
        ------
        ThermocalInputError
            When the options contradict each other or the number of files.
        """
        if self.gyro_model not in ("full", "scale"):
            raise ParameterError("gyro_model", f"{{name}} {self.gyro_model!r}: full or scale")
        if self.g_sensitivity not in G_SENSITIVITY_CHOICES:
            raise ParameterError(
                "g_sensitivity",
                f"{{name}} {self.g_sensitivity!r}: {', '.join(G_SENSITIVITY_CHOICES)}",
            )
        if self.g_sensitivity == "apply" and self.gyro is None:
            raise ParameterError(
                "g_sensitivity",
                "{name} apply: the g-sensitivity is the gyro's; name its columns with {gyro} X,Y,Z",
                ("gyro",),
            )
        if self.gyro_model != "full" and self.gyro is None:
            raise ParameterError(
                "gyro_model",
                f"{{name}} {self.gyro_model}: no gyro columns to fit; name them with "
                "{gyro} X,Y,Z",
                ("gyro",),
            )
        if n_files > 1 and self.temps is None:
            raise ThermocalInputError.naming(
                "several files: name their temperature column with {temps} (one file per "
                "temperature)",
                "temps",
            )
        if (self.order is not None or self.tref_c is not None) and n_files < 2:
            raise ThermocalInputError.naming(
                "{order} and {tref_c} need several files and {temps}", "order", "tref_c", "temps"
            )
        if self.gravity_m_s2 is not None and self.latitude_deg is not None:
            raise ThermocalInputError.naming(
                "give {gravity_m_s2} or {latitude_deg}, not both", "gravity_m_s2", "latitude_deg"
            )
        if self.gravity_m_s2 is not None and not 9.7 <= self.gravity_m_s2 <= 9.9:
            raise ParameterError(  # a gravity of 1 (in g) scaled every axis by 1/9.8
                "gravity_m_s2",
                f"{{name}} {self.gravity_m_s2:g}: local gravity in m/s² is 9.78-9.83 on the "
                "earth's surface (1 g = 9.80665 m/s²); give it in m/s², or {latitude_deg} DEG",
                ("latitude_deg",),
            )
        if self.static_s is not None and not (math.isfinite(self.static_s) and self.static_s > 0):
            raise ParameterError(
                "static_s", f"{{name}} must be a positive number, got {self.static_s!r}"
            )
        if poses is not None and n_files > 1:
            raise ParameterError("poses", "{name} names the sections of one file; give one file")


@dataclass(frozen=True)
class SessionRun:
    """One session file calibrated.

    Attributes
    ----------
    path : Path
        The session file.
    result : SessionResult
        Its calibration (:func:`thermocal.multipos.calibrate.calibrate_session`).
    t_range_c : tuple of float or None
        Its temperature range [°C] (None without a temperature column).
    detection : PoseDetection or None
        The pose detector's choice (None with a POSES file).
    offsets : dict or None
        Each triad's zero removed before the directions were judged [its unit].
    """

    path: Path
    result: SessionResult
    t_range_c: tuple[float, float] | None
    detection: PoseDetection | None = None
    """The pose detector's choice (None with a POSES file)."""
    offsets: dict[str, float] | None = None
    """Each triad's zero removed before the directions were judged [its unit]."""
    accel_k2: AccelK2Fit | None = None
    """The accelerometer fitted with K2 per axis (``accel_k2``), else None."""


@dataclass(frozen=True, eq=False)
class StoredGSensitivity:
    """The gyro's g-sensitivity over the sessions (:func:`combine_g_sensitivity
    <thermocal.multipos.gsens.combine_g_sensitivity>`) and the decision to store it.

    Attributes
    ----------
    matrix, sigma : numpy.ndarray, shape (3, 3) or None
        ``A`` and its σ [``unit``]; None when no session separates it.
    unit : str
        The gyro's unit per g (``deg/s/g``).
    stored : bool
        Written into the calibration (and applied by ``compensate``).
    why : str
        Why (the option, the significance, or what the poses lack).
    n_sessions : int
        Sessions whose estimate entered the mean.
    """

    matrix: Any
    sigma: Any
    unit: str
    stored: bool
    why: str
    n_sessions: int

    def to_dict(self) -> dict[str, Any]:
        """``matrix``, ``matrix_sigma`` (None when not estimated), ``unit``, ``stored``,
        ``why``, ``n_sessions``."""
        return {
            "matrix": None if self.matrix is None else np.asarray(self.matrix).tolist(),
            "matrix_sigma": None if self.sigma is None else np.asarray(self.sigma).tolist(),
            "unit": self.unit,
            "stored": self.stored,
            "why": self.why,
            "n_sessions": self.n_sessions,
        }


@dataclass(frozen=True, eq=False)
class MultiposResult:
    """The result of :func:`calibrate_files`: the calibration written, each session run,
    each triad's thermal model, the units and the gravity used; :meth:`to_dict` is its one
    JSON form.

    Attributes
    ----------
    calibration : Calibration
        The calibration of triads written to ``output``.
    runs : tuple of SessionRun
        Each session file calibrated alone.
    models : dict
        ``{"accel": TriadThermal, "gyro": TriadThermal}`` (``gyro`` only with its columns).
    accel_unit : str
        The accelerometer columns' unit (the figures' unit).
    gyro_unit : str or None
        The gyro columns' unit (None without gyro columns).
    gravity_m_s2 : float
        Local gravity used [m/s²].
    output : Path
        The calibration file written.
    count_scales : dict
        ``{triad: (value, unit)}`` of the triads read as raw counts.
    g_sensitivity : StoredGSensitivity or None
        The gyro's g-sensitivity over the sessions and whether it was stored.
    """

    calibration: Calibration
    runs: tuple[SessionRun, ...]
    models: dict[str, Any]
    accel_unit: str
    gyro_unit: str | None
    gravity_m_s2: float
    output: Path
    count_scales: dict[str, tuple[float, str]]
    g_sensitivity: StoredGSensitivity | None = None
    """The gyro's g-sensitivity and whether the calibration holds it (None without a gyro)."""

    def to_dict(self, spell: Callable[[str], str] | None = None) -> dict[str, Any]:
        """The result as JSON types (what the ``multipos`` command prints as JSON).

        Parameters
        ----------
        spell : callable, optional
            How a rejected pose's reason writes the detector's parameters it names
            (:meth:`thermocal.multipos.poses.Rejected.spelled`; default their own names).

        Returns
        -------
        dict
            Each triad at TREF in the data's units (bias, scale factors [ppm],
            misalignments [″] with their σ), the poses, the gravity-magnitude residuals
            before and after in the accelerometer's unit, each run's figures and the pose
            detector's choice, and ``output``, the calibration file written.
        """
        out = _summary(
            list(self.runs), self.models, self.accel_unit, self.gyro_unit, self.gravity_m_s2,
            spell,
        )  # fmt: skip
        for kind, (value, unit) in self.count_scales.items():
            if kind in out:  # raw counts: the figures are in the scale's unit
                out[kind]["count_scale"] = {"value": value, "unit": unit}
        if self.g_sensitivity is not None and "gyro" in out:
            out["gyro"]["g_sensitivity"] = self.g_sensitivity.to_dict()
        out["output"] = str(self.output)
        return out


def _unit_of(
    rec: Any,
    cols: list[str],
    option: str | None,
    kind: str,
    path: Path,
    scale: tuple[float, str] | None = None,
) -> tuple[str, float]:
    """The columns' unit and the factor to it: the option, else the file's (metadata,
    column name; raw ``counts`` where a ``scale`` is given and nothing states one, as the
    reader resolves them); raw counts need ``scale`` (their unit is then the scale's)."""
    stated = [c for c in cols if rec.unit_sources.get(c, "default") != "default"]
    found = {option} if option else {rec.units.get(c) or "" for c in stated}
    if not option and len(stated) < 3:
        found = set()
    if len(found) != 1 or not next(iter(found)):
        raise ThermocalInputError.naming(
            f"{path}: the {kind} columns {cols} state no single unit; give {{{kind}_unit}}",
            f"{kind}_unit",
        )
    unit = str(units.normalize_signal_unit(found.pop()))
    want = "accel" if kind == "accel" else "rate"
    if unit == "counts":
        if scale is None:
            example = "0.061,mg" if kind == "accel" else "0.00763,deg/s"
            raise ThermocalInputError.naming(
                f"{path}: the {kind} columns are raw counts; give {{{kind}_scale}} VALUE,UNIT "
                f"(one count, from the datasheet's sensitivity, e.g. {example})",
                f"{kind}_scale",
            )
        return scale[1], scale[0]
    if scale is not None:
        raise ThermocalInputError.naming(
            f"{path}: {{{kind}_scale}} is for raw counts; the {kind} columns are in {unit}",
            f"{kind}_scale",
        )
    if units.signal_kind(unit) != want:
        what = "an acceleration" if kind == "accel" else "a rate"
        raise ThermocalInputError(f"{path}: the {kind} columns' unit {unit!r} is not {what} unit")
    return unit, 1.0


def _read_poses(poses: Path | None) -> dict[str, Any] | None:
    """The POSES file's JSON object (None without one); a ``.csv`` is imucal's section list
    as pandas writes it (``section_list.to_csv``: a header ``,start,end`` and one row
    ``name,i,j`` per section), and so is a file of another name (``.txt``, none) whose text
    is not a JSON object or list."""
    if poses is None:
        return None
    try:
        text = poses.read_text(encoding="utf-8")
        suffix = poses.suffix.lower()
        if suffix == ".csv" or (suffix != ".json" and not text.lstrip().startswith(("{", "["))):
            return _poses_csv(text, poses)
        doc: dict[str, Any] = json.loads(text)
    except (OSError, UnicodeDecodeError, ValueError) as exc:  # a 5000-digit integer too
        raise ThermocalInputError(f"{poses}: not a readable JSON file ({exc})") from None
    except RecursionError:  # thousands of nested brackets
        raise ThermocalInputError(f"{poses}: not a POSES file (JSON nested too deeply)") from None
    return doc


def _poses_csv(text: str, poses: Path) -> dict[str, Any]:
    """imucal's section list written by pandas as CSV (:func:`_read_poses`)."""
    import csv

    rows = [r for r in csv.reader(text.splitlines()) if any(c.strip() for c in r)]
    head = [c.strip() for c in rows[0]] if rows else []
    if "start" not in head or "end" not in head:
        raise ThermocalInputError(
            f"{poses}: a CSV section list needs a header with 'start' and 'end' (and the "
            "section names in the first column), or give the sections as JSON"
        )
    i0, i1 = head.index("start"), head.index("end")
    out: dict[str, Any] = {}
    for r in rows[1:]:
        try:
            out[r[0].strip()] = {"start": int(r[i0]), "end": int(r[i1])}
        except (IndexError, ValueError):
            raise ThermocalInputError(
                f"{poses}: section row {','.join(r)!r} needs integer start and end"
            ) from None
    return out


class _Gravity:
    """The latitude and local gravity of the sessions: the options', else the first file's
    latitude (and its WGS-84 normal gravity)."""

    def __init__(self, opts: MultiposOptions) -> None:
        self.latitude_deg = opts.latitude_deg
        self.g_m_s2 = opts.gravity_m_s2
        self.opts = opts

    def update(self, rec: Recording, path: Path) -> None:
        lat = (
            self.opts.latitude_deg if self.opts.latitude_deg is not None else rec.meta.latitude_deg
        )
        if self.latitude_deg is None:
            self.latitude_deg = lat
        if self.g_m_s2 is None:
            if lat is None:
                raise ThermocalInputError.naming(
                    f"{path}: give the local gravity ({{gravity_m_s2}} M/S2) or the latitude "
                    "({latitude_deg} DEG, WGS-84 normal gravity)",
                    "gravity_m_s2",
                    "latitude_deg",
                )
            self.g_m_s2 = units.normal_gravity_m_s2(float(lat))


MID_SCALE = 32768.0
"""Mid-scale of unsigned 16-bit ADC counts (imu_tk's Xsens data sit around it)."""


def _offset(raw: np.ndarray, given: float | None, unit: str, kind: str, path: Path) -> float:
    """The triad's zero in its columns' unit: ``given`` (``accel_offset``, ``gyro_offset``),
    else mid-scale for raw counts that are all in 0…65535 with every column's median in the
    middle half (unsigned ADC counts, a warning), else 0."""
    if given is not None:
        if not math.isfinite(given):
            raise ParameterError(
                f"{kind}_offset", f"{{name}} must be a finite number, got {given!r}"
            )
        return float(given)
    if unit != "counts" or raw.size == 0:
        return 0.0
    med = np.median(raw, axis=0)
    if (
        float(raw.min()) >= 0
        and float(raw.max()) <= 65535
        and np.all(np.abs(med - MID_SCALE) < MID_SCALE / 2)
    ):
        warnings.warn(
            ThermocalWarning.naming(
                f"{path}: the {kind} columns look like unsigned counts around mid-scale "
                f"(medians {', '.join(f'{m:.0f}' for m in med)}): {MID_SCALE:.0f} taken as "
                f"their zero; give {{{kind}_offset}} (0 for none) to say it",
                f"{kind}_offset",
            ),
            stacklevel=3,
        )
        return MID_SCALE
    return 0.0


def _triad(
    rec: Recording, cols: list[str], opts: MultiposOptions, kind: str, path: Path
) -> tuple[np.ndarray, str, float]:
    """The triad's samples in mg (accel) or rad/s (gyro) with its zero removed, its unit
    and that zero [its unit]."""
    scale = opts.accel_scale if kind == "accel" else opts.gyro_scale
    unit, factor = _unit_of(rec, cols, opts.accel_unit if kind == "accel" else opts.gyro_unit,
                            kind, path, scale)  # fmt: skip
    raw = np.column_stack([rec.column(c) for c in cols])
    col_unit = "counts" if scale is not None else unit
    off = _offset(raw, opts.accel_offset if kind == "accel" else opts.gyro_offset, col_unit,
                  kind, path)  # fmt: skip
    to = "mg" if kind == "accel" else "rad/s"
    return units.convert((raw - off) * factor, unit, to), unit, off * factor


def _with_offsets(res: SessionResult, acc_off_mg: float, gyr_off_deg_h: float) -> SessionResult:
    """The session's calibration with the zeros put back into the biases (the compensation
    sees the columns as they are) and into the pose means."""
    if acc_off_mg == 0.0 and gyr_off_deg_h == 0.0:
        return res
    th = res.accel.theta.copy()
    th[0:3] += acc_off_mg
    poses = tuple(replace(p, f_mean_mg=p.f_mean_mg + acc_off_mg) for p in res.poses)
    k2 = res.accel_k2
    if k2 is not None:  # the K2 fit's bias too (the model is the same about the zero)
        tk = k2.linear.theta.copy()
        tk[0:3] += acc_off_mg
        k2 = replace(k2, linear=replace(k2.linear, theta=tk))
    gyro = res.gyro
    if gyro is not None:
        tg = gyro.theta.copy()
        tg[0:3] += gyr_off_deg_h
        gyro = replace(gyro, theta=tg)
    return replace(res, accel=replace(res.accel, theta=th), gyro=gyro, poses=poses, accel_k2=k2)


def _detect(t: np.ndarray, acc: np.ndarray, w: np.ndarray | None, opts: MultiposOptions,
            path: Path) -> PoseDetection:  # fmt: skip
    """The poses found in the data (:func:`find_poses` with the detector's options of
    ``opts``); fewer than six refused with what was rejected and the parameters that change it."""
    det = find_poses(t, acc, w, static_s=opts.static_s, window_s=opts.window_s,
                     still_threshold=opts.still_threshold, motion_fraction=opts.motion_fraction,
                     drift_deg=opts.drift_deg)  # fmt: skip
    if len(det.poses) < 6:
        why = "; ".join(f"{r.template} ({r.start}…{r.end})" for r in det.rejected[:4])
        named = tuple(dict.fromkeys(p for r in det.rejected[:4] for p in r.parameters))
        raise DesignError.naming(
            f"{path}: {len(det.poses)} static poses found (the accelerometer triad needs at "
            f"least 9 distinct ones){'; rejected: ' + why if why else ''}: lower {{static_s}}, "
            "raise {still_threshold} or {motion_fraction}, or name the poses with {poses}",
            *dict.fromkeys(("static_s", "still_threshold", "motion_fraction", "poses", *named)),
        )
    return det


def _saturation(
    rec: Recording, cols: list[str], sections: list[Section], path: Path
) -> np.ndarray | None:
    """The samples with a gyro column on its rails (:func:`thermocal.inspection.saturated_mask`),
    None when there are none.  A 360° turn across them is refused; each motion between
    consecutive static poses across them is named in a warning (the gyro fit leaves it out)."""
    sat = np.zeros(rec.n_samples, dtype=bool)
    for c in cols:
        sat |= saturated_mask(rec.column(c))
    if not sat.any():
        return None
    for sec in sections:
        if sec.is_turn and sat[sec.start : sec.end].any():
            k = sec.start + int(np.argmax(sat[sec.start : sec.end]))
            raise ThermocalInputError(
                f"{path}: the turn {sec.name!r} has gyro samples on their rails (first at row "
                f"{k}): its rotation is unknown; record it slower, or with a wider gyro range"
            )
    statics = [s for s in sections if not s.is_turn]
    hit = [
        f"{a.name} → {b.name} (rows {a.end + int(np.argmax(sat[a.end : b.start]))}…)"
        for a, b in itertools.pairwise(statics)
        if sat[a.start : b.end].any()
    ]
    if hit:
        warnings.warn(
            ThermocalWarning(
                f"{path}: the gyro is on its rails (clipped) during {len(hit)} motion(s): "
                f"{', '.join(hit[:6])}{' …' if len(hit) > 6 else ''}; left out of the gyro "
                "fit (`thermocal inspect` lists the samples)"
            ),
            stacklevel=3,
        )
    return sat


def _session(
    path: Path,
    opts: MultiposOptions,
    grav: _Gravity,
    sections_d: dict[str, Any] | None,
    poses: Path | None,
) -> tuple[SessionRun, str, str | None]:
    """Read and calibrate one session file; its accelerometer and gyro units."""
    acc_cols, gyr_cols, temps = list(opts.accel), list(opts.gyro or []) or None, opts.temps
    given = [opts.accel_unit] * 3 + ([opts.gyro_unit] * 3 if gyr_cols else [])
    read = (opts.read or ReadOptions()).replace(
        time=opts.time,
        time_unit=opts.time_unit,
        signals=(*acc_cols, *(gyr_cols or [])),
        signal_unit=tuple(u or "" for u in given) if any(given) else None,
        temperatures=(temps,) if temps else None,
    )
    rec = read_recording(
        path, read,
        ask_units={**dict.fromkeys([] if opts.accel_scale else acc_cols, "accel_unit"),
                   **dict.fromkeys([] if opts.gyro_scale else (gyr_cols or []), "gyro_unit")},
        implied_units={**dict.fromkeys(acc_cols if opts.accel_scale else [], "counts"),
                       **dict.fromkeys((gyr_cols or []) if opts.gyro_scale else [], "counts")},
    )  # fmt: skip
    rec.validate(
        required=[*acc_cols, *(gyr_cols or []), *([temps] if temps else [])],
        unit_parameters={**dict.fromkeys(acc_cols, "accel_unit"),
                         **dict.fromkeys(gyr_cols or [], "gyro_unit")},
    )  # fmt: skip
    acc, au, a_off = _triad(rec, acc_cols, opts, "accel", path)
    grav.update(rec, path)
    w, gu, g_off = None, None, 0.0
    if gyr_cols:
        w, gu, g_off = _triad(rec, gyr_cols, opts, "gyro", path)
    det = None
    if sections_d is not None:
        sections = parse_poses(sections_d, rec.n_samples, str(poses))
    else:
        det = _detect(rec.time_s, acc, w, opts, path)
        sections = list(det.poses)
    sat = _saturation(rec, gyr_cols, sections, path) if gyr_cols else None
    temp = rec.temperature_c(temps) if temps else None
    assert grav.g_m_s2 is not None
    try:
        res = calibrate_session(
            rec.time_s, acc, w, g_mg=float(grav.g_m_s2) / 9.80665e-3,
            latitude_deg=grav.latitude_deg, sections=sections, static_s=opts.static_s,
            temperature_c=temp, where=str(path), saturated=sat, sections_from=str(poses),
            gyro_model=opts.gyro_model, accel_k2=opts.accel_k2,
        )  # fmt: skip
    except DesignError as exc:
        if "distinct poses" not in str(exc) or "K2" in str(exc):  # K2's own: said whole
            raise
        offset = (
            "; or, if the raw counts' zero is not 0 (unsigned ADC counts sit around "
            "mid-scale), give it with {accel_offset} (e.g. 32768)"
        )
        after = offset if opts.accel_scale is not None else ""
        raise DesignError.around(exc, f"{path}: ", after, "accel_offset") from None
    acc_off_mg = float(units.convert(np.array([a_off]), au, "mg")[0]) if a_off else 0.0
    g_off_dh = float(units.convert(np.array([g_off]), str(gu), "deg/h")[0]) if g_off else 0.0
    res = _with_offsets(res, acc_off_mg, g_off_dh)
    t_range = (float(np.min(temp)), float(np.max(temp))) if temp is not None else None
    offsets = {"accel": a_off, **({"gyro": g_off} if gyr_cols else {})}
    return SessionRun(path, res, t_range, det, offsets, res.accel_k2), au, gu


def _g_sensitivity(
    runs: list[SessionRun], opts: MultiposOptions, g_unit: str | None
) -> tuple[StoredGSensitivity | None, list[SessionRun]]:
    """The gyro's g-sensitivity over the sessions that separate it and the decision of
    ``opts.g_sensitivity``; when stored, the sessions with each gyro bias moved to zero
    specific force (:func:`_zero_force_bias`), for the thermal fit."""
    if opts.gyro is None or g_unit is None:
        return None, runs
    unit = f"{g_unit}/g"
    found = [r.result.g_sensitivity for r in runs if r.result.g_sensitivity is not None]
    if not found:
        note = next((r.result.g_sensitivity_note for r in runs), None) or "not estimated"
        if opts.g_sensitivity == "apply":
            raise DesignError.naming(
                f"{runs[0].path}: {{g_sensitivity}} apply: {note}", "g_sensitivity"
            )
        return StoredGSensitivity(None, None, unit, False, f"not estimated: {note}", 0), runs
    a, sig = combine_g_sensitivity(found)
    beyond = bool(np.any(np.abs(a) > SIGNIFICANT_SIGMA * sig))
    iso = isotropic_part(a, sig) if beyond else None
    store = opts.g_sensitivity == "apply" or (
        opts.g_sensitivity == "auto" and beyond and iso is None
    )
    why = {
        "apply": "stored as asked (apply)",
        "off": "not stored (off)",
        "auto": f"stored: an element is beyond {SIGNIFICANT_SIGMA:g}σ"
        if store
        else "not stored: " + ISOTROPIC_NOTE.format(c=iso[0], s=iso[1])
        if iso is not None
        else f"not stored: no element beyond {SIGNIFICANT_SIGMA:g}σ",
    }[opts.g_sensitivity]
    to_g = float(units.convert(np.array([1.0]), "deg/h", g_unit)[0])
    stored = StoredGSensitivity(a * to_g, sig * to_g, unit, store, why, len(found))
    if not store:
        return stored, runs
    # a session whose rates had A f(t) taken off before its gyro fit (where calibrate_session
    # does that, SessionResult.g_sensitivity_subtracted) has its bias at zero force already:
    # moved only where that was not done
    return stored, [
        r if r.result.g_sensitivity_subtracted else _zero_force_bias(r, a, sig) for r in runs
    ]


def _zero_force_bias(run: SessionRun, a_deg_h_g: np.ndarray, sig_deg_h_g: np.ndarray) -> SessionRun:
    """The session with its gyro bias at zero specific force: the static bias is the poses'
    sample-weighted mean rate (:func:`thermocal.multipos.gyro.static_bias`), which holds
    ``A f̄`` with ``f̄`` their sample-weighted mean specific force [g], taken from the poses'
    means less the accelerometer's bias; ``b₀ = b − A f̄``, ``σ²(b₀) = σ²(b) + σ²(A) f̄²``."""
    r = run.result
    assert r.gyro is not None
    n = np.array([p.section.n for p in r.poses], dtype=np.float64)
    f_mg = np.array([p.f_mean_mg for p in r.poses]) - r.accel.theta[0:3]
    f_bar = np.average(f_mg, axis=0, weights=n) / units.G_TO_MG
    theta = r.gyro.theta.copy()
    theta[0:3] -= a_deg_h_g @ f_bar
    cov = r.gyro.cov.copy()
    cov[0:3, 0:3] += np.diag(sig_deg_h_g**2 @ f_bar**2)
    return replace(run, result=replace(r, gyro=replace(r.gyro, theta=theta, cov=cov)))


def _fit_triads(
    runs: list[SessionRun],
    opts: MultiposOptions,
    a_unit: str,
    g_unit: str | None,
    grav: _Gravity,
    g_sens: StoredGSensitivity | None = None,
) -> tuple[list[Triad], dict[str, Any]]:
    """Each triad's thermal model: a polynomial in T − TREF over several sessions, else
    the one session's parameters as constants."""
    triads = []
    models: dict[str, Any] = {}
    for kind, cols, unit in (("accel", opts.accel, a_unit), ("gyro", opts.gyro, g_unit)):
        if cols is None or unit is None:
            continue
        fits = [_accel_fit(r) if kind == "accel" else r.result.gyro for r in runs]
        if len(runs) > 1:
            m = thermal.fit_triad(
                kind, [float(r.result.temperature_c) for r in runs],  # type: ignore[arg-type]
                [ft.theta for ft in fits], [ft.sigma for ft in fits],  # type: ignore[union-attr]
                tref_c=opts.tref_c if kind == "accel" or "accel" not in models
                else models["accel"].tref_c,
                order=opts.order, method=METHOD, gravity_m_s2=grav.g_m_s2,
            )  # fmt: skip
        else:
            r = runs[0].result
            ft = fits[0]
            assert ft is not None
            m = thermal.constant_triad(
                kind, r.temperature_c if r.temperature_c is not None else NO_TEMPERATURE_TREF_C,
                ft.theta, ft.cov, t_range_c=runs[0].t_range_c, method=METHOD,
                gravity_m_s2=grav.g_m_s2,
            )  # fmt: skip
        models[kind] = m
        sc = opts.accel_scale if kind == "accel" else opts.gyro_scale
        stored = g_sens if kind == "gyro" and g_sens is not None and g_sens.stored else None
        triads.append(
            Triad(
                kind, (cols[0], cols[1], cols[2]), unit, opts.temps or "", m,
                latitude_deg=grav.latitude_deg, count_scale=None if sc is None else sc[0],
                data=tuple({"file": Path(r.path).name, "sha256": file_sha256(r.path)}
                           for r in runs),
                g_sensitivity=None if stored is None else stored.matrix,
                g_sensitivity_sigma=None if stored is None else stored.sigma,
                **(_stored_k2(runs, unit) if kind == "accel" else {}),
            )
        )  # fmt: skip
    return triads, models


def _accel_fit(run: SessionRun) -> Any:
    """The accelerometer's linear parameters the triad stores: those fitted with K2 when
    the session was (``accel_k2``: the stored model is the one K2 belongs to), else the
    nine of the gravity-magnitude fit."""
    return run.result.accel if run.accel_k2 is None else run.accel_k2.linear


def _stored_k2(runs: list[SessionRun], unit: str) -> dict[str, Any]:
    """``k2`` and ``k2_sigma`` of the accelerometer Triad [``unit`` per g², g = 9.80665
    m/s²]: the sessions' K2 (fitted per local gravity g_L, so ``K2 (g/g_L)²``) pooled by
    inverse variance, ``K̄ = Σ K_r/σ_r² / Σ 1/σ_r²``, ``σ(K̄) = (Σ 1/σ_r²)^(-1/2)``; empty
    when no session was fitted with K2."""
    fits = [r.accel_k2 for r in runs if r.accel_k2 is not None]
    if not fits:
        return {}
    to_u = float(units.convert(np.array([1.0]), "mg", unit)[0])
    ks = np.array([f.k2_mg_per_g2 * (units.G_TO_MG / f.g_mg) ** 2 for f in fits]) * to_u
    ss = np.array([f.k2_sigma * (units.G_TO_MG / f.g_mg) ** 2 for f in fits]) * to_u
    w = 1.0 / ss**2
    return {"k2": (ks * w).sum(axis=0) / w.sum(axis=0), "k2_sigma": 1.0 / np.sqrt(w.sum(axis=0))}


def calibrate_files(
    files: Sequence[Path], output: Path, opts: MultiposOptions, poses: Path | None = None
) -> MultiposResult:
    """Calibrate the sessions ``files`` (one per temperature; ``poses`` the named sections
    of a single file) and write the calibration of triads to ``output`` (module
    docstring).  Every file's columns must be in one unit per triad.

    Parameters
    ----------
    files : sequence of Path
        Session recordings, one per temperature.
    output : Path
        The calibration file to write (``.json``).
    opts : MultiposOptions
        Columns, units, gravity [m/s²], earth rate and model options.
    poses : Path or None, optional
        A file naming the static sections of a single recording (default ``None``).

    Returns
    -------
    MultiposResult
        The per-session estimates, the triads' models and the path written.

    Raises
    ------
    ThermocalInputError
        When ``output`` is an input or not ``.json``, the options are inconsistent, or a
        session cannot support the calibration.

    References
    ----------
    - Tedaldi, D., Pretto, A., Menegatti, E., "A robust and easy to implement method for
      IMU calibration without external equipments", IEEE ICRA 2014, pp. 3042-3049.
    """
    check_not_input(output, [*files, *([poses] if poses else [])])
    if output.suffix.lower() != ".json":
        raise ThermocalInputError(f"{output}: the calibration is JSON; use a .json name")
    opts.check(len(files), poses)
    sections_d = _read_poses(poses)
    runs: list[SessionRun] = []
    a_units: set[str] = set()
    g_units: set[str] = set()
    grav = _Gravity(opts)
    for f in files:
        run, au, gu = _session(f, opts, grav, sections_d, poses)
        a_units.add(au)
        if gu is not None:
            g_units.add(gu)
        runs.append(run)
    for what, found in (("accelerometer", a_units), ("gyro", g_units)):
        if len(found) > 1:
            raise ThermocalInputError(f"the files' {what} columns differ in unit: {sorted(found)}")
    a_unit = a_units.pop()
    g_unit = g_units.pop() if g_units else None
    g_sens, fit_runs = _g_sensitivity(runs, opts, g_unit)
    triads, models = _fit_triads(fit_runs, opts, a_unit, g_unit, grav, g_sens)
    cal = Calibration([], triads)
    check_as_read(cal, output, "check the columns' units ({accel_unit}, {gyro_unit}, "
                  "{accel_scale}, {gyro_scale}) and the poses ({poses}), or fit a lower "
                  "{order}", "accel_unit", "gyro_unit", "accel_scale", "gyro_scale", "poses",
                  "order")  # fmt: skip
    save_calibration(cal, output)
    assert grav.g_m_s2 is not None
    scales = {"accel": opts.accel_scale, "gyro": opts.gyro_scale}
    return MultiposResult(
        cal, tuple(runs), models, a_unit, g_unit, float(grav.g_m_s2), output,
        {k: sc for k, sc in scales.items() if sc is not None}, g_sens,
    )  # fmt: skip


def _triad_dict(theta: Any, sigma: Any, bias_factor: float, bias_unit: str) -> dict[str, Any]:
    return {
        "bias": (np.asarray(theta[0:3]) * bias_factor).tolist(),
        "bias_sigma": (np.asarray(sigma[0:3]) * bias_factor).tolist(),
        "bias_unit": bias_unit,
        "scale_factor_ppm": list(theta[3:6]),
        "scale_factor_ppm_sigma": list(sigma[3:6]),
        "misalignment_arcsec": list(theta[6:12]),
        "misalignment_arcsec_sigma": list(sigma[6:12]),
        "misalignment_names": ["yx", "zx", "xy", "zy", "xz", "yz"],
    }


def _summary(
    runs: list[SessionRun],
    models: dict[str, Any],
    a_unit: str,
    g_unit: str | None,
    g_m_s2: float,
    spell: Callable[[str], str] | None = None,
) -> dict[str, Any]:
    """The result's JSON object: each triad at TREF in the data's units, the
    poses, the gravity residuals in the accelerometer's unit, and each run's figures."""
    to_a = float(units.convert(np.array([1.0]), "mg", a_unit)[0])
    to_g = float(units.convert(np.array([1.0]), "deg/h", g_unit)[0]) if g_unit else 1.0
    out: dict[str, Any] = {"format": "thermocal-calibration", "gravity_m_s2": g_m_s2}
    run_dicts = []
    all_before, all_after = [], []
    for run in runs:
        f, r = run.path, run.result
        rd: dict[str, Any] = {
            "input": str(f),
            "temperature_c": r.temperature_c,
            "n_poses": len(r.poses),
            "accel": {**_triad_dict(r.accel.theta, r.accel.sigma, to_a, a_unit),
                      "method": r.accel.method, "reduced_chi2": r.accel.reduced_chi2,
                      "misfit": r.accel.misfit_mg * to_a},
            "poses": [
                {**p, "mean_specific_force": (np.asarray(p["mean_specific_force_mg"])
                                              * to_a).tolist(),
                 "gravity_residual": p["gravity_residual_mg"] * to_a}
                for p in r.poses_dict()
            ],
            "not_still": list(r.not_still),
        }  # fmt: skip
        for p in rd["poses"]:
            del p["mean_specific_force_mg"], p["gravity_residual_mg"]
        if run.detection is not None:
            to_gr = float(units.convert(np.array([1.0]), "rad/s", g_unit)[0]) if g_unit else 1.0
            rd["pose_detection"] = run.detection.to_dict(to_a, to_gr, spell)
        if run.offsets and any(run.offsets.values()):
            rd["offset"] = dict(run.offsets)
        if r.gyro is not None:
            rd["gyro"] = {**_triad_dict(r.gyro.theta, r.gyro.sigma, to_g, str(g_unit)),
                          "method": "rotations between poses"
                          + (" and 360° turns" if r.gyro.n_turns else ""),
                          "n_motions": r.gyro.n_motions, "n_turns": r.gyro.n_turns,
                          "model": r.gyro.model, "dof": r.gyro.dof,
                          "reduced_chi2": r.gyro.reduced_chi2,
                          "turn_axis_lean_deg": math.degrees(r.gyro.turn_axis_lean_rad),
                          "direction_rms_before_deg": math.degrees(
                              r.gyro.direction_rms_before_rad),
                          "direction_rms_after_deg": math.degrees(
                              r.gyro.direction_rms_after_rad),
                          "g_sensitivity": None if r.g_sensitivity is None
                          else r.g_sensitivity.to_dict(to_g, str(g_unit)),
                          "g_sensitivity_note": r.g_sensitivity_note,
                          "g_sensitivity_subtracted": r.g_sensitivity_subtracted}  # fmt: skip
        if run.accel_k2 is not None:
            rd["accel_k2"] = run.accel_k2.to_dict(to_a, a_unit)
        stored = _accel_fit(run)  # the fit the calibration holds (with K2 when fitted)
        all_before.append(stored.residual_rms_before_mg**2 * len(r.poses))
        all_after.append(stored.residual_rms_after_mg**2 * len(r.poses))
        run_dicts.append(rd)
    n_poses = sum(len(run.result.poses) for run in runs)
    out["n_poses"] = n_poses
    out["gravity_residual_rms_before"] = math.sqrt(sum(all_before) / n_poses) * to_a
    out["gravity_residual_rms_after"] = math.sqrt(sum(all_after) / n_poses) * to_a
    out["unit"] = a_unit
    out["poses"] = [dict(p, file=rd["input"]) for rd in run_dicts for p in rd["poses"]]
    for kind, m in models.items():
        theta = np.array([f.coef[0] for f in m.fits])
        sigma = np.array([f.sigma[0] for f in m.fits])
        if kind == "accel":
            d = _triad_dict(theta, sigma, to_a, a_unit)
            d["method"] = _accel_fit(runs[0]).method
            k2 = _stored_k2(runs, a_unit)
            if k2:  # stored in the calibration (module Triad.k2), per standard g²
                d["k2"] = {"k2": k2["k2"].tolist(), "k2_sigma": k2["k2_sigma"].tolist(),
                           "unit": f"{a_unit}/g^2"}  # fmt: skip
        else:
            d = _triad_dict(theta, sigma, to_g, str(g_unit))
            d["method"] = run_dicts[0]["gyro"]["method"]
        d["tref_c"] = m.tref_c
        if len(runs) > 1:
            d["order"] = m.order
            d["temperature_range_c"] = [m.t_lo_c, m.t_hi_c]
            d["parameters"] = {
                f.name: {"unit": f.unit, "coefficients": f.coef.tolist(),
                         "coefficients_sigma": f.sigma.tolist(),
                         "loto_rms": f.loto_rms if math.isfinite(f.loto_rms) else None}
                for f in m.fits
            }  # fmt: skip
        out[kind] = d
    out["pose_detection"] = [
        {"input": rd["input"], **rd["pose_detection"]} for rd in run_dicts if "pose_detection" in rd
    ]
    out["runs"] = run_dicts
    return out


__all__ = [
    "NO_TEMPERATURE_TREF_C",
    "MultiposOptions",
    "MultiposResult",
    "SessionRun",
    "calibrate_files",
]
