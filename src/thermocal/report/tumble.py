"""The tumble test as a self-contained HTML page (the tumble command's report): the
coefficients table, then the output against the head's angle with the fitted harmonics and,
below, each point's residual with what the second harmonic (K2, K_ip) adds.  matplotlib is
imported only when a figure is drawn."""

from __future__ import annotations

from html import escape
from typing import TYPE_CHECKING

import numpy as np

from thermocal.report.figures import _figure
from thermocal.report.ratetable import STYLE, _table_html, _uri
from thermocal.report.tumble_text import tumble_text
from thermocal.tumble.analysis import harmonic_design

if TYPE_CHECKING:
    from thermocal.pipeline.tumble import TumbleResult


def harmonics_figure(res: TumbleResult) -> str:
    """The output minus its first harmonic against the angle: the stations' means (1σ
    bars; every sample of a continuous tumble), the fitted higher harmonics and the residual.

    Parameters
    ----------
    res : TumbleResult
        The test.

    Returns
    -------
    str
        A PNG ``data:`` URI.
    """
    fit = res.fit
    c = fit.coefficients
    grid = np.linspace(0.0, 360.0, 361)
    higher = harmonic_design(grid, fit.harmonics)[:, 3:] @ c[3:]
    with _figure(2, 3.0, sharex=True) as (fig, axes):
        if res.stations:  # a continuous tumble: the fitted curve only
            th = np.array([s.angle_deg for s in res.stations]) % 360.0
            se = np.array([s.se for s in res.stations])
            pts = (harmonic_design(th, fit.harmonics)[:, 3:] @ c[3:]) + fit.residuals
            axes[0].errorbar(th, pts, se, marker="o", ms=3, ls="", capsize=2, label="stations")
            axes[1].errorbar(th, fit.residuals, se, marker="o", ms=3, ls="", capsize=2)
        axes[0].plot(grid, higher, label="second (and higher) harmonics fitted")
        axes[0].set_ylabel(f"output − a0 − 1st harmonic [{res.output_unit}]")
        axes[1].axhline(0.0, color="0.5", lw=0.8)
        axes[1].set_ylabel(f"residual [{res.output_unit}]")
        axes[1].set_xlabel("head angle θ [°] (0: input axis up, 90: pendulous axis up)")
        axes[1].set_xticks(range(0, 361, 45))
        axes[0].legend(fontsize=8)
        return _uri(fig)


def tumble_html(res: TumbleResult, title: str = "Tumble test") -> str:
    """The tumble test's page: the text rendering's lines and table, then the figure.

    Parameters
    ----------
    res : TumbleResult
        The test.
    title : str
        The page's title.

    Returns
    -------
    str
        A self-contained HTML page (figure embedded).
    """
    parts = [
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{escape(title)}</title>"
        f"<style>{STYLE}</style></head><body><h1>{escape(title)}</h1>",
        "<p>The model equation and the tumble test of IEEE Std 1293-1998. Uncertainties are "
        "1σ.</p>",
    ]
    for b in tumble_text(res):
        parts.append(f"<p>{escape(b)}</p>" if isinstance(b, str) else _table_html(b))
    parts.append(
        f'<figure><img class="figure" id="fig-tumble-harmonics" src="{harmonics_figure(res)}" '
        'alt="output against the head angle, its harmonics and residuals"></figure>'
    )
    parts.append("</body></html>\n")
    return "\n".join(parts)
