"""ArduPilot's thermal calibration from one DataFlash log: ``thermocal ardupilot-tempcal``.

The ArduPilot dialect of the one pipeline (:mod:`thermocal.tempcal.pipeline`): the ``IMU``
messages (up to three instances; temperature ``T``, ``Temp`` in Copter 3.4–3.6), the
``INS_TCAL<n>_*`` parameters (a polynomial about :data:`AP_TREF_C` = 35 °C without constant,
as the firmware takes it), and the log's hygiene: the board rotation ``AHRS_ORIENTATION`` and
an active ``INS_TCAL`` the firmware had subtracted are undone before fitting
(:func:`ardupilot_raw`).  The coefficients active in the log and the firmware's own learning
(``TCLR``) are compared with the new ones; the first barometer gets ``TCAL_BARO_EXP``
(:mod:`thermocal.tempcal.ardupilot_baro`).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from thermocal.errors import ThermocalInputError
from thermocal.firmware.ardupilot import (
    AP_CURVE_FORMULA,
    AP_ROTATIONS,
    ardupilot_poly_curve,
    ardupilot_rotation,
    tclr_learned,
)
from thermocal.firmware.formats import AP_TREF_C, FORMATS
from thermocal.heater import HeaterJudgement, HeaterOptions
from thermocal.models.calibration import Calibration
from thermocal.outputs import check_outputs
from thermocal.recording import FloatArray, Recording
from thermocal.tempcal.ardupilot_baro import (
    ArdupilotBaroFit,
    baro_report_request,
    fit_ardupilot_baro,
)
from thermocal.tempcal.compare import CoefficientComparison, compare_coefficients
from thermocal.tempcal.flightlog import DataflashFlightLog, read_ardupilot_log
from thermocal.tempcal.heated import judge_instance
from thermocal.tempcal.learning import ArdupilotEmulation
from thermocal.tempcal.pipeline import (
    AXES,
    GateWarning,
    OutputSet,
    Reporter,
    ReportRequest,
    SensorFit,
    calibration_of,
    check_output_dir,
    end_warning,
    fit_sensor,
    gyro_unit_warning,
    report_worker,
    require_fields,
    staged_set,
    stall_warning,
    step_warnings,
    summary,
    warn_gates,
)
from thermocal.tempcal.thermometers import (
    TemperatureMode,
    TempsFrom,
    ThermometerPlan,
    ardupilot_plan,
    record_thermometer,
    sensor_temperature,
)

MAX_IMUS = 3
"""ArduPilot logs up to three IMUs (``IMU``, instances 0…2)."""
MESSAGES = ("IMU", "IMU2", "IMU3", "TCLR", "BARO")
"""The messages the calibration reads of a DataFlash log (``IMU2``/``IMU3``: older firmware's
second and third IMU; ``TCLR``: the firmware's own learning; ``BARO``: the barometer)."""
KINDS = (("gyro", "Gyr", "rad/s"), ("accel", "Acc", "m/s^2"))
"""(kind, field prefix of the ``IMU`` message, its unit) per sensor of an IMU."""
KIND_UNITS = {kind: unit for kind, _prefix, unit in KINDS}
NO_ALLAN = (
    "The Allan deviation of each axis is not drawn; "
    "thermocal ardupilot-tempcal LOG -o DIR --allan draws it."  # cli-words: its command
)
"""The report's note when its Allan section is left out (``allan`` False)."""
BARO_REPORT = "report_BARO_0.html"
"""The report of the first barometer's ``TCAL_BARO_EXP``."""


# --- ArduPilot log hygiene ---------------------------------------------------------------


@dataclass(frozen=True)
class ActiveTcal:
    """An IMU's ``INS_TCAL<n>_*`` found in the log's parameters: ``coefficients[kind]`` the
    3×3 ``c_k`` (row k = 1…3, columns x, y, z, as stored: ×1e-6 in use), the range and the
    calibration temperatures ``INS_ACC<n>_CALTEMP``/``INS_GYR<n>_CALTEMP`` [°C].

    Attributes
    ----------
    instance : int
        The IMU (``n`` of ``INS_TCAL<n>``).
    tmin_c, tmax_c : float
        ``INS_TCAL<n>_TMIN/TMAX`` [°C].
    coefficients : dict of str to list of list of float
        ``c_k`` per sensor kind, rows k = 1…3, columns x, y, z, as stored.
    caltemp_c : dict of str to float
        ``INS_ACC<n>_CALTEMP``/``INS_GYR<n>_CALTEMP`` [°C].
    """

    instance: int
    tmin_c: float
    tmax_c: float
    coefficients: dict[str, list[list[float]]]
    caltemp_c: dict[str, float]

    def correction(self, kind: str, temp_c: FloatArray) -> FloatArray:
        r"""What the firmware subtracted from the logged data at temperatures ``temp_c``.

        Parameters
        ----------
        kind : str
            ``"gyro"`` or ``"accel"``.
        temp_c : numpy.ndarray
            IMU temperatures, shape (n,) [°C].

        Returns
        -------
        numpy.ndarray
            Shape (n, 3), x, y, z [rad/s for a gyro, m/s² for an accelerometer].

        Notes
        -----
        With :math:`T` and :math:`T_{cal}` clamped to ``[tmin_c, tmax_c]`` and
        :math:`T_{ref} = 35` °C:

        .. math:: \Delta(T) = p(T - T_{ref}) - p(T_{cal} - T_{ref}), \qquad
           p(t) = (c_1 + (c_2 + c_3 t)\,t)\,t \cdot 10^{-6}

        References
        ----------
        - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
          (``correct_sensor``).

        Examples
        --------
        >>> import numpy as np
        >>> p = {"INS_TCAL1_ENABLE": 1, "INS_TCAL1_GYR1_X": 100.0, "INS_TCAL1_TMIN": 0.0,
        ...      "INS_TCAL1_TMAX": 70.0, "INS_GYR1_CALTEMP": 35.0}
        >>> active = ardupilot_active(p, 0)
        >>> [round(float(x), 6) for x in active.correction("gyro", np.array([45.0]))[0]]
        [0.001, 0.0, 0.0]
        """
        c = np.asarray(self.coefficients[kind], dtype=np.float64)

        def poly(t: FloatArray) -> FloatArray:
            t = t[:, None]
            out: FloatArray = (c[0] + (c[1] + c[2] * t) * t) * t * 1e-6
            return out

        t = np.clip(np.asarray(temp_c, dtype=np.float64), self.tmin_c, self.tmax_c)
        tcal = float(np.clip(self.caltemp_c[kind], self.tmin_c, self.tmax_c))
        return poly(t - AP_TREF_C) - poly(np.array([tcal - AP_TREF_C]))


def ardupilot_comparison(
    active: ActiveTcal, new_params: Mapping[str, float], kind: str, unit: str,
    sweep_c: tuple[float, float],
) -> CoefficientComparison:  # fmt: skip
    """The coefficients active in the log against the new ``INS_TCAL<n>_*`` of one sensor.

    Parameters
    ----------
    active : ActiveTcal
        The calibration active in the log (IMU ``active.instance``).
    new_params : mapping of str to float
        The new parameters (``INS_TCAL<n>_*``; coefficients as stored, ×1e-6 in use).
    kind : str
        ``"gyro"`` or ``"accel"``.
    unit : str
        Unit of the corrections shown (``rad/s`` or ``m/s^2``).
    sweep_c : tuple of float
        The temperature sweep ``(lo, hi)`` over which both corrections are drawn [°C].

    Returns
    -------
    thermocal.tempcal.compare.CoefficientComparison
        Each parameter old → new, and both corrections
        (:func:`thermocal.firmware.ardupilot.ardupilot_poly_curve`, each clamped to its own
        TMIN…TMAX) over ``sweep_c``.

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
    """
    n = active.instance + 1
    tag = "GYR" if kind == "gyro" else "ACC"
    names = [[f"INS_TCAL{n}_{tag}{k}_{a}" for a in "XYZ"] for k in (1, 2, 3)]
    new = [[float(new_params[p]) for p in row] for row in names]
    old = active.coefficients[kind]
    rows = [(names[k][j], old[k][j], new[k][j]) for k in range(3) for j in range(3)]
    rows += [
        (f"INS_TCAL{n}_TMIN", active.tmin_c, float(new_params[f"INS_TCAL{n}_TMIN"])),
        (f"INS_TCAL{n}_TMAX", active.tmax_c, float(new_params[f"INS_TCAL{n}_TMAX"])),
    ]
    return compare_coefficients(
        f"IMU.{active.instance} {kind}", unit, rows, sweep_c,
        ardupilot_poly_curve(old, active.tmin_c, active.tmax_c),
        ardupilot_poly_curve(new, new_params[f"INS_TCAL{n}_TMIN"],
                             new_params[f"INS_TCAL{n}_TMAX"]),
        AP_CURVE_FORMULA,
    )  # fmt: skip


def ardupilot_active(params: dict[str, float], instance: int) -> ActiveTcal | None:
    """The active temperature calibration of IMU ``instance`` in a log's ``PARM`` values.

    Active when ``INS_TCAL<n>_ENABLE`` = 1 (n = instance + 1).  Missing coefficients are 0,
    a missing range 0…70 °C, a missing or unset ``CALTEMP`` (NaN or ≤ -100) 35 °C.

    Parameters
    ----------
    params : dict of str to float
        The log's parameter values.
    instance : int
        IMU instance (0, 1, 2).

    Returns
    -------
    ActiveTcal or None
        The calibration, or None when not enabled.

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
    """
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
    r"""Logged IMU data back to the raw sensor frame, as ArduPilot's firmware produced them.

    Parameters
    ----------
    params : dict of str to float
        The parameters in force (``AHRS_ORIENTATION``, ``INS_TCAL<n>_*``, ``CALTEMP``).
    instance : int
        IMU instance (0, 1, 2).
    kind : str
        ``"gyro"`` or ``"accel"``.
    temp_c : numpy.ndarray
        IMU temperatures, shape (n,) [°C].
    xyz : numpy.ndarray
        Logged vectors, shape (n, 3) [rad/s or m/s²].

    Returns
    -------
    tuple
        (raw vectors (n, 3) [rad/s or m/s²], the active calibration or None, the orientation
        code).

    Raises
    ------
    ThermocalInputError
        When ``AHRS_ORIENTATION`` is not an integer.

    Notes
    -----
    The logged vector is the board rotation :math:`R` (``AHRS_ORIENTATION``) of the sensor
    vector less the temperature correction :math:`\Delta(T)` (:meth:`ActiveTcal.correction`):

    .. math:: \ell = R\,(v - \Delta(T)) \quad\Longrightarrow\quad v = R^\mathsf{T} \ell + \Delta(T)

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
      (``correct_sensor``) and ``libraries/AP_Math/rotations.h``.

    Examples
    --------
    >>> import numpy as np
    >>> v, active, code = ardupilot_raw({"AHRS_ORIENTATION": 0}, 0, "gyro",
    ...                                  np.array([30.0]), np.array([[0.1, 0.2, 0.3]]))
    >>> v.tolist(), active, code
    ([[0.1, 0.2, 0.3]], None, 0)
    """
    value = params.get("AHRS_ORIENTATION", 0)
    if not (math.isfinite(value) and float(value).is_integer()):
        raise ThermocalInputError(  # int(2.5) would rotate by YAW_90 without a word
            f"AHRS_ORIENTATION {value:g} is not a rotation code (an integer): the data cannot "
            "be rotated back to the sensor frame"
        )
    code = int(value)
    out = np.asarray(xyz, dtype=np.float64)
    if code:
        out = out @ ardupilot_rotation(code)  # row vectors: (Rᵀ·v)ᵀ = vᵀ·R
    active = ardupilot_active(params, instance)
    if active is not None:
        out = out + active.correction(kind, temp_c)
    return out, active, code


def imu_hygiene_params(name: str, instance: int) -> bool:
    """Whether parameter ``name`` changes what the firmware did to IMU ``instance``'s data.

    Parameters
    ----------
    name : str
        A parameter name.
    instance : int
        IMU instance (0, 1, 2); n = instance + 1 in the names.

    Returns
    -------
    bool
        True for ``AHRS_ORIENTATION``, ``INS_TCAL<n>_*``, ``INS_ACC<n>_CALTEMP`` and
        ``INS_GYR<n>_CALTEMP``.
    """
    n = instance + 1
    return name == "AHRS_ORIENTATION" or name.startswith(f"INS_TCAL{n}_") or name in (
        f"INS_ACC{n}_CALTEMP", f"INS_GYR{n}_CALTEMP",
    )  # fmt: skip


@dataclass(frozen=True)
class ParamInterval:
    """A stretch of the log ``[start_s, end_s)`` [s, the log's ``TimeUS`` clock; ±inf at the
    ends] over which the parameters ``params`` were in force.

    Attributes
    ----------
    start_s, end_s : float
        The stretch [s, ``TimeUS`` clock; ±inf at the ends].
    params : dict of str to float
        The parameters in force.
    """

    start_s: float
    end_s: float
    params: dict[str, float]


NOTE_CHANGES = 50
"""Parameter changes a note names one by one (the JSON's ``parameter_changes`` holds all):
a whole INS_TCAL set replaced twice (2 × 22 values) is named in full."""


def param_intervals(
    initial: Mapping[str, float], changes: Sequence[Any], relevant: Callable[[str], bool]
) -> tuple[list[ParamInterval], list[Any]]:
    """The log cut where a relevant parameter changed, each piece with the values in force.

    ArduPilot reads ``INS_TCAL*``, its ``CALTEMP`` and ``AHRS_ORIENTATION`` live
    (``correct_sensor`` reads the parameters at each sample), so a sample logged at ``t`` was
    corrected with the values set last before ``t``.

    Parameters
    ----------
    initial : mapping of str to float
        The parameter values at the start of the log.
    changes : sequence of thermocal.readers.dataflash.ParamChange
        The parameter changes, in log order (time [s], name, old, new).
    relevant : callable
        ``relevant(name)``: whether a change cuts the log (:func:`imu_hygiene_params`).

    Returns
    -------
    tuple
        (the intervals ``[start_s, end_s)`` [s] with their parameters, the relevant changes).

    Raises
    ------
    ThermocalInputError
        When a relevant parameter (other than a ``CALTEMP``) is set to a value that is not a
        number.

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
    """
    cur = dict(initial)
    out: list[ParamInterval] = []
    used = [c for c in changes if relevant(c.name)]
    bad = next((c for c in used if not math.isfinite(c.new) and "CALTEMP" not in c.name), None)
    if bad is not None:  # (a CALTEMP not finite is the firmware's "not set", AP_TREF_C)
        raise ThermocalInputError(
            f"{bad.name} set to {bad.new} at log time {bad.time_s:.3f} s: the samples after it "
            "cannot be undone (the firmware corrected them with a value that is not a number)"
        )
    start = -math.inf
    for c in used:
        if c.time_s > start:
            out.append(ParamInterval(start, c.time_s, dict(cur)))
            start = c.time_s
        cur[c.name] = c.new
    out.append(ParamInterval(start, math.inf, dict(cur)))
    return out, used


def ardupilot_raw_intervals(
    intervals: Sequence[ParamInterval], instance: int, kind: str, time_s: FloatArray,
    temp_c: FloatArray, xyz: FloatArray,
) -> tuple[FloatArray, list[ActiveTcal | None], list[int]]:  # fmt: skip
    """:func:`ardupilot_raw` per interval: each sample undone with the parameters then in force.

    Parameters
    ----------
    intervals : sequence of ParamInterval
        The intervals of :func:`param_intervals`, in time order.
    instance : int
        IMU instance (0, 1, 2).
    kind : str
        ``"gyro"`` or ``"accel"``.
    time_s : numpy.ndarray
        Sample times (n,) [s, the log's clock].
    temp_c : numpy.ndarray
        IMU temperatures (n,) [°C].
    xyz : numpy.ndarray
        Logged vectors (n, 3) [rad/s or m/s²].

    Returns
    -------
    tuple
        (raw vectors (n, 3), per interval the active calibration or None, per interval the
        orientation code).

    Raises
    ------
    ThermocalInputError
        When an interval's ``AHRS_ORIENTATION`` is not an integer.
    """
    out = np.asarray(xyz, dtype=np.float64).copy()
    if len(intervals) == 1:  # no change in the log: every sample at once, no regrouping
        part, active, code = ardupilot_raw(intervals[0].params, instance, kind, temp_c, out)
        out[:] = part
        return out, [active], [code]
    actives: list[ActiveTcal | None] = []
    codes: list[int] = []
    # each sample's interval, the samples grouped by it (one pass, not a mask per interval:
    # a parameter set at every sample makes as many intervals as samples)
    starts = np.array([iv.start_s for iv in intervals[1:]], dtype=np.float64)
    which = np.searchsorted(starts, np.asarray(time_s, dtype=np.float64), side="right")
    order = np.argsort(which, kind="stable")
    bounds = np.searchsorted(which[order], np.arange(len(intervals) + 1), side="left")
    for k, iv in enumerate(intervals):
        sel = order[bounds[k] : bounds[k + 1]]
        part, active, code = ardupilot_raw(iv.params, instance, kind, temp_c[sel], out[sel])
        out[sel] = part
        actives.append(active)
        codes.append(code)
    return out, actives, codes


# --- the firmware's own learning: TCLR ----------------------------------------------------------

TCLR_STYPES = {"accel": 0, "gyro": 1}
"""``TCLR`` (AP_InertialSensor_tempcal.cpp ``Learn::add_sample``: ``AP::logger().Write("TCLR",
"TimeUS,I,SType,Temp,X,Y,Z,NSamp", "s#------", "F000000-", "QBBffffI", …)``): IMU ``I``,
sensor ``SType`` (0 accelerometer, 1 gyro), ``Temp`` the mid temperature of the averaging
window [°C], ``X, Y, Z`` the mean of ``NSamp`` (≥ 100) samples over a ≥ 0.5 °C rise in the
sensor's frame before the temperature correction [m/s², relative to the first window's
mean, or rad/s], logged while ``INS_TCAL<n>_ENABLE`` = 2 (learning)."""


def tclr_points(
    rows: Sequence[Mapping[str, float]], instance: int, kind: str
) -> tuple[FloatArray, FloatArray]:
    """The ``TCLR`` points of IMU ``instance``'s ``kind``.

    Parameters
    ----------
    rows : sequence of mapping
        The log's ``TCLR`` messages (fields ``I``, ``SType``, ``Temp``, ``X``, ``Y``, ``Z``).
    instance : int
        IMU instance (0, 1, 2).
    kind : str
        ``"gyro"`` (SType 1) or ``"accel"`` (SType 0).

    Returns
    -------
    tuple of numpy.ndarray
        (``Temp`` (n,) [°C], ``X``/``Y``/``Z`` (n, 3) [rad/s or m/s²]).

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
      (``Learn::add_sample``).
    """
    st = TCLR_STYPES[kind]
    sel = [r for r in rows if int(r.get("I", 0)) == instance and int(r.get("SType", -1)) == st]
    temp = np.array([r["Temp"] for r in sel], dtype=np.float64)
    xyz = np.array([[r["X"], r["Y"], r["Z"]] for r in sel], dtype=np.float64).reshape(-1, 3)
    return temp, xyz


@dataclass(frozen=True)
class TclrRange:
    """The range ``TMIN…TMAX`` [°C] the firmware saves with its learned coefficients of one
    IMU (both its sensors: ``INS_TCAL<n>_TMIN/TMAX`` are per IMU), and where it was found.

    Attributes
    ----------
    tmin_c, tmax_c : float
        The range [°C].
    source : str
        Where it was found.
    """

    tmin_c: float
    tmax_c: float
    source: str


def tclr_range(
    rows: Sequence[Mapping[str, float]], instance: int, changes: Sequence[Any],
    imu_time_s: FloatArray, imu_temp_c: FloatArray,
) -> TclrRange | None:  # fmt: skip
    """IMU ``instance``'s learned range as the firmware defines it.

    ``Learn::save_calibration`` saves ``temp_min = start_temp``, ``temp_max = temperature``:
    ``start_temp`` is the mid temperature of the accelerometer's first window (its first
    ``TCLR`` with SType 0), ``temperature`` the (filtered) temperature when the last window
    closed.  In order of preference: the ``INS_TCAL<n>_TMIN/TMAX`` the firmware saved during
    the log (set at or after the instance's first ``TCLR``: exact); else TMIN from the first
    accelerometer window and TMAX the IMU temperature at the last ``TCLR``'s ``TimeUS``; else
    (times outside the IMU's) the highest window temperature, a lower bound.

    Parameters
    ----------
    rows : sequence of mapping
        The log's ``TCLR`` messages.
    instance : int
        IMU instance (0, 1, 2).
    changes : sequence of thermocal.readers.dataflash.ParamChange
        The log's parameter changes (time [s], name, old, new).
    imu_time_s : numpy.ndarray
        The IMU's sample times [s].
    imu_temp_c : numpy.ndarray
        The IMU's temperatures [°C].

    Returns
    -------
    TclrRange or None
        TMIN, TMAX [°C] and how they were found; None without ``TCLR`` of this IMU.

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
    """
    mine = [r for r in rows if int(r.get("I", 0)) == instance and "Temp" in r]
    if not mine:
        return None
    acc = [r for r in mine if int(r.get("SType", -1)) == TCLR_STYPES["accel"]]
    t_first = min(float(r.get("TimeUS", 0.0)) for r in mine) * 1e-6
    t_last = max(float(r.get("TimeUS", 0.0)) for r in mine) * 1e-6
    n = instance + 1
    lo_name, hi_name = f"INS_TCAL{n}_TMIN", f"INS_TCAL{n}_TMAX"
    saved = {c.name: c.new for c in changes if c.name in (lo_name, hi_name) and c.time_s >= t_first}
    if len(saved) == 2:
        return TclrRange(
            saved[lo_name], saved[hi_name], f"{lo_name}/TMAX as the firmware saved them in the log"
        )
    tmin = float(acc[0]["Temp"]) if acc else min(float(r["Temp"]) for r in mine)
    how = "TMIN the accelerometer's first window" if acc else "TMIN the lowest window"
    t = np.asarray(imu_time_s, dtype=np.float64)
    ok = np.isfinite(t) & np.isfinite(np.asarray(imu_temp_c, dtype=np.float64))
    if ok.any() and t[ok][0] <= t_last <= t[ok][-1]:
        tmax = float(np.interp(t_last, t[ok], np.asarray(imu_temp_c, dtype=np.float64)[ok]))
        how += ", TMAX the IMU temperature when the last window closed"
    else:
        tmax = max(float(r["Temp"]) for r in mine)
        how += ", TMAX the highest window (a lower bound: the firmware's is its end)"
    return TclrRange(tmin, max(tmax, tmin), how + " (AP_InertialSensor_tempcal.cpp)")


def tclr_comparison(
    rows: Sequence[Mapping[str, float]], instance: int, kind: str, unit: str,
    new_params: Mapping[str, float], sweep_c: tuple[float, float], learned_range: TclrRange,
) -> CoefficientComparison | None:  # fmt: skip
    """The firmware's learned coefficients of one sensor against thermocal's.

    Parameters
    ----------
    rows : sequence of mapping
        The log's ``TCLR`` messages.
    instance : int
        IMU instance (0, 1, 2).
    kind : str
        ``"gyro"`` or ``"accel"``.
    unit : str
        Unit of the corrections shown (``rad/s`` or ``m/s^2``).
    new_params : mapping of str to float
        thermocal's ``INS_TCAL<n>_*``.
    sweep_c : tuple of float
        The temperature sweep ``(lo, hi)`` [°C].
    learned_range : TclrRange
        The IMU's learned range (:func:`tclr_range`) [°C].

    Returns
    -------
    thermocal.tempcal.compare.CoefficientComparison or None
        The comparison (:func:`thermocal.firmware.ardupilot.tclr_learned` of the ``TCLR``
        points: a least-squares cubic in T − 35 °C); None with fewer than 4 points at distinct
        temperatures (no cubic).

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
      (``Learn::finish_calibration``).
    """
    temp, xyz = tclr_points(rows, instance, kind)
    if np.unique(temp).size < 4:
        return None
    learned = tclr_learned(temp, xyz)
    tmin, tmax = learned_range.tmin_c, learned_range.tmax_c
    fw = ActiveTcal(instance, tmin, tmax, {kind: learned}, {kind: AP_TREF_C})
    cmp = ardupilot_comparison(fw, new_params, kind, unit, sweep_c)
    return dataclasses.replace(
        cmp, old_key="firmware", new_key="thermocal", anchor="firmware-learning",
        title="The firmware's own learning (TCLR) against thermocal's coefficients",
        old_label="firmware (TCLR)",
        intro=(
            f"The log holds {temp.size} TCLR points of this sensor "
            f"({float(np.min(temp)):.1f}…{float(np.max(temp)):.1f} °C): the firmware's own "
            "temperature learning; its coefficients are restated here as the firmware "
            "computes them (a least-squares cubic of the points in T − 35 °C), valid over "
            f"the IMU's learned range {tmin:.2f}…{tmax:.2f} °C ({learned_range.source})."
        ),
    )  # fmt: skip


# --- the whole command -----------------------------------------------------------------------


@dataclass(frozen=True)
class ArdupilotTempcalResult:
    """What :func:`ardupilot_tempcal` wrote and found: the files of the set, every IMU
    sensor's fit, the parameter file's notes and the log's hygiene (``AHRS_ORIENTATION``,
    per IMU the active ``INS_TCAL`` removed and its coefficients old → new); per sensor
    (``IMU.Gyr.<n>``/``IMU.Acc.<n>``) the active coefficients against the new ones
    (``previous``) and the firmware's own learning against them (``firmware_learning``,
    from ``TCLR``); the first barometer's ``TCAL_BARO_EXP`` (``baro``).

    Attributes
    ----------
    log : Path
        The log read.
    params_path, calibration_path : Path
        The parameter file and the calibration file.
    reports : tuple of Path
        The HTML reports.
    fits : tuple of SensorFit
        Every IMU sensor's fit.
    notes : tuple of str
        The parameter file's notes.
    orientation : int
        ``AHRS_ORIENTATION`` at the end of the log.
    hygiene : dict
        Per IMU, the active ``INS_TCAL`` removed and its coefficients old → new.
    previous : dict of str to CoefficientComparison
        Per sensor, the active coefficients against the new ones.
    firmware_learning : dict of str to CoefficientComparison
        Per sensor, the firmware's learning (``TCLR``) against the new ones.
    baro : ArdupilotBaroFit or None
        The first barometer's ``TCAL_BARO_EXP``.
    rotated : bool
        Some data were recorded with ``AHRS_ORIENTATION`` ≠ 0.
    parameter_changes : tuple of dict
        The changes of the undone parameters during the log.
    """

    log: Path
    params_path: Path
    calibration_path: Path
    reports: tuple[Path, ...]
    fits: tuple[SensorFit, ...]
    notes: tuple[str, ...]
    orientation: int
    hygiene: dict[str, dict[str, Any]]
    previous: dict[str, CoefficientComparison] = dataclasses.field(default_factory=dict)
    firmware_learning: dict[str, CoefficientComparison] = dataclasses.field(default_factory=dict)
    baro: ArdupilotBaroFit | None = None
    rotated: bool = False
    """Some of the data were recorded with ``AHRS_ORIENTATION`` ≠ 0 (``orientation`` is the
    value at the end of the log)."""
    parameter_changes: tuple[dict[str, Any], ...] = ()
    """The changes during the log of the parameters undone (``time_s`` [s], ``name``,
    ``old``, ``new``); the data were undone per interval."""
    emulated_learning: dict[str, ArdupilotEmulation] = dataclasses.field(default_factory=dict)
    """Per IMU (``IMU.<n>``), the firmware's in-flight learning emulated on the log
    (``emulate_learning``; :mod:`thermocal.tempcal.learning`)."""

    @property
    def active_found(self) -> list[str]:
        """The IMUs whose active ``INS_TCAL`` was removed from the data."""
        return [k for k, h in self.hygiene.items() if h["active_tcal_removed"]]

    def to_dict(self) -> dict[str, Any]:
        """The result as a JSON object (what the ``ardupilot-tempcal`` command prints as JSON)."""
        return {
            "log": str(self.log),
            "params": str(self.params_path),
            "calibration": str(self.calibration_path),
            "reports": [str(p) for p in self.reports],
            "sensors": {
                k: {
                    **v,
                    "previous": p.to_dict() if (p := self.previous.get(k)) else None,
                    "firmware_learning": f.to_dict()
                    if (f := self.firmware_learning.get(k))
                    else None,
                }
                for k, v in summary(self.fits).items()
            }
            | ({f"BARO.{self.baro.instance}": self.baro.to_dict()} if self.baro else {}),
            "notes": list(self.notes),
            "log_hygiene": {
                "AHRS_ORIENTATION": self.orientation,
                "rotated_back_to_sensor_frame": self.rotated or self.orientation != 0,
                "parameter_changes": list(self.parameter_changes),
                "imus": self.hygiene,
            },
        } | (
            {"emulated_learning": {k: e.to_dict() for k, e in self.emulated_learning.items()}}
            if self.emulated_learning
            else {}
        )


@dataclass
class _Run:
    """The state of one :func:`ardupilot_tempcal` run across its IMUs."""

    log: Path
    flight: DataflashFlightLog
    overrides: tuple[str, ...]
    params: Any
    out_set: OutputSet
    fits: list[SensorFit]
    gates: list[str | None]
    series: dict[str, tuple[FloatArray, FloatArray]]
    hygiene: dict[str, dict[str, Any]]
    orientation: int = 0
    rotated: bool = False
    param_notes: list[str] = dataclasses.field(default_factory=list)
    previous: dict[str, CoefficientComparison] = dataclasses.field(default_factory=dict)
    learning: dict[str, CoefficientComparison] = dataclasses.field(default_factory=dict)
    baro: ArdupilotBaroFit | None = None
    allan: bool = False
    """The gyro and accelerometer reports draw each axis's Allan deviation."""
    heater: HeaterOptions = dataclasses.field(default_factory=HeaterOptions)
    """How each IMU's heater hold is looked for (:func:`.heated.judge_instance`)."""
    motions: dict[str, Any] = dataclasses.field(default_factory=dict)
    """Each instance's stillness from its fit (:func:`.pipeline.fit_sensor`), for the step
    warnings (computed once)."""
    emulate: bool = False
    """The firmware's in-flight learning is emulated on each IMU."""
    emulated: dict[str, ArdupilotEmulation] = dataclasses.field(default_factory=dict)
    plan: ThermometerPlan = dataclasses.field(default_factory=ThermometerPlan)
    """The temperature each IMU is fitted on (:mod:`.thermometers`)."""


def ardupilot_tempcal(
    log: Path,
    output: Path,
    *,
    overrides: tuple[str, ...] = (),
    reporter: Reporter | None = None,
    allan: bool = False,
    heater: HeaterOptions | None = None,
    emulate_learning: bool = False,
    temperature: TemperatureMode = "reconstructed",
    temps_from: TempsFrom | None = None,
) -> ArdupilotTempcalResult:
    """ArduPilot's thermal calibration of every IMU of a DataFlash log, written as one set.

    Parameters
    ----------
    log : Path
        An ArduPilot DataFlash log (``.bin``) with ``IMU`` messages over a temperature sweep.
    output : Path
        The directory of the set: ``calibration.json``, ``ardupilot.parm``
        (``INS_TCAL<n>_*``), ``report_IMU_<n>_<kind>.html`` per sensor and the first
        barometer's ``TCAL_BARO_EXP`` report; built beside it and moved into place whole.
    overrides : tuple of str
        Adequacy checks let through (``"narrow"``, ``"motion"``).
    reporter : callable, optional
        Writes one report (the presentation layer's); None: no report written.
    allan : bool, optional
        The gyro and accelerometer reports draw each axis's overlapping Allan deviation
        before and after compensation with its noise terms (IEEE Std 952-1997 Annex C);
        default False: left out (on a long log, most of a report's cost).
    heater : HeaterOptions, optional
        The heater's hold (:class:`thermocal.heater.HeaterOptions`; default: the set-point
        ``BRD_HEAT_TARG``/``BRD_IMU_TARGTEMP`` unless −1, else inferred), looked for in
        the temperature fitted on (``temperature``, ``temps_from``).
    emulate_learning : bool, optional
        Also emulate the firmware's learning on each IMU (:mod:`thermocal.tempcal.learning`).
    temperature : {"reconstructed", "raw"}, optional
        A quantised or slow thermometer (:mod:`thermocal.thermometer`) is fitted on the
        temperature reconstructed at each sample (default), or on its reading as logged.
    temps_from : TempsFrom, optional
        Calibrate against another IMU's (or ``BARO`` 0's) thermometer, joined by time
        (:func:`.thermometers.sensor_temperature`); default each IMU its own.

    Returns
    -------
    ArdupilotTempcalResult
        The files written, each sensor's fit, the log's hygiene (rotation undone, an active
        ``INS_TCAL`` removed), the previous and the firmware-learned coefficients compared.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        An unreadable log, no IMU with a usable temperature, a sweep narrower than
        ArduPilot's 10 °C or otherwise inadequate unless overridden, a board rotation that
        cannot be undone, an output that is the log or not a directory.

    Notes
    -----
    Each IMU's gyro and accelerometer go through the pipeline (:func:`.pipeline.fit_sensor`
    with ArduPilot's minimum sweep) after the log's hygiene (:func:`ardupilot_raw`); an IMU
    whose temperature is all 0 or NaN is left out with a warning.  The firmware subtracts

    .. math::

        p(\\operatorname{clamp}(T) - 35) - p(T_\\mathrm{cal} - 35), \\qquad
        p(t) = (c_1 + (c_2 + c_3 t)\\,t)\\,t \\cdot 10^{-6} .

    References
    ----------
    * ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``,
      https://github.com/ArduPilot/ardupilot/blob/master/libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp
    * ArduPilot, ``libraries/AP_TempCalibration/AP_TempCalibration.cpp`` (the barometer).
    """
    from thermocal.export.params import ParamSet

    _check_set(log, output)
    with (
        report_worker(reporter, log) as pool,  # starts while the log is read
        staged_set(output, reporter, pool) as out_set,  # moved into place whole, or removed
    ):
        flight = read_ardupilot_log(log, MESSAGES)  # the log is read once, passed down
        run = _Run(log, flight, overrides, ParamSet("ardupilot"), out_set, [], [], {}, {})
        run.allan, run.heater, run.emulate = allan, heater or HeaterOptions(), emulate_learning
        run.plan = ardupilot_plan(flight, temperature, temps_from)
        _imus(run)
        if not run.fits:
            raise ThermocalInputError(f"{log}: no IMU with a usable temperature in the log")
        _commit(run)
    return ArdupilotTempcalResult(
        log, output / FORMATS["ardupilot"].params_file, output / "calibration.json",
        tuple(out_set.reports), tuple(run.fits), tuple(_run_notes(run)), run.orientation,
        run.hygiene, run.previous, run.learning, run.baro, run.rotated, _changes_said(run),
        run.emulated,
    )  # fmt: skip


def _check_set(log: Path, output: Path) -> None:
    """Refuse an output set that would overwrite the log (DIR may hold the log; the files of
    the set, replaced by name, may not be it) or that is not a directory."""
    names = ["calibration.json", FORMATS["ardupilot"].params_file, BARO_REPORT]
    names += [f"report_IMU_{i}_{k}.html" for i in range(MAX_IMUS) for k in ("gyro", "accel")]
    check_outputs([output / n for n in names], [log], dirs=[output])
    check_output_dir(output)


def _commit(run: _Run) -> None:
    """The end of a run once its IMUs are fitted: the barometer, the step warnings across
    instances, the gates said, the parameters checked and the set committed."""
    from thermocal.export.params import check_documented, check_values

    _baro(run)
    run.gates.extend(step_warnings(run.fits, run.series, run.motions))
    warn_gates(run.gates)
    check_values(run.params)
    check_documented(run.params)
    run.out_set.commit(
        calibration_of(run.fits), FORMATS["ardupilot"].params_file, run.params.text()
    )


def _run_notes(run: _Run) -> list[str]:
    """The notes of an :func:`ardupilot_tempcal` run: the parameter file's, the log's
    hygiene (an active ``INS_TCAL`` removed, a rotation undone), the firmware's learning
    found, the barometer's exponent and the parameter changes during the recording."""
    notes = list(run.params.notes)
    found = [k for k, h in run.hygiene.items() if h["active_tcal_removed"]]
    if found:
        notes.append(
            "active INS_TCAL coefficients found in the log and removed from the data before "
            "fitting (the firmware had subtracted them): " + ", ".join(found)
        )
    if run.learning:
        notes.append(
            "the firmware's own temperature learning (TCLR) found in the log for "
            + ", ".join(run.learning)
            + ": its coefficients restated and compared with thermocal's (firmware_learning)"
        )
    if run.baro is not None:
        b = run.baro
        notes.append(
            f"BARO.0: TCAL_BARO_EXP {b.exponent:.4g} (ArduPilot's barometer temperature "
            f"correction max(T − 25, 0)^e Pa, AP_TempCalibration): rms over the temperature "
            f"bins {b.rms_before_pa:.3g} → {b.rms_after_pa:.3g} Pa, hold-out "
            f"{b.holdout_rms_pa:.3g} Pa"
        )
    notes.extend(run.param_notes)
    if run.orientation:
        notes.append(
            f"AHRS_ORIENTATION {run.orientation} ({AP_ROTATIONS[run.orientation]}): the data "
            "were rotated back to the sensor frame before fitting"
        )
    return notes


def _changes_said(run: _Run) -> tuple[dict[str, Any], ...]:
    """Every change of a parameter undone for some IMU, once, in log order."""
    seen: dict[tuple[Any, ...], dict[str, Any]] = {}  # keyed: a list search is O(n²)
    for h in run.hygiene.values():
        for c in h.get("parameter_changes", []):
            seen.setdefault((c["time_s"], c["name"], c["old"], c["new"]), c)
    return tuple(sorted(seen.values(), key=lambda c: float(c["time_s"])))


_IMU_FIELDS = ("T", "Temp", *(f"{p}{a}" for p in ("Gyr", "Acc") for a in "XYZ"), "AHz")
"""The fields of ``IMU`` the calibration reads (besides ``TimeUS``; ``AHz``, the driver's
rate, only when the log has it: the learning's emulation reads it)."""


@dataclass
class _ImuData:
    """One IMU's samples as its fits take them, copied out of the log's table (which is
    then dropped): times [s], temperatures [°C], the logged vectors per kind (n, 3); or the
    sentence it is left out with, or the error it is refused with (each said at its turn)."""

    inst: int
    time_s: FloatArray | None = None
    temp_c: FloatArray | None = None
    xyz: dict[str, FloatArray] = dataclasses.field(default_factory=dict)
    left_out: str | None = None
    error: ThermocalInputError | None = None
    ahz: FloatArray | None = None
    """The driver's sample rate ``AHz`` [Hz] per row, when the log has it and the firmware's
    learning is emulated (:func:`_emulate`)."""


def _imu_data(run: _Run, inst: int) -> _ImuData:
    """IMU ``inst``'s samples (:class:`_ImuData`) from a table of only the fields read;
    raises ``MissingColumnError`` when the log has no such instance."""
    df, _info = run.flight.table("IMU", inst, _IMU_FIELDS)
    if not {"T", "Temp"} & set(df.columns) or not set(_IMU_FIELDS[2:8]) <= set(df.columns):
        df, _info = run.flight.table("IMU", inst)  # every field: the refusal names them
    try:
        temp_c = _imu_temperature(run, df, inst)
    except ThermocalInputError as exc:
        return _ImuData(inst, error=exc)
    if isinstance(temp_c, str):
        return _ImuData(inst, left_out=temp_c)
    xyz = {
        kind: _compact(np.column_stack([df[f"{prefix}{a.upper()}"].to_numpy() for a in AXES]))
        for kind, prefix, _unit in KINDS
    }
    ahz = df["AHz"].to_numpy() if run.emulate and "AHz" in df.columns else None
    return _ImuData(inst, df["TimeUS"].to_numpy() * 1e-6, _compact(temp_c), xyz, ahz=ahz)


def _compact(x: FloatArray) -> Any:
    """``x`` held as float32 while it waits for its turn when that keeps every value (the
    log's float32 fields, made float64 by the reader): half the memory, the same numbers
    once made float64 again; else ``x`` as it is."""
    x32 = x.astype(np.float32)
    return x32 if np.array_equal(x32, x, equal_nan=True) else x


def _imus(run: _Run) -> None:
    """Every IMU of the log through :func:`_imu`, in turn.  Each one's samples are copied
    out of the log first (:func:`_imu_data`) and the log's rows released, so that the fits
    and the reports hold the samples once; each IMU's are given back after its turn."""
    from thermocal.errors import MissingColumnError

    datas: list[_ImuData] = []
    for inst in range(MAX_IMUS):
        try:
            data = _imu_data(run, inst)
        except MissingColumnError:
            if inst == 0:
                raise
            break
        except ThermocalInputError as exc:  # refused at its turn, after the IMUs before it
            data = _ImuData(inst, error=exc)
        datas.append(data)
        if data.error is not None:
            break  # the run stops there: no later IMU is read
    for name in ("IMU", "IMU2", "IMU3"):  # the rows of the log, all copied out
        run.flight.release(name)
    while datas:
        data = datas.pop(0)
        if data.error is not None:
            raise data.error
        if data.left_out is not None:
            warnings.warn(GateWarning(data.left_out), stacklevel=2)
            continue
        _imu(run, data)
        del data


def _imu_temperature(run: _Run, df: Any, inst: int) -> FloatArray | str:
    """The temperature of IMU ``inst`` [°C] (field ``T``, ``Temp`` in Copter 3.4–3.6;
    refused when neither is there); the sentence it is left out with when it is all 0 or
    NaN."""
    tcol = next((c for c in ("T", "Temp") if c in df.columns), None)
    if tcol is None:  # LogStructure.h: ``T`` (``Temp`` in Copter 3.4–3.6)
        raise ThermocalInputError(
            f"{run.log}: IMU.{inst} has no temperature field (T or Temp); it has: "
            + ", ".join(map(str, df.columns))
        )
    require_fields(df, [f"{p}{a}" for p in ("Gyr", "Acc") for a in "XYZ"], run.log, f"IMU.{inst}")
    # a copy: a view would keep the table's whole float64 block (every field) alive
    temp_c: FloatArray = df[tcol].to_numpy(dtype=np.float64, copy=True)
    if not np.isfinite(temp_c).any() or np.all(temp_c[np.isfinite(temp_c)] == 0):
        return (
            f"{run.log}: IMU.{inst} left out: its temperature is all 0 or NaN (a sensor "
            "without a thermometer cannot be calibrated over temperature)"
        )
    return temp_c


def _imu(run: _Run, data: _ImuData) -> None:
    """One IMU: its gyro and accelerometer back to the sensor frame (:func:`ardupilot_raw`)
    and through the pipeline, its ``INS_TCAL<n>`` parameters, hygiene, gates and reports."""
    from thermocal.export.params import export_params

    assert data.time_s is not None and data.temp_c is not None
    inst, time_s = data.inst, data.time_s
    # the IMU's thermometer as logged (exact: see _compact): what the firmware read, for
    # undoing its corrections and emulating its learning; the fits take the plan's
    temp_c: FloatArray = data.temp_c.astype(np.float64)
    held: HeaterJudgement | None = None  # judged once, on the temperature fitted on
    per_kind: list[tuple[SensorFit, Recording]] = []
    raw: dict[str, FloatArray] = {}  # what the firmware's learner is fed, per kind
    intervals, changes = param_intervals(
        run.flight.parameters,
        run.flight.parameter_changes,
        lambda n: imu_hygiene_params(n, inst),
    )
    prev_params = _previous_params(run, inst, intervals, changes, time_s)
    for kind, prefix, unit in KINDS:
        xyz = data.xyz.pop(kind).astype(np.float64)  # exact (_compact); given back once undone
        xyz, actives, codes = ardupilot_raw_intervals(intervals, inst, kind, time_s, temp_c, xyz)
        if run.emulate:
            raw[kind] = xyz
        run.orientation = codes[-1]
        run.rotated = run.rotated or any(codes)
        active = ardupilot_active(prev_params, inst)
        hyg = run.hygiene.setdefault(
            f"IMU.{inst}", {"active_tcal_removed": any(a is not None for a in actives)}
        )
        if active is not None:
            hyg.update(tmin_c=active.tmin_c, tmax_c=active.tmax_c, caltemp_c=active.caltemp_c)
        if changes:
            hyg["parameter_changes"] = [c.to_dict() for c in changes]
        sub_rec = Recording.from_arrays(
            time_s, {a: xyz[:, j] for j, a in enumerate(AXES)},
            {"temperature": temp_c}, signal_unit=unit,
        )  # fmt: skip
        sub_rec.source = str(run.log)
        sub_rec.validate()
        sub_rec, thermo = sensor_temperature(
            sub_rec, f"IMU.{inst}", temperature=run.plan.temperature,
            source=run.plan.source_for(kind, inst),
        )  # fmt: skip
        if held is None:  # one thermometer per IMU: the same for its two sensors
            held = _heater(run, inst, sub_rec, thermo.get("own_minus_source_c"))
        fit = fit_sensor(
            sub_rec, f"IMU.{prefix}", kind, inst, overrides=run.overrides,
            firmware="ardupilot", motions=run.motions,
        )  # fmt: skip
        fit.heater = held.to_dict()
        said = record_thermometer(fit, thermo, f"IMU.{inst}")
        if said and kind == "gyro":  # one thermometer per IMU: said once
            run.params.notes.append(said)
        run.fits.append(fit)
        per_kind.append((fit, sub_rec))
        if kind == "gyro":
            vals = np.column_stack([sub_rec.signal(a)[0] for a in AXES])
            run.gates.append(gyro_unit_warning(f"{run.log}: IMU.{inst} gyro", vals))
            del vals
        # the step check across instances reads the stillness result (motions), not values
        run.series[f"{fit.topic}.{inst}"] = (time_s, np.empty((0, len(AXES))))
    assert held is not None  # KINDS is not empty
    sub = Calibration([ch for f, _r in per_kind for ch in f.channels])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ps = export_params(sub, "ardupilot", instance=inst)
    run.params.merge(ps, f"IMU.{inst}")
    run.params.notes.extend(f"IMU.{inst}: {n}" for n in held.notes if held.hold is not None)
    _hygiene_and_gates(run, inst, ps, prev_params)
    active = ardupilot_active(prev_params, inst)
    fw_range = tclr_range(
        run.flight.rows("TCLR"), inst, run.flight.parameter_changes, time_s, temp_c
    )
    emulated = (
        _emulate(run, inst, data.ahz, time_s, temp_c, raw, ps.params) if run.emulate else None
    )
    _reports(run, inst, per_kind, ps, held, emulated, active, fw_range)


def _heater(
    run: _Run, inst: int, rec: Recording, own_minus_c: float | None = None
) -> HeaterJudgement:
    """IMU ``inst``'s heater hold (:func:`.heated.judge_instance`) judged on the temperature
    its fits take (``rec``'s: reconstructed, or borrowed, ``own_minus_c`` below its own),
    its warnings and a stall's (no hold, or an inferred one) added to the run's gates."""
    time_s, temp_c = rec.time_s, rec.temperature_c("temperature")
    held = judge_instance(
        f"{run.log}: IMU.{inst}", time_s, temp_c, run.flight.parameters, "ardupilot",
        run.heater, own_minus_c=own_minus_c,
    )  # fmt: skip
    run.gates.extend(held.warnings)
    if held.hold is None or held.hold.setpoint_source == "inferred":  # a stall, or a heater?
        run.gates.append(stall_warning(f"IMU.{inst}", time_s, temp_c))
    return held


def _reports(
    run: _Run, inst: int, per_kind: list[tuple[SensorFit, Recording]], ps: Any,
    held: HeaterJudgement, emulated: ArdupilotEmulation | None, active: Any, fw_range: Any,
) -> None:  # fmt: skip
    """IMU ``inst``'s gyro and accelerometer compared with the log's coefficients and the
    firmware's learning (``active``, ``fw_range``), and their reports requested."""
    for fit, sub_rec in per_kind:
        key = f"{fit.topic}.{inst}"
        if active is not None:  # the log's coefficients against the new ones
            run.previous[key] = ardupilot_comparison(
                active, ps.params, fit.kind, KIND_UNITS[fit.kind],
                fit.sweep_c,
            )  # fmt: skip
        learned = None if fw_range is None else tclr_comparison(
            run.flight.rows("TCLR"), inst, fit.kind,
            KIND_UNITS[fit.kind], ps.params, fit.sweep_c, fw_range,
        )  # fmt: skip
        if learned is not None:
            run.learning[key] = learned
        run.out_set.report(
            f"report_IMU_{inst}_{fit.kind}.html",
            ReportRequest(
                calibration=Calibration(fit.channels), recording=sub_rec,
                recording_path=str(run.log), title=f"ArduPilot thermal calibration — IMU {inst} "
                f"{fit.kind}", generated_by="thermocal ardupilot-tempcal",
                notes=(
                    *(f"Firmware: {n}" for n in ps.notes), *(f"Heater: {n}" for n in held.notes),
                    *(() if run.allan else (NO_ALLAN,)),
                ),
                previous=run.previous.get(key),
                firmware_learning=run.learning.get(key), allan=run.allan,
                emulated_learning=emulated.against_thermocal.get(fit.kind) if emulated else None,
            ),
        )  # fmt: skip


def _emulate(
    run: _Run, inst: int, ahz: FloatArray | None, time_s: FloatArray, temp_c: FloatArray,
    raw: dict[str, FloatArray], new_params: Mapping[str, float],
) -> ArdupilotEmulation:  # fmt: skip
    """The firmware's learning of IMU ``inst`` emulated (:func:`.learning.emulate_ardupilot`),
    fed at the driver's rate ``AHz`` of the ``IMU`` message when the log has it."""
    from thermocal.tempcal.learning import emulate_ardupilot, samples_per_logged

    ok = np.isfinite(time_s) & np.isfinite(temp_c)  # samples the firmware could not use
    for v in raw.values():
        ok &= np.isfinite(v).all(axis=1)
    em = emulate_ardupilot(
        inst, time_s[ok], temp_c[ok], {k: v[ok] for k, v in raw.items()},
        parameters=run.flight.parameters, new_params=new_params,
        tclr_rows=run.flight.rows("TCLR"),
        samples_per_sample=samples_per_logged(
            time_s[ok], None if ahz is None else ahz[ok]
        ),
    )  # fmt: skip
    run.emulated[f"IMU.{inst}"] = em
    return em


def _baro(run: _Run) -> None:
    """The first barometer's ``TCAL_BARO_EXP`` (:func:`.ardupilot_baro.fit_ardupilot_baro`;
    the firmware corrects instance 0 only), merged into the parameters; a barometer whose
    temperature stays below 25 °C, or whose drift the firmware's model cannot follow, is
    named in a warning."""
    from thermocal.errors import MissingColumnError

    try:
        df, _info = run.flight.table("BARO", 0)
    except MissingColumnError:
        return  # no barometer in the log
    require_fields(df, ["Press", "Temp"], run.log, "BARO.0")
    temp_c, press_pa = _baro_screened(run, df)
    if temp_c is None or press_pa is None:
        return
    fit = fit_ardupilot_baro(temp_c, press_pa)
    if fit is None:
        run.gates.append(
            "BARO.0: its temperature stays (almost) below 25 °C: ArduPilot's barometer "
            "calibration (TCAL_BARO_EXP, AP_TempCalibration) corrects above 25 °C only; "
            "not fitted"
        )
        return
    if fit.at_limit:
        run.gates.append(
            f"BARO.0: TCAL_BARO_EXP {fit.exponent:g} is at a limit of 0…2: the firmware's "
            "one-parameter correction max(T − 25, 0)^e added to the pressure does not follow "
            f"this barometer's drift (rms {fit.rms_before_pa:.3g} → {fit.rms_after_pa:.3g} Pa); "
            "written with TCAL_ENABLED 0 (the correction off)"
        )
    run.gates.append(fit.int8_clamped())
    for name, value in fit.params().items():
        run.params.params[name] = value
        run.params.types[name] = 9 if name == "TCAL_BARO_EXP" else 6
    run.baro = fit
    said = tuple(g for g in run.gates if g is not None and g.startswith("BARO."))
    run.out_set.report(
        BARO_REPORT,
        baro_report_request(
            fit, temp_c, press_pa, str(run.log), "thermocal ardupilot-tempcal",
            run.flight.parameters_at_end(), said,
        ),
    )  # fmt: skip


def _baro_screened(run: _Run, df: Any) -> tuple[FloatArray | None, FloatArray | None]:
    """``BARO.0``'s (temperature [°C], pressure [Pa]) through the barometer gates of
    :func:`.offset_gates.screen_baro` (ArduPilot logs ``Press`` in Pa, LogStructure.h): the
    samples set aside said with their count, an implausible barometer left out (None, None)
    with its sentence."""
    from thermocal.tempcal.offset_gates import ARDUPILOT_BARO, screen_baro

    temp_c, press_pa = df["Temp"].to_numpy(), df["Press"].to_numpy()
    time_s = (
        df["TimeUS"].to_numpy() * 1e-6 if "TimeUS" in df.columns
        else np.arange(temp_c.size, dtype=np.float64)
    )  # fmt: skip
    judged = screen_baro(f"BARO.0 of {run.log}", time_s, temp_c, press_pa, ARDUPILOT_BARO)
    run.gates.extend(judged.notes)
    if judged.keep is None:
        run.gates.append(judged.left_out)
        return None, None
    return temp_c[judged.keep], press_pa[judged.keep]


def _previous_params(
    run: _Run, inst: int, intervals: Sequence[ParamInterval], changes: Sequence[Any],
    time_s: FloatArray,
) -> dict[str, float]:  # fmt: skip
    """The parameters IMU ``inst``'s new coefficients are compared with (``previous``, the
    hygiene's ``old``): those in force at the end of the log, the board's calibration the new
    one replaces; when ``INS_TCAL<n>`` was not active then, those of the last interval in
    which it was.  Each change of a relevant parameter is said in a note (name, old → new,
    log time) with the values used."""
    chosen = intervals[-1]
    for iv in reversed(intervals):
        if ardupilot_active(iv.params, inst) is not None:
            chosen = iv
            break
    if changes:
        t0, t1 = float(np.nanmin(time_s)), float(np.nanmax(time_s))
        said = "; ".join(
            f"{c.name} {c.old:g} → {c.new:g} at log time {c.time_s:.3f} s"
            for c in changes[:NOTE_CHANGES]
        )
        if len(changes) > NOTE_CHANGES:
            said += (
                f"; … {len(changes) - NOTE_CHANGES} more, every one in "
                "log_hygiene.parameter_changes"
            )
        lo = max(chosen.start_s, t0)
        hi = min(chosen.end_s, t1)
        run.param_notes.append(
            f"IMU.{inst}: parameters of its temperature correction changed during the "
            f"recording ({said}; data {t0:.3f}…{t1:.3f} s): each sample was undone with the "
            f"values in force when it was recorded ({len(intervals)} intervals); the "
            f"coefficients compared (previous) are those in force over {lo:.3f}…{hi:.3f} s"
        )
    return chosen.params


def _hygiene_and_gates(run: _Run, inst: int, ps: Any, prev_params: Mapping[str, float]) -> None:
    """IMU ``inst``'s coefficients in the log (old: ``prev_params``, :func:`_previous_params`)
    beside the new ones, and the gate of a ``CALTEMP`` too close to the calibrated range's
    ends."""
    hyg = run.hygiene[f"IMU.{inst}"]
    old_coef = {n: prev_params[n] for n in ps.params if n in prev_params}
    hyg["coefficients"] = {
        n: {"old": (o := old_coef.get(n)), "new": float(v),
            "difference": None if o is None else float(v) - o}
        for n, v in ps.params.items() if "_ACC" in n or "_GYR" in n
    }  # fmt: skip
    for kind in ("accel", "gyro"):
        ref = hyg.get("caltemp_c", {}).get(kind)
        if ref is not None:
            lo_c, hi_c = (
                ps.params[f"INS_TCAL{inst + 1}_TMIN"],
                ps.params[f"INS_TCAL{inst + 1}_TMAX"],
            )
            run.gates.append(end_warning(f"IMU.{inst}", f"{kind} CALTEMP", ref, lo_c, hi_c))


__all__ = [
    "ActiveTcal",
    "ArdupilotTempcalResult",
    "ardupilot_active",
    "ardupilot_raw",
    "ardupilot_raw_intervals",
    "ardupilot_tempcal",
    "imu_hygiene_params",
    "param_intervals",
    "tclr_points",
    "tclr_range",
]
