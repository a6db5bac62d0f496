"""Periodic terms of a static record: sinusoids found in its spectrum, named with their
frequency where the Allan deviation shows them.

Pure maths (numpy only; no file I/O).

A sinusoid ``A·sin(2π f₀ t)`` in rate data has the Allan deviation (IEEE Std 952-1997
Annex C.1.7)::

    σ(τ) = A · sin²(π f₀ τ) / (π f₀ τ)

largest, 0.7246·A, at τ = 0.3710/f₀; the noise model σ² = Σ C_p τ^p has no such bump, so
its fit is poor there.  The sinusoid is found in Welch's averaged periodogram (P. D. Welch,
IEEE Trans. Audio Electroacoust. 15(2), 1967; Hann windows, half-overlapping segments):
a bin whose power density stands above the median of its neighbourhood (the local noise
floor) beyond the chi-square quantile of the periodogram's degrees of freedom at a 1 %
family-wise false-alarm probability over the bins (and at least 10×).  Its power is the
density summed over the peak's bins above the floor, ``P = Σ (S − floor)·Δf``, so
``A = √(2P)``; its frequency the power-weighted centroid of those bins.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal.stability.quantiles import chi2_isf

SINE_PEAK_TAU: Final = 0.3710
"""τ·f₀ at which a sinusoid's Allan deviation A·sin²(πf₀τ)/(πf₀τ) is largest."""

SINE_PEAK_FACTOR: Final = 0.7246
"""The largest Allan deviation of a sinusoid of amplitude A is 0.7246·A (IEEE 952 C.1.7)."""

PERIODIC_FALSE_ALARM: Final = 0.01
"""Family-wise probability that noise alone makes a peak of the periodogram."""

PERIODIC_MIN_RATIO: Final = 10.0
"""A peak stands at least this many times above its local floor."""

PERIODIC_MIN_SHARE: Final = 0.05
"""A periodic term is named when its ADEV bump holds at least this share of the measured
Allan variance at τ = 0.371/f₀ (a smaller line does not shape the curve)."""

_MIN_SEGMENTS: Final = 8
"""Welch segments at least (the floor's estimate needs averages)."""

_FLOOR_BINS: Final = 32
"""The local floor: the median density over this many bins either side."""

_MAX_SAMPLES: Final = 1 << 23
"""The periodogram reads at most this many samples (the first): 8.4 million give hundreds of
segments at the longest segment length, and a day at 1 kHz costs no more than that."""

_PEAK_BINS: Final = 3
"""Bins either side of a peak's maximum that hold its power (a Hann window's main lobe
spans ±2 bins)."""


@dataclass(frozen=True)
class PeriodicTerm:
    """A sinusoid found in the record.

    ``frequency_hz`` f₀ [Hz] and its resolution ``resolution_hz`` (the periodogram's bin);
    ``amplitude`` A [``unit``]; ``ratio`` the peak's density over the local floor;
    ``tau_peak_s`` 0.3710/f₀ [s] where its Allan deviation ``adev_peak`` = 0.7246·A
    [``unit``] is largest; ``share`` that bump's share of the measured Allan variance
    there (None when not compared).

    Attributes
    ----------
    frequency_hz : float
        Frequency f₀ of the sinusoid [Hz].
    resolution_hz : float
        The periodogram's bin width [Hz].
    amplitude : float
        Amplitude A [``unit``].
    unit : str
        Unit of the record.
    ratio : float
        The peak's density over the local floor of the periodogram.
    tau_peak_s : float
        0.3710/f₀ [s], where the sinusoid's Allan deviation is largest.
    adev_peak : float
        0.7246·A [``unit``], that largest Allan deviation.
    share : float or None
        The bump's share of the measured Allan variance at ``tau_peak_s`` (None: not compared).
    """

    frequency_hz: float
    resolution_hz: float
    amplitude: float
    unit: str
    ratio: float
    tau_peak_s: float
    adev_peak: float
    share: float | None = None

    def adev(self, tau_s: npt.ArrayLike) -> npt.NDArray[np.float64]:
        r"""The sinusoid's Allan deviation A·sin²(πf₀τ)/(πf₀τ) [unit] at ``tau_s`` [s].

        Parameters
        ----------
        tau_s : array_like
            Averaging times [s].

        Returns
        -------
        numpy.ndarray
            Allan deviation [unit].

        Notes
        -----
        .. math:: \sigma(\tau) = A \sin^2(\pi f_0 \tau) / (\pi f_0 \tau)

        References
        ----------
        - IEEE Std 952-1997, Annex C.1.7 (sinusoidal noise).
        """
        x = math.pi * self.frequency_hz * np.asarray(tau_s, dtype=np.float64)
        return np.asarray(self.amplitude * np.sin(x) ** 2 / x)

    def adev_bound(self, tau_s: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The most the sinusoid adds to the Allan deviation [unit] at ``tau_s`` [s]: its
        own curve A·sin²(πf₀τ)/(πf₀τ) up to its first maximum region (πf₀τ ≤ π/2), its
        envelope A/(πf₀τ) beyond, where f₀'s resolution leaves the zeros' places unknown.

        Parameters
        ----------
        tau_s : array_like
            Averaging times [s].

        Returns
        -------
        numpy.ndarray
            Upper bound of the Allan deviation [unit].
        """
        x = math.pi * self.frequency_hz * np.asarray(tau_s, dtype=np.float64)
        return np.asarray(
            np.where(x <= math.pi / 2, self.amplitude * np.sin(x) ** 2 / x, self.amplitude / x)
        )

    def words(self) -> str:
        """The term in words, for reasons and text output."""
        return (
            f"a periodic term at {self.frequency_hz:.4g} Hz (± {self.resolution_hz:.2g}), "
            f"amplitude {self.amplitude:.4g} {self.unit}: its Allan deviation "
            f"A·sin²(πf₀τ)/(πf₀τ) peaks at {self.adev_peak:.4g} {self.unit} at τ = "
            f"{self.tau_peak_s:.4g} s (IEEE 952 C.1.7)"
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the term."""
        return {
            "frequency_hz": self.frequency_hz,
            "resolution_hz": self.resolution_hz,
            "amplitude": self.amplitude,
            "unit": self.unit,
            "ratio": self.ratio,
            "tau_peak_s": self.tau_peak_s,
            "adev_peak": self.adev_peak,
            "share": self.share,
            "source": "Welch periodogram peak above the local floor; Allan deviation "
            "A·sin²(πf₀τ)/(πf₀τ) (IEEE Std 952-1997 C.1.7)",
        }


def welch(
    x: npt.NDArray[np.float64], fs: float, seg: int
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], int]:
    r"""Welch's one-sided power spectral density [unit²/Hz] of ``x`` sampled at ``fs`` [Hz]:
    Hann segments of ``seg`` samples overlapping by half, each with its least-squares line
    removed, ``S = 2 |X|² / (fs Σw²)`` averaged (DC and Nyquist not doubled), as
    ``scipy.signal.welch(x, fs, "hann", seg, detrend="linear")`` (numpy only: scipy.signal
    costs a command two seconds of import).  Returns (frequencies, S, segments).

    The line is removed in the frequency domain, where it is two known spectra: with
    ``t`` the segment's centred sample index, ``a`` its mean and ``b = Σ s·t / Σ t²`` its
    slope, ``rfft(w·(s − a − b·t)) = rfft(w·s) − a·rfft(w) − b·rfft(w·t)``; the periodic
    Hann window's ``rfft(w)`` is ``seg/2`` at DC, ``−seg/4`` at the first bin and 0 beyond.
    One pass over the samples (the window) instead of four.

    Parameters
    ----------
    x : numpy.ndarray
        Samples [unit].
    fs : float
        Sample rate [Hz].
    seg : int
        Segment length [samples].

    Returns
    -------
    tuple
        Frequencies [Hz], PSD [unit²/Hz], number of segments.

    Notes
    -----
    .. math:: S = 2 |X|^2 / (f_s \textstyle\sum w^2), \quad
              X = \mathrm{rfft}(w s) - a\,\mathrm{rfft}(w) - b\,\mathrm{rfft}(w t)

    References
    ----------
    - Welch, P. D. (1967), IEEE Trans. Audio Electroacoust. 15(2), 70–73.
    """
    step = seg // 2
    n_seg = (x.size - seg) // step + 1
    nf = seg // 2 + 1
    w = 0.5 - 0.5 * np.cos(2.0 * math.pi * np.arange(seg) / seg)  # periodic Hann
    t = np.arange(seg, dtype=np.float64) - (seg - 1) / 2.0
    slope_spectrum = np.fft.rfft(w * t) / float(t @ t)  # rfft(w·t) per unit of Σ s·t
    sums, moments = _segment_moments(x, seg, step, n_seg, t)
    view = np.lib.stride_tricks.sliding_window_view(x, seg)[::step][:n_seg]
    rows = min(_WELCH_ROWS, n_seg)  # segments a block, in reused buffers (no page faults)
    buf, spec = np.empty((rows, seg)), np.empty((rows, nf), dtype=np.complex128)
    line = np.empty(nf, dtype=np.complex128)
    acc = np.zeros(2 * nf)  # Σ Re², Σ Im² per bin
    for a in range(0, n_seg, rows):
        k = min(rows, n_seg - a)
        block, sp = buf[:k], spec[:k]
        np.multiply(view[a : a + k], w, out=block)
        if _RFFT_OUT:
            np.fft.rfft(block, axis=1, out=sp)
        else:  # numpy < 2 has no ``out``: the same transform, its result copied
            sp[...] = np.fft.rfft(block, axis=1)
        for r in range(k):
            np.multiply(slope_spectrum, moments[a + r], out=line)
            np.subtract(sp[r], line, out=sp[r])
        mean = sums[a : a + k] / seg
        sp[:, 0] -= mean * (seg / 2.0)
        if nf > 1:
            sp[:, 1] += mean * (seg / 4.0)
        flat = sp.view(np.float64)
        acc += np.einsum("ij,ij->j", flat, flat)
    psd = (acc[0::2] + acc[1::2]) / n_seg * 2.0 / (fs * float(w @ w))
    psd[0] /= 2.0
    if seg % 2 == 0:
        psd[-1] /= 2.0
    return np.asarray(np.fft.rfftfreq(seg, 1.0 / fs), dtype=np.float64), psd, n_seg


_RFFT_OUT: Final = np.lib.NumpyVersion(np.__version__) >= "2.0.0"
"""``numpy.fft.rfft`` takes ``out`` from numpy 2.0 (the floor, 1.26, does not)."""

_WELCH_ROWS: Final = 8
"""Segments :func:`welch` transforms at a time (8 of 65 536 samples: 4 MB, in the cache)."""


def _segment_moments(
    x: npt.NDArray[np.float64], seg: int, step: int, n_seg: int, t: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Per Welch segment ``i`` (samples ``i·step … i·step + seg``) the sum Σ s and the moment
    Σ s·t about its centre: from the half-segments in one matrix product when the segment
    is two of them (``seg`` even), else segment by segment."""
    if seg == 2 * step and n_seg >= 1:
        halves = x[: (n_seg + 1) * step].reshape(n_seg + 1, step)
        basis = np.empty((step, 3))
        basis[:, 0], basis[:, 1], basis[:, 2] = 1.0, t[:step], t[step:]
        q = halves @ basis
        return q[:-1, 0] + q[1:, 0], q[:-1, 1] + q[1:, 2]
    view = np.lib.stride_tricks.sliding_window_view(x, seg)[::step][:n_seg]
    both = np.array([[float(row.sum()), float(row @ t)] for row in view]).reshape(-1, 2)
    return both[:, 0], both[:, 1]


def _running_median(x: npt.NDArray[np.float64], half: int) -> npt.NDArray[np.float64]:
    """The median of ``x`` over ``[i − half, i + half]`` (clipped at the ends): the middle
    of the ``2·half + 1`` values once partitioned (an odd count: the median itself), in
    blocks of reused rows."""
    pad = np.pad(x, half, mode="reflect")
    win = np.lib.stride_tricks.sliding_window_view(pad, 2 * half + 1)
    out = np.empty(x.size)
    rows = 4096
    buf = np.empty((min(rows, x.size), 2 * half + 1))
    for a in range(0, x.size, rows):
        block = buf[: min(rows, x.size - a)]
        block[...] = win[a : a + rows]
        block.partition(half, axis=1)
        out[a : a + rows] = block[:, half]
    return out


def periodic_terms(
    values: npt.ArrayLike, tau0_s: float, unit: str, *, max_terms: int = 3
) -> tuple[PeriodicTerm, ...]:
    """The sinusoids of a rate record ``values`` [``unit``] sampled every ``tau0_s`` [s]
    (module docstring), strongest first, at most ``max_terms``; () when none stands out or
    the record is too short for :data:`_MIN_SEGMENTS` segments of 256 samples.

    Gaps are the caller's: pass one contiguous stretch (its first :data:`_MAX_SAMPLES`
    samples are read).

    Parameters
    ----------
    values : array_like
        Rate samples [``unit``].
    tau0_s : float
        Sample interval [s].
    unit : str
        Rate unit.
    max_terms : int, optional
        Most sinusoids returned (default 3).

    Returns
    -------
    tuple of PeriodicTerm
        The sinusoids, strongest first.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(20_000) * 0.1
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, t.size) + 5.0 * np.sin(np.pi * t)
    >>> (p,) = periodic_terms(y, 0.1, "deg/h")
    >>> print(f"{p.frequency_hz:.3g} Hz, {p.amplitude:.3g} {p.unit}")
    0.5 Hz, 5 deg/h
    """
    x = np.asarray(values, dtype=np.float64).ravel()[:_MAX_SAMPLES]
    with np.errstate(over="ignore", invalid="ignore"):
        all_finite = math.isfinite(float(np.add.reduce(x))) if x.size else True
    if not all_finite:  # else the record's own buffer is read (no 67 MB copy)
        x = x[np.isfinite(x)]
    if x.size < 256 * _MIN_SEGMENTS:
        return ()
    fs = 1.0 / tau0_s
    seg = 1 << math.floor(math.log2(x.size / _MIN_SEGMENTS))
    seg = min(seg, 1 << 16)
    f, s, n_seg = welch(x, fs, seg)
    df = float(f[1] - f[0])
    dof = max(2.0, 2.0 * n_seg * 0.9)  # Hann, half overlap: ≈ 0.9 of the independent dof
    floor = _running_median(s, _FLOOR_BINS) / (1.0 - 2.0 / (9.0 * dof)) ** 3  # median→mean
    usable = np.arange(f.size) > 2 * _PEAK_BINS  # away from DC (drifts, the window's leak)
    usable &= np.arange(f.size) < f.size - 1
    n_bins = int(usable.sum())
    if n_bins < 8:
        return ()
    thresh = float(chi2_isf(PERIODIC_FALSE_ALARM / n_bins, dof)) / dof
    thresh = max(thresh, PERIODIC_MIN_RATIO)
    ratio = np.where(usable & (floor > 0), s / np.where(floor > 0, floor, 1.0), 0.0)
    found: list[PeriodicTerm] = []
    taken = np.zeros(f.size, dtype=bool)
    for k in np.argsort(ratio)[::-1]:
        if ratio[k] < thresh or len(found) >= max_terms:
            break
        if taken[k]:
            continue
        lo, hi = max(k - _PEAK_BINS, 0), min(k + _PEAK_BINS + 1, f.size)
        taken[max(k - 2 * _PEAK_BINS, 0) : hi + _PEAK_BINS] = True
        excess = np.maximum(s[lo:hi] - floor[lo:hi], 0.0)
        power = float(excess.sum()) * df
        f0 = float(np.sum(excess * f[lo:hi]) / excess.sum())
        amp = math.sqrt(2.0 * power)
        found.append(
            PeriodicTerm(
                frequency_hz=f0, resolution_hz=df, amplitude=amp, unit=unit,
                ratio=float(ratio[k]), tau_peak_s=SINE_PEAK_TAU / f0,
                adev_peak=SINE_PEAK_FACTOR * amp,
            )
        )  # fmt: skip
    return tuple(found)


def shaping_terms(
    found: tuple[PeriodicTerm, ...], tau_s: npt.ArrayLike, adev: npt.ArrayLike
) -> tuple[PeriodicTerm, ...]:
    """The terms of ``found`` whose Allan deviation bump holds at least
    :data:`PERIODIC_MIN_SHARE` of the measured Allan variance ``adev`` [unit] at the τ
    [s] nearest (in log) to their ``tau_peak_s``, each with its ``share``.

    Parameters
    ----------
    found : tuple of PeriodicTerm
        Sinusoids found.
    tau_s : array_like
        Averaging times [s].
    adev : array_like
        Measured Allan deviation [unit].

    Returns
    -------
    tuple of PeriodicTerm
        The terms that shape the curve, each with its share.
    """
    tau = np.asarray(tau_s, dtype=np.float64)
    dev = np.asarray(adev, dtype=np.float64)
    ok = np.isfinite(dev) & (dev > 0)
    if not ok.any():
        return ()
    tau, dev = tau[ok], dev[ok]
    out = []
    for p in found:
        k = int(np.argmin(np.abs(np.log(tau / p.tau_peak_s))))
        share = float(p.adev(tau[k])[()] ** 2 / dev[k] ** 2)
        if share >= PERIODIC_MIN_SHARE:
            out.append(
                PeriodicTerm(
                    p.frequency_hz, p.resolution_hz, p.amplitude, p.unit, p.ratio,
                    p.tau_peak_s, p.adev_peak, min(share, 1.0),
                )
            )  # fmt: skip
    return tuple(out)


__all__ = [
    "PERIODIC_FALSE_ALARM",
    "PERIODIC_MIN_RATIO",
    "PERIODIC_MIN_SHARE",
    "SINE_PEAK_FACTOR",
    "SINE_PEAK_TAU",
    "PeriodicTerm",
    "periodic_terms",
    "shaping_terms",
    "welch",
]
