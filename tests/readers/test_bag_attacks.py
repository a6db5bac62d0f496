"""Damaged bags (:mod:`thermocal.readers.bag`): ROS 1, ROS 2 sqlite3 and MCAP bags written
with ``rosbags``, then 1 to 20 random bytes of the storage overwritten (seeded): every read
through the command line ends with status 0 (the damage fell in values no format checks)
or 2 with one ``error:`` line, never a traceback, and the input is never modified."""

from __future__ import annotations

import contextlib
import hashlib
import io
import shutil
from pathlib import Path

import numpy as np
import pytest

from bag_writer import KINDS, NS, Topic, storage_file, write_bag
from thermocal.cli import main

pytest.importorskip("rosbags")

T0_NS = 1_700_000_000 * NS


@pytest.mark.parametrize("kind", KINDS)
def test_random_byte_damage_is_exit_0_or_one_error_line(kind: str, tmp_path: Path) -> None:
    header = T0_NS + np.arange(300, dtype=np.int64) * 10_000_000
    th = T0_NS + np.arange(4, dtype=np.int64) * NS
    topics = [
        Topic("/imu", "sensor_msgs/msg/Imu", header, header, np.ones((300, 6))),
        Topic("/t", "sensor_msgs/msg/Temperature", th, th, np.ones((4, 1))),
    ]
    src = write_bag(tmp_path / ("src.bag" if kind == "ros1" else "src"), kind, topics)
    rng = np.random.default_rng(0)
    codes = []
    for _ in range(25):
        bag = tmp_path / ("b.bag" if kind == "ros1" else "b")
        if bag.exists():
            shutil.rmtree(bag) if bag.is_dir() else bag.unlink()
        shutil.copytree(src, bag) if src.is_dir() else shutil.copy(src, bag)
        target = bag if kind == "ros1" else storage_file(bag)
        data = bytearray(target.read_bytes())
        for _ in range(int(rng.integers(1, 20))):
            data[int(rng.integers(0, len(data)))] = int(rng.integers(0, 256))
        target.write_bytes(bytes(data))
        before = hashlib.sha256(bytes(data)).hexdigest()
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = main(["inspect", str(bag), "--topic", "/imu"])
        lines = [ln for ln in err.getvalue().splitlines() if ln.startswith("error:")]
        assert code in (0, 2), err.getvalue()
        assert code == 0 or len(lines) == 1, err.getvalue()
        assert "Traceback" not in err.getvalue()
        if kind == "ros1":  # a ROS 1 bag is never taken for an MCAP file
            assert "MCAP file whose message definitions" not in err.getvalue()
        assert hashlib.sha256(target.read_bytes()).hexdigest() == before
        codes.append(code)
    assert 2 in codes  # the damage was seen at least once
