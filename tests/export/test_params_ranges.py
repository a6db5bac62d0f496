"""The temperature range and reference the firmware parameters carry
(:mod:`thermocal.export.params`, :mod:`thermocal.export.triad_params`): ArduPilot's one
range per instance, where every channel was fitted, and PX4's range and reference of a
triad.  Each kills a mutant of ``benchmarks/mutation_check.py`` (``params-*``); the
expected values are worked out here from the firmware's documented conventions."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.export.params import export_params
from thermocal.pipeline.model_file import load_calibration
from thermocal.simulate import SCENARIOS
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
