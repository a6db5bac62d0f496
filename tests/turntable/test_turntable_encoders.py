"""Turntable runs with real encoders (issue 12 §2): jitter of 0.1″–5″ at 10–200 Hz and
readings quantised to 0.001° give the same 16 dwells and the same estimates.

The noisy encoder columns are made here, in the test, from a clean simulated run (numpy
jitter and rounding), not by the simulator's own noise code."""

from __future__ import annotations

import json
import warnings
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.recording import Recording
from thermocal.turntable.calibration import TurntableResult, calibrate
from thermocal.turntable.model import coeffs_from_error_matrix
from thermocal.turntable.schedule import detect_motion
from thermocal.turntable.simulate import simulate_turntable16

DWELL_S = 20.0
"""Short dwells keep the test fast; calibrate is told to accept them."""


@cache
def _clean(rate_hz: float) -> tuple[Recording, dict[str, object]]:
    # start angles and move rate off any round grid, as on a real table
    return simulate_turntable16(
        3,
        rate_hz=rate_hz,
        dwell_s=DWELL_S,
        arw_deg_sqrt_h=0.003,
        alpha0_deg=12.3456789,
        beta0_deg=-7.654321,
        move_rate_deg_s=9.87654,
    )


def _noisy(
    rate_hz: float, jitter_arcsec: float, quantum_deg: float = 0.0, seed: int = 0
) -> Recording:
    """The clean run with encoder readings jittered and/or quantised, done here."""
    rec, _ = _clean(rate_hz)
    rng = np.random.default_rng(seed)
    cols = dict(rec.columns)
    for c in ("alpha_deg", "beta_deg"):
        x = cols[c] + rng.normal(0.0, jitter_arcsec / 3600.0, cols[c].size)
        if quantum_deg:
            x = np.round(x / quantum_deg) * quantum_deg
        cols[c] = np.mod(x, 360.0)
    return Recording(
        time_s=rec.time_s,
        columns=cols,
        units=dict(rec.units),
        signals=rec.signals,
        temperatures=rec.temperatures,
        meta=rec.meta,
    )


def _calibrate(rec: Recording) -> TurntableResult:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate(rec, 40.0, min_dwell_s=DWELL_S - 1.0)


def _dwells(rec: Recording) -> list[tuple[int, int]]:
    a = np.unwrap(rec.column("alpha_deg"), period=360.0)
    b = np.unwrap(rec.column("beta_deg"), period=360.0)
    moving = detect_motion(rec.time_s, a, b).moving
    m = np.concatenate([[True], moving, [True]])
    d = np.diff((~m).astype(np.int8))
    starts, stops = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    return [
        (int(s), int(e)) for s, e in zip(starts, stops, strict=True) if e - s > rec.n_samples / 200
    ]


CASES = [(10.0, 0.1), (10.0, 5.0), (100.0, 1.0), (100.0, 5.0), (200.0, 0.1), (200.0, 5.0)]


@pytest.mark.parametrize(("rate_hz", "jitter"), CASES)
def test_same_sixteen_dwells_with_jitter(rate_hz: float, jitter: float) -> None:
    clean = _dwells(_clean(rate_hz)[0])
    noisy = _dwells(_noisy(rate_hz, jitter))
    assert len(clean) == 16
    assert len(noisy) == 16
    # boundaries agree within 2 samples
    assert np.max(np.abs(np.array(clean) - np.array(noisy))) <= 2


@pytest.mark.parametrize(("rate_hz", "jitter"), [(10.0, 5.0), (100.0, 5.0), (200.0, 1.0)])
def test_estimates_unchanged_within_sigma(rate_hz: float, jitter: float) -> None:
    rec, truth = _clean(rate_hz)
    ref = _calibrate(rec)
    res = _calibrate(_noisy(rate_hz, jitter))
    th_true = coeffs_from_error_matrix(truth["error_matrix"], truth["bias_deg_h"])  # type: ignore[arg-type]
    assert res.n_positions == 16 and res.n_dwells == 16
    for est in (res.kalman, res.least_squares):
        assert np.max(np.abs(est.theta - th_true) / est.sigma) < 4.0
    assert np.max(np.abs(res.kalman.theta - ref.kalman.theta) / res.kalman.sigma) < 2.0
    assert res.agreement < 0.5  # filter and least squares agree
    # the jitter is estimated from the dwells and used as the reading noise
    assert res.encoder_noise_source == "dwells"
    assert res.encoder_jitter_arcsec == pytest.approx(jitter, rel=0.3)
    assert res.encoder_noise_arcsec == pytest.approx(jitter, rel=0.3)


def test_filter_innovations_are_consistent_with_the_encoder_noise() -> None:
    """With 5″ of jitter, the filter's normalised innovations have rms ≈ 1 only when its
    innovation variance includes the measurement noise R (kalman.run_filter)."""
    res = _calibrate(_noisy(100.0, 5.0))
    assert 0.8 < res.normalised_innovation_rms < 1.25


def test_quantised_readings() -> None:
    """Readings on a 0.001° grid, no jitter: the grid is found, the reading σ is q/√12,
    the dwells and the estimates are those of the clean run."""
    rate_hz = 100.0
    rec, truth = _clean(rate_hz)
    q = _noisy(rate_hz, 0.0, quantum_deg=0.001)
    clean, quantised = np.array(_dwells(rec)), np.array(_dwells(q))
    assert clean.shape == quantised.shape == (16, 2)
    assert np.max(np.abs(clean - quantised)) <= 2
    res = _calibrate(q)
    assert res.encoder_quantum_deg == pytest.approx(0.001, rel=1e-6)
    assert res.encoder_noise_arcsec == pytest.approx(3.6 / np.sqrt(12.0), rel=1e-6)
    th_true = coeffs_from_error_matrix(truth["error_matrix"], truth["bias_deg_h"])  # type: ignore[arg-type]
    assert np.max(np.abs(res.kalman.theta - th_true) / res.kalman.sigma) < 4.0
    assert res.agreement < 0.5


def test_cli_on_a_noisy_quantised_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = _noisy(100.0, 2.0, quantum_deg=0.0001, seed=5)
    import pandas as pd

    f = tmp_path / "tt.csv"
    pd.DataFrame({"time": rec.time_s, **rec.columns}).to_csv(f, index=False)
    out = tmp_path / "r.json"
    code = main(["turntable", str(f), "-o", str(out), "--latitude", "40", "--min-dwell", "19",
                 "--json"])  # fmt: skip
    stdout, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(stdout)
    assert d["n_dwells"] == 16
    assert d["encoder_noise_source"] == "dwells"
    assert d["encoder_jitter_arcsec"] == pytest.approx(2.0, rel=0.3)
