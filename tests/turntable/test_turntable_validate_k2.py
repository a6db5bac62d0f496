"""A turntable validation inverts an accelerometer triad's stored K2 as ``compensate`` does.

Three simulated soaks calibrate the triads (``turntable --accel``); the held-out soak's
accelerometer columns get ``K2 ⊙ (a/g)²`` added, ``a`` the true specific force recovered
here from the simulator's own accelerometer parameters (``accel_theta_at_mean``) and
K2 = (0.05, −0.04, 0.03) m/s²/g².  The calibration given that K2 brings the held-out
dwell means to the floor (the same soak without K2 judged by the calibration without it:
0.083, 0.079, 0.048 mg measured); without it they keep K2's few mg (2.6, 2.1, 2.1 mg), and
so did every validation before (K2 was left out).  Library and ``validate --json`` alike."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.models.calibration import Calibration
from thermocal.pipeline.model_file import load_calibration, save_calibration
from thermocal.turntable.calibration import validate_turntable_run
from thermocal.turntable.model import error_matrices
from thermocal.turntable.simulate import simulate_turntable_thermal
from thermocal.writers import write_recording

K2 = np.array([0.05, -0.04, 0.03])  # m/s² per g², the truth added
G0 = 9.80665
COLS = ["accel_x", "accel_y", "accel_z"]


@pytest.fixture(scope="module")
def soaks(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("k2soaks")
    files, held, truth_h = [], None, None
    for rec, truth in simulate_turntable_thermal(seed=3, soaks_c=(-20.0, 20.0, 60.0)):
        if truth["held_out"]:
            held, truth_h = rec, truth
        else:
            files.append(d / f"{truth['label']}.parquet")
            write_recording(rec, files[-1])
    assert held is not None and truth_h is not None
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["turntable", *map(str, files), "--temps", "T_imu", "--order", "1",
                     "--accel", ",".join(COLS), "-o", str(d / "cal.json")]) == 0  # fmt: skip
    th = np.asarray(truth_h["accel_theta_at_mean"])  # mg, ppm, arcsec
    raw = np.column_stack([held.column(c) for c in COLS])  # m/s²
    a = np.linalg.solve(np.eye(3) + error_matrices(th), (raw - th[0:3] * G0 / 1000.0).T).T
    held_k2 = held.with_columns(
        {c: raw[:, k] + K2[k] * (a[:, k] / G0) ** 2 for k, c in enumerate(COLS)},
        dict.fromkeys(COLS, "m/s^2"),
    )
    triads = list(load_calibration(d / "cal.json").triads)
    with_k2 = [dataclasses.replace(t, k2=K2.copy(), k2_sigma=np.full(3, 1e-3))
               if t.name == "accel" else t for t in triads]  # fmt: skip
    return {"d": d, "held": held, "held_k2": held_k2, "triads": triads, "with_k2": with_k2}


def _accel(results: list[Any]) -> Any:
    return next(v for v in results if v.triad == "accel")


def test_the_stored_k2_is_inverted(soaks: dict[str, Any]) -> None:
    floor = _accel(validate_turntable_run(soaks["triads"], soaks["held"])).dwell_rms_after
    got = _accel(validate_turntable_run(soaks["with_k2"], soaks["held_k2"]))
    left = _accel(validate_turntable_run(soaks["triads"], soaks["held_k2"]))
    assert max(floor) < 0.1  # mg
    for f, g, w in zip(floor, got.dwell_rms_after, left.dwell_rms_after, strict=True):
        assert g < 1.05 * f and w > 10 * f, (f, g, w)
    assert got.dwell_rms_before == left.dwell_rms_before  # "before": the raw samples


def test_validate_command_inverts_it(soaks: dict[str, Any]) -> None:
    d = soaks["d"]
    save_calibration(Calibration([], soaks["with_k2"]), d / "k2.json")
    write_recording(soaks["held_k2"], d / "held_k2.parquet")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["validate", str(d / "k2.json"), str(d / "held_k2.parquet"), "--json"]) == 0
    acc = json.loads(out.getvalue())["triads"]["accel"]
    want = _accel(validate_turntable_run(soaks["with_k2"], soaks["held_k2"])).dwell_rms_after
    assert acc["unit"] == "mg" and acc["dwell_rms_after"] == pytest.approx(want, rel=1e-9)
    assert max(acc["dwell_rms_after"]) < 0.1
