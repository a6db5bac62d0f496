"""Tests of the HTML report (thermocal.report): numbers, self-containment, figures,
and a real headless-Chromium rendering (screenshot, console errors, images loaded).

The report is built here on a small synthetic chamber test with a test-only
linear model family (so the report is tested independently of the other model
families); the demo test (tests/demo/test_demo.py) renders the full workflow.
"""

from __future__ import annotations

import dataclasses
import html
import json
import math
import re
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, ClassVar, Self

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.signal import lfilter

from report_checks import (
    check_number,
    check_rendered,
    embedded_pngs,
    png_size,
    run_chromium,
    skip_without_chromium,
    tagged_numbers,
)
from thermocal.errors import ThermocalInputError
from thermocal.models.base import ModelStream, TemperatureModel
from thermocal.models.registry import MODEL_REGISTRY
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData
from thermocal.pipeline.model_file import save_model
from thermocal.recording import FloatArray, Metadata, Recording
from thermocal.report import (
    ModelEntry,
    ReportInputs,
    build_report,
    fmt_num,
    improvement_pct,
    write_report,
)
from thermocal.report.figures import binned_means, decimate_for_plot
from thermocal.writers import write_json, write_recording

TRUE_SLOPE = 0.05  # [°/h/°C] of the synthetic gyro on T1
TRUE_OFFSET = 1.5  # [°/h]


# --- a test-only model family: bias = c0 + c1 T1 ----------------------------------------


class _LinearStream(ModelStream):
    def __init__(self, coef: FloatArray) -> None:
        self.coef = coef

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        return float(self.coef[0] + self.coef[1] * temps_c[0])

    def reset(self) -> None:
        pass


class ReportTestLinear(TemperatureModel):
    """bias = c0 + c1·T (first channel); least squares with numpy.linalg.lstsq."""

    family: ClassVar[str] = "report-test-linear"

    def __init__(self, *, note: str | None = None) -> None:
        self.note = note

    def fit(self, runs: Sequence[RunData]) -> Self:
        t = np.concatenate([r.temps_c[:, 0] for r in runs])
        y = np.concatenate([r.target() for r in runs])
        x = np.column_stack([np.ones_like(t), t])
        coef, *_ = np.linalg.lstsq(x, y, rcond=None)
        res = y - x @ coef
        s2 = float(res @ res) / (y.size - 2)
        _q, r = np.linalg.qr(x)
        rinv = np.linalg.solve(r, np.eye(2))
        self.coef_ = coef
        self.se_ = np.sqrt(s2 * np.sum(rinv**2, axis=1))
        self._record_common(
            runs,
            FitStats(y.size, 2, float(np.sqrt(np.mean(res**2))), 12.5, 0.99, y.size - 2),
        )
        return self

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        temps = self.clamp(run.temps_c, extrapolate=extrapolate)
        out: FloatArray = self.coef_[0] + self.coef_[1] * temps[:, 0]
        return out

    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> ModelStream:
        return _LinearStream(self.coef_)

    def coefficients(self) -> list[Coefficient]:
        return [
            Coefficient("a0", float(self.coef_[0]), float(self.se_[0]), "deg/h"),
            Coefficient("T1", float(self.coef_[1]), float(self.se_[1]), "deg/h/degC"),
        ]

    def _state(self) -> dict[str, Any]:
        return {"coef": self.coef_.tolist(), "se": self.se_.tolist()}

    def _set_state(self, state: dict[str, Any]) -> None:
        self.coef_ = np.asarray(state["coef"], dtype=np.float64)
        self.se_ = np.asarray(state["se"], dtype=np.float64)


@pytest.fixture(scope="module", autouse=True)
def linear_family() -> Iterator[type[ReportTestLinear]]:
    """Register the test-only family for this module's tests and remove it afterwards, so
    it does not leak into other test files (e.g. the every-family checks of the C export
    and the chunked compensation) run in the same process."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(MODEL_REGISTRY, ReportTestLinear.family, ReportTestLinear)
        yield ReportTestLinear


# --- synthetic chamber runs -----------------------------------------------------------------


def _run(seed: int, hours: float, period_h: float, lo: float, hi: float, name: str) -> Recording:
    """1 Hz gyro [°/h] with bias = 1.5 + 0.05·T1 + white noise; T1…T3 lag the chamber."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 1.0)
    chamber = (lo + hi) / 2 + (hi - lo) / 2 * np.sign(np.sin(2 * np.pi * t / (period_h * 3600)))
    temps = {}
    for k, lag_s in enumerate((400.0, 900.0, 1500.0), start=1):
        # first-order lag y_i = d·y_{i−1} + (1 − d)·u_i, exact at 1 s, starting at u_0
        d = math.exp(-1.0 / lag_s)
        y, _ = lfilter([1.0 - d], [1.0, -d], chamber, zi=[d * chamber[0]])
        temps[f"T{k}"] = y
    gyro = TRUE_OFFSET + TRUE_SLOPE * temps["T1"] + rng.normal(0.0, 0.02, t.size)
    rec = Recording.from_arrays(
        t,
        {"gyro": gyro},
        {**temps, "T_chamber": chamber},
        meta=Metadata(sensor_id="SN-TEST-1", run_id=name),
    )
    return rec


@pytest.fixture(scope="module")
def case(
    tmp_path_factory: pytest.TempPathFactory, linear_family: type[ReportTestLinear]
) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("report")
    mod = _run(1, 3.0, 1.5, -10.0, 40.0, "modelling")
    val = _run(2, 2.0, 1.0, 0.0, 30.0, "validation")
    write_recording(mod, d / "mod.csv")
    write_recording(val, d / "val.csv")
    model = linear_family().fit([RunData.from_recording(mod, "gyro", ["T1", "T2"])])
    model.signal_name = "gyro"
    model_dict = save_model(model, d / "model.json")
    # a validation result as `thermocal validate --json` writes it (INTERFACE.md keys)
    r = float(np.corrcoef(mod.column("T_chamber")[: val.n_samples], val.column("T_chamber"))[0, 1])
    validation = {
        "r": r,
        "weakly_correlated": r < 0.4,
        "n_stages": 3,
        "bias_stability_before": 0.6123456,
        "bias_stability_after": 0.0212345,
        "bias_repeatability_before": 0.7234567,
        "bias_repeatability_after": 0.0134567,
        "rms_before": 0.5345678,
        "rms_after": 0.0456789,
        "peak_to_peak_before": 1.5012345,
        "peak_to_peak_after": 0.0987654,
        "averaging_s": 100.0,
    }
    write_json(d / "val.json", validation)
    inputs = ReportInputs(
        models=(ModelEntry("linear", model_dict, validation, str(d / "model.json")),),
        recording=val,
        modeling=mod,
        recording_path=str(d / "val.csv"),
        modeling_path=str(d / "mod.csv"),
        sensor="SN-TEST-1",
    )
    path = write_report(d / "report.html", inputs)
    return {
        "dir": d,
        "path": path,
        "html": path.read_text(encoding="utf-8"),
        "model": model_dict,
        "validation": validation,
        "val": val,
    }


# --- pure helpers -------------------------------------------------------------------------------


def test_fmt_num_and_improvement() -> None:
    assert fmt_num(None) == "—"
    assert fmt_num(float("nan")) == "—"
    assert fmt_num(3) == "3"
    assert fmt_num(0.0212345) == "0.02123"
    assert fmt_num(1.5012345) == "1.501"
    assert fmt_num(1.2345e-5) == "1.234e-05" or fmt_num(1.2345e-5) == "1.235e-05"
    assert fmt_num(2.5e7, 3) == "2.50e+07"
    assert improvement_pct(2.0, 0.5) == pytest.approx(75.0, abs=1e-12)
    assert improvement_pct(1.0, 2.0) == pytest.approx(-100.0, abs=1e-12)
    assert improvement_pct(0.0, 1.0) is None
    assert improvement_pct(None, 1.0) is None


def test_decimate_for_plot_block_means() -> None:
    x = np.arange(10.0)
    y = 2 * x
    # m = 3: blocks 0-2, 3-5, 6-8; the trailing block (9) is shorter than m/2: dropped
    xs, ys = decimate_for_plot(x, y, max_points=4)
    assert_allclose(xs, [1.0, 4.0, 7.0], rtol=0, atol=1e-15)
    assert_allclose(ys, [2.0, 8.0, 14.0], rtol=0, atol=1e-15)
    xs, ys = decimate_for_plot(x, y, max_points=100, block=4)  # blocks 0-3, 4-7, 8-9
    assert_allclose(xs, [1.5, 5.5, 8.5], rtol=0, atol=1e-15)
    same = decimate_for_plot(x, y, max_points=100)
    assert_allclose(same[1], y, rtol=0, atol=0)


def test_binned_means() -> None:
    rng = np.random.default_rng(0)
    x = rng.uniform(0.0, 10.0, 20_000)
    y = 3.0 + 0.5 * x + rng.normal(0.0, 0.1, x.size)
    c, m, se = binned_means(x, y, n_bins=10, min_count=30)
    assert c.size == 10
    # bin means follow the line at the bin centres within a few standard errors
    assert np.all(np.abs(m - (3.0 + 0.5 * c)) < 0.05)
    # the standard error of a bin mean is ≈ sqrt(σ² + (0.5·w)²/12)/sqrt(n) with w = 1
    expected = math.sqrt(0.1**2 + 0.25 / 12.0) / math.sqrt(x.size / 10)
    assert_allclose(se, expected, rtol=0.1)


# --- the built report ---------------------------------------------------------------------------


def test_report_is_self_contained(case: dict[str, Any]) -> None:
    text = case["html"]
    assert text.startswith("<!DOCTYPE html>")
    # nothing loaded from anywhere: no external src/href, CSP forbids it anyway
    assert not re.search(r'(src|href)="(?!data:|#)', text)
    assert "http://" not in text and "https://" not in text
    assert "default-src 'none'" in text
    for section in ("summary", "conditions", "profile", "validation", "bias", "allan", "drift"):
        assert f'<section id="{section}">' in text


def test_report_figures_are_valid_pngs(case: dict[str, Any]) -> None:
    pngs = embedded_pngs(case["html"])
    expected = {
        "fig-profile",
        "fig-fit",
        "fig-bias_time",
        "fig-bias_temp",
        "fig-allan",
        "fig-drift",
    }
    assert set(pngs) == expected
    for fid, data in pngs.items():
        w, h = png_size(data)
        assert w >= 600 and h >= 200, fid
        assert len(data) > 5000, fid  # has content, not an empty canvas
    # every figure has a caption
    assert len(re.findall(r"<figcaption>Figure \d+\. ", case["html"])) == len(expected)


def test_report_numbers_equal_the_json(case: dict[str, Any]) -> None:
    tags = tagged_numbers(case["html"])
    v = case["validation"]
    for key in (
        "r",
        "bias_stability_before",
        "bias_stability_after",
        "bias_repeatability_before",
        "bias_repeatability_after",
        "rms_before",
        "rms_after",
        "peak_to_peak_before",
        "peak_to_peak_after",
    ):
        check_number(tags, f"validation.linear.{key}", v[key])
    check_number(tags, "validation.linear.n_stages", v["n_stages"])
    imp = 100 * (1 - v["bias_stability_after"] / v["bias_stability_before"])
    check_number(tags, "validation.linear.bias_stability_improvement_pct", imp)
    m = case["model"]
    for i, c in enumerate(m["coefficients"]):
        check_number(tags, f"model.coefficients.{i}.value", c["value"])
        check_number(tags, f"model.coefficients.{i}.stderr", c["stderr"])
    check_number(tags, "models.linear.rms_residual", m["fit"]["rms_residual"])
    check_number(tags, "models.linear.condition_number", m["fit"]["condition_number"])
    lo, hi = m["range"]["temperature_c"]["T1"]
    check_number(tags, "model.range.temperature_c.T1.0", lo)
    check_number(tags, "model.range.temperature_c.T1.1", hi)
    # the fitted slope is the simulator's truth (noise 0.02 °/h over 10 800 samples)
    assert m["coefficients"][1]["value"] == pytest.approx(TRUE_SLOPE, abs=1e-3)


def _drift_reference(time_s: FloatArray, rate_deg_h: FloatArray, b0: float) -> FloatArray:
    """θ(t) = ∫ (ω − b0) dt / 3600 [°], scipy's cumulative trapezoid."""
    from scipy.integrate import cumulative_trapezoid

    out: FloatArray = cumulative_trapezoid(rate_deg_h - b0, time_s, initial=0.0)
    return out / 3600.0


def test_report_drift_angle_and_flags(case: dict[str, Any]) -> None:
    tags = tagged_numbers(case["html"])
    val: Recording = case["val"]
    gyro = val.column("gyro")
    coef = [c["value"] for c in case["model"]["coefficients"]]
    t1 = np.clip(val.column("T1"), *case["model"]["range"]["temperature_c"]["T1"])
    after = gyro - (coef[0] + coef[1] * t1)
    # before: b0 = the mean over the first 10 % of the run (a stated reference, not the
    # run's own mean, issue 25 item 6); after: like with like (issue 38), the compensated
    # rate's own mean over the same window; and both with nothing removed
    rel = val.time_s - val.time_s[0]
    win = rel <= 0.1 * rel[-1]
    theta_before = _drift_reference(val.time_s, gyro, float(np.mean(gyro[win])))
    theta_after = _drift_reference(val.time_s, after, float(np.mean(after[win])))
    # the report's drift angle (thermocal.metrics) equals scipy's trapezoid integral
    check_number(tags, "fom.before.drift_angle_max", float(np.max(np.abs(theta_before))), rel=1e-9)
    check_number(tags, "fom.after.drift_angle_max", float(np.max(np.abs(theta_after))), rel=1e-9)
    raw_b = float(np.max(np.abs(_drift_reference(val.time_s, gyro, 0.0))))
    raw_a = float(np.max(np.abs(_drift_reference(val.time_s, after, 0.0))))
    check_number(tags, "fom.before.drift_angle_raw_max", raw_b, rel=1e-9)
    check_number(tags, "fom.after.drift_angle_raw_max", raw_a, rel=1e-9)
    check_number(tags, "fom.before.drift_angle_raw_max_deg", raw_b, rel=1e-9)  # the cards
    check_number(tags, "summary.drift_angle_raw_improvement_pct", 100 * (1 - raw_a / raw_b))
    k_b = int(np.argmax(np.abs(theta_before)))
    check_number(tags, "fom.before.drift_angle_max_time_h", float(rel[k_b]) / 3600.0, rel=1e-9)
    # compensation removes the temperature drift: the drift angle shrinks a lot
    assert np.max(np.abs(theta_after)) < 0.1 * np.max(np.abs(theta_before))
    # flags: r of these square-wave profiles is far from weak → correlation flag fails
    weak = case["validation"]["weakly_correlated"]
    assert ('data-flag="pass"' in case["html"]) and (
        ("not weakly correlated" in case["html"]) == (not weak)
    )
    if not weak:
        assert 'data-kind="correlation"' in case["html"]


def _card(text: str, label: str) -> str:
    """The HTML of the summary card titled ``label``."""
    i = text.index(f'<div class="label">{label}</div>')
    return text[i : text.index('<div class="card', i) if '<div class="card' in text[i:] else None]


def test_report_drift_cards_compare_like_with_like(case: dict[str, Any]) -> None:
    """Issue 38: a validation run 3 °/h off the model's constant (another turn-on) read
    "largest drift angle 17.8° → 413°, not improved": a bias-removed before against a raw
    after.  Each card now compares one definition, before and after (scipy here)."""
    val: Recording = case["val"]
    gyro = val.column("gyro") + 3.0
    shifted = dataclasses.replace(val, columns={**val.columns, "gyro": gyro})
    text = build_report(ReportInputs(models=(ModelEntry("linear", case["model"], None),),
                                     recording=shifted))  # fmt: skip
    coef = [c["value"] for c in case["model"]["coefficients"]]
    t1 = np.clip(val.column("T1"), *case["model"]["range"]["temperature_c"]["T1"])
    after = gyro - (coef[0] + coef[1] * t1)
    rel = val.time_s - val.time_s[0]
    win = rel <= 0.1 * rel[-1]

    def peak(x: FloatArray, b0: float) -> float:
        return float(np.max(np.abs(_drift_reference(val.time_s, x, b0))))

    start = _card(text, "Largest drift angle, start bias removed")
    tags = tagged_numbers(start)
    b, a = peak(gyro, float(np.mean(gyro[win]))), peak(after, float(np.mean(after[win])))
    check_number(tags, "fom.before.drift_angle_max_deg", b, rel=1e-9)
    check_number(tags, "fom.after.drift_angle_max_deg", a, rel=1e-9)
    assert a < 0.2 * b and 'badge pass">improved<' in start and "same for the compensated" in start
    raw = _card(text, "Largest drift angle, no bias removed")
    tags = tagged_numbers(raw)
    check_number(tags, "fom.before.drift_angle_raw_max_deg", peak(gyro, 0.0), rel=1e-9)
    check_number(tags, "fom.after.drift_angle_raw_max_deg", peak(after, 0.0), rel=1e-9)
    assert "θ = ∫ (ω − Ω) dt, before and after" in html.unescape(raw)


def test_report_equal_figures_say_no_change(case: dict[str, Any]) -> None:
    """Issue 38: "Peak-to-peak −1.06e-13 %" — equal figures (to rounding) are "no change"."""
    v = dict(case["validation"], peak_to_peak_after=1.5012345 * (1 + 1e-15))
    v.pop("improvement_pct", None)
    text = build_report(ReportInputs(models=(ModelEntry("linear", case["model"], v),),
                                     recording=case["val"]))  # fmt: skip
    card = _card(text, "Peak-to-peak bias")
    assert ">no change<" in card and "e-13" not in card and "%" not in card
    assert 'badge fail">no change<' in card  # no change is not an improvement
    assert tagged_numbers(card)["validation.linear.peak_to_peak_improvement_pct"][0] == "0.0"
    # every card states its definition, the same before and after (averaging_s = 100 s)
    assert "max − min of the run's 100 s averages, before and after" in html.unescape(card)
    stab = _card(text, "Bias stability")
    assert "std of the 100 s averages within each hold stage" in stab


def test_report_warns_on_extrapolation_and_conditioning(case: dict[str, Any]) -> None:
    # validation run hotter than the modelling range, ill-conditioned model fit
    val = _run(3, 1.0, 0.5, 30.0, 60.0, "hot")
    m = json.loads(json.dumps(case["model"]))
    m["fit"]["condition_number"] = 3.0e9
    v = dict(case["validation"], r=0.62, weakly_correlated=False)
    text = build_report(ReportInputs(models=(ModelEntry("hot", m, v),), recording=val))
    assert 'data-kind="extrapolation"' in text
    assert 'data-kind="conditioning"' in text
    assert 'data-kind="correlation"' in text
    assert 'id="verdict"' in text and 'data-flag="fail"' in text
    assert "fig-fit" not in text  # no modelling run given: no fit figure


def test_report_bad_inputs(case: dict[str, Any]) -> None:
    with pytest.raises(ThermocalInputError):
        build_report(ReportInputs(models=(), recording=case["val"]))
    entry = ModelEntry("x", case["model"], None)
    with pytest.raises(ThermocalInputError):
        build_report(ReportInputs(models=(entry, entry), recording=case["val"]))


# --- real browser -------------------------------------------------------------------------------


def test_report_renders_in_headless_chromium(case: dict[str, Any], tmp_path: Path) -> None:
    skip_without_chromium()
    result = run_chromium(case["path"], tmp_path)
    dom = check_rendered(result, n_figures_min=6)
    # the numbers in the rendered page are the JSON's
    tags = tagged_numbers(dom)
    check_number(tags, "validation.linear.r", case["validation"]["r"])
    check_number(
        tags, "validation.linear.bias_stability_after", case["validation"]["bias_stability_after"]
    )


def test_chromium_check_detects_console_errors(tmp_path: Path) -> None:
    """The browser check itself: a page with a console error and an uncaught exception."""
    skip_without_chromium()
    bad = tmp_path / "bad.html"
    bad.write_text(
        "<!DOCTYPE html><html><body><p>x</p>"
        '<script>console.error("boom"); throw new Error("xyz");</script></body></html>'
    )
    result = run_chromium(bad, tmp_path)
    text = " ".join(result["console_errors"])
    assert "boom" in text and "Uncaught Error: xyz" in text


# --- command line -------------------------------------------------------------------------------


def test_report_cli_writes_the_report(case: dict[str, Any], tmp_path: Path) -> None:
    from thermocal.cli import main

    d = case["dir"]
    out = tmp_path / "cli-report.html"
    status = main(
        [
            "report",
            "--model",
            str(d / "model.json"),
            "--validation",
            str(d / "val.json"),
            "--recording",
            str(d / "val.csv"),
            "--modeling",
            str(d / "mod.csv"),
            "--sensor",
            "SN-CLI",
            "-o",
            str(out),
        ]
    )
    assert status == 0
    text = out.read_text(encoding="utf-8")
    assert "SN-CLI" in text
    tags = tagged_numbers(text)
    v = case["validation"]
    check_number(tags, "validation.model.r", v["r"])
    check_number(tags, "validation.model.bias_repeatability_after", v["bias_repeatability_after"])
    # the CLI's report shows the same figures-of-merit numbers as the library's
    lib = tagged_numbers(case["html"])
    for key in ("fom.before.bias_stability", "fom.after.bias_stability", "fom.after.bias"):
        assert tags[key][0] == lib[key][0]
    assert len(embedded_pngs(text)) == 6


def test_report_cli_bad_input(
    case: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from thermocal.cli import main

    d = case["dir"]
    base = ["report", "--model", str(d / "model.json"), "--recording", str(d / "val.csv")]
    # two validation files for one model
    status = main(
        [*base, "--validation", str(d / "val.json"), "--validation", str(d / "val.json"),
         "-o", str(tmp_path / "r.html")]
    )  # fmt: skip
    assert status == 2
    assert "error:" in capsys.readouterr().err
    # a model file as validation result
    status = main([*base, "--validation", str(d / "model.json"), "-o", str(tmp_path / "r.html")])
    assert status == 2
    assert "not a validation result" in capsys.readouterr().err
    # never write over an input
    status = main([*base, "-o", str(d / "val.csv")])
    assert status == 2
    assert "refusing to write over" in capsys.readouterr().err
    assert not (tmp_path / "r.html").exists()


@pytest.mark.parametrize("removed_in_fit", [True, False])
def test_apply_model_uses_the_fit_provenance_for_the_earth_rate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], removed_in_fit: bool
) -> None:
    """A model fitted with the earth rate removed (``--latitude/--axis``) and one fitted on
    the raw output both give the same bias after compensation in the report."""
    from thermocal.cli import main
    from thermocal.pipeline.model_file import load_model_dict
    from thermocal.report.build import apply_model, known_input_of

    n = 4000
    t = np.arange(n, dtype=np.float64)
    temp = 20.0 + 10.0 * np.sin(2 * np.pi * t / n)
    rng = np.random.default_rng(3)
    meta = Metadata(latitude_deg=45.0, axis="up")
    rec0 = Recording.from_arrays(t, {"gyro": np.zeros(n)}, {"T1": temp}, meta=meta)
    earth = known_input_of(rec0, "deg/h")
    assert earth == pytest.approx(15.041067 * math.sin(math.radians(45.0)), rel=1e-6)
    gyro = earth + 0.2 + 0.01 * (temp - 20.0) + 0.001 * rng.standard_normal(n)
    rec = Recording.from_arrays(t, {"gyro": gyro}, {"T1": temp}, meta=meta)
    path = write_recording(rec, tmp_path / "run.csv")
    extra = ["--latitude", "45", "--axis", "up"] if removed_in_fit else []
    out = tmp_path / "m.json"
    code = main(
        ["fit", str(path), "--model", "poly", "--order", "1", "--signal", "gyro", "--temps",
         "T1", *extra, "-o", str(out)]
    )  # fmt: skip
    capsys.readouterr()
    assert code == 0
    res = apply_model(load_model_dict(out), rec, "gyro")
    assert res.model_includes_known_input is (not removed_in_fit)
    # after compensation only the noise is left, whichever way the model was fitted
    assert float(np.std(res.after)) < 0.0015
    assert abs(float(np.mean(res.after))) < 1e-3
