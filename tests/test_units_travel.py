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
    assert saved["format_version"] == 2
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
    # 1e-4 rad/s = 20.6265 °/h: metrics reports the bias in °/h (canonical) naming it
    code, out, err = _run(
        capsys, "metrics", str(f), "--time", "time (ms)", "--signal", "gyrox rad/s",
        "--average", "1", "--json",
    )  # fmt: skip
    assert code == 0, err
    m = json.loads(out)
    assert m["unit"] == "deg/h"
    assert m["bias"] == pytest.approx(1e-4 * 180.0 / np.pi * 3600.0, rel=1e-9)


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
    assert resolve_unit("g [deg/s]", "signal", option="rad/s").source == "option"
    assert resolve_unit("g [deg/s]", "signal", metadata="deg/h").unit == "deg/h"
    assert resolve_unit("g [deg/s]", "signal", model="deg/h").unit == "deg/s"
    assert resolve_unit("g", "signal", model="mg").unit == "mg"
    with pytest.warns(UnitWarning, match="assuming deg/h"):
        assert resolve_unit("g", "signal").source == "default"
    with pytest.warns(UnitWarning, match="contradicts the file's metadata"):
        assert resolve_unit("g", "signal", option="mg", metadata="deg/h").unit == "mg"


def test_only_the_resolver_chooses_a_default_unit() -> None:
    """No `or "deg/h"`, `or "degC"` or `or "s"` fallbacks left in the package: the resolver
    (units.resolve_unit) is the only place that chooses a unit nobody stated."""
    import re

    import thermocal

    root = Path(thermocal.__file__).parent
    pattern = re.compile(r"""or\s+["'](deg/h|degC|s|mg)["']""")
    hits = [
        f"{p.relative_to(root)}:{i + 1}"
        for p in root.rglob("*.py")
        for i, line in enumerate(p.read_text(encoding="utf-8").splitlines())
        if pattern.search(line)
    ]
    assert hits == [], hits
