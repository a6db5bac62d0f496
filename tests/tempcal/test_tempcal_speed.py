"""px4-tempcal's speed work (issue 28, item 4) changes no number: the stillness of a sensor is
computed once, reports built by the worker process are the ones built here (and their
warnings are said), the report's shown figures are figures_of_merit's."""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import thermocal.tempcal.pipeline as pipeline
from fc_sweeps import px4_sweep_log
from thermocal import adequacy
from thermocal.errors import ThermocalWarning
from thermocal.recording import Metadata
from thermocal.report.analysis import figures_of_merit, shown_figures
from thermocal.report.sensor import write_sensor_report
from thermocal.tempcal.px4 import px4_tempcal


def _log(tmp_path: Path, n: int = 6000) -> Path:
    return px4_sweep_log(tmp_path / "s.ulg", n, 0.03, 3)


def test_stillness_is_computed_once_per_sensor(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[int] = []
    real = adequacy._stillness

    def counted(*args: Any, **kwargs: Any) -> adequacy.Motion:
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(adequacy, "_stillness", counted)
    res = px4_tempcal(_log(tmp_path), tmp_path / "out")
    assert len(res.fits) == 2
    # the adequacy judgement and the bump mask share one computation per sensor (was 2)
    assert len(calls) == 2
    # and the result is the one computed afresh
    with adequacy.stillness_remembered():
        t, v = np.arange(100.0), np.zeros((100, 3))
        first = adequacy.stillness(t, v, 1.0)
        assert adequacy.stillness(t, v, 1.0) is first
        assert adequacy.stillness(t, v.copy(), 1.0) is not first  # identity, not equality


def _warning_reporter(path: Path, request: Any) -> None:
    """A reporter that says something (module level: sent to the worker by reference)."""
    warnings.warn(ThermocalWarning(f"report {path.name} says hello"), stacklevel=1)
    write_sensor_report(path, request)


def _reports(out: Path) -> dict[str, str]:
    strip = re.compile(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC")
    return {p.name: strip.sub("", p.read_text()) for p in sorted(out.glob("report_*.html"))}


def test_reports_built_by_the_worker_are_the_same(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    log = _log(tmp_path, 20000)  # 10 minutes: the report's 100 s averages
    monkeypatch.setattr(pipeline, "report_workers", lambda: 0)
    with pytest.warns(ThermocalWarning, match="says hello"):
        px4_tempcal(log, tmp_path / "here", reporter=_warning_reporter)
    sent: list[str] = []
    real_pool = pipeline._report_pool

    class Counting:
        def __init__(self) -> None:
            self.pool = real_pool()

        def submit(self, fn: Any, *args: Any) -> Any:
            sent.append(args[1].name)
            return self.pool.submit(fn, *args)

        def shutdown(self, **kw: Any) -> None:
            self.pool.shutdown(**kw)

    monkeypatch.setattr(pipeline, "report_workers", lambda: 1)
    monkeypatch.setattr(pipeline, "PARALLEL_MIN_SAMPLES", 0)
    monkeypatch.setattr(pipeline, "_report_pool", Counting)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        px4_tempcal(log, tmp_path / "worker", reporter=_warning_reporter)
    assert sent == ["report_sensor_accel_0.html", "report_sensor_gyro_0.html"]
    said = sorted(str(w.message) for w in caught if "says hello" in str(w.message))
    assert said == [f"report report_sensor_{s}_0.html says hello" for s in ("accel", "gyro")]
    here, there = _reports(tmp_path / "here"), _reports(tmp_path / "worker")
    assert list(here) == ["report_sensor_accel_0.html", "report_sensor_gyro_0.html"]
    assert here == there
    for name in ("px4.params",):
        assert (tmp_path / "here" / name).read_text() == (tmp_path / "worker" / name).read_text()


def test_shown_figures_are_figures_of_merit() -> None:
    # three 15-minute holds at 10, 25 and 40 °C joined by ramps, a 30 s gap in the middle
    # hold; the bias is 3 + 0.2·T [deg/h] plus noise
    rng = np.random.default_rng(9)
    t = np.arange(0.0, 4200.0, 0.5)
    temp = np.interp(t, [0, 900, 1200, 2100, 2400, 3300, 4200], [10, 10, 25, 25, 40, 40, 40])
    keep = (t < 1603.7) | (t > 1633.7)
    t, temp = t[keep], temp[keep]
    before = 3.0 + 0.2 * temp + rng.normal(0, 0.5, t.size)
    after = rng.normal(0, 0.5, t.size)
    got = shown_figures(t, (before, after), "deg/h", averaging_s=10.0, meta=Metadata(),
                        temp_name="T", temp_c=temp)  # fmt: skip
    want = [
        figures_of_merit(
            t, x, "deg/h", averaging_s=10.0, meta=Metadata(), temp_name="T", temp_c=temp
        )
        for x in (before, after)
    ]
    assert got == [(f.bias_stability, f.sensitivity_slope) for f in want]
    assert got[0][1] == pytest.approx(0.2, abs=0.01)  # the slope of 3 + 0.2·T
    # bias stability: std of 20-sample means, never across the gap, of the drift-free series
    parts = [after[: np.flatnonzero(~(t < 1603.7))[0]], after[np.flatnonzero(t > 1633.7)[0] :]]
    means = np.concatenate([p[: p.size // 20 * 20].reshape(-1, 20).mean(axis=1) for p in parts])
    assert got[1][0] == pytest.approx(float(np.std(means, ddof=1)), rel=1e-12)
