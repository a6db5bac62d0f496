"""The stuck-column check of the stability analysis (:func:`thermocal.stability.analysis.
check_not_stuck`): a constant column refused (NaN and infinities aside), one of at most
three distinct values warned naming them, counted here by a Python set; a column with more
values passes silently, whether the fourth comes in the first 100 000 samples or after.
"""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest

from thermocal.errors import ConditioningWarning, ThermocalInputError
from thermocal.stability.analysis import check_not_stuck


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_constant_with_a_bad_sample_is_refused(bad: float) -> None:
    v = np.full(1000, 2.5)
    v[7] = bad
    with pytest.raises(ThermocalInputError, match=r"constant \(2\.5 in all 999 samples\)"):
        check_not_stuck(v, "gx", "f.csv")


@pytest.mark.parametrize("n", [5000, 250_000])
def test_three_levels_warned_with_their_values(n: int) -> None:
    rng = np.random.default_rng(1)
    v = rng.choice([0.51, 0.5, -0.25], n)
    v[3] = np.nan
    want = sorted({float(x) for x in v if np.isfinite(x)})
    assert len(want) == 3
    with pytest.warns(ConditioningWarning) as got:
        check_not_stuck(v, "gx", "f.csv")
    (w,) = got
    text = str(w.message)
    assert f"takes only 3 distinct values in {n - 1} samples" in text
    assert "(" + ", ".join(f"{x:.6g}" for x in want) + ")" in text


@pytest.mark.parametrize("where", [10, 150_000])
def test_a_fourth_level_passes_silently(where: int) -> None:
    v = np.tile([1.0, 2.0, 3.0], 100_000)
    v[where] = 4.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_not_stuck(v, "gx", "f.csv")


def test_noise_passes_without_numpy_ma() -> None:
    """The check on a noise record imports no masked-array module (np.unique would: 6 to
    13 ms of a command's start), in a fresh interpreter.  numpy < 2 imports ``numpy.ma``
    with itself (the floor check's 1.26): there the check can add nothing, and is skipped."""
    code = (
        "import sys, numpy as np\n"
        "print('numpy.ma' in sys.modules)\n"
        "from thermocal.stability.analysis import check_not_stuck\n"
        "check_not_stuck(np.random.default_rng(2).normal(size=200_000), 'gx', 'f.csv')\n"
        "print('numpy.ma' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    with_numpy, after = out.stdout.split()
    if with_numpy == "True":
        pytest.skip("this numpy imports numpy.ma with itself")
    assert after == "False"
