"""``thermocal demo``: the whole chamber workflow ends in a report whose numbers are the
JSON outputs', within the time budget, rendered in headless Chromium."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from report_checks import (
    check_number,
    check_rendered,
    embedded_pngs,
    run_chromium,
    skip_without_chromium,
    tagged_numbers,
)
from thermocal.cli import main
from thermocal.demo.chamber import DEMO_STEPS, QUICK, run_demo
from thermocal.models import RunData
from thermocal.pipeline.model_file import load_model, load_model_dict
from thermocal.readers.dispatch import read_recording

DEMO_BUDGET_S = 60.0
"""The issue's limit for ``thermocal demo`` on the 2-core machine [s]."""


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """``thermocal demo -o DIR --json`` with the default (full-size) data, in process."""
    out = tmp_path_factory.mktemp("demo") / "thermocal-demo"
    capture = tmp_path_factory.mktemp("demo-stdout") / "stdout.json"
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        status = main(["demo", "-o", str(out), "--json"])
    capture.write_text(buf.getvalue())
    assert status == 0, buf.getvalue()
    return {"dir": out, "summary": json.loads(buf.getvalue())}


def test_demo_writes_every_file(demo: dict[str, Any]) -> None:
    d: Path = demo["dir"]
    s = demo["summary"]
    assert Path(s["report"]) == d / "report.html"
    for rel in (
        "report.html",
        "models/seed37.json",
        "models/selected.json",
        "validation/seed37.json",
        "validation/selected.json",
        "c/thermocal_seed37.h",
        "c/thermocal_seed37.c",
        "c/thermocal_selected.h",
        "c/thermocal_selected.c",
        "data/rlg-modelling.parquet",
        "data/rlg-validation.parquet",
        "data/rlg-validation-compensated.parquet",
        "profiles/rlg-modelling.csv",
        "profiles/rlg-validation.csv",
    ):
        assert (d / rel).is_file(), rel
        assert (d / rel).stat().st_size > 0, rel
    assert set(s["timings_s"]) == set(DEMO_STEPS)
    # the budget, measured by the demo itself
    assert s["elapsed_s"] < DEMO_BUDGET_S


def test_demo_models_and_validation(demo: dict[str, Any]) -> None:
    d: Path = demo["dir"]
    seed37 = load_model_dict(d / "models" / "seed37.json")
    selected = load_model_dict(d / "models" / "selected.json")
    assert len(seed37["coefficients"]) == 37  # SPEC §4a: 9 per sensor × 4 + constant
    assert 1 < len(selected["coefficients"]) < 37
    for lab in ("seed37", "selected"):
        v = json.loads((d / "validation" / f"{lab}.json").read_text())
        assert v["r"] < 0.4 and v["weakly_correlated"] is True  # SPEC §5
        assert v["n_stages"] >= 4
    # the reported (first) model has the smaller rms of the compensated validation run
    rows = demo["summary"]["models"]
    rms = [json.loads(Path(r["validation"]).read_text())["rms_after"] for r in rows]
    assert rms[0] <= rms[1]
    # the compensated file adds <signal>_model and <signal>_comp to every input column
    comp = read_recording(d / "data" / "rlg-validation-compensated.parquet")
    raw = read_recording(d / "data" / "rlg-validation.parquet")
    assert set(raw.columns) | {"gyro_model", "gyro_comp"} == set(comp.columns)


def test_demo_selected_model_recovers_the_truth(demo: dict[str, Any]) -> None:
    """On the validation run the reported model follows the simulator's true
    temperature-induced bias: the error (means removed) is well below its spread."""
    d: Path = demo["dir"]
    rec = read_recording(d / "data" / "rlg-validation.parquet")
    truth = rec.column("truth_bias")
    model = load_model(d / "models" / f"{demo['summary']['models'][0]['label']}.json")
    pred = model.predict(RunData.from_recording(rec, "gyro", list(model.temp_names_)))
    err = (pred - pred.mean()) - (truth - truth.mean())
    # noise 0.12 °/h per 1 s sample over ~40 000 samples: a 2-parameter fit is good to
    # ~1e-3 °/h; the temperature-induced bias spreads ~7e-3 °/h
    assert np.sqrt(np.mean(err**2)) < 0.5 * truth.std()


def test_demo_report_shows_the_json_numbers(demo: dict[str, Any]) -> None:
    d: Path = demo["dir"]
    text = (d / "report.html").read_text(encoding="utf-8")
    tags = tagged_numbers(text)
    for lab in ("seed37", "selected"):
        v = json.loads((d / "validation" / f"{lab}.json").read_text())
        for key in (
            "r",
            "n_stages",
            "bias_stability_before",
            "bias_stability_after",
            "bias_repeatability_before",
            "bias_repeatability_after",
            "rms_before",
            "rms_after",
            "peak_to_peak_before",
            "peak_to_peak_after",
        ):
            check_number(tags, f"validation.{lab}.{key}", v[key])
        for key, value in v["improvement_pct"].items():
            check_number(tags, f"validation.{lab}.{key}_improvement_pct", value)
    primary = demo["summary"]["models"][0]["label"]
    m = load_model_dict(d / "models" / f"{primary}.json")
    for i, c in enumerate(m["coefficients"]):
        check_number(tags, f"model.coefficients.{i}.value", c["value"])
        check_number(tags, f"model.coefficients.{i}.stderr", c["stderr"])
    assert len(embedded_pngs(text)) == 6


def test_demo_c_files_compile(demo: dict[str, Any], tmp_path: Path) -> None:
    from thermocal.export.c import CFLAGS, find_compiler

    cc = find_compiler()
    if cc is None:
        pytest.skip("no C compiler")
    d: Path = demo["dir"] / "c"
    for lab in ("seed37", "selected"):
        src = d / f"thermocal_{lab}.c"
        proc = subprocess.run(
            [cc, *CFLAGS, "-c", str(src), "-I", str(d), "-o", str(tmp_path / f"{lab}.o")],
            capture_output=True, text=True, check=False,
        )  # fmt: skip
        assert proc.returncode == 0, proc.stderr


def test_demo_report_renders_in_headless_chromium(demo: dict[str, Any], tmp_path: Path) -> None:
    skip_without_chromium()
    result = run_chromium(demo["dir"] / "report.html", tmp_path)
    dom = check_rendered(result, n_figures_min=6)
    v = json.loads((demo["dir"] / "validation" / "selected.json").read_text())
    check_number(tagged_numbers(dom), "validation.selected.r", v["r"])


def test_run_demo_quick_is_seeded(tmp_path: Path) -> None:
    """The library function with the quick configuration: same seed, same numbers;
    progress is reported once per step."""
    steps: list[str] = []
    a = run_demo(tmp_path / "a", seed=3, config=QUICK, progress=steps.append)
    assert steps == list(DEMO_STEPS)
    assert a.report_path.is_file()
    va = json.loads(a.models[0].validation_path.read_text())
    assert va["weakly_correlated"] is True
    b = run_demo(tmp_path / "b", seed=3, config=QUICK)
    vb = json.loads(b.models[0].validation_path.read_text())
    for key in ("r", "bias_stability_after", "bias_repeatability_after"):
        assert va[key] == vb[key]


def test_report_cli_on_the_demo_files(demo: dict[str, Any], tmp_path: Path) -> None:
    """``thermocal report`` rebuilds the report from the files the demo wrote."""
    d: Path = demo["dir"]
    out = tmp_path / "again.html"
    status = main(
        [
            "report",
            "--model", str(d / "models" / "selected.json"),
            "--model", str(d / "models" / "seed37.json"),
            "--validation", str(d / "validation" / "selected.json"),
            "--validation", str(d / "validation" / "seed37.json"),
            "--recording", str(d / "data" / "rlg-validation.parquet"),
            "--modeling", str(d / "data" / "rlg-modelling.parquet"),
            "-o", str(out),
        ]
    )  # fmt: skip
    assert status == 0
    tags = tagged_numbers(out.read_text(encoding="utf-8"))
    demo_tags = tagged_numbers((d / "report.html").read_text(encoding="utf-8"))
    v = json.loads((d / "validation" / "seed37.json").read_text())
    check_number(tags, "validation.seed37.bias_repeatability_after", v["bias_repeatability_after"])
    # figures of merit and Allan noise terms computed by the report are the same
    for key, (value, _shown) in demo_tags.items():
        if (
            key.startswith(("fom.", "allan.", "truth."))
            and demo["summary"]["models"][0]["label"] == "selected"
        ):
            assert tags[key][0] == value, key
