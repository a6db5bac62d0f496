"""Frequency-stability analysis of arrays: the NIST SP 1065 deviation family [1]_ with
confidence intervals, and the IEEE Std 952 noise terms [2]_.

The public calls take a numpy array and a sample rate (as ``allantools.oadev(y, rate=…)``):

* :func:`deviation` — any registered deviation by name; :func:`oadev`, :func:`adev`,
  :func:`mdev`, :func:`tdev`, :func:`hdev`, :func:`ohdev`, :func:`totdev`, :func:`mtotdev`,
  :func:`ttotdev`, :func:`htotdev`, :func:`theo1`, :func:`mtie`, :func:`tierms` — each a
  :class:`DeviationResult` with ``to_dict()`` / ``to_frame()``;
* :func:`allan_noise` — the overlapping Allan deviation and the five noise terms
  (:class:`AllanNoise`);
* :func:`register` — add a deviation (:class:`Deviation`) to the one registry the command
  line, the analysis and the report read.

The modules behind them: :mod:`.deviations` (the kernels), :mod:`.edf` (Greenhall's
equivalent degrees of freedom, noise identification), :mod:`.family` (several deviations of
one record with intervals), :mod:`.allan` (overlapping ADEV and noise terms),
:mod:`.registry` (the deviation table), :mod:`.noise_model` (the estimators' noise model).
Pure numpy/scipy maths: no I/O, no plotting.  Imported on first use.

References
----------
.. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.
.. [2] IEEE Std 952-1997, Annex C.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from thermocal.stability.api import (
        TAU_SETS,
        AllanNoise,
        DataType,
        DeviationResult,
        TauSet,
        adev,
        allan_noise,
        deviation,
        hdev,
        htotdev,
        mdev,
        mtie,
        mtotdev,
        oadev,
        ohdev,
        tdev,
        theo1,
        tierms,
        totdev,
        ttotdev,
    )
    from thermocal.stability.registry import Deviation, names, register

_API = frozenset(
    (
        "TAU_SETS",
        "AllanNoise",
        "DataType",
        "DeviationResult",
        "TauSet",
        "adev",
        "allan_noise",
        "deviation",
        "hdev",
        "htotdev",
        "mdev",
        "mtie",
        "mtotdev",
        "oadev",
        "ohdev",
        "tdev",
        "theo1",
        "tierms",
        "totdev",
        "ttotdev",
    )
)
_REGISTRY = frozenset(("Deviation", "names", "register"))


def __getattr__(name: str) -> Any:
    """The public names, imported on first use (``import thermocal.stability.edf`` loads no
    more than it needs)."""
    if name in _API:
        from thermocal.stability import api

        return getattr(api, name)
    if name in _REGISTRY:
        from thermocal.stability import registry

        return getattr(registry, name)
    raise AttributeError(f"module 'thermocal.stability' has no attribute {name!r}")


__all__ = [
    "TAU_SETS",
    "AllanNoise",
    "DataType",
    "Deviation",
    "DeviationResult",
    "TauSet",
    "adev",
    "allan_noise",
    "deviation",
    "hdev",
    "htotdev",
    "mdev",
    "mtie",
    "mtotdev",
    "names",
    "oadev",
    "ohdev",
    "register",
    "tdev",
    "theo1",
    "tierms",
    "totdev",
    "ttotdev",
]
