"""Issue 38: generated C that reads as it runs.

A gyro fitted with the earth rate removed (``--latitude 48.1 --axis up``) gave a header with
``48.1\\u00b0``, a known input stated in deg/h beside a setter that takes deg/s, and a state
field commented ``[deg/h]`` under ``SIGNAL_UNIT "deg/s" (unit of ... known_input)``; a triad
calibrated without a temperature column read ``T [degC] of ,``.  Now: plain ASCII, the known
input in the setter's unit (the earth rate's vertical component computed here from Ω and the
latitude), and the C, compiled with ``-std=c99 -Wall -Wextra -Werror -pedantic``, equal to
``thermocal compensate`` to 1e-9."""

from __future__ import annotations

import math
import re
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.export.c import compile_harness, generate_c, run_harness
from thermocal.export.c.harness import CFLAGS, find_compiler
from thermocal.export.c.triad import generate_c_triads
from thermocal.models.calibration import Triad
from thermocal.pipeline.model_file import load_model_dict
from thermocal.turntable import thermal

needs_cc = pytest.mark.skipif(find_compiler() is None, reason="no C compiler")
OMEGA_E_RAD_S = 7.2921150e-5  # WGS-84 earth rate
STRICT = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")


def _no_escapes(text: str) -> None:
    assert not re.search(r"\\[uU][0-9a-fA-F]{4}", text), re.findall(r".*\\[uU].*", text)
    assert " of ," not in text and " of ;" not in text


@needs_cc
def test_earth_rate_model_header_plain_and_in_the_setter_unit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert set(STRICT) <= set(CFLAGS)  # the harness compiles as strictly as the issue asks
    rng = np.random.default_rng(11)
    n = 1500
    t = np.arange(n, dtype=float)
    tc = 25.0 + 15.0 * np.sin(2 * np.pi * t / n)
    earth_dps = OMEGA_E_RAD_S * math.degrees(1.0) * math.sin(math.radians(48.1))
    gyro = earth_dps + 0.01 + 2e-4 * (tc - 25.0) + 1e-5 * rng.standard_normal(n)
    src = tmp_path / "run.csv"
    pd.DataFrame({"time": t, "gyro": gyro, "T1": tc}).to_csv(src, index=False)
    model = tmp_path / "lat.json"
    assert main(["fit", str(src), "--model", "poly", "--terms", "T1,T1^2", "--signal", "gyro",
                 "--signal-unit", "deg/s", "--temps", "T1", "--time-unit", "s", "--temp-unit",
                 "degC", "--latitude", "48.1", "--axis", "up", "-o", str(model)]) == 0  # fmt: skip
    assert main(["export-c", str(model), "-o", str(tmp_path / "c")]) == 0
    capsys.readouterr()
    header = (tmp_path / "c" / "lat.h").read_text()
    source = (tmp_path / "c" / "lat.c").read_text()
    _no_escapes(header + source)
    assert "latitude 48.1deg" in header
    m = re.search(r"known input:\s+(\S+) deg/s \((\S+) deg/h\)", header)
    assert m is not None, header
    assert float(m.group(1)) == pytest.approx(earth_dps, rel=1e-6)
    assert float(m.group(2)) == pytest.approx(earth_dps * 3600.0, rel=1e-6)
    assert "what lat_set_known_input gives, in [deg/s]" in header
    field = next(ln for ln in header.splitlines() if "known_input;" in ln)
    assert "[deg/h], set in [deg/s] by lat_set_known_input" in field
    # the C, given the known input in deg/s, equals compensate's model column
    out = tmp_path / "comp.csv"
    assert main(["compensate", str(model), str(src), "-o", str(out)]) == 0
    capsys.readouterr()
    y_py = np.asarray(pd.read_csv(out)["gyro_model"], dtype=float)
    ex = generate_c(load_model_dict(model), prefix="lat")
    y_c = run_harness(compile_harness(ex, tmp_path / "b"), t, tc[:, None], gyro, 1.0,
                      known_input=float(m.group(1)))  # fmt: skip
    np.testing.assert_allclose(y_c, y_py, rtol=1e-9, atol=1e-9 * np.abs(y_py).max())


@needs_cc
def test_triad_without_temperature_column_says_so_and_compiles(tmp_path: Path) -> None:
    theta = np.array([5.0, -3.0, 2.0, 100.0, -50.0, 20.0, 30.0, -20.0, 10.0, 5.0, -8.0, 4.0])
    m = thermal.constant_triad("accel", 25.0, theta, np.eye(12) * 1e-4)
    tri = Triad("accel", ("ax", "ay", "az"), "m/s^2", "", m)  # multipos without --temps
    ex = generate_c_triads([tri], prefix="mp")
    _no_escapes(ex.header + ex.source)
    assert "no temperature column (none measured)" in ex.header
    assert "calibrated at" not in ex.header
    ex.write(tmp_path)
    main_c = tmp_path / "main.c"
    main_c.write_text(
        '#include <stdio.h>\n#include "mp.h"\nint main(void)\n{\n'
        "    double x[3] = {1.0, -2.0, 9.8}, a[3], b[3];\n"
        "    mp_accel_correct(-40.0, x, a);\n    mp_accel_correct(80.0, x, b);\n"
        '    printf("%.17g %.17g %.17g %.17g\\n", a[0], a[2], b[0], b[2]);\n    return 0;\n}\n'
    )
    exe = tmp_path / "mp"
    subprocess.run([str(find_compiler()), *STRICT, "-o", str(exe), str(tmp_path / "mp.c"),
                    str(main_c)], check=True)  # fmt: skip
    got = [float(v) for v in subprocess.run([str(exe)], capture_output=True, text=True,
                                            check=True).stdout.split()]  # fmt: skip
    py = thermal.correct(m, np.array([[1.0, -2.0, 9.8]]), [25.0], 9.80665e-3)[0]
    assert got[0] == pytest.approx(got[2]) and got[1] == pytest.approx(got[3])  # T has no effect
    np.testing.assert_allclose([got[0], got[1]], [py[0], py[2]], rtol=1e-12)
