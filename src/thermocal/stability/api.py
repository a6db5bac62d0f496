"""Frequency stability of a numpy array: the deviation family and the IEEE 952 noise terms.

The calls a notebook user makes with an array of rate (or phase) samples and a sample rate,
in the manner of allantools (``allantools.oadev(y, rate=…, data_type="freq", taus=…)``):
:func:`deviation` (any registered deviation, :mod:`.registry`), one function per deviation
(:func:`oadev`, :func:`mdev`, …: NIST SP 1065 [1]_, intervals from Greenhall and Riley's
EDF [3]_) and :func:`allan_noise` (the IEEE 952 noise terms [2]_).  Each returns a
frozen result with ``to_dict()`` and ``to_frame()``.  The recording-based analysis
(:func:`thermocal.stability.analysis.allan_analysis`, ``thermocal allan``) computes the same
numbers through the same functions.

References
----------
.. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special Publication
   1065, 2008.
.. [2] IEEE Std 952-1997, "IEEE Standard Specification Format Guide and Test Procedure for
   Single-Axis Interferometric Fiber Optic Gyros", Annex C.
.. [3] C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on finite
   differences", Proc. 35th PTTI Meeting, 2003.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError
from thermocal.stability import allan, family, registry
from thermocal.stability.edf import ONE_SIGMA_CONFIDENCE

if TYPE_CHECKING:
    import pandas as pd

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

TauSet = Literal["octave", "decade", "log", "all"]
"""A named set of averaging factors: ``octave`` m = 1, 2, 4, …; ``decade`` 1, 2, 4, 10, 20,
40, …; ``log`` about ten per decade; ``all`` every m."""

DataType = Literal["freq", "rate", "phase"]
"""``freq`` (allantools' word) and ``rate``: samples each the mean over τ0 (a gyro's rate, a
fractional frequency); ``phase``: the integral (an angle, a time error)."""

TAU_SETS: tuple[TauSet, ...] = ("octave", "decade", "log", "all")
"""The named τ sets (:data:`TauSet`)."""


@dataclass(frozen=True, eq=False)
class DeviationResult:
    """One deviation against τ, with its chi-square interval.

    Parameters
    ----------
    name : str
        The deviation (:func:`thermocal.stability.registry.names`).
    tau_s : numpy.ndarray
        Averaging times τ [s] (Theo1: 0.75 m τ0).
    m : numpy.ndarray
        Averaging factors.
    dev : numpy.ndarray
        The deviation [``unit``] (NaN where the record gives no term).
    low, high : numpy.ndarray
        Its interval at ``confidence`` [``unit``] (NaN where the deviation has none).
    edf : numpy.ndarray
        Equivalent degrees of freedom of each point.
    n_terms : numpy.ndarray
        Terms (differences, subsequences, windows) behind each point.
    alpha : numpy.ndarray
        Power-law noise exponent α (S_y(f) ∝ f^α) used for the EDF.
    alpha_method : tuple of str
        How each α was found (``lag1``, ``b1``, ``b1-rn``, ``b1-previous``, ``previous``,
        ``given``).
    unit : str
        Unit of ``dev`` (the data's, times s for a time deviation of rate data).
    confidence : float
        Confidence level of ``low``/``high`` (0.683: ±1σ).
    data_type : str
        ``rate`` or ``phase``.
    rate_hz : float
        Sample rate [Hz].
    bias : numpy.ndarray or None
        Stable32's bias factor ``dev`` was multiplied by (None when not asked).
    """

    name: str
    tau_s: FloatArray
    m: IntArray
    dev: FloatArray
    low: FloatArray
    high: FloatArray
    edf: FloatArray
    n_terms: FloatArray
    alpha: IntArray
    alpha_method: tuple[str, ...]
    unit: str
    confidence: float
    data_type: str
    rate_hz: float
    bias: FloatArray | None = None

    def to_dict(self) -> dict[str, Any]:
        """The result as plain Python values (lists of floats; JSON-ready but for NaN)."""
        out: dict[str, Any] = {
            "name": self.name,
            "unit": self.unit,
            "confidence": self.confidence,
            "data_type": self.data_type,
            "rate_hz": self.rate_hz,
        }
        out.update({k: v.tolist() for k, v in self._columns().items()})
        out["alpha_method"] = list(self.alpha_method)
        return out

    def _columns(self) -> dict[str, npt.NDArray[Any]]:
        """The per-τ columns, in table order."""
        cols: dict[str, npt.NDArray[Any]] = {
            "tau_s": self.tau_s, "m": self.m, "dev": self.dev, "low": self.low,
            "high": self.high, "edf": self.edf, "n_terms": self.n_terms, "alpha": self.alpha,
        }  # fmt: skip
        if self.bias is not None:
            cols["bias"] = self.bias
        return cols

    def to_frame(self) -> pd.DataFrame:
        """The result as a pandas DataFrame, one row per τ (pandas must be installed)."""
        import pandas

        frame = pandas.DataFrame(self._columns())
        frame["alpha_method"] = list(self.alpha_method)
        frame.attrs.update(name=self.name, unit=self.unit, confidence=self.confidence)
        return frame


def _tau0(rate_hz: float) -> float:
    """The sample interval 1/rate_hz [s], the rate checked."""
    if isinstance(rate_hz, bool) or not isinstance(rate_hz, int | float | np.number):
        raise ParameterError("rate_hz", f"{{name}} must be a number [Hz], got {rate_hz!r}")
    if not (math.isfinite(rate_hz) and rate_hz > 0):
        raise ParameterError(
            "rate_hz", f"{{name}} must be positive and finite [Hz], got {rate_hz!r}"
        )
    return 1.0 / float(rate_hz)


def _tau_spec(taus: TauSet | npt.ArrayLike) -> str | FloatArray:
    """A named τ set as given, else the τ values [s] as a checked float array."""
    if isinstance(taus, str):
        if taus not in TAU_SETS:
            raise ParameterError(
                "taus", f"{{name}} {taus!r}: use {', '.join(TAU_SETS)} or an array of τ [s]"
            )
        return taus
    tau = np.asarray(taus, dtype=np.float64).ravel()
    if tau.size == 0 or not np.all(np.isfinite(tau)) or np.any(tau <= 0):
        raise ParameterError("taus", "{name}: averaging times τ must be positive and finite [s]")
    return tau


def _samples(y: npt.ArrayLike) -> FloatArray:
    """``y`` as a float array of one axis (a table of several axes is refused, not flattened)."""
    values = np.asarray(y, dtype=np.float64)
    if values.ndim != 1:
        raise ParameterError(
            "y", f"{{name}} must be one-dimensional (one axis), got shape {values.shape}"
        )
    return values


def _data_type(data_type: DataType) -> str:
    """``freq`` and ``rate`` → ``rate``; ``phase`` as given."""
    if data_type in ("freq", "rate"):
        return "rate"
    if data_type == "phase":
        return "phase"
    raise ParameterError("data_type", f"{{name}} {data_type!r}: use freq, rate or phase")


def deviation(
    name: str,
    y: npt.ArrayLike,
    rate_hz: float,
    taus: TauSet | npt.ArrayLike = "octave",
    *,
    data_type: DataType = "freq",
    unit: str = "",
    confidence: float = ONE_SIGMA_CONFIDENCE,
    noise_type: int | None = None,
    bias_correct: bool = False,
    max_work: float = family.DEFAULT_MAX_WORK,
) -> DeviationResult:
    r"""One deviation of the NIST SP 1065 family of an array, with chi-square intervals.

    Parameters
    ----------
    name : str
        A registered deviation (``oadev``, ``mdev``, …: :func:`.registry.names`).
    y : array_like
        Rate samples [unit] (phase points with ``data_type="phase"``); not modified.
    rate_hz : float
        Sample rate [Hz] (τ0 = 1/rate_hz).
    taus : {"octave", "decade", "log", "all"} or array_like
        A named τ set, or averaging times τ [s] (rounded to multiples of τ0).
    data_type : {"freq", "rate", "phase"}
        Rate samples (``freq``, ``rate``) or their integral (``phase``).
    unit : str
        Unit of ``y`` (reported; a time deviation of rate data is in unit·s).
    confidence : float
        Confidence level of the interval (default 0.683, ±1σ).
    noise_type : int or None
        Power-law exponent α (−4…2) for the EDF at every τ; None: identified per τ.
    bias_correct : bool
        Multiply totdev and htotdev by Stable32's bias factor.
    max_work : float
        Arithmetic operations allowed before the request is refused.

    Returns
    -------
    DeviationResult
        τ, the deviation, its interval and EDF.

    Raises
    ------
    ParameterError
        Unknown deviation or τ set, a bad rate or data type (NaN samples: MissingValueError).

    Notes
    -----
    Rate samples become phase :math:`x_k = \tau_0 \sum_{i<k} y_i`; the overlapping Allan
    deviation at :math:`\tau = m\tau_0` is (NIST SP 1065 eq. 11)

    .. math::

        \sigma_y^2(\tau) = \frac{1}{2\tau^2 (N-2m)} \sum_{k=0}^{N-2m-1}
            (x_{k+2m} - 2x_{k+m} + x_k)^2 .

    The interval is :math:`\nu\hat\sigma^2/\chi^2_{p}(\nu)` (SP 1065 eq. 45) with
    Greenhall & Riley's equivalent degrees of freedom ν for the noise type identified per
    τ by the lag-1 autocorrelation (Riley & Greenhall 2004); each deviation's formula is
    in its function's docstring (:func:`oadev`, :func:`mdev`, …).

    References
    ----------
    .. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.
    .. [2] C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on
       finite differences", Proc. 35th PTTI Meeting, 2003.

    Examples
    --------
    White rate noise of σ = 2: the overlapping Allan deviation at τ0 is σ.

    >>> import numpy as np
    >>> from thermocal import stability
    >>> y = np.random.default_rng(0).normal(0.0, 2.0, 100_000)
    >>> r = stability.deviation("oadev", y, rate_hz=100.0, taus="octave")
    >>> round(float(r.tau_s[0]), 3), round(float(r.dev[0]), 2)
    (0.01, 2.0)
    >>> bool(r.low[0] < r.dev[0] < r.high[0])
    True
    """
    dev, kind = registry.get(name), _data_type(data_type)
    if noise_type is not None and noise_type not in range(-4 if dev.hadamard else -2, 3):
        raise ParameterError("noise_type", f"{{name}} {noise_type!r}: α outside {name}'s range")
    res = family.stability(
        _samples(y), _tau0(rate_hz), [dev.name], _tau_spec(taus),
        data_type=kind, unit=unit, confidence=confidence, alpha=noise_type,
        bias_correct=bias_correct, max_work=max_work,
    )  # fmt: skip
    c = res.curves[dev.name]
    return DeviationResult(
        c.name, c.tau_s, c.m, c.dev, c.low, c.high, c.edf, c.n_terms, c.alpha, c.alpha_method,
        c.unit, res.confidence, kind, float(rate_hz), c.bias,
    )  # fmt: skip


_DeviationFunction = Callable[..., DeviationResult]


def _one(name: str, formula: str, words: str) -> _DeviationFunction:
    """The function of one built-in deviation: :func:`deviation` with ``name`` fixed."""

    def func(
        y: npt.ArrayLike,
        rate_hz: float,
        taus: TauSet | npt.ArrayLike = "octave",
        *,
        data_type: DataType = "freq",
        unit: str = "",
        confidence: float = ONE_SIGMA_CONFIDENCE,
        noise_type: int | None = None,
    ) -> DeviationResult:
        return deviation(
            name, y, rate_hz, taus, data_type=data_type, unit=unit, confidence=confidence,
            noise_type=noise_type,
        )  # fmt: skip

    ref = registry.get(name).reference
    func.__name__ = func.__qualname__ = name
    func.__doc__ = f"""{words} of an array, with its interval ({ref}).

    Parameters
    ----------
    y : array_like
        Rate samples [unit] (phase points with ``data_type="phase"``).
    rate_hz : float
        Sample rate [Hz] (τ0 = 1/rate_hz).
    taus : {{"octave", "decade", "log", "all"}} or array_like
        A named τ set or averaging times τ [s].
    data_type : {{"freq", "rate", "phase"}}
        Rate (``freq``, ``rate``) or phase data.
    unit : str
        Unit of ``y``.
    confidence : float
        Confidence level of the interval.
    noise_type : int or None
        Power-law exponent α for the EDF; None: identified per τ.

    Returns
    -------
    DeviationResult
        As :func:`deviation` gives it.

    Raises
    ------
    ParameterError
        As :func:`deviation`.

    Notes
    -----
    With phase :math:`x_k` (rate data: :math:`x_k = \\tau_0 \\sum_{{i<k}} y_i`),
    :math:`\\tau = m\\tau_0` and N phase points ({ref}):

    .. math::

        {formula}

    References
    ----------
    .. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.
    """
    return func


oadev = _one(
    "oadev",
    r"\sigma_y^2(\tau) = \frac{1}{2\tau^2(N-2m)}\sum_{k=0}^{N-2m-1}(x_{k+2m}-2x_{k+m}+x_k)^2",
    "Overlapping Allan deviation",
)
adev = _one(
    "adev",
    r"\sigma_y^2(\tau) = \frac{1}{2\tau^2(M-1)}\sum_{j=0}^{M-2}(x_{(j+2)m}-2x_{(j+1)m}+x_{jm})^2,"
    r"\ M = \lfloor (N-1)/m \rfloor",
    "Allan deviation (non-overlapping)",
)
mdev = _one(
    "mdev",
    r"\mathrm{Mod}\,\sigma_y^2(\tau) = \frac{1}{2m^2\tau^2(N-3m+1)}\sum_{j=0}^{N-3m}"
    r"\Bigl(\sum_{i=j}^{j+m-1}x_{i+2m}-2x_{i+m}+x_i\Bigr)^2",
    "Modified Allan deviation",
)
tdev = _one(
    "tdev",
    r"\sigma_x^2(\tau) = \frac{\tau^2}{3}\,\mathrm{Mod}\,\sigma_y^2(\tau)",
    "Time deviation",
)
hdev = _one(
    "hdev",
    r"H\sigma_y^2(\tau) = \frac{1}{6\tau^2 M}\sum_{j}(x_{(j+3)m}-3x_{(j+2)m}+3x_{(j+1)m}-x_{jm})^2",
    "Hadamard deviation (non-overlapping)",
)
ohdev = _one(
    "ohdev",
    r"H\sigma_y^2(\tau) = \frac{1}{6\tau^2(N-3m)}\sum_{k=0}^{N-3m-1}"
    r"(x_{k+3m}-3x_{k+2m}+3x_{k+m}-x_k)^2",
    "Overlapping Hadamard deviation",
)
totdev = _one(
    "totdev",
    r"\mathrm{Tot}\,\sigma_y^2(\tau) = \frac{1}{2\tau^2(N-2)}\sum_{i=2}^{N-1}"
    r"(x^*_{i-m}-2x^*_i+x^*_{i+m})^2,\ x^* \text{ reflected oddly at both ends}",
    "Total deviation",
)
mtotdev = _one(
    "mtotdev",
    r"\mathrm{Mod\,Tot}\,\sigma_y^2(\tau) = \frac{1}{2\tau^2(N-3m+1)}\sum_{n=1}^{N-3m+1}"
    r"\frac{1}{6m}\sum_{i}\bigl(z^\#_{i}(m)\bigr)^2",
    "Modified total deviation",
)
ttotdev = _one(
    "ttotdev",
    r"\sigma_x^2(\tau) = \frac{\tau^2}{3}\,\mathrm{Mod\,Tot}\,\sigma_y^2(\tau)",
    "Time total deviation",
)
htotdev = _one(
    "htotdev",
    r"\mathrm{Htot}\,\sigma_y^2(\tau) = \frac{1}{6(N-3m)}\sum_{n=1}^{N-3m}"
    r"\frac{1}{6m}\sum_{i}\bigl(H_i(m)\bigr)^2",
    "Hadamard total deviation",
)
theo1 = _one(
    "theo1",
    r"\mathrm{Theo1}(m,\tau_0,N) = \frac{1}{0.75\,(N-m)(m\tau_0)^2}\sum_{i=0}^{N-m-1}"
    r"\sum_{\delta=0}^{m/2-1}\frac{\bigl[(x_i-x_{i-\delta+m/2})+(x_{i+m}-x_{i+\delta+m/2})"
    r"\bigr]^2}{m/2-\delta},\ \tau = 0.75\,m\tau_0",
    "Theo1 deviation",
)
mtie = _one(
    "mtie",
    r"\mathrm{MTIE}(\tau) = \max_{k}\Bigl(\max_{k\le i\le k+m}x_i-\min_{k\le i\le k+m}x_i\Bigr)",
    "Maximum time interval error",
)
tierms = _one(
    "tierms",
    r"\mathrm{TIE}_{\mathrm{rms}}(\tau) = \sqrt{\frac{1}{N-m}\sum_{k=0}^{N-m-1}(x_{k+m}-x_k)^2}",
    "Time interval error, rms",
)


@dataclass(frozen=True, eq=False)
class AllanNoise:
    """The overlapping Allan deviation of an array and its IEEE 952 noise terms.

    Parameters
    ----------
    adev : thermocal.stability.allan.AllanResult
        The overlapping Allan deviation with intervals.
    terms : thermocal.stability.allan.NoiseTerms
        The terms by slope lines and by the weighted least-squares fit.
    """

    adev: allan.AllanResult
    terms: allan.NoiseTerms

    def term(self, name: str, method: Literal["fit", "slope"] = "fit") -> allan.NoiseTerm:
        """One term (``quantization``, ``angle_random_walk``, ``bias_instability``,
        ``rate_random_walk``, ``rate_ramp``) by ``method``.

        Parameters
        ----------
        name : str
            Term name.
        method : {"fit", "slope"}, optional
            Least-squares fit (default) or slope line.

        Returns
        -------
        NoiseTerm
            The term's value [its unit] and interval.
        """
        if name not in allan.TERM_NAMES:
            raise ParameterError("name", f"{{name}} {name!r}: use {', '.join(allan.TERM_NAMES)}")
        if method not in ("fit", "slope"):
            raise ParameterError("method", f"{{name}} {method!r}: use fit or slope")
        chosen = self.terms.fit if method == "fit" else self.terms.slope
        return chosen.terms()[name]

    def _rows(self) -> list[dict[str, Any]]:
        """One row per (method, term)."""
        rows = []
        for chosen in (self.terms.fit, self.terms.slope):
            for name, t in chosen.terms().items():
                rows.append(
                    {
                        "method": chosen.method, "term": name, "value": t.value, "low": t.low,
                        "high": t.high, "unit": t.unit, "tau_s": t.tau_s, "reason": t.reason,
                    }
                )  # fmt: skip
        return rows

    def to_dict(self) -> dict[str, Any]:
        """The curve (``tau_s``, ``adev``, ``low``, ``high``, ``edf``) and the terms
        (``terms``: one dict per method and term) as plain Python values."""
        a = self.adev
        return {
            "unit": a.unit,
            "confidence": a.confidence,
            "tau_s": a.tau_s.tolist(),
            "adev": a.adev.tolist(),
            "low": a.adev_low.tolist(),
            "high": a.adev_high.tolist(),
            "edf": a.edf.tolist(),
            "terms": self._rows(),
        }

    def to_frame(self) -> pd.DataFrame:
        """The noise terms as a pandas DataFrame, one row per method and term."""
        import pandas

        return pandas.DataFrame(self._rows())


def allan_noise(
    y: npt.ArrayLike,
    rate_hz: float,
    *,
    unit: str = "deg/h",
    taus: TauSet | Sequence[float] | npt.ArrayLike = "octave",
    confidence: float = ONE_SIGMA_CONFIDENCE,
) -> AllanNoise:
    r"""IEEE 952 noise terms of an array of rate samples, with intervals.

    Parameters
    ----------
    y : array_like
        Rate samples [unit], each the mean over 1/rate_hz.  Not modified.
    rate_hz : float
        Sample rate [Hz].
    unit : str
        Unit of ``y``: ``deg/h`` (terms in arcsec, °/√h, °/h, °/h/√h, °/h/h), ``deg/s``,
        ``rad/s``, ``mg``, ``m/s^2`` or any other (terms in unit·s, unit·√s, unit, unit/√s,
        unit/s).
    taus : {"octave", "decade", "log"} or array_like
        A named τ set or averaging times τ [s].
    confidence : float
        Confidence level of the intervals (default 0.683, ±1σ).

    Returns
    -------
    AllanNoise
        The overlapping Allan deviation and the five terms by both methods.

    Raises
    ------
    ParameterError
        A non-positive rate, an unknown τ set.
    thermocal.errors.MissingValueError
        NaN or infinite samples.

    Notes
    -----
    The terms are read from the model (IEEE Std 952-1997 Annex C, eq. C.27–C.32)

    .. math::

        \sigma^2(\tau) = \frac{3Q^2}{\tau^2} + \frac{N^2}{\tau} + \frac{2\ln 2}{\pi}B^2
            + \frac{K^2\tau}{3} + \frac{R^2\tau^2}{2}

    by weighted non-negative least squares (``fit``) and by slope lines read at
    τ = √3, 1, 3 and √2 s (``slope``); quantization Q, angle random walk N, bias
    instability B, rate random walk K, rate ramp R.  A term the data do not show is
    ``None`` with its reason.

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C.
    .. [2] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.

    Examples
    --------
    White rate noise of σ = 1 °/s per sample at 100 Hz: angle random walk
    N = σ √τ0 = 0.1 °/√s = 6 °/√h.

    >>> import numpy as np
    >>> from thermocal import stability
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 200_000)  # deg/s at 100 Hz
    >>> r = stability.allan_noise(y, rate_hz=100.0, unit="deg/s")
    >>> arw = r.term("angle_random_walk")
    >>> round(arw.value, 1), arw.unit
    (6.0, 'deg/sqrt(h)')
    """
    tau0 = _tau0(rate_hz)
    spec = _tau_spec(taus)
    if spec == "all":
        raise ParameterError("taus", "{name} 'all': use octave, decade, log or τ [s]")
    res = allan.overlapping_adev(_samples(y), tau0, spec, unit=unit, confidence=confidence)
    return AllanNoise(res, allan.noise_terms(res))


__all__ = [
    "TAU_SETS",
    "AllanNoise",
    "DataType",
    "DeviationResult",
    "TauSet",
    "adev",
    "allan_noise",
    "deviation",
    "hdev",
    "htotdev",
    "mdev",
    "mtie",
    "mtotdev",
    "oadev",
    "ohdev",
    "tdev",
    "theo1",
    "tierms",
    "totdev",
    "ttotdev",
]
