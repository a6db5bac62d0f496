"""``thermocal report`` of a multipos calibration of triads (issue 38): the report honours
``--title`` and ``--sensor``; a triad calibrated without a temperature column (or at one
temperature) gets a table, not twelve single points plotted against a temperature nobody
measured; with ``--temps`` over several sessions its parameters are plotted against the
real temperatures; no column of ``nan``; a gyro bias in the calibration's unit (°/s for a
°/s calibration, not °/h); the held-out figures as absolute figures (rms before → after).

Sessions are written as a consumer-IMU logger writes them (``timestamp, ax … gz`` int16
counts of an MPU-6050 at ±4 g and ±2000 °/s, and a temperature column for the sessions at
several temperatures); the expected numbers come from the simulator's truth (biases in °/s,
each within 4σ of the report's own σ) and a numpy computation written here (the held-out
gravity-magnitude error before compensation, rms over the truth's still windows).
"""

from __future__ import annotations

import contextlib
import html as _html
import io
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from thermocal.cli import main
from thermocal.multipos.simulate import simulate_attitudes, simulate_session

ACC_MG_PER_COUNT = 1000.0 / 8192.0
GYR_DPS_PER_COUNT = 1.0 / 16.4
MG_M_S2 = 9.80665e-3
TRIM = 30
G_BIAS_25 = np.array([3000.0, -2000.0, 1500.0])  # °/h at 25 °C
G_BIAS_SLOPE = np.array([40.0, -25.0, 30.0])  # °/h per °C
TEMPS = (10.0, 25.0, 40.0)


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def _truth(temp_c: float) -> tuple[np.ndarray, np.ndarray]:
    ta, tg = np.zeros(12), np.zeros(12)
    ta[0:3], ta[3:6] = [30.0, -45.0, 25.0], [6000.0, -4000.0, 3000.0]
    ta[[8, 10, 11]] = [300.0, -250.0, 200.0]
    tg[0:3] = G_BIAS_25 + G_BIAS_SLOPE * (temp_c - 25.0)
    tg[3:6] = [4000.0, -3000.0, 2500.0]
    return ta, tg


def _write(path: Path, seed: int, temp_c: float | None, static_s: float | None = None) -> dict:
    """A session in int16 counts (with a ``temp_degC`` column when ``temp_c`` is given)."""
    ta, tg = _truth(25.0 if temp_c is None else temp_c)
    rng = np.random.default_rng(seed)
    if static_s is None:
        s = simulate_session(rng, ta, tg, n_poses=16, accel_noise_mg=1.5)
    else:
        att = Rotation.random(random_state=seed).as_matrix()
        s = simulate_attitudes(rng, [att], ta, tg, dwell_s=static_s, accel_noise_mg=1.5)
    acc = np.clip(np.round(s["accel_mg"] / ACC_MG_PER_COUNT), -32768, 32767).astype(np.int16)
    gyr = np.clip(np.round(s["gyro_deg_s"] / GYR_DPS_PER_COUNT), -32768, 32767).astype(np.int16)
    t = np.round(s["time_s"], 3)
    head = "timestamp,ax,ay,az,gx,gy,gz" + ("" if temp_c is None else ",temp_degC")
    tail = "" if temp_c is None else f",{temp_c:.2f}"
    lines = [head] + [
        f"{t[i]:.3f},{acc[i, 0]},{acc[i, 1]},{acc[i, 2]},{gyr[i, 0]},{gyr[i, 1]},{gyr[i, 2]}{tail}"
        for i in range(t.size)
    ]
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return {"sim": s, "acc": acc.astype(np.float64)}


COUNTS = ["--time", "timestamp", "--time-unit", "s", "--accel", "ax,ay,az", "--gyro",
          "gx,gy,gz", "--accel-unit", "counts", "--gyro-unit", "counts", "--accel-scale",
          f"{ACC_MG_PER_COUNT!r},mg", "--gyro-scale", f"{GYR_DPS_PER_COUNT!r},deg/s",
          "--latitude", "45"]  # fmt: skip
READ = ["--time", "timestamp", "--time-unit", "s"]


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("reporttriads")
    _write(d / "cal.csv", 11, None)
    held = _write(d / "held.csv", 12, None)
    _write(d / "static.csv", 21, None, static_s=20.0)
    code, _o, err = _run(["multipos", str(d / "cal.csv"), *COUNTS, "-o", str(d / "cal.json")])
    assert code == 0, err
    for k, temp in enumerate(TEMPS):
        _write(d / f"cal_{temp:g}.csv", 30 + k, temp)
    _write(d / "held_25.csv", 40, 25.0)
    several = [str(d / f"cal_{temp:g}.csv") for temp in TEMPS]
    code, _o, err = _run(["multipos", *several, *COUNTS, "--temps", "temp_degC", "--order",
                          "1", "-o", str(d / "cal_t.json")])  # fmt: skip
    assert code == 0, err
    code, out, err = _run(["multipos", str(d / "cal_25.csv"), *COUNTS, "--temps", "temp_degC",
                           "-o", str(d / "cal_one_t.json"), "--json"])  # fmt: skip
    assert code == 0, err
    one = json.loads(out)["gyro"]
    assert one["bias_unit"] == "deg/s"
    return {"dir": d, "held": held, "session_bias_sigma_dps": one["bias_sigma"]}


def _report(d: Path, cal: str, rec: str, name: str, *extra: str) -> str:
    out = d / name
    code, _o, err = _run(["report", "--model", str(d / cal), "--recording", str(d / rec),
                          *READ, "-o", str(out), *extra])  # fmt: skip
    assert code == 0, err
    return out.read_text(encoding="utf-8")


def _table(html: str, table_id: str) -> list[list[str]]:
    """The body rows of the table ``table_id``, each cell's text."""
    body = html.split(f'id="{table_id}"')[1].split("</table>")[0].split("<tbody>")[1]
    rows = re.findall(r"<tr>(.*?)</tr>", body, flags=re.S)
    return [[_html.unescape(re.sub(r"<[^>]+>", "", c)).strip()
             for c in re.findall(r"<td[^>]*>(.*?)</td>", r, flags=re.S)] for r in rows]  # fmt: skip


def _text(html: str) -> str:
    t = re.sub(r"<(style|script)[^>]*>.*?</\1>", " ", html, flags=re.S)
    return _html.unescape(re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", t)))


def test_title_sensor_units_and_no_invented_temperature(files: dict[str, Any]) -> None:
    d = files["dir"]
    html = _report(d, "cal.json", "held.csv", "r.html", "--title", "MPU-6050 bench",
                   "--sensor", "SN-0042")  # fmt: skip
    assert "<title>MPU-6050 bench — SN-0042</title>" in html
    assert "<h1>MPU-6050 bench</h1>" in html and "SN-0042" in _text(html)
    # no temperature column: no plot against temperature, said so
    assert 'id="fig-accel"' not in html and 'id="fig-gyro"' not in html
    assert "without a temperature column" in _text(html)
    assert "nan" not in _text(html).lower().split()
    # the gyro bias in the calibration's unit, °/s, the truth within 4σ
    rows = {r[0]: r for r in _table(html, "params-gyro")}
    for k, a in enumerate("xyz"):
        name, unit, value, sigma = rows[f"bias_{a}"][:4]
        assert unit == "deg/s"
        assert abs(float(value) - G_BIAS_25[k] / 3600.0) < 4 * float(sigma), rows[name]
    # the absolute held-out figures: before as computed here, after far below
    h = files["held"]
    f = h["acc"] * ACC_MG_PER_COUNT
    g_mg = h["sim"]["g_m_s2"] / MG_M_S2
    e = [np.linalg.norm(f[a + TRIM : b - TRIM].mean(axis=0)) - g_mg for a, b in h["sim"]["poses"]]
    summary = {r[0]: r for r in _table(html, "validation-summary")}
    _triad, what, n, before, after, change, unit = summary["accel"]
    assert what == "gravity-magnitude error rms" and unit == "mg" and int(n) == len(e)
    assert float(before) == pytest.approx(math.sqrt(np.mean(np.square(e))), rel=2e-3)
    assert float(after) < 0.01 * float(before) and float(change.rstrip(" %")) > 99.0
    assert summary["gyro"][1] == "rotation-angle error rms" and summary["gyro"][6] == "deg"


def test_one_temperature_is_a_table(files: dict[str, Any]) -> None:
    """A session with a temperature column at one temperature: a table at the measured
    temperature, no plot and no LOTO column (it needs several temperatures; said)."""
    d = files["dir"]
    html = _report(d, "cal_one_t.json", "held_25.csv", "r1.html")
    text = _text(html)
    assert 'id="fig-gyro"' not in html and "Calibrated at one temperature, 25 °C" in text
    assert "LOTO rms" not in html.split('id="params-gyro"')[1].split("</thead>")[0]
    assert "nan" not in text.lower().split()


def test_over_temperature_plots_against_the_real_temperatures(files: dict[str, Any]) -> None:
    """Three sessions at 10, 25 and 40 °C (``--temps``): a figure per triad, and the runs
    at those temperatures with the gyro bias in °/s, the truth's b(T) within 4σ of one
    session's bias (σ of the 25 °C session calibrated alone, ``multipos --json``)."""
    d = files["dir"]
    html = _report(d, "cal_t.json", "held_25.csv", "rt.html")
    assert 'id="fig-accel"' in html and 'id="fig-gyro"' in html
    runs = html.split('id="triad-gyro"')[1].split('class="compact runs"')[1]
    head = re.findall(r"<th>([^<]*)</th>", runs.split("</thead>")[0])
    assert head[1] == "bias_x [deg/s]"
    rows = _table('id="x"' + runs, "x")
    assert [float(r[0]) for r in rows] == pytest.approx(list(TEMPS), abs=1e-6)
    params = {r[0]: r for r in _table(html, "params-gyro")}
    assert params["bias_x"][1] == "deg/s"
    sigma = files["session_bias_sigma_dps"]
    for r, temp in zip(rows, TEMPS, strict=True):
        for k in range(3):
            truth = (G_BIAS_25[k] + G_BIAS_SLOPE[k] * (temp - 25.0)) / 3600.0
            assert abs(float(r[1 + k]) - truth) < 4 * sigma[k], (r, truth)


def test_one_static_pose_report_says_what_is_not_judged(files: dict[str, Any]) -> None:
    d = files["dir"]
    html = _report(d, "cal.json", "static.csv", "rs.html")
    text = _text(html)
    assert 'id="not-judged-accel"' in html and "rotation-angle error needs motions" in text
    summary = {r[0]: r for r in _table(html, "validation-summary")}
    assert summary["gyro"][1] == "mean rate at rest" and summary["gyro"][6] == "deg/s"
    assert int(summary["accel"][2]) == 1
