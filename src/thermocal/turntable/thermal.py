"""A triad's error model over temperature from turntable runs at several soaks.

Each run gives θ (12: bias, scale factors, misalignments) with standard errors at its
soak temperature T_r.  Each parameter becomes a polynomial in ``T − TREF``:

    θ_k(T) = Σ_{p=0}^{P} c_kp (T − TREF)^p

fitted by weighted least squares (weights 1/σ_rk², through an SVD of the design scaled to
[−1, 1]); the standard errors are scaled by the reduced χ² when it exceeds 1 (the soaks
scatter more than their own σ say).  The order P is ``order`` if given, else chosen per
parameter from 0…min(3, R − 2) by the leave-one-temperature-out (LOTO) error: each run is
predicted from the others' fit, and the order with the smallest LOTO rms (in units of the
runs' σ) wins, a higher order having to lower it by 5 %.  Each parameter's LOTO rms is
reported so the user sees whether the soaks support the order.  Outside the calibrated
range the polynomials are evaluated at the nearest end (clamped), as the firmware does.

Applied to data (:func:`correct`): ``x_c = (I + E(T))⁻¹ (x − b(T))`` per sample, at each
sample's temperature.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import DesignError, ModelFileError, ParameterError, ThermocalInputError
from thermocal.turntable import model

FloatArray = npt.NDArray[np.float64]

MAX_ORDER = 3
PARAMETER_NAMES = (
    "bias_x",
    "bias_y",
    "bias_z",
    "scale_factor_x",
    "scale_factor_y",
    "scale_factor_z",
    *(f"misalignment_{m}" for m in model.MISALIGNMENT_NAMES),
)
"""θ's twelve names, in order."""
UNITS = {
    "gyro": ("deg/h",) * 3 + ("ppm",) * 3 + ("arcsec",) * 6,
    "accel": ("mg",) * 3 + ("ppm",) * 3 + ("arcsec",) * 6,
}
TRIAD_FORMAT = "thermocal-triad-thermal"
TRIAD_VERSION = 1


@dataclass(frozen=True)
class ParameterFit:
    """One parameter's polynomial in temperature, with its covariance and fit figures.

    Attributes
    ----------
    name : str
        The parameter's name (one of :data:`PARAMETER_NAMES`).
    unit : str
        Its unit: °/h or mg (bias), ppm (scale factor), arcsec (misalignment).
    coef : numpy.ndarray, shape (P + 1,)
        Coefficients of ascending powers of ``T − TREF`` [unit / °C^p].
    cov : numpy.ndarray, shape (P + 1, P + 1)
        Their covariance [unit² / °C^(p+q)].
    loto_rms : float
        Leave-one-temperature-out rms prediction error [unit]; NaN when not computable.
    reduced_chi2 : float
        Reduced χ² of the weighted fit (dimensionless); NaN with no degree of freedom.
    """

    name: str
    unit: str
    coef: FloatArray
    cov: FloatArray
    loto_rms: float
    reduced_chi2: float

    @property
    def sigma(self) -> FloatArray:
        """Standard errors of :attr:`coef` (square root of the covariance's diagonal)."""
        out: FloatArray = np.sqrt(np.maximum(np.diag(self.cov), 0.0))
        return out


def _design(dt: FloatArray, order: int, scale: float) -> FloatArray:
    out: FloatArray = (dt[:, None] / scale) ** np.arange(order + 1)[None, :]
    return out


def _wls(
    dt: FloatArray, v: FloatArray, w: FloatArray, order: int, scale: float
) -> tuple[FloatArray, FloatArray, float]:
    """Weighted LS of one parameter: (coef in physical powers, covariance, reduced χ²)."""
    a = _design(dt, order, scale) * np.sqrt(w)[:, None]
    y = v * np.sqrt(w)
    u, s, vt = np.linalg.svd(a, full_matrices=False)
    if not s[-1] > 1e-12 * s[0]:
        raise DesignError(f"the soak temperatures cannot support order {order}")
    vs = vt.T / s
    x = vs @ (u.T @ y)
    r = a @ x - y
    dof = len(v) - (order + 1)
    chi2 = float(r @ r) / dof if dof > 0 else float("nan")
    cov = (vs @ vs.T) * (max(chi2, 1.0) if dof > 0 else 1.0)
    unscale = scale ** -np.arange(order + 1)
    coef: FloatArray = x * unscale
    return coef, cov * np.outer(unscale, unscale), chi2


def _choose_order(
    dt: FloatArray, v: FloatArray, sigma: FloatArray, w: FloatArray, scale: float
) -> int:
    """The order 0…min(3, R − 2) with the smallest LOTO error in units of the runs' own σ;
    a higher order must lower it by 5 % to be taken."""
    best, chosen = math.inf, 0
    for p in range(0, min(MAX_ORDER, len(v) - 2) + 1):
        pred = _loto(dt, v, w, p, scale)
        ok = np.isfinite(pred)
        if not ok.any():
            continue
        score = float(np.sqrt(np.mean(((pred - v) / sigma)[ok] ** 2)))
        if score < best * 0.95:
            best, chosen = score, p
    return chosen


def _loto(dt: FloatArray, v: FloatArray, w: FloatArray, order: int, scale: float) -> FloatArray:
    """Each run predicted from the others (NaN when the others cannot support ``order``)."""
    out = np.full(len(v), np.nan)
    for i in range(len(v)):
        keep = np.arange(len(v)) != i
        if keep.sum() < order + 1:
            continue
        try:
            coef, _, _ = _wls(dt[keep], v[keep], w[keep], order, scale)
        except DesignError:
            continue
        out[i] = float(np.polynomial.polynomial.polyval(dt[i], coef))
    return out


@dataclass(frozen=True)
class TriadThermal:
    """A triad's twelve error parameters as polynomials in temperature.

    Attributes
    ----------
    kind : {"gyro", "accel"}
        The triad's kind.
    tref_c : float
        Reference temperature TREF [°C].
    order : int
        The highest polynomial order among the parameters (0…3).
    t_lo_c, t_hi_c : float
        The calibrated temperature range [°C]; evaluation is clamped to it.
    fits : tuple of ParameterFit
        The twelve parameters in the order of :data:`PARAMETER_NAMES`.
    soak_temperatures_c : tuple of float
        The runs' soak temperatures [°C].

    Notes
    -----
    Each parameter is

    .. math:: \\theta_k(T) = \\sum_{p=0}^{P} c_{kp}\\,(T - T_\\mathrm{ref})^p,

    evaluated at ``clip(T, t_lo_c, t_hi_c)``.

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    - IEEE Std 1431-2004, *IEEE Standard Specification Format Guide and Test Procedure for
      Coriolis Vibratory Gyros* (temperature sensitivity of bias and scale factor).
    """

    kind: str
    tref_c: float
    order: int
    t_lo_c: float
    t_hi_c: float
    fits: tuple[ParameterFit, ...]
    soak_temperatures_c: tuple[float, ...]
    runs: tuple[tuple[float, tuple[float, ...], tuple[float, ...]], ...] = ()
    """Each run's (temperature [°C], θ, σ) the polynomials were fitted to (for reports)."""
    method: str = "turntable"
    """How the runs were calibrated: ``turntable`` or ``multipos``."""
    gravity_m_s2: float | None = None
    """Local gravity the runs were calibrated with (multipos), for a later validation."""

    def sigma_at(self, temp_c: npt.ArrayLike) -> FloatArray:
        """Standard error of each fitted parameter at temperatures (clamped to the range).

        Parameters
        ----------
        temp_c : array_like
            Temperatures [°C], any shape (…).

        Returns
        -------
        numpy.ndarray, shape (…, 12)
            σ of each parameter [its unit].

        Notes
        -----
        .. math:: \\sigma_k(T)^2 = v^\\mathsf{T} C_k v, \\quad
                  v = (1, \\Delta T, \\Delta T^2, \\dots), \\quad \\Delta T = T - T_\\mathrm{ref}
        """
        t = np.clip(np.asarray(temp_c, dtype=np.float64), self.t_lo_c, self.t_hi_c)
        dt = t - self.tref_c
        cols = []
        for f in self.fits:
            v = dt[..., None] ** np.arange(len(f.coef))
            cols.append(np.sqrt(np.maximum(np.einsum("...i,ij,...j->...", v, f.cov, v), 0.0)))
        out: FloatArray = np.stack(cols, axis=-1)
        return out

    def theta_at(self, temp_c: npt.ArrayLike) -> FloatArray:
        """The twelve parameters θ at temperatures clamped to the calibrated range.

        Parameters
        ----------
        temp_c : array_like
            Temperatures [°C], any shape (…).

        Returns
        -------
        numpy.ndarray, shape (…, 12)
            θ in the units of :data:`UNITS` (°/h or mg, ppm, arcsec).

        Examples
        --------
        >>> import numpy as np
        >>> from thermocal.turntable.thermal import fit_triad
        >>> temps = [0.0, 20.0, 40.0]
        >>> thetas = np.zeros((3, 12))
        >>> thetas[:, 0] = [1.0, 3.0, 5.0]  # bias_x [°/h], 0.1 °/h per °C
        >>> tri = fit_triad("gyro", temps, thetas, np.ones((3, 12)), order=1)
        >>> round(float(tri.theta_at(30.0)[0]), 3)
        4.0
        >>> round(float(tri.theta_at(60.0)[0]), 3)  # clamped to 40 °C
        5.0
        """
        t = np.clip(np.asarray(temp_c, dtype=np.float64), self.t_lo_c, self.t_hi_c)
        dt = t - self.tref_c
        out: FloatArray = np.stack(
            [np.polynomial.polynomial.polyval(dt, f.coef) for f in self.fits], axis=-1
        )
        return out

    def to_dict(self) -> dict[str, Any]:
        """The file form (JSON-ready dict) that :meth:`from_dict` reads back."""
        return {
            "format": TRIAD_FORMAT,
            "version": TRIAD_VERSION,
            "kind": self.kind,
            "tref_c": self.tref_c,
            "order": self.order,
            "temperature_range_c": [self.t_lo_c, self.t_hi_c],
            "soak_temperatures_c": list(self.soak_temperatures_c),
            "runs": [
                {"temperature_c": t, "theta": list(th), "sigma": list(sg)}
                for t, th, sg in self.runs
            ],
            "parameters": [
                {
                    "name": f.name,
                    "unit": f.unit,
                    "coefficients": f.coef.tolist(),
                    "coefficients_sigma": f.sigma.tolist(),
                    "covariance": f.cov.tolist(),
                    "loto_rms": f.loto_rms if math.isfinite(f.loto_rms) else None,
                    "reduced_chi2": f.reduced_chi2 if math.isfinite(f.reduced_chi2) else None,
                }
                for f in self.fits
            ],
            **({} if self.method == "turntable" else {"method": self.method}),
            **({} if self.gravity_m_s2 is None else {"gravity_m_s2": self.gravity_m_s2}),
        }

    @classmethod
    def from_dict(cls, d: Any, where: str = "triad") -> TriadThermal:
        """Read the file form (:meth:`to_dict`) back, checked before use.

        Parameters
        ----------
        d : Any
            The parsed JSON object.
        where : str, default "triad"
            Prefix of the key path in errors (e.g. ``FILE: triads[0].model``).

        Returns
        -------
        TriadThermal

        Raises
        ------
        thermocal.errors.ModelFileError
            Wrong types, shapes or non-finite numbers (:func:`check_triad_dict`), or an
            ill-conditioned ``I + E(T)`` (:func:`check_conditioning`).
        """
        check_triad_dict(d, where)
        fits = tuple(
            ParameterFit(
                p["name"],
                p["unit"],
                np.asarray(p["coefficients"], dtype=np.float64),
                np.asarray(p["covariance"], dtype=np.float64),
                _float_or_nan(p.get("loto_rms")),
                _float_or_nan(p.get("reduced_chi2")),
            )
            for p in d["parameters"]
        )
        lo, hi = (float(v) for v in d["temperature_range_c"])
        out = cls(
            d["kind"],
            float(d["tref_c"]),
            int(d["order"]),
            lo,
            hi,
            fits,
            tuple(float(v) for v in d.get("soak_temperatures_c") or []),
            tuple(
                (
                    float(r["temperature_c"]),
                    tuple(float(v) for v in r["theta"]),
                    tuple(float(v) for v in r["sigma"]),
                )
                for r in d.get("runs") or []
            ),
            str(d.get("method") or "turntable"),
            None if d.get("gravity_m_s2") is None else float(d["gravity_m_s2"]),
        )
        check_conditioning(out, where)
        return out


MAX_CONDITION = 10.0
"""Largest condition number of ``I + E(T)`` accepted over a triad's calibrated range.  A
sensor triad's scale-factor errors and misalignments are small (``I + E`` within a few
per cent of the identity, condition number ≈ 1); 10 means one axis reads ten times another
after compensation: a corrupted file, not a calibration.  The compensation's error
amplification is bounded by this number."""
CONDITION_GRID = 1001
"""Temperatures of the calibrated range at which ``I + E(T)`` is checked."""


def _float_or_nan(v: Any) -> float:
    return float("nan") if v is None else float(v)


def _fail(path: str, what: str, got: Any) -> ModelFileError:
    text = repr(got)
    if len(text) > 60:
        text = text[:57] + "..."
    return ModelFileError(f"{path}: expected {what}, got {text}")


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _numbers(v: Any, path: str, n: int | None = None, *, min_len: int = 0) -> None:
    """A list of finite numbers (``n`` of them, or at least ``min_len``)."""
    want = f"a list of {n} finite numbers" if n is not None else "a list of finite numbers"
    if not isinstance(v, list) or (n is not None and len(v) != n) or len(v) < min_len:
        raise _fail(path, want, v)
    for i, x in enumerate(v):
        if not _is_number(x):
            raise _fail(f"{path}[{i}]", "a finite number", x)


def check_triad_dict(d: Any, where: str) -> None:
    """Check a triad model's file form before anything uses it.

    Parameters
    ----------
    d : Any
        The parsed JSON object.
    where : str
        The key-path prefix in errors.

    Returns
    -------
    None

    Raises
    ------
    thermocal.errors.ModelFileError
        Naming the key path (``where`` + ``.parameters[0].coefficients``).

    Notes
    -----
    Checked: the format tag and version, ``kind`` (gyro/accel), ``order`` (0…3), a finite
    ``tref_c`` inside or near (:func:`thermocal.models.schema.near_range`) a finite
    ``temperature_range_c`` ``[lo, hi]`` with lo < hi, the twelve parameters in θ's order
    (:data:`PARAMETER_NAMES`), each with 1…4 finite coefficients (ascending powers of
    ``T − TREF``) and a square finite covariance of that size, and the recorded runs
    (temperature, twelve θ and twelve σ each)."""
    from thermocal.models.schema import near_range

    if not isinstance(d, dict):
        raise _fail(where, "an object (a triad model)", d)
    if d.get("format") != TRIAD_FORMAT:
        raise _fail(f"{where}.format", repr(TRIAD_FORMAT), d.get("format"))
    ver = d.get("version", TRIAD_VERSION)
    if isinstance(ver, bool) or not isinstance(ver, int):
        raise _fail(f"{where}.version", "an integer", ver)
    if ver > TRIAD_VERSION:
        raise ModelFileError(
            f"{where}.version: triad model version {ver} is newer than this thermocal "
            f"supports ({TRIAD_VERSION}); upgrade thermocal"
        )
    for key in ("kind", "tref_c", "order", "temperature_range_c", "parameters"):
        if key not in d:
            raise ModelFileError(f"{where}: the field {key!r} is missing")
    if d["kind"] not in UNITS:
        raise _fail(f"{where}.kind", "gyro or accel", d["kind"])
    order = d["order"]
    if isinstance(order, bool) or not isinstance(order, int) or not 0 <= order <= MAX_ORDER:
        raise _fail(f"{where}.order", f"an integer 0…{MAX_ORDER}", order)
    _numbers(d["temperature_range_c"], f"{where}.temperature_range_c", 2)
    lo, hi = d["temperature_range_c"]
    if not (lo < hi or (lo == hi and d["order"] == 0)):  # one temperature: a constant
        raise _fail(f"{where}.temperature_range_c", "[low, high] with low < high", [lo, hi])
    if not _is_number(d["tref_c"]):
        raise _fail(f"{where}.tref_c", "a finite number (TREF [°C])", d["tref_c"])
    near_range(d["tref_c"], lo, hi, f"{where}.tref_c", "TREF")
    soaks = d.get("soak_temperatures_c")
    if soaks is not None:
        _numbers(soaks, f"{where}.soak_temperatures_c")
    runs = d.get("runs")
    if runs is not None:
        if not isinstance(runs, list):
            raise _fail(f"{where}.runs", "a list", runs)
        for i, r in enumerate(runs):
            at = f"{where}.runs[{i}]"
            if not isinstance(r, dict):
                raise _fail(at, "an object", r)
            if not _is_number(r.get("temperature_c")):
                raise _fail(f"{at}.temperature_c", "a finite number", r.get("temperature_c"))
            _numbers(r.get("theta"), f"{at}.theta", 12)
            _numbers(r.get("sigma"), f"{at}.sigma", 12)
    params = d["parameters"]
    if not isinstance(params, list) or len(params) != 12:
        raise _fail(f"{where}.parameters", "a list of the twelve parameters", params)
    for k, p in enumerate(params):
        at = f"{where}.parameters[{k}]"
        if not isinstance(p, dict):
            raise _fail(at, "an object", p)
        if p.get("name") != PARAMETER_NAMES[k]:
            raise _fail(f"{at}.name", repr(PARAMETER_NAMES[k]), p.get("name"))
        if not isinstance(p.get("unit"), str):
            raise _fail(f"{at}.unit", "a string", p.get("unit"))
        coef: list[float] = p.get("coefficients")  # type: ignore[assignment]
        _numbers(coef, f"{at}.coefficients", min_len=1)
        if len(coef) > MAX_ORDER + 1:
            raise _fail(f"{at}.coefficients", f"at most {MAX_ORDER + 1} coefficients", coef)
        cov = p.get("covariance")
        n = len(coef)
        if not isinstance(cov, list) or len(cov) != n:
            raise _fail(f"{at}.covariance", f"a {n}×{n} matrix", cov)
        for i, row in enumerate(cov):
            _numbers(row, f"{at}.covariance[{i}]", n)
        for key in ("loto_rms", "reduced_chi2"):
            v = p.get(key)
            if v is not None and not _is_number(v):
                raise _fail(f"{at}.{key}", "a finite number or null", v)


def check_conditioning(triad: TriadThermal, where: str) -> None:
    """Refuse a triad whose ``I + E(T)`` is singular or ill-conditioned somewhere in its
    calibrated range (compensation divides by it: ``x_c = (I + E)⁻¹ (x − b)``): checked at
    :data:`CONDITION_GRID` temperatures spanning the range (the polynomials are clamped to
    it, so no other temperature is ever used) and the soaks; the condition number
    (2-norm, ratio of extreme singular values) must be at most :data:`MAX_CONDITION` and
    the determinant keep one sign (a sign change is a singular point between two grid
    temperatures).

    Parameters
    ----------
    triad : TriadThermal
        The model to check.
    where : str
        Key-path prefix in the error message.

    Raises
    ------
    thermocal.errors.ModelFileError
        ``I + E(T)`` not finite, with condition number above :data:`MAX_CONDITION`, or
        with a determinant that changes sign over the range.

    Notes
    -----
    .. math:: \\kappa(T) = \\sigma_\\max(I + E(T)) / \\sigma_\\min(I + E(T)) \\le 10

    References
    ----------
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013 (§2.6, the
      condition number of a linear system).
    """
    grid = np.linspace(triad.t_lo_c, triad.t_hi_c, CONDITION_GRID)
    _, e = error_terms(triad, grid)
    m = e + np.eye(3)[None, :, :]
    with np.errstate(all="ignore"):
        sv = np.linalg.svd(m, compute_uv=False) if np.isfinite(m).all() else None
        det = np.linalg.det(m) if sv is not None else None
    at = f"{where}.parameters"
    if sv is None or det is None:
        k = int(np.argmax(~np.isfinite(m).all(axis=(1, 2))))
        raise ModelFileError(
            f"{at}: I + E(T) is not finite at T = {grid[k]:.4g} °C: the scale factors or "
            "misalignments overflow"
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        cond = np.where(sv[:, -1] > 0, sv[:, 0] / sv[:, -1], np.inf)
    worst = int(np.argmax(cond))
    if not cond[worst] <= MAX_CONDITION:
        raise ModelFileError(
            f"{at}: I + E(T) is singular or ill-conditioned at T = {grid[worst]:.4g} °C "
            f"(condition number {cond[worst]:.3g} > {MAX_CONDITION:g}): the scale factors and "
            "misalignments do not describe a sensor triad"
        )
    flips = np.flatnonzero(np.sign(det[1:]) != np.sign(det[:-1]))
    if flips.size:
        k = int(flips[0])
        raise ModelFileError(
            f"{at}: I + E(T) is singular between T = {grid[k]:.4g} and {grid[k + 1]:.4g} °C "
            "(its determinant changes sign): the scale factors and misalignments do not "
            "describe a sensor triad"
        )


def check_tref(tref_c: float, lo: float, hi: float) -> None:
    """Refuse (naming ``tref_c``) a reference temperature [°C] that the calibration
    file's reader would refuse (:func:`check_triad_dict`: finite, inside the soaks'
    range ``[lo, hi]`` or within :func:`thermocal.models.checks.range_margin` of it), before
    anything is fitted or written.

    Parameters
    ----------
    tref_c : float
        Reference temperature [°C].
    lo, hi : float
        The soaks' temperature range [°C].

    Raises
    ------
    thermocal.errors.ParameterError
        ``tref_c`` not finite or farther than the margin outside ``[lo, hi]``.
    """
    from thermocal.models.checks import range_margin

    margin = range_margin(lo, hi)
    if not (math.isfinite(tref_c) and lo - margin <= tref_c <= hi + margin):
        where = "far outside" if math.isfinite(tref_c) else "not a temperature within"
        raise ParameterError(
            "tref_c",
            f"{{name}} {tref_c:g}: the reference temperature is {where} the soaks' "
            f"[{lo:.4g}, {hi:.4g}] °C (more than {margin:.4g} °C beyond; a calibration file "
            f"with it is refused when read); give a {{name}} within [{lo - margin:.4g}, "
            f"{hi + margin:.4g}] °C, or leave it out (the middle of the soaks)",
        )


def _fit_inputs(
    kind: str,
    temps_c: Sequence[float],
    thetas: npt.ArrayLike,
    sigmas: npt.ArrayLike,
    tref_c: float | None,
    order: int | None,
) -> tuple[FloatArray, FloatArray, FloatArray, float]:
    """:func:`fit_triad`'s inputs checked, as arrays, with TREF [°C]."""
    if kind not in UNITS:
        raise ThermocalInputError(f"triad kind must be gyro or accel, got {kind!r}")
    t = np.asarray(temps_c, dtype=np.float64)
    th = np.asarray(thetas, dtype=np.float64)
    sg = np.asarray(sigmas, dtype=np.float64)
    r = t.size
    if th.shape != (r, 12) or sg.shape != (r, 12):
        raise ThermocalInputError("thetas and sigmas must be (runs, 12)")
    if r < 2:
        raise DesignError("a temperature model needs runs at two soak temperatures at least")
    span = float(t.max() - t.min())
    if not span > 0.5:
        raise DesignError(
            f"the runs' temperatures span {span:.3g} °C: soak them at different temperatures"
        )
    tref = float(0.5 * (t.min() + t.max())) if tref_c is None else float(tref_c)
    check_tref(tref, float(t.min()), float(t.max()))
    max_order = min(MAX_ORDER, r - 1)
    if order is not None and not 0 <= order <= max_order:
        raise DesignError(
            f"order {order} needs at least {order + 1} soak temperatures; the runs give {r}"
        )
    return t, th, sg, tref


def fit_triad(
    kind: str,
    temps_c: Sequence[float],
    thetas: npt.ArrayLike,
    sigmas: npt.ArrayLike,
    *,
    tref_c: float | None = None,
    order: int | None = None,
    method: str = "turntable",
    gravity_m_s2: float | None = None,
) -> TriadThermal:
    """Fit the twelve parameters of a triad over the soaks.

    Parameters
    ----------
    kind : {"gyro", "accel"}
        The triad's kind.
    temps_c : sequence of float
        Each run's soak temperature [°C].
    thetas, sigmas : array_like, shape (R, 12)
        Each run's θ and its σ in the units of :data:`UNITS`; a parameter whose σ is zero in
        every run (held by a constraint) is fitted unweighted.
    tref_c : float, optional
        The reference temperature [°C] (default: the middle of the soaks).
    order : int, optional
        The polynomial order (default: chosen per parameter by the LOTO error).
    method, gravity_m_s2 : str, float, optional
        How the runs were calibrated and the accelerometer's gravity [m/s²], recorded.

    Returns
    -------
    TriadThermal
        Each parameter's polynomial :math:`\\theta_k(T) = \\sum_p c_{kp} (T - T_\\mathrm{ref})^p`
        with its σ, order and LOTO rms (module docstring).

    Raises
    ------
    thermocal.errors.ParameterError
        A ``tref_c`` the calibration file's reader would refuse.
    thermocal.errors.ThermocalInputError
        ``kind`` not gyro/accel, or ``thetas``/``sigmas`` not of shape (R, 12).
    thermocal.errors.DesignError
        Fewer than two soaks, soaks within 0.5 °C, or an ``order`` the soaks cannot support.

    Notes
    -----
    Weighted least squares with weights :math:`w_r = 1/\\sigma_{rk}^2`; the covariance
    :math:`(A^\\mathsf{T} W A)^{-1}` is scaled by the reduced χ² when it exceeds 1.

    References
    ----------
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013 (weighted least
      squares by the SVD).
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.

    Examples
    --------
    >>> import numpy as np
    >>> temps = [-10.0, 25.0, 60.0]
    >>> thetas = np.zeros((3, 12))
    >>> thetas[:, 3] = [100.0, 135.0, 170.0]  # scale_factor_x [ppm]: 1 ppm/°C
    >>> tri = fit_triad("gyro", temps, thetas, np.ones((3, 12)), order=1)
    >>> round(float(tri.fits[3].coef[1]), 3), tri.tref_c
    (1.0, 25.0)
    """
    t, th, sg, tref = _fit_inputs(kind, temps_c, thetas, sigmas, tref_c, order)
    r = t.size
    dt = t - tref
    scale = max(float(np.max(np.abs(dt))), 1.0)
    fits = []
    for k in range(12):
        sg_k = sg[:, k]
        if not np.any(sg_k > 0):  # a constrained parameter (σ = 0 everywhere): unweighted
            sg_k = np.ones(r)
        w = 1.0 / np.maximum(sg_k, 1e-12 * float(np.max(sg_k))) ** 2
        p_k = order if order is not None else _choose_order(dt, th[:, k], sg_k, w, scale)
        coef, cov, chi2 = _wls(dt, th[:, k], w, p_k, scale)
        pred = _loto(dt, th[:, k], w, p_k, scale) if r > p_k + 1 else np.full(r, np.nan)
        ok = np.isfinite(pred)
        loto = float(np.sqrt(np.mean((pred - th[:, k])[ok] ** 2))) if ok.any() else float("nan")
        fits.append(ParameterFit(PARAMETER_NAMES[k], UNITS[kind][k], coef, cov, loto, chi2))
    chosen = max(len(f.coef) - 1 for f in fits)
    runs = tuple(
        (float(t[i]), tuple(float(v) for v in th[i]), tuple(float(v) for v in sg[i]))
        for i in range(r)
    )
    return TriadThermal(
        kind,
        tref,
        chosen,
        float(t.min()),
        float(t.max()),
        tuple(fits),
        tuple(float(v) for v in t),
        runs,
        method,
        gravity_m_s2,
    )


def constant_triad(
    kind: str,
    temp_c: float,
    theta: npt.ArrayLike,
    cov: npt.ArrayLike,
    *,
    t_range_c: tuple[float, float] | None = None,
    method: str = "turntable",
    gravity_m_s2: float | None = None,
) -> TriadThermal:
    """A triad calibrated at one temperature: every parameter a constant (order 0), the
    calibrated range ``t_range_c`` (the temperatures the run saw; default that temperature
    alone; the model is applied unchanged at any temperature, with the usual warning
    outside it).

    Parameters
    ----------
    kind : {"gyro", "accel"}
        The triad's kind.
    temp_c : float
        The run's temperature [°C], also TREF.
    theta : array_like, shape (12,)
        The parameters in the units of :data:`UNITS` (°/h or mg, ppm, arcsec).
    cov : array_like, shape (12, 12)
        Their covariance [units²].
    t_range_c : tuple of float, optional
        The calibrated range [°C] (default: ``temp_c`` alone).
    method : str, default "turntable"
        How the run was calibrated (``turntable`` or ``multipos``), recorded.
    gravity_m_s2 : float, optional
        Local gravity used [m/s²], recorded.

    Returns
    -------
    TriadThermal
        Order 0 in every parameter.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        ``kind`` not gyro/accel.
    """
    if kind not in UNITS:
        raise ThermocalInputError(f"triad kind must be gyro or accel, got {kind!r}")
    th = np.asarray(theta, dtype=np.float64).reshape(12)
    c = np.asarray(cov, dtype=np.float64).reshape(12, 12)
    fits = tuple(
        ParameterFit(PARAMETER_NAMES[k], UNITS[kind][k], th[k : k + 1].copy(),
                     c[k : k + 1, k : k + 1].copy(), float("nan"), float("nan"))
        for k in range(12)
    )  # fmt: skip
    sg = np.sqrt(np.maximum(np.diag(c), 0.0))
    t = float(temp_c)
    lo, hi = (t, t) if t_range_c is None else (float(t_range_c[0]), float(t_range_c[1]))
    return TriadThermal(
        kind, t, 0, lo, hi, fits, (t,),
        ((t, tuple(float(v) for v in th), tuple(float(v) for v in sg)),),
        method, gravity_m_s2,
    )  # fmt: skip


def error_terms(triad: TriadThermal, temp_c: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Bias vector and error matrix of a triad at each temperature.

    Parameters
    ----------
    triad : TriadThermal
        The model.
    temp_c : array_like, shape (n,)
        Temperatures [°C] (clamped to the calibrated range).

    Returns
    -------
    b : numpy.ndarray, shape (n, 3)
        Bias b(T) [°/h or mg].
    E : numpy.ndarray, shape (n, 3, 3)
        Scale-factor and misalignment matrix E(T) (dimensionless), see
        :func:`thermocal.turntable.model.error_matrices`.
    """
    th = np.atleast_2d(triad.theta_at(temp_c))
    b: FloatArray = th[:, 0:3]
    return b, model.error_matrices(th)


CORRECT_BLOCK = 1 << 18
"""Samples per block of :func:`correct` (bounded working memory)."""


def solve3(m: FloatArray, r: FloatArray) -> FloatArray:
    """``m⁻¹ r`` for stacks of 3×3 matrices ``m`` (n, 3, 3) and vectors ``r`` (n, 3), by the
    adjugate over the determinant (Cramer's rule; ``I + E`` is within 10⁻³ of the identity,
    so the determinant is near 1 and the formula exact to rounding) — vectorised, where a
    LAPACK call per 3×3 matrix would cost microseconds each.

    Parameters
    ----------
    m : numpy.ndarray, shape (n, 3, 3)
        Matrices.
    r : numpy.ndarray, shape (n, 3)
        Right-hand sides.

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        ``m⁻¹ r`` per row.

    Notes
    -----
    .. math:: m^{-1} r = \\operatorname{adj}(m)\\, r / \\det m

    References
    ----------
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013.

    Examples
    --------
    >>> import numpy as np
    >>> m = np.array([[[2.0, 0, 0], [0, 4.0, 0], [0, 0, 1.0]]])
    >>> solve3(m, np.array([[2.0, 2.0, 3.0]])).round(3).tolist()
    [[1.0, 0.5, 3.0]]
    """
    a, b, c = m[:, 0, 0], m[:, 0, 1], m[:, 0, 2]
    d, e, f = m[:, 1, 0], m[:, 1, 1], m[:, 1, 2]
    g, h, i = m[:, 2, 0], m[:, 2, 1], m[:, 2, 2]
    co_a, co_b, co_c = e * i - f * h, -(d * i - f * g), d * h - e * g
    det = a * co_a + b * co_b + c * co_c
    x, y, z = r[:, 0], r[:, 1], r[:, 2]
    out = np.empty_like(r)
    out[:, 0] = (co_a * x - (b * i - c * h) * y + (b * f - c * e) * z) / det
    out[:, 1] = (co_b * x + (a * i - c * g) * y - (a * f - c * d) * z) / det
    out[:, 2] = (co_c * x - (a * h - b * g) * y + (a * e - b * d) * z) / det
    return out


def correct(
    triad: TriadThermal, x: npt.ArrayLike, temp_c: npt.ArrayLike, bias_to_data: float
) -> FloatArray:
    """``x_c = (I + E(T))⁻¹ (x − b(T))`` per sample; ``x`` (n, 3) in the data's unit,
    ``bias_to_data`` the factor from the triad's bias unit (°/h or mg) to it.  Computed in
    blocks of :data:`CORRECT_BLOCK` samples (:func:`solve3` for the 3×3 solves).

    Parameters
    ----------
    triad : TriadThermal
        The model.
    x : array_like, shape (n, 3)
        Raw samples [data unit, e.g. °/s or m/s²].
    temp_c : array_like, shape (n,) or scalar
        Each sample's temperature [°C].
    bias_to_data : float
        Factor from the triad's bias unit (°/h or mg) to the data's unit.

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        Compensated samples [data unit].

    Notes
    -----
    .. math:: x_c = (I + E(T))^{-1}\\,(x - b(T))

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.

    Examples
    --------
    >>> import numpy as np
    >>> tri = constant_triad("gyro", 25.0, [3600.0, 0, 0] + [0.0] * 9, np.eye(12))
    >>> correct(tri, [[2.0, 0.0, 0.0]], 25.0, 1 / 3600).round(3).tolist()  # °/s
    [[1.0, 0.0, 0.0]]
    """
    xs = np.asarray(x, dtype=np.float64)
    tc = np.broadcast_to(np.asarray(temp_c, dtype=np.float64), xs.shape[:1])
    out = np.empty_like(xs)
    for a0 in range(0, xs.shape[0], CORRECT_BLOCK):
        sl = slice(a0, min(xs.shape[0], a0 + CORRECT_BLOCK))
        b, e = error_terms(triad, tc[sl])
        e[:, 0, 0] += 1.0
        e[:, 1, 1] += 1.0
        e[:, 2, 2] += 1.0
        out[sl] = solve3(e, xs[sl] - b * bias_to_data)
    return out


__all__ = [
    "MAX_CONDITION",
    "PARAMETER_NAMES",
    "ParameterFit",
    "TriadThermal",
    "TriadValidation",
    "check_conditioning",
    "check_tref",
    "check_triad_dict",
    "constant_triad",
    "correct",
    "error_terms",
    "fit_triad",
    "solve3",
    "validate_triad",
]


@dataclass(frozen=True)
class TriadValidation:
    """How a triad calibration does on an independent turntable run (:func:`validate_triad`):
    per axis, before (raw) and after (compensated), the rms over the dwells of the dwell-mean
    error against the reference the encoders give (earth rate or gravity in body axes) and,
    for gyros, the rms over the moves of the angle error accumulated during each move.

    Attributes
    ----------
    triad : str
        The triad's name.
    unit : str
        Unit of the dwell figures (°/h or mg).
    dwell_rms_before, dwell_rms_after : tuple of float
        Per-axis rms of the dwell-mean error [unit], raw and compensated.
    move_angle_rms_before_arcsec, move_angle_rms_after_arcsec : tuple of float or None
        Per-axis rms of the move-angle error [arcsec] (gyros with two dwells or more).
    n_dwells : int
        Number of dwells.
    temperature_c : tuple of float
        Lowest and highest sample temperature [°C].
    outside_range_fraction : float
        Fraction of samples outside the calibrated range (0…1).
    """

    triad: str
    unit: str
    dwell_rms_before: tuple[float, float, float]
    dwell_rms_after: tuple[float, float, float]
    move_angle_rms_before_arcsec: tuple[float, float, float] | None
    move_angle_rms_after_arcsec: tuple[float, float, float] | None
    n_dwells: int
    temperature_c: tuple[float, float]
    outside_range_fraction: float

    def to_dict(self) -> dict[str, Any]:
        """The fields as a JSON-ready dict."""
        from dataclasses import asdict

        return asdict(self)

    def rows(self) -> list[tuple[str, tuple[float, ...], tuple[float, ...]]]:
        """``(label [unit], before (x, y, z), after (x, y, z))`` for a table."""
        out: list[tuple[str, tuple[float, ...], tuple[float, ...]]] = [
            (f"dwell-mean error rms [{self.unit}]", self.dwell_rms_before, self.dwell_rms_after)
        ]
        before, after = self.move_angle_rms_before_arcsec, self.move_angle_rms_after_arcsec
        if before is not None and after is not None:
            out.append(("move-angle error rms [arcsec]", before, after))
        return out


def validate_triad(
    triad: TriadThermal,
    kind_unit: str,
    x: FloatArray,
    temp_c: FloatArray,
    reference: FloatArray,
    dwells: Sequence[Any],
    bias_to_data: float,
    dt_s: float,
    *,
    name: str,
    figure_unit_factor: float,
    figure_unit: str,
    g_term: FloatArray | None = None,
    compensate: Callable[[FloatArray, FloatArray], FloatArray] | None = None,
) -> TriadValidation:
    """Compare raw and compensated samples ``x`` (n, 3, data unit) with ``reference`` (n, 3,
    same unit; the true body rate or specific force from the encoder angles) over the
    ``dwells`` (interval indexing of :mod:`.schedule`) and, for a gyro triad, over the moves
    between them (angle = Σ rate·Δt).  Figures in ``figure_unit`` (data unit ×
    ``figure_unit_factor``: °/h or mg).

    Parameters
    ----------
    triad : TriadThermal
        The calibration to validate.
    kind_unit : str
        The data's unit (recorded by the caller; not used in the arithmetic).
    x, reference : numpy.ndarray, shape (n, 3)
        Raw samples and the encoder-derived truth [data unit].
    temp_c : numpy.ndarray, shape (n,)
        Each sample's temperature [°C].
    dwells : sequence of slice-like
        The dwells (``start``/``stop`` into the interval indexing of :mod:`.schedule`).
    bias_to_data : float
        Factor from the triad's bias unit to the data's unit.
    dt_s : float
        Sample interval [s].
    name : str
        The triad's name in the result.
    figure_unit_factor : float
        Factor from the data's unit to ``figure_unit``.
    figure_unit : str
        Unit of the dwell figures (°/h or mg).
    g_term : numpy.ndarray, shape (n, 3), optional
        A gyro's g-sensitivity term :math:`A f` [data unit], taken off before the
        compensation (the compensated samples :math:`C(x - A f)`; the raw ones as read).
    compensate : callable, optional
        ``compensate(x, temp_c)`` → the compensated samples [data unit]: the calibration's
        own correction (an accelerometer's K2,
        :meth:`thermocal.models.calibration.Triad.correct`); default :func:`correct` of
        ``triad`` with ``bias_to_data``.

    Returns
    -------
    TriadValidation

    Notes
    -----
    .. math:: e_\\mathrm{dwell} = \\sqrt{\\tfrac{1}{D}\\sum_d (\\bar x_d - \\bar r_d)^2}, \\quad
              \\Delta\\theta_\\mathrm{move} = \\sum (x - r)\\,\\Delta t

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    """
    xg = x if g_term is None else x - g_term
    xc = correct(triad, xg, temp_c, bias_to_data) if compensate is None else compensate(xg, temp_c)

    def dwell_rms(v: FloatArray) -> tuple[float, float, float]:
        errs = np.array(
            [v[1:][d.start : d.stop].mean(axis=0) - reference[1:][d.start : d.stop].mean(axis=0)
             for d in dwells]
        )  # fmt: skip
        r = np.sqrt(np.mean(errs**2, axis=0)) * figure_unit_factor
        return (float(r[0]), float(r[1]), float(r[2]))

    def move_rms(v: FloatArray) -> tuple[float, float, float]:
        errs = []
        for d0, d1 in itertools.pairwise(dwells):
            sl = slice(d0.stop, d1.start)
            errs.append(((v[1:][sl] - reference[1:][sl]) * dt_s).sum(axis=0))
        r = np.sqrt(np.mean(np.square(errs), axis=0)) * figure_unit_factor
        return (float(r[0]), float(r[1]), float(r[2]))

    moves = triad.kind == "gyro" and len(dwells) > 1
    outside = float(np.mean((temp_c < triad.t_lo_c) | (temp_c > triad.t_hi_c)))
    return TriadValidation(
        name,
        figure_unit,
        dwell_rms(x),
        dwell_rms(xc),
        move_rms(x) if moves else None,
        move_rms(xc) if moves else None,
        len(dwells),
        (float(np.min(temp_c)), float(np.max(temp_c))),
        outside,
    )
