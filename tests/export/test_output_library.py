"""The library functions behind ``compensate``, ``export-c`` and ``export-params``
(issue 27: the commands only parse, call one of these and print), tested without the
command line against numbers computed here."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.errors import ThermocalInputError
from thermocal.export.c import generate_c, generate_c_calibration
from thermocal.export.c.files import ExportCResult, export_c_file
from thermocal.models.calibration import Calibration, Channel
from thermocal.models.format import model_file_dict
from thermocal.models.registry import make_model
from thermocal.models.rundata import RunData
from thermocal.pipeline.compensate import CalibrationCompensation, compensate_calibration_file
from thermocal.pipeline.model_file import save_calibration, save_model
from thermocal.readers.options import ReadOptions

N = 4000
SLOPES = {"gx": 0.02, "gy": -0.05}
"""Each channel's bias against temperature [°/h per °C] written into the data."""


def _data(tmp_path: Path) -> tuple[Path, pd.DataFrame]:
    """time [s], gx and gy [°/h] = offset + slope·(T − 25) exactly, T [°C] one slow sweep."""
    t = np.arange(N, dtype=np.float64)
    T = 25.0 + 12.0 * np.sin(2.0 * np.pi * t / N)
    df = pd.DataFrame({"time": t, "T": T})
    for k, (name, slope) in enumerate(SLOPES.items()):
        df[name] = 0.3 * (k + 1) + slope * (T - 25.0)
    path = tmp_path / "run.csv"
    df.to_csv(path, index=False)
    return path, df


def _channel(df: pd.DataFrame, name: str) -> Channel:
    run = RunData(
        time_s=df["time"].to_numpy(),
        temps_c=df[["T"]].to_numpy(),
        signal=df[name].to_numpy(),
        temp_names=("T",),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the data's adequacy (one sweep) is not the point
        model = make_model("poly", terms="T1").fit([run])
    model.signal_name, model.signal_unit = name, "deg/h"
    return Channel(name, name, "deg/h", model)


def _quiet(fn, *args, **kwargs):  # type: ignore[no-untyped-def]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # units stated by no file: defaults, with a warning
        return fn(*args, **kwargs)


def test_compensate_calibration_file_two_channels_in_one_pass(tmp_path: Path) -> None:
    src, df = _data(tmp_path)
    cal = Calibration([_channel(df, n) for n in SLOPES])
    cal_path = tmp_path / "cal.json"
    save_calibration(cal, cal_path)
    out = tmp_path / "out.csv"
    read = ReadOptions(time_unit="s", signal_unit="deg/h", temp_unit="degC")
    run = _quiet(compensate_calibration_file, cal_path, src, out, read, chunk_rows=777)
    assert isinstance(run, CalibrationCompensation) and run.kind == "channels"
    got = pd.read_csv(out)
    for k, ((name, family, res), slope) in enumerate(
        zip(run.channels, SLOPES.values(), strict=True)
    ):
        assert family == "poly" and res.n_rows == N and res.n_chunks == -(-N // 777)
        # the model (with its constant) is the line written into the data
        line = 0.3 * (k + 1) + slope * (df["T"].to_numpy() - 25.0)
        np.testing.assert_allclose(got[f"{name}_model"], line, rtol=0, atol=1e-9)
        np.testing.assert_allclose(got[f"{name}_comp"], 0.0, rtol=0, atol=1e-9)
        assert res.rms_before == pytest.approx(float(np.std(df[name])), rel=1e-9)
        assert res.rms_before == pytest.approx(abs(slope) * 12.0 / np.sqrt(2.0), rel=1e-3)
        assert res.rms_after < 1e-6
    d = run.to_dict()
    assert d["model"] == str(cal_path) and d["output"] == str(out)
    assert list(d["channels"]) == list(SLOPES)
    assert d["channels"]["gx"]["family"] == "poly" and d["channels"]["gx"]["n_rows"] == N


def test_compensate_calibration_file_one_model_and_its_refusals(tmp_path: Path) -> None:
    src, df = _data(tmp_path)
    ch = _channel(df, "gy")
    model_path = tmp_path / "m.json"
    save_model(ch.model, model_path)
    read = ReadOptions(time_unit="s", signal_unit="deg/h", temp_unit="degC")
    run = _quiet(compensate_calibration_file, model_path, src, tmp_path / "o.parquet", read)
    assert run.kind == "single"
    d = run.to_dict()
    assert d["model"] == str(model_path) and d["family"] == "poly" and d["signal"] == "gy"
    assert d["rms_before"] == pytest.approx(float(np.std(df["gy"])), rel=1e-9)
    with pytest.raises(ThermocalInputError):  # the output may not be an input
        compensate_calibration_file(model_path, src, src)


def _without_identity(c_text: str) -> str:
    """Generated C without the lines that say when it was made (``created (UTC)`` and the
    ``checksum (sha256)`` over the file that includes it)."""
    return "\n".join(
        ln
        for ln in c_text.splitlines()
        if "created (UTC):" not in ln and "checksum (sha256):" not in ln
    )


def test_export_c_file_writes_what_generate_c_gives(tmp_path: Path) -> None:
    _src, df = _data(tmp_path)
    ch = _channel(df, "gx")
    model_path = tmp_path / "gx_model.json"
    save_model(ch.model, model_path)
    res = _quiet(export_c_file, model_path, tmp_path / "c", sample_interval_s=1.0)
    assert isinstance(res, ExportCResult) and res.kind == "model"
    want = generate_c(model_file_dict(ch.model), prefix="gx_model", sample_interval_s=1.0)
    assert [p.name for p in res.files] == ["gx_model.h", "gx_model.c"]
    # the identity block aside (its creation time and checksum: a second may tick between
    # the two), the same C
    assert _without_identity(res.files[1].read_text()) == _without_identity(want.source)
    assert res.to_dict()["float_max_abs_error"] is None
    cal_path = tmp_path / "cal.json"
    save_calibration(Calibration([ch, _channel(df, "gy")]), cal_path)
    res = _quiet(export_c_file, cal_path, tmp_path / "c2", name="imu")
    chans = [(c.name, model_file_dict(c.model), None) for c in (ch, _channel(df, "gy"))]
    want = generate_c_calibration(chans, prefix="imu")
    # the identity block aside (its creation time, to the second, and the checksum over it
    # may fall in the next second between the two generations), the same header
    assert res.kind == "calibration"
    assert _without_identity(res.files[0].read_text()) == _without_identity(want.header)
    assert res.to_dict()["channels"] == {
        "gx": {"unit": "deg/h", "family": "poly"},
        "gy": {"unit": "deg/h", "family": "poly"},
    }


def test_export_params_file_writes_the_parameters_it_returns(tmp_path: Path) -> None:
    from thermocal.cli import main
    from thermocal.export.params import ParamsFileResult, export_params_file
    from thermocal.simulate import SCENARIOS
    from thermocal.writers import write_recording

    ((mod, _truth),) = SCENARIOS["mems-imu"](11, rate_hz=0.2)
    write_recording(mod, tmp_path / "mod.parquet")
    cal = tmp_path / "cal.json"
    assert main(["fit", str(tmp_path / "mod.parquet"), "--model", "poly", "--order", "3",
                 "--signal", "gx,gy,gz,ax,ay,az", "--temps", "T_die", "--gravity-axis", "+z",
                 "--gravity", "9.80665", "-o", str(cal)]) == 0  # fmt: skip
    out = tmp_path / "tc.params"
    res = _quiet(export_params_file, cal, "px4", out, tref_c=30.0, device_id=7)
    assert isinstance(res, ParamsFileResult) and res.output == str(out)
    written = {}
    for line in out.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            _v, _c, name, value, _typ = line.split("\t")
            written[name] = float(value)
    assert written == pytest.approx(res.params.params, rel=1e-6)
    assert written["TC_G0_TREF"] == 30.0 and written["TC_G0_ID"] == 7.0
    d = res.to_dict()
    assert d["format"] == "px4" and len(d["axes"]) == 6
    assert {a["tref_c"] for a in d["axes"]} == {30.0}
    with pytest.raises(ThermocalInputError):  # the output may not be the calibration
        export_params_file(cal, "px4", cal)


def test_compensate_calibration_file_takes_the_channels_as_a_tuple(tmp_path: Path) -> None:
    """``signals=("gy",)`` applies gy alone (its line, written into the data, is the model);
    a CSV output whose sidecar would land on the model file is refused before any write."""
    src, df = _data(tmp_path)
    cal_path = tmp_path / "cal.json"
    save_calibration(Calibration([_channel(df, n) for n in SLOPES]), cal_path)
    out = tmp_path / "out.csv"
    read = ReadOptions(time_unit="s", signal_unit="deg/h", temp_unit="degC")
    run = _quiet(compensate_calibration_file, cal_path, src, out, read, signals=("gy",))
    assert run.kind == "channels" and [name for name, _f, _r in run.channels] == ["gy"]
    got = pd.read_csv(out)
    assert "gx_comp" not in got.columns
    line = 0.6 + SLOPES["gy"] * (df["T"].to_numpy() - 25.0)
    np.testing.assert_allclose(got["gy_model"], line, rtol=0, atol=1e-9)
    side_on_model = tmp_path / "o.csv.meta.json"
    side_on_model.write_bytes(cal_path.read_bytes())
    with pytest.raises(ThermocalInputError, match=r"meta\.json"):
        _quiet(compensate_calibration_file, side_on_model, src, tmp_path / "o.csv", read)
    assert not (tmp_path / "o.csv").exists()
