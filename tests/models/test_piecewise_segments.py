"""Issue 38: ``fit --model piecewise --segments 3`` fitted a 0.28 °C segment holding one
burst, with no adequacy check per segment, and ``export-c`` shipped it.  Every segment is
now judged as the line it is by the common rules (span ≥ 5 °C for order 1, distinct
temperatures, samples per coefficient): refused with the option that helps, or, with
``--allow-narrow``, recorded so that ``export-c`` says so.

The data: 5 s bursts at 50 Hz every 5 min, each burst's temperature rising 0.28 °C, burst
centres every 4 °C from −10 to 30 °C; the bias bends at 20 and 24 °C, so the segment
between the two bends holds the one burst at 22.00…22.28 °C (spans known by construction)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.models.piecewise import PiecewiseModel
from thermocal.models.rundata import RunData
from thermocal.recording import Recording

BURST_SPAN_C = 0.28
ARGS = ["--model", "piecewise", "--signal", "gyro", "--temps", "T", "--signal-unit", "deg/h",
        "--time-unit", "s", "--temp-unit", "degC"]  # fmt: skip


def _bursts(tmp_path: Path) -> tuple[Path, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    centres = np.arange(-10.0, 31.0, 4.0)
    t = np.concatenate([300.0 * i + 0.02 * np.arange(250) for i in range(centres.size)])
    temp = np.concatenate([c + np.linspace(0.0, BURST_SPAN_C, 250) for c in centres])
    truth = 0.5 + 0.01 * temp + 0.08 * np.maximum(0, temp - 20) - 0.16 * np.maximum(0, temp - 24)
    y = truth + rng.normal(0.0, 0.01, temp.size)
    path = tmp_path / "bursts.csv"
    pd.DataFrame({"time": t, "gyro": y, "T": temp}).to_csv(path, index=False)
    return path, t, temp, y


def test_each_segment_is_judged_in_the_library(tmp_path: Path) -> None:
    _path, t, temp, y = _bursts(tmp_path)
    run = RunData.from_recording(Recording.from_arrays(t, {"gyro": y}, {"T": temp}), "gyro", ["T"])
    m = PiecewiseModel(segments=3).fit([run])
    spans = {x.name: x for x in m.segment_tests_ if x.name.endswith("temperature_span")}
    assert len(spans) == m.breakpoints_.size + 1 == 3
    one_burst = spans["segment_2_temperature_span"]
    assert one_burst.figure == pytest.approx(BURST_SPAN_C, abs=1e-9)
    assert one_burst.verdict == "fail" and one_burst.threshold == 5.0
    message = one_burst.to_dict()["message"]  # the library names its parameter
    assert "ask fewer segments (segments 2)" in message and "22.00…22.28 °C" in message
    assert spans["segment_1_temperature_span"].verdict == "pass"  # −10…18.28 °C: 28.28 °C


def test_fit_refuses_a_one_burst_segment_and_export_c_flags_an_override(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, *_ = _bursts(tmp_path)
    model = tmp_path / "pw.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the gaps between bursts are warned about
        code = main(["fit", str(path), *ARGS, "--segments", "3", "-o", str(model)])
    err = capsys.readouterr().err
    assert code == 2 and not model.exists()
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"error: {path.name}: ") and "spans 0.28 °C" in last
    assert "--segments 2" in last and "--allow-narrow" in last
    with warnings.catch_warnings():  # breakpoints given: the advice is to move them
        warnings.simplefilter("ignore")
        code = main(["fit", str(path), *ARGS, "--breakpoints", "20,24", "--method",
                     "continuous", "-o", str(model)])  # fmt: skip
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert code == 2 and "move or drop a breakpoint (--breakpoints)" in last, last
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(["fit", str(path), *ARGS, "--segments", "3", "--allow-narrow",
                     "-o", str(model)])  # fmt: skip
    assert code == 0
    rec = json.loads(model.read_text())["adequacy"]
    failed = {x["name"] for x in rec["tests"] if x["verdict"] == "fail"}
    assert "segment_2_temperature_span" in failed and rec["verdict"] == "overridden"
    capsys.readouterr()
    assert main(["export-c", str(model), "-o", str(tmp_path / "c")]) == 0
    warned = capsys.readouterr().err
    assert "warning:" in warned and "segment_2_temperature_span failed" in warned


def test_a_sweep_that_supports_three_segments_is_fitted(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    n = 6000
    t = np.arange(n, dtype=float)
    temp = np.linspace(-10.0, 50.0, n)
    y = 0.01 * temp + 0.05 * np.maximum(0, temp - 10) - 0.1 * np.maximum(0, temp - 30)
    y += np.random.default_rng(1).normal(0.0, 0.01, n)
    path = tmp_path / "sweep.csv"
    pd.DataFrame({"time": t, "gyro": y, "T": temp}).to_csv(path, index=False)
    model = tmp_path / "ok.json"
    assert main(["fit", str(path), *ARGS, "--segments", "3", "-o", str(model)]) == 0
    capsys.readouterr()
    tests = json.loads(model.read_text())["adequacy"]["tests"]
    spans = [x for x in tests if x["name"].startswith("segment_") and "span" in x["name"]]
    assert len(spans) == 3 and all(x["verdict"] == "pass" and x["figure"] > 5 for x in spans)


def test_raw_count_temperatures_are_not_judged_in_degrees(tmp_path: Path) -> None:
    """A segment's span in raw counts is not a span in °C: not judged (as the whole-run
    test does), instead of refusing 0.28 counts as 0.28 °C."""
    import dataclasses

    _path, t, temp, y = _bursts(tmp_path)
    run = RunData.from_recording(Recording.from_arrays(t, {"gyro": y}, {"T": temp}), "gyro", ["T"])
    m = PiecewiseModel(segments=3).fit([dataclasses.replace(run, temperature_unit="counts")])
    spans = [x for x in m.segment_tests_ if x.name.endswith("temperature_span")]
    assert len(spans) == 3 and all(x.verdict == "n/a" for x in spans)
