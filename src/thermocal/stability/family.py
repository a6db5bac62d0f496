"""Several deviations of one record at once, with Greenhall intervals per τ.

:func:`stability` is the library entry of the deviation family (the ``allan`` command with
deviations named): it splits the
record at gaps, computes each requested deviation of :mod:`.deviations` per stretch, pools
them, identifies the power-law noise per τ (:func:`.edf.identify_noise`) and gives each
point its equivalent degrees of freedom and chi-square interval (NIST SP 1065 eq. 45):

=========================  =========================================================
deviation                  EDF
=========================  =========================================================
adev / oadev               Greenhall d = 2, S = 1 / m, F = m
mdev, tdev                 Greenhall d = 2, S = m, F = 1
hdev / ohdev               Greenhall d = 3, S = 1 / m, F = m
totdev                     SP 1065 Table 7 (α = 0, −1, −2), else as oadev
mtotdev, ttotdev           SP 1065 Table 8
htotdev                    SP 1065 §5.2.14 (α = 0, −1, −2), else as ohdev; m = 1 as ohdev
theo1                      Howe's empirical fits (:func:`.edf.edf_theo1`), α identified
                           at the averaging factor of τ = 0.75 m τ0
mtie, tierms               none (NaN; JSON ``<name>_interval`` says why: :func:`no_interval`)
=========================  =========================================================

The EDFs of gap-separated stretches add (independent estimates).
"""

from __future__ import annotations

import contextlib
import math
import threading
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Final

import numpy as np
import numpy.typing as npt
from threadpoolctl import threadpool_limits

from thermocal.errors import MissingValueError, ParameterError, ThermocalInputError
from thermocal.stability import deviations as dv
from thermocal.stability import edf as ed
from thermocal.stability import registry
from thermocal.stability import total as _total

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

TOTAL = frozenset({"totdev", "mtotdev", "ttotdev", "htotdev"})
NOISE_IDS: Final = ("thermocal", "stable32")
"""Noise-identification rules (:func:`stability`): thermocal's (B1 against Barnes' theory at
the number of averages, bounded by the shorter τ's α) or Stable32's."""


def no_interval(name: str) -> str | None:
    """Why the deviation ``name`` has no interval (its ``low``/``high`` are NaN;
    ``<name>_interval`` in JSON), or None when it has one.

    Parameters
    ----------
    name : str
        Deviation name.

    Returns
    -------
    str or None
        The reason, or None.
    """
    dev = registry.get(name)
    return dev.interval if dev.edf is None else None


def edf_source(name: str) -> str:
    """Where a deviation's EDF comes from, as the ``<name>_interval`` text states it.

    Parameters
    ----------
    name : str
        Deviation name.

    Returns
    -------
    str
        The source of its EDF.
    """
    return registry.get(name).interval


@dataclass(frozen=True, eq=False)
class DeviationCurve:
    """One deviation against τ.

    Parameters
    ----------
    name : str
        The deviation.
    tau_s : numpy.ndarray
        Averaging times τ [s] (theo1: 0.75 m τ0).
    m : numpy.ndarray
        Averaging factors.
    dev : numpy.ndarray
        The deviation [``unit``].
    low, high : numpy.ndarray
        Its interval [``unit``] (NaN where none).
    edf : numpy.ndarray
        Equivalent degrees of freedom.
    n_terms : numpy.ndarray
        Terms behind each point.
    alpha : numpy.ndarray
        The power-law noise exponent used for the EDF.
    alpha_method : tuple of str
        Per τ: ``lag1``, ``b1``, ``b1-rn`` (B1 read phase noise, R(n) split white from
        flicker PM), ``b1-previous`` (B1 read a higher α than the shorter τ's, which is
        kept), ``previous`` (too few averages), ``given``.
    unit : str
        Unit of ``dev``.
    bias : numpy.ndarray or None
        The factor ``dev``, ``low`` and ``high`` were multiplied by (:func:`stable32_bias`;
        None when no correction was asked).
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
    bias: FloatArray | None = None


@dataclass(frozen=True, eq=False)
class StabilityResult:
    """Deviations of one record (:func:`stability`).

    Parameters
    ----------
    curves : dict of str to DeviationCurve
        One curve per deviation, in the order asked.
    tau_s : numpy.ndarray
        The common averaging times [s] (theo1 has its own).
    m : numpy.ndarray
        The common averaging factors.
    tau0_s : float
        Sample interval [s].
    data_type : str
        ``rate`` or ``phase``.
    confidence : float
        Confidence level of the intervals.
    n_segments : int
        Gap-free stretches used.
    n_points : int
        Phase points over the stretches.
    unit : str
        Unit of the data.
    notes : tuple of str
        Remarks on the analysis.
    noise_id : str
        The identification rules used (``thermocal`` or ``stable32``).
    """

    curves: dict[str, DeviationCurve]
    tau_s: FloatArray
    m: IntArray
    tau0_s: float
    data_type: str
    confidence: float
    n_segments: int
    n_points: int
    unit: str
    notes: tuple[str, ...] = field(default=())
    noise_id: str = "thermocal"

    def to_dict(self) -> dict[str, Any]:
        """The result as plain Python values: the object the ``allan`` command prints as JSON
        for the deviations named (NaN where it prints null).

        Returns
        -------
        dict
            ``tau_s``, ``data_type``, ``confidence``, ``tau0_s``, ``n_segments``,
            ``deviations`` (the names), ``noise_id``, ``alpha`` (the noise identified per
            ``tau_s`` by the first Allan-family deviation; None for theo1 alone) and per
            deviation NAME the keys NAME, NAME_low, NAME_high, NAME_edf, NAME_alpha,
            NAME_alpha_method, NAME_n, NAME_tau_s, NAME_unit, NAME_interval (how the
            interval was found, or "none: why") and, when a bias correction was asked,
            NAME_bias_factor.
        """
        out: dict[str, Any] = {
            "tau_s": self.tau_s.tolist(),
            "data_type": self.data_type,
            "confidence": self.confidence,
            "tau0_s": self.tau0_s,
            "n_segments": self.n_segments,
            "deviations": list(self.curves),
            "noise_id": self.noise_id,
        }
        alpha_src = next(
            (c for c in self.curves.values() if c.name not in _NOT_ALPHA_SOURCES),
            next(iter(self.curves.values())),
        )
        out["alpha"] = alpha_src.alpha.tolist() if alpha_src.name != "theo1" else None
        for name, c in self.curves.items():
            out[name] = c.dev.tolist()
            out[f"{name}_low"] = c.low.tolist()
            out[f"{name}_high"] = c.high.tolist()
            out[f"{name}_edf"] = c.edf.tolist()
            out[f"{name}_alpha"] = c.alpha.tolist()
            out[f"{name}_alpha_method"] = list(c.alpha_method)
            out[f"{name}_n"] = c.n_terms.tolist()
            out[f"{name}_tau_s"] = c.tau_s.tolist()
            out[f"{name}_unit"] = c.unit
            out[f"{name}_interval"] = no_interval(name) or (
                f"chi-square, {100 * self.confidence:.1f} %, {edf_source(name)}"
            )
            if c.bias is not None:
                out[f"{name}_bias_factor"] = c.bias.tolist()
        return out


_NOT_ALPHA_SOURCES: Final = ("theo1", "hdev", "ohdev", "htotdev")
"""Deviations whose α column does not stand for the record's noise in ``alpha``."""


_TOTVAR_BIAS: Final = {-1: 1.0 / (3.0 * math.log(2.0)), -2: 0.75}
_HTOTVAR_BIAS: Final = {0: -0.005, -1: -0.149, -2: -0.229, -3: -0.283, -4: -0.321}


def stable32_bias(name: str, alpha: int, m: int, n_phase: int) -> float:
    r"""The factor Stable32 multiplies a total deviation by to remove its bias.

    * totdev: ``1/√(1 − a·τ/T)`` with a = 1/(3 ln 2) for flicker FM, 3/4 for random-walk FM,
      0 otherwise, and T = (N − 1) τ0 the record length (D. A. Howe, "Total variance
      explained", Proc. 1999 Joint EFTF/FCS, Table 1; NIST SP 1065 §5.2.11).
    * htotdev at m ≥ 2: ``1/√(1 + a)`` with a = −0.005, −0.149, −0.229, −0.283, −0.321 for
      α = 0 … −4 (D. A. Howe et al., "A total estimator of the Hadamard function used for
      GPS operations", Proc. 32nd PTTI, 2000; SP 1065 §5.2.14); at m = 1 Htot is the
      overlapping Hadamard deviation and is not corrected; phase noise is not corrected.
    * every other deviation: 1.

    Checked against Stable32's printed values (which are so corrected): PHASE.DAT's Htot
    (÷√0.995 from m = 2), the Sr87 record's Htot at α = −1, −2 (factors 1.0840, 1.1389) and
    its totdev at α = −1, −2 (m = 1–400: within the five printed digits).

    Parameters
    ----------
    name : str
        Deviation name.
    alpha : int
        Power-law noise exponent α.
    m : int
        Averaging factor [samples].
    n_phase : int
        Number of phase points N.

    Returns
    -------
    float
        Bias factor [1].

    Notes
    -----
    .. math:: b_{tot} = 1 / \sqrt{1 - a \tau / T}

    References
    ----------
    - Howe 1999 (TOTDEV bias); Howe et al. 2000, PTTI (Htot bias).
    """
    if name == "totdev":
        a = _TOTVAR_BIAS.get(alpha, 0.0)
        ratio = m / max(n_phase - 1, 1)
        return 1.0 / math.sqrt(1.0 - a * ratio) if a * ratio < 1.0 else float("nan")
    if name == "htotdev" and m >= 2 and alpha in _HTOTVAR_BIAS:
        return 1.0 / math.sqrt(1.0 + _HTOTVAR_BIAS[alpha])
    return 1.0


NOISE_TYPES: Final = {"wpm": 2, "fpm": 1, "wfm": 0, "ffm": -1, "rwfm": -2, "fwfm": -3, "rrfm": -4}
"""Power-law noise names → α (S_y(f) ∝ f^α; NIST SP 1065 Table 1): white and flicker PM,
white, flicker and random-walk FM, flicker-walk and random-run FM (Hadamard family only)."""


def check_noise_type(alpha: int | None, names: Sequence[str]) -> int | None:
    """The power-law exponent α the EDF and bias factors assume at every τ (Stable32's noise
    type setting), checked for the deviations ``names``.

    Parameters
    ----------
    alpha : int or None
        α (S_y(f) ∝ f^α, NIST SP 1065 Table 1) from −4 to 2; None: identified per τ.
    names : sequence of str
        The deviations it is for.

    Returns
    -------
    int or None
        ``alpha``.

    Raises
    ------
    ParameterError
        α outside −4…2, or below −2 for a deviation outside the Hadamard family: the
        Allan-family EDF (Greenhall & Riley 2003) needs α + 2d > 1 with d = 2.
    """
    if alpha is None:
        return None
    if isinstance(alpha, bool) or not isinstance(alpha, int | np.integer) or not -4 <= alpha <= 2:
        raise ParameterError("noise_type", f"{{name}} {alpha!r}: give α from -4 to 2 or None")
    not_h = [n for n in names if not registry.get(n).hadamard and registry.get(n).edf is not None]
    if alpha < -2 and not_h:
        raise ParameterError(
            "noise_type",
            f"{{name}} α = {alpha} is defined for the Hadamard deviations (hdev, ohdev, "
            f"htotdev) only, not {', '.join(not_h)}",
        )
    return int(alpha)


def factors(
    taus: str | npt.ArrayLike, tau0_s: float, m_max: int, *, theo1: bool = False
) -> IntArray:
    """Averaging factors for a τ set (``octave``: 1, 2, 4 …; ``decade``: 1, 2, 4, 10, 20,
    40 …; ``log``: ≈10 per decade; ``all``: every m; or τ [s]); theo1: even m with
    τ = 0.75 m τ0.

    Parameters
    ----------
    taus : str or array_like
        Named τ set or averaging times [s].
    tau0_s : float
        Sample interval [s].
    m_max : int
        Largest averaging factor [samples].
    theo1 : bool, optional
        Theo1's even factors (default False).

    Returns
    -------
    numpy.ndarray
        Averaging factors [samples].
    """
    if m_max < 1:
        return np.zeros(0, dtype=np.int64)
    m: npt.NDArray[np.float64] | IntArray
    if isinstance(taus, str):
        if taus == "octave":
            m = 2 ** np.arange(int(math.log2(m_max)) + 1)
        elif taus == "decade":
            dec = 10 ** np.arange(int(math.log10(m_max)) + 1)
            m = (dec[:, None] * np.array([1, 2, 4])[None, :]).ravel()
        elif taus == "log":
            m = np.round(10.0 ** (np.arange(int(10 * math.log10(m_max)) + 1) / 10.0))
        elif taus == "all":
            m = np.arange(1, m_max + 1)
        else:
            raise ThermocalInputError(
                f"unknown tau set {taus!r}; use octave, decade, log, all or τ [s]"
            )
        if theo1:
            m = 2 * m
    else:
        tau = np.asarray(taus, dtype=np.float64).ravel()
        if tau.size == 0 or not np.all(np.isfinite(tau)) or np.any(tau <= 0):
            raise ThermocalInputError("averaging times τ must be positive and finite")
        m = 2 * np.round(tau / (1.5 * tau0_s)) if theo1 else np.round(tau / tau0_s)
    mi = np.sort(np.asarray(m).astype(np.int64).ravel())  # unique: np.unique imports numpy.ma
    mi = mi[np.concatenate(([True], mi[1:] != mi[:-1]))]
    return mi[(mi >= 1) & (mi <= m_max)]


def _edf(name: str, alpha: int, m: int, n_phase: int) -> float:
    """The registered EDF of ``name`` (:mod:`.registry`); NaN where it has none."""
    edf = registry.get(name).edf
    if edf is None:
        return float("nan")
    try:
        return edf(alpha, m, n_phase)
    except ValueError:
        return float("nan")


def _stretches(
    values: npt.ArrayLike, tau0_s: float, data_type: str, segments: list[slice] | None
) -> tuple[FloatArray, list[slice], float]:
    """The checked samples, the gap-free stretches giving at least 3 phase points and the
    samples' sum."""
    y = np.asarray(values, dtype=np.float64)
    if y.ndim != 1:  # a table of axes flattened into one record: a silent wrong number
        raise ParameterError("values", f"{{name}} must be one-dimensional, got shape {y.shape}")
    if not (math.isfinite(tau0_s) and tau0_s > 0):
        raise ThermocalInputError(f"sample interval τ0 must be positive, got {tau0_s!r}")
    # a NaN or ±inf sample makes the sum non-finite (the sum alone overflowing is rare):
    # the full O(n) mask only then
    bad = np.zeros(0, dtype=np.int64)
    total = float(y.sum())
    if not math.isfinite(total):
        bad = np.flatnonzero(~np.isfinite(y))
    if bad.size:
        raise MissingValueError(
            f"data have {bad.size} NaN/infinite samples (first at row {bad[0]}); "
            "remove them or split the record"
        )
    slices = segments if segments is not None else [slice(0, y.size)]
    extra = 1 if data_type == "rate" else 0  # rate: n samples give n + 1 phase points
    kept = [
        sl for sl in slices if sl.stop > sl.start and y[sl].size + extra >= 3
    ]  # fmt: skip
    if not kept:
        raise ThermocalInputError("stability analysis needs at least 3 contiguous points")
    return y, kept, total


_LADDER_MIN: Final = 1 << 20
"""Phase records from this many points identify their noise on contiguous decimations
(:meth:`_Record.phase_r1`); shorter ones read strided views (they fit in the cache)."""


class _Record:
    """The gap-free stretches of one record, each form (phase, centred phase, octave
    levels) built once, when a deviation first asks for it."""

    def __init__(
        self, y: FloatArray, kept: list[slice], tau0_s: float, data_type: str, names: list[str]
    ) -> None:
        self.y, self.kept, self.tau0_s, self.data_type, self.names = (
            y, kept, tau0_s, data_type, names,
        )  # fmt: skip
        rate = data_type == "rate"
        self.sizes = [y[sl].size + (1 if rate else 0) for sl in kept]
        """Phase points per stretch."""
        self.longest = self.sizes.index(max(self.sizes))
        self._phases: list[FloatArray] | None = None
        self._centred: list[FloatArray] | None = None
        self._levels: dict[int, list[dv.OctaveLevel]] = {}
        self._means: dict[int, float] = {}
        self.m_max = 0
        """Octave levels up to this factor (0: no octave levels; set by the caller)."""
        self.own = False
        """The caller gave ``y`` up: phase data are centred in its own buffer."""
        self._rung: tuple[int, FloatArray, int] | None = None
        """``(k, buffer, n)``: ``buffer[:n]`` holds x[::k] − :func:`.edf.phase_shift` of
        the longest stretch's centred phase x, the last rung of the phase decimations
        (:meth:`phase_r1`); later rungs are written into the same buffer."""
        self._r1: dict[int, tuple[float, ...]] = {}
        """Per m, the r1 of the decimated phase's differences (:meth:`phase_r1`)."""
        self.dmax = 3 if any(registry.get(n).hadamard for n in names) else 2
        """Difference orders the phase identification gathers at once."""
        self.plan: list[int] = []
        """The common averaging factors, ascending (:meth:`set_octave`)."""

    def set_octave(self, m: IntArray) -> None:
        """The common factors ``m`` (ascending): the phase identification's next rung is
        the next of them that the current one divides (:meth:`phase_r1`).  Rate data at
        octave factors only (every m a power of 2): adev, hdev and the noise identification
        up to the largest m come from the octave levels."""
        self.plan = [int(k) for k in m]
        if self.data_type == "rate" and m.size and np.all(m & (m - 1) == 0):
            self.m_max = int(m.max())

    def mean(self, i: int) -> float:
        """Stretch i's mean sample (numpy's, as ``y[sl].mean()``)."""
        if i not in self._means:
            self._means[i] = float(self.y[self.kept[i]].mean())
        return self._means[i]

    def preset_mean(self, i: int, mean: float) -> None:
        self._means[i] = mean

    def phases(self) -> list[FloatArray]:
        """Each stretch's phase (phase data given up by the caller: the stretch itself)."""
        if self._phases is None:
            rate = self.data_type == "rate"
            if not rate and self.own:
                self._phases = [self.y[sl] for sl in self.kept]
                return self._phases
            self._phases = [
                dv.as_phase(self.y[sl], self.tau0_s, self.data_type, self.mean(i) if rate else 0.0)
                for i, sl in enumerate(self.kept)
            ]
        return self._phases

    def centred(self) -> list[FloatArray]:
        """The phases minus their end-point lines (in place unless mtie/tierms need the raw
        phase).  The noise identification reads these: for rate data the m-averages only
        shift by a constant; for phase data the frequency offset is gone before the lag-1
        test, which removes nothing else (:func:`.edf.identify_noise`)."""
        if self._centred is None:
            raw = any(registry.get(n).raw_phase for n in self.names)
            self._centred = [dv.centred(x, inplace=not raw) for x in self.phases()]
        return self._centred

    def levels(self, i: int) -> list[dv.OctaveLevel]:
        """Stretch i's octave pyramid (rate data), with the Allan/Hadamard sums if asked."""
        if i not in self._levels:
            self._levels[i] = dv.octave_levels(
                self.y[self.kept[i]], self.mean(i), self.m_max,
                d1="adev" in self.names, d2="hdev" in self.names,
            )  # fmt: skip
        return self._levels[i]

    def identify(self, m: int, dmax: int, rules: ed.IdRules = ed.THERMOCAL_RULES) -> ed.NoiseId:
        """:func:`thermocal.stability.edf.identify_noise` on the longest stretch at m: from
        its octave level when there is one (the same m-averages, as block sums), else from
        its centred phase (``rules``: as there)."""
        if 1 <= m <= self.m_max and m & (m - 1) == 0:
            by_m = {lv.m: lv for lv in self.levels(self.longest)}
            if m in by_m:
                lv = by_m[m]
                nid = ed.identify_rate_averages(lv.z, dmax=dmax, sums=lv.lag, rules=rules)
                if nid.method == "b1" and nid.alpha == 2:  # B1 read PM: R(n) from the phase
                    nid = ed.split_pm(nid, self.centred()[self.longest], m)
                return nid
            if self.sizes[self.longest] - 1 < m:  # no m-average: nothing to identify
                return ed.identify_rate_averages(np.zeros(0), dmax=dmax)
        x = self.centred()[self.longest]
        if self.data_type == "phase" and x[:: max(m, 1)].size >= ed.MIN_ACF_POINTS:
            r1 = self.phase_r1(m, dmax)
            return ed.identify_phase_lag1(r1, x[::m].size, dmax, rules)
        return ed.identify_noise(
            x, m, dmax=dmax, phase_input=self.data_type == "phase", rules=rules
        )

    def phase_r1(self, m: int, dmax: int) -> tuple[float, ...]:
        """The r1 of x[::m] and of its differences up to order ``max(dmax, self.dmax)``
        (:func:`.edf.lag1_of_differences`, one pass), x the longest stretch's centred phase;
        kept per m.  From :data:`_LADDER_MIN` points the decimations are rungs of one
        reused buffer (:meth:`_rung_r1`); the points, and so every sum, are those
        :func:`.edf.identify_noise` reads from the strided phase."""
        got = self._r1.get(m)
        if got is not None and len(got) > dmax:
            return got
        x = self.centred()[self.longest]
        order, shift = max(dmax, self.dmax), ed.phase_shift(x)
        if x.size < _LADDER_MIN:  # strided views (in the cache)
            got = ed.lag1_of_differences(x[::m], order, shift=shift)
        else:
            got = self._rung_r1(x, m, order, shift)
        self._r1[m] = got
        return got

    def _rung_r1(self, x: FloatArray, m: int, order: int, shift: float) -> tuple[float, ...]:
        """:meth:`phase_r1` on a long record.  The pass over x[::m] reads the rung prepared
        for m in place, or copies x[::m] into the buffer (from the last rung, stride m/k,
        when its k divides m; else from x), and writes the next planned factor's rung (the
        next of :attr:`plan` that m divides) behind it in the same pass.  A strided view of
        a 10⁷-point phase costs a sweep of the whole array for m ≤ 8 (a cache line holds 8
        points); a rung is read once, contiguous, and half of it written."""
        k, buf, nk = self._rung if self._rung is not None else (0, x[:0], 0)
        n = x[::m].size
        nxt = next((q for q in self.plan if q > m and q % m == 0), 0)
        n_next = x[::nxt].size if nxt else 0
        if n_next < ed.MIN_ACF_POINTS:
            nxt = n_next = 0
        out: FloatArray | None = None
        if k == m:
            src, off = buf[:nk], 0.0
        elif k and m % k == 0:
            src, off, out = buf[:nk][:: m // k], 0.0, buf
        elif m == 1:
            src, off = x, shift
        else:
            src, off, out = x[::m], shift, buf
        need = max(n_next, n if out is not None else 0)
        if buf.size < need:  # the first rung (read from x: the old buffer is not its source)
            buf = np.empty(need)
            out = buf if out is not None else None
        then = (nxt // m, buf) if nxt else None
        got = ed.lag1_of_differences(src, order, shift=off, out=out, then=then)
        if nxt:
            self._rung = (nxt, buf, n_next)
        elif out is not None:
            self._rung = (m, buf, n)
        if any(math.isnan(r) for r in got):  # exact passes on a series written over
            got = ed.lag1_of_differences(x[::m], order, shift=shift)
        return got

    def sums(self, name: str, m: IntArray) -> tuple[FloatArray, FloatArray]:
        """The pooled deviation and term count of ``name`` per m over the stretches."""
        if name in ("adev", "hdev") and self.m_max:
            parts = [dv.octave_sums(name, self.levels(i), m) for i in range(len(self.kept))]
        else:
            dev = registry.get(name)
            xs = self.phases() if dev.raw_phase else self.centred()  # no centred copy unasked
            parts = [dev.sums(x, self.tau0_s, m) for x in xs]
        return dv.pool(name, parts, m.size)


def _new_record(
    values: npt.ArrayLike,
    tau0_s: float,
    data_type: str,
    segments: list[slice] | None,
    names: list[str],
    overwrite: bool = False,
) -> _Record:
    """The checked record (:func:`_stretches`) with the whole record's mean preset;
    ``overwrite``: the caller's own writeable float64 buffer may be changed."""
    y, kept, total = _stretches(values, tau0_s, data_type, segments)
    record = _Record(y, kept, tau0_s, data_type, names)
    record.own = overwrite and y is values and bool(y.flags.writeable)
    if len(kept) == 1 and kept[0].indices(y.size)[:2] == (0, y.size):
        record.preset_mean(0, total / y.size)  # numpy's mean: the same sum over n
    return record


def oadev_edf(
    rate: npt.ArrayLike,
    tau0_s: float,
    m: IntArray,
    *,
    segments: list[slice] | None = None,
    alpha: int | None = None,
) -> tuple[IntArray, tuple[str, ...], FloatArray]:
    """Per averaging factor m of the overlapping Allan deviation of ``rate`` [any unit]
    sampled every ``tau0_s`` [s] in the gap-free ``segments``: the noise exponent α, how it
    was found and the equivalent degrees of freedom summed over the segments (NaN where
    none) — exactly what :func:`stability` gives ``oadev`` (the default ``thermocal allan``
    path takes its intervals from here: one implementation).

    α per τ from :func:`.edf.identify_noise` on the longest segment (lag-1 autocorrelation
    of the m-averages, Riley & Greenhall 2004; the B1 ratio where too few averages remain),
    bounded by the shorter τ's α as in :func:`stability`; or ``alpha`` when given.  EDF:
    Greenhall & Riley's algorithm (:func:`.edf.greenhall_edf`, d = 2, S = 1/m, F = m) per
    segment, added over the segments (independent estimates).  Reads ``rate`` only (call it
    before a computation that overwrites the buffer); holds the octave block sums of the
    longest segment (octave m) or its phase (other m) while it runs.

    Parameters
    ----------
    rate : array_like
        Rate samples [unit].
    tau0_s : float
        Sample interval [s].
    m : numpy.ndarray
        Averaging factors [samples].
    segments : list of slice, optional
        Gap-free segments (default the whole record).
    alpha : int, optional
        Noise exponent α to assume (default identified).

    Returns
    -------
    tuple
        α per factor, how it was found, and the EDF [1].

    References
    ----------
    - Greenhall & Riley 2003 (EDF); Riley & Greenhall 2004 (noise identification).
    """
    record = _new_record(rate, tau0_s, "rate", segments, ["oadev"])
    m = np.asarray(m, dtype=np.int64)
    record.set_octave(m)
    alphas, methods = _noise_exponents("oadev", m, record, alpha, {})
    return alphas, methods, _pooled_edf("oadev", m, alphas, record.sizes)


def _noise_exponents(
    name: str,
    m: IntArray,
    record: _Record,
    alpha: int | None,
    id_cache: dict[tuple[int, int, ed.IdRules], ed.NoiseId],
    noise_id: str = "thermocal",
    n_terms: FloatArray | None = None,
) -> tuple[IntArray, tuple[str, ...]]:
    """Per averaging factor, the noise exponent α for the EDF and how it was found: given,
    identified on the longest stretch (:func:`thermocal.stability.edf.identify_noise`,
    d = 3 for the Hadamard family, else 2; clipped to −2…2, −4…2 for Hadamard), or the
    shorter τ's where too few averages identify nothing.  ``noise_id="stable32"``:
    Stable32's rules (:data:`thermocal.stability.edf.STABLE32_B1_MIN_TOTAL`): B1 against
    the theory at n = the deviation's number of terms (``n_terms``, Stable32's "#"
    column), down to 6 averages for the total family and 10 for ADEV and HDEV, never
    bounded by the shorter τ's α; the lag-1 method on rate averages with their mean removed
    (not their line) and r1 normalised as Stable32's (:class:`thermocal.stability.edf.IdRules`)."""
    dmax = 3 if registry.get(name).hadamard else 2
    stable32 = noise_id == "stable32"
    b1_min = ed.MIN_B1_GROUPS
    if stable32 and name in TOTAL:
        b1_min = ed.STABLE32_B1_MIN_TOTAL
    elif stable32 and name in ("adev", "hdev"):
        b1_min = ed.STABLE32_B1_MIN_NONOVERLAPPING
    alphas = np.zeros(m.size, dtype=np.int64)
    methods: list[str] = []
    for i, mm in enumerate(m.tolist()):
        if alpha is not None:
            alphas[i] = alpha
            methods.append("given")
            continue
        if name == "theo1":  # Theo1's τ is 0.75 m τ0: the noise of that averaging time
            mm = max(1, round(0.75 * mm))
        rules = ed.THERMOCAL_RULES
        if stable32:
            cnt = n_terms[i] if n_terms is not None and name != "theo1" else math.nan
            b1_n = int(cnt) if math.isfinite(cnt) and cnt > 0 else sum(record.sizes) - 1
            rules = ed.IdRules(b1_n, b1_min, rate_detrend=False, r1_sample=True)
            if (record.sizes[record.longest] - 1) // int(mm) >= ed.MIN_ACF_POINTS:
                # lag-1 decides, B1's n and minimum play no part: one read for every deviation
                rules = replace(rules, b1_n=None, b1_min=ed.MIN_B1_GROUPS)
        key = (int(mm), dmax, rules)
        if key not in id_cache:
            id_cache[key] = record.identify(int(mm), dmax, rules)
        nid = id_cache[key]
        if nid.method == "none" and i > 0:  # too few averages: the shorter τ's noise
            alphas[i] = alphas[i - 1]
            methods.append("previous")
            continue
        alphas[i] = max(min(nid.alpha, 2), -2 if dmax == 2 else -4)
        if not stable32 and nid.method == "b1" and i > 0 and alphas[i] > alphas[i - 1]:
            # B1 from 8–29 averages misreads random-walk FM as flicker or white FM in ≈ 40 %
            # of records (α read higher than at the shorter τ, where power-law noise can only
            # steepen): the shorter τ's α is kept (Monte-Carlo coverage).
            # A phase-noise reading split by R(n) (``b1-rn``) is no such misreading (B1 of
            # random-walk FM is ≈ N/2, of PM ≈ 2/3) and stands, as in Stable32 (Sr87 m = 100,
            # PHASE.DAT m = 100: flicker PM after white FM)
            alphas[i] = alphas[i - 1]
            methods.append("b1-previous")
            continue
        methods.append(nid.method)
    return alphas, tuple(methods)


def _pooled_edf(name: str, m: IntArray, alphas: IntArray, sizes: list[int]) -> FloatArray:
    """The equivalent degrees of freedom summed over the stretches (``sizes``: their phase
    points) long enough for each factor (NaN where none contributes)."""
    edf = np.zeros(m.size)
    for n_phase in sizes:
        for i, mm in enumerate(m.tolist()):
            if mm <= registry.get(name).max_factor(n_phase):
                e = _edf(name, int(alphas[i]), int(mm), n_phase)
                edf[i] += e if math.isfinite(e) and e > 0 else 0.0
    edf[edf <= 0] = np.nan
    return edf


DEFAULT_MAX_WORK: Final = 3e10
"""Arithmetic operations :func:`stability` takes on before it refuses (``max_work``):
about half a minute on one core (:func:`.deviations.work`: ≈ 1 ns per operation)."""


def factor_sets(
    names: list[str], taus: str | npt.ArrayLike, tau0_s: float, n_long: int
) -> dict[str, IntArray]:
    """The averaging factors of each deviation for a longest stretch of ``n_long`` phase
    points: ``""`` the common set (every deviation but theo1, up to the largest
    :func:`.deviations.max_factor`), theo1 its own even set (:func:`factors`).

    Parameters
    ----------
    names : list of str
        Deviation names.
    taus : str or array_like
        Named τ set or averaging times [s].
    tau0_s : float
        Sample interval [s].
    n_long : int
        Phase points of the longest stretch.

    Returns
    -------
    dict of str to numpy.ndarray
        Averaging factors per set.
    """
    others = [n for n in names if n != "theo1"]
    top = max(registry.get(n).max_factor(n_long) for n in others) if others else 1
    sets = {"": factors(taus, tau0_s, top)}
    for name in names:
        sets[name] = (
            factors(taus, tau0_s, registry.get(name).max_factor(n_long), theo1=True)
            if name == "theo1"
            else sets[""]
        )
    return sets


def check_work(
    names: list[str],
    sets: dict[str, IntArray],
    sizes: list[int],
    max_work: float,
    taus: str | npt.ArrayLike = "",
    where: str = "",
) -> float:
    """The estimated operations of the deviations ``names`` at the factors ``sets``
    (:func:`factor_sets`) over stretches of ``sizes`` phase points
    (:func:`.deviations.work`, summed); a :class:`ThermocalInputError` naming ``deviations``,
    ``taus`` and ``max_work`` when beyond ``max_work``.  Theo1 costs O(N·m) per factor (NIST
    SP 1065 eq. 30; the total family O(N log m), eqs. 27–29), so its every τ of a long record
    grows as N³: the refusal comes before any work, with the estimate and the costliest
    deviation (``where``: the file, named first).

    Parameters
    ----------
    names : list of str
        Deviation names.
    sets : dict of str to numpy.ndarray
        Averaging factors (:func:`factor_sets`).
    sizes : list of int
        Phase points of each stretch.
    max_work : float
        Largest allowed estimate [operations].
    taus : str or array_like, optional
        τ set named in the message.
    where : str, optional
        File named in the message.

    Returns
    -------
    float
        Estimated operations.

    Raises
    ------
    ThermocalInputError
        When the estimate exceeds ``max_work``.
    """
    if not math.isfinite(max_work) and max_work > 0:
        return math.nan
    if not max_work > 0:
        raise ParameterError("max_work", f"{{name}} {max_work!r}: give a positive operation count")
    per = {n: sum(registry.get(n).estimated_work(size, sets[n]) for size in sizes) for n in names}
    total = sum(per.values())
    if total > max_work:
        worst = max(per, key=lambda n: per[n])
        spec = taus if isinstance(taus, str) else "(the τ list)"
        fewer = "a shorter τ list" if spec == "octave" else "{taus} octave"
        raise ThermocalInputError.naming(
            (f"{where}: " if where else "")
            + f"{{deviations}} {','.join(names)} at {{taus}} {spec} on {sum(sizes)} points "
            f"needs about {total:.2g} operations ({worst}: {per[worst]:.2g}), beyond the "
            f"budget of {max_work:.2g}; use {fewer} or fewer deviations, or raise "
            f"{{max_work}} to {_ceil2(total)} to run it",
            "deviations",
            "taus",
            "max_work",
        )
    return total


def _ceil2(x: float) -> str:
    """``x`` rounded up to two significant digits, as a number the option takes."""
    if x <= 0:
        return "0"
    e = 10.0 ** (math.floor(math.log10(x)) - 1)
    return f"{math.ceil(x / e) * e:.2g}"


def _check_request(names: list[str], data_type: str, noise_id: str) -> None:
    """The data type and the identification rules checked for the deviations ``names``."""
    if data_type not in registry.DATA_TYPES:
        raise ParameterError("data_type", f"{{name}} {data_type!r}: use rate or phase")
    if noise_id not in NOISE_IDS:
        raise ParameterError("noise_id", f"{{name}} {noise_id!r}: use {' or '.join(NOISE_IDS)}")
    for name in names:
        if data_type not in registry.get(name).data_types:
            raise ParameterError(
                "data_type",
                f"{{name}} {data_type!r}: {name} takes "
                + " or ".join(registry.get(name).data_types),
            )


def _curve(
    name: str,
    m: IntArray,
    record: _Record,
    alpha: int | None,
    id_cache: dict[tuple[int, int, ed.IdRules], ed.NoiseId],
    noise_id: str,
    confidence: float,
    bias_correct: bool,
    unit: str,
) -> DeviationCurve:
    """One deviation of the record at the factors ``m``, with its interval (:func:`stability`)."""
    dev, cnt = record.sums(name, m)
    alphas, methods = _noise_exponents(
        name, m, record, alpha, id_cache, noise_id, np.asarray(cnt, dtype=np.float64)
    )
    edf = _pooled_edf(name, m, alphas, record.sizes)
    ok = np.isfinite(edf) & np.isfinite(dev)
    lo = np.full(m.size, np.nan)
    hi = np.full(m.size, np.nan)
    if ok.any():  # an EDF ≪ 1 (Theo1's fit at the record's end): χ² quantile 0, high ∞
        with np.errstate(divide="ignore"):
            lo_ok, hi_ok = ed.confidence_interval(dev[ok], edf[ok], confidence)
        lo[ok], hi[ok] = lo_ok, hi_ok
    bias = None
    if bias_correct:
        n_rec = sum(record.sizes) - len(record.sizes) + 1
        bias = np.array(
            [stable32_bias(name, int(a), int(mm), n_rec) for a, mm in zip(alphas, m, strict=True)]
        )
        dev, lo, hi = dev * bias, lo * bias, hi * bias
    tau0_s, data_type = record.tau0_s, record.data_type
    tau = dv.theo1_tau(m, tau0_s) if name == "theo1" else m * float(tau0_s)
    return DeviationCurve(
        name, np.asarray(tau, dtype=np.float64), m, dev, lo, hi, edf, cnt, alphas,
        methods, _unit(name, unit, data_type), bias,
    )  # fmt: skip


def stability(
    values: npt.ArrayLike,
    tau0_s: float,
    names: list[str],
    taus: str | npt.ArrayLike = "octave",
    *,
    data_type: str = "rate",
    segments: list[slice] | None = None,
    unit: str = "",
    confidence: float = 0.6826894921370859,
    alpha: int | None = None,
    bias_correct: bool = False,
    noise_id: str = "thermocal",
    max_work: float = DEFAULT_MAX_WORK,
    where: str = "",
    overwrite: bool = False,
    progress: Callable[[float], None] | None = None,
) -> StabilityResult:
    r"""Several deviations of one record of rate or phase data, with chi-square intervals.

    Parameters
    ----------
    values : array_like
        Rate samples [unit] (each the mean over τ0) or phase points [unit].
    tau0_s : float
        Sample interval τ0 [s].
    names : list of str
        Registered deviations (:func:`thermocal.stability.registry.names`).
    taus : {"octave", "decade", "log", "all"} or array_like
        A named τ set or averaging times τ [s].
    data_type : {"rate", "phase"}
        What ``values`` are: rate data give deviations in ``unit``, time deviations in
        ``unit*s``; phase data deviations in ``unit/s``, time deviations in ``unit``.
    segments : list of slice, optional
        The gap-free index ranges (default: one), pooled; their EDFs add.
    unit, confidence : str, float
        Unit of ``values``; confidence level of the intervals (default 0.683, ±1σ).
    alpha : int, optional
        The noise exponent α of the EDF at every τ instead of the identified one.
    bias_correct : bool
        Multiply totdev and htotdev by Stable32's bias factor (:func:`stable32_bias`).
    noise_id : {"thermocal", "stable32"}
        The identification's rules (:func:`_noise_exponents`).
    max_work, where : float, str
        Operations allowed before the request is refused (:func:`check_work`); the file
        the refusals name.
    overwrite : bool
        Phase data may be centred in ``values``' own buffer (destroyed; rate: never).
    progress : callable, optional
        Called with the rising fraction (0–1) of the total family's sums done; 1.0 at the end.

    Returns
    -------
    StabilityResult
        One :class:`DeviationCurve` per name.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        An unknown data type, too few points, a bad τ list, work beyond ``max_work``.

    Notes
    -----
    Each deviation is its NIST SP 1065 sum over the phase (:mod:`.deviations`); the interval
    (SP 1065 eq. 45) is

    .. math:: \left[\hat\sigma\sqrt{\nu/\chi^2_{(1+p)/2}(\nu)},\;
              \hat\sigma\sqrt{\nu/\chi^2_{(1-p)/2}(\nu)}\right]

    with ν the deviation's EDF for the noise identified per τ (lag-1 autocorrelation,
    Riley & Greenhall 2004; B1 ratio where few averages remain).

    References
    ----------
    .. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.
    .. [2] C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on
       finite differences", Proc. 35th PTTI Meeting, 2003.

    Examples
    --------
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> r = stability(y, 1.0, ["oadev", "mdev"], [1.0, 10.0])
    >>> [round(float(v), 2) for v in r.curves["oadev"].dev]
    [1.0, 0.32]
    """
    with threadpool_limits(limits=1, user_api="blas"):  # many short dots: BLAS threads wait
        _check_request(names, data_type, noise_id)
        record = _new_record(values, tau0_s, data_type, segments, names, overwrite)
        sets = factor_sets(names, taus, tau0_s, max(record.sizes))
        check_work(names, sets, record.sizes, max_work, taus, where)
        m_common = sets[""]
        record.set_octave(m_common)
        with _reporting(progress, names, sets, record.sizes):
            curves = _curves(names, sets, record, alpha, noise_id, confidence, bias_correct, unit)
        return StabilityResult(
            curves, np.asarray(m_common * float(tau0_s), dtype=np.float64), m_common,
            float(tau0_s), data_type, float(confidence), len(record.kept),
            int(sum(record.sizes)), unit, noise_id=noise_id,
        )  # fmt: skip


_TOTAL_SUMS: Final = ("mtotdev", "ttotdev", "htotdev")
"""The deviations whose sums :mod:`.total` computes and reports as it goes."""


def _curves(
    names: list[str],
    sets: dict[str, IntArray],
    record: _Record,
    alpha: int | None,
    noise_id: str,
    confidence: float,
    bias_correct: bool,
    unit: str,
) -> dict[str, DeviationCurve]:
    """Every deviation's curve, the noise identified once per (m, order, rules)."""
    id_cache: dict[tuple[int, int, ed.IdRules], ed.NoiseId] = {}
    return {
        n: _curve(n, sets[n], record, alpha, id_cache, noise_id, confidence, bias_correct, unit)
        for n in names
    }


@contextlib.contextmanager
def _reporting(
    progress: Callable[[float], None] | None,
    names: list[str],
    sets: dict[str, IntArray],
    sizes: list[int],
) -> Iterator[None]:
    """:func:`.total.reporting` turned into rising fractions of the total family's estimated
    operations (those :func:`.total.tot_sums` reports: htotdev's m = 1 is ohdev's); 1.0
    when the block ends."""
    whole = 0.0
    for n in names:
        if n in _TOTAL_SUMS:
            m = sets[n][sets[n] > 1] if n == "htotdev" else sets[n]
            whole += sum(dv.work(n, size, m) for size in sizes)
    if progress is None:
        yield
        return
    if not whole > 0:
        yield
        progress(1.0)
        return
    lock = threading.Lock()
    state = [0.0, 0.0]  # operations done, fraction shown

    def add(ops: float) -> None:  # from the worker threads
        with lock:
            state[0] += ops
            frac = min(state[0] / whole, 1.0)
            if frac > state[1]:
                state[1] = frac
                progress(frac)

    with _total.reporting(add):
        yield
    progress(1.0)


def _unit(name: str, unit: str, data_type: str) -> str:
    if not unit:
        return ""
    if data_type == "rate":
        return f"{unit}*s" if registry.get(name).time_deviation else unit
    return unit if registry.get(name).time_deviation else f"{unit}/s"
