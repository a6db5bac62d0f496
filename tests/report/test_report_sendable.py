"""Reports that can be sent (issue 25 item 9), through the CLI on files shaped like a
logger's: time in ms, a gyro in °/s named with its unit, the temperature as raw ADC counts
(T[°C] = 0.01·counts − 40), a validation record that is mostly a gap.

Checked: no green "No warnings" where thermocal warned; each warning once; the recording
named by its role; every conversion stated; coefficients, fit residual and figures in the
data's unit (°/s, not °/h); the model's adequacy record shown with a non-green box when
it failed or was overridden."""

from __future__ import annotations

import html as html_lib
import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.readers.options import ReadOptions

GAIN, OFFSET = 0.01, -40.0
N = 6000
SLOPE_DEG_S_PER_C = 0.3 / 3600.0 * 50.0  # °/s per °C


def _csv(path: Path, seed: int, phase: float, gap_after: int | None = None) -> None:
    rng = np.random.default_rng(seed)
    i = np.arange(N)
    t_ms = i * 1000.0
    if gap_after is not None:
        t_ms[gap_after:] += 5.0e8  # ≈ 139 h without a sample
    temp = 25.0 + 15.0 * np.sin(2 * np.pi * i / N + phase)
    gyro = SLOPE_DEG_S_PER_C * (temp - 25.0) + 0.002 * rng.standard_normal(N)
    counts = np.round((temp - OFFSET) / GAIN)
    pd.DataFrame({"time (ms)": t_ms, "gz [deg/s]": gyro, "T1": counts}).to_csv(path, index=False)


COMMON = ["--temp-unit", "counts", "--temp-conversion", f"{GAIN},{OFFSET}"]


@pytest.fixture(scope="module")
def work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("sendable")
    _csv(d / "mod.csv", 1, 0.0)
    _csv(d / "gappy.csv", 2, 1.9, gap_after=3000)
    code = main(["fit", str(d / "mod.csv"), "--model", "poly", "--order", "1", "--signal",
                 "gz [deg/s]", "--temps", "T1", *COMMON, "-o", str(d / "m.json")])  # fmt: skip
    assert code == 0
    return d


def _text(html: str) -> str:
    body = re.sub(r'src="data:image/png;base64,[^"]*"', "", html)
    body = re.sub(r"<(style|script)>.*?</\1>", "", body, flags=re.S)
    return html_lib.unescape(re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", body)))


def _warnings(html: str) -> list[str]:
    return [_text(m) for m in re.findall(r'<li data-kind="[^"]*">(.*?)</li>', html, flags=re.S)]


def _tag(html: str, key: str) -> float:
    m = re.search(rf'data-key="{re.escape(key)}" data-value="([^"]*)"', html)
    assert m is not None, key
    return float(m.group(1))


def _report(work: Path, name: str, *args: str) -> str:
    out = work / name
    code = main(["report", "--model", str(work / "m.json"), *args, *COMMON, "-o", str(out)])
    assert code == 0
    return out.read_text(encoding="utf-8")


def test_a_gappy_record_never_gets_no_warnings(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["validate", str(work / "m.json"), str(work / "gappy.csv"), *COMMON, "--json"])
    assert code == 0
    (work / "v.json").write_text(capsys.readouterr().out)
    html = _report(work, "gappy.html", "--validation", str(work / "v.json"), "--recording",
                   str(work / "gappy.csv"))  # fmt: skip
    assert "No warnings" not in html and 'class="ok" id="warnings"' not in html
    warns = _warnings(html)
    # the reader's gap warning is in the report, once; the share of the span is stated
    gap_lines = [w for w in warns if "gaps in time" in w]
    assert len(gap_lines) == 1
    span_h = (5.0e8 / 1000.0 + (N - 1)) / 3600.0
    share = 100.0 * (5.0e8 / 1000.0 - 1.0) / (span_h * 3600.0)
    assert share > 98.0
    assert any(f"{share:.3g} % of its" in w for w in warns), warns
    # each warning once
    assert len(warns) == len(set(warns))


def test_runs_are_named_by_their_role(work: Path) -> None:
    html = _report(work, "self.html", "--recording", str(work / "mod.csv"))
    text = _text(html)
    # the recording is the data the model was fitted on: a modelling run, never "validation"
    assert "Validation run" not in text and "validation run:" not in text.lower()
    assert "Modelling run: bias" in text and "whole modelling run" in text
    assert re.search(r"<tr><td>modelling</td><td><code>mod.csv</code>", html)
    assert any("the data the model was fitted on" in w for w in _warnings(html))


def test_conversions_and_units_are_stated(work: Path) -> None:
    html = _report(work, "units.html", "--recording", str(work / "mod.csv"))
    text = _text(html)
    assert "time: column in ms (column name), converted to s" in text
    assert "T[°C] = 0.01·counts − 40" in text
    assert "signal gz [deg/s]: deg/s (column name); figures shown in °/s" in text
    assert "°/h" not in text  # nothing in the canonical unit beside °/s tables
    model = json.loads((work / "m.json").read_text())
    coefs = model["coefficients"]
    assert [c["unit"] for c in coefs] == ["deg/h", "deg/h/degC"]  # the file's own unit
    for i, c in enumerate(coefs):  # shown in °/s: value / 3600
        assert _tag(html, f"model.coefficients.{i}.value") == pytest.approx(c["value"] / 3600.0)
        assert _tag(html, f"model.coefficients.{i}.stderr") == pytest.approx(c["stderr"] / 3600.0)
    assert re.search(r"°/s/°C", text)
    rms = _tag(html, "models.m.rms_residual")
    assert rms == pytest.approx(model["fit"]["rms_residual"] / 3600.0, rel=1e-12)
    # the figures of merit of the run in °/s, computed here: 100 s means of the raw rate
    df = pd.read_csv(work / "mod.csv")
    blocks = df["gz [deg/s]"].to_numpy()[: N // 100 * 100].reshape(-1, 100).mean(axis=1)
    assert _tag(html, "fom.before.bias_stability") == pytest.approx(
        float(np.std(blocks, ddof=1)), rel=1e-9
    )


def _with_adequacy(work: Path, verdict: str, overrides: list[str]) -> Path:
    from thermocal.models.format import checksum

    m: dict[str, Any] = json.loads((work / "m.json").read_text())
    m["adequacy"] = {
        "verdict": verdict,
        "overrides": overrides,
        "tests": [
            {"name": "temperature_span", "figure": 0.34, "threshold": 15.0, "unit": "degC",
             "verdict": "fail", "override": "--allow-narrow",
             "message": "the data span 0.34 °C; a first-order model needs 15 °C"},
            {"name": "stillness", "figure": 0.002, "threshold": 0.05, "unit": "deg/s",
             "verdict": "pass", "override": None, "message": "still"},
        ],
    }  # fmt: skip
    m.pop("checksum", None)
    m["checksum"] = checksum(m)
    path = work / f"m_{verdict}.json"
    path.write_text(json.dumps(m))
    return path


@pytest.mark.parametrize(("verdict", "css"), [("overridden", "warn"), ("fail", "fail")])
def test_the_adequacy_record_is_shown(work: Path, verdict: str, css: str) -> None:
    model = _with_adequacy(work, verdict, ["--allow-narrow"] if verdict == "overridden" else [])
    out = work / f"adequacy_{verdict}.html"
    code = main(["report", "--model", str(model), "--label", "m", "--recording",
                 str(work / "mod.csv"), *COMMON, "-o", str(out)])  # fmt: skip
    assert code == 0
    html = out.read_text(encoding="utf-8")
    assert f'<div class="verdict {css}" id="adequacy-verdict-m" data-flag="{verdict}">' in html
    assert _tag(html, "adequacy.m.temperature_span.figure") == 0.34
    assert _tag(html, "adequacy.m.temperature_span.threshold") == 15.0
    row = re.search(r'<tr data-test="temperature_span">(.*?)</tr>', html, flags=re.S)
    assert row is not None and ">fail<" in row.group(1) and "--allow-narrow" in row.group(1)
    assert any("adequacy" in w for w in _warnings(html))


def test_one_finding_from_several_sources_is_shown_once(work: Path) -> None:
    from thermocal.readers.dispatch import read_recording
    from thermocal.report import ModelEntry, ReportInputs, build_report

    msg = "2350 samples outside the model's temperature range: T1 20.00…50.00 °C"
    model = json.loads((work / "m.json").read_text())
    validation = {"warnings": [msg, f"hot.csv: {msg}"]}
    from thermocal.units import TemperatureConversion

    rec = read_recording(
        work / "mod.csv",
        ReadOptions(
            time="time (ms)",
            signals=["gz [deg/s]"],
            temperatures=["T1"],
            temp_unit="counts",
            temp_conversion=TemperatureConversion(GAIN, OFFSET),
        ),
    )
    inputs = ReportInputs(
        models=(ModelEntry("m", model, validation),),
        recording=rec,
        signal="gz [deg/s]",
        warnings=(f"m: {msg}", f"warning: {msg}."),
    )
    html = build_report(inputs)
    hits = [w for w in _warnings(html) if "2350 samples outside" in w]
    assert len(hits) == 1, hits


def test_an_empty_figure_says_why(monkeypatch: pytest.MonkeyPatch) -> None:
    from thermocal.report import figures as F

    drawn: list[Any] = []
    monkeypatch.setattr(F, "_png", lambda fig: drawn.append(fig) or b"png")
    t = np.arange(100.0)
    F.bias_vs_temperature(np.full(100, 25.0), t, t, unit="°/s", temperature_label="T1")
    F.allan_deviation([F.AllanCurve("after compensation", np.array([1.0]), np.array([0.0]))],
                      unit="°/s")  # fmt: skip
    texts = [" ".join(tx.get_text() for tx in fig.axes[0].texts) for fig in drawn]
    assert "T1 does not vary (constant at 25 °C)" in texts[0]
    assert "no Allan deviation to draw for after compensation" in texts[1]
