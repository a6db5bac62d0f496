"""The report says only what it was given (issue 13 item 6).

Data written here as CSV: a gyro [°/h] whose bias is 0.3 °/h/°C · (T − 25) + noise, the
temperature as raw ADC counts (T[°C] = 0.01·counts − 40, so 25 °C is 6500 counts), the way
a logger writes an unconverted channel.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

GAIN, OFFSET = 0.01, -40.0


def _csv(path: Path, seed: int, phase: float) -> None:
    rng = np.random.default_rng(seed)
    n = 20_000
    t = np.arange(n, dtype=float)
    temp = 25.0 + 20.0 * np.sin(2 * np.pi * t / n + phase)
    gyro = 0.3 * (temp - 25.0) + 0.05 * rng.standard_normal(n)
    counts = np.round((temp - OFFSET) / GAIN)
    pd.DataFrame({"time": t, "gyro": gyro, "T1": counts}).to_csv(path, index=False)


@pytest.fixture(scope="module")
def work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("report")
    _csv(d / "mod.csv", 1, 0.0)
    _csv(d / "val.csv", 2, 1.9)  # another phase: weakly correlated with the modelling run
    common = ["--signal", "gyro", "--signal-unit", "deg/h", "--time-unit", "s", "--temps",
              "T1", "--temp-conversion", f"{GAIN},{OFFSET}"]  # fmt: skip
    for name, order in (("lin", "1"), ("cub", "3")):
        code = main(["fit", str(d / "mod.csv"), "--model", "poly", "--order", order,
                     *common, "-o", str(d / f"{name}.json")])  # fmt: skip
        assert code == 0
    return d


def _html(path: Path) -> str:
    return path.read_text(encoding="utf-8")


def _verdict(html: str) -> str:
    m = re.search(r'<div class="verdict (\w+)"', html)
    assert m is not None
    return m.group(1)


def test_no_validation_no_verdict(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = work / "a.html"
    code = main(["report", "--model", str(work / "lin.json"), "--recording",
                 str(work / "val.csv"), "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    html = _html(out)
    assert _verdict(html) == "na"
    assert "PASS" not in html and "ATTENTION" not in html
    assert "no validation result was given" in html


def test_validation_given_gives_a_verdict(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", str(work / "lin.json"), str(work / "val.csv"), "--json"]) == 0
    (work / "v.json").write_text(capsys.readouterr().out)
    v = json.loads((work / "v.json").read_text())
    out = work / "b.html"
    code = main(["report", "--model", str(work / "lin.json"), "--validation", str(work / "v.json"),
                 "--recording", str(work / "val.csv"), "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    verdict = _verdict(_html(out))
    assert verdict in ("pass", "fail")
    assert (verdict == "pass") == bool(v["weakly_correlated"]) or verdict == "fail"


def test_every_model_is_shown(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = work / "c.html"
    code = main(["report", "--model", str(work / "lin.json"), "--model", str(work / "cub.json"),
                 "--recording", str(work / "val.csv"), "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    html = _html(out)
    first = html[html.index('id="coefficients"') : html.index('id="coefficients-2"')]
    second = html[html.index('id="coefficients-2"') :]
    second = second[: second.index("</table>")]
    assert "T1^3" not in first and "T1^3" in second  # the cubic's own table
    assert "Model cub" in html and "Model lin" in html
    # the second model's slope is tagged with its own key
    lin = json.loads((work / "lin.json").read_text())
    slope = next(c["value"] for c in lin["coefficients"] if c["name"] == "T1")
    assert slope == pytest.approx(0.3, rel=0.01)
    assert 'data-key="models.cub.coefficients.' in html


def test_raw_count_temperatures_are_reported_in_degc(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The model recorded its conversion: the report converts the raw counts (5…45 °C,
    not 4500…8500 'degC'); an explicit --temp-conversion does the same."""
    for extra in ([], ["--temp-conversion", f"{GAIN},{OFFSET}"]):
        out = work / "d.html"
        code = main(["report", "--model", str(work / "lin.json"), "--recording",
                     str(work / "val.csv"), "-o", str(out), *extra])  # fmt: skip
        assert code == 0, capsys.readouterr().err
        html = _html(out)
        spans = re.findall(r'<td class="n">(-?[\d.]+) … (-?[\d.]+)</td></tr>', html)
        assert spans, "the run table shows the temperature span"
        lo, hi = (float(v) for v in spans[-1])
        assert 4.0 < lo < 6.0 and 44.0 < hi < 46.0


def test_average_option_sets_the_averaging_time(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = work / "e.html"
    code = main(["report", "--model", str(work / "lin.json"), "--recording",
                 str(work / "val.csv"), "-o", str(out), "--average", "250"])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    assert "Bias stability (250 s averages)" in _html(out)
