"""ROS bags and MCAP files on the command line: ``thermocal noise bag --topic /imu --format
kalibr`` gives the figures of the same samples written to a CSV (ROS 1 ``.bag``, ROS 2
sqlite3 and MCAP folders, a bare ``.mcap``, all written here with ``rosbags``' writers, with
messages received out of header-stamp order); hostile bags end in one ``error:`` line with
the input untouched."""

from __future__ import annotations

import hashlib
import math
import shutil
import struct
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from bag_writer import KINDS, NS, Topic, storage_file, write_bag
from thermocal.cli import main

pytest.importorskip("rosbags")

FS_HZ = 100.0
N = 30_000  # 300 s
GYRO_DENSITY = 2.0e-4  # rad/s/√Hz
ACCEL_DENSITY = 2.0e-3  # m/s²/√Hz
T0_NS = 1_700_000_000 * NS + 123_456_789
GYRO = "gyro_x,gyro_y,gyro_z"
ACCEL = "accel_x,accel_y,accel_z"


def _samples() -> tuple[np.ndarray, np.ndarray]:
    """Header stamps [ns] and gyro [rad/s] + accel [m/s²] white noise of known densities."""
    rng = np.random.default_rng(43)
    dt = 1.0 / FS_HZ
    header = T0_NS + np.arange(N, dtype=np.int64) * 10_000_000
    gyro = rng.normal(0.0, GYRO_DENSITY / math.sqrt(dt), (N, 3)) + 0.01
    accel = rng.normal(0.0, ACCEL_DENSITY / math.sqrt(dt), (N, 3)) + np.array([0.0, 0.0, 9.81])
    return header, np.column_stack([gyro, accel])


def _received(header: np.ndarray, values: np.ndarray) -> Topic:
    """Every 97th message received before the one sampled just ahead of it."""
    order = np.arange(N)
    for i in range(50, N - 1, 97):
        order[i], order[i + 1] = order[i + 1], order[i]
    recv = header + 1_500_000
    return Topic("/imu", "sensor_msgs/msg/Imu", header[order], recv, values[order])


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    import pandas as pd

    base = tmp_path_factory.mktemp("bags")
    header, values = _samples()
    topic = _received(header, values)
    out = {k: write_bag(base / ("imu.bag" if k == "ros1" else k), k, [topic]) for k in KINDS}
    out["bare.mcap"] = shutil.copy(storage_file(out["mcap"]), base / "bare.mcap")
    # the same samples in time order, the time as the sensor stamped it [s from the first]
    cols = {"time": (header - T0_NS) / 1e9}
    for i, c in enumerate((*GYRO.split(","), *ACCEL.split(","))):
        cols[c] = values[:, i]
    frame = pd.DataFrame(cols)
    frame.to_csv(base / "imu.csv", index=False, float_format="%.17g")
    out["csv"] = base / "imu.csv"
    return out


def _noise(path: Path, out: Path, *extra: str) -> int:
    return main(["noise", str(path), "--gyro", GYRO, "--accel", ACCEL, "--format", "kalibr",
                 "-o", str(out), *extra])  # fmt: skip


def _figures(path: Path) -> dict[str, float]:
    doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    return {k: v for k, v in doc.items() if isinstance(v, float)}


@pytest.mark.parametrize("kind", [*KINDS, "bare.mcap"])
def test_noise_of_a_bag_equals_noise_of_the_csv(
    bags: dict[str, Path], kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ref = tmp_path / "csv.yaml"
    assert _noise(bags["csv"], ref, "--time", "time", "--time-unit", "s",
                  "--gyro-unit", "rad/s", "--accel-unit", "m/s^2") == 0  # fmt: skip
    capsys.readouterr()
    got = tmp_path / f"{kind}.yaml"
    assert _noise(bags[kind], got, "--topic", "/imu") == 0
    err = capsys.readouterr().err
    swaps = len(range(50, N - 1, 97))
    assert f"warning: {bags[kind]}: /imu: {swaps} header stamps out of order (sorted)" in err
    assert "--stamp receive" in err
    want, have = _figures(ref), _figures(got)
    assert set(have) == set(want)
    for key, value in want.items():
        assert have[key] == pytest.approx(value, rel=1e-12, abs=0.0), key
    # and the figures are the simulator's densities
    assert have["gyroscope_noise_density"] == pytest.approx(GYRO_DENSITY, rel=0.1)
    assert have["accelerometer_noise_density"] == pytest.approx(ACCEL_DENSITY, rel=0.1)
    assert have["update_rate"] == pytest.approx(FS_HZ, rel=1e-9)


def test_receive_stamps_and_other_commands(
    bags: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = bags["mcap"]
    out = tmp_path / "r.yaml"
    assert _noise(path, out, "--topic", "/imu", "--stamp", "receive") == 0
    assert "out of order" not in capsys.readouterr().err  # the receive times are in order
    assert _figures(out)["update_rate"] == pytest.approx(FS_HZ, rel=1e-9)
    assert main(["allan", str(path), "--topic", "/imu", "--signal", "gyro_z",
                 "--stamp", "receive"]) == 0  # fmt: skip
    assert main(["inspect", str(path), "--topic", "/imu", "--stamp", "receive"]) == 0
    assert main(["metrics", str(bags["ros1"]), "--topic", "/imu", "--signal", "gyro_x",
                 "--stamp", "receive"]) == 0  # fmt: skip
    capsys.readouterr()
    assert main(["inspect", str(bags["csv"]), "--stamp", "receive"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: {bags['csv']}: --stamp is for ROS bags and MCAP files"]


def _hash(path: Path) -> str:
    h = hashlib.sha256()
    for f in sorted(path.rglob("*")) if path.is_dir() else [path]:
        if f.is_file():
            h.update(f.name.encode() + f.read_bytes())
    return h.hexdigest()


def _refused(path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> str:
    before = _hash(path)
    capsys.readouterr()
    assert main(["inspect", str(path), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: "), err
    assert _hash(path) == before
    return err[0]


def _small(tmp_path: Path, kind: str, extra: tuple[str, ...] = ()) -> Path:
    header = T0_NS + np.arange(50, dtype=np.int64) * 10_000_000
    topic = Topic("/imu", "sensor_msgs/msg/Imu", header, header, np.ones((50, 6)))
    return write_bag(tmp_path / ("s.bag" if kind == "ros1" else kind), kind, [topic], extra)


@pytest.mark.parametrize("kind", KINDS)
def test_truncated_bags_are_refused(
    kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _small(tmp_path, kind)
    target = path if kind == "ros1" else storage_file(path)
    data = target.read_bytes()
    target.write_bytes(data[: len(data) // 2])
    line = _refused(path, capsys, "--topic", "/imu")
    assert "not a readable ROS bag or MCAP file" in line


@pytest.mark.parametrize("kind", KINDS)
def test_wrong_types_and_absent_topics_name_what_the_bag_has(
    kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _small(tmp_path, kind, extra=("/chatter",))
    line = _refused(path, capsys, "--topic", "/chatter")
    assert "topic /chatter is std_msgs/msg/String, not sensor_msgs/Imu" in line
    assert "choose with --topic" in line and "/imu (sensor_msgs/msg/Imu, 50 messages)" in line
    line = _refused(path, capsys, "--topic", "/camera")
    assert "no topic /camera in the bag; choose one with --topic" in line


def test_empty_bags_and_a_folder_without_metadata(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for kind in KINDS:
        path = write_bag(tmp_path / ("e.bag" if kind == "ros1" else f"e{kind}"), kind, [])
        assert "the bag holds no topics" in _refused(path, capsys)
        none = Topic("/imu", "sensor_msgs/msg/Imu", np.zeros(0, np.int64),
                     np.zeros(0, np.int64), np.zeros((0, 6)))  # fmt: skip
        path = write_bag(tmp_path / ("n.bag" if kind == "ros1" else f"n{kind}"), kind, [none])
        line = _refused(path, capsys)
        assert "topic /imu holds no messages; choose another with --topic" in line
    folder = _small(tmp_path, "sqlite3")
    (folder / "metadata.yaml").unlink()
    line = _refused(folder, capsys)
    assert "needs its metadata.yaml" in line and ".db3 or .mcap storage file" in line
    (tmp_path / "plain").mkdir()
    assert "is a directory, not a recording file" in _refused(tmp_path / "plain", capsys)


def _mcap_statistics_huge(path: Path) -> None:
    """Walk the MCAP records (opcode u8, length u64, content; Foxglove's MCAP specification)
    to the Statistics record (0x0B) and make its message count 2^64-1, its chunk count
    2^31-1 and its first channel's message count 2^64-1."""
    data = bytearray(path.read_bytes())
    pos, found = 8, False
    while pos < len(data) - 8 and data[pos] != 0x02:  # up to the footer
        op, length = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        if op == 0x0B:
            c = pos + 9
            data[c : c + 8] = b"\xff" * 8  # message_count
            data[c + 22 : c + 26] = struct.pack("<I", 0x7FFFFFFF)  # chunk_count
            data[c + 48 : c + 56] = b"\xff" * 8  # channel_message_counts[0] (after id u16)
            found = True
        pos += 9 + length
    assert found
    path.write_bytes(bytes(data))


def test_headers_claiming_huge_counts(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # ROS 1 (Bags/Format/2.0): the bag header record's conn_count and chunk_count: refused
    path = _small(tmp_path, "ros1")
    data = bytearray(path.read_bytes())
    for key in (b"conn_count=", b"chunk_count="):
        at = data.index(key) + len(key)
        data[at : at + 4] = struct.pack("<I", 0x7FFFFFFF)
    path.write_bytes(bytes(data))
    assert "not a readable ROS bag or MCAP file" in _refused(path, capsys)
    # ROS 2 metadata.yaml and MCAP statistics claiming 10^15 and 2^64-1 messages: the 50
    # messages the file holds are read, nothing is sized from the claim
    folder = _small(tmp_path, "mcap")
    meta = folder / "metadata.yaml"
    meta.write_text(meta.read_text().replace("message_count: 50", "message_count: 10" + "0" * 15))
    bare = Path(shutil.copy(storage_file(folder), tmp_path / "h.mcap"))
    _mcap_statistics_huge(bare)
    for p in (folder, bare):
        before = _hash(p)
        capsys.readouterr()
        assert main(["inspect", str(p), "--topic", "/imu"]) == 0
        assert "50 samples over 0.49 s" in capsys.readouterr().out
        assert _hash(p) == before


def test_an_mcap_of_ros1_messages_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``mcap convert`` of a ROS 1 bag gives schemas encoded ``ros1msg`` (MCAP's
    well-known encodings); rosbags reads ROS 2 definitions only."""
    bare = Path(shutil.copy(storage_file(_small(tmp_path, "mcap")), tmp_path / "r1.mcap"))
    data = bare.read_bytes()
    assert data.count(b"ros2msg") == 2  # the schema record, and its copy in the summary
    bare.write_bytes(data.replace(b"ros2msg", b"ros1msg"))
    line = _refused(bare, capsys, "--topic", "/imu")
    assert "message definitions are 'ros1msg', not ROS 2" in line


def test_without_the_extra_one_error_line(
    bags: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    monkeypatch.setitem(sys.modules, "rosbags.highlevel", None)
    line = _refused(bags["ros1"], capsys, "--topic", "/imu")
    assert "pip install 'thermocal[bags]'" in line


def test_fit_of_a_bag_folder_equals_the_fit_of_the_csv(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A gyro of known slope 2e-4 rad/s/°C over a 10…50 °C sweep read at 1 Hz: the model
    fitted from the ROS 2 bag folder (hashed file by file in its provenance) is the model
    of the same samples in a CSV, the temperature interpolated here with numpy."""
    import json

    import pandas as pd

    rng = np.random.default_rng(5)
    n, rate = 4000, 10.0
    t_s = np.arange(n) / rate
    header = T0_NS + np.arange(n, dtype=np.int64) * 100_000_000
    th = T0_NS + np.arange(-1, 402, dtype=np.int64) * NS
    temp = 10.0 + 0.1 * (th - T0_NS) / NS
    temp_at = np.interp(t_s, (th - T0_NS) / NS, temp)
    gyro = 1e-3 + 2e-4 * (temp_at - 25.0) + rng.normal(0.0, 1e-4, n)
    values = np.column_stack([gyro, np.zeros((n, 4)), np.full(n, 9.81)])
    bag = write_bag(tmp_path / "sweep", "sqlite3", [
        Topic("/imu", "sensor_msgs/msg/Imu", header, header, values),
        Topic("/temp", "sensor_msgs/msg/Temperature", th, th, temp.reshape(-1, 1)),
    ])  # fmt: skip
    csv = tmp_path / "sweep.csv"
    pd.DataFrame({"time": t_s, "gyro_x": gyro, "temperature": temp_at}).to_csv(
        csv, index=False, float_format="%.17g"
    )
    fit = ["fit", "--model", "poly", "--order", "1", "--signal", "gyro_x",
           "--temps", "temperature"]  # fmt: skip
    assert main([*fit, str(bag), "--topic", "/imu", "-o", str(tmp_path / "b.json")]) == 0
    assert main([*fit, str(csv), "--signal-unit", "rad/s", "--temp-unit", "degC",
                 "--time-unit", "s", "-o", str(tmp_path / "c.json")]) == 0  # fmt: skip
    b, c = (json.loads((tmp_path / f).read_text()) for f in ("b.json", "c.json"))
    for cb, cc in zip(b["coefficients"], c["coefficients"], strict=True):
        assert cb["name"] == cc["name"] and cb["unit"] == cc["unit"]
        assert cb["value"] == pytest.approx(cc["value"], rel=1e-9, abs=1e-9)
    slope = next(x for x in b["coefficients"] if x["name"] == "T1")
    assert slope["unit"] == "deg/h/degC"  # 2e-4 rad/s/°C = 41.25 °/h/°C
    assert slope["value"] == pytest.approx(math.degrees(2e-4) * 3600, rel=0.01)
    # compensated from the bag (the receive stamps are the header stamps here), in the
    # file's unit: the slope gone, the residual the simulated noise (1e-4 rad/s)
    for stamp in ("header", "receive"):
        out = tmp_path / f"comp_{stamp}.csv"
        assert main(["compensate", str(tmp_path / "b.json"), str(bag), "--topic", "/imu",
                     "--stamp", stamp, "-o", str(out)]) == 0  # fmt: skip
        comp = pd.read_csv(out)["gyro_x_comp"].to_numpy()
        assert np.std(comp) == pytest.approx(1e-4, rel=0.05)
        assert abs(np.polyfit(temp_at, comp, 1)[0]) < 0.02 * 2e-4
