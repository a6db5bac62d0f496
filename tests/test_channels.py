"""Several channels at once (issue 15): ``--signal gx,gy,...`` reads the file once and gives
every channel exactly what a one-channel run gives (INTERFACE: ``{"channels": {NAME: …}}``).

The IMU file is written here: three gyros in °/s and three accelerometers in mg, each with
its own temperature slope, one die temperature, gravity on z.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

CHANNELS = ("gx", "gy", "gz", "ax", "ay", "az")
UNITS = ("deg/s", "deg/s", "deg/s", "mg", "mg", "mg")


@pytest.fixture(scope="module")
def imu(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rng = np.random.default_rng(0)
    n = 20_000
    t = np.arange(n) * 0.1
    temp = 25.0 + 10.0 * np.sin(2 * np.pi * t / t[-1])
    cols: dict[str, np.ndarray] = {"time": t, "T1": temp}
    for i, name in enumerate(CHANNELS):
        base = 1000.0 if name == "az" else 0.0
        noise = 0.01 if name.startswith("g") else 0.1
        cols[name] = base + 0.1 * (i + 1) * (temp - 25.0) + noise * rng.standard_normal(n)
    path = tmp_path_factory.mktemp("imu") / "imu.csv"
    pd.DataFrame(cols).to_csv(path, index=False)
    return path


def _json(capsys: pytest.CaptureFixture[str], *args: str) -> dict:
    code = main([*args, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


COMMON = ["--temps", "T1", "--temp-unit", "degC", "--time-unit", "s"]


@pytest.mark.parametrize("command", ["metrics", "allan"])
def test_six_channels_equal_six_single_runs(
    imu: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    extra = ["--average", "10"] if command == "metrics" else []
    many = _json(
        capsys, command, str(imu), "--signal", ",".join(CHANNELS),
        "--signal-unit", ",".join(UNITS), *COMMON, *extra,
    )  # fmt: skip
    assert list(many) == ["channels"]
    assert list(many["channels"]) == list(CHANNELS)
    for name, unit in zip(CHANNELS, UNITS, strict=True):
        one = _json(
            capsys, command, str(imu), "--signal", name, "--signal-unit", unit, *COMMON, *extra
        )
        assert many["channels"][name] == one, name


def test_channels_keep_their_own_units(imu: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d = _json(
        capsys, "metrics", str(imu), "--signal", "gx,az", "--signal-unit", "deg/s,mg",
        *COMMON, "--average", "10",
    )  # fmt: skip
    gx, az = d["channels"]["gx"], d["channels"]["az"]
    assert gx["unit"] == "deg/h" and az["unit"] == "mg"
    assert az["bias"] == pytest.approx(1000.0, abs=0.5)  # gravity on z, in mg
    # the gyro bias in °/h: the mean of 0.1 (T − 25) °/s over a full sine is 0
    assert abs(gx["bias"]) < 0.01 * 3600


def test_earth_rate_with_several_channels_is_refused(
    imu: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["metrics", str(imu), "--signal", "gx,gy", "--signal-unit", "deg/s", *COMMON,
         "--latitude", "45", "--axis", "up"]
    )  # fmt: skip
    assert code == 2
    assert "one signal at a time" in capsys.readouterr().err


def test_allan_plots_one_file_per_channel(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["allan", str(imu), "--signal", "gx,az", "--signal-unit", "deg/s,mg", "--time-unit",
         "s", "--plot", str(tmp_path / "adev.png")]
    )  # fmt: skip
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "adev_gx.png").stat().st_size > 1000
    assert (tmp_path / "adev_az.png").stat().st_size > 1000
