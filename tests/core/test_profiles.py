"""Chamber profiles, correlation and validation design (SPEC §5, §6)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from thermocal.errors import (
    DesignError,
    MissingColumnError,
    NonNumericError,
    ThermocalInputError,
    TimestampError,
)
from thermocal.profiles import (
    PROFILE_NAMES,
    Cycle,
    Hold,
    Profile,
    Ramp,
    builtin_profile,
    correlate,
    design_validation_profile,
    find_holds,
)
from thermocal.readers.program import read_program
from thermocal.writers import write_program


def test_segments_expand_exactly() -> None:
    prof = Profile(20.0, (Hold(600), Ramp(50.0, 2.0), Hold(1200), Ramp(-10.0, -0.5)))
    t, c = prof.knots()
    # 600 s hold, 30 °C at 2 °C/min = 900 s, 1200 s hold, 60 °C at 0.5 °C/min = 7200 s
    assert_allclose(t, [0, 600, 1500, 2700, 9900])
    assert_allclose(c, [20, 20, 50, 50, -10])
    assert prof.duration_s == pytest.approx(9900.0)
    tp, cp = prof.program(60.0)
    assert tp[-1] == pytest.approx(9900.0)
    assert_allclose(np.diff(tp), 60.0)
    assert_allclose(cp, np.interp(tp, t, c), atol=1e-12)


def test_cycle_repeats_and_labels() -> None:
    prof = Profile(0.0, (Cycle((Ramp(10.0, 1.0, "up"), Ramp(0.0, 1.0, "down")), 3, "run"),))
    labels = [p.label for p in prof.pieces()]
    assert labels == ["run1/up", "run1/down", "run2/up", "run2/down", "run3/up", "run3/down"]
    assert prof.duration_s == pytest.approx(6 * 600.0)


@pytest.mark.parametrize("name", PROFILE_NAMES)
def test_builtin_ramps_have_requested_rates_on_the_program_grid(name: str) -> None:
    prof = builtin_profile(name)
    t, c = prof.program(10.0)
    slopes = np.diff(c) / np.diff(t) * 60.0  # °C/min
    for p in prof.pieces():
        inside = (t[:-1] >= p.start_s) & (t[1:] <= p.end_s)
        assert inside.any()
        expected = p.rate_c_per_min
        assert_allclose(slopes[inside], expected, atol=1e-9)


def test_rlg_modelling_rates_and_holds() -> None:
    prof = builtin_profile("rlg-modelling", hold_s=3000.0, rate_hold_s=1500.0)
    pieces = prof.pieces()
    rate_ramps = [p for p in pieces if p.kind == "ramp" and p.label.startswith("rate ±")]
    got = sorted({round(abs(p.rate_c_per_min), 12) for p in rate_ramps})
    assert got == [0.1, 0.2, 0.5, 1.0, 2.0]
    for p in rate_ramps:  # each rate ramps up and down over the full span
        assert {p.start_c, p.end_c} == {-20.0, 50.0}
        assert p.duration_s == pytest.approx(70.0 / abs(p.rate_c_per_min) * 60.0)
    holds = [p for p in pieces if p.kind == "hold"]
    assert {round(p.duration_s, 9) for p in holds} == {3000.0, 1500.0}
    temps = prof.knots()[1]
    assert temps.min() == -20.0 and temps.max() == 50.0


def test_accel_full_range_structure() -> None:
    prof = builtin_profile("accel-full-range", repeats=2)
    pieces = prof.pieces()
    for run in ("run1/", "run2/"):
        mine = [p for p in pieces if p.label.startswith(run)]
        soak_low = [p for p in mine if p.label == run + "soak-low"]
        assert len(soak_low) == 1 and soak_low[0].start_c == -40.0
        assert soak_low[0].duration_s == pytest.approx(7200.0)
        ramp = next(p for p in mine if p.label == run + "ramp")
        assert (ramp.start_c, ramp.end_c) == (-40.0, 60.0)
        assert ramp.rate_c_per_min == pytest.approx(2.0)
        points = [p for p in mine if p.label.startswith(run + "point")]
        assert [p.start_c for p in points] == [-40.0 + 5 * i for i in range(21)]
        assert all(p.duration_s == pytest.approx(1800.0) for p in points)


def test_mems_warmup_power_on_holds() -> None:
    prof = builtin_profile("mems-warmup", start_temps_c=(-40, 25, 85), record_s=420)
    on = [s for s in prof.stages() if s.label.startswith("power-on")]
    assert [s.setpoint_c for s in on] == [-40.0, 25.0, 85.0]
    assert all(s.end_s - s.start_s == pytest.approx(420.0) for s in on)
    with pytest.raises(ThermocalInputError):
        builtin_profile("mems-warmup", record_s=300)


def test_bad_segments_and_names() -> None:
    with pytest.raises(ThermocalInputError):
        Ramp(10.0, 0.0)
    with pytest.raises(ThermocalInputError):
        Hold(-1.0)
    with pytest.raises(ThermocalInputError):
        Cycle((Hold(1.0),), 0)
    with pytest.raises(ThermocalInputError, match="unknown profile"):
        builtin_profile("nope")
    with pytest.raises(ThermocalInputError, match="fog-slow"):
        builtin_profile("fog-slow", bogus=1)
    with pytest.raises(ThermocalInputError):
        builtin_profile("fog-slow").program(0.0)


def test_correlate_matches_numpy_corrcoef() -> None:
    rng = np.random.default_rng(1)
    t = np.arange(1000.0) * 10.0
    x = np.cumsum(rng.normal(size=t.size))
    y = 0.5 * x + np.cumsum(rng.normal(size=t.size))
    res = correlate(t, x, t + 5000.0, y, n_points=t.size)  # B starts later: elapsed time
    assert res.r == pytest.approx(np.corrcoef(x, y)[0, 1], abs=1e-12)
    assert res.n == t.size
    assert res.weakly_correlated == (res.r < 0.4)
    assert correlate(t, x, t, x).r == pytest.approx(1.0)
    assert correlate(t, x, t, -x).r == pytest.approx(-1.0)


def test_correlate_uses_common_elapsed_base() -> None:
    t_a = np.linspace(0, 36000, 3601)
    a = np.sin(t_a / 3000.0)
    t_b = np.linspace(0, 72000, 7201)
    b = np.cos(t_b / 5000.0)
    full = correlate(t_a, a, t_b, b, n_points=3601)
    cut = t_b <= 36000
    trunc = correlate(t_a, a, t_b[cut], b[cut], n_points=3601)
    assert full.r == pytest.approx(trunc.r, abs=1e-12)
    assert full.duration_s == pytest.approx(36000.0)


def test_correlate_bad_input() -> None:
    t = np.arange(10.0)
    with pytest.raises(ThermocalInputError, match="constant"):
        correlate(t, np.ones(10), t, t)
    with pytest.raises(ThermocalInputError):
        correlate(t, t[:5], t, t)
    with pytest.raises(TimestampError):
        correlate(t[::-1], t, t, t)


def test_default_validation_is_weakly_correlated_with_modelling() -> None:
    tm, cm = builtin_profile("rlg-modelling").program(60.0)
    tv, cv = builtin_profile("rlg-validation").program(60.0)
    res = correlate(tm, cm, tv, cv)
    assert abs(res.r) < 0.4 and res.weakly_correlated


def test_designer_meets_limit_covers_range_and_is_reproducible() -> None:
    tm, cm = builtin_profile("rlg-modelling").program(60.0)
    a = design_validation_profile(tm, cm, seed=7)
    b = design_validation_profile(tm, cm, seed=7)
    c = design_validation_profile(tm, cm, seed=8)
    assert a.knots()[0].tolist() == b.knots()[0].tolist()
    assert a.knots()[1].tolist() == b.knots()[1].tolist()
    assert a.knots()[1].tolist() != c.knots()[1].tolist()
    tv, cv = a.program(60.0)
    res = correlate(tm, cm, tv, cv)
    assert abs(res.r) < 0.4 and res.weakly_correlated
    holds = [s.setpoint_c for s in a.stages()]
    assert min(holds) == pytest.approx(cm.min()) and max(holds) == pytest.approx(cm.max())
    assert len(holds) == 8  # one per 10 °C over −20…+50


def test_designer_reports_failure() -> None:
    tm, cm = builtin_profile("rlg-modelling").program(600.0)
    with pytest.raises(DesignError):
        design_validation_profile(tm, cm, seed=0, r_limit=1e-12, n_candidates=3)


def test_program_round_trip_and_errors(tmp_path: Path) -> None:
    t, c = builtin_profile("fog-slow").program(30.0)
    p = write_program(tmp_path / "prog.csv", t, c)
    t2, c2 = read_program(p)
    assert_allclose(t2, t, rtol=1e-10)
    assert_allclose(c2, c, rtol=1e-9)
    bad = tmp_path / "bad.csv"
    bad.write_text("time,setpoint_c\n0,1\n")
    with pytest.raises(MissingColumnError, match="time_s"):
        read_program(bad)
    bad.write_text("time_s,setpoint_c\n0,1\n10,x\n")
    with pytest.raises(NonNumericError, match="row 1"):
        read_program(bad)
    bad.write_text("time_s,setpoint_c\n0,1\n10,2\n5,3\n")
    with pytest.raises(TimestampError, match="row 2"):
        read_program(bad)


def test_find_holds_recovers_validation_holds() -> None:
    prof = builtin_profile("rlg-validation", hold_s=5400.0)
    t, c = prof.program(60.0)
    holds = find_holds(t, c, min_duration_s=600.0)
    assert [h.setpoint_c for h in holds] == pytest.approx(
        [5.0, -20.0, 35.0, -5.0, 50.0, 20.0, -10.0, 40.0]
    )
    assert all(h.end_s - h.start_s == pytest.approx(5400.0) for h in holds)
