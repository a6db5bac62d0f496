"""ardupilot-tempcal's reports draw the per-axis Allan deviation only when asked (``allan``,
``--allan``): without it none is computed, the section and its contents entry are left out
and a note says how to get it; the parameters and the rest of the JSON are the same either
way."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pymavlink")

from fc_sweeps import ardupilot_sweep_log, count_allan_calls, run_json


def test_allan_section_only_when_asked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = count_allan_calls(monkeypatch)
    log = ardupilot_sweep_log(tmp_path / "s.bin", 6000, 0.1, 41)
    plain = run_json("ardupilot-tempcal", log, tmp_path / "plain", capsys)
    assert calls == []  # nothing of the Allan section computed
    asked = run_json("ardupilot-tempcal", log, tmp_path / "asked", capsys, "--allan")
    assert len(calls) == 2 * 3 * 2  # gyro and accelerometer, three axes, before and after
    for name in ("report_IMU_0_gyro.html", "report_IMU_0_accel.html"):
        without = (tmp_path / "plain" / name).read_text()
        with_ = (tmp_path / "asked" / name).read_text()
        assert 'id="fig-allan-grid"' not in without and 'id="noise"' not in without
        assert "ardupilot-tempcal LOG -o DIR --allan draws it" in without
        assert 'id="fig-allan-grid"' in with_ and 'id="noise"' in with_
        assert "--allan draws it" not in with_
    assert (tmp_path / "plain" / "ardupilot.parm").read_text() == (
        tmp_path / "asked" / "ardupilot.parm"
    ).read_text()
    strip = {"params", "calibration", "reports"}
    assert {k: v for k, v in plain.items() if k not in strip} == {
        k: v for k, v in asked.items() if k not in strip
    }
