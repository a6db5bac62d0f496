"""Judge what the sensor's user sees (issue 25 item 4): compensate and validate report the
mean, the rms about zero and the largest |error| before and after, in the data's unit, and
a model that makes the absolute error worse says so (warning, JSON flag, verdicts).

The case of the issue: a model fitted on a cold soak applied to a hot soak.  The figures
about the mean do not move (the clamped model is a constant there) while the output moves
away from zero.  Every expected number is computed here: the fitted line by numpy's
least squares, the model value at the hot soak = the line at the top of the fitted range
(the model holds its input at the calibrated range)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

SIG = "gx [deg/s]"
SIG2 = "gy [deg/s]"
N = 3600


def _cold(path: Path, seed: int = 7) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A cold soak swept 5 → 21 °C at 1 Hz: gx bias −0.29 + 0.01 (T − 13) °/s, noise 0.3 °/s;
    gy bias 0.02 (T − 13) °/s, noise 0.05 °/s."""
    rng = np.random.default_rng(seed)
    t = np.arange(N, dtype=float)
    temp = 5.0 + 16.0 * t / (N - 1) + 0.01 * rng.standard_normal(N)
    gx = -0.29 + 0.01 * (temp - 13.0) + 0.3 * rng.standard_normal(N)
    gy = 0.02 * (temp - 13.0) + 0.05 * rng.standard_normal(N)
    pd.DataFrame({"time (s)": t, SIG: gx, SIG2: gy, "temp_c": temp}).to_csv(path, index=False)
    return temp, gx, gy


def _hot(path: Path, seed: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A hot soak at 47 °C: gx reads 0.50 °/s (the issue's board), gy 0.02·(47 − 13)."""
    rng = np.random.default_rng(seed)
    t = np.arange(N, dtype=float)
    temp = 47.0 + 0.01 * rng.standard_normal(N)
    gx = 0.50 + 0.3 * rng.standard_normal(N)
    gy = 0.02 * (temp - 13.0) + 0.05 * rng.standard_normal(N)
    pd.DataFrame({"time (s)": t, SIG: gx, SIG2: gy, "temp_c": temp}).to_csv(path, index=False)
    return temp, gx, gy


def _line_at_top(temp: np.ndarray, y: np.ndarray) -> float:
    """The least-squares line of y on T evaluated at the top of T's range [unit of y]."""
    p = np.polyfit(temp, y, 1)
    return float(np.polyval(p, temp.max()))


def _figures(x: np.ndarray) -> dict[str, float]:
    return {
        "mean": float(np.mean(x)),
        "rms_about_zero": float(np.sqrt(np.mean(x * x))),
        "max_abs": float(np.max(np.abs(x))),
    }


def _fit(tmp_path: Path, signals: str, out: str) -> Path:
    model = tmp_path / out
    code = main(["fit", str(tmp_path / "cold.csv"), "--model", "poly", "--order", "1",
                 "--signal", signals, "--temps", "temp_c", "-o", str(model)])  # fmt: skip
    assert code == 0
    return model


def _check(obj: dict, before: np.ndarray, after: np.ndarray) -> None:
    for when, x in (("before", before), ("after", after)):
        for key, val in _figures(x).items():
            assert obj[f"{key}_{when}"] == pytest.approx(val, rel=1e-6), (key, when)


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_cold_soak_model_on_hot_soak_is_worse_about_zero(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t_cold, gx_cold, _ = _cold(tmp_path / "cold.csv")
    _t_hot, gx_hot, _ = _hot(tmp_path / "hot.csv")
    model = _fit(tmp_path, SIG, "m.json")
    capsys.readouterr()
    y = _line_at_top(t_cold, gx_cold)  # every hot sample: the line at 21 °C [deg/s]
    before, after = gx_hot, gx_hot - y

    code = main(["compensate", str(model), str(tmp_path / "hot.csv"),
                 "-o", str(tmp_path / "out.csv"), "--chunk-rows", "700", "--json"])  # fmt: skip
    io = capsys.readouterr()
    assert code == 0, io.err
    res = json.loads(io.out)
    _check(res, before, after)
    assert res["unit"] == "deg/s"
    # about the mean nothing moved (the "rms 0.3017 → 0.3017 °/s") ...
    assert res["rms_after"] == pytest.approx(res["rms_before"], rel=1e-9)
    # ... about zero it is worse, and said so once
    assert res["absolute_error_worse"] is True
    assert res["zero_reference"] == {
        "value": 0.0,
        "unit": "deg/s",
        "what": "no known input given, in the file's metadata or in the model file: zero is 0",
    }
    lines = [ln for ln in io.err.splitlines() if "makes the absolute error worse" in ln]
    assert len(lines) == 1 and lines[0].startswith("warning: ")
    pct = 100.0 * (_figures(after)["rms_about_zero"] / _figures(before)["rms_about_zero"] - 1.0)
    assert f"({pct:+.3g} %)" in lines[0] and "deg/s" in lines[0]

    code = main(["validate", str(model), str(tmp_path / "hot.csv"), "--json"])
    io = capsys.readouterr()
    assert code == 0, io.err
    v = json.loads(io.out)
    _check(v, before, after)
    assert v["unit"] == "deg/s"
    assert v["absolute_error_worse"] is True
    assert v["verdict"] == "NOT improved (absolute error worse)"
    assert "warning: " in io.err and "makes the absolute error worse" in io.err
    # the human output shows the figures and the verdict
    code = main(["validate", str(model), str(tmp_path / "hot.csv")])
    out = capsys.readouterr().out
    assert "rms about zero" in out and "verdict: NOT improved (absolute error worse)" in out


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_several_channels_report_absolute_figures_per_channel(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """gx: worse about zero on the hot soak; gy: the compensation (its line held at 21 °C)
    removes part of the offset, so gy is not flagged; figures computed here per channel."""
    t_cold, gx_cold, gy_cold = _cold(tmp_path / "cold.csv")
    _t_hot, gx_hot, gy_hot = _hot(tmp_path / "hot.csv")
    cal = _fit(tmp_path, f"{SIG},{SIG2}", "cal.json")
    capsys.readouterr()
    exp = {
        SIG: (gx_hot, gx_hot - _line_at_top(t_cold, gx_cold), True),
        SIG2: (gy_hot, gy_hot - _line_at_top(t_cold, gy_cold), False),
    }
    code = main(["compensate", str(cal), str(tmp_path / "hot.csv"),
                 "-o", str(tmp_path / "out.parquet"), "--json"])  # fmt: skip
    io = capsys.readouterr()
    assert code == 0, io.err
    chans = json.loads(io.out)["channels"]
    for name, (b, a, worse) in exp.items():
        _check(chans[name], b, a)
        assert chans[name]["absolute_error_worse"] is worse
        assert chans[name]["unit"] == "deg/s"
    assert io.err.count("makes the absolute error worse") == 1
    code = main(["validate", str(cal), str(tmp_path / "hot.csv"), "--json"])
    io = capsys.readouterr()
    assert code == 0, io.err
    chans = json.loads(io.out)["channels"]
    for name, (b, a, worse) in exp.items():
        _check(chans[name], b, a)
        assert chans[name]["absolute_error_worse"] is worse
    assert chans[SIG]["verdict"] == "NOT improved (absolute error worse)"
    assert chans[SIG2]["verdict"] != "NOT improved (absolute error worse)"


def _holds(path: Path, offset: float, seed: int) -> None:
    """Holds at 20, 6, 16, 10 °C (1500 s each, drifting 0.03 °C/min, joined by 1 °C/min
    ramps): gx bias offset + 0.05 (T − 13) °/s, noise 0.05 °/s."""
    rng = np.random.default_rng(seed)
    knots_t, knots_T = [0.0], [20.0]
    for lev in (20.0, 6.0, 16.0, 10.0):
        if len(knots_t) > 1:
            knots_t.append(knots_t[-1] + abs(lev - knots_T[-1]) * 60.0)
            knots_T.append(lev)
        knots_t.append(knots_t[-1] + 1500.0)
        knots_T.append(lev + 0.75)
    t = np.arange(0.0, knots_t[-1], 1.0)
    temp = np.interp(t, knots_t, knots_T)
    gx = offset + 0.05 * (temp - 13.0) + 0.05 * rng.standard_normal(t.size)
    pd.DataFrame({"time (s)": t, SIG: gx, "temp_c": temp}).to_csv(path, index=False)


def test_report_verdict_weighs_the_absolute_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Another power-on (bias offset −0.29 → +0.50 °/s) in the calibrated range: the slope
    is removed, so every figure about the mean improves, but the output moves away from
    zero: the report's verdict is not PASS."""
    rng = np.random.default_rng(3)
    t = np.arange(N, dtype=float)
    temp = 5.0 + 16.0 * t / (N - 1)
    gx = -0.29 + 0.05 * (temp - 13.0) + 0.05 * rng.standard_normal(N)
    pd.DataFrame({"time (s)": t, SIG: gx, "temp_c": temp}).to_csv(tmp_path / "cold.csv",
                                                                  index=False)  # fmt: skip
    _holds(tmp_path / "val.csv", 0.50, 4)
    model = _fit(tmp_path, SIG, "m.json")
    capsys.readouterr()
    assert main(["validate", str(model), str(tmp_path / "val.csv"), "--json"]) == 0
    io = capsys.readouterr()
    v = json.loads(io.out)
    assert v["weakly_correlated"] is True
    assert all(p > 0 for p in v["improvement_pct"].values())  # about the mean: better
    assert v["absolute_error_worse"] is True
    (tmp_path / "v.json").write_text(io.out)
    out = tmp_path / "r.html"
    code = main(["report", "--model", str(model), "--validation", str(tmp_path / "v.json"),
                 "--recording", str(tmp_path / "val.csv"), "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    html = out.read_text(encoding="utf-8")
    m = re.search(r'<div class="verdict (\w+)"', html)
    assert m is not None and m.group(1) == "fail"
    assert "Error about zero" in html and "absolute error worse" in html
