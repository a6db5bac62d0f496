"""The noise command's results as text beyond one recording's model: a noise model from
data-sheet figures, the noise per temperature bin and its trend, the PSD beside the ADEV."""

from __future__ import annotations

from typing import TYPE_CHECKING

from thermocal.report.text import Block, TextTable, fmt

if TYPE_CHECKING:
    from thermocal.stability.datasheet import DatasheetNoise


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
