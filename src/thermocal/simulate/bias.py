"""The temperature-induced bias of a simulated sensor: polynomial, piecewise,
warm-up and hysteresis terms.

Part of :mod:`thermocal.simulate`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import ThermocalInputError

FloatArray = npt.NDArray[np.float64]
ProgramArrays = tuple[FloatArray, FloatArray]
Truth = dict[str, Any]


# --- bias model ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class PiecewiseTerm:
    """Continuous piecewise-linear bias in ``T_sensor`` (*Design and engineering implementation
    of a fibre-optic-gyro line-of-sight stabilisation system*), zero at ``t_ref``.

    ``b(T) = s_0 (T − T_ref) + Σ_j (s_{j+1} − s_j) w ln(1 + e^{(T − c_j)/w})`` − its
    value at T_ref: slopes ``slopes`` [unit/°C] between breakpoints ``breakpoints_c``,
    corners rounded over ``smoothing_c`` = w [°C] (softplus).

    Attributes
    ----------
    sensor : int
        Index of the temperature sensor ``T_sensor`` the term depends on.
    breakpoints_c : tuple of float
        Breakpoints c_j [°C], increasing.
    slopes : tuple of float
        Slopes s_0 … s_n [unit/°C] on either side of the breakpoints (one more than them).
    smoothing_c : float
        Corner width w [°C] of the softplus rounding.
    """

    sensor: int
    breakpoints_c: tuple[float, ...]
    slopes: tuple[float, ...]
    smoothing_c: float = 0.2

    def __call__(self, temp: FloatArray, t_ref: float) -> FloatArray:
        if len(self.slopes) != len(self.breakpoints_c) + 1:
            raise ThermocalInputError("piecewise term: one slope more than breakpoints")
        w = self.smoothing_c

        def f(x: FloatArray) -> FloatArray:
            out = self.slopes[0] * x
            for c, s0, s1 in zip(
                self.breakpoints_c, self.slopes[:-1], self.slopes[1:], strict=True
            ):
                z = (x + t_ref - c) / w
                out = out + (s1 - s0) * w * np.logaddexp(0.0, z)
            return np.asarray(out, dtype=np.float64)

        out: FloatArray = f(temp - t_ref) - f(np.zeros(1))[0]
        return out


@dataclass(frozen=True)
class WarmupTerm:
    """Warm-up bias (*Temperature-characteristic calibration test plan*): ``Σ_{j≥1} a_j(T0)
    ΔT^j``, ``ΔT = T − T0``,
    ``a_j(T0) = b_j0 + b_j1 T0 + b_j2 T0²``; ``coefficients[j−1] = (b_j0, b_j1, b_j2)``;
    ``start`` = ``(c0, c1, c2)`` gives the power-on bias ``c0 + c1 T0 + c2 T0²``.
    T0 is the sensor temperature at power-on [°C].

    Attributes
    ----------
    sensor : int
        Index of the temperature sensor whose rise ΔT drives the term.
    coefficients : tuple of (float, float, float)
        ``(b_j0, b_j1, b_j2)`` of each power j ≥ 1 [unit/°C^j, unit/°C^(j+1), unit/°C^(j+2)].
    start : (float, float, float)
        ``(c0, c1, c2)`` of the power-on bias [unit, unit/°C, unit/°C²].
    """

    sensor: int
    coefficients: tuple[tuple[float, float, float], ...]
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def a(self, t0_c: float) -> list[float]:
        """Coefficients a_j(T0) [unit/°C^j], j = 1..order.

        Parameters
        ----------
        t0_c : float
            Sensor temperature at power-on T0 [°C].

        Returns
        -------
        list of float
        """
        return [b0 + b1 * t0_c + b2 * t0_c**2 for b0, b1, b2 in self.coefficients]

    def start_bias(self, t0_c: float) -> float:
        """The power-on bias c0 + c1 T0 + c2 T0² [unit of the sensor] at T0 = ``t0_c`` [°C].

        Parameters
        ----------
        t0_c : float
            Sensor temperature at power-on T0 [°C].

        Returns
        -------
        float
        """
        c0, c1, c2 = self.start
        return c0 + c1 * t0_c + c2 * t0_c**2


@dataclass(frozen=True)
class HysteresisTerm:
    """Hysteresis: ``amplitude · (T − p)/(width/2)`` with p the play (backlash) operator
    of ``T_sensor`` of width ``width_c`` — ``+amplitude`` on a long heating, ``−amplitude``
    on cooling.

    Attributes
    ----------
    sensor : int
        Index of the temperature sensor ``T_sensor``.
    width_c : float
        Width of the play operator [°C].
    amplitude : float
        Half the difference between heating and cooling branches [unit of the sensor].
    """

    sensor: int
    width_c: float
    amplitude: float


def play_operator(x: FloatArray, width: float, p0: float | None = None) -> FloatArray:
    """Play (backlash) operator: ``p_i = clip(p_{i−1}, x_i − w/2, x_i + w/2)``.

    Parameters
    ----------
    x : numpy.ndarray
        The input (a temperature history) [°C].
    width : float
        The play's width w [°C].
    p0 : float, optional
        The initial state (default ``x[0]``).

    Returns
    -------
    numpy.ndarray
        The operator's output, same shape as ``x``.

    Notes
    -----
    The play (backlash) operator of hysteresis models: it follows the input only once the input
    has moved w/2 beyond it.

    References
    ----------
    M. A. Krasnosel'skii and A. V. Pokrovskii, *Systems with Hysteresis*, Springer, 1989.

    Examples
    --------
    >>> import numpy as np
    >>> play_operator(np.array([0.0, 1.0, 2.0, 1.5, 0.0]), 1.0).tolist()
    [0.0, 0.5, 1.5, 1.5, 0.5]
    """
    half = width / 2.0
    out = np.empty_like(x)
    p = float(x[0]) if p0 is None else p0
    xs = x.tolist()
    for i, v in enumerate(xs):
        if p < v - half:
            p = v - half
        elif p > v + half:
            p = v + half
        out[i] = p
    return out


@dataclass(frozen=True)
class BiasModel:
    """Temperature-induced bias ``E`` [unit of the sensor: °/h or mg].

    ``E = Σ_k Σ_j poly[k][j−1] (T_k − T_ref)^j + Σ_k rate[k] Ṫ_k
    + Σ_k coupling[k] (T_k − T_ref) Ṫ_k + Σ g (T_i − T_j)`` (+ piecewise, warm-up,
    hysteresis terms), with ``Ṫ`` in [°C/min].  Every polynomial, rate, coupling
    and gradient term lies in the span of the 37-term model of *A modelling and validation
    method for the temperature compensation model of a ring-laser gyroscope*.

    Attributes
    ----------
    t_ref_c : float
        Reference temperature T_ref [°C].
    poly : tuple of tuple of float
        ``poly[k][j-1]``: coefficient of (T_k − T_ref)^j [unit/°C^j].
    rate : tuple of float
        ``rate[k]``: coefficient of Ṫ_k [unit/(°C/min)].
    coupling : tuple of float
        ``coupling[k]``: coefficient of (T_k − T_ref) Ṫ_k [unit/(°C·°C/min)].
    gradient : tuple of (int, int, float)
        ``(i, j, g)``: coefficient g [unit/°C] of the difference T_i − T_j.
    piecewise, warmup, hysteresis : PiecewiseTerm, WarmupTerm, HysteresisTerm or None
        The optional non-polynomial terms.
    offset : float
        Constant bias [unit].
    """

    t_ref_c: float = 20.0
    poly: tuple[tuple[float, ...], ...] = ()
    rate: tuple[float, ...] = ()
    coupling: tuple[float, ...] = ()
    gradient: tuple[tuple[int, int, float], ...] = ()
    piecewise: PiecewiseTerm | None = None
    warmup: WarmupTerm | None = None
    hysteresis: HysteresisTerm | None = None
    offset: float = 0.0

    def evaluate(
        self,
        temps_c: FloatArray,
        rates_c_per_min: FloatArray,
        t0_c: FloatArray | None = None,
        power_on_index: int = 0,
    ) -> FloatArray:
        """E at every sample: ``temps_c`` and ``rates_c_per_min`` are (n, k); ``t0_c`` the
        node temperatures at power-on (warm-up term; before ``power_on_index`` it is 0).

        Parameters
        ----------
        temps_c : numpy.ndarray
            Node temperatures (n, k) [°C].
        rates_c_per_min : numpy.ndarray
            Their rates (n, k) [°C/min].
        t0_c : numpy.ndarray, optional
            Node temperatures at power-on (k,) [°C].
        power_on_index : int
            Sample of the power-on.

        Returns
        -------
        numpy.ndarray
            E (n,) [unit of the sensor].
        """
        n = temps_c.shape[0]
        out = np.full(n, float(self.offset))
        xk = np.empty(n)
        p = np.empty(n)
        for k, coefs in enumerate(self.poly):
            np.subtract(temps_c[:, k], self.t_ref_c, out=xk)
            p.fill(0.0)
            for c in reversed(coefs):  # Horner: Σ c_j x^j, j ≥ 1
                p += c
                p *= xk
            out += p
        for k, d in enumerate(self.rate):
            if d:
                np.multiply(rates_c_per_min[:, k], d, out=p)
                out += p
        for k, e in enumerate(self.coupling):
            if e:
                np.subtract(temps_c[:, k], self.t_ref_c, out=xk)
                np.multiply(rates_c_per_min[:, k], e, out=p)
                p *= xk
                out += p
        for i, j, g in self.gradient:
            np.subtract(temps_c[:, i], temps_c[:, j], out=p)
            p *= g
            out += p
        del xk, p
        if self.piecewise is not None:
            out += self.piecewise(temps_c[:, self.piecewise.sensor], self.t_ref_c)
        if self.warmup is not None:
            s = self.warmup.sensor
            t0 = float(temps_c[power_on_index, s] if t0_c is None else t0_c[s])
            dt = temps_c[:, s] - t0
            w = np.zeros(n)
            for j, a in enumerate(self.warmup.a(t0), start=1):
                w += a * dt**j
            w[:power_on_index] = 0.0
            out += w
        if self.hysteresis is not None:
            hy = self.hysteresis
            temp = temps_c[:, hy.sensor]
            step = max(1, n // 100_000)
            coarse = play_operator(temp[::step], hy.width_c)
            p = np.interp(np.arange(n), np.arange(0, n, step), coarse)
            out += hy.amplitude * (temp - p) / (hy.width_c / 2.0)
        return out
