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
from thermocal.pipeline.model_file import load_calibration
from thermocal.simulate import SCENARIOS
from thermocal.tempcal.px4 import SensorFit, fit_offset_sensor, step_warnings
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


@pytest.mark.parametrize(
    ("step_deg_h", "other_step_at", "flagged"),
    [(500.0, None, False), (3000.0, None, True), (3000.0, 5200, False)],
)
def test_a_bias_step_on_one_imu_is_judged_against_the_motion_floor(
    step_deg_h: float, other_step_at: int | None, flagged: bool
) -> None:
    """The step check of a multi-IMU board (px4-tempcal) uses the motion floor 0.3 °/s =
    1080 °/h for gyros: a 500 °/h jump on one instance is below it (not reported), a
    3000 °/h one above it (reported, naming the instance).  With the floor taken as
    0.3 °/h (mutant px4-motion-threshold) the 500 °/h jump is reported too.  The same jump
    on the other instance 20 s later (within the 60 s stillness window) is the board
    moving, not reported (mutant px4-step-window)."""
    n = 10_000
    fits = [SensorFit("sensor_gyro", "gyro", i, 0, "deg/h", (20.0, 40.0), n, 40) for i in (0, 1)]
    series = {
        "sensor_gyro.0": _series(n, n // 2, step_deg_h, 1),
        "sensor_gyro.1": _series(n, other_step_at, step_deg_h, 2),
    }
    got = step_warnings(fits, series)
    if flagged:
        assert len(got) == 1 and got[0].startswith("sensor_gyro.0: a step-like bias at 500 s")
    else:
        assert got == []


def test_px4_range_and_reference_of_a_triad(cal_path: Path) -> None:
    """One channel of the gyro triad fitted on a narrower range (3 °C in at the bottom,
    2 °C at the top): TC_G0_TMIN/TMAX are the range all three share (mutant
    params-range-union), and the default TREF is its middle (mutant params-px4-tref-low-end)."""
    cal = load_calibration(cal_path)
    lo, hi = (float(v) for v in cal.channel("gx").model.temp_range_[0])
    cal.channel("gy").model.temp_range_ = np.array([[lo + 3.0, hi - 2.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = export_params(cal, "px4")
    assert out.params["TC_G0_TMIN"] == pytest.approx(lo + 3.0, abs=1e-9)
    assert out.params["TC_G0_TMAX"] == pytest.approx(hi - 2.0, abs=1e-9)
    assert out.params["TC_G0_TREF"] == pytest.approx(0.5 * (lo + hi + 1.0), abs=1e-9)


def test_a_barometer_offset_fit_by_hand() -> None:
    """A 10 → 40 °C sweep of a barometer (PX4: a 5th-order polynomial in T − TREF, TREF
    the middle of the sweep, relative to the log's median pressure): bins of 0.5 °C
    (medians), the hold-out rms of a polynomial fitted to the even bins judged on the odd
    ones, and the final coefficients, all recomputed here with numpy alone (mutants
    px4-baro-holdout-on-training, px4-baro-tref-low-end)."""
    rng = np.random.default_rng(21)
    n = 30_000
    t = np.arange(n) * 0.1
    temp = 10.0 + 30.0 * t / t[-1]
    p = 101325.0 + 3.0 * (temp - 25.0) + 0.05 * (temp - 25.0) ** 2 + rng.normal(0.0, 2.0, n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = fit_offset_sensor(t, temp, p, "sensor_baro", 0, 1)
    tref = 0.5 * (temp.min() + temp.max())
    assert fit.tref_c == pytest.approx(tref, abs=1e-12) and fit.order == 5
    rel = p - np.median(p)
    lo = np.floor(temp.min() / 0.5) * 0.5
    idx = np.floor((temp - lo) / 0.5).astype(int)
    bins = np.unique(idx)
    x = np.array([np.median(temp[idx == b]) for b in bins]) - tref
    v = np.array([np.median(rel[idx == b]) for b in bins])
    even, odd = slice(0, None, 2), slice(1, None, 2)
    held = np.polyval(np.polyfit(x[even], v[even], 5), x[odd])
    want = float(np.sqrt(np.mean((v[odd] - held) ** 2)))
    insample = np.polyval(np.polyfit(x, v, 5), x[odd])
    assert want > 1.05 * float(np.sqrt(np.mean((v[odd] - insample) ** 2)))
    assert fit.holdout_rms["pressure"] == pytest.approx(want, rel=1e-6)
    np.testing.assert_allclose(fit.coefficients[0], np.polyfit(x, v, 5)[::-1], rtol=1e-6, atol=1e-9)


def test_six_soak_temperatures_are_too_few_bins_for_a_cubic(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Six soaks 0 … 25 °C (a sweep wide enough for the firmware, four distinct
    temperatures and more for a cubic) occupy six 0.5 °C bins: fewer than the 8 a cubic is
    fitted to and judged on (even bins fitted, odd ones judged: 4 + 4), refused with the
    reason (mutant px4-min-bins fits them)."""
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    rng = np.random.default_rng(2)
    per = 3000
    temp = np.repeat([0.0, 5.0, 10.0, 15.0, 20.0, 25.0], per)
    t = np.arange(temp.size) * 0.1
    g = 0.001 * temp[:, None] * np.ones(3) + rng.normal(0.0, 1e-4, (temp.size, 3))
    ts = (1e6 + t * 1e6).astype(np.int64)
    rows = [
        (int(s), 2293768, *map(float, v), float(tt)) for s, v, tt in zip(ts, g, temp, strict=True)
    ]
    log = tmp_path / "soaks.ulg"
    log.write_bytes(ulog_bytes([("sensor_gyro", 0, SENSOR_FIELDS, rows)]))
    assert main(["px4-tempcal", str(log), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "covers 6 bins of 0.5 °C" in err and "at least 8" in err, err
