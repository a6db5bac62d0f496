"""Plateaus of a rate-table run (thermocal.ratetable.plateaus) against the simulator's truth:
the table's own rate column, the gyro's output alone, what the operator does (a ladder run up
and back down, a plateau cut short, the table's overshoot), and the refusals."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.errors import DesignError, ParameterError
from thermocal.ratetable import (
    match_rates,
    plateaus_from_output,
    plateaus_from_rate,
    plateaus_from_schedule,
)
from thermocal.ratetable.simulate import expected_output, ladder_order, simulate_ladder

LADDER = (-300.0, -100.0, -10.0, 0.0, 10.0, 100.0, 300.0)


def _sim(seed: int = 0, **kw: object) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    opts = {"rates_dps": LADDER, "dwell_s": 10.0, "rate_hz": 50.0, **kw}
    rec, truth = simulate_ladder(np.random.default_rng(seed), **opts)  # type: ignore[arg-type]
    return rec.time_s, rec.columns["gyro"], rec.columns["table_rate"], truth


def test_rate_column_plateaus_are_the_truths_with_the_settling_left_out() -> None:
    t, y, r, truth = _sim(up_down=True, cut_short=9, cut_fraction=0.3)
    d = plateaus_from_rate(t, y, r, settle_s=1.0)
    want = [p for k, p in enumerate(truth["plateaus"]) if k != 9]  # 3 s: below 5 s
    assert [p.rate_dps for p in d.plateaus] == [p["rate_dps"] for p in want]
    for p, w in zip(d.plateaus, want, strict=True):
        # the plateau starts once the table's overshoot has settled below 1e-3 °/s (1.3 s
        # at most for a 200 °/s step), then one more second is left out
        assert w["start_s"] + 1.0 <= p.start_s <= w["start_s"] + 2.5
        assert p.end_s == pytest.approx(w["end_s"], abs=0.03)
    cut = truth["plateaus"][9]
    assert len(d.dropped) == 1
    assert cut["start_s"] <= d.dropped[0][0] <= cut["start_s"] + 1.5
    assert d.dropped[0][1] == pytest.approx(cut["end_s"], abs=0.03)
    assert d.source == "rate column" and d.settle_s == 1.0


def test_output_plateaus_found_between_the_accelerations() -> None:
    t, y, _, truth = _sim(seed=1, noise_dps=0.02)
    d = match_rates(plateaus_from_output(t, y), LADDER)
    assert len(d.plateaus) == len(LADDER)
    for p, w in zip(d.plateaus, truth["plateaus"], strict=True):
        assert w["start_s"] + 1.0 <= p.start_s <= w["start_s"] + 2.0
        assert w["end_s"] - 0.6 <= p.end_s <= w["end_s"] + 0.1
        assert p.mean == pytest.approx(expected_output([w["rate_dps"]])[0], abs=5 * p.se)
        assert p.sd == pytest.approx(0.02, rel=0.15)  # the overshoot settled: white noise only


def test_schedule_plateaus_and_a_bad_row() -> None:
    t, y, _, truth = _sim(seed=2)
    rows = [(p["start_s"] + 1, p["end_s"], p["rate_dps"]) for p in truth["plateaus"]]
    d = plateaus_from_schedule(t, y, rows)
    assert [p.rate_dps for p in d.plateaus] == list(LADDER)
    assert d.plateaus[0].n == round((rows[0][1] - rows[0][0]) * 50) + 1
    with pytest.raises(DesignError, match="plateau 2 of schedule"):
        plateaus_from_schedule(t, y, [rows[0], (1e6, 1e6 + 5, 1.0)])


def test_refusals() -> None:
    t, y, r, _ = _sim(seed=3)
    d = plateaus_from_output(t, y)
    with pytest.raises(DesignError, match=r"7 plateaus found.*but 6 rates"):
        match_rates(d, LADDER[:-1])
    with pytest.raises(DesignError, match="do not follow the rates"):
        match_rates(d, (-300.0, -100.0, 10.0, 0.0, -10.0, 100.0, 300.0))
    with pytest.raises(DesignError, match="no plateau of at least 500 s"):
        plateaus_from_rate(t, y, r, min_plateau_s=500.0)
    with pytest.raises(DesignError, match="no steady plateau"):
        plateaus_from_output(t, np.cumsum(np.ones_like(t)))  # a ramp: never steady
    with pytest.raises(ParameterError, match="window_s"):
        plateaus_from_output(t, y, window_s=0.0)


def test_ladder_order_and_expected_output() -> None:
    assert ladder_order([-1.0, 0.0, 1.0], repeats=2, up_down=True) == [
        -1.0, 0.0, 1.0, 0.0, -1.0, -1.0, 0.0, 1.0, 0.0, -1.0,
    ]  # fmt: skip
    w = np.array([-300.0, -0.01, 0.01, 150.0, 300.0])
    y = expected_output(w, scale_factor=2.0, quadratic_ppm=100.0, cubic_ppm=200.0,
                        asymmetry_ppm=400.0, bias_dps=0.5, dead_zone_dps=0.02,
                        tc_ppm_per_c=50.0, temperature_c=45.0)  # fmt: skip
    k = 2.0 * (1 + 50e-6 * 20.0)
    g = w + 100e-6 * w**2 / 300 + 200e-6 * w**3 / 300**2
    want = np.where(np.abs(w) < 0.02, 0.0, k * (1 + 200e-6 * np.sign(w)) * g) + 0.5
    np.testing.assert_allclose(y, want, rtol=1e-15)
