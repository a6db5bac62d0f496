"""Firmware thermal-calibration parameters from a calibration: the parameter
files of the firmwares' thermal compensation.

* **PX4** (``TemperatureCompensation``): per sensor instance ``n`` and axis ``i``,
  ``offset_i = X0_i + X1_i·dT + X2_i·dT² + X3_i·dT³`` with
  ``dT = clamp(T, TMIN, TMAX) − TREF``; the firmware subtracts the offset.  Gyros in
  [rad/s], accelerometers in [m/s²].  Parameters ``TC_G<n>_*`` / ``TC_A<n>_*``: ``ID``
  (device id), ``TMIN``, ``TMAX``, ``TREF``, ``X<p>_<i>``; written as a QGroundControl
  parameter file (tab-separated ``vehicle component name value type``, type 9 = float,
  6 = int32).
* **ArduPilot** (``AP_InertialSensor_tempcal``): the firmware subtracts
  ``poly(clamp(T) − 35) − poly(T_cal − 35)`` with ``poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``
  (no constant term: the correction is relative to the calibration temperature T_cal),
  in [rad/s] and [m/s²].  Parameters ``INS_TCAL<n+1>_ENABLE``, ``_TMIN``, ``_TMAX``,
  ``_ACC{1,2,3}_{X,Y,Z}``, ``_GYR{1,2,3}_{X,Y,Z}`` (``c_k``); written as ``NAME VALUE``
  lines (a ``.parm`` file).

A channel's polynomial is re-expanded about the format's reference temperature
(:meth:`thermocal.models.poly.PolyModel.coefficients_about`, exact) and converted from
the model's unit (°/h or mg) to the firmware's.  A calibration the format cannot express —
another family, Ṫ or several temperature inputs, a power above 3, raw-count temperatures
without a conversion — is refused with what to fit instead.

Accelerometers: gravity is in their data, and from one placement a horizontal bias
cannot be told from the bench's tilt (:mod:`thermocal.gravity`: a triad fitted with a
``gravity_axis`` removes gravity along its measured direction, so its model's constant
holds the horizontal biases only relative to the placement's mean; a lone channel's
direction is not known at all; without ``gravity_axis`` the constant holds gravity).
So no absolute accelerometer offset is ever written: the PX4 offset is relative to the
model's value at the middle of the fitted range (PX4's own script fits accelerometers
relative to the run's median; the absolute offset is the accelerometer calibration's,
``CAL_ACC*``), and ArduPilot's polynomial is relative to the calibration temperature by
its definition.  The notes say so; a model fitted without ``gravity_axis`` is also
warned.

Refused: a channel given twice or to both triads, a channel of the other kind,
an instance the firmware does not have (:data:`thermocal.firmware.formats.FORMATS`), and
any parameter that is not a finite float32 (or, for the int32 ``ID``, outside int32).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import units
from thermocal.errors import ParameterError, ThermocalInputError, ThermocalWarning
from thermocal.firmware.formats import ARDUPILOT_SCALE, FORMATS, INT32_RANGE, firmware_format
from thermocal.models.base import TemperatureModel
from thermocal.models.calibration import Calibration

ARDUPILOT_MIN_SPAN_C = 10.0
"""ArduPilot's learning needs a sweep of at least 10 °C (tempcal_IMU.py's minimum)."""
AXES = ("x", "y", "z")
FLOAT32_MAX = float(np.finfo(np.float32).max)
"""Largest finite float32 (≈ 3.4028235e38): the firmware stores parameters as 32-bit floats."""


@dataclass(frozen=True)
class AxisPoly:
    """One axis: polynomial coefficients ``b_k`` of ``(T − tref)^k``, k = 0…3, in the
    firmware's unit ([rad/s] or [m/s²]), the fitted range and the channel it came from.

    Attributes
    ----------
    channel : str
        The channel it came from.
    kind : str
        ``"gyro"`` or ``"accel"``.
    axis : str
        ``x``, ``y`` or ``z``.
    tref_c : float
        Reference temperature [°C].
    coef : (float, float, float, float)
        b_0 … b_3 [firmware unit/°C^k].
    tmin_c, tmax_c : float
        The fitted range [°C].
    relative : bool
        The coefficients are relative to the value at ``tref_c`` (b_0 = 0).
    """

    channel: str
    kind: str  # "gyro" or "accel"
    axis: str
    tref_c: float
    coef: tuple[float, float, float, float]
    tmin_c: float
    tmax_c: float
    relative: bool = False

    def offset(self, temp_c: Any) -> Any:
        r"""The firmware's offset at ``temp_c`` (clamped to the range) [firmware unit].

        Parameters
        ----------
        temp_c : float or array_like
            Sensor temperature [°C].

        Returns
        -------
        float or numpy.ndarray
            The offset the firmware subtracts [rad/s for a gyro, m/s² for an accel].

        Notes
        -----
        .. math:: b(T) = b_0 + b_1 \tau + b_2 \tau^2 + b_3 \tau^3,\quad
                  \tau = \operatorname{clip}(T, T_\min, T_\max) - T_\mathrm{ref}

        References
        ----------
        - PX4-Autopilot, ``src/modules/temperature_compensation/TemperatureCompensation.cpp``.
        - ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
        """
        t = np.clip(np.asarray(temp_c, dtype=np.float64), self.tmin_c, self.tmax_c) - self.tref_c
        b0, b1, b2, b3 = self.coef
        return b0 + t * (b1 + t * (b2 + t * b3))


@dataclass
class ParamSet:
    """The parameters of one export: ``params`` name → value, ``types`` name → MAVLink
    parameter type (9 float, 6 int32), what the firmware does at the range ends, and the
    warnings raised.

    Attributes
    ----------
    format : str
        The firmware (``"px4"`` or ``"ardupilot"``).
    params : dict of str to float
        Parameter name → value.
    types : dict of str to int
        Parameter name → MAVLink type (9 float, 6 int32).
    axes : list of AxisPoly
        The axes the parameters hold.
    notes : list of str
        The notes written into the file (range ends, warnings).
    """

    format: str
    params: dict[str, float] = field(default_factory=dict)
    types: dict[str, int] = field(default_factory=dict)
    axes: list[AxisPoly] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def merge(self, other: ParamSet, label: str) -> None:
        """Add another instance's parameters (one file for every sensor of a log).

        Parameters
        ----------
        other : ParamSet
            The parameters of another sensor instance, same format.
        label : str
            Prefix of its notes (e.g. the instance's name).

        Returns
        -------
        None
        """
        self.params.update(other.params)
        self.types.update(other.types)
        self.axes += other.axes
        self.notes += [f"{label}: {n}" for n in other.notes]

    def text(self) -> str:
        """The parameter file: its dialect's layout
        (:class:`thermocal.firmware.formats.ParamsFileLayout`, a QGroundControl file for PX4,
        ``NAME VALUE`` lines for ArduPilot) with a line saying what wrote it.

        Returns
        -------
        str
        """
        dialect = firmware_format(self.format)
        what = f"{dialect.name} ({dialect.layout.thermal})"
        provenance = f"# thermocal export-params --format {what}"  # cli-words: the file's origin
        return dialect.layout.text(self.params, self.types, [provenance])


def _model_unit_factor(kind: str, model_unit: str) -> float:
    """Firmware unit per model unit: [rad/s per °/h] for gyros, [m/s² per mg] for accels."""
    if kind == "gyro":
        return float(units.convert(1.0, model_unit, "deg/h")) * units.DH_TO_RS
    return float(units.convert(1.0, model_unit, "mg")) * units.MG_TO_MS2


def _inexpressible(message: str) -> ThermocalInputError:
    """The refusal of a channel the firmware formats cannot express, saying what to fit."""
    return ThermocalInputError.naming(
        f"{message}; fit it with {{model}} poly {{order}} 3 on one temperature column",
        "model",
        "order",
    )


def _check_expressible(name: str, model: TemperatureModel) -> None:
    """Refuse a channel the firmware formats cannot express, saying what to fit instead."""
    if model.family != "poly":
        raise _inexpressible(
            f"channel {name!r}: a {model.family} model cannot be written as firmware "
            "parameters (a cubic in T − TREF)"
        )
    temps = list(model.temp_names_)
    if len(temps) != 1:
        raise _inexpressible(
            f"channel {name!r}: the model uses {len(temps)} temperature inputs "
            f"({', '.join(temps)}); the firmware takes one"
        )
    if model.temperature_unit != "degC":
        raise ThermocalInputError.naming(
            f"channel {name!r}: the model is in raw temperature counts; the firmware takes °C: "
            "refit with {temp_conversion} GAIN,OFFSET",
            "temp_conversion",
        )
    for c in model.coefficients_about(0.0):  # type: ignore[attr-defined]
        if c.name == "const":
            continue
        if "rate" in c.name:
            raise _inexpressible(
                f"channel {name!r}: the model has a temperature-rate term ({c.name}); the "
                "firmware has none"
            )
        power = int(c.name.split("^")[1]) if "^" in c.name else 1
        if power > 3:
            raise _inexpressible(
                f"channel {name!r}: the model has a T^{power} term; the firmware takes a cubic"
            )


def axis_poly(name: str, model: TemperatureModel, kind: str, axis: str, tref_c: float) -> AxisPoly:
    """One channel as the firmware's cubic about ``tref_c`` in its unit (exact re-expansion).

    Parameters
    ----------
    name : str
        The channel's name in the calibration.
    model : TemperatureModel
        Its fitted polynomial model (at most cubic in one temperature).
    kind : {"gyro", "accel"}
        The sensor kind, which fixes the firmware unit (rad/s or m/s²).
    axis : {"x", "y", "z"}
        The firmware axis.
    tref_c : float
        Reference temperature of the cubic [°C].

    Returns
    -------
    AxisPoly
        The cubic's coefficients [firmware unit / °Cᵏ] and the fitted range [°C]; an accel's
        is relative to its value at mid-range.

    Raises
    ------
    ThermocalInputError
        When the model is not a polynomial in one temperature of order ≤ 3.
    """
    _check_expressible(name, model)
    coefs = {c.name: c.value for c in model.coefficients_about(tref_c)}  # type: ignore[attr-defined]
    b = [coefs.get("const", 0.0)] + [
        coefs.get("(T1-TREF)" if k == 1 else f"(T1-TREF)^{k}", 0.0) for k in (1, 2, 3)
    ]
    f = _model_unit_factor(kind, model.signal_unit)
    lo, hi = (float(v) for v in model.temp_range_[0])
    relative = False
    if kind == "accel":
        # no absolute offset is known (module docstring): relative to the model at mid-range
        mid = 0.5 * (lo + hi) - tref_c
        b[0] = 0.0 - (b[1] * mid + b[2] * mid**2 + b[3] * mid**3)  # no -0.0 at mid
        relative = True
    return AxisPoly(name, kind, axis, tref_c, (b[0] * f, b[1] * f, b[2] * f, b[3] * f),
                    lo, hi, relative)  # fmt: skip


def map_axes(
    cal: Calibration, gyro: Sequence[str] | None, accel: Sequence[str] | None
) -> dict[str, dict[str, str]]:
    """``{"gyro": {"x": channel, …}, "accel": {…}}`` from ``gyro``/``accel`` or the roles.

    Parameters
    ----------
    cal : Calibration
        The calibration's channels.
    gyro, accel : sequence of str or None
        Three channel names in x, y, z order; ``None``: taken from the channels' roles.

    Returns
    -------
    dict
        Per kind present, the channel of each axis; each triad complete or absent.

    Raises
    ------
    ParameterError
        ``gyro``/``accel``: not three channels, repeated, unknown, of the other kind, or
        a partial triad in the roles.
    ThermocalInputError
        No triad found, or a channel in both triads.
    """
    from thermocal.models.calibration import guess_role

    out: dict[str, dict[str, str]] = {}
    for kind, given in (("gyro", gyro), ("accel", accel)):
        if given:
            if len(given) != 3:
                raise ParameterError(kind, f"{{name}} takes three channels, x,y,z; got {given}")
            twice = sorted({c for c in given if list(given).count(c) > 1})
            if twice:
                raise ParameterError(
                    kind,
                    f"{{name}} {','.join(given)}: channel {', '.join(map(repr, twice))} given "
                    "for more than one axis; each axis takes its own channel",
                )
            missing = [c for c in given if c not in cal.names]
            if missing:
                raise ParameterError(
                    kind,
                    f"{{name}}: no channel {', '.join(map(repr, missing))} in the calibration "
                    f"({', '.join(cal.names)})",
                )
            for c in given:
                ch = cal.channel(c)
                role = ch.role or guess_role(c, ch.model.signal_unit) or {}
                if role.get("kind") not in (None, kind):
                    art = {"gyro": "a gyro", "accel": "an accel"}
                    raise ParameterError(
                        kind,
                        f"{{name}} {','.join(given)}: channel {c!r} is {art[role['kind']]} "
                        f"({ch.model.signal_unit}), not {art[kind]}",
                    )
            out[kind] = dict(zip(AXES, given, strict=True))
            continue
        found = {
            str((ch.role or {}).get("axis")): ch.name
            for ch in cal.channels
            if (ch.role or {}).get("kind") == kind and (ch.role or {}).get("axis") in AXES
        }
        if found and set(found) != set(AXES):
            raise ParameterError(
                kind,
                f"the calibration has {kind} axes {sorted(found)} only; the firmware takes a "
                "triad: give {name} X,Y,Z",
            )
        if found:
            out[kind] = {a: found[a] for a in AXES}
    if not out:
        raise ThermocalInputError.naming(
            "no gyro or accelerometer triad found in the calibration's roles; give "
            "{gyro} X,Y,Z and/or {accel} X,Y,Z",
            "gyro",
            "accel",
        )
    if "gyro" in out and "accel" in out:
        both = sorted(set(out["gyro"].values()) & set(out["accel"].values()))
        if both:
            raise ThermocalInputError.naming(
                f"{{gyro}} and {{accel}} both take channel {', '.join(map(repr, both))}; a "
                "channel is one sensor's axis",
                "gyro",
                "accel",
            )
    return out


def _show(v: float) -> str:
    """A value for an error line (an integer of thousands of digits is not printed)."""
    if isinstance(v, int) and abs(v) >= 10**18:
        return f"an integer of {v.bit_length()} bits"
    return repr(v)


def check_values(ps: ParamSet) -> None:
    r"""Refuse any parameter the firmware cannot store: a float (type 9) that is NaN,
    infinite or beyond ±:data:`FLOAT32_MAX` (it would be written as ``nan``/``inf`` or
    become infinite in float32), an int32 (type 6) outside :data:`INT32_RANGE`.

    Parameters
    ----------
    ps : ParamSet
        The parameters and their MAVLink types.

    Returns
    -------
    None

    Raises
    ------
    ThermocalInputError
        Naming the first parameter that cannot be stored.

    References
    ----------
    - IEEE Std 754-2019, binary32 format (largest finite value
      :math:`(2 - 2^{-23})\,2^{127}`).
    - MAVLink common message set, ``MAV_PARAM_TYPE``.
    """
    for name, v in ps.params.items():
        if ps.types.get(name, 9) == 6:
            whole = isinstance(v, int) or (math.isfinite(v) and float(v).is_integer())
            if not (whole and INT32_RANGE[0] <= int(v) <= INT32_RANGE[1]):
                raise ThermocalInputError(
                    f"{name} = {_show(v)}: not an int32 ({INT32_RANGE[0]}…{INT32_RANGE[1]}), which "
                    "the firmware stores"
                )
        elif not (math.isfinite(v) and abs(v) <= FLOAT32_MAX):
            raise ThermocalInputError.naming(
                f"{name} = {_show(v)}: not a finite float32 (|x| ≤ {FLOAT32_MAX:.8g}), which the "
                "firmware stores; check the calibration's coefficients, range and {tref_c}",
                "tref_c",
            )


def check_documented(ps: ParamSet) -> None:
    """Every parameter of ``ps`` against what the firmwares document of it
    (``documented`` of :data:`thermocal.firmware.formats.FORMATS`): a type other than the one
    documented, or a value outside a ``hard`` range, refused (exit 2) naming the parameter,
    the value and the source; outside a ground station's @Range: a warning.

    Parameters
    ----------
    ps : ParamSet
        The parameters and their MAVLink types.

    Returns
    -------
    None

    Raises
    ------
    ThermocalInputError
        A type other than documented, or a value outside a hard range.

    Warns
    -----
    ThermocalWarning
        A value outside a documented soft range.
    """
    import re

    for name, v in ps.params.items():
        documented = (d for f in FORMATS.values() for d in f.documented)
        doc = next((d for d in documented if re.fullmatch(d.pattern, name)), None)
        if doc is None:
            continue
        typ = ps.types.get(name, 9)
        whole = isinstance(v, int) or (math.isfinite(v) and float(v).is_integer())
        if typ != doc.type or (doc.type == 6 and not whole):
            raise ThermocalInputError(
                f"{name} = {_show(v)}: written as type {typ}, documented as "
                f"{'an integer' if doc.type == 6 else 'a float'} ({doc.source})"
            )
        if doc.lo <= v <= doc.hi:
            continue
        what = f"{name} = {_show(v)}: outside {doc.lo:g}…{doc.hi:g} ({doc.source})"
        if doc.hard:
            raise ThermocalInputError(f"{what}: the firmware would not take it")
        warnings.warn(
            f"{what}: a ground station flags it; check the calibration's range",
            ThermocalWarning,
            stacklevel=2,
        )


def export_params(
    cal: Calibration,
    fmt: str,
    *,
    gyro: Sequence[str] | None = None,
    accel: Sequence[str] | None = None,
    instance: int = 0,
    device_id: Mapping[str, int] | None = None,
    tref_c: float | None = None,
) -> ParamSet:
    """The firmware parameters of a calibration's gyro and accelerometer triads.

    Parameters
    ----------
    cal : Calibration
        Channels fitted with the ``poly`` family, order ≤ 3, on one temperature in °C.
    fmt : {"px4", "ardupilot"}
        The dialect (:data:`thermocal.firmware.formats.FORMATS`).
    gyro, accel : sequence of str, optional
        The channels of each triad in x, y, z order; default the channels' roles.
    instance : int
        The sensor instance (PX4 0…3: ``TC_G0``…; ArduPilot 0…2: ``INS_TCAL1``…).
    device_id : Mapping[str, int], optional
        PX4 device id per kind, ``{"gyro": id, "accel": id}``; default the calibration's
        recorded sensor id when numeric, else 0 with a warning.
    tref_c : float, optional
        PX4's ``TREF`` [°C]; default the middle of the fitted range (ArduPilot's is 35 °C).

    Returns
    -------
    ParamSet
        Name → value and MAVLink type of every parameter, the polynomials per axis in the
        firmware's unit (rad/s, m/s²), the notes of the file.

    Raises
    ------
    thermocal.errors.ParameterError
        ``fmt``, ``instance``, ``tref_c``, ``gyro``/``accel`` or ``device_id`` the firmware
        cannot take (the parameter is named).
    thermocal.errors.ThermocalInputError
        A channel the firmware cannot express (another family, Ṫ or several temperatures,
        a power above 3), ranges that do not overlap, a value that is not a finite float32.

    Notes
    -----
    Each channel's polynomial is re-expanded exactly about the reference temperature and
    converted from the model's unit (°/h, mg) to the firmware's.  PX4 subtracts
    :math:`\\sum_{k=0}^{3} X_k\\,\\Delta T^k`,
    :math:`\\Delta T = \\operatorname{clamp}(T, T_\\mathrm{min}, T_\\mathrm{max}) -
    T_\\mathrm{ref}`; ArduPilot stores :math:`c_k = b_k \\cdot 10^6`, k = 1…3, of the
    polynomial about 35 °C (no constant).  Accelerometer offsets are relative (module
    docstring).

    References
    ----------
    * PX4-Autopilot, ``src/modules/temperature_compensation/TemperatureCompensation.cpp``.
    * ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
    """
    _check_arguments(fmt, instance, tref_c)
    triads = map_axes(cal, gyro, accel)
    out = ParamSet(fmt)
    for kind, chans in triads.items():
        models = {a: cal.channel(c).model for a, c in chans.items()}
        lo = max(float(m.temp_range_[0, 0]) for m in models.values())
        hi = min(float(m.temp_range_[0, 1]) for m in models.values())
        if not hi > lo:
            raise ThermocalInputError(f"the {kind} channels' fitted ranges do not overlap")
        if fmt == "px4":
            tref = 0.5 * (lo + hi) if tref_c is None else float(tref_c)
        else:
            tref = float(FORMATS[fmt].tref_c or 0.0)
            if hi - lo < ARDUPILOT_MIN_SPAN_C:
                warnings.warn(
                    f"{kind}: the fitted range {lo:.1f}…{hi:.1f} °C spans less than "
                    f"{ARDUPILOT_MIN_SPAN_C:g} °C; ArduPilot's calibration needs at least that",
                    ThermocalWarning,
                    stacklevel=2,
                )
        polys = [axis_poly(chans[a], models[a], kind, a, tref) for a in AXES]
        out.axes += polys
        if kind == "accel":
            _accel_notes(out, fmt, [models[a] for a in AXES], lo, hi)
        out.notes.append(
            f"{kind}: the firmware clamps the temperature to {lo:.2f}…{hi:.2f} °C (the fitted "
            "range): below and above, the correction of the range end is applied"
        )
        if fmt == "px4":
            _px4_params(out, kind, polys, instance, lo, hi, tref, _device_id(cal, kind, device_id))
        else:
            _ardupilot_params(out, kind, polys, instance, lo, hi)
    check_values(out)
    check_documented(out)
    return out


def _check_arguments(fmt: str, instance: int, tref_c: float | None) -> None:
    """Refuse a dialect, an instance or a TREF :func:`export_params` cannot take."""
    if fmt not in FORMATS:
        raise ParameterError("format", f"{{name}} must be one of {', '.join(FORMATS)}, got {fmt!r}")
    n_max = FORMATS[fmt].max_instances
    if not 0 <= instance < n_max:
        have = FORMATS[fmt].instances
        raise ParameterError(
            "instance", f"{{name}} {instance}: {fmt} has {have}, instances 0…{n_max - 1}"
        )
    if tref_c is not None and not math.isfinite(tref_c):
        raise ParameterError("tref_c", f"{{name}} {tref_c}: not a finite temperature")


def _accel_notes(
    out: ParamSet, fmt: str, models: Sequence[TemperatureModel], lo: float, hi: float
) -> None:
    """Say which convention the accelerometer offsets follow and why no absolute one is
    written (module docstring); warn when gravity is in the models' constants."""
    gravity = [((getattr(m, "inputs_", {}) or {}).get("known_input") or {}) for m in models]
    if not all("gravity" in str(k.get("what", "")) for k in gravity):
        warnings.warn(
            ThermocalWarning.naming(
                "accel: fitted without {gravity_axis}, so gravity is in the model's constant "
                "(compensate would take it out); the firmware offsets below are relative, as "
                "PX4's own script writes them",
                "gravity_axis",
            ),
            stacklevel=3,
        )
        why = "gravity is in the models' constants"
    elif all((k.get("gravity") or {}).get("direction_measured") for k in gravity):
        why = (
            "gravity was removed along the triad's measured direction, and on one placement "
            "a horizontal bias cannot be told from the bench's tilt"
        )
    else:
        why = "the gravity direction was not measured (channels fitted without their triad)"
    if fmt == "px4":
        out.notes.append(
            f"accel: offsets relative to the model's value at mid-range "
            f"({0.5 * (lo + hi):.2f} °C), as PX4's own script writes them ({why}); the "
            "absolute offset is the accelerometer calibration's (CAL_ACC*)"
        )
    else:
        out.notes.append(
            f"accel: ArduPilot's correction is relative to the calibration temperature by "
            f"its definition; no absolute offset is written ({why})"
        )


def _device_id(cal: Calibration, kind: str, given: Mapping[str, int] | None) -> int:
    if given and kind in given:
        return int(given[kind])
    for ch in cal.channels:
        sid = (getattr(ch.model, "inputs_", {}) or {}).get("sensor_id")
        text = str(sid) if sid is not None else ""
        if text.isascii() and text.isdigit():
            if len(text) > 10:  # beyond any int32; check_values would refuse it
                raise ParameterError(
                    "device_id",
                    f"{kind}: the recorded sensor id ({len(text)} digits) is not a device id "
                    "the firmware can store (int32): give {name}",
                )
            return int(text)
    warnings.warn(
        ThermocalWarning.naming(
            f"{kind}: no numeric device id recorded; TC_*_ID written as 0, which PX4 matches "
            "to no sensor: give {device_id}",
            "device_id",
        ),
        stacklevel=3,
    )
    return 0


def _px4_params(
    out: ParamSet,
    kind: str,
    polys: list[AxisPoly],
    n: int,
    lo: float,
    hi: float,
    tref: float,
    device_id: int,
) -> None:
    p = f"TC_{'G' if kind == 'gyro' else 'A'}{n}_"
    out.params[f"TC_{'G' if kind == 'gyro' else 'A'}_ENABLE"] = 1
    out.types[f"TC_{'G' if kind == 'gyro' else 'A'}_ENABLE"] = 6
    out.params[p + "ID"] = device_id
    out.types[p + "ID"] = 6
    out.params[p + "TMIN"] = lo
    out.params[p + "TMAX"] = hi
    out.params[p + "TREF"] = tref
    for i, poly in enumerate(polys):
        for k in range(4):
            out.params[f"{p}X{k}_{i}"] = poly.coef[k]


def _ardupilot_params(
    out: ParamSet, kind: str, polys: list[AxisPoly], n: int, lo: float, hi: float
) -> None:
    p = f"INS_TCAL{n + 1}_"
    out.params[p + "ENABLE"] = 1
    out.types[p + "ENABLE"] = 6
    # one range for the instance: where every channel was fitted
    out.params[p + "TMIN"] = max(out.params.get(p + "TMIN", lo), lo)
    out.params[p + "TMAX"] = min(out.params.get(p + "TMAX", hi), hi)
    tag = "GYR" if kind == "gyro" else "ACC"
    for poly in polys:
        for k in (1, 2, 3):
            out.params[f"{p}{tag}{k}_{poly.axis.upper()}"] = poly.coef[k] / ARDUPILOT_SCALE


__all__ = [
    "AxisPoly",
    "ParamSet",
    "axis_poly",
    "check_documented",
    "check_values",
    "export_params",
    "map_axes",
]


PX4_OFFSET_KINDS = ("baro", "mag")
"""PX4's thermally compensated sensors besides the IMU (their parameters:
:data:`thermocal.firmware.formats.FORMATS`).  The firmware subtracts ``Σ X_k·dT^k`` with
``dT = clamp(T, TMIN, TMAX) − TREF`` from the measurement."""


def px4_offset_params(
    kind: str,
    instance: int,
    device_id: int,
    tmin_c: float,
    tmax_c: float,
    tref_c: float,
    coefficients: Sequence[Sequence[float]],
) -> ParamSet:
    """PX4's barometer (``TC_B<n>_*``) or magnetometer (``TC_M<n>_*``) parameters.

    Parameters
    ----------
    kind : {"baro", "mag"}
        The sensor.
    instance : int
        Its instance, 0…3.
    device_id : int
        PX4's device id of the sensor.
    tmin_c, tmax_c, tref_c : float
        ``TMIN``, ``TMAX``, ``TREF`` [°C].
    coefficients : sequence of sequence of float
        ``[[X0…X5]]`` for the barometer [Pa], ``[[X0…X3]]`` per axis x, y, z for the
        magnetometer [gauss]: the polynomial in ``T − TREF``
        (:data:`thermocal.firmware.formats.FORMATS`).

    Returns
    -------
    ParamSet
        The parameters, checked.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A sensor or an instance PX4 has no parameters for, coefficients of the wrong shape,
        a value that is not a finite float32.

    Notes
    -----
    The firmware subtracts :math:`\\sum_k X_k\\,\\Delta T^k`,
    :math:`\\Delta T = \\operatorname{clamp}(T, T_\\mathrm{min}, T_\\mathrm{max}) -
    T_\\mathrm{ref}`, from the measurement (PX4-Autopilot
    ``src/modules/temperature_compensation/TemperatureCompensation.cpp``).

    Examples
    --------
    >>> ps = px4_offset_params("baro", 0, 7, 10.0, 50.0, 30.0, [[1.5, -2.0, 0, 0, 0, 0]])
    >>> ps.params["TC_B0_X1"], ps.params["TC_B0_TREF"], ps.params["TC_B_ENABLE"]
    (-2.0, 30.0, 1)
    """
    if kind not in PX4_OFFSET_KINDS:
        raise ThermocalInputError(f"no PX4 thermal parameters for a {kind!r} sensor")
    sensor, n_max = FORMATS["px4"].sensors[kind], FORMATS["px4"].max_instances
    letter, order, n_axes = sensor.tag, sensor.order, sensor.n_axes
    if not 0 <= instance < n_max:
        raise ThermocalInputError(
            f"PX4 has TC_{letter}0…TC_{letter}{n_max - 1}; {kind} instance {instance} has none"
        )
    if len(coefficients) != n_axes or any(len(c) != order + 1 for c in coefficients):
        raise ThermocalInputError(
            f"TC_{letter}: {n_axes} axis/axes of {order + 1} coefficients expected"
        )
    out = ParamSet("px4")
    p = f"TC_{letter}{instance}_"
    out.params[f"TC_{letter}_ENABLE"] = 1
    out.types[f"TC_{letter}_ENABLE"] = 6
    out.params[p + "ID"] = device_id
    out.types[p + "ID"] = 6
    out.params[p + "TMIN"] = tmin_c
    out.params[p + "TMAX"] = tmax_c
    out.params[p + "TREF"] = tref_c
    for i, axis_coef in enumerate(coefficients):
        for k, c in enumerate(axis_coef):
            out.params[f"{p}X{k}" if n_axes == 1 else f"{p}X{k}_{i}"] = float(c)
    check_values(out)
    check_documented(out)
    return out


@dataclass(frozen=True)
class ParamsFileResult:
    """What :func:`export_params_file` wrote: the parameter file, its firmware and the
    parameters (:class:`ParamSet`).

    Attributes
    ----------
    output : str
        The parameter file.
    format : str
        Its firmware.
    params : ParamSet
        The parameters.
    """

    output: str
    format: str
    params: ParamSet

    def unit_of(self, kind: str) -> str:
        """The unit of the offsets the firmware subtracts for a sensor.

        Parameters
        ----------
        kind : str
            ``"gyro"`` or ``"accel"``.

        Returns
        -------
        str
            ``"rad/s"`` or ``"m/s^2"`` (:data:`thermocal.firmware.formats.FORMATS`).
        """
        return FORMATS[self.format].sensors[kind].unit

    def to_dict(self) -> dict[str, Any]:
        """The result as a JSON object (what the ``export-params`` command prints as JSON)."""
        return {
            "output": self.output,
            "format": self.format,
            "params": self.params.params,
            "axes": [
                {"channel": a.channel, "kind": a.kind, "axis": a.axis, "tref_c": a.tref_c,
                 "coefficients": list(a.coef), "tmin_c": a.tmin_c, "tmax_c": a.tmax_c,
                 "relative": a.relative}
                for a in self.params.axes
            ],
            "notes": self.params.notes,
        }  # fmt: skip


def export_params_file(
    calibration: str | Path,
    fmt: str,
    output: str | Path,
    *,
    gyro: Sequence[str] | None = None,
    accel: Sequence[str] | None = None,
    instance: int = 0,
    tref_c: float | None = None,
    device_id: int | None = None,
) -> ParamsFileResult:
    """A calibration (or model) file's firmware parameters, written to a parameter file.

    Parameters
    ----------
    calibration : str or Path
        The calibration or model file (``thermocal fit``, ``multipos``, ``turntable``).
    fmt : {"px4", "ardupilot"}
        The dialect (:data:`thermocal.firmware.formats.FORMATS`).
    output : str or Path
        The parameter file, written atomically (never one of the inputs).
    gyro, accel : sequence of str, optional
        The channels of each triad in x, y, z order; default the channels' roles.
    instance : int
        The sensor instance the parameters are for.
    tref_c : float, optional
        PX4's ``TREF`` [°C]; default the middle of the fitted range.
    device_id : int, optional
        The PX4 device id of both the gyro and the accelerometer.

    Returns
    -------
    ParamsFileResult
        The file written, its dialect and the parameters (:class:`ParamSet`).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        What :func:`export_params` refuses, and data behind the calibration that do not
        support the fit (:func:`thermocal.export.checks.check_firmware_adequacy`,
        ArduPilot's 10 °C sweep too).
    """
    from thermocal.export.checks import check_firmware_adequacy
    from thermocal.pipeline.model_file import load_calibration
    from thermocal.writers import atomic_write, check_not_input

    check_not_input(output, [calibration])
    cal = load_calibration(calibration)
    if not cal.channels and cal.triads:  # a calibration of triads
        if tref_c is not None:
            raise ParameterError(
                "tref_c",
                "{name} is for thermal parameters; a triad's values are taken at its own TREF",
            )
        return _triad_params_file(cal, calibration, fmt, output, gyro, accel, instance,
                                  device_id)  # fmt: skip
    cal.require_channels("export-params")
    check_firmware_adequacy(cal, calibration, fmt)
    ids = {"gyro": device_id, "accel": device_id} if device_id is not None else None
    ps = export_params(
        cal, fmt, gyro=gyro, accel=accel, instance=instance, device_id=ids, tref_c=tref_c
    )
    with atomic_write(output, "w") as fh:
        fh.write(ps.text())
    return ParamsFileResult(str(output), fmt, ps)


def _triad_params_file(
    cal: Calibration,
    calibration: str | Path,
    fmt: str,
    output: str | Path,
    gyro: Sequence[str] | None,
    accel: Sequence[str] | None,
    instance: int,
    device_id: int | None,
) -> ParamsFileResult:
    """``export-params`` of a calibration of triads: the firmware's sensor-calibration
    offsets and scales (:mod:`thermocal.export.triad_params`), written atomically."""
    from thermocal.export.checks import check_firmware_adequacy
    from thermocal.export.triad_params import triad_params
    from thermocal.writers import atomic_write

    check_firmware_adequacy(cal, calibration, None)
    tp = triad_params(cal, fmt, instance=instance, device_id=device_id, gyro=gyro, accel=accel)
    with atomic_write(output, "w") as fh:
        fh.write(tp.text())
    ps = ParamSet(fmt, dict(tp.params), dict(tp.types), [], list(tp.notes))
    return ParamsFileResult(str(output), fmt, ps)
