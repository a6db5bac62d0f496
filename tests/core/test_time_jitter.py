"""recording.time_jitter's statistics from one partition: equal to the bit to numpy's
median and linear percentiles (the reference, outside the code under test), and the jitter
of a uniform ±30 % latency read as 0.27."""

import numpy as np
import pytest

from thermocal.recording import JITTER_RELATIVE, _median_p5_p95, time_jitter


@pytest.mark.parametrize("kind", ["normal", "rounded", "three-levels", "uniform", "cauchy"])
def test_median_and_percentiles_equal_numpy_to_the_bit(kind: str) -> None:
    rng = np.random.default_rng(7)
    draw = {
        "normal": lambda n: rng.standard_normal(n) * 1e-3 + 0.01,
        "rounded": lambda n: np.round(rng.standard_normal(n) * 1e-3 + 0.01, 4),
        "three-levels": lambda n: rng.integers(0, 3, n) * 0.005,
        "uniform": lambda n: 0.01 + rng.uniform(-0.3, 0.3, n) * 0.01,
        "cauchy": lambda n: np.abs(rng.standard_cauchy(n)),
    }[kind]
    for n in [*range(2, 40), 99, 100, 1001, 4096, 65537]:
        x = draw(n)
        want = (float(np.median(x)), *(float(v) for v in np.percentile(x, [5.0, 95.0])))
        assert _median_p5_p95(x.copy()) == want, n


def test_percentile_at_half_way_interpolates_as_numpy() -> None:
    # n = 11, 31: the 5 and 95 % virtual indices (n − 1)·q fall half-way (γ = ½), where
    # numpy interpolates down from the upper neighbour; from below differs in the last bit.
    rng = np.random.default_rng(11)
    for n in (11, 31, 51):
        for _ in range(300):
            x = rng.uniform(0.0, 1.0, n) * 10.0 ** rng.integers(-6, 3)
            want = tuple(float(v) for v in np.percentile(x, [5.0, 95.0]))
            assert _median_p5_p95(x.copy())[1:] == want, n


def test_uniform_latency_reads_its_5_to_95_range() -> None:
    rng = np.random.default_rng(3)
    n = 1 << 20
    steps = 0.01 * (1.0 + rng.uniform(-0.3, 0.3, n))  # ±30 % around 10 ms
    jit = time_jitter(np.concatenate(([0.0], np.cumsum(steps))))
    assert jit is not None and jit.n_steps == n and jit.n_same == 0
    assert jit.interval_s == pytest.approx(0.01, rel=2e-3)
    assert jit.relative == pytest.approx(0.27, abs=2e-3)  # the 5–95 % range of U(±0.3)
    assert jit.relative > JITTER_RELATIVE


def test_a_regular_grid_and_a_stamped_burst() -> None:
    grid = time_jitter(np.arange(1000) * 0.5)
    assert grid is not None and grid.relative == 0.0 and grid.interval_s == 0.5
    t = np.arange(1000) * 0.5
    t[10] = t[9]  # two samples stamped at the same instant
    burst = time_jitter(t)
    assert burst is not None and burst.n_same == 1
    flat = time_jitter(np.zeros(5))
    assert flat is not None and flat.interval_s == 0.0 and flat.relative == np.inf
