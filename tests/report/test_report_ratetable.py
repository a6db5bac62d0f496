"""``thermocal report --ratetable RESULT.json``: the rate-table spec sheet as a section of a
model's report, its numbers those of the ``ratetable`` command, its figure embedded; what
cannot go in refused with one line."""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np
import pytest

from report_checks import embedded_pngs
from thermocal.cli import main
from thermocal.recording import Recording
from thermocal.writers import write_recording


def _run(seed: int, t0: float, t1: float) -> Recording:
    """A chamber run: a bias of 0.05 °/h per °C over a cosine sweep, 0.01 °/h noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 4 * 3600.0, 10.0)
    temp = t0 + (t1 - t0) * 0.5 * (1 - np.cos(2 * np.pi * t / t[-1]))
    g = 2.0 + 0.05 * (temp - 20) + 0.01 * rng.standard_normal(t.size)
    return Recording.from_arrays(t, {"gyro": g}, {"T1": temp}, signal_unit="deg/h")


@pytest.fixture(scope="module")
def case(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("rtreport")
    write_recording(_run(1, -10.0, 50.0), d / "mod.csv")
    write_recording(_run(2, 0.0, 40.0), d / "val.csv")
    assert main(["fit", str(d / "mod.csv"), "--model", "poly", "-o", str(d / "m.json")]) == 0
    assert main(["simulate", "ratetable", "--runs", "2", "--rate-hz", "50", "-o",
                 str(d / "rt")]) == 0  # fmt: skip
    files = sorted(str(p) for p in (d / "rt").glob("*.csv"))
    assert main(["ratetable", *files, "--rate-column", "table_rate", "--temps", "temp",
                 "-o", str(d / "rt.json")]) == 0  # fmt: skip
    return {"dir": d, "model": d / "m.json", "val": d / "val.csv", "rt": d / "rt.json"}


def test_spec_sheet_is_a_section_of_the_report(
    case: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    out = case["dir"] / "report.html"
    before = hashlib.sha256(case["rt"].read_bytes()).hexdigest()
    assert main(["report", "--model", str(case["model"]), "--recording", str(case["val"]),
                 "--ratetable", str(case["rt"]), "-o", str(out)]) == 0  # fmt: skip
    capsys.readouterr()
    html = out.read_text()
    assert hashlib.sha256(case["rt"].read_bytes()).hexdigest() == before
    assert re.search(r"<h2>\d+\. Rate-table test \(spec sheet\)</h2>", html)
    assert '<a href="#ratetable">' in html
    section = html[html.index('<section id="ratetable">') :]
    # the scale factors and the temperature coefficient the ratetable command computed
    res = json.loads(case["rt"].read_text())
    for ld in res["ladders"]:
        assert f"{ld['scale_factor']:.8g} ± " in section
        assert f"rate-table test at {ld['temperature_c']:.1f} °C" in section
    tc = res["temperature_coefficient"]["ppm_per_c"]
    assert f"{tc:.4g}" in section and "ppm/°C" in section
    pngs = embedded_pngs(section)
    assert {"fig-ratetable-nonlinearity", "fig-ratetable-temperature"} <= set(pngs)
    n = int(re.search(r"(\d+) figures embedded", html)[1])  # type: ignore[index]
    assert n == html.count("<img ")


def test_what_is_not_a_rate_table_result_refused(
    case: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    out = case["dir"] / "bad.html"
    for ratetable in (case["model"], case["dir"] / "missing.json"):
        assert main(["report", "--model", str(case["model"]), "--recording", str(case["val"]),
                     "--ratetable", str(ratetable), "-o", str(out)]) == 2  # fmt: skip
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("error: ") and "rate-table result" in err[0]
    assert not out.exists()
    before = case["rt"].read_bytes()
    assert main(["report", "--model", str(case["model"]), "--recording", str(case["val"]),
                 "--ratetable", str(case["rt"]), "-o", str(case["rt"])]) == 2  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ")
    assert case["rt"].read_bytes() == before


def test_beside_a_calibration_of_several_channels_refused(
    case: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    d = case["dir"]
    t = np.arange(0.0, 4 * 3600.0, 10.0)
    temp = -10.0 + 30.0 * (1 - np.cos(2 * np.pi * t / t[-1]))
    noise = np.random.default_rng(0).standard_normal((2, t.size)) * 0.01
    rec = Recording.from_arrays(
        t, {"gx": 0.05 * temp + noise[0], "gy": -0.03 * temp + noise[1]}, {"T1": temp},
        signal_unit="deg/h",
    )  # fmt: skip
    write_recording(rec, d / "two.csv")
    assert main(["fit", str(d / "two.csv"), "--signal", "gx,gy", "--model", "poly", "-o",
                 str(d / "two.json")]) == 0  # fmt: skip
    capsys.readouterr()
    out = d / "two.html"
    assert main(["report", "--model", str(d / "two.json"), "--recording", str(d / "two.csv"),
                 "--ratetable", str(case["rt"]), "-o", str(out)]) == 2  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "--ratetable" in err[0]
    assert "one-channel model" in err[0] and not out.exists()
