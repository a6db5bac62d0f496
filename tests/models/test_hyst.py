"""The hyst family (thermocal.models.hyst): the lag τ recovered within its σ over seeds of the
simulator's thermal-lag sweep, the leg-to-leg residual at the noise floor with the lag and
not without, the lag against the closed form of a ramp, the stream equal to predict, the
model file's checks."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

from thermocal.errors import DesignError, ModelFileError, ParameterError
from thermocal.legs import find_legs
from thermocal.models import RunData
from thermocal.models.hyst import HystModel
from thermocal.models.hyst_lag import first_order_lag
from thermocal.models.registry import make_model, model_from_dict
from thermocal.simulate import SCENARIOS

NOISE = 0.5  # °/h per sample, the scenario's default
LAG = 300.0  # s, the scenario's default


def _run(seed: int, **opts: float) -> tuple[RunData, dict]:
    rec, truth = SCENARIOS["thermal-lag"](seed, **opts)[0]
    return RunData.from_recording(rec, "gyro", ["T1"]), truth


def _part(run: RunData, a: int, b: int) -> RunData:
    return dataclasses.replace(
        run, time_s=run.time_s[a:b], temps_c=run.temps_c[a:b], signal=run.signal[a:b]
    )


def test_the_lag_is_the_closed_form_of_a_ramp_from_a_hold() -> None:
    """z = T − rτ(1 − e^(−t/τ)) on a ramp of rate r from equilibrium, with uneven steps."""
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(0.5, 1.5, 5000))
    t -= t[0]
    r, tau = 0.02, 250.0
    z = first_order_lag(t, 10.0 + r * t, tau)
    exact = 10.0 + r * t - r * tau * (1.0 - np.exp(-t / tau))
    assert np.max(np.abs(z - exact)) < 1e-9
    uniform = np.arange(0.0, 3000.0)
    z = first_order_lag(uniform, 10.0 + r * uniform, tau)
    exact = 10.0 + r * uniform - r * tau * (1.0 - np.exp(-uniform / tau))
    assert np.max(np.abs(z - exact)) < 1e-9
    assert np.array_equal(first_order_lag(uniform, uniform, 0.0), uniform)


def test_the_lag_is_recovered_within_its_sigma_over_seeds() -> None:
    pulls = []
    for seed in range(8):
        run, truth = _run(seed, quant_c=0.0625)
        m = HystModel(order=2).fit([run])
        assert m.tau_stderr_ is not None and 0.1 < m.tau_stderr_ < 2.0
        pulls.append((m.tau_ - truth["lag_s"]) / m.tau_stderr_)
    pulls_a = np.array(pulls)
    assert np.all(np.abs(pulls_a) < 3.0), pulls
    assert 0.3 < math.sqrt(np.mean(pulls_a**2)) < 2.0, pulls


def test_fit_on_heating_validate_on_cooling_reaches_the_noise_floor_only_with_the_lag() -> None:
    for seed in (1, 2, 3):
        run, _ = _run(seed, quant_c=0.0625)
        legs = find_legs(run.time_s, run.temps_c[:, 0])
        (heat,), (cool,) = legs.of("heating"), legs.of("cooling")
        fit_on, check_on = _part(run, heat.start, heat.stop), _part(run, cool.start, cool.stop)
        hyst = make_model("hyst", order=2).fit([fit_on])
        poly = make_model("poly", order=3).fit([fit_on])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rms_h = float(np.sqrt(np.mean(hyst.residuals(check_on) ** 2)))
            rms_p = float(np.sqrt(np.mean(poly.residuals(check_on) ** 2)))
        # the lag's own uncertainty from one leg: an offset σ_τ·r·slope (r 1/60 °C/s, ≤ 2 °/h/°C)
        allowance = 3.0 * hyst.tau_stderr_ * (1 / 60.0) * 2.0
        assert rms_h <= math.hypot(NOISE * 1.05, allowance), (seed, rms_h, hyst.tau_)
        assert rms_p > 10 * NOISE, (seed, rms_p)
        both = make_model("hyst", order=2).fit([run])
        res = both.residuals(check_on)
        assert float(np.sqrt(np.mean(res**2))) == pytest.approx(NOISE, rel=0.06)


def test_the_stream_equals_predict_and_the_file_round_trips() -> None:
    run, _ = _run(4, quant_c=0.25)
    m = HystModel(order=3).fit([run])
    batch = m.predict(run)
    s = m.stream(1.0)
    one = np.array([s.update(float(t), T) for t, T in zip(run.time_s, run.temps_c, strict=True)])
    assert np.max(np.abs(one - batch)) <= 1e-12 * np.max(np.abs(batch))
    back = model_from_dict(m.to_dict())
    assert isinstance(back, HystModel) and back.tau_ == m.tau_
    assert np.array_equal(back.predict(run), batch)
    names = [c.name for c in m.coefficients()]
    assert names == ["tau", "a0", "a1", "a2", "a3"]


def test_a_fixed_lag_and_the_refusals() -> None:
    run, _ = _run(5)
    fixed = make_model("hyst", order=2, tau_s=300.0).fit([run])
    assert fixed.tau_ == 300.0 and fixed.tau_stderr_ is None and not fixed.tau_fitted_
    zero = make_model("hyst", order=2, tau_s=0.0).fit([run])
    assert zero.stats_.rms_residual > 5 * fixed.stats_.rms_residual
    flat = RunData(np.arange(100.0), np.full((100, 1), 25.0), np.zeros(100), ("T1",))
    with pytest.raises(DesignError, match="does not change"):
        HystModel().fit([flat])
    with pytest.raises(ParameterError, match="tau_max_s"):
        HystModel.from_options({"tau_max_s": 0.0})
    d = fixed.to_dict()
    d["state"]["coefficients"] = d["state"]["coefficients"][:-1]
    with pytest.raises(ModelFileError, match="coefficients"):
        HystModel.check_state(d)
