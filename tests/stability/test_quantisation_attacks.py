"""Output quantisation (:mod:`thermocal.stability`) on hostile records: no lattice, NaN and
inf, integers at 1e15, the storage precision, a float32 accelerometer."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main


def _run(argv: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(argv)
    return code, o.getvalue(), e.getvalue()


def _lattice(v: np.ndarray) -> Any:
    from thermocal.stability.noise_model import lattice_step

    return lattice_step(v)


def test_quantisation_no_claim_on_records_that_show_no_lattice() -> None:
    rng = np.random.default_rng(8)
    n = 20_000
    assert _lattice(np.full(n, 3.3)) is None  # constant
    assert _lattice(np.where(rng.random(n) < 0.5, 0.0, 0.05)) is None  # two levels
    assert _lattice(np.round(rng.normal(0, 1, 10) / 0.05) * 0.05) is None  # 10 samples
    assert _lattice(rng.normal(0.0, 1.0, n)) is None  # ordinary floating point
    assert _lattice(rng.normal(0.0, 1.0, n) * 1e300) is None


def test_quantisation_ignores_nan_and_inf_and_finds_the_step() -> None:
    rng = np.random.default_rng(9)
    k = np.round(rng.normal(0.0, 1.0, 20_000) / 0.05)
    v = np.r_[k * 0.05, np.nan, np.inf, -np.inf]
    step, offset, levels, n = _lattice(v)
    assert step == pytest.approx(0.05, rel=1e-9)
    assert offset == pytest.approx(k.min() * 0.05)
    assert levels == np.unique(k).size and n == 20_000


def test_quantisation_integers_at_1e15_lie_on_a_step_of_one() -> None:
    """1e15 + 0…9: integers, exactly representable (float64 spacing there is 0.125): the
    lattice is real, its step 1 and its 10 levels."""
    rng = np.random.default_rng(10)
    found = _lattice(1e15 + rng.integers(0, 10, 20_000).astype(np.float64))
    assert found is not None and found[0] == 1.0 and found[2] == 10


def test_quantisation_not_claimed_for_the_storage_precision() -> None:
    """Seen red before the fix: a float64 record at 1e15 lies on float64's own 0.125
    spacing, and a float32 record (a ULog field, a float32 Parquet column) on float32's —
    the storage's rounding, reported as the sensor's output quantisation."""
    rng = np.random.default_rng(11)
    n = 20_000
    assert _lattice(1e15 + rng.normal(0.0, 1.0, n)) is None
    assert _lattice((9.8 + rng.normal(0.0, 1e-5, n)).astype(np.float32).astype(np.float64)) is None
    # a real step stored as float32 is still found (0.05 deg/s, float32-rounded)
    k = np.round(rng.normal(0.0, 1.0, n) / 0.05)
    found = _lattice((k * 0.05).astype(np.float32).astype(np.float64))
    assert found is not None and found[0] == pytest.approx(0.05, rel=1e-6)


def test_allan_on_a_float32_accelerometer_claims_no_quantisation(tmp_path: Path) -> None:
    """A still accelerometer at 9.8 m/s² (0.01 mg noise) stored float32 in Parquet, 100 Hz:
    allan's JSON gives no output quantisation (seen red before the fix: a
    9.5e-7 m/s² "rate quantization step")."""
    rng = np.random.default_rng(12)
    n = 20_000
    t = np.arange(n) * 0.01
    cols = {"time [s]": t}
    for name, g in (("ax", 0.0), ("ay", 0.0), ("az", 9.8)):
        cols[name] = (g + rng.normal(0.0, 1e-4, n)).astype(np.float32)
    pd.DataFrame(cols).to_parquet(tmp_path / "acc.parquet")
    argv = ["allan", str(tmp_path / "acc.parquet"), "--signal", "az", "--signal-unit", "m/s^2"]
    code, out, err = _run([*argv, "--time", "time [s]", "--json"])
    assert code == 0, err
    assert json.loads(out)["output_quantization"] is None
