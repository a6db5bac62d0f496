"""The coefficients a log was recorded with against the new ones (issue 28, item 2).

A flight controller's log carries the thermal calibration that was active while it was
recorded (ArduPilot's ``INS_TCAL<n>_*`` in its ``PARM`` messages).  A
:class:`CoefficientComparison` holds, for one sensor, each parameter old → new with their
difference, and the correction each set applies over the calibrated range, per axis, as the
firmware computes it — for the table and figure of the report and the ``previous`` object of
``--json``.
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
    ``curve_formula`` says how (the firmware's formula, with its source)."""

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
        """The ``previous`` (or ``firmware_learning``) object of a sensor in ``--json``: per
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
    """The comparison of one sensor: ``old``/``new`` map temperatures (n,) [°C] to the
    correction (n, axes) [``unit``]; evaluated at :data:`CURVE_POINTS` temperatures over
    ``range_c`` (the new calibration's range); ``labels``: the naming fields of
    :class:`CoefficientComparison` (``old_key``, ``title``, …)."""
    t = np.linspace(range_c[0], range_c[1], CURVE_POINTS)
    o, n = np.asarray(old(t)).reshape(t.size, -1), np.asarray(new(t)).reshape(t.size, -1)
    return CoefficientComparison(
        sensor, unit, tuple((p, float(a), float(b)) for p, a, b in parameters),
        tuple(float(x) for x in t),
        {a: tuple(float(x) for x in o[:, j]) for j, a in enumerate(axes)},
        {a: tuple(float(x) for x in n[:, j]) for j, a in enumerate(axes)},
        formula, **labels,
    )  # fmt: skip


__all__ = ["CURVE_POINTS", "CoefficientComparison", "compare_coefficients"]
