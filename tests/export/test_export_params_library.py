"""export.params as a library: a bad argument is refused naming the PARAMETER
(:class:`thermocal.errors.ParameterError`), and the command line shows the same sentence
with its option in that place (``--format``, ``--instance``, ``--tref``, ``--gyro``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from thermocal.cli import main
from thermocal.errors import ParameterError
from thermocal.pipeline.model_file import load_calibration
from thermocal.simulate import SCENARIOS
from thermocal.writers import write_recording

GYROS = ("gx", "gy", "gz")


@pytest.fixture(scope="module")
def cal_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("params_lib")
    ((mod, _truth),) = SCENARIOS["mems-imu"](11, rate_hz=0.2)
    write_recording(mod, d / "mod.parquet")
    cal = d / "cal.json"
    assert main(["fit", str(d / "mod.parquet"), "--model", "poly", "--order", "3", "--signal",
                 ",".join(GYROS), "--temps", "T_die", "-o", str(cal)]) == 0  # fmt: skip
    return cal


CASES = [  # (keywords, parameter, library sentence, command-line options, CLI sentence)
    ({"fmt": "dji"}, "format", "format must be one of px4, ardupilot, got 'dji'",
     ["--format", "dji"], "--format must be one of px4, ardupilot, got 'dji'"),
    ({"instance": 4}, "instance", "instance 4: px4 has TC_G0…TC_G3 and TC_A0…TC_A3, instances 0…3",
     ["--instance", "4"], "--instance 4: px4 has TC_G0…TC_G3 and TC_A0…TC_A3, instances 0…3"),
    ({"tref_c": float("inf")}, "tref_c", "tref_c inf: not a finite temperature",
     ["--tref", "inf"], "--tref inf: not a finite temperature"),
    ({"gyro": ["gx", "gy"]}, "gyro", "gyro takes three channels, x,y,z; got ['gx', 'gy']",
     ["--gyro", "gx,gy"], "--gyro takes three channels, x,y,z; got ['gx', 'gy']"),
]  # fmt: skip


@pytest.mark.parametrize(("kw", "param", "lib", "opts", "cli"), CASES)
def test_library_names_the_parameter_and_cli_the_option(
    cal_path: Path, capsys: pytest.CaptureFixture[str], tmp_path: Path,
    kw: dict, param: str, lib: str, opts: list[str], cli: str,
) -> None:  # fmt: skip
    from thermocal.export.params import export_params

    cal = load_calibration(cal_path)
    args = {"fmt": "px4", "device_id": {"gyro": 1}, **kw}
    fmt = args.pop("fmt")
    with pytest.raises(ParameterError) as e:
        export_params(cal, fmt, **args)
    assert e.value.parameter == param and str(e.value) == lib
    capsys.readouterr()
    cmd = ["export-params", str(cal_path), "--format", "px4", "-o", str(tmp_path / "p.params")]
    code = main([*cmd, *opts])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and err == [f"error: {cli}"], err
    assert not (tmp_path / "p.params").exists()
