"""The chamber air and the thermal network of the sensor.

Part of :mod:`thermocal.simulate`."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal._lazy import LazyModule
from thermocal.errors import ThermocalInputError
from thermocal.profiles import (
    check_program,
)

if TYPE_CHECKING:
    from scipy import signal as _signal
else:
    _signal = LazyModule("scipy.signal")

FloatArray = npt.NDArray[np.float64]
ProgramArrays = tuple[FloatArray, FloatArray]
Truth = dict[str, Any]


# --- JSON-ready values ---
def _plain_dict(obj: dict[str, Any]) -> dict[str, Any]:
    """:func:`_plain` of a dict, typed."""
    out: dict[str, Any] = _plain(obj)
    return out


def _plain(obj: Any) -> Any:
    """Tuples → lists, numpy scalars → floats, recursively (JSON-ready)."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


# --- chamber -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ChamberModel:
    """A temperature chamber: its set-point slew limit and air lag.

    Parameters
    ----------
    max_rate_c_per_min : float
        Slew limit of the set-point [°C/min] (``inf``: no limit).
    air_time_constant_s : float
        Lag τ of the air behind the limited set-point [s] (0: no lag).
    internal_step_s : float
        Step of the internal grid the chamber is simulated on [s].
    """

    max_rate_c_per_min: float = 3.0
    air_time_constant_s: float = 120.0
    internal_step_s: float = 1.0


def _foh_coefficients(lam: FloatArray, h: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Exact discretisation of ``dz/dt = −λ z + u(t)`` with u linear between samples.

    ``z[n] = a z[n−1] + β0 u[n−1] + β1 u[n]`` with ``a = e^{−x}``, ``x = λh``,
    ``β0 + β1 = h φ1(x)``, ``β1 = h (φ1(x) − φ2(x))``, ``φ1 = (1 − e^{−x})/x``,
    ``φ2 = (1 − e^{−x}(1 + x))/x²`` (series for small x).
    """
    x = lam * h
    a = np.exp(-x)
    small = x < 1e-3
    xs = np.where(small, 1.0, x)
    phi1 = np.where(small, 1 - x / 2 + x**2 / 6 - x**3 / 24, -np.expm1(-xs) / xs)
    phi2 = np.where(
        small, 0.5 - x / 3 + x**2 / 8 - x**3 / 30, (-np.expm1(-xs) - xs * np.exp(-xs)) / xs**2
    )
    beta1 = h * (phi1 - phi2)
    beta0 = h * phi1 - beta1
    return a, beta0, beta1


def _first_order(u: FloatArray, lam: float, gain: float, h: float, z0: float) -> FloatArray:
    """``dz/dt = −λ z + gain·u(t)`` sampled every h [s] from ``z(0) = z0`` (u linear between
    samples), by :func:`scipy.signal.lfilter`."""
    a, b0, b1 = _foh_coefficients(np.array([lam]), h)
    out = np.empty_like(u)
    out[0] = z0
    if u.size > 1:
        v = np.multiply(u[1:], gain * float(b1[0]))
        v += (gain * float(b0[0])) * u[:-1]
        out[1:], _ = _signal.lfilter([1.0], [1.0, -float(a[0])], v, zi=[float(a[0]) * z0])
    return out


def _slew_limit(x: FloatArray, max_step: float) -> FloatArray:
    """Slew-rate limiter ``y[i] = y[i−1] + clip(x[i] − y[i−1], −max_step, max_step)``."""
    d = np.diff(x)
    if not np.isfinite(max_step) or np.all(np.abs(d) <= max_step):
        return x.copy()
    y = np.empty_like(x)
    prev = float(x[0])
    y[0] = prev
    xs = x.tolist()
    for i in range(1, len(xs)):
        step = xs[i] - prev
        if step > max_step:
            step = max_step
        elif step < -max_step:
            step = -max_step
        prev += step
        y[i] = prev
    return y


def chamber_air(
    time_s: FloatArray,
    program_time_s: FloatArray,
    program_setpoint_c: FloatArray,
    chamber: ChamberModel | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Chamber set-point and air temperature [°C] at ``time_s`` (elapsed program time).

    The program is linear between its points and held at its ends; on an internal
    grid of ``internal_step_s`` it is slew-limited to ``max_rate_c_per_min`` and
    lagged by ``τ_air dA/dt = S_lim − A`` (exact first-order-hold discretisation),
    starting in equilibrium; then interpolated to ``time_s``.
    Returns ``(setpoint_c, air_c)``.

    Parameters
    ----------
    time_s : numpy.ndarray
        Elapsed program time [s].
    program_time_s, program_setpoint_c : numpy.ndarray
        The chamber program: times [s] and set-points [°C].
    chamber : ChamberModel, optional
        The chamber (default :class:`ChamberModel`).

    Returns
    -------
    tuple of numpy.ndarray
        ``(setpoint_c, air_c)`` at ``time_s`` [°C].

    Raises
    ------
    ThermocalInputError
        A program whose times do not increase or whose values are not finite.

    Examples
    --------
    A 10 °C step: the default slew limit of 3 °C/min turns it into a 200 s ramp, which the
    air follows with its 120 s lag; at 600 s the air lacks
    6 (1 − e^(−200/120)) e^(−400/120) = 0.17 °C (worked out by hand from the two stages):

    >>> import numpy as np
    >>> sp, air = chamber_air(np.array([0.0, 600.0, 3600.0]), np.array([0.0, 1.0]),
    ...                       np.array([20.0, 30.0]))
    >>> sp.round(1).tolist(), air.round(1).tolist()
    ([20.0, 30.0, 30.0], [20.0, 29.8, 30.0])
    """
    ch = chamber or ChamberModel()
    check_program(program_time_s, program_setpoint_c, "chamber program")
    sp = np.interp(time_s, program_time_s, program_setpoint_c)
    h = float(ch.internal_step_s)
    t0, t1 = float(time_s[0]), float(time_s[-1])
    n = math.ceil((t1 - t0) / h) + 1
    grid = t0 + np.arange(n) * h
    s = np.interp(grid, program_time_s, program_setpoint_c)
    s = _slew_limit(s, ch.max_rate_c_per_min / units.SECONDS_PER_MINUTE * h)
    if ch.air_time_constant_s > 0:
        lam = 1.0 / ch.air_time_constant_s
        air = _first_order(s, lam, lam, h, float(s[0]))
    else:
        air = s
    return sp, np.interp(time_s, grid, air)


# --- thermal network -----------------------------------------------------------------------------


@dataclass(frozen=True)
class ThermalNetwork:
    r"""Lumped thermal network of a sensor (several temperature sensors at places with
    different lags, so that gradients exist, as in the ring-laser-gyro method).

    Parameters
    ----------
    names : tuple of str
        Node (temperature channel) names.
    capacitance_j_per_k : tuple of float
        Heat capacity C_i of each node [J/K].
    to_air_w_per_k : tuple of float
        Conductance of each node to the chamber air [W/K].
    links : tuple of (int, int, float)
        ``(i, j, G_ij)``: conductances between nodes [W/K].
    power_w : tuple of float
        Self-heating power of each node after power-on [W].

    Raises
    ------
    ThermocalInputError
        The tuples differ in length, a capacity is not positive, or no node couples to
        the air.

    Notes
    -----
    .. math::

        C\,\frac{\mathrm dT}{\mathrm dt} = -(L + \operatorname{diag}(g_{air}))\,T
        + g_{air}\,A(t) + P\,H(t - t_{on})

    with :math:`L` the Laplacian of the links and :math:`A` the chamber air.
    """

    names: tuple[str, ...]
    capacitance_j_per_k: tuple[float, ...]
    to_air_w_per_k: tuple[float, ...]
    links: tuple[tuple[int, int, float], ...]
    power_w: tuple[float, ...]

    def __post_init__(self) -> None:
        k = len(self.names)
        if not (
            len(self.capacitance_j_per_k) == len(self.to_air_w_per_k) == len(self.power_w) == k
        ):
            raise ThermocalInputError("thermal network: one capacitance, g_air and power per node")
        if min(self.capacitance_j_per_k) <= 0:
            raise ThermocalInputError("thermal network: capacitances must be > 0")
        if sum(self.to_air_w_per_k) <= 0:
            raise ThermocalInputError("thermal network: at least one node must couple to the air")

    @property
    def n_nodes(self) -> int:
        """Number of nodes k."""
        return len(self.names)

    def conductance_matrix(self) -> FloatArray:
        """``K = L + diag(g_air)`` [W/K] (L the Laplacian of the links)."""
        k = self.n_nodes
        mat = np.diag(np.asarray(self.to_air_w_per_k, dtype=np.float64))
        for i, j, g in self.links:
            mat[i, i] += g
            mat[j, j] += g
            mat[i, j] -= g
            mat[j, i] -= g
        return mat.reshape(k, k)

    def modes(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Modal form: ``(λ [1/s], M, w_air, w_power)`` with ``T = M z`` and
        ``dz/dt = −λ z + w_air A(t) + w_power H(t − t_on)``.

        ``S = C^{-1/2} K C^{-1/2} = Q diag(λ) Qᵀ`` (symmetric, :func:`numpy.linalg.eigh`),
        ``M = C^{-1/2} Q``, ``w = Qᵀ C^{-1/2} (g_air or P)``.
        """
        c_isqrt = 1.0 / np.sqrt(np.asarray(self.capacitance_j_per_k, dtype=np.float64))
        s = c_isqrt[:, None] * self.conductance_matrix() * c_isqrt[None, :]
        lam, q = np.linalg.eigh(s)
        m = c_isqrt[:, None] * q
        w_air = q.T @ (c_isqrt * np.asarray(self.to_air_w_per_k, dtype=np.float64))
        w_pow = q.T @ (c_isqrt * np.asarray(self.power_w, dtype=np.float64))
        return lam, m, w_air, w_pow

    def time_constants_s(self) -> FloatArray:
        """Time constants ``1/λ_i`` [s] of the network, longest first."""
        return np.sort(1.0 / self.modes()[0])[::-1]

    def steady_rise_c(self) -> FloatArray:
        """Steady self-heating rise of each node above the air [°C]: ``K ΔT = P``."""
        return np.asarray(
            np.linalg.solve(self.conductance_matrix(), np.asarray(self.power_w, dtype=np.float64)),
            dtype=np.float64,
        )

    def to_dict(self) -> dict[str, Any]:
        """The network as plain JSON data, with its time constants and steady rise."""
        d = dataclasses.asdict(self)
        d["time_constants_s"] = [float(v) for v in self.time_constants_s()]
        d["steady_rise_c"] = [float(v) for v in self.steady_rise_c()]
        return _plain_dict(d)


_CHUNK = 1 << 15
"""Samples per block of the thermal recursion (keeps the work in cache)."""


def uniform_step(time_s: FloatArray, what: str = "time") -> float:
    """The constant sample interval of a uniform time grid (relative tolerance 1e-6).

    Parameters
    ----------
    time_s : numpy.ndarray
        The grid [s].
    what : str
        How the message names it.

    Returns
    -------
    float
        The step [s].

    Raises
    ------
    ThermocalInputError
        Fewer than two samples, or a grid that is not uniform and increasing.
    """
    if time_s.size < 2:
        raise ThermocalInputError(f"{what}: needs at least two samples")
    d = np.diff(time_s)
    h = float((time_s[-1] - time_s[0]) / (time_s.size - 1))
    if not h > 0 or max(float(d.max()) - h, h - float(d.min())) > 1e-6 * h + 1e-9:
        raise ThermocalInputError(f"{what}: the simulator needs a uniform, increasing time grid")
    return h


def simulate_nodes(
    time_s: FloatArray,
    air_c: FloatArray,
    network: ThermalNetwork,
    *,
    power_on_s: float | None = 0.0,
    warmed_up: bool = False,
    dt_s: float | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Node temperatures [°C] and rates [°C/min] of the network for an air history.

    The unit starts soaked at ``air_c[0]`` and unpowered; self-heating ``P`` is
    switched on at ``power_on_s`` (``None``: never).  With ``warmed_up`` it starts in
    the powered steady state.  Exact for air linear between samples (uniform grid):
    per mode ``z_i`` (:meth:`ThermalNetwork.modes`) the air response is a first-order
    recursion and the power-step response ``w_P/λ (1 − e^{−λ(t − t_on)})``; ``T = M z``.
    ``dt_s`` is the grid step when already checked by the caller.
    Returns ``(temperatures (n, k), rates_c_per_min (n, k))``, column-contiguous.

    Parameters
    ----------
    time_s : numpy.ndarray
        Uniform time grid (n,) [s].
    air_c : numpy.ndarray
        Chamber air (n,) [°C].
    network : ThermalNetwork
        The sensor's network (k nodes).
    power_on_s : float or None
        Power-on time [s]; None: never powered.
    warmed_up : bool
        Start in the powered steady state.
    dt_s : float, optional
        The grid step [s], when the caller has checked it.

    Returns
    -------
    tuple of numpy.ndarray
        ``(temperatures (n, k) [°C], rates (n, k) [°C/min])``.
    """
    h = uniform_step(time_s) if dt_s is None else float(dt_s)
    lam, m, w_air, w_pow = network.modes()
    a, b0, b1 = _foh_coefficients(lam, h)
    n, k = time_s.size, network.n_nodes
    temps = np.empty((k, n))
    rates = np.empty((k, n))
    m_rate = m * units.SECONDS_PER_MINUTE
    u0 = float(air_c[0])
    # z[-1] = z0 (soaked steady state) and u[-1] = u0 make the recursion exact from n = 0
    z_last = w_air * u0 / lam
    pow_ss = w_pow / lam
    t_on = 0.0 if power_on_s is None else float(power_on_s)
    powered = warmed_up or power_on_s is not None
    zc = np.empty((k, _CHUNK))
    dzc = np.empty((k, _CHUNK))
    for s0 in range(0, n, _CHUNK):
        s1 = min(n, s0 + _CHUNK)
        c = s1 - s0
        u = air_c[s0:s1]
        up = air_c[s0 - 1 : s1 - 1] if s0 > 0 else np.concatenate(([u0], air_c[: s1 - 1]))
        for i in range(k):
            v = (w_air[i] * b1[i]) * u + (w_air[i] * b0[i]) * up
            zc[i, :c], _ = _signal.lfilter([1.0], [1.0, -a[i]], v, zi=[a[i] * z_last[i]])
            z_last[i] = zc[i, c - 1]
        np.multiply(w_air[:, None], u[None, :], out=dzc[:, :c])
        dzc[:, :c] -= lam[:, None] * zc[:, :c]
        if warmed_up:
            zc[:, :c] += pow_ss[:, None]
        elif powered:
            since = time_s[s0:s1] - t_on
            if since[-1] >= 0:
                on = since >= 0
                decay = np.exp(-lam[:, None] * np.maximum(since, 0.0)[None, :])
                zc[:, :c] += pow_ss[:, None] * (1.0 - decay) * on
                dzc[:, :c] += w_pow[:, None] * decay * on
        np.matmul(m, zc[:, :c], out=temps[:, s0:s1])
        np.matmul(m_rate, dzc[:, :c], out=rates[:, s0:s1])
    return temps.T, rates.T


@dataclass(frozen=True)
class ThermalResult:
    """Output of :func:`simulate_thermal`.

    Parameters
    ----------
    time_s : numpy.ndarray
        Time (n,) [s].
    setpoint_c, air_c : numpy.ndarray
        Chamber set-point and air (n,) [°C].
    temperatures_c : numpy.ndarray
        Node temperatures (n, k) [°C].
    rates_c_per_min : numpy.ndarray
        Their exact rates (n, k) [°C/min].
    names : tuple of str
        The node names.
    time_constants_s : numpy.ndarray
        The network's time constants, longest first [s].
    dt_s : float
        The sample interval [s] (NaN: computed from ``time_s``).
    """

    time_s: FloatArray
    setpoint_c: FloatArray
    air_c: FloatArray
    temperatures_c: FloatArray
    rates_c_per_min: FloatArray
    names: tuple[str, ...]
    time_constants_s: FloatArray
    dt_s: float = float("nan")

    @property
    def sample_interval_s(self) -> float:
        """The (uniform) sample interval [s]."""
        return self.dt_s if math.isfinite(self.dt_s) else uniform_step(self.time_s)


def simulate_thermal(
    time_s: FloatArray,
    program_time_s: FloatArray,
    program_setpoint_c: FloatArray,
    network: ThermalNetwork,
    *,
    chamber: ChamberModel | None = None,
    power_on_s: float | None = 0.0,
    warmed_up: bool = False,
) -> ThermalResult:
    """Chamber set-point → chamber air (:func:`chamber_air`) → sensor node temperatures
    (:func:`simulate_nodes`).  ``time_s`` is elapsed program time on a uniform grid.

    Parameters
    ----------
    time_s : numpy.ndarray
        Elapsed program time on a uniform grid [s].
    program_time_s, program_setpoint_c : numpy.ndarray
        The chamber program: times [s] and set-points [°C].
    network : ThermalNetwork
        The sensor's network.
    chamber : ChamberModel, optional
        The chamber (default :class:`ChamberModel`).
    power_on_s : float or None
        Power-on time [s]; None: never powered.
    warmed_up : bool
        Start in the powered steady state.

    Returns
    -------
    ThermalResult

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.simulate import FOG
    >>> th = simulate_thermal(np.arange(0.0, 7200.0, 10.0), np.array([0.0, 600.0]),
    ...                       np.array([20.0, 20.0]), FOG.network, warmed_up=True)
    >>> bool(np.allclose(th.temperatures_c[-1] - 20.0, FOG.network.steady_rise_c(), atol=1e-6))
    True
    """
    t = np.asarray(time_s, dtype=np.float64)
    sp, air = chamber_air(
        t,
        np.asarray(program_time_s, dtype=np.float64),
        np.asarray(program_setpoint_c, dtype=np.float64),
        chamber,
    )
    h = uniform_step(t)
    temps, rates = simulate_nodes(
        t, air, network, power_on_s=power_on_s, warmed_up=warmed_up, dt_s=h
    )
    return ThermalResult(t, sp, air, temps, rates, network.names, network.time_constants_s(), h)
