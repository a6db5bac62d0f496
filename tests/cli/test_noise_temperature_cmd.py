"""``thermocal noise FILE --temps COL``: the noise per temperature bin through the command
line, on a simulated chamber run (``tests/helpers/chamber_noise``: gyro white noise growing
2 %/°C, steps 10/25/40/55 °C with overshoot, a 0.5 °C thermometer); the Kalibr file at
``--at-temperature`` against the simulator's N(T); hostile inputs exit 2 with one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from chamber_noise import DT_S, chamber, gyro_density, white
from thermocal.cli import main

GYRO = "gx [rad/s],gy [rad/s],gz [rad/s]"
ACCEL = "ax [m/s^2],ay [m/s^2],az [m/s^2]"


@pytest.fixture(scope="module")
def csv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    import pandas as pd

    rng = np.random.default_rng(11)
    true, reading = chamber(rng, setpoints=(10.0, 30.0, 50.0), hold_s=300.0, ramp_c_per_min=4.0)
    cols: dict[str, np.ndarray] = {"time [s]": np.arange(true.size) * DT_S}
    for c in GYRO.split(","):
        cols[c] = white(rng, gyro_density(true), true.size)
    for c in ACCEL.split(","):
        cols[c] = white(rng, 1e-3, true.size) + (9.81 if c.startswith("az") else 0.0)
    cols["imu temp [degC]"] = reading
    path = tmp_path_factory.mktemp("noiseT") / "chamber.csv"
    pd.DataFrame(cols).to_csv(path, index=False, float_format="%.9g")
    return path


def _args(csv: Path, out: Path, *extra: str) -> list[str]:
    return ["noise", str(csv), "--time", "time [s]", "--gyro", GYRO, "--accel", ACCEL,
            "--temps", "imu temp [degC]", "-o", str(out), *extra]  # fmt: skip


def test_kalibr_at_a_temperature(csv: Path, tmp_path: Path) -> None:
    before = csv.read_bytes()
    out = tmp_path / "imu45.yaml"
    assert main(_args(csv, out, "--temp-bins", "0,20,40,60", "--at-temperature", "40")) == 0
    k = yaml.safe_load(out.read_text(encoding="utf-8"))
    # the largest of three axes near 40 °C: within 4 % of the simulator's N(40 °C)
    assert k["gyroscope_noise_density"] == pytest.approx(float(gyro_density(40.0)), rel=0.04)
    assert k["accelerometer_noise_density"] == pytest.approx(1e-3, rel=0.04)
    text = out.read_text(encoding="utf-8")
    assert "Inflation INCLUDED in the values below: x1 (none)" in text
    assert "(temperature)" in text and "(bias_instability)" in text
    assert csv.read_bytes() == before
    js = tmp_path / "bins.json"
    assert main(_args(csv, js, "--temp-bins", "0,20,40,60", "--format", "json")) == 0
    d = json.loads(js.read_text(encoding="utf-8"))
    bins = d["by_temperature"]["bins"]
    assert [b["refused"] is None for b in bins] == [True, True, True]
    trend = next(
        t for t in d["by_temperature"]["trends"] if t["axis"] == "gx [rad/s]"
        and t["term"] == "noise_density"
    )  # fmt: skip
    assert trend["significant"] and abs(trend["slope_per_c"] - 2e-6) <= 3 * trend["slope_sigma"]


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (
            ["--temp-bins", "100", "--format", "json"],
            "--temp-bins",
        ),  # one bin: no change with temperature
        (["--temp-bins", "0,20,40,60", "--at-temperature", "80"], "--at-temperature 80"),
        (["--temp-bins", "warm", "--format", "json"], "--temp-bins 'warm'"),
        (["--temp-bins", "0,20,40,60"], "--at-temperature T"),  # kalibr needs a temperature
        (["--temp-bins", "nan", "--format", "json"], "--temp-bins nan"),
        (["--temp-bins", "0.0001", "--format", "json"], "--temp-bins 0.0001 °C makes"),
        (["--temp-bins", "10,nan,30", "--format", "json"], "--temp-bins (10.0, nan, 30.0)"),
        (["--temp-bins", "0,20,40,60", "--at-temperature", "nan"], "--at-temperature nan"),
        (["--format", "json", "--psd", "p.csv"], "--psd is of the whole record"),
    ],
)
def test_hostile_is_one_line(
    csv: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], words: str
) -> None:
    out = tmp_path / "x.yaml"
    assert main(_args(csv, out, *extra)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and words in err[0], err
    assert not out.exists()


def test_nan_temperature_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import pandas as pd

    rng = np.random.default_rng(3)
    n = 30_000
    df = pd.DataFrame({"time [s]": np.arange(n) * DT_S, "imu temp [degC]": np.nan})
    for c in GYRO.split(",") + ACCEL.split(","):
        df[c] = white(rng, 1e-4, n) + (9.81 if c.startswith("az") else 0.0)
    path = tmp_path / "nan.csv"
    df.to_csv(path, index=False)
    assert main(_args(path, tmp_path / "x.json", "--format", "json")) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "imu temp" in err[0], err


def test_allan_per_temperature_bin(
    csv: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``allan --temps COL --temp-bins EDGES --json``: the same bins for one signal, each N
    within 4 % of the simulator's N at the bin's mean temperature."""
    args = ["allan", str(csv), "--time", "time [s]", "--signal", "gx [rad/s]",
            "--temps", "imu temp [degC]", "--temp-bins", "0,20,40,60", "--json"]  # fmt: skip
    assert main(args) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["temperature"] == "imu temp [degC]" and len(d["bins"]) == 3
    for b in d["bins"]:
        n = b["axes"]["gx [rad/s]"]["noise_density"]
        assert n["value"] == pytest.approx(float(gyro_density(b["mean_c"])), rel=0.04)
    gx = next(t for t in d["trends"] if t["term"] == "noise_density")
    assert gx["significant"] and abs(gx["slope_per_c"] - 2e-6) <= 3 * gx["slope_sigma"]
    assert main([*args[:-5], "--temp-bins", "5"]) == 2  # bins without a temperature column
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--temps" in err[0]


def test_plot_against_temperature(
    csv: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "t.png"
    args = _args(csv, tmp_path / "t.json", "--temp-bins", "0,20,40,60", "--format", "json")
    assert main([*args, "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main([*args, "--plot", str(tmp_path / "t.json")]) == 2  # the same file as -o
    no_temps = ["noise", str(csv), "--time", "time [s]", "--gyro", GYRO, "--accel", ACCEL,
                "--format", "json", "-o", str(tmp_path / "u.json"), "--plot", str(png)]  # fmt: skip
    assert main(no_temps) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "--temps" in err[1]


def test_options_that_do_not_go_together(
    csv: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    allan = ["allan", str(csv), "--time", "time [s]", "--signal", "gx [rad/s]",
             "--temps", "imu temp [degC]", "--temp-bins", "20"]  # fmt: skip
    assert main([*allan, "--deviation", "mdev"]) == 2
    assert main([*allan, "--data-type", "phase"]) == 2
    sheet = tmp_path / "s.toml"
    sheet.write_text("update_rate_hz = 100\n", encoding="utf-8")
    assert main(["noise", str(sheet), "--from-datasheet", "--temps", "T", "-o",
                 str(tmp_path / "x.yaml")]) == 2  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3
    assert "drop --deviation" in err[0] and "drop --data-type" in err[1]
    assert "drop --temps" in err[2]
