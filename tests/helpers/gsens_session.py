"""A simulated multi-position session whose gyro has a known g-sensitivity, written as a CSV
(``t`` [s], ``ax, ay, az`` [mg], ``gx, gy, gz`` [deg/s]) and calibrated by ``thermocal
multipos``: shared by the compensation and the C-export tests of the g-sensitivity."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from thermocal.cli import main
from thermocal.multipos.simulate import simulate_session

A_TRUE = np.array([[180.0, -90.0, 36.0], [50.0, -250.0, 120.0], [-30.0, 60.0, 300.0]])
"""The gyro's g-sensitivity [deg/h per g], row the gyro axis, column the force's axis."""
ACCEL_THETA = np.array([30.0, -45.0, 25.0, 6000.0, -4000.0, 3000.0, 0, 0, 300.0, 0, -250.0, 200.0])
GYRO_THETA = np.array(
    [3000.0, -2000.0, 1500.0, 4000.0, -3000.0, 2500.0, 500.0, -400.0, 300.0, 200.0, -100.0, 600.0]
)
GYRO_NOISE_DEG_S = 0.03
LATITUDE_DEG = 45.0
READ = ["--time", "t", "--time-unit", "s"]
MULTIPOS = [*READ, "--accel", "ax,ay,az", "--accel-unit", "mg", "--gyro", "gx,gy,gz",
            "--gyro-unit", "deg/s", "--latitude", str(LATITUDE_DEG)]  # fmt: skip


def run(args: list[str]) -> tuple[int, str, str]:
    """``thermocal ARGS``: exit status, stdout, stderr."""
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def write_session(
    folder: Path, seed: int = 5, a_deg_h_g: Any = A_TRUE, *, k2_mg_g2: Any = None,
    name: str = "s.csv", n_poses: int = 16,
) -> dict[str, Any]:  # fmt: skip
    """The session simulated with ``a_deg_h_g`` (and the accelerometer's ``k2_mg_g2``
    [mg per g²]) and written to ``folder/NAME``."""
    s = simulate_session(np.random.default_rng(seed), ACCEL_THETA, GYRO_THETA, n_poses=n_poses,
                         gyro_noise_deg_s=GYRO_NOISE_DEG_S, latitude_deg=LATITUDE_DEG,
                         g_sensitivity_deg_h_g=a_deg_h_g, accel_k2_mg_g2=k2_mg_g2)  # fmt: skip
    cols = {"t": s["time_s"]}
    cols.update({f"a{c}": s["accel_mg"][:, k] for k, c in enumerate("xyz")})
    cols.update({f"g{c}": s["gyro_deg_s"][:, k] for k, c in enumerate("xyz")})
    pd.DataFrame(cols).to_csv(folder / name, index=False)
    return s


def calibrate(folder: Path, *extra: str, name: str = "cal.json") -> dict[str, Any]:
    """``multipos`` on ``folder/s.csv`` into ``folder/NAME``; its JSON result."""
    code, out, err = run(["multipos", str(folder / "s.csv"), *MULTIPOS, "-o",
                          str(folder / name), "--json", *extra])  # fmt: skip
    assert code == 0, err
    result: dict[str, Any] = json.loads(out)
    return result
