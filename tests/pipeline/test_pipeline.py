"""The fit → validate path as library functions (issue 27): :func:`fit_files` and
:func:`validate_files` without the command line, against truths computed here; the options
dataclasses against the commands' options; ``validate --modeling`` reading a headerless
serial log with the text-log options; every ``--option`` the fit/validate code advises exists."""

from __future__ import annotations

import ast
import dataclasses
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.pipeline.fit import fit_files
from thermocal.pipeline.messages import option_name
from thermocal.pipeline.options import (
    ALIASES,
    FitOptions,
    ValidateOptions,
    family_option_kinds,
    options_from_table,
)
from thermocal.pipeline.validate import validate_files

SRC = Path(__file__).resolve().parents[2] / "src" / "thermocal"
BIAS = 1.5  # [°/h]
SLOPE = 0.03  # [°/h/°C]
SIGMA = 0.01  # [°/h] white noise
N = 2000


def _write(path: Path, temp: np.ndarray, seed: int) -> np.ndarray:
    """A still gyro (1 Hz) following ``BIAS + SLOPE·(T − 25)`` plus noise; returns the signal."""
    rng = np.random.default_rng(seed)
    gyro = BIAS + SLOPE * (temp - 25.0) + rng.normal(0.0, SIGMA, temp.size)
    pd.DataFrame({"time [s]": np.arange(temp.size, dtype=float), "gyro [deg/h]": gyro,
                  "T1 [degC]": temp}).to_csv(path, index=False, float_format="%.12g")  # fmt: skip
    return gyro


RAMP = np.linspace(-10.0, 60.0, N)
SINE = 25.0 + 20.0 * np.sin(2 * np.pi * np.arange(N) / N)


def test_fit_files_recovers_the_bias_and_slope(tmp_path: Path) -> None:
    """Order 1 about TREF = 25 °C: the constant is the bias and the T1 term the slope, within
    3 standard errors of a straight-line fit to white noise (σ/√n and σ/(√n·std T))."""
    _write(tmp_path / "mod.csv", RAMP, 1)
    opts = FitOptions(
        model="poly",
        params={"order": 1},
        signals=("gyro [deg/h]",),
        temperatures=("T1 [degC]",),
        tref=25.0,
    )
    res = fit_files([tmp_path / "mod.csv"], opts, tmp_path / "m.json")
    assert not res.calibration and res.output.is_file()
    fig = res.channels[0].figures
    coefs = {c["name"]: c["value"] for c in fig["tref"]["coefficients"]}
    se_bias = SIGMA / np.sqrt(N)
    se_slope = SIGMA / (np.sqrt(N) * RAMP.std())
    assert set(coefs) == {"const", "(T1-TREF)"}
    assert coefs["const"] == pytest.approx(BIAS, abs=3 * se_bias)  # the ramp's mean is 25 °C
    assert coefs["(T1-TREF)"] == pytest.approx(SLOPE, abs=3 * se_slope)
    assert fig["rms_residual"] == pytest.approx(SIGMA, rel=0.1)
    assert fig["n_samples"] == N and fig["n_runs"] == 1


def test_fit_files_refuses_options_before_reading(tmp_path: Path) -> None:
    from thermocal.errors import ThermocalInputError

    # the library names its parameter; the command line shows --order in its place
    with pytest.raises(ThermocalInputError, match=r"^order must be between 1 and 10"):
        fit_files(
            [tmp_path / "nothing.csv"],
            FitOptions(model="poly", params={"order": 11}),
            tmp_path / "m.json",
        )


def test_validate_files_figures_against_a_hand_computation(tmp_path: Path) -> None:
    """Averaging 1 s at 1 Hz: ``rms_before`` is the population std of the raw signal, and
    ``rms_after`` that of the signal minus the model, here computed with the fitted slope."""
    _write(tmp_path / "mod.csv", RAMP, 1)
    val = _write(tmp_path / "val.csv", SINE, 2)
    opts = FitOptions(
        model="poly",
        params={"order": 1},
        signals=("gyro [deg/h]",),
        temperatures=("T1 [degC]",),
        tref=25.0,
    )
    fit = fit_files([tmp_path / "mod.csv"], opts, tmp_path / "m.json")
    coefs = {c["name"]: c["value"] for c in fit.channels[0].figures["tref"]["coefficients"]}
    with pytest.warns(UserWarning, match="temperature-hold stage"):  # none in a sine
        rep = validate_files(
            tmp_path / "m.json",
            tmp_path / "val.csv",
            ValidateOptions(averaging=1.0, modeling=tmp_path / "mod.csv"),
        )
    out = rep.to_dict()
    assert out["rms_before"] == pytest.approx(np.std(val), rel=1e-9)
    after = val - (coefs["const"] + coefs["(T1-TREF)"] * (SINE - 25.0))
    assert out["rms_after"] == pytest.approx(np.std(after), rel=1e-6)
    assert out["rms_after"] == pytest.approx(SIGMA, rel=0.1)


def _serial_log(path: Path, temp: np.ndarray, seed: int) -> None:
    """A serial-terminal capture: a banner, no header row, no time column, blank-separated."""
    rng = np.random.default_rng(seed)
    gyro = BIAS + SLOPE * (temp - 25.0) + rng.normal(0.0, SIGMA, temp.size)
    lines = ["=~=~=~= PuTTY log 2026.11.20 10:15:03 =~=~=~=", "gyro test v1.0"]
    lines += [f"{g:.6f} {t:.6f}" for g, t in zip(gyro, temp, strict=True)]
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode())


TEXT = ["--names", "gx,T", "--rate", "1", "--signal-unit", "deg/h", "--temp-unit", "degC"]


def test_validate_modeling_reads_a_headerless_serial_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--modeling`` gets the text-log options of the validated file: r of the two ambient
    histories (a ramp and one sine period over the same 2000 s) equals Pearson's r of the
    two curves computed here on a dense grid."""
    mod, val = tmp_path / "mod.log", tmp_path / "val.log"
    _serial_log(mod, RAMP, 1)
    _serial_log(val, SINE, 2)
    model = tmp_path / "m.json"
    assert main(["fit", str(mod), "--model", "poly", "--order", "1", "--signal", "gx",
                 "--temps", "T", *TEXT, "-o", str(model)]) == 0  # fmt: skip
    other = tmp_path / "elsewhere"
    other.mkdir()
    mod.rename(other / "mod.log")  # the model's recorded file is gone: only --modeling gives r
    capsys.readouterr()
    code = main(["validate", str(model), str(val), "--modeling", str(other / "mod.log"),
                 *TEXT, "--json"])  # fmt: skip
    io = capsys.readouterr()
    assert code == 0, io.err
    res = json.loads(io.out)
    tt = np.linspace(0.0, N - 1.0, 200_001)
    ramp = np.interp(tt, np.arange(N), RAMP)
    sine = 25.0 + 20.0 * np.sin(2 * np.pi * tt / N)
    assert res["r"] == pytest.approx(np.corrcoef(ramp, sine)[0, 1], abs=2e-3)
    assert res["modeling_file"] == str(other / "mod.log")


# --- the options dataclasses are the commands' options ----------------------------------------


def _command(name: str):  # type: ignore[no-untyped-def]
    import typer

    from thermocal.cli import _register
    from thermocal.cli.application import app

    _register()
    return typer.main.get_command(app).commands[name]  # type: ignore[attr-defined]


def _long_options(name: str) -> dict[str, bool]:
    """``{--option: is a flag}`` of a command, second names included."""
    out: dict[str, bool] = {}
    for p in _command(name).params:
        for o in [*getattr(p, "opts", []), *getattr(p, "secondary_opts", [])]:
            if o.startswith("--"):
                out[o] = bool(getattr(p, "is_flag", False))
    return out


@pytest.mark.parametrize(("command", "cls"), [("fit", FitOptions), ("validate", ValidateOptions)])
def test_the_options_dataclass_is_the_command(command: str, cls: type) -> None:
    # each field is its option (option_name: signals is --signal, rate_hz is --rate)
    fields = {option_name(f.name) for f in dataclasses.fields(cls)} - {"--params"}
    if command == "fit":  # the families' declared options, and none besides
        fields |= {"--" + name for name in family_option_kinds()}
    aliases = {"--" + a for a in ALIASES.get(command, {})}
    opts = set(_long_options(command)) - {"--output", "--json", "--help", "--no-per-run-offset"}
    # the chamber log's options are one field, chamber_log (a ChamberLogSpec)
    opts -= {o for o in opts if o.startswith("--chamber-") and o != "--chamber-log"}
    assert fields | aliases == opts


def test_a_table_gives_the_options_and_the_arguments() -> None:
    table = {"model": "poly", "order": 2, "signal": ["gx", "gy"], "select": True, "ridge": 0.5}
    opts, args = options_from_table("fit", table, "cfg [fit]")
    assert opts == FitOptions(
        model="poly", params={"order": 2, "select": "bic", "ridge": 0.5}, signals=("gx", "gy")
    )
    assert args == ["--model", "poly", "--order", "2", "--signal", "gx,gy", "--select",
                    "--ridge", "0.5"]  # fmt: skip
    v, _ = options_from_table("validate", {"average": 30}, "cfg [validate]")
    assert v == ValidateOptions(averaging=30.0)


# --- advice names options as they exist ---------------------------------------------------------

_OPTION = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)(?:\s+([A-Za-z0-9_.]+))?")
_WORDS = {"or", "and", "to", "is", "with", "for", "in", "on", "the", "a", "an", "when", "if",
          "instead", "only", "applies", "takes", "must", "gives", "first", "as", "at", "of",
          "from", "then", "forces", "needs", "not", "also"}  # fmt: skip
"""Words that may follow a flag in a sentence (anything else after a flag is a value)."""

FIT_MODULES = ["pipeline/fit.py", "pipeline/reading.py", "cli/fit_cmd.py", "adequacy.py",
               "gravity.py", "units.py", "recording.py", "readers/[!p]*.py",
               "models/*.py"]  # fmt: skip
"""What ``fit`` runs (readers/program.py, the chamber-program reader of ``profile``, is not)."""
VALIDATE_MODULES = ["pipeline/validate.py", "pipeline/reading.py", "cli/validate_cmd.py",
                    "readers/[!p]*.py",
                    "validation.py", "compensate/kernels.py", "models/base.py",
                    "pipeline/model_file.py", "models/calibration.py"]  # fmt: skip
DESCRIBED = {"the known input given (--known-input)", "--encoder-unit", " --axis "}
"""Texts naming a ``fit`` option the model recorded (what it was given), not advice; and the
unit option of the encoder-angle role (units.py's table of roles), which only ``turntable``
and triad validation resolve: ``fit`` reads no encoder column; and validate's advice to
refit (``thermocal fit --latitude L --axis A``, compensate/kernels.py), ``fit``'s option."""


def advice_problems(text: str, options: dict[str, bool]) -> list[str]:
    """The ``--option`` mentions of ``text`` that the command cannot take: an unknown
    option, or a flag followed by a value (``--select bic``)."""
    bad = []
    for m in _OPTION.finditer(text):
        opt, nxt = m.group(1), m.group(2)
        if opt not in options:
            bad.append(f"{opt} is not an option")
        elif options[opt] and nxt is not None and nxt.lower() not in _WORDS:
            bad.append(f"{opt} is a flag, given a value {nxt!r}")
    return bad


def _texts(path: Path) -> list[tuple[int, str]]:
    """The string constants of a module that are not docstrings."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = {
        id(n.body[0].value)
        for n in ast.walk(tree)
        if isinstance(n, ast.Module | ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)
        and n.body
        and isinstance(n.body[0], ast.Expr)
        and isinstance(n.body[0].value, ast.Constant)
    }
    return [
        (n.lineno, n.value)
        for n in ast.walk(tree)
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs
    ]


@pytest.mark.parametrize(
    ("command", "modules"), [("fit", FIT_MODULES), ("validate", VALIDATE_MODULES)]
)
def test_every_option_the_advice_names_exists(command: str, modules: list[str]) -> None:
    options = _long_options(command)
    found = []
    for pattern in modules:
        for path in sorted(SRC.glob(pattern)):
            for line, text in _texts(path):
                if text in DESCRIBED:
                    continue
                found += [f"{path.name}:{line}: {p}" for p in advice_problems(text, options)]
    assert found == []


def test_the_advice_check_catches_a_flag_given_a_value() -> None:
    options = _long_options("fit")
    assert advice_problems("consider --select bic or fewer terms", options) == [
        "--select is a flag, given a value 'bic'"
    ]
    assert advice_problems("consider --select or fewer terms", options) == []
    assert advice_problems("use --selection", options) == ["--selection is not an option"]
    assert advice_problems("--select-method bic", options) == []


def test_the_fleet_figures_are_what_fit_and_validate_give(tmp_path: Path) -> None:
    """The figure names a fleet unit records (one place, :mod:`thermocal.fleet.stats`) are
    keys of the fit's and the validation's results."""
    from thermocal.fleet.stats import FIT_FIGURES, SERIES_FIGURES, VALIDATION_FIGURES

    _write(tmp_path / "mod.csv", RAMP, 1)
    _write(tmp_path / "val.csv", SINE, 2)
    opts = FitOptions(
        model="poly", params={"order": 1}, signals=("gyro [deg/h]",), temperatures=("T1 [degC]",)
    )
    fit = fit_files([tmp_path / "mod.csv"], opts, tmp_path / "m.json")
    with pytest.warns(UserWarning, match="temperature-hold stage"):
        rep = validate_files(tmp_path / "m.json", tmp_path / "val.csv")
    assert set(FIT_FIGURES) <= set(fit.to_dict())
    assert set(VALIDATION_FIGURES) <= set(rep.to_dict())
    assert set(SERIES_FIGURES) <= set(FIT_FIGURES) | set(VALIDATION_FIGURES)


def test_the_fleet_report_does_not_import_the_batch_driver() -> None:
    """No circle: the statistics and the configuration sit below both."""
    for name in ("report.py", "stats.py", "config.py"):
        tree = ast.parse((SRC / "fleet" / name).read_text(encoding="utf-8"))
        imported = {
            n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module
        } | {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        assert "thermocal.fleet.batch" not in imported, name


def test_validate_reads_the_log_topic_it_is_given(tmp_path: Path) -> None:
    """``validate --topic`` (issue 27: every file a command takes is read with the same
    options): a model fitted on instance 1 of a PX4 ``sensor_gyro`` topic is judged on
    instance 1 of another log, whose bias is exactly the model: rms after ≈ 0, rms before =
    the rms of the bias about its mean (computed here, in rad/s as logged); instance 0 of
    each log holds another sensor, a constant, which the default topic would read."""
    from thermocal.cli import main
    from thermocal.errors import ThermocalWarning
    from ulog_writer import SENSOR_FIELDS, ulog_bytes

    slope_rad_s_per_c = 2e-5

    def log(path: Path, temp: np.ndarray) -> np.ndarray:
        t_us = (np.arange(temp.size) * 0.5e6).astype(np.int64).tolist()
        x = (slope_rad_s_per_c * (temp - 35.0)).tolist()
        rows1 = [[a, 7, b, 0.0, 0.0, c] for a, b, c in zip(t_us, x, temp.tolist(), strict=True)]
        rows0 = [[a, 3, 0.5, 0.0, 0.0, c] for a, c in zip(t_us, temp.tolist(), strict=True)]
        topics = [
            ("sensor_gyro", 0, SENSOR_FIELDS, rows0),
            ("sensor_gyro", 1, SENSOR_FIELDS, rows1),
        ]
        path.write_bytes(ulog_bytes(topics))
        return np.asarray([r[2] for r in rows1], dtype=np.float32).astype(np.float64)

    n = 14400
    log(tmp_path / "modelling.ulg", 20.0 + 30.0 * np.arange(n) / (n - 1))
    x_val = log(tmp_path / "validation.ulg", 35.0 + 12.0 * np.sin(np.arange(n) / n * 2 * np.pi))
    common = ["--time", "timestamp", "--time-unit", "us", "--topic", "sensor_gyro.1"]
    assert main(["fit", str(tmp_path / "modelling.ulg"), "--model", "poly", "--order", "1",
                 "--signal", "x", "--temps", "temperature", *common,
                 "-o", str(tmp_path / "m.json")]) == 0  # fmt: skip
    opts = ValidateOptions(time="timestamp", time_unit="us", topic="sensor_gyro.1",
                           modeling=tmp_path / "modelling.ulg")  # fmt: skip
    with pytest.warns(ThermocalWarning, match="temperature-hold stage"):  # a sine: no holds
        out = validate_files(tmp_path / "m.json", tmp_path / "validation.ulg", opts).to_dict()
    assert out["rms_before"] == pytest.approx(float(np.std(x_val)), rel=1e-3)
    assert abs(out["rms_after"]) < 1e-3 * out["rms_before"]
