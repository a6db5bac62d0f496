"""A model applied outside its calibrated range says how far and for what share of the
samples (issue 25 item 5): temperature [°C] and Ṫ [°C/min], once per channel in compensate
(whatever the number of chunks), in validate's warning, JSON and verdict line, and in the
streaming compensator.  Expected shares and distances are computed here from the data."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.compensate.kernels import StreamingCompensator
from thermocal.errors import ExtrapolationWarning
from thermocal.pipeline.model_file import load_model

SIG = "gx [deg/s]"
N = 3600


def _write(path: Path, t: np.ndarray, temp: np.ndarray, seed: int) -> None:
    rng = np.random.default_rng(seed)
    gx = -0.29 + 0.01 * (temp - 13.0) + 0.05 * rng.standard_normal(t.size)
    pd.DataFrame({"time (s)": t, SIG: gx, "temp_c": temp}).to_csv(path, index=False)


def _cold(tmp_path: Path) -> np.ndarray:
    """5 → 21 °C at 1 Hz, no temperature noise (Ṫ = 16/3599·60 °C/min after the first
    sample)."""
    t = np.arange(N, dtype=float)
    temp = 5.0 + 16.0 * t / (N - 1)
    _write(tmp_path / "cold.csv", t, temp, 1)
    return temp


def _fit(tmp_path: Path, *extra: str) -> Path:
    model = tmp_path / "m.json"
    code = main(["fit", str(tmp_path / "cold.csv"), "--model", "poly", *extra,
                 "--signal", SIG, "--temps", "temp_c", "-o", str(model)])  # fmt: skip
    assert code == 0
    return model


def _backward_rate(t: np.ndarray, temp: np.ndarray, dt: float = 60.0) -> np.ndarray:
    """Ṫ(t_i) = (T_i − T_j)/(t_i − t_j)·60 [°C/min], j the first sample with t_j ≥ t_i − Δt
    (0 when j = i)."""
    out = np.zeros(t.size)
    for i in range(t.size):
        j = int(np.searchsorted(t, t[i] - dt, side="left"))
        if t[i] > t[j]:
            out[i] = (temp[i] - temp[j]) / (t[i] - t[j]) * 60.0
    return out


def test_temperature_outside_the_range_says_how_far_and_how_often(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cold = _cold(tmp_path)
    rng = np.random.default_rng(2)
    t = np.arange(N, dtype=float)
    temp = np.where(t < 1200, 15.0, 30.0) + 0.01 * rng.standard_normal(N)  # 2/3 above
    _write(tmp_path / "warm.csv", t, temp, 3)
    model = _fit(tmp_path, "--order", "1")
    capsys.readouterr()
    share = float(np.mean((temp > cold.max()) | (temp < cold.min())))
    beyond = float(temp.max() - cold.max())

    code = main(["compensate", str(model), str(tmp_path / "warm.csv"), "-o",
                 str(tmp_path / "o.csv"), "--chunk-rows", "500", "--json"])  # fmt: skip
    io = capsys.readouterr()
    assert code == 0, io.err
    lines = [ln for ln in io.err.splitlines() if "outside its calibrated range" in ln]
    assert len(lines) == 1, io.err  # one for the file, not one per chunk (8 chunks)
    assert lines[0].startswith("warning: ")
    assert f"{round(share * N)} samples outside ({100 * share:.3g} % of {N})" in lines[0]
    assert f"up to {beyond:.3g} °C beyond" in lines[0]
    res = json.loads(io.out)
    assert res["outside_calibrated_range"] is True
    assert res["outside_range"]["temperature"]["share"] == pytest.approx(share, abs=1e-12)
    assert res["outside_range"]["temperature"]["max_beyond_c"] == pytest.approx(beyond, rel=1e-9)

    code = main(["validate", str(model), str(tmp_path / "warm.csv"), "--json"])
    io = capsys.readouterr()
    assert code == 0, io.err
    v = json.loads(io.out)
    tr = v["outside_range"]["temperature"]
    assert tr["share"] == pytest.approx(share, abs=1e-12)
    assert tr["max_beyond_c"] == pytest.approx(beyond, rel=1e-9)
    assert v["outside_calibrated_range"] is True
    assert "outside the calibrated range (temperature" in v["verdict_line"]
    assert io.err.count("outside its calibrated range") == 1
    # the model's own per-call range warning gave way to this one
    assert "samples outside the model's temperature range" not in io.err

    # inside the range: quiet, and flagged as such
    _write(tmp_path / "in.csv", t, 10.0 + 5.0 * t / N, 4)
    code = main(["validate", str(model), str(tmp_path / "in.csv"), "--json"])
    io = capsys.readouterr()
    assert "outside its calibrated range" not in io.err
    v = json.loads(io.out)
    assert v["outside_calibrated_range"] is False
    assert v["outside_range"]["temperature"]["share"] == 0.0


def test_temperature_rate_outside_the_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A T + Ṫ model fitted on a 0.27 °C/min sweep applied to a 1 °C/min ramp (inside the
    temperature range): the share of samples with Ṫ beyond the fitted Ṫ range and how far."""
    cold = _cold(tmp_path)
    t = np.arange(N, dtype=float)
    temp = np.clip(8.0 + t / 60.0, None, 18.0)  # 1 °C/min for 600 s, then a hold
    _write(tmp_path / "ramp.csv", t, temp, 5)
    # one rate only: the adequacy check refuses Ṫ terms without the override (issue 25)
    model = _fit(tmp_path, "--terms", "T1,dT1", "--allow-narrow")
    capsys.readouterr()
    r_fit = _backward_rate(np.arange(N, dtype=float), cold)
    r = _backward_rate(t, temp)
    out = (r > r_fit.max()) | (r < r_fit.min())
    share = float(np.mean(out))
    beyond = float(max(r.max() - r_fit.max(), r_fit.min() - r.min(), 0.0))
    assert 0.1 < share < 0.3 and beyond > 0.7  # the case is what it says

    code = main(["compensate", str(model), str(tmp_path / "ramp.csv"), "-o",
                 str(tmp_path / "o.csv"), "--chunk-rows", "333", "--json"])  # fmt: skip
    io = capsys.readouterr()
    assert code == 0, io.err
    rr = json.loads(io.out)["outside_range"]["temperature_rate"]
    assert rr["n_outside"] == int(out.sum())  # the chunks carry Ṫ's history
    assert rr["max_beyond_c_per_min"] == pytest.approx(beyond, rel=1e-9)
    assert json.loads(io.out)["outside_range"]["temperature"]["share"] == 0.0
    lines = [ln for ln in io.err.splitlines() if "outside its calibrated range" in ln]
    assert len(lines) == 1 and f"Ṫ: {int(out.sum())} samples outside" in lines[0]
    assert f"up to {beyond:.3g} °C/min beyond" in lines[0]

    code = main(["validate", str(model), str(tmp_path / "ramp.csv"), "--json"])
    io = capsys.readouterr()
    assert code == 0, io.err
    v = json.loads(io.out)
    assert v["outside_range"]["temperature_rate"]["share"] == pytest.approx(share, abs=1e-12)
    assert "temperature rate" in v["verdict_line"]
    assert "temperature rate outside the model's fitted range" not in io.err


def test_streaming_blocks_warn_once_and_count_every_block(tmp_path: Path) -> None:
    cold = _cold(tmp_path)
    _fit(tmp_path, "--order", "1")
    model = load_model(tmp_path / "m.json")
    t = np.arange(1000, dtype=float)
    temp = 20.0 + 0.01 * t  # leaves 21.0 °C after 100 s
    sc = StreamingCompensator(model, 1.0)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        for a in range(0, 1000, 100):
            sc.update_block(t[a : a + 100], temp[a : a + 100, None], np.zeros(100))
    ext = [w for w in rec if issubclass(w.category, ExtrapolationWarning)]
    assert len(ext) == 1
    (tr,) = [e for e in sc.outside_range if e.quantity == "temperature"]
    assert tr.n_outside == int(np.count_nonzero(temp > cold.max()))
    assert tr.max_beyond == pytest.approx(float(temp.max() - cold.max()), rel=1e-9)
