"""Equivalent degrees of freedom (EDF) and power-law noise identification.

Symbols: α the exponent of the frequency (rate) power spectral density ``S_y(f) ∝ f^α``
(+2 white PM / quantization, +1 flicker PM, 0 white FM / angle random walk, −1 flicker FM /
bias instability, −2 random-walk FM / rate random walk, −3, −4); N phase points; m the
averaging factor (τ = m τ0).

* :func:`greenhall_edf`: C. A. Greenhall and W. J. Riley, "Uncertainty of stability
  variances based on finite differences", Proc. 35th PTTI Meeting (2003), eqs. (7)–(13) and
  Tables 1–3 (the algorithm Stable32 uses); written here from the paper's equations.
* :func:`edf_totdev`, :func:`edf_htotdev`: NIST SP 1065 (2008) §5.2.11, §5.2.14
  (``b·(N/m) − c``; Htot ``(N/m)/(b0 + b1·m/N)``), with Stable32's rule where those do not
  serve (phase noise; Htot below m = 16): the simple EDF of :func:`edf_simple` (Howe,
  Allan & Barnes 1981) + 2, read from Stable32's printed bounds.
* :func:`edf_mtotdev`: the rule Stable32's MTOT/TTOT intervals follow (Greenhall's modified
  Allan EDF below m = 10, a line in N/m above), read from Stable32's printed bounds.
* :func:`edf_theo1`: Howe's empirical Theo1 EDF per noise type (SP 1065 §5.2.16).
* :func:`identify_noise`: lag-1 autocorrelation (W. J. Riley and C. A. Greenhall, "Power law
  noise identification using the lag 1 autocorrelation", Proc. 18th EFTF, 2004), with the
  B1 ratio (Barnes 1969; D. A. Howe et al., 2000) when fewer than 30 averaged points remain;
  on phase data the r1 of every difference order from one pass over the decimated phase
  (:func:`lag1_of_differences`) and the walk on them (:func:`identify_phase_lag1`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.stability import quantiles as _quantiles

FloatArray = npt.NDArray[np.float64]

ONE_SIGMA_CONFIDENCE: Final = math.erf(1.0 / math.sqrt(2.0))
"""0.6827, the confidence of a ±1σ interval (the Stable32 default)."""

J_MAX: Final = 100
"""Greenhall's summation limit beyond which the large-sample approximations are used."""

MIN_ACF_POINTS: Final = 30
"""Averaged points the lag-1 autocorrelation method needs (Riley & Greenhall 2004)."""

MIN_B1_GROUPS: Final = 8
"""m-averages the B1 ratio needs; with fewer, no noise type is identified at that τ and
the caller carries the α of the next shorter τ (the choice that reproduces Stable32's α column
on its PHASE.DAT: its last octave point, 7 averages, keeps the white FM of the one before)."""

STABLE32_B1_MIN_TOTAL: Final = 6
"""Stable32's noise identification (``noise_id="stable32"`` in
:func:`thermocal.stability.family.stability`, the ``allan`` command's ``stable32`` noise
identification), read from its
printed α columns (none written by thermocal); the evidence is every Stable32 output in
allantools' and allantoolkit's test data (benchmarks/stable32_conformance.py: with these
rules all 691 rows with bounds and all 1924 all-τ rows of the OCXO record carry Stable32's
α):

* B1 is judged against the theoretical B1(n, μ) at n = the deviation's number of terms
  (Stable32's "#" column: N − 2m for OADEV, the averages − 1 for ADEV, …), not at the
  number of m-averages the ratio is taken over.  The OCXO all-τ OADEV, MDEV, TDEV and
  OHDEV outputs have 69 τ each with 8–29 averages: all 69 read Stable32's α that way
  (OADEV: 41 at n = the averages); the Cs 5071A's m = 2·10⁴, 4·10⁴ (27, 13 averages) read
  white FM only that way.  For the overlapping deviations B1 then cannot read random-walk
  FM (its boundary grows with the record), which is why thermocal's own rule keeps Barnes'
  n and bounds B1's reading by the shorter τ's α.
* No bound by the shorter τ's α.
* r1 of n points is taken as r1·(n − 1)/n (the variance under it with n − 1): the OCXO
  all-τ m = 113 and 463 (2δ = −0.503, −0.509 with r1 as Riley & Greenhall print it, a hair
  past −0.5) read Stable32's random-walk FM only that way, in every deviation, and no
  other lag-1 row of the six records changes.
* Rate data: the lag-1 method reads the m-averages with their mean removed, not their
  line: all 167 OCXO all-τ rows with ≥ 30 averages read Stable32's α that way, m = 5
  (flicker PM) only that way.
* Below 8 averages the overlapping Allan and Hadamard deviations keep the shorter τ's α,
  the non-overlapping ADEV and HDEV below 10 (:data:`STABLE32_B1_MIN_NONOVERLAPPING`); the
  total family (totdev, mtotdev, ttotdev, htotdev) reads B1 down to this many averages:
  PHASE.DAT m = 128 (MTOT, TTOT, Htot), Sr87 m = 200, GPS m = 32768, 53230A m = 8192
  (6–7 averages) read Stable32's α that way and not by keeping the shorter τ's, PHASE.DAT's
  decade m = 200 (5 averages) and the rows with 2–4 averages keep it."""

STABLE32_B1_MIN_NONOVERLAPPING: Final = 10
"""The fewest averages Stable32's B1 reads for the non-overlapping ADEV and HDEV (below: the
shorter τ's α).  On the OCXO all-τ outputs the ADEV and HDEV rows with 8–9 averages carry
the α of the last row with 10 (flicker FM), where their B1 reads random-walk FM; the ADEV
row at m = 1884 (10 averages) reads random-walk FM by B1, as Stable32.  With this bound all
69 B1 rows of each equal Stable32's α (66 and 60 without it)."""

# Table 1 (modified variances, F = 1) and Table 2 (unmodified, F = m) of Greenhall & Riley
# 2003: (a0, a1) of 1/edf ≈ (a0 − a1/r)/r, indexed [α][d] with d = 1, 2, 3.
_TABLE1: Final[dict[int, tuple[tuple[float, float] | None, ...]]] = {
    2: ((2.0 / 3.0, 1.0 / 3.0), (7.0 / 9.0, 0.5), (22.0 / 25.0, 2.0 / 3.0)),
    1: ((0.840, 0.345), (0.997, 0.616), (1.141, 0.843)),
    0: ((1.079, 0.368), (1.033, 0.607), (1.184, 0.848)),
    -1: (None, (1.048, 0.534), (1.180, 0.816)),
    -2: (None, (1.302, 0.535), (1.175, 0.777)),
    -3: (None, None, (1.194, 0.703)),
    -4: (None, None, (1.489, 0.702)),
}
_TABLE2: Final[dict[int, tuple[tuple[float, float] | None, ...]]] = {
    2: ((1.5, 0.5), (35.0 / 18.0, 1.0), (231.0 / 100.0, 1.5)),
    1: ((78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)),
    0: ((2.0 / 3.0, 1.0 / 6.0), (2.0 / 3.0, 1.0 / 3.0), (7.0 / 9.0, 0.5)),
    -1: (None, (0.852, 0.375), (0.997, 0.617)),
    -2: (None, (1.079, 0.368), (1.033, 0.607)),
    -3: (None, None, (1.053, 0.553)),
    -4: (None, None, (1.302, 0.535)),
}
_TABLE3: Final = ((6.0, 4.0), (15.23, 12.0), (47.8, 40.0))
"""(b0, b1) of the α = +1 normalisation (b0 + b1 ln m)² (Table 3)."""


def _sw(t: FloatArray, alpha: int) -> FloatArray:
    """Greenhall eq. (7): the generalised autocovariance kernel of phase noise of type α."""
    a = np.abs(t)
    with np.errstate(divide="ignore", invalid="ignore"):
        lg = np.where(a > 0, np.log(np.where(a > 0, a, 1.0)), 0.0)
    if alpha == 2:
        return -a
    if alpha == 1:
        return t**2 * lg
    if alpha == 0:
        return a**3
    if alpha == -1:
        return -(t**4) * lg
    if alpha == -2:
        return -(a**5)
    if alpha == -3:
        return t**6 * lg
    if alpha == -4:
        return a**7
    raise ValueError(f"noise exponent α must be an integer in −4…2, got {alpha}")


def _sx(t: FloatArray, f: float, alpha: int) -> FloatArray:
    """Eq. (8): the filter of length 1/F applied (F = ∞: the limit sw(t, α + 2))."""
    if math.isinf(f):
        return _sw(t, alpha + 2)
    return f * f * (2.0 * _sw(t, alpha) - _sw(t - 1.0 / f, alpha) - _sw(t + 1.0 / f, alpha))


_BINOMIAL: Final = {1: (2, -1), 2: (6, -4, 1), 3: (20, -15, 6, -1)}


def _sz(t: FloatArray, f: float, alpha: int, d: int) -> FloatArray:
    """Eq. (9): the d-th difference (d = 1, 2, 3) of ``_sx``."""
    c = _BINOMIAL[d]
    out = c[0] * _sx(t, f, alpha)
    for k in range(1, d + 1):
        out = out + c[k] * (_sx(t - k, f, alpha) + _sx(t + k, f, alpha))
    return np.asarray(out, dtype=np.float64)


def _basic_sum(j: int, m_terms: float, s: float, f: float, alpha: int, d: int) -> float:
    """Eq. (10): sz²(0) + 2 Σ_{i=1}^{J−1} (1 − i/M) sz²(i/S) + (1 − J/M) sz²(J/S)."""
    first = float(_sz(np.zeros(1), f, alpha, d)[0]) ** 2
    last = (1.0 - j / m_terms) * float(_sz(np.array([j / s]), f, alpha, d)[0]) ** 2
    i = np.arange(1, int(j), dtype=np.float64)
    mid = float(np.sum(2.0 * (1.0 - i / m_terms) * _sz(i / s, f, alpha, d) ** 2))
    return first + mid + last


def greenhall_edf(
    alpha: int, d: int, m: int, n_phase: int, *, overlapping: bool, modified: bool
) -> float:
    r"""Equivalent degrees of freedom of a finite-difference variance.

    Parameters
    ----------
    alpha : int
        Power-law noise exponent α (S_y(f) ∝ f^α); needs α + 2d > 1.
    d : int
        Order of the phase difference: 2 for the Allan family (ADEV, OADEV, MDEV, TDEV),
        3 for the Hadamard family (HDEV, OHDEV).
    m : int
        Averaging factor (τ = m τ0).
    n_phase : int
        Phase points N.
    overlapping : bool
        Stride S = 1 (every start), else S = m.
    modified : bool
        Filter factor F = 1 (MDEV, TDEV), else F = m.

    Returns
    -------
    float
        The EDF ν; NaN when N < L (no term).

    Raises
    ------
    ValueError
        α + 2d ≤ 1 (the variance does not converge).

    Notes
    -----
    The EDF of a variance estimate V is the ν of the chi-square law with its mean and
    variance,

    .. math:: \nu = \frac{2\,(\mathrm{E}\,V)^2}{\mathrm{Var}\,V},

    evaluated by Greenhall & Riley's algorithm (eqs. 11–13, Tables 1–3) with L = m/F + m d
    phase points per term, M = 1 + ⌊S(N − L)/m⌋ terms, J = min(M, (d+1)S) and r = M/S.

    References
    ----------
    .. [1] C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on
       finite differences", Proc. 35th PTTI Meeting, 2003.

    Examples
    --------
    White FM, overlapping Allan variance of 1001 phase points at m = 1 (Stable32 prints
    782 for its record PHASE.DAT there):

    >>> round(greenhall_edf(0, 2, 1, 1001, overlapping=True, modified=False), 1)
    782.0
    """
    f = 1.0 if modified else float(m)
    s = float(m) if overlapping else 1.0
    if alpha + 2 * d <= 1:
        raise ValueError(f"Greenhall EDF needs α + 2d > 1 (α = {alpha}, d = {d})")
    big_l = m / f + m * d
    if n_phase < big_l:
        return float("nan")
    big_m = 1.0 + math.floor(s * (n_phase - big_l) / m)
    j = min(big_m, (d + 1) * s)
    r = big_m / s
    if modified:  # case 1: modified variances, every α
        if j <= J_MAX:
            inv = _basic_sum(int(j), big_m, s, 1.0, alpha, d) / (
                float(_sz(np.zeros(1), 1.0, alpha, d)[0]) ** 2 * big_m
            )
        elif r > d + 1:
            a0, a1 = _coeffs(_TABLE1, alpha, d)
            inv = (a0 - a1 / r) / r
        else:
            mp = J_MAX / r
            inv = _basic_sum(J_MAX, J_MAX, mp, 1.0, alpha, d) / (
                float(_sz(np.zeros(1), 1.0, alpha, d)[0]) ** 2 * J_MAX
            )
        return 1.0 / inv
    if alpha <= 0:  # case 2: unmodified, α ≤ 0
        if j <= J_MAX:
            fp = float(m) if m * (d + 1) <= J_MAX else math.inf
            inv = _basic_sum(int(j), big_m, s, fp, alpha, d) / (
                float(_sz(np.zeros(1), fp, alpha, d)[0]) ** 2 * big_m
            )
        elif r > d + 1:
            a0, a1 = _coeffs(_TABLE2, alpha, d)
            inv = (a0 - a1 / r) / r
        else:
            mp = J_MAX / r
            inv = _basic_sum(J_MAX, J_MAX, mp, math.inf, alpha, d) / (
                float(_sz(np.zeros(1), math.inf, alpha, d)[0]) ** 2 * J_MAX
            )
        return 1.0 / inv
    return _pm_edf(alpha, d, m, j, big_m, s, r)


def _pm_edf(alpha: int, d: int, m: int, j: float, big_m: float, s: float, r: float) -> float:
    """Greenhall & Riley's EDF of an unmodified variance at phase noise (cases 3 and 4)."""
    if alpha == 1:  # case 3: unmodified, flicker PM
        if j <= J_MAX:
            inv = _basic_sum(int(j), big_m, s, float(m), 1, d) / (
                float(_sz(np.zeros(1), float(m), 1, d)[0]) ** 2 * big_m
            )
        else:
            b0, b1 = _TABLE3[d - 1]
            norm = (b0 + b1 * math.log(m)) ** 2
            if r > d + 1:
                a0, a1 = _coeffs(_TABLE2, 1, d)
                inv = (a0 - a1 / r) / (norm * r)
            else:
                mp = J_MAX / r
                inv = _basic_sum(J_MAX, J_MAX, mp, mp, 1, d) / (norm * J_MAX)
        return 1.0 / inv
    # case 4: unmodified, white PM
    if math.ceil(r) <= d:  # the exact sum (the paper's small-K case)
        inv = _basic_sum(int(j), big_m, s, float(m), 2, d) / (
            float(_sz(np.zeros(1), float(m), 2, d)[0]) ** 2 * big_m
        )
        return 1.0 / inv
    a0 = math.comb(4 * d, 2 * d) / math.comb(2 * d, d) ** 2
    a1 = d / 2.0
    return 1.0 / ((a0 - a1 / r) / big_m)


def _coeffs(
    table: dict[int, tuple[tuple[float, float] | None, ...]], alpha: int, d: int
) -> tuple[float, float]:
    row = table[alpha][d - 1]
    if row is None:
        raise ValueError(f"no Greenhall table entry for α = {alpha}, d = {d}")
    return row


# --- total-deviation family (SP 1065 Tables 7, 8 and §5.2.14) --------------------------------

_TOT: Final = {0: (1.50, 0.0), -1: (1.17, 0.22), -2: (0.93, 0.36)}
_MTOT: Final = {
    2: (1.90, 2.10),
    1: (1.20, 1.40),
    0: (1.10, 1.20),
    -1: (0.85, 0.50),
    -2: (0.75, 0.31),
}
_HTOT: Final = {0: (0.559, 1.004), -1: (0.868, 1.140), -2: (0.938, 1.696)}


STABLE32_SIMPLE_OFFSET: Final = 2.0
"""What Stable32 adds to the simple EDF where its total deviations use it (read from its
printed bounds; see :func:`edf_stable32_simple`)."""


def edf_simple(n_phase: int, m: int, alpha: int) -> float:
    """The "simple" EDF approximations of the overlapping Allan variance (D. A. Howe,
    D. W. Allan and J. A. Barnes, "Properties of signal sources and measurement methods",
    Proc. 35th Frequency Control Symposium, 1981; NIST SP 1065 §5.3.3), N phase points:

    * α = +2 (white PM): ``(N + 1)(N − 2m) / (2(N − m))``
    * α = +1 (flicker PM): ``exp(√(ln((N − 1)/(2m)) · ln((2m + 1)(N − 1)/4)))``
    * α = 0 (white FM): ``(3(N − 1)/(2m) − 2(N − 2)/N) · 4m²/(4m² + 5)``
    * α = −1 (flicker FM): ``2(N − 2)²/(2.3N − 4.9)`` at m = 1, ``5N²/(4m(N + 3m))`` above
    * α = −2 (random-walk FM): ``(N − 2)/m · ((N − 1)² − 3m(N − 1) + 4m²)/(N − 3)²``

    NaN outside their domain (N ≤ 2m); α outside −2…2 is refused.

    Parameters
    ----------
    n_phase : int
        Number of phase points N.
    m : int
        Averaging factor [samples].
    alpha : int
        Power-law noise exponent α (+2 … −2).

    Returns
    -------
    float
        Equivalent degrees of freedom [1].

    References
    ----------
    - NIST SP 1065 (Riley 2008), Table 5 (Howe, Allan & Barnes simple approximations).
    """
    n = float(n_phase)
    if n <= 2 * m:
        return float("nan")
    if alpha == 2:
        return (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m))
    if alpha == 1:
        a = math.log((n - 1.0) / (2.0 * m))
        b = math.log((2.0 * m + 1.0) * (n - 1.0) / 4.0)
        return math.exp(math.sqrt(a * b))
    if alpha == 0:
        return (
            (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n) * 4.0 * m * m / (4.0 * m * m + 5.0)
        )
    if alpha == -1:
        if m == 1:
            return 2.0 * (n - 2.0) ** 2 / (2.3 * n - 4.9)
        return 5.0 * n * n / (4.0 * m * (n + 3.0 * m))
    if alpha == -2:
        return (n - 2.0) / m * ((n - 1.0) ** 2 - 3.0 * m * (n - 1.0) + 4.0 * m * m) / (n - 3.0) ** 2
    raise ValueError(f"the simple EDF covers α = −2 … 2, not α = {alpha}")


def edf_stable32_simple(n_phase: int, m: int, alpha: int) -> float:
    """The simple EDF (:func:`edf_simple`) plus 2 (:data:`STABLE32_SIMPLE_OFFSET`): the rule
    Stable32's intervals follow for the total deviations where the total-variance EDF
    tables (SP 1065 Tables 7, 9) do not serve: TOTDEV at phase noise (α = +1, +2), Htot at
    phase noise and below m = 16 for white, flicker and random-walk FM.

    Read from Stable32's printed bounds (exact chi-square intervals, see
    :func:`edf_mtotdev`), none of them written by thermocal; Stable32 − simple formula:

    * TOTDEV, flicker PM: GPS 1PPS record of allantools' test data (N = 241218) m = 32768,
      65536: 216.0 − 214.0, 43.6 − 41.6; Keysight 53230A record (N = 55688) m = 2048, 4096:
      924.3 − 922.4, 390.6 − 388.8.
    * Htot, flicker PM: PHASE.DAT (N = 1001) m = 128, 256: 50.6 − 48.6, 18.6 − 16.5; white PM
      (Stable32's run with the noise set by hand) m = 1–256: 330–502, 1.2–2.0 above.
    * Htot below m = 16 on the Sr87 clock record (N = 1253; allantoolkit's test assets):
      flicker FM m = 1, 4: 1090 − 1088.0, 390 − 387.9; random-walk FM m = 2: 627 − 624.5;
      white FM m = 8, 10 and PHASE.DAT m = 1, 2, 4, 8: within 0.1 % of simple + 2.

    The same 1.8–2.1 at EDF 18 as at 924: an offset, not a change of N or m.  Greenhall's
    overlapping Allan/Hadamard EDF, used here before for these cases, put bounds 0.3–30 %
    off (flicker PM) and 2–2.5 ‰ off (Htot flicker and random-walk FM below m = 16).

    Parameters
    ----------
    n_phase : int
        Number of phase points N.
    m : int
        Averaging factor [samples].
    alpha : int
        Power-law noise exponent α (+2 … −2).

    Returns
    -------
    float
        Equivalent degrees of freedom [1].
    """
    return edf_simple(n_phase, m, alpha) + STABLE32_SIMPLE_OFFSET


def edf_totdev(n_phase: int, m: int, alpha: int) -> float:
    r"""Equivalent degrees of freedom of the total variance.

    Parameters
    ----------
    n_phase : int
        Phase points N.
    m : int
        Averaging factor.
    alpha : int
        Power-law noise exponent α.

    Returns
    -------
    float
        The EDF ν.

    Notes
    -----
    NIST SP 1065 Table 7 for white, flicker and random-walk FM (α = 0, −1, −2; b = 1.50,
    1.17, 0.93 and c = 0, 0.22, 0.36):

    .. math:: \nu = b\,\frac{N}{m} - c

    Phase noise (α > 0): :func:`edf_stable32_simple`, as Stable32; α < −2: Greenhall's
    overlapping Allan EDF at α = −2.

    References
    ----------
    .. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.
    .. [2] D. A. Howe, "The total deviation approach to long-term characterization of
       frequency stability", IEEE Trans. UFFC 47(5), 2000.

    Examples
    --------
    White FM, 1001 phase points, m = 10: 1.5 · 100.1 = 150.15.

    >>> round(edf_totdev(1001, 10, 0), 2)
    150.15
    """
    if alpha in _TOT:
        b, c = _TOT[alpha]
        return b * n_phase / m - c
    if alpha > 0:
        return edf_stable32_simple(n_phase, m, min(alpha, 2))
    return greenhall_edf(max(alpha, -2), 2, m, n_phase, overlapping=True, modified=False)


MTOT_GREENHALL_BELOW: Final = 10
"""Averaging factors below this take Greenhall's EDF of the modified Allan variance for
MTOT/TTOT, as Stable32 does (its printed bounds: m ≤ 8 Greenhall, m ≥ 10 the linear rule;
m = 9 was in no reference output and follows the Greenhall side)."""

_MTOT_STABLE32: Final = {1: (1.730, 2.987), 0: (1.330, 1.891), -1: (0.920, 0.759)}
"""(b, c) of Stable32's MTOT/TTOT EDF ``b·N/m − c`` at m ≥ 10, read here from Stable32's
printed 68.3 % bounds (see :func:`edf_mtotdev`)."""


def edf_mtotdev(n_phase: int, m: int, alpha: int) -> float:
    """Modified total (and time total) variance EDF, the rule Stable32's intervals follow.

    * m < 10 (:data:`MTOT_GREENHALL_BELOW`): Greenhall's EDF of the modified Allan variance
      (:func:`greenhall_edf`, d = 2, overlapping, F = 1), every α.
    * m ≥ 10: ``b·N/m − c`` with (b, c) = (1.730, 2.987) for α = +1, (1.330, 1.891) for
      α = 0, (0.920, 0.759) for α = −1.  α = +2 and −2, which no Stable32 output at hand
      shows at m ≥ 10, take NIST SP 1065 Table 8 (1.90, 2.10 | 0.75, 0.31): not checked
      against Stable32.

    Source of the rule: Stable32's printed bounds are exact chi-square intervals (both
    bounds give one EDF, to 1e-4; Stable32 computes χ² by Abramowitz & Stegun 26.4.17 with
    26.2.22 above EDF 100, which explains its 1 % offset there), so each printed row gives
    Stable32's EDF.  On PHASE.DAT (N = 1001, this package's tests/data) and on the public
    Sr87 clock record (N = 1253, Stable32 1.60 outputs in the allantoolkit project's
    test assets) the rows at m ≤ 8 equal Greenhall's modified-Allan EDF (N = 1001, m = 1, 2,
    4, 8: 780.3–781.7, 478.7–479.3, 240.0, 118.9 against 782.0, 479.0, 240.0, 118.9); the
    rows at m ≥ 10 lie on one line in N/m per α.  The coefficients were fitted on Sr87's
    octave rows (α = 0), PHASE.DAT's m = 128, 256 (α = +1) and Sr87's decade m = 200, 400
    (α = −1) and predict the other rows (PHASE.DAT m = 16–64, Sr87 m = 10, 20, 40, 100 and
    the frequency-data run) within 0.07 % of EDF (bounds within 2e-5).  SP 1065 Table 8
    (1.10, 1.20 for α = 0) gives EDFs 12–28 % off Stable32's (bounds off 0.4–2 %).

    Parameters
    ----------
    n_phase : int
        Number of phase points N.
    m : int
        Averaging factor [samples].
    alpha : int
        Power-law noise exponent α (+2 … −2).

    Returns
    -------
    float
        Equivalent degrees of freedom [1].

    References
    ----------
    - NIST SP 1065 (Riley 2008), Table 8; Greenhall & Riley 2003.
    """
    if m < MTOT_GREENHALL_BELOW:
        return greenhall_edf(max(min(alpha, 2), -2), 2, m, n_phase, overlapping=True, modified=True)
    if alpha in _MTOT_STABLE32:
        b, c = _MTOT_STABLE32[alpha]
    else:
        b, c = _MTOT[max(min(alpha, 2), -2)]
    return b * n_phase / m - c


HTOT_FORMULA_FROM: Final = 16
"""From this averaging factor Stable32's Htot EDF for FM noise is SP 1065's
``(N/m)/(b0 + b1·m/N)``; below it, the simple EDF + 2 (:func:`edf_htotdev`)."""


def edf_htotdev(n_phase: int, m: int, alpha: int) -> float:
    """Hadamard total variance EDF, the rule Stable32's intervals follow.

    * α = +2, +1 (phase noise), every m, and α = 0, −1, −2 below m = 16
      (:data:`HTOT_FORMULA_FROM`): the simple EDF + 2 (:func:`edf_stable32_simple`).
    * m ≥ 16, α = 0, −1, −2: SP 1065 §5.2.14, ``(N/m)/(b0 + b1·m/N)`` with (b0, b1) =
      (0.559, 1.004), (0.868, 1.140), (0.938, 1.696) (Howe et al., PTTI 2000, Table 1).
    * α = −3, −4 (no Stable32 output at hand shows them): Greenhall's EDF of the
      overlapping Hadamard variance, which Htot equals at m = 1.

    Against Stable32's printed bounds (read as exact chi-square intervals, with Stable32's
    Abramowitz & Stegun χ² above EDF 100; see :func:`edf_mtotdev`): at m ≥ 16 the formula
    is Stable32's EDF for α = 0 and −1 (PHASE.DAT m = 16–64: 108.8, 52.9, 25.1 against 108.8,
    52.9, 25.1; Sr87 N = 1253, m = 16–256 and 200, 400: within 0.1 %).  Below m = 16:
    PHASE.DAT (N = 1001) white FM m = 1, 2, 4, 8: 668.0, 571.4, 348.1, 184.2 (simple + 2:
    667.8, 571.9, 348.4, 184.0); Sr87 white FM m = 8, 10: 230.3, 185.5 (230.2, 185.5),
    flicker FM m = 1, 4: 1090, 390 (1090.0, 389.9), random-walk FM m = 2: 627 (626.5).
    Greenhall's overlapping-Hadamard EDF gives 897, 359 and 666 for the last three.

    Parameters
    ----------
    n_phase : int
        Number of phase points N.
    m : int
        Averaging factor [samples].
    alpha : int
        Power-law noise exponent α (+2 … −2).

    Returns
    -------
    float
        Equivalent degrees of freedom [1].

    References
    ----------
    - Howe, D. A. et al. (2000), PTTI, Table 1 (Hadamard total variance).
    """
    if alpha > 0 or (m < HTOT_FORMULA_FROM and alpha >= -2):
        return edf_stable32_simple(n_phase, m, min(alpha, 2))
    if alpha in _HTOT:
        b0, b1 = _HTOT[alpha]
        return (n_phase / m) / (b0 + b1 * m / n_phase)
    return greenhall_edf(max(alpha, -4), 3, m, n_phase, overlapping=True, modified=False)


def edf_theo1(n_phase: int, m: int, alpha: int) -> float:
    """Theo1 EDF (Howe & Peppler, "Estimation of very long-term frequency stability using
    a special-purpose statistic", Proc. 2003 joint EFTF/IEEE FCS; D. A. Howe and T. N.
    Tasset, "Theo1: characterization of very long-term frequency stability", Proc. 18th
    EFTF 2004; NIST SP 1065 §5.2.16; W. J. Riley, "Confidence intervals and bias
    corrections for the Stable32 variance functions", Theo1 EDF), empirical fits in the
    record length N (phase points) and Theo1's averaging factor t = 0.75 m (τ = t τ0),
    both in units of τ0:

    * α = +2 (white PM): ``0.86 (N+1)(N − 4t/3) / (N − t) · t/(t + 1.14)``
    * α = +1 (flicker PM): ``(4.798 N² − 6.374 N t + 12.387 t) / (√(t + 36.6) (N − t))
      · t/(t + 0.3)``
    * α = 0 (white FM): ``((4.1 N + 0.8)/t − (3.1 N + 6.5)/N) · t^1.5/(t^1.5 + 5.2)``
    * α = −1 (flicker FM): ``(2 N² − 1.3 N t − 3.5 t)/(N t) · t³/(t³ + 2.3)``
    * α = −2 (random-walk FM): ``(4.4 N − 2)/(2.9 t) · ((4.4 N − 1)² − 8.6 t (4.4 N − 1)
      + 11.4 t²)/(4.4 N − 3)²``

    ``m`` is Theo1's even averaging factor (τ = 0.75 m τ0, m ≤ N − 1).  Other α (−3, −4)
    take the random-walk FM fit, the steepest the paper gives; NaN when m is out of range
    or the fit is not positive.  The coefficients are as W. J. Riley's Stable32 notes
    print them (read through the allantoolkit project's transcription); SP 1065 itself was
    not at hand.  Checked against the scatter of Theo1 over 2000 simulated records of
    N = 201 (tests/test_noise_terms_theo1_edf.py): white PM 6–11 % above the Monte-Carlo
    EDF, white FM within 5 %, random-walk FM within 15 % for t ≤ 0.22 N — but at t =
    0.56 N (m = 150) the random-walk FM fit gives 0.24 where the simulation gives 1.2: its
    intervals there are far too wide.  Flicker PM/FM were not simulated.  Stable32's own
    Theo1 intervals were not at hand (the PHASE.DAT Theo1 reference prints none).

    Parameters
    ----------
    n_phase : int
        Number of phase points N.
    m : int
        Averaging factor [samples].
    alpha : int
        Power-law noise exponent α (+2 … −2).

    Returns
    -------
    float
        Equivalent degrees of freedom [1].

    References
    ----------
    - Howe & Peppler 2003; Howe & Tasset 2004.
    """
    n = float(n_phase)
    t = 0.75 * m
    if m < 2 or m > n_phase - 1:
        return float("nan")
    if alpha >= 2:
        edf = 0.86 * (n + 1.0) * (n - 4.0 * t / 3.0) / (n - t) * t / (t + 1.14)
    elif alpha == 1:
        edf = (
            (4.798 * n * n - 6.374 * n * t + 12.387 * t)
            / (math.sqrt(t + 36.6) * (n - t))
            * t
            / (t + 0.3)
        )
    elif alpha == 0:
        edf = ((4.1 * n + 0.8) / t - (3.1 * n + 6.5) / n) * t**1.5 / (t**1.5 + 5.2)
    elif alpha == -1:
        edf = (2.0 * n * n - 1.3 * n * t - 3.5 * t) / (n * t) * t**3 / (t**3 + 2.3)
    else:
        a = 4.4 * n
        edf = (a - 2.0) / (2.9 * t) * ((a - 1.0) ** 2 - 8.6 * t * (a - 1.0) + 11.4 * t * t)
        edf /= (a - 3.0) ** 2
    return edf if edf > 0 else float("nan")


# --- noise identification ----------------------------------------------------------------


@dataclass(frozen=True)
class NoiseId:
    """The identified power-law noise at one averaging factor.

    ``alpha`` the integer exponent; ``alpha_float`` the unrounded lag-1 estimate (NaN for
    B1); ``method`` ``"lag1"``, ``"b1"`` or ``"b1-rn"`` (B1 then R(n), :func:`split_pm`)
    (or ``"none"`` when neither could run: α = 0
    assumed); ``d`` differences taken (lag-1 method).

    Attributes
    ----------
    alpha : int
        The power-law exponent α.
    alpha_float : float
        The unrounded lag-1 estimate (NaN for B1).
    method : str
        ``"lag1"``, ``"b1"``, ``"b1-rn"`` or ``"none"``.
    d : int
        Differences taken (lag-1 method).
    """

    alpha: int
    alpha_float: float
    method: str
    d: int


def lag1_autocorrelation(z: FloatArray) -> float:
    r"""r1 = Σ (z_n − z̄)(z_{n+1} − z̄) / Σ (z_n − z̄)²  (Riley & Greenhall 2004, eq. 2).

    Parameters
    ----------
    z : numpy.ndarray
        Samples (phase or rate averages).

    Returns
    -------
    float
        Lag-1 autocorrelation r1 [1].

    Notes
    -----
    .. math:: r_1 = \frac{\sum (z_n - \bar z)(z_{n+1} - \bar z)}{\sum (z_n - \bar z)^2}

    References
    ----------
    - Riley & Greenhall 2004, eq. 2.
    """
    c = z - z.mean()
    den = float(c @ c)
    return float(c[:-1] @ c[1:]) / den if den > 0 else 0.0


def _detrend(z: FloatArray, deg: int) -> FloatArray:
    """``z`` minus its least-squares polynomial of degree ``deg`` (1 or 2) in the index,
    by projection on the discrete orthogonal polynomials 1, u, u² − ⟨u²⟩ (u = k − k̄): two
    or three dot products, no design matrix (the same fit as a least-squares polyfit)."""
    n = z.size
    u = np.arange(n, dtype=np.float64)
    u -= (n - 1) / 2.0
    out = z - z.mean()
    uu = float(u @ u)
    if uu > 0:
        out -= (float(u @ out) / uu) * u
    if deg >= 2 and n > 2:
        p2 = u * u
        p2 -= uu / n
        pp = float(p2 @ p2)
        if pp > 0:
            out -= (float(p2 @ out) / pp) * p2
    return np.asarray(out, dtype=np.float64)


_BLOCK: Final = 1 << 16
_BLOCK_INDEX: Final = np.arange(_BLOCK, dtype=np.float64)


def _index_dot(z: FloatArray) -> float:
    """Σ_k k z_k, in blocks against one small index array (no array of n indices)."""
    total = 0.0
    for a in range(0, z.size, _BLOCK):
        blk = z[a : a + _BLOCK]
        total += float(_BLOCK_INDEX[: blk.size] @ blk) + a * float(blk.sum())
    return total


def _lag1_linear_detrended(z: FloatArray, *, own: bool = False) -> float:
    """r1 of ``z`` minus its least-squares line, from sums over ``z`` alone (one centred
    copy, no detrended one).  With z_c = z − z̄, u_k = k − (n−1)/2, b = Σ u z_c / Σ u² and
    c = z_c − b u (Σ c = 0):

    Σ c_k² = Σ z_c² − b² Σ u²,   Σ u² = n(n² − 1)/12;
    Σ c_k c_{k+1} = Σ z_c,k z_c,k+1 − b (2 Σ u z_c − (u_0 − 1) z_c,0 − (u_{n−1} + 1) z_c,n−1)
    + b² (Σ u² − u_{n−1}² − u_{n−1}).

    Where the line carries nearly all of Σ z_c² (the subtraction would lose digits) the
    detrended series is formed explicitly (:func:`_detrend`).  ``own``: ``z`` may be
    centred in place (its differences are unchanged)."""
    n = z.size
    if own:
        z -= z.mean()
        zc = z
    else:
        zc = z - z.mean()
    szz = float(zc @ zc)
    if szz <= 0:
        return 0.0
    sums = LagSums(n, szz, _index_dot(zc), float(zc[:-1] @ zc[1:]), float(zc[0]), float(zc[-1]))
    r1 = _lag1_from_sums(sums)
    return lag1_autocorrelation(_detrend(z, 1)) if r1 is None else r1


@dataclass(frozen=True)
class LagSums:
    """Sums over a series z of n points, centred (z_c = z − z̄): ``szz`` Σ z_c², ``uz``
    Σ k z_c,k, ``cross`` Σ z_c,k z_c,k+1, ``first``/``last`` z_c,0 and z_c,n−1.

    Attributes
    ----------
    n : int
        Number of points.
    szz : float
        Σ z_c².
    uz : float
        Σ k z_c,k.
    cross : float
        Σ z_c,k z_c,k+1.
    first, last : float
        z_c,0 and z_c,n−1.
    """

    n: int
    szz: float
    uz: float
    cross: float
    first: float
    last: float


def _lag1_from_sums(s: LagSums) -> float | None:
    """r1 of the linearly detrended series from its :class:`LagSums` (formulas of
    :func:`_lag1_linear_detrended`); None where the line carries nearly all of Σ z_c²
    (the caller detrends explicitly); 0 for a constant series."""
    n = s.n
    if s.szz <= 0:
        return 0.0
    uu = n * (n * n - 1.0) / 12.0
    b = s.uz / uu
    scc = s.szz - b * b * uu
    if not scc > 1e-6 * s.szz:
        return None
    u0, un = -(n - 1) / 2.0, (n - 1) / 2.0
    cross = s.cross
    cross -= b * (2.0 * s.uz - (u0 - 1.0) * s.first - (un + 1.0) * s.last)
    cross += b * b * (uu - un * un - un)
    return cross / scc


def _b1_theory(n: int, mu: int) -> float:
    """Expected B1 (standard over Allan variance) for N averages and τ-exponent μ of the
    Allan variance (Howe, Beard, Greenhall, Riley 2000, Table 3)."""
    if mu == 2:
        return n * (n + 1.0) / 6.0
    if mu == 1:
        return n / 2.0
    if mu == 0:
        return n * math.log(n) / (2.0 * (n - 1.0) * math.log(2.0))
    if mu == -1:
        return 1.0
    if mu == -2:
        return (n * n - 1.0) / (1.5 * n * (n - 1.0))
    return float(n * (1.0 - float(n) ** mu) / (2.0 * (n - 1.0) * (1.0 - 2.0**mu)))


_MU_TO_ALPHA: Final = {-2: 2, -1: 0, 0: -1, 1: -2, 2: -3, 3: -4}


@dataclass(frozen=True)
class IdRules:
    """How :func:`identify_noise` reads the noise.  Defaults: thermocal's (Riley & Greenhall
    2004 and Barnes' B1 as published).  ``b1_n``: the n of the theoretical B1 (None: the
    number of averages); ``b1_min``: the fewest averages B1 reads; ``rate_detrend``: the rate
    averages' line removed before the lag-1 method (else only their mean); ``r1_sample``: r1
    with the sample variance (÷ (n − 1)) under the lag product summed over n − 1 pairs and
    divided by n, i.e. r1·(n − 1)/n.  Stable32's rules: :data:`STABLE32_B1_MIN_TOTAL`.

    Attributes
    ----------
    b1_n : int or None
        n of the theoretical B1 (None: the number of averages).
    b1_min : int
        Fewest averages B1 reads.
    rate_detrend : bool
        Remove the rate averages' line before the lag-1 method.
    r1_sample : bool
        r1 as Stable32 computes it (see above).
    """

    b1_n: int | None = None
    b1_min: int = MIN_B1_GROUPS
    rate_detrend: bool = True
    r1_sample: bool = False


THERMOCAL_RULES: Final = IdRules()


def identify_noise(
    x: FloatArray,
    m: int,
    *,
    dmax: int,
    phase_input: bool,
    rules: IdRules = THERMOCAL_RULES,
) -> NoiseId:
    """Power-law noise α at averaging factor m (Riley & Greenhall 2004; B1 otherwise).

    ``x``: phase points of one gap-free stretch.  Lag-1 method: the phase decimated by m
    (its mean removed, nothing else) when the data were given as phase, else the rate
    averaged over blocks of m (linear trend removed); difference until ρ = r1/(1 + r1) <
    0.25 or d = dmax (``dmax`` counted on phase: 2 for the Allan family, 3 for Hadamard; one
    less on rate); α = −round(2ρ) − 2d (+2 for phase).  With fewer than 30 averaged points:
    the B1 ratio of the standard variance of the m-averages to their Allan variance, against
    the theoretical B1 of each noise (boundaries at geometric means); where B1 reads phase
    noise, the R(n) ratio tells white from flicker PM (:func:`split_pm`).  ``rules``: the
    variants of :class:`IdRules` (Stable32's: :data:`STABLE32_B1_MIN_TOTAL`).

    The decimated phase is not detrended (the differencing removes a line), as in
    Stable32's identification: with a quadratic removed, the 32 points of the Sr87 clock
    record at m = 40 (Stable32 1.60's α column in the allantoolkit project's test assets)
    read white PM where Stable32 reads white FM, in every deviation; with a line removed,
    the 56 points of allantools' Cs 5071A record at m = 10⁴ read white PM where Stable32
    reads white FM.  Without either, every lag-1 α of PHASE.DAT, Sr87, the Cs 5071A, GPS
    and Keysight 53230A records equals Stable32's.  Frequency drift is therefore not removed
    here: remove it from the data first (as Stable32's users do).

    Parameters
    ----------
    x : numpy.ndarray
        Phase points of one gap-free stretch [unit·s].
    m : int
        Averaging factor [samples].
    dmax : int
        Difference order: 2 for the Allan family, 3 for Hadamard.
    phase_input : bool
        Whether the data were given as phase.
    rules : IdRules, optional
        Identification rules (default thermocal's).

    Returns
    -------
    NoiseId
        Noise exponent α and the method that gave it.

    References
    ----------
    - Riley & Greenhall 2004 (lag-1 autocorrelation).
    - Barnes, J. A. (1969), NBS Technical Note 375 (bias functions B1 and B2).

    Examples
    --------
    White FM (α = 0) and random-walk FM (α = −2) rate, as phase points:

    >>> import numpy as np
    >>> w = np.random.default_rng(0).normal(size=4000)
    >>> identify_noise(np.r_[0.0, np.cumsum(w)], 4, dmax=2, phase_input=False).alpha
    0
    >>> rw = np.cumsum(w)
    >>> identify_noise(np.r_[0.0, np.cumsum(rw)], 4, dmax=2, phase_input=False).alpha
    -2
    """
    if phase_input and x[:: max(m, 1)].size >= MIN_ACF_POINTS:
        z = x[:: max(m, 1)]  # a strided view: read block by block, never copied whole
        r1 = lag1_of_differences(z, dmax, shift=phase_shift(x))
        return identify_phase_lag1(r1, z.size, dmax, rules)
    nb = (x.size - 1) // m  # m-averages of the rate: (x_{(k+1)m} − x_{km}) / m
    ym = np.diff(x[: nb * m + 1 : m]) if nb else x[:0].copy()
    if m > 1:
        ym /= m
    if not phase_input:
        return split_pm(identify_rate_averages(ym, dmax=dmax, own=True, rules=rules), x, m)
    return split_pm(_b1_identify(ym, dmax, n_theory=rules.b1_n, min_groups=rules.b1_min), x, m)


def _lag1_in_place(c: FloatArray) -> float:
    """:func:`lag1_autocorrelation` of ``c`` with ``c`` itself centred in place (the same
    arithmetic: no second copy)."""
    np.subtract(c, c.mean(), out=c)
    den = float(c @ c)
    return float(c[:-1] @ c[1:]) / den if den > 0 else 0.0


def _lag1_centred(z: FloatArray, shift: float) -> float:
    """:func:`lag1_autocorrelation` of ``z − shift`` (``z`` possibly a strided view): up to
    :data:`_WHOLE_PHASE` points through one centred copy, longer series in blocks of
    :data:`_CACHE_BLOCK` (the mean of ``z − shift``, then Σ c² and Σ c_k c_{k+1} of c = z −
    shift − that mean over blocks: memory per block, no copy of the whole; equal but for
    the order of the additions, ≈ 1e-16 relative)."""
    n = z.size
    if n <= _WHOLE_PHASE:
        return _lag1_in_place(z - shift)
    total = 0.0
    for a in range(0, n, _CACHE_BLOCK):
        total += float((z[a : a + _CACHE_BLOCK] - shift).sum())
    mean = total / n
    den = num = 0.0
    prev: float | None = None
    for a in range(0, n, _CACHE_BLOCK):
        c = z[a : a + _CACHE_BLOCK] - shift
        c -= mean
        den += float(c @ c)
        num += float(c[:-1] @ c[1:])
        if prev is not None:
            num += prev * float(c[0])
        prev = float(c[-1])
    return num / den if den > 0 else 0.0


def modified_allan_ratio(x: FloatArray, m: int) -> float:
    r"""R(n) = Mod σ²_y(τ) / σ²_y(τ) at τ = m τ0 from the phase ``x`` (both overlapping; τ0
    cancels): ``(Σ_j s_j² / (m² (N − 3m + 1))) / (Σ_i d_i² / (N − 2m))`` with d_i = x_{i+2m}
    − 2 x_{i+m} + x_i and s_j = Σ_{i=j}^{j+m−1} d_i (NIST SP 1065 eqs. 13 and 14).  NaN when
    the record is shorter than 3m + 1 points or has no second difference.

    Parameters
    ----------
    x : numpy.ndarray
        Phase points [unit·s].
    m : int
        Averaging factor [samples].

    Returns
    -------
    float
        Ratio R(n) [1], NaN when undefined.

    Notes
    -----
    .. math:: R(n) = \operatorname{Mod}\sigma_y^2(\tau) / \sigma_y^2(\tau)

    References
    ----------
    - NIST SP 1065 (Riley 2008), eqs. 13 and 14.
    """
    n = x.size
    if m < 1 or n < 3 * m + 1:
        return float("nan")
    d = x[2 * m :] - 2.0 * x[m:-m] + x[: n - 2 * m]
    den = float(d @ d) / d.size
    if not den > 0:
        return float("nan")
    c = np.concatenate(([0.0], np.cumsum(d)))
    s = c[m:] - c[:-m]
    return float(s @ s) / s.size / (m * m) / den


def _r_theory(m: int, alpha: int) -> float:
    """Theoretical R(n) at n = m (D. W. Allan and J. A. Barnes, "A modified Allan variance
    with increased oscillator characterization ability", Proc. 35th FCS, 1981; W. J. Riley,
    NIST SP 1065 §5.6): white PM 1/n; flicker PM ``3 ln(256/27) / (2 (1.038 + 3 ln(2π f_h
    τ)))`` with the measurement bandwidth f_h = 1/(2 τ0), so 2π f_h τ = π n."""
    if alpha == 2:
        return 1.0 / m
    return 3.0 * math.log(256.0 / 27.0) / (2.0 * (1.038 + 3.0 * math.log(math.pi * m)))


def split_pm(nid: NoiseId, x: FloatArray, m: int) -> NoiseId:
    """Where B1 read phase noise (α = +2, which it cannot split), white or flicker PM by
    the R(n) ratio (:func:`modified_allan_ratio`) against the geometric mean of the two
    noises' theoretical R(n) (Riley, SP 1065 §5.6, the B1/R(n) identification Stable32
    uses): above it flicker PM (α = +1, method ``b1-rn``), else white PM.

    Stable32 reads flicker PM there on PHASE.DAT's total family at m = 128, Sr87 at m = 100
    and a Keysight 53230A time-interval record at m = 2048, 4096 (allantools' test data),
    where B1 alone gave white PM.

    Parameters
    ----------
    nid : NoiseId
        Identification from B1.
    x : numpy.ndarray
        Phase points [unit·s].
    m : int
        Averaging factor [samples].

    Returns
    -------
    NoiseId
        ``nid`` with white or flicker PM told apart.
    """
    if nid.method != "b1" or nid.alpha != 2:
        return nid
    r = modified_allan_ratio(x, m)
    if not math.isfinite(r):
        return nid
    bound = math.sqrt(_r_theory(m, 2) * _r_theory(m, 1))
    return NoiseId(1 if r > bound else 2, float("nan"), "b1-rn", 0)


def identify_rate_averages(
    z: FloatArray,
    *,
    dmax: int,
    own: bool = False,
    sums: LagSums | None = None,
    rules: IdRules = THERMOCAL_RULES,
) -> NoiseId:
    """The rate branch of :func:`identify_noise` from the m-averages ``z`` of the rate
    (any scale and offset: block sums serve as well).  ``own``: ``z`` may be centred in
    place; ``sums``: its :class:`LagSums` already taken (``z`` is then only read where the
    sums cannot decide: explicit detrending, differencing, B1); ``rules``: see
    :func:`identify_noise`.

    Parameters
    ----------
    z : numpy.ndarray
        m-averages (or block sums) of the rate.
    dmax : int
        Difference order: 2 for the Allan family, 3 for Hadamard.
    own : bool, optional
        ``z`` may be centred in place (default False).
    sums : LagSums, optional
        Lag sums of ``z`` already taken.
    rules : IdRules, optional
        Identification rules (default thermocal's).

    Returns
    -------
    NoiseId
        Noise exponent α and the method that gave it.
    """
    if z.size >= MIN_ACF_POINTS and not rules.rate_detrend:  # the mean removed, no line
        if sums is not None:  # Σ z_c,k z_c,k+1 / Σ z_c² of the sums: no centred copy
            r1_mean = sums.cross / sums.szz if sums.szz > 0 else 0.0
        else:
            r1_mean = lag1_autocorrelation(z)
        return _lag1_differenced(r1_mean, z, dmax - 1, 0, rules.r1_sample)
    if z.size >= MIN_ACF_POINTS:
        r1 = _lag1_from_sums(sums) if sums is not None else None
        if r1 is None:  # r1 of the detrended averages from sums (no detrended copy)
            r1 = _lag1_linear_detrended(z, own=own)
        # differencing cancels the line but its constant slope, which r1's mean removes
        return _lag1_differenced(r1, z, dmax - 1, 0, rules.r1_sample)
    return _b1_identify(z, dmax, n_theory=rules.b1_n, min_groups=rules.b1_min)


_DIFF_BLOCK = 1 << 20
"""Series longer than this are differenced block by block (:func:`_lag1_of_difference`)."""

_CACHE_BLOCK = 1 << 13
"""Block of the phase's lag-1 passes (:func:`_lag1_centred`): its temporaries stay in the
processor's cache (4× faster than blocks of :data:`_DIFF_BLOCK` on a 10⁷-sample record)."""

_WHOLE_PHASE = 1 << 16
"""Decimated phase series up to this length are centred and differenced whole."""


def _lag1_of_difference(z: FloatArray, d: int, shift: float | None = None) -> float:
    """:func:`lag1_autocorrelation` of ``np.diff(z, d)`` (of ``np.diff(z − shift, d)``
    with ``shift``, element for element the same differences as of a centred copy) without
    the differenced copy: the mean, Σ c² and Σ c_k c_{k+1} (c = w − w̄) gathered over
    blocks of :data:`_DIFF_BLOCK` differences (:data:`_CACHE_BLOCK` with ``shift``; two
    passes; memory per block, not per sample).  Equal to the whole-array formula but for the
    order of the additions (≈ 1e-16 relative)."""
    n = z.size - d

    def part(a: int, b: int) -> FloatArray:
        seg = z[a : b + d]
        return np.diff(seg if shift is None else seg - shift, d)

    if n <= (_DIFF_BLOCK if shift is None else _WHOLE_PHASE):
        return lag1_autocorrelation(part(0, n))
    step = _DIFF_BLOCK if shift is None else _CACHE_BLOCK
    total = 0.0
    for a in range(0, n, step):
        total += float(part(a, min(a + step, n)).sum())
    mean = total / n
    den = num = 0.0
    prev: float | None = None
    for a in range(0, n, step):
        c = part(a, min(a + step, n))
        c -= mean
        den += float(c @ c)
        num += float(c[:-1] @ c[1:])
        if prev is not None:
            num += prev * float(c[0])
        prev = float(c[-1])
    return num / den if den > 0 else 0.0


_LAG_BLOCK: Final = 1 << 15
"""Points of the phase rung per block of :func:`lag1_of_differences` (its buffers, one per
difference order, stay in the processor's cache)."""

_CARRY: Final = 4
"""Points of the previous block each block's window repeats: the third differences ending
in the block and the lag pair across the boundary (orders up to 3; ``dmax + 1`` above, so
that orders 2 and 3 read the same windows and give the same sums)."""

_ONES: Final = np.ones(_LAG_BLOCK + 64)

_LOST: Final = 1e-2
"""Below this fraction of Σ w² the centred Σ c² = Σ w² − N w̄² has lost digits to the mean
(a large frequency offset): :func:`lag1_of_differences` then takes that order's r1 in two
exact passes instead."""


def phase_shift(x: FloatArray) -> float:
    """The offset :func:`lag1_of_differences` removes from a phase record ``x`` before its
    sums: the mean of its first :data:`_LAG_BLOCK` points (numpy's).  One value per record,
    so that a decimation read from ``x`` and one copied from an earlier rung hold the same
    numbers.

    Parameters
    ----------
    x : numpy.ndarray
        Phase points [unit·s].

    Returns
    -------
    float
        The offset [unit·s].
    """
    return float(x[:_LAG_BLOCK].mean())


def _block_orders(w: FloatArray, own: int, bufs: list[FloatArray], acc: FloatArray) -> None:
    """Adds one block's sums to ``acc`` (column d the d-th differences of the window ``w``;
    rows Σ w of order 0, Σ w² of every order, Σ w_k w_{k+1} of the highest order): the
    differences whose last point lies in the block (``own``: where the block starts in
    ``w``), the pairs whose second does."""
    wd = w
    top = acc.shape[1] - 1
    for d in range(top + 1):
        if d:
            nxt = bufs[d - 1][: wd.size - 1]
            np.subtract(wd[1:], wd[:-1], out=nxt)
            wd = nxt
        mine = wd[max(own - d, 0) :]
        if d == 0:  # BLAS against ones: twice numpy's pairwise sum's speed
            acc[0, 0] += float(mine @ _ONES[: mine.size])
        acc[1, d] += float(mine @ mine)
    p0 = max(own - top - 1, 0)
    acc[2, top] += float(wd[p0:-1] @ wd[p0 + 1 :])


def lag1_of_differences(
    z: FloatArray,
    dmax: int,
    *,
    shift: float = 0.0,
    out: FloatArray | None = None,
    then: tuple[int, FloatArray] | None = None,
) -> tuple[float, ...]:
    r"""The lag-1 autocorrelation r1 of ``z − shift`` and of its differences of order 1 …
    ``dmax``, in one pass over ``z`` (Riley & Greenhall 2004, eq. 2, per order).

    ``z`` (possibly a strided view of a longer phase) is read in blocks of
    :data:`_LAG_BLOCK` points; each block, with the :data:`_CARRY` points before it, is
    shifted into a reused buffer (into ``out[a:b]``, a contiguous copy of the decimation,
    when ``out`` is given; ``z`` may then be ``out[:: s]`` itself, s ≥ 1: each block is
    written where no later block reads; read in place when ``z`` is contiguous and
    ``shift`` 0) and differenced order by order into reused buffers.
    Per order d, with w = Δ^d (z − shift) of N = n − d points: Σ w² is gathered per block,
    and Σ w_k w_{k+1} with the pair across each block boundary for d = ``dmax``; below it
    the lag sum follows from the next order's squares, Σ w_k w_{k+1} = (2 Σ w² − w_0² −
    w_{N−1}² − Σ (Δw)²) / 2 (one dot product fewer per order, and no loss where r1 → 1:
    the small Σ (Δw)² is summed itself).  Σ w is the block sums' for d = 0 and, for d ≥ 1,
    telescoped from the end points, Σ Δ^d v = Δ^{d−1}v_{N} − Δ^{d−1}v_0.  With w̄ = Σ w / N:

    Σ c² = Σ w² − w̄ Σ w,   Σ c_k c_{k+1} = Σ w_k w_{k+1} − w̄ (2 Σ w − w_0 − w_{N−1})
    + (N − 1) w̄²,   r1 = Σ c_k c_{k+1} / Σ c²  (0 when Σ c² = 0).

    Where Σ c² < :data:`_LOST` · Σ w² (the mean dominating: a large frequency offset) that
    order is taken in two exact passes (:func:`_lag1_centred`, :func:`_lag1_of_difference`).
    Equal to the whole-array formula on ``np.diff(z − shift, d)`` but for the order of the
    additions (≈ 1e-16 relative).

    Parameters
    ----------
    z : numpy.ndarray
        Phase points (a decimation x[::m]) [unit·s], at least ``dmax + 2``.
    dmax : int
        Highest difference order (0 … 63; 2 for the Allan family, 3 for Hadamard).
    shift : float, optional
        Offset removed first [unit·s] (:func:`phase_shift`; default 0).
    out : numpy.ndarray, optional
        Receives ``z − shift`` (its first ``z.size`` points).
    then : tuple of (int, numpy.ndarray), optional
        ``(s, dest)``: the next decimation, (z − shift)[::s], written into ``dest`` in the
        same pass (``dest`` may be ``z``'s or ``out``'s buffer: each block is written behind
        every later window).  Where ``dest`` overwrites the series and an order needs the
        exact passes, that order's r1 is NaN (read ``z`` again without ``then``).

    Returns
    -------
    tuple of float
        r1 [1] of the differences of order 0 … ``dmax``.

    Notes
    -----
    .. math:: r_1^{(d)} = \frac{\sum_k c_k c_{k+1}}{\sum_k c_k^2},\quad
              c = \Delta^d (z - \mu) - \overline{\Delta^d (z - \mu)}

    References
    ----------
    - W. J. Riley and C. A. Greenhall, "Power law noise identification using the lag 1
      autocorrelation", Proc. 18th EFTF, 2004.
    - W. J. Riley, NIST SP 1065, 2008, §5.5.
    """
    n = z.size
    if not 0 <= dmax < 64 or n < dmax + 2:
        raise ValueError(f"lag1_of_differences: order {dmax} of {n} points")
    head = z[: dmax + 1] - shift  # before ``out`` or ``then`` may overwrite z
    tail = z[n - dmax - 1 :] - shift
    acc = _blocked_sums(z, dmax, shift, out, then)
    for d in range(dmax):  # Σ (w_{k+1} − w_k)² = Σ_{k≥1} w_k² + Σ_{k<N−1} w_k² − 2 Σ w_k w_{k+1}
        first, last = float(np.diff(head, d)[0]), float(np.diff(tail, d)[-1])
        acc[2, d] = (2.0 * acc[1, d] - first * first - last * last - acc[1, d + 1]) / 2.0
    series: FloatArray | None = z if out is None else out[:n]
    if then is not None and (
        np.may_share_memory(then[1], z) or (out is not None and np.may_share_memory(then[1], out))
    ):
        series = None  # written over by the next decimation
    off = 0.0 if out is not None else shift
    return tuple(_r1_of_order(acc[:, d], d, n, head, tail, series, off) for d in range(dmax + 1))


def _blocked_sums(
    z: FloatArray,
    dmax: int,
    shift: float,
    out: FloatArray | None,
    then: tuple[int, FloatArray] | None,
) -> FloatArray:
    """The pass of :func:`lag1_of_differences`: per block its window (read in place when
    ``z`` is contiguous and unshifted, else shifted into a buffer or into ``out``), its sums
    (:func:`_block_orders`), then, with ``then = (s, dest)``, its points of global index
    ≡ 0 (mod s) copied to ``dest[index // s]`` (behind every later window: ``dest`` may be
    ``z``'s own buffer)."""
    n = z.size
    carry = max(_CARRY, dmax + 1)
    acc = np.zeros((3, dmax + 1))
    bufs = [np.empty(_LAG_BLOCK + carry) for _ in range(dmax)]
    direct = out is None and shift == 0.0 and z.flags.c_contiguous
    work = np.empty(_LAG_BLOCK + carry) if out is None and not direct else None
    for a in range(0, n, _LAG_BLOCK):
        b, a0 = min(a + _LAG_BLOCK, n), max(a - carry, 0)
        if direct:
            w = z[a0:b]
        elif work is not None:
            w = work[: b - a0]
            np.subtract(z[a0:b], shift, out=w)
        else:
            assert out is not None
            np.subtract(z[a:b], shift, out=out[a:b])
            w = out[a0:b]
        _block_orders(w, a - a0, bufs, acc)
        if then is not None:
            step, dest = then
            first = -a % step
            pts = w[a - a0 + first :: step]
            dest[(a + first) // step : (a + first) // step + pts.size] = pts
    return acc


def _r1_of_order(
    acc: FloatArray,
    d: int,
    n: int,
    head: FloatArray,
    tail: FloatArray,
    series: FloatArray | None,
    shift: float,
) -> float:
    """r1 of order d from its sums (:func:`lag1_of_differences`); NaN where exact passes
    are needed and the series is gone (``series`` None)."""
    big_n = n - d
    first, last = float(np.diff(head, d)[0]), float(np.diff(tail, d)[-1])
    if d == 0:
        total = float(acc[0])
    else:
        total = float(np.diff(tail, d - 1)[-1]) - float(np.diff(head, d - 1)[0])
    mean = total / big_n
    sq = float(acc[1])
    den = sq - mean * total
    if not sq > 0:
        return 0.0
    if not den > _LOST * sq:  # the mean carried Σ w²: exact passes
        if series is None:
            return math.nan
        if d == 0:
            return _lag1_centred(series, float(series.mean()))
        return _lag1_of_difference(series, d, shift)
    cross = float(acc[2]) - mean * (2.0 * total - first - last) + (big_n - 1) * mean * mean
    return cross / den


def _lag1_differenced(
    r1: float,
    z: FloatArray,
    dm: int,
    add: int,
    sample: bool = False,
    shift: float | None = None,
) -> NoiseId:
    """Riley & Greenhall's rule: difference ``z`` until ρ = r1/(1 + r1) < 0.25 or d = dm;
    α = −round(2ρ) − 2d + ``add`` (the differences' r1 by :func:`_lag1_of_difference`: a
    10⁷-sample m = 1 level needs no differenced copy).  ``sample``: every r1 (of n points)
    taken as r1·(n − 1)/n, Stable32's normalisation (:class:`IdRules`).  ``shift``: the
    series differenced is ``z − shift`` (the centred phase), formed block by block."""
    return _riley_walk(
        lambda d: r1 if d == 0 else _lag1_of_difference(z, d, shift), z.size, dm, add, sample
    )


def _riley_walk(
    r1_of: Callable[[int], float], size: int, dm: int, add: int, sample: bool
) -> NoiseId:
    """Riley & Greenhall's walk on the r1 of each difference order (``r1_of(d)``, asked in
    order, only as far as the walk goes) of a series of ``size`` points: stop at the first
    d with ρ = r1/(1 + r1) < 0.25 (each r1 taken as r1·(n − 1)/n with ``sample``, n = size
    − d) or at d = ``dm``; α = −round(2ρ) − 2d + ``add``."""
    d = 0
    while True:
        r1 = r1_of(d)
        if sample:
            n = size - d
            r1 = r1 * (n - 1) / n if n > 1 else r1
        rho = r1 / (1.0 + r1) if r1 > -1.0 else 0.0
        if rho < 0.25 or d >= dm:
            a = -round(2.0 * rho) - 2 * d + add
            return NoiseId(int(a), -2.0 * (rho + d) + add, "lag1", d)
        d += 1


def identify_phase_lag1(
    r1: Sequence[float], size: int, dmax: int, rules: IdRules = THERMOCAL_RULES
) -> NoiseId:
    r"""The lag-1 identification of phase data (:func:`identify_noise`) from the r1 of the
    decimated phase and of its differences (:func:`lag1_of_differences`): Riley & Greenhall's
    walk, difference until ρ = r1/(1 + r1) < 0.25 or d = ``dmax``, α = −round(2ρ) − 2d + 2.

    Parameters
    ----------
    r1 : sequence of float
        r1 [1] of the decimated phase's differences of order 0 … at least ``dmax``.
    size : int
        Points of the decimated phase.
    dmax : int
        Difference order: 2 for the Allan family, 3 for Hadamard.
    rules : IdRules, optional
        Identification rules (``r1_sample``: Stable32's normalisation).

    Returns
    -------
    NoiseId
        Noise exponent α, method ``lag1`` and the differences taken.

    Notes
    -----
    .. math:: \rho = r_1 / (1 + r_1),\quad \alpha = -\operatorname{round}(2\rho) - 2d + 2

    References
    ----------
    - Riley & Greenhall 2004 (lag-1 autocorrelation).
    """
    if len(r1) <= dmax:
        raise ValueError(f"identify_phase_lag1: {len(r1)} orders for dmax = {dmax}")
    return _riley_walk(r1.__getitem__, size, dmax, 2, rules.r1_sample)


def _b1_identify(
    ym: FloatArray, dmax: int, *, n_theory: int | None = None, min_groups: int = MIN_B1_GROUPS
) -> NoiseId:
    """The B1 ratio of the m-averages ``ym`` against its theoretical value per noise, B1(n, μ)
    at n = the number of averages (Barnes' definition) or ``n_theory`` (Stable32: the
    deviation's number of terms, :data:`STABLE32_B1_MIN_TOTAL`); nothing with fewer than
    ``min_groups`` averages."""
    nb = ym.size
    if nb < max(min_groups, 2):
        return NoiseId(0, float("nan"), "none", 0)
    n_th = nb if n_theory is None else max(int(n_theory), 2)
    avar = float(np.mean(np.diff(ym) ** 2)) / 2.0
    if avar <= 0:
        return NoiseId(0, float("nan"), "none", 0)
    b1 = float(np.var(ym, ddof=1)) / avar
    mus = [-2, -1, 0, 1, 2, 3][: 4 + max(dmax - 2, 0) * 2]
    chosen = mus[-1]
    for lo, hi in itertools.pairwise(mus):
        if b1 < math.sqrt(_b1_theory(n_th, lo) * _b1_theory(n_th, hi)):
            chosen = lo
            break
    return NoiseId(_MU_TO_ALPHA[chosen], float("nan"), "b1", 0)


CONFIDENCE_MIN: Final = 0.5
"""The smallest confidence level accepted: below it the interval no longer brackets the
median of the chi-square law, so it need not contain the estimate itself (at c → 0 both
bounds collapse onto ``σ̂ √(ν / χ²_{0.5}(ν))``, beside σ̂)."""
CONFIDENCE_MAX: Final = 1.0 - 1e-9
"""The largest confidence level accepted: beyond it ``(1 − c)/2`` < 5e-10 and the chi-square
quantiles of a few degrees of freedom run to 0 or to the double range (an interval of
``[0, ∞)`` printed as numbers)."""


def check_confidence(confidence: float) -> float:
    """Return ``confidence`` when ``CONFIDENCE_MIN ≤ c ≤ CONFIDENCE_MAX``, else raise
    :class:`~thermocal.errors.ParameterError` naming ``confidence`` and the value (a
    confidence of 1e-300 would give an interval of zero width beside the estimate).

    Parameters
    ----------
    confidence : float
        Confidence level of a two-sided chi-square interval (dimensionless, e.g. 0.683 for
        one sigma, NIST SP 1065 eq. 45).

    Returns
    -------
    float
        ``confidence`` unchanged.

    Raises
    ------
    thermocal.errors.ParameterError
        A confidence outside [``CONFIDENCE_MIN``, ``CONFIDENCE_MAX``].

    Examples
    --------
    >>> check_confidence(0.95)
    0.95
    """
    c = float(confidence)
    if not CONFIDENCE_MIN <= c <= CONFIDENCE_MAX:
        raise ParameterError(
            "confidence",
            f"{{name}} {confidence!r}: give a confidence level between {CONFIDENCE_MIN} and "
            f"{CONFIDENCE_MAX!r} (0.6827 is one sigma, 0.95 two)",
        )
    return c


def confidence_interval(
    adev: npt.ArrayLike, edf: npt.ArrayLike, confidence: float = ONE_SIGMA_CONFIDENCE
) -> tuple[FloatArray, FloatArray]:
    r"""Chi-square confidence interval of a deviation.

    Parameters
    ----------
    adev : array_like
        The deviations σ̂ [any unit].
    edf : array_like
        Their equivalent degrees of freedom ν.
    confidence : float
        Confidence level p, in (0, 1) (default 0.683, ±1σ).

    Returns
    -------
    low, high : numpy.ndarray
        The bounds [the unit of ``adev``].

    Raises
    ------
    thermocal.errors.ThermocalInputError
        ``confidence`` outside (0, 1).

    Notes
    -----
    NIST SP 1065 eq. 45:

    .. math::

        \sigma_{low} = \hat\sigma \sqrt{\nu / \chi^2_{(1+p)/2}(\nu)}, \qquad
        \sigma_{high} = \hat\sigma \sqrt{\nu / \chi^2_{(1-p)/2}(\nu)}

    References
    ----------
    .. [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.

    Examples
    --------
    ν = 100 at 95 %: √(100/129.56) and √(100/74.22), the chi-square quantiles of any table:

    >>> lo, hi = confidence_interval([1.0], [100.0], 0.95)
    >>> round(float(lo[0]), 3), round(float(hi[0]), 3)
    (0.879, 1.161)
    """
    if not 0.0 < confidence < 1.0:
        raise ThermocalInputError(f"confidence must be in (0, 1), got {confidence!r}")
    dev = np.asarray(adev, dtype=np.float64)
    nu = np.asarray(edf, dtype=np.float64)
    p_lo = (1.0 - confidence) / 2.0
    chi_hi = _quantiles.chi2_isf(p_lo, nu)  # upper quantile: inverse survival function
    chi_lo = _quantiles.chi2_ppf(p_lo, nu)  # lower quantile: inverse CDF
    return dev * np.sqrt(nu / chi_hi), dev * np.sqrt(nu / chi_lo)
