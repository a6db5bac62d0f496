"""Report content of the flight-controller calibrations.

:func:`comparison_html`: the coefficients active in the log against the new ones, a table
(per parameter old, new, difference) and a figure (the correction of each set over the
calibrated range, per axis), as a section of the sensor's calibration report.
:func:`write_offset_report`: the report of a barometer or magnetometer calibration (PX4
``TC_B``/``TC_M``): residual before/after against the temperature, the held-out bins.
:func:`write_ardupilot_baro_report`: the same for ArduPilot's ``TCAL_BARO_EXP``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from thermocal.recording import FloatArray
from thermocal.report.build import _b64, unit_label

if TYPE_CHECKING:
    from thermocal.tempcal.ardupilot_baro import ArdupilotBaroReportRequest
    from thermocal.tempcal.compare import CoefficientComparison
    from thermocal.tempcal.offset_report import OffsetReportRequest

OLD_COLOR = "#c0392b"
NEW_COLOR = "#1f6fb2"


def comparison_figure(cmp: CoefficientComparison) -> bytes:
    """One panel per axis: the old and the new correction [cmp.unit] against the
    temperature [°C] over the calibrated range (PNG).

    Parameters
    ----------
    cmp : CoefficientComparison
        The coefficients of two calibrations.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    from thermocal.report.figures import _figure, _png

    t = np.asarray(cmp.temp_c)
    axes_names = list(cmp.new_curve)
    with _figure(len(axes_names), height_in=2.2, sharex=True) as (fig, axes):
        for ax, name in zip(axes, axes_names, strict=True):
            ax.plot(t, cmp.old_curve[name], color=OLD_COLOR, lw=1.4, label=cmp.old_label)
            ax.plot(t, cmp.new_curve[name], color=NEW_COLOR, lw=1.4, ls="--", label="new")
            ax.set_ylabel(f"{name} [{unit_label(cmp.unit)}]", fontsize=9)
        axes[0].legend(fontsize=8, loc="best")
        axes[0].set_title(f"{cmp.sensor}: {cmp.title.lower()}", fontsize=10)
        axes[-1].set_xlabel("temperature [°C]", fontsize=9)
        return _png(fig)


def comparison_html(cmp: CoefficientComparison) -> str:
    """The section ``#<cmp.anchor>`` of a report: table and figure of :func:`comparison_figure`
    (each number also in ``data-old``/``data-new``/``data-difference`` at full precision).

    Parameters
    ----------
    cmp : CoefficientComparison
        The coefficients of two calibrations.

    Returns
    -------
    str
        An HTML fragment.
    """
    from markupsafe import escape

    rows = "\n".join(
        f'<tr data-param="{escape(n)}" data-old="{old!r}" data-new="{new!r}" '
        f'data-difference="{new - old!r}"><td><code>{escape(n)}</code></td>'
        f'<td class="n">{old:.6g}</td><td class="n">{new:.6g}</td>'
        f'<td class="n">{new - old:+.6g}</td></tr>'
        for n, old, new in cmp.parameters
    )
    a = escape(cmp.anchor)
    return (
        f'<section id="{a}">\n<h2>{escape(cmp.title)} — {escape(cmp.sensor)}</h2>\n'
        f"<p>{escape(cmp.intro)} Each parameter as the firmware stores it, "
        f"{escape(cmp.old_label)} → new; the figure shows the correction each set applies over "
        f"the calibrated range, in {escape(unit_label(cmp.unit))}: "
        f"{escape(cmp.curve_formula)}.</p>\n"
        f'<table class="compact" id="{a}-coefficients">\n<thead><tr><th>Parameter</th>'
        f'<th class="n">{escape(cmp.old_label)}</th><th class="n">new (thermocal)</th>'
        '<th class="n">difference</th></tr></thead>\n'
        f"<tbody>\n{rows}\n</tbody></table>\n"
        f'<figure><img class="figure" id="{a}-figure" src="{_b64(comparison_figure(cmp))}" '
        f'alt="{escape(cmp.title)}: correction against temperature"></figure>\n'
        "</section>"
    )


# --- barometers and magnetometers -------------------------------------------------------


def offset_residual_figure(req: OffsetReportRequest) -> bytes:
    """One panel per axis: the residual before (samples relative to their median) and after
    the firmware's correction [unit] against the temperature [°C]; the samples (block means,
    in time order) light, the bin medians dark (PNG).

    Parameters
    ----------
    req
        What the report shows.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    from thermocal.report.figures import _figure, _png, decimate_for_plot

    unit = unit_label(req.fit.unit)
    with _figure(len(req.axes), height_in=2.4, sharex=True) as (fig, axes):
        for j, (ax, name) in enumerate(zip(axes, req.axes, strict=True)):
            t, b, a = decimate_for_plot(req.temp_c, req.before[:, j], req.after[:, j])
            ax.plot(t, b, ".", ms=1.5, color=OLD_COLOR, alpha=0.25)
            ax.plot(t, a, ".", ms=1.5, color=NEW_COLOR, alpha=0.25)
            ax.plot(req.bin_temp_c, req.bin_before[:, j], color=OLD_COLOR, lw=1.3,
                    label="before (bin medians)")  # fmt: skip
            ax.plot(req.bin_temp_c, req.bin_after[:, j], color=NEW_COLOR, lw=1.3,
                    label="after the TC correction")  # fmt: skip
            ax.set_ylabel(f"{name} [{unit}]", fontsize=9)
        axes[0].legend(fontsize=8, loc="best")
        axes[-1].set_xlabel("temperature [°C]", fontsize=9)
        return _png(fig)


def offset_holdout_figure(req: OffsetReportRequest) -> bytes:
    """One panel per axis: the odd temperature bins' residual [unit] to the polynomial
    fitted to the even bins only, with its rms (the fit's hold-out rms) (PNG).

    Parameters
    ----------
    req
        What the report shows.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    from thermocal.report.figures import _figure, _png

    unit = unit_label(req.fit.unit)
    with _figure(len(req.axes), height_in=2.0, sharex=True) as (fig, axes):
        for j, (ax, name) in enumerate(zip(axes, req.axes, strict=True)):
            ax.axhline(0.0, color="#888888", lw=0.8)
            ax.plot(req.odd_temp_c, req.odd_residual[:, j], "o", ms=2.5, color=NEW_COLOR)
            ax.set_ylabel(f"{name} [{unit}]", fontsize=9)
            ax.set_title(
                f"held-out rms {req.fit.holdout_rms[name]:.4g} {unit}", fontsize=9, loc="right"
            )
        axes[-1].set_xlabel("temperature of the held-out (odd) bins [°C]", fontsize=9)
        return _png(fig)


def build_offset_report(req: OffsetReportRequest) -> str:
    """The HTML report of one barometer or magnetometer calibration: its parameters, the
    residual before/after against the temperature and the held-out bins
    (:func:`offset_residual_figure`, :func:`offset_holdout_figure`).

    Parameters
    ----------
    req
        What the report shows.

    Returns
    -------
    str
        The self-contained HTML document.
    """
    import datetime as _dt

    from thermocal import __version__
    from thermocal.readers.common import sha256_of
    from thermocal.report.build import _env

    f = req.fit

    def rms(x: FloatArray) -> list[float]:
        return [float(v) for v in np.sqrt(np.mean(x**2, axis=0))]

    html: str = (
        _env()
        .get_template("tempcal_offset.html.j2")
        .render(
            title=req.title, version=__version__, generated_by=req.generated_by,
            generated_utc=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
            fit=f, unit=unit_label(f.unit), axes=list(req.axes),
            bins_before=rms(req.bin_before), bins_after=rms(req.bin_after),
            residual_fig=_b64(offset_residual_figure(req)),
            holdout_fig=_b64(offset_holdout_figure(req)),
            files=[("log", req.log_path, sha256_of(req.log_path))],
            appendix=[comparison_html(req.previous)] if req.previous is not None else [],
        )
    )  # fmt: skip
    return html


def write_offset_report(path: str | Path, req: OffsetReportRequest) -> Path:
    """:func:`build_offset_report` written atomically to ``path``.

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write.
    req
        What the report shows.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    from thermocal.writers import write_html

    return write_html(path, build_offset_report(req))


# --- ArduPilot's barometer: TCAL_BARO_EXP --------------------------------------------------


def ardupilot_baro_figures(req: ArdupilotBaroReportRequest) -> tuple[bytes, bytes]:
    """(the pressure residual before and after the firmware's correction ``max(T − 25, 0)^e``
    [Pa] against the temperature [°C], samples light and bin means dark; the odd bins'
    residual [Pa] to the exponent fitted to the even bins) as PNGs.

    Parameters
    ----------
    req
        What the report shows.

    Returns
    -------
    tuple of bytes
        Two PNG figures.
    """
    from thermocal.report.figures import _figure, _png, decimate_for_plot

    with _figure(1, height_in=2.8) as (fig, axes):
        ax = axes[0]
        t, b, a = decimate_for_plot(req.temp_c, req.before, req.after)
        ax.plot(t, b, ".", ms=1.5, color=OLD_COLOR, alpha=0.25)
        ax.plot(t, a, ".", ms=1.5, color=NEW_COLOR, alpha=0.25)
        ax.plot(req.bin_temp_c, req.bin_before, color=OLD_COLOR, lw=1.3, label="before (bins)")
        ax.plot(req.bin_temp_c, req.bin_after, color=NEW_COLOR, lw=1.3,
                label=f"after TCAL_BARO_EXP {req.fit.exponent:.4g}")  # fmt: skip
        ax.axvline(25.0, color="#888888", lw=0.8, ls=":")
        ax.set_ylabel("pressure [Pa]", fontsize=9)
        ax.set_xlabel("temperature [°C]", fontsize=9)
        ax.legend(fontsize=8, loc="best")
        residual = _png(fig)
    with _figure(1, height_in=2.2) as (fig, axes):
        ax = axes[0]
        ax.axhline(0.0, color="#888888", lw=0.8)
        ax.plot(req.odd_temp_c, req.odd_residual, "o", ms=2.5, color=NEW_COLOR)
        ax.set_ylabel("pressure [Pa]", fontsize=9)
        ax.set_xlabel("temperature of the held-out (odd) bins [°C]", fontsize=9)
        ax.set_title(f"held-out rms {req.fit.holdout_rms_pa:.4g} Pa", fontsize=9, loc="right")
        holdout = _png(fig)
    return residual, holdout


def build_ardupilot_baro_report(req: ArdupilotBaroReportRequest) -> str:
    """The HTML report of ArduPilot's barometer calibration: the parameters
    ``TCAL_ENABLED``/``TEMP_MIN``/``TEMP_MAX``/``BARO_EXP`` (the log's beside the new), the
    rms before/after, the residual figure, the held-out bins, the warnings
    (:func:`ardupilot_baro_figures`).

    Parameters
    ----------
    req
        What the report shows.

    Returns
    -------
    str
        The self-contained HTML document.
    """
    import datetime as _dt

    from thermocal import __version__
    from thermocal.readers.common import sha256_of
    from thermocal.report.build import _env

    residual, holdout = ardupilot_baro_figures(req)
    html: str = (
        _env()
        .get_template("tempcal_ardupilot_baro.html.j2")
        .render(
            title=req.title, version=__version__, generated_by=req.generated_by,
            generated_utc=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
            fit=req.fit, params=req.fit.params(), old=req.old, warnings=list(req.warnings),
            holdout_exponent=req.holdout_exponent,
            residual_fig=_b64(residual), holdout_fig=_b64(holdout),
            files=[("log", req.log_path, sha256_of(req.log_path))],
        )
    )  # fmt: skip
    return html


def write_ardupilot_baro_report(path: str | Path, req: ArdupilotBaroReportRequest) -> Path:
    """:func:`build_ardupilot_baro_report` written atomically to ``path``.

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write.
    req
        What the report shows.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    from thermocal.writers import write_html

    return write_html(path, build_ardupilot_baro_report(req))


__all__ = [
    "ardupilot_baro_figures",
    "build_ardupilot_baro_report",
    "build_offset_report",
    "comparison_figure",
    "comparison_html",
    "offset_holdout_figure",
    "offset_residual_figure",
    "write_ardupilot_baro_report",
    "write_offset_report",
]
