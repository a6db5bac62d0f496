"""ArduPilot parameters changed during a log, hostile cases (:mod:`thermocal.tempcal.ardupilot`):
a parameter set at every sample, the orientation set mid-log, a coefficient set to NaN,
a change stamped before the first sample."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main


def _run(argv: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(argv)
    return code, o.getvalue(), e.getvalue()


def _refused(argv: list[str], *words: str) -> str:
    """Exit 2, exactly one ``error:`` line holding every word, no traceback."""
    code, _o, err = _run(argv)
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2, (code, err)
    assert len(errors) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in errors[0], (w, errors[0])
    return errors[0]


def _ap_log(
    m: dict[str, np.ndarray], before: Any, *, initial: Any = None, data: Any = None
) -> bytes:
    """A DataFlash log of IMU 0 (``m`` from test_fc_log_readers.imu_truth): the initial PARM
    values (default AHRS_ORIENTATION 10, INS_TCAL1_ENABLE 1 and test_ardupilot_param_changes'
    SET_A), ``before(i)`` PARM messages written before sample ``i``; ``data`` (gyro, accel)
    replaces the measured vectors."""
    from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log, parm
    from test_ardupilot_param_changes import SET_A, set_parms

    g, a = data if data is not None else (m["gyro_meas"], m["accel_meas"])
    if initial is None:
        initial = [
            parm("AHRS_ORIENTATION", 10),
            parm("INS_TCAL1_ENABLE", 1),
            *set_parms(SET_A, 1000),
        ]
    msgs = list(initial)
    for i in range(m["temp"].size):
        msgs += before(i)
        msgs.append((100, (int(m["time_us"][i]), 0, *g[i], *a[i], 0, 0, float(m["temp"][i]),
                           1, 1, 1000, 1000)))  # fmt: skip
    return dataflash_log([PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)


def _ap(log: Path, out: Path) -> tuple[int, dict[str, Any], str]:
    code, o, err = _run(["ardupilot-tempcal", str(log), "-o", str(out), "--json"])
    return code, (json.loads(o) if code == 0 else {}), err


def test_ardupilot_parameter_set_at_every_sample(tmp_path: Path) -> None:
    """INS_TCAL1_GYR1_X set again at every one of 6000 samples: every change is in
    log_hygiene.parameter_changes, the note names the first 50 and counts the rest (seen
    red: a note of every change, 270 000 characters), and the run is linear in the changes
    (the changes were merged with a list search and each interval selected with a mask
    over the whole log: O(n²))."""
    from dataflash_writer import parm
    from fc_logs import imu_truth

    m = imu_truth(6000, 11, 1.0)
    tu = m["time_us"]
    log = tmp_path / "every.bin"
    log.write_bytes(_ap_log(m, lambda i: [parm("INS_TCAL1_GYR1_X", float(i % 7), int(tu[i]))]))
    code, res, err = _ap(log, tmp_path / "out")
    assert code == 0, err
    changes = res["log_hygiene"]["parameter_changes"]
    # sample 0 sets 0 (was 60), then 1, 2, …: one change per sample
    assert len(changes) == 6000
    assert changes[1] == {"time_s": pytest.approx(tu[1] * 1e-6), "name": "INS_TCAL1_GYR1_X",
                          "old": 0.0, "new": 1.0}  # fmt: skip
    note = next(n for n in res["notes"] if "changed during the recording" in n)
    assert len(note) < 5000 and "5950 more" in note, len(note)


@pytest.mark.parametrize(
    ("value", "words"),
    [
        (999, ("AHRS_ORIENTATION 999", "not implemented")),
        (-1, ("AHRS_ORIENTATION -1",)),
        (2.5, ("AHRS_ORIENTATION 2.5", "not a rotation code")),  # seen red: int(2.5) = YAW_90
    ],
)
def test_ardupilot_orientation_set_mid_log_to_no_rotation(
    tmp_path: Path, value: float, words: tuple[str, ...]
) -> None:
    from dataflash_writer import parm
    from fc_logs import imu_truth

    m = imu_truth(3000, 11, 1.0)
    t_mid = int(m["time_us"][1500])
    log = tmp_path / "o.bin"
    log.write_bytes(
        _ap_log(m, lambda i: [parm("AHRS_ORIENTATION", value, t_mid)] if i == 1500 else [])
    )
    _refused(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")], *words)


def test_ardupilot_coefficient_set_to_nan_mid_log(tmp_path: Path) -> None:
    """Seen red: refused as "column 'x' has 1500 NaN values", naming no parameter."""
    from dataflash_writer import parm
    from fc_logs import imu_truth

    m = imu_truth(3000, 11, 1.0)
    t_mid = int(m["time_us"][1500])
    log = tmp_path / "n.bin"
    log.write_bytes(
        _ap_log(m, lambda i: [parm("INS_TCAL1_GYR1_X", float("nan"), t_mid)] if i == 1500 else [])
    )
    _refused(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")], "INS_TCAL1_GYR1_X",
             f"{t_mid * 1e-6:.3f} s")  # fmt: skip


def test_ardupilot_change_before_the_first_sample_is_the_initial_value(tmp_path: Path) -> None:
    """SET_B set 0.5 ms before the first IMU sample is, for every sample, what SET_B as the
    log's initial values is: the same data give the same parameter file, value for value."""
    from dataflash_writer import parm
    from fc_logs import imu_truth
    from test_ardupilot_param_changes import SET_B, corrected, set_parms

    m = imu_truth(12000, 13, 1.0)
    temp32 = m["temp"].astype(np.float32).astype(np.float64)
    data = (corrected(m["gyro_meas"], temp32, "GYR", SET_B),
            corrected(m["accel_meas"], temp32, "ACC", SET_B))  # fmt: skip
    t_before = int(m["time_us"][0]) - 500
    changed = tmp_path / "changed.bin"
    changed.write_bytes(
        _ap_log(m, lambda i: set_parms(SET_B, t_before) if i == 0 else [], data=data)
    )
    first = tmp_path / "first.bin"
    initial = [parm("AHRS_ORIENTATION", 10), parm("INS_TCAL1_ENABLE", 1), *set_parms(SET_B, 1000)]
    first.write_bytes(_ap_log(m, lambda i: [], initial=initial, data=data))
    code, res, err = _ap(changed, tmp_path / "c")
    assert code == 0, err
    assert res["log_hygiene"]["parameter_changes"][0]["time_s"] == pytest.approx(t_before * 1e-6)
    code, _r, err = _ap(first, tmp_path / "f")
    assert code == 0, err
    assert (tmp_path / "c" / "ardupilot.parm").read_text() == (
        tmp_path / "f" / "ardupilot.parm"
    ).read_text()
