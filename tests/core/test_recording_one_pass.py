"""The checks of a recording's columns in one pass over each (issue 41): the time scan's
finiteness, the NaN check and the signal's plausible range from each column's smallest and
largest value, and the timestamp jitter left unmeasured where the scan bounds it, all give
what direct numpy computations written here give, across block boundaries."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from thermocal import recording as rmod
from thermocal.errors import TimestampWarning
from thermocal.recording import Recording, find_problems, scan_time, time_jitter

LIMIT_DEG_S = 1e8 / 3600.0
"""The plausible limit of a gyro, 10⁸ °/h (``PLAUSIBLE_SIGNAL["rate"]``), in °/s."""


@pytest.fixture
def small_blocks(monkeypatch: pytest.MonkeyPatch) -> None:
    """Blocks of a few rows, so that short columns span many of them."""
    monkeypatch.setattr(rmod, "DIFF_BLOCK", 7)
    monkeypatch.setattr(rmod, "RANGE_BLOCK", 5)


@pytest.mark.usefixtures("small_blocks")
@pytest.mark.parametrize(
    "bad", [None, (0, np.nan), (9, np.nan), (40, np.inf), (63, -np.inf), (0, -np.inf)]
)
def test_time_scan_finiteness_and_steps_equal_numpy(bad: tuple[int, float] | None) -> None:
    t = np.arange(64) * 0.5 + 3.0
    t[20] = t[19]  # a duplicate stamp, in the third block
    if bad is not None:
        t[bad[0]] = bad[1]
    sc = scan_time(t)
    finite = bool(np.all(np.isfinite(t)))
    assert sc.finite == finite
    if finite:
        dt = np.diff(t)
        assert (sc.min_step_s, sc.max_step_s) == (dt.min(), dt.max())
        assert sc.duplicate_rows.tolist() == np.flatnonzero(dt == 0).tolist() == [19]
    else:
        assert np.isnan(sc.interval_s)


def test_time_steps_that_overflow_are_scanned_as_before() -> None:
    """Finite stamps whose step overflows (a corrupt file): every stamp is finite, the step
    is infinite (numpy's overflow warning is as before: not this test's)."""
    with np.errstate(over="ignore"):
        sc = scan_time(np.array([-1e308, 1e308, 1.5e308]))
    assert sc.finite
    assert sc.max_step_s == np.inf


@pytest.mark.parametrize("t", [[0.0, np.inf, np.inf], [-1e308, 1e308, np.nan], [np.nan, 1.0]])
def test_stamps_that_are_not_finite_warn_of_no_arithmetic(t: list[float]) -> None:
    """Not finite (said by ``finite``), without a numpy warning of a step computed on the
    way (``inf − inf``, an overflow): the stamps are not differenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sc = scan_time(np.array(t))
    assert not sc.finite


def _signal_rec(values: np.ndarray, unit: str) -> Recording:
    t = np.arange(values.size) * 0.01
    return Recording.from_arrays(t, {"g": values}, {}, signal_unit=unit)


@pytest.mark.usefixtures("small_blocks")
@pytest.mark.parametrize("row", [0, 4, 5, 22, 49])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_the_first_value_beyond_any_gyro_is_named(row: int, sign: float) -> None:
    values = np.linspace(-100.0, 100.0, 50)
    values[[row, 30]] = sign * np.nextafter(LIMIT_DEG_S, np.inf) * 1.001
    probs = [p for p in find_problems(_signal_rec(values, "deg/s")) if p.kind.startswith("impl")]
    first = int(np.flatnonzero(np.abs(values * 3600.0) > 1e8)[0])  # numpy, not thermocal
    assert [(p.kind, p.row) for p in probs] == [("implausible_signal", first)]


@pytest.mark.usefixtures("small_blocks")
def test_values_up_to_the_limit_are_quiet_and_a_nan_is_counted() -> None:
    values = np.full(23, 10.0)
    values[[3, 17]] = [LIMIT_DEG_S, -LIMIT_DEG_S]  # 10⁸ °/h once converted: allowed
    assert np.all(np.abs(values * 3600.0) <= 1e8)
    assert [p.kind for p in find_problems(_signal_rec(values, "deg/s"))] == []
    values[12] = np.nan
    values[19] = 1e30  # beyond, after the NaN
    probs = find_problems(_signal_rec(values, "deg/s"))
    nan = [p for p in probs if p.kind == "nan"]
    assert [(p.row, p.severity) for p in nan] == [(12, "error")]
    assert "1 NaN/empty/infinite values" in nan[0].message
    assert [p.row for p in probs if p.kind == "implausible_signal"] == [19]


def _relative(t: np.ndarray) -> float:
    """Half the 5–95 % range of the steps over their median (numpy's percentiles)."""
    dt = np.diff(t)
    p5, p95 = np.percentile(dt, [5, 95])
    return float((p95 - p5) / (2 * np.median(dt)))


@pytest.mark.parametrize("spread", [0.0, 0.05, 0.099, 0.1, 0.2, 0.6, 1.0])
def test_jitter_is_skipped_only_where_the_steps_bound_it(spread: float) -> None:
    """Steps uniform in [1, 1 + spread] ms: the scan's bound skips the measurement up to a
    spread of 10 % (the steps' relative jitter then at most 5 %); the warning is given
    exactly when numpy's percentiles put the jitter above 10 %."""
    rng = np.random.default_rng(int(spread * 1000))
    t = np.concatenate([[0.0], np.cumsum(1e-3 * (1.0 + spread * rng.random(5000)))])
    sc = scan_time(t)
    if rmod._jitter_bounded(sc):
        assert spread <= 0.1
        assert _relative(t) <= 0.05
    else:
        assert spread > 0.099
    rec = Recording.from_arrays(t, {"g": np.ones(t.size)}, {}, signal_unit="deg/h")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec.validate()
    warned = [w for w in caught if issubclass(w.category, TimestampWarning)]
    assert len(warned) == (1 if _relative(t) > 0.1 else 0)
    jit = time_jitter(t)
    assert jit is not None and jit.relative == pytest.approx(_relative(t), rel=1e-12)
