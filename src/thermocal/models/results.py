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
    """A learned coefficient, in physical (unscaled) units, with its standard error.

    Attributes
    ----------
    name : str
        Term name (e.g. ``"T1"``, ``"T1^2"``, ``"const"``).
    value : float
        Value [signal unit per unit of the term, e.g. (°/h)/°C].
    stderr : float or None
        Standard error [same unit]; None or NaN: not estimable.
    unit : str
        Unit text (default ``""``).

    Examples
    --------
    >>> Coefficient("T1", 0.02, float("nan"), "deg/h/degC").to_dict()
    {'name': 'T1', 'value': 0.02, 'unit': 'deg/h/degC'}
    """

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
        """JSON-ready dict; a non-finite standard error is left out."""
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

    Attributes
    ----------
    n_samples : int
        Samples fitted.
    n_coefficients : int
        Coefficients learned.
    rms_residual : float
        RMS of the residuals [signal unit].
    condition_number : float or None
        2-norm condition number κ of the scaled design (ratio of extreme singular values).
    r_squared : float or None
        Coefficient of determination :math:`1 - \\mathrm{RSS}/\\mathrm{TSS}`.
    dof : int or None
        Residual degrees of freedom n − p.
    extra : dict
        Family-specific statistics, written to the model file's ``fit`` section.
    """

    n_samples: int
    n_coefficients: int
    rms_residual: float
    condition_number: float | None = None
    r_squared: float | None = None
    dof: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (``extra`` merged in)."""
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

    Parameters
    ----------
    kappa : float or None
        The 2-norm condition number κ (dimensionless); None or non-finite: unknown.

    Returns
    -------
    str
        The words.

    References
    ----------
    - Golub, G. H. & Van Loan, C. F. (2013). *Matrix Computations*, 4th ed., Johns Hopkins
      University Press, §5.3.8.

    Examples
    --------
    >>> condition_wording(12.0), condition_wording(3e7)
    ('well conditioned', "ill-conditioned: about 7 of the data's digits lost")
    """
    if kappa is None or not math.isfinite(kappa):
        return "condition unknown"
    words = next(w for bound, w in CONDITION_WORDS if kappa <= bound)
    if kappa <= 1e3:
        return words
    return f"{words}: about {math.log10(kappa):.0f} of the data's digits lost"
