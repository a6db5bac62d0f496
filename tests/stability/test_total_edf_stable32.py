"""The total family's intervals against Stable32's printed bounds on a record that is not
PHASE.DAT: the Sr87 optical-clock record (1253 phase points, τ0 = 2.5 s), whose Stable32 1.60
outputs are public in the allantoolkit project's test assets (tests/assets/Sr87/phase0/,
GPL-3.0; only the printed figures below are quoted, no file or code is copied).

Each row is (m, α Stable32 identified, lower bound, deviation, upper bound).  The EDF rule is
given α (Stable32's noise identification at few averages is not reproduced, see
test_stability_reference), so these rows test the EDF alone.  Which rows the MTOT
coefficients were fitted on is stated in ``thermocal.stability.edf.edf_mtotdev``; the rows
here are the others, except α = −1 (m = 200, 400), the only Stable32 rows with that α."""

from __future__ import annotations

import pytest

from thermocal.stability.edf import confidence_interval, edf_htotdev, edf_mtotdev, edf_totdev

N_SR87 = 1253

# Stable32, Sigma Type: Modified Total, decade τ, phase0_data.txt (1253 points)
MTOT_SR87_DECADE = [
    (1, -1, 6.2540e-17, 6.3842e-17, 6.5230e-17),
    (2, -2, 6.4501e-17, 6.6538e-17, 6.8782e-17),
    (4, -1, 7.1559e-17, 7.4419e-17, 7.7655e-17),
    (10, 0, 6.3861e-17, 6.7260e-17, 7.1270e-17),
    (20, 0, 5.3546e-17, 5.7573e-17, 6.2669e-17),
    (40, 0, 3.9907e-17, 4.4121e-17, 5.0032e-17),
    (100, 1, 2.5070e-17, 2.8818e-17, 3.4977e-17),
    (200, -1, 1.1921e-17, 1.5037e-17, 2.3447e-17),
    (400, -1, 1.2033e-17, 1.6256e-17, 3.7550e-17),
]

# Stable32, Sigma Type: Hadamard Total, the rows at m >= 16 (octave and decade τ)
HTOT_SR87_LONG = [
    (16, 0, 7.8591e-17, 8.3165e-17, 8.8649e-17),
    (32, 0, 6.4085e-17, 6.9376e-17, 7.6241e-17),
    (64, 0, 4.8613e-17, 5.4288e-17, 6.2567e-17),
    (128, 0, 3.4607e-17, 4.0350e-17, 5.0403e-17),
    (256, 0, 1.8034e-17, 2.2308e-17, 3.2500e-17),
    (20, 0, 7.5569e-17, 8.0481e-17, 8.6500e-17),
    (40, 0, 5.8634e-17, 6.4044e-17, 7.1295e-17),
    (200, -1, 2.2752e-17, 2.8300e-17, 4.1983e-17),
    (400, -1, 1.1419e-17, 1.5213e-17, 3.1436e-17),
]

# Stable32 Hadamard Total below m = 16 on PHASE.DAT (1001 points, α = 0; tests/data; printed
# with Stable32's bias correction, which scales value and bounds alike): Stable32's white-FM
# rule there was read from these rows; the Sr87 rows at m = 8, 10 check it on another record
HTOT_WHITE_FM_SHORT = [
    (1001, 1, 2.8670e-01, 2.9439e-01, 3.0274e-01),
    (1001, 2, 1.9726e-01, 2.0297e-01, 2.0922e-01),
    (1001, 4, 1.3744e-01, 1.4252e-01, 1.4821e-01),
    (1001, 8, 1.0303e-01, 1.0822e-01, 1.1430e-01),
    (N_SR87, 8, 8.5090e-17, 8.8938e-17, 9.3364e-17),
    (N_SR87, 10, 8.1805e-17, 8.5915e-17, 9.0718e-17),
]

# Stable32 Hadamard Total below m = 16 on Sr87 at flicker FM (m = 1, 4) and random-walk FM
# (m = 2), printed with the bias correction (scales value and bounds alike): the simple EDF + 2
# (1090.0, 389.9, 626.5), where Greenhall's overlapping-Hadamard EDF gives 897, 359, 666
HTOT_SR87_SHORT = [
    (1, -1, 8.0946e-17, 8.2651e-17, 8.4469e-17),
    (2, -2, 7.5923e-17, 7.8025e-17, 8.0313e-17),
    (4, -1, 8.8264e-17, 9.1349e-17, 9.4785e-17),
]

# Stable32 Hadamard Total at flicker PM (PHASE.DAT m = 128, 256; no bias correction there)
HTOT_FLICKER_PM = [
    (128, 1, 2.6309e-02, 2.8790e-02, 3.2137e-02),
    (256, 1, 1.2846e-02, 1.4773e-02, 1.7946e-02),
]


def _bounds_equal(edf: float, low: float, dev: float, high: float, rel: float = 2e-3) -> None:
    """The chi-square 68.3 % bounds of ``dev`` with ``edf`` against Stable32's printed ones."""
    lo, hi = confidence_interval(dev, edf)
    assert float(lo) == pytest.approx(low, rel=rel, abs=0.0)
    assert float(hi) == pytest.approx(high, rel=rel, abs=0.0)


@pytest.mark.parametrize(("m", "alpha", "low", "dev", "high"), MTOT_SR87_DECADE)
def test_mtot_bounds_equal_stable32_on_sr87(
    m: int, alpha: int, low: float, dev: float, high: float
) -> None:
    _bounds_equal(edf_mtotdev(N_SR87, m, alpha), low, dev, high)


@pytest.mark.parametrize(("m", "alpha", "low", "dev", "high"), HTOT_SR87_LONG)
def test_htot_bounds_equal_stable32_on_sr87_from_m16(
    m: int, alpha: int, low: float, dev: float, high: float
) -> None:
    _bounds_equal(edf_htotdev(N_SR87, m, alpha), low, dev, high)


@pytest.mark.parametrize(("n", "m", "low", "dev", "high"), HTOT_WHITE_FM_SHORT)
def test_htot_white_fm_bounds_below_m16_equal_stable32(
    n: int, m: int, low: float, dev: float, high: float
) -> None:
    _bounds_equal(edf_htotdev(n, m, 0), low, dev, high)


@pytest.mark.parametrize(("m", "alpha", "low", "dev", "high"), HTOT_SR87_SHORT)
def test_htot_flicker_and_random_walk_fm_below_m16_equal_stable32(
    m: int, alpha: int, low: float, dev: float, high: float
) -> None:
    _bounds_equal(edf_htotdev(N_SR87, m, alpha), low, dev, high, rel=5e-4)


@pytest.mark.parametrize(("m", "alpha", "low", "dev", "high"), HTOT_FLICKER_PM)
def test_htot_flicker_pm_bounds_equal_stable32(
    m: int, alpha: int, low: float, dev: float, high: float
) -> None:
    """Stable32's phase-noise rule (simple EDF + 2); Greenhall's ohdev EDF (32.8, 15.9 where
    Stable32's is 50.6, 18.6) put these bounds 8–30 % off."""
    _bounds_equal(edf_htotdev(1001, m, alpha), low, dev, high)


# Stable32 TOTDEV rows at flicker PM on two more public records of allantools' test data
# (LGPL-3.0; figures quoted): the GPS 1PPS phase record (tests/gps, N = 241218) and the
# Keysight 53230A noise-floor record (tests/Keysight53230A_ti_noise_floor, N = 55688).
# (N, m, lower bound, deviation, upper bound); bias factor 1 at phase noise
TOTDEV_FLICKER_PM = [
    (241218, 2, 3.2009e-09, 3.2071e-09, 3.2133e-09),
    (241218, 16, 5.6984e-10, 5.7119e-10, 5.7255e-10),
    (241218, 1024, 1.1923e-11, 1.1998e-11, 1.2074e-11),
    (241218, 4096, 3.5895e-12, 3.6305e-12, 3.6730e-12),
    (241218, 32768, 7.2339e-13, 7.5714e-13, 7.9613e-13),
    (241218, 65536, 3.7976e-13, 4.1817e-13, 4.7121e-13),
    (55688, 2048, 8.7523e-15, 8.9523e-15, 9.1668e-15),
    (55688, 4096, 4.3980e-15, 4.5516e-15, 4.7226e-15),
]


@pytest.mark.parametrize(("n", "m", "low", "dev", "high"), TOTDEV_FLICKER_PM)
def test_totdev_flicker_pm_bounds_equal_stable32(
    n: int, m: int, low: float, dev: float, high: float
) -> None:
    """Greenhall's overlapping-Allan EDF, used before, put m = 1024–65536 0.7–25 % off."""
    _bounds_equal(edf_totdev(n, m, 1), low, dev, high)


def test_total_pm_edf_is_the_simple_formula_plus_two() -> None:
    """The simple formulas by hand (Howe, Allan & Barnes 1981) at N = 1001, m = 128:
    white PM 1002·745/(2·873) = 427.55, flicker PM exp(√(ln(1000/256)·ln(257·250))) = 48.612."""
    assert edf_totdev(1001, 128, 2) == pytest.approx(1002 * 745 / (2 * 873) + 2, rel=1e-12)
    assert edf_htotdev(1001, 128, 1) == pytest.approx(48.6121 + 2, rel=1e-5)
