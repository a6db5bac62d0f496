"""Units that travel (issue 13): from the file, through the model file, to every output.

Regression tests of the silent wrong numbers found on recordings other tools wrote: a model
fitted on °/s data applied without repeating the unit (×3600), a sidecar's time unit
overridden by a default, units written in column names ignored.  The data are written here
with numpy, in the units and layouts other tools use; expected values are worked out here.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal import units
from thermocal.cli import main
from thermocal.datasets import example_path
from thermocal.errors import UnitWarning
from thermocal.units import resolve_unit, unit_in_column_name


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _gyro_deg_s(n: int = 4000, seed: int = 3) -> pd.DataFrame:
    """A gyro in °/s: bias 0.01 °/s + 2e-4 °/s/°C · (T − 25), noise 1e-5 °/s, time in s."""
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=float)
    temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / n)
    gyro = 0.01 + 2e-4 * (temp - 25.0) + 1e-5 * rng.standard_normal(n)
    return pd.DataFrame({"time": t, "gyro": gyro, "T1": temp})


def test_model_fitted_in_deg_s_compensates_deg_s_data_without_repeating_the_unit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Bug 1: fit --signal-unit deg/s, then compensate without the unit.  Before, the model
    (kept in °/h) was subtracted from °/s data: <sig>_comp ≈ −1810, exit 0.  Now the model
    file records the input unit and the output is in °/s: the compensated signal is the
    noise about 0.01 °/s (the model's constant is the run mean)."""
    df = _gyro_deg_s()
    src = tmp_path / "run.csv"
    df.to_csv(src, index=False)
    model = tmp_path / "m.json"
    code, _, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
        "--signal-unit", "deg/s", "--temps", "T1", "--temp-unit", "degC", "--time-unit", "s",
        "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    saved = json.loads(model.read_text())
    assert saved["format_version"] == 3
    assert saved["inputs"]["units"] == {"gyro": "deg/s", "T1": "degC"}
    assert saved["inputs"]["time_unit"] == "s"
    out = tmp_path / "comp.csv"
    code, _, err = _run(capsys, "compensate", str(model), str(src), "-o", str(out))
    assert code == 0, err
    assert "no unit stated" not in err  # the model said what the units were
    got = pd.read_csv(out)
    expect_model = 0.01 + 2e-4 * (df["T1"] - 25.0)  # [°/s], written out
    np.testing.assert_allclose(got["gyro_model"], expect_model, rtol=0, atol=2e-6)
    assert abs(float(got["gyro_comp"].mean())) < 1e-6
    assert float(got["gyro_comp"].std()) == pytest.approx(1e-5, rel=0.1)
    # validate reads the same units from the model
    code, stdout, err = _run(capsys, "validate", str(model), str(src), "--json")
    assert code == 0, err
    v = json.loads(stdout)
    # the temperature effect 2e-4 °/s/°C × 15 °C sine has rms 2.12e-3 °/s = 7.64 °/h; the
    # figures are in the unit they name, and the model removes nearly all of it
    scale = {"deg/s": 1.0, "deg/h": 3600.0}[v["unit"]]
    assert v["rms_before"] == pytest.approx(2e-4 * 15.0 / np.sqrt(2.0) * scale, rel=0.05)
    assert v["rms_after"] < 0.01 * v["rms_before"]


def test_raw_count_temperature_conversion_travels_with_the_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Temperatures logged as ADC counts, converted with --temp-conversion at fit only:
    compensate and validate use the model's recorded conversion (same numbers as °C)."""
    df = _gyro_deg_s()
    counts = np.round((df["T1"] + 50.0) / 0.0625)
    raw = df.assign(T1=counts)
    src = tmp_path / "raw.csv"
    raw.to_csv(src, index=False)
    model = tmp_path / "m.json"
    code, _, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
        "--signal-unit", "deg/s", "--temps", "T1", "--temp-unit", "counts",
        "--temp-conversion", "0.0625,-50", "--time-unit", "s", "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    out = tmp_path / "comp.csv"
    code, _, err = _run(capsys, "compensate", str(model), str(src), "-o", str(out))
    assert code == 0, err
    got = pd.read_csv(out)
    expect = 0.01 + 2e-4 * (counts * 0.0625 - 50.0 - 25.0)
    np.testing.assert_allclose(got["gyro_model"], expect, rtol=0, atol=2e-6)


def test_sidecar_time_unit_is_not_overridden_by_a_default(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Bug 2: allan and metrics took --time-unit s by default over the sidecar's ms: on the
    shipped 50 Hz example τ started at 20 s and ARW was 31.6× too large."""
    f = example_path("tvac")
    code, out, err = _run(capsys, "allan", str(f), "--signal", "gyro deg/h", "--json")
    assert code == 0, err
    assert json.loads(out)["tau_s"][0] == pytest.approx(0.02, rel=1e-9)
    code, out, err = _run(
        capsys, "metrics", str(f), "--signal", "gyro deg/h", "--average", "1", "--json"
    )
    assert code == 0, err


def test_units_in_column_names(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Bug 3: `time (ms)` was read as seconds (0.05 Hz over 7.3e6 s).  The unit in the
    column name is used: 50 Hz over 10 s; `gyrox rad/s` is in rad/s."""
    n = 501
    t_ms = np.arange(n) * 20.0
    df = pd.DataFrame({"time (ms)": t_ms, "gyrox rad/s": np.full(n, 1e-4), "T [°C]": 25.0})
    f = tmp_path / "named.csv"
    df.to_csv(f, index=False)
    code, out, err = _run(
        capsys, "inspect", str(f), "--time", "time (ms)", "--signal", "gyrox rad/s",
        "--temps", "T [°C]", "--json",
    )  # fmt: skip
    assert code == 0, err
    d = json.loads(out)
    assert d["sample_rate_hz"] == pytest.approx(50.0, rel=1e-9)
    assert d["duration_s"] == pytest.approx(10.0, rel=1e-9)
    assert d["columns"]["gyrox rad/s"]["unit"] == "rad/s"
    assert "no unit stated" not in err
    # metrics reports the bias of 1e-4 rad/s in rad/s, the column's unit, naming it
    code, out, err = _run(
        capsys, "metrics", str(f), "--time", "time (ms)", "--signal", "gyrox rad/s",
        "--average", "1", "--json",
    )  # fmt: skip
    assert code == 0, err
    m = json.loads(out)
    assert m["unit"] == "rad/s"  # the data's own unit (issue 25)
    assert m["bias"] == pytest.approx(1e-4, rel=1e-9)


def test_nothing_stated_gives_a_warning_naming_the_default(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "bare.csv"
    _gyro_deg_s(200).to_csv(f, index=False)
    code, _, err = _run(capsys, "metrics", str(f), "--signal", "gyro", "--average", "10")
    assert code == 0, err
    assert "warning: " in err and "no unit stated for the signal column 'gyro'" in err
    assert "assuming deg/h" in err and "no unit stated for the time column 'time'" in err


@pytest.mark.parametrize(
    ("name", "role", "unit"),
    [
        ("time (ms)", "time", "ms"),
        ("time_ms", "time", "ms"),
        ("t [us]", "time", "us"),
        ("time", "time", None),
        ("gyrox rad/s", "signal", "rad/s"),
        ("gx [deg/s]", "signal", "deg/s"),
        ("acc_x (m/s^2)", "signal", "m/s^2"),
        ("gyro_x", "signal", None),
        ("g", "signal", None),
        ("temp_counts", "temperature", "counts"),
        ("T [°C]", "temperature", "degC"),
        ("T1", "temperature", None),
    ],
)
def test_unit_in_column_name(name: str, role: str, unit: str | None) -> None:
    assert unit_in_column_name(name, role) == unit  # type: ignore[arg-type]


def test_resolution_order() -> None:
    """option > metadata > column name > model > default (INTERFACE.md common rules)."""
    with pytest.warns(UnitWarning, match="contradicts the column name 'g \\[deg/s\\]'"):
        assert resolve_unit("g [deg/s]", "signal", option="rad/s").source == "option"
    assert resolve_unit("g [deg/s]", "signal", metadata="deg/h").unit == "deg/h"
    assert resolve_unit("g [deg/s]", "signal", model="deg/h").unit == "deg/s"
    assert resolve_unit("g", "signal", model="mg").unit == "mg"
    with pytest.warns(UnitWarning, match="assuming deg/h"):
        assert resolve_unit("g", "signal").source == "default"
    with pytest.warns(UnitWarning, match="contradicts the file's metadata"):
        assert resolve_unit("g", "signal", option="mg", metadata="deg/h").unit == "mg"


# --- the model learns its inputs: the simulator's truth, raw and signed counts --------------


def test_deg_s_data_against_the_simulator_truth(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Bug 1 against an independent truth: the simulator's FOG (truth_bias in °/h) written in
    °/s, fitted with --signal-unit deg/s; compensate and validate without the unit.  The
    model column, in °/s, follows truth/3600 (the ×3600 bug put it 3600× off), the figures
    are in °/s and say so."""
    from thermocal.simulate import SCENARIOS

    rec, _truth = SCENARIOS["fog-slow"](1)[0]
    keep = slice(None, None, 4)
    truth_deg_s = rec.columns["truth_bias"][keep] * units.DH_TO_DS
    src = tmp_path / "fog.csv"
    pd.DataFrame(
        {
            "time": rec.time_s[keep],
            "gyro": rec.columns["gyro"][keep] * units.DH_TO_DS,
            "T1": rec.columns["T1"][keep],
        }
    ).to_csv(src, index=False)
    model = tmp_path / "fog.json"
    code, _, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--terms", "T1,T1^2,T1^3,dT1,T1*dT1",
        "--signal", "gyro", "--signal-unit", "deg/s", "--temps", "T1", "--time-unit", "s",
        "--temp-unit", "degC", "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    out = tmp_path / "comp.csv"
    code, stdout, err = _run(capsys, "compensate", str(model), str(src), "-o", str(out))
    assert code == 0, err
    assert "rms after" in stdout and "deg/s" in stdout  # the printed figure names its unit
    got = pd.read_csv(out)["gyro_model"].to_numpy()
    miss = (got - got.mean()) - (truth_deg_s - truth_deg_s.mean())
    assert np.sqrt(np.mean(miss**2)) < 0.25 * truth_deg_s.std()
    code, stdout, err = _run(capsys, "validate", str(model), str(src), "--json")
    assert code == 0, err
    v = json.loads(stdout)
    assert v["unit"] == "deg/s" and v["model_unit"] == "deg/h"
    # rms of the 100 s averages before compensation: the truth's variation, in °/s
    assert v["rms_before"] == pytest.approx(truth_deg_s.std(), rel=0.15)


def _signed_counts_run(tmp_path: Path) -> tuple[Path, pd.DataFrame, np.ndarray]:
    """Temperatures as a logger writes a signed 16-bit sensor: LSB 1/128 °C about 25 °C,
    stored unsigned (below 25 °C the count is 65536 + v).  T spans 5…45 °C."""
    df = _gyro_deg_s()
    df["T1"] = np.round((5.0 + 40.0 * (df["T1"] - 10.0) / 30.0) * 128.0) / 128.0
    temp = df["T1"].to_numpy()
    df["gyro"] = (
        0.01 + 2e-4 * (temp - 25.0) + 1e-5 * np.random.default_rng(5).standard_normal(temp.size)
    )
    v = np.round((temp - 25.0) * 128.0)
    raw = df.assign(T1=np.where(v < 0, v + 65536.0, v))
    src = tmp_path / "signed.csv"
    raw.to_csv(src, index=False)
    return src, raw, temp


def test_signed_16_bit_counts_converted_at_fit_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Bug 4: signed 16-bit counts stored unsigned (≈ 64 000 below 25 °C).  With
    --temp-conversion 0.0078125,25,int16 at fit only, compensate and validate use the
    recorded conversion: the model follows the truth, written out in °C."""
    src, raw, temp = _signed_counts_run(tmp_path)
    assert raw["T1"].max() > 60000  # what the user sees in the file
    model = tmp_path / "m.json"
    code, out, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
        "--signal-unit", "deg/s", "--temps", "T1", "--temp-conversion", "0.0078125,25,int16",
        "--time-unit", "s", "--json", "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    fit = json.loads(out)
    assert fit["temperature_range"]["T1"] == pytest.approx([temp.min(), temp.max()])
    saved = json.loads(model.read_text())
    assert saved["inputs"]["temperature_conversion"] == {"T1": [0.0078125, 25.0, "int16"]}
    comp = tmp_path / "comp.csv"
    code, _, err = _run(capsys, "compensate", str(model), str(src), "-o", str(comp))
    assert code == 0, err
    expect = 0.01 + 2e-4 * (temp - 25.0)  # [°/s]
    np.testing.assert_allclose(pd.read_csv(comp)["gyro_model"], expect, rtol=0, atol=2e-6)
    code, stdout, err = _run(capsys, "validate", str(model), str(src), "--json")
    assert code == 0, err
    v = json.loads(stdout)
    assert v["unit"] == "deg/s" and v["rms_after"] < 0.01 * v["rms_before"]


def test_raw_counts_without_a_conversion_give_a_model_in_counts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Raw counts with no conversion anywhere: the fit is in counts and says so (file and
    ranges); it applies to counts data (same model values as the truth), and °C data are
    refused naming the column."""
    df = _gyro_deg_s()
    counts = np.round((df["T1"] + 50.0) / 0.0625)
    src = tmp_path / "raw.csv"
    df.assign(temp_counts=counts).drop(columns="T1").to_csv(src, index=False)
    model = tmp_path / "m.json"
    code, _, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
        "--signal-unit", "deg/s", "--temps", "temp_counts", "--time-unit", "s", "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    assert "warning: " in err and "fitted in counts" in err
    saved = json.loads(model.read_text())
    assert saved["temperature_unit"] == "counts" and saved["range"]["temperature_unit"] == "counts"
    assert saved["range"]["temperature_c"]["temp_counts"] == [counts.min(), counts.max()]
    out = tmp_path / "comp.csv"
    code, _, err = _run(capsys, "compensate", str(model), str(src), "-o", str(out))
    assert code == 0, err
    expect = 0.01 + 2e-4 * (counts * 0.0625 - 50.0 - 25.0)
    np.testing.assert_allclose(pd.read_csv(out)["gyro_model"], expect, rtol=0, atol=2e-6)
    deg = tmp_path / "deg.csv"
    df.rename(columns={"T1": "temp_counts"}).to_csv(deg, index=False)
    for cmd in (["compensate", str(model), str(deg), "-o", str(tmp_path / "x.csv")],
                ["validate", str(model), str(deg)]):  # fmt: skip
        code, _, err = _run(capsys, *cmd, "--temp-unit", "degC")
        assert code == 2
        assert "raw counts" in err and "'temp_counts'" in err and "degC" in err
    assert not (tmp_path / "x.csv").exists()


def test_data_of_another_kind_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A gyro model (fitted in °/s) applied to a file whose sidecar says the column is in mg:
    refused by compensate, validate and report's entry point, naming both units."""
    df = _gyro_deg_s()
    src = tmp_path / "run.csv"
    df.to_csv(src, index=False)
    model = tmp_path / "m.json"
    code, _, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
        "--signal-unit", "deg/s", "--temps", "T1", "--time-unit", "s", "--temp-unit", "degC",
        "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    acc = tmp_path / "acc.csv"
    df.to_csv(acc, index=False)
    (tmp_path / "acc.csv.meta.json").write_text(json.dumps({"signals": {"gyro": "mg"}}))
    for cmd in (["compensate", str(model), str(acc), "-o", str(tmp_path / "o.csv")],
                ["validate", str(model), str(acc)]):  # fmt: skip
        code, _, err = _run(capsys, *cmd)
        assert code == 2, err
        last = err.strip().splitlines()[-1]
        assert last.startswith("error: ") and "'deg/h'" in last and "'mg'" in last
    assert not (tmp_path / "o.csv").exists()


def test_option_contradicting_the_sidecar_wins_with_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    n = 200
    src = tmp_path / "x.csv"
    pd.DataFrame({"time": np.arange(n) * 20.0, "gyro": np.full(n, 1.0)}).to_csv(src, index=False)
    (tmp_path / "x.csv.meta.json").write_text(
        json.dumps({"time_unit": "ms", "signals": {"gyro": "deg/s"}})
    )
    code, out, err = _run(
        capsys, "metrics", str(src), "--signal", "gyro", "--signal-unit", "deg/h",
        "--average", "1", "--json",
    )  # fmt: skip
    assert code == 0, err
    assert "--signal-unit deg/h contradicts the file's metadata" in err and "deg/s" in err
    m = json.loads(out)
    assert m["unit"] == "deg/h" and m["bias"] == pytest.approx(1.0)


def test_model_files_of_format_version_1_still_load(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An older model file (no ``inputs``): what it did not record is unknown, so the data's
    unstated units fall to the stated default — the model's own unit, said in a warning."""
    from thermocal.models.format import checksum

    df = _gyro_deg_s()
    src = tmp_path / "run.csv"
    (df.assign(gyro=df["gyro"] * 3600.0)).to_csv(src, index=False)
    model = tmp_path / "m.json"
    code, _, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
        "--signal-unit", "deg/h", "--temps", "T1", "--time-unit", "s", "--temp-unit", "degC",
        "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    d = json.loads(model.read_text())
    d = {k: v for k, v in d.items() if k not in ("inputs", "checksum")}
    d["format_version"] = 1
    d["range"].pop("temperature_unit")
    d["checksum"] = checksum(d)
    old = tmp_path / "old.json"
    old.write_text(json.dumps(d))
    out = tmp_path / "c.csv"
    code, _, err = _run(capsys, "compensate", str(old), str(src), "-o", str(out))
    assert code == 0, err
    assert "no unit stated for the signal column 'gyro'; assuming deg/h (the model's unit)" in err
    assert "no unit stated for the time column 'time'; assuming s" in err
    expect = (0.01 + 2e-4 * (df["T1"] - 25.0)) * 3600.0
    np.testing.assert_allclose(pd.read_csv(out)["gyro_model"], expect, rtol=0, atol=1e-2)


@pytest.mark.parametrize(
    ("temps", "unit_opts", "code_want", "words"),
    [
        # ADC counts named as a temperature with nothing stated: warned with the cause
        (np.round(np.linspace(63123.0, 65249.0, 400)), [], 0, "raw ADC counts?"),
        # stated °C, outside any chamber: a warning naming column and value
        (np.linspace(20.0, 260.0, 400), ["--temp-unit", "degC"], 0, "outside -100…+200 °C"),
        # below absolute zero: refused
        (np.linspace(-300.0, 20.0, 400), ["--temp-unit", "degC"], 2, "below absolute zero"),
    ],
)
def test_implausible_temperatures_are_named(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    temps: np.ndarray,
    unit_opts: list[str],
    code_want: int,
    words: str,
) -> None:
    """Bug 4: '63123…65249 °C' was fitted without a word.  Now the command says which
    column holds which implausible value (or refuses below absolute zero)."""
    n = temps.size
    src = tmp_path / "t.csv"
    pd.DataFrame({"time": np.arange(n, dtype=float), "gyro": 0.01 * temps, "temp": temps}).to_csv(
        src, index=False
    )
    code, _, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--order", "1", "--signal", "gyro",
        "--signal-unit", "deg/h", "--temps", "temp", "--time-unit", "s", *unit_opts,
        "-o", str(tmp_path / "m.json"),
    )  # fmt: skip
    assert code == code_want, err
    line = next(ln for ln in err.splitlines() if words.replace("-", "−") in ln or words in ln)
    assert "'temp'" in line and ("warning: " in line or "error: " in line)


def test_a_sidecar_alone_gives_the_time_unit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Bug 2 with nothing but the sidecar saying ms (the column is plain 'time'): allan's
    τ starts at one 20 ms sample, metrics' rate is 50 Hz."""
    n = 3000
    src = tmp_path / "ms.csv"
    rng = np.random.default_rng(2)
    pd.DataFrame({"time": np.arange(n) * 20.0, "gyro": 1.0 + 0.1 * rng.standard_normal(n)}).to_csv(
        src, index=False
    )
    (tmp_path / "ms.csv.meta.json").write_text(
        json.dumps({"time_unit": "ms", "signals": {"gyro": "deg/h"}})
    )
    code, out, err = _run(capsys, "allan", str(src), "--signal", "gyro", "--json")
    assert code == 0, err
    assert json.loads(out)["tau_s"][0] == pytest.approx(0.02, rel=1e-12)
    assert "no unit stated" not in err


def test_int16_conversion_in_a_sidecar_and_round_trip(tmp_path: Path) -> None:
    """The sidecar's ``temperature_conversion`` may say ``int16`` too; it survives a
    write/read round trip of the recording."""
    from thermocal.readers.dispatch import read_recording
    from thermocal.writers import write_recording

    src = tmp_path / "s.csv"
    raw = np.array([65280.0, 65535.0, 0.0, 256.0])  # −256, −1, 0, 256 as signed counts
    pd.DataFrame({"time": np.arange(4.0), "g": np.zeros(4), "tc": raw}).to_csv(src, index=False)
    (tmp_path / "s.csv.meta.json").write_text(
        json.dumps(
            {
                "time_unit": "s",
                "signals": {"g": "deg/h"},
                "temperatures": {"tc": "counts"},
                "metadata": {"temperature_conversion": {"tc": [0.0078125, 25.0, "int16"]}},
            }
        )
    )
    rec = read_recording(src)
    expect = np.array([-256.0, -1.0, 0.0, 256.0]) * 0.0078125 + 25.0
    np.testing.assert_array_equal(rec.temperature_c("tc"), expect)
    back = read_recording(write_recording(rec, tmp_path / "o.csv"))
    np.testing.assert_array_equal(back.temperature_c("tc"), expect)
    assert back.meta.temperature_conversion["tc"].encoding == "int16"


def test_printed_figures_name_their_units(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Units in brackets were eaten as rich markup: fit printed "rms residual" with no unit,
    validate "before"/"after", compensate "gx _model".  Every figure names its unit."""
    df = _gyro_deg_s().rename(columns={"gyro": "gx [deg/s]"})
    src = tmp_path / "run.csv"
    df.to_csv(src, index=False)
    model = tmp_path / "m.json"
    code, out, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--order", "1", "--signal", "gx [deg/s]",
        "--temps", "T1", "--temp-unit", "degC", "--time-unit", "s", "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    # the data's own unit (issue 25): the column is in deg/s
    assert "rms residual [deg/s]" in out and "range T1 [°C]" in out
    code, out, err = _run(capsys, "compensate", str(model), str(src), "-o", str(tmp_path / "c.csv"))
    assert code == 0, err
    assert "gx [deg/s]_model, gx [deg/s]_comp [deg/s]" in out
    code, out, err = _run(capsys, "validate", str(model), str(src))
    assert code == 0, err
    assert "before [deg/s]" in out and "after [deg/s]" in out


def test_scale_factor_without_unit_is_stated(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Pulse counts with a scale factor K but no unit for K: the pulses-per-arcsec default
    is stated in a warning; with the unit stated, nothing is said. 3 pulses per 1 s sample
    at K = 1 pulse/arcsec is 3 arcsec/s = 3 °/h."""
    n = 2000
    df = pd.DataFrame({"time": np.arange(n, dtype=float), "pulses": np.full(n, 3.0)})
    df.to_csv(tmp_path / "rlg.csv", index=False)
    side = {"time_unit": "s", "signals": {"pulses": "counts"},
            "metadata": {"scale_factor": 1.0}}  # fmt: skip
    (tmp_path / "rlg.csv.meta.json").write_text(json.dumps(side))
    code, out, err = _run(capsys, "metrics", str(tmp_path / "rlg.csv"), "--json")
    assert code == 0, err
    assert "counts/arcsec assumed" in err
    assert json.loads(out)["bias"] == pytest.approx(3.0)
    side["metadata"]["scale_factor_unit"] = "counts/arcsec"  # type: ignore[index]
    (tmp_path / "rlg.csv.meta.json").write_text(json.dumps(side))
    code, out, err = _run(capsys, "metrics", str(tmp_path / "rlg.csv"), "--json")
    assert code == 0 and "assumed" not in err
