"""The C of a calibration of triads (issue 19) against Python's correction, to 1e-9, on
samples whose temperatures run past both ends of the calibrated range (clamping); and the
command refusals for what does not handle triads yet."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from thermocal import units
from thermocal.cli import main
from thermocal.export.c.harness import find_compiler
from thermocal.export.c.triad import generate_c_triads
from thermocal.models.calibration import Calibration, Triad
from thermocal.pipeline.model_file import save_calibration
from thermocal.turntable import thermal

SOAKS = np.array([-40.0, -20.0, 0.0, 20.0, 40.0, 60.0])

MAIN = r"""
#include <stdio.h>
#include "tri.h"
int main(void)
{
    double t, x[3], g[3], a[3];
    while (scanf("%lf %lf %lf %lf", &t, &x[0], &x[1], &x[2]) == 4) {
        tri_gyro_correct(t, x, g);
        tri_accel_correct(t, x, a);
        printf("%.17g %.17g %.17g %.17g %.17g %.17g\n", g[0], g[1], g[2], a[0], a[1], a[2]);
    }
    return 0;
}
"""


def _theta(t: np.ndarray, scale: float) -> np.ndarray:
    d = t - 10.0
    cols = [scale * (0.5 + 0.01 * d - 2e-4 * d**2 + 3e-6 * d**3) * (i + 1) for i in range(3)]
    cols += [80.0 * (i - 1) + 2.0 * d + 0.02 * d**2 for i in range(3)]
    cols += [20.0 * (k - 2.5) + 0.3 * (k - 2) * d for k in range(6)]
    return np.stack(cols, axis=-1)


def _calibration() -> Calibration:
    sg = np.tile([0.01] * 3 + [1.0] * 3 + [0.5] * 6, (SOAKS.size, 1))
    gyro = thermal.fit_triad("gyro", SOAKS, _theta(SOAKS, 1.0), sg, order=3)
    acc = thermal.fit_triad("accel", SOAKS, _theta(SOAKS, 2.0), sg, order=3)
    return Calibration(
        [],
        [
            Triad("gyro", ("gx", "gy", "gz"), "deg/s", "T", gyro),
            Triad("accel", ("ax", "ay", "az"), "m/s^2", "T", acc),
        ],
    )


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler on this machine")
def test_c_matches_python_with_clamping(tmp_path: Path) -> None:
    cal = _calibration()
    ex = generate_c_triads(cal.triads, prefix="tri")
    ex.write(tmp_path)
    (tmp_path / "main.c").write_text(MAIN)
    exe = tmp_path / "tri"
    subprocess.run([str(find_compiler()), "-O2", "-std=c99", "-Wall", "-Wextra", "-Werror",
                    "-pedantic", "-o", str(exe), str(tmp_path / "tri.c"), str(tmp_path / "main.c")],
                   check=True)  # fmt: skip
    rng = np.random.default_rng(0)
    n = 5000
    temp = np.linspace(-70.0, 90.0, n)  # past both ends of −40…60
    x = rng.normal(0.0, 50.0, (n, 3))
    rows = np.column_stack([temp, x]).tolist()  # Python floats: repr is the shortest exact form
    text = "\n".join(" ".join(repr(v) for v in row) for row in rows)
    res = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    c_out = np.array([[float(v) for v in line.split()] for line in res.stdout.splitlines()])
    to_g = float(units.convert([1.0], "deg/h", "deg/s")[0])
    to_a = float(units.convert([1.0], "mg", "m/s^2")[0])
    py_g = thermal.correct(cal.triads[0].model, x, temp, to_g)
    py_a = thermal.correct(cal.triads[1].model, x, temp, to_a)
    np.testing.assert_allclose(c_out[:, 0:3], py_g, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(c_out[:, 3:6], py_a, rtol=1e-9, atol=1e-9)
    # the clamping is exercised: the ends give the values at −40 and 60 °C
    assert np.allclose(
        py_g[temp < -40.0][:1],
        thermal.correct(cal.triads[0].model, x[temp < -40.0][:1], [-40.0], to_g),
    )


def test_commands_that_do_not_handle_triads_say_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "cal.json"
    save_calibration(_calibration(), path)
    rec = tmp_path / "r.csv"
    rec.write_text("time,gx,T\n0,1,20\n1,1,20\n")
    # validate takes a calibration of triads, but on a turntable run: this file has no encoders
    assert main(["validate", str(path), str(rec), "--latitude", "45"]) == 2
    assert "alpha_deg" in capsys.readouterr().err
    assert main(["report", "--model", str(path), "--recording", str(rec), "-o",
                 str(tmp_path / "r.html"), "--latitude", "45"]) == 2  # fmt: skip
    assert "alpha_deg" in capsys.readouterr().err
    assert not (tmp_path / "r.html").exists()
    # export-params takes triads since issue 30: the firmware's offsets and scales, with
    # what it cannot hold (misalignment, temperature dependence) warned
    assert main(["export-params", str(path), "--format", "px4", "-o", str(tmp_path / "p")]) == 0
    assert "not held" in capsys.readouterr().err
    assert "CAL_GYRO0_XOFF" in (tmp_path / "p").read_text()
