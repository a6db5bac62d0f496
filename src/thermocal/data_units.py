"""A signal in the data's own unit: the unit its figures are shown in and the values in it.

Every figure thermocal prints is in the unit the data came in (``deg/s`` stays ``deg/s``);
:meth:`thermocal.recording.Recording.signal` gives a signal in its canonical unit ([°/h] for
a rate, [mg] for a specific force, or ``counts``).  :func:`data_unit_of` gives the unit to
show and the factor between the two, :func:`signal_in_data_unit` the values in the shown
unit.  A small module of its own so that ``thermocal allan`` (which needs only these) does
not import :mod:`thermocal.metrics`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from thermocal import units

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

    from thermocal.recording import Recording

    FloatArray = npt.NDArray[np.float64]


def data_unit_of(rec: Recording, name: str, canonical: str) -> tuple[str, float]:
    r"""The unit a signal's figures are shown in and the factor ``k`` with
    ``value[canonical] = k · value[shown]``.

    The column's own unit as given (``deg/s`` stays ``deg/s``); raw counts are shown in
    the unit :meth:`Recording.signal` gave them (``canonical``: [°/h] or [mg] when a scale
    factor K converted them, else ``counts``), so k = 1.  The factor is the conversion of
    :func:`thermocal.units.shown_unit` (e.g. k = 3600 for [°/s] against [°/h]).

    Parameters
    ----------
    rec : Recording
        The recording.
    name : str
        Signal name.
    canonical : str
        Unit :meth:`Recording.signal` gave the signal.

    Returns
    -------
    tuple of (str, float)
        The shown unit and the factor k.
    """
    given = rec.units.get(name)
    shown = units.shown_unit(canonical, units.normalize_signal_unit(given) if given else None)
    return shown.unit, shown.to_model


def signal_in_data_unit(rec: Recording, name: str) -> tuple[FloatArray, str]:
    r"""The signal ``name`` in the data's own unit and that unit: the canonical values
    divided by k of :func:`data_unit_of`, :math:`v = v_{canonical} / k` (the canonical array
    itself when k = 1, so a caller may overwrite it).

    Parameters
    ----------
    rec : Recording
        The recording.
    name : str
        Signal name.

    Returns
    -------
    tuple of (numpy.ndarray, str)
        Values [unit] and the unit.
    """
    canonical, canon_unit = rec.signal(name)
    unit, k = data_unit_of(rec, name, canon_unit)
    return (canonical if k == 1.0 else canonical / k), unit


__all__ = ["data_unit_of", "signal_in_data_unit"]
