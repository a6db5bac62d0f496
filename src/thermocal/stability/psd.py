"""The power spectral density of an IMU axis beside its Allan deviation: Welch's one-sided
estimate in the data's unit/√Hz, its white level read on the flat part, compared with the
white-noise density the Allan deviation gives.

Pure maths on arrays: no file I/O.  Conventions: the one-sided PSD S(f) [unit²/Hz] of
white noise whose Allan variance is ``N²/τ`` is ``S = 2N²`` (its two-sided PSD, IEEE Std
952-1997 Table C.1's ``S_Ω(f) = N²``, folded onto f ≥ 0), so the one-sided amplitude
spectral density (ASD) is ``√2·N`` and ``N = √(S/2)``.  A data sheet's "noise density" is
usually the one-sided ASD: read it as ``√2·N`` when comparing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.recording import Recording
from thermocal.stability.noise_model import SI_UNIT, AxisNoise

FloatArray = npt.NDArray[np.float64]

AGREE: Final = 0.10
"""The PSD's and the ADEV's white levels agree when their ratio is within 1 ± this."""

FLAT: Final = 1.25
"""Bands whose mean PSD lies within this factor of a candidate level (either way) count as
that level's flat part (± 12 % in ASD)."""

LINE_FACTOR: Final = 10.0
"""A frequency bin this many times above the flat level is a line (vibration, a clock):
for a Welch average of K ≥ 8 segments the chance of a bin of white noise this high is
below e^{-10K}·…, nil."""

BANDS_PER_DECADE: Final = 10


@dataclass(frozen=True, eq=False)
class AxisPsd:
    """One axis's PSD and its white level beside the Allan deviation's.

    Attributes
    ----------
    name : str
        The axis.
    unit : str
        The data's unit (the ASD is in ``unit``/√Hz).
    freq_hz : numpy.ndarray
        Frequencies [Hz] (0 excluded).
    asd : numpy.ndarray
        One-sided amplitude spectral density [``unit``/√Hz].
    segments : int
        Welch segments averaged.
    white_asd : float
        The flat part's level, one-sided [``unit``/√Hz].
    white_band_hz : (float, float)
        The flat part [Hz].
    psd_density : float
        N from the PSD, ``white_asd/√2`` in SI [rad/s/√Hz or m/s²/√Hz].
    adev_density : float
        N from the Allan deviation (SI).
    ratio : float
        ``psd_density / adev_density``.
    agree : bool
        ``|ratio − 1| ≤ 0.10``.
    lines_hz : tuple of (float, float)
        Lines found: (frequency [Hz], ASD [``unit``/√Hz]), the strongest first.
    low_rise_hz : float or None
        Below this frequency [Hz] the PSD rises above the flat part (1/f or random-walk
        noise); None when it does not.
    words : str
        The comparison in words: agree, or where and why they disagree.
    """

    name: str
    unit: str
    freq_hz: FloatArray
    asd: FloatArray
    segments: int
    white_asd: float
    white_band_hz: tuple[float, float]
    psd_density: float
    adev_density: float
    ratio: float
    agree: bool
    lines_hz: tuple[tuple[float, float], ...]
    low_rise_hz: float | None
    words: str

    def to_dict(self) -> dict[str, Any]:
        """Plain values without the spectrum: every attribute but ``freq_hz`` and ``asd``.

        Returns
        -------
        dict
        """
        return {
            "name": self.name, "unit": self.unit, "segments": self.segments,
            "white_asd": self.white_asd, "white_asd_unit": f"{self.unit}/sqrt(Hz)",
            "white_band_hz": list(self.white_band_hz), "psd_density": self.psd_density,
            "adev_density": self.adev_density, "ratio": self.ratio, "agree": self.agree,
            "lines_hz": [list(x) for x in self.lines_hz], "low_rise_hz": self.low_rise_hz,
            "words": self.words,
        }  # fmt: skip


def welch_psd(
    values: npt.ArrayLike, tau0_s: float, *, segment_s: float | None = None
) -> tuple[FloatArray, FloatArray, int]:
    """Welch's one-sided PSD of rate samples: Hann windows of 50 % overlap, each segment's
    mean removed.

    Parameters
    ----------
    values : array_like
        Samples [unit], gap-free.
    tau0_s : float
        Sample interval [s].
    segment_s : float, optional
        Segment length [s] (default: the record's 1/16, at most 2¹⁶ samples, at least 256).

    Returns
    -------
    freq_hz : numpy.ndarray
        Frequencies [Hz], 0 excluded.
    psd : numpy.ndarray
        One-sided PSD [unit²/Hz]: ``∫ S df`` over 0…fs/2 is the variance.
    segments : int
        Segments averaged.

    Raises
    ------
    thermocal.errors.ParameterError
        ``tau0_s`` or ``segment_s`` not positive.
    thermocal.errors.ThermocalInputError
        Fewer than 512 samples (or two segments).

    References
    ----------
    .. [1] P. D. Welch, "The use of fast Fourier transform for the estimation of power
       spectra", IEEE Trans. Audio Electroacoust. AU-15 (1967) 70–73.

    Examples
    --------
    White noise of σ = 0.1 at 100 Hz: one-sided PSD 2σ²/fs = 2·10⁻⁴.

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 0.1, 100_000)
    >>> f, s, k = welch_psd(y, 0.01)
    >>> print(f"{s.mean():.3g}")
    0.0002
    """
    from scipy.signal import welch

    if not (math.isfinite(tau0_s) and tau0_s > 0):
        raise ParameterError("tau0_s", f"{{name}} {tau0_s!r}: give the sample interval [s] > 0")
    y = np.asarray(values, dtype=np.float64).ravel()
    if y.size < 512:
        raise ThermocalInputError(f"{y.size} samples: a PSD needs at least 512")
    if segment_s is None:
        nper = int(min(max(256, 2 ** int(math.log2(max(y.size // 16, 1)))), 2**16))
    elif not (math.isfinite(segment_s) and segment_s > 0):
        raise ParameterError("segment_s", f"{{name}} {segment_s!r}: give seconds > 0")
    else:
        nper = round(segment_s / tau0_s)
    if nper < 16 or 2 * nper > y.size:
        raise ThermocalInputError(
            f"a Welch segment of {nper} samples: the record ({y.size}) holds fewer than two"
        )
    f, s = welch(y, fs=1.0 / tau0_s, window="hann", nperseg=nper, noverlap=nper // 2,
                 detrend="constant", scaling="density", return_onesided=True)  # fmt: skip
    k = 1 + (y.size - nper) // (nper - nper // 2)
    return np.asarray(f[1:], dtype=np.float64), np.asarray(s[1:], dtype=np.float64), k


def white_level(freq_hz: npt.ArrayLike, psd: npt.ArrayLike) -> tuple[float, tuple[float, float]]:
    """The PSD's flat part: log-spaced bands (10 a decade, up to 0.8 of the highest
    frequency, clear of an anti-alias filter's edge), the longest run of consecutive bands
    within :data:`FLAT` of one level, its level the mean PSD over the run's frequencies.

    Parameters
    ----------
    freq_hz : array_like
        Frequencies [Hz] (> 0, increasing).
    psd : array_like
        One-sided PSD [unit²/Hz].

    Returns
    -------
    level : float
        The flat part's mean PSD [unit²/Hz].
    band_hz : (float, float)
        Its frequencies [Hz].
    """
    f = np.asarray(freq_hz, dtype=np.float64)
    s = np.asarray(psd, dtype=np.float64)
    top = 0.8 * f[-1]
    edges = np.exp(np.arange(math.log(f[0]), math.log(top), math.log(10) / BANDS_PER_DECADE))
    edges = np.append(edges, top)
    idx = np.searchsorted(edges, f, side="right") - 1
    ok = (idx >= 0) & (idx < edges.size - 1)
    bands = [np.flatnonzero(ok & (idx == b)) for b in range(edges.size - 1)]
    bands = [b for b in bands if b.size]
    means = np.array([float(s[b].mean()) for b in bands])
    best = (0, 0, 0)  # (length, start, stop)
    for i, lev in enumerate(means):
        inside = (means <= lev * FLAT) & (means >= lev / FLAT)
        lo = hi = i
        while lo > 0 and inside[lo - 1]:
            lo -= 1
        while hi < means.size - 1 and inside[hi + 1]:
            hi += 1
        if hi - lo + 1 > best[0]:
            best = (hi - lo + 1, lo, hi)
    sel = np.concatenate(bands[best[1] : best[2] + 1])
    return float(s[sel].mean()), (float(f[sel[0]]), float(f[sel[-1]]))


def axis_psd(
    values: npt.ArrayLike, tau0_s: float, ax: AxisNoise, *, segment_s: float | None = None
) -> AxisPsd:
    """An axis's PSD, its white level, and the comparison with the Allan deviation's N.

    Parameters
    ----------
    values : array_like
        The axis's samples [``ax.unit``], gap-free.
    tau0_s : float
        Sample interval [s].
    ax : AxisNoise
        The axis's Allan analysis (:func:`thermocal.stability.noise_model.axis_noise`).
    segment_s : float, optional
        Welch segment length [s] (default :func:`welch_psd`'s).

    Returns
    -------
    AxisPsd
        The spectrum, its white level, lines, low-frequency rise and the comparison.

    Notes
    -----
    .. math:: N_{PSD} = \\sqrt{\\bar S / 2},\\qquad
              \\text{agree} \\iff |N_{PSD}/N_{ADEV} - 1| \\le 0.10

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C (Table C.1: S_Ω(f) = N² two-sided).
    .. [2] P. D. Welch (1967), see :func:`welch_psd`.

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.stability.noise_model import axis_noise
    >>> y = np.random.default_rng(0).normal(0.0, 0.01, 20_000)
    >>> ax = axis_noise(y, 0.01, name="gx", sensor="gyro", unit="rad/s")
    >>> p = axis_psd(y, 0.01, ax)
    >>> print(round(p.ratio, 2), p.agree)
    1.0 True
    """
    f, s, k = welch_psd(values, tau0_s, segment_s=segment_s)
    level, band = white_level(f, s)
    si = float(units.convert(1.0, ax.unit, SI_UNIT[ax.sensor]))
    n_psd = math.sqrt(level / 2.0) * si
    n_adev = ax.density.value
    ratio = n_psd / n_adev
    lines = _lines(f, s, level)
    rise = _low_rise(f, s, level, band, lines)
    words = _words(ratio, ax, lines, rise, band)
    return AxisPsd(ax.name, ax.unit, f, np.sqrt(s), k, math.sqrt(level), band, n_psd,
                   n_adev, ratio, abs(ratio - 1.0) <= AGREE, lines, rise, words)  # fmt: skip


def _lines(f: FloatArray, s: FloatArray, level: float) -> tuple[tuple[float, float], ...]:
    """Narrow peaks: local maxima :data:`LINE_FACTOR` above the flat level and 5× the
    median of the 16 bins around them (a rising 1/f or random-walk floor is no line),
    strongest first."""
    out = []
    for i in np.flatnonzero(s > LINE_FACTOR * level):
        if i < 2 or s[i] < s[i - 1] or (i < s.size - 1 and s[i] < s[i + 1]):
            continue  # the first bins cannot tell a line from a rising floor
        around = np.concatenate((s[max(i - 9, 0) : max(i - 1, 0)], s[i + 2 : i + 10]))
        if around.size and s[i] > 5.0 * float(np.median(around)):
            out.append(int(i))
    out.sort(key=lambda i: -s[i])
    return tuple((float(f[i]), float(math.sqrt(s[i]))) for i in out[:5])


def _low_rise(
    f: FloatArray,
    s: FloatArray,
    level: float,
    band: tuple[float, float],
    lines: tuple[tuple[float, float], ...],
) -> float | None:
    """The highest frequency below the flat part where 5 bins in a row (lines left out)
    average 2× the level."""
    keep = f < band[0]
    for fl, _ in lines:
        keep &= np.abs(f - fl) > 3.0 * (f[1] - f[0])
    below = np.flatnonzero(keep)
    if below.size < 5:
        return None
    sm = np.convolve(s[below], np.ones(5) / 5.0, mode="valid")
    up = np.flatnonzero(sm > 2.0 * level)
    return None if up.size == 0 else float(f[below[up[-1] + 2]])


def _words(
    ratio: float,
    ax: AxisNoise,
    lines: tuple[tuple[float, float], ...],
    rise: float | None,
    band: tuple[float, float],
) -> str:
    """Agree, or where and why the PSD and the ADEV disagree."""
    head = f"PSD's white level / ADEV's = {ratio:.3f} (flat part {band[0]:.3g}…{band[1]:.3g} Hz)"
    if abs(ratio - 1.0) <= AGREE:
        out = head + ": agree within 10 %"
    else:
        rng = ax.density.tau_range_s
        where = (f"the ADEV's −½ stretch τ {rng[0]:.3g}…{rng[1]:.3g} s looks at "
                 f"f ≈ {1 / (2 * rng[1]):.3g}…{1 / (2 * rng[0]):.3g} Hz") if rng else (
                 "the ADEV's white level comes from its fit")  # fmt: skip
        out = head + f": DISAGREE; {where}"
    if lines:
        out += "; lines at " + ", ".join(f"{x:.4g} Hz" for x, _ in lines[:3])
        out += " (a line raises the ADEV near τ ≈ 1/(2f) but not the PSD's flat part)"
    if rise is not None:
        out += (f"; the PSD rises below {rise:.3g} Hz (1/f or random-walk noise: only above "
                "it is the PSD's flat part white noise alone)")  # fmt: skip
    return out


def imu_psd(
    rec: Recording, axes: Sequence[AxisNoise], *, segment_s: float | None = None
) -> tuple[AxisPsd, ...]:
    """Every axis's PSD on the record's longest gap-free stretch, beside its ADEV.

    Parameters
    ----------
    rec : Recording
        The recording.
    axes : sequence of AxisNoise
        Each axis's Allan analysis (in the data's unit).
    segment_s : float, optional
        Welch segment length [s].

    Returns
    -------
    tuple of AxisPsd
    """
    from thermocal.stability.analysis import signal_in_data_unit

    seg = max(rec.segments(), key=lambda sl: sl.stop - sl.start)
    out = []
    for ax in axes:
        values, _unit = signal_in_data_unit(rec, ax.name)
        out.append(axis_psd(values[seg], rec.sample_interval_s, ax, segment_s=segment_s))
    return tuple(out)
