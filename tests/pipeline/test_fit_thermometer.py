"""``thermocal fit`` on a table whose thermometer is coarse: a gyro column with a cubic bias
over a −10…50 °C sweep, its temperature read by a Bosch whole-degree thermometer (rounded,
every sample) and, in another file, the true temperature.  Fitted on the reconstructed
temperature (the default), the residual is within 1.1× of the fit on the truth; as logged
(``--temperature raw``), the staircase adds slope × 1/√12 °C: ≥ 1.25×."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.pipeline.fit import fit_files
from thermocal.pipeline.model_file import load_model
from thermocal.pipeline.options import FitOptions
from thermocal.thermometer import ThermometerWarning


def _files(d: Path) -> dict[str, Path]:
    t = np.arange(0, 3000.0, 0.05)
    true = -10 + 60 * (0.5 - 0.5 * np.cos(np.pi * t / 3000))
    x = (true - 20) / 30
    gyro = 0.5 + 2 * x - 0.6 * x**2 + 0.4 * x**3
    gyro = gyro + np.random.default_rng(0).normal(0, 0.02, t.size)  # [deg/s]
    out = {}
    for name, temp in (("true", true), ("whole", np.round(true))):
        out[name] = d / f"{name}.csv"
        np.savetxt(out[name], np.column_stack([t, gyro, temp]), delimiter=",",
                   header="time_s,gyro,T [degC]", comments="", fmt="%.6f")  # fmt: skip
    return out


def _fit(path: Path, out: Path, *more: str) -> dict:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["fit", str(path), "--model", "poly", "--order", "3", "--signal", "gyro",
                     "--temps", "T [degC]", "--signal-unit", "deg/s", "-o", str(out), "--json",
                     *more])  # fmt: skip
    assert code == 0
    return json.loads(buf.getvalue())


def test_fit_reconstructs_a_whole_degree_thermometer(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = _files(tmp_path)
    truth = _fit(f["true"], tmp_path / "t.json")
    assert truth["thermometers"][0]["kind"] == "continuous"
    capsys.readouterr()
    rec = _fit(f["whole"], tmp_path / "r.json")
    err = capsys.readouterr().err
    assert "'T [degC]': the thermometer is quantised (1 °C)" in err
    assert "give --temperature raw to fit it as logged" in err
    th = rec["thermometers"][0]
    assert th["step_c"] == pytest.approx(1.0, abs=1e-9) and th["temperature"] == "reconstructed"
    raw = _fit(f["whole"], tmp_path / "w.json", "--temperature", "raw")
    assert raw["thermometers"][0]["temperature"] == "raw"
    model = load_model(tmp_path / "r.json")  # the model file records it, and reads back
    assert model.inputs_["thermometers"][0]["temperature"] == "reconstructed"
    assert rec["rms_residual"] <= 1.1 * truth["rms_residual"]
    assert raw["rms_residual"] >= 1.25 * truth["rms_residual"]  # the staircase


def test_fit_files_api_and_a_bad_mode(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = _files(tmp_path)
    o = FitOptions(
        "poly", {"order": 3}, signals=("gyro",), temperatures=("T [degC]",), signal_unit="deg/s"
    )
    with pytest.warns(ThermometerWarning, match="give temperature raw"):
        res = fit_files([f["whole"]], o, tmp_path / "a.json")
    assert res.channels[0].figures["thermometers"][0]["temperature"] == "reconstructed"
    with pytest.raises(Exception, match="temperature must be reconstructed or raw"):
        FitOptions("poly", {"order": 3}, temperature="smooth")  # type: ignore[arg-type]
    bad = ["--temperature", "smooth"]
    code = main(["fit", str(f["whole"]), "--model", "poly", "--signal", "gyro", "--temps",
                 "T [degC]", "-o", str(tmp_path / "b.json"), *bad])  # fmt: skip
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("error: ") and "--temperature must be reconstructed or raw" in err[-1]
    assert not (tmp_path / "b.json").exists()
