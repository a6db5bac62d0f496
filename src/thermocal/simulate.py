"""Sensor and chamber simulator with known truth (SPEC §2, §6).

Chain of the simulation (every stage a pure function on arrays):

1. **Chamber** (:func:`chamber_air`): the programmed set-point ``S(t)`` [°C] goes
   through a slew-rate limiter (``max_rate_c_per_min``) and a first-order lag
   ``τ_air dA/dt = S_lim − A`` — the air temperature of a real chamber.
2. **Thermal network** (:func:`simulate_nodes`): a lumped RC network of the
   sensor, ``C dT/dt = −(L + diag(g_air)) T + g_air A(t) + P·H(t − t_on)``, with
   heat capacities ``C`` [J/K], conductances between nodes (Laplacian ``L``) and to
   the air ``g_air`` [W/K], and self-heating power ``P`` [W] switched on at power-on.
   Solved exactly for piecewise-linear air input in its modal form
   (``C^{-1/2} K C^{-1/2} = Q Λ Qᵀ``, time constants ``1/λ_i``), each mode a
   first-order recursion run by :func:`scipy.signal.lfilter`.  The node
   temperatures are the sensor's temperature channels ``T1..T4``; their exact
   derivatives give the temperature rates.
3. **Sensor** (:func:`simulate_sensor`): SPEC §2 error model
   ``F = (1 + δK(T)) · (ω_in + B0 + D + E(T, Ṫ, ∇T)) + noise`` where ``B0`` is the
   constant bias, ``D`` the turn-on offset (random per run: repeatability), ``E``
   the temperature-induced bias (:class:`BiasModel`: polynomial, rate,
   coupling, gradient, piecewise-linear, warm-up and hysteresis terms), ``δK`` the
   scale-factor temperature coefficient; noise (:func:`simulate_noise`): angle
   random walk, bias instability (flicker, PSD ``B²/(2πf)``), rate random walk,
   rate ramp (IEEE Std 952-1997 Annex C) and quantization — pulse counts with
   scale factor K for ring-laser gyros (SPEC §1), output resolution otherwise.

Truth columns (all scenarios):

* ``truth_bias`` [°/h or mg]: the noise-free *temperature-induced* bias ``E`` —
  gyros: the temperature, rate, coupling, gradient (and hysteresis) terms, zero
  at ``t_ref_c`` (20 °C) with no temperature rate; it does **not** include the
  constant bias, the turn-on offset or the earth rate, which are in the truth
  JSON (``bias_constant``, ``turn_on_offset``, ``input``).  MEMS warm-up:
  ``Σ_j a_j(T0) ΔT^j`` (zero at power-on; the power-on value is
  ``start_bias``).  Accelerometers: the run's characteristic curve at ``T1``.
* ``truth_rate`` [same unit]: the noise-free output ``(1 + δK)(ω_in + B0 + D + E)``.

Presets (:data:`PRESETS`) and scenarios (:data:`SCENARIOS`, used by
``thermocal simulate``) are registries keyed by name.  Every random number comes
from an explicit :class:`numpy.random.Generator`; scenarios derive it from
``SeedSequence([seed, crc32(scenario)])`` so the same seed gives the same file.
"""

from __future__ import annotations

import dataclasses
import math
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
import scipy.fft
from scipy.signal import lfilter

from thermocal import units
from thermocal.errors import ThermocalInputError
from thermocal.profiles import (
    POWER_ON_LABEL,
    Profile,
    Stage,
    builtin_profile,
    check_program,
    find_holds,
)
from thermocal.recording import Metadata, Recording

FloatArray = npt.NDArray[np.float64]
ProgramArrays = tuple[FloatArray, FloatArray]
ProfileInput = Profile | ProgramArrays | None
Truth = dict[str, Any]
ScenarioResult = list[tuple[Recording, Truth]]

TRUTH_FORMAT = "thermocal-truth"
TRUTH_VERSION = 1

# --- chamber -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ChamberModel:
    """A temperature chamber: set-point slew limit [°C/min] and air lag τ [s]
    (``0`` for no lag, ``inf`` rate for no limit)."""

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
        out[1:], _ = lfilter([1.0], [1.0, -float(a[0])], v, zi=[float(a[0]) * z0])
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
    """Lumped thermal network of a sensor (SPEC §2: several sensors at places with
    different lags, so that gradients exist).

    names : node (temperature channel) names; capacitance_j_per_k : C_i [J/K];
    to_air_w_per_k : conductance of each node to the chamber air [W/K];
    links : ``(i, j, G_ij)`` conductances between nodes [W/K];
    power_w : self-heating power of each node after power-on [W].
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
        d = dataclasses.asdict(self)
        d["time_constants_s"] = [float(v) for v in self.time_constants_s()]
        d["steady_rise_c"] = [float(v) for v in self.steady_rise_c()]
        return _plain_dict(d)


_CHUNK = 1 << 15
"""Samples per block of the thermal recursion (keeps the work in cache)."""


def uniform_step(time_s: FloatArray, what: str = "time") -> float:
    """The constant sample interval [s] of a uniform time grid (relative tolerance 1e-6)."""
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
            zc[i, :c], _ = lfilter([1.0], [1.0, -a[i]], v, zi=[a[i] * z_last[i]])
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
    """Output of :func:`simulate_thermal`: time [s], set-point and chamber air [°C],
    node temperatures (n, k) [°C] and their exact rates (n, k) [°C/min]."""

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
    (:func:`simulate_nodes`).  ``time_s`` is elapsed program time on a uniform grid."""
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


# --- bias model ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class PiecewiseTerm:
    """Continuous piecewise-linear bias in ``T_sensor`` (seed 001), zero at ``t_ref``.

    ``b(T) = s_0 (T − T_ref) + Σ_j (s_{j+1} − s_j) w ln(1 + e^{(T − c_j)/w})`` − its
    value at T_ref: slopes ``slopes`` [unit/°C] between breakpoints ``breakpoints_c``,
    corners rounded over ``smoothing_c`` = w [°C] (softplus).
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
    """Warm-up bias (seed 003, SPEC §4c): ``Σ_{j≥1} a_j(T0) ΔT^j``, ``ΔT = T − T0``,
    ``a_j(T0) = b_j0 + b_j1 T0 + b_j2 T0²``; ``coefficients[j−1] = (b_j0, b_j1, b_j2)``;
    ``start`` = ``(c0, c1, c2)`` gives the power-on bias ``c0 + c1 T0 + c2 T0²``.
    T0 is the sensor temperature at power-on [°C]."""

    sensor: int
    coefficients: tuple[tuple[float, float, float], ...]
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def a(self, t0_c: float) -> list[float]:
        """Coefficients a_j(T0) [unit/°C^j], j = 1..order."""
        return [b0 + b1 * t0_c + b2 * t0_c**2 for b0, b1, b2 in self.coefficients]

    def start_bias(self, t0_c: float) -> float:
        c0, c1, c2 = self.start
        return c0 + c1 * t0_c + c2 * t0_c**2


@dataclass(frozen=True)
class HysteresisTerm:
    """Hysteresis: ``amplitude · (T − p)/(width/2)`` with p the play (backlash) operator
    of ``T_sensor`` of width ``width_c`` — ``+amplitude`` on a long heating, ``−amplitude``
    on cooling."""

    sensor: int
    width_c: float
    amplitude: float


def play_operator(x: FloatArray, width: float, p0: float | None = None) -> FloatArray:
    """Play (backlash) operator: ``p_i = clip(p_{i−1}, x_i − w/2, x_i + w/2)``."""
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
    """Temperature-induced bias ``E`` of SPEC §2 [unit of the sensor: °/h or mg].

    ``E = Σ_k Σ_j poly[k][j−1] (T_k − T_ref)^j + Σ_k rate[k] Ṫ_k
    + Σ_k coupling[k] (T_k − T_ref) Ṫ_k + Σ g (T_i − T_j)`` (+ piecewise, warm-up,
    hysteresis terms), with ``Ṫ`` in [°C/min].  Every polynomial, rate, coupling
    and gradient term lies in the span of the seed-000 37-term model (SPEC §4a).
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
        node temperatures at power-on (warm-up term; before ``power_on_index`` it is 0)."""
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


# --- noise (IEEE Std 952-1997 Annex C) -----------------------------------------------------------


@dataclass(frozen=True)
class NoiseParams:
    """Noise terms of a sensor output, in its unit ``u`` (°/h or mg).

    white_density : N [u·√s] = [u/√Hz], two-sided PSD N² (angle / velocity random walk;
        a gyro ARW of N' [°/√h] is N = 60·N' [°/h·√s]); Allan ``σ²(τ) = N²/τ``.
    bias_instability : B [u], flicker PSD ``B²/(2πf)``; Allan plateau ``0.664 B``.
    rate_random_walk : K [u/√s]; Allan ``σ²(τ) = K² τ/3``.
    rate_ramp : R [u/s]; Allan ``σ²(τ) = R² τ²/2``.
    resolution : output LSB [u] (0: none); pulse outputs are quantized by K instead.
    """

    white_density: float = 0.0
    bias_instability: float = 0.0
    rate_random_walk: float = 0.0
    rate_ramp: float = 0.0
    resolution: float = 0.0


def flicker_noise(n: int, dt_s: float, b: float, rng: np.random.Generator) -> FloatArray:
    """Flicker (1/f) noise with two-sided PSD ``S(f) = B²/(2πf)`` (IEEE 952 bias instability).

    Spectral synthesis: ``X_k = sqrt(N f_s S(f_k)/2)·(a + ib)``, a, b ~ N(0, 1),
    ``x = irfft(X)`` (so ``E|X_k|² = N f_s S(f_k)``); the DC bin is zero.
    """
    if b == 0.0 or n == 0:
        return np.zeros(n)
    nfft = int(scipy.fft.next_fast_len(n, real=True))
    f = np.fft.rfftfreq(nfft, dt_s)
    amp = np.zeros(f.size)
    np.sqrt(nfft / dt_s * b**2 / (4 * math.pi) / f[1:], out=amp[1:])
    del f
    spec = np.empty(amp.size, dtype=np.complex128)
    spec.real = rng.standard_normal(amp.size)
    spec.imag = rng.standard_normal(amp.size)
    spec *= amp
    if nfft % 2 == 0:  # the Nyquist bin of a real signal is real (same variance)
        spec[-1] = math.sqrt(2.0) * spec[-1].real
    del amp
    x = scipy.fft.irfft(spec, nfft, workers=-1, overwrite_x=True)
    return np.asarray(x[:n], dtype=np.float64)


FLICKER_MAX_RATE_HZ = 10.0
"""Flicker noise is synthesised at this rate at most (held constant within each block)."""


def simulate_noise(n: int, dt_s: float, noise: NoiseParams, rng: np.random.Generator) -> FloatArray:
    """Sum of white (N/√τ0 per sample), flicker (:func:`flicker_noise`, at most at
    :data:`FLICKER_MAX_RATE_HZ`), rate random walk (cumulative sum of N(0, K² τ0)) and
    rate ramp (R·t) noise, n samples at τ0 = dt_s.
    Samples are mean rates over each interval (IEEE Std 952 Annex C)."""
    if noise.white_density:
        out = rng.standard_normal(n)
        out *= noise.white_density / math.sqrt(dt_s)
    else:
        out = np.zeros(n)
    if noise.bias_instability:
        # flicker is synthesised at ≤ FLICKER_MAX_RATE_HZ and held over each block: it is
        # far below the white noise at short τ, and cluster averages over whole blocks are
        # exactly those of flicker at the lower rate
        m = max(1, math.floor(1.0 / (dt_s * FLICKER_MAX_RATE_HZ) + 1e-9))
        n_blocks = -(-n // m)
        fl = flicker_noise(n_blocks, dt_s * m, noise.bias_instability, rng)
        if m == 1:
            out += fl
        else:
            whole = out[: (n // m) * m].reshape(-1, m)  # a view: updated in place
            whole += fl[: n // m, None]
            if n % m:
                out[(n // m) * m :] += fl[-1]
    if noise.rate_random_walk:
        w = rng.standard_normal(n)
        w *= noise.rate_random_walk * math.sqrt(dt_s)
        np.cumsum(w, out=w)
        out += w
        del w
    if noise.rate_ramp:
        out += noise.rate_ramp * dt_s * np.arange(n)
    return out


# --- sensor presets ------------------------------------------------------------------------------


@dataclass(frozen=True)
class SensorPreset:
    """A simulated sensor: thermal network, error model and noise.

    ``unit`` is the physical unit of truth and noise (``deg/h`` or ``mg``);
    ``output`` is ``pulses`` (integrating counts with scale factor K, SPEC §1) or
    ``value`` (the physical unit).  ``curves`` are the characteristic curves
    (seed 004) of accelerometers; a run picks one.
    """

    name: str
    kind: Literal["gyro", "accel"]
    description: str
    unit: str
    output: Literal["pulses", "value"]
    bias_constant: float
    turn_on_sigma: float
    bias_model: BiasModel
    noise: NoiseParams
    network: ThermalNetwork
    chamber: ChamberModel = field(default_factory=ChamberModel)
    scale_factor: float | None = None
    scale_factor_unit: str | None = None
    scale_factor_tc_ppm_per_c: float = 0.0
    rate_hz: float = 1.0
    curves: tuple[BiasModel, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        d = _plain_dict(dataclasses.asdict(self))
        d["network"] = self.network.to_dict()
        return d


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


_ARW = 1.0 / units.ARW_DEG_SQRT_H_PER_DEG_H_SQRT_HZ  # [°/√h] → [°/h·√s]

RLG = SensorPreset(
    name="rlg",
    kind="gyro",
    description="navigation-grade ring-laser gyro, pulse output K = 4 counts/arcsec, "
    "four temperature sensors (T1 block, T2 discharge, T3 mount, T4 case)",
    unit="deg/h",
    output="pulses",
    bias_constant=0.004,
    turn_on_sigma=0.002,
    bias_model=BiasModel(
        t_ref_c=20.0,
        # uncompensated temperature-induced bias ≈ 0.2 °/h peak to peak over −20…+50 °C
        # (≈ 0.003 °/h/°C), well above the 37-term least-squares noise floor
        poly=((3.0e-3, 3.0e-5, -6.0e-7), (-1.0e-3,), (1.5e-3, -1.5e-5), (0.5e-3,)),
        rate=(0.04, -0.01, 0.02, 0.0),
        coupling=(4.0e-4, 0.0, 0.0, 0.0),
        gradient=((0, 2, 1.0e-2),),
    ),
    noise=NoiseParams(white_density=0.002 * _ARW, bias_instability=0.0015),
    network=ThermalNetwork(
        names=("T1", "T2", "T3", "T4"),
        capacitance_j_per_k=(1200.0, 150.0, 1800.0, 900.0),
        to_air_w_per_k=(0.0, 0.0, 0.4, 1.6),
        links=((3, 2, 2.0), (2, 0, 1.5), (0, 1, 0.8), (3, 0, 0.5)),
        power_w=(1.0, 3.0, 0.0, 1.0),
    ),
    chamber=ChamberModel(max_rate_c_per_min=3.0, air_time_constant_s=120.0),
    scale_factor=4.0,
    scale_factor_unit="counts/arcsec",
    scale_factor_tc_ppm_per_c=0.1,
    rate_hz=1.0,
)

FOG = SensorPreset(
    name="fog",
    kind="gyro",
    description="tactical-grade fibre-optic gyro, rate output [°/h], bias piecewise linear "
    "in the coil temperature T1 with corners near 23.6 and 30 °C (seed 001)",
    unit="deg/h",
    output="value",
    bias_constant=0.3,
    turn_on_sigma=0.05,
    bias_model=BiasModel(
        t_ref_c=20.0,
        piecewise=PiecewiseTerm(
            sensor=0, breakpoints_c=(23.6, 30.0), slopes=(0.35, -0.15, 0.45), smoothing_c=0.15
        ),
    ),
    noise=NoiseParams(white_density=0.003 * _ARW, bias_instability=0.005),
    network=ThermalNetwork(
        names=("T1", "T2", "T3", "T4"),
        capacitance_j_per_k=(400.0, 100.0, 1500.0, 600.0),
        to_air_w_per_k=(0.0, 0.0, 0.5, 1.5),
        links=((3, 2, 2.0), (2, 0, 1.2), (0, 1, 0.5), (3, 1, 0.3)),
        power_w=(0.2, 2.0, 0.0, 0.5),
    ),
    scale_factor_tc_ppm_per_c=1.0,
    rate_hz=1.0,
)

MEMS_GYRO = SensorPreset(
    name="mems-gyro",
    kind="gyro",
    description="industrial MEMS gyro, rate output [°/h], strong self-heating warm-up "
    "(T1 die, T2 board, T3 case, T4 fixture); warm-up bias per seed 003",
    unit="deg/h",
    output="value",
    bias_constant=0.0,
    turn_on_sigma=8.0,
    bias_model=BiasModel(
        t_ref_c=20.0,
        warmup=WarmupTerm(
            sensor=0,
            coefficients=((6.0, 0.04, 0.0008), (-0.25, 0.002, 4.0e-5)),
            start=(30.0, 0.8, -0.004),
        ),
    ),
    noise=NoiseParams(white_density=0.15 * _ARW, bias_instability=3.0),
    network=ThermalNetwork(
        names=("T1", "T2", "T3", "T4"),
        capacitance_j_per_k=(0.5, 15.0, 120.0, 1500.0),
        to_air_w_per_k=(0.0, 0.0, 0.6, 1.5),
        links=((0, 1, 0.04), (1, 2, 0.4), (2, 3, 0.5)),
        power_w=(0.15, 1.2, 0.0, 0.0),
    ),
    chamber=ChamberModel(max_rate_c_per_min=3.0, air_time_constant_s=120.0),
    rate_hz=10.0,
)

_ACCEL_BASE = ((0.025, 1.5e-4),)
ACCEL = SensorPreset(
    name="accel",
    kind="accel",
    description="navigation/tactical accelerometer, output [mg], bias vs T1 in one of "
    "three characteristic curves per run (seed 004)",
    unit="mg",
    output="value",
    bias_constant=0.0,
    turn_on_sigma=0.03,
    bias_model=BiasModel(t_ref_c=20.0, poly=_ACCEL_BASE),
    noise=NoiseParams(white_density=0.02, bias_instability=0.005),
    network=ThermalNetwork(
        names=("T1", "T2", "T3", "T4"),
        capacitance_j_per_k=(300.0, 150.0, 1500.0, 700.0),
        to_air_w_per_k=(0.0, 0.0, 0.5, 1.5),
        links=((3, 2, 2.0), (2, 0, 1.0), (0, 1, 0.6), (3, 1, 0.3)),
        power_w=(0.3, 1.5, 0.0, 0.3),
    ),
    chamber=ChamberModel(max_rate_c_per_min=3.0, air_time_constant_s=120.0),
    scale_factor_tc_ppm_per_c=20.0,
    rate_hz=1.0,
    curves=(
        BiasModel(t_ref_c=20.0, poly=((0.025, 1.5e-4),), offset=0.0),
        BiasModel(t_ref_c=20.0, poly=((0.029, 1.5e-4),), offset=1.6),
        BiasModel(t_ref_c=20.0, poly=((0.022, 1.2e-4),), offset=-1.4),
    ),
)

PRESETS: dict[str, SensorPreset] = {p.name: p for p in (RLG, FOG, MEMS_GYRO, ACCEL)}
"""Registry of sensor presets by name: ``rlg``, ``fog``, ``mems-gyro``, ``accel``."""


def get_preset(name: str) -> SensorPreset:
    """A preset by name; :class:`ThermocalInputError` lists the known ones."""
    try:
        return PRESETS[name]
    except KeyError:
        raise ThermocalInputError(
            f"unknown sensor preset {name!r}; known: {', '.join(PRESETS)}"
        ) from None


# --- sensor --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SensorOutput:
    """Output of :func:`simulate_sensor`.

    signal : the output column (counts for pulse outputs, else the preset unit);
    signal_unit : its unit string; truth_bias, truth_rate : see the module docstring
    [preset unit]; turn_on_offset : D [preset unit]; start_temperatures_c : node
    temperatures at power-on [°C].
    """

    signal: FloatArray
    signal_unit: str
    truth_bias: FloatArray
    truth_rate: FloatArray
    turn_on_offset: float
    start_temperatures_c: FloatArray


def simulate_sensor(
    thermal: ThermalResult,
    preset: SensorPreset,
    rng: np.random.Generator,
    *,
    input_value: float | FloatArray = 0.0,
    bias_model: BiasModel | None = None,
    turn_on_offset: float | None = None,
    power_on_s: float = 0.0,
) -> SensorOutput:
    """Sensor output for a thermal history (SPEC §2).

    ``F = (1 + δK(T1)) (ω_in + B0 + D + E) + noise`` with ``δK = tc·1e-6·(T1 − T_ref)``,
    ``D ~ N(0, turn_on_sigma²)`` unless given, ``E`` from ``bias_model`` (default:
    the preset's).  Pulse outputs: counts ``N_i = ⌊K θ_i/f + φ⌋ − ⌊K θ_{i−1}/f + φ⌋``
    with θ the integrated rate, φ ~ U(0, 1) and ``f`` the scale-factor-unit factor of
    :data:`thermocal.units.SCALE_FACTOR_UNITS` (so ``N/(τK)·f`` is the mean rate).
    """
    t = thermal.time_s
    n = t.size
    dt = thermal.sample_interval_s
    model = bias_model or preset.bias_model
    on_idx = int(np.searchsorted(t, power_on_s))
    on_idx = min(max(on_idx, 0), n - 1)
    t0 = thermal.temperatures_c[on_idx]
    e = model.evaluate(thermal.temperatures_c, thermal.rates_c_per_min, t0, on_idx)
    d = float(rng.normal(0.0, preset.turn_on_sigma)) if turn_on_offset is None else turn_on_offset
    start = 0.0
    if model.warmup is not None:
        start = model.warmup.start_bias(float(t0[model.warmup.sensor]))
    dk = np.subtract(thermal.temperatures_c[:, 0], model.t_ref_c)
    dk *= preset.scale_factor_tc_ppm_per_c * units.PPM
    dk += 1.0
    truth_rate = e + (np.asarray(input_value) + (preset.bias_constant + start + d))
    truth_rate *= dk
    del dk
    measured = simulate_noise(n, dt, preset.noise, rng)
    measured += truth_rate
    if preset.output == "pulses":
        if preset.scale_factor is None or preset.scale_factor_unit is None:
            raise ThermocalInputError(f"preset {preset.name!r}: pulse output needs K and its unit")
        integrating, factor, _ = units.SCALE_FACTOR_UNITS[preset.scale_factor_unit]
        if not integrating:
            raise ThermocalInputError("pulse output needs an integrating scale-factor unit")
        phase = float(rng.uniform())
        acc = measured  # reused in place: accumulated counts K θ/f + φ, then its floor
        acc *= dt * preset.scale_factor / factor
        np.cumsum(acc, out=acc)
        acc += phase
        np.floor(acc, out=acc)
        signal = np.empty(n)
        signal[0] = acc[0] - math.floor(phase)
        np.subtract(acc[1:], acc[:-1], out=signal[1:])
        del acc, measured
        signal_unit = "counts"
    else:
        signal = measured
        if preset.noise.resolution > 0:
            signal = np.round(signal / preset.noise.resolution) * preset.noise.resolution
        signal_unit = preset.unit
    return SensorOutput(signal, signal_unit, e, truth_rate, d, np.asarray(t0, dtype=np.float64))


# --- scenarios -----------------------------------------------------------------------------------


def scenario_rng(scenario: str, seed: int, n: int) -> list[np.random.Generator]:
    """``n`` independent generators from ``SeedSequence([seed, crc32(scenario)])``."""
    if int(seed) != seed or seed < 0:
        raise ThermocalInputError(f"seed must be a non-negative integer, got {seed!r}")
    ss = np.random.SeedSequence([int(seed), zlib.crc32(scenario.encode())])
    return [np.random.default_rng(s) for s in ss.spawn(n)]


def _program(profile: ProfileInput, default: str) -> tuple[ProgramArrays, list[Stage]]:
    """Program arrays and hold stages of a profile (the default built-in when None)."""
    if profile is None:
        profile = builtin_profile(default)
    if isinstance(profile, Profile):
        return profile.knots(), profile.stages()
    t, c = (np.asarray(a, dtype=np.float64) for a in profile)
    check_program(t, c, "chamber program")
    t = t - t[0]
    return (t, c), find_holds(t, c)


def _time_grid(duration_s: float, rate_hz: float) -> FloatArray:
    if not (math.isfinite(rate_hz) and rate_hz > 0):
        raise ThermocalInputError(f"rate_hz must be > 0, got {rate_hz!r}")
    dt = 1.0 / rate_hz
    n = math.floor(duration_s / dt + 1e-9) + 1
    if n < 2:
        raise ThermocalInputError("the chamber program is shorter than two samples")
    return np.arange(n, dtype=np.float64) * dt


def _metadata(
    preset: SensorPreset, scenario: str, seed: int, label: str, rate_hz: float, **extra: Any
) -> Metadata:
    run = f"{scenario}-seed{seed}" + (f"-{label}" if label else "")
    return Metadata(
        sample_interval_s=1.0 / rate_hz,
        scale_factor=preset.scale_factor if preset.output == "pulses" else None,
        scale_factor_unit=preset.scale_factor_unit if preset.output == "pulses" else None,
        latitude_deg=extra.pop("latitude_deg", None),
        axis=extra.pop("axis", None),
        sensor_id=f"sim-{preset.name}-001",
        run_id=run,
        notes=f"simulated by thermocal ({scenario}, seed {seed}); truth_bias = "
        "temperature-induced bias, truth_rate = noise-free output",
        extra={"scenario": scenario, "seed": int(seed), "label": label, **extra},
    )


def _recording(
    thermal: ThermalResult, out: SensorOutput, preset: SensorPreset, meta: Metadata
) -> Recording:
    signal_name = "gyro" if preset.kind == "gyro" else "accel"
    temps: dict[str, npt.ArrayLike] = {
        name: thermal.temperatures_c[:, i] for i, name in enumerate(thermal.names)
    }
    return Recording.from_arrays(
        thermal.time_s,
        signals={signal_name: out.signal},
        temperatures=temps,
        signal_unit=out.signal_unit,
        other={
            "T_chamber": thermal.air_c,
            "setpoint_c": thermal.setpoint_c,
            "truth_bias": out.truth_bias,
            "truth_rate": out.truth_rate,
        },
        other_units={
            "T_chamber": "degC",
            "setpoint_c": "degC",
            "truth_bias": preset.unit,
            "truth_rate": preset.unit,
        },
        meta=meta,
    )


def _truth(
    scenario: str,
    seed: int,
    label: str,
    preset: SensorPreset,
    out: SensorOutput,
    thermal: ThermalResult,
    stages: Sequence[Stage],
    **extra: Any,
) -> Truth:
    return _plain_dict(
        {
            "format": TRUTH_FORMAT,
            "version": TRUTH_VERSION,
            "scenario": scenario,
            "seed": int(seed),
            "label": label,
            "preset": preset.to_dict(),
            "unit": preset.unit,
            "signal": "gyro" if preset.kind == "gyro" else "accel",
            "signal_unit": out.signal_unit,
            "sample_rate_hz": 1.0 / thermal.sample_interval_s,
            "n_samples": int(thermal.time_s.size),
            "bias_constant": preset.bias_constant,
            "turn_on_offset": out.turn_on_offset,
            "start_temperatures_c": dict(
                zip(thermal.names, (float(v) for v in out.start_temperatures_c), strict=True)
            ),
            "time_constants_s": [float(v) for v in thermal.time_constants_s],
            "stages": [s.to_dict() for s in stages],
            "truth_bias_definition": "temperature-induced bias E (SPEC §2); see "
            "thermocal.simulate module docstring",
            **extra,
        }
    )


def _gyro_run(
    scenario: str,
    preset: SensorPreset,
    seed: int,
    rng: np.random.Generator,
    program: ProgramArrays,
    stages: Sequence[Stage],
    *,
    rate_hz: float,
    latitude_deg: float,
    axis: str,
    warmed_up: bool,
    label: str = "",
) -> tuple[Recording, Truth]:
    t = _time_grid(float(program[0][-1]), rate_hz)
    thermal = simulate_thermal(
        t, program[0], program[1], preset.network, chamber=preset.chamber, warmed_up=warmed_up
    )
    omega = units.earth_rate_on_axis_deg_h(latitude_deg, units.parse_axis(axis))
    out = simulate_sensor(thermal, preset, rng, input_value=omega)
    meta = _metadata(preset, scenario, seed, label, rate_hz, latitude_deg=latitude_deg, axis=axis)
    truth = _truth(
        scenario,
        seed,
        label,
        preset,
        out,
        thermal,
        stages,
        input=omega,
        earth_rate_on_axis_deg_h=omega,
        latitude_deg=latitude_deg,
        axis=axis,
        power_on_s=None if warmed_up else 0.0,
        warmed_up=warmed_up,
    )
    return _recording(thermal, out, preset, meta), truth


DEFAULT_LATITUDE_DEG = 45.0


def _single_gyro_scenario(
    name: str,
    seed: int,
    profile: ProfileInput,
    rate_hz: float | None,
    latitude_deg: float,
    axis: str,
    preset: str,
    *,
    warmed_up: bool,
) -> ScenarioResult:
    """One gyro run of scenario ``name`` over its profile (the built-in one by default)."""
    p = get_preset(preset)
    program, stages = _program(profile, name)
    rng = scenario_rng(name, seed, 1)[0]
    return [
        _gyro_run(
            name, p, seed, rng, program, stages,
            rate_hz=rate_hz or p.rate_hz, latitude_deg=latitude_deg, axis=axis,
            warmed_up=warmed_up,
        )
    ]  # fmt: skip


def scenario_rlg_modelling(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    axis: str = "up",
    preset: str = "rlg",
) -> ScenarioResult:
    """Seed-000 modelling run of the ``rlg`` preset over the ``rlg-modelling`` profile
    (≈ 65 h at 1 Hz by default); powered on at t = 0, soaked at the start temperature."""
    return _single_gyro_scenario(
        "rlg-modelling", seed, profile, rate_hz, latitude_deg, axis, preset, warmed_up=False
    )


def scenario_rlg_validation(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    axis: str = "up",
    preset: str = "rlg",
) -> ScenarioResult:
    """Seed-000 validation run (holds, weakly correlated with ``rlg-modelling``), same
    sensor as :func:`scenario_rlg_modelling`, another turn-on and noise."""
    return _single_gyro_scenario(
        "rlg-validation", seed, profile, rate_hz, latitude_deg, axis, preset, warmed_up=False
    )


def scenario_fog_slow(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    axis: str = "up",
    preset: str = "fog",
) -> ScenarioResult:
    """Seed-001 slow drift over 15–42 °C of a warmed-up ``fog`` (piecewise bias)."""
    return _single_gyro_scenario(
        "fog-slow", seed, profile, rate_hz, latitude_deg, axis, preset, warmed_up=True
    )


def _power_on_windows(profile: ProfileInput, record_s: float) -> tuple[ProgramArrays, list[Stage]]:
    """Power-on windows of a warm-up program: labelled holds of a built-in profile, or for
    program arrays the last ``record_s`` of every hold of at least ``record_s``."""
    if profile is None:
        profile = builtin_profile("mems-warmup", record_s=record_s)
    if isinstance(profile, Profile):
        wins = [s for s in profile.stages() if s.label.startswith(POWER_ON_LABEL)]
        program = profile.knots()
    else:
        program, holds = _program(profile, "mems-warmup")
        wins = [
            Stage(h.end_s - record_s, h.end_s, h.setpoint_c, f"{POWER_ON_LABEL} T{h.setpoint_c:+g}")
            for h in holds
            if h.end_s - h.start_s >= record_s
        ]
    if not wins:
        raise ThermocalInputError(
            f"the warm-up program has no power-on hold (a hold of at least {record_s:g} s)"
        )
    return program, wins


def scenario_mems_warmup(
    seed: int,
    profile: ProfileInput = None,
    *,
    rate_hz: float | None = None,
    record_s: float = 900.0,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    axis: str = "up",
    preset: str = "mems-gyro",
) -> ScenarioResult:
    """Seed-003 warm-ups: one file per start temperature (label ``T+25`` …).

    Each file starts at power-on (t = 0) with the unit soaked at the chamber air
    temperature and lasts the power-on hold (``record_s`` ≥ 360 s for program
    files).  Truth: ``start_temperature_c`` (T0 = T1 at power-on), the warm-up
    coefficients ``a_j(T0)`` and ``start_bias``.
    """
    if record_s < 360:
        raise ThermocalInputError(f"record_s must be ≥ 360 s (seed 003), got {record_s}")
    p = get_preset(preset)
    program, wins = _power_on_windows(profile, record_s)
    hz = rate_hz or p.rate_hz
    rngs = scenario_rng("mems-warmup", seed, len(wins))
    full_t = _time_grid(float(program[0][-1]), 1.0)
    _, air_full = chamber_air(full_t, program[0], program[1], p.chamber)
    results: ScenarioResult = []
    omega = units.earth_rate_on_axis_deg_h(latitude_deg, units.parse_axis(axis))
    for win, rng in zip(wins, rngs, strict=True):
        label = win.label.removeprefix(POWER_ON_LABEL).strip()
        t = _time_grid(win.end_s - win.start_s, hz)
        sp, air = chamber_air(t + win.start_s, program[0], program[1], p.chamber)
        air = air - air[0] + float(np.interp(win.start_s, full_t, air_full))
        temps, rates = simulate_nodes(t, air, p.network, power_on_s=0.0)
        thermal = ThermalResult(
            t, sp, air, temps, rates, p.network.names, p.network.time_constants_s()
        )
        out = simulate_sensor(thermal, p, rng, input_value=omega)
        t0 = float(out.start_temperatures_c[0])
        wu = p.bias_model.warmup
        meta = _metadata(p, "mems-warmup", seed, label, hz, latitude_deg=latitude_deg, axis=axis)
        truth = _truth(
            "mems-warmup", seed, label, p, out, thermal, [],
            input=omega, earth_rate_on_axis_deg_h=omega, latitude_deg=latitude_deg, axis=axis,
            power_on_s=0.0, program_start_s=win.start_s, start_temperature_c=t0,
            warmup_coefficients=wu.a(t0) if wu else [],
            start_bias=wu.start_bias(t0) if wu else 0.0,
        )  # fmt: skip
        results.append((_recording(thermal, out, p, meta), truth))
    return results


ORIENTATIONS: dict[str, float] = {"horizontal": 0.0, "up": 1.0, "down": -1.0}
"""Accelerometer sensitive-axis orientations and their gravity input [g]."""


def scenario_accel_full_range(
    seed: int,
    profile: ProfileInput = None,
    *,
    runs: int = 5,
    rate_hz: float | None = None,
    orientation: str = "horizontal",
    preset: str = "accel",
) -> ScenarioResult:
    """Seed-004 full-range runs: one file per run (label ``run1`` …).

    The program (default ``accel-full-range`` with one repetition) is one run,
    repeated ``runs`` times with a power-on at the start of each.  Each run's bias
    follows one characteristic curve (``curve`` in the truth), assigned as a
    shuffled balanced cycle over the preset's curves, plus the turn-on offset.
    The input is gravity on the sensitive axis (``orientation``: horizontal 0 g,
    up +1 g, down −1 g) in [mg].
    """
    p = get_preset(preset)
    if orientation not in ORIENTATIONS:
        raise ThermocalInputError(
            f"unknown orientation {orientation!r}; known: {', '.join(ORIENTATIONS)}"
        )
    if int(runs) != runs or runs < 1:
        raise ThermocalInputError(f"runs must be an integer ≥ 1, got {runs!r}")
    if profile is None:
        profile = builtin_profile("accel-full-range", repeats=1)
    program, stages = _program(profile, "accel-full-range")
    stages = [dataclasses.replace(s, label=s.label.removeprefix("run1/")) for s in stages]
    hz = rate_hz or p.rate_hz
    rngs = scenario_rng("accel-full-range", seed, int(runs) + 1)
    curves = p.curves or (p.bias_model,)
    assign = rngs[-1].permutation(np.resize(np.arange(len(curves)), int(runs)))
    input_mg = ORIENTATIONS[orientation] * units.G_TO_MG
    t = _time_grid(float(program[0][-1]), hz)
    thermal = simulate_thermal(t, program[0], program[1], p.network, chamber=p.chamber)
    results: ScenarioResult = []
    for i in range(int(runs)):
        label = f"run{i + 1}"
        k = int(assign[i])
        out = simulate_sensor(thermal, p, rngs[i], input_value=input_mg, bias_model=curves[k])
        meta = _metadata(p, "accel-full-range", seed, label, hz, orientation=orientation)
        truth = _truth(
            "accel-full-range", seed, label, p, out, thermal, stages,
            input=input_mg, input_mg=input_mg, orientation=orientation, curve=k,
            n_curves=len(curves), power_on_s=0.0,
        )  # fmt: skip
        results.append((_recording(thermal, out, p, meta), truth))
    return results


def scenario_turntable16(seed: int, profile: ProfileInput = None, **opts: Any) -> ScenarioResult:
    """The 16-position turntable run (SPEC §7), delegated to
    :func:`thermocal.turntable.simulate.simulate_turntable16` (imported lazily)."""
    if profile is not None:
        raise ThermocalInputError("the turntable-16 scenario takes no chamber profile")
    from thermocal.turntable.simulate import simulate_turntable16

    try:
        res: Any = simulate_turntable16(seed=seed, **opts)
    except ThermocalInputError:
        raise
    except ValueError as exc:
        raise ThermocalInputError(f"turntable-16: {exc}") from None
    items = res if isinstance(res, list) else [res]
    out: ScenarioResult = []
    for item in items:
        if isinstance(item, tuple):
            rec, truth = item[0], item[1]
        elif hasattr(item, "recording"):
            rec, truth = item.recording, getattr(item, "truth", {})
        else:
            rec, truth = item, {}
        if not isinstance(rec, Recording):
            raise TypeError("simulate_turntable16 did not return a Recording")
        truth_d: Any = truth
        if dataclasses.is_dataclass(truth) and not isinstance(truth, type):
            truth_d = dataclasses.asdict(truth)
        if not isinstance(truth_d, dict):
            truth_d = {"truth": truth_d}
        out.append(
            (rec, _plain({"scenario": "turntable-16", "seed": int(seed), "label": "", **truth_d}))
        )
    return out


IMU_CHANNELS: tuple[tuple[str, str], ...] = (
    ("gx", "deg/s"),
    ("gy", "deg/s"),
    ("gz", "deg/s"),
    ("ax", "mg"),
    ("ay", "mg"),
    ("az", "mg"),
)
"""The six channels of the MEMS IMU scenario and their units."""
IMU_BIAS_SPAN: dict[str, tuple[float, float, float, float]] = {
    # unit: (constant, linear, quadratic, cubic) spans of b(x) = Σ c_j x^j, x = (T − 25)/40 °C
    "deg/s": (0.2, 0.06, 0.02, 0.015),
    "mg": (30.0, 15.0, 6.0, 4.0),
}
"""Realistic MEMS magnitudes over −15…+65 °C: a few 0.01 °/s and a few 10 mg (consumer and
industrial MEMS data sheets quote 0.01-0.05 °/s/°C·40 °C and 0.1-0.5 mg/°C·40 °C)."""
IMU_NOISE: dict[str, float] = {"deg/s": 0.005, "mg": 0.5}
"""White noise σ per 1 s sample (°/s, mg)."""


def scenario_mems_imu(
    seed: int,
    profile: ProfileInput = None,
    *,
    run: str = "modelling",
    rate_hz: float = 1.0,
    gravity_axis: str = "az",
    preset: str = "mems-gyro",
) -> ScenarioResult:
    """A six-axis MEMS IMU in a chamber (issue 15): three gyros [°/s], three
    accelerometers [mg], one die temperature ``T_die`` (the first node of the preset's
    thermal network, so it lags the chamber air) and the air ``T_chamber``.

    Each channel's temperature-induced bias is a cubic in the die temperature,
    ``b(T) = Σ_j c_j x^j`` with ``x = (T − 25)/40`` and coefficients drawn (per seed) within
    :data:`IMU_BIAS_SPAN`; gravity (+1000 mg) is on ``gravity_axis``; white noise
    :data:`IMU_NOISE`. ``run`` ``"modelling"`` uses the soak-and-ramp program of
    ``rlg-modelling``, ``"validation"`` the weakly correlated ``rlg-validation`` program
    (the same unit: the same coefficients). Truth: ``channels`` {name: {unit, coefficients,
    gravity_mg}} and ``truth_<name>`` columns (the temperature-induced bias alone).
    """
    if run not in ("modelling", "validation"):
        raise ThermocalInputError(f"run must be modelling or validation, got {run!r}")
    names = [n for n, _u in IMU_CHANNELS]
    if gravity_axis not in names[3:]:
        raise ThermocalInputError(f"gravity_axis must be one of {names[3:]}, got {gravity_axis!r}")
    p = get_preset(preset)
    program, stages = _program(profile, f"rlg-{run}")
    t = _time_grid(float(program[0][-1]), rate_hz)
    thermal = simulate_thermal(t, program[0], program[1], p.network, chamber=p.chamber)
    die = thermal.temperatures_c[:, 0]
    coef_rng, *noise_rngs = scenario_rng("mems-imu", seed, 1 + len(IMU_CHANNELS))
    if run == "validation":  # a different noise draw, the same unit (same coefficients)
        noise_rngs = scenario_rng("mems-imu-validation", seed, len(IMU_CHANNELS))
    x = (die - 25.0) / 40.0
    signals: dict[str, npt.ArrayLike] = {}
    other: dict[str, npt.ArrayLike] = {"T_chamber": thermal.air_c, "setpoint_c": thermal.setpoint_c}
    other_units = {"T_chamber": "degC", "setpoint_c": "degC"}
    truth_channels: dict[str, Any] = {}
    for (name, unit), rng in zip(IMU_CHANNELS, noise_rngs, strict=True):
        span = IMU_BIAS_SPAN[unit]
        coef = [float(coef_rng.uniform(-a, a)) for a in span]
        bias = coef[0] + x * (coef[1] + x * (coef[2] + x * coef[3]))
        gravity = 1000.0 if name == gravity_axis else 0.0
        signals[name] = gravity + bias + IMU_NOISE[unit] * rng.standard_normal(t.size)
        other[f"truth_{name}"] = bias - coef[0]
        other_units[f"truth_{name}"] = unit
        truth_channels[name] = {
            "unit": unit,
            "coefficients": coef,
            "x": "(T_die - 25)/40",
            "gravity_mg": gravity,
        }
    meta = Metadata(
        sample_interval_s=1.0 / rate_hz,
        sensor_id="sim-mems-imu-001",
        run_id=f"mems-imu-seed{seed}-{run}",
        notes="simulated by thermocal (mems-imu); truth_<channel> = temperature-induced bias "
        "about its value at 25 °C",
        extra={"scenario": "mems-imu", "seed": int(seed), "label": run},
    )
    rec = Recording.from_arrays(
        t,
        signals=signals,
        temperatures={"T_die": die},
        signal_unit=dict(IMU_CHANNELS),
        other=other,
        other_units=other_units,
        meta=meta,
    )
    truth = _plain_dict(
        {
            "format": TRUTH_FORMAT,
            "version": TRUTH_VERSION,
            "scenario": "mems-imu",
            "seed": int(seed),
            "label": run,
            "sample_rate_hz": float(rate_hz),
            "n_samples": int(t.size),
            "channels": truth_channels,
            "stages": [st.to_dict() for st in stages],
        }
    )
    return [(rec, truth)]


ScenarioFn = Callable[..., ScenarioResult]

SCENARIOS: dict[str, ScenarioFn] = {
    "rlg-modelling": scenario_rlg_modelling,
    "rlg-validation": scenario_rlg_validation,
    "fog-slow": scenario_fog_slow,
    "mems-warmup": scenario_mems_warmup,
    "accel-full-range": scenario_accel_full_range,
    "turntable-16": scenario_turntable16,
    "mems-imu": scenario_mems_imu,
}
"""Registry: scenario name → ``fn(seed, profile=None, **opts) -> [(Recording, truth)]``."""


def run_scenario(
    name: str, seed: int = 0, profile: ProfileInput = None, **opts: Any
) -> ScenarioResult:
    """Run a scenario by name; unknown names and options raise :class:`ThermocalInputError`."""
    try:
        fn = SCENARIOS[name]
    except KeyError:
        raise ThermocalInputError(
            f"unknown scenario {name!r}; known scenarios: {', '.join(SCENARIOS)}"
        ) from None
    try:
        return fn(seed, profile, **opts)
    except TypeError as exc:
        if "unexpected keyword" in str(exc):
            raise ThermocalInputError(f"scenario {name!r}: {exc}") from None
        raise
