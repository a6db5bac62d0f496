"""A ``PARM`` change stamped earlier than data already logged (a clock that went backwards)
takes effect where it is logged, with a warning — not from its stamp back in time over
samples recorded before it (session 8 red-team note)."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

pytest.importorskip("pymavlink")

from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log, parm
from thermocal.errors import PlausibilityWarning
from thermocal.readers.dataflash import read_dataflash_log


def _imu(t_us: int) -> tuple[int, tuple[float, ...]]:
    return (100, (t_us, 0, 0.01, 0.02, 0.03, 0.1, 0.2, -9.8, 0, 0, 30.0, 1, 1, 1000, 1000))


def _log(tmp: Path, stamp_us: int) -> Path:
    msgs: list = [parm("INS_TCAL1_ENABLE", 1, 1000)]
    msgs += [_imu(1_000_000 + 10_000 * i) for i in range(100)]  # 1.00 … 1.99 s
    msgs.append(parm("INS_TCAL1_ENABLE", 0, stamp_us))  # logged after the sample at 1.99 s
    msgs += [_imu(2_000_000 + 10_000 * i) for i in range(100)]
    path = tmp / f"log_{stamp_us}.bin"
    path.write_bytes(dataflash_log([PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs))
    return path


def test_a_change_stamped_back_in_time_is_taken_where_it_is_logged(tmp_path: Path) -> None:
    with pytest.warns(PlausibilityWarning, match="clock went backwards"):
        log = read_dataflash_log(_log(tmp_path, 500_000), ["IMU"])
    (change,) = log.param_changes
    assert (change.name, change.old, change.new) == ("INS_TCAL1_ENABLE", 1.0, 0.0)
    assert change.time_s == pytest.approx(1.99)  # the last sample logged before it


def test_a_change_in_order_keeps_its_stamp(tmp_path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        log = read_dataflash_log(_log(tmp_path, 1_995_000), ["IMU"])
    (change,) = log.param_changes
    assert change.time_s == pytest.approx(1.995)
