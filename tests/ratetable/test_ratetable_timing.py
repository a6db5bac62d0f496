"""A rate ladder run to a timed program (thermocal.ratetable.timing): the plateaus placed by
the rates and their dwell on a simulated record whose start nobody wrote down, against the
simulator's truth; a program that does not fit the record refused."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.errors import DesignError, ParameterError
from thermocal.ratetable.simulate import simulate_ladder
from thermocal.ratetable.timing import fit_timing, ladder_profile, plateaus_from_dwell

LADDER = (-300.0, -100.0, -10.0, -0.1, 0.0, 0.1, 10.0, 100.0, 300.0)
ERRORS = {"cubic_ppm": 150.0, "asymmetry_ppm": 200.0, "bias_dps": 0.02, "dead_zone_dps": 0.015}


def _sim(seed: int, lead_s: float, **kw: object) -> tuple[np.ndarray, np.ndarray, dict]:
    opts = {"rates_dps": LADDER, "dwell_s": 12.0, "rate_hz": 100.0, "up_down": True, **kw}
    rec, truth = simulate_ladder(
        np.random.default_rng(seed), lead_s=lead_s, rate_column=False, **opts, **ERRORS
    )  # type: ignore[arg-type]
    assert "table_rate" not in rec.columns
    return rec.time_s, rec.columns["gyro"], truth


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_plateaus_of_a_program_recovered_with_the_start_unknown(seed: int) -> None:
    lead = 4.0 + 7.3 * seed
    t, y, truth = _sim(seed, lead)
    det, tm = plateaus_from_dwell(t, y, truth["order_dps"], 12.0, settle_s=1.0)
    assert tm.found == ("start", "accel")
    # the first plateau starts once the table has come from rest to its rate at 100 °/s²
    assert truth["plateaus"][0]["start_s"] == pytest.approx(lead + 300.0 / 100.0)
    assert tm.start_s == pytest.approx(truth["plateaus"][0]["start_s"], abs=0.015)
    assert tm.accel_dps2 == pytest.approx(100.0, rel=1e-3)
    assert [p.rate_dps for p in det.plateaus] == truth["order_dps"]
    for p, w in zip(det.plateaus, truth["plateaus"], strict=True):
        # the truth's samples, the first second left out: the same to one sample (10 ms)
        i0 = int(np.searchsorted(t, w["start_s"] + 1.0, "left"))
        i1 = int(np.searchsorted(t, w["end_s"], "right"))
        assert abs(p.i0 - i0) <= 1 and abs(p.i1 - i1) <= 1
    # each plateau's mean is the noise-free output of the truth within 6 standard errors
    # (the first-order lag has settled within the second left out)
    want = np.array(truth["outputs"])
    got = np.array([p.mean for p in det.plateaus])
    se = np.array([p.se for p in det.plateaus])
    assert np.all(np.abs(got - want) < 6 * se)


def test_what_is_given_is_held() -> None:
    t, y, truth = _sim(5, 9.0)
    start = truth["plateaus"][0]["start_s"]
    _, tm = plateaus_from_dwell(t, y, truth["order_dps"], 12.0, start_s=start, accel_dps2=100.0)
    assert tm.found == () and tm.start_s == start and tm.accel_dps2 == 100.0
    want = [(w["start_s"], w["end_s"]) for w in truth["plateaus"]]
    np.testing.assert_allclose(tm.spans, want, atol=1e-9)
    _, tm2 = plateaus_from_dwell(t, y, truth["order_dps"], 12.0, start_s=start)
    assert tm2.found == ("accel",) and tm2.accel_dps2 == pytest.approx(100.0, rel=1e-3)


def test_profile_follows_the_timing_formula() -> None:
    # s_k = s_{k-1} + d_{k-1} + |Ω_k − Ω_{k-1}| / a, written out by hand
    kt, kr, spans = ladder_profile([5.0, -15.0, 25.0], [3.0, 4.0, 2.0], 20.0, 1.5)
    assert spans == [(1.5, 4.5), (5.5, 9.5), (11.5, 13.5)]
    assert kr.tolist() == [5.0, 5.0, -15.0, -15.0, 25.0, 25.0]
    assert kt.tolist() == [1.5, 4.5, 5.5, 9.5, 11.5, 13.5]


def test_exact_profile_gives_start_and_acceleration() -> None:
    t = np.arange(0.0, 200.0, 0.02)
    rates = [30.0, -30.0, 0.0, 60.0, 10.0]
    kt, kr, _ = ladder_profile(rates, [20.0, 25.0, 30.0, 20.0, 25.0], 7.5, 31.27)
    tm = fit_timing(t, 3.0 - 0.5 * np.interp(t, kt, kr), rates, [20, 25, 30, 20, 25])
    assert tm.start_s == pytest.approx(31.27, abs=1e-3)
    assert tm.accel_dps2 == pytest.approx(7.5, rel=1e-4)


def test_dwell_longer_than_the_record_refused() -> None:
    t, y, truth = _sim(0, 5.0)
    with pytest.raises(DesignError, match="beyond the record"):
        plateaus_from_dwell(t, y, truth["order_dps"], 13.0)
    with pytest.raises(DesignError, match="beyond the record"):
        plateaus_from_dwell(t, y, truth["order_dps"], 12.0, start_s=40.0)


def test_program_that_does_not_fit_the_output_refused() -> None:
    t, y, truth = _sim(1, 20.0)
    start = truth["plateaus"][0]["start_s"]
    with pytest.raises(DesignError, match="does not hold still"):
        plateaus_from_dwell(t, y, truth["order_dps"], 12.0, start_s=start + 1.5)
    with pytest.raises(DesignError, match=r"does not hold still|beyond the record"):
        plateaus_from_dwell(t, y, truth["order_dps"], 11.6)


def test_bad_programs_refused() -> None:
    t, y, truth = _sim(0, 5.0)
    with pytest.raises(ParameterError, match="dwell_s"):
        plateaus_from_dwell(t, y, truth["order_dps"], [12.0, 12.0])
    with pytest.raises(ParameterError, match="dwell_s"):
        plateaus_from_dwell(t, y, truth["order_dps"], -1.0)
    with pytest.raises(ParameterError, match="rates_dps"):
        plateaus_from_dwell(t, y, [1.0], 12.0)
    with pytest.raises(ParameterError, match="settling"):
        plateaus_from_dwell(t, y, truth["order_dps"], 12.0, settle_s=15.0)
