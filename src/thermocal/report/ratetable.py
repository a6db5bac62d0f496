"""The rate-table test as a self-contained HTML spec sheet (``thermocal ratetable``'s report):
each ladder's spec-sheet table, the nonlinearity and bias per rate with their 1σ bars, and
with ladders at several temperatures the scale factor against temperature with its fitted
coefficient.  matplotlib is imported only when a figure is drawn."""

from __future__ import annotations

import base64
from html import escape
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal.report.figures import _figure, _png
from thermocal.report.ratetable_text import ratetable_text
from thermocal.report.text import TextTable

if TYPE_CHECKING:
    from thermocal.pipeline.ratetable import RateTableResult
    from thermocal.ratetable.analysis import TemperatureCoefficient

STYLE = (
    "body{font-family:sans-serif;max-width:60em;margin:2em auto;color:#222222}"
    "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:.2em .6em}"
    "td.n{text-align:right}img.figure{max-width:100%}"
)


def _uri(fig: Any) -> str:
    """A figure as a PNG ``data:`` URI."""
    return "data:image/png;base64," + base64.b64encode(_png(fig)).decode("ascii")


def nonlinearity_figure(res: RateTableResult) -> str:
    """Nonlinearity [ppm FS] and bias [°/h] per rate, one series per ladder, 1σ bars.

    Parameters
    ----------
    res : RateTableResult
        The test.

    Returns
    -------
    str
        A PNG ``data:`` URI.
    """
    rates = sorted({r.rate_dps for ld in res.ladders for r in ld.rows})
    pos = {r: i for i, r in enumerate(rates)}
    with _figure(2, 3.0, sharex=True) as (fig, axes):
        for ld in res.ladders:
            x = [pos[r.rate_dps] for r in ld.rows]
            lab = f"{ld.temperature_c:.1f} °C" if ld.temperature_c is not None else "ladder"
            nl = [r.nonlinearity_ppm_fs for r in ld.rows]
            axes[0].errorbar(
                x,
                nl,
                [r.nonlinearity_sigma_ppm_fs for r in ld.rows],
                marker="o",
                ms=3,
                capsize=2,
                label=lab,
            )
            bias = [r.bias_dps * 3600 for r in ld.rows]
            axes[1].errorbar(
                x,
                bias,
                [r.bias_sigma_dps * 3600 for r in ld.rows],
                marker="o",
                ms=3,
                capsize=2,
                label=lab,
            )
        axes[0].set_ylabel("deviation from the line [ppm FS]")
        axes[1].set_ylabel("bias at the rate [°/h]")
        axes[1].set_xlabel("input rate [°/s] (one tick per rate of the ladder)")
        axes[1].set_xticks(range(len(rates)), [f"{r:g}" for r in rates], rotation=60)
        axes[0].legend(fontsize=8)
        return _uri(fig)


def scale_factor_figure(tc: TemperatureCoefficient) -> str:
    """The ladders' scale factors against temperature with the fitted line (1σ bars).

    Parameters
    ----------
    tc : TemperatureCoefficient
        The coefficient and the points it was fitted to.

    Returns
    -------
    str
        A PNG ``data:`` URI.
    """
    t = np.array(tc.temperatures_c)
    k = np.array(tc.scale_factors)
    with _figure(1, 3.2) as (fig, axes):
        ax = axes[0]
        ppm = (k / tc.k_at_tref - 1) * 1e6
        ax.errorbar(
            t,
            ppm,
            np.array(tc.sigmas) / tc.k_at_tref * 1e6,
            marker="o",
            ls="",
            capsize=3,
            label="ladders",
        )
        tt = np.linspace(t.min(), t.max(), 50)
        ax.plot(
            tt,
            tc.ppm_per_c * (tt - tc.tref_c),
            label=f"{tc.ppm_per_c:.3g} ± {tc.sigma_ppm_per_c:.2g} ppm/°C",
        )
        ax.set_xlabel("temperature [°C]")
        ax.set_ylabel(f"K / K({tc.tref_c:.1f} °C) − 1 [ppm]")
        ax.legend(fontsize=8)
        return _uri(fig)


def _table_html(t: TextTable) -> str:
    """A text table as an HTML table."""
    head = "".join(f"<th>{escape(c)}</th>" for c in t.columns)
    rows = "".join(
        "<tr>"
        + "".join(
            f'<td class="{"n" if j == "right" else ""}">{escape(c)}</td>'
            for c, j in zip(r, t.justify, strict=True)
        )
        + "</tr>"
        for r in t.rows
    )
    cap = f"<caption>{escape(t.title)}</caption>" if t.title else ""
    return f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>"


def ratetable_html(res: RateTableResult, title: str = "Rate-table test") -> str:
    """The spec-sheet page: the text rendering's tables and lines, then the figures.

    Parameters
    ----------
    res : RateTableResult
        The test.
    title : str
        The page's title.

    Returns
    -------
    str
        A self-contained HTML page (figures embedded).
    """
    head = (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{escape(title)}</title>"
        f"<style>{STYLE}</style></head><body><h1>{escape(title)}</h1>"
    )
    return "\n".join([head, ratetable_section(res), "</body></html>\n"])


def ratetable_section(res: RateTableResult) -> str:
    """The spec sheet as an HTML fragment: the standards, the text rendering's tables and
    lines, then the figures (the rate-table test's own page, and its section in a model's
    report).

    Parameters
    ----------
    res : RateTableResult
        The test.

    Returns
    -------
    str
        HTML, figures embedded; text escaped.
    """
    parts = [
        "<p>Terms of IEEE Std 528-2001; test procedures of IEEE Std 952-1997 and IEEE Std "
        "1431-2004. Uncertainties are 1σ, from the plateaus' noise.</p>",
    ]
    for b in ratetable_text(res):
        parts.append(f"<p>{escape(b)}</p>" if isinstance(b, str) else _table_html(b))
    parts.append(
        f'<figure><img class="figure" id="fig-ratetable-nonlinearity" '
        f'src="{nonlinearity_figure(res)}" alt="nonlinearity and bias per rate">'
        "</figure>"
    )
    tc = res.temperature_coefficient
    if tc is not None:
        parts.append(
            f'<figure><img class="figure" id="fig-ratetable-temperature" '
            f'src="{scale_factor_figure(tc)}" alt="scale factor against temperature">'
            "</figure>"
        )
    return "\n".join(parts)
