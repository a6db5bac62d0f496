"""Tests of the piecewise-linear model (SPEC §4b, seed 001)."""

from __future__ import annotations

import dataclasses
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from thermocal.errors import (
    DesignError,
    ExtrapolationWarning,
    ThermocalInputError,
    ThermocalWarning,
)
from thermocal.models import RunData, get_model_class
from thermocal.models.breakpoints import evaluate_lines
from thermocal.models.piecewise import PiecewiseModel
from thermocal.pipeline.model_file import load_model, save_model
from thermocal.simulate import SCENARIOS

BPS = np.array([23.6, 30.0])
INTER = np.array([1.0 - 0.05 * 23.6, 1.0 - 0.01 * 23.6, 1.064 - 0.08 * 30.0])
SLOPES = np.array([0.05, 0.01, 0.08])


def truth(T):
    """The seed's shape written out independently of the model code: slope 0.05 below
    23.6 °C, 0.01 up to 30 °C, 0.08 above, value 1.0 at 23.6 °C."""
    T = np.asarray(T, dtype=float)
    return (
        1.0
        + 0.05 * np.minimum(T - 23.6, 0.0)
        + 0.01 * np.clip(T - 23.6, 0.0, 6.4)
        + 0.08 * np.maximum(T - 30.0, 0.0)
    )


def test_truth_matches_the_line_table():
    """The hand-written lines (INTER, SLOPES) and the hinge formula agree."""
    T = np.linspace(10.0, 45.0, 3501)
    assert_allclose(evaluate_lines(BPS, INTER, SLOPES, T), truth(T), atol=1e-12)


def make_run(n=12000, noise=0.0, seed=0, gap=False, offset=0.0, name="r"):
    rng = np.random.default_rng(seed)
    t = np.arange(float(n))
    if gap:
        t[n // 2 :] += 500.0
    T = 15 + 27 * (0.5 - 0.5 * np.cos(2 * np.pi * t / n))
    y = truth(T) + offset + noise * rng.standard_normal(n)
    return RunData(t, np.column_stack([T, T + 1.0]), y, ("T1", "T2"), name)


def test_truth_is_continuous():
    for b in BPS:
        assert truth(np.array([b - 1e-12]))[0] == pytest.approx(truth(np.array([b]))[0], abs=1e-9)


def test_continuous_exact_recovery_with_given_breakpoints():
    run = make_run()
    m = PiecewiseModel(breakpoints=[23.6, 30.0], method="continuous", per_run_offset=False)
    m.fit([run])
    assert_allclose(m.slopes_, SLOPES, atol=1e-10)
    assert_allclose(m.intercepts_, INTER, atol=1e-9)
    assert m.stats_.n_coefficients == 4
    assert m.stats_.rms_residual < 1e-10


def test_intersect_moves_breakpoints_and_is_continuous():
    run = make_run(noise=0.01)
    m = PiecewiseModel(breakpoints=[25, 30]).fit([run])
    # the 25 °C breakpoint moves towards the true corner (seed: 25 → 23.6)
    assert 23.0 < m.breakpoints_[0] < 25.0
    assert m.breakpoints_[1] == pytest.approx(30.0, abs=0.3)
    a, s = m.intercepts_, m.slopes_
    for j, b in enumerate(m.breakpoints_):
        assert a[j] + s[j] * b == pytest.approx(a[j + 1] + s[j + 1] * b, abs=1e-9)
    assert m.stats_.extra["initial_breakpoints"] == [25.0, 30.0]


@pytest.mark.parametrize("method", ["intersect", "continuous"])
def test_breakpoints_chosen_from_data(method):
    run = make_run(noise=0.005)
    m = PiecewiseModel(segments=3, method=method).fit([run])
    assert_allclose(m.breakpoints_, BPS, atol=0.2)
    assert_allclose(m.slopes_, SLOPES, atol=2e-3)


def test_uses_named_temperature():
    run = make_run()
    m = PiecewiseModel(breakpoints=[24.6, 31.0], method="continuous", temperature="T2")
    m.fit([run])
    assert m.temp_names_ == ("T2",)
    # T2 = T1 + 1: same lines shifted by 1 °C
    assert_allclose(m.slopes_, SLOPES, atol=1e-9)
    assert_allclose(m.predict(run), truth(run.temps_c[:, 0]), atol=1e-9)


def test_stream_equals_batch_with_gap_and_round_trip(tmp_path):
    run = make_run(n=3000, noise=0.01, gap=True)
    m = PiecewiseModel(segments=3).fit([run])
    batch = m.predict(run)
    s = m.stream(1.0)
    vals = np.array([s.update(run.time_s[i], run.temps_c[i]) for i in range(run.n_samples)])
    assert_allclose(vals, batch, rtol=1e-12, atol=1e-12)
    save_model(m, tmp_path / "pw.json")
    back = load_model(tmp_path / "pw.json")
    assert isinstance(back, PiecewiseModel)
    assert_array_equal(back.predict(run), batch)
    one_col = dataclasses.replace(run, temps_c=run.temps_c[:, :1], temp_names=("T1",))
    assert_array_equal(back.predict(one_col), batch)


def test_out_of_range_clamps_and_warns():
    run = make_run()
    m = PiecewiseModel(breakpoints=[23.6, 30.0], method="continuous").fit([run])
    hot = dataclasses.replace(run, temps_c=run.temps_c + 10.0)
    with pytest.warns(ExtrapolationWarning):
        got = m.predict(hot)
    top = m.predict(dataclasses.replace(run, temps_c=np.full_like(run.temps_c, 42.0)))
    assert_allclose(got[hot.temps_c[:, 0] > 42.0], top[0], atol=1e-12)
    with pytest.warns(ExtrapolationWarning):
        ext = m.predict(hot, extrapolate=True)
    assert_allclose(ext, truth(hot.temps_c[:, 0]), atol=1e-9)
    s = m.stream(1.0)
    with pytest.warns(ExtrapolationWarning):
        assert s.update(0.0, np.array([60.0, 61.0])) == pytest.approx(top[0], abs=1e-12)


def test_per_run_offsets():
    a = make_run(noise=0.005, seed=1, offset=0.2, name="a")
    b = make_run(noise=0.005, seed=2, offset=-0.4, name="b")
    m = PiecewiseModel(breakpoints=[23.6, 30.0], method="continuous").fit([a, b])
    assert m.offsets_[0] - m.offsets_[1] == pytest.approx(0.6, abs=2e-3)
    assert_allclose(m.slopes_, SLOPES, atol=2e-3)


def test_bad_inputs():
    run = make_run(n=2000)
    with pytest.raises(DesignError, match="outside"):
        PiecewiseModel(breakpoints=[50.0]).fit([run])
    narrow = dataclasses.replace(
        run, temps_c=np.column_stack([np.r_[np.full(1999, 20.0), 40.0], np.zeros(2000)])
    )
    with pytest.raises(DesignError, match="sample"):
        PiecewiseModel(breakpoints=[30.0]).fit([narrow])
    with pytest.raises(ThermocalInputError):
        PiecewiseModel(method="spline").fit([run])
    with pytest.raises(ThermocalInputError):
        PiecewiseModel(breakpoints=[25.0], segments=3).fit([run])
    with pytest.raises(ThermocalInputError):
        PiecewiseModel(temperature="T9").fit([run])
    assert get_model_class("piecewise") is PiecewiseModel


@pytest.mark.parametrize("seed", [1, 2])
def test_fog_slow_peak_to_peak_reduced_96_percent(seed):
    """Seed 001: piecewise compensation cuts the bias peak-to-peak over 15–42 °C by ≥ 96 %."""
    rec, tr = SCENARIOS["fog-slow"](seed)[0]
    run = RunData.from_recording(rec, "gyro", ["T1"], known_input=tr["input"])
    tb = rec.columns["truth_bias"]
    for kw in ({"breakpoints": [25.0, 30.0]}, {"segments": 3, "method": "continuous"}):
        m = PiecewiseModel(**kw).fit([run])  # type: ignore[arg-type]
        e = tb - m.predict(run)
        assert 1.0 - np.ptp(e) / np.ptp(tb) >= 0.96


def test_stream_warns_once_per_stream():
    run = make_run()
    m = PiecewiseModel(breakpoints=[23.6, 30.0], method="continuous").fit([run])
    hot = dataclasses.replace(run, temps_c=run.temps_c + 10.0)
    s = m.stream(1.0)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        live = [s.update(t, row) for t, row in zip(hot.time_s, hot.temps_c, strict=True)]
        batch = m.predict(hot)
    assert len([w for w in rec if issubclass(w.category, ExtrapolationWarning)]) == 2
    assert_array_equal(live, batch)
    s.reset()
    with pytest.warns(ExtrapolationWarning):
        s.update(0.0, [60.0])


# --- the breakpoint search: no degenerate segments, breakpoints only where warranted ----


def _history(shape: str, n: int, rng: np.random.Generator) -> np.ndarray:
    """Temperature histories of several shapes over about 15…42 °C."""
    u = np.arange(n) / n
    if shape == "ramp":
        return 15.0 + 27.0 * u
    if shape == "cycles":
        return 28.5 - 13.5 * np.cos(2 * np.pi * 3 * u)
    if shape == "holds":  # steps of 5 °C with short ramps and sensor noise
        levels = np.repeat(np.arange(15.0, 45.0, 5.0), n // 6 + 1)[:n]
        return np.convolve(levels, np.ones(50) / 50, mode="same") + rng.normal(0, 0.01, n)
    if shape == "uneven":  # most samples near the cold end
        return 15.0 + 27.0 * u**3
    raise AssertionError(shape)


SHAPES = ("ramp", "cycles", "holds", "uneven")


def _segment_widths(m: PiecewiseModel) -> np.ndarray:
    lo, hi = m.temp_range_[0]
    return np.diff(np.concatenate([[lo], m.initial_breakpoints_, [hi]])) / (hi - lo)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("seed", range(5))
def test_a_straight_line_is_fitted_as_one_line_with_a_warning(shape, seed):
    """Data that are one line (slope 0.05 /°C, noise 0.01) and 3 segments asked for: the
    fit keeps one segment and says so; it never ends on a degenerate segment."""
    rng = np.random.default_rng(1000 + seed)
    n = 3000
    T = _history(shape, n, rng)
    y = 1.0 + 0.05 * T + 0.01 * rng.standard_normal(n)
    run = RunData(np.arange(float(n)), T[:, None], y, ("T1",), "line")
    with pytest.warns(
        ThermocalWarning, match="3 segments asked for, 1 fitted: the data are a line"
    ):
        m = PiecewiseModel(segments=3).fit([run])
    assert m.breakpoints_.size == 0
    assert m.slopes_[0] == pytest.approx(0.05, abs=2e-3)
    sel = m.stats_.extra["segment_selection"]
    assert sel["segments_requested"] == 3 and sel["segments_kept"] == 1


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("method", ["intersect", "continuous"])
def test_real_kinks_are_recovered(shape, method):
    """Three segments of the seed's shape (corners at 23.6 and 30 °C) with noise
    0.005: both corners found within 0.3 °C, slopes within 3e-3 /°C, no warning."""
    rng = np.random.default_rng(7)
    n = 6000
    T = _history(shape, n, rng)
    y = truth(T) + 0.005 * rng.standard_normal(n)
    run = RunData(np.arange(float(n)), T[:, None], y, ("T1",), "kinks")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ThermocalWarning)
        m = PiecewiseModel(segments=3, method=method).fit([run])
    assert_allclose(m.breakpoints_, BPS, atol=0.3)
    assert_allclose(m.slopes_, SLOPES, atol=3e-3)
    assert np.all(_segment_widths(m) >= 0.05 - 1e-12)


def test_four_segments_recovered_and_a_fifth_refused():
    """Corners at 20, 27 and 35 °C (slopes 0.04, −0.02, 0.03, 0.0): with 5 segments asked
    for, the BIC keeps the true 4 and the warning says so."""
    rng = np.random.default_rng(11)
    n = 8000
    T = _history("cycles", n, rng)
    y = (
        0.04 * np.minimum(T - 20.0, 0.0)
        - 0.02 * np.clip(T - 20.0, 0.0, 7.0)
        + 0.03 * np.clip(T - 27.0, 0.0, 8.0)
        + 0.0 * np.maximum(T - 35.0, 0.0)
        + 0.004 * rng.standard_normal(n)
    )
    run = RunData(np.arange(float(n)), T[:, None], y, ("T1",), "four")
    with pytest.warns(ThermocalWarning, match="5 segments asked for, 4 fitted"):
        m = PiecewiseModel(segments=5, method="continuous").fit([run])
    assert_allclose(m.breakpoints_, [20.0, 27.0, 35.0], atol=0.4)
    assert_allclose(m.slopes_, [0.04, -0.02, 0.03, 0.0], atol=3e-3)


def test_more_segments_than_the_width_rule_allows_are_reduced():
    """A 2 °C span cannot hold 30 segments of ≥ 5 % each: at most 20 are considered."""
    rng = np.random.default_rng(3)
    T = np.linspace(20.0, 22.0, 2000)
    y = 0.1 * T + 0.001 * rng.standard_normal(T.size)
    run = RunData(np.arange(float(T.size)), T[:, None], y, ("T1",), "narrow")
    with pytest.warns(ThermocalWarning, match="allow at most 20"):
        m = PiecewiseModel(segments=30).fit([run])
    assert np.all(_segment_widths(m) >= 0.05 - 1e-12)


def test_all_zero_bias_and_two_samples_fit_without_crash(tmp_path: Path) -> None:
    """Found by the property test: an all-zero signal made the BIC floor 0 and log(0)
    failed; two samples for two coefficients gave NaN standard errors that JSON cannot
    hold.  The command line refuses two samples for two coefficients (the adequacy check,
    issue 25: nothing is written); the library fit still works, leaves the standard errors
    out ("not estimable") and its file form holds no NaN."""
    from typer.testing import CliRunner

    from thermocal.cli import app

    src = tmp_path / "two.csv"
    src.write_text("time,gyro,T1\n0.0,0.0,0.0\n1.0,0.0,1.0\n")
    out = tmp_path / "m.json"
    res = CliRunner().invoke(
        app,
        ["fit", str(src), "--model", "piecewise", "--segments", "2", "--signal", "gyro",
         "--temps", "T1", "-o", str(out), "--signal-unit", "deg/h", "--time-unit", "s",
         "--temp-unit", "degC"],
    )  # fmt: skip
    assert res.exit_code == 2, res.output
    assert "2 samples for 2 coefficients" in res.output and not out.exists()
    run = RunData(np.array([0.0, 1.0]), np.array([[0.0], [1.0]]), np.zeros(2), ("T1",))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # few samples: the fit's own conditioning notes
        m = PiecewiseModel(segments=2).fit([run])
    d = m.to_dict()
    assert [c["value"] for c in d["coefficients"]] == [0.0, 0.0]
    assert all("stderr" not in c for c in d["coefficients"])
    json.dumps(d, allow_nan=False)


def test_non_finite_model_is_refused_not_written(tmp_path: Path) -> None:
    """A model holding NaN is refused naming the field, and no file appears."""
    from thermocal.errors import DesignError

    t = np.linspace(20.0, 30.0, 50)
    est = PiecewiseModel(breakpoints=[25.0], method="continuous").fit(
        [RunData(np.arange(50.0), t[:, None], 0.1 * t, ("T1",), "line")]
    )
    est.temp_range_ = np.array([[np.nan, 30.0]])
    out = tmp_path / "bad.json"
    with pytest.raises(DesignError, match="non-finite"):
        save_model(est, out)
    assert not out.exists()
