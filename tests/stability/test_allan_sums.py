"""The overlapping Allan variance's sums of squared second differences
(:func:`thermocal.stability.allan.second_difference_sums`, NIST SP 1065 eq. 11) equal the
direct formula written here, Σ (x_{k+2m} − 2x_{k+m} + x_k)² over the whole phase with its
x_0 = 0, for factors taking either form of the blocked loop (a difference of first
differences up to a quarter block, three terms beyond), records of several blocks and
none, a drift and an offset, on one thread and shared between threads.
"""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.stability import allan


def _direct(y: np.ndarray, m: np.ndarray) -> np.ndarray:
    """x_k = Σ_{i<k} (y_i − ȳ) with x_0 = 0, then each factor's sum, whole arrays."""
    x = np.concatenate([[0.0], np.cumsum(y - y.mean())])
    return np.array([np.sum((x[2 * k :] - 2.0 * x[k:-k] + x[: -2 * k]) ** 2) for k in m])


@pytest.mark.parametrize(
    ("n", "drift"), [(9, 0.0), (3 * allan._CHUNK + 17, 0.0), (3 * allan._CHUNK + 17, 2e-4),
                     (allan._THREADED_FROM + 5, 1e-6)],
)  # fmt: skip
def test_sums_equal_the_direct_formula(n: int, drift: float) -> None:
    rng = np.random.default_rng(21)
    y = 40.0 + rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * 1e-2
    y += drift * np.arange(n)
    short = allan._SHORT_M
    cand = [1, 2, 3, short - 1, short, short + 1, allan._CHUNK, allan._CHUNK + 3, (n - 1) // 2]
    m = np.unique(np.array([k for k in cand if 1 <= k <= (n - 1) // 2], dtype=np.int64))
    got = allan.second_difference_sums(allan._phase(y.copy()), m)
    np.testing.assert_allclose(got, _direct(y, m), rtol=1e-12)


def test_sums_of_a_smooth_record_keep_their_digits() -> None:
    """A slowly varying record (a temperature ramp read as a rate): its phase is large
    against its short-m second differences, so the order of the operations decides the
    digits.  The sums equal the same float64 phase's sums taken in extended precision
    (numpy's longdouble, written here) to 1e-12; three taps added at once (main before
    this test) were 1e-9 off here, 1.6e-5 on the 10⁷-row temperature column of
    ``bench_allan_cli.py``'s file."""
    n = 300_000
    k = np.arange(n, dtype=np.float64)
    y = 25.0 + 1e-6 * k + 1e-13 * k**2
    x1 = allan._phase(y.copy())
    m = np.array([1, 2, 4, 16, 256, allan._SHORT_M], dtype=np.int64)
    x = np.concatenate([[0.0], x1]).astype(np.longdouble)
    want = np.array([np.sum((x[2 * j :] - 2 * x[j:-j] + x[: -2 * j]) ** 2) for j in m])
    got = allan.second_difference_sums(x1, m)
    np.testing.assert_allclose(got, want.astype(np.float64), rtol=1e-12)
