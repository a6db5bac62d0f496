"""``thermocal fit`` (and :func:`thermocal.pipeline.fit.fit_files`) on a CSV of a heated
sensor: the temperature ramps to a heater's set-point, overshoots and holds for 50 minutes
(tests/helpers/fc_logs.py's simulator), while the bias keeps settling at the set-point (the
board warms after its thermometer).  The hold is found without being told, thinned to the
sweep's density, and the fitted model's residual on the sweep is within 1.1× of the same fit
on the sweep alone (the CSV cut at the set-point) — the whole hold fitted as it is would
have spoilt it by more than that (both computed here)."""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from fc_logs import heated_truth
from thermocal.cli import main
from thermocal.heater import HeaterWarning
from thermocal.models.rundata import RunData
from thermocal.pipeline.fit import fit_files
from thermocal.pipeline.options import FitOptions

ARGS = ["--model", "poly", "--order", "3", "--signal", "gyro_x", "--temps", "temperature",
        "--time-unit", "s", "--signal-unit", "deg/h", "--temp-unit", "degC"]  # fmt: skip
"""A cubic in T (no Ṫ terms: those would tell the hold from the ramp by themselves)."""


@pytest.fixture(scope="module")
def heated_csv(tmp_path_factory: pytest.TempPathFactory) -> dict:
    d = tmp_path_factory.mktemp("fit_heater")
    tr = heated_truth(5, hold_s=3000.0)
    T, t = np.round(tr["temp"], 4), np.round(tr["time_s"], 3)  # as the CSV holds them
    x = (T - 35.0) / 20.0
    settling = 2.0 * (1.0 - np.exp(-np.clip(t - tr["reached_s"], 0.0, None) / 600.0))
    truth = 10.0 * x + 4.0 * x**2 + 3.0 * x**4 + settling  # [°/h]
    bias = np.round(truth + np.random.default_rng(1).normal(0.0, 0.3, T.size), 6)

    def write(path: Path, rows: np.ndarray) -> Path:
        with path.open("w") as f:
            f.write("time,gyro_x,temperature\n")
            for a, b, c in zip(t[rows], bias[rows], T[rows], strict=True):
                f.write(f"{a:.3f},{b:.6f},{c:.4f}\n")
        return path

    every = np.ones(t.size, dtype=bool)
    sweep = t < tr["reached_s"]
    csv, ramp = write(d / "heated.csv", every), write(d / "ramp.csv", sweep)
    return {"dir": d, "truth": tr, "t": t, "T": T, "bias": bias, "sweep": sweep, "csv": csv,
            "ramp": ramp}  # fmt: skip


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(args)
    return code, buf.getvalue(), capsys.readouterr().err


def _rms_on_sweep(model_path: Path, data: dict) -> float:
    from thermocal.pipeline.model_file import load_model

    est = load_model(model_path)
    s = data["sweep"]
    run = RunData(data["t"][s], data["T"][s].reshape(-1, 1), None, ("temperature",))
    return float(np.sqrt(np.mean((est.predict(run) - data["bias"][s]) ** 2)))


def test_fit_finds_the_hold_and_fits_the_sweep(
    heated_csv: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    d, tr = heated_csv["dir"], heated_csv["truth"]
    before = hashlib.sha256(heated_csv["csv"].read_bytes()).hexdigest()
    code, out, err = _run(["fit", str(heated_csv["csv"]), *ARGS, "-o", str(d / "m.json"),
                           "--json"], capsys)  # fmt: skip
    assert code == 0, err
    assert hashlib.sha256(heated_csv["csv"].read_bytes()).hexdigest() == before
    res = json.loads(out)
    hold = res["heater"]["heated.csv"]
    assert hold["setpoint_source"] == "inferred"
    assert abs(hold["setpoint_c"] - 55.0) < 0.05
    assert abs(hold["reached_s"] - tr["reached_s"]) < 1.0
    assert hold["range_cut"]
    said = [ln for ln in err.splitlines() if "heater hold at 55.00 °C (inferred)" in ln]
    assert len(said) == 1 and said[0].startswith("warning: ")
    assert "beyond it the model extrapolates" in said[0] and "heater off or" in said[0]
    assert any("heater hold" in w for w in res["warnings"])
    # thinned: the sweep's samples plus about as many hold samples as the sweep has per °C
    n_sweep = int(np.count_nonzero(heated_csv["t"] < hold["hold_start_s"]))
    assert n_sweep < res["n_samples"] < n_sweep + 1000
    # judged on the sweep: within 1.1x of the fit without the hold
    code, _o, err = _run(["fit", str(heated_csv["ramp"]), *ARGS, "-o", str(d / "ramp.json"),
                          "--heater", "ignore"], capsys)  # fmt: skip
    assert code == 0, err
    code, _o, err = _run(["fit", str(heated_csv["csv"]), *ARGS, "-o", str(d / "all.json"),
                          "--heater", "ignore"], capsys)  # fmt: skip
    assert code == 0, err
    thinned = _rms_on_sweep(d / "m.json", heated_csv)
    without = _rms_on_sweep(d / "ramp.json", heated_csv)
    everything = _rms_on_sweep(d / "all.json", heated_csv)
    assert thinned <= 1.1 * without, (thinned, without)
    assert everything > 1.1 * without, (everything, without)  # what the thinning saves


def test_fit_refuses_a_cut_range_when_asked(
    heated_csv: dict, capsys: pytest.CaptureFixture[str]
) -> None:
    d = heated_csv["dir"]
    code, _o, err = _run(["fit", str(heated_csv["csv"]), *ARGS, "-o", str(d / "r.json"),
                          "--heater", "refuse"], capsys)  # fmt: skip
    assert code == 2 and not (d / "r.json").exists()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {heated_csv['csv']}: heater hold")
    assert "give --heater cut" in lines[0]
    code, _o, err = _run(["fit", str(heated_csv["csv"]), *ARGS, "-o", str(d / "r.json"),
                          "--heater", "maybe"], capsys)  # fmt: skip
    assert code == 2 and "--heater must be cut, refuse or ignore, got 'maybe'" in err


def test_fit_files_api_with_a_given_setpoint(heated_csv: dict) -> None:
    opts = FitOptions("poly", {"order": 3}, signals=("gyro_x",), temperatures=("temperature",),
                      time_unit="s", signal_unit="deg/h", temp_unit="degC",
                      heater_setpoint=55.0)  # fmt: skip
    with warnings.catch_warnings(record=True) as caught:  # the fit's own doubts as well
        warnings.simplefilter("always")
        res = fit_files([heated_csv["csv"]], opts, heated_csv["dir"] / "api.json")
    said = [str(w.message) for w in caught if issubclass(w.category, HeaterWarning)]
    assert len(said) == 1 and "heater hold at 55.00 °C (given)" in said[0]
    hold = res.to_dict()["heater"]["heated.csv"]
    assert hold["setpoint_c"] == 55.0
    assert abs(hold["reached_s"] - heated_csv["truth"]["reached_s"]) < 1.0


def test_a_csv_at_the_setpoint_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tr = heated_truth(2, at_setpoint=True)
    path = tmp_path / "warm.csv"
    rows = "\n".join(f"{a:.3f},{0.01 * c:.6f},{c:.4f}" for a, c in zip(tr["time_s"], tr["temp"],
                                                                       strict=True))  # fmt: skip
    path.write_text("time,gyro_x,temperature\n" + rows + "\n")
    out = str(tmp_path / "m.json")
    code, _o, err = _run(["fit", str(path), *ARGS, "-o", out, "--heater-setpoint", "55"], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "no sweep to calibrate" in lines[0]
    # no set-point given: a plateau without a sweep is no heater's; the data's judgement
    # refuses the narrow span, naming its override
    code, _o, err = _run(["fit", str(path), *ARGS, "-o", out], capsys)
    assert code == 2 and "heater" not in err and "--allow-narrow" in err


@pytest.mark.parametrize(
    ("option", "value"),
    [
        ("--heater-setpoint", "nan"),
        ("--heater-setpoint", "-1e9"),
        ("--heater", ""),
        ("--heater-band", "0"),
        ("--heater-min-hold", "inf"),
    ],
)
def test_hostile_heater_options_of_fit(
    heated_csv: dict, capsys: pytest.CaptureFixture[str], option: str, value: str
) -> None:
    out = heated_csv["dir"] / "hostile.json"
    before = hashlib.sha256(heated_csv["csv"].read_bytes()).hexdigest()
    code, _o, err = _run(["fit", str(heated_csv["csv"]), *ARGS, "-o", str(out), option, value],
                         capsys)  # fmt: skip
    assert code == 2 and not out.exists()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {option} must be"), err
    assert hashlib.sha256(heated_csv["csv"].read_bytes()).hexdigest() == before
