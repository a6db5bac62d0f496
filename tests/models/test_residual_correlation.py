"""Standard errors that hold on coloured residuals (issue 13, honest statistics).

References written out here: an AR(1) series x_t = ρ x_{t−1} + w_t has integrated
autocorrelation time τ = (1 + ρ)/(1 − ρ); a straight-line slope fitted on a smooth
temperature with AR(1) errors has a spread across repetitions that the reported standard
error must match (the OLS one is √τ too small).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import signal

from thermocal.cli import main
from thermocal.models import RunData
from thermocal.models.piecewise import PiecewiseModel
from thermocal.models.poly import PolyModel
from thermocal.models.residuals import residual_correlation


def _ar1(rho: float, n: int, rng: np.random.Generator) -> np.ndarray:
    w = rng.standard_normal(n)
    return signal.lfilter([1.0], [1.0, -rho], w)


@pytest.mark.parametrize("rho", [0.5, 0.9, 0.98])
def test_ar1_tau_matches_the_closed_form(rho: float) -> None:
    rng = np.random.default_rng(7)
    x = _ar1(rho, 400_000, rng)
    got = residual_correlation([x])
    expect = (1 + rho) / (1 - rho)
    assert got.tau == pytest.approx(expect, rel=0.1)
    assert got.n_eff == pytest.approx(400_000 / expect, rel=0.1)
    assert got.lag1 == pytest.approx(rho, abs=0.01)
    assert got.converged


def test_white_noise_keeps_the_ols_errors_exactly() -> None:
    for seed in range(10):
        x = np.random.default_rng(seed).standard_normal(5000)
        assert residual_correlation([x]).tau == 1.0


def test_runs_are_not_joined_and_exact_fits_are_white() -> None:
    rng = np.random.default_rng(1)
    # two white runs with very different means: joining them would look like a step
    a, b = rng.standard_normal(3000), 100.0 + rng.standard_normal(3000)
    assert residual_correlation([a, b]).tau == 1.0
    assert residual_correlation([np.concatenate([a, b])]).tau > 100.0
    tiny = 1e-14 * np.sin(np.arange(3000) / 50.0)  # rounding-level structured residue
    assert residual_correlation([tiny], data_rms=1.0).tau == 1.0


@pytest.mark.parametrize("model", ["poly", "piecewise"])
def test_reported_slope_error_matches_its_spread_on_ar1_residuals(model: str) -> None:
    """200 records of 4000 samples, T a slow ramp, error AR(1) with ρ = 0.95 (τ = 39):
    the reported standard error of the slope is within 30 % of the slope's spread over
    the records; OLS alone would report √39 ≈ 6× too little."""
    rng = np.random.default_rng(11)
    n, rho, slope = 4000, 0.95, 0.8
    t = np.arange(float(n))
    temp = 20.0 + 20.0 * np.sin(np.pi * t / n) ** 2 + 5.0 * t / n  # smooth, not monotonic
    got, reported, taus = [], [], []
    for _ in range(200):
        y = slope * temp + _ar1(rho, n, rng)
        run = RunData(t, temp[:, None], y, ("T1",), "r")
        if model == "poly":
            m = PolyModel(order=1, per_run_offset=False).fit([run])
            c = next(c for c in m.coefficients() if c.name == "T1")
        else:
            m = PiecewiseModel(breakpoints=[30.0], method="continuous").fit([run])
            c = next(c for c in m.coefficients() if c.name.startswith("slope"))
        got.append(c.value)
        assert c.stderr is not None
        reported.append(c.stderr)
        taus.append(m.stats_.extra["residual_correlation"]["tau_samples"])
    spread = float(np.std(got, ddof=1))
    assert float(np.mean(got)) == pytest.approx(slope, abs=3 * spread / np.sqrt(200))
    assert float(np.median(reported)) == pytest.approx(spread, rel=0.3)
    assert float(np.median(taus)) == pytest.approx((1 + rho) / (1 - rho), rel=0.3)


@pytest.mark.parametrize(
    ("kappa", "words"),
    [
        (1.0, "well conditioned"),
        (999.0, "well conditioned"),
        (4.2e4, "moderately conditioned: about 5 of the data's digits lost"),
        (4.2e6, "ill-conditioned: about 7 of the data's digits lost"),  # issue 13 item 9
        (3e12, "near singular: about 12 of the data's digits lost"),
        (None, "condition unknown"),
    ],
)
def test_condition_wording_matches_the_number(kappa: float | None, words: str) -> None:
    from thermocal.models.results import condition_wording

    assert condition_wording(kappa) == words


def test_fit_prints_effective_samples_and_flags_weak_coefficients(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Through the CLI: a CSV with AR(1) errors (ρ = 0.995, τ ≈ 399, 15 effective
    samples) — the fit warns that few effective samples remain, prints them, and its JSON
    carries τ and the wording."""
    rng = np.random.default_rng(3)
    n = 6000
    t = np.arange(float(n))
    temp = 20.0 + 10.0 * np.sin(2 * np.pi * t / n)
    y = 0.5 * temp + _ar1(0.995, n, rng)
    pd.DataFrame({"time": t, "gyro": y, "T1": temp}).to_csv(tmp_path / "r.csv", index=False)
    args = ["fit", str(tmp_path / "r.csv"), "--model", "poly", "--order", "1", "--signal",
            "gyro", "--signal-unit", "deg/h", "--temps", "T1", "--temp-unit", "degC",
            "--time-unit", "s", "-o", str(tmp_path / "m.json")]  # fmt: skip
    assert main(args) == 0
    out, err = capsys.readouterr()
    assert "effective samples" in out
    assert "strongly autocorrelated" in err
    assert main([*args, "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    corr = res["fit"]["residual_correlation"]
    assert corr["tau_samples"] == pytest.approx(399.0, rel=0.5)
    assert res["condition"] == "well conditioned"
