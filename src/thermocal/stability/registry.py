"""The deviation registry: one table of every frequency-stability deviation thermocal computes.

Each entry (:class:`Deviation`) names the deviation, its sums over one gap-free stretch of
phase, its largest averaging factor, its equivalent degrees of freedom, the data types it
takes and its Stable32 name.  The command line (the ``allan`` command), the
library (:func:`thermocal.stability.family.stability`, :func:`thermocal.stability.deviation`)
and the report read this table; a new deviation is one :func:`register` call.  The built-in
entries are NIST SP 1065's deviations [1]_ with Greenhall and Riley's EDF [2]_.

References
----------
.. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special Publication
   1065, 2008.
.. [2] C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on finite
   differences", Proc. 35th PTTI Meeting, 2003.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError
from thermocal.stability import deviations as dv
from thermocal.stability import edf as ed

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

SumsFunction = Callable[[FloatArray, float, IntArray], tuple[FloatArray, FloatArray]]
"""``(x, tau0_s, m) -> (numerator, terms)`` per factor m for one gap-free stretch of phase
``x``; the variance is Σ numerator / Σ terms over the stretches (a factor beyond the
deviation's largest gives (0, 0))."""

EdfFunction = Callable[[int, int, int], float]
"""``(alpha, m, n_phase) -> EDF`` of one stretch of ``n_phase`` phase points at factor m for
the power-law noise exponent α (a ValueError or NaN: no interval at that point)."""

DATA_TYPES: Final = ("rate", "phase")
"""The data types of the stability analysis: rate (fractional-frequency-like) samples or
phase (time-error-like) points."""


@dataclass(frozen=True)
class Deviation:
    """One deviation of the registry.

    Parameters
    ----------
    name : str
        The name :func:`thermocal.stability.deviation` and the ``deviations`` of
        :func:`thermocal.stability.analysis.allan_analysis` take (lower case).
    sums : SumsFunction
        Sums of one gap-free stretch of phase ``x`` [unit·s]: ``(x, tau0_s, m) ->
        (numerator, terms)``.
    max_factor : Callable[[int], int]
        The largest averaging factor m with at least one term for N phase points.
    edf : EdfFunction or None
        Equivalent degrees of freedom ``(alpha, m, n_phase) -> float``; None: the deviation
        has no chi-square interval (``interval`` says why).
    interval : str
        Where the interval comes from (or, when ``edf`` is None, why there is none).
    stable32_name : str
        The deviation's name in Stable32 (empty when Stable32 has none).
    data_types : tuple of str
        The data types it takes (:data:`DATA_TYPES`).
    time_deviation : bool
        In phase units (unit·s for rate data) rather than rate units.
    hadamard : bool
        Third differences: noise exponents down to α = −4 (d = 3 in the identification).
    raw_phase : bool
        Reads the phase as given (not its end-point line removed): MTIE and TIE rms.
    work : Callable[[int, IntArray], float] or None
        Estimated arithmetic operations on N phase points at the factors m; None: 4 N per
        factor (an O(N) difference and its square).
    reference : str
        The published definition (e.g. ``"NIST SP 1065 eq. 11"``).
    """

    name: str
    sums: SumsFunction
    max_factor: Callable[[int], int]
    edf: EdfFunction | None
    interval: str = "Greenhall/SP 1065 EDF"
    stable32_name: str = ""
    data_types: tuple[str, ...] = DATA_TYPES
    time_deviation: bool = False
    hadamard: bool = False
    raw_phase: bool = False
    work: Callable[[int, IntArray], float] | None = None
    reference: str = ""

    def estimated_work(self, n_phase: int, m: npt.ArrayLike) -> float:
        """Estimated arithmetic operations on ``n_phase`` phase points at the factors ``m``
        (those beyond :attr:`max_factor` cost nothing).

        Parameters
        ----------
        n_phase : int
            Number of phase points.
        m : array_like
            Averaging factors [samples].

        Returns
        -------
        float
            Estimated operations.
        """
        mm = np.asarray(m, dtype=np.int64).ravel()
        if self.work is not None:
            return self.work(n_phase, mm)
        used = int(np.sum((mm >= 1) & (mm <= self.max_factor(n_phase))))
        return dv.WORK_PER_POINT * float(n_phase) * used


_TABLE: dict[str, Deviation] = {}


def register(deviation: Deviation) -> Deviation:
    """Add ``deviation`` to the registry (the one step a new deviation needs).

    Parameters
    ----------
    deviation : Deviation
        The entry; its name must be new, lower case and free of commas and spaces.

    Returns
    -------
    Deviation
        The entry, registered.

    Raises
    ------
    ParameterError
        The name is taken or not a plain lower-case word, or a data type is unknown.
    """
    name = deviation.name
    if name in _TABLE:
        raise ParameterError("deviation", f"{{name}} {name!r} is registered already")
    if not name or name != name.strip().lower() or any(c in name for c in ", "):
        raise ParameterError("deviation", f"{{name}} {name!r}: use a lower-case word")
    bad = [t for t in deviation.data_types if t not in DATA_TYPES]
    if bad or not deviation.data_types:
        raise ParameterError("deviation", f"{{name}} {name!r}: data types must be rate or phase")
    _TABLE[name] = deviation
    return deviation


def unregister(name: str) -> None:
    """Remove a deviation added by :func:`register` (tests; built-in ones stay).

    Parameters
    ----------
    name : str
        Deviation name.
    """
    if name in _BUILT_IN:
        raise ParameterError("deviation", f"{{name}} {name!r} is built in")
    _TABLE.pop(name, None)


def get(name: str) -> Deviation:
    """The registered deviation ``name``.

    Parameters
    ----------
    name : str
        Deviation name (``"oadev"``, ``"mdev"`` …).

    Returns
    -------
    Deviation
        Its registry entry.

    Raises
    ------
    ParameterError
        ``name`` is not registered (the message lists the names).

    Examples
    --------
    >>> get("mdev").reference
    'NIST SP 1065 eq. 14'
    """
    try:
        return _TABLE[name]
    except KeyError:
        raise ParameterError(
            "deviation", f"{{name}} {name!r}: unknown; use {', '.join(_TABLE)}"
        ) from None


def names() -> tuple[str, ...]:
    """Every registered deviation's name, the built-in ones first (NIST SP 1065's order)."""
    return tuple(_TABLE)


def _greenhall(d: int, overlapping: bool, modified: bool) -> EdfFunction:
    """Greenhall & Riley's EDF for d-th differences (2003)."""

    def edf(alpha: int, m: int, n_phase: int) -> float:
        return ed.greenhall_edf(alpha, d, m, n_phase, overlapping=overlapping, modified=modified)

    return edf


def _flip(func: Callable[[int, int, int], float]) -> EdfFunction:
    """An EDF function of the (n_phase, m, alpha) signature as (alpha, m, n_phase)."""

    def edf(alpha: int, m: int, n_phase: int) -> float:
        return func(n_phase, m, alpha)

    return edf


def _built_in(
    name: str, edf: EdfFunction | None, stable32: str, reference: str, **kw: object
) -> Deviation:
    """A deviation of :mod:`.deviations` (its kernels, factors and work estimate)."""
    return Deviation(
        name,
        functools.partial(dv.segment_sums, name),
        functools.partial(dv.max_factor, name),
        edf,
        stable32_name=stable32,
        work=functools.partial(dv.work, name),
        reference=reference,
        **kw,  # type: ignore[arg-type]
    )


_MTOT_TEXT: Final = (
    "Stable32's MTOT EDF (Greenhall's modified-Allan EDF below m = 10, a line in N/m "
    "above, read from Stable32's bounds)"
)

for _dev in (
    _built_in("oadev", _greenhall(2, True, False), "Overlapping Allan", "NIST SP 1065 eq. 11"),
    _built_in("adev", _greenhall(2, False, False), "Allan", "NIST SP 1065 eq. 10"),
    _built_in("mdev", _greenhall(2, True, True), "Modified Allan", "NIST SP 1065 eq. 14"),
    _built_in(
        "tdev", _greenhall(2, True, True), "Time", "NIST SP 1065 eq. 15", time_deviation=True
    ),
    _built_in(
        "hdev", _greenhall(3, False, False), "Hadamard", "NIST SP 1065 eq. 17", hadamard=True
    ),
    _built_in(
        "ohdev",
        _greenhall(3, True, False),
        "Overlapping Hadamard",
        "NIST SP 1065 eq. 18",
        hadamard=True,
    ),
    _built_in(
        "totdev",
        _flip(ed.edf_totdev),
        "Total",
        "NIST SP 1065 eq. 25",
        interval="SP 1065 TOTVAR EDF, Stable32's phase-noise rule (simple EDF + 2)",
    ),
    _built_in(
        "mtotdev",
        _flip(ed.edf_mtotdev),
        "Modified Total",
        "NIST SP 1065 eq. 27",
        interval=_MTOT_TEXT,
    ),
    _built_in(
        "ttotdev",
        _flip(ed.edf_mtotdev),
        "Time Total",
        "NIST SP 1065 eq. 28",
        interval=_MTOT_TEXT,
        time_deviation=True,
    ),
    _built_in(
        "htotdev",
        _flip(ed.edf_htotdev),
        "Hadamard Total",
        "NIST SP 1065 eq. 29",
        interval="SP 1065 Htot EDF from m = 16, Stable32's rule (the simple EDF + 2) below "
        "m = 16 and at phase noise",
        hadamard=True,
    ),
    _built_in(
        "theo1",
        _flip(ed.edf_theo1),
        "Theo1",
        "NIST SP 1065 eq. 30",
        interval="Howe's empirical Theo1 EDF (its random-walk FM fit is far too small, the "
        "interval too wide, beyond τ ≈ 0.2 of the record)",
    ),
    _built_in(
        "mtie",
        None,
        "MTIE",
        "NIST SP 1065 eq. 31",
        time_deviation=True,
        raw_phase=True,
        interval="none: MTIE is a maximum over windows, not a variance; no chi-square EDF "
        "applies and neither NIST SP 1065 nor Stable32 gives it an interval",
    ),
    _built_in(
        "tierms",
        None,
        "TIE rms",
        "NIST SP 1065 eq. 33",
        time_deviation=True,
        raw_phase=True,
        interval="none: NIST SP 1065 gives TIE rms no EDF",
    ),
):
    register(_dev)

_BUILT_IN: Final = frozenset(_TABLE)


__all__ = [
    "DATA_TYPES",
    "Deviation",
    "EdfFunction",
    "SumsFunction",
    "get",
    "names",
    "register",
    "unregister",
]
