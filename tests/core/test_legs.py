"""Heating and cooling legs (thermocal.legs): found on simulated profiles whose ramps are
known, with a quantised and a noisy thermometer; none on an isothermal record; the
heating-vs-cooling test against a difference and a t written here."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from thermocal.legs import compare_legs, find_legs
from thermocal.simulate import SCENARIOS


def _truth_legs(truth: dict) -> list[tuple[str, float, float]]:
    return [(g["direction"], g["start_s"], g["stop_s"]) for g in truth["legs"]]


@pytest.mark.parametrize(
    ("quant", "noise"), [(0.0625, 0.0), (0.25, 0.0), (0.0, 0.05), (0.125, 0.03)]
)
def test_legs_found_exactly_on_a_quantised_simulated_sweep(quant: float, noise: float) -> None:
    """The program's two ramps (1 °C/min) and nothing else; each end within the time the
    ramp takes to cross three lattice steps or six noise σ."""
    rec, truth = SCENARIOS["thermal-lag"](2, quant_c=quant, temp_noise_c=noise)[0]
    legs = find_legs(rec.time_s, rec.columns["T1"])
    rate = 1.0 / 60.0  # °C/s of the program
    tol = max(3 * quant, 6 * noise) / rate + 2.0
    found = [(g.direction, g.start_s, g.stop_s) for g in legs.legs]
    want = _truth_legs(truth)
    assert [f[0] for f in found] == [w[0] for w in want] == ["heating", "cooling"]
    for (_, a, b), (_, ta, tb) in zip(found, want, strict=True):
        assert abs(a - ta) <= tol and abs(b - tb) <= tol, (found, want, tol)
    if quant and not noise:  # the lattice test misses it (holds outnumber the ramps' levels)
        assert legs.threshold_c == pytest.approx(2.5 * quant)


def test_holds_split_a_staircase_and_reversals_end_a_leg() -> None:
    t = np.arange(0.0, 12_000.0, 2.0)
    knots = ([0, 600, 1800, 3600, 4800, 6600, 9000, 12_000], [20, 20, 40, 40, 60, 60, 30, 30])
    temp = 0.1 * np.round(np.interp(t, *knots) / 0.1)
    legs = find_legs(t, temp)
    got = [(g.direction, round(g.temp_start_c), round(g.temp_stop_c)) for g in legs.legs]
    assert got == [("heating", 20, 40), ("heating", 40, 60), ("cooling", 60, 30)]
    assert legs.legs[0].rate_c_per_min == pytest.approx(1.0, rel=0.02)
    assert legs.mask("cooling").sum() == pytest.approx(2400 / 2.0, abs=3)


def test_an_isothermal_record_has_no_leg_and_says_so() -> None:
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 7200.0)
    # a thermometer toggling between two and three levels of 0.125 °C, and a noisy one
    two = 25.0 + 0.125 * rng.integers(0, 2, t.size)
    three = 25.0 + 0.125 * rng.integers(-1, 2, t.size)
    for temp in (two, three, 25.0 + 0.05 * rng.standard_normal(t.size)):
        legs = find_legs(t, temp)
        assert legs.legs == ()
        assert legs.summary().startswith("no heating or cooling leg")
        cmp = compare_legs(legs, temp, rng.standard_normal(t.size), "deg/h")
        assert cmp.mean_difference is None and cmp.disagree is None
        assert cmp.reason == "no heating leg"
    empty = find_legs(np.array([0.0]), np.array([np.nan]))
    assert empty.legs == ()


def _cycle(seed: int, offset: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 6000.0)
    temp = np.interp(t, [0, 600, 2700, 3300, 5400, 6000], [20, 20, 55, 55, 20, 20])
    heating = (t > 600) & (t < 2700)
    cooling = (t > 3300) & (t < 5400)
    resid = rng.standard_normal(t.size) + offset * (heating.astype(float) - cooling)
    return t, temp, resid


def test_legs_that_differ_disagree_with_the_difference_and_t_written_here() -> None:
    t, temp, resid = _cycle(5, 0.8)
    legs = find_legs(t, temp)
    cmp = compare_legs(legs, temp, resid, "deg/h")
    # the test's own statistic: 12 bins over the common range, heating − cooling means
    th, tc = legs.mask("heating"), legs.mask("cooling")
    lo, hi = max(temp[th].min(), temp[tc].min()), min(temp[th].max(), temp[tc].max())
    edges = np.linspace(lo, hi, 13)
    d = []
    for a, b in itertools.pairwise(edges):
        last = b == edges[-1]
        inb = (temp >= a) & ((temp <= b) if last else (temp < b))
        d.append(resid[inb & th].mean() - resid[inb & tc].mean())
    d = np.array(d)
    t_here = d.mean() / (d.std(ddof=1) / math.sqrt(d.size))
    assert cmp.n_bins == 12
    assert cmp.t_critical == pytest.approx(3.106, abs=1e-3)  # Student's t table, 0.995, 11 dof
    assert cmp.mean_difference == pytest.approx(d.mean(), rel=1e-9)
    assert cmp.t_statistic == pytest.approx(t_here, rel=1e-9)
    assert cmp.mean_difference == pytest.approx(1.6, abs=0.15)  # 2 × 0.8
    assert cmp.disagree is True
    assert cmp.noise == pytest.approx(1.0, rel=0.1)
    assert "DISAGREE" in cmp.line()
    per = {f.leg.direction: f for f in cmp.per_leg}
    assert per["heating"].mean - per["cooling"].mean == pytest.approx(1.6, abs=0.1)


def test_legs_that_agree_pass_at_the_stated_rate() -> None:
    """White residuals with no hysteresis: at 99 %, at most 2 of 30 seeds disagree."""
    flagged = 0
    for seed in range(30):
        t, temp, resid = _cycle(100 + seed, 0.0)
        flagged += bool(compare_legs(find_legs(t, temp), temp, resid, "deg/h").disagree)
    assert flagged <= 2
