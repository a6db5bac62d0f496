"""Every file ``turntable`` and ``profile correlate`` take is read like every other
command's (issue 27): headerless serial-terminal logs with the text-log options, a ULog
topic with ``--topic``; and encoder angle columns have a unit like every other column."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.recording import Recording
from thermocal.turntable import calibrate, simulate_turntable16
from thermocal.writers import write_recording
from ulog_writer import ulog_bytes

COLS = ["gyro_x", "gyro_y", "gyro_z", "alpha_deg", "beta_deg"]
KEYS = ("bias_deg_h", "scale_factor_ppm", "misalignment_arcsec")


@pytest.fixture(scope="module")
def run() -> tuple[Recording, dict[str, list[float]]]:
    return simulate_turntable16(1, rate_hz=2.0)


def _json(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[dict, str]:
    code = main([*args, "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    return json.loads(cap.out), cap.err


def test_turntable_reads_a_headerless_serial_log(
    run: tuple[Recording, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec, _truth = run
    csv = tmp_path / "run.csv"
    write_recording(rec, csv)
    ref, _ = _json(["turntable", str(csv), "-o", str(tmp_path / "a.json"), "--latitude", "40"],
                   capsys)  # fmt: skip
    log = tmp_path / "run.log"  # what a serial terminal saves: no header, spaces
    data = np.column_stack([rec.time_s, *(rec.column(c) for c in COLS)])
    log.write_text("\n".join(" ".join(f"{v:.12g}" for v in row) for row in data) + "\n")
    got, _ = _json(
        ["turntable", str(log), "-o", str(tmp_path / "b.json"), "--latitude", "40",
         "--names", "t,gx,gy,gz,enc_in_deg,enc_out_deg", "--time", "t", "--gyro", "gx,gy,gz",
         "--gyro-unit", "deg/s", "--alpha", "enc_in_deg", "--beta", "enc_out_deg"],
        capsys,
    )  # fmt: skip
    for key in KEYS:
        np.testing.assert_allclose(got[key], ref[key], rtol=0, atol=1e-6)
    assert got["n_positions"] == 16


def test_turntable_reads_a_ulog_topic(
    run: tuple[Recording, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec, truth = run
    fields = [("uint64_t", "timestamp")] + [("float", c) for c in COLS]
    stamps = (1e6 + rec.time_s * 1e6).astype(np.int64)
    rows = [(int(s), *(float(rec.column(c)[i]) for c in COLS)) for i, s in enumerate(stamps)]
    log = tmp_path / "tt.ulg"
    log.write_bytes(ulog_bytes([("turntable_run", 0, fields, rows)]))
    got, _ = _json(
        ["turntable", str(log), "-o", str(tmp_path / "r.json"), "--topic", "turntable_run.0",
         "--time", "timestamp", "--time-unit", "us", "--gyro-unit", "deg/s", "--latitude", "40"],
        capsys,
    )  # fmt: skip
    assert got["n_positions"] == 16
    for key in KEYS:  # float32 fields: the truth within 5 σ
        err = np.abs(np.array(got[key]) - np.array(truth[key]))
        assert np.all(err < 5 * np.array(got[key + "_sigma"])), key


def test_encoder_columns_in_rad_give_the_deg_calibration(
    run: tuple[Recording, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec, _truth = run
    ref = calibrate(rec, 40.0)
    cols = dict(rec.columns)
    cols["alpha_rad"] = np.deg2rad(cols.pop("alpha_deg"))
    cols["beta_rad"] = np.deg2rad(cols.pop("beta_deg"))
    units = {k: v for k, v in rec.units.items() if k not in ("alpha_deg", "beta_deg")}
    rad = Recording(rec.time_s, cols, units, rec.signals, rec.temperatures, rec.meta)
    # the unit from the column name, and from the option
    by_name = calibrate(rad, 40.0, alpha_column="alpha_rad", beta_column="beta_rad")
    np.testing.assert_allclose(by_name.kalman.theta, ref.kalman.theta, rtol=0, atol=1e-6)
    cols["a"], cols["b"] = cols.pop("alpha_rad"), cols.pop("beta_rad")
    path = tmp_path / "rad.csv"
    write_recording(Recording(rec.time_s, cols, units, rec.signals, rec.temperatures, rec.meta),
                    path)  # fmt: skip
    args = ["turntable", str(path), "-o", str(tmp_path / "r.json"), "--latitude", "40"]
    got, err = _json([*args, "--alpha", "a", "--beta", "b", "--encoder-unit", "rad"], capsys)
    np.testing.assert_allclose(got["bias_deg_h"], ref.kalman.theta[0:3], rtol=0, atol=1e-6)
    np.testing.assert_allclose(got["misalignment_arcsec"], ref.kalman.theta[6:], atol=1e-4)
    assert "angle column" not in err


def test_encoder_column_of_unknown_unit_is_said(
    run: tuple[Recording, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec, _truth = run
    cols = dict(rec.columns)
    cols["a"] = cols.pop("alpha_deg")
    units = {k: v for k, v in rec.units.items() if k != "alpha_deg"}
    path = tmp_path / "a.csv"
    write_recording(Recording(rec.time_s, cols, units, rec.signals, rec.temperatures, rec.meta),
                    path)  # fmt: skip
    got, err = _json(["turntable", str(path), "-o", str(tmp_path / "r.json"), "--latitude",
                      "40", "--alpha", "a"], capsys)  # fmt: skip
    assert "warning:" in err and "angle column 'a'" in err and "assuming deg" in err
    assert got["n_positions"] == 16
    code = main(["turntable", str(path), "-o", str(tmp_path / "r.json"), "--latitude", "40",
                 "--alpha", "a", "--encoder-unit", "furlong"])  # fmt: skip
    assert code == 2 and "unknown angle unit 'furlong'" in capsys.readouterr().err


def _history(t: np.ndarray, phase: float) -> np.ndarray:
    return 20.0 + 30.0 * np.sin(2 * np.pi * t / 7200.0 + phase)


def test_profile_correlate_reads_serial_logs_and_ulog_topics(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t = np.arange(0.0, 7200.0, 10.0)
    a, b = _history(t, 0.0), _history(t, 1.0)
    want = float(np.corrcoef(a, b)[0, 1])  # same time base: r of the samples themselves
    for name, x in (("a.log", a), ("b.log", b)):
        lines = [f"{tt:g};{v:.9f}" for tt, v in zip(t, x, strict=True)]
        (tmp_path / name).write_text("\n".join(lines) + "\n")
    got, _ = _json(["profile", "correlate", str(tmp_path / "a.log"), str(tmp_path / "b.log"),
                    "--names", "time,T_chamber", "--column", "T_chamber", "--points",
                    str(t.size)], capsys)  # fmt: skip
    assert got["r"] == pytest.approx(want, abs=1e-6)
    assert got["column_a"] == got["column_b"] == "T_chamber"
    fields = [("uint64_t", "timestamp"), ("uint32_t", "device_id"), ("float", "x"),
              ("float", "y"), ("float", "z"), ("float", "temperature")]  # fmt: skip
    for name, x in (("a.ulg", a), ("b.ulg", b)):
        rows = [
            (int(1e6 + tt * 1e6), 1, 0.0, 0.0, 0.0, float(v)) for tt, v in zip(t, x, strict=True)
        ]
        (tmp_path / name).write_bytes(ulog_bytes([("sensor_baro", 0, fields, rows)]))
    got, _ = _json(["profile", "correlate", str(tmp_path / "a.ulg"), str(tmp_path / "b.ulg"),
                    "--topic", "sensor_baro.0", "--column", "temperature", "--points",
                    str(t.size)], capsys)  # fmt: skip
    assert got["r"] == pytest.approx(want, abs=1e-5)


def test_angle_units_of_the_glossary() -> None:
    from thermocal import units
    from thermocal.errors import UnitError

    assert [units.normalize_angle_unit(u) for u in ("deg", "°", "Degrees", "rad", "radian")] == [
        "deg", "deg", "deg", "rad", "rad"
    ]  # fmt: skip
    np.testing.assert_allclose(units.angle_to_deg([np.pi, -np.pi / 2], "rad"), [180.0, -90.0])
    assert units.unit_in_column_name("enc_in [rad]", "angle") == "rad"
    assert units.unit_in_column_name("alpha_deg", "angle") == "deg"
    assert units.DEG_TO_ARCSEC == 3600.0 and units.ARCSEC_TO_DEG * 3600.0 == 1.0
    with pytest.raises(UnitError, match="unknown angle unit"):
        units.normalize_angle_unit("deg/s")
