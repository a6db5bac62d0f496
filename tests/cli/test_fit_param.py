"""``thermocal fit --param NAME=VALUE``: a family's declared option by its parameter name.

The built-in families' options also have options of their own (``--order``); ``--param``
reaches the same constructor parameters, parsed by their declared kind and checked against
their declared bounds, and refuses what the family does not declare in one error line.
The numbers come from least squares written here with numpy.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main


def _run(args: list[str]) -> tuple[int, str, str]:
    """Exit status, stdout and stderr of one command line."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(args)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture
def run_csv(tmp_path: Path) -> Path:
    """A gyro bias quadratic in T over a 40 °C sweep [°/h], seeded noise of 1e-3 °/h."""
    t = np.arange(0.0, 4000.0, 1.0)
    temp = 10.0 + 40.0 * t / t[-1]
    noise = 1e-3 * np.random.default_rng(0).standard_normal(t.size)
    gx = 0.02 * (temp - 25.0) + 1e-3 * (temp - 25.0) ** 2 + noise
    path = tmp_path / "run.csv"
    pd.DataFrame({"time_s": t, "gx": gx, "T1": temp}).to_csv(path, index=False)
    return path


def _base(run_csv: Path, out: Path) -> list[str]:
    return ["fit", str(run_csv), "--signal", "gx", "--signal-unit", "deg/h", "--temps", "T1",
            "--temp-unit", "degC", "--model", "poly", "-o", str(out)]  # fmt: skip


def test_param_sets_a_declared_option_as_its_own_option_does(run_csv: Path, tmp_path: Path) -> None:
    code, out, err = _run([*_base(run_csv, tmp_path / "a.json"), "--param", "order=2", "--json"])
    assert code == 0, err
    got = {c["name"]: c["value"] for c in json.loads(out)["coefficients"]}
    frame = pd.read_csv(run_csv)
    t = frame["T1"].to_numpy()
    design = np.column_stack([np.ones_like(t), t, t**2])
    want = np.linalg.lstsq(design, frame["gx"].to_numpy(), rcond=None)[0]
    assert [got["const"], got["T1"], got["T1^2"]] == pytest.approx(want, rel=1e-6, abs=1e-9)
    assert got["T1^2"] == pytest.approx(1e-3, rel=0.01)  # the quadratic written into the data
    code, out2, err = _run([*_base(run_csv, tmp_path / "b.json"), "--order", "2", "--json"])
    assert code == 0, err
    assert json.loads(out2)["coefficients"] == json.loads(out)["coefficients"]


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (["--order", "2", "--param", "order=2"],
         "error: --param 'order=2': the option order is given twice"),
        (["--param", "order=x"],
         "error: --param order must be an integer, got 'x' (model 'poly' takes: terms, order, "
         "rate_interval_s, rate_method, select, ridge, rcond, per_run_offset, solver, "
         "noise_threshold)"),
        (["--param", "order=11"],
         "error: --param order must be between 1 and 10, got 11 (model 'poly' takes: terms, "
         "order, rate_interval_s, rate_method, select, ridge, rcond, per_run_offset, solver, "
         "noise_threshold)"),
        (["--param", "order"],
         "error: --param 'order': give NAME=VALUE, NAME an option of model 'poly' (it takes: "
         "terms, order, rate_interval_s, rate_method, select, ridge, rcond, per_run_offset, "
         "solver, noise_threshold)"),
    ],
)  # fmt: skip
def test_param_refuses_in_one_line(
    run_csv: Path, tmp_path: Path, args: list[str], line: str
) -> None:
    code, _out, err = _run([*_base(run_csv, tmp_path / "c.json"), *args])
    assert code == 2 and err.strip().splitlines() == [line], err
    assert not (tmp_path / "c.json").exists()


def test_param_parses_a_yes_no_option(run_csv: Path, tmp_path: Path) -> None:
    out = tmp_path / "d.json"
    code, _o, err = _run([*_base(run_csv, out), "--order", "1", "--param", "per_run_offset=no"])
    assert code == 0, err
    assert json.loads(out.read_text(encoding="utf-8"))["params"]["per_run_offset"] is False
