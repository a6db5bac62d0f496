"""PX4's whole thermal calibration from one ULog (issue 16): ``thermocal px4-tempcal``.

PX4's ``Tools/process_sensor_caldata.py`` fits, for every ``sensor_gyro`` and
``sensor_accel`` instance, a cubic per axis in ``T − TREF`` (TREF mid-range; accelerometers
relative to their median because gravity is in the data) and writes ``TC_*`` parameters.
thermocal does the same with three differences (each stated in the summary):

* **equal weight across the temperature range**: the samples are first reduced to the
  median of each temperature bin (:data:`BIN_WIDTH_C`), so a slow end of the sweep does not
  outweigh a fast middle — PX4 bins the temperature for the same reason;
* **robust to spikes**: the bin statistic is the median, not the mean;
* **judged on data it was not fitted to**: a cubic fitted on the even bins is evaluated on
  the odd ones (hold-out rms per axis, in the report and the JSON), before the final fit on
  every bin.

The fitted cubics form a calibration (one channel per axis, roles gyro/accel x/y/z, in the
log's units rad/s and m/s²); :func:`thermocal.export.params.export_params` writes the
parameter file.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import adequacy, units
from thermocal.errors import ThermocalInputError, ThermocalWarning
from thermocal.models.base import RunData, model_inputs
from thermocal.models.calibration import Calibration, Channel
from thermocal.models.poly import PolyModel
from thermocal.recording import FloatArray, Recording

BIN_WIDTH_C = 0.5
"""Width of the temperature bins whose medians are fitted [°C]."""
MIN_BINS = 8
"""Fewest occupied bins a cubic is fitted to (and judged on)."""
MIN_SWEEP_C = adequacy.ARDUPILOT_MIN_SPAN_C
"""ArduPilot's learning requires a 10 °C sweep (the firmware minimum of the adequacy check)."""
AXES = ("x", "y", "z")
TOPICS = ("sensor_gyro", "sensor_accel")


def temperature_bins(
    temp_c: FloatArray, values: FloatArray, width_c: float = BIN_WIDTH_C
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(bin centres, median temperature, median of each column of ``values``) of the
    occupied temperature bins of ``width_c`` [°C]."""
    lo = math.floor(float(np.min(temp_c)) / width_c) * width_c
    idx = np.floor((temp_c - lo) / width_c).astype(np.int64)
    order = np.argsort(idx, kind="stable")
    idx_s = idx[order]
    starts = np.flatnonzero(np.r_[True, np.diff(idx_s) != 0])
    stops = np.r_[starts[1:], idx_s.size]
    centres = lo + (idx_s[starts] + 0.5) * width_c
    t_med = np.array([np.median(temp_c[order[a:b]]) for a, b in zip(starts, stops, strict=True)])
    v_med = np.array(
        [np.median(values[order[a:b]], axis=0) for a, b in zip(starts, stops, strict=True)]
    )
    f64 = np.float64
    return centres.astype(f64), t_med.astype(f64), v_med.astype(f64)


@dataclass
class SensorFit:
    """One sensor instance: its topic, device id, sweep, per-axis hold-out rms [its unit]."""

    topic: str
    kind: str
    instance: int
    device_id: int
    unit: str
    sweep_c: tuple[float, float]
    n_samples: int
    n_bins: int
    holdout_rms: dict[str, float] = field(default_factory=dict)
    channels: list[Channel] = field(default_factory=list)
    adequacy: dict[str, Any] = field(default_factory=dict)


def _cubic(t: FloatArray, y: FloatArray, unit: str, name: str, rec: Recording) -> PolyModel:
    """A cubic in T fitted to bin medians (the bins are the samples; their index the time)."""
    run = RunData(
        time_s=np.arange(t.size, dtype=np.float64),
        temps_c=t.reshape(-1, 1),
        signal=y,
        temp_names=("temperature",),
        name=name,
        signal_unit=unit,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # bin medians: few samples, correlated by design
        return PolyModel(order=3, per_run_offset=False).fit([run])


def fit_sensor(
    rec: Recording,
    topic: str,
    kind: str,
    instance: int,
    *,
    overrides: tuple[str, ...] = (),
    firmware: str = "px4",
) -> SensorFit:
    """Judge the log (:func:`thermocal.adequacy.judge`: a cubic's sweep, the sensor still,
    the firmware's minimum sweep), then bin, judge (even bins → odd bins) and fit one
    sensor instance's three axes."""
    temp = rec.temperature_c("temperature")
    lo, hi = float(np.min(temp)), float(np.max(temp))
    where = f"{topic}.{instance}"
    vals = np.column_stack([rec.signal(a)[0] for a in AXES])  # canonical unit (°/h or mg)
    unit = rec.signal(AXES[0])[1]
    given = rec.units.get(AXES[0], unit)
    try:
        factor = float(units.convert(1.0, unit, given))
    except ThermocalInputError:
        factor, given = 1.0, unit
    tname = f"{where} temperature"
    judged = adequacy.judge(
        adequacy.Needs({tname: 3}, 4),
        [rec.time_s],
        [temp.reshape(-1, 1)],
        [tname],
        signals=[vals],
        kind=kind,
        name=where,
        unit_factor=factor,
        unit=given,
        overrides=overrides,
    )
    if firmware == "ardupilot":
        judged = judged.merged(
            adequacy.Adequacy(
                (adequacy.firmware_test(hi - lo, "ArduPilot", adequacy.ARDUPILOT_MIN_SPAN_C),),
                overrides,
            )
        )
    record = judged.enforce().to_dict()
    _c, t_med, v_med = temperature_bins(temp, vals)
    if t_med.size < MIN_BINS:
        raise ThermocalInputError(
            f"{where}: the temperature covers {t_med.size} bins of {BIN_WIDTH_C:g} °C; a cubic "
            f"needs at least {MIN_BINS}: record a wider sweep"
        )
    sid = rec.meta.sensor_id
    fit = SensorFit(
        topic, kind, instance, int(sid) if sid and str(sid).isdigit() else 0, unit,
        (lo, hi), int(temp.size), int(t_med.size), adequacy=record,
    )  # fmt: skip
    even, odd = np.arange(0, t_med.size, 2), np.arange(1, t_med.size, 2)
    short = "g" if kind == "gyro" else "a"
    for j, axis in enumerate(AXES):
        name = f"{short}{instance}_{axis}"
        held = _cubic(t_med[even], v_med[even, j], unit, name, rec)
        run_odd = RunData(
            np.arange(odd.size, dtype=np.float64), t_med[odd].reshape(-1, 1), None,
            ("temperature",),
        )  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pred = held.predict(run_odd)
        fit.holdout_rms[axis] = float(np.sqrt(np.mean((v_med[odd, j] - pred) ** 2)))
        model = _cubic(t_med, v_med[:, j], unit, name, rec)
        model.signal_name, model.signal_unit = axis, unit
        model.adequacy_ = record
        model.inputs_ = {
            **model_inputs(rec, axis, ["temperature"]),
            "sensor_id": str(fit.device_id),
        }
        role = {"kind": kind, "axis": axis, "instance": instance}
        fit.channels.append(Channel(name, axis, rec.units.get(axis, unit), model, role))
    return fit


def log_topics(path: Path) -> list[tuple[str, int]]:
    """The ``sensor_gyro``/``sensor_accel``/``sensor_baro``/``sensor_mag`` instances of a ULog
    that carry a temperature
    (:func:`thermocal.readers.ulog.ulog_sensor_instances`: an unreadable log is refused, damage and
    every instance left out are said in warnings)."""
    from thermocal.readers.ulog import ulog_sensor_instances

    return ulog_sensor_instances(path, (*TOPICS, *OFFSET_TOPICS))


def calibration_of(fits: list[SensorFit]) -> Calibration:
    return Calibration([ch for f in fits for ch in f.channels])


def summary(fits: list[SensorFit]) -> dict[str, Any]:
    """The JSON summary: per sensor the sweep, bins and hold-out rms per axis."""
    return {
        f"{f.topic}.{f.instance}": {
            **{k: v for k, v in dataclasses.asdict(f).items() if k != "channels"},
            "holdout_rms_unit": f.unit,
        }
        for f in fits
    }


__all__ = [
    "BIN_WIDTH_C",
    "SensorFit",
    "calibration_of",
    "fit_sensor",
    "log_topics",
    "summary",
    "temperature_bins",
]


# --- gates (issue 28, item 5): doubtful, named in a warning --------------------------------

STALL_S = 600.0
"""A sweep that does not rise by :data:`STALL_RISE_C` for this long has stopped rising
(ArduPilot's learning ends then: AP_InertialSensor_tempcal.cpp ``CAL_TIMEOUT_MS`` = 600 s)."""
STALL_RISE_C = 0.5
"""The rise ArduPilot's learning waits for before it takes the next sample [°C]."""
END_MARGIN_C = 2.0
"""A reference temperature closer than this to an end of the calibrated range [°C]."""


class GateWarning(ThermocalWarning):
    """A calibration log that is usable but doubtful: said, named, not refused."""


def sweep_stall(time_s: FloatArray, temp_c: FloatArray) -> tuple[float, float, float]:
    """(longest time without a :data:`STALL_RISE_C` rise of the running maximum [s], the
    temperature it stalled at [°C], the time it began [s from the log's start]).  A rise:
    the running maximum enters the next 0.5 °C step above the first temperature; the
    stretch after the last rise counts too (a sweep that ends on a plateau)."""
    t = np.asarray(time_s, dtype=np.float64)
    temp = np.asarray(temp_c, dtype=np.float64)
    if t.size < 2:
        return 0.0, float(temp[0]) if temp.size else math.nan, 0.0
    level = np.floor((np.maximum.accumulate(temp) - temp[0]) / STALL_RISE_C)
    rises = [0, *(int(i) + 1 for i in np.flatnonzero(np.diff(level) > 0))]
    marks = np.array([*(t[r] for r in rises), t[-1]])
    gaps = np.diff(marks)
    k = int(np.argmax(gaps))
    return float(gaps[k]), float(temp[rises[k]]), float(marks[k] - t[0])


def stall_warning(where: str, time_s: FloatArray, temp_c: FloatArray) -> str | None:
    """The sentence of a sweep that stops rising for more than :data:`STALL_S`, or None."""
    gap, at_c, start = sweep_stall(time_s, temp_c)
    if gap <= STALL_S:
        return None
    return (
        f"{where}: the temperature sweep stops rising: {gap:.0f} s from {start:.0f} s on "
        f"without a {STALL_RISE_C:g} °C rise (at {at_c:.1f} °C); ArduPilot's own learning "
        f"ends after {STALL_S:.0f} s without one — check the heating"
    )


def step_warnings(
    fits: list[SensorFit], series: dict[str, tuple[FloatArray, FloatArray]]
) -> list[str]:
    """A step-like bias on one instance of a multi-IMU board:
    :func:`thermocal.adequacy.stillness` of every instance of a kind (``series``: name →
    (time [s], values in the canonical unit)); a step on one instance not seen on another
    within the stillness window is a bias jump of that sensor, not the board moving (which
    every instance would see)."""
    out: list[str] = []
    by_kind: dict[str, list[SensorFit]] = {}
    for f in fits:
        by_kind.setdefault(f.kind, []).append(f)
    for kind, group in by_kind.items():
        if len(group) < 2:
            continue
        floor = (
            adequacy.MOTION_FLOOR_DEG_S * adequacy.DEG_H_PER_DEG_S
            if kind == "gyro"
            else adequacy.MOTION_FLOOR_MG
        )
        steps = {}
        for f in group:
            key = f"{f.topic}.{f.instance}"
            if key in series:
                t, v = series[key]
                steps[key] = adequacy.stillness(t, v, floor).steps
        for key, mine in steps.items():
            others = [s for k, ss in steps.items() if k != key for s in ss]
            alone = [
                s for s in mine
                if not any(abs(s[0] - o[0]) <= adequacy.STILL_WINDOW_S for o in others)
            ]  # fmt: skip
            if alone:
                t0 = float(series[key][0][0])
                shown = ", ".join(f"{s[0] - t0:.0f} s" for s in alone[:5])
                out.append(
                    f"{key}: a step-like bias at {shown} that the other {kind} instance(s) do "
                    "not show — a bias jump of this sensor (not the board moving); its "
                    "calibration is doubtful"
                )
    return out


def end_warning(where: str, what: str, ref_c: float, lo: float, hi: float) -> str | None:
    """``what`` (a reference temperature) within :data:`END_MARGIN_C` of, or outside, the
    calibrated range [lo, hi] °C: the firmware clamps there, the cubic is least known."""
    if lo + END_MARGIN_C <= ref_c <= hi - END_MARGIN_C:
        return None
    return (
        f"{where}: {what} {ref_c:.1f} °C is too close to the calibration's end "
        f"({lo:.1f}…{hi:.1f} °C; within {END_MARGIN_C:g} °C or outside): the cubic is least "
        "determined there and the firmware clamps beyond it"
    )


# --- barometers and magnetometers (issue 28, item 3) -------------------------------------

OFFSET_TOPICS = {"sensor_baro": ("baro", ("pressure",), "Pa"), "sensor_mag": ("mag", AXES, "gauss")}
"""PX4 topics calibrated as offsets in the firmware's unit (uORB ``SensorBaro.msg`` pressure
[Pa], ``SensorMag.msg`` x, y, z [gauss]) with the polynomial order of their parameters
(:data:`thermocal.export.params.PX4_OFFSET_SENSORS`: 5 for TC_B, 3 for TC_M)."""


@dataclass(frozen=True)
class OffsetFit:
    """A barometer or magnetometer instance: the polynomial about ``tref_c`` per axis
    (``coefficients[axis][k]`` of ``(T − TREF)^k`` [unit], relative to the median of the
    log — the weather's pressure and the Earth's field are in the data, as PX4's own script
    fits them), judged like the IMU on held-out temperature bins (``holdout_rms`` [unit])."""

    topic: str
    kind: str
    instance: int
    device_id: int
    unit: str
    sweep_c: tuple[float, float]
    tref_c: float
    n_samples: int
    n_bins: int
    order: int
    coefficients: tuple[tuple[float, ...], ...]
    holdout_rms: dict[str, float]
    adequacy: dict[str, Any]


def fit_offset_sensor(
    time_s: FloatArray,
    temp_c: FloatArray,
    values: FloatArray,
    topic: str,
    instance: int,
    device_id: int,
    *,
    tref_c: float | None = None,
    overrides: tuple[str, ...] = (),
) -> OffsetFit:
    """Judge (:func:`thermocal.adequacy.judge`: sweep, bins, ends), bin (medians of
    :data:`BIN_WIDTH_C` bins, equal weight across the range, robust to spikes), judge on
    held-out bins (a polynomial fitted to the even bins, its rms on the odd ones) and fit a
    polynomial of PX4's order in ``T − TREF`` (TREF mid-range unless given) to every bin.
    ``values`` (n, axes) in the topic's unit (:data:`OFFSET_TOPICS`)."""
    from thermocal.export.params import PX4_OFFSET_SENSORS

    kind, fields, unit = OFFSET_TOPICS[topic]
    order = PX4_OFFSET_SENSORS[kind][1]
    where = f"{topic}.{instance}"
    vals = np.asarray(values, dtype=np.float64).reshape(len(temp_c), -1)
    temp = np.asarray(temp_c, dtype=np.float64)
    lo, hi = float(np.min(temp)), float(np.max(temp))
    tname = f"{where} temperature"
    record = (
        adequacy.judge(
            adequacy.Needs({tname: order}, order + 1), [np.asarray(time_s, dtype=np.float64)],
            [temp.reshape(-1, 1)], [tname], kind=kind, name=where, overrides=overrides,
        )
        .enforce()
        .to_dict()
    )  # fmt: skip
    rel = vals - np.median(vals, axis=0)
    _c, t_med, v_med = temperature_bins(temp, rel)
    need = max(MIN_BINS, 2 * (order + 1))
    if t_med.size < need:
        raise ThermocalInputError(
            f"{where}: the temperature covers {t_med.size} bins of {BIN_WIDTH_C:g} °C; a "
            f"polynomial of order {order} needs at least {need}: record a wider sweep"
        )
    tref = 0.5 * (lo + hi) if tref_c is None else float(tref_c)
    x = t_med - tref
    even, odd = np.arange(0, x.size, 2), np.arange(1, x.size, 2)
    coefs, rms = [], {}
    names = fields if len(fields) > 1 else ("pressure",)
    for j, name in enumerate(names):
        held = np.polynomial.polynomial.polyfit(x[even], v_med[even, j], order)
        pred = np.polynomial.polynomial.polyval(x[odd], held)
        rms[name] = float(np.sqrt(np.mean((v_med[odd, j] - pred) ** 2)))
        coefs.append(
            tuple(float(c) for c in np.polynomial.polynomial.polyfit(x, v_med[:, j], order))
        )
    return OffsetFit(
        topic, kind, instance, device_id, unit, (lo, hi), tref, int(temp.size), int(t_med.size),
        order, tuple(coefs), rms, record,
    )  # fmt: skip


def offset_summary(fits: list[OffsetFit]) -> dict[str, Any]:
    """The JSON summary of the barometers and magnetometers (as :func:`summary`)."""
    return {
        f"{f.topic}.{f.instance}": {**dataclasses.asdict(f), "holdout_rms_unit": f.unit}
        for f in fits
    }


# --- ArduPilot log hygiene (issue 28, item 4) ---------------------------------------------

AP_ROTATIONS: dict[int, str] = {
    0: "NONE", 1: "YAW_45", 2: "YAW_90", 3: "YAW_135", 4: "YAW_180", 5: "YAW_225",
    6: "YAW_270", 7: "YAW_315", 8: "ROLL_180", 9: "ROLL_180_YAW_45", 10: "ROLL_180_YAW_90",
    11: "ROLL_180_YAW_135", 12: "PITCH_180", 13: "ROLL_180_YAW_225", 14: "ROLL_180_YAW_270",
    15: "ROLL_180_YAW_315", 16: "ROLL_90", 17: "ROLL_90_YAW_45", 18: "ROLL_90_YAW_90",
    19: "ROLL_90_YAW_135", 20: "ROLL_270", 21: "ROLL_270_YAW_45", 22: "ROLL_270_YAW_90",
    23: "ROLL_270_YAW_135", 24: "PITCH_90", 25: "PITCH_270", 26: "PITCH_180_YAW_90",
    27: "PITCH_180_YAW_270", 28: "ROLL_90_PITCH_90", 29: "ROLL_180_PITCH_90",
    30: "ROLL_270_PITCH_90", 31: "ROLL_90_PITCH_180", 32: "ROLL_270_PITCH_180",
    33: "ROLL_90_PITCH_270", 34: "ROLL_180_PITCH_270", 35: "ROLL_270_PITCH_270",
    36: "ROLL_90_PITCH_180_YAW_90", 37: "ROLL_90_YAW_270", 39: "PITCH_315",
    40: "ROLL_90_PITCH_315", 41: "PITCH_7", 42: "ROLL_45", 43: "ROLL_315",
}  # fmt: skip
"""ArduPilot's ``enum Rotation`` (``libraries/AP_Math/rotations.h``), the board orientations
``AHRS_ORIENTATION`` takes, by value; 38 (``ROLL_90_PITCH_68_YAW_293``) and 100 (custom) are
not implemented and refused by name."""
AP_REFUSED_ROTATIONS = {38: "ROLL_90_PITCH_68_YAW_293", 100: "CUSTOM"}


def ardupilot_rotation(code: int) -> FloatArray:
    """The matrix ``R`` of ArduPilot rotation ``code``: ``Vector3::rotate`` gives ``R·v``
    with ``R = Rz(yaw)·Ry(pitch)·Rx(roll)`` for ``ROTATION_ROLL_r_PITCH_p_YAW_y`` (checked
    against rotations.cpp: YAW_90 is (x, y) → (−y, x), ROLL_90 is (y, z) → (−z, y), PITCH_90
    is (x, z) → (z, −x))."""
    if code not in AP_ROTATIONS:
        name = AP_REFUSED_ROTATIONS.get(code, "unknown")
        raise ThermocalInputError(
            f"AHRS_ORIENTATION {code} ({name}) is not implemented: the data cannot be rotated "
            "back to the sensor frame; calibrate from a log recorded with AHRS_ORIENTATION 0"
        )
    angles = {"ROLL": 0.0, "PITCH": 0.0, "YAW": 0.0}
    parts = AP_ROTATIONS[code].split("_")
    for axis, deg in zip(parts[::2], parts[1::2], strict=True):
        angles[axis] = math.radians(float(deg))
    cr, sr = math.cos(angles["ROLL"]), math.sin(angles["ROLL"])
    cp, sp = math.cos(angles["PITCH"]), math.sin(angles["PITCH"])
    cy, sy = math.cos(angles["YAW"]), math.sin(angles["YAW"])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    r: FloatArray = np.round(rz @ ry @ rx, 12).astype(np.float64)
    return r


AP_TREF_C = 35.0
"""ArduPilot's ``TEMP_REFERENCE`` (AP_InertialSensor_tempcal.cpp)."""


@dataclass(frozen=True)
class ActiveTcal:
    """An IMU's ``INS_TCAL<n>_*`` found in the log's parameters: ``coefficients[kind]`` the
    3×3 ``c_k`` (row k = 1…3, columns x, y, z, as stored: ×1e-6 in use), the range and the
    calibration temperatures ``INS_ACC<n>_CALTEMP``/``INS_GYR<n>_CALTEMP`` [°C]."""

    instance: int
    tmin_c: float
    tmax_c: float
    coefficients: dict[str, list[list[float]]]
    caltemp_c: dict[str, float]

    def correction(self, kind: str, temp_c: FloatArray) -> FloatArray:
        """What the firmware subtracted (AP_InertialSensor_tempcal.cpp ``correct_sensor``):
        ``poly(clamp(T) − 35) − poly(clamp(T_cal) − 35)``, ``poly(t) = (c1 + (c2 + c3·t)·t)·t
        ·1e-6``, (n, 3) [rad/s or m/s²]."""
        c = np.asarray(self.coefficients[kind], dtype=np.float64)

        def poly(t: FloatArray) -> FloatArray:
            t = t[:, None]
            out: FloatArray = (c[0] + (c[1] + c[2] * t) * t) * t * 1e-6
            return out

        t = np.clip(np.asarray(temp_c, dtype=np.float64), self.tmin_c, self.tmax_c)
        tcal = float(np.clip(self.caltemp_c[kind], self.tmin_c, self.tmax_c))
        return poly(t - AP_TREF_C) - poly(np.array([tcal - AP_TREF_C]))


def ardupilot_active(params: dict[str, float], instance: int) -> ActiveTcal | None:
    """The active temperature calibration of IMU ``instance`` in a log's ``PARM`` values
    (``INS_TCAL<n>_ENABLE`` = 1, n = instance + 1), or None."""
    n = instance + 1
    if int(params.get(f"INS_TCAL{n}_ENABLE", 0)) != 1:
        return None
    coef = {
        kind: [[params.get(f"INS_TCAL{n}_{tag}{k}_{a}", 0.0) for a in "XYZ"] for k in (1, 2, 3)]
        for kind, tag in (("accel", "ACC"), ("gyro", "GYR"))
    }
    tmin = params.get(f"INS_TCAL{n}_TMIN", 0.0)
    tmax = params.get(f"INS_TCAL{n}_TMAX", 70.0)
    cal = {
        kind: params.get(f"INS_{tag}{n}_CALTEMP", math.nan)
        for kind, tag in (("accel", "ACC"), ("gyro", "GYR"))
    }
    cal = {k: (v if math.isfinite(v) and v > -100.0 else AP_TREF_C) for k, v in cal.items()}
    return ActiveTcal(instance, tmin, tmax, coef, cal)


def ardupilot_raw(
    params: dict[str, float], instance: int, kind: str, temp_c: FloatArray, xyz: FloatArray
) -> tuple[FloatArray, ActiveTcal | None, int]:
    """Logged IMU data back to the raw sensor frame as ArduPilot's firmware produced them:
    the logged vector is ``R·(v − correction)`` (the temperature correction in the sensor
    frame, then the board's rotation ``AHRS_ORIENTATION``), so ``v = Rᵀ·logged +
    correction``.  Returns (v, the active calibration or None, the orientation code)."""
    code = int(params.get("AHRS_ORIENTATION", 0))
    out = np.asarray(xyz, dtype=np.float64)
    if code:
        out = out @ ardupilot_rotation(code)  # row vectors: (Rᵀ·v)ᵀ = vᵀ·R
    active = ardupilot_active(params, instance)
    if active is not None:
        out = out + active.correction(kind, temp_c)
    return out, active, code
