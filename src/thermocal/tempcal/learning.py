"""The firmware's own learning emulated on a flight-controller log, beside the offline fit.

With ``emulate_learning``, :func:`thermocal.tempcal.ardupilot.ardupilot_tempcal` and
:func:`thermocal.tempcal.px4.px4_tempcal` run
:func:`thermocal.firmware.learning.ardupilot_learning` (per IMU) and
:func:`thermocal.firmware.learning.px4_oncal` (per gyro and accelerometer instance) on the
samples the calibration read, and set what each firmware would have stored beside
thermocal's coefficients (the correction curves over the common range) and, for ArduPilot,
the emulated ``TCLR`` points beside those the log holds.

References
----------
* ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
* PX4-Autopilot, ``src/modules/temperature_compensation/temperature_calibration/``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal.firmware.ardupilot import AP_CURVE_FORMULA, ardupilot_poly_curve
from thermocal.firmware.learning import (
    AP_TMAX_DEFAULT_C,
    PX4_TDEL_C,
    PX4_TMAX_C,
    PX4_TMIN_C,
    ArdupilotLearning,
    LearnPoint,
    Px4Oncal,
    ardupilot_learning,
    px4_oncal,
)
from thermocal.recording import FloatArray
from thermocal.tempcal.compare import (
    PX4_CURVE_FORMULA,
    CoefficientComparison,
    compare_coefficients,
    px4_poly_curve,
)

AP_TAGS = {"accel": "ACC", "gyro": "GYR"}


@dataclass(frozen=True)
class TclrMatch:
    """The emulated ``TCLR`` points of one sensor against those the log holds.

    Attributes
    ----------
    kind : str
        ``"gyro"`` or ``"accel"``.
    n_logged, n_emulated, n_matched : int
        The points logged, emulated, and paired (each logged point with the emulated one
        nearest in time, within 1 s).
    max_temp_diff_c : float
        The largest difference of ``Temp`` over the pairs [°C] (NaN without a pair).
    max_value_diff : float
        The largest difference of ``X``/``Y``/``Z`` over the pairs [rad/s or m/s²].
    max_time_diff_s : float
        The largest difference of the times the pairs closed [s].
    """

    kind: str
    n_logged: int
    n_emulated: int
    n_matched: int
    max_temp_diff_c: float
    max_value_diff: float
    max_time_diff_s: float

    def to_dict(self) -> dict[str, Any]:
        """The match as plain values (JSON)."""
        return dataclasses.asdict(self)


def match_tclr(
    kind: str, emulated: Sequence[LearnPoint], logged_time_s: FloatArray,
    logged_temp_c: FloatArray, logged_xyz: FloatArray,
) -> TclrMatch:  # fmt: skip
    """Each logged ``TCLR`` point paired with the emulated point nearest in time.

    Parameters
    ----------
    kind : str
        ``"gyro"`` or ``"accel"``.
    emulated : sequence of LearnPoint
        The emulated points.
    logged_time_s, logged_temp_c : numpy.ndarray
        The logged points' ``TimeUS`` [s] and ``Temp`` [°C], shape (n,).
    logged_xyz : numpy.ndarray
        Their ``X``, ``Y``, ``Z``, shape (n, 3) [rad/s or m/s²].

    Returns
    -------
    TclrMatch
        The counts and the largest differences over the pairs closer than 1 s.
    """
    nan = float("nan")
    if not emulated or logged_time_s.size == 0:
        return TclrMatch(kind, int(logged_time_s.size), len(emulated), 0, nan, nan, nan)
    et = np.array([p.time_s for p in emulated])
    idx = np.clip(np.searchsorted(et, logged_time_s), 1, et.size - 1) if et.size > 1 else None
    if idx is None:
        near = np.zeros(logged_time_s.size, dtype=int)
    else:
        left = np.abs(logged_time_s - et[idx - 1]) <= np.abs(logged_time_s - et[idx])
        near = np.where(left, idx - 1, idx)
    dt = np.abs(logged_time_s - et[near])
    ok = dt <= 1.0
    if not ok.any():
        return TclrMatch(kind, int(logged_time_s.size), len(emulated), 0, nan, nan, nan)
    e_temp = np.array([emulated[i].temp_c for i in near[ok]])
    e_xyz = np.array([emulated[i].xyz for i in near[ok]])
    return TclrMatch(
        kind, int(logged_time_s.size), len(emulated), int(ok.sum()),
        float(np.max(np.abs(e_temp - logged_temp_c[ok]))),
        float(np.max(np.abs(e_xyz - logged_xyz[ok]))), float(np.max(dt[ok])),
    )  # fmt: skip


def samples_per_logged(time_s: FloatArray, driver_hz: FloatArray | None) -> float:
    """How many of the driver's samples each logged sample stands for.

    Parameters
    ----------
    time_s : numpy.ndarray
        The logged samples' times [s].
    driver_hz : numpy.ndarray or None
        The driver's sample rate logged with them (ArduPilot ``IMU.AHz``) [Hz]; None or not
        positive: 1 (each logged sample taken as one the learner saw).

    Returns
    -------
    float
        The median driver rate over the median logged rate, within 1…999.
    """
    if driver_hz is None or time_s.size < 2:
        return 1.0
    hz = np.asarray(driver_hz, dtype=np.float64)
    hz = hz[np.isfinite(hz) & (hz > 0)]
    dt = np.diff(time_s)
    dt = dt[dt > 0]
    if hz.size == 0 or dt.size == 0:
        return 1.0
    return float(np.clip(float(np.median(hz)) * float(np.median(dt)), 1.0, 999.0))


@dataclass(frozen=True)
class ArdupilotEmulation:
    """ArduPilot's learning of one IMU emulated, beside thermocal's fit and the log's
    ``TCLR``.

    Attributes
    ----------
    learning : ArdupilotLearning
        The emulation (completed or not, why, what it would store, its points).
    samples_per_sample : float
        The driver's samples each logged sample stood for.
    against_thermocal : dict of str to CoefficientComparison
        Per sensor kind, the stored coefficients' correction against thermocal's, over the
        range both cover (none when nothing would be stored).
    tclr : dict of str to TclrMatch
        Per sensor kind, the emulated points against the logged ones (empty without
        ``TCLR`` of this IMU).
    note : str
        What limits the emulation (a log slower than the driver without its rate), or "".
    """

    learning: ArdupilotLearning
    samples_per_sample: float
    against_thermocal: dict[str, CoefficientComparison]
    tclr: dict[str, TclrMatch]
    note: str = ""

    def max_difference(self, kind: str) -> float:
        """The largest difference of the two corrections of ``kind``.

        Parameters
        ----------
        kind : str
            ``"gyro"`` or ``"accel"``.

        Returns
        -------
        float
            max |emulated − thermocal| over the axes and the common range [rad/s or m/s²];
            NaN when nothing would be stored.
        """
        c = self.against_thermocal.get(kind)
        if c is None:
            return float("nan")
        return max(
            float(np.max(np.abs(np.subtract(c.old_curve[a], c.new_curve[a])))) for a in c.old_curve
        )

    def to_dict(self) -> dict[str, Any]:
        """The emulation as plain values (JSON)."""
        return {
            **self.learning.to_dict(),
            "samples_per_sample": self.samples_per_sample,
            "max_difference_to_thermocal": {
                k: self.max_difference(k) for k in self.against_thermocal
            },
            "tclr": {k: m.to_dict() for k, m in self.tclr.items()},
            "note": self.note,
        }


def _ap_range(stored: Mapping[str, float], n: int, new: Mapping[str, float]) -> tuple[float, float]:
    """The range both the stored and thermocal's coefficients cover [°C]."""
    lo = max(stored[f"INS_TCAL{n}_TMIN"], new.get(f"INS_TCAL{n}_TMIN", -np.inf))
    hi = min(stored[f"INS_TCAL{n}_TMAX"], new.get(f"INS_TCAL{n}_TMAX", np.inf))
    return (lo, hi) if hi > lo else (stored[f"INS_TCAL{n}_TMIN"], stored[f"INS_TCAL{n}_TMAX"])


def _ap_against(
    learning: ArdupilotLearning, kind: str, unit: str, new: Mapping[str, float]
) -> CoefficientComparison | None:
    """The stored coefficients of ``kind`` against thermocal's ``new`` ones."""
    n, tag = learning.instance + 1, AP_TAGS[kind]
    names = [f"INS_TCAL{n}_{tag}{k}_{a}" for k in (1, 2, 3) for a in "XYZ"]
    st = learning.stored
    if any(x not in st for x in names) or any(x not in new for x in names):
        return None

    def coef(p: Mapping[str, float]) -> list[list[float]]:
        return [[p[f"INS_TCAL{n}_{tag}{k}_{a}"] for a in "XYZ"] for k in (1, 2, 3)]

    def rng(p: Mapping[str, float]) -> tuple[float, float]:
        return p.get(f"INS_TCAL{n}_TMIN", -np.inf), p.get(f"INS_TCAL{n}_TMAX", np.inf)

    rows = [(x, st[x], new[x]) for x in (*names, f"INS_TCAL{n}_TMIN", f"INS_TCAL{n}_TMAX")
            if x in st and x in new]  # fmt: skip
    how = "completed" if learning.completed else "a partial save"
    return compare_coefficients(
        f"IMU {learning.instance} {kind}", unit, rows, _ap_range(st, n, new),
        ardupilot_poly_curve(coef(st), *rng(st)), ardupilot_poly_curve(coef(new), *rng(new)),
        AP_CURVE_FORMULA, old_key="emulated", new_key="thermocal",
        anchor="emulated-learning", old_label="the firmware's learning (emulated)",
        title="What the firmware's own learning would store, against thermocal's fit",
        intro=(
            f"ArduPilot's in-flight learning (INS_TCAL{n}_ENABLE = 2) emulated on this log's "
            f"samples ({how}): {learning.reason}."
        ),
    )  # fmt: skip


def emulate_ardupilot(
    instance: int,
    time_s: FloatArray,
    temp_c: FloatArray,
    raw: Mapping[str, FloatArray],
    *,
    parameters: Mapping[str, float],
    new_params: Mapping[str, float],
    tclr_rows: Sequence[Mapping[str, float]] = (),
    samples_per_sample: float = 1.0,
) -> ArdupilotEmulation:
    """ArduPilot's learning of IMU ``instance`` emulated on the samples of a log.

    Parameters
    ----------
    instance : int
        The IMU, 0…2.
    time_s, temp_c : numpy.ndarray
        The IMU's sample times [s] and temperatures [°C].
    raw : mapping of str to numpy.ndarray
        ``"accel"`` [m/s²] and ``"gyro"`` [rad/s], shape (n, 3): the samples in the
        sensor's frame before any temperature correction (what the learner is fed).
    parameters : mapping of str to float
        The log's parameters at its start (``INS_TCAL<n>_TMAX``: the target, default 70).
    new_params : mapping of str to float
        thermocal's ``INS_TCAL<n>_*``.
    tclr_rows : sequence of mapping
        The log's ``TCLR`` messages.
    samples_per_sample : float
        The driver's samples per logged sample (see
        :func:`thermocal.firmware.learning.ardupilot_learning`).

    Returns
    -------
    ArdupilotEmulation
        The emulation, its coefficients against thermocal's, its points against the log's.

    Raises
    ------
    thermocal.errors.ParameterError
        Arrays of mismatched shapes or not finite.
    """
    n = instance + 1
    tmax = float(parameters.get(f"INS_TCAL{n}_TMAX", AP_TMAX_DEFAULT_C))
    learning = ardupilot_learning(
        time_s, temp_c, raw["accel"], raw["gyro"], tmax_c=tmax, instance=instance,
        samples_per_sample=samples_per_sample,
    )  # fmt: skip
    units = {"accel": "m/s^2", "gyro": "rad/s"}
    against = {
        k: c for k in ("gyro", "accel") if (c := _ap_against(learning, k, units[k], new_params))
    }
    tclr: dict[str, TclrMatch] = {}
    mine = [r for r in tclr_rows if int(r.get("I", 0)) == instance]
    for kind, stype, pts in (
        ("accel", 0, learning.accel_points),
        ("gyro", 1, learning.gyro_points),
    ):
        rows = [r for r in mine if int(r.get("SType", -1)) == stype]
        if rows:
            tclr[kind] = match_tclr(
                kind, pts, np.array([float(r.get("TimeUS", 0.0)) * 1e-6 for r in rows]),
                np.array([float(r["Temp"]) for r in rows]),
                np.array([[float(r["X"]), float(r["Y"]), float(r["Z"])] for r in rows]),
            )  # fmt: skip
    note = ""
    dt = np.diff(np.asarray(time_s, dtype=np.float64))
    rate = 1.0 / float(np.median(dt[dt > 0])) if np.any(dt > 0) else float("nan")
    if samples_per_sample == 1.0 and rate < 100.0:
        note = (
            f"each logged sample ({rate:.3g} Hz) taken as one the learner saw (no driver rate "
            "in the log): the firmware sees its driver's samples (about 1 kHz), so its "
            "windows close sooner and its filter lags less than emulated here"
        )
    unpaired = [f"{m.n_logged - m.n_matched} of {m.n_logged} {k}" for k, m in tclr.items()
                if m.n_matched < m.n_logged]  # fmt: skip
    if unpaired:
        note = "; ".join(x for x in (note, (
            "logged TCLR points without an emulated one within 1 s ("
            + ", ".join(unpaired) + "): the firmware's learning starts at boot, so a log that "
            "starts later (or a driver rate other than emulated) closes other windows"
        )) if x)  # fmt: skip
    return ArdupilotEmulation(learning, samples_per_sample, against, tclr, note)


@dataclass(frozen=True)
class Px4Emulation:
    """PX4's on-board calibration of one sensor instance emulated, beside thermocal's fit.

    Attributes
    ----------
    oncal : Px4Oncal
        The emulation (completed or not, why, what it would write).
    limits : dict of str to float
        ``SYS_CAL_TDEL``, ``SYS_CAL_TMIN``, ``SYS_CAL_TMAX`` used [°C].
    against_thermocal : CoefficientComparison or None
        Its ``TC_*`` correction against thermocal's (None when it would write nothing).
    """

    oncal: Px4Oncal
    limits: dict[str, float]
    against_thermocal: CoefficientComparison | None

    def max_difference(self) -> float:
        """The largest difference of the two corrections [rad/s or m/s²]."""
        c = self.against_thermocal
        if c is None:
            return float("nan")
        return max(
            float(np.max(np.abs(np.subtract(c.old_curve[a], c.new_curve[a])))) for a in c.old_curve
        )

    def to_dict(self) -> dict[str, Any]:
        """The emulation as plain values (JSON)."""
        return {
            **self.oncal.to_dict(),
            "limits": dict(self.limits),
            "max_difference_to_thermocal": self.max_difference(),
        }


def emulate_px4(
    kind: str,
    instance: int,
    time_s: FloatArray,
    values: FloatArray,
    temp_c: FloatArray,
    *,
    parameters: Mapping[str, float],
    new_params: Mapping[str, float],
    device_id: int = 0,
) -> Px4Emulation:
    """PX4's on-board temperature calibration of one instance emulated on a log's samples.

    Parameters
    ----------
    kind : {"gyro", "accel"}
        The sensor.
    instance : int
        The instance, 0…2.
    time_s : numpy.ndarray
        Time since boot [s], shape (n,).
    values : numpy.ndarray
        The sensor's output [rad/s or m/s²], shape (n, 3).
    temp_c : numpy.ndarray
        Its temperature [°C], shape (n,).
    parameters : mapping of str to float
        The log's parameters (``SYS_CAL_TDEL``, ``SYS_CAL_TMIN``, ``SYS_CAL_TMAX``; PX4's
        defaults 24, 5, 10 when absent).
    new_params : mapping of str to float
        thermocal's ``TC_*``.
    device_id : int
        The sensor's device id (``TC_*_ID``).

    Returns
    -------
    Px4Emulation
        The emulation and its correction against thermocal's.

    Raises
    ------
    thermocal.errors.ParameterError
        Arrays of mismatched shapes, an unknown ``kind``.
    """
    limits = {
        "SYS_CAL_TDEL": float(parameters.get("SYS_CAL_TDEL", PX4_TDEL_C)),
        "SYS_CAL_TMIN": float(parameters.get("SYS_CAL_TMIN", PX4_TMIN_C)),
        "SYS_CAL_TMAX": float(parameters.get("SYS_CAL_TMAX", PX4_TMAX_C)),
    }
    oncal = px4_oncal(
        time_s, temp_c, values, kind=kind, instance=instance, tdel_c=limits["SYS_CAL_TDEL"],
        tmin_c=limits["SYS_CAL_TMIN"], tmax_c=limits["SYS_CAL_TMAX"], device_id=device_id,
    )  # fmt: skip
    tag = "G" if kind == "gyro" else "A"
    p = f"TC_{tag}{instance}_"
    keys = ["TMIN", "TMAX", "TREF"] + [f"X{k}_{a}" for k in range(4) for a in range(3)]
    against = None
    if oncal.stored and all(p + k in new_params for k in keys):
        lo = max(oncal.low_c, new_params[p + "TMIN"])
        hi = min(oncal.high_c, new_params[p + "TMAX"])
        rng = (lo, hi) if hi > lo else (oncal.low_c, oncal.high_c)
        suffixes = ("_0", "_1", "_2")
        against = compare_coefficients(
            f"{kind} {instance}", "rad/s" if kind == "gyro" else "m/s^2",
            [(p + k, oncal.stored[p + k], float(new_params[p + k])) for k in keys], rng,
            px4_poly_curve(oncal.stored, p, 3, suffixes),
            px4_poly_curve(new_params, p, 3, suffixes),
            PX4_CURVE_FORMULA, old_key="emulated", new_key="thermocal",
            anchor="emulated-learning", old_label="PX4's on-board calibration (emulated)",
            title="What PX4's on-board calibration would write, against thermocal's fit",
            intro=f"PX4's on-board temperature calibration emulated on this log: {oncal.reason}.",
        )  # fmt: skip
    return Px4Emulation(oncal, limits, against)


def px4_overall(emulated: Mapping[str, Px4Emulation]) -> dict[str, Any]:
    """The whole on-board calibration's end: PX4 writes parameters only when every sensor
    instance of every calibrator is done, and aborts all at a start above ``SYS_CAL_TMAX``.

    Parameters
    ----------
    emulated : mapping of str to Px4Emulation
        Per sensor instance (``sensor_gyro.<n>`` …).

    Returns
    -------
    dict
        ``completed`` (bool), ``reason`` (str) and ``sensors`` (each instance's emulation as
        plain values), the JSON of the PX4 calibration's emulated learning.

    References
    ----------
    - PX4-Autopilot ``temperature_calibration/task.cpp`` (``task_main``) and ``common.h``
      (``update``).
    """
    hot = [k for k, e in emulated.items() if e.oncal.outcome == "too hot"]
    short = [k for k, e in emulated.items() if not e.oncal.completed]
    if hot:
        reason = (f"aborted: {', '.join(hot)} started above SYS_CAL_TMAX; PX4 writes nothing "
                  "(cool the board below it and restart)")  # fmt: skip
    elif short:
        reason = ("not completed: " + "; ".join(f"{k} {emulated[k].oncal.reason}" for k in short)
                  + "; PX4 writes nothing until every sensor is done")  # fmt: skip
    else:
        reason = "completed: every sensor rose more than SYS_CAL_TDEL; the TC_* parameters written"
    return {
        "completed": not (hot or short),
        "reason": reason,
        "sensors": {k: e.to_dict() for k, e in emulated.items()},
    }


__all__ = [
    "ArdupilotEmulation",
    "Px4Emulation",
    "TclrMatch",
    "emulate_ardupilot",
    "emulate_px4",
    "match_tclr",
    "px4_overall",
    "samples_per_logged",
]
