"""The tumble test through the Python API (thermocal.pipeline.tumble.tumble_file) with what
the command line's reading options give it: a chamber's own log joined by time (the test's
temperature, against the air the log was written from), a bag's topic and stamps, and a
stated unit that contradicts the file said under the parameter that stated it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bag_writer import NS, Topic, write_bag
from chamber_logs import air_c, write_log
from thermocal.errors import UnitWarning
from thermocal.pipeline.tumble import TumbleOptions, tumble_file
from thermocal.readers.options import ChamberLogSpec, ReadOptions
from thermocal.tumble.simulate import simulate_tumble
from thermocal.writers import write_recording

G_MG = 9.80665e-3
"""One mg in m/s² (standard gravity 9.80665 m/s², CGPM 1901)."""


@pytest.fixture(scope="module")
def stations(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, np.ndarray]:
    d = tmp_path_factory.mktemp("tbapi")
    rec, _ = simulate_tumble(np.random.default_rng(4), stations=12, dwell_s=10.0)
    write_recording(rec, d / "tb.csv")
    return d / "tb.csv", rec.time_s


def test_the_chamber_log_is_the_temperature(
    stations: tuple[Path, np.ndarray], tmp_path: Path
) -> None:
    path, t = stations
    log = write_log(tmp_path / "log.csv", style="hh:mm", period_s=60.0, unit="degC")
    spec = ChamberLogSpec(str(log), offset_s=2000.0)
    res = tumble_file(path, TumbleOptions(angle_column="angle", read=ReadOptions(chamber_log=spec)))
    air = air_c(2000.0 + t)  # on the 20 → 60 °C ramp: linear, so the minute log is exact
    tt = res.temperature
    assert tt is not None and tt.column == "chamber"
    assert tt.mean_c == pytest.approx(float(np.mean(air)), abs=0.01)
    assert (tt.min_c, tt.max_c) == (pytest.approx(float(air.min()), abs=0.01),
                                    pytest.approx(float(air.max()), abs=0.01))  # fmt: skip
    for s, got in zip(res.stations, tt.stations_c, strict=True):
        kept = (t >= s.start_s) & (t <= s.end_s)
        assert got == pytest.approx(float(np.mean(air[kept])), abs=0.01)
    assert res.to_dict()["temperature"]["mean_c"] == tt.mean_c
    assert tumble_file(path, TumbleOptions(angle_column="angle")).temperature is None


def test_a_bag_topic_and_its_receive_stamps(tmp_path: Path) -> None:
    rec, truth = simulate_tumble(np.random.default_rng(5), turn_rate_dps=3.0, rate_hz=10.0)
    n = rec.n_samples
    header = (1_700_000_000 * NS + np.round(rec.time_s * NS)).astype(np.int64)
    receive = header[0] + 3 * (header - header[0])  # the recorder's clock, three times slower
    imu = np.zeros((n, 6))
    imu[:, 5] = rec.columns["accel"] * G_MG
    bag = write_bag(tmp_path / "tb.bag", "ros1", [
        Topic("/head", "sensor_msgs/msg/Imu", header, receive, imu),
        Topic("/base", "sensor_msgs/msg/Imu", header, receive, np.zeros((n, 6)) + 1.0),
    ])  # fmt: skip
    read = ReadOptions(topic="/head", stamp="receive")
    res = tumble_file(bag, TumbleOptions("accel_z", turn_rate_dps=1.0, read=read))
    for k in ("k0", "k1", "k2", "k_ip"):
        i = res.coefficients.names.index(k)
        want = truth[k] * G_MG
        assert abs(res.coefficients.values[i] - want) < 3 * res.coefficients.sigmas[i], k


def test_a_unit_against_the_file_names_accel_unit(stations: tuple[Path, np.ndarray]) -> None:
    path, _ = stations  # the file says mg
    with pytest.warns(UnitWarning) as caught:
        tumble_file(path, TumbleOptions(angle_column="angle", accel_unit="ug"))
    said = [str(w.message) for w in caught if "contradicts" in str(w.message)]
    assert len(said) == 1 and "accel_unit ug contradicts the file's metadata" in said[0], said
