"""The noise command's results as text beyond one recording's model: a noise model from
data-sheet figures, the noise per temperature bin and its trend, the PSD beside the ADEV."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from thermocal.report.text import Block, TextTable, fmt

if TYPE_CHECKING:
    from thermocal.stability.datasheet import DatasheetNoise
    from thermocal.stability.noise_temperature import NoiseAtTemperature, NoiseOverTemperature
    from thermocal.stability.psd import AxisPsd


def datasheet_noise_text(where: str, model: DatasheetNoise) -> list[Block]:
    """A data-sheet noise model: per Kalibr key the figure as stated, its SI value and
    where it came from; then the notes (disagreeing figures, derived values).

    Parameters
    ----------
    where : str
        The file of figures the title names.
    model : thermocal.stability.datasheet.DatasheetNoise
        The model (:func:`thermocal.stability.datasheet.datasheet_noise`).

    Returns
    -------
    list of str or TextTable
    """
    columns = ("Kalibr key", "data sheet", "SI (continuous time)", "unit", "from")
    rows = []
    for key, f in model.figures.items():
        stated = f"{f.value:g} {f.unit}" if f.source == "datasheet" else "—"
        how = "data sheet" if f.source == "datasheet" else "derived (see below)"
        rows.append((key, stated, fmt(f.si * model.inflate), f.si_unit, how))
    title = f"{where} — IMU noise model from the data sheet" + (
        f" (inflated ×{model.inflate:g})" if model.inflate != 1.0 else " (not inflated)"
    )
    out: list[Block] = [TextTable(title, columns, tuple(rows), ("left",) * len(columns))]
    return out + list(model.notes)


def noise_by_temperature_text(
    where: str, res: NoiseOverTemperature, at: NoiseAtTemperature | None
) -> list[Block]:
    """The noise per temperature bin (per axis N and K in SI, B at the minimum in the
    data's unit, each with its interval), refused bins with the reason, the trends, and
    the model at a temperature with the inflation the record supports.

    Parameters
    ----------
    where : str
        The file the title names.
    res : thermocal.stability.noise_temperature.NoiseOverTemperature
        The noise per bin.
    at : thermocal.stability.noise_temperature.NoiseAtTemperature or None
        The model at a temperature (None: not asked).

    Returns
    -------
    list of str or TextTable
    """
    columns = ("bin [°C]", "mean [°C]", "s", "axis", "noise density [interval]",
               "random walk [interval]", "bias instability (minimum) [interval]")  # fmt: skip
    rows = []
    for b in res.bins:
        span = f"{b.low_c:g}…{b.high_c:g}"
        if b.refused is not None:
            rows.append((span, "—", f"{b.duration_s:.0f}", "—", "refused: " + b.refused, "", ""))
            continue
        for a in b.axes:
            d, w, m = a.density, a.walk, a.terms.bias_minimum
            bcell = "—" if m is None else f"{fmt(m.value)} [{fmt(m.low)}, {fmt(m.high)}] {m.unit}"
            dcell = f"{fmt(d.value)} [{fmt(d.low)}, {fmt(d.high)}]"
            wcell = f"{fmt(w.value)} [{fmt(w.low)}, {fmt(w.high)}] {w.method}"
            rows.append(
                (span, f"{b.mean_c:.2f}", f"{b.duration_s:.0f}", a.name, dcell, wcell, bcell)
            )
    title = (f"{where} — noise per bin of {res.temperature} (continuous time, SI; "
             f"{res.confidence * 100:.1f} % intervals)")  # fmt: skip
    out: list[Block] = [TextTable(title, columns, tuple(rows), ("left",) * len(columns))]
    out += [f"trend {t.axis} {t.term}: {t.words}" for t in res.trends]
    if at is not None:
        vals = ", ".join(f"{k} {v:.4g} ({at.axis_of[k]})" for k, v in at.values.items())
        out.append(f"at {at.temperature_c:g} °C (inflation included ×{at.inflate:g}): {vals}")
        out += [f"inflation {i.key} ×{i.factor:.3g} ({i.reason}): {i.words}" for i in at.advice]
    return out


def psd_text(res: Sequence[AxisPsd]) -> list[Block]:
    """Per axis the PSD's white level (one-sided ASD in the data's unit/√Hz, and N in SI),
    the Allan deviation's N, their ratio and the comparison in words.

    Parameters
    ----------
    res : sequence of thermocal.stability.psd.AxisPsd
        The axes' PSDs (:func:`thermocal.stability.psd.imu_psd`).

    Returns
    -------
    list of str or TextTable
    """
    columns = ("axis", "PSD white ASD (one-sided)", "N from PSD", "N from ADEV", "ratio", "")
    rows = tuple(
        (p.name, f"{fmt(p.white_asd)} {p.unit}/sqrt(Hz)", fmt(p.psd_density),
         fmt(p.adev_density), f"{p.ratio:.3f}", "agree" if p.agree else "DISAGREE")
        for p in res
    )  # fmt: skip
    title = "White noise: the PSD's flat part (N = ASD/√2) beside the Allan deviation's −½ line"
    out: list[Block] = [TextTable(title, columns, rows, ("left",) * len(columns))]
    return out + [f"{p.name}: {p.words}" for p in res]
