"""Allan noise-model fit quality (issue 13 item 9): a fit that does not describe the curve
is flagged, its terms marked doubtful with the reason, and the CLI warns.

Data made here: white noise (ARW) plus a random walk (RRW) — the model holds — and the
same white noise plus a 500 s sinusoid, which puts a bump in the Allan deviation at
τ ≈ 0.37·500 s that σ² = Σ C_p τ^p cannot follow.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.stability.allan import fit_quality, noise_terms, overlapping_adev


def _white_rw(seed: int, n: int = 200_000) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return 0.5 * rng.standard_normal(n) + 0.002 * np.cumsum(rng.standard_normal(n))


def _sine(seed: int, n: int = 200_000) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.1
    return 0.5 * rng.standard_normal(n) + 0.2 * np.sin(2 * np.pi * t / 500.0)


@pytest.mark.parametrize("seed", range(8))
def test_model_that_holds_is_good(seed: int) -> None:
    res = overlapping_adev(_white_rw(seed), 0.1, "octave", unit="deg/h")
    nt = noise_terms(res)
    assert nt.quality is not None
    assert nt.quality.quality == "good", nt.quality.reason
    assert nt.quality.reduced_chi2 < 2.0
    arw = nt.fit.angle_random_walk
    # white rate noise of σ = 0.5 °/h at τ0 = 0.1 s: N = σ √τ0 = 0.158 °/h·√s
    # = 0.158/60 °/√h = 2.64e-3 °/√h
    assert arw.quality is None and arw.value == pytest.approx(0.5 * np.sqrt(0.1) / 60, rel=0.05)


@pytest.mark.parametrize("seed", range(4))
def test_periodic_term_is_flagged_poor_with_the_tau_region(seed: int) -> None:
    res = overlapping_adev(_sine(seed), 0.1, "octave", unit="deg/h")
    nt = noise_terms(res)
    assert nt.quality is not None and nt.quality.quality == "poor"
    assert nt.quality.reduced_chi2 > 10
    assert nt.quality.misfits, nt.quality.reason
    m = nt.quality.misfits[0]
    assert m["tau_from_s"] < m["tau_to_s"]
    assert "does not describe this curve" in (nt.quality.reason or "")
    for term in nt.fit.terms().values():
        if term.value is not None:
            assert term.quality == "poor" and term.reason == nt.quality.reason


def test_fit_quality_runs_and_chi2_written_out() -> None:
    tau = np.array([1.0, 2, 4, 8, 16, 32, 64, 128])
    # four points in a row more than 1.5 σ above: a misfit stretch from 8 to 64 s
    r = np.array([0.1, -0.3, 0.2, 2.0, 2.5, 1.8, 3.0, -0.2])
    q = fit_quality(tau, r, n_active=2)
    assert q.misfits == ({"tau_from_s": 8.0, "tau_to_s": 64.0, "side": "above",
                          "mean_sigma": pytest.approx(2.325)},)  # fmt: skip
    assert q.reduced_chi2 == pytest.approx(float(r @ r) / 6)
    assert q.quality == "poor"
    # three in a row is not a stretch, and χ²/dof = 1.6 is not poor
    r2 = np.array([0.1, -0.3, 0.2, 2.0, 2.5, 1.8, -0.5, -0.2])
    assert fit_quality(tau, r2, 2).quality == "good"


def test_cli_warns_and_json_carries_the_quality(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    n = 100_000
    pd.DataFrame({"time": np.arange(n) * 0.1, "gyro": _sine(1, n)}).to_csv(
        tmp_path / "s.csv", index=False
    )
    args = ["allan", str(tmp_path / "s.csv"), "--signal", "gyro", "--signal-unit", "deg/h",
            "--time-unit", "s"]  # fmt: skip
    assert main([*args, "--json"]) == 0
    out, err = capsys.readouterr()
    d = json.loads(out)
    assert d["fit_quality"]["quality"] == "poor"
    assert "warning:" in err and "does not describe this curve" in err
    # every term found carries the poor mark (under the honest standard errors scaled by
    # the reduced χ² no fitted term is significant here; the slope line's ARW is found)
    found = [t for key in ("noise", "noise_slope") for t in d[key].values() if t["value"]]
    assert found and all(t["quality"] == "poor" for t in found)
    assert main(args) == 0
    out, _ = capsys.readouterr()
    assert "— poor" in out
