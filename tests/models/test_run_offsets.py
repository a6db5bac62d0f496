"""Per-run offsets only where the runs overlap in temperature (issue 13 item 5).

Two runs recorded at separate temperatures, each with a slow turn-on drift (as real MEMS
gyros have): with a free offset per run the offsets absorb the difference between the
runs and the slope comes from within-run variation, which the drift dominates. On a real
BMI270 pair that gave 449 °/h/°C instead of 69. The data are written here as two CSV
files, the truth is the formula below.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.errors import ConditioningWarning
from thermocal.models import RunData
from thermocal.models.fitting import decide_run_offsets, run_overlap_groups

SLOPE = 69.0  # °/h/°C, the truth
DRIFT = -150.0  # °/h, turn-on drift amplitude, settling with a 20 min time constant


def _run_csv(path: Path, t_start: float, t_end: float, seed: int, hours: float = 1.0) -> None:
    """A 1 Hz run whose temperature rises from t_start to t_end [°C] while the bias
    settles: bias = 69 (T − 25) + DRIFT·(1 − exp(−t/1200 s)) + 2 °/h white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 1.0)
    temp = t_start + (t_end - t_start) * (1.0 - np.exp(-t / 900.0))
    gyro = SLOPE * (temp - 25.0) + DRIFT * (1.0 - np.exp(-t / 1200.0))
    gyro += 2.0 * rng.standard_normal(t.size)
    pd.DataFrame({"time_s": t, "gyro_dph": gyro, "T1": temp}).to_csv(path, index=False)


def _fit(tmp_path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> tuple[dict, str]:
    out = tmp_path / "m.json"
    code = main(
        [
            "fit", str(tmp_path / "a.csv"), str(tmp_path / "b.csv"), "--model", "poly",
            "--order", "1", "--signal", "gyro_dph", "--signal-unit", "deg/h", "--temps", "T1",
            "--temp-unit", "degC", "--time-unit", "s", "-o", str(out), *extra,
        ]
    )  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out.read_text()), err


def _slope(model: dict) -> float:
    return next(c["value"] for c in model["coefficients"] if c["name"] == "T1")


def test_separate_runs_are_pooled_with_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _run_csv(tmp_path / "a.csv", 20.0, 24.0, seed=1)
    _run_csv(tmp_path / "b.csv", 40.0, 44.0, seed=2)
    model, err = _fit(tmp_path, capsys)
    assert "do not overlap in temperature" in err
    assert "pooled" in err
    decision = model["fit"]["offset_decision"]
    assert decision["used"] is False and decision["connected"] is False
    # pooled: the slope comes from the 20 °C step between the runs; the drift (−150 °/h
    # in both runs) adds about the same to each, so the slope is near the truth
    assert _slope(model) == pytest.approx(SLOPE, rel=0.15)


def test_forced_offsets_on_separate_runs_warn_and_show_the_bias(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--per-run-offset forces the old behaviour: the slope is then the within-run one,
    contaminated by the drift (far from 69), and a warning says to distrust it."""
    _run_csv(tmp_path / "a.csv", 20.0, 24.0, seed=1)
    _run_csv(tmp_path / "b.csv", 40.0, 44.0, seed=2)
    model, err = _fit(tmp_path, capsys, "--per-run-offset")
    assert "distrust the slope" in err
    assert model["fit"]["offset_decision"]["used"] is True
    # within a run, T and the drift follow nearly the same exponential: the slope soaks up
    # DRIFT / 4 °C ≈ −37.5 °/h/°C of it
    assert abs(_slope(model) - SLOPE) > 15.0


def test_overlapping_runs_keep_their_offsets(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Runs sharing temperatures: offsets estimated, no warning, the offsets' difference
    recovered (run b written 30 °/h higher)."""
    rng = np.random.default_rng(4)
    for name, t0, t1, shift in (("a", 20.0, 40.0, 0.0), ("b", 25.0, 45.0, 30.0)):
        t = np.arange(0.0, 7200.0, 1.0)
        temp = t0 + (t1 - t0) * t / t[-1]
        gyro = SLOPE * (temp - 25.0) + shift + 2.0 * rng.standard_normal(t.size)
        pd.DataFrame({"time_s": t, "gyro_dph": gyro, "T1": temp}).to_csv(
            tmp_path / f"{name}.csv", index=False
        )
    model, err = _fit(tmp_path, capsys)
    assert "overlap" not in err
    extra = model["fit"]
    assert extra["offset_decision"]["used"] is True
    off = extra["per_run_offsets"]
    assert off[1] - off[0] == pytest.approx(30.0, abs=0.5)
    assert _slope(model) == pytest.approx(SLOPE, rel=0.01)


@pytest.mark.parametrize(
    ("ranges", "groups"),
    [
        ([(20, 25), (40, 45)], [[0], [1]]),
        ([(20, 30), (25, 35)], [[0, 1]]),  # 5 of 10 °C shared: exactly half
        ([(20, 30), (28, 38)], [[0], [1]]),  # 2 of 10 °C: too little
        ([(20, 30), (25, 25)], [[0, 1]]),  # a hold inside the other run's range
        ([(20, 30), (29, 40), (39, 50)], [[0], [1], [2]]),
        ([(20, 30), (25, 35), (60, 70), (62, 71)], [[0, 1], [2, 3]]),
        ([(20, 30), (25, 35), (30, 40)], [[0, 1, 2]]),  # linked through the middle run
    ],
)
def test_overlap_groups(ranges: list[tuple[float, float]], groups: list[list[int]]) -> None:
    got = run_overlap_groups([(float(a), float(b)) for a, b in ranges])
    assert got == groups


def test_one_run_and_explicit_false_never_warn() -> None:
    t = np.arange(100.0)
    runs = [
        RunData(t, (20.0 + 0.01 * t)[:, None], t, ("T1",), "a"),
        RunData(t, (60.0 + 0.01 * t)[:, None], t, ("T1",), "b"),
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConditioningWarning)
        assert decide_run_offsets(None, runs[:1], "poly").used is False
        assert decide_run_offsets(False, runs, "poly").used is False
    with pytest.warns(ConditioningWarning, match="2 groups"):
        assert decide_run_offsets(None, runs, "poly").used is False
