"""HTML report of a calibration of triads over temperature (issue 19): for each triad every
parameter against temperature — the per-run estimates with their ±1σ error bars, the fitted
polynomial and its ±1σ band — a table of the polynomials (order, value at TREF, LOTO rms) and
of the runs, and, on an independent turntable run, the dwell-mean and move-angle errors
before and after compensation (:func:`thermocal.turntable.calibrate.validate_triads`).
One self-contained file; matplotlib and jinja2 are imported here only."""

from __future__ import annotations

import base64
import datetime as _dt
from pathlib import Path
from typing import Any

import numpy as np

from thermocal.writers import write_html


def _b64(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _figure(tri: Any) -> bytes:
    """Twelve panels: each parameter against temperature."""
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
            ax.fill_between(grid, curve[:, k] - band[:, k], curve[:, k] + band[:, k],
                            color="#1f6fb2", alpha=0.2, linewidth=0)  # fmt: skip
            ax.plot(grid, curve[:, k], color="#1f6fb2", linewidth=1.2)
            if m.runs:
                t = [r[0] for r in m.runs]
                v = [r[1][k] for r in m.runs]
                e = [r[2][k] for r in m.runs]
                ax.errorbar(t, v, yerr=e, fmt="o", color="#c0392b", markersize=3, capsize=2)
            ax.set_title(f"{f.name} [{f.unit}] (order {len(f.coef) - 1})", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(True, color="#dddddd", linewidth=0.5)
        for ax in axes[-1, :]:
            ax.set_xlabel("temperature [°C]", fontsize=8)
        return _png(fig)


def build_triad_report(
    cal: Any,
    cal_path: str | Path,
    validation: list[Any] | None,
    recording_path: str | Path | None,
) -> str:
    from thermocal import __version__
    from thermocal.report.build import _env
    from thermocal.report.multipos import pose_section

    triads = []
    for tri in cal.triads:
        m = tri.model
        triads.append(
            {
                "name": tri.name,
                "kind": m.kind,
                "columns": ", ".join(tri.columns),
                "unit": tri.unit,
                "temperature": tri.temperature,
                "tref": m.tref_c,
                "range": f"{m.t_lo_c:g} … {m.t_hi_c:g}",
                "img": _b64(_figure(tri)),
                "params": [
                    {
                        "name": f.name,
                        "unit": f.unit,
                        "order": len(f.coef) - 1,
                        "at_tref": f"{f.coef[0]:.5g}",
                        "sigma": f"{f.sigma[0]:.3g}",
                        "loto": f"{f.loto_rms:.3g}",
                    }
                    for f in m.fits
                ],
                "runs": [
                    {"t": f"{t:.3g}", "theta": [f"{v:.4g}" for v in th]} for t, th, _s in m.runs
                ],
                "names": [f.name for f in m.fits],
            }
        )
    val = []
    for r in validation or []:
        for label, before, after in r.rows():
            val.append(
                {
                    "triad": r.triad,
                    "label": label,
                    "cells": [f"{b:.4g} → {a:.4g}" for b, a in zip(before, after, strict=True)],
                }
            )
    html: str = (
        _env()
        .get_template("triads.html.j2")
        .render(
            title=f"Triad calibration over temperature — {Path(cal_path).name}",
            version=__version__,
            generated_utc=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
            triads=triads,
            validation=val,
            recording=str(recording_path) if recording_path else None,
            multipos=pose_section(validation),
        )
    )
    return html


def write_triad_report(path: str | Path, *args: Any) -> Path:
    return write_html(path, build_triad_report(*args))


__all__ = ["build_triad_report", "write_triad_report"]
