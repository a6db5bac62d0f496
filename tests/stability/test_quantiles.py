"""The chi-square and normal quantiles written without scipy (``stability/quantiles.py``)
against scipy's (the reference the intervals used before) on a grid of (p, ν), and where
scipy itself is inaccurate (the lower tail beyond 4.5 σ at ν > 1e6: cephes' ``igam`` loses
up to 1e-5 there) against the incomplete gamma function computed in 60-digit decimal
arithmetic in this file."""

from __future__ import annotations

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest
import scipy.special as sp
import scipy.stats as st

from thermocal.stability import quantiles as q
from thermocal.stability.edf import confidence_interval

PS = [1e-10, 5e-10, 3e-7, 1e-6, 1e-3, 0.0228, 0.1587, 0.3, 0.5, 0.7, 0.8413, 0.975, 0.999,
      1 - 1e-6, 1 - 5e-10]  # fmt: skip
DOFS = [0.05, 0.1, 0.5, 0.9, 1.0, 1.5, 2.0, 3.0, 7.3, 10.0, 19.9, 20.0, 21.0, 50.0,
        100.0, 399.0, 459.0, 1000.0, 3999.5, 4001.0, 1e4, 12345.6, 1e5, 1e6, 2e6, 1e7, 2e7,
        1e8]  # fmt: skip


def _scipy_unreliable(p: float, dof: float) -> bool:
    """scipy's lower tail beyond 4.5 σ at large ν (checked against decimals below)."""
    z = abs(float(sp.ndtri(min(p, 1 - p))))
    return dof > 1e5 and z > 4.5


@pytest.mark.parametrize("dof", DOFS)
def test_chi2_quantiles_equal_scipy(dof: float) -> None:
    for p in PS:
        if _scipy_unreliable(p, dof):
            continue
        lower, upper = float(q.chi2_ppf(p, dof)), float(q.chi2_isf(p, dof))
        assert lower == pytest.approx(float(st.chi2.ppf(p, dof)), rel=1e-12, abs=0), (p, dof)
        assert upper == pytest.approx(float(sp.chdtri(dof, p)), rel=1e-12, abs=0), (p, dof)


getcontext().prec = 60
_PI = Decimal("3.14159265358979323846264338327950288419716939937510582097494")


def _lgamma1(a: Decimal) -> Decimal:
    """ln Γ(a+1) in decimals: shifted above 60, then Stirling's series to 1e-40."""
    k, shift = a, Decimal(0)
    while k < 60:
        k += 1
        shift += k.ln()
    s = k * k.ln() - k + (2 * _PI * k).ln() / 2
    for i, b in enumerate([Decimal(1) / 12, Decimal(-1) / 360, Decimal(1) / 1260,
                           Decimal(-1) / 1680, Decimal(1) / 1188]):  # fmt: skip
        s += b / k ** (2 * i + 1)
    return s - shift


def _p_decimal(a: float, x: float) -> tuple[Decimal, Decimal]:
    """(P(a, x), x·dP/dx) by the series, in 60 digits."""
    ad, xd = Decimal(a), Decimal(x)
    log_d = ad * xd.ln() - xd - _lgamma1(ad)
    term = total = Decimal(1)
    n = 0
    while term > total * Decimal(10) ** -45:
        n += 1
        term *= xd / (ad + n)
        total += term
    d = log_d.exp()
    return d * total, d * ad  # x·dP/dx = x^a e^-x / Γ(a)


@pytest.mark.parametrize(("p", "dof"), [(1e-10, 2e6), (1e-6, 1e6), (3e-7, 1e7), (5e-10, 2e7)])
def test_chi2_lower_tail_at_large_dof_against_decimals(p: float, dof: float) -> None:
    x = float(q.chi2_ppf(p, dof))
    big_p, x_dens = _p_decimal(dof / 2, x / 2)
    rel_x = abs(float((big_p - Decimal(p)) / x_dens))  # δx/x = δP / (x·dP/dx)
    assert rel_x <= 1e-12
    # and scipy is the one off there (so the grid above leaves these points out)
    assert abs(float(st.chi2.ppf(p, dof)) / x - 1.0) > 2e-12


def test_chi2_sf_and_normal_ppf_equal_scipy() -> None:
    for x, dof in [(3.0, 5.0), (50.0, 3.0), (200.0, 10.0), (1e-3, 2.0), (30.0, 30.0),
                   (0.5, 0.7), (1e4, 9e3), (2.0, 1.0), (1e-30, 25.0), (3.0, 40.0)]:  # fmt: skip
        assert q.chi2_sf(x, dof) == pytest.approx(float(sp.chdtrc(dof, x)), rel=1e-12)
    for p in [1e-12, 1e-6, 0.0228, 0.3, 0.5, 0.8413447460685429, 0.975, 1 - 1e-9]:
        assert q.normal_ppf(p) == pytest.approx(float(sp.ndtri(p)), rel=1e-13, abs=1e-300)


def test_out_of_range_gives_nan_or_the_ends() -> None:
    got = q.chi2_ppf([0.0, 1.0, 0.5, -0.1, 0.5], [3.0, 3.0, 0.0, 3.0, np.nan])
    assert got[0] == 0.0 and got[1] == math.inf
    assert np.isnan(got[2:]).all()
    assert q.chi2_isf(0.0, 3.0) == math.inf and q.chi2_isf(1.0, 3.0) == 0.0
    with pytest.raises(ValueError, match="p must be in"):
        q.normal_ppf(1.0)


def test_interval_equals_the_scipy_formula() -> None:
    """NIST SP 1065 eq. 45 written here with scipy: the bounds move ≤ 1e-12 (at levels
    where scipy is accurate: at 1 − 1e-9 and ν = 8e6 its lower-tail quantile is 5e-8 off,
    as the decimal test above shows for such points)."""
    edf = np.array([0.7, 2.0, 13.4, 250.0, 3.3e4, 8e6])
    dev = np.linspace(1.0, 2.0, edf.size)
    for conf in (0.6826894921370859, 0.95, 0.999):
        p = (1 - conf) / 2
        low, high = confidence_interval(dev, edf, conf)
        ref_low = dev * np.sqrt(edf / sp.chdtri(edf, p))
        ref_high = dev * np.sqrt(edf / (2 * sp.gammaincinv(edf / 2, p)))
        np.testing.assert_allclose(low, ref_low, rtol=1e-12, atol=0)
        np.testing.assert_allclose(high, ref_high, rtol=1e-12, atol=0)
