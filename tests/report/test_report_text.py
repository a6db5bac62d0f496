"""The results as text (:mod:`thermocal.report.text`): the cells are the result's numbers,
checked against numbers computed here with numpy (the bias is the mean, the overlapping
Allan deviation at τ0 is the rms of successive differences over √2, IEEE Std 952-1997)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from thermocal.metrics import MetricsOptions, channel_metrics
from thermocal.recording import Recording
from thermocal.report.text import (
    TextTable,
    allan_text,
    fmt,
    inspection_text,
    metrics_text,
)


def _white(n: int = 4000, sigma: float = 0.5, bias: float = 2.0) -> Recording:
    rng = np.random.default_rng(0)
    x = bias + sigma * rng.standard_normal(n)
    return Recording.from_arrays(np.arange(n) * 1.0, {"gx": x}, signal_unit="deg/h")


def test_fmt_significant_digits_and_missing() -> None:
    assert fmt(0.0123456) == "0.01235"
    assert fmt(123456.0, 3) == "1.23e+05"
    assert fmt(None) == fmt(float("nan")) == fmt(float("inf")) == "—"
    assert fmt(7) == "7"


def test_text_table_to_text_pads_each_column() -> None:
    t = TextTable(None, ("a", "bb"), (("xxx", "1"), ("y", "22")), ("left", "right"))
    assert t.to_text().splitlines() == ["a   bb", "xxx  1", "y   22"]


def test_metrics_text_holds_the_mean_as_bias() -> None:
    rec = _white()
    x = rec.signal("gx")[0]
    results = channel_metrics(rec, ["gx"], MetricsOptions(averaging_s=10.0))
    (table,) = metrics_text("run.csv", results)
    assert isinstance(table, TextTable)
    assert table.title == "run.csv — gx"
    assert table.columns == ("figure", "value", "unit")
    assert table.justify == ("left", "right", "left")
    rows = {r[0]: r[1:] for r in table.rows}
    assert rows["bias"] == (f"{np.mean(x):.6g}", "deg/h")
    means = x.reshape(-1, 10).mean(axis=1)  # 400 averages of 10 s
    assert rows["bias stability (10 s)"] == (f"{np.std(means, ddof=1):.4g}", "deg/h")
    assert rows["samples"] == ("4000", "")
    assert "temp. sensitivity, LS slope" not in rows  # no temperature: the row is left out


def test_allan_text_first_point_is_the_difference_rms() -> None:
    from thermocal.stability.analysis import allan_analysis

    rec = _white()
    x = rec.signal("gx")[0].copy()  # the analysis may reuse the recording's buffer
    res = allan_analysis(rec, ["gx"], taus=[1.0, 10.0])
    blocks = allan_text("run.csv", res.channels["gx"])
    adev, noise = blocks[0], blocks[1]
    assert isinstance(adev, TextTable) and isinstance(noise, TextTable)
    assert adev.title == "run.csv — overlapping Allan deviation [deg/h]"
    assert adev.columns == ("τ [s]", "ADEV", "low", "high", "terms", "edf")
    expected = np.sqrt(0.5 * np.mean(np.diff(x) ** 2))
    assert adev.rows[0][:2] == ("1", f"{expected:.4g}")
    assert adev.rows[0][4] == "3999"  # N − 1 differences at τ0
    assert noise.title == "noise terms"
    assert all(isinstance(b, str) for b in blocks[2:])


def test_inspection_text_counts_samples_and_columns(tmp_path: Path) -> None:
    from thermocal.inspection import inspect_recording

    rec = _white(n=50)
    blocks = inspection_text(inspect_recording(rec))
    assert blocks[0] == "50 samples over 49 s, sample rate 1 Hz, 0 gaps, 1 contiguous segments"
    table = blocks[1]
    assert isinstance(table, TextTable) and table.title is None
    gx = next(r for r in table.rows if r[0] == "gx")
    x = rec.signal("gx")[0]
    assert gx[3:6] == (f"{x.min():.6g}", f"{x.max():.6g}", f"{x.mean():.6g}")
