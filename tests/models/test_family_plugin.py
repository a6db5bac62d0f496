"""A model family from another package, through the command line (ARCHITECTURE.md, "A new
model family"): the test writes a package ``toyfam`` in a temporary folder — one class, a
constant plus a line in the first temperature, carrying its declaration — and one
registration line, the entry point ``toy = toyfam:ToyModel`` of group
``thermocal.families`` in ``toyfam-0.1.dist-info/entry_points.txt``.  Its option ``t0_c``
(the temperature the line is written about) has no option of its own on the command line:
``fit --param t0_c=25`` sets it.  With that folder on
``PYTHONPATH``, ``thermocal fit --model toy``, ``validate`` and ``compensate`` run in a
fresh interpreter on simulated data (``thermocal simulate fog-slow``), touching no file of
thermocal.  The numbers are checked against the simulator's truth (``truth_bias``) and
against least squares written here with numpy."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

TOY = '''
"""A toy family: y = c0 + c1·(T1 − t0_c) (order 1) or y = c0 (order 0)."""
from typing import ClassVar

import numpy as np

from thermocal.families import FamilyDeclaration, FamilyOption
from thermocal.models.base import Coefficient, FitStats, ModelStream, TemperatureModel

DECLARATION = FamilyDeclaration(
    "toy",
    "toyfam:ToyModel",
    "a constant plus a line in the first temperature",
    (FamilyOption("order", "int", "0: a constant; 1: a constant plus a line", 0, 1),
     FamilyOption("t0_c", "float", "temperature the line is written about [°C]", -50, 150)),
    "a line in the first temperature column",
)


class _Stream(ModelStream):
    def __init__(self, model):
        self.model = model

    def update(self, time_s, temps_c, signal=None):
        return float(self.model.value(np.atleast_1d(temps_c)[:1])[0])

    def reset(self):
        pass


class ToyModel(TemperatureModel):
    declaration: ClassVar[FamilyDeclaration] = DECLARATION

    def __init__(self, order: int = 1, t0_c: float = 0.0) -> None:
        self.order = order
        self.t0_c = t0_c

    def value(self, t):
        t = t - self.t0_c
        return self.coef_[0] + (self.coef_[1] * t if self.order else 0.0 * t)

    def fit(self, runs):
        t = np.concatenate([r.temps_c[:, 0] for r in runs]) - self.t0_c
        y = np.concatenate([r.target() for r in runs])
        design = np.column_stack([np.ones_like(t), t][: self.order + 1])
        coef, *_ = np.linalg.lstsq(design, y, rcond=None)
        self.coef_ = [float(c) for c in coef] + [0.0] * (1 - self.order)
        rms = float(np.sqrt(np.mean((y - design @ coef) ** 2)))
        self._record_common(runs, FitStats(t.size, self.order + 1, rms))
        return self

    def predict(self, run, *, extrapolate=False):
        return self.value(run.temps_c[:, 0])

    def stream(self, sample_interval_s, *, extrapolate=False):
        return _Stream(self)

    def coefficients(self):
        names = ("c0", "c1")[: self.order + 1]
        return [Coefficient(n, c, None) for n, c in zip(names, self.coef_, strict=False)]

    def _state(self):
        return {"coef": list(self.coef_)}

    def _set_state(self, state):
        self.coef_ = [float(c) for c in state["coef"]]
'''


def _plugin(root: Path) -> Path:
    """The package and its one registration line (the entry point)."""
    (root / "toyfam").mkdir(parents=True)
    (root / "toyfam" / "__init__.py").write_text(TOY, encoding="utf-8")
    meta = root / "toyfam-0.1.dist-info"
    meta.mkdir()
    (meta / "METADATA").write_text("Metadata-Version: 2.1\nName: toyfam\nVersion: 0.1\n")
    (meta / "entry_points.txt").write_text("[thermocal.families]\ntoy = toyfam:ToyModel\n")
    return root


def _thermocal(args: list[str], pythonpath: Path) -> subprocess.CompletedProcess[str]:
    """``thermocal ARGS`` in a fresh interpreter with the plugin folder on the path."""
    src = Path(__file__).resolve().parents[2] / "src"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(pythonpath), str(src)])}
    code = "import sys; from thermocal.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, check=False
    )


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The plugin, a simulated modelling run and an independent validation run."""
    d = tmp_path_factory.mktemp("toy")
    _plugin(d / "plugins")
    for seed, name in ((0, "mod.csv"), (1, "val.csv")):
        done = _thermocal(
            ["simulate", "fog-slow", "-o", str(d / name), "--seed", str(seed),
             "--rate-hz", "0.1"], d / "plugins",
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
    return d


def _line(frame: pd.DataFrame, column: str, t0_c: float = 0.0) -> np.ndarray:
    """Least squares of ``column`` on a constant and T1 − t0_c, written here: [c0, c1]."""
    t = frame["T1"].to_numpy() - t0_c
    design = np.column_stack([np.ones_like(t), t])
    return np.linalg.lstsq(design, frame[column].to_numpy(), rcond=None)[0]


def test_a_plugin_family_fits_validates_and_compensates_through_the_cli(runs: Path) -> None:
    plugins, model = runs / "plugins", runs / "toy.json"
    fit = _thermocal(
        ["fit", str(runs / "mod.csv"), "--model", "toy", "--signal", "gyro", "--temps", "T1",
         "--order", "1", "-o", str(model), "--json"], plugins,
    )  # fmt: skip
    assert fit.returncode == 0, fit.stderr
    out = json.loads(fit.stdout)
    mod = pd.read_csv(runs / "mod.csv")
    c0, c1 = _line(mod, "gyro")
    got = {c["name"]: c["value"] for c in out["coefficients"]}
    assert out["model"] == "toy"
    assert got == pytest.approx({"c0": c0, "c1": c1}, rel=1e-9)
    # the slope is the simulator's: its true bias, fitted by the same line (sensor noise and
    # the true bias's curvature move it by well under 1 %)
    assert got["c1"] == pytest.approx(_line(mod, "truth_bias")[1], rel=0.01)

    val = _thermocal(
        ["validate", str(model), str(runs / "val.csv"), "--modeling", str(runs / "mod.csv"),
         "--json"], plugins,
    )  # fmt: skip
    assert val.returncode == 0, val.stderr
    rep = json.loads(val.stdout)
    assert rep["family"] == "toy"
    assert rep["rms_after"] < 0.5 * rep["rms_before"]

    comp = runs / "comp.csv"
    done = _thermocal(["compensate", str(model), str(runs / "val.csv"), "-o", str(comp)], plugins)
    assert done.returncode == 0, done.stderr
    frame, written = pd.read_csv(runs / "val.csv"), pd.read_csv(comp)
    model_value = c0 + c1 * frame["T1"]
    np.testing.assert_allclose(written["gyro_model"], model_value, rtol=1e-9)
    np.testing.assert_allclose(written["gyro_comp"], frame["gyro"] - model_value, atol=1e-9)


def test_the_plugin_declares_its_bounds_and_the_cli_shows_the_option(runs: Path) -> None:
    """The plugin's declared bound on ``order`` is checked by the library and shown with the
    command line's option; an option it does not declare is refused, naming it."""
    plugins = runs / "plugins"
    base = ["fit", str(runs / "mod.csv"), "--model", "toy", "--signal", "gyro", "-o",
            str(runs / "x.json")]  # fmt: skip
    done = _thermocal([*base, "--order", "2"], plugins)
    assert done.returncode == 2 and done.stderr.strip().splitlines()[-1] == (
        "error: --order must be between 0 and 1, got 2"
    )
    done = _thermocal([*base, "--segments", "3"], plugins)
    assert done.returncode == 2
    assert "segments does not apply to model 'toy' (it takes: order, t0_c)" in done.stderr


def test_a_plugin_option_without_a_cli_option_is_set_with_param(runs: Path) -> None:
    """``--param t0_c=25`` reaches the toy family's constructor: the saved line is written
    about 25 °C (c0 is the value at 25 °C, least squares on T1 − 25 here), the slope is the
    same; an unknown name and a value outside the declared bounds are one error line each,
    listing the family's options."""
    plugins, model = runs / "plugins", runs / "toy25.json"
    base = ["fit", str(runs / "mod.csv"), "--model", "toy", "--signal", "gyro", "--temps", "T1"]
    fit = _thermocal([*base, "--param", "t0_c=25", "-o", str(model), "--json"], plugins)
    assert fit.returncode == 0, fit.stderr
    got = {c["name"]: c["value"] for c in json.loads(fit.stdout)["coefficients"]}
    mod = pd.read_csv(runs / "mod.csv")
    c0, c1 = _line(mod, "gyro", 25.0)
    assert got == pytest.approx({"c0": c0, "c1": c1}, rel=1e-9)
    c0_zero, c1_zero = _line(mod, "gyro")
    assert c0 == pytest.approx(c0_zero + 25.0 * c1_zero, rel=1e-9)  # the same line
    saved = json.loads(model.read_text(encoding="utf-8"))
    assert saved["params"]["t0_c"] == 25.0

    bad = str(runs / "bad.json")
    for arg, line in (
        ("gain=2", "error: --param 'gain=2': give NAME=VALUE, NAME an option of model 'toy' "
                   "(it takes: order, t0_c)"),
        ("t0_c=400", "error: --param t0_c must be between -50 and 150, got 400.0 "
                     "(model 'toy' takes: order, t0_c)"),
    ):  # fmt: skip
        done = _thermocal([*base, "--param", arg, "-o", bad], plugins)
        assert done.returncode == 2 and done.stderr.strip().splitlines() == [line], done.stderr
    assert not Path(bad).exists()


def test_a_broken_plugin_is_one_warning_and_skipped(tmp_path: Path) -> None:
    root = _plugin(tmp_path)
    (root / "toyfam-0.1.dist-info" / "entry_points.txt").write_text(
        "[thermocal.families]\ntoy = toyfam:NoSuchClass\n"
    )
    code = textwrap.dedent(
        """
        import warnings
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            from thermocal.models.registry import MODEL_REGISTRY
        print(sorted(MODEL_REGISTRY))
        print(*[str(w.message) for w in caught], sep="\\n")
        """
    )
    src = Path(__file__).resolve().parents[2] / "src"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(root), str(src)])}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    ).stdout.splitlines()
    assert out[0] == "['bank', 'hyst', 'piecewise', 'poly', 'warmup']"
    assert out[1:] == [
        "model family plugin 'toy' (toyfam:NoSuchClass) skipped: AttributeError: module "
        "'toyfam' has no attribute 'NoSuchClass'"
    ]
