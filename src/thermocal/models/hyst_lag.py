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
LFILTER_RUNS: Final = 64
"""Fewer runs of equal time steps than this: the lag by :func:`scipy.signal.lfilter` run by
run; as many or more: by the blocked scan (:func:`affine_scan`)."""
SCAN_BLOCK: Final = 32
"""Samples of a block of :func:`affine_scan` (the recursion's steps run side by side across
the blocks; 16–64 equally fast, fewer calls against shorter rows)."""


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
    Workman, *Digital Control of Dynamic Systems*, 3rd ed., 1998, §6.3).  A record of at
    most :data:`LFILTER_RUNS` runs of equal steps runs through :func:`scipy.signal.lfilter`
    run by run; any other (jittered clocks, float time stamps whose steps differ in the last
    bit) through the same recursion for :math:`g = T - z`,

    .. math:: g_k = e_k g_{k-1} + c_k (T_k - T_{k-1}), \qquad g_0 = 0,

    solved by a blocked scan (:func:`affine_scan`), exact in the same arithmetic as the
    sample-by-sample loop (which it equals to ~1e-15 relative; the recursion in :math:`g`,
    a small difference, rounds less than the loop in :math:`z`).

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
    t = np.asarray(time_s, dtype=np.float64)
    if x.size == 1:
        return x.copy()
    if not _few_runs(t):
        return _lag_scan(t, x, float(tau_s))
    h = np.diff(t)
    change = np.flatnonzero(h[1:] != h[:-1]) + 1
    e, c = lag_coefficients(h, float(tau_s))
    z = np.empty_like(x)
    z[0] = x[0]
    bounds = [0, *change.tolist(), e.size]
    for a, b in itertools.pairwise(bounds):
        ek, ck = float(e[a]), float(c[a])
        v = (1.0 - ck) * x[a + 1 : b + 1] + (ck - ek) * x[a:b]
        z[a + 1 : b + 1], _ = _signal.lfilter([1.0], [1.0, -ek], v, zi=[ek * z[a]])
    return z


def _few_runs(t: FloatArray, chunk: int = 65_536) -> bool:
    """Whether the steps of ``t`` form fewer than :data:`LFILTER_RUNS` runs of equal steps
    (chunk by chunk, stopping at the first chunk that settles it)."""
    changes = 0
    for a in range(0, t.size - 2, chunk):
        h = np.diff(t[a : a + chunk + 2])
        changes += int(np.count_nonzero(h[1:] != h[:-1]))
        if changes >= LFILTER_RUNS - 1:
            return False
    return True


def _scan_rows(a: FloatArray, w: FloatArray, q: FloatArray) -> None:
    """Row by row of ``(B, nb)`` arrays, in place: ``w[j] += a[j] w[j-1]`` (each column a
    block's recursion from zero) and ``q[j] = a[j] q[j-1]``, ``q[0] = a[0]`` (the products
    that carry a block's starting value), then each block started from the end of the one
    before (columns chained through :func:`affine_scan` of the blocks' ends)."""
    q[0] = a[0]
    for j in range(1, a.shape[0]):
        np.multiply(a[j], w[j - 1], out=q[j])
        w[j] += q[j]
        np.multiply(a[j], q[j - 1], out=q[j])
    ends = affine_scan(q[-1], w[-1])
    np.multiply(q[:, 1:], ends[:-1], out=q[:, 1:])
    w[:, 1:] += q[:, 1:]


def affine_scan(a: FloatArray, v: FloatArray) -> FloatArray:
    r"""The first-order recursion :math:`y_k = a_k y_{k-1} + v_k`, :math:`y_{-1} = 0`.

    Parameters
    ----------
    a, v : numpy.ndarray
        Coefficients (dimensionless) and inputs [any unit], same length.

    Returns
    -------
    numpy.ndarray
        :math:`y` [unit of v].

    Notes
    -----
    Blocks of :data:`SCAN_BLOCK` samples, laid side by side (a block a column), are run
    together step by step from zero, :math:`w_{b,j} = a_{b,j} w_{b,j-1} + v_{b,j}`, with
    the products :math:`q_{b,j} = \prod_{i \le j} a_{b,i}`; the blocks' ends are the same
    recursion one level up, :math:`Y_b = q_{b,B} Y_{b-1} + w_{b,B}` (this function again),
    and :math:`y_{b,j} = w_{b,j} + q_{b,j} Y_{b-1}`.  Every operation is the loop's own
    product and sum (no logarithm, no division: nothing overflows, a product that
    underflows is the loop's vanishing memory); the parallel prefix of an associative
    operator (Blelloch, "Prefix sums and their applications", CMU-CS-90-190, 1990, §1.4).

    References
    ----------
    - G. E. Blelloch, "Prefix sums and their applications", Technical Report
      CMU-CS-90-190, Carnegie Mellon University, 1990.

    Examples
    --------
    >>> import numpy as np
    >>> affine_scan(np.array([0.5, 0.5, 2.0]), np.array([1.0, 1.0, 1.0])).tolist()
    [1.0, 1.5, 4.0]
    """
    n = a.size
    y = np.empty(n)
    nb = n // SCAN_BLOCK if n >= 4 * SCAN_BLOCK else 0
    m = nb * SCAN_BLOCK
    if nb:
        shape = (SCAN_BLOCK, nb)
        w = np.empty(shape)
        np.copyto(w, v[:m].reshape(nb, SCAN_BLOCK).T)
        at = np.empty(shape)
        np.copyto(at, a[:m].reshape(nb, SCAN_BLOCK).T)
        _scan_rows(at, w, np.empty(shape))
        np.copyto(y[:m].reshape(nb, SCAN_BLOCK), w.T)
    acc = float(y[m - 1]) if m else 0.0
    for k, (ak, vk) in enumerate(zip(a[m:].tolist(), v[m:].tolist(), strict=True), m):
        acc = ak * acc + vk
        y[k] = acc
    return y


def _lag_scan(t: FloatArray, x: FloatArray, tau_s: float) -> FloatArray:
    """:func:`first_order_lag` of irregular steps: the recursion in g = T − z (its Notes),
    computed block-major from the start (the steps, their coefficients and the scan on
    ``(B, nb)`` arrays, three of them: the output's memory is the first's until the end),
    the last ``n mod B`` steps continued one by one."""
    n, bsz = t.size - 1, SCAN_BLOCK
    nb = n // bsz if n >= 4 * bsz else 0
    m = nb * bsz
    z = np.empty(n + 1)
    g_end = 0.0
    if nb:
        scratch = z[:m].reshape(bsz, nb)
        x1 = x[1 : m + 1].reshape(nb, bsz).T
        np.subtract(x1, x[:m].reshape(nb, bsz).T, out=scratch)  # T_k − T_{k−1}
        v = np.subtract(t[1 : m + 1].reshape(nb, bsz).T, t[:m].reshape(nb, bsz).T,
                        out=np.empty((bsz, nb)))  # fmt: skip
        bad = None if float(v.min()) > 0 else ~(v > 0)
        np.divide(v, -tau_s, out=v)  # −h/τ
        e = np.expm1(v)
        with np.errstate(invalid="ignore", divide="ignore"):
            np.divide(e, v, out=v)  # c
        e += 1.0  # e^(−h/τ) to 1e-16 absolute (the loop's exp: to 1e-16 relative)
        if bad is not None:
            np.copyto(e, 1.0, where=bad)
            np.copyto(v, 1.0, where=bad)
        v *= scratch  # c (T_k − T_{k−1})
        _scan_rows(e, v, scratch)
        np.subtract(x1.T, v.T, out=z[1 : m + 1].reshape(nb, bsz))
        g_end = float(v[-1, -1])
    z[0] = x[0]
    e_t, c_t = lag_coefficients(t[m + 1 :] - t[m:-1], tau_s)
    for k, (ek, ck) in enumerate(zip(e_t.tolist(), c_t.tolist(), strict=True), m + 1):
        g_end = ek * g_end + ck * (float(x[k]) - float(x[k - 1]))
        z[k] = float(x[k]) - g_end
    return z


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
    parts = [first_order_lag(t, x, tau_s) for t, x in zip(times, temps, strict=True)]
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


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


def rss_at(
    times: Sequence[FloatArray],
    temps: Sequence[FloatArray],
    y: FloatArray,
    tau_s: float,
    order: int,
    centre_scale: tuple[float, float],
    work: FloatArray | None = None,
) -> float:
    r"""The residual sum of squares of :func:`fit_at` at one τ, without the design matrix
    (the lag search's objective).

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
    work : numpy.ndarray, optional
        Scratch, shape ``(2, y.size)``, reused from call to call (fresh memory costs more
        than the sums on a large record).

    Returns
    -------
    float
        :math:`\mathrm{RSS}(\tau)` [signal unit²].

    Notes
    -----
    The normal equations from power sums, :math:`G_{jk} = \sum_i u_i^{j+k}`,
    :math:`b_j = \sum_i y_i u_i^j` (:math:`u = (z - \mu)/s`), solved for :math:`a`, then
    :math:`\mathrm{RSS} = \sum_i (y_i - \sum_j a_j u_i^j)^2` from the residuals themselves
    (an error :math:`\delta a` of the normal equations, conditioned as :math:`V^\top V`,
    raises the RSS by :math:`\delta a^\top G\,\delta a` only: second order; Björck,
    *Numerical Methods for Least Squares Problems*, SIAM, 1996, §2.2).  Equal to
    :func:`fit_at`'s RSS to ~1e-12 relative for the orders of the family.

    References
    ----------
    - Å. Björck, *Numerical Methods for Least Squares Problems*, SIAM, 1996.
    """
    mu, s = centre_scale
    u = lagged_runs(times, temps, tau_s)
    u -= mu
    u /= s
    power, prod = np.empty((2, u.size)) if work is None else work
    np.copyto(power, u)
    sums = [float(u.size)]
    yu = [float(y.sum())]
    for k in range(1, 2 * order + 1):  # numpy's pairwise sums: no BLAS threads spinning
        if k > 1:
            power *= u
        sums.append(float(power.sum()))
        if k <= order:
            yu.append(float(np.multiply(y, power, out=prod).sum()))
    gram = np.array([[sums[j + k] for k in range(order + 1)] for j in range(order + 1)])
    coef = np.linalg.lstsq(gram, np.array(yu), rcond=None)[0]
    resid = power
    resid.fill(float(coef[-1]))
    for c in coef[-2::-1]:  # Horner
        resid *= u
        resid += float(c)
    np.subtract(y, resid, out=resid)
    return float(np.multiply(resid, resid, out=resid).sum())


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

    work = np.empty((2, y.size))

    def rss(tau: float) -> float:
        return rss_at(times, temps, y, tau, order, centre_scale, work)

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
    best = fit_at(times, temps, y, tau, order, centre_scale)
    return best, tau_stderr(rss, best, order + 1)
