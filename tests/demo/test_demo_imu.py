"""``thermocal demo --imu``: the six-channel workflow (issue 15) ends in one calibration,
one C module and one report whose numbers are the CLI's own per-channel figures."""

from __future__ import annotations

import contextlib
import io
import json
import re
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from report_checks import (
    check_number,
    check_rendered,
    run_chromium,
    skip_without_chromium,
    tagged_numbers,
)
from thermocal.cli import main
from thermocal.simulate import IMU_CHANNELS

NAMES = [n for n, _u in IMU_CHANNELS]


def _run(args: list[str]) -> tuple[int, str]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        status = main(args)
    return status, buf.getvalue()


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("imu-demo") / "d"
    status, text = _run(["demo", "--imu", "--quick", "--seed", "2", "-o", str(out), "--json"])
    assert status == 0, text
    return {"dir": out, "summary": json.loads(text)}


def test_every_channel_removes_97_percent_of_the_true_bias(demo: dict[str, Any]) -> None:
    ch = demo["summary"]["channels"]
    assert list(ch) == NAMES
    for name, unit in IMU_CHANNELS:
        assert ch[name]["unit"] == unit
        assert ch[name]["removed_pct"] >= 97.0, (name, ch[name]["removed_pct"])
        # figures are in the channel's own unit: the gyro bias span of the scenario is a
        # few hundredths of a deg/s, not tens of deg/h
        assert ch[name]["rms_after"] < ch[name]["rms_before"]
        if unit == "deg/s":
            assert ch[name]["rms_before"] < 0.2


def test_demo_figures_equal_the_validate_command(demo: dict[str, Any]) -> None:
    """The report's validation figures are what ``thermocal validate`` prints for the
    calibration, channel by channel, in the data's unit."""
    d: Path = demo["dir"]
    status, text = _run([
        "validate", str(d / "models" / "imu.json"), str(d / "data" / "imu-validation.parquet"),
        "--modeling", str(d / "data" / "imu-modelling.parquet"), "--ambient", "T_chamber",
        "--json",
    ])  # fmt: skip
    assert status == 0, text
    v = json.loads(text)["channels"]
    for name in NAMES:
        for key in ("r", "rms_before", "rms_after", "bias_stability_after"):
            got, want = demo["summary"]["channels"][name][key], v[name][key]
            assert got == pytest.approx(want, rel=1e-9), (name, key)


def test_compensated_file_is_raw_minus_model(demo: dict[str, Any]) -> None:
    d: Path = demo["dir"] / "data"
    comp = pd.read_parquet(d / "imu-validation-compensated.parquet")
    raw = pd.read_parquet(d / "imu-validation.parquet")
    for name in NAMES:
        np.testing.assert_allclose(comp[f"{name}_comp"], raw[name] - comp[f"{name}_model"],
                                   rtol=0, atol=1e-9)  # fmt: skip
    # +z is up: the compensated z accelerometer keeps gravity, the others read about 0
    assert float(comp["az_comp"].mean()) == pytest.approx(1000.0, abs=0.5)
    assert abs(float(comp["ax_comp"].mean())) < 0.5


def test_report_table_shows_the_json_numbers(demo: dict[str, Any]) -> None:
    html = (demo["dir"] / "report.html").read_text()
    assert re.findall(r'<tr data-channel="(\w+)"', html) == NAMES
    tags = tagged_numbers(html)
    v = json.loads((demo["dir"] / "validation.json").read_text())["channels"]
    for name in NAMES:
        ch = demo["summary"]["channels"][name]
        check_number(tags, f"channels.{name}.extra.0", ch["removed_pct"])
        check_number(tags, f"channels.{name}.validation.rms_after", ch["rms_after"])
        check_number(tags, f"channels.{name}.validation.rms_after", v[name]["rms_after"])


def test_one_c_module_compiles(demo: dict[str, Any], tmp_path: Path) -> None:
    from thermocal.export.c import CFLAGS, find_compiler

    cc = find_compiler()
    if cc is None:
        pytest.skip("no C compiler")
    d: Path = demo["dir"] / "c"
    assert sorted(p.name for p in d.iterdir()) == ["imu.c", "imu.h"]  # one module
    proc = subprocess.run([cc, *CFLAGS, "-c", str(d / "imu.c"), "-I", str(d),
                           "-o", str(tmp_path / "imu.o")],
                          capture_output=True, text=True, check=False)  # fmt: skip
    assert proc.returncode == 0, proc.stderr


def test_imu_report_renders_in_headless_chromium(demo: dict[str, Any], tmp_path: Path) -> None:
    skip_without_chromium()
    result = run_chromium(demo["dir"] / "report.html", tmp_path)
    check_rendered(result, n_figures_min=2)
