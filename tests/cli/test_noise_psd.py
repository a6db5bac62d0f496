"""``thermocal noise FILE --psd PSD.csv``: the spectra written beside the Kalibr file, the
PSD's white level and the ADEV's agreeing within 10 % on simulated white noise; the PSD file
never over the input or the other output."""

from __future__ import annotations

import csv as csvmod
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

DT = 0.01


@pytest.fixture(scope="module")
def imu(tmp_path_factory: pytest.TempPathFactory) -> Path:
    import pandas as pd

    rng = np.random.default_rng(21)
    n = 120_000
    df = pd.DataFrame({"time [s]": np.arange(n) * DT})
    for c in ("gx", "gy", "gz"):
        df[c + " [rad/s]"] = rng.normal(0.0, 1e-4 / np.sqrt(DT), n)
    for c, g in (("ax", 0.0), ("ay", 0.0), ("az", 9.81)):
        df[c + " [m/s^2]"] = g + rng.normal(0.0, 1e-3 / np.sqrt(DT), n)
    path = tmp_path_factory.mktemp("psd") / "imu.csv"
    df.to_csv(path, index=False, float_format="%.9g")
    return path


def _args(imu: Path, out: Path, psd: Path) -> list[str]:
    return ["noise", str(imu), "--time", "time [s]", "--gyro",
            "gx [rad/s],gy [rad/s],gz [rad/s]", "--accel", "ax [m/s^2],ay [m/s^2],az [m/s^2]",
            "--format", "json", "-o", str(out), "--psd", str(psd)]  # fmt: skip


def test_psd_written_and_compared(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    psd = tmp_path / "psd.csv"
    assert main(_args(imu, tmp_path / "n.json", psd)) == 0
    out = capsys.readouterr().out
    assert out.count("agree within 10 %") == 6 and "DISAGREE" not in out
    rows = list(csvmod.reader(psd.read_text(encoding="utf-8").splitlines()))
    assert rows[0][0] == "frequency_hz" and rows[0][1] == "asd gx [rad/s] [rad/s/sqrt(Hz)]"
    a = np.array(rows[1:], dtype=float)
    mid = (a[:, 0] > 1.0) & (a[:, 0] < 40.0)
    # one-sided ASD of white noise: √2·N, N the simulated density
    assert np.sqrt(np.mean(a[mid, 1] ** 2)) == pytest.approx(np.sqrt(2) * 1e-4, rel=0.03)
    assert np.sqrt(np.mean(a[mid, 4] ** 2)) == pytest.approx(np.sqrt(2) * 1e-3, rel=0.03)


def test_psd_file_never_over_an_input_or_the_output(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "n.json"
    assert main(_args(imu, out, imu)) == 2
    assert main(_args(imu, out, out)) == 2
    assert main(_args(imu, out, tmp_path)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(e.startswith("error: ") for e in err)
    assert not out.exists()
