"""Figures of the HTML report, drawn with matplotlib (Agg) and returned as PNG bytes.

Every function takes plain numpy arrays and returns the PNG image as ``bytes``
(embedded in the report as a ``data:image/png;base64`` URI, so the report needs no
network and no other file).  matplotlib is imported here only, with the
non-interactive Agg backend, so the maths modules never depend on it
(STYLE.md rule 1).

Long time series are reduced for drawing by :func:`decimate_for_plot` (block
means, which keep the shape of a slowly varying bias; the statistics in the
report are always computed on the full data, never on the plotted points).
"""

from __future__ import annotations

import io
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

MAX_PLOT_POINTS = 2000
"""Time series are drawn with at most this many points (block means)."""

BEFORE_COLOR = "#c0392b"
AFTER_COLOR = "#1f6fb2"
TEMP_COLORS = ("#d35400", "#8e44ad", "#16a085", "#2c3e50", "#7f8c8d", "#b7950b")
CHAMBER_COLOR = "#555555"
FIG_WIDTH_IN = 9.0
DPI = 110


def decimate_for_plot(
    x: npt.ArrayLike, *ys: npt.ArrayLike, max_points: int = MAX_PLOT_POINTS, block: int = 1
) -> tuple[FloatArray, ...]:
    """Block means of ``x`` and every ``y`` so that at most ``max_points`` remain.

    Block length ``m = max(block, ceil(n / max_points))``; the trailing partial
    block is averaged on its own.  With ``m = 1`` the arrays are returned unchanged.

    Parameters
    ----------
    x : array_like
        The abscissa.
    max_points : int
        Most points drawn.
    block : int
        Samples already averaged per point.
    *ys : array_like
        The ordinates.

    Returns
    -------
    tuple of numpy.ndarray
    """
    arrays = [np.asarray(a, dtype=np.float64) for a in (x, *ys)]
    n = arrays[0].size
    m = max(int(block), int(np.ceil(n / max_points)), 1)
    if m == 1:
        return tuple(arrays)
    starts = np.arange(0, n, m)
    counts = np.diff(np.r_[starts, n])
    if starts.size > 1 and counts[-1] < m / 2:  # a short trailing block is mostly noise
        starts, counts = starts[:-1], counts[:-1]
        arrays = [a[: starts[-1] + counts[-1]] for a in arrays]
    out = []
    for a in arrays:
        out.append(np.add.reduceat(a, starts) / counts)
    return tuple(out)


def binned_means(
    x: npt.ArrayLike, y: npt.ArrayLike, n_bins: int = 40, min_count: int = 30
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Means of ``y`` in ``n_bins`` equal-width bins of ``x``: (bin centre, mean, standard
    error of the mean), bins with fewer than ``min_count`` samples left out.

    Parameters
    ----------
    x : array_like
        The abscissa (a temperature).
    y : array_like
        The values.
    n_bins : int
        Number of bins.
    min_count : int
        Fewest samples a bin needs.

    Returns
    -------
    tuple of numpy.ndarray
        Bin centres, means and counts.
    """
    xa = np.asarray(x, dtype=np.float64)
    ya = np.asarray(y, dtype=np.float64)
    edges = np.linspace(float(xa.min()), float(xa.max()), n_bins + 1)
    idx = np.clip(np.searchsorted(edges, xa, side="right") - 1, 0, n_bins - 1)
    cnt = np.bincount(idx, minlength=n_bins).astype(np.float64)
    s1 = np.bincount(idx, weights=ya, minlength=n_bins)
    s2 = np.bincount(idx, weights=ya * ya, minlength=n_bins)
    ok = cnt >= min_count
    mean = s1[ok] / cnt[ok]
    var = np.maximum(s2[ok] / cnt[ok] - mean**2, 0.0) * cnt[ok] / np.maximum(cnt[ok] - 1, 1)
    centres = 0.5 * (edges[:-1] + edges[1:])[ok]
    return centres, mean, np.sqrt(var / cnt[ok])


PLAIN_TEXT: Any = {"text.parse_math": False}
"""matplotlib settings under which every text of a figure is drawn as written: a column
named ``T1 $\\frac$`` is a name, not TeX (mathtext would raise ValueError)."""


@contextmanager
def _figure(nrows: int = 1, height_in: float = 3.4, sharex: bool = False) -> Iterator[Any]:
    import matplotlib

    matplotlib.use("Agg", force=True)
    from matplotlib.figure import Figure

    with matplotlib.rc_context(PLAIN_TEXT):  # the axes' own label texts are made here
        fig = Figure(figsize=(FIG_WIDTH_IN, height_in * nrows), dpi=DPI, layout="constrained")
        axes = fig.subplots(nrows, 1, sharex=sharex, squeeze=False)[:, 0]
        for ax in axes:
            ax.grid(True, which="major", color="#dddddd", linewidth=0.6)
            ax.grid(True, which="minor", color="#f0f0f0", linewidth=0.4)
            for side in ("top", "right"):
                ax.spines[side].set_visible(False)
            ax.tick_params(labelsize=8.5)
        yield fig, axes


def _png(fig: Any) -> bytes:
    buf = io.BytesIO()
    with drawing_names():
        fig.savefig(buf, format="png", dpi=DPI, facecolor="white")
    return buf.getvalue()


@contextmanager
def drawing_names() -> Iterator[None]:
    """While a figure is drawn: matplotlib's "Glyph N missing from font" warning not
    shown (a column name holding NEL, CR or a script the font lacks is drawn as boxes;
    the warning was a foreign line on stderr, and an error under ``-W error``)."""
    import warnings

    with warnings.catch_warnings():
        # matplotlib ≥ 3.9: "… missing from font(s) …"; 3.8 (the floor): "… missing from
        # current font."
        warnings.filterwarnings("ignore", r"Glyph \d+ .*missing from", UserWarning)
        yield


def _hours(time_s: FloatArray) -> FloatArray:
    out: FloatArray = (time_s - time_s[0]) / 3600.0
    return out


@dataclass(frozen=True)
class TemperaturePanel:
    """One run's temperature channels for :func:`temperature_profile`.

    ``time_s`` [s]; ``channels`` name → temperature [°C]; ``chamber`` the chamber
    (ambient) temperature or set-point [°C], drawn dashed, if known.

    Attributes
    ----------
    title : str
        The panel's title (the run).
    time_s : numpy.ndarray
        Time [s].
    channels : dict of str to numpy.ndarray
        Temperature channel name → temperature [°C].
    chamber : numpy.ndarray or None
        Chamber (ambient) temperature or set-point [°C], drawn dashed; None when unknown.
    chamber_label : str
        Legend label of ``chamber``.
    """

    title: str
    time_s: FloatArray
    channels: dict[str, FloatArray]
    chamber: FloatArray | None = None
    chamber_label: str = "chamber"


def temperature_profile(panels: Sequence[TemperaturePanel]) -> bytes:
    """Chamber profile and temperature channels of each run against time [h].

    Parameters
    ----------
    panels : sequence of TemperaturePanel
        One panel per run.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    with _figure(len(panels), height_in=3.0) as (fig, axes):
        for ax, p in zip(axes, panels, strict=True):
            t = np.asarray(p.time_s, dtype=np.float64)
            if p.chamber is not None:
                th, ch = decimate_for_plot(_hours(t), p.chamber)
                ax.plot(th, ch, "--", color=CHAMBER_COLOR, lw=1.2, label=p.chamber_label)
            for i, (name, temp) in enumerate(p.channels.items()):
                th, tc = decimate_for_plot(_hours(t), temp)
                ax.plot(th, tc, color=TEMP_COLORS[i % len(TEMP_COLORS)], lw=1.0, label=name)
            ax.set_title(p.title, fontsize=10, loc="left")
            ax.set_ylabel("temperature [°C]", fontsize=9)
            ax.legend(fontsize=8, ncol=6, loc="upper right", frameon=False)
        axes[-1].set_xlabel("time [h]", fontsize=9)
        return _png(fig)


def bias_vs_time(
    time_s: FloatArray,
    before: FloatArray,
    after: FloatArray,
    *,
    unit: str,
    stages: Sequence[tuple[float, float]] = (),
    temperature: FloatArray | None = None,
    temperature_label: str = "T",
    block: int = 1,
) -> bytes:
    """Bias before and after compensation against time [h]; hold stages shaded.

    ``stages`` are (start_s, stop_s) of the temperature holds used for the
    stability and repeatability figures.  When ``temperature`` is given it is
    drawn on a right-hand axis.

    Parameters
    ----------
    time_s : numpy.ndarray
        Time [s].
    before : numpy.ndarray
        Bias before compensation [``unit``].
    after : numpy.ndarray
        After [``unit``].
    unit : str
        The data's unit.
    stages : sequence of (float, float)
        Hold stages [s].
    temperature : numpy.ndarray, optional
        A temperature drawn on a second axis [°C].
    temperature_label : str
        Its name.
    block : int
        Samples averaged per point.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    t = np.asarray(time_s, dtype=np.float64)
    with _figure(1, height_in=3.6) as (fig, axes):
        ax = axes[0]
        for a, b in stages:
            ax.axvspan((a - t[0]) / 3600.0, (b - t[0]) / 3600.0, color="#e8f1e4", lw=0, zorder=0)
        th, yb, ya = decimate_for_plot(_hours(t), before, after, block=block)
        ax.plot(th, yb, color=BEFORE_COLOR, lw=1.0, label="before compensation")
        ax.plot(th, ya, color=AFTER_COLOR, lw=1.0, label="after compensation")
        ax.set_xlabel("time [h]", fontsize=9)
        ax.set_ylabel(f"bias [{unit}]", fontsize=9)
        if temperature is not None:
            ax2 = ax.twinx()
            th2, tt = decimate_for_plot(_hours(t), temperature)
            ax2.plot(th2, tt, ":", color=CHAMBER_COLOR, lw=1.0, label=temperature_label)
            ax2.set_ylabel(f"{temperature_label} [°C]", fontsize=9)
            ax2.tick_params(labelsize=8.5)
            ax2.spines["top"].set_visible(False)
            h1, l1 = ax.get_legend_handles_labels()
            h2, l2 = ax2.get_legend_handles_labels()
            ax.legend(h1 + h2, l1 + l2, fontsize=8, loc="upper right", frameon=False, ncol=3)
        else:
            ax.legend(fontsize=8, loc="upper right", frameon=False, ncol=2)
        return _png(fig)


def bias_vs_temperature(
    temperature_c: FloatArray,
    before: FloatArray,
    after: FloatArray,
    *,
    unit: str,
    temperature_label: str = "T",
    block: int = 1,
) -> bytes:
    """Bias before and after compensation against a temperature channel [°C]: averages
    over ``block`` samples (faint dots) and means in 40 temperature bins (lines).

    Parameters
    ----------
    temperature_c : numpy.ndarray
        Temperature [°C].
    before : numpy.ndarray
        Bias before [``unit``].
    after : numpy.ndarray
        After [``unit``].
    unit : str
        The data's unit.
    temperature_label : str
        Its name.
    block : int
        Samples averaged per point.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    x = np.asarray(temperature_c, dtype=np.float64)
    with _figure(1, height_in=3.6) as (fig, axes):
        ax = axes[0]
        fin = x[np.isfinite(x)]
        if fin.size == 0 or float(np.ptp(fin)) == 0.0:
            say_why_empty(
                ax,
                f"no bias-against-temperature curve: {temperature_label} does not vary"
                + (f" (constant at {float(fin[0]):.4g} °C)" if fin.size else " (no value)"),
            )
            ax.set_xlabel(f"{temperature_label} [°C]", fontsize=9)
            return _png(fig)
        xs, yb, ya = decimate_for_plot(x, before, after, block=block)
        ax.plot(xs, yb, ".", ms=2.5, color=BEFORE_COLOR, alpha=0.25)
        ax.plot(xs, ya, ".", ms=2.5, color=AFTER_COLOR, alpha=0.25)
        for y, col, lab in ((before, BEFORE_COLOR, "before"), (after, AFTER_COLOR, "after")):
            c, m, se = binned_means(x, y)
            ax.errorbar(c, m, yerr=se, fmt="o-", ms=3, lw=1.4, capsize=0, color=col,
                        label=f"{lab} compensation (binned mean ± s.e.)")  # fmt: skip
        ax.set_xlabel(f"{temperature_label} [°C]", fontsize=9)
        ax.set_ylabel(f"bias [{unit}]", fontsize=9)
        ax.legend(fontsize=8, loc="best", frameon=True, framealpha=0.9)
        return _png(fig)


@dataclass(frozen=True)
class AllanCurve:
    """An Allan deviation curve: τ [s], σ(τ) and its confidence bounds (signal unit).

    Attributes
    ----------
    label : str
        Legend label.
    tau_s : numpy.ndarray
        Averaging times τ [s].
    adev : numpy.ndarray
        σ(τ) [signal unit].
    adev_low, adev_high : numpy.ndarray or None
        Lower and upper confidence bounds of σ(τ) [signal unit]; None: no bounds drawn.
    """

    label: str
    tau_s: FloatArray
    adev: FloatArray
    adev_low: FloatArray | None = None
    adev_high: FloatArray | None = None


def say_why_empty(ax: Any, reason: str) -> None:
    """Write in an empty panel why it is empty (a blank figure never goes out unexplained).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes.
    reason : str
        Why it is empty.
    """
    ax.text(0.5, 0.5, reason, ha="center", va="center", wrap=True, fontsize=9,
            color="#5b6773", transform=ax.transAxes)  # fmt: skip


def allan_deviation(curves: Sequence[AllanCurve], *, unit: str) -> bytes:
    """Log-log Allan deviation σ(τ) with confidence intervals as error bars; a curve with no
    positive point is named in the panel with the reason.

    Parameters
    ----------
    curves : sequence of AllanCurve
        The curves.
    unit : str
        The data's unit.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    colors = (BEFORE_COLOR, AFTER_COLOR, "#27ae60", "#8e44ad")
    with _figure(1, height_in=4.0) as (fig, axes):
        ax = axes[0]
        empty = [
            c.label
            for c in curves
            if not np.any(
                np.isfinite(np.asarray(c.adev, dtype=np.float64)) & (np.asarray(c.adev) > 0)
            )
        ]
        if empty:
            say_why_empty(
                ax,
                "no Allan deviation to draw for " + ", ".join(empty) + ": the record is "
                "shorter than two clusters of the smallest τ, or the output does not vary",
            )
        for i, c in enumerate(curves):
            col = colors[i % len(colors)]
            tau = np.asarray(c.tau_s, dtype=np.float64)
            ad = np.asarray(c.adev, dtype=np.float64)
            ok = np.isfinite(ad) & (ad > 0)
            if c.adev_low is not None and c.adev_high is not None:
                lo = np.asarray(c.adev_low, dtype=np.float64)
                hi = np.asarray(c.adev_high, dtype=np.float64)
                ok &= np.isfinite(lo) & np.isfinite(hi)
                yerr = np.vstack([np.maximum(ad - lo, 0.0), np.maximum(hi - ad, 0.0)])[:, ok]
                ax.errorbar(
                    tau[ok], ad[ok], yerr=yerr, fmt="o-", ms=3, lw=1.1, capsize=2,
                    color=col, label=c.label,
                )  # fmt: skip
            else:
                ax.plot(tau[ok], ad[ok], "o-", ms=3, lw=1.1, color=col, label=c.label)
        if len(empty) < len(curves):
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_xlabel("averaging time τ [s]", fontsize=9)
        ax.set_ylabel(f"Allan deviation σ(τ) [{unit}]", fontsize=9)
        ax.legend(fontsize=8, frameon=False)
        return _png(fig)


def drift_angle(
    time_s: FloatArray,
    before_deg: FloatArray,
    after_deg: FloatArray,
    *,
    unit: str = "°",
) -> bytes:
    """Drift angle [``unit``] (integral of the rate less a stated constant bias) before and
    after compensation, against time [h].

    Parameters
    ----------
    time_s : numpy.ndarray
        Time [s].
    before_deg : numpy.ndarray
        Drift angle before [``unit``].
    after_deg : numpy.ndarray
        After [``unit``].
    unit : str
        The angle's unit.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    t = np.asarray(time_s, dtype=np.float64)
    with _figure(1, height_in=3.4) as (fig, axes):
        ax = axes[0]
        th, yb, ya = decimate_for_plot(_hours(t), before_deg, after_deg)
        ax.plot(th, yb, color=BEFORE_COLOR, lw=1.2, label="before compensation")
        ax.plot(th, ya, color=AFTER_COLOR, lw=1.2, label="after compensation")
        ax.axhline(0.0, color="#999999", lw=0.6)
        ax.set_xlabel("time [h]", fontsize=9)
        ax.set_ylabel(f"drift angle [{unit}]", fontsize=9)
        ax.legend(fontsize=8, loc="upper left", frameon=False)
        return _png(fig)


def model_fit(
    time_s: FloatArray,
    measured: FloatArray,
    modelled: FloatArray,
    *,
    unit: str,
    block: int = 1,
) -> bytes:
    """Modelling run: measured bias, model output and residual against time [h].

    Parameters
    ----------
    time_s : numpy.ndarray
        Time [s].
    measured : numpy.ndarray
        The output [``unit``].
    modelled : numpy.ndarray
        The model [``unit``].
    unit : str
        The data's unit.
    block : int
        Samples averaged per point.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    t = np.asarray(time_s, dtype=np.float64)
    with _figure(2, height_in=2.6, sharex=True) as (fig, axes):
        th, ym, yf = decimate_for_plot(_hours(t), measured, modelled, block=block)
        axes[0].plot(th, ym, color=BEFORE_COLOR, lw=1.0, label="measured bias")
        axes[0].plot(th, yf, color="#111111", lw=1.0, label="model")
        axes[0].set_ylabel(f"bias [{unit}]", fontsize=9)
        axes[0].legend(fontsize=8, loc="upper right", frameon=False, ncol=2)
        axes[1].plot(th, ym - yf, color=AFTER_COLOR, lw=1.0, label="residual")
        axes[1].set_ylabel(f"residual [{unit}]", fontsize=9)
        axes[1].set_xlabel("time [h]", fontsize=9)
        return _png(fig)


__all__ = [
    "AllanCurve",
    "TemperaturePanel",
    "allan_deviation",
    "bias_vs_temperature",
    "bias_vs_time",
    "decimate_for_plot",
    "drift_angle",
    "model_fit",
    "say_why_empty",
    "temperature_profile",
]


# --- several channels (a calibration) ---------------------------------------------------------


@dataclass(frozen=True)
class ChannelBias:
    """One channel's bias before and after compensation against its temperature.

    Attributes
    ----------
    name : str
        The channel.
    unit : str
        Its unit.
    temperature_label : str
        Name of the temperature on the horizontal axis.
    temperature_c : numpy.ndarray
        That temperature [°C].
    before, after : numpy.ndarray
        The bias before and after compensation [``unit``].
    """

    name: str
    unit: str
    temperature_label: str
    temperature_c: FloatArray
    before: FloatArray
    after: FloatArray


GRID_COLS = 3
"""Panels per row of the per-channel grids."""


@contextmanager
def _grid(n: int, panel_height_in: float = 2.7) -> Iterator[Any]:
    import matplotlib

    matplotlib.use("Agg", force=True)
    from matplotlib.figure import Figure

    cols = min(GRID_COLS, max(n, 1))
    rows = (n + cols - 1) // cols
    height = panel_height_in * rows
    # fixed margins [in] rather than a constrained layout: the layout engine measures every
    # tick label once more per draw (half the cost of a grid)
    with matplotlib.rc_context(PLAIN_TEXT):  # the axes' own label texts are made here
        fig = Figure(figsize=(FIG_WIDTH_IN * 1.25, height), dpi=DPI)
        fig.subplots_adjust(left=0.07, right=0.99, bottom=0.55 / height,
                            top=1.0 - 0.3 / height, wspace=0.28,
                            hspace=0.85 / panel_height_in)  # fmt: skip
        axes = fig.subplots(rows, cols, squeeze=False).ravel()
        for ax in axes[n:]:
            ax.set_visible(False)
        for ax in axes[:n]:
            ax.grid(True, which="major", color="#dddddd", linewidth=0.6)
            for side in ("top", "right"):
                ax.spines[side].set_visible(False)
            ax.tick_params(labelsize=7.5)
        # titles at a fixed height above their panel (no ticks on top): matplotlib's
        # automatic title placement measures every tick label of the panel at each draw
        with matplotlib.rc_context({"axes.titley": 1.0}):
            yield fig, axes[:n]


def bias_vs_temperature_grid(channels: Sequence[ChannelBias]) -> bytes:
    """One panel per channel: bias before and after compensation [its unit] against its
    temperature [°C], both centred on their means (faint dots: block means; lines: means
    in 30 temperature bins).

    Parameters
    ----------
    channels : sequence of ChannelBias
        One panel per channel.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    with _grid(len(channels)) as (fig, axes):
        for ax, ch in zip(axes, channels, strict=True):
            b = ch.before - float(np.mean(ch.before))
            a = ch.after - float(np.mean(ch.after))
            xs, yb, ya = decimate_for_plot(ch.temperature_c, b, a, max_points=1500)
            ax.plot(xs, yb, ".", ms=1.8, color=BEFORE_COLOR, alpha=0.25)
            ax.plot(xs, ya, ".", ms=1.8, color=AFTER_COLOR, alpha=0.25)
            for y, col, lab in ((b, BEFORE_COLOR, "before"), (a, AFTER_COLOR, "after")):
                c, m, _se = binned_means(ch.temperature_c, y, n_bins=30, min_count=5)
                ax.plot(c, m, "-", lw=1.5, color=col, label=lab)
            ax.set_title(f"{ch.name} [{ch.unit}]", fontsize=9)
            ax.set_xlabel(f"{ch.temperature_label} [°C]", fontsize=8)
        if axes[0].get_legend_handles_labels()[0]:
            axes[0].legend(fontsize=7, frameon=False)
        return _png(fig)


def _few_minor_ticks(ax: Any) -> None:
    """Log axes: minor ticks only where a decade would otherwise go unlabelled (an axis
    spanning more than two decades gets none: every tick is an object matplotlib builds and
    measures at each draw, most of a log grid's cost)."""
    for axis in (ax.xaxis, ax.yaxis):
        lo, hi = sorted(axis.get_view_interval())
        if lo > 0 and hi / lo > 100.0:
            from matplotlib.ticker import NullLocator

            axis.set_minor_locator(NullLocator())


def allan_grid(curves: Sequence[tuple[str, str, Sequence[AllanCurve]]]) -> bytes:
    """One log-log panel per channel ``(name, unit, curves)``: Allan deviation before and
    after compensation with its confidence intervals.

    Parameters
    ----------
    curves : sequence of (str, str, sequence of AllanCurve)
        Per channel its name, unit and curves.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    colors = (BEFORE_COLOR, AFTER_COLOR)
    with _grid(len(curves)) as (fig, axes):
        for ax, (name, unit, cs) in zip(axes, curves, strict=True):
            if not any(bool(np.any(np.isfinite(c.adev) & (c.adev > 0))) for c in cs):
                ax.set_title(f"{name} [{unit}]", fontsize=9)
                ax.text(0.5, 0.5, "no variation", ha="center", va="center",
                        transform=ax.transAxes)  # fmt: skip
                continue
            for i, c in enumerate(cs):
                ok = np.isfinite(c.adev) & (c.adev > 0)
                ax.plot(c.tau_s[ok], c.adev[ok], "o-", ms=2.5, lw=1.0,
                        color=colors[i % 2], label=c.label)  # fmt: skip
                if c.adev_low is not None and c.adev_high is not None:
                    ok &= np.isfinite(c.adev_low) & np.isfinite(c.adev_high)
                    ax.fill_between(c.tau_s[ok], c.adev_low[ok], c.adev_high[ok],
                                    color=colors[i % 2], alpha=0.15, lw=0)  # fmt: skip
            ax.set_xscale("log")
            ax.set_yscale("log")
            _few_minor_ticks(ax)
            ax.set_title(f"{name} [{unit}]", fontsize=9)
            ax.set_xlabel("τ [s]", fontsize=8)
        if axes[0].get_legend_handles_labels()[0]:
            axes[0].legend(fontsize=7, frameon=False)
        return _png(fig)
