"""``DIR/fleet.html``: the report of a production batch.

Yield (calibrated, passed, failed), the distribution of each channel's residual figures and
fitted coefficients across the units (each coefficient as a robust z-score, so that terms of
different sizes share one axis), the robust outliers named (modified z-score above
:data:`thermocal.fleet.stats.OUTLIER_Z`, Iglewicz & Hoaglin 1993), the failed units with their
errors and the units outside the limits.  One self-contained file (figures as data URIs);
matplotlib and jinja2 are imported here only.
"""

from __future__ import annotations

import base64
import datetime as _dt
import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal.fleet.stats import HISTOGRAM_FIGURES, OUTLIER_Z, channel_series, outliers, robust_z
from thermocal.writers import write_html

if TYPE_CHECKING:
    from thermocal.fleet.config import FleetConfig

_COLOURS = ("#1f6fb2", "#c0392b", "#2e8b57", "#8e44ad")
"""Colours of the histograms, in the order of :data:`thermocal.fleet.stats.HISTOGRAM_FIGURES`."""


def _b64(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _fmt(v: Any, digits: int = 4) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    if isinstance(v, float):
        return f"{v:.{digits}g}"
    return str(v)


def _figure_distributions(channel: str, ok: Mapping[str, Mapping[str, Any]]) -> bytes:
    """Histograms of a channel's rms residual and (if validated) rms after compensation,
    in the channel's data unit (:func:`thermocal.fleet.stats.channel_series`), and a strip plot
    of every coefficient's robust z-score across the units."""
    from thermocal.report.figures import _figure, _png

    figs = [r["channels"][channel] for r in ok.values()]
    unit, series = channel_series(figs)
    terms = [k[len("coefficient ") :] for k in series if k.startswith("coefficient ")]
    with _figure(nrows=2, height_in=2.6) as (fig, axes):
        ax = axes[0]
        for (key, label), colour in zip(HISTOGRAM_FIGURES.items(), _COLOURS, strict=False):
            vals = np.array(series[key], dtype=float)
            vals = vals[np.isfinite(vals)]
            if vals.size:
                ax.hist(vals, bins=max(5, min(30, vals.size // 2)), alpha=0.6, color=colour,
                        label=f"{label} (n={vals.size})")  # fmt: skip
        ax.set_xlabel(f"{channel} [{unit}]", fontsize=9)
        ax.set_ylabel("units", fontsize=9)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
        ax = axes[1]
        for j, t in enumerate(terms):
            z = np.array(robust_z(series[f"coefficient {t}"]), dtype=float)
            z = z[np.isfinite(z)]
            jitter = (np.arange(z.size) % 7 - 3) * 0.05
            out = np.abs(z) > OUTLIER_Z
            ax.scatter(z[~out], j + jitter[~out], s=8, color="#555555")
            ax.scatter(z[out], j + jitter[out], s=14, color="#c0392b")
        ax.set_yticks(range(len(terms)))
        ax.set_yticklabels(terms, fontsize=7)
        ax.axvline(-OUTLIER_Z, color="#c0392b", linewidth=0.8, linestyle="--")
        ax.axvline(OUTLIER_Z, color="#c0392b", linewidth=0.8, linestyle="--")
        ax.set_xlabel(
            f"coefficient, robust z-score across units (|z| > {OUTLIER_Z:g}: outlier)", fontsize=9
        )
        fig.set_size_inches(9.0, 2.8 + max(2.0, 0.18 * len(terms)))
        return _png(fig)


def _templates() -> Any:
    """The report templates as every report reads them (``thermocal.report``'s, escaped,
    undefined names an error), without the calibration report's filters, which the batch's
    template does not use: importing them (``thermocal.report.build`` and the analysis
    modules behind it) was a fixed cost of every batch."""
    import jinja2

    return jinja2.Environment(
        loader=jinja2.PackageLoader("thermocal.report", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        trim_blocks=True,
        lstrip_blocks=True,
        undefined=jinja2.StrictUndefined,
    )


def build_fleet_report(
    config: FleetConfig,
    records: Mapping[str, Mapping[str, Any] | None],
    redone: Mapping[str, str] | None = None,
) -> str:
    """The batch report as one HTML document (module docstring); every figure in its
    channel's data unit, as ``unit.json`` holds it; ``redone``: the units redone in this
    run and why.

    Parameters
    ----------
    config : FleetConfig
        The batch.
    records : mapping of str to mapping or None
        Each unit's ``unit.json`` by id (None: not done).
    redone : mapping of str to str, optional
        The units redone in this run and why.

    Returns
    -------
    str
        The self-contained HTML document.
    """
    from thermocal import __version__

    units = []
    for u in config.units:
        rec = records.get(u.id)
        units.append(
            {
                "id": u.id,
                "status": (rec or {}).get("status", "pending"),
                "pass": (rec or {}).get("pass"),
                "error": (rec or {}).get("error") or ("not run yet" if rec is None else ""),
                "reasons": "; ".join((rec or {}).get("fail_reasons") or []),
                "channels": {
                    ch: {
                        k: _fmt(v)
                        for k, v in f.items()
                        if k not in ("coefficients", "coefficient_units")
                    }
                    for ch, f in ((rec or {}).get("channels") or {}).items()
                },
                "coefficients": [
                    {
                        "channel": ch,
                        "name": name,
                        "value": _fmt(value, 6),
                        "unit": (f.get("coefficient_units") or {}).get(name, ""),
                    }
                    for ch, f in ((rec or {}).get("channels") or {}).items()
                    for name, value in (f.get("coefficients") or {}).items()
                ],
                "n_warnings": len((rec or {}).get("warnings") or []),
            }
        )
    ok = {k: v for k, v in records.items() if v and v.get("status") == "ok"}
    channels = sorted({ch for v in ok.values() for ch in (v.get("channels") or {})})
    figures = [
        {"channel": ch, "img": _b64(_figure_distributions(ch, {k: v for k, v in ok.items()
                                                              if ch in v["channels"]}))}
        for ch in channels
    ]  # fmt: skip
    n = len(units)
    n_ok = sum(1 for u in units if u["status"] == "ok")
    n_failed = sum(1 for u in units if u["status"] == "failed")
    n_pass = sum(1 for u in units if u["status"] == "ok" and u["pass"] is True)
    html: str = (
        _templates()
        .get_template("fleet.html.j2")
        .render(
            title=f"Production batch — {config.path.name}",
            version=__version__,
            generated_utc=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
            n=n,
            n_ok=n_ok,
            n_failed=n_failed,
            n_pending=n - n_ok - n_failed,
            n_pass=n_pass,
            yield_pct=100.0 * n_pass / n if n else 0.0,
            limits=[lim.label for lim in config.limits],
            units=units,
            channels=channels,
            figures=figures,
            outliers=[
                {**o, "value": _fmt(o["value"]), "z": f"{o['z']:+.1f}"}
                for o in outliers(records)[:50]
            ],
            failed=[u for u in units if u["status"] == "failed"],
            redone=sorted((redone or {}).items()),
            out_of_limits=[u for u in units if u["status"] == "ok" and u["pass"] is False],
            fit_options=config.fit_options,
        )
    )
    return html


def write_fleet_report(
    path: str | Path,
    config: FleetConfig,
    records: Mapping[str, Mapping[str, Any] | None],
    redone: Mapping[str, str] | None = None,
) -> Path:
    """Build the batch report and write it atomically; returns the path.

    Parameters
    ----------
    path : str or pathlib.Path
        The HTML file to write.
    config, records, redone
        As :func:`build_fleet_report`.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    return write_html(path, build_fleet_report(config, records, redone))


__all__ = ["build_fleet_report", "write_fleet_report"]
