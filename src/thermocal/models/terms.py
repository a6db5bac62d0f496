"""Regression terms of the polynomial model and the least-squares machinery behind it.

Three parts, all pure numpy/scipy:

1. **Terms** (SPEC §4a, seed 000).  A term belongs to one temperature sensor k
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
   (every lower power present, as in ``seed000`` and ``--order N``) it equals
   the span of the raw monomials.

   Term text (``--terms``): factors joined by ``*``, each ``T<k>``, ``dT<k>``
   or a parenthesised product, with an optional ``^p``; ``k`` is the 1-based
   position of the sensor in the temperature list (``--temps``).  A raw
   monomial ``T^p Ṫ^q`` is stored as ``c = min(p, q)``, ``a = p − c``,
   ``b = q − c``: ``T1*dT1`` is the coupling base variable w₁, ``(T1*dT1)^2``
   is w₁², ``T1^2*dT1`` is u₁·w₁.  A constant is always part of the model.

2. **Features**: :func:`term_features` evaluates the terms for a block of
   samples; powers are formed by repeated multiplication so that a one-sample
   block (the streaming twin) gives the same numbers as a long one.

3. **Least squares in chunks**: :func:`accumulate_r` reduces the design
   ``A = [F | Z | y]`` (F the term features, Z one indicator column per run for
   the per-run offsets, y the target) to its triangular factor ``R_aug`` chunk
   by chunk, either by a chunked Householder QR (R factors stacked and
   re-triangularised, LAPACK ``dgeqrf``) or by accumulating the Gram matrix
   ``AᵀA`` and taking its Cholesky factor (``RᵀR = AᵀA``; the same R up to
   signs).  The Gram path is used only when the column-equilibrated design is
   well conditioned (κ ≤ :data:`GRAM_MAX_COND`, so that the κ²ε loss of
   forming AᵀA stays below ~1e-6 relative); otherwise the data are passed again
   through the QR path.  :func:`solve_r` then solves the column-scaled problem
   ``min ‖R_s γ − z‖² + n α ‖γ_F‖²`` by SVD (optional ridge α, optional
   truncation of singular values below ``rcond · s_max``), and gives the
   coefficient covariance ``σ² V S⁻² Vᵀ`` (from the SVD, no inverse of AᵀA).
   Golub & Van Loan, *Matrix Computations*, 4th ed., §5.3 (least squares by QR
   and SVD), §5.3.7 (column scaling); Fukaya et al. (2014) for CholeskyQR.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
from scipy import linalg as sla
from scipy.linalg import blas, lapack

from thermocal.errors import DesignError, ThermocalInputError
from thermocal.preprocess import (  # Ṫ has one implementation, in preprocess (issue 15)
    RATE_BLOCK_ROWS as RATE_BLOCK_ROWS,
)
from thermocal.preprocess import (
    backward_partners as backward_partners,
)
from thermocal.preprocess import (
    backward_rates as backward_rates,
)
from thermocal.preprocess import (
    gap_free_slices as gap_free_slices,
)
from thermocal.preprocess import (
    segment_rates as segment_rates,
)
from thermocal.preprocess import (
    step_range as step_range,
)
from thermocal.preprocess import (
    temperature_rates as temperature_rates,
)
from thermocal.recording import FloatArray

GRAM_MAX_COND = 1.0e5
"""Largest condition number (column-equilibrated design) for which the Gram path is kept."""

SINGULAR_RCOND = 1.0e-11
"""``s_min/s_max`` below this: the design is singular → :class:`DesignError`."""

CHUNK_ROWS = 32768
"""Rows per chunk when accumulating a design."""


# --- terms ---------------------------------------------------------------------------------


@dataclass(frozen=True, order=True)
class Term:
    """One regression term ``u_k^a · v_k^b · w_k^c`` of sensor ``sensor`` (0-based), eq. (1)."""

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
        return {
            "name": self.name,
            "sensor": self.sensor,
            "t_power": self.t_power,
            "rate_power": self.rate_power,
            "coupling_power": self.coupling_power,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Term:
        return cls(
            sensor=int(d["sensor"]),
            t_power=int(d.get("t_power", 0)),
            rate_power=int(d.get("rate_power", 0)),
            coupling_power=int(d.get("coupling_power", 0)),
        )


def seed000_terms(n_sensors: int) -> list[Term]:
    """The seed-000 term set (SPEC §4a): per sensor T, T², T³, Ṫ, Ṫ², Ṫ³, TṪ, (TṪ)², (TṪ)³.

    With the implicit constant: ``9·n_sensors + 1`` coefficients (37 for 4 sensors).
    """
    out: list[Term] = []
    for k in range(n_sensors):
        out += [Term(k, t_power=p) for p in (1, 2, 3)]
        out += [Term(k, rate_power=p) for p in (1, 2, 3)]
        out += [Term(k, coupling_power=p) for p in (1, 2, 3)]
    return out


def polynomial_terms(n_sensors: int, order: int) -> list[Term]:
    """Plain polynomial in the temperatures: per sensor T, T², …, T^order (no rate terms)."""
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
                raise ThermocalInputError(
                    f"cannot read term {whole!r}: factor {f!r} is not T<k> or dT<k> "
                    "(k = position in --temps, from 1)"
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

    Raises :class:`ThermocalInputError` for cross-sensor products, unknown
    factors and sensors beyond ``n_sensors``.
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
    """Term list from a ``--terms`` value, or a plain polynomial from ``order``.

    ``spec``: ``"seed000"`` (default when both are None), a comma-separated
    string or a list of term texts.  Duplicates are an input error.
    """
    if n_sensors < 1:
        raise ThermocalInputError("the polynomial model needs at least one temperature column")
    if order is not None:
        if spec not in (None, "seed000"):
            raise ThermocalInputError("give either an explicit term list or --order, not both")
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


# --- base variables and features -------------------------------------------------------------


@dataclass(frozen=True)
class BaseScaling:
    """Centres and scales of the base variables of eq. (1), per sensor.

    ``t_center``/``t_scale`` [°C], ``rate_center``/``rate_scale`` [°C/min],
    ``coupling_center``/``coupling_scale`` [°C²/min]; arrays of length k.
    Unused base variables have centre 0 and scale 1.
    """

    t_center: FloatArray
    t_scale: FloatArray
    rate_center: FloatArray
    rate_scale: FloatArray
    coupling_center: FloatArray
    coupling_scale: FloatArray

    def to_list(self, names: Sequence[str]) -> list[dict[str, Any]]:
        return [
            {
                "name": names[k] if k < len(names) else f"T{k + 1}",
                "t_center": float(self.t_center[k]),
                "t_scale": float(self.t_scale[k]),
                "rate_center": float(self.rate_center[k]),
                "rate_scale": float(self.rate_scale[k]),
                "coupling_center": float(self.coupling_center[k]),
                "coupling_scale": float(self.coupling_scale[k]),
            }
            for k in range(self.t_center.size)
        ]

    @classmethod
    def from_list(cls, items: Sequence[dict[str, Any]]) -> BaseScaling:
        def col(key: str) -> FloatArray:
            return np.array([float(d[key]) for d in items], dtype=np.float64)

        return cls(
            col("t_center"),
            col("t_scale"),
            col("rate_center"),
            col("rate_scale"),
            col("coupling_center"),
            col("coupling_scale"),
        )


def fit_base_scaling(
    temps: Sequence[FloatArray], rates: Sequence[FloatArray] | None, terms: Sequence[Term]
) -> BaseScaling:
    """Means and standard deviations of T, Ṫ, TṪ over all runs, for the sensors the terms use.

    A base variable that the terms need but that does not vary raises
    :class:`DesignError` naming the terms.
    """
    k = temps[0].shape[1]
    tc, ts = np.zeros(k), np.ones(k)
    rc, rs = np.zeros(k), np.ones(k)
    wc, ws = np.zeros(k), np.ones(k)
    n = sum(t.shape[0] for t in temps)

    def mean_std(values: list[FloatArray]) -> tuple[float, float]:
        m = sum(float(np.sum(v)) for v in values) / n
        ss = 0.0
        for v in values:
            d = v - m
            ss += float(np.dot(d, d))
        return m, math.sqrt(ss / n)

    for j in range(k):
        used = [t for t in terms if t.sensor == j]
        for kind in ("T", "dT", "T*dT"):
            if kind == "T":
                users = [t for t in used if t.t_power > 0]
            elif kind == "dT":
                users = [t for t in used if t.rate_power > 0]
            else:
                users = [t for t in used if t.coupling_power > 0]
            if not users:
                continue
            if kind == "T":
                vals = [t[:, j] for t in temps]
            elif rates is None:
                raise ThermocalInputError("rate terms need the temperature rate")
            elif kind == "dT":
                vals = [r[:, j] for r in rates]
            else:
                vals = [t[:, j] * r[:, j] for t, r in zip(temps, rates, strict=True)]
            m, s = mean_std(vals)
            if not s > 1e-12 * max(1.0, abs(m)):
                what = {"T": f"T{j + 1}", "dT": f"dT{j + 1}"}.get(kind, f"T{j + 1}*dT{j + 1}")
                raise DesignError(
                    f"base variable {what} is constant over the fitted data, so term(s) "
                    + ", ".join(t.name for t in users)
                    + " cannot be determined; drop them or use data where it varies"
                )
            if kind == "T":
                tc[j], ts[j] = m, s
            elif kind == "dT":
                rc[j], rs[j] = m, s
            else:
                wc[j], ws[j] = m, s
    return BaseScaling(tc, ts, rc, rs, wc, ws)


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
    """
    n = temps_c.shape[0]
    if out is None:
        out = np.empty((n, len(terms)), dtype=np.float64, order="F")
    powers: dict[tuple[int, str, int], FloatArray] = {}

    def base(j: int, kind: str) -> FloatArray:
        key = (j, kind, 1)
        if key not in powers:
            T = temps_c[:, j]
            if kind == "u":
                x = (T - scaling.t_center[j]) / scaling.t_scale[j]
            else:
                if rates_c_per_min is None:
                    raise ThermocalInputError("rate terms need the temperature rate")
                R = rates_c_per_min[:, j]
                if kind == "v":
                    x = (R - scaling.rate_center[j]) / scaling.rate_scale[j]
                else:
                    x = (T * R - scaling.coupling_center[j]) / scaling.coupling_scale[j]
            powers[key] = x
        return powers[key]

    def power(j: int, kind: str, p: int, dest: FloatArray | None) -> FloatArray:
        key = (j, kind, p)
        if key in powers:
            if dest is not None:
                dest[...] = powers[key]
                return dest
            return powers[key]
        x = base(j, kind)
        if p == 1:
            if dest is not None:
                dest[...] = x
                return dest
            return x
        prev = power(j, kind, p - 1, None)
        res = np.multiply(prev, x, out=dest) if dest is not None else prev * x
        powers[key] = res
        return res

    for col, t in enumerate(terms):
        factors = [
            (kind, p)
            for kind, p in (("u", t.t_power), ("v", t.rate_power), ("w", t.coupling_power))
            if p
        ]
        dest = out[:, col]
        if len(factors) == 1:
            power(t.sensor, factors[0][0], factors[0][1], dest)
        else:
            acc = power(t.sensor, factors[0][0], factors[0][1], None)
            for kind, p in factors[1:-1]:
                acc = acc * power(t.sensor, kind, p, None)
            kind, p = factors[-1]
            np.multiply(acc, power(t.sensor, kind, p, None), out=dest)
    return out


# --- least squares in chunks ------------------------------------------------------------------

Chunk = tuple[FloatArray, int, int]
"""``(A, group, fold)`` of one block of c rows: ``A`` (c, p + 1 + t), Fortran order, holds
``[F | 1 | Y]`` (the p features, a column of ones, the t ≥ 1 targets: several channels
sharing one design, issue 15)."""


@dataclass(frozen=True)
class Reduced:
    """A design reduced to triangular form, per fold.

    ``r_aug[f]`` is the (q+t)×(q+t) upper-triangular factor of ``[F | Z | Y]``
    for fold f (q = p features + m groups, t targets, usually 1); ``n[f]`` its row count;
    ``solver`` ``"qr"`` or ``"gram"``.
    """

    r_aug: list[FloatArray]
    n: list[int]
    solver: str

    def combined(self) -> FloatArray:
        """R factor of all folds together."""
        if len(self.r_aug) == 1:
            return self.r_aug[0]
        return _triangularise(np.vstack(self.r_aug))

    @property
    def n_total(self) -> int:
        return int(sum(self.n))


def _triangularise(a: FloatArray) -> FloatArray:
    q = a.shape[1]
    if a.shape[0] == 0:
        return np.zeros((q, q))
    r = sla.qr(a, mode="r", check_finite=False)[0]
    out = np.zeros((q, q))
    m = min(r.shape[0], q)
    out[:m] = np.triu(r[:m])
    return out


def _accumulate_qr(
    chunks: Iterable[Chunk], p: int, m: int, n_folds: int, n_targets: int = 1
) -> tuple[list[list[FloatArray]], list[int]]:
    """R factors of ``[F | Z | y_j]`` per target and fold by a chunked Householder QR
    (TSQR-like): each chunk is stacked under the running R and re-triangularised (LAPACK
    ``dgeqrf``); one update per target, so each equals a one-target run."""
    q1 = p + m + 1
    r_acc = [[np.zeros((q1, q1), order="F") for _ in range(n_folds)] for _ in range(n_targets)]
    counts = [0] * n_folds
    buf: FloatArray | None = None
    for A, g, f in chunks:
        c = A.shape[0]
        if c == 0:
            continue
        rows = q1 + c
        if buf is None or buf.shape[0] != rows:
            buf = np.zeros((rows, q1), order="F")
        for j in range(n_targets):
            a = buf
            a[:q1] = r_acc[j][f]
            a[q1:, :p] = A[:, :p]
            a[q1:, p : p + m] = 0.0
            a[q1:, p + g] = 1.0
            a[q1:, p + m] = A[:, p + 1 + j]
            qr, _tau, _work, info = lapack.dgeqrf(a, lwork=max(1, q1 * 64), overwrite_a=1)
            if info != 0:
                raise DesignError(f"QR factorisation failed (LAPACK info {info})")
            r_acc[j][f] = np.asfortranarray(np.triu(qr[:q1]))
        counts[f] += c
    return [[np.ascontiguousarray(r) for r in rj] for rj in r_acc], counts


def _accumulate_gram(
    chunks: Iterable[Chunk], p: int, m: int, n_folds: int, n_targets: int = 1
) -> tuple[list[list[FloatArray]], list[int]]:
    """Gram matrices of ``[F | Z | y_j]`` per fold and target: ``[F | 1]ᵀ[F | 1]`` per
    (fold, group) once (BLAS ``dsyrk``, upper triangle), ``[F | 1]ᵀ y_j`` and ``y_jᵀ y_j``
    per target; returns ``grams[f][j]``."""
    t = n_targets
    q1 = p + m + 1
    xx = [[np.zeros((p + 1, p + 1)) for _ in range(m)] for _ in range(n_folds)]
    xy = [[np.zeros((p + 1, t)) for _ in range(m)] for _ in range(n_folds)]
    yy = [[np.zeros(t) for _ in range(m)] for _ in range(n_folds)]
    counts = [0] * n_folds
    for A, g, f in chunks:
        c = A.shape[0]
        if c == 0:
            continue
        X = np.asfortranarray(A[:, : p + 1])
        xx[f][g] += blas.dsyrk(1.0, X, trans=1, lower=0)
        for j in range(t):
            y = A[:, p + 1 + j]
            xy[f][g][:, j] += X.T @ y
            yy[f][g][j] += float(y @ y)
        counts[f] += c
    grams: list[list[FloatArray]] = []
    for f in range(n_folds):
        per_target = []
        for j in range(t):
            G = np.zeros((q1, q1))
            for g in range(m):
                P = np.triu(xx[f][g])
                P = P + np.triu(P, 1).T
                G[:p, :p] += P[:p, :p]
                G[:p, p + g] = P[:p, p]
                G[p + g, :p] = P[p, :p]
                G[p + g, p + g] = P[p, p]
                G[:p, q1 - 1] += xy[f][g][:p, j]
                G[q1 - 1, :p] += xy[f][g][:p, j]
                G[p + g, q1 - 1] = xy[f][g][p, j]
                G[q1 - 1, p + g] = xy[f][g][p, j]
                G[q1 - 1, q1 - 1] += yy[f][g][j]
            per_target.append(G)
        grams.append(per_target)
    return grams, counts


def _chol_r(G: FloatArray) -> FloatArray | None:
    """Upper Cholesky factor of an augmented Gram matrix, equilibrated; None if not PD."""
    d = np.sqrt(np.diag(G))
    if not np.all(d > 0):
        return None
    Gs = G / d[:, None] / d[None, :]
    try:
        Rs = sla.cholesky(Gs, lower=False, check_finite=False)
    except np.linalg.LinAlgError:
        return None
    R: FloatArray = Rs * d[None, :]
    return R


def accumulate_r(
    make_chunks: Callable[[], Iterator[Chunk]],
    p: int,
    m: int,
    *,
    n_folds: int = 1,
    solver: Literal["auto", "qr", "gram"] = "auto",
) -> Reduced:
    """Reduce the design ``[F | Z | y]`` to triangular factors, per fold, in chunks.

    ``make_chunks()`` yields :data:`Chunk` tuples (it is called a second time
    when the Gram path is abandoned for the QR path).  ``"auto"``: Gram path,
    kept when every fold's Cholesky succeeds and the column-equilibrated design
    has κ ≤ :data:`GRAM_MAX_COND`, else the chunked Householder QR.
    """
    return accumulate_targets(make_chunks, p, m, 1, n_folds=n_folds, solver=solver)[0]


def accumulate_targets(
    make_chunks: Callable[[], Iterator[Chunk]],
    p: int,
    m: int,
    n_targets: int,
    *,
    n_folds: int = 1,
    solver: Literal["auto", "qr", "gram"] = "auto",
) -> list[Reduced]:
    """:func:`accumulate_r` for ``n_targets`` targets sharing one design (several channels,
    issue 15): one :class:`Reduced` per target, each computed by the very operations a
    single target gets, so each equals its own one-target reduction bit for bit.

    Shared: the features of every chunk (built once by ``make_chunks``), the Gram matrix
    of ``[F | 1]`` (BLAS ``dsyrk``) and the Gram/QR decision; per target: ``[F | 1]ᵀ y`` and
    ``yᵀy`` (Gram path) or the Householder update (QR path, used for ill-conditioned
    designs).
    """
    if solver not in ("auto", "qr", "gram"):
        raise ThermocalInputError(f"unknown solver {solver!r}; use auto, qr or gram")
    if solver in ("auto", "gram"):
        grams, counts = _accumulate_gram(make_chunks(), p, m, n_folds, n_targets)
        reds: list[Reduced] = []
        for j in range(n_targets):
            rs = [_chol_r(G[j]) for G in grams]
            if not all(r is not None for r in rs):
                break
            reds.append(Reduced([r for r in rs if r is not None], counts, "gram"))
        if len(reds) == n_targets:
            cond = scaled_condition(reds[0].combined()[: p + m, : p + m])
            if solver == "gram" or cond <= GRAM_MAX_COND:
                return reds
        elif solver == "gram":
            raise DesignError(
                "the Gram matrix is not positive definite (singular design); use solver='qr' "
                "to find the terms at fault"
            )
    r_lists, counts = _accumulate_qr(make_chunks(), p, m, n_folds, n_targets)
    return [Reduced(r_list, counts, "qr") for r_list in r_lists]


def column_scales(r: FloatArray) -> FloatArray:
    """Column 2-norms of the design from its R factor (‖A e_j‖ = ‖R e_j‖)."""
    s = np.sqrt(np.sum(r * r, axis=0))
    out: FloatArray = np.where(s > 0, s, 1.0)
    return out


def scaled_condition(r: FloatArray) -> float:
    """2-norm condition number of the column-equilibrated design (from its R factor)."""
    rs = r / column_scales(r)[None, :]
    sv = np.linalg.svd(rs, compute_uv=False)
    if sv.size == 0 or sv[-1] <= 0:
        return math.inf
    return float(sv[0] / sv[-1])


@dataclass(frozen=True)
class LstsqSolution:
    """Solution of a column-scaled least-squares problem from its R factor.

    ``coef`` (q,) and ``cov`` (q, q) in the original column units; ``rss`` the
    residual sum of squares (ridge and truncation included); ``dof`` = n − rank;
    ``condition_number`` of the equilibrated design; ``rank`` singular values
    kept; ``singular_values`` of the equilibrated R (descending).
    """

    coef: FloatArray
    cov: FloatArray
    rss: float
    n: int
    dof: int
    condition_number: float
    rank: int
    n_truncated: int
    singular_values: FloatArray
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def sigma2(self) -> float:
        return self.rss / self.dof if self.dof > 0 else math.nan


def singular_error(
    r: FloatArray, names: Sequence[str], *, rcond: float = SINGULAR_RCOND
) -> DesignError | None:
    """A :class:`DesignError` naming the columns of a (near-)singular design, or None."""
    q = r.shape[1]
    if q == 0:
        return None
    rs = r / column_scales(r)[None, :]
    _u, sv, vt = np.linalg.svd(rs)
    if sv.size < q:
        sv = np.r_[sv, np.zeros(q - sv.size)]
    if sv[-1] > rcond * sv[0]:
        return None
    null = vt[-1]
    big = np.flatnonzero(np.abs(null) > 0.1 * np.max(np.abs(null)))
    involved = [names[int(i)] for i in big]
    zero_cols = [names[i] for i in range(q) if not np.any(r[:, i])]
    if zero_cols:
        return DesignError(
            "singular design: column(s) " + ", ".join(zero_cols) + " are zero over the fitted data"
        )
    return DesignError(
        "singular design (condition number "
        + (f"{sv[0] / sv[-1]:.3g}" if sv[-1] > 0 else "∞")
        + "): these terms are linearly dependent in the data: "
        + ", ".join(involved)
        + "; drop one of them or add data that separates them"
    )


def solve_r(
    r_aug: FloatArray,
    n: int,
    names: Sequence[str],
    *,
    penalised: npt.NDArray[np.bool_] | None = None,
    ridge: float = 0.0,
    rcond: float | None = None,
    noise_threshold: float | None = None,
    columns: Sequence[int] | None = None,
) -> LstsqSolution:
    """Least squares from the augmented R factor of ``[A | y]``, columns equilibrated.

    The columns are scaled to unit RMS (``A_s = A D``) and split into the free
    ones (U: constant, per-run offsets) and the regularised ones (P: the
    ``penalised`` terms).  A QR of ``[A_s,U  A_s,P | y]`` (from R, never from
    the data again) gives ``R11, R12, R22, z1, z2``; the P part is solved by SVD,
    ``R22 = U S Vᵀ``, ``c = Uᵀ z2``::

        γ_P = Σ_{kept i} v_i c_i s_i/(s_i² + nα),     γ_U = R11⁻¹ (z1 − R12 γ_P)

    (ridge α ≥ 0 shrinks only the P coefficients; Golub & Van Loan §6.1.4).
    Component i is kept when ``s_i > rcond · s_max`` (truncated SVD) or, with
    ``noise_threshold`` k, when ``|c_i| > k σ̂`` — its share of the data stands
    out of the noise (σ̂² = RSS/(n − q) of the full fit; a discrete Picard
    rule, Hansen, *Rank-Deficient and Discrete Ill-Posed Problems*, SIAM 1998,
    §3.2).  ``β = D γ``; ``cov(β) = σ² D L Lᵀ D`` with L
    the linear map from ``[z1; z2]`` to γ (triangular solves, no inverse of
    AᵀA).  Residuals are assumed white; with coloured noise the standard
    errors are optimistic.  A design with ``s_min < 1e-11 s_max`` raises
    :class:`DesignError` naming the dependent columns.  ``columns`` restricts
    the problem to a subset (in that order).
    """
    q = r_aug.shape[1] - 1
    cols = list(range(q)) if columns is None else list(columns)
    pen_all = np.zeros(q, dtype=bool) if penalised is None else np.asarray(penalised, dtype=bool)
    if ridge < 0:
        raise ThermocalInputError(f"ridge α must be ≥ 0, got {ridge}")
    err = singular_error(r_aug[:, cols], [names[i] for i in cols])
    if err is not None:
        raise err
    free = [c for c in cols if not pen_all[c]]
    reg = [c for c in cols if pen_all[c]]
    order = free + reg
    R = r_aug[:, order]
    scale = column_scales(R) / math.sqrt(max(n, 1))  # RMS of each column
    Rs = R / scale[None, :]
    cond = scaled_condition(R)
    qq = len(order)
    nu = len(free)
    A2 = _triangularise(np.column_stack([Rs, r_aug[:, q]]))
    R11 = A2[:nu, :nu]
    R12 = A2[:nu, nu:qq]
    R22 = A2[nu:qq, nu:qq]
    z1 = A2[:nu, qq]
    z2 = A2[nu:qq, qq]
    rss0 = float(A2[qq, qq] ** 2) if A2.shape[0] > qq else 0.0
    np_ = qq - nu
    dof_full = n - qq
    sigma_full = math.sqrt(rss0 / dof_full) if dof_full > 0 else math.nan
    H = np.zeros((np_, np_))
    keep = np.zeros(np_, dtype=bool)
    sv = np.zeros(0)
    if np_:
        U, S, Vt = np.linalg.svd(R22)
        sv = S
        c = U.T @ z2
        keep = np.greater(S, (rcond or 0.0) * S[0])
        if noise_threshold is not None and math.isfinite(sigma_full):
            # a small-s_i component stays when the data along it stand out of the noise
            strong = np.abs(c) > noise_threshold * sigma_full
            keep |= strong & np.greater(S, SINGULAR_RCOND * S[0])
        f = np.zeros_like(S)
        f[keep] = S[keep] / (S[keep] ** 2 + n * ridge)
        H = (Vt.T * f) @ U.T  # γ_P = H z2
    gamma_p = H @ z2
    if nu:
        Linv_u = sla.solve_triangular(R11, np.eye(nu), lower=False)
        gamma_u = Linv_u @ (z1 - R12 @ gamma_p)
        Lmap = np.zeros((qq, qq))
        Lmap[:nu, :nu] = Linv_u
        Lmap[:nu, nu:] = -Linv_u @ R12 @ H
        Lmap[nu:, nu:] = H
    else:
        gamma_u = np.zeros(0)
        Lmap = H
    gamma = np.r_[gamma_u, gamma_p]
    res2 = z2 - R22 @ gamma_p
    rss = rss0 + float(res2 @ res2)
    rank = nu + int(keep.sum())
    dof = n - rank
    sigma2 = rss / dof if dof > 0 else math.nan
    cov_g = sigma2 * (Lmap @ Lmap.T)
    coef_o = gamma / scale
    cov_o = cov_g / scale[:, None] / scale[None, :]
    # back to the order of ``cols``
    pos = [order.index(c) for c in cols]
    coef = coef_o[pos]
    cov = cov_o[np.ix_(pos, pos)]
    return LstsqSolution(
        coef=coef,
        cov=cov,
        rss=rss,
        n=n,
        dof=dof,
        condition_number=cond,
        rank=rank,
        n_truncated=int((~keep).sum()),
        singular_values=np.asarray(sv, dtype=np.float64),
        extra={"sigma_full": sigma_full},
    )


def subset_rss(r_aug: FloatArray, columns: Sequence[int]) -> tuple[float, FloatArray]:
    """RSS and coefficients of the least-squares fit on a column subset, from R_aug.

    ``‖y − A_S β‖² = ‖r_y − R_S β‖²`` where ``r_y`` is the last column of
    ``R_aug`` (Q orthogonal); solved by lstsq on the small matrix.
    """
    q = r_aug.shape[1] - 1
    R = r_aug[:, list(columns)]
    z = r_aug[:, q]
    beta, _res, _rank, _sv = np.linalg.lstsq(R, z, rcond=None)
    res = z - R @ beta
    return float(res @ res), np.asarray(beta, dtype=np.float64)


def holdout_rss(r_aug_hold: FloatArray, columns: Sequence[int], beta: FloatArray) -> float:
    """``‖y_h − A_h,S β‖²`` of a held-out fold from its R factor."""
    q = r_aug_hold.shape[1] - 1
    res = r_aug_hold[:, q] - r_aug_hold[:, list(columns)] @ beta
    return float(res @ res)


@dataclass(frozen=True)
class Selection:
    """Result of forward stepwise selection: kept columns in the order added, and the path."""

    kept: list[int]
    path: list[dict[str, Any]]
    method: str


def forward_select(
    red: Reduced,
    candidates: Sequence[int],
    required: Sequence[int],
    names: Sequence[str],
    method: Literal["bic", "holdout"] = "bic",
) -> Selection:
    """Forward stepwise term selection (SPEC §4a: by information criterion or validation error).

    Starting from the ``required`` columns (constant / per-run offsets), add at
    each step the candidate that lowers the score most; stop when none lowers
    it.  ``"bic"``: ``n ln(RSS/n) + k ln n`` on all data (Schwarz 1978,
    doi:10.1214/aos/1176344136); ``"holdout"``: RSS on fold 1 of a fit on fold 0
    (blocked hold-out; ``red`` must have two folds).
    """
    kept: list[int] = list(required)
    remaining = [c for c in candidates if c not in kept]
    path: list[dict[str, Any]] = []
    if method == "bic":
        R = red.combined()
        n = red.n_total

        def score(cols: list[int]) -> float:
            rss, _ = subset_rss(R, cols)
            return n * math.log(max(rss, 1e-300) / n) + len(cols) * math.log(n)

    elif method == "holdout":
        if len(red.r_aug) != 2:
            raise ThermocalInputError("hold-out selection needs two folds")
        Rt, Rh = red.r_aug

        def score(cols: list[int]) -> float:
            _rss, beta = subset_rss(Rt, cols)
            return holdout_rss(Rh, cols, beta)

    else:
        raise ThermocalInputError(f"unknown selection method {method!r}; use bic or holdout")
    current = score(kept)
    path.append({"added": None, "score": current})
    while remaining:
        trials = [(score([*kept, c]), c) for c in remaining]
        best, c = min(trials)
        if not best < current:
            break
        kept.append(c)
        remaining.remove(c)
        current = best
        path.append({"added": names[c], "score": best})
    return Selection(kept=kept, path=path, method=method)


def raw_expansion(
    terms: Sequence[Term], scaling: BaseScaling
) -> tuple[list[tuple[int, int, int]], FloatArray]:
    """Map scaled-basis term coefficients to raw-monomial coefficients.

    Expands ``u^a v^b w^c`` (eq. 1) binomially into monomials ``T^P Ṫ^Q``
    (``P = i + l``, ``Q = j + l`` for ``T^i Ṫ^j (TṪ)^l``).  Returns the list of
    monomials ``(sensor, P, Q)`` (``(-1, 0, 0)`` = constant, first) and the
    matrix M with ``raw = M @ [constant, term coefficients...]``.
    """
    keys: list[tuple[int, int, int]] = [(-1, 0, 0)]
    index: dict[tuple[int, int, int], int] = {(-1, 0, 0): 0}
    cols: list[dict[int, float]] = [{0: 1.0}]
    for t in terms:
        k = t.sensor

        def expand(power: int, center: float, scale: float) -> list[tuple[int, float]]:
            # ((x − c)/s)^p = Σ_i C(p,i) x^i (−c)^(p−i) / s^p
            return [
                (i, math.comb(power, i) * (-center) ** (power - i) / scale**power)
                for i in range(power + 1)
            ]

        eu = expand(t.t_power, float(scaling.t_center[k]), float(scaling.t_scale[k]))
        ev = expand(t.rate_power, float(scaling.rate_center[k]), float(scaling.rate_scale[k]))
        ew = expand(
            t.coupling_power, float(scaling.coupling_center[k]), float(scaling.coupling_scale[k])
        )
        col: dict[int, float] = {}
        for i, cu in eu:
            for j, cv in ev:
                for l, cw in ew:
                    P, Q = i + l, j + l
                    key = (-1, 0, 0) if P == 0 and Q == 0 else (k, P, Q)
                    if key not in index:
                        index[key] = len(keys)
                        keys.append(key)
                    col[index[key]] = col.get(index[key], 0.0) + cu * cv * cw
        cols.append(col)
    M = np.zeros((len(keys), len(cols)))
    for jc, col in enumerate(cols):
        for i, v in col.items():
            M[i, jc] = v
    return keys, M


def monomial_name(key: tuple[int, int, int]) -> str:
    """Name of a raw monomial ``T_k^P Ṫ_k^Q``: ``const``, ``T1^2``, ``(T1*dT1)^2``, ``T1^2*dT1``."""
    k, P, Q = key
    if k < 0:
        return "const"
    s = k + 1
    if P == Q:
        return f"T{s}*dT{s}" if P == 1 else f"(T{s}*dT{s})^{P}"
    parts = []
    if P:
        parts.append(f"T{s}" if P == 1 else f"T{s}^{P}")
    if Q:
        parts.append(f"dT{s}" if Q == 1 else f"dT{s}^{Q}")
    return "*".join(parts)
