"""The base variables of the polynomial model's terms ([Seed-RLG]): their centres and scales
(:class:`BaseScaling`, fitted by :func:`fit_base_scaling`), and the expansion of a scaled
term polynomial into raw monomials ``T^P Ṫ^Q`` (:func:`raw_expansion`, named by
:func:`monomial_name`) for the model file and the firmware.

The terms themselves, their text and their features are in :mod:`thermocal.models.terms`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal.errors import DesignError, ThermocalInputError
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from thermocal.models.terms import Term


@dataclass(frozen=True)
class BaseScaling:
    """Centres and scales of the base variables of eq. (1), per sensor.

    Unused base variables have centre 0 and scale 1.

    Attributes
    ----------
    t_center, t_scale : numpy.ndarray
        Centre and scale of T per sensor, shape (k,) [°C].
    rate_center, rate_scale : numpy.ndarray
        Centre and scale of Ṫ per sensor, shape (k,) [°C/min].
    coupling_center, coupling_scale : numpy.ndarray
        Centre and scale of TṪ per sensor, shape (k,) [°C²/min].
    """

    t_center: FloatArray
    t_scale: FloatArray
    rate_center: FloatArray
    rate_scale: FloatArray
    coupling_center: FloatArray
    coupling_scale: FloatArray

    def to_list(self, names: Sequence[str]) -> list[dict[str, Any]]:
        """One JSON-ready dict per sensor.

        Parameters
        ----------
        names : sequence of str
            The sensors' column names.

        Returns
        -------
        list of dict
        """
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
        """Inverse of :meth:`to_list`.

        Parameters
        ----------
        items : sequence of dict
            One dict per sensor.

        Returns
        -------
        BaseScaling
        """

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

    Parameters
    ----------
    temps : sequence of numpy.ndarray
        Temperatures per run, each (n_r, k) [°C].
    rates : sequence of numpy.ndarray or None
        Ṫ per run, each (n_r, k) [°C/min]; needed when a term uses Ṫ.
    terms : sequence of Term
        The model's terms.

    Returns
    -------
    BaseScaling

    Raises
    ------
    thermocal.errors.DesignError
        A base variable the terms need does not vary, naming the terms.

    Notes
    -----
    .. math:: c = \\frac{1}{N}\\sum_i x_i, \\qquad s = \\sqrt{\\frac{1}{N}\\sum_i (x_i - c)^2}
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


def raw_expansion(
    terms: Sequence[Term], scaling: BaseScaling
) -> tuple[list[tuple[int, int, int]], FloatArray]:
    """Map scaled-basis term coefficients to raw-monomial coefficients.

    Expands ``u^a v^b w^c`` (eq. 1) binomially into monomials ``T^P Ṫ^Q``
    (``P = i + l``, ``Q = j + l`` for ``T^i Ṫ^j (TṪ)^l``).  Returns the list of
    monomials ``(sensor, P, Q)`` (``(-1, 0, 0)`` = constant, first) and the
    matrix M with ``raw = M @ [constant, term coefficients...]``.

    Parameters
    ----------
    terms : sequence of Term
        The terms.
    scaling : BaseScaling
        Their centres and scales.

    Returns
    -------
    monomials : list of tuple of int
        ``(sensor, P, Q)`` per raw monomial, the constant ``(-1, 0, 0)`` first.
    M : numpy.ndarray
        Shape (n_monomials, 1 + n_terms).

    Notes
    -----
    .. math:: \\left(\\frac{x - c}{s}\\right)^p
              = \\sum_{i=0}^{p} \\binom{p}{i} \\frac{x^i (-c)^{p-i}}{s^p}
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
    """Name of a raw monomial ``T_k^P Ṫ_k^Q``: ``const``, ``T1^2``, ``(T1*dT1)^2``, ``T1^2*dT1``.

    Parameters
    ----------
    key : tuple of int
        ``(sensor, P, Q)``; sensor −1 is the constant.

    Returns
    -------
    str

    Examples
    --------
    >>> monomial_name((-1, 0, 0)), monomial_name((0, 2, 1))
    ('const', 'T1^2*dT1')
    """
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
