"""``thermocal fit`` through the command line."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.errors import ThermocalInputError
from thermocal.models.piecewise import PiecewiseModel
from thermocal.models.poly import PolyModel
from thermocal.models.registry import MODEL_REGISTRY
from thermocal.pipeline.fit import build_model
from thermocal.pipeline.model_file import load_model
from thermocal.recording import Recording
from thermocal.writers import write_recording


def _write_run(path: Path, seed: int, offset: float = 0.0, n: int = 4000) -> Path:
    rng = np.random.default_rng(seed)
    t = np.arange(float(n))
    amb = 25 + 15 * np.sin(2 * np.pi * t / 3000 + seed)
    temps = {f"T{k + 1}": amb + 0.5 * np.sin(t / (200 + 37 * k) + k) for k in range(4)}
    y = 0.02 * temps["T1"] + offset + 0.01 * rng.standard_normal(n) + 10.0
    rec = Recording.from_arrays(t, {"gyro": y}, temps, signal_unit="deg/h")
    write_recording(rec, path)
    return path


def _run(capsys, args):
    code = main(args)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_fit_poly_json(tmp_path, capsys):
    f = _write_run(tmp_path / "a.csv", 1)
    out = tmp_path / "m.json"
    code, so, se = _run(
        capsys,
        ["fit", str(f), "--model", "poly", "--signal", "gyro", "--temps", "T1,T2,T3,T4",
         "-o", str(out), "--json"],
    )  # fmt: skip
    assert code == 0, se
    res = json.loads(so)
    for key in ("model", "n_coefficients", "rms_residual", "condition_number", "temperature_range"):
        assert key in res
    assert res["model"] == "poly"
    assert res["n_coefficients"] == 37
    assert res["rms_residual"] == pytest.approx(0.01, rel=0.1)
    assert set(res["temperature_range"]) == {"T1", "T2", "T3", "T4"}
    assert res["output"] == str(out)
    assert res["files"][0]["sha256"] == hashlib.sha256(f.read_bytes()).hexdigest()
    model = load_model(out)
    assert isinstance(model, PolyModel)
    assert model.data_[0]["sha256"] == res["files"][0]["sha256"]
    d = json.loads(out.read_text())
    assert d["signal"] == {"name": "gyro", "unit": "deg/h", "target": "bias"}
    assert d["rate"]["interval_s"] == 60.0


def test_fit_several_runs_select_earth_rate(tmp_path, capsys):
    a = _write_run(tmp_path / "a.csv", 1, offset=0.1)
    b = _write_run(tmp_path / "b.csv", 2, offset=-0.1)
    out = tmp_path / "m.json"
    code, so, se = _run(
        capsys,
        ["fit", str(a), str(b), "--model", "poly", "--signal", "gyro", "--temps", "T1,T2",
         "--select", "--rate-interval", "30", "--latitude", "45", "--axis", "up",
         "--target", "scale_factor", "-o", str(out), "--json"],
    )  # fmt: skip
    assert code == 0, se
    res = json.loads(so)
    assert res["n_runs"] == 2 and res["target"] == "scale_factor"
    assert "T1" in res["terms_kept"]
    offs = res["fit"]["per_run_offsets"]
    assert offs[0] - offs[1] == pytest.approx(0.2, abs=0.01)
    model = load_model(out)
    assert model.data_[0]["known_input"] == pytest.approx(15.041 * np.sin(np.pi / 4), rel=1e-3)
    assert json.loads(out.read_text())["params"]["rate_interval_s"] == 30.0


def test_fit_piecewise_human_output(tmp_path, capsys):
    f = _write_run(tmp_path / "a.csv", 3)
    out = tmp_path / "pw.json"
    code, so, se = _run(
        capsys,
        ["fit", str(f), "--model", "piecewise", "--signal", "gyro", "--temps", "T1",
         "--breakpoints", "20,30", "--method", "continuous", "-o", str(out)],
    )  # fmt: skip
    assert code == 0, se
    assert "piecewise" in so and "coefficients" in so
    assert isinstance(load_model(out), PiecewiseModel)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--model", "poly", "--signal", "nope"], "nope"),
        (["--model", "spline", "--signal", "gyro"], "unknown model family"),
        (["--model", "poly", "--signal", "gyro", "--breakpoints", "25"], "does not apply"),
        (["--model", "piecewise", "--signal", "gyro", "--breakpoints", "x"], "--breakpoints"),
        (["--model", "poly", "--signal", "gyro", "--latitude", "45"], "--axis"),
        (["--model", "poly", "--signal", "gyro", "--target", "drift"], "--target"),
        # a criterion without the selection it chooses for was silently ignored
        (
            ["--model", "poly", "--signal", "gyro", "--select-method", "holdout"],
            "--select-method holdout chooses how --select works, but --select is not given",
        ),
    ],
)
def test_bad_input_exit_2(tmp_path, capsys, extra, message):
    f = _write_run(tmp_path / "a.csv", 1, n=500)
    code, so, se = _run(capsys, ["fit", str(f), *extra, "-o", str(tmp_path / "m.json")])
    assert code == 2
    assert so == ""
    lines = se.strip().splitlines()
    assert lines[-1].startswith("error: ") and message in lines[-1]
    assert "Traceback" not in se


def test_never_writes_over_input(tmp_path, capsys):
    f = _write_run(tmp_path / "a.csv", 1, n=500)
    before = f.read_bytes()
    code, _so, se = _run(
        capsys, ["fit", str(f), "--model", "poly", "--signal", "gyro", "-o", str(f)]
    )
    assert code == 2 and "refusing" in se
    assert f.read_bytes() == before


def test_dispatch_through_registry(monkeypatch):
    """A family registered without its own declaration takes its parent's declared options;
    every family refuses an option it does not take (one parser for all)."""

    class Plain(PiecewiseModel):
        family = "plain-test"

    monkeypatch.setitem(MODEL_REGISTRY, "plain-test", Plain)
    m = build_model("plain-test", {"segments": 2, "method": None})
    assert isinstance(m, Plain) and m.segments == 2
    with pytest.raises(ThermocalInputError, match="ridge"):
        build_model("plain-test", {"ridge": 1.0})
    for fam, foreign in (("poly", "segments"), ("piecewise", "ridge"), ("warmup", "tolerance"),
                         ("bank", "rate_interval_s")):  # fmt: skip
        assert build_model(fam, {}).family == fam
        with pytest.raises(ThermocalInputError, match=f"{foreign} does not apply to model '{fam}'"):
            build_model(fam, {foreign: 1.0})
