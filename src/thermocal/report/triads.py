"""HTML report of a calibration of triads: for each triad its parameters
in the calibration's own units (a bias in the triad's unit, °/s for a °/s calibration; scale
factors [ppm], misalignments [″]) with their σ, and, on an independent run, the figures
before and after compensation: a turntable run's dwell-mean and move-angle errors
(:func:`thermocal.turntable.calibration.validate_turntable_run`) or a multipos held-out
session's gravity-magnitude and rotation-angle errors
(:func:`thermocal.multipos.validate.validate_held_out_session`), first as the absolute
figures (rms over poses or motions, before → after, the change in %), then per axis.
Each triad's second-order term comes with it (:func:`term_section`): a gyro's g-sensitivity
``A`` (3×3) or an accelerometer's ``K2`` (per axis), each element with its σ and ``|v|/σ``
(beyond 3σ marked), or why the calibration holds none.

Against temperature only what was measured against it: a triad calibrated over several
temperatures (a multi-position calibration with ``temps`` and a file per temperature, or a
turntable over temperature) gets every parameter plotted against the real run temperatures
with the fitted polynomial and its ±1σ band, and a table of the runs; a triad calibrated at
one temperature, or without a temperature column, gets the table only and says so (no point
is plotted against a temperature nobody measured).  A column with nothing to show (the leave-one-
temperature-out rms of a one-temperature calibration) is left out and the reason given.
One self-contained file; matplotlib and jinja2 are imported here only."""

from __future__ import annotations

import base64
import datetime as _dt
import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import units
from thermocal.writers import write_html


def _b64(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def display_factors(tri: Any) -> list[tuple[float, str]]:
    """Per parameter of ``tri``'s model, the factor and unit it is shown in: a bias
    (stored in °/h or mg) in the triad's own unit (``Triad.unit``), the others as stored.

    Parameters
    ----------
    tri
        The triad calibration.

    Returns
    -------
    list of (float, str)
        Per axis the factor to the shown unit and the unit.
    """
    out = []
    for f in tri.model.fits:
        if f.name.startswith("bias") and f.unit != tri.unit:
            out.append((float(units.convert(np.array([1.0]), f.unit, tri.unit)[0]), tri.unit))
        else:
            out.append((1.0, str(f.unit)))
    return out


def run_temperatures(tri: Any) -> list[float]:
    """The distinct temperatures [°C] the triad was calibrated at (none without a
    temperature column: the TREF recorded then is no measurement).

    Parameters
    ----------
    tri
        The triad calibration.

    Returns
    -------
    list of float
        The runs' temperatures [°C].
    """
    if not tri.temperature:
        return []
    return sorted({round(float(r[0]), 6) for r in tri.model.runs})


def _figure(tri: Any, shown: list[tuple[float, str]]) -> bytes:
    """Twelve panels: each parameter against the runs' temperatures, in its shown unit."""
    from thermocal.report.figures import _figure as new_figure
    from thermocal.report.figures import _png

    m = tri.model
    grid = np.linspace(m.t_lo_c, m.t_hi_c, 200)
    curve = m.theta_at(grid)
    band = m.sigma_at(grid)
    with new_figure(nrows=1, height_in=9.0) as (fig, _axes):
        fig.clear()
        axes = fig.subplots(4, 3)
        for k, f in enumerate(m.fits):
            ax = axes.flat[k]
            c, u = shown[k]
            ax.fill_between(grid, c * (curve[:, k] - band[:, k]), c * (curve[:, k] + band[:, k]),
                            color="#1f6fb2", alpha=0.2, linewidth=0)  # fmt: skip
            ax.plot(grid, c * curve[:, k], color="#1f6fb2", linewidth=1.2)
            t = [r[0] for r in m.runs]
            v = [c * r[1][k] for r in m.runs]
            e = [c * r[2][k] for r in m.runs]
            ax.errorbar(t, v, yerr=e, fmt="o", color="#c0392b", markersize=3, capsize=2)
            ax.set_title(f"{f.name} [{u}] (order {len(f.coef) - 1})", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(True, color="#dddddd", linewidth=0.5)
        for ax in axes[-1, :]:
            ax.set_xlabel("temperature [°C]", fontsize=8)
        return _png(fig)


def _temperature_text(tri: Any, temps: list[float]) -> str:
    """What the triad's parameters hold against temperature, in words."""
    m = tri.model
    if not tri.temperature:
        return ("Calibrated without a temperature column: the parameters apply unchanged at "
                "every temperature (nothing to plot against temperature).")  # fmt: skip
    if len(temps) < 2:
        return (f"Calibrated at one temperature, {temps[0]:.4g} °C (column {tri.temperature}): "
                "the parameters are held at every temperature; a plot against temperature "
                "needs sessions at several.")  # fmt: skip
    return (
        f"Every parameter against temperature: the runs at {len(temps)} temperatures (±1σ), "
        f"the fitted polynomial in T − {m.tref_c:g} °C and its ±1σ band; calibrated range "
        f"{m.t_lo_c:g} … {m.t_hi_c:g} °C (held at the ends outside it)."
    )


LOTO_NOTE = (
    "LOTO rms (leave one temperature out) not shown: it needs more temperatures than the "
    "polynomial order + 1"
)


def _sigma_text(c: float, f: Any) -> str:
    """A parameter's σ at TREF; "fixed (not estimated)" for one the model holds at zero
    (the accelerometer's upper misalignments: its axes define the body frame)."""
    if f.sigma[0] == 0 and not np.any(f.coef):
        return "fixed (not estimated)"
    return f"{c * f.sigma[0]:.3g}"


def _runs(runs: Any, shown: list[tuple[float, str]]) -> list[dict[str, Any]]:
    """The runs' table rows: temperature [°C] and each parameter in its shown unit."""
    return [
        {"t": f"{t:.4g}", "theta": [f"{c * v:.4g}" for v, (c, _u) in zip(th, shown, strict=True)]}
        for t, th, _s in runs
    ]


def _cell(v: float, s: float | None) -> dict[str, Any]:
    """A term's table cell: the value ± σ, ``|v|/σ`` and whether it lies beyond
    :data:`thermocal.multipos.gsens.SIGNIFICANT_SIGMA` σ (no σ: not judged)."""
    from thermocal.multipos.gsens import SIGNIFICANT_SIGMA

    if s is None or not s > 0:
        return {"text": f"{v:.4g}", "z": "—", "beyond": False}
    z = abs(v) / s
    return {"text": f"{v:.4g} ± {s:.2g}", "z": f"{z:.1f}", "beyond": z > SIGNIFICANT_SIGMA}


def _absent_why(tri: Any, triads: Any) -> str:
    """Why a gyro triad has no ``g_sensitivity`` or an accelerometer triad no ``k2`` in its
    file, as far as the file tells (it records what was stored, not what was found)."""
    if tri.model.kind == "gyro":
        if not any(t.model.kind == "accel" for t in triads):
            return ("not estimated: the calibration holds no accelerometer triad, whose "
                    "specific force A multiplies")  # fmt: skip
        when = (
            "every soak's dwells found an element beyond 3σ and took it off"
            if tri.model.method == "turntable"
            else "an element of the poses' estimate lies beyond 3σ (not c·I alone), or "
            "when asked for (g_sensitivity 'apply')"
        )
        return (f"not stored in this calibration: A is stored when {when}; the calibrating "
                "command's output gives the estimate. The compensation leaves any "
                "g-sensitivity in the gyro's output")  # fmt: skip
    if tri.model.method == "turntable":
        return ("not estimated: the turntable's accelerometer fit holds the bias, scale "
                "factors and misalignments alone (the tumble test gives one axis's "
                "K2)")  # fmt: skip
    return ("not estimated: the calibration was fitted without K2 (multi-position poses at a "
            "slant to every axis give it with accel_k2; the six faces cannot)")  # fmt: skip


def term_section(tri: Any, triads: Any) -> dict[str, Any] | None:
    """A triad's second-order term as the report shows it: a gyro's g-sensitivity ``A``
    (3×3, row the gyro axis, column the specific force's axis) or an accelerometer's ``K2``
    (per axis), each element with its σ and ``|value|/σ`` (beyond 3σ marked), or why the
    calibration holds none; None for a triad of another kind.

    Parameters
    ----------
    tri : Triad
        The triad (:class:`thermocal.models.calibration.Triad`).
    triads : sequence of Triad
        Every triad of the calibration (a gyro's A needs an accelerometer triad).

    Returns
    -------
    dict or None
        ``what``, ``symbol``, ``unit``, ``matrix`` (A: True), ``rows`` (each a label and
        its cells), ``absent`` (the reason, or None), ``formula``.

    Notes
    -----
    The gyro reads :math:`b + A f` more at rest under the specific force :math:`f` [g]
    (IEEE Std 952-1997 annex B); the accelerometer :math:`K_{2,i} (a_i/g)^2` more per axis
    (IEEE Std 1293-1998).  An element is significant when :math:`|v| > 3\\sigma`.

    References
    ----------
    - IEEE Std 952-1997, annex B (acceleration-sensitive drift).
    - IEEE Std 1293-1998 (the accelerometer's second-order coefficient K2).
    """
    kind = tri.model.kind
    if kind == "gyro":
        value, sigma, unit = tri.g_sensitivity, tri.g_sensitivity_sigma, tri.g_sensitivity_unit
        what, symbol = "g-sensitivity", "A"
        formula = (
            "compensate takes A f off: (I + E(T))⁻¹ (x − b(T) − A f), f the "
            "accelerometer's compensated output [g]"
        )
    elif kind == "accel":
        value, sigma, unit = tri.k2, tri.k2_sigma, tri.k2_unit
        what, symbol = "second-order coefficient", "K2"
        formula = "compensate inverts x = (I + E(T)) a + b(T) + K2 ⊙ (a/g)², g = 9.80665 m/s²"
    else:
        return None
    out: dict[str, Any] = {"what": what, "symbol": symbol, "unit": unit.replace("^2", "²"),
                           "matrix": kind == "gyro", "rows": [], "absent": None,
                           "formula": formula}  # fmt: skip
    if value is None:
        out["absent"] = _absent_why(tri, triads)
        return out
    v = np.asarray(value, dtype=np.float64)
    s = None if sigma is None else np.asarray(sigma, dtype=np.float64)
    if kind == "gyro":
        out["rows"] = [{"label": f"gyro {ax}",
                        "cells": [_cell(float(v[i, j]), None if s is None else float(s[i, j]))
                                  for j in range(3)]}
                       for i, ax in enumerate("xyz")]  # fmt: skip
    else:
        out["rows"] = [{"label": f"K2 {ax}",
                        "cells": [_cell(float(v[i]), None if s is None else float(s[i]))]}
                       for i, ax in enumerate("xyz")]  # fmt: skip
    return out


def _triad_section(tri: Any, triads: Any = ()) -> dict[str, Any]:
    """One triad's part of the report (module docstring)."""
    m = tri.model
    shown = display_factors(tri)
    temps = run_temperatures(tri)
    over_t = len(temps) >= 2
    loto = [f.loto_rms for f in m.fits]
    has_loto = over_t and any(math.isfinite(v) for v in loto)
    scale = getattr(tri, "count_scale", None)
    params = []
    for f, (c, u) in zip(m.fits, shown, strict=True):
        row = {"name": f.name, "unit": u, "order": len(f.coef) - 1,
               "at_tref": f"{c * f.coef[0]:.5g}", "sigma": _sigma_text(c, f),
               "loto": f"{c * f.loto_rms:.3g}" if math.isfinite(f.loto_rms) else "—"}  # fmt: skip
        params.append(row)
    return {
        "name": tri.name,
        "kind": m.kind,
        "columns": ", ".join(tri.columns),
        "unit": tri.unit,
        "counts": None if scale is None else f"{scale:.10g} {tri.unit}",
        "temperature": tri.temperature,
        "temperature_text": _temperature_text(tri, temps),
        "over_temperature": over_t,
        "has_loto": has_loto,
        "loto_note": None if has_loto or not over_t else LOTO_NOTE,
        "tref": m.tref_c,
        "img": _b64(_figure(tri, shown)) if over_t else None,
        "params": params,
        "runs": _runs(m.runs, shown) if over_t else [],
        "names": [f"{f.name} [{u}]" for f, (_c, u) in zip(m.fits, shown, strict=True)],
        "term": term_section(tri, triads),
    }


def _change(before: float, after: float) -> str:
    return f"{100.0 * (before - after) / before:.1f} %" if before else "—"


def _summary_of(r: Any) -> list[dict[str, Any]]:
    """One result's absolute figures: a multipos result's own totals (rms over poses or
    motions); a turntable result's per-figure 3-axis rms, ``√(Σ axis²)`` of the per-axis
    rms over the dwells or moves."""
    if hasattr(r, "rms_before"):
        what = f"{r.what} rms" if r.n > 1 else r.what
        return [{"triad": r.triad, "what": what, "n": r.n, "unit": r.unit,
                 "before": f"{r.rms_before:.4g}", "after": f"{r.rms_after:.4g}",
                 "change": _change(r.rms_before, r.rms_after)}]  # fmt: skip
    out = []
    for label, before, after in r.rows():
        m = re.fullmatch(r"(.*) \[(.*)\]", label)
        what, unit = (m.group(1), m.group(2)) if m else (label, "")
        b, a = float(np.sqrt(np.sum(np.square(before)))), float(np.sqrt(np.sum(np.square(after))))
        out.append({"triad": r.triad, "what": f"{what} (3-axis, √Σ axis²)",
                    "n": getattr(r, "n_dwells", ""), "unit": unit, "before": f"{b:.4g}",
                    "after": f"{a:.4g}", "change": _change(b, a)})  # fmt: skip
    return out


def validation_rows(validation: list[Any] | None) -> tuple[list[dict[str, Any]], ...]:
    """The validation's absolute figures (one row per figure: n, before, after, change in %
    and unit), its per-axis rows, and what it could not judge.

    Parameters
    ----------
    validation : sequence, optional
        The held-out validation results.

    Returns
    -------
    tuple of list of dict
    """
    summary: list[dict[str, Any]] = []
    per_axis: list[dict[str, Any]] = []
    notes: list[dict[str, Any]] = []
    for r in validation or []:
        summary += _summary_of(r)
        for label, before, after in r.rows():
            per_axis.append({"triad": r.triad, "label": label,
                             "cells": [f"{b:.4g} → {a:.4g}"
                                       for b, a in zip(before, after, strict=True)]})  # fmt: skip
        note = getattr(r, "not_judged", "")
        if note and note not in [n["text"] for n in notes]:
            notes.append({"triad": r.triad, "text": note})
    return summary, per_axis, notes


def _own_session(cal: Any, recording_path: str | Path | None) -> bool:
    """Whether the recording is a session the triads were calibrated on (its SHA-256 among
    their ``data``)."""
    from thermocal.pipeline.model_file import file_sha256

    known = {d.get("sha256") for t in cal.triads for d in t.data}
    path = Path(recording_path) if recording_path else None
    return bool(known) and path is not None and path.is_file() and file_sha256(path) in known


def build_triad_report(
    cal: Any,
    cal_path: str | Path,
    validation: list[Any] | None,
    recording_path: str | Path | None,
    *,
    title: str | None = None,
    sensor: str | None = None,
) -> str:
    """The report's HTML (module docstring); ``title`` default "Triad calibration —
    <file name>", ``sensor`` the sensor's name or serial number shown under it.

    Parameters
    ----------
    cal : Calibration
        The triad calibration.
    cal_path : str or pathlib.Path
        Its file (provenance).
    validation : sequence, optional
        The held-out validation results.
    recording_path : str or pathlib.Path, optional
        The validation run (provenance).
    title : str, optional
        The headline.
    sensor : str, optional
        The sensor's name.

    Returns
    -------
    str
        The self-contained HTML document.
    """
    from thermocal import __version__
    from thermocal.report.build import _env
    from thermocal.report.multipos import pose_section

    summary, per_axis, notes = validation_rows(validation)
    own = _own_session(cal, recording_path)
    html: str = (
        _env()
        .get_template("triads.html.j2")
        .render(
            title=title or f"Triad calibration — {Path(cal_path).name}",
            sensor=sensor,
            calibration=Path(cal_path).name,
            version=__version__,
            generated_utc=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
            triads=[_triad_section(tri, cal.triads) for tri in cal.triads],
            summary=summary,
            validation=per_axis,
            notes=notes,
            recording=str(recording_path) if recording_path else None,
            multipos=pose_section(validation),
            own_session=own,
            session_word="calibration" if own else "held-out",
        )
    )
    return html


def write_triad_report(path: str | Path, *args: Any, **kwargs: Any) -> Path:
    """Write :func:`build_triad_report`'s HTML to ``path`` (a temporary, then renamed).

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write.
    *args
        As :func:`build_triad_report`.
    **kwargs
        As :func:`build_triad_report`.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    return write_html(path, build_triad_report(*args, **kwargs))


__all__ = [
    "build_triad_report",
    "display_factors",
    "run_temperatures",
    "term_section",
    "validation_rows",
    "write_triad_report",
]
