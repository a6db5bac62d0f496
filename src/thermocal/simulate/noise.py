"""Sensor noise by IEEE Std 952-1997 Annex C: white, flicker, random walks and ramps.

Part of :mod:`thermocal.simulate`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule

if TYPE_CHECKING:
    import scipy.fft as sfft
else:
    sfft = LazyModule("scipy.fft")

FloatArray = npt.NDArray[np.float64]
ProgramArrays = tuple[FloatArray, FloatArray]
Truth = dict[str, Any]


# --- noise (IEEE Std 952-1997 Annex C) -----------------------------------------------------------


@dataclass(frozen=True)
class NoiseParams:
    r"""Noise terms of a sensor output, in its unit ``u`` (°/h or mg).

    Parameters
    ----------
    white_density : float
        N [u·√s] = [u/√Hz], two-sided PSD N² (angle or velocity random walk; a gyro ARW of
        N' [°/√h] is N = 60·N' [°/h·√s]).
    bias_instability : float
        B [u], flicker noise of PSD B²/(2πf).
    rate_random_walk : float
        K [u/√s].
    rate_ramp : float
        R [u/s].
    resolution : float
        Output LSB [u] (0: none); pulse outputs are quantized by the scale factor instead.
    white_density_per_c : float
        Relative change of N per °C [1/°C] (0: none): at temperature T the white-noise
        density is ``N·(1 + white_density_per_c·(T − white_reference_c))`` (a MEMS
        sensor's noise grows with temperature), when the temperature is given.
    white_reference_c : float
        The temperature at which the density is N [°C] (default 25).

    Notes
    -----
    The Allan variance of each term, as IEEE Std 952-1997 Annex C gives it:

    .. math::

        \sigma^2(\tau) = \frac{N^2}{\tau} + \frac{2\ln 2}{\pi}B^2
        + \frac{K^2\tau}{3} + \frac{R^2\tau^2}{2},

    so that the flicker plateau is :math:`\sqrt{2\ln 2/\pi}\,B \approx 0.664\,B`.

    References
    ----------
    IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for
    Single-Axis Interferometric Fiber Optic Gyros*, Annex C.

    W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065, 2008.
    """

    white_density: float = 0.0
    bias_instability: float = 0.0
    rate_random_walk: float = 0.0
    rate_ramp: float = 0.0
    resolution: float = 0.0
    white_density_per_c: float = 0.0
    white_reference_c: float = 25.0


def flicker_noise(n: int, dt_s: float, b: float, rng: np.random.Generator) -> FloatArray:
    r"""Flicker (1/f) noise of two-sided PSD ``S(f) = B²/(2πf)`` (IEEE 952 bias instability).

    Parameters
    ----------
    n : int
        Number of samples.
    dt_s : float
        Sample interval τ0 [s].
    b : float
        Bias instability coefficient B [unit of the output].
    rng : numpy.random.Generator
        The source of the random numbers.

    Returns
    -------
    numpy.ndarray
        The noise (n,) [unit of B].

    Notes
    -----
    Spectral synthesis on the FFT grid :math:`f_k`:

    .. math::

        X_k = \sqrt{N f_s S(f_k)/2}\,(a_k + i b_k),\quad a_k, b_k \sim N(0, 1),
        \qquad x = \mathrm{irfft}(X),

    so that :math:`E|X_k|^2 = N f_s S(f_k)`; the DC bin is zero.  Its Allan deviation is
    flat at :math:`\sqrt{2\ln 2/\pi}\,B \approx 0.664\,B`.

    References
    ----------
    IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for
    Single-Axis Interferometric Fiber Optic Gyros*, Annex C.

    W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST Special Publication 1065,
    2008.
    """
    if b == 0.0 or n == 0:
        return np.zeros(n)
    nfft = int(sfft.next_fast_len(n, real=True))
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
    x = sfft.irfft(spec, nfft, workers=-1, overwrite_x=True)
    return np.asarray(x[:n], dtype=np.float64)


FLICKER_MAX_RATE_HZ = 10.0
"""Flicker noise is synthesised at this rate at most (held constant within each block)."""


def simulate_noise(
    n: int,
    dt_s: float,
    noise: NoiseParams,
    rng: np.random.Generator,
    temperature_c: npt.ArrayLike | None = None,
) -> FloatArray:
    r"""The noise of a sensor output: white, flicker, rate random walk and rate ramp.

    White noise of standard deviation N/√τ0 per sample, flicker (:func:`flicker_noise`,
    synthesised at most at :data:`FLICKER_MAX_RATE_HZ`), rate random walk (cumulative
    sum of N(0, K² τ0)) and rate ramp (R·t).  Samples are mean rates over each interval.

    Parameters
    ----------
    n : int
        Number of samples.
    dt_s : float
        Sample interval τ0 [s].
    noise : NoiseParams
        The noise terms N, B, K, R.
    rng : numpy.random.Generator
        The source of the random numbers.
    temperature_c : array_like, optional
        The sensor's temperature at each sample [°C]: the white noise's density follows it
        by ``noise.white_density_per_c`` (ignored when that is 0).

    Returns
    -------
    numpy.ndarray
        The noise (n,) [unit of the terms].

    Notes
    -----
    The Allan variance of the sum is that of IEEE Std 952-1997 Annex C,

    .. math::

        \sigma^2(\tau) = \frac{N^2}{\tau} + \frac{2\ln 2}{\pi}B^2
        + \frac{K^2\tau}{3} + \frac{R^2\tau^2}{2} .

    References
    ----------
    IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for
    Single-Axis Interferometric Fiber Optic Gyros*, Annex C.

    W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST Special Publication 1065,
    2008.

    Examples
    --------
    White noise of N = 0.1 [unit·√s] at τ0 = 0.01 s has a standard deviation
    N/√τ0 = 1 per sample:

    >>> import numpy as np
    >>> y = simulate_noise(200_000, 0.01, NoiseParams(white_density=0.1),
    ...                    np.random.default_rng(0))
    >>> round(float(y.std()), 2)
    1.0
    """
    if noise.white_density:
        out = rng.standard_normal(n)
        out *= noise.white_density / math.sqrt(dt_s)
        if noise.white_density_per_c and temperature_c is not None:
            dt_c = np.asarray(temperature_c, dtype=np.float64) - noise.white_reference_c
            out *= np.maximum(1.0 + noise.white_density_per_c * dt_c, 0.0)
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
