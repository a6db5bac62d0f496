"""Parameter-export and px4-tempcal tests written to kill mutants of the mutation check
(issue 27 item 6: ``benchmarks/mutation_check.py``, the mutants named ``params-*`` and
``px4-*``).

The expected values are worked out here from the firmware's documented conventions
(INTERFACE.md; ArduPilot: one range per instance, where every channel was fitted) and the
adequacy floors written with their numbers (0.3 °/s = 1080 °/h)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.export.params import export_params
from thermocal.models.files import load_calibration
from thermocal.simulate import SCENARIOS
from thermocal.tempcal.px4 import SensorFit, step_warnings
from thermocal.writers import write_recording

G0 = 9.80665
GYROS, ACCELS = ("gx", "gy", "gz"), ("ax", "ay", "az")


@pytest.fixture(scope="module")
def cal_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("mutants_export")
    ((mod, _truth),) = SCENARIOS["mems-imu"](11, rate_hz=0.2)
    write_recording(mod, d / "mod.parquet")
    cal = d / "cal.json"
    assert main(["fit", str(d / "mod.parquet"), "--model", "poly", "--order", "3", "--signal",
                 ",".join(GYROS + ACCELS), "--temps", "T_die", "--gravity-axis", "+z",
                 "--gravity", str(G0), "-o", str(cal)]) == 0  # fmt: skip
    return cal


def test_ardupilot_range_is_where_every_channel_was_fitted(cal_path: Path) -> None:
    """The accelerometers fitted on a narrower range than the gyros (5 °C in from each
    end): INS_TCAL1_TMIN/TMAX are the accelerometers' ends, the range both triads share
    (mutants params-ardupilot-tmin, params-ardupilot-tmax)."""
    cal = load_calibration(cal_path)
    lo, hi = (float(v) for v in cal.channel("gx").model.temp_range_[0])
    assert hi - lo > 20.0
    for name in ACCELS:
        m = cal.channel(name).model
        m.temp_range_ = np.array([[lo + 5.0, hi - 5.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = export_params(cal, "ardupilot")
    assert out.params["INS_TCAL1_TMIN"] == pytest.approx(lo + 5.0, abs=1e-9)
    assert out.params["INS_TCAL1_TMAX"] == pytest.approx(hi - 5.0, abs=1e-9)


def _series(
    n: int, step_at: int | None, step_deg_h: float, seed: int
) -> tuple[np.ndarray, np.ndarray]:
    """1000 s at 10 Hz of a still gyro triad [°/h]: 30 °/h white noise, a slow drift, and
    optionally a step on x."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.1
    v = rng.normal(0.0, 30.0, (n, 3)) + 0.05 * t[:, None]
    if step_at is not None:
        v[step_at:, 0] += step_deg_h
    return t, v


@pytest.mark.parametrize(("step_deg_h", "flagged"), [(500.0, False), (3000.0, True)])
def test_a_bias_step_on_one_imu_is_judged_against_the_motion_floor(
    step_deg_h: float, flagged: bool
) -> None:
    """The step check of a multi-IMU board (px4-tempcal) uses the motion floor 0.3 °/s =
    1080 °/h for gyros: a 500 °/h jump on one instance is below it (not reported), a
    3000 °/h one above it (reported, naming the instance).  With the floor taken as
    0.3 °/h (mutant px4-motion-threshold) the 500 °/h jump is reported too."""
    n = 10_000
    fits = [
        SensorFit("sensor_gyro", "gyro", i, 0, "deg/h", (20.0, 40.0), n, 40) for i in (0, 1)
    ]
    series = {
        "sensor_gyro.0": _series(n, n // 2, step_deg_h, 1),
        "sensor_gyro.1": _series(n, None, 0.0, 2),
    }
    got = step_warnings(fits, series)
    if flagged:
        assert len(got) == 1 and got[0].startswith("sensor_gyro.0: a step-like bias at 500 s")
    else:
        assert got == []
