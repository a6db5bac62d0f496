"""``thermocal validate`` tried as a new user would, on the shipped public sessions
(``tests/data/``) or simulated records: the earth rate a fit kept in its bias, validating
on the calibration session, one signal unit for two triads, the accelerometer's per-axis
figures against the total."""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

DATA = Path(__file__).parents[1] / "data"


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


MPU = DATA / "imucalibration_mpu6050"


MPU_ARGS = ["--accel", "ax,ay,az", "--gyro", "gx,gy,gz", "--rate", "100", "--gravity", "9.81",
            "--accel-scale", "0.00006103515625,g", "--gyro-scale", "0.00763,deg/s",
            "--gyro-model", "scale"]  # fmt: skip


@pytest.fixture(scope="module")
def mpu_cal(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The MPU-6050 session calibrated as its README says (±2 g, ±250 °/s, 100 Hz)."""
    cal = tmp_path_factory.mktemp("mpu") / "mpu.json"
    code, _, err = _run(["multipos", str(MPU / "example_data_calibration.csv"),
                         "-o", str(cal), *MPU_ARGS])  # fmt: skip
    assert code == 0, err
    return cal


def test_validate_names_the_earth_rate_a_fit_kept_in_its_bias(tmp_path: Path) -> None:
    """``simulate rlg-modelling``/``rlg-validation`` (metadata: latitude 45°, axis up), then
    ``fit --model poly`` and ``validate``: the fit took nothing off (no --latitude/--axis),
    validate takes the metadata's earth rate as the zero, so the compensated output reads
    −Ω_up (−10.64 °/h: 15.041 °/h · sin 45°) and the verdict is "NOT improved" — true, but
    the warning blamed "another power-on, temperature or sensor?".  It now names the cause
    and the fit options; with them the same run is improved."""
    mod, val = tmp_path / "m.parquet", tmp_path / "v.parquet"
    assert _run(["simulate", "rlg-modelling", "-o", str(mod)])[0] == 0
    assert _run(["simulate", "rlg-validation", "-o", str(val)])[0] == 0
    omega_up = 15.041067 * np.sin(np.radians(45.0))  # °/h, the earth rate on the up axis
    cases = (([], "NOT improved"), (["--latitude", "45", "--axis", "up"], "improved"))
    for extra, verdict in cases:
        cal = tmp_path / f"m{len(extra)}.json"
        assert _run(["fit", str(mod), "-o", str(cal), "--model", "poly", *extra])[0] == 0
        code, out, err = _run(["validate", str(cal), str(val), "--json"])
        assert code == 0, err
        d = json.loads(out)
        assert d["verdict"].startswith(verdict), d["verdict"]
        assert d["zero_reference"]["value"] == pytest.approx(omega_up, rel=1e-4)
        if not extra:
            assert d["mean_after"] == pytest.approx(-omega_up, rel=0.01)
            assert "fit --latitude 45 --axis up" in err and "another power-on" not in err, err
        else:
            assert "absolute error worse" not in err, err


def test_validating_on_the_calibration_session_is_said(mpu_cal: Path, tmp_path: Path) -> None:
    """A user who validates (and reports) the MPU-6050 calibration on its own session got
    figures headed "On the independent run … held-out session", no warning: the fit's
    residuals passed for an independent test.  The calibration now records its sessions'
    SHA-256 (``triads[].data``, as a model file's ``data``); the held-out file is still
    "independent"."""
    own, held = MPU / "example_data_calibration.csv", MPU / "imu_90_x_rot.csv"
    cal = json.loads(mpu_cal.read_text(encoding="utf-8"))
    sha = hashlib.sha256(own.read_bytes()).hexdigest()
    assert all(t["data"] == [{"file": own.name, "sha256": sha}] for t in cal["triads"])
    for rec, is_own in ((own, True), (held, False)):
        code, out, err = _run(["validate", str(mpu_cal), str(rec), "--rate", "100", "--json"])
        assert code == 0, err
        assert ("the session the calibration was fitted on" in err) is is_own, err
        val = tmp_path / f"v{is_own}.json"
        val.write_text(out, encoding="utf-8")
        html = tmp_path / f"r{is_own}.html"
        code, _, err = _run(["report", "--model", str(mpu_cal), "--recording", str(rec),
                             "--rate", "100", "--validation", str(val),
                             "-o", str(html)])  # fmt: skip
        assert code == 0, err
        page = html.read_text(encoding="utf-8")
        assert ("On the calibration's own session" in page) is is_own
        assert ("On the independent run" in page) is not is_own
        assert ("found in the held-out session" in page) is not is_own


def test_one_signal_unit_for_two_triads_points_to_one_per_column(mpu_cal: Path) -> None:
    """``validate`` of the MPU-6050 calibration (accelerometer and gyro) with one
    ``--signal-unit deg/s`` said "the accel triad was calibrated on g data; these columns
    are in deg/s": no columns, no way forward (and the triad was calibrated on counts)."""
    code, _, err = _run(["validate", str(mpu_cal), str(MPU / "imu_90_x_rot.csv"), "--rate",
                         "100", "--signal-unit", "deg/s"])  # fmt: skip
    assert code == 2
    (line,) = [ln for ln in err.splitlines() if ln.startswith("error: ")]
    assert "raw counts of g data" in line and "'ax', 'ay', 'az'" in line, line
    assert "--signal-unit one unit per triad column" in line, line


def test_accel_per_axis_figures_add_up_to_the_total(mpu_cal: Path) -> None:
    """``validate`` of the MPU-6050 calibration on its held-out turn: "gravity-magnitude
    error rms [g] (total 0.03916 → 0.001337)" above per-axis "before" figures of 0.0444,
    0.0194 and 0.1058 g — each axis's larger than the total, because "before" was the raw
    mean's vector error against the *compensated* direction, another figure.  Per axis is
    now the magnitude error along the pose's own direction, before as after, so the axes add
    in quadrature to the total (as the gyro's rotation-angle errors do)."""
    code, out, err = _run(["validate", str(mpu_cal), str(MPU / "imu_90_x_rot.csv"),
                           "--rate", "100", "--json"])  # fmt: skip
    assert code == 0, err
    for tri in json.loads(out)["triads"].values():
        for when in ("before", "after"):
            total = tri[f"rms_{when}"]
            axes = np.asarray(tri[f"per_axis_{when}"])
            assert float(np.sqrt(np.sum(axes**2))) == pytest.approx(total, rel=1e-9), tri
