"""A DataFlash table of some fields only (``fields``): the values of those fields, the same
whichever way the log was read (fixed-format parser or pymavlink), ``TimeUS`` always, the
message's own order; and a released message's rows are gone (the calibration's memory)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pymavlink")

from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, dataflash_log
from thermocal.errors import MissingColumnError
from thermocal.readers import dataflash
from thermocal.tempcal.flightlog import read_ardupilot_log


def _log(tmp: Path) -> tuple[Path, np.ndarray]:
    """Two IMU instances, 40 messages each, interleaved; the values as written (float32)."""
    rng = np.random.default_rng(3)
    rows = []
    for k in range(80):
        gyr_acc = [float(np.float32(v)) for v in rng.normal(size=6)]
        temp = float(np.float32(20.0 + 0.1 * k))
        rows.append((1_000_000 + 5_000 * k, k % 2, *gyr_acc, 0, 0, temp, 0, 0, 1000, 1000))
    body = dataflash_log([(100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], [(100, r) for r in rows])
    path = tmp / "imu.bin"
    path.write_bytes(body)
    return path, np.array(rows, dtype=np.float64)


@pytest.mark.parametrize("how", ["fast", "pymavlink"])
def test_fields_are_the_values_written(tmp_path: Path, how: str) -> None:
    path, written = _log(tmp_path)
    read = dataflash.read_dataflash_log if how == "fast" else dataflash._pymavlink_pass
    log = read(path, ["IMU"])
    assert bool(log.columns) == (how == "fast")
    df, _info = dataflash.dataflash_table(log, path, "IMU", 1, ("T", "GyrY", "Temp", "NoSuch"))
    assert list(df.columns) == ["TimeUS", "GyrY", "T"]  # the message's order, TimeUS kept
    mine = written[written[:, 1] == 1]
    col = {n: i for i, n in enumerate(NEW_IMU_LABELS)}
    for name in df.columns:
        np.testing.assert_array_equal(df[name].to_numpy(), mine[:, col[name]])
    full, _ = dataflash.dataflash_table(log, path, "IMU", 1)
    assert len(full.columns) == len(NEW_IMU_LABELS)


def test_release_forgets_the_rows(tmp_path: Path) -> None:
    path, _written = _log(tmp_path)
    flight = read_ardupilot_log(path, ("IMU",))
    assert flight.table("IMU", 0, ("T",))[0].shape == (40, 2)
    flight.release("IMU")
    with pytest.raises(MissingColumnError):
        flight.table("IMU", 0)
