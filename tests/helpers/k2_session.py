"""A simulated multi-position session with a known K2 per axis (the simulator's sessions,
``K2 ⊙ (f/g)²`` added here to the accelerometer columns [m/s²]), shared by the K2 tests of
compensate and the C export."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from thermocal.cli import main

COLS = ["accel_x", "accel_y", "accel_z"]
K2 = np.array([0.05, -0.04, 0.03])  # m/s² per g², the simulated truth


def simulate(tmp: Path) -> list[dict[str, Any]]:
    """The simulator's sessions (seed 4) in ``tmp/mp`` and their truth, K2 not yet added."""
    assert main(["simulate", "multipos", "-o", str(tmp / "mp"), "--truth",
                 str(tmp / "t.json"), "--seed", "4"]) == 0  # fmt: skip
    files: list[dict[str, Any]] = json.loads((tmp / "t.json").read_text())["files"]
    return files


def add_k2(files: list[dict[str, Any]]) -> None:
    """``K2 ⊙ (f/g)²`` added to every session's accelerometer columns (g the truth's)."""
    for truth in files:
        p = Path(truth["file"])
        df = pd.read_csv(p)
        f = df[COLS].to_numpy()
        df[COLS] = f + K2 * (f / truth["gravity_m_s2"]) ** 2
        df.to_csv(p, index=False)


def calibrate(files: list[dict[str, Any]], out: Path, *extra: str) -> None:
    """``thermocal multipos`` on the first (not held-out) session, accelerometer only."""
    assert main(["multipos", files[0]["file"], "-o", str(out), "--accel", ",".join(COLS),
                 *extra]) == 0  # fmt: skip


def held_out(files: list[dict[str, Any]]) -> dict[str, Any]:
    """The held-out session's truth."""
    return next(f for f in files if f["held_out"])


def pose_residuals(out: Path, truth: dict[str, Any]) -> np.ndarray:
    """Each pose's mean compensated |f| less the simulator's gravity [m/s²]."""
    df = pd.read_csv(out)
    f = df[[f"{c}_comp" for c in COLS]].to_numpy()
    poses = json.loads(truth["poses"]) if isinstance(truth["poses"], str) else truth["poses"]
    means = np.array([np.linalg.norm(f[a:b].mean(axis=0)) for a, b in poses])
    return np.asarray(means - truth["gravity_m_s2"])
