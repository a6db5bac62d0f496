"""Log-log Allan deviation plot with confidence bars and fitted noise lines.

Plotting stays at the edge: matplotlib (Agg backend) is imported inside
:func:`plot_allan` only, never by :mod:`thermocal.stability.allan`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from thermocal.report.figures import drawing_names
from thermocal.stability.allan import TERM_NAMES, AllanResult, DynamicAllan, NoiseTerms
from thermocal.writers import atomic_write_path


def plot_allan(
    result: AllanResult,
    noise: NoiseTerms | None,
    path: str | Path,
    *,
    title: str | None = None,
) -> Path:
    """Write a PNG: σ(τ) with its confidence bars, the fitted model and each
    significant fitted term (IEEE 952 slope lines), the −½ stretch's line over the τ it was
    fitted on and the curve's minimum (bias instability, IEEE 952 C.3).  Written
    atomically.

    Parameters
    ----------
    result : AllanResult
        The deviation (:func:`thermocal.stability.allan.overlapping_adev`).
    noise : NoiseTerms, optional
        The noise terms drawn as their lines.
    path : str or pathlib.Path
        The file to write.
    title : str, optional
        The figure's title.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 5.0), dpi=110)
    try:
        yerr = np.vstack([result.adev - result.adev_low, result.adev_high - result.adev])
        ax.errorbar(
            result.tau_s,
            result.adev,
            yerr=yerr,
            fmt="o",
            ms=3.5,
            capsize=2,
            label=f"overlapping ADEV ({result.confidence:.1%} CI)",
        )
        if noise is not None and result.tau_s.size:
            tt = np.geomspace(result.tau_s[0], result.tau_s[-1], 200)
            ax.plot(tt, noise.fit_curve(tt), "k-", lw=1.2, label="least-squares fit")
            for name in TERM_NAMES:
                term = noise.fit.terms()[name]
                if term.value is None:
                    continue
                ax.plot(
                    tt,
                    noise.term_curve(name, tt),
                    "--",
                    lw=0.9,
                    label=f"{term.label}: {term.value:.4g} {term.unit}",
                )
            _mark_readings(ax, result, noise)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("averaging time τ [s]")
        ax.set_ylabel(f"Allan deviation [{result.unit}]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        if title:
            ax.set_title(title, parse_math=False)
        positive = result.adev_low[result.adev_low > 0]
        if positive.size:
            ax.set_ylim(bottom=float(np.min(positive)) / 2.0)
        out = Path(path)

        def _write(tmp: Path) -> None:
            with drawing_names():
                fig.savefig(tmp, format="png")

        atomic_write_path(out, _write)
    finally:
        plt.close(fig)
    return out


def _mark_readings(ax: Any, result: AllanResult, noise: NoiseTerms) -> None:
    """The −½ stretch's line N/√τ (N in the data's √s unit: σ at τ = 1 s) over its τ range,
    and the minimum's point, on the axes ``ax``."""
    arw = noise.slope.angle_random_walk
    if arw.tau_range_s is not None and arw.value is not None:
        lo, hi = arw.tau_range_s
        ok = (result.tau_s >= lo) & (result.tau_s <= hi) & (result.adev > 0)
        if ok.any():  # the line through the stretch's points, in the ADEV's own unit
            c = float(np.exp(np.mean(np.log(result.adev[ok] * np.sqrt(result.tau_s[ok])))))
            tt = np.geomspace(lo, hi, 20)
            ax.plot(
                tt,
                c / np.sqrt(tt),
                "-",
                lw=3.0,
                alpha=0.4,
                label=f"−½ stretch τ {lo:.3g}…{hi:.3g} s: N = {arw.value:.4g} {arw.unit}",
            )
    bm = noise.bias_minimum
    if bm is not None and bm.value is not None and bm.tau_s is not None:
        k = int(np.argmin(np.abs(result.tau_s - bm.tau_s)))
        ax.plot(
            [bm.tau_s],
            [result.adev[k]],
            "v",
            ms=9,
            mfc="none",
            label=f"minimum: B = {bm.value:.4g} {bm.unit} ({bm.quality})",
        )


def plot_dynamic(dyn: DynamicAllan, path: str | Path, *, title: str | None = None) -> Path:
    """Write a heat map of the dynamic Allan deviation: window centre [s] across, τ [s]
    up (log), log10 ADEV [unit] as colour; windows where the curve departs from the whole
    record's are outlined.  Written atomically.

    Parameters
    ----------
    dyn : DynamicAllan
        The dynamic Allan deviation.
    path : str or pathlib.Path
        The file to write.
    title : str, optional
        The figure's title.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 5.0), dpi=110)
    try:
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.log10(np.where(dyn.adev > 0, dyn.adev, np.nan)).T
        t_edges = _edges(dyn.t_s, log=False)
        tau_edges = _edges(dyn.tau_s, log=True)
        mesh = ax.pcolormesh(t_edges, tau_edges, np.ma.masked_invalid(z), shading="flat")
        fig.colorbar(mesh, ax=ax, label=f"log10 ADEV [{dyn.unit}]")
        if dyn.changes:
            ax.plot(
                [c["t_s"] for c in dyn.changes], [c["tau_s"] for c in dyn.changes], "rx",
                ms=4, label="differs from the whole record",
            )  # fmt: skip
            ax.legend(fontsize=7)
        ax.set_yscale("log")
        ax.set_xlabel(f"window centre [s] (windows of {dyn.window_s:g} s)")
        ax.set_ylabel("averaging time τ [s]")
        ax.set_title(title or "dynamic Allan deviation", parse_math=False)
        out = Path(path)

        def _write(tmp: Path) -> None:
            with drawing_names():
                fig.savefig(tmp, format="png")

        atomic_write_path(out, _write)
    finally:
        plt.close(fig)
    return out


def _edges(centres: np.ndarray, *, log: bool) -> np.ndarray:
    """Cell edges around sorted centres (geometric midpoints on a log axis)."""
    c = np.log(centres) if log else np.asarray(centres, dtype=np.float64)
    if c.size == 1:
        e = np.array([c[0] - 0.5, c[0] + 0.5])
    else:
        mid = (c[1:] + c[:-1]) / 2.0
        e = np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])
    return np.exp(e) if log else e
