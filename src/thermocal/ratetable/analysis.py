"""Scale factor, nonlinearity, asymmetry, bias, threshold, resolution and repeatability of a
gyro on a rate table, from the means of its plateaus.

Definitions (IEEE Std 528-2001, clause 2; the same terms in IEEE Std 952-1997 and IEEE Std
1431-2004, clause 3):

* **scale factor** ``K``: the slope of the straight line fitted by least squares to the
  input-output data over the input range (every plateau, both directions, unweighted);
* **scale-factor nonlinearity**: the systematic deviation of the output from that line,
  stated as the largest deviation in ppm of the full-scale output ``|K|·Ω_FS`` and per rate
  (ppm of full scale and ppm of the rate's own output);
* **scale-factor asymmetry**: the scale factor of the positive inputs minus that of the
  negative inputs, as a fraction of ``K``: ``(K₊ − K₋)/K`` [ppm];
* **input threshold**: the largest absolute value of the minimum input that produces an
  output of at least 50 % of that expected with the nominal scale factor;
* **resolution**: the largest value of the minimum change of input, above the threshold,
  that produces a change of output of at least 50 % of that expected;
* **scale-factor repeatability**: the spread (1σ, ppm of ``K``) of the scale factors of
  repeated ladders.

Uncertainties: each plateau mean ``ȳ_k`` has the variance ``v_k = s_k²/n_k`` of its samples'
white noise; every figure is linear in the ``ȳ`` (or made so to first order), so
``σ² = Σ g_k² v_k`` with ``g`` its gradient — the least-squares line ``β = A ȳ``,
``A = (XᵀX)⁻¹Xᵀ``, has ``Cov β = A diag(v) Aᵀ``; the residuals ``r = (I − XA) ȳ`` have
``Cov r = M diag(v) Mᵀ``, ``M = I − XA``.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import DesignError, ParameterError

FloatArray = npt.NDArray[np.float64]

SMALL_FRACTION = 0.01
"""Rates up to this fraction of full scale are the small rates of the threshold test."""
RESPONSE = 0.5
"""The threshold and resolution criterion: at least this fraction of the expected output."""
MAX_RATIO_SIGMA = 0.25
"""A response ratio with a larger standard error cannot tell 50 % from 0 or 100 %: left out."""
RATE_MATCH = 1e-9
"""Rates closer than this [°/s] are one rate of the ladder."""


def _slope_rows(w: FloatArray) -> FloatArray:
    """``A = (XᵀX)⁻¹Xᵀ`` of the straight line ``y = b + K w`` (rows: intercept, slope)."""
    x = np.column_stack([np.ones_like(w), w])
    return np.asarray(np.linalg.solve(x.T @ x, x.T), dtype=float)


@dataclass(frozen=True)
class RateRow:
    """One distinct rate of the ladder.

    Attributes
    ----------
    rate_dps : float
        Applied rate [°/s].
    n_plateaus : int
        Plateaus at this rate.
    mean, se : float
        Mean output and its standard error [output unit].
    bias_dps, bias_sigma_dps : float
        Bias at this rate: ``(ȳ − K Ω)/K`` [°/s], and its σ.
    nonlinearity_ppm_fs, nonlinearity_sigma_ppm_fs : float
        Deviation from the line, ``r/(|K| Ω_FS)·10⁶`` [ppm of full scale], and its σ.
    nonlinearity_ppm_rate : float or None
        The same as ppm of the rate's own output ``r/(K Ω)·10⁶`` (None at zero rate).
    """

    rate_dps: float
    n_plateaus: int
    mean: float
    se: float
    bias_dps: float
    bias_sigma_dps: float
    nonlinearity_ppm_fs: float
    nonlinearity_sigma_ppm_fs: float
    nonlinearity_ppm_rate: float | None


@dataclass(frozen=True)
class Figure:
    """A figure with its standard uncertainty, or the reason it was not computed.

    Attributes
    ----------
    value, sigma : float or None
        The figure and its 1σ (None when refused).
    reason : str or None
        Why it was not computed.
    detail : dict
        What it was computed from.
    """

    value: float | None
    sigma: float | None
    reason: str | None = None
    detail: dict[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        """The figure as a JSON object.

        Returns
        -------
        dict
            ``value``, ``sigma``, ``reason`` and the detail's keys.
        """
        return {
            "value": self.value,
            "sigma": self.sigma,
            "reason": self.reason,
            **(self.detail or {}),
        }


def _refused(reason: str) -> Figure:
    """A figure not computed, with its reason."""
    return Figure(None, None, reason)


@dataclass(frozen=True)
class LadderResult:
    """The scale-factor figures of one ladder (one temperature).

    Attributes
    ----------
    scale_factor, scale_factor_sigma : float
        ``K`` [output unit per °/s] and its σ.
    bias, bias_sigma : float
        Intercept of the line [output unit] and its σ (the zero-rate bias).
    zero_rate_bias_dps, zero_rate_bias_sigma_dps : float
        The intercept as a rate, ``b/K`` [°/s], and its σ.
    full_scale_dps : float
        Largest applied rate ``Ω_FS`` [°/s].
    nonlinearity : Figure
        Largest ``|r_k|`` in ppm of full scale (the rate it occurs at in ``detail``).
    asymmetry : Figure
        ``(K₊ − K₋)/K`` [ppm].
    threshold : Figure
        Input threshold [°/s] (an upper bound when the smallest rate tried responded).
    resolution : Figure
        Resolution [°/s].
    repeatability : Figure
        Scale-factor repeatability, 1σ [ppm].
    rows : tuple of RateRow
        Per distinct rate.
    temperature_c : float or None
        Mean temperature [°C].
    n_plateaus : int
        Plateaus used.
    """

    scale_factor: float
    scale_factor_sigma: float
    bias: float
    bias_sigma: float
    zero_rate_bias_dps: float
    zero_rate_bias_sigma_dps: float
    full_scale_dps: float
    nonlinearity: Figure
    asymmetry: Figure
    threshold: Figure
    resolution: Figure
    repeatability: Figure
    rows: tuple[RateRow, ...]
    temperature_c: float | None
    n_plateaus: int

    def to_dict(self) -> dict[str, Any]:
        """The result as a JSON object (keys in the JSON reference).

        Returns
        -------
        dict
        """
        return {
            "scale_factor": self.scale_factor,
            "scale_factor_sigma": self.scale_factor_sigma,
            "bias": self.bias,
            "bias_sigma": self.bias_sigma,
            "zero_rate_bias_dps": self.zero_rate_bias_dps,
            "zero_rate_bias_sigma_dps": self.zero_rate_bias_sigma_dps,
            "full_scale_dps": self.full_scale_dps,
            "nonlinearity_ppm_fs": self.nonlinearity.to_dict(),
            "asymmetry_ppm": self.asymmetry.to_dict(),
            "threshold_dps": self.threshold.to_dict(),
            "resolution_dps": self.resolution.to_dict(),
            "repeatability_ppm": self.repeatability.to_dict(),
            "temperature_c": self.temperature_c,
            "n_plateaus": self.n_plateaus,
            "rates": [dict(vars(r)) for r in self.rows],
        }


def _check(w: FloatArray, y: FloatArray, se: FloatArray) -> None:
    """Refuse arrays that cannot make a line."""
    if not (w.shape == y.shape == se.shape) or w.ndim != 1:
        raise ParameterError("means", "{name}: one mean and one standard error per rate")
    if not (np.all(np.isfinite(w)) and np.all(np.isfinite(y)) and np.all(se >= 0)):
        raise ParameterError("means", "{name}: rates, means and errors must be finite")
    if np.unique(w).size < 2:
        raise DesignError.naming(
            f"{w.size} plateau(s) at {np.unique(w).size} distinct rate(s): a scale factor "
            "needs at least two distinct rates; give them with {rates}",
            "rates",
        )


def _asymmetry(w: FloatArray, y: FloatArray, v: FloatArray, k: float, a_k: FloatArray) -> Figure:
    """``(K₊ − K₋)/K`` [ppm] from the lines over Ω ≥ 0 and Ω ≤ 0 (zero-rate plateaus in both)."""
    pos, neg = w >= 0, w <= 0
    if not np.any(w > 0) or not np.any(w < 0):
        side = "positive" if np.any(w > 0) else "negative"
        return _refused(f"only {side} rates: the asymmetry needs rates in both directions")
    if np.unique(w[pos]).size < 2 or np.unique(w[neg]).size < 2:
        return _refused(
            "the asymmetry needs two distinct rates on each side (zero counts on both): add "
            "a zero-rate plateau or more rates"
        )
    g = np.zeros((2, w.size))
    g[0, pos] = _slope_rows(w[pos])[1]
    g[1, neg] = _slope_rows(w[neg])[1]
    kp, kn = float(g[0] @ y), float(g[1] @ y)
    val = (kp - kn) / k
    grad = (g[0] - g[1]) / k - (kp - kn) / k**2 * a_k
    sig = float(np.sqrt(np.sum(grad**2 * v)))
    return Figure(val * 1e6, sig * 1e6, None, {"k_positive": kp, "k_negative": kn})


def _distinct(w: FloatArray, y: FloatArray, v: FloatArray) -> tuple[FloatArray, ...]:
    """Distinct rates with their mean output, its variance and the plateaus' count."""
    keys = np.unique(w)
    ym = np.array([np.mean(y[w == r]) for r in keys])
    vm = np.array([np.mean(v[w == r]) / np.sum(w == r) for r in keys])
    cnt = np.array([float(np.sum(w == r)) for r in keys])
    return keys, ym, vm, cnt


def _small_responses(
    w: FloatArray, y: FloatArray, v: FloatArray, k: float, fs: float, small: float
) -> tuple[list[dict[str, Any]], str | None]:
    """Each small rate's response ratio ``(ȳ − ȳ₀)/(K Ω)`` against the zero-rate plateaus."""
    keys, ym, vm, _ = _distinct(w, y, v)
    if not np.any(keys == 0):
        return [], "no zero-rate plateau to measure the response against: add a rate 0"
    y0, v0 = float(ym[keys == 0][0]), float(vm[keys == 0][0])
    sel = (keys != 0) & (np.abs(keys) <= small * fs)
    if not np.any(sel):
        return [], (
            f"no small rates (0 < |Ω| ≤ {small * fs:.3g} °/s, {small:g} of full scale): the "
            "ladder must hold small rates in both directions"
        )
    out = []
    for r, yr, vr in zip(keys[sel], ym[sel], vm[sel], strict=True):
        ratio = (yr - y0) / (k * r)
        out.append(
            {
                "rate_dps": float(r),
                "ratio": float(ratio),
                "sigma": float(np.sqrt(vr + v0) / abs(k * r)),
                "mean": float(yr),
                "var": float(vr),
            }
        )
    return out, None


def _threshold(resp: list[dict[str, Any]], why: str | None) -> Figure:
    """The input threshold from the small rates' responses (largest of both directions)."""
    if why is not None:
        return _refused(why)
    judged = [r for r in resp if r["sigma"] <= MAX_RATIO_SIGMA]
    if not judged:
        return _refused(
            "the noise is too large at the small rates to judge a 50 % response "
            f"(σ of the ratio > {MAX_RATIO_SIGMA:g}): hold them longer"
        )
    per_side: dict[str, tuple[float, float | None, bool]] = {}
    for side, sgn in (("positive", 1.0), ("negative", -1.0)):
        rs = sorted(
            (r for r in judged if np.sign(r["rate_dps"]) == sgn), key=lambda r: abs(r["rate_dps"])
        )
        if not rs:
            continue
        up = None  # smallest rate from which every larger one responds
        for r in reversed(rs):
            if r["ratio"] < RESPONSE:
                break
            up = abs(r["rate_dps"])
        below = [abs(r["rate_dps"]) for r in rs if up is None or abs(r["rate_dps"]) < up]
        per_side[side] = (
            up if up is not None else float("inf"),
            max(below) if below else None,
            up == abs(rs[0]["rate_dps"]),
        )
    if any(np.isinf(v[0]) for v in per_side.values()):
        return _refused("no small rate responded with 50 % of its expected output")
    side = max(per_side, key=lambda s: per_side[s][0])
    up, low, bound = per_side[side]
    return Figure(
        up,
        None,
        None,
        {
            "upper_bound_only": bool(bound),
            "above_dps": low,
            "direction": side,
            "directions": sorted(per_side),
            "responses": [{k: r[k] for k in ("rate_dps", "ratio", "sigma")} for r in resp],
        },
    )


def _resolution(resp: list[dict[str, Any]], k: float, thr: Figure) -> Figure:
    """The resolution: the smallest step between consecutive small rates above the threshold
    that responded, every larger step responding too (an upper bound when none failed)."""
    if thr.value is None:
        return _refused(f"needs the input threshold: {thr.reason}")
    steps: list[dict[str, Any]] = []
    for sgn in (1.0, -1.0):
        rs = sorted(
            (r for r in resp if np.sign(r["rate_dps"]) == sgn and abs(r["rate_dps"]) >= thr.value),
            key=lambda r: abs(r["rate_dps"]),
        )
        for a, b in itertools.pairwise(rs):
            d = b["rate_dps"] - a["rate_dps"]
            ratio = (b["mean"] - a["mean"]) / (k * d)
            sig = np.sqrt(a["var"] + b["var"]) / abs(k * d)
            if sig <= MAX_RATIO_SIGMA:
                steps.append(
                    {
                        "from_dps": a["rate_dps"],
                        "to_dps": b["rate_dps"],
                        "step_dps": abs(d),
                        "ratio": float(ratio),
                        "sigma": float(sig),
                    }
                )
    if not steps:
        return _refused(
            "no two small rates above the threshold on one side, with their response "
            "measurable against the noise: add small steps above the threshold"
        )
    bad = [s["step_dps"] for s in steps if s["ratio"] < RESPONSE]
    ok = [
        s["step_dps"]
        for s in steps
        if s["ratio"] >= RESPONSE and s["step_dps"] > max(bad, default=0)
    ]
    if not ok:
        return _refused("the largest step tried did not respond with 50 % of its expected output")
    return Figure(
        min(ok),
        None,
        None,
        {"above_dps": max(bad) if bad else None, "upper_bound_only": not bad, "steps": steps},
    )


def _repeatability(w: FloatArray, y: FloatArray, v: FloatArray, k: float) -> Figure:
    """Spread of the scale factors of repeated ladders (the i-th visit of each rate: pass i)."""
    keys, _, _, cnt = _distinct(w, y, v)
    p = int(np.max(cnt))
    use = keys[cnt == p]
    if p < 2 or use.size < 2:
        return _refused("each rate visited once: repeat the ladder for the repeatability")
    ks, sig = [], []
    for i in range(p):
        idx = np.array([np.flatnonzero(w == r)[i] for r in use])
        a = _slope_rows(w[idx])[1]
        ks.append(float(a @ y[idx]))
        sig.append(float(np.sqrt(np.sum(a**2 * v[idx]))))
    sd = float(np.std(ks, ddof=1))
    return Figure(
        sd / abs(k) * 1e6,
        float(sd / abs(k) * 1e6 / np.sqrt(2 * (p - 1))),
        None,
        {
            "passes": p,
            "scale_factors": ks,
            "rates_used": use.size,
            "from_noise_ppm": float(np.sqrt(np.mean(np.square(sig)))) / abs(k) * 1e6,
        },
    )


def _rows(
    w: FloatArray, y: FloatArray, v: FloatArray, beta: FloatArray, a: FloatArray, fs: float
) -> tuple[RateRow, ...]:
    """Per distinct rate: bias and deviation from the line with their σ."""
    k = float(beta[1])
    x = np.column_stack([np.ones_like(w), w])
    m = np.eye(w.size) - x @ a
    rows = []
    for r in np.unique(w):
        sel = (w == r).astype(float) / np.sum(w == r)
        res_g = sel @ m  # residual of this rate's mean, linear in y
        res = float(res_g @ y)
        rsig = float(np.sqrt(np.sum(res_g**2 * v)))
        ym = float(sel @ y)
        bias_g = (sel - r * a[1]) / k
        rows.append(
            RateRow(
                float(r),
                int(np.sum(w == r)),
                ym,
                float(np.sqrt(np.sum(sel**2 * v))),
                (ym - k * r) / k,
                float(np.sqrt(np.sum(bias_g**2 * v))),
                res / (abs(k) * fs) * 1e6,
                rsig / (abs(k) * fs) * 1e6,
                None if r == 0 else res / (k * r) * 1e6,
            )
        )
    return tuple(rows)


def analyse_ladder(
    rates_dps: npt.ArrayLike,
    means: npt.ArrayLike,
    standard_errors: npt.ArrayLike,
    *,
    temperature_c: float | None = None,
    small_fraction: float = SMALL_FRACTION,
) -> LadderResult:
    """Scale-factor figures of one rate ladder from its plateau means.

    Parameters
    ----------
    rates_dps : array_like
        Applied rate of each plateau [°/s] (repeated rates: one entry per plateau).
    means : array_like
        Mean output of each plateau [output unit].
    standard_errors : array_like
        Standard error of each mean [output unit] (``s/√n`` for white noise).
    temperature_c : float, optional
        The ladder's temperature [°C], recorded.
    small_fraction : float
        Rates up to this fraction of full scale are the threshold test's small rates.

    Returns
    -------
    LadderResult

    Raises
    ------
    DesignError
        Fewer than two distinct rates.
    ParameterError
        Arrays of different lengths or not finite.

    Notes
    -----
    The line :math:`\\bar y_k = b + K\\,\\Omega_k` by unweighted least squares; the
    nonlinearity of rate :math:`\\Omega` is the mean residual of its plateaus,

    .. math:: N(\\Omega) = \\frac{\\bar y(\\Omega) - b - K\\Omega}{|K|\\,\\Omega_{FS}}\\,10^6
              \\ \\text{ppm FS},

    the asymmetry :math:`(K_+ - K_-)/K` with :math:`K_\\pm` the lines over
    :math:`\\Omega \\ge 0` and :math:`\\Omega \\le 0`; the bias at a rate
    :math:`(\\bar y - K\\Omega)/K`.  Standard errors by linear propagation of the
    plateau means' variances (module docstring).

    References
    ----------
    IEEE Std 528-2001, *IEEE Standard for Inertial Sensor Terminology*, clause 2 (scale
    factor, scale-factor nonlinearity, asymmetry, input threshold, resolution).
    IEEE Std 952-1997 (R2008), clause 3 (definitions) and the scale-factor tests of its
    test procedure; IEEE Std 1431-2004, the same for Coriolis vibratory gyros.

    Examples
    --------
    >>> w = np.array([-100.0, -10.0, 0.0, 10.0, 100.0])
    >>> y = 1.001 * w + 0.5 + 1e-7 * w**3
    >>> res = analyse_ladder(w, y, np.full(5, 1e-3))
    >>> round(res.scale_factor, 6), round(res.nonlinearity.value, 1)
    (1.00199, 97.8)
    """
    w = np.asarray(rates_dps, float)
    y = np.asarray(means, float)
    se = np.asarray(standard_errors, float)
    _check(w, y, se)
    if not (np.isfinite(small_fraction) and 0 < small_fraction < 1):
        raise ParameterError("small_fraction", f"{{name}} must be in (0, 1), got {small_fraction}")
    return _ladder(w, y, se**2, temperature_c, small_fraction)


def _ladder(
    w: FloatArray, y: FloatArray, v: FloatArray, temperature_c: float | None, small: float
) -> LadderResult:
    """The figures of :func:`analyse_ladder` from checked arrays (``v``: the means' variances)."""
    a = _slope_rows(w)
    beta = a @ y
    cov = a @ np.diag(v) @ a.T
    b, k = float(beta[0]), float(beta[1])
    if k == 0:
        raise DesignError("the output does not change with the rate (scale factor 0)")
    fs = float(np.max(np.abs(w)))
    rows = _rows(w, y, v, beta, a, fs)
    worst = max(rows, key=lambda r: abs(r.nonlinearity_ppm_fs))
    nl = Figure(
        abs(worst.nonlinearity_ppm_fs),
        worst.nonlinearity_sigma_ppm_fs,
        None,
        {"at_rate_dps": worst.rate_dps},
    )
    resp, why = _small_responses(w, y, v, k, fs, small)
    thr = _threshold(resp, why)
    zb_g = a[0] / k - b / k**2 * a[1]
    return LadderResult(
        k,
        float(np.sqrt(cov[1, 1])),
        b,
        float(np.sqrt(cov[0, 0])),
        b / k,
        float(np.sqrt(np.sum(zb_g**2 * v))),
        fs,
        nl,
        _asymmetry(w, y, v, k, a[1]),
        thr,
        _resolution(resp, k, thr),
        _repeatability(w, y, v, k),
        rows,
        temperature_c,
        int(w.size),
    )


@dataclass(frozen=True)
class TemperatureCoefficient:
    """The scale factor's temperature coefficient.

    Attributes
    ----------
    ppm_per_c, sigma_ppm_per_c : float
        ``(dK/dT)/K(T_ref)·10⁶`` [ppm/°C] and its σ.
    tref_c : float
        Reference temperature [°C] (the weighted mean of the ladders').
    k_at_tref : float
        ``K(T_ref)`` [output unit per °/s].
    temperatures_c, scale_factors, sigmas : tuple of float
        The ladders' temperatures [°C], scale factors and their σ.
    birge_ratio : float or None
        ``√(χ²/(n − 2))`` of the line (None with two temperatures): well above 1, the
        scale factor is not linear in temperature or varies beyond its noise.
    """

    ppm_per_c: float
    sigma_ppm_per_c: float
    tref_c: float
    k_at_tref: float
    temperatures_c: tuple[float, ...]
    scale_factors: tuple[float, ...]
    sigmas: tuple[float, ...]
    birge_ratio: float | None

    def to_dict(self) -> dict[str, Any]:
        """The coefficient as a JSON object.

        Returns
        -------
        dict
        """
        return {k: list(v) if isinstance(v, tuple) else v for k, v in vars(self).items()}


def temperature_coefficient(
    temperatures_c: Sequence[float], scale_factors: Sequence[float], sigmas: Sequence[float]
) -> TemperatureCoefficient:
    """The scale factor's temperature coefficient from ladders at several temperatures.

    Parameters
    ----------
    temperatures_c : sequence of float
        Each ladder's temperature [°C].
    scale_factors : sequence of float
        Its scale factor [output unit per °/s].
    sigmas : sequence of float
        Their standard uncertainties.

    Returns
    -------
    TemperatureCoefficient

    Raises
    ------
    DesignError
        Fewer than two temperatures at least 1 °C apart.

    Notes
    -----
    Weighted least squares :math:`K_j = K_0 + c\\,(T_j - T_\\mathrm{ref})` with weights
    :math:`1/\\sigma_j^2`, :math:`T_\\mathrm{ref} = \\sum T_j/\\sigma_j^2 / \\sum 1/\\sigma_j^2`
    (so :math:`K_0` and :math:`c` are uncorrelated);
    :math:`\\mathrm{TC} = c/K_0 \\cdot 10^6` ppm/°C,
    :math:`\\sigma_\\mathrm{TC} = 10^6 \\sigma_c/|K_0|` with
    :math:`\\sigma_c^2 = 1/\\sum (T_j - T_\\mathrm{ref})^2/\\sigma_j^2`.

    References
    ----------
    IEEE Std 952-1997 (R2008), the temperature sensitivity of the scale factor of its
    specification format.

    Examples
    --------
    >>> tc = temperature_coefficient([-20, 25, 70], [0.99955, 1.0, 1.00045], [1e-6] * 3)
    >>> round(tc.ppm_per_c, 3)
    10.0
    """
    t = np.asarray(temperatures_c, float)
    k = np.asarray(scale_factors, float)
    s = np.asarray(sigmas, float)
    if t.size < 2 or float(np.ptp(t)) < 1.0:
        raise DesignError.naming(
            f"ladders at {', '.join(f'{x:.1f}' for x in t)} °C: the scale factor's temperature "
            "coefficient needs ladders at two or more temperatures at least 1 °C apart (one "
            "file per temperature, or one file whose {temps} column spans them)",
            "temps",
        )
    if not np.all(s > 0):
        s = np.where(s > 0, s, np.min(s[s > 0]) if np.any(s > 0) else 1.0)
    wts = 1.0 / s**2
    tref = float(np.sum(wts * t) / np.sum(wts))
    dt = t - tref
    c = float(np.sum(wts * dt * k) / np.sum(wts * dt**2))
    k0 = float(np.sum(wts * k) / np.sum(wts))
    sc = float(1.0 / np.sqrt(np.sum(wts * dt**2)))
    chi2 = float(np.sum(wts * (k - k0 - c * dt) ** 2))
    birge = float(np.sqrt(chi2 / (t.size - 2))) if t.size > 2 else None
    return TemperatureCoefficient(
        c / k0 * 1e6,
        sc / abs(k0) * 1e6,
        tref,
        k0,
        tuple(t.tolist()),
        tuple(k.tolist()),
        tuple(s.tolist()),
        birge,
    )
