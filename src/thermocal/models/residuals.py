"""Standard errors that hold on coloured residuals.

Chamber residuals are never white: unmodelled slow drift, hysteresis and the sensor's
own flicker noise make neighbouring samples alike. Ordinary least-squares standard
errors assume independent samples and then claim precision the data do not have.

The correction used here is the *integrated autocorrelation time* of the residuals,

    τ = 1 + 2 Σ_{k=1}^{M} ρ_k,        n_eff = n / τ,

with ρ_k the residuals' sample autocorrelation at lag k and the window M chosen by
Sokal's automatic rule (the smallest M with M ≥ c·τ(M), c = 5, M ≤ n/4; A. D. Sokal, *Monte Carlo
Methods in Statistical Mechanics*, Cargèse lectures 1996, §3; the effective sample size
goes back to Bayley & Hammersley, J. R. Stat. Soc. B 8, 1946). The coefficients'
covariance is multiplied by τ. For a regression on a smooth regressor (temperatures are
far smoother than the residuals) with AR(1) errors of lag-one correlation ρ, the exact
variance inflation is (1 + ρρₓ)/(1 − ρρₓ) → (1 + ρ)/(1 − ρ) = τ as ρₓ → 1, so the
factor is the right one for the temperature terms and conservative for fast ones.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal.recording import FloatArray

SOKAL_C = 5.0
"""Window constant of Sokal's rule: M ≥ c·τ."""

MAX_SAMPLES_PER_SERIES = 1 << 21
"""The autocorrelation of a longer series is taken from its first 2²¹ samples."""

FEW_EFFECTIVE_SAMPLES = 30.0
"""Below this many effective samples the standard errors are flagged as rough."""


@dataclass(frozen=True)
class ResidualCorrelation:
    """Integrated autocorrelation time of the residuals.

    Attributes
    ----------
    tau : float
        τ [samples] (≥ 1).
    n : int
        Samples.
    n_eff : float
        n/τ.
    window : int
        Sokal's window M [samples].
    lag1 : float
        Lag-one autocorrelation.
    converged : bool
        The window rule was met before the series ran out (otherwise τ is a lower bound:
        the residuals hold a component as slow as the record).
    """

    tau: float
    n: int
    n_eff: float
    window: int
    lag1: float
    converged: bool

    @property
    def stderr_factor(self) -> float:
        """√τ: the factor on OLS standard errors."""
        return math.sqrt(self.tau)

    def to_dict(self) -> dict[str, Any]:
        """JSON form (model file ``fit.residual_correlation``)."""
        return {
            "tau_samples": self.tau,
            "n_samples": self.n,
            "n_effective": self.n_eff,
            "window_samples": self.window,
            "lag1": self.lag1,
            "converged": self.converged,
            "stderr_factor": self.stderr_factor,
            "method": "OLS covariance x integrated autocorrelation time (Sokal window, c=5)",
            "note": self.note(),
        }

    def note(self) -> str | None:
        """A warning line when the standard errors rest on few effective samples."""
        if self.n_eff >= FEW_EFFECTIVE_SAMPLES and self.converged:
            return None
        bound = "" if self.converged else "at least "
        return (
            f"the residuals are strongly autocorrelated (τ = {bound}{self.tau:.4g} samples, "
            f"{self.n_eff:.3g} effective samples of {self.n}): an unmodelled slow component "
            "dominates them; the standard errors account for it but are rough — consider "
            "more terms, a longer record or a model of the drift"
        )


def _autocovariance(x: FloatArray) -> FloatArray:
    """Biased sample autocovariance γ_k = Σ_{t} x_t x_{t+k} / n of a centred series (FFT)."""
    n = x.size
    size = 1 << math.ceil(math.log2(2 * n - 1)) if n > 1 else 2
    f = np.fft.rfft(x, size)
    acov = np.fft.irfft(f * np.conj(f), size)[:n] / n
    return np.asarray(acov, dtype=np.float64)


DIRECT_LAGS = 64
"""Lags summed directly before the FFT of the whole series is needed (Sokal's window is
usually a few lags: white or weakly correlated residuals)."""


def _lagged_sums(pieces: Sequence[FloatArray], lags: int) -> FloatArray:
    """Σ_t x_t x_{t+k} for k = 0 … ``lags`` of each centred piece, pooled (lags never
    cross from one piece into the next): the FFT's numbers, by direct sums."""
    acc = np.zeros(lags + 1)
    for p in pieces:
        if p.size < 2:
            continue
        x = p - p.mean()
        for k in range(min(lags, x.size - 1) + 1):
            acc[k] += float(np.dot(x[: x.size - k], x[k:]))
    return acc


def _window_within(acc: FloatArray, longest: int, c: float) -> bool:
    """Whether Sokal's window M ≥ c τ(M) is reached within the lags of ``acc`` (then the
    longer lags do not change the result)."""
    if acc[0] <= 0.0:
        return True
    rho = acc / acc[0]
    top = min(acc.size - 1, max(1, longest // 4))
    cums = 1.0 + 2.0 * np.cumsum(rho[1 : top + 1])
    ms = np.arange(1, top + 1)
    return bool(np.any(ms >= c * cums))


def residual_correlation(
    series: Sequence[FloatArray], *, data_rms: float | None = None, c: float = SOKAL_C
) -> ResidualCorrelation:
    """τ, n_eff and the window of the residuals of one or several runs (module docstring).

    Each run's residuals are centred on their own mean; the autocovariances of the runs
    are pooled (sum of lagged products over the sum of lengths), so the lags never cross
    from one run into the next. A series of one sample adds nothing.

    τ is kept at 1 (white) when the estimate does not exceed 1 by two of its standard
    deviations under white noise, sd(τ̂) ≈ τ·√(2(2M + 1)/n) with τ = 1 (Sokal, eq.
    3.19): white residuals then give the OLS standard errors exactly rather than a random
    few per cent more. Residuals
    below 1e-9 of ``data_rms`` (an exact fit: rounding noise) also give τ = 1.

    Parameters
    ----------
    series : sequence of numpy.ndarray
        Residuals per run [signal unit].
    data_rms : float, optional
        RMS of the data [signal unit], for the exact-fit rule.
    c : float, optional
        Sokal's window constant.  Default :data:`SOKAL_C` (5).

    Returns
    -------
    ResidualCorrelation

    Notes
    -----
    .. math:: \\tau = 1 + 2 \\sum_{k=1}^{M} \\rho_k

    References
    ----------
    - Sokal, A. D. (1997). Monte Carlo methods in statistical mechanics: foundations and
      new algorithms. In *Functional Integration* (Cargèse 1996), NATO ASI Series B 361,
      Plenum, 131–192, §3.

    Examples
    --------
    AR(1) residuals of lag-one correlation 0.9 (τ = (1 + ρ)/(1 − ρ) = 19 in theory):

    >>> import numpy as np
    >>> e = np.random.default_rng(0).standard_normal(2000)
    >>> x = np.zeros(2000)
    >>> for i in range(1, 2000):
    ...     x[i] = 0.9 * x[i - 1] + e[i]
    >>> r = residual_correlation([x])
    >>> round(r.tau, 1), round(r.lag1, 2)
    (22.6, 0.9)
    """
    pieces = [np.asarray(s, dtype=np.float64)[:MAX_SAMPLES_PER_SERIES] for s in series]
    pieces = [p[np.isfinite(p)] for p in pieces]
    n_total = int(sum(p.size for p in series))
    longest = max((p.size for p in pieces), default=0)
    if longest < 3:
        return ResidualCorrelation(1.0, n_total, float(n_total), 0, 0.0, False)
    used = int(sum(p.size for p in pieces if p.size >= 2))
    # the window is usually a few lags: their sums directly (no FFT of 2^22 points, no
    # 100 MB of transforms); the whole autocovariance only when the window is longer
    acc = _lagged_sums(pieces, min(DIRECT_LAGS, longest - 1))
    if not _window_within(acc, longest, c):
        acc = np.zeros(longest)
        for p in pieces:
            if p.size < 2:
                continue
            acov = _autocovariance(p - p.mean()) * p.size  # Σ lagged products
            acc[: p.size] += acov
    exact = data_rms is not None and math.sqrt(acc[0] / max(used, 1)) <= 1e-9 * data_rms
    if acc[0] <= 0.0 or exact:
        return ResidualCorrelation(1.0, n_total, float(n_total), 0, 0.0, True)
    rho = acc / acc[0]
    # windows up to a quarter of the longest run: beyond, the estimated autocorrelation
    # of a slow component (a step, a drift) decays and turns negative by construction
    top = min(acc.size - 1, max(1, longest // 4))  # the lags summed (all, or the direct ones)
    cums = 1.0 + 2.0 * np.cumsum(rho[1 : top + 1])  # τ(M) for M = 1, 2, …, top
    ms = np.arange(1, top + 1)
    ok = np.flatnonzero(ms >= c * cums)
    converged = ok.size > 0
    m = int(ms[ok[0]]) if converged else int(ms[-1])
    tau = float(max(1.0, cums[m - 1] if converged else float(np.max(cums))))
    if converged and tau - 1.0 <= 2.0 * math.sqrt(2.0 * (2 * m + 1) / used):
        tau = 1.0  # not distinguishable from white noise
    tau = min(tau, used / 2.0)  # never fewer than 2 effective samples
    return ResidualCorrelation(
        tau=tau,
        n=n_total,
        n_eff=n_total / tau,
        window=m,
        lag1=float(rho[1]),
        converged=converged,
    )
