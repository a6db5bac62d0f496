"""readers.ulog.release_parsed_topic: within parsed_once, a topic instance read once gives
its parsed data back; the other instances read as before (values from the file, checked
against the rows written), the released one is no longer there, outside the block nothing
happens."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from thermocal.errors import MissingColumnError
from thermocal.readers.ulog import parsed_once, read_ulog, release_parsed_topic
from ulog_writer import SENSOR_FIELDS, ulog_bytes


def _rows(n: int, dev: int, scale: float) -> list[tuple[int, int, float, float, float, float]]:
    t = np.arange(n)
    return [(int(1_000_000 + 10_000 * i), dev, scale * i, -scale * i, 0.5, 20.0 + 0.01 * i)
            for i in t]  # fmt: skip


def _log(tmp_path: Path) -> Path:
    log = tmp_path / "two.ulg"
    topics = [("sensor_gyro", 0, SENSOR_FIELDS, _rows(300, 7, 0.25)),
              ("sensor_gyro", 1, SENSOR_FIELDS, _rows(200, 9, 0.5))]  # fmt: skip
    log.write_bytes(ulog_bytes(topics))
    return log


def test_release_gives_back_one_instance(tmp_path: Path) -> None:
    log = _log(tmp_path)
    assert release_parsed_topic(log, "sensor_gyro.0") is False  # outside the block
    with parsed_once(log, ["sensor_gyro"]):
        assert release_parsed_topic(log, "sensor_gyro.0") is False  # not parsed yet
        df0, _ = read_ulog(log, "sensor_gyro.0")
        assert df0["x"].to_numpy() == pytest.approx(0.25 * np.arange(300))
        assert release_parsed_topic(log, "sensor_gyro.0") is True
        assert release_parsed_topic(log, "sensor_gyro.0") is False  # already given back
        df1, _ = read_ulog(log, "sensor_gyro.1")  # the other instance is still there
        assert df1["y"].to_numpy() == pytest.approx(-0.5 * np.arange(200))
        with pytest.raises(MissingColumnError, match=r"no topic sensor_gyro\.0"):
            read_ulog(log, "sensor_gyro.0")
    df0, _ = read_ulog(log, "sensor_gyro.0")  # a new parse outside the block: all of it
    assert len(df0) == 300
