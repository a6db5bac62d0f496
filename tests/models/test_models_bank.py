"""Tests of the adaptive model bank (SPEC §4d): clustering, piecewise fits, the
power-on selection on the simulator's truth, streaming twin, files, bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from thermocal.errors import DesignError, ExtrapolationWarning, ThermocalInputError
from thermocal.models import get_model_class
from thermocal.models.bank import BankModel
from thermocal.models.bank_curves import cluster_runs, curve_distance, hat_basis, pwl_evaluate
from thermocal.models.bank_select import Selection
from thermocal.models.base import ModelStream
from thermocal.models.rundata import RunData
from thermocal.pipeline.model_file import load_model, save_model
from thermocal.simulate import SCENARIOS

OFFSETS = (0.0, 1.5, -2.0)
CURVATURE = (2e-4, 0.0, 1e-4)  # curves ≥ 1 mg apart over −40…60 °C


def feed(st: ModelStream, run: RunData, *, with_signal: bool = True) -> np.ndarray:
    """Feed a run sample by sample to a model stream (the streaming twin of predict)."""
    sig = run.signal if (with_signal and run.signal is not None) else [None] * run.n_samples
    return np.array(
        [
            st.update(float(t), row, s)
            for t, row, s in zip(run.time_s, run.temps_c, sig, strict=True)
        ]
    )


def curve(k: int, temp: np.ndarray) -> np.ndarray:
    """Characteristic curve k [mg] against temperature [°C]."""
    return OFFSETS[k] + 0.02 * temp + CURVATURE[k] * (temp - 10.0) ** 2


def full_run(
    k: int, seed: int, *, dt: float = 10.0, gravity: float = 0.0, t_lo: float = -40.0
) -> RunData:
    """Type-1 run: soak at t_lo, ramp 2 °C/min to +60 °C, soak (2 h each)."""
    rng = np.random.default_rng(seed)
    soak, ramp = 7200.0, (60.0 - t_lo) / 2.0 * 60.0
    t = np.arange(0.0, 2 * soak + ramp, dt)
    tch = np.where(t < soak, t_lo, np.where(t < soak + ramp, t_lo + (t - soak) / 60.0 * 2.0, 60.0))
    temp = tch + rng.normal(0.0, 0.02, t.size)
    y = curve(k, tch) + rng.normal(0.0, 0.03) + rng.normal(0.0, 0.05, t.size) + gravity
    return RunData(t, temp[:, None], y, ("T1",), f"full{k}-{seed}", known_input=gravity)


def constant_points_run(k: int, seed: int, *, dt: float = 10.0) -> RunData:
    """Type-2 run: 20-min holds every 5 °C from −40 to +60 °C, 2 °C/min between."""
    rng = np.random.default_rng(seed)
    pts = np.arange(-40.0, 61.0, 5.0)
    knots_t, knots_c = [0.0], [pts[0]]
    for p in pts:
        if p != knots_c[-1]:
            knots_t.append(knots_t[-1] + abs(p - knots_c[-1]) / 2.0 * 60.0)
            knots_c.append(p)
        knots_t.append(knots_t[-1] + 1200.0)
        knots_c.append(p)
    t = np.arange(0.0, knots_t[-1], dt)
    tch = np.interp(t, knots_t, knots_c)
    y = curve(k, tch) + rng.normal(0.0, 0.03) + rng.normal(0.0, 0.05, t.size)
    return RunData(t, tch[:, None], y, ("T1",), f"points{k}-{seed}")


def power_on(k: int, temp0: float, seed: int, *, gravity: float = 0.0, n: int = 120) -> RunData:
    """A short power-on at ``temp0`` (1 Hz, slow drift of the temperature)."""
    rng = np.random.default_rng(seed)
    t = np.arange(float(n))
    temp = temp0 + 0.5 * t / 60.0 + rng.normal(0.0, 0.02, n)
    y = curve(k, temp) + rng.normal(0.0, 0.03) + rng.normal(0.0, 0.05, n) + gravity
    return RunData(t, temp[:, None], y, ("T1",), f"on{k}-{seed}", known_input=gravity)


@pytest.fixture(scope="module")
def synthetic() -> BankModel:
    runs = [full_run(k, 10 * k + r) for k in range(3) for r in range(3)]
    return BankModel().fit(runs)


# --- pure functions ---------------------------------------------------------------------------


def test_pwl_and_hat_basis_against_interp() -> None:
    x = np.array([-10.0, 0.0, 5.0, 20.0])
    v = np.array([1.0, -2.0, 0.5, 3.0])
    temp = np.linspace(-10.0, 20.0, 97)
    np.testing.assert_allclose(pwl_evaluate(x, v, temp), np.interp(temp, x, v), atol=1e-14)
    np.testing.assert_allclose(hat_basis(x, temp) @ v, np.interp(temp, x, v), atol=1e-14)
    np.testing.assert_allclose(hat_basis(x, temp).sum(axis=1), 1.0, atol=1e-15)
    # linear extension of the end segments
    ext = pwl_evaluate(x, v, np.array([-20.0, 30.0]))
    np.testing.assert_allclose(
        ext, [1.0 + (-3.0 / 10.0) * -10.0, 3.0 + 2.5 / 15.0 * 10.0], rtol=1e-14
    )


def test_clustering_is_complete_linkage() -> None:
    # curves: 0 and 1 within 0.6; 2 within 0.6 of 1 but 1.2 from 0 → complete linkage
    # keeps {0, 1} and {2}; 3 far away
    c = np.array([[0.0, 0.0], [0.6, 0.6], [1.2, 1.2], [5.0, 5.0]])
    d = curve_distance(c)
    np.testing.assert_allclose(d[0], [0.0, 0.6, 1.2, 5.0])
    assert cluster_runs(d, 1.0) == [[0, 1], [2], [3]]
    # NaN bins are ignored
    c2 = np.array([[0.0, np.nan, 1.0], [0.1, 9.0, 1.1]])
    np.testing.assert_allclose(curve_distance(c2)[0, 1], 0.1, atol=1e-12)


# --- synthetic truth ---------------------------------------------------------------------------


def test_groups_and_models_recover_the_curves(synthetic: BankModel) -> None:
    assert synthetic.groups_ == [[0, 1, 2], [3, 4, 5], [6, 7, 8]]
    assert synthetic.n_models == 3
    for k in range(3):
        x, v = synthetic.breakpoints_[k], synthetic.values_[k]
        np.testing.assert_allclose(x, np.linspace(x[0], x[-1], 21))
        # piecewise-linear interpolation error of the curve ≤ h²/8·|f''| = 0.0013 mg,
        # turn-on offsets averaged over 3 runs (σ 0.03/√3), noise
        np.testing.assert_allclose(v, curve(k, x), atol=0.06)
    assert all(info["fit_error"] < 0.2 for info in synthetic.model_info_)
    assert synthetic.stats_.extra["n_groups"] == 3
    assert len(synthetic.coefficients()) == 63


@pytest.mark.parametrize("gravity", [0.0, 1000.0])
def test_selection_on_synthetic_power_ons(synthetic: BankModel, gravity: float) -> None:
    correct = 0
    for s in range(30):
        k = s % 3
        run = power_on(k, -38.0 + 3.2 * s, 100 + s, gravity=gravity)
        pred = synthetic.predict(run)
        sel = synthetic.selection_
        correct += sel.index == k
        assert sel.complete
        assert sel.margin > 0.5
        assert sel.n_samples == 20
        truth = curve(k, run.temps_c[:, 0])
        assert np.max(np.abs(truth - pred)) < 0.2
    assert correct == 30


def test_select_reports_deviations(synthetic: BankModel) -> None:
    run = power_on(1, 20.0, 5)
    sel = synthetic.select(run)
    assert isinstance(sel, Selection)
    f = np.column_stack(
        [
            pwl_evaluate(b, v, run.temps_c[:20, 0])
            for b, v in zip(synthetic.breakpoints_, synthetic.values_, strict=True)
        ]
    )
    dev = np.abs(np.mean(run.target()[:20, None] - f, axis=0))
    np.testing.assert_allclose(sel.deviations, dev, rtol=1e-12)
    assert sel.index == 1
    srt = np.sort(dev)
    assert sel.margin == pytest.approx(srt[1] - srt[0], rel=1e-12)
    assert sel.to_dict()["index"] == 1


def test_constant_points_are_characteristic_lines() -> None:
    runs = [constant_points_run(k, 40 + 3 * k + r) for k in range(2) for r in range(2)]
    m = BankModel().fit(runs)
    assert m.groups_ == [[0, 1], [2, 3]]
    assert [info["check"] for info in m.model_info_] == ["holds", "holds"]
    assert all(info["n_check_points"] == 21 for info in m.model_info_)


def test_tolerance_rejects_models_that_do_not_fit() -> None:
    runs = [full_run(k, 10 * k + r) for k in range(2) for r in range(2)]
    # a kinked third curve that 20 °C knot spacing cannot follow
    kinked = [
        RunData(
            r.time_s,
            r.temps_c,
            r.signal + 3.0 + 2.0 * np.abs(r.temps_c[:, 0] - 12.0) / 10.0,
            r.temp_names,
            f"kinked{i}",
        )
        for i, r in enumerate(runs[:2])
    ]
    m = BankModel(knot_spacing_c=20.0, tolerance=0.2).fit(runs + kinked)
    assert m.n_models == 2
    assert len(m.rejected_) == 1
    assert m.rejected_[0]["runs"] == ["kinked0", "kinked1"]
    assert m.rejected_[0]["fit_error"] > 0.2
    with pytest.raises(DesignError, match="no characteristic curve"):
        BankModel(knot_spacing_c=20.0, tolerance=0.2).fit(kinked)


# --- simulator truth (scenario accel-full-range) -------------------------------------------------


def _sim_runs(seed: int, n: int) -> list[tuple[RunData, dict, np.ndarray]]:
    out = []
    for rec, truth in SCENARIOS["accel-full-range"](seed, runs=n):
        run = RunData.from_recording(rec, "accel", ["T1"], known_input=truth["input_mg"])
        err_free = rec.column("truth_rate") - truth["input_mg"]
        out.append((run, truth, err_free))
    return out


def _slice(run: RunData, start_s: float) -> RunData:
    keep = run.time_s >= start_s
    return RunData(
        run.time_s[keep],
        run.temps_c[keep],
        run.signal[keep],
        run.temp_names,
        f"{run.name}@{start_s:g}",
        known_input=run.known_input,
    )


def test_simulator_bank_picks_right_curve_and_compensates() -> None:
    """accel-full-range: fit on 6 runs (seed 0), ≥ 95 % right picks on 45 held-out
    power-ons (seed 1, at the start, the cold and the hot soak) with < 0.2 mg error."""
    fit = _sim_runs(0, 6)
    model = BankModel(deviation=1.0, tolerance=0.2, startup_s=20.0).fit([r for r, _, _ in fit])
    assert model.n_models == 3
    curve_of = [fit[g[0]][1]["curve"] for g in model.groups_]
    for g in model.groups_:  # every group follows one true curve
        assert len({fit[i][1]["curve"] for i in g}) == 1
    held = _sim_runs(1, 15)
    stages = {s["label"]: s["start_s"] for s in held[0][1]["stages"]}
    correct, total, worst = 0, 0, 0.0
    for run, truth, noise_free in held:
        for start in (0.0, stages["soak-low"], stages["soak-high"]):
            r = _slice(run, start)
            pred = model.predict(r)
            total += 1
            correct += curve_of[model.selection_.index] == truth["curve"]
            err = noise_free[run.time_s >= start] - pred
            worst = max(worst, float(np.sqrt(np.mean(err**2))))
    assert correct / total >= 0.95
    assert worst < 0.2


# --- streaming, files ---------------------------------------------------------------------------


def test_stream_equals_predict_with_gap_and_known_input(synthetic: BankModel) -> None:
    run = power_on(2, 10.0, 77, gravity=-1000.0, n=200)
    keep = np.ones(run.n_samples, bool)
    keep[5:9] = False  # gap inside the start-up window
    keep[100:150] = False
    gapped = RunData(
        run.time_s[keep],
        run.temps_c[keep],
        run.signal[keep],
        run.temp_names,
        known_input=run.known_input,
    )
    batch = synthetic.predict(gapped)
    st = synthetic.stream(1.0, known_input=-1000.0)
    live = feed(st, gapped)
    np.testing.assert_allclose(live, batch, rtol=1e-12, atol=0)
    assert st.selection.index == synthetic.selection_.index == 2
    # after the start-up window the signal is no longer needed
    assert st.update(1000.0, np.array([10.0])) == pytest.approx(
        pwl_evaluate(synthetic.breakpoints_[2], synthetic.values_[2], np.array([10.0]))[0]
    )
    st.reset()
    with pytest.raises(ThermocalInputError, match="needs the measured signal"):
        st.update(0.0, np.array([10.0]))


def test_model_file_round_trip(synthetic: BankModel, tmp_path) -> None:
    synthetic.signal_name, synthetic.signal_unit = "accel", "mg"
    path = tmp_path / "bank.json"
    d = save_model(synthetic, path)
    assert d["family"] == "bank"
    assert len(d["state"]["models"]) == 3
    assert len(d["state"]["models"][0]["breakpoints_c"]) == 21
    loaded = load_model(path)
    assert isinstance(loaded, BankModel)
    for s in range(3):
        run = power_on(s, 15.0 * s - 10.0, 300 + s)
        np.testing.assert_array_equal(loaded.predict(run), synthetic.predict(run))
        assert loaded.selection_ == synthetic.selection_


def test_registry_and_cli_options() -> None:
    assert get_model_class("bank") is BankModel
    m = BankModel.from_options(
        {
            "deviation": 0.5,
            "tolerance": None,
            "startup_s": 10,
            "per_run_offset": None,  # not given
        }
    )
    assert (m.deviation, m.tolerance, m.startup_s) == (0.5, 0.2, 10)
    # the bank has no per-run offsets: the option is refused, not dropped silently
    with pytest.raises(ThermocalInputError, match="per_run_offset does not apply"):
        BankModel.from_options({"per_run_offset": True})


# --- range and bad input ------------------------------------------------------------------------


def test_out_of_range_clamps_and_warns(synthetic: BankModel) -> None:
    hot = power_on(1, 70.0, 8)
    with pytest.warns(ExtrapolationWarning, match="clamped"):
        clamped = synthetic.predict(hot)
    hi = synthetic.temp_range_[0, 1]
    sel = synthetic.selection_.index
    x, v = synthetic.breakpoints_[sel], synthetic.values_[sel]
    assert hi == pytest.approx(x[-1])
    np.testing.assert_allclose(clamped[20:], v[-1], atol=1e-12)  # after the start-up
    at_edge = RunData(hot.time_s, np.minimum(hot.temps_c, hi), hot.signal, hot.temp_names)
    np.testing.assert_array_equal(clamped, synthetic.predict(at_edge))
    with pytest.warns(ExtrapolationWarning, match="extrapolating"):
        extra = synthetic.predict(hot, extrapolate=True)
    assert np.all(extra > clamped)  # curve 1 rises with temperature
    st = synthetic.stream(1.0)
    with pytest.warns(ExtrapolationWarning):
        live = feed(st, hot)
    np.testing.assert_allclose(live, clamped, rtol=1e-12, atol=0)


def test_runs_covering_different_ranges_are_refused() -> None:
    runs = [full_run(0, 1), full_run(1, 2, t_lo=0.0)]
    with pytest.raises(DesignError, match="cover different temperature ranges"):
        BankModel().fit(runs)


def test_bad_input(synthetic: BankModel) -> None:
    run = power_on(0, 20.0, 1)
    no_signal = RunData(run.time_s, run.temps_c, None, run.temp_names)
    with pytest.raises(ThermocalInputError, match="needs the measured signal"):
        synthetic.predict(no_signal)
    with pytest.raises(ThermocalInputError, match="deviation"):
        BankModel(deviation=-1.0).fit([full_run(0, 1)])
    with pytest.raises(ThermocalInputError, match="error_metric"):
        BankModel(error_metric="median").fit([full_run(0, 1)])
    with pytest.raises(ThermocalInputError, match="no runs"):
        BankModel().fit([])
    with pytest.raises(ThermocalInputError, match="not fitted"):
        BankModel().predict(run)
    flat = RunData(run.time_s, np.full_like(run.temps_c, 20.0), run.signal, run.temp_names)
    with pytest.raises(DesignError, match="span only"):
        BankModel().fit([flat])


def test_predict_equals_every_model_reference_and_stream_warns_once(synthetic: BankModel) -> None:
    hot = power_on(1, 58.0, 21, n=300)
    hot = RunData(
        hot.time_s, hot.temps_c + np.linspace(0.0, 8.0, 300)[:, None], hot.signal, hot.temp_names
    )
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        got = synthetic.predict(hot)
        st = synthetic.stream(1.0)
        live = feed(st, hot)
    # reference: every model at every (clamped) sample, running choice then frozen
    temp = np.minimum(hot.temps_c[:, 0], synthetic.temp_range_[0, 1])
    f = np.column_stack(
        [
            pwl_evaluate(b, v, temp)
            for b, v in zip(synthetic.breakpoints_, synthetic.values_, strict=True)
        ]
    )
    m = int(np.count_nonzero(hot.time_s - hot.time_s[0] < synthetic.startup_s))
    dev = np.abs(np.cumsum(hot.signal[:m, None] - f[:m], axis=0) / np.arange(1, m + 1)[:, None])
    idx = np.r_[np.argmin(dev, axis=1), np.full(hot.n_samples - m, np.argmin(dev[-1]))]
    np.testing.assert_array_equal(got, f[np.arange(hot.n_samples), idx])
    np.testing.assert_array_equal(live, got)
    stream_warnings = [
        w
        for w in rec
        if issubclass(w.category, ExtrapolationWarning) and "samples" not in str(w.message)
    ]
    assert len(stream_warnings) == 1


def test_streaming_compensator_removes_the_known_input_before_selecting(
    synthetic: BankModel,
) -> None:
    """A power-on of curve 2 under a known input K = +1 (curves 0, 1, 2 lie at 0.2, 1.7,
    −1.8 at 10 °C): the streaming compensator with ``known_input=1`` hands the bank F − K,
    so it selects curve 2 and its output is F − ŷ with ŷ the batch prediction (issue 27
    mutant compensate-stream-known-input-sign hands it F + K = curve 2 + 2: curve 0).  A
    far larger K (−1000) moves every deviation alike and cannot tell the sign."""
    from thermocal.compensate.kernels import StreamingCompensator

    run = power_on(2, 10.0, 77, gravity=1.0, n=200)
    batch = synthetic.predict(run)
    sc = StreamingCompensator(synthetic, 1.0, known_input=1.0)
    out = np.array(
        [
            sc.update(float(t), run.temps_c[i], float(run.signal[i]))
            for i, t in enumerate(run.time_s)
        ]
    )
    np.testing.assert_allclose(out, run.signal - batch, rtol=0, atol=1e-9)
