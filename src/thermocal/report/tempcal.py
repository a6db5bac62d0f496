"""Report content of the flight-controller calibrations (issue 28, items 2 and 3).

:func:`comparison_html`: the coefficients active in the log against the new ones, a table
(per parameter old, new, difference) and a figure (the correction of each set over the
calibrated range, per axis), as a section of the sensor's calibration report.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from thermocal.report.build import _b64, unit_label

if TYPE_CHECKING:
    from thermocal.tempcal.compare import CoefficientComparison

OLD_COLOR = "#c0392b"
NEW_COLOR = "#1f6fb2"


def comparison_figure(cmp: CoefficientComparison) -> bytes:
    """One panel per axis: the old and the new correction [cmp.unit] against the
    temperature [°C] over the calibrated range (PNG)."""
    from thermocal.report.figures import _figure, _png

    t = np.asarray(cmp.temp_c)
    axes_names = list(cmp.new_curve)
    with _figure(len(axes_names), height_in=2.2, sharex=True) as (fig, axes):
        for ax, name in zip(axes, axes_names, strict=True):
            ax.plot(t, cmp.old_curve[name], color=OLD_COLOR, lw=1.4, label="in the log (old)")
            ax.plot(t, cmp.new_curve[name], color=NEW_COLOR, lw=1.4, ls="--", label="new")
            ax.set_ylabel(f"{name} [{unit_label(cmp.unit)}]", fontsize=9)
        axes[0].legend(fontsize=8, loc="best")
        axes[0].set_title(
            f"{cmp.sensor}: correction of the old and the new coefficients", fontsize=10
        )
        axes[-1].set_xlabel("temperature [°C]", fontsize=9)
        return _png(fig)


def comparison_html(cmp: CoefficientComparison) -> str:
    """The section ``#previous`` of a report: table and figure of :func:`comparison_figure`
    (each number also in ``data-old``/``data-new``/``data-difference`` at full precision)."""
    from markupsafe import escape

    rows = "\n".join(
        f'<tr data-param="{escape(n)}" data-old="{old!r}" data-new="{new!r}" '
        f'data-difference="{new - old!r}"><td><code>{escape(n)}</code></td>'
        f'<td class="n">{old:.6g}</td><td class="n">{new:.6g}</td>'
        f'<td class="n">{new - old:+.6g}</td></tr>'
        for n, old, new in cmp.parameters
    )
    return (
        '<section id="previous">\n<h2>Coefficients in the log against the new ones</h2>\n'
        f"<p>The log was recorded with a thermal calibration active on {escape(cmp.sensor)}; "
        "it was removed from the data before fitting. Each parameter as the firmware stores "
        "it, old → new; the figure shows the correction each set applies over the calibrated "
        f"range, in {escape(unit_label(cmp.unit))}: {escape(cmp.curve_formula)}.</p>\n"
        '<table class="compact" id="previous-coefficients">\n<thead><tr><th>Parameter</th>'
        '<th class="n">old (in the log)</th><th class="n">new</th>'
        '<th class="n">difference</th></tr></thead>\n'
        f"<tbody>\n{rows}\n</tbody></table>\n"
        f'<figure><img id="previous-figure" src="{_b64(comparison_figure(cmp))}" '
        f'alt="old and new correction of {escape(cmp.sensor)} against temperature"></figure>\n'
        "</section>"
    )


__all__ = ["comparison_figure", "comparison_html"]
