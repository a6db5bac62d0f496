"""Tests of the warm-up model (SPEC §4c): truth recovery, independent two-stage
reference, streaming twin, file round-trip, clamping and bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from thermocal.errors import DesignError, ExtrapolationWarning, ThermocalInputError
from thermocal.models import get_model_class
from thermocal.models.base import ModelStream
from thermocal.models.numerics import running_start_mean
from thermocal.models.rundata import RunData
from thermocal.models.warmup import WarmupModel
from thermocal.pipeline.model_file import load_model, save_model

# true b (rows: ΔT^0..ΔT^2, columns: T0^0..T0^2), a0 ≡ 0 [°/h, °/h/°C, ...]
B_TRUE = np.array(
    [
        [0.0, 0.0, 0.0],
        [2.0, -0.03, 4e-4],
        [-0.05, 1e-3, 2e-5],
    ]
)
WINDOW_S = 10.0


def feed(st: ModelStream, run: RunData, *, with_signal: bool = True) -> np.ndarray:
    """Feed a run sample by sample to a model stream (the streaming twin of predict)."""
    sig = run.signal if (with_signal and run.signal is not None) else [None] * run.n_samples
    return np.array(
        [
            st.update(float(t), row, s)
            for t, row, s in zip(run.time_s, run.temps_c, sig, strict=True)
        ]
    )


def _a(t0: float) -> list[float]:
    return [float(np.polyval(B_TRUE[j][::-1], t0)) for j in range(3)]


def exact_run(t0: float, *, n: int = 400, dt: float = 1.0) -> RunData:
    """Noise-free run in the model class: T = T0 during the start window, then
    self-heating; F = 5 + Σ_j a_j(T0) ΔT^j exactly."""
    t = np.arange(n) * dt
    rise = np.where(t < WINDOW_S, 0.0, (6.0 + 0.05 * t0) * (1 - np.exp(-(t - WINDOW_S) / 90.0)))
    temp = t0 + rise
    a = _a(t0)
    f = 5.0 + a[1] * rise + a[2] * rise**2
    return RunData(
        time_s=t,
        temps_c=np.column_stack([temp, temp - 3.0]),
        signal=f,
        temp_names=("T1", "T2"),
        name=f"exact{t0:g}",
    )


def physical_run(t_amb: float, seed: int, *, n: int = 480) -> tuple[RunData, np.ndarray]:
    """A power-on at ambient ``t_amb``: self-heating from the first sample (also
    inside the start window), a bias that depends nonlinearly on the heating and
    on the ambient, turn-on offset and white noise.  Returns (run, true drift)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=np.float64)
    heat = (7.0 + 0.03 * t_amb) * (1 - np.exp(-t / 100.0))
    temp_true = t_amb + heat
    drift = (1.5 - 0.01 * t_amb) * heat - (0.04 + 2e-4 * t_amb) * heat**2 + 2e-3 * heat**3
    sig = 3.0 + rng.normal(0.0, 0.5) + drift + rng.normal(0.0, 0.05, n)
    temp = temp_true + rng.normal(0.0, 0.01, n)
    run = RunData(time_s=t, temps_c=temp[:, None], signal=sig, temp_names=("T1",), name=f"p{t_amb}")
    return run, drift


FIT_AMBIENTS = (-20.0, 0.0, 20.0, 40.0, 60.0)


@pytest.fixture(scope="module")
def fitted() -> WarmupModel:
    runs = [physical_run(a, i)[0] for i, a in enumerate(FIT_AMBIENTS)]
    return WarmupModel(order=3, t0_order=2, start_window_s=WINDOW_S).fit(runs)


# --- truth recovery --------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["two_stage", "joint"])
def test_exact_recovery_of_b(method: str) -> None:
    runs = [exact_run(t0) for t0 in (-10.0, 10.0, 30.0, 50.0)]
    m = WarmupModel(order=2, t0_order=2, start_window_s=WINDOW_S, method=method).fit(runs)
    np.testing.assert_allclose(m.b_, B_TRUE, rtol=1e-8, atol=1e-10)
    assert m.stats_.rms_residual < 1e-9
    assert m.sensor_name_ == "T1"
    assert m.temp_names_ == ("T1",)
    # predict on an unseen start temperature reproduces the truth exactly
    test = exact_run(25.0)
    truth = test.target() - 5.0
    np.testing.assert_allclose(m.predict(test), truth, atol=1e-8)


@pytest.mark.parametrize(
    ("method", "per_run_offset", "exact"),
    [("two_stage", True, True), ("joint", True, True), ("joint", False, False)],
)
def test_turn_on_noise_in_f0_stays_out_of_the_slopes(
    method: str, per_run_offset: bool, exact: bool
) -> None:
    """A random error of F0 (noise in the start window) shifts ΔF of a run by a
    constant: a free a0 per run absorbs it; a0(T0) forced smooth does not."""
    rng = np.random.default_rng(3)
    runs = []
    for t0 in (-10.0, 0.0, 10.0, 30.0, 50.0):
        r = exact_run(t0)
        sig = r.signal.copy()
        sig[r.time_s < WINDOW_S] += rng.normal(0.0, 0.5)
        runs.append(RunData(r.time_s, r.temps_c, sig, r.temp_names, r.name))
    m = WarmupModel(
        order=2, t0_order=2, start_window_s=WINDOW_S, method=method, per_run_offset=per_run_offset
    ).fit(runs)
    close = np.allclose(m.b_[1:], B_TRUE[1:], rtol=1e-7, atol=1e-9)
    assert close == exact


def test_two_stage_matches_independent_polyfit_reference(fitted: WarmupModel) -> None:
    """Stage 1 with np.polyfit per run, stage 2 with np.polyfit of a_j against T0."""
    runs = [physical_run(a, i)[0] for i, a in enumerate(FIT_AMBIENTS)]
    a_runs, t0s = [], []
    for r in runs:
        m = int(np.count_nonzero(r.time_s - r.time_s[0] < WINDOW_S))
        temp, y = r.temps_c[:, 0], r.target()
        t0, f0 = temp[:m].mean(), y[:m].mean()
        a_runs.append(np.polyfit(temp[m:] - t0, y[m:] - f0, 3)[::-1])
        t0s.append(t0)
    a_arr = np.array(a_runs)
    b_ref = np.array([np.polyfit(t0s, a_arr[:, j], 2)[::-1] for j in range(4)])
    np.testing.assert_allclose(fitted.b_, b_ref, rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(fitted.run_coefficients_, a_arr, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(fitted.start_temps_, t0s, rtol=1e-12)
    assert fitted.b_stderr_ is not None
    assert np.all(fitted.b_stderr_ > 0)
    assert len(fitted.coefficients()) == 12
    assert fitted.stats_.dof == 2


@pytest.mark.parametrize("t_amb", [10.0, 30.0, 50.0])
def test_removes_warmup_drift_at_unfitted_start_temperature(
    fitted: WarmupModel, t_amb: float
) -> None:
    """≥ 90 % of the warm-up drift removed at start temperatures not fitted."""
    run, drift = physical_run(t_amb, 100 + int(t_amb))
    model = fitted.predict(run)
    residual = drift - model
    before = np.sqrt(np.mean((drift - drift.mean()) ** 2))
    after = np.sqrt(np.mean((residual - residual.mean()) ** 2))
    assert after / before < 0.10, (t_amb, after, before)
    # the corrected output is F − ΔF (SPEC §4c)
    a_j = fitted.a_of_t0(run.temps_c[:10, 0].mean())
    dt = run.temps_c[-1, 0] - run.temps_c[:10, 0].mean()
    assert model[-1] == pytest.approx(np.polyval(a_j[::-1], dt), rel=1e-12)


def test_t0_is_causal_running_mean() -> None:
    t = np.array([0.0, 1.0, 2.0, 3.0, 10.0, 11.0])
    x = np.array([1.0, 2.0, 3.0, 4.0, 50.0, 60.0])
    np.testing.assert_allclose(
        running_start_mean(t, x, 3.5), [1.0, 1.5, 2.0, 2.5, 2.5, 2.5], rtol=0, atol=0
    )
    # predict of a prefix equals the prefix of predict (causality)
    run, _ = physical_run(25.0, 7)
    m = WarmupModel(order=2, t0_order=1, start_window_s=WINDOW_S).fit(
        [physical_run(a, i)[0] for i, a in enumerate((0.0, 20.0, 40.0))]
    )
    full = m.predict(run)
    k = 7
    pre = RunData(run.time_s[:k], run.temps_c[:k], run.signal[:k], run.temp_names)
    np.testing.assert_array_equal(m.predict(pre), full[:k])


# --- streaming, files --------------------------------------------------------------------------


def test_stream_equals_predict_with_gap(fitted: WarmupModel) -> None:
    run, _ = physical_run(30.0, 55)
    keep = np.ones(run.n_samples, bool)
    keep[4:7] = False  # gap inside the start window
    keep[200:260] = False  # and a later one
    gapped = RunData(
        run.time_s[keep],
        run.temps_c[keep],
        run.signal[keep],
        run.temp_names,
    )
    batch = fitted.predict(gapped)
    st = fitted.stream(1.0)
    live = np.array(feed(st, gapped))
    np.testing.assert_allclose(live, batch, rtol=1e-12, atol=0)
    # a reset is a new power-on
    st.reset()
    again = feed(st, gapped, with_signal=False)[:20]
    np.testing.assert_allclose(again, batch[:20], rtol=1e-12, atol=0)


def test_stream_with_all_channels_uses_sensor_index() -> None:
    runs = [exact_run(t0) for t0 in (-10.0, 10.0, 30.0, 50.0)]
    m = WarmupModel(order=2, t0_order=2, start_window_s=WINDOW_S, sensor=1).fit(runs)
    assert m.sensor_name_ == "T2"
    test = exact_run(20.0)
    batch = m.predict(test)
    st = m.stream(1.0)
    live = feed(st, test, with_signal=False)
    np.testing.assert_allclose(live, batch, rtol=1e-12, atol=0)


def test_model_file_round_trip(fitted: WarmupModel, tmp_path) -> None:
    fitted.signal_name, fitted.signal_unit = "gyro", "deg/h"
    path = tmp_path / "warmup.json"
    d = save_model(fitted, path)
    assert d["family"] == "warmup"
    assert np.array(d["state"]["b"]).shape == (4, 3)
    assert d["state"]["start_window_s"] == WINDOW_S
    loaded = load_model(path)
    assert isinstance(loaded, WarmupModel)
    run, _ = physical_run(35.0, 3)
    np.testing.assert_array_equal(loaded.predict(run), fitted.predict(run))
    assert loaded.get_params() == fitted.get_params()


def test_registry_and_cli_options() -> None:
    assert get_model_class("warmup") is WarmupModel
    m = WarmupModel.from_options(
        {
            "start_window_s": 5.0,
            "order": 3,
            "t0_order": None,
            "per_run_offset": True,
            "segments": None,  # not given: no matter that warmup does not take it
        }
    )
    assert (m.start_window_s, m.order, m.t0_order) == (5.0, 3, 2)
    # an option warmup does not take is refused (no longer dropped silently)
    with pytest.raises(ThermocalInputError, match="segments does not apply to model 'warmup'"):
        WarmupModel.from_options({"segments": 3})


# --- range and bad input -----------------------------------------------------------------------


def test_out_of_range_clamps_and_warns(fitted: WarmupModel) -> None:
    run, _ = physical_run(75.0, 9)  # start temperature above the fitted 60 °C
    with pytest.warns(ExtrapolationWarning, match="outside"):
        clamped = fitted.predict(run)
    lo, hi = fitted.temp_range_[0]
    t0_hi = fitted.t0_range_[1]
    temp = np.clip(run.temps_c[:, 0], lo, hi)
    t0 = running_start_mean(run.time_s, temp, WINDOW_S)
    a = fitted.a_of_t0(np.minimum(t0, t0_hi))
    ref = sum(a[:, j] * (temp - t0) ** j for j in range(4))
    np.testing.assert_allclose(clamped, ref, rtol=1e-10, atol=1e-10)
    with pytest.warns(ExtrapolationWarning, match="extrapolating"):
        extra = fitted.predict(run, extrapolate=True)
    assert not np.allclose(extra, clamped)
    st = fitted.stream(1.0)
    with pytest.warns(ExtrapolationWarning):
        live = feed(st, run, with_signal=False)
    np.testing.assert_allclose(live, clamped, rtol=1e-12, atol=0)


def test_single_start_temperature_needs_more_runs() -> None:
    runs = [physical_run(20.0, i)[0] for i in range(3)]
    with pytest.raises(DesignError, match=r"t0_order=2 needs runs at ≥ 3 distinct start"):
        WarmupModel(t0_order=2).fit(runs)
    # t0_order 0 works with one start temperature
    m = WarmupModel(order=2, t0_order=0).fit(runs)
    assert m.b_.shape == (3, 1)


def test_bad_input() -> None:
    run = physical_run(20.0, 1)[0]
    flat = RunData(run.time_s, np.full((run.n_samples, 1), 20.0), run.signal, ("T1",))
    with pytest.raises(DesignError, match="does not change"):
        WarmupModel(t0_order=0).fit([flat])
    with pytest.raises(ThermocalInputError, match="order"):
        WarmupModel(order=0).fit([run])
    with pytest.raises(ThermocalInputError, match="start_window_s"):
        WarmupModel(start_window_s=-1.0).fit([run])
    with pytest.raises(ThermocalInputError, match="method"):
        WarmupModel(method="magic").fit([run])
    with pytest.raises(ThermocalInputError, match="sensor=3"):
        WarmupModel(sensor=3, t0_order=0).fit([run])
    with pytest.raises(ThermocalInputError, match="no runs"):
        WarmupModel().fit([])
    short = RunData(run.time_s[:11], run.temps_c[:11], run.signal[:11], ("T1",))
    with pytest.raises(DesignError, match="after the 10 s start window"):
        WarmupModel(t0_order=0, start_window_s=10.0).fit([short])
    with pytest.raises(ThermocalInputError, match="not fitted"):
        WarmupModel().predict(run)


# --- simulator truth (scenario mems-warmup) -------------------------------------------------------


def _mems_runs(seed: int) -> list[tuple[RunData, dict, np.ndarray]]:
    from thermocal.simulate import SCENARIOS

    out = []
    for rec, truth in SCENARIOS["mems-warmup"](seed):
        run = RunData.from_recording(rec, "gyro", ["T1", "T2"], known_input=truth["input"])
        out.append((run, truth, rec.column("truth_bias")))
    return out


@pytest.mark.parametrize("held_out", ["T+20", "T+40"])
def test_simulator_removes_90_percent_of_warmup_drift(held_out: str) -> None:
    """mems-warmup: fit on the start temperatures −40…+80 °C except ``held_out``
    (8 repeats, seeds 0–7: the mems-gyro's flicker noise, B = 3 °/h, needs the
    repeats — with one repeat only ≈ 80 % is removed), test on ``held_out`` of seed 100:
    the RMS of the drift left is ≤ 10 % of the RMS of the true drift."""
    fit = [r for s in range(8) for r, tr, _ in _mems_runs(s) if tr["label"] != held_out]
    model = WarmupModel(order=2, t0_order=2, start_window_s=0.5).fit(fit)
    assert model.sensor_name_ == "T1"
    run, truth, drift = next(x for x in _mems_runs(100) if x[1]["label"] == held_out)
    t0_true = truth["start_temperature_c"]
    assert not any(abs(t0 - t0_true) < 1.0 for t0 in model.start_temps_)
    left = drift - model.predict(run)
    removed = 1.0 - np.std(left) / np.std(drift)
    assert removed >= 0.90, removed
    # and on the noise-free output (truth_rate) the model structure leaves < 1 %
    exact = [
        RunData(r.time_s, r.temps_c, r.signal - r.target() + d, r.temp_names)
        for r, tr, d in _mems_runs(0)
        if tr["label"] != held_out
    ]
    ideal = WarmupModel(order=2, t0_order=2, start_window_s=0.5).fit(exact)
    left_ideal = drift - ideal.predict(run)
    assert 1.0 - np.std(left_ideal) / np.std(drift) >= 0.99


def test_stream_warns_once_per_kind(fitted: WarmupModel) -> None:
    run, _ = physical_run(75.0, 9)  # start temperature and temperatures above the range
    st = fitted.stream(1.0)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        live = feed(st, run, with_signal=False)
        batch = fitted.predict(run)
    texts = [str(w.message) for w in rec if issubclass(w.category, ExtrapolationWarning)]
    stream_texts = [t for t in texts if "samples" not in t]
    assert len(stream_texts) == 2  # temperature, start temperature T0: once each
    np.testing.assert_array_equal(live, batch)


def test_record_longer_than_any_fitted_power_on_is_warned(
    fitted: WarmupModel, tmp_path, capsys
) -> None:
    """Issue 14: a warm-up model fitted on 480 s power-ons applied to a 6 h record says
    so (predict, stream, and compensate through the CLI); a record within the fitted
    span does not."""
    import pandas as pd

    from thermocal.cli import main

    assert fitted.duration_range_s_ == (479.0, 479.0)
    long_run, _ = physical_run(20.0, 9, n=6 * 3600)
    with pytest.warns(ExtrapolationWarning, match=r"runs 21599 s after power-on.*479…479 s"):
        fitted.predict(long_run)
    st = fitted.stream(1.0)
    with pytest.warns(ExtrapolationWarning, match="after power-on"):
        feed(st, long_run)
    short_run, _ = physical_run(20.0, 9, n=480)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ExtrapolationWarning)
        fitted.predict(short_run)
        feed(fitted.stream(1.0), short_run)
    # through the CLI, on a CSV
    model = tmp_path / "w.json"
    save_model(fitted, model)
    pd.DataFrame(
        {"time": long_run.time_s, "T1": long_run.temps_c[:, 0], "sig": long_run.signal}
    ).to_csv(tmp_path / "long.csv", index=False)
    code = main(
        ["compensate", str(model), str(tmp_path / "long.csv"), "--signal", "sig",
         "--signal-unit", "deg/h", "--time-unit", "s", "--temp-unit", "degC",
         "-o", str(tmp_path / "out.csv")]
    )  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 0, err
    assert "after power-on" in err
    # the older files without the field still load (no check then)
    d = load_model(model)
    assert d.duration_range_s_ == (479.0, 479.0)
