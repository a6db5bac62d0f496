"""``thermocal noise SHEET --from-datasheet``: Kalibr's imu.yaml from a TOML file of
data-sheet figures; hostile files and figures end in exit 2 with one line naming the file."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
import yaml

from thermocal.cli import main

SHEET = """# BMI088 data sheet (Bosch BST-BMI088-DS001): gyro 0.014 °/s/√Hz, accel 175 µg/√Hz
update_rate_hz = 400
gyro_noise_density = "0.014 °/s/√Hz"
accel_noise_density = "175 µg/√Hz"
gyro_random_walk = "2 deg/h/sqrt(h)"
accel_bias_instability = "40 ug"
"""


def _run(sheet: Path, out: Path, *extra: str) -> int:
    return main(["noise", str(sheet), "--from-datasheet", "-o", str(out), *extra])


def test_kalibr_file_from_the_sheet(tmp_path: Path) -> None:
    sheet = tmp_path / "bmi088.toml"
    sheet.write_text(SHEET, encoding="utf-8")
    before = sheet.read_bytes()
    assert _run(sheet, tmp_path / "imu.yaml", "--inflate", "2") == 0
    k = yaml.safe_load((tmp_path / "imu.yaml").read_text(encoding="utf-8"))
    n_g = 0.014 * math.pi / 180.0
    n_a = 175e-6 * 9.80665
    assert k["gyroscope_noise_density"] == pytest.approx(2 * n_g, rel=1e-6)
    assert k["accelerometer_noise_density"] == pytest.approx(2 * n_a, rel=1e-6)
    assert k["gyroscope_random_walk"] == pytest.approx(2 * 2 * math.pi / 180 / 3600 / 60, rel=1e-6)
    sigma = 40e-6 * 9.80665  # K = √3 σ_min² / (2N)
    assert k["accelerometer_random_walk"] == pytest.approx(
        2 * math.sqrt(3) * sigma**2 / (2 * n_a), rel=1e-6
    )
    assert k["update_rate"] == 400.0 and k["rostopic"] == "/imu0"
    assert sheet.read_bytes() == before
    assert _run(sheet, tmp_path / "imu.json", "--format", "json") == 0
    d = json.loads((tmp_path / "imu.json").read_text(encoding="utf-8"))
    assert d["from"] == "datasheet" and d["inflate"] == 1.0
    assert d["figures"]["accelerometer_random_walk"]["source"].startswith("derived")


@pytest.mark.parametrize(
    ("text", "words"),
    [
        (SHEET.replace('"0.014 °/s/√Hz"', '"1000 deg/sqrt(h)"'), "outside any gyro"),
        (SHEET.replace("µg/√Hz", "furlong/√Hz"), "unit 'furlong/√Hz'"),
        (SHEET.replace("update_rate_hz = 400\n", ""), "no update_rate_hz"),
        (SHEET.replace('"40 ug"', "40"), "give a value and its unit"),
        (SHEET + 'gyro_nois = "1 deg/s"\n', "unknown figure 'gyro_nois'"),
        (SHEET.replace("accel_bias_instability", "accel_thing"), "unknown figure"),
        ("update_rate_hz = [", "not a TOML file"),
    ],
)
def test_hostile_sheet_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, words: str
) -> None:
    sheet = tmp_path / "s.toml"
    sheet.write_text(text, encoding="utf-8")
    assert _run(sheet, tmp_path / "imu.yaml") == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and words in err[0], err
    assert str(sheet) in err[0]
    assert not (tmp_path / "imu.yaml").exists()


def test_recording_still_needs_the_gyro(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    csv = tmp_path / "r.csv"
    csv.write_text("time,g\n0,1\n", encoding="utf-8")
    assert main(["noise", str(csv), "-o", str(tmp_path / "x.yaml")]) == 2
    assert "--gyro X,Y,Z" in capsys.readouterr().err
    sheet = tmp_path / "s.toml"
    sheet.write_text(SHEET, encoding="utf-8")
    assert _run(sheet, sheet) == 2  # never over the input
