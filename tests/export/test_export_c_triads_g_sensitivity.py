"""The C of a calibration whose gyro triad holds a g-sensitivity (issue 44): the gyro's
function takes the accelerometer function's output and takes ``A f`` off; compiled with the
C compiler and run on the simulated session's samples, it equals ``thermocal compensate``
to 1e-6 relative (and 1e-9 °/s); without the force it would not.  ``export-params`` says
the firmware holds no ``A``."""

from __future__ import annotations

import subprocess
from typing import Any

import numpy as np
import pandas as pd
import pytest

from gsens_session import READ, calibrate, run, write_session
from thermocal.export.c.harness import find_compiler

MAIN = r"""
#include <stdio.h>
#include "imu.h"
int main(void)
{
    double t, a[3], g[3], ac[3], gc[3];
    while (scanf("%lf %lf %lf %lf %lf %lf %lf", &t, &a[0], &a[1], &a[2], &g[0], &g[1], &g[2])
           == 7) {
        imu_accel_correct(25.0, a, ac);
        imu_gyro_correct(25.0, g, ac, gc);
        printf("%.17g %.17g %.17g %.17g %.17g %.17g\n", ac[0], ac[1], ac[2], gc[0], gc[1], gc[2]);
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("gsens_c")
    write_session(d, seed=6)
    calibrate(d)
    return {"dir": d}


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler on this machine")
def test_c_equals_compensate(made: dict[str, Any]) -> None:
    """Seen red with the A f term left out of the C: differences of ~0.04 °/s."""
    d = made["dir"]
    code, _o, err = run(["export-c", str(d / "cal.json"), "-o", str(d / "c"), "--name", "imu"])
    assert code == 0, err
    header = (d / "c" / "imu.h").read_text()
    assert "const double f[3]" in header and "A f" in header
    (d / "c" / "main.c").write_text(MAIN)
    exe = d / "c" / "imu"
    subprocess.run([str(find_compiler()), "-O2", "-std=c99", "-Wall", "-Wextra", "-Werror",
                    "-pedantic", "-o", str(exe), str(d / "c" / "imu.c"),
                    str(d / "c" / "main.c")], check=True)  # fmt: skip
    code, _o, err = run(["compensate", str(d / "cal.json"), str(d / "s.csv"), "-o",
                         str(d / "py.csv"), *READ])  # fmt: skip
    assert code == 0, err
    data = pd.read_csv(d / "s.csv")
    rows = data[["t", "ax", "ay", "az", "gx", "gy", "gz"]].to_numpy().tolist()
    text = "\n".join(" ".join(repr(float(v)) for v in row) for row in rows)
    res = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    c_out = np.array([[float(v) for v in line.split()] for line in res.stdout.splitlines()])
    py = pd.read_csv(d / "py.csv")
    acc = py[["ax_comp", "ay_comp", "az_comp"]].to_numpy()
    gyr = py[["gx_comp", "gy_comp", "gz_comp"]].to_numpy()
    np.testing.assert_allclose(c_out[:, 0:3], acc, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(c_out[:, 3:6], gyr, rtol=1e-6, atol=1e-9)
    # the term matters here: the gyro's A f is far beyond the tolerance
    code, _o, err = run(["compensate", str(d / "cal.json"), str(d / "s.csv"), "-o",
                         str(d / "off.csv"), *READ, "--g-sensitivity", "off"])  # fmt: skip
    assert code == 0, err
    off = pd.read_csv(d / "off.csv")[["gx_comp", "gy_comp", "gz_comp"]].to_numpy()
    assert np.max(np.abs(off - gyr)) > 1e-2


def test_export_params_warns_that_the_firmware_holds_no_a(made: dict[str, Any]) -> None:
    d = made["dir"]
    for fmt in ("px4", "ardupilot"):
        out = d / f"{fmt}.params"
        code, _o, err = run(["export-params", str(d / "cal.json"), "--format", fmt, "-o",
                             str(out)])  # fmt: skip
        assert code == 0, err
        warned = [ln for ln in err.splitlines() if "g-sensitivity" in ln]
        assert len(warned) == 1 and warned[0].startswith("warning:"), err
        assert "deg/s/g" in warned[0] and "not held" in warned[0]
        assert "g-sensitivity" in out.read_text()
