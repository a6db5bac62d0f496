"""The ROS bag tutorial (``docs/tutorials/ros-bags.md``) runs as written: every block in
order in an empty folder, what it prints equal to the page's ``text`` block, and its
figures the simulated truth the page draws its samples with (white noise of density
N = 2·10⁻⁴ rad/s/√Hz and 2·10⁻³ m/s²/√Hz at 200 Hz; 240 swapped and 119 repeated
messages)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tutorial_pages import TUTORIALS, _numbers, _run_in_scratch

pytest.importorskip("rosbags")

PAGE = "ros-bags.md"
GYRO_N, ACCEL_N = 2e-4, 2e-3


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[tuple[str, str]], Path]:
    tmp = tmp_path_factory.mktemp("ros-bags")
    return _run_in_scratch(tmp, PAGE), tmp


def test_ros_bag_tutorial_prints_what_the_page_shows(
    page: tuple[list[tuple[str, str]], Path],
) -> None:
    pairs, _ = page
    assert len(pairs) == 5
    for printed, shown in pairs:
        assert _numbers(printed) == _numbers(shown)
        # rich versions differ in the spaces padding a table's title line: compare lines
        # without their trailing spaces
        lines = [ln.rstrip() for ln in printed.strip().splitlines()]
        assert lines == [ln.rstrip() for ln in shown.strip().splitlines()]


def test_ros_bag_tutorial_figures_are_the_simulated_truth(
    page: tuple[list[tuple[str, str]], Path],
) -> None:
    pairs, tmp = page
    assert pairs[0][0].startswith("imu_bag: 120119 Imu messages (120000 samples)")
    assert "120000 samples over 599.995 s, sample rate 200 Hz, 0 gaps" in pairs[1][0]
    values = {k: float(v) for k, v in re.findall(r"^(\w+): ([-\d.e+]+)$", pairs[3][0], re.M)}
    assert values["gyroscope_noise_density"] == pytest.approx(GYRO_N, rel=0.01)
    assert values["accelerometer_noise_density"] == pytest.approx(ACCEL_N, rel=0.01)
    assert values["update_rate"] == 200.0
    assert (tmp / "imu.yaml").is_file()
    swaps, repeats = len(range(250, 120_000 - 1, 500)), len(range(1000, 120_000, 1000))
    said = f"{swaps} header stamps out of order (sorted) and {repeats} exact duplicates"
    assert said in pairs[4][0]
    text = (TUTORIALS / PAGE).read_text(encoding="utf-8")
    assert f"warning: imu_bag: /imu: {swaps} header stamps" in text
