"""What a calibration's channels need from a recording: their temperature inputs
(:func:`temperatures_of`) and their recorded inputs merged into one model-file ``inputs``
object (:func:`merged_inputs`), so that a recording is read once for every channel.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from thermocal.models.calibration import Calibration


def temperatures_of(cal: Calibration, names: Sequence[str] | None = None) -> list[str]:
    """Every temperature input of the chosen channels, in first-seen order.

    Parameters
    ----------
    cal : Calibration
        The calibration.
    names : sequence of str, optional
        Channels to use; None (default): all.

    Returns
    -------
    list of str
    """
    out: list[str] = []
    for n in names or cal.names:
        for t in cal.channel(n).model.temp_names_:
            if t not in out:
                out.append(str(t))
    return out


def merged_inputs(cal: Calibration, names: Sequence[str] | None = None) -> dict[str, Any]:
    """The chosen channels' recorded inputs (units, conversions, time unit) merged into one
    model-file ``inputs`` object, to read a recording once for all of them; the first
    channel's wins where two disagree (each channel's unit is checked again when its model
    is applied).

    Parameters
    ----------
    cal : Calibration
        The calibration.
    names : sequence of str, optional
        Channels to use; None (default): all.

    Returns
    -------
    dict
        One model-file ``inputs`` object.
    """
    out: dict[str, Any] = {}
    units_: dict[str, Any] = {}
    conv: dict[str, Any] = {}
    for n in reversed(list(names or cal.names)):
        inp = dict(getattr(cal.channel(n).model, "inputs_", {}) or {})
        units_.update(inp.get("units") or {})
        conv.update(inp.get("temperature_conversion") or {})
        out.update(inp)
    out["units"] = units_
    out["temperature_conversion"] = conv
    return out


__all__ = ["merged_inputs", "temperatures_of"]
