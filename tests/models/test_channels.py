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
    assert gx["unit"] == "deg/s" and az["unit"] == "mg"  # each in its data's own unit
    assert az["bias"] == pytest.approx(1000.0, abs=0.5)  # gravity on z, in mg
    # the gyro bias in °/s: the mean of 0.1 (T − 25) °/s over a full sine is 0
    assert abs(gx["bias"]) < 0.01


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


def test_fit_several_channels_writes_a_calibration_equal_to_single_fits(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from thermocal.pipeline.model_file import load_calibration, load_model

    cal_path = tmp_path / "cal.json"
    res = _json(
        capsys, "fit", str(imu), "--model", "poly", "--order", "2", "--signal",
        ",".join(CHANNELS), "--signal-unit", ",".join(UNITS), *COMMON, "-o", str(cal_path),
    )  # fmt: skip
    assert list(res["channels"]) == list(CHANNELS)
    cal = load_calibration(cal_path)
    assert cal.names == list(CHANNELS)
    assert [c.unit for c in cal.channels] == list(UNITS)
    assert cal.channel("gx").role == {"kind": "gyro", "axis": "x"}
    assert cal.channel("az").role == {"kind": "accel", "axis": "z"}
    for name, unit in zip(CHANNELS, UNITS, strict=True):
        one = tmp_path / f"{name}.json"
        _json(
            capsys, "fit", str(imu), "--model", "poly", "--order", "2", "--signal", name,
            "--signal-unit", unit, *COMMON, "-o", str(one),
        )  # fmt: skip
        single = load_model(one)
        multi = cal.channel(name).model
        assert [c.value for c in multi.coefficients()] == [c.value for c in single.coefficients()]
        assert [c.stderr for c in multi.coefficients()] == [c.stderr for c in single.coefficients()]
    # the slopes written into the data, in the data's units: 0.1·(i+1) per °C
    gz = {c.name: c.value for c in cal.channel("gz").model.coefficients()}
    assert gz["T1"] == pytest.approx(0.3 * 3600, rel=1e-3)  # the model is in °/h


def test_a_single_model_file_loads_as_a_one_channel_calibration(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from thermocal.pipeline.model_file import load_calibration

    one = tmp_path / "gx.json"
    _json(
        capsys, "fit", str(imu), "--model", "poly", "--order", "1", "--signal", "gx",
        "--signal-unit", "deg/s", *COMMON, "-o", str(one),
    )  # fmt: skip
    cal = load_calibration(one)
    assert cal.names == ["gx"] and cal.channels[0].unit == "deg/s"


def test_corrupt_calibration_is_refused_naming_the_channel(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from thermocal.errors import ModelFileError
    from thermocal.models.format import checksum
    from thermocal.pipeline.model_file import load_calibration

    cal_path = tmp_path / "cal.json"
    _json(
        capsys, "fit", str(imu), "--model", "poly", "--order", "1", "--signal", "gx,gy",
        "--signal-unit", "deg/s", *COMMON, "-o", str(cal_path),
    )  # fmt: skip
    d = json.loads(cal_path.read_text())
    d["channels"][1]["model"]["coefficients"][0]["value"] = 1.0  # edited by hand
    d["checksum"] = checksum(d)  # ...and the outer checksum recomputed
    cal_path.write_text(json.dumps(d))
    with pytest.raises(ModelFileError, match=r"channels\[1\]\.model: checksum mismatch"):
        load_calibration(cal_path)
    d["checksum"] = "0" * 64
    cal_path.write_text(json.dumps(d))
    with pytest.raises(ModelFileError, match="calibration file was corrupted"):
        load_calibration(cal_path)


def test_compensate_a_calibration_in_one_pass_equals_single_channels(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cal_path = tmp_path / "cal.json"
    _json(
        capsys, "fit", str(imu), "--model", "poly", "--order", "2", "--signal",
        ",".join(CHANNELS), "--signal-unit", ",".join(UNITS), *COMMON, "-o", str(cal_path),
    )  # fmt: skip
    out = tmp_path / "all.parquet"
    res = _json(capsys, "compensate", str(cal_path), str(imu), "-o", str(out),
                "--chunk-rows", "3000")  # fmt: skip
    assert list(res["channels"]) == list(CHANNELS)
    got = pd.read_parquet(out)
    raw = pd.read_csv(imu)
    for name, unit in zip(CHANNELS, UNITS, strict=True):
        # <sig>_comp = raw − model, in the data column's unit
        np.testing.assert_allclose(
            got[f"{name}_comp"], raw[name] - got[f"{name}_model"], rtol=0, atol=1e-12
        )
        assert res["channels"][name]["unit"] == unit
        # the temperature-induced part (0.1 (i+1) per °C, quadratic model) is removed to
        # the noise: 0.01 °/s for gyros, 0.1 mg for accelerometers
        noise = 0.01 if name.startswith("g") else 0.1
        assert float(got[f"{name}_comp"].std()) == pytest.approx(noise, rel=0.05)
        # equal to a one-channel compensation with the single-channel model
        one_model = tmp_path / f"{name}.json"
        _json(
            capsys, "fit", str(imu), "--model", "poly", "--order", "2", "--signal", name,
            "--signal-unit", unit, *COMMON, "-o", str(one_model),
        )  # fmt: skip
        one_out = tmp_path / f"{name}.parquet"
        _json(capsys, "compensate", str(one_model), str(imu), "-o", str(one_out),
              "--chunk-rows", "3000")  # fmt: skip
        single = pd.read_parquet(one_out)
        np.testing.assert_array_equal(got[f"{name}_comp"], single[f"{name}_comp"])


def test_compensate_a_subset_of_channels(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cal_path = tmp_path / "cal.json"
    _json(
        capsys, "fit", str(imu), "--model", "poly", "--order", "1", "--signal", "gx,gy,az",
        "--signal-unit", "deg/s,deg/s,mg", *COMMON, "-o", str(cal_path),
    )  # fmt: skip
    out = tmp_path / "sub.csv"
    res = _json(capsys, "compensate", str(cal_path), str(imu), "-o", str(out),
                "--signal", "gy,az")  # fmt: skip
    assert list(res["channels"]) == ["gy", "az"]
    cols = pd.read_csv(out).columns
    assert "gy_comp" in cols and "az_comp" in cols and "gx_comp" not in cols
    code = main(["compensate", str(cal_path), str(imu), "-o", str(tmp_path / "x.csv"),
                 "--signal", "gq"])  # fmt: skip
    assert code == 2
    assert "no channel 'gq'" in capsys.readouterr().err


def test_validate_a_calibration_gives_per_channel_figures_equal_to_single_runs(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cal_path = tmp_path / "cal.json"
    _json(
        capsys, "fit", str(imu), "--model", "poly", "--order", "2", "--signal", "gx,az",
        "--signal-unit", "deg/s,mg", *COMMON, "-o", str(cal_path),
    )  # fmt: skip
    many = _json(capsys, "validate", str(cal_path), str(imu))
    assert list(many["channels"]) == ["gx", "az"]
    for name, unit in (("gx", "deg/s"), ("az", "mg")):
        ch = many["channels"][name]
        assert ch["unit"] == unit
        assert ch["verdict"] == "NOT weakly correlated"  # validated on its own modelling run
        one_model = tmp_path / f"{name}.json"
        _json(
            capsys, "fit", str(imu), "--model", "poly", "--order", "2", "--signal", name,
            "--signal-unit", unit, *COMMON, "-o", str(one_model),
        )  # fmt: skip
        one = _json(capsys, "validate", str(one_model), str(imu))
        for key in ("r", "rms_before", "rms_after", "bias_stability_before",
                    "bias_stability_after"):  # fmt: skip
            assert ch[key] == one[key], (name, key)


C_DRIVER = r"""
#include <stdio.h>
#include "imu.h"
int main(void) {
    imu_state s;
    double t, temps[IMU_N_TEMPS], raw[IMU_N_CHANNELS], out[IMU_N_CHANNELS];
    int i, first = 1;
    while (scanf("%lf", &t) == 1) {
        for (i = 0; i < IMU_N_TEMPS; i++) if (scanf("%lf", &temps[i]) != 1) return 1;
        for (i = 0; i < IMU_N_CHANNELS; i++) if (scanf("%lf", &raw[i]) != 1) return 1;
        if (first) { imu_init(&s, 0.1); first = 0; }
        imu_compensate(&s, t, temps, raw, out);
        for (i = 0; i < IMU_N_CHANNELS; i++)
            printf("%.17g%c", out[i], i + 1 < IMU_N_CHANNELS ? ' ' : '\n');
    }
    return 0;
}
"""


def test_calibration_c_compiles_strict_and_matches_python(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One header/source for six channels (a cubic with Ṫ terms on the gyros, a quadratic
    on the accelerometers), compiled with -std=c99 -Wall -Wextra -Werror -pedantic,
    equals Python's compensation to 1e-9 (relative) on 10⁵ samples with a gap and
    temperatures beyond the fitted range (clamped)."""
    import shutil
    import subprocess

    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        pytest.skip("no C compiler on this machine")
    from thermocal.models.calibration import Calibration, Channel
    from thermocal.pipeline.model_file import load_model, save_calibration

    models = {}
    for name, unit in zip(CHANNELS, UNITS, strict=True):
        path = tmp_path / f"{name}.json"
        opts = ["--terms", "T1,T1^2,dT1,T1*dT1"] if name.startswith("g") else ["--order", "2"]
        _json(
            capsys, "fit", str(imu), "--model", "poly", *opts, "--rate-interval", "30",
            "--signal", name, "--signal-unit", unit, *COMMON, "-o", str(path),
        )  # fmt: skip
        models[name] = load_model(path)
    cal_path = tmp_path / "imu.json"
    save_calibration(
        Calibration([Channel(n, n, u, models[n]) for n, u in zip(CHANNELS, UNITS, strict=True)]),
        cal_path,
    )
    cdir = tmp_path / "c"
    assert main(["export-c", str(cal_path), "-o", str(cdir), "--name", "imu"]) == 0
    capsys.readouterr()
    (cdir / "main.c").write_text(C_DRIVER)
    exe = cdir / "run"
    subprocess.run(
        [cc, "-O2", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-o", str(exe),
         str(cdir / "imu.c"), str(cdir / "main.c"), "-lm"],
        check=True,
    )  # fmt: skip
    # inputs: 10⁵ samples at 10 Hz, a 60 s gap, temperatures from 5 to 45 °C (fitted 15…35)
    rng = np.random.default_rng(9)
    n = 100_000
    t = np.arange(n) * 0.1
    t[n // 2 :] += 60.0
    temp = 25.0 + 20.0 * np.sin(2 * np.pi * t / t[-1] * 1.5)
    data = {"time": t, "T1": temp}
    for i, name in enumerate(CHANNELS):
        data[name] = rng.normal(0.0, 1.0, n) + (1000.0 if name == "az" else 0.0) + i
    src = tmp_path / "in.csv"
    pd.DataFrame(data).to_csv(src, index=False)
    out = tmp_path / "out.parquet"
    capsys.readouterr()
    assert main(["compensate", str(cal_path), str(src), "-o", str(out), "--time-unit", "s"]) == 0
    capsys.readouterr()
    py = pd.read_parquet(out)
    text = "\n".join(
        " ".join(repr(float(data[c][j])) for c in ("time", "T1", *CHANNELS)) for j in range(n)
    )
    proc = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    c_out = np.array([[float(v) for v in line.split()] for line in proc.stdout.splitlines()])
    assert c_out.shape == (n, len(CHANNELS))
    for i, name in enumerate(CHANNELS):
        ref = py[f"{name}_comp"].to_numpy()
        scale = max(1.0, float(np.max(np.abs(ref))))
        np.testing.assert_allclose(c_out[:, i], ref, rtol=0, atol=1e-9 * scale, err_msg=name)


def test_export_sizes_the_rate_buffer_for_the_fitted_sample_interval(
    imu: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The data were at 10 Hz: a 60 s rate interval needs ⌈60/0.1⌉ + 8 = 608 slots. Before,
    the buffer was sized for 1 s samples (68) and the firmware's Ṫ silently spanned 6.8 s."""
    model = tmp_path / "gx.json"
    _json(
        capsys, "fit", str(imu), "--model", "poly", "--terms", "T1,dT1", "--signal", "gx",
        "--signal-unit", "deg/s", *COMMON, "-o", str(model),
    )  # fmt: skip
    assert json.loads(model.read_text())["inputs"]["sample_interval_s"] == pytest.approx(0.1)
    assert main(["export-c", str(model), "-o", str(tmp_path / "c"), "--name", "g"]) == 0
    assert "#define G_RATE_BUF_LEN 608" in (tmp_path / "c" / "g.h").read_text()
    assert main(["export-c", str(model), "-o", str(tmp_path / "d"), "--name", "g",
                 "--sample-interval", "1"]) == 0  # fmt: skip
    assert "#define G_RATE_BUF_LEN 68" in (tmp_path / "d" / "g.h").read_text()
