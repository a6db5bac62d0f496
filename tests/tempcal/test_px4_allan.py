"""px4-tempcal's reports draw the per-axis Allan deviation only when asked (``allan``,
``--allan``): without it none is computed (its cost is most of a report's on a long log),
the section and its contents entry are left out and a note says how to get it; the rest of
the report, the parameters and the JSON are the same either way."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import thermocal.report.calibration as calibration_report
from thermocal.cli import main
from ulog_writer import SENSOR_FIELDS, ulog_bytes


def _log(tmp_path: Path, n: int = 6000) -> Path:
    """A gyro and an accelerometer over a −10…50 °C sweep, cubic-free biases (rad/s, m/s²)."""
    rng = np.random.default_rng(41)
    t = np.arange(n) * 0.1
    temp = -10.0 + 60.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))
    x = (temp - 20.0) / 30.0
    g = np.column_stack([0.002 + 0.004 * x, -0.003 * x, 0.006 * x**2])
    a = np.column_stack([0.05 + 0.08 * x, -0.06 * x, -9.80665 + 0.1 * x])
    g, a = g + rng.normal(0, 1e-4, (n, 3)), a + rng.normal(0, 2e-3, (n, 3))
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows_g = [(int(s), 7, *map(float, v), float(T)) for s, v, T in zip(ts, g, temp, strict=True)]
    rows_a = [(int(s), 8, *map(float, v), float(T)) for s, v, T in zip(ts, a, temp, strict=True)]
    log = tmp_path / "s.ulg"
    log.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, rows_g),
                                ("sensor_accel", 0, SENSOR_FIELDS, rows_a)]))  # fmt: skip
    return log


def _run(
    log: Path, out: Path, capsys: pytest.CaptureFixture[str], *extra: str
) -> dict[str, Any]:
    code = main(["px4-tempcal", str(log), "-o", str(out), "--json", *extra])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    result: dict[str, Any] = json.loads(captured.out)
    return result


def _section(html: str, ident: str) -> str:
    start = html.index(f'<section id="{ident}">')
    return html[start : html.index("</section>", start)]


def test_allan_section_only_when_asked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[int] = []
    real = calibration_report.allan_of

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(calibration_report, "allan_of", counted)
    log = _log(tmp_path)
    plain = _run(log, tmp_path / "plain", capsys)
    assert calls == []  # nothing of the Allan section computed
    asked = _run(log, tmp_path / "asked", capsys, "--allan")
    assert len(calls) == 2 * 3 * 2  # two sensors, three axes, before and after
    for name in ("report_sensor_gyro_0.html", "report_sensor_accel_0.html"):
        without = (tmp_path / "plain" / name).read_text()
        with_ = (tmp_path / "asked" / name).read_text()
        assert 'id="fig-allan-grid"' not in without and 'id="noise"' not in without
        assert 'href="#allan"' not in without
        assert "--allan draws it" in without
        assert 'id="fig-allan-grid"' in with_ and 'id="noise"' in with_
        assert "--allan draws it" not in with_
        assert "<h2>3. Channels in detail</h2>" in without
        assert "<h2>4. Channels in detail</h2>" in with_
        # the rest is the same: the summary table and the bias figure
        for ident in ("summary", "bias"):
            a, b = _section(without, ident), _section(with_, ident)
            assert re.sub(r"<p class=\"small muted\">[^<]*</p>", "", a) == re.sub(
                r"<p class=\"small muted\">[^<]*</p>", "", b
            )
    assert (tmp_path / "plain" / "px4.params").read_text() == (
        tmp_path / "asked" / "px4.params"
    ).read_text()
    strip = {"params", "calibration", "reports"}
    assert {k: v for k, v in plain.items() if k not in strip} == {
        k: v for k, v in asked.items() if k not in strip
    }
