"""What a fit reports: each :class:`Coefficient` with its standard error and unit, the
:class:`FitStats` of the fit, and the words of a design's condition number
(:func:`condition_wording`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

# --- fitted coefficients and statistics ----------------------------------------------------

DISTINCT_T = 2.0
"""A coefficient within this many standard errors of zero is not distinct from zero."""


@dataclass(frozen=True)
class Coefficient:
    """A learned coefficient, in physical (unscaled) units, with its standard error."""

    name: str
    value: float
    stderr: float | None = None
    unit: str = ""

    @property
    def t_ratio(self) -> float | None:
        r"""The coefficient over its standard error, :math:`|v|/s` (None without a standard
        error or with a zero one).

        Returns
        -------
        float or None
            The magnitude in standard errors [dimensionless].

        Examples
        --------
        >>> round(Coefficient("c1", -0.5, 0.25).t_ratio, 3)
        2.0
        """
        return abs(self.value) / self.stderr if self.stderr else None

    @property
    def indistinct_from_zero(self) -> bool:
        r"""Whether the coefficient lies within :data:`DISTINCT_T` standard errors of zero:
        not distinct from zero on the data it was fitted on.

        Returns
        -------
        bool
            True when :math:`|v|/s <` :data:`DISTINCT_T` (a NaN ratio included); False
            without a standard error.

        Notes
        -----
        Two standard errors is the 95 % two-sided bound of a normal estimate (1.96 σ).

        References
        ----------
        IEEE Std 952-1997, IEEE Standard Specification Format Guide and Test Procedure for
        Single-Axis Interferometric Fiber Optic Gyros, Annex C (least-squares model
        fitting of test data).

        Examples
        --------
        >>> Coefficient("c1", 0.3, 0.2).indistinct_from_zero
        True
        >>> Coefficient("c1", 3.0, 0.2).indistinct_from_zero
        False
        """
        ratio = self.t_ratio
        return not (ratio is None or ratio >= DISTINCT_T)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"name": self.name, "value": self.value}
        # a standard error that cannot be estimated (no residual degrees of freedom) is
        # left out — "not estimable" — rather than written as a non-JSON NaN
        if self.stderr is not None and math.isfinite(self.stderr):
            d["stderr"] = self.stderr
        if self.unit:
            d["unit"] = self.unit
        return d


@dataclass(frozen=True)
class FitStats:
    """Fit statistics reported with every model.

    ``rms_residual`` in the signal unit; ``condition_number`` of the scaled
    design (2-norm, from the SVD); ``dof`` residual degrees of freedom.
    """

    n_samples: int
    n_coefficients: int
    rms_residual: float
    condition_number: float | None = None
    r_squared: float | None = None
    dof: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "n_samples": self.n_samples,
            "n_coefficients": self.n_coefficients,
            "rms_residual": self.rms_residual,
            "condition_number": self.condition_number,
            "r_squared": self.r_squared,
            "dof": self.dof,
        }
        d.update(self.extra)
        return d


CONDITION_WORDS: tuple[tuple[float, str], ...] = (
    (1e3, "well conditioned"),
    (1e6, "moderately conditioned"),
    (1e10, "ill-conditioned"),
    (math.inf, "near singular"),
)
"""Upper bounds of the 2-norm condition number κ of the scaled design and their words."""


def condition_wording(kappa: float | None) -> str:
    """Words for a condition number κ that match the number.

    κ ≤ 1e3 well conditioned; ≤ 1e6 moderately (about log₁₀κ of the data's digits are
    lost: the coefficients' standard errors are inflated by collinear terms); ≤ 1e10
    ill-conditioned (individual coefficients are not meaningful, only the prediction);
    beyond, near singular. Least squares loses ≈ log₁₀ κ significant digits (Golub & Van
    Loan, *Matrix Computations*, 4th ed., §5.3.8).
    """
    if kappa is None or not math.isfinite(kappa):
        return "condition unknown"
    words = next(w for bound, w in CONDITION_WORDS if kappa <= bound)
    if kappa <= 1e3:
        return words
    return f"{words}: about {math.log10(kappa):.0f} of the data's digits lost"
