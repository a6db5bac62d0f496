"""One scan of the time column (issue 17): the interval, duplicates, backward steps and gaps
it finds are what direct numpy computations find, on regular, jittered, gapped and broken
grids; a recording scans its time once for validation, gaps, segments and the interval."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal import recording as rmod
from thermocal.recording import Recording, find_gaps, scan_time


def _reference(t: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    dt = np.diff(t)
    return float(np.median(dt)), np.flatnonzero(dt == 0), np.flatnonzero(dt < 0)


@pytest.mark.parametrize("t0", [0.0, 1.7e9])  # seconds from zero, and a Unix epoch
@pytest.mark.parametrize("step", [0.01, 1.0 / 400.0, 1.0])
def test_regular_grid_interval_is_the_median_to_the_stamps_rounding(t0: float, step: float) -> None:
    t = t0 + np.arange(300_001) * step  # several blocks of the scan
    sc = scan_time(t)
    med, _dup, _back = _reference(t)
    assert sc.regular
    ulp = np.spacing(abs(t[-1]))
    assert abs(sc.interval_s - med) <= rmod.REGULAR_GRID_ULPS * ulp
    assert sc.interval_s == pytest.approx(step, rel=1e-9 if t0 == 0 else 1e-6)


def test_jittered_grid_uses_the_exact_median() -> None:
    rng = np.random.default_rng(4)
    t = np.cumsum(0.01 + 1e-4 * rng.standard_normal(500_000))
    sc = scan_time(t)
    assert not sc.regular
    assert sc.interval_s == np.median(np.diff(t))


def test_duplicates_backward_steps_and_gaps_match_numpy() -> None:
    t = np.cumsum(np.full(600_000, 0.01))
    t[[1000, 400_000]] = t[[999, 399_999]]  # duplicates
    t[300_000] = t[299_998]  # a backward step
    t[500_000:] += 3.0  # a gap
    sc = scan_time(t)
    med, dup, back = _reference(t)
    assert sc.interval_s == med
    assert np.array_equal(sc.duplicate_rows, dup)
    assert np.array_equal(sc.backward_rows, back)
    dt = np.diff(t)
    assert [g.index for g in find_gaps(t)] == list(np.flatnonzero(dt > 1.5 * med))


def test_non_finite_or_short_time() -> None:
    assert not scan_time(np.array([0.0, np.nan, 2.0])).finite
    assert np.isnan(scan_time(np.array([1.0])).interval_s)


def test_a_recording_scans_its_time_once(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[int] = []
    real = rmod.scan_time

    def counting(t: np.ndarray) -> rmod.TimeScan:
        calls.append(t.size)
        return real(t)

    monkeypatch.setattr(rmod, "scan_time", counting)
    t = np.arange(10_000) * 0.1
    t[5000:] += 10.0
    rec = Recording.from_arrays(t, {"g": np.ones(t.size)}, {"T": np.linspace(20.0, 30.0, t.size)})
    rec.validate()
    assert len(rec.gaps()) == 1 and len(rec.segments()) == 2
    assert rec.sample_interval_s == pytest.approx(0.1)
    assert calls == [10_000]
    part = rec.select(slice(0, 5000))  # a new time array: scanned anew
    assert part.gaps() == [] and calls == [10_000, 5000]


def test_extreme_stamps_raise_no_warning() -> None:
    """Stamps at the edge of float64 (a corrupt file): no overflow in the regularity test
    (found by the malformed-Parquet property test)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sc = scan_time(np.array([0.0, 0.0, 1.7976931348623157e308]))
    assert sc.duplicate_rows.tolist() == [0] and not sc.regular
