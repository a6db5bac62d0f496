"""The noise terms against temperature: one panel per term (white-noise density, random
walk, bias instability at the minimum), each axis's value per bin with its interval and
its trend line.  matplotlib (Agg) is imported inside :func:`plot_noise_by_temperature`."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from thermocal.report.figures import drawing_names
from thermocal.stability.noise_temperature import NoiseOverTemperature
from thermocal.writers import atomic_write_path

_TITLES = {
    "noise_density": "white-noise density N",
    "random_walk": "random walk K (open: upper bound)",
    "bias_instability": "bias instability B (minimum)",
}


def plot_noise_by_temperature(
    res: NoiseOverTemperature, path: str | Path, *, title: str | None = None
) -> Path:
    """Write a PNG of N, K and B per temperature bin against the bin's mean temperature,
    with the intervals and each significant trend's line; written atomically.

    Parameters
    ----------
    res : NoiseOverTemperature
        The noise per bin (:func:`thermocal.stability.noise_temperature.noise_by_temperature`).
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

    sensors = list(dict.fromkeys(a.sensor for a in res.used[0].axes))
    fig, panels = plt.subplots(3, len(sensors), figsize=(6.0 * len(sensors), 8.5), dpi=110,
                               sharex=True, squeeze=False)  # fmt: skip
    try:
        for col, sensor in enumerate(sensors):
            for row, term in enumerate(_TITLES):
                _panel(panels[row][col], res, term, sensor)
            panels[-1][col].set_xlabel(f"temperature ({res.temperature}) [°C]")
            panels[0][col].set_title(sensor)
        if title:
            fig.suptitle(title)
        fig.tight_layout()
        out = Path(path)

        def _write(tmp: Path) -> None:
            with drawing_names():
                fig.savefig(tmp, format="png")

        atomic_write_path(out, _write)
    finally:
        plt.close(fig)
    return out


def _points(
    res: NoiseOverTemperature, name: str, term: str
) -> tuple[list[list[float]], str, list[bool]]:
    """(temperature, value, minus, plus) per bin with the term, its unit, bound flags."""
    cols: list[list[float]] = [[], [], [], []]
    unit, bound = "", []
    for b in res.used:
        a = b.axis(name)
        if term == "bias_instability":
            m = a.terms.bias_minimum
            if m is None or m.value is None:
                continue
            val, low, high, unit, flag = m.value, m.low, m.high, m.unit, False
        else:
            c = a.density if term == "noise_density" else a.walk
            val, low, high, unit, flag = c.value, c.low, c.high, c.unit, c.method == "bound"
        cols[0].append(b.mean_c)
        cols[1].append(val)
        cols[2].append(val - (val if low is None else low))
        cols[3].append((val if high is None else high) - val)
        bound.append(flag)
    return cols, unit, bound


def _panel(ax: Any, res: NoiseOverTemperature, term: str, sensor: str) -> None:
    """One term's points, intervals and significant trend lines of one sensor's axes."""
    unit = ""
    for name in [a.name for a in res.used[0].axes if a.sensor == sensor]:
        (t, v, minus, plus), u, bound = _points(res, name, term)
        if not t:
            continue
        unit = u
        line = ax.errorbar(t, v, yerr=np.vstack([minus, plus]), fmt="o-", ms=4, capsize=3,
                           label=name)  # fmt: skip
        colour = line[0].get_color()
        tb = [x for x, f in zip(t, bound, strict=True) if f]
        if tb:
            vb = [x for x, f in zip(v, bound, strict=True) if f]
            ax.plot(tb, vb, "o", mfc="white", color=colour)
        tr = next((x for x in res.trends if x.axis == name and x.term == term), None)
        if tr is not None and tr.significant and tr.slope_per_c is not None:
            assert tr.mean_c is not None and tr.value_at_mean is not None
            tt = np.array([min(t), max(t)])
            ax.plot(tt, tr.value_at_mean + tr.slope_per_c * (tt - tr.mean_c), ":", color=colour,
                    label=f"{name}: {tr.words.split(' over ')[0]}")  # fmt: skip
    ax.set_ylabel(f"{_TITLES[term]}\n[{unit}]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
