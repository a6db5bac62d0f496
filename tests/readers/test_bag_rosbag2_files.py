"""ROS 2 bags written by the ROS 2 tools themselves (rosbag2's test bags, in
``tests/data/rosbag2_test_bags``) and bags that store no message definitions, as every bag
recorded with ROS 2 Foxy, Galactic or Humble does."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import numpy as np
import pytest

from bag_writer import NS, Topic, storage_file, write_bag
from thermocal.cli import main
from thermocal.errors import MissingColumnError
from thermocal.readers.bag import read_bag

pytest.importorskip("rosbags")

DATA = Path(__file__).parents[1] / "data" / "rosbag2_test_bags"


@pytest.mark.parametrize("name", ["talker_sqlite3", "talker_mcap", "empty_bag_v4"])
def test_real_ros2_bags_without_an_imu_are_refused_naming_their_topics(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = DATA / name
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    with pytest.raises(MissingColumnError) as e:
        read_bag(folder)
    text = str(e.value)
    assert "no sensor_msgs/Imu topic" in text and "record the IMU as sensor_msgs/Imu" in text
    assert "/rosout (rcl_interfaces/msg/Log" in text
    if name.startswith("talker"):
        assert "/topic (std_msgs/msg/String, 10 messages)" in text
    assert main(["inspect", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and "default_typestore" not in err
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before


def test_a_bag_without_message_definitions_is_read(tmp_path: Path) -> None:
    """rosbag2 stores the message definitions from ROS 2 Iron on; a Humble bag has only the
    type names, and rosbags reads it only with definitions supplied."""
    n = 50
    stamps = 1_700_000_000 * NS + np.arange(n, dtype=np.int64) * (NS // 100)
    rng = np.random.default_rng(0)
    values = rng.normal(size=(n, 6))
    imu = Topic("/imu", "sensor_msgs/msg/Imu", stamps, stamps + 1000, values)
    folder = write_bag(tmp_path / "humble", "sqlite3", [imu])
    with sqlite3.connect(storage_file(folder)) as db:  # as a Humble recorder leaves it
        db.execute("DELETE FROM message_definitions")
    df, _info = read_bag(folder)
    got = df[["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]].to_numpy()
    np.testing.assert_array_equal(got, values)
    np.testing.assert_allclose(df["time"].to_numpy(), (stamps - stamps[0]) / NS, atol=1e-9)
