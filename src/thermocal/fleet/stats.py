"""The fleet's figures and their statistics across units: the figure names a unit
records, the unit a channel's figures are shown in, robust z-scores and outliers.  Shared by
the batch driver (:mod:`thermocal.fleet.batch`) and its report (:mod:`thermocal.fleet.report`)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

FIT_FIGURES = ("rms_residual", "condition_number", "n_coefficients", "n_samples")
"""Per-channel figures of a fit (the JSON of the ``fit`` command), in the summary."""


VALIDATION_FIGURES = (
    "r",
    "rms_before",
    "rms_after",
    "peak_to_peak_before",
    "peak_to_peak_after",
    "bias_stability_before",
    "bias_stability_after",
    "bias_repeatability_before",
    "bias_repeatability_after",
)
"""Per-channel figures of a validation (the JSON of the ``validate`` command), in the summary."""


FIGURES = FIT_FIGURES + VALIDATION_FIGURES


UNITLESS = frozenset({"r", "condition_number", "n_coefficients", "n_samples"})
"""Figures without a unit (every other figure is in the channel's data unit)."""


def shown_unit(model_unit: str, data_unit: str) -> tuple[str, float]:
    """The unit a channel's figures are shown in and the factor taking a value in the
    model's unit to it: ``(data_unit, f)`` with ``x[data_unit] = f · x[model_unit]``
    (:func:`thermocal.units.convert`, e.g. 1/3600 from °/h to °/s) when both are physical
    units of one kind; otherwise (raw counts, made physical by a scale factor) the model's
    own unit and 1.

    Parameters
    ----------
    model_unit : str
        The unit of the channel's model (``"deg/h"``).
    data_unit : str
        The unit of the channel's data column (``"deg/s"``).

    Returns
    -------
    tuple of (str, float)
        The shown unit and the factor from the model's unit to it.

    Examples
    --------
    >>> unit, f = shown_unit("deg/h", "deg/s")
    >>> unit, f * 3600
    ('deg/s', 1.0)
    """
    from thermocal import units
    from thermocal.errors import UnitError

    try:
        shown = units.shown_unit(model_unit, units.normalize_signal_unit(data_unit))
    except UnitError:
        return model_unit, 1.0
    return shown.unit, shown.to_shown


def convert_unit_label(unit: str, model_unit: str, shown: str) -> str | None:
    """``deg/h/degC^2`` → ``deg/s/degC^2``: the unit of a coefficient proportional to the
    signal (its unit starts with the model's signal unit) in the shown unit; None when the
    coefficient is not in the signal's unit (a breakpoint in °C, a time constant).

    Parameters
    ----------
    unit : str
        The coefficient's unit.
    model_unit : str
        The model's signal unit.
    shown : str
        The unit the signal is shown in.

    Returns
    -------
    str or None

    Examples
    --------
    >>> convert_unit_label("deg/h/degC^2", "deg/h", "deg/s")
    'deg/s/degC^2'
    >>> convert_unit_label("degC", "deg/h", "deg/s") is None
    True
    """
    if unit == model_unit or unit.startswith(model_unit + "/"):
        return shown + unit[len(model_unit) :]
    return None


def robust_z(values: Iterable[float]) -> list[float]:
    r"""Modified z-scores of a figure across the units of a batch.

    Parameters
    ----------
    values : iterable of float
        The figure of each unit (NaN or inf: missing).

    Returns
    -------
    list of float
        One score per value; NaN where the value is missing, or everywhere when fewer
        than three values are finite or the MAD is zero.

    Notes
    -----
    .. math::

        z_i = \frac{0.6745\,(x_i - \tilde x)}{\operatorname{MAD}}, \qquad
        \operatorname{MAD} = \operatorname{median}_j |x_j - \tilde x| ,

    with :math:`\tilde x` the median of the finite values; :math:`|z| >` :data:`OUTLIER_Z`
    (3.5) marks an outlier.  0.6745 is the 0.75 quantile of the standard normal
    distribution, so that :math:`z` is a standard score for normal data.

    References
    ----------
    B. Iglewicz and D. C. Hoaglin, *How to Detect and Handle Outliers*, ASQC Basic
    References in Quality Control vol. 16, ASQC Quality Press, 1993.

    Examples
    --------
    Median 3, MAD 1 (worked out by hand), so the scores are 0.6745 (x − 3):

    >>> [round(z, 3) for z in robust_z([1, 2, 3, 4, 100])]
    [-1.349, -0.674, 0.0, 0.674, 65.427]
    """
    import numpy as np

    x = np.asarray(list(values), dtype=np.float64)
    ok = np.isfinite(x)
    if ok.sum() < 3:
        return [math.nan] * x.size
    med = float(np.median(x[ok]))
    mad = float(np.median(np.abs(x[ok] - med)))
    if not mad > 0:
        return [math.nan] * x.size
    return [float(0.6745 * (v - med) / mad) if math.isfinite(v) else math.nan for v in x]


OUTLIER_Z = 3.5
"""|modified z| above this names a unit as an outlier (Iglewicz & Hoaglin)."""


def common_unit(figs: Sequence[Mapping[str, Any]]) -> tuple[str, list[float]]:
    """The unit most of a channel's units are shown in, and per record the factor taking
    its signal figures there (NaN where it cannot be converted: left out of comparisons
    across units).  A batch whose files give one channel in different units is compared in
    one unit.

    Parameters
    ----------
    figs : sequence of mapping
        One channel's figures per unit, each with its ``"unit"``.

    Returns
    -------
    tuple of (str, list of float)
        The common unit and one factor per record.

    Examples
    --------
    >>> common_unit([{"unit": "deg/h"}, {"unit": "deg/h"}, {"unit": "deg/s"}])
    ('deg/h', [1.0, 1.0, 3600.0])
    """
    from collections import Counter

    names = [str(f.get("unit") or "") for f in figs]
    if not names:
        return "", []
    unit = Counter(names).most_common(1)[0][0]
    factors = []
    for n in names:
        if n == unit:
            factors.append(1.0)
            continue
        shown, f = shown_unit(n, unit)
        factors.append(f if shown == unit else math.nan)
    return unit, factors


SERIES_FIGURES = ("rms_residual", "rms_after", "bias_stability_after")
"""The figures of a channel compared across the units (:func:`channel_series`: the outliers
and the report)."""
HISTOGRAM_FIGURES = {"rms_residual": "fit rms residual", "rms_after": "validation rms after"}
"""The figures whose distribution across the units the report draws, with their labels."""


def channel_series(figs: Sequence[Mapping[str, Any]]) -> tuple[str, dict[str, list[float]]]:
    """A channel's figures and coefficients across units, each in one unit
    (:func:`common_unit`): ``(unit, {what: values})``, ``what`` a figure name or
    ``coefficient <term>``.

    Parameters
    ----------
    figs : sequence of mapping
        One channel's figures per unit (the JSON figures of the ``fit`` and ``validate``
        commands, ``coefficients`` and ``coefficient_units``).

    Returns
    -------
    tuple of (str, dict)
        The common unit and each series (NaN where a unit lacks the value).
    """
    unit, factors = common_unit(figs)
    series: dict[str, list[float]] = {}
    for n in SERIES_FIGURES:
        series[n] = [_num(f.get(n)) * k for f, k in zip(figs, factors, strict=True)]
    terms = sorted({t for f in figs for t in (f.get("coefficients") or {})})
    for t in terms:
        vals = []
        for f, k in zip(figs, factors, strict=True):
            cu = str((f.get("coefficient_units") or {}).get(t, ""))
            scaled = convert_unit_label(cu, str(f.get("unit") or ""), unit) is not None
            vals.append(_num((f.get("coefficients") or {}).get(t)) * (k if scaled else 1.0))
        series[f"coefficient {t}"] = vals
    return unit, series


def coefficient_unit(figs: Sequence[Mapping[str, Any]], term: str, unit: str) -> str:
    """The unit of a coefficient across units, in the channel's common ``unit``.

    Parameters
    ----------
    figs : sequence of mapping
        One channel's figures per unit.
    term : str
        The coefficient's term name.
    unit : str
        The channel's common unit.

    Returns
    -------
    str
        The unit label, or ``""`` when no record gives one.
    """
    for f in figs:
        cu = (f.get("coefficient_units") or {}).get(term)
        if cu:
            label = convert_unit_label(str(cu), str(f.get("unit") or ""), unit)
            return label if label is not None else str(cu)
    return ""


def outliers(records: Mapping[str, Mapping[str, Any] | None]) -> list[dict[str, Any]]:
    """Units whose figure or coefficient is a robust outlier among the ok units, per
    channel: ``{"id", "channel", "what", "value", "unit", "z"}`` (the value in the
    channel's common data unit, :func:`channel_series`), largest |z| first.

    Parameters
    ----------
    records : mapping of str to mapping or None
        Each unit's summary record by unit id (``status`` and ``channels``); units that did
        not finish (``status`` other than ``"ok"``) are left out.

    Returns
    -------
    list of dict
        One entry per outlying value, largest |z| first.

    Examples
    --------
    Six gyros, one of them with a validation rms five times the others'.  Median 0.105, MAD
    0.01 (by hand), so z = 0.6745 × 0.395 / 0.01 = 26.6:

    >>> rms = [0.10, 0.11, 0.09, 0.10, 0.12, 0.5]
    >>> records = {f"u{i}": {"status": "ok", "channels": {"gyro": {"unit": "deg/h",
    ...                                                             "rms_after": v}}}
    ...            for i, v in enumerate(rms)}
    >>> [(o["id"], o["what"], round(o["z"], 1)) for o in outliers(records)]
    [('u5', 'rms_after', 26.6)]
    """
    ok = {k: v for k, v in records.items() if v and v.get("status") == "ok"}
    found: list[dict[str, Any]] = []
    channels = sorted({ch for v in ok.values() for ch in (v.get("channels") or {})})
    for ch in channels:
        ids = [k for k, v in ok.items() if ch in (v.get("channels") or {})]
        figs = [ok[k]["channels"][ch] for k in ids]
        unit, series = channel_series(figs)
        for what, vals in series.items():
            if what.startswith("coefficient "):
                what_unit = coefficient_unit(figs, what[len("coefficient ") :], unit)
            else:
                what_unit = unit
            for uid, v, z in zip(ids, vals, robust_z(vals), strict=True):
                if math.isfinite(z) and abs(z) > OUTLIER_Z:
                    found.append(
                        {"id": uid, "channel": ch, "what": what, "value": v, "unit": what_unit,
                         "z": z}
                    )  # fmt: skip
    return sorted(found, key=lambda d: -abs(d["z"]))


def _num(v: Any) -> float:
    try:
        return float(v) if v is not None else math.nan
    except (TypeError, ValueError):
        return math.nan


__all__ = [
    "FIGURES",
    "FIT_FIGURES",
    "HISTOGRAM_FIGURES",
    "OUTLIER_Z",
    "SERIES_FIGURES",
    "UNITLESS",
    "VALIDATION_FIGURES",
    "channel_series",
    "coefficient_unit",
    "common_unit",
    "convert_unit_label",
    "outliers",
    "robust_z",
    "shown_unit",
]
