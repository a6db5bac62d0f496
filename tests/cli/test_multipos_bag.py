"""``thermocal multipos`` reads a ROS bag as tumble and ratetable do: ``--topic`` picks the
board's IMU among two, ``--stamp`` picks the clock.  A simulated hand-placed session with a
known accelerometer and gyro (the simulator's truth) logged beside a second, error-free IMU:
each topic gives its own sensor's bias; the receive stamps, running at twice the header
stamps' pace, double the rotations' angles and the gyro's scale factors come out +100 %,
which the command refuses; two IMU topics and none named: the refusal names ``--topic``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from bag_writer import NS, Topic, write_bag
from gsens_session import ACCEL_THETA, GYRO_THETA, LATITUDE_DEG, run
from thermocal.multipos.simulate import simulate_session

MG_M_S2 = 9.80665e-3
"""One mg in m/s² (standard gravity, CGPM 1901)."""
DEG_H_RAD_S = np.pi / 180.0 / 3600.0
"""One °/h in rad/s."""


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("mpbag")
    board = simulate_session(np.random.default_rng(5), ACCEL_THETA, GYRO_THETA,
                             latitude_deg=LATITUDE_DEG)  # fmt: skip
    other = simulate_session(np.random.default_rng(6), np.zeros(12), np.zeros(12),
                             latitude_deg=LATITUDE_DEG)  # fmt: skip
    n = min(board["time_s"].size, other["time_s"].size)
    header = (1_700_000_000 * NS + np.round(board["time_s"][:n] * NS)).astype(np.int64)
    receive = header[0] + 2 * (header - header[0])

    def rows(s: dict) -> np.ndarray:  # rad/s and m/s², as sensor_msgs/Imu holds them
        return np.column_stack([np.radians(s["gyro_deg_s"][:n]), s["accel_mg"][:n] * MG_M_S2])

    return write_bag(d / "session.bag", "ros1", [
        Topic("/imu_board", "sensor_msgs/msg/Imu", header, receive, rows(board)),
        Topic("/imu_other", "sensor_msgs/msg/Imu", header, receive, rows(other)),
    ])  # fmt: skip


def _multipos(bag: Path, *extra: str, out: str = "cal.json") -> tuple[int, str, str]:
    return run(["multipos", str(bag), "--accel", "accel_x,accel_y,accel_z", "--gyro",
                "gyro_x,gyro_y,gyro_z", "--latitude", str(LATITUDE_DEG), "--json", "-o",
                str(bag.parent / out), *extra])  # fmt: skip


def test_the_topic_picks_the_board(bag: Path) -> None:
    code, out, err = _multipos(bag, "--topic", "/imu_board")
    assert code == 0, err
    res = json.loads(out)
    assert res["unit"] == "m/s^2" and res["n_poses"] >= 14
    for sensor, truth in (("accel", ACCEL_THETA[:3] * MG_M_S2),
                          ("gyro", GYRO_THETA[:3] * DEG_H_RAD_S)):  # fmt: skip
        got, sd = np.array(res[sensor]["bias"]), np.array(res[sensor]["bias_sigma"])
        assert np.all(np.abs(got - truth) < 4 * sd), (sensor, got, truth, sd)
    # the other IMU has no bias: its topic gives its own
    code, out, err = _multipos(bag, "--topic", "/imu_other")
    assert code == 0, err
    res = json.loads(out)
    got, sd = np.array(res["accel"]["bias"]), np.array(res["accel"]["bias_sigma"])
    assert np.all(np.abs(got) < 4 * sd), (got, sd)


def test_the_stamp_picks_the_clock(bag: Path) -> None:
    code, _out, err = _multipos(bag, "--topic", "/imu_board", "--stamp", "receive",
                                out="receive.json")  # fmt: skip
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert "the gyro's scale factors come out x +9" in lines[0] and "--gyro-unit" in lines[0]
    assert not (bag.parent / "receive.json").exists()
    code, _out, err = _multipos(bag, "--topic", "/imu_board", "--stamp", "header",
                                out="header.json")  # fmt: skip
    assert code == 0 and (bag.parent / "header.json").exists(), err


def test_two_imu_topics_and_none_named(bag: Path) -> None:
    code, _out, err = _multipos(bag)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "--topic" in lines[0], err
