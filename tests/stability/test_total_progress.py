"""The total family's progress through the library's callback: fractions of the estimated
operations that rise to 1.0 (a determinate bar), per channel and over several channels."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from thermocal.recording import Recording
from thermocal.stability import deviations as dv
from thermocal.stability import total
from thermocal.stability.analysis import allan_analysis
from thermocal.stability.family import stability


def _fractions(names: list[str], n: int = 6000) -> list[float]:
    seen: list[float] = []
    y = np.random.default_rng(3).standard_normal(n)
    stability(y, 0.1, names, "octave", progress=seen.append)
    return seen


@pytest.mark.parametrize(
    "names", [["mtotdev", "ttotdev", "htotdev"], ["htotdev"], ["oadev", "mtotdev"]]
)
def test_total_family_fractions_rise_to_one(names: list[str]) -> None:
    seen = _fractions(names)
    assert seen[-1] == 1.0
    assert all(b >= a for a, b in itertools.pairwise(seen))
    assert all(0.0 < f <= 1.0 for f in seen)
    # the bar moves while the sums run (factors above the direct ones report row by row) …
    assert len({round(f, 3) for f in seen if f < 1.0}) >= 5
    # … and the sums' own reports reach 1.0 before the closing call (an estimate too large
    # stops short of it and jumps at the end)
    assert seen.count(1.0) == 2


@pytest.mark.parametrize("names", [["mtotdev", "ttotdev", "htotdev"], ["htotdev"]])
def test_the_estimate_is_what_the_sums_report(names: list[str]) -> None:
    """The fractions' whole, :func:`.deviations.work` of each total deviation at its
    factors (htotdev's m = 1 is ohdev's, not the total sums'), equals the operations the sums
    report (an estimate too small saturates the bar early)."""
    n = 6000
    y = np.random.default_rng(3).standard_normal(n)
    got: list[float] = []
    total._CACHE.clear()
    with total.reporting(got.append):
        res = stability(y, 0.1, names, "octave")
    whole = 0.0
    for name in names:
        m = res.curves[name].m
        m = m[m > 1] if name == "htotdev" else m
        whole += dv.work(name, n + 1, m)  # rate data: N + 1 phase points
    assert sum(got) == pytest.approx(whole, rel=1e-9)


def test_no_total_deviation_reports_only_the_end() -> None:
    assert _fractions(["oadev", "mdev"]) == [1.0]


def test_several_channels_share_the_bar() -> None:
    rng = np.random.default_rng(4)
    n = 5000
    rec = Recording.from_arrays(
        np.arange(n) * 0.1, {"a": rng.standard_normal(n), "b": rng.standard_normal(n)}
    )
    seen: list[float] = []
    allan_analysis(rec, ["a", "b"], deviations=["mtotdev"], progress=seen.append)
    assert seen[-1] == 1.0
    assert all(b >= a for a, b in itertools.pairwise(seen))
    assert any(0.1 < f < 0.5 for f in seen) and any(0.5 < f < 1.0 for f in seen)
    assert 0.5 in seen  # the first channel's end


def test_reporting_gives_operations() -> None:
    """:func:`total.reporting` (the operations form the fractions are made of) still sums to
    the estimate of :func:`total.cost`."""
    z = np.cumsum(np.random.default_rng(5).standard_normal(4000))
    got: list[float] = []
    ms = [1, 2, 8, 64]
    total._CACHE.clear()
    with total.reporting(got.append):
        total.tot_sums(z, ms)
    assert sum(got) == pytest.approx(sum(total.cost(z.size, m) for m in ms), rel=1e-9)
