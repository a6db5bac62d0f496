"""px4-tempcal's reports draw the per-axis Allan deviation only when asked (``allan``,
``--allan``): without it none is computed (its cost is most of a report's on a long log),
the section and its contents entry are left out and a note says how to get it; the rest of
the report, the parameters and the JSON are the same either way."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from fc_sweeps import count_allan_calls, px4_sweep_log, run_json


def _section(html: str, ident: str) -> str:
    start = html.index(f'<section id="{ident}">')
    return html[start : html.index("</section>", start)]


def test_allan_section_only_when_asked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = count_allan_calls(monkeypatch)
    log = px4_sweep_log(tmp_path / "s.ulg", 6000, 0.1, 41)
    plain = run_json("px4-tempcal", log, tmp_path / "plain", capsys)
    assert calls == []  # nothing of the Allan section computed
    asked = run_json("px4-tempcal", log, tmp_path / "asked", capsys, "--allan")
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
