"""ROS 1 bags, ROS 2 bags (sqlite3 and MCAP storage) and MCAP files
(:mod:`thermocal.readers.bag`), written here with ``rosbags``' writers from arrays whose
every number the test knows: messages received out of header-stamp order, exact duplicates,
a 1 Hz temperature topic joined to the IMU's stamps."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from bag_writer import KINDS, NS, Topic, storage_file, write_bag
from thermocal.errors import (
    FileFormatError,
    MissingColumnError,
    ParameterError,
    ThermocalInputError,
    TimestampWarning,
)
from thermocal.readers import read_recording
from thermocal.readers.bag import read_bag
from thermocal.readers.formats import format_of
from thermocal.readers.options import ReadOptions

pytest.importorskip("rosbags")

N = 600
DT_NS = 5_000_000  # 200 Hz
T0_NS = 1_732_000_000 * NS + 987_654_321
SWAPPED = (100, 250, 401)  # message i+1 received before message i
DUPLICATED = (30, 500)  # received a second time, 1 ms after the first


def _truth(seed: int = 7) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    header = T0_NS + np.arange(N, dtype=np.int64) * DT_NS
    values = np.column_stack(
        [rng.normal(0.0, 0.01, (N, 3)), rng.normal((0.0, 0.0, 9.81), 0.05, (N, 3))]
    )
    return header, values


def _topics(frames: bool = False) -> tuple[list[Topic], np.ndarray, np.ndarray]:
    """The IMU topic as received (swaps, duplicates) and a 1 Hz thermometer; returns the
    topics and the truth (header stamps, values) in time order."""
    header, values = _truth()
    order = np.arange(N)
    for i in SWAPPED:
        order[i], order[i + 1] = order[i + 1], order[i]
    recv = header + 2_000_000  # 2 ms after sampling, in the order received
    rows = list(order) + list(DUPLICATED)
    rec = list(recv) + [int(recv[i]) + 1_000_000 for i in DUPLICATED]
    frame_ids = [("imu" + "_" * (i % 3)) for i in range(len(rows))] if frames else None
    imu = Topic("/imu", "sensor_msgs/msg/Imu", header[rows], np.asarray(rec), values[rows],
                frame_ids)  # fmt: skip
    t_header = T0_NS - NS // 2 + np.arange(5, dtype=np.int64) * NS
    temp = Topic("/imu/temperature", "sensor_msgs/msg/Temperature", t_header,
                 t_header + 3_000_000, (25.0 + 0.25 * np.arange(5)).reshape(-1, 1))  # fmt: skip
    return [imu, temp], header, values


@pytest.fixture(scope="module", params=KINDS)
def bag(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Path:
    topics, _, _ = _topics()
    name = "imu.bag" if request.param == "ros1" else "imu"
    return write_bag(tmp_path_factory.mktemp(request.param) / name, request.param, topics)


def _read(path: Path, topic: str | None = "/imu", stamp: str = "header") -> tuple:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        df, info = read_bag(path, topic, stamp)  # type: ignore[arg-type]
    return df, info, [str(w.message) for w in caught]


def test_header_stamps_sorted_duplicates_dropped_and_counted(bag: Path) -> None:
    header, values = _truth()
    df, info, said = _read(bag)
    assert list(df.columns) == ["time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y",
                                "accel_z", "temperature"]  # fmt: skip
    assert len(df) == N
    # seconds since the first stamp, exact; the first in the metadata
    np.testing.assert_array_equal(df["time"].to_numpy(), (header - T0_NS) / 1e9)
    assert info["metadata"] == {"time_origin_ns": T0_NS, "stamp": "header"}
    np.testing.assert_array_equal(df.iloc[:, 1:7].to_numpy(), values)
    assert info["units"]["gyro_x"] == "rad/s" and info["units"]["accel_z"] == "m/s^2"
    assert info["units"]["temperature"] == "degC" and info["time_unit"] == "s"
    assert len(said) == 1
    assert f"{len(SWAPPED)} header stamps out of order (sorted)" in said[0]
    assert f"{len(DUPLICATED)} exact duplicates (dropped)" in said[0]
    assert "stamp receive" in said[0]


def test_temperature_joined_linearly_at_the_imu_stamps(bag: Path) -> None:
    header, _ = _truth()
    t_header = T0_NS - NS // 2 + np.arange(5, dtype=np.int64) * NS
    want = np.interp((header - T0_NS) / 1e9, (t_header - T0_NS) / 1e9, 25.0 + 0.25 * np.arange(5))
    df, _, _ = _read(bag)
    np.testing.assert_allclose(df["temperature"].to_numpy(), want, rtol=0, atol=1e-12)
    # the thermometer alone
    dft, _, said = _read(bag, "/imu/temperature")
    np.testing.assert_array_equal(dft["temperature"].to_numpy(), 25.0 + 0.25 * np.arange(5))
    assert said == []


def test_receive_stamps_on_request(bag: Path) -> None:
    topics, _, _ = _topics()
    imu = topics[0]
    df, _, said = _read(bag, stamp="receive")
    assert said == []  # written in receive order, the duplicates 1 ms later: nothing to repair
    order = np.argsort(imu.receive_ns, kind="stable")
    recv = imu.receive_ns[order]
    np.testing.assert_array_equal(df["time"].to_numpy(), (recv - recv[0]) / 1e9)
    np.testing.assert_array_equal(df["gyro_y"].to_numpy(), imu.values[order, 1])


def test_every_reading_path_reads_a_bag(bag: Path) -> None:
    _, values = _truth()
    assert format_of(bag).name == "rosbag"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TimestampWarning)
        rec = read_recording(bag, ReadOptions(topic="/imu", signals=("gyro_x", "accel_z")))
    np.testing.assert_array_equal(rec.column("gyro_x"), values[:, 0])
    np.testing.assert_array_equal(rec.column("accel_z"), values[:, 5])


def test_mcap_and_db3_storage_files_alone(tmp_path: Path) -> None:
    topics, _, values = _topics()
    for kind in ("mcap", "sqlite3"):
        folder = write_bag(tmp_path / kind, kind, topics)
        single = storage_file(folder)
        assert format_of(single).name == "rosbag"
        df, _, said = _read(single)
        np.testing.assert_array_equal(df["accel_x"].to_numpy(), values[:, 3])
        assert len(said) == 1


def test_messages_of_several_layouts_read_one_by_one(tmp_path: Path) -> None:
    """frame_id of three lengths: no batch of one layout, every message deserialized."""
    topics, _, values = _topics(frames=True)
    for kind in KINDS:
        path = write_bag(tmp_path / f"{kind}.bag" if kind == "ros1" else tmp_path / kind,
                         kind, topics)  # fmt: skip
        df, _, _ = _read(path)
        np.testing.assert_array_equal(df.iloc[:, 1:7].to_numpy(), values)


def test_topic_choices_and_their_errors(tmp_path: Path) -> None:
    topics, _, _ = _topics()
    path = write_bag(tmp_path / "x.bag", "ros1", topics, extra=["/chatter"])
    df, _, _ = _read(path, None)  # the only Imu topic
    assert len(df) == N
    with pytest.raises(MissingColumnError) as e:
        read_bag(path, "/imu0")
    assert "no topic /imu0" in str(e.value)
    assert "/chatter (std_msgs/msg/String, 1 messages)" in str(e.value)
    assert "/imu (sensor_msgs/msg/Imu, 602 messages)" in str(e.value)
    with pytest.raises(ThermocalInputError, match="/chatter is std_msgs/msg/String"):
        read_bag(path, "/chatter")
    with pytest.raises(ThermocalInputError, match="not a Temperature"):
        read_bag(path, "/imu,/chatter")
    only_temp = write_bag(tmp_path / "t.bag", "ros1", topics[1:])
    with pytest.raises(MissingColumnError, match="no sensor_msgs/Imu topic; choose a sensor_msg"):
        read_bag(only_temp, None)

    with pytest.raises(ThermocalInputError, match="stamp must be header or receive"):
        read_bag(path, "/imu", "arrival")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="stamp must be header or receive"):
        ReadOptions(stamp="arrival")  # type: ignore[arg-type]


def test_several_thermometers_none_joined_unless_named(tmp_path: Path) -> None:
    topics, _, _ = _topics()
    second = Topic("/board/temperature", topics[1].msgtype, topics[1].header_ns,
                   topics[1].receive_ns + 1, topics[1].values + 10.0)  # fmt: skip
    path = write_bag(tmp_path / "two", "mcap", [*topics, second])
    df, _, said = _read(path, "/imu")
    assert "temperature" not in df.columns
    assert any("several sensor_msgs/Temperature topics (/board/temperature, "
               "/imu/temperature): none joined to /imu" in w for w in said)  # fmt: skip
    df, _, _ = _read(path, "/imu,/board/temperature")
    assert df["temperature"].iloc[0] == pytest.approx(35.0 + 0.25 * 0.5, abs=1e-12)


def test_a_stamp_repeated_with_other_values_is_refused(tmp_path: Path) -> None:
    header, values = _truth()
    imu = Topic("/imu", "sensor_msgs/msg/Imu", np.r_[header[:10], header[5]],
                np.arange(11) * DT_NS + T0_NS, np.vstack([values[:10], values[6]]))  # fmt: skip
    path = write_bag(tmp_path / "clash", "sqlite3", [imu])
    with pytest.raises(FileFormatError, match="1 messages of /imu repeat the header stamp"):
        read_bag(path)
    df, _, said = _read(path, stamp="receive")  # the bag's own times tell them apart
    assert len(df) == 11 and said == []


def test_without_rosbags_one_error_names_the_extra(
    bag: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "rosbags.highlevel", None)
    with pytest.raises(ThermocalInputError, match=r"pip install 'thermocal\[bags\]'"):
        read_bag(bag)


def test_fixed_layout_messages_are_gathered_not_deserialized_one_by_one(
    bag: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Messages of one length: numpy reads the fields at the offsets of the message
    definition, the deserializer checks the first of each batch only."""
    from thermocal.readers import bag as bag_module

    calls: list[int] = []
    slow = bag_module._slow

    def counted(reader, conn, raws, kind):  # type: ignore[no-untyped-def]
        calls.append(len(raws))
        return slow(reader, conn, raws, kind)

    monkeypatch.setattr(bag_module, "_slow", counted)
    _, values = _truth()
    df, _, _ = _read(bag)
    np.testing.assert_array_equal(df.iloc[:, 1:7].to_numpy(), values)
    assert calls == [1, 1]  # the IMU's one batch and the thermometer's


def test_temperature_outside_its_readings_is_nan(tmp_path: Path) -> None:
    topics, header, _ = _topics()
    late = Topic("/imu/temperature", topics[1].msgtype, header[[100, 300]],
                 header[[100, 300]] + 1, np.array([[30.0], [32.0]]))  # fmt: skip
    path = write_bag(tmp_path / "late.bag", "ros1", [topics[0], late])
    df, _, _ = _read(path)
    temp = df["temperature"].to_numpy()
    assert np.isnan(temp[:100]).all() and np.isnan(temp[301:]).all()
    np.testing.assert_allclose(temp[100:301], 30.0 + 2.0 * np.arange(201) / 200, atol=1e-12)
