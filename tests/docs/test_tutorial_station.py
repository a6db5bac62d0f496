"""The test-station tutorial (``docs/tutorials/station.md``) runs as written.

Its blocks run in order in an empty folder: the ``python`` blocks in one namespace (the
simulated chamber and serial gyro they start live on to the last block, which stops them;
the test stops them too if a block fails), the ``$ thermocal …`` lines through the command
line.  A timed run's numbers differ a little between runs (samples recorded, the noise, the
port), so what a block prints is compared with the page's ``text`` block with every number
masked and the tables' rules and padding collapsed: the same lines, the same words, the
same table rows.  The numbers are checked against the simulator's truth
(:class:`thermocal.station.sim.GyroTruth`: 0.002 °/s/°C, 0.05 °/s at 25 °C, white noise
0.0005 °/s), not against the page.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import shlex
from pathlib import Path
from typing import Any

import pytest

from thermocal.cli import main
from tutorial_pages import BLOCK, TUTORIALS, fresh_cli

pytest.importorskip("pymodbus")
pytest.importorskip("serial")

PAGE = TUTORIALS / "station.md"


def masked(text: str) -> list[str]:
    """The text's lines with numbers as ``#``, rules and runs of blanks collapsed."""
    text = re.sub(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", "#", text)
    text = re.sub(r"[━─]+", "─", text)
    return [" ".join(line.split()) for line in text.splitlines() if line.strip()]


def _run_console(body: str) -> str:
    out = io.StringIO()
    for line in body.splitlines():
        assert line.startswith("$ thermocal "), line
        err = io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(shlex.split(line[len("$ thermocal ") :]))
        assert code == 0, (line, err.getvalue())
    return out.getvalue()


def _run_page(ns: dict[str, Any]) -> list[tuple[str, str]]:
    blocks = [(m.group(1), m.group(2)) for m in BLOCK.finditer(PAGE.read_text(encoding="utf-8"))]
    done = []
    for i, (lang, body) in enumerate(blocks):
        if lang not in ("console", "python"):
            continue
        if lang == "python":
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                exec(compile(body, PAGE.name, "exec"), ns)
            printed = buf.getvalue()
        else:
            printed = _run_console(body)
        done.append((printed, next(b for la, b in blocks[i + 1 :] if la == "text")))
    return done


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[tuple[str, str]], Path]:
    tmp = tmp_path_factory.mktemp("station-page")
    ns: dict[str, Any] = {}
    try:
        with pytest.MonkeyPatch.context() as mp:
            fresh_cli(mp)
            mp.chdir(tmp)
            return _run_page(ns), tmp
    finally:  # a failed block leaves no simulator running
        for name in ("imu", "chamber"):
            if name in ns:
                ns[name].stop()


def test_station_tutorial_prints_what_the_page_shows(
    page: tuple[list[tuple[str, str]], Path],
) -> None:
    blocks, _ = page
    assert len(blocks) == 10
    for printed, shown in blocks:
        assert masked(printed) == masked(shown)


def test_station_tutorial_recovers_the_simulated_gyro(
    page: tuple[list[tuple[str, str]], Path],
) -> None:
    from thermocal.station.sim import GyroTruth

    blocks, tmp = page
    truth = GyroTruth()
    coef = {c["name"]: c for c in json.loads((tmp / "model.json").read_text())["coefficients"]}
    assert coef["T1"]["unit"] == "deg/h/degC"
    assert coef["T1"]["value"] / 3600.0 == pytest.approx(truth.slope_deg_s_per_c, rel=0.01)
    # const is the bias at 0 °C in deg/h: 0.05 - 25 * 0.002 = 0 deg/s, within its std. errors
    assert abs(coef["const"]["value"]) < 4 * coef["const"]["stderr"] + 0.01 * 3600 * 0.002
    # the validation: weakly correlated; the error about zero brought down to the noise
    validation = blocks[-3][0]
    r = float(re.search(r"r = (\S+) \(weakly correlated\)", validation)[1])  # type: ignore[index]
    assert abs(r) < 0.4
    rms_zero = re.search(r"rms about zero\s*│\s*(\S+)\s*│\s*(\S+)", validation)
    assert rms_zero is not None
    before, after = float(rms_zero[1]), float(rms_zero[2])
    assert after < 1.5 * truth.noise_deg_s
    assert before > 50 * truth.noise_deg_s
    assert sorted(p.name for p in (tmp / "c").iterdir()) == ["model.c", "model.h"]
    recorded = json.loads((tmp / "modelling" / "station.json").read_text())
    assert recorded  # the station's own record of the run
