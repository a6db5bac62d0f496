"""Stable32's PHASE.DAT and its printed outputs (tests/data/stable32_phasedat, allantools'
test data, LGPL-3.0): the rows of an output file, PHASE.DAT as a CSV, one ``allan --json``
run of it; ``allan`` refusing options on a small rate record (exit 2)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main

DATA = Path(__file__).parents[1] / "data" / "stable32_phasedat"


def rows(name: str, *, commented: bool = False) -> np.ndarray:
    """The numeric rows; ``commented``: also the rows allantools' copy comments out with '#'
    (printed by Stable32 all the same)."""
    lines = (DATA / name).read_text(encoding="latin-1").splitlines()
    out = []
    for ln in lines:
        body = ln[1:] if commented and ln.startswith("#") else ln
        if not body.strip() or body.startswith("#"):
            continue
        try:
            out.append([float(v) for v in body.split()])
        except ValueError:  # a commented header line
            continue
    return np.array(out)


def phase_csv(tmp_path: Path) -> Path:
    """PHASE.DAT (1001 points, τ0 = 1 s) as ``time (s),phase [s]``."""
    x = np.loadtxt(DATA / "PHASE.DAT", comments="#")
    assert x.size == 1001
    path = tmp_path / "phase.csv"
    body = "".join(f"{i}.0,{float(v)!r}\n" for i, v in enumerate(x))
    path.write_text("time (s),phase [s]\n" + body)
    return path


def run_allan(
    capsys: pytest.CaptureFixture[str], path: Path, dev: str, taus: np.ndarray, *extra: str
) -> dict[str, Any]:
    """``allan PATH --data-type phase --deviation DEV --taus … --json [extra]``, exit 0."""
    tau_list = ",".join(f"{t:g}" for t in taus)
    code = main(["allan", str(path), "--signal", "phase [s]", "--data-type", "phase",
                 "--deviation", dev, "--taus", tau_list, *extra, "--json"])  # fmt: skip
    cap = capsys.readouterr()
    assert code == 0, cap.err
    return json.loads(cap.out)  # type: ignore[no-any-return]


def allan_refuses(tmp_path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> str:
    """``allan`` on a 400-sample rate record with ``extra`` options: exit 2; its stderr."""
    path = tmp_path / "gyro.csv"
    y = np.random.default_rng(3).standard_normal(400)
    path.write_text(
        "time (s),rate [deg/h]\n" + "".join(f"{i},{float(v)!r}\n" for i, v in enumerate(y))
    )
    code = main(["allan", str(path), "--signal", "rate [deg/h]", *extra])
    err = capsys.readouterr().err
    assert code == 2, err
    return err
