"""``inspect`` states a quantised or slow thermometer: a CSV whose temperature is read by a
BMI088-like thermometer (0.125 °C lattice about 23 °C, updated every 1.28 s, the gyro at
100 Hz) and another column with a continuous one; the step and the period are the
simulator's."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.inspection import inspect_recording
from thermocal.recording import Recording


def _columns() -> dict[str, np.ndarray]:
    t = np.arange(0, 900.0, 0.01)
    true = 20.0 + 15.0 * t / t[-1] + 0.3 * np.sin(t / 50.0)
    upd = np.floor((t - 0.3) / 1.28) * 1.28 + 0.3
    bmi = 23.0 + 0.125 * np.round((np.interp(np.maximum(upd, 0), t, true) - 23.0) / 0.125)
    gyro = 0.01 * (true - 20) + np.random.default_rng(0).normal(0, 0.01, t.size)
    return {"time_s": t, "gyro": gyro, "T_bmi": bmi, "T_fine": true}


def test_inspection_states_the_thermometers() -> None:
    c = _columns()
    rec = Recording.from_arrays(
        c["time_s"], {"gyro": c["gyro"]}, {"T_bmi": c["T_bmi"], "T_fine": c["T_fine"]},
        signal_unit="deg/s",
    )  # fmt: skip
    th = inspect_recording(rec).thermometers
    assert th["T_bmi"] is not None and th["T_fine"] is not None
    assert th["T_bmi"]["step_c"] == pytest.approx(0.125, abs=1e-9)
    assert th["T_bmi"]["update_period_s"] == pytest.approx(1.28, abs=0.01)
    assert th["T_bmi"]["quantised"] and th["T_bmi"]["slow"]
    assert th["T_fine"]["kind"] == "continuous"


def test_inspect_command_json_and_text(tmp_path: Path) -> None:
    c = _columns()
    path = tmp_path / "bmi.csv"
    np.savetxt(path, np.column_stack(list(c.values())), delimiter=",",
               header=",".join(c), comments="", fmt="%.6f")  # fmt: skip
    before = path.read_bytes()
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["inspect", str(path), "--temps", "T_bmi,T_fine", "--signal-unit", "deg/s",
                     "--json"])  # fmt: skip
    assert code == 0
    got = json.loads(buf.getvalue())["thermometers"]
    assert got["T_bmi"]["kind"] == "quantised (0.125 °C) and slow (updated every 1.28 s)"
    assert got["T_fine"]["quantised"] is False
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["inspect", str(path), "--temps", "T_bmi,T_fine", "--signal-unit", "deg/s"])
    assert code == 0
    text = " ".join(buf.getvalue().split())
    assert "temperature 'T_bmi': the thermometer is quantised (0.125 °C)" in text
    assert "'T_fine': the thermometer" not in text
    assert path.read_bytes() == before
