"""ardupilot-tempcal copies every IMU's samples out of the log before the fits (the log's rows
released), yet each IMU is still judged at its turn: IMU 0 is fitted before a damaged IMU 1
stops the run, with the error the reader gives for it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pymavlink")

import thermocal.tempcal.ardupilot as ardupilot
from dataflash_writer import OLD_IMU_FMT, OLD_IMU_LABELS, dataflash_log
from fc_logs import imu_truth
from thermocal.errors import FileFormatError


def test_imu0_fitted_before_a_damaged_imu1_stops_the_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    m = imu_truth(4000, 5, 1.0)
    no_time = ("Stamp", *OLD_IMU_LABELS[1:])  # IMU2's format definition lost its TimeUS
    formats = [(100, "IMU", OLD_IMU_FMT, OLD_IMU_LABELS), (101, "IMU2", OLD_IMU_FMT, no_time)]
    msgs = []
    for i in range(m["temp"].size):
        row = (int(m["time_us"][i]), *m["gyro_meas"][i], *m["accel_meas"][i], 0, 0,
               float(m["temp"][i]))  # fmt: skip
        msgs += [(100, row), (101, row)]
    log = tmp_path / "two.bin"
    log.write_bytes(dataflash_log(formats, msgs))
    fitted: list[str] = []
    real = ardupilot.fit_sensor

    def counted(rec: Any, topic: str, kind: str, inst: int, **kw: Any) -> Any:
        fitted.append(f"{kind}.{inst}")
        return real(rec, topic, kind, inst, **kw)

    monkeypatch.setattr(ardupilot, "fit_sensor", counted)
    with pytest.raises(FileFormatError, match="IMU2 messages have no TimeUS field"):
        ardupilot.ardupilot_tempcal(log, tmp_path / "out", overrides=("motion",))
    assert fitted == ["gyro.0", "accel.0"]
    assert not (tmp_path / "out").exists()  # nothing written: the set is moved whole or not
