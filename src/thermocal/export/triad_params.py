"""Firmware sensor-calibration parameters from a calibration of triads:
``thermocal export-params`` of what
``thermocal multipos`` (or ``turntable``) wrote.

The triad model (:mod:`thermocal.turntable.model`) is ``x = (I + E) x_true + b``, so the
exact correction is ``x_true = M (x − b)`` with ``M = (I + E)⁻¹``.  The firmwares hold a
per-axis offset and (accelerometer only) a per-axis scale:

* **PX4** (``src/lib/sensor_calibration/Accelerometer.hpp``, ``Gyroscope.hpp``,
  ``Correct()``): ``a_c = R · diag(CAL_ACC<n>_[XYZ]SCALE) · (a − thermal_offset −
  CAL_ACC<n>_[XYZ]OFF)`` and ``ω_c = R · (ω − thermal_offset − CAL_GYRO<n>_[XYZ]OFF)``;
  offsets in the sensor topics' units, [m/s²] and [rad/s]; scales dimensionless (no range
  in the parameter reference); ``CAL_ACC<n>_ID`` / ``CAL_GYRO<n>_ID`` say which sensor
  the calibration is for (n = 0…3).
* **ArduPilot** (``AP_InertialSensor_Backend::_rotate_and_correct_accel``):
  ``a_c = (a − INS_ACCOFFS)·INS_ACCSCAL`` per axis, ``ω_c = ω − INS_GYROFFS``;
  ``INS_ACCOFFS_*`` [m/s/s] with ``@Range: -3.5 3.5``, ``INS_ACCSCAL_*`` with
  ``@Range: 0.8 1.2``, ``INS_GYROFFS_*`` [rad/s] (``AP_InertialSensor_Params.cpp``);
  the second and third IMU: ``INS_ACC2OFFS_*``, ``INS_ACC2SCAL_*``, ``INS_GYR2OFFS_*``
  (``…3…``).

So ``OFF = b`` (in the firmware's unit) and ``SCALE_i = M_ii``; what the firmware cannot
hold is stated in a ``warning:`` and in the file's comments: ``M``'s off-diagonal terms
(misalignment), the gyro's scale factors (neither firmware has a gyro scale), and the
temperature dependence (the values are those at TREF).  A value outside ArduPilot's
documented range is refused (exit 2): the ground station and the firmware's own checks
treat it as a failed calibration.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal import units
from thermocal.errors import ParameterError, ThermocalInputError, ThermocalWarning
from thermocal.firmware.formats import FORMATS, INT32_RANGE
from thermocal.models.calibration import Calibration, Triad

ARDUPILOT_ACCSCAL_RANGE = (0.8, 1.2)
"""``INS_ACCSCAL_*`` ``@Range: 0.8 1.2`` (ArduPilot ``AP_InertialSensor_Params.cpp``)."""
ARDUPILOT_ACCOFFS_RANGE_M_S2 = (-3.5, 3.5)
"""``INS_ACCOFFS_*`` ``@Range: -3.5 3.5`` [m/s/s] (same file)."""
PX4_ACCSCALE_RANGE = (0.1, 3.0)
"""``CAL_ACC${i}_XSCALE``/``YSCALE``/``ZSCALE`` ``min: 0.1``, ``max: 3.0`` (PX4-Autopilot
``src/modules/sensors/module.yaml``, the parameter metadata QGroundControl enforces);
``CAL_ACC${i}_XOFF`` and ``CAL_GYRO${i}_XOFF`` have no range there."""
PX4_ID_TYPE = "int32"
"""``CAL_ACC${i}_ID``, ``CAL_GYRO${i}_ID``: ``type: int32`` (same file)."""
PLAUSIBLE_NOTE = (
    "a scale this far from 1 or an offset this large is not a sensor's error but a unit or "
    "range setting off by that factor: check the multipos {accel_unit}/{accel_scale}"
)
"""Why ArduPilot's @Range (:data:`ARDUPILOT_ACCSCAL_RANGE`, :data:`ARDUPILOT_ACCOFFS_RANGE_M_S2`)
is applied to PX4's values too: the same physical sensor, a MEMS accelerometer whose
sensitivity is specified within a few % (e.g. ±2 % initial tolerance, Bosch BMI088, TDK
ICM-20602 datasheets) and whose zero-g offset within a few hundred mg."""


@dataclass(frozen=True)
class TriadFirmware:
    """One triad as the firmware holds it: ``offset`` [m/s² or rad/s], ``scale`` (the
    diagonal of ``(I + E)⁻¹``; 1 for a gyro, which the firmware does not scale), and what
    is lost: the largest off-diagonal term of ``(I + E)⁻¹`` [″], the largest gyro scale
    error [ppm] and whether the model depends on temperature.

    Attributes
    ----------
    kind : str
        ``"accel"`` or ``"gyro"``.
    offset : (float, float, float)
        Offset per axis [m/s² or rad/s].
    scale : (float, float, float)
        Diagonal of ``(I + E)⁻¹`` (1 for a gyro).
    misalignment_lost_arcsec : float
        Largest off-diagonal term of ``(I + E)⁻¹`` the firmware cannot hold [″].
    scale_lost_ppm : float
        Largest gyro scale error the firmware cannot hold [ppm].
    temperature_dependent : bool
        The model depends on temperature.
    tref_c : float
        Temperature at which the values are taken [°C].
    count_scale : (float, str) or None
        For a triad calibrated on raw counts: one count is ``value`` ``unit``.
    """

    kind: str
    offset: tuple[float, float, float]
    scale: tuple[float, float, float]
    misalignment_lost_arcsec: float
    scale_lost_ppm: float
    temperature_dependent: bool
    tref_c: float
    count_scale: tuple[float, str] | None = None
    """A triad calibrated on raw counts: one count is ``value`` ``unit``."""


def triad_firmware(triad: Triad) -> TriadFirmware:
    r"""The triad's offsets and scales at its TREF (module docstring: ``OFF = b``,
    ``SCALE_i = ((I + E)⁻¹)_ii``).

    Parameters
    ----------
    triad : Triad
        A calibrated triad with its temperature model.

    Returns
    -------
    TriadFirmware
        Offsets [triad unit] and scales [-] at TREF [°C], with what the firmware loses
        (misalignment [″], scale [ppm]).

    Notes
    -----
    .. math:: \mathrm{OFF} = \mathbf b(T_\mathrm{ref}),\quad
              \mathrm{SCALE}_i = \left[(I + E(T_\mathrm{ref}))^{-1}\right]_{ii}

    References
    ----------
    - PX4-Autopilot, ``src/lib/sensor_calibration`` (``CAL_ACCn_*``, ``CAL_GYROn_*``).
    - ArduPilot, ``libraries/AP_InertialSensor`` (``INS_ACCOFFS``, ``INS_ACCSCAL``).
    """
    from thermocal.turntable import thermal

    m = triad.model
    b, e = thermal.error_terms(m, m.tref_c)
    inv = np.linalg.inv(np.eye(3) + e[0])
    off_diag = inv - np.diag(np.diag(inv))
    lost = float(np.max(np.abs(off_diag))) * units.RAD_TO_ARCSEC
    if triad.name == "accel":
        offset = b[0] * units.MG_TO_MS2
        scale = np.diag(inv)
        scale_lost = 0.0
    else:
        offset = b[0] * units.DH_TO_RS
        scale = np.ones(3)
        scale_lost = float(np.max(np.abs(np.diag(e[0])))) / units.PPM
    dependent = any(np.any(np.asarray(f.coef[1:]) != 0.0) for f in m.fits)
    return TriadFirmware(
        triad.name, (float(offset[0]), float(offset[1]), float(offset[2])),
        (float(scale[0]), float(scale[1]), float(scale[2])), lost, scale_lost, dependent,
        float(m.tref_c),
        None if triad.count_scale is None else (float(triad.count_scale), triad.unit),
    )  # fmt: skip


@dataclass(frozen=True)
class TriadParams:
    """The parameters of one export (name → value, name → MAVLink type 9 float / 6 int32),
    the comments written at the top of the file, and each triad as held.

    Attributes
    ----------
    format : str
        The firmware.
    params : dict of str to float
        Parameter name → value.
    types : dict of str to int
        Parameter name → MAVLink type (9 float, 6 int32).
    notes : tuple of str
        The comments at the top of the file.
    triads : tuple of TriadFirmware
        Each triad as the firmware holds it.
    """

    format: str
    params: dict[str, float]
    types: dict[str, int]
    notes: tuple[str, ...]
    triads: tuple[TriadFirmware, ...]

    def text(self) -> str:
        """A QGroundControl parameter file (PX4) or ``NAME VALUE`` lines (ArduPilot), the
        notes as ``#`` comments."""
        comments = [f"# {n}" for n in self.notes]
        if self.format == "px4":
            head = ["# Onboard parameters for Vehicle 1", "#",
                    "# thermocal export-params --format px4"  # cli-words: provenance
                    " (sensor calibration, CAL_*)",
                    *comments, "#", "# Vehicle-Id Component-Id Name Value Type"]  # fmt: skip
            rows = [f"1\t1\t{n}\t{_num(v, self.types[n])}\t{self.types[n]}"
                    for n, v in self.params.items()]  # fmt: skip
        else:
            head = ["# thermocal export-params --format ardupilot"  # cli-words: provenance
                    " (INS_ACC*, INS_GYR*)",
                    *comments]  # fmt: skip
            rows = [f"{n} {_num(v, self.types[n])}" for n, v in self.params.items()]
        return "\n".join(head + rows) + "\n"


def _num(v: float, typ: int) -> str:
    return str(int(v)) if typ == 6 else repr(float(v))


def _names(fmt: str, kind: str, instance: int) -> tuple[list[str], list[str] | None]:
    """The offset and scale parameter names x, y, z (scale None: the firmware has none)."""
    if fmt == "px4":
        p = f"CAL_ACC{instance}_" if kind == "accel" else f"CAL_GYRO{instance}_"
        offs = [f"{p}{a}OFF" for a in "XYZ"]
        return offs, ([f"{p}{a}SCALE" for a in "XYZ"] if kind == "accel" else None)
    k = "" if instance == 0 else str(instance + 1)
    if kind == "accel":
        return [f"INS_ACC{k}OFFS_{a}" for a in "XYZ"], [f"INS_ACC{k}SCAL_{a}" for a in "XYZ"]
    return [f"INS_GYR{k}OFFS_{a}" if k else f"INS_GYROFFS_{a}" for a in "XYZ"], None


def _check_ardupilot(names: Sequence[str], values: Sequence[float], rng: tuple[float, float],
                     what: str) -> None:  # fmt: skip
    for n, v in zip(names, values, strict=True):
        if not rng[0] <= v <= rng[1]:
            raise ThermocalInputError(
                f"{n} = {v:.6g}: outside ArduPilot's range {rng[0]:g}…{rng[1]:g} {what}"
                "(@Range in AP_InertialSensor_Params.cpp); the firmware's accelerometer "
                "calibration would not accept it: check the sensor and its unit"
            )


def _check_px4_accel(names: Sequence[str], values: Sequence[float], scale: bool) -> None:
    """PX4's ``CAL_ACC*`` scale within its metadata range (:data:`PX4_ACCSCALE_RANGE`) and,
    scales and offsets, within what a sensor's error can be (:data:`PLAUSIBLE_NOTE`)."""
    rng = ARDUPILOT_ACCSCAL_RANGE if scale else ARDUPILOT_ACCOFFS_RANGE_M_S2
    for n, v in zip(names, values, strict=True):
        if scale and not PX4_ACCSCALE_RANGE[0] <= v <= PX4_ACCSCALE_RANGE[1]:
            raise ThermocalInputError.naming(
                f"{n} = {v:.6g}: outside PX4's range {PX4_ACCSCALE_RANGE[0]:g}…"
                f"{PX4_ACCSCALE_RANGE[1]:g} (min/max of CAL_ACC${{i}}_XSCALE in PX4's "
                f"src/modules/sensors/module.yaml); {PLAUSIBLE_NOTE}",
                *("accel_unit", "accel_scale"),
            )
        if not rng[0] <= v <= rng[1]:
            unit = "" if scale else " m/s²"
            px4 = "PX4's metadata allows 0.1…3.0" if scale else "PX4 documents no range"
            raise ThermocalInputError.naming(
                f"{n} = {v:.6g}{unit}: beyond {rng[0]:g}…{rng[1]:g}{unit}, the range ArduPilot "
                f"documents for the same calibration (@Range in AP_InertialSensor_Params.cpp; "
                f"{px4}); {PLAUSIBLE_NOTE}",
                *("accel_unit", "accel_scale"),
            )


def _check_device_id(name: str, device_id: int) -> None:
    """A device id PX4 stores (:data:`PX4_ID_TYPE`)."""
    if not INT32_RANGE[0] <= device_id <= INT32_RANGE[1]:
        raise ParameterError(
            "device_id",
            f"{{name}} {device_id}: {name} is an int32 ({INT32_RANGE[0]}…{INT32_RANGE[1]}, "
            "type of CAL_ACC${i}_ID in PX4's src/modules/sensors/module.yaml); give the "
            "device id PX4 shows for the sensor (a 24-bit bus/address/type code)",
        )


def _lost_notes(t: TriadFirmware) -> list[str]:
    """What the firmware cannot hold of this triad (also warned)."""
    unit = "m/s^2" if t.kind == "accel" else "rad/s"
    out = []
    if t.misalignment_lost_arcsec > 0.0:
        err = t.misalignment_lost_arcsec * units.ARCSEC_TO_RAD
        size = "1 g" if t.kind == "accel" else "the rate"
        out.append(
            f"{t.kind}: misalignment up to {t.misalignment_lost_arcsec:.4g} arcsec is not held "
            f"(no cross-axis terms in the firmware): up to {err:.3g} of {size} stays on the "
            "other axes"
        )
    if t.scale_lost_ppm > 0.0:
        out.append(
            f"{t.kind}: scale-factor errors up to {t.scale_lost_ppm:.4g} ppm are not held (the "
            "firmware has no gyro scale)"
        )
    if t.count_scale is not None:
        out.append(
            f"{t.kind}: calibrated on raw counts (one count = {t.count_scale[0]:.10g} "
            f"{t.count_scale[1]}); the firmware's input is its driver's physical output ({unit}), "
            "not counts: the values hold if the driver's sensitivity is that count scale"
        )
    if t.temperature_dependent:
        out.append(
            f"{t.kind}: the calibration depends on temperature; the values are those at TREF "
            f"{t.tref_c:.2f} °C and the firmware applies them at every temperature "
            f"(offsets in {unit})"
        )
    return out


def _g_sensitivity_notes(triad: Triad) -> list[str]:
    """A gyro triad's g-sensitivity, which no firmware parameter holds (also warned)."""
    if triad.g_sensitivity is None:
        return []
    a = np.asarray(triad.g_sensitivity, dtype=np.float64)
    worst = float(np.max(np.linalg.norm(a, axis=1)))
    return [
        f"{triad.name}: the g-sensitivity A (rows up to {worst:.4g} {triad.g_sensitivity_unit}) "
        "is not held (the firmware has no gyro term in the specific force): the offsets are "
        "the bias at zero specific force, and at rest the gyro reads A·f more, up to "
        f"{worst:.4g} {triad.unit} at 1 g"
    ]


def _k2_notes(triad: Triad) -> list[str]:
    """An accelerometer triad's K2, which no firmware parameter holds (also warned)."""
    if getattr(triad, "k2", None) is None:
        return []
    worst = float(np.max(np.abs(np.asarray(triad.k2, dtype=np.float64))))
    return [
        f"{triad.name}: K2 (up to {worst:.4g} {triad.k2_unit}) is not held (the firmware has "
        "no second-order term): the offsets and scales are those fitted with K2, and each "
        f"axis reads up to {worst:.4g} {triad.unit} more at 1 g along it"
    ]


def _triads_of(
    cal: Calibration, gyro: Sequence[str] | None, accel: Sequence[str] | None
) -> dict[str, Triad]:
    """The calibration's accel and gyro triads by name; refuses none, or axes not theirs."""
    triads = {t.name: t for t in cal.triads if t.name in ("accel", "gyro")}
    if not triads:
        raise ThermocalInputError("the calibration has no accel or gyro triad")
    for kind, given in (("accel", accel), ("gyro", gyro)):
        if given and (kind not in triads or tuple(given) != triads[kind].columns):
            have = ",".join(triads[kind].columns) if kind in triads else "none"
            raise ThermocalInputError(
                f"--{kind} {','.join(given)}: the calibration's {kind} triad reads {have}; "
                "a triad's axes are those it was calibrated on"
            )
    return triads


def triad_params(
    cal: Calibration,
    fmt: str,
    *,
    instance: int = 0,
    device_id: int | None = None,
    gyro: Sequence[str] | None = None,
    accel: Sequence[str] | None = None,
) -> TriadParams:
    """The firmware parameters of the calibration's ``accel`` and ``gyro`` triads (module
    docstring); warns what the firmware cannot hold, refuses a value outside ArduPilot's
    range or an instance the firmware does not have.

    Parameters
    ----------
    cal : Calibration
        A calibration with an ``accel`` and/or ``gyro`` triad.
    fmt : {"px4", "ardupilot"}
        The firmware.
    instance, device_id : int, optional
        Sensor instance from 0 (default 0); PX4 device id, an int32 (default ``None``:
        not written, with a warning).
    gyro, accel : sequence of str or None, optional
        Channel names in x, y, z order, checked against the triads' (default ``None``).

    Returns
    -------
    TriadParams
        The parameters and the triads as held.

    Raises
    ------
    ParameterError
        ``format``/``instance``/``device_id``: unknown firmware, an instance it does not
        have, or a device id outside int32.
    ThermocalInputError
        No accel or gyro triad, ``gyro``/``accel`` not its axes, or a value not a float32.
    """
    if fmt not in FORMATS:
        raise ParameterError("format", f"{{name}} must be px4 or ardupilot, got {fmt!r}")
    n_max = FORMATS[fmt].max_instances  # PX4 CAL_ACC0…3 / CAL_GYRO0…3; ArduPilot three IMUs
    if not 0 <= instance < n_max:
        have = "CAL_ACC0…CAL_ACC3" if fmt == "px4" else "INS_ACC, INS_ACC2, INS_ACC3"
        raise ParameterError(
            "instance", f"{{name}} {instance}: {fmt} has {have}, instances 0…{n_max - 1}"
        )
    triads = _triads_of(cal, gyro, accel)
    params: dict[str, float] = {}
    types: dict[str, int] = {}
    notes: list[str] = []
    held = []
    for kind in ("accel", "gyro"):
        if kind not in triads:
            continue
        t = triad_firmware(triads[kind])
        held.append(t)
        offs, scales = _names(fmt, kind, instance)
        if fmt == "px4":
            idn = f"CAL_ACC{instance}_ID" if kind == "accel" else f"CAL_GYRO{instance}_ID"
            if device_id is not None:
                _check_device_id(idn, device_id)
                params[idn], types[idn] = device_id, 6
            else:
                warnings.warn(
                    ThermocalWarning.naming(
                        f"{kind}: {idn} not written (no {{device_id}}): PX4 applies the values "
                        f"only to the sensor whose device id {idn} holds",
                        "device_id",
                    ),
                    stacklevel=2,
                )
            if kind == "accel":
                _check_px4_accel(offs, t.offset, scale=False)
                assert scales is not None
                _check_px4_accel(scales, t.scale, scale=True)
        elif kind == "accel":
            _check_ardupilot(offs, t.offset, ARDUPILOT_ACCOFFS_RANGE_M_S2, "m/s/s ")
            assert scales is not None
            _check_ardupilot(scales, t.scale, ARDUPILOT_ACCSCAL_RANGE, "")
        for n, v in zip(offs, t.offset, strict=True):
            params[n], types[n] = v, 9
        for n, v in zip(scales or [], t.scale, strict=False):
            params[n], types[n] = v, 9
        lost = _lost_notes(t) + _g_sensitivity_notes(triads[kind]) + _k2_notes(triads[kind])
        for line in lost:
            warnings.warn(line, ThermocalWarning, stacklevel=2)
        notes += lost
    for n, v in params.items():
        if not (math.isfinite(v) and abs(v) <= float(np.finfo(np.float32).max)):
            raise ThermocalInputError(f"{n} = {v!r}: not a finite float32, which the firmware "
                                      "stores")  # fmt: skip
    formula = (
        "PX4 applies a_c = SCALE*(a - OFF) per axis [m/s^2], w_c = w - OFF [rad/s]"
        if fmt == "px4"
        else "ArduPilot applies a_c = (a - OFFS)*SCAL per axis [m/s^2], w_c = w - OFFS [rad/s]"
    )
    notes.insert(0, formula + "; values in the frame of the calibrated columns")
    return TriadParams(fmt, params, types, tuple(notes), tuple(held))


def as_dict(tp: TriadParams) -> dict[str, Any]:
    """The triads as held, as JSON types.

    Parameters
    ----------
    tp : TriadParams
        The result of :func:`triad_params`.

    Returns
    -------
    dict
        Per kind: offset, scale, tref_c [°C], misalignment lost [″], scale lost [ppm].
    """
    return {
        t.kind: {"offset": list(t.offset), "scale": list(t.scale), "tref_c": t.tref_c,
                 "misalignment_lost_arcsec": t.misalignment_lost_arcsec,
                 "scale_lost_ppm": t.scale_lost_ppm,
                 "temperature_dependent": t.temperature_dependent}
        for t in tp.triads
    }  # fmt: skip


__all__ = [
    "ARDUPILOT_ACCOFFS_RANGE_M_S2",
    "ARDUPILOT_ACCSCAL_RANGE",
    "TriadFirmware",
    "TriadParams",
    "as_dict",
    "triad_firmware",
    "triad_params",
]
