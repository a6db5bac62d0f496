"""The coefficients a log was recorded with against the new ones.

A flight controller's log carries the thermal calibration that was active while it was
recorded (ArduPilot's ``INS_TCAL<n>_*`` in its ``PARM`` messages).  A
:class:`CoefficientComparison` holds, for one sensor, each parameter old → new with their
difference, and the correction each set applies over the calibrated range, per axis, as the
firmware computes it — for the table and figure of the report and the ``previous`` object of
the result's JSON (``to_dict``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal.recording import FloatArray

CURVE_POINTS = 41
"""Temperatures at which the old and new corrections are evaluated (evenly spaced over the
calibrated range, ends included)."""


@dataclass(frozen=True)
class CoefficientComparison:
    """One sensor's previous thermal coefficients against the new ones.

    ``parameters``: (name, old, new) as the firmware stores them; ``temp_c`` the
    temperatures [°C] of the curves; ``old_curve``/``new_curve``: per axis the correction
    each set applies at ``temp_c`` [``unit``, the firmware's unit of the sensor];
    ``curve_formula`` says how (the firmware's formula, with its source).

    Attributes
    ----------
    sensor : str
        The sensor (``IMU.Gyr.0`` …).
    unit : str
        The firmware's unit of the sensor.
    parameters : tuple of (str, float, float)
        ``(name, old, new)`` as the firmware stores them.
    temp_c : tuple of float
        Temperatures of the curves [°C].
    old_curve, new_curve : mapping of str to tuple of float
        Per axis, the correction each set applies at ``temp_c`` [``unit``].
    curve_formula : str
        How the curves are computed.
    old_key, new_key : str
        The sets' names in the JSON.
    title, old_label : str
        The report section's title and the old set's label.
    anchor : str
        The HTML id of the report's section.
    intro : str
        The section's first sentence.
    """

    sensor: str
    unit: str
    parameters: tuple[tuple[str, float, float], ...]
    temp_c: tuple[float, ...]
    old_curve: Mapping[str, tuple[float, ...]]
    new_curve: Mapping[str, tuple[float, ...]]
    curve_formula: str
    old_key: str = "old"
    """What the old set is called in the JSON (``firmware`` for the firmware's learning)."""
    new_key: str = "new"
    title: str = "Coefficients in the log against the new ones"
    old_label: str = "old (in the log)"
    anchor: str = "previous"
    """The HTML id of the report's section (its table ``<anchor>-coefficients``, its
    figure ``<anchor>-figure``)."""
    intro: str = (
        "The log was recorded with a thermal calibration active; it was removed from the data "
        "before fitting."
    )

    def to_dict(self) -> dict[str, Any]:
        """The ``previous`` (or ``firmware_learning``) object of a sensor in the JSON: per
        parameter old, new (named :attr:`old_key`, :attr:`new_key`) and ``difference`` =
        new − old; the curves per axis [``unit``]."""
        ok, nk = self.old_key, self.new_key
        return {
            "sensor": self.sensor,
            "unit": self.unit,
            "parameters": {
                n: {ok: old, nk: new, "difference": new - old} for n, old, new in self.parameters
            },
            "curves": {
                "temperature_c": list(self.temp_c),
                ok: {a: list(v) for a, v in self.old_curve.items()},
                nk: {a: list(v) for a, v in self.new_curve.items()},
                "formula": self.curve_formula,
            },
        }


def compare_coefficients(
    sensor: str,
    unit: str,
    parameters: Sequence[tuple[str, float, float]],
    range_c: tuple[float, float],
    old: Callable[[FloatArray], FloatArray],
    new: Callable[[FloatArray], FloatArray],
    formula: str,
    axes: Sequence[str] = ("x", "y", "z"),
    **labels: str,
) -> CoefficientComparison:
    """The comparison of one sensor's old and new temperature corrections.

    Parameters
    ----------
    sensor : str
        Name of the sensor (e.g. ``"IMU.0 gyro"``).
    unit : str
        Unit of the corrections (e.g. ``rad/s``).
    parameters : sequence of tuple
        (parameter name, old value, new value).
    range_c : tuple of float
        Temperature range ``(lo, hi)`` the curves are evaluated over [°C] (the new
        calibration's).
    old, new : callable
        Temperatures (n,) [°C] → correction (n, axes) [``unit``].
    formula : str
        The correction's formula, shown in the report.
    axes : sequence of str, optional
        Axis names (default x, y, z).
    **labels : str
        The naming fields of :class:`CoefficientComparison` (``old_key``, ``title``, …).

    Returns
    -------
    CoefficientComparison
        Both curves at :data:`CURVE_POINTS` temperatures and the parameter table.
    """
    t = np.linspace(range_c[0], range_c[1], CURVE_POINTS)
    o, n = np.asarray(old(t)).reshape(t.size, -1), np.asarray(new(t)).reshape(t.size, -1)
    return CoefficientComparison(
        sensor, unit, tuple((p, float(a), float(b)) for p, a, b in parameters),
        tuple(float(x) for x in t),
        {a: tuple(float(x) for x in o[:, j]) for j, a in enumerate(axes)},
        {a: tuple(float(x) for x in n[:, j]) for j, a in enumerate(axes)},
        formula, **labels,
    )  # fmt: skip


# --- PX4: the TC_* parameters of the ULog against the new ones --------------------------------

PX4_TC = {
    "gyro": ("G", 3, ("_0", "_1", "_2"), ("x", "y", "z")),
    "accel": ("A", 3, ("_0", "_1", "_2"), ("x", "y", "z")),
    "baro": ("B", 5, ("",), ("pressure",)),
    "mag": ("M", 3, ("_0", "_1", "_2"), ("x", "y", "z")),
}
"""Per sensor kind: the letter of PX4's ``TC_<letter><n>_*``, the polynomial order, the axis
suffixes of ``X<k><suffix>``, the axes (PX4 ``temperature_compensation`` parameters)."""
PX4_INSTANCES = 4
PX4_CURVE_FORMULA = (
    "Σ X_k·(clamp(T, TMIN, TMAX) − TREF)^k (PX4 temperature_compensation: the offset "
    "subtracted from the measurement)"
)


def px4_poly_curve(
    params: Mapping[str, float], prefix: str, order: int, suffixes: Sequence[str]
) -> Callable[[FloatArray], FloatArray]:
    r"""PX4's offset for the parameters ``<prefix>X<k><suffix>``.

    Parameters
    ----------
    params : mapping of str to float
        PX4 parameters holding ``<prefix>TMIN``, ``TMAX``, ``TREF`` [°C] and ``X<k><suffix>``.
    prefix : str
        E.g. ``"TC_G0_"``.
    order : int
        Polynomial order (3, or 5 for the barometer).
    suffixes : sequence of str
        Axis suffixes (``"_0"``, ``"_1"``, ``"_2"``; ``""`` for the barometer).

    Returns
    -------
    callable
        Temperatures (n,) [°C] → offset (n, axes) [the sensor's unit].

    Notes
    -----
    :data:`PX4_CURVE_FORMULA`:

    .. math:: o(T) = \sum_{k=0}^{n} X_k \left(\operatorname{clamp}(T, T_{min}, T_{max})
       - T_{ref}\right)^k

    References
    ----------
    - PX4 ``src/modules/sensors/temperature_compensation/TemperatureCompensation.cpp``.
    """
    lo, hi, tref = (params[prefix + k] for k in ("TMIN", "TMAX", "TREF"))
    c = np.array([[params[f"{prefix}X{k}{s}"] for s in suffixes] for k in range(order + 1)])

    def curve(temp_c: FloatArray) -> FloatArray:
        x = np.clip(np.asarray(temp_c, dtype=np.float64), lo, hi) - tref
        out: FloatArray = np.polynomial.polynomial.polyval(x, c).T.reshape(x.size, -1)
        return out

    return curve


def px4_comparison(
    old: Mapping[str, float], new: Mapping[str, float], kind: str, instance: int,
    device_id: int, unit: str, range_c: tuple[float, float],
) -> CoefficientComparison | None:  # fmt: skip
    """The ``TC_*`` active in the log for a device against the new ones.

    PX4 matches the calibration to a sensor by device id, not by instance: the calibration
    index ``m`` whose ``TC_<letter><m>_ID`` is ``device_id`` is compared with the new
    ``TC_<letter><instance>_*``.

    Parameters
    ----------
    old : mapping of str to float
        The log's parameters.
    new : mapping of str to float
        The new parameters.
    kind : str
        ``"gyro"``, ``"accel"``, ``"baro"`` or ``"mag"``.
    instance : int
        The new calibration's instance (0…3).
    device_id : int
        PX4's device id of the sensor (0: unknown).
    unit : str
        Unit of the offsets.
    range_c : tuple of float
        Temperature range of the curves [°C].

    Returns
    -------
    CoefficientComparison or None
        None when the log has no calibration for this device (or ``device_id`` is 0).

    References
    ----------
    - PX4 ``src/modules/sensors/temperature_compensation/TemperatureCompensation.cpp``.
    """
    letter, order, suffixes, axes = PX4_TC[kind]
    m = next(
        (
            k
            for k in range(PX4_INSTANCES)
            if device_id and old.get(f"TC_{letter}{k}_ID") == device_id
        ),
        None,
    )
    if m is None:
        return None
    po, pn = f"TC_{letter}{m}_", f"TC_{letter}{instance}_"
    keys = ["TMIN", "TMAX", "TREF"] + [f"X{k}{s}" for k in range(order + 1) for s in suffixes]
    if any(po + k not in old for k in keys) or any(pn + k not in new for k in keys):
        return None
    rows = [(pn + k, float(old[po + k]), float(new[pn + k])) for k in keys]
    enabled = old.get(f"TC_{letter}_ENABLE", 0) == 1
    return compare_coefficients(
        f"{kind} {instance} (device id {device_id})", unit, rows, range_c,
        px4_poly_curve(old, po, order, suffixes), px4_poly_curve(new, pn, order, suffixes),
        PX4_CURVE_FORMULA, axes,
        intro=(
            f"The log's parameters hold TC_{letter}{m}_* for this device "
            f"(TC_{letter}_ENABLE {'1: active' if enabled else 'not 1: inactive'} while it was "
            "recorded; PX4 logs its sensor topics uncorrected, so nothing was removed)."
        ),
    )  # fmt: skip


__all__ = [
    "CURVE_POINTS",
    "CoefficientComparison",
    "compare_coefficients",
    "px4_comparison",
    "px4_poly_curve",
]
