r"""The maths of the ``hyst`` family: the die temperature as a first-order lag of the measured
temperature, a polynomial in it, and the lag's time constant found by a 1-D search.

The sensing element (the die) lags the thermometer that is recorded: on heating it is
cooler than the reading, on cooling warmer, and a polynomial in the reading leaves a
residual of opposite sign on the two legs (thermal hysteresis; Niu et al. 2013, Kim & Jung
2025).  The die temperature is modelled as the first-order lag

.. math:: \tau \dot z = T - z, \qquad z(t_0) = T(t_0),

solved exactly for a reading linear between samples (first-order hold): with
:math:`h_k = t_k - t_{k-1}`, :math:`e_k = e^{-h_k/\tau}`, :math:`c_k = (\tau/h_k)(1-e_k)`,

.. math:: z_k = e_k z_{k-1} + (1 - c_k) T_k + (c_k - e_k) T_{k-1}

(:math:`z_k = z_{k-1}` when :math:`h_k \le 0`; :math:`z = T` when :math:`\tau = 0`).  On a
ramp of rate :math:`r` from a hold it gives :math:`z = T - r\tau(1 - e^{-t/\tau})`, the
closed form a test compares with.  Pure maths (numpy; scipy.signal and scipy.optimize,
imported lazily).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

import numpy as np

from thermocal._lazy import LazyModule
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from scipy import optimize as _optimize
    from scipy import signal as _signal
else:
    _signal = LazyModule("scipy.signal")
    _optimize = LazyModule("scipy.optimize")

GRID_POINTS: Final = 41
"""Log-spaced lags of the coarse search between the sample interval and the upper bound."""
CURVATURE_STEP: Final = 0.02
"""Relative step of the finite difference giving the curvature of RSS(τ) at its minimum."""


def lag_coefficients(h: FloatArray, tau_s: float) -> tuple[FloatArray, FloatArray]:
    r"""The first-order-hold coefficients ``(e_k, c_k)`` of each step (module docstring).

    Parameters
    ----------
    h : numpy.ndarray
        Time steps [s].
    tau_s : float
        Time constant τ [s], > 0.

    Returns
    -------
    tuple of numpy.ndarray
        :math:`e_k = e^{-h_k/\tau}` and :math:`c_k = (\tau/h_k)(1 - e_k)` (1 where
        :math:`h_k \le 0`).
    """
    pos = h > 0
    x = np.where(pos, h, 1.0) / tau_s
    e = np.where(pos, np.exp(-x), 1.0)
    c = np.where(pos, -np.expm1(-x) / x, 1.0)
    return e, c


def first_order_lag(time_s: FloatArray, temp_c: FloatArray, tau_s: float) -> FloatArray:
    r"""The die temperature :math:`z` of a reading :math:`T` through a first-order lag.

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    temp_c : numpy.ndarray
        The reading [°C], same length.
    tau_s : float
        Time constant τ [s] (0: no lag).

    Returns
    -------
    numpy.ndarray
        :math:`z_k` [°C], starting at :math:`z_0 = T_0`.

    Notes
    -----
    .. math:: z_k = e_k z_{k-1} + (1 - c_k) T_k + (c_k - e_k) T_{k-1}

    exact for a reading linear between samples (the first-order hold of Franklin, Powell &
    Workman, *Digital Control of Dynamic Systems*, 3rd ed., 1998, §6.3).  Steps of equal
    coefficients run through :func:`scipy.signal.lfilter`.

    References
    ----------
    - G. F. Franklin, J. D. Powell and M. L. Workman, *Digital Control of Dynamic
      Systems*, 3rd ed., Addison-Wesley, 1998 (first-order-hold discretisation).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 2001.0)
    >>> z = first_order_lag(t, 20.0 + 0.01 * t, 100.0)
    >>> exact = 20.0 + 20.0 - 0.01 * 100.0 * (1 - np.exp(-2000.0 / 100.0))
    >>> round(float(z[-1]), 12) == round(float(exact), 12)
    True
    """
    x = np.asarray(temp_c, dtype=np.float64)
    if x.size == 0 or tau_s <= 0:
        return x.copy()
    e, c = lag_coefficients(np.diff(np.asarray(time_s, dtype=np.float64)), float(tau_s))
    z = np.empty_like(x)
    z[0] = x[0]
    if x.size == 1:
        return z
    change = np.flatnonzero((np.diff(e) != 0) | (np.diff(c) != 0)) + 1
    if change.size > e.size // 50:
        _lag_loop(x, e, c, z)
        return z
    bounds = [0, *change.tolist(), e.size]
    for a, b in itertools.pairwise(bounds):
        ek, ck = float(e[a]), float(c[a])
        v = (1.0 - ck) * x[a + 1 : b + 1] + (ck - ek) * x[a:b]
        z[a + 1 : b + 1], _ = _signal.lfilter([1.0], [1.0, -ek], v, zi=[ek * z[a]])
    return z


def _lag_loop(x: FloatArray, e: FloatArray, c: FloatArray, z: FloatArray) -> None:
    """The recursion sample by sample (irregular steps), into ``z`` (``z[0]`` set)."""
    zk = float(z[0])
    xs, es, cs = x.tolist(), e.tolist(), c.tolist()
    for k in range(1, len(xs)):
        ek, ck = es[k - 1], cs[k - 1]
        zk = ek * zk + (1.0 - ck) * xs[k] + (ck - ek) * xs[k - 1]
        z[k] = zk


@dataclass(frozen=True)
class LagFit:
    """A polynomial in the lagged temperature, fitted at one τ.

    Attributes
    ----------
    tau_s : float
        The lag τ [s].
    coefficients : numpy.ndarray
        :math:`a_j` of :math:`\\sum_j a_j ((z - \\mu)/s)^j` [signal unit].
    cov : numpy.ndarray
        Their covariance (τ held) [signal unit²].
    rss : float
        Residual sum of squares [signal unit²].
    n : int
        Samples.
    cond : float
        Condition number of the scaled design.
    residuals : numpy.ndarray
        The residuals [signal unit].
    """

    tau_s: float
    coefficients: FloatArray
    cov: FloatArray
    rss: float
    n: int
    cond: float
    residuals: FloatArray


def lagged_runs(
    times: Sequence[FloatArray], temps: Sequence[FloatArray], tau_s: float
) -> FloatArray:
    """Each run's lagged temperature (each from its own first sample), concatenated.

    Parameters
    ----------
    times, temps : sequence of numpy.ndarray
        Each run's times [s] and reading [°C].
    tau_s : float
        The lag τ [s].

    Returns
    -------
    numpy.ndarray
        z [°C] of every sample, run after run.
    """
    return np.concatenate([first_order_lag(t, x, tau_s) for t, x in zip(times, temps, strict=True)])


def fit_at(
    times: Sequence[FloatArray],
    temps: Sequence[FloatArray],
    y: FloatArray,
    tau_s: float,
    order: int,
    centre_scale: tuple[float, float],
) -> LagFit:
    r"""Least squares of :math:`y = \sum_{j=0}^{p} a_j ((z - \mu)/s)^j` at one τ.

    Parameters
    ----------
    times, temps : sequence of numpy.ndarray
        Each run's times [s] and reading [°C].
    y : numpy.ndarray
        The runs' targets concatenated [signal unit].
    tau_s : float
        The lag [s].
    order : int
        Polynomial order p.
    centre_scale : tuple of float
        μ and s [°C] of the scaled variable.

    Returns
    -------
    LagFit
    """
    mu, s = centre_scale
    u = (lagged_runs(times, temps, tau_s) - mu) / s
    v = np.vander(u, order + 1, increasing=True)
    coef, _, _, sv = np.linalg.lstsq(v, y, rcond=None)
    resid = y - v @ coef
    rss = float(resid @ resid)
    dof = max(y.size - (order + 1), 1)
    cov = np.linalg.pinv(v.T @ v) * (rss / dof)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    return LagFit(
        float(tau_s),
        np.asarray(coef, dtype=np.float64),
        np.asarray(cov, dtype=np.float64),
        rss,
        int(y.size),
        cond,
        resid,
    )


def _lag1(r: FloatArray) -> float:
    """Lag-1 autocorrelation of the residuals (0 when undefined)."""
    d = r - r.mean()
    den = float(d @ d)
    return float(d[1:] @ d[:-1]) / den if den > 0 else 0.0


def tau_stderr(rss_at: Callable[[float], float], best: LagFit, n_params: int) -> float | None:
    r"""Standard error of τ from the curvature of the profiled RSS(τ).

    Parameters
    ----------
    rss_at : callable
        τ [s] → RSS at the best polynomial for that τ.
    best : LagFit
        The fit at τ̂.
    n_params : int
        Linear coefficients (the polynomial's).

    Returns
    -------
    float or None
        σ_τ [s]; None when τ̂ = 0 or the curvature is not positive.

    Notes
    -----
    .. math:: \sigma_\tau^2 = \frac{2 s^2}{\mathrm{RSS}''(\hat\tau)}\,\frac{1+\rho}{1-\rho},
              \qquad s^2 = \frac{\mathrm{RSS}}{n - p - 1}

    the Gauss–Newton covariance of a separable least squares (Golub & Pereyra 1973),
    inflated for residuals with lag-1 autocorrelation ρ > 0 (the effective sample size of
    an AR(1) series, Bayley & Hammersley 1946).

    References
    ----------
    - G. H. Golub and V. Pereyra, "The differentiation of pseudo-inverses and nonlinear
      least squares problems whose variables separate", *SIAM J. Numer. Anal.* 10 (1973)
      413–432.
    - G. V. Bayley and J. M. Hammersley, "The 'effective' number of independent
      observations in an autocorrelated time series", *J. R. Stat. Soc. Suppl.* 8 (1946)
      184–197.
    """
    tau = best.tau_s
    if not tau > 0:
        return None
    d = CURVATURE_STEP * tau
    curv = (rss_at(tau + d) - 2.0 * best.rss + rss_at(tau - d)) / d**2
    if not curv > 0:
        return None
    s2 = best.rss / max(best.n - n_params - 1, 1)
    rho = max(_lag1(best.residuals), 0.0)
    infl = (1.0 + rho) / (1.0 - rho) if rho < 1.0 else math.inf
    return float(math.sqrt(2.0 * s2 / curv * infl))


def search_tau(
    times: Sequence[FloatArray],
    temps: Sequence[FloatArray],
    y: FloatArray,
    order: int,
    centre_scale: tuple[float, float],
    bounds_s: tuple[float, float],
) -> tuple[LagFit, float | None]:
    r"""τ minimising the RSS: a log-spaced grid of :data:`GRID_POINTS` lags (and τ = 0),
    refined by Brent's bounded search in ln τ between the best point's neighbours.

    Parameters
    ----------
    times, temps : sequence of numpy.ndarray
        Each run's times [s] and reading [°C].
    y : numpy.ndarray
        Targets [signal unit].
    order : int
        Polynomial order.
    centre_scale : tuple of float
        μ and s [°C].
    bounds_s : tuple of float
        The search's lower and upper lag [s], 0 < lo < hi.

    Returns
    -------
    tuple
        The fit at τ̂ and σ_τ [s] (:func:`tau_stderr`; None at τ̂ = 0).

    Notes
    -----
    .. math:: \hat\tau = \arg\min_\tau \min_a \sum_i (y_i - \sum_j a_j u_i(\tau)^j)^2

    References
    ----------
    - R. P. Brent, *Algorithms for Minimization without Derivatives*, Prentice-Hall, 1973.
    """

    def at(tau: float) -> LagFit:
        return fit_at(times, temps, y, tau, order, centre_scale)

    def rss(tau: float) -> float:
        return at(tau).rss

    lo, hi = bounds_s
    grid = np.concatenate([[0.0], np.geomspace(lo, hi, GRID_POINTS)])
    values = np.array([rss(float(g)) for g in grid])
    i = int(np.argmin(values))
    if 1 <= i < grid.size - 1:
        a, b = math.log(grid[max(i - 1, 1)]), math.log(grid[i + 1])
        res = _optimize.minimize_scalar(
            lambda v: rss(math.exp(v)), bounds=(a, b), method="bounded",
            options={"xatol": 1e-5},
        )  # fmt: skip
        tau = math.exp(float(res.x)) if float(res.fun) <= values[i] else float(grid[i])
    else:
        tau = float(grid[i])
    best = at(tau)
    return best, tau_stderr(rss, best, order + 1)
