"""The report of ArduPilot's barometer calibration (issue 28, item 3): ``ardupilot-tempcal``
writes ``report_BARO_0.html`` beside the IMU reports, with the parameters TCAL_ENABLED,
TCAL_TEMP_MIN, TCAL_TEMP_MAX, TCAL_BARO_EXP (the fitted exponent), the rms before/after
over the temperature bins, the residual figure, the held-out bins and the warnings said
about the barometer.  The log is the one of :func:`test_fc_reports.baro_log` (pressure
dropping by max(T − 25, 0)^1.35 Pa, written from the format description)."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest

from fc_logs import parm_file
from test_fc_reports import baro_log, run_cli


def test_ardupilot_baro_report_holds_the_fit(tmp_path: Path) -> None:
    log = tmp_path / "baro.bin"
    temp, press = baro_log(log, 1.35, +1.0)
    code, text = run_cli(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, text
    out = json.loads(text)
    report = tmp_path / "out" / "report_BARO_0.html"
    assert str(report) in out["reports"]
    html = report.read_text()
    section = html[html.index('<section id="ardupilot-baro">') :]
    section = section[: section.index("</section>")]
    p = parm_file(tmp_path / "out" / "ardupilot.parm")
    got = dict(re.findall(r'data-param="(TCAL_\w+)" data-new="([^"]+)"', section))
    assert set(got) == {"TCAL_ENABLED", "TCAL_TEMP_MIN", "TCAL_TEMP_MAX", "TCAL_BARO_EXP"}
    assert float(got["TCAL_BARO_EXP"]) == pytest.approx(p["TCAL_BARO_EXP"], rel=1e-6)
    assert float(got["TCAL_BARO_EXP"]) == pytest.approx(1.35, abs=0.01)
    assert float(got["TCAL_TEMP_MAX"]) == round(temp.max())
    # the rms after the correction, recomputed here from the log's samples
    corrected = press + np.maximum(temp - 25.0, 0.0) ** p["TCAL_BARO_EXP"]
    k = np.floor((temp - np.floor(temp.min() / 0.5) * 0.5) / 0.5).astype(int)
    bins = np.array([np.median(corrected[k == b]) for b in np.unique(k)])
    after = float(re.search(r'data-after="([^"]+)"', section).group(1))  # type: ignore[union-attr]
    assert after == pytest.approx(float(np.std(bins)), rel=0.05, abs=0.05)
    assert 'id="ardupilot-baro-residual"' in html and 'id="ardupilot-baro-holdout"' in html
    assert 'id="warnings"' not in html


def test_ardupilot_baro_report_says_the_warning(tmp_path: Path) -> None:
    log = tmp_path / "baro_up.bin"
    baro_log(log, 1.2, -1.0)  # a rise the firmware's correction cannot follow
    from thermocal.cli import main

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
        code = main(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out"), "--json"])
    assert code == 0, buf.getvalue()
    html = (tmp_path / "out" / "report_BARO_0.html").read_text()
    warned = html[html.index('<section id="warnings">') :]
    assert "TCAL_BARO_EXP 0 is at a limit" in warned and "does not follow" in warned
