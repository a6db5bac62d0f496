"""``allan --bias-correct``: totdev and htotdev carry Stable32's bias factors.

References from outside thermocal: Stable32 1.60's printed (bias-corrected) values, and the
uncorrected deviations of the same record computed by allantools 2024.06 (``totdev``,
``htotdev``).  The Sr87 clock record (1253 phase points, τ0 = 2.5 s) is in the allantoolkit
project's test assets (GPL-3.0); only figures are quoted here.  PHASE.DAT's bias-corrected
Htot run is in tests/data (allantools' test data, LGPL-3.0)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stable32_phasedat import allan_refuses, phase_csv, rows, run_allan
from thermocal.stability.family import stable32_bias

# (deviation, m, α Stable32 identified, allantools' uncorrected value, Stable32's printed value)
SR87 = [
    ("totdev", 1, -1, 9.0286465707e-17, 9.0304e-17),
    ("totdev", 2, -2, 8.8876982664e-17, 8.8930e-17),
    ("totdev", 4, -1, 1.0514616765e-16, 1.0523e-16),
    ("totdev", 200, -1, 2.4272198096e-17, 2.5261e-17),
    ("totdev", 400, -1, 1.8853443927e-17, 2.0492e-17),
    ("htotdev", 2, -2, 6.8510776640e-17, 7.8025e-17),
    ("htotdev", 4, -1, 8.4269544400e-17, 9.1349e-17),
    ("htotdev", 200, -1, 2.6106826396e-17, 2.8300e-17),
    ("htotdev", 400, -1, 1.4033795561e-17, 1.5213e-17),
]


@pytest.mark.parametrize(("name", "m", "alpha", "raw", "printed"), SR87)
def test_bias_factor_gives_stable32s_value_on_sr87(
    name: str, m: int, alpha: int, raw: float, printed: float
) -> None:
    assert raw * stable32_bias(name, alpha, m, 1253) == pytest.approx(printed, rel=1e-4, abs=0)


def test_no_correction_where_stable32_makes_none() -> None:
    assert stable32_bias("totdev", 0, 100, 1001) == 1.0  # white FM: unbiased
    assert stable32_bias("htotdev", 0, 1, 1001) == 1.0  # m = 1: the overlapping Hadamard
    assert stable32_bias("htotdev", 1, 128, 1001) == 1.0  # phase noise
    assert stable32_bias("mtotdev", -2, 64, 1001) == 1.0


def test_htotdev_bias_corrected_equals_stable32_on_phasedat(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Rows m = 1–64 (Stable32's α = 0 there, as thermocal's): values to 1e-4 (÷√0.995 from
    m = 2) and bounds to 2e-3 (Stable32's Htot EDF: the simple EDF + 2 below m = 16)."""
    r = rows("phase_dat_htotdev_octave.txt", commented=True)[:7]
    obj = run_allan(capsys, phase_csv(tmp_path), "htotdev", r[:, 1], "--bias-correct")
    np.testing.assert_array_equal(obj["htotdev_alpha"], r[:, 3].astype(int))
    np.testing.assert_allclose(obj["htotdev"], r[:, 5], rtol=1e-4)
    np.testing.assert_allclose(obj["htotdev_low"], r[:, 4], rtol=2e-3)
    np.testing.assert_allclose(obj["htotdev_high"], r[:, 6], rtol=2e-3)
    assert obj["htotdev_bias_factor"][0] == 1.0
    assert obj["htotdev_bias_factor"][1] == pytest.approx(1 / np.sqrt(0.995), rel=1e-12)


def test_bias_correct_without_the_family_is_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    err = allan_refuses(tmp_path, capsys, "--bias-correct")
    assert "--bias-correct" in err and "--deviation" in err
