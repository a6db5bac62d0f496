"""Regression terms of the polynomial model and the least-squares machinery behind it.

Three parts, all pure numpy/scipy:

1. **Terms** ([Seed-RLG]).  A term belongs to one temperature sensor k
   and is the product of powers of three *base variables* of that sensor,

   .. math::

       u_k = (T_k - c^T_k)/s^T_k, \\quad
       v_k = (\\dot T_k - c^R_k)/s^R_k, \\quad
       w_k = (T_k \\dot T_k - c^W_k)/s^W_k,                          (1)

   ``term = u^a · v^b · w^c`` (``a`` = ``t_power``, ``b`` = ``rate_power``,
   ``c`` = ``coupling_power``), with T [°C], Ṫ [°C/min], centres ``c`` the
   means and scales ``s`` the standard deviations over the fitted data.  The
   seed's 37-term set ``seed000`` is, per sensor, u, u², u³, v, v², v³, w, w², w³
   plus a constant; its span equals that of the raw monomials T, T², T³, Ṫ, Ṫ²,
   Ṫ³, TṪ, (TṪ)², (TṪ)³ and 1 (each base variable is an affine map of the raw
   one), but the design is far better conditioned.  In general the span of a
   term list is the span of its centred monomials; for hierarchical lists
   (every lower power present, as in ``seed000`` and ``order=N``) it equals
   the span of the raw monomials.

   Term text (``terms``): factors joined by ``*``, each ``T<k>``, ``dT<k>``
   or a parenthesised product, with an optional ``^p``; ``k`` is the 1-based
   position of the sensor in the temperature list (``temperatures``).  A raw
   monomial ``T^p Ṫ^q`` is stored as ``c = min(p, q)``, ``a = p − c``,
   ``b = q − c``: ``T1*dT1`` is the coupling base variable w₁, ``(T1*dT1)^2``
   is w₁², ``T1^2*dT1`` is u₁·w₁.  A constant is always part of the model.

   The base variables' centres and scales (:class:`~thermocal.models.term_scaling.BaseScaling`)
   and the expansion into raw monomials are in :mod:`thermocal.models.term_scaling`.

2. **Features**: :func:`term_features` evaluates the terms for a block of
   samples; powers are formed by repeated multiplication so that a one-sample
   block (the streaming twin) gives the same numbers as a long one.

3. **Least squares in chunks** (:mod:`thermocal.models.reduction` and
   :mod:`thermocal.models.lstsq`, used with the terms):
   :func:`~thermocal.models.reduction.accumulate_r` reduces the design
   ``A = [F | Z | y]`` (F the term features, Z one indicator column per run for
   the per-run offsets, y the target) to its triangular factor ``R_aug`` chunk
   by chunk, either by a chunked Householder QR (R factors stacked and
   re-triangularised, LAPACK ``dgeqrf``) or by accumulating the Gram matrix
   ``AᵀA`` and taking its Cholesky factor (``RᵀR = AᵀA``; the same R up to
   signs).  The Gram path is used only when the column-equilibrated design is
   well conditioned (κ ≤ :data:`~thermocal.models.reduction.GRAM_MAX_COND`, so that the κ²ε loss of
   forming AᵀA stays below ~1e-6 relative); otherwise the data are passed again
   through the QR path.  :func:`~thermocal.models.lstsq.solve_r` then solves the
   column-scaled problem ``min ‖R_s γ − z‖² + n α ‖γ_F‖²`` by SVD (optional ridge α, optional
   truncation of singular values below ``rcond · s_max``), and gives the
   coefficient covariance ``σ² V S⁻² Vᵀ`` (from the SVD, no inverse of AᵀA).
   Golub & Van Loan, *Matrix Computations*, 4th ed., §5.3 (least squares by QR
   and SVD), §5.3.7 (column scaling); Fukaya et al. (2014) for CholeskyQR.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermocal.errors import ThermocalInputError
from thermocal.models.term_scaling import BaseScaling
from thermocal.recording import FloatArray

CHUNK_ROWS = 32768
"""Rows per chunk when accumulating a design."""


# --- terms ---------------------------------------------------------------------------------


@dataclass(frozen=True, order=True)
class Term:
    """One regression term ``u_k^a · v_k^b · w_k^c`` of sensor ``sensor`` (0-based), eq. (1).

    Attributes
    ----------
    sensor : int
        0-based index of the temperature sensor k.
    t_power : int
        Power a of the scaled temperature u (default 0).
    rate_power : int
        Power b of the scaled rate v (default 0).
    coupling_power : int
        Power c of the scaled coupling w = TṪ (default 0).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A negative power or sensor, or all powers zero (the constant is implicit).

    Notes
    -----
    .. math:: \\mathrm{term} = u_k^a\\, v_k^b\\, w_k^c

    References
    ----------
    - *A modelling and validation method for the temperature compensation model of a
      ring-laser gyroscope*, Chinese invention patent, published 2017.
    """

    sensor: int
    t_power: int = 0
    rate_power: int = 0
    coupling_power: int = 0

    def __post_init__(self) -> None:
        if min(self.t_power, self.rate_power, self.coupling_power) < 0 or self.sensor < 0:
            raise ThermocalInputError(f"invalid term {self!r}")
        if self.t_power + self.rate_power + self.coupling_power == 0:
            raise ThermocalInputError(
                "a term must have a positive power (the constant is implicit)"
            )

    @property
    def uses_rate(self) -> bool:
        """True when the term needs Ṫ (a rate or coupling power)."""
        return self.rate_power > 0 or self.coupling_power > 0

    @property
    def degree(self) -> int:
        """Total degree in the raw variables T and Ṫ."""
        return self.t_power + self.rate_power + 2 * self.coupling_power

    @property
    def name(self) -> str:
        """Canonical text, e.g. ``T1``, ``T1^2``, ``dT1^3``, ``T1*dT1``, ``(T1*dT1)^2``."""
        k = self.sensor + 1

        def pw(base: str, p: int) -> str:
            return base if p == 1 else f"{base}^{p}"

        parts: list[str] = []
        if self.t_power:
            parts.append(pw(f"T{k}", self.t_power))
        if self.rate_power:
            parts.append(pw(f"dT{k}", self.rate_power))
        if self.coupling_power:
            if self.coupling_power == 1 and not parts:
                parts.append(f"T{k}*dT{k}")
            else:
                parts.append(pw(f"(T{k}*dT{k})", self.coupling_power))
        return "*".join(parts)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: name, sensor and the three powers."""
        return {
            "name": self.name,
            "sensor": self.sensor,
            "t_power": self.t_power,
            "rate_power": self.rate_power,
            "coupling_power": self.coupling_power,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Term:
        """Inverse of :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            ``sensor``, ``t_power``, ``rate_power``, ``coupling_power``.

        Returns
        -------
        Term
        """
        return cls(
            sensor=int(d["sensor"]),
            t_power=int(d.get("t_power", 0)),
            rate_power=int(d.get("rate_power", 0)),
            coupling_power=int(d.get("coupling_power", 0)),
        )


def seed000_terms(n_sensors: int) -> list[Term]:
    """The term set ([Seed-RLG]): per sensor T, T², T³, Ṫ, Ṫ², Ṫ³, TṪ, (TṪ)², (TṪ)³.

    With the implicit constant: ``9·n_sensors + 1`` coefficients (37 for 4 sensors).

    Parameters
    ----------
    n_sensors : int
        Number of temperature sensors k.

    Returns
    -------
    list of Term
        ``9·n_sensors`` terms.

    References
    ----------
    - *A modelling and validation method for the temperature compensation model of a
      ring-laser gyroscope*, Chinese invention patent, published 2017.

    Examples
    --------
    >>> len(seed000_terms(4)) + 1
    37
    """
    out: list[Term] = []
    for k in range(n_sensors):
        out += [Term(k, t_power=p) for p in (1, 2, 3)]
        out += [Term(k, rate_power=p) for p in (1, 2, 3)]
        out += [Term(k, coupling_power=p) for p in (1, 2, 3)]
    return out


def polynomial_terms(n_sensors: int, order: int) -> list[Term]:
    """Plain polynomial in the temperatures: per sensor T, T², …, T^order (no rate terms).

    Parameters
    ----------
    n_sensors : int
        Number of temperature sensors.
    order : int
        Polynomial order (≥ 1).

    Returns
    -------
    list of Term

    Raises
    ------
    thermocal.errors.ThermocalInputError
        ``order`` below 1.

    Examples
    --------
    >>> [t.name for t in polynomial_terms(2, 2)]
    ['T1', 'T1^2', 'T2', 'T2^2']
    """
    if order < 1:
        raise ThermocalInputError(f"polynomial order must be ≥ 1, got {order}")
    return [Term(k, t_power=p) for k in range(n_sensors) for p in range(1, order + 1)]


_ATOM = re.compile(r"^(d?)T(\d+)$")


def _split_top(text: str) -> list[str]:
    parts: list[str] = []
    depth = 0
    cur = ""
    for ch in text:
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
            if depth < 0:
                raise ThermocalInputError(f"unbalanced parentheses in term {text!r}")
        if ch == "*" and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    if depth != 0:
        raise ThermocalInputError(f"unbalanced parentheses in term {text!r}")
    parts.append(cur)
    return parts


def _parse_monomial(text: str, whole: str) -> dict[tuple[int, str], int]:
    """Raw exponents {(sensor, 'T'|'dT'): power} of a product text."""
    out: dict[tuple[int, str], int] = {}
    for raw in _split_top(text):
        f = raw.strip()
        if not f:
            raise ThermocalInputError(f"empty factor in term {whole!r}")
        power = 1
        m = re.match(r"^(.*)\^\s*(\d+)$", f)
        if m:
            f, power = m.group(1).strip(), int(m.group(2))
        if f.startswith("(") and f.endswith(")"):
            inner = _parse_monomial(f[1:-1], whole)
        else:
            a = _ATOM.match(f)
            if a is None:
                if f in ("1", "const") and power == 1:
                    continue
                raise ThermocalInputError.naming(
                    f"cannot read term {whole!r}: factor {f!r} is not "
                    "T<k> or dT<k> (k = position in {temperatures}, from 1)",
                    "temperatures",
                )
            sensor = int(a.group(2)) - 1
            if sensor < 0:
                raise ThermocalInputError(f"term {whole!r}: sensors are numbered from 1")
            inner = {(sensor, "dT" if a.group(1) else "T"): 1}
        for key, p in inner.items():
            out[key] = out.get(key, 0) + p * power
    return out


def parse_term(text: str, n_sensors: int) -> Term | None:
    """Read one term (``"T1^2"``, ``"dT2"``, ``"T1*dT1"``, ``"(T3*dT3)^2"``); None for a constant.

    Parameters
    ----------
    text : str
        The term's text.
    n_sensors : int
        Number of temperature sensors (``T<k>`` must have k ≤ n_sensors).

    Returns
    -------
    Term or None
        The term; None for a constant.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Cross-sensor products, unknown factors and sensors beyond ``n_sensors``.

    Examples
    --------
    >>> parse_term("T1*dT1", 1)
    Term(sensor=0, t_power=0, rate_power=0, coupling_power=1)
    """
    whole = text.strip()
    exps = _parse_monomial(whole, whole)
    exps = {k: v for k, v in exps.items() if v}
    if not exps:
        return None
    sensors = {k[0] for k in exps}
    if len(sensors) > 1:
        raise ThermocalInputError(
            f"term {whole!r} mixes sensors {sorted(s + 1 for s in sensors)}; "
            "cross-sensor products are not supported"
        )
    sensor = sensors.pop()
    if sensor >= n_sensors:
        raise ThermocalInputError(
            f"term {whole!r} refers to sensor T{sensor + 1}, but only {n_sensors} "
            "temperature column(s) are given"
        )
    p = exps.get((sensor, "T"), 0)
    q = exps.get((sensor, "dT"), 0)
    c = min(p, q)
    return Term(sensor, t_power=p - c, rate_power=q - c, coupling_power=c)


def parse_terms(
    spec: str | Sequence[str] | None, n_sensors: int, order: int | None = None
) -> list[Term]:
    """Term list from a ``terms`` value (text or list), or a plain polynomial from ``order``.

    Parameters
    ----------
    spec : str or sequence of str or None
        ``"seed000"`` (default when both are None), a comma-separated string or a list of
        term texts.
    n_sensors : int
        Number of temperature sensors.
    order : int, optional
        Order of a plain polynomial (:func:`polynomial_terms`) when ``spec`` is None.

    Returns
    -------
    list of Term

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A duplicate or unreadable term.

    Examples
    --------
    >>> [t.name for t in parse_terms("T1,T1^2,dT1,(T1*dT1)^2", 1)]
    ['T1', 'T1^2', 'dT1', '(T1*dT1)^2']
    """
    if n_sensors < 1:
        raise ThermocalInputError("the polynomial model needs at least one temperature column")
    if order is not None:
        if spec not in (None, "seed000"):
            raise ThermocalInputError.naming(
                "give either an explicit term list or {order}, not both", "order"
            )
        return polynomial_terms(n_sensors, int(order))
    if spec is None or (isinstance(spec, str) and spec.strip() == "seed000"):
        return seed000_terms(n_sensors)
    texts = spec.split(",") if isinstance(spec, str) else list(spec)
    terms: list[Term] = []
    for t in texts:
        if not t.strip():
            continue
        term = parse_term(t, n_sensors)
        if term is None:
            continue
        if term in terms:
            raise ThermocalInputError(f"term {t.strip()!r} ({term.name}) is listed twice")
        terms.append(term)
    if not terms:
        raise ThermocalInputError("the term list is empty (the constant alone is not a model)")
    return terms


# --- features ----------------------------------------------------------------------------


class _Powers:
    """The scaled bases (u, v, w of each temperature) of one block and their powers, each
    made once (a plain object, no closure: nothing keeps the block alive after it)."""

    def __init__(
        self, scaling: BaseScaling, temps_c: FloatArray, rates_c_per_min: FloatArray | None
    ) -> None:
        self.scaling, self.temps_c, self.rates = scaling, temps_c, rates_c_per_min
        self.made: dict[tuple[int, str, int], FloatArray] = {}

    def base(self, j: int, kind: str) -> FloatArray:
        """The scaled u (T), v (Ṫ) or w (T·Ṫ) of temperature ``j``."""
        key = (j, kind, 1)
        if key not in self.made:
            sc, T = self.scaling, self.temps_c[:, j]
            if kind == "u":
                x = (T - sc.t_center[j]) / sc.t_scale[j]
            else:
                if self.rates is None:
                    raise ThermocalInputError("rate terms need the temperature rate")
                R = self.rates[:, j]
                if kind == "v":
                    x = (R - sc.rate_center[j]) / sc.rate_scale[j]
                else:
                    x = (T * R - sc.coupling_center[j]) / sc.coupling_scale[j]
            self.made[key] = x
        return self.made[key]

    def power(self, j: int, kind: str, p: int, dest: FloatArray | None) -> FloatArray:
        """``base(j, kind)**p`` by repeated products from the highest power at hand, written
        into ``dest`` when given."""
        key = (j, kind, p)
        if key in self.made:
            if dest is not None:
                dest[...] = self.made[key]
                return dest
            return self.made[key]
        x = self.base(j, kind)
        if p == 1:
            if dest is not None:
                dest[...] = x
                return dest
            return x
        q = max(r for r in range(1, p) if (j, kind, r) in self.made)
        res = self.made[(j, kind, q)]
        for r in range(q + 1, p + 1):
            res = np.multiply(res, x, out=dest) if r == p and dest is not None else res * x
            self.made[(j, kind, r)] = res
        return res


def term_features(
    terms: Sequence[Term],
    scaling: BaseScaling,
    temps_c: FloatArray,
    rates_c_per_min: FloatArray | None,
    out: FloatArray | None = None,
) -> FloatArray:
    """Evaluate the terms (eq. 1) for a block of samples: returns (n, n_terms).

    ``temps_c`` (n, k) [°C], ``rates_c_per_min`` (n, k) [°C/min] (needed when a
    term uses Ṫ).  ``out`` may be a preallocated (n, n_terms) array (Fortran
    order is fastest).  Powers are built by repeated multiplication
    (``x³ = x²·x``), the same arithmetic for any block length.

    Parameters
    ----------
    terms : sequence of Term
        The terms.
    scaling : BaseScaling
        Centres and scales (:func:`fit_base_scaling`).
    temps_c : numpy.ndarray
        Temperatures (n, k) [°C].
    rates_c_per_min : numpy.ndarray or None
        Ṫ (n, k) [°C/min], needed when a term uses Ṫ.
    out : numpy.ndarray, optional
        Preallocated (n, n_terms) result.

    Returns
    -------
    numpy.ndarray
        The design columns, shape (n, n_terms) (dimensionless).

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.models.term_scaling import fit_base_scaling
    >>> temps = 20.0 + 10.0 * np.random.default_rng(0).random((50, 1))
    >>> terms = parse_terms("T1,T1^2", 1)
    >>> features = term_features(terms, fit_base_scaling([temps], None, terms), temps, None)
    >>> features.shape, np.round(features.mean(axis=0), 6).tolist()
    ((50, 2), [0.0, 1.0])
    """
    n = temps_c.shape[0]
    if out is None:
        out = np.empty((n, len(terms)), dtype=np.float64, order="F")
    powers = _Powers(scaling, temps_c, rates_c_per_min)
    for col, t in enumerate(terms):
        factors = [
            (kind, p)
            for kind, p in (("u", t.t_power), ("v", t.rate_power), ("w", t.coupling_power))
            if p
        ]
        dest = out[:, col]
        if len(factors) == 1:
            powers.power(t.sensor, factors[0][0], factors[0][1], dest)
        else:
            acc = powers.power(t.sensor, factors[0][0], factors[0][1], None)
            for kind, p in factors[1:-1]:
                acc = acc * powers.power(t.sensor, kind, p, None)
            kind, p = factors[-1]
            np.multiply(acc, powers.power(t.sensor, kind, p, None), out=dest)
    return out
