"""Live compensation of a whole IMU (issue 15): :class:`CalibrationStream` takes one sample
of every channel at a time and gives what the file compensation gives, each channel in its
own data unit."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.compensate.kernels import CalibrationStream
from thermocal.errors import ThermocalInputError
from thermocal.pipeline.model_file import load_calibration
from thermocal.simulate import IMU_CHANNELS, SCENARIOS
from thermocal.writers import write_recording

NAMES = [n for n, _u in IMU_CHANNELS]


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory) -> dict:
    d = tmp_path_factory.mktemp("stream")
    ((mod, _t),) = SCENARIOS["mems-imu"](8, rate_hz=0.2)
    ((val, _),) = SCENARIOS["mems-imu"](8, run="validation", rate_hz=0.2)
    write_recording(mod, d / "mod.parquet")
    # 4000 samples of the validation run with a 10-minute gap in the middle
    keep = np.r_[0:2000, 2120:4120]
    cols = {"time": val.time_s[keep], "T_die": val.column("T_die")[keep]}
    cols.update({n: val.column(n)[keep] for n in NAMES})
    pd.DataFrame(cols).to_parquet(d / "val.parquet")
    (d / "val.parquet.meta.json").write_text(
        '{"time": "time", "time_unit": "s", "units": {"T_die": "degC", '
        + ", ".join(f'"{n}": "{u}"' for n, u in IMU_CHANNELS)
        + "}}"
    )
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["fit", str(d / "mod.parquet"), "--model", "poly", "--terms",
                     "T1,T1^2,T1^3,dT1", "--signal", ",".join(NAMES), "--temps", "T_die",
                     "--gravity-axis", "+z", "--gravity", "9.80665",
                     "-o", str(d / "cal.json")]) == 0  # fmt: skip
        assert main(["compensate", str(d / "cal.json"), str(d / "val.parquet"),
                     "-o", str(d / "out.parquet"), "--chunk-rows", "700"]) == 0  # fmt: skip
    return {
        "dir": d,
        "cal": load_calibration(d / "cal.json"),
        "out": pd.read_parquet(d / "out.parquet"),
    }


def test_sample_by_sample_equals_the_file_compensation(setup: dict) -> None:
    out = setup["out"]
    s = CalibrationStream(setup["cal"], 5.0)
    assert s.names == tuple(NAMES)
    assert s.temperature_names == ("T_die",)
    assert s.units == tuple(u for _n, u in IMU_CHANNELS)
    raw = out[NAMES].to_numpy()
    got = np.array([s.update(t, [T], r) for t, T, r in zip(out["time"], out["T_die"], raw,
                                                           strict=True)])  # fmt: skip
    for i, n in enumerate(NAMES):
        want = out[f"{n}_comp"].to_numpy()
        scale = float(np.max(np.abs(out[f"{n}_model"])))
        np.testing.assert_allclose(got[:, i], want, rtol=0, atol=1e-9 * scale, err_msg=n)
    # gravity stays in az (the calibration recorded +z up)
    assert float(np.mean(got[:, NAMES.index("az")])) == pytest.approx(1000.0, abs=1.0)


def test_blocks_equal_the_file_compensation(setup: dict) -> None:
    out = setup["out"]
    s = CalibrationStream(setup["cal"], 5.0)
    raw = out[NAMES].to_numpy()
    models, comps = [], []
    for a in range(0, len(out), 97):
        m, c = s.update_block(out["time"][a : a + 97], out["T_die"][a : a + 97], raw[a : a + 97])
        models.append(m)
        comps.append(c)
    got = np.vstack(comps)
    for i, n in enumerate(NAMES):
        np.testing.assert_allclose(np.vstack(models)[:, i], out[f"{n}_model"], rtol=1e-12,
                                   atol=1e-12, err_msg=n)  # fmt: skip
        np.testing.assert_allclose(got[:, i], out[f"{n}_comp"], rtol=1e-12, atol=1e-9)


def test_temperatures_by_name_and_bad_lengths(setup: dict) -> None:
    s = CalibrationStream(setup["cal"], 5.0)
    a = s.update(0.0, {"T_die": 20.0}, np.zeros(6))
    s.reset()
    b = s.update(0.0, [20.0], np.zeros(6))
    assert np.array_equal(a, b)
    with pytest.raises(ThermocalInputError, match="expected 6 raw values"):
        s.update(5.0, [20.0], np.zeros(5))
    with pytest.raises(ThermocalInputError, match="T_die"):
        s.update(5.0, {"T_chamber": 20.0}, np.zeros(6))


def test_a_gyro_in_deg_s_is_converted_both_ways(setup: dict, tmp_path: Path) -> None:
    cal = setup["cal"]
    gx = cal.channel("gx").model
    s = CalibrationStream([("gx", gx, "deg/s")], 5.0)
    s_h = CalibrationStream([("gx", gx, "deg/h")], 5.0)
    c_s = s.update(0.0, [30.0], [0.01])[0]
    c_h = s_h.update(0.0, [30.0], [0.01 * 3600.0])[0]
    assert c_h == pytest.approx(3600.0 * c_s, rel=1e-12)
